// zhc bench --volume-cost: bench_volume's JSON (GPU volume layouts) in the text, JSON and HTML
// output, the best layout per GPU byte computed from it, and one-line errors for bad files.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "tests/support.h"

namespace zhc {
namespace {

struct Layout {
    const char* name;
    double bytes;
    double ns;  // -1: not measured
    double demo_mean, gltf_mean;
};

// Hand-made so that the answer is known: at 16 B three layouts, "b" and "h" tie on error (h is
// faster, so h), "a" is worse; at 32 B "d" wins on the demo grid but "e" on the worse grid of the
// two; "f" only ties "e"; "g" only ties "sh3"; "c" is worse than the 16-byte best.
const std::vector<Layout> kLayouts = {
    {"sh3", 108, 1000, 0, 0},  {"a", 16, 100, 0.2, 0.3},   {"b", 16, 50, 0.1, 0.05}, {"c", 24, -1, 0.2, 0.2},
    {"d", 32, 200, 0.01, 0.04}, {"e", 32, 300, 0.03, 0.03}, {"f", 40, 10, 0.03, 0.02}, {"g", 200, 5, 0, 0},
    {"h", 16, 40, 0.1, 0.1},
};

std::string volume_json(const std::vector<Layout>& layouts) {
    nlohmann::ordered_json j;
    j["benchmark"] = "volume";
    j["device"] = "test lavapipe";
    j["samples"] = 1000;
    j["grids"] = {"demo", "scene.glb"};
    j["rows"] = nlohmann::ordered_json::array();
    for (const Layout& l : layouts)
        j["rows"].push_back({{"layout", l.name},
                             {"kind", "k"},
                             {"textures", "t"},
                             {"bytes_per_probe", l.bytes},
                             {"fetches", 7},
                             {"spirv_instructions_minus_skeleton", l.ns < 0 ? -1 : 150},
                             {"lavapipe_ns_per_sample", l.ns},
                             {"ratio_to_sh3", -1},
                             {"gpu_vs_model", -1},
                             {"demo", {{"mean", l.demo_mean}, {"p95", 2 * l.demo_mean}, {"max", 3 * l.demo_mean}}},
                             {"gltf", {{"mean", l.gltf_mean}, {"p95", 2 * l.gltf_mean}, {"max", 3 * l.gltf_mean}}}});
    return j.dump(2);
}

// The slow twin of volume_best_per_byte: for every budget B in the table, scan all layouts of at
// most B bytes for the lowest worst-grid mean error (then lowest time, then file order); keep the
// budgets where that error drops.
std::vector<std::pair<double, std::string>> best_per_byte_twin(const std::vector<Layout>& layouts) {
    std::vector<double> budgets;
    for (const Layout& l : layouts) budgets.push_back(l.bytes);
    std::sort(budgets.begin(), budgets.end());
    budgets.erase(std::unique(budgets.begin(), budgets.end()), budgets.end());
    std::vector<std::pair<double, std::string>> out;
    double last = std::numeric_limits<double>::infinity();
    for (double b : budgets) {
        const Layout* best = nullptr;
        auto err = [](const Layout& l) { return std::max(l.demo_mean, l.gltf_mean); };
        auto ns = [](const Layout& l) { return l.ns < 0 ? std::numeric_limits<double>::infinity() : l.ns; };
        for (const Layout& l : layouts) {
            if (l.bytes > b) continue;
            if (!best || err(l) < err(*best) || (err(l) == err(*best) && ns(l) < ns(*best))) best = &l;
        }
        if (err(*best) < last) {
            out.push_back({b, best->name});
            last = err(*best);
        }
    }
    return out;
}

std::vector<std::string> bench_args(const std::string& volume, std::vector<std::string> extra) {
    std::vector<std::string> a = {"bench", test::envmap_paths()[0], "-r", "sh3,zh3_q16", "--repeats", "1",
                                  "--directions", "32", "--no-plots", "--volume-cost", volume};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
}

void write_text(const std::string& path, const std::string& text) {
    test::write_bytes(path, std::vector<std::uint8_t>(text.begin(), text.end()));
}

TEST(BenchVolumeCost, JsonRowsAndBestPerByte) {
    const std::string dir = test::fresh_dir("bench_volume_cost");
    const std::string vol = dir + "/volume.json";
    write_text(vol, volume_json(kLayouts));
    const auto r = test::run_zhc(bench_args(vol, {"--json"}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j.contains("volume_layouts"));
    const auto& v = j["volume_layouts"];
    EXPECT_EQ(v["device"], "test lavapipe");
    EXPECT_EQ(v["gltf_grid"], "scene.glb");
    ASSERT_EQ(v["rows"].size(), kLayouts.size());
    for (std::size_t i = 0; i < kLayouts.size(); ++i) {
        const auto& row = v["rows"][i];
        EXPECT_EQ(row["layout"], kLayouts[i].name);
        EXPECT_EQ(row["bytes_per_probe"].get<double>(), kLayouts[i].bytes);
        EXPECT_EQ(row["lavapipe_ns_per_sample"].get<double>(), kLayouts[i].ns);
        EXPECT_EQ(row["demo"]["mean"].get<double>(), kLayouts[i].demo_mean);
        EXPECT_EQ(row["gltf"]["p95"].get<double>(), 2 * kLayouts[i].gltf_mean);
        // Ratio to the sh3 row (1000 ns), computed from the times; -1 where not measured.
        const double want = kLayouts[i].ns < 0 ? -1 : kLayouts[i].ns / 1000;
        EXPECT_DOUBLE_EQ(row["ratio_to_sh3"].get<double>(), want) << kLayouts[i].name;
    }
    EXPECT_EQ(v["rows"][3]["spirv_instructions"].get<int>(), -1);
    // Known answer, and the slow twin agrees.
    const std::vector<std::pair<double, std::string>> known = {{16, "h"}, {32, "e"}, {108, "sh3"}};
    ASSERT_EQ(best_per_byte_twin(kLayouts), known);
    ASSERT_EQ(v["best_per_byte"].size(), known.size());
    for (std::size_t i = 0; i < known.size(); ++i) {
        EXPECT_EQ(v["best_per_byte"][i]["max_bytes_per_probe"].get<double>(), known[i].first);
        EXPECT_EQ(v["best_per_byte"][i]["layout"], known[i].second);
    }
    EXPECT_EQ(v["best_per_byte"][1]["worst_mean_error"].get<double>(), 0.03);

    // The same order reversed: file order must not decide anything but exact ties.
    std::vector<Layout> reversed(kLayouts.rbegin(), kLayouts.rend());
    write_text(vol, volume_json(reversed));
    const auto rr = test::run_zhc(bench_args(vol, {"--json"}));
    ASSERT_EQ(rr.exit_code, 0) << rr.err;
    const auto jr = nlohmann::json::parse(rr.out)["volume_layouts"]["best_per_byte"];
    ASSERT_EQ(jr.size(), known.size());
    for (std::size_t i = 0; i < known.size(); ++i) EXPECT_EQ(jr[i]["layout"], known[i].second);
}

TEST(BenchVolumeCost, TextAndHtmlShowTheTableAndTheBestLine) {
    const std::string dir = test::fresh_dir("bench_volume_cost_html");
    const std::string vol = dir + "/volume.json", html = dir + "/bench.html";
    write_text(vol, volume_json(kLayouts));
    const auto r = test::run_zhc(bench_args(vol, {"--html", html}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("GPU volume layouts"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("16 B h (0.1), 32 B e (0.03), 108 B sh3 (0)"), std::string::npos) << r.out;
    const auto bytes = test::read_bytes(html);
    const std::string page(bytes.begin(), bytes.end());
    const auto section = page.find("<section id=\"volume-layouts\">");
    ASSERT_NE(section, std::string::npos);
    const std::string s = page.substr(section, page.find("</section>", section) - section);
    EXPECT_NE(s.find("<h2>GPU volume layouts</h2>"), std::string::npos);
    for (const char* col : {"bytes/probe", "fetches", "SPIR-V", "lavapipe ns", "vs sh3", "demo mean", "glTF p95"})
        EXPECT_NE(s.find(std::string(">") + col + "<"), std::string::npos) << col;
    for (const Layout& l : kLayouts) EXPECT_NE(s.find(std::string("<th scope=\"row\">") + l.name + "</th>"), std::string::npos) << l.name;
    EXPECT_NE(s.find("<td data-v=\"0.20000000000000001\">0.20</td>"), std::string::npos);  // d: 200 / 1000 ns
    EXPECT_NE(s.find("Best layout per GPU byte"), std::string::npos);
    EXPECT_NE(s.find("16 B h (0.1), 32 B e (0.03), 108 B sh3 (0)."), std::string::npos);
    EXPECT_NE(page.find("volume.json (test lavapipe)"), std::string::npos);  // the settings list
}

TEST(BenchVolumeCost, BadFilesAreOneLineErrorsNamingTheField) {
    const std::string dir = test::fresh_dir("bench_volume_cost_bad");
    const std::string good = volume_json(kLayouts);
    struct Case {
        const char* what;
        std::string from, to;  // replace the first `from` in the good file
        const char* field;
    };
    const std::vector<Case> cases = {
        {"missing field", "\"fetches\": 7,", "", "rows[0].fetches: missing"},
        {"wrong type", "\"bytes_per_probe\": 108.0", "\"bytes_per_probe\": \"108\"", "rows[0].bytes_per_probe: not a number"},
        {"NaN literal", "\"mean\": 0.2,", "\"mean\": NaN,", "rows[1].demo.mean: not valid JSON"},
        {"NaN string", "\"mean\": 0.2,", "\"mean\": \"NaN\",", "rows[1].demo.mean: not a number"},
        {"negative error", "\"mean\": 0.2,", "\"mean\": -0.2,", "rows[1].demo.mean: "},
        {"unmeasured bytes", "\"bytes_per_probe\": 108.0", "\"bytes_per_probe\": -1", "rows[0].bytes_per_probe: "},
        {"grid not an object", "\"gltf\": {", "\"gltf\": 3, \"x\": {", "rows[0].gltf: missing or not an object"},
        {"duplicate layout", "\"layout\": \"a\"", "\"layout\": \"sh3\"", "rows[1].layout: 'sh3' listed twice"},
        {"no rows", "\"rows\"", "\"rowz\"", "rows: missing"},
        {"cut", good.substr(good.size() / 2), "", "rows["},
    };
    for (const Case& c : cases) {
        std::string text = good;
        const auto at = text.find(c.from);
        ASSERT_NE(at, std::string::npos) << c.what;
        text.replace(at, c.from.size(), c.to);
        const std::string path = dir + "/bad.json";
        write_text(path, text);
        const auto r = test::run_zhc(bench_args(path, {"--json"}));
        EXPECT_EQ(r.exit_code, 4) << c.what << ": " << r.err;
        EXPECT_NE(r.err.find(path + ": " + c.field), std::string::npos) << c.what << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.what << ": " << r.err;
        EXPECT_TRUE(r.out.empty()) << c.what;  // no partial output
    }
    const auto m = test::run_zhc(bench_args(dir + "/absent.json", {}));
    EXPECT_EQ(m.exit_code, 3) << m.err;
    EXPECT_NE(m.err.find("absent.json"), std::string::npos) << m.err;
}

}  // namespace
}  // namespace zhc
