// zhc/codec/bake/scene_setup.cpp — the default scene, probe placement, scene validation and the
// bake report's summary (codec/bake/scene.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "codec/bake/bake_internal.h"
#include "codec/bake/scene.h"

namespace zhc {
using namespace bake_detail;

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
            if (m.textured() && !(m.base_factor[k] >= 0 && m.base_factor[k] <= 1)) return bad(at + ": base colour factor must be in [0, 1]");
        }
        if (m.textured() && !(m.metallic >= 0 && m.metallic <= 1)) return bad(at + ": metallic must be in [0, 1]");
        for (const SceneMaterial::UvTransform* t : {&m.base_uv, &m.metal_rough_uv, &m.emissive_uv})
            for (float f : *t)
                if (!std::isfinite(f)) return bad(at + ": texture UV transform must be finite");
        for (int t : {m.base_texture, m.metal_rough_texture, m.emissive_texture})
            if (t < -1 || (t >= 0 && static_cast<size_t>(t) >= s.textures.size()))
                return bad(at + ": texture " + std::to_string(t) + " is not in textures");
    }
    for (size_t i = 0; i < s.textures.size(); ++i) {
        const SceneTexture& t = s.textures[i];
        if (t.width == 0 || t.height == 0 || t.texels.size() != std::size_t(t.width) * t.height * 3)
            return bad("textures[" + std::to_string(i) + "]: needs width x height x 3 texels, width and height > 0");
        for (float f : t.texels)
            if (!std::isfinite(f) || f < 0) return bad("textures[" + std::to_string(i) + "]: texels must be finite and >= 0");
    }
    for (size_t i = 0; i < s.surfaces.size(); ++i) {
        const SurfaceUv& u = s.surfaces[i];
        if (u.material >= s.materials.size())
            return bad("surfaces[" + std::to_string(i) + "]: material " + std::to_string(u.material) + " is not in materials");
        for (const auto& c : u.uv)
            if (!std::isfinite(c[0]) || !std::isfinite(c[1])) return bad("surfaces[" + std::to_string(i) + "]: UV is not finite");
    }
    if (s.transport.max_bounces < 0 || s.transport.max_bounces > 1024) return bad("transport.bounces must be in [0, 1024]");
    if (!(s.transport.max_noise > 0 && s.transport.max_noise <= 1)) return bad("transport.max_noise must be in (0, 1]");
    if (s.transport.min_rays < 1 || s.transport.max_rays < s.transport.min_rays || s.transport.max_rays > (1 << 20))
        return bad("transport: need 1 <= min_rays <= max_rays <= 1048576");
    for (size_t i = 0; i < s.occluders.size(); ++i) {
        const Occluder& o = s.occluders[i];
        const std::string at = "occluders[" + std::to_string(i) + "]";
        if (is_surface(o.material)) {
            if (o.kind != OccluderKind::kTriangle || (o.material & ~kSurfaceBit) >= s.surfaces.size())
                return bad(at + ": surface " + std::to_string(o.material & ~kSurfaceBit) + " is not in surfaces (or not a triangle)");
        } else if (o.material != kNoMaterial && o.material >= s.materials.size()) {
            return bad(at + ": material " + std::to_string(o.material) + " is not in materials");
        }
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

std::vector<std::string> BakeReport::leak_lines() const {
    std::vector<std::string> out;
    if (!validity_checked) return out;
    char buf[512];
    std::snprintf(buf, sizeof buf, "probe validity (the same %llu rays/probe): %llu of %llu probes inside geometry, %llu dilated (%.3f ms)",
                  static_cast<unsigned long long>(probes ? occlusion_rays / probes : 0), static_cast<unsigned long long>(invalid_probes),
                  static_cast<unsigned long long>(probes), static_cast<unsigned long long>(dilated_probes), dilation_ms);
    out.push_back(buf);
    if (moved_out + left_inside + left_near + moved_towards > 0) {
        std::snprintf(buf, sizeof buf,
                      "probes kept out of walls: %llu in or near geometry at their grid points: %llu baked at a clear point nearby, "
                      "%llu left inside geometry (invalid, dilated), %llu left near it; %llu moved towards a wall (%llu rays, %.3f ms)",
                      static_cast<unsigned long long>(moved_out + left_inside + left_near), static_cast<unsigned long long>(moved_out),
                      static_cast<unsigned long long>(left_inside), static_cast<unsigned long long>(left_near),
                      static_cast<unsigned long long>(moved_towards), static_cast<unsigned long long>(relocation_rays), relocation_ms);
        out.push_back(buf);
    }
    if (planes.cells > 0) {
        const PlaneFitStats& p = planes;
        const std::uint64_t blocked = p.blocked_pairs + p.unresolved_pairs, leaking = p.leaking_pairs + p.unresolved_pairs;
        std::snprintf(buf, sizeof buf,
                      "cell planes: %llu of %llu cells crossed by geometry or a shadow edge have a plane, %llu along a light's shadow "
                      "edge, %llu of them corner regions (%llu cells; %llu rays, %.3f ms)",
                      static_cast<unsigned long long>(p.planes), static_cast<unsigned long long>(p.crossed_cells),
                      static_cast<unsigned long long>(p.shadow_planes), static_cast<unsigned long long>(p.regions),
                      static_cast<unsigned long long>(p.cells),
                      static_cast<unsigned long long>(p.rays), plane_ms);
        out.push_back(buf);
        if (blocked > 0)
            std::snprintf(buf, sizeof buf,
                          "leak estimate: %llu of %llu blocked (sample point, probe) pairs in those cells still blend (%.2f %%); "
                          "%llu visible pairs dropped (%.2f %% of the pairs)",
                          static_cast<unsigned long long>(leaking), static_cast<unsigned long long>(blocked),
                          100.0 * double(leaking) / double(blocked), static_cast<unsigned long long>(p.dropped_pairs),
                          p.pairs ? 100.0 * double(p.dropped_pairs) / double(p.pairs) : 0.0);
        else
            std::snprintf(buf, sizeof buf, "leak estimate: no geometry or shadow edge crosses a cell: nothing to separate");
        out.push_back(buf);
    }
    return out;
}

}  // namespace zhc
