// zhc/codec/lightmap/irradz_internal.h — internal to codec/: what the IrradZ files share: 9-vector
// helpers, the constant tables (the hemisphere and ambient terms in SH3, the hemispherical Gram
// matrix and its sparsity, the HLSH projections; irradz.cpp), the clamped-cosine SH3 projection
// (Funk-Hecke), the stored direction range, and the Newton solve for encode().
//
// Source: Roughton, "IrradZ" (SIGGRAPH 2024 Advances in Real-Time Rendering talk);
// the slide formulas are re-derived in docs/irradz.md.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "codec/lightmap/irradz.h"

namespace zhc::irradz::detail {

using Vec9 = std::array<double, 9>;
using Mat9 = std::array<double, 81>;

inline double dot9(const Vec9& a, const Vec9& b) {
    double s = 0;
    for (int i = 0; i < 9; ++i) s += a[static_cast<size_t>(i)] * b[static_cast<size_t>(i)];
    return s;
}
inline Vec9 mul(const Mat9& g, const Vec9& v) {
    Vec9 r{};
    for (int i = 0; i < 9; ++i) {
        double s = 0;
        for (int j = 0; j < 9; ++j) s += g[static_cast<size_t>(i * 9 + j)] * v[static_cast<size_t>(j)];
        r[static_cast<size_t>(i)] = s;
    }
    return r;
}

// Constant tables: SH3 irradiance coefficients of the hemisphere light (1 + z)/2 and of the
// constant 1, and the HLSH projection vectors over the upper hemisphere.
struct Tables {
    Vec9 hemi{}, ambient{};
    Vec9 g_hemi_hemi{}, g_hemi_ambient{};  // G_hemi times the two constant terms
    // Non-zero entries of G_hemi: over z >= 0 the phi integral only pairs basis functions of the
    // same m (and sin/cos type), so 19 of the 81 entries are non-zero.
    std::array<std::uint8_t, 81> nz_i{}, nz_j{};
    int nnz = 0;
    Vec9 p_one_minus_z{}, p_x{}, p_y{};  // integral over z >= 0 of Y_i * (1 - z), Y_i x, Y_i y
    Vec9 y_up{};                         // Y_i(+Z)
    Mat9 g_hemi{}, g_sphere{};
};
const Tables& tables();

// SH3 irradiance coefficients of max(0, n.d): Funk-Hecke, pi * {1, 2/3, 1/4}_l * Y_i(d).
inline Vec9 clamped_cosine_sh(Vec3 d) {
    const auto y = sh3_basis(d);
    Vec9 r{};
    for (int i = 0; i < 9; ++i) {
        const int l = i == 0 ? 0 : (i < 4 ? 1 : 2);
        r[static_cast<size_t>(i)] = kPi * kIrradianceBandScale[l] * y[static_cast<size_t>(i)];
    }
    return r;
}

inline Vec3 direction_from_angles(double theta, double phi) {
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// Keeps d in the stored range: d_z >= kMinDz, azimuth kept.
inline Vec3 clamp_to_hemisphere(Vec3 d) {
    d = normalize_or(d, {0, 0, 1});
    if (d.z >= kMinDz) return d;
    const double phi = std::atan2(d.y, d.x);
    return direction_from_angles(kMaxTheta, phi);
}

// The Newton solve of d and w_a (Solve::kNewton; irradz_newton.cpp): the fit of one texel, its
// SH-space hemispherical error in `error` (optional).
IrradZ fit_newton(const Sh3Irradiance& irr, Model model, const EncodeOptions& options, double* error,
                  const Rgb* sampled_iz);
// fit_newton of n texels (no sampled I_z, no error), the same results bit for bit: their evaluations
// of psi run four at a time in the lanes of a vector, in the AVX2 build where the CPU has AVX2 and
// `allow_avx2` (false: the baseline build, for the tests).
void fit_newton_many(const Sh3Irradiance* irr, std::size_t n, Model model, const EncodeOptions& options, IrradZ* out,
                     bool allow_avx2 = true);

}  // namespace zhc::irradz::detail
