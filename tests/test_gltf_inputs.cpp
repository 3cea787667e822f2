// glTF files other programs wrote (issue 16): tests/data/gltf, made by glTF-Transform (npm) and
// Debian's gltfpack with tests/js/make_gltf_corpus.mjs. Every variant of the one scene (strips,
// fans, meshopt- and Draco-compressed buffers, no scene, data-URI images) must read as the same
// triangles and bake the same probes as the plain triangle-list version the same tool wrote;
// refused variants must give the README's exit code on one line, naming the file.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

#include "codec/bake/scene.h"
#include "formats/io/file_io.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"
#include "formats/scene/scene_gltf.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string data(const std::string& name) { return std::string(ZHC_TEST_DATA_DIR) + "/gltf/" + name; }

// zhc bake FILE -o DIR/out.json, the probes read back (ASSERTs exit 0).
std::vector<Sh3Radiance> bake(const std::string& file, const std::string& tag) {
    const std::string out = test::temp_dir("gltf_inputs") + "/" + tag + ".json";
    const auto r = test::run_zhc({"bake", file, "-o", out, "--threads", "2", "--quiet"});
    EXPECT_EQ(r.exit_code, 0) << file << ": " << r.err;
    auto list = read_probe_json(out);
    EXPECT_TRUE(list.ok()) << (list.ok() ? "" : list.error().message);
    return list.ok() ? list->probes : std::vector<Sh3Radiance>{};
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

Scene scene_of(const std::string& file) {
    auto bytes = read_file_bytes(file, GltfLimits{}.max_file_bytes);
    EXPECT_TRUE(bytes.ok()) << (bytes.ok() ? "" : bytes.error().message);
    if (!bytes.ok()) return Scene{};
    auto s = parse_scene_gltf(*bytes, file);
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return s.ok() ? std::move(s).value() : Scene{};
}

// A triangle as its vertex set (rotation and winding ignored), rounded to `grid` for matching.
using Tri = std::array<std::array<long long, 3>, 3>;
std::vector<Tri> triangles(const Scene& s, double grid) {
    std::vector<Tri> out;
    for (const Occluder& o : s.occluders) {
        if (o.kind != OccluderKind::kTriangle) continue;
        Tri t;
        const Vec3 v[3] = {o.v0, o.v1, o.v2};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) t[static_cast<size_t>(k)][static_cast<size_t>(a)] = std::llround(v[k][a] / grid);
        std::sort(t.begin(), t.end());
        out.push_back(t);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// The scene of make_gltf_corpus.mjs: floor (2 triangles), box (12), wall (2).
constexpr size_t kSceneTriangles = 16;

TEST(GltfInputs, ReferenceListHasTheWrittenGeometry) {
    const Scene s = scene_of(data("gt_list.glb"));
    EXPECT_EQ(triangles(s, 1e-6).size(), kSceneTriangles);
    EXPECT_EQ(s.lights.size(), 2u);
    ASSERT_EQ(s.probes.kind, ProbePlacementKind::kGrid);  // extras.zhc kept by glTF-Transform
    EXPECT_EQ(s.probes.counts, (std::array<std::uint32_t, 3>{4, 4, 3}));
    // Floor corners (glTF (+-2, 0, +-2) -> zhc (+-2, +-2, 0)) and the box top at glTF y = 1.6.
    double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
    for (const Occluder& o : s.occluders)
        for (const Vec3& v : {o.v0, o.v1, o.v2})
            for (int a = 0; a < 3; ++a) {
                lo[a] = std::min(lo[a], v[a]);
                hi[a] = std::max(hi[a], v[a]);
            }
    EXPECT_EQ(lo[0], -2);
    EXPECT_EQ(hi[0], 2);
    EXPECT_EQ(lo[2], 0);
    EXPECT_NEAR(hi[2], 2.0, 1e-6);  // the wall's top
}

// Strips, fans and meshopt: the same triangles as the list, and bit-identical probes.
TEST(GltfInputs, StripFanMeshoptBakeLikeTheList) {
    const auto reference = bake(data("gt_list.glb"), "gt_list");
    ASSERT_FALSE(reference.empty());
    EXPECT_GT(max_coefficient(reference), 0.01);
    const auto ref_tris = triangles(scene_of(data("gt_list.glb")), 1e-6);
    for (const char* name : {"gt_strip.glb", "gt_fan.glb", "gt_meshopt.glb", "gt_meshopt_strip.glb", "gt_list.gltf"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(triangles(scene_of(data(name)), 1e-6), ref_tris);
        EXPECT_EQ(max_diff(bake(data(name), name), reference), 0.0);
    }
}

TEST(GltfInputs, GltfpackMeshoptBakesLikeGltfpackPlain) {
    if (!fs::exists(data("gp_meshopt.glb"))) GTEST_SKIP() << "gltfpack files not in the corpus";
    const auto plain_tris = triangles(scene_of(data("gp_list.glb")), 1e-6);
    EXPECT_EQ(plain_tris.size(), kSceneTriangles);
    EXPECT_EQ(triangles(scene_of(data("gp_meshopt.glb")), 1e-6), plain_tris);
    EXPECT_EQ(plain_tris, triangles(scene_of(data("gt_list.glb")), 1e-6));  // gltfpack kept the geometry
    const auto plain = bake(data("gp_list.glb"), "gp_list");
    EXPECT_GT(max_coefficient(plain), 0.01);
    EXPECT_EQ(max_diff(bake(data("gp_meshopt.glb"), "gp_meshopt"), plain), 0.0);
}

// gltfpack's default output quantises positions (KHR_mesh_quantization: 14-bit UNSIGNED_SHORT,
// plain or normalized, dequantised by the mesh node's scale and translation; step 4 m / 16383 =
// 2.44e-4 m). Independent expectation: every triangle of gltfpack's unquantised version within one
// step. The meshopt-compressed and the fallback-file versions of the quantised data are lossless:
// bit-identical. Probes (a default grid over the vertex bounds, which move by up to a step):
// measured median difference 2.4e-7, 6 of 512 probes (those whose shadow rays graze a moved edge)
// up to 0.63% of the largest coefficient; asserted: at least 97% of the probes within 1e-5 and
// every probe within 1e-2 of the largest coefficient.
TEST(GltfInputs, GltfpackQuantisedPositionsReadWithinAStep) {
    if (!fs::exists(data("gp_quant.glb"))) GTEST_SKIP() << "gltfpack files not in the corpus";
    const double step = 4.0 / 16383;
    const auto plain = triangles(scene_of(data("gp_list.glb")), step);
    for (const char* name : {"gp_quant.glb", "gp_quant_norm.glb"}) {
        SCOPED_TRACE(name);
        const Scene q = scene_of(data(name));
        const Scene l = scene_of(data("gp_list.glb"));
        ASSERT_EQ(q.occluders.size(), l.occluders.size());
        for (size_t i = 0; i < l.occluders.size(); ++i) {  // gltfpack keeps the triangle order
            const Vec3 a[3] = {l.occluders[i].v0, l.occluders[i].v1, l.occluders[i].v2};
            const Vec3 b[3] = {q.occluders[i].v0, q.occluders[i].v1, q.occluders[i].v2};
            for (int k = 0; k < 3; ++k)
                for (int ax = 0; ax < 3; ++ax) EXPECT_LE(std::abs(a[k][ax] - b[k][ax]), step) << "triangle " << i;
        }
    }
    EXPECT_EQ(plain.size(), kSceneTriangles);
    const auto reference = bake(data("gp_list.glb"), "gp_list_q");
    const auto quant = bake(data("gp_quant.glb"), "gp_quant");
    const double big = max_coefficient(reference);
    size_t close = 0;
    for (size_t i = 0; i < std::min(reference.size(), quant.size()); ++i) {
        const double d = test::max_abs_diff(reference[i], quant[i]);
        close += d <= 1e-5 * big;
        EXPECT_LE(d, 1e-2 * big) << "probe " << i;
    }
    EXPECT_EQ(quant.size(), reference.size());
    EXPECT_GE(static_cast<double>(close), 0.97 * static_cast<double>(reference.size()));
    for (const char* name : {"gp_quant_meshopt.glb", "gp_fallback.gltf"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(max_diff(bake(data(name), name), quant), 0.0);
    }
}

// Draco quantises positions (16 bits over the 4 m extent: a step of 4 / 65535 m): every triangle
// of the list is found within one step, and the probes agree within the error the moved edges
// can cause (measured 0 here: no shadow ray passes within 6e-5 m of an edge; bound stated 1e-3
// of the largest coefficient).
TEST(GltfInputs, DracoReadsTheSameTrianglesWithinQuantisation) {
    const double step = 4.0 / 65535;
    const Scene d = scene_of(data("gt_draco.glb"));
    const Scene l = scene_of(data("gt_list.glb"));
    ASSERT_EQ(d.occluders.size(), l.occluders.size());
    // Match each list triangle to a Draco one with the same three vertices (any order) within a step.
    std::vector<char> used(d.occluders.size(), 0);
    for (const Occluder& a : l.occluders) {
        bool found = false;
        for (size_t j = 0; j < d.occluders.size() && !found; ++j) {
            if (used[j]) continue;
            const Vec3 av[3] = {a.v0, a.v1, a.v2};
            const Vec3 bv[3] = {d.occluders[j].v0, d.occluders[j].v1, d.occluders[j].v2};
            int matched = 0;
            for (const Vec3& p : av)
                for (const Vec3& q : bv)
                    if (std::abs(p.x - q.x) <= step && std::abs(p.y - q.y) <= step && std::abs(p.z - q.z) <= step) {
                        ++matched;
                        break;
                    }
            if (matched == 3) found = true, used[j] = 1;
        }
        EXPECT_TRUE(found) << "list triangle " << a.v0.x << "," << a.v0.y << "," << a.v0.z;
    }
    const auto reference = bake(data("gt_list.glb"), "gt_list_d");
    const auto draco = bake(data("gt_draco.glb"), "gt_draco");
    EXPECT_LE(max_diff(draco, reference), 1e-3 * max_coefficient(reference));
}

TEST(GltfInputs, NoSceneUsesEveryRootNode) {
    // Same nodes as gt_list.gltf, all of them roots of its scene: the same bake.
    EXPECT_EQ(max_diff(bake(data("noscene.gltf"), "noscene"), bake(data("gt_list.gltf"), "gt_list_gltf")), 0.0);
}

TEST(GltfInputs, DataUriAndMissingImagesAreNotNeeded) {
    const auto reference = bake(data("gt_list.gltf"), "gt_list_gltf2");
    for (const char* name : {"datauri_image.gltf", "datauri_webp_image.gltf", "missing_image.gltf"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(max_diff(bake(data(name), name), reference), 0.0);
    }
}

void expect_refused(const std::string& file, int code, const std::string& needle, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"bake", file, "-o", test::temp_dir("gltf_inputs") + "/refused.json"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = test::run_zhc(args);
    EXPECT_EQ(r.exit_code, code) << file << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("zhc: error: " + file + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
}

TEST(GltfInputs, RefusedWithTheReadmeExitCodes) {
    expect_refused(data("missing_bin.gltf"), 3, "referenced file 'missing.bin' not found");
    expect_refused(data("version3.gltf"), 5, "glTF version 3.0");
    expect_refused(data("minversion.gltf"), 5, "minVersion");
    expect_refused(data("noversion.gltf"), 4, "asset.version missing");
}

// Where an external buffer resolves depends on the glTF file's folder only: not on the working
// directory, even when the working directory holds a file of that name.
TEST(GltfInputs, UrisResolveAgainstTheFileNotTheWorkingDirectory) {
    const std::string root = test::fresh_dir("gltf_inputs_cwd");
    fs::create_directories(root + "/asset");
    fs::create_directories(root + "/elsewhere");
    fs::copy_file(data("gt_list.gltf"), root + "/asset/scene.gltf");
    fs::copy_file(data("gt_list.bin"), root + "/asset/gt_list.bin");
    fs::copy_file(data("tex.png"), root + "/asset/tex.png");
    const fs::path old = fs::current_path();
    struct Restore {
        fs::path p;
        ~Restore() { fs::current_path(p); }
    } restore{old};
    fs::current_path(root + "/elsewhere");
    const auto reference = bake(data("gt_list.gltf"), "cwd_reference");
    EXPECT_EQ(max_diff(bake("../asset/scene.gltf", "cwd_relative"), reference), 0.0);
    EXPECT_EQ(max_diff(bake(root + "/asset/scene.gltf", "cwd_absolute"), reference), 0.0);
    // The buffer missing next to the file but present in the working directory: still missing.
    fs::copy_file(data("gt_list.gltf"), root + "/elsewhere/lonely.gltf");
    fs::create_directories(root + "/other");
    fs::copy_file(root + "/elsewhere/lonely.gltf", root + "/other/lonely.gltf");
    fs::copy_file(data("gt_list.bin"), root + "/elsewhere/gt_list.bin");
    expect_refused("../other/lonely.gltf", 3, "'gt_list.bin' not found");
}

// GLB edits for hostile variants: the JSON chunk replaced, the BIN chunk kept.
std::vector<std::uint8_t> edit_glb(const std::string& file, const std::function<void(json&, std::vector<std::uint8_t>&)>& edit) {
    std::vector<std::uint8_t> b = test::read_bytes(file);
    const std::uint32_t jlen = test::get32(b, 12);
    json j = json::parse(b.begin() + 20, b.begin() + 20 + jlen);
    std::vector<std::uint8_t> bin(b.begin() + 20 + jlen + 8, b.end());
    edit(j, bin);
    std::string text = j.dump();
    while (text.size() % 4) text.push_back(' ');
    while (bin.size() % 4) bin.push_back(0);
    std::vector<std::uint8_t> out(12, 0);
    auto add32 = [&](std::uint32_t v) {
        for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
    };
    add32(static_cast<std::uint32_t>(text.size()));
    add32(0x4E4F534A);
    out.insert(out.end(), text.begin(), text.end());
    add32(static_cast<std::uint32_t>(bin.size()));
    add32(0x004E4942);
    out.insert(out.end(), bin.begin(), bin.end());
    test::put32(out, 0, 0x46546C67);
    test::put32(out, 4, 2);
    test::put32(out, 8, static_cast<std::uint32_t>(out.size()));
    return out;
}

TEST(GltfInputs, HostileCompressedViewsRefused) {
    const std::string dir = test::temp_dir("gltf_inputs_hostile");
    struct Case {
        const char* name;
        const char* source;
        std::function<void(json&, std::vector<std::uint8_t>&)> edit;
        int exit_code;
        const char* needle;
    };
    const char* mo = "EXT_meshopt_compression";
    const std::vector<Case> cases = {
        {"mo_huge", "gt_meshopt.glb", [&](json& j, auto&) {
             j["bufferViews"][2]["extensions"][mo]["count"] = 80000000;
             j["bufferViews"][2]["byteLength"] = 960000000;
         }, 4, "compressed bytes cannot hold"},
        {"mo_above_limit", "gt_meshopt.glb", [&](json& j, auto&) {
             j["bufferViews"][2]["extensions"][mo]["count"] = 200000000;
             j["bufferViews"][2]["byteLength"] = 2400000000u;
         }, 6, "above the buffer limit"},
        {"mo_garbage", "gt_meshopt.glb", [&](json& j, std::vector<std::uint8_t>& bin) {
             const size_t off = j["bufferViews"][2]["extensions"][mo]["byteOffset"].get<size_t>();
             const size_t len = j["bufferViews"][2]["extensions"][mo]["byteLength"].get<size_t>();
             for (size_t i = off + 1; i < off + len; ++i) bin[i] = static_cast<std::uint8_t>(i * 131 + 7);
             j["bufferViews"][2]["extensions"][mo]["byteLength"] = 20;  // and too short
         }, 4, "does not decode"},
        {"mo_mode", "gt_meshopt.glb", [&](json& j, auto&) { j["bufferViews"][0]["extensions"][mo]["mode"] = "VERTICES"; }, 5,
         "unknown meshopt mode"},
        {"mo_stride", "gt_meshopt.glb", [&](json& j, auto&) {
             j["bufferViews"][0]["extensions"][mo]["byteStride"] = 6;
             j["bufferViews"][0]["byteLength"] = 24;
         }, 4, "multiple of 4"},
        {"mo_version", "gt_meshopt.glb", [&](json& j, std::vector<std::uint8_t>& bin) {
             bin[j["bufferViews"][0]["extensions"][mo]["byteOffset"].get<size_t>()] = 0xa1;
         }, 5, "meshopt codec version 1"},
        {"mo_range", "gt_meshopt.glb", [&](json& j, auto&) { j["bufferViews"][0]["extensions"][mo]["byteOffset"] = 100000; }, 4,
         "outside buffer"},
        {"draco_garbage", "gt_draco.glb", [&](json& j, std::vector<std::uint8_t>& bin) {
             const size_t off = j["bufferViews"][1].value("byteOffset", 0), len = j["bufferViews"][1]["byteLength"].get<size_t>();
             for (size_t i = off + 12; i < off + len; ++i) bin[i] = static_cast<std::uint8_t>(i * 97 + 3);
         }, 4, "Draco"},
        {"draco_count", "gt_draco.glb", [&](json& j, auto&) { j["accessors"][3]["count"] = 9; }, 4, "points"},
        {"draco_not_mesh", "gt_draco.glb", [&](json& j, std::vector<std::uint8_t>& bin) {
             bin[j["bufferViews"][0].value("byteOffset", 0) + 7] = 0;
         }, 5, "not a triangular mesh"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const std::string file = dir + "/" + c.name + ".glb";
        test::write_bytes(file, edit_glb(data(c.source), c.edit));
        expect_refused(file, c.exit_code, c.needle);
    }
    // The unedited round trip of edit_glb reads (the edits, not the rewrite, are refused).
    const std::string same = dir + "/same.glb";
    test::write_bytes(same, edit_glb(data("gt_meshopt.glb"), [](json&, auto&) {}));
    EXPECT_EQ(test::run_zhc({"bake", same, "-o", dir + "/same.json", "--quiet"}).exit_code, 0);
}

// KHR_meshopt_compression (the Khronos successor, same fields) read like EXT_: the glTF-Transform
// file with the extension renamed.
TEST(GltfInputs, KhrMeshoptNameReadLikeExt) {
    const std::string file = test::temp_dir("gltf_inputs_hostile") + "/khr_meshopt.glb";
    test::write_bytes(file, edit_glb(data("gt_meshopt.glb"), [](json& j, auto&) {
        std::string text = j.dump();
        for (size_t at; (at = text.find("EXT_meshopt_compression")) != std::string::npos;) text.replace(at, 3, "KHR");
        j = json::parse(text);
    }));
    EXPECT_EQ(max_diff(bake(file, "khr_meshopt"), bake(data("gt_list.glb"), "gt_list_khr")), 0.0);
}

// Probes baked into a copy of a compressed asset: the fallback buffer stays uri-less, the copy
// reads back (its own probes and, baked again, the same probes).
TEST(GltfInputs, BakeIntoCompressedAssetsRoundTrips) {
    const std::string dir = test::fresh_dir("gltf_inputs_embed");
    const auto reference = bake(data("gt_list.glb"), "gt_list_embed");
    for (const char* name : {"gt_meshopt.glb", "gt_draco.glb"})
        for (const char* ext : {".glb", ".gltf"}) {
            SCOPED_TRACE(std::string(name) + " -> " + ext);
            const std::string out = dir + "/" + name + ext;
            ASSERT_EQ(test::run_zhc({"bake", data(name), "-o", out, "--quiet"}).exit_code, 0);
            auto s = read_gltf_probes_file(out);
            ASSERT_TRUE(s.ok()) << s.error().message;
            ASSERT_EQ(s->volumes.size(), 1u);
            EXPECT_EQ(s->volumes[0].set.count, reference.size());
            EXPECT_EQ(max_diff(bake(out, std::string(name) + ext), reference), 0.0);
        }
}

// zhc bake IN.gltf -o OTHER/out.gltf|.glb: the output's image references resolve from its folder.
TEST(GltfInputs, OutputImagesResolveFromTheOutputFolder) {
    const std::string root = test::fresh_dir("gltf_inputs_out");
    fs::create_directories(root + "/in");
    fs::create_directories(root + "/other");
    for (const char* f : {"gt_list.gltf", "gt_list.bin", "tex.png"}) fs::copy_file(data(f), root + "/in/" + f);
    const std::vector<std::uint8_t> png = test::read_bytes(data("tex.png"));
    // .gltf elsewhere: the image becomes a data URI of the same bytes.
    ASSERT_EQ(test::run_zhc({"bake", root + "/in/gt_list.gltf", "-o", root + "/other/out.gltf", "--quiet"}).exit_code, 0);
    const json g = json::parse(test::read_bytes(root + "/other/out.gltf"));
    const std::string uri = g["images"][0]["uri"];
    EXPECT_EQ(uri.rfind("data:image/png;base64,", 0), 0u) << uri;
    // .gltf in the parent folder: a relative reference into in/.
    ASSERT_EQ(test::run_zhc({"bake", root + "/in/gt_list.gltf", "-o", root + "/up.gltf", "--quiet"}).exit_code, 0);
    EXPECT_EQ(json::parse(test::read_bytes(root + "/up.gltf"))["images"][0]["uri"], "in/tex.png");
    // .gltf next to the input: unchanged.
    ASSERT_EQ(test::run_zhc({"bake", root + "/in/gt_list.gltf", "-o", root + "/in/same.gltf", "--quiet"}).exit_code, 0);
    EXPECT_EQ(json::parse(test::read_bytes(root + "/in/same.gltf"))["images"][0]["uri"], "tex.png");
    // .glb elsewhere: the PNG's bytes in a bufferView of the binary chunk, with its MIME type.
    ASSERT_EQ(test::run_zhc({"bake", root + "/in/gt_list.gltf", "-o", root + "/other/out.glb", "--quiet"}).exit_code, 0);
    const std::vector<std::uint8_t> glb = test::read_bytes(root + "/other/out.glb");
    const std::uint32_t jlen = test::get32(glb, 12);
    const json j = json::parse(glb.begin() + 20, glb.begin() + 20 + jlen);
    ASSERT_TRUE(j["images"][0].contains("bufferView")) << j["images"][0].dump();
    EXPECT_FALSE(j["images"][0].contains("uri"));
    EXPECT_EQ(j["images"][0]["mimeType"], "image/png");
    const json& v = j["bufferViews"][j["images"][0]["bufferView"].get<size_t>()];
    const size_t off = 20 + jlen + 8 + v.value("byteOffset", size_t(0));
    ASSERT_EQ(v["byteLength"].get<size_t>(), png.size());
    EXPECT_TRUE(std::equal(png.begin(), png.end(), glb.begin() + static_cast<std::ptrdiff_t>(off)));
    // The outputs read back (zhc's own reader) with the probes embedded.
    for (const char* out : {"/other/out.gltf", "/up.gltf", "/other/out.glb"}) {
        auto s = read_gltf_probes_file(root + out);
        ASSERT_TRUE(s.ok()) << out << ": " << s.error().message;
        EXPECT_EQ(s->volumes.size(), 1u);
        EXPECT_EQ(s->images, 1u);
    }
    // A missing image cannot be carried over: exit 3 naming it, nothing written.
    fs::remove(root + "/in/tex.png");
    const auto r = test::run_zhc({"bake", root + "/in/gt_list.gltf", "-o", root + "/other/gone.glb", "--quiet"});
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find("'tex.png' not found"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(root + "/other/gone.glb"));
}

}  // namespace
}  // namespace zhc
