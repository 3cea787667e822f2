// ZHC_light_probes (formats/probes/gltf_probes.h, docs/gltf-extension.md): embed -> extract round trips
// (float lossless, quantised bit-exact, grid/points/none, radiance/irradiance), preservation of the
// scene's other content (mesh, material, unknown extensions, a Draco-compressed mesh; buffer bytes
// byte-for-byte) and the frame conversion (positions and SH checked against dense direction
// sampling). The Draco point-cloud payload, hostile inputs and the CLI verbs are in
// test_gltf_hostile.cpp (helpers: gltf_helpers.h); the real-client checks (glTF-Validator, three.js)
// are the node tests in tests/js/.
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
#include "gltf_helpers.h"
#include "support.h"

namespace zhc {
namespace {

using namespace gltf_test;

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
    CodecOptions odd;
    odd.bits = 6;
    odd.sqrt_encoding = true;
    odd.zonal_mapping = ZonalMapping::kZeroPreserving;
    odd.l2_bound = L2Bound::kLoose;
    odd.dc_format = DcFormat::kRGB9E5;
    odd.luminance = {0.3, 0.59, 0.11};
    CodecOptions irr;
    irr.kind = StoredKind::kIrradiance;
    CodecOptions chan;
    chan.axis_mode = ZonalAxisMode::kPerChannel;
    int checked = 0;
    for (const Codec& c : codecs()) {
        const std::string rep(c.name);
        for (const CodecOptions& p : {CodecOptions{}, odd, irr, chan}) {
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
    GltfEmbedOptions second;
    second.name = "second";  // a volume of the name already there is refused (GltfInputs.EmbedOntoAnExistingVolumeRefusedOrReplaced)
    auto twice = embed_probes_gltf(*once, "s.glb", scattered_set(10, "sh3"), second);
    ASSERT_TRUE(twice) << twice.error().message;
    auto s = read_gltf_probes(*twice, "t.glb");
    ASSERT_TRUE(s) << s.error().message;
    ASSERT_EQ(s->volumes.size(), 2u);
    EXPECT_EQ(s->volumes[0].set.representation, "zh3_q16");
    EXPECT_EQ(s->volumes[1].set.representation, "sh3");
    EXPECT_EQ(s->volumes[1].name, "second");
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

}  // namespace
}  // namespace zhc
