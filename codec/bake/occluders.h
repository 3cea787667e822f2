// zhc/codec/bake/occluders.h — shadow rays against sphere, box and triangle occluders through a BVH.
//
// std-only (codec/ may not use Embree). The BVH is a binary tree over the occluders' bounding
// boxes, split at the median centroid along the longest centroid axis (leaves of <= 4
// primitives), built deterministically from precomputed boxes in O(n log n); `occluded` is an
// any-hit query with an explicit stack that visits the nearer child first. Triangle meshes of
// 10^5..10^6 triangles are one triangle primitive each in the same tree; bench/bench_bake reports
// rays per second against brute force and bytes per triangle. The tree keeps the occluders
// themselves (80 bytes each) in leaf order plus about 0.7 nodes of 72 bytes: 127 to 135 bytes per
// triangle (memory_bytes(); test_scene_mesh prints it). Built from a const vector it copies the
// occluders; from an rvalue it takes them over and reorders them in place, so a baked scene's mesh
// is held once (bake_scene(Scene&&)).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "codec/sh/sh.h"

namespace zhc {

enum class OccluderKind : std::uint8_t { kSphere, kBox, kTriangle };
// Three points' worth of doubles whatever the kind (80 bytes: meshes bring hundreds of thousands of
// triangles, and the BVH keeps these as its primitives): a triangle's vertices v0, v1, v2 (either
// winding; both faces block); a sphere's centre in v0 and radius in v1.x; a box's corners min in v0
// and max in v1 (axis-aligned, min <= max per axis). Make them with the functions below; read a
// sphere or box through its accessors.
// `material` indexes the scene's materials (codec/bake/transport.h SceneMaterial); kNoMaterial (the
// default) absorbs all light and emits none. It sits in the padding after `kind`: still 80 bytes.
constexpr std::uint32_t kNoMaterial = 0xFFFFFFFFu;
struct Occluder {
    OccluderKind kind = OccluderKind::kSphere;
    std::uint32_t material = kNoMaterial;
    Vec3 v0, v1, v2;
    std::string_view name() const {
        return kind == OccluderKind::kSphere ? "sphere" : kind == OccluderKind::kBox ? "box" : "triangle";
    }
    Vec3 center() const { return v0; }    // sphere
    double radius() const { return v1.x; }  // sphere
    Vec3 min() const { return v0; }       // box
    Vec3 max() const { return v1; }       // box
};

// A triangle occluder with vertices a, b, c; a sphere (centre c, radius r); a box (corners lo, hi).
Occluder triangle_occluder(Vec3 a, Vec3 b, Vec3 c);
Occluder sphere_occluder(Vec3 c, double r);
Occluder box_occluder(Vec3 lo, Vec3 hi);
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
    std::uint32_t prim = 0;  // OccluderBvh::nearest: the primitive hit (OccluderBvh::primitive)
};
RayHit ray_nearest(const Occluder& occ, Vec3 o, Vec3 d, double t_min, double t_max);
// Is p inside (or on) a sphere or box occluder? (Triangles bound no volume.)
bool inside_solid(const Occluder& occ, Vec3 p);
// The unit surface normal of `occ` at a point x on its surface, turned to face against the ray
// direction d (surfaces are two-sided): a triangle's geometric normal, a sphere's radial direction,
// a box's face normal (the face x is nearest to).
Vec3 surface_normal(const Occluder& occ, Vec3 x, Vec3 d);

class OccluderBvh {
public:
    OccluderBvh() = default;
    explicit OccluderBvh(const std::vector<Occluder>& occluders);
    // Takes the occluders over (no copy: they are reordered in place into the tree's leaf order and
    // their vector is left empty), so a scene's mesh is held once.
    explicit OccluderBvh(std::vector<Occluder>&& occluders);
    bool empty() const { return prims_.empty(); }
    // Any hit with t in (t_min, t_max)?
    bool occluded(Vec3 o, Vec3 d, double t_min, double t_max) const;
    // The nearest hit with t in (t_min, t_max) (ties between primitives at the same t: the first
    // visited, the nearer child on the split axis first, so the answer is the same on every run).
    RayHit nearest(Vec3 o, Vec3 d, double t_min, double t_max) const;
    // Is p inside (or on) any sphere or box occluder?
    bool inside_any_solid(Vec3 p) const;
    // Does the bounding box of any occluder overlap the closed box [lo, hi]? Conservative (a true
    // answer does not mean a surface lies inside the box); the plane fit skips cells it says false
    // for (codec/bake/leak_planes.h).
    bool overlaps_box(Vec3 lo, Vec3 hi) const;
    // The primitive a nearest() hit names (leaf order; RayHit::prim).
    const Occluder& primitive(std::uint32_t i) const { return prims_[i]; }
    std::size_t node_count() const { return nodes_.size(); }
    // The box around every occluder (the root node's); not called on an empty tree.
    void root_bounds(Vec3* lo, Vec3* hi) const {
        *lo = {nodes_[0].lo[0], nodes_[0].lo[1], nodes_[0].lo[2]};
        *hi = {nodes_[0].hi[0], nodes_[0].hi[1], nodes_[0].hi[2]};
    }
    // Bytes the tree holds (primitives and nodes), printed per primitive by test_scene_mesh.
    std::size_t memory_bytes() const { return prims_.capacity() * sizeof(Occluder) + nodes_.capacity() * sizeof(Node); }

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
    std::vector<Node> nodes_;
    std::uint32_t build(std::vector<std::uint32_t>& order, const std::vector<Bounds>& bounds, std::uint32_t first,
                        std::uint32_t count, int depth);
    // The tree over prims_ (in input order), which it then reorders into leaf order.
    void build_tree();
};

}  // namespace zhc
