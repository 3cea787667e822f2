// zhc audit FILE|FOLDER... : every representation's irradiance error, size and speed per input.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "formats/report/audit_inputs.h"
#include "choice_output.h"
#include "cli.h"
#include "json_output.h"
#include "progress.h"
#include "table.h"
#include "codec/audit/audit_run.h"
#include "codec/audit/choice.h"
#include "formats/io/file_io.h"
#include "formats/report/html_report.h"
#include "formats/report/runtime_cost.h"
#include "codec/audit/benchmark.h"

namespace zhc::cli {
namespace cmd_audit {  // one namespace per verb file: the CLI is a unity build
namespace {

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
    LatLongConvention latlong = LatLongConvention::kOpenExr;
    LdrDecoding ldr;
    std::string runtime_cost;  // bench_runtime --json output: GPU cost per encoding
    std::string paths_base;    // --paths-relative-to
    // The choice section (codec/audit/choice.h): extra budgets and the constraints.
    std::vector<std::size_t> budgets;
    std::vector<std::string> require;  // "nonnegative"
    long long max_instructions = -1;
    double max_encode_us = -1;
};

std::string fmt(double v, const char* f = "%.4g") {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

// The table columns; the timing columns only when timing is on (--no-timing leaves them out).
std::vector<std::string> columns(bool timed) {
    std::vector<std::string> c{"representation", "bytes", "rmse", "rel_rmse", "max_abs", "min_irr", "neg_frac", "chroma"};
    if (timed) c.insert(c.end(), {"enc_ns", "dec_ns"});
    return c;
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

std::vector<std::string> row_of(const RepresentationResult& r, bool timed) {
    const ErrorMetrics& m = r.metrics;
    std::vector<std::string> row{std::string(r.codec->name), std::to_string(r.codec->size_bytes), fmt(m.rmse),
                                 fmt(m.relative_rmse, "%.4f"), fmt(m.max_abs), fmt(m.min_irradiance),
                                 fmt(m.negative_fraction, "%.4f"), fmt(m.chromaticity_error, "%.4f")};
    if (timed) row.insert(row.end(), {fmt(r.encode_ns, "%.0f"), fmt(r.decode_ns, "%.0f")});
    return row;
}


// encode_ns and decode_ns only when timing is on (--no-timing: absent, not 0).
nlohmann::ordered_json metrics_json(const RepresentationResult& r, bool timed) {
    const ErrorMetrics& m = r.metrics;
    nlohmann::ordered_json j{{"rmse", m.rmse},
                             {"relative_rmse", m.relative_rmse},
                             {"max_abs", m.max_abs},
                             {"min_irradiance", m.min_irradiance},
                             {"negative_fraction", m.negative_fraction},
                             {"chromaticity_error", m.chromaticity_error},
                             {"bytes_per_probe", r.codec->size_bytes}};
    if (timed) {
        j["encode_ns"] = r.encode_ns;
        j["decode_ns"] = r.decode_ns;
    }
    j["clamped_ratios"] = r.stats.clamped_ratios;
    j["dering_clamped"] = r.stats.dering_clamped;
    return j;
}

// The gate failure in one line: per configured gate that some probe breaks, how many (input,
// representation) pairs break it, and the worst probe's value against the threshold and where.
std::string gate_summary(const AuditGates& gates, const AuditRun& run) {
    struct Worst {
        std::size_t pairs = 0;
        double value = 0;
        std::string where;
    };
    Worst rmse, relative, negative;
    std::size_t pairs = 0, failing = 0;
    auto note = [](Worst& w, bool breaks, double v, bool worse, const std::string& path, const Codec* c, std::size_t probe) {
        if (!breaks) return;
        if (w.pairs++ == 0 || worse) {
            w.value = v;
            w.where = path + ": " + std::string(c->name) + " at probe " + std::to_string(probe);
        }
    };
    for (const InputAudit& in : run.inputs)
        for (std::size_t c = 0; c < in.results.size() && c < in.extremes.size(); ++c) {
            ++pairs;
            failing += c < in.failing_probes.size() && !in.failing_probes[c].empty();
            const InputAudit::Extremes& x = in.extremes[c];
            const Codec* codec = in.results[c].codec;
            note(rmse, gates.max_rmse >= 0 && x.rmse > gates.max_rmse, x.rmse, x.rmse > rmse.value, in.path, codec, x.rmse_probe);
            note(relative, gates.max_relative_rmse >= 0 && x.relative_rmse > gates.max_relative_rmse, x.relative_rmse,
                 x.relative_rmse > relative.value, in.path, codec, x.relative_rmse_probe);
            note(negative, gates.fail_on_negative && x.min_irradiance < 0, x.min_irradiance, x.min_irradiance < negative.value,
                 in.path, codec, x.min_irradiance_probe);
        }
    std::string s = std::to_string(failing) + " of " + std::to_string(pairs) + " (input, representation) pairs fail";
    auto add = [&](const Worst& w, const std::string& gate, const std::string& what, const std::string& threshold) {
        if (w.pairs == 0) return;
        s += "; " + gate + ": " + std::to_string(w.pairs) + " pairs, worst " + what + " " + fmt(w.value) + " vs " + threshold +
             " (" + w.where + ")";
    };
    add(rmse, "--max-rmse", "rmse", fmt(gates.max_rmse));
    add(relative, "--max-relative-rmse", "relative rmse", fmt(gates.max_relative_rmse));
    add(negative, "--fail-on-negative", "min irradiance", "0");
    return s;
}

// The "engine_layouts" array of the audit JSON (docs/schema/audit.schema.json): each audited engine
// layout beside zhc's best representation at its size (codec/audit/choice.h).
nlohmann::ordered_json engine_json(const std::vector<EngineComparison>& rows) {
    using J = nlohmann::ordered_json;
    J out = J::array();
    for (const EngineComparison& k : rows) {
        J j{{"representation", std::string(k.engine->name)},
            {"engine", std::string(k.engine->traits.engine)},
            {"bytes_per_probe", k.engine->size_bytes},
            {"relative_rmse", k.error},
            {"max_negative_fraction", k.max_negative_fraction}};
        j["zhc_best"] = k.zhc ? J{{"representation", std::string(k.zhc->name)},
                                  {"bytes_per_probe", k.zhc->size_bytes},
                                  {"relative_rmse", k.zhc_error},
                                  {"max_negative_fraction", k.zhc_max_negative_fraction}}
                              : J(nullptr);
        out.push_back(j);
    }
    return out;
}

// The same as a section of the HTML report.
HtmlTable engine_html(const std::vector<EngineComparison>& rows) {
    HtmlTable t;
    t.id = "engine-layouts";
    t.title = "Engine layouts";
    t.intro = engine_intro();
    const std::vector<std::vector<std::string>> cells = engine_table(rows);
    t.columns = cells[0];
    for (std::size_t i = 1; i < cells.size(); ++i) {
        const EngineComparison& k = rows[i - 1];
        std::vector<HtmlCell> row;
        for (const std::string& c : cells[i]) row.push_back({c, 0});
        row[2].sort = double(k.engine->size_bytes);
        row[3].sort = k.error;
        row[4].sort = k.max_negative_fraction;
        row[6].sort = k.zhc ? double(k.zhc->size_bytes) : -1;
        row[7].sort = k.zhc ? k.zhc_error : -1;
        row[8].sort = k.zhc ? k.zhc_max_negative_fraction : -1;
        row[9].sort = k.zhc && k.zhc_error > 0 ? k.error / k.zhc_error : 0;
        t.rows.push_back(std::move(row));
    }
    t.notes = {"The plot \"Error vs bytes per probe\" below draws the engine layouts as orange squares against zhc's "
               "Pareto frontier."};
    return t;
}

// The failures' detail for the text report: the first 10 lines, then how many more.
constexpr std::size_t kGateDetailLines = 10;

HtmlRow html_row(const RepresentationResult& r, bool timed) {
    HtmlRow h;
    h.name = std::string(r.codec->name);
    h.bytes = r.codec->size_bytes;
    h.metrics = r.metrics;
    h.encode_ns = timed ? r.encode_ns : -1;
    h.decode_ns = timed ? r.decode_ns : -1;
    return h;
}

HtmlReport html_of(const Options& o, const AuditGates& gates, const AuditedFiles& audited,
                   const std::vector<SpherePictures>& pictures, const RuntimeCostTable* gpu,
                   const std::vector<double>& eval_ns, const ChoiceResult& choice,
                   const std::vector<EngineComparison>& engines) {
    const std::vector<AuditInput>& inputs = audited.inputs;
    const std::vector<RepresentationResult>& aggregate = audited.run.aggregate;
    HtmlReport h;
    h.title = "zhc audit";
    h.version = ZHC_VERSION;
    h.intro = "Irradiance error, size and speed of every representation. Reference: environment maps are integrated "
              "over each pixel's exact footprint (box-downsampled to at least 512x256); probe files use their probes' SH3 irradiance. Errors at " +
              std::to_string(o.directions) + " Fibonacci-lattice directions per probe.";
    std::string given;
    for (const std::string& i : o.inputs) given += (given.empty() ? "" : " ") + shown_path(i, o.paths_base);
    h.settings = {{"inputs", given},
                  {"files audited", std::to_string(inputs.size())},
                  {"representations", o.representations.empty() ? "all (" + std::to_string(aggregate.size()) + ")" : o.representations},
                  {"directions", std::to_string(o.directions)},
                  {"timing", o.no_timing ? "off (--no-timing)" : "on: median of 5 batches, first 8 probes of each file"}};
    if (!o.part.empty()) h.settings.push_back({"EXR part", o.part});
    if (o.replace_non_finite) h.settings.push_back({"non-finite pixels", "replaced by 0"});
    h.settings.push_back({"lat-long orientation", latlong_convention_name(o.latlong)});
    const bool timed = !o.no_timing;
    h.summary_caption = inputs.size() > 1 ? "Aggregate over " + std::to_string(inputs.size()) +
                                                " files (mean rmse, relative rmse, fractions and times; worst max abs and min irradiance)"
                                          : inputs[0].path;
    for (size_t c = 0; c < aggregate.size(); ++c) {
        h.summary.push_back(html_row(aggregate[c], timed));
        if (c < eval_ns.size()) h.summary.back().eval_ns = eval_ns[c];
    }
    if (timed) h.settings.push_back({"eval ns/sample", "CPU, one irradiance evaluation through the runtime path, median of 5 batches over the directions, probe 0 of the first file"});
    h.gates_configured = gates.configured();
    h.gates = gates.descriptions();
    h.gate_failures = audited.run.gates.messages();
    // Error against bytes per probe (the summary's relative rmse): zhc's Pareto frontier, the engine
    // layouts drawn apart.
    ScatterPlot plot{"Error vs bytes per probe", "bytes per probe (log scale)", "relative irradiance rmse (log scale)", {}, {}};
    for (const RepresentationResult& r : aggregate)
        plot.points.push_back(codec_point(*r.codec, double(r.codec->size_bytes), r.metrics.relative_rmse));
    plot.frontier = zhc_frontier(plot);
    h.plots.push_back(plot);
    for (size_t i = 0; i < inputs.size(); ++i) {
        HtmlInputSection s;
        s.title = inputs[i].path;
        s.description = inputs[i].description + (inputs[i].probes.size() > 1 ? "; pictures show probe 0" : "");
        for (const RepresentationResult& r : audited.run.inputs[i].results) s.rows.push_back(html_row(r, timed));
        if (i < pictures.size()) s.pictures = pictures[i];
        h.inputs.push_back(std::move(s));
    }
    apply_runtime_cost(h, gpu, o.runtime_cost);
    // The choice right after the summary and gates (an HTML report is read from the top; its input
    // sections with pictures are long); text, Markdown and JSON end with it.
    h.tables.push_back(choice_html(choice));
    if (!engines.empty()) h.tables.push_back(engine_html(engines));
    return h;
}

int run(const Options& o) {
    // The choice's constraints need what they test: a runtime cost table, encode timing.
    if (o.max_instructions >= 0 && o.runtime_cost.empty()) {
        std::fprintf(stderr, "zhc: error: --max-instructions: needs --runtime-cost FILE (bench_runtime --json) for the "
                             "SPIR-V instruction counts\n");
        return kExitUsage;
    }
    if (o.max_encode_us >= 0 && o.no_timing) {
        std::fprintf(stderr, "zhc: error: --max-encode-us: needs the encode timing that --no-timing turns off\n");
        return kExitUsage;
    }
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
    std::vector<std::string> skipped;
    auto files = expand_audit_inputs(o.inputs, &skipped);
    if (!files) return report(files.error());
    if (files->empty())
        return report(make_error(ErrorCode::kInvalidArgument,
                                 "no audit inputs found" + (skipped.empty() ? std::string()
                                                                            : " (skipped " + skipped[0] +
                                                                                  (skipped.size() > 1 ? ", and " + std::to_string(skipped.size() - 1) + " more" : "") + ")")));
    // A folder's JSON files that are not probe lists (a scene beside its maps): one note each.
    for (const std::string& n : skipped) std::fprintf(stderr, "zhc: note: skipped %s\n", n.c_str());
    for (const auto& [option, path] : {std::pair<std::string, std::string>{"--markdown", o.markdown}, {"--html", o.html}})
        if (!path.empty())
            if (int rc = refuse_output_over_input(option, path, *files); rc != kExitOk) return rc;
    const bool timed = !o.no_timing;

    const std::vector<Vec3> dirs = fibonacci_sphere(o.directions);
    Progress progress("zhc audit", "files", o.progress);
    AuditOptions aopt;
    aopt.timing = !o.no_timing;
    aopt.threads = resolve_threads(o.threads);
    aopt.gates = {o.max_rmse, o.max_relative_rmse, o.fail_on_negative};
    AuditLoadOptions lopt;
    lopt.threads = aopt.threads;
    lopt.replace_non_finite = o.replace_non_finite;
    lopt.part = o.part;
    lopt.latlong = o.latlong;
    lopt.ldr = o.ldr;
    // After each input: its pictures (--images, --html) and the progress.
    std::vector<SpherePictures> pictures;
    bool output_failed = false;
    auto after_input = [&](const AuditInput& input, const InputAudit&, size_t index) -> Status {
        if (!o.images.empty()) {
            Status s = write_audit_images(o.images, input, dirs, selected, aopt.codec_options);
            output_failed = !s;
            if (!s) return s;
        }
        if (!o.html.empty()) pictures.push_back(render_sphere_pictures(input, selected, aopt.codec_options, 96));
        progress.update(index + 1, files->size());
        return Ok{};
    };
    auto audited = audit_files(*files, dirs, selected, aopt, lopt, after_input);
    if (!audited) return output_failed ? report_output(audited.error()) : report(audited.error());
    // Every report names the inputs as --paths-relative-to says (gate messages included).
    for (AuditInput& in : audited->inputs) in.path = shown_path(in.path, o.paths_base);
    for (InputAudit& in : audited->run.inputs) in.path = shown_path(in.path, o.paths_base);
    for (auto& f : audited->run.gates.failures) f.path = shown_path(f.path, o.paths_base);
    const std::vector<AuditInput>& inputs = audited->inputs;
    const AuditRun& result = audited->run;
    const std::vector<std::string> failures = result.gates.messages();
    ChoiceConstraints constraints;
    constraints.nonnegative = std::find(o.require.begin(), o.require.end(), "nonnegative") != o.require.end();
    constraints.max_instructions = o.max_instructions;
    constraints.max_encode_us = o.max_encode_us;
    const ChoiceResult choice = choose_representations(result.inputs, result.aggregate, choice_instructions(result.aggregate, gpu),
                                                       timed, constraints, choice_budgets(o.budgets));
    const std::vector<EngineComparison> engines = compare_engine_layouts(result.inputs, result.aggregate);

    if (o.json) {
        nlohmann::ordered_json j;
        j["directions"] = o.directions;
        j["reference"] = "environment maps: the map's irradiance over each pixel's exact footprint (box-downsampled to >= 512x256); "
                         "probe files: the probes' SH3 irradiance";
        j["files"] = nlohmann::ordered_json::array();
        for (size_t i = 0; i < inputs.size(); ++i) {
            nlohmann::ordered_json f;
            f["path"] = inputs[i].path;
            f["kind"] = inputs[i].kind;
            f["probes"] = inputs[i].probes.size();
            f["reference"] = inputs[i].reference;
            nlohmann::ordered_json reps = nlohmann::ordered_json::object();
            for (const RepresentationResult& r : result.inputs[i].results) reps[std::string(r.codec->name)] = metrics_json(r, timed);
            f["representations"] = reps;
            j["files"].push_back(f);
        }
        nlohmann::ordered_json agg = nlohmann::ordered_json::object();
        for (const RepresentationResult& r : result.aggregate) agg[std::string(r.codec->name)] = metrics_json(r, timed);
        j["aggregate"] = {{"files", inputs.size()}, {"representations", agg}};
        j["gates"] = {{"passed", failures.empty()}, {"failures", failures}};
        if (!failures.empty()) j["gates"]["summary"] = gate_summary(aopt.gates, result);
        j["choice"] = choice_json(choice);
        j["engine_layouts"] = engine_json(engines);
        print_json("audit", j);
    } else {
        for (size_t i = 0; i < inputs.size(); ++i) {
            std::cout << inputs[i].path << " (" << inputs[i].description << ", " << o.directions << " directions)\n";
            std::cout << "reference: " << inputs[i].reference << "\n";
            std::vector<std::vector<std::string>> rows{columns(timed)};
            for (const RepresentationResult& r : result.inputs[i].results) rows.push_back(row_of(r, timed));
            add_cost_columns(rows, gpu);
            print_table(std::cout, rows, false);
            std::cout << "\n";
        }
        if (inputs.size() > 1) {
            std::cout << "aggregate over " << inputs.size() << " files (mean rmse, rel_rmse, fractions, times; worst max_abs, min_irr)\n";
            std::vector<std::vector<std::string>> rows{columns(timed)};
            for (const RepresentationResult& r : result.aggregate) rows.push_back(row_of(r, timed));
            add_cost_columns(rows, gpu);
            print_table(std::cout, rows, false);
        }
        std::cout << "\nchoice: " << choice_intro(choice) << "\n";
        print_table(std::cout, choice_table(choice), false);
        for (const std::string& n : choice_notes(choice)) std::cout << "  " << n << "\n";
        if (!engines.empty()) {
            std::cout << "\nengine layouts: " << engine_intro() << "\n";
            print_table(std::cout, engine_table(engines), false);
        }
    }
    if (!o.markdown.empty()) {
        std::ostringstream md;
        md << "# zhc audit\n\nIrradiance error against the reference at " << o.directions
           << " directions (environment maps: the map's irradiance over each pixel's exact footprint; probe files: their SH3).\n\n";
        for (size_t i = 0; i < inputs.size(); ++i) {
            md << "## " << inputs[i].path << "\n\n" << inputs[i].description << "\n\nReference: " << inputs[i].reference << ".\n\n";
            std::vector<std::vector<std::string>> rows{columns(timed)};
            for (const RepresentationResult& r : result.inputs[i].results) rows.push_back(row_of(r, timed));
            add_cost_columns(rows, gpu);
            print_table(md, rows, true);
            md << "\n";
        }
        md << "## Aggregate over " << inputs.size() << " files\n\n";
        std::vector<std::vector<std::string>> rows{columns(timed)};
        for (const RepresentationResult& r : result.aggregate) rows.push_back(row_of(r, timed));
        add_cost_columns(rows, gpu);
        print_table(md, rows, true);
        md << "\n## Choice\n\n" << choice_intro(choice) << "\n\n";
        print_table(md, choice_table(choice), true);
        const std::vector<std::string> notes = choice_notes(choice);
        if (!notes.empty()) md << "\n";
        for (const std::string& n : notes) md << "- " << n << "\n";
        if (!engines.empty()) {
            md << "\n## Engine layouts\n\n" << engine_intro() << "\n\n";
            print_table(md, engine_table(engines), true);
        }
        const std::string text = md.str();
        if (Status s = write_file_atomic(o.markdown, std::vector<std::uint8_t>(text.begin(), text.end())); !s)
            return report_output(s.error());
    }
    if (!o.html.empty()) {
        std::vector<double> eval_ns;  // CPU evaluation cost: cheap, measured only when timing is on
        if (!o.no_timing && !inputs[0].probes.empty())
            for (const Codec* c : selected) eval_ns.push_back(eval_ns_per_sample(*c, inputs[0].probes[0], dirs, aopt.codec_options));
        if (Status s = write_html_report(o.html, html_of(o, aopt.gates, *audited, pictures, gpu, eval_ns, choice, engines)); !s)
            return report_output(s.error());
        std::fprintf(stderr, "report: %s\n", o.html.c_str());
    }
    if (!failures.empty()) {
        // The detail (bounded) after the text report; JSON holds every failure in gates.failures.
        // stderr gets one line: which gates, how many failures, the worst value and where.
        if (!o.json) {
            std::printf("\ngate failures (%zu):\n", failures.size());
            for (std::size_t i = 0; i < failures.size() && i < kGateDetailLines; ++i) std::printf("  %s\n", failures[i].c_str());
            if (failures.size() > kGateDetailLines)
                std::printf("  ... %zu more (all of them: --json, gates.failures)\n", failures.size() - kGateDetailLines);
        }
        std::fprintf(stderr, "zhc: gate failed: %s\n", gate_summary(aopt.gates, result).c_str());
        return kExitGateFailed;
    }
    return kExitOk;
}

const VerbRegistration registration(40, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("audit", "Irradiance error, size and speed of every representation on your lighting");
    sub->add_option("INPUTS", o->inputs,
                    "environment maps (.exr, .hdr, KTX2 / KTX 1 / DDS cube maps), probe files, or folders of them (their "
                    ".exr, .hdr, .zhp and .json files; a JSON file that is not a probe list, such as a scene, is skipped "
                    "with a note)")
        ->required();
    add_representations_option(sub, o->representations, RepresentationCount::kList, "default: all");
    add_json_flag(sub, o->json, "files, aggregate, gates, choice, engine_layouts");
    sub->add_option("--markdown", o->markdown, "also write the tables as Markdown to this file");
    sub->add_option("--html", o->html, "also write one self-contained HTML report (tables, gates, lit spheres, plots) to this file");
    sub->add_option("--runtime-cost", o->runtime_cost,
                    "GPU cost per encoding from build/bench/bench_runtime --json FILE: SPIR-V instructions and lavapipe ns/eval "
                    "columns (text, Markdown, HTML) and an error-vs-runtime-cost plot in the HTML report");
    sub->add_option("--budget", o->budgets,
                    "choice section: one more byte budget per probe (repeatable; 16, 28, 48, 60 and 108 are always there). "
                    "Each budget's pick shows its negativity (neg_frac, min_irr) and, as cheaper_" +
                        fmt(100.0 * kCheaperWithin, "%.0f%%") + ", the smallest representation with fewer bytes within " +
                        fmt(100.0 * kCheaperWithin, "%.0f%%") + " of its relative rmse")
        ->check(CLI::Range(std::size_t(1), std::size_t(1) << 20));
    sub->add_option("--require", o->require,
                    "choice section: only representations with negative_fraction 0 on every input (nonnegative)")
        ->check(CLI::IsMember({"nonnegative"}));
    sub->add_option("--max-instructions", o->max_instructions,
                    "choice section: only representations whose GPU evaluation has at most N SPIR-V instructions "
                    "(needs --runtime-cost; one it does not list does not qualify)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--max-encode-us", o->max_encode_us,
                    "choice section: only representations encoding a probe in at most N microseconds (the audit's timing)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--images", o->images, "write irradiance/error PNGs per input into this folder");
    sub->add_option("--directions", o->directions, "number of Fibonacci-lattice directions")->check(CLI::Range(16, 1 << 20));
    add_threads_option(sub, o->threads, "results do not depend on it");
    add_progress_flags(sub, o->progress);
    sub->add_flag("--no-timing", o->no_timing, "skip encode/decode timing (outputs become byte-identical across runs)");
    sub->add_option("--max-rmse", o->max_rmse, "gate: fail (exit 8) if any representation's RMSE exceeds this");
    sub->add_option("--max-relative-rmse", o->max_relative_rmse, "gate: fail (exit 8) if any relative RMSE exceeds this");
    sub->add_flag("--fail-on-negative", o->fail_on_negative, "gate: fail (exit 8) if any reconstruction goes negative");
    add_envmap_read_options(sub, &o->replace_non_finite, o->part);
    add_latlong_option(sub, o->latlong, nullptr, "default openexr");
    add_ldr_encoding_option(sub, o->ldr);
    add_depfile_option(sub);
    add_paths_relative_to_option(sub, o->paths_base);
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_audit
}  // namespace zhc::cli
