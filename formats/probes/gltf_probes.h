// zhc/formats/probes/gltf_probes.h — probe sets inside glTF 2.0 assets: the ZHC_light_probes extension.
//
// Spec: docs/gltf-extension.md (schema docs/schema/ZHC_light_probes.schema.json). Embedding keeps
// everything else of the input (meshes, materials, other extensions, buffers byte-for-byte): the
// probe data goes to the end of the GLB binary buffer (whose existing bytes stay a prefix) or, for
// .gltf output, into a new data-URI buffer. Reading is strict and safe for untrusted input: URIs
// may not leave the input's directory, sizes are checked before allocating, images are never
// decoded, and every index/byte range of the extension is bound-checked.
//
// Frames: positions and grids are stored in glTF axes, (x, y, z)_glTF = (y, z, x)_zhc (a proper
// rotation); the SH coefficients are in the axes named by `shAxes` ("zhc" by default, exact).
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "codec/probe/probe_set.h"
#include "codec/status.h"

namespace zhc {

inline constexpr const char* kGltfProbeExtension = "ZHC_light_probes";

// zhc axes -> glTF axes, (x, y, z)_glTF = (y, z, x)_zhc, as a rotation matrix (R * v_zhc).
Mat3 zhc_to_gltf_rotation();

enum class GltfShAxes : std::uint8_t {
    kZhc = 0,   // coefficients in zhc's Z-up axes (exact round trip; default)
    kGltf = 1,  // coefficients rotated into glTF axes (float: rounded once; quantised: re-encoded)
};

struct GltfLimits {
    std::uint64_t max_file_bytes = std::uint64_t(1) << 30;    // input file (GLB or JSON)
    std::uint64_t max_buffer_bytes = std::uint64_t(1) << 30;  // one buffer's byteLength / data URI
    std::uint64_t max_total_bytes = std::uint64_t(1) << 31;   // all buffers (and external images)
    std::uint64_t max_probes = std::uint64_t(1) << 26;
};

struct GltfEmbedOptions {
    bool binary = true;                  // write GLB (else .gltf JSON with data-URI buffers)
    GltfShAxes sh_axes = GltfShAxes::kZhc;
    bool add_node = true;                // add a node referencing the volume to every scene
    std::string name = "zhc_probes";     // volume (and node) name
    // A volume of the same name already in the asset: false refuses the embedding
    // (kInvalidArgument naming the volume); true replaces it in place (same index, the nodes that
    // referenced it reference the new one, no node added). The replaced volume's accessors and
    // bytes stay in the asset, unreferenced.
    bool replace = false;
    bool draco = false;                  // Draco point cloud (points layout, float sh3/sh2 only)
    int draco_bits = 0;                  // Draco quantisation bits, 0 = lossless
    // Where the output will be written. Images the input references by a relative URI keep it
    // when the output goes to the input's folder; else they are referenced relative to the
    // output's folder when they lie inside it, else embedded (GLB: a bufferView of the binary
    // chunk; .gltf: a data: URI). Empty: URIs are copied verbatim.
    std::string output_path = {};
};

// One volume as read back: the set in zhc axes (grid order and positions converted back).
struct GltfProbeVolume {
    std::string name;
    ProbeSet set;
    GltfShAxes sh_axes = GltfShAxes::kZhc;
    bool draco = false;
    std::uint64_t stored_bytes = 0;  // bytes the volume's data takes in the buffer
    std::vector<int> nodes;          // nodes that reference the volume
};

struct GltfSummary {
    bool binary = false;
    std::string generator;
    std::size_t meshes = 0, materials = 0, nodes = 0, buffers = 0, accessors = 0, images = 0;
    std::vector<std::string> extensions_used, extensions_required;
    std::vector<GltfProbeVolume> volumes;
};

// True when the bytes start with the GLB magic "glTF".
bool looks_like_glb(std::span<const std::uint8_t> bytes);

// Embeds `set` (a valid ProbeSet) into the scene given as file bytes. `scene_path` locates
// external buffers (relative URIs are resolved in its directory, never outside). Returns the
// output file's bytes (GLB or .gltf JSON, per options.binary). Deterministic.
Result<std::vector<std::uint8_t>> embed_probes_gltf(std::span<const std::uint8_t> scene_bytes,
                                                    const std::string& scene_path, const ProbeSet& set,
                                                    const GltfEmbedOptions& options = {},
                                                    const GltfLimits& limits = {});

// Reads every ZHC_light_probes volume (kBadFormat/kUnsupported/kTooLarge with a clear message on
// anything malformed). An asset without the extension gives an empty list in the summary.
Result<GltfSummary> read_gltf_probes(std::span<const std::uint8_t> bytes, const std::string& path,
                                     const GltfLimits& limits = {});

// An asset loaded with the reader's checks (GLB framing, URIs confined to the input's directory,
// declared sizes before allocating; images never decoded): its JSON text and every buffer's
// bytes, for readers of other parts of an asset (formats/scene/scene_gltf.h).
struct GltfRaw {
    std::string json;
    std::vector<std::vector<std::uint8_t>> buffers;
    bool binary = false;
};
Result<GltfRaw> load_gltf_raw(std::span<const std::uint8_t> bytes, const std::string& path, const GltfLimits& limits = {});

// File helpers (atomic write).
Result<GltfSummary> read_gltf_probes_file(const std::string& path, const GltfLimits& limits = {});

}  // namespace zhc
