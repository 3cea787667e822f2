// zhc/codec/probe/zh3_hall_solve.h — hallucinate-solve and the adaptive hallucination scale.
//
// The decoders are the curve hallucination of the ZH3 paper (Roughton et al. 2024, Sec. 3.4.3,
// Eq. 21, Listing 1): from stored linear SH (DC f0, L1) the decoder derives the zonal axis a (the
// luminance L1, or each channel's own L1) and adds the zonal L2 coefficient
//     f20 = s (A p^2 + B p) f0,   p = clamp(|L1 . a| / f0, 0, sqrt 3)
// (A, B = CodecOptions::hallucinate_a/b; s = 1 is hall_curve). The encoders here choose the stored
// L1 that minimises the irradiance error AFTER that hallucination, instead of storing the target's
// L1 unchanged (the DC is kept exact). Derivation (docs/zh3.md "Hallucinate-solve"): for a fixed
// decoder axis a the best L1 is closed form per channel (the component across a as in the ZH3 solve's
// profile, the component along a the minimiser of a quartic in one variable), so the solve is a
// search over the axis only: candidate axes, then BFGS on the sphere.
//
// Codec-table entries (codec/probe/zh3_hall_solve.cpp, hall_solve_codecs()):
//   hall_solved        48 bytes, sh2's float layout; decodes exactly as hall_curve
//   hall_solved_q16    16 bytes, sh2_q's layout; decodes exactly as hall_curve_q
//   hall_adaptive_q16  16 bytes, sh2_q's layout with byte 15 = scale code (docs/quantization.md)
#pragma once

#include <cstdint>

#include "codec/probe/codec.h"
#include "codec/probe/quantize.h"
#include "codec/sh/sh.h"
#include "codec/probe/zh3.h"

namespace zhc {

// The audit's metric against an SH3 target, exactly: the squared L2 norm over the sphere of the
// irradiance difference, summed over the three channels (Parseval on the irradiance SH: band scales
// 1, 2/3, 1/4). The audit's RMSE against the true irradiance differs from this only by the target's
// own (fixed) truncation error above L2 and the quadrature. Units: irradiance^2 sr.
double irradiance_sq_error(const Sh3Radiance& target, const Sh3Radiance& decoded);

// Decoder: the linear SH plus the scaled Eq. 21 zonal term (f20 = ((s A) p^2 + (s B) p) f0) on
// `mode`'s axis, expanded to SH3 radiance. scale 1 is exactly hall_curve(_channel)'s decode.
Sh3Radiance hall_scaled_expand(const Sh2Radiance& linear, double scale, ZonalAxisMode mode, const CodecOptions& o);

// Encoder: the target's DC and the L1 minimising irradiance_sq_error(target, hall_scaled_expand(.)).
// Deterministic and scale-invariant (the solve runs on the target divided by a power of two near its
// magnitude). Never worse (float-exact, through hall_scaled_expand) than storing the target's own L1.
// stats->solver_iterations gets the BFGS iterations.
Sh2Radiance hall_solve(const Sh3Radiance& target, double scale, ZonalAxisMode mode, const CodecOptions& o,
                       EncodeStats* stats);

// The solve's profile (exposed for tests): the error of the best L1 whose decoder axis is the unit
// `axis` — for kLuminance the whole probe (channel ignored), for kPerChannel channel `channel` alone.
double hall_axis_profile(const Sh3Radiance& target, double scale, ZonalAxisMode mode, int channel, Vec3 axis,
                         const CodecOptions& o);

// ---- hall_adaptive_q16: the scale code in byte 15 of the sh2_q layout -------------------------

inline constexpr int kHallScaleCodeCount = 8;  // codes 0..7; larger byte values decode as 7
// s = 0.5 * code for codes 0..7 (0 = plain linear SH, 2 = the curve as fitted, 7 = 3.5x); the set is
// chosen by measurement (docs/zh3.md).
double hall_scale_of_code(std::uint8_t code);

}  // namespace zhc
