// ZHC_light_probes (formats/probes/gltf_probes.h): the Draco point-cloud payload (order, losslessness,
// size, header checked before decoding), hostile inputs (URIs, sizes, indices, GLB framing) and the
// CLI verbs embed/extract/eval/info (helpers: gltf_helpers.h).
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
    const std::string dir = test::fresh_dir("gltf_hostile");  // emptied: the symlink below is made anew every run
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
    ASSERT_FALSE(ec) << "cannot create a symbolic link in " << dir << ": " << ec.message();
    {
        json doc = base;
        doc["buffers"][0]["uri"] = "link.bin";
        doc["buffers"][0]["byteLength"] = 36;
        expect_rejected(text_bytes(doc), dir + "/inner/scene.gltf", ErrorCode::kBadFormat, "outside the input's directory");
    }
    // Images are never read nor decoded by the reader (garbage PNG bytes are fine, and a URI that
    // leaves the folder is not followed); embedding into another folder, which reads or
    // re-references them, checks the URI like a buffer's.
    json doc = base;
    doc["images"] = json::array({json{{"uri", "../secret.bin"}}});
    EXPECT_TRUE(read_gltf_probes(text_bytes(doc), dir + "/inner/scene.gltf"));
    for (const std::string uri : {"../secret.bin", "%2e%2e/secret.bin", "/etc/passwd", "file:///etc/passwd", "..\\secret.bin"}) {
        doc["images"][0]["uri"] = uri;
        GltfEmbedOptions eo;
        eo.output_path = dir + "/out.glb";  // not inner/
        auto r = embed_probes_gltf(text_bytes(doc), dir + "/inner/scene.gltf", scattered_set(4, "sh3"), eo);
        ASSERT_FALSE(r) << uri;
        EXPECT_EQ(r.error().code, ErrorCode::kBadFormat) << r.error().message;
        EXPECT_NE(r.error().message.find("images[0].uri"), std::string::npos) << r.error().message;
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    }
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
