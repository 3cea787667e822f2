// zhc/codec/bake/scene.h — a lighting scene and its bake into SH3 radiance probes (no I/O).
//
// zhc is not a renderer: a bake evaluates exactly the effects the scene lists, each in closed form
// where one exists (docs/scene.md), and reports what it simulated and how long each took.
//
//  * environment: an SH3 radiance projection (formats/scene_json does the projection once),
//    scaled by `intensity` and rotated about +Z by `rotation_rad` (codec/sh/sh.h rotate);
//  * sky: constant radiance, or the sky/ground gradient of codec/bake/sky.h;
//  * directional light (a sun): a cone of angular radius sigma, ZH3 paper Eq. 15 (a delta for
//    sigma = 0); `irradiance` is zhc's normalised irradiance on a surface facing it (E = L sin^2 sigma);
//  * point light: radiance arriving from the light integrates to intensity / d^2 (a delta);
//  * spot light: a point light times the cone attenuation
//        a = smoothstep(cos outer, cos inner, dot(spot direction, unit(probe - light)))
//    with smoothstep(e0, e1, x) = t^2 (3 - 2t), t = clamp((x - e0) / (e1 - e0), 0, 1)
//    (a hard step when inner == outer);
//  * sphere light of radius r and constant radiance at distance d: a cone of half-angle
//    asin(r / d) towards its centre; a probe inside the sphere (d <= r) sees that radiance over
//    the whole sphere (L00 only);
//  * hemisphere light: constant radiance over the hemisphere around `direction` (Eq. 15, pi/2).
//
// Occluders (spheres, axis-aligned boxes, triangles of meshes) shadow the lights with `shadows`
// on, and occlude the sky and the environment (below). Lights:
//  * point, spot and zero-radius directional lights: one shadow ray (to the light / to infinity);
//  * cone lights (sun with a radius, sphere lights, hemisphere lights): a fixed set of
//    `shadow_samples` equal-solid-angle directions inside the cone (a spherical-Fibonacci spiral
//    over the cap). The occluded samples' projection (each weighted by cone solid angle / N) is
//    subtracted from the closed form; all samples visible -> the closed form exactly; all blocked
//    -> exactly zero.
//
// Sky and environment occlusion (docs/scene.md "Probes near geometry"): with occluders and
// `occlusion.sky_samples` = N > 0, each probe casts N fixed equal-area directions over the sphere
// (a spherical-Fibonacci spiral); the blocked directions' projection, sum_k (4 pi / N) L(d_k) Y(d_k)
// with L the sky's / the environment's radiance in d_k, is subtracted from the closed forms: no
// blocked ray -> the closed forms exactly, all blocked -> exactly zero. The same rays classify the
// probe (grid layouts): more than `invalid_fraction` of them starting inside a box/sphere or meeting
// a triangle's back face first -> invalid; its SH becomes the inverse-distance blend of the valid
// probes of the nearest grid shell (at most kDilationShells steps away) holding any. Before that,
// grid probes in or near geometry are baked at a clear point nearby and probes far from a wall that
// crosses one of their cells nearer to it (`occlusion.move_probes`), and one separating plane per
// cell is fitted to the probes where they were baked (ProbeSet::planes; codec/bake/leak_planes.h):
// only probes that stay inside geometry are invalid. Visibility masks (ProbeSet::visibility, on
// request): per grid probe and each of its 8 cells, kMaskPoints rays from the cell's centre region
// to the probe.
//
// Reflected and emitted light (docs/scene.md "Reflected light"): where an occluder's material
// reflects or emits, each valid probe also gathers the radiance leaving the surfaces it sees,
// path-traced by codec/bake/transport.h to a noise target; nothing is traced otherwise.
//
// Determinism: every probe is computed by itself with the effects in scene order, summed in
// double, its random numbers seeded by its index; dilation reads only baked valid probes; so the
// result is the same bytes whatever the thread count.
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
// BakeOptions::progress is called one call at a time (serialised across the bake's threads).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "codec/bake/leak_planes.h"
#include "codec/bake/occluders.h"
#include "codec/probe/probe_set.h"
#include "codec/sh/sh.h"
#include "codec/bake/sky.h"
#include "codec/bake/transport.h"
#include "codec/status.h"

namespace zhc {

struct SceneEnvironment {
    Sh3Radiance projected;     // the map's SH3 radiance as read (before intensity and rotation)
    double intensity = 1.0;
    double rotation_rad = 0;   // about +Z, right-hand rule
    std::string source;        // for reports (the map's path)
    // How a lat-long map's columns turn (codec/sh/sh.h; `projected` is already in zhc's frame).
    LatLongConvention latlong = LatLongConvention::kOpenExr;
    bool latlong_map = true;   // false: a cube map (its orientation is its format's)
    std::string label;         // the bake report's effect name when not a projected map (a glTF
                               // image-based light's SH); empty: "environment"
    // 8-bit cube maps: how texels become radiance (formats/envmap/envmap.h parse_ldr_decoding).
    std::string ldr_encoding = "auto";
};

enum class SkyKind : std::uint8_t { kConstant, kGradient };
struct SceneSky {
    SkyKind kind = SkyKind::kGradient;
    Rgb radiance{1, 1, 1};  // kConstant
    GradientSky gradient;   // kGradient
};

enum class LightKind : std::uint8_t { kDirectional, kPoint, kSpot, kSphere, kHemisphere };
const char* light_kind_name(LightKind kind);

struct SceneLight {
    LightKind kind = LightKind::kPoint;
    std::string name;
    Vec3 position;                   // point, spot
    Vec3 center;                     // sphere
    Vec3 direction{0, 0, 1};         // directional: towards the light; spot: where it points;
                                     // hemisphere: the hemisphere's axis
    Rgb color{1, 1, 1};              // directional: irradiance; point/spot: intensity; sphere/hemisphere: radiance
    double angular_radius_rad = 0;   // directional
    double radius = 0;               // sphere
    double inner_angle_rad = 0;      // spot (half-angles)
    double outer_angle_rad = 0;
    bool shadows = false;
    int shadow_samples = 64;         // cone lights with shadows
};

enum class ProbePlacementKind : std::uint8_t { kGrid, kPositions };
struct ProbePlacement {
    ProbePlacementKind kind = ProbePlacementKind::kGrid;
    Vec3 min, max;                              // kGrid: bounds; probes at the corners and in between
    std::array<std::uint32_t, 3> counts{1, 1, 1};
    std::vector<Vec3> positions;                // kPositions
};

// Occlusion of the sky/environment and probe validity (docs/scene.md "Probes near geometry").
struct SceneOcclusion {
    int sky_samples = 256;          // rays per probe; 0: sky/environment not occluded, no validity/masks
    double invalid_fraction = 0.25;  // invalid when more than this fraction of rays see "inside"
    // Grids: bake probes that lie in or near geometry at a clear point nearby, and probes far from
    // a wall that crosses one of their cells nearer to it (codec/bake/leak_planes.h); false: every
    // probe is baked at its grid point.
    bool move_probes = true;
    // Grids: cells where a light's hard shadow edge passes between the corner probes get the plane
    // along that edge (codec/bake/leak_planes.h "Shadow planes"); false: planes follow geometry only.
    bool shadow_planes = true;
    // Grids: cells around an enclosed pocket of air (a closed box's inside) get a corner region
    // instead of a plane where it separates far better (leak_planes.h); false: planes only.
    bool corner_regions = true;
};
// Visibility-mask rays per (probe, cell): the cell's centre and the 8 points centre +- spacing/4.
constexpr int kMaskPoints = 9;
// Dilation looks for valid probes in grid shells 1..kDilationShells around an invalid probe.
constexpr int kDilationShells = 3;

struct Scene {
    SceneOcclusion occlusion;
    ProbePlacement probes;
    std::optional<SceneEnvironment> environment;
    std::optional<SceneSky> sky;
    std::vector<SceneLight> lights;
    std::vector<Occluder> occluders;
    // Surfaces' reflectance and emission (Occluder::material indexes them) and the limits of the
    // reflected-light pass (codec/bake/transport.h).
    std::vector<SceneMaterial> materials;
    SceneTransport transport;
    // Textures of textured materials, and the UVs of textured triangles (Occluder::material
    // kSurfaceBit | index; codec/bake/transport.h SurfaceUv).
    std::vector<SceneTexture> textures;
    std::vector<SurfaceUv> surfaces;
};

// The built-in default scene of `zhc demo`: the default gradient sky and sun (codec/bake/sky.h), three
// coloured sphere lights, a box occluder under the sun and a sphere occluder (both also occlude
// the sky), 8 x 8 x 4 probes.
Scene default_scene();

// Probe positions in index order (grid: x fastest, then y, then z) and the container layout.
std::vector<Vec3> probe_positions(const ProbePlacement& placement);
ProbeLayout probe_layout(const ProbePlacement& placement);
// Checks counts, finiteness, angles, radii; kInvalidValue naming the field.
Status validate_scene(const Scene& scene);

// One simulated effect, in scene order.
struct BakeEffect {
    std::string name;      // "sky", "environment", "sun 'key'", "sphere 'lamp'", ...
    std::string method;    // "closed form" or "closed form, shadowed: N rays"
    std::uint64_t rays = 0;
    double milliseconds = 0;
};
struct BakeReport {
    std::vector<BakeEffect> effects;
    std::uint64_t probes = 0;
    std::uint64_t rays = 0;
    double occluder_build_ms = 0;
    double total_ms = 0;
    // Occlusion pass (sky/environment visibility and probe validity share its rays), validity
    // dilation and visibility masks; zero when not run.
    std::uint64_t occlusion_rays = 0;
    double occlusion_ms = 0;
    bool validity_checked = false;  // grid with occluders and sky_samples > 0
    std::uint64_t invalid_probes = 0, dilated_probes = 0;
    double dilation_ms = 0;
    std::uint64_t mask_rays = 0, mask_probes = 0;
    double mask_ms = 0;
    // Probes kept out of walls and the planes per cell (codec/bake/leak_planes.h); zero when not
    // run (validity_checked false). moved_out + left_inside + left_near: the probes in or near
    // geometry at their grid points; left_inside are the invalid, dilated ones.
    std::uint64_t moved_out = 0, moved_towards = 0, left_inside = 0, left_near = 0;
    std::uint64_t relocation_rays = 0;
    double relocation_ms = 0;
    PlaneFitStats planes;  // the fit stored with the probes (ProbeLeakData::planes asked for)
    double plane_ms = 0;
    // Reflected and emitted light (codec/bake/transport.h); traced == false when not run.
    TransportReport transport;
    // "sky (closed form): 0.3 ms; sun 'key' (closed form, shadowed: 4096 rays): 1.2 ms"
    std::string summary() const;
    // What the bake did against leaks, one line each (empty when validity was not checked): the
    // probes in or near geometry and where they went, the planes per cell and the leak estimate
    // (blocked sample-to-probe pairs the planes still blend). `zhc bake` prints them, the demo's
    // report shows them.
    std::vector<std::string> leak_lines() const;
};

struct BakeOptions {
    int threads = 1;
    // With ProbeLeakData asked for: also trace the 8-bit visibility masks (the leak study's
    // comparison, docs/leaks.md); the planes are always fitted.
    bool visibility_masks = false;
    // Called after each block of probes with (probes done, total), one call at a time (serialised
    // across threads), done increasing; the baked bytes never depend on it.
    std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

// Leak-avoidance data of a grid bake (codec/probe/probe_set.h ProbeSet::validity/visibility/planes).
struct ProbeLeakData {
    std::vector<std::uint8_t> validity;    // 1 valid, 0 inside geometry (dilated)
    std::vector<std::uint8_t> visibility;  // BakeOptions::visibility_masks: bit (cx + 2 cy + 4 cz): visible from that cell
    std::vector<std::uint8_t> planes;      // 5 bytes per probe: the plane of the cell it starts (leak_planes.h)
    std::vector<Vec3> baked_positions;     // where each probe was baked (its grid point unless moved)
};

// Bakes every probe (validate_scene first; kInvalidValue on a bad scene). `leak`, when given, is
// filled for grid layouts of scenes with occluders and sky_samples > 0 (else left empty); the
// masks are traced only when it is asked for. The probes do not depend on `leak`.
Result<std::vector<Sh3Radiance>> bake_scene(const Scene& scene, const BakeOptions& options = {},
                                            BakeReport* report = nullptr, ProbeLeakData* leak = nullptr);
// Whether a bake of `scene` traces rays against its occluders: it has some, and sky_samples > 0
// with distant lighting or a probe grid (sky occlusion, validity and visibility masks), or a light
// casts shadows. Otherwise the bake builds no tree and its occluders change nothing.
bool bake_traces_occluders(const Scene& scene);

// The same bake of a scene given up: its occluders move into the bake's BVH instead of being
// copied, so a mesh of n triangles is held once (80 bytes per triangle plus the tree's nodes) rather
// than twice; `scene.occluders` is left empty.
Result<std::vector<Sh3Radiance>> bake_scene(Scene&& scene, const BakeOptions& options = {},
                                            BakeReport* report = nullptr, ProbeLeakData* leak = nullptr);

// One light's radiance SH at probe position p, closed form, no shadows (the building block,
// exposed for tests and benchmarks): accumulates into acc (27 doubles, coefficient-major RGB).
void add_light_closed_form(const SceneLight& light, Vec3 p, double acc[27]);
// The equal-solid-angle sample directions of a cone (unit, around `axis`), deterministic.
std::vector<Vec3> cone_sample_directions(Vec3 axis, double sigma, int count);
// The sky-occlusion directions: N equal-area directions over the sphere, z_k = 1 - (2k + 1)/N,
// azimuth k pi (3 - sqrt 5) (a spherical-Fibonacci spiral), deterministic.
std::vector<Vec3> sphere_sample_directions(int count);
// Radiance of the scene's sky in unit direction d (the function the closed forms project).
void sky_radiance(const SceneSky& sky, Vec3 d, double rgb[3]);

}  // namespace zhc
