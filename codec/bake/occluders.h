// zhc/codec/bake/occluders.h — occluders (spheres, boxes, triangles), their double-precision ray tests, and
// OccluderBvh: the bake's ray tracer on Embree 3 (docs/scene.md "The ray tracer").
//
// The primitive tests below are exact double arithmetic: analytic spheres, slab boxes and
// Moller-Trumbore triangles (barycentrics widened by a relative 1e-10, both faces). OccluderBvh
// (codec/bake/occluder_bvh.cpp) builds an Embree scene over the occluders: triangles as one Embree
// triangle mesh in float, spheres and boxes as Embree user geometry running the tests below. For a
// triangle Embree decides whether the ray meets it (its watertight float test, on triangles grown by
// 2^-18 of the scene's half size so no ray slips between neighbours); the distance, the face and
// the interval (t_min, t_max) are decided in double (ray_triangle_plane: the same bits as
// ray_nearest). So hits differ from a double-precision tracer only for rays within about 1e-5 of
// the scene's size of a triangle's edge (test_scene_mesh compares it with its reference twin,
// tests/reference_bvh.h, zhc's own double BVH). nearest() keeps the smallest (distance, index) over
// every candidate, whatever order Embree visits them in; Embree builds on one thread and runs its
// SSE4.2 kernels (no fused multiply-add), so a bake gives the same bytes for any thread count, on
// every run and on every x86-64 CPU with SSE4.2. Memory: the occluders (80 bytes each, kept in the order given),
// Embree's float vertices and indices (48 bytes per triangle) and its BVH, about 192 bytes per
// triangle in all (memory_bytes(); test_scene_mesh prints it). Built from a const vector it copies
// the occluders; from an rvalue it takes them over, so a baked scene's mesh is held once
// (bake_scene(Scene&&)).
#pragma once

#include <cstdint>
#include <memory>
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
// Where o + t d meets the plane of triangle `tri`: ray_nearest's arithmetic (Moller-Trumbore's t, and
// `back` from its determinant's sign) without the test that the point lies inside the triangle.
// False when the ray runs parallel to the plane or the triangle is degenerate (determinant 0 or
// not finite). OccluderBvh takes the inside decision from Embree and the distance from here.
bool ray_triangle_plane(const Occluder& tri, Vec3 o, Vec3 d, double* t, bool* back);
// The axis-aligned box of an occluder: a triangle's vertices, a sphere's centre +- radius, a box.
void occluder_bounds(const Occluder& occ, Vec3* lo, Vec3* hi);
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
    // Takes the occluders over (no copy; their vector is left empty), so a scene's mesh is held once.
    explicit OccluderBvh(std::vector<Occluder>&& occluders);
    bool empty() const { return count_ == 0; }
    // Any hit with t in (t_min, t_max)?
    bool occluded(Vec3 o, Vec3 d, double t_min, double t_max) const;
    // The nearest hit with t in (t_min, t_max); of primitives hit at the same t, the lowest index.
    RayHit nearest(Vec3 o, Vec3 d, double t_min, double t_max) const;
    // Is p inside (or on) any sphere or box occluder?
    bool inside_any_solid(Vec3 p) const;
    // Does the bounding box of any occluder overlap the closed box [lo, hi]? Conservative (a true
    // answer does not mean a surface lies inside the box); the plane fit skips cells it says false
    // for (codec/bake/leak_planes.h).
    bool overlaps_box(Vec3 lo, Vec3 hi) const;
    // The primitive a nearest() hit names (RayHit::prim): the occluders in the order given.
    const Occluder& primitive(std::uint32_t i) const { return prims_[i]; }
    // The box around every occluder, each side moved out by a relative 1e-9 of the box (a
    // conservative bound for callers that scale offsets by the scene's extent); not called on an
    // empty tree.
    void root_bounds(Vec3* lo, Vec3* hi) const {
        *lo = lo_;
        *hi = hi_;
    }
    // Bytes held: the occluders (80 each) and everything Embree allocated for the scene (vertex and
    // index buffers, the BVH), counted by Embree's memory monitor once the build has finished.
    std::size_t memory_bytes() const;

    struct Impl;  // codec/bake/occluder_bvh.cpp

private:
    std::shared_ptr<const Impl> impl_;  // shared by copies: the scene is immutable once built
    const Occluder* prims_ = nullptr;   // impl_'s occluders
    std::size_t count_ = 0;
    Vec3 lo_, hi_;
    void build(std::vector<Occluder>&& occluders);
};

}  // namespace zhc
