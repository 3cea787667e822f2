// zhc_volume_layouts.hpp — GPU texture layouts for a probe grid (docs/runtime.md, "GPU volume
// layouts"): a load-time transcode of a zhc_volume (any encoding; every probe decoded to SH3 first)
// into the payloads of 3D textures that the GPU filters, and an exact CPU model of what a shader
// reconstructs from hardware-trilinear samples of them.
//
// Header-only C++17 on top of zhc_runtime.h. A layout is a list of textures of counts[0] x
// counts[1] x counts[2] texels (texel (x, y, z) = probe (x, y, z), row-major x fastest: the order a
// glTexImage3D / vkCmdCopyBufferToImage upload takes), each with 1, 3 or 4 components stored as
// float32, binary16 (half), 8-bit SNORM or RGB9_E5 (shared exponent). A hardware filter returns the
// trilinear blend of the stored (rounded) texel values:
//   filtered = sum_b w_b q(v_b),   w_b the weights of zhc_volume_sh3 (probes at texel centres,
//   clamp-to-edge), q the storage rounding (float32, half round-to-nearest-even, SNORM8
//   round(127 v) / 127, RGB9_E5 as GL/Vulkan specify it).
// Where the stored values are linear in the probe's SH3 (every layout but ratio8), that is the blend
// of the stored SH up to q (the *_l2lum / *_l2grey layouts then approximate colour L2 from the
// luminance L2 by design). The model blends the rounded
// values in double. Real GPUs also quantise the filter weights (commonly to 8 bits of the
// fractional texel coordinate) and filter in reduced precision: not modelled. ratio8 stores
// coefficient / DC ratios and multiplies the filtered ratio by the filtered DC, which is NOT the
// blend of the products: its error includes that covariance term (measured by bench_volume).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "zhc_runtime.h"

namespace zhc_layouts {

enum class Storage { kF32, kF16, kSnorm8, kRgb9e5 };

inline const char* storage_name(Storage s, int components) {
    if (s == Storage::kF32) return components == 4 ? "RGBA32F" : "R32F";
    if (s == Storage::kF16) return components == 4 ? "RGBA16F" : "R16F";
    if (s == Storage::kRgb9e5) return "RGB9_E5";
    return components == 4 ? "RGBA8_SNORM" : "R8_SNORM";
}

enum class Layout {
    kSh3F32,       // 27 SH3 floats in 7 RGBA32F (three.js's float atlas): 112 B, exact up to float
    kSh3F16,       // the same in 7 RGBA16F (three.js's binary16 atlas): 56 B
    kSh2F16,       // L0 + L1 RGB (12 floats) in 3 RGBA16F: 24 B
    kSh2L2GreyF16,  // L0 + L1 RGB in 3 RGBA16F + L2 of the luminance (5 floats) in 2 RGBA16F, added to every
                    // channel unscaled (three.js PR #33125's "L1 color + L2 greyscale"): 40 B
    kSh2L2LumF16,  // the same textures, L2 scaled per channel by the colour of the DC (L2_Y c_0k / Y_0): 40 B
    kRatio8,       // L0 RGB in RGBA16F + the 24 ratios c_ik / c_0k in 6 RGBA8_SNORM: 32 B (ratios filtered: biased)
    kSh3Rgb9e5,    // zhc: coefficient i of the 3 channels + offset_i L0 (>= 0) in RGB9_E5 texture i, 9 textures: 36 B
    kSh2Rgb9e5,    // zhc: the same for L0 + L1, 4 RGB9_E5: 16 B
    kSh2Rgb9e5L2Lum,  // zhc: 4 RGB9_E5 (L0 + L1) + L2 of the luminance + offset_i L0_Y in 2 RGB9_E5: 24 B
};
constexpr Layout kAllLayouts[] = {Layout::kSh3F32,      Layout::kSh3F16,   Layout::kSh2F16,    Layout::kSh2L2GreyF16,
                                  Layout::kSh2L2LumF16, Layout::kRatio8,   Layout::kSh3Rgb9e5, Layout::kSh2Rgb9e5,
                                  Layout::kSh2Rgb9e5L2Lum};

struct TextureSpec {
    Storage storage;
    int components;  // 1 or 4 (kRgb9e5: 3)
};
// Bytes of one texel.
inline std::size_t texel_bytes(TextureSpec t) {
    if (t.storage == Storage::kRgb9e5) return 4;
    return static_cast<std::size_t>(t.components) * (t.storage == Storage::kF32 ? 4 : (t.storage == Storage::kF16 ? 2 : 1));
}

inline const char* layout_name(Layout l) {
    switch (l) {
        case Layout::kSh3F32: return "sh3_rgba32f";
        case Layout::kSh3F16: return "sh3_rgba16f";
        case Layout::kSh2F16: return "sh2_rgba16f";
        case Layout::kSh2L2GreyF16: return "sh2_l2grey_rgba16f";
        case Layout::kSh2L2LumF16: return "sh2_l2lum_rgba16f";
        case Layout::kRatio8: return "ratio8";
        case Layout::kSh3Rgb9e5: return "sh3_rgb9e5";
        case Layout::kSh2Rgb9e5: return "sh2_rgb9e5";
        case Layout::kSh2Rgb9e5L2Lum: return "sh2_rgb9e5_l2lum";
    }
    return "?";
}

inline std::vector<TextureSpec> layout_textures(Layout l) {
    const TextureSpec h4{Storage::kF16, 4}, s4{Storage::kSnorm8, 4}, e3{Storage::kRgb9e5, 3};
    switch (l) {
        case Layout::kSh3F32: return std::vector<TextureSpec>(7, TextureSpec{Storage::kF32, 4});
        case Layout::kSh3F16: return std::vector<TextureSpec>(7, h4);
        case Layout::kSh2F16: return {h4, h4, h4};
        case Layout::kSh2L2GreyF16:
        case Layout::kSh2L2LumF16: return {h4, h4, h4, h4, h4};
        case Layout::kRatio8: return {h4, s4, s4, s4, s4, s4, s4};
        case Layout::kSh3Rgb9e5: return std::vector<TextureSpec>(9, e3);
        case Layout::kSh2Rgb9e5: return std::vector<TextureSpec>(4, e3);
        case Layout::kSh2Rgb9e5L2Lum: return std::vector<TextureSpec>(6, e3);
    }
    return {};
}

inline std::size_t layout_bytes_per_probe(Layout l) {
    std::size_t b = 0;
    for (const TextureSpec& t : layout_textures(l)) b += texel_bytes(t);
    return b;
}

// ---- storage rounding ------------------------------------------------------------------------

// binary16 bits of a float, round to nearest, ties to even (overflow: +-inf; NaN: a quiet NaN).
inline std::uint16_t float_to_half(float f) {
    std::uint32_t x;
    std::memcpy(&x, &f, 4);
    const std::uint16_t sign = static_cast<std::uint16_t>((x >> 16) & 0x8000u);
    const std::uint32_t mag = x & 0x7FFFFFFFu;
    if (mag > 0x7F800000u) return static_cast<std::uint16_t>(sign | 0x7E00u);
    if (mag >= 0x477FF000u) return static_cast<std::uint16_t>(sign | 0x7C00u);  // >= 65520: rounds to inf
    if (mag < 0x38800000u) {                                                      // below 2^-14: subnormal half
        // value = mag_float; half subnormal step 2^-24. Exact: |f| * 2^24 is representable in double.
        const double scaled = std::ldexp(static_cast<double>(std::fabs(f)), 24);
        const double r = std::nearbyint(scaled);  // default rounding mode: ties to even
        return static_cast<std::uint16_t>(sign | static_cast<std::uint16_t>(r));  // r <= 1024 -> 0x0400 (min normal)
    }
    // Normal: drop 13 mantissa bits with round to nearest even.
    const std::uint32_t rounded = mag + 0xFFFu + ((mag >> 13) & 1u);
    return static_cast<std::uint16_t>(sign | ((rounded >> 13) - (112u << 10)));
}

// SNORM8 code of v (clamped to [-1, 1]): round half away from zero, as GL/Vulkan specify
// (the tie case never changes the reconstructed value's error bound of 1/254).
inline std::int8_t snorm8(double v) {
    if (!(v > -1.0)) v = -1.0;  // NaN too
    if (v > 1.0) v = 1.0;
    return static_cast<std::int8_t>(std::lround(v * 127.0));
}
inline double snorm8_value(std::int8_t c) { return c < -127 ? -1.0 : c / 127.0; }

// RGB9_E5 bits of three values (EXT_texture_shared_exponent / Vulkan's
// VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 conversion: N = 9 mantissa bits, bias 15, each value clamped to
// [0, (511/512) 2^16] (NaN: 0), shared exponent from the largest, round half up). Decode:
// zhc_unpack_rgb9e5.
inline std::uint32_t pack_rgb9e5(const double rgb[3]) {
    const double kMax = 511.0 / 512.0 * 65536.0;
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = rgb[k] > 0 ? (rgb[k] < kMax ? rgb[k] : kMax) : 0.0;
    const double mx = std::fmax(c[0], std::fmax(c[1], c[2]));
    int e = 0;  // exp_shared_p = max(-B - 1, floor(log2 mx)) + 1 + B
    if (mx > 0) {
        int ex;
        std::frexp(mx, &ex);  // mx = m 2^ex, m in [0.5, 1): floor(log2 mx) = ex - 1
        e = std::max(-16, ex - 1) + 16;
    }
    if (std::floor(mx / std::ldexp(1.0, e - 24) + 0.5) == 512.0) ++e;
    std::uint32_t bits = static_cast<std::uint32_t>(e) << 27;
    for (int k = 0; k < 3; ++k) bits |= static_cast<std::uint32_t>(std::floor(c[k] / std::ldexp(1.0, e - 24) + 0.5)) << (9 * k);
    return bits;
}

// ---- the transcode ----------------------------------------------------------------------------

// Ratio intervals (non-negative radiance: |c_lm| <= max|Y_lm| / Y_00 c_00): L1 +-sqrt(3); L2 zonal
// (index 6) [-sqrt(5)/2, sqrt(5)]; other L2 +-sqrt(15)/2. Mapped affinely to [-1, 1].
inline void ratio_interval(int i, double* lo, double* hi) {
    if (i < 4) {
        *lo = -std::sqrt(3.0);
        *hi = std::sqrt(3.0);
    } else if (i == 6) {
        *lo = -std::sqrt(5.0) / 2;
        *hi = std::sqrt(5.0);
    } else {
        *lo = -std::sqrt(15.0) / 2;
        *hi = std::sqrt(15.0) / 2;
    }
}
inline double ratio_to_unit(int i, double r) {
    double lo, hi;
    ratio_interval(i, &lo, &hi);
    return (2 * r - (lo + hi)) / (hi - lo);
}
inline double unit_to_ratio(int i, double u) {
    double lo, hi;
    ratio_interval(i, &lo, &hi);
    return (u * (hi - lo) + (lo + hi)) / 2;
}

// Offsets of the RGB9_E5 layouts: stored c_ik + offset_i c_0k, >= 0 for non-negative radiance
// (the lower ends of the intervals above; 0 for the DC). Linear in the SH, so the filter commutes.
inline double offset(int i) {
    if (i == 0) return 0.0;
    double lo, hi;
    ratio_interval(i, &lo, &hi);
    return -lo;
}

constexpr double kLumW[3] = {0.2126, 0.7152, 0.0722};  // Rec. 709, zhc's default luminance weights

// Value slots of one probe: texture t, component c at slot 4 t + c (at most 9 textures).
constexpr int kSlots = 36;

// The unrounded values of one probe's texels, in layout order (texture t, component c at
// slot 4 t + c; R-only textures take one slot). sh[i*3+k] as zhc_decode_probe.
inline void probe_values(Layout l, const float sh[27], double out[kSlots]) {
    for (int j = 0; j < kSlots; ++j) out[j] = 0.0;
    auto lum = [&](int i) { return kLumW[0] * sh[i * 3] + kLumW[1] * sh[i * 3 + 1] + kLumW[2] * sh[i * 3 + 2]; };
    auto ratio = [](double c, double dc) { return dc > 0 ? c / dc : 0.0; };
    switch (l) {
        case Layout::kSh3F32:
        case Layout::kSh3F16:
            for (int j = 0; j < 27; ++j) out[j] = sh[j];
            return;
        case Layout::kSh2F16:
            for (int j = 0; j < 12; ++j) out[j] = sh[j];
            return;
        case Layout::kSh2L2GreyF16:
        case Layout::kSh2L2LumF16:
            for (int j = 0; j < 12; ++j) out[j] = sh[j];
            for (int i = 4; i < 9; ++i) out[12 + i - 4] = lum(i);
            return;
        case Layout::kRatio8:
            for (int k = 0; k < 3; ++k) out[k] = sh[k];
            for (int i = 1; i < 9; ++i)
                for (int k = 0; k < 3; ++k) out[4 + (i - 1) * 3 + k] = ratio_to_unit(i, ratio(sh[i * 3 + k], sh[k]));
            return;
        case Layout::kSh3Rgb9e5:
        case Layout::kSh2Rgb9e5:
        case Layout::kSh2Rgb9e5L2Lum: {
            const int bands = l == Layout::kSh3Rgb9e5 ? 9 : 4;
            for (int i = 0; i < bands; ++i)
                for (int k = 0; k < 3; ++k) out[4 * i + k] = double(sh[i * 3 + k]) + offset(i) * double(sh[k]);
            if (l == Layout::kSh2Rgb9e5L2Lum)
                for (int i = 4; i < 9; ++i) out[i < 7 ? 16 + i - 4 : 20 + i - 7] = lum(i) + offset(i) * lum(0);
            return;
        }
    }
}

// The SH3 radiance (27 doubles) a shader reconstructs from the filtered texel values v (slots as
// probe_values): the inverse of probe_values applied AFTER the filter.
inline void reconstruct_sh3(Layout l, const double v[kSlots], double sh[27]) {
    for (int j = 0; j < 27; ++j) sh[j] = 0.0;
    switch (l) {
        case Layout::kSh3F32:
        case Layout::kSh3F16:
            for (int j = 0; j < 27; ++j) sh[j] = v[j];
            return;
        case Layout::kSh2F16:
            for (int j = 0; j < 12; ++j) sh[j] = v[j];
            return;
        case Layout::kSh2L2GreyF16:
            for (int j = 0; j < 12; ++j) sh[j] = v[j];
            for (int i = 4; i < 9; ++i)
                for (int k = 0; k < 3; ++k) sh[i * 3 + k] = v[12 + i - 4];
            return;
        case Layout::kSh2L2LumF16: {
            for (int j = 0; j < 12; ++j) sh[j] = v[j];
            const double y0 = kLumW[0] * v[0] + kLumW[1] * v[1] + kLumW[2] * v[2];
            for (int i = 4; i < 9; ++i)
                for (int k = 0; k < 3; ++k) sh[i * 3 + k] = y0 > 0 ? v[12 + i - 4] * v[k] / y0 : 0.0;
            return;
        }
        case Layout::kRatio8:
            for (int k = 0; k < 3; ++k) sh[k] = v[k];
            for (int i = 1; i < 9; ++i)
                for (int k = 0; k < 3; ++k) sh[i * 3 + k] = unit_to_ratio(i, v[4 + (i - 1) * 3 + k]) * v[k];
            return;
        case Layout::kSh3Rgb9e5:
        case Layout::kSh2Rgb9e5:
        case Layout::kSh2Rgb9e5L2Lum: {
            const int bands = l == Layout::kSh3Rgb9e5 ? 9 : 4;
            for (int i = 0; i < bands; ++i)
                for (int k = 0; k < 3; ++k) sh[i * 3 + k] = v[4 * i + k] - offset(i) * v[k];
            if (l == Layout::kSh2Rgb9e5L2Lum) {
                const double y0 = kLumW[0] * v[0] + kLumW[1] * v[1] + kLumW[2] * v[2];
                for (int i = 4; i < 9; ++i) {
                    const double y = v[i < 7 ? 16 + i - 4 : 20 + i - 7] - offset(i) * y0;
                    for (int k = 0; k < 3; ++k) sh[i * 3 + k] = y0 > 0 ? y * v[k] / y0 : 0.0;
                }
            }
            return;
        }
    }
}

// The texture payloads of a volume in layout l: one byte vector per texture, counts[0] counts[1]
// counts[2] texels of `components` values each, little-endian float32 / binary16 bits / int8, ready
// for glTexImage3D(GL_TEXTURE_3D, 0, internal format, nx, ny, nz, 0, GL_RGBA or GL_RED,
// GL_FLOAT / GL_HALF_FLOAT / GL_BYTE, payload). Every probe is decoded with zhc_decode_probe.
// An invalid volume gives an empty vector.
inline std::vector<std::vector<std::uint8_t>> volume_textures(const zhc_volume& v, Layout l) {
    std::vector<std::vector<std::uint8_t>> out;
    if (!v.probes || v.probe_size == 0) return out;
    const std::size_t count = static_cast<std::size_t>(v.counts[0]) * v.counts[1] * v.counts[2];
    const std::vector<TextureSpec> tex = layout_textures(l);
    for (const TextureSpec& t : tex) out.emplace_back(count * texel_bytes(t));
    for (std::size_t p = 0; p < count; ++p) {
        float sh[27];
        double vals[kSlots];
        zhc_decode_probe(&v.format, v.probes + p * v.probe_size, sh);
        probe_values(l, sh, vals);
        for (std::size_t t = 0; t < tex.size(); ++t) {
            if (tex[t].storage == Storage::kRgb9e5) {
                const std::uint32_t bits = pack_rgb9e5(vals + 4 * t);
                for (int b = 0; b < 4; ++b) out[t][p * 4 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(bits >> (8 * b));
                continue;
            }
            const std::size_t comp_bytes = texel_bytes(tex[t]) / static_cast<std::size_t>(tex[t].components);
            for (int c = 0; c < tex[t].components; ++c) {
                const double x = vals[4 * t + static_cast<std::size_t>(c)];
                std::uint8_t* dst = out[t].data() + p * texel_bytes(tex[t]) + static_cast<std::size_t>(c) * comp_bytes;
                if (tex[t].storage == Storage::kF32) {
                    const float f = static_cast<float>(x);
                    std::memcpy(dst, &f, 4);
                } else if (tex[t].storage == Storage::kF16) {
                    const std::uint16_t h = float_to_half(static_cast<float>(x));
                    dst[0] = static_cast<std::uint8_t>(h & 0xFFu);
                    dst[1] = static_cast<std::uint8_t>(h >> 8);
                } else {
                    const std::int8_t s = snorm8(x);
                    std::memcpy(dst, &s, 1);
                }
            }
        }
    }
    return out;
}

// What the sampler returns for texel `index`, component c of texture t (the GPU's conversion to float).
inline double texel_value(const std::vector<std::uint8_t>& payload, TextureSpec t, std::size_t index, int c) {
    if (t.storage == Storage::kRgb9e5) {
        const std::uint8_t* q = payload.data() + index * 4;
        float rgb[3];
        zhc_unpack_rgb9e5(static_cast<std::uint32_t>(q[0]) | static_cast<std::uint32_t>(q[1]) << 8 |
                              static_cast<std::uint32_t>(q[2]) << 16 | static_cast<std::uint32_t>(q[3]) << 24,
                          rgb);
        return rgb[c];
    }
    const std::size_t comp_bytes = texel_bytes(t) / static_cast<std::size_t>(t.components);
    const std::size_t at = index * texel_bytes(t) + static_cast<std::size_t>(c) * comp_bytes;
    if (t.storage == Storage::kF32) {
        float f;
        std::memcpy(&f, payload.data() + at, 4);
        return f;
    }
    if (t.storage == Storage::kF16)
        return zhc_unpack_half(static_cast<std::uint16_t>(payload[at] | (payload[at + 1] << 8)));
    std::int8_t s;
    std::memcpy(&s, payload.data() + at, 1);
    return snorm8_value(s);
}

// The model of one shader sample: hardware trilinear filter of every texture at `position` (the
// weights of zhc_volume_sh3, blended in double), reconstruction, SH3 irradiance at the normalised
// normal (zero or non-finite: +Z), in double. `grid` supplies origin, spacing and counts.
inline void sample_sh3(const zhc_volume& grid, Layout l, const std::vector<std::vector<std::uint8_t>>& textures,
                       const double position[3], double sh[27]) {
    const std::vector<TextureSpec> tex = layout_textures(l);
    double vals[kSlots] = {0};
    std::uint32_t i0[3];
    double f[3];
    for (int c = 0; c < 3; ++c) zhc__volume_axis(position[c], grid.origin[c], grid.spacing[c], grid.counts[c], &i0[c], &f[c]);
    for (int corner = 0; corner < 8; ++corner) {
        const int bx = corner & 1, by = (corner >> 1) & 1, bz = (corner >> 2) & 1;
        const double w = (bx ? f[0] : 1.0 - f[0]) * (by ? f[1] : 1.0 - f[1]) * (bz ? f[2] : 1.0 - f[2]);
        if (w == 0.0) continue;
        const std::size_t index =
            (i0[0] + static_cast<std::uint32_t>(bx)) +
            static_cast<std::size_t>(grid.counts[0]) *
                ((i0[1] + static_cast<std::uint32_t>(by)) + static_cast<std::size_t>(grid.counts[1]) * (i0[2] + static_cast<std::uint32_t>(bz)));
        for (std::size_t t = 0; t < tex.size(); ++t)
            for (int c = 0; c < tex[t].components; ++c) vals[4 * t + static_cast<std::size_t>(c)] += w * texel_value(textures[t], tex[t], index, c);
    }
    reconstruct_sh3(l, vals, sh);
}

// Irradiance of SH3 radiance sh (double) at normal n: E = sum_i s_l c_i Y_i(n), as zhc_volume_irradiance_d.
inline void sh3_irradiance_d(const double sh[27], const double normal[3], double rgb[3]) {
    double n[3], y[9];
    zhc__normalize_or_z(normal, n);
    zhc__sh3_basis(n, y);
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    for (int i = 0; i < 9; ++i) {
        const double s = i == 0 ? 1.0 : (i < 4 ? ZHC__BAND1 : ZHC__BAND2);
        for (int k = 0; k < 3; ++k) rgb[k] += s * sh[i * 3 + k] * y[i];
    }
}

inline void sample_irradiance(const zhc_volume& grid, Layout l, const std::vector<std::vector<std::uint8_t>>& textures,
                              const double position[3], const double normal[3], double rgb[3]) {
    double sh[27];
    sample_sh3(grid, l, textures, position, sh);
    sh3_irradiance_d(sh, normal, rgb);
}

}  // namespace zhc_layouts
