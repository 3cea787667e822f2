// Deringing SH3 lighting: P.-P. Sloan, "Deringing Spherical Harmonics", SIGGRAPH Asia 2017
// Technical Briefs. Sec. 2.3: conservative minimum of an SH3 function; Sec. 2.4 /
// Table 1 / Eq. 6: the windowing table and its bisection; Sec. 3: per-channel search, strongest
// window applied to all channels, extra windowing of punctual sources. Derivations and the
// reading of Table 1: docs/dering.md.
#include "codec/probe/dering.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "codec/probe/codec.h"

namespace zhc {

// ---- Table 1 ---------------------------------------------------------------------------------

const double kDeringTableW[kDeringTableColumns] = {std::numeric_limits<double>::infinity(), 16.7, 11.3, 10.0,
                                                   9.0, 7.0, 5.6};
const double kDeringTableRows[3][kDeringTableColumns] = {
    {1.0, 0.9941, 0.9872, 0.9634, 0.9602, 0.9184, 0.8915},  // "l1"
    {1.0, 0.9766, 0.9493, 0.9355, 0.9207, 0.8710, 0.8030},  // "l2"
    {1.0, 0.9478, 0.8880, 0.8584, 0.8270, 0.7241, 0.5904},  // "l3"
};

namespace {
// Which printed rows scale SH bands 1 and 2. The extraction's row labels are ambiguous; the
// reading that satisfies the paper's stated property of the table ("the most aggressive window
// makes the irradiance of a delta function strictly positive", Sec. 2.4 and Fig. 4) and Eq. 6
// (row "l2" equals sinc^4(pi l / w) at l = 1 for every w) is: band 1 <- row "l2",
// band 2 <- row "l3". docs/dering.md has the numbers for both readings; tests check the property.
constexpr int kRowForBand1 = 1;
constexpr int kRowForBand2 = 2;

double lerp(double a, double b, double u) { return a + (b - a) * u; }
}  // namespace

double sinc4_window(double l, double w) {
    if (l == 0.0 || std::isinf(w)) return 1.0;
    const double x = kPi * l / w;
    const double s = std::sin(x) / x;
    return s * s * s * s;
}

WindowScales dering_window(double t) {
    if (!(t > 0.0)) return {};  // also NaN
    constexpr int last = kDeringTableColumns - 1;
    if (t >= kDeringWindowMax) return {0.0, 0.0};
    if (t > last) {
        // Beyond the table: from the strongest column linearly to DC only (docs/dering.md).
        const double u = 1.0 - (t - last);
        return {u * kDeringTableRows[kRowForBand1][last], u * kDeringTableRows[kRowForBand2][last]};
    }
    const int i = std::min(static_cast<int>(t), last - 1);
    const double u = t - i;
    return {lerp(kDeringTableRows[kRowForBand1][i], kDeringTableRows[kRowForBand1][i + 1], u),
            lerp(kDeringTableRows[kRowForBand2][i], kDeringTableRows[kRowForBand2][i + 1], u)};
}

Sh3Radiance apply_window(const Sh3Radiance& radiance, WindowScales scales) {
    Sh3Radiance out = radiance;
    for (int i = 1; i < 9; ++i) {
        const double s = i < 4 ? scales.l1 : scales.l2;
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(s * radiance[i][k]);
    }
    return out;
}

// ---- channels ---------------------------------------------------------------------------------

Sh3Channel channel_of(const Sh3Radiance& sh, int k) {
    Sh3Channel f{};
    for (int i = 0; i < 9; ++i) f[static_cast<size_t>(i)] = sh[i][k];
    return f;
}
Sh3Channel channel_of(const Sh3Irradiance& sh, int k) {
    Sh3Channel f{};
    for (int i = 0; i < 9; ++i) f[static_cast<size_t>(i)] = sh[i][k];
    return f;
}

namespace {

// The SH3 channel as a polynomial on the unit sphere: f(d) = c + v.d + d^T Q d with Q symmetric
// and traceless (3z^2 - 1 = 2z^2 - x^2 - y^2 on the sphere), from the Cartesian basis of sh.h.
struct Polynomial {
    double c = 0;
    Vec3 v;
    Mat3 q;
};

Polynomial polynomial_of(const Sh3Channel& f) {
    Polynomial p;
    p.c = kY00 * f[0];
    p.v = kY1 * Vec3{-f[3], -f[1], f[2]};
    const double xy = 0.5 * kY2 * f[4], yz = -0.5 * kY2 * f[5], xz = -0.5 * kY2 * f[7];
    p.q.m = {-kY20 * f[6] + kY22 * f[8], xy, xz,
             xy, -kY20 * f[6] - kY22 * f[8], yz,
             xz, yz, 2.0 * kY20 * f[6]};
    return p;
}

double eval(const Polynomial& p, Vec3 d) { return p.c + dot(p.v, d) + dot(d, p.q * d); }

}  // namespace

Sh3AxisForm sh3_axis_form(const Sh3Channel& f) {
    Sh3AxisForm form;
    form.dc = f[0];
    Vec3 axis{0, 0, 1};
    optimal_linear_direction(f[1], f[2], f[3], &axis);  // Sec. 2.2: (-f3, -f1, f2); +Z if zero
    form.axis = axis;
    // Rotate into the frame whose +Z is the axis (Sec. 2.3): with R = frame_from_z(axis) the
    // rotated function is g(u) = f(R u), so g's linear vector is R^T v and its form R^T Q R.
    const Mat3 r = frame_from_z(axis);
    const Mat3 rt = transpose(r);
    const Polynomial p = polynomial_of(f);
    const Vec3 v = rt * p.v;
    form.linear = v.z / kY1;  // >= 0: the axis is the direction of v; v.x, v.y vanish
    const Mat3 q = rt * p.q * r;
    // Inverse of polynomial_of's L2 map (the rotated form stays traceless).
    form.zonal2 = (2.0 * q(2, 2) - q(0, 0) - q(1, 1)) / (6.0 * kY20);
    const double f2m1 = -2.0 * q(1, 2) / kY2, f2p1 = -2.0 * q(0, 2) / kY2;
    const double f2m2 = 2.0 * q(0, 1) / kY2, f2p2 = (q(0, 0) - q(1, 1)) / (2.0 * kY22);
    form.amp1 = std::hypot(f2m1, f2p1);
    form.amp2 = std::hypot(f2m2, f2p2);
    return form;
}

namespace {

// Minimum over z in [-1, 0] of the quadratic a z^2 + b z + c (Sec. 2.3.1: vertex if inside,
// else the end points).
double quadratic_min_lower(double a, double b, double c) {
    double m = std::min(a - b + c, c);
    if (a > 0.0) {
        const double zv = -b / (2.0 * a);
        if (zv > -1.0 && zv < 0.0) m = std::min(m, c - b * b / (4.0 * a));
    }
    return m;
}

// Minimum over z in [-1, 0] of g(z) = a z^2 + b z + c + A z sqrt(1 - z^2), A >= 0.
//
// Sec. 2.3.3 minimises the z sqrt(1 - z^2) term by Newton's method from the minimum of the basis
// function (z = -1/sqrt(2)). To make the result a guaranteed global minimum (a single Newton run
// can stop in a local minimum) we use the shape of h(z) = z sqrt(1 - z^2) on [-1, 0]:
//   h'(z) = (1 - 2 z^2) / sqrt(1 - z^2),   h''(z) = z (2 z^2 - 3) / (1 - z^2)^(3/2) >= 0,
// and h'' grows monotonically from 0 (z = 0) to +inf (z -> -1). So g'' = 2a + A h'' changes sign at
// most once: g is convex on [-1, z*] and concave on [z*, 0] (z* = 0 when a >= 0). The global
// minimum is therefore one of g(-1), g(0), g(z*) and the single root of g' in (-1, z*), which
// exists iff g'(z*) > 0 (g' -> -inf at -1, increasing there) and is found by safeguarded Newton.
double hemisphere_min(double a, double b, double c, double amp) {
    double best = std::min(a - b + c, c);
    if (!(amp > 0.0)) return quadratic_min_lower(a, b, c);
    const auto s_of = [](double z) { return std::sqrt(std::max(0.0, (1.0 - z) * (1.0 + z))); };
    const auto g = [&](double z) { return (a * z + b) * z + c + amp * z * s_of(z); };
    const auto g1 = [&](double z) {
        const double s = s_of(z);
        return 2.0 * a * z + b + amp * (1.0 - 2.0 * z * z) / s;
    };
    const auto g2 = [&](double z) {
        const double s = s_of(z);
        return 2.0 * a + amp * z * (2.0 * z * z - 3.0) / (s * s * s);
    };
    // End of the convex part.
    double zs = 0.0;
    if (a < 0.0) {
        // Solve F(z) = 2a + A h''(z) = 0 on (-1, 0). F' = A h''' with h'''(z) = -3 / (1 - z^2)^(5/2):
        // F is decreasing and convex there, so Newton from any point with F > 0 climbs
        // monotonically towards the root without passing it (the tangent lies below F). Every
        // iterate keeps g'' >= 0, so [-1, zs] stays inside the convex part.
        double z = -1.0 / std::sqrt(2.0);
        while (g2(z) <= 0.0 && z > -1.0) z = 0.5 * (-1.0 + z);  // a start with F > 0
        for (int it = 0; it < 100; ++it) {
            const double w = (1.0 - z) * (1.0 + z);
            const double step = g2(z) * w * w * std::sqrt(w) / (3.0 * amp);  // -F / F'
            const double next = z + step;
            if (!(step > 4.0 * std::numeric_limits<double>::epsilon()) || !(next < 0.0) || !(g2(next) >= 0.0)) break;
            z = next;
        }
        zs = z;
        best = std::min(best, g(zs));
    }
    if (zs <= -1.0) return best;
    const double d_end = g1(zs);
    if (!(d_end > 0.0)) return best;  // g decreasing on the convex part: no interior minimum
    // Root of g' in (-1, zs): g'(-1+) = -inf, g'(zs) > 0, g' increasing. Safeguarded Newton from
    // the basis function's minimum -1/sqrt(2) (Sec. 2.3.3), bisecting whenever Newton leaves the
    // bracket.
    double lo = -1.0, hi = zs;
    double z = -1.0 / std::sqrt(2.0);
    if (!(z > lo && z < hi)) z = 0.5 * (lo + hi);
    double dz = 0;
    for (int it = 0; it < 200; ++it) {
        dz = g1(z);
        if (dz == 0.0) { lo = hi = z; break; }
        if (dz < 0.0) lo = z; else hi = z;
        if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon()) break;
        double next = z - dz / g2(z);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (next == z) break;
        z = next;
    }
    // g is convex on [lo, hi]: g(t) >= g(z) + g'(z)(t - z) >= g(z) - |g'(z)| (hi - lo), which keeps
    // the result a lower bound whatever the iteration stopped at.
    const double val = g(z) - std::fabs(dz) * (hi - lo);
    return std::min(best, val);
}

}  // namespace

double sh3_min_bound(const Sh3AxisForm& form, double s1, double s2, bool early_out, double threshold) {
    // In the frame of the optimal linear direction (Eq. 3 and Sec. 2.3.1, re-derived: the
    // extraction's a and b carry a stray z^2 / z and a drops the 3 of 3z^2 - 1):
    //   zonal: kY00 f0 + kY1 f10 z + kY20 f20 (3 z^2 - 1)
    //   |m| = 2 pair (Eq. 4): amplitude q2 times kY22 (x^2 - y^2) rotated; its worst value at height
    //     z is -kY22 q2 (1 - z^2) (Sec. 2.3.2), so a += kY22 q2, c -= kY22 q2;
    //   |m| = 1 pair (Eq. 5): amplitude q1 times kY2 x z rotated; its worst value at height z is
    //     -kY2 q1 |z| sqrt(1 - z^2) (Sec. 2.3.3), a lower bound independent of the |m| = 2 phase.
    if (!std::isfinite(form.dc) || !std::isfinite(form.linear) || !std::isfinite(form.zonal2) ||
        !std::isfinite(form.amp1) || !std::isfinite(form.amp2) || !std::isfinite(s1) || !std::isfinite(s2))
        return std::numeric_limits<double>::quiet_NaN();
    const double f20 = s2 * form.zonal2, q2 = s2 * form.amp2, q1 = s2 * form.amp1;
    const double a = 3.0 * kY20 * f20 + kY22 * q2;
    const double b = kY1 * s1 * form.linear;
    const double c = kY00 * form.dc - kY20 * f20 - kY22 * q2;
    const double amp = kY2 * q1;
    // Both hemispheres (Sec. 2.3.3, "run twice with the sign negated"): the upper one z in [0, 1]
    // is the lower one of the function mirrored z -> -z, which negates b.
    double result = std::numeric_limits<double>::infinity();
    for (const double bb : {b, -b}) {
        if (early_out) {
            // |z sqrt(1 - z^2)| <= 1/2: a valid, cheaper bound; enough when it is non-negative.
            const double quick = quadratic_min_lower(a, bb, c) - 0.5 * amp;
            if (quick >= threshold) {
                result = std::min(result, quick);
                continue;
            }
        }
        result = std::min(result, hemisphere_min(a, bb, c, amp));
    }
    return result;
}

double sh3_min_bound(const Sh3Channel& f) { return sh3_min_bound(sh3_axis_form(f)); }

// ---- numerical minimum ----------------------------------------------------------------------

namespace {

// Riemannian Newton descent on the unit sphere for f = c + v.d + d^T Q d, monotone (every accepted
// step lowers f), falling back to gradient steps where the Hessian is not positive definite.
Sh3Minimum descend(const Polynomial& p, Vec3 d) {
    double f = eval(p, d);
    for (int it = 0; it < 200; ++it) {
        const Vec3 grad = p.v + 2.0 * (p.q * d);  // Euclidean gradient of the extension
        const Mat3 tf = frame_from_z(d);
        const Vec3 t1{tf(0, 0), tf(1, 0), tf(2, 0)}, t2{tf(0, 1), tf(1, 1), tf(2, 1)};
        const double g1 = dot(t1, grad), g2 = dot(t2, grad);
        if (std::hypot(g1, g2) < 1e-15 * (1.0 + std::fabs(f))) break;
        // Riemannian Hessian on the tangent plane: t_i^T (2Q) t_j - (d . grad) delta_ij.
        const double nd = dot(d, grad);
        const double h11 = 2.0 * dot(t1, p.q * t1) - nd, h22 = 2.0 * dot(t2, p.q * t2) - nd;
        const double h12 = 2.0 * dot(t1, p.q * t2);
        const double det = h11 * h22 - h12 * h12;
        // Newton step where the tangent Hessian is positive definite, then (or else) a gradient
        // step; each capped at 0.5 rad and backtracked until f decreases.
        const double gscale = 1.0 / (std::fabs(h11) + std::fabs(h22) + std::fabs(h12) + 1e-300);
        double steps[2][2] = {{-g1 * gscale, -g2 * gscale}, {-g1 * gscale, -g2 * gscale}};
        if (h11 > 0.0 && det > 0.0) {
            steps[0][0] = -(h22 * g1 - h12 * g2) / det;
            steps[0][1] = -(h11 * g2 - h12 * g1) / det;
        }
        bool improved = false;
        for (int s = 0; s < 2 && !improved; ++s) {
            double x1 = steps[s][0], x2 = steps[s][1];
            const double len = std::hypot(x1, x2);
            if (len > 0.5) {
                x1 *= 0.5 / len;
                x2 *= 0.5 / len;
            }
            for (int k = 0; k < 60; ++k) {
                const Vec3 cand = normalize_or(d + x1 * t1 + x2 * t2, d);
                const double fc = eval(p, cand);
                if (fc < f) {
                    d = cand;
                    f = fc;
                    improved = true;
                    break;
                }
                x1 *= 0.5;
                x2 *= 0.5;
            }
        }
        if (!improved) break;
    }
    return {f, d};
}

}  // namespace

Sh3Minimum sh3_min_numeric(const Sh3Channel& f, int samples, int starts) {
    const Polynomial p = polynomial_of(f);
    const std::vector<Vec3> dirs = fibonacci_sphere(std::max(samples, 1));
    std::vector<std::pair<double, int>> values(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) values[i] = {eval(p, dirs[i]), static_cast<int>(i)};
    const size_t k = std::min(values.size(), static_cast<size_t>(std::max(starts, 1)));
    std::partial_sort(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    Sh3Minimum best{values[0].first, dirs[static_cast<size_t>(values[0].second)]};
    for (size_t i = 0; i < k; ++i) {
        const Sh3Minimum m = descend(p, dirs[static_cast<size_t>(values[i].second)]);
        if (m.value < best.value) best = m;
    }
    return best;
}

// ---- irradiance helpers -----------------------------------------------------------------------

namespace {
Sh3Channel irradiance_channel(const Sh3Radiance& radiance, int k) {
    Sh3Channel f = channel_of(radiance, k);
    for (int i = 0; i < 9; ++i) f[static_cast<size_t>(i)] *= kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)];
    return f;
}
}  // namespace

std::array<double, 3> sh3_min_irradiance_bound(const Sh3Radiance& radiance) {
    std::array<double, 3> out{};
    for (int k = 0; k < 3; ++k) out[static_cast<size_t>(k)] = sh3_min_bound(irradiance_channel(radiance, k));
    return out;
}
std::array<double, 3> sh3_min_bound(const Sh3Irradiance& irradiance) {
    std::array<double, 3> out{};
    for (int k = 0; k < 3; ++k) out[static_cast<size_t>(k)] = sh3_min_bound(channel_of(irradiance, k));
    return out;
}
std::array<double, 3> sh3_min_irradiance_numeric(const Sh3Radiance& radiance, int samples) {
    std::array<double, 3> out{};
    for (int k = 0; k < 3; ++k)
        out[static_cast<size_t>(k)] = sh3_min_numeric(irradiance_channel(radiance, k), samples).value;
    return out;
}
std::array<double, 3> sh3_min_numeric(const Sh3Irradiance& irradiance, int samples) {
    std::array<double, 3> out{};
    for (int k = 0; k < 3; ++k) out[static_cast<size_t>(k)] = sh3_min_numeric(channel_of(irradiance, k), samples).value;
    return out;
}

double negative_fraction(const Sh3Irradiance& irradiance, std::span<const Vec3> directions) {
    if (directions.empty()) return 0.0;
    Polynomial p[3];
    for (int k = 0; k < 3; ++k) p[k] = polynomial_of(channel_of(irradiance, k));
    size_t negative = 0;
    for (const Vec3 d : directions)
        if (eval(p[0], d) < 0.0 || eval(p[1], d) < 0.0 || eval(p[2], d) < 0.0) ++negative;
    return static_cast<double>(negative) / static_cast<double>(directions.size());
}

double negative_fraction(const Sh3Irradiance& irradiance, int count) {
    const std::vector<Vec3> dirs = fibonacci_sphere(count);
    return negative_fraction(irradiance, dirs);
}

// ---- deringing (Sec. 2.4, Sec. 3) -------------------------------------------------------------

namespace {

// Whether the irradiance bound of a radiance axis form under window t reaches the margin (kernel band scales 2/3, 1/4 times the
// window's band scales).
bool window_passes(const Sh3AxisForm& form, WindowScales base, double t) {
    const WindowScales w = dering_window(t);
    const double target = kDeringMargin * kY00 * std::fabs(form.dc);
    return sh3_min_bound(form, kIrradianceBandScale[1] * base.l1 * w.l1, kIrradianceBandScale[2] * base.l2 * w.l2,
                         /*early_out=*/true, target) >= target;
}

// Least t in [lo_start, kDeringWindowMax] passing `passes`, by bisection (Sec. 2.4). Returns the
// passing end and writes the final interval width.
template <class Pred>
double bisect_window(Pred passes, double lo, int steps, double* step_out) {
    double hi = kDeringWindowMax;
    for (int i = 0; i < steps; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (passes(mid)) hi = mid; else lo = mid;
    }
    *step_out = hi - lo;
    return hi;
}

}  // namespace

DeringResult dering_sh3(const Sh3Radiance& radiance, const DeringOptions& options) {
    DeringResult r;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(radiance[i][k])) {
                // Nothing to search on: returned unchanged, flagged as not fixed.
                r.radiance = radiance;
                r.nonnegative = false;
                return r;
            }
    const WindowScales base = options.punctual ? kPunctualWindow : WindowScales{};
    Sh3AxisForm forms[3];
    for (int k = 0; k < 3; ++k) forms[k] = sh3_axis_form(channel_of(radiance, k));
    const int steps = std::clamp(options.bisection_steps, 1, 60);
    double step = 0.0;
    // Per channel (Sec. 3): the least window whose irradiance bound is non-negative.
    for (int k = 0; k < 3; ++k) {
        const auto passes = [&](double t) { return window_passes(forms[k], base, t); };
        double t = 0.0;
        if (!passes(0.0)) {
            double s = 0.0;
            t = passes(kDeringWindowMax) ? bisect_window(passes, 0.0, steps, &s) : kDeringWindowMax;
            step = std::max(step, s);
        }
        r.channel_window[static_cast<size_t>(k)] = t;
    }
    // The strongest applied to all three channels; the bound is not guaranteed monotone in t, so
    // check the other channels there and continue the search above it if one fails.
    double t = std::max({r.channel_window[0], r.channel_window[1], r.channel_window[2]});
    const auto all_pass = [&](double tt) {
        for (int k = 0; k < 3; ++k)
            if (!window_passes(forms[k], base, tt)) return false;
        return true;
    };
    if (!all_pass(t) && t < kDeringWindowMax) {
        double s = 0.0;
        t = all_pass(kDeringWindowMax) ? bisect_window(all_pass, t, steps, &s) : kDeringWindowMax;
        step = s;
    }
    r.window = t;
    r.bisection_step = step;
    r.nonnegative = all_pass(t);
    const WindowScales w = dering_window(t);
    r.scales = {base.l1 * w.l1, base.l2 * w.l2};
    r.windowed = r.scales.l1 != 1.0 || r.scales.l2 != 1.0;
    r.radiance = r.windowed ? apply_window(radiance, r.scales) : radiance;
    return r;
}

// ---- codec entry ------------------------------------------------------------------------------

namespace {

void encode_dering(const Sh3Radiance& in, const CodecOptions& options, std::uint8_t* out, EncodeStats* stats) {
    DeringOptions d;
    d.punctual = options.dering_punctual;
    const DeringResult r = dering_sh3(in, d);
    float v[27];
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) v[i * 3 + k] = r.radiance[i][k];
    store_floats(v, out);
    if (stats) stats->dering_clamped = stats->dering_clamped || r.windowed;
}

Sh3Radiance decode_dering(const std::uint8_t* in, const CodecOptions&) {
    float v[27];
    load_floats(in, v);
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = v[i * 3 + k];
    return out;
}

Rgb irradiance_dering(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return irradiance(decode_dering(in, o), n);
}

const Codec kDering[] = {
    {"sh3_dering", "quadratic SH windowed to non-negative irradiance (Sloan 2017), 27 floats", 27 * 4,
     encode_dering, decode_dering, irradiance_dering},
};

}  // namespace

std::span<const Codec> dering_codecs() { return kDering; }

}  // namespace zhc
