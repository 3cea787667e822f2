// zhc/codec/probe/dering.h — non-negative SH3 lighting: conservative minimum and deringing
// (Sloan 2017, "Deringing Spherical Harmonics", SIGGRAPH Asia Technical Briefs).
//
// Three pieces:
//  * a conservative LOWER BOUND of the minimum of one SH3 function over the sphere (Sec. 2.3),
//    plus a near-exact numerical minimum (dense sampling + Newton refinement) for audits/tests;
//  * the windowing of Table 1 (sinc^4 family, Eq. 6) walked by a bisection with linear
//    interpolation between the table's columns, finding the least windowing that makes the
//    IRRADIANCE bound non-negative — per channel, then the strongest applied to all channels
//    (Sec. 3); DC is never changed;
//  * helpers the audit uses (minimum irradiance, fraction of the sphere that is negative).
//
// See docs/dering.md for the derivations and for how Table 1's rows are read.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "codec/sh/sh.h"

namespace zhc {

// One channel of an SH3 function in double, index l(l+1)+m (zhc basis, codec/sh/sh.h).
using Sh3Channel = std::array<double, 9>;

Sh3Channel channel_of(const Sh3Radiance& sh, int k);
Sh3Channel channel_of(const Sh3Irradiance& sh, int k);

// ---- conservative minimum (Sec. 2.3) --------------------------------------------------------

// An SH3 channel rotated into the frame whose +Z is its optimal linear direction (Sec. 2.2),
// reduced to what the bound needs. In that frame the L1 band is zonal with f_1^0 = `linear` >= 0;
// the |m| = 1 and |m| = 2 pairs are kept only through their amplitudes (Sec. 2.2: a +-m pair is a
// scaled rotation in Z of one basis function).
struct Sh3AxisForm {
    Vec3 axis{0, 0, 1};  // the optimal linear direction (+Z when L1 is zero)
    double dc = 0;       // f_0^0
    double linear = 0;   // f_1^0 in the frame (= |L1| coefficient norm)
    double zonal2 = 0;   // f_2^0 in the frame
    double amp1 = 0;     // sqrt(f_2^-1^2 + f_2^1^2) in the frame
    double amp2 = 0;     // sqrt(f_2^-2^2 + f_2^2^2) in the frame
};
Sh3AxisForm sh3_axis_form(const Sh3Channel& f);

// Lower bound of min over the sphere of the function whose axis form is `form`, with band 1
// scaled by s1 and band 2 by s2 (windowing and/or the irradiance kernel commute with the
// rotation, so the form is computed once). Exact for the zonal and |m| = 2 parts; the |m| = 1 pair
// is taken at its worst phase on each hemisphere. `early_out`: when min(quadratic) - |A|/2 >=
// `threshold` on a hemisphere (|z sqrt(1-z^2)| <= 1/2), that cheaper (still valid, looser) bound is
// returned for it (Sec. 2.3.3's early out); use it when only "bound >= threshold" matters.
double sh3_min_bound(const Sh3AxisForm& form, double s1 = 1.0, double s2 = 1.0, bool early_out = false,
                     double threshold = 0.0);
// Lower bound of min over the sphere of the SH3 function f (any kind: apply the irradiance band
// scales first for irradiance, or use the functions below).
double sh3_min_bound(const Sh3Channel& f);

// Near-exact minimum of f over the sphere: the best of `samples` spherical-Fibonacci directions,
// then a safeguarded Riemannian Newton descent from the best `starts` samples. The value is
// attained (f(direction) == value), so it is an upper bound of the true minimum that converges
// to it; used as the slow reference for the bound.
struct Sh3Minimum {
    double value = 0;
    Vec3 direction{0, 0, 1};
};
Sh3Minimum sh3_min_numeric(const Sh3Channel& f, int samples = 4096, int starts = 6);

// Per channel, of the irradiance of an SH3 radiance (band scales 1, 2/3, 1/4) or of an SH3
// irradiance.
std::array<double, 3> sh3_min_irradiance_bound(const Sh3Radiance& radiance);
std::array<double, 3> sh3_min_bound(const Sh3Irradiance& irradiance);
std::array<double, 3> sh3_min_irradiance_numeric(const Sh3Radiance& radiance, int samples = 4096);
std::array<double, 3> sh3_min_numeric(const Sh3Irradiance& irradiance, int samples = 4096);

// Fraction of `directions` at which any channel of the irradiance is negative (0 when empty).
double negative_fraction(const Sh3Irradiance& irradiance, std::span<const Vec3> directions);
// Same on `count` spherical-Fibonacci directions (fibonacci_sphere of codec/sh/sh.h).
double negative_fraction(const Sh3Irradiance& irradiance, int count = 16384);

// ---- windowing (Sec. 2.4, Table 1, Eq. 6) ---------------------------------------------------

// Eq. 6: (sin(pi l / w) / (pi l / w))^4; 1 at l = 0 or w = infinity.
double sinc4_window(double l, double w);

// Table 1 as printed: window sizes w and three rows of per-band scales, strongest last.
inline constexpr int kDeringTableColumns = 7;
extern const double kDeringTableW[kDeringTableColumns];        // inf, 16.7, ..., 5.6
extern const double kDeringTableRows[3][kDeringTableColumns];  // rows "l1", "l2", "l3"

// Per-band scales of the windowing (DC is always 1).
struct WindowScales {
    double l1 = 1.0;
    double l2 = 1.0;
};

// The window parameter t walks the table: t = 0 is no windowing, t = i is column i, linear
// interpolation in between (Sec. 2.4 "binary search with linear interpolation"). t in
// (kDeringTableColumns - 1, kDeringWindowMax] continues linearly from the strongest column to
// DC only (zero bands 1 and 2): a fallback beyond the paper for inputs the table cannot make
// non-negative (a conservative bound too loose, or a function that is not from non-negative
// lighting). See docs/dering.md for which rows of Table 1 scale bands 1 and 2.
inline constexpr double kDeringWindowMax = kDeringTableColumns;
WindowScales dering_window(double t);

// Extra windowing for punctual (direct) lights, Sec. 3: linear 0.92, quadratic 0.73.
inline constexpr WindowScales kPunctualWindow{0.92, 0.73};

Sh3Radiance apply_window(const Sh3Radiance& radiance, WindowScales scales);

// The search asks the irradiance bound to reach kDeringMargin x the mean irradiance rather than 0,
// so the irradiance stays >= 0 after the windowed coefficients are rounded to float (relative
// error 2^-24 per coefficient); 2^-18 is a window change far below one Table 1 step.
inline constexpr double kDeringMargin = 1.0 / (1 << 18);

struct DeringOptions {
    bool punctual = false;     // apply kPunctualWindow first (source marked as direct lights)
    int bisection_steps = 24;  // halvings of [0, kDeringWindowMax]
};

struct DeringResult {
    Sh3Radiance radiance;                // windowed radiance (DC untouched)
    double window = 0;                   // t applied to all channels (0: untouched by the search)
    std::array<double, 3> channel_window{};  // least t per channel (Sec. 3 takes the largest)
    WindowScales scales;                 // total band scales applied (punctual x table)
    double bisection_step = 0;           // width of the final interval of the search that set
                                         // `window` (per-channel searches: kDeringWindowMax / 2^steps)
    bool windowed = false;               // any coefficient changed
    bool nonnegative = true;             // the irradiance bound is >= 0 in every channel
};

// Least windowing (on the bound, in double) that makes the irradiance of `radiance` non-negative.
// Non-finite coefficients: returned unchanged with nonnegative = false (the bound is NaN).
DeringResult dering_sh3(const Sh3Radiance& radiance, const DeringOptions& options = {});

}  // namespace zhc
