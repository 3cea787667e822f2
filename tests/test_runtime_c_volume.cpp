// runtime/zhc_runtime.h probe volumes (zhc_volume_*, docs/runtime.md "Probe volumes"):
//  * acceptance: the strict-C99 tests/runtime_c/zhc_volume_sample builds a volume with
//    zhc_volume_from_zhp from the .zhp files `zhc demo` writes (and `zhc convert` of them to every
//    codec table entry) and samples 10,000 random points in and around the grid with random
//    normals; the result must match a slow double-precision twin (zhc's own decode_probe_set, hat
//    function weights summed over EVERY probe, SH3 irradiance) within 1e-5 of the mean irradiance;
//  * analytic cases: constant probes give the trilinear interpolant (corners, centres, clamping
//    outside), a field linear in position is reproduced, count-1 axes;
//  * the reason for blending decoded SH3: blending ZH3's stored numbers is not the same;
//  * hostile bytes: truncations, bit flips and checksum-fixed header mutations never crash and
//    agree with zhc's reader.
// Built with -ffp-contract=off like the codec (tests/runtime_c/CMakeLists.txt).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/probe_set.h"
#include "formats/probes/probe_file.h"
#include "runtime_c_helpers.h"
#include "support.h"
#include "zhc_runtime.h"

namespace zhc {
namespace {

using namespace runtime_c_test;
using D3 = std::array<double, 3>;

// ---- the slow, obviously-correct twin --------------------------------------------------------

// Irradiance at p, n of a grid of decoded probes: grid coordinates t_c clamped to [0, n_c - 1],
// probe weight prod_c max(0, 1 - |t_c - x_c|) (the trilinear hat function) summed over every
// probe of the grid, SH3 blended in double, E = sum_i s_l c_i Y_i(n / |n|).
D3 reference_irradiance(const std::vector<Sh3Radiance>& hub, const ProbeGrid& g, const D3& p, const D3& normal) {
    D3 t;
    for (int c = 0; c < 3; ++c) {
        const double hi = double(g.counts[size_t(c)] - 1);
        const double u = (p[size_t(c)] - g.origin[c]) / g.spacing[c];
        t[size_t(c)] = std::isnan(u) ? 0.0 : std::min(std::max(u, 0.0), hi);  // NaN: the low face
    }
    double sh[9][3] = {};
    for (std::uint32_t z = 0; z < g.counts[2]; ++z)
        for (std::uint32_t y = 0; y < g.counts[1]; ++y)
            for (std::uint32_t x = 0; x < g.counts[0]; ++x) {
                const double w = std::max(0.0, 1 - std::abs(t[0] - x)) * std::max(0.0, 1 - std::abs(t[1] - y)) *
                                 std::max(0.0, 1 - std::abs(t[2] - z));
                if (w == 0) continue;
                const Sh3Radiance& probe = hub[x + size_t(g.counts[0]) * (y + size_t(g.counts[1]) * z)];
                for (int i = 0; i < 9; ++i)
                    for (int k = 0; k < 3; ++k) sh[i][k] += w * double(probe[i][k]);
            }
    const Vec3 n = normalize_or({normal[0], normal[1], normal[2]}, {0, 0, 1});
    const auto y = sh3_basis(n);
    const double band[9] = {1, 2.0 / 3, 2.0 / 3, 2.0 / 3, 0.25, 0.25, 0.25, 0.25, 0.25};
    D3 e{0, 0, 0};
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) e[size_t(k)] += band[i] * sh[i][k] * y[size_t(i)];
    return e;
}

struct Sample {
    std::array<float, 3> p, n;
};

// n random points in the grid's box grown by a quarter of its size on every side (a count-1 axis:
// +-1 spacing), random unit normals; then every probe position (exact grid nodes).
std::vector<Sample> random_samples(const ProbeGrid& g, int n, unsigned seed) {
    test::Rng rng(seed);
    std::vector<Sample> out;
    for (int i = 0; i < n; ++i) {
        Sample s;
        for (int c = 0; c < 3; ++c) {
            const double size = g.counts[size_t(c)] > 1 ? (g.counts[size_t(c)] - 1) * g.spacing[c] : 2 * g.spacing[c];
            const double lo = g.counts[size_t(c)] > 1 ? g.origin[c] - 0.25 * size : g.origin[c] - g.spacing[c];
            s.p[size_t(c)] = float(lo + 1.5 * size * rng.u());
        }
        const Vec3 d = rng.dir();
        s.n = {float(d.x), float(d.y), float(d.z)};
        out.push_back(s);
    }
    for (std::uint32_t z = 0; z < g.counts[2]; ++z)
        for (std::uint32_t y = 0; y < g.counts[1]; ++y)
            for (std::uint32_t x = 0; x < g.counts[0]; ++x) {
                const Vec3 d = rng.dir();
                out.push_back({{float(g.origin.x + x * g.spacing.x), float(g.origin.y + y * g.spacing.y),
                                float(g.origin.z + z * g.spacing.z)},
                               {float(d.x), float(d.y), float(d.z)}});
            }
    return out;
}

// Runs the C99 sampler on a .zhp file and the points; its three floats per point.
std::vector<std::array<float, 3>> run_c99_sampler(const std::string& zhp, const std::vector<Sample>& samples,
                                                  const std::string& dir) {
    const std::string points = dir + "/points.txt";
    {
        FILE* f = std::fopen(points.c_str(), "w");
        EXPECT_NE(f, nullptr);
        if (!f) return {};
        for (const Sample& s : samples)
            std::fprintf(f, "%.9g %.9g %.9g %.9g %.9g %.9g\n", s.p[0], s.p[1], s.p[2], s.n[0], s.n[1], s.n[2]);
        std::fclose(f);
    }
    // --plain: the masks dropped (see check_file).
    const std::string cmd = std::string("'") + ZHC_VOLUME_SAMPLE + "' '" + zhp + "' '" + points + "' --plain";
    FILE* pipe = popen(cmd.c_str(), "r");
    EXPECT_NE(pipe, nullptr);
    if (!pipe) return {};
    std::vector<std::array<float, 3>> out;
    std::array<float, 3> rgb;
    while (std::fscanf(pipe, "%f %f %f", &rgb[0], &rgb[1], &rgb[2]) == 3) out.push_back(rgb);
    EXPECT_EQ(pclose(pipe), 0) << cmd;
    return out;
}

// The acceptance measurement on one grid .zhp: C99 sampler and in-process header against the twin.
void check_file(const std::string& path, const std::string& what, const std::string& dir, int n, unsigned seed,
                double* worst_out = nullptr) {
    const std::vector<std::uint8_t> bytes = test::read_bytes(path);
    auto set = parse_probe_set(bytes, path);
    ASSERT_TRUE(bool(set)) << what;
    ASSERT_EQ(set->layout.kind, ProbeLayoutKind::kGrid) << what;
    auto hub = decode_probe_set(*set);
    ASSERT_TRUE(bool(hub)) << what;
    const ProbeGrid& g = set->layout.grid;
    const std::vector<Sample> samples = random_samples(g, n, seed);
    const auto c99 = run_c99_sampler(path, samples, dir);
    ASSERT_EQ(c99.size(), samples.size()) << what;
    zhc_volume v;
    ASSERT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_OK) << what;
    // The double twin here is the plain trilinear blend: a baked file's validity, visibility masks
    // and cell planes (the demo's) are dropped, in-process and in the C99 program (--plain). The
    // blend with them has its own twin (test_runtime_c_volume_leak.cpp, on baked files too).
    ASSERT_EQ(v.validity != nullptr, !set->validity.empty()) << what;
    ASSERT_EQ(v.planes != nullptr, !set->planes.empty()) << what;
    v.validity = v.visibility = nullptr;
    v.planes = nullptr;
    std::vector<D3> ref;
    double mean = 0;
    for (const Sample& s : samples) {
        ref.push_back(reference_irradiance(*hub, g, {s.p[0], s.p[1], s.p[2]}, {s.n[0], s.n[1], s.n[2]}));
        for (double e : ref.back()) mean += std::abs(e);
    }
    mean /= 3.0 * double(samples.size());
    ASSERT_GT(mean, 0) << what;
    double worst = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
        float rgb[3];
        zhc_volume_irradiance(&v, samples[i].p.data(), samples[i].n.data(), rgb);
        for (int k = 0; k < 3; ++k) {
            // The C99 program and this C++ translation unit run the same header code.
            ASSERT_EQ(std::memcmp(&rgb[k], &c99[i][size_t(k)], 4), 0) << what << " sample " << i;
            worst = std::max(worst, std::abs(double(c99[i][size_t(k)]) - ref[i][size_t(k)]) / mean);
        }
    }
    std::printf("volume %-24s %zu samples, mean irradiance %.6g, max error / mean %.3g\n", what.c_str(), samples.size(),
                mean, worst);
    EXPECT_LE(worst, 1e-5) << what;
    if (worst_out) *worst_out = worst;
}

// Acceptance: the demo's grid (`zhc demo`: probes_sh3.zhp, probes_zh3_q16.zhp) and `zhc convert`
// of it to every codec table entry (a new entry is included automatically).
TEST(RuntimeCVolume, DemoZhpFilesOfEveryEncodingMatchTheDoubleTwin) {
    const std::string dir = test::fresh_dir("runtime_c_volume_demo");
    const auto demo = test::run_zhc({"demo", "-o", dir + "/demo", "--directions", "16"});
    ASSERT_EQ(demo.exit_code, 0) << demo.err;
    const std::string sh3 = dir + "/demo/probes_sh3.zhp";
    // 10,000 points per file (scripts/sanitize.sh's ZHC_TEST_SAMPLE_SCALE: fewer, same paths).
    const int n = int(test::sample_count(10000));
    check_file(dir + "/demo/probes_zh3_q16.zhp", "demo zh3_q16", dir, n, 26);
    int files = 0;
    for (const Codec& c : runtime_codecs()) {  // the engine layouts are no .zhp the runtime opens
        std::string path = sh3;
        if (std::string(c.name) != "sh3") {
            path = dir + "/" + std::string(c.name) + ".zhp";
            const auto r = test::run_zhc({"convert", sh3, "--to", std::string(c.name), "-o", path});
            ASSERT_EQ(r.exit_code, 0) << c.name << ": " << r.err;
        }
        check_file(path, std::string(c.name), dir, n, 1000u + unsigned(files));
        ++files;
    }
    EXPECT_EQ(files, ZHC_ENC_COUNT);
}

// A grid with count-1 axes written by zhc's writer, random probes, random quantiser parameters.
TEST(RuntimeCVolume, GridsWithCountOneAxesFromZhcsWriterMatchTheTwin) {
    const std::string dir = test::fresh_dir("runtime_c_volume_axes");
    std::mt19937_64 rng(7);
    int file = 0;
    for (const std::array<std::uint32_t, 3>& counts :
         {std::array<std::uint32_t, 3>{5, 1, 3}, {1, 1, 1}, {1, 4, 1}, {2, 2, 2}})
        for (const char* enc : {"sh3", "zh3_q16", "hall_adaptive_q16", "zh3_lum", "sh3_q28"}) {
            std::vector<Sh3Radiance> hub;
            for (std::uint32_t i = 0; i < counts[0] * counts[1] * counts[2]; ++i) hub.push_back(random_probe(rng, i * 4));
            ProbeLayout layout;
            layout.kind = ProbeLayoutKind::kGrid;
            layout.grid.counts = counts;
            layout.grid.origin = {-1.5, 0.25, 3};
            layout.grid.spacing = {0.75, 2, 0.125};
            auto set = encode_probe_set(hub, enc, file % 2 ? random_params(rng, enc) : CodecOptions{}, layout);
            ASSERT_TRUE(bool(set)) << enc;
            auto bytes = serialize_probe_set(*set);
            ASSERT_TRUE(bool(bytes));
            const std::string path = dir + "/g" + std::to_string(file++) + ".zhp";
            test::write_bytes(path, *bytes);
            check_file(path, std::string(enc) + " " + std::to_string(counts[0]) + "x" + std::to_string(counts[1]) + "x" +
                                 std::to_string(counts[2]),
                       dir, 2000, 50u + unsigned(file));
        }
}

// ---- analytic cases ----------------------------------------------------------------------------

// sh3 bytes of a probe list (27 floats each).
std::vector<std::uint8_t> sh3_bytes(const std::vector<std::array<float, 27>>& probes) {
    std::vector<std::uint8_t> out(probes.size() * 108);
    for (size_t i = 0; i < probes.size(); ++i) std::memcpy(out.data() + i * 108, probes[i].data(), 108);
    return out;
}

zhc_probe_format sh3_format() {
    zhc_probe_format f;
    EXPECT_EQ(zhc_probe_format_init(&f, "sh3"), ZHC_OK);
    return f;
}

TEST(RuntimeCVolume, ConstantProbesGiveTheTrilinearInterpolant) {
    const std::uint32_t counts[3] = {3, 4, 2};
    const double origin[3] = {-1, 2, 0.5}, spacing[3] = {0.5, 0.25, 2};
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.1, 5);
    std::vector<std::array<float, 27>> probes(24);
    std::vector<D3> value(24);  // each probe's irradiance (constant radiance: the same at every normal)
    for (size_t i = 0; i < 24; ++i) {
        probes[i].fill(0.0f);
        for (int k = 0; k < 3; ++k) {
            probes[i][size_t(k)] = float(u(rng));
            value[i][size_t(k)] = double(probes[i][size_t(k)]) * ZHC__Y00;
        }
    }
    const auto bytes = sh3_bytes(probes);
    const zhc_probe_format f = sh3_format();
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
    const auto probe_at = [&](int x, int y, int z) { return value[size_t(x + 3 * (y + 4 * z))]; };
    const auto close = [](const D3& a, const D3& b) {
        for (int k = 0; k < 3; ++k)
            if (!(std::abs(a[size_t(k)] - b[size_t(k)]) <= 1e-13 * std::abs(b[size_t(k)]))) return false;
        return true;
    };
    test::Rng r(3);
    int checked = 0;
    // Corners: the probe's own value, at every normal.
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 3; ++x) {
                const double p[3] = {origin[0] + x * spacing[0], origin[1] + y * spacing[1], origin[2] + z * spacing[2]};
                const Vec3 nv = r.dir();
                const double n[3] = {nv.x, nv.y, nv.z};
                D3 e;
                zhc_volume_irradiance_d(&v, p, n, e.data());
                EXPECT_TRUE(close(e, probe_at(x, y, z))) << x << y << z;
                ++checked;
            }
    // Cell centres: the mean of the 8 corners.
    for (int z = 0; z < 1; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 2; ++x) {
                const double p[3] = {origin[0] + (x + 0.5) * spacing[0], origin[1] + (y + 0.5) * spacing[1],
                                     origin[2] + (z + 0.5) * spacing[2]};
                D3 want{0, 0, 0};
                for (int c = 0; c < 8; ++c) {
                    const D3 pv = probe_at(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2));
                    for (int k = 0; k < 3; ++k) want[size_t(k)] += pv[size_t(k)] / 8;
                }
                const double n[3] = {0, 0, -3};  // not unit: normalised by the function
                D3 e;
                zhc_volume_irradiance_d(&v, p, n, e.data());
                EXPECT_TRUE(close(e, want)) << x << y << z;
                ++checked;
            }
    // Random inside points: the trilinear formula written out; outside points: the value at the
    // nearest point of the box (bit for bit).
    for (int i = 0; i < 2000; ++i) {
        double p[3], q[3];
        double t[3];
        for (int c = 0; c < 3; ++c) {
            const double size = (counts[c] - 1) * spacing[c];
            p[c] = origin[c] - size + 3 * size * r.u();
            q[c] = std::min(std::max(p[c], origin[c]), origin[c] + size);
            t[c] = (q[c] - origin[c]) / spacing[c];
        }
        const int x0 = std::min(int(t[0]), 1), y0 = std::min(int(t[1]), 2), z0 = 0;
        const double fx = t[0] - x0, fy = t[1] - y0, fz = t[2] - z0;
        D3 want{0, 0, 0};
        for (int c = 0; c < 8; ++c) {
            const int bx = c & 1, by = (c >> 1) & 1, bz = c >> 2;
            const double w = (bx ? fx : 1 - fx) * (by ? fy : 1 - fy) * (bz ? fz : 1 - fz);
            const D3 pv = probe_at(x0 + bx, y0 + by, z0 + bz);
            for (int k = 0; k < 3; ++k) want[size_t(k)] += w * pv[size_t(k)];
        }
        const double n[3] = {r.u() - 0.5, r.u() - 0.5, r.u() - 0.5};
        D3 e, eq;
        zhc_volume_irradiance_d(&v, p, n, e.data());
        zhc_volume_irradiance_d(&v, q, n, eq.data());
        EXPECT_TRUE(close(e, want)) << i;
        EXPECT_EQ(std::memcmp(e.data(), eq.data(), sizeof e), 0) << "clamping, sample " << i;
        ++checked;
    }
    // Far outside, infinite and NaN positions: clamped (NaN -> the low face), finite.
    const double far[][3] = {{-1e30, 1e30, 0}, {INFINITY, -INFINITY, INFINITY}, {NAN, NAN, NAN}};
    const double near[][3] = {{-1, 2.75, 0.5}, {0, 2, 2.5}, {-1, 2, 0.5}};
    for (int i = 0; i < 3; ++i) {
        const double n[3] = {0, 1, 0};
        D3 a, b;
        zhc_volume_irradiance_d(&v, far[i], n, a.data());
        zhc_volume_irradiance_d(&v, near[i], n, b.data());
        EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof a), 0) << i;
    }
    std::printf("constant probes: %d positions checked\n", checked);
}

// Probes whose 27 SH3 coefficients are an affine function of the probe position: the blend is that
// function at the (clamped) point, at any normal.
TEST(RuntimeCVolume, AFieldLinearInPositionIsReproduced) {
    const std::uint32_t counts[3] = {4, 3, 5};
    const double origin[3] = {0.5, -2, 1}, spacing[3] = {1.5, 0.5, 0.75};
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> u(-1, 1);
    double a[27], b[27][3];
    for (int j = 0; j < 27; ++j) {
        a[j] = 4 * u(rng);
        for (int c = 0; c < 3; ++c) b[j][c] = u(rng);
    }
    const auto field = [&](const double p[3], double out[27]) {
        for (int j = 0; j < 27; ++j) out[j] = a[j] + b[j][0] * p[0] + b[j][1] * p[1] + b[j][2] * p[2];
    };
    std::vector<std::array<float, 27>> probes;
    double coefficient_scale = 0;
    for (std::uint32_t z = 0; z < counts[2]; ++z)
        for (std::uint32_t y = 0; y < counts[1]; ++y)
            for (std::uint32_t x = 0; x < counts[0]; ++x) {
                const double p[3] = {origin[0] + x * spacing[0], origin[1] + y * spacing[1], origin[2] + z * spacing[2]};
                double c[27];
                field(p, c);
                std::array<float, 27> fp;
                for (int j = 0; j < 27; ++j) {
                    fp[size_t(j)] = float(c[j]);
                    coefficient_scale = std::max(coefficient_scale, std::abs(c[j]));
                }
                probes.push_back(fp);
            }
    const auto bytes = sh3_bytes(probes);
    const zhc_probe_format f = sh3_format();
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
    test::Rng r(5);
    double worst = 0;
    for (int i = 0; i < 5000; ++i) {
        double p[3], q[3];
        for (int c = 0; c < 3; ++c) {
            const double size = (counts[c] - 1) * spacing[c];
            p[c] = origin[c] - 0.5 * size + 2 * size * r.u();
            q[c] = std::min(std::max(p[c], origin[c]), origin[c] + size);
        }
        double want_sh[27], got_sh[27];
        field(q, want_sh);
        zhc_volume_sh3(&v, p, got_sh);
        for (int j = 0; j < 27; ++j) worst = std::max(worst, std::abs(got_sh[j] - want_sh[j]) / coefficient_scale);
        const Vec3 nv = r.dir();
        const double n[3] = {nv.x, nv.y, nv.z};
        D3 e;
        zhc_volume_irradiance_d(&v, p, n, e.data());
        // E = sum_i s_l c_i Y_i(n) of the field itself.
        const auto y = sh3_basis(nv);
        for (int k = 0; k < 3; ++k) {
            double want = 0;
            for (int j = 0; j < 9; ++j) want += (j == 0 ? 1.0 : (j < 4 ? 2.0 / 3 : 0.25)) * want_sh[j * 3 + k] * y[size_t(j)];
            worst = std::max(worst, std::abs(e[size_t(k)] - want) / coefficient_scale);
        }
    }
    std::printf("linear field: max error %.3g of the largest coefficient (float storage)\n", worst);
    EXPECT_LE(worst, 2e-7);  // the probes are stored as float (half an ulp: 6e-8 relative)
}

TEST(RuntimeCVolume, CountOneAxesDegenerateToLowerDimensionalInterpolation) {
    const zhc_probe_format f = sh3_format();
    const double origin[3] = {1, 2, 3}, spacing[3] = {0.5, 0.5, 0.5};
    // 4 x 1 x 1: linear interpolation along x; y and z do not matter.
    std::vector<std::array<float, 27>> probes(4);
    for (int i = 0; i < 4; ++i) {
        probes[size_t(i)].fill(0.0f);
        probes[size_t(i)][0] = probes[size_t(i)][1] = probes[size_t(i)][2] = float(1 + i * i);
    }
    auto bytes = sh3_bytes(probes);
    const std::uint32_t line[3] = {4, 1, 1};
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), origin, spacing, line), ZHC_OK);
    test::Rng r(9);
    for (int i = 0; i < 500; ++i) {
        const double x = 0.5 + 2.5 * r.u();
        const double p[3] = {x, 2 + 10 * (r.u() - 0.5), 3 + 10 * (r.u() - 0.5)}, base[3] = {x, 2, 3};
        const double n[3] = {0, 0, 1};
        D3 e, e0;
        zhc_volume_irradiance_d(&v, p, n, e.data());
        zhc_volume_irradiance_d(&v, base, n, e0.data());
        EXPECT_EQ(std::memcmp(e.data(), e0.data(), sizeof e), 0);
        const double t = std::min(std::max((x - 1) / 0.5, 0.0), 3.0);
        const int i0 = std::min(int(t), 2);
        const double want = ((1 - (t - i0)) * (1 + i0 * i0) + (t - i0) * (1 + (i0 + 1) * (i0 + 1))) * ZHC__Y00;
        EXPECT_NEAR(e[0], want, 1e-13 * want);
    }
    // 1 x 1 x 1: the one probe everywhere.
    const std::uint32_t one[3] = {1, 1, 1};
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), 108, origin, spacing, one), ZHC_OK);
    for (int i = 0; i < 100; ++i) {
        const double p[3] = {100 * (r.u() - 0.5), 100 * (r.u() - 0.5), 100 * (r.u() - 0.5)}, n[3] = {1, 0, 0};
        D3 e;
        zhc_volume_irradiance_d(&v, p, n, e.data());
        EXPECT_EQ(e[1], double(probes[0][1]) * ZHC__Y00);
    }
}

// Why the blend is defined on DECODED SH3: ZH3 stores (DC, L1, zonal f20) and the L2 band is
// f20 Y2(axis) with the axis the normalised L1 of THAT probe. Blending the stored numbers first
// puts the blended f20 on the blended axis, which is not the blend of the probes' L2.
TEST(RuntimeCVolume, BlendingStoredZh3IsNotBlendingItsRadiance) {
    zhc_probe_format f;
    ASSERT_EQ(zhc_probe_format_init(&f, "zh3_lum"), ZHC_OK);
    // Two probes: L1 along x and along y, the same zonal coefficient.
    float a[15] = {}, b[15] = {};
    for (int k = 0; k < 3; ++k) {
        a[k] = b[k] = 2.0f;
        a[9 + k] = -1.0f;  // L11 = -x: L1 vector along +x
        b[3 + k] = -1.0f;  // L1-1 = -y: along +y
        a[12 + k] = b[12 + k] = 0.8f;
    }
    std::vector<std::uint8_t> bytes(120);
    std::memcpy(bytes.data(), a, 60);
    std::memcpy(bytes.data() + 60, b, 60);
    const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1}, mid[3] = {0.5, 0, 0};
    const std::uint32_t counts[3] = {2, 1, 1};
    zhc_volume v;
    ASSERT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
    double blended[27];
    zhc_volume_sh3(&v, mid, blended);
    float da[27], db[27], stored_mid[15], ds[27];
    ASSERT_EQ(zhc_decode_probe(&f, a, da), ZHC_OK);
    ASSERT_EQ(zhc_decode_probe(&f, b, db), ZHC_OK);
    for (int j = 0; j < 15; ++j) stored_mid[j] = 0.5f * (a[j] + b[j]);
    ASSERT_EQ(zhc_decode_probe(&f, stored_mid, ds), ZHC_OK);
    double linear_gap = 0, stored_gap = 0;
    for (int j = 0; j < 27; ++j) {
        linear_gap = std::max(linear_gap, std::abs(blended[j] - 0.5 * (double(da[j]) + double(db[j]))));
        stored_gap = std::max(stored_gap, std::abs(double(ds[j]) - 0.5 * (double(da[j]) + double(db[j]))));
    }
    std::printf("zh3 midpoint: decoded blend off by %.3g, stored-number blend off by %.3g (DC 2)\n", linear_gap, stored_gap);
    EXPECT_LE(linear_gap, 1e-7);
    EXPECT_GT(stored_gap, 0.1);
}

// ---- API errors and hostile bytes ----------------------------------------------------------------

TEST(RuntimeCVolume, InitRejectsInvalidGridsAndArguments) {
    const zhc_probe_format f = sh3_format();
    std::vector<std::uint8_t> bytes(108 * 8, 0);
    const double o[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    const std::uint32_t c[3] = {2, 2, 2};
    zhc_volume v;
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o, s, c), ZHC_OK);
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size() - 1, o, s, c), ZHC_ERR_TRUNCATED);
    EXPECT_EQ(v.probes, nullptr);
    EXPECT_EQ(zhc_volume_init(nullptr, &f, bytes.data(), bytes.size(), o, s, c), ZHC_ERR_ARGUMENT);
    EXPECT_EQ(zhc_volume_init(&v, nullptr, bytes.data(), bytes.size(), o, s, c), ZHC_ERR_ARGUMENT);
    EXPECT_EQ(zhc_volume_init(&v, &f, nullptr, bytes.size(), o, s, c), ZHC_ERR_ARGUMENT);
    zhc_probe_format bad = f;
    bad.bits = 9;
    EXPECT_EQ(zhc_volume_init(&v, &bad, bytes.data(), bytes.size(), o, s, c), ZHC_ERR_ARGUMENT);
    for (double spacing : {0.0, -1.0, -0.0, double(NAN), double(INFINITY), -1e308}) {
        const double s2[3] = {1, spacing, 1};
        EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o, s2, c), ZHC_ERR_INVALID_VALUE) << spacing;
    }
    const double o2[3] = {0, double(NAN), 0};
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o2, s, c), ZHC_ERR_INVALID_VALUE);
    // The far corner origin + (count - 1) spacing overflows.
    const double o3[3] = {0, 1e308, 0}, s3[3] = {1, 1e308, 1};
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o3, s3, c), ZHC_ERR_INVALID_VALUE);
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o, s3, c), ZHC_OK);
    const std::uint32_t zero[3] = {2, 0, 2}, huge[3] = {1u << 10, 1u << 10, 1u << 7};
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o, s, zero), ZHC_ERR_INVALID_VALUE);
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o, s, huge), ZHC_ERR_TOO_LARGE);
    const std::uint32_t max32[3] = {0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFFFFFFu};
    EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o, s, max32), ZHC_ERR_TOO_LARGE);
    // A zeroed volume samples to zeros.
    std::memset(&v, 0, sizeof v);
    const double p[3] = {0, 0, 0}, n[3] = {0, 0, 1};
    D3 e{1, 1, 1};
    zhc_volume_irradiance_d(&v, p, n, e.data());
    EXPECT_EQ(e[0], 0.0);
}

// Grid files of every codec table entry from zhc's writer (random probes, random parameters).
std::vector<std::vector<std::uint8_t>> grid_files() {
    std::mt19937_64 rng(26);
    std::vector<std::vector<std::uint8_t>> files;
    for (const Codec& c : runtime_codecs()) {  // the engine layouts are no .zhp the runtime opens
        std::vector<Sh3Radiance> hub;
        for (int i = 0; i < 12; ++i) hub.push_back(random_probe(rng, std::uint64_t(i)));
        ProbeLayout layout;
        layout.kind = ProbeLayoutKind::kGrid;
        layout.grid.counts = {3, 2, 2};
        layout.grid.origin = {1, -2, 0.5};
        layout.grid.spacing = {0.25, 1, 2};
        auto set = encode_probe_set(hub, c.name, files.size() % 2 ? random_params(rng, c.name) : CodecOptions{}, layout);
        EXPECT_TRUE(bool(set)) << c.name;
        if (!set) continue;
        auto bytes = serialize_probe_set(*set);
        EXPECT_TRUE(bool(bytes));
        if (bytes) files.push_back(*bytes);
    }
    return files;
}

// What zhc_volume_from_zhp must return for `file`, from zhc's reader and the grid rules.
int expected_volume_code(const std::vector<std::uint8_t>& file) {
    zhc_probe_format f;
    zhc_zhp_info info;
    const int open = zhc_zhp_open(&f, &info, file.data(), file.size());
    if (open != ZHC_OK) return open;  // agreement of zhc_zhp_open with zhc's reader: test_runtime_c_zhp
    auto set = parse_probe_set(file, "x");
    EXPECT_TRUE(bool(set));
    if (!set) return -1;
    if (set->layout.kind != ProbeLayoutKind::kGrid) return ZHC_ERR_NOT_GRID;
    const ProbeGrid& g = set->layout.grid;
    for (int c = 0; c < 3; ++c) {
        if (g.counts[size_t(c)] == 0 || !(g.spacing[c] > 0)) return ZHC_ERR_INVALID_VALUE;
        if (!std::isfinite(g.origin[c] + double(g.counts[size_t(c)] - 1) * g.spacing[c])) return ZHC_ERR_INVALID_VALUE;
    }
    return ZHC_OK;
}

// Samples a volume at random, extreme and non-finite points; where zhc's reader decodes the same
// file, compares with the twin (finite references).
void sample_hostile(const zhc_volume& v, const std::vector<std::uint8_t>& file, std::mt19937_64& rng) {
    auto set = parse_probe_set(file, "x");
    ASSERT_TRUE(bool(set));
    auto hub = decode_probe_set(*set);
    ASSERT_TRUE(bool(hub));
    double scale = 1;  // the largest finite decoded coefficient: the size of the rounding errors
    for (const Sh3Radiance& h : *hub)
        for (int j = 0; j < 9; ++j)
            for (int k = 0; k < 3; ++k)
                if (std::isfinite(h[j][k])) scale = std::max(scale, double(std::abs(h[j][k])));
    std::uniform_real_distribution<double> u(-10, 10);
    for (int i = 0; i < 12; ++i) {
        D3 p{u(rng), u(rng), u(rng)}, n{u(rng), u(rng), u(rng)};
        if (i == 0) p = {NAN, INFINITY, -INFINITY};
        if (i == 1) n = {0, 0, 0};
        if (i == 2) n = {NAN, 1, 0};
        D3 e;
        zhc_volume_irradiance_d(&v, p.data(), n.data(), e.data());
        const D3 want = reference_irradiance(*hub, set->layout.grid, p, n);
        for (int k = 0; k < 3; ++k) {
            if (std::isfinite(want[size_t(k)])) {
                ASSERT_NEAR(e[size_t(k)], want[size_t(k)], 1e-12 * scale) << i << " " << k;
            }
        }
    }
}

TEST(RuntimeCVolume, HostileBytesNeverCrashAndAgreeWithZhcsReader) {
    const auto files = grid_files();
    ASSERT_EQ(files.size(), size_t(ZHC_ENC_COUNT));
    std::mt19937_64 rng(2626);
    std::uint64_t accepted = 0, rejected = 0;
    const auto check = [&](const std::vector<std::uint8_t>& bad, const std::string& what) {
        zhc_volume v;
        const int r = zhc_volume_from_zhp(&v, bad.data(), bad.size());
        ASSERT_EQ(r, expected_volume_code(bad)) << what;
        if (r == ZHC_OK) {
            ++accepted;
            sample_hostile(v, bad, rng);
        } else {
            ++rejected;
            EXPECT_EQ(v.probes, nullptr) << what;
        }
    };
    for (size_t i = 0; i < files.size(); ++i) {
        const auto& good = files[i];
        check(good, "file " + std::to_string(i));
        for (size_t len = 0; len < good.size(); len += (len < 200 ? 1 : 7))
            check(std::vector<std::uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(len)), "truncated " + std::to_string(len));
        for (size_t byte = 0; byte < good.size(); ++byte) {
            auto bad = good;
            bad[byte] ^= std::uint8_t(1u << (rng() % 8));
            check(bad, "flip " + std::to_string(byte));
        }
        if (HasFailure()) return;
    }
    // Header field mutations with the header CRC fixed (grid values, counts, layout, parameters).
    const long mutations = test::scaled_count(20000, 2000);  // the Release pass: all 20,000
    for (long it = 0; it < mutations; ++it) {
        auto bad = files[rng() % files.size()];
        const int edits = 1 + int(rng() % 3);
        for (int e = 0; e < edits; ++e) {
            // Half the edits in the grid fields (bytes 96..155) and the layout byte 20.
            const size_t at = rng() % 2 ? 96 + size_t(rng() % 60) : (rng() % 4 ? size_t(rng() % 180) : 20);
            switch (rng() % 4) {
                case 0: bad[at] = std::uint8_t(rng()); break;
                case 1: bad[at] = std::uint8_t(rng() % 4); break;
                case 2: bad[at] ^= std::uint8_t(1u << (rng() % 8)); break;
                default: bad[at] = 0; break;
            }
        }
        test::put32(bad, 180, crc32({bad.data(), 180}));
        check(bad, "mutation " + std::to_string(it));
        if (HasFailure()) return;
    }
    std::printf("volume from hostile .zhp: %llu accepted (sampled), %llu rejected\n", (unsigned long long)accepted,
                (unsigned long long)rejected);
    EXPECT_GT(accepted, 100u);
    EXPECT_GT(rejected, 1000u);
}

TEST(RuntimeCVolume, NonGridCompressedAndBadSpacingFilesGetTheirCodes) {
    std::mt19937_64 rng(3);
    std::vector<Sh3Radiance> hub;
    for (int i = 0; i < 8; ++i) hub.push_back(random_probe(rng, std::uint64_t(i)));
    ProbeLayout none, points, grid;
    points.kind = ProbeLayoutKind::kPositions;
    for (int i = 0; i < 8; ++i) points.positions.push_back({float(i), 0, 1});
    grid.kind = ProbeLayoutKind::kGrid;
    grid.grid.counts = {2, 2, 2};
    grid.grid.origin = {0, 0, 0};
    grid.grid.spacing = {1, 1, 1};
    const auto file = [&](const ProbeLayout& l, int zstd) {
        auto set = encode_probe_set(hub, "zh3_q16", CodecOptions{}, l);
        EXPECT_TRUE(bool(set));
        ProbeFileWriteOptions wo;
        wo.zstd_level = zstd;
        auto bytes = serialize_probe_set(*set, wo);
        EXPECT_TRUE(bool(bytes));
        return *bytes;
    };
    zhc_volume v;
    auto g = file(grid, 0);
    EXPECT_EQ(zhc_volume_from_zhp(&v, g.data(), g.size()), ZHC_OK);
    EXPECT_EQ(v.probe_size, 16u);
    EXPECT_EQ(v.probes, g.data() + ZHC_ZHP_HEADER_BYTES);
    auto n = file(none, 0), p = file(points, 0), z = file(grid, 3);
    EXPECT_EQ(zhc_volume_from_zhp(&v, n.data(), n.size()), ZHC_ERR_NOT_GRID);
    EXPECT_EQ(zhc_volume_from_zhp(&v, p.data(), p.size()), ZHC_ERR_NOT_GRID);
    EXPECT_EQ(zhc_volume_from_zhp(&v, z.data(), z.size()), ZHC_ERR_COMPRESSED);
    EXPECT_EQ(zhc_volume_from_zhp(&v, nullptr, 0), ZHC_ERR_TRUNCATED);
    EXPECT_EQ(zhc_volume_from_zhp(nullptr, g.data(), g.size()), ZHC_ERR_ARGUMENT);
    // Origin y (bytes 104..111), spacing y (bytes 128..135) = (0, 0), (0, -2), (0, -0), (1e308, 1e308)
    // (far corner overflows): a valid .zhp, not a volume.
    for (const std::array<double, 2>& os : {std::array<double, 2>{0, 0}, {0, -2}, {0, -0.0}, {1e308, 1e308}}) {
        const double s = os[1];
        std::uint8_t b[16];
        std::memcpy(b, os.data(), 16);
        auto bad = test::zhp_with_header_edit(g, 104, {b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]});
        bad = test::zhp_with_header_edit(bad, 128, {b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15]});
        EXPECT_TRUE(bool(parse_probe_set(bad, "x"))) << s;
        EXPECT_EQ(zhc_volume_from_zhp(&v, bad.data(), bad.size()), ZHC_ERR_INVALID_VALUE) << s;
    }
}

}  // namespace
}  // namespace zhc
