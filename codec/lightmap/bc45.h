// zhc/codec/lightmap/bc45.h — BC4 (one channel) and BC5 (two channels) UNORM encoders and decoders.
//
// Standard library only. A BC4 block is 8 bytes: endpoints r0, r1 (bytes 0, 1) and sixteen 3-bit
// indices (bytes 2..7, little-endian, texel 0 in the low bits). r0 > r1: eight-value palette
// r0, r1, (6 r0 + r1)/7 ... (r0 + 6 r1)/7; r0 <= r1: r0, r1, (4 r0 + r1)/5 ... (r0 + 4 r1)/5, 0, 1.
// BC5 is a BC4 block for red followed by one for green (16 bytes). Decoders are total (any bytes).
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace zhc::bc45 {

enum class Quality { kFast, kDefault };

// 16 values in [0, 1] (clamped; NaN -> 0), texel x + 4 y. Minimises the squared error against
// the float values (not against 8-bit-rounded ones).
void encode_bc4_block(const float v[16], Quality quality, std::uint8_t out[8]);
// Exact palette values (in [0, 1], the real-valued interpolation of the format).
void decode_bc4_block(const std::uint8_t in[8], float out[16]);
void encode_bc5_block(const float rg[16][2], Quality quality, std::uint8_t out[16]);
void decode_bc5_block(const std::uint8_t in[16], float out[16][2]);

namespace detail {
// encode_bc4_block's scalar twin: the same search with the plain per-texel index loop; the vector
// paths (AVX2, eight texels at a time; SSE2, four) give the same bytes (tested bit for bit).
void encode_bc4_block_scalar(const float v[16], Quality quality, std::uint8_t out[8]);
// The SSE2 path (four texels at a time), which encode_bc4_block takes where the CPU lacks AVX2 (eight).
void encode_bc4_block_sse2(const float v[16], Quality quality, std::uint8_t out[8]);
}  // namespace detail

// Whole images; `channels` interleaved floats per texel (1 for BC4, 2 for BC5); edge blocks
// replicate the last row/column. Deterministic whatever `threads` is.
std::vector<std::uint8_t> encode_image(const float* values, int channels, int width, int height, Quality quality,
                                       int threads = 1);
// Decodes `channels` (1: BC4, 2: BC5) interleaved floats per texel.
std::vector<float> decode_image(const std::uint8_t* blocks, std::size_t size, int channels, int width, int height);

}  // namespace zhc::bc45
