// zhc demo [-o DIR]: the main job on the built-in default scene (no input files).
//
// Bakes the default scene (gradient sky, sun, three coloured sphere lights, a roof and a sphere
// occluder that shadow the sun and lamps and occlude the sky; codec/bake/scene.h default_scene)
// into a probe grid, encodes it with every representation
// of the codec table, writes the probe containers, the scene, the audit table (reference: each
// probe's baked SH3 irradiance) with its choice per byte budget (codec/audit/choice.h) and
// pictures of a few probes, and prints where everything is.
//
// The containers and the glTF hold zh3_q16 whatever the choice: the demo's outputs are a fixed
// fixture (the runtime tests and the examples read probes_zh3_q16.zhp and probes.glb as zh3_q16),
// and zh3_q16 is the ZH3 paper's own 16-byte layout. The demo prints the 16-byte choice beside it,
// where zh3_q16 ranks, and the commands that embed the choice instead.
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <thread>

#include "choice_output.h"
#include "cli.h"
#include "table.h"
#include "codec/audit/audit_run.h"
#include "codec/audit/choice.h"
#include "codec/bake/scene.h"
#include "formats/report/audit_inputs.h"
#include "formats/io/file_io.h"
#include "formats/probes/gltf_probes.h"
#include "formats/report/html_report.h"
#include "codec/audit/benchmark.h"
#include "formats/probes/probe_file.h"
#include "formats/report/runtime_cost.h"
#include "formats/scene/scene_json.h"

namespace zhc::cli {
namespace cmd_demo {  // one namespace per verb file: the CLI is a unity build
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Options {
    std::string dir = "zhc-demo";
    int threads = 0;
    int directions = 512;
    std::string html;  // default: DIR/report.html
    std::string runtime_cost;  // bench_runtime --json output: GPU cost per encoding
};

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::string fmt(double v, const char* f = "%.4g") {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}


Status write_text(const std::string& path, const std::string& text) {
    return write_file_atomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
}

// Why the containers and the glTF hold zh3_q16, against the 16-byte choice (file comment).
constexpr const char* kEmbedded = "zh3_q16";
std::string embedded_note(const ChoiceResult& choice, const std::string& dir) {
    const BudgetChoice* b16 = nullptr;
    for (const BudgetChoice& b : choice.budgets)
        if (b.budget == 16) b16 = &b;
    const ChoiceCandidate* best = b16 ? choice.chosen(*b16) : nullptr;
    // zh3_q16's rank among the 16-byte representations, by the choice's order (error, then bytes,
    // then the audit's order; a non-finite error ranks last).
    std::vector<const ChoiceCandidate*> fit;
    const ChoiceCandidate* embedded = nullptr;
    for (const ChoiceCandidate& k : choice.candidates) {
        if (k.codec->size_bytes > 16) continue;
        fit.push_back(&k);
        if (k.codec->name == kEmbedded) embedded = &k;
    }
    std::stable_sort(fit.begin(), fit.end(), [](const ChoiceCandidate* a, const ChoiceCandidate* c) {
        const bool fa = std::isfinite(a->error), fc = std::isfinite(c->error);
        if (fa != fc) return fa;
        if (fa && a->error != c->error) return a->error < c->error;
        return a->codec->size_bytes < c->codec->size_bytes;
    });
    if (!best || !embedded) return std::string(kEmbedded) + " (probes_zh3_q16.zhp, probes.glb)";
    const std::size_t rank = static_cast<std::size_t>(std::find(fit.begin(), fit.end(), embedded) - fit.begin()) + 1;
    std::string s = std::string(kEmbedded) + " (probes_zh3_q16.zhp, probes.glb), relative rmse " + fmt(embedded->error, "%.4f");
    if (best == embedded) return s + ": the 16-byte choice on this scene.";
    const std::string name(best->codec->name);
    s += ", rank " + std::to_string(rank) + " of " + std::to_string(fit.size()) + " at 16 bytes; the 16-byte choice on this scene is " +
         name + " (" + fmt(best->error, "%.4f") + "). The demo keeps zh3_q16, the ZH3 paper's 16-byte layout, so that its " +
         "outputs keep one encoding whatever the scene or release (the runtime tests and examples read them as zh3_q16). "
         "To embed the "
         "choice: zhc convert " + (fs::path(dir) / "probes_sh3.zhp").string() + " -o probes_" + name + ".zhp -r " + name +
         ", then zhc gltf embed SCENE.glb probes_" + name + ".zhp -o lit.glb.";
    return s;
}

int run(const Options& o) {
    const auto t_all = Clock::now();
    RuntimeCostTable gpu_table;
    if (!o.runtime_cost.empty()) {
        auto t = read_runtime_cost(o.runtime_cost);
        if (!t) return report(t.error());
        gpu_table = std::move(*t);
    }
    const int threads = resolve_threads(o.threads);
    std::error_code ec;
    fs::create_directories(o.dir, ec);
    if (ec) return report_output(make_error(ErrorCode::kIoError, o.dir + ": cannot create folder (" + ec.message() + ")"));
    // --html may name a file in the folder just created: checked here, before the work, not in main().
    if (!o.html.empty())
        if (const int rc = refuse_unwritable_output("--html", o.html); rc != kExitOk) return rc;
    const auto path = [&](const std::string& name) { return (fs::path(o.dir) / name).string(); };
    std::vector<std::pair<std::string, std::string>> outputs;  // path, what

    // 1. The scene, written out so `zhc bake` can reproduce (and the user can edit) it.
    const Scene scene = default_scene();
    if (Status s = write_text(path("scene.json"), scene_json(scene)); !s) return report_output(s.error());
    outputs.push_back({path("scene.json"), "the built-in scene (zhc bake input)"});
    const auto& c = scene.probes.counts;
    std::printf("zhc demo: built-in scene: gradient sky, sun, %zu sphere lights, %zu occluders (they shadow the sun and two lamps and occlude the sky); %ux%ux%u probe grid\n",
                scene.lights.size() - 1, scene.occluders.size(), c[0], c[1], c[2]);

    // 2. Bake.
    BakeOptions bo;
    bo.threads = threads;
    BakeReport rep;
    ProbeLeakData leak;  // validity and cell planes: the demo's containers equal `zhc bake`'s
    auto baked = bake_scene(scene, bo, &rep, &leak);
    if (!baked) return report(baked.error());
    const std::vector<Sh3Radiance>& probes = *baked;
    std::printf("\nbake: %llu probes in %.1f ms (CPU time per effect, summed over %d threads):\n",
                static_cast<unsigned long long>(rep.probes), rep.total_ms, threads);
    for (const BakeEffect& e : rep.effects)
        std::printf("  %-16s %-38s %9.3f ms\n", e.name.c_str(), ("(" + e.method + ")").c_str(), e.milliseconds);
    for (const std::string& l : rep.leak_lines()) std::printf("  %s\n", l.c_str());

    // 3. Containers: the SH3 hub and the 16-byte zh3_q16.
    const ProbeLayout layout = probe_layout(scene.probes);
    ProbeSet q16_set;
    for (const char* rep_name : {"sh3", "zh3_q16"}) {
        auto set = encode_probe_set(probes, rep_name, CodecOptions{}, layout);
        if (!set) return report(set.error());
        set->validity = leak.validity;
        set->visibility = leak.visibility;
        set->planes = leak.planes;
        if (std::string(rep_name) == "zh3_q16") q16_set = *set;
        if (Status s = write_probe_file(path(std::string("probes_") + rep_name + ".zhp"), *set); !s)
            return report_output(s.error());
        outputs.push_back({path(std::string("probes_") + rep_name + ".zhp"),
                           std::string(rep_name) + " probe container (" + std::to_string(set->codec()->size_bytes) + " bytes/probe)"});
    }

    // 4. Every representation against the baked SH3 (reference: each probe's SH3 irradiance).
    const auto t_audit = Clock::now();
    std::vector<const Codec*> all;
    for (const Codec& k : codecs()) all.push_back(&k);
    const std::vector<Vec3> dirs = fibonacci_sphere(o.directions);
    const CodecOptions copt;
    // The baked grid as one audit input (reference: each probe's SH3); per-probe metrics kept for
    // the pictured probes' tables.
    AuditInput grid;
    grid.path = "baked grid";
    grid.kind = "probes";
    grid.probes = probes;
    AuditOptions aopt;
    aopt.timing = false;
    aopt.threads = threads;
    std::vector<std::vector<ErrorMetrics>> probe_metrics(probes.size());
    const InputAudit audit = audit_input(grid, dirs, all, aopt, [&](size_t p, const std::vector<RepresentationResult>& per_codec) {
        for (const RepresentationResult& r : per_codec) probe_metrics[p].push_back(r.metrics);
    });
    std::vector<std::vector<std::string>> rows{{"representation", "bytes", "grid_bytes", "rmse", "rel_rmse", "max_abs",
                                                "min_irr", "neg_frac", "chroma", "clamped"}};
    std::vector<HtmlRow> html_rows;
    for (size_t k = 0; k < all.size(); ++k) {
        const ErrorMetrics& m = audit.results[k].metrics;
        const int clamped = audit.results[k].stats.clamped_ratios;
        html_rows.push_back({std::string(all[k]->name), all[k]->size_bytes, m, -1, -1});
        rows.push_back({std::string(all[k]->name), std::to_string(all[k]->size_bytes),
                        std::to_string(all[k]->size_bytes * probes.size()), fmt(m.rmse), fmt(m.relative_rmse, "%.4f"),
                        fmt(m.max_abs), fmt(m.min_irradiance), fmt(m.negative_fraction, "%.4f"),
                        fmt(m.chromaticity_error, "%.4f"), std::to_string(clamped)});
        if (!o.runtime_cost.empty()) {  // --runtime-cost: SPIR-V instructions, GPU ns per evaluation
            auto it = gpu_table.by_name.find(std::string(all[k]->name));
            rows.back().push_back(it == gpu_table.by_name.end() ? "-" : std::to_string(it->second.spirv_instructions));
            rows.back().push_back(it == gpu_table.by_name.end() ? "-" : fmt(it->second.ns_per_eval, "%.3g"));
        }
    }
    if (!o.runtime_cost.empty()) {
        rows[0].push_back("spirv");
        rows[0].push_back("gpu_ns");
    }
    std::printf("\naudit: every representation on the %zu baked probes, irradiance at %d directions per probe\n"
                "(reference: the baked SH3; %.0f ms)\n",
                probes.size(), o.directions, ms_since(t_audit));
    std::ostringstream table;
    print_table(table, rows, false);
    std::fputs(table.str().c_str(), stdout);
    // The choice per byte budget (no constraints: `zhc audit` takes them), from the same rows.
    const std::vector<InputAudit> audited{audit};
    const ChoiceResult choice =
        choose_representations(audited, aggregate_inputs(audited), {}, false, ChoiceConstraints{}, choice_budgets({}));
    std::printf("\nchoice: %s\n", choice_intro(choice).c_str());
    std::ostringstream choice_text;
    print_table(choice_text, choice_table(choice), false);
    std::fputs(choice_text.str().c_str(), stdout);
    const std::string why_embedded = embedded_note(choice, o.dir);
    std::printf("\nembedded: %s\n", why_embedded.c_str());
    std::ostringstream md;
    md << "# zhc demo audit\n\n" << rep.probes << " probes of the built-in scene, baked (" << rep.summary()
       << ").\nIrradiance error of every representation against the baked SH3 at " << o.directions
       << " directions per probe.\n\n";
    for (const std::string& l : rep.leak_lines()) md << "- " << l << "\n";
    md << "\n";
    print_table(md, rows, true);
    md << "\n## Choice\n\n" << choice_intro(choice) << "\n\n";
    print_table(md, choice_table(choice), true);
    md << "\nEmbedded: " << why_embedded << "\n";
    if (Status s = write_text(path("audit.md"), md.str()); !s) return report_output(s.error());
    outputs.push_back({path("audit.md"), "the audit table (Markdown)"});

    // 5. Pictures of a few probes: the brightest (in the sun, near a light), the darkest
    // (shadowed), the grid's first and last.
    std::vector<size_t> pick{0, probes.size() - 1};
    std::vector<std::string> role(probes.size());
    role[0] = "first";
    role[probes.size() - 1] = "last";
    size_t bright = 0, dark = 0;
    for (size_t p = 0; p < probes.size(); ++p) {
        const double v = luminance(probes[p][0], LuminanceWeights{});
        if (v > luminance(probes[bright][0], LuminanceWeights{})) bright = p;
        if (v < luminance(probes[dark][0], LuminanceWeights{})) dark = p;
    }
    pick.push_back(bright);
    pick.push_back(dark);
    role[bright] = "brightest";
    role[dark] = "darkest";
    std::sort(pick.begin(), pick.end());
    pick.erase(std::unique(pick.begin(), pick.end()), pick.end());
    const std::string img_dir = path("images");
    const std::vector<Vec3> positions = probe_positions(scene.probes);
    // One picture per worker at a time (each is independent; files are written atomically).
    const auto t_images = Clock::now();
    std::vector<Status> image_status(pick.size(), Status(Ok{}));
    {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
            pool.emplace_back([&, t] {
                for (size_t i = static_cast<size_t>(t); i < pick.size(); i += static_cast<size_t>(threads)) {
                    AuditInput in;
                    in.path = "probe_" + std::to_string(pick[i]);
                    in.kind = "probes";
                    in.description = "baked probe " + std::to_string(pick[i]);
                    in.probes = {probes[pick[i]]};
                    image_status[i] = write_audit_images(img_dir, in, dirs, all, copt);
                }
            });
        for (auto& th : pool) th.join();
    }
    for (const Status& s : image_status)
        if (!s) return report_output(s.error());
    std::printf("\npictures: %zu probes in %.0f ms\n", pick.size(), ms_since(t_images));
    for (size_t p : pick) {
        const std::string stem = "probe_" + std::to_string(p);
        const Vec3 pos = positions[p];
        outputs.push_back({(fs::path(img_dir) / (stem + ".png")).string(),
                           role[p] + " probe " + std::to_string(p) + " at (" + fmt(pos.x, "%.2f") + ", " + fmt(pos.y, "%.2f") + ", " +
                               fmt(pos.z, "%.2f") + "): irradiance and error per representation"});
    }

    // 5b. One self-contained HTML report: the table, a plot, lit spheres of the pictured probes.
    {
        const auto t_html = Clock::now();
        HtmlReport h;
        h.title = "zhc demo";
        h.version = ZHC_VERSION;
        h.intro = "Every representation on the " + std::to_string(probes.size()) +
                  " probes baked from the built-in scene; reference: each probe's baked SH3 irradiance, at " +
                  std::to_string(o.directions) + " Fibonacci-lattice directions per probe (so sh3 itself is exact).";
        h.settings = {{"scene", "built-in default scene (written to " + path("scene.json") + ")"},
                      {"probe grid", std::to_string(c[0]) + "x" + std::to_string(c[1]) + "x" + std::to_string(c[2])},
                      {"bake", rep.summary()},
                      {"walls and leaks", [&] {
                           std::string t;
                           for (const std::string& l : rep.leak_lines()) t += (t.empty() ? "" : "; ") + l;
                           return t.empty() ? std::string("no occluders: nothing to separate") : t;
                       }()},
                      {"directions", std::to_string(o.directions)},
                      {"timing", "not measured by the demo (zhc audit and zhc bench time encode and decode)"},
                      {"command", "zhc demo -o " + o.dir + " --directions " + std::to_string(o.directions) +
                                      (o.runtime_cost.empty() ? "" : " --runtime-cost " + o.runtime_cost)}};
        h.summary_caption = "All " + std::to_string(probes.size()) + " probes pooled";
        h.summary = html_rows;
        ScatterPlot plot{"Error vs bytes per probe", "bytes per probe (log scale)", "relative irradiance rmse (log scale)", {}, {}};
        for (size_t k = 0; k < html_rows.size() && k < all.size(); ++k)  // html_rows follow `all`
            plot.points.push_back(codec_point(*all[k], double(html_rows[k].bytes), html_rows[k].metrics.relative_rmse));
        plot.frontier = zhc_frontier(plot);  // the engine layouts drawn apart (formats/report/plot.h)
        h.plots.push_back(plot);
        h.inputs.resize(pick.size());
        {
            std::vector<std::thread> pool;
            for (int t = 0; t < threads; ++t)
                pool.emplace_back([&, t] {
                    for (size_t i = static_cast<size_t>(t); i < pick.size(); i += static_cast<size_t>(threads)) {
                        const size_t p = pick[i];
                        const Vec3 pos = positions[p];
                        HtmlInputSection& s = h.inputs[i];
                        s.title = role[p] + " probe " + std::to_string(p);
                        s.description = "at (" + fmt(pos.x, "%.2f") + ", " + fmt(pos.y, "%.2f") + ", " + fmt(pos.z, "%.2f") + ")";
                        for (size_t k = 0; k < all.size(); ++k)
                            s.rows.push_back({std::string(all[k]->name), all[k]->size_bytes, probe_metrics[p][k], -1, -1});
                        AuditInput in;
                        in.path = "probe_" + std::to_string(p);
                        in.kind = "probes";
                        in.probes = {probes[p]};
                        s.pictures = render_sphere_pictures(in, all, copt, 96);
                    }
                });
            for (auto& th : pool) th.join();
        }
        apply_runtime_cost(h, o.runtime_cost.empty() ? nullptr : &gpu_table, o.runtime_cost);
        h.tables.push_back(choice_html(choice));
        h.tables.back().notes.push_back("Embedded: " + why_embedded);
        const std::string html_path = o.html.empty() ? path("report.html") : o.html;
        const std::string doc = html_report(h);
        if (Status s = write_text(html_path, doc); !s) return report_output(s.error());
        outputs.push_back({html_path, "the report: table, plot, lit spheres (open in a browser)"});
        std::printf("\nreport: %s (%.0f KB, %.0f ms)\n", html_path.c_str(), doc.size() / 1024.0, ms_since(t_html));
    }

    // 6. The zh3_q16 grid embedded in a glTF (ZHC_light_probes, docs/gltf-extension.md) of an
    // otherwise empty scene; `zhc gltf embed` does the same into a real scene.
    {
        const std::string empty_scene =
            R"({"asset":{"version":"2.0","generator":"zhc demo"},"scene":0,"scenes":[{"name":"zhc demo","nodes":[]}]})";
        const std::vector<std::uint8_t> scene_bytes(empty_scene.begin(), empty_scene.end());
        auto glb = embed_probes_gltf(scene_bytes, path("scene.gltf"), q16_set);
        if (!glb) return report(glb.error());
        if (Status s = write_file_atomic(path("probes.glb"), *glb); !s) return report_output(s.error());
        outputs.push_back({path("probes.glb"), "glTF with the zh3_q16 probe grid (ZHC_light_probes extension)"});
        std::printf("\nglTF: %s (%zu bytes)\n", path("probes.glb").c_str(), glb->size());
    }
    std::printf("\noutputs (%.1f s in all):\n", ms_since(t_all) / 1000.0);
    for (const auto& [p, what] : outputs) std::printf("  %-34s %s\n", p.c_str(), what.c_str());
    std::printf("re-bake: zhc bake %s -o probes.zhp\n", path("scene.json").c_str());
    return kExitOk;
}

const VerbRegistration registration(10, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("demo", "Run the main job on the built-in default scene (no input files needed)");
    sub->add_option("-o,--output", o->dir, "output folder (default: zhc-demo in the current folder)");
    add_threads_option(sub, o->threads, "outputs identical for any count");
    sub->add_option("--directions", o->directions, "audit directions per probe")->check(CLI::Range(16, 1 << 16));
    sub->add_option("--html", o->html, "where to write the HTML report (default: report.html in the output folder)");
    sub->add_option("--runtime-cost", o->runtime_cost,
                    "GPU cost per encoding from build/bench/bench_runtime --json FILE: SPIR-V instructions and lavapipe ns/eval "
                    "in the audit table and the report (without it the report says the cost was not given)");
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_demo
}  // namespace zhc::cli
