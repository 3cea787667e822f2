// zhc/codec/bake/occluders.h — shadow rays against sphere, box and triangle occluders through a BVH.
//
// std-only (codec/ may not use Embree). The BVH is a binary tree over the occluders' bounding
// boxes, split at the median centroid along the longest centroid axis (leaves of <= 4
// primitives), built deterministically from precomputed boxes and centroids in O(n log n);
// `occluded` is an any-hit query with an explicit stack that visits the nearer child first.
// Triangle meshes of 10^5..10^6 triangles are one triangle primitive each in the same tree;
// bench/bench_bake reports rays per second against brute force. The tree reads the caller's
// occluders without copying them and keeps each primitive in 80 bytes (its nine doubles and its
// kind) plus about 0.7 nodes of 72 bytes: 132 bytes per triangle on a 22,800-triangle mesh
// (test_scene_mesh prints it; memory_bytes()).
//
// Ray/triangle (Moller & Trumbore 1997, "Fast, minimum storage ray/triangle intersection"), in
// double, epsilon policy (docs/scene.md "Triangle meshes"):
//  * both faces block (no back-face culling: an occluder is a surface, not a closed solid);
//  * a ray exactly parallel to the triangle's plane (determinant == 0, bit-exact) misses: it sees
//    the triangle edge-on, zero solid angle; no other epsilon on the determinant;
//  * barycentric bounds are inclusive and widened by 1e-10 (u >= -1e-10, v >= -1e-10,
//    u + v <= 1 + 1e-10): Moller-Trumbore is not watertight (neighbours compute their own u, v and
//    may both reject a ray through their shared edge by a few ulps); the widening, far above
//    rounding (~1e-15) and far below any scene feature, closes those cracks: no leaks along the
//    seams of a closed mesh ("watertight enough" for shadow rays);
//  * the hit distance must lie in the open interval (t_min, t_max), like the other primitives;
//  * a degenerate (zero-area) triangle never blocks.
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
// An occluder set (and its BVH) is immutable once built: rays may be cast from many threads at once.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "codec/sh/sh.h"

namespace zhc {

enum class OccluderKind : std::uint8_t { kSphere, kBox, kTriangle };
struct Occluder {
    OccluderKind kind = OccluderKind::kSphere;
    std::string_view name() const {
        return kind == OccluderKind::kSphere ? "sphere" : kind == OccluderKind::kBox ? "box" : "triangle";
    }
    Vec3 center;        // sphere
    double radius = 0;  // sphere
    Vec3 min, max;      // box (axis-aligned, min <= max per axis)
    Vec3 v0, v1, v2;    // triangle (either winding; both faces block)
};

// A triangle occluder with vertices a, b, c.
Occluder triangle_occluder(Vec3 a, Vec3 b, Vec3 c);
// Triangles of a UV sphere (centre c, radius r) with n_lat x n_lon quads of two triangles each
// (one at the poles): 2 n_lat n_lon - 2 n_lon triangles. A closed mesh occluder for scenes,
// tests and benchmarks.
std::vector<Occluder> uv_sphere_triangles(Vec3 c, double r, int n_lat, int n_lon);

// Ray o + t d (d unit) against one occluder: true when it is hit for some t in (t_min, t_max).
// A ray starting inside a sphere or box is blocked (the probe is inside solid matter); triangles
// follow the policy above.
bool ray_hits(const Occluder& occ, Vec3 o, Vec3 d, double t_min, double t_max);

// The nearest hit of a ray (probe validity, docs/scene.md "Probes near geometry"). `back`: the ray
// starts inside a sphere or box (then t = t_min), or meets a triangle's back face: the side
// opposite its normal (v1 - v0) x (v2 - v0), i.e. the triangle is wound clockwise as seen from
// the ray's origin (glTF's front faces are counter-clockwise).
struct RayHit {
    bool hit = false;
    bool back = false;
    double t = 0;
};
RayHit ray_nearest(const Occluder& occ, Vec3 o, Vec3 d, double t_min, double t_max);
// Is p inside (or on) a sphere or box occluder? (Triangles bound no volume.)
bool inside_solid(const Occluder& occ, Vec3 p);

class OccluderBvh {
public:
    OccluderBvh() = default;
    explicit OccluderBvh(const std::vector<Occluder>& occluders);
    bool empty() const { return prims_.empty(); }
    // Any hit with t in (t_min, t_max)?
    bool occluded(Vec3 o, Vec3 d, double t_min, double t_max) const;
    // The nearest hit with t in (t_min, t_max) (ties between primitives at the same t: the first
    // visited, the nearer child on the split axis first, so the answer is the same on every run).
    RayHit nearest(Vec3 o, Vec3 d, double t_min, double t_max) const;
    // Is p inside (or on) any sphere or box occluder?
    bool inside_any_solid(Vec3 p) const;
    std::size_t node_count() const { return nodes_.size(); }
    // Bytes the tree holds (primitives and nodes), printed per primitive by test_scene_mesh.
    std::size_t memory_bytes() const { return prims_.capacity() * sizeof(Prim) + nodes_.capacity() * sizeof(Node); }

private:
    struct Node {
        double lo[3], hi[3];
        std::uint32_t first = 0, count = 0;  // leaf: primitive range [first, first + count)
        std::uint32_t left = 0, right = 0;   // inner node (count == 0): children
        std::uint8_t axis = 0;               // inner node: split axis (nearer child first)
    };
    struct Bounds {
        double lo[3], hi[3], centroid[3];
    };
    // A primitive in leaf order, compactly: nine doubles (the kind's vertices / centre and radius /
    // corners) and the kind, 80 bytes (an Occluder is 160).
    struct Prim {
        double p[9];
        OccluderKind kind;
    };
    static Prim compact(const Occluder& o);
    static Occluder expand(const Prim& p);
    std::vector<Prim> prims_;
    std::vector<Node> nodes_;
    std::uint32_t build(std::vector<std::uint32_t>& order, const std::vector<Bounds>& bounds, std::uint32_t first,
                        std::uint32_t count, int depth);
};

}  // namespace zhc
