// zhc/codec/probe/zh3.h — ZH3: linear SH plus one quadratic zonal coefficient per channel
// (Roughton et al. 2024, "ZH3: Quadratic Zonal Harmonics").
//
// Stored form: the RGB linear SH (DC + L1, radiance) and, per channel, the radiance zonal
// coefficient f_2^0 in the frame of the zonal axis. The axis is never stored: it is derived from
// the stored L1 (the luminance L1's optimal linear direction, shared by all channels, or each
// channel's own), so the decoder needs nothing else.
//
// Codec-table entries, each with the algorithm it stores: zh3_lum, zh3_channel, zh3_solved_lum,
// zh3_solved_channel (zh3.cpp, zh3_codecs()), hall_{ambdir,sphere,curve}[_channel]
// (zh3_hallucinate.cpp, zh3_hallucinated_codecs()), zh3_lum_axis_clamp (App. B) and
// zh3_lum_sphere_clamp (zh3_clamp.cpp, zh3_clamp_codecs()). Derivations and choices: docs/zh3.md.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"

namespace zhc {

// ZonalAxisMode: codec/probe/codec.h.

struct Zh3 {
    Sh2Radiance linear;  // DC and L1, radiance
    Rgb zonal;           // f_2^0 (radiance) along each channel's zonal axis
};

// Zonal axis of channel k (0..2) under `mode`, derived from the linear SH only.
// A zero L1 (no defined direction) gives +Z; callers that care check has_zonal_axis().
Vec3 zh3_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w);
bool has_zonal_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w);

// Least-squares zonal fit along the axis of the unchanged L1 (Eq. 9/10).
Zh3 zh3_fit(const Sh3Radiance& sh, ZonalAxisMode mode, const LuminanceWeights& w);
// Expansion to the hub: the L2 band is f_2^0 * sqrt(4 pi / 5) * Y_2(axis) per channel.
Sh3Radiance zh3_expand(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w);
// Irradiance at n straight from ZH3 (runtime path, Listing 1 style).
Rgb zh3_irradiance(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w, Vec3 n);

// ---- axis solve (Sec. 3.3, Eq. 11, App. C) ---------------------------------------------------
//
// Eq. 11 with t the IRRADIANCE SH of `target` (band scales 1, 2/3, 1/4) and f the IRRADIANCE linear
// SH of the candidate (its stored radiance L1 times 2/3):
//   E = sum_k |f1_k - t1_k|^2 + |(4 pi / 5)(Y2(a_k) . t2_k) Y2(a_k) - t2_k|^2,
// a_k the zonal axis of channel k derived from f (shared luminance axis or the channel's own).
// Because the zonal coefficient is the least-squares fit (Eq. 9), E is exactly the squared L2 norm
// over the sphere of (irradiance of the ZH3 expansion) minus (irradiance of the SH3 target); L0 is
// exact and does not enter. Units: irradiance^2 * sr.
double zh3_eq11_error(const Sh3Radiance& target, const Sh2Radiance& linear, ZonalAxisMode mode,
                      const LuminanceWeights& w);

// Eq. 11 in the paper's shared-axis parameterisation (App. C): g holds the nine IRRADIANCE L1
// coefficients, g[3 m + k] = coefficient (1, m - 1) of channel k (the order of Eq. 34). Returns E and
// writes dE/dg (analytic, App. C Eq. 27-36) when `grad` is not null. E is +inf when the luminance L1
// of g is zero (no axis).
double zh3_lum_objective(const Sh3Radiance& target, const LuminanceWeights& w, const double g[9],
                         double grad[9]);
// Per-channel form (Sec. 3.3: "it suffices to solve for the axis"): x is an unnormalised axis
// direction, the channel's L1 is the projection of t1 onto it, and the zonal L2 its Eq. 9 fit;
// returns that E for channel `channel` (same units) and dE/dx when `grad` is not null.
double zh3_channel_objective(const Sh3Radiance& target, int channel, Vec3 x, Vec3* grad);

// The BFGS axis solve. Iterations per start and the relative gradient tolerance come from
// `options`; stats->solver_iterations gets the BFGS iterations summed over the starts.
// The result's Eq. 11 error (evaluated on the float-rounded stored L1) is never above that of
// zh3_fit(sh, mode): the fit is returned instead when the solve does not beat it.
Zh3 zh3_solve(const Sh3Radiance& sh, ZonalAxisMode mode, const CodecOptions& options,
              EncodeStats* stats);

// ---- hallucination (Sec. 3.4, Listing 1) -----------------------------------------------------

enum class Hallucination : std::uint8_t {
    kAmbientDirectional = 0,  // Eq. 14: f20 = sqrt(15)/3 |f1^0|
    kSphere = 1,              // Eq. 19/20: f20 = (2 sqrt(5)/3 p^2 - sqrt(5/3) p) f0, p in [0, sqrt(3)]
    kCurve = 2,               // Eq. 21: f20 = (a p^2 + b p) f0, p in [0, sqrt(3)]
};
// Radiance zonal coefficient hallucinated from DC f0 and the L1 projected on the zonal axis
// (f1_zonal; its absolute value is used as in Listing 1). p = |f1_zonal| / f0 is clamped to
// [0, sqrt(3)] (the ratio range of non-negative functions); f0 <= 0 gives 0 (except Eq. 14,
// which does not involve f0).
double hallucinate_zonal(Hallucination model, double f0, double f1_zonal, double curve_a,
                         double curve_b);
Zh3 zh3_hallucinate(const Sh2Radiance& linear, Hallucination model, ZonalAxisMode mode,
                    const CodecOptions& options);

// ---- zonal clamps (App. B; zh3_clamp.cpp) -----------------------------------------------------

// The interval of RADIANCE zonal coefficients f20 for which
//   Y00 f0 + (2/3) kY1 f1_zonal z + (1/4) kY20 f20 (3 z^2 - 1) >= 0  for all z in [-1, 1]
// (App. B Eq. 22, re-derived exactly: see docs/zh3.md). When no f20 works (|a| > sqrt(3) or
// f0 <= 0) `feasible` is false and lo == hi is the value that maximises the minimum over z
// (0 when f0 <= 0).
struct ZonalInterval {
    double lo = 0, hi = 0;
    bool feasible = false;
};
ZonalInterval zh3_axis_clamp_interval(double f0, double f1_zonal);
// Clamps each channel's zonal coefficient into its interval (f1_zonal = the channel's L1 projected
// on its zonal axis). Returns true when a coefficient changed.
bool zh3_axis_clamp(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w);

// Whole-sphere variant (zhc's extension, docs/zh3.md): with the channel's L1 split into f1_zonal
// along the zonal axis and f1_perp (length) across it, the channel's minimum irradiance over the
// sphere, divided by Y00 f0, is min over theta in [0, pi] of
//   1 + a cos(theta) - c sin(theta) + b (3 cos^2(theta) - 1),  c = 2 f1_perp / (sqrt(3) f0)
// (the worst azimuth is analytic). Returns the radiance f20 nearest to `f20` that makes it >= 0, or,
// when none does, the one that maximises it; *clamped tells whether it changed. f0 <= 0 gives 0.
double zh3_sphere_clamp_zonal(double f0, double f1_zonal, double f1_perp, double f20, bool* clamped);
// Applies it to every channel of a ZH3 (axis from `mode`). Returns true when a coefficient changed.
bool zh3_sphere_clamp(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w);

// The codec table parts of these files (their entries in table order).
std::span<const Codec> zh3_codecs();
std::span<const Codec> zh3_hallucinated_codecs();
std::span<const Codec> zh3_clamp_codecs();

}  // namespace zhc
