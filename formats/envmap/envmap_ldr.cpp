// 8-bit and packed-float texel decoders for cube maps (formats/envmap/envmap_ldr.h). Written from
// the Khronos Data Format Specification 1.3 ("S3TC Compressed Texture Image Formats": BC1, BC2,
// BC3; "Unsigned 11-bit / 10-bit floating-point numbers"), IEC 61966-2-1 (sRGB) and, for RGBM /
// RGBD, three.js's RGBMToLinear / RGBDToLinear (docs/inputs.md cites them).
#include "formats/envmap/envmap_ldr.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace zhc {

namespace {
constexpr float kMaxRange = 65504.0f;
}

bool parse_ldr_decoding(const std::string& text, LdrDecoding* out) {
    LdrDecoding d;
    if (text == "auto") d.encoding = LdrEncoding::kAsFormat;
    else if (text == "srgb") d.encoding = LdrEncoding::kSrgb;
    else if (text == "linear") d.encoding = LdrEncoding::kLinear;
    else if (text.rfind("rgbm:", 0) == 0 || text.rfind("rgbd:", 0) == 0) {
        d.encoding = text[3] == 'm' ? LdrEncoding::kRgbm : LdrEncoding::kRgbd;
        const std::string num = text.substr(5);
        if (num.empty() || num.size() > 32) return false;
        char* end = nullptr;
        const double v = std::strtod(num.c_str(), &end);
        if (end != num.c_str() + num.size() || !std::isfinite(v) || v <= 0 || v > kMaxRange) return false;
        d.range = static_cast<float>(v);
    } else {
        return false;
    }
    if (out) *out = d;
    return true;
}

std::string ldr_decoding_name(const LdrDecoding& d) {
    switch (d.encoding) {
        case LdrEncoding::kAsFormat: return "auto";
        case LdrEncoding::kSrgb: return "srgb";
        case LdrEncoding::kLinear: return "linear";
        default: {
            char buf[48];
            std::snprintf(buf, sizeof buf, "%s:%g", d.encoding == LdrEncoding::kRgbm ? "rgbm" : "rgbd", static_cast<double>(d.range));
            return buf;
        }
    }
}

namespace ldr {

namespace {
// RGB565 (red in the high bits) to [0, 1] per channel.
void unpack565(std::uint16_t c, float out[3]) {
    out[0] = static_cast<float>((c >> 11) & 31) / 31.0f;
    out[1] = static_cast<float>((c >> 5) & 63) / 63.0f;
    out[2] = static_cast<float>(c & 31) / 31.0f;
}

// The colour half of a BC1/2/3 block (8 bytes) into rgba[..][0..2] (and alpha for BC1).
void decode_colour(const std::uint8_t* b, bool four_colour_always, bool bc1_alpha, float rgba[16][4]) {
    const std::uint16_t c0 = static_cast<std::uint16_t>(b[0] | (b[1] << 8)), c1 = static_cast<std::uint16_t>(b[2] | (b[3] << 8));
    float pal[4][4];
    unpack565(c0, pal[0]);
    unpack565(c1, pal[1]);
    pal[0][3] = pal[1][3] = pal[2][3] = pal[3][3] = 1.0f;
    if (four_colour_always || c0 > c1) {
        for (int k = 0; k < 3; ++k) {
            pal[2][k] = (2.0f * pal[0][k] + pal[1][k]) / 3.0f;
            pal[3][k] = (pal[0][k] + 2.0f * pal[1][k]) / 3.0f;
        }
    } else {
        for (int k = 0; k < 3; ++k) {
            pal[2][k] = (pal[0][k] + pal[1][k]) / 2.0f;
            pal[3][k] = 0.0f;
        }
        if (bc1_alpha) pal[3][3] = 0.0f;
    }
    const std::uint32_t idx = std::uint32_t(b[4]) | std::uint32_t(b[5]) << 8 | std::uint32_t(b[6]) << 16 | std::uint32_t(b[7]) << 24;
    for (int i = 0; i < 16; ++i) {
        const float* p = pal[(idx >> (2 * i)) & 3];
        for (int k = 0; k < 4; ++k) rgba[i][k] = p[k];
    }
}
}  // namespace

void decode_bc1(const std::uint8_t block[8], bool bc1_alpha, float rgba[16][4]) { decode_colour(block, false, bc1_alpha, rgba); }

void decode_bc2(const std::uint8_t block[16], float rgba[16][4]) {
    decode_colour(block + 8, true, false, rgba);
    for (int i = 0; i < 16; ++i) rgba[i][3] = static_cast<float>((block[i / 2] >> (4 * (i % 2))) & 15) / 15.0f;
}

void decode_bc3(const std::uint8_t block[16], float rgba[16][4]) {
    decode_colour(block + 8, true, false, rgba);
    const float a0 = block[0] / 255.0f, a1 = block[1] / 255.0f;
    float pal[8] = {a0, a1, 0, 0, 0, 0, 0, 0};
    if (block[0] > block[1]) {
        for (int k = 2; k < 8; ++k) pal[k] = (static_cast<float>(8 - k) * a0 + static_cast<float>(k - 1) * a1) / 7.0f;
    } else {
        for (int k = 2; k < 6; ++k) pal[k] = (static_cast<float>(6 - k) * a0 + static_cast<float>(k - 1) * a1) / 5.0f;
        pal[6] = 0.0f;
        pal[7] = 1.0f;
    }
    std::uint64_t idx = 0;
    for (int k = 0; k < 6; ++k) idx |= std::uint64_t(block[2 + k]) << (8 * k);
    for (int i = 0; i < 16; ++i) rgba[i][3] = pal[(idx >> (3 * i)) & 7];
}

float srgb_to_linear(float v) {
    const double x = v;
    return static_cast<float>(x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4));
}

namespace {
// Unsigned float with a 5-bit exponent (bias 15) and an m-bit mantissa.
float ufloat(std::uint32_t e, std::uint32_t m, int mbits) {
    if (e == 31) return m == 0 ? INFINITY : NAN;
    if (e == 0) return std::ldexp(static_cast<float>(m), -14 - mbits);
    return std::ldexp(1.0f + std::ldexp(static_cast<float>(m), -mbits), static_cast<int>(e) - 15);
}
}  // namespace

void decode_r11g11b10(std::uint32_t v, float out[3]) {
    out[0] = ufloat((v >> 6) & 31, v & 63, 6);
    out[1] = ufloat((v >> 17) & 31, (v >> 11) & 63, 6);
    out[2] = ufloat((v >> 27) & 31, (v >> 22) & 31, 5);
}

bool decode_ldr_texel(const float rgba[4], bool format_srgb, const LdrDecoding& d, float out[3]) {
    const bool srgb = d.encoding == LdrEncoding::kSrgb || (format_srgb && d.encoding != LdrEncoding::kLinear);
    float c[3];
    for (int k = 0; k < 3; ++k) c[k] = srgb ? srgb_to_linear(rgba[k]) : rgba[k];
    float scale = 1.0f;
    if (d.encoding == LdrEncoding::kRgbm) scale = rgba[3] * d.range;
    if (d.encoding == LdrEncoding::kRgbd) {
        if (!(rgba[3] > 0.0f)) return false;
        scale = d.range / 255.0f / rgba[3];
    }
    for (int k = 0; k < 3; ++k) out[k] = c[k] * scale;
    return true;
}

}  // namespace ldr
}  // namespace zhc
