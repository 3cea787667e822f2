// zhc/formats/scene/scene_gltf.h — a lighting scene from a glTF 2.0 asset (docs/scene.md "glTF input").
//
// Read from the asset's default scene (`scene`, else scene 0; an asset with no scene at all uses
// every node that is no node's child, in index order), walking the node tree with each node's
// matrix or TRS:
//  * KHR_lights_punctual lights: directional (intensity in lux), point and spot (candela), colour,
//    spot innerConeAngle/outerConeAngle; lights shine down their node's local -Z;
//  * mesh primitives of mode TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN (POSITION, indices
//    optional; strips/fans triangulated as the spec orders them, index-degenerate joins dropped)
//    as triangle occluders, with the node's world transform applied; POINTS/LINES primitives
//    block nothing and are skipped. POSITION may be FLOAT or (KHR_mesh_quantization) [UNSIGNED_]
//    BYTE/SHORT, normalized or not; buffer views may be EXT_/KHR_meshopt_compression-compressed
//    (decoded with libmeshoptimizer, sizes checked first) and primitives
//    KHR_draco_mesh_compression-compressed (decoded with Draco, counts checked against the
//    accessors);
//  * EXT_mesh_gpu_instancing: a mesh node draws its mesh once per instance, world x T R S (i);
//  * EXT_lights_image_based: the scene's image-based light as its environment (the 9 SH
//    irradiance coefficients as SH3 radiance, with intensity and rotation; extras.zhc's
//    environment or sky wins over it);
//  * probe placement, sky, environment and extra lights/occluders from the optional root
//    `extras.zhc` object: a zhc JSON scene (docs/scene.md, zhc axes) whose `version` and `probes`
//    may be omitted (default probes: an 8 x 8 x 8 grid of cell centres over the bounds of the
//    meshes and point/spot lights),
//    plus `"gltf_light_shadows": bool` (default: true when the asset has triangle occluders).
// Axes: glTF is +Y up, zhc +Z up: (x, y, z)_zhc = (z, x, y)_glTF, the rotation ZHC_light_probes
// uses (formats/probes/gltf_probes.h), so probes baked from an asset embed back where they were.
// Units: 1 glTF nit (cd/m^2) = 1 zhc radiance unit: point/spot intensity I_zhc = I_cd * colour,
// directional E_zhc = E_lux * colour / pi (zhc's irradiance is normalised, integral L dw = pi E).
//
// Loading goes through the ZHC_light_probes reader's checks (formats/probes/gltf_probes.h load_gltf_raw:
// glTF 2.x only, bounded sizes, URIs resolved in the asset's own directory and confined to it);
// images are read and decoded (stb_image, under SceneJsonLimits::max_texels) only for the
// textures of a scene that traces reflected light (docs/scene.md "Reflected light"), their URIs
// confined like buffers'; every index, count, stride and byte range used here is
// bound-checked. Errors are one line naming the file and the JSON path: kIoError (a referenced
// file missing), kBadFormat (not glTF), kInvalidValue (a bad field or index, compressed data
// that does not decode to what it declares), kUnsupported (glTF 1.x/3.x, an unknown light type,
// sparse or UNSIGNED_INT positions, an unknown meshopt mode/filter or codec version),
// kTooLarge (a limit).
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
#include <vector>

#include "codec/bake/scene.h"
#include "codec/status.h"
#include "formats/probes/gltf_probes.h"
#include "formats/scene/scene_json.h"

namespace zhc {

// `path` names the asset in messages and locates external buffers and the environment map.
// `notes` (optional) receives one line per thing the asset defines that the bake does not use
// (an image-based light no scene references, or one that extras.zhc overrides).
Result<Scene> parse_scene_gltf(std::span<const std::uint8_t> bytes, const std::string& path,
                               const SceneLoadOptions& options = {}, const GltfLimits& gltf_limits = {},
                               std::vector<std::string>* notes = nullptr);

// True for paths ending in .gltf or .glb (any case).
bool is_gltf_path(const std::string& path);

}  // namespace zhc
