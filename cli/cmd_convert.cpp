// zhc convert IN -o OUT [--to REPRESENTATION] [quantiser options] [--zstd LEVEL]
//
// IN: an environment map (one probe, projected to SH3), a .zhp probe container, a JSON probe list or
// an engine's probe file (formats/engines/engine_files.h; detected by content). OUT's extension
// picks the output: .zhp (container) or .json (float SH3 probe list); with --engine NAME, the
// engine's file (its extension), read back once written to print its irradiance error against the
// input. Outputs are written atomically.
#include <cstdio>
#include <map>
#include <optional>
#include <vector>

#include "cli.h"
#include "engine_output.h"
#include "codec/probe/probe_set.h"
#include "formats/engines/engine_files.h"
#include "formats/envmap/envmap.h"
#include "formats/io/file_io.h"
#include "formats/probes/probe_file.h"
#include "formats/probes/tetra.h"
#include "formats/report/audit_inputs.h"

namespace zhc::cli {
namespace cmd_convert {  // one namespace per verb file: the CLI is a unity build
namespace {

struct Options {
    std::string input;
    std::string output;
    std::string to;
    std::string engine;
    int bits = 8;
    bool sqrt = false;
    std::string bound = "tight";
    std::string dc = "r11g11b10f";
    std::string zonal_map = "affine";
    std::string axis = "luminance";
    bool irradiance = false;
    int zstd = 0;
    bool replace_non_finite = false;
    std::string part;
    LatLongConvention latlong = LatLongConvention::kOpenExr;
    LdrDecoding ldr;
    int threads = 0;
    // The options that set CodecOptions' storage fields, each with the StorageOptionUse field saying
    // whether an entry uses it (null: every entry does, --irradiance).
    std::vector<std::pair<CLI::Option*, bool StorageOptionUse::*>> storage_flags;
    bool any_storage_flag() const {
        for (const auto& [opt, use] : storage_flags)
            if (opt->count() > 0) return true;
        return false;
    }
};

// A storage option given for a representation that does not use it would be silently ignored:
// refuse it, naming the option, the representation and the entries that do use it.
int refuse_unused_storage_options(const Options& o, const std::string& rep) {
    const Codec* codec = rep.empty() ? nullptr : find_codec(rep);
    for (const auto& [opt, use] : o.storage_flags) {
        if (opt->count() == 0) continue;
        if (codec && (!use || storage_options_used(*codec).*use)) continue;
        std::string users;
        for (const Codec& c : codecs())
            if (use && storage_options_used(c).*use) users += (users.empty() ? "" : ", ") + std::string(c.name);
        if (!use) users = "every representation";
        const std::string what = codec ? "the representation " + rep + " does not use it"
                                       : "without -r/--representations the output is float SH3, which does not use it";
        std::fprintf(stderr, "zhc: error: %s: %s (used by: %s)\n", opt->get_name().c_str(), what.c_str(), users.c_str());
        return kExitUsage;
    }
    return kExitOk;
}

// What any input turns into: hub probes + layout, and the set itself when it was a container.
struct Loaded {
    ProbeList list;
    std::optional<ProbeSet> set;
    std::string kind;  // "envmap", "zhp", "json", or an engine file's name
    std::vector<std::uint8_t> validity;  // an engine file's, when it has one
};

Result<Loaded> load_input(const Options& o) {
    auto bytes = read_file_bytes(o.input, std::uint64_t(2) << 30);
    if (!bytes) return bytes.error();
    Loaded in;
    // An engine's file before environment maps: three.js's atlas is an OpenEXR, Bevy's volume a
    // KTX2, both of which an environment-map reader would take for an image.
    if (looks_like_probe_file(*bytes)) {
        auto file = parse_and_decode_probe_set(*bytes, o.input);
        if (!file) return file.error();
        in.list.probes = std::move(file->hub);
        in.list.layout = file->set.layout;
        in.set = std::move(file->set);
        in.kind = "zhp";
    } else if (const EngineFile* engine = sniff_engine_file(*bytes)) {
        auto probes = engine->read(*bytes, o.input);
        if (!probes) return probes.error();
        for (const std::string& line : probes->notes) std::fprintf(stderr, "zhc: note: %s: %s\n", o.input.c_str(), line.c_str());
        in.list.probes = std::move(probes->hub);
        in.list.layout = std::move(probes->layout);
        in.validity = std::move(probes->validity);
        in.kind = std::string(engine->name);
    } else if (looks_like_envmap(*bytes)) {
        EnvmapReadOptions ro;
        if (o.replace_non_finite) ro.non_finite = NonFinitePolicy::kReplaceZero;
        ro.part = o.part;
        ro.latlong = o.latlong;
        ro.ldr = o.ldr;
        auto img = read_envmap_memory(*bytes, o.input, ro);
        if (!img) return img.error();
        in.list.probes.push_back(project_envmap(*img, resolve_threads(o.threads)));
        in.kind = "envmap";
    } else if (looks_like_json(*bytes)) {
        auto list = parse_probe_json(*bytes, o.input);
        if (!list) return list.error();
        in.list = std::move(list).value();
        in.kind = "json";
    } else {
        return unknown_probe_input(o.input, *bytes);
    }
    return in;
}

Result<CodecOptions> params_from(const Options& o) {
    CodecOptions p;
    p.bits = o.bits;
    p.sqrt_encoding = o.sqrt;
    p.l2_bound = o.bound == "loose" ? L2Bound::kLoose : L2Bound::kTight;
    p.dc_format = o.dc == "rgb9e5" ? DcFormat::kRGB9E5 : (o.dc == "half" ? DcFormat::kHalf : DcFormat::kR11G11B10F);
    p.zonal_mapping = o.zonal_map == "zero" ? ZonalMapping::kZeroPreserving
                                            : (o.zonal_map == "symmetric" ? ZonalMapping::kSymmetric : ZonalMapping::kAffine);
    p.axis_mode = o.axis == "channel" ? ZonalAxisMode::kPerChannel : ZonalAxisMode::kLuminance;
    p.kind = o.irradiance ? StoredKind::kIrradiance : StoredKind::kRadiance;
    return p;
}

// --engine NAME: the engine's file (read back before it is written, to print its error).
int run_engine(const Options& o, const EngineFile& engine) {
    if (!o.to.empty() || o.any_storage_flag() || o.zstd != 0) {
        std::fprintf(stderr, "zhc: error: --engine %s: the file holds the engine's own layout (%s): -r/--to, the quantiser options and --zstd do not apply\n",
                     o.engine.c_str(), std::string(engine.layout_codec).c_str());
        return kExitUsage;
    }
    if (int rc = refuse_output_over_input("-o", o.output, {o.input}); rc != kExitOk) return rc;
    auto in = load_input(o);
    if (!in) return report(in.error());
    EngineFileInput ei;
    ei.hub = in->list.probes;
    ei.layout = in->list.layout;
    ei.validity = in->set ? std::span<const std::uint8_t>(in->set->validity) : std::span<const std::uint8_t>(in->validity);
    if (in->set) ei.tetrahedra = in->set->tetrahedra;
    return write_engine_output(engine, ei, o.output);
}

int run(const Options& o) {
    const std::string ext = file_extension(o.output);
    if (!o.engine.empty()) {
        const EngineFile* engine = engine_for_output(o.engine, o.output);
        return engine ? run_engine(o, *engine) : kExitUsage;
    }
    if (ext != ".zhp" && ext != ".json") {
        std::fprintf(stderr, "zhc: error: %s: output extension must be .zhp or .json (an engine's file: --engine NAME)\n", o.output.c_str());
        return kExitUsage;
    }
    if (ext == ".json" && o.zstd != 0) {
        std::fprintf(stderr, "zhc: error: --zstd %d: the output %s is a JSON probe list, which is not compressed (--zstd is for a .zhp output)\n",
                     o.zstd, o.output.c_str());
        return kExitUsage;
    }
    if (!o.to.empty() && !representation_named(o.to)) return kExitUsage;
    if (int rc = refuse_output_over_input("-o", o.output, {o.input}); rc != kExitOk) return rc;
    auto params = params_from(o);
    if (!params) return report(params.error());
    auto in = load_input(o);
    if (!in) return report(in.error());

    std::string rep = o.to;
    if (const Codec* named = rep.empty() ? nullptr : find_codec(rep)) rep = std::string(named->name);  // an alias: its entry
    if (rep.empty() && ext == ".zhp") {
        if (!in->set) {
            std::fprintf(stderr, "zhc: error: -r/--representations NAME is required to write a .zhp from %s input\n",
                         in->kind.c_str());
            return kExitUsage;
        }
        rep = in->set->representation;
        // Same representation, no quantiser flags: keep the input's parameters too.
        if (!o.any_storage_flag()) *params = in->set->params;
    }
    if (int rc = refuse_unused_storage_options(o, rep); rc != kExitOk) return rc;
    if (Status st = validate_quant_params(*params, rep.empty() ? "sh3" : rep); !st) {
        std::fprintf(stderr, "zhc: error: %s\n", st.error().message.c_str());
        return kExitUsage;
    }

    EncodeStats stats;
    if (ext == ".zhp") {
        ProbeSet out;
        if (in->set && in->set->representation == rep && same_storage(in->set->params, *params)) {
            out = *in->set;  // same representation and parameters: keep the bytes (no re-quantisation)
        } else {
            auto set = encode_probe_set(in->list.probes, rep, *params, in->list.layout, &stats);
            if (!set) return report(set.error());
            out = std::move(set).value();
            out.validity = in->validity;  // an engine file's validity (empty otherwise)
            if (in->set) {  // validity, visibility masks and cell planes do not depend on the representation
                out.validity = in->set->validity;
                out.visibility = in->set->visibility;
                out.planes = in->set->planes;
                out.tetrahedra = in->set->tetrahedra;
                out.tetra_neighbours = in->set->tetra_neighbours;
            }
        }
        // A points layout carries its Delaunay tetrahedra (the input's, else computed here). What
        // the tetrahedralisation notices is printed once the file is written (a failed write
        // prints its error alone).
        std::vector<std::string> tetra_notes;
        if (out.layout.kind == ProbeLayoutKind::kPositions && out.tetrahedra.empty()) tetra_notes = add_tetrahedra(out);
        ProbeFileWriteOptions wo;
        wo.zstd_level = o.zstd;
        auto bytes = serialize_probe_set(out, wo);
        if (!bytes) return report(bytes.error());
        if (Status st = write_file_atomic(o.output, *bytes); !st) return report_output(st.error());
        for (const std::string& line : tetra_notes) std::fprintf(stderr, "zhc: warning: %s: %s\n", o.output.c_str(), line.c_str());
        const size_t per = out.codec()->size_bytes;
        std::printf("%s: %llu probes as %s (%zu bytes/probe), %zu bytes (%llu payload + %zu header%s), "
                    "clamped ratios: %d\n",
                    o.output.c_str(), static_cast<unsigned long long>(out.count), rep.c_str(), per, bytes->size(),
                    static_cast<unsigned long long>(out.count * per), kProbeFileHeaderBytes,
                    o.zstd > 0 ? ", body zstd-compressed" : "", stats.clamped_ratios);
        return kExitOk;
    }
    // JSON: float SH3; through the representation first when --to is given (a lossy preview).
    ProbeList list = in->list;
    if (!rep.empty()) {
        auto hub = round_trip_probes(list.probes, rep, *params, list.layout, &stats);
        if (!hub) return report(hub.error());
        list.probes = std::move(hub).value();
    }
    if (Status st = write_probe_json(o.output, list); !st) return report_write(st.error());
    std::printf("%s: %zu probes as JSON float SH3%s%s, clamped ratios: %d\n", o.output.c_str(), list.probes.size(),
                rep.empty() ? "" : " via ", rep.c_str(), stats.clamped_ratios);
    return kExitOk;
}

const VerbRegistration registration(40, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand(
        "convert", "Convert probes between environment maps, .zhp containers and JSON probe lists");
    sub->add_option("IN", o->input, "environment map (EXR/.hdr or KTX2/KTX 1/DDS cube map: one probe), .zhp container or JSON probe list")
        ->required();
    sub->add_option("-o,--output", o->output, "output file: .zhp (container), .json (float SH3 probe list) or, with --engine, the engine's file")
        ->required();
    add_engine_option(sub, o->engine);
    add_representations_option(sub, o->to, RepresentationCount::kOne, "default: the input container's; JSON output: none (float SH3)", "--to");
    auto& f = o->storage_flags;
    f.emplace_back(sub->add_option("--bits", o->bits, "bits per quantised ratio (2..8, default 8)")->check(CLI::Range(2, 8)),
                   &StorageOptionUse::bits);
    f.emplace_back(sub->add_flag("--sqrt", o->sqrt, "sign-preserving square-root encoding of the ratios"), &StorageOptionUse::sqrt);
    f.emplace_back(sub->add_option("--bound", o->bound, "non-zonal L2 bound: tight (sqrt(15)/2, default) or loose (sqrt(5)); sh3_q28 only")
                       ->check(CLI::IsMember({"tight", "loose"})),
                   &StorageOptionUse::l2_bound);
    f.emplace_back(sub->add_option("--dc", o->dc, "DC format: r11g11b10f (default), rgb9e5, half (sh2_q layouts only)")
                       ->check(CLI::IsMember({"r11g11b10f", "rgb9e5", "half"})),
                   &StorageOptionUse::dc);
    f.emplace_back(sub->add_option("--zonal-map", o->zonal_map,
                                   "zonal L2 interval mapping: affine (default), zero (zero-preserving), symmetric (+-sqrt(5))")
                       ->check(CLI::IsMember({"affine", "zero", "symmetric"})),
                   &StorageOptionUse::zonal_mapping);
    f.emplace_back(sub->add_option("--axis", o->axis,
                                   "zonal axis of the entries that take it from the parameters (zh3_q16, hall_curve_q, ...): "
                                   "luminance (default) or channel")
                       ->check(CLI::IsMember({"luminance", "channel"})),
                   &StorageOptionUse::axis);
    f.emplace_back(sub->add_flag("--irradiance", o->irradiance, "store irradiance SH (irradiance-scaled bounds) instead of radiance"),
                   nullptr);
    sub->footer("The quantiser options (--bits .. --axis) concern the quantised representations; one that the chosen "
                "representation does not use is refused (exit 2).");
    sub->add_option("--zstd", o->zstd, "zstd-compress the .zhp body at this level (1..22; 0 = none)")
        ->check(CLI::Range(0, 22));
    add_envmap_read_options(sub, &o->replace_non_finite, o->part);
    add_latlong_option(sub, o->latlong, nullptr, "default openexr");
    add_ldr_encoding_option(sub, o->ldr);
    add_threads_option(sub, o->threads, "environment map projection; result identical for any count");
    add_depfile_option(sub);
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_convert
}  // namespace zhc::cli
