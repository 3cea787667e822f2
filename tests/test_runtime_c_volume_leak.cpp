// runtime/zhc_runtime.h probe volumes with validity, visibility and cell planes (zhc_volume::validity /
// ::visibility / ::planes, docs/runtime.md "Validity and visibility", "Cell planes"):
//  * zhc_volume_sh3 / zhc_volume_irradiance_d bit for bit against a slow twin written from the
//    contract in probe_set.h and docs/runtime.md (per corner: trilinear weight x valid x mask bit
//    7 - corner x (no plane, or the corner's side bit = the point's side of the cell's plane),
//    summed in corner order, divided by the sum; all-zero: plain trilinear), on random grids, random
//    masks and planes, random points, for .zhp files written by zhc's writer (version 2) and read
//    with zhc_volume_from_zhp;
//  * analytic cases: two constant probes separated by a mask bit give exactly the visible probe;
//    an invalid corner at a cell centre gives the mean of the other seven; all eight masked gives
//    the plain trilinear blend bit for bit; absent data gives the plain blend bit for bit; two
//    constant probe layers split by an axis plane give exactly the point's side; an oblique plane
//    keeps exactly the corners on the point's side; a constant field stays constant; "no plane"
//    entries give the masks-only result bit for bit; a plane whose corners all lie on the other
//    side falls back to the plain blend; zhc_plane_normal on its whole code space;
//  * hostile: validity bytes other than 0/1 and a plane on a probe that is the last along an axis
//    are ZHC_ERR_INVALID_VALUE.
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

// The plane rule of docs/runtime.md "Cell planes", written from the text: the normal of the
// octahedral code (a = min(code, 254) / 127 - 1, z = 1 - |a| - |b|, folded when z < 0), normalised.
std::array<double, 3> spec_normal(std::uint8_t ou, std::uint8_t ov) {
    double a = std::min<int>(ou, 254) / 127.0 - 1.0, b = std::min<int>(ov, 254) / 127.0 - 1.0;
    const double z = 1.0 - std::fabs(a) - std::fabs(b);
    if (z < 0) {
        const double sa = a < 0 ? -1.0 : 1.0, sb = b < 0 ? -1.0 : 1.0;
        const double fa = (1.0 - std::fabs(b)) * sa, fb = (1.0 - std::fabs(a)) * sb;
        a = fa;
        b = fb;
    }
    const double len = std::sqrt(a * a + b * b + z * z);
    return {a / len, b / len, z / len};
}

// The signed distance-like value n . (x - c) - offset |spacing| / 65534 of the plane entry `e` of the
// cell with first probe i0 (c its centre); *has = false for "no plane" (offset -32768).
double spec_plane_value(const std::uint8_t* e, const double origin[3], const double spacing[3], const std::uint32_t i0[3],
                        const double x[3], bool* has) {
    const std::int16_t offset = std::int16_t(std::uint16_t(e[2] | (e[3] << 8)));
    *has = offset != -32768;
    if (!*has) return 0;
    const std::array<double, 3> n = spec_normal(e[0], e[1]);
    double dot = 0;
    for (int c = 0; c < 3; ++c) dot += n[size_t(c)] * (x[c] - (origin[c] + (double(i0[c]) + 0.5) * spacing[c]));
    const double diag = std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
    return dot - double(offset) * diag / 65534.0;
}

// A corner region entry (docs/runtime.md "Corner regions"): offset -32768 and bit 7 of byte 4.
bool spec_is_region(const std::uint8_t* e) { return e[2] == 0x00 && e[3] == 0x80 && (e[4] & 0x80) != 0; }

// Whether x lies inside the corner region `e` of the cell with first probe i0, and (*corners) which
// corners do; *margin: the smallest |s_a - t_a| / (31 spacing_a) over the bounding axes (how near x
// is to a face of the region, in cells).
bool spec_region_inside(const std::uint8_t* e, const double origin[3], const double spacing[3], const std::uint32_t i0[3],
                        const double x[3], std::uint8_t* corners, double* margin) {
    const unsigned r = unsigned(e[0]) | unsigned(e[1]) << 8;
    bool inside = true;
    *corners = 0;
    *margin = INFINITY;
    for (int k = 0; k < 8; ++k) {
        bool in = true;
        for (int a = 0; a < 3; ++a) {
            const unsigned q = (r >> (5 * a)) & 31u, d = (e[4] >> a) & 1u;
            in = in && (q == 0 || d == unsigned((k >> a) & 1));
        }
        if (in) *corners = std::uint8_t(*corners | (1u << k));
    }
    for (int a = 0; a < 3; ++a) {
        const unsigned q = (r >> (5 * a)) & 31u, d = (e[4] >> a) & 1u;
        if (q == 0) continue;
        const double s_a = (x[a] - (origin[a] + double(i0[a]) * spacing[a])) * 31.0, t_a = double(q) * spacing[a];
        inside = inside && (d ? s_a >= t_a : s_a < t_a);
        *margin = std::min(*margin, std::fabs(s_a - t_a) / (31.0 * spacing[a]));
    }
    return inside;
}

// The twin: the cell of p (clamped grid coordinate, lower corner <= n - 2), the 8 corner weights,
// masked per the contract, renormalised, blended over the decoded hub in corner order. *near_plane
// (when given) is set when p lies within 1e-12 |spacing| of its cell's plane, where the twin's
// side (computed in another order than the header's) may differ by rounding.
Sh27 twin_sh3(const ProbeSet& set, const std::vector<Sh3Radiance>& hub, const double p[3], bool* near_plane = nullptr) {
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
    // The plane of the cell (entry of corner 0's probe) and p's side of it.
    bool has_plane = false;
    int side = 0;
    std::uint8_t sides = 0;
    if (near_plane) *near_plane = false;
    if (!set.planes.empty()) {
        const std::uint8_t* e = set.planes.data() + 5 * (i0[0] + size_t(g.counts[0]) * (i0[1] + size_t(g.counts[1]) * i0[2]));
        const double origin[3] = {g.origin.x, g.origin.y, g.origin.z}, spacing[3] = {g.spacing.x, g.spacing.y, g.spacing.z};
        if (spec_is_region(e)) {
            double margin = 0;
            has_plane = true;
            side = spec_region_inside(e, origin, spacing, i0, p, &sides, &margin) ? 1 : 0;
            // The header's operations exactly (one subtraction, one product, one comparison per
            // axis): no rounding difference to allow for.
        } else {
            const double value = spec_plane_value(e, origin, spacing, i0, p, &has_plane);
            side = value >= 0 ? 1 : 0;
            sides = e[4];
            const double diag = std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
            if (near_plane && has_plane) *near_plane = std::fabs(value) < 1e-12 * diag;
        }
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
        const bool same_side = !has_plane || ((sides >> corner) & 1) == side;
        m[corner] = valid && seen && same_side ? w[corner] : 0.0;
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

// zhc's normalised irradiance of blended SH3 at the unit normal n (s_l = 1, 2/3, 1/4; the order of
// zhc_volume_irradiance_d's sum).
std::array<double, 3> sh3_irradiance(const Sh27& sh, const double normal[3]) {
    double n[3], y[9];
    zhc__normalize_or_z(normal, n);
    zhc__sh3_basis(n, y);
    std::array<double, 3> rgb{0, 0, 0};
    for (int i = 0; i < 9; ++i) {
        const double s = i == 0 ? 1.0 : (i < 4 ? 2.0 / 3.0 : 0.25);
        for (int k = 0; k < 3; ++k) rgb[size_t(k)] += s * sh[size_t(i * 3 + k)] * y[i];
    }
    return rgb;
}

Sh27 runtime_sh3(const zhc_volume& v, const double p[3]) {
    Sh27 sh;
    zhc_volume_sh3(&v, p, sh.data());
    return sh;
}

// One sample point: whether the runtime's blend equals the twin's bit for bit (the return value),
// whether it differs from the same volume's plain blend, masks and planes dropped (*moved), and
// whether it lies within rounding of its cell's plane (*near_plane, as twin_sh3).
bool matches_twin(const zhc_volume& v, const ProbeSet& set, const std::vector<Sh3Radiance>& hub, const double p[3],
                  bool* moved, bool* near_plane = nullptr) {
    zhc_volume plain = v;
    plain.validity = plain.visibility = plain.planes = nullptr;
    const Sh27 got = runtime_sh3(v, p), want = twin_sh3(set, hub, p, near_plane), base = runtime_sh3(plain, p);
    *moved = std::memcmp(got.data(), base.data(), sizeof got) != 0;
    return std::memcmp(got.data(), want.data(), sizeof got) == 0;
}

// A grid of random probes (random_probe(rng, i * stride) for probe i) over a fixed box, encoded
// as `enc`: the random-volume tests' common start.
Result<ProbeSet> random_grid_set(std::mt19937_64& rng, std::array<std::uint32_t, 3> counts, const char* enc, std::size_t stride) {
    const size_t n = size_t(counts[0]) * counts[1] * counts[2];
    std::vector<Sh3Radiance> hub;
    for (size_t i = 0; i < n; ++i) hub.push_back(random_probe(rng, i * stride));
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kGrid;
    layout.grid.counts = counts;
    layout.grid.origin = {-0.5, 1, 2};
    layout.grid.spacing = {0.75, 0.5, 1.25};
    return encode_probe_set(hub, enc, {}, layout);
}

TEST(RuntimeCVolumeLeak, RandomMasksMatchTheTwinBitForBit) {
    std::mt19937_64 rng(27);
    int samples = 0, renormalised = 0;
    for (const std::array<std::uint32_t, 3>& counts :
         {std::array<std::uint32_t, 3>{4, 3, 2}, {2, 2, 2}, {5, 1, 3}, {1, 1, 1}, {3, 4, 1}})
        for (const char* enc : {"sh3", "zh3_q16", "sh3_q28"})
            for (int sections = 1; sections <= 3; ++sections) {
                const size_t n = size_t(counts[0]) * counts[1] * counts[2];
                auto set = random_grid_set(rng, counts, enc, 3);
                ASSERT_TRUE(bool(set));
                const ProbeLayout& layout = set->layout;
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

// Real data: the leak data `zhc demo` bakes for its scene (walls and boxes through the grid):
// validity and the cell planes (or the visibility masks, whichever sections the bake writes), in its
// zh3_q16 and sh3 containers, against the twin at random points of the box.
TEST(RuntimeCVolumeLeak, DemoBakeLeakDataMatchesTheTwinBitForBit) {
    const std::string dir = test::fresh_dir("runtime_c_volume_leak_demo");
    const auto demo = test::run_zhc({"demo", "-o", dir, "--directions", "16"});
    ASSERT_EQ(demo.exit_code, 0) << demo.err;
    for (const char* name : {"probes_zh3_q16.zhp", "probes_sh3.zhp"}) {
        const std::vector<std::uint8_t> bytes = test::read_bytes(dir + "/" + name);
        auto set = parse_probe_set(bytes, name);
        ASSERT_TRUE(bool(set)) << name;
        ASSERT_EQ(set->validity.size(), set->count) << name;
        ASSERT_TRUE(!set->visibility.empty() || !set->planes.empty()) << name << ": masks or planes";
        size_t hidden_bits = 0, invalid = 0, cells_with_plane = 0;
        for (size_t i = 0; i < set->count; ++i) {
            invalid += set->validity[i] == 0;
            if (!set->visibility.empty())
                for (int b = 0; b < 8; ++b) hidden_bits += ((set->visibility[i] >> b) & 1) == 0;
            if (!set->planes.empty()) cells_with_plane += !(set->planes[5 * i + 2] == 0x00 && set->planes[5 * i + 3] == 0x80);
        }
        EXPECT_GT(hidden_bits + cells_with_plane, 0u) << name << ": the demo's occluders cut the grid";
        const auto decoded = *decode_probe_set(*set);
        zhc_volume v;
        ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK) << name;
        EXPECT_EQ(v.planes != nullptr, !set->planes.empty()) << name;
        const ProbeGrid& g = set->layout.grid;
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        int differ = 0, near = 0;
        const int samples = int(test::scaled_count(4000, 400));  // Release: 4000
        for (int s = 0; s < samples; ++s) {
            double p[3];
            for (int c = 0; c < 3; ++c) p[c] = g.origin[c] + u(rng) * (g.counts[size_t(c)] - 1) * g.spacing[c];
            bool moved = false, near_plane = false;
            const bool same = matches_twin(v, *set, decoded, p, &moved, &near_plane);
            if (near_plane) {
                ++near;
                continue;
            }
            ASSERT_TRUE(same) << name << " sample " << s;
            differ += moved;
        }
        std::printf("demo %s: %zu probes, %zu invalid, %zu hidden mask bits, %zu cells with a plane; %d of %d samples bit for bit "
                    "(%d within 1e-12 |spacing| of a plane), %d differ from the plain blend\n",
                    name, size_t(set->count), invalid, hidden_bits, cells_with_plane, samples - near, samples, near, differ);
        EXPECT_EQ(near, 0) << name;
        EXPECT_GT(differ, 0) << name;
    }
}

// A default `zhc bake` of tests/data/leak_room.json (a closed room with 0.1-thick walls, a lamp
// outside its west wall): the file carries validity and cell planes (no masks); the runtime equals
// the twin bit for bit at random points of the box, and inside the room next to the west wall the
// planes keep the lamp's side out: the mean irradiance there is below half the validity-only blend's.
TEST(RuntimeCVolumeLeak, BakedRoomPlanesMatchTheTwinAndKeepTheLampOut) {
    const std::string dir = test::fresh_dir("runtime_c_volume_leak_room");
    const std::string zhp = dir + "/room.zhp";
    const auto bake = test::run_zhc({"bake", std::string(ZHC_TEST_DATA_DIR) + "/leak_room.json", "-o", zhp, "-r", "zh3_q16"});
    ASSERT_EQ(bake.exit_code, 0) << bake.err;
    const std::vector<std::uint8_t> bytes = test::read_bytes(zhp);
    auto set = parse_probe_set(bytes, "room.zhp");
    ASSERT_TRUE(bool(set));
    ASSERT_EQ(set->validity.size(), set->count);
    EXPECT_TRUE(set->visibility.empty());
    ASSERT_EQ(set->planes.size(), 5 * set->count);
    size_t cells_with_plane = 0;
    for (size_t i = 0; i < set->count; ++i) cells_with_plane += !(set->planes[5 * i + 2] == 0x00 && set->planes[5 * i + 3] == 0x80);
    EXPECT_GE(cells_with_plane, 10u);
    zhc_volume v;
    ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK);
    ASSERT_NE(v.planes, nullptr);
    const auto decoded = *decode_probe_set(*set);
    const ProbeGrid& g = set->layout.grid;
    std::mt19937 rng(38);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int differ = 0, near = 0;
    const int samples = int(test::scaled_count(4000, 400));
    for (int s = 0; s < samples; ++s) {
        double p[3];
        for (int c = 0; c < 3; ++c) p[c] = g.origin[c] + u(rng) * (g.counts[size_t(c)] - 1) * g.spacing[c];
        bool moved = false, near_plane = false;
        const bool same = matches_twin(v, *set, decoded, p, &moved, &near_plane);
        if (near_plane) {
            ++near;
            continue;
        }
        ASSERT_TRUE(same) << "sample " << s;
        differ += moved;
    }
    EXPECT_EQ(near, 0);
    EXPECT_GT(differ, samples / 20);
    // Inside the room within 0.5 of the west wall's inner face (x = 2.4), away from the other walls.
    zhc_volume validity_only = v;
    validity_only.planes = nullptr;
    double with_planes = 0, without = 0;
    for (int s = 0; s < 2000; ++s) {
        const float p[3] = {float(2.45 + 0.45 * u(rng)), float(0.3 + 4.0 * u(rng)), float(0.2 + 2.7 * u(rng))};
        const float n[3] = {float(u(rng) - 0.5), float(u(rng) - 0.5), float(u(rng) - 0.5)};
        float a[3], b[3];
        zhc_volume_irradiance(&v, p, n, a);
        zhc_volume_irradiance(&validity_only, p, n, b);
        with_planes += a[0] + a[1] + a[2];
        without += b[0] + b[1] + b[2];
    }
    std::printf("leak_room bake: %zu cells with a plane; %d of %d samples differ from the plain blend; next to the west wall "
                "inside: mean irradiance %.4g with planes, %.4g without\n",
                cells_with_plane, differ, samples, with_planes / 2000, without / 2000);
    EXPECT_LT(with_planes, 0.5 * without);  // measured: 0.059 of it
}

// A 2x1x1 grid, probe 0 constant a, probe 1 constant b; probe 1 hidden from the cell between them
// (its bit 7 - 1 = 6, the cell on its -x side): anywhere in the cell, except exactly at probe 1
// (where probe 0's weight is 0 and the fallback applies), the sample is exactly probe 0.
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

// ---- cell planes ---------------------------------------------------------------------------------

// A 5-byte plane entry: code (ou, ov), offset, sides.
std::array<std::uint8_t, 5> plane_entry(std::uint8_t ou, std::uint8_t ov, int offset, std::uint8_t sides) {
    const std::uint16_t o = std::uint16_t(std::int16_t(offset));
    return {ou, ov, std::uint8_t(o & 0xFF), std::uint8_t(o >> 8), sides};
}
const std::array<std::uint8_t, 5> kNoPlane = {127, 127, 0x00, 0x80, 0};

// The offset code of the plane with the normal of (ou, ov) through the point `at`, for the cell with
// first probe i0 (rounded; the plane it encodes lies within |spacing| / 131068 of `at`).
int offset_through(std::uint8_t ou, std::uint8_t ov, const double origin[3], const double spacing[3], const std::uint32_t i0[3],
                   const double at[3]) {
    const std::array<double, 3> n = spec_normal(ou, ov);
    double dot = 0;
    for (int c = 0; c < 3; ++c) dot += n[size_t(c)] * (at[c] - (origin[c] + (double(i0[c]) + 0.5) * spacing[c]));
    const double diag = std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
    return int(std::lround(std::clamp(dot * 65534.0 / diag, -32767.0, 32767.0)));
}

// The sides byte of a plane entry as the bake writes it: bit k set when corner k of the cell lies on
// the positive side of the plane the entry encodes.
std::uint8_t geometric_sides(const std::array<std::uint8_t, 5>& e, const double origin[3], const double spacing[3],
                             const std::uint32_t i0[3]) {
    std::uint8_t sides = 0;
    for (int k = 0; k < 8; ++k) {
        const double corner[3] = {origin[0] + (i0[0] + (k & 1)) * spacing[0], origin[1] + (i0[1] + ((k >> 1) & 1)) * spacing[1],
                                  origin[2] + (i0[2] + (k >> 2)) * spacing[2]};
        bool has = false;
        if (spec_plane_value(e.data(), origin, spacing, i0, corner, &has) >= 0) sides = std::uint8_t(sides | (1u << k));
    }
    return sides;
}

// Random plane entries for a grid, as the file format allows them: "no plane" on every probe that is
// the last along an axis of count >= 2; elsewhere 1 in 4 "no plane", else a random normal code (the whole code
// space, 255 included) and offset within half the diagonal of the centre, with the geometric sides
// (1 in 2) or a random sides byte.
std::vector<std::uint8_t> random_planes(std::mt19937_64& rng, const ProbeGrid& g) {
    const std::uint32_t* n = g.counts.data();
    const double origin[3] = {g.origin.x, g.origin.y, g.origin.z}, spacing[3] = {g.spacing.x, g.spacing.y, g.spacing.z};
    std::vector<std::uint8_t> planes;
    for (std::uint32_t z = 0; z < n[2]; ++z)
        for (std::uint32_t y = 0; y < n[1]; ++y)
            for (std::uint32_t x = 0; x < n[0]; ++x) {
                std::array<std::uint8_t, 5> e = kNoPlane;
                e[0] = std::uint8_t(rng());
                e[1] = std::uint8_t(rng());
                e[4] = std::uint8_t(rng() & 0x7F);  // "no plane": any bytes but bit 7 of byte 4
                // The last probe along an axis of count >= 2 starts no cell (along a count-1 axis the
                // one probe starts the flat cell).
                const bool last = (n[0] > 1 && x + 1 == n[0]) || (n[1] > 1 && y + 1 == n[1]) || (n[2] > 1 && z + 1 == n[2]);
                const unsigned kind = unsigned(rng() % 8);
                if (!last && kind >= 5) {
                    // A corner region: random thresholds (0 = the axis does not bound it) and directions.
                    const unsigned r = unsigned(rng() % 32) | unsigned(rng() % 32) << 5 | unsigned(rng() % 32) << 10;
                    e = {std::uint8_t(r & 0xFF), std::uint8_t(r >> 8), 0x00, 0x80, std::uint8_t(0x80 | (rng() & 7))};
                } else if (!last && kind >= 2) {
                    const std::uint32_t i0[3] = {x, y, z};
                    e = plane_entry(e[0], e[1], int(rng() % 65535) - 32767, e[4]);
                    if (rng() % 2) e[4] = geometric_sides(e, origin, spacing, i0);
                }
                planes.insert(planes.end(), e.begin(), e.end());
            }
    return planes;
}

TEST(RuntimeCVolumeLeak, RandomPlanesMatchTheTwinBitForBit) {
    std::mt19937_64 rng(38);
    int samples = 0, by_planes = 0, near = 0, in_region = 0, out_region = 0;
    for (const std::array<std::uint32_t, 3>& counts :
         {std::array<std::uint32_t, 3>{4, 3, 2}, {2, 2, 2}, {3, 3, 3}, {5, 1, 3}, {1, 1, 1}})
        for (const char* enc : {"sh3", "zh3_q16", "sh3_q28"})
            for (int sections = 4; sections <= 7; ++sections) {
                const size_t n = size_t(counts[0]) * counts[1] * counts[2];
                auto set = random_grid_set(rng, counts, enc, 5);
                ASSERT_TRUE(bool(set));
                const ProbeLayout& layout = set->layout;
                if (sections & 1)
                    for (size_t i = 0; i < n; ++i) set->validity.push_back(rng() % 4 == 0 ? 0 : 1);
                if (sections & 2)
                    for (size_t i = 0; i < n; ++i) set->visibility.push_back(std::uint8_t(rng() | rng()));  // each bit set with p = 3/4
                set->planes = random_planes(rng, layout.grid);
                const auto bytes = *serialize_probe_set(*set);
                zhc_zhp_info info;
                ASSERT_EQ(zhc_zhp_parse_header(nullptr, &info, bytes.data(), bytes.size()), ZHC_OK);
                EXPECT_EQ(bytes[21], sections);
                EXPECT_EQ(info.planes_offset, bytes.size() - 5 * n);
                zhc_volume v;
                ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK);
                ASSERT_EQ(v.validity != nullptr, bool(sections & 1));
                ASSERT_EQ(v.visibility != nullptr, bool(sections & 2));
                ASSERT_EQ(v.planes, bytes.data() + bytes.size() - 5 * n);
                EXPECT_EQ(std::memcmp(v.planes, set->planes.data(), 5 * n), 0);
                zhc_volume masks_only = v;
                masks_only.planes = nullptr;
                const auto decoded = *decode_probe_set(*parse_probe_set(bytes, "x"));
                std::uniform_real_distribution<double> u(-0.2, 1.2);
                for (int s = 0; s < 400; ++s) {
                    double p[3];
                    for (int c = 0; c < 3; ++c)
                        p[c] = layout.grid.origin[c] + u(rng) * std::max(1u, counts[size_t(c)] - 1) * layout.grid.spacing[c];
                    if (s % 50 == 0)  // exact probe positions and faces too
                        for (int c = 0; c < 3; ++c) p[c] = layout.grid.origin[c] + double(rng() % counts[size_t(c)]) * layout.grid.spacing[c];
                    bool near_plane = false;
                    const Sh27 want = twin_sh3(*set, decoded, p, &near_plane), got = runtime_sh3(v, p);
                    if (near_plane) {
                        ++near;
                        continue;
                    }
                    ASSERT_EQ(std::memcmp(got.data(), want.data(), sizeof got), 0)
                        << enc << " " << counts[0] << "x" << counts[1] << "x" << counts[2] << " sections " << sections << " sample " << s;
                    const double nrm[3] = {u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
                    double e[3];
                    zhc_volume_irradiance_d(&v, p, nrm, e);
                    const std::array<double, 3> te = sh3_irradiance(want, nrm);
                    ASSERT_EQ(std::memcmp(e, te.data(), sizeof e), 0) << enc << " sample " << s;
                    const Sh27 base = runtime_sh3(masks_only, p);
                    by_planes += std::memcmp(got.data(), base.data(), sizeof got) != 0;
                    ++samples;
                    {  // which kind of entry the sample's cell has, and (a region) which side
                        std::uint32_t i0[3];
                        for (int c = 0; c < 3; ++c) {
                            const std::uint32_t nc = counts[size_t(c)];
                            double t = std::clamp((p[c] - layout.grid.origin[c]) / layout.grid.spacing[c], 0.0, double(nc - 1));
                            i0[c] = std::min(std::uint32_t(t), nc >= 2 ? nc - 2 : 0u);
                        }
                        const std::uint8_t* e = set->planes.data() + 5 * (i0[0] + size_t(counts[0]) * (i0[1] + size_t(counts[1]) * i0[2]));
                        if (spec_is_region(e)) {
                            std::uint8_t corners = 0;
                            double margin = 0;
                            const double origin[3] = {layout.grid.origin.x, layout.grid.origin.y, layout.grid.origin.z};
                            const double spacing[3] = {layout.grid.spacing.x, layout.grid.spacing.y, layout.grid.spacing.z};
                            ++(spec_region_inside(e, origin, spacing, i0, p, &corners, &margin) ? in_region : out_region);
                        }
                    }
                }
            }
    std::printf("volume with planes: %d samples bit for bit, %d differ from the masks-only blend, %d within 1e-12 |spacing| of a plane; "
                "%d inside and %d outside a corner region\n",
                samples, by_planes, near, in_region, out_region);
    EXPECT_GT(by_planes, samples / 8);  // the planes do change the result
    EXPECT_GT(in_region, samples / 50);  // both sides of corner regions are sampled
    EXPECT_GT(out_region, samples / 50);
    EXPECT_EQ(near, 0);
}

// A 2x2x2 sh3 volume of unit spacing whose probes have the constant radiance a (x = 0) or b (x = 1)
// in channel 0 of the DC; the caller sets v.planes.
struct TwoLayers {
    std::vector<float> bytes = std::vector<float>(8 * 27, 0.0f);
    zhc_volume v;
    static constexpr float a = 3.0f, b = 100.0f;
    explicit TwoLayers(std::uint32_t nx = 2) {
        bytes.assign(size_t(nx) * 4 * 27, 0.0f);
        for (std::uint32_t i = 0; i < nx * 4; ++i) bytes[27 * i] = (i % nx) == 0 ? a : ((i % nx) == 1 ? b : 7.0f);
        zhc_probe_format f;
        EXPECT_EQ(zhc_probe_format_init(&f, "sh3"), ZHC_OK);
        const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
        const std::uint32_t counts[3] = {nx, 2, 2};
        EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size() * 4, origin, spacing, counts), ZHC_OK);
    }
};

TEST(RuntimeCVolumeLeak, AnAxisPlaneBetweenTwoConstantLayersGivesThePointsSide) {
    TwoLayers t;
    // The plane x = 0.375 (normal +x: code (254, 127)); the cell's centre is x = 0.5, so the offset is
    // -0.125 along +x, in units of sqrt(3) / 65534. Corners x = 0 (bits 0, 2, 4, 6) on the negative side.
    const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1}, at[3] = {0.375, 0.5, 0.5};
    const std::uint32_t i0[3] = {0, 0, 0};
    const int offset = offset_through(254, 127, origin, spacing, i0, at);
    EXPECT_EQ(offset, int(std::lround(-0.125 * 65534 / std::sqrt(3.0))));
    std::array<std::uint8_t, 5> e = plane_entry(254, 127, offset, 0);
    e[4] = geometric_sides(e, origin, spacing, i0);
    EXPECT_EQ(e[4], 0xAA);
    std::vector<std::uint8_t> planes(5 * 8);
    for (int i = 1; i < 8; ++i) std::copy(kNoPlane.begin(), kNoPlane.end(), planes.begin() + 5 * i);
    std::copy(e.begin(), e.end(), planes.begin());
    t.v.planes = planes.data();
    const double plane_x = 0.5 + offset * std::sqrt(3.0) / 65534;  // the plane the entry encodes
    // Dyadic points (every weight and their sums exact): exactly a or b, and the irradiance of it.
    int checked = 0;
    for (double x : {0.0, 0.125, 0.25, 0.3125, 0.4375, 0.5, 0.75, 0.875, 1.0})
        for (double y : {0.0, 0.25, 0.5, 1.0})
            for (double z : {0.0, 0.5, 0.75}) {
                const double p[3] = {x, y, z}, nrm[3] = {0.3, -0.2, 0.9};
                const bool positive = x >= plane_x;
                // At x = 0 (resp. 1) the other layer has weight 0: still exactly that layer.
                const double want = positive ? TwoLayers::b : TwoLayers::a;
                double sh[27], irr[3];
                zhc_volume_sh3(&t.v, p, sh);
                EXPECT_EQ(sh[0], want) << x << " " << y << " " << z;
                for (int i = 1; i < 27; ++i) EXPECT_EQ(sh[i], 0.0);
                zhc_volume_irradiance_d(&t.v, p, nrm, irr);
                EXPECT_EQ(irr[0], want * ZHC__Y00);
                ++checked;
            }
    EXPECT_EQ(checked, 108);
    // Random points: the point's side within a few ulps; the plain blend is in between.
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    for (int s = 0; s < 2000; ++s) {
        const double p[3] = {u(rng), u(rng), u(rng)};
        if (std::fabs(p[0] - plane_x) < 1e-12) continue;
        double sh[27];
        zhc_volume_sh3(&t.v, p, sh);
        EXPECT_NEAR(sh[0], p[0] >= plane_x ? TwoLayers::b : TwoLayers::a, 1e-15 * TwoLayers::b) << s;
    }
    // The same plane through the second cell of a 3x2x2 grid (entry of probe 1; cell 0 has none):
    // cell 0 (x < 1) blends a and b, cell 1 (x in [1, 2], probes b and 7) splits at x = 1.375.
    TwoLayers t3(3);
    std::vector<std::uint8_t> planes3(5 * 12);
    for (int i = 0; i < 12; ++i) std::copy(kNoPlane.begin(), kNoPlane.end(), planes3.begin() + 5 * i);
    const double at3[3] = {1.375, 0.5, 0.5};
    const std::uint32_t cell1[3] = {1, 0, 0};
    std::array<std::uint8_t, 5> e3 = plane_entry(254, 127, offset_through(254, 127, origin, spacing, cell1, at3), 0);
    e3[4] = geometric_sides(e3, origin, spacing, cell1);
    std::copy(e3.begin(), e3.end(), planes3.begin() + 5);
    t3.v.planes = planes3.data();
    for (double x : {0.25, 0.5, 1.0, 1.25, 1.5, 1.75, 2.0}) {
        const double p[3] = {x, 0.25, 0.75};
        double sh[27];
        zhc_volume_sh3(&t3.v, p, sh);
        const double want = x < 1.0 ? (1 - x) * TwoLayers::a + x * TwoLayers::b : (x < 1.375 ? TwoLayers::b : 7.0);
        EXPECT_EQ(sh[0], want) << x;
    }
}

TEST(RuntimeCVolumeLeak, AnObliquePlaneKeepsTheCornersOnThePointsSide) {
    // 2x2x2, non-uniform spacing, corner k holding the constant k + 1 (channel 0): every set of kept
    // corners gives its own value. Oblique codes (the fold included), planes through random points
    // of the cell, geometric sides; the expected value sum_{k on p's side} w_k (k + 1) / sum w_k.
    std::vector<float> bytes(8 * 27, 0.0f);
    for (int i = 0; i < 8; ++i) bytes[size_t(27 * i)] = float(i + 1);
    zhc_probe_format f;
    ASSERT_EQ(zhc_probe_format_init(&f, "sh3"), ZHC_OK);
    const double origin[3] = {-1, 2, 0.5}, spacing[3] = {1.5, 0.75, 2};
    const std::uint32_t counts[3] = {2, 2, 2}, i0[3] = {0, 0, 0};
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size() * 4, origin, spacing, counts), ZHC_OK);
    std::vector<std::uint8_t> planes(5 * 8);
    for (int i = 0; i < 8; ++i) std::copy(kNoPlane.begin(), kNoPlane.end(), planes.begin() + 5 * i);
    v.planes = planes.data();
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(0, 1);
    int compared = 0, split = 0;
    const std::uint8_t codes[][2] = {{190, 190}, {40, 200}, {10, 20}, {250, 5}, {127, 230}, {100, 60}};
    for (const auto& code : codes)
        for (int plane = 0; plane < 20; ++plane) {
            const double at[3] = {origin[0] + u(rng) * spacing[0], origin[1] + u(rng) * spacing[1], origin[2] + u(rng) * spacing[2]};
            std::array<std::uint8_t, 5> e = plane_entry(code[0], code[1], offset_through(code[0], code[1], origin, spacing, i0, at), 0);
            e[4] = geometric_sides(e, origin, spacing, i0);
            split += e[4] != 0 && e[4] != 0xFF;
            std::copy(e.begin(), e.end(), planes.begin());
            for (int s = 0; s < 50; ++s) {
                double p[3], fr[3];
                for (int c = 0; c < 3; ++c) {
                    fr[c] = u(rng);
                    p[c] = origin[c] + fr[c] * spacing[c];
                }
                bool has = false;
                const double value = spec_plane_value(e.data(), origin, spacing, i0, p, &has);
                ASSERT_TRUE(has);
                if (std::fabs(value) < 1e-9) continue;
                const int side = value >= 0;
                double num = 0, den = 0;
                for (int k = 0; k < 8; ++k) {
                    const double w = ((k & 1) ? fr[0] : 1 - fr[0]) * ((k >> 1 & 1) ? fr[1] : 1 - fr[1]) * ((k >> 2) ? fr[2] : 1 - fr[2]);
                    if (((e[4] >> k) & 1) != side) continue;
                    num += w * (k + 1);
                    den += w;
                }
                ASSERT_GT(den, 0);  // p lies in the cell: some corner is on its side
                double sh[27];
                zhc_volume_sh3(&v, p, sh);
                EXPECT_NEAR(sh[0], num / den, 1e-13) << int(code[0]) << "," << int(code[1]) << " sample " << s;
                ++compared;
            }
        }
    EXPECT_GT(compared, 5500);
    EXPECT_GT(split, 100);  // most planes do cut the cell
}

TEST(RuntimeCVolumeLeak, PlanesKeepAConstantFieldConstant) {
    // Every probe the same radiance: with random validity, masks and planes every blend that keeps any
    // corner is a partition of unity (and the fallback is the plain blend): constant within rounding.
    std::mt19937_64 rng(19);
    Sh3Radiance c = random_probe(rng, 3);
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kGrid;
    layout.grid.counts = {4, 3, 3};
    layout.grid.origin = {0.5, -1, 2};
    layout.grid.spacing = {1.5, 0.5, 0.75};
    const size_t n = 36;
    auto set = encode_probe_set(std::vector<Sh3Radiance>(n, c), "sh3", {}, layout);
    ASSERT_TRUE(bool(set));
    for (size_t i = 0; i < n; ++i) {
        set->validity.push_back(rng() % 5 == 0 ? 0 : 1);
        set->visibility.push_back(std::uint8_t(rng() | rng()));
    }
    set->planes = random_planes(rng, layout.grid);
    const auto bytes = *serialize_probe_set(*set);
    zhc_volume v;
    ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK);
    ASSERT_NE(v.planes, nullptr);
    float decoded[27];
    zhc_decode_probe(&v.format, v.probes, decoded);
    std::uniform_real_distribution<double> u(-0.1, 1.1);
    double worst = 0;
    for (int s = 0; s < 4000; ++s) {
        double p[3], sh[27];
        for (int cc = 0; cc < 3; ++cc)
            p[cc] = layout.grid.origin[cc] + u(rng) * (layout.grid.counts[size_t(cc)] - 1) * layout.grid.spacing[cc];
        zhc_volume_sh3(&v, p, sh);
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) {
                const double want = decoded[i * 3 + k];
                worst = std::max(worst, std::fabs(sh[i * 3 + k] - want) / std::max(1e-300, std::fabs(want)));
            }
    }
    std::printf("constant field with planes: max relative deviation %.3g\n", worst);
    EXPECT_LT(worst, 2e-15);
}

TEST(RuntimeCVolumeLeak, NoPlaneEntriesGiveTheMasksOnlyBlendBitForBit) {
    // Every entry "no plane" (random normal codes and sides bytes but bit 7, which marks a corner
    // region: ignored): the result equals the same volume without planes, bit for bit, with and
    // without validity and masks.
    std::mt19937_64 rng(23);
    std::vector<Sh3Radiance> hub;
    for (size_t i = 0; i < 24; ++i) hub.push_back(random_probe(rng, i));
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kGrid;
    layout.grid.counts = {4, 3, 2};
    layout.grid.spacing = {0.5, 1, 2};
    auto set = encode_probe_set(hub, "zh3_q16", {}, layout);
    ASSERT_TRUE(bool(set));
    for (size_t i = 0; i < 24; ++i) {
        set->validity.push_back(rng() % 4 == 0 ? 0 : 1);
        set->visibility.push_back(std::uint8_t(rng()));
        const std::array<std::uint8_t, 5> e = {std::uint8_t(rng()), std::uint8_t(rng()), 0x00, 0x80, std::uint8_t(rng() & 0x7F)};
        set->planes.insert(set->planes.end(), e.begin(), e.end());
    }
    const auto bytes = *serialize_probe_set(*set);
    zhc_volume v;
    ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK);
    ASSERT_NE(v.planes, nullptr);
    std::uniform_real_distribution<double> u(-0.2, 1.2);
    int differ_from_plain = 0;
    for (int masks = 0; masks < 2; ++masks)
        for (int s = 0; s < 1000; ++s) {
            zhc_volume with = v;
            if (!masks) with.validity = with.visibility = nullptr;
            zhc_volume without = with;
            without.planes = nullptr;
            const double p[3] = {u(rng) * 1.5, u(rng) * 2, u(rng) * 2};
            const Sh27 a = runtime_sh3(with, p), b = runtime_sh3(without, p);
            if (masks) {  // the masks-only blend, bit for bit
                EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof a), 0) << s;
                zhc_volume plain = without;
                plain.validity = plain.visibility = nullptr;
                const Sh27 c = runtime_sh3(plain, p);
                differ_from_plain += std::memcmp(a.data(), c.data(), sizeof a) != 0;
            } else {  // planes alone, none present: every corner kept, the plain weights renormalised
                for (int i = 0; i < 27; ++i) EXPECT_NEAR(a[size_t(i)], b[size_t(i)], 1e-14 * (1 + std::fabs(b[size_t(i)]))) << s;
            }
        }
    EXPECT_GT(differ_from_plain, 250);  // the masks act beside the "no plane" entries
}

TEST(RuntimeCVolumeLeak, APlaneWithEveryCornerOnTheOtherSideFallsBackToPlain) {
    // Sides 0xFF (every corner positive) and points on the negative side: no corner is kept, the
    // result is the plain trilinear blend bit for bit; sides 0x00 and points on the positive side
    // likewise. Points on the corners' side: every corner kept, the plain blend within rounding.
    std::vector<float> bytes(8 * 27, 0.0f);
    for (int i = 0; i < 8; ++i) bytes[size_t(27 * i)] = float(i + 1);
    zhc_probe_format f;
    ASSERT_EQ(zhc_probe_format_init(&f, "sh3"), ZHC_OK);
    const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
    const std::uint32_t counts[3] = {2, 2, 2}, i0[3] = {0, 0, 0};
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size() * 4, origin, spacing, counts), ZHC_OK);
    zhc_volume plain = v;
    std::vector<std::uint8_t> planes(5 * 8);
    for (int i = 0; i < 8; ++i) std::copy(kNoPlane.begin(), kNoPlane.end(), planes.begin() + 5 * i);
    v.planes = planes.data();
    const double at[3] = {0.4, 0.6, 0.5};
    std::mt19937_64 rng(29);
    std::uniform_real_distribution<double> u(0, 1);
    int fallback = 0, kept = 0;
    for (const std::uint8_t sides : {std::uint8_t(0xFF), std::uint8_t(0x00)}) {
        std::array<std::uint8_t, 5> e = plane_entry(200, 90, offset_through(200, 90, origin, spacing, i0, at), sides);
        std::copy(e.begin(), e.end(), planes.begin());
        for (int s = 0; s < 1000; ++s) {
            const double p[3] = {u(rng), u(rng), u(rng)};
            bool has = false;
            const double value = spec_plane_value(e.data(), origin, spacing, i0, p, &has);
            if (std::fabs(value) < 1e-12) continue;
            const bool corners_side = (value >= 0) == (sides == 0xFF);
            const Sh27 a = runtime_sh3(v, p), b = runtime_sh3(plain, p);
            if (!corners_side) {
                EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof a), 0) << int(sides) << " " << s;
                ++fallback;
            } else {
                EXPECT_NEAR(a[0], b[0], 1e-14) << int(sides) << " " << s;
                ++kept;
            }
        }
    }
    EXPECT_GT(fallback, 600);
    EXPECT_GT(kept, 600);
}

TEST(RuntimeCVolumeLeak, PlaneNormalIsExactOnTheAxesUnitAndCoversTheSphere) {
    const struct {
        std::uint8_t ou, ov;
        double n[3];
    } axes[] = {{254, 127, {1, 0, 0}}, {0, 127, {-1, 0, 0}}, {127, 254, {0, 1, 0}}, {127, 0, {0, -1, 0}},
                {127, 127, {0, 0, 1}}, {0, 0, {0, 0, -1}},   {254, 254, {0, 0, -1}}, {0, 254, {0, 0, -1}},
                {254, 0, {0, 0, -1}},  {255, 127, {1, 0, 0}}, {255, 255, {0, 0, -1}}};
    for (const auto& a : axes) {
        double n[3];
        zhc_plane_normal(a.ou, a.ov, n);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(n[c], a.n[c]) << int(a.ou) << "," << int(a.ov) << " component " << c;
    }
    // Every code: unit length, and the decode of code 255 is that of 254.
    int lower = 0;
    double worst_len = 0;
    std::vector<std::array<double, 3>> all;
    for (int ou = 0; ou < 256; ++ou)
        for (int ov = 0; ov < 256; ++ov) {
            double n[3];
            zhc_plane_normal(std::uint8_t(ou), std::uint8_t(ov), n);
            worst_len = std::max(worst_len, std::fabs(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) - 1));
            lower += n[2] < 0;
            const std::array<double, 3> s = spec_normal(std::uint8_t(ou), std::uint8_t(ov));
            EXPECT_EQ(std::memcmp(n, s.data(), sizeof n), 0) << ou << "," << ov;
            if (ou < 255 && ov < 255) all.push_back({n[0], n[1], n[2]});
        }
    EXPECT_LT(worst_len, 4e-16);
    EXPECT_GT(lower, 20000);  // the folded half of the code square
    // Coverage: every direction of the sphere (lower hemisphere included) has a code within 1 degree.
    std::mt19937_64 rng(31);
    std::uniform_real_distribution<double> u(0, 1);
    double worst_angle = 0, worst_lower = 0;
    for (int s = 0; s < 400; ++s) {
        const Vec3 d = test::uniform_direction(u(rng), u(rng));
        double best = -1;
        for (const auto& n : all) best = std::max(best, n[0] * d.x + n[1] * d.y + n[2] * d.z);
        const double angle = std::acos(std::min(1.0, best)) * 180 / M_PI;
        worst_angle = std::max(worst_angle, angle);
        if (d.z < 0) worst_lower = std::max(worst_lower, angle);
    }
    std::printf("plane normals: %d of 65536 codes below the equator; worst unit-length error %.3g; nearest code within %.3f deg (lower hemisphere %.3f)\n",
                lower, worst_len, worst_angle, worst_lower);
    EXPECT_LT(worst_angle, 1.0);
    EXPECT_GT(worst_lower, 0.0);
}

TEST(RuntimeCVolumeLeak, FilesWithPlanesAndAPlaneOnALastProbe) {
    std::mt19937_64 rng(37);
    std::vector<Sh3Radiance> hub;
    for (int i = 0; i < 12; ++i) hub.push_back(random_probe(rng, std::uint64_t(i)));
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kGrid;
    layout.grid.counts = {3, 2, 2};
    auto set = encode_probe_set(hub, "zh3_q16", {}, layout);
    ASSERT_TRUE(bool(set));
    set->planes = random_planes(rng, layout.grid);
    // Probe 0 and 1 own the grid's two cells: give both a plane.
    for (size_t i : {size_t(0), size_t(1)}) {
        const std::array<std::uint8_t, 5> e = plane_entry(200, 100, 1234, 0x5A);
        std::copy(e.begin(), e.end(), set->planes.begin() + std::ptrdiff_t(5 * i));
    }
    auto bytes = *serialize_probe_set(*set);
    EXPECT_EQ(bytes[21], 4);  // planes only
    zhc_volume v;
    ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK);
    EXPECT_EQ(v.validity, nullptr);
    EXPECT_EQ(v.visibility, nullptr);
    ASSERT_EQ(v.planes, bytes.data() + bytes.size() - 60);
    EXPECT_EQ(v.planes[5 * 1 + 2], std::uint8_t(1234 & 0xFF));
    // A plane on each probe that is the last along some axis (x = 2, y = 1 or z = 1): refused.
    const auto reseal = [](std::vector<std::uint8_t>& b) {
        const std::uint32_t crc = crc32({b.data() + kProbeFileHeaderBytes, b.size() - kProbeFileHeaderBytes});
        test::put32(b, 176, crc);
        test::put32(b, 180, crc32({b.data(), 180}));
    };
    int refused = 0;
    for (size_t i = 0; i < 12; ++i) {
        const size_t x = i % 3, y = i / 3 % 2, z = i / 6;
        if (x + 1 != 3 && y + 1 != 2 && z + 1 != 2) continue;
        for (const int offset : {0, -32767, 32767}) {
            auto bad = bytes;
            const size_t at = bad.size() - 60 + 5 * i;
            bad[at + 2] = std::uint8_t(std::uint16_t(offset) & 0xFF);
            bad[at + 3] = std::uint8_t(std::uint16_t(offset) >> 8);
            reseal(bad);
            EXPECT_EQ(zhc_volume_from_zhp(&v, bad.data(), bad.size()), ZHC_ERR_INVALID_VALUE) << i << " " << offset;
            EXPECT_EQ(v.probes, nullptr);
            EXPECT_EQ(v.planes, nullptr);
            zhc_zhp_info info;
            EXPECT_EQ(zhc_zhp_open(nullptr, &info, bad.data(), bad.size()), ZHC_ERR_INVALID_VALUE);
            const auto parsed = parse_probe_set(bad, "x");
            ASSERT_FALSE(bool(parsed)) << i;
            EXPECT_EQ(parsed.error().code, ErrorCode::kInvalidValue) << i;
            ++refused;
        }
    }
    EXPECT_EQ(refused, 3 * 10);
    // The same change on a probe that owns a cell is accepted.
    auto ok = bytes;
    ok[ok.size() - 60 + 2] = 0x00;
    ok[ok.size() - 60 + 3] = 0x00;
    reseal(ok);
    EXPECT_EQ(zhc_volume_from_zhp(&v, ok.data(), ok.size()), ZHC_OK);
    // Corner regions (docs/runtime.md "Corner regions"): accepted on a probe that owns a cell,
    // refused on a last probe (probe 2: x = 2) and with a reserved bit set, by the header and the
    // C++ reader alike.
    const auto with_entry = [&](size_t probe, std::array<std::uint8_t, 5> e) {
        auto b = bytes;
        std::copy(e.begin(), e.end(), b.begin() + std::ptrdiff_t(b.size() - 60 + 5 * probe));
        reseal(b);
        return b;
    };
    const std::array<std::uint8_t, 5> region = {0x2F, 0x21, 0x00, 0x80, 0x85};  // q = 15, 9, 8; d = 1, 0, 1
    for (const auto& [b, code] : {std::pair{with_entry(0, region), ZHC_OK},
                                  std::pair{with_entry(2, region), ZHC_ERR_INVALID_VALUE},
                                  std::pair{with_entry(2, {0, 0, 0x00, 0x80, 0x80}), ZHC_ERR_INVALID_VALUE},
                                  std::pair{with_entry(0, {0x2F, 0xA1, 0x00, 0x80, 0x85}), ZHC_ERR_INVALID_VALUE},
                                  std::pair{with_entry(0, {0x2F, 0x21, 0x00, 0x80, 0x8D}), ZHC_ERR_INVALID_VALUE}}) {
        EXPECT_EQ(zhc_volume_from_zhp(&v, b.data(), b.size()), code);
        EXPECT_EQ(parse_probe_set(b, "x").ok(), code == ZHC_OK);
    }
    // A flat 3x1x2 grid: the y = 0 probes start the flat cells (x < 2, z = 0: probes 0 and 1 hold a
    // plane), the others are the last along x or z.
    layout.grid.counts = {3, 1, 2};
    auto flat = encode_probe_set(std::vector<Sh3Radiance>(hub.begin(), hub.begin() + 6), "sh3", {}, layout);
    ASSERT_TRUE(bool(flat));
    for (size_t i = 0; i < 6; ++i) {
        const std::array<std::uint8_t, 5> e = i < 2 ? plane_entry(254, 127, -100, 0xAA) : kNoPlane;
        flat->planes.insert(flat->planes.end(), e.begin(), e.end());
    }
    auto flat_bytes = *serialize_probe_set(*flat);
    ASSERT_EQ(zhc_volume_from_zhp(&v, flat_bytes.data(), flat_bytes.size()), ZHC_OK);
    ASSERT_NE(v.planes, nullptr);
    EXPECT_EQ(v.planes[2], std::uint8_t(-100 & 0xFF));
    for (size_t i = 2; i < 6; ++i) {
        auto bad = flat_bytes;
        bad[bad.size() - 30 + 5 * i + 3] = 0;
        reseal(bad);
        EXPECT_EQ(zhc_volume_from_zhp(&v, bad.data(), bad.size()), ZHC_ERR_INVALID_VALUE) << "flat " << i;
    }
}

}  // namespace
}  // namespace zhc
