// zhc/codec/lightmap/irradz_linear_sh.cpp — linear SH <-> HHD in closed form (the talk's slide "HHD
// and linear SH", re-derived in docs/irradz.md "Linear SH <-> HHD"): the linear SH of the radiance an
// HHD stands for, the exact inverse per channel (a quadratic in C_a), IrradZ from linear SH, and
// lightmap blending in linear SH (the talk's method) or in the parameters (for comparison).
//
// Source: Roughton, "IrradZ" (SIGGRAPH 2024 Advances in Real-Time Rendering talk);
// the slide formulas are re-derived in docs/irradz.md.
#include "codec/lightmap/irradz.h"

#include <algorithm>
#include <cmath>

#include "codec/lightmap/irradz_internal.h"

namespace zhc::irradz {

using namespace detail;  // irradz_internal.h

Sh2Radiance hhd_to_linear_sh(const Lighting& l) {
    // Radiance: C_a over the hemisphere z >= 0 plus a delta of integral pi C_d along d.
    //  l0 = C_a * sqrt(pi) + pi C_d / (2 sqrt(pi)) = sqrt(pi) (C_a + C_d / 2)
    //  L1 = kY1 * V swizzled, V = pi (C_a n_v + C_d d) (integral of w over the hemisphere is pi n_v).
    Sh2Radiance sh;
    for (int k = 0; k < 3; ++k) {
        const double ca = l.c_a[k], cd = l.c_d[k];
        const Vec3 v = kPi * (Vec3{0, 0, ca} + cd * l.d);
        sh[0][k] = static_cast<float>(std::sqrt(kPi) * (ca + cd / 2));
        sh[1][k] = static_cast<float>(-kY1 * v.y);
        sh[2][k] = static_cast<float>(kY1 * v.z);
        sh[3][k] = static_cast<float>(-kY1 * v.x);
    }
    return sh;
}
Sh2Radiance irradz_to_linear_sh(const IrradZ& p) { return hhd_to_linear_sh(to_lighting(p)); }

ChannelHhd linear_sh_to_hhd_channel(double l0, double l1m1, double l10, double l1p1) {
    // b_c = 2 l0 / sqrt(pi) = 2 C_a + C_d;  b = L1 / (kY1 pi) = C_a n_v + C_d d.
    const double s = 1.0 / (kY1 * kPi);  // = 2 / sqrt(3 pi)
    const double bc = 2.0 * l0 / std::sqrt(kPi);
    const Vec3 b{-l1p1 * s, -l1m1 * s, l10 * s};
    const double iz = b.z;  // I_z = b . n_v
    // |b - C_a n_v|^2 = (b_c - 2 C_a)^2  =>  3 C_a^2 - 2 (2 b_c - I_z) C_a + (b_c^2 - |b|^2) = 0;
    // the smaller root is C_a for every valid HHD (the other is C_a + C_d (4 - 2 d_z) / 3).
    const double q = 2 * bc - iz;
    const double disc = std::max(0.0, q * q - 3 * (bc * bc - dot(b, b)));
    ChannelHhd h;
    h.c_a = std::max(0.0, (q - std::sqrt(disc)) / 3);
    const Vec3 v = b - Vec3{0, 0, h.c_a};
    h.c_d = length(v);
    h.d = h.c_d > 1e-30 ? (1.0 / h.c_d) * v : Vec3{0, 0, 1};
    return h;
}

IrradZ linear_sh_to_irradz(const Sh2Radiance& sh, const LuminanceWeights& w) {
    const ChannelHhd lum =
        linear_sh_to_hhd_channel(luminance(sh[0], w), luminance(sh[1], w), luminance(sh[2], w), luminance(sh[3], w));
    const double s = 1.0 / (kY1 * kPi);
    IrradZ p;
    for (int k = 0; k < 3; ++k) p.i_z[k] = static_cast<float>(std::max(0.0, double(sh[2][k]) * s));
    const double iz_lum = luminance(sh[2], w) * s;
    p.d = clamp_to_hemisphere(lum.d);
    p.w_a = iz_lum > 0 ? std::clamp(lum.c_a / iz_lum, 0.0, 1.0) : 1.0;
    return p;
}

IrradZ blend_linear_sh(std::span<const IrradZ> texels, std::span<const double> weights) {
    double acc[4][3] = {};
    for (size_t t = 0; t < texels.size() && t < weights.size(); ++t) {
        const Sh2Radiance sh = irradz_to_linear_sh(texels[t]);
        for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k) acc[i][k] += weights[t] * sh[i][k];
    }
    Sh2Radiance sum;
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) sum[i][k] = static_cast<float>(acc[i][k]);
    return linear_sh_to_irradz(sum);
}

IrradZ blend_parameters(std::span<const IrradZ> texels, std::span<const double> weights) {
    double iz[3] = {}, wa = 0, wsum = 0;
    Vec3 d{0, 0, 0};
    for (size_t t = 0; t < texels.size() && t < weights.size(); ++t) {
        for (int k = 0; k < 3; ++k) iz[k] += weights[t] * texels[t].i_z[k];
        wa += weights[t] * texels[t].w_a;
        wsum += weights[t];
        d = d + weights[t] * texels[t].d;
    }
    IrradZ p;
    for (int k = 0; k < 3; ++k) p.i_z[k] = static_cast<float>(iz[k]);
    p.w_a = wsum > 0 ? std::clamp(wa / wsum, 0.0, 1.0) : 1.0;
    p.d = clamp_to_hemisphere(d);
    return p;
}

}  // namespace zhc::irradz
