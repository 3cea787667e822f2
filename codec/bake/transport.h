// zhc/codec/bake/transport.h — the light a scene's surfaces reflect and emit, arriving at probes
// (path tracing; no I/O). docs/scene.md "Reflected light".
//
// What a probe at p sees in direction w is, besides the closed-form effects of codec/bake/scene.h
// (lights, sky, environment, with their occlusion), the radiance leaving the first surface x that
// the ray p + t w meets:
//
//     L_o(x) = L_e(x) + rho(x) / pi * integral over the hemisphere at x of L_i(x, w') cos(n, w') dw'
//
// for Lambertian surfaces of albedo rho (glTF: base colour times (1 - metallic), the diffuse part)
// and emitted radiance L_e (glTF: emissive factor times KHR_materials_emissive_strength), each
// times its textures at x's UV on textured triangles (SceneMaterial, SurfaceUv below). The
// probe's SH3 gains  sum_k (4 pi / N) L_o(x_k) Y(w_k)  over N directions w_k; a direction that meets
// no surface adds nothing here (its sky/environment light is the closed form's).
//
// L_o is estimated by a path per direction (unbiased Monte Carlo):
//  * next-event estimation at every vertex for point, spot and directional lights and sphere lights
//    (one shadow ray each when the light casts shadows; cone lights, one uniform direction in the
//    cone): E = I cos / d^2, pi E_n cos (zhc's normalised irradiance E_n of a sun), L Omega cos;
//  * the path continues in a cosine-distributed direction (pdf cos / pi, so its throughput is
//    multiplied by rho); a continuation ray that meets no surface gathers the distant radiance
//    (sky, environment, hemisphere lights) in its direction; one that meets an emitting surface
//    gathers its L_e (emitters are found only by such hits: no double counting);
//  * Russian roulette from the third vertex on: continue with probability q = max channel of the
//    throughput (capped at 1) and divide by q; at most `max_bounces` vertices. Cutting a path there
//    drops at most a_max^max_bounces of the light (a_max the largest albedo channel; the Neumann
//    series of a closed room of albedo a loses a^N after N bounces): TransportReport::energy_left.
//
// Directions: batches of kTransportBatch stratified directions (equal-area z bands, one jittered
// sample each, golden-angle azimuths from a random offset), a fresh jitter per batch. Probes take
// batches until the relative standard error of their irradiance (the largest standard error of the
// six axis irradiances, over the batches' spread, divided by the probe's mean axis irradiance with
// the closed-form effects included) is at most `max_noise`, between `min_rays` and `max_rays`.
// Random numbers come from a counter-based generator seeded by the probe index, batch and sample:
// a probe's result is the same whatever the thread count or the order of probes.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "codec/bake/occluders.h"
#include "codec/sh/sh.h"

namespace zhc {

struct Scene;

// A Lambertian surface (Occluder::material indexes Scene::materials, or names a textured surface:
// kSurfaceBit below). Untextured, `albedo` and `emission` are the surface's everywhere. Textured
// (glTF metal-rough materials, docs/scene.md "Reflected light"), at a point of UV (u, v):
//     albedo   = base_factor x base(u, v) x (1 - metallic x metal_rough(u, v).b)
//     emission = emission x emissive(u, v)
// where an absent texture reads 1 (so without a metallic-roughness texture the albedo is
// base_factor x base(u, v) x (1 - metallic)); `albedo` still holds base_factor x (1 - metallic),
// the value of a texel of 1.
struct SceneMaterial {
    std::string name;
    Rgb albedo{0, 0, 0};    // diffuse reflectance, each channel in [0, 1]
    Rgb emission{0, 0, 0};  // emitted radiance, >= 0 (the scene's radiance units)
    // Textures (indices into Scene::textures, -1: none); only read on triangles with a SurfaceUv.
    int base_texture = -1, metal_rough_texture = -1, emissive_texture = -1;
    // Per texture, the affine map of the triangle's UV to the UV it is sampled at
    // (glTF KHR_texture_transform): u' = t[0] u + t[1] v + t[2], v' = t[3] u + t[4] v + t[5].
    using UvTransform = std::array<float, 6>;
    static constexpr UvTransform kIdentityUv{1, 0, 0, 0, 1, 0};
    UvTransform base_uv = kIdentityUv, metal_rough_uv = kIdentityUv, emissive_uv = kIdentityUv;
    Rgb base_factor{0, 0, 0};  // with textures: the base colour factor, each channel in [0, 1]
    float metallic = 0;        // with textures: the metallic factor, in [0, 1]
    bool textured() const { return base_texture >= 0 || metal_rough_texture >= 0 || emissive_texture >= 0; }
};

// A texture as the tracer samples it: linear RGB texels, row 0 at v = 0 (glTF's UV origin is the
// image's first row), bilinear or nearest, each axis wrapped as glTF samplers do.
enum class TextureWrap : std::uint8_t { kRepeat, kClamp, kMirror };
struct SceneTexture {
    std::string name;
    std::uint32_t width = 0, height = 0;
    std::vector<float> texels;  // width x height x 3 (R, G, B), row-major from row 0
    TextureWrap wrap_s = TextureWrap::kRepeat, wrap_t = TextureWrap::kRepeat;
    bool nearest = false;  // magnification filter NEAREST; else bilinear
};
// The texel of `tex` at (u, v), linear RGB (bilinear between the four nearest texel centres, or
// the nearest texel), wrapped per axis.
void sample_texture(const SceneTexture& tex, double u, double v, double rgb[3]);

// A textured triangle's UVs (texture coordinates of v0, v1, v2 in the Occluder's order) and its
// material. An Occluder whose `material` is kSurfaceBit | i (and not kNoMaterial) is textured: its
// material is surfaces[i].material, and the UV at a point of it is interpolated barycentrically.
// The Occluder carries the index, so the side table survives the BVH's reordering.
constexpr std::uint32_t kSurfaceBit = 0x80000000u;
struct SurfaceUv {
    std::uint32_t material = 0;
    float uv[3][2] = {{0, 0}, {0, 0}, {0, 0}};
};
inline bool is_surface(std::uint32_t material) { return material != kNoMaterial && (material & kSurfaceBit) != 0; }

// Limits of the reflected-light pass (JSON "transport", `zhc bake --bounces/--max-noise/--rays`).
struct SceneTransport {
    int max_bounces = 64;     // vertices per path; 0 turns the pass off
    double max_noise = 0.02;  // target relative standard error of a probe's irradiance
    int min_rays = 512;       // directions per probe, rounded up to whole batches
    int max_rays = 8192;
};
constexpr int kTransportBatch = 128;

// Whether the bake traces reflected light: max_bounces > 0 and an occluder has a material that
// reflects (albedo > 0) or emits, and (for reflection alone) the scene has light to reflect.
bool scene_has_transport(const Scene& scene);

struct TransportReport {
    bool traced = false;
    std::uint64_t probes = 0;     // probes traced (invalid probes are dilated instead)
    std::uint64_t paths = 0;      // directions from probes
    std::uint64_t rays = 0;       // every ray: probe, continuation and shadow rays
    std::uint64_t vertices = 0;   // surface hits shaded
    std::uint64_t cut = 0;        // paths stopped by the bounce limit with light still carried
    int max_depth = 0;            // deepest vertex reached
    int max_bounces = 0;
    double energy_left = 0;       // bound on the light the bounce limit drops: a_max^max_bounces
    double noise_median = 0, noise_max = 0;  // per-probe relative standard error
    std::uint64_t probes_over_noise = 0;     // probes that reached max_rays above max_noise
    double milliseconds = 0;
};

// The path tracer of one bake: the scene's lights, distant radiance and materials, over the
// bake's BVH (which holds the occluders; scene.occluders is not read).
class PathTracer {
public:
    PathTracer(const Scene& scene, const OccluderBvh& bvh);
    struct ProbeStats {
        std::uint64_t paths = 0, rays = 0, vertices = 0, cut = 0;
        int max_depth = 0;
        double noise = 0;
    };
    // Adds the reflected and emitted radiance arriving at p to acc (27 doubles, coefficient-major
    // RGB). `closed_form` (27 doubles) is the probe's closed-form SH, used for the noise target only.
    ProbeStats trace_probe(Vec3 p, std::uint64_t probe_index, const double closed_form[27], double acc[27]) const;
    double energy_left() const { return energy_left_; }

private:
    struct Light {
        int kind = 0;  // LightKind
        Vec3 position, direction, center;
        double rgb[3] = {0, 0, 0};
        double cos_outer = -1, cos_inner = -1, radius = 0, cos_sigma = 1;
        bool shadows = false;
    };
    struct Rng;
    const Scene& scene_;
    const OccluderBvh& bvh_;
    std::vector<SceneMaterial> materials_;
    // The material of the surface `occ` at x: albedo and emission (textures sampled); false when
    // it has none (absorbs everything, emits nothing).
    bool shade(const Occluder& occ, Vec3 x, double albedo[3], double emission[3]) const;
    std::vector<Light> lights_;
    // Distant radiance: environment SH (rotated, scaled), the sky, hemisphere lights.
    bool has_env_ = false;
    double env_[27] = {};
    std::vector<Light> hemispheres_;
    SceneTransport limits_;
    double eps_ = 1e-9;  // surface offset of continuation and shadow rays
    double energy_left_ = 0;

    void distant_radiance(Vec3 d, double rgb[3]) const;
    void light_irradiance(Vec3 x, Vec3 n, Rng& rng, double E[3], std::uint64_t* rays) const;
    // Radiance leaving the surface hit (prim at x, seen along d).
    void path_radiance(Vec3 x, Vec3 d, std::uint32_t prim, Rng& rng, double L[3], ProbeStats& st) const;
};

}  // namespace zhc
