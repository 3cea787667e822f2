#include "codec/bake/occluders.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace zhc {
static_assert(sizeof(Occluder) == 80, "Occluder: the material index lives in the padding after kind");
namespace {

void bounds_of(const Occluder& o, double lo[3], double hi[3]) {
    for (int a = 0; a < 3; ++a) {
        if (o.kind == OccluderKind::kSphere) {
            lo[a] = o.center()[a] - o.radius();
            hi[a] = o.center()[a] + o.radius();
        } else if (o.kind == OccluderKind::kTriangle) {
            lo[a] = std::min({o.v0[a], o.v1[a], o.v2[a]});
            hi[a] = std::max({o.v0[a], o.v1[a], o.v2[a]});
        } else {
            lo[a] = o.min()[a];
            hi[a] = o.max()[a];
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

OccluderBvh::OccluderBvh(const std::vector<Occluder>& occluders) : prims_(occluders) { build_tree(); }

OccluderBvh::OccluderBvh(std::vector<Occluder>&& occluders) : prims_(std::move(occluders)) {
    occluders.clear();
    occluders.shrink_to_fit();
    build_tree();
}

void OccluderBvh::build_tree() {
    if (prims_.empty()) return;
    prims_.shrink_to_fit();
    // Boxes once (a centroid is computed from its box where needed: the same doubles as storing it,
    // 24 bytes per primitive less at the build's peak); the build permutes indices, then the
    // primitives are put in leaf order (each leaf a contiguous range) in place, following the
    // permutation's cycles.
    std::vector<Bounds> bounds(prims_.size());
    for (size_t i = 0; i < prims_.size(); ++i) {
        bounds_of(prims_[i], bounds[i].lo, bounds[i].hi);
    }
    std::vector<std::uint32_t> order(prims_.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
    nodes_.reserve(prims_.size() + 1);  // leaves of 2..4 primitives: < n nodes
    build(order, bounds, 0, static_cast<std::uint32_t>(order.size()), 0);
    std::vector<Bounds>().swap(bounds);
    nodes_.shrink_to_fit();  // the reservation was the bound n + 1; leaves hold 2..4 primitives
    // prims_[i] becomes what prims_[order[i]] held: each cycle of the permutation rotated once.
    for (size_t start = 0; start < order.size(); ++start) {
        if (order[start] == start) continue;
        const Occluder first = prims_[start];
        size_t i = start;
        while (order[i] != start) {
            const size_t next = order[i];
            prims_[i] = prims_[next];
            order[i] = static_cast<std::uint32_t>(i);
            i = next;
        }
        prims_[i] = first;
        order[i] = static_cast<std::uint32_t>(i);
    }
}

std::uint32_t OccluderBvh::build(std::vector<std::uint32_t>& order, const std::vector<Bounds>& bounds,
                                 std::uint32_t first, std::uint32_t count, int depth) {
    const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    Node n;
    double clo[3], chi[3];  // centroid bounds
    for (int a = 0; a < 3; ++a) {
        n.lo[a] = clo[a] = std::numeric_limits<double>::infinity();
        n.hi[a] = chi[a] = -std::numeric_limits<double>::infinity();
    }
    for (std::uint32_t i = first; i < first + count; ++i) {
        const Bounds& b = bounds[order[i]];
        for (int a = 0; a < 3; ++a) {
            n.lo[a] = std::min(n.lo[a], b.lo[a]);
            n.hi[a] = std::max(n.hi[a], b.hi[a]);
            clo[a] = std::min(clo[a], b.centroid(a));
            chi[a] = std::max(chi[a], b.centroid(a));
        }
    }
    // Conservative node boxes: widened by a relative 1e-9 so rounding in the slab test never
    // rejects a ray that grazes a box face where a primitive's own (widened) test would hit, e.g.
    // a ray through the rim of a flat mesh whose box has zero thickness.
    for (int a = 0; a < 3; ++a) {
        const double pad = 1e-9 * std::max({n.hi[a] - n.lo[a], std::abs(n.lo[a]), std::abs(n.hi[a]), 1e-300});
        n.lo[a] -= pad;
        n.hi[a] += pad;
    }
    // Depth cap: median splits halve the count, so depth <= log2(n) + 1 < 40 for any n < 2^32;
    // the cap only guards the traversal stack.
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
    // Median split by centroid, ties broken by the primitive's index: a strict total order, so the
    // partition (and the whole tree) is the same for the same input on every run.
    std::nth_element(order.begin() + first, order.begin() + mid, order.begin() + first + count,
                     [&bounds, axis](std::uint32_t a, std::uint32_t b) {
                         const double ca = bounds[a].centroid(axis), cb = bounds[b].centroid(axis);
                         return ca < cb || (ca == cb && a < b);
                     });
    n.count = 0;
    n.axis = static_cast<std::uint8_t>(axis);
    n.left = build(order, bounds, first, mid - first, depth + 1);
    n.right = build(order, bounds, mid, first + count - mid, depth + 1);
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
            for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
                const Occluder& p = prims_[i];
                const bool hit = p.kind == OccluderKind::kTriangle
                                     ? ray_hits_triangle(p.v0, p.v1, p.v2, o, d, t_min, t_max)
                                     : ray_hits(p, o, d, t_min, t_max);
                if (hit) return true;
            }
        } else if (top + 2 <= 128) {
            // Nearer child (along the ray on the split axis) popped first: an any-hit query stops
            // sooner when the closer half blocks.
            if (dir[n.axis] < 0) {
                stack[top++] = n.left;
                stack[top++] = n.right;
            } else {
                stack[top++] = n.right;
                stack[top++] = n.left;
            }
        }
    }
    return false;
}

RayHit OccluderBvh::nearest(Vec3 o, Vec3 d, double t_min, double t_max) const {
    RayHit best;
    if (nodes_.empty()) return best;
    const double org[3] = {o.x, o.y, o.z}, dir[3] = {d.x, d.y, d.z};
    double inv[3];
    for (int a = 0; a < 3; ++a) inv[a] = dir[a] != 0.0 ? 1.0 / dir[a] : 0.0;
    // The node's clipped interval against (t_min, far); false when the ray misses it.
    auto node_hit = [&](const Node& n, double far) {
        double t0 = t_min, t1 = far;
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
    double far = t_max;
    while (top > 0) {
        const Node& n = nodes_[stack[--top]];
        if (!node_hit(n, far)) {
            bool inside = true;
            for (int a = 0; a < 3; ++a) inside = inside && org[a] >= n.lo[a] && org[a] <= n.hi[a];
            if (!inside) continue;
        }
        if (n.count > 0) {
            for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
                // Strictly nearer hits only (t < far, the best so far): the first primitive visited wins a tie.
                const RayHit h = ray_nearest(prims_[i], o, d, t_min, far);
                if (h.hit && (!best.hit || h.t < best.t)) {
                    best = h;
                    best.prim = i;
                    far = h.t;
                }
            }
        } else if (top + 2 <= 128) {
            if (dir[n.axis] < 0) {
                stack[top++] = n.left;
                stack[top++] = n.right;
            } else {
                stack[top++] = n.right;
                stack[top++] = n.left;
            }
        }
    }
    return best;
}

bool OccluderBvh::inside_any_solid(Vec3 p) const {
    if (nodes_.empty()) return false;
    const double q[3] = {p.x, p.y, p.z};
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = nodes_[stack[--top]];
        bool in = true;
        for (int a = 0; a < 3; ++a) in = in && q[a] >= n.lo[a] && q[a] <= n.hi[a];
        if (!in) continue;
        if (n.count > 0) {
            for (std::uint32_t i = n.first; i < n.first + n.count; ++i)
                if (inside_solid(prims_[i], p)) return true;
        } else if (top + 2 <= 128) {
            stack[top++] = n.left;
            stack[top++] = n.right;
        }
    }
    return false;
}

bool OccluderBvh::overlaps_box(Vec3 lo, Vec3 hi) const {
    if (nodes_.empty()) return false;
    const double blo[3] = {lo.x, lo.y, lo.z}, bhi[3] = {hi.x, hi.y, hi.z};
    auto overlap = [&](const double* a_lo, const double* a_hi) {
        for (int a = 0; a < 3; ++a)
            if (a_hi[a] < blo[a] || a_lo[a] > bhi[a]) return false;
        return true;
    };
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
        const Node& n = nodes_[stack.back()];
        stack.pop_back();
        if (!overlap(n.lo, n.hi)) continue;
        if (n.count > 0) {
            for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
                double plo[3], phi[3];
                bounds_of(prims_[i], plo, phi);
                if (overlap(plo, phi)) return true;
            }
        } else {
            stack.push_back(n.left);
            stack.push_back(n.right);
        }
    }
    return false;
}

}  // namespace zhc
