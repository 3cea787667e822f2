// zhc/codec/bake/scene.cpp — the bake: the effects per probe in blocks (closed forms, shadows, the
// occlusion pass), reflected light (codec/bake/transport.h), dilation of invalid probes and the
// visibility masks. The lights' closed forms are in lights.cpp, validation and placement in
// scene_setup.cpp.
#include "codec/bake/scene.h"

#include "codec/bake/bake_internal.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <thread>

namespace zhc {
using namespace bake_detail;
namespace {

using Clock = std::chrono::steady_clock;

// One effect of the bake: what to add to a probe at position p.
struct Effect {
    enum Kind { kConstantSh, kLight } kind = kLight;
    double sh[27] = {};            // kConstantSh: environment or sky, the same at every probe
    bool distant = false;          // environment or sky: occluded by the occlusion pass
    const SceneLight* light = nullptr;
    bool traced = false;           // light with shadows and a non-empty occluder set
    std::vector<Vec3> unit_cone;   // cone samples around +Z (rotated per probe), traced cone lights
    std::vector<double> cos_phi, sin_phi;  // sphere lights: the spiral's azimuths (sigma varies per probe)
};

// Shadowed contribution of a light at p: closed form minus the occluded sample directions.
void add_light_shadowed(const Effect& e, const OccluderBvh& bvh, Vec3 p, double acc[27], std::uint64_t* rays) {
    const SceneLight& l = *e.light;
    double local[27] = {};
    add_light_closed_form(l, p, local);
    // Punctual: one ray.
    auto punctual = [&](Vec3 dir, double t_max) {
        ++*rays;
        if (!bvh.occluded(p, dir, kRayEpsilon, t_max))
            for (int i = 0; i < 27; ++i) acc[i] += local[i];
    };
    Vec3 axis;
    double cos_s = 1;
    Rgb radiance = l.color;
    bool sphere = false, inside = false;
    switch (l.kind) {
        case LightKind::kPoint:
        case LightKind::kSpot: {
            const Vec3 v = l.position - p;
            const double d = length(v);
            if (!(d > 0)) return;
            punctual((1.0 / d) * v, d);
            return;
        }
        case LightKind::kDirectional:
            if (l.angular_radius_rad <= 0) {
                punctual(normalize_or(l.direction, {0, 0, 1}), std::numeric_limits<double>::infinity());
                return;
            }
            axis = normalize_or(l.direction, {0, 0, 1});
            cos_s = std::cos(l.angular_radius_rad);
            {
                const double s = std::sin(l.angular_radius_rad);
                for (int k = 0; k < 3; ++k) radiance[k] = static_cast<float>(l.color[k] / (s * s));
            }
            break;
        case LightKind::kHemisphere:
            axis = normalize_or(l.direction, {0, 0, 1});
            cos_s = 0;
            break;
        case LightKind::kSphere: {
            sphere = true;
            const Vec3 v = l.center - p;
            const double d2 = dot(v, v), r2 = l.radius * l.radius;
            if (d2 <= r2) {
                inside = true;
                axis = {0, 0, 1};
                cos_s = -1;
            } else {
                const double d = std::sqrt(d2);
                axis = (1.0 / d) * v;
                cos_s = std::sqrt(1.0 - r2 / d2);
            }
            break;
        }
    }
    // Cone light: the fixed sample set (built around +Z for this light's sigma, except sphere
    // lights whose sigma depends on the probe) rotated onto the axis.
    const int n = l.shadow_samples;
    const double solid_angle = 2.0 * kPi * (1.0 - cos_s);
    const double w = solid_angle / n;
    const Mat3 frame = frame_from_z(axis);
    int blocked = 0;
    double removed[27] = {};
    for (int k = 0; k < n; ++k) {
        Vec3 local_dir;
        if (!e.unit_cone.empty()) {
            local_dir = e.unit_cone[static_cast<size_t>(k)];
        } else {
            const double z = 1.0 - (k + 0.5) / n * (1.0 - cos_s);
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
            local_dir = {r * e.cos_phi[static_cast<size_t>(k)], r * e.sin_phi[static_cast<size_t>(k)], z};
        }
        const Vec3 d = frame * local_dir;
        double t_max = std::numeric_limits<double>::infinity();
        if (sphere) {
            // Distance to the light's surface along d (near root; far root from inside).
            const Vec3 v = l.center - p;
            const double b = dot(d, v), disc = std::max(0.0, b * b - dot(v, v) + l.radius * l.radius);
            t_max = inside ? b + std::sqrt(disc) : b - std::sqrt(disc);
        }
        ++*rays;
        if (bvh.occluded(p, d, kRayEpsilon, t_max)) {
            ++blocked;
            const double wk[3] = {w * radiance.r, w * radiance.g, w * radiance.b};
            add_weighted_basis(d, wk, removed);
        }
    }
    if (blocked == n) return;  // fully shadowed: exactly nothing
    for (int i = 0; i < 27; ++i) acc[i] += local[i] - (blocked ? removed[i] : 0.0);
}

}  // namespace

namespace {

using bake_detail::parallel_blocks;


}  // namespace

namespace bake_detail {

// The visibility mask of grid probe (x, y, z): bit (cx + 2 cy + 4 cz) set when the probe is
// visible from the cell on its side (cx, cy, cz). A cell beyond the grid keeps its bit set (it is
// never sampled). Per cell kMaskPoints points (the centre, centre +- spacing/4 per axis); a point
// inside a box/sphere occluder does not vote; the bit is set when at least half of the voting
// points reach the probe unblocked (all points inside solids: set). The rays go to `target`: the
// probe's grid position in the bake, a moved position in the leak study (tests/leak_candidates.h).
std::uint8_t grid_visibility_mask(const OccluderBvh& bvh, const ProbeGrid& g, std::uint32_t x, std::uint32_t y,
                                  std::uint32_t z, Vec3 target, std::uint64_t* rays) {
    const std::uint32_t idx[3] = {x, y, z};
    const Vec3 p{g.origin.x + x * g.spacing.x, g.origin.y + y * g.spacing.y, g.origin.z + z * g.spacing.z};
    std::uint8_t mask = 0;
    for (int c = 0; c < 8; ++c) {
        const int side[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
        double centre[3], half[3];
        bool inside_grid = true;
        for (int a = 0; a < 3; ++a) {
            const std::uint32_t n = g.counts[static_cast<size_t>(a)];
            const double pa = a == 0 ? p.x : (a == 1 ? p.y : p.z), s = g.spacing[a];
            if (n <= 1) {  // a flat axis: the sampled "cell" is the probe's own plane
                if (side[a] == 0) inside_grid = false;
                centre[a] = pa;
                half[a] = 0;
                continue;
            }
            // Cell on side 0 spans [i - 1, i], on side 1 [i, i + 1].
            if ((side[a] == 0 && idx[a] == 0) || (side[a] == 1 && idx[a] + 1 >= n)) inside_grid = false;
            centre[a] = pa + (side[a] ? 0.5 : -0.5) * s;
            half[a] = 0.25 * s;
        }
        if (!inside_grid) {
            mask = static_cast<std::uint8_t>(mask | (1u << c));
            continue;
        }
        int votes = 0, reach = 0;
        for (int k = 0; k < kMaskPoints; ++k) {
            Vec3 q{centre[0], centre[1], centre[2]};
            if (k > 0) {
                const int b = k - 1;
                q = {centre[0] + ((b & 1) ? half[0] : -half[0]), centre[1] + ((b & 2) ? half[1] : -half[1]),
                     centre[2] + ((b & 4) ? half[2] : -half[2])};
            }
            if (bvh.inside_any_solid(q)) continue;
            ++votes;
            const Vec3 v = target - q;
            const double len = length(v);
            if (!(len > 2 * kRayEpsilon)) {
                ++reach;
                continue;
            }
            ++*rays;
            if (!bvh.occluded(q, (1.0 / len) * v, kRayEpsilon, len - kRayEpsilon)) ++reach;
        }
        if (votes == 0 || 2 * reach >= votes) mask = static_cast<std::uint8_t>(mask | (1u << c));
    }
    return mask;
}

}  // namespace bake_detail

namespace {
Result<std::vector<Sh3Radiance>> bake_with(const Scene& scene, const OccluderBvh& bvh, bool transport, double bvh_ms,
                                           Clock::time_point t_start, const BakeOptions& options, BakeReport* report,
                                           ProbeLeakData* leak);
}  // namespace

bool bake_traces_occluders(const Scene& scene) {
    if (scene.occluders.empty()) return false;
    if (scene_has_transport(scene)) return true;
    // Sky occlusion of the distant lighting, probe validity and visibility masks (grids), shadows.
    const bool grid = scene.probes.kind == ProbePlacementKind::kGrid;
    if (scene.occlusion.sky_samples > 0 && (scene.environment || scene.sky || grid)) return true;
    for (const SceneLight& l : scene.lights)
        if (l.shadows) return true;
    return false;
}

Result<std::vector<Sh3Radiance>> bake_scene(const Scene& scene, const BakeOptions& options, BakeReport* report,
                                            ProbeLeakData* leak) {
    const auto t_start = Clock::now();
    if (Status s = validate_scene(scene); !s) return s.error();
    const auto t_bvh = Clock::now();
    // No tree when no effect traces (the bake is the same: every effect sees no occluders then).
    const OccluderBvh bvh = bake_traces_occluders(scene) ? OccluderBvh(scene.occluders) : OccluderBvh();
    const double bvh_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_bvh).count();
    return bake_with(scene, bvh, scene_has_transport(scene), bvh_ms, t_start, options, report, leak);
}

Result<std::vector<Sh3Radiance>> bake_scene(Scene&& scene, const BakeOptions& options, BakeReport* report,
                                            ProbeLeakData* leak) {
    const auto t_start = Clock::now();
    if (Status s = validate_scene(scene); !s) return s.error();
    const auto t_bvh = Clock::now();
    const bool traced = bake_traces_occluders(scene);
    const bool transport = scene_has_transport(scene);
    const OccluderBvh bvh = traced ? OccluderBvh(std::move(scene.occluders)) : OccluderBvh();
    std::vector<Occluder>().swap(scene.occluders);
    const double bvh_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_bvh).count();
    return bake_with(scene, bvh, transport, bvh_ms, t_start, options, report, leak);
}

namespace {

// The bake of a validated scene whose occluders are in `bvh` (scene.occluders is not read).
Result<std::vector<Sh3Radiance>> bake_with(const Scene& scene, const OccluderBvh& bvh, bool transport, double bvh_ms,
                                           Clock::time_point t_start, const BakeOptions& options, BakeReport* report,
                                           ProbeLeakData* leak) {
    if (leak) *leak = {};
    std::vector<Vec3> positions = probe_positions(scene.probes);
    const size_t count = positions.size();
    const bool grid = scene.probes.kind == ProbePlacementKind::kGrid;
    const int n_occ = bvh.empty() ? 0 : scene.occlusion.sky_samples;
    const bool occlude_distant = n_occ > 0 && (scene.environment || scene.sky);
    const bool validity = n_occ > 0 && grid;
    const bool tracing = occlude_distant || validity;

    // Effects in scene order: environment, sky, lights.
    std::vector<Effect> effects;
    std::vector<BakeEffect> info;
    const std::string occluded_method = "occluded: " + std::to_string(n_occ) + " rays/probe";
    if (scene.environment) {
        const SceneEnvironment& env = *scene.environment;
        Sh3Radiance sh = env.projected;
        if (env.rotation_rad != 0) sh = rotate(sh, rotation_axis_angle({0, 0, 1}, env.rotation_rad));
        Effect e;
        e.kind = Effect::kConstantSh;
        e.distant = true;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) e.sh[i * 3 + k] = double(sh[i][k]) * env.intensity;
        effects.push_back(std::move(e));
        const std::string orientation = env.label.empty() && env.latlong_map ? std::string(", ") + latlong_convention_name(env.latlong) + " lat-long" : "";
        info.push_back({env.label.empty() ? "environment" : env.label,
                        (env.label.empty() ? "projected once" + orientation : std::string("SH coefficients")) +
                            std::string(env.rotation_rad != 0 ? ", rotated" : "") +
                            (occlude_distant ? ", " + occluded_method : std::string()), 0, 0});
    }
    if (scene.sky) {
        const SceneSky& sky = *scene.sky;
        Effect e;
        e.kind = Effect::kConstantSh;
        e.distant = true;
        if (sky.kind == SkyKind::kConstant) {
            for (int k = 0; k < 3; ++k) e.sh[k] = 2.0 * std::sqrt(kPi) * sky.radiance[k];  // L00 of constant radiance
        } else {
            const Sh3Radiance sh = project_gradient_sky(sky.gradient);
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) e.sh[i * 3 + k] = sh[i][k];
        }
        effects.push_back(std::move(e));
        info.push_back({sky.kind == SkyKind::kConstant ? "sky (constant)" : "sky (gradient)",
                        occlude_distant ? occluded_method : "closed form", 0, 0});
    }
    size_t last_distant = 0;  // index + 1 of the last distant effect (0: none)
    for (size_t ei = 0; ei < effects.size(); ++ei)
        if (effects[ei].distant) last_distant = ei + 1;
    // Occlusion directions and, per direction, what its blocking removes: (4 pi / N) L(d) Y(d)
    // summed over the distant effects (the environment's radiance is its SH3 evaluated at d).
    std::vector<Vec3> dirs;
    std::vector<double> removal;
    if (tracing) {
        dirs = sphere_sample_directions(n_occ);
        if (occlude_distant) {
            removal.assign(dirs.size() * 27, 0.0);
            const double w = 4.0 * kPi / n_occ;
            for (size_t k = 0; k < dirs.size(); ++k) {
                const auto y = sh3_basis(dirs[k]);
                double L[3] = {0, 0, 0};
                if (scene.environment) {
                    const double* env = effects[0].sh;
                    for (int i = 0; i < 9; ++i)
                        for (int c = 0; c < 3; ++c) L[c] += env[i * 3 + c] * y[static_cast<size_t>(i)];
                }
                if (scene.sky) {
                    double sky[3];
                    sky_radiance(*scene.sky, dirs[k], sky);
                    for (int c = 0; c < 3; ++c) L[c] += sky[c];
                }
                for (int i = 0; i < 9; ++i)
                    for (int c = 0; c < 3; ++c) removal[k * 27 + static_cast<size_t>(i * 3 + c)] = w * L[c] * y[static_cast<size_t>(i)];
            }
        }
    }
    for (const SceneLight& l : scene.lights) {
        Effect e;
        e.kind = Effect::kLight;
        e.light = &l;
        e.traced = l.shadows && !bvh.empty();
        if (e.traced && (l.kind == LightKind::kDirectional || l.kind == LightKind::kHemisphere) &&
            !(l.kind == LightKind::kDirectional && l.angular_radius_rad <= 0)) {
            const double sigma = l.kind == LightKind::kHemisphere ? kPi / 2 : l.angular_radius_rad;
            e.unit_cone = cone_sample_directions({0, 0, 1}, sigma, l.shadow_samples);
        }
        if (e.traced && l.kind == LightKind::kSphere) {
            // The same azimuths as cone_sample_directions (golden-angle steps).
            const double golden = kPi * (3.0 - std::sqrt(5.0));
            for (int k = 0; k < l.shadow_samples; ++k) {
                e.cos_phi.push_back(std::cos(golden * k));
                e.sin_phi.push_back(std::sin(golden * k));
            }
        }
        if (!e.traced && (l.kind == LightKind::kDirectional || l.kind == LightKind::kHemisphere)) {
            // Distant lights do not depend on the probe position: evaluate once, add everywhere
            // (the same additions as per probe, so the same bytes).
            e.kind = Effect::kConstantSh;
            add_light_closed_form(l, {0, 0, 0}, e.sh);
        }
        effects.push_back(std::move(e));
        info.push_back({effect_name(l), "closed form", 0, 0});
    }

    const std::uint64_t invalid_limit =
        static_cast<std::uint64_t>(std::floor(scene.occlusion.invalid_fraction * n_occ));  // invalid: back > limit
    // Grids with occluders: where each probe is baked (leak_planes.h), with the validity test of
    // the occlusion pass below (the same directions and limit, so both agree on every probe).
    const ProbeLayout layout = probe_layout(scene.probes);
    const InsideTest inside_test{&dirs, invalid_limit};
    const LeakPlacementOptions placement;
    ProbeRelocation reloc;
    double reloc_ms = 0;
    if (validity && scene.occlusion.move_probes) {
        const auto t_reloc = Clock::now();
        reloc = relocate_grid_probes(bvh, layout.grid, inside_test, placement, true, std::max(1, options.threads));
        positions = reloc.positions;
        reloc_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_reloc).count();
    }

    // Probes in blocks; each block runs the occlusion pass, then the effects in order into a
    // double accumulator. Blocks are independent, so any thread count gives the same bytes.
    // Reflected light: a path tracer over the same tree; its probes are costly, so blocks are small.
    std::optional<PathTracer> tracer;
    if (transport && !bvh.empty()) {
        tracer.emplace(scene, bvh);
        info.push_back({"reflected light", "path traced", 0, 0});
    }
    const size_t kBlock = tracer ? 16 : 1024;
    const size_t blocks = (count + kBlock - 1) / kBlock;
    const int threads = std::max(1, std::min<int>(options.threads, static_cast<int>(std::max<size_t>(blocks, 1))));
    std::vector<Sh3Radiance> out(count);
    std::vector<std::uint8_t> valid(validity ? count : 0, 1);
    std::vector<std::vector<double>> ms(static_cast<size_t>(threads), std::vector<double>(effects.size() + 1, 0.0));
    std::vector<PathTracer::ProbeStats> tstats(tracer ? count : 0);
    std::vector<double> tms(static_cast<size_t>(threads), 0.0);
    std::vector<std::vector<std::uint64_t>> rays(static_cast<size_t>(threads),
                                                 std::vector<std::uint64_t>(effects.size() + 1, 0));
    std::mutex progress_mutex;
    std::uint64_t probes_done = 0;
    parallel_blocks(count, kBlock, threads, [&](size_t lo, size_t hi, int t) {
        std::vector<double> acc((hi - lo) * 27, 0.0);
        std::vector<int> blocked(hi - lo, 0);
        std::vector<double> removed(occlude_distant ? (hi - lo) * 27 : 0, 0.0);
        const size_t tz = static_cast<size_t>(t);
        if (tracing) {
            const auto t0 = Clock::now();
            for (size_t p = lo; p < hi; ++p) {
                int nb = 0;
                std::uint64_t back = 0;
                for (size_t k = 0; k < dirs.size(); ++k) {
                    bool hit;
                    if (validity) {
                        const RayHit h = bvh.nearest(positions[p], dirs[k], kRayEpsilon, std::numeric_limits<double>::infinity());
                        hit = h.hit;
                        back += h.back;
                    } else {
                        hit = bvh.occluded(positions[p], dirs[k], kRayEpsilon, std::numeric_limits<double>::infinity());
                    }
                    if (!hit) continue;
                    ++nb;
                    if (occlude_distant)
                        for (int i = 0; i < 27; ++i) removed[(p - lo) * 27 + static_cast<size_t>(i)] += removal[k * 27 + static_cast<size_t>(i)];
                }
                blocked[p - lo] = nb;
                if (validity && back > invalid_limit) valid[p] = 0;
            }
            rays[tz][effects.size()] += (hi - lo) * dirs.size();
            ms[tz][effects.size()] += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        }
        for (size_t ei = 0; ei < effects.size(); ++ei) {
            const Effect& e = effects[ei];
            const auto t0 = Clock::now();
            if (e.kind == Effect::kConstantSh) {
                for (size_t p = lo; p < hi; ++p) {
                    // A distant effect seen by no ray adds nothing (exactly zero).
                    if (e.distant && occlude_distant && blocked[p - lo] == n_occ) continue;
                    for (int i = 0; i < 27; ++i) acc[(p - lo) * 27 + static_cast<size_t>(i)] += e.sh[i];
                }
                if (occlude_distant && ei + 1 == last_distant)
                    for (size_t p = lo; p < hi; ++p)
                        if (blocked[p - lo] > 0 && blocked[p - lo] < n_occ)
                            for (int i = 0; i < 27; ++i)
                                acc[(p - lo) * 27 + static_cast<size_t>(i)] -= removed[(p - lo) * 27 + static_cast<size_t>(i)];
            } else if (!e.traced) {
                for (size_t p = lo; p < hi; ++p) add_light_closed_form(*e.light, positions[p], &acc[(p - lo) * 27]);
            } else {
                std::uint64_t r = 0;
                for (size_t p = lo; p < hi; ++p) add_light_shadowed(e, bvh, positions[p], &acc[(p - lo) * 27], &r);
                rays[tz][ei] += r;
            }
            ms[tz][ei] += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        }
        if (tracer) {
            const auto t0 = Clock::now();
            // Invalid probes are dilated from their valid neighbours below: not traced.
            for (size_t p = lo; p < hi; ++p)
                if (!validity || valid[p]) tstats[p] = tracer->trace_probe(positions[p], p, &acc[(p - lo) * 27], &acc[(p - lo) * 27]);
            tms[tz] += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        }
        for (size_t p = lo; p < hi; ++p)
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k)
                    out[p][i][k] = static_cast<float>(acc[(p - lo) * 27 + static_cast<size_t>(i * 3 + k)]);
        if (options.progress) {
            const std::lock_guard<std::mutex> lock(progress_mutex);
            probes_done += hi - lo;
            options.progress(probes_done, count);
        }
    });

    // Dilation: each invalid probe becomes the inverse-distance blend of the valid probes of the
    // nearest grid shell (Chebyshev distance 1..kDilationShells) holding any, visited z, y, x
    // ascending and summed in double. Only baked valid probes are read, so the order of the
    // invalid probes does not matter.
    const auto t_dil = Clock::now();
    std::uint64_t invalid = 0, dilated = 0;
    if (validity) {
        const auto& g = layout.grid;
        const long nx = g.counts[0], ny = g.counts[1], nz = g.counts[2];
        // Written in place: only valid probes are read and only invalid ones written, so the
        // order of the probes does not matter.
        for (size_t i = 0; i < count; ++i) {
            if (valid[i]) continue;
            ++invalid;
            const long x = static_cast<long>(i % static_cast<size_t>(nx)), y = static_cast<long>((i / static_cast<size_t>(nx)) % static_cast<size_t>(ny)),
                       z = static_cast<long>(i / (static_cast<size_t>(nx) * static_cast<size_t>(ny)));
            for (long r = 1; r <= kDilationShells; ++r) {
                double sum[27] = {}, wsum = 0;
                for (long dz = -r; dz <= r; ++dz)
                    for (long dy = -r; dy <= r; ++dy)
                        for (long dx = -r; dx <= r; ++dx) {
                            if (std::max({std::labs(dx), std::labs(dy), std::labs(dz)}) != r) continue;
                            const long X = x + dx, Y = y + dy, Z = z + dz;
                            if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
                            const size_t j = static_cast<size_t>(X + nx * (Y + ny * Z));
                            if (!valid[j]) continue;
                            const double d = std::sqrt(std::pow(dx * g.spacing.x, 2) + std::pow(dy * g.spacing.y, 2) +
                                                       std::pow(dz * g.spacing.z, 2));
                            const double w = 1.0 / d;
                            wsum += w;
                            for (int c = 0; c < 9; ++c)
                                for (int k = 0; k < 3; ++k) sum[c * 3 + k] += w * out[j][c][k];
                        }
                if (wsum > 0) {
                    for (int c = 0; c < 9; ++c)
                        for (int k = 0; k < 3; ++k) out[i][c][k] = static_cast<float>(sum[c * 3 + k] / wsum);
                    ++dilated;
                    break;
                }
            }
        }
    }
    const double dil_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_dil).count();

    // The planes per cell, fitted to the probes where they were baked (asked for, grid, occluders).
    double plane_ms = 0;
    PlaneFitStats plane_stats;
    if (leak && validity) {
        const auto t_plane = Clock::now();
        leak->validity = valid;
        leak->baked_positions = positions;
        // The hard shadow edges the planes follow in open air (leak_planes.h "Shadow planes").
        std::vector<ShadowLight> shadow_lights;
        for (const SceneLight& l : scene.lights) {
            if (!l.shadows || !scene.occlusion.shadow_planes) continue;
            ShadowLight sl;
            sl.intensity = 0.2126 * l.color.r + 0.7152 * l.color.g + 0.0722 * l.color.b;
            if (l.kind == LightKind::kDirectional && l.angular_radius_rad <= 0) {
                sl.directional = true;
                sl.direction = l.direction;
            } else if (l.kind == LightKind::kPoint || l.kind == LightKind::kSpot) {
                sl.position = l.position;
                if (l.kind == LightKind::kSpot) {
                    sl.spot_axis = l.direction;
                    sl.cos_outer = std::cos(l.outer_angle_rad);
                }
            } else {
                continue;  // cone lights: soft shadows
            }
            if (sl.intensity > 0) shadow_lights.push_back(sl);
        }
        leak->planes = cell_planes_bytes(fit_cell_planes(bvh, layout.grid, positions, valid, placement.lattice,
                                                         std::max(1, options.threads), &plane_stats, nullptr,
                                                         shadow_lights, scene.occlusion.corner_regions));
        plane_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_plane).count();
    }

    // Visibility masks (asked for, grid, occluders).
    double mask_ms = 0;
    std::uint64_t mask_rays = 0;
    if (leak && validity && options.visibility_masks) {
        const auto t_mask = Clock::now();
        leak->visibility.assign(count, 0xFF);
        const auto& g = layout.grid;
        std::vector<std::uint64_t> mr(static_cast<size_t>(std::max(1, options.threads)), 0);
        parallel_blocks(count, kBlock, std::max(1, options.threads), [&](size_t lo, size_t hi, int t) {
            for (size_t i = lo; i < hi; ++i) {
                const std::uint32_t x = static_cast<std::uint32_t>(i % g.counts[0]),
                                    y = static_cast<std::uint32_t>((i / g.counts[0]) % g.counts[1]),
                                    z = static_cast<std::uint32_t>(i / (size_t(g.counts[0]) * g.counts[1]));
                leak->visibility[i] = grid_visibility_mask(bvh, g, x, y, z, positions[i], &mr[static_cast<size_t>(t)]);
            }
        });
        for (std::uint64_t r : mr) mask_rays += r;
        mask_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_mask).count();
    }

    if (report) {
        *report = BakeReport{};
        report->effects = info;
        report->probes = count;
        report->rays = 0;
        report->occluder_build_ms = bvh_ms;
        for (int t = 0; t < threads; ++t) {
            report->occlusion_ms += ms[static_cast<size_t>(t)][effects.size()];
            report->occlusion_rays += rays[static_cast<size_t>(t)][effects.size()];
        }
        for (size_t ei = 0; ei < effects.size(); ++ei) {
            BakeEffect& be = report->effects[ei];
            for (int t = 0; t < threads; ++t) {
                be.milliseconds += ms[static_cast<size_t>(t)][ei];
                be.rays += rays[static_cast<size_t>(t)][ei];
            }
            if (effects[ei].traced) be.method = "closed form, shadowed: " + std::to_string(be.rays) + " rays";
            // The first distant effect carries the occlusion pass's rays and time.
            if (effects[ei].distant && occlude_distant && ei == 0) {
                be.rays += report->occlusion_rays;
                be.milliseconds += report->occlusion_ms;
            }
            report->rays += be.rays;
        }
        if (tracing && !occlude_distant) report->rays += report->occlusion_rays;
        report->invalid_probes = invalid;
        report->dilated_probes = dilated;
        report->dilation_ms = dil_ms;
        report->mask_rays = mask_rays;
        report->mask_probes = leak && validity && options.visibility_masks ? count : 0;
        report->validity_checked = validity;
        report->mask_ms = mask_ms;
        report->rays += mask_rays;
        report->moved_out = reloc.moved_out;
        report->moved_towards = reloc.moved_towards;
        report->left_inside = reloc.left_inside;
        report->left_near = reloc.left_near;
        report->relocation_rays = reloc.rays;
        report->relocation_ms = reloc_ms;
        report->rays += reloc.rays;
        report->planes = plane_stats;
        report->plane_ms = plane_ms;
        report->rays += plane_stats.rays;
        if (tracer) {
            TransportReport& tr = report->transport;
            tr.traced = true;
            tr.max_bounces = scene.transport.max_bounces;
            tr.energy_left = tracer->energy_left();
            std::vector<double> noise;
            for (size_t p = 0; p < count; ++p) {
                const PathTracer::ProbeStats& st = tstats[p];
                if (st.paths == 0) continue;
                ++tr.probes;
                tr.paths += st.paths;
                tr.rays += st.rays;
                tr.vertices += st.vertices;
                tr.cut += st.cut;
                tr.max_depth = std::max(tr.max_depth, st.max_depth);
                noise.push_back(st.noise);
                if (st.noise > scene.transport.max_noise) ++tr.probes_over_noise;
            }
            if (!noise.empty()) {
                std::sort(noise.begin(), noise.end());
                tr.noise_median = noise[noise.size() / 2];
                tr.noise_max = noise.back();
            }
            for (double t : tms) tr.milliseconds += t;
            BakeEffect& be = report->effects.back();
            be.rays = tr.rays;
            be.milliseconds = tr.milliseconds;
            be.method = "path traced: " + std::to_string(tr.rays) + " rays";
            report->rays += tr.rays;
        }
        report->total_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_start).count();
    }
    return out;
}

}  // namespace

}  // namespace zhc
