#include "codec/bake/occluders.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace zhc {
static_assert(sizeof(Occluder) == 80, "Occluder: the material index lives in the padding after kind");
namespace {

// Slab test: the parameter interval where the ray is inside [lo, hi], clipped to (t0, t1).
// Division by a zero direction component gives +-inf, which the min/max handle; a NaN (0 * inf
// when the origin lies on a slab plane) is avoided by testing the origin against the slab.
bool slab(const double lo[3], const double hi[3], Vec3 o, Vec3 d, double t0, double t1, double* enter) {
    for (int a = 0; a < 3; ++a) {
        const double da = d[a], oa = o[a];
        if (da == 0.0) {
            if (oa < lo[a] || oa > hi[a]) return false;
            continue;
        }
        const double inv = 1.0 / da;
        double ta = (lo[a] - oa) * inv, tb = (hi[a] - oa) * inv;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    if (enter) *enter = t0;
    return true;
}

// Moller-Trumbore (1997): solve o + t d = v0 + u e1 + v e2 by Cramer's rule with
// det = e1 . (d x e2). Policy in occluders.h: det == 0 (parallel, or a degenerate triangle) misses;
// inclusive barycentric bounds widened by 1e-10; t in the open interval (t_min, t_max); both faces.
// Returns 0 (miss), 1 (front face) or 2 (back face), and the hit distance in *t_out.
inline int ray_triangle_face(Vec3 v0, Vec3 v1, Vec3 v2, Vec3 o, Vec3 d, double t_min, double t_max, double* t_out) {
    const Vec3 e1 = v1 - v0, e2 = v2 - v0;
    const Vec3 p = cross(d, e2);
    const double det = dot(e1, p);
    if (det == 0.0 || !std::isfinite(det)) return 0;
    const double inv = 1.0 / det;
    const Vec3 s = o - v0;
    // Barycentric tolerance: Moller-Trumbore computes u, v per triangle, so on a shared edge the
    // two neighbours can both reject by a few ulps (not watertight). Growing every triangle by a
    // relative 1e-10 of its edges closes such cracks (rounding errors are ~1e-15 for well-posed
    // rays) while moving its boundary by far less than any scene feature.
    constexpr double kBary = 1e-10;
    const double u = dot(s, p) * inv;
    if (u < -kBary || u > 1.0 + kBary) return 0;
    const Vec3 q = cross(s, e1);
    const double v = dot(d, q) * inv;
    if (v < -kBary || u + v > 1.0 + kBary) return 0;
    const double t = dot(e2, q) * inv;
    if (!(t > t_min && t < t_max)) return 0;
    *t_out = t;
    // det = e1 . (d x e2) = -d . (e1 x e2): det < 0 when d runs along the normal (a back face).
    return det < 0 ? 2 : 1;
}

bool ray_hits_triangle(Vec3 v0, Vec3 v1, Vec3 v2, Vec3 o, Vec3 d, double t_min, double t_max) {
    double t;
    return ray_triangle_face(v0, v1, v2, o, d, t_min, t_max, &t) != 0;
}

}  // namespace

bool inside_solid(const Occluder& occ, Vec3 p) {
    if (occ.kind == OccluderKind::kSphere) {
        const Vec3 v = p - occ.center();
        return dot(v, v) <= occ.radius() * occ.radius();
    }
    if (occ.kind == OccluderKind::kBox)
        return p.x >= occ.min().x && p.x <= occ.max().x && p.y >= occ.min().y && p.y <= occ.max().y && p.z >= occ.min().z &&
               p.z <= occ.max().z;
    return false;
}

RayHit ray_nearest(const Occluder& occ, Vec3 o, Vec3 d, double t_min, double t_max) {
    RayHit h;
    if (occ.kind == OccluderKind::kTriangle) {
        double t = 0;
        const int face = ray_triangle_face(occ.v0, occ.v1, occ.v2, o, d, t_min, t_max, &t);
        if (face) h = {true, face == 2, t};
        return h;
    }
    if (inside_solid(occ, o)) return {true, true, t_min};
    if (occ.kind == OccluderKind::kSphere) {
        const Vec3 oc = o - occ.center();
        const double b = dot(d, oc), c = dot(oc, oc) - occ.radius() * occ.radius();
        const double disc = b * b - c;
        if (disc < 0.0) return h;
        const double t_near = -b - std::sqrt(disc);
        if (t_near > t_min && t_near < t_max) h = {true, false, t_near};
        return h;
    }
    double lo[3] = {occ.min().x, occ.min().y, occ.min().z}, hi[3] = {occ.max().x, occ.max().y, occ.max().z};
    double enter = 0;
    if (slab(lo, hi, o, d, t_min, t_max, &enter) && enter < t_max) h = {true, false, enter};
    return h;
}

Vec3 surface_normal(const Occluder& occ, Vec3 x, Vec3 d) {
    Vec3 n{0, 0, 1};
    if (occ.kind == OccluderKind::kTriangle) {
        n = normalize_or(cross(occ.v1 - occ.v0, occ.v2 - occ.v0), {0, 0, 1});
    } else if (occ.kind == OccluderKind::kSphere) {
        n = normalize_or(x - occ.center(), {0, 0, 1});
    } else {
        // The face whose plane is nearest to x.
        double best = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 3; ++a)
            for (int side = 0; side < 2; ++side) {
                const double dist = std::fabs(x[a] - (side ? occ.max()[a] : occ.min()[a]));
                if (dist < best) {
                    best = dist;
                    n = {0, 0, 0};
                    (a == 0 ? n.x : a == 1 ? n.y : n.z) = side ? 1.0 : -1.0;
                }
            }
    }
    return dot(n, d) > 0 ? -1.0 * n : n;
}

bool ray_triangle_plane(const Occluder& tri, Vec3 o, Vec3 d, double* t, bool* back) {
    // The expressions of ray_triangle_face, in the same order: the same t to the last bit.
    const Vec3 e1 = tri.v1 - tri.v0, e2 = tri.v2 - tri.v0;
    const Vec3 p = cross(d, e2);
    const double det = dot(e1, p);
    if (det == 0.0 || !std::isfinite(det)) return false;
    const double inv = 1.0 / det;
    const Vec3 s = o - tri.v0;
    const Vec3 q = cross(s, e1);
    *t = dot(e2, q) * inv;
    *back = det < 0;
    return true;
}

void occluder_bounds(const Occluder& o, Vec3* lo, Vec3* hi) {
    if (o.kind == OccluderKind::kSphere) {
        const Vec3 r{o.radius(), o.radius(), o.radius()};
        *lo = o.center() - r;
        *hi = o.center() + r;
    } else if (o.kind == OccluderKind::kTriangle) {
        *lo = {std::min({o.v0.x, o.v1.x, o.v2.x}), std::min({o.v0.y, o.v1.y, o.v2.y}), std::min({o.v0.z, o.v1.z, o.v2.z})};
        *hi = {std::max({o.v0.x, o.v1.x, o.v2.x}), std::max({o.v0.y, o.v1.y, o.v2.y}), std::max({o.v0.z, o.v1.z, o.v2.z})};
    } else {
        *lo = o.min();
        *hi = o.max();
    }
}

Occluder triangle_occluder(Vec3 a, Vec3 b, Vec3 c) {
    Occluder o;
    o.kind = OccluderKind::kTriangle;
    o.v0 = a;
    o.v1 = b;
    o.v2 = c;
    return o;
}

Occluder sphere_occluder(Vec3 c, double r) {
    Occluder o;
    o.kind = OccluderKind::kSphere;
    o.v0 = c;
    o.v1 = {r, 0, 0};
    return o;
}

Occluder box_occluder(Vec3 lo, Vec3 hi) {
    Occluder o;
    o.kind = OccluderKind::kBox;
    o.v0 = lo;
    o.v1 = hi;
    return o;
}

std::vector<Occluder> uv_sphere_triangles(Vec3 c, double r, int n_lat, int n_lon) {
    std::vector<Occluder> out;
    auto at = [&](int i, int j) {
        const double th = kPi * i / n_lat, ph = 2 * kPi * j / n_lon;
        return c + r * Vec3{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
    };
    for (int i = 0; i < n_lat; ++i)
        for (int j = 0; j < n_lon; ++j) {
            const Vec3 a = at(i, j), b = at(i + 1, j), cc = at(i + 1, j + 1), d = at(i, j + 1);
            if (i != n_lat - 1) out.push_back(triangle_occluder(a, b, cc));
            if (i != 0) out.push_back(triangle_occluder(a, cc, d));
        }
    return out;
}

bool ray_hits(const Occluder& occ, Vec3 o, Vec3 d, double t_min, double t_max) {
    if (occ.kind == OccluderKind::kTriangle) return ray_hits_triangle(occ.v0, occ.v1, occ.v2, o, d, t_min, t_max);
    if (occ.kind == OccluderKind::kSphere) {
        // |o + t d - c|^2 = r^2 with |d| = 1: t^2 + 2 b t + c = 0, b = d.(o - c), c = |o - c|^2 - r^2.
        const Vec3 oc = o - occ.center();
        const double b = dot(d, oc), c = dot(oc, oc) - occ.radius() * occ.radius();
        if (c <= 0.0) return true;  // origin inside (or on) the sphere
        const double disc = b * b - c;
        if (disc < 0.0) return false;
        const double s = std::sqrt(disc);
        const double t_near = -b - s, t_far = -b + s;
        // Any t of [t_near, t_far] inside (t_min, t_max)?
        return t_far > t_min && t_near < t_max;
    }
    double lo[3] = {occ.min().x, occ.min().y, occ.min().z}, hi[3] = {occ.max().x, occ.max().y, occ.max().z};
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && o[a] >= lo[a] && o[a] <= hi[a];
    if (inside) return true;
    double enter = 0;
    // Open interval: the box must be entered strictly after t_min and before t_max.
    if (!slab(lo, hi, o, d, t_min, t_max, &enter)) return false;
    return enter < t_max;
}

}  // namespace zhc
