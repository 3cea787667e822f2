// KTX2 and DDS environment cube maps (formats/envmap/envmap_cube.h): the Vulkan / D3D face table,
// analytic SH3 maps in every pixel format, consistency with the lat-long sample maps, mip chains,
// and hostile variants through the CLI (README exit codes).
//
// The files are written here, by this test's own KTX2 / DDS writers (from the KTX 2.0
// specification and Microsoft's DDS documentation), not by zhc: zhc has no cube-map writer. No
// Debian package writes KTX2 or float DDS cube maps (checked: no ktx-tools / libktx in the
// archive; ImageMagick's DDS coder writes 2-D DXT1/DXT5/8-bit textures only).
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

namespace zhc {
namespace {

// ---- the spec's face table, written out independently of codec/cubemap --------------------
// Vulkan "Cube Map Face Selection": major axis -> (face, sc, tc, ma); s = (sc / |ma| + 1) / 2,
// t = (tc / |ma| + 1) / 2. Direction r in the API frame (Y up).
void select_face(double rx, double ry, double rz, int* face, double* s, double* t) {
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
void to_api(Vec3 d, double* rx, double* ry, double* rz) {
    *rx = d.y;
    *ry = d.z;
    *rz = d.x;
}

// A known SH3 radiance function with every coefficient non-zero and positive values everywhere
// (unsigned formats: RGB9E5, BC6H_UFLOAT).
Sh3Radiance test_sh() {
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
const char* fmt_name(Fmt f) {
    switch (f) {
        case Fmt::kRgba16f: return "rgba16f";
        case Fmt::kRgba32f: return "rgba32f";
        case Fmt::kRgb9e5: return "rgb9e5";
        default: return "bc6h";
    }
}

void put16(std::vector<std::uint8_t>& b, std::uint16_t v) {
    b.push_back(static_cast<std::uint8_t>(v));
    b.push_back(static_cast<std::uint8_t>(v >> 8));
}
void put32v(std::vector<std::uint8_t>& b, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}
void put64v(std::vector<std::uint8_t>& b, std::uint64_t v) {
    for (int k = 0; k < 8; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

// RGB9E5 as the Vulkan / OpenGL specification's shared-exponent conversion defines it.
std::uint32_t encode_rgb9e5(const float* rgb) {
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
std::vector<std::uint8_t> encode_face(const Image& cube, int face, Fmt f) {
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
Image half_cube(const Image& c) {
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

std::uint32_t vk_of(Fmt f) { return f == Fmt::kRgba16f ? 97 : f == Fmt::kRgba32f ? 109 : f == Fmt::kRgb9e5 ? 123 : 143; }

// KTX2: header, level index, a basic DFD-shaped block (not read by zhc), then the levels, smallest
// first, each aligned to lcm(texel block size, 4). `levels` mip levels (box-filtered; the lower
// levels are darker by `mip_scale` so that reading one instead of level 0 would show).
// `zstd`: supercompressionScheme 2, each level one Zstandard frame (alignment 1).
std::vector<std::uint8_t> write_ktx2(const Image& cube, Fmt f, int levels = 1, float mip_scale = 1.0f, bool zstd = false) {
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
std::vector<std::uint8_t> write_dds(const Image& cube, Fmt f, bool legacy, int levels = 1, float mip_scale = 1.0f) {
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

Result<Image> read(const std::vector<std::uint8_t>& b, EnvmapInfo* info = nullptr) {
    return read_envmap_memory(b, "test", {}, info);
}

// ---- 1. the face table ---------------------------------------------------------------------

TEST(CubeContainers, FaceTableIsVulkans) {
    // Every texel centre's direction (codec/cubemap, kCubeLayoutVulkan) selects, by the spec's
    // table, its own face at its own s, t; cube_nearest_pixel inverts it; and the test's own
    // renderer (solved from the table) agrees.
    for (int n : {1, 2, 5, 16}) {
        const Image ids = render_cube(n, [](Vec3 d) { return Rgb{float(d.x), float(d.y), float(d.z)}; });
        for (int face = 0; face < 6; ++face)
            for (int row = 0; row < n; ++row)
                for (int col = 0; col < n; ++col) {
                    const Vec3 d = cube_direction(kCubeLayoutVulkan, face, col, row, n);
                    double rx, ry, rz, s, t;
                    int f;
                    to_api(d, &rx, &ry, &rz);
                    select_face(rx, ry, rz, &f, &s, &t);
                    ASSERT_EQ(f, face);
                    EXPECT_NEAR(s, (col + 0.5) / n, 1e-12);
                    EXPECT_NEAR(t, (row + 0.5) / n, 1e-12);
                    const float* p = ids.row(face * n + row) + 3 * col;
                    EXPECT_NEAR(p[0], d.x, 1e-6);
                    EXPECT_NEAR(p[1], d.y, 1e-6);
                    EXPECT_NEAR(p[2], d.z, 1e-6);
                    int nf, nc, nr;
                    cube_nearest_pixel(kCubeLayoutVulkan, d, n, &nf, &nc, &nr);
                    EXPECT_EQ(nf, face);
                    EXPECT_EQ(nc, col);
                    EXPECT_EQ(nr, row);
                }
    }
    // API +Y is zhc +Z (up): the +Y face's centre looks up.
    const Vec3 up = cube_direction(kCubeLayoutVulkan, 2, 0.0, 0.0, 1);
    EXPECT_NEAR(up.z, 1.0, 1e-12);
    // Solid angles tile the sphere.
    for (int n : {1, 3, 64}) {
        double total = 0;
        for (int r = 0; r < n; ++r)
            for (int c = 0; c < n; ++c) total += 6 * cube_pixel_solid_angle(kCubeLayoutVulkan, c, r, n);
        EXPECT_NEAR(total, 4 * M_PI, 1e-10) << n;
    }
}

// ---- 2. analytic maps in every format and both containers ------------------------------------

struct Case {
    const char* container;
    Fmt fmt;
    bool legacy;
    double tol;  // of |L00|
};

std::vector<std::uint8_t> write(const Case& c, const Image& cube, int levels = 1, float mip_scale = 1.0f) {
    return std::string(c.container) == "ktx2" ? write_ktx2(cube, c.fmt, levels, mip_scale)
                                              : write_dds(cube, c.fmt, c.legacy, levels, mip_scale);
}

// Tolerances (measured at N = 64, see the notes): float formats 2e-5 (the texel-centre quadrature,
// O(1/N^2)); half 1e-4; RGB9E5 6e-4 (9-bit mantissas); BC6H 4e-3.
const Case kCases[] = {
    {"ktx2", Fmt::kRgba32f, false, 1e-4}, {"ktx2", Fmt::kRgba16f, false, 3e-4}, {"ktx2", Fmt::kRgb9e5, false, 2e-3},
    {"ktx2", Fmt::kBc6h, false, 1e-2},    {"dds", Fmt::kRgba32f, true, 1e-4},   {"dds", Fmt::kRgba16f, true, 3e-4},
    {"dds", Fmt::kRgba32f, false, 1e-4},  {"dds", Fmt::kRgba16f, false, 3e-4},  {"dds", Fmt::kRgb9e5, false, 2e-3},
    {"dds", Fmt::kBc6h, false, 1e-2},
};

TEST(CubeContainers, AnalyticShMapProjectsBackInEveryFormat) {
    const Sh3Radiance a = test_sh();
    const int n = 64;
    const Image cube = render_cube(n, [&](Vec3 d) { return evaluate(a, d); });
    const double exact = test::sh_distance(project_envmap(cube), a);  // the quadrature alone
    std::printf("analytic SH3, N=64, float cube in memory: %.2e of |L00|\n", exact);
    EXPECT_LT(exact, 1e-4);
    for (const Case& c : kCases) {
        SCOPED_TRACE(std::string(c.container) + " " + fmt_name(c.fmt) + (c.legacy ? " legacy" : ""));
        EnvmapInfo info;
        auto img = read(write(c, cube), &info);
        ASSERT_TRUE(img) << img.error().message;
        ASSERT_EQ(img->layout, EnvmapLayout::kCubeVulkan);
        ASSERT_EQ(img->width, n);
        ASSERT_EQ(img->height, 6 * n);
        EXPECT_EQ(info.format, c.container);
        EXPECT_EQ(info.layout, "cube");
        const double d = test::sh_distance(project_envmap(*img), a);
        std::printf("%-4s %-8s %-6s: %.2e of |L00| (tolerance %.0e)\n", c.container, fmt_name(c.fmt), c.legacy ? "legacy" : "",
                    d, c.tol);
        EXPECT_LT(d, c.tol);
        if (c.fmt == Fmt::kRgba32f) {
            EXPECT_EQ(img->rgb, cube.rgb);  // bit exact
        }
        if (c.fmt == Fmt::kRgba16f) {
            for (size_t i = 0; i < cube.rgb.size(); ++i)
                ASSERT_EQ(img->rgb[i], bc6h::half_to_float(bc6h::float_to_half(cube.rgb[i]))) << i;
        }
    }
    // A mirrored reading (OpenEXR's right-handed table on the same texels) is far off: the test
    // can see orientation mistakes.
    Image wrong = cube;
    wrong.layout = EnvmapLayout::kCubeOpenExr;
    EXPECT_GT(test::sh_distance(project_envmap(wrong), a), 0.01);
}

TEST(CubeContainers, ConstantCubeHasOnlyL00) {
    const int n = 64;
    const Rgb c{0.5f, 1.0f, 2.0f};
    const Image cube = render_cube(n, [&](Vec3) { return c; });
    for (const Case& k : kCases) {
        SCOPED_TRACE(std::string(k.container) + " " + fmt_name(k.fmt));
        auto img = read(write(k, cube));
        ASSERT_TRUE(img) << img.error().message;
        const Sh3Radiance s = project_envmap(*img);
        for (int ch = 0; ch < 3; ++ch) {
            // L00 = c * sqrt(4 pi) (the half / RGB9E5 / BC6H value of c is c exactly: powers of 2)
            EXPECT_NEAR(s[0][ch], c[ch] * std::sqrt(4 * M_PI), 1e-5 * c[ch]);
            for (int i = 1; i < 9; ++i) EXPECT_NEAR(s[i][ch], 0.0, 1e-6) << i;
        }
    }
}

TEST(CubeContainers, ZstdSupercompressedKtx2ReadsLikeTheRawOne) {
    const Sh3Radiance a = test_sh();
    const Image cube = render_cube(64, [&](Vec3 d) { return evaluate(a, d); });
    for (Fmt f : {Fmt::kRgba16f, Fmt::kRgba32f, Fmt::kRgb9e5, Fmt::kBc6h}) {
        SCOPED_TRACE(fmt_name(f));
        EnvmapInfo info;
        const auto raw = read(write_ktx2(cube, f, 3, 0.5f));
        const auto z = read(write_ktx2(cube, f, 3, 0.5f, true), &info);
        ASSERT_TRUE(raw && z) << (z ? "" : z.error().message);
        EXPECT_EQ(raw->rgb, z->rgb);
        EXPECT_EQ(info.compression, "zstd");
    }
    const auto small = write_ktx2(render_cube(4, [](Vec3) { return Rgb{1, 2, 3}; }), Fmt::kRgba16f, 3, 0.5f, true);
    ASSERT_TRUE(read(small));
    for (size_t len = 0; len < small.size(); ++len) {
        auto r = read({small.begin(), small.begin() + static_cast<std::ptrdiff_t>(len)});
        ASSERT_FALSE(r) << len;
        EXPECT_TRUE(r.error().code == ErrorCode::kTruncated || r.error().code == ErrorCode::kBadFormat) << r.error().message;
    }
    // Every single-byte change is refused or read (never a crash; checked under the sanitizers).
    for (size_t i = 0; i < small.size(); ++i) {
        auto t = small;
        t[i] ^= 0xA5;
        auto r = read(t);
        if (!r) {
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
        }
    }
}

TEST(CubeContainers, MipChainsReadLevelZero) {
    // Lower levels scaled by 0.5 per level: reading any of them would change L00.
    const Sh3Radiance a = test_sh();
    const Image cube = render_cube(32, [&](Vec3 d) { return evaluate(a, d); });
    for (const Case& c : kCases) {
        SCOPED_TRACE(std::string(c.container) + " " + fmt_name(c.fmt));
        const auto one = read(write(c, cube));
        const auto mips = read(write(c, cube, 6, 0.5f));
        ASSERT_TRUE(one && mips) << (mips ? "" : mips.error().message);
        EXPECT_EQ(one->rgb, mips->rgb);
    }
}

// ---- 3. consistency with a lat-long sample map ------------------------------------------------

// Nearest pixel of a lat-long map in direction d (the inverse of latlong_direction).
const float* latlong_pixel(const Image& ll, Vec3 d) {
    const double phi = std::atan2(d.y, d.x), theta = std::acos(std::clamp(d.z, -1.0, 1.0));
    const double col = 0.5 * ll.width * (1.0 - phi / M_PI) - 0.5, row = theta / M_PI * ll.height - 0.5;
    const int c = std::clamp(static_cast<int>(std::lround(col)), 0, ll.width - 1);
    const int r = std::clamp(static_cast<int>(std::lround(row)), 0, ll.height - 1);
    return ll.row(r) + 3 * c;
}

TEST(CubeContainers, SampleMapAsCubeProjectsLikeTheLatLong) {
    // Each sample map resampled to a Vulkan-layout cube (face 128, 4x4 nearest-pixel samples per
    // texel, directions from the test's own table), written as KTX2 / DDS, must project like the
    // lat-long original. Measured (city, courtyard, forest): float / half 0.20% to 0.51% of |L00|
    // (the resampling; threshold 0.6%); BC6H 0.29% to 3.6% (city: its sun, a few very bright
    // texels sharing BC6H blocks with sky, is where BC6H's error goes; threshold 5%). The BC6H
    // error alone (BC6H cube against the same cube in float) is printed too.
    const int n = 128, sub = 4;
    double worst[2] = {0, 0};
    auto paths = test::envmap_paths();
    ASSERT_FALSE(paths.empty());
    if (paths.size() > 3) paths.resize(3);  // time: three maps
    for (const std::string& path : paths) {
        SCOPED_TRACE(path);
        const Image ll = test::load_envmap(path);
        const Sh3Radiance ref = project_envmap(ll);
        // Sub-sample directions: render_cube at n * sub, then box-average down to n.
        Image fine = render_cube(n * sub, [&](Vec3 d) {
            const float* p = latlong_pixel(ll, d);
            return Rgb{p[0], p[1], p[2]};
        });
        while (fine.width > n) fine = half_cube(fine);
        float brightest = 0;
        for (float v : fine.rgb) brightest = std::max(brightest, v);
        ASSERT_LT(brightest, 65504.0f);  // half / BC6H hold every value: no clamping in this comparison
        const Sh3Radiance float_cube = project_envmap(fine);
        for (const Case& c : kCases) {
            if (c.fmt == Fmt::kRgb9e5 || (c.legacy && std::string(c.container) == "dds")) continue;
            SCOPED_TRACE(std::string(c.container) + " " + fmt_name(c.fmt));
            auto img = read(write(c, fine));
            ASSERT_TRUE(img) << img.error().message;
            const double d = test::sh_distance(project_envmap(*img), ref);
            const bool bc = c.fmt == Fmt::kBc6h;
            std::printf("%-10s %-4s %-8s vs lat-long: %.4f of |L00| (vs the float cube: %.4f; brightest texel %.0f)\n",
                        test::envmap_name(path).c_str(), c.container, fmt_name(c.fmt), d,
                        test::sh_distance(project_envmap(*img), float_cube), brightest);
            EXPECT_LT(d, bc ? 0.05 : 0.006);
            worst[bc] = std::max(worst[bc], d);
        }
    }
    std::printf("worst: float/half %.4f, BC6H %.4f of |L00|\n", worst[0], worst[1]);
}

// ---- 4. hostile variants --------------------------------------------------------------------

TEST(CubeContainers, EveryPrefixIsRefusedCleanly) {
    const Image cube = render_cube(4, [](Vec3 d) { return Rgb{float(d.x + 2), 1.0f, 0.5f}; });
    for (const Case& c : kCases) {
        const auto good = write(c, cube, 3);
        ASSERT_TRUE(read(good));
        for (size_t len = 0; len < good.size(); ++len) {
            const std::vector<std::uint8_t> cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(len));
            auto r = read(cut);
            ASSERT_FALSE(r) << len;
            EXPECT_TRUE(r.error().code == ErrorCode::kTruncated || r.error().code == ErrorCode::kBadFormat) << r.error().message;
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
        }
        auto more = good;
        more.push_back(0);
        auto r = read(more);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, ErrorCode::kTrailingBytes) << r.error().message;
    }
}

struct Hostile {
    std::string name;
    std::vector<std::uint8_t> bytes;
    int exit_code;
};

std::vector<Hostile> hostile_set() {
    const Image cube = render_cube(8, [](Vec3 d) { return Rgb{float(d.x + 2), 1.0f, 0.5f}; });
    const auto ktx = write_ktx2(cube, Fmt::kRgba16f);
    const auto dds = write_dds(cube, Fmt::kRgba16f, false);
    const auto dds_legacy = write_dds(cube, Fmt::kRgba16f, true);
    std::vector<Hostile> v;
    v.push_back({"good.ktx2", ktx, 0});
    v.push_back({"good.dds", dds, 0});
    v.push_back({"good_legacy.dds", dds_legacy, 0});
    v.push_back({"truncated.ktx2", {ktx.begin(), ktx.end() - 1}, 4});
    v.push_back({"truncated.dds", {dds.begin(), dds.end() - 1}, 4});
    // One header field changed: {file name, base file, {byte offset, new 32-bit value}..., exit code}.
    struct Patch {
        const char* name;
        const std::vector<std::uint8_t>* base;
        std::vector<std::pair<std::size_t, std::uint32_t>> fields;
        int exit_code;
    };
    constexpr std::uint32_t kAllButMinusZ = 0x200 | 0x400 | 0x800 | 0x1000 | 0x2000 | 0x4000;
    const Patch patches[] = {
        {"faces5.ktx2", &ktx, {{36, 5}}, 4},
        {"faces1.ktx2", &ktx, {{36, 1}}, 5},  // a 2-D texture
        {"array.ktx2", &ktx, {{32, 2}}, 5},
        {"zstd_raw.ktx2", &ktx, {{44, 2}}, 4},  // says Zstandard, holds raw texels
        {"basislz.ktx2", &ktx, {{44, 1}}, 5},
        {"bc6h_sfloat.ktx2", &ktx, {{12, 144}, {16, 1}}, 5},
        {"rgba8.ktx2", &ktx, {{12, 37}}, 5},  // R8G8B8A8_UNORM
        {"huge.ktx2", &ktx, {{20, 60000}, {24, 60000}}, 6},
        {"not_square.ktx2", &ktx, {{24, 4}}, 4},
        {"level_length.ktx2", &ktx, {{80 + 8, 0xFFFFFFF0u}}, 4},  // level 0 byteLength
        {"level_offset.ktx2", &ktx, {{80, 0xFFFFFFF0u}}, 4},      // level 0 offset beyond the file
        {"levels.ktx2", &ktx, {{40, 40}}, 4},                     // levelCount
        {"partial.dds", &dds, {{112, kAllButMinusZ}}, 5},         // no -Z
        {"partial_legacy.dds", &dds_legacy, {{112, 0x200 | 0x400}}, 5},
        {"flat_legacy.dds", &dds_legacy, {{112, 0}}, 5},
        {"array.dds", &dds, {{140, 2}}, 5},
        {"bc6h_sf16.dds", &dds, {{128, 96}}, 5},
        {"huge.dds", &dds, {{12, 70000}, {16, 70000}}, 6},
        {"mips.dds", &dds, {{28, 30}}, 4},
        {"header_size.dds", &dds, {{4, 100}}, 4},
    };
    for (const Patch& p : patches) {
        std::vector<std::uint8_t> t = *p.base;
        for (const auto& [offset, value] : p.fields) test::put32(t, offset, value);
        v.push_back({p.name, t, p.exit_code});
    }
    for (const auto* base : {&ktx, &dds}) {
        std::vector<std::uint8_t> t = *base;
        t.push_back(7);
        v.push_back({base == &ktx ? "trailing.ktx2" : "trailing.dds", t, 4});
    }
    const auto ktx_z = write_ktx2(cube, Fmt::kRgba16f, 2, 1.0f, true);
    v.push_back({"good_zstd.ktx2", ktx_z, 0});
    auto t = ktx_z;
    t[t.size() - 3] ^= 0x55;  // level 0 is last in the file: damage its frame
    v.push_back({"zstd_damaged.ktx2", t, 4});
    v.push_back({"header_only.dds", {dds.begin(), dds.begin() + 128}, 4});
    // zhc's own 2-D lightmap KTX2 / DDS are not environment maps.
    auto lm = encode_ktx2(test::sample_block_image(kVkFormatBc6hUfloat, 8, 8));
    v.push_back({"lightmap.ktx2", *lm, 5});
    return v;
}

TEST(CubeContainers, HostileVariantsGiveTheReadmeExitCodes) {
    const std::string dir = test::fresh_dir("cube_containers_hostile");
    for (const Hostile& h : hostile_set()) {
        SCOPED_TRACE(h.name);
        const std::string path = dir + "/" + h.name;
        test::write_bytes(path, h.bytes);
        const auto r = test::run_zhc({"project", path, "--json"});
        EXPECT_EQ(r.exit_code, h.exit_code) << r.err;
        if (h.exit_code != 0) {
            EXPECT_FALSE(r.err.empty());
            EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        }
    }
}

TEST(CubeContainers, CliProjectConvertAndAuditReadCubes) {
    // `zhc project` of a KTX2 and a DDS cube gives the analytic coefficients; `zhc audit` measures
    // sh3 against the cube's lat-long reference (SH3 holds the map exactly: small error).
    const Sh3Radiance a = test_sh();
    const Image cube = render_cube(64, [&](Vec3 d) { return evaluate(a, d); });
    const std::string dir = test::fresh_dir("cube_containers_cli");
    test::write_bytes(dir + "/env.ktx2", write_ktx2(cube, Fmt::kRgba32f));
    test::write_bytes(dir + "/env.dds", write_dds(cube, Fmt::kRgba16f, false));
    for (const char* f : {"/env.ktx2", "/env.dds"}) {
        SCOPED_TRACE(f);
        const auto r = test::run_zhc({"project", dir + f, "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto j = nlohmann::json::parse(r.out);
        Sh3Radiance s;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) s[i][k] = j["sh3"][static_cast<size_t>(i)][static_cast<size_t>(k)].get<float>();
        EXPECT_LT(test::sh_distance(s, a), 3e-4);
        EXPECT_EQ(j["layout"], "cube");
        const auto au = test::run_zhc({"audit", dir + f, "--representations", "sh3", "--json"});
        ASSERT_EQ(au.exit_code, 0) << au.err;
        const double rel = nlohmann::json::parse(au.out)["files"][0]["representations"]["sh3"]["relative_rmse"].get<double>();
        std::printf("audit %s: sh3 relative_rmse %.2e\n", f, rel);
        EXPECT_LT(rel, 5e-3);
        const auto cv = test::run_zhc({"convert", dir + f, "-o", dir + f + ".json"});
        EXPECT_EQ(cv.exit_code, 0) << cv.err;
    }
}

}  // namespace
}  // namespace zhc
