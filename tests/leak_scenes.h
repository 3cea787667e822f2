// The leak suite's scenes, ground truth and measurement (tests/test_leak_suite.cpp asserts on them,
// bench/bench_leak.cpp prints the table; docs/leaks.md describes both).
//
// Scenes (y up, metres, walls are axis-aligned box occluders 0.2 thick unless said otherwise, every
// light casts shadows, no materials and transport.max_bounces = 0: direct light only):
//  * two_rooms(offset, thickness): two 5 x 3 x 6 m rooms split along x by a solid wall of
//    thickness `thickness` x the x spacing (1.5 m), one 8 cd point light in the west room; the
//    wall's centre lies `offset` x spacing on the +x side of a probe plane (0: a probe column
//    inside the wall, 0.5: the wall through the middle of a cell);
//  * l_corridor(): an L-shaped corridor 2 m wide, 3 m high (legs 8 m along x and 8 m along z), an
//    8 cd point light at the far end of the x leg, the z leg dark around the corner;
//  * window_room(): a closed 5 x 3 x 6 m room lit only by a constant sky (radiance 1) through a
//    1 x 2 m window in its east wall, a ground slab outside;
//  * closed_box(): a 6 x 3 x 6 m room with an 8 cd point light and a closed hollow box (0.1 m
//    walls, 1.4 x 1.4 x 1.4 m inside) in its middle, a probe inside the box.
// Probe grids of about 1.5 m spacing lie inside each scene's rooms.
//
// Shading points (Kronecker sequences, fixed seeds): on every surface of the side's region (floor, ceiling, walls; a
// point is kept only where geometry lies right behind it, so window openings and open sides drop
// out), 1e-4 off the surface, normal into the air; and free points with uniformly random normals.
// Regions: "lit" and "dark" air within one cell of the separating geometry (the wall; the corner's
// walls; the window wall; the box's walls). Dark points of scenes with point lights must be in the
// lights' shadow (points of the corridor's dark region that see the light are dropped).
//
// Ground truth (exact_irradiance): zhc's normalised irradiance (irradiance / pi, what
// zhc_volume_irradiance returns) for the point's normal: per point light I max(0, n.w) / (pi d^2)
// times its shadow ray (the bake's ray: from the point, t in (1e-9, d)); the sky by quadrature over
// kTruthSkyDirections spherical-Fibonacci directions, (4 / N) sum L(d) max(0, n.d) V(d).
//
// Volumes: the bake's probes as an sh3 .zhp written by formats/probes, opened with
// zhc_volume_from_zhp: "plain" a file without the leak sections (version 1: plain trilinear over
// the baked, dilated probes), "masks" the same probes with validity + visibility (version 2).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "codec/bake/occluders.h"
#include "codec/bake/scene.h"
#include "codec/probe/probe_set.h"
#include "formats/probes/probe_file.h"
#include "runtime/zhc_runtime.h"

namespace zhc::leak {

constexpr int kTruthSkyDirections = 4096;
constexpr double kSurfaceOffset = 1e-4;

enum class Side : std::uint8_t { kLit, kDark };

struct ShadingPoint {
    Vec3 p, n;
    Side side = Side::kLit;
    std::string kind;  // "floor", "ceiling", "wall", "free"
};

struct LeakScene {
    std::string name;
    double offset = -1, thickness = -1;  // two_rooms only: fractions of the cell
    double cell = 0;                     // probe spacing across the separating geometry
    Scene scene;
    std::vector<ShadingPoint> points;
    std::size_t dropped_lit_dark = 0;  // dark-region points that see a light (dropped)
};

// ---- building blocks --------------------------------------------------------------------------

inline double u01(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1p-53; }
inline double axis_of(Vec3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }
inline void set_axis(Vec3& v, int a, double x) { (a == 0 ? v.x : (a == 1 ? v.y : v.z)) = x; }
inline bool inside_box(Vec3 p, Vec3 lo, Vec3 hi) {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
}

inline SceneLight point_light(Vec3 position, double intensity) {
    SceneLight l;
    l.kind = LightKind::kPoint;
    l.name = "lamp";
    l.position = position;
    l.color = {float(intensity), float(intensity), float(intensity)};
    l.shadows = true;
    return l;
}

// A grid of counts[a] probes from lo to hi (counts 1: at lo).
inline void set_grid(Scene& s, Vec3 lo, Vec3 hi, std::array<std::uint32_t, 3> counts) {
    s.probes.kind = ProbePlacementKind::kGrid;
    s.probes.min = lo;
    s.probes.max = hi;
    s.probes.counts = counts;
}

inline Scene empty_scene() {
    Scene s;
    s.transport.max_bounces = 0;  // direct light only (no occluder has a material anyway)
    return s;
}

// A Kronecker (R_d) low-discrepancy sequence, frac(shift + k alpha) with alpha_i = phi_d^-i
// (phi_d the root of x^(d+1) = x + 1) and a random shift per call: deterministic, and its means
// converge much faster than independent random points'.
template <int D>
struct Kronecker {
    double alpha[D], shift[D];
    std::uint64_t k = 0;
    explicit Kronecker(std::mt19937_64& rng) {
        double phi = 2;
        for (int i = 0; i < 64; ++i) phi = std::pow(1 + phi, 1.0 / (D + 1));
        for (int i = 0; i < D; ++i) {
            alpha[i] = std::pow(phi, -(i + 1));
            shift[i] = u01(rng);
        }
    }
    void next(double out[D]) {
        ++k;
        for (int i = 0; i < D; ++i) out[i] = std::fmod(shift[i] + double(k) * alpha[i], 1.0);
    }
};

// Samples `per_face` points on each face of [lo, hi] (normal into the box, or out of it when
// `outward`) kept where geometry lies right behind them, and `free_points` points inside with
// uniformly distributed normals; points inside a solid or inside `exclude_lo..exclude_hi` are
// rejected. Positions (and the free points' normals) follow Kronecker sequences.
inline void sample_region(const OccluderBvh& bvh, Vec3 lo, Vec3 hi, Side side, bool outward, int per_face,
                          int free_points, std::mt19937_64& rng, std::vector<ShadingPoint>& out,
                          Vec3 exclude_lo = {1, 1, 1}, Vec3 exclude_hi = {0, 0, 0}) {
    const double margin = 1e-3;
    for (int a = 0; a < 3; ++a)
        for (int s = 0; s < 2; ++s) {
            Vec3 n{};
            set_axis(n, a, (s == 0) != outward ? 1.0 : -1.0);
            Kronecker<2> seq(rng);
            for (int k = 0; k < per_face; ++k) {
                double uv[2];
                seq.next(uv);
                Vec3 p{};
                for (int b = 0, j = 0; b < 3; ++b) {
                    if (b == a) continue;
                    set_axis(p, b, axis_of(lo, b) + margin + uv[j++] * (axis_of(hi, b) - axis_of(lo, b) - 2 * margin));
                }
                set_axis(p, a, (s == 0 ? axis_of(lo, a) : axis_of(hi, a)) + kSurfaceOffset * axis_of(n, a));
                if (!bvh.occluded(p, -1.0 * n, 0.0, 10 * kSurfaceOffset) || bvh.inside_any_solid(p)) continue;
                if (inside_box(p, exclude_lo, exclude_hi)) continue;
                const char* kind = a != 1 ? "wall" : (n.y > 0 ? "floor" : "ceiling");
                out.push_back({p, n, side, kind});
            }
        }
    Kronecker<5> seq(rng);
    for (int k = 0; k < free_points;) {
        double x[5];
        seq.next(x);
        Vec3 p{};
        for (int b = 0; b < 3; ++b) set_axis(p, b, axis_of(lo, b) + 0.02 + x[b] * (axis_of(hi, b) - axis_of(lo, b) - 0.04));
        const double z = 2 * x[3] - 1, phi = 2 * M_PI * x[4], r = std::sqrt(std::max(0.0, 1 - z * z));
        const Vec3 n{r * std::cos(phi), r * std::sin(phi), z};
        if (bvh.inside_any_solid(p) || inside_box(p, exclude_lo, exclude_hi)) continue;  // rejected: the next one
        out.push_back({p, n, side, "free"});
        ++k;
    }
}

// Drops dark points that see any shadowed light (counted in dropped_lit_dark).
inline void keep_shadowed_dark(LeakScene& ls, const OccluderBvh& bvh) {
    std::vector<ShadingPoint> kept;
    for (const ShadingPoint& sp : ls.points) {
        bool sees = false;
        if (sp.side == Side::kDark)
            for (const SceneLight& l : ls.scene.lights) {
                const Vec3 v = l.position - sp.p;
                const double d = length(v);
                sees = sees || !bvh.occluded(sp.p, (1.0 / d) * v, 1e-9, d);
            }
        if (sees) ++ls.dropped_lit_dark;
        else kept.push_back(sp);
    }
    ls.points = std::move(kept);
}

// ---- the scenes -------------------------------------------------------------------------------

constexpr double kCell = 1.5;

inline LeakScene two_rooms(double offset, double thickness, int per_face = 24, std::uint64_t seed = 1) {
    LeakScene ls;
    ls.offset = offset;
    ls.thickness = thickness;
    ls.cell = kCell;
    const double t = thickness * kCell, w = 10 + t;  // west room x 0..5, wall 5..5+t, east room 5+t..10+t
    char name[96];
    std::snprintf(name, sizeof name, "two rooms, wall at %.1f, %.0f %%", offset, 100 * thickness);
    ls.name = name;
    Scene s = empty_scene();
    auto box = [&](Vec3 lo, Vec3 hi) { s.occluders.push_back(box_occluder(lo, hi)); };
    box({-0.2, -0.2, -0.2}, {w + 0.2, 0, 6.2});  // floor
    box({-0.2, 3, -0.2}, {w + 0.2, 3.2, 6.2});   // ceiling
    box({-0.2, 0, 0}, {0, 3, 6});                // west
    box({w, 0, 0}, {w + 0.2, 3, 6});             // east
    box({-0.2, 0, -0.2}, {w + 0.2, 3, 0});       // south
    box({-0.2, 0, 6}, {w + 0.2, 3, 6.2});        // north
    box({5, 0, 0}, {5 + t, 3, 6});               // the wall between the rooms
    s.lights.push_back(point_light({2.5, 2.0, 3.0}, 8));
    // x: a probe plane `offset` cells on the -x side of the wall's centre, probes inside the house.
    const double c = 5 + 0.5 * t, xp = c - offset * kCell;
    const int below = int(std::floor((xp - 0.05) / kCell)), above = int(std::floor((w - 0.05 - xp) / kCell));
    set_grid(s, {xp - below * kCell, 0.25, 0.25}, {xp + above * kCell, 2.75, 5.75},
             {std::uint32_t(below + above + 1), 3, 5});
    ls.scene = std::move(s);
    const OccluderBvh bvh(ls.scene.occluders);
    std::mt19937_64 rng(seed);
    sample_region(bvh, {5 - kCell, 0, 0}, {5, 3, 6}, Side::kLit, false, per_face, 2 * per_face, rng, ls.points);
    sample_region(bvh, {5 + t, 0, 0}, {5 + t + kCell, 3, 6}, Side::kDark, false, per_face, 2 * per_face, rng, ls.points);
    keep_shadowed_dark(ls, bvh);
    return ls;
}

// density: the probe grid's cells split density times per axis (1: the suite's 1.5 m).
inline LeakScene l_corridor(int per_face = 24, std::uint64_t seed = 2, std::uint32_t density = 1) {
    LeakScene ls;
    ls.name = "L corridor";
    ls.cell = kCell;
    Scene s = empty_scene();
    auto box = [&](Vec3 lo, Vec3 hi) { s.occluders.push_back(box_occluder(lo, hi)); };
    box({-0.2, -0.2, -0.2}, {8.2, 0, 10.2});  // floor
    box({-0.2, 3, -0.2}, {8.2, 3.2, 10.2});   // ceiling
    box({-0.2, 0, -0.2}, {8.2, 3, 0});        // x leg, south
    box({-0.2, 0, 0}, {0, 3, 2});             // x leg, west end
    box({-0.2, 0, 2}, {6, 3, 2.2});           // x leg, north (inner corner)
    box({5.8, 0, 2}, {6, 3, 10});             // z leg, west (inner corner)
    box({8, 0, -0.2}, {8.2, 3, 10.2});        // east, both legs
    box({5.8, 0, 10}, {8.2, 3, 10.2});        // z leg, north end
    s.lights.push_back(point_light({1, 2, 1}, 8));
    set_grid(s, {0.25, 0.25, 0.25}, {7.75, 2.75, 9.25}, {5 * density + 1, 2 * density + 1, 6 * density + 1});
    ls.scene = std::move(s);
    const OccluderBvh bvh(ls.scene.occluders);
    std::mt19937_64 rng(seed);
    sample_region(bvh, {6 - kCell, 0, 0}, {8, 3, 2}, Side::kLit, false, per_face, 2 * per_face, rng, ls.points);
    sample_region(bvh, {6, 0, 2}, {8, 3, 2 + kCell}, Side::kDark, false, per_face, 2 * per_face, rng, ls.points);
    keep_shadowed_dark(ls, bvh);
    return ls;
}

inline LeakScene window_room(int per_face = 24, std::uint64_t seed = 3) {
    LeakScene ls;
    ls.name = "window room (sky)";
    ls.cell = kCell;
    Scene s = empty_scene();
    auto box = [&](Vec3 lo, Vec3 hi) { s.occluders.push_back(box_occluder(lo, hi)); };
    box({-0.2, -0.2, -0.2}, {8, 0, 6.2});   // floor and the ground outside
    box({-0.2, 3, -0.2}, {5.2, 3.2, 6.2});  // ceiling
    box({-0.2, 0, 0}, {0, 3, 6});           // west
    box({-0.2, 0, -0.2}, {5.2, 3, 0});      // south
    box({-0.2, 0, 6}, {5.2, 3, 6.2});       // north
    box({5, 0, 0}, {5.2, 1, 6});            // east wall: below the window
    box({5, 2, 0}, {5.2, 3, 6});            // above it
    box({5, 1, 0}, {5.2, 2, 2});            // beside it
    box({5, 1, 4}, {5.2, 2, 6});
    SceneSky sky;
    sky.kind = SkyKind::kConstant;
    sky.radiance = {1, 1, 1};
    s.sky = sky;
    set_grid(s, {0.25, 0.25, 0.25}, {7.75, 2.75, 5.75}, {6, 3, 5});
    ls.scene = std::move(s);
    const OccluderBvh bvh(ls.scene.occluders);
    std::mt19937_64 rng(seed);
    sample_region(bvh, {5.2, 0, 0}, {5.2 + kCell, 3, 6}, Side::kLit, false, per_face, 2 * per_face, rng, ls.points);
    sample_region(bvh, {5 - kCell, 0, 0}, {5, 3, 6}, Side::kDark, false, per_face, 2 * per_face, rng, ls.points);
    return ls;
}

// The hollow box: outer [2.3, 0.8, 2.3]..[3.7, 2.2, 3.7] minus the inner air
// [2.4, 0.9, 2.4]..[3.6, 2.1, 3.6]; the probe (3, 1.5, 3) lies inside it.
constexpr double kBoxLo = 2.3, kBoxHi = 3.7, kBoxYLo = 0.8, kBoxYHi = 2.2, kBoxWall = 0.1;

// density: the probe grid's cells split density times per axis (1: the suite's 1.375 m).
inline LeakScene closed_box(int per_face = 24, std::uint64_t seed = 4, std::uint32_t density = 1) {
    LeakScene ls;
    ls.name = "closed box in a lit room";
    ls.cell = 1.375;
    Scene s = empty_scene();
    auto box = [&](Vec3 lo, Vec3 hi) { s.occluders.push_back(box_occluder(lo, hi)); };
    box({-0.2, -0.2, -0.2}, {6.2, 0, 6.2});
    box({-0.2, 3, -0.2}, {6.2, 3.2, 6.2});
    box({-0.2, 0, 0}, {0, 3, 6});
    box({6, 0, 0}, {6.2, 3, 6});
    box({-0.2, 0, -0.2}, {6.2, 3, 0});
    box({-0.2, 0, 6}, {6.2, 3, 6.2});
    const double a = kBoxLo, b = kBoxHi, y0 = kBoxYLo, y1 = kBoxYHi, d = kBoxWall;
    box({a, y0, a}, {b, y0 + d, b});          // bottom
    box({a, y1 - d, a}, {b, y1, b});          // top
    box({a, y0 + d, a}, {a + d, y1 - d, b});  // -x
    box({b - d, y0 + d, a}, {b, y1 - d, b});  // +x
    box({a + d, y0 + d, a}, {b - d, y1 - d, a + d});  // -z
    box({a + d, y0 + d, b - d}, {b - d, y1 - d, b});  // +z
    s.lights.push_back(point_light({1, 2.5, 1}, 8));
    set_grid(s, {0.25, 0.25, 0.25}, {5.75, 2.75, 5.75}, {4 * density + 1, 2 * density + 1, 4 * density + 1});
    ls.scene = std::move(s);
    const OccluderBvh bvh(ls.scene.occluders);
    std::mt19937_64 rng(seed);
    const double c = ls.cell;
    // Lit: the air within one cell of the box's outside (floor, ceiling, the box's outer faces).
    sample_region(bvh, {a - c, 0, a - c}, {b + c, 3, b + c}, Side::kLit, false, per_face, 2 * per_face, rng, ls.points,
                  {a, y0, a}, {b, y1, b});
    sample_region(bvh, {a, y0, a}, {b, y1, b}, Side::kLit, true, per_face, 0, rng, ls.points);
    // Dark: the air inside the box.
    sample_region(bvh, {a + d, y0 + d, a + d}, {b - d, y1 - d, b - d}, Side::kDark, false, per_face, 2 * per_face, rng,
                  ls.points);
    keep_shadowed_dark(ls, bvh);
    return ls;
}

// Every scene of the suite: the two rooms at offsets x thicknesses, then the other three.
inline const std::vector<double>& wall_offsets() {
    static const std::vector<double> v{0.0, 0.2, 0.4, 0.5, 0.6, 0.8};
    return v;
}
inline const std::vector<double>& wall_thicknesses() {
    static const std::vector<double> v{0.02, 0.10, 0.20};
    return v;
}
inline std::vector<LeakScene> suite_scenes(int per_face = 24) {
    std::vector<LeakScene> scenes;
    for (double th : wall_thicknesses())
        for (double off : wall_offsets()) scenes.push_back(two_rooms(off, th, per_face));
    scenes.push_back(l_corridor(per_face));
    scenes.push_back(window_room(per_face));
    scenes.push_back(closed_box(per_face));
    return scenes;
}

// ---- ground truth -----------------------------------------------------------------------------

// zhc's normalised irradiance (mean of the RGB channels) at p for normal n, direct light only.
inline double exact_irradiance(const Scene& s, const OccluderBvh& bvh, Vec3 p, Vec3 n,
                               const std::vector<Vec3>& sky_dirs) {
    n = normalize_or(n, {0, 0, 1});
    double e = 0;
    for (const SceneLight& l : s.lights) {
        if (l.kind != LightKind::kPoint) continue;  // the suite has point lights only
        const Vec3 v = l.position - p;
        const double d = length(v), c = dot(n, v) / d;
        if (!(d > 0) || c <= 0) continue;
        if (l.shadows && !bvh.empty() && bvh.occluded(p, (1.0 / d) * v, 1e-9, d)) continue;
        e += (double(l.color.r) + double(l.color.g) + double(l.color.b)) / 3.0 * c / (M_PI * d * d);
    }
    if (s.sky) {
        double sum = 0;
        for (const Vec3& dir : sky_dirs) {
            const double c = dot(n, dir);
            if (c <= 0) continue;
            if (!bvh.empty() && bvh.occluded(p, dir, 1e-9, std::numeric_limits<double>::infinity())) continue;
            double rgb[3];
            sky_radiance(*s.sky, dir, rgb);
            sum += (rgb[0] + rgb[1] + rgb[2]) / 3.0 * c;
        }
        e += 4.0 * sum / double(sky_dirs.size());
    }
    return e;
}

inline std::vector<double> truth_of(const LeakScene& ls) {
    const OccluderBvh bvh(ls.scene.occluders);
    const std::vector<Vec3> dirs = sphere_sample_directions(kTruthSkyDirections);
    std::vector<double> t;
    t.reserve(ls.points.size());
    for (const ShadingPoint& sp : ls.points) t.push_back(exact_irradiance(ls.scene, bvh, sp.p, sp.n, dirs));
    return t;
}

// ---- bake and volumes -------------------------------------------------------------------------

// Two bakes of one scene: every probe at its grid point (occlusion.move_probes false, visibility
// masks traced), written without leak data (plain) and with validity + masks; and the default bake
// (probes kept out of walls, codec/bake/leak_planes.h) with validity + planes, as `zhc bake`
// writes it. shadow_planes false: one plane per cell that follows geometry only
// (occlusion.shadow_planes and occlusion.corner_regions false: the candidate study's scheme,
// tests/leak_candidates.h).
struct Baked {
    std::vector<Sh3Radiance> probes;  // at the grid points
    ProbeLeakData leak;
    BakeReport report;
    std::vector<std::uint8_t> plain_zhp, masked_zhp;  // sh3 .zhp without / with validity + masks
    std::vector<Sh3Radiance> planes_probes;           // the default bake
    ProbeLeakData planes_leak;
    BakeReport planes_report;
    std::vector<std::uint8_t> planes_zhp;             // sh3 .zhp with validity + planes
    std::string error;                                 // non-empty: the bake or a write failed
};

inline Baked bake_volumes(const LeakScene& ls, int threads = 1, bool shadow_planes = true) {
    Baked b;
    BakeOptions opt;
    opt.threads = threads;
    opt.visibility_masks = true;
    Scene in_place = ls.scene;
    in_place.occlusion.move_probes = false;
    auto probes = bake_scene(in_place, opt, &b.report, &b.leak);
    if (!probes) {
        b.error = ls.name + ": " + probes.error().message;
        return b;
    }
    b.probes = std::move(*probes);
    auto set = encode_probe_set(b.probes, "sh3", {}, probe_layout(ls.scene.probes));
    if (!set) {
        b.error = ls.name + ": " + set.error().message;
        return b;
    }
    auto plain = serialize_probe_set(*set);
    set->validity = b.leak.validity;
    set->visibility = b.leak.visibility;
    auto masked = serialize_probe_set(*set);
    if (!plain || !masked) {
        b.error = ls.name + ": cannot write the .zhp";
        return b;
    }
    b.plain_zhp = std::move(*plain);
    b.masked_zhp = std::move(*masked);
    BakeOptions def;
    def.threads = threads;
    Scene defaults = ls.scene;
    defaults.occlusion.shadow_planes = shadow_planes && ls.scene.occlusion.shadow_planes;
    defaults.occlusion.corner_regions = shadow_planes && ls.scene.occlusion.corner_regions;
    auto moved = bake_scene(defaults, def, &b.planes_report, &b.planes_leak);
    if (!moved) {
        b.error = ls.name + ": " + moved.error().message;
        return b;
    }
    b.planes_probes = std::move(*moved);
    auto pset = encode_probe_set(b.planes_probes, "sh3", {}, probe_layout(ls.scene.probes));
    if (!pset) {
        b.error = ls.name + ": " + pset.error().message;
        return b;
    }
    pset->validity = b.planes_leak.validity;
    pset->planes = b.planes_leak.planes;
    auto pz = serialize_probe_set(*pset);
    if (!pz) {
        b.error = ls.name + ": cannot write the .zhp with planes";
        return b;
    }
    b.planes_zhp = std::move(*pz);
    return b;
}

// Irradiance (RGB mean) of a volume at every shading point through zhc_volume_irradiance.
inline std::vector<double> sample_points(const zhc_volume& v, const std::vector<ShadingPoint>& pts) {
    std::vector<double> e;
    e.reserve(pts.size());
    for (const ShadingPoint& sp : pts) {
        const float p[3] = {float(sp.p.x), float(sp.p.y), float(sp.p.z)}, n[3] = {float(sp.n.x), float(sp.n.y), float(sp.n.z)};
        float rgb[3];
        zhc_volume_irradiance(&v, p, n, rgb);
        e.push_back((double(rgb[0]) + double(rgb[1]) + double(rgb[2])) / 3.0);
    }
    return e;
}

// The SH3 floor: a probe baked at each shading point itself (a positions bake, same rays),
// evaluated as a one-probe volume: what no interpolation scheme can beat.
inline std::vector<double> at_point_sh3(const LeakScene& ls, int threads = 1) {
    Scene s = ls.scene;
    s.probes = {};
    s.probes.kind = ProbePlacementKind::kPositions;
    for (const ShadingPoint& sp : ls.points) s.probes.positions.push_back(sp.p);
    BakeOptions opt;
    opt.threads = threads;
    auto probes = bake_scene(s, opt);
    std::vector<double> e;
    if (!probes) return e;
    zhc_probe_format f;
    if (zhc_probe_format_init(&f, "sh3") != ZHC_OK) return e;
    const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
    const std::uint32_t counts[3] = {1, 1, 1};
    for (size_t i = 0; i < ls.points.size(); ++i) {
        float sh[27];
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) sh[c * 3 + k] = (*probes)[i][c][k];
        zhc_volume v;
        if (zhc_volume_init(&v, &f, sh, sizeof sh, origin, spacing, counts) != ZHC_OK) return {};
        ShadingPoint at = ls.points[i];
        at.p = {0, 0, 0};
        e.push_back(sample_points(v, {at})[0]);
    }
    return e;
}

// ---- metrics ----------------------------------------------------------------------------------

struct Metrics {
    double lit_mean = 0, dark_mean = 0;
    double leak = 0;       // dark_mean / lit_mean
    double lit_error = 0;  // mean |E - E_true| over lit points / mean E_true over lit points
};

inline Metrics metrics(const std::vector<ShadingPoint>& pts, const std::vector<double>& e, const std::vector<double>& truth) {
    Metrics m;
    double lit = 0, dark = 0, err = 0, tlit = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        if (pts[i].side == Side::kLit) {
            m.lit_mean += e[i];
            err += std::fabs(e[i] - truth[i]);
            tlit += truth[i];
            ++lit;
        } else {
            m.dark_mean += e[i];
            ++dark;
        }
    }
    m.lit_mean /= std::max(1.0, lit);
    m.dark_mean /= std::max(1.0, dark);
    m.leak = m.lit_mean > 0 ? m.dark_mean / m.lit_mean : 0;
    m.lit_error = tlit > 0 ? err / tlit : 0;
    return m;
}

// One scene measured: the truth's own dark/lit ratio, the SH3 floor, plain, masks and planes.
struct Measured {
    std::size_t probes = 0, invalid = 0, lit_points = 0, dark_points = 0;
    Metrics truth, floor, plain, masks, planes;
    double mask_bytes_per_probe = 0;    // extra .zhp bytes per probe of validity + visibility
    double planes_bytes_per_probe = 0;  // extra .zhp bytes per probe of validity + planes
    std::vector<double> truth_e, plain_e, masks_e, planes_e;
};

inline bool open_volume(const std::vector<std::uint8_t>& zhp, zhc_volume* v) {
    return zhc_volume_from_zhp(v, zhp.data(), zhp.size()) == ZHC_OK;
}

inline Measured measure(const LeakScene& ls, const Baked& b, bool with_floor = true) {
    Measured m;
    m.probes = b.probes.size();
    m.invalid = std::size_t(b.report.invalid_probes);
    for (const ShadingPoint& sp : ls.points) (sp.side == Side::kLit ? m.lit_points : m.dark_points) += 1;
    m.truth_e = truth_of(ls);
    m.truth = metrics(ls.points, m.truth_e, m.truth_e);
    if (with_floor) {
        const std::vector<double> f = at_point_sh3(ls);
        if (f.size() == ls.points.size()) m.floor = metrics(ls.points, f, m.truth_e);
    }
    zhc_volume plain, masked, planes;
    if (!open_volume(b.plain_zhp, &plain) || !open_volume(b.masked_zhp, &masked) || !open_volume(b.planes_zhp, &planes)) return m;
    m.plain_e = sample_points(plain, ls.points);
    m.masks_e = sample_points(masked, ls.points);
    m.planes_e = sample_points(planes, ls.points);
    m.plain = metrics(ls.points, m.plain_e, m.truth_e);
    m.masks = metrics(ls.points, m.masks_e, m.truth_e);
    m.planes = metrics(ls.points, m.planes_e, m.truth_e);
    m.mask_bytes_per_probe = m.probes ? double(b.masked_zhp.size() - b.plain_zhp.size()) / double(m.probes) : 0;
    m.planes_bytes_per_probe = m.probes ? double(b.planes_zhp.size() - b.plain_zhp.size()) / double(m.probes) : 0;
    return m;
}

}  // namespace zhc::leak
