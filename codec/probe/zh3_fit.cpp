// zhc/codec/probe/zh3_fit.cpp — ZH3 fit: the zonal axis derived from the stored L1 (Sec. 3.1 per
// channel, Sec. 3.2 luminance), the least-squares zonal coefficient along it (Eq. 9/10), the
// expansion of a ZH3 to SH3 (Eq. 2) and irradiance straight from ZH3 (Listing 1).
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md.
#include "codec/probe/zh3.h"

#include <algorithm>
#include <cmath>

#include "codec/probe/zh3_internal.h"

namespace zhc {
namespace {

using namespace detail;  // zh3_internal.h and sh_l1.h

// Axis source vector of channel k (not normalised).
Vec3 axis_source(const Rgb* c, ZonalAxisMode mode, int k, const LuminanceWeights& w) {
    return mode == ZonalAxisMode::kLuminance ? luminance_l1(c, w) : l1_vector(c, k);
}

}  // namespace

Vec3 zh3_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w) {
    return normalize_or(axis_source(linear.c.data(), mode, std::clamp(channel, 0, 2), w), {0, 0, 1});
}

bool has_zonal_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w) {
    return usable_length(length(axis_source(linear.c.data(), mode, std::clamp(channel, 0, 2), w)));
}

// Eq. 9/10: l20 = sqrt(4 pi / 5) Y2(axis) . f2, the least-squares zonal coefficient along the axis.
Zh3 zh3_fit(const Sh3Radiance& sh, ZonalAxisMode mode, const LuminanceWeights& w) {
    Zh3 z;
    z.linear = truncate_to_sh2(sh);
    const Axes axes(z.linear, mode, w);
    for (int k = 0; k < 3; ++k) z.zonal[k] = static_cast<float>(fit_zonal(sh, k, axes.a[k]));
    return z;
}

Sh3Radiance zh3_expand(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w) {
    Sh3Radiance out = extend_to_sh3(zh3.linear);
    const Axes axes(zh3.linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        // Eq. 2 on a zonal function: f_2^m = f_2^0 sqrt(4 pi / 5) Y_2^m(axis).
        const auto q = y2(axes.a[k]);
        for (int m = 0; m < 5; ++m) out[4 + m][k] = static_cast<float>(zh3.zonal[k] * kSqrtFourPiOverFive * q[static_cast<size_t>(m)]);
    }
    return out;
}

Rgb zh3_irradiance(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w, Vec3 n) {
    Rgb out;
    const Rgb* c = zh3.linear.c.data();
    const Axes axes(zh3.linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        const Vec3 a = axes.a[k];
        const double z = dot(a, n);
        // Listing 1: linear SH with the L1 band scaled by 2/3, plus 1/4 of the zonal L2 term.
        const double e = kY00 * c[0][k] + kIrradianceBandScale[1] * kY1 * dot(l1_vector(c, k), n) +
                         kIrradianceBandScale[2] * zh3.zonal[k] * kY20 * (3.0 * z * z - 1.0);
        out[k] = static_cast<float>(e);
    }
    return out;
}

}  // namespace zhc
