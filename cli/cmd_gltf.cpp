// zhc gltf embed SCENE.gltf|.glb PROBES -o OUT.glb|.gltf [--encoding NAME] [--sh-axes zhc|gltf]
//                [--draco] [--draco-bits N] [--name NAME] [--replace]
// zhc gltf extract IN.glb|.gltf -o PROBES.zhp|.json [--volume I]
// zhc gltf eval IN.glb|.gltf --probe I --dir X,Y,Z [--volume V]
//
// The ZHC_light_probes extension (docs/gltf-extension.md). PROBES: a .zhp container or a JSON
// probe list (detected by content). `eval` prints the irradiance zhc computes for probe I in the
// glTF-space direction (X, Y, Z) — the reference the three.js client test compares against.
// Outputs are written atomically.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cli.h"
#include "codec/probe/probe_set.h"
#include "formats/io/file_io.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"

namespace zhc::cli {
namespace cmd_gltf {  // one namespace per verb file: the CLI is a unity build
namespace {

struct Options {
    std::string scene, probes, input, output, encoding, sh_axes = "zhc", name = GltfEmbedOptions{}.name;
    bool draco = false, replace = false;
    int draco_bits = 0;
    std::size_t volume = 0;
    std::uint64_t probe = 0;
    std::vector<double> dir;
};

Result<ProbeSet> load_probes(const std::string& path, const std::string& encoding) {
    auto bytes = read_file_bytes(path, std::uint64_t(2) << 30);
    if (!bytes) return bytes.error();
    if (looks_like_probe_file(*bytes)) {
        auto file = parse_and_decode_probe_set(*bytes, path);
        if (!file) return file.error();
        if (encoding.empty() || encoding == file->set.representation) return std::move(file->set);
        CodecOptions params;
        params.kind = file->set.params.kind;
        return convert_probe_set(file->set, encoding, params);
    }
    if (looks_like_json(*bytes)) {
        auto list = parse_probe_json(*bytes, path);
        if (!list) return list.error();
        return encode_probe_set(list->probes, encoding.empty() ? "sh3" : encoding, CodecOptions{}, list->layout);
    }
    return make_error(ErrorCode::kBadFormat, path + ": not a .zhp probe container or JSON probe list");
}

int run_embed(const Options& o) {
    const std::string ext = file_extension(o.output);
    if (ext != ".glb" && ext != ".gltf") {
        std::fprintf(stderr, "zhc: error: %s: output extension must be .glb or .gltf\n", o.output.c_str());
        return kExitUsage;
    }
    if (!o.encoding.empty() && !representation_named(o.encoding)) return kExitUsage;
    if (int rc = refuse_output_over_input("-o", o.output, {o.scene, o.probes}); rc != kExitOk) return rc;
    auto set = load_probes(o.probes, o.encoding);
    if (!set) return set.error().code == ErrorCode::kInvalidArgument ? (std::fprintf(stderr, "zhc: error: %s\n", set.error().message.c_str()), kExitUsage)
                                                                      : report(set.error());
    auto scene = read_file_bytes(o.scene, GltfLimits{}.max_file_bytes);
    if (!scene) return report(scene.error());
    GltfEmbedOptions eo;
    eo.binary = ext == ".glb";
    eo.sh_axes = o.sh_axes == "gltf" ? GltfShAxes::kGltf : GltfShAxes::kZhc;
    eo.draco = o.draco;
    eo.draco_bits = o.draco_bits;
    eo.name = o.name;
    eo.replace = o.replace;
    eo.output_path = o.output;
    auto out = embed_probes_gltf(*scene, o.scene, *set, eo);
    if (!out) {
        if (out.error().code == ErrorCode::kInvalidArgument) {
            std::fprintf(stderr, "zhc: error: %s\n", out.error().message.c_str());
            return kExitUsage;
        }
        return report(out.error());
    }
    if (Status st = write_file_atomic(o.output, *out); !st) return report_output(st.error());
    std::printf("%s: %llu %s probes embedded (%s%s), %zu bytes (scene %zu bytes)\n", o.output.c_str(),
                static_cast<unsigned long long>(set->count), set->representation.c_str(),
                eo.draco ? "draco point cloud, " : "", eo.sh_axes == GltfShAxes::kZhc ? "SH in zhc axes" : "SH in glTF axes",
                out->size(), scene->size());
    return kExitOk;
}

Result<GltfProbeVolume> load_volume(const std::string& path, std::size_t volume) {
    auto s = read_gltf_probes_file(path);
    if (!s) return s.error();
    if (s->volumes.empty()) return make_error(ErrorCode::kBadFormat, path + ": no ZHC_light_probes volume in this asset");
    if (volume >= s->volumes.size())
        return make_error(ErrorCode::kBadFormat, path + ": volume " + std::to_string(volume) + " out of range (" +
                                                     std::to_string(s->volumes.size()) + " volumes)");
    return std::move(s->volumes[volume]);
}

int run_extract(const Options& o) {
    const std::string ext = file_extension(o.output);
    if (ext != ".zhp" && ext != ".json") {
        std::fprintf(stderr, "zhc: error: %s: output extension must be .zhp or .json\n", o.output.c_str());
        return kExitUsage;
    }
    if (int rc = refuse_output_over_input("-o", o.output, {o.input}); rc != kExitOk) return rc;
    auto v = load_volume(o.input, o.volume);
    if (!v) return report(v.error());
    if (ext == ".zhp") {
        if (Status st = write_probe_file(o.output, v->set); !st) return report_output(st.error());
    } else {
        auto hub = decode_probe_set(v->set);
        if (!hub) return report(hub.error());
        if (Status st = write_probe_json(o.output, ProbeList{std::move(hub).value(), v->set.layout}); !st)
            return report_output(st.error());
    }
    std::printf("%s: %llu %s probes from volume %zu ('%s')\n", o.output.c_str(), static_cast<unsigned long long>(v->set.count),
                v->set.representation.c_str(), o.volume, v->name.c_str());
    return kExitOk;
}

int run_eval(const Options& o) {
    // A direction is three finite numbers, not all zero; anything else (0,0,0, NaN, Inf) is a usage
    // error, found before the file is read. Scaled by the largest magnitude first, so a tiny or huge
    // (finite) vector still normalises.
    const double m = o.dir.size() == 3 ? std::max({std::fabs(o.dir[0]), std::fabs(o.dir[1]), std::fabs(o.dir[2])}) : 0.0;
    const bool finite = o.dir.size() == 3 && std::isfinite(o.dir[0]) && std::isfinite(o.dir[1]) && std::isfinite(o.dir[2]);
    if (!finite || !(m > 0.0)) {
        std::string given;
        for (double d : o.dir) {
            char b[32];
            std::snprintf(b, sizeof b, "%.9g", d);
            if (!given.empty()) given += ',';
            given += b;
        }
        std::fprintf(stderr, "zhc: error: --dir %s: needs X,Y,Z, a direction in glTF axes (finite, not all zero)\n", given.c_str());
        return kExitUsage;
    }
    const Vec3 a{o.dir[0], o.dir[1], o.dir[2]};
    const double len = length(a);
    const Vec3 scaled = (1.0 / m) * a;  // only where the plain length under- or overflows
    const Vec3 g = len > 0.0 && std::isfinite(len) ? (1.0 / len) * a : (1.0 / length(scaled)) * scaled;
    auto v = load_volume(o.input, o.volume);
    if (!v) return report(v.error());
    if (o.probe >= v->set.count) {
        std::fprintf(stderr, "zhc: error: --probe %llu out of range (%llu probes)\n", static_cast<unsigned long long>(o.probe),
                     static_cast<unsigned long long>(v->set.count));
        return kExitUsage;
    }
    // The probe as stored in glTF order: grid volumes are reordered on extraction, so map the
    // glTF probe number back to zhc's order (gltf index j + ny (k + nz i) for zhc (i, j, k)).
    std::uint64_t zi = o.probe;
    if (v->set.layout.kind == ProbeLayoutKind::kGrid) {
        const auto& c = v->set.layout.grid.counts;  // zhc (nx, ny, nz)
        const std::uint64_t j = o.probe % c[1], k = (o.probe / c[1]) % c[2], i = o.probe / (std::uint64_t(c[1]) * c[2]);
        zi = i + c[0] * (j + std::uint64_t(c[1]) * k);
    }
    const Vec3 n_zhc{g.z, g.x, g.y};  // (x, y, z)_zhc = (z, x, y)_glTF
    const Codec& codec = *v->set.codec();
    const Sh3Radiance hub = decode_probe(codec, v->set.params, v->set.payload.data() + zi * codec.size_bytes);
    const Rgb e = irradiance(hub, n_zhc);
    std::printf("%.9g %.9g %.9g\n", double(e.r), double(e.g), double(e.b));
    return kExitOk;
}

const VerbRegistration registration(60, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("gltf", "Embed probe sets in glTF (ZHC_light_probes) and read them back");
    sub->require_subcommand(1);
    CLI::App* embed = sub->add_subcommand("embed", "Embed a probe set into a glTF scene, keeping everything else");
    embed->add_option("SCENE", o->scene, "input scene (.gltf or .glb)")->required();
    embed->add_option("PROBES", o->probes, "probe set (.zhp container or JSON probe list)")->required();
    embed->add_option("-o,--output", o->output, "output: .glb (binary) or .gltf (JSON, data-URI buffers)")->required();
    add_representations_option(embed, o->encoding, RepresentationCount::kOne, "stored in the glTF (default: the input's; JSON input: sh3)", "--encoding");
    embed->add_option("--sh-axes", o->sh_axes, "zhc (default, exact) or gltf (coefficients rotated into glTF axes)")
        ->check(CLI::IsMember({"zhc", "gltf"}));
    embed->add_flag("--draco", o->draco, "store positions + coefficients as a Draco point cloud (points layout, sh3/sh2)");
    embed->add_option("--draco-bits", o->draco_bits, "Draco quantisation bits (0 = lossless, default)")->check(CLI::Range(0, 30));
    embed->add_option("--name", o->name, "volume (and node) name (default zhc_probes)")
        ->check([](const std::string& v) { return v.empty() ? std::string("the volume name is empty") : std::string(); });
    embed->add_flag("--replace", o->replace,
                    "replace the scene's volume of the same name in place; without it such a scene is refused");
    add_depfile_option(embed);
    CLI::App* extract = sub->add_subcommand("extract", "Read a ZHC_light_probes volume back into a probe file");
    extract->add_option("IN", o->input, "glTF asset (.gltf or .glb)")->required();
    extract->add_option("-o,--output", o->output, "output: .zhp (container, bytes as stored) or .json (float SH3)")->required();
    extract->add_option("--volume", o->volume, "volume index (default 0)");
    add_depfile_option(extract);
    CLI::App* eval = sub->add_subcommand("eval", "Print the irradiance of one embedded probe in a glTF-space direction");
    eval->add_option("IN", o->input, "glTF asset (.gltf or .glb)")->required();
    eval->add_option("--volume", o->volume, "volume index (default 0)");
    eval->add_option("--probe", o->probe, "probe number in the glTF volume's order")->required();
    eval->add_option("--dir", o->dir, "direction X,Y,Z in glTF axes")->required()->delimiter(',')->expected(3);
    return [o, embed, extract] {
        if (embed->parsed()) return run_embed(*o);
        if (extract->parsed()) return run_extract(*o);
        return run_eval(*o);
    };
});

}  // namespace
}  // namespace cmd_gltf
}  // namespace zhc::cli
