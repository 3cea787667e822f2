// glTF scene reading (formats/scene/scene_gltf.h: KHR_lights_punctual, meshes as occluders, node tree,
// extras.zhc) from untrusted GLB / glTF JSON bytes. The input lives in a directory that does not
// exist, so external buffers and environment maps fail without touching real files. A successful
// read is a valid scene: it bakes to exactly one probe per position with finite coefficients, and
// its occluder BVH agrees with a brute-force loop on a few rays (except a ray within 1e-5 of the
// scene's half size of a triangle's edge, where Embree's float test decides: tests/reference_bvh.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "codec/bake/occluders.h"
#include "codec/bake/scene.h"
#include "formats/scene/scene_gltf.h"
#include "tests/reference_bvh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::GltfLimits glimits;
    glimits.max_file_bytes = 1 << 20;
    glimits.max_buffer_bytes = 1 << 18;
    glimits.max_total_bytes = 1 << 19;
    zhc::SceneLoadOptions options;
    options.load_environment = false;
    options.limits.max_probes = 1 << 9;
    options.limits.max_lights = 16;
    options.limits.max_occluders = 64;
    options.limits.max_triangles = 4096;
    options.limits.max_shadow_samples = 64;
    options.limits.max_rays = 1 << 16;
    auto scene = zhc::parse_scene_gltf({data, size}, "/nonexistent-zhc-fuzz/scene.gltf", options, glimits);
    if (!scene) {
        if (scene.error().message.empty() || scene.error().message.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    auto probes = zhc::bake_scene(*scene);
    if (!probes) std::abort();  // a parsed scene is a valid scene
    if (probes->size() != zhc::probe_positions(scene->probes).size()) std::abort();
    const zhc::OccluderBvh bvh(scene->occluders);
    if (bvh.empty()) return 0;
    zhc::Vec3 lo, hi;
    bvh.root_bounds(&lo, &hi);
    const double half = 0.5 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const zhc::Vec3 dirs[3] = {{0, 0, 1}, {0.6, -0.48, 0.64}, {-1, 0, 0}};
    for (const zhc::Vec3& d : dirs) {
        bool brute = false;
        for (const zhc::Occluder& o : scene->occluders) brute = brute || zhc::ray_hits(o, {0.1, 0.2, 0.3}, d, 1e-9, 1e30);
        if (bvh.occluded({0.1, 0.2, 0.3}, d, 1e-9, 1e30) != brute &&
            !zhc::grazes_an_edge(scene->occluders, {0.1, 0.2, 0.3}, d, 1e-9, 1e30, 1e-5 * half))
            std::abort();
    }
    return 0;
}
