// Properties of the ZH3 representations (codec/probe/zh3.h, codec/probe/zh3.cpp): fit, luminance axis, axis
// solve, hallucination, ZH3 deringing — on analytic cases and on the eight real maps.
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

namespace zhc {
namespace {

using test::fibonacci_directions;

const char* const kZh3Names[] = {"zh3_lum",     "zh3_channel",         "zh3_solved_lum",      "zh3_solved_channel",
                                 "hall_ambdir", "hall_sphere",         "hall_curve",          "hall_ambdir_channel",
                                 "hall_sphere_channel", "hall_curve_channel", "zh3_lum_dering",
                                 "zh3_lum_dering_sphere"};

const Codec& codec(const char* name) {
    const Codec* c = find_codec(name);
    if (!c) {
        ADD_FAILURE() << "missing codec " << name;
        return *find_codec("sh3");
    }
    return *c;
}

Sh3Radiance round_trip(const Codec& c, const Sh3Radiance& in, const CodecOptions& o = {}, EncodeStats* stats = nullptr) {
    std::vector<std::uint8_t> bytes(c.size_bytes);
    c.encode(in, o, bytes.data(), stats);
    return c.decode(bytes.data(), o);
}

double coefficient_distance(const Sh3Radiance& a, const Sh3Radiance& b, int from = 0, int to = 9) {
    double s = 0;
    for (int i = from; i < to; ++i)
        for (int k = 0; k < 3; ++k) s += (double(a[i][k]) - b[i][k]) * (double(a[i][k]) - b[i][k]);
    return std::sqrt(s);
}
double coefficient_norm(const Sh3Radiance& a, int from = 0, int to = 9) { return coefficient_distance(a, Sh3Radiance{}, from, to); }

// ---- inputs -----------------------------------------------------------------------------------

struct Rng : test::Rng {
    using test::Rng::Rng;
    Rgb colour() { return {float(0.1 + u()), float(0.1 + u()), float(0.1 + u())}; }
};

// A sum of deltas, sphere lights and hemispheres with random colours: a non-negative lighting.
Sh3Radiance random_lighting(Rng& rng) {
    Sh3Radiance sh = project_constant({float(0.05 * rng.u()), float(0.05 * rng.u()), float(0.05 * rng.u())});
    const int n = 1 + static_cast<int>(rng.u() * 4);
    for (int i = 0; i < n; ++i) {
        const double kind = rng.u();
        const Vec3 d = rng.dir();
        if (kind < 0.35) {
            sh = sh + project_directional(d, rng.colour());
        } else if (kind < 0.8) {
            const double sigma = 0.05 + 1.5 * rng.u();
            sh = sh + project_cone(d, sigma, rng.colour());
        } else {
            sh = sh + project_hemisphere(d, rng.colour());
        }
    }
    return sh;
}
// Random coefficients (not necessarily from a non-negative function), DC kept positive.
Sh3Radiance random_coefficients(Rng& rng) {
    Sh3Radiance sh;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) sh[i][k] = static_cast<float>(i == 0 ? 1.0 + rng.u() : 2.0 * rng.u() - 1.0);
    return sh;
}

struct RealMap {
    std::string name;
    Sh3Radiance sh;
    std::vector<Rgb> true_irradiance;  // at reference_directions(), from the 256x128 downsample
};
const std::vector<Vec3>& reference_directions() {
    static const std::vector<Vec3> dirs = fibonacci_directions(2048);
    return dirs;
}
// Reference irradiance of a map at reference_directions() by direct integration.
void add_true_irradiance(const Image& img, RealMap* out) {
    // Same sum as test::integrate_irradiance (flux-preserving 4x box downsample to 256x128), with the
    // pixel directions and solid angles computed once instead of per direction.
    RealMap& m = *out;
    const Image small = test::downsample_latlong(img, 4);
    std::vector<Vec3> pixel_dir;
    std::vector<double> pixel_weight;
    for (int y = 0; y < small.height; ++y)
        for (int x = 0; x < small.width; ++x) {
            pixel_dir.push_back(latlong_direction(x, y, small.width, small.height));
            pixel_weight.push_back(latlong_pixel_solid_angle(y, small.width, small.height));
        }
    for (const Vec3 n : reference_directions()) {
        double acc[3] = {};
        for (size_t i = 0; i < pixel_dir.size(); ++i) {
            const double c = dot(n, pixel_dir[i]);
            if (c <= 0) continue;
            for (int k = 0; k < 3; ++k) acc[k] += pixel_weight[i] * c * small.rgb[i * 3 + static_cast<size_t>(k)];
        }
        m.true_irradiance.push_back({float(acc[0] / kPi), float(acc[1] / kPi), float(acc[2] / kPi)});
    }
    // spot check against the support twin
    const Rgb twin = test::integrate_irradiance(small, reference_directions()[100]);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(twin[k], m.true_irradiance[100][k], 1e-5 * (1 + std::fabs(twin[k])));
}

// The eight maps; with_true_irradiance also integrates the reference irradiance (slower).
std::vector<RealMap> load_real_maps(bool with_true_irradiance) {
    std::vector<RealMap> out;
    {
        for (const std::string& path : test::envmap_paths()) {
            const Image img = test::load_envmap(path);
            if (img.width == 0) continue;
            RealMap m;
            m.name = test::envmap_name(path);
            m.sh = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
            if (with_true_irradiance) add_true_irradiance(img, &m);
            out.push_back(std::move(m));
        }
    }
    return out;
}
// The eight maps projected exactly at full resolution, loaded once per test process.
const std::vector<RealMap>& real_maps() {
    static const std::vector<RealMap> maps = load_real_maps(false);
    return maps;
}

Mat3 random_rotation(Rng& rng) {
    const Vec3 axis = rng.dir();
    return rotation_axis_angle(axis, 2 * kPi * rng.u());
}

// ---- fit ----------------------------------------------------------------------------------------

TEST(Zh3Fit, ZonalSignalIsReproducedExactly) {
    Rng rng(11);
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 axis = rng.dir();
        const double sigma = 0.02 + (kPi - 0.04) * rng.u();
        const Sh3Radiance in = project_cone(axis, sigma, rng.colour());
        for (const char* name : {"zh3_lum", "zh3_channel", "zh3_solved_lum", "zh3_solved_channel"}) {
            const Sh3Radiance out = round_trip(codec(name), in);
            EXPECT_LE(coefficient_distance(in, out), 2e-6 * coefficient_norm(in)) << name << " sigma " << sigma;
        }
    }
}

TEST(Zh3Fit, MatchesTheLeastSquaresZonalFitByDirectSearch) {
    // Slow twin of Eq. 9/10: the zonal coefficient minimising the L2-band error, by scanning.
    Rng rng(12);
    for (int trial = 0; trial < 20; ++trial) {
        const Sh3Radiance in = random_coefficients(rng);
        for (auto mode : {ZonalAxisMode::kLuminance, ZonalAxisMode::kPerChannel}) {
            const Zh3 z = zh3_fit(in, mode, {});
            for (int k = 0; k < 3; ++k) {
                const Vec3 a = zh3_axis(z.linear, mode, k, {});
                const auto y = sh3_basis(a);
                auto err = [&](double c) {
                    double e = 0;
                    for (int m = 0; m < 5; ++m) {
                        const double d = c * std::sqrt(4 * kPi / 5) * y[4 + m] - in[4 + m][k];
                        e += d * d;
                    }
                    return e;
                };
                double best = 0, best_e = err(0);
                for (double c = -4; c <= 4; c += 1e-4)
                    if (err(c) < best_e) best_e = err(c), best = c;
                EXPECT_NEAR(z.zonal[k], best, 1.5e-4);
                EXPECT_LE(err(z.zonal[k]), best_e + 1e-9);
            }
        }
    }
}

TEST(Zh3Fit, NeverHasHigherL2BandErrorThanDroppingL2) {
    Rng rng(13);
    std::vector<Sh3Radiance> inputs;
    for (int i = 0; i < 300; ++i) inputs.push_back(i % 2 ? random_lighting(rng) : random_coefficients(rng));
    for (const RealMap& m : real_maps()) inputs.push_back(m.sh);
    for (const Sh3Radiance& in : inputs)
        for (const char* name : {"zh3_lum", "zh3_channel"}) {  // (deringing trades L2 error for non-negativity)
            const Sh3Radiance out = round_trip(codec(name), in);
            for (int k = 0; k < 3; ++k) {
                double err = 0, dropped = 0;
                for (int i = 4; i < 9; ++i) {
                    err += (double(out[i][k]) - in[i][k]) * (double(out[i][k]) - in[i][k]);
                    dropped += double(in[i][k]) * in[i][k];
                }
                EXPECT_LE(err, dropped * (1 + 1e-6) + 1e-12) << name;
            }
        }
}

TEST(Zh3, EveryVariantKeepsL0ExactAndLinearWhereStored) {
    Rng rng(14);
    for (int trial = 0; trial < 100; ++trial) {
        const Sh3Radiance in = trial % 2 ? random_lighting(rng) : random_coefficients(rng);
        for (const char* name : kZh3Names) {
            const Sh3Radiance out = round_trip(codec(name), in);
            for (int k = 0; k < 3; ++k) EXPECT_EQ(out[0][k], in[0][k]) << name;
            // Everything but the solves keeps the linear band bit-exact.
            if (std::strstr(name, "solved") == nullptr) {
                for (int i = 1; i < 4; ++i)
                    for (int k = 0; k < 3; ++k) EXPECT_EQ(out[i][k], in[i][k]) << name;
            }
        }
    }
}

TEST(Zh3, StoredSizesAndHallucinatedBytesEqualLinearSh) {
    Rng rng(15);
    const Sh3Radiance in = random_lighting(rng);
    std::vector<std::uint8_t> sh2(48), other;
    codec("sh2").encode(in, {}, sh2.data(), nullptr);
    for (const char* name : kZh3Names) {
        const Codec& c = codec(name);
        const bool hall = std::strncmp(name, "hall_", 5) == 0;
        EXPECT_EQ(c.size_bytes, hall ? 48u : 60u) << name;
        other.assign(c.size_bytes, 0xAB);
        c.encode(in, {}, other.data(), nullptr);
        if (hall) {
            EXPECT_EQ(other, sh2) << name;
        }
    }
}

TEST(Zh3, RotationEquivariance) {
    Rng rng(16);
    for (int trial = 0; trial < 100; ++trial) {
        const Sh3Radiance in = trial % 2 ? random_lighting(rng) : random_coefficients(rng);
        const Mat3 r = random_rotation(rng);
        for (const char* name : kZh3Names) {
            const Codec& c = codec(name);
            const Sh3Radiance a = round_trip(c, rotate(in, r));
            const Sh3Radiance b = rotate(round_trip(c, in), r);
            // Solves are equivariant in exact arithmetic (starts, objective and BFGS all are);
            // float rounding may end them an iteration apart.
            const double tol = std::strstr(name, "solved") ? 2e-3 : 2e-5;
            EXPECT_LE(coefficient_distance(a, b), tol * coefficient_norm(in)) << name << " trial " << trial;
        }
    }
}

TEST(Zh3, IrradianceFastPathMatchesExpansionTwin) {
    Rng rng(17);
    const auto dirs = fibonacci_directions(300);
    for (int trial = 0; trial < 30; ++trial) {
        const Sh3Radiance in = trial % 2 ? random_lighting(rng) : random_coefficients(rng);
        for (const char* name : kZh3Names) {
            const Codec& c = codec(name);
            std::vector<std::uint8_t> bytes(c.size_bytes);
            c.encode(in, {}, bytes.data(), nullptr);
            const Sh3Radiance decoded = c.decode(bytes.data(), {});
            for (const Vec3 n : dirs) {
                const Rgb fast = c.irradiance(bytes.data(), {}, n), slow = irradiance(decoded, n);
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(fast[k], slow[k], 1e-5 * (1 + std::fabs(slow[k]))) << name;
            }
        }
    }
}

TEST(Zh3, DecodersAreTotalOnArbitraryBytes) {
    std::mt19937 gen(18);
    std::vector<std::uint8_t> bytes(60);
    for (int trial = 0; trial < 2000; ++trial) {
        for (auto& b : bytes) b = static_cast<std::uint8_t>(gen());
        if (trial % 5 == 0) std::fill(bytes.begin(), bytes.end(), trial % 10 == 0 ? 0x00 : 0xFF);  // zeros, NaNs
        for (const char* name : kZh3Names) {
            const Codec& c = codec(name);
            (void)c.decode(bytes.data(), {});
            (void)c.irradiance(bytes.data(), {}, {0, 0, 1});
        }
    }
    SUCCEED();
}

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

// ---- scale invariance (issue 18, finding 1) -------------------------------------------------------

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

// ---- multi-start against a brute-force axis search (issue 18, finding 2) ---------------------------

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
    // (the notes give a 10,000-probe run); 2,000 keeps the sanitizer build quick.
    int probes = 2000;
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

// ---- hallucination ------------------------------------------------------------------------------

TEST(Zh3Hallucinate, SphereModelReproducesASphereLightFromItsLinearSh) {
    Rng rng(26);
    for (int trial = 0; trial < 300; ++trial) {
        const Vec3 axis = rng.dir();
        const double sigma = 0.01 + (kPi - 0.02) * rng.u();  // Eq. 20 holds for every cone, sigma in (0, pi)
        const Sh3Radiance in = project_cone(axis, sigma, rng.colour());
        for (const char* name : {"hall_sphere", "hall_sphere_channel"}) {
            const Sh3Radiance out = round_trip(codec(name), in);
            EXPECT_LE(coefficient_distance(in, out), 1e-5 * coefficient_norm(in)) << name << " sigma " << sigma;
        }
    }
}

TEST(Zh3Hallucinate, Eq20IsEq15ThroughEq19) {
    for (double sigma = 0; sigma <= kPi; sigma += 1e-3) {
        const ZonalCoefficients z = cone_zonal(sigma, 1.7);
        if (z.f0 <= 0) continue;
        EXPECT_NEAR(hallucinate_zonal(Hallucination::kSphere, z.f0, z.f1, 0, 0), z.f2, 1e-12 * (1 + z.f0));
        EXPECT_NEAR(hallucinate_zonal(Hallucination::kSphere, z.f0, -z.f1, 0, 0), z.f2, 1e-12 * (1 + z.f0));
    }
    // p beyond sqrt(3) (impossible for non-negative lighting) is clamped to the delta light's sqrt(5) f0.
    EXPECT_NEAR(hallucinate_zonal(Hallucination::kSphere, 1.0, 5.0, 0, 0), std::sqrt(5.0), 1e-12);
    EXPECT_EQ(hallucinate_zonal(Hallucination::kSphere, 0.0, 1.0, 0, 0), 0.0);
    EXPECT_EQ(hallucinate_zonal(Hallucination::kCurve, -1.0, 1.0, 0.6, 0.08), 0.0);
}

TEST(Zh3Hallucinate, AmbientDirectionalReproducesADirectionalLight) {
    Rng rng(27);
    for (int trial = 0; trial < 100; ++trial) {
        const Vec3 d = rng.dir();
        const Sh3Radiance in = project_directional(d, rng.colour());
        for (const char* name : {"hall_ambdir", "hall_ambdir_channel"}) {
            const Sh3Radiance out = round_trip(codec(name), in);
            EXPECT_LE(coefficient_distance(in, out), 1e-5 * coefficient_norm(in)) << name;
        }
        // and a directional light plus ambient
        const Sh3Radiance amb = in + project_constant({0.3f, 0.2f, 0.1f});
        EXPECT_LE(coefficient_distance(amb, round_trip(codec("hall_ambdir"), amb)), 1e-5 * coefficient_norm(amb));
    }
}

TEST(Zh3Hallucinate, CurveFollowsEq21AndListing1) {
    // Listing 1 written out literally (float maths, luminance axis, abs of the projected L1).
    Rng rng(28);
    CodecOptions o;
    o.hallucinate_a = 0.6;
    o.hallucinate_b = 0.08;
    const Codec& c = codec("hall_curve");
    for (int trial = 0; trial < 200; ++trial) {
        const Sh3Radiance in = trial % 2 ? random_lighting(rng) : random_coefficients(rng);
        std::vector<std::uint8_t> bytes(c.size_bytes);
        c.encode(in, o, bytes.data(), nullptr);
        const Vec3 n = rng.dir();
        float lum[3];
        for (int i = 1; i < 4; ++i) lum[i - 1] = 0.2126f * in[i].r + 0.7152f * in[i].g + 0.0722f * in[i].b;
        float ax[3] = {-lum[2], -lum[0], lum[1]};
        const float len = std::sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
        for (float& v : ax) v /= len;
        const Rgb got = c.irradiance(bytes.data(), o, n);
        for (int k = 0; k < 3; ++k) {
            float ratio = std::fabs(-in[3][k] * ax[0] - in[1][k] * ax[1] + in[2][k] * ax[2]) / in[0][k];
            ratio = std::min(ratio, std::sqrt(3.0f));  // zhc clamps p (documented)
            const float zonal = in[0][k] * (0.08f * ratio + 0.6f * ratio * ratio);
            const float fz = ax[0] * float(n.x) + ax[1] * float(n.y) + ax[2] * float(n.z);
            const float zh = std::sqrt(5.0f / (16.0f * float(kPi))) * (3.0f * fz * fz - 1.0f);
            const Rgb lin = irradiance(truncate_to_sh2(in), n);
            const float want = lin[k] + 0.25f * zonal * zh;
            EXPECT_NEAR(got[k], want, 2e-5f * (1 + std::fabs(want) + in[0][k]));
        }
    }
    // Coefficients are options.
    o.hallucinate_a = 0;
    o.hallucinate_b = 0;
    const Sh3Radiance in = random_lighting(rng);
    EXPECT_EQ(coefficient_norm(round_trip(c, in, o), 4, 9), 0.0);
}

// ---- ZH3 deringing (App. B) ---------------------------------------------------------------------

double min_along(double f0, double f1, double f20) {
    double m = 1e300;
    for (int i = 0; i <= 20000; ++i) {
        const double z = -1.0 + 2.0 * i / 20000;
        m = std::min(m, kY00 * f0 + 2.0 / 3.0 * kY1 * f1 * z + 0.25 * kY20 * f20 * (3 * z * z - 1));
    }
    return m;
}

TEST(Zh3Dering, IntervalIsExactByDenseSampling) {
    // Inside the interval the zonal irradiance is >= 0 for every z; just outside it goes negative.
    for (double a = 0; a <= std::sqrt(3.0); a += 0.01) {
        const double f0 = 1.3, f1 = a * std::sqrt(3.0) * f0 / 2.0;
        const ZonalInterval iv = zh3_dering_interval(f0, f1);
        ASSERT_TRUE(iv.feasible) << a;
        const double scale = kY00 * f0, eps = 1e-3 * (iv.hi - iv.lo + 1);
        EXPECT_GE(min_along(f0, f1, iv.lo), -1e-9 * scale) << a;
        EXPECT_GE(min_along(f0, f1, iv.hi), -1e-9 * scale) << a;
        EXPECT_GE(min_along(f0, f1, 0.5 * (iv.lo + iv.hi)), -1e-9 * scale) << a;
        EXPECT_LT(min_along(f0, f1, iv.lo - eps), 0.0) << a;
        EXPECT_LT(min_along(f0, f1, iv.hi + eps), 0.0) << a;
        // symmetric in the sign of the L1 (z -> -z)
        const ZonalInterval neg = zh3_dering_interval(f0, -f1);
        EXPECT_EQ(neg.lo, iv.lo);
        EXPECT_EQ(neg.hi, iv.hi);
    }
    // Beyond sqrt(3) nothing is feasible; the chosen value maximises the minimum (scan check).
    for (double a : {1.75, 1.9, 2.5}) {
        const double f0 = 1.0, f1 = a * std::sqrt(3.0) / 2.0;
        const ZonalInterval iv = zh3_dering_interval(f0, f1);
        EXPECT_FALSE(iv.feasible);
        const double got = min_along(f0, f1, iv.lo);
        for (double f20 = -4; f20 <= 4; f20 += 0.01) EXPECT_GE(got, min_along(f0, f1, f20) - 1e-9) << a;
    }
}

TEST(Zh3Dering, PapersEq25LowerBoundIsNotSufficientAboveThreeHalves) {
    // App. B claims the max of (az - 1)/(3z^2 - 1) over (1/sqrt 3, 1] is at z = 1, giving b >= (a - 1)/2.
    // For a > 3/2 it is interior: b = (a - 1)/2 leaves negative irradiance. zhc uses b- instead.
    const double a = 1.7, f0 = 1.0, f1 = a * std::sqrt(3.0) / 2.0;
    const double paper_lo = (a - 1) / 2 * 8 * f0 / std::sqrt(5.0);
    EXPECT_LT(min_along(f0, f1, paper_lo), -1e-3 * kY00);
    EXPECT_GT(zh3_dering_interval(f0, f1).lo, paper_lo);
    // Its upper bound b <= sqrt(5)/4 (Eq. 24-26, f20 <= 2 f0) is too high near a = sqrt(3), where
    // the exact upper bound b+ = (1 + sqrt(1 - a^2/3)) / 2 tends to 1/2 ...
    const double a2 = std::sqrt(3.0) - 1e-3, f1b = a2 * std::sqrt(3.0) / 2.0;
    EXPECT_LT(min_along(f0, f1b, 2.0 * f0), -1e-3 * kY00);
    EXPECT_LT(zh3_dering_interval(f0, f1b).hi, 2.0 * f0);
    // ... and needlessly low for small a (b+ tends to 1, i.e. f20 <= 8 f0 / sqrt(5)).
    EXPECT_GE(min_along(f0, 0.0, 8.0 / std::sqrt(5.0) * f0), -1e-12);
    EXPECT_NEAR(zh3_dering_interval(f0, 0.0).hi, 8.0 / std::sqrt(5.0) * f0, 1e-12);
}

TEST(Zh3Dering, ClampedResultIsNonNegativeAlongTheAxisAndValidInputsAreUnchanged) {
    Rng rng(29);
    std::vector<Sh3Radiance> inputs;
    for (int i = 0; i < 300; ++i) inputs.push_back(random_lighting(rng));
    for (int i = 0; i < 100; ++i) inputs.push_back(random_coefficients(rng));
    for (const RealMap& m : real_maps()) inputs.push_back(m.sh);
    // monochrome inputs: L1 of every channel parallel to the axis, so the guarantee is global
    for (int i = 0; i < 100; ++i) {
        Sh3Radiance s = random_lighting(rng);
        for (int j = 0; j < 9; ++j) s[j].g = s[j].b = s[j].r;
        inputs.push_back(s);
    }
    const auto sphere = fibonacci_directions(20000);
    const auto coarse = fibonacci_directions(4000);
    int clamped = 0, unchanged = 0, negative_before = 0, negative_after = 0, nonneg_inputs = 0, infeasible = 0,
        negative_after_feasible = 0;
    const Codec& dering = codec("zh3_lum_dering");
    const Codec& plain = codec("zh3_lum");
    for (size_t idx = 0; idx < inputs.size(); ++idx) {
        const Sh3Radiance& in = inputs[idx];
        std::vector<std::uint8_t> a(60), b(60);
        EncodeStats st;
        dering.encode(in, {}, a.data(), &st);
        plain.encode(in, {}, b.data(), nullptr);
        const bool was_valid = [&] {
            const Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, {});
            for (int k = 0; k < 3; ++k) {
                const double f1 = dot(Vec3{-z.linear[3][k], -z.linear[1][k], z.linear[2][k]},
                                      zh3_axis(z.linear, ZonalAxisMode::kLuminance, 0, {}));
                const ZonalInterval iv = zh3_dering_interval(z.linear[0][k], f1);
                if (!(z.zonal[k] >= iv.lo && z.zonal[k] <= iv.hi)) return false;
            }
            return true;
        }();
        EXPECT_EQ(st.dering_clamped, !was_valid);
        if (was_valid) {
            EXPECT_EQ(a, b) << "valid input changed";
            ++unchanged;
        } else {
            ++clamped;
        }
        // Dense check along the axis: circle averages of irradiance (the perpendicular L1 averages
        // out) and the two poles, for every channel with positive DC.
        const Sh3Radiance dec = dering.decode(a.data(), {});
        if (idx < 300 || idx >= inputs.size() - 108) {  // non-negative lighting (random lights, maps, mono)
            const Sh3Radiance before = plain.decode(b.data(), {});
            bool neg_b = false, neg_a = false;
            for (const Vec3 n : coarse) {
                const Rgb eb = irradiance(before, n), ea = irradiance(dec, n);
                for (int k = 0; k < 3; ++k) {
                    neg_b |= eb[k] < -1e-6 * kY00 * in[0][k];
                    neg_a |= ea[k] < -1e-6 * kY00 * in[0][k];
                }
            }
            bool feasible = true;
            const Vec3 ax = zh3_axis(truncate_to_sh2(dec), ZonalAxisMode::kLuminance, 0, {});
            for (int k = 0; k < 3; ++k)
                feasible &= zh3_dering_interval(dec[0][k], dot(Vec3{-dec[3][k], -dec[1][k], dec[2][k]}, ax)).feasible;
            ++nonneg_inputs;
            infeasible += !feasible;
            negative_before += neg_b;
            negative_after += neg_a;
            negative_after_feasible += neg_a && feasible;
        }
        const Vec3 axis = zh3_axis(truncate_to_sh2(dec), ZonalAxisMode::kLuminance, 0, {});
        const Mat3 frame = frame_from_z(axis);
        for (int k = 0; k < 3; ++k) {
            const double f0 = dec[0][k];
            if (f0 <= 0) continue;
            const double dc = kY00 * f0;
            const double f1 = dot(Vec3{-dec[3][k], -dec[1][k], dec[2][k]}, axis);
            const bool aligned = std::fabs(std::fabs(f1) - length(Vec3{-dec[3][k], -dec[1][k], dec[2][k]})) <=
                                 1e-6 * (1 + std::fabs(f1));
            const double lhs_l1 = std::fabs(f1) * 2 / (std::sqrt(3.0) * f0);
            for (int i = 0; i <= 400; ++i) {
                const double zc = -1.0 + 2.0 * i / 400, r = std::sqrt(std::max(0.0, 1 - zc * zc));
                double avg = 0;
                for (int j = 0; j < 16; ++j) {
                    const double phi = 2 * kPi * j / 16;
                    const Vec3 n = frame * Vec3{r * std::cos(phi), r * std::sin(phi), zc};
                    avg += irradiance(dec, n)[k] / 16.0;
                }
                if (lhs_l1 <= std::sqrt(3.0)) {
                    EXPECT_GE(avg, -1e-6 * dc) << "input " << idx << " z " << zc;
                }
            }
            if (aligned && lhs_l1 <= std::sqrt(3.0)) {
                for (const Vec3 n : sphere) EXPECT_GE(irradiance(dec, n)[k], -1e-6 * dc) << "input " << idx;
            }
        }
    }
    std::printf("zh3_lum_dering: %d inputs clamped, %d unchanged; of %d non-negative lightings %d had negative"
                " irradiance somewhere with zh3_lum, %d with zh3_lum_dering (4000 directions); %d have a channel with"
                " a > sqrt(3) (no safe zonal value); %d of the others stay negative off the axis\n",
                clamped, unchanged, nonneg_inputs, negative_before, negative_after, infeasible, negative_after_feasible);
    EXPECT_LE(negative_after, negative_before);
    EXPECT_GT(clamped, 0);
    EXPECT_GT(unchanged, 0);
}

TEST(Zh3Dering, SphereVariantIsNonNegativeEverywhereWhenAnyZonalValueIs) {
    Rng rng(30);
    std::vector<Sh3Radiance> inputs;
    for (int i = 0; i < 300; ++i) inputs.push_back(random_lighting(rng));
    for (int i = 0; i < 60; ++i) inputs.push_back(random_coefficients(rng));
    for (const RealMap& m : real_maps()) inputs.push_back(m.sh);
    const auto sphere = fibonacci_directions(20000);
    const auto coarse = fibonacci_directions(3000);
    const Codec& strict = codec("zh3_lum_dering_sphere");
    const Codec& plain = codec("zh3_lum");
    int clamped = 0, infeasible = 0, negative_before = 0;
    for (size_t idx = 0; idx < inputs.size(); ++idx) {
        const Sh3Radiance& in = inputs[idx];
        std::vector<std::uint8_t> a(60), b(60);
        EncodeStats st;
        strict.encode(in, {}, a.data(), &st);
        plain.encode(in, {}, b.data(), nullptr);
        if (!st.dering_clamped) {
            EXPECT_EQ(a, b);
        }
        clamped += st.dering_clamped;
        const Sh3Radiance dec = strict.decode(a.data(), {}), before = plain.decode(b.data(), {});
        for (int k = 0; k < 3; ++k) {
            const double dc = kY00 * in[0][k];
            if (dc <= 0) continue;
            double mn = 1e300, mn_before = 1e300;
            for (const Vec3 n : sphere) {
                mn = std::min(mn, double(irradiance(dec, n)[k]));
                mn_before = std::min(mn_before, double(irradiance(before, n)[k]));
            }
            negative_before += mn_before < -1e-6 * dc;
            if (mn >= -1e-6 * dc) {
                // Nearest to the fit: 10 % of the way back towards the fitted value goes negative
                // (checked where the fit is clearly negative, so the sampled minimum resolves it).
                if (dec[6][k] != before[6][k] && mn_before < -1e-3 * dc) {
                    Sh3Radiance back = dec;
                    for (int i = 4; i < 9; ++i) back[i][k] = dec[i][k] + 0.1f * (before[i][k] - dec[i][k]);
                    double m2 = 1e300;
                    for (const Vec3 n : sphere) m2 = std::min(m2, double(irradiance(back, n)[k]));
                    EXPECT_LT(m2, 0.0) << "input " << idx << " channel " << k;
                }
                continue;
            }
            // Still negative: then no zonal value at all makes this channel non-negative (scan).
            ++infeasible;
            Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, {});
            double best = -1e300;
            for (double f20 = -4.0 * in[0][k]; f20 <= 4.0 * in[0][k]; f20 += 0.02 * in[0][k]) {
                z.zonal[k] = static_cast<float>(f20);
                const Sh3Radiance e = zh3_expand(z, ZonalAxisMode::kLuminance, {});
                double m = 1e300;
                for (const Vec3 n : coarse) m = std::min(m, double(irradiance(e, n)[k]));
                best = std::max(best, m);
            }
            EXPECT_LT(best, 1e-6 * dc) << "input " << idx << " channel " << k;
            // and the stored value is (close to) the least negative one
            EXPECT_GE(mn, best - 5e-3 * dc - 1e-9) << "input " << idx << " channel " << k;
        }
    }
    std::printf("zh3_lum_dering_sphere: %zu inputs, %d clamped, %d channels negative with zh3_lum, %d channels with no"
                " non-negative zonal value\n",
                inputs.size(), clamped, negative_before, infeasible);
    EXPECT_GT(clamped, 0);
}

// ---- real maps: irradiance RMSE table ----------------------------------------------------------

TEST(Zh3RealMaps, IrradianceRmseTable) {
    const std::vector<RealMap> maps = load_real_maps(true);
    ASSERT_EQ(maps.size(), 8u);
    const auto& dirs = reference_directions();
    std::vector<std::string> names = {"sh2", "sh3"};
    for (const char* n : kZh3Names) names.push_back(n);
    // rmse[ref][name][map]; ref 0 = true irradiance (direct integration), 1 = SH3 irradiance
    std::map<std::string, std::vector<double>> rmse[2];
    for (const RealMap& m : maps) {
        for (const std::string& name : names) {
            const Codec& c = *find_codec(name);
            std::vector<std::uint8_t> bytes(c.size_bytes);
            c.encode(m.sh, {}, bytes.data(), nullptr);
            double s[2] = {0, 0};
            for (size_t i = 0; i < dirs.size(); ++i) {
                const Rgb e = c.irradiance(bytes.data(), {}, dirs[i]);
                const Rgb ref_sh3 = irradiance(m.sh, dirs[i]);
                for (int k = 0; k < 3; ++k) {
                    s[0] += (double(e[k]) - m.true_irradiance[i][k]) * (double(e[k]) - m.true_irradiance[i][k]);
                    s[1] += (double(e[k]) - ref_sh3[k]) * (double(e[k]) - ref_sh3[k]);
                }
            }
            for (int r = 0; r < 2; ++r) rmse[r][name].push_back(std::sqrt(s[r] / (3.0 * dirs.size())));
        }
    }
    for (int r = 0; r < 2; ++r) {
        std::printf("\nirradiance RMSE vs %s (2048 Fibonacci directions)\n%-20s", r == 0 ? "TRUE irradiance (256x128 integration)" : "SH3 irradiance", "");
        for (const RealMap& m : maps) std::printf("%10s", m.name.c_str());
        std::printf("%12s\n", "mean/sh2");
        for (const std::string& name : names) {
            std::printf("%-20s", name.c_str());
            double ratio = 0;
            for (size_t i = 0; i < maps.size(); ++i) {
                std::printf("%10.5f", rmse[r][name][i]);
                ratio += rmse[r][name][i] / rmse[r]["sh2"][i];
            }
            std::printf("%12.3f\n", ratio / maps.size());
        }
    }
    // Acceptance (issue 3), against the true irradiance: averaged over the maps, zh3_lum cuts RMSE
    // against sh2 by at least a third and hall_curve by at least a fifth.
    auto mean_ratio = [&](const std::string& name) {
        double s = 0;
        for (size_t i = 0; i < maps.size(); ++i) s += rmse[0][name][i] / rmse[0]["sh2"][i];
        return s / maps.size();
    };
    auto ratio_of_means = [&](const std::string& name) {
        double a = 0, b = 0;
        for (size_t i = 0; i < maps.size(); ++i) a += rmse[0][name][i], b += rmse[0]["sh2"][i];
        return a / b;
    };
    EXPECT_LE(mean_ratio("zh3_lum"), 2.0 / 3.0);
    EXPECT_LE(ratio_of_means("zh3_lum"), 2.0 / 3.0);
    EXPECT_LE(mean_ratio("hall_curve"), 0.8);
    EXPECT_LE(ratio_of_means("hall_curve"), 0.8);
    // Against SH3 the solves are never worse than the fits (Eq. 11 is that squared error, sampled here).
    for (size_t i = 0; i < maps.size(); ++i) {
        EXPECT_LE(rmse[1]["zh3_solved_lum"][i], rmse[1]["zh3_lum"][i] * (1 + 1e-3));
        EXPECT_LE(rmse[1]["zh3_solved_channel"][i], rmse[1]["zh3_channel"][i] * (1 + 1e-3));
    }
}

}  // namespace
}  // namespace zhc
