// zhc audit FILE|FOLDER... : every representation's irradiance error, size and speed per input.
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include "formats/report/audit_inputs.h"
#include "cli.h"
#include "json_output.h"
#include "progress.h"
#include "table.h"
#include "codec/report/audit.h"
#include "formats/io/file_io.h"
#include "formats/report/html_report.h"
#include "formats/report/runtime_cost.h"
#include "codec/report/benchmark.h"

namespace zhc::cli {
namespace cmd_audit {  // one namespace per verb file: the CLI is a unity build
namespace {

namespace fs = std::filesystem;

struct Options {
    std::vector<std::string> inputs;
    std::string representations;
    bool json = false;
    std::string markdown;
    std::string images;
    std::string html;
    int directions = 2048;
    int threads = 0;
    ProgressFlags progress;
    bool no_timing = false;
    double max_rmse = -1, max_relative_rmse = -1;
    bool fail_on_negative = false;
    bool replace_non_finite = false;
    std::string part;
    std::string runtime_cost;  // bench_runtime --json output: GPU cost per encoding
};

struct FileReport {
    AuditInput input;
    std::vector<RepresentationResult> results;  // pooled over the file's probes
    std::vector<std::vector<std::size_t>> worst_probes;  // per representation: probe indices failing a gate
    SpherePictures pictures;  // --html: lit spheres of probe 0
};

std::string fmt(double v, const char* f = "%.4g") {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

std::vector<std::string> columns() {
    return {"representation", "bytes", "rmse", "rel_rmse", "max_abs", "min_irr", "neg_frac", "chroma", "enc_ns", "dec_ns"};
}
// --runtime-cost: two more columns (SPIR-V instructions, GPU ns/eval) looked up by the row's name.
void add_cost_columns(std::vector<std::vector<std::string>>& rows, const RuntimeCostTable* gpu) {
    if (!gpu || rows.empty()) return;
    rows[0].push_back("spirv");
    rows[0].push_back("gpu_ns");
    for (size_t i = 1; i < rows.size(); ++i) {
        auto it = gpu->by_name.find(rows[i][0]);
        rows[i].push_back(it == gpu->by_name.end() ? "-" : std::to_string(it->second.spirv_instructions));
        rows[i].push_back(it == gpu->by_name.end() ? "-" : fmt(it->second.ns_per_eval, "%.3g"));
    }
}

// CPU time of one irradiance evaluation through the codec's runtime path (median of 5 batches over
// the directions), on `hub`.
double eval_ns_per_sample(const Codec& codec, const Sh3Radiance& hub, const std::vector<Vec3>& dirs, const CodecOptions& copt) {
    std::vector<std::uint8_t> stored(codec.size_bytes);
    codec.encode(hub, copt, stored.data(), nullptr);
    std::vector<double> t;
    volatile float sink = 0;
    for (int b = 0; b < 5; ++b) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<Rgb> e = codec_irradiance(codec, stored.data(), copt, dirs);
        t.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() /
                    static_cast<double>(std::max<size_t>(1, dirs.size())));
        if (!e.empty()) sink = sink + e[0].r;
    }
    std::nth_element(t.begin(), t.begin() + 2, t.end());
    return t[2];
}

std::vector<std::string> row_of(const RepresentationResult& r) {
    const ErrorMetrics& m = r.metrics;
    return {std::string(r.codec->name), std::to_string(r.codec->size_bytes), fmt(m.rmse), fmt(m.relative_rmse, "%.4f"),
            fmt(m.max_abs), fmt(m.min_irradiance), fmt(m.negative_fraction, "%.4f"), fmt(m.chromaticity_error, "%.4f"),
            fmt(r.encode_ns, "%.0f"), fmt(r.decode_ns, "%.0f")};
}


nlohmann::ordered_json metrics_json(const RepresentationResult& r) {
    const ErrorMetrics& m = r.metrics;
    return {{"rmse", m.rmse},
            {"relative_rmse", m.relative_rmse},
            {"max_abs", m.max_abs},
            {"min_irradiance", m.min_irradiance},
            {"negative_fraction", m.negative_fraction},
            {"chromaticity_error", m.chromaticity_error},
            {"bytes_per_probe", r.codec->size_bytes},
            {"encode_ns", r.encode_ns},
            {"decode_ns", r.decode_ns},
            {"clamped_ratios", r.stats.clamped_ratios},
            {"dering_clamped", r.stats.dering_clamped}};
}

HtmlRow html_row(const RepresentationResult& r, bool timed) {
    HtmlRow h;
    h.name = std::string(r.codec->name);
    h.bytes = r.codec->size_bytes;
    h.metrics = r.metrics;
    h.encode_ns = timed ? r.encode_ns : -1;
    h.decode_ns = timed ? r.decode_ns : -1;
    return h;
}

HtmlReport html_of(const Options& o, const std::vector<FileReport>& reports,
                   const std::vector<RepresentationResult>& aggregate, const std::vector<std::string>& failures,
                   const RuntimeCostTable* gpu, const std::vector<double>& eval_ns) {
    HtmlReport h;
    h.title = "zhc audit";
    h.version = ZHC_VERSION;
    h.intro = "Irradiance error, size and speed of every representation. Reference: environment maps are integrated "
              "directly (box-downsampled to at least 512x256); probe files use their probes' SH3 irradiance. Errors at " +
              std::to_string(o.directions) + " Fibonacci-lattice directions per probe.";
    std::string inputs;
    for (const std::string& i : o.inputs) inputs += (inputs.empty() ? "" : " ") + i;
    h.settings = {{"inputs", inputs},
                  {"files audited", std::to_string(reports.size())},
                  {"representations", o.representations.empty() ? "all (" + std::to_string(aggregate.size()) + ")" : o.representations},
                  {"directions", std::to_string(o.directions)},
                  {"timing", o.no_timing ? "off (--no-timing)" : "on: median of 5 batches, first 8 probes of each file"}};
    if (!o.part.empty()) h.settings.push_back({"EXR part", o.part});
    if (o.replace_non_finite) h.settings.push_back({"non-finite pixels", "replaced by 0"});
    const bool timed = !o.no_timing;
    h.summary_caption = reports.size() > 1 ? "Aggregate over " + std::to_string(reports.size()) +
                                                 " files (mean rmse, relative rmse, fractions and times; worst max abs and min irradiance)"
                                           : reports[0].input.path;
    for (size_t c = 0; c < aggregate.size(); ++c) {
        h.summary.push_back(html_row(aggregate[c], timed));
        if (c < eval_ns.size()) h.summary.back().eval_ns = eval_ns[c];
    }
    if (timed) h.settings.push_back({"eval ns/sample", "CPU, one irradiance evaluation through the runtime path, median of 5 batches over the directions, probe 0 of the first file"});
    h.gates_configured = o.max_rmse >= 0 || o.max_relative_rmse >= 0 || o.fail_on_negative;
    if (o.max_rmse >= 0) h.gates.push_back("rmse <= " + fmt(o.max_rmse) + " on every probe");
    if (o.max_relative_rmse >= 0) h.gates.push_back("relative rmse <= " + fmt(o.max_relative_rmse) + " on every probe");
    if (o.fail_on_negative) h.gates.push_back("no negative irradiance on any probe");
    h.gate_failures = failures;
    // Error against bytes per probe (the summary's relative rmse).
    ScatterPlot plot{"Error vs bytes per probe", "bytes per probe (log scale)", "relative irradiance rmse (log scale)", {}, {}};
    std::vector<double> b, e;
    for (const RepresentationResult& r : aggregate) {
        plot.points.push_back({std::string(r.codec->name), double(r.codec->size_bytes), r.metrics.relative_rmse});
        b.push_back(double(r.codec->size_bytes));
        e.push_back(r.metrics.relative_rmse);
    }
    plot.frontier = pareto_frontier(b, e);
    h.plots.push_back(plot);
    for (const FileReport& fr : reports) {
        HtmlInputSection s;
        s.title = fr.input.path;
        s.description = fr.input.description + (fr.input.probes.size() > 1 ? "; pictures show probe 0" : "");
        for (const RepresentationResult& r : fr.results) s.rows.push_back(html_row(r, timed));
        s.pictures = fr.pictures;
        h.inputs.push_back(std::move(s));
    }
    apply_runtime_cost(h, gpu, o.runtime_cost);
    return h;
}

int run(const Options& o) {
    auto chosen = select_codecs(o.representations);
    if (!chosen) return report(chosen.error());
    const std::vector<const Codec*>& selected = *chosen;
    RuntimeCostTable gpu_table;
    if (!o.runtime_cost.empty()) {
        auto t = read_runtime_cost(o.runtime_cost);
        if (!t) return report(t.error());
        gpu_table = std::move(*t);
    }
    const RuntimeCostTable* gpu = o.runtime_cost.empty() ? nullptr : &gpu_table;
    auto files = expand_audit_inputs(o.inputs);
    if (!files) return report(files.error());
    if (files->empty()) return report(make_error(ErrorCode::kInvalidArgument, "no audit inputs found"));

    const int threads = resolve_threads(o.threads);
    const std::vector<Vec3> dirs = fibonacci_sphere(o.directions);
    Progress progress("zhc audit", "files", o.progress);
    CodecOptions copt;
    AuditLoadOptions lopt;
    lopt.threads = threads;
    lopt.replace_non_finite = o.replace_non_finite;
    lopt.part = o.part;

    std::vector<FileReport> reports;
    for (size_t fi = 0; fi < files->size(); ++fi) {
        const std::string& path = (*files)[fi];
        auto input = load_audit_input(path, dirs, lopt);
        if (!input) return report(input.error());
        FileReport fr;
        fr.input = std::move(input).value();
        std::vector<MetricsAccumulator> acc(selected.size());
        std::vector<double> enc(selected.size()), dec(selected.size());
        std::vector<EncodeStats> stats(selected.size());
        fr.worst_probes.resize(selected.size());
        const size_t probes = fr.input.probes.size();
        const size_t timed = std::min<size_t>(probes, 8);  // time a few probes, not all of a big grid
        for (size_t p = 0; p < probes; ++p) {
            const std::vector<Rgb> ref = fr.input.reference_for(p, dirs);
            std::vector<std::vector<Rgb>> rec;
            auto res = audit_probe(fr.input.probes[p], ref, dirs, selected, copt, !o.no_timing && p < timed, &rec);
            for (size_t c = 0; c < selected.size(); ++c) {
                acc[c].add(rec[c], ref);
                if (p < timed) {
                    enc[c] += res[c].encode_ns / static_cast<double>(timed);
                    dec[c] += res[c].decode_ns / static_cast<double>(timed);
                }
                stats[c].clamped_ratios += res[c].stats.clamped_ratios;
                stats[c].dering_clamped = stats[c].dering_clamped || res[c].stats.dering_clamped;
                const ErrorMetrics& m = res[c].metrics;
                const bool fails = (o.max_rmse >= 0 && m.rmse > o.max_rmse) ||
                                   (o.max_relative_rmse >= 0 && m.relative_rmse > o.max_relative_rmse) ||
                                   (o.fail_on_negative && m.min_irradiance < 0);
                if (fails) fr.worst_probes[c].push_back(p);
            }
        }
        for (size_t c = 0; c < selected.size(); ++c) {
            RepresentationResult r;
            r.codec = selected[c];
            r.metrics = acc[c].result();
            r.encode_ns = enc[c];
            r.decode_ns = dec[c];
            r.stats = stats[c];
            fr.results.push_back(r);
        }
        if (!o.images.empty()) {
            if (Status s = write_audit_images(o.images, fr.input, dirs, selected, copt); !s) return report_output(s.error());
        }
        if (!o.html.empty()) fr.pictures = render_sphere_pictures(fr.input, selected, copt, 96);
        reports.push_back(std::move(fr));
        progress.update(fi + 1, files->size());
    }

    // Aggregate over files: mean RMSE and relative RMSE, worst max_abs and minimum, mean fractions.
    std::vector<RepresentationResult> aggregate(selected.size());
    for (size_t c = 0; c < selected.size(); ++c) {
        RepresentationResult& a = aggregate[c];
        a.codec = selected[c];
        a.metrics.min_irradiance = reports[0].results[c].metrics.min_irradiance;
        for (const FileReport& fr : reports) {
            const RepresentationResult& r = fr.results[c];
            const double n = static_cast<double>(reports.size());
            a.metrics.rmse += r.metrics.rmse / n;
            a.metrics.relative_rmse += r.metrics.relative_rmse / n;
            a.metrics.max_abs = std::max(a.metrics.max_abs, r.metrics.max_abs);
            a.metrics.min_irradiance = std::min(a.metrics.min_irradiance, r.metrics.min_irradiance);
            a.metrics.negative_fraction += r.metrics.negative_fraction / n;
            a.metrics.chromaticity_error += r.metrics.chromaticity_error / n;
            a.encode_ns += r.encode_ns / n;
            a.decode_ns += r.decode_ns / n;
            a.stats.clamped_ratios += r.stats.clamped_ratios;
            a.stats.dering_clamped = a.stats.dering_clamped || r.stats.dering_clamped;
        }
    }

    // Gates.
    std::vector<std::string> failures;
    for (const FileReport& fr : reports)
        for (size_t c = 0; c < selected.size(); ++c) {
            const auto& bad = fr.worst_probes[c];
            if (bad.empty()) continue;
            std::string probes;
            for (size_t i = 0; i < bad.size() && i < 10; ++i) probes += (i ? "," : "") + std::to_string(bad[i]);
            if (bad.size() > 10) probes += ",... (" + std::to_string(bad.size()) + " probes)";
            const ErrorMetrics& m = fr.results[c].metrics;
            failures.push_back(fr.input.path + ": " + std::string(selected[c]->name) + " fails a gate (rmse " +
                               fmt(m.rmse) + ", relative_rmse " + fmt(m.relative_rmse) + ", min_irradiance " +
                               fmt(m.min_irradiance) + ") at probe " + probes);
        }

    if (o.json) {
        nlohmann::ordered_json j;
        j["directions"] = o.directions;
        j["reference"] = "environment maps: direct integration of the map (box-downsampled to >= 512x256); "
                         "probe files: the probes' SH3 irradiance";
        j["files"] = nlohmann::ordered_json::array();
        for (const FileReport& fr : reports) {
            nlohmann::ordered_json f;
            f["path"] = fr.input.path;
            f["kind"] = fr.input.kind;
            f["probes"] = fr.input.probes.size();
            nlohmann::ordered_json reps = nlohmann::ordered_json::object();
            for (const RepresentationResult& r : fr.results) reps[std::string(r.codec->name)] = metrics_json(r);
            f["representations"] = reps;
            j["files"].push_back(f);
        }
        nlohmann::ordered_json agg = nlohmann::ordered_json::object();
        for (const RepresentationResult& r : aggregate) agg[std::string(r.codec->name)] = metrics_json(r);
        j["aggregate"] = {{"files", reports.size()}, {"representations", agg}};
        j["gates"] = {{"passed", failures.empty()}, {"failures", failures}};
        print_json("audit", j);
    } else {
        for (const FileReport& fr : reports) {
            std::cout << fr.input.path << " (" << fr.input.description << ", " << o.directions << " directions)\n";
            std::vector<std::vector<std::string>> rows{columns()};
            for (const RepresentationResult& r : fr.results) rows.push_back(row_of(r));
            add_cost_columns(rows, gpu);
            print_table(std::cout, rows, false);
            std::cout << "\n";
        }
        if (reports.size() > 1) {
            std::cout << "aggregate over " << reports.size() << " files (mean rmse, rel_rmse, fractions, times; worst max_abs, min_irr)\n";
            std::vector<std::vector<std::string>> rows{columns()};
            for (const RepresentationResult& r : aggregate) rows.push_back(row_of(r));
            add_cost_columns(rows, gpu);
            print_table(std::cout, rows, false);
        }
    }
    if (!o.markdown.empty()) {
        std::ostringstream md;
        md << "# zhc audit\n\nIrradiance error against the reference at " << o.directions
           << " directions (environment maps: direct integration of the map; probe files: their SH3).\n\n";
        for (const FileReport& fr : reports) {
            md << "## " << fr.input.path << "\n\n" << fr.input.description << "\n\n";
            std::vector<std::vector<std::string>> rows{columns()};
            for (const RepresentationResult& r : fr.results) rows.push_back(row_of(r));
            add_cost_columns(rows, gpu);
            print_table(md, rows, true);
            md << "\n";
        }
        md << "## Aggregate over " << reports.size() << " files\n\n";
        std::vector<std::vector<std::string>> rows{columns()};
        for (const RepresentationResult& r : aggregate) rows.push_back(row_of(r));
        add_cost_columns(rows, gpu);
        print_table(md, rows, true);
        const std::string text = md.str();
        if (Status s = write_file_atomic(o.markdown, std::vector<std::uint8_t>(text.begin(), text.end())); !s)
            return report_output(s.error());
    }
    if (!o.html.empty()) {
        std::vector<double> eval_ns;  // CPU evaluation cost: cheap, measured only when timing is on
        if (!o.no_timing && !reports[0].input.probes.empty())
            for (const Codec* c : selected) eval_ns.push_back(eval_ns_per_sample(*c, reports[0].input.probes[0], dirs, copt));
        if (Status s = write_html_report(o.html, html_of(o, reports, aggregate, failures, gpu, eval_ns)); !s)
            return report_output(s.error());
        std::fprintf(stderr, "report: %s\n", o.html.c_str());
    }
    if (!failures.empty()) {
        for (const std::string& f : failures) std::fprintf(stderr, "zhc: gate failed: %s\n", f.c_str());
        return kExitGateFailed;
    }
    return kExitOk;
}

const VerbRegistration registration(40, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("audit", "Irradiance error, size and speed of every representation on your lighting");
    sub->add_option("INPUTS", o->inputs, "environment maps (.exr, .hdr), probe files, or folders of them")->required();
    add_representations_option(sub, o->representations, RepresentationCount::kList, "default: all");
    add_json_flag(sub, o->json, "files, aggregate, gates");
    sub->add_option("--markdown", o->markdown, "also write the tables as Markdown to this file");
    sub->add_option("--html", o->html, "also write one self-contained HTML report (tables, gates, lit spheres, plots) to this file");
    sub->add_option("--runtime-cost", o->runtime_cost,
                    "GPU cost per encoding from build/bench/bench_runtime --json FILE: SPIR-V instructions and lavapipe ns/eval "
                    "columns (text, Markdown, HTML) and an error-vs-runtime-cost plot in the HTML report");
    sub->add_option("--images", o->images, "write irradiance/error PNGs per input into this folder");
    sub->add_option("--directions", o->directions, "number of Fibonacci-lattice directions")->check(CLI::Range(16, 1 << 20));
    add_threads_option(sub, o->threads, "results do not depend on it");
    add_progress_flags(sub, o->progress);
    sub->add_flag("--no-timing", o->no_timing, "skip encode/decode timing (outputs become byte-identical across runs)");
    sub->add_option("--max-rmse", o->max_rmse, "gate: fail (exit 8) if any representation's RMSE exceeds this");
    sub->add_option("--max-relative-rmse", o->max_relative_rmse, "gate: fail (exit 8) if any relative RMSE exceeds this");
    sub->add_flag("--fail-on-negative", o->fail_on_negative, "gate: fail (exit 8) if any reconstruction goes negative");
    add_envmap_read_options(sub, &o->replace_non_finite, o->part);
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_audit
}  // namespace zhc::cli
