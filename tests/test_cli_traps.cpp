// Small CLI traps a newcomer falls into: each test runs the zhc binary the way the trap was found
// and checks the refusal, the message or the output that replaces the silent wrong answer.
// (Rows that fit the CLI conformance table are in tests/conformance/cases.txt, ids trap_*.)
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/probe_set.h"
#include "formats/probes/probe_file.h"
#include "tests/support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;

std::size_t count_lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

// The four golden probes, each scaled by an irregular factor: their DC values then differ between
// the DC formats (the golden ones are exactly representable in all of them).
std::vector<Sh3Radiance> probes_in_use() {
    std::vector<Sh3Radiance> probes = test::golden_probes();
    for (size_t p = 0; p < probes.size(); ++p)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) probes[p][i][k] *= static_cast<float>(1.0 + 0.1372 * double(p + 1) + 0.0113 * k);
    return probes;
}

// A JSON probe list of probes_in_use() in `dir`.
std::string golden_json(const std::string& dir) {
    const std::string path = dir + "/golden.json";
    ProbeList list;
    list.probes = probes_in_use();
    EXPECT_TRUE(write_probe_json(path, list).ok());
    return path;
}

// ---- storage options an entry does not use ----------------------------------------------------

struct StorageFlag {
    std::vector<std::string> args;  // a non-default value
    CodecOptions params;            // the same value in CodecOptions
};
std::vector<StorageFlag> storage_flags() {
    std::vector<StorageFlag> f(6);
    f[0].args = {"--bits", "4"};
    f[0].params.bits = 4;
    f[1].args = {"--sqrt"};
    f[1].params.sqrt_encoding = true;
    f[2].args = {"--bound", "loose"};
    f[2].params.l2_bound = L2Bound::kLoose;
    f[3].args = {"--dc", "rgb9e5"};
    f[3].params.dc_format = DcFormat::kRGB9E5;
    f[4].args = {"--zonal-map", "zero"};
    f[4].params.zonal_mapping = ZonalMapping::kZeroPreserving;
    f[5].args = {"--axis", "channel"};
    f[5].params.axis_mode = ZonalAxisMode::kPerChannel;
    return f;
}

// Every entry x every storage option: convert accepts the option exactly when the entry's decoded
// probes depend on it (the obviously-correct twin: encode + decode through the library with and
// without the value), and a refusal is exit 2 naming the option and the entry, with no output.
TEST(CliTraps, StorageOptionRefusedExactlyWhereUnused) {
    const std::string dir = test::fresh_dir("traps_storage");
    const std::string in = golden_json(dir);
    const std::vector<Sh3Radiance> probes = probes_in_use();
    int refused = 0, accepted = 0;
    for (const Codec& c : codecs()) {
        const std::string name(c.name);
        auto base = encode_probe_set(probes, name, CodecOptions{}, ProbeLayout{});
        ASSERT_TRUE(base.ok()) << name;
        const auto base_hub = decode_probe_set(*base);
        ASSERT_TRUE(base_hub.ok());
        for (const StorageFlag& flag : storage_flags()) {
            auto set = encode_probe_set(probes, name, flag.params, ProbeLayout{});
            ASSERT_TRUE(set.ok()) << name << " " << flag.args[0];
            const auto hub = decode_probe_set(*set);
            ASSERT_TRUE(hub.ok());
            const bool used = *hub != *base_hub;
            const std::string out = dir + "/" + name + flag.args[0].substr(2) + ".zhp";
            std::vector<std::string> args{"convert", in, "-o", out, "-r", name};
            args.insert(args.end(), flag.args.begin(), flag.args.end());
            const auto r = test::run_zhc(args);
            if (used) {
                EXPECT_EQ(r.exit_code, 0) << name << " " << flag.args[0] << ": " << r.err;
                auto file = read_probe_file(out);
                ASSERT_TRUE(file.ok()) << name;
                EXPECT_EQ(file->payload, set->payload) << name << " " << flag.args[0];
                ++accepted;
            } else {
                EXPECT_EQ(r.exit_code, 2) << name << " " << flag.args[0] << " changes nothing, yet was accepted";
                EXPECT_NE(r.err.find("zhc: error: " + flag.args[0] + ": the representation " + name + " does not use it"),
                          std::string::npos)
                    << r.err;
                EXPECT_EQ(count_lines(r.err), 1u) << r.err;
                EXPECT_EQ(r.out, "");
                EXPECT_FALSE(fs::exists(out)) << out;
                ++refused;
            }
        }
    }
    EXPECT_GT(refused, 27);   // the float entries refuse all six
    EXPECT_GT(accepted, 27);  // the quantised ones take most
}

// Without -r a JSON output is float SH3: a storage option (and --irradiance) would do nothing.
TEST(CliTraps, StorageOptionRefusedForFloatJsonOutput) {
    const std::string dir = test::fresh_dir("traps_storage_json");
    const std::string in = golden_json(dir);
    for (const std::vector<std::string>& flag : {std::vector<std::string>{"--sqrt"}, {"--irradiance"}, {"--bits", "5"}}) {
        std::vector<std::string> args{"convert", in, "-o", dir + "/o.json"};
        args.insert(args.end(), flag.begin(), flag.end());
        const auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 2) << flag[0];
        EXPECT_NE(r.err.find(flag[0] + ": without -r/--representations the output is float SH3"), std::string::npos) << r.err;
    }
}

// ---- info's summary line agrees with the fields beside it --------------------------------------

std::string upper_dc(const std::string& dc) {
    if (dc == "r11g11b10f") return "R11G11B10F";
    if (dc == "rgb9e5") return "RGB9E5";
    return "half-float";
}

TEST(CliTraps, InfoSummaryAgreesWithFields) {
    const std::string dir = test::fresh_dir("traps_info");
    const std::string in = golden_json(dir);
    const std::vector<std::vector<std::string>> combos = {
        {"-r", "zh3_q16"},
        {"-r", "zh3_q16", "--dc", "rgb9e5", "--axis", "channel"},
        {"-r", "zh3_q16", "--bits", "4", "--sqrt", "--zonal-map", "symmetric", "--irradiance"},
        {"-r", "sh3_q28", "--bound", "loose", "--zonal-map", "zero", "--bits", "6"},
        {"-r", "sh2_q", "--dc", "half", "--sqrt"},
        {"-r", "hall_curve_q", "--axis", "channel", "--bits", "3"},
        {"-r", "zh3_channel_q16", "--dc", "rgb9e5"},
        {"-r", "sh3", "--irradiance"},
    };
    for (size_t i = 0; i < combos.size(); ++i) {
        const std::string out = dir + "/c" + std::to_string(i) + ".zhp";
        std::vector<std::string> args{"convert", in, "-o", out};
        args.insert(args.end(), combos[i].begin(), combos[i].end());
        ASSERT_EQ(test::run_zhc(args).exit_code, 0) << combos[i][1];
        const auto r = test::run_zhc({"info", out, "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto j = nlohmann::json::parse(r.out);
        const std::string summary = j["summary"];
        const std::string rep = j["representation"];
        SCOPED_TRACE(rep + ": " + summary);
        EXPECT_EQ(summary.find("(luminance axis)") != std::string::npos && j.contains("axis") && j["axis"] == "channel", false);
        EXPECT_EQ(summary.find("stored as irradiance") != std::string::npos, j["kind"] == "irradiance");
        const bool packed = j.contains("bits");
        if (packed) {
            EXPECT_NE(summary.find(upper_dc(j["dc_format"]) + " DC"), std::string::npos);
            EXPECT_NE(summary.find(std::to_string(j["bits"].get<int>()) + "-bit "), std::string::npos);
            EXPECT_EQ(summary.find("square-root") != std::string::npos, j["sqrt"].get<bool>());
            // Named once, as the fields say: the other values never appear.
            for (const char* dc : {"R11G11B10F DC", "RGB9E5 DC", "half-float DC"})
                if (upper_dc(j["dc_format"]) + " DC" != dc) {
                    EXPECT_EQ(summary.find(dc), std::string::npos);
                }
            if (rep == "sh3_q28") {
                EXPECT_NE(summary.find(j["l2_bound"].get<std::string>() + " L2 bound"), std::string::npos);
            } else {
                EXPECT_EQ(summary.find("L2 bound"), std::string::npos);
            }
            if (rep == "sh3_q28" || rep == "zh3_q16" || rep == "zh3_channel_q16") {
                EXPECT_NE(summary.find(j["zonal_mapping"].get<std::string>() + " zonal mapping"), std::string::npos);
            }
            if (rep == "sh3_q28" || rep == "sh2_q") {
                EXPECT_EQ(summary.find("zonal axis"), std::string::npos);
            } else {
                EXPECT_NE(summary.find("zonal axis " + j["axis"].get<std::string>()), std::string::npos);
            }
        }
        // The text output prints the same line.
        const auto text = test::run_zhc({"info", out});
        EXPECT_NE(text.out.find(summary), std::string::npos);
    }
    // The trap as found: --dc rgb9e5 --axis channel on zh3_q16.
    const auto r = test::run_zhc({"info", dir + "/c1.zhp", "--json"});
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["axis"], "channel");
    EXPECT_EQ(j["dc_format"], "rgb9e5");
    EXPECT_NE(j["summary"].get<std::string>().find("RGB9E5 DC"), std::string::npos);
    EXPECT_NE(j["summary"].get<std::string>().find("zonal axis channel"), std::string::npos);
    // zh3_channel_q16 always decodes per channel: the axis field says so whatever the header holds.
    const auto ch = nlohmann::json::parse(test::run_zhc({"info", dir + "/c6.zhp", "--json"}).out);
    EXPECT_EQ(ch["axis"], "channel");
}

// ---- bench without maps -------------------------------------------------------------------------

TEST(CliTraps, BenchWithoutMapsNeedsThem) {
    const std::string dir = test::fresh_dir("traps_bench");
    ASSERT_EQ(::setenv("ZHC_ENVMAP_DIR", (dir + "/nowhere").c_str(), 1), 0);
    const auto r = test::run_zhc({"bench", "--no-plots", "-r", "sh3"});
    ::unsetenv("ZHC_ENVMAP_DIR");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err.rfind("zhc: error: give environment maps: zhc bench MAP...", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u);
    EXPECT_EQ(r.out, "");
    // ZHC_ENVMAP_DIR pointing at maps: they are benchmarked.
    fs::create_directories(dir + "/maps");
    fs::copy_file(test::envmap_paths()[0], dir + "/maps/" + fs::path(test::envmap_paths()[0]).filename().string());
    ASSERT_EQ(::setenv("ZHC_ENVMAP_DIR", (dir + "/maps").c_str(), 1), 0);
    const auto ok = test::run_zhc({"bench", "--no-plots", "-r", "sh3,sh2", "--repeats", "1", "--directions", "64", "--json"});
    ::unsetenv("ZHC_ENVMAP_DIR");
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_EQ(nlohmann::json::parse(ok.out)["representations"].size(), 2u);
    // The help says where maps come from.
    const auto help = test::run_zhc({"bench", "--help"});
    EXPECT_NE(help.out.find("ZHC_ENVMAP_DIR"), std::string::npos);
}

// ---- --threads: one default, the same output ----------------------------------------------------

TEST(CliTraps, ThreadsDefaultIsZeroEverywhereAndOutputEqualsOneThread) {
    for (const std::vector<std::string>& verb :
         {std::vector<std::string>{"convert"}, {"bake"}, {"demo"}, {"audit"}, {"dering"}, {"project"}, {"lightmap", "encode"},
          {"lightmap", "audit"}, {"lightmap", "synth"}}) {
        std::vector<std::string> args = verb;
        args.push_back("--help");
        const auto r = test::run_zhc(args);
        ASSERT_EQ(r.exit_code, 0) << verb[0];
        // CLI11 prints the default after the type ("--threads INT:INT in [0 - 256]=0"), the help after.
        const std::regex threads_help(R"(--threads INT:INT in \[0 - 256\]=0\s+worker threads, 0 = all cores, the default)");
        EXPECT_TRUE(std::regex_search(r.out, threads_help)) << verb.back() << ":\n" << r.out;
    }
    // The output with the default equals the one-thread output (convert's projection).
    const std::string dir = test::fresh_dir("traps_threads");
    const std::string map = test::envmap_paths()[0];
    ASSERT_EQ(test::run_zhc({"convert", map, "-o", dir + "/d.zhp", "-r", "zh3_q16"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"convert", map, "-o", dir + "/1.zhp", "-r", "zh3_q16", "--threads", "1"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(dir + "/d.zhp"), test::read_bytes(dir + "/1.zhp"));
    ASSERT_EQ(test::run_zhc({"dering", map, "-o", dir + "/d.json"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"dering", map, "-o", dir + "/1.json", "--threads", "1"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(dir + "/d.json"), test::read_bytes(dir + "/1.json"));
}

// ---- audit: --no-timing leaves timing out; the reference of a stored file is named -------------

TEST(CliTraps, NoTimingLeavesTimingOut) {
    const std::string dir = test::fresh_dir("traps_no_timing");
    const std::string in = golden_json(dir);
    const std::vector<std::string> base{"audit", in, "-r", "sh3,zh3_q16", "--directions", "64"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = base;
        a.insert(a.end(), extra.begin(), extra.end());
        return test::run_zhc(a);
    };
    const auto text = with({"--no-timing", "--markdown", dir + "/r.md"});
    ASSERT_EQ(text.exit_code, 0) << text.err;
    EXPECT_NE(text.out.find("chroma"), std::string::npos);
    EXPECT_EQ(text.out.find("enc_ns"), std::string::npos) << text.out;
    EXPECT_EQ(text.out.find("dec_ns"), std::string::npos);
    const auto md_bytes = test::read_bytes(dir + "/r.md");
    const std::string md(md_bytes.begin(), md_bytes.end());
    EXPECT_NE(md.find("chroma"), std::string::npos);
    EXPECT_EQ(md.find("enc_ns"), std::string::npos);
    const auto json = with({"--no-timing", "--json"});
    ASSERT_EQ(json.exit_code, 0);
    const auto j = nlohmann::json::parse(json.out);
    for (const auto& [name, m] : j["aggregate"]["representations"].items()) {
        EXPECT_TRUE(m.contains("rmse")) << name;
        EXPECT_FALSE(m.contains("encode_ns")) << name;
        EXPECT_FALSE(m.contains("decode_ns")) << name;
    }
    // Timing on: the columns and keys are there, with measured (positive) times.
    const auto timed_text = with({});
    EXPECT_NE(timed_text.out.find("enc_ns"), std::string::npos);
    const auto tj = nlohmann::json::parse(with({"--json"}).out);
    for (const auto& [name, m] : tj["aggregate"]["representations"].items()) EXPECT_GT(m["encode_ns"].get<double>(), 0.0) << name;
}

TEST(CliTraps, AuditOfStoredDataSaysSo) {
    const std::string dir = test::fresh_dir("traps_reference");
    const std::string in = golden_json(dir);
    ASSERT_EQ(test::run_zhc({"convert", in, "-o", dir + "/q16.zhp", "-r", "zh3_q16"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"convert", in, "-o", dir + "/sh3.zhp", "-r", "sh3"}).exit_code, 0);
    const auto r = test::run_zhc({"audit", dir + "/q16.zhp", "-r", "zh3_q16,sh3", "--directions", "64", "--no-timing", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    // The trap: zero error for the stored representation, because the reference IS the stored data.
    EXPECT_EQ(j["files"][0]["representations"]["zh3_q16"]["rmse"].get<double>(), 0.0);
    const std::string ref = j["files"][0]["reference"];
    EXPECT_NE(ref.find("the stored data"), std::string::npos) << ref;
    EXPECT_NE(ref.find("zh3_q16"), std::string::npos) << ref;
    const auto text = test::run_zhc({"audit", dir + "/q16.zhp", "-r", "zh3_q16", "--directions", "64", "--no-timing"});
    EXPECT_NE(text.out.find("reference: the stored data: the probes as decoded from zh3_q16"), std::string::npos) << text.out;
    // An exactly stored file and a JSON list say what they are instead.
    const auto exact = nlohmann::json::parse(
        test::run_zhc({"audit", dir + "/sh3.zhp", in, "-r", "sh3", "--directions", "64", "--no-timing", "--json"}).out);
    EXPECT_NE(exact["files"][0]["reference"].get<std::string>().find("stored exactly as sh3"), std::string::npos);
    EXPECT_NE(exact["files"][1]["reference"].get<std::string>().find("JSON float SH3"), std::string::npos);
    EXPECT_EQ(exact["files"][0]["reference"].get<std::string>().find("stored data"), std::string::npos);
}

// ---- gate failure: one line that says which gate, bounded detail --------------------------------

TEST(CliTraps, GateFailureEndsWithOneLineSummary) {
    const std::string dir = test::fresh_dir("traps_gate");
    const std::string in = golden_json(dir);
    // Every lossy entry fails a 1e-9 rmse gate on the golden probes; sh3 (exact) passes.
    const auto r = test::run_zhc({"audit", in, "--directions", "64", "--no-timing", "--max-rmse", "1e-9"});
    ASSERT_EQ(r.exit_code, 8) << r.err;
    const auto j = nlohmann::json::parse(
        test::run_zhc({"audit", in, "--directions", "64", "--no-timing", "--max-rmse", "1e-9", "--json"}).out);
    const std::size_t failures = j["gates"]["failures"].size();
    ASSERT_GT(failures, 10u);
    // The slow twin of the worst value: the largest per-probe rmse over the lossy entries, from the
    // per-probe audits (one probe per file).
    double worst = 0;
    std::string worst_name;
    for (std::size_t p = 0; p < 4; ++p) {
        ProbeList one;
        one.probes = {probes_in_use()[p]};
        const std::string path = dir + "/p" + std::to_string(p) + ".json";
        ASSERT_TRUE(write_probe_json(path, one).ok());
        // ordered_json: table order, the order the summary scans (first of equal values wins).
        const auto pj = nlohmann::ordered_json::parse(test::run_zhc({"audit", path, "--directions", "64", "--no-timing", "--json"}).out);
        for (const auto& [name, m] : pj["files"][0]["representations"].items())
            if (m["rmse"].get<double>() > worst) {
                worst = m["rmse"].get<double>();
                worst_name = name + " at probe " + std::to_string(p);
            }
    }
    // stderr: exactly one line, the summary.
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("zhc: gate failed: " + std::to_string(failures) + " of " +
                              std::to_string(codecs().size()) + " (input, representation) pairs fail; --max-rmse: " +
                              std::to_string(failures) + " pairs, worst rmse ",
                          0),
              0u)
        << r.err;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4g", worst);
    EXPECT_NE(r.err.find(std::string("worst rmse ") + buf + " vs 1e-09 (" + in + ": " + worst_name + ")"), std::string::npos)
        << r.err << " expected worst " << buf << " " << worst_name;
    // stdout: the report, then at most 10 failure lines and the count of the rest.
    EXPECT_NE(r.out.find("gate failures (" + std::to_string(failures) + "):"), std::string::npos);
    EXPECT_NE(r.out.find("  ... " + std::to_string(failures - 10) + " more"), std::string::npos);
    EXPECT_EQ(static_cast<std::size_t>(std::count(r.out.begin(), r.out.end(), '\n')) -
                  count_lines(test::run_zhc({"audit", in, "--directions", "64", "--no-timing"}).out),
              1u + 1u + 10u + 1u);  // blank, header, 10 lines, "... N more"
    EXPECT_EQ(j["gates"]["summary"], r.err.substr(18, r.err.size() - 19));
}

// ---- an output path that is an input --------------------------------------------------------------

// Runs args and checks the refusal: exit 2, one line naming the input, the input unchanged.
void expect_refused(const std::vector<std::string>& args, const std::string& input) {
    const auto before = test::read_bytes(input);
    const auto r = test::run_zhc(args);
    std::string cmd;
    for (const auto& a : args) cmd += a + " ";
    EXPECT_EQ(r.exit_code, 2) << cmd << "\n" << r.err;
    EXPECT_NE(r.err.find(": is the input "), std::string::npos) << cmd << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.out, "") << cmd;
    EXPECT_EQ(test::read_bytes(input), before) << cmd << ": the input changed";
}

TEST(CliTraps, OutputOverInputRefusedInEveryWritingVerb) {
    const std::string dir = test::fresh_dir("traps_overwrite");
    const std::string in = golden_json(dir);
    const std::string zhp = dir + "/p.zhp";
    ASSERT_EQ(test::run_zhc({"convert", in, "-o", zhp, "-r", "sh3"}).exit_code, 0);
    // Spellings of the same file: the path itself, with ./ and ../, a symlink, a hard link.
    const std::string base = fs::path(dir).filename().string();
    fs::create_symlink(zhp, dir + "/sym.zhp");
    fs::create_hard_link(zhp, dir + "/hard.zhp");
    for (const std::string& same : {zhp, dir + "/./p.zhp", dir + "/../" + base + "/p.zhp", dir + "/sym.zhp", dir + "/hard.zhp"})
        expect_refused({"convert", zhp, "-o", same}, zhp);
    expect_refused({"convert", in, "-o", dir + "/./golden.json", "-r", "sh2"}, in);
    // A symlinked folder in the output path.
    fs::create_directory_symlink(dir, dir + "/again");
    expect_refused({"convert", zhp, "-o", dir + "/again/p.zhp", "-r", "zh3_q16"}, zhp);
    expect_refused({"dering", in, "-o", dir + "/again/golden.json"}, in);
    // bake (a copy of the committed scene: the check must not depend on the refusal working).
    const std::string scene = dir + "/scene.json";
    fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/../conformance/inputs/scene.json", scene);
    expect_refused({"bake", scene, "-o", dir + "/./scene.json", "--quiet"}, scene);
    // gltf embed (scene or probes as output) and extract.
    const std::string glb = dir + "/s.glb";
    fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/gltf/gt_list.glb", glb);
    expect_refused({"gltf", "embed", glb, zhp, "-o", glb}, glb);
    const std::string lit = dir + "/lit.glb";
    ASSERT_EQ(test::run_zhc({"gltf", "embed", glb, zhp, "-o", lit}).exit_code, 0);
    // extract writes .zhp/.json: a glTF input named .json (read by content) stands in for the case.
    fs::copy_file(lit, dir + "/lit.json");
    expect_refused({"gltf", "extract", dir + "/lit.json", "-o", dir + "/../" + base + "/lit.json"}, dir + "/lit.json");
    // lightmap synth / encode / decode / audit --html.
    const std::string map = dir + "/map.exr";
    fs::copy_file(test::envmap_paths()[0], map);
    expect_refused({"lightmap", "synth", map, "-o", dir + "/./map.exr", "--size", "8"}, map);
    const std::string lm = dir + "/lm.exr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "-o", lm, "--size", "8"}).exit_code, 0);
    fs::copy_file(lm, dir + "/lm.iz.ktx2");  // an input named like encode's first output
    expect_refused({"lightmap", "encode", dir + "/lm.iz.ktx2", "-o", dir + "/lm"}, dir + "/lm.iz.ktx2");
    fs::remove(dir + "/lm.iz.ktx2");
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", lm, "-o", dir + "/z"}).exit_code, 0);
    expect_refused({"lightmap", "decode", dir + "/z", "-o", dir + "/z.d.ktx2"}, dir + "/z.d.ktx2");
    expect_refused({"lightmap", "audit", lm, "--html", dir + "/./lm.exr"}, lm);
    // audit --markdown over an input.
    expect_refused({"audit", in, "-r", "sh3", "--markdown", dir + "/./golden.json"}, in);
    // A different file next to the input is fine.
    EXPECT_EQ(test::run_zhc({"convert", zhp, "-o", dir + "/other.zhp"}).exit_code, 0);
}

// zhc info on 2-D DDS textures ImageMagick writes (DXT1 and uncompressed, with mip chains): exit
// 0 describing the header (format, size, levels) and why zhc does not read it, instead of refusing
// the file as unknown.
TEST(CliTraps, InfoDescribesTwoDimensionalTexturesImageMagickWrote) {
    const std::string dir = test::fresh_dir("info_2d_dds");
    struct Case {
        const char* compression;
        const char* format;
    };
    for (const Case& c : {Case{"dxt1", "FourCC 'DXT1'"}, Case{"none", "-bit uncompressed"}}) {
        SCOPED_TRACE(c.compression);
        const std::string path = dir + "/" + c.compression + ".dds";
        const std::string cmd = "convert -size 16x8 gradient:red-blue -define dds:compression=" + std::string(c.compression) + " '" + path + "'";
        ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
        const auto r = test::run_zhc({"info", path, "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["type"], "DDS texture (not a cube map; not an IrradZ plane)");
        EXPECT_NE(j["format"].get<std::string>().find(c.format), std::string::npos) << j["format"];
        EXPECT_EQ(j["width"], 16);
        EXPECT_EQ(j["height"], 8);
        EXPECT_EQ(j["levels"], 5);  // 16x8, 8x4, 4x2, 2x1, 1x1
        EXPECT_EQ(j["faces"], 1);
        EXPECT_EQ(j["read_by_zhc"].get<std::string>().rfind("no: ", 0), 0u) << j["read_by_zhc"];
    }
}

// ---- Ctrl-C and kill: no temporary files left ----------------------------------------------------

// The names in `dir` that contain ".tmp-" (the temp-then-rename writers' temporaries).
std::vector<std::string> temporaries_in(const std::string& dir) {
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(e.path().filename().string());
    return found;
}

// Starts zhc with `args`, standard streams on /dev/null, the default action for SIGINT, SIGTERM and
// SIGHUP whatever the test runner had (a runner started in the background ignores SIGINT, and an
// ignored signal stays ignored across exec); returns the child's pid (<= 0 when fork failed).
pid_t spawn_zhc(const std::vector<std::string>& args) {
    std::vector<std::string> argv_s{ZHC_CLI_PATH};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        for (const int s : {SIGINT, SIGTERM, SIGHUP}) ::signal(s, SIG_DFL);
        const int null = ::open("/dev/null", O_RDWR);
        ::dup2(null, 0);
        ::dup2(null, 1);
        ::dup2(null, 2);
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    return pid;
}

struct SignalRun {
    bool saw_temporary = false;  // a temporary appeared before the signal was sent
    int status = 0;              // waitpid's
};
// Starts zhc with `args` (spawn_zhc), waits until a temporary file appears in `dir` (at most
// 120 s), sends `sig`, and waits for the process.
SignalRun run_and_signal(const std::vector<std::string>& args, const std::string& dir, int sig) {
    SignalRun r;
    const pid_t pid = spawn_zhc(args);
    EXPECT_GT(pid, 0);
    if (pid <= 0) return r;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < deadline) {
        if (!temporaries_in(dir).empty()) {
            r.saw_temporary = true;
            break;
        }
        if (::waitpid(pid, &r.status, WNOHANG) == pid) return r;  // ended before a temporary showed
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ::kill(pid, sig);
    ::waitpid(pid, &r.status, 0);
    return r;
}

// lightmap synth, encode and decode stopped by SIGINT (Ctrl-C) and SIGTERM (kill) while they write:
// the process ends by that signal (exit status "killed by SIGINT", as without the handler), no
// *.tmp-PID-* file is left, and the outputs of an earlier run under the same names are untouched.
TEST(CliTraps, SignalRemovesTemporariesAndKeepsFinalNames) {
    const std::string dir = test::fresh_dir("traps_signals");
    const std::string map = test::envmap_paths()[0];
    // The earlier run's outputs (small), kept to compare bytes afterwards.
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "-o", dir + "/lm.exr", "--size", "16"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/lm"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "decode", dir + "/lm", "-o", dir + "/lm_d.exr"}).exit_code, 0);
    // The big jobs' input: 1024 x 1024 texels, one thread, small bands, so each job writes for a while.
    const std::string big = dir + "/big.exr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "-o", big, "--size", "1024", "--half"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", big, "-o", dir + "/big"}).exit_code, 0);
    const std::vector<std::string> finals = {"lm.exr", "lm.iz.ktx2", "lm.d.ktx2", "lm.wa.ktx2", "lm_d.exr"};
    std::vector<std::vector<std::uint8_t>> before;
    for (const auto& f : finals) before.push_back(test::read_bytes(dir + "/" + f));
    const std::vector<std::vector<std::string>> jobs = {
        {"lightmap", "synth", map, "-o", dir + "/lm.exr", "--size", "1024", "--threads", "1", "--band-rows", "16"},
        {"lightmap", "encode", big, "-o", dir + "/lm", "--threads", "1", "--band-rows", "16", "--quality", "slow"},
        {"lightmap", "decode", dir + "/big", "-o", dir + "/lm_d.exr", "--band-rows", "16"},
    };
    for (const int sig : {SIGINT, SIGTERM}) {
        for (const auto& job : jobs) {
            SCOPED_TRACE(job[1] + " " + ::strsignal(sig));
            const SignalRun r = run_and_signal(job, dir, sig);
            EXPECT_TRUE(r.saw_temporary) << "the job ended before it wrote a temporary file";
            EXPECT_TRUE(WIFSIGNALED(r.status)) << "status " << r.status;
            if (WIFSIGNALED(r.status)) {
                EXPECT_EQ(WTERMSIG(r.status), sig);
            }
            const auto left = temporaries_in(dir);
            EXPECT_TRUE(left.empty()) << left.size() << " left, e.g. " << (left.empty() ? "" : left[0]);
            for (const auto& t : left) fs::remove(dir + "/" + t);
            for (size_t i = 0; i < finals.size(); ++i) EXPECT_EQ(test::read_bytes(dir + "/" + finals[i]), before[i]) << finals[i];
        }
    }
}

// Starts zhc with `args`, sends `sig` after `delay`, and returns waitpid's status (the process may
// have ended by itself before).
int run_and_signal_after(const std::vector<std::string>& args, std::chrono::microseconds delay, int sig) {
    const pid_t pid = spawn_zhc(args);
    int status = 0;
    if (pid <= 0) return -1;
    std::this_thread::sleep_for(delay);
    ::kill(pid, sig);
    ::waitpid(pid, &status, 0);
    return status;
}

// A signal at any moment of an encode over an earlier lightmap's planes leaves either the earlier
// set or the whole new one, never a mix (the renames of a set run with the signals held off), and
// no temporary. Signals are sent at 40 moments spread over the encode's run time.
TEST(CliTraps, SignalDuringEncodeLeavesOneWholeSet) {
    const std::string dir = test::fresh_dir("traps_signal_publish");
    const auto maps = test::envmap_paths();
    ASSERT_GE(maps.size(), 2u);
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", maps[0], "-o", dir + "/a.exr", "--size", "64"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", maps[1], "-o", dir + "/b.exr", "--size", "64"}).exit_code, 0);
    const std::vector<std::string> planes = {".iz.ktx2", ".d.ktx2", ".wa.ktx2"};
    auto set_of = [&](const std::string& prefix) {
        std::vector<std::vector<std::uint8_t>> v;
        for (const auto& p : planes) v.push_back(fs::exists(prefix + p) ? test::read_bytes(prefix + p) : std::vector<std::uint8_t>{});
        return v;
    };
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", dir + "/a.exr", "-o", dir + "/a"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", dir + "/b.exr", "-o", dir + "/b"}).exit_code, 0);
    const auto old_set = set_of(dir + "/a"), new_set = set_of(dir + "/b");
    ASSERT_NE(old_set, new_set);
    const std::vector<std::string> job = {"lightmap", "encode", dir + "/b.exr", "-o", dir + "/out", "--threads", "1"};
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(test::run_zhc(job).exit_code, 0);
    const auto run_us = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
    int killed = 0, finished = 0;
    for (int i = 0; i < 40; ++i) {
        for (size_t p = 0; p < planes.size(); ++p) fs::copy_file(dir + "/a" + planes[p], dir + "/out" + planes[p], fs::copy_options::overwrite_existing);
        const int status = run_and_signal_after(job, std::chrono::microseconds(run_us * i / 32), i % 2 ? SIGINT : SIGTERM);
        const auto now = set_of(dir + "/out");
        EXPECT_TRUE(now == old_set || now == new_set) << "moment " << i << ": a mixed set";
        EXPECT_TRUE(temporaries_in(dir).empty()) << "moment " << i;
        if (WIFSIGNALED(status)) {
            ++killed;
        } else {
            EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
            EXPECT_EQ(now, new_set);
            ++finished;
        }
    }
    EXPECT_GT(killed, 10);  // the moments cover the run: most stop it, the last ones come after its end
    std::printf("encode of 64x64: %.1f ms; %d runs stopped by the signal, %d finished\n", run_us / 1000.0, killed, finished);
}

// A signal the process was started ignoring stays ignored (nohup, a background job): the command
// runs to the end and writes its output.
TEST(CliTraps, IgnoredSignalStaysIgnored) {
    const std::string dir = test::fresh_dir("traps_signal_ignored");
    const std::string out = dir + "/lm.exr";
    // sh starts a background job with SIGINT ignored (and `trap '' INT` says so for any shell).
    const std::string script = dir + "/run.sh";
    const std::string text = "trap '' INT\n\"" + std::string(ZHC_CLI_PATH) + "\" lightmap synth '" + test::envmap_paths()[0] + "' -o '" + out +
                             "' --size 512 --threads 1 --band-rows 8 >/dev/null 2>&1 &\npid=$!\n"
                             "i=0; while ! ls '" + dir + "' | grep -q 'tmp-' && [ $i -lt 6000 ]; do sleep 0.01; i=$((i+1)); done\n"
                             "ls '" + dir + "' | grep -q 'tmp-' || exit 99\nkill -INT $pid\nwait $pid\n";
    test::write_bytes(script, std::vector<std::uint8_t>(text.begin(), text.end()));
    const int status = std::system(("sh '" + script + "'").c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "99: no temporary seen before the job ended";
    EXPECT_TRUE(fs::exists(out));
    EXPECT_TRUE(temporaries_in(dir).empty());
}

// ---- lightmap encode: one prefix, one target ----------------------------------------------------

std::set<std::string> files_in(const std::string& dir, const std::string& prefix) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().rfind(prefix, 0) == 0) names.insert(e.path().filename().string());
    return names;
}

// The README's sequence (bc, then --target astc under the same prefix) and the other orders: after
// each encode the prefix holds exactly that encode's planes plus the same target's other container,
// each removed file is named in one note line, and decode reads the newest lightmap (the bytes a
// fresh prefix decodes to).
TEST(CliTraps, EncodeRemovesTheOtherTargetsPlanes) {
    const std::string dir = test::fresh_dir("traps_stale_planes");
    const std::string lm = dir + "/lm.exr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", test::envmap_paths()[0], "-o", lm, "--size", "24"}).exit_code, 0);
    // Fresh-prefix references.
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", lm, "-o", dir + "/ref_bc"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", lm, "-o", dir + "/ref_astc", "--target", "astc"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "decode", dir + "/ref_bc", "-o", dir + "/ref_bc.exr"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "decode", dir + "/ref_astc", "-o", dir + "/ref_astc.exr"}).exit_code, 0);
    const std::string p = dir + "/out";
    struct Step {
        std::vector<std::string> extra;
        std::set<std::string> after;    // files "out.*" afterwards
        std::set<std::string> removed;  // named in notes
        std::string decodes_like;       // "" = no decode check
    };
    const std::vector<Step> steps = {
        {{}, {"out.iz.ktx2", "out.d.ktx2", "out.wa.ktx2"}, {}, "ref_bc.exr"},
        // The README's trap: astc after bc leaves no BC d / w_a planes.
        {{"--target", "astc"}, {"out.iz.ktx2", "out.dwa.ktx2"}, {"out.d.ktx2", "out.wa.ktx2"}, "ref_astc.exr"},
        {{}, {"out.iz.ktx2", "out.d.ktx2", "out.wa.ktx2"}, {"out.dwa.ktx2"}, "ref_bc.exr"},
        // The same target in the other container is kept.
        {{"--container", "dds"}, {"out.iz.ktx2", "out.d.ktx2", "out.wa.ktx2", "out.iz.dds", "out.d.dds", "out.wa.dds"}, {}, ""},
        {{"--target", "astc-ldr"}, {"out.iz.ktx2", "out.dwa.ktx2"}, {"out.d.ktx2", "out.wa.ktx2", "out.iz.dds", "out.d.dds", "out.wa.dds"}, ""},
        // bc in DDS after astc: the ASTC I_z plane (.iz.ktx2) goes with its d/w_a plane.
        {{"--container", "dds"}, {"out.iz.dds", "out.d.dds", "out.wa.dds"}, {"out.iz.ktx2", "out.dwa.ktx2"}, "ref_bc.exr"},
    };
    for (size_t i = 0; i < steps.size(); ++i) {
        const Step& st = steps[i];
        SCOPED_TRACE("step " + std::to_string(i));
        std::vector<std::string> args{"lightmap", "encode", lm, "-o", p};
        args.insert(args.end(), st.extra.begin(), st.extra.end());
        const auto r = test::run_zhc(args);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_EQ(files_in(dir, "out."), st.after);
        std::set<std::string> noted;
        const std::regex note("zhc: note: removed " + dir + "/(out\\.[a-z.0-9]+): a (bc|astc) plane of an earlier encode under this prefix");
        for (std::sregex_iterator it(r.err.begin(), r.err.end(), note), end; it != end; ++it) noted.insert((*it)[1]);
        EXPECT_EQ(noted, st.removed) << r.err;
        EXPECT_EQ(count_lines(r.err), st.removed.size()) << r.err;
        if (!st.decodes_like.empty()) {
            const std::string out = dir + "/dec" + std::to_string(i) + ".exr";
            const auto d = test::run_zhc({"lightmap", "decode", p, "-o", out});
            ASSERT_EQ(d.exit_code, 0) << d.err;
            EXPECT_EQ(test::read_bytes(out), test::read_bytes(dir + "/" + st.decodes_like));
        }
    }
    // A failed encode (an input that is not a lightmap) removes nothing.
    const std::set<std::string> kept = files_in(dir, "out.");
    const auto bad = test::run_zhc({"lightmap", "encode", dir + "/ref_bc.iz.ktx2", "-o", p, "--target", "astc"});
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_EQ(files_in(dir, "out."), kept);
}

// ---- options the command would ignore or misread -------------------------------------------------

TEST(CliTraps, FootprintWithoutAstcTargetRefused) {
    const std::string dir = test::fresh_dir("traps_footprint");
    const std::string lm = dir + "/lm.exr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", test::envmap_paths()[0], "-o", lm, "--size", "16"}).exit_code, 0);
    for (const std::vector<std::string>& extra : {std::vector<std::string>{"--footprint", "6x6"}, {"--footprint", "4x4", "--target", "bc"},
                                                  {"--footprint", "8x8", "--container", "dds"}}) {
        std::vector<std::string> args{"lightmap", "encode", lm, "-o", dir + "/o"};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 2) << extra[1];
        EXPECT_EQ(r.err.rfind("zhc: error: --footprint " + extra[1] + ": --target bc does not use it", 0), 0u) << r.err;
        EXPECT_EQ(count_lines(r.err), 1u);
        EXPECT_EQ(r.out, "");
        EXPECT_TRUE(files_in(dir, "o.").empty());
    }
    // With an ASTC target it is used: 6x6 blocks are smaller than 4x4 ones.
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", lm, "-o", dir + "/a6", "--target", "astc", "--footprint", "6x6"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "encode", lm, "-o", dir + "/a4", "--target", "astc"}).exit_code, 0);
    EXPECT_LT(fs::file_size(dir + "/a6.dwa.ktx2"), fs::file_size(dir + "/a4.dwa.ktx2"));
}

// --zstd compresses a .zhp body only: with a JSON or glTF output it would change nothing.
TEST(CliTraps, ZstdWithoutZhpOutputRefused) {
    const std::string dir = test::fresh_dir("traps_zstd");
    const std::string in = golden_json(dir);
    const std::string scene = std::string(ZHC_TEST_DATA_DIR) + "/../conformance/inputs/scene.json";
    for (const std::vector<std::string>& args : {std::vector<std::string>{"convert", in, "-o", dir + "/o.json", "--zstd", "3"},
                                                 {"bake", scene, "-o", dir + "/o.json", "--zstd", "3"},
                                                 {"bake", scene, "-o", dir + "/o.glb", "--zstd", "19"}}) {
        const auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 2) << args[0] << " " << args[3];
        EXPECT_EQ(r.err.rfind("zhc: error: --zstd " + args[5] + ": the output " + args[3], 0), 0u) << r.err;
        EXPECT_EQ(count_lines(r.err), 1u);
        EXPECT_EQ(r.out, "");
        EXPECT_FALSE(fs::exists(args[3]));
    }
    // Into a .zhp it is used (the body is compressed: other bytes than without), and --zstd 0 (none)
    // goes with any output.
    ASSERT_EQ(test::run_zhc({"bake", scene, "-o", dir + "/z.zhp", "--zstd", "19", "--quiet"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"bake", scene, "-o", dir + "/p.zhp", "--quiet"}).exit_code, 0);
    EXPECT_NE(test::read_bytes(dir + "/z.zhp"), test::read_bytes(dir + "/p.zhp"));
    EXPECT_EQ(test::run_zhc({"convert", in, "-o", dir + "/o.json", "--zstd", "0"}).exit_code, 0);
    EXPECT_EQ(test::run_zhc({"bake", scene, "-o", dir + "/o.glb", "--zstd", "0", "--quiet"}).exit_code, 0);
}

// The verbs and their integer options, read from the help (every option whose type is INT or UINT).
std::vector<std::pair<std::vector<std::string>, std::string>> integer_options() {
    std::vector<std::pair<std::vector<std::string>, std::string>> found;
    const std::vector<std::vector<std::string>> verbs = {{"project"}, {"convert"}, {"bake"}, {"audit"}, {"bench"}, {"demo"}, {"dering"},
                                                         {"info"}, {"gltf", "embed"}, {"gltf", "extract"}, {"gltf", "eval"},
                                                         {"lightmap", "encode"}, {"lightmap", "decode"}, {"lightmap", "audit"},
                                                         {"lightmap", "synth"}};
    const std::regex option(R"((--[a-z0-9-]+) U?INT\b)");
    for (const auto& verb : verbs) {
        std::vector<std::string> args = verb;
        args.push_back("--help");
        const auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 0) << verb[0];
        for (std::sregex_iterator it(r.out.begin(), r.out.end(), option), end; it != end; ++it) found.push_back({verb, (*it)[1]});
    }
    return found;
}

// Integers are decimal in every option: "0x10" and "1e3" are refused naming the option (CLI11's
// base auto-detection read them as 16 and refused "1e3" as out of range), a word says it is not a
// number, and a leading zero is decimal ("020" is 20, not octal 16).
TEST(CliTraps, IntegerOptionsAreDecimal) {
    const auto options = integer_options();
    std::set<std::string> names;
    for (const auto& [verb, opt] : options) names.insert(opt);
    // The ones the trap was found with, and the common ones: the help scan sees them.
    for (const char* must : {"--threads", "--budget", "--size", "--band-rows", "--bits", "--zstd", "--directions", "--stride"})
        EXPECT_TRUE(names.count(must)) << must;
    EXPECT_GT(options.size(), 25u);
    for (const auto& [verb, opt] : options) {
        for (const char* bad : {"0x10", "abc", "1e3", "12abc"}) {
            std::vector<std::string> args = verb;
            args.push_back(opt);
            args.push_back(bad);
            const auto r = test::run_zhc(args);
            EXPECT_EQ(r.exit_code, 2) << verb.back() << " " << opt << " " << bad;
            EXPECT_NE(r.err.find(opt), std::string::npos) << r.err;
            EXPECT_NE(r.err.find(std::string("'") + bad + "' is not a decimal integer"), std::string::npos) << r.err;
            EXPECT_EQ(count_lines(r.err), 1u) << r.err;
        }
    }
    // UINT options refuse a sign (strtoull wrapped -1 to 2^64 - 1).
    const auto neg = test::run_zhc({"audit", "x.json", "--budget", "-1"});
    EXPECT_EQ(neg.exit_code, 2);
    EXPECT_NE(neg.err.find("'-1' is negative"), std::string::npos) << neg.err;
    // --budget 020 is budget 20: the same report as --budget 20, and another than --budget 16.
    const std::string dir = test::fresh_dir("traps_decimal");
    const std::string in = golden_json(dir);
    auto audit = [&](const std::string& budget) {
        const auto r = test::run_zhc({"audit", in, "--directions", "64", "--no-timing", "--json", "--budget", budget});
        EXPECT_EQ(r.exit_code, 0) << budget << ": " << r.err;
        return r.out;
    };
    const std::string b20 = audit("20");
    EXPECT_EQ(audit("020"), b20);
    EXPECT_EQ(audit("+0020"), b20);
    EXPECT_NE(audit("16"), b20);
    EXPECT_NE(b20.find("\"budget_bytes\": 20"), std::string::npos);
    EXPECT_EQ(b20.find("\"budget_bytes\": 16,"), b20.find("\"budget_bytes\"")) << "16 is the first budget";
    // --size 016 synthesises 16 x 16, byte for byte as --size 16.
    const std::string map = test::envmap_paths()[0];
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "-o", dir + "/a.exr", "--size", "016"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "-o", dir + "/b.exr", "--size", "16"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(dir + "/a.exr"), test::read_bytes(dir + "/b.exr"));
    // Range checks still apply after the decimal reading: 0257 is 257, above --threads' 256.
    const auto range = test::run_zhc({"project", map, "--threads", "0257"});
    EXPECT_EQ(range.exit_code, 2);
    EXPECT_NE(range.err.find("--threads"), std::string::npos) << range.err;
}

// ---- outputs checked before the work --------------------------------------------------------------

// A file output whose folder takes no files: refused with exit 7 before the work (stdout empty:
// the verbs print their report only after the work), naming the option, the path and the folder.
// zhc run as user nobody (setpriv, util-linux): how a root test process meets a read-only folder.
test::CommandResult run_zhc_as_nobody(const std::vector<std::string>& args, const std::string& dir) {
    auto quote = [](const std::string& a) {
        std::string q = "'";
        for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
        return q + "'";
    };
    std::string cmd = "setpriv --reuid=65534 --regid=65534 --clear-groups " + quote(ZHC_CLI_PATH);
    for (const auto& a : args) cmd += " " + quote(a);
    cmd += " > " + quote(dir + "/nobody.out") + " 2> " + quote(dir + "/nobody.err") + " < /dev/null";
    const int status = std::system(cmd.c_str());
    test::CommandResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    const auto out = test::read_bytes(dir + "/nobody.out"), err = test::read_bytes(dir + "/nobody.err");
    r.out.assign(out.begin(), out.end());
    r.err.assign(err.begin(), err.end());
    return r;
}

void expect_refused_before_work(const std::vector<std::string>& args, const std::string& option, const std::string& path,
                                const std::string& why, const std::string& nobody_dir = "") {
    std::string cmd;
    for (const auto& a : args) cmd += a + " ";
    const auto r = nobody_dir.empty() ? test::run_zhc(args) : run_zhc_as_nobody(args, nobody_dir);
    EXPECT_EQ(r.exit_code, 7) << cmd << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("zhc: error: " + option + " " + path + ": ", 0), 0u) << cmd << "\n" << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("checked before the work"), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.out, "") << cmd;
}

TEST(CliTraps, UnwritableOutputFolderRefusedBeforeWork) {
    const std::string dir = test::fresh_dir("traps_unwritable");
    const std::string in = golden_json(dir);
    const std::string scene = std::string(ZHC_TEST_DATA_DIR) + "/../conformance/inputs/scene.json";
    const std::string lm = dir + "/lm.exr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", test::envmap_paths()[0], "-o", lm, "--size", "256"}).exit_code, 0);
    test::write_bytes(dir + "/file", {'x'});
    // Folders that take no file, for any user: missing, and a file where the folder should be.
    struct Place {
        std::string folder, why;
        bool as_nobody = false;
    };
    std::vector<Place> places = {{dir + "/missing", "the folder " + dir + "/missing does not exist"},
                                 {dir + "/file", dir + "/file is not a folder"}};
    // A read-only folder (root writes there anyway: checked where the tests run as another user).
    const std::string ro = dir + "/read_only";
    fs::create_directory(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    // Root writes there anyway: a root test process runs zhc as user nobody for this folder (the
    // test folder open to it, the read-only folder not).
    const bool root = ::geteuid() == 0;
    if (root) fs::permissions(dir, fs::perms::all);
    places.push_back({ro, "cannot create a file in the folder " + ro + " (Permission denied)", root});
    // Into a folder that takes files the bake runs and prints its report on stdout: an empty stdout
    // below means the refusal came before the bake.
    const auto bake_ok = test::run_zhc({"bake", scene, "-o", dir + "/ok.zhp"});
    ASSERT_EQ(bake_ok.exit_code, 0) << bake_ok.err;
    EXPECT_NE(bake_ok.out.find("bake total"), std::string::npos);
    for (const Place& pl : places) {
        SCOPED_TRACE(pl.folder);
        const std::string as = pl.as_nobody ? dir : "";  // run as nobody, its output files in dir
        expect_refused_before_work({"bake", scene, "-o", pl.folder + "/p.zhp"}, "-o", pl.folder + "/p.zhp", pl.why, as);
        expect_refused_before_work({"audit", in, "-r", "sh3", "--directions", "64", "--html", pl.folder + "/r.html"}, "--html",
                                   pl.folder + "/r.html", pl.why, as);
        expect_refused_before_work({"audit", in, "-r", "sh3", "--directions", "64", "--markdown", pl.folder + "/r.md"}, "--markdown",
                                   pl.folder + "/r.md", pl.why, as);
        expect_refused_before_work({"lightmap", "audit", lm, "--html", pl.folder + "/l.html"}, "--html", pl.folder + "/l.html", pl.why, as);
        expect_refused_before_work({"lightmap", "encode", lm, "-o", pl.folder + "/x"}, "-o", pl.folder + "/x.iz.ktx2", pl.why, as);
        expect_refused_before_work({"lightmap", "encode", lm, "-o", pl.folder + "/x", "--container", "dds"}, "-o", pl.folder + "/x.iz.dds",
                                   pl.why, as);
        expect_refused_before_work({"convert", in, "-o", pl.folder + "/c.zhp", "-r", "zh3_q16"}, "-o", pl.folder + "/c.zhp", pl.why, as);
        expect_refused_before_work({"convert", in, "-o", dir + "/c.zhp", "--depfile", pl.folder + "/c.d"}, "--depfile", pl.folder + "/c.d",
                                   pl.why, as);
        EXPECT_FALSE(fs::exists(dir + "/c.zhp"));
        // demo checks --html once it has created its -o folder (the report may go into it).
        expect_refused_before_work({"demo", "-o", dir + "/demo", "--html", pl.folder + "/d.html"}, "--html", pl.folder + "/d.html", pl.why, as);
        EXPECT_FALSE(fs::exists(dir + "/demo/scene.json"));
    }
    fs::permissions(ro, fs::perms::owner_all);
    // demo's --html into the -o folder it creates (the folder does not exist before the run).
    const auto demo = test::run_zhc({"demo", "-o", dir + "/demo2", "--html", dir + "/demo2/r.html", "--directions", "16"});
    EXPECT_EQ(demo.exit_code, 0) << demo.err;
    EXPECT_TRUE(fs::exists(dir + "/demo2/r.html"));
    // audit --html into the --images folder that audit creates.
    const auto images = test::run_zhc({"audit", in, "-r", "sh3", "--directions", "64", "--images", dir + "/pics", "--html", dir + "/pics/r.html",
                                       "--markdown", dir + "/pics/r.md"});
    EXPECT_EQ(images.exit_code, 0) << images.err;
    EXPECT_TRUE(fs::exists(dir + "/pics/r.html"));
    // ... but not into a folder beside it.
    expect_refused_before_work({"audit", in, "-r", "sh3", "--directions", "64", "--images", dir + "/pics2", "--html", dir + "/other/r.html"},
                               "--html", dir + "/other/r.html", "the folder " + dir + "/other does not exist");
    // A folder that takes files leaves no probe file behind.
    EXPECT_TRUE(temporaries_in(dir).empty());
}

// --depfile with nothing to name as its target: refused before the work (audit prints its tables
// only after it), exit 7 as documented (docs/build-integration.md).
TEST(CliTraps, DepfileWithoutFileOutputRefusedBeforeWork) {
    const std::string dir = test::fresh_dir("traps_depfile_target");
    const std::string in = golden_json(dir);
    const std::string lm = dir + "/lm.exr";
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", test::envmap_paths()[0], "-o", lm, "--size", "16"}).exit_code, 0);
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"audit", in, "--directions", "64", "--depfile", dir + "/a.d"}, {"lightmap", "audit", lm, "--depfile", dir + "/a.d"}}) {
        const auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 7) << args[0];
        EXPECT_EQ(r.err.rfind("zhc: error: --depfile " + dir + "/a.d: zhc " + (args[0] == "audit" ? "audit" : "lightmap audit") +
                                  " writes no file here, and a depfile needs one",
                              0),
                  0u)
            << r.err;
        EXPECT_EQ(count_lines(r.err), 1u);
        EXPECT_EQ(r.out, "");
        EXPECT_FALSE(fs::exists(dir + "/a.d"));
    }
    // With a file output the depfile is written and names it.
    const auto ok = test::run_zhc({"audit", in, "--directions", "64", "--markdown", dir + "/r.md", "--depfile", dir + "/a.d"});
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    const auto d = test::read_bytes(dir + "/a.d");
    EXPECT_EQ(std::string(d.begin(), d.end()).rfind(dir + "/r.md:", 0), 0u);
}

// ---- help texts say what an option is ----------------------------------------------------------

TEST(CliTraps, HelpTextsSayWhatOptionsAre) {
    for (const std::vector<std::string>& verb :
         {std::vector<std::string>{}, {"project"}, {"convert"}, {"bake"}, {"audit"}, {"bench"}, {"demo"}, {"dering"}, {"info"}, {"gltf"},
          {"gltf", "embed"}, {"gltf", "extract"}, {"gltf", "eval"}, {"lightmap"}, {"lightmap", "encode"}, {"lightmap", "decode"},
          {"lightmap", "audit"}, {"lightmap", "synth"}}) {
        std::vector<std::string> args = verb;
        args.push_back("--help");
        const auto r = test::run_zhc(args);
        ASSERT_EQ(r.exit_code, 0);
        // (Value names are not history: lightmap encode's --solve takes "old", the talk's name for its baseline.)
        const std::regex history(R"(\b(older|formerly|deprecated|legacy|used to|no longer|renamed|previously|was replaced|the old)\b)",
                                 std::regex::icase);
        std::smatch m;
        EXPECT_FALSE(std::regex_search(r.out, m, history)) << (verb.empty() ? "zhc" : verb.back()) << ": '" << m.str() << "' in\n" << r.out;
    }
    // The second names say what they are.
    EXPECT_NE(test::run_zhc({"bake", "--help"}).out.find("--to is another name for -r, the same option"), std::string::npos);
    EXPECT_NE(test::run_zhc({"convert", "--help"}).out.find("--to is another name for -r, the same option"), std::string::npos);
    EXPECT_NE(test::run_zhc({"gltf", "embed", "--help"}).out.find("--encoding is another name for -r, the same option"), std::string::npos);
}

}  // namespace
}  // namespace zhc
