// bench_volume — GPU volume layouts: error per GPU byte (docs/runtime.md, "GPU volume layouts").
//
// Two baked probe grids: the demo's (codec/bake default_scene, 8x8x4, as `zhc demo` bakes it) and a
// baked glTF scene (tests/data/gltf/gi_nodes.glb: 1,500 instanced triangles, KHR_lights_punctual,
// the default 8x8x8 grid over its bounds). Reference: the exact trilinear SH3 volume of the baked
// probes stored as sh3 (float), sampled with zhc_volume_irradiance_d (double).
// Rows:
//  * packed encodings in an integer texture, the 8-probe decode + blend in the shader: exactly
//    zhc_volume_irradiance_d of that encoding's volume (error = the encoding's own error);
//  * filterable layouts (runtime/zhc_volume_layouts.hpp): texel values rounded to their storage
//    format, hardware trilinear = the trilinear blend of the rounded values (filter-weight
//    quantisation of real GPUs not modelled), reconstructed SH3, irradiance in double.
// Error of one sample: |E - E_ref| (RGB Euclidean) / mean over the grid's samples of |E_ref|;
// reported: mean, 95th percentile and max over N random points in the grid's box with random unit
// normals (N = 100,000 by default, fixed seeds). Benchmarks never decide pass/fail.
//
// Usage: bench_volume [--samples N] [--gltf FILE] [--json FILE]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "codec/bake/scene.h"
#include "codec/probe/codec.h"
#include "codec/probe/probe_set.h"
#include "formats/io/file_io.h"
#include "formats/scene/scene_gltf.h"
#include "runtime/zhc_runtime.h"
#include "runtime/zhc_volume_layouts.hpp"
#include "timing.h"

namespace {

using namespace zhc;
namespace L = zhc_layouts;

struct Grid {
    std::string name;
    std::vector<Sh3Radiance> probes;
    ProbeLayout layout;
};

struct Stats {
    double mean = 0, p95 = 0, max = 0;
};

struct Row {
    std::string name, kind, textures;
    double bytes = 0;
    Stats err[2];
};

bool encode(const Grid& g, const char* rep, std::vector<std::uint8_t>* payload, zhc_volume* vol, zhc_probe_format* fmt) {
    auto set = encode_probe_set(g.probes, rep, CodecOptions{}, g.layout);
    if (!set) {
        std::fprintf(stderr, "%s: %s\n", rep, set.error().message.c_str());
        return false;
    }
    *payload = set->payload;
    if (zhc_probe_format_init(fmt, rep) != ZHC_OK) return false;
    const ProbeGrid& pg = g.layout.grid;
    const double origin[3] = {pg.origin.x, pg.origin.y, pg.origin.z}, spacing[3] = {pg.spacing.x, pg.spacing.y, pg.spacing.z};
    const std::uint32_t counts[3] = {pg.counts[0], pg.counts[1], pg.counts[2]};
    return zhc_volume_init(vol, fmt, payload->data(), payload->size(), origin, spacing, counts) == ZHC_OK;
}

Stats stats(std::vector<double> e) {
    Stats s;
    if (e.empty()) return s;
    std::sort(e.begin(), e.end());
    double sum = 0;
    for (double x : e) sum += x;
    s.mean = sum / double(e.size());
    s.p95 = e[std::min(e.size() - 1, static_cast<std::size_t>(0.95 * double(e.size())))];
    s.max = e.back();
    return s;
}

double norm3(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace

int main(int argc, char** argv) {
    int samples = 100000;
    std::string json, gltf = ZHC_GLTF_SCENE;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--samples" && i + 1 < argc) samples = std::max(100, std::atoi(argv[++i]));
        else if (a == "--gltf" && i + 1 < argc) gltf = argv[++i];
        else if (a == "--json" && i + 1 < argc) json = argv[++i];
        else {
            std::fprintf(stderr, "usage: %s [--samples N] [--gltf FILE] [--json FILE]\n", argv[0]);
            return 2;
        }
    }
    std::vector<Grid> grids;
    {
        const Scene scene = default_scene();
        auto baked = bake_scene(scene);
        if (!baked) {
            std::fprintf(stderr, "demo bake: %s\n", baked.error().message.c_str());
            return 1;
        }
        grids.push_back({"demo", *baked, probe_layout(scene.probes)});
    }
    {
        auto bytes = read_file_bytes(gltf, std::uint64_t(1) << 30);
        if (!bytes) {
            std::fprintf(stderr, "%s\n", bytes.error().message.c_str());
            return 1;
        }
        auto scene = parse_scene_gltf(*bytes, gltf);
        if (!scene) {
            std::fprintf(stderr, "%s\n", scene.error().message.c_str());
            return 1;
        }
        auto baked = bake_scene(*scene);
        if (!baked) {
            std::fprintf(stderr, "%s: %s\n", gltf.c_str(), baked.error().message.c_str());
            return 1;
        }
        grids.push_back({"gltf", *baked, probe_layout(scene->probes)});
    }

    const char* packed[] = {"zh3_q16", "sh2_q", "sh3_q28"};
    std::vector<Row> rows;
    for (const char* p : packed) {
        Row r;
        r.name = p;
        r.kind = "integer texture, 8-probe decode + blend in the shader";
        r.textures = "stored bytes";
        r.bytes = double(find_codec(p)->size_bytes);
        rows.push_back(r);
    }
    for (L::Layout l : L::kAllLayouts) {
        Row r;
        r.name = L::layout_name(l);
        r.kind = "hardware trilinear";
        r.bytes = double(L::layout_bytes_per_probe(l));
        std::vector<L::TextureSpec> t = L::layout_textures(l);
        for (std::size_t i = 0; i < t.size();) {
            std::size_t j = i;
            while (j < t.size() && t[j].storage == t[i].storage && t[j].components == t[i].components) ++j;
            if (!r.textures.empty()) r.textures += " + ";
            r.textures += std::to_string(j - i) + " " + L::storage_name(t[i].storage, t[i].components);
            i = j;
        }
        rows.push_back(r);
    }

    for (std::size_t gi = 0; gi < grids.size(); ++gi) {
        const Grid& g = grids[gi];
        std::vector<std::uint8_t> ref_bytes;
        zhc_volume ref;
        zhc_probe_format ref_fmt;
        if (!encode(g, "sh3", &ref_bytes, &ref, &ref_fmt)) return 1;
        // Sample points and normals, and the reference.
        std::mt19937_64 rng(1234 + gi);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        std::normal_distribution<double> gauss;
        std::vector<std::array<double, 6>> pts(static_cast<std::size_t>(samples));
        std::vector<std::array<double, 3>> eref(pts.size());
        double mean_ref = 0;
        for (std::size_t s = 0; s < pts.size(); ++s) {
            for (int c = 0; c < 3; ++c)
                pts[s][static_cast<std::size_t>(c)] = ref.origin[c] + u(rng) * ref.spacing[c] * double(ref.counts[c] - 1);
            for (int c = 3; c < 6; ++c) pts[s][static_cast<std::size_t>(c)] = gauss(rng);
            zhc_volume_irradiance_d(&ref, pts[s].data(), pts[s].data() + 3, eref[s].data());
            mean_ref += norm3(eref[s].data());
        }
        mean_ref /= double(pts.size());
        std::size_t ri = 0;
        for (const char* p : packed) {
            std::vector<std::uint8_t> bytes;
            zhc_volume vol;
            zhc_probe_format fmt;
            if (!encode(g, p, &bytes, &vol, &fmt)) return 1;
            std::vector<double> e(pts.size());
            for (std::size_t s = 0; s < pts.size(); ++s) {
                double rgb[3];
                zhc_volume_irradiance_d(&vol, pts[s].data(), pts[s].data() + 3, rgb);
                const double d[3] = {rgb[0] - eref[s][0], rgb[1] - eref[s][1], rgb[2] - eref[s][2]};
                e[s] = norm3(d) / mean_ref;
            }
            rows[ri++].err[gi] = stats(e);
        }
        for (L::Layout l : L::kAllLayouts) {
            const auto tex = L::volume_textures(ref, l);
            std::vector<double> e(pts.size());
            for (std::size_t s = 0; s < pts.size(); ++s) {
                double rgb[3];
                L::sample_irradiance(ref, l, tex, pts[s].data(), pts[s].data() + 3, rgb);
                const double d[3] = {rgb[0] - eref[s][0], rgb[1] - eref[s][1], rgb[2] - eref[s][2]};
                e[s] = norm3(d) / mean_ref;
            }
            rows[ri++].err[gi] = stats(e);
        }
        std::printf("grid %s: %u x %u x %u probes, %d samples, mean |E_ref| %.4g\n", g.name.c_str(), ref.counts[0], ref.counts[1],
                    ref.counts[2], samples, mean_ref);
    }

    std::printf("\nerror of one sample vs the exact trilinear SH3 volume: |dE| / mean |E_ref| (demo | gltf)\n");
    std::printf("%-22s %6s  %-34s %10s %10s %10s | %10s %10s %10s\n", "layout", "B/probe", "textures", "mean", "p95", "max", "mean",
                "p95", "max");
    for (const Row& r : rows)
        std::printf("%-22s %6.0f  %-34s %10.3g %10.3g %10.3g | %10.3g %10.3g %10.3g\n", r.name.c_str(), r.bytes, r.textures.c_str(),
                    r.err[0].mean, r.err[0].p95, r.err[0].max, r.err[1].mean, r.err[1].p95, r.err[1].max);
    if (!json.empty()) {
        std::ofstream out(json);
        out << "{\n  \"benchmark\": \"volume\",\n  \"samples\": " << samples << ",\n  \"grids\": [\"demo\", \"" << gltf
            << "\"],\n  \"rows\": [\n";
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const Row& r = rows[i];
            char buf[768];
            std::snprintf(buf, sizeof buf,
                          "    {\"layout\": \"%s\", \"kind\": \"%s\", \"textures\": \"%s\", \"bytes_per_probe\": %g, "
                          "\"demo\": {\"mean\": %.6g, \"p95\": %.6g, \"max\": %.6g}, "
                          "\"gltf\": {\"mean\": %.6g, \"p95\": %.6g, \"max\": %.6g}}%s\n",
                          r.name.c_str(), r.kind.c_str(), r.textures.c_str(), r.bytes, r.err[0].mean, r.err[0].p95, r.err[0].max,
                          r.err[1].mean, r.err[1].p95, r.err[1].max, i + 1 < rows.size() ? "," : "");
            out << buf;
        }
        if (!bench::finish_json(out, json)) return 1;
    }
    return 0;
}
