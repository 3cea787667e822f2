// Deringing (codec/probe/dering.h, Sloan 2017), the bound and the window: the axis form, the
// conservative minimum against dense sampling (exact cases, 10^5 random inputs) and the window table
// (helpers: dering_helpers.h).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "codec/probe/codec.h"
#include "codec/probe/dering.h"
#include "dering_helpers.h"
#include "support.h"

namespace zhc {
namespace {

using namespace dering_test;

double eval_channel(const Sh3Channel& f, Vec3 d) {
    const auto y = sh3_basis(d);
    double s = 0;
    for (int i = 0; i < 9; ++i) s += f[static_cast<size_t>(i)] * y[static_cast<size_t>(i)];
    return s;
}

// Slow twin of the minimum: the smallest value over a direction set.
double dense_min(const Sh3Channel& f, const std::vector<Vec3>& dirs) {
    double m = std::numeric_limits<double>::infinity();
    for (const Vec3 d : dirs) m = std::min(m, eval_channel(f, d));
    return m;
}


// Scale of an SH3 channel: the largest absolute value it can take is <= sum |f_i| max|Y_i|; used
// to express floating-point tolerances relative to the function's size.
double magnitude(const Sh3Channel& f) {
    double s = 0;
    for (double v : f) s += std::fabs(v);
    return s;
}


// ---- the 1-D minimisation and the axis form ----------------------------------------------------

TEST(AxisForm, MatchesTheCoefficientsOfShRotateIntoTheOptimalLinearFrame) {
    Generator g(11);
    for (int trial = 0; trial < 200; ++trial) {
        const Sh3Radiance sh = g.mixed() + g.deltas(1);
        for (int k = 0; k < 3; ++k) {
            const Sh3AxisForm form = sh3_axis_form(channel_of(sh, k));
            // rotate() gives g(d) = f(R^T d); R^T = frame_from_z(axis) brings the axis to +Z.
            const Sh3Radiance rot = rotate(sh, transpose(frame_from_z(form.axis)));
            const double tol = 2e-6 * magnitude(channel_of(sh, k));
            EXPECT_NEAR(rot[1][k], 0.0, tol);
            EXPECT_NEAR(rot[3][k], 0.0, tol);
            EXPECT_NEAR(rot[2][k], form.linear, tol);
            EXPECT_GE(form.linear, 0.0);
            EXPECT_NEAR(rot[6][k], form.zonal2, tol);
            EXPECT_NEAR(std::hypot(rot[5][k], rot[7][k]), form.amp1, tol);
            EXPECT_NEAR(std::hypot(rot[4][k], rot[8][k]), form.amp2, tol);
            EXPECT_EQ(form.dc, sh[0][k]);
        }
    }
}

// The bound's 1-D problem, min over z of P(z) - kY2 q1 |z| sqrt(1 - z^2), solved by brute force.
double dense_profile_min(const Sh3AxisForm& f, int n) {
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= n; ++i) {
        const double z = -1.0 + 2.0 * i / n;
        const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double v = kY00 * f.dc + kY1 * f.linear * z + kY20 * f.zonal2 * (3 * z * z - 1) -
                         kY22 * f.amp2 * (1 - z * z) - kY2 * f.amp1 * std::fabs(z) * s;
        best = std::min(best, v);
    }
    return best;
}

TEST(Bound, SolvesItsOneDimensionalProblemExactly) {
    // The Newton / convexity logic against 2e6-point brute force over z: the bound must not be
    // above the brute-force minimum, and not below it by more than the grid's resolution.
    Generator g(5);
    std::normal_distribution<double> n(0.0, 1.0);
    for (int trial = 0; trial < 150; ++trial) {
        Sh3AxisForm f;
        f.dc = n(g.rng);
        f.linear = std::fabs(n(g.rng)) * (trial % 7 == 0 ? 0.0 : 1.0);
        f.zonal2 = n(g.rng);
        f.amp1 = std::fabs(n(g.rng)) * (trial % 5 == 0 ? 0.0 : 1.0);
        f.amp2 = std::fabs(n(g.rng)) * (trial % 3 == 0 ? 0.0 : 1.0);
        const double bound = sh3_min_bound(f);
        const double brute = dense_profile_min(f, 1000000);
        EXPECT_LE(bound, brute + 1e-12) << trial;
        EXPECT_GE(bound, brute - 1e-6) << trial;
        // The early-out bound is valid and never tighter.
        const double quick = sh3_min_bound(f, 1, 1, true);
        EXPECT_LE(quick, bound + 1e-15);
        EXPECT_EQ(quick >= 0, bound >= 0) << "early out must not change the sign decision";
    }
}

TEST(Bound, IsExactWithoutTheMEqualsOnePair) {
    // Zonal part and |m| = 2 pair are exact (Sec. 2.3.2): build f in the frame with q1 = 0 and a
    // random rotation; the bound must equal the true minimum.
    Generator g(3);
    std::normal_distribution<double> n(0.0, 1.0);
    const auto dirs = fibonacci_directions(20000);
    for (int trial = 0; trial < 200; ++trial) {
        Sh3Radiance sh;
        sh[0] = {static_cast<float>(n(g.rng)), 0, 0};
        sh[2] = {static_cast<float>(std::fabs(n(g.rng))), 0, 0};
        sh[6] = {static_cast<float>(n(g.rng)), 0, 0};
        sh[4] = {static_cast<float>(n(g.rng)), 0, 0};
        sh[8] = {static_cast<float>(n(g.rng)), 0, 0};
        const Mat3 r = rotation_axis_angle(g.dir(), 2 * kPi * g.uni());
        const Sh3Channel f = channel_of(rotate(sh, r), 0);
        const double bound = sh3_min_bound(f);
        const Sh3Minimum m = sh3_min_numeric(f);
        EXPECT_LE(bound, m.value + 1e-9 * magnitude(f)) << trial;
        EXPECT_NEAR(bound, m.value, 2e-6 * magnitude(f)) << trial;
    }
}

TEST(Bound, AnalyticCases) {
    // Constant: exact. A single delta's irradiance: zonal, so exact, and its known minimum
    // E(t)/E_dc = 1 + 2t + (5/8)(3t^2 - 1) at t = -8/15 (-0.1583 of the mean).
    Sh3Channel c{};
    c[0] = 2 * std::sqrt(kPi) * 0.7;
    EXPECT_NEAR(sh3_min_bound(c), 0.7, 1e-14);
    const Sh3Radiance delta = project_directional({0.36, -0.48, 0.8}, {1, 1, 1});
    const Sh3Channel e = irradiance_channel(delta, 0);
    const double mean = kY00 * e[0];
    const double t = -8.0 / 15.0;
    const double expected = mean * (1 + 2 * t + 5.0 / 8.0 * (3 * t * t - 1));
    EXPECT_NEAR(sh3_min_bound(e), expected, 1e-6 * mean);
    EXPECT_NEAR(sh3_min_numeric(e).value, expected, 1e-6 * mean);
}

// ---- the acceptance run: 10^5 random inputs -----------------------------------------------------

TEST(Bound, NeverAboveTheTrueMinimumOnHundredThousandRandomInputs) {
    // True minimum: 2048 Fibonacci samples + Newton refinement from the best 6 (an attained value,
    // so >= the true minimum). The refinement is validated against 100k-direction sampling on
    // 300 inputs: refined <= dense + eps, so it is at least as low as the 100k-sample minimum.
    // The sanitizer pass (ZHC_TEST_SAMPLE_SCALE=0.1, scripts/sanitize.sh) runs the first tenth of the
    // same inputs (test::scaled_count); the Release pass runs all 10^5.
    const long n = test::scaled_count(100000, 1000);
    Generator g(2017);
    const auto dense_dirs = fibonacci_directions(100000);
    int violations = 0, refine_misses = 0;
    double worst_excess = -1e300, worst_gap = 0, lighting_gap_sum = 0, lighting_gap_max = 0;
    int lighting = 0;
    for (int i = 0; i < n; ++i) {
        const Sh3Channel f = g.any(i);
        const double scale = magnitude(f);
        const double bound = sh3_min_bound(f);
        const Sh3Minimum truth = sh3_min_numeric(f, 2048, 6);
        ASSERT_NEAR(eval_channel(f, truth.direction), truth.value, 1e-12 * scale);
        const double excess = (bound - truth.value) / scale;
        worst_excess = std::max(worst_excess, excess);
        worst_gap = std::max(worst_gap, -excess);
        if (bound > truth.value + 1e-12 * scale) ++violations;
        if (i % 5 != 4 && f[0] > 0) {  // lighting families: gap as a fraction of the mean (DC) value
            const double rel = (truth.value - bound) / (kY00 * f[0]);
            lighting_gap_sum += rel;
            lighting_gap_max = std::max(lighting_gap_max, rel);
            ++lighting;
        }
        if (i < 300) {
            const double dense = dense_min(f, dense_dirs);
            if (truth.value > dense + 1e-12 * scale) {
                ++refine_misses;
                std::printf("miss %d: refined %.17g dense %.17g scale %g\n", i, truth.value, dense, scale);
            }
            EXPECT_LE(bound, dense + 1e-12 * scale) << i;
        }
    }
    std::printf("[bound] %ld inputs: worst (bound - true)/scale = %.3g, largest gap/scale = %.3g\n", n,
                worst_excess, worst_gap);
    std::printf("[bound] %d lighting inputs: (true - bound) / mean value: mean %.4f, max %.4f\n", lighting,
                lighting_gap_sum / lighting, lighting_gap_max);
    EXPECT_EQ(refine_misses, 0) << "refined minimum above the 100k-sample minimum";
    EXPECT_EQ(violations, 0);
}

// ---- window table -------------------------------------------------------------------------------

TEST(Window, TableRowL2IsEquationSixAtBandOne) {
    // Eq. 6 with l = 1 reproduces row "l2" to within the paper's hand tuning (<= 0.006) at every w;
    // rows "l1" and "l3" are Eq. 6 at l = 1/2 and 3/2 for the weakest window.
    for (int i = 1; i < kDeringTableColumns; ++i)
        EXPECT_NEAR(kDeringTableRows[1][i], sinc4_window(1, kDeringTableW[i]), 0.006) << kDeringTableW[i];
    EXPECT_NEAR(kDeringTableRows[0][1], sinc4_window(0.5, 16.7), 1e-4);
    EXPECT_NEAR(kDeringTableRows[2][1], sinc4_window(1.5, 16.7), 5e-4);
    EXPECT_EQ(sinc4_window(0, 3), 1.0);
    EXPECT_EQ(sinc4_window(2, std::numeric_limits<double>::infinity()), 1.0);
}

// Minimum over t in [-1, 1] of a windowed delta's irradiance relative to its mean:
// 1 + 2 s1 t + (5/8) s2 (3t^2 - 1) (the delta's irradiance, bands scaled by s1, s2).
double delta_relative_min(double s1, double s2) {
    double m = 1e300;
    for (int i = 0; i <= 200000; ++i) {
        const double t = -1 + i / 100000.0;
        m = std::min(m, 1 + 2 * s1 * t + 5.0 / 8.0 * s2 * (3 * t * t - 1));
    }
    return m;
}

TEST(Window, StrongestColumnMakesADeltaNonNegative) {
    // Sec. 2.4 / Fig. 4: "the most aggressive window makes the irradiance of a delta function
    // strictly positive" — holds for the reading band 1 <- "l2", band 2 <- "l3" (used), fails
    // for band 1 <- "l1", band 2 <- "l2" (printed for the record).
    const WindowScales w = dering_window(kDeringTableColumns - 1);
    EXPECT_EQ(w.l1, kDeringTableRows[1][6]);
    EXPECT_EQ(w.l2, kDeringTableRows[2][6]);
    const double used = delta_relative_min(w.l1, w.l2);
    const double other = delta_relative_min(kDeringTableRows[0][6], kDeringTableRows[1][6]);
    std::printf("[table] windowed delta irradiance min / mean at w = 5.6: used reading %.4f, "
                "other reading %.4f, none %.4f\n", used, other, delta_relative_min(1, 1));
    EXPECT_GT(used, 0.0);
    EXPECT_LT(other, 0.0);
    // and on the sphere, with the library's own windowing
    const Sh3Radiance delta = apply_window(project_directional({0, 0.6, -0.8}, {3, 2, 1}), w);
    const Sh3Channel e = irradiance_channel(delta, 0);
    EXPECT_GT(dense_min(e, fibonacci_directions(100000)), 0.0);
}

TEST(Window, ParameterWalksTheTableMonotonically) {
    EXPECT_EQ(dering_window(0).l1, 1.0);
    EXPECT_EQ(dering_window(0).l2, 1.0);
    for (int i = 0; i < kDeringTableColumns; ++i) {
        EXPECT_DOUBLE_EQ(dering_window(i).l1, kDeringTableRows[1][i]);
        EXPECT_DOUBLE_EQ(dering_window(i).l2, kDeringTableRows[2][i]);
    }
    EXPECT_DOUBLE_EQ(dering_window(2.5).l1, 0.5 * (kDeringTableRows[1][2] + kDeringTableRows[1][3]));
    EXPECT_EQ(dering_window(kDeringWindowMax).l1, 0.0);
    EXPECT_EQ(dering_window(kDeringWindowMax).l2, 0.0);
    WindowScales prev = dering_window(0);
    for (int i = 1; i <= 7000; ++i) {
        const WindowScales w = dering_window(i * 1e-3);
        EXPECT_LE(w.l1, prev.l1);
        EXPECT_LE(w.l2, prev.l2);
        prev = w;
    }
}

}  // namespace
}  // namespace zhc
