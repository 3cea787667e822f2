// Golden metrics, in the style of basis_universal's test table: for every lossy path,
// on fixed small inputs, the error, the size and a 64-bit FNV-1a hash of the output bytes, each
// checked against tests/golden/metrics.tsv.
//
//   probe   every codec-table representation on each of the eight sample maps: irradiance
//           relative RMSE at 128 Fibonacci directions against the map integrated directly
//           (the `zhc audit` reference); hash of the stored bytes and the decoded SH3 hub.
//   bc6h    every BC6H quality on a 16x16 crop of each map (the audit's 512x256 downsample) and
//           on the I_z plane of a 16x16 synthetic lightmap lit by that map: log2-PSNR.
//   bc5/bc4 every BC5/BC4 quality on the crop (tone-mapped R,G / luminance) and on the
//           lightmap's d / w_a planes: PSNR (20 log10(1 / RMSE)).
//   irradz  the three IrradZ solves (search, talk_baseline, newton = the default) on the synthetic lightmap:
//           hemispherical irradiance RMSE against its SH3 (lightmap::audit), hash of the planes;
//           "search_bc" / "newton_bc" = that solve, then BC6H + BC5 + BC4 at default quality
//           ("newton_bc" is the `zhc lightmap encode` output).
//   astc    the newton planes through the ASTC targets (formats/lightmap/astc.h, astcenc 4.2 at
//           medium effort): "astc_4x4", "astc_6x6" (HDR I_z + LDR (u, v, w_a)), "astc_ldr_4x4"
//           (the LDR range fallback): hemispherical RMSE after decoding, bytes and hash of the blocks.
//           Listed after every other row (one block at the end of the table).
//
// A row fails when its size or hash changes, or its error leaves [value - tolerance, value +
// tolerance] (absolute, stored in the file: 0.1% of the value when generated). A codec entry
// without rows fails too, as does a row whose entry is gone. After a deliberate change:
//     scripts/golden.sh [BUILD_DIR]
// (runs this test with ZHC_GOLDEN_REGENERATE=1: it rewrites the table and prints every changed,
// added and removed row; review that diff, then commit the table).
//
// Fixed inputs (no ZHC_TEST_SAMPLE_SCALE): the same hashes in the Release and sanitizer builds,
// and with g++ and clang (the "same bytes on every machine" contract, codec/probe/codec.h).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include "codec/audit/audit.h"
#include "codec/lightmap/bc45.h"
#include "codec/lightmap/bc6h.h"
#include "codec/probe/codec.h"
#include "codec/lightmap/lightmap.h"
#include "formats/lightmap/astc.h"
#include "formats/report/audit_inputs.h"
#include "support.h"

namespace zhc {
namespace {

const char* const kTablePath = ZHC_GOLDEN_DIR "/metrics.tsv";
constexpr int kDirections = 128;
constexpr int kCrop = 16;         // crop and lightmap: 16x16 texels = 16 blocks
constexpr int kCropX = 248, kCropY = 96;  // in the 512x256 audit downsample: above the horizon, centre

struct Hash {
    std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a 64
    void bytes(const std::uint8_t* p, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
    }
    void bytes(const std::vector<std::uint8_t>& v) { bytes(v.data(), v.size()); }
    void floats(const float* f, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) {
            const std::uint32_t u = std::bit_cast<std::uint32_t>(f[i]);
            const std::uint8_t b[4] = {std::uint8_t(u), std::uint8_t(u >> 8), std::uint8_t(u >> 16), std::uint8_t(u >> 24)};
            bytes(b, 4);
        }
    }
    void floats(const std::vector<float>& v) { floats(v.data(), v.size()); }
    void halves(const std::vector<std::uint16_t>& v) {
        for (std::uint16_t x : v) {
            const std::uint8_t b[2] = {std::uint8_t(x), std::uint8_t(x >> 8)};
            bytes(b, 2);
        }
    }
};

struct Row {
    std::string kind, path, input, metric;
    std::uint64_t bytes = 0;
    double value = 0, tolerance = 0;
    std::uint64_t hash = 0;
    std::string key() const { return kind + "/" + path + "/" + input; }
};

std::string hex(std::uint64_t h) {
    char b[17];
    std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h));
    return b;
}

std::string format_row(const Row& r) {
    char v[64], t[64];
    std::snprintf(v, sizeof v, "%.9g", r.value);
    std::snprintf(t, sizeof t, "%.3g", r.tolerance);
    return r.kind + "\t" + r.path + "\t" + r.input + "\t" + std::to_string(r.bytes) + "\t" + r.metric + "\t" + v + "\t" + t +
           "\t" + hex(r.hash);
}

const char* const kHeader =
    "# zhc golden metrics (tests/test_golden.cpp). Regenerate: scripts/golden.sh; review the diff.\n"
    "# kind\tpath\tinput\tbytes\tmetric\tvalue\ttolerance\thash\n";

// kind path input bytes metric value tolerance hash; '#' lines are comments. Malformed lines fail.
std::map<std::string, Row> read_table(std::vector<std::string>* problems) {
    std::map<std::string, Row> rows;
    std::ifstream in(kTablePath);
    if (!in) {
        problems->push_back(std::string("cannot read ") + kTablePath);
        return rows;
    }
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
        ++n;
        if (line.empty() || line[0] == '#') continue;
        std::istringstream s(line);
        Row r;
        std::string hash;
        if (!(s >> r.kind >> r.path >> r.input >> r.bytes >> r.metric >> r.value >> r.tolerance >> hash) || hash.size() != 16) {
            problems->push_back("metrics.tsv line " + std::to_string(n) + " is malformed: " + line);
            continue;
        }
        r.hash = std::strtoull(hash.c_str(), nullptr, 16);
        rows[r.key()] = r;
    }
    return rows;
}

Row make_row(std::string kind, std::string path, std::string input, std::uint64_t bytes, std::string metric, double value,
             std::uint64_t hash) {
    Row r{std::move(kind), std::move(path), std::move(input), std::move(metric), bytes, value, 0, hash};
    r.tolerance = std::max(1e-12, 1e-3 * std::fabs(value));
    return r;
}

double psnr(const std::vector<float>& ref, const std::vector<float>& dec) {
    double mse = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) mse += (double(ref[i]) - dec[i]) * (double(ref[i]) - dec[i]);
    mse /= double(std::max<std::size_t>(1, ref.size()));
    return mse > 0 ? 20 * std::log10(1 / std::sqrt(mse)) : 999.0;
}

const std::pair<const char*, bc6h::Quality> kBc6hQualities[] = {
    {"mode11", bc6h::Quality::kMode11}, {"fast", bc6h::Quality::kFast},
    {"default", bc6h::Quality::kDefault}, {"exhaustive", bc6h::Quality::kExhaustive}};
const std::pair<const char*, bc45::Quality> kBc45Qualities[] = {{"fast", bc45::Quality::kFast}, {"default", bc45::Quality::kDefault}};

// BC6H / BC5 / BC4 rows for one HDR RGB image (16x16), one unorm 2-channel and one 1-channel plane.
void block_rows(const std::string& input, const std::vector<float>& rgb, const std::vector<float>& two,
                const std::vector<float>& one, std::vector<Row>& out) {
    for (const auto& [name, q] : kBc6hQualities) {
        const auto blocks = bc6h::encode_image(rgb.data(), kCrop, kCrop, q, 1);
        const auto half = bc6h::decode_image(blocks.data(), blocks.size(), kCrop, kCrop);
        Hash h;
        h.bytes(blocks);
        out.push_back(make_row("bc6h", name, input, blocks.size(), "log2_psnr",
                               lightmap::log2_psnr(rgb.data(), half.data(), rgb.size()), h.h));
    }
    for (const auto& [name, q] : kBc45Qualities) {
        for (int channels : {2, 1}) {
            const std::vector<float>& v = channels == 2 ? two : one;
            const auto blocks = bc45::encode_image(v.data(), channels, kCrop, kCrop, q, 1);
            const auto dec = bc45::decode_image(blocks.data(), blocks.size(), channels, kCrop, kCrop);
            Hash h;
            h.bytes(blocks);
            out.push_back(make_row(channels == 2 ? "bc5" : "bc4", name, input, blocks.size(), "psnr", psnr(v, dec), h.h));
        }
    }
}

// Every row, recomputed.
std::vector<Row> compute_rows() {
    std::vector<Row> rows, astc_rows;
    const std::vector<Vec3> dirs = fibonacci_sphere(kDirections);
    for (const std::string& path : test::envmap_paths()) {
        const std::string map = test::envmap_name(path);
        auto in = load_audit_input(path, dirs, {});
        EXPECT_TRUE(in) << path << ": " << (in ? "" : in.error().message);
        if (!in) continue;
        const Sh3Radiance& hub = in->probes.at(0);
        const std::vector<Rgb> ref = in->reference_for(0, dirs);

        // Every representation: stored bytes + decoded hub, irradiance error against the map.
        const CodecOptions options;
        for (const Codec& c : codecs()) {
            std::vector<std::uint8_t> stored(c.size_bytes);
            c.encode(hub, options, stored.data(), nullptr);
            const Sh3Radiance back = c.decode(stored.data(), options);
            Hash h;
            h.bytes(stored);
            for (int i = 0; i < 9; ++i) {
                const float f[3] = {back[i].r, back[i].g, back[i].b};
                h.floats(f, 3);
            }
            MetricsAccumulator acc;
            acc.add(codec_irradiance(c, stored.data(), options, dirs), ref);
            rows.push_back(make_row("probe", std::string(c.name), map, c.size_bytes, "rel_rmse", acc.result().relative_rmse, h.h));
        }

        // Block compression on a crop of the map: HDR RGB; tone-mapped v / (1 + v) for BC5 (R, G)
        // and BC4 (luminance).
        std::vector<float> crop, two, one;
        for (int y = 0; y < kCrop; ++y)
            for (int x = 0; x < kCrop; ++x) {
                const float* p = &in->map.rgb[3 * (std::size_t(kCropY + y) * in->map.width + kCropX + x)];
                crop.insert(crop.end(), p, p + 3);
                two.push_back(p[0] / (1 + p[0]));
                two.push_back(p[1] / (1 + p[1]));
                const float lum = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
                one.push_back(lum / (1 + lum));
            }
        block_rows(map, crop, two, one, rows);

        // A synthetic lightmap lit by the map: both IrradZ solves, the encoder's output after block
        // compression, and each block format on its planes.
        const lightmap::ShLightmap lm = lightmap::synthesize_sphere(hub, kCrop, kCrop, 1);
        irradz::EncodeOptions eo;
        eo.solve = irradz::Solve::kSearch;
        const lightmap::IrradzPlanes search = lightmap::encode_planes(lm, eo, 1);
        eo.solve = irradz::Solve::kTalkBaseline;
        const lightmap::IrradzPlanes old_way = lightmap::encode_planes(lm, eo, 1);
        const lightmap::Compressed c = lightmap::compress(search, bc6h::Quality::kDefault, bc45::Quality::kDefault, 1);
        const lightmap::IrradzPlanes after = lightmap::decompress(c);
        const lightmap::Audit a = lightmap::audit(lm, search, old_way, after, 1);
        const std::string lmname = "lm_" + map;
        auto planes_hash = [](const lightmap::IrradzPlanes& p) {
            Hash h;
            h.floats(p.iz);
            h.floats(p.wa);
            h.floats(p.d);
            return h.h;
        };
        const std::uint64_t plane_bytes = 4 * (search.iz.size() + search.wa.size() + search.d.size());
        rows.push_back(make_row("irradz", "search", lmname, plane_bytes, "hemi_rmse", a.rmse_search, planes_hash(search)));
        rows.push_back(make_row("irradz", "talk_baseline", lmname, plane_bytes, "hemi_rmse", a.rmse_old, planes_hash(old_way)));
        auto blocks_hash = [](const lightmap::Compressed& k) {
            Hash h;
            h.bytes(k.bc6h);
            h.bytes(k.bc5);
            h.bytes(k.bc4);
            return h.h;
        };
        auto blocks_size = [](const lightmap::Compressed& k) { return k.bc6h.size() + k.bc5.size() + k.bc4.size(); };
        rows.push_back(make_row("irradz", "search_bc", lmname, blocks_size(c), "hemi_rmse", a.rmse_after_bc, blocks_hash(c)));
        block_rows(lmname, search.iz, search.d, search.wa, rows);
        // The default solve (Newton on d) and the default encoder output built on it.
        eo.solve = irradz::Solve::kNewton;
        const lightmap::IrradzPlanes newton = lightmap::encode_planes(lm, eo, 1);
        const lightmap::Compressed cn = lightmap::compress(newton, bc6h::Quality::kDefault, bc45::Quality::kDefault, 1);
        const lightmap::Audit an = lightmap::audit(lm, newton, old_way, lightmap::decompress(cn), 1);
        rows.push_back(make_row("irradz", "newton", lmname, plane_bytes, "hemi_rmse", an.rmse_search, planes_hash(newton)));
        rows.push_back(make_row("irradz", "newton_bc", lmname, blocks_size(cn), "hemi_rmse", an.rmse_after_bc, blocks_hash(cn)));
        // The ASTC targets on the same planes.
        for (const auto& [name, fp, ldr] : {std::tuple{"astc_4x4", astc::Footprint{4, 4}, false},
                                            std::tuple{"astc_6x6", astc::Footprint{6, 6}, false},
                                            std::tuple{"astc_ldr_4x4", astc::Footprint{4, 4}, true}}) {
            lightmap_astc::Options ao;
            ao.footprint = fp;
            ao.ldr_iz = ldr;
            float mn = 0, mx = 0;
            lightmap::iz_extent(newton.iz, mn, mx);
            ao.range = lightmap::iz_log_range(mn, mx);
            auto ca = lightmap_astc::compress(newton, ao, 1);
            EXPECT_TRUE(ca.ok());
            if (!ca) continue;
            auto da = lightmap_astc::decompress(*ca);
            EXPECT_TRUE(da.ok());
            if (!da) continue;
            const lightmap::Audit aa = lightmap::audit(lm, newton, old_way, *da, 1);
            Hash h;
            h.bytes(ca->iz);
            h.bytes(ca->dwa);
            astc_rows.push_back(make_row("astc", name, lmname, ca->bytes(), "hemi_rmse", aa.rmse_after_bc, h.h));
        }
    }
    rows.insert(rows.end(), astc_rows.begin(), astc_rows.end());
    return rows;
}

TEST(Golden, EveryLossyPathMatchesTheTable) {
    const std::vector<Row> now = compute_rows();
    ASSERT_EQ(now.size() % test::envmap_paths().size(), 0u);
    std::vector<std::string> problems;
    const std::map<std::string, Row> table = read_table(&problems);
    const bool regenerate = std::getenv("ZHC_GOLDEN_REGENERATE") != nullptr;

    std::map<std::string, const Row*> seen;
    for (const Row& r : now) {
        seen[r.key()] = &r;
        const auto it = table.find(r.key());
        if (it == table.end()) {
            problems.push_back("no golden row for " + r.key() + " (a new codec entry or path?): run scripts/golden.sh "
                               "to regenerate tests/golden/metrics.tsv and review the diff");
            continue;
        }
        const Row& g = it->second;
        if (g.metric != r.metric) problems.push_back(r.key() + ": metric " + r.metric + ", table says " + g.metric);
        if (g.bytes != r.bytes)
            problems.push_back(r.key() + ": " + std::to_string(r.bytes) + " bytes, table says " + std::to_string(g.bytes));
        if (!(std::fabs(r.value - g.value) <= g.tolerance)) {
            char b[256];
            std::snprintf(b, sizeof b, ": %s %.9g outside the table's %.9g +- %.3g", r.metric.c_str(), r.value, g.value, g.tolerance);
            problems.push_back(r.key() + b);
        }
        if (g.hash != r.hash) problems.push_back(r.key() + ": output hash " + hex(r.hash) + ", table says " + hex(g.hash));
    }
    for (const auto& [key, g] : table)
        if (!seen.count(key)) problems.push_back("table row " + key + " is no longer produced (entry removed?)");

    if (regenerate) {
        // Print the diff, then write the table (thresholds re-derived from the new values).
        std::ofstream outf(kTablePath, std::ios::trunc);
        ASSERT_TRUE(outf) << "cannot write " << kTablePath;
        outf << kHeader;
        for (const Row& r : now) outf << format_row(r) << "\n";
        ASSERT_TRUE(outf.flush()) << "cannot write " << kTablePath;
        int changed = 0;
        for (const Row& r : now) {
            const auto it = table.find(r.key());
            if (it == table.end()) {
                std::printf("+ %s\n", format_row(r).c_str());
                ++changed;
            } else if (it->second.hash != r.hash || it->second.bytes != r.bytes ||
                       !(std::fabs(r.value - it->second.value) <= it->second.tolerance)) {
                std::printf("- %s\n+ %s\n", format_row(it->second).c_str(), format_row(r).c_str());
                ++changed;
            }
        }
        for (const auto& [key, g] : table)
            if (!seen.count(key)) {
                std::printf("- %s\n", format_row(g).c_str());
                ++changed;
            }
        std::printf("%s: %zu rows written, %d changed, added or removed\n", kTablePath, now.size(), changed);
        return;
    }
    for (std::size_t i = 0; i < problems.size() && i < 40; ++i) ADD_FAILURE() << problems[i];
    if (problems.size() > 40) ADD_FAILURE() << problems.size() - 40 << " more differences";
    if (!problems.empty()) ADD_FAILURE() << "golden table: " << problems.size() << " differences (scripts/golden.sh regenerates)";
}

// The table's own shape: every codec on every map, every block format and quality, the solves.
TEST(Golden, TableCoversEveryPath) {
    std::vector<std::string> problems;
    const auto table = read_table(&problems);
    EXPECT_TRUE(problems.empty()) << problems[0];
    const std::size_t maps = test::envmap_paths().size();
    EXPECT_EQ(maps, 8u);
    std::map<std::string, std::size_t> per_kind;
    for (const auto& [key, r] : table) {
        ++per_kind[r.kind];
        EXPECT_GT(r.tolerance, 0) << key;
        EXPECT_LE(r.tolerance, 0.01 * std::fabs(r.value) + 1e-9) << key << ": a threshold wider than 1% of its value";
    }
    EXPECT_EQ(per_kind["probe"], codecs().size() * maps);
    EXPECT_EQ(per_kind["bc6h"], 4 * 2 * maps);
    EXPECT_EQ(per_kind["bc5"], 2 * 2 * maps);
    EXPECT_EQ(per_kind["bc4"], 2 * 2 * maps);
    EXPECT_EQ(per_kind["irradz"], 5 * maps);
    EXPECT_EQ(per_kind["astc"], 3 * maps);
}

}  // namespace
}  // namespace zhc
