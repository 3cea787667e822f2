// zhc/formats/probes/gltf_meshopt.h — EXT_meshopt_compression / KHR_meshopt_compression buffer views
// (the Khronos extension texts): one compressed bufferView decoded with Debian's
// libmeshoptimizer (meshopt_decodeVertexBuffer / IndexBuffer / IndexSequence and the
// OCTAHEDRAL / QUATERNION / EXPONENTIAL filters). Internal to formats/ (used by scene_gltf).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

enum class MeshoptMode : std::uint8_t { kAttributes, kTriangles, kIndices };
enum class MeshoptFilter : std::uint8_t { kNone, kOctahedral, kQuaternion, kExponential };

struct MeshoptView {
    std::uint64_t count = 0, stride = 0;
    MeshoptMode mode = MeshoptMode::kAttributes;
    MeshoptFilter filter = MeshoptFilter::kNone;
};

// "" when the (count, stride, mode, filter) combination is one the extension allows, else why not.
std::string meshopt_view_problem(const MeshoptView& v);

// Decodes `compressed` into count * stride bytes (the caller has checked that size against its
// limits and meshopt_view_problem). kBadFormat when the bytes do not decode, kUnsupported for a
// codec version this libmeshoptimizer does not know. `where` names the view in messages.
Result<std::vector<std::uint8_t>> decode_meshopt_view(std::span<const std::uint8_t> compressed, const MeshoptView& v,
                                                      const std::string& where);

}  // namespace zhc
