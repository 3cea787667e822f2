// ASTC lightmap targets (formats/lightmap/astc.h, lightmap_stream's astc / astc-ldr, ktx2.h's ASTC
// formats and key/value data): the vkFormat numbers, the DFD written out by hand, astcenc's bytes for
// any thread count and band height, the LDR range encoding against a long-double twin, analytic
// constant images, the streaming encode / decode against the whole-image functions, the CLI's
// refusals, and the side-by-side audit's ordering on a sample map's lightmap.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "codec/lightmap/lightmap.h"
#include "formats/envmap/envmap.h"
#include "formats/lightmap/astc.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"
#include "formats/lightmap/lightmap_stream.h"
#include "support.h"
#include "zhc_runtime.h"

namespace zhc {
namespace {

Sh3Radiance sample_world(size_t k = 0) {
    auto img = read_envmap(test::envmap_paths().at(k));
    EXPECT_TRUE(img.ok());
    return img.ok() ? project_envmap(*img, 1) : Sh3Radiance{};
}

lightmap::IrradzPlanes sample_planes(int w, int h, size_t k = 0) {
    const auto lm = lightmap::synthesize_sphere(sample_world(k), w, h, 2);
    return lightmap::fit_planes(lm, lightmap::Fit::kNewton, 2);
}

TEST(LightmapAstc, VkFormatNumbersFollowTheVulkanEnumeration) {
    // VK_FORMAT_ASTC_4x4_SFLOAT_BLOCK = 1000066000 ... (VK_EXT_texture_compression_astc_hdr, in the order
    // 4x4, 5x4, 5x5, 6x5, 6x6, 8x5, 8x6, 8x8, ...); UNORM 157, 159, 161, 163, 165, 167, 169, 171 (SRGB = UNORM + 1).
    EXPECT_EQ(astc::vk_format_hdr({4, 4}), 1000066000u);
    EXPECT_EQ(astc::vk_format_hdr({5, 5}), 1000066002u);
    EXPECT_EQ(astc::vk_format_hdr({6, 6}), 1000066004u);
    EXPECT_EQ(astc::vk_format_hdr({8, 8}), 1000066007u);
    EXPECT_EQ(astc::vk_format_ldr({4, 4}), 157u);
    EXPECT_EQ(astc::vk_format_ldr({5, 5}), 161u);
    EXPECT_EQ(astc::vk_format_ldr({6, 6}), 165u);
    EXPECT_EQ(astc::vk_format_ldr({8, 8}), 171u);
    EXPECT_EQ(astc::vk_format_ldr({5, 4}), 0u);
    EXPECT_FALSE(astc::format_of_vk(158));  // 4x4 SRGB: not written, not read
    for (astc::Footprint f : {astc::Footprint{4, 4}, {5, 5}, {6, 6}, {8, 8}}) {
        EXPECT_TRUE(astc::format_of_vk(astc::vk_format_hdr(f))->hdr);
        EXPECT_EQ(astc::format_of_vk(astc::vk_format_ldr(f))->footprint, f);
        EXPECT_EQ(ktx2_block_dims(astc::vk_format_ldr(f)), (std::array<int, 2>{f.x, f.y}));
    }
    EXPECT_EQ(ktx2_level_bytes(astc::vk_format_hdr({6, 6}), 13, 7), 3u * 2u * 16u);
}

// The Khronos Basic DFD of ASTC 6x6 SFLOAT, word by word (KDFS 1.3: model 162 KHR_DF_MODEL_ASTC,
// BT.709, linear, texelBlockDimension 5,5; one 128-bit sample, channel 0 with the float and signed
// qualifiers, lower -1.0f, upper 1.0f), and UNORM (no qualifiers, 0 .. 0xFFFFFFFF).
TEST(LightmapAstc, Ktx2DfdAndKeyValueData) {
    Ktx2Image img;
    img.vk_format = astc::vk_format_hdr({6, 6});
    img.width = 13;
    img.height = 7;
    img.blocks.assign(ktx2_level_bytes(img.vk_format, 13, 7), 0xA5);
    img.key_values.push_back({"zhc.iz_log2_range", {'1', ' ', '2', 0}});
    auto bytes = encode_ktx2(img);
    ASSERT_TRUE(bytes.ok());
    const std::vector<std::uint8_t>& b = *bytes;
    EXPECT_EQ(test::get32(b, 12), 1000066004u);
    const std::uint32_t dfd = test::get32(b, 48);
    ASSERT_EQ(dfd, 104u);
    EXPECT_EQ(test::get32(b, 52), 44u);
    const std::uint32_t expected[11] = {44, 0, 2u | (40u << 16), 162u | (1u << 8) | (1u << 16), 5u | (5u << 8), 16, 0,
                                        (127u << 16) | (0xC0u << 24), 0, 0xBF800000u, 0x3F800000u};
    for (int i = 0; i < 11; ++i) EXPECT_EQ(test::get32(b, dfd + 4 * static_cast<size_t>(i)), expected[i]) << "DFD word " << i;
    // Key/value data right after the DFD: length 18 + 4, key, NUL, value, padding.
    EXPECT_EQ(test::get32(b, 56), 148u);
    EXPECT_EQ(test::get32(b, 60), 28u);  // 4 + 22, padded to 4
    EXPECT_EQ(test::get32(b, 148), 22u);
    EXPECT_EQ(std::memcmp(b.data() + 152, "zhc.iz_log2_range\0" "1 2", 21), 0);
    EXPECT_EQ(test::get32(b, 80) % 16, 0u);  // level offset aligned to the 16-byte block
    auto back = decode_ktx2(b, "t.ktx2");
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->vk_format, img.vk_format);
    EXPECT_EQ(back->blocks, img.blocks);
    ASSERT_EQ(back->key_values.size(), 1u);
    EXPECT_EQ(back->key_values[0].key, "zhc.iz_log2_range");
    EXPECT_EQ(back->key_values[0].value, img.key_values[0].value);
    // A key without its NUL is refused.
    auto bad = b;
    bad[152 + 17] = 'x';
    for (size_t i = 152; i < 152 + 22; ++i)
        if (bad[i] == 0) bad[i] = 'x';
    auto r = decode_ktx2(bad, "bad.ktx2");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kBadFormat);
    EXPECT_NE(r.error().message.find("NUL-terminated key"), std::string::npos) << r.error().message;
    // Key/value data above 32 KiB is refused (read_ktx2_layout reads the first 64 KiB of a file).
    auto big = img;
    big.key_values.push_back({"zhc.padding", std::vector<std::uint8_t>(40000, 'x')});
    EXPECT_FALSE(encode_ktx2(big).ok());  // nor written
    auto big_bytes = *bytes;
    test::put32(big_bytes, 60, 40000);
    auto rb = decode_ktx2(big_bytes, "big.ktx2");
    ASSERT_FALSE(rb.ok());
    EXPECT_NE(rb.error().message.find("exceeds the limit 32768"), std::string::npos) << rb.error().message;
    // UNORM: no qualifiers, 0 .. 0xFFFFFFFF.
    img.vk_format = astc::vk_format_ldr({4, 4});
    img.blocks.assign(ktx2_level_bytes(img.vk_format, 13, 7), 0);
    img.key_values.clear();
    bytes = encode_ktx2(img);
    ASSERT_TRUE(bytes.ok());
    EXPECT_EQ(test::get32(*bytes, 104 + 16), 3u | (3u << 8));
    EXPECT_EQ(test::get32(*bytes, 104 + 28), 127u << 16);
    EXPECT_EQ(test::get32(*bytes, 104 + 40), 0xFFFFFFFFu);
    EXPECT_EQ(test::get32(*bytes, 56), 0u);
    EXPECT_TRUE(decode_ktx2(*bytes, "u.ktx2").ok());
}

TEST(LightmapAstc, BytesDoNotDependOnThreadsBandsOrRuns) {
    const auto p = sample_planes(60, 48);
    std::vector<float> dwa;
    for (size_t i = 0; i < p.wa.size(); ++i) dwa.insert(dwa.end(), {p.d[2 * i], p.d[2 * i + 1], p.wa[i]});
    for (astc::Footprint f : {astc::Footprint{4, 4}, {6, 6}}) {
        for (bool hdr : {true, false}) {
            const float* v = hdr ? p.iz.data() : dwa.data();
            auto one = astc::encode(v, 3, p.width, p.height, f, hdr, astc::Effort::kMedium, 1);
            ASSERT_TRUE(one.ok()) << one.error().message;
            ASSERT_EQ(one->size(), 16 * astc::block_count(f, p.width, p.height));
            for (int threads : {1, 2, 4}) {
                auto again = astc::encode(v, 3, p.width, p.height, f, hdr, astc::Effort::kMedium, threads);
                ASSERT_TRUE(again.ok());
                EXPECT_EQ(*again, *one) << "threads " << threads << " hdr " << hdr << " footprint " << f.x;
            }
            // Bands of 12 rows (whole block rows of 4 and of 6), concatenated.
            std::vector<std::uint8_t> banded;
            for (int y0 = 0; y0 < p.height; y0 += 12) {
                auto b = astc::encode(v + static_cast<size_t>(y0) * static_cast<size_t>(p.width) * 3, 3, p.width,
                                      std::min(12, p.height - y0), f, hdr, astc::Effort::kMedium, 2);
                ASSERT_TRUE(b.ok());
                banded.insert(banded.end(), b->begin(), b->end());
            }
            EXPECT_EQ(banded, *one) << "banded, hdr " << hdr << " footprint " << f.x;
        }
    }
}

TEST(LightmapAstc, ConstantImagesDecodeToTheirValue) {
    // A constant block is ASTC's void-extent block: HDR stores the half float, LDR the unorm16 value.
    const int w = 9, h = 7;
    const float rgb[3] = {0.375f, 12.5f, 1024.0f};  // exact halves
    std::vector<float> img;
    for (int i = 0; i < w * h; ++i) img.insert(img.end(), rgb, rgb + 3);
    for (astc::Footprint f : {astc::Footprint{4, 4}, {5, 5}, {6, 6}, {8, 8}}) {
        auto b = astc::encode(img.data(), 3, w, h, f, true, astc::Effort::kMedium, 1);
        ASSERT_TRUE(b.ok());
        auto d = astc::decode_rgba(b->data(), b->size(), w, h, f, true);
        ASSERT_TRUE(d.ok());
        for (int i = 0; i < w * h; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_EQ((*d)[4 * static_cast<size_t>(i) + static_cast<size_t>(k)], rgb[k]) << f.x;
        const float ldr[3] = {0.25f, 0.5f, 1.0f};
        std::vector<float> l;
        for (int i = 0; i < w * h; ++i) l.insert(l.end(), ldr, ldr + 3);
        b = astc::encode(l.data(), 3, w, h, f, false, astc::Effort::kMedium, 1);
        ASSERT_TRUE(b.ok());
        d = astc::decode_rgba(b->data(), b->size(), w, h, f, false);
        ASSERT_TRUE(d.ok());
        for (int i = 0; i < w * h; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR((*d)[4 * static_cast<size_t>(i) + static_cast<size_t>(k)], ldr[k], 1.0 / 255) << f.x;
    }
    EXPECT_EQ(astc::encode(img.data(), 3, w, h, {5, 4}, true, astc::Effort::kFast, 1).error().code, ErrorCode::kUnsupported);
}

// The LDR range encoding against its definition in long double.
TEST(LightmapAstc, LdrRangeEncodingMatchesItsDefinition) {
    const lightmap::IzLogRange r = lightmap::iz_log_range(0.01f, 40.0f);
    EXPECT_EQ(r.lo, static_cast<float>(std::log2(0.01)));
    EXPECT_EQ(r.hi, static_cast<float>(std::log2(40.0 + std::exp2(double(r.lo)))));
    const auto wide = lightmap::iz_log_range(1e-9f, 4.0f);  // at most 16 stops below the maximum
    EXPECT_FLOAT_EQ(wide.lo, 2.0f - 16);
    const auto empty = lightmap::iz_log_range(0, 0);
    EXPECT_LT(empty.lo, empty.hi);
    EXPECT_EQ(lightmap::iz_to_ldr(0, r), 0.0f);
    EXPECT_EQ(lightmap::iz_from_ldr(0, r), 0.0f);
    EXPECT_EQ(lightmap::iz_to_ldr(-3, r), 0.0f);
    EXPECT_EQ(lightmap::iz_from_ldr(std::nanf(""), r), 0.0f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0, 1);
    for (int i = 0; i < 2000; ++i) {
        const float t = u(rng);
        const long double lo = r.lo, hi = r.hi;
        const long double want = std::exp2(lo + (long double)t * (hi - lo)) - std::exp2(lo);
        EXPECT_EQ(lightmap::iz_from_ldr(t, r), static_cast<float>(want)) << t;
        const float v = 0.01f + 40 * u(rng);
        const float back = lightmap::iz_from_ldr(lightmap::iz_to_ldr(v, r), r);
        EXPECT_NEAR(back, v, 4e-6 * v) << v;
    }
    EXPECT_EQ(lightmap::iz_to_ldr(1e6f, r), 1.0f);
    // The key/value text round-trips the floats exactly; malformed values are refused.
    const auto text = lightmap_astc::range_value(r);
    const auto parsed = lightmap_astc::parse_range_value(text);
    ASSERT_TRUE(parsed);
    EXPECT_EQ(parsed->lo, r.lo);
    EXPECT_EQ(parsed->hi, r.hi);
    for (const char* s : {"1 2", "2 1", "1  2", "1 nan", "x 2", "1 2 3"}) {
        std::vector<std::uint8_t> v(s, s + std::strlen(s));
        v.push_back(0);
        EXPECT_EQ(lightmap_astc::parse_range_value(v).has_value(), std::string(s) == "1 2") << s;
    }
    EXPECT_FALSE(lightmap_astc::parse_range_value({'1', ' ', '2'}));  // no NUL
}

// The streaming encode / decode against the whole-image lightmap_astc::compress / decompress: the
// same blocks, the same decoded planes, for both ASTC targets, two footprints and a band height
// that is not the default.
TEST(LightmapAstc, StreamingEncodeDecodeEqualsWholeImage) {
    const std::string dir = test::fresh_dir("lightmap_astc");
    const int w = 40, h = 30;
    const auto lm = lightmap::synthesize_sphere(sample_world(1), w, h, 2);
    const std::string exr = dir + "/lm.exr";
    ASSERT_TRUE(lightmap_stream::synth(sample_world(1), w, h, exr, false, 2, 0, {}).ok());
    auto read_back = read_sh_lightmap_exr(exr);
    ASSERT_TRUE(read_back.ok());
    const auto planes = lightmap::fit_planes(*read_back, lightmap::Fit::kNewton, 1);
    for (auto target : {lightmap_stream::Target::kAstc, lightmap_stream::Target::kAstcLdr})
        for (astc::Footprint f : {astc::Footprint{4, 4}, {6, 6}}) {
            lightmap_stream::EncodeOptions eo;
            eo.target = target;
            eo.footprint = f;
            eo.threads = 2;
            eo.band_rows = 7;  // rounded up to 8 and then to whole rows of blocks
            const std::string prefix = dir + "/out";
            auto r = lightmap_stream::encode({exr}, prefix, eo);
            ASSERT_TRUE(r.ok()) << r.error().message;
            lightmap_astc::Options ao;
            ao.footprint = f;
            ao.ldr_iz = target == lightmap_stream::Target::kAstcLdr;
            if (ao.ldr_iz) {
                float mn = 0, mx = 0;
                lightmap::iz_extent(planes.iz, mn, mx);
                ao.range = lightmap::iz_log_range(mn, mx);
            }
            auto whole = lightmap_astc::compress(planes, ao, 1);
            ASSERT_TRUE(whole.ok());
            auto iz = read_ktx2(prefix + ".iz.ktx2");
            auto dwa = read_ktx2(prefix + ".dwa.ktx2");
            ASSERT_TRUE(iz.ok() && dwa.ok());
            EXPECT_EQ(iz->vk_format, ao.ldr_iz ? astc::vk_format_ldr(f) : astc::vk_format_hdr(f));
            EXPECT_EQ(dwa->vk_format, astc::vk_format_ldr(f));
            EXPECT_EQ(iz->blocks, whole->iz);
            EXPECT_EQ(dwa->blocks, whole->dwa);
            EXPECT_EQ(r->block_bytes, whole->bytes());
            EXPECT_EQ(iz->key_values.size(), ao.ldr_iz ? 1u : 0u);
            auto dec = lightmap_stream::decode(prefix, false, dir + "/dec.exr", 0, {});
            ASSERT_TRUE(dec.ok()) << dec.error().message;
            EXPECT_EQ(dec->target, target);
            const auto want = lightmap_astc::decompress(*whole);
            ASSERT_TRUE(want.ok());
            ASSERT_TRUE(write_irradz_exr(dir + "/dec_ref.exr", *want).ok());
            EXPECT_EQ(test::read_bytes(dir + "/dec.exr"), test::read_bytes(dir + "/dec_ref.exr")) << f.x;
        }
}

TEST(LightmapAstc, CliRefusesDdsAndBrokenFiles) {
    const std::string dir = test::fresh_dir("lightmap_astc_cli");
    const std::string exr = dir + "/lm.exr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", test::envmap_paths().at(0), "-o", exr, "--size", "16"}).exit_code, 0);
    auto r = test::run_zhc({"lightmap", "encode", exr, "-o", dir + "/x", "--target", "astc", "--container", "dds"});
    EXPECT_EQ(r.exit_code, 5);
    EXPECT_NE(r.err.find("DDS has no ASTC formats"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/x.iz.dds"));
    r = test::run_zhc({"lightmap", "encode", exr, "-o", dir + "/y", "--target", "astc", "--footprint", "5x4"});
    EXPECT_EQ(r.exit_code, 2);
    r = test::run_zhc({"lightmap", "encode", exr, "-o", dir + "/l", "--target", "astc-ldr", "--footprint", "6x6"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(test::run_zhc({"lightmap", "decode", dir + "/l", "-o", dir + "/l.exr"}).exit_code, 0);
    // The LDR I_z without its range key: exit 4, naming the key.
    auto iz = read_ktx2(dir + "/l.iz.ktx2");
    ASSERT_TRUE(iz.ok());
    iz->key_values.clear();
    ASSERT_TRUE(write_ktx2(dir + "/l.iz.ktx2", *iz).ok());
    r = test::run_zhc({"lightmap", "decode", dir + "/l", "-o", dir + "/l2.exr"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("zhc.iz_log2_range"), std::string::npos) << r.err;
    // A range key whose value is not "lo hi" with lo < hi: exit 4.
    iz->key_values.push_back({std::string(lightmap_astc::kRangeKey), {'2', ' ', '1', 0}});
    ASSERT_TRUE(write_ktx2(dir + "/l.iz.ktx2", *iz).ok());
    r = test::run_zhc({"lightmap", "decode", dir + "/l", "-o", dir + "/l3.exr"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("not two finite floats"), std::string::npos) << r.err;
    // Two processes, 1 and 3 threads, other band heights: the same files.
    for (const char* target : {"astc", "astc-ldr"}) {
        ASSERT_EQ(test::run_zhc({"lightmap", "encode", exr, "-o", dir + "/p1", "--target", target, "--threads", "1"}).exit_code, 0);
        ASSERT_EQ(test::run_zhc({"lightmap", "encode", exr, "-o", dir + "/p3", "--target", target, "--threads", "3", "--band-rows", "4"}).exit_code, 0);
        for (const char* part : {".iz.ktx2", ".dwa.ktx2"})
            EXPECT_EQ(test::read_bytes(dir + "/p1" + part), test::read_bytes(dir + "/p3" + part)) << target << part;
    }
    // A 6x6 d/w_a texture beside a 4x4 I_z (the last p1: astc-ldr 4x4): exit 4, naming the expected vkFormat.
    std::filesystem::copy_file(dir + "/p1.iz.ktx2", dir + "/m.iz.ktx2", std::filesystem::copy_options::overwrite_existing);
    std::filesystem::copy_file(dir + "/l.dwa.ktx2", dir + "/m.dwa.ktx2", std::filesystem::copy_options::overwrite_existing);
    r = test::run_zhc({"lightmap", "decode", dir + "/m", "-o", dir + "/m.exr"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("expected 157"), std::string::npos) << r.err;
    // An HDR I_z block with a reserved encoding (all zero bits: block mode 0) decodes to the error
    // colour, NaN in HDR: exit 4 naming the file and the block, no output.
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", exr, "-o", dir + "/h", "--target", "astc"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "decode", dir + "/h", "-o", dir + "/h_ok.exr"}).exit_code, 0);
    auto hiz = read_ktx2(dir + "/h.iz.ktx2");
    ASSERT_TRUE(hiz.ok());
    ASSERT_EQ(hiz->blocks.size(), 16u * 16u);  // 16 x 16 texels, 4 x 4 blocks
    std::fill(hiz->blocks.begin() + 16 * 6, hiz->blocks.begin() + 16 * 7, std::uint8_t{0});  // block (2, 1)
    ASSERT_TRUE(write_ktx2(dir + "/h.iz.ktx2", *hiz).ok());
    r = test::run_zhc({"lightmap", "decode", dir + "/h", "-o", dir + "/h_bad.exr"});
    EXPECT_EQ(r.exit_code, 4);
    EXPECT_NE(r.err.find("h.iz.ktx2: invalid ASTC HDR block at block column 2, row 1"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/h_bad.exr"));
    // --targets with --html: one summary row per target in the report.
    r = test::run_zhc({"lightmap", "audit", exr, "--targets", "bc,astc:6x6", "--html", dir + "/t.html"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto page = test::read_bytes(dir + "/t.html");
    const std::string html(page.begin(), page.end());
    EXPECT_NE(html.find("target astc:6x6 ("), std::string::npos);
    EXPECT_NE(html.find("target bc (2.500 bytes/texel)"), std::string::npos);
    EXPECT_NE(r.out.find("astc:6x6"), std::string::npos) << r.out;
    r = test::run_zhc({"lightmap", "audit", exr, "--targets", "bc,astc:7x7"});
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find("astc:7x7"), std::string::npos) << r.err;
}

// The side-by-side audit: the bc column equals the plain audit's numbers, bytes per texel are the
// formats' sizes, the fit before compression is a floor for every target, ASTC 4x4 beats 8x8, and
// the Godot-style irradiance-only column is far worse than any IrradZ target.
TEST(LightmapAstc, AuditTargetsSideBySide) {
    const std::string dir = test::fresh_dir("lightmap_astc_audit");
    const int w = 48, h = 48;
    const std::string exr = dir + "/lm.exr";
    ASSERT_TRUE(lightmap_stream::synth(sample_world(2), w, h, exr, false, 2, 0, {}).ok());
    lightmap_stream::AuditOptions ao;
    ao.threads = 2;
    ao.stride = 5;
    std::vector<lightmap_stream::TargetSpec> specs;
    for (const char* t : {"bc", "astc", "astc:8x8", "astc-ldr:4x4", "astc-split", "plain-astc"}) specs.push_back(*lightmap_stream::parse_target(t));
    auto r = lightmap_stream::audit_targets({exr}, ao, specs);
    ASSERT_TRUE(r.ok()) << r.error().message;
    auto plain = lightmap_stream::audit({exr}, ao);
    ASSERT_TRUE(plain.ok());
    const auto& t = *r;
    EXPECT_DOUBLE_EQ(t[0].audit.rmse_after_bc, plain->audit.rmse_after_bc);
    EXPECT_DOUBLE_EQ(t[0].audit.psnr_d, plain->audit.psnr_d);
    const double texels = w * h;
    EXPECT_DOUBLE_EQ(double(t[0].bytes) / texels, 2.5);
    EXPECT_DOUBLE_EQ(double(t[1].bytes) / texels, 2.0);
    EXPECT_DOUBLE_EQ(double(t[2].bytes) / texels, 2 * 36 * 16 / texels);
    EXPECT_DOUBLE_EQ(double(t[4].bytes) / texels, 3.0);
    EXPECT_DOUBLE_EQ(double(t[5].bytes) / texels, 1.0);
    for (const auto& x : t) EXPECT_GE(x.audit.rmse_after_bc, 0.999 * plain->audit.rmse_search) << x.spec.name;
    EXPECT_LT(t[1].audit.rmse_after_bc, t[2].audit.rmse_after_bc);
    EXPECT_GT(t[1].audit.psnr_d, t[2].audit.psnr_d);
    EXPECT_GT(t[5].audit.rmse_after_bc, 2 * t[2].audit.rmse_after_bc);
    // ASTC 4x4 within 5% of BC's error on this map.
    EXPECT_LT(t[1].audit.rmse_after_bc, 1.05 * t[0].audit.rmse_after_bc);
    EXPECT_FALSE(lightmap_stream::parse_target("bc:4x4"));
    EXPECT_FALSE(lightmap_stream::parse_target("astc:5x4"));
    EXPECT_FALSE(lightmap_stream::parse_target("astc:"));
    EXPECT_EQ(lightmap_stream::parse_target("astc-ldr:6x6")->footprint, (astc::Footprint{6, 6}));
}

// Randomly corrupted ASTC KTX2 files (with key/value data): the reader accepts or refuses with one
// line, never crashes; whatever it accepts decodes with astcenc (any 128-bit pattern is a block).
TEST(LightmapAstc, CorruptedFilesNeverCrash) {
    Ktx2Image img;
    img.vk_format = astc::vk_format_ldr({6, 6});
    img.width = 13;
    img.height = 8;
    std::mt19937 rng(5);
    img.blocks.resize(ktx2_level_bytes(img.vk_format, 13, 8));
    for (auto& b : img.blocks) b = static_cast<std::uint8_t>(rng());
    img.key_values.push_back({lightmap_astc::kRangeKey, lightmap_astc::range_value({-3, 2})});
    img.key_values.push_back({"KTXwriter", {'z', 'h', 'c', 0}});
    const auto good = encode_ktx2(img);
    ASSERT_TRUE(good.ok());
    int accepted = 0;
    for (int i = 0; i < 3000; ++i) {
        auto b = *good;
        const int flips = 1 + static_cast<int>(rng() % 4);
        for (int k = 0; k < flips; ++k) b[rng() % b.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        if (i % 10 == 0) b.resize(rng() % b.size());
        auto r = decode_ktx2(b, "c.ktx2");
        if (!r) {
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
            continue;
        }
        ++accepted;
        const auto f = astc::format_of_vk(r->vk_format);
        if (!f) continue;
        auto d = astc::decode_rgba(r->blocks.data(), r->blocks.size(), r->width, r->height, f->footprint, f->hdr);
        EXPECT_TRUE(d.ok());
    }
    EXPECT_GT(accepted, 100);  // block bytes flipped: still valid files
}

// runtime/zhc_runtime.h's ASTC reconstruction from the textures' values (astcenc's decoder) equals
// the codec's decode (lightmap_astc::decompress, then irradz::evaluate) bit for bit, both targets.
TEST(LightmapAstc, RuntimeCReconstructionEqualsTheCodec) {
    const auto p = sample_planes(24, 20, 3);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-0.25f, 1.25f);
    const lightmap::IzLogRange r = lightmap::iz_log_range(0.003f, 7.5f);
    for (int i = 0; i < 200000; ++i) {
        const float t = i % 1000 == 0 ? std::nanf("") : u(rng);
        const float a = zhc_irradz_iz_from_ldr(t, r.lo, r.hi), b = lightmap::iz_from_ldr(t, r);
        ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << t;
    }
    for (bool ldr : {false, true}) {
        lightmap_astc::Options o;
        o.footprint = {6, 6};
        o.ldr_iz = ldr;
        float mn = 0, mx = 0;
        lightmap::iz_extent(p.iz, mn, mx);
        o.range = lightmap::iz_log_range(mn, mx);
        auto c = lightmap_astc::compress(p, o, 2);
        ASSERT_TRUE(c.ok());
        auto planes = lightmap_astc::decompress(*c);
        ASSERT_TRUE(planes.ok());
        auto iz = astc::decode_rgba(c->iz.data(), c->iz.size(), p.width, p.height, o.footprint, !ldr);
        auto dwa = astc::decode_rgba(c->dwa.data(), c->dwa.size(), p.width, p.height, o.footprint, false);
        ASSERT_TRUE(iz.ok() && dwa.ok());
        int checked = 0;
        for (size_t i = 0; i < p.wa.size(); ++i)
            for (int model = 0; model < 2; ++model) {
                const Vec3 n = normalize_or(Vec3{std::sin(0.37 * double(i)), std::cos(0.21 * double(i)), 0.8}, {0, 0, 1});
                const double nn[3] = {n.x, n.y, n.z};
                float e[3];
                zhc_irradz_irradiance_astc(&(*iz)[4 * i], &(*dwa)[4 * i], ldr ? 1 : 0, o.range.lo, o.range.hi, model, nn, e);
                const Rgb want = irradz::evaluate(planes->texel(i), model == 0 ? irradz::Model::kHhd : irradz::Model::kAhd, n);
                for (int k = 0; k < 3; ++k) ASSERT_EQ(e[k], want[k]) << "texel " << i << " ldr " << ldr;
                ++checked;
            }
        EXPECT_EQ(checked, 2 * p.width * p.height);
    }
}

}  // namespace
}  // namespace zhc
