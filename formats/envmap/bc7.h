// zhc/formats/envmap/bc7.h — BC7 (BPTC UNORM, D3D BC7_UNORM, Vulkan BC7_UNORM_BLOCK / BC7_SRGB_BLOCK)
// block decoder for 8-bit cube maps, written from the Khronos Data Format Specification's "BPTC
// Compressed Texture Image Formats" section (BC7): the mode table (subsets, partition bits,
// rotation, index selection, colour / alpha bits, endpoint and shared P-bits, index bits), the
// 2- and 3-subset partition tables with their anchor indices, the 2/3/4-bit interpolation weights
// and ((64 - w) E0 + w E1 + 32) >> 6. A block whose low byte is 0 (the reserved mode) decodes to
// 0 in every channel of every texel, as the specification asks of hardware decoders.
#pragma once

#include <cstdint>

namespace zhc::bc7 {

// The mode of a block (0-7), or 8 for the reserved mode (low byte 0).
int block_mode(const std::uint8_t block[16]);

// One 16-byte block to 16 texels (row-major, texel t at x = t % 4, y = t / 4) of 8-bit RGBA, the
// values the block encodes (no transfer function applied: the sRGB variant stores the same bits).
void decode_block(const std::uint8_t block[16], std::uint8_t rgba[16][4]);

}  // namespace zhc::bc7
