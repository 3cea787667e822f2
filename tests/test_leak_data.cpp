// Per-probe leak-avoidance data (ProbeSet::validity / ::visibility, codec/probe/probe_set.h)
// through the in-memory checks, convert_probe_set, the .zhp container (version 2 sections,
// docs/zhp-container.md) and `zhc convert` / `zhc info`:
//  * validate_probe_set: sizes (empty or count), values 0/1, visibility only with a grid;
//  * convert_probe_set and `zhc convert` keep both vectors (same and other representation);
//  * .zhp: a set without the data is written byte for byte as version 1 (the golden files of
//    test_container); with it, as version 2, round trip exact, a golden version 2 file;
//  * hostile version 2 files: every truncation, wrong section flags, values other than 0/1,
//    visibility without a grid, a version 1 file that claims sections -> distinct error codes,
//    and the CLI's documented exit codes for them;
//  * glTF ZHC_light_probes: validity / visibility accessors (UNSIGNED_BYTE SCALAR, one per probe,
//    glTF probe order, masks in the glTF grid's axes) written and read back to the same set, both
//    SH axes, GLB and .gltf; a mask that is one cell side maps to the same physical side; bad
//    accessors (values, counts, visibility without a grid) refused.
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <filesystem>
#include <string>
#include <vector>

#include "codec/probe/probe_set.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"
#include "support.h"

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace zhc {
namespace {

ProbeLayout grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz) {
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kGrid;
    l.grid.origin = {-1, 0.5, 2};
    l.grid.spacing = {0.5, 1, 0.25};
    l.grid.counts = {nx, ny, nz};
    return l;
}

std::vector<Sh3Radiance> probes(size_t n) {
    std::vector<Sh3Radiance> hub(n);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k)
                hub[i][c][k] = c == 0 ? float(1 + i + k) : float(0.1 * std::sin(double(i * 27 + size_t(c) * 3 + size_t(k))));
    return hub;
}

// A 3x2x2 grid with validity (two invalid probes) and a visibility mask per probe.
ProbeSet leak_set(const std::string& rep = "zh3_q16") {
    auto set = encode_probe_set(probes(12), rep, {}, grid(3, 2, 2));
    EXPECT_TRUE(set.ok());
    set->validity = {1, 1, 0, 1, 1, 1, 1, 0, 1, 1, 1, 1};
    set->visibility = {0xFF, 0x7F, 0x00, 0x80, 0x01, 0xAA, 0x55, 0xFE, 0xFF, 0x0F, 0xF0, 0x3C};
    return std::move(set).value();
}

ErrorCode code_of(const std::vector<std::uint8_t>& b) {
    auto r = parse_probe_set(b, "mem");
    return r.ok() ? ErrorCode::kInternal : r.error().code;
}

// Rewrites the body CRC after a body edit (uncompressed file).
std::vector<std::uint8_t> fix_body_crc(std::vector<std::uint8_t> b) {
    const std::uint32_t crc = crc32({b.data() + kProbeFileHeaderBytes, b.size() - kProbeFileHeaderBytes});
    return test::zhp_with_header_edit(b, 176, {std::uint8_t(crc), std::uint8_t(crc >> 8), std::uint8_t(crc >> 16),
                                                std::uint8_t(crc >> 24)});
}

TEST(LeakData, ValidationChecksSizesValuesAndLayout) {
    ProbeSet set = leak_set();
    EXPECT_TRUE(validate_probe_set(set).ok());
    auto broken = set;
    broken.validity.pop_back();
    ASSERT_FALSE(validate_probe_set(broken).ok());
    EXPECT_NE(validate_probe_set(broken).error().message.find("validity holds 11 bytes, expected 0 or 12"), std::string::npos);
    broken = set;
    broken.validity[4] = 2;
    ASSERT_FALSE(validate_probe_set(broken).ok());
    EXPECT_NE(validate_probe_set(broken).error().message.find("validity[4] is 2"), std::string::npos);
    broken = set;
    broken.visibility.push_back(0);
    EXPECT_FALSE(validate_probe_set(broken).ok());
    EXPECT_FALSE(decode_probe_set(broken).ok());
    // Visibility needs a grid; validity alone is fine for scattered probes.
    broken = set;
    broken.layout = {};
    EXPECT_FALSE(validate_probe_set(broken).ok());
    broken.visibility.clear();
    EXPECT_TRUE(validate_probe_set(broken).ok());
    // Either vector empty = absent.
    broken = set;
    broken.validity.clear();
    EXPECT_TRUE(validate_probe_set(broken).ok());
}

TEST(LeakData, ConvertKeepsValidityAndVisibility) {
    const ProbeSet set = leak_set("sh3");
    for (const char* rep : {"zh3_q16", "sh3_q28", "sh3"}) {
        auto out = convert_probe_set(set, rep, {});
        ASSERT_TRUE(out.ok()) << rep;
        EXPECT_EQ(out->validity, set.validity) << rep;
        EXPECT_EQ(out->visibility, set.visibility) << rep;
    }
}

TEST(LeakData, SetsWithoutTheDataStayVersion1ByteForByte) {
    ProbeSet set = leak_set();
    set.validity.clear();
    set.visibility.clear();
    const auto v1 = *serialize_probe_set(set);
    EXPECT_EQ(v1[8], 1);
    EXPECT_EQ(v1[21], 0);
    EXPECT_EQ(v1.size(), kProbeFileHeaderBytes + 12 * 16);
    auto back = parse_probe_set(v1, "mem");
    ASSERT_TRUE(back.ok());
    EXPECT_TRUE(back->validity.empty());
    EXPECT_TRUE(back->visibility.empty());
}

TEST(LeakData, Version2RoundTripsEverySectionCombinationAndCompression) {
    for (int sections = 1; sections <= 3; ++sections)
        for (int level : {0, 7}) {
            ProbeSet set = leak_set();
            if (!(sections & 1)) set.validity.clear();
            if (!(sections & 2)) set.visibility.clear();
            ProbeFileWriteOptions wo;
            wo.zstd_level = level;
            auto bytes = serialize_probe_set(set, wo);
            ASSERT_TRUE(bytes.ok());
            EXPECT_EQ((*bytes)[8], 2);
            EXPECT_EQ((*bytes)[21], sections);
            if (level == 0) {
                EXPECT_EQ(bytes->size(), kProbeFileHeaderBytes + 12 * 16 + set.validity.size() + set.visibility.size());
            }
            ProbeFileInfo info;
            auto back = parse_probe_set(*bytes, "mem", {}, &info);
            ASSERT_TRUE(back.ok()) << back.error().message;
            EXPECT_EQ(info.version, 2);
            EXPECT_EQ(back->payload, set.payload);
            EXPECT_EQ(back->validity, set.validity);
            EXPECT_EQ(back->visibility, set.visibility);
        }
    // Scattered probes with validity.
    auto pos = leak_set();
    pos.visibility.clear();
    pos.layout = {};
    pos.layout.kind = ProbeLayoutKind::kPositions;
    for (int i = 0; i < 12; ++i) pos.layout.positions.push_back({float(i), 1.0f, -1.0f});
    auto back = parse_probe_set(*serialize_probe_set(pos), "mem");
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->validity, pos.validity);
    EXPECT_EQ(back->layout.positions, pos.layout.positions);
}

TEST(LeakData, GoldenVersion2Container) {
    // Literal payload bytes (no encoder) so the file tests the container alone.
    ProbeSet set;
    set.representation = "zh3_q16";
    set.count = 6;
    set.layout = grid(3, 2, 1);
    for (std::uint64_t i = 0; i < set.count * 16; ++i) set.payload.push_back(static_cast<std::uint8_t>(i * 37 + 11));
    set.validity = {1, 0, 1, 1, 1, 0};
    set.visibility = {0xFF, 0x00, 0x0F, 0xF0, 0x81, 0x7E};
    const auto bytes = *serialize_probe_set(set);
    const std::string path = std::string(ZHC_GOLDEN_DIR) + "/container_v2_zh3_q16_grid_leak.zhp";
    if (const char* u = std::getenv("ZHC_UPDATE_GOLDEN"); u && std::string(u) == "1") test::write_bytes(path, bytes);
    ASSERT_TRUE(fs::exists(path)) << path << " missing (run with ZHC_UPDATE_GOLDEN=1)";
    EXPECT_EQ(test::read_bytes(path), bytes);
    // The sections are the last 12 bytes, validity first.
    const std::vector<std::uint8_t> tail(bytes.end() - 12, bytes.end());
    EXPECT_EQ(tail, (std::vector<std::uint8_t>{1, 0, 1, 1, 1, 0, 0xFF, 0x00, 0x0F, 0xF0, 0x81, 0x7E}));
}

TEST(LeakData, HostileVersion2FilesGetDistinctErrors) {
    const auto good = *serialize_probe_set(leak_set());
    EXPECT_EQ(code_of(good), ErrorCode::kInternal);
    // Every proper prefix is truncated, an extra byte is trailing.
    for (size_t n = 0; n < good.size(); ++n)
        EXPECT_EQ(code_of(std::vector<std::uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(n))), ErrorCode::kTruncated) << n;
    auto longer = good;
    longer.push_back(0);
    EXPECT_EQ(code_of(longer), ErrorCode::kTrailingBytes);
    // Section flags: unknown bits (a newer writer) unsupported; none in version 2, or any in version
    // 1, malformed; visibility and planes only with a grid layout.
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 21, {16})), ErrorCode::kUnsupported);
    // Bit 2 (cell planes) is known: declared without its 5 bytes per probe, the body size is wrong.
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 21, {7})), ErrorCode::kBadFormat);
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 21, {0x83})), ErrorCode::kUnsupported);
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 21, {0})), ErrorCode::kBadFormat);
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 8, {1, 0})), ErrorCode::kBadFormat);
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 8, {3, 0})), ErrorCode::kUnsupported);
    // Fewer sections than the body holds: the declared body size no longer matches (byte 160).
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 21, {1})), ErrorCode::kBadFormat);
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 21, {2})), ErrorCode::kBadFormat);
    // A body size that claims more (wrong size for the sections): refused before any allocation.
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 160, {0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0, 0})), ErrorCode::kBadFormat);
    {
        ProbeSet pos = leak_set();
        pos.visibility.clear();
        pos.layout = {};
        pos.layout.kind = ProbeLayoutKind::kPositions;
        for (int i = 0; i < 12; ++i) pos.layout.positions.push_back({0, 0, float(i)});
        auto bytes = *serialize_probe_set(pos);
        // Claiming a visibility section too (body size fixed up): visibility without a grid.
        auto bad = test::zhp_with_header_edit(bytes, 21, {3});
        bad.insert(bad.end(), 12, 0xFF);
        const std::uint64_t raw = bad.size() - kProbeFileHeaderBytes;
        bad = test::zhp_with_header_edit(bad, 160, {std::uint8_t(raw), std::uint8_t(raw >> 8), 0, 0, 0, 0, 0, 0});
        bad = test::zhp_with_header_edit(bad, 168, {std::uint8_t(raw), std::uint8_t(raw >> 8), 0, 0, 0, 0, 0, 0});
        bad = fix_body_crc(bad);
        EXPECT_EQ(code_of(bad), ErrorCode::kBadFormat);
    }
    // Validity values other than 0/1 (valid CRC): invalid value, naming the probe.
    for (std::uint8_t v : {std::uint8_t(2), std::uint8_t(0xFF)}) {
        auto bad = good;
        bad[kProbeFileHeaderBytes + 12 * 16 + 5] = v;
        bad = fix_body_crc(bad);
        auto r = parse_probe_set(bad, "f.zhp");
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidValue);
        EXPECT_NE(r.error().message.find("f.zhp: validity of probe 5 is " + std::to_string(v) + ", expected 0 or 1"),
                  std::string::npos)
            << r.error().message;
    }
    // Any visibility byte is a valid mask.
    auto any = good;
    any[good.size() - 1] ^= 0x5A;
    EXPECT_EQ(code_of(fix_body_crc(any)), ErrorCode::kInternal);
}

TEST(LeakData, CliConvertKeepsTheSectionsAndReportsBadFilesWithExitCodes) {
    const std::string dir = test::temp_dir("leak_data_cli");
    const ProbeSet set = leak_set("sh3");
    const std::string in = dir + "/in.zhp";
    ASSERT_TRUE(write_probe_file(in, set).ok());
    for (const char* rep : {"", "zh3_q16"}) {
        const std::string out = dir + "/out_" + std::string(*rep ? rep : "same") + ".zhp";
        std::vector<std::string> args = {"convert", in, "-o", out, "--zstd", "3"};
        if (*rep) args.insert(args.end(), {"--to", rep});
        auto r = test::run_zhc(args);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        auto back = read_probe_file(out);
        ASSERT_TRUE(back.ok()) << back.error().message;
        EXPECT_EQ(back->validity, set.validity) << rep;
        EXPECT_EQ(back->visibility, set.visibility) << rep;
    }
    // A bad validity byte: exit 4 with a one-line message naming the file; an unknown section flag
    // (a newer writer): exit 5.
    auto bad = *serialize_probe_set(leak_set());
    bad[kProbeFileHeaderBytes + 12 * 16] = 7;
    test::write_bytes(dir + "/bad.zhp", fix_body_crc(bad));
    auto r = test::run_zhc({"info", dir + "/bad.zhp"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_NE(r.err.find("bad.zhp: validity of probe 0 is 7"), std::string::npos) << r.err;
    test::write_bytes(dir + "/newer.zhp", test::zhp_with_header_edit(*serialize_probe_set(leak_set()), 21, {16}));
    r = test::run_zhc({"convert", dir + "/newer.zhp", "-o", dir + "/x.zhp"});
    EXPECT_EQ(r.exit_code, 5) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/x.zhp"));
}

// ---- glTF ---------------------------------------------------------------------------------------

std::vector<std::uint8_t> empty_gltf() {
    const std::string s = R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0})";
    return {s.begin(), s.end()};
}

TEST(LeakData, GltfAccessorsRoundTripEitherAxesAndContainer) {
    // 3x2x2: every axis has its own count, so a wrong probe order or bit permutation shows.
    for (GltfShAxes axes : {GltfShAxes::kZhc, GltfShAxes::kGltf})
        for (bool binary : {true, false}) {
            const ProbeSet set = leak_set("sh3");
            GltfEmbedOptions eo;
            eo.sh_axes = axes;
            eo.binary = binary;
            auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", set, eo);
            ASSERT_TRUE(bytes.ok()) << bytes.error().message;
            auto back = read_gltf_probes(*bytes, "out");
            ASSERT_TRUE(back.ok()) << back.error().message;
            ASSERT_EQ(back->volumes.size(), 1u);
            EXPECT_EQ(back->volumes[0].set.validity, set.validity);
            EXPECT_EQ(back->volumes[0].set.visibility, set.visibility);
            if (!binary) {
                const auto doc = nlohmann::json::parse(bytes->begin(), bytes->end());
                const auto& vol = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
                for (const char* key : {"validity", "visibility"}) {
                    const auto& acc = doc["accessors"][vol[key].get<size_t>()];
                    EXPECT_EQ(acc["componentType"], 5121) << key;
                    EXPECT_EQ(acc["type"], "SCALAR") << key;
                    EXPECT_EQ(acc["count"], 12) << key;
                }
            }
        }
    // Without the data: no keys.
    ProbeSet plain = leak_set();
    plain.validity.clear();
    plain.visibility.clear();
    GltfEmbedOptions eo;
    eo.binary = false;
    auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", plain, eo);
    ASSERT_TRUE(bytes.ok());
    const auto doc = nlohmann::json::parse(bytes->begin(), bytes->end());
    EXPECT_FALSE(doc["extensions"]["ZHC_light_probes"]["volumes"][0].contains("validity"));
    EXPECT_FALSE(doc["extensions"]["ZHC_light_probes"]["volumes"][0].contains("visibility"));
}

// In glTF, probe (gx, gy, gz) of the glTF grid is zhc probe (x, y, z) = (gz, gx, gy) and a mask bit
// names a cell side in glTF grid axes: zhc's +x side (bit 1) is glTF's +z side (bit 4).
TEST(LeakData, GltfMasksUseTheGltfGridAxes) {
    auto set = encode_probe_set(probes(12), "zh3_q16", {}, grid(3, 2, 2));
    ASSERT_TRUE(set.ok());
    set->visibility.assign(12, 0);
    set->visibility[1] = 0x01 | 0x02;  // zhc probe (1, 0, 0): sides (-,-,-) and (+x,-,-)
    set->visibility[3] = 0x04;         // zhc probe (0, 1, 0): side (-, +y, -), bit 2
    GltfEmbedOptions eo;  // GLB: the accessor bytes are in the BIN chunk (buffer 0)
    auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", *set, eo);
    ASSERT_TRUE(bytes.ok());
    auto le32 = [&](size_t at) {
        return std::uint32_t((*bytes)[at]) | std::uint32_t((*bytes)[at + 1]) << 8 | std::uint32_t((*bytes)[at + 2]) << 16 |
               std::uint32_t((*bytes)[at + 3]) << 24;
    };
    const std::uint32_t json_len = le32(12);
    const auto doc = nlohmann::json::parse(bytes->begin() + 20, bytes->begin() + 20 + json_len);
    const std::vector<std::uint8_t> raw(bytes->begin() + 28 + json_len, bytes->end());
    const auto& vol = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
    EXPECT_EQ(vol["grid"]["counts"], nlohmann::json({2, 2, 3}));  // glTF (ny, nz, nx)
    const auto& acc = doc["accessors"][vol["visibility"].get<size_t>()];
    const auto& view = doc["bufferViews"][acc["bufferView"].get<size_t>()];
    EXPECT_EQ(view["buffer"], 0);
    auto summary = read_gltf_probes(*bytes, "out");
    ASSERT_TRUE(summary.ok());
    EXPECT_EQ(summary->volumes[0].set.visibility, set->visibility);
    const std::size_t off = view["byteOffset"].get<size_t>() + acc.value("byteOffset", size_t(0));
    // zhc (1, 0, 0) -> glTF (gx, gy, gz) = (0, 0, 1): index 0 + 2 (0 + 2 * 1) = 4; bits: (-,-,-) stays 1,
    // zhc +x (bit 1) -> glTF +z (bit 4).
    EXPECT_EQ(raw[off + 4], 0x01 | 0x10);
    // zhc (0, 1, 0) -> glTF (1, 0, 0): index 1; zhc +y (bit 2) -> glTF +x (bit 1, value 2).
    EXPECT_EQ(raw[off + 1], 0x02);
    for (size_t i = 0; i < 12; ++i)
        if (i != 1 && i != 4) {
            EXPECT_EQ(raw[off + i], 0) << i;
        }
}

TEST(LeakData, GltfBadAccessorsAreRefused) {
    const ProbeSet set = leak_set();
    GltfEmbedOptions eo;
    eo.binary = false;
    const auto good = *embed_probes_gltf(empty_gltf(), "in.gltf", set, eo);
    const auto doc = nlohmann::json::parse(good.begin(), good.end());
    auto code_with = [&](const std::function<void(nlohmann::json&)>& edit) {
        nlohmann::json d = doc;
        edit(d);
        const std::string text = d.dump();
        auto r = read_gltf_probes(std::vector<std::uint8_t>(text.begin(), text.end()), "x.gltf");
        return r.ok() ? ErrorCode::kInternal : r.error().code;
    };
    EXPECT_EQ(code_with([](nlohmann::json&) {}), ErrorCode::kInternal);
    auto& vol0 = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
    const size_t va = vol0["validity"], vi = vol0["visibility"], co = vol0["coefficients"];
    // Wrong count, wrong type, index out of range, the coefficients accessor as validity (count).
    EXPECT_EQ(code_with([&](nlohmann::json& d) { d["accessors"][va]["count"] = 11; }), ErrorCode::kBadFormat);
    EXPECT_EQ(code_with([&](nlohmann::json& d) { d["accessors"][vi]["type"] = "VEC2"; }), ErrorCode::kBadFormat);
    EXPECT_EQ(code_with([&](nlohmann::json& d) { d["extensions"]["ZHC_light_probes"]["volumes"][0]["validity"] = 999; }),
              ErrorCode::kBadFormat);
    EXPECT_EQ(code_with([&](nlohmann::json& d) { d["extensions"]["ZHC_light_probes"]["volumes"][0]["validity"] = co; }),
              ErrorCode::kBadFormat);
    // A value other than 0/1: the validity accessor pointed at the visibility bytes (0xFF, 0x7F, ...).
    EXPECT_EQ(code_with([&](nlohmann::json& d) { d["extensions"]["ZHC_light_probes"]["volumes"][0]["validity"] = vi; }),
              ErrorCode::kInvalidValue);
    // Visibility on a non-grid volume.
    ProbeSet pos = leak_set();
    pos.visibility.clear();
    pos.layout = {};
    auto pb = *embed_probes_gltf(empty_gltf(), "in.gltf", pos, eo);
    auto pd = nlohmann::json::parse(pb.begin(), pb.end());
    pd["extensions"]["ZHC_light_probes"]["volumes"][0]["visibility"] = pd["extensions"]["ZHC_light_probes"]["volumes"][0]["validity"];
    const std::string text = pd.dump();
    auto r = read_gltf_probes(std::vector<std::uint8_t>(text.begin(), text.end()), "x.gltf");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kBadFormat);
    EXPECT_NE(r.error().message.find("visibility needs layout grid"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace zhc
