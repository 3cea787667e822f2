// zhc bake SCENE.json|SCENE.gltf|SCENE.glb -o PROBES.zhp|.json|.glb|.gltf [--engine NAME] [--threads N]
//          [--to REPRESENTATION] [--zstd LEVEL] [--sky-samples N] [--invalid-fraction F]:
// bakes the scene's probes (only the effects it lists; docs/scene.md) and writes them: a probe
// container, a JSON probe list, or a glTF with the probes embedded (ZHC_light_probes,
// docs/gltf-extension.md) — into a copy of the input asset when the scene is glTF, else into a
// minimal asset; with --engine NAME, an engine's probe file (formats/engines/engine_files.h).
#include <cstdio>
#include <thread>

#include "cli.h"
#include "engine_output.h"
#include "progress.h"
#include "codec/bake/scene.h"
#include "formats/io/file_io.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"
#include "formats/probes/tetra.h"
#include "formats/scene/scene_gltf.h"
#include "formats/scene/scene_json.h"

namespace zhc::cli {
namespace cmd_bake {  // one namespace per verb file: the CLI is a unity build
namespace {

struct Options {
    std::string scene;
    std::string output;
    std::string to = "sh3";
    std::string engine;
    CLI::Option* to_option = nullptr;  // --to given: refused with --engine
    int threads = 0;
    int zstd = 0;
    int sky_samples = -1;        // -1: the scene's occlusion.sky_samples
    double invalid_fraction = -1;  // < 0: the scene's occlusion.invalid_fraction
    int bounces = -1;              // -1: the scene's transport.bounces
    double max_noise = -1;         // < 0: the scene's transport.max_noise
    std::string rays;              // "MIN[:MAX]": the scene's transport.min_rays/max_rays
    ProgressFlags progress;  // --quiet also drops the effects report
};

// "MIN" or "MIN:MAX", decimal, 1 <= MIN <= MAX <= 2^20.
bool parse_ray_range(const std::string& text, int* lo, int* hi) {
    auto number = [](const std::string& t, int* v) {
        if (t.empty() || t.size() > 7 || t.find_first_not_of("0123456789") != std::string::npos) return false;
        *v = std::stoi(t);
        return *v >= 1 && *v <= (1 << 20);
    };
    const size_t colon = text.find(':');
    if (colon == std::string::npos) {
        if (!number(text, lo)) return false;
        *hi = std::max(*lo, SceneTransport{}.max_rays);
        return true;
    }
    return number(text.substr(0, colon), lo) && number(text.substr(colon + 1), hi) && *lo <= *hi;
}

void print_report(const BakeReport& r) {
    std::printf("simulated effects (%llu probes; times are CPU time summed over threads):\n",
                static_cast<unsigned long long>(r.probes));
    for (const BakeEffect& e : r.effects) std::printf("  %-24s %-42s %10.3f ms\n", e.name.c_str(), ("(" + e.method + ")").c_str(), e.milliseconds);
    if (r.effects.empty()) std::printf("  (none: the scene lists no lighting; every probe is zero)\n");
    for (const std::string& line : r.leak_lines()) std::printf("  %s\n", line.c_str());
    if (r.mask_probes > 0)
        std::printf("  visibility masks: %llu rays (%.1f rays/probe) %.3f ms\n", static_cast<unsigned long long>(r.mask_rays),
                    double(r.mask_rays) / double(r.mask_probes), r.mask_ms);
    if (r.transport.traced) {
        const TransportReport& t = r.transport;
        std::printf("  reflected light: %llu probes, %llu paths (%.0f per probe), %llu rays, %.2f bounces per path (deepest %d of at most %d)\n",
                    static_cast<unsigned long long>(t.probes), static_cast<unsigned long long>(t.paths),
                    t.probes ? double(t.paths) / double(t.probes) : 0.0, static_cast<unsigned long long>(t.rays),
                    t.paths ? double(t.vertices) / double(t.paths) : 0.0, t.max_depth, t.max_bounces);
        std::printf("  reflected light: noise (relative standard error of a probe's irradiance) median %.2f %%, max %.2f %%%s; energy left by the bounce limit <= %.1e\n",
                    100 * t.noise_median, 100 * t.noise_max,
                    t.probes_over_noise ? (" (" + std::to_string(t.probes_over_noise) + " probes stopped at the ray limit above the target)").c_str() : "",
                    t.energy_left);
        if (t.milliseconds > 0 && t.rays > 0)
            std::printf("  reflected light: %.3f ms per probe, %.1f ms per million rays\n", t.milliseconds / double(std::max<std::uint64_t>(t.probes, 1)),
                        t.milliseconds / (double(t.rays) * 1e-6));
    }
    if (r.rays > 0)
        std::printf("  occluder BVH built in %.3f ms; %llu rays in total\n", r.occluder_build_ms,
                    static_cast<unsigned long long>(r.rays));
    std::printf("bake total %.3f ms\n", r.total_ms);
}

int run(const Options& o) {
    const std::string ext = file_extension(o.output);
    const bool gltf_out = ext == ".glb" || ext == ".gltf";
    const EngineFile* engine = nullptr;
    if (!o.engine.empty()) {
        engine = engine_for_output(o.engine, o.output);
        if (!engine) return kExitUsage;
        if (o.zstd != 0 || (o.to_option && o.to_option->count() > 0)) {
            std::fprintf(stderr, "zhc: error: --engine %s: the file holds the engine's own layout (%s): --to and --zstd do not apply\n",
                         o.engine.c_str(), std::string(engine->layout_codec).c_str());
            return kExitUsage;
        }
    } else if (ext != ".zhp" && ext != ".json" && !gltf_out) {
        std::fprintf(stderr, "zhc: error: -o %s: the output must end in .zhp (container), .json (probe list) or .glb/.gltf (glTF with embedded probes)\n",
                     o.output.c_str());
        return kExitUsage;
    }
    if (ext != ".zhp" && o.zstd != 0) {
        std::fprintf(stderr, "zhc: error: --zstd %d: the output %s is not a .zhp container, the only output --zstd compresses\n", o.zstd,
                     o.output.c_str());
        return kExitUsage;
    }
    const Codec* codec = representation_named(o.to);
    if (!codec) return kExitUsage;
    if (int rc = refuse_output_over_input("-o", o.output, {o.scene}); rc != kExitOk) return rc;
    const int threads = resolve_threads(o.threads);
    SceneLoadOptions lo;
    lo.threads = threads;
    // A lat-long environment map is read in the glTF ecosystem's orientation when the bake's output
    // is glTF (and always for a glTF scene) unless the scene's environment.latlong says otherwise;
    // the effects report names the orientation used.
    if (gltf_out) lo.default_latlong = LatLongConvention::kGltf;
    lo.bounces = o.bounces;  // before the scene is read: --bounces 0 decodes no texture
    // A glTF input is read once: it is both the scene and, for -o .glb/.gltf, the host asset.
    const bool gltf_in = is_gltf_path(o.scene);
    std::vector<std::uint8_t> input_asset;
    if (gltf_in) {
        auto bytes = read_file_bytes(o.scene, GltfLimits{}.max_file_bytes);
        if (!bytes) return report(bytes.error());
        input_asset = std::move(bytes).value();
    }
    std::vector<std::string> notes;  // what the glTF defines that the bake does not use
    auto scene = gltf_in ? parse_scene_gltf(input_asset, o.scene, lo, GltfLimits{}, &notes) : read_scene_file(o.scene, lo);
    if (!scene) return report(scene.error());
    for (const std::string& n : notes) std::fprintf(stderr, "zhc: note: %s: %s\n", o.scene.c_str(), n.c_str());
    if (o.sky_samples >= 0) scene->occlusion.sky_samples = o.sky_samples;
    if (o.invalid_fraction >= 0) scene->occlusion.invalid_fraction = o.invalid_fraction;
    if (o.bounces >= 0) scene->transport.max_bounces = o.bounces;
    if (o.max_noise > 0) scene->transport.max_noise = o.max_noise;
    if (!o.rays.empty()) {
        int lo = 0, hi = 0;
        if (!parse_ray_range(o.rays, &lo, &hi)) {
            std::fprintf(stderr, "zhc: error: --rays %s: expected MIN or MIN:MAX, integers with 1 <= MIN <= MAX <= 1048576\n", o.rays.c_str());
            return kExitUsage;
        }
        scene->transport.min_rays = lo;
        scene->transport.max_rays = hi;
    }
    if (Status b = check_ray_budget(*scene, SceneJsonLimits{}, o.scene); !b) return report(b.error());
    BakeOptions bo;
    bo.threads = threads;
    BakeReport rep;
    ProbeLeakData leak;
    Progress progress("zhc bake", "probes", o.progress);
    if (progress.enabled()) bo.progress = [&](std::uint64_t d, std::uint64_t t) { progress.update(d, t); };
    size_t occluders = scene->occluders.size(), triangles = 0;
    for (const Occluder& oc : scene->occluders) triangles += oc.kind == OccluderKind::kTriangle;
    const bool traced = bake_traces_occluders(*scene);
    // The bake takes the occluders over (its BVH holds the only copy of the mesh).
    auto probes = bake_scene(std::move(*scene), bo, &rep, &leak);
    progress.finish();
    if (!probes) return report(probes.error());
    {
        bool all_zero = true;
        for (const Sh3Radiance& p : *probes)
            for (int i = 0; i < 9 && all_zero; ++i) all_zero = p[i][0] == 0 && p[i][1] == 0 && p[i][2] == 0;
        if (all_zero)
            std::fprintf(stderr, "zhc: warning: %s: every probe is zero: no light of the scene reaches a probe (lights, sky, environment or emitting surfaces; docs/scene.md)\n",
                         o.scene.c_str());
    }
    if (!o.progress.quiet) {
        print_report(rep);
        if (occluders > 0)
            std::printf("occluders: %zu (%zu mesh triangles)%s\n", occluders, triangles,
                        traced ? "" : "; not traced: no shadowed light, and sky samples 0 or nothing they would occlude");
    }

    const ProbeLayout layout = probe_layout(scene->probes);
    if (engine) {
        EngineFileInput ei;
        ei.hub = *probes;
        ei.layout = layout;
        ei.validity = leak.validity;
        return write_engine_output(*engine, ei, o.output);
    }
    if (ext == ".json") {
        ProbeList list;
        list.probes = *probes;
        list.layout = layout;
        if (!codec->traits.exact) {  // a lossy entry: the JSON holds what it decodes to
            auto hub = round_trip_probes(list.probes, o.to, CodecOptions{}, layout);
            if (!hub) return report(hub.error());
            list.probes = std::move(hub).value();
        }
        if (Status st = write_probe_json(o.output, list); !st) return report_write(st.error());
        std::printf("%s: %zu probes as JSON float SH3 radiance\n", o.output.c_str(), list.probes.size());
        return kExitOk;
    }
    auto set = encode_probe_set(*probes, o.to, CodecOptions{}, layout);
    if (!set) return report(set.error());
    // Grid bakes of scenes with occluders carry validity and the planes per cell (docs/scene.md
    // "Probes near geometry"); empty otherwise.
    set->validity = std::move(leak.validity);
    set->visibility = std::move(leak.visibility);
    set->planes = std::move(leak.planes);
    // Probes at explicit positions carry their Delaunay tetrahedra (the runtimes interpolate in them).
    for (const std::string& line : add_tetrahedra(*set))
        std::fprintf(stderr, "zhc: warning: %s: %s\n", o.output.c_str(), line.c_str());
    if (gltf_out) {
        // Into a copy of the input asset (everything of it kept, docs/gltf-extension.md), or into
        // a minimal asset for a JSON scene.
        std::vector<std::uint8_t> host;
        std::string host_path = o.output;
        if (gltf_in) {
            host = std::move(input_asset);
            host_path = o.scene;
        } else {
            const std::string minimal =
                R"({"asset":{"version":"2.0","generator":"zhc bake"},"scene":0,"scenes":[{"name":"zhc bake","nodes":[]}]})";
            host.assign(minimal.begin(), minimal.end());
        }
        GltfEmbedOptions eo;
        eo.binary = ext == ".glb";
        eo.output_path = o.output;
        eo.replace = true;  // an asset baked before: its zhc_probes volume is this bake's
        auto out = embed_probes_gltf(host, host_path, *set, eo);
        if (!out) return report(out.error());
        if (Status st = write_file_atomic(o.output, *out); !st) return report_output(st.error());
        std::printf("%s: %llu probes as %s embedded in %s (%zu bytes)\n", o.output.c_str(),
                    static_cast<unsigned long long>(set->count), set->representation.c_str(),
                    gltf_in ? "a copy of the input asset" : "a minimal glTF", out->size());
        return kExitOk;
    }
    ProbeFileWriteOptions wo;
    wo.zstd_level = o.zstd;
    auto bytes = serialize_probe_set(*set, wo);
    if (!bytes) return report(bytes.error());
    if (Status st = write_file_atomic(o.output, *bytes); !st) return report_output(st.error());
    std::printf("%s: %llu probes as %s (%zu bytes/probe), %zu bytes\n", o.output.c_str(),
                static_cast<unsigned long long>(set->count), set->representation.c_str(), codec->size_bytes, bytes->size());
    return kExitOk;
}

const VerbRegistration registration(15, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("bake", "Bake a scene (JSON, or glTF lights and meshes) into SH3 radiance probes");
    sub->add_option("SCENE", o->scene, "scene: JSON (docs/scene.md) or glTF .gltf/.glb (KHR_lights_punctual lights, meshes as occluders)")->required();
    sub->add_option("-o,--output", o->output, "output: .zhp (probe container), .json (float SH3 probe list), .glb/.gltf (probes embedded in glTF), or with --engine the engine's file")->required();
    add_engine_option(sub, o->engine);
    add_threads_option(sub, o->threads, "output identical for any count");
    o->to_option = add_representations_option(sub, o->to, RepresentationCount::kOne, "stored in the .zhp/glTF (default sh3)", "--to");
    o->to_option->capture_default_str();
    sub->add_option("--sky-samples", o->sky_samples, "occlusion rays per probe for the sky/environment, probe validity (default: the scene's occlusion.sky_samples, 256; 0 = no occlusion)")->check(CLI::Range(0, 65536));
    sub->add_option("--invalid-fraction", o->invalid_fraction, "a probe is invalid (dilated) when more than this fraction of its rays start inside geometry (default: the scene's occlusion.invalid_fraction, 0.25)")->check(CLI::Range(0.0, 1.0));
    sub->add_option("--bounces", o->bounces, "reflected light: at most this many surface bounces per path (default: the scene's transport.bounces, 64; 0 = no reflected or emitted light)")->check(CLI::Range(0, 1024));
    sub->add_option("--max-noise", o->max_noise, "reflected light: rays are added to a probe until the relative standard error of its irradiance is at most this (default: the scene's transport.max_noise, 0.02)")->check(CLI::Range(1e-6, 1.0));
    sub->add_option("--rays", o->rays, "reflected light: rays per probe, MIN or MIN:MAX (default: the scene's transport.min_rays:max_rays, 512:8192)");
    sub->add_option("--zstd", o->zstd, "zstd-compress the .zhp body at this level (1..22; 0 = none)")->check(CLI::Range(0, 22));
    sub->add_flag("--progress", o->progress.force, "progress on stderr even when it is not a terminal (one line per 10 %)");
    sub->add_flag("--quiet", o->progress.quiet, "do not print the effects report nor progress");
    add_depfile_option(sub);
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_bake
}  // namespace zhc::cli
