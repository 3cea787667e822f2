// zhc/codec/probe/zh3_internal.h — internal to codec/: the ZH3 helpers shared by the fit
// (zh3_fit.cpp), the solve (zh3_solve.cpp), hallucination (zh3_hallucinate.cpp) and the zonal clamps
// (zh3_clamp.cpp): the L2 basis at an axis, the zonal axes derived from a stored L1 (Sec. 3.1/3.2),
// the least-squares zonal coefficient along an axis (Eq. 9/10), and the 15-float ZH3 layout the
// codec-table entries of those files share (zh3.cpp).
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md.
//
// Vector form of the bands used throughout (sh.h conventions): the L1 band of a channel,
// (f1-1, f10, f11), is the vector v = (-f11, -f1-1, f10) with f1(d) = kY1 v . d; |v| = |f1| and
// the optimal linear direction is v / |v|. The L2 band evaluated at a unit direction a is
// Y2(a) . f2 = a^T Q a for a traceless symmetric Q.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "codec/probe/zh3.h"
#include "codec/sh/sh_l1.h"

namespace zhc::detail {

// sqrt(4 pi / 5): |Y2(a)|^2 = 5 / (4 pi) on the unit sphere (Eq. 8/9).
inline const double kSqrtFourPiOverFive = std::sqrt(4.0 * kPi / 5.0);
inline const double kSqrt3 = std::sqrt(3.0);

inline std::array<double, 5> y2(Vec3 a) {
    return {kY2 * a.x * a.y, -kY2 * a.y * a.z, kY20 * (3.0 * a.z * a.z - 1.0), -kY2 * a.x * a.z,
            kY22 * (a.x * a.x - a.y * a.y)};
}
inline double dot5(const std::array<double, 5>& a, const double* b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4];
}

inline Vec3 luminance_l1(const Rgb* c, const LuminanceWeights& w) {
    return w.r * l1_vector(c, 0) + w.g * l1_vector(c, 1) + w.b * l1_vector(c, 2);
}

inline bool usable_length(double len) { return len > 0.0 && std::isfinite(len); }

// The three channels' zonal axes, the shared luminance axis computed once.
struct Axes {
    Vec3 a[3];
    Axes(const Sh2Radiance& linear, ZonalAxisMode mode, const LuminanceWeights& w) {
        if (mode == ZonalAxisMode::kLuminance) {
            a[0] = a[1] = a[2] = normalize_or(luminance_l1(linear.c.data(), w), {0, 0, 1});
        } else {
            for (int k = 0; k < 3; ++k) a[k] = normalize_or(l1_vector(linear.c.data(), k), {0, 0, 1});
        }
    }
};

// The zonal coefficient (radiance, Eq. 10) of channel k of `sh` along unit axis a.
inline double fit_zonal(const Sh3Radiance& sh, int k, Vec3 a) {
    const auto q = y2(a);
    double f2[5];
    for (int m = 0; m < 5; ++m) f2[m] = sh[4 + m][k];
    return kSqrtFourPiOverFive * dot5(q, f2);
}

// The 15-float ZH3 layout: DC and L1 as [coefficient][R, G, B], then the three zonal coefficients
// (defined in zh3.cpp).
inline constexpr std::size_t kZh3Floats = 15;
inline constexpr std::size_t kLinearFloats = 12;  // the hallucinated entries store sh2's 12 floats
void store_zh3(const Zh3& z, std::uint8_t* out);
Zh3 load_zh3(const std::uint8_t* in);

template <ZonalAxisMode Mode>
Sh3Radiance decode_zh3(const std::uint8_t* in, const CodecOptions& o) {
    return zh3_expand(load_zh3(in), Mode, o.luminance);
}
template <ZonalAxisMode Mode>
Rgb irradiance_zh3(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return zh3_irradiance(load_zh3(in), Mode, o.luminance, n);
}

}  // namespace zhc::detail
