// zhc/codec/probe/zh3_clamp.cpp — ZH3 zonal clamps: the zonal L2 coefficient clamped towards
// non-negative irradiance, along the zonal axis by the closed-form interval (App. B, Eq. 23-26,
// re-derived: zh3_axis_clamp) and on the whole sphere by a golden-section search and bisection on the
// exact minimum over the sphere (zh3_sphere_clamp, zhc's own), and their codec-table entries
// zh3_lum_axis_clamp and zh3_lum_sphere_clamp (zh3_clamp_codecs()). Neither touches the L1, so where
// the linear band alone goes negative irradiance stays negative: the entries that guarantee
// irradiance >= 0 are the deringers zh3_dering and zh3_dering_q16 (zh3_dering.cpp).
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md (the App. B interval).
#include "codec/probe/zh3.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "codec/probe/zh3_internal.h"

namespace zhc {

using namespace detail;  // zh3_internal.h and sh_l1.h

// App. B, re-derived (docs/zh3.md). Along the zonal axis, irradiance / (Y00 f0) is
//   g(z) = 1 + a z + b (3 z^2 - 1),  a = 2 f1 / (sqrt(3) f0),  b = sqrt(5) f20 / (8 f0)   (Eq. 23).
// With a >= 0 (g(-z) swaps the sign of a): the end z = -1 needs b >= (a - 1) / 2; for b >= a / 6
// the vertex z* = -a / (6 b) lies in [-1, 0] and needs 12 b^2 - 12 b + a^2 <= 0, i.e.
// b in [b-, b+] = [(1 -+ sqrt(1 - a^2 / 3)) / 2]. Together:
//   a <= 3/2:           b in [(a - 1) / 2, b+]
//   3/2 < a <= sqrt(3): b in [b-, b+]          (the paper's Eq. 25 lower bound is too low here)
//   a > sqrt(3):        infeasible; b = a / (2 sqrt(3)) maximises min g (= 1 - a / sqrt(3)).
// The paper's upper bound sqrt(5)/4 (Eq. 24-26) is neither b+ (which runs from 1 to 1/2) nor safe
// near a = sqrt(3); see docs/zh3.md.
ZonalInterval zh3_axis_clamp_interval(double f0, double f1_zonal) {
    ZonalInterval out;
    if (!(f0 > 0) || !std::isfinite(f0) || !std::isfinite(f1_zonal)) return out;  // nothing is safe
    const double a = std::fabs(2.0 * f1_zonal / (kSqrt3 * f0));
    const double to_f20 = 8.0 * f0 / std::sqrt(5.0);  // f20 = b * 8 f0 / sqrt(5)
    if (a > kSqrt3) {
        out.lo = out.hi = a / (2.0 * kSqrt3) * to_f20;
        return out;
    }
    const double root = std::sqrt(std::max(0.0, 1.0 - a * a / 3.0));
    const double lo = a <= 1.5 ? (a - 1.0) / 2.0 : (1.0 - root) / 2.0;
    out.lo = lo * to_f20;
    out.hi = (1.0 + root) / 2.0 * to_f20;
    out.feasible = true;
    return out;
}

bool zh3_axis_clamp(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w) {
    bool clamped = false;
    const Axes axes(zh3->linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        // Only the L1 component along the zonal axis enters g(z); see docs/zh3.md for what that
        // guarantees when the channel's L1 is not parallel to the axis.
        const double f1 = dot(l1_vector(zh3->linear.c.data(), k), axes.a[k]);
        const ZonalInterval iv = zh3_axis_clamp_interval(zh3->linear[0][k], f1);
        const double f20 = zh3->zonal[k];
        const double c = std::isfinite(f20) ? std::clamp(f20, iv.lo, iv.hi) : iv.lo;
        if (c != f20) {
            zh3->zonal[k] = static_cast<float>(c);
            clamped = true;
        }
    }
    return clamped;
}

namespace {
// h(theta) = 1 + a cos t - c sin t + b (3 cos^2 t - 1) over [0, pi]: a trigonometric polynomial of
// degree 2 (1 + b/2 + a cos t - c sin t + (3b/2) cos 2t), so it has at most four critical points
// per period. Sampling 33 points (tabulated) and polishing every sampled local minimum by Newton
// finds the minimum to rounding.
struct SampleTable {
    static constexpr int kSamples = 32;
    double cos_t[kSamples + 1], sin_t[kSamples + 1];
    SampleTable() {
        for (int i = 0; i <= kSamples; ++i) {
            cos_t[i] = std::cos(kPi * i / kSamples);
            sin_t[i] = std::sin(kPi * i / kSamples);
        }
    }
};

double sphere_min_ratio(double a, double c, double b) {
    static const SampleTable table;
    constexpr int n = SampleTable::kSamples;
    auto h = [&](double ct, double st) { return 1.0 + a * ct - c * st + b * (3.0 * ct * ct - 1.0); };
    double v[n + 1];
    for (int i = 0; i <= n; ++i) v[i] = h(table.cos_t[i], table.sin_t[i]);
    double best = 1e300;
    for (int i = 0; i <= n; ++i) {
        best = std::min(best, v[i]);
        // Newton from every discrete local minimum, the end samples included: with a small c the
        // minimum can sit between the last two samples while v[n] < v[n - 1] (h'(pi) = c > 0), and
        // the end sample alone would overestimate it (a test found 1.5e-4 of the DC this way).
        if (!((i == 0 || v[i] <= v[i - 1]) && (i == n || v[i] <= v[i + 1]))) continue;
        // Newton on theta, carried as (cos, sin) and rotated by the step: every iterate is a real
        // direction, so h there is an upper bound of the minimum that converges to it. Steps stay
        // within one sample spacing (pi/32), where the Taylor rotation is accurate to ~1e-10.
        double ct = table.cos_t[i], st = table.sin_t[i];
        const double max_step = kPi / n;
        for (int it = 0; it < 5; ++it) {
            const double d1 = -a * st - c * ct - 6.0 * b * st * ct;            // h'
            const double d2 = -a * ct + c * st - 6.0 * b * (ct * ct - st * st);  // h''
            if (!(d2 > 0)) break;
            const double delta = std::clamp(-d1 / d2, -max_step, max_step);
            const double d2s = delta * delta;
            const double cd = 1.0 - d2s / 2.0 * (1.0 - d2s / 12.0), sd = delta * (1.0 - d2s / 6.0 * (1.0 - d2s / 20.0));
            double nc = ct * cd - st * sd, ns = st * cd + ct * sd;
            if (ns < 0) break;  // left [0, pi]: the end samples cover it
            const double len = std::sqrt(nc * nc + ns * ns);
            nc /= len;
            ns /= len;
            ct = nc;
            st = ns;
            if (std::fabs(delta) < 1e-12) break;
        }
        best = std::min(best, h(ct, st));
    }
    return best;
}
}  // namespace

double zh3_sphere_clamp_zonal(double f0, double f1_zonal, double f1_perp, double f20, bool* clamped) {
    *clamped = false;
    if (!(f0 > 0) || !std::isfinite(f0) || !std::isfinite(f1_zonal) || !std::isfinite(f1_perp)) {
        *clamped = f20 != 0.0;
        return 0.0;
    }
    const double a = 2.0 * f1_zonal / (kSqrt3 * f0), c = std::fabs(2.0 * f1_perp / (kSqrt3 * f0));
    const double to_f20 = 8.0 * f0 / std::sqrt(5.0);
    const double b0 = std::isfinite(f20) ? f20 / to_f20 : 0.0;
    // F(b) = min over the sphere is concave in b (a minimum of affine functions), so {F >= 0} is an
    // interval and the nearest feasible b lies between b0 and the maximiser of F.
    auto f = [&](double b) { return sphere_min_ratio(a, c, b); };
    if (std::isfinite(f20) && f(b0) >= 0) return f20;
    *clamped = true;
    // F(b) <= 1 - b - c at z = 0 and <= 1 + 2b - |a| at z = -+1: the maximiser lies in this bracket.
    const double r = std::sqrt(a * a + c * c);
    double lo = -1.0 - r, hi = 1.0 + r;
    const double phi = (std::sqrt(5.0) - 1.0) / 2.0;
    double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo), f1 = f(x1), f2 = f(x2);
    for (int it = 0; it < 60 && hi - lo > 1e-9 * (1.0 + r); ++it) {  // golden section on concave F
        if (f1 < f2) {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + phi * (hi - lo);
            f2 = f(x2);
        } else {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - phi * (hi - lo);
            f1 = f(x1);
        }
    }
    const double bstar = f1 >= f2 ? x1 : x2;
    if (!(f(bstar) >= 0) || !std::isfinite(b0)) return bstar * to_f20;  // nothing is safe: least negative
    // Bisection between the infeasible b0 and the feasible bstar; keep the feasible end.
    double bad = b0, good = bstar;
    for (int it = 0; it < 60 && std::fabs(good - bad) > 1e-9 * (1.0 + r); ++it) {
        const double mid = 0.5 * (bad + good);
        (f(mid) >= 0 ? good : bad) = mid;
    }
    return good * to_f20;
}

bool zh3_sphere_clamp(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w) {
    bool any = false;
    const Axes axes(zh3->linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        const Vec3 axis = axes.a[k];
        const Vec3 v = l1_vector(zh3->linear.c.data(), k);
        const double along = dot(v, axis);
        const double across = length(v - along * axis);
        bool clamped = false;
        const double c = zh3_sphere_clamp_zonal(zh3->linear[0][k], along, across, zh3->zonal[k], &clamped);
        if (clamped) {
            // The stored value is a float: step it by ulps further into the feasible side (away from
            // the infeasible original) until the stored value itself passes.
            const double f0 = zh3->linear[0][k];
            const float from = zh3->zonal[k];
            float cf = static_cast<float>(c);
            if (f0 > 0 && std::isfinite(from) &&
                sphere_min_ratio(2.0 * along / (kSqrt3 * f0), 2.0 * across / (kSqrt3 * f0), c * std::sqrt(5.0) / (8.0 * f0)) >= 0) {
                const float toward = c > from ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
                const double a = 2.0 * along / (kSqrt3 * f0), cc = 2.0 * across / (kSqrt3 * f0);
                for (int step = 0; step < 8 && sphere_min_ratio(a, cc, cf * std::sqrt(5.0) / (8.0 * f0)) < 0; ++step)
                    cf = std::nextafter(cf, toward);
            }
            zh3->zonal[k] = cf;
            any = true;
        }
    }
    return any;
}

namespace {

void encode_lum_axis_clamp(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, o.luminance);
    const bool clamped = zh3_axis_clamp(&z, ZonalAxisMode::kLuminance, o.luminance);
    if (stats) stats->dering_clamped = clamped;
    store_zh3(z, out);
}
void encode_lum_sphere_clamp(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, o.luminance);
    const bool clamped = zh3_sphere_clamp(&z, ZonalAxisMode::kLuminance, o.luminance);
    if (stats) stats->dering_clamped = clamped;
    store_zh3(z, out);
}

constexpr auto kLum = ZonalAxisMode::kLuminance;
constexpr CodecTraits kLumAxis{.zonal_axis = ZonalAxis::kLuminance};

// Their stored bytes are zh3_lum's (same decoder); codec_aliases() (codec_table.cpp) maps the names
// zh3_lum_dering and zh3_lum_dering_sphere to them.
const Codec kClampCodecs[] = {
    {"zh3_lum_axis_clamp", "zh3_lum with the zonal L2 clamped for irradiance >= 0 along the axis (App. B)",
     kZh3Floats * 4, encode_lum_axis_clamp, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_lum_sphere_clamp", "zh3_lum, zonal L2 nearest to the fit with irradiance >= 0 on the whole sphere if one exists",
     kZh3Floats * 4, encode_lum_sphere_clamp, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
};

}  // namespace

std::span<const Codec> zh3_clamp_codecs() { return kClampCodecs; }

}  // namespace zhc
