// The HTML report: `zhc audit --html` on two sample maps and `zhc demo` write one
// self-contained file each; the table has one row per representation; headless Chromium opens
// each from a file:// URL, every picture decodes, and a screenshot is not blank.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <limits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "codec/probe/codec.h"
#include "formats/report/html_report.h"
#include "formats/report/lightmap_report.h"
#include "support.h"

namespace fs = std::filesystem;
using namespace zhc;

namespace {

std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

size_t count(const std::string& text, const std::string& needle) {
    size_t n = 0;
    for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++n;
    return n;
}

// The <table ... id="summary"> element's text.
std::string summary_table(const std::string& doc) {
    const size_t a = doc.find("id=\"summary\"");
    if (a == std::string::npos) return "";
    const size_t b = doc.find("</table>", a);
    return b == std::string::npos ? "" : doc.substr(a, b - a);
}

// Names in the summary table's row headers, in order.
std::vector<std::string> row_names(const std::string& table) {
    std::vector<std::string> names;
    const std::regex row(R"(<tr class="rep"><th scope="row">([^<]*)</th>)");
    for (auto it = std::sregex_iterator(table.begin(), table.end(), row); it != std::sregex_iterator(); ++it)
        names.push_back((*it)[1].str());
    return names;
}

std::vector<std::string> codec_names() {
    std::vector<std::string> n;
    for (const Codec& c : codecs()) n.emplace_back(c.name);
    return n;
}

// What every report must satisfy without a browser.
void check_self_contained(const std::string& doc, size_t expected_images) {
    ASSERT_FALSE(doc.empty());
    EXPECT_EQ(doc.rfind("<!DOCTYPE html>", 0), 0u);
    // Nothing fetched: no http(s) URL anywhere, no external script, style sheet or font.
    EXPECT_EQ(doc.find("http://"), std::string::npos);
    EXPECT_EQ(doc.find("https://"), std::string::npos);
    EXPECT_EQ(doc.find("<link"), std::string::npos);
    EXPECT_EQ(doc.find("@import"), std::string::npos);
    EXPECT_EQ(doc.find("@font-face"), std::string::npos);
    const std::regex script_src(R"(<script[^>]*\ssrc=)");
    EXPECT_FALSE(std::regex_search(doc, script_src));
    // Every image is an inlined PNG that decodes, and there are as many as expected.
    // Parsed by hand: std::regex recurses per character and overflows the stack on a long data URI.
    const std::string prefix = "<img src=\"data:image/png;base64,";
    const size_t step = expected_images > 20 ? 9 : 1;  // decode every 9th of many (slow under sanitizers)
    size_t n = 0;
    for (size_t at = doc.find(prefix); at != std::string::npos; at = doc.find(prefix, at + 1), ++n) {
        const size_t b64_begin = at + prefix.size();
        const size_t b64_end = doc.find('"', b64_begin);
        ASSERT_NE(b64_end, std::string::npos);
        const std::regex size_attrs(R"re(^" width="(\d+)" height="(\d+)")re");
        std::smatch m;
        const std::string attrs = doc.substr(b64_end, 64);
        ASSERT_TRUE(std::regex_search(attrs, m, size_attrs)) << attrs;
        if (n % step != 0) continue;
        // Decode the base64 here (an independent decoder, not the writer's encoder run backwards).
        std::vector<std::uint8_t> bytes;
        std::uint32_t val = 0;
        int bits = -8;
        const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        for (size_t i = b64_begin; i < b64_end; ++i) {
            const char ch = doc[i];
            const char* p = std::strchr(alphabet, ch);
            if (ch == '=' || !p) break;
            val = ((val << 6) | static_cast<std::uint32_t>(p - alphabet)) & 0xFFFFFFu;
            bits += 6;
            if (bits >= 0) {
                bytes.push_back(static_cast<std::uint8_t>((val >> bits) & 0xFF));
                bits -= 8;
            }
        }
        auto decoded = decode_image_rgb8(bytes);
        ASSERT_TRUE(decoded.ok()) << "inline image " << n << " does not decode";
        EXPECT_EQ(decoded->width, std::stoi(m[1].str()));
        EXPECT_EQ(decoded->height, std::stoi(m[2].str()));
    }
    EXPECT_EQ(n, expected_images);
    EXPECT_EQ(count(doc, "<img "), expected_images);
}

std::string chromium() {
#ifdef ZHC_CHROMIUM
    const std::string c = ZHC_CHROMIUM;
    if (!c.empty() && c.find("NOTFOUND") == std::string::npos) return c;
#endif
    return "";
}

bool require_browser() {
#if defined(ZHC_REQUIRE_BROWSER) && ZHC_REQUIRE_BROWSER
    return true;
#else
    return false;
#endif
}

struct BrowserRun {
    int exit_code = -1;
    std::string out, err;
};

// Headless Chromium on `html` with `extra` flags, a fresh profile, no network services.
BrowserRun run_chromium(const std::string& html, const std::string& work, const std::string& extra) {
    const std::string profile = work + "/profile";
    std::error_code ec;
    fs::remove_all(profile, ec);
    fs::create_directories(profile, ec);
    const std::string out = work + "/chromium.out", err = work + "/chromium.err";
    const std::string cmd = "timeout 180 '" + chromium() +
                            "' --headless=new --no-sandbox --disable-gpu --disable-quic --no-first-run "
                            "--disable-background-networking --disable-component-update --disable-sync "
                            "--enable-logging=stderr --v=0 --user-data-dir='" + profile + "' " + extra + " 'file://" +
                            fs::absolute(html).string() + "' > '" + out + "' 2> '" + err + "' < /dev/null";
    const int status = std::system(cmd.c_str());
    BrowserRun r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(out);
    r.err = slurp(err);
    fs::remove_all(profile, ec);
    return r;
}

// Opens the report in Chromium: the DOM holds the table rows, every image decoded (the page's
// own script counts them once loaded), no console error, a screenshot that is not blank.
void check_in_browser(const std::string& html, const std::string& work, size_t rows, size_t images) {
    if (chromium().empty()) {
        if (require_browser()) FAIL() << "chromium not found but ZHC_REQUIRE_MESA_TEST is on";
        GTEST_SKIP() << "chromium not found (install: chromium)";
    }
    const BrowserRun dom = run_chromium(html, work, "--virtual-time-budget=10000 --dump-dom");
    ASSERT_EQ(dom.exit_code, 0) << dom.err;
    const std::string expect_ok = "data-images-ok=\"" + std::to_string(images) + "/" + std::to_string(images) + "\"";
    EXPECT_NE(dom.out.find(expect_ok), std::string::npos) << "the page's image count is not " << expect_ok;
    EXPECT_EQ(row_names(summary_table(dom.out)).size(), rows);
    EXPECT_EQ(dom.err.find("Uncaught"), std::string::npos) << dom.err;
    EXPECT_EQ(dom.err.find(":CONSOLE"), std::string::npos) << "console message: " << dom.err;

    const std::string shot = work + "/screenshot.png";
    fs::remove(shot);
    const BrowserRun s = run_chromium(html, work, "--virtual-time-budget=10000 --window-size=1280,2000 --screenshot='" + shot + "'");
    ASSERT_EQ(s.exit_code, 0) << s.err;
    const std::vector<std::uint8_t> png = zhc::test::read_bytes(shot);
    auto img = decode_image_rgb8(png);
    ASSERT_TRUE(img.ok()) << shot;
    EXPECT_EQ(img->width, 1280);
    EXPECT_EQ(img->height, 2000);
    std::set<std::uint32_t> colours;
    size_t non_white = 0;
    for (size_t i = 0; i + 2 < img->rgb.size(); i += 3) {
        colours.insert((std::uint32_t(img->rgb[i]) << 16) | (std::uint32_t(img->rgb[i + 1]) << 8) | img->rgb[i + 2]);
        if (img->rgb[i] < 200 || img->rgb[i + 1] < 200 || img->rgb[i + 2] < 200) ++non_white;
    }
    // Text, the table and the pictures: many colours, and a good part of the page is not background.
    EXPECT_GT(colours.size(), 200u);
    EXPECT_GT(non_white, img->rgb.size() / 3 / 50);
}

}  // namespace

TEST(HtmlReport, WriterPieces) {
    EXPECT_EQ(html_escape("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
    // RFC 4648 test vectors.
    auto b64 = [](const std::string& s) { return base64_encode(std::vector<std::uint8_t>(s.begin(), s.end())); };
    EXPECT_EQ(b64(""), "");
    EXPECT_EQ(b64("f"), "Zg==");
    EXPECT_EQ(b64("fo"), "Zm8=");
    EXPECT_EQ(b64("foo"), "Zm9v");
    EXPECT_EQ(b64("foobar"), "Zm9vYmFy");
    // PNG round trip through stb.
    std::vector<std::uint8_t> px(7 * 5 * 3);
    for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<std::uint8_t>(i * 37 + 11);
    auto back = decode_image_rgb8(encode_png_rgb8(px, 7, 5));
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->rgb, px);
    EXPECT_FALSE(decode_image_rgb8({1, 2, 3}).ok());
    EXPECT_TRUE(encode_png_rgb8(px, 8, 5).empty());  // wrong size: refused
    // Sphere normals: unit length, the disc centres face +X and -X, top is +Z.
    Vec3 n;
    ASSERT_TRUE(sphere_pixel_normal(48, 48, 96, &n));
    EXPECT_GT(n.x, 0.99);
    ASSERT_TRUE(sphere_pixel_normal(96 + 48, 48, 96, &n));
    EXPECT_LT(n.x, -0.99);
    ASSERT_TRUE(sphere_pixel_normal(48, 1, 96, &n));
    EXPECT_GT(n.z, 0.9);
    EXPECT_FALSE(sphere_pixel_normal(0, 0, 96, &n));
    EXPECT_FALSE(sphere_pixel_normal(192, 0, 96, &n));
    EXPECT_FALSE(sphere_pixel_normal(-1, 5, 96, &n));
    for (int y = 0; y < 96; y += 7)
        for (int x = 0; x < 192; x += 5)
            if (sphere_pixel_normal(x, y, 96, &n)) {
                EXPECT_NEAR(dot(n, n), 1.0, 1e-12);
            }
}

TEST(HtmlReport, SvgLabelsNeverOverprint) {
    // Points that coincide or nearly so: their labels must still be at least a line apart.
    ScatterPlot p{"t", "x", "y", {}, {}};
    for (int i = 0; i < 12; ++i) p.points.push_back({"label" + std::to_string(i), 16.0 + (i % 3), 0.01 * (1 + (i % 2) * 1e-3)});
    const std::string svg = scatter_svg(p);
    const std::regex text(R"re(<text x="(\d+)" y="([-0-9.e]+)" font-size="12" fill="#[0-9a-f]+">label)re");
    std::vector<double> ys;
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), text); it != std::sregex_iterator(); ++it)
        ys.push_back(std::stod((*it)[2].str()));
    ASSERT_EQ(ys.size(), 12u);
    std::sort(ys.begin(), ys.end());
    for (size_t i = 1; i < ys.size(); ++i) EXPECT_GE(ys[i] - ys[i - 1], 14.9);
}

TEST(HtmlReport, AuditOfTwoSampleMaps) {
    const std::string dir = zhc::test::fresh_dir("html_report_audit");
    const std::string html = dir + "/audit.html";
    const std::string maps = ZHC_ENVMAP_DIR;
    const auto r = zhc::test::run_zhc({"audit", maps + "/city.exr", maps + "/studio.exr", "--no-timing", "--directions", "512",
                                       "--max-relative-rmse", "0.08", "--html", html});
    ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 8) << r.err;
    const std::string doc = slurp(html);
    const size_t reps = codecs().size();
    // Per input: the reference and, per representation, irradiance and error, each as lit spheres
    // and as a lat-long map (128x64).
    check_self_contained(doc, 2 * 2 * (1 + 2 * reps));
    EXPECT_EQ(count(doc, "width=\"128\" height=\"64\" alt="), 2 * (1 + 2 * reps));
    EXPECT_EQ(count(doc, "width=\"192\" height=\"96\" alt="), 2 * (1 + 2 * reps));
    // No --runtime-cost: the runtime cost column says it was not given, in every table, and how to give it.
    EXPECT_EQ(count(doc, "<th scope=\"col\">runtime cost</th>"), 3u);
    EXPECT_EQ(count(doc, "<td class=\"na\">not given</td>"), 3 * reps);
    EXPECT_NE(doc.find("pass that file with --runtime-cost FILE"), std::string::npos);
    EXPECT_EQ(row_names(summary_table(doc)), codec_names());
    EXPECT_EQ(count(doc, "<tr class=\"rep\">"), 3 * reps);  // summary + one table per input
    EXPECT_NE(doc.find("city.exr"), std::string::npos);
    EXPECT_NE(doc.find("studio.exr"), std::string::npos);
    // The gate's outcome agrees with the exit code.
    if (r.exit_code == 8) {
        EXPECT_NE(doc.find("<ul class=\"failures\">"), std::string::npos);
        EXPECT_NE(doc.find("fails a gate"), std::string::npos);
    } else {
        EXPECT_NE(doc.find("All gates passed."), std::string::npos);
    }
    EXPECT_NE(doc.find("<svg class=\"plot\""), std::string::npos);
    // Deterministic with --no-timing.
    const std::string html2 = dir + "/audit2.html";
    const auto r2 = zhc::test::run_zhc({"audit", maps + "/city.exr", maps + "/studio.exr", "--no-timing", "--directions", "512",
                                        "--max-relative-rmse", "0.08", "--html", html2});
    EXPECT_EQ(r2.exit_code, r.exit_code);
    EXPECT_EQ(slurp(html2), doc);
    check_in_browser(html, dir, reps, 2 * 2 * (1 + 2 * reps));
}

TEST(HtmlReport, Demo) {
    const std::string dir = zhc::test::fresh_dir("html_report_demo");
    const auto r = zhc::test::run_zhc({"demo", "-o", dir, "--directions", "128"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string html = dir + "/report.html";
    EXPECT_NE(r.out.find("report: " + html), std::string::npos) << r.out;
    const std::string doc = slurp(html);
    EXPECT_LT(doc.size(), 5u << 20);
    const size_t reps = codecs().size();
    const size_t inputs = count(doc, "<section id=\"input-");
    EXPECT_GE(inputs, 2u);
    check_self_contained(doc, inputs * 2 * (1 + 2 * reps));
    EXPECT_EQ(count(doc, "width=\"128\" height=\"64\" alt="), inputs * (1 + 2 * reps));
    EXPECT_EQ(row_names(summary_table(doc)), codec_names());
    EXPECT_EQ(count(doc, "<td class=\"na\">not given</td>"), (1 + inputs) * reps);
    check_in_browser(html, dir, reps, inputs * 2 * (1 + 2 * reps));
}

TEST(HtmlReport, Bench) {
    const std::string dir = zhc::test::fresh_dir("html_report_bench");
    const std::string html = dir + "/bench.html";
    const auto r = zhc::test::run_zhc({"bench", std::string(ZHC_ENVMAP_DIR) + "/city.exr", "--repeats", "1", "--directions", "256",
                                       "--no-plots", "--html", html});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string doc = slurp(html);
    check_self_contained(doc, 0);
    EXPECT_EQ(row_names(summary_table(doc)), codec_names());
    EXPECT_NE(doc.find("<th scope=\"col\">eval ns/sample</th>"), std::string::npos);
    EXPECT_EQ(count(doc, "<svg class=\"plot\""), 2u);  // error vs bytes, error vs encode time
    EXPECT_EQ(count(doc, "red: Pareto frontier"), 2u);
    check_in_browser(html, dir, codecs().size(), 0);
}

TEST(HtmlReport, RuntimeCostColumns) {
    // bench_runtime's JSON for three of the four representations audited.
    const std::string dir = zhc::test::fresh_dir("html_report_cost");
    const std::string cost = dir + "/cost.json", html = dir + "/audit.html", demo_dir = dir + "/demo";
    {
        std::ofstream f(cost);
        f << R"({"benchmark":"runtime","device":"test device","rows":[)"
             R"({"encoding":"sh3","spirv_instructions":123,"ns_per_eval":2.5,"ratio_to_sh3":1},)"
             R"({"encoding":"zh3_q16","spirv_instructions":97,"ns_per_eval":1.25,"ratio_to_sh3":0.5},)"
             R"({"encoding":"sh2","spirv_instructions":61,"ns_per_eval":0.75,"ratio_to_sh3":0.3}]})";
    }
    const auto r = zhc::test::run_zhc({"audit", std::string(ZHC_ENVMAP_DIR) + "/city.exr", "--representations", "sh3,sh2,zh3_lum,zh3_q16",
                                       "--no-timing", "--directions", "256", "--runtime-cost", cost, "--html", html});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string doc = slurp(html);
    const std::string table = summary_table(doc);
    EXPECT_NE(table.find("runtime cost: SPIR-V instructions"), std::string::npos);
    // Each row's cost is its own: the row text of sh3 has 123 and 2.5, zh3_lum (not in the file) dashes.
    auto row = [&](const std::string& name) {
        const size_t a = table.find("<th scope=\"row\">" + name + "</th>");
        return a == std::string::npos ? std::string() : table.substr(a, table.find("</tr>", a) - a);
    };
    EXPECT_NE(row("sh3").find(">123</td><td data-v=\"2.5\">2.5</td>"), std::string::npos) << row("sh3");
    EXPECT_NE(row("sh2").find(">61</td><td data-v=\"0.75\">0.75</td>"), std::string::npos) << row("sh2");
    EXPECT_NE(row("zh3_q16").find(">97</td>"), std::string::npos);
    const std::string lum = row("zh3_lum");
    ASSERT_GT(lum.size(), 40u);
    EXPECT_EQ(lum.substr(lum.size() - 44), "<td data-v=\"-1\">-</td><td data-v=\"-1\">-</td>") << lum;
    EXPECT_EQ(doc.find("not given"), std::string::npos);
    EXPECT_NE(doc.find("test device"), std::string::npos);
    EXPECT_EQ(count(doc, "<svg class=\"plot\""), 2u);  // error vs bytes, error vs runtime cost
    EXPECT_NE(doc.find("Error vs runtime cost"), std::string::npos);
    // The text table has the columns too.
    EXPECT_NE(r.out.find("spirv"), std::string::npos);
    EXPECT_NE(r.out.find("gpu_ns"), std::string::npos);
    // The demo takes the same option; its table and report show the cost.
    const auto d = zhc::test::run_zhc({"demo", "-o", demo_dir, "--directions", "64", "--runtime-cost", cost});
    ASSERT_EQ(d.exit_code, 0) << d.err;
    const std::string demo = slurp(demo_dir + "/report.html");
    EXPECT_NE(summary_table(demo).find(">123</td>"), std::string::npos);
    EXPECT_NE(d.out.find("gpu_ns"), std::string::npos);
    // zhc bench's report shows the same columns.
    const auto b = zhc::test::run_zhc({"bench", std::string(ZHC_ENVMAP_DIR) + "/city.exr", "--representations", "sh3,zh3_lum",
                                       "--repeats", "1", "--directions", "64", "--no-plots", "--runtime-cost", cost, "--html",
                                       dir + "/bench.html"});
    ASSERT_EQ(b.exit_code, 0) << b.err;
    const std::string bench = summary_table(slurp(dir + "/bench.html"));
    EXPECT_NE(bench.find(">123</td><td data-v=\"2.5\">2.5</td>"), std::string::npos) << bench;
    // A cost file that is not bench_runtime's output is an error naming the file.
    {
        std::ofstream f(dir + "/bad.json");
        f << R"({"rows":[{"encoding":"sh3"}]})";
    }
    const auto bad = zhc::test::run_zhc({"audit", std::string(ZHC_ENVMAP_DIR) + "/city.exr", "--representations", "sh3",
                                         "--runtime-cost", dir + "/bad.json", "--html", dir + "/x.html"});
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_NE(bad.err.find("bad.json"), std::string::npos) << bad.err;
}

TEST(LightmapReport, WorstErrorWindowMatchesBruteForce) {
    // The sliding-window search against summing every window directly.
    std::uint32_t state = 12345;
    auto rnd = [&] { state = state * 1664525u + 1013904223u; return (state >> 8) / double(1u << 24); };
    for (const auto& [w, h, size] : std::vector<std::array<int, 3>>{{37, 29, 8}, {20, 50, 16}, {13, 9, 64}, {64, 64, 64}, {1, 7, 3}}) {
        std::vector<double> e(static_cast<size_t>(w) * h);
        for (double& v : e) v = rnd() < 0.9 ? rnd() * 0.01 : rnd();
        const CropWindow got = worst_error_window(e, w, h, size);
        const int cw = std::min(size, w), ch = std::min(size, h);
        EXPECT_EQ(got.width, cw);
        EXPECT_EQ(got.height, ch);
        double best = -1;
        int bx = 0, by = 0;
        for (int y = 0; y + ch <= h; ++y)
            for (int x = 0; x + cw <= w; ++x) {
                double s = 0;
                for (int yy = y; yy < y + ch; ++yy)
                    for (int xx = x; xx < x + cw; ++xx) s += e[static_cast<size_t>(yy) * w + xx];
                if (s > best + 1e-9) best = s, bx = x, by = y;
            }
        EXPECT_EQ(got.x, bx) << w << "x" << h << " window " << size;
        EXPECT_EQ(got.y, by) << w << "x" << h << " window " << size;
    }
    // A single hot texel: the window contains it. Non-finite errors count as the largest.
    std::vector<double> e(100 * 80, 0.001);
    e[static_cast<size_t>(70) * 100 + 90] = std::numeric_limits<double>::quiet_NaN();
    const CropWindow hot = worst_error_window(e, 100, 80, 16);
    EXPECT_TRUE(hot.x <= 90 && 90 < hot.x + 16 && hot.y <= 70 && 70 < hot.y + 16);
    // Empty or mismatched: an empty window, no crash.
    EXPECT_EQ(worst_error_window({}, 0, 0, 256).width, 0);
    EXPECT_EQ(worst_error_window(e, 99, 80, 256).width, 0);
}

TEST(LightmapReport, AuditHtml) {
    const std::string dir = zhc::test::fresh_dir("html_report_lightmap");
    // 300x300: the 256x256 crop lies inside; a 48x48 lightmap is shown whole, enlarged.
    for (const int size : {48, 300}) {
        const std::string lm = dir + "/lm" + std::to_string(size) + ".exr", html = dir + "/lm" + std::to_string(size) + ".html";
        const auto s = zhc::test::run_zhc({"lightmap", "synth", std::string(ZHC_ENVMAP_DIR) + "/city.exr", "-o", lm, "--size",
                                           std::to_string(size), "--threads", "2"});
        ASSERT_EQ(s.exit_code, 0) << s.err;
        const auto r = zhc::test::run_zhc({"lightmap", "audit", lm, "--threads", "2", "--quality", "fast", "--html", html});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const std::string doc = slurp(html);
        // Overview and crop of I_z before, after, error; overview of the tilted-normal irradiance.
        check_self_contained(doc, 9);
        EXPECT_NE(doc.find("normal tilted 45 degrees"), std::string::npos);
        const std::vector<std::string> rows = row_names(summary_table(doc));
        ASSERT_EQ(rows.size(), 3u);
        EXPECT_EQ(rows[2], "fit after BC6H + BC5 + BC4");
        // The table's numbers are the command's: its text output prints the same rmse.
        const std::regex after(R"(fit after BC6H \+ BC5 \+ BC4\s+([0-9.e-]+))");
        std::smatch m;
        ASSERT_TRUE(std::regex_search(r.out, m, after)) << r.out;
        std::string cell = ">";
        cell += m[1].str();
        cell += "</td>";
        EXPECT_NE(summary_table(doc).find(cell), std::string::npos) << cell;
        EXPECT_NE(doc.find("Worst-error region"), std::string::npos);
        EXPECT_NE(doc.find("I_z BC6H PSNR"), std::string::npos);
        EXPECT_NE(doc.find(lm), std::string::npos);  // the input, to reproduce
        EXPECT_NE(doc.find("<svg class=\"bar\""), std::string::npos);  // the error scale
        const std::string crop = size == 300 ? "the 256x256 window" : "the 48x48 window";
        EXPECT_NE(doc.find(crop), std::string::npos);
        // The crop pictures are readable: at least 256 pixels on a side (1:1, or enlarged).
        const std::regex crop_img(R"re(width="(\d+)" height="(\d+)" alt="crop )re");
        size_t crops = 0;
        for (auto it = std::sregex_iterator(doc.begin(), doc.end(), crop_img); it != std::sregex_iterator(); ++it, ++crops)
            EXPECT_GE(std::stoi((*it)[1].str()), 240);
        EXPECT_EQ(crops, 3u);
        // Deterministic.
        const auto r2 = zhc::test::run_zhc({"lightmap", "audit", lm, "--threads", "2", "--quality", "fast", "--html", html + "2"});
        ASSERT_EQ(r2.exit_code, 0);
        EXPECT_EQ(slurp(html + "2"), doc);
        if (size == 300) check_in_browser(html, dir, 3, 9);
    }
}
