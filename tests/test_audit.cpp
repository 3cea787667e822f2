// The audit: metric definitions on known cases, the reference integration against closed forms,
// agreement with an independent implementation on the real maps, gates, outputs, determinism.
#include <nlohmann/json.hpp>

#include <filesystem>

#include "cli/cli.h"
#include "codec/audit/audit.h"
#include "codec/audit/benchmark.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;

TEST(AuditMetrics, KnownOffsetsGiveKnownNumbers) {
    std::vector<Rgb> ref, rec;
    for (int i = 0; i < 100; ++i) {
        ref.push_back({1, 2, 3});
        rec.push_back({1.5f, 2.5f, 3.5f});
    }
    const ErrorMetrics m = compare_irradiance(rec, ref);
    EXPECT_NEAR(m.rmse, 0.5, 1e-9);
    EXPECT_NEAR(m.max_abs, 0.5, 1e-9);
    EXPECT_NEAR(m.relative_rmse, 0.25, 1e-9);
    EXPECT_NEAR(m.min_irradiance, 1.5, 1e-9);
    EXPECT_EQ(m.negative_fraction, 0.0);
    rec[0].g = -1;
    rec[1].b = -1;
    EXPECT_NEAR(compare_irradiance(rec, ref).negative_fraction, 0.02, 1e-12);
    EXPECT_NEAR(compare_irradiance(rec, ref).min_irradiance, -1.0, 1e-12);
}

TEST(AuditMetrics, ChromaticityErrorIgnoresBrightnessAndSeesHueShifts) {
    std::vector<Rgb> ref(10, Rgb{1, 2, 3}), brighter(10, Rgb{2, 4, 6}), shifted(10, Rgb{2, 2, 2});
    EXPECT_NEAR(compare_irradiance(brighter, ref).chromaticity_error, 0.0, 1e-7);
    // (1/3, 1/3) vs (1/6, 1/3): distance 1/6
    EXPECT_NEAR(compare_irradiance(shifted, ref).chromaticity_error, 1.0 / 6.0, 1e-6);
}

TEST(AuditMetrics, PooledAccumulatorEqualsConcatenation) {
    std::vector<Rgb> a_ref(50, Rgb{1, 1, 1}), a_rec(50, Rgb{1.2f, 1, 0.9f});
    std::vector<Rgb> b_ref(30, Rgb{3, 2, 1}), b_rec(30, Rgb{2.5f, 2, 1.5f});
    MetricsAccumulator acc;
    acc.add(a_rec, a_ref);
    acc.add(b_rec, b_ref);
    std::vector<Rgb> ref = a_ref, rec = a_rec;
    ref.insert(ref.end(), b_ref.begin(), b_ref.end());
    rec.insert(rec.end(), b_rec.begin(), b_rec.end());
    const ErrorMetrics pooled = acc.result(), whole = compare_irradiance(rec, ref);
    EXPECT_NEAR(pooled.rmse, whole.rmse, 1e-12);
    EXPECT_NEAR(pooled.relative_rmse, whole.relative_rmse, 1e-12);
    EXPECT_NEAR(pooled.max_abs, whole.max_abs, 1e-12);
}

TEST(AuditReference, DirectIntegrationMatchesClosedFormIrradiance) {
    // A hemisphere light about a tilted axis: E(n) = (1 + n.a) / 2 exactly.
    const Vec3 axis = normalize_or({0.2, -0.4, 0.9}, {0, 0, 1});
    const Image img = test::render_latlong(1024, 512, [&](Vec3 d) { return dot(d, axis) > 0 ? Rgb{1, 1, 1} : Rgb{}; });
    const LatLongImage small = downsample_for_audit({img.rgb.data(), img.width, img.height});
    EXPECT_EQ(small.width, 512);
    EXPECT_EQ(small.height, 256);
    const auto dirs = fibonacci_sphere(300);
    const auto e = integrate_irradiance(small.view(), dirs, 2);
    for (size_t i = 0; i < dirs.size(); ++i) EXPECT_NEAR(e[i].g, (1 + dot(dirs[i], axis)) / 2, 4e-3);
    // The exact-footprint integration agrees with the test-side slow twin: pixel centres of the
    // 1024x512 map (its half-pixel footprint error is far below the tolerance).
    const auto e1 = integrate_irradiance(small.view(), {dirs[0], dirs[7]}, 1);
    EXPECT_NEAR(e1[1].r, test::integrate_irradiance(img, dirs[7]).r, 2e-5);
}

TEST(AuditCli, RmseAgreesWithAnIndependentImplementationWithin3Percent) {
    // Independent: test-side downsample (256x128), test-side integration, 512 directions of the
    // test's own Fibonacci lattice; SH3/SH2 evaluated from the projection.
    const auto run = test::run_zhc({"audit", ZHC_ENVMAP_DIR, "--json", "--no-timing", "--representations", "sh2,sh3"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    ASSERT_EQ(j["files"].size(), 8u);
    for (const auto& f : j["files"]) {
        const std::string path = f["path"];
        SCOPED_TRACE(path);
        const Image img = test::load_envmap(path);
        const Image small = test::downsample_latlong(img, 4);
        const Sh3Radiance sh = project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u);
        const auto dirs = test::fibonacci_directions(512);
        double sq2 = 0, sq3 = 0;
        for (const Vec3 n : dirs) {
            const Rgb ref = test::integrate_irradiance(small, n), e3 = irradiance(sh, n), e2 = irradiance(truncate_to_sh2(sh), n);
            for (int k = 0; k < 3; ++k) {
                sq3 += (e3[k] - ref[k]) * (e3[k] - ref[k]);
                sq2 += (e2[k] - ref[k]) * (e2[k] - ref[k]);
            }
        }
        const double rmse3 = std::sqrt(sq3 / (3 * dirs.size())), rmse2 = std::sqrt(sq2 / (3 * dirs.size()));
        EXPECT_NEAR(f["representations"]["sh3"]["rmse"].get<double>() / rmse3, 1.0, 0.03);
        EXPECT_NEAR(f["representations"]["sh2"]["rmse"].get<double>() / rmse2, 1.0, 0.03);
    }
    EXPECT_TRUE(j["aggregate"]["representations"].contains("sh3"));
    EXPECT_TRUE(j["gates"]["passed"].get<bool>());
}

// Gates (exit 8 naming file, representation and probe), an unknown representation (2), a missing
// input (3): tests/conformance gate_*, cli_usage_unknown_repr, exr_audit_missing.

TEST(AuditCli, WritesMarkdownAndImagesAndIsDeterministic) {
    const std::string dir = test::temp_dir("audit_out");
    fs::remove_all(dir + "/img");
    const std::string map = test::envmap_paths()[1];
    auto a = test::run_zhc({"audit", map, "--json", "--no-timing", "--threads", "1", "--markdown", dir + "/r.md",
                            "--images", dir + "/img"});
    ASSERT_EQ(a.exit_code, 0) << a.err;
    auto b = test::run_zhc({"audit", map, "--json", "--no-timing", "--threads", "2"});
    EXPECT_EQ(a.out, b.out);
    const auto md = test::read_bytes(dir + "/r.md");
    EXPECT_NE(std::string(md.begin(), md.end()).find("| sh3"), std::string::npos);
    const auto png = test::read_bytes(dir + "/img/courtyard.png");
    ASSERT_GT(png.size(), 1000u);
    EXPECT_EQ(png[1], 'P');
    EXPECT_EQ(png[2], 'N');
}

}  // namespace
}  // namespace zhc

namespace zhc {
namespace {

TEST(Benchmark, ParetoFrontierKeepsOnlyUndominatedPoints) {
    // cost, error: (1, 5) (2, 3) (3, 4) dominated by (2,3); (4, 1); (5, 1) dominated by (4, 1)
    const auto f = pareto_frontier({1, 2, 3, 4, 5}, {5, 3, 4, 1, 1});
    EXPECT_EQ(f, (std::vector<std::size_t>{0, 1, 3}));
}

TEST(BenchCli, PrintsJsonRowsAndWritesBothPlots) {
    const std::string dir = test::temp_dir("bench_plots");
    std::filesystem::remove_all(dir);
    const auto r = test::run_zhc({"bench", test::envmap_paths()[0], "--representations", "sh2,sh3", "--repeats", "2",
                                  "--directions", "64", "--plots", dir, "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["representations"].size(), 2u);
    // Rows follow --representations: sh2 (48 bytes) then sh3 (108 bytes); SH2 has the larger error.
    EXPECT_EQ(j["representations"][0]["bytes_per_probe"].get<int>(), 48);
    EXPECT_EQ(j["representations"][1]["bytes_per_probe"].get<int>(), 108);
    EXPECT_GT(j["representations"][0]["mean_rmse"].get<double>(), j["representations"][1]["mean_rmse"].get<double>());
    EXPECT_GT(j["representations"][0]["encode_ns_per_probe"]["median"].get<double>(), 0.0);
    EXPECT_GT(test::read_bytes(dir + "/error_vs_encode_time.png").size(), 1000u);
    EXPECT_GT(test::read_bytes(dir + "/error_vs_bytes.png").size(), 1000u);
}

// bench_runtime's JSON (GPU cost per encoding) joins the table, the JSON and a third plot; a bad
// file is a one-line error with the README's exit code.
TEST(BenchCli, RuntimeCostFileAddsGpuCostAndPlot) {
    const std::string dir = test::fresh_dir("bench_runtime_cost");
    const std::string cost = dir + "/cost.json";
    const std::string text = R"json({"benchmark": "runtime", "device": "llvmpipe (test)", "rows": [
        {"encoding": "sh3", "bytes": 108, "spirv_instructions": 120, "ns_per_eval": 2.5, "ratio_to_sh3": 1.0},
        {"encoding": "sh2", "bytes": 48, "spirv_instructions": 60, "ns_per_eval": 1.5, "ratio_to_sh3": 0.6}]})json";
    test::write_bytes(cost, std::vector<std::uint8_t>(text.begin(), text.end()));
    const auto r = test::run_zhc({"bench", test::envmap_paths()[0], "--representations", "sh2,sh3,zh3_lum", "--repeats",
                                  "1", "--directions", "64", "--plots", dir, "--json", "--runtime-cost", cost});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["runtime_cost_device"], "llvmpipe (test)");
    EXPECT_EQ(j["representations"][0]["runtime_cost"]["spirv_instructions"].get<int>(), 60);
    EXPECT_EQ(j["representations"][1]["runtime_cost"]["gpu_ns_per_eval"].get<double>(), 2.5);
    EXPECT_FALSE(j["representations"][2].contains("runtime_cost"));  // zh3_lum not in the file
    EXPECT_GT(test::read_bytes(dir + "/error_vs_runtime_cost.png").size(), 1000u);

    const std::string bad = dir + "/bad.json";
    const std::string bad_text = R"({"rows": [{"encoding": "sh3", "spirv_instructions": -4}]})";
    test::write_bytes(bad, std::vector<std::uint8_t>(bad_text.begin(), bad_text.end()));
    const auto b = test::run_zhc({"bench", test::envmap_paths()[0], "--representations", "sh3", "--repeats", "1",
                                  "--directions", "64", "--no-plots", "--runtime-cost", bad});
    EXPECT_EQ(b.exit_code, 4) << b.err;
    EXPECT_NE(b.err.find("rows[0].spirv_instructions"), std::string::npos) << b.err;
    EXPECT_EQ(std::count(b.err.begin(), b.err.end(), '\n'), 1) << b.err;
    const auto m = test::run_zhc({"bench", test::envmap_paths()[0], "--representations", "sh3", "--repeats", "1",
                                  "--no-plots", "--runtime-cost", dir + "/missing.json"});
    EXPECT_EQ(m.exit_code, 3) << m.err;
}

}  // namespace
}  // namespace zhc

#include "codec/probe/probe_set.h"
#include "formats/probes/probe_file.h"

namespace zhc {
namespace {

TEST(AuditCli, AuditsProbeContainersAndNamesFailingProbes) {
    std::vector<Sh3Radiance> hubs;
    for (int i = 0; i < 3; ++i)
        hubs.push_back(project_cone(normalize_or({double(i), 1, 2}, {0, 0, 1}), 0.4, {2, 1, 1}) + project_constant({0.2f, 0.2f, 0.2f}));
    auto set = encode_probe_set(hubs, "sh3", CodecOptions{}, ProbeLayout{});
    ASSERT_TRUE(set) << set.error().message;
    const std::string path = test::temp_dir("audit_probes") + "/three.zhp";
    ASSERT_TRUE(write_probe_file(path, *set));
    auto ok = test::run_zhc({"audit", path, "--json", "--no-timing", "--representations", "sh3,sh2"});
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    const auto j = nlohmann::json::parse(ok.out);
    EXPECT_EQ(j["files"][0]["kind"], "probes");
    EXPECT_EQ(j["files"][0]["probes"].get<int>(), 3);
    // Against its own SH3 the hub is exact; SH2 is not.
    EXPECT_LT(j["files"][0]["representations"]["sh3"]["rmse"].get<double>(), 1e-6);
    EXPECT_GT(j["files"][0]["representations"]["sh2"]["rmse"].get<double>(), 1e-3);
    auto gate = test::run_zhc({"audit", path, "--no-timing", "--representations", "sh2", "--max-rmse", "1e-6"});
    EXPECT_EQ(gate.exit_code, cli::kExitGateFailed);
    // The failing probes after the report on stdout; stderr's one line names the gate and the worst.
    EXPECT_NE(gate.out.find("at probe 0,1,2"), std::string::npos) << gate.out;
    EXPECT_NE(gate.err.find("--max-rmse: 1 pairs, worst rmse "), std::string::npos) << gate.err;
}

}  // namespace
}  // namespace zhc

// The reference of a small lat-long map: every pixel constant over its exact footprint, as
// `zhc project` integrates it, not a point light at its centre.
#include "formats/report/audit_inputs.h"

namespace zhc {
namespace {

// The test-side twin of the exact footprint: each pixel cut into k x k sub-pixels (the same
// piecewise-constant map), summed at their centres (test::integrate_irradiance); converges as 1/k^2.
Rgb supersampled_irradiance(const LatLongView& map, int k, Vec3 n) {
    Image fine;
    fine.width = map.width * k;
    fine.height = map.height * k;
    fine.rgb.resize(static_cast<size_t>(fine.width) * fine.height * 3);
    for (int y = 0; y < fine.height; ++y)
        for (int x = 0; x < fine.width; ++x)
            for (int c = 0; c < 3; ++c)
                fine.row(y)[x * 3 + c] = map.rgb[(static_cast<size_t>(y / k) * map.width + x / k) * 3 + c];
    return test::integrate_irradiance(fine, n);
}

// Pixel (col, row) of a w x h map seen from n when all of it faces n: (1/pi) n . int w dw over the
// pixel, in closed form (theta in [t0, t1], phi in [p0, p1], latlong_direction's openexr columns).
double one_pixel_irradiance(int col, int row, int w, int h, Vec3 n) {
    const double t0 = kPi * row / h, t1 = kPi * (row + 1) / h;
    const double p1 = kPi * (1.0 - 2.0 * col / w), p0 = kPi * (1.0 - 2.0 * (col + 1) / w);
    const double ss = (t1 - t0) / 2 - (std::sin(2 * t1) - std::sin(2 * t0)) / 4;  // int sin^2 t dt
    const double sc = (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0)) / 2;  // int sin t cos t dt
    const double vx = ss * (std::sin(p1) - std::sin(p0)), vy = ss * (std::cos(p0) - std::cos(p1)), vz = sc * (p1 - p0);
    return (n.x * vx + n.y * vy + n.z * vz) / kPi;
}

TEST(AuditReference, ConstantMapsOfAnySizeGiveTheirRadianceExactly) {
    const auto dirs = fibonacci_sphere(500);
    for (auto [w, h] : {std::pair{8, 2}, {1, 1}, {3, 5}, {16, 8}, {7, 3}}) {
        std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
        for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = 0.5f + float(i % 3);
        for (LatLongConvention c : {LatLongConvention::kOpenExr, LatLongConvention::kGltf}) {
            const auto e = integrate_irradiance({rgb.data(), w, h, c}, dirs, 1);
            for (size_t i = 0; i < dirs.size(); ++i)
                for (int k = 0; k < 3; ++k) ASSERT_NEAR(e[i][k], 0.5 + k, 2e-6) << w << "x" << h << " direction " << i;
        }
    }
}

TEST(AuditReference, OnePixelMatchesItsClosedFormAndTheSupersampledTwin) {
    // An 8x2 map with one lit pixel (column 2, row 0): where n faces the whole pixel, the closed
    // form; everywhere, the supersampled twin (k = 64: within 3e-4 of the pixel's flux / pi).
    const int w = 8, h = 2, col = 2, row = 0;
    std::vector<float> rgb(static_cast<size_t>(w) * h * 3, 0.0f);
    for (int k = 0; k < 3; ++k) rgb[(static_cast<size_t>(row) * w + col) * 3 + k] = 1.0f + k;
    const LatLongView map{rgb.data(), w, h};
    const auto dirs = fibonacci_sphere(200);
    const auto e = integrate_irradiance(map, dirs, 2);
    const double flux = latlong_pixel_solid_angle(row, w, h) / kPi;
    std::size_t closed = 0, partial = 0;
    for (size_t i = 0; i < dirs.size(); ++i) {
        // All of the pixel faces n when its four corners and its edges' extreme points do:
        // sampled densely along the boundary.
        bool faces = true;
        for (int s = 0; s <= 64 && faces; ++s)
            for (auto [x, y] : {std::pair{col + s / 64.0 - 0.5, row - 0.5}, {col + s / 64.0 - 0.5, row + 0.5},
                                {col - 0.5, row + s / 64.0 - 0.5}, {col + 0.5, row + s / 64.0 - 0.5}})
                faces = faces && dot(dirs[i], latlong_direction(x, y, w, h)) > 0;
        if (faces) {
            ++closed;
            EXPECT_NEAR(e[i].g, 2.0 * one_pixel_irradiance(col, row, w, h, dirs[i]), 1e-6) << i;
        }
        const Rgb twin = supersampled_irradiance(map, 64, dirs[i]);
        partial += !faces && e[i].r > 0;
        EXPECT_NEAR(e[i].b, twin.b, 3e-4 * 3 * flux) << i;
    }
    EXPECT_GE(closed, 20u);
    EXPECT_GE(partial, 20u);  // directions whose horizon cuts the pixel
    // Threads change nothing.
    const auto e3 = integrate_irradiance(map, dirs, 3);
    for (size_t i = 0; i < dirs.size(); ++i) EXPECT_EQ(e3[i].g, e[i].g);
}

TEST(AuditReference, GltfColumnsTurnTheReferenceByAQuarterTurn) {
    // The same pixels read as gltf: latlong_direction's phi + pi/2, so E_gltf(n) = E_openexr(R n)
    // with R the -90 degree turn about +Z: (x, y, z) -> (y, -x, z).
    const Image img = test::load_envmap(test::envmap_paths()[0]);
    const LatLongImage small = downsample_for_audit({img.rgb.data(), img.width, img.height}, 16, 8);
    ASSERT_EQ(small.width, 16);
    const auto dirs = fibonacci_sphere(100);
    std::vector<Vec3> turned;
    for (const Vec3& d : dirs) turned.push_back({d.y, -d.x, d.z});
    LatLongView gltf = small.view();
    gltf.convention = LatLongConvention::kGltf;
    const auto a = integrate_irradiance(gltf, dirs, 1), b = integrate_irradiance(small.view(), turned, 1);
    for (size_t i = 0; i < dirs.size(); ++i) EXPECT_NEAR(a[i].g, b[i].g, 1e-5 * (1 + std::fabs(b[i].g))) << i;
}

// tests/data/hdr/simple-rle.hdr: loaders.gl's modules/textures/test/data/simple-rle.hdr (visgl/loaders.gl,
// MIT), an 8x2 run-length-encoded Radiance file. Against the exact-footprint reference SH3 leaves
// only the map's bands above 2: relative rmse ~1e-4 (pixel centres as point lights said 0.458).
TEST(AuditCli, SmallRealMapReferenceIsTheExactFootprint) {
    const std::string path = std::string(ZHC_TEST_DATA_DIR) + "/hdr/simple-rle.hdr";
    const auto run = test::run_zhc({"audit", path, "-r", "sh3,sh2", "--json", "--no-timing"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    const auto& reps = j["files"][0]["representations"];
    const double sh3 = reps["sh3"]["relative_rmse"].get<double>(), sh2 = reps["sh2"]["relative_rmse"].get<double>();
    EXPECT_LT(sh3, 5e-4);
    EXPECT_GT(sh3, 1e-6);  // the map is not band-limited: SH3 is not exact
    EXPECT_GT(sh2, 10 * sh3);
    EXPECT_NE(j["files"][0]["reference"].get<std::string>().find("8x2"), std::string::npos);
    // The reference itself against the supersampled twin of the file's pixels.
    const auto dirs = fibonacci_sphere(64);
    auto in = load_audit_input(path, dirs, {});
    ASSERT_TRUE(in.ok()) << in.error().message;
    ASSERT_EQ(in->map.width, 8);
    ASSERT_EQ(in->map.height, 2);
    double mean = 0;
    for (const Rgb& e : in->map_reference) mean += (e.r + e.g + e.b) / (3.0 * dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) {
        const Rgb twin = supersampled_irradiance(in->map.view(), 64, dirs[i]);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(in->map_reference[i][k], twin[k], 3e-4 * mean) << i;
    }
}

// The same at 8x4 and 16x8: a real map (the first sample map) box-downsampled to those sizes.
// The reference agrees with the supersampled twin, SH3 against either gives the same error, and a
// sum over pixel centres would be off by more than 1 % relative rmse at both sizes.
TEST(AuditReference, SmallDownsamplesOfARealMapAuditAgainstTheirFootprint) {
    const Image img = test::load_envmap(test::envmap_paths()[0]);
    const auto dirs = fibonacci_sphere(128);
    for (auto [w, h] : {std::pair{8, 4}, {16, 8}}) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
        const LatLongImage small = downsample_for_audit({img.rgb.data(), img.width, img.height}, w, h);
        ASSERT_EQ(small.width, w);
        ASSERT_EQ(small.height, h);
        const Sh3Radiance sh = project_latlong(small.rgb.data(), w, h, static_cast<size_t>(w) * 3);
        const auto ref = integrate_irradiance(small.view(), dirs, 2), fit = sh3_irradiance(sh, dirs);
        std::vector<Rgb> twin, centres;
        Image coarse;
        coarse.width = w;
        coarse.height = h;
        coarse.rgb = small.rgb;
        for (const Vec3& n : dirs) {
            twin.push_back(supersampled_irradiance(small.view(), 64, n));
            centres.push_back(test::integrate_irradiance(coarse, n));
        }
        const double exact = compare_irradiance(fit, ref).relative_rmse, by_twin = compare_irradiance(fit, twin).relative_rmse;
        const double by_centres = compare_irradiance(fit, centres).relative_rmse;
        const double ref_vs_twin = compare_irradiance(ref, twin).relative_rmse;
        const double centres_vs_ref = compare_irradiance(centres, ref).relative_rmse;
        std::printf("%dx%d: SH3 relative rmse %.3g (exact footprint), %.3g (twin), %.3g (pixel centres); reference vs twin "
                    "%.2g, pixel centres vs reference %.2g\n", w, h, exact, by_twin, by_centres, ref_vs_twin, centres_vs_ref);
        EXPECT_NEAR(exact, by_twin, 0.02 * exact);
        EXPECT_LT(ref_vs_twin, 3e-4);
        EXPECT_GT(centres_vs_ref, 0.01);  // what a centre-sum reference would have added to every error
    }
}

}  // namespace
}  // namespace zhc

// What audit, info and convert say about files they do not read: a 2-D KTX2 / KTX 1 / DDS texture
// gets the cube reader's own reason and exit 5, as `zhc project` gives; a cube in a format zhc
// does not decode is named by its Vulkan name.
#include "formats/lightmap/ktx2.h"

namespace zhc {
namespace {

std::string one_line(const test::CommandResult& r) { return r.err.substr(0, r.err.find('\n')); }

TEST(AuditCli, TwoDimensionalTexturesGetTheCubeReadersReasonLikeProject) {
    const std::string dir = test::fresh_dir("audit_2d_textures");
    // zhc's own 2-D planes (KTX2 and DDS) and a KTX 1 2-D texture another program wrote:
    // tests/data/textures/hdr-rgba-rgba16.ktx from ARM-software/astc-encoder (Test/Images/Small/HDR-RGBA,
    // Apache-2.0), an 8x8 RGBA16F image.
    const std::string map = std::string(ZHC_TEST_DATA_DIR) + "/hdr/simple-rle.hdr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "-o", dir + "/lm.exr", "--size", "8", "--quiet"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/k", "--quiet"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/d", "--container", "dds", "--quiet"}).exit_code, 0);
    const std::vector<std::pair<std::string, std::string>> textures{
        {dir + "/k.iz.ktx2", "KTX2 faceCount 1 (byte 36): a 2-D texture, not a cube map"},
        {dir + "/d.d.dds", "not a cube map"},
        {std::string(ZHC_TEST_DATA_DIR) + "/textures/hdr-rgba-rgba16.ktx", "KTX 1 numberOfFaces 1 (byte 52): a 2-D texture, not a cube map"}};
    for (const auto& [path, reason] : textures) {
        SCOPED_TRACE(path);
        const auto project = test::run_zhc({"project", path});
        EXPECT_EQ(project.exit_code, 5) << project.err;
        EXPECT_NE(project.err.find(reason), std::string::npos) << project.err;
        const auto audit = test::run_zhc({"audit", path, "--no-timing"});
        EXPECT_EQ(audit.exit_code, 5) << audit.err;
        EXPECT_EQ(one_line(audit), one_line(project));
        EXPECT_EQ(std::count(audit.err.begin(), audit.err.end(), '\n'), 1) << audit.err;
        EXPECT_TRUE(audit.out.empty()) << audit.out;
        const auto convert = test::run_zhc({"convert", path, "-o", dir + "/x.zhp"});
        EXPECT_EQ(convert.exit_code, 5) << convert.err;
        EXPECT_EQ(one_line(convert), one_line(project));
        EXPECT_FALSE(fs::exists(dir + "/x.zhp"));
    }
    // info describes 2-D KTX2 and DDS headers; a 2-D KTX 1 gets project's reason and exit 5.
    EXPECT_EQ(test::run_zhc({"info", dir + "/k.iz.ktx2"}).exit_code, 0);
    const auto info = test::run_zhc({"info", textures[2].first});
    EXPECT_EQ(info.exit_code, 5) << info.err;
    EXPECT_EQ(one_line(info), one_line(test::run_zhc({"project", textures[2].first})));
}

TEST(AuditCli, RefusedCubeFormatsAreNamed) {
    EXPECT_EQ(vk_format_name(97), "VK_FORMAT_R16G16B16A16_SFLOAT");
    EXPECT_EQ(vk_format_name(158), "VK_FORMAT_ASTC_4x4_SRGB_BLOCK");
    EXPECT_EQ(vk_format_name(184), "VK_FORMAT_ASTC_12x12_SRGB_BLOCK");
    EXPECT_EQ(vk_format_name(1000066000), "VK_FORMAT_ASTC_4x4_SFLOAT_BLOCK");
    EXPECT_EQ(vk_format_name(1000066013), "VK_FORMAT_ASTC_12x12_SFLOAT_BLOCK");
    EXPECT_EQ(vk_format_name(185), "");
    EXPECT_EQ(vk_format_label(185), "vkFormat 185");
    // A KTX2 cube (the fuzz corpus' RGBA16F seed) relabelled ASTC 4x4 sRGB (vkFormat 158).
    auto bytes = test::read_bytes(std::string(ZHC_TEST_DATA_DIR) + "/../../fuzz/corpus/fuzz_envmap/cube-rgba16f.ktx2");
    ASSERT_GT(bytes.size(), 48u);
    ASSERT_EQ(bytes[12], 97);
    bytes[12] = 158;
    const std::string path = test::fresh_dir("audit_cube_format") + "/astc.ktx2";
    test::write_bytes(path, bytes);
    for (const char* verb : {"project", "audit"}) {
        const auto r = test::run_zhc({verb, path});
        EXPECT_EQ(r.exit_code, 5) << verb << ": " << r.err;
        EXPECT_NE(r.err.find("KTX2 vkFormat 158 (VK_FORMAT_ASTC_4x4_SRGB_BLOCK, byte 12) is not supported for cube maps"),
                  std::string::npos)
            << verb << ": " << r.err;
    }
}

// A folder of maps with a scene JSON (and a glTF JSON) beside them: those are left out with one
// note each; probe lists are audited; a scene named on its own is still an error.
TEST(AuditCli, FolderSkipsJsonThatIsNotAProbeList) {
    const std::string dir = test::fresh_dir("audit_folder_scene");
    fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/hdr/simple-rle.hdr", dir + "/map.hdr");
    fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/leak_room.json", dir + "/scene.json");
    fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/gltf/gt_list.gltf", dir + "/asset.json");
    ProbeList list;
    list.probes = {project_constant({0.5f, 0.4f, 0.3f}), project_cone({0, 0, 1}, 0.5, {1, 1, 1})};
    ASSERT_TRUE(write_probe_json(dir + "/probes.json", list));
    const auto r = test::run_zhc({"audit", dir, "--no-timing", "-r", "sh3,sh2", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("zhc: note: skipped " + dir + "/scene.json: a zhc-scene file, not a probe list\n"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("zhc: note: skipped " + dir + "/asset.json: a glTF file, not a probe list\n"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["files"].size(), 2u);
    EXPECT_EQ(j["files"][0]["path"], dir + "/map.hdr");
    EXPECT_EQ(j["files"][1]["path"], dir + "/probes.json");
    EXPECT_EQ(j["files"][1]["probes"], 2);
    // Named on its own, the scene is an input the audit cannot read.
    const auto named = test::run_zhc({"audit", dir + "/scene.json", "--no-timing"});
    EXPECT_EQ(named.exit_code, 4) << named.err;
    EXPECT_NE(named.err.find("scene.json"), std::string::npos) << named.err;
    // A folder with nothing but a scene: nothing to audit.
    const std::string only = test::fresh_dir("audit_folder_scene_only");
    fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/leak_room.json", only + "/scene.json");
    const auto none = test::run_zhc({"audit", only, "--no-timing"});
    EXPECT_EQ(none.exit_code, 2) << none.err;
    EXPECT_EQ(none.err, "zhc: error: no audit inputs found (skipped " + only + "/scene.json: a zhc-scene file, not a probe list)\n");
}

}  // namespace
}  // namespace zhc
