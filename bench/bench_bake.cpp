// Scene-bake throughput, plain timing main: ./build/bench/bench_bake [probes_per_axis] [--json FILE]
//
//  * closed-form scenes: probe-lights per second on ONE thread, per light type and for a mixed
//    scene, against the target of 10^6 per second per core (ratio printed), and against a floor
//    measured in the same run: one SH3 basis evaluation + 27 multiply-adds per probe-light;
//  * occluded scenes: shadow rays per second (one thread) for the default scene's occluders and
//    for 1000 random spheres/boxes (BVH stress), plus the brute-force (no BVH) rate for contrast;
//  * triangle meshes: a tessellated sphere of ~20k triangles (and ~200k) as the occluder of a
//    sun: BVH build time, rays per second through the whole bake, the BVH query alone, and brute
//    force over every triangle on a subset of the same rays;
//  * occlusion passes on the ~200k-triangle sphere (docs/scene.md "Probes near geometry"): rays per
//    probe and probes per second of the sky/environment occlusion pass (whose rays also decide
//    probe validity), the dilation, the visibility-mask pass, the relocation of probes out of and
//    towards walls and the cell-plane fit, each as a ratio of its rays/s to
//    the shadow-ray throughput of the same mesh measured in the same run.
// Medians over 5 runs in the thread's CPU time (one thread throughout, so a loaded machine slows
// the run, not the numbers); the spread (min..max) is printed. The occlusion passes: medians of 3
// of the bake report's per-pass times, which are wall clock (steady_clock), so load shows there.
// Numbers never gate tests.
// --json FILE also writes the numbers as one JSON object (scripts/docs_numbers.py makes docs tables of it).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include "codec/bake/occluders.h"
#include "codec/bake/scene.h"
#include "timing.h"

using namespace zhc;

namespace {

Scene grid_scene(std::uint32_t n) {
    Scene s;
    s.probes.kind = ProbePlacementKind::kGrid;
    s.probes.min = {-4, -4, 0.1};
    s.probes.max = {4, 4, 3.1};
    s.probes.counts = {n, n, std::max<std::uint32_t>(1, n / 4)};
    return s;
}

SceneLight light_of(LightKind kind, int i) {
    SceneLight l;
    l.kind = kind;
    const double a = 0.7 * i;
    const Vec3 where{5.5 * std::cos(a), 5.5 * std::sin(a), 1.0 + 0.2 * i};  // outside the probe bounds
    l.position = where;
    l.center = where;
    l.radius = 0.3;
    l.direction = normalize_or({std::cos(a), std::sin(a), 0.8}, {0, 0, 1});
    if (kind == LightKind::kSpot) l.direction = -1.0 * where;
    l.angular_radius_rad = 0.01;
    l.inner_angle_rad = 0.4;
    l.outer_angle_rad = 0.7;
    l.color = {1.0f + i, 2.0f, 3.0f};
    return l;
}

// A sphere of radius 1.5 hovering over the middle of the probe grid, lit by a sun with a
// 3-degree radius and 64 samples: a mix of blocked rays (under it) and misses.
Scene mesh_scene(std::uint32_t n, int res) {
    Scene s = grid_scene(n);
    s.occlusion.sky_samples = 0;
    s.occluders = uv_sphere_triangles({0.3, -0.2, 4.5}, 1.5, res, res);
    SceneLight sun = light_of(LightKind::kDirectional, 0);
    sun.direction = {0.2, 0.1, 1};
    sun.angular_radius_rad = 3 * kPi / 180;
    sun.shadows = true;
    sun.shadow_samples = 64;
    s.lights = {sun};
    return s;
}


// In a fresh process (this program run as `--peak-child N RES`, so that no memory an earlier
// measurement freed is reused and uncounted): the resident set before the mesh scene is made, then
// the high-water mark of making it and baking it given up (bake_scene(Scene&&), as `zhc bake`
// runs it), per triangle. -1 where /proc or the child fails.
// The mesh scene with reflected light: the sphere mesh and a floor under it reflect (albedo 0.5).
Scene reflecting_mesh_scene(std::uint32_t n, int res) {
    Scene s = mesh_scene(n, res);
    s.materials.push_back(SceneMaterial{"grey", {0.5f, 0.5f, 0.5f}, {0, 0, 0}});
    for (Occluder& o : s.occluders) o.material = 0;
    s.occluders.push_back(triangle_occluder({-50, -50, -0.5}, {50, -50, -0.5}, {50, 50, -0.5}));
    s.occluders.push_back(triangle_occluder({-50, -50, -0.5}, {50, 50, -0.5}, {-50, 50, -0.5}));
    s.occluders[s.occluders.size() - 1].material = s.occluders[s.occluders.size() - 2].material = 0;
    s.transport.min_rays = s.transport.max_rays = 256;
    return s;
}

double bake_peak_bytes_per_triangle(std::uint32_t n, int res, bool reflecting = false) {
    char exe[4096];
    const ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);  // in the shell it names sh
    if (len <= 0) return -1;
    exe[len] = 0;
    char cmd[4200];
    std::snprintf(cmd, sizeof cmd, "'%s' --peak-child %u %d%s", exe, n, res, reflecting ? " reflecting" : "");
    FILE* f = popen(cmd, "r");
    if (!f) return -1;
    double v = -1;
    if (std::fscanf(f, "%lf", &v) != 1) v = -1;
    return pclose(f) == 0 ? v : -1;
}
int peak_child(std::uint32_t n, int res, bool reflecting) {
    const double rss0 = bench::proc_status_bytes("VmRSS:");
    if (rss0 <= 0 || !bench::reset_peak()) return std::printf("-1\n"), 0;
    Scene s = reflecting ? reflecting_mesh_scene(n, res) : mesh_scene(n, res);
    const double tris = double(s.occluders.size());
    bench::keep(bake_scene(std::move(s)));
    const double hwm = bench::proc_status_bytes("VmHWM:");
    std::printf("%.6g\n", hwm > 0 ? (hwm - rss0) / tris : -1.0);
    return 0;
}

double probe_count(const Scene& s) {
    return double(s.probes.counts[0]) * s.probes.counts[1] * s.probes.counts[2];
}

// printf into a std::string (the --json rows).
template <class... A>
std::string format(const char* f, A... a) {
    char buf[512];
    std::snprintf(buf, sizeof buf, f, a...);
    return buf;
}

std::string join(const std::vector<std::string>& rows) {
    std::string s;
    for (size_t i = 0; i < rows.size(); ++i) s += (i ? ",\n    " : "\n    ") + rows[i];
    return s + "\n  ";
}

}  // namespace

int main(int argc, char** argv) {
    if ((argc == 4 || argc == 5) && std::string(argv[1]) == "--peak-child")
        return peak_child(static_cast<std::uint32_t>(std::atoi(argv[2])), std::atoi(argv[3]), argc == 5);
    std::uint32_t n = 64;
    std::string json;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--json" && i + 1 < argc) json = argv[++i];
        else if (std::atoi(a.c_str()) >= 4) n = static_cast<std::uint32_t>(std::atoi(a.c_str()));
        else {
            std::fprintf(stderr, "usage: %s [probes_per_axis >= 4] [--json FILE]\n", argv[0]);
            return 2;
        }
    }
    std::vector<std::string> closed_rows, occluded_rows, mesh_rows;
    double floor_rate = 0;
    const int lights = 16, repeats = 5;
    const double target = 1e6;
    std::printf("bench_bake: %ux%ux%u probes, %d lights per scene, 1 thread, median of %d runs (thread CPU time)\n\n", n, n,
                std::max<std::uint32_t>(1, n / 4), lights, repeats);

    // Floor: one basis evaluation and 27 multiply-adds per probe-light.
    {
        const Scene s = grid_scene(n);
        const std::vector<Vec3> pos = probe_positions(s.probes);
        std::vector<double> acc(pos.size() * 27);
        const auto t = bench::time_repeats_cpu(repeats, [&] {
            for (int l = 0; l < lights; ++l)
                for (size_t p = 0; p < pos.size(); ++p) {
                    const auto y = sh3_basis(normalize_or(pos[p] - Vec3{1.0 * l, 2, 3}, {0, 0, 1}));
                    for (int i = 0; i < 27; ++i) acc[p * 27 + i] += y[i / 3] * (1 + i % 3);
                }
            bench::keep(acc);
        });
        floor_rate = pos.size() * lights / t.median_s;
        std::printf("floor (basis + 27 madds)   %10.3g probe-lights/s  (%.1f ns each)\n\n",
                    floor_rate, t.median_s * 1e9 / (pos.size() * lights));
    }

    std::printf("%-24s %14s %9s %10s %18s\n", "closed form", "probe-lights/s", "ns each", "vs 1e6/s", "spread (ms)");
    struct Case {
        const char* name;
        std::vector<LightKind> kinds;
    };
    const Case cases[] = {{"directional (delta)", {LightKind::kDirectional}},
                          {"sun (cone)", {LightKind::kDirectional}},
                          {"point", {LightKind::kPoint}},
                          {"spot", {LightKind::kSpot}},
                          {"sphere", {LightKind::kSphere}},
                          {"hemisphere", {LightKind::kHemisphere}},
                          {"mixed (all five)",
                           {LightKind::kDirectional, LightKind::kPoint, LightKind::kSpot, LightKind::kSphere,
                            LightKind::kHemisphere}}};
    for (const Case& c : cases) {
        Scene s = grid_scene(n);
        for (int i = 0; i < lights; ++i) {
            SceneLight l = light_of(c.kinds[static_cast<size_t>(i) % c.kinds.size()], i);
            if (std::string(c.name) == "directional (delta)") l.angular_radius_rad = 0;
            s.lights.push_back(l);
        }
        const auto t = bench::time_repeats_cpu(repeats, [&] { bench::keep(bake_scene(s)); });
        const double rate = probe_count(s) * lights / t.median_s;
        std::printf("%-24s %14.3g %9.1f %9.2fx %8.1f..%-8.1f\n", c.name, rate, 1e9 / rate, rate / target,
                    t.min_s * 1e3, t.max_s * 1e3);
        closed_rows.push_back(format("{\"case\": \"%s\", \"probe_lights_per_s\": %.6g, \"ns_each\": %.4g, \"vs_target\": %.4g}",
                                     c.name, rate, 1e9 / rate, rate / target));
    }

    std::printf("\n%-40s %12s %12s %10s\n", "occluded", "rays/s", "ns per ray", "ms");
    {
        Scene s = default_scene();
        s.probes.counts = {n, n, std::max<std::uint32_t>(1, n / 4)};
        s.occlusion.sky_samples = 0;  // shadow rays only (the occlusion passes: the last section)
        BakeReport rep;
        const auto t = bench::time_repeats_cpu(repeats, [&] { bench::keep(bake_scene(s, {}, &rep)); });
        std::printf("%-40s %12.3g %12.1f %10.1f  (%llu rays; whole bake incl. closed forms)\n",
                    "default scene (2 occluders, 3 traced)", rep.rays / t.median_s, t.median_s * 1e9 / rep.rays,
                    t.median_s * 1e3, static_cast<unsigned long long>(rep.rays));
        occluded_rows.push_back(format("{\"case\": \"default scene\", \"rays\": %llu, \"rays_per_s\": %.6g}",
                                       static_cast<unsigned long long>(rep.rays), rep.rays / t.median_s));
    }
    {
        std::mt19937 rng(3);
        std::uniform_real_distribution<double> u(-6, 6), u01(0, 1);
        Scene s = grid_scene(n / 2);
        s.occlusion.sky_samples = 0;
        for (int i = 0; i < 1000; ++i) {
            const Vec3 c{u(rng), u(rng), 4 + 0.5 * u(rng)};
            const double r = 0.1 + 0.2 * u01(rng);
            const Vec3 hi = c + Vec3{0.4 * u01(rng), 0.4 * u01(rng), 0.1};
            s.occluders.push_back(i % 2 ? sphere_occluder(c, r) : box_occluder(c, hi));
        }
        SceneLight sun = light_of(LightKind::kDirectional, 0);
        sun.direction = {0.2, 0.1, 1};
        sun.angular_radius_rad = 0.05;
        sun.shadows = true;
        sun.shadow_samples = 64;
        s.lights = {sun};
        BakeReport rep;
        const auto t = bench::time_repeats_cpu(repeats, [&] { bench::keep(bake_scene(s, {}, &rep)); });
        std::printf("%-40s %12.3g %12.1f %10.1f  (%llu rays)\n", "1000 random occluders, sun 64 samples",
                    rep.rays / t.median_s, t.median_s * 1e9 / rep.rays, t.median_s * 1e3,
                    static_cast<unsigned long long>(rep.rays));
        // Brute force over the same rays (no BVH), for contrast: a subset of probes.
        const std::vector<Vec3> pos = probe_positions(s.probes);
        const auto dirs = cone_sample_directions(sun.direction, sun.angular_radius_rad, 64);
        const size_t probes = std::min<size_t>(pos.size(), 512);
        int hits = 0;
        const auto tb = bench::time_repeats_cpu(3, [&] {
            for (size_t p = 0; p < probes; ++p)
                for (const Vec3& d : dirs) {
                    bool h = false;
                    for (const Occluder& o : s.occluders) h = h || ray_hits(o, pos[p], d, 1e-9, 1e30);
                    hits += h;
                }
        });
        bench::keep(hits);
        std::printf("%-40s %12.3g %12.1f\n", "  same rays, brute force (no BVH)", probes * 64 / tb.median_s,
                    tb.median_s * 1e9 / (probes * 64));
        occluded_rows.push_back(format("{\"case\": \"1000 random occluders\", \"rays\": %llu, \"rays_per_s\": %.6g, "
                                       "\"brute_force_rays_per_s\": %.6g}",
                                       static_cast<unsigned long long>(rep.rays), rep.rays / t.median_s,
                                       probes * 64 / tb.median_s));
    }
    std::printf("\n%-40s %12s %12s %10s\n", "triangle-mesh occluder", "rays/s", "ns per ray", "ms");
    for (const int res : {100, 316}) {
        const Scene s = mesh_scene(n / 2, res);
        const SceneLight& sun = s.lights[0];
        const size_t tris = s.occluders.size();
        const auto tb0 = bench::time_repeats_cpu(3, [&] { bench::keep(OccluderBvh(s.occluders)); });
        BakeReport rep;
        const auto t = bench::time_repeats_cpu(repeats, [&] { bench::keep(bake_scene(s, {}, &rep)); });
        char label[96];
        std::snprintf(label, sizeof label, "sphere mesh %zu tris, sun 64 samples", tris);
        std::printf("%-40s %12.3g %12.1f %10.1f  (%llu rays, whole bake; BVH build %.1f ms)\n", label,
                    rep.rays / t.median_s, t.median_s * 1e9 / rep.rays, t.median_s * 1e3,
                    static_cast<unsigned long long>(rep.rays), tb0.median_s * 1e3);
        // The same rays straight through the BVH query and, on a subset, through a brute-force loop
        // over every triangle (identical hit/miss is a test; here only the speed).
        const OccluderBvh bvh(s.occluders);
        const std::vector<Vec3> pos = probe_positions(s.probes);
        const auto dirs = cone_sample_directions(sun.direction, sun.angular_radius_rad, 64);
        long hits = 0;
        const auto tq = bench::time_repeats_cpu(repeats, [&] {
            for (const Vec3& p : pos)
                for (const Vec3& d : dirs) hits += bvh.occluded(p, d, 1e-9, 1e30);
        });
        const double query_rate = double(pos.size()) * dirs.size() / tq.median_s;
        std::printf("%-40s %12.3g %12.1f %10.1f  (%.1f%% of rays blocked)\n", "  BVH query only", query_rate,
                    1e9 / query_rate, tq.median_s * 1e3, 100.0 * hits / repeats / (double(pos.size()) * dirs.size()));
        const size_t probes = std::min<size_t>(pos.size(), res > 200 ? 8 : 64);
        long bhits = 0;
        const auto tbf = bench::time_repeats_cpu(3, [&] {
            for (size_t p = 0; p < probes; ++p)
                for (const Vec3& d : dirs) {
                    bool h = false;
                    for (const Occluder& o : s.occluders)
                        if (ray_hits(o, pos[p], d, 1e-9, 1e30)) {
                            h = true;
                            break;  // any hit, as the BVH: stop at the first blocker
                        }
                    bhits += h;
                }
        });
        bench::keep(bhits);
        const double brute_rate = double(probes) * dirs.size() / tbf.median_s;
        std::printf("%-40s %12.3g %12.1f %10s  (BVH query %.0fx faster)\n", "  brute force (early exit)", brute_rate,
                    1e9 / brute_rate, "", query_rate / brute_rate);
        // Memory per triangle: the tree (its primitives, 80 bytes each, and nodes), and the peak of
        // making the scene and baking it given up, in a fresh process (bake_peak_bytes_per_triangle).
        const double bvh_per_tri = double(bvh.memory_bytes()) / double(tris);
        const double bake_peak_per_tri = bake_peak_bytes_per_triangle(n / 2, res);
        std::printf("%-40s tracer %.1f bytes per triangle (%zu-byte occluders, Embree's vertices, indices and BVH); bake peak %.1f bytes per triangle\n",
                    "  memory", bvh_per_tri, sizeof(Occluder), bake_peak_per_tri);
        mesh_rows.push_back(format("{\"triangles\": %zu, \"bvh_build_ms\": %.4g, \"rays\": %llu, \"bake_rays_per_s\": %.6g, "
                                   "\"query_rays_per_s\": %.6g, \"blocked_fraction\": %.4f, \"brute_force_rays_per_s\": %.6g, "
                                   "\"bvh_bytes_per_triangle\": %.4g, \"bake_peak_bytes_per_triangle\": %.4g}",
                                   tris, tb0.median_s * 1e3, static_cast<unsigned long long>(rep.rays), rep.rays / t.median_s,
                                   query_rate, double(hits) / repeats / (double(pos.size()) * dirs.size()), brute_rate,
                                   bvh_per_tri, bake_peak_per_tri));
    }
    
    // Occlusion passes on the 200k-triangle mesh, against its shadow rays in the same run.
    std::string occlusion_json = "null";
    {
        // ~200k triangles: the mesh scene's sphere over the grid (shadows the sun) and one the probes
        // sit around and inside (validity and masks have work), under a sky, occlusion on.
        Scene s = mesh_scene(n / 2, 224);
        s.occlusion = SceneOcclusion{};
        const auto low = uv_sphere_triangles({-1.5, 1.0, 1.5}, 1.2, 224, 224);
        s.occluders.insert(s.occluders.end(), low.begin(), low.end());
        s.sky = SceneSky{};
        const double probes = probe_count(s);
        std::printf("\nocclusion passes, %zu triangles, %.0f probes, 1 thread (median of 3)\n", s.occluders.size(), probes);
        // Shadow rays alone (no sky occlusion): the reference throughput.
        Scene shadow_only = s;
        shadow_only.occlusion.sky_samples = 0;
        // The sun effect's own time (the BVH build is outside every pass).
        BakeReport rs;
        std::vector<double> sun_ms;
        for (int i = 0; i < 3; ++i) {
            bench::keep(bake_scene(shadow_only, {}, &rs));
            sun_ms.push_back(rs.effects[1].milliseconds);
        }
        std::sort(sun_ms.begin(), sun_ms.end());
        const double sun_s = sun_ms[1] / 1e3, shadow_rate = rs.effects[1].rays / sun_s;
        std::printf("%-34s %10s %12s %12s %10s\n", "pass", "rays/probe", "probes/s", "rays/s", "vs shadow");
        std::printf("%-34s %10.1f %12.3g %12.3g %9.2fx  (BVH build %.0f ms, not in any pass)\n", "sun shadow rays (reference)",
                    rs.effects[1].rays / probes, probes / sun_s, shadow_rate, 1.0, rs.occluder_build_ms);
        std::vector<double> occ_ms, dil_ms, mask_ms, reloc_ms, plane_ms;
        BakeReport r;
        BakeOptions with_masks;
        with_masks.visibility_masks = true;  // the masks' pass too (zhc bake writes planes only)
        for (int i = 0; i < 3; ++i) {
            ProbeLeakData leak;
            bench::keep(bake_scene(s, with_masks, &r, &leak));
            occ_ms.push_back(r.occlusion_ms);
            dil_ms.push_back(r.dilation_ms);
            mask_ms.push_back(r.mask_ms);
            reloc_ms.push_back(r.relocation_ms);
            plane_ms.push_back(r.plane_ms);
        }
        auto median = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            return v[v.size() / 2];
        };
        const double o_s = median(occ_ms) / 1e3, d_s = median(dil_ms) / 1e3, m_s = median(mask_ms) / 1e3;
        const double r_s = median(reloc_ms) / 1e3, p_s = median(plane_ms) / 1e3;
        std::printf("%-34s %10.1f %12.3g %12.3g %9.2fx\n", "sky occlusion + validity (nearest)", r.occlusion_rays / probes,
                    probes / o_s, r.occlusion_rays / o_s, r.occlusion_rays / o_s / shadow_rate);
        std::printf("%-34s %10s %12.3g %12s %10s  (%llu invalid, %llu dilated)\n", "dilation", "0", probes / d_s, "-", "-",
                    static_cast<unsigned long long>(r.invalid_probes), static_cast<unsigned long long>(r.dilated_probes));
        std::printf("%-34s %10.1f %12.3g %12.3g %9.2fx\n", "visibility masks (any hit)", r.mask_rays / probes, probes / m_s,
                    r.mask_rays / m_s, r.mask_rays / m_s / shadow_rate);
        std::printf("%-34s %10.1f %12.3g %12.3g %9.2fx  (%llu moved out, %llu towards walls)\n", "probes kept out of walls",
                    r.relocation_rays / probes, probes / r_s, r.relocation_rays / r_s, r.relocation_rays / r_s / shadow_rate,
                    static_cast<unsigned long long>(r.moved_out), static_cast<unsigned long long>(r.moved_towards));
        std::printf("%-34s %10.1f %12.3g %12.3g %9.2fx  (%llu of %llu cells crossed, %llu planes)\n", "cell planes",
                    r.planes.rays / probes, probes / p_s, r.planes.rays / p_s, r.planes.rays / p_s / shadow_rate,
                    static_cast<unsigned long long>(r.planes.crossed_cells), static_cast<unsigned long long>(r.planes.cells),
                    static_cast<unsigned long long>(r.planes.planes));
        occlusion_json = format("{\"triangles\": %zu, \"probes\": %.0f, \"shadow_rays_per_s\": %.6g, "
                                "\"occlusion_rays_per_probe\": %.4g, \"occlusion_rays_per_s\": %.6g, \"dilation_probes_per_s\": %.6g, "
                                "\"mask_rays_per_probe\": %.4g, \"mask_rays_per_s\": %.6g, \"relocation_rays_per_probe\": %.4g, "
                                "\"relocation_rays_per_s\": %.6g, \"plane_rays_per_probe\": %.4g, \"plane_rays_per_s\": %.6g}",
                                s.occluders.size(), probes, shadow_rate, r.occlusion_rays / probes, r.occlusion_rays / o_s,
                                probes / d_s, r.mask_rays / probes, r.mask_rays / m_s, r.relocation_rays / probes,
                                r.relocation_rays / r_s, r.planes.rays / probes, r.planes.rays / p_s);
    }
    // Reflected light (codec/bake/transport.h) over the 596k-triangle sphere mesh and a floor,
    // both grey 0.5, 4 x 4 x 4 probes, 256 paths each: time per probe and per million rays, the
    // noise, and the bake's peak memory per triangle beside the same scene without materials.
    std::string transport_json = "null";
    {
        Scene s = reflecting_mesh_scene(4, 546);
        const double tris = double(s.occluders.size());
        BakeReport r;
        bench::keep(bake_scene(s, BakeOptions{}, &r));
        const TransportReport& t = r.transport;
        const double peak_plain = bake_peak_bytes_per_triangle(4, 546), peak_reflect = bake_peak_bytes_per_triangle(4, 546, true);
        std::printf("\nreflected light, %.0f triangles (sphere mesh and floor, albedo 0.5), %llu probes x %llu paths, 1 thread\n", tris,
                    static_cast<unsigned long long>(t.probes), static_cast<unsigned long long>(t.probes ? t.paths / t.probes : 0));
        std::printf("%-40s %10.2f ms per probe, %.1f ms per million rays (%llu rays, %.2f bounces per path)\n", "  path tracing",
                    t.milliseconds / double(std::max<std::uint64_t>(t.probes, 1)), t.milliseconds / (double(t.rays) * 1e-6),
                    static_cast<unsigned long long>(t.rays), t.paths ? double(t.vertices) / double(t.paths) : 0.0);
        std::printf("%-40s median %.2f %%, max %.2f %% relative standard error\n", "  noise", 100 * t.noise_median, 100 * t.noise_max);
        std::printf("%-40s %.1f bytes per triangle (without materials: %.1f)\n", "  bake peak memory", peak_reflect, peak_plain);
        transport_json = format("{\"triangles\": %.0f, \"probes\": %llu, \"paths\": %llu, \"rays\": %llu, \"ms_per_probe\": %.4g, "
                                "\"ms_per_million_rays\": %.4g, \"noise_median\": %.4g, \"bake_peak_bytes_per_triangle\": %.4g, "
                                "\"bake_peak_bytes_per_triangle_without_materials\": %.4g}",
                                tris, static_cast<unsigned long long>(t.probes), static_cast<unsigned long long>(t.paths),
                                static_cast<unsigned long long>(t.rays), t.milliseconds / double(std::max<std::uint64_t>(t.probes, 1)),
                                t.milliseconds / (double(t.rays) * 1e-6), t.noise_median, peak_reflect, peak_plain);
    }
    if (!json.empty()) {
        std::ofstream out(json);
        out << "{\n  \"benchmark\": \"bake\",\n"
            << format("  \"probes_per_axis\": %u, \"lights\": %d, \"repeats\": %d, \"threads\": 1, \"clock\": \"thread_cpu\",\n", n, lights, repeats)
            << format("  \"floor_probe_lights_per_s\": %.6g,\n", floor_rate) << "  \"closed_form\": [" << join(closed_rows)
            << "],\n  \"occluded\": [" << join(occluded_rows) << "],\n  \"occlusion_passes\": " << occlusion_json
            << ",\n  \"reflected_light\": " << transport_json
            << ",\n  \"meshes\": [" << join(mesh_rows).substr(0, join(mesh_rows).size() - 2);
        if (!bench::finish_json(out, json)) return 1;
    }
    return 0;
}
