// bench_leak — light leaking through walls in probe volumes: the leak suite's table (docs/leaks.md).
//
// Scenes (tests/leak_scenes.h): two 5 x 3 x 6 m rooms split by a solid wall at 6 offsets across a
// 1.5 m cell x 3 thicknesses (2, 10, 20 % of the cell), one point light in the west room; an
// L-shaped corridor; a room lit only through a window by the sky; a closed box in a lit room. Each
// is baked with bake_scene (direct light only: transport.max_bounces = 0; the scenes' occluders
// have no material, so no reflected light would be traced anyway), its probes written as sh3 .zhp
// files by formats/probes without and with the leak sections, opened with zhc_volume_from_zhp and
// sampled with zhc_volume_irradiance at the shading points.
//
// Columns, per scene and sampling ("plain": probes baked at their grid points, the file without
// leak sections, plain trilinear over the baked, dilated probes; "masks": the same probes with
// validity + 8-bit visibility masks; "planes": the default bake, probes kept out of walls, validity
// + one plane per cell, codec/bake/leak_planes.h, what `zhc bake` writes):
//  * leak: mean irradiance at the dark side's points / mean irradiance at the lit side's points
//    (points within one cell of the separating geometry); the truth's own ratio beside it (0 where
//    the dark side gets no light);
//  * lit err: mean |E - E_true| / mean E_true over the lit side's points, E_true the exact direct
//    irradiance with the same shadow rays; "floor": the same for a probe baked at each point itself
//    (the SH3 limit no interpolation can beat);
//  * B/probe: extra bytes per probe of the leak data in the .zhp (0 for plain);
//  * ns: CPU time per zhc_volume_irradiance call (thread CPU time, median of 9 interleaved rounds
//    over every shading point) and masks / plain, planes / plain in the same run.
// Benchmarks never decide pass/fail (tests/test_leak_suite.cpp asserts the measured facts).
//
// Usage: bench_leak [--points N] [--threads N] [--json FILE] [--density K]
//   --points: shading points per surface of a region (free points: twice that; default 96)
//   --density: only the L corridor and the closed box, their probe cells split K times per axis
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "tests/leak_scenes.h"
#include "timing.h"

namespace {

using namespace zhc;
using namespace zhc::leak;

struct Row {
    std::string name;
    double offset = -1, thickness = -1;
    Measured m;
    double ns_plain = 0, ns_masks = 0, ns_planes = 0;
    std::uint64_t mask_rays = 0, plane_rays = 0, relocation_rays = 0;
};

// ns per zhc_volume_irradiance call over every shading point; plain, masks and planes in
// interleaved rounds.
void time_calls(const Baked& b, const std::vector<ShadingPoint>& pts, double* ns_plain, double* ns_masks, double* ns_planes) {
    zhc_volume v[3];
    if (!open_volume(b.plain_zhp, &v[0]) || !open_volume(b.masked_zhp, &v[1]) || !open_volume(b.planes_zhp, &v[2])) return;
    std::vector<float> p, n;
    for (const ShadingPoint& sp : pts) {
        p.insert(p.end(), {float(sp.p.x), float(sp.p.y), float(sp.p.z)});
        n.insert(n.end(), {float(sp.n.x), float(sp.n.y), float(sp.n.z)});
    }
    const int inner = std::max(1, 200000 / int(pts.size()));
    std::vector<double> t[3];
    for (int round = 0; round < 9; ++round)
        for (int which = 0; which < 3; ++which) {
            const bench::Timing tm = bench::time_repeats_cpu(1, [&] {
                float acc = 0;
                for (int r = 0; r < inner; ++r)
                    for (size_t i = 0; i < pts.size(); ++i) {
                        float rgb[3];
                        zhc_volume_irradiance(&v[which], &p[3 * i], &n[3 * i], rgb);
                        acc += rgb[0];
                    }
                bench::keep(acc);
            });
            t[which].push_back(tm.median_s * 1e9 / double(inner * pts.size()));
        }
    for (auto& x : t) std::sort(x.begin(), x.end());
    *ns_plain = t[0][t[0].size() / 2];
    *ns_masks = t[1][t[1].size() / 2];
    *ns_planes = t[2][t[2].size() / 2];
}

void print_row(const Row& r) {
    const Measured& m = r.m;
    std::printf("%-30s %4zu %3zu %4zu/%-4zu %6.2f%% | %6.2f%% %6.2f%% %6.2f%% | %6.1f%% %6.1f%% %6.1f%% %6.1f%% | %3.0f %3.0f | "
                "%5.1f %5.1f %5.1f %5.2fx %5.2fx\n",
                r.name.c_str(), m.probes, m.invalid, m.lit_points, m.dark_points, 100 * m.truth.leak, 100 * m.plain.leak,
                100 * m.masks.leak, 100 * m.planes.leak, 100 * m.floor.lit_error, 100 * m.plain.lit_error, 100 * m.masks.lit_error,
                100 * m.planes.lit_error, m.mask_bytes_per_probe, m.planes_bytes_per_probe, r.ns_plain, r.ns_masks, r.ns_planes,
                r.ns_plain > 0 ? r.ns_masks / r.ns_plain : 0.0, r.ns_plain > 0 ? r.ns_planes / r.ns_plain : 0.0);
}

void json_metrics(std::ostream& o, const char* key, const Metrics& x) {
    o << "\"" << key << "\": {\"leak\": " << x.leak << ", \"lit_error\": " << x.lit_error << ", \"lit_mean\": " << x.lit_mean
      << ", \"dark_mean\": " << x.dark_mean << "}";
}

}  // namespace

int main(int argc, char** argv) {
    int per_face = 96, threads = 1;
    std::uint32_t density = 1;
    std::string json;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--points" && i + 1 < argc) per_face = std::max(1, std::atoi(argv[++i]));
        else if (a == "--threads" && i + 1 < argc) threads = std::max(1, std::atoi(argv[++i]));
        else if (a == "--json" && i + 1 < argc) json = argv[++i];
        else if (a == "--density" && i + 1 < argc) density = std::uint32_t(std::max(1, std::atoi(argv[++i])));
        else {
            std::fprintf(stderr, "usage: %s [--points N] [--threads N] [--json FILE] [--density K]\n", argv[0]);
            return 2;
        }
    }
    std::vector<LeakScene> scenes = suite_scenes(per_face);
    if (density > 1) {
        // The corridor and the box alone, their probe cells split `density` times per axis.
        scenes = {l_corridor(per_face, 2, density), closed_box(per_face, 4, density)};
        std::printf("--density %u: the L corridor and the closed box with their cells split %u times per axis\n", density, density);
    }

    std::printf("Leak suite (tests/leak_scenes.h): direct light only (transport.max_bounces = 0), sh3 probes,\n"
                "zhc_volume_irradiance on volumes from zhc_volume_from_zhp; %d points per surface, %d free per region.\n\n",
                per_face, 2 * per_face);
    std::printf("%-30s %4s %3s %9s %7s | %7s %7s %7s | %7s %7s %7s %7s | %3s %3s | %5s %5s %5s %6s %6s\n", "scene", "prb", "inv",
                "lit/dark", "truth", "plain", "masks", "planes", "floor", "plain", "masks", "planes", "B/p", "B/p", "ns", "ns", "ns",
                "masks/", "planes/");
    std::printf("%-30s %4s %3s %9s %7s | %7s %7s %7s | %7s %7s %7s %7s | %3s %3s | %5s %5s %5s %6s %6s\n", "", "", "", "points",
                "leak", "leak", "leak", "leak", "lit err", "lit err", "lit err", "lit err", "msk", "pln", "plain", "masks", "plane",
                "plain", "plain");
    std::vector<Row> rows;
    for (const LeakScene& ls : scenes) {
        const Baked b = bake_volumes(ls, threads);
        if (!b.error.empty()) {
            std::fprintf(stderr, "%s\n", b.error.c_str());
            return 1;
        }
        Row r;
        r.name = ls.name;
        r.offset = ls.offset;
        r.thickness = ls.thickness;
        r.m = measure(ls, b);
        r.mask_rays = b.report.mask_rays;
        r.plane_rays = b.planes_report.planes.rays;
        r.relocation_rays = b.planes_report.relocation_rays;
        time_calls(b, ls.points, &r.ns_plain, &r.ns_masks, &r.ns_planes);
        print_row(r);
        rows.push_back(std::move(r));
    }
    if (!json.empty()) {
        std::ofstream o(json);
        o << "{\n  \"bench\": \"bench_leak\",\n  \"points_per_surface\": " << per_face << ",\n  \"rows\": [\n";
        for (size_t i = 0; i < rows.size(); ++i) {
            const Row& r = rows[i];
            o << "    {\"scene\": \"" << r.name << "\", \"offset\": " << r.offset << ", \"thickness\": " << r.thickness
              << ", \"probes\": " << r.m.probes << ", \"invalid\": " << r.m.invalid << ", \"lit_points\": " << r.m.lit_points
              << ", \"dark_points\": " << r.m.dark_points << ", \"mask_rays\": " << r.mask_rays << ", \"plane_rays\": " << r.plane_rays
              << ", \"relocation_rays\": " << r.relocation_rays << ", ";
            json_metrics(o, "truth", r.m.truth);
            o << ", ";
            json_metrics(o, "floor", r.m.floor);
            o << ", ";
            json_metrics(o, "plain", r.m.plain);
            o << ", ";
            json_metrics(o, "masks", r.m.masks);
            o << ", ";
            json_metrics(o, "planes", r.m.planes);
            o << ", \"bytes_per_probe\": {\"plain\": 0, \"masks\": " << r.m.mask_bytes_per_probe << ", \"planes\": "
              << r.m.planes_bytes_per_probe << "}, \"ns_per_sample\": {\"plain\": " << r.ns_plain << ", \"masks\": " << r.ns_masks
              << ", \"planes\": " << r.ns_planes << "}}" << (i + 1 < rows.size() ? "," : "") << "\n";
        }
        if (!bench::finish_json(o, json)) return 1;
    }
    return 0;
}
