// zhc/codec/probe/zh3_channel_q16.h — ZH3 on per-channel axes in the 16-byte zh3_q16 layout.
//
// Two codec-table entries (zh3_channel_q16_codecs(), appended last to the table):
//   zh3_channel_q16         zh3_q16 bytes decoded with each channel's own zonal axis (the axis of
//                           the channel's decoded L1, ZH3 paper Sec. 3.1); encoder: L1 ratios, then
//                           the zonal refitted along the decoder's axis (Eq. 9) and quantised.
//   zh3_solved_channel_q16  the same bytes and decoder; the encoder searches the stored codes: per
//                           channel, the three L1 codes and the zonal code that minimise the Eq. 11
//                           error of what the DECODER reconstructs (its axis follows the decoded L1).
// Both fix the axis per channel: the container's axis_mode does not apply to them.
// Bytes, search and measurements: docs/quantization.md ("zh3_channel_q16").
#pragma once

#include <array>
#include <cstdint>

#include "codec/probe/quantize.h"

namespace zhc {

// One channel's search problem, in ratio units (coefficient / decoded DC of the channel), so it
// does not depend on the lighting's magnitude:
//   E(codes) = w1 |L1(codes) - t1|^2 + w2 |z(code) Y2'(axis(L1(codes))) - t2|^2,
// with t1 the target L1 ratios (SH indices 1, 2, 3), t2 the target L2 ratios (indices 4..8),
// Y2' = sqrt(4 pi / 5) Y2 (unit length), axis(L1) = normalize(-L11, -L1-1, L10) (+Z when zero),
// and w1, w2 the squared factors from the stored band to irradiance (Eq. 11 measures irradiance).
struct ChannelCodeProblem {
    std::array<double, 3> t1{};
    std::array<double, 5> t2{};
    double w1 = 1, w2 = 1;
};
struct ChannelCodes {
    std::array<std::uint8_t, 3> l1{};  // codes of SH indices 1, 2, 3
    std::uint8_t zonal = 0;
};

// E of given L1 codes with the best zonal code for them (nearest decoded zonal value to the
// least-squares fit along the decoder's axis: E is quadratic in it with unit curvature).
double channel_code_error(const ChannelCodeProblem& problem, const CodecOptions& params,
                          const std::array<std::uint8_t, 3>& l1, std::uint8_t* best_zonal);

// Descent over the L1 code grid from each start (every step moves to the best of the 26
// neighbours within +-1 code of each index while that lowers E), then the best zonal code.
// Returns the codes with the lowest E over all starts; *evaluations counts the E evaluations.
ChannelCodes solve_channel_codes(const ChannelCodeProblem& problem, const CodecOptions& params,
                                 const std::array<std::uint8_t, 3>* starts, int start_count, int* evaluations);

}  // namespace zhc
