// zhc/formats/probes/gltf_probes_internal.h — internal to formats/: what the three files of the
// ZHC_light_probes implementation (docs/gltf-extension.md, glTF 2.0) share: the guarded tinygltf
// load of an untrusted asset, GLB / data-URI writing, and the zhc <-> glTF frames.
//   gltf_probes.cpp        file access confined to the input's folder, the tinygltf load, GLB writing, frames
//   gltf_probes_check.cpp  untrusted input checked before tinygltf: GLB framing, version, sizes, URIs
//   gltf_probes_read.cpp   reading and validating the extension (volumes, accessors, Draco payloads)
//   gltf_probes_write.cpp  embedding a probe set into an asset (buffers, accessors, images, GLB)
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "formats/io/le_bytes.h"
#include "formats/probes/gltf_probes.h"

namespace zhc::gltf_detail {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
inline constexpr auto le32 = le::load32;

inline constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
inline constexpr int kUbyte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
inline constexpr int kUint = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;

inline constexpr std::uint32_t kGlbMagic = 0x46546C67;   // "glTF"
inline constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
inline constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

// "<path>: <what>" as an error of `code`.
Error fail(ErrorCode code, const std::string& path, const std::string& what);

// ---- untrusted input, checked before tinygltf sees it (gltf_probes_check.cpp) ----

// A GLB split into its JSON text and the place of its BIN chunk.
struct GlbParts {
    std::string json_text;
    bool has_bin = false;
    std::uint64_t bin_offset = 0;
    std::uint64_t bin_bytes = 0;
};
// The GLB framing: header, length, JSON chunk, optional BIN chunk (nothing after the declared length).
Result<GlbParts> split_glb(std::span<const std::uint8_t> b, const std::string& path);
// "" when the URI is an acceptable relative reference inside the input's directory (or a data
// URI), else why not (percent escapes decoded first).
std::string uri_problem(const std::string& uri);
// Per buffer, whether it needs no bytes under EXT_/KHR_meshopt_compression: marked
// `"fallback": true`, or referenced by at least one bufferView and only by views that carry the
// extension (each decoded from its compressed source, never from this buffer) and never the
// source of a compressed view. One pass over the views; empty when `buffers` is not an array.
std::vector<bool> meshopt_placeholders(const json& doc);
// Every declared size and buffer URI, glTF 2.x only (asset.version / minVersion), before
// tinygltf allocates anything; `glb` is null for a .gltf file.
Status precheck(const json& doc, const std::string& path, const GltfLimits& limits, const GlbParts* glb);
// The glTF 2.0 schema's required properties (and KHR_lights_punctual's), named by glTF path.
Status check_required(const json& doc, const std::string& path);

// The path a relative URI names (percent escapes decoded; call after the URI was accepted).
std::string uri_path(const std::string& uri);
// Whether `p` lies inside `base` (both canonical).
bool inside(const fs::path& base, const fs::path& p);
// `file` (canonical, inside the canonical `base`) spelled from `user_dir`, the folder as the caller
// named it (empty: the working directory): the path a build system sees in a depfile
// (formats/io/file_io.h FileRecorder), relative when the asset was named by a relative path.
fs::path user_spelling(const fs::path& user_dir, const fs::path& base, const fs::path& file);

// GLB 2.0: header, JSON chunk padded with spaces, optional BIN chunk padded with zeros.
std::vector<std::uint8_t> make_glb(const std::string& json_text, std::span<const std::uint8_t> bin);
std::string base64(std::span<const std::uint8_t> b);
std::string data_uri(std::span<const std::uint8_t> b);  // data:application/octet-stream;base64,...

// An asset loaded from untrusted bytes: our own parse of its JSON and tinygltf's model (used for
// buffer bytes only).
struct Loaded {
    json doc;
    tinygltf::Model model;
    bool binary = false;
    std::vector<size_t> placeholder_buffers;  // uri-less meshopt placeholder buffers (no bytes loaded)
};

// Checks the framing, every URI and declared size, then loads the asset with tinygltf reading
// only files inside the input's directory (see gltf_probes.cpp).
Result<Loaded> load(std::span<const std::uint8_t> bytes, const std::string& path, const GltfLimits& limits);

// Frames: (x, y, z)_glTF = (y, z, x)_zhc.
std::array<float, 3> to_gltf(const std::array<float, 3>& p);
std::array<float, 3> from_gltf(const std::array<float, 3>& p);
Vec3 to_gltf(Vec3 v);
Vec3 from_gltf(Vec3 v);

// Whether the encoding's coefficients are stored as a VEC3 float accessor (else UNSIGNED_BYTE SCALAR).
bool is_float_vec3_encoding(const std::string& name);

// Re-encodes every probe after rotating it by r (decode -> rotate -> encode); validity,
// visibility, cell planes and tetrahedra are kept.
Result<ProbeSet> rotate_set(const ProbeSet& set, const Mat3& r);

// A visibility mask or a cell plane's sides byte (bit cx + 2 cy + 4 cz, c per grid axis) from
// zhc's grid axes to the glTF grid's (glTF axis 0, 1, 2 = zhc axis 1, 2, 0) and back.
std::uint8_t visibility_to_gltf(std::uint8_t mask);
std::uint8_t visibility_from_gltf(std::uint8_t mask);
// A corner region's (docs/runtime.md "Corner regions") per-axis fields permuted to glTF axes
// (to_gltf) or back.
void region_entry_axes(std::uint8_t e[5], bool to_gltf);

// Grid probe order zhc (i fastest, zhc axes) <-> glTF (glTF x = zhc y fastest).
std::vector<std::uint8_t> reorder_grid(const std::vector<std::uint8_t>& payload, std::size_t size,
                                       const std::array<std::uint32_t, 3>& zc, bool to_gltf_order);

}  // namespace zhc::gltf_detail
