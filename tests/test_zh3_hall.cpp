// Hallucinate-solve (hall_solved, hall_solved_q16) and the adaptive hallucination scale
// (hall_adaptive_q16): codec/zh3_hall.h, issue 18 items 3-4.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>

#include "codec/audit.h"
#include "codec/codec.h"
#include "codec/probe_set.h"
#include "codec/quantize.h"
#include "codec/zh3.h"
#include "codec/zh3_hall.h"
#include "tests/support.h"

namespace zhc {
namespace {

struct Rng {
    std::mt19937 gen;
    explicit Rng(unsigned seed) : gen(seed) {}
    double u() { return std::uniform_real_distribution<double>(0, 1)(gen); }
    Vec3 dir() {
        const double u1 = u();
        return test::uniform_direction(u1, u());
    }
};

// Synthetic interior: a dim coloured ambient plus 2-5 coloured lights (deltas, spheres) from
// different directions; non-negative lighting.
Sh3Radiance synthetic_interior(Rng& rng) {
    const float amb = static_cast<float>(0.02 + 0.1 * rng.u());
    Sh3Radiance sh = project_constant({amb, static_cast<float>(amb * (0.6 + 0.8 * rng.u())), static_cast<float>(amb * (0.6 + 0.8 * rng.u()))});
    const int lights = 2 + static_cast<int>(rng.u() * 4);
    for (int l = 0; l < lights; ++l) {
        const Vec3 d = rng.dir();
        const double i = 0.2 + 3.0 * rng.u();
        const double r = rng.u(), g = rng.u(), b = rng.u();
        const Rgb c{static_cast<float>(i * (0.1 + r)), static_cast<float>(i * (0.1 + g)), static_cast<float>(i * (0.1 + b))};
        Sh3Radiance add;
        if (rng.u() < 0.5) add = project_directional(d, c);
        else add = project_cone(d, 0.05 + 0.6 * rng.u(), c);
        for (int j = 0; j < 9; ++j)
            for (int k = 0; k < 3; ++k) sh[j][k] += add[j][k];
    }
    return sh;
}

// A sample map: its SH3 (exact projection, as `zhc audit`) and the audit's reference irradiance
// (flux-preserving downsample, direct integration) at given directions.
struct Map {
    std::string name;
    Sh3Radiance sh;
    LatLongImage small;
};
const std::vector<Map>& maps() {
    static const std::vector<Map> out = [] {
        std::vector<Map> v;
        for (const std::string& path : test::envmap_paths()) {
            const Image img = test::load_envmap(path);
            if (img.width == 0) continue;
            Map m;
            m.name = test::envmap_name(path);
            m.sh = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
            m.small = downsample_for_audit({img.rgb.data(), img.width, img.height}, 256, 128);
            v.push_back(std::move(m));
        }
        return v;
    }();
    return out;
}

// RMSE of a codec's runtime irradiance against a reference at directions (the audit's metric).
double codec_rmse(const Codec& c, const Sh3Radiance& sh, const std::vector<Vec3>& dirs, const std::vector<Rgb>& ref) {
    std::vector<std::uint8_t> bytes(c.size_bytes);
    c.encode(sh, {}, bytes.data(), nullptr);
    return compare_irradiance(codec_irradiance(c, bytes.data(), {}, dirs), ref).rmse;
}

// ---- slow twins -----------------------------------------------------------------------------------

// The decoder's error for a candidate L1 (float-exact through hall_scaled_expand).
double decoded_error(const Sh3Radiance& t, const Sh2Radiance& lin, double s, ZonalAxisMode mode) {
    return irradiance_sq_error(t, hall_scaled_expand(lin, s, mode, {}));
}

// Brute-force profile at axis a (luminance mode): the L1 across a as the closed form (the same
// projection as the ZH3 profile), each channel's component along a by a dense scan of 4001 values
// in [-2 sqrt 3 f0, 2 sqrt 3 f0] refined by golden section, errors evaluated by the generic decoder.
double brute_profile(const Sh3Radiance& t, double s, Vec3 a) {
    const LuminanceWeights w;
    const double wv[3] = {w.r, w.g, w.b};
    auto l1 = [&](int k) { return Vec3{-double(t[3][k]), -double(t[1][k]), double(t[2][k])}; };
    Vec3 U{};
    for (int k = 0; k < 3; ++k) U = U + wv[k] * l1(k);
    const Vec3 Up = U - dot(U, a) * a;
    const double ww = wv[0] * wv[0] + wv[1] * wv[1] + wv[2] * wv[2];
    Sh2Radiance lin = truncate_to_sh2(t);
    double alpha[3];
    for (int k = 0; k < 3; ++k) alpha[k] = dot(l1(k), a);
    auto set = [&](Sh2Radiance* out) {
        for (int k = 0; k < 3; ++k) {
            const Vec3 beta = (l1(k) - dot(l1(k), a) * a) - (wv[k] / ww) * Up;
            const Vec3 v = alpha[k] * a + beta;
            (*out)[1][k] = float(-v.y);
            (*out)[2][k] = float(v.z);
            (*out)[3][k] = float(-v.x);
        }
    };
    // Channel errors separate once the axis is fixed: scan each channel's alpha with the others held.
    for (int k = 0; k < 3; ++k) {
        const double f0 = t[0][k];
        auto err = [&](double al) {
            const double keep = alpha[k];
            alpha[k] = al;
            set(&lin);
            alpha[k] = keep;
            // Evaluate with the axis forced to a: the luminance L1 of lin is along a by construction.
            return decoded_error(t, lin, s, ZonalAxisMode::kLuminance);
        };
        double best = alpha[k], be = err(best);
        const double range = 2.0 * std::sqrt(3.0) * std::max(f0, 1e-30);
        for (int i = 0; i <= 4000; ++i) {
            const double al = -range + 2.0 * range * i / 4000.0;
            const double e = err(al);
            if (e < be) {
                be = e;
                best = al;
            }
        }
        double lo = best - 2.0 * range / 4000.0, hi = best + 2.0 * range / 4000.0;
        for (int it = 0; it < 60; ++it) {
            const double m1 = lo + (hi - lo) * 0.382, m2 = lo + (hi - lo) * 0.618;
            if (err(m1) < err(m2)) hi = m2;
            else lo = m1;
        }
        const double g = 0.5 * (lo + hi);
        if (err(g) < be) best = g;
        alpha[k] = best;
    }
    set(&lin);
    return decoded_error(t, lin, s, ZonalAxisMode::kLuminance);
}

// Brute-force axis search on the fast profile: 6000 Fibonacci axes, then compass refinement.
double brute_axis_min(const Sh3Radiance& t, double s) {
    const auto dirs = test::fibonacci_directions(6000);
    Vec3 best{0, 0, 1};
    double be = 1e300;
    for (const Vec3& d : dirs) {
        const double e = hall_axis_profile(t, s, ZonalAxisMode::kLuminance, 0, d, {});
        if (e < be) {
            be = e;
            best = d;
        }
    }
    for (double step = 0.05; step > 1e-7; step *= 0.5)
        for (bool moved = true; moved;) {
            moved = false;
            const Mat3 f = frame_from_z(best);
            for (int i = 0; i < 8; ++i) {
                const double ang = i * kPi / 4;
                const Vec3 c = normalize_or(best + step * std::cos(ang) * Vec3{f(0, 0), f(1, 0), f(2, 0)} +
                                                step * std::sin(ang) * Vec3{f(0, 1), f(1, 1), f(2, 1)},
                                            best);
                const double e = hall_axis_profile(t, s, ZonalAxisMode::kLuminance, 0, c, {});
                if (e < be) {
                    be = e;
                    best = c;
                    moved = true;
                }
            }
        }
    return be;
}

TEST(HallSolve, ProfileMatchesBruteForceInnerMinimisation) {
    Rng rng(11);
    for (int i = 0; i < 12; ++i) {
        const Sh3Radiance t = synthetic_interior(rng);
        const double s = 0.5 * (i % 6);
        for (int j = 0; j < 3; ++j) {
            const Vec3 a = rng.dir();
            const double fast = hall_axis_profile(t, s, ZonalAxisMode::kLuminance, 0, a, {});
            const double slow = brute_profile(t, s, a);
            // The profile is the exact minimum over L1 with decoder axis a: never above the scan
            // (beyond float rounding of the stored L1), and the scan finds it to its resolution.
            EXPECT_LE(fast, slow * (1 + 1e-6) + 1e-12) << i << " " << j;
            EXPECT_NEAR(fast, slow, 1e-5 * slow + 1e-12) << i << " " << j;
        }
    }
}

TEST(HallSolve, ReachesBruteForceAxisSearch) {
    Rng rng(5);
    std::vector<Sh3Radiance> probes;
    for (const Map& m : maps())
        for (int r = 0; r < 3; ++r) probes.push_back(rotate(m.sh, rotation_axis_angle(rng.dir(), 2 * kPi * rng.u())));
    for (int i = 0; i < 40; ++i) probes.push_back(synthetic_interior(rng));
    double worst = 0, sum = 0;
    int n = 0;
    for (const Sh3Radiance& t : probes)
        for (double s : {1.0, 2.5}) {
            const double solved = decoded_error(t, hall_solve(t, s, ZonalAxisMode::kLuminance, {}, nullptr), s, ZonalAxisMode::kLuminance);
            const double brute = brute_axis_min(t, s);
            const double r = solved / brute;
            worst = std::max(worst, r);
            sum += r;
            ++n;
        }
    std::printf("hall_solve / brute-force axis search: mean %.6f worst %.6f over %d solves\n", sum / n, worst, n);
    EXPECT_LE(worst, 1.01);
    EXPECT_LE(sum / n, 1.001);
}

// ---- the audit on the sample maps -----------------------------------------------------------------

const char* const kRows[] = {"sh2", "sh2_q", "hall_curve", "hall_curve_q", "hall_solved", "hall_solved_q16",
                             "hall_adaptive_q16", "zh3_q16"};

TEST(HallAudit, SampleMapsUnderRotationsAgainstTrueIrradiance) {
    ASSERT_EQ(maps().size(), 8u);
    const std::vector<Vec3> dirs = fibonacci_sphere(1024);
    Rng rng(3);
    constexpr int kRotations = 4;  // rotation 0 is the identity (the audit's own numbers)
    // rmse[name][map * kRotations + r]
    std::map<std::string, std::vector<double>> rmse;
    for (const Map& m : maps())
        for (int r = 0; r < kRotations; ++r) {
            const Mat3 R = r == 0 ? Mat3{} : rotation_axis_angle(rng.dir(), 2 * kPi * rng.u());
            const Mat3 Rt = transpose(R);
            std::vector<Vec3> back;
            for (const Vec3& n : dirs) back.push_back(Rt * n);
            const std::vector<Rgb> ref = integrate_irradiance(m.small.view(), back);
            const Sh3Radiance sh = rotate(m.sh, R);
            for (const char* name : kRows) rmse[name].push_back(codec_rmse(*find_codec(name), sh, dirs, ref));
        }
    std::printf("\nirradiance RMSE vs the true irradiance (audit reference, 1024 directions), rotation 0; ratio to sh2\n%-18s", "");
    for (const Map& m : maps()) std::printf("%10s", m.name.c_str());
    std::printf("%10s%10s%12s\n", "mean/sh2", "worst", "rot. mean");
    std::map<std::string, double> mean_ratio, worst_ratio, rot_mean;
    for (const char* name : kRows) {
        std::printf("%-18s", name);
        double sum = 0, worst = 0, rsum = 0;
        for (size_t i = 0; i < maps().size(); ++i) {
            const double r0 = rmse[name][i * kRotations] / rmse["sh2"][i * kRotations];
            std::printf("%10.5f", rmse[name][i * kRotations]);
            sum += r0;
            for (int r = 0; r < kRotations; ++r) {
                const double q = rmse[name][i * kRotations + r] / rmse["sh2"][i * kRotations + r];
                worst = std::max(worst, q);
                rsum += q;
            }
        }
        mean_ratio[name] = sum / maps().size();
        worst_ratio[name] = worst;
        rot_mean[name] = rsum / (maps().size() * kRotations);
        std::printf("%10.3f%10.3f%12.3f\n", mean_ratio[name], worst, rot_mean[name]);
    }
    // Issue 18 item 4: never worse than SH2 on any map and rotation (float and 16-byte SH2), mean at
    // or below 0.62 of SH2 on the sample maps.
    for (size_t i = 0; i < rmse["sh2"].size(); ++i) {
        EXPECT_LE(rmse["hall_adaptive_q16"][i], rmse["sh2"][i]) << i;
        EXPECT_LE(rmse["hall_adaptive_q16"][i], rmse["sh2_q"][i]) << i;
    }
    EXPECT_LE(mean_ratio["hall_adaptive_q16"], 0.62);
    EXPECT_LE(rot_mean["hall_adaptive_q16"], 0.62);
    // Item 3: the solve beats storing the target's L1 (hall_curve) on the mean, float and 16 bytes.
    EXPECT_LT(mean_ratio["hall_solved"], 0.97 * mean_ratio["hall_curve"]);
    EXPECT_LT(mean_ratio["hall_solved_q16"], 0.97 * mean_ratio["hall_curve_q"]);
    EXPECT_LT(rot_mean["hall_solved"], 0.97 * rot_mean["hall_curve"]);
}

TEST(HallAudit, SyntheticInteriorsNeverWorseThanSh2) {
    // Several coloured lights from different directions (no map: the reference is the SH3
    // irradiance, exact over the sphere). The adaptive entry's encoder measures exactly this.
    Rng rng(17);
    double sum_adaptive = 0, sum_solved = 0, sum_curve = 0, worst = 0;
    const int n = 400;
    for (int i = 0; i < n; ++i) {
        const Sh3Radiance t = synthetic_interior(rng);
        auto err = [&](const char* name) {
            const Codec& c = *find_codec(name);
            std::vector<std::uint8_t> b(c.size_bytes);
            c.encode(t, {}, b.data(), nullptr);
            return std::sqrt(irradiance_sq_error(t, c.decode(b.data(), {})));
        };
        const double e2 = err("sh2"), e2q = err("sh2_q"), ea = err("hall_adaptive_q16");
        EXPECT_LE(ea, e2q * (1 + 1e-12)) << i;
        EXPECT_LE(ea, e2 * 1.01) << i;  // sh2_q's own quantisation is about 0.5 % of SH2's error
        worst = std::max(worst, ea / e2);
        sum_adaptive += ea / e2;
        sum_solved += err("hall_solved") / e2;
        sum_curve += err("hall_curve") / e2;
    }
    std::printf("synthetic interiors, error / sh2: hall_curve %.3f hall_solved %.3f hall_adaptive_q16 %.3f (worst %.3f)\n",
                sum_curve / n, sum_solved / n, sum_adaptive / n, worst);
    EXPECT_LT(sum_solved, sum_curve);
    EXPECT_LE(sum_adaptive / n, 0.75);
}

TEST(HallExperiment, DISABLED_BestScaleDistribution) {
    // Which per-probe hallucination scales the solve wants (continuous grid), on rotated maps and
    // synthetic interiors; coefficient metric against SH3.
    Rng rng(7);
    std::vector<Sh3Radiance> probes;
    for (const Map& m : maps())
        for (int r = 0; r < 16; ++r) probes.push_back(rotate(m.sh, rotation_axis_angle(rng.dir(), 2 * kPi * rng.u())));
    for (int i = 0; i < 100; ++i) probes.push_back(synthetic_interior(rng));
    const CodecOptions o;
    std::vector<double> grid;
    for (int g = 0; g <= 40; ++g) grid.push_back(0.125 * g);
    // ratio[probe][g] = RMSE ratio to SH2 (coefficient metric) at scale grid[g]
    std::vector<std::vector<double>> ratio;
    const auto t0 = std::chrono::steady_clock::now();
    for (const Sh3Radiance& p : probes) {
        const double e2 = irradiance_sq_error(p, extend_to_sh3(truncate_to_sh2(p)));
        std::vector<double> r;
        for (double s : grid)
            r.push_back(std::sqrt(irradiance_sq_error(p, hall_scaled_expand(hall_solve(p, s, ZonalAxisMode::kLuminance, o, nullptr), s, ZonalAxisMode::kLuminance, o)) / e2));
        ratio.push_back(r);
    }
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / (probes.size() * grid.size());
    std::printf("%.2f us per solve\n", us);
    for (int step : {1, 2, 3, 4}) for (int count : {4, 8, 16, 32}) {
        if ((count - 1) * step >= static_cast<int>(grid.size())) continue;
        double maps_sum = 0, synth_sum = 0, worst = 0;
        for (size_t i = 0; i < probes.size(); ++i) {
            double b = 1e300;
            for (int c = 0; c < count; ++c) b = std::min(b, ratio[i][static_cast<size_t>(c * step)]);
            (i < 128 ? maps_sum : synth_sum) += b;
            worst = std::max(worst, b);
        }
        std::printf("step %.3f count %2d (max %.3f): maps %.4f synth %.4f worst %.4f\n", 0.125 * step, count, 0.125 * step * (count - 1), maps_sum / 128, synth_sum / (probes.size() - 128), worst);
    }
}

}  // namespace
}  // namespace zhc
