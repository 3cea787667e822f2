// zhc/formats/envmap/envmap_ldr.h — the 8-bit (LDR) and packed-float texel decoders the cube-map
// readers (envmap_cube.cpp) share: BC1, BC2 and BC3 blocks (written from the Khronos Data Format
// Specification's "S3TC Compressed Texture Image Formats" section and Microsoft's "Block
// Compression (Direct3D 10)" page), the sRGB EOTF, B10G11R11 unsigned floats, and the HDR-in-LDR
// encodings (RGBM, RGBD) selected by EnvmapReadOptions::ldr.
#pragma once

#include <cstdint>

#include "formats/envmap/envmap.h"

namespace zhc::ldr {

// One 4x4 block to 16 RGBA texels (row-major, values in [0, 1], the block's encoded values: no
// transfer function applied). BC1: four-colour mode when colour0 > colour1 (as 16-bit numbers),
// else three colours plus index 3 = black with alpha 0 when `bc1_alpha`, opaque black otherwise.
// BC2: explicit 4-bit alpha + BC1 colour in four-colour mode. BC3: interpolated alpha (6 or 4
// interpolated values) + BC1 colour in four-colour mode. Interpolation is exact (in float): the
// Data Format Specification's ratios, without the rounding to 8 bits some hardware does.
void decode_bc1(const std::uint8_t block[8], bool bc1_alpha, float rgba[16][4]);
void decode_bc2(const std::uint8_t block[16], float rgba[16][4]);
void decode_bc3(const std::uint8_t block[16], float rgba[16][4]);

// IEC 61966-2-1 sRGB EOTF (exact piecewise form), v in [0, 1].
float srgb_to_linear(float v);

// B10G11R11_UFLOAT_PACK32 / R11G11B10_FLOAT / GL_R11F_G11F_B10F (UNSIGNED_INT_10F_11F_11F_REV):
// R bits 0-10, G 11-21 (5-bit exponent, 6-bit mantissa), B 22-31 (5-bit exponent, 5-bit mantissa),
// no sign, bias 15; exponent 31 is Inf (mantissa 0) or NaN.
void decode_r11g11b10(std::uint32_t v, float out[3]);

// Radiance of one texel from its encoded RGBA (in [0, 1]) by the encoding `d` and the format's
// transfer function (`format_srgb`): kAsFormat decodes rgb by the format's transfer function,
// kSrgb / kLinear force one; kRgbm: T(rgb) * a * range; kRgbd: T(rgb) * (range / 255) / a, where
// T is the format's transfer function and alpha is always linear. False (out untouched) for RGBD
// with a == 0 (no radiance is encoded: the encoders never write it).
bool decode_ldr_texel(const float rgba[4], bool format_srgb, const LdrDecoding& d, float out[3]);

}  // namespace zhc::ldr
