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

// The number of nodes of a .glb or .gltf file.
size_t gltf_node_count(const std::string& file) {
    const std::vector<std::uint8_t> b = test::read_bytes(file);
    const json j = test::get32(b, 0) == 0x46546C67 ? json::parse(b.begin() + 20, b.begin() + 20 + test::get32(b, 12)) : json::parse(b);
    return j["nodes"].size();
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

// An image URI that leaves the asset's folder ('..') is refused only where the image is read or
// embedded (an output in another folder), never by commands that do not read images: info, bake
// to .zhp/.json, and bake or embed into the input's own folder (the URI copied as it is).
TEST(GltfInputs, ImageUriOutsideTheFolderRefusedOnlyWhereRead) {
    const std::string root = test::fresh_dir("gltf_inputs_image_uri");
    fs::create_directories(root + "/asset");
    fs::create_directories(root + "/other");
    json doc = json::parse(test::read_bytes(data("gt_list.gltf")));
    ASSERT_TRUE(doc.contains("images"));
    doc["images"][0]["uri"] = "../tex.png";
    const std::string text = doc.dump();
    const std::string in = root + "/asset/scene.gltf";
    test::write_bytes(in, std::vector<std::uint8_t>(text.begin(), text.end()));
    fs::copy_file(data("gt_list.bin"), root + "/asset/gt_list.bin");
    fs::copy_file(data("tex.png"), root + "/tex.png");
    const auto info = test::run_zhc({"info", in});
    EXPECT_EQ(info.exit_code, 0) << info.err;
    EXPECT_EQ(max_diff(bake(in, "image_uri_up"), bake(data("gt_list.gltf"), "image_uri_reference")), 0.0);
    const auto zhp = test::run_zhc({"bake", in, "-o", root + "/out.zhp", "--quiet"});
    EXPECT_EQ(zhp.exit_code, 0) << zhp.err;
    // Into the input's folder: the reference is kept as written.
    const auto same = test::run_zhc({"bake", in, "-o", root + "/asset/same.gltf", "--quiet"});
    ASSERT_EQ(same.exit_code, 0) << same.err;
    EXPECT_EQ(json::parse(test::read_bytes(root + "/asset/same.gltf"))["images"][0]["uri"], "../tex.png");
    // Elsewhere the image would have to be read or re-referenced: refused (exit 4), naming it.
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"bake", in, "-o", root + "/other/out.glb", "--quiet"},
          std::vector<std::string>{"gltf", "embed", in, root + "/out.zhp", "-o", root + "/other/out.gltf"}}) {
        const auto r = test::run_zhc(args);
        EXPECT_EQ(r.exit_code, 4) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find("image '../tex.png'"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("images[0].uri"), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(root + "/other/out.glb"));
    EXPECT_FALSE(fs::exists(root + "/other/out.gltf"));
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

// gltf-pipeline's meshopt assets (tests/data/gltf/gltf-pipeline, written by gltfpack 0.16):
// meshopt-no-fallback's buffers[1] has neither a uri nor `"fallback": true` (both extensions make
// the flag optional). Every view of it carries the extension, so it needs no bytes: bake, info
// and gltf embed read it, and the bake is byte for byte that of the sibling meshopt-fallback,
// whose fallback file holds the uncompressed views. Independent check: that sibling with the
// compression extension removed from its views reads the fallback file's plain bytes, and gives
// the same triangles as the decoded views. The assets have no lights: the lit copies add a
// constant sky (extras.zhc), occluded by the two meshes, so the probes depend on the geometry.
TEST(GltfInputs, MeshoptPlaceholderWithoutFallbackFlag) {
    const std::string dir = test::fresh_dir("gltf_inputs_placeholder");
    for (const std::string ext : {"EXT", "KHR"}) {
        SCOPED_TRACE(ext);
        const std::string name = ext + "_meshopt_compression";
        const std::string src = data("gltf-pipeline/" + name + "/");
        const std::string no_fb = src + "meshopt-no-fallback/meshopt-no-fallback.gltf";
        const std::string fb = src + "meshopt-fallback/meshopt-fallback.gltf";
        const json doc = json::parse(test::read_bytes(no_fb));
        ASSERT_FALSE(doc["buffers"][1].contains("uri"));
        ASSERT_FALSE(doc["buffers"][1].contains("extensions"));  // no "fallback" flag
        const auto tris = triangles(scene_of(fb), 1e-9);
        EXPECT_EQ(tris.size(), 60u);  // a box (36 indices) and a 26-vertex solid above it (144)
        EXPECT_EQ(triangles(scene_of(no_fb), 1e-9), tris);
        // The fallback file's plain bytes (views without the extension) are the same triangles.
        const std::string plain_dir = dir + "/" + ext + "_plain";
        fs::create_directories(plain_dir);
        json plain = json::parse(test::read_bytes(fb));
        for (json& v : plain["bufferViews"]) v.erase("extensions");
        plain.erase("extensionsRequired");
        const std::string plain_text = plain.dump();
        test::write_bytes(plain_dir + "/plain.gltf", std::vector<std::uint8_t>(plain_text.begin(), plain_text.end()));
        for (const char* f : {"meshopt-fallback.bin", "meshopt-fallback.fallback.bin"})
            fs::copy_file(src + "meshopt-fallback/" + f, plain_dir + "/" + f, fs::copy_options::overwrite_existing);
        EXPECT_EQ(triangles(scene_of(plain_dir + "/plain.gltf"), 1e-9), tris);
        // Bake outputs byte for byte, as given (no lights) and lit by an occluded sky.
        auto out_bytes = [&](const std::string& in, const std::string& out) {
            const auto r = test::run_zhc({"bake", in, "-o", out, "--threads", "2", "--quiet"});
            EXPECT_EQ(r.exit_code, 0) << in << ": " << r.err;
            return test::read_bytes(out);
        };
        for (const char* o : {".zhp", ".json"})
            EXPECT_EQ(out_bytes(no_fb, dir + "/" + ext + "_nofb" + o), out_bytes(fb, dir + "/" + ext + "_fb" + o)) << o;
        std::vector<std::string> lit;
        for (const std::string variant : {"meshopt-no-fallback", "meshopt-fallback"}) {
            const std::string lit_dir = dir + "/" + ext + "_lit_" + variant;
            fs::create_directories(lit_dir);
            for (const auto& e : fs::directory_iterator(src + variant))
                fs::copy_file(e.path(), lit_dir + "/" + e.path().filename().string(), fs::copy_options::overwrite_existing);
            json j = json::parse(test::read_bytes(src + variant + "/" + variant + ".gltf"));
            j["extras"]["zhc"] = {{"sky", {{"type", "constant"}, {"radiance", 1.0}}}};
            const std::string text = j.dump();
            lit.push_back(lit_dir + "/" + variant + ".gltf");
            test::write_bytes(lit.back(), std::vector<std::uint8_t>(text.begin(), text.end()));
        }
        const auto lit_no_fb = bake(lit[0], ext + "_lit_nofb");
        EXPECT_EQ(out_bytes(lit[0], dir + "/" + ext + "_lit_nofb.zhp"), out_bytes(lit[1], dir + "/" + ext + "_lit_fb.zhp"));
        EXPECT_EQ(max_diff(lit_no_fb, bake(lit[1], ext + "_lit_fb")), 0.0);
        // Occlusion shaped the probes: an open sky of radiance 1 has L00 = 2 sqrt(pi) everywhere.
        double lo = INFINITY, hi = 0;
        for (const Sh3Radiance& p : lit_no_fb) {
            lo = std::min(lo, static_cast<double>(p.c[0].r));
            hi = std::max(hi, static_cast<double>(p.c[0].r));
        }
        EXPECT_GT(hi, 0.5);
        EXPECT_LT(lo, hi - 0.1);
        // info reads it; gltf embed writes it into .gltf and .glb, the placeholder staying uri-less.
        const auto info = test::run_zhc({"info", no_fb});
        EXPECT_EQ(info.exit_code, 0) << info.err;
        for (const char* o : {".gltf", ".glb"}) {
            SCOPED_TRACE(o);
            const std::string out = dir + "/" + ext + "_embedded" + o;
            const auto r = test::run_zhc({"gltf", "embed", no_fb, dir + "/" + ext + "_nofb.zhp", "-o", out});
            ASSERT_EQ(r.exit_code, 0) << r.err;
            auto s = read_gltf_probes_file(out);
            ASSERT_TRUE(s.ok()) << s.error().message;
            EXPECT_EQ(s->volumes.size(), 1u);
            EXPECT_EQ(triangles(scene_of(out), 1e-9), tris);
        }
    }
    // A uri-less buffer that a plain view reads still needs its bytes: refused, naming it.
    json bad = json::parse(test::read_bytes(data("gltf-pipeline/EXT_meshopt_compression/meshopt-no-fallback/meshopt-no-fallback.gltf")));
    bad["bufferViews"][2].erase("extensions");
    const std::string bad_dir = dir + "/plain_view";
    fs::create_directories(bad_dir);
    fs::copy_file(data("gltf-pipeline/EXT_meshopt_compression/meshopt-no-fallback/meshopt-no-fallback.bin"), bad_dir + "/meshopt-no-fallback.bin");
    const std::string bad_text = bad.dump();
    test::write_bytes(bad_dir + "/bad.gltf", std::vector<std::uint8_t>(bad_text.begin(), bad_text.end()));
    expect_refused(bad_dir + "/bad.gltf", 4, "buffers[1]: no uri");
    // So does one that is a compressed view's source.
    bad = json::parse(test::read_bytes(data("gltf-pipeline/EXT_meshopt_compression/meshopt-no-fallback/meshopt-no-fallback.gltf")));
    bad["bufferViews"][2]["extensions"]["EXT_meshopt_compression"]["buffer"] = 1;
    const std::string source_text = bad.dump();
    test::write_bytes(bad_dir + "/source.gltf", std::vector<std::uint8_t>(source_text.begin(), source_text.end()));
    expect_refused(bad_dir + "/source.gltf", 4, "buffers[1]: no uri");
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

// gltf embed onto an asset that already has a volume of the name it writes (zhc_probes): refused
// (exit 2, naming the volume, nothing written) unless --replace, which replaces that volume in
// place: still one volume, the same node referencing it, and extract returns the new probes;
// --name adds a volume of another name. A bake of an already baked asset replaces its volume.
TEST(GltfInputs, EmbedOntoAnExistingVolumeRefusedOrReplaced) {
    const std::string dir = test::fresh_dir("gltf_inputs_replace");
    ASSERT_EQ(test::run_zhc({"bake", data("gt_list.glb"), "-o", dir + "/lit.glb", "--quiet"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"bake", data("gt_list.glb"), "-o", dir + "/baked.zhp", "--quiet"}).exit_code, 0);
    // A second probe set: the same grid as zh3_q16.
    const auto conv = test::run_zhc({"convert", dir + "/baked.zhp", "-o", dir + "/other.zhp", "--to", "zh3_q16"});
    ASSERT_EQ(conv.exit_code, 0) << conv.err;
    const size_t nodes_before = gltf_node_count(dir + "/lit.glb");
    for (const char* out : {"/twice.glb", "/twice.gltf"}) {
        const auto r = test::run_zhc({"gltf", "embed", dir + "/lit.glb", dir + "/other.zhp", "-o", dir + out});
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find("volume named 'zhc_probes' (extensions.ZHC_light_probes.volumes[0])"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("--replace"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir + out));
    }
    auto other = read_probe_file(dir + "/other.zhp");
    ASSERT_TRUE(other.ok());
    // Another name adds a second volume, the first kept.
    const auto named = test::run_zhc({"gltf", "embed", dir + "/lit.glb", dir + "/other.zhp", "-o", dir + "/two.glb", "--name", "other"});
    ASSERT_EQ(named.exit_code, 0) << named.err;
    auto two = read_gltf_probes_file(dir + "/two.glb");
    ASSERT_TRUE(two.ok()) << two.error().message;
    ASSERT_EQ(two->volumes.size(), 2u);
    EXPECT_EQ(two->volumes[0].name, "zhc_probes");
    EXPECT_EQ(two->volumes[0].set.representation, "sh3");
    EXPECT_EQ(two->volumes[1].name, "other");
    EXPECT_EQ(two->volumes[1].set.payload, other->payload);
    for (const char* out : {"/replaced.glb", "/replaced.gltf"}) {
        SCOPED_TRACE(out);
        const auto r = test::run_zhc({"gltf", "embed", dir + "/lit.glb", dir + "/other.zhp", "-o", dir + out, "--replace"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        auto s = read_gltf_probes_file(dir + out);
        ASSERT_TRUE(s.ok()) << s.error().message;
        ASSERT_EQ(s->volumes.size(), 1u);
        EXPECT_EQ(s->volumes[0].name, "zhc_probes");
        EXPECT_EQ(s->volumes[0].set.representation, "zh3_q16");
        EXPECT_EQ(s->volumes[0].nodes.size(), 1u);
        const auto x = test::run_zhc({"gltf", "extract", dir + out, "-o", dir + out + ".zhp"});
        ASSERT_EQ(x.exit_code, 0) << x.err;
        auto back = read_probe_file(dir + out + ".zhp");
        ASSERT_TRUE(back.ok());
        EXPECT_EQ(back->representation, "zh3_q16");
        EXPECT_EQ(back->payload, other->payload);
        // The node count of the asset did not grow (the existing node references the new volume).
        EXPECT_EQ(gltf_node_count(dir + out), nodes_before);
    }
    // Re-baking a baked asset: one volume, the bake's.
    ASSERT_EQ(test::run_zhc({"bake", dir + "/lit.glb", "-o", dir + "/relit.glb", "--quiet"}).exit_code, 0);
    auto relit = read_gltf_probes_file(dir + "/relit.glb");
    ASSERT_TRUE(relit.ok()) << relit.error().message;
    EXPECT_EQ(relit->volumes.size(), 1u);
    EXPECT_EQ(max_diff(bake(dir + "/relit.glb", "relit"), bake(data("gt_list.glb"), "relit_reference")), 0.0);
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
