// The CLI conformance suite (KTX-Software's CTS is the model): every row of
// tests/conformance/cases.txt is one command line with its expected exit code and expected output
// (a stderr/stdout excerpt, a golden JSON file), run as its own test named after the row's id.
// The format of the table and of the generated inputs: tests/conformance/README.md.
// ZHC_CONFORMANCE_UPDATE=1 rewrites the golden JSON files and prints what changed.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "formats/envmap/envmap.h"
#include "formats/lightmap/lightmap_exr.h"
#include "formats/probes/probe_file.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;

const std::string kConformanceDir = std::filesystem::weakly_canonical(std::string(ZHC_TEST_DATA_DIR) + "/../conformance").string();

// ---- the table -------------------------------------------------------------------------------

struct Case {
    std::string id;
    int exit_code = 0;
    std::vector<std::string> command;  // tokens, placeholders not yet expanded
    std::vector<std::string> checks;   // "err~REGEX", "out~REGEX", "json=NAME", "file=PATH", "gone=PATH"
    int line = 0;
};

std::string trim(const std::string& s) {
    const size_t b = s.find_first_not_of(" \t");
    if (b == std::string::npos) return "";
    return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// Splits "a | b | c" on " | " (a '|' without spaces on both sides stays: regex alternation).
std::vector<std::string> split_fields(const std::string& line) {
    std::vector<std::string> out;
    size_t start = 0;
    for (size_t at; (at = line.find(" | ", start)) != std::string::npos; start = at + 3) out.push_back(trim(line.substr(start, at - start)));
    out.push_back(trim(line.substr(start)));
    return out;
}

struct Table {
    std::vector<Case> cases;
    std::vector<std::string> errors;  // lines that do not parse
};

const Table& table() {
    static const Table t = [] {
        Table t;
        std::ifstream in(kConformanceDir + "/cases.txt");
        if (!in) t.errors.push_back("cannot read " + kConformanceDir + "/cases.txt");
        std::string line;
        std::set<std::string> ids;
        for (int n = 1; std::getline(in, line); ++n) {
            if (trim(line).empty() || trim(line)[0] == '#') continue;
            const auto f = split_fields(line);
            Case c;
            c.line = n;
            c.id = f[0];
            const bool id_ok = !c.id.empty() && std::all_of(c.id.begin(), c.id.end(), [](char ch) {
                return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
            });
            if (f.size() < 3 || !id_ok || f[1].size() != 1 || !std::isdigit(static_cast<unsigned char>(f[1][0])) ||
                !ids.insert(c.id).second) {
                t.errors.push_back("cases.txt:" + std::to_string(n) + ": bad row (id [A-Za-z0-9_], unique; exit code one digit; a command): " + line);
                continue;
            }
            c.exit_code = f[1][0] - '0';
            std::istringstream words(f[2]);
            for (std::string w; words >> w;) c.command.push_back(w);
            if (c.command == std::vector<std::string>{"(none)"}) c.command.clear();
            c.checks.assign(f.begin() + 3, f.end());
            t.cases.push_back(c);
        }
        return t;
    }();
    return t;
}

// ---- generated inputs (${GEN}/NAME) --------------------------------------------------------------
// Small good files made here with the library (or, for multi-file outputs, with zhc itself), and
// bad ones derived from them by a few byte edits. Nothing big is committed.

std::vector<std::uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

// A 32x16 lat-long map: smooth, positive, brighter towards +Z and +X (its SH3 has every band).
Image small_map() {
    return test::render_latlong(32, 16, [](Vec3 d) {
        return Rgb{float(1.5 + d.z + 0.5 * d.x), float(1.0 + 0.5 * d.z * d.z), float(0.75 + 0.25 * d.y)};
    });
}

// The offset of `what` in `b` (it must be there).
size_t find_bytes(const std::vector<std::uint8_t>& b, const std::string& what) {
    const auto it = std::search(b.begin(), b.end(), what.begin(), what.end());
    EXPECT_NE(it, b.end()) << "generator: no '" << what << "' in the base file";
    return it == b.end() ? 0 : static_cast<size_t>(it - b.begin());
}

// An OpenEXR header attribute's value: the bytes after "name\0type\0" and the 4-byte size.
size_t exr_attribute(const std::vector<std::uint8_t>& b, const std::string& name, const std::string& type) {
    return find_bytes(b, name + std::string(1, '\0') + type + std::string(1, '\0')) + name.size() + type.size() + 2 + 4;
}

void put64(std::vector<std::uint8_t>& b, std::uint64_t v) {
    for (int k = 0; k < 8; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}
void put32_back(std::vector<std::uint8_t>& b, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

// A 2x2-per-face cube map of one colour, R32G32B32A32_SFLOAT, in KTX2 (docs/inputs.md "Cube maps").
std::vector<std::uint8_t> cube_ktx2() {
    constexpr int kN = 2;
    std::vector<std::uint8_t> b = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    const std::uint32_t dfd = 44, index_end = 80 + 24, data = (index_end + dfd + 15) / 16 * 16;
    const std::uint64_t level = 6ull * kN * kN * 16;
    for (std::uint32_t v : {109u, 4u, std::uint32_t(kN), std::uint32_t(kN), 0u, 0u, 6u, 1u, 0u, index_end, dfd, 0u, 0u})
        put32_back(b, v);
    put64(b, 0);
    put64(b, 0);
    put64(b, data);
    put64(b, level);
    put64(b, level);
    for (std::uint32_t v : {dfd, 0u, 2u | (40u << 16)}) put32_back(b, v);
    b.resize(data, 0);
    for (int t = 0; t < 6 * kN * kN; ++t)
        for (float v : {2.0f, 1.0f, 0.5f, 1.0f}) put32_back(b, std::bit_cast<std::uint32_t>(v));
    return b;
}

// The same cube as a DDS with a DX10 header (R32G32B32A32_FLOAT, TEXTURECUBE, all six faces).
std::vector<std::uint8_t> cube_dds() {
    constexpr int kN = 2;
    std::vector<std::uint8_t> b = {'D', 'D', 'S', ' '};
    const std::uint32_t caps2 = 0x200 | 0x400 | 0x800 | 0x1000 | 0x2000 | 0x4000 | 0x8000;
    put32_back(b, 124);
    put32_back(b, 0x1 | 0x2 | 0x4 | 0x1000 | 0x8);  // CAPS HEIGHT WIDTH PIXELFORMAT PITCH
    put32_back(b, kN);                             // height
    put32_back(b, kN);                             // width
    put32_back(b, kN * 16);                        // pitch
    put32_back(b, 0);                              // depth
    put32_back(b, 1);                              // mip count
    for (int k = 0; k < 11; ++k) put32_back(b, 0);
    for (std::uint32_t v : {32u, 0x4u, 0x30315844u, 0u, 0u, 0u, 0u, 0u}) put32_back(b, v);  // pixel format: FourCC DX10
    put32_back(b, 0x1000 | 0x8);  // caps: TEXTURE COMPLEX
    put32_back(b, caps2);
    for (int k = 0; k < 3; ++k) put32_back(b, 0);
    for (std::uint32_t v : {2u, 3u, 0x4u, 1u, 0u}) put32_back(b, v);  // DX10: R32G32B32A32_FLOAT, TEXTURE2D, CUBE, 1
    for (int t = 0; t < 6 * kN * kN; ++t)
        for (float v : {2.0f, 1.0f, 0.5f, 1.0f}) put32_back(b, std::bit_cast<std::uint32_t>(v));
    return b;
}

using Bytes = std::vector<std::uint8_t>;
Bytes cut(Bytes b, size_t n) { return b.resize(b.size() - n), b; }
Bytes with_tail(Bytes b) { return b.push_back(0), b; }
Bytes patched32(Bytes b, size_t offset, std::uint32_t v) { return test::put32(b, offset, v), b; }

void write_text(const std::string& path, const std::string& text) { test::write_bytes(path, bytes_of(text)); }

std::string run_ok(const std::vector<std::string>& args) {
    const auto r = test::run_zhc(args);
    EXPECT_EQ(r.exit_code, 0) << "generator step failed: " << r.err;
    return r.out;
}

Bytes exr_bytes(const std::string& dir, const Image& img) {
    const std::string p = dir + "/.gen.exr";
    EXPECT_TRUE(write_exr(p, img));
    const Bytes b = test::read_bytes(p);
    fs::remove(p);
    return b;
}

// The sh lightmap every lightmap case starts from: 8x8 texels of the small map's SH3.
Bytes lightmap_bytes(const std::string& dir, bool nan) {
    lightmap::ShLightmap lm;
    lm.width = lm.height = 8;
    const Image m = small_map();
    lm.texels.assign(64, project_latlong(m.rgb.data(), m.width, m.height, m.width * 3u));
    if (nan) lm.texels[9][4][1] = std::nanf("");
    const std::string p = dir + "/.gen_lm.exr";
    EXPECT_TRUE(write_sh_lightmap_exr(p, lm));
    const Bytes b = test::read_bytes(p);
    fs::remove(p);
    return b;
}

ProbeList small_probe_list() {
    ProbeList l;
    l.probes = test::golden_probes();
    l.layout.kind = ProbeLayoutKind::kPositions;
    for (int i = 0; i < 4; ++i) l.layout.positions.push_back({float(i), 0.5f * float(i), 1.0f});
    return l;
}

// probes.zhp: the four golden probes as float sh3 at listed positions (on a 4x1x1 grid: grid.zhp).
Bytes probes_zhp(bool grid = false) {
    const ProbeList l = small_probe_list();
    ProbeSet s;
    s.representation = "sh3";
    s.layout = l.layout;
    if (grid) {
        s.layout = {};
        s.layout.kind = ProbeLayoutKind::kGrid;
        s.layout.grid.counts = {4, 1, 1};
    }
    s.count = l.probes.size();
    for (const Sh3Radiance& p : l.probes)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) {
                const auto u = std::bit_cast<std::array<std::uint8_t, 4>>(p[i][k]);
                s.payload.insert(s.payload.end(), u.begin(), u.end());
            }
    auto b = serialize_probe_set(s);
    EXPECT_TRUE(b.ok());
    return b.ok() ? *b : Bytes{};
}

// A Git LFS pointer file as git-lfs writes it (specification v1: version, oid, size lines).
Bytes lfs_pointer() {
    return bytes_of("version https://git-lfs.github.com/spec/v1\n"
                    "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\n"
                    "size 12345\n");
}

using Generator = std::function<void(const std::string& dir, const std::string& name)>;
Generator file(std::function<Bytes(const std::string& dir)> make) {
    return [make](const std::string& dir, const std::string& name) { test::write_bytes(dir + "/" + name, make(dir)); };
}

// A lightmap triplet (NAME.iz/.d/.wa.ktx2 or .dds) from the 8x8 lightmap, the .d file cut short
// when `cut_d`.
enum class TripletEdit { kNone, kCutD, kIzAsD, kSignedIz, kHugeIz };
Generator triplet(const std::string& container, TripletEdit edit) {
    return [container, edit](const std::string& dir, const std::string& name) {
        test::write_bytes(dir + "/.gen_lm.exr", lightmap_bytes(dir, false));
        run_ok({"lightmap", "encode", dir + "/.gen_lm.exr", "-o", dir + "/" + name, "--container", container, "--quality",
                "fast", "--quiet"});
        fs::remove(dir + "/.gen_lm.exr");
        const std::string d = dir + "/" + name + ".d." + container;
        if (edit == TripletEdit::kCutD) test::write_bytes(d, cut(test::read_bytes(d), 3));
        if (edit == TripletEdit::kIzAsD) test::write_bytes(d, test::read_bytes(dir + "/" + name + ".iz." + container));
        const std::string iz = dir + "/" + name + ".iz." + container;
        const bool ktx2 = container == "ktx2";
        if (edit == TripletEdit::kSignedIz)  // BC6H_SFLOAT: KTX2 vkFormat 144, DDS DX10 dxgiFormat 96
            test::write_bytes(iz, patched32(test::read_bytes(iz), ktx2 ? 12 : 128, ktx2 ? 144 : 96));
        if (edit == TripletEdit::kHugeIz)  // 60000 x 60000 texels: KTX2 pixelWidth/Height, DDS height/width
            test::write_bytes(iz, patched32(patched32(test::read_bytes(iz), ktx2 ? 20 : 12, 60000), ktx2 ? 24 : 16, 60000));
    };
}

enum class GlbEdit { kNone, kCut, kVersion3 };
void embed_probes(const std::string& dir, const std::string& name, GlbEdit edit) {
    test::write_bytes(dir + "/.gen.zhp", probes_zhp());
    const std::string out = dir + "/" + name;
    run_ok({"gltf", "embed", std::string(ZHC_TEST_DATA_DIR) + "/gltf/gt_list.glb", dir + "/.gen.zhp", "-o", out});
    fs::remove(dir + "/.gen.zhp");
    if (edit == GlbEdit::kCut) test::write_bytes(out, cut(test::read_bytes(out), 10));
    if (edit == GlbEdit::kVersion3) test::write_bytes(out, patched32(test::read_bytes(out), 4, 3));  // GLB header version
}

const std::map<std::string, Generator>& generators() {
    static const std::map<std::string, Generator> g = {
        // Environment maps.
        {"map.exr", file([](const std::string& d) { return exr_bytes(d, small_map()); })},
        {"map.hdr", [](const std::string& d, const std::string& n) { EXPECT_TRUE(write_hdr(d + "/" + n, small_map())); }},
        {"nan.exr", file([](const std::string& d) {
             Image m = small_map();
             m.row(3)[7] = std::nanf("");
             return exr_bytes(d, m);
         })},
        {"cut.exr", file([](const std::string& d) { return cut(exr_bytes(d, small_map()), 200); })},
        {"tail.exr", file([](const std::string& d) { return with_tail(exr_bytes(d, small_map())); })},
        {"huge.exr", file([](const std::string& d) {  // dataWindow (0,0)-(9999,9999): 10^8 pixels
             Bytes b = exr_bytes(d, small_map());
             const size_t at = exr_attribute(b, "dataWindow", "box2i");
             return patched32(patched32(b, at + 8, 9999), at + 12, 9999);
         })},
        {"nochannels.exr", file([](const std::string& d) {  // channels B G R renamed C H Q: well-formed, nothing to read
             Bytes b = exr_bytes(d, small_map());
             size_t at = exr_attribute(b, "channels", "chlist");
             for (const char to : {'C', 'H', 'Q'}) {
                 b[at] = static_cast<std::uint8_t>(to);
                 at += 2 + 16;
             }
             return b;
         })},
        {"cut.hdr", [](const std::string& d, const std::string& n) {
             EXPECT_TRUE(write_hdr(d + "/" + n, small_map()));
             test::write_bytes(d + "/" + n, cut(test::read_bytes(d + "/" + n), 40));
         }},
        {"tail.hdr", [](const std::string& d, const std::string& n) {
             EXPECT_TRUE(write_hdr(d + "/" + n, small_map()));
             test::write_bytes(d + "/" + n, with_tail(test::read_bytes(d + "/" + n)));
         }},
        {"huge.hdr", file([](const std::string&) { return bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 10000 +X 10000\n"); })},
        {"format.hdr", file([](const std::string&) { return bytes_of("#?RADIANCE\nFORMAT=32-bit_float\n\n-Y 2 +X 2\n"); })},
        // Cube maps.
        {"cube.ktx2", file([](const std::string&) { return cube_ktx2(); })},
        {"cube.dds", file([](const std::string&) { return cube_dds(); })},
        {"cut_cube.ktx2", file([](const std::string&) { return cut(cube_ktx2(), 1); })},
        {"cut_cube.dds", file([](const std::string&) { return cut(cube_dds(), 1); })},
        {"nan_cube.ktx2", file([](const std::string&) {  // the last texel's red is NaN
             Bytes b = cube_ktx2();
             return patched32(b, b.size() - 16, std::bit_cast<std::uint32_t>(std::nanf("")));
         })},
        {"array_cube.ktx2", file([](const std::string&) { return patched32(cube_ktx2(), 32, 2); })},  // layerCount 2
        {"partial_cube.dds", file([](const std::string&) { return patched32(cube_dds(), 112, 0x200 | 0x400); })},
        {"huge_cube.ktx2", file([](const std::string&) { return patched32(patched32(cube_ktx2(), 20, 60000), 24, 60000); })},
        {"huge_cube.dds", file([](const std::string&) { return patched32(patched32(cube_dds(), 12, 70000), 16, 70000); })},
        // Probe containers and JSON probe lists.
        {"probes.json", file([](const std::string&) { return bytes_of(probe_json(small_probe_list())); })},
        {"probes.zhp", file([](const std::string&) { return probes_zhp(); })},
        {"grid.zhp", file([](const std::string&) { return probes_zhp(true); })},
        {"cut.zhp", file([](const std::string&) { return cut(probes_zhp(), 3); })},
        {"tail.zhp", file([](const std::string&) { return with_tail(probes_zhp()); })},
        {"crc.zhp", file([](const std::string&) {  // a body byte changed: the body CRC no longer matches
             Bytes b = probes_zhp();
             b[b.size() - 5] ^= 4;
             return b;
         })},
        {"future.zhp", file([](const std::string&) { return test::zhp_with_header_edit(probes_zhp(), 8, {9, 0}); })},  // version 9
        {"nan.zhp", file([](const std::string&) {  // probe 1's L00 red is NaN, both CRCs made to match
             Bytes b = probes_zhp();
             const size_t body = kProbeFileHeaderBytes + 4 * 12;  // after the four positions
             test::put32(b, body + 108, std::bit_cast<std::uint32_t>(std::nanf("")));
             const std::uint32_t body_crc = crc32(std::span<const std::uint8_t>(b.data() + kProbeFileHeaderBytes, b.size() - kProbeFileHeaderBytes));
             return test::zhp_with_header_edit(b, 176, {std::uint8_t(body_crc), std::uint8_t(body_crc >> 8), std::uint8_t(body_crc >> 16), std::uint8_t(body_crc >> 24)});
         })},
        {"huge.zhp", file([](const std::string&) { return test::zhp_with_header_edit(probes_zhp(), 56, {0, 0, 0, 0, 1}); })},  // 2^32 probes
        // Outputs in the way: an existing file a failed run must leave alone; directories where an
        // output (or the last of a lightmap triplet) must go, so that the write fails (exit 7).
        {"existing.zhp", file([](const std::string&) { return Bytes{1, 2, 3}; })},
        {"blocked.zhp", [](const std::string& d, const std::string& n) { fs::create_directories(d + "/" + n + "/inside"); }},
        {"blocked", [](const std::string& d, const std::string& n) {
             for (const char* c : {".wa.ktx2", ".wa.dds"}) fs::create_directories(d + "/" + n + c + "/inside");
         }},
        {"garbage.bin", file([](const std::string&) { return bytes_of("these bytes are no format zhc knows\n"); })},
        {"deep.json", file([](const std::string&) { return bytes_of("{\"probes\":" + std::string(600, '[') + std::string(600, ']') + "}"); })},
        // Lightmaps.
        {"lm.exr", file([](const std::string& d) { return lightmap_bytes(d, false); })},
        {"nan_lm.exr", file([](const std::string& d) { return lightmap_bytes(d, true); })},
        {"cut_lm.exr", file([](const std::string& d) { return cut(lightmap_bytes(d, false), 100); })},
        {"huge_lm.exr", file([](const std::string& d) {
             Bytes b = lightmap_bytes(d, false);
             const size_t at = exr_attribute(b, "dataWindow", "box2i");
             return patched32(patched32(b, at + 8, 19999), at + 12, 19999);
         })},
        {"lm", triplet("ktx2", TripletEdit::kNone)},
        {"lmdds", triplet("dds", TripletEdit::kNone)},
        {"cutlm", triplet("ktx2", TripletEdit::kCutD)},
        {"cutlmdds", triplet("dds", TripletEdit::kCutD)},
        {"swappedlm", triplet("ktx2", TripletEdit::kIzAsD)},  // BC6H where the BC5 direction belongs
        {"swappedlmdds", triplet("dds", TripletEdit::kIzAsD)},
        {"sf16lmdds", triplet("dds", TripletEdit::kSignedIz)},  // signed BC6H where BC6H_UF16 belongs
        {"sf16lm", triplet("ktx2", TripletEdit::kSignedIz)},
        {"hugelm", triplet("ktx2", TripletEdit::kHugeIz)},
        {"hugelmdds", triplet("dds", TripletEdit::kHugeIz)},
        // 2-D KTX2 in a format zhc does not read: the BC6H plane relabelled BC7 (same block size).
        {"bc7_2d.ktx2", [](const std::string& d, const std::string& n) {
             triplet("ktx2", TripletEdit::kNone)(d, ".gen_2d");
             test::write_bytes(d + "/" + n, patched32(test::read_bytes(d + "/.gen_2d.iz.ktx2"), 12, 145));
             for (const char* p : {".iz.ktx2", ".d.ktx2", ".wa.ktx2"}) fs::remove(d + "/.gen_2d" + p);
         }},
        // IrradZ planes as lightmap decode writes them.
        {"irradz.exr", [](const std::string& d, const std::string& n) {
             triplet("ktx2", TripletEdit::kNone)(d, ".gen_iz");
             run_ok({"lightmap", "decode", d + "/.gen_iz", "-o", d + "/" + n, "--quiet"});
             for (const char* p : {".iz.ktx2", ".d.ktx2", ".wa.ktx2"}) fs::remove(d + "/.gen_iz" + p);
         }},
        // Git LFS pointers (what a checkout holds when git lfs did not fetch the content) where an
        // EXR, a glTF, a .zhp, a lightmap EXR / KTX2 triplet or a glTF's .bin belongs.
        {"lfs.exr", file([](const std::string&) { return lfs_pointer(); })},
        {"lfs.gltf", file([](const std::string&) { return lfs_pointer(); })},
        {"lfs.zhp", file([](const std::string&) { return lfs_pointer(); })},
        {"lfs_lm.exr", file([](const std::string&) { return lfs_pointer(); })},
        {"lfslm", [](const std::string& d, const std::string& n) {
             for (const char* p : {".iz.ktx2", ".d.ktx2", ".wa.ktx2"}) test::write_bytes(d + "/" + n + p, lfs_pointer());
         }},
        {"lfsbin.gltf", [](const std::string& d, const std::string& n) {
             test::write_bytes(d + "/" + n, bytes_of(R"({"asset":{"version":"2.0"},"buffers":[{"uri":"lfsbin.bin","byteLength":1000}]})"));
             test::write_bytes(d + "/lfsbin.bin", lfs_pointer());
         }},
        // glTF: the four probes embedded into the corpus's plain triangle list.
        {"lit.glb", [](const std::string& d, const std::string& n) { embed_probes(d, n, GlbEdit::kNone); }},
        {"cut.glb", [](const std::string& d, const std::string& n) { embed_probes(d, n, GlbEdit::kCut); }},
        {"v3.glb", [](const std::string& d, const std::string& n) { embed_probes(d, n, GlbEdit::kVersion3); }},
    };
    return g;
}

// ---- running one case ------------------------------------------------------------------------------

struct Paths {
    std::string tmp;
    std::map<std::string, std::string> vars;
    std::set<std::string> generated;
};

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
    if (from.empty()) return s;
    for (size_t at = 0; (at = s.find(from, at)) != std::string::npos; at += to.size()) s.replace(at, from.size(), to);
    return s;
}

// Expands ${TMP} ${ENVMAPS} ${DATA} ${INPUTS}; ${GEN}/NAME generates NAME into ${TMP} first.
std::string expand(const std::string& token, Paths& p) {
    std::string s = token;
    const std::string gen = "${GEN}/";
    for (size_t at; (at = s.find(gen)) != std::string::npos;) {
        size_t end = at + gen.size();
        while (end < s.size() && (std::isalnum(static_cast<unsigned char>(s[end])) || s[end] == '_' || s[end] == '.')) ++end;
        // NAME, else NAME without its last extensions (lm.iz.ktx2: the generator "lm" writes it).
        std::string name = s.substr(at + gen.size(), end - at - gen.size());
        while (!generators().count(name) && name.find('.') != std::string::npos) name.erase(name.rfind('.'));
        const auto it = generators().find(name);
        if (it == generators().end())
            ADD_FAILURE() << "no generator for " << s;
        else if (p.generated.insert(name).second)
            it->second(p.tmp, name);
        s.replace(at, gen.size(), "${TMP}/");
    }
    for (const auto& [var, value] : p.vars) s = replace_all(s, "${" + var + "}", value);
    return s;
}

// Paths in outputs written back as placeholders, so goldens do not depend on the machine.
std::string unexpand(std::string s, const Paths& p) {
    for (const auto& [var, value] : p.vars) s = replace_all(s, value, "${" + var + "}");
    return s;
}

// Every path under `dir` with its bytes ("<dir>" for a folder): a failed run must leave it as it was.
std::map<std::string, std::string> snapshot(const std::string& dir) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::vector<std::uint8_t> b = e.is_directory() ? std::vector<std::uint8_t>{} : test::read_bytes(e.path().string());
        out[fs::relative(e.path(), dir).string()] = e.is_directory() ? "<dir>" : std::string(b.begin(), b.end());
    }
    return out;
}

// Keys whose values change run to run or release to release: replaced by a marker, kept as keys.
bool volatile_key(const std::string& k) {
    static const std::regex re("zhc|.*_ns|.*_ms|.*seconds|.*_per_s|threads");
    return std::regex_match(k, re);
}

nlohmann::json normalised(nlohmann::json j, const Paths& p) {
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end(); ++it) {
            if (volatile_key(it.key()))
                it.value() = "<volatile>";
            else
                it.value() = normalised(it.value(), p);
        }
    } else if (j.is_array()) {
        for (auto& v : j) v = normalised(v, p);
    } else if (j.is_string()) {
        j = unexpand(j.get<std::string>(), p);
    }
    return j;
}

// Equal, numbers within 1e-9 relative or 1e-12 absolute (the same code built by g++ and by clang
// may round the last bit of a sum differently, and a coefficient that is zero in exact arithmetic
// comes out as +-1e-16; any real change moves far more).
bool same_json(const nlohmann::json& a, const nlohmann::json& b, const std::string& where, std::string* why) {
    if (a.is_number() && b.is_number()) {
        const double x = a.get<double>(), y = b.get<double>();
        if (std::abs(x - y) <= 1e-9 * std::max(std::abs(x), std::abs(y)) + 1e-12) return true;
        *why = where + ": " + b.dump() + " (golden " + a.dump() + ")";
        return false;
    }
    if (a.type() != b.type()) {
        *why = where + ": " + b.dump() + " (golden " + a.dump() + ")";
        return false;
    }
    if (a.is_object()) {
        if (a.size() != b.size()) {
            *why = where + ": keys " + std::to_string(b.size()) + " (golden " + std::to_string(a.size()) + ")";
            return false;
        }
        for (auto it = a.begin(); it != a.end(); ++it) {
            if (!b.contains(it.key())) {
                *why = where + "." + it.key() + ": missing";
                return false;
            }
            if (!same_json(it.value(), b.at(it.key()), where + "." + it.key(), why)) return false;
        }
        return true;
    }
    if (a.is_array()) {
        if (a.size() != b.size()) {
            *why = where + ": " + std::to_string(b.size()) + " elements (golden " + std::to_string(a.size()) + ")";
            return false;
        }
        for (size_t i = 0; i < a.size(); ++i)
            if (!same_json(a[i], b[i], where + "[" + std::to_string(i) + "]", why)) return false;
        return true;
    }
    if (a != b) *why = where + ": " + b.dump() + " (golden " + a.dump() + ")";
    return a == b;
}

bool update_mode() {
    const char* u = std::getenv("ZHC_CONFORMANCE_UPDATE");
    return u && std::string(u) == "1";
}

void check_golden_json(const std::string& name, const std::string& out, const Paths& p) {
    nlohmann::json got;
    try {
        // The envelope (README "JSON output"): "zhc" (the version) first, then "command".
        const auto ordered = nlohmann::ordered_json::parse(out);
        ASSERT_TRUE(ordered.is_object() && ordered.size() >= 2) << out;
        EXPECT_EQ(ordered.begin().key(), "zhc");
        EXPECT_EQ(std::next(ordered.begin()).key(), "command");
        EXPECT_EQ("zhc " + ordered.begin().value().get<std::string>() + "\n", test::run_zhc({"--version"}).out)
            << "\"zhc\" holds the version --version prints";
        got = normalised(nlohmann::json::parse(out), p);
    } catch (const std::exception& e) {
        ADD_FAILURE() << "stdout is not JSON (" << e.what() << "): " << out;
        return;
    }
    const std::string path = kConformanceDir + "/golden/" + name + ".json";
    const std::string text = got.dump(2) + "\n";
    std::ifstream in(path);
    std::stringstream old;
    old << in.rdbuf();
    if (update_mode()) {
        if (old.str() == text) return;
        const std::string before = fs::temp_directory_path() / ("zhc_golden_" + name + ".old.json");
        write_text(before, old.str());
        write_text(path, text);
        std::printf("conformance: rewrote golden/%s.json\n", name.c_str());
        const std::string diff = "diff -u '" + before + "' '" + path + "'";
        [[maybe_unused]] const int rc = std::system(diff.c_str());
        fs::remove(before);
        return;
    }
    ASSERT_TRUE(in.good() || !old.str().empty()) << "no golden " << path << " (ZHC_CONFORMANCE_UPDATE=1 writes it)";
    std::string why;
    EXPECT_TRUE(same_json(nlohmann::json::parse(old.str()), got, name, &why))
        << "golden/" << name << ".json differs: " << why << " (ZHC_CONFORMANCE_UPDATE=1 rewrites it and shows the diff)";
}

class Conformance : public testing::TestWithParam<Case> {};

TEST_P(Conformance, Row) {
    const Case& c = GetParam();
    Paths p;
    p.tmp = test::fresh_dir("conformance/" + c.id);
    p.vars = {{"TMP", p.tmp},
              {"ENVMAPS", ZHC_ENVMAP_DIR},
              {"DATA", ZHC_TEST_DATA_DIR},
              {"INPUTS", fs::weakly_canonical(kConformanceDir + "/inputs").string()}};
    SCOPED_TRACE("tests/conformance/cases.txt:" + std::to_string(c.line) + " " + c.id);
    std::vector<std::string> args;
    for (const std::string& t : c.command) args.push_back(expand(t, p));
    const auto before = snapshot(p.tmp);
    const auto r = test::run_zhc(args);
    const std::string err = unexpand(r.err, p), out = unexpand(r.out, p);
    EXPECT_EQ(r.exit_code, c.exit_code) << "stderr: " << err << "stdout: " << out.substr(0, 2000);
    if (c.exit_code != 0) {
        // Errors: one line ("zhc: gate failed: ..." for a gate, else "zhc: error: ..."), nothing
        // left behind. Input and usage errors come before any work: nothing on stdout either
        // (an output or gate failure may follow a report on stdout).
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << err;
        EXPECT_EQ(r.err.rfind(c.exit_code == 8 ? "zhc: gate failed: " : "zhc: error: ", 0), 0u) << err;
        if (c.exit_code < 7) {
            EXPECT_EQ(r.out, "") << "an input or usage error prints nothing on stdout";
        }
        const auto after = snapshot(p.tmp);
        for (const auto& [path, bytes] : after)
            EXPECT_TRUE(before.count(path)) << "a failed run left " << path << " behind";
        for (const auto& [path, bytes] : before)
            EXPECT_TRUE(after.count(path) && after.at(path) == bytes) << "a failed run removed or changed " << path;
    }
    for (const std::string& check : c.checks) {
        const std::string arg = check.size() > 4 ? check.substr(4) : "";
        if (check.rfind("err~", 0) == 0 || check.rfind("out~", 0) == 0) {
            const std::string& text = check[0] == 'e' ? err : out;
            EXPECT_FALSE(arg.empty()) << check << ": an empty pattern matches anything";
            EXPECT_TRUE(std::regex_search(text, std::regex(arg))) << check << "\ngot: " << text;
        } else if (check.rfind("json=", 0) == 0) {
            check_golden_json(check.substr(5), r.out, p);
        } else if (check.rfind("file=", 0) == 0) {
            const std::string f = expand(check.substr(5), p);
            EXPECT_TRUE(fs::is_regular_file(f) && fs::file_size(f) > 0) << check << ": not written";
        } else {
            ADD_FAILURE() << "unknown check '" << check << "' (err~ out~ json= file=)";
        }
    }
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.id; }

std::string case_name(const testing::TestParamInfo<Case>& info) { return info.param.id; }

INSTANTIATE_TEST_SUITE_P(Cli, Conformance, testing::ValuesIn(table().cases), case_name);

// The table itself: every row parses, every golden file is some row's and exists.
TEST(ConformanceTable, ParsesAndEveryGoldenIsUsed) {
    for (const std::string& e : table().errors) ADD_FAILURE() << e;
    EXPECT_GE(table().cases.size(), 50u);
    std::set<std::string> used;
    for (const Case& c : table().cases)
        for (const std::string& check : c.checks)
            if (check.rfind("json=", 0) == 0) used.insert(check.substr(5) + ".json");
    for (const auto& e : fs::directory_iterator(kConformanceDir + "/golden"))
        EXPECT_TRUE(used.count(e.path().filename().string())) << "golden file no row uses: " << e.path();
    for (const std::string& g : used) EXPECT_TRUE(fs::exists(kConformanceDir + "/golden/" + g)) << g;
}

}  // namespace
}  // namespace zhc
