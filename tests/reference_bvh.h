// zhc/tests/reference_bvh.h — the reference twin of OccluderBvh: a slow, plainly correct double-precision
// BVH over the same occluders, for tests and benchmarks (test_scene_mesh compares the bake's Embree
// tracer with it on random rays over real meshes; bench_rays times both).
//
// A binary tree over the occluders' bounding boxes, split at the median centroid along the longest
// centroid axis (leaves of <= 4 primitives, ties broken by primitive index: the same tree on every
// run), node boxes widened by a relative 1e-9 so rounding in the slab test never culls a grazing
// hit; any-hit and nearest-hit traversals with an explicit stack, nearer child first. Every
// primitive test is codec/bake/occluders.h's (ray_hits, ray_nearest: Moller-Trumbore in double with
// barycentrics widened by 1e-10, analytic spheres, slab boxes). The tree keeps the occluders in leaf
// order: RayHit::prim indexes primitive(), not the input order (original_index() maps it back).
// edge_distance and grazes_an_edge (below) tell the rays where the two tracers may differ: those
// passing within a tolerance of a triangle's edge (test_scene_mesh, fuzz/fuzz_scene_gltf.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "codec/bake/occluders.h"

namespace zhc {

class ReferenceBvh {
public:
    ReferenceBvh() = default;
    explicit ReferenceBvh(const std::vector<Occluder>& occluders);
    explicit ReferenceBvh(std::vector<Occluder>&& occluders);
    bool empty() const { return prims_.empty(); }
    // Any hit with t in (t_min, t_max)?
    bool occluded(Vec3 o, Vec3 d, double t_min, double t_max) const;
    // The nearest hit with t in (t_min, t_max) (ties between primitives at the same t: the first
    // visited, the nearer child on the split axis first).
    RayHit nearest(Vec3 o, Vec3 d, double t_min, double t_max) const;
    bool inside_any_solid(Vec3 p) const;
    bool overlaps_box(Vec3 lo, Vec3 hi) const;
    const Occluder& primitive(std::uint32_t i) const { return prims_[i]; }
    // The input index of leaf-order primitive i.
    std::uint32_t original_index(std::uint32_t i) const { return original_[i]; }
    std::size_t node_count() const { return nodes_.size(); }
    std::size_t memory_bytes() const {
        return prims_.capacity() * sizeof(Occluder) + original_.capacity() * sizeof(std::uint32_t) + nodes_.capacity() * sizeof(Node);
    }

private:
    struct Node {
        double lo[3], hi[3];
        std::uint32_t first = 0, count = 0;  // leaf: primitive range [first, first + count)
        std::uint32_t left = 0, right = 0;   // inner node (count == 0): children
        std::uint8_t axis = 0;               // inner node: split axis (nearer child first)
    };
    struct Bounds {
        double lo[3], hi[3];
        double centroid(int a) const { return 0.5 * (lo[a] + hi[a]); }
    };
    std::vector<Occluder> prims_;  // in leaf order
    std::vector<std::uint32_t> original_;
    std::vector<Node> nodes_;
    static void reference_bounds(const Occluder& o, double lo[3], double hi[3]) {
        Vec3 a, b;
        occluder_bounds(o, &a, &b);
        for (int k = 0; k < 3; ++k) {
            lo[k] = a[k];
            hi[k] = b[k];
        }
    }
    std::uint32_t build(std::vector<std::uint32_t>& order, const std::vector<Bounds>& bounds, std::uint32_t first,
                        std::uint32_t count, int depth);
    void build_tree();
};

inline ReferenceBvh::ReferenceBvh(const std::vector<Occluder>& occluders) : prims_(occluders) { build_tree(); }

inline ReferenceBvh::ReferenceBvh(std::vector<Occluder>&& occluders) : prims_(std::move(occluders)) {
    occluders.clear();
    occluders.shrink_to_fit();
    build_tree();
}

inline void ReferenceBvh::build_tree() {
    if (prims_.empty()) return;
    prims_.shrink_to_fit();
    // Boxes once (a centroid is computed from its box where needed: the same doubles as storing it,
    // 24 bytes per primitive less at the build's peak); the build permutes indices, then the
    // primitives are put in leaf order (each leaf a contiguous range) in place, following the
    // permutation's cycles.
    std::vector<Bounds> bounds(prims_.size());
    for (size_t i = 0; i < prims_.size(); ++i) {
        reference_bounds(prims_[i], bounds[i].lo, bounds[i].hi);
    }
    std::vector<std::uint32_t> order(prims_.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
    nodes_.reserve(prims_.size() + 1);  // leaves of 2..4 primitives: < n nodes
    build(order, bounds, 0, static_cast<std::uint32_t>(order.size()), 0);
    original_ = order;  // leaf position -> input index
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

inline std::uint32_t ReferenceBvh::build(std::vector<std::uint32_t>& order, const std::vector<Bounds>& bounds,
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

inline bool ReferenceBvh::occluded(Vec3 o, Vec3 d, double t_min, double t_max) const {
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
                if (ray_hits(p, o, d, t_min, t_max)) return true;
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

inline RayHit ReferenceBvh::nearest(Vec3 o, Vec3 d, double t_min, double t_max) const {
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

inline bool ReferenceBvh::inside_any_solid(Vec3 p) const {
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

inline bool ReferenceBvh::overlaps_box(Vec3 lo, Vec3 hi) const {
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
                reference_bounds(prims_[i], plo, phi);
                if (overlap(plo, phi)) return true;
            }
        } else {
            stack.push_back(n.left);
            stack.push_back(n.right);
        }
    }
    return false;
}

// How far the point where o + t d meets triangle `tri`'s plane lies from the triangle's boundary, in
// scene units (inside or outside: the distance to the nearest violated edge line, or to the nearest
// edge line when inside). +inf when the ray runs parallel to the plane.
inline double edge_distance(const Occluder& tri, Vec3 o, Vec3 d) {
    const Vec3 n = cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
    const double nn = std::sqrt(dot(n, n)), dn = dot(d, n);
    if (nn == 0 || dn == 0) return std::numeric_limits<double>::infinity();
    const Vec3 q = o + (dot(n, tri.v0 - o) / dn) * d;
    const Vec3 v[3] = {tri.v0, tri.v1, tri.v2};
    double inside = std::numeric_limits<double>::infinity(), outside = 0;
    for (int k = 0; k < 3; ++k) {
        const Vec3 a = v[k], b = v[(k + 1) % 3];
        const double len = length(b - a);
        if (len == 0) return 0;
        const double e = dot(n, cross(b - a, q - a)) / (nn * len);  // signed distance to the edge's line
        if (e >= 0) inside = std::min(inside, e);
        else outside = std::max(outside, -e);
    }
    return outside > 0 ? outside : inside;
}

// Does the ray pass within `tol` of an edge of any triangle whose plane it meets inside (t_min, t_max)?
// Where it does, Embree's float test (triangles grown by 2^-18 of the scene's half size,
// codec/bake/occluder_bvh.cpp) and the double Moller-Trumbore test may decide differently.
inline bool grazes_an_edge(const std::vector<Occluder>& occ, Vec3 o, Vec3 d, double t_min, double t_max, double tol) {
    for (const Occluder& x : occ) {
        if (x.kind != OccluderKind::kTriangle) continue;
        double t = 0;
        bool back = false;
        if (!ray_triangle_plane(x, o, d, &t, &back) || !(t > t_min - tol && t < t_max + tol)) continue;
        if (edge_distance(x, o, d) < tol) return true;
    }
    return false;
}

}  // namespace zhc
