// IrradZ lightmap textures (codec/lightmap/lightmap.h), SH lightmap EXR I/O (formats/lightmap/lightmap_exr.h) and
// the `zhc lightmap` verbs.
#include <cstdio>
#include <filesystem>
#include <random>
#include <set>
#include <string_view>

#include "codec/bake/sky.h"
#include "codec/lightmap/lightmap.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"
#include "support.h"

namespace zhc {
namespace {

using namespace lightmap;

TEST(LightmapHemiOct, RoundTripsAndIsTotal) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    double worst = 0;
    for (int t = 0; t < 100000; ++t) {
        Vec3 d = test::uniform_direction(u(rng), u(rng));
        d.z = std::abs(d.z);
        const auto uv = encode_hemioct(d);
        ASSERT_GE(uv[0], 0.0f);
        ASSERT_LE(uv[0], 1.0f);
        const Vec3 back = decode_hemioct(uv[0], uv[1]);
        worst = std::max(worst, std::acos(std::clamp(dot(back, d), -1.0, 1.0)));
    }
    EXPECT_LT(worst * 180 / kPi, 1e-3);
    // Any stored pair (8-bit grid and beyond the range) decodes to a unit upper-hemisphere vector.
    for (int a = -2; a <= 257; ++a)
        for (int b = -2; b <= 257; ++b) {
            const Vec3 d = decode_hemioct(a / 255.0f, b / 255.0f);
            ASSERT_NEAR(length(d), 1.0, 1e-9);
            ASSERT_GE(d.z, 0.0);
        }
    // 8-bit quantisation error of the mapping (what BC5 can at best keep): max angle.
    double q = 0;
    for (int t = 0; t < 20000; ++t) {
        Vec3 d = test::uniform_direction(u(rng), u(rng));
        d.z = std::abs(d.z);
        auto uv = encode_hemioct(d);
        for (float& c : uv) c = std::round(c * 255) / 255;
        q = std::max(q, std::acos(std::clamp(dot(decode_hemioct(uv[0], uv[1]), d), -1.0, 1.0)));
    }
    std::printf("hemi-octahedral d at 8 bits: max angular error %.3f deg\n", q * 180 / kPi);
    EXPECT_LT(q * 180 / kPi, 0.6);
}

TEST(Lightmap, CompressedPlanesKeepTheHemisphericalError) {
    const Image img = test::load_envmap(test::envmap_paths().front());
    const Sh3Radiance world = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
    const ShLightmap lm = synthesize_sphere(world, 64, 64, 2);
    ASSERT_EQ(lm.texels.size(), 64u * 64u);
    // Synthetic texels only see their upper hemisphere: the windowed radiance has (almost) no
    // irradiance from below, so the SH irradiance at -Z is small compared to +Z on average.
    const IrradzPlanes search = encode_planes(lm, {}, 2);
    irradz::EncodeOptions old;
    old.solve = irradz::Solve::kTalkBaseline;
    const IrradzPlanes old_way = encode_planes(lm, old, 1);
    EXPECT_EQ(encode_planes(lm, {}, 1).wa, search.wa);  // thread count does not matter
    const Compressed c = compress(search, bc6h::Quality::kDefault, bc45::Quality::kDefault, 2);
    EXPECT_EQ(c.bc6h.size() + c.bc5.size() + c.bc4.size(), static_cast<size_t>(64 * 64 * 5 / 2));  // 2.5 B/texel
    const IrradzPlanes after = decompress(c);
    const Audit a = audit(lm, search, old_way, after, 1);
    std::printf("64x64 sphere lightmap: hemi RMSE old %.5f search %.5f after BC %.5f (mean Iz %.4f); PSNR Iz %.1f wa %.1f d %.1f\n",
                a.rmse_old, a.rmse_search, a.rmse_after_bc, a.mean_iz, a.psnr_iz_log2, a.psnr_wa, a.psnr_d);
    EXPECT_LT(a.rmse_search, a.rmse_old);
    EXPECT_LT(a.rmse_after_bc, 1.05 * a.rmse_search);  // block compression adds < 5 %
    EXPECT_GT(a.psnr_iz_log2, 50);
}

TEST(LightmapExr, RoundTripAndErrors) {
    const std::string dir = test::temp_dir("lightmap_exr");
    ShLightmap lm;
    lm.width = 5;
    lm.height = 3;
    lm.texels.resize(15);
    for (size_t t = 0; t < 15; ++t)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) lm.texels[t][i][k] = static_cast<float>(t * 100 + i * 10 + k) * 0.01f;
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/a.exr", lm).ok());
    auto back = read_sh_lightmap_exr(dir + "/a.exr");
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->width, 5);
    for (size_t t = 0; t < 15; ++t) EXPECT_TRUE(back->texels[t] == lm.texels[t]);
    LightmapReadOptions small;
    small.max_texels = 10;
    EXPECT_EQ(read_sh_lightmap_exr(dir + "/a.exr", small).error().code, ErrorCode::kTooLarge);
    EXPECT_EQ(read_sh_lightmap_exr(dir + "/missing.exr").error().code, ErrorCode::kIoError);
    test::write_bytes(dir + "/junk.exr", {1, 2, 3, 4, 5});
    EXPECT_EQ(read_sh_lightmap_exr(dir + "/junk.exr").error().code, ErrorCode::kBadFormat);
    // An ordinary RGB EXR is not an SH lightmap: the missing channel is named.
    const auto env = read_sh_lightmap_exr(test::envmap_paths().front());
    ASSERT_FALSE(env.ok());
    EXPECT_NE(env.error().message.find("sh0.R"), std::string::npos);
    lm.texels[7][3].g = std::nanf("");
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/nan.exr", lm).ok());
    EXPECT_EQ(read_sh_lightmap_exr(dir + "/nan.exr").error().code, ErrorCode::kInvalidValue);
}

// The lightmap tables: unique names that find their own entry; each fit entry gives the planes of
// the solve it names (computed here without the table), and every preset and fit is accepted by
// the CLI under its table name (a 16x16 lightmap), an unknown name is a usage error.
TEST(LightmapTables, FitsAndPresetsAreWhatTheirNamesSay) {
    std::set<std::string_view> names;
    for (const FitEntry& f : fits()) {
        EXPECT_TRUE(names.insert(f.name).second) << f.name;
        EXPECT_EQ(find_fit(f.name), &f);
        EXPECT_FALSE(f.summary.empty());
    }
    EXPECT_EQ(find_fit("nope"), nullptr);
    EXPECT_EQ(fits().front().fit, Fit::kNewton);  // the default comes first
    // Aliases find the entry they name and never shadow a name: "old" is the talk's baseline.
    ASSERT_FALSE(fit_aliases().empty());
    for (const FitAlias& a : fit_aliases()) {
        EXPECT_TRUE(names.count(a.alias) == 0) << a.alias;
        ASSERT_NE(find_fit(a.alias), nullptr) << a.alias;
        EXPECT_EQ(find_fit(a.alias), find_fit(a.name));
    }
    ASSERT_NE(find_fit("old"), nullptr);
    EXPECT_EQ(find_fit("old")->fit, Fit::kTalkBaseline);
    names.clear();
    for (const QualityPreset& q : quality_presets()) {
        EXPECT_TRUE(names.insert(q.name).second) << q.name;
        EXPECT_EQ(find_quality_preset(q.name), &q);
    }
    EXPECT_EQ(find_quality_preset("nope"), nullptr);
    EXPECT_EQ(find_quality_preset("slow")->bc6h, bc6h::Quality::kExhaustive);
    EXPECT_EQ(find_quality_preset("fast")->bc45, bc45::Quality::kFast);

    const Sh3Radiance world = project_default_lighting();
    const ShLightmap lm = synthesize_sphere(world, 8, 8, 1);
    const std::pair<Fit, irradz::Solve> solves[] = {
        {Fit::kNewton, irradz::Solve::kNewton}, {Fit::kSearch, irradz::Solve::kSearch}, {Fit::kTalkBaseline, irradz::Solve::kTalkBaseline}};
    for (auto [fit, solve] : solves) {
        irradz::EncodeOptions eo;
        eo.solve = solve;
        const IrradzPlanes direct = encode_planes(lm, eo, 1), table = fit_planes(lm, fit, 1);
        EXPECT_EQ(direct.iz, table.iz);
        EXPECT_EQ(direct.wa, table.wa);
        EXPECT_EQ(direct.d, table.d);
    }
    EXPECT_EQ(fit_planes(lm, Fit::kLinear, 1).d, encode_planes_linear_sh(lm, 1).d);

    const std::string dir = test::temp_dir("lightmap_tables");
    auto r = test::run_zhc({"lightmap", "synth", test::envmap_paths().front(), "-o", dir + "/lm.exr", "--size", "16"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const QualityPreset& q : quality_presets()) {
        r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/q", "--quality", std::string(q.name)});
        EXPECT_EQ(r.exit_code, 0) << q.name << ": " << r.err;
    }
    for (const FitEntry& f : fits()) {
        r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/f", "--solve", std::string(f.name), "--quality", "fast"});
        EXPECT_EQ(r.exit_code, 0) << f.name << ": " << r.err;
    }
    r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/f", "--solve", "nope"});
    EXPECT_EQ(r.exit_code, 2);
    // The CLI takes an alias and writes what its entry writes.
    for (const FitAlias& a : fit_aliases()) {
        r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/named", "--solve", std::string(a.name), "--quality", "fast"});
        ASSERT_EQ(r.exit_code, 0) << a.name << ": " << r.err;
        r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/alias", "--solve", std::string(a.alias), "--quality", "fast"});
        ASSERT_EQ(r.exit_code, 0) << a.alias << ": " << r.err;
        for (const char* plane : {".iz.ktx2", ".d.ktx2", ".wa.ktx2"})
            EXPECT_EQ(test::read_bytes(dir + "/named" + plane), test::read_bytes(dir + "/alias" + plane)) << a.alias << plane;
    }
}

TEST(LightmapCli, EncodeDecodeAuditAndBadInput) {
    const std::string dir = test::temp_dir("lightmap_cli");
    auto r = test::run_zhc({"lightmap", "synth", test::envmap_paths().front(), "-o", dir + "/lm.exr", "--size", "32"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/out", "--quality", "fast", "--threads", "2"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* s : {".iz.ktx2", ".d.ktx2", ".wa.ktx2"}) {
        auto k = read_ktx2(dir + "/out" + s);
        ASSERT_TRUE(k.ok()) << k.error().message;
        EXPECT_EQ(k->width, 32);
    }
    // Same bytes for any thread count.
    r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/out1", "--quality", "fast"});
    ASSERT_EQ(r.exit_code, 0);
    EXPECT_EQ(test::read_bytes(dir + "/out.iz.ktx2"), test::read_bytes(dir + "/out1.iz.ktx2"));
    r = test::run_zhc({"lightmap", "decode", dir + "/out", "-o", dir + "/dec.exr"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"lightmap", "audit", dir + "/lm.exr", "--json", "--stride", "3"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\"hemi_rmse\""), std::string::npos);
    // Bad inputs (missing, an environment map, a cut KTX2, a bad --quality): tests/conformance
    // lmexr_*, lmktx2_*, cli_usage_lm_quality.
}

}  // namespace
}  // namespace zhc
