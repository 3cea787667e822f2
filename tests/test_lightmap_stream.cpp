// Streaming lightmap pipeline (formats/lightmap/lightmap_stream.h): the band-by-band encode / decode /
// audit / synth against the whole-image functions (codec/lightmap/lightmap.h, formats/lightmap/lightmap_exr.h,
// formats/lightmap/ktx2.h, formats/lightmap/dds.h) they replace in the CLI; linear-SH and per-coefficient inputs;
// progress on stderr (cli/progress.h).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "codec/lightmap/lightmap.h"
#include "formats/lightmap/dds.h"
#include "formats/envmap/envmap.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"
#include "formats/lightmap/lightmap_stream.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;
using lightmap::ShLightmap;

Sh3Radiance sample_world() {
    auto img = read_envmap(test::envmap_paths().front());
    EXPECT_TRUE(img.ok());
    return img.ok() ? project_envmap(*img, 1) : Sh3Radiance{};
}

// The whole-image reference: read everything, fit everything, compress everything, one container.
std::vector<std::vector<std::uint8_t>> whole_image_files(const std::string& exr, lightmap_stream::Fit fit, bool dds,
                                                         bc6h::Quality q6, bc45::Quality q45) {
    auto lm = read_sh_lightmap_exr(exr);
    EXPECT_TRUE(lm.ok()) << lm.error().message;
    if (!lm) return {};
    const lightmap::IrradzPlanes planes = lightmap::fit_planes(*lm, fit, 1);
    const auto c = lightmap::compress(planes, q6, q45, 1);
    std::vector<std::vector<std::uint8_t>> files;
    const std::pair<std::uint32_t, const std::vector<std::uint8_t>*> parts[3] = {
        {kVkFormatBc6hUfloat, &c.bc6h}, {kVkFormatBc5Unorm, &c.bc5}, {kVkFormatBc4Unorm, &c.bc4}};
    for (const auto& [fmt, blocks] : parts) {
        Ktx2Image k;
        k.vk_format = fmt;
        k.width = c.width;
        k.height = c.height;
        k.blocks = *blocks;
        auto b = dds ? encode_dds(k) : encode_ktx2(k);
        EXPECT_TRUE(b.ok());
        files.push_back(b.ok() ? *b : std::vector<std::uint8_t>{});
    }
    return files;
}

std::vector<std::vector<std::uint8_t>> read_set(const std::string& prefix, bool dds) {
    std::vector<std::vector<std::uint8_t>> files;
    for (const char* s : {".iz", ".d", ".wa"}) files.push_back(test::read_bytes(prefix + s + (dds ? ".dds" : ".ktx2")));
    return files;
}

// Files in `dir` (to check that a failed run leaves nothing, not even a temporary).
std::vector<std::string> listing(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

TEST(LightmapStream, EncodeBytesDoNotDependOnBandsOrThreads) {
    const std::string dir = test::fresh_dir("lightmap_stream_encode");
    const Sh3Radiance world = sample_world();
    // Heights that are and are not multiples of 4; a width that is not either.
    for (const auto& size : {std::pair{37, 23}, std::pair{16, 30}, std::pair{9, 4}}) {
        const int w = size.first, h = size.second;
        const std::string exr = dir + "/lm" + std::to_string(w) + "x" + std::to_string(h) + ".exr";
        ASSERT_TRUE(write_sh_lightmap_exr(exr, lightmap::synthesize_sphere(world, w, h)).ok());
        for (bool dds : {false, true}) {
            const auto ref = whole_image_files(exr, lightmap_stream::Fit::kNewton, dds, bc6h::Quality::kFast, bc45::Quality::kFast);
            ASSERT_EQ(ref.size(), 3u);
            // 1 rounds up to 4; 12 and 8 do not divide 23 or 30; 0 is automatic; 1000 is one band.
            for (int rows : {1, 4, 8, 12, 0, 1000})
                for (int threads : {1, 2, 3}) {
                    lightmap_stream::EncodeOptions o;
                    o.bc6h_quality = bc6h::Quality::kFast;
                    o.bc45_quality = bc45::Quality::kFast;
                    o.band_rows = rows;
                    o.threads = threads;
                    o.dds = dds;
                    std::vector<std::uint64_t> seen;
                    o.progress = [&](std::uint64_t done, std::uint64_t total) {
                        EXPECT_EQ(total, static_cast<std::uint64_t>(h));
                        seen.push_back(done);
                    };
                    const std::string prefix = dir + "/s";
                    auto r = lightmap_stream::encode({exr}, prefix, o);
                    ASSERT_TRUE(r.ok()) << r.error().message;
                    EXPECT_EQ(r->width, w);
                    EXPECT_EQ(r->height, h);
                    EXPECT_EQ(read_set(prefix, dds), ref) << w << "x" << h << " rows " << rows << " threads " << threads;
                    ASSERT_FALSE(seen.empty());
                    EXPECT_EQ(seen.back(), static_cast<std::uint64_t>(h));
                    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
                }
        }
    }
    // The default quality and the other solves too (one band size that does not divide the height).
    const std::string exr = dir + "/lm37x23.exr";
    for (auto fit : {lightmap_stream::Fit::kNewton, lightmap_stream::Fit::kSearch, lightmap_stream::Fit::kTalkBaseline}) {
        lightmap_stream::EncodeOptions o;
        o.fit = fit;
        o.band_rows = 8;
        o.threads = 2;
        ASSERT_TRUE(lightmap_stream::encode({exr}, dir + "/q", o).ok());
        EXPECT_EQ(read_set(dir + "/q", false), whole_image_files(exr, fit, false, bc6h::Quality::kDefault, bc45::Quality::kDefault));
    }
}

TEST(LightmapStream, TiledInputGivesTheSameBytes) {
    // A tiled copy (OpenEXR's exrmaketiled, from the openexr package in scripts/packages-test.txt)
    // with 8x8 tiles, read in bands of 4 and 12 rows that cut through tile rows.
    const std::string dir = test::fresh_dir("lightmap_stream_tiled");
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/s.exr", lightmap::synthesize_sphere(sample_world(), 37, 23)).ok());
    ASSERT_EQ(std::system(("exrmaketiled -t 8 8 '" + dir + "/s.exr' '" + dir + "/t.exr' > /dev/null 2>&1").c_str()), 0)
        << "exrmaketiled (Debian package openexr) is needed";
    const auto head = test::read_bytes(dir + "/t.exr");
    ASSERT_GT(head.size(), 8u);
    EXPECT_NE(head[5] & 0x02, 0) << "not a single-part tiled file";  // version flag 0x200
    lightmap_stream::EncodeOptions o;
    o.bc6h_quality = bc6h::Quality::kFast;
    o.bc45_quality = bc45::Quality::kFast;
    ASSERT_TRUE(lightmap_stream::encode({dir + "/s.exr"}, dir + "/s", o).ok());
    for (int rows : {4, 12}) {
        o.band_rows = rows;
        o.threads = 2;
        auto r = lightmap_stream::encode({dir + "/t.exr"}, dir + "/t", o);
        ASSERT_TRUE(r.ok()) << r.error().message;
        EXPECT_EQ(read_set(dir + "/t", false), read_set(dir + "/s", false)) << rows;
    }
}

TEST(LightmapStream, DecodeAuditSynthMatchWholeImage) {
    const std::string dir = test::fresh_dir("lightmap_stream_other");
    const Sh3Radiance world = sample_world();
    const int w = 21, h = 30;
    const auto lm = lightmap::synthesize_sphere(world, w, h);
    const std::string exr = dir + "/lm.exr";
    ASSERT_TRUE(write_sh_lightmap_exr(exr, lm).ok());
    // synth: the same file for any band height and thread count.
    const auto square = lightmap::synthesize_sphere(world, 26, 26, 2);
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/sq_ref.exr", square).ok());
    for (int rows : {4, 12, 0, 1000})
        for (int threads : {1, 3}) {
            ASSERT_TRUE(lightmap_stream::synth(world, 26, 26, dir + "/sq.exr", false, threads, rows, {}).ok());
            EXPECT_EQ(test::read_bytes(dir + "/sq.exr"), test::read_bytes(dir + "/sq_ref.exr")) << rows << " " << threads;
        }
    ASSERT_TRUE(lightmap_stream::synth(world, w, h, dir + "/rect.exr", false, 2, 8, {}).ok());
    EXPECT_EQ(test::read_bytes(dir + "/rect.exr"), test::read_bytes(exr));
    // synthesize_sphere_rows is the band of synthesize_sphere.
    const auto band = lightmap::synthesize_sphere_rows(world, w, h, 8, 13, 2);
    ASSERT_EQ(band.height, 5);
    for (size_t t = 0; t < band.texels.size(); ++t) EXPECT_TRUE(band.texels[t] == lm.texels[8 * w + t]);
    // HALF output reads back within half precision.
    ASSERT_TRUE(lightmap_stream::synth(world, 26, 26, dir + "/half.exr", true, 1, 8, {}).ok());
    auto half = read_sh_lightmap_exr(dir + "/half.exr");
    ASSERT_TRUE(half.ok());
    for (size_t t = 0; t < square.texels.size(); ++t)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(half->texels[t][i][k], square.texels[t][i][k], 1e-3 * std::abs(square.texels[t][i][k]) + 1e-6);

    // decode: the same EXR as write_irradz_exr of the whole decompressed image.
    lightmap_stream::EncodeOptions eo;
    eo.bc6h_quality = bc6h::Quality::kFast;
    eo.bc45_quality = bc45::Quality::kFast;
    for (bool dds : {false, true}) {
        eo.dds = dds;
        ASSERT_TRUE(lightmap_stream::encode({exr}, dir + "/e", eo).ok());
        auto ref = read_sh_lightmap_exr(exr);
        ASSERT_TRUE(ref.ok());
        lightmap::Compressed c;
        c.width = w;
        c.height = h;
        const auto files = read_set(dir + "/e", dds);
        std::vector<std::uint8_t>* parts[3] = {&c.bc6h, &c.bc5, &c.bc4};
        for (int f = 0; f < 3; ++f) {
            auto img = dds ? decode_dds(files[static_cast<size_t>(f)], "x") : decode_ktx2(files[static_cast<size_t>(f)], "x");
            ASSERT_TRUE(img.ok());
            *parts[f] = img->blocks;
        }
        ASSERT_TRUE(write_irradz_exr(dir + "/dec_ref.exr", lightmap::decompress(c)).ok());
        for (int rows : {4, 8, 0}) {
            auto r = lightmap_stream::decode(dir + "/e", dds, dir + "/dec.exr", rows, {});
            ASSERT_TRUE(r.ok()) << r.error().message;
            EXPECT_EQ(test::read_bytes(dir + "/dec.exr"), test::read_bytes(dir + "/dec_ref.exr")) << rows;
        }
    }

    // audit: the same numbers as lightmap::audit on the whole image, for any band height.
    irradz::EncodeOptions so;
    const auto search = lightmap::encode_planes(lm, so, 1);
    so.solve = irradz::Solve::kTalkBaseline;
    const auto old_way = lightmap::encode_planes(lm, so, 1);
    const auto after = lightmap::decompress(lightmap::compress(search, bc6h::Quality::kFast, bc45::Quality::kFast, 1));
    const auto ref = lightmap::audit(lm, search, old_way, after, 7);
    for (int rows : {4, 12, 0}) {
        lightmap_stream::AuditOptions ao;
        ao.bc6h_quality = bc6h::Quality::kFast;
        ao.bc45_quality = bc45::Quality::kFast;
        ao.band_rows = rows;
        ao.threads = 2;
        ao.stride = 7;
        auto r = lightmap_stream::audit({exr}, ao);
        ASSERT_TRUE(r.ok()) << r.error().message;
        const auto& a = r->audit;
        EXPECT_EQ(a.texels_sampled, ref.texels_sampled);
        EXPECT_EQ(a.rmse_search, ref.rmse_search);
        EXPECT_EQ(a.rmse_old, ref.rmse_old);
        EXPECT_EQ(a.rmse_after_bc, ref.rmse_after_bc);
        EXPECT_EQ(a.mean_iz, ref.mean_iz);
        EXPECT_EQ(a.psnr_iz_log2, ref.psnr_iz_log2);
        EXPECT_EQ(a.psnr_wa, ref.psnr_wa);
        EXPECT_EQ(a.psnr_d, ref.psnr_d);
        EXPECT_EQ(a.d_mean_deg, ref.d_mean_deg);
        EXPECT_EQ(a.d_max_deg, ref.d_max_deg);
    }
}

// Writes `lm` (L0 and L1 only) as a 12-channel linear-SH EXR and as four per-coefficient EXRs.
void write_linear_forms(const ShLightmap& lm, const std::string& dir) {
    std::vector<std::string> names;
    for (int i = 0; i < 4; ++i)
        for (const char* c : {"R", "G", "B"}) names.push_back("sh" + std::to_string(i) + "." + c);
    std::vector<float> twelve(lm.texels.size() * 12);
    for (size_t t = 0; t < lm.texels.size(); ++t)
        for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k) twelve[t * 12 + static_cast<size_t>(i * 3 + k)] = lm.texels[t][i][k];
    auto w = ExrBandWriter::open(dir + "/linear.exr", lm.width, lm.height, names, false);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE((*w)->write_rows(twelve.data(), lm.height).ok());
    ASSERT_TRUE((*w)->commit().ok());
    for (int i = 0; i < 4; ++i) {
        std::vector<float> rgb(lm.texels.size() * 3);
        for (size_t t = 0; t < lm.texels.size(); ++t)
            for (int k = 0; k < 3; ++k) rgb[t * 3 + static_cast<size_t>(k)] = lm.texels[t][i][k];
        auto f = ExrBandWriter::open(dir + "/coef" + std::to_string(i) + ".exr", lm.width, lm.height, {"R", "G", "B"}, false);
        ASSERT_TRUE(f.ok());
        // Two bands of rows (the writer appends).
        ASSERT_TRUE((*f)->write_rows(rgb.data(), 8).ok());
        ASSERT_TRUE((*f)->write_rows(rgb.data() + static_cast<size_t>(8 * lm.width * 3), lm.height - 8).ok());
        ASSERT_TRUE((*f)->commit().ok());
    }
}

TEST(LightmapStream, LinearShInputEqualsSh3PathWithZeroL2) {
    const std::string dir = test::fresh_dir("lightmap_stream_linear");
    auto lm = lightmap::synthesize_sphere(sample_world(), 19, 14);
    for (auto& t : lm.texels)
        for (int i = 4; i < 9; ++i) t[i] = Rgb{};
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/sh3.exr", lm).ok());
    write_linear_forms(lm, dir);
    std::vector<std::string> coef;
    for (int i = 0; i < 4; ++i) coef.push_back(dir + "/coef" + std::to_string(i) + ".exr");
    for (auto fit : {lightmap_stream::Fit::kSearch, lightmap_stream::Fit::kLinear}) {
        lightmap_stream::EncodeOptions o;
        o.fit = fit;
        o.bc6h_quality = bc6h::Quality::kFast;
        o.bc45_quality = bc45::Quality::kFast;
        o.band_rows = 8;
        auto a = lightmap_stream::encode({dir + "/sh3.exr"}, dir + "/a", o);
        ASSERT_TRUE(a.ok()) << a.error().message;
        EXPECT_EQ(a->coefficients, 9);
        auto b = lightmap_stream::encode({dir + "/linear.exr"}, dir + "/b", o);
        ASSERT_TRUE(b.ok()) << b.error().message;
        EXPECT_EQ(b->coefficients, 4);
        o.band_rows = 4;
        auto c = lightmap_stream::encode(coef, dir + "/c", o);
        ASSERT_TRUE(c.ok()) << c.error().message;
        EXPECT_EQ(c->coefficients, 4);
        const auto ref = read_set(dir + "/a", false);
        EXPECT_EQ(read_set(dir + "/b", false), ref);
        EXPECT_EQ(read_set(dir + "/c", false), ref);
        EXPECT_EQ(ref, whole_image_files(dir + "/sh3.exr", fit, false, bc6h::Quality::kFast, bc45::Quality::kFast));
    }
    // The linear fit (closed form) differs from the search on this lightmap: it is a different path.
    EXPECT_NE(whole_image_files(dir + "/sh3.exr", lightmap_stream::Fit::kLinear, false, bc6h::Quality::kFast, bc45::Quality::kFast),
              whole_image_files(dir + "/sh3.exr", lightmap_stream::Fit::kSearch, false, bc6h::Quality::kFast, bc45::Quality::kFast));
}

TEST(LightmapStream, LinearFitRecoversIrradzValidHhd) {
    // Texels that are the linear SH of known IrradZ parameters (one d and w_a for all channels):
    // the closed form gives them back.
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0, 1);
    ShLightmap lm;
    lm.width = 8;
    lm.height = 8;
    std::vector<irradz::IrradZ> truth;
    for (int t = 0; t < 64; ++t) {
        irradz::IrradZ p;
        p.i_z = Rgb{static_cast<float>(0.2 + u(rng)), static_cast<float>(0.2 + u(rng)), static_cast<float>(0.2 + u(rng))};
        p.w_a = 0.1 + 0.8 * u(rng);
        const double th = u(rng) * 1.2, ph = u(rng) * 2 * kPi;
        p.d = Vec3{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
        truth.push_back(p);
        const Sh2Radiance l = irradz::irradz_to_linear_sh(p);
        Sh3Radiance r;
        for (int i = 0; i < 4; ++i) r[i] = l[i];
        lm.texels.push_back(r);
    }
    const auto planes = lightmap::encode_planes_linear_sh(lm, 2);
    for (size_t t = 0; t < 64; ++t) {
        const irradz::IrradZ got = planes.texel(t);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(got.i_z[k], truth[t].i_z[k], 1e-4 * truth[t].i_z[k]);
        EXPECT_NEAR(got.w_a, truth[t].w_a, 2e-4);
        EXPECT_GT(dot(got.d, truth[t].d), std::cos(1e-3));
    }
}

TEST(LightmapStream, BadInputsFailCleanlyAndLeaveNothing) {
    const std::string dir = test::fresh_dir("lightmap_stream_bad");
    auto lm = lightmap::synthesize_sphere(sample_world(), 12, 40);
    // A NaN in the last band: found only after earlier bands were written; nothing is left.
    lm.texels[38 * 12 + 5][2].b = std::nanf("");
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/nan.exr", lm).ok());
    fs::create_directory(dir + "/out");
    lightmap_stream::EncodeOptions o;
    o.band_rows = 8;
    o.bc6h_quality = bc6h::Quality::kFast;
    o.bc45_quality = bc45::Quality::kFast;
    bool output_failed = true;
    auto r = lightmap_stream::encode({dir + "/nan.exr"}, dir + "/out/x", o, &output_failed);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidValue);
    EXPECT_NE(r.error().message.find("(5, 38)"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("sh2.B"), std::string::npos) << r.error().message;
    EXPECT_TRUE(listing(dir + "/out").empty());
    // Wrong numbers of files, different sizes, a partial L2 band, an RGB file as the SH lightmap.
    auto good = lightmap::synthesize_sphere(sample_world(), 12, 8);
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/good.exr", good).ok());
    EXPECT_EQ(lightmap_stream::encode({dir + "/good.exr", dir + "/good.exr"}, dir + "/out/x", o).error().code,
              ErrorCode::kInvalidArgument);
    write_linear_forms(lm, dir);  // 12 x 40
    EXPECT_EQ(lightmap_stream::encode({dir + "/coef0.exr", dir + "/coef1.exr", dir + "/coef2.exr", dir + "/good.exr"},
                                      dir + "/out/x", o)
                  .error()
                  .code,
              ErrorCode::kBadFormat);
    std::vector<std::string> names;
    for (int i = 0; i < 5; ++i)
        for (const char* c : {"R", "G", "B"}) names.push_back("sh" + std::to_string(i) + "." + c);
    std::vector<float> zeros(12 * 4 * 15, 0.0f);
    auto w = ExrBandWriter::open(dir + "/partial.exr", 12, 4, names, false);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE((*w)->write_rows(zeros.data(), 4).ok());
    ASSERT_TRUE((*w)->commit().ok());
    auto partial = lightmap_stream::encode({dir + "/partial.exr"}, dir + "/out/x", o);
    ASSERT_FALSE(partial.ok());
    EXPECT_EQ(partial.error().code, ErrorCode::kBadFormat);
    EXPECT_NE(partial.error().message.find("sh5.R"), std::string::npos);
    EXPECT_EQ(lightmap_stream::encode({test::envmap_paths().front()}, dir + "/out/x", o).error().code, ErrorCode::kBadFormat);
    EXPECT_EQ(lightmap_stream::encode({dir + "/none.exr"}, dir + "/out/x", o).error().code, ErrorCode::kIoError);
    EXPECT_TRUE(listing(dir + "/out").empty());
    // An unwritable output is an output error.
    output_failed = false;
    r = lightmap_stream::encode({dir + "/good.exr"}, dir + "/no_such_dir/x", o, &output_failed);
    EXPECT_FALSE(r.ok());
    EXPECT_TRUE(output_failed);
    // A writer destroyed before commit leaves nothing.
    {
        auto v = ExrBandWriter::open(dir + "/out/never.exr", 12, 4, names, false);
        ASSERT_TRUE(v.ok());
        ASSERT_TRUE((*v)->write_rows(zeros.data(), 2).ok());
        EXPECT_FALSE((*v)->commit().ok());  // two rows missing
    }
    EXPECT_TRUE(listing(dir + "/out").empty());
}

TEST(LightmapStreamCli, ProgressGoesToStderrOnlyAndQuietSilences) {
    const std::string dir = test::fresh_dir("lightmap_stream_cli");
    const std::string env = test::envmap_paths().front();
    auto a = test::run_zhc({"lightmap", "synth", env, "-o", dir + "/a.exr", "--size", "40", "--quiet"});
    ASSERT_EQ(a.exit_code, 0) << a.err;
    EXPECT_EQ(a.err, "");
    auto b = test::run_zhc({"lightmap", "synth", env, "-o", dir + "/b.exr", "--size", "40", "--progress", "--band-rows", "4"});
    ASSERT_EQ(b.exit_code, 0) << b.err;
    EXPECT_EQ(test::read_bytes(dir + "/a.exr"), test::read_bytes(dir + "/b.exr"));
    // stdout names the output; otherwise identical.
    EXPECT_EQ(b.out, a.out.replace(a.out.find("a.exr"), 5, "b.exr"));
    EXPECT_NE(b.err.find("zhc lightmap synth: 100% (40/40 rows)"), std::string::npos) << b.err;
    EXPECT_NE(b.err.find("zhc lightmap synth: 10% (4/40 rows)"), std::string::npos) << b.err;
    EXPECT_EQ(b.out.find('%'), std::string::npos);
    // Not a terminal and no --progress: nothing on stderr either.
    auto c = test::run_zhc({"lightmap", "encode", dir + "/a.exr", "-o", dir + "/p", "--quality", "fast"});
    ASSERT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(c.err, "");
    auto d = test::run_zhc({"lightmap", "encode", dir + "/a.exr", "-o", dir + "/q", "--quality", "fast", "--progress",
                            "--band-rows", "8", "--threads", "2"});
    ASSERT_EQ(d.exit_code, 0) << d.err;
    EXPECT_NE(d.err.find("zhc lightmap encode: 100% (40/40 rows)"), std::string::npos) << d.err;
    EXPECT_EQ(read_set(dir + "/p", false), read_set(dir + "/q", false));
    // The first stdout line is the same but for the prefix (the second holds timings).
    EXPECT_EQ(c.out.substr(0, c.out.find('\n')), d.out.substr(0, d.out.find('\n')).replace(d.out.find("/q."), 3, "/p."));
    auto e = test::run_zhc({"lightmap", "decode", dir + "/p", "-o", dir + "/p.exr", "--quiet"});
    ASSERT_EQ(e.exit_code, 0) << e.err;
    EXPECT_EQ(e.err, "");
    auto f = test::run_zhc({"lightmap", "decode", dir + "/p", "-o", dir + "/q.exr", "--progress"});
    ASSERT_EQ(f.exit_code, 0) << f.err;
    EXPECT_EQ(test::read_bytes(dir + "/p.exr"), test::read_bytes(dir + "/q.exr"));
    EXPECT_EQ(e.out, f.out.replace(f.out.find("q.exr"), 5, "p.exr"));
    EXPECT_NE(f.err.find("zhc lightmap decode: 100%"), std::string::npos) << f.err;
    auto g = test::run_zhc({"lightmap", "audit", dir + "/a.exr", "--json", "--progress", "--quality", "fast"});
    ASSERT_EQ(g.exit_code, 0) << g.err;
    EXPECT_EQ(g.out.front(), '{');
    EXPECT_NE(g.err.find("zhc lightmap audit: 100%"), std::string::npos) << g.err;
    auto h = test::run_zhc({"lightmap", "audit", dir + "/a.exr", "--quiet", "--quality", "fast"});
    ASSERT_EQ(h.exit_code, 0) << h.err;
    EXPECT_EQ(h.err, "");
    // Linear SH through the CLI: the pattern form, and --solve linear.
    const auto lm = read_sh_lightmap_exr(dir + "/a.exr");
    ASSERT_TRUE(lm.ok());
    write_linear_forms(*lm, dir);
    auto k = test::run_zhc({"lightmap", "encode", dir + "/coef{i}.exr", "-o", dir + "/lin", "--solve", "linear", "--quiet"});
    ASSERT_EQ(k.exit_code, 0) << k.err;
    EXPECT_NE(k.out.find("coef3.exr"), std::string::npos);
    auto m = test::run_zhc({"lightmap", "encode", dir + "/linear.exr", "-o", dir + "/lin2", "--solve", "linear"});
    ASSERT_EQ(m.exit_code, 0) << m.err;
    EXPECT_EQ(read_set(dir + "/lin", false), read_set(dir + "/lin2", false));
    // `zhc audit` over several files: the same progress helper ("files").
    const auto maps = test::envmap_paths();
    ASSERT_GE(maps.size(), 2u);
    auto p1 = test::run_zhc({"audit", maps[0], maps[1], "--no-timing", "--directions", "64", "--progress"});
    ASSERT_EQ(p1.exit_code, 0) << p1.err;
    EXPECT_NE(p1.err.find("zhc audit: 50% (1/2 files)"), std::string::npos) << p1.err;
    EXPECT_NE(p1.err.find("zhc audit: 100% (2/2 files)"), std::string::npos) << p1.err;
    auto p2 = test::run_zhc({"audit", maps[0], maps[1], "--no-timing", "--directions", "64", "--quiet"});
    ASSERT_EQ(p2.exit_code, 0) << p2.err;
    EXPECT_EQ(p2.err, "");
    EXPECT_EQ(p1.out, p2.out);
    // Usage errors (two inputs, --band-rows 0, --size 16385): tests/conformance cli_usage_lm_*.
}

}  // namespace
}  // namespace zhc
