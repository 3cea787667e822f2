// zhc/formats/probes/gltf_draco.cpp — see gltf_draco.h.
#include "formats/probes/gltf_draco.h"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <draco/point_cloud/point_cloud_builder.h>

#include <cstring>

#include "codec/probe/codec.h"

namespace zhc {
namespace {

struct Group {
    const char* name;
    int first_float;  // within a probe's floats
    int floats;
};
// Band groups of the float layouts: L0 = coefficient 0 (RGB), L1 = 1..3, L2 = 4..8.
constexpr Group kSh3Groups[] = {{"L0", 0, 3}, {"L1", 3, 9}, {"L2", 12, 15}};

// One attribute per band of an entry stored as float RGB triples (CodecTraits::float_bands), else 0.
int groups_for(const std::string& representation) {
    const Codec* c = find_codec(representation);
    return c ? c->traits.float_bands : 0;
}

}  // namespace

Result<DracoProbeCloud> encode_probe_point_cloud(const std::vector<std::array<float, 3>>& positions,
                                                 const std::vector<std::uint8_t>& payload,
                                                 const std::string& representation, int quantization_bits) {
    const int ngroups = groups_for(representation);
    if (ngroups == 0) return make_error(ErrorCode::kInvalidArgument, "Draco payload needs encoding sh3 or sh2");
    if (quantization_bits < 0 || quantization_bits > 30)
        return make_error(ErrorCode::kInvalidArgument, "Draco quantisation bits must be 0 (lossless) or 1..30");
    const std::size_t n = positions.size();
    const std::size_t floats_per_probe = 3 * static_cast<size_t>(ngroups * ngroups);  // 27 or 12
    if (n == 0 || payload.size() != n * floats_per_probe * 4)
        return make_error(ErrorCode::kInvalidArgument, "Draco payload: positions and payload sizes disagree");
    std::vector<float> values(n * floats_per_probe);
    std::memcpy(values.data(), payload.data(), payload.size());  // little-endian host (x86-64, aarch64)

    draco::PointCloudBuilder builder;
    builder.Start(static_cast<draco::PointIndex::ValueType>(n));
    DracoProbeCloud out;
    const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
    builder.SetAttributeValuesForAllPoints(pos, positions.data(), 12);
    std::vector<int> ids{pos};
    std::vector<std::vector<float>> group_values(static_cast<size_t>(ngroups));
    for (int g = 0; g < ngroups; ++g) {
        const Group& gr = kSh3Groups[g];
        std::vector<float>& gv = group_values[static_cast<size_t>(g)];
        gv.resize(n * static_cast<size_t>(gr.floats));
        for (std::size_t i = 0; i < n; ++i)
            std::memcpy(&gv[i * static_cast<size_t>(gr.floats)], &values[i * floats_per_probe + static_cast<size_t>(gr.first_float)],
                        static_cast<size_t>(gr.floats) * 4);
        const int id = builder.AddAttribute(draco::GeometryAttribute::GENERIC, static_cast<int8_t>(gr.floats), draco::DT_FLOAT32);
        builder.SetAttributeValuesForAllPoints(id, gv.data(), gr.floats * 4);
        ids.push_back(id);
    }
    std::vector<std::uint32_t> index(n);
    for (std::size_t i = 0; i < n; ++i) index[i] = static_cast<std::uint32_t>(i);
    const int idx = builder.AddAttribute(draco::GeometryAttribute::GENERIC, 1, draco::DT_UINT32);
    builder.SetAttributeValuesForAllPoints(idx, index.data(), 4);
    ids.push_back(idx);
    std::unique_ptr<draco::PointCloud> pc = builder.Finalize(/*deduplicate_points=*/false);
    if (!pc) return make_error(ErrorCode::kInternal, "Draco point cloud builder failed");
    out.attributes["POSITION"] = static_cast<int>(pc->attribute(pos)->unique_id());
    for (int g = 0; g < ngroups; ++g)
        out.attributes[kSh3Groups[g].name] = static_cast<int>(pc->attribute(ids[static_cast<size_t>(g) + 1])->unique_id());
    out.attributes["INDEX"] = static_cast<int>(pc->attribute(idx)->unique_id());

    draco::Encoder encoder;
    // Sequential encoding keeps the point order (the k-d tree method would sort the points).
    encoder.SetEncodingMethod(draco::POINT_CLOUD_SEQUENTIAL_ENCODING);
    encoder.SetSpeedOptions(0, 0);
    if (quantization_bits > 0) {
        encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, quantization_bits);
        encoder.SetAttributeQuantization(draco::GeometryAttribute::GENERIC, quantization_bits);
    }
    draco::EncoderBuffer buffer;
    const draco::Status st = encoder.EncodePointCloudToBuffer(*pc, &buffer);
    if (!st.ok()) return make_error(ErrorCode::kInternal, std::string("Draco encode failed: ") + st.error_msg());
    out.bytes.assign(buffer.data(), buffer.data() + buffer.size());
    return out;
}

Result<DecodedProbeCloud> decode_probe_point_cloud(std::span<const std::uint8_t> bytes, const std::string& representation,
                                                   std::uint64_t count, const std::map<std::string, int>& attributes,
                                                   const std::string& where) {
    auto bad = [&](const std::string& what) { return make_error(ErrorCode::kBadFormat, where + ": Draco: " + what); };
    const int ngroups = groups_for(representation);
    if (ngroups == 0) return make_error(ErrorCode::kUnsupported, where + ": Draco payload needs encoding sh3 or sh2");
    // Draco allocates from the point count in its own header before anything can be checked, so
    // read the header first (Draco 2.x bitstream: "DRACO", major, minor, encoder type, method,
    // u16 flags, then for a sequential point cloud the i32 point count) and insist on exactly
    // what zhc writes: a point cloud, sequential method, no metadata, the volume's count.
    if (bytes.size() < 15 || std::memcmp(bytes.data(), "DRACO", 5) != 0) return bad("not a Draco bitstream");
    if (bytes[7] != 0 || bytes[8] != 0)
        return make_error(ErrorCode::kUnsupported, where + ": Draco: only sequential point clouds are supported");
    if (bytes[9] != 0 || bytes[10] != 0) return make_error(ErrorCode::kUnsupported, where + ": Draco: metadata/flags not supported");
    std::int32_t header_points;
    std::memcpy(&header_points, bytes.data() + 11, 4);
    if (header_points < 0 || static_cast<std::uint64_t>(header_points) != count)
        return bad("header declares " + std::to_string(header_points) + " points, the volume " + std::to_string(count));
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodePointCloudFromBuffer(&buffer);
    if (!decoded.ok()) return bad(decoded.status().error_msg_string());
    std::unique_ptr<draco::PointCloud> pc = std::move(decoded).value();
    if (pc->num_points() != count) return bad("point count " + std::to_string(pc->num_points()) + " != volume count " + std::to_string(count));
    auto attribute = [&](const char* name, int components, draco::DataType type) -> const draco::PointAttribute* {
        auto it = attributes.find(name);
        if (it == attributes.end() || it->second < 0) return nullptr;
        const draco::PointAttribute* a = pc->GetAttributeByUniqueId(static_cast<uint32_t>(it->second));
        if (!a || a->num_components() != components || a->data_type() != type) return nullptr;
        return a;
    };
    const std::size_t floats_per_probe = 3 * static_cast<size_t>(ngroups * ngroups);  // 27 or 12
    const draco::PointAttribute* pos = attribute("POSITION", 3, draco::DT_FLOAT32);
    const draco::PointAttribute* idx = attribute("INDEX", 1, draco::DT_UINT32);
    if (!pos || !idx) return bad("POSITION (3 x f32) or INDEX (1 x u32) attribute missing or of the wrong type");
    const std::size_t n = static_cast<std::size_t>(count);
    DecodedProbeCloud out;
    out.positions.resize(n);
    std::vector<float> values(n * floats_per_probe);
    std::vector<bool> seen(n, false);
    std::vector<std::size_t> slot(n);
    for (std::size_t p = 0; p < n; ++p) {
        std::uint32_t original = 0;
        if (!idx->ConvertValue<std::uint32_t>(idx->mapped_index(draco::PointIndex(static_cast<uint32_t>(p))), 1, &original) ||
            original >= n || seen[original])
            return bad("INDEX attribute is not a permutation of the probe numbers");
        seen[original] = true;
        slot[p] = original;
        if (!pos->ConvertValue<float>(pos->mapped_index(draco::PointIndex(static_cast<uint32_t>(p))), 3, out.positions[original].data()))
            return bad("cannot read POSITION");
    }
    for (int g = 0; g < ngroups; ++g) {
        const Group& gr = kSh3Groups[g];
        const draco::PointAttribute* a = attribute(gr.name, gr.floats, draco::DT_FLOAT32);
        if (!a) return bad(std::string(gr.name) + " attribute missing or of the wrong type");
        for (std::size_t p = 0; p < n; ++p)
            if (!a->ConvertValue<float>(a->mapped_index(draco::PointIndex(static_cast<uint32_t>(p))), static_cast<int8_t>(gr.floats),
                                        &values[slot[p] * floats_per_probe + static_cast<size_t>(gr.first_float)]))
                return bad(std::string("cannot read ") + gr.name);
    }
    out.payload.resize(values.size() * 4);
    std::memcpy(out.payload.data(), values.data(), out.payload.size());
    return out;
}

Result<DecodedDracoMesh> decode_draco_mesh(std::span<const std::uint8_t> bytes, int position_id, std::uint64_t expected_points,
                                           std::uint64_t expected_faces, const std::string& where, int texcoord_id) {
    auto bad = [&](const std::string& what) { return make_error(ErrorCode::kBadFormat, where + ": Draco: " + what); };
    // Header (Draco 2.x): "DRACO", major, minor, encoder type (1 = triangular mesh), method.
    if (bytes.size() < 11 || std::memcmp(bytes.data(), "DRACO", 5) != 0) return bad("not a Draco bitstream");
    if (bytes[7] != 1) return make_error(ErrorCode::kUnsupported, where + ": Draco: the bitstream is not a triangular mesh");
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) return bad(decoded.status().error_msg_string());
    std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
    if (mesh->num_points() != expected_points)
        return make_error(ErrorCode::kInvalidValue, where + ": Draco mesh has " + std::to_string(mesh->num_points()) +
                                                        " points, the POSITION accessor's count is " + std::to_string(expected_points));
    if (mesh->num_faces() != expected_faces)
        return make_error(ErrorCode::kInvalidValue, where + ": Draco mesh has " + std::to_string(mesh->num_faces()) +
                                                        " triangles, the indices accessor declares " + std::to_string(expected_faces));
    if (position_id < 0) return bad("no POSITION attribute id");
    const draco::PointAttribute* pos = mesh->GetAttributeByUniqueId(static_cast<uint32_t>(position_id));
    if (!pos || pos->num_components() != 3) return bad("POSITION attribute " + std::to_string(position_id) + " missing or not 3 components");
    DecodedDracoMesh out;
    out.positions.resize(mesh->num_points());
    for (draco::PointIndex p(0); p < mesh->num_points(); ++p)
        if (!pos->ConvertValue<float>(pos->mapped_index(p), 3, out.positions[p.value()].data())) return bad("cannot read POSITION");
    if (texcoord_id >= 0) {
        const draco::PointAttribute* uv = mesh->GetAttributeByUniqueId(static_cast<uint32_t>(texcoord_id));
        if (!uv || uv->num_components() != 2) return bad("TEXCOORD attribute " + std::to_string(texcoord_id) + " missing or not 2 components");
        out.texcoords.resize(mesh->num_points());
        for (draco::PointIndex p(0); p < mesh->num_points(); ++p)
            if (!uv->ConvertValue<float>(uv->mapped_index(p), 2, out.texcoords[p.value()].data())) return bad("cannot read TEXCOORD");
    }
    out.faces.resize(mesh->num_faces());
    for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f) {
        const draco::Mesh::Face& face = mesh->face(f);
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = face[k].value();
            if (v >= mesh->num_points()) return bad("face " + std::to_string(f.value()) + " names point " + std::to_string(v));
            out.faces[f.value()][static_cast<size_t>(k)] = v;
        }
    }
    return out;
}

}  // namespace zhc
