// zhc/codec/occluders.h — shadow rays against sphere and box occluders through a small BVH.
//
// std-only (codec/ may not use Embree). The BVH is a binary tree over the occluders' bounding
// boxes, split at the median centroid along the longest axis (leaves of <= 4 primitives), built
// deterministically; `occluded` is an any-hit query with an explicit stack. Scenes hold few
// occluders (tens to thousands), so this is enough; bench/bench_bake reports rays per second.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "sh.h"

namespace zhc {

enum class OccluderKind : std::uint8_t { kSphere, kBox };
struct Occluder {
    OccluderKind kind = OccluderKind::kSphere;
    std::string_view name() const { return kind == OccluderKind::kSphere ? "sphere" : "box"; }
    Vec3 center;        // sphere
    double radius = 0;  // sphere
    Vec3 min, max;      // box (axis-aligned, min <= max per axis)
};

// Ray o + t d (d unit) against one occluder: true when it is hit for some t in (t_min, t_max).
// A ray starting inside a sphere or box is blocked (the probe is inside solid matter).
bool ray_hits(const Occluder& occ, Vec3 o, Vec3 d, double t_min, double t_max);

class OccluderBvh {
public:
    OccluderBvh() = default;
    explicit OccluderBvh(std::vector<Occluder> occluders);
    bool empty() const { return prims_.empty(); }
    // Any hit with t in (t_min, t_max)?
    bool occluded(Vec3 o, Vec3 d, double t_min, double t_max) const;
    std::size_t node_count() const { return nodes_.size(); }

private:
    struct Node {
        double lo[3], hi[3];
        std::uint32_t first = 0, count = 0;  // leaf: primitive range [first, first + count)
        std::uint32_t left = 0, right = 0;   // inner node (count == 0): children
    };
    std::vector<Occluder> prims_;
    std::vector<Node> nodes_;
    std::uint32_t build(std::uint32_t first, std::uint32_t count, int depth);
};

}  // namespace zhc
