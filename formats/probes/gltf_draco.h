// zhc/formats/probes/gltf_draco.h — scattered float probes as a Draco point cloud (ZHC_light_probes
// "draco" payload, docs/gltf-extension.md "Draco"). Internal to formats/ (used by gltf_probes).
//
// Attributes: POSITION (3 x f32), one GENERIC f32 attribute per SH band group (L0: 3, L1: 9,
// L2: 15 floats; sh2 has no L2) and INDEX (1 x u32, the original probe number). Encoded with
// Draco's sequential point-cloud method and no deduplication, so points keep their order; the
// decoder still reorders by INDEX (and checks it is a permutation), so any conforming encoder
// works. quantization_bits = 0 stores floats losslessly.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

struct DracoProbeCloud {
    std::vector<std::uint8_t> bytes;
    std::map<std::string, int> attributes;  // name -> Draco unique id
};

// positions: glTF axes, one per probe; payload: count * size_bytes of an sh3/sh2 payload.
Result<DracoProbeCloud> encode_probe_point_cloud(const std::vector<std::array<float, 3>>& positions,
                                                 const std::vector<std::uint8_t>& payload,
                                                 const std::string& representation, int quantization_bits);

struct DecodedProbeCloud {
    std::vector<std::array<float, 3>> positions;
    std::vector<std::uint8_t> payload;
};
Result<DecodedProbeCloud> decode_probe_point_cloud(std::span<const std::uint8_t> bytes, const std::string& representation,
                                                   std::uint64_t count, const std::map<std::string, int>& attributes,
                                                   const std::string& where);

// A KHR_draco_mesh_compression primitive's triangles (the extension text): positions (glTF axes,
// dequantised to float) of the Draco attribute with unique id `position_id`, and the faces as
// point indices. Only triangular-mesh bitstreams are read (kUnsupported otherwise); the point
// and face counts must equal `expected_points` / `expected_faces` (the primitive's accessors,
// checked against zhc's limits before this is called) or the result is kInvalidValue. With
// `texcoord_id` >= 0, also that 2-component attribute per point (texture coordinates, dequantised).
struct DecodedDracoMesh {
    std::vector<std::array<float, 3>> positions;
    std::vector<std::array<std::uint32_t, 3>> faces;
    std::vector<std::array<float, 2>> texcoords;  // empty unless texcoord_id >= 0
};
Result<DecodedDracoMesh> decode_draco_mesh(std::span<const std::uint8_t> bytes, int position_id, std::uint64_t expected_points,
                                           std::uint64_t expected_faces, const std::string& where, int texcoord_id = -1);

}  // namespace zhc
