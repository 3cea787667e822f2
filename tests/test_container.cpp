// The probe set (codec/probe/probe_set.h), the .zhp container and the JSON probe list
// (formats/probes/probe_file.h), and the convert/info verbs: round trips, strict decoding (every
// truncation, every bit flip, trailing bytes, limits, unknown versions), golden container bytes,
// determinism, and CLI behaviour including error paths and atomic outputs.
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "codec/probe/probe_set.h"
#include "formats/io/file_io.h"
#include "formats/probes/probe_file.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;

// Probes from an analytic family: sky-ish lobes varying smoothly over a grid (non-negative).
std::vector<Sh3Radiance> grid_probes(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz) {
    std::vector<Sh3Radiance> out;
    for (std::uint32_t z = 0; z < nz; ++z)
        for (std::uint32_t y = 0; y < ny; ++y)
            for (std::uint32_t x = 0; x < nx; ++x) {
                const Vec3 a = normalize_or({std::cos(0.3 * x), std::sin(0.2 * y), 0.5 + 0.1 * z}, {0, 0, 1});
                Sh3Radiance sh = project_cone(a, 0.2 + 0.05 * (x % 7), {2.0f, 1.5f, 1.0f});
                sh = sh + project_constant({0.1f + 0.01f * y, 0.2f, 0.3f + 0.02f * z});
                out.push_back(sh);
            }
    return out;
}

ProbeLayout grid_layout(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz) {
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kGrid;
    l.grid.origin = {-1.5, 0.25, 3};
    l.grid.spacing = {0.5, 0.5, 1.25};
    l.grid.counts = {nx, ny, nz};
    return l;
}

ProbeSet make_set(const std::string& rep, ProbeLayoutKind kind, int n = 12) {
    std::vector<Sh3Radiance> hub = grid_probes(static_cast<std::uint32_t>(n), 1, 1);
    ProbeLayout l;
    l.kind = kind;
    if (kind == ProbeLayoutKind::kGrid) l = grid_layout(static_cast<std::uint32_t>(n), 1, 1);
    if (kind == ProbeLayoutKind::kPositions)
        for (int i = 0; i < n; ++i) l.positions.push_back({float(i), float(-i) * 0.5f, 2.0f});
    auto set = encode_probe_set(hub, rep, {}, l);
    EXPECT_TRUE(set.ok()) << (set.ok() ? "" : set.error().message);
    return std::move(set).value();
}

void expect_same_set(const ProbeSet& a, const ProbeSet& b) {
    EXPECT_EQ(a.representation, b.representation);
    EXPECT_EQ(a.count, b.count);
    EXPECT_EQ(a.payload, b.payload);
    EXPECT_EQ(a.layout.kind, b.layout.kind);
    EXPECT_EQ(a.layout.positions, b.layout.positions);
    EXPECT_EQ(a.layout.grid.counts, b.layout.grid.counts);
    EXPECT_EQ(a.layout.grid.origin.x, b.layout.grid.origin.x);
    EXPECT_EQ(a.layout.grid.spacing.z, b.layout.grid.spacing.z);
    EXPECT_EQ(a.params.bits, b.params.bits);
    EXPECT_EQ(a.params.sqrt_encoding, b.params.sqrt_encoding);
    EXPECT_EQ(a.params.l2_bound, b.params.l2_bound);
    EXPECT_EQ(a.params.dc_format, b.params.dc_format);
    EXPECT_EQ(a.params.kind, b.params.kind);
    EXPECT_EQ(a.params.zonal_mapping, b.params.zonal_mapping);
    EXPECT_EQ(a.params.axis_mode, b.params.axis_mode);
    EXPECT_EQ(a.params.luminance.g, b.params.luminance.g);
}

// ---- ProbeSet ---------------------------------------------------------------------------------

TEST(ProbeSet, EncodeDecodeConvertAndPositions) {
    const auto hub = grid_probes(4, 3, 2);
    auto set = encode_probe_set(hub, "sh3", {}, grid_layout(4, 3, 2));
    ASSERT_TRUE(set.ok());
    EXPECT_EQ(set->payload.size(), 24u * 108u);
    auto back = decode_probe_set(*set);
    ASSERT_TRUE(back.ok());
    for (size_t i = 0; i < hub.size(); ++i) EXPECT_EQ((*back)[i], hub[i]);  // float hub: exact
    // Probe (x, y, z) = (3, 2, 1) is index 3 + 4 (2 + 3 * 1) = 23.
    const Vec3 p = probe_position(*set, 23);
    EXPECT_DOUBLE_EQ(p.x, -1.5 + 3 * 0.5);
    EXPECT_DOUBLE_EQ(p.y, 0.25 + 2 * 0.5);
    EXPECT_DOUBLE_EQ(p.z, 3 + 1 * 1.25);
    // Conversion to zh3_q16 keeps layout and gives 16 bytes per probe; equals direct encoding.
    auto q = convert_probe_set(*set, "zh3_q16", {});
    ASSERT_TRUE(q.ok());
    EXPECT_EQ(q->payload.size(), 24u * 16u);
    auto direct = encode_probe_set(hub, "zh3_q16", {}, grid_layout(4, 3, 2));
    EXPECT_EQ(q->payload, direct->payload);
    EXPECT_EQ(q->layout.grid.counts, set->layout.grid.counts);
    // Irradiance-stored sets decode back to the same radiance hub (float reps: up to rounding).
    CodecOptions irr;
    irr.kind = StoredKind::kIrradiance;
    auto e = encode_probe_set(hub, "sh3", irr, {});
    auto eb = decode_probe_set(*e);
    for (size_t i = 0; i < hub.size(); ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR((*eb)[i][c][k], hub[i][c][k], 1e-6 * (1 + std::fabs(hub[i][c][k])));
    // Quantised, irradiance-scaled bounds: decodes to the radiance hub within the quantisation.
    auto qi = encode_probe_set(hub, "sh3_q28", irr, {});
    auto qib = decode_probe_set(*qi);
    auto qr = decode_probe_set(*encode_probe_set(hub, "sh3_q28", {}, {}));
    for (size_t i = 0; i < hub.size(); ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR((*qib)[i][c][k], (*qr)[i][c][k], 1e-5 + 0.02 * std::fabs(hub[i][0][k]));
}

TEST(ProbeSet, ValidationNamesTheBrokenInvariant) {
    const auto hub = grid_probes(3, 1, 1);
    EXPECT_EQ(encode_probe_set(hub, "nope", {}, {}).error().code, ErrorCode::kInvalidArgument);
    EXPECT_FALSE(encode_probe_set(hub, "sh3", {}, grid_layout(2, 1, 1)).ok());  // 2 != 3
    CodecOptions half;
    half.dc_format = DcFormat::kHalf;
    EXPECT_FALSE(encode_probe_set(hub, "zh3_q16", half, {}).ok());
    EXPECT_TRUE(encode_probe_set(hub, "sh2_q", half, {}).ok());
    ProbeLayout pos;
    pos.kind = ProbeLayoutKind::kPositions;
    pos.positions = {{0, 0, 0}, {1, 1, 1}, {NAN, 0, 0}};
    EXPECT_FALSE(encode_probe_set(hub, "sh3", {}, pos).ok());
    ProbeSet set = make_set("sh3", ProbeLayoutKind::kNone, 3);
    set.payload.pop_back();
    EXPECT_FALSE(validate_probe_set(set).ok());
    EXPECT_FALSE(decode_probe_set(set).ok());
}

// ---- .zhp container -----------------------------------------------------------------------------

TEST(ProbeFile, RoundTripsEveryLayoutRepresentationAndCompression) {
    for (const char* rep : {"sh3", "zh3_q16", "sh3_q28", "sh2_q", "zh3_lum"})
        for (ProbeLayoutKind kind : {ProbeLayoutKind::kNone, ProbeLayoutKind::kGrid, ProbeLayoutKind::kPositions})
            for (int level : {0, 3}) {
                const ProbeSet set = make_set(rep, kind);
                ProbeFileWriteOptions wo;
                wo.zstd_level = level;
                auto bytes = serialize_probe_set(set, wo);
                ASSERT_TRUE(bytes.ok()) << bytes.error().message;
                if (level == 0) {
                    EXPECT_EQ(bytes->size(), kProbeFileHeaderBytes + set.payload.size() +
                                                 (kind == ProbeLayoutKind::kPositions ? 12 * set.count : 0));
                }
                ProbeFileInfo info;
                auto back = parse_probe_set(*bytes, "mem", {}, &info);
                ASSERT_TRUE(back.ok()) << back.error().message;
                expect_same_set(set, *back);
                EXPECT_EQ(info.compressed, level > 0);
                // Deterministic: the same set serialises to the same bytes.
                EXPECT_EQ(*serialize_probe_set(*back, wo), *bytes);
            }
    // Non-default parameters round-trip through the header.
    CodecOptions p;
    p.bits = 5;
    p.sqrt_encoding = true;
    p.l2_bound = L2Bound::kLoose;
    p.dc_format = DcFormat::kRGB9E5;
    p.kind = StoredKind::kIrradiance;
    p.zonal_mapping = ZonalMapping::kSymmetric;
    p.axis_mode = ZonalAxisMode::kPerChannel;
    p.luminance = {0.3, 0.59, 0.11};
    auto set = encode_probe_set(grid_probes(5, 1, 1), "zh3_q16", p, {});
    auto back = parse_probe_set(*serialize_probe_set(*set), "mem");
    ASSERT_TRUE(back.ok());
    expect_same_set(*set, *back);
}

TEST(ProbeFile, EveryTruncationIsTruncatedAndTrailingBytesAreRejected) {
    for (int level : {0, 5}) {
        ProbeFileWriteOptions wo;
        wo.zstd_level = level;
        const auto bytes = *serialize_probe_set(make_set("zh3_q16", ProbeLayoutKind::kPositions), wo);
        for (size_t n = 0; n < bytes.size(); ++n) {
            auto r = parse_probe_set({bytes.data(), n}, "mem");
            ASSERT_FALSE(r.ok()) << n;
            EXPECT_EQ(r.error().code, ErrorCode::kTruncated) << "prefix " << n << ": " << r.error().message;
        }
        for (size_t extra : {1, 7, 1000}) {
            auto longer = bytes;
            longer.insert(longer.end(), extra, 0);
            auto r = parse_probe_set(longer, "mem");
            ASSERT_FALSE(r.ok());
            EXPECT_EQ(r.error().code, ErrorCode::kTrailingBytes) << r.error().message;
        }
    }
}

TEST(ProbeFile, EveryBitFlipIsRejectedWithTheRightError) {
    for (int level : {0, 5}) {
        ProbeFileWriteOptions wo;
        wo.zstd_level = level;
        const auto bytes = *serialize_probe_set(make_set("sh3_q28", ProbeLayoutKind::kGrid), wo);
        for (size_t i = 0; i < bytes.size(); ++i)
            for (int bit = 0; bit < 8; ++bit) {
                auto bad = bytes;
                bad[i] ^= static_cast<std::uint8_t>(1u << bit);
                auto r = parse_probe_set(bad, "mem");
                ASSERT_FALSE(r.ok()) << "byte " << i << " bit " << bit;
                // Magic -> not ours; version -> unsupported; anything else -> a checksum.
                const ErrorCode want = i < 8 ? ErrorCode::kBadFormat : (i < 10 ? ErrorCode::kUnsupported : ErrorCode::kChecksum);
                EXPECT_EQ(r.error().code, want) << "byte " << i << " bit " << bit << ": " << r.error().message;
            }
    }
}

TEST(ProbeFile, FieldChecksHaveDistinctErrors) {
    const auto good = *serialize_probe_set(make_set("zh3_q16", ProbeLayoutKind::kGrid));
    auto code_of = [](const std::vector<std::uint8_t>& b, const ProbeFileLimits& lim = {}) {
        auto r = parse_probe_set(b, "mem", lim);
        return r.ok() ? ErrorCode::kInternal : r.error().code;
    };
    EXPECT_EQ(code_of(good), ErrorCode::kInternal);  // i.e. it parses
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 8, {3, 0})), ErrorCode::kUnsupported);       // version 3
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 8, {2, 0})), ErrorCode::kBadFormat);  // 2 without sections
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 24, {'z', 'h', '9'})), ErrorCode::kUnsupported);  // unknown rep
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 14, {7})), ErrorCode::kUnsupported);         // DC format 7
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 19, {2})), ErrorCode::kUnsupported);         // compression 2
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 13, {9})), ErrorCode::kBadFormat);           // bits 9
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 21, {1})), ErrorCode::kBadFormat);           // reserved
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 64, {28})), ErrorCode::kBadFormat);          // probe size
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 144, {13})), ErrorCode::kBadFormat);         // grid != count
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 10, {183})), ErrorCode::kBadFormat);         // header size
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 96, {0, 0, 0, 0, 0, 0, 0xF0, 0x7F})), ErrorCode::kInvalidValue);  // Inf
    // Count above the limit: kTooLarge, checked before any allocation.
    ProbeFileLimits small;
    small.max_probes = 5;
    EXPECT_EQ(code_of(good, small), ErrorCode::kTooLarge);
    ProbeFileLimits tiny_body;
    tiny_body.max_body_bytes = 100;
    EXPECT_EQ(code_of(good, tiny_body), ErrorCode::kTooLarge);
    // A huge declared count (2^60) with everything else consistent is refused by the limit.
    EXPECT_EQ(code_of(test::zhp_with_header_edit(good, 56, {0, 0, 0, 0, 0, 0, 0, 0x10})), ErrorCode::kTooLarge);
    // Not a .zhp at all; empty.
    EXPECT_EQ(code_of({'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd'}), ErrorCode::kBadFormat);
    EXPECT_EQ(code_of({}), ErrorCode::kTruncated);
    // A damaged zstd body with a matching CRC: kBadFormat from the decompressor checks.
    ProbeFileWriteOptions wo;
    wo.zstd_level = 3;
    auto z = *serialize_probe_set(make_set("zh3_q16", ProbeLayoutKind::kGrid), wo);
    z[kProbeFileHeaderBytes + 1] ^= 0xFF;
    const std::uint32_t crc = crc32({z.data() + kProbeFileHeaderBytes, z.size() - kProbeFileHeaderBytes});
    z = test::zhp_with_header_edit(z, 176, {std::uint8_t(crc), std::uint8_t(crc >> 8), std::uint8_t(crc >> 16), std::uint8_t(crc >> 24)});
    EXPECT_EQ(code_of(z), ErrorCode::kBadFormat);
}

TEST(ProbeFile, Crc32MatchesTheStandardCheckValue) {
    const std::string s = "123456789";
    EXPECT_EQ(crc32({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}), 0xCBF43926u);
}

TEST(ProbeFile, RandomBytesNeverCrash) {
    std::mt19937 rng(9);
    const auto good = *serialize_probe_set(make_set("zh3_q16", ProbeLayoutKind::kPositions));
    for (int trial = 0; trial < 3000; ++trial) {
        auto b = good;
        const int edits = 1 + trial % 8;
        for (int e = 0; e < edits; ++e) b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
        if (trial % 3 == 0) b.resize(rng() % (b.size() + 1));
        (void)parse_probe_set(b, "mem");
    }
}

// ---- golden container bytes ---------------------------------------------------------------------

std::string golden_dir() { return std::string(ZHC_GOLDEN_DIR); }

void expect_golden(const std::string& name, const std::vector<std::uint8_t>& bytes) {
    const std::string path = golden_dir() + "/" + name;
    if (const char* u = std::getenv("ZHC_UPDATE_GOLDEN"); u && std::string(u) == "1") {
        fs::create_directories(golden_dir());
        test::write_bytes(path, bytes);
        return;
    }
    ASSERT_TRUE(fs::exists(path)) << path << " missing (run with ZHC_UPDATE_GOLDEN=1)";
    EXPECT_EQ(test::read_bytes(path), bytes) << name;
    // And the committed file parses and re-serialises to itself.
    auto set = parse_probe_set(bytes, name);
    ASSERT_TRUE(set.ok()) << set.error().message;
}

TEST(ProbeFile, GoldenContainerBytesVersion1) {
    // Payload built from literal bytes (not from an encoder) so the file tests the container alone.
    ProbeSet set;
    set.representation = "zh3_q16";
    set.count = 6;
    set.layout = grid_layout(3, 2, 1);
    for (std::uint64_t i = 0; i < set.count * 16; ++i) set.payload.push_back(static_cast<std::uint8_t>(i * 37 + 11));
    expect_golden("container_v1_zh3_q16_grid.zhp", *serialize_probe_set(set));
    set.layout = {};
    set.layout.kind = ProbeLayoutKind::kPositions;
    for (std::uint64_t i = 0; i < set.count; ++i) set.layout.positions.push_back({float(i), 0.5f, -2.25f});
    set.params.sqrt_encoding = true;
    set.params.bits = 7;
    expect_golden("container_v1_zh3_q16_positions_sqrt7.zhp", *serialize_probe_set(set));
    // zstd output is specified by the zstd version (Debian 12: 1.5.4); the decoder accepts any.
    ProbeFileWriteOptions wo;
    wo.zstd_level = 19;
    expect_golden("container_v1_zh3_q16_positions_zstd19.zhp", *serialize_probe_set(set, wo));
}

// ---- JSON probe list ----------------------------------------------------------------------------

std::span<const std::uint8_t> as_bytes(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(ProbeJson, RoundTripsExactlyAndChecksTheSchema) {
    ProbeList list;
    list.probes = grid_probes(3, 2, 1);
    list.layout = grid_layout(3, 2, 1);
    const std::string text = probe_json(list);
    auto back = parse_probe_json(as_bytes(text), "mem");
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_EQ(back->probes.size(), list.probes.size());
    for (size_t i = 0; i < list.probes.size(); ++i) EXPECT_EQ(back->probes[i], list.probes[i]);  // floats exact
    EXPECT_EQ(back->layout.kind, ProbeLayoutKind::kGrid);
    EXPECT_EQ(back->layout.grid.counts, list.layout.grid.counts);
    // Minimal form, positions inferred; irradiance converted to radiance.
    const std::string minimal =
        R"({"kind":"irradiance","probes":[{"position":[1,2,3],"sh3":[[1,1,1],[0.5,0,0],[0,0,0],[0,0,0],[0.25,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0]]}]})";
    auto m = parse_probe_json(as_bytes(minimal), "mem");
    ASSERT_TRUE(m.ok()) << m.error().message;
    EXPECT_EQ(m->layout.kind, ProbeLayoutKind::kPositions);
    EXPECT_FLOAT_EQ(m->probes[0][1].r, 0.75f);  // 0.5 / (2/3)
    EXPECT_FLOAT_EQ(m->probes[0][4].r, 1.0f);   // 0.25 / (1/4)
    EXPECT_EQ(m->layout.positions[0][2], 3.0f);
    // Errors.
    auto code = [](const std::string& s) {
        auto r = parse_probe_json(as_bytes(s), "mem");
        return r.ok() ? ErrorCode::kInternal : r.error().code;
    };
    EXPECT_EQ(code("{"), ErrorCode::kBadFormat);
    EXPECT_EQ(code("[]"), ErrorCode::kBadFormat);
    EXPECT_EQ(code(R"({"probes":[{"sh3":[[1,1,1]]}]})"), ErrorCode::kBadFormat);
    EXPECT_EQ(code(R"({"probes":[{"sh3":"x"}]})"), ErrorCode::kBadFormat);
    EXPECT_EQ(code(R"({"version":2,"probes":[]})"), ErrorCode::kUnsupported);
    EXPECT_EQ(code(R"({"layout":{"type":"grid","origin":[0,0,0],"spacing":[1,1,1],"counts":[2,1,1]},"probes":[]})"),
              ErrorCode::kBadFormat);
    EXPECT_EQ(code(R"({"probes":[{"sh3":[[1e39,1,1],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0]]}]})"),
              ErrorCode::kInvalidValue);
    // Positions must fit a float too (a fuzzer's 160-digit position became inf), and irradiance
    // must still fit once converted to radiance (L2 x 4).
    EXPECT_EQ(code(R"({"probes":[{"position":[1,2,1e39],"sh3":[[1,1,1],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0]]}]})"),
              ErrorCode::kInvalidValue);
    EXPECT_EQ(code(R"({"kind":"irradiance","probes":[{"sh3":[[1,1,1],[0,0,0],[0,0,0],[0,0,0],[1e38,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0]]}]})"),
              ErrorCode::kInvalidValue);
    ProbeJsonLimits lim;
    lim.max_probes = 2;
    EXPECT_EQ(parse_probe_json(as_bytes(text), "mem", lim).error().code, ErrorCode::kTooLarge);
    // Deep nesting does not crash (nlohmann's parser is iterative).
    EXPECT_EQ(code("{\"probes\":" + std::string(100000, '[') + std::string(100000, ']') + "}"), ErrorCode::kBadFormat);
}

// ---- CLI ------------------------------------------------------------------------------------------

// JSON cannot hold NaN/Inf: write_probe_json refuses such a probe (kInvalidValue, naming the file)
// and leaves no file; the verbs refuse such input earlier, so this is the library's own guard.
TEST(ProbeJson, WriteRefusesNonFiniteProbesAndWritesNothing) {
    const std::string dir = test::temp_dir("probe_json_write_nan");
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        ProbeList list;
        list.probes = grid_probes(2, 1, 1);
        list.layout = grid_layout(2, 1, 1);
        list.probes[1][4].g = bad;
        const std::string path = dir + "/bad.json";
        const Status st = write_probe_json(path, list);
        ASSERT_FALSE(st.ok());
        EXPECT_EQ(st.error().code, ErrorCode::kInvalidValue);
        EXPECT_NE(st.error().message.find(path), std::string::npos) << st.error().message;
        EXPECT_FALSE(fs::exists(path));
    }
}

TEST(CliConvert, GridSh3ToZh3Q16AndBackAndInfo) {
    const std::string dir = test::temp_dir("container_cli");
    const std::uint32_t nx = 16, ny = 16, nz = 16;  // 4096 probes (the report measures 100k once)
    ProbeList list;
    list.probes = grid_probes(nx, ny, nz);
    list.layout = grid_layout(nx, ny, nz);
    const std::string json = dir + "/grid.json", sh3 = dir + "/grid_sh3.zhp", q16 = dir + "/grid_q16.zhp",
                      back = dir + "/grid_back.zhp", back_json = dir + "/grid_back.json";
    ASSERT_TRUE(write_probe_json(json, list).ok());
    auto r = test::run_zhc({"convert", json, "-o", sh3, "--to", "sh3"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"convert", sh3, "-o", q16, "--to", "zh3_q16"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const size_t n = size_t(nx) * ny * nz;
    EXPECT_EQ(fs::file_size(q16), kProbeFileHeaderBytes + 16 * n);  // 16 bytes/probe + header
    EXPECT_EQ(fs::file_size(sh3), kProbeFileHeaderBytes + 108 * n);
    r = test::run_zhc({"convert", q16, "-o", back, "--to", "sh3", "--zstd", "9"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"info", q16, "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["representation"], "zh3_q16");
    EXPECT_EQ(j["probes"], n);
    EXPECT_EQ(j["bytes_per_probe"], 16);
    EXPECT_EQ(j["file_bytes"], kProbeFileHeaderBytes + 16 * n);
    EXPECT_EQ(j["layout"]["counts"][2], nz);
    EXPECT_EQ(j["non_finite_probes"], 0);
    r = test::run_zhc({"info", back});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("zstd"), std::string::npos);
    // The CLI result equals the library conversion, and the round trip is zh3_q16's decode.
    auto lib = encode_probe_set(list.probes, "zh3_q16", {}, list.layout);
    auto file = read_probe_file(q16);
    ASSERT_TRUE(file.ok());
    EXPECT_EQ(file->payload, lib->payload);
    r = test::run_zhc({"convert", back, "-o", back_json});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto bj = read_probe_json(back_json);
    auto decoded = decode_probe_set(*lib);
    ASSERT_TRUE(bj.ok());
    for (size_t i = 0; i < n; i += 97) EXPECT_EQ(bj->probes[i], (*decoded)[i]);
    // Same representation, no flags: bytes are kept (recompression does not re-quantise).
    const std::string q16z = dir + "/grid_q16z.zhp";
    r = test::run_zhc({"convert", q16, "-o", q16z, "--zstd", "3"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(read_probe_file(q16z)->payload, file->payload);
    // Determinism: the same command twice gives the same bytes.
    const std::string again = dir + "/grid_q16_again.zhp";
    ASSERT_EQ(test::run_zhc({"convert", sh3, "-o", again, "--to", "zh3_q16"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(again), test::read_bytes(q16));
}

TEST(CliConvert, EnvmapInputAndOptions) {
    const std::string dir = test::temp_dir("container_cli_env");
    const std::string map = test::envmap_paths()[0];
    const std::string out = dir + "/one.zhp";
    auto r = test::run_zhc({"convert", map, "-o", out, "--to", "sh3_q28", "--sqrt", "--bits", "6", "--bound", "loose",
                            "--dc", "rgb9e5", "--irradiance"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto set = read_probe_file(out);
    ASSERT_TRUE(set.ok());
    EXPECT_EQ(set->count, 1u);
    EXPECT_TRUE(set->params.sqrt_encoding);
    EXPECT_EQ(set->params.bits, 6);
    EXPECT_EQ(set->params.l2_bound, L2Bound::kLoose);
    EXPECT_EQ(set->params.dc_format, DcFormat::kRGB9E5);
    EXPECT_EQ(set->params.kind, StoredKind::kIrradiance);
    r = test::run_zhc({"info", map});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("1024"), std::string::npos);
    // Same bytes whatever the projection thread count.
    const std::string t1 = dir + "/t1.zhp", t3 = dir + "/t3.zhp";
    ASSERT_EQ(test::run_zhc({"convert", map, "-o", t1, "--to", "zh3_q16", "--threads", "1"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"convert", map, "-o", t3, "--to", "zh3_q16", "--threads", "3"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(t1), test::read_bytes(t3));
    // JSON output through a representation (a lossy preview) and info on it.
    const std::string js = dir + "/one.json";
    ASSERT_EQ(test::run_zhc({"convert", map, "-o", js, "--to", "zh3_q16"}).exit_code, 0);
    r = test::run_zhc({"info", js});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("JSON probe list"), std::string::npos);
}

// convert's errors (missing, bad extension, unknown representation, --bits 9, --dc half, not a
// probe list; truncated, corrupt, trailing, future-version containers through convert and info;
// an unwritable output; a failed run leaving an existing output and a blocking directory as they
// were, no temporary behind): tests/conformance zhp_*, probejson_*, cli_usage_convert_*.

}  // namespace
}  // namespace zhc
