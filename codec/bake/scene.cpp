#include "codec/bake/scene.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <thread>

namespace zhc {
namespace {

using Clock = std::chrono::steady_clock;

// Zonal factors of ZH3 paper Eq. 15 times the sqrt(4 pi / (2l + 1)) of the rotation to `axis`
// (Eq. 2), so a cone contributes  L * F_l(c, s2) * Y_lm(axis)  to coefficient (l, m):
//   f0 = sqrt(pi) (1 - c),  f1 = sqrt(3 pi) / 2 s^2,  f2 = sqrt(5 pi) / 2 c s^2.
const double kSqrtPi = std::sqrt(kPi);
const double kBand0 = std::sqrt(4.0 * kPi), kBand1 = std::sqrt(4.0 * kPi / 3.0), kBand2 = std::sqrt(4.0 * kPi / 5.0);

void add_weighted_basis(Vec3 d, const double w[3], double acc[27]) {
    const auto y = sh3_basis(d);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) acc[i * 3 + k] += w[k] * y[static_cast<size_t>(i)];
}

// Cone of half-angle sigma (cos_s = cos sigma, sin2 = sin^2 sigma) around unit `axis`.
void add_cone(Vec3 axis, double cos_s, double sin2, Rgb radiance, double acc[27]) {
    const double f[3] = {kSqrtPi * (1.0 - cos_s) * kBand0, std::sqrt(3.0 * kPi) / 2.0 * sin2 * kBand1,
                         std::sqrt(5.0 * kPi) / 2.0 * cos_s * sin2 * kBand2};
    const auto y = sh3_basis(axis);
    for (int i = 0; i < 9; ++i) {
        const int l = i == 0 ? 0 : (i < 4 ? 1 : 2);
        const double fy = f[l] * y[static_cast<size_t>(i)];
        for (int k = 0; k < 3; ++k) acc[i * 3 + k] += fy * radiance[k];
    }
}

void add_delta(Vec3 d, double scale, Rgb color, double acc[27]) {
    const double w[3] = {scale * color.r, scale * color.g, scale * color.b};
    add_weighted_basis(d, w, acc);
}

double smoothstep(double e0, double e1, double x) {
    if (e1 <= e0) return x >= e0 ? 1.0 : 0.0;
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool colour_ok(Rgb c) {
    for (int k = 0; k < 3; ++k)
        if (!std::isfinite(c[k]) || c[k] < 0) return false;
    return true;
}

// The cone a light subtends at p (for shadow sampling) and the distance to its surface along a
// sample direction. Returns false when the light is not a cone light at p.
struct ConeGeometry {
    Vec3 axis;
    double sigma = 0, cos_s = 1, sin2 = 0;
    Rgb radiance;
    bool finite_light = false;  // sphere light: rays stop at its surface
    bool inside = false;        // probe inside a sphere light: the whole sphere, rays to the far side
};

std::string effect_name(const SceneLight& l) {
    std::string n = l.kind == LightKind::kDirectional ? "sun" : light_kind_name(l.kind);
    if (l.kind == LightKind::kDirectional && l.angular_radius_rad == 0) n = "directional";
    if (!l.name.empty()) n += " '" + l.name + "'";
    return n;
}

// Shadow-ray start offset: rays start a hair off the probe so a probe lying exactly on an
// occluder's surface is not blocked by that surface's own boundary test. Scale-free enough for
// scenes in metres (1e-9 m).
constexpr double kRayEpsilon = 1e-9;

}  // namespace

const char* light_kind_name(LightKind kind) {
    switch (kind) {
        case LightKind::kDirectional: return "directional";
        case LightKind::kPoint: return "point";
        case LightKind::kSpot: return "spot";
        case LightKind::kSphere: return "sphere";
        case LightKind::kHemisphere: return "hemisphere";
    }
    return "?";
}

void add_light_closed_form(const SceneLight& light, Vec3 p, double acc[27]) {
    switch (light.kind) {
        case LightKind::kDirectional: {
            const Vec3 d = normalize_or(light.direction, {0, 0, 1});
            if (light.angular_radius_rad <= 0) {
                // A delta whose normalised irradiance on a facing surface is E: integral L dw = pi E.
                add_delta(d, kPi, light.color, acc);
            } else {
                const double s = std::sin(light.angular_radius_rad), c = std::cos(light.angular_radius_rad);
                const double to_radiance = 1.0 / (s * s);  // E = L sin^2 sigma (codec/bake/sky.h Sun)
                const Rgb L{float(light.color.r * to_radiance), float(light.color.g * to_radiance),
                            float(light.color.b * to_radiance)};
                add_cone(d, c, s * s, L, acc);
            }
            return;
        }
        case LightKind::kPoint:
        case LightKind::kSpot: {
            const Vec3 v = light.position - p;
            const double d2 = dot(v, v);
            if (!(d2 > 0)) return;  // probe at the light: undefined, contributes nothing (docs/scene.md)
            const double d = std::sqrt(d2);
            const Vec3 w = (1.0 / d) * v;
            double scale = 1.0 / d2;  // inverse square: integral L dw = I / d^2
            if (light.kind == LightKind::kSpot) {
                const Vec3 axis = normalize_or(light.direction, {0, 0, -1});
                scale *= smoothstep(std::cos(light.outer_angle_rad), std::cos(light.inner_angle_rad), -dot(axis, w));
                if (scale == 0) return;
            }
            add_delta(w, scale, light.color, acc);
            return;
        }
        case LightKind::kSphere: {
            const Vec3 v = light.center - p;
            const double d2 = dot(v, v), r2 = light.radius * light.radius;
            if (d2 <= r2) {  // inside: constant radiance over the whole sphere, L00 = 2 sqrt(pi) L
                for (int k = 0; k < 3; ++k) acc[k] += 2.0 * kSqrtPi * light.color[k];
                return;
            }
            const double d = std::sqrt(d2);
            const double sin2 = r2 / d2;  // sin sigma = r / d
            add_cone((1.0 / d) * v, std::sqrt(1.0 - sin2), sin2, light.color, acc);
            return;
        }
        case LightKind::kHemisphere:
            add_cone(normalize_or(light.direction, {0, 0, 1}), 0.0, 1.0, light.color, acc);
            return;
    }
}

std::vector<Vec3> cone_sample_directions(Vec3 axis, double sigma, int count) {
    // Equal-area spiral over the cap: z uniform in [cos sigma, 1] (Archimedes: equal z steps are
    // equal areas), azimuth stepped by the golden angle pi (3 - sqrt 5).
    std::vector<Vec3> out;
    if (count <= 0) return out;
    out.reserve(static_cast<size_t>(count));
    const Mat3 frame = frame_from_z(normalize_or(axis, {0, 0, 1}));
    const double c = std::cos(sigma), golden = kPi * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < count; ++k) {
        const double z = 1.0 - (k + 0.5) / count * (1.0 - c);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = golden * k;
        out.push_back(frame * Vec3{r * std::cos(phi), r * std::sin(phi), z});
    }
    return out;
}

std::vector<Vec3> sphere_sample_directions(int count) { return fibonacci_sphere(count); }

void sky_radiance(const SceneSky& sky, Vec3 d, double rgb[3]) {
    if (sky.kind == SkyKind::kConstant) {
        for (int k = 0; k < 3; ++k) rgb[k] = sky.radiance[k];
        return;
    }
    const GradientSky& g = sky.gradient;
    const double z = dot(normalize_or(g.up, {0, 0, 1}), d);
    for (int k = 0; k < 3; ++k)
        rgb[k] = z >= 0 ? double(g.horizon[k]) + (double(g.zenith[k]) - g.horizon[k]) * z : double(g.ground[k]);
}

Scene default_scene() {
    Scene s;
    s.probes.kind = ProbePlacementKind::kGrid;
    s.probes.min = {-4, -4, 0.25};
    s.probes.max = {4, 4, 3.25};
    s.probes.counts = {8, 8, 4};
    SceneSky sky;
    sky.kind = SkyKind::kGradient;
    s.sky = sky;
    const Sun sun;
    SceneLight l;
    l.kind = LightKind::kDirectional;
    l.name = "sun";
    l.direction = sun.towards_sun;
    l.angular_radius_rad = sun.angular_radius_rad;
    l.color = sun.irradiance;
    l.shadows = true;
    l.shadow_samples = 16;
    s.lights.push_back(l);
    auto sphere = [&](const char* name, Vec3 c, double r, Rgb radiance, bool shadows) {
        SceneLight q;
        q.kind = LightKind::kSphere;
        q.name = name;
        q.center = c;
        q.radius = r;
        q.color = radiance;
        q.shadows = shadows;
        q.shadow_samples = 32;
        s.lights.push_back(q);
    };
    sphere("red", {-2.3, -1.2, 1.7}, 0.35, {40, 6, 3}, true);
    sphere("green", {2.2, -2.4, 0.8}, 0.3, {4, 30, 6}, false);
    sphere("blue", {1.2, 2.3, 2.7}, 0.4, {4, 10, 36}, true);
    // A roof over one corner (shades the sun there) and a pillar-like sphere between lights.
    s.occluders.push_back(box_occluder({-4.5, -4.5, 3.6}, {0.5, 0.5, 3.8}));
    s.occluders.push_back(sphere_occluder({-1.0, 0.6, 1.6}, 0.55));
    return s;
}

std::vector<Vec3> probe_positions(const ProbePlacement& pl) {
    if (pl.kind == ProbePlacementKind::kPositions) return pl.positions;
    std::vector<Vec3> out;
    const ProbeLayout layout = probe_layout(pl);
    const auto& g = layout.grid;
    out.reserve(static_cast<size_t>(g.counts[0]) * g.counts[1] * g.counts[2]);
    for (std::uint32_t z = 0; z < g.counts[2]; ++z)
        for (std::uint32_t y = 0; y < g.counts[1]; ++y)
            for (std::uint32_t x = 0; x < g.counts[0]; ++x)
                out.push_back({g.origin.x + x * g.spacing.x, g.origin.y + y * g.spacing.y, g.origin.z + z * g.spacing.z});
    return out;
}

ProbeLayout probe_layout(const ProbePlacement& pl) {
    ProbeLayout layout;
    if (pl.kind == ProbePlacementKind::kPositions) {
        layout.kind = ProbeLayoutKind::kPositions;
        for (const Vec3& p : pl.positions)
            layout.positions.push_back({float(p.x), float(p.y), float(p.z)});
        return layout;
    }
    layout.kind = ProbeLayoutKind::kGrid;
    layout.grid.counts = pl.counts;
    double origin[3], spacing[3];
    for (int a = 0; a < 3; ++a) {
        const double lo = pl.min[a], hi = pl.max[a];
        const std::uint32_t n = pl.counts[static_cast<size_t>(a)];
        // One probe along an axis sits in the middle of the bounds; its spacing is then the
        // extent (or 1 for a flat extent) so the stored grid stays well-formed.
        if (n <= 1) {
            origin[a] = 0.5 * (lo + hi);
            spacing[a] = hi > lo ? hi - lo : 1.0;
        } else {
            origin[a] = lo;
            spacing[a] = (hi - lo) / (n - 1);
        }
    }
    layout.grid.origin = {origin[0], origin[1], origin[2]};
    layout.grid.spacing = {spacing[0], spacing[1], spacing[2]};
    return layout;
}

Status validate_scene(const Scene& s) {
    auto bad = [](const std::string& what) { return Status(make_error(ErrorCode::kInvalidValue, "scene: " + what)); };
    if (s.probes.kind == ProbePlacementKind::kGrid) {
        if (!finite3(s.probes.min) || !finite3(s.probes.max)) return bad("probes.grid bounds are not finite");
        for (int a = 0; a < 3; ++a) {
            if (s.probes.min[a] > s.probes.max[a]) return bad("probes.grid: min > max on axis " + std::to_string(a));
            if (s.probes.counts[static_cast<size_t>(a)] == 0) return bad("probes.grid.counts must be >= 1");
        }
    } else {
        if (s.probes.positions.empty()) return bad("probes.positions is empty");
        for (const Vec3& p : s.probes.positions)
            if (!finite3(p)) return bad("probes.positions holds a non-finite position");
    }
    if (s.occlusion.sky_samples < 0 || s.occlusion.sky_samples > 65536)
        return bad("occlusion.sky_samples must be in [0, 65536]");
    if (!(s.occlusion.invalid_fraction >= 0 && s.occlusion.invalid_fraction <= 1))
        return bad("occlusion.invalid_fraction must be in [0, 1]");
    if (s.environment) {
        if (!std::isfinite(s.environment->intensity) || s.environment->intensity < 0)
            return bad("environment.intensity must be finite and >= 0");
        if (!std::isfinite(s.environment->rotation_rad)) return bad("environment.rotation is not finite");
    }
    for (size_t i = 0; i < s.lights.size(); ++i) {
        const SceneLight& l = s.lights[i];
        const std::string at = "lights[" + std::to_string(i) + "]";
        if (!colour_ok(l.color)) return bad(at + ": colour must be finite and >= 0");
        if (!finite3(l.position) || !finite3(l.center) || !finite3(l.direction)) return bad(at + ": non-finite vector");
        if (l.shadows && (l.shadow_samples < 1 || l.shadow_samples > 65536))
            return bad(at + ".shadow_samples must be in [1, 65536]");
        switch (l.kind) {
            case LightKind::kDirectional:
                if (!(l.angular_radius_rad >= 0 && l.angular_radius_rad < kPi / 2))
                    return bad(at + ".angular_radius must be in [0, 90) degrees");
                if (!(length(l.direction) > 0)) return bad(at + ".direction must be non-zero");
                break;
            case LightKind::kSpot:
                if (!(l.inner_angle_rad >= 0 && l.inner_angle_rad <= l.outer_angle_rad && l.outer_angle_rad <= kPi))
                    return bad(at + ": need 0 <= inner_angle <= outer_angle <= 180 degrees");
                if (!(length(l.direction) > 0)) return bad(at + ".direction must be non-zero");
                break;
            case LightKind::kSphere:
                if (!(l.radius > 0) || !std::isfinite(l.radius)) return bad(at + ".radius must be > 0");
                break;
            case LightKind::kHemisphere:
                if (!(length(l.direction) > 0)) return bad(at + ".direction must be non-zero");
                break;
            case LightKind::kPoint: break;
        }
    }
    for (size_t i = 0; i < s.materials.size(); ++i) {
        const SceneMaterial& m = s.materials[i];
        const std::string at = "materials[" + std::to_string(i) + "]";
        for (int k = 0; k < 3; ++k) {
            if (!(m.albedo[k] >= 0 && m.albedo[k] <= 1)) return bad(at + ": albedo must be in [0, 1]");
            if (!(m.emission[k] >= 0) || !std::isfinite(m.emission[k])) return bad(at + ": emission must be finite and >= 0");
        }
    }
    if (s.transport.max_bounces < 0 || s.transport.max_bounces > 1024) return bad("transport.bounces must be in [0, 1024]");
    if (!(s.transport.max_noise > 0 && s.transport.max_noise <= 1)) return bad("transport.max_noise must be in (0, 1]");
    if (s.transport.min_rays < 1 || s.transport.max_rays < s.transport.min_rays || s.transport.max_rays > (1 << 20))
        return bad("transport: need 1 <= min_rays <= max_rays <= 1048576");
    for (size_t i = 0; i < s.occluders.size(); ++i) {
        const Occluder& o = s.occluders[i];
        const std::string at = "occluders[" + std::to_string(i) + "]";
        if (o.material != kNoMaterial && o.material >= s.materials.size())
            return bad(at + ": material " + std::to_string(o.material) + " is not in materials");
        if (o.kind == OccluderKind::kSphere) {
            if (!finite3(o.center()) || !(o.radius() > 0) || !std::isfinite(o.radius()))
                return bad(at + ": sphere needs a finite centre and radius > 0");
        } else if (o.kind == OccluderKind::kTriangle) {
            if (!finite3(o.v0) || !finite3(o.v1) || !finite3(o.v2)) return bad(at + ": triangle vertex is not finite");
        } else {
            if (!finite3(o.min()) || !finite3(o.max())) return bad(at + ": box bounds are not finite");
            for (int a = 0; a < 3; ++a)
                if (o.min()[a] > o.max()[a]) return bad(at + ": box min > max on axis " + std::to_string(a));
        }
    }
    return Ok{};
}

std::string BakeReport::summary() const {
    std::string out;
    char buf[256];
    for (const BakeEffect& e : effects) {
        std::snprintf(buf, sizeof buf, "%s%s (%s): %.3f ms", out.empty() ? "" : "; ", e.name.c_str(), e.method.c_str(),
                      e.milliseconds);
        out += buf;
    }
    return out;
}

namespace {

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

// Runs fn(lo, hi, thread) over [0, count) in blocks of `block`, on `threads` threads. Each block is
// independent, so the results do not depend on the thread count.
template <class Fn>
void parallel_blocks(size_t count, size_t block, int threads, Fn&& fn) {
    const size_t blocks = (count + block - 1) / block;
    const int n = std::max(1, std::min<int>(threads, static_cast<int>(std::max<size_t>(blocks, 1))));
    std::atomic<size_t> next{0};
    auto worker = [&](int t) {
        for (size_t b = next++; b < blocks; b = next++) fn(b * block, std::min(count, (b + 1) * block), t);
    };
    if (n == 1) {
        worker(0);
        return;
    }
    std::vector<std::thread> pool;
    for (int t = 0; t < n; ++t) pool.emplace_back(worker, t);
    for (auto& th : pool) th.join();
}

// The visibility mask of grid probe (x, y, z): bit (cx + 2 cy + 4 cz) set when the probe is
// visible from the cell on its side (cx, cy, cz). A cell beyond the grid keeps its bit set (it is
// never sampled). Per cell kMaskPoints points (the centre, centre +- spacing/4 per axis); a point
// inside a box/sphere occluder does not vote; the bit is set when at least half of the voting
// points reach the probe unblocked (all points inside solids: set).
std::uint8_t grid_visibility_mask(const OccluderBvh& bvh, const ProbeGrid& g, std::uint32_t x, std::uint32_t y,
                                  std::uint32_t z, std::uint64_t* rays) {
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
            const Vec3 v = p - q;
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

}  // namespace

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
    const std::vector<Vec3> positions = probe_positions(scene.probes);
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
            for (int k = 0; k < 3; ++k) e.sh[k] = 2.0 * kSqrtPi * sky.radiance[k];
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
    const std::uint64_t invalid_limit =
        static_cast<std::uint64_t>(std::floor(scene.occlusion.invalid_fraction * n_occ));  // invalid: back > limit
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
    const ProbeLayout layout = probe_layout(scene.probes);
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

    // Visibility masks (asked for, grid, occluders).
    double mask_ms = 0;
    std::uint64_t mask_rays = 0;
    if (leak && validity) {
        const auto t_mask = Clock::now();
        leak->validity = valid;
        leak->visibility.assign(count, 0xFF);
        const auto& g = layout.grid;
        std::vector<std::uint64_t> mr(static_cast<size_t>(std::max(1, options.threads)), 0);
        parallel_blocks(count, kBlock, std::max(1, options.threads), [&](size_t lo, size_t hi, int t) {
            for (size_t i = lo; i < hi; ++i) {
                const std::uint32_t x = static_cast<std::uint32_t>(i % g.counts[0]),
                                    y = static_cast<std::uint32_t>((i / g.counts[0]) % g.counts[1]),
                                    z = static_cast<std::uint32_t>(i / (size_t(g.counts[0]) * g.counts[1]));
                leak->visibility[i] = grid_visibility_mask(bvh, g, x, y, z, &mr[static_cast<size_t>(t)]);
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
        report->mask_probes = leak && validity ? count : 0;
        report->validity_checked = validity;
        report->mask_ms = mask_ms;
        report->rays += mask_rays;
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
