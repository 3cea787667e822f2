// Helpers shared by the ZHC_light_probes tests (test_gltf, test_gltf_hostile): scenes made with tinygltf
// (one with a Draco-compressed primitive), their JSON and buffers, probe sets from the real maps, the
// embed -> extract round trip.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "codec/probe/probe_set.h"
#include "formats/envmap/envmap.h"
#include "formats/io/file_io.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"
#include "support.h"

namespace zhc::gltf_test {

namespace fs = std::filesystem;
using nlohmann::json;
using Bytes = std::vector<std::uint8_t>;

// ---- scenes ---------------------------------------------------------------------------------

// A scene made with tinygltf: one triangle mesh, a material, an unknown vendor extension on the
// material and at the top level, extras; with `draco`, a second primitive compressed with
// KHR_draco_mesh_compression (encoded here with libdraco).
inline tinygltf::Model make_scene(bool draco) {
    tinygltf::Model m;
    m.asset.version = "2.0";
    m.asset.generator = "zhc test_gltf";
    m.buffers.emplace_back();
    std::vector<unsigned char>& data = m.buffers[0].data;
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    data.resize(sizeof tri);
    std::memcpy(data.data(), tri, sizeof tri);
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = 0;
    bv.byteLength = sizeof tri;
    bv.target = TINYGLTF_TARGET_ARRAY_BUFFER;
    m.bufferViews.push_back(bv);
    tinygltf::Accessor a;
    a.bufferView = 0;
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.type = TINYGLTF_TYPE_VEC3;
    a.count = 3;
    a.minValues = {0, 0, 0};
    a.maxValues = {1, 1, 0};
    m.accessors.push_back(a);
    tinygltf::Material mat;
    mat.name = "painted";
    mat.pbrMetallicRoughness.baseColorFactor = {0.8, 0.2, 0.1, 1.0};
    tinygltf::Value::Object vendor;
    vendor["answer"] = tinygltf::Value(42);
    vendor["label"] = tinygltf::Value(std::string("keep me"));
    mat.extensions["VENDOR_unknown_material"] = tinygltf::Value(vendor);
    m.materials.push_back(mat);
    tinygltf::Mesh mesh;
    mesh.name = "triangle";
    tinygltf::Primitive prim;
    prim.attributes["POSITION"] = 0;
    prim.material = 0;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    mesh.primitives.push_back(prim);
    if (draco) {
        draco::TriangleSoupMeshBuilder b;
        b.Start(2);
        const int pos = b.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
        b.SetAttributeValuesForFace(pos, draco::FaceIndex(0), tri, tri + 3, tri + 6);
        const float tri2[9] = {1, 0, 0, 1, 1, 0, 0, 1, 0};
        b.SetAttributeValuesForFace(pos, draco::FaceIndex(1), tri2, tri2 + 3, tri2 + 6);
        std::unique_ptr<draco::Mesh> dm = b.Finalize();
        draco::Encoder enc;
        draco::EncoderBuffer eb;
        EXPECT_TRUE(enc.EncodeMeshToBuffer(*dm, &eb).ok());
        while (data.size() % 4) data.push_back(0);
        tinygltf::BufferView dv;
        dv.buffer = 0;
        dv.byteOffset = data.size();
        dv.byteLength = eb.size();
        data.insert(data.end(), eb.data(), eb.data() + eb.size());
        while (data.size() % 4) data.push_back(0);
        m.bufferViews.push_back(dv);
        tinygltf::Accessor da;  // no bufferView: the data is in the Draco stream
        da.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        da.type = TINYGLTF_TYPE_VEC3;
        da.count = dm->num_points();
        da.minValues = {0, 0, 0};
        da.maxValues = {1, 1, 0};
        m.accessors.push_back(da);
        tinygltf::Primitive dp;
        dp.attributes["POSITION"] = 1;
        dp.mode = TINYGLTF_MODE_TRIANGLES;
        tinygltf::Value::Object attrs;
        attrs["POSITION"] = tinygltf::Value(static_cast<int>(dm->attribute(0)->unique_id()));
        tinygltf::Value::Object ext;
        ext["bufferView"] = tinygltf::Value(1);
        ext["attributes"] = tinygltf::Value(attrs);
        dp.extensions["KHR_draco_mesh_compression"] = tinygltf::Value(ext);
        tinygltf::Accessor ia;
        ia.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        ia.type = TINYGLTF_TYPE_SCALAR;
        ia.count = dm->num_faces() * 3;
        m.accessors.push_back(ia);
        dp.indices = 2;
        mesh.primitives.push_back(dp);
        m.extensionsUsed.push_back("KHR_draco_mesh_compression");
        m.extensionsRequired.push_back("KHR_draco_mesh_compression");
    }
    m.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = "tri";
    node.mesh = 0;
    m.nodes.push_back(node);
    tinygltf::Scene scene;
    scene.nodes = {0};
    m.scenes.push_back(scene);
    m.defaultScene = 0;
    tinygltf::Value::Object top;
    top["note"] = tinygltf::Value(std::string("unknown top-level extension"));
    m.extensions["VENDOR_unknown_top"] = tinygltf::Value(top);
    m.extensionsUsed.push_back("VENDOR_unknown_material");
    m.extensionsUsed.push_back("VENDOR_unknown_top");
    return m;
}

inline Bytes write_model(const tinygltf::Model& m, bool binary) {
    tinygltf::TinyGLTF w;
    std::ostringstream os;
    EXPECT_TRUE(w.WriteGltfSceneToStream(&m, os, !binary, binary));
    const std::string s = os.str();
    return Bytes(s.begin(), s.end());
}

inline json gltf_json(const Bytes& b) {
    if (looks_like_glb(b)) {
        std::uint32_t len;
        std::memcpy(&len, b.data() + 12, 4);
        return json::parse(std::string(reinterpret_cast<const char*>(b.data() + 20), len));
    }
    return json::parse(std::string(b.begin(), b.end()));
}

inline tinygltf::Model load_model(const Bytes& b) {
    tinygltf::TinyGLTF l;
    l.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                        void*) { return true; },
                     nullptr);
    tinygltf::Model m;
    std::string err, warn;
    bool ok = looks_like_glb(b) ? l.LoadBinaryFromMemory(&m, &err, &warn, b.data(), static_cast<unsigned>(b.size()))
                                : l.LoadASCIIFromString(&m, &err, &warn, reinterpret_cast<const char*>(b.data()),
                                                        static_cast<unsigned>(b.size()), "");
    EXPECT_TRUE(ok) << err;
    return m;
}

// Bytes of buffer i of a zhc output, read independently of tinygltf (which cannot load the
// Draco-mesh scene): the GLB BIN chunk for buffer 0 of a GLB, else the base64 data URI.
inline Bytes buffer_bytes(const Bytes& file, size_t i) {
    const json doc = gltf_json(file);
    const json& b = doc["buffers"][i];
    const size_t len = b["byteLength"].get<size_t>();
    if (looks_like_glb(file) && i == 0 && !b.contains("uri")) {
        std::uint32_t json_len;
        std::memcpy(&json_len, file.data() + 12, 4);
        const size_t at = 20 + json_len + 8;
        return Bytes(file.begin() + static_cast<std::ptrdiff_t>(at), file.begin() + static_cast<std::ptrdiff_t>(at + len));
    }
    const std::string uri = b["uri"].get<std::string>();
    const std::string data = uri.substr(uri.find(',') + 1);
    Bytes out;
    std::uint32_t acc = 0;
    int nbits = 0;
    for (char c : data) {
        int v = (c >= 'A' && c <= 'Z') ? c - 'A' : (c >= 'a' && c <= 'z') ? c - 'a' + 26 : (c >= '0' && c <= '9') ? c - '0' + 52 : c == '+' ? 62 : c == '/' ? 63 : -1;
        if (v < 0) break;
        acc = (acc << 6) | std::uint32_t(v);
        nbits += 6;
        if (nbits >= 8) {
            nbits -= 8;
            out.push_back(static_cast<std::uint8_t>(acc >> nbits));
        }
    }
    EXPECT_EQ(out.size(), len);
    return out;
}

// ---- probes ---------------------------------------------------------------------------------

// Probes from the 8 real environment maps (downsampled for speed), blended by position so the
// scattered set varies smoothly like a baked volume.
inline const std::vector<Sh3Radiance>& env_probes() {
    static const std::vector<Sh3Radiance> probes = [] {
        std::vector<Sh3Radiance> out;
        for (const std::string& p : test::envmap_paths()) {
            const Image img = test::downsample_latlong(test::load_envmap(p), 8);
            out.push_back(project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3));
        }
        return out;
    }();
    return probes;
}

inline Sh3Radiance blended_probe(Vec3 p) {
    const auto& env = env_probes();
    Sh3Radiance sh;
    double total = 0;
    for (size_t k = 0; k < env.size(); ++k) {
        const double w = 1.0 / (1.0 + dot(p - Vec3{double(k), 0.5 * double(k % 3), 0.25 * double(k % 2)},
                                          p - Vec3{double(k), 0.5 * double(k % 3), 0.25 * double(k % 2)}));
        sh = sh + scale(env[k], w);
        total += w;
    }
    return scale(sh, 1.0 / total);
}

inline ProbeSet scattered_set(std::size_t n, const std::string& rep, const CodecOptions& params = {}) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 8.0f);
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kPositions;
    std::vector<Sh3Radiance> hub;
    for (std::size_t i = 0; i < n; ++i) {
        const std::array<float, 3> p{u(rng), u(rng) * 0.5f, u(rng) * 0.25f};
        layout.positions.push_back(p);
        hub.push_back(blended_probe({p[0], p[1], p[2]}));
    }
    auto set = encode_probe_set(hub, rep, params, layout);
    EXPECT_TRUE(set) << set.error().message;
    return std::move(set).value();
}

inline ProbeSet grid_set(const std::string& rep, const CodecOptions& params = {}) {
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kGrid;
    layout.grid.origin = {-1.5, 0.25, 3};
    layout.grid.spacing = {0.5, 0.75, 1.25};
    layout.grid.counts = {5, 3, 4};
    std::vector<Sh3Radiance> hub;
    for (std::uint32_t z = 0; z < 4; ++z)
        for (std::uint32_t y = 0; y < 3; ++y)
            for (std::uint32_t x = 0; x < 5; ++x) hub.push_back(blended_probe({double(x), double(y), double(z)}));
    auto set = encode_probe_set(hub, rep, params, layout);
    EXPECT_TRUE(set) << set.error().message;
    return std::move(set).value();
}

inline void expect_same_set(const ProbeSet& a, const ProbeSet& b) {
    EXPECT_EQ(a.representation, b.representation);
    EXPECT_EQ(a.count, b.count);
    EXPECT_TRUE(a.payload == b.payload) << "payload bytes differ";
    EXPECT_EQ(a.layout.kind, b.layout.kind);
    EXPECT_TRUE(a.layout.positions == b.layout.positions);
    EXPECT_EQ(a.layout.grid.counts, b.layout.grid.counts);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(a.layout.grid.origin[k], b.layout.grid.origin[k]);
        EXPECT_EQ(a.layout.grid.spacing[k], b.layout.grid.spacing[k]);
    }
    const CodecOptions &p = a.params, &q = b.params;
    EXPECT_EQ(p.kind, q.kind);
    EXPECT_EQ(p.luminance.r, q.luminance.r);
    EXPECT_EQ(p.luminance.g, q.luminance.g);
    EXPECT_EQ(p.luminance.b, q.luminance.b);
    PackedLayout packed;
    if (!packed_layout_from_name(a.representation, &packed)) return;  // the rest only changes quantised bytes
    EXPECT_EQ(p.bits, q.bits);
    EXPECT_EQ(p.sqrt_encoding, q.sqrt_encoding);
    EXPECT_EQ(p.l2_bound, q.l2_bound);
    EXPECT_EQ(p.dc_format, q.dc_format);
    EXPECT_EQ(p.kind, q.kind);
    EXPECT_EQ(p.zonal_mapping, q.zonal_mapping);
    EXPECT_EQ(p.axis_mode, q.axis_mode);
    EXPECT_EQ(p.luminance.r, q.luminance.r);
    EXPECT_EQ(p.luminance.g, q.luminance.g);
    EXPECT_EQ(p.luminance.b, q.luminance.b);
}

inline GltfProbeVolume round_trip(const Bytes& scene, const ProbeSet& set, const GltfEmbedOptions& o = {}, Bytes* out_bytes = nullptr) {
    auto out = embed_probes_gltf(scene, "scene.glb", set, o);
    EXPECT_TRUE(out) << out.error().message;
    if (!out) return {};
    if (out_bytes) *out_bytes = *out;
    auto s = read_gltf_probes(*out, "out.glb");
    EXPECT_TRUE(s) << s.error().message;
    if (!s) return {};
    EXPECT_EQ(s->volumes.size(), 1u);
    return s->volumes.empty() ? GltfProbeVolume{} : s->volumes[0];
}

}  // namespace zhc::gltf_test
