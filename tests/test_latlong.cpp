// The two lat-long orientations (docs/conventions.md "Lat-long maps"): OpenEXR's (zhc's default)
// and the glTF ecosystem's (--latlong gltf, scene environment.latlong). Analytic cases with known
// answers, slow twins of the fast path, cube maps unaffected, every verb and scene key wired.
// The real client (three.js in Chromium) is js.latlong_three (tests/js/latlong_three.mjs).
#include <nlohmann/json.hpp>

#include <cmath>

#include "cube_helpers.h"
#include "formats/scene/scene_gltf.h"
#include "formats/scene/scene_json.h"
#include "support.h"

namespace zhc {
namespace {

constexpr LatLongConvention kOpenExr = LatLongConvention::kOpenExr;
constexpr LatLongConvention kGltf = LatLongConvention::kGltf;

double angle_deg(Vec3 a, Vec3 b) {
    const double c = dot(a, b) / (length(a) * length(b));
    return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
}

// The L1 direction of channel k: normalize(-f11, -f1-1, f10).
Vec3 l1_direction(const Sh3Radiance& sh, int k) {
    Vec3 d;
    EXPECT_TRUE(optimal_linear_direction(sh[1][k], sh[2][k], sh[3][k], &d));
    return d;
}

// Slow twin of project_latlong under either convention: nine basis functions at the centres of
// sub x sub sub-pixels, times their exact solid angles, with the convention's direction formula
// written out here (not latlong_direction).
Sh3Radiance slow_projection(const Image& img, LatLongConvention c, int sub) {
    double acc[9][3] = {};
    const int sw = img.width * sub, sh = img.height * sub;
    for (int y = 0; y < sh; ++y) {
        const double w = latlong_pixel_solid_angle(y, sw, sh);
        const double theta = kPi * (y + 0.5) / sh;
        for (int x = 0; x < sw; ++x) {
            const double u = (x + 0.5) / sw;
            const double phi = c == kGltf ? kPi * (1.5 - 2.0 * u) : kPi * (1.0 - 2.0 * u);
            const auto basis = sh3_basis({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
            const float* p = img.row(y / sub) + (x / sub) * 3;
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) acc[i][k] += w * p[k] * basis[static_cast<size_t>(i)];
        }
    }
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(acc[i][k]);
    return out;
}

Image with_convention(Image img, LatLongConvention c) {
    img.latlong = c;
    return img;
}

Image random_map(int w, int h, unsigned seed) {
    test::Rng rng(seed);
    Image img;
    img.width = w;
    img.height = h;
    img.rgb.resize(static_cast<size_t>(w) * h * 3);
    for (float& v : img.rgb) v = static_cast<float>(rng.u() * 4.0);
    return img;
}

// The same pixels with every column moved left by w / 4 (wrapping): under openexr, column x - w/4
// looks where column x looks under gltf.
Image rolled(const Image& img) {
    Image out = img;
    const int s = img.width / 4;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int k = 0; k < 3; ++k) out.row(y)[((x + img.width - s) % img.width) * 3 + k] = img.row(y)[x * 3 + k];
    return out;
}

TEST(LatLong, NamesAndParsing) {
    EXPECT_STREQ(latlong_convention_name(kOpenExr), "openexr");
    EXPECT_STREQ(latlong_convention_name(kGltf), "gltf");
    LatLongConvention c = kOpenExr;
    EXPECT_TRUE(parse_latlong_convention("gltf", &c));
    EXPECT_EQ(c, kGltf);
    EXPECT_TRUE(parse_latlong_convention("openexr", &c));
    EXPECT_EQ(c, kOpenExr);
    for (const char* bad : {"", "GLTF", "exr", "gltf ", "openEXR"}) EXPECT_FALSE(parse_latlong_convention(bad, &c)) << bad;
}

// The direction formulas against the glTF ecosystem's inverse mapping, written in glTF's Y-up axes
// ((x, y, z)_glTF = (y, z, x)_zhc, docs/gltf-extension.md): u = 1/2 + atan2(z, x) / (2 pi),
// v = acos(y) / pi — three.js's equirectUv (with its image's row 0 at the top), the Khronos
// glTF-IBL-Sampler. And OpenEXR's Imf::LatLongMap with (x, y, z)_zhc = (z, x, y)_OpenEXR:
// u = 1/2 - atan2(x, z) / (2 pi) in OpenEXR's axes (its longitude runs right to left).
TEST(LatLong, DirectionFormulasInvertTheEcosystemsMappings) {
    test::Rng rng(29);
    for (int i = 0; i < 200; ++i) {
        const int w = 64 + static_cast<int>(rng.u() * 200), h = 32 + static_cast<int>(rng.u() * 100);
        const double col = rng.u() * w - 0.5, row = rng.u() * h - 0.5;
        const double u = (col + 0.5) / w, v = (row + 0.5) / h;
        const Vec3 g = latlong_direction(col, row, w, h, kGltf);
        const double gx = g.y, gy = g.z, gz = g.x;  // glTF axes
        double gu = 0.5 + std::atan2(gz, gx) / (2 * kPi);
        if (gu < 0) gu += 1;
        EXPECT_NEAR(std::fmod(gu + 1 - u + 0.5, 1.0) - 0.5, 0.0, 1e-12);
        EXPECT_NEAR(std::acos(gy) / kPi, v, 1e-9);
        const Vec3 e = latlong_direction(col, row, w, h, kOpenExr);
        const double ex = e.y, ez = e.x;  // OpenEXR axes: x_exr = y_zhc, z_exr = x_zhc
        const double eu = 0.5 - std::atan2(ex, ez) / (2 * kPi);
        EXPECT_NEAR(std::fmod(eu + 1 - u + 0.5, 1.0) - 0.5, 0.0, 1e-12);
        // gltf = openexr turned +90 degrees about +Z: (x, y, z) -> (-y, x, z).
        EXPECT_NEAR(g.x, -e.y, 1e-12);
        EXPECT_NEAR(g.y, e.x, 1e-12);
        EXPECT_NEAR(g.z, e.z, 1e-12);
    }
    // Landmarks: the centre column looks along +X (openexr) or +Y = glTF +X (gltf); u = 3/4 under
    // gltf is zhc +X = glTF +Z.
    const Vec3 c_exr = latlong_direction(63.5, 31.5, 128, 64, kOpenExr), c_gltf = latlong_direction(63.5, 31.5, 128, 64, kGltf);
    EXPECT_NEAR(c_exr.x, 1, 1e-12);
    EXPECT_NEAR(c_gltf.y, 1, 1e-12);
    EXPECT_NEAR(latlong_direction(95.5, 31.5, 128, 64, kGltf).x, 1, 1e-12);
}

// (a) One bright texel at a known pixel: the projection's L1 points at the formula's direction
// under each convention (the texel's footprint is symmetric in phi, so the azimuth is exact; the
// polar angle is the footprint's mean, within a fraction of the pixel's 0.35 degrees at 512 x 256).
TEST(LatLong, BrightTexelPointsWhereTheFormulaSays) {
    const int w = 512, h = 256;
    const int pixels[][2] = {{37, 61}, {128, 128}, {300, 20}, {511, 200}, {0, 100}};
    for (const auto& p : pixels) {
        Image img;
        img.width = w;
        img.height = h;
        img.rgb.assign(static_cast<size_t>(w) * h * 3, 0.0f);
        for (int k = 0; k < 3; ++k) img.row(p[1])[p[0] * 3 + k] = 1000.0f;
        for (const LatLongConvention c : {kOpenExr, kGltf}) {
            const Sh3Radiance sh = project_envmap(with_convention(img, c));
            const Vec3 want = latlong_direction(p[0], p[1], w, h, c);
            const Vec3 got = l1_direction(sh, 0);
            EXPECT_LT(angle_deg(got, want), 0.01) << p[0] << "," << p[1] << " " << latlong_convention_name(c);
            EXPECT_NEAR(std::atan2(got.y, got.x), std::atan2(want.y, want.x), 1e-5);
        }
        // And the two are a quarter turn apart about +Z (azimuth gltf - openexr = +90 degrees).
        const Vec3 a = l1_direction(project_envmap(with_convention(img, kOpenExr)), 0);
        const Vec3 b = l1_direction(project_envmap(with_convention(img, kGltf)), 0);
        double daz = (std::atan2(b.y, b.x) - std::atan2(a.y, a.x)) * 180 / kPi;
        daz = std::fmod(daz + 540.0, 360.0) - 180.0;
        EXPECT_NEAR(daz, 90.0, 1e-4);
    }
}

// (b) The fast path under gltf against the slow twin, against the general SH rotation by +90
// degrees about +Z, and against the openexr projection of the map with its columns rolled by W/4.
TEST(LatLong, ConventionsDifferByAQuarterTurnAboutZ) {
    const Mat3 quarter = rotation_axis_angle({0, 0, 1}, kPi / 2);
    for (const auto& [w, h, seed] : {std::tuple{64, 32, 1u}, {36, 18, 2u}, {20, 7, 3u}}) {
        const Image img = random_map(w, h, seed);
        const Sh3Radiance exr = project_envmap(img);
        const Sh3Radiance gltf = project_envmap(with_convention(img, kGltf));
        EXPECT_LT(test::sh_distance(gltf, slow_projection(img, kGltf, 4)), 2e-3) << w;  // sub-pixel quadrature error
        EXPECT_LT(test::sh_distance(gltf, rotate(exr, quarter)), 1e-6) << w;
        EXPECT_EQ(latlong_quarter_turn(exr, kGltf), gltf);
        EXPECT_EQ(latlong_quarter_turn(exr, kOpenExr), exr);
        if (w % 4 == 0) {
            EXPECT_LT(test::sh_distance(gltf, project_envmap(rolled(img))), 1e-6) << w;
        }
        // The slow twins of both conventions converge to the fast path (the same quadrature).
        EXPECT_LT(test::sh_distance(exr, slow_projection(img, kOpenExr, 4)), 2e-3) << w;
        // The thread count does not matter under gltf either.
        EXPECT_EQ(project_envmap(with_convention(img, kGltf), 3), gltf);
    }
}

// A real map: the L1 direction turns by exactly 90 degrees of azimuth, the elevation stays.
TEST(LatLong, SampleMapTurnsByNinetyDegrees) {
    const auto paths = test::envmap_paths();
    ASSERT_FALSE(paths.empty());
    for (const std::string& path : paths) {
        const Image img = test::load_envmap(path);
        const Sh3Radiance a = project_envmap(img), b = project_envmap(with_convention(img, kGltf));
        const Vec3 da = l1_direction(a, 1), db = l1_direction(b, 1);
        double daz = (std::atan2(db.y, db.x) - std::atan2(da.y, da.x)) * 180 / kPi;
        daz = std::fmod(daz + 540.0, 360.0) - 180.0;
        std::printf("%s: L1 (green) azimuth openexr %.3f deg, gltf %.3f deg: difference %.6f deg\n", test::envmap_name(path).c_str(),
                    std::atan2(da.y, da.x) * 180 / kPi, std::atan2(db.y, db.x) * 180 / kPi, daz);
        EXPECT_NEAR(daz, 90.0, 1e-4) << path;
        EXPECT_NEAR(da.z, db.z, 1e-6) << path;
        for (int k = 0; k < 3; ++k) EXPECT_EQ(a[0][k], b[0][k]);
    }
}

// Cube maps have their format's face convention: --latlong does not touch them. And a lat-long
// map made under gltf from the same function as a cube map projects like the cube (under openexr
// it does not).
TEST(LatLong, CubeMapsIgnoreTheConventionAndMatchGltfLatLong) {
    // A function with a strong horizontal lobe (its azimuth is what the conventions disagree on).
    auto f = [](Vec3 d) {
        const double lobe = std::exp(8.0 * (dot(d, Vec3{0.6, 0.7, 0.387298}) - 1.0));
        return Rgb{static_cast<float>(0.2 + 5 * lobe), static_cast<float>(0.3 + 3 * lobe), static_cast<float>(0.4 + lobe)};
    };
    const Image cube = cube_test::render_cube(64, f);
    const auto bytes = cube_test::write_ktx2(cube, cube_test::Fmt::kRgba32f);
    EnvmapReadOptions ro;
    ro.latlong = kGltf;
    auto as_gltf = read_envmap_memory(bytes, "cube.ktx2", ro);
    auto plain = read_envmap_memory(bytes, "cube.ktx2");
    ASSERT_TRUE(as_gltf && plain);
    EXPECT_EQ(as_gltf->layout, EnvmapLayout::kCubeVulkan);
    const Sh3Radiance cube_sh = project_envmap(*plain);
    EXPECT_EQ(project_envmap(*as_gltf), cube_sh);

    Image ll;
    ll.width = 512;
    ll.height = 256;
    ll.rgb.resize(512 * 256 * 3);
    for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 512; ++x) {
            const Rgb c = f(latlong_direction(x, y, 512, 256, kGltf));
            for (int k = 0; k < 3; ++k) ll.row(y)[3 * x + k] = c[k];
        }
    const double d_gltf = test::sh_distance(project_envmap(with_convention(ll, kGltf)), cube_sh);
    const double d_exr = test::sh_distance(project_envmap(ll), cube_sh);
    std::printf("gltf lat-long vs the cube of the same function: %.2e of L00; openexr: %.2e\n", d_gltf, d_exr);
    EXPECT_LT(d_gltf, 2e-3);
    EXPECT_GT(d_exr, 0.1);
}

// --- through the CLI --------------------------------------------------------------------------

std::string write_map(const std::string& dir, const std::string& name, const Image& img) {
    const std::string path = dir + "/" + name;
    EXPECT_TRUE(write_hdr(path, img));
    return path;
}

Sh3Radiance sh_of_json(const nlohmann::json& rows) {
    Sh3Radiance s;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) s[i][k] = rows[static_cast<size_t>(i)][static_cast<size_t>(k)].get<float>();
    return s;
}

TEST(LatLongCli, ProjectConvertDeringAuditSynthTakeTheOption) {
    const std::string dir = test::fresh_dir("latlong_cli");
    const Image img = random_map(64, 32, 7);
    const std::string map = write_map(dir, "map.hdr", img);
    auto read_back = read_envmap(map);
    ASSERT_TRUE(read_back);
    const Sh3Radiance exr = project_envmap(*read_back), gltf = latlong_quarter_turn(exr, kGltf);
    // project: the default is openexr, the JSON says which.
    auto p = test::run_zhc({"project", map, "--json"});
    ASSERT_EQ(p.exit_code, 0) << p.err;
    auto j = nlohmann::json::parse(p.out);
    EXPECT_EQ(j["latlong"], "openexr");
    EXPECT_EQ(sh_of_json(j["sh3"]), exr);
    p = test::run_zhc({"project", map, "--json", "--latlong", "gltf"});
    ASSERT_EQ(p.exit_code, 0) << p.err;
    j = nlohmann::json::parse(p.out);
    EXPECT_EQ(j["latlong"], "gltf");
    EXPECT_EQ(sh_of_json(j["sh3"]), gltf);
    p = test::run_zhc({"project", map, "--latlong", "gltf"});
    EXPECT_NE(p.out.find("lat-long gltf orientation"), std::string::npos) << p.out;
    // A bad value is a usage error.
    EXPECT_EQ(test::run_zhc({"project", map, "--latlong", "blender"}).exit_code, 2);
    // convert: the JSON probe holds the same SH3.
    for (const char* c : {"openexr", "gltf"}) {
        const std::string out = dir + "/conv_" + c + ".json";
        auto r = test::run_zhc({"convert", map, "-o", out, "--latlong", c});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        auto list = nlohmann::json::parse(test::read_bytes(out));
        EXPECT_EQ(sh_of_json(list["probes"][0]["sh3"]), std::string(c) == "gltf" ? gltf : exr) << c;
    }
    // dering: gltf of the map = openexr of the map with its columns rolled (a quarter turn).
    const std::string map_rolled = write_map(dir, "rolled.hdr", rolled(*read_back));
    auto d1 = test::run_zhc({"dering", map, "-o", dir + "/d_gltf.json", "--latlong", "gltf"});
    auto d2 = test::run_zhc({"dering", map_rolled, "-o", dir + "/d_rolled.json"});
    auto d3 = test::run_zhc({"dering", map, "-o", dir + "/d_exr.json"});
    ASSERT_EQ(d1.exit_code + d2.exit_code + d3.exit_code, 0) << d1.err << d2.err << d3.err;
    const auto jd1 = nlohmann::json::parse(test::read_bytes(dir + "/d_gltf.json"));
    const auto jd2 = nlohmann::json::parse(test::read_bytes(dir + "/d_rolled.json"));
    const auto jd3 = nlohmann::json::parse(test::read_bytes(dir + "/d_exr.json"));
    EXPECT_LT(test::sh_distance(sh_of_json(jd1["probes"][0]["sh3"]), sh_of_json(jd2["probes"][0]["sh3"])), 1e-5);
    EXPECT_GT(test::sh_distance(sh_of_json(jd1["probes"][0]["sh3"]), sh_of_json(jd3["probes"][0]["sh3"])), 1e-2);
    // audit: the reference (the map integrated pixel by pixel) turns too: gltf of the map audits
    // like openexr of the rolled map, and the probe's SH matches its reference either way.
    auto rmse = [&](const std::vector<std::string>& extra) {
        std::vector<std::string> args = {"audit", "--json", "--no-timing", "-r", "sh3", "--directions", "256"};
        args.insert(args.end(), extra.begin(), extra.end());
        auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return nlohmann::json::parse(r.out.empty() ? "{}" : r.out);
    };
    const auto a_gltf = rmse({map, "--latlong", "gltf"}), a_rolled = rmse({map_rolled}), a_exr = rmse({map});
    const double r_gltf = a_gltf["files"][0]["representations"]["sh3"]["rmse"].get<double>();
    const double r_rolled = a_rolled["files"][0]["representations"]["sh3"]["rmse"].get<double>();
    const double r_exr = a_exr["files"][0]["representations"]["sh3"]["rmse"].get<double>();
    std::printf("audit sh3 rmse: gltf %.9g, rolled map %.9g, openexr %.9g\n", r_gltf, r_rolled, r_exr);
    EXPECT_NEAR(r_gltf, r_rolled, 1e-4 * r_rolled);
    // The openexr reading is another map (turned): its error differs, so the check above can fail.
    EXPECT_GT(std::abs(r_exr - r_rolled), 1e-3 * r_rolled);
    // lightmap synth: the output follows the convention (the map is not symmetric about +Z).
    auto s1 = test::run_zhc({"lightmap", "synth", map, "-o", dir + "/s_exr.exr", "--size", "8", "--quiet"});
    auto s2 = test::run_zhc({"lightmap", "synth", map, "-o", dir + "/s_gltf.exr", "--size", "8", "--latlong", "gltf", "--quiet"});
    ASSERT_EQ(s1.exit_code + s2.exit_code, 0) << s1.err << s2.err;
    EXPECT_NE(test::read_bytes(dir + "/s_exr.exr"), test::read_bytes(dir + "/s_gltf.exr"));
}

// Scenes: environment.latlong; JSON scenes default to openexr, glTF scenes to gltf; `zhc bake`
// of a JSON scene to a glTF output defaults to gltf and says so in its report.
TEST(LatLongScene, EnvironmentKeyAndDefaults) {
    const std::string dir = test::fresh_dir("latlong_scene");
    const Image img = random_map(32, 16, 11);
    write_map(dir, "env.hdr", img);
    auto read_back = read_envmap(dir + "/env.hdr");
    ASSERT_TRUE(read_back);
    const Sh3Radiance exr = project_envmap(*read_back), gltf = latlong_quarter_turn(exr, kGltf);
    auto scene_text = [](const std::string& latlong) {
        return std::string(R"({"version":1,"probes":{"positions":[[0,0,0]]},"environment":{"map":"env.hdr")") +
               (latlong.empty() ? "" : R"(,"latlong":)" + latlong) + "}}";
    };
    auto parse = [&](const std::string& text, const SceneLoadOptions& o = {}) {
        return parse_scene_json(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()),
                                "scene.json", dir, o);
    };
    auto s = parse(scene_text(""));
    ASSERT_TRUE(s);
    EXPECT_EQ(s->environment->latlong, kOpenExr);
    EXPECT_EQ(s->environment->projected, exr);
    s = parse(scene_text("\"gltf\""));
    ASSERT_TRUE(s);
    EXPECT_EQ(s->environment->latlong, kGltf);
    EXPECT_EQ(s->environment->projected, gltf);
    SceneLoadOptions glb_default;
    glb_default.default_latlong = kGltf;
    s = parse(scene_text(""), glb_default);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->environment->projected, gltf);
    s = parse(scene_text("\"openexr\""), glb_default);  // the key wins over the default
    ASSERT_TRUE(s);
    EXPECT_EQ(s->environment->projected, exr);
    // Round trip: scene_json writes the key.
    const std::string text = scene_json(*parse(scene_text("\"gltf\"")));
    EXPECT_NE(text.find("\"latlong\": \"gltf\""), std::string::npos) << text;
    EXPECT_EQ(parse(text)->environment->projected, gltf);
    // Bad values: the field path and what is allowed.
    for (const std::string bad : {"\"GLTF\"", "1", "null"}) {
        auto b = parse(scene_text(bad));
        ASSERT_FALSE(b) << bad;
        EXPECT_EQ(b.error().code, ErrorCode::kInvalidValue) << bad;
        EXPECT_NE(b.error().message.find("environment.latlong"), std::string::npos) << b.error().message;
    }
    // glTF scene: extras.zhc is a zhc scene; its environment defaults to gltf.
    auto gltf_scene = [&](const std::string& latlong) {
        const std::string t = R"({"asset":{"version":"2.0"},"extras":{"zhc":)" + scene_text(latlong) + "}}";
        const std::string path = dir + "/scene.gltf";
        test::write_bytes(path, std::vector<std::uint8_t>(t.begin(), t.end()));
        return path;
    };
    auto g = parse_scene_gltf(test::read_bytes(gltf_scene("")), dir + "/scene.gltf");
    ASSERT_TRUE(g) << g.error().message;
    EXPECT_EQ(g->environment->projected, gltf);
    g = parse_scene_gltf(test::read_bytes(gltf_scene("\"openexr\"")), dir + "/scene.gltf");
    ASSERT_TRUE(g) << g.error().message;
    EXPECT_EQ(g->environment->projected, exr);
    // zhc bake: JSON scene -> .json keeps openexr; -> .glb reads gltf; the report names it.
    const std::string st = scene_text("");
    test::write_bytes(dir + "/scene.json", std::vector<std::uint8_t>(st.begin(), st.end()));
    auto b1 = test::run_zhc({"bake", dir + "/scene.json", "-o", dir + "/out.json"});
    ASSERT_EQ(b1.exit_code, 0) << b1.err;
    EXPECT_NE(b1.out.find("openexr lat-long"), std::string::npos) << b1.out;
    const auto probes = nlohmann::json::parse(test::read_bytes(dir + "/out.json"));
    EXPECT_LT(test::sh_distance(sh_of_json(probes["probes"][0]["sh3"]), exr), 1e-6);
    auto b2 = test::run_zhc({"bake", dir + "/scene.json", "-o", dir + "/out.glb"});
    ASSERT_EQ(b2.exit_code, 0) << b2.err;
    EXPECT_NE(b2.out.find("gltf lat-long"), std::string::npos) << b2.out;
    auto b3 = test::run_zhc({"bake", gltf_scene(""), "-o", dir + "/out2.json"});
    ASSERT_EQ(b3.exit_code, 0) << b3.err;
    EXPECT_NE(b3.out.find("gltf lat-long"), std::string::npos) << b3.out;
    const auto probes3 = nlohmann::json::parse(test::read_bytes(dir + "/out2.json"));
    EXPECT_LT(test::sh_distance(sh_of_json(probes3["probes"][0]["sh3"]), gltf), 1e-6);
}

}  // namespace
}  // namespace zhc
