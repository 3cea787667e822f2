// zhc bench [MAPS...]: what accuracy costs in time, per representation, with Pareto plots.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli.h"
#include "json_output.h"
#include "codec/audit/benchmark.h"
#include "formats/report/audit_inputs.h"
#include "formats/report/html_report.h"
#include "formats/report/plot.h"
#include "formats/report/runtime_cost.h"
#include "formats/report/volume_cost.h"

namespace zhc::cli {
namespace cmd_bench {  // one namespace per verb file: the CLI is a unity build
namespace {

namespace fs = std::filesystem;

struct Options {
    std::vector<std::string> inputs;
    std::string representations;
    bool json = false;
    std::string plots = "zhc-bench";
    bool no_plots = false;
    int repeats = 7;
    int directions = 1024;
    std::string runtime_cost;  // bench_runtime --json output: GPU cost per encoding
    std::string volume_cost;   // bench_volume --json output: GPU volume layouts
    std::string html;
};

// "1.5e-03" style for errors, "-" for unmeasured (< 0) values.
std::string volume_number(double v, const char* format) {
    if (v < 0) return "-";
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

// The best-per-byte line (formats/report/volume_cost.h): "16 B zh3_q16 (8.3e-02), 24 B ...".
std::string best_per_byte_text(const VolumeCostTable& t) {
    std::string s;
    for (std::size_t i : volume_best_per_byte(t)) {
        const VolumeLayoutCost& r = t.rows[i];
        s += (s.empty() ? "" : ", ") + volume_number(r.bytes_per_probe, "%g") + " B " + r.layout + " (" +
             volume_number(r.worst_mean(), "%.2g") + ")";
    }
    return s;
}

const char* kBestPerByteDefinition =
    "best layout per GPU byte: for each budget of B bytes per probe, the layout with the lowest mean error (the larger of "
    "the two grids' means) among the layouts of at most B bytes; listed where it changes";

int run(const Options& o) {
    std::vector<std::string> inputs = o.inputs;
    if (inputs.empty()) {
        // No maps given: the sample maps, where ZHC_ENVMAP_DIR says (an installed zhc), else where
        // the build found them (the folder the tests read); neither there: the maps are required.
        const char* env = std::getenv("ZHC_ENVMAP_DIR");
        const std::string dir = env && *env ? std::string(env) : std::string(ZHC_SAMPLE_ENVMAP_DIR);
        std::error_code ec;
        if (!fs::is_directory(dir, ec)) {
            std::fprintf(stderr,
                         "zhc: error: give environment maps: zhc bench MAP... (no maps given, and the sample maps' folder %s%s "
                         "does not exist)\n",
                         dir.c_str(), env && *env ? " (ZHC_ENVMAP_DIR)" : " (the build's)");
            return kExitUsage;
        }
        inputs.push_back(dir);
    }
    auto files = expand_audit_inputs(inputs);
    if (!files) return report(files.error());
    if (!o.html.empty())
        if (int rc = refuse_output_over_input("--html", o.html, *files); rc != kExitOk) return rc;
    auto chosen = select_codecs(o.representations);
    if (!chosen) return report(chosen.error());
    const std::vector<const Codec*>& selected = *chosen;
    const std::vector<Vec3> dirs = fibonacci_sphere(o.directions);
    std::vector<BenchProbe> probes;
    AuditLoadOptions lo;
    lo.threads = 2;
    for (const std::string& f : *files) {
        auto in = load_audit_input(f, dirs, lo);
        if (!in) return report(in.error());
        for (size_t p = 0; p < in->probes.size(); ++p) probes.push_back({in->probes[p], in->reference_for(p, dirs)});
    }
    if (probes.empty()) return report(make_error(ErrorCode::kInvalidArgument, "no probes to benchmark"));
    RuntimeCostTable gpu;
    if (!o.runtime_cost.empty()) {
        auto t = read_runtime_cost(o.runtime_cost);
        if (!t) return report(t.error());
        gpu = std::move(*t);
    }
    VolumeCostTable volume;
    if (!o.volume_cost.empty()) {
        auto t = read_volume_cost(o.volume_cost);
        if (!t) return report(t.error());
        volume = std::move(*t);
    }
    auto gpu_cost = [&](const BenchRow& r) -> const RuntimeCost* {
        auto it = gpu.by_name.find(std::string(r.codec->name));
        return it == gpu.by_name.end() ? nullptr : &it->second;
    };
    const auto rows = benchmark_codecs(probes, dirs, selected, CodecOptions{}, o.repeats);

    if (o.json) {
        nlohmann::ordered_json j;
        j["probes"] = probes.size();
        j["directions"] = o.directions;
        j["repeats"] = o.repeats;
        if (!o.runtime_cost.empty()) j["runtime_cost_device"] = gpu.device;
        j["representations"] = nlohmann::ordered_json::array();
        for (const BenchRow& r : rows) {
            auto spread = [](const Spread& s) { return nlohmann::ordered_json{{"median", s.median}, {"min", s.min}, {"max", s.max}}; };
            j["representations"].push_back({{"name", r.codec->name},
                                             {"bytes_per_probe", r.codec->size_bytes},
                                             {"mean_rmse", r.mean_rmse},
                                             {"mean_relative_rmse", r.mean_relative_rmse},
                                             {"encode_ns_per_probe", spread(r.encode_ns)},
                                             {"decode_ns_per_probe", spread(r.decode_ns)},
                                             {"eval_ns_per_sample", spread(r.eval_ns)}});
            if (const RuntimeCost* c = gpu_cost(r))
                j["representations"].back()["runtime_cost"] = {{"spirv_instructions", c->spirv_instructions},
                                                               {"gpu_ns_per_eval", c->ns_per_eval},
                                                               {"gpu_ratio_to_sh3", c->ratio_to_sh3}};
        }
        if (!o.volume_cost.empty()) {
            nlohmann::ordered_json v;
            v["source"] = o.volume_cost;
            v["device"] = volume.device;
            v["gltf_grid"] = volume.gltf_grid;
            v["rows"] = nlohmann::ordered_json::array();
            for (const VolumeLayoutCost& r : volume.rows) {
                auto grid = [](const VolumeGridError& e) { return nlohmann::ordered_json{{"mean", e.mean}, {"p95", e.p95}}; };
                v["rows"].push_back({{"layout", r.layout},
                                     {"bytes_per_probe", r.bytes_per_probe},
                                     {"fetches", r.fetches},
                                     {"spirv_instructions", r.spirv_instructions},
                                     {"lavapipe_ns_per_sample", r.lavapipe_ns},
                                     {"ratio_to_sh3", volume_ratio_to_sh3(volume, r)},
                                     {"demo", grid(r.demo)},
                                     {"gltf", grid(r.gltf)}});
            }
            v["best_per_byte"] = nlohmann::ordered_json::array();
            for (std::size_t i : volume_best_per_byte(volume))
                v["best_per_byte"].push_back({{"max_bytes_per_probe", volume.rows[i].bytes_per_probe},
                                              {"layout", volume.rows[i].layout},
                                              {"worst_mean_error", volume.rows[i].worst_mean()}});
            j["volume_layouts"] = v;
        }
        print_json("bench", j);
    } else {
        std::printf("%zu probes, %d directions, medians of %d repeats [min-max], single thread\n", probes.size(),
                    o.directions, o.repeats);
        std::printf("%-22s %6s %10s %9s %22s %18s %16s", "representation", "bytes", "mean_rmse", "rel_rmse",
                    "encode ns/probe", "decode ns/probe", "eval ns/sample");
        if (!o.runtime_cost.empty()) std::printf(" %7s %11s %7s", "SPIR-V", "GPU ns/eval", "vs sh3");
        std::printf("\n");
        for (const BenchRow& r : rows) {
            char enc[64], dec[64], ev[64];
            std::snprintf(enc, sizeof enc, "%.0f [%.0f-%.0f]", r.encode_ns.median, r.encode_ns.min, r.encode_ns.max);
            std::snprintf(dec, sizeof dec, "%.0f [%.0f-%.0f]", r.decode_ns.median, r.decode_ns.min, r.decode_ns.max);
            std::snprintf(ev, sizeof ev, "%.1f [%.1f-%.1f]", r.eval_ns.median, r.eval_ns.min, r.eval_ns.max);
            std::printf("%-22s %6zu %10.4g %9.4f %22s %18s %16s", std::string(r.codec->name).c_str(),
                        r.codec->size_bytes, r.mean_rmse, r.mean_relative_rmse, enc, dec, ev);
            if (const RuntimeCost* c = gpu_cost(r)) std::printf(" %7d %11.3f %7.2f", c->spirv_instructions, c->ns_per_eval, c->ratio_to_sh3);
            else if (!o.runtime_cost.empty()) std::printf(" %7s %11s %7s", "-", "-", "-");
            std::printf("\n");
        }
        if (!o.runtime_cost.empty()) std::printf("GPU cost: %s (%s)\n", gpu.device.c_str(), o.runtime_cost.c_str());
        if (!o.volume_cost.empty()) {
            std::printf("\nGPU volume layouts: %s (%s); error of one trilinear sample / mean irradiance, demo grid | glTF grid\n",
                        o.volume_cost.c_str(), volume.device.c_str());
            std::printf("%-22s %7s %7s %7s %11s %7s %9s %9s %9s %9s\n", "layout", "B/probe", "fetches", "SPIR-V", "lavapipe ns",
                        "vs sh3", "demo mean", "demo p95", "glTF mean", "glTF p95");
            for (const VolumeLayoutCost& r : volume.rows)
                std::printf("%-22s %7s %7d %7s %11s %7s %9.2g %9.2g %9.2g %9.2g\n", r.layout.c_str(),
                            volume_number(r.bytes_per_probe, "%g").c_str(), r.fetches,
                            volume_number(r.spirv_instructions, "%.0f").c_str(), volume_number(r.lavapipe_ns, "%.4g").c_str(),
                            volume_number(volume_ratio_to_sh3(volume, r), "%.2f").c_str(), r.demo.mean, r.demo.p95, r.gltf.mean,
                            r.gltf.p95);
            std::printf("%s: %s\n", kBestPerByteDefinition, best_per_byte_text(volume).c_str());
        }
    }
    std::fflush(stdout);
    if (!o.html.empty()) {
        HtmlReport h;
        h.title = "zhc bench";
        h.version = ZHC_VERSION;
        h.intro = "What accuracy costs in time, per representation: bytes, mean irradiance error over " +
                  std::to_string(probes.size()) + " probes (reference: the maps integrated directly), encode, decode and "
                  "evaluation time (single thread, medians of " + std::to_string(o.repeats) + " repeats).";
        std::string in;
        for (const std::string& f : *files) in += (in.empty() ? "" : " ") + f;
        h.settings = {{"inputs", in},
                      {"representations", o.representations.empty() ? "all (" + std::to_string(selected.size()) + ")" : o.representations},
                      {"directions", std::to_string(o.directions)},
                      {"repeats", std::to_string(o.repeats)}};
        if (!o.runtime_cost.empty()) h.settings.push_back({"runtime cost", o.runtime_cost + " (" + gpu.device + ")"});
        if (!o.volume_cost.empty()) {
            h.settings.push_back({"volume cost", o.volume_cost + " (" + volume.device + ")"});
            HtmlTable t;
            t.id = "volume-layouts";
            t.title = "GPU volume layouts";
            t.intro = "One trilinear sample of a probe volume per GPU layout, from " + o.volume_cost + " (bench_volume --json, " +
                      volume.device + "): GPU bytes per probe, texture fetches (or probe decodes), SPIR-V instructions after "
                      "spirv-opt -O minus a skeleton kernel's, lavapipe ns per sample and its ratio to the packed sh3 row, and the "
                      "error of one sample against the exact trilinear SH3 volume (|E - E_ref| over the mean |E_ref|) on the demo "
                      "grid and the baked glTF scene" + (volume.gltf_grid.empty() ? "" : " (" + volume.gltf_grid + ")") +
                      "; - is not measured.";
            t.columns = {"layout", "bytes/probe", "fetches", "SPIR-V", "lavapipe ns", "vs sh3", "demo mean",
                         "demo p95", "glTF mean", "glTF p95"};
            auto cell = [](double v, const char* f) { return HtmlCell{volume_number(v, f), v}; };
            for (const VolumeLayoutCost& r : volume.rows)
                t.rows.push_back({HtmlCell{r.layout, 0}, cell(r.bytes_per_probe, "%g"), cell(r.fetches, "%.0f"),
                                  cell(r.spirv_instructions, "%.0f"), cell(r.lavapipe_ns, "%.4g"),
                                  cell(volume_ratio_to_sh3(volume, r), "%.2f"), cell(r.demo.mean, "%.2g"),
                                  cell(r.demo.p95, "%.2g"), cell(r.gltf.mean, "%.2g"), cell(r.gltf.p95, "%.2g")});
            std::string def = kBestPerByteDefinition;
            def[0] = 'B';
            t.notes = {def + ": " + best_per_byte_text(volume) + "."};
            h.tables.push_back(std::move(t));
        }
        h.summary_caption = "Means over " + std::to_string(probes.size()) + " probes; times are medians";
        std::vector<double> cost, cost_err;
        ScatterPlot by_bytes{"Error vs bytes per probe", "bytes per probe (log scale)", "mean relative irradiance rmse (log scale)", {}, {}};
        ScatterPlot by_time{"Error vs encode time", "encode time per probe, ns (log scale)", "mean relative irradiance rmse (log scale)", {}, {}};
        ScatterPlot by_runtime{"Error vs runtime cost", "SPIR-V instructions per irradiance evaluation (log scale)",
                               "mean relative irradiance rmse (log scale)", {}, {}};
        for (const BenchRow& r : rows) {
            HtmlRow row;
            row.name = std::string(r.codec->name);
            row.bytes = r.codec->size_bytes;
            row.metrics.rmse = r.mean_rmse;
            row.metrics.relative_rmse = r.mean_relative_rmse;
            row.all_metrics = false;
            row.encode_ns = r.encode_ns.median;
            row.decode_ns = r.decode_ns.median;
            row.eval_ns = r.eval_ns.median;
            if (const RuntimeCost* c = gpu_cost(r)) {
                row.spirv_instructions = c->spirv_instructions;
                row.gpu_ns = c->ns_per_eval;
            }
            h.summary.push_back(row);
            by_bytes.points.push_back(codec_point(*r.codec, double(row.bytes), r.mean_relative_rmse));
            by_time.points.push_back(codec_point(*r.codec, r.encode_ns.median, r.mean_relative_rmse));
            if (const RuntimeCost* c = gpu_cost(r)) {
                by_runtime.points.push_back({row.name, double(c->spirv_instructions), r.mean_relative_rmse});
                cost.push_back(c->spirv_instructions);
                cost_err.push_back(r.mean_relative_rmse);
            }
        }
        by_bytes.frontier = zhc_frontier(by_bytes);  // the engine layouts drawn apart (formats/report/plot.h)
        by_time.frontier = zhc_frontier(by_time);
        h.plots = {by_bytes, by_time};
        if (!by_runtime.points.empty()) {
            by_runtime.frontier = pareto_frontier(cost, cost_err);
            h.plots.push_back(by_runtime);
        }
        if (Status s = write_html_report(o.html, h); !s) return report_output(s.error());
        std::fprintf(stderr, "report: %s\n", o.html.c_str());
    }
    if (!o.no_plots) {
        std::error_code ec;
        fs::create_directories(o.plots, ec);
        ScatterPlot by_time{"Error vs encode time", "encode time per probe, ns (log scale)", "mean relative irradiance rmse (log scale)", {}, {}};
        ScatterPlot by_bytes{"Error vs bytes per probe", "bytes per probe (log scale)", "mean relative irradiance rmse (log scale)", {}, {}};
        for (const BenchRow& r : rows) {
            by_time.points.push_back(codec_point(*r.codec, std::max(r.encode_ns.median, 0.1), r.mean_relative_rmse));
            by_bytes.points.push_back(codec_point(*r.codec, double(r.codec->size_bytes), r.mean_relative_rmse));
        }
        by_time.frontier = zhc_frontier(by_time);
        by_bytes.frontier = zhc_frontier(by_bytes);
        const std::string p1 = (fs::path(o.plots) / "error_vs_encode_time.png").string();
        const std::string p2 = (fs::path(o.plots) / "error_vs_bytes.png").string();
        if (Status s = write_scatter_png(p1, by_time); !s) return report_output(s.error());
        if (Status s = write_scatter_png(p2, by_bytes); !s) return report_output(s.error());
        std::fprintf(stderr, "plots: %s, %s\n", p1.c_str(), p2.c_str());
        // The ZH3 paper's argument: error against what the runtime pays per evaluation.
        ScatterPlot by_runtime{"Error vs runtime cost", "SPIR-V instructions per irradiance evaluation (log scale)",
                               "mean relative irradiance rmse (log scale)", {}, {}};
        std::vector<double> cost, err;
        for (const BenchRow& r : rows)
            if (const RuntimeCost* c = gpu_cost(r)) {
                by_runtime.points.push_back({std::string(r.codec->name), double(c->spirv_instructions), r.mean_relative_rmse});
                cost.push_back(c->spirv_instructions);
                err.push_back(r.mean_relative_rmse);
            }
        if (!by_runtime.points.empty()) {
            by_runtime.frontier = pareto_frontier(cost, err);
            const std::string p3 = (fs::path(o.plots) / "error_vs_runtime_cost.png").string();
            if (Status s = write_scatter_png(p3, by_runtime); !s) return report_output(s.error());
            std::fprintf(stderr, "plot: %s\n", p3.c_str());
        }
    }
    return kExitOk;
}

const VerbRegistration registration(50, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("bench", "Bytes, encode/decode/evaluation time and error of every representation, with Pareto plots");
    sub->add_option("MAPS", o->inputs,
                    "environment maps or folders; none: the sample maps' folder, $ZHC_ENVMAP_DIR if set, else the one this "
                    "zhc was built with (" ZHC_SAMPLE_ENVMAP_DIR "); exit 2 when it does not exist");
    add_representations_option(sub, o->representations, RepresentationCount::kList, "default: all");
    add_json_flag(sub, o->json);
    sub->add_option("--plots", o->plots, "folder for error_vs_encode_time.png and error_vs_bytes.png")->capture_default_str();
    sub->add_flag("--no-plots", o->no_plots, "do not write plots");
    sub->add_option("--html", o->html, "also write one self-contained HTML report (table, SVG plots) to this file");
    sub->add_option("--repeats", o->repeats, "timing repeats (median and spread are reported)")->check(CLI::Range(1, 1000));
    sub->add_option("--directions", o->directions, "Fibonacci directions for error and evaluation")->check(CLI::Range(16, 1 << 20));
    sub->add_option("--runtime-cost", o->runtime_cost,
                    "GPU cost per encoding from build/bench/bench_runtime --json FILE: adds SPIR-V instructions and "
                    "lavapipe ns/eval, and error_vs_runtime_cost.png");
    sub->add_option("--volume-cost", o->volume_cost,
                    "GPU volume layouts from build/bench/bench_volume --json FILE: adds a table (bytes/probe, fetches, SPIR-V, "
                    "lavapipe ns, error on two grids) and the best layout per GPU byte to the output and the HTML report");
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_bench
}  // namespace zhc::cli
