// zhc/formats/probes/gltf_meshopt.cpp — see gltf_meshopt.h.
#include "formats/probes/gltf_meshopt.h"

#include <meshoptimizer.h>

namespace zhc {

std::string meshopt_view_problem(const MeshoptView& v) {
    switch (v.mode) {
        case MeshoptMode::kAttributes:
            // meshopt_decodeVertexBuffer: 0 < stride <= 256, a multiple of 4.
            if (v.stride == 0 || v.stride > 256 || v.stride % 4 != 0) return "ATTRIBUTES need a byteStride that is a multiple of 4 in [4, 256]";
            break;
        case MeshoptMode::kTriangles:
            if (v.stride != 2 && v.stride != 4) return "TRIANGLES need byteStride 2 or 4";
            if (v.count % 3 != 0) return "TRIANGLES need a count that is a multiple of 3";
            break;
        case MeshoptMode::kIndices:
            if (v.stride != 2 && v.stride != 4) return "INDICES need byteStride 2 or 4";
            break;
    }
    if (v.filter != MeshoptFilter::kNone && v.mode != MeshoptMode::kAttributes) return "filters apply to ATTRIBUTES only";
    if (v.filter == MeshoptFilter::kOctahedral && v.stride != 4 && v.stride != 8) return "OCTAHEDRAL needs byteStride 4 or 8";
    if (v.filter == MeshoptFilter::kQuaternion && v.stride != 8) return "QUATERNION needs byteStride 8";
    return "";  // EXPONENTIAL: any multiple of 4, checked above
}

Result<std::vector<std::uint8_t>> decode_meshopt_view(std::span<const std::uint8_t> compressed, const MeshoptView& v,
                                                      const std::string& where) {
    const std::string why = meshopt_view_problem(v);
    if (!why.empty()) return make_error(ErrorCode::kInvalidValue, where + ": " + why);
    if (compressed.empty()) return make_error(ErrorCode::kBadFormat, where + ": meshopt: empty compressed data");
    // Header byte: 0xa0 | version (vertex codec), 0xe0 | version (index), 0xd0 | version (sequence).
    const int header = compressed[0];
    const int version = header & 0x0f;
    const int kind = header & 0xf0;
    const int expected_kind = v.mode == MeshoptMode::kAttributes ? 0xa0 : v.mode == MeshoptMode::kTriangles ? 0xe0 : 0xd0;
    if (kind != expected_kind) return make_error(ErrorCode::kBadFormat, where + ": meshopt: header does not match the view's mode");
    const int known = v.mode == MeshoptMode::kAttributes ? 0 : 1;  // libmeshoptimizer 0.18: vertex v0, index/sequence v0-v1
    if (version > known)
        return make_error(ErrorCode::kUnsupported, where + ": meshopt codec version " + std::to_string(version) +
                                                       " (this build decodes up to version " + std::to_string(known) + ")");
    std::vector<std::uint8_t> out(static_cast<size_t>(v.count * v.stride));
    if (out.empty()) return out;  // nothing to decode (and no null destination for the library)
    const size_t n = static_cast<size_t>(v.count), stride = static_cast<size_t>(v.stride);
    int rc = 0;
    switch (v.mode) {
        case MeshoptMode::kAttributes: rc = meshopt_decodeVertexBuffer(out.data(), n, stride, compressed.data(), compressed.size()); break;
        case MeshoptMode::kTriangles: rc = meshopt_decodeIndexBuffer(out.data(), n, stride, compressed.data(), compressed.size()); break;
        case MeshoptMode::kIndices: rc = meshopt_decodeIndexSequence(out.data(), n, stride, compressed.data(), compressed.size()); break;
    }
    if (rc != 0) return make_error(ErrorCode::kBadFormat, where + ": meshopt data does not decode (error " + std::to_string(rc) + ")");
    switch (v.filter) {
        case MeshoptFilter::kNone: break;
        case MeshoptFilter::kOctahedral: meshopt_decodeFilterOct(out.data(), n, stride); break;
        case MeshoptFilter::kQuaternion: meshopt_decodeFilterQuat(out.data(), n, stride); break;
        case MeshoptFilter::kExponential: meshopt_decodeFilterExp(out.data(), n, stride); break;
    }
    return out;
}

}  // namespace zhc
