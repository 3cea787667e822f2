// KTX 1 cube maps and 8-bit cube maps (formats/envmap/envmap_cube.h, envmap_ldr.h): analytic maps in
// every KTX 1 format and byte order, 8-bit formats (RGBA8 / BGRA8 / RGB8, BC1 / BC2 / BC3, sRGB or
// UNORM) in KTX2, KTX 1 and DDS, the --ldr-encoding choices (sRGB / linear overrides, RGBM, RGBD),
// BC1 / BC3 faces written by ImageMagick, and hostile KTX 1 files through the CLI.
//
// Files: the KTX 1 containers are written here by hand from the KTX File Format Specification
// version 1.1 (no Debian package writes KTX 1: no ktx-tools / libktx in Debian 12); the KTX2 / DDS
// containers by this test's own writers (as in test_cube_containers); BC1 / BC3 block data by
// ImageMagick (`convert -define dds:compression=dxt1|dxt5`, which writes 2-D DDS only: its six
// faces' blocks are put into cube containers here) and by this test's own encoder.
//
// Bounds: an SH coefficient of f is the integral of f Y_i over the sphere, so a texel error of at
// most e changes it by at most e * integral |Y_i| <= e * sqrt(4 pi) (Cauchy-Schwarz, ||Y_i|| = 1).
// The tests measure e with their own slow decoders (the twins below: bit-by-bit block reads, the
// sRGB EOTF written out) on the exact bytes in the file, and allow sqrt(4 pi) e / |L00| plus the
// texel quadrature's own error (1e-4 of |L00| at N = 64, as measured in test_cube_containers).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "codec/lightmap/bc6h.h"
#include "formats/envmap/envmap.h"
#include "formats/envmap/bc7.h"
#include "formats/envmap/envmap_ldr.h"
#include "formats/scene/scene_json.h"
#include "cube_ldr_helpers.h"
#include "support.h"

namespace zhc {
namespace {

using namespace cube_test;
using Bytes = std::vector<std::uint8_t>;

constexpr double kQuadrature = 1e-4;  // of |L00|, the texel quadrature at N = 64

// ---- twins: slow block decoders --------------------------------------------
std::uint8_t q8(double v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

// Bit k of a little-endian byte string.
int bit(const std::uint8_t* p, int k) { return (p[k / 8] >> (k % 8)) & 1; }
int bits(const std::uint8_t* p, int first, int count) {
    int v = 0;
    for (int i = count - 1; i >= 0; --i) v = 2 * v + bit(p, first + i);
    return v;
}
// BC1 colour block (8 bytes) per the Data Format Specification: texel i's colour, in [0, 1].
void bc1_texel_twin(const std::uint8_t* b, int i, bool force_four, double out[4]) {
    const int c0 = bits(b, 0, 16), c1 = bits(b, 16, 16);
    const double e0[3] = {bits(b, 11, 5) / 31.0, bits(b, 5, 6) / 63.0, bits(b, 0, 5) / 31.0};
    const double e1[3] = {bits(b, 27, 5) / 31.0, bits(b, 21, 6) / 63.0, bits(b, 16, 5) / 31.0};
    const int idx = bits(b, 32 + 2 * i, 2);
    out[3] = 1;
    for (int k = 0; k < 3; ++k) {
        if (force_four || c0 > c1) {
            const double w[4] = {0, 1, 1.0 / 3, 2.0 / 3};  // weight of e1
            out[k] = e0[k] * (1 - w[idx]) + e1[k] * w[idx];
        } else {
            out[k] = idx == 0 ? e0[k] : idx == 1 ? e1[k] : idx == 2 ? (e0[k] + e1[k]) / 2 : 0.0;
        }
    }
}
double bc3_alpha_twin(const std::uint8_t* b, int i) {
    const int a0 = b[0], a1 = b[1], idx = bits(b, 16 + 3 * i, 3);
    if (idx == 0) return a0 / 255.0;
    if (idx == 1) return a1 / 255.0;
    if (a0 > a1) return ((8 - idx) * a0 + (idx - 1) * a1) / (7.0 * 255.0);
    if (idx == 6) return 0;
    if (idx == 7) return 1;
    return ((6 - idx) * a0 + (idx - 1) * a1) / (5.0 * 255.0);
}

// B10G11R11 unsigned float, round to nearest (the test's encoder; normal numbers only).
std::uint32_t ufloat_enc_twin(double v, int mbits) {
    int e = static_cast<int>(std::floor(std::log2(v)));
    long m = std::lround((v / std::ldexp(1.0, e) - 1) * (1 << mbits));
    if (m == (1 << mbits)) m = 0, ++e;
    return static_cast<std::uint32_t>((e + 15) << mbits | m);
}

// ---- 8-bit formats: the test's encoders and the twins' decode of a face --------------------------
enum class Ldr { kRgba8, kBgra8, kRgb8, kBc1, kBc3 };
const char* ldr_name(Ldr f) {
    switch (f) {
        case Ldr::kRgba8: return "RGBA8";
        case Ldr::kBgra8: return "BGRA8";
        case Ldr::kRgb8: return "RGB8";
        case Ldr::kBc1: return "BC1";
        default: return "BC3";
    }
}
bool is_block(Ldr f) { return f == Ldr::kBc1 || f == Ldr::kBc3; }

// Face `face` of an RGBA target (encoded values in [0, 1], n x 6n x 4 floats) as bytes.
// BC1: endpoints the block's bounding box (565), each texel the nearest of the four colours; BC3:
// the same colour block plus alpha endpoints min / max (8-value mode), nearest alpha.
Bytes encode_ldr_face(const std::vector<float>& rgba, int n, int face, Ldr f) {
    Bytes out;
    auto at = [&](int r, int c, int k) { return rgba[((static_cast<size_t>(face) * n + r) * n + c) * 4 + k]; };
    if (!is_block(f)) {
        for (int r = 0; r < n; ++r)
            for (int c = 0; c < n; ++c) {
                const int order[4][4] = {{0, 1, 2, 3}, {2, 1, 0, 3}, {0, 1, 2, -1}};
                const int* o = order[f == Ldr::kRgba8 ? 0 : f == Ldr::kBgra8 ? 1 : 2];
                for (int k = 0; k < 4; ++k)
                    if (o[k] >= 0) out.push_back(q8(at(r, c, o[k])));
            }
        return out;
    }
    for (int by = 0; by < n; by += 4)
        for (int bx = 0; bx < n; bx += 4) {
            double lo[4] = {1, 1, 1, 1}, hi[4] = {0, 0, 0, 0};
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x)
                    for (int k = 0; k < 4; ++k) {
                        lo[k] = std::min(lo[k], double(at(by + y, bx + x, k)));
                        hi[k] = std::max(hi[k], double(at(by + y, bx + x, k)));
                    }
            auto p565 = [](const double* c) {
                return static_cast<int>(std::lround(c[0] * 31) << 11 | std::lround(c[1] * 63) << 5 | std::lround(c[2] * 31));
            };
            int c0 = p565(hi), c1 = p565(lo);
            if (c0 < c1) std::swap(c0, c1);
            std::uint8_t colour[8] = {std::uint8_t(c0), std::uint8_t(c0 >> 8), std::uint8_t(c1), std::uint8_t(c1 >> 8), 0, 0, 0, 0};
            for (int i = 0; i < 16; ++i) {
                int best = 0;
                double best_d = 1e30;
                for (int idx = 0; idx < 4; ++idx) {
                    std::uint8_t trial[8];
                    std::memcpy(trial, colour, 8);
                    trial[4 + i / 4] = static_cast<std::uint8_t>(trial[4 + i / 4] | (idx << (2 * (i % 4))));
                    double v[4], d = 0;
                    bc1_texel_twin(trial, i, f == Ldr::kBc3, v);
                    for (int k = 0; k < 3; ++k) d += std::pow(v[k] - at(by + i / 4, bx + i % 4, k), 2);
                    if (d < best_d) best_d = d, best = idx;
                }
                colour[4 + i / 4] = static_cast<std::uint8_t>(colour[4 + i / 4] | (best << (2 * (i % 4))));
            }
            if (f == Ldr::kBc3) {
                std::uint8_t alpha[8] = {q8(hi[3]), q8(lo[3]), 0, 0, 0, 0, 0, 0};
                if (alpha[0] == alpha[1]) alpha[1] = alpha[0] > 0 ? alpha[0] - 1 : 1, std::swap(alpha[0], alpha[1]);
                if (alpha[0] < alpha[1]) std::swap(alpha[0], alpha[1]);
                for (int i = 0; i < 16; ++i) {
                    int best = 0;
                    double best_d = 1e30;
                    for (int idx = 0; idx < 8; ++idx) {
                        std::uint8_t trial[8];
                        std::memcpy(trial, alpha, 8);
                        const int k = 16 + 3 * i;
                        for (int j = 0; j < 3; ++j)
                            if ((idx >> j) & 1) trial[(k + j) / 8] = static_cast<std::uint8_t>(trial[(k + j) / 8] | (1 << ((k + j) % 8)));
                        const double d = std::fabs(bc3_alpha_twin(trial, i) - at(by + i / 4, bx + i % 4, 3));
                        if (d < best_d) best_d = d, best = idx;
                    }
                    const int k = 16 + 3 * i;
                    for (int j = 0; j < 3; ++j)
                        if ((best >> j) & 1) alpha[(k + j) / 8] = static_cast<std::uint8_t>(alpha[(k + j) / 8] | (1 << ((k + j) % 8)));
                }
                out.insert(out.end(), alpha, alpha + 8);
            }
            out.insert(out.end(), colour, colour + 8);
        }
    return out;
}

// The encoded RGBA of every texel of six faces' bytes (the twins), n x 6n x 4.
std::vector<double> decode_ldr_twin(const Bytes& faces, int n, Ldr f) {
    std::vector<double> out(static_cast<size_t>(6) * n * n * 4);
    const size_t face_bytes = faces.size() / 6;
    for (int face = 0; face < 6; ++face) {
        const std::uint8_t* src = faces.data() + face * face_bytes;
        for (int r = 0; r < n; ++r)
            for (int c = 0; c < n; ++c) {
                double* o = &out[((static_cast<size_t>(face) * n + r) * n + c) * 4];
                if (is_block(f)) {
                    const int bs = f == Ldr::kBc1 ? 8 : 16;
                    const std::uint8_t* blk = src + static_cast<size_t>((r / 4) * (n / 4) + c / 4) * bs;
                    const int i = (r % 4) * 4 + c % 4;
                    bc1_texel_twin(blk + (bs - 8), i, f == Ldr::kBc3, o);
                    if (f == Ldr::kBc3) o[3] = bc3_alpha_twin(blk, i);
                } else {
                    const int bpp = f == Ldr::kRgb8 ? 3 : 4;
                    const std::uint8_t* p = src + (static_cast<size_t>(r) * n + c) * bpp;
                    const int order[3] = {f == Ldr::kBgra8 ? 2 : 0, 1, f == Ldr::kBgra8 ? 0 : 2};
                    for (int k = 0; k < 3; ++k) o[k] = p[order[k]] / 255.0;
                    o[3] = bpp == 4 ? p[3] / 255.0 : 1.0;
                }
            }
    }
    return out;
}

TEST(CubeLdr, BlockDecodersMatchTheTwins) {
    // Random blocks cover both BC1 modes (colour0 > colour1 or not) and both BC3 alpha modes.
    std::mt19937 rng(29);
    int three_colour = 0, six_alpha = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        std::uint8_t b[16];
        for (auto& v : b) v = static_cast<std::uint8_t>(rng());
        if (trial % 7 == 0) b[8] = b[10], b[9] = b[11];  // equal colour endpoints
        float bc1[16][4], bc1a[16][4], bc2[16][4], bc3[16][4];
        ldr::decode_bc1(b + 8, false, bc1);
        ldr::decode_bc1(b + 8, true, bc1a);
        ldr::decode_bc2(b, bc2);
        ldr::decode_bc3(b, bc3);
        const bool four = bits(b + 8, 0, 16) > bits(b + 8, 16, 16);
        three_colour += !four;
        six_alpha += b[0] > b[1];
        for (int i = 0; i < 16; ++i) {
            double t[4], t4[4];
            bc1_texel_twin(b + 8, i, false, t);
            bc1_texel_twin(b + 8, i, true, t4);
            const bool transparent = !four && bits(b + 8, 32 + 2 * i, 2) == 3;
            for (int k = 0; k < 3; ++k) {
                ASSERT_NEAR(bc1[i][k], t[k], 1e-6) << trial << " " << i;
                ASSERT_NEAR(bc1a[i][k], t[k], 1e-6);
                ASSERT_NEAR(bc2[i][k], t4[k], 1e-6);
                ASSERT_NEAR(bc3[i][k], t4[k], 1e-6);
            }
            ASSERT_EQ(bc1[i][3], 1.0f);
            ASSERT_EQ(bc1a[i][3], transparent ? 0.0f : 1.0f);
            ASSERT_NEAR(bc2[i][3], bits(b, 4 * i, 4) / 15.0, 1e-7);
            ASSERT_NEAR(bc3[i][3], bc3_alpha_twin(b, i), 1e-6) << trial << " " << i;
        }
    }
    EXPECT_GT(three_colour, 1000);
    EXPECT_GT(six_alpha, 1000);
    EXPECT_LT(six_alpha, 19000);
    // B10G11R11: the twin's encoding decodes to within half a mantissa step.
    for (double v : {0.001, 0.2, 1.0, 1.7, 3.14159, 250.0, 60000.0}) {
        float out[3];
        ldr::decode_r11g11b10(ufloat_enc_twin(v, 6) | ufloat_enc_twin(v, 6) << 11 | ufloat_enc_twin(v, 5) << 22, out);
        EXPECT_NEAR(out[0], v, v / 128 + 1e-9) << v;
        EXPECT_NEAR(out[1], v, v / 128 + 1e-9) << v;
        EXPECT_NEAR(out[2], v, v / 64 + 1e-9) << v;
    }
    float special[3];
    ldr::decode_r11g11b10(31u << 6 | 31u << 17 | 1u << 11 | 31u << 27, special);  // R Inf, G NaN, B Inf
    EXPECT_TRUE(std::isinf(special[0]));
    EXPECT_TRUE(std::isnan(special[1]));
    EXPECT_TRUE(std::isinf(special[2]));
}

// ---- containers ---------------------------------------------------------------------------------
void put32(Bytes& b, std::uint32_t v) { put32v(b, v); }


// KTX 1 (KTX File Format Specification 1.1): 64-byte header, key/value data, then per level
// imageSize (one face's bytes, rows padded to 4) and six faces. `levels` > 1 adds levels whose
// bytes are a pattern (never level 0's data). `big_endian`: every header field, imageSize and
// glTypeSize unit byte-swapped, endianness 0x04030201 as written on such a machine.
struct Ktx1Spec {
    std::uint32_t type = 0, type_size = 1, format = 0, internal = 0;
    std::uint64_t texel_bytes = 0;  // uncompressed: bytes per texel (rows get padded); 0: block data
    std::uint64_t block_bytes = 0;
    bool big_endian = false;
    int levels = 1;
    bool image_size_six = false;  // imageSize of six faces (what some writers store)
    std::string kvd;              // one key/value pair "key\0value" when not empty
};
Ktx1Spec spec(std::uint32_t type, std::uint32_t type_size, std::uint32_t format, std::uint32_t internal, std::uint64_t texel_bytes,
              std::uint64_t block_bytes) {
    Ktx1Spec s;
    s.type = type, s.type_size = type_size, s.format = format, s.internal = internal;
    s.texel_bytes = texel_bytes, s.block_bytes = block_bytes;
    return s;
}

Bytes ktx1(const Ktx1Spec& s, int n, const Bytes& faces) {
    auto u32 = [&](Bytes& b, std::uint32_t v) {
        if (s.big_endian) v = (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
        put32(b, v);
    };
    Bytes kv;
    if (!s.kvd.empty()) {
        Bytes pair;
        u32(pair, static_cast<std::uint32_t>(s.kvd.size()));
        for (char ch : s.kvd) pair.push_back(static_cast<std::uint8_t>(ch));
        while (pair.size() % 4) pair.push_back(0);
        kv = pair;
    }
    Bytes b = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    for (std::uint32_t v : {0x04030201u, s.type, s.type_size, s.format, s.internal, s.format ? s.format : 0x1908u, std::uint32_t(n),
                            std::uint32_t(n), 0u, 0u, 6u, std::uint32_t(s.levels), std::uint32_t(kv.size())})
        u32(b, v);
    b.insert(b.end(), kv.begin(), kv.end());
    for (int l = 0; l < s.levels; ++l) {
        const int m = std::max(1, n >> l);
        const std::uint64_t row = s.texel_bytes ? m * s.texel_bytes : static_cast<std::uint64_t>((m + 3) / 4) * s.block_bytes;
        const std::uint64_t rows = s.texel_bytes ? m : (m + 3) / 4, padded = (row + 3) / 4 * 4;
        u32(b, static_cast<std::uint32_t>(padded * rows * (s.image_size_six ? 6 : 1)));
        for (int face = 0; face < 6; ++face)
            for (std::uint64_t r = 0; r < rows; ++r) {
                Bytes line(static_cast<size_t>(padded), 0);
                for (std::uint64_t i = 0; i < row; ++i) {
                    const size_t at = (static_cast<size_t>(face) * rows + r) * row + i;  // hostile specs may outgrow `faces`
                    line[i] = l == 0 ? (at < faces.size() ? faces[at] : 0) : static_cast<std::uint8_t>(37 * i + 11 * l);
                }
                if (s.big_endian && s.type_size > 1)
                    for (std::uint64_t i = 0; i + s.type_size <= row; i += s.type_size)
                        std::reverse(line.begin() + static_cast<std::ptrdiff_t>(i), line.begin() + static_cast<std::ptrdiff_t>(i + s.type_size));
                b.insert(b.end(), line.begin(), line.end());
            }
    }
    return b;
}

Result<Image> read_with(const Bytes& b, LdrDecoding ldr = {}, EnvmapInfo* info = nullptr) {
    EnvmapReadOptions o;
    o.ldr = ldr;
    o.warn = [](const std::string&) {};
    return read_envmap_memory(b, "test", o, info);
}

LdrDecoding dec(const char* text) {
    LdrDecoding d;
    EXPECT_TRUE(parse_ldr_decoding(text, &d)) << text;
    return d;
}

// ---- 1. KTX 1 float formats, both byte orders ------------------------------------------------------

// Six faces of a float cube in a format, tightly packed, with the KTX 1 description and the KTX2
// vkFormat of the same bytes.
struct FloatCase {
    const char* name;
    std::uint32_t type, type_size, format, internal, vk, vk_type_size;
    std::uint64_t texel_bytes, block_bytes;
    double tol;  // of |L00| (test_cube_containers' tolerances; B10G11R11: 6-bit mantissas, 2^-7 relative)
};
constexpr std::uint32_t kHalf = 0x140B, kFloat = 0x1406, kRgba = 0x1908, kRgb = 0x1907;
const FloatCase kFloatCases[] = {
    {"RGBA16F", kHalf, 2, kRgba, 0x881A, 97, 2, 8, 0, 3e-4},
    {"RGB16F", kHalf, 2, kRgb, 0x881B, 90, 2, 6, 0, 3e-4},
    {"RGBA32F", kFloat, 4, kRgba, 0x8814, 109, 4, 16, 0, 1e-4},
    {"RGB32F", kFloat, 4, kRgb, 0x8815, 106, 4, 12, 0, 1e-4},
    {"RGBA16F as float data", kFloat, 4, kRgba, 0x881A, 109, 4, 16, 0, 1e-4},
    {"R11F_G11F_B10F", 0x8C3B, 4, kRgb, 0x8C3A, 122, 4, 4, 0, 1e-2},
    {"RGB9_E5", 0x8C3E, 4, kRgb, 0x8C3D, 123, 4, 4, 0, 2e-3},
    {"BPTC_UNSIGNED_FLOAT", 0, 1, 0, 0x8E8F, 143, 1, 0, 16, 1e-2},
};


Bytes float_faces(const Image& cube, const FloatCase& c) {
    Bytes all;
    for (int face = 0; face < 6; ++face) {
        Bytes f;
        const std::string name = c.name;
        if (c.vk == 97 || c.vk == 90) f = encode_face(cube, face, Fmt::kRgba16f);
        else if (c.vk == 109 || c.vk == 106) f = encode_face(cube, face, Fmt::kRgba32f);
        else if (c.vk == 123) f = encode_face(cube, face, Fmt::kRgb9e5);
        else if (c.vk == 143) f = encode_face(cube, face, Fmt::kBc6h);
        else {
            const int n = cube.width;
            for (int r = 0; r < n; ++r)
                for (int col = 0; col < n; ++col) {
                    const float* p = cube.row(face * n + r) + 3 * col;
                    put32(f, ufloat_enc_twin(p[0], 6) | ufloat_enc_twin(p[1], 6) << 11 | ufloat_enc_twin(p[2], 5) << 22);
                }
        }
        if (c.vk == 90 || c.vk == 106) {  // drop alpha
            const size_t unit = c.vk == 90 ? 2 : 4;
            Bytes rgb;
            for (size_t i = 0; i < f.size(); i += 4 * unit) rgb.insert(rgb.end(), f.begin() + i, f.begin() + i + 3 * unit);
            f = rgb;
        }
        all.insert(all.end(), f.begin(), f.end());
    }
    return all;
}

TEST(CubeLdr, Ktx1FloatFormatsInBothByteOrdersProjectToTheFunction) {
    const Sh3Radiance a = test_sh();
    for (int n : {64, 63}) {  // 63: odd rows of RGB16F need the 4-byte row padding
        const Image cube = render_cube(n, [&](Vec3 d) { return evaluate(a, d); });
        for (const FloatCase& c : kFloatCases) {
            if (n == 63 && c.block_bytes) continue;
            SCOPED_TRACE(std::string(c.name) + " N=" + std::to_string(n));
            const Bytes faces = float_faces(cube, c);
            const auto as_ktx2 = read_with(ktx2_one_level(c.vk, c.vk_type_size, n, faces));
            ASSERT_TRUE(as_ktx2) << as_ktx2.error().message;
            for (bool big : {false, true})
                for (int levels : {1, 4}) {
                    Ktx1Spec s = spec(c.type, c.type_size, c.format, c.internal, c.texel_bytes, c.block_bytes);
                    s.big_endian = big;
                    s.levels = levels;
                    s.image_size_six = levels == 4;
                    if (levels == 4) s.kvd = std::string("KTXorientation\0S=r,T=d", 23);
                    EnvmapInfo info;
                    auto img = read_with(ktx1(s, n, faces), {}, &info);
                    ASSERT_TRUE(img) << img.error().message;
                    EXPECT_EQ(info.format, "ktx1");
                    EXPECT_EQ(img->layout, EnvmapLayout::kCubeVulkan);
                    EXPECT_EQ(img->rgb, as_ktx2->rgb) << "KTX 1 and KTX2 of the same bytes differ (big-endian " << big << ")";
                    const double d = test::sh_distance(project_envmap(*img), a);
                    if (!big && levels == 1) std::printf("KTX 1 %-22s N=%d: %.2e of |L00| (tolerance %.0e)\n", c.name, n, d, c.tol);
                    EXPECT_LT(d, c.tol);
                }
        }
    }
}

// ---- 2. 8-bit formats in every container -------------------------------------------------------

struct LdrCase {
    const char* container;
    Ldr fmt;
    bool srgb;
};

// The file for a case; `faces` are the six faces' bytes.
Bytes ldr_file(const LdrCase& c, int n, const Bytes& faces) {
    const std::string k = c.container;
    const bool s = c.srgb;
    if (k == "ktx2") {
        const std::uint32_t vk[] = {s ? 43u : 37u, s ? 50u : 44u, s ? 29u : 23u, s ? 132u : 131u, s ? 138u : 137u};
        return ktx2_one_level(vk[static_cast<int>(c.fmt)], 1, n, faces);
    }
    if (k == "ktx1") {
        Ktx1Spec sp;
        sp.type_size = 1;
        switch (c.fmt) {
            case Ldr::kRgba8: sp = spec(0x1401, 1, kRgba, s ? 0x8C43u : 0x8058u, 4, 0); break;
            case Ldr::kBgra8: sp = spec(0x1401, 1, 0x80E1, s ? 0x8C43u : 0x8058u, 4, 0); break;
            case Ldr::kRgb8: sp = spec(0x1401, 1, kRgb, s ? 0x8C41u : 0x8051u, 3, 0); break;
            case Ldr::kBc1: sp = spec(0, 1, 0, s ? 0x8C4Cu : 0x83F0u, 0, 8); break;
            default: sp = spec(0, 1, 0, s ? 0x8C4Fu : 0x83F3u, 0, 16); break;
        }
        return ktx1(sp, n, faces);
    }
    DdsPf pf;
    if (k == "dds") {
        const std::uint32_t dxgi[] = {s ? 29u : 28u, s ? 91u : 87u, 0, s ? 72u : 71u, s ? 78u : 77u};
        pf.dxgi = dxgi[static_cast<int>(c.fmt)];
    } else if (c.fmt == Ldr::kBc1 || c.fmt == Ldr::kBc3) {  // legacy DDS: DXT1 / DXT5
        pf.fourcc = c.fmt == Ldr::kBc1 ? 0x31545844u : 0x35545844u;
    } else {  // legacy 32-bit with masks: A8B8G8R8 (RGBA bytes) / A8R8G8B8 (BGRA bytes)
        pf.flags = 0x40 | 0x1;
        pf.bits = 32;
        const bool bgra = c.fmt == Ldr::kBgra8;
        pf.masks[0] = bgra ? 0x00ff0000u : 0x000000ffu;
        pf.masks[1] = 0x0000ff00u;
        pf.masks[2] = bgra ? 0x000000ffu : 0x00ff0000u;
        pf.masks[3] = 0xff000000u;
    }
    return dds(pf, n, faces);
}

const LdrCase kLdrCases[] = {
    {"ktx2", Ldr::kRgba8, true},  {"ktx2", Ldr::kRgba8, false}, {"ktx2", Ldr::kBgra8, true}, {"ktx2", Ldr::kRgb8, true},
    {"ktx2", Ldr::kBc1, true},    {"ktx2", Ldr::kBc1, false},   {"ktx2", Ldr::kBc3, true},  {"ktx2", Ldr::kBc3, false},
    {"ktx1", Ldr::kRgba8, true},  {"ktx1", Ldr::kRgba8, false}, {"ktx1", Ldr::kBgra8, true}, {"ktx1", Ldr::kRgb8, false},
    {"ktx1", Ldr::kBc1, true},    {"ktx1", Ldr::kBc3, false},   {"dds", Ldr::kRgba8, true},  {"dds", Ldr::kBgra8, false},
    {"dds", Ldr::kBc1, true},     {"dds", Ldr::kBc3, false},    {"dds-legacy", Ldr::kRgba8, false},
    {"dds-legacy", Ldr::kBgra8, false}, {"dds-legacy", Ldr::kBc1, false}, {"dds-legacy", Ldr::kBc3, false},
};

// The RGBA target for a linear function: rgb encoded by the transfer function, alpha a pattern.
std::vector<float> ldr_target(const Image& lin, bool srgb) {
    std::vector<float> t;
    const size_t texels = lin.rgb.size() / 3;
    for (size_t i = 0; i < texels; ++i) {
        for (int k = 0; k < 3; ++k) t.push_back(static_cast<float>(srgb ? srgb_oetf_twin(lin.rgb[3 * i + k]) : lin.rgb[3 * i + k]));
        t.push_back(static_cast<float>(0.5 + 0.4 * std::sin(0.01 * static_cast<double>(i))));
    }
    return t;
}

// Largest |twin-decoded radiance - function| over the texels, for the file's bytes.
double twin_error(const Bytes& faces, const Image& lin, int n, Ldr f, bool srgb) {
    const auto enc = decode_ldr_twin(faces, n, f);
    double e = 0;
    for (size_t i = 0; i < lin.rgb.size() / 3; ++i)
        for (int k = 0; k < 3; ++k) {
            const double v = srgb ? srgb_eotf_twin(enc[4 * i + k]) : enc[4 * i + k];
            e = std::max(e, std::fabs(v - lin.rgb[3 * i + k]));
        }
    return e;
}

Bytes all_faces(const std::vector<float>& target, int n, Ldr f) {
    Bytes b;
    for (int face = 0; face < 6; ++face) {
        const Bytes e = encode_ldr_face(target, n, face, f);
        b.insert(b.end(), e.begin(), e.end());
    }
    return b;
}

TEST(CubeLdr, EightBitFormatsProjectToTheFunctionWithinTheQuantisationBound) {
    const int n = 64;
    const Linear fn;
    const Sh3Radiance a = fn.sh();
    const Image lin = render_cube(n, fn);
    ASSERT_LT(test::sh_distance(project_envmap(lin), a), kQuadrature);  // the analytic SH is right
    for (const LdrCase& c : kLdrCases) {
        SCOPED_TRACE(std::string(c.container) + " " + ldr_name(c.fmt) + (c.srgb ? " sRGB" : " UNORM"));
        const Bytes faces = all_faces(ldr_target(lin, c.srgb), n, c.fmt);
        EnvmapInfo info;
        auto img = read_with(ldr_file(c, n, faces), {}, &info);
        ASSERT_TRUE(img) << img.error().message;
        EXPECT_NE(info.channels.find(c.srgb ? "sRGB" : "UNORM"), std::string::npos) << info.channels;
        // zhc's decode against the twins', texel by texel.
        const auto enc = decode_ldr_twin(faces, n, c.fmt);
        double worst = 0;
        for (size_t i = 0; i < img->rgb.size(); ++i) {
            const double want = c.srgb ? srgb_eotf_twin(enc[4 * (i / 3) + i % 3]) : enc[4 * (i / 3) + i % 3];
            worst = std::max(worst, std::fabs(img->rgb[i] - want));
        }
        EXPECT_LT(worst, 2e-6);
        const double e = twin_error(faces, lin, n, c.fmt, c.srgb);
        // A priori: 8-bit rounding is half a step, times the sRGB EOTF's largest slope (2.4 / 1.055)
        // for sRGB. Blocks (a check of the test's encoder): a 4x4 block of this function spans at
        // most 0.036 per channel, so the 565 endpoint rounding (0.5 / 31) plus a third of the span
        // between palette colours keeps the encoded error under 0.03, times the slope for sRGB.
        const double slope = c.srgb ? 2.4 / 1.055 : 1.0;
        const double a_priori = slope * (is_block(c.fmt) ? 0.03 : 0.5 / 255) + 1e-7;
        EXPECT_LE(e, a_priori);
        const double bound = kSqrt4Pi * e / (kSqrt4Pi * fn.c[2]) + kQuadrature;
        const double d = test::sh_distance(project_envmap(*img), a);
        std::printf("%-10s %-5s %-5s: %.2e of |L00| (texel error %.4f, bound %.2e)\n", c.container, ldr_name(c.fmt),
                    c.srgb ? "sRGB" : "UNORM", d, e, bound);
        EXPECT_LT(d, bound);
    }
}

// BC7 blocks (random, every mode and the reserved one) in KTX2, KTX 1 and DDS, UNORM and sRGB:
// each container gives every texel as bc7::decode_block's bytes (test_bc7, test_mesa_bc check the
// decoder) under the format's transfer function, and at N = 6 the partial edge blocks are cut.
TEST(CubeLdr, Bc7InEveryContainer) {
    std::mt19937_64 rng(77);
    for (const int n : {8, 6}) {
        const int bw = (n + 3) / 4;
        Bytes faces;
        for (int b = 0; b < 6 * bw * bw; ++b) {
            std::uint8_t blk[16];
            for (auto& v : blk) v = static_cast<std::uint8_t>(rng());
            const int mode = b % 9;
            blk[0] = mode == 8 ? 0 : static_cast<std::uint8_t>((blk[0] & ~((2u << mode) - 1)) | (1u << mode));
            faces.insert(faces.end(), blk, blk + 16);
        }
        for (const bool srgb : {false, true}) {
            const Bytes files[] = {ktx2_one_level(srgb ? 146 : 145, 1, n, faces), ktx1(spec(0, 1, 0, srgb ? 0x8E8Du : 0x8E8Cu, 0, 16), n, faces),
                                   dds(DdsPf{srgb ? 99u : 98u}, n, faces)};
            for (const Bytes& file : files) {
                EnvmapInfo info;
                auto img = read_with(file, {}, &info);
                ASSERT_TRUE(img) << img.error().message;
                EXPECT_EQ(info.channels, srgb ? "BC7 sRGB" : "BC7 UNORM");
                ASSERT_EQ(img->width, n);
                double worst = 0;
                for (int face = 0; face < 6; ++face)
                    for (int by = 0; by < bw; ++by)
                        for (int bx = 0; bx < bw; ++bx) {
                            std::uint8_t t[16][4];
                            bc7::decode_block(faces.data() + 16 * (static_cast<size_t>(face * bw + by) * bw + bx), t);
                            for (int i = 0; i < 16; ++i) {
                                const int x = 4 * bx + i % 4, y = 4 * by + i / 4;
                                if (x >= n || y >= n) continue;
                                for (int k = 0; k < 3; ++k) {
                                    const double v = t[i][k] / 255.0;
                                    worst = std::max(worst, std::fabs(img->row(face * n + y)[3 * x + k] - (srgb ? srgb_eotf_twin(v) : v)));
                                }
                            }
                        }
                EXPECT_LT(worst, 2e-6) << "n " << n << (srgb ? " sRGB" : " UNORM");
            }
        }
    }
}

TEST(CubeLdr, SrgbAndLinearChooseTheTransferFunction) {
    EXPECT_NEAR(ldr::srgb_to_linear(0.5f), 0.214041, 1e-6);  // the sRGB EOTF of 0.5
    EXPECT_NEAR(ldr::srgb_to_linear(0.04045f), 0.04045 / 12.92, 1e-7);
    for (int v = 0; v < 256; ++v) EXPECT_NEAR(ldr::srgb_to_linear(v / 255.0f), srgb_eotf_twin(v / 255.0), 2e-7) << v;
    // A constant cube of byte 128 (128/255 = 0.50196): 0.21586 through the sRGB EOTF.
    const int n = 8;
    const Bytes faces(static_cast<size_t>(6) * n * n * 4, 128);
    const double srgb = srgb_eotf_twin(128 / 255.0), linear = 128 / 255.0;
    EXPECT_NEAR(srgb, 0.215861, 1e-6);
    struct {
        bool srgb_format;
        const char* option;
        double want;
    } cases[] = {{true, "auto", srgb}, {false, "auto", linear}, {true, "linear", linear}, {false, "srgb", srgb}, {true, "srgb", srgb},
                 {false, "linear", linear}};
    for (const auto& c : cases) {
        SCOPED_TRACE(std::string(c.srgb_format ? "sRGB file, " : "UNORM file, ") + c.option);
        auto img = read_with(ktx2_one_level(c.srgb_format ? 43 : 37, 1, n, faces), dec(c.option));
        ASSERT_TRUE(img) << img.error().message;
        const Sh3Radiance s = project_envmap(*img);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[0][k] / kSqrt4Pi, c.want, 1e-6);
    }
    // Through the CLI: the UNORM file warns that it was read as linear; --ldr-encoding srgb says otherwise.
    const std::string dir = test::fresh_dir("cube_ldr");
    test::write_bytes(dir + "/unorm.ktx2", ktx2_one_level(37, 1, n, faces));
    const auto plain = test::run_zhc({"project", dir + "/unorm.ktx2", "--json"});
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    EXPECT_NE(plain.err.find("read as linear"), std::string::npos) << plain.err;
    const auto forced = test::run_zhc({"project", dir + "/unorm.ktx2", "--json", "--ldr-encoding", "srgb"});
    ASSERT_EQ(forced.exit_code, 0) << forced.err;
    EXPECT_EQ(forced.err.find("read as linear"), std::string::npos) << forced.err;
    const double l00 = nlohmann::json::parse(forced.out)["sh3"][0][0].get<double>();
    EXPECT_NEAR(l00 / kSqrt4Pi, srgb, 1e-5);
    const auto bad = test::run_zhc({"project", dir + "/unorm.ktx2", "--ldr-encoding", "rgbm:-1"});
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
}

// ---- 3. RGBM and RGBD ---------------------------------------------------------------------------

// three.js's LinearToRGBM / LinearToRGBD (the encoders whose decoders zhc's options are), twins.
void rgbm_encode(const float* v, double range, float out[4]) {
    const double m = std::max({double(v[0]), double(v[1]), double(v[2])});
    const double mm = std::ceil(std::clamp(m / range, 0.0, 1.0) * 255) / 255;
    for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(mm > 0 ? v[k] / (mm * range) : 0);
    out[3] = static_cast<float>(mm);
}
void rgbd_encode(const float* v, double range, float out[4]) {
    const double m = std::max({double(v[0]), double(v[1]), double(v[2]), 1e-6});
    const double d = std::clamp(std::floor(std::max(range / m, 1.0)) / 255, 0.0, 1.0);
    for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(v[k] * d * (255 / range));
    out[3] = static_cast<float>(d);
}

TEST(CubeLdr, RgbmAndRgbdRoundTrip) {
    const int n = 64;
    const Sh3Radiance a = test_sh();  // HDR: radiance about 1.5 to 4.5
    const Image hdr = render_cube(n, [&](Vec3 d) { return evaluate(a, d); });
    float hi = 0;
    for (float v : hdr.rgb) hi = std::max(hi, v);
    struct {
        const char* option;
        double range;
        bool rgbd;
    } cases[] = {{"rgbm:8", 8, false}, {"rgbm:6", 6, false}, {"rgbd:255", 255, true}, {"rgbd:256", 256, true}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.option);
        std::vector<float> target;
        for (size_t i = 0; i < hdr.rgb.size() / 3; ++i) {
            float e[4];
            (c.rgbd ? rgbd_encode : rgbm_encode)(&hdr.rgb[3 * i], c.range, e);
            target.insert(target.end(), e, e + 4);
        }
        for (Ldr f : {Ldr::kRgba8, Ldr::kBc3}) {
            SCOPED_TRACE(ldr_name(f));
            const Bytes faces = all_faces(target, n, f);
            const Bytes file = ldr_file({"ktx2", f, false}, n, faces);
            auto img = read_with(file, dec(c.option));
            ASSERT_TRUE(img) << img.error().message;
            // The twins' decode of the same bytes: rgb * a * range, rgb * (range / 255) / a.
            const auto enc = decode_ldr_twin(faces, n, f);
            double e = 0, worst = 0;
            for (size_t i = 0; i < hdr.rgb.size(); ++i) {
                const double* t = &enc[4 * (i / 3)];
                const double v = c.rgbd ? t[i % 3] * (c.range / 255) / t[3] : t[i % 3] * t[3] * c.range;
                worst = std::max(worst, std::fabs(img->rgb[i] - v) / std::max(1.0, v));
                e = std::max(e, std::fabs(v - hdr.rgb[i]));
            }
            EXPECT_LT(worst, 1e-5);
            if (f == Ldr::kRgba8 && !c.rgbd) {
                EXPECT_LE(e, 0.5 / 255 * hi * (1 + 1.0 / 255) + 1e-6);  // rgb rounding, scaled by a * range
            }
            const double bound = kSqrt4Pi * e / a[0][0] + kQuadrature;
            const double d = test::sh_distance(project_envmap(*img), a);
            std::printf("%-9s %-5s: %.2e of |L00| (texel error %.4f, bound %.2e)\n", c.option, ldr_name(f), d, e, bound);
            EXPECT_LT(d, bound);
            // Read as plain 8-bit, the same file is far off: the option is what decodes it.
            auto plain = read_with(file);
            ASSERT_TRUE(plain);
            EXPECT_GT(test::sh_distance(project_envmap(*plain), a), 0.3);
        }
    }
    // The option reaches convert and dering as it reaches project.
    {
        const std::string dir = test::fresh_dir("cube_ldr_verbs");
        std::vector<float> target;
        for (size_t i = 0; i < hdr.rgb.size() / 3; ++i) {
            float e[4];
            rgbm_encode(&hdr.rgb[3 * i], 8, e);
            target.insert(target.end(), e, e + 4);
        }
        const std::string file = dir + "/rgbm.ktx2";
        test::write_bytes(file, ldr_file({"ktx2", Ldr::kRgba8, false}, n, all_faces(target, n, Ldr::kRgba8)));
        auto l00 = [](const std::string& json_text, bool probe_list) {
            const auto j = nlohmann::json::parse(json_text);
            return (probe_list ? j["probes"][0]["sh3"] : j["sh3"])[0][0].get<double>();
        };
        const auto p = test::run_zhc({"project", file, "--json", "--ldr-encoding", "rgbm:8"});
        ASSERT_EQ(p.exit_code, 0) << p.err;
        EXPECT_NEAR(l00(p.out, false), a[0][0], 3.3e-3 * a[0][0]);
        for (const char* opt : {"rgbm:8", "auto"}) {
            SCOPED_TRACE(opt);
            const auto c = test::run_zhc({"convert", file, "-o", dir + "/probe.json", "--ldr-encoding", opt});
            ASSERT_EQ(c.exit_code, 0) << c.err;
            const Bytes text = test::read_bytes(dir + "/probe.json");
            const double got = l00(std::string(text.begin(), text.end()), true);
            if (std::string(opt) == "auto") {
                EXPECT_GT(std::fabs(got - a[0][0]), 0.3 * a[0][0]);
            } else {
                EXPECT_NEAR(got, l00(p.out, false), 1e-5 * a[0][0]);
            }
        }
        EXPECT_EQ(test::run_zhc({"dering", file, "-o", dir + "/dering.json", "--ldr-encoding", "rgbm:8"}).exit_code, 0);
    }
    // RGBD cannot decode alpha 0: exit 4 (invalid input data) naming the texel.
    const std::string dir = test::fresh_dir("cube_ldr");
    Bytes zero(static_cast<size_t>(6) * 4 * 4 * 4, 200);
    zero[4 * 5 + 3] = 0;  // face 0, texel (1, 1)
    test::write_bytes(dir + "/rgbd0.ktx2", ktx2_one_level(37, 1, 4, zero));
    const auto r = test::run_zhc({"project", dir + "/rgbd0.ktx2", "--ldr-encoding", "rgbd:255"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_NE(r.err.find("face 0 texel (1, 1) has alpha 0"), std::string::npos) << r.err;
    EXPECT_EQ(test::run_zhc({"project", dir + "/rgbd0.ktx2", "--ldr-encoding", "rgbm:4"}).exit_code, 0);
}

TEST(CubeLdr, SceneEnvironmentTakesTheLdrEncoding) {
    const int n = 32;
    const Sh3Radiance a = test_sh();
    const Image hdr = render_cube(n, [&](Vec3 d) { return evaluate(a, d); });
    std::vector<float> target;
    for (size_t i = 0; i < hdr.rgb.size() / 3; ++i) {
        float e[4];
        rgbm_encode(&hdr.rgb[3 * i], 8, e);
        target.insert(target.end(), e, e + 4);
    }
    const std::string dir = test::fresh_dir("cube_ldr_scene");
    test::write_bytes(dir + "/env.ktx2", ldr_file({"ktx2", Ldr::kRgba8, false}, n, all_faces(target, n, Ldr::kRgba8)));
    auto scene_with = [&](const std::string& extra) {
        const std::string text = R"({"format": "zhc-scene", "version": 1, "probes": {"positions": [[0, 0, 0]]},
            "environment": {"map": "env.ktx2")" + extra + "}}";
        Bytes tb;
        for (char ch : text) tb.push_back(static_cast<std::uint8_t>(ch));
        test::write_bytes(dir + "/scene.json", tb);
        return read_scene_file(dir + "/scene.json");
    };
    auto rgbm = scene_with(R"(, "ldr_encoding": "rgbm:8")");
    ASSERT_TRUE(rgbm) << rgbm.error().message;
    ASSERT_TRUE(rgbm->environment);
    EXPECT_EQ(rgbm->environment->ldr_encoding, "rgbm:8");
    EXPECT_LT(test::sh_distance(rgbm->environment->projected, a), 3.3e-3);  // RgbmAndRgbdRoundTrip's bound for RGBA8
    EXPECT_NE(scene_json(*rgbm).find("\"ldr_encoding\": \"rgbm:8\""), std::string::npos) << scene_json(*rgbm);
    auto plain = scene_with("");
    ASSERT_TRUE(plain) << plain.error().message;
    EXPECT_GT(test::sh_distance(plain->environment->projected, a), 0.3);
    auto bad = scene_with(R"(, "ldr_encoding": "rgbm")");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().code, ErrorCode::kInvalidValue);
    EXPECT_NE(bad.error().message.find("environment.ldr_encoding"), std::string::npos) << bad.error().message;
}

// ---- 4. BC1 / BC3 faces written by ImageMagick -------------------------------------------------

TEST(CubeLdr, ImageMagickBlocksInCubeContainers) {
    const int n = 64;
    const Linear fn;
    const Sh3Radiance a = fn.sh();
    const Image lin = render_cube(n, fn);
    const std::string dir = test::fresh_dir("cube_ldr_magick");
    for (bool srgb : {true, false}) {
        const std::vector<float> target = ldr_target(lin, srgb);
        for (Ldr f : {Ldr::kBc1, Ldr::kBc3}) {
            SCOPED_TRACE(std::string(ldr_name(f)) + (srgb ? " sRGB" : " UNORM"));
            Bytes faces;
            for (int face = 0; face < 6; ++face) {
                // The face as an 8-bit PAM, then ImageMagick's DXT1 / DXT5 DDS of it.
                const std::string pam = dir + "/face" + std::to_string(face) + ".pam", out = dir + "/face" + std::to_string(face) + ".dds";
                std::string text = "P7\nWIDTH " + std::to_string(n) + "\nHEIGHT " + std::to_string(n) +
                                   "\nDEPTH 4\nMAXVAL 255\nTUPLTYPE RGB_ALPHA\nENDHDR\n";
                Bytes pix;
                for (char ch : text) pix.push_back(static_cast<std::uint8_t>(ch));
                for (size_t i = 0; i < static_cast<size_t>(n) * n * 4; ++i) pix.push_back(q8(target[static_cast<size_t>(face) * n * n * 4 + i]));
                test::write_bytes(pam, pix);
                const std::string cmd = "convert '" + pam + "' -define dds:compression=" + (f == Ldr::kBc1 ? "dxt1" : "dxt5") +
                                        " -define dds:mipmaps=0 '" + out + "'";
                ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
                const Bytes d = test::read_bytes(out);
                const size_t blocks = static_cast<size_t>(n / 4) * (n / 4) * (f == Ldr::kBc1 ? 8 : 16);
                ASSERT_EQ(d.size(), 128 + blocks) << "ImageMagick wrote a DDS of another shape";
                ASSERT_EQ(test::get32(d, 84), f == Ldr::kBc1 ? 0x31545844u : 0x35545844u);
                faces.insert(faces.end(), d.begin() + 128, d.end());
            }
            const double e = twin_error(faces, lin, n, f, srgb);
            const double bound = e / fn.c[2] + kQuadrature;
            for (const char* container : {"ktx2", "ktx1", "dds"}) {
                const Bytes file = ldr_file({container, f, srgb}, n, faces);
                auto img = read_with(file);
                ASSERT_TRUE(img) << img.error().message;
                const double d = test::sh_distance(project_envmap(*img), a);
                std::printf("ImageMagick %s %-5s in %-4s: %.2e of |L00| (texel error %.4f, bound %.2e)\n", ldr_name(f),
                            srgb ? "sRGB" : "UNORM", container, d, e, bound);
                EXPECT_LT(d, bound);
            }
        }
    }
}

// ---- 5. hostile KTX 1 ---------------------------------------------------------------------------

Bytes small_ktx1(const Ktx1Spec& s) {
    const Image cube = render_cube(8, [](Vec3 d) { return Rgb{float(d.x + 2), 1.0f, 0.5f}; });
    Bytes faces;
    for (int face = 0; face < 6; ++face) {
        const Bytes f = encode_face(cube, face, Fmt::kRgba16f);
        faces.insert(faces.end(), f.begin(), f.end());
    }
    return ktx1(s, 8, faces);
}

TEST(CubeLdr, Ktx1HostileFilesAreRefusedCleanly) {
    Ktx1Spec three = spec(kHalf, 2, kRgba, 0x881A, 8, 0);
    three.levels = 3;
    const Bytes good = small_ktx1(three);
    ASSERT_TRUE(read_with(good));
    for (size_t len = 0; len < good.size(); ++len) {
        auto r = read_with(Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(len)));
        ASSERT_FALSE(r) << len;
        EXPECT_TRUE(r.error().code == ErrorCode::kTruncated || r.error().code == ErrorCode::kBadFormat) << r.error().message;
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    }
    for (size_t i = 0; i < good.size(); ++i) {  // every single-byte change: read or refused in one line
        Bytes t = good;
        t[i] ^= 0x5A;
        auto r = read_with(t);
        if (!r) {
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
        }
    }
    const std::string dir = test::fresh_dir("cube_ldr_hostile");
    struct Case {
        std::string name;
        Bytes bytes;
        int exit_code;
        std::string says;
    };
    std::vector<Case> cases;
    auto edit = [&](size_t at, std::uint32_t v) {
        Bytes b = good;
        test::put32(b, at, v);
        return b;
    };
    cases.push_back({"astc", small_ktx1(spec(0, 1, 0, 0x93B0, 0, 16)), 5, "KTX 1 glInternalFormat 0x93B0 (byte 28) is not supported"});
    cases.push_back({"rgba4", small_ktx1(spec(0x8033, 2, kRgba, 0x8056, 2, 0)), 5, "KTX 1 glInternalFormat 0x8056"});
    cases.push_back({"etc2", small_ktx1(spec(0, 1, 0, 0x9278, 0, 16)), 5, "KTX 1 glInternalFormat 0x9278"});
    cases.push_back({"half as bytes", small_ktx1(spec(0x1401, 1, kRgba, 0x881A, 4, 0)), 5, "glType 0x1401"});
    cases.push_back({"one face", edit(52, 1), 5, "numberOfFaces 1"});
    cases.push_back({"array", edit(48, 2), 5, "numberOfArrayElements 2"});
    cases.push_back({"endianness", edit(12, 0x12345678), 4, "endianness"});
    cases.push_back({"type size", edit(20, 4), 4, "glTypeSize 4"});
    cases.push_back({"not square", edit(40, 4), 4, "square"});
    cases.push_back({"image size", edit(64, 12345), 4, "imageSize 12345"});
    cases.push_back({"kvd past end", edit(60, 1u << 30), 4, "bytesOfKeyValueData"});
    cases.push_back({"too many levels", edit(56, 9), 4, "numberOfMipmapLevels 9"});
    Bytes huge = edit(36, 1u << 16);
    test::put32(huge, 40, 1u << 16);
    cases.push_back({"huge face", huge, 6, "exceeds the limit"});
    Bytes trailing = good;
    trailing.resize(trailing.size() + 4, 0);
    cases.push_back({"trailing", trailing, 4, "trailing bytes"});
    Bytes truncated(good.begin(), good.end() - 100);
    cases.push_back({"truncated", truncated, 4, "truncated"});
    // A face of 2048 RGBA32F claims 6 x 2048^2 x 16 bytes = 402 MB in a file of a few hundred:
    // refused before anything that size is allocated (the process's peak memory stays put).
    Bytes big = small_ktx1(spec(kFloat, 4, kRgba, 0x8814, 16, 0));
    test::put32(big, 36, 2048);
    test::put32(big, 40, 2048);
    test::put32(big, 64, 2048u * 2048u * 16u);
    cases.push_back({"big claim", big, 4, "KTX 1 level 0 truncated"});
    rusage before{};
    getrusage(RUSAGE_SELF, &before);
    auto r_big = read_with(big);
    rusage after{};
    getrusage(RUSAGE_SELF, &after);
    ASSERT_FALSE(r_big);
    EXPECT_EQ(r_big.error().code, ErrorCode::kTruncated) << r_big.error().message;
    EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 64 * 1024) << "KiB of peak memory added by a refused file";
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const std::string path = dir + "/" + std::to_string(&c - cases.data()) + ".ktx";
        test::write_bytes(path, c.bytes);
        const auto r = test::run_zhc({"project", path});
        EXPECT_EQ(r.exit_code, c.exit_code) << r.err;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    // The CLI verbs read KTX 1 cubes: project, info, convert.
    const std::string path = dir + "/good.ktx";
    test::write_bytes(path, good);
    const auto info = test::run_zhc({"info", path});
    EXPECT_EQ(info.exit_code, 0) << info.err;
    EXPECT_NE(info.out.find("ktx1"), std::string::npos) << info.out;
    EXPECT_EQ(test::run_zhc({"convert", path, "-o", dir + "/good.json"}).exit_code, 0);
}

}  // namespace
}  // namespace zhc

namespace zhc {
namespace {

// ---- 6. fuzz seeds ----------------------------------------------------------------------------
// fuzz/corpus/fuzz_envmap/ holds small KTX 1 and 8-bit cube maps made by this test's writers
// (ZHC_UPDATE_FUZZ_SEEDS=1 rewrites them); each must read as the cube it is.
TEST(CubeLdr, FuzzSeedsReadAsCubes) {
    const std::string dir = std::string(ZHC_TEST_DATA_DIR) + "/../../fuzz/corpus/fuzz_envmap/";
    const Linear fn;
    auto faces_of = [&](int n, Ldr f, bool srgb) { return all_faces(ldr_target(render_cube(n, fn), srgb), n, f); };
    auto half_faces = [&](int n) {
        Bytes b;
        const Image cube = render_cube(n, fn);
        for (int face = 0; face < 6; ++face) {
            const Bytes f = encode_face(cube, face, Fmt::kRgba16f);
            b.insert(b.end(), f.begin(), f.end());
        }
        return b;
    };
    Ktx1Spec le = spec(kHalf, 2, kRgba, 0x881A, 8, 0);
    le.levels = 3;
    le.kvd = std::string("KTXorientation\0S=r,T=d", 23);
    Ktx1Spec be = spec(kHalf, 2, kRgba, 0x881A, 8, 0);
    be.big_endian = true;
    const struct {
        const char* file;
        Bytes bytes;
        const char* format;
    } seeds[] = {
        {"cube-rgba16f.ktx", ktx1(le, 4, half_faces(4)), "ktx1"},
        {"cube-rgba16f-big-endian.ktx", ktx1(be, 4, half_faces(4)), "ktx1"},
        {"cube-bc1-srgb.ktx", ldr_file({"ktx1", Ldr::kBc1, true}, 8, faces_of(8, Ldr::kBc1, true)), "ktx1"},
        {"cube-rgba8-srgb.ktx2", ldr_file({"ktx2", Ldr::kRgba8, true}, 4, faces_of(4, Ldr::kRgba8, true)), "ktx2"},
        {"cube-bc3-dx10.dds", ldr_file({"dds", Ldr::kBc3, false}, 8, faces_of(8, Ldr::kBc3, false)), "dds"},
        {"cube-dxt1-legacy.dds", ldr_file({"dds-legacy", Ldr::kBc1, false}, 8, faces_of(8, Ldr::kBc1, false)), "dds"},
        {"cube-bgra8-legacy.dds", ldr_file({"dds-legacy", Ldr::kBgra8, false}, 4, faces_of(4, Ldr::kBgra8, false)), "dds"},
    };
    const char* update = std::getenv("ZHC_UPDATE_FUZZ_SEEDS");
    for (const auto& s : seeds) {
        SCOPED_TRACE(s.file);
        if (update && std::string(update) == "1") test::write_bytes(dir + s.file, s.bytes);
        const Bytes committed = test::read_bytes(dir + s.file);
        EXPECT_EQ(committed, s.bytes) << "the committed seed differs from the writers' (ZHC_UPDATE_FUZZ_SEEDS=1 rewrites it)";
        EnvmapInfo info;
        auto img = read_with(committed, {}, &info);
        ASSERT_TRUE(img) << img.error().message;
        EXPECT_EQ(info.format, s.format);
        EXPECT_LT(test::sh_distance(project_envmap(*img), fn.sh()), 0.05);
    }
}

}  // namespace
}  // namespace zhc
