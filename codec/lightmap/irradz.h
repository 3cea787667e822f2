// zhc/codec/lightmap/irradz.h — IrradZ directional lightmaps (Roughton, SIGGRAPH 2024 Advances talk,
// on hemispherical lighting): the AHD and HHD lighting models, the IrradZ parameterisation (I_z, w_a, d), the
// hemispherical least-squares encoder, closed-form linear SH -> HHD, lightmap blending in linear SH,
// and the HLSH hemisphere / cone multiply. Derivations: docs/irradz.md.
//
// Frames: everything per texel is in the TANGENT frame, surface (hemisphere) normal n_v = +Z.
// This is the lightmap hub (per-texel SH3 radiance in tangent frame); it is separate from the probe
// codec table (codec/probe/codec.h), which is for world-space probes.
//
// Standard library only; no I/O.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "codec/sh/sh.h"

namespace zhc::irradz {

// ---- models --------------------------------------------------------------------------------

enum class Model {
    kHhd,  // E(n) = C_a (1 + n_v.n) / 2 + C_d max(0, n.d)   (hemisphere + highlight direction)
    kAhd,  // E(n) = C_a + C_d max(0, n.d)                    (ambient + highlight direction)
};

// Model parameters in colour form.
struct Lighting {
    Rgb c_a, c_d;
    Vec3 d{0, 0, 1};  // unit highlight direction (tangent frame)
};

// The stored parameterisation. I_z = E(n_v) is held exact; w_a blends between the hemisphere (or
// ambient) term and the directional term:  C_a = w_a I_z,  C_d = (1 - w_a) I_z / d_z.
struct IrradZ {
    Rgb i_z;
    double w_a = 1.0;     // [0, 1]
    Vec3 d{0, 0, 1};      // unit, d_z >= kMinDz (upper hemisphere)
};

// Directions are kept at least this far above the horizon (theta <= 85 degrees) so that
// C_d = (1 - w_a) I_z / d_z stays bounded (<= 11.5 I_z).
inline const double kMaxTheta = 85.0 * kPi / 180.0;
inline const double kMinDz = std::cos(kMaxTheta);

Lighting to_lighting(const IrradZ& p);
// Irradiance of the model at unit normal n (tangent frame).
Rgb evaluate(const Lighting& l, Model model, Vec3 n);
Rgb evaluate(const IrradZ& p, Model model, Vec3 n);

// ---- hemispherical quadrature and Gram matrices --------------------------------------------

// Integral over the spherical cap {w : w_z >= cos_alpha} of Y_i(w) Y_j(w) (SH3 basis, row-major
// 9x9). cos_alpha = 0 is the upper hemisphere (the "hemispherical Gram matrix"), -1 the sphere (I).
// Computed with a product rule (Gauss-Legendre in z, uniform in phi) that is exact for these
// polynomials.
std::array<double, 81> cap_gram(double cos_alpha);
const std::array<double, 81>& hemisphere_gram();

// ---- encoder -------------------------------------------------------------------------------

enum class Solve {
    kNewton,  // the same least squares, d by Newton on the analytic reduced error (default)
    kSearch,  // talk: w_a by least squares with the hemispherical Gram matrix, d by golden-section
    kTalkBaseline,  // the talk's baseline, its "old way": optimal linear direction + spherical Gram matrix (identity)
};

struct EncodeOptions {
    Model model = Model::kHhd;
    Solve solve = Solve::kNewton;
    int newton_iterations = 12;   // Newton steps at most (each with a backtracking line search)
    double newton_tolerance = 1e-4;  // a Newton step shorter than this (stereographic units, about
                                     // 2e-4 rad) is taken without a check and ends the solve
    int scan_steps = 8;           // coarse theta samples before golden-section (bracketing)
    int golden_iterations = 16;   // golden-section steps (bracket shrinks by 0.618^16 ~ 5e-4)
    int azimuth_rounds = 1;       // phi-then-theta refinement rounds after the talk's theta search
    LuminanceWeights luminance;   // azimuth of the search plane from the luminance L1 band
};

// SH3 irradiance coefficients (per channel) of the model, i.e. the model projected onto SH3.
// The clamped-cosine term is projected with Funk-Hecke (pi * {1, 2/3, 1/4} * Y_i(d)).
Sh3Irradiance model_sh3(const IrradZ& p, Model model);

// Hemispherical error of `p` against the SH3 irradiance `target` measured in SH3:
// sum over RGB of (t - m)^T G_hemi (t - m), m = model_sh3(p).
double sh_hemispherical_error(const Sh3Irradiance& target, const IrradZ& p, Model model);

// True hemispherical mean squared error (per channel, summed over RGB) of the model against the SH3
// irradiance: (1 / 2pi) * integral over z >= 0 of |T(n) - E_model(n)|^2, by a fixed 16 x 32
// product rule (Gauss-Legendre in z, uniform in phi). Used by the audit and the tests.
double hemispherical_mse(const Sh3Irradiance& target, const IrradZ& p, Model model);

// Fit IrradZ to per-texel SH3 radiance in the tangent frame. `error` (optional) receives the
// SH-space hemispherical error of the result. I_z is the SH3 irradiance at the normal unless the
// baker sampled it directly (`sampled_iz`, the talk's "directly sample I_z in the bake").
IrradZ encode(const Sh3Radiance& tangent_radiance, const EncodeOptions& options = {},
              double* error = nullptr, const Rgb* sampled_iz = nullptr);
// encode() of n texels into out[0 .. n), the same results bit for bit; with Solve::kNewton the
// texels' evaluations run four at a time in vector lanes (give it a few dozen texels at once). Its
// workspace is per thread: threads may call it concurrently.
void encode_many(const Sh3Radiance* tangent_radiance, std::size_t n, const EncodeOptions& options, IrradZ* out);

// The reduced error the Newton solve minimises, at the gnomonic direction q = (d_x, d_y) / d_z:
// psi(q) = min over s = 1 - w_a in [0, 1] of |m - u|_G^2 (u the I_z-weighted colour average of the
// target; the SH-space error is C + S psi, S = sum_k I_k^2), with its analytic gradient and Hessian
// in q (hess: xx, xy, yy; the reduced Hessian, s eliminated where it is not clamped). Exposed for
// the tests (finite differences, the general error).
struct ReducedError {
    double psi = 0, s = 0;
    double grad[2] = {0, 0}, hess[3] = {0, 0, 0};
};
ReducedError reduced_error(const Sh3Irradiance& target, Model model, double qx, double qy, const Rgb* sampled_iz = nullptr);

// For a fixed direction d: I_z from the target, w_a by least squares under Gram matrix `gram`
// (hemisphere or identity), clamped to [0, 1]. Exposed for the tests (brute-force twin).
IrradZ solve_w_a(const Sh3Irradiance& target, Vec3 d, Model model, const std::array<double, 81>& gram);

// ---- linear SH <-> HHD (talk slide "HHD and linear SH", re-derived in docs/irradz.md) -------

// Linear SH (SH2 radiance) of the radiance an HHD stands for: a constant hemisphere light of
// radiance C_a over n_v's hemisphere plus a delta light of integral pi C_d from d.
Sh2Radiance hhd_to_linear_sh(const Lighting& l);
Sh2Radiance irradz_to_linear_sh(const IrradZ& p);
// Closed form back, per channel (each channel its own d); exact for valid HHD (C_a, C_d >= 0).
struct ChannelHhd {
    double c_a = 0, c_d = 0;
    Vec3 d{0, 0, 1};
};
ChannelHhd linear_sh_to_hhd_channel(double l0, double l1m1, double l10, double l1p1);
// To IrradZ (one shared d, w_a): d and w_a from the luminance channel, I_z per channel from L1.
// Exact for IrradZ-valid HHD (same d and w_a in all channels).
IrradZ linear_sh_to_irradz(const Sh2Radiance& sh, const LuminanceWeights& w = {});

// Blend several lightmap texels with weights: in linear SH then solved back (the talk's method),
// or by blending the parameters directly (I_z, w_a lerp; d normalised lerp) for comparison.
IrradZ blend_linear_sh(std::span<const IrradZ> texels, std::span<const double> weights);
IrradZ blend_parameters(std::span<const IrradZ> texels, std::span<const double> weights);

// ---- HLSH hemisphere and cone multiply (probe occlusion) ----------------------------------

// HLSH: I(m) = I_z m_z + C_a (1 - m_z) + c_x m_x + c_y m_y with m in the frame of the normal.
struct Hlsh {
    Rgb i_z, c_a, c_x, c_y;
};
Rgb evaluate(const Hlsh& h, Vec3 m_tangent);

// Radiance times the cap {w . n >= cos_alpha}, projected back onto SH3: o = G_cap L in the frame of
// n (cos_alpha = 0: the hemisphere multiply). Result in the tangent frame of `frame` (n = +Z).
Sh3Radiance cap_multiply(const Sh3Radiance& tangent_radiance, double cos_alpha);

// From SH3 radiance (world frame), the frame of the normal (third column = n, see frame_from_z)
// and the cone's cos_alpha: I_z = occluded SH3 irradiance at n (exact constraint); C_a, c_x, c_y by
// least squares over the normal's hemisphere against the occluded SH3 irradiance.
Hlsh hlsh_multiply(const Sh3Radiance& world_radiance, const Mat3& frame, double cos_alpha);

}  // namespace zhc::irradz
