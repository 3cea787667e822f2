// zhc dering IN -o OUT.json [--punctual]: window SH3 radiance so its irradiance is non-negative
// (Sloan 2017; codec/probe/dering.h). IN is a lat-long environment map (one probe: its SH3 projection)
// or a JSON probe list: {"sh3": 9x[r,g,b]} (what `zhc project --json` prints), {"probes": [...]},
// or [...], each probe an object with "sh3" (and optional "name") or a bare 9x[r,g,b] array.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli.h"
#include "codec/probe/dering.h"
#include "codec/sh/sh.h"
#include "formats/envmap/envmap.h"
#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"

namespace zhc::cli {
namespace cmd_dering {  // one namespace per verb file: the CLI is a unity build
namespace {

constexpr std::uint64_t kMaxInputBytes = std::uint64_t(1) << 30;
constexpr size_t kMaxProbes = size_t(1) << 24;

struct Options {
    std::string input;
    std::string paths_base;  // --paths-relative-to
    std::string output;
    bool punctual = false;
    bool replace_non_finite = false;
    std::string part;
    LatLongConvention latlong = LatLongConvention::kOpenExr;
    LdrDecoding ldr;
    int threads = 0;
};

struct Probe {
    std::string name;
    Sh3Radiance sh;
};

Result<Sh3Radiance> parse_sh3(const nlohmann::json& rows, const std::string& where) {
    const auto bad = [&] {
        return make_error(ErrorCode::kBadFormat, where + ": \"sh3\" must be 9 rows of [r, g, b] numbers");
    };
    if (!rows.is_array() || rows.size() != 9) return bad();
    Sh3Radiance sh;
    for (int i = 0; i < 9; ++i) {
        const auto& row = rows[static_cast<size_t>(i)];
        if (!row.is_array() || row.size() != 3) return bad();
        for (int k = 0; k < 3; ++k) {
            const auto& v = row[static_cast<size_t>(k)];
            if (!v.is_number()) return bad();
            const double d = v.get<double>();
            if (!std::isfinite(d) || std::fabs(d) > 3.0e38)
                return make_error(ErrorCode::kInvalidValue, where + ": coefficient " + std::to_string(i) +
                                                                " channel " + std::to_string(k) +
                                                                " is not a finite float");
            sh[i][k] = static_cast<float>(d);
        }
    }
    return sh;
}

Result<std::vector<Probe>> parse_probe_list(const std::vector<std::uint8_t>& bytes, const std::string& path) {
    if (Status depth = check_json_depth(bytes, path); !depth) return depth.error();
    const nlohmann::json j = nlohmann::json::parse(bytes.begin(), bytes.end(), nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded())
        return make_error(ErrorCode::kBadFormat, path + ": neither an environment map (EXR/.hdr, KTX2/KTX 1/DDS cube map) nor valid JSON");
    const nlohmann::json* list = nullptr;
    std::vector<Probe> probes;
    if (j.is_object() && j.contains("sh3")) {
        auto sh = parse_sh3(j["sh3"], path);
        if (!sh) return sh.error();
        probes.push_back({j.contains("name") && j["name"].is_string() ? j["name"].get<std::string>() : "", *sh});
        return probes;
    }
    if (j.is_object() && j.contains("probes")) list = &j["probes"];
    else if (j.is_array()) list = &j;
    if (list == nullptr || !list->is_array())
        return make_error(ErrorCode::kBadFormat, path + ": expected {\"sh3\": ...}, {\"probes\": [...]} or a JSON array");
    if (list->size() > kMaxProbes)
        return make_error(ErrorCode::kTooLarge, path + ": more than " + std::to_string(kMaxProbes) + " probes");
    for (size_t i = 0; i < list->size(); ++i) {
        const auto& p = (*list)[i];
        const std::string where = path + ": probe " + std::to_string(i);
        const nlohmann::json* rows = &p;
        std::string name;
        if (p.is_object()) {
            if (!p.contains("sh3")) return make_error(ErrorCode::kBadFormat, where + ": missing \"sh3\"");
            rows = &p["sh3"];
            if (p.contains("name") && p["name"].is_string()) name = p["name"].get<std::string>();
        }
        auto sh = parse_sh3(*rows, where);
        if (!sh) return sh.error();
        probes.push_back({name, *sh});
    }
    return probes;
}

nlohmann::json rgb_rows(const Sh3Radiance& sh) {
    nlohmann::json rows = nlohmann::json::array();
    for (int i = 0; i < 9; ++i) rows.push_back({sh[i].r, sh[i].g, sh[i].b});
    return rows;
}

int run(const Options& o) {
    if (int rc = refuse_output_over_input("-o", o.output, {o.input}); rc != kExitOk) return rc;
    auto bytes = read_file_bytes(o.input, kMaxInputBytes);
    if (!bytes) return report(bytes.error());
    std::vector<Probe> probes;
    if (looks_like_envmap(*bytes)) {
        EnvmapReadOptions ro;
        if (o.replace_non_finite) ro.non_finite = NonFinitePolicy::kReplaceZero;
        ro.part = o.part;
        ro.latlong = o.latlong;
        ro.ldr = o.ldr;
        auto img = read_envmap_memory(*bytes, o.input, ro);
        if (!img) return report(img.error());
        probes.push_back({"", project_envmap(*img, resolve_threads(o.threads))});
    } else {
        auto list = parse_probe_list(*bytes, o.input);
        if (!list) return report(list.error());
        probes = std::move(list).value();
    }

    DeringOptions d;
    d.punctual = o.punctual;
    nlohmann::json out;
    out["input"] = shown_path(o.input, o.paths_base);
    out["kind"] = "radiance";
    out["basis"] = "zhc (ZH3 paper Eq. 4/5), index l(l+1)+m";
    out["method"] = "Sloan 2017 deringing: least Table 1 window making the irradiance bound non-negative";
    out["window_parameter"] = "0 none; 1..6 Table 1 columns w = 16.7, 11.3, 10, 9, 7, 5.6 (linear in between); 7 DC only";
    out["punctual"] = o.punctual;
    nlohmann::json list = nlohmann::json::array();
    int windowed = 0, failed = 0;
    double strongest = 0;
    for (const Probe& p : probes) {
        const DeringResult r = dering_sh3(p.sh, d);
        nlohmann::json j;
        if (!p.name.empty()) j["name"] = p.name;
        j["sh3"] = rgb_rows(r.radiance);
        j["window"] = r.window;
        j["scales"] = {1.0, r.scales.l1, r.scales.l2};
        j["windowed"] = r.windowed;
        j["nonnegative"] = r.nonnegative;
        const auto before = sh3_min_irradiance_bound(p.sh), after = sh3_min_irradiance_bound(r.radiance);
        j["min_irradiance_bound_before"] = {before[0], before[1], before[2]};
        j["min_irradiance_bound_after"] = {after[0], after[1], after[2]};
        list.push_back(std::move(j));
        windowed += r.windowed ? 1 : 0;
        failed += r.nonnegative ? 0 : 1;
        strongest = std::max(strongest, r.window);
    }
    out["probes"] = std::move(list);
    const std::string text = out.dump() + "\n";
    if (auto s = write_file_atomic(o.output, std::vector<std::uint8_t>(text.begin(), text.end())); !s)
        return report_output(s.error());
    std::printf("%zu probe(s): %d windowed, strongest window %.4f%s -> %s\n", probes.size(), windowed, strongest,
                failed ? (", " + std::to_string(failed) + " not fixable (negative mean)").c_str() : "",
                o.output.c_str());
    return kExitOk;
}

const VerbRegistration registration(60, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand(
        "dering", "Window SH3 radiance so its irradiance is non-negative (Sloan 2017 deringing)");
    sub->add_option("IN", o->input, "environment map (EXR/.hdr, KTX2/KTX 1/DDS cube map) or JSON probe list")->required();
    sub->add_option("-o,--output", o->output, "output JSON (written atomically)")->required();
    sub->add_flag("--punctual", o->punctual, "source is punctual lights: extra windowing 0.92 / 0.73 first");
    add_envmap_read_options(sub, &o->replace_non_finite, o->part);
    add_latlong_option(sub, o->latlong, nullptr, "default openexr");
    add_ldr_encoding_option(sub, o->ldr);
    add_threads_option(sub, o->threads, "environment map projection; same result for any count");
    add_depfile_option(sub);
    add_paths_relative_to_option(sub, o->paths_base);
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_dering
}  // namespace zhc::cli
