// zhc/formats/scene/scene_json.h — the JSON scene description (docs/scene.md,
// docs/schema/scene.schema.json) -> codec/bake/scene.h Scene, and back.
//
// Strict: unknown keys, wrong types, missing required fields, out-of-range values and limits are
// errors naming the file, the field path and what is wrong, e.g.
//   "room.json: lights[2].radius: must be > 0 (got -1)".
// Error codes: not JSON -> kBadFormat; a field missing, of the wrong type or out of range ->
// kInvalidValue; an unknown "type" or "version" -> kUnsupported; above a limit -> kTooLarge;
// the environment map unreadable -> the map reader's code (kIoError for a missing file).
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments. The only process-wide state touched is OpenEXR's own
// global thread pool (grown, never shrunk, when a call asks for more threads; OpenEXR
// guards it), which never changes the bytes read or written.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "codec/bake/scene.h"
#include "codec/status.h"

namespace zhc {

struct SceneJsonLimits {
    std::uint64_t max_file_bytes = std::uint64_t(64) << 20;
    std::uint64_t max_probes = std::uint64_t(1) << 22;  // as the JSON probe list
    std::uint64_t max_lights = 4096;
    std::uint64_t max_occluders = std::uint64_t(1) << 16;  // entries of "occluders" (a mesh is one)
    std::uint64_t max_triangles = std::uint64_t(1) << 21;  // over all meshes (and glTF instances)
    int max_shadow_samples = 4096;
    // Upper bound on shadow rays a bake may cast (probes x samples over shadowed lights), so a
    // hostile scene cannot ask for hours of tracing.
    std::uint64_t max_rays = std::uint64_t(1) << 32;
    // Texels of the textures a glTF scene's reflected light samples, over all of them (each is
    // held as 3 floats: 12 bytes per texel).
    std::uint64_t max_texels = std::uint64_t(1) << 25;
};

struct SceneLoadOptions {
    SceneJsonLimits limits;
    int threads = 1;             // environment map projection
    bool load_environment = true;  // false: keep the map path in environment->source, SH zero
    // environment.latlong when the scene does not say (glTF scenes and glTF outputs: kGltf).
    LatLongConvention default_latlong = LatLongConvention::kOpenExr;
    // >= 0: replaces the scene's transport.bounces (`zhc bake --bounces`) while the scene is read,
    // so that a glTF scene decodes its textures only when the bake will trace reflected light.
    int bounces = -1;
};

// `name` is used in messages; `base_dir` resolves the environment map path.
Result<Scene> parse_scene_json(std::span<const std::uint8_t> bytes, const std::string& name,
                               const std::string& base_dir, const SceneLoadOptions& options = {});
Result<Scene> read_scene_file(const std::string& path, const SceneLoadOptions& options = {});

// `text` with control characters (a newline in a JSON string or key echoed into an error)
// written as \xNN, so an error message stays one line.
std::string one_line_message(std::string_view text);

// kTooLarge ("NAME: lights: the bake would cast P x S shadow rays, above the limit of ...") when
// the shadowed lights of `s` would trace more than limits.max_rays rays; Ok without occluders.
Status check_ray_budget(const Scene& s, const SceneJsonLimits& limits, const std::string& name);

// The scene as JSON (the schema above). An environment is written with its `source` path as
// "map"; each run of consecutive triangle occluders is written as one "mesh" (no indices). Round trip: parse_scene_json(scene_json(s)) gives s back (angles via degrees).
std::string scene_json(const Scene& scene);

}  // namespace zhc
