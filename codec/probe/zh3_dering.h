// zhc/codec/probe/zh3_dering.h — ZH3 deringing that keeps irradiance non-negative on the WHOLE sphere
// (zhc's extension; docs/zh3.md "Whole-sphere windowing").
//
// The ZH3 paper's App. B (zh3_dering) only bounds the zonal coefficient along the axis; when the
// linear band alone pulls irradiance below zero (small strong lights), no zonal value helps.
// Sloan 2017 windows the bands of SH3; this is the same idea for ZH3:
//
//  1. Per channel, irradiance / (Y00 f0) over the sphere reduces exactly to a function of the angle
//     theta to the zonal axis (the worst azimuth is analytic):
//        h(theta) = 1 + a cos(theta) - c sin(theta) + b (3 cos^2(theta) - 1)
//     a = 2 f1_zonal / (sqrt(3) f0),  c = 2 |f1_perp| / (sqrt(3) f0),  b = sqrt(5) f20 / (8 f0).
//     Its minimum is found by branch and bound with a certified lower bound (below), not sampled.
//  2. The least uniform window s in [0, 1] that scales the L1 band AND the zonal term of every
//     channel together with min >= margin: s = (1 - margin) / -min(h - 1) (closed form once the
//     minimum is known; one s for all channels keeps the luminance axis, which is derived from the
//     stored L1, unchanged). DC never changes.
//  3. Then each channel's zonal term moves back towards its unwindowed fit as far as the whole
//     sphere stays non-negative (the feasible zonal values form an interval: the minimum is
//     concave in the zonal coefficient), which only lowers the error.
//
// Quantised (zh3_dering_q16): the 16-byte encoder windows, quantises, DECODES and checks the
// decoded probe's certified minimum; while it is negative (quantisation moved the DC, the L1 or
// the decoder's axis) it windows further (quantize.cpp, QuantEncodeControls::dering).
#pragma once

#include "codec/probe/zh3.h"

namespace zhc {

// Certified minimum of h(theta) - 1 = a cos - c sin + b (3 cos^2 - 1) over all theta:
// lower <= true minimum <= upper (upper is attained at some theta), upper - lower <= tolerance
// unless the evaluation budget ran out (then lower is still a valid bound, only looser).
struct ProfileMinimum {
    double lower = 0, upper = 0;
};
ProfileMinimum zh3_profile_minimum(double a, double c, double b, double tolerance = 1e-10);

// Kept above zero by this fraction of each channel's Y00 f0, so float rounding of the stored
// coefficients (and of the runtime's evaluation) cannot push the minimum below zero.
inline constexpr double kZh3DeringMargin = 1.0 / (1 << 18);

// Certified lower bound of channel k's irradiance minimum over the sphere (absolute units).
double zh3_min_irradiance_bound(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w, int channel);

// The least uniform window s in [0, 1] (see above); 1 when the irradiance is already >= margin
// everywhere. 0 when a channel with DC <= 0 has non-zero bands (nothing else can help).
double zh3_dering_window_scale(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w);

// Applies the window (capped at max_scale) and the zonal refit of step 3. Returns the scale used.
double zh3_dering_window(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w, double max_scale = 1.0);

// Codec-table entries: zh3_dering (15 floats, as zh3_lum) and zh3_dering_q16 (zh3_q16 bytes).
std::span<const Codec> zh3_dering_codecs();

}  // namespace zhc
