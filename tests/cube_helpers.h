// Helpers shared by the cube-map tests (test_cube_containers, test_cube_containers_hostile): the spec's
// face table written out independently of codec/cubemap, analytic cubes, and this test's own KTX2 / DDS
// writers (from the KTX 2.0 specification and Microsoft's DDS documentation; zhc has no cube-map
// writer) with the format/container cases and their tolerances.
#pragma once

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <utility>

#include <zstd.h>

#include "codec/lightmap/bc6h.h"
#include "codec/sh/cubemap.h"
#include "formats/envmap/envmap.h"
#include "formats/envmap/envmap_cube.h"
#include "formats/lightmap/ktx2.h"
#include "support.h"

namespace zhc::cube_test {

// ---- the spec's face table, written out independently of codec/cubemap --------------------
// Vulkan "Cube Map Face Selection": major axis -> (face, sc, tc, ma); s = (sc / |ma| + 1) / 2,
// t = (tc / |ma| + 1) / 2. Direction r in the API frame (Y up).
inline void select_face(double rx, double ry, double rz, int* face, double* s, double* t) {
    const double ax = std::fabs(rx), ay = std::fabs(ry), az = std::fabs(rz);
    double sc, tc, ma;
    if (ax >= ay && ax >= az) {
        *face = rx > 0 ? 0 : 1;
        sc = rx > 0 ? -rz : rz;
        tc = -ry;
        ma = ax;
    } else if (ay >= az) {
        *face = ry > 0 ? 2 : 3;
        sc = rx;
        tc = ry > 0 ? rz : -rz;
        ma = ay;
    } else {
        *face = rz > 0 ? 4 : 5;
        sc = rz > 0 ? rx : -rx;
        tc = -ry;
        ma = az;
    }
    *s = 0.5 * (sc / ma + 1.0);
    *t = 0.5 * (tc / ma + 1.0);
}

// zhc direction -> API frame: (x, y, z)_zhc = (z, x, y)_API.
inline void to_api(Vec3 d, double* rx, double* ry, double* rz) {
    *rx = d.y;
    *ry = d.z;
    *rz = d.x;
}

// A known SH3 radiance function with every coefficient non-zero and positive values everywhere
// (unsigned formats: RGB9E5, BC6H_UFLOAT).
inline Sh3Radiance test_sh() {
    Sh3Radiance a;
    std::mt19937 rng(1616);
    std::uniform_real_distribution<float> u(-0.25f, 0.25f);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) {
            const float v = u(rng);
            a[i][k] = i == 0 ? 8.0f + 2.0f * k : (v >= 0 ? v + 0.05f : v - 0.05f);
        }
    return a;
}

// A cube map (n x 6n, Vulkan layout) whose texel (col, row) of face f holds F(direction of the
// texel centre), the direction built from the spec's s, t: the inverse of select_face.
template <class F>
Image render_cube(int n, F&& f) {
    Image img;
    img.width = n;
    img.height = 6 * n;
    img.layout = EnvmapLayout::kCubeVulkan;
    img.rgb.resize(static_cast<size_t>(n) * 6 * n * 3);
    for (int face = 0; face < 6; ++face)
        for (int row = 0; row < n; ++row)
            for (int col = 0; col < n; ++col) {
                const double sc = 2.0 * (col + 0.5) / n - 1.0, tc = 2.0 * (row + 0.5) / n - 1.0;
                double r[3];
                switch (face) {  // solve the table for r with |ma| = 1
                    case 0: r[0] = 1, r[2] = -sc, r[1] = -tc; break;
                    case 1: r[0] = -1, r[2] = sc, r[1] = -tc; break;
                    case 2: r[1] = 1, r[0] = sc, r[2] = tc; break;
                    case 3: r[1] = -1, r[0] = sc, r[2] = -tc; break;
                    case 4: r[2] = 1, r[0] = sc, r[1] = -tc; break;
                    default: r[2] = -1, r[0] = -sc, r[1] = -tc; break;
                }
                const double len = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
                const Vec3 d{r[2] / len, r[0] / len, r[1] / len};  // zhc = (z, x, y)_API
                const Rgb c = f(d);
                float* p = img.row(face * n + row) + 3 * col;
                p[0] = c.r, p[1] = c.g, p[2] = c.b;
            }
    return img;
}

// ---- this test's writers -------------------------------------------------------------------
enum class Fmt { kRgba16f, kRgba32f, kRgb9e5, kBc6h };
inline const char* fmt_name(Fmt f) {
    switch (f) {
        case Fmt::kRgba16f: return "rgba16f";
        case Fmt::kRgba32f: return "rgba32f";
        case Fmt::kRgb9e5: return "rgb9e5";
        default: return "bc6h";
    }
}

inline void put16(std::vector<std::uint8_t>& b, std::uint16_t v) {
    b.push_back(static_cast<std::uint8_t>(v));
    b.push_back(static_cast<std::uint8_t>(v >> 8));
}
inline void put32v(std::vector<std::uint8_t>& b, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}
inline void put64v(std::vector<std::uint8_t>& b, std::uint64_t v) {
    for (int k = 0; k < 8; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

// RGB9E5 as the Vulkan / OpenGL specification's shared-exponent conversion defines it.
inline std::uint32_t encode_rgb9e5(const float* rgb) {
    const double kMax = 511.0 / 512.0 * 65536.0;
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(static_cast<double>(rgb[k]), 0.0, kMax);
    const double m = std::max({c[0], c[1], c[2]});
    int e = std::max(-16, static_cast<int>(std::floor(std::log2(std::max(m, 1e-30))))) + 16;
    double denom = std::ldexp(1.0, e - 24);
    if (static_cast<int>(std::floor(m / denom + 0.5)) == 512) denom *= 2, ++e;
    std::uint32_t v = static_cast<std::uint32_t>(e) << 27;
    for (int k = 0; k < 3; ++k) v |= static_cast<std::uint32_t>(std::floor(c[k] / denom + 0.5)) << (9 * k);
    return v;
}

// One face (rows face*n.. of a cube of face size n) of an image in the format.
inline std::vector<std::uint8_t> encode_face(const Image& cube, int face, Fmt f) {
    const int n = cube.width;
    std::vector<std::uint8_t> out;
    if (f == Fmt::kBc6h)
        return bc6h::encode_image(cube.row(face * n), n, n, bc6h::Quality::kDefault);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const float* p = cube.row(face * n + r) + 3 * c;
            switch (f) {
                case Fmt::kRgba16f:
                    for (int k = 0; k < 3; ++k) put16(out, bc6h::float_to_half(p[k]));
                    put16(out, 0x3C00);
                    break;
                case Fmt::kRgba32f:
                    for (int k = 0; k < 3; ++k) {
                        std::uint32_t v;
                        std::memcpy(&v, &p[k], 4);
                        put32v(out, v);
                    }
                    put32v(out, 0x3F800000u);
                    break;
                default: put32v(out, encode_rgb9e5(p)); break;
            }
        }
    return out;
}

// A box-filtered half-size cube (for mip levels).
inline Image half_cube(const Image& c) {
    const int n = std::max(1, c.width / 2);
    Image h;
    h.width = n;
    h.height = 6 * n;
    h.layout = c.layout;
    h.rgb.assign(static_cast<size_t>(n) * 6 * n * 3, 0.0f);
    for (int y = 0; y < 6 * n; ++y)
        for (int x = 0; x < n; ++x)
            for (int k = 0; k < 3; ++k) {
                const int face = y / n, r = y % n;
                double s = 0;
                for (int j = 0; j < 2; ++j)
                    for (int i = 0; i < 2; ++i)
                        s += c.row(face * c.width + std::min(c.width - 1, 2 * r + j))[3 * std::min(c.width - 1, 2 * x + i) + k];
                h.row(y)[3 * x + k] = static_cast<float>(s / 4);
            }
    return h;
}

inline std::uint32_t vk_of(Fmt f) { return f == Fmt::kRgba16f ? 97 : f == Fmt::kRgba32f ? 109 : f == Fmt::kRgb9e5 ? 123 : 143; }

// KTX2: header, level index, a basic DFD-shaped block (not read by zhc), then the levels, smallest
// first, each aligned to lcm(texel block size, 4). `levels` mip levels (box-filtered; the lower
// levels are darker by `mip_scale` so that reading one instead of level 0 would show).
// `zstd`: supercompressionScheme 2, each level one Zstandard frame (alignment 1).
inline std::vector<std::uint8_t> write_ktx2(const Image& cube, Fmt f, int levels = 1, float mip_scale = 1.0f, bool zstd = false) {
    std::vector<std::vector<std::uint8_t>> data;
    std::vector<std::uint64_t> raw_size;
    Image level = cube;
    for (int l = 0; l < levels; ++l) {
        std::vector<std::uint8_t> d;
        for (int face = 0; face < 6; ++face) {
            const auto fb = encode_face(level, face, f);
            d.insert(d.end(), fb.begin(), fb.end());
        }
        data.push_back(d);
        raw_size.push_back(d.size());
        if (zstd) {
            std::vector<std::uint8_t> z(ZSTD_compressBound(d.size()));
            const size_t got = ZSTD_compress(z.data(), z.size(), d.data(), d.size(), 9);
            EXPECT_FALSE(ZSTD_isError(got));
            z.resize(got);
            data.back() = z;
        }
        level = half_cube(level);
        for (float& v : level.rgb) v *= mip_scale;
    }
    const std::uint32_t align = zstd ? 1 : f == Fmt::kBc6h ? 16 : f == Fmt::kRgba16f ? 8 : f == Fmt::kRgba32f ? 16 : 4;
    const std::uint32_t dfd_len = 44;
    const std::uint64_t index_end = 80 + 24 * static_cast<std::uint64_t>(levels);
    std::vector<std::uint64_t> offset(static_cast<size_t>(levels));
    std::uint64_t pos = index_end + dfd_len;
    for (int l = levels - 1; l >= 0; --l) {
        pos = (pos + align - 1) / align * align;
        offset[static_cast<size_t>(l)] = pos;
        pos += data[static_cast<size_t>(l)].size();
    }
    std::vector<std::uint8_t> b = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    put32v(b, vk_of(f));
    put32v(b, f == Fmt::kBc6h ? 1 : f == Fmt::kRgba16f ? 2 : 4);  // typeSize
    put32v(b, static_cast<std::uint32_t>(cube.width));
    put32v(b, static_cast<std::uint32_t>(cube.width));
    put32v(b, 0);  // pixelDepth
    put32v(b, 0);  // layerCount
    put32v(b, 6);  // faceCount
    put32v(b, static_cast<std::uint32_t>(levels));
    put32v(b, zstd ? 2 : 0);  // supercompressionScheme
    put32v(b, static_cast<std::uint32_t>(index_end));
    put32v(b, dfd_len);
    put32v(b, 0);
    put32v(b, 0);
    put64v(b, 0);
    put64v(b, 0);
    for (int l = 0; l < levels; ++l) {
        put64v(b, offset[static_cast<size_t>(l)]);
        put64v(b, data[static_cast<size_t>(l)].size());
        put64v(b, raw_size[static_cast<size_t>(l)]);
    }
    put32v(b, dfd_len);  // dfdTotalSize, then one basic descriptor block without samples' details
    put32v(b, 0);
    put32v(b, 2u | (40u << 16));
    b.resize(index_end + dfd_len, 0);
    for (int l = levels - 1; l >= 0; --l) {
        b.resize(offset[static_cast<size_t>(l)], 0);
        b.insert(b.end(), data[static_cast<size_t>(l)].begin(), data[static_cast<size_t>(l)].end());
    }
    return b;
}

// DDS: legacy FourCC (113 / 116) when `legacy`, else DX10; for each face its mip chain.
inline std::vector<std::uint8_t> write_dds(const Image& cube, Fmt f, bool legacy, int levels = 1, float mip_scale = 1.0f) {
    std::vector<std::vector<std::uint8_t>> face_chain(6);
    Image level = cube;
    for (int l = 0; l < levels; ++l) {
        for (int face = 0; face < 6; ++face) {
            const auto fb = encode_face(level, face, f);
            face_chain[static_cast<size_t>(face)].insert(face_chain[static_cast<size_t>(face)].end(), fb.begin(), fb.end());
        }
        level = half_cube(level);
        for (float& v : level.rgb) v *= mip_scale;
    }
    std::vector<std::uint8_t> b;
    put32v(b, 0x20534444);
    put32v(b, 124);
    put32v(b, 0x1 | 0x2 | 0x4 | 0x1000 | (levels > 1 ? 0x20000 : 0));  // CAPS HEIGHT WIDTH PIXELFORMAT (MIPMAPCOUNT)
    put32v(b, static_cast<std::uint32_t>(cube.width));                   // height
    put32v(b, static_cast<std::uint32_t>(cube.width));                   // width
    put32v(b, 0);                                                        // pitchOrLinearSize
    put32v(b, 0);                                                        // depth
    put32v(b, static_cast<std::uint32_t>(levels));
    for (int i = 0; i < 11; ++i) put32v(b, 0);
    put32v(b, 32);
    put32v(b, 0x4);  // DDPF_FOURCC
    put32v(b, legacy ? (f == Fmt::kRgba16f ? 113u : 116u) : 0x30315844u);
    for (int i = 0; i < 5; ++i) put32v(b, 0);
    put32v(b, 0x1000 | 0x8 | (levels > 1 ? 0x400000 : 0));  // TEXTURE COMPLEX (MIPMAP)
    put32v(b, 0x200 | 0xFC00);                              // CUBEMAP + all faces
    put32v(b, 0);
    put32v(b, 0);
    put32v(b, 0);
    if (!legacy) {
        put32v(b, f == Fmt::kRgba16f ? 10u : f == Fmt::kRgba32f ? 2u : f == Fmt::kRgb9e5 ? 67u : 95u);
        put32v(b, 3);    // TEXTURE2D
        put32v(b, 0x4);  // TEXTURECUBE
        put32v(b, 1);    // arraySize
        put32v(b, 0);
    }
    for (const auto& c : face_chain) b.insert(b.end(), c.begin(), c.end());
    return b;
}

inline Result<Image> read(const std::vector<std::uint8_t>& b, EnvmapInfo* info = nullptr) {
    return read_envmap_memory(b, "test", {}, info);
}


// ---- 2. analytic maps in every format and both containers ------------------------------------

struct Case {
    const char* container;
    Fmt fmt;
    bool legacy;
    double tol;  // of |L00|
};

inline std::vector<std::uint8_t> write(const Case& c, const Image& cube, int levels = 1, float mip_scale = 1.0f) {
    return std::string(c.container) == "ktx2" ? write_ktx2(cube, c.fmt, levels, mip_scale)
                                              : write_dds(cube, c.fmt, c.legacy, levels, mip_scale);
}

// Tolerances (measured at N = 64, see the notes): float formats 2e-5 (the texel-centre quadrature,
// O(1/N^2)); half 1e-4; RGB9E5 6e-4 (9-bit mantissas); BC6H 4e-3.
inline constexpr Case kCases[] = {
    {"ktx2", Fmt::kRgba32f, false, 1e-4}, {"ktx2", Fmt::kRgba16f, false, 3e-4}, {"ktx2", Fmt::kRgb9e5, false, 2e-3},
    {"ktx2", Fmt::kBc6h, false, 1e-2},    {"dds", Fmt::kRgba32f, true, 1e-4},   {"dds", Fmt::kRgba16f, true, 3e-4},
    {"dds", Fmt::kRgba32f, false, 1e-4},  {"dds", Fmt::kRgba16f, false, 3e-4},  {"dds", Fmt::kRgb9e5, false, 2e-3},
    {"dds", Fmt::kBc6h, false, 1e-2},
};

}  // namespace zhc::cube_test
