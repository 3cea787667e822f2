#include "occluders.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace zhc {
namespace {

void bounds_of(const Occluder& o, double lo[3], double hi[3]) {
    for (int a = 0; a < 3; ++a) {
        if (o.kind == OccluderKind::kSphere) {
            lo[a] = o.center[a] - o.radius;
            hi[a] = o.center[a] + o.radius;
        } else {
            lo[a] = o.min[a];
            hi[a] = o.max[a];
        }
    }
}

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

}  // namespace

bool ray_hits(const Occluder& occ, Vec3 o, Vec3 d, double t_min, double t_max) {
    if (occ.kind == OccluderKind::kSphere) {
        // |o + t d - c|^2 = r^2 with |d| = 1: t^2 + 2 b t + c = 0, b = d.(o - c), c = |o - c|^2 - r^2.
        const Vec3 oc = o - occ.center;
        const double b = dot(d, oc), c = dot(oc, oc) - occ.radius * occ.radius;
        if (c <= 0.0) return true;  // origin inside (or on) the sphere
        const double disc = b * b - c;
        if (disc < 0.0) return false;
        const double s = std::sqrt(disc);
        const double t_near = -b - s, t_far = -b + s;
        // Any t of [t_near, t_far] inside (t_min, t_max)?
        return t_far > t_min && t_near < t_max;
    }
    double lo[3] = {occ.min.x, occ.min.y, occ.min.z}, hi[3] = {occ.max.x, occ.max.y, occ.max.z};
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && o[a] >= lo[a] && o[a] <= hi[a];
    if (inside) return true;
    double enter = 0;
    // Open interval: the box must be entered strictly after t_min and before t_max.
    if (!slab(lo, hi, o, d, t_min, t_max, &enter)) return false;
    return enter < t_max;
}

OccluderBvh::OccluderBvh(std::vector<Occluder> occluders) : prims_(std::move(occluders)) {
    if (prims_.empty()) return;
    nodes_.reserve(2 * prims_.size());
    build(0, static_cast<std::uint32_t>(prims_.size()), 0);
}

std::uint32_t OccluderBvh::build(std::uint32_t first, std::uint32_t count, int depth) {
    const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    Node n;
    for (int a = 0; a < 3; ++a) {
        n.lo[a] = std::numeric_limits<double>::infinity();
        n.hi[a] = -std::numeric_limits<double>::infinity();
    }
    double clo[3], chi[3];  // centroid bounds
    for (int a = 0; a < 3; ++a) {
        clo[a] = std::numeric_limits<double>::infinity();
        chi[a] = -std::numeric_limits<double>::infinity();
    }
    for (std::uint32_t i = first; i < first + count; ++i) {
        double lo[3], hi[3];
        bounds_of(prims_[i], lo, hi);
        for (int a = 0; a < 3; ++a) {
            n.lo[a] = std::min(n.lo[a], lo[a]);
            n.hi[a] = std::max(n.hi[a], hi[a]);
            const double c = 0.5 * (lo[a] + hi[a]);
            clo[a] = std::min(clo[a], c);
            chi[a] = std::max(chi[a], c);
        }
    }
    if (count <= 4 || depth > 40) {
        n.first = first;
        n.count = count;
        nodes_[index] = n;
        return index;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
    const std::uint32_t mid = first + count / 2;
    // nth_element is deterministic for a given input; ties broken by the original order via a
    // stable key (centroid, then index is not needed: equal keys in any order give the same tree
    // bounds, and the query result is order independent).
    std::nth_element(prims_.begin() + first, prims_.begin() + mid, prims_.begin() + first + count,
                     [axis](const Occluder& a, const Occluder& b) {
                         double alo[3], ahi[3], blo[3], bhi[3];
                         bounds_of(a, alo, ahi);
                         bounds_of(b, blo, bhi);
                         return alo[axis] + ahi[axis] < blo[axis] + bhi[axis];
                     });
    n.count = 0;
    n.left = build(first, mid - first, depth + 1);
    n.right = build(mid, first + count - mid, depth + 1);
    nodes_[index] = n;
    return index;
}

bool OccluderBvh::occluded(Vec3 o, Vec3 d, double t_min, double t_max) const {
    if (nodes_.empty()) return false;
    // Per-ray constants of the slab test (ZERO direction components handled by the origin test).
    const double org[3] = {o.x, o.y, o.z}, dir[3] = {d.x, d.y, d.z};
    double inv[3];
    for (int a = 0; a < 3; ++a) inv[a] = dir[a] != 0.0 ? 1.0 / dir[a] : 0.0;
    auto node_hit = [&](const Node& n) {
        double t0 = t_min, t1 = t_max;
        for (int a = 0; a < 3; ++a) {
            if (dir[a] == 0.0) {
                if (org[a] < n.lo[a] || org[a] > n.hi[a]) return false;
                continue;
            }
            double ta = (n.lo[a] - org[a]) * inv[a], tb = (n.hi[a] - org[a]) * inv[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = ta > t0 ? ta : t0;
            t1 = tb < t1 ? tb : t1;
            if (t0 > t1) return false;
        }
        return true;
    };
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = nodes_[stack[--top]];
        // A node is entered when the clipped ray overlaps its box (this includes an origin inside
        // it: then t0 <= t_min <= t1).
        if (!node_hit(n)) {
            bool inside = true;
            for (int a = 0; a < 3; ++a) inside = inside && org[a] >= n.lo[a] && org[a] <= n.hi[a];
            if (!inside) continue;
        }
        if (n.count > 0) {
            for (std::uint32_t i = n.first; i < n.first + n.count; ++i)
                if (ray_hits(prims_[i], o, d, t_min, t_max)) return true;
        } else if (top + 2 <= 128) {
            stack[top++] = n.left;
            stack[top++] = n.right;
        }
    }
    return false;
}

}  // namespace zhc
