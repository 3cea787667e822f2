// The audit run (codec/audit/audit_run.h, formats audit_files): gates on analytic cases with known
// answers, per-input pooling against a slow twin over the concatenated directions, the
// cross-input aggregate, determinism across thread counts, files against in-memory inputs.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "codec/audit/audit_run.h"
#include "formats/report/audit_inputs.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;

// Probes with a positive DC term and random L1/L2 terms (deterministic).
std::vector<Sh3Radiance> random_probes(std::size_t n, unsigned seed, float l2_scale = 0.3f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<Sh3Radiance> out(n);
    for (Sh3Radiance& p : out) {
        for (int k = 0; k < 3; ++k) {
            p[0][k] = 2.0f + 0.5f * u(rng);
            for (int i = 1; i < 4; ++i) p[i][k] = 0.4f * u(rng);
            for (int i = 4; i < 9; ++i) p[i][k] = l2_scale * u(rng);
        }
    }
    return out;
}

AuditInput probes_input(const std::string& path, std::vector<Sh3Radiance> probes) {
    AuditInput in;
    in.path = path;
    in.kind = "probes";
    in.description = "test probes";
    in.probes = std::move(probes);
    return in;
}

std::vector<const Codec*> every_codec() {
    std::vector<const Codec*> all;
    for (const Codec& c : codecs()) all.push_back(&c);
    return all;
}

bool same_metrics(const ErrorMetrics& a, const ErrorMetrics& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(AuditRun, Sh3IsExactAndPassesAZeroRmseGate) {
    const Codec* sh3 = find_codec("sh3");
    ASSERT_NE(sh3, nullptr);
    AuditOptions o;
    o.timing = false;
    o.gates.max_rmse = 0;
    o.gates.max_relative_rmse = 0;
    const auto dirs = fibonacci_sphere(512);
    const AuditRun run = run_audit({probes_input("a", random_probes(12, 1))}, dirs, {sh3}, o);
    ASSERT_EQ(run.inputs.size(), 1u);
    EXPECT_EQ(run.inputs[0].results[0].metrics.rmse, 0.0);
    EXPECT_EQ(run.inputs[0].results[0].metrics.max_abs, 0.0);
    EXPECT_TRUE(run.gates.passed());
    EXPECT_TRUE(run.inputs[0].failing_probes[0].empty());
}

TEST(AuditRun, Sh2FailsTheRmseGateJustBelowItsAnalyticError) {
    // sh2 keeps L0 and L1 exactly and drops L2: its irradiance error at n is
    // (1/4) sum_{i=4..8} c_i Y_i(n) per channel (band scale 1/4), whose mean square over the sphere
    // is (1/16) sum_i c_i^2 / (4 pi) (orthonormal basis). Over the three channels:
    // rmse = (1/4) sqrt(sum_{i,k} c_ik^2 / (12 pi)).
    const Codec* sh2 = find_codec("sh2");
    ASSERT_NE(sh2, nullptr);
    const std::vector<Sh3Radiance> probes = random_probes(6, 2);
    std::vector<double> bound;
    for (const Sh3Radiance& p : probes) {
        double s = 0;
        for (int i = 4; i < 9; ++i)
            for (int k = 0; k < 3; ++k) s += double(p[i][k]) * p[i][k];
        bound.push_back(0.25 * std::sqrt(s / (12.0 * kPi)));
    }
    const auto dirs = fibonacci_sphere(4096);
    AuditOptions o;
    o.timing = false;
    std::vector<double> measured;
    audit_input(probes_input("p", probes), dirs, {sh2}, o, [&](std::size_t, const std::vector<RepresentationResult>& r) {
        measured.push_back(r[0].metrics.rmse);
    });
    ASSERT_EQ(measured.size(), probes.size());
    for (size_t p = 0; p < probes.size(); ++p) EXPECT_NEAR(measured[p], bound[p], 5e-3 * bound[p]) << p;
    // A gate 2% below each probe's bound fails exactly that probe; 2% above, it passes.
    for (size_t p = 0; p < probes.size(); ++p) {
        AuditOptions tight = o, loose = o;
        tight.gates.max_rmse = 0.98 * bound[p];
        loose.gates.max_rmse = 1.02 * bound[p];
        const AuditInput one = probes_input("p", {probes[p]});
        const AuditRun fail = run_audit({one}, dirs, {sh2}, tight), pass = run_audit({one}, dirs, {sh2}, loose);
        ASSERT_EQ(fail.gates.failures.size(), 1u);
        EXPECT_EQ(fail.gates.failures[0].codec, sh2);
        EXPECT_EQ(fail.gates.failures[0].probes, std::vector<std::size_t>{0});
        EXPECT_TRUE(pass.gates.passed());
    }
}

TEST(AuditRun, PoolingOverProbesEqualsTheConcatenatedDirectionsAndGatesMatchPerProbe) {
    // Slow twin: every probe encoded and evaluated here, all directions of all probes concatenated
    // into one comparison; per-probe gate decisions from per-probe comparisons.
    const std::vector<Sh3Radiance> probes = random_probes(9, 3, 1.0f);
    const auto dirs = fibonacci_sphere(300);
    const std::vector<const Codec*> cs = every_codec();
    AuditOptions o;
    o.timing = false;
    o.threads = 3;
    o.gates.max_relative_rmse = 0.03;
    o.gates.fail_on_negative = true;
    const InputAudit got = audit_input(probes_input("x", probes), dirs, cs, o);
    ASSERT_EQ(got.results.size(), cs.size());
    for (size_t c = 0; c < cs.size(); ++c) {
        std::vector<Rgb> all_rec, all_ref;
        std::vector<std::size_t> failing;
        int clamped = 0;
        for (size_t p = 0; p < probes.size(); ++p) {
            std::vector<std::uint8_t> stored(cs[c]->size_bytes);
            EncodeStats st;
            cs[c]->encode(probes[p], o.codec_options, stored.data(), &st);
            clamped += st.clamped_ratios;
            std::vector<Rgb> rec, ref;
            const Sh3Irradiance e = to_irradiance(probes[p]);
            for (const Vec3& d : dirs) {
                rec.push_back(cs[c]->irradiance(stored.data(), o.codec_options, d));
                ref.push_back(evaluate(e, d));
            }
            const ErrorMetrics m = compare_irradiance(rec, ref);
            if (m.relative_rmse > 0.03 || m.min_irradiance < 0) failing.push_back(p);
            all_rec.insert(all_rec.end(), rec.begin(), rec.end());
            all_ref.insert(all_ref.end(), ref.begin(), ref.end());
        }
        const ErrorMetrics whole = compare_irradiance(all_rec, all_ref), &pooled = got.results[c].metrics;
        const std::string name(cs[c]->name);
        EXPECT_EQ(got.results[c].codec, cs[c]);
        EXPECT_NEAR(pooled.rmse, whole.rmse, 1e-12 * (1 + whole.rmse)) << name;
        EXPECT_NEAR(pooled.relative_rmse, whole.relative_rmse, 1e-12 * (1 + whole.relative_rmse)) << name;
        EXPECT_EQ(pooled.max_abs, whole.max_abs) << name;
        EXPECT_EQ(pooled.min_irradiance, whole.min_irradiance) << name;
        EXPECT_EQ(pooled.negative_fraction, whole.negative_fraction) << name;
        EXPECT_EQ(got.results[c].stats.clamped_ratios, clamped) << name;
        EXPECT_EQ(got.failing_probes[c], failing) << name;
    }
    // Some representation fails a gate on some probe and another passes (the case is not vacuous).
    size_t failing_codecs = 0;
    for (const auto& f : got.failing_probes) failing_codecs += f.empty() ? 0 : 1;
    EXPECT_GT(failing_codecs, 0u);
    EXPECT_LT(failing_codecs, cs.size());
}

TEST(AuditRun, AggregateIsTheMeanOverInputsWithWorstExtremes) {
    const auto dirs = fibonacci_sphere(200);
    const std::vector<const Codec*> cs = {find_codec("sh2"), find_codec("zh3_q16")};
    ASSERT_NE(cs[0], nullptr);
    ASSERT_NE(cs[1], nullptr);
    AuditOptions o;
    o.timing = false;
    o.gates.max_rmse = 0.05;
    const std::vector<AuditInput> inputs = {probes_input("a", random_probes(3, 4, 1.0f)),
                                            probes_input("b", random_probes(5, 5, 0.1f))};
    const AuditRun run = run_audit(inputs, dirs, cs, o);
    ASSERT_EQ(run.inputs.size(), 2u);
    for (size_t i = 0; i < 2; ++i) {  // each input's audit is its own audit_input
        const InputAudit alone = audit_input(inputs[i], dirs, cs, o);
        for (size_t c = 0; c < cs.size(); ++c) EXPECT_TRUE(same_metrics(alone.results[c].metrics, run.inputs[i].results[c].metrics));
    }
    ASSERT_EQ(run.aggregate.size(), cs.size());
    for (size_t c = 0; c < cs.size(); ++c) {
        const ErrorMetrics &a = run.inputs[0].results[c].metrics, &b = run.inputs[1].results[c].metrics,
                           &m = run.aggregate[c].metrics;
        EXPECT_NEAR(m.rmse, (a.rmse + b.rmse) / 2, 1e-15);
        EXPECT_NEAR(m.relative_rmse, (a.relative_rmse + b.relative_rmse) / 2, 1e-15);
        EXPECT_NEAR(m.chromaticity_error, (a.chromaticity_error + b.chromaticity_error) / 2, 1e-15);
        EXPECT_EQ(m.max_abs, std::max(a.max_abs, b.max_abs));
        EXPECT_EQ(m.min_irradiance, std::min(a.min_irradiance, b.min_irradiance));
    }
    // Gates: the failures list input "a" (large L2) before "b", in codec order, and nothing else.
    std::vector<std::string> expected;
    for (const InputAudit& in : run.inputs)
        for (size_t c = 0; c < cs.size(); ++c)
            if (!in.failing_probes[c].empty()) expected.push_back(in.path + ":" + std::string(cs[c]->name));
    std::vector<std::string> got;
    for (const GateFailure& f : run.gates.failures) got.push_back(f.path + ":" + std::string(f.codec->name));
    EXPECT_EQ(got, expected);
    EXPECT_FALSE(got.empty());
    EXPECT_EQ(got[0].substr(0, 2), "a:");
    EXPECT_TRUE(aggregate_inputs({}).empty());
    EXPECT_TRUE(summarize_audit({}).gates.passed());
}

TEST(AuditRun, GateMessageNamesInputCodecMetricsAndAtMostTenProbes) {
    GateFailure f;
    f.path = "maps/x.exr";
    f.codec = find_codec("sh2");
    ASSERT_NE(f.codec, nullptr);
    f.metrics.rmse = 0.5;
    f.metrics.relative_rmse = 0.25;
    f.metrics.min_irradiance = -1;
    f.probes = {3, 7};
    EXPECT_EQ(f.message(), "maps/x.exr: sh2 fails a gate (rmse 0.5, relative_rmse 0.25, min_irradiance -1) at probe 3,7");
    f.probes.clear();
    for (std::size_t p = 0; p < 12; ++p) f.probes.push_back(p);
    EXPECT_EQ(f.message(), "maps/x.exr: sh2 fails a gate (rmse 0.5, relative_rmse 0.25, min_irradiance -1) at probe "
                           "0,1,2,3,4,5,6,7,8,9,... (12 probes)");
    AuditGates g;
    EXPECT_FALSE(g.configured());
    EXPECT_TRUE(g.descriptions().empty());
    g.max_rmse = 0.01;
    g.fail_on_negative = true;
    EXPECT_EQ(g.descriptions(), (std::vector<std::string>{"rmse <= 0.01 on every probe", "no negative irradiance on any probe"}));
    ErrorMetrics m;
    m.rmse = 0.01;
    EXPECT_FALSE(g.fails(m));  // the threshold itself passes
    m.rmse = 0.0101;
    EXPECT_TRUE(g.fails(m));
    m.rmse = 0;
    m.min_irradiance = -1e-9;
    EXPECT_TRUE(g.fails(m));
}

TEST(AuditRun, ResultsAndProbeOrderDoNotDependOnTheThreadCount) {
    const AuditInput in = probes_input("t", random_probes(23, 6, 0.8f));
    const auto dirs = fibonacci_sphere(128);
    const std::vector<const Codec*> cs = every_codec();
    AuditOptions o;
    o.timing = false;
    o.gates.max_relative_rmse = 0.05;
    std::vector<InputAudit> runs;
    for (int threads : {1, 2, 3, 8}) {
        o.threads = threads;
        std::vector<std::size_t> order;
        runs.push_back(audit_input(in, dirs, cs, o, [&](std::size_t p, const std::vector<RepresentationResult>& r) {
            order.push_back(p);
            EXPECT_EQ(r.size(), cs.size());
        }));
        ASSERT_EQ(order.size(), in.probes.size());
        for (size_t p = 0; p < order.size(); ++p) EXPECT_EQ(order[p], p);
    }
    for (size_t t = 1; t < runs.size(); ++t)
        for (size_t c = 0; c < cs.size(); ++c) {
            EXPECT_TRUE(same_metrics(runs[t].results[c].metrics, runs[0].results[c].metrics)) << cs[c]->name;
            EXPECT_EQ(runs[t].results[c].stats.clamped_ratios, runs[0].results[c].stats.clamped_ratios);
            EXPECT_EQ(runs[t].failing_probes[c], runs[0].failing_probes[c]);
        }
}

TEST(AuditRun, TimingCoversTheTimedProbesOnly) {
    const AuditInput in = probes_input("t", random_probes(4, 7));
    const auto dirs = fibonacci_sphere(64);
    const Codec* sh3 = find_codec("sh3");
    ASSERT_NE(sh3, nullptr);
    AuditOptions o;
    o.timed_probes = 2;
    const InputAudit timed = audit_input(in, dirs, {sh3}, o);
    EXPECT_GT(timed.results[0].encode_ns, 0.0);
    EXPECT_GT(timed.results[0].decode_ns, 0.0);
    o.timing = false;
    const InputAudit untimed = audit_input(in, dirs, {sh3}, o);
    EXPECT_EQ(untimed.results[0].encode_ns, 0.0);
    EXPECT_EQ(untimed.results[0].decode_ns, 0.0);
    EXPECT_TRUE(same_metrics(timed.results[0].metrics, untimed.results[0].metrics));
    const double ns = eval_ns_per_sample(*sh3, in.probes[0], dirs, o.codec_options);
    EXPECT_TRUE(std::isfinite(ns));
    EXPECT_GT(ns, 0.0);
}

TEST(AuditRun, EmptyInputsAndCodecListsAreHandled) {
    const auto dirs = fibonacci_sphere(32);
    AuditOptions o;
    const InputAudit none = audit_input(probes_input("e", {}), dirs, every_codec(), o);
    ASSERT_EQ(none.results.size(), codecs().size());
    EXPECT_EQ(none.results[0].metrics.rmse, 0.0);
    const AuditRun no_codecs = run_audit({probes_input("p", random_probes(2, 8))}, dirs, {}, o);
    EXPECT_TRUE(no_codecs.aggregate.empty());
    EXPECT_TRUE(no_codecs.gates.passed());
}

TEST(AuditFiles, SampleMapsGiveTheInMemoryAuditAndStopAtAFailingHook) {
    const std::vector<std::string> files = {std::string(ZHC_ENVMAP_DIR) + "/night.exr",
                                            std::string(ZHC_ENVMAP_DIR) + "/city.exr"};
    for (const std::string& f : files)
        if (!fs::exists(f)) GTEST_SKIP() << f << " missing";
    const auto dirs = fibonacci_sphere(256);
    const std::vector<const Codec*> cs = {find_codec("sh3"), find_codec("sh2")};
    AuditOptions o;
    o.timing = false;
    o.threads = 2;
    o.gates.max_relative_rmse = 0.1;  // sh2 fails on both maps (relative rmse > 0.2), sh3 passes (< 0.05)
    AuditLoadOptions lo;
    lo.threads = 2;
    std::vector<std::size_t> seen;
    auto got = audit_files(files, dirs, cs, o, lo, [&](const AuditInput& in, const InputAudit& a, std::size_t i) -> Status {
        EXPECT_EQ(in.path, files[i]);
        EXPECT_EQ(a.path, files[i]);
        seen.push_back(i);
        return Ok{};
    });
    ASSERT_TRUE(got) << got.error().message;
    EXPECT_EQ(seen, (std::vector<std::size_t>{0, 1}));
    std::vector<AuditInput> loaded;
    for (const std::string& f : files) {
        auto in = load_audit_input(f, dirs, lo);
        ASSERT_TRUE(in);
        loaded.push_back(std::move(*in));
    }
    const AuditRun twin = run_audit(loaded, dirs, cs, o);
    for (size_t i = 0; i < files.size(); ++i)
        for (size_t c = 0; c < cs.size(); ++c)
            EXPECT_TRUE(same_metrics(got->run.inputs[i].results[c].metrics, twin.inputs[i].results[c].metrics));
    ASSERT_EQ(got->run.gates.failures.size(), 2u);
    for (const GateFailure& f : got->run.gates.failures) EXPECT_EQ(f.codec, cs[1]);
    // A failing hook stops after the first file and its error comes back.
    seen.clear();
    auto stopped = audit_files(files, dirs, cs, o, lo, [&](const AuditInput&, const InputAudit&, std::size_t i) -> Status {
        seen.push_back(i);
        return make_error(ErrorCode::kIoError, "hook");
    });
    ASSERT_FALSE(stopped);
    EXPECT_EQ(stopped.error().message, "hook");
    EXPECT_EQ(seen, std::vector<std::size_t>{0});
    // A missing file is the loader's error.
    auto missing = audit_files({files[0] + ".missing"}, dirs, cs, o, lo);
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::kIoError);
}

}  // namespace
}  // namespace zhc
