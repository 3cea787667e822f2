// runtime/zhc_runtime.h probe volumes with validity and visibility (zhc_volume::validity /
// ::visibility, docs/runtime.md "Validity and visibility"):
//  * zhc_volume_sh3 bit for bit against a slow twin written from the contract in probe_set.h (per
//    corner: trilinear weight x valid x mask bit 7 - corner, summed in corner order, divided by the
//    sum; all-zero: plain trilinear), on random grids, random masks, random points, for .zhp files
//    written by zhc's writer (version 2) and read with zhc_volume_from_zhp;
//  * analytic cases: two constant probes separated by a mask bit give exactly the visible probe;
//    an invalid corner at a cell centre gives the mean of the other seven; all eight masked gives
//    the plain trilinear blend bit for bit; absent data gives the plain blend bit for bit;
//  * hostile: validity bytes other than 0/1 in a file are ZHC_ERR_INVALID_VALUE.
// Built with -ffp-contract=off like the codec (tests/runtime_c/CMakeLists.txt).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "codec/probe/probe_set.h"
#include "formats/probes/probe_file.h"
#include "runtime_c_helpers.h"
#include "support.h"
#include "zhc_runtime.h"

namespace zhc {
namespace {

using namespace runtime_c_test;
using Sh27 = std::array<double, 27>;

// The twin: the cell of p (clamped grid coordinate, lower corner <= n - 2), the 8 corner weights,
// masked per the contract, renormalised, blended over the decoded hub in corner order.
Sh27 twin_sh3(const ProbeSet& set, const std::vector<Sh3Radiance>& hub, const double p[3]) {
    const ProbeGrid& g = set.layout.grid;
    std::uint32_t i0[3];
    double f[3];
    for (int c = 0; c < 3; ++c) {
        const std::uint32_t n = g.counts[size_t(c)];
        double t = (p[c] - g.origin[c]) / g.spacing[c];
        if (std::isnan(t) || t < 0) t = 0;
        if (t > double(n - 1)) t = double(n - 1);
        std::uint32_t i = std::uint32_t(std::floor(t));
        if (n >= 2 && i > n - 2) i = n - 2;
        i0[c] = i;
        f[c] = n >= 2 ? t - double(i) : 0.0;
    }
    double w[8], m[8], sum = 0;
    size_t idx[8];
    for (int corner = 0; corner < 8; ++corner) {
        const int d[3] = {corner & 1, (corner >> 1) & 1, corner >> 2};
        w[corner] = 1;
        for (int c = 0; c < 3; ++c) w[corner] *= d[c] ? f[c] : 1 - f[c];
        idx[corner] = (i0[0] + std::uint32_t(d[0])) +
                      size_t(g.counts[0]) * ((i0[1] + std::uint32_t(d[1])) + size_t(g.counts[1]) * (i0[2] + std::uint32_t(d[2])));
        // A corner of weight 0 is never read: on an axis of one probe its index lies past the grid.
        const int bit = 7 - (d[0] + 2 * d[1] + 4 * d[2]);
        const bool valid = w[corner] != 0 && (set.validity.empty() || set.validity[idx[corner]] == 1);
        const bool seen = w[corner] != 0 && (set.visibility.empty() || ((set.visibility[idx[corner]] >> bit) & 1));
        m[corner] = valid && seen ? w[corner] : 0.0;
        sum += m[corner];
    }
    Sh27 sh{};
    for (int corner = 0; corner < 8; ++corner) {
        const double wc = sum > 0 ? m[corner] / sum : w[corner];
        if (wc == 0) continue;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) sh[size_t(i * 3 + k)] += wc * double(hub[idx[corner]][i][k]);
    }
    return sh;
}

Sh27 runtime_sh3(const zhc_volume& v, const double p[3]) {
    Sh27 sh;
    zhc_volume_sh3(&v, p, sh.data());
    return sh;
}

// One sample point: whether the runtime's blend equals the twin's bit for bit (the return value),
// and whether it differs from the same volume's plain blend, masks dropped (*moved).
bool matches_twin(const zhc_volume& v, const ProbeSet& set, const std::vector<Sh3Radiance>& hub, const double p[3],
                  bool* moved) {
    zhc_volume plain = v;
    plain.validity = plain.visibility = nullptr;
    const Sh27 got = runtime_sh3(v, p), want = twin_sh3(set, hub, p), base = runtime_sh3(plain, p);
    *moved = std::memcmp(got.data(), base.data(), sizeof got) != 0;
    return std::memcmp(got.data(), want.data(), sizeof got) == 0;
}

TEST(RuntimeCVolumeLeak, RandomMasksMatchTheTwinBitForBit) {
    std::mt19937_64 rng(27);
    int samples = 0, renormalised = 0;
    for (const std::array<std::uint32_t, 3>& counts :
         {std::array<std::uint32_t, 3>{4, 3, 2}, {2, 2, 2}, {5, 1, 3}, {1, 1, 1}, {3, 4, 1}})
        for (const char* enc : {"sh3", "zh3_q16", "sh3_q28"})
            for (int sections = 1; sections <= 3; ++sections) {
                const size_t n = size_t(counts[0]) * counts[1] * counts[2];
                std::vector<Sh3Radiance> hub;
                for (size_t i = 0; i < n; ++i) hub.push_back(random_probe(rng, i * 3));
                ProbeLayout layout;
                layout.kind = ProbeLayoutKind::kGrid;
                layout.grid.counts = counts;
                layout.grid.origin = {-0.5, 1, 2};
                layout.grid.spacing = {0.75, 0.5, 1.25};
                auto set = encode_probe_set(hub, enc, {}, layout);
                ASSERT_TRUE(bool(set));
                if (sections & 1)
                    for (size_t i = 0; i < n; ++i) set->validity.push_back(rng() % 4 == 0 ? 0 : 1);
                if (sections & 2)
                    for (size_t i = 0; i < n; ++i) set->visibility.push_back(std::uint8_t(rng() & rng()));  // each bit set with p = 1/4
                const auto bytes = *serialize_probe_set(*set);
                zhc_volume v;
                ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK);
                ASSERT_EQ(v.validity != nullptr, bool(sections & 1));
                ASSERT_EQ(v.visibility != nullptr, bool(sections & 2));
                // The runtime decodes as zhc does (test_runtime_c): the twin uses zhc's hub.
                const auto decoded = *decode_probe_set(*parse_probe_set(bytes, "x"));
                std::uniform_real_distribution<double> u(-0.2, 1.2);
                for (int s = 0; s < 400; ++s) {
                    double p[3];
                    for (int c = 0; c < 3; ++c)
                        p[c] = layout.grid.origin[c] + u(rng) * std::max(1u, counts[size_t(c)] - 1) * layout.grid.spacing[c];
                    if (s % 50 == 0)  // exact probe positions and faces too
                        for (int c = 0; c < 3; ++c) p[c] = layout.grid.origin[c] + double(rng() % counts[size_t(c)]) * layout.grid.spacing[c];
                    bool moved = false;
                    ASSERT_TRUE(matches_twin(v, *set, decoded, p, &moved))
                        << enc << " " << counts[0] << "x" << counts[1] << "x" << counts[2] << " sample " << s;
                    renormalised += moved;
                    ++samples;
                }
            }
    std::printf("masked volume: %d samples bit for bit, %d differ from the plain blend\n", samples, renormalised);
    EXPECT_GT(renormalised, samples / 4);  // the masks do change the result
}

// A 2x1x1 grid, probe 0 constant a, probe 1 constant b; probe 1 hidden from the cell between them
// (its bit 7 - 1 = 6, the cell on its -x side): anywhere in the cell, except exactly at probe 1
// (where probe 0's weight is 0 and the fallback applies), the sample is exactly probe 0.
// Real data: the masks `zhc demo` bakes for its scene (walls and boxes through the grid), in its
// zh3_q16 and sh3 containers, against the twin at random points of the box.
TEST(RuntimeCVolumeLeak, DemoBakeMasksMatchTheTwinBitForBit) {
    const std::string dir = test::fresh_dir("runtime_c_volume_leak_demo");
    const auto demo = test::run_zhc({"demo", "-o", dir, "--directions", "16"});
    ASSERT_EQ(demo.exit_code, 0) << demo.err;
    for (const char* name : {"probes_zh3_q16.zhp", "probes_sh3.zhp"}) {
        const std::vector<std::uint8_t> bytes = test::read_bytes(dir + "/" + name);
        auto set = parse_probe_set(bytes, name);
        ASSERT_TRUE(bool(set)) << name;
        ASSERT_EQ(set->validity.size(), set->count) << name;
        ASSERT_EQ(set->visibility.size(), set->count) << name;
        size_t hidden_bits = 0, invalid = 0;
        for (size_t i = 0; i < set->count; ++i) {
            invalid += set->validity[i] == 0;
            for (int b = 0; b < 8; ++b) hidden_bits += ((set->visibility[i] >> b) & 1) == 0;
        }
        EXPECT_GT(hidden_bits, 0u) << name << ": the demo's occluders cut the grid";
        const auto decoded = *decode_probe_set(*set);
        zhc_volume v;
        ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK) << name;
        const ProbeGrid& g = set->layout.grid;
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        int differ = 0;
        const int samples = int(test::scaled_count(4000, 400));  // Release: 4000
        for (int s = 0; s < samples; ++s) {
            double p[3];
            for (int c = 0; c < 3; ++c) p[c] = g.origin[c] + u(rng) * (g.counts[size_t(c)] - 1) * g.spacing[c];
            bool moved = false;
            ASSERT_TRUE(matches_twin(v, *set, decoded, p, &moved)) << name << " sample " << s;
            differ += moved;
        }
        std::printf("demo %s: %zu probes, %zu invalid, %zu hidden mask bits; %d of %d samples bit for bit, %d differ from the plain blend\n",
                    name, size_t(set->count), invalid, hidden_bits, samples, samples, differ);
        EXPECT_GT(differ, 0) << name;
    }
}

TEST(RuntimeCVolumeLeak, TwoConstantsSeparatedByAMaskBitGiveTheVisibleOne) {
    std::vector<float> bytes(54, 0.0f);
    const float a[3] = {3.0f, 0.5f, 0.25f}, b[3] = {100.0f, 200.0f, 300.0f};
    for (int k = 0; k < 3; ++k) {
        bytes[size_t(k)] = a[k];
        bytes[size_t(27 + k)] = b[k];
    }
    zhc_probe_format f;
    ASSERT_EQ(zhc_probe_format_init(&f, "sh3"), ZHC_OK);
    const double origin[3] = {0, 0, 0}, spacing[3] = {2, 1, 1};
    const std::uint32_t counts[3] = {2, 1, 1};
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size() * 4, origin, spacing, counts), ZHC_OK);
    const std::uint8_t visibility[2] = {0xFF, std::uint8_t(0xFF & ~(1u << 6))};
    v.visibility = visibility;
    const double n[3] = {0.3, -0.2, 0.9};
    for (double x : {-5.0, 0.0, 0.001, 0.5, 1.0, 1.7, 1.999999}) {
        const double p[3] = {x, 0.25, -3};
        double e[3], sh[27];
        zhc_volume_sh3(&v, p, sh);
        zhc_volume_irradiance_d(&v, p, n, e);
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(sh[k], double(a[k])) << x;  // weight 1 exactly: w0 / w0
            EXPECT_EQ(e[k], double(a[k]) * ZHC__Y00) << x;
        }
        for (int i = 3; i < 27; ++i) EXPECT_EQ(sh[i], 0.0);
    }
    // Exactly at probe 1 (and beyond, clamped): probe 0's weight is 0, probe 1's is masked: the
    // documented fallback is the plain trilinear blend, probe 1 itself.
    for (double x : {2.0, 7.0}) {
        const double p[3] = {x, 0, 0};
        double sh[27];
        zhc_volume_sh3(&v, p, sh);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(sh[k], double(b[k])) << x;
    }
    // Validity does the same: probe 1 invalid.
    const std::uint8_t validity[2] = {1, 0};
    v.visibility = nullptr;
    v.validity = validity;
    const double p[3] = {1.2, 0, 0};
    double sh[27];
    zhc_volume_sh3(&v, p, sh);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(sh[k], double(a[k]));
    // And a mask bit of another cell side (bit 7, the +x side) changes nothing here.
    const std::uint8_t other[2] = {0xFF, 0x7F};
    v.validity = nullptr;
    v.visibility = other;
    zhc_volume_sh3(&v, p, sh);
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(sh[k], 0.4 * a[k] + 0.6 * b[k]);
}

TEST(RuntimeCVolumeLeak, InvalidCornerAllMaskedFallbackAndAbsentData) {
    // 2x2x2 grid of constants c_i = i + 1 (channel 0); at the cell centre every weight is 1/8.
    std::vector<float> bytes(8 * 27, 0.0f);
    for (int i = 0; i < 8; ++i) bytes[size_t(27 * i)] = float(i + 1);
    zhc_probe_format f;
    ASSERT_EQ(zhc_probe_format_init(&f, "sh3"), ZHC_OK);
    const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
    const std::uint32_t counts[3] = {2, 2, 2};
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size() * 4, origin, spacing, counts), ZHC_OK);
    ASSERT_EQ(v.validity, nullptr);
    ASSERT_EQ(v.visibility, nullptr);
    const double centre[3] = {0.5, 0.5, 0.5};
    double plain[27], sh[27];
    zhc_volume_sh3(&v, centre, plain);
    EXPECT_EQ(plain[0], 4.5);  // (1 + ... + 8) / 8
    // Probe 3 invalid: the mean of the other seven, (36 - 4) / 7.
    std::uint8_t validity[8] = {1, 1, 1, 0, 1, 1, 1, 1};
    v.validity = validity;
    zhc_volume_sh3(&v, centre, sh);
    EXPECT_NEAR(sh[0], 32.0 / 7.0, 1e-15);
    // Corners 0 and 7 hidden through their masks (corner 0 reads bit 7, corner 7 reads bit 0).
    std::uint8_t visibility[8] = {0x7F, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFE};
    v.visibility = visibility;
    zhc_volume_sh3(&v, centre, sh);
    EXPECT_NEAR(sh[0], (36.0 - 4 - 1 - 8) / 5.0, 1e-15);
    // Every corner masked: the plain trilinear blend, bit for bit, at many points.
    std::memset(validity, 0, sizeof validity);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-0.5, 1.5);
    for (int s = 0; s < 200; ++s) {
        const double p[3] = {u(rng), u(rng), u(rng)};
        zhc_volume copy = v;
        copy.validity = copy.visibility = nullptr;
        zhc_volume_sh3(&copy, p, plain);
        zhc_volume_sh3(&v, p, sh);
        EXPECT_EQ(std::memcmp(plain, sh, sizeof sh), 0) << s;
    }
    // All bits set and all valid: the renormalised blend equals the plain one (sum of the
    // weights is 1 up to rounding).
    std::memset(validity, 1, sizeof validity);
    std::memset(visibility, 0xFF, sizeof visibility);
    for (int s = 0; s < 200; ++s) {
        const double p[3] = {u(rng), u(rng), u(rng)};
        zhc_volume copy = v;
        copy.validity = copy.visibility = nullptr;
        zhc_volume_sh3(&copy, p, plain);
        zhc_volume_sh3(&v, p, sh);
        EXPECT_NEAR(sh[0], plain[0], 1e-14) << s;
    }
}

TEST(RuntimeCVolumeLeak, FilesWithoutSectionsAndBadValidityBytes) {
    std::mt19937_64 rng(3);
    std::vector<Sh3Radiance> hub;
    for (int i = 0; i < 8; ++i) hub.push_back(random_probe(rng, std::uint64_t(i)));
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kGrid;
    layout.grid.counts = {2, 2, 2};
    auto set = encode_probe_set(hub, "zh3_q16", {}, layout);
    ASSERT_TRUE(bool(set));
    const auto v1 = *serialize_probe_set(*set);
    zhc_volume v;
    ASSERT_EQ(zhc_volume_from_zhp(&v, v1.data(), v1.size()), ZHC_OK);
    EXPECT_EQ(v.validity, nullptr);
    EXPECT_EQ(v.visibility, nullptr);
    set->validity = {1, 1, 1, 1, 0, 1, 1, 1};
    auto v2 = *serialize_probe_set(*set);
    ASSERT_EQ(zhc_volume_from_zhp(&v, v2.data(), v2.size()), ZHC_OK);
    EXPECT_EQ(v.validity, v2.data() + v2.size() - 8);
    EXPECT_EQ(v.visibility, nullptr);
    v2[v2.size() - 3] = 2;
    const std::uint32_t crc = crc32({v2.data() + kProbeFileHeaderBytes, v2.size() - kProbeFileHeaderBytes});
    test::put32(v2, 176, crc);
    test::put32(v2, 180, crc32({v2.data(), 180}));
    EXPECT_EQ(zhc_volume_from_zhp(&v, v2.data(), v2.size()), ZHC_ERR_INVALID_VALUE);
    EXPECT_EQ(v.probes, nullptr);
    EXPECT_EQ(parse_probe_set(v2, "x").error().code, ErrorCode::kInvalidValue);
}

}  // namespace
}  // namespace zhc
