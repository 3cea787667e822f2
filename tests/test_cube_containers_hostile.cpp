// KTX2 and DDS environment cube maps (formats/envmap/envmap_cube.h): every prefix of every case and
// hostile variants refused cleanly, through the library and the CLI (README exit codes); the CLI
// verbs read cubes (helpers: cube_helpers.h, the test's own writers).
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
#include "cube_helpers.h"
#include "support.h"

namespace zhc {
namespace {

using namespace cube_test;

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
        more.push_back(std::string(c.container) == "dds" ? 7 : 0);  // DDS: zero padding is read (below)
        auto r = read(more);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, ErrorCode::kTrailingBytes) << r.error().message;
    }
}

// Bytes after a DDS cube's six faces: DirectXTex's loader (DirectXTexDDS.cpp CopyImage) needs the
// bytes the header describes and ignores any after them. zhc ignores them when they are all zero
// (padding) and refuses any other (kTrailingBytes naming the first non-zero byte, exit 4): data
// the header does not describe could mean the faces sit elsewhere (an undeclared mip chain).
// Constructed: every DDS case with 1 byte and a mip level's worth of zeros reads bit for bit as
// without. Real: derkreature/IBLBaker's paperMillDiffuseMDR.dds (32-pixel RGBA8 faces, 6,144 zero
// bytes after them) reads, and every texel is the file's bytes at the offset the header gives.
TEST(CubeContainers, DdsZeroPaddingIgnoredOtherTrailingBytesRefused) {
    const Image cube = render_cube(8, [](Vec3 d) { return Rgb{float(d.x + 2), 1.0f, float(d.z + 1.5)}; });
    for (const Case& c : kCases) {
        if (std::string(c.container) != "dds") continue;
        SCOPED_TRACE(std::to_string(static_cast<int>(c.fmt)) + (c.legacy ? " legacy" : " dx10"));
        const auto good = write(c, cube);
        auto plain = read(good);
        ASSERT_TRUE(plain) << plain.error().message;
        const size_t level1 = write(c, cube, 2).size() - good.size();  // one mip level of the six faces
        for (size_t pad : {size_t(1), level1}) {
            auto padded = good;
            padded.resize(good.size() + pad, 0);
            auto r = read(padded);
            ASSERT_TRUE(r) << pad << ": " << r.error().message;
            EXPECT_EQ(r->rgb, plain->rgb);
            padded[good.size() + pad / 2] = 1;
            r = read(padded);
            ASSERT_FALSE(r);
            EXPECT_EQ(r.error().code, ErrorCode::kTrailingBytes) << r.error().message;
            EXPECT_NE(r.error().message.find("(byte " + std::to_string(good.size() + pad / 2) + " is not)"), std::string::npos)
                << r.error().message;
        }
    }
    const std::string file = std::string(ZHC_TEST_DATA_DIR) + "/cube/iblbaker_paperMillDiffuseMDR.dds";
    const std::vector<std::uint8_t> b = test::read_bytes(file);
    constexpr size_t kFace = 32 * 32 * 4, kData = 128 + 6 * kFace;
    ASSERT_EQ(b.size(), kData + 6144);
    EXPECT_EQ(std::count(b.begin() + kData, b.end(), 0), 6144);
    EnvmapInfo info;
    auto img = read_envmap_memory(b, file, {}, &info);
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_EQ(info.format, "dds");
    EXPECT_EQ(info.channels, "RGBA8 UNORM");  // masks R 000000ff, G 0000ff00, B 00ff0000, A ff000000
    ASSERT_EQ(img->width, 32);
    ASSERT_EQ(img->height, 6 * 32);
    size_t differ = 0;
    for (size_t f = 0; f < 6; ++f)
        for (size_t t = 0; t < 32 * 32; ++t) {
            const std::uint8_t* p = b.data() + 128 + f * kFace + t * 4;  // R, G, B, A
            const float* q = img->rgb.data() + (f * 32 * 32 + t) * 3;
            for (int k = 0; k < 3; ++k) differ += std::abs(q[k] - p[k] / 255.0f) > 1e-6f;  // UNORM read as linear
        }
    EXPECT_EQ(differ, 0u);
    // Without its padding: the same image.
    auto cut = read_envmap_memory(std::vector<std::uint8_t>(b.begin(), b.begin() + kData), file, {}, nullptr);
    ASSERT_TRUE(cut) << cut.error().message;
    EXPECT_EQ(cut->rgb, img->rgb);
    // The CLI: exit 0; a non-zero byte in the padding: exit 4 naming it.
    const std::string dir = test::fresh_dir("cube_dds_padding");
    EXPECT_EQ(test::run_zhc({"project", file, "--json"}).exit_code, 0);
    auto bad = b;
    bad[kData + 100] = 0x40;
    test::write_bytes(dir + "/bad.dds", bad);
    const auto r = test::run_zhc({"project", dir + "/bad.dds", "--json"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_NE(r.err.find("6144 trailing bytes after the DDS data (which ends at byte 24704), not all zero (byte 24804 is not)"),
              std::string::npos) << r.err;
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
        {"astc.ktx2", &ktx, {{12, 157}, {16, 1}}, 5},  // ASTC_4x4_UNORM_BLOCK: no ASTC decoder
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
