// ZHC_light_probes (formats/probes/gltf_probes.h, docs/gltf-extension.md): embed -> extract round trips
// (float lossless, quantised bit-exact, grid/points/none, radiance/irradiance), preservation of the
// scene's other content (mesh, material, unknown extensions, a Draco-compressed mesh; buffer bytes
// byte-for-byte), the frame conversion (positions and SH checked against dense direction
// sampling), the Draco point-cloud payload (order, losslessness, size), hostile inputs, and the
// CLI verbs. The real-client checks (glTF-Validator, three.js) are the node tests in tests/js/.
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

namespace zhc {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Bytes = std::vector<std::uint8_t>;

// ---- scenes ---------------------------------------------------------------------------------

// A scene made with tinygltf: one triangle mesh, a material, an unknown vendor extension on the
// material and at the top level, extras; with `draco`, a second primitive compressed with
// KHR_draco_mesh_compression (encoded here with libdraco).
tinygltf::Model make_scene(bool draco) {
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

Bytes write_model(const tinygltf::Model& m, bool binary) {
    tinygltf::TinyGLTF w;
    std::ostringstream os;
    EXPECT_TRUE(w.WriteGltfSceneToStream(&m, os, !binary, binary));
    const std::string s = os.str();
    return Bytes(s.begin(), s.end());
}

json gltf_json(const Bytes& b) {
    if (looks_like_glb(b)) {
        std::uint32_t len;
        std::memcpy(&len, b.data() + 12, 4);
        return json::parse(std::string(reinterpret_cast<const char*>(b.data() + 20), len));
    }
    return json::parse(std::string(b.begin(), b.end()));
}

tinygltf::Model load_model(const Bytes& b) {
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
Bytes buffer_bytes(const Bytes& file, size_t i) {
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
const std::vector<Sh3Radiance>& env_probes() {
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

Sh3Radiance blended_probe(Vec3 p) {
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

ProbeSet scattered_set(std::size_t n, const std::string& rep, const StorageParams& params = {}) {
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

ProbeSet grid_set(const std::string& rep, const StorageParams& params = {}) {
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

void expect_same_set(const ProbeSet& a, const ProbeSet& b) {
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
    const StorageParams &p = a.params, &q = b.params;
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

GltfProbeVolume round_trip(const Bytes& scene, const ProbeSet& set, const GltfEmbedOptions& o = {}, Bytes* out_bytes = nullptr) {
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

// ---- round trips ------------------------------------------------------------------------------

TEST(GltfProbes, FloatSh3LosslessEveryLayoutBothContainers) {
    const Bytes scene = write_model(make_scene(false), true);
    ProbeSet none = scattered_set(1, "sh3");
    none.layout = {};
    for (const ProbeSet& set : {scattered_set(300, "sh3"), grid_set("sh3"), none}) {
        for (bool binary : {true, false}) {
            GltfEmbedOptions o;
            o.binary = binary;
            Bytes out;
            const GltfProbeVolume v = round_trip(scene, set, o, &out);
            expect_same_set(set, v.set);
            EXPECT_EQ(v.sh_axes, GltfShAxes::kZhc);
            ASSERT_EQ(v.nodes.size(), 1u);
            EXPECT_EQ(looks_like_glb(out), binary);
            const json doc = gltf_json(out);
            EXPECT_FALSE(doc.contains("extensionsRequired") &&
                         std::find(doc["extensionsRequired"].begin(), doc["extensionsRequired"].end(), kGltfProbeExtension) !=
                             doc["extensionsRequired"].end());
            EXPECT_NE(std::find(doc["extensionsUsed"].begin(), doc["extensionsUsed"].end(), kGltfProbeExtension),
                      doc["extensionsUsed"].end());
        }
    }
}

TEST(GltfProbes, QuantisedBitExact) {
    const Bytes scene = write_model(make_scene(false), true);
    StorageParams odd;
    odd.bits = 6;
    odd.sqrt_encoding = true;
    odd.zonal_mapping = ZonalMapping::kZeroPreserving;
    odd.l2_bound = L2Bound::kLoose;
    odd.dc_format = DcFormat::kRGB9E5;
    odd.luminance = {0.3, 0.59, 0.11};
    StorageParams irr;
    irr.kind = StoredKind::kIrradiance;
    StorageParams chan;
    chan.axis_mode = ZonalAxisMode::kPerChannel;
    int checked = 0;
    for (const Codec& c : codecs()) {
        const std::string rep(c.name);
        for (const StorageParams& p : {StorageParams{}, odd, irr, chan}) {
            if (!validate_quant_params(p, rep)) continue;
            for (const ProbeSet& set : {scattered_set(64, rep, p), grid_set(rep, p)}) {
                const GltfProbeVolume v = round_trip(scene, set);
                SCOPED_TRACE(rep);
                expect_same_set(set, v.set);
                ++checked;
            }
        }
    }
    std::printf("bit-exact embed -> extract: %d (representation, params, layout) cases over %zu codecs\n", checked,
                codecs().size());
    EXPECT_GT(checked, 20);
}

TEST(GltfProbes, VolumesAppendAndNodesReference) {
    const Bytes scene = write_model(make_scene(false), true);
    auto once = embed_probes_gltf(scene, "s.glb", grid_set("zh3_q16"));
    ASSERT_TRUE(once);
    auto twice = embed_probes_gltf(*once, "s.glb", scattered_set(10, "sh3"));
    ASSERT_TRUE(twice);
    auto s = read_gltf_probes(*twice, "t.glb");
    ASSERT_TRUE(s) << s.error().message;
    ASSERT_EQ(s->volumes.size(), 2u);
    EXPECT_EQ(s->volumes[0].set.representation, "zh3_q16");
    EXPECT_EQ(s->volumes[1].set.representation, "sh3");
    ASSERT_EQ(s->volumes[1].nodes.size(), 1u);
    const json doc = gltf_json(*twice);
    EXPECT_EQ(doc["nodes"][s->volumes[1].nodes[0]]["extensions"][kGltfProbeExtension]["volume"], 1);
    // The new nodes are roots of the scene, so the probes move with the scene.
    EXPECT_EQ(doc["scenes"][0]["nodes"].size(), 3u);
}

// ---- the scene's other content survives --------------------------------------------------------

void expect_preserved(const tinygltf::Model& original, const Bytes& in, const Bytes& out) {
    const json a = gltf_json(in), b = gltf_json(out);
    for (const char* key : {"meshes", "materials", "extensionsRequired", "asset"}) {
        if (a.contains(key)) {
            EXPECT_EQ(a[key], b[key]) << key;
        }
    }
    EXPECT_EQ(a["extensions"]["VENDOR_unknown_top"], b["extensions"]["VENDOR_unknown_top"]);
    for (size_t i = 0; i < a["accessors"].size(); ++i) EXPECT_EQ(a["accessors"][i], b["accessors"][i]);
    for (size_t i = 0; i < a["bufferViews"].size(); ++i) EXPECT_EQ(a["bufferViews"][i], b["bufferViews"][i]);
    for (size_t i = 0; i < a["nodes"].size(); ++i) EXPECT_EQ(a["nodes"][i], b["nodes"][i]);
    for (const auto& e : a["extensionsUsed"])
        EXPECT_NE(std::find(b["extensionsUsed"].begin(), b["extensionsUsed"].end(), e), b["extensionsUsed"].end());
    ASSERT_GE(b["buffers"].size(), original.buffers.size());
    for (size_t i = 0; i < original.buffers.size(); ++i) {
        const auto& ob = original.buffers[i].data;
        const Bytes nb = buffer_bytes(out, i);
        ASSERT_GE(nb.size(), ob.size());
        EXPECT_TRUE(std::equal(ob.begin(), ob.end(), nb.begin())) << "buffer " << i << " bytes changed";
    }
}

TEST(GltfProbes, SceneContentSurvivesByteForByte) {
    for (bool draco : {false, true}) {
        const tinygltf::Model scene_model = make_scene(draco);
        for (bool in_binary : {true, false}) {
            const Bytes scene = write_model(scene_model, in_binary);
            for (bool out_binary : {true, false}) {
                GltfEmbedOptions o;
                o.binary = out_binary;
                auto out = embed_probes_gltf(scene, "scene.gltf", grid_set("sh3_q28"), o);
                ASSERT_TRUE(out) << out.error().message;
                SCOPED_TRACE(std::string(draco ? "draco mesh " : "") + (in_binary ? "glb->" : "gltf->") + (out_binary ? "glb" : "gltf"));
                expect_preserved(scene_model, scene, *out);
                // The Draco mesh's compressed bytes are still decodable (same bytes as before).
                if (draco) {
                    EXPECT_EQ(gltf_json(*out)["meshes"][0]["primitives"][1]["extensions"]["KHR_draco_mesh_compression"]["bufferView"], 1);
                }
            }
        }
    }
}

TEST(GltfProbes, ExternalBufferInsideDirectoryIsRead) {
    const std::string dir = test::temp_dir("gltf_external");
    const tinygltf::Model m = make_scene(false);
    test::write_bytes(dir + "/scene.bin", Bytes(m.buffers[0].data.begin(), m.buffers[0].data.end()));
    json doc = gltf_json(write_model(m, false));
    doc["buffers"][0]["uri"] = "scene.bin";
    const std::string text = doc.dump();
    test::write_bytes(dir + "/scene.gltf", Bytes(text.begin(), text.end()));
    auto out = embed_probes_gltf(test::read_bytes(dir + "/scene.gltf"), dir + "/scene.gltf", grid_set("sh3"));
    ASSERT_TRUE(out) << out.error().message;
    const tinygltf::Model back = load_model(*out);
    EXPECT_TRUE(std::equal(m.buffers[0].data.begin(), m.buffers[0].data.end(), back.buffers[0].data.begin()));
}

// ---- frames -----------------------------------------------------------------------------------

TEST(GltfProbes, FrameIsAProperRotationUpGoesToY) {
    const Mat3 r = zhc_to_gltf_rotation();
    const Vec3 up = r * Vec3{0, 0, 1};
    EXPECT_EQ(up.x, 0);
    EXPECT_EQ(up.y, 1);
    EXPECT_EQ(up.z, 0);
    const double det = r(0, 0) * (r(1, 1) * r(2, 2) - r(1, 2) * r(2, 1)) - r(0, 1) * (r(1, 0) * r(2, 2) - r(1, 2) * r(2, 0)) +
                       r(0, 2) * (r(1, 0) * r(2, 1) - r(1, 1) * r(2, 0));
    EXPECT_EQ(det, 1.0);
}

// Positions in the file are the zhc positions rotated into glTF axes, and in glTF order for grids.
TEST(GltfProbes, StoredPositionsAndGridOrderAreInGltfAxes) {
    const Bytes scene = write_model(make_scene(false), true);
    const ProbeSet pts = scattered_set(20, "sh3");
    auto out = embed_probes_gltf(scene, "s.glb", pts);
    ASSERT_TRUE(out);
    const tinygltf::Model m = load_model(*out);
    const json vol = gltf_json(*out)["extensions"][kGltfProbeExtension]["volumes"][0];
    const tinygltf::Accessor& a = m.accessors[vol["positions"].get<size_t>()];
    const tinygltf::BufferView& bv = m.bufferViews[static_cast<size_t>(a.bufferView)];
    const Mat3 r = zhc_to_gltf_rotation();
    for (size_t i = 0; i < pts.count; ++i) {
        float g[3];
        std::memcpy(g, m.buffers[0].data.data() + bv.byteOffset + i * 12, 12);
        const auto& z = pts.layout.positions[i];
        const Vec3 want = r * Vec3{z[0], z[1], z[2]};
        EXPECT_EQ(g[0], want.x);
        EXPECT_EQ(g[1], want.y);
        EXPECT_EQ(g[2], want.z);
    }
    // Grid: the glTF probe at glTF grid cell (a, b, c) is the zhc probe at the same world point.
    const ProbeSet grid = grid_set("sh3");
    auto gout = embed_probes_gltf(scene, "s.glb", grid);
    ASSERT_TRUE(gout);
    const tinygltf::Model gm = load_model(*gout);
    const json gv = gltf_json(*gout)["extensions"][kGltfProbeExtension]["volumes"][0];
    const tinygltf::BufferView& cv = gm.bufferViews[static_cast<size_t>(gm.accessors[gv["coefficients"].get<size_t>()].bufferView)];
    const auto counts = gv["grid"]["counts"].get<std::array<std::uint64_t, 3>>();
    const auto origin = gv["grid"]["origin"].get<std::array<double, 3>>();
    const auto spacing = gv["grid"]["spacing"].get<std::array<double, 3>>();
    const Mat3 rt = transpose(r);
    for (std::uint64_t c = 0; c < counts[2]; ++c)
        for (std::uint64_t b = 0; b < counts[1]; ++b)
            for (std::uint64_t a2 = 0; a2 < counts[0]; ++a2) {
                const std::uint64_t gi = a2 + counts[0] * (b + counts[1] * c);
                const Vec3 pg{origin[0] + double(a2) * spacing[0], origin[1] + double(b) * spacing[1], origin[2] + double(c) * spacing[2]};
                const Vec3 pz = rt * pg;
                // Find the zhc probe at that position.
                bool found = false;
                for (std::uint64_t i = 0; i < grid.count; ++i) {
                    const Vec3 q = probe_position(grid, i);
                    if (q.x == pz.x && q.y == pz.y && q.z == pz.z) {
                        found = true;
                        EXPECT_EQ(0, std::memcmp(gm.buffers[0].data.data() + cv.byteOffset + gi * 108, grid.payload.data() + i * 108, 108));
                    }
                }
                EXPECT_TRUE(found) << gi;
            }
}

// --sh-axes gltf: the stored float coefficients, evaluated at a glTF direction R d, equal the zhc
// probe at d (checked on 2000 Fibonacci directions, the slow twin of the rotation); reading back
// gives the input to float rounding.
TEST(GltfProbes, GltfShAxesStoreRotatedCoefficients) {
    const Bytes scene = write_model(make_scene(false), true);
    const ProbeSet set = scattered_set(16, "sh3");
    GltfEmbedOptions o;
    o.sh_axes = GltfShAxes::kGltf;
    Bytes out;
    const GltfProbeVolume v = round_trip(scene, set, o, &out);
    EXPECT_EQ(v.sh_axes, GltfShAxes::kGltf);
    const tinygltf::Model m = load_model(out);
    const json vol = gltf_json(out)["extensions"][kGltfProbeExtension]["volumes"][0];
    EXPECT_EQ(vol["shAxes"], "gltf");
    const tinygltf::BufferView& bv = m.bufferViews[static_cast<size_t>(m.accessors[vol["coefficients"].get<size_t>()].bufferView)];
    const Mat3 r = zhc_to_gltf_rotation();
    const auto dirs = test::fibonacci_directions(2000);
    const Codec& sh3 = *find_codec("sh3");
    double worst = 0, worst_back = 0;
    for (std::uint64_t i = 0; i < set.count; ++i) {
        const Sh3Radiance stored = sh3.decode(m.buffers[0].data.data() + bv.byteOffset + i * 108, {});
        const Sh3Radiance orig = sh3.decode(set.payload.data() + i * 108, {});
        const Sh3Radiance back = sh3.decode(v.set.payload.data() + i * 108, {});
        for (const Vec3& d : dirs) {
            const Rgb want = evaluate(orig, d), got = evaluate(stored, r * d), again = evaluate(back, d);
            for (int k = 0; k < 3; ++k) {
                worst = std::max(worst, std::abs(double(got[k]) - double(want[k])) / (1e-3 + std::abs(double(want[k]))));
                worst_back = std::max(worst_back, std::abs(double(again[k]) - double(want[k])) / (1e-3 + std::abs(double(want[k]))));
            }
        }
    }
    std::printf("shAxes gltf: worst relative radiance error stored-vs-zhc %.3g, read-back %.3g\n", worst, worst_back);
    EXPECT_LT(worst, 1e-5);
    EXPECT_LT(worst_back, 1e-5);
    // Positions are converted the same way as with zhc axes.
    EXPECT_TRUE(v.set.layout.positions == set.layout.positions);
}

// ---- Draco ------------------------------------------------------------------------------------

TEST(GltfProbes, DracoPointCloudKeepsOrderAndSavesSpace) {
    const Bytes scene = write_model(make_scene(false), true);
    const ProbeSet set = scattered_set(4000, "sh3");
    Bytes plain;
    round_trip(scene, set, {}, &plain);
    std::printf("Draco point cloud, %llu scattered sh3 probes (positions + 27 floats):\n", static_cast<unsigned long long>(set.count));
    std::printf("| mode | probe bytes in file | vs float accessors | max abs coefficient error |\n| --- | ---: | ---: | ---: |\n");
    const GltfProbeVolume p = round_trip(scene, set);
    std::printf("| float accessors | %llu | 1.000 | 0 |\n", static_cast<unsigned long long>(p.stored_bytes));
    for (int bits : {0, 16, 14, 12, 10}) {
        GltfEmbedOptions o;
        o.draco = true;
        o.draco_bits = bits;
        const GltfProbeVolume v = round_trip(scene, set, o);
        ASSERT_TRUE(v.draco);
        ASSERT_EQ(v.set.count, set.count);
        double err = 0;
        const auto hub_a = decode_probe_set(set).value(), hub_b = decode_probe_set(v.set).value();
        for (size_t i = 0; i < hub_a.size(); ++i)
            for (int c = 0; c < 9; ++c)
                for (int k = 0; k < 3; ++k) err = std::max(err, std::abs(double(hub_a[i][c][k]) - double(hub_b[i][c][k])));
        std::printf("| draco %s | %llu | %.3f | %.3g |\n", bits == 0 ? "lossless" : (std::to_string(bits) + " bits").c_str(),
                    static_cast<unsigned long long>(v.stored_bytes), double(v.stored_bytes) / double(p.stored_bytes), err);
        if (bits == 0) {
            expect_same_set(set, v.set);  // lossless and in the original order
        } else {
            // Order preserved: every probe is within the quantisation error of its own input (a
            // permutation would pair probes from different places, far off).
            EXPECT_LT(err, 0.05 * 4096.0 / double(1 << bits) + 1e-3);
            double pos_err = 0;
            for (size_t i = 0; i < set.count; ++i)
                for (int k = 0; k < 3; ++k)
                    pos_err = std::max(pos_err, double(std::abs(set.layout.positions[i][static_cast<size_t>(k)] -
                                                                 v.set.layout.positions[i][static_cast<size_t>(k)])));
            EXPECT_LT(pos_err, 9.0 * 2.0 / double(1 << bits) + 1e-6);
        }
        EXPECT_LT(v.stored_bytes, p.stored_bytes * (bits == 0 ? 1.05 : 0.8));
    }
}

TEST(GltfProbes, DracoRejectsGridOrQuantisedInput) {
    const Bytes scene = write_model(make_scene(false), true);
    GltfEmbedOptions o;
    o.draco = true;
    auto a = embed_probes_gltf(scene, "s.glb", grid_set("sh3"), o);
    ASSERT_FALSE(a);
    EXPECT_EQ(a.error().code, ErrorCode::kInvalidArgument);
    auto b = embed_probes_gltf(scene, "s.glb", scattered_set(5, "zh3_q16"), o);
    ASSERT_FALSE(b);
}

// A Draco stream whose header claims another point count (or another method) is rejected before
// the Draco decoder sees it (it would allocate from that count).
TEST(GltfProbes, DracoHeaderCheckedBeforeDecoding) {
    GltfEmbedOptions o;
    o.draco = true;
    auto out = embed_probes_gltf(write_model(make_scene(false), true), "s.glb", scattered_set(12, "sh3"), o);
    ASSERT_TRUE(out);
    const json doc = gltf_json(*out);
    const json& vol = doc["extensions"][kGltfProbeExtension]["volumes"][0];
    std::uint32_t json_len;
    std::memcpy(&json_len, out->data() + 12, 4);
    const size_t at = 20 + json_len + 8 + doc["bufferViews"][vol["draco"]["bufferView"].get<size_t>()]["byteOffset"].get<size_t>();
    ASSERT_EQ(0, std::memcmp(out->data() + at, "DRACO", 5));
    Bytes b = *out;
    const std::int32_t huge = 1 << 30;
    std::memcpy(b.data() + at + 11, &huge, 4);
    auto r = read_gltf_probes(b, "count.glb");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("header declares 1073741824 points"), std::string::npos) << r.error().message;
    b = *out;
    b[at + 8] = 1;  // k-d tree method
    r = read_gltf_probes(b, "method.glb");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kUnsupported);
    b = *out;
    b[at + 40] ^= 0x5A;  // damage inside the stream: an error or a (checked) decode, never a crash
    (void)read_gltf_probes(b, "flip.glb");
}

// ---- hostile inputs ---------------------------------------------------------------------------

Bytes text_bytes(const json& j) {
    const std::string s = j.dump();
    return Bytes(s.begin(), s.end());
}

void expect_rejected(const Bytes& b, const std::string& path, ErrorCode code, const std::string& needle) {
    auto r = read_gltf_probes(b, path);
    ASSERT_FALSE(r) << "accepted: " << needle;
    EXPECT_EQ(r.error().code, code) << r.error().message;
    EXPECT_NE(r.error().message.find(needle), std::string::npos) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_EQ(r.error().message.rfind(path, 0), 0u) << r.error().message;
}

TEST(GltfProbes, HostileUrisRejectedBeforeReading) {
    const std::string dir = test::temp_dir("gltf_hostile");
    fs::create_directories(dir + "/inner");
    test::write_bytes(dir + "/secret.bin", Bytes(36, 7));  // outside inner/
    const json base = gltf_json(write_model(make_scene(false), false));
    for (const std::string uri : {"../secret.bin", "%2e%2e/secret.bin", "sub/../../secret.bin", "/etc/passwd",
                                  "file:///etc/passwd", "http://example.com/a.bin", "C:\\x.bin", "..\\secret.bin",
                                  "%2fetc/passwd", "a%00b"}) {
        json doc = base;
        doc["buffers"][0]["uri"] = uri;
        doc["buffers"][0]["byteLength"] = 36;
        expect_rejected(text_bytes(doc), dir + "/inner/scene.gltf", ErrorCode::kBadFormat, "uri rejected");
        // The CLI exits 4 and leaves no output.
        test::write_bytes(dir + "/inner/scene.gltf", text_bytes(doc));
        const auto r = test::run_zhc({"gltf", "extract", dir + "/inner/scene.gltf", "-o", dir + "/out.json"});
        EXPECT_EQ(r.exit_code, 4) << uri << r.err;
        EXPECT_FALSE(fs::exists(dir + "/out.json"));
    }
    // Symlink escaping the directory: caught by the file-system guard.
    std::error_code ec;
    fs::create_symlink(dir + "/secret.bin", dir + "/inner/link.bin", ec);
    if (!ec) {
        json doc = base;
        doc["buffers"][0]["uri"] = "link.bin";
        doc["buffers"][0]["byteLength"] = 36;
        expect_rejected(text_bytes(doc), dir + "/inner/scene.gltf", ErrorCode::kBadFormat, "outside the input's directory");
    }
    // Images: the URI is checked too, and images are never decoded (garbage PNG bytes are fine).
    json doc = base;
    doc["images"] = json::array({json{{"uri", "../x.png"}}});
    expect_rejected(text_bytes(doc), dir + "/inner/scene.gltf", ErrorCode::kBadFormat, "images[0]: uri rejected");
    doc["images"] = json::array({json{{"uri", "data:image/png;base64,AAAAAAAA"}}});
    EXPECT_TRUE(read_gltf_probes(text_bytes(doc), dir + "/inner/scene.gltf"));
}

TEST(GltfProbes, HugeDeclaredSizesRejected) {
    const json base = gltf_json(write_model(make_scene(false), false));
    json doc = base;
    doc["buffers"][0]["byteLength"] = std::uint64_t(1) << 40;
    expect_rejected(text_bytes(doc), "huge.gltf", ErrorCode::kTooLarge, "byteLength");
    doc = base;
    doc["buffers"] = json::array();
    for (int i = 0; i < 3; ++i) doc["buffers"].push_back(json{{"byteLength", std::uint64_t(1) << 30}, {"uri", "a.bin"}});
    expect_rejected(text_bytes(doc), "many.gltf", ErrorCode::kTooLarge, "total");
    GltfLimits small;
    small.max_buffer_bytes = 1000;
    doc = base;
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + std::string(4000, 'A');
    doc["buffers"][0]["byteLength"] = 36;
    auto r = read_gltf_probes(text_bytes(doc), "datauri.gltf", small);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);
    // Volume count above the probe limit.
    auto out = embed_probes_gltf(write_model(make_scene(false), true), "s.glb", grid_set("sh3"), {.binary = false});
    ASSERT_TRUE(out);
    doc = gltf_json(*out);
    doc["extensions"][kGltfProbeExtension]["volumes"][0]["count"] = std::uint64_t(1) << 40;
    expect_rejected(text_bytes(doc), "count.gltf", ErrorCode::kTooLarge, "count");
}

TEST(GltfProbes, BadExtensionIndicesRejected) {
    GltfEmbedOptions o;
    o.binary = false;
    auto out = embed_probes_gltf(write_model(make_scene(false), true), "s.glb", scattered_set(8, "zh3_q16"), o);
    ASSERT_TRUE(out);
    const json good = gltf_json(*out);
    ASSERT_TRUE(read_gltf_probes(text_bytes(good), "good.gltf"));
    const std::string vol = std::string("/extensions/") + kGltfProbeExtension + "/volumes/0";
    struct Case {
        std::string pointer;
        json value;
        ErrorCode code;
        std::string needle;
    };
    const std::vector<Case> cases = {
        {vol + "/coefficients", 999, ErrorCode::kBadFormat, "coefficients is not a valid index"},
        {vol + "/coefficients", -1, ErrorCode::kBadFormat, "coefficients is not a valid index"},
        {vol + "/coefficients", "x", ErrorCode::kBadFormat, "coefficients is not a valid index"},
        {vol + "/positions", 1 << 20, ErrorCode::kBadFormat, "positions is not a valid index"},
        {vol + "/positions", 2, ErrorCode::kBadFormat, "positions accessor 2 has the wrong component type"},
        {vol + "/count", 9, ErrorCode::kBadFormat, "elements, expected"},
        {vol + "/count", 0, ErrorCode::kBadFormat, "count is not a positive integer"},
        {vol + "/encoding", "no_such_codec", ErrorCode::kUnsupported, "unknown encoding"},
        {vol + "/layout", "spiral", ErrorCode::kUnsupported, "layout must be"},
        {vol + "/kind", "luminance", ErrorCode::kUnsupported, "kind"},
        {vol + "/quantization/bits", 99, ErrorCode::kBadFormat, "bits"},
        {vol + "/shAxes", "yup", ErrorCode::kUnsupported, "shAxes"},
        {"/nodes/1/extensions/" + std::string(kGltfProbeExtension) + "/volume", 5, ErrorCode::kBadFormat, "valid volume index"},
    };
    for (const Case& c : cases) {
        json doc = good;
        doc[json::json_pointer(c.pointer)] = c.value;
        SCOPED_TRACE(c.pointer);
        expect_rejected(text_bytes(doc), "bad.gltf", c.code, c.needle);
    }
    // Accessor ranges pointing past the buffer, and a bufferView pointing at a missing buffer.
    json doc = good;
    const size_t acc = good["extensions"][kGltfProbeExtension]["volumes"][0]["coefficients"].get<size_t>();
    const size_t view = good["accessors"][acc]["bufferView"].get<size_t>();
    doc["accessors"][acc]["byteOffset"] = 1 << 20;
    auto r = read_gltf_probes(text_bytes(doc), "range.gltf");
    EXPECT_FALSE(r);
    doc = good;
    doc["bufferViews"][view]["byteLength"] = std::uint64_t(1) << 31;
    EXPECT_FALSE(read_gltf_probes(text_bytes(doc), "range.gltf"));
    doc = good;
    doc["extensions"][kGltfProbeExtension]["volumes"] = "nope";
    expect_rejected(text_bytes(doc), "vols.gltf", ErrorCode::kBadFormat, "volumes is not an array");
}

TEST(GltfProbes, BadGlbFramingRejected) {
    auto out = embed_probes_gltf(write_model(make_scene(false), true), "s.glb", grid_set("sh3"));
    ASSERT_TRUE(out);
    const Bytes good = *out;
    // Every proper prefix fails cleanly (no crash), never silently succeeds.
    for (size_t n = 0; n < good.size(); n += std::max<size_t>(1, good.size() / 300)) {
        Bytes b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
        EXPECT_FALSE(read_gltf_probes(b, "cut.glb")) << n;
    }
    Bytes b = good;
    b.push_back(0);
    expect_rejected(b, "long.glb", ErrorCode::kTrailingBytes, "declared length");
    b = good;
    b[12] = 0xFF;  // JSON chunk length
    b[13] = 0xFF;
    b[14] = 0xFF;
    expect_rejected(b, "chunk.glb", ErrorCode::kTruncated, "JSON chunk");
    b = good;
    b[4] = 1;
    expect_rejected(b, "v1.glb", ErrorCode::kUnsupported, "version");
    // Random byte flips: never a crash (results may be accepted when a flip hits padding).
    std::mt19937 rng(3);
    for (int i = 0; i < 300; ++i) {
        Bytes f = good;
        f[rng() % f.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        (void)read_gltf_probes(f, "flip.glb");
    }
}

// ---- CLI ----------------------------------------------------------------------------------------

TEST(GltfCli, EmbedExtractEvalInfo) {
    const std::string dir = test::temp_dir("gltf_cli");
    test::write_bytes(dir + "/scene.glb", write_model(make_scene(true), true));
    const ProbeSet set = grid_set("zh3_q16");
    ASSERT_TRUE(write_probe_file(dir + "/probes.zhp", set));
    auto r = test::run_zhc({"gltf", "embed", dir + "/scene.glb", dir + "/probes.zhp", "-o", dir + "/out.glb"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"gltf", "extract", dir + "/out.glb", "-o", dir + "/back.zhp"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto back = read_probe_file(dir + "/back.zhp");
    ASSERT_TRUE(back);
    expect_same_set(set, *back);
    // eval: glTF probe 7 in glTF direction d equals the zhc irradiance of the same probe at R^T d.
    const json vol = gltf_json(test::read_bytes(dir + "/out.glb"))["extensions"][kGltfProbeExtension]["volumes"][0];
    const auto gc = vol["grid"]["counts"].get<std::array<std::uint64_t, 3>>();
    const std::uint64_t g = 7, a = g % gc[0], b = (g / gc[0]) % gc[1], c = g / (gc[0] * gc[1]);
    // glTF cell (a, b, c) = zhc cell (c, a, b).
    const std::uint64_t zi = c + 5 * (a + 3 * b);
    const Codec& codec = *set.codec();
    const Sh3Radiance hub = decode_probe(codec, set.params, set.payload.data() + zi * codec.size_bytes);
    const Vec3 dg = normalize_or({0.3, 0.8, -0.52}, {0, 1, 0});
    const Rgb want = irradiance(hub, transpose(zhc_to_gltf_rotation()) * dg);
    r = test::run_zhc({"gltf", "eval", dir + "/out.glb", "--probe", "7", "--dir", "0.3,0.8,-0.52"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    double e[3];
    ASSERT_EQ(std::sscanf(r.out.c_str(), "%lf %lf %lf", &e[0], &e[1], &e[2]), 3);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(e[k], want[k], 1e-6 * std::abs(want[k]) + 1e-9);
    r = test::run_zhc({"info", dir + "/out.glb", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json info = json::parse(r.out);
    EXPECT_EQ(info["volumes"][0]["encoding"], "zh3_q16");
    EXPECT_EQ(info["volumes"][0]["probes"], 60);
    // Errors (bad output extension, Draco on a grid, missing scene, an asset without probes):
    // tests/conformance cli_usage_gltf_extension, gltfprobes_*.
}

}  // namespace
}  // namespace zhc
