// glTF scene extensions and files other tools wrote, round 2: EXT_mesh_gpu_instancing (files written
// by glTF-Transform and gltfpack, tests/js/make_instancing_corpus.mjs, and hand-written ones),
// EXT_lights_image_based (coefficients from a known radiance, the factor between its irradiance SH
// and zhc's radiance SH derived by quadrature), external .bin files longer or shorter than their
// buffer's byteLength, and glTF fields of the wrong JSON type met while embedding probes.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "codec/bake/scene.h"
#include "formats/io/file_io.h"
#include "formats/probes/probe_file.h"
#include "formats/scene/scene_gltf.h"
#include "formats/report/html_report.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string data(const std::string& name) { return std::string(ZHC_TEST_DATA_DIR) + "/gltf/" + name; }

// gt_list.gltf (+ gt_list.bin, tex.png), written by glTF-Transform, copied into `dir`.
void copy_gt_list(const std::string& dir) {
    for (const char* f : {"gt_list.gltf", "gt_list.bin", "tex.png"})
        fs::copy_file(data(f), dir + "/" + f, fs::copy_options::overwrite_existing);
}

std::string base64(const std::vector<std::uint8_t>& b) { return base64_encode(b); }  // formats/report/html_report.h

// A glTF asset written by hand: one data-URI buffer, accessors appended as needed.
struct Asset {
    json doc = {{"asset", {{"version", "2.0"}, {"generator", "zhc test_scene_gltf_ext"}}},
                {"scene", 0},
                {"scenes", json::array({json{{"nodes", json::array()}}})},
                {"nodes", json::array()}};
    std::vector<std::uint8_t> bin;

    size_t accessor(const void* bytes, size_t size, int component, const char* type, size_t count, bool normalized = false) {
        while (bin.size() % 4) bin.push_back(0);
        const size_t off = bin.size();
        bin.insert(bin.end(), static_cast<const std::uint8_t*>(bytes), static_cast<const std::uint8_t*>(bytes) + size);
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", size}});
        json a = {{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", component}, {"count", count}, {"type", type}};
        if (normalized) a["normalized"] = true;
        doc["accessors"].push_back(a);
        return doc["accessors"].size() - 1;
    }
    size_t floats(const std::vector<float>& v, const char* type, size_t per) {
        return accessor(v.data(), v.size() * 4, 5126, type, v.size() / per);
    }
    size_t mesh(const std::vector<float>& xyz, const std::vector<std::uint16_t>& idx) {
        json prim = {{"attributes", {{"POSITION", floats(xyz, "VEC3", 3)}}}};
        prim["indices"] = accessor(idx.data(), idx.size() * 2, 5123, "SCALAR", idx.size());
        doc["meshes"].push_back({{"primitives", json::array({prim})}});
        return doc["meshes"].size() - 1;
    }
    size_t node(json n, bool root = true) {
        doc["nodes"].push_back(std::move(n));
        const size_t i = doc["nodes"].size() - 1;
        if (root) doc["scenes"][0]["nodes"].push_back(i);
        return i;
    }
    std::vector<std::uint8_t> bytes() const {
        json d = doc;
        if (!bin.empty()) d["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
        const std::string t = d.dump(1);
        return {t.begin(), t.end()};
    }
    std::string write(const std::string& dir, const std::string& name) const {
        const std::string p = dir + "/" + name;
        test::write_bytes(p, bytes());
        return p;
    }
};

Result<Scene> parse(const Asset& a, const SceneLoadOptions& options = {}, std::vector<std::string>* notes = nullptr) {
    return parse_scene_gltf(a.bytes(), "hand.gltf", options, GltfLimits{}, notes);
}

Scene scene_of(const std::string& file) {
    auto bytes = read_file_bytes(file, GltfLimits{}.max_file_bytes);
    EXPECT_TRUE(bytes.ok()) << file;
    if (!bytes.ok()) return Scene{};
    auto s = parse_scene_gltf(*bytes, file);
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return s.ok() ? std::move(s).value() : Scene{};
}

std::vector<Sh3Radiance> bake(const Scene& s) {
    auto r = bake_scene(s);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? *r : std::vector<Sh3Radiance>{};
}

// zhc bake FILE -o DIR/TAG.json through the CLI, the probe list read back.
ProbeList bake_cli(const std::string& file, const std::string& tag, const std::vector<std::string>& extra = {}) {
    const std::string out = test::temp_dir("gltf_ext") + "/" + tag + ".json";
    std::vector<std::string> args = {"bake", file, "-o", out, "--threads", "2", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = test::run_zhc(args);
    EXPECT_EQ(r.exit_code, 0) << file << ": " << r.err;
    auto list = read_probe_json(out);
    EXPECT_TRUE(list.ok()) << (list.ok() ? "" : list.error().message);
    return list.ok() ? std::move(list).value() : ProbeList{};
}

double max_diff(const std::vector<Sh3Radiance>& a, const std::vector<Sh3Radiance>& b) {
    EXPECT_EQ(a.size(), b.size());
    double m = a.size() == b.size() ? 0 : INFINITY;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) m = std::max(m, test::max_abs_diff(a[i], b[i]));
    return m;
}
double max_coefficient(const std::vector<Sh3Radiance>& a) {
    double m = 0;
    for (const auto& p : a) m = std::max(m, test::max_abs(p));
    return m;
}
size_t triangle_count(const Scene& s) {
    return static_cast<size_t>(std::count_if(s.occluders.begin(), s.occluders.end(), [](const Occluder& o) { return o.kind == OccluderKind::kTriangle; }));
}

// The JSON chunk of a GLB.
json glb_json(const std::string& path) {
    const auto b = test::read_bytes(path);
    const std::uint32_t n = test::get32(b, 12);
    return json::parse(b.begin() + 20, b.begin() + 20 + n);
}

// A GLB with its JSON chunk replaced by `doc` (padded with spaces), the BIN chunk kept.
std::vector<std::uint8_t> glb_with_json(const std::string& path, const json& doc) {
    const auto b = test::read_bytes(path);
    const std::uint32_t n = test::get32(b, 12);
    std::string text = doc.dump();
    while (text.size() % 4) text.push_back(' ');
    const size_t rest = b.size() - 20 - n;
    std::vector<std::uint8_t> out(20 + text.size() + rest);
    std::memcpy(out.data(), b.data(), 20);
    std::memcpy(out.data() + 20, text.data(), text.size());
    if (rest > 0) std::memcpy(out.data() + 20 + text.size(), b.data() + 20 + n, rest);
    test::put32(out, 8, static_cast<std::uint32_t>(out.size()));
    test::put32(out, 12, static_cast<std::uint32_t>(text.size()));
    return out;
}

// ---- EXT_mesh_gpu_instancing -----------------------------------------------------------------

// The corpus scene: 125 boxes of 12 triangles under a rotated, translated parent.
constexpr size_t kBoxes = 125, kBoxTriangles = 12;

TEST(GltfInstancing, GlTransformFloatInstancesBakeExactlyTheSceneOfPlainNodes) {
    const Scene nodes = scene_of(data("gi_nodes.glb")), inst = scene_of(data("gi_float.glb"));
    EXPECT_EQ(triangle_count(nodes), kBoxes * kBoxTriangles);
    EXPECT_EQ(triangle_count(inst), kBoxes * kBoxTriangles);  // was 12: one box
    // The same world-space triangles in the same order (node world x instance T R S).
    ASSERT_EQ(nodes.occluders.size(), inst.occluders.size());
    double worst = 0;
    for (size_t i = 0; i < nodes.occluders.size(); ++i)
        for (auto v : {&Occluder::v0, &Occluder::v1, &Occluder::v2}) worst = std::max(worst, length(nodes.occluders[i].*v - inst.occluders[i].*v));
    EXPECT_EQ(worst, 0.0);
    // The same default grid (over every instance) and bit-identical probes through the CLI.
    const ProbeList a = bake_cli(data("gi_nodes.glb"), "gi_nodes"), b = bake_cli(data("gi_float.glb"), "gi_float");
    ASSERT_EQ(a.layout.kind, ProbeLayoutKind::kGrid);
    ASSERT_EQ(b.layout.kind, ProbeLayoutKind::kGrid);
    EXPECT_EQ(a.layout.grid.counts, b.layout.grid.counts);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(a.layout.grid.origin[k], b.layout.grid.origin[k]);
        EXPECT_EQ(a.layout.grid.spacing[k], b.layout.grid.spacing[k]);
    }
    // One box spans about 1.5; the 125 span more than 10 along every axis.
    for (int k = 0; k < 3; ++k) EXPECT_GT(a.layout.grid.spacing[k] * (a.layout.grid.counts[static_cast<size_t>(k)] - 1), 9.0) << k;
    EXPECT_EQ(max_diff(a.probes, b.probes), 0.0);
    EXPECT_GT(max_coefficient(a.probes), 1.0);  // lit: the comparison means something
}

// Normalized SHORT and BYTE rotations: every vertex within what the quantisation step allows.
// A quaternion component off by at most step / 2 turns a vector of length r by at most about
// 2 |dq| r with |dq| <= 2 * step / 2 (four components); boxes reach r <= 2.5 from their origin.
TEST(GltfInstancing, NormalizedShortAndByteRotationsPlaceEveryInstance) {
    const Scene nodes = scene_of(data("gi_nodes.glb"));
    for (const auto& [file, step] : {std::pair<const char*, double>{"gi_rot_short.glb", 1 / 32767.0}, {"gi_rot_byte.glb", 1 / 127.0}}) {
        const Scene q = scene_of(data(file));
        ASSERT_EQ(q.occluders.size(), nodes.occluders.size()) << file;
        double worst = 0;
        for (size_t i = 0; i < q.occluders.size(); ++i)
            for (auto v : {&Occluder::v0, &Occluder::v1, &Occluder::v2}) worst = std::max(worst, length(nodes.occluders[i].*v - q.occluders[i].*v));
        const double bound = 2 * (2 * step / 2) * 2.5 * 1.1;  // 10 % for the normalisation's rounding
        EXPECT_LE(worst, bound) << file;
        EXPECT_GT(worst, 0.0) << file << ": quantised rotations cannot be exact";
        std::printf("[ measured ] %s: largest vertex offset %.3g (bound %.3g)\n", file, worst, bound);
    }
    // Through the CLI the SHORT file bakes within 1e-4 of the probes' scale.
    const ProbeList a = bake_cli(data("gi_nodes.glb"), "gi_nodes_s"), b = bake_cli(data("gi_rot_short.glb"), "gi_rot_short");
    EXPECT_LE(max_diff(a.probes, b.probes), 1e-4 * max_coefficient(a.probes));
}

TEST(GltfInstancing, GltfpackInstancedOutputBakesLikeItsInput) {
    // gltfpack -mi folded the parent transform into 125 instances with SHORT normalized rotations.
    const json j = glb_json(data("gp_instanced.glb"));
    ASSERT_TRUE(j.contains("extensionsUsed"));
    EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "EXT_mesh_gpu_instancing"), j["extensionsUsed"].end());
    const json& attrs = j["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"];
    EXPECT_EQ(j["accessors"][attrs["ROTATION"].get<size_t>()]["componentType"], 5122);
    EXPECT_EQ(j["accessors"][attrs["TRANSLATION"].get<size_t>()]["count"], kBoxes);
    EXPECT_EQ(triangle_count(scene_of(data("gp_instanced.glb"))), kBoxes * kBoxTriangles);
    const ProbeList a = bake_cli(data("gi_nodes_uniform.glb"), "gi_nodes_uniform"), b = bake_cli(data("gp_instanced.glb"), "gp_instanced");
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.layout.grid.origin[k], b.layout.grid.origin[k], 1e-3) << k;
    const double d = max_diff(a.probes, b.probes), m = max_coefficient(a.probes);
    std::printf("[ measured ] gltfpack -mi vs plain nodes: max probe difference %.3g (largest coefficient %.3g)\n", d, m);
    EXPECT_LE(d, 1e-4 * m);
}

// A quad at glTF height 1 drawn at x = 0, 5, 10 (instances), a sun straight down, probes under
// each instance and one in the open. Instances 1 and 2 alone can darken probes 1 and 2.
Asset shadow_scene(int rotation_component, bool float_scale = true) {
    Asset a;
    const size_t mesh = a.mesh({-1, 1, -1, 1, 1, -1, 1, 1, 1, -1, 1, 1}, {0, 1, 2, 0, 2, 3});
    const size_t t = a.floats({0, 0, 0, 5, 0, 0, 10, 0, 0}, "VEC3", 3);
    json attrs = {{"TRANSLATION", t}};
    if (rotation_component == 5126) {
        attrs["ROTATION"] = a.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, "VEC4", 4);
    } else if (rotation_component == 5122) {
        const std::int16_t r[12] = {0, 0, 0, 32767, 0, 0, 0, 32767, 0, 0, 0, 32767};
        attrs["ROTATION"] = a.accessor(r, sizeof r, 5122, "VEC4", 3, true);
    } else if (rotation_component == 5120) {
        const std::int8_t r[12] = {0, 0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127};
        attrs["ROTATION"] = a.accessor(r, sizeof r, 5120, "VEC4", 3, true);
    }
    if (float_scale) attrs["SCALE"] = a.floats({1, 1, 1, 1, 1, 1, 1, 1, 1}, "VEC3", 3);
    attrs["_ID"] = a.floats({0, 1, 2}, "SCALAR", 1);  // custom attributes are allowed and ignored
    // The instanced node sits under a parent moved 2 along glTF z (zhc x).
    const size_t child = a.node({{"mesh", mesh}, {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", attrs}}}}}}, false);
    a.node({{"translation", {0, 0, 2}}, {"children", {child}}});
    a.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing", "KHR_lights_punctual"};
    a.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({json{{"type", "directional"}, {"intensity", kPi}}});
    // -Z turned to -Y: rotation of -90 degrees about +X.
    a.node({{"rotation", {-std::sqrt(0.5), 0, 0, std::sqrt(0.5)}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    // Probes in zhc axes ((x, y, z)_zhc = (z, x, y)_glTF): under instances 0, 1, 2 and at 15.
    a.doc["extras"]["zhc"]["probes"]["positions"] = {{2, 0, 0}, {2, 5, 0}, {2, 10, 0}, {2, 15, 0}};
    return a;
}

TEST(GltfInstancing, OnlyTheInstancesShadowTheProbesUnderThem) {
    for (int rc : {5126, 5122, 5120, 0}) {
        auto s = parse(shadow_scene(rc));
        ASSERT_TRUE(s.ok()) << rc << ": " << s.error().message;
        EXPECT_EQ(triangle_count(*s), 6u) << rc;
        const auto p = bake(*s);
        ASSERT_EQ(p.size(), 4u);
        // The sun (from zhc +Z) in the open: its closed form.
        ASSERT_EQ(s->lights.size(), 1u);
        EXPECT_NEAR(s->lights[0].direction.z, 1.0, 1e-12);
        double acc[27] = {};
        add_light_closed_form(s->lights[0], {2, 15, 0}, acc);
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(p[3][i][k], acc[i * 3 + k], 1e-6) << rc;
        EXPECT_GT(acc[0], 0.1);
        for (int i = 0; i < 3; ++i) EXPECT_EQ(test::max_abs(p[static_cast<size_t>(i)]), 0.0) << rc << ": probe " << i << " is under instance " << i;
    }
    // The default grid spans every instance: glTF x from -1 to 11 is zhc y.
    Asset a = shadow_scene(5126);
    a.doc["extras"].erase("zhc");
    auto s = parse(a);
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_EQ(s->probes.kind, ProbePlacementKind::kGrid);
    EXPECT_NEAR(s->probes.min.y, -1 + 12.0 / 16, 1e-12);
    EXPECT_NEAR(s->probes.max.y, 11 - 12.0 / 16, 1e-12);
}

TEST(GltfInstancing, WhatTheExtensionDoesNotDefineIsRefusedNamingTheAttribute) {
    const std::string dir = test::fresh_dir("instancing_refused");
    struct Case {
        std::string file;
        int exit;
        std::string where;
    };
    std::vector<Case> cases = {
        {data("gi_count.glb"), 4, "nodes[1].extensions.EXT_mesh_gpu_instancing.attributes.ROTATION: has 124 elements, TRANSLATION 125"},
        {data("gi_scale_byte.glb"), 5, "nodes[1].extensions.EXT_mesh_gpu_instancing.attributes.SCALE: must be FLOAT"},
    };
    auto edited = [&](const std::string& name, const std::function<void(Asset&)>& edit) {
        Asset a = shadow_scene(5122);
        edit(a);
        return a.write(dir, name);
    };
    // ROTATION as SHORT but not normalized, TRANSLATION as VEC4, attributes missing, a zero quaternion.
    cases.push_back({edited("rot_unnormalized.gltf", [](Asset& a) { a.doc["accessors"][3].erase("normalized"); }), 5,
                     "nodes[0].extensions.EXT_mesh_gpu_instancing.attributes.ROTATION: ROTATION must be FLOAT, or BYTE or SHORT normalized"});
    cases.push_back({edited("t_vec4.gltf", [](Asset& a) { a.doc["accessors"][2]["type"] = "VEC4"; }), 4,
                     "attributes.TRANSLATION: must be a VEC3 accessor"});
    cases.push_back({edited("no_attrs.gltf", [](Asset& a) { a.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"].erase("attributes"); }), 4,
                     "nodes[0].extensions.EXT_mesh_gpu_instancing.attributes: missing or not an object"});
    cases.push_back({edited("zero_quat.gltf",
                            [](Asset& a) {
                                // instance 1's w component (bytes 8 + 6..7 of the rotation view) set to 0
                                const size_t off = a.doc["bufferViews"][a.doc["accessors"][3]["bufferView"].get<size_t>()]["byteOffset"].get<size_t>();
                                a.bin[off + 14] = 0;
                                a.bin[off + 15] = 0;
                            }),
                     4, "attributes.ROTATION: instance 1: must be a unit quaternion (got zero)"});
    for (const Case& c : cases) {
        const std::string out = dir + "/out.json";
        const auto r = test::run_zhc({"bake", c.file, "-o", out, "--quiet"});
        EXPECT_EQ(r.exit_code, c.exit) << c.file << ": " << r.err;
        EXPECT_NE(r.err.find(c.where), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(fs::exists(out)) << c.file;
    }
    // The triangle limit counts every instance, checked before anything is decoded.
    SceneLoadOptions small;
    small.limits.max_triangles = 5;  // 3 instances x 2 triangles = 6
    auto s = parse(shadow_scene(5126), small);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kTooLarge);
}

// ---- EXT_lights_image_based ------------------------------------------------------------------

// zhc's SH basis (docs/conventions.md) written out, evaluated on (x, y, z) of whichever frame.
std::array<double, 9> basis(double x, double y, double z) {
    const double k0 = 0.5 / std::sqrt(kPi), k1 = std::sqrt(3 / (4 * kPi)), k2 = std::sqrt(15 / (4 * kPi)),
                 k20 = std::sqrt(5 / (16 * kPi)), k22 = std::sqrt(15 / (16 * kPi));
    return {k0, -k1 * y, k1 * z, -k1 * x, k2 * x * y, -k2 * y * z, k20 * (3 * z * z - 1), -k2 * x * z, k22 * (x * x - y * y)};
}

// The slow twin of what an exporter computes: the SH of the physical irradiance
// E(n) = integral L(w) max(0, n.w) dw, both integrals by quadrature over N Fibonacci directions.
std::array<double, 9> irradiance_sh_by_quadrature(const std::function<double(Vec3)>& radiance, int n) {
    const std::vector<Vec3> dirs = test::fibonacci_directions(n);
    std::vector<double> l(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) l[i] = radiance(dirs[i]);
    const double w = 4 * kPi / static_cast<double>(dirs.size());
    std::array<double, 9> c{};
    for (const Vec3& nrm : dirs) {
        double e = 0;
        for (size_t i = 0; i < dirs.size(); ++i) e += l[i] * std::max(0.0, dot(nrm, dirs[i]));
        e *= w;
        const auto y = basis(nrm.x, nrm.y, nrm.z);
        for (int k = 0; k < 9; ++k) c[static_cast<size_t>(k)] += e * y[static_cast<size_t>(k)] * w;
    }
    return c;
}

// The analytic radiance, in glTF axes: L = 1 + 0.5 y + 0.4 x z (a constant sky, a vertical
// gradient, and a band-2 term), and its radiance SH in closed form (glTF frame): L00 = 2 sqrt(pi),
// L1-1 = -0.5 sqrt(4 pi / 3) (Y1-1 = -sqrt(3/4pi) y, integral y^2 = 4 pi / 3),
// L21 = -0.4 sqrt(4 pi / 15) (Y21 = -sqrt(15/4pi) x z, integral (x z)^2 = 4 pi / 15).
double analytic_radiance(Vec3 g) { return 1 + 0.5 * g.y + 0.4 * g.x * g.z; }
std::array<double, 9> analytic_radiance_sh() {
    std::array<double, 9> l{};
    l[0] = 2 * std::sqrt(kPi);
    l[1] = -0.5 * std::sqrt(4 * kPi / 3);
    l[7] = -0.4 * std::sqrt(4 * kPi / 15);
    return l;
}
constexpr double kBandFactor[3] = {kPi, 2 * kPi / 3, kPi / 4};  // Ramamoorthi & Hanrahan A_l
int band(int i) { return i == 0 ? 0 : i < 4 ? 1 : 2; }

TEST(GltfImageBasedLight, IrradianceCoefficientsAreRadianceTimesTheCosineLobeFactors) {
    // Derive the factor the reader uses: physical irradiance SH over radiance SH, band by band.
    const auto c = irradiance_sh_by_quadrature(analytic_radiance, 6000);
    const auto l = analytic_radiance_sh();
    for (int i : {0, 1, 7}) {
        const double factor = c[static_cast<size_t>(i)] / l[static_cast<size_t>(i)];
        std::printf("[ measured ] band %d: irradiance / radiance coefficient = %.5f (A_l = %.5f)\n", band(i), factor, kBandFactor[band(i)]);
        EXPECT_NEAR(factor, kBandFactor[band(i)], 2e-3 * kBandFactor[band(i)]) << i;
    }
    for (int i : {2, 3, 4, 5, 6, 8}) EXPECT_NEAR(c[static_cast<size_t>(i)], 0.0, 2e-3) << i;
}

// An asset whose scene references one EXT_lights_image_based light with these coefficients.
Asset ibl_asset(const std::array<double, 9>& grey, double intensity, const std::vector<double>& rotation) {
    Asset a;
    json coeffs = json::array();
    for (int i = 0; i < 9; ++i) {
        const double v = grey[static_cast<size_t>(i)];
        coeffs.push_back({v, 0.5 * v, 0.25 * v});  // colour: 1, 0.5, 0.25
    }
    json light = {{"name", "studio"}, {"irradianceCoefficients", coeffs}, {"specularImageSize", 256}, {"specularImages", json::array()}};
    if (intensity != 1) light["intensity"] = intensity;
    if (!rotation.empty()) light["rotation"] = rotation;
    a.doc["extensions"]["EXT_lights_image_based"]["lights"] = json::array({light});
    a.doc["extensionsUsed"] = {"EXT_lights_image_based"};
    a.doc["scenes"][0]["extensions"]["EXT_lights_image_based"]["light"] = 0;
    return a;
}

// Expected zhc SH3 radiance (zhc axes, grey) against a probe's red/green/blue = 1, 0.5, 0.25.
void expect_probe(const Sh3Radiance& p, const std::array<double, 9>& grey, double tol, const std::string& what) {
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(p[i][k], grey[static_cast<size_t>(i)] * (k == 0 ? 1 : k == 1 ? 0.5 : 0.25), tol) << what << ": coefficient " << i << " channel " << k;
}

// In zhc axes the same radiance reads L = 1 + 0.5 z + 0.4 y x ((x, y, z)_zhc = (z, x, y)_glTF):
// L00 = 2 sqrt(pi), L10 = 0.5 sqrt(4 pi / 3), L2-2 = 0.4 sqrt(4 pi / 15).
std::array<double, 9> analytic_radiance_zhc() {
    std::array<double, 9> l{};
    l[0] = 2 * std::sqrt(kPi);
    l[2] = 0.5 * std::sqrt(4 * kPi / 3);
    l[4] = 0.4 * std::sqrt(4 * kPi / 15);
    return l;
}

TEST(GltfImageBasedLight, BakesTheRadianceItsCoefficientsDescribe) {
    // Coefficients an exporter would write (quadrature), and the exact ones (A_l L_lm).
    const auto numeric = irradiance_sh_by_quadrature(analytic_radiance, 6000);
    std::array<double, 9> exact{};
    const auto l = analytic_radiance_sh();
    for (int i = 0; i < 9; ++i) exact[static_cast<size_t>(i)] = kBandFactor[band(i)] * l[static_cast<size_t>(i)];
    for (const auto& [coeffs, tol] : {std::pair{numeric, 5e-3}, std::pair{exact, 2e-6}}) {
        Asset a = ibl_asset(coeffs, 1, {});
        a.doc["extras"]["zhc"]["probes"]["positions"] = {{0, 0, 0}, {3, -1, 2}};
        std::vector<std::string> notes;
        auto s = parse(a, {}, &notes);
        ASSERT_TRUE(s.ok()) << s.error().message;
        EXPECT_TRUE(notes.empty());
        ASSERT_TRUE(s->environment.has_value());
        const auto p = bake(*s);
        ASSERT_EQ(p.size(), 2u);
        expect_probe(p[0], analytic_radiance_zhc(), tol, "probe 0");
        EXPECT_EQ(test::max_abs_diff(p[0], p[1]), 0.0);  // an environment is the same everywhere
    }
}

TEST(GltfImageBasedLight, IntensityAndRotationApply) {
    // L = 1 + 0.5 z_glTF, exact coefficients; intensity 2; rotation 90 degrees about glTF +Y,
    // which turns +Z to +X: the scene sees L = 1 + 0.5 x_glTF = 1 + 0.5 y_zhc, times 2.
    std::array<double, 9> c{};
    c[0] = kPi * 2 * std::sqrt(kPi);
    c[2] = 2 * kPi / 3 * 0.5 * std::sqrt(4 * kPi / 3);
    const double h = std::sqrt(0.5);
    auto s = parse(ibl_asset(c, 2, {0, h, 0, h}));
    ASSERT_TRUE(s.ok()) << s.error().message;
    const auto p = bake(*s);
    ASSERT_EQ(p.size(), 1u);
    std::array<double, 9> want{};
    want[0] = 2 * 2 * std::sqrt(kPi);
    want[1] = 2 * -0.5 * std::sqrt(4 * kPi / 3);  // Y1-1 = -sqrt(3/4pi) y
    expect_probe(p[0], want, 2e-6, "rotated");
    // Without the rotation the gradient stays along glTF +Z = zhc +X (Y11 = -sqrt(3/4pi) x).
    auto unrotated = parse(ibl_asset(c, 2, {}));
    ASSERT_TRUE(unrotated.ok());
    std::array<double, 9> want0{};
    want0[0] = want[0];
    want0[3] = want[1];
    expect_probe(bake(*unrotated)[0], want0, 2e-6, "unrotated");
    // A non-unit quaternion is normalised (glTF requires unit ones; this absorbs rounding).
    auto scaled = parse(ibl_asset(c, 2, {0, 3 * h, 0, 3 * h}));
    ASSERT_TRUE(scaled.ok());
    expect_probe(bake(*scaled)[0], want, 2e-6, "scaled quaternion");
}

TEST(GltfImageBasedLight, TheReportNamesItAndWhatIsNotUsedIsSaid) {
    const std::string dir = test::fresh_dir("ibl_report");
    std::array<double, 9> c{};
    c[0] = kPi * 2 * std::sqrt(kPi);  // constant radiance 1
    const std::string used = ibl_asset(c, 1, {}).write(dir, "used.gltf");
    auto r = test::run_zhc({"bake", used, "-o", dir + "/used.json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("EXT_lights_image_based 'studio'"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("(none"), std::string::npos) << r.out;
    auto probes = read_probe_json(dir + "/used.json");
    ASSERT_TRUE(probes.ok());
    EXPECT_NEAR(probes->probes[0][0][0], 2 * std::sqrt(kPi), 2e-6);

    // Defined but referenced by no scene: not baked, and said so.
    Asset unref = ibl_asset(c, 1, {});
    unref.doc["scenes"][0].erase("extensions");
    r = test::run_zhc({"bake", unref.write(dir, "unref.gltf"), "-o", dir + "/unref.json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("note: " + dir + "/unref.gltf: EXT_lights_image_based: 1 image-based light(s) defined, none referenced by scenes[0]: not used"),
              std::string::npos) << r.err;

    // extras.zhc's sky or environment wins over the glTF light, and the bake says so.
    Asset sky = ibl_asset(c, 1, {});
    sky.doc["extras"]["zhc"]["sky"] = {{"type", "constant"}, {"radiance", 3}};
    r = test::run_zhc({"bake", sky.write(dir, "sky.gltf"), "-o", dir + "/sky.json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("EXT_lights_image_based 'studio': not used: extras.zhc.sky gives the scene's environment"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("sky (constant)"), std::string::npos);
    probes = read_probe_json(dir + "/sky.json");
    ASSERT_TRUE(probes.ok());
    EXPECT_NEAR(probes->probes[0][0][0], 3 * 2 * std::sqrt(kPi), 1e-5);  // the sky's, not the light's
    // --quiet drops the effects report, never the notes.
    r = test::run_zhc({"bake", dir + "/sky.gltf", "-o", dir + "/sky2.json", "--quiet"});
    EXPECT_NE(r.err.find("not used"), std::string::npos) << r.err;
}

// No Debian or npm tool here writes EXT_lights_image_based: gt_list.gltf (glTF-Transform) edited by
// hand to reference one. The environment adds to its lights: probe for probe, the bake differs
// from the unedited file's by the light's SH alone (here a gradient along glTF +Z, intensity 0.5).
TEST(GltfImageBasedLight, AddsToTheLightsOfARealFile) {
    const std::string dir = test::fresh_dir("ibl_real");
    copy_gt_list(dir);
    json d = json::parse(test::read_bytes(dir + "/gt_list.gltf"));
    ASSERT_FALSE(d["extras"]["zhc"].contains("sky"));
    ASSERT_FALSE(d["extras"]["zhc"].contains("environment"));
    json c = json::array();
    for (int i = 0; i < 9; ++i) c.push_back({0.0, 0.0, 0.0});
    c[0] = {kPi * 2 * std::sqrt(kPi), kPi * 2 * std::sqrt(kPi), 0.0};               // constant 1 (red, green)
    c[2] = {0.0, 0.0, 2 * kPi / 3 * 0.5 * std::sqrt(4 * kPi / 3)};                     // 0.5 z_glTF (blue)
    d["extensions"]["EXT_lights_image_based"]["lights"] = json::array({json{{"name", "hand"}, {"intensity", 0.5}, {"irradianceCoefficients", c},
                                                                           {"specularImageSize", 16}, {"specularImages", json::array()}}});
    d["extensionsUsed"].push_back("EXT_lights_image_based");
    d["scenes"][d.value("scene", 0)]["extensions"]["EXT_lights_image_based"]["light"] = 0;
    const std::string t = d.dump(), edited = dir + "/ibl.gltf";
    test::write_bytes(edited, std::vector<std::uint8_t>(t.begin(), t.end()));
    // The asset's meshes occlude the environment (docs/scene.md "Probes near geometry"): the
    // conversion factors are checked with that occlusion off (--sky-samples 0), then with it on
    // the environment can only lose radiance (its red and green are constant 1 in every direction).
    const std::vector<std::string> open_sky = {"--sky-samples", "0"};
    const ProbeList plain = bake_cli(dir + "/gt_list.gltf", "ibl_real_plain", open_sky), lit = bake_cli(edited, "ibl_real_lit", open_sky);
    {
        const ProbeList plain_occ = bake_cli(dir + "/gt_list.gltf", "ibl_real_plain_occ"), lit_occ = bake_cli(edited, "ibl_real_lit_occ");
        ASSERT_EQ(plain_occ.probes.size(), lit_occ.probes.size());
        int occluded = 0;
        for (size_t p = 0; p < plain_occ.probes.size(); ++p) {
            const double added = double(lit_occ.probes[p][0][0]) - plain_occ.probes[p][0][0];
            EXPECT_GE(added, -1e-5) << p;
            EXPECT_LE(added, 0.5 * 2 * std::sqrt(kPi) + 1e-5) << p;
            occluded += added < 0.5 * 2 * std::sqrt(kPi) - 1e-3;
        }
        EXPECT_GT(occluded, 0);
    }
    ASSERT_EQ(plain.probes.size(), lit.probes.size());
    ASSERT_GT(plain.probes.size(), 0u);
    for (size_t p = 0; p < plain.probes.size(); ++p)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) {
                // zhc +X is glTF +Z: Y11 = -sqrt(3/4pi) x.
                const double want = i == 0 && k < 2 ? 0.5 * 2 * std::sqrt(kPi) : i == 3 && k == 2 ? -0.5 * 0.5 * std::sqrt(4 * kPi / 3) : 0.0;
                EXPECT_NEAR(lit.probes[p][i][k] - plain.probes[p][i][k], want, 2e-5 * (1 + std::fabs(plain.probes[p][i][k])))
                    << "probe " << p << " coefficient " << i << " channel " << k;
            }
}

TEST(GltfImageBasedLight, MalformedLightsAreRefusedNamingTheField) {
    const std::string dir = test::fresh_dir("ibl_refused");
    std::array<double, 9> c{};
    c[0] = 1;
    struct Case {
        std::string name;
        std::function<void(Asset&)> edit;
        std::string where;
    };
    const std::vector<Case> cases = {
        {"rows8", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0]["irradianceCoefficients"].erase(8); },
         "extensions.EXT_lights_image_based.lights[0].irradianceCoefficients: must be an array of 9"},
        {"flat27", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0]["irradianceCoefficients"] = json(std::vector<double>(27, 0.5)); },
         "extensions.EXT_lights_image_based.lights[0].irradianceCoefficients: must be an array of 9"},
        {"row2", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0]["irradianceCoefficients"][4] = {1, 2}; },
         "irradianceCoefficients[4]: must be an array of 3 numbers"},
        {"missing", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0].erase("irradianceCoefficients"); },
         "lights[0].irradianceCoefficients: missing required field"},
        {"index", [](Asset& a) { a.doc["scenes"][0]["extensions"]["EXT_lights_image_based"]["light"] = 1; },
         "scenes[0].extensions.EXT_lights_image_based.light: must be an index into extensions.EXT_lights_image_based.lights (0..1), got 1"},
        {"intensity", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0]["intensity"] = -1; },
         "lights[0].intensity: must be >= 0"},
        {"rotation", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0]["rotation"] = {0, 0, 0, 0}; },
         "lights[0].rotation: must be a unit quaternion (got zero)"},
        {"lights", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"] = json::object(); },
         "extensions.EXT_lights_image_based.lights: must be an array"},
        {"huge", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0]["irradianceCoefficients"][3] = {1e38, 0, 0}; },
         "irradianceCoefficients[3]: too large"},
        {"overflow", [](Asset& a) { a.doc["extensions"]["EXT_lights_image_based"]["lights"][0]["intensity"] = 1e300; },
         "lights[0].intensity: intensity x irradianceCoefficients does not fit 32-bit floats"},
    };
    for (const Case& k : cases) {
        Asset a = ibl_asset(c, 1, {});
        k.edit(a);
        const std::string out = dir + "/" + k.name + ".json";
        const auto r = test::run_zhc({"bake", a.write(dir, k.name + ".gltf"), "-o", out, "--quiet"});
        EXPECT_EQ(r.exit_code, 4) << k.name << ": " << r.err;
        EXPECT_NE(r.err.find(k.where), std::string::npos) << k.name << ": " << r.err;
        EXPECT_FALSE(fs::exists(out)) << k.name;
    }
}

// ---- external buffers longer / shorter than byteLength ----------------------------------------

TEST(GltfBufferLength, ALongerBinReadsItsByteLengthAShorterOneIsRefused) {
    const std::string exact = test::fresh_dir("bin_exact"), longer = test::fresh_dir("bin_longer"), shorter = test::fresh_dir("bin_shorter");
    copy_gt_list(exact);
    copy_gt_list(longer);
    copy_gt_list(shorter);
    auto bin = test::read_bytes(exact + "/gt_list.bin");
    auto more = bin;
    for (int i = 0; i < 131; ++i) more.push_back(static_cast<std::uint8_t>(0xA5 ^ i));  // the 131 extra bytes
    test::write_bytes(longer + "/gt_list.bin", more);
    test::write_bytes(shorter + "/gt_list.bin", std::vector<std::uint8_t>(bin.begin(), bin.end() - 4));

    // Bake and embed: the longer file gives the same bytes as the exact one.
    const auto probes = exact + "/p.zhp";
    ASSERT_EQ(test::run_zhc({"bake", exact + "/gt_list.gltf", "-o", probes, "--quiet"}).exit_code, 0);
    for (const std::string& dir : {exact, longer}) {
        auto r = test::run_zhc({"bake", dir + "/gt_list.gltf", "-o", dir + "/out.json", "--quiet"});
        EXPECT_EQ(r.exit_code, 0) << dir << ": " << r.err;
        r = test::run_zhc({"gltf", "embed", dir + "/gt_list.gltf", probes, "-o", dir + "/out.glb"});
        EXPECT_EQ(r.exit_code, 0) << dir << ": " << r.err;
    }
    EXPECT_EQ(test::read_bytes(exact + "/out.json"), test::read_bytes(longer + "/out.json"));
    EXPECT_EQ(test::read_bytes(exact + "/out.glb"), test::read_bytes(longer + "/out.glb"));

    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"bake", shorter + "/gt_list.gltf", "-o", shorter + "/out.json"},
          std::vector<std::string>{"gltf", "embed", shorter + "/gt_list.gltf", probes, "-o", shorter + "/out.glb"},
          std::vector<std::string>{"info", shorter + "/gt_list.gltf"}}) {
        const auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 4) << args[0] << ": " << r.err;
        EXPECT_NE(r.err.find("gt_list.gltf: buffers[0]: file 'gt_list.bin' has " + std::to_string(bin.size() - 4) +
                             " bytes, fewer than the buffer's byteLength " + std::to_string(bin.size())),
                  std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(shorter + "/out.json"));
    EXPECT_FALSE(fs::exists(shorter + "/out.glb"));
}

// The same for a base64 data: URI (gt_list.gltf with its .bin inlined by hand): the validator
// accepts more bytes than byteLength, tinygltf alone would refuse them.
TEST(GltfBufferLength, ADataUriLongerThanByteLengthToo) {
    const std::string dir = test::fresh_dir("data_uri_length");
    copy_gt_list(dir);
    const auto bin = test::read_bytes(dir + "/gt_list.bin");
    json base = json::parse(test::read_bytes(dir + "/gt_list.gltf"));
    auto with = [&](std::vector<std::uint8_t> bytes, const std::string& name) {
        json d = base;
        d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bytes);
        const std::string t = d.dump(), p = dir + "/" + name + ".gltf";
        test::write_bytes(p, std::vector<std::uint8_t>(t.begin(), t.end()));
        return p;
    };
    auto longer = bin;
    for (int i = 0; i < 7; ++i) longer.push_back(static_cast<std::uint8_t>(i));
    const std::string exact = with(bin, "exact"), more = with(longer, "longer"), less = with({bin.begin(), bin.end() - 5}, "shorter");
    for (const std::string& f : {exact, more}) {
        const auto r = test::run_zhc({"bake", f, "-o", f + ".json", "--quiet"});
        EXPECT_EQ(r.exit_code, 0) << f << ": " << r.err;
    }
    EXPECT_EQ(test::read_bytes(exact + ".json"), test::read_bytes(more + ".json"));
    const auto r = test::run_zhc({"bake", less, "-o", less + ".json", "--quiet"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_NE(r.err.find("shorter.gltf: buffers[0]: the data: URI holds " + std::to_string(bin.size() - 5) + " bytes, fewer than the buffer's byteLength " +
                         std::to_string(bin.size())), std::string::npos) << r.err;
    EXPECT_LT(r.err.size(), 300u) << "the URI is not echoed";
    EXPECT_FALSE(fs::exists(less + ".json"));
}

// ---- fields of the wrong JSON type while embedding ---------------------------------------------

// One class each: push_back onto an object (scenes[i].nodes, bufferViews, accessors), a
// container silently replaced before (extensions.ZHC_light_probes, extensionsUsed, nodes), an
// entry of the wrong type (images[0]), value() on a non-object while loading (meshes[1]).
TEST(GltfEmbedFields, WrongJsonTypesAreRefusedNamingTheFieldFromBakeAndEmbed) {
    const std::string dir = test::fresh_dir("embed_fields");
    copy_gt_list(dir);
    const std::string probes = dir + "/p.zhp";
    ASSERT_EQ(test::run_zhc({"bake", dir + "/gt_list.gltf", "-o", probes, "--quiet"}).exit_code, 0);
    const json base = json::parse(test::read_bytes(dir + "/gt_list.gltf"));
    struct Case {
        std::string name;
        std::function<void(json&)> edit;
        std::string where;
        bool glb = false;  // an edit of gt_draco.glb (glTF-Transform, KHR_draco_mesh_compression)
    };
    const std::vector<Case> cases = {
        {"scene1_nodes", [](json& d) { d["scenes"].push_back({{"nodes", {{"first", 0}}}}); }, "scenes[1].nodes: must be an array (got object)"},
        {"bufferviews", [](json& d) { d["bufferViews"] = json::object(); d.erase("accessors"); d.erase("meshes"); for (json& n : d["nodes"]) n.erase("mesh"); },
         "bufferViews: must be an array (got object)"},
        {"zhc_ext", [](json& d) { d["extensions"]["ZHC_light_probes"] = json::array(); }, "extensions.ZHC_light_probes: must be an object (got array)"},
        {"used", [](json& d) { d["extensionsUsed"] = json::object(); }, "extensionsUsed: must be an array (got object)"},
        {"image", [](json& d) { d["images"].push_back(7); }, "images[1]: must be an object (got number)"},
        // A Draco asset (its index accessors lack a bufferView) with a mesh that is a number.
        {"mesh_number", [](json& d) { d["meshes"].push_back(7); }, "meshes", true},
    };
    const json draco = glb_json(data("gt_draco.glb"));
    for (const Case& c : cases) {
        json d = c.glb ? draco : base;
        c.edit(d);
        const std::string in = dir + "/" + c.name + (c.glb ? ".glb" : ".gltf");
        const std::string text = d.dump();
        test::write_bytes(in, c.glb ? glb_with_json(data("gt_draco.glb"), d) : std::vector<std::uint8_t>(text.begin(), text.end()));
        for (const std::vector<std::string>& args : {std::vector<std::string>{"bake", in, "-o", dir + "/out.glb", "--quiet"},
                                                     std::vector<std::string>{"gltf", "embed", in, probes, "-o", dir + "/out.glb"}}) {
            const auto r = test::run_zhc(args);
            EXPECT_EQ(r.exit_code, 4) << c.name << " " << args[0] << ": " << r.err;
            EXPECT_NE(r.err.find(fs::path(in).filename().string() + ": "), std::string::npos) << r.err;
            EXPECT_NE(r.err.find(c.where), std::string::npos) << c.name << " " << args[0] << ": " << r.err;
            EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
            EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
            EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
            EXPECT_FALSE(fs::exists(dir + "/out.glb")) << c.name << " " << args[0];
        }
    }
    // The untouched file embeds (the checks refuse only what is wrong).
    EXPECT_EQ(test::run_zhc({"gltf", "embed", dir + "/gt_list.gltf", probes, "-o", dir + "/ok.glb"}).exit_code, 0);
}

}  // namespace
}  // namespace zhc
