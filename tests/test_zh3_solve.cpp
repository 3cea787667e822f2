// The ZH3 axis solve (codec/probe/zh3.h): Eq. 11 and its gradient against slow twins, never worse than
// the fit, scale invariance, multi-start against a brute-force axis search (helpers: zh3_helpers.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/zh3.h"
#include "support.h"
#include "zh3_helpers.h"

namespace zhc {
namespace {

using namespace zh3_test;

// ---- Eq. 11 and the solve -----------------------------------------------------------------------

TEST(Zh3Solve, Eq11IsTheSquaredIrradianceErrorAgainstSh3) {
    // Slow twin of zh3_eq11_error: integrate (E_zh3 - E_sh3)^2 over the sphere by dense quadrature,
    // with the zonal coefficient fitted (Eq. 9) along the stored axis.
    Rng rng(19);
    const auto dirs = fibonacci_directions(40000);
    for (int trial = 0; trial < 6; ++trial) {
        const Sh3Radiance in = random_lighting(rng);
        for (auto mode : {ZonalAxisMode::kLuminance, ZonalAxisMode::kPerChannel}) {
            Zh3 z = zh3_fit(in, mode, {});
            // perturb the L1 so the L1 term of Eq. 11 is non-zero too
            for (int k = 0; k < 3; ++k) z.linear[1][k] += 0.1f * float(rng.u());
            for (int k = 0; k < 3; ++k) {
                const Vec3 a = zh3_axis(z.linear, mode, k, {});
                double f2[5];
                for (int m = 0; m < 5; ++m) f2[m] = in[4 + m][k];
                const auto y = sh3_basis(a);
                double dotq = 0;
                for (int m = 0; m < 5; ++m) dotq += y[4 + m] * f2[m];
                z.zonal[k] = static_cast<float>(std::sqrt(4 * kPi / 5) * dotq);
            }
            const Sh3Radiance rec = zh3_expand(z, mode, {});
            double integral = 0;
            for (const Vec3 n : dirs) {
                const Rgb e1 = irradiance(rec, n), e2 = irradiance(in, n);
                for (int k = 0; k < 3; ++k) integral += (double(e1[k]) - e2[k]) * (double(e1[k]) - e2[k]);
            }
            integral *= 4 * kPi / dirs.size();
            EXPECT_NEAR(zh3_eq11_error(in, z.linear, mode, {}), integral, 1e-3 * integral + 1e-9);
        }
    }
}

TEST(Zh3Solve, AnalyticGradientMatchesCentralDifferences) {
    Rng rng(20);
    LuminanceWeights w;
    for (int trial = 0; trial < 50; ++trial) {
        const Sh3Radiance in = trial % 2 ? random_lighting(rng) : random_coefficients(rng);
        double g[9], grad[9];
        for (int i = 0; i < 9; ++i) g[i] = 2.0 / 3.0 * in[1 + i / 3][i % 3] + 0.3 * (rng.u() - 0.5);
        const double e = zh3_lum_objective(in, w, g, grad);
        ASSERT_TRUE(std::isfinite(e));
        for (int i = 0; i < 9; ++i) {
            const double h = 1e-6;
            double gp[9], gm[9];
            std::copy(g, g + 9, gp);
            std::copy(g, g + 9, gm);
            gp[i] += h;
            gm[i] -= h;
            const double fd = (zh3_lum_objective(in, w, gp, nullptr) - zh3_lum_objective(in, w, gm, nullptr)) / (2 * h);
            EXPECT_NEAR(grad[i], fd, 1e-6 * (1 + std::fabs(fd))) << "coefficient " << i;
        }
        // per-channel axis objective
        for (int k = 0; k < 3; ++k) {
            const Vec3 x = rng.dir();
            Vec3 gr;
            zh3_channel_objective(in, k, x, &gr);
            for (int j = 0; j < 3; ++j) {
                const double h = 1e-6;
                Vec3 xp = x, xm = x;
                (j == 0 ? xp.x : j == 1 ? xp.y : xp.z) += h;
                (j == 0 ? xm.x : j == 1 ? xm.y : xm.z) -= h;
                const double fd = (zh3_channel_objective(in, k, xp, nullptr) - zh3_channel_objective(in, k, xm, nullptr)) / (2 * h);
                EXPECT_NEAR(gr[j], fd, 1e-6 * (1 + std::fabs(fd)));
            }
        }
    }
}

TEST(Zh3Solve, LumObjectiveAtTheTargetL1IsTheFitError) {
    // Eq. 11 at f = t1 (the unsolved L1) is exactly zh3_lum's error: ties the objective to the codec.
    Rng rng(21);
    for (int trial = 0; trial < 50; ++trial) {
        const Sh3Radiance in = random_lighting(rng);
        double g[9];
        for (int i = 0; i < 9; ++i) g[i] = 2.0 / 3.0 * in[1 + i / 3][i % 3];
        const Zh3 fit = zh3_fit(in, ZonalAxisMode::kLuminance, {});
        EXPECT_NEAR(zh3_lum_objective(in, {}, g, nullptr), zh3_eq11_error(in, fit.linear, ZonalAxisMode::kLuminance, {}),
                    1e-9 * (1 + coefficient_norm(in) * coefficient_norm(in)));
    }
}

double eq11(const char* name, const Sh3Radiance& in, EncodeStats* stats = nullptr, const CodecOptions& o = {}) {
    const Codec& c = codec(name);
    std::vector<std::uint8_t> bytes(c.size_bytes);
    c.encode(in, o, bytes.data(), stats);
    const Sh3Radiance d = c.decode(bytes.data(), o);
    const auto mode = std::strstr(name, "channel") ? ZonalAxisMode::kPerChannel : ZonalAxisMode::kLuminance;
    return zh3_eq11_error(in, truncate_to_sh2(d), mode, o.luminance);
}

TEST(Zh3Solve, NeverWorseThanTheFitAndUsuallyBetter) {
    Rng rng(22);
    std::vector<Sh3Radiance> inputs;
    for (const RealMap& m : real_maps()) {
        inputs.push_back(m.sh);
        for (int r = 0; r < 24; ++r) inputs.push_back(rotate(m.sh, random_rotation(rng)));
    }
    for (int i = 0; i < 400; ++i) inputs.push_back(i % 2 ? random_lighting(rng) : random_coefficients(rng));
    double sum_fit[2] = {0, 0}, sum_solved[2] = {0, 0};
    int improved[2] = {0, 0}, iterations = 0;
    for (const Sh3Radiance& in : inputs) {
        const double fit_lum = eq11("zh3_lum", in), fit_chan = eq11("zh3_channel", in);
        EncodeStats st;
        const double sol_lum = eq11("zh3_solved_lum", in, &st), sol_chan = eq11("zh3_solved_channel", in);
        iterations += st.solver_iterations;
        EXPECT_LE(sol_lum, fit_lum);
        EXPECT_LE(sol_chan, fit_chan);
        sum_fit[0] += fit_lum;
        sum_fit[1] += fit_chan;
        sum_solved[0] += sol_lum;
        sum_solved[1] += sol_chan;
        improved[0] += sol_lum < 0.999 * fit_lum;
        improved[1] += sol_chan < 0.999 * fit_chan;
    }
    std::printf("solve vs fit over %zu inputs: summed Eq.11 solved/fit lum %.3f (%d improved by > 0.1%%), channel %.3f"
                " (%d improved), mean L-BFGS iterations (lum) %.1f\n",
                inputs.size(), sum_solved[0] / sum_fit[0], improved[0], sum_solved[1] / sum_fit[1], improved[1],
                double(iterations) / inputs.size());
    // The solve must actually do something on most inputs.
    EXPECT_GT(improved[0], static_cast<int>(inputs.size()) / 2);
    EXPECT_GT(improved[1], static_cast<int>(inputs.size()) / 2);
}

TEST(Zh3Solve, ReachesTheBestAxisFoundByExhaustiveSearch) {
    // Slow twin of the per-channel solve: scan axes on a dense Fibonacci set, refine nothing.
    Rng rng(23);
    const auto dirs = fibonacci_directions(20000);
    for (int trial = 0; trial < 10; ++trial) {
        const Sh3Radiance in = random_coefficients(rng);
        const Zh3 solved = zh3_solve(in, ZonalAxisMode::kPerChannel, {}, nullptr);
        for (int k = 0; k < 3; ++k) {
            double best = 1e300;
            for (const Vec3 d : dirs) best = std::min(best, zh3_channel_objective(in, k, d, nullptr));
            const Vec3 a = zh3_axis(solved.linear, ZonalAxisMode::kPerChannel, k, {});
            const double got = zh3_channel_objective(in, k, a, nullptr);
            EXPECT_LE(got, best + 1e-6 * (1 + best)) << "channel " << k;
        }
        // lum: the profile over axes (optimal L1 for each shared axis) scanned densely
        const LuminanceWeights w;
        const Sh3Radiance sol_lum = round_trip(codec("zh3_solved_lum"), in);
        const double got = zh3_eq11_error(in, truncate_to_sh2(sol_lum), ZonalAxisMode::kLuminance, w);
        double best = 1e300;
        const double wv[3] = {w.r, w.g, w.b}, ww = wv[0] * wv[0] + wv[1] * wv[1] + wv[2] * wv[2];
        for (const Vec3 a : dirs) {
            double g[9];
            Vec3 u{};
            for (int k = 0; k < 3; ++k) u = u + wv[k] * Vec3{-in[3][k] * 2 / 3.0, -in[1][k] * 2 / 3.0, in[2][k] * 2 / 3.0};
            const Vec3 shift = (1.0 / ww) * (u - dot(u, a) * a);
            for (int k = 0; k < 3; ++k) {
                const Vec3 t{-in[3][k] * 2 / 3.0, -in[1][k] * 2 / 3.0, in[2][k] * 2 / 3.0};
                const Vec3 v = t - wv[k] * shift;
                g[0 + k] = -v.y;
                g[3 + k] = v.z;
                g[6 + k] = -v.x;
            }
            best = std::min(best, zh3_lum_objective(in, w, g, nullptr));
        }
        EXPECT_LE(got, best + 1e-5 * (1 + best));
    }
}

// ---- scale invariance -----------------------------------------------------------------------------

Sh3Radiance scaled(const Sh3Radiance& in, double s) {
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(s * in[i][k]);
    return out;
}

// The stored floats of a ZH3 (nine L1 + three zonal; DC is copied and not solved).
std::vector<double> solved_values(const Zh3& z) {
    std::vector<double> v;
    for (int i = 1; i < 4; ++i)
        for (int k = 0; k < 3; ++k) v.push_back(z.linear[i][k]);
    for (int k = 0; k < 3; ++k) v.push_back(z.zonal[k]);
    return v;
}

std::vector<Sh3Radiance> scale_test_probes() {
    Rng rng(40);
    std::vector<Sh3Radiance> probes;
    for (const RealMap& m : real_maps()) {
        probes.push_back(m.sh);
        for (int r = 0; r < 2; ++r) probes.push_back(rotate(m.sh, random_rotation(rng)));
    }
    for (int i = 0; i < 120; ++i) probes.push_back(random_lighting(rng));
    return probes;
}

TEST(Zh3Solve, PowerOfTwoScalingGivesBitIdenticalSolves) {
    // Normalising by a power of two is exact, so 2^n-scaled probes (far beyond the power-of-ten range
    // below) must give exactly 2^n times the result with the same iterations.
    for (const Sh3Radiance& p : scale_test_probes())
        for (const ZonalAxisMode mode : {ZonalAxisMode::kLuminance, ZonalAxisMode::kPerChannel}) {
            EncodeStats st1;
            const Zh3 r1 = zh3_solve(p, mode, {}, &st1);
            const std::vector<double> v1 = solved_values(r1);
            for (const int n : {-60, -27, -1, 1, 33, 60}) {
                const double s = std::ldexp(1.0, n);
                EncodeStats st;
                const std::vector<double> v = solved_values(zh3_solve(scaled(p, s), mode, {}, &st));
                EXPECT_EQ(st.solver_iterations, st1.solver_iterations) << "2^" << n;
                for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], s * v1[i]) << "2^" << n << " value " << i;
            }
        }
}

TEST(Zh3Solve, ResultAndIterationsDoNotDependOnTheLightingsUnits) {
    // Scales 1e-8 .. 1e8: the solved coefficients are s times the scale-1 ones within 1e-6 of the
    // result's norm, with identical iteration counts. (The scaled probe is rounded to float, so it is
    // not exactly s times the original: this also checks that the solves are not fragile to that.)
    const std::vector<Sh3Radiance> probes = scale_test_probes();
    const CodecOptions o;
    int mismatched_iterations = 0, solves = 0, mism[2] = {0, 0}, its[2] = {0, 0};
    double worst = 0;
    for (const Sh3Radiance& p : probes)
        for (const ZonalAxisMode mode : {ZonalAxisMode::kLuminance, ZonalAxisMode::kPerChannel}) {
            EncodeStats st1;
            const std::vector<double> v1 = solved_values(zh3_solve(p, mode, o, &st1));
            its[int(mode)] += st1.solver_iterations;
            double norm = 0;
            for (const double x : v1) norm += x * x;
            norm = std::sqrt(norm);
            for (int e = -8; e <= 8; ++e) {
                if (e == 0) continue;
                const double s = std::pow(10.0, e);
                EncodeStats st;
                const std::vector<double> v = solved_values(zh3_solve(scaled(p, s), mode, o, &st));
                ++solves;
                mismatched_iterations += st.solver_iterations != st1.solver_iterations;
                mism[int(mode)] += st.solver_iterations != st1.solver_iterations;
                EXPECT_EQ(st.solver_iterations, st1.solver_iterations)
                    << "scale 1e" << e << (mode == ZonalAxisMode::kLuminance ? " lum" : " channel");
                double d = 0;
                for (size_t i = 0; i < v.size(); ++i) d += (v[i] / s - v1[i]) * (v[i] / s - v1[i]);
                const double rel = std::sqrt(d) / norm;
                worst = std::max(worst, rel);
                EXPECT_LE(rel, 1e-6) << "scale 1e" << e;
            }
        }
    std::printf("scale invariance: %d solves at scales 1e-8..1e8, %d with a different iteration count (lum %d, channel %d;"
                " mean iterations lum %.2f channel %.2f), worst relative difference %.3g\n", solves, mismatched_iterations,
                mism[0], mism[1], double(its[0]) / probes.size(), double(its[1]) / probes.size(), worst);
}

// ---- multi-start against a brute-force axis search -------------------------------------------------

// Slow twin of an axis solve: the objective on a Fibonacci sphere of `dirs`, then a compass search
// on the tangent plane from each of the best grid points that are at least 0.3 rad apart (as axes),
// step halved down to 1e-10 rad. Returns the lowest value found.
template <class F>
double brute_force_axis_min(F&& objective, const std::vector<Vec3>& dirs) {
    std::vector<std::pair<double, int>> values;
    values.reserve(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) values.push_back({objective(dirs[i]), static_cast<int>(i)});
    std::sort(values.begin(), values.end());
    std::vector<Vec3> seeds;
    for (const auto& [v, i] : values) {
        if (seeds.size() >= 6) break;
        bool far = true;
        for (const Vec3 q : seeds) far = far && std::fabs(dot(q, dirs[i])) < std::cos(0.3);
        if (far) seeds.push_back(dirs[i]);
    }
    double best = values.front().first;
    const double spacing = std::sqrt(4 * kPi / dirs.size());
    for (Vec3 a : seeds) {
        double e = objective(a), h = spacing;
        for (int evals = 0; h > 1e-10 && evals < 20000;) {
            const Vec3 helper = std::fabs(a.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
            const Vec3 u = normalize_or(cross(a, helper), {0, 0, 1}), v = cross(a, u);
            bool moved = false;
            for (const Vec3 d : {u, -1.0 * u, v, -1.0 * v}) {
                const Vec3 b = normalize_or(a + h * d, a);
                const double eb = objective(b);
                ++evals;
                if (eb < e) {
                    a = b;
                    e = eb;
                    moved = true;
                    break;
                }
            }
            if (!moved) h *= 0.5;
        }
        best = std::min(best, e);
    }
    return best;
}

// Eq. 11 of channel k alone, as decoded (zh3_eq11_error on the channel with the others zeroed).
double channel_eq11(const Sh3Radiance& in, const Sh2Radiance& linear, int k) {
    Sh3Radiance tk;
    Sh2Radiance lk;
    for (int i = 0; i < 9; ++i) tk[i][k] = in[i][k];
    for (int i = 0; i < 4; ++i) lk[i][k] = linear[i][k];
    return zh3_eq11_error(tk, lk, ZonalAxisMode::kPerChannel, {});
}

// Profile of the shared-axis objective: the best nine L1 coefficients for a fixed axis a (see
// docs/zh3.md) evaluated through the public objective.
double lum_profile(const Sh3Radiance& in, const LuminanceWeights& w, Vec3 a) {
    const double wv[3] = {w.r, w.g, w.b}, ww = wv[0] * wv[0] + wv[1] * wv[1] + wv[2] * wv[2];
    Vec3 u{};
    for (int k = 0; k < 3; ++k) u = u + wv[k] * Vec3{-in[3][k] * 2 / 3.0, -in[1][k] * 2 / 3.0, in[2][k] * 2 / 3.0};
    const Vec3 shift = (1.0 / ww) * (u - dot(u, a) * a);
    double g[9];
    for (int k = 0; k < 3; ++k) {
        const Vec3 t{-in[3][k] * 2 / 3.0, -in[1][k] * 2 / 3.0, in[2][k] * 2 / 3.0};
        const Vec3 v = t - wv[k] * shift;
        g[0 + k] = -v.y;
        g[3 + k] = v.z;
        g[6 + k] = -v.x;
    }
    return zh3_lum_objective(in, w, g, nullptr);
}

TEST(Zh3Solve, NeverMoreThanATenthOfAPercentAboveABruteForceAxisSearch) {
    // Random lightings (several coloured lights + ambient). ZHC_ZH3_BRUTE_PROBES overrides the count
    // (the notes give a 10,000-probe run). The Release pass runs 2,000; the sanitizer pass
    // (ZHC_TEST_SAMPLE_SCALE=0.1, scripts/sanitize.sh) the first 200 of them (test::scaled_count).
    int probes = static_cast<int>(test::scaled_count(2000, 200));
    if (const char* env = std::getenv("ZHC_ZH3_BRUTE_PROBES")) probes = std::max(1, std::atoi(env));
    const auto dirs = fibonacci_directions(3000);
    const LuminanceWeights w;
    Rng rng(41);
    double sum_ratio[2] = {0, 0}, worst_ratio[2] = {0, 0};
    int count[2] = {0, 0}, above[2] = {0, 0};
    for (int trial = 0; trial < probes; ++trial) {
        const Sh3Radiance in = random_lighting(rng);
        EncodeStats st;
        const Zh3 chan = zh3_solve(in, ZonalAxisMode::kPerChannel, {}, &st);
        for (int k = 0; k < 3; ++k) {
            const double got = channel_eq11(in, chan.linear, k);
            const double brute =
                brute_force_axis_min([&](Vec3 a) { return zh3_channel_objective(in, k, a, nullptr); }, dirs);
            const double scale = double(in[0][k]) * in[0][k];
            EXPECT_LE(got, 1.001 * brute + 1e-12 * scale) << "probe " << trial << " channel " << k;
            if (brute > 1e-9 * scale) {
                const double r = got / brute;
                sum_ratio[1] += r;
                worst_ratio[1] = std::max(worst_ratio[1], r);
                above[1] += r > 1.001;
                ++count[1];
            }
        }
        const Zh3 lum = zh3_solve(in, ZonalAxisMode::kLuminance, {}, nullptr);
        const double got = zh3_eq11_error(in, lum.linear, ZonalAxisMode::kLuminance, w);
        const double brute = brute_force_axis_min([&](Vec3 a) { return lum_profile(in, w, a); }, dirs);
        const double scale = double(in[0][1]) * in[0][1];
        // Reported, not asserted: the shared-axis solve still runs from its best-ranked start only
        // (see the notes: about 1 probe in 1,000 ends more than 0.1 % above the brute force).
        if (brute > 1e-9 * scale) {
            const double r = got / brute;
            sum_ratio[0] += r;
            worst_ratio[0] = std::max(worst_ratio[0], r);
            above[0] += r > 1.001;
            ++count[0];
        }
    }
    std::printf("vs brute force (%d random lightings): lum mean ratio %.6f worst %.6f (%d > 1.001); per-channel mean"
                " %.6f worst %.6f (%d of %d channels > 1.001)\n",
                probes, sum_ratio[0] / std::max(count[0], 1), worst_ratio[0], above[0], sum_ratio[1] / std::max(count[1], 1),
                worst_ratio[1], above[1], count[1]);
}

TEST(Zh3Solve, DegenerateZeroL1GivesFiniteOutputAndFindsTheZonalAxis) {
    Rng rng(24);
    for (int trial = 0; trial < 50; ++trial) {
        // Two equal opposite sphere lights: L1 is zero, L2 is zonal along a random axis.
        const Vec3 axis = rng.dir();
        const Rgb c = rng.colour();
        const Sh3Radiance in = project_cone(axis, 0.4, c) + project_cone(-1.0 * axis, 0.4, c);
        for (const char* name : kZh3Names) {
            const Sh3Radiance out = round_trip(codec(name), in);
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(out[i][k])) << name;
        }
        // All-zero input too.
        for (const char* name : kZh3Names) {
            const Sh3Radiance out = round_trip(codec(name), Sh3Radiance{});
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) EXPECT_EQ(out[i][k], 0.0f) << name;
        }
        // The fit falls back to +Z; the solves find the true axis and represent the L2 band.
        const double l2 = coefficient_norm(in, 4, 9);
        for (const char* name : {"zh3_solved_lum", "zh3_solved_channel"}) {
            const Sh3Radiance out = round_trip(codec(name), in);
            EXPECT_LE(coefficient_distance(in, out, 4, 9), 1e-3 * l2) << name;
            EXPECT_LE(coefficient_distance(in, out, 1, 4), 2e-3 * l2) << name;  // L1 stays ~0
        }
    }
}

TEST(Zh3Solve, IterationOptionsAreHonoured) {
    Rng rng(25);
    const Sh3Radiance in = random_coefficients(rng);
    CodecOptions o;
    o.solver_iterations = 0;
    EncodeStats st;
    std::vector<std::uint8_t> a(60), b(60);
    codec("zh3_solved_lum").encode(in, o, a.data(), &st);
    EXPECT_EQ(st.solver_iterations, 0);
    o.solver_iterations = 3;
    codec("zh3_solved_lum").encode(in, o, b.data(), &st);
    EXPECT_GT(st.solver_iterations, 0);
    EXPECT_LE(st.solver_iterations, 2 * 3);  // at most two starts
}

}  // namespace
}  // namespace zhc
