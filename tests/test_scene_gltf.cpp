// glTF scene input (formats/scene/scene_gltf.h) and `zhc bake -o OUT.glb|.gltf`: glTF files written by
// the test (JSON + a base64 buffer) against the same scene written as zhc JSON (the twin), spot
// cones, directional lights, mesh occluders with node transforms, strict errors, and the embedded
// probes equal to the .zhp output.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

#include "codec/bake/scene.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"
#include "formats/scene/scene_gltf.h"
#include "formats/scene/scene_json.h"
#include "formats/io/file_io.h"
#include "formats/report/html_report.h"
#include "formats/report/raster.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string base64(const std::vector<std::uint8_t>& b) { return base64_encode(b); }  // formats/report/html_report.h

// A glTF asset built by hand: one buffer (data URI), accessors appended as needed.
struct Asset {
    json doc = {{"asset", {{"version", "2.0"}, {"generator", "zhc test_scene_gltf"}}},
                {"scene", 0},
                {"scenes", json::array({json{{"nodes", json::array()}}})},
                {"nodes", json::array()}};
    std::vector<std::uint8_t> bin;

    size_t view(const void* data, size_t bytes) {
        while (bin.size() % 4) bin.push_back(0);
        const size_t off = bin.size();
        bin.insert(bin.end(), static_cast<const std::uint8_t*>(data), static_cast<const std::uint8_t*>(data) + bytes);
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", bytes}});
        return doc["bufferViews"].size() - 1;
    }
    size_t positions(const std::vector<float>& xyz) {
        const size_t v = view(xyz.data(), xyz.size() * 4);
        std::array<float, 3> lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
        for (size_t i = 0; i < xyz.size(); ++i) {
            lo[i % 3] = std::min(lo[i % 3], xyz[i]);
            hi[i % 3] = std::max(hi[i % 3], xyz[i]);
        }
        doc["accessors"].push_back({{"bufferView", v}, {"componentType", 5126}, {"count", xyz.size() / 3}, {"type", "VEC3"}, {"min", lo}, {"max", hi}});
        return doc["accessors"].size() - 1;
    }
    size_t indices16(const std::vector<std::uint16_t>& idx) {
        const size_t v = view(idx.data(), idx.size() * 2);
        doc["accessors"].push_back({{"bufferView", v}, {"componentType", 5123}, {"count", idx.size()}, {"type", "SCALAR"}});
        return doc["accessors"].size() - 1;
    }
    // A mesh of one TRIANGLES primitive; returns the mesh index.
    size_t mesh(const std::vector<float>& xyz, const std::vector<std::uint16_t>& idx) {
        json prim = {{"attributes", {{"POSITION", positions(xyz)}}}};
        if (!idx.empty()) prim["indices"] = indices16(idx);
        doc["meshes"].push_back({{"primitives", json::array({prim})}});
        return doc["meshes"].size() - 1;
    }
    size_t light(json l) {
        doc["extensionsUsed"] = json::array({"KHR_lights_punctual"});
        doc["extensions"]["KHR_lights_punctual"]["lights"].push_back(std::move(l));
        return doc["extensions"]["KHR_lights_punctual"]["lights"].size() - 1;
    }
    // A node (optionally a root of the scene); returns its index.
    size_t node(json n, bool root = true) {
        doc["nodes"].push_back(std::move(n));
        const size_t i = doc["nodes"].size() - 1;
        if (root) doc["scenes"][0]["nodes"].push_back(i);
        return i;
    }
    static json light_node(size_t light, json extra = json::object()) {
        extra["extensions"]["KHR_lights_punctual"]["light"] = light;
        return extra;
    }
    std::string text() const {
        json d = doc;
        if (!bin.empty()) d["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
        return d.dump(1);
    }
    std::vector<std::uint8_t> bytes() const {
        const std::string t = text();
        return {t.begin(), t.end()};
    }
};

Result<Scene> parse(const Asset& a, const std::string& name = "test.gltf") {
    return parse_scene_gltf(a.bytes(), name);
}
Result<Scene> parse_json(const json& j) {
    const std::string t = j.dump();
    return parse_scene_json(std::vector<std::uint8_t>(t.begin(), t.end()), "twin.json", "");
}

std::vector<Sh3Radiance> bake(const Scene& s) {
    auto r = bake_scene(s);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? *r : std::vector<Sh3Radiance>{};
}

const json kProbes = {{"positions", {{0, 0, 0}, {1, -2, 0.5}, {-1.5, 0.5, 2.5}}}};  // zhc axes

TEST(SceneGltf, PointLightEqualsTheSameSceneInJson) {
    Asset a;
    const size_t l = a.light({{"type", "point"}, {"name", "bulb"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 40.0}});
    a.node(Asset::light_node(l, {{"translation", {1.0, 2.0, 3.0}}}));  // glTF (1, 2, 3) = zhc (3, 1, 2)
    a.doc["extras"]["zhc"] = {{"probes", kProbes}};
    auto g = parse(a);
    ASSERT_TRUE(g.ok()) << g.error().message;
    ASSERT_EQ(g->lights.size(), 1u);
    EXPECT_EQ(g->lights[0].name, "bulb");
    EXPECT_FALSE(g->lights[0].shadows);  // no meshes: nothing to trace
    auto j = parse_json({{"version", 1}, {"probes", kProbes},
                         {"lights", {{{"type", "point"}, {"position", {3, 1, 2}}, {"intensity", {40, 20, 10}}}}}});
    ASSERT_TRUE(j.ok()) << j.error().message;
    const auto bg = bake(*g), bj = bake(*j);
    ASSERT_EQ(bg.size(), 3u);
    for (size_t p = 0; p < 3; ++p) {
        EXPECT_GT(test::max_abs(bj[p]), 0.1);
        EXPECT_EQ(bg[p], bj[p]) << "probe " << p;  // same numbers in, same bytes out
    }
}

TEST(SceneGltf, NodeHierarchyMatrixAndTrs) {
    // Parent: rotation of 90 degrees about glTF +Y then translation (10, 0, 0); child: a matrix
    // translating by (0, 1, 2). The light sits at parent (R * (0, 1, 2) + (10, 0, 0)):
    // R_y(90) (x, y, z) = (z, y, -x) -> (2, 1, 0) -> glTF (12, 1, 0) -> zhc (0, 12, 1).
    Asset a;
    const size_t l = a.light({{"type", "point"}, {"intensity", 5.0}});
    const double h = std::sqrt(0.5);
    const size_t child = a.node(Asset::light_node(l, {{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 2, 1}}}), false);
    a.node({{"rotation", {0.0, h, 0.0, h}}, {"translation", {10.0, 0.0, 0.0}}, {"children", {child}}});
    a.doc["extras"]["zhc"] = {{"probes", kProbes}};
    auto g = parse(a);
    ASSERT_TRUE(g.ok()) << g.error().message;
    ASSERT_EQ(g->lights.size(), 1u);
    EXPECT_NEAR(g->lights[0].position.x, 0.0, 1e-12);
    EXPECT_NEAR(g->lights[0].position.y, 12.0, 1e-12);
    EXPECT_NEAR(g->lights[0].position.z, 1.0, 1e-12);
}

TEST(SceneGltf, SpotConeMatchesJsonTwin) {
    // A spot 4 m above the origin pointing down: its node is rotated -90 degrees about glTF +X,
    // which turns the light's local -Z into glTF -Y (zhc -Z).
    Asset a;
    const double h = std::sqrt(0.5);
    const size_t l = a.light({{"type", "spot"}, {"intensity", 10.0}, {"spot", {{"innerConeAngle", 20 * kPi / 180}, {"outerConeAngle", 30 * kPi / 180}}}});
    a.node(Asset::light_node(l, {{"translation", {0.0, 4.0, 0.0}}, {"rotation", {-h, 0.0, 0.0, h}}}));
    auto at = [](double deg) {
        const double r = deg * kPi / 180;
        return json::array({2 * std::sin(r), 0.0, 4 - 2 * std::cos(r)});
    };
    const json probes = {{"positions", {at(10), at(25), at(35)}}};
    a.doc["extras"]["zhc"] = {{"probes", probes}};
    auto g = parse(a);
    ASSERT_TRUE(g.ok()) << g.error().message;
    EXPECT_NEAR(g->lights[0].direction.z, -1.0, 1e-12);
    auto j = parse_json({{"version", 1}, {"probes", probes},
                         {"lights", {{{"type", "spot"}, {"position", {0, 0, 4}}, {"direction", {0, 0, -1}}, {"intensity", 10},
                                      {"inner_angle_deg", 20}, {"outer_angle_deg", 30}}}}});
    ASSERT_TRUE(j.ok()) << j.error().message;
    const auto bg = bake(*g), bj = bake(*j);
    for (size_t p = 0; p < 3; ++p) EXPECT_LT(test::max_abs_diff(bg[p], bj[p]), 1e-6 * (test::max_abs(bj[p]) + 1)) << p;
    EXPECT_GT(test::max_abs(bg[0]), 0.1);    // inside the inner cone
    EXPECT_GT(test::max_abs(bg[1]), 0.01);   // in the falloff
    EXPECT_LT(test::max_abs(bg[1]), test::max_abs(bg[0]));
    EXPECT_EQ(test::max_abs(bg[2]), 0.0);    // outside the outer cone
}

TEST(SceneGltf, DirectionalLightIsLuxOverPi) {
    // Sun straight overhead: the node turns local -Z into glTF -Y; towards the light is zhc +Z.
    Asset a;
    const double h = std::sqrt(0.5);
    const size_t l = a.light({{"type", "directional"}, {"intensity", 3.0}, {"color", {1.0, 0.9, 0.8}}});
    a.node(Asset::light_node(l, {{"rotation", {-h, 0.0, 0.0, h}}}));
    a.doc["extras"]["zhc"] = {{"probes", kProbes}};
    auto g = parse(a);
    ASSERT_TRUE(g.ok()) << g.error().message;
    EXPECT_NEAR(g->lights[0].direction.z, 1.0, 1e-12);
    auto j = parse_json({{"version", 1}, {"probes", kProbes},
                         {"lights", {{{"type", "directional"}, {"direction", {0, 0, 1}}, {"irradiance", {3 / kPi, 2.7 / kPi, 2.4 / kPi}}}}}});
    ASSERT_TRUE(j.ok());
    const auto bg = bake(*g), bj = bake(*j);
    for (size_t p = 0; p < 3; ++p) EXPECT_LT(test::max_abs_diff(bg[p], bj[p]), 1e-6) << p;
    // Physically: a surface facing the sun receives E_v = 3 lux = integral L cos; zhc's normalised
    // SH3 irradiance of a delta keeps 4.25 / (4 pi) of it (bands 1 + 2 + 5/4), times 1 / pi.
    EXPECT_NEAR(irradiance(bg[0], {0, 0, 1}).r, 3.0 * 4.25 / (4 * kPi), 1e-5);
}

// A quad (two triangles) in local [-0.5, 0.5]^2 at y = 0, scaled by 2 and moved to glTF y = 2 by
// its node: zhc z = 2, x and y in [-1, 1].
size_t add_quad(Asset& a) {
    const size_t m = a.mesh({-0.5f, 0, -0.5f, 0.5f, 0, -0.5f, 0.5f, 0, 0.5f, -0.5f, 0, 0.5f}, {0, 1, 2, 0, 2, 3});
    return a.node({{"mesh", m}, {"translation", {0.0, 2.0, 0.0}}, {"scale", {2.0, 1.0, 2.0}}});
}

TEST(SceneGltf, MeshOccluderBlocksTheLight) {
    Asset a;
    add_quad(a);
    const size_t l = a.light({{"type", "point"}, {"intensity", 8.0}});
    a.node(Asset::light_node(l, {{"translation", {0.0, 4.0, 0.0}}}));  // zhc (0, 0, 4)
    a.doc["extras"]["zhc"] = {{"probes", {{"positions", {{0, 0, 0}, {3, 0, 0}}}}}};
    auto g = parse(a);
    ASSERT_TRUE(g.ok()) << g.error().message;
    ASSERT_EQ(g->occluders.size(), 2u);
    EXPECT_TRUE(g->lights[0].shadows);  // the asset has meshes: glTF lights cast shadows
    for (const Occluder& o : g->occluders) {
        EXPECT_EQ(o.kind, OccluderKind::kTriangle);
        for (const Vec3& v : {o.v0, o.v1, o.v2}) {
            EXPECT_EQ(v.z, 2.0);
            EXPECT_EQ(std::abs(v.x), 1.0);
            EXPECT_EQ(std::abs(v.y), 1.0);
        }
    }
    const auto b = bake(*g);
    EXPECT_EQ(test::max_abs(b[0]), 0.0);  // behind the quad: the light's contribution is gone
    // Probe 1 sees the light: equal to the unshadowed twin.
    auto j = parse_json({{"version", 1}, {"probes", {{"positions", {{0, 0, 0}, {3, 0, 0}}}}},
                         {"lights", {{{"type", "point"}, {"position", {0, 0, 4}}, {"intensity", 8}}}}});
    ASSERT_TRUE(j.ok());
    const auto bj = bake(*j);
    EXPECT_GT(test::max_abs(bj[0]), 0.1);
    EXPECT_EQ(b[1], bj[1]);
    // extras.zhc.gltf_light_shadows = false switches the shadows off.
    a.doc["extras"]["zhc"]["gltf_light_shadows"] = false;
    auto off = parse(a);
    ASSERT_TRUE(off.ok()) << off.error().message;
    EXPECT_EQ(bake(*off)[0], bj[0]);
}

TEST(SceneGltf, ExtrasAddSkyAndDefaultProbesCoverTheMeshes) {
    Asset a;
    add_quad(a);
    auto g = parse(a);
    ASSERT_TRUE(g.ok()) << g.error().message;
    // Bounds x, y in [-1, 1], z = 2 (flat): 8 x 8 x 1 cell centres.
    EXPECT_EQ(g->probes.kind, ProbePlacementKind::kGrid);
    EXPECT_EQ(g->probes.counts, (std::array<std::uint32_t, 3>{8, 8, 1}));
    EXPECT_NEAR(g->probes.min.x, -1 + 1.0 / 8, 1e-12);
    EXPECT_NEAR(g->probes.max.y, 1 - 1.0 / 8, 1e-12);
    EXPECT_EQ(g->probes.min.z, 2.0);
    EXPECT_FALSE(g->sky.has_value());
    a.doc["extras"]["zhc"] = {{"sky", {{"type", "constant"}, {"radiance", 0.5}}},
                              {"lights", {{{"type", "sphere"}, {"center", {0, 0, 5}}, {"radius", 0.5}, {"radiance", 3}}}}};
    auto s = parse(a);
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_TRUE(s->sky.has_value());
    EXPECT_EQ(s->lights.size(), 1u);
}

TEST(SceneGltf, StrictErrorsNameTheFileAndField) {
    struct Case {
        const char* what;
        std::function<void(Asset&)> edit;
        ErrorCode code;
        const char* message;
    };
    const Case cases[] = {
        {"light index", [](Asset& a) { a.node(Asset::light_node(7)); }, ErrorCode::kInvalidValue,
         "nodes[0].extensions.KHR_lights_punctual.light: must be an index into KHR_lights_punctual.lights"},
        {"light type", [](Asset& a) { a.node(Asset::light_node(a.light({{"type", "area"}}))); }, ErrorCode::kUnsupported,
         "extensions.KHR_lights_punctual.lights[0].type: unknown light type \"area\""},
        {"spot cone", [](Asset& a) { a.node(Asset::light_node(a.light({{"type", "spot"}, {"spot", {{"innerConeAngle", 0.5}, {"outerConeAngle", 0.5}}}}))); },
         ErrorCode::kInvalidValue, "lights[0].spot: need 0 <= innerConeAngle < outerConeAngle <= pi/2"},
        {"negative intensity", [](Asset& a) { a.node(Asset::light_node(a.light({{"type", "point"}, {"intensity", -1}}))); },
         ErrorCode::kInvalidValue, "lights[0].intensity: must be >= 0"},
        {"cycle", [](Asset& a) { a.node({{"children", {0}}}); }, ErrorCode::kInvalidValue, "nodes[0]: reached twice"},
        {"matrix and trs", [](Asset& a) { a.node({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}, {"scale", {1, 1, 1}}}); },
         ErrorCode::kInvalidValue, "nodes[0]: has both matrix and translation/rotation/scale"},
        {"index out of range", [](Asset& a) { a.node({{"mesh", a.mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 3})}}); }, ErrorCode::kInvalidValue,
         "accessors[1]: index 2 = 3 is not below the vertex count 3"},
        {"accessor overrun", [](Asset& a) {
             a.node({{"mesh", a.mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {})}});
             a.doc["accessors"][0]["count"] = 6;
         }, ErrorCode::kInvalidValue, "accessors[0]: 6 elements run past the end of bufferViews[0]"},
        {"not triangles", [](Asset& a) {
             a.node({{"mesh", a.mesh({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {})}});
         }, ErrorCode::kInvalidValue, "TRIANGLES need a multiple of 3 vertices (got 4)"},
        {"unknown mode", [](Asset& a) {
             a.node({{"mesh", a.mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {})}});
             a.doc["meshes"][0]["primitives"][0]["mode"] = 7;
         }, ErrorCode::kInvalidValue, "meshes[0].primitives[0].mode: unknown primitive mode 7"},
        {"uint positions", [](Asset& a) {
             a.node({{"mesh", a.mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {})}});
             a.doc["accessors"][0]["componentType"] = 5125;
         }, ErrorCode::kUnsupported, "accessors[0].componentType: POSITION must be FLOAT, BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT"},
        {"extras probes", [](Asset& a) { a.doc["extras"]["zhc"] = {{"probes", {{"grid", {{"min", {0, 0, 0}}}}}}}; },
         ErrorCode::kInvalidValue, "test.gltf: extras.zhc: probes.grid.max: missing required field"},
        {"extras unknown", [](Asset& a) { a.doc["extras"]["zhc"] = {{"lihgts", json::array()}}; }, ErrorCode::kInvalidValue,
         "extras.zhc: lihgts: unknown field"},
        {"newline echoed", [](Asset& a) { a.node(Asset::light_node(a.light({{"type", "are\na"}}))); }, ErrorCode::kUnsupported,
         "unknown light type \"are\\x0aa\""},  // fuzzer: a JSON "\n" made the message two lines
        {"newline in extras", [](Asset& a) { a.doc["extras"]["zhc"] = {{"sky", {{"type", "const\nt"}}}}; }, ErrorCode::kUnsupported,
         "sky.type: unknown sky type \"const\\x0at\""},
        {"scene without scenes", [](Asset& a) { a.doc.erase("scenes"); }, ErrorCode::kInvalidValue, "scene: must be an index into scenes"},
    };
    for (const Case& c : cases) {
        Asset a;
        c.edit(a);
        auto s = parse(a);
        ASSERT_FALSE(s.ok()) << c.what;
        EXPECT_EQ(s.error().code, c.code) << c.what << ": " << s.error().message;
        EXPECT_NE(s.error().message.find(c.message), std::string::npos) << c.what << ": " << s.error().message;
        EXPECT_EQ(s.error().message.rfind("test.gltf: ", 0), 0u) << s.error().message;
        EXPECT_EQ(s.error().message.find('\n'), std::string::npos) << s.error().message;
    }
    // Not glTF at all, and a triangle limit.
    const std::string junk = "{\"asset\": 3}";
    EXPECT_EQ(parse_scene_gltf(std::vector<std::uint8_t>(junk.begin(), junk.end()), "junk.gltf").error().code, ErrorCode::kBadFormat);
    Asset big;
    add_quad(big);
    add_quad(big);
    SceneLoadOptions small;
    small.limits.max_triangles = 3;
    auto s = parse_scene_gltf(big.bytes(), "big.gltf", small);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kTooLarge);
    EXPECT_NE(s.error().message.find("exceed the limit of 3"), std::string::npos) << s.error().message;
}

// ---- the CLI: glTF in, glTF out ----------------------------------------------------------------

std::vector<Sh3Radiance> decode_zhp(const std::string& path) {
    auto set = read_probe_file(path);
    EXPECT_TRUE(set.ok()) << (set.ok() ? "" : set.error().message);
    if (!set.ok()) return {};
    auto hub = decode_probe_set(*set);
    return hub.ok() ? *hub : std::vector<Sh3Radiance>{};
}

TEST(SceneGltfCli, BakeGltfAndEmbedEqualsZhp) {
    const std::string dir = test::temp_dir("scene_gltf_cli");
    Asset a;
    add_quad(a);
    const size_t l = a.light({{"type", "point"}, {"intensity", 8.0}, {"color", {1.0, 0.8, 0.6}}});
    a.node(Asset::light_node(l, {{"translation", {0.5, 4.0, 0.3}}}));
    const size_t sun = a.light({{"type", "directional"}, {"intensity", 2.0}});
    a.node(Asset::light_node(sun, {{"rotation", {-0.5, 0.1, 0.0, 0.86}}}));
    a.doc["extras"]["zhc"] = {{"sky", {{"type", "gradient"}}}};
    test::write_bytes(dir + "/room.gltf", a.bytes());
    const auto zhp = test::run_zhc({"bake", dir + "/room.gltf", "-o", dir + "/room.zhp"});
    ASSERT_EQ(zhp.exit_code, 0) << zhp.err;
    EXPECT_NE(zhp.out.find("point 'gltf light 0'"), std::string::npos) << zhp.out;
    EXPECT_NE(zhp.out.find("shadowed: "), std::string::npos) << zhp.out;
    const auto ref = decode_zhp(dir + "/room.zhp");
    ASSERT_EQ(ref.size(), 512u);  // default 8 x 8 x 8 grid over the quad and the point light
    for (const char* out : {"room_lit.glb", "room_lit.gltf"}) {
        const auto r = test::run_zhc({"bake", dir + "/room.gltf", "-o", dir + "/" + out, "--threads", "2"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.out.find("a copy of the input asset"), std::string::npos) << r.out;
        auto summary = read_gltf_probes_file(dir + "/" + out);
        ASSERT_TRUE(summary.ok()) << summary.error().message;
        EXPECT_EQ(summary->meshes, 1u);  // the input asset is kept
        EXPECT_NE(std::find(summary->extensions_used.begin(), summary->extensions_used.end(), "KHR_lights_punctual"),
                  summary->extensions_used.end());
        ASSERT_EQ(summary->volumes.size(), 1u);
        auto hub = decode_probe_set(summary->volumes[0].set);
        ASSERT_TRUE(hub.ok());
        EXPECT_EQ(*hub, ref) << out;
        EXPECT_EQ(summary->volumes[0].set.layout.kind, ProbeLayoutKind::kGrid);
        // And the output is still a scene zhc bakes the same (the lights and mesh are intact).
        const auto again = test::run_zhc({"bake", dir + "/" + out, "-o", dir + "/again.zhp", "--quiet"});
        ASSERT_EQ(again.exit_code, 0) << again.err;
        EXPECT_EQ(decode_zhp(dir + "/again.zhp"), ref);
    }
    // A .gltf whose buffer is an external file next to it: read through the guarded loader, and
    // the output is self-contained (the buffer becomes part of the GLB).
    {
        json d = json::parse(a.text());
        d["buffers"][0]["uri"] = "room.bin";
        const std::string t = d.dump();
        test::write_bytes(dir + "/room_ext.gltf", std::vector<std::uint8_t>(t.begin(), t.end()));
        test::write_bytes(dir + "/room.bin", a.bin);
        const auto r = test::run_zhc({"bake", dir + "/room_ext.gltf", "-o", dir + "/room_ext.glb"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.out.find("occluders: 2 (2 mesh triangles)"), std::string::npos) << r.out;
        auto g = read_gltf_probes_file(dir + "/room_ext.glb");
        ASSERT_TRUE(g.ok()) << g.error().message;
        EXPECT_EQ(*decode_probe_set(g->volumes[0].set), ref);
        // A buffer URI leaving the directory is refused (exit 4), nothing written.
        d["buffers"][0]["uri"] = "../room.bin";
        const std::string bad = d.dump();
        test::write_bytes(dir + "/room_escape.gltf", std::vector<std::uint8_t>(bad.begin(), bad.end()));
        const auto e = test::run_zhc({"bake", dir + "/room_escape.gltf", "-o", dir + "/room_escape.glb"});
        EXPECT_EQ(e.exit_code, 4) << e.err;
        EXPECT_NE(e.err.find("'..' escapes the input's directory"), std::string::npos) << e.err;
        EXPECT_FALSE(fs::exists(dir + "/room_escape.glb"));
    }
    // A quantised representation: the embedded bytes are the .zhp payload.
    ASSERT_EQ(test::run_zhc({"bake", dir + "/room.gltf", "-o", dir + "/q.zhp", "--to", "zh3_q16", "--quiet"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"bake", dir + "/room.gltf", "-o", dir + "/q.glb", "--to", "zh3_q16", "--quiet"}).exit_code, 0);
    auto qset = read_probe_file(dir + "/q.zhp");
    auto qg = read_gltf_probes_file(dir + "/q.glb");
    ASSERT_TRUE(qset.ok() && qg.ok());
    EXPECT_EQ(qg->volumes[0].set.payload, qset->payload);
    EXPECT_EQ(qg->volumes[0].set.representation, "zh3_q16");
}

TEST(SceneGltfCli, JsonSceneToMinimalGlb) {
    const std::string dir = test::temp_dir("scene_gltf_min");
    Scene s = default_scene();
    s.probes.counts = {4, 3, 2};
    const std::string text = scene_json(s);
    test::write_bytes(dir + "/scene.json", std::vector<std::uint8_t>(text.begin(), text.end()));
    ASSERT_EQ(test::run_zhc({"bake", dir + "/scene.json", "-o", dir + "/p.zhp", "--quiet"}).exit_code, 0);
    const auto r = test::run_zhc({"bake", dir + "/scene.json", "-o", dir + "/p.glb"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("a minimal glTF"), std::string::npos);
    auto g = read_gltf_probes_file(dir + "/p.glb");
    ASSERT_TRUE(g.ok()) << g.error().message;
    ASSERT_EQ(g->volumes.size(), 1u);
    auto hub = decode_probe_set(g->volumes[0].set);
    ASSERT_TRUE(hub.ok());
    EXPECT_EQ(*hub, decode_zhp(dir + "/p.zhp"));
    EXPECT_EQ(hub->size(), 24u);
    // Errors (a glTF without asset.version, a missing input, an .obj output): tests/conformance
    // scenegltf_*, cli_usage_bake_obj.
}

}  // namespace
}  // namespace zhc

namespace zhc {
namespace {

// castle-engine/demo-models gltf/lines and gltf/points (GPL-2+, unmodified, tests/data/gltf/
// castle-demo-models): LINES / POINTS meshes and a point light. Their vertices span the default
// probe grid (8 x 8 x 8 over every vertex and the light), they occlude nothing, and the bake is
// not zero.
TEST(SceneGltf, LinesAndPointsSpanTheDefaultGrid) {
    for (const char* name : {"lines/lines.gltf", "points/points.gltf"}) {
        const std::string path = std::string(ZHC_TEST_DATA_DIR) + "/gltf/castle-demo-models/" + name;
        auto s = parse_scene_gltf(test::read_bytes(path), path);
        ASSERT_TRUE(s.ok()) << s.error().message;
        EXPECT_TRUE(s->occluders.empty()) << name;
        ASSERT_EQ(s->probes.kind, ProbePlacementKind::kGrid) << name;
        EXPECT_EQ(s->probes.counts, (std::array<std::uint32_t, 3>{8, 8, 8})) << name;
        for (int a = 0; a < 3; ++a) EXPECT_GT(s->probes.max[a] - s->probes.min[a], 0.5) << name << " axis " << a;
        const auto probes = bake(*s);
        double sum = 0;
        for (const Sh3Radiance& p : probes) sum += std::fabs(p[0][0]);
        EXPECT_GT(sum, 0) << name;
    }
}

// glTF materials: albedo = base colour x (1 - metallic), emission = emissive x strength; no
// material (the spec's default, fully metallic) and black materials reflect nothing; a lit
// reflecting floor adds light to a probe above it, and a bake with the default material is the
// same bytes as one without any material.
TEST(SceneGltf, MaterialsReflectAndEmit) {
    const std::vector<float> floor = {-5, 0, -5, 5, 0, -5, 5, 0, 5, -5, 0, 5};  // glTF y up
    const std::vector<std::uint16_t> quad = {0, 2, 1, 0, 3, 2};
    auto make = [&](json material) {
        Asset a;
        const size_t m = a.mesh(floor, quad);
        if (!material.is_null()) {
            a.doc["materials"].push_back(material);
            a.doc["meshes"][m]["primitives"][0]["material"] = 0;
        }
        a.node({{"mesh", m}});
        a.node(Asset::light_node(a.light({{"type", "point"}, {"intensity", 10.0}}), {{"translation", {0, 2, 0}}}));
        a.doc["extras"]["zhc"]["probes"] = {{"positions", {{0, 0, 1}}}};
        return a;
    };
    auto none = parse(make(nullptr));
    ASSERT_TRUE(none.ok()) << none.error().message;
    EXPECT_TRUE(none->materials.empty());
    EXPECT_FALSE(scene_has_transport(*none));
    auto metal = parse(make({{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.8, 0.8, 1}}}}}));  // metallic 1
    ASSERT_TRUE(metal.ok());
    EXPECT_TRUE(metal->materials.empty());
    auto grey = parse(make({{"name", "grey"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.4, 0.2, 1}}, {"metallicFactor", 0.25}}},
                            {"emissiveFactor", {0.5, 0, 0}},
                            {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}}));
    ASSERT_TRUE(grey.ok()) << grey.error().message;
    ASSERT_EQ(grey->materials.size(), 1u);
    EXPECT_FLOAT_EQ(grey->materials[0].albedo.r, 0.6f);
    EXPECT_FLOAT_EQ(grey->materials[0].albedo.g, 0.3f);
    EXPECT_FLOAT_EQ(grey->materials[0].albedo.b, 0.15f);
    EXPECT_FLOAT_EQ(grey->materials[0].emission.r, 2.0f);
    for (const Occluder& o : grey->occluders) EXPECT_EQ(o.material, 0u);
    EXPECT_TRUE(scene_has_transport(*grey));
    const auto p_none = bake(*none), p_metal = bake(*metal), p_grey = bake(*grey);
    ASSERT_EQ(p_none.size(), 1u);
    EXPECT_EQ(std::memcmp(p_none.data(), p_metal.data(), sizeof(Sh3Radiance)), 0);
    // The floor (below the probe, zhc -z) now reflects and emits: the downward irradiance grows.
    auto down = [](const Sh3Radiance& p) { return p[0][0] / (2 * std::sqrt(kPi)) - p[2][0] * std::sqrt(3 / (4 * kPi)) * 2 / 3; };
    EXPECT_GT(down(p_grey[0]), down(p_none[0]) + 0.5);
}

// ---- textures in the reflected light ------------------------------------------------------

std::string png_uri(const std::vector<std::uint8_t>& rgb, int w, int h) {
    return "data:image/png;base64," + base64(png_bytes_rgb8(rgb.data(), rgb.size(), w, h));
}

// A glTF floor (y = 0, x and z in [x0, x1] x [-5, 5]) with TEXCOORD_0 u = (x + 5) / 10,
// v = (z + 5) / 10; returns the mesh index.
size_t uv_floor(Asset& a, float x0, float x1, bool uvs) {
    const std::vector<float> xyz = {x0, 0, -5, x1, 0, -5, x1, 0, 5, x0, 0, 5};
    const size_t m = a.mesh(xyz, {0, 2, 1, 0, 3, 2});
    if (uvs) {
        std::vector<float> uv;
        for (size_t i = 0; i < 4; ++i) {
            uv.push_back((xyz[i * 3] + 5) / 10);
            uv.push_back((xyz[i * 3 + 2] + 5) / 10);
        }
        const size_t v = a.view(uv.data(), uv.size() * 4);
        a.doc["accessors"].push_back({{"bufferView", v}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}});
        a.doc["meshes"][m]["primitives"][0]["attributes"]["TEXCOORD_0"] = a.doc["accessors"].size() - 1;
    }
    return m;
}
// The floor with a base colour texture from `image` (an images[] entry), a NEAREST sampler, a
// point light 2 above it (when `lit`) and three probes.
Asset textured_floor(json image, bool lit = true) {
    Asset a;
    const size_t m = uv_floor(a, -5, 5, true);
    a.doc["images"] = json::array({image});
    a.doc["samplers"] = json::array({{{"magFilter", 9728}}});
    a.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
    a.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.8, 0.8, 1}}, {"metallicFactor", 0}, {"baseColorTexture", {{"index", 0}}}}}}});
    a.doc["meshes"][m]["primitives"][0]["material"] = 0;
    a.node({{"mesh", m}});
    if (lit) a.node(Asset::light_node(a.light({{"type", "point"}, {"intensity", 10.0}}), {{"translation", {0, 2, 0}}}));
    a.doc["extras"]["zhc"]["probes"] = {{"positions", {{0, -2, 1}, {0, 2, 1}, {1, 0.5, 0.5}}}};
    return a;
}
const std::vector<std::uint8_t> kBlackWhite = {0, 0, 0, 255, 255, 255};  // 2 x 1: u < 0.5 black

// A floor whose base colour texture is black over u < 0.5 and white over u > 0.5 (a PNG in a data
// URI, sRGB-decoded: 0 and 1 exactly) bakes as the same floor split into a black and a white
// material (within rounding: the triangles differ, the surfaces do not).
TEST(SceneGltf, TexturedFloorEqualsTwoMaterials) {
    auto tex = parse(textured_floor({{"uri", png_uri(kBlackWhite, 2, 1)}}));
    ASSERT_TRUE(tex.ok()) << tex.error().message;
    ASSERT_EQ(tex->textures.size(), 1u);
    EXPECT_EQ(tex->textures[0].width, 2u);
    EXPECT_TRUE(tex->textures[0].nearest);
    EXPECT_EQ(tex->textures[0].texels, (std::vector<float>{0, 0, 0, 1, 1, 1}));
    ASSERT_EQ(tex->surfaces.size(), 2u);
    for (const Occluder& o : tex->occluders) EXPECT_TRUE(is_surface(o.material));
    ASSERT_EQ(tex->materials.size(), 1u);
    EXPECT_EQ(tex->materials[0].base_texture, 0);
    Asset twin;
    const size_t black = uv_floor(twin, -5, 0, false), white = uv_floor(twin, 0, 5, false);
    twin.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}}}},
                                         {{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.8, 0.8, 1}}, {"metallicFactor", 0}}}}});
    twin.doc["meshes"][black]["primitives"][0]["material"] = 0;
    twin.doc["meshes"][white]["primitives"][0]["material"] = 1;
    twin.node({{"mesh", black}});
    twin.node({{"mesh", white}});
    twin.node(Asset::light_node(twin.light({{"type", "point"}, {"intensity", 10.0}}), {{"translation", {0, 2, 0}}}));
    twin.doc["extras"]["zhc"]["probes"] = {{"positions", {{0, -2, 1}, {0, 2, 1}, {1, 0.5, 0.5}}}};
    auto two = parse(twin);
    ASSERT_TRUE(two.ok()) << two.error().message;
    EXPECT_TRUE(two->textures.empty());
    const auto pt = bake(*tex), p2 = bake(*two);
    ASSERT_EQ(pt.size(), 3u);
    ASSERT_EQ(p2.size(), 3u);
    for (size_t i = 0; i < 3; ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(pt[i][c][k], p2[i][c][k], 1e-5 * (1 + std::fabs(p2[i][0][k]))) << i << " " << c;
    // The probe over the black half (glTF x < 0: zhc y < 0) sees less light below it than the other.
    EXPECT_LT(pt[0][0][0], pt[1][0][0] * 0.9);
    // Written as a zhc JSON scene: one mesh with the material's factors (JSON holds no textures).
    const json back = json::parse(scene_json(*tex));
    ASSERT_EQ(back["occluders"].size(), 1u);
    EXPECT_EQ(back["occluders"][0]["positions"].size(), 18u);
    EXPECT_NEAR(back["occluders"][0]["albedo"][0].get<double>(), 0.8, 1e-6);
}

// sRGB decoding for base colour and emissive (glTF 2.0 spec 3.9.2), linear for metallic-roughness:
// one image used both ways is two textures; the blue channel of metallic-roughness scales metallic.
TEST(SceneGltf, TextureColourSpaces) {
    Asset a = textured_floor({{"uri", png_uri({128, 64, 255}, 1, 1)}});
    json& mat = a.doc["materials"][0];
    mat["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", 0}};
    mat["pbrMetallicRoughness"]["metallicFactor"] = 1.0;
    mat["emissiveTexture"] = {{"index", 0}};
    mat["emissiveFactor"] = {1, 1, 1};
    auto s = parse(a);
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_EQ(s->textures.size(), 2u);
    const SceneMaterial& m = s->materials[0];
    ASSERT_GE(m.base_texture, 0);
    ASSERT_GE(m.metal_rough_texture, 0);
    EXPECT_EQ(m.emissive_texture, m.base_texture);
    EXPECT_NE(m.metal_rough_texture, m.base_texture);
    auto srgb = [](double c8) { const double c = c8 / 255; return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
    const auto& lin = s->textures[static_cast<size_t>(m.metal_rough_texture)].texels;
    const auto& col = s->textures[static_cast<size_t>(m.base_texture)].texels;
    EXPECT_NEAR(col[0], 0.21586, 1e-5);  // sRGB 128
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(col[static_cast<size_t>(k)], srgb(k == 0 ? 128 : k == 1 ? 64 : 255), 1e-7);
        EXPECT_NEAR(lin[static_cast<size_t>(k)], (k == 0 ? 128 : k == 1 ? 64 : 255) / 255.0, 1e-7);
    }
    // Metallic 1 x blue 1: no diffuse part anywhere; the floor only emits.
    double albedo_seen = 0;
    SceneTexture mr = s->textures[static_cast<size_t>(m.metal_rough_texture)];
    double rgb[3];
    sample_texture(mr, 0.3, 0.7, rgb);
    albedo_seen = m.base_factor[0] * (1 - m.metallic * rgb[2]);
    EXPECT_EQ(albedo_seen, 0.0);
    EXPECT_TRUE(scene_has_transport(*s));
}

// KHR_texture_transform: u' = T R S u (offset, rotation, scale), per texture.
TEST(SceneGltf, TextureTransform) {
    Asset a = textured_floor({{"uri", png_uri(kBlackWhite, 2, 1)}});
    a.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] = {
        {"offset", {0.1, 0.2}}, {"rotation", kPi / 2}, {"scale", {2, 3}}};
    auto s = parse(a);
    ASSERT_TRUE(s.ok()) << s.error().message;
    const auto& t = s->materials[0].base_uv;
    const float want[6] = {0, 3, 0.1f, -2, 0, 0.2f};
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(t[static_cast<size_t>(i)], want[i], 1e-6) << i;
    EXPECT_EQ(s->materials[0].emissive_uv, SceneMaterial::kIdentityUv);
    a.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["scale"] = {1e300, 1};
    auto bad = parse(a);
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().message.find("KHR_texture_transform"), std::string::npos) << bad.error().message;
}

// A fully metallic factor with a metallic-roughness texture whose blue channel is 0 reflects its
// base colour: the texture is decoded (the decision to trace counts it) and the floor bakes as a
// diffuse one of that colour.
TEST(SceneGltf, MetallicRoughnessTextureMakesMetalDiffuse) {
    Asset a = textured_floor({{"uri", png_uri({0, 0, 0}, 1, 1)}});
    json& pbr = a.doc["materials"][0]["pbrMetallicRoughness"];
    pbr.erase("baseColorTexture");
    pbr["metallicRoughnessTexture"] = {{"index", 0}};
    pbr["metallicFactor"] = 1.0;
    auto s = parse(a);
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_EQ(s->textures.size(), 1u);
    EXPECT_FALSE(s->surfaces.empty());
    EXPECT_TRUE(scene_has_transport(*s));
    Asset d = textured_floor({{"uri", png_uri({0, 0, 0}, 1, 1)}});
    d.doc["materials"][0]["pbrMetallicRoughness"].erase("baseColorTexture");
    auto plain = parse(d);
    ASSERT_TRUE(plain.ok()) << plain.error().message;
    EXPECT_TRUE(plain->textures.empty());
    const auto p1 = bake(*s), p2 = bake(*plain);
    ASSERT_EQ(p1.size(), p2.size());
    for (size_t i = 0; i < p1.size(); ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(p1[i][c][k], p2[i][c][k], 1e-6 * (1 + std::fabs(p2[i][0][k])));
}

// Images are read only for a bake that traces reflected light: an image URI escaping the asset's
// folder, or a missing image, is no error for a scene with nothing to reflect, and a one-line
// error naming the image where the textures are decoded; an image beside the asset is read and
// recorded as an input (--depfile).
TEST(SceneGltf, ImagesReadOnlyForReflectedLight) {
    const std::string root = test::fresh_dir("scene_gltf_texture_uris");
    fs::create_directories(root + "/asset");
    test::write_bytes(root + "/tex.png", png_bytes_rgb8(kBlackWhite.data(), kBlackWhite.size(), 2, 1));
    test::write_bytes(root + "/asset/beside.png", png_bytes_rgb8(kBlackWhite.data(), kBlackWhite.size(), 2, 1));
    struct Case {
        const char* uri;
        ErrorCode code;
    };
    for (const Case& c : {Case{"../tex.png", ErrorCode::kBadFormat}, Case{"missing.png", ErrorCode::kIoError}}) {
        const std::string in = root + "/asset/scene.gltf";
        for (bool lit : {false, true}) {
            const std::string text = textured_floor({{"uri", c.uri}}, lit).text();
            test::write_bytes(in, std::vector<std::uint8_t>(text.begin(), text.end()));
            auto bytes = read_file_bytes(in, std::uint64_t(1) << 30);
            ASSERT_TRUE(bytes.ok());
            auto s = parse_scene_gltf(*bytes, in);
            if (!lit) {
                ASSERT_TRUE(s.ok()) << c.uri << ": " << s.error().message;
                EXPECT_TRUE(s->surfaces.empty());
                EXPECT_TRUE(s->textures.empty());
                for (const Occluder& o : s->occluders) EXPECT_EQ(o.material, 0u);
                continue;
            }
            ASSERT_FALSE(s.ok()) << c.uri;
            EXPECT_EQ(s.error().code, c.code) << s.error().message;
            EXPECT_NE(s.error().message.find("images[0].uri"), std::string::npos) << s.error().message;
            EXPECT_EQ(s.error().message.find('\n'), std::string::npos) << s.error().message;
        }
    }
    const std::string in = root + "/asset/scene.gltf";
    const std::string text = textured_floor({{"uri", "beside.png"}}).text();
    test::write_bytes(in, std::vector<std::uint8_t>(text.begin(), text.end()));
    FileRecorder rec;
    {
        ScopedFileRecording on(&rec);
        auto bytes = read_file_bytes(in, std::uint64_t(1) << 30);
        ASSERT_TRUE(bytes.ok());
        auto s = parse_scene_gltf(*bytes, in);
        ASSERT_TRUE(s.ok()) << s.error().message;
        ASSERT_EQ(s->textures.size(), 1u);
        EXPECT_EQ(s->textures[0].texels[3], 1.0f);
    }
    const auto inputs = rec.inputs();
    EXPECT_NE(std::find(inputs.begin(), inputs.end(), root + "/asset/beside.png"), inputs.end()) << inputs.size();
    // `zhc bake --depfile` lists the image when the bake decodes it, and not otherwise.
    for (bool lit : {true, false}) {
        const std::string t = textured_floor({{"uri", "beside.png"}}, lit).text();
        test::write_bytes(in, std::vector<std::uint8_t>(t.begin(), t.end()));
        const auto b = test::run_zhc({"bake", in, "-o", root + "/dep.zhp", "--depfile", root + "/dep.d", "--quiet"});
        ASSERT_EQ(b.exit_code, 0) << b.err;
        const auto dep = test::read_bytes(root + "/dep.d");
        const std::string d(dep.begin(), dep.end());
        EXPECT_EQ(d.find("beside.png") != std::string::npos, lit) << d;
        if (!lit) continue;
        // --bounces 0 traces no reflected light: the image is not decoded either.
        const auto z = test::run_zhc({"bake", in, "-o", root + "/dep0.zhp", "--depfile", root + "/dep0.d", "--quiet", "--bounces", "0"});
        ASSERT_EQ(z.exit_code, 0) << z.err;
        const auto dep0 = test::read_bytes(root + "/dep0.d");
        EXPECT_EQ(std::string(dep0.begin(), dep0.end()).find("beside.png"), std::string::npos);
    }
    // The command line: exit 4 for the escaping image, one line.
    const std::string esc = textured_floor({{"uri", "../tex.png"}}).text();
    test::write_bytes(in, std::vector<std::uint8_t>(esc.begin(), esc.end()));
    const auto r = test::run_zhc({"bake", in, "-o", root + "/out.zhp", "--quiet"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(root + "/out.zhp"));
}

// KHR_mesh_quantization texture coordinates: normalized UNSIGNED_SHORT (c / 65535), BYTE
// (max(c / 127, -1)) and unnormalized UNSIGNED_BYTE (c) read as the spec says.
TEST(SceneGltf, QuantizedTexcoords) {
    struct Case {
        int component;
        bool normalized;
        std::vector<std::uint8_t> raw;  // 4 UVs
        std::vector<float> want;
    };
    const std::vector<Case> cases = {
        {5123, true, {0, 0, 0, 0, 0xFF, 0xFF, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0xFF, 0x7F}, {0, 0, 1, 0, 1, 1, 0, 32767 / 65535.f}},
        {5120, true, {0, 0, 127, 0x81, 0x80, 0, 64, 0}, {0, 0, 1, -1, -1, 0, 64 / 127.f, 0}},
        {5121, false, {0, 0, 2, 0, 2, 3, 0, 3}, {0, 0, 2, 0, 2, 3, 0, 3}},
    };
    for (const Case& c : cases) {
        Asset a = textured_floor({{"uri", png_uri(kBlackWhite, 2, 1)}});
        const size_t v = a.view(c.raw.data(), c.raw.size());
        a.doc["accessors"].push_back({{"bufferView", v}, {"componentType", c.component}, {"normalized", c.normalized}, {"count", 4}, {"type", "VEC2"}});
        a.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = a.doc["accessors"].size() - 1;
        auto s = parse(a);
        ASSERT_TRUE(s.ok()) << s.error().message;
        ASSERT_EQ(s->surfaces.size(), 2u);
        // Triangle 0 is vertices (0, 2, 1) of the quad.
        const int order[3] = {0, 2, 1};
        for (int k = 0; k < 3; ++k) {
            EXPECT_FLOAT_EQ(s->surfaces[0].uv[k][0], c.want[static_cast<size_t>(order[k] * 2)]) << c.component;
            EXPECT_FLOAT_EQ(s->surfaces[0].uv[k][1], c.want[static_cast<size_t>(order[k] * 2 + 1)]) << c.component;
        }
    }
}

// The texel limit (SceneJsonLimits::max_texels) is checked from the image's header before decoding.
TEST(SceneGltf, TexelLimit) {
    const Asset a = textured_floor({{"uri", png_uri(kBlackWhite, 2, 1)}});
    SceneLoadOptions o;
    o.limits.max_texels = 1;
    auto s = parse_scene_gltf(a.bytes(), "big.gltf", o);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kTooLarge);
    EXPECT_NE(s.error().message.find("images[0]"), std::string::npos) << s.error().message;
    EXPECT_NE(s.error().message.find("limit of 1 texels"), std::string::npos) << s.error().message;
    o.limits.max_texels = 2;
    EXPECT_TRUE(parse_scene_gltf(a.bytes(), "big.gltf", o).ok());
}

// GLB edits: the JSON chunk replaced, the BIN chunk kept.
std::vector<std::uint8_t> edit_glb(const std::string& file, const std::function<void(json&)>& edit) {
    std::vector<std::uint8_t> b = test::read_bytes(file);
    const std::uint32_t jlen = test::get32(b, 12);
    json j = json::parse(b.begin() + 20, b.begin() + 20 + jlen);
    const std::vector<std::uint8_t> rest(b.begin() + 20 + jlen, b.end());
    edit(j);
    std::string t = j.dump();
    while (t.size() % 4) t.push_back(' ');
    std::vector<std::uint8_t> out(20);
    out.insert(out.end(), t.begin(), t.end());
    out.insert(out.end(), rest.begin(), rest.end());
    std::memcpy(out.data(), "glTF", 4);
    test::put32(out, 4, 2);
    test::put32(out, 8, static_cast<std::uint32_t>(out.size()));
    test::put32(out, 12, static_cast<std::uint32_t>(t.size()));
    std::memcpy(out.data() + 16, "JSON", 4);
    return out;
}
json textured_material(json& j) {
    j["images"] = json::array({{{"uri", png_uri(kBlackWhite, 2, 1)}}});
    j["textures"] = json::array({{{"source", 0}}});
    j["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}, {"metallicFactor", 0}, {"baseColorTexture", {{"index", 0}}}}}}});
    return j;
}

// A meshopt-compressed TEXCOORD_0 (gp_meshopt.glb, gltf-pipeline's meshopt encoding: a VEC2
// accessor over the compressed POSITION view, so each UV is its vertex's glTF (x, y)) is decoded;
// a Draco-compressed textured primitive (gt_draco.glb) keeps its factors, with a note.
TEST(SceneGltf, CompressedTexturedPrimitives) {
    const std::string dir = std::string(ZHC_TEST_DATA_DIR) + "/gltf/";
    const auto mo = edit_glb(dir + "gp_meshopt.glb", [](json& j) {
        textured_material(j);
        j["accessors"].push_back({{"bufferView", 0}, {"byteOffset", 0}, {"componentType", 5126}, {"count", 16}, {"type", "VEC2"}});
        j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = j["accessors"].size() - 1;
        j["meshes"][0]["primitives"][0]["material"] = 0;
    });
    auto s = parse_scene_gltf(mo, "meshopt_textured.glb");
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_FALSE(s->surfaces.empty());
    ASSERT_EQ(s->textures.size(), 1u);
    size_t textured = 0;
    for (const Occluder& o : s->occluders) {
        if (!is_surface(o.material)) continue;
        ++textured;
        const SurfaceUv& uv = s->surfaces[o.material & ~kSurfaceBit];
        const Vec3 v[3] = {o.v0, o.v1, o.v2};
        for (int k = 0; k < 3; ++k) {  // zhc (x, y, z) = glTF (z, x, y)
            EXPECT_FLOAT_EQ(uv.uv[k][0], float(v[k].y));
            EXPECT_FLOAT_EQ(uv.uv[k][1], float(v[k].z));
        }
    }
    EXPECT_EQ(textured, 16u);  // 48 indices
    EXPECT_FALSE(bake(*s).empty());
    std::vector<std::string> notes;
    const auto dr = edit_glb(dir + "gt_draco.glb", [](json& j) {
        textured_material(j);
        j["meshes"][0]["primitives"][0]["material"] = 0;
    });
    auto d = parse_scene_gltf(dr, "draco_textured.glb", {}, {}, &notes);
    ASSERT_TRUE(d.ok()) << d.error().message;
    EXPECT_TRUE(d->surfaces.empty());
    ASSERT_EQ(d->materials.size(), 1u);
    EXPECT_FLOAT_EQ(d->materials[0].albedo.r, 0.5f);
    bool noted = false;
    for (const std::string& n : notes) noted = noted || n.find("its Draco stream has no TEXCOORD_0") != std::string::npos;
    EXPECT_TRUE(noted);
}

// loaders.gl's tile.glb (Vricon photogrammetry: two Draco primitives with TEXCOORD_0 in the Draco
// streams, JPEG textures in buffer views), made diffuse (metallic 0) and lit by a sun: the Draco UVs
// are read (within the bounds the uncompressed accessors declare), both JPEGs decode, every
// triangle is textured, and the photo texture reflects less than the same tile untextured (white).
TEST(SceneGltf, DracoTexturedTerrainTile) {
    const std::string file = std::string(ZHC_TEST_DATA_DIR) + "/gltf/loaders.gl/tile.glb";
    json declared;
    const auto glb = edit_glb(file, [&](json& j) {
        for (json& m : j["materials"]) m["pbrMetallicRoughness"]["metallicFactor"] = 0.0;
        json& z = j["extras"]["zhc"];
        z["probes"]["grid"] = {{"min", {-200, -200, -100}}, {"max", {200, 200, 250}}, {"counts", {3, 3, 3}}};
        z["lights"] = json::array({{{"type", "directional"}, {"direction", {0.3, 0.2, 1}}, {"irradiance", 1.0}}});
        z["transport"] = {{"min_rays", 256}, {"max_rays", 512}};
        declared = j["accessors"];
    });
    std::vector<std::string> notes;
    auto s = parse_scene_gltf(glb, "tile.glb", {}, {}, &notes);
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_EQ(s->textures.size(), 2u);
    for (const SceneTexture& t : s->textures) {
        EXPECT_GT(t.width, 64u);
        EXPECT_GT(t.height, 64u);
    }
    EXPECT_EQ(s->occluders.size(), 19635u / 3 + 8682u / 3);
    EXPECT_EQ(s->surfaces.size(), s->occluders.size());
    float lo[2] = {1e9f, 1e9f}, hi[2] = {-1e9f, -1e9f};
    for (const SurfaceUv& u : s->surfaces)
        for (const auto& c : u.uv)
            for (int k = 0; k < 2; ++k) {
                lo[k] = std::min(lo[k], c[k]);
                hi[k] = std::max(hi[k], c[k]);
            }
    for (int k = 0; k < 2; ++k) {  // accessors 2 and 5 are the TEXCOORD_0 accessors
        const double dlo = std::min(declared[2]["min"][k].get<double>(), declared[5]["min"][k].get<double>());
        const double dhi = std::max(declared[2]["max"][k].get<double>(), declared[5]["max"][k].get<double>());
        EXPECT_NEAR(lo[k], dlo, 1e-3) << k;
        EXPECT_NEAR(hi[k], dhi, 1e-3) << k;
    }
    for (const std::string& n : notes) EXPECT_EQ(n.find("TEXCOORD"), std::string::npos) << n;
    BakeReport rt, rw;
    auto textured = bake_scene(*s, {}, &rt);
    ASSERT_TRUE(textured.ok()) << textured.error().message;
    Scene white = *s;
    for (SceneMaterial& m : white.materials) m.base_texture = -1;
    auto plain = bake_scene(white, {}, &rw);
    ASSERT_TRUE(plain.ok());
    EXPECT_TRUE(rt.transport.traced);
    double sum_t = 0, sum_w = 0;
    for (size_t i = 0; i < textured->size(); ++i) {
        sum_t += (*textured)[i][0][1];
        sum_w += (*plain)[i][0][1];
    }
    std::printf("tile.glb: L00 green summed over %zu probes: textured %.4f, white %.4f; reflected light %.1f ms\n", textured->size(), sum_t, sum_w,
                rt.transport.milliseconds);
    EXPECT_LT(sum_t, sum_w - 0.01 * std::fabs(sum_w));
}

// gltf-pipeline's box-textured-embedded (COLLADA2GLTF: a unit box, PNG in a bufferView, UVs up to
// 6 with REPEAT) and box-textured-separate (the same PNG as "cesium logo.png" beside the asset, a
// percent-encoded URI) under a point light: the texture is decoded (128 x 128), every triangle is
// textured, both files bake the same probes, and the box's lit face reflects less light than a
// white box's would.
TEST(SceneGltf, GltfPipelineTexturedBox) {
    const std::string dir = std::string(ZHC_TEST_DATA_DIR) + "/gltf/gltf-pipeline/";
    auto with_light = [](json& j) {
        j["extensionsUsed"].push_back("KHR_lights_punctual");
        j["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 20.0}}});
        j["nodes"].push_back({{"translation", {0, 0, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
        j["scenes"][0]["nodes"].push_back(j["nodes"].size() - 1);
        // zhc axes: the box spans [-0.5, 0.5]^3; the light and probes sit outside it.
        j["nodes"].back()["translation"] = {0, 0, 2.0};  // glTF z = zhc x
        j["extras"]["zhc"]["probes"] = {{"positions", {{1.0, 0.2, 0.1}, {0.8, -0.3, 0.6}}}};
    };
    std::vector<Sh3Radiance> probes[2];
    int i = 0;
    for (const char* name : {"box-textured-embedded/box-textured-embedded.gltf", "box-textured-separate/box-textured-separate.gltf"}) {
        json j = json::parse(test::read_bytes(dir + name));
        with_light(j);
        const std::string path = test::fresh_dir(std::string("pipeline_box_") + std::to_string(i)) + "/box.gltf";
        if (i == 1)
            for (const char* f : {"box-textured-separate.bin", "cesium logo.png"})
                fs::copy_file(dir + "box-textured-separate/" + f, fs::path(path).parent_path() / f);
        const std::string t = j.dump();
        test::write_bytes(path, std::vector<std::uint8_t>(t.begin(), t.end()));
        auto s = parse_scene_gltf(std::vector<std::uint8_t>(t.begin(), t.end()), path);
        ASSERT_TRUE(s.ok()) << name << ": " << s.error().message;
        ASSERT_EQ(s->textures.size(), 1u) << name;
        EXPECT_EQ(s->textures[0].width, 128u);
        EXPECT_EQ(s->textures[0].height, 128u);
        EXPECT_EQ(s->surfaces.size(), 12u);
        for (const Occluder& o : s->occluders) EXPECT_TRUE(is_surface(o.material));
        probes[i] = bake(*s);
        // The same box untextured (white factor): it reflects more.
        if (i == 0) {
            Scene w = *s;
            for (Occluder& o : w.occluders) o.material = w.surfaces[o.material & ~kSurfaceBit].material;
            w.materials[0].base_texture = -1;
            const auto pw = bake(w);
            EXPECT_LT(probes[0][0][0][1], pw[0][0][1] - 0.01) << "textured " << probes[0][0][0][1] << " white " << pw[0][0][1];
        }
        ++i;
    }
    ASSERT_EQ(probes[0].size(), 2u);
    for (size_t p = 0; p < 2; ++p) EXPECT_EQ(probes[0][p], probes[1][p]) << p;
}

}  // namespace
}  // namespace zhc
