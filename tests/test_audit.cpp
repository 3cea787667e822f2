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
    // The fast integration agrees with the test-side slow twin.
    const auto e1 = integrate_irradiance(small.view(), {dirs[0], dirs[7]}, 1);
    EXPECT_NEAR(e1[1].r, test::integrate_irradiance(test::downsample_latlong(img, 2), dirs[7]).r, 1e-5);
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
