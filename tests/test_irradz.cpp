// IrradZ / HHD / AHD lightmap maths (codec/lightmap/irradz.h) against brute-force twins: dense sphere and
// hemisphere sampling, grid searches, direct integration. Derivations: docs/irradz.md. The Newton
// solve is tested in test_irradz_newton.cpp (helpers: irradz_helpers.h).
#include <cstdio>
#include <limits>
#include <random>

#include "codec/lightmap/irradz.h"
#include "irradz_helpers.h"
#include "support.h"

namespace zhc {
namespace {

using namespace irradz_test;

TEST(IrradzGram, CapGramMatchesDenseSampling) {
    for (const double c : {-1.0, 0.0, 0.5, 0.9}) {
        const auto g = cap_gram(c);
        double b[81] = {};
        const auto dirs = fibonacci_directions(200000);
        for (const Vec3 v : dirs) {
            if (v.z < c) continue;
            const auto y = sh3_basis(v);
            for (int i = 0; i < 9; ++i)
                for (int j = 0; j < 9; ++j) b[i * 9 + j] += y[i] * y[j] * 4 * kPi / dirs.size();
        }
        for (int i = 0; i < 81; ++i) EXPECT_NEAR(g[i], b[i], 2e-3) << "c=" << c << " i=" << i;
        if (c == -1.0) {
            for (int i = 0; i < 9; ++i) EXPECT_NEAR(g[i * 10], 1.0, 1e-12);
        }
    }
    // The hemisphere Gram matrix is not the identity (that is the point of the talk's solve).
    EXPECT_NEAR(hemisphere_gram()[0], 0.5, 1e-12);
    EXPECT_GT(std::abs(hemisphere_gram()[2]), 0.1);  // <Y00, Y10> over the hemisphere
}

TEST(IrradzModel, ShProjectionMatchesBruteForceProjection) {
    std::mt19937 rng(1);
    for (int t = 0; t < 6; ++t)
        for (const Model model : {Model::kHhd, Model::kAhd}) {
            IrradZ p;
            p.i_z = Rgb{1.5f, 0.7f, 0.2f};
            p.w_a = 0.2 + 0.1 * t;
            p.d = upper_direction(rng, kMaxTheta);
            const Sh3Irradiance m = model_sh3(p, model);
            // Project the model's irradiance (a function on the whole sphere) by dense sampling.
            const auto dirs = fibonacci_directions(100000);
            double acc[9][3] = {};
            for (const Vec3 n : dirs) {
                const Rgb e = evaluate(p, model, n);
                const auto y = sh3_basis(n);
                for (int i = 0; i < 9; ++i)
                    for (int k = 0; k < 3; ++k) acc[i][k] += e[k] * y[i] * 4 * kPi / dirs.size();
            }
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(m[i][k], acc[i][k], 2e-3) << i << " " << k;
        }
    // The hemisphere term is the irradiance of a hemisphere light (zhc's closed form).
    IrradZ hemi;
    hemi.i_z = Rgb{1, 1, 1};
    hemi.w_a = 1;
    const Sh3Irradiance m = model_sh3(hemi, Model::kHhd);
    const Sh3Irradiance ref = to_irradiance(project_hemisphere({0, 0, 1}, Rgb{1, 1, 1}));
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(m[i].g, ref[i].g, 1e-6) << i;
}

TEST(IrradzModel, ReconstructionHoldsIzExact) {
    std::mt19937 rng(2);
    for (int t = 0; t < 50; ++t) {
        IrradZ p;
        p.i_z = Rgb{2.0f, 1.0f, 0.25f};
        p.w_a = (t % 11) / 10.0;
        p.d = upper_direction(rng, kMaxTheta);
        for (const Model model : {Model::kHhd, Model::kAhd}) {
            const Rgb e = evaluate(p, model, {0, 0, 1});
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(e[k], p.i_z[k], 1e-5 * p.i_z[k]);
            const Lighting l = to_lighting(p);
            EXPECT_NEAR(l.c_a.r, p.w_a * 2.0, 1e-6);
            EXPECT_NEAR(l.c_d.r, (1 - p.w_a) * 2.0 / p.d.z, 1e-4);
        }
    }
}

TEST(IrradzEncode, ErrorFormulasMatchDenseHemisphereIntegration) {
    std::mt19937 rng(3);
    for (int t = 0; t < 4; ++t) {
        const Sh3Irradiance target = to_irradiance(random_radiance(rng));
        IrradZ p;
        p.i_z = Rgb{3, 2.5f, 3.2f};
        p.w_a = 0.3 + 0.15 * t;
        p.d = upper_direction(rng, kMaxTheta);
        for (const Model model : {Model::kHhd, Model::kAhd}) {
            const Sh3Irradiance m = model_sh3(p, model);
            const double sh_err = sh_hemispherical_error(target, p, model);
            const double brute_sh = brute_error(target, [&](int k, Vec3 n) { return sh_eval(m, k, n); }, false);
            EXPECT_NEAR(sh_err, brute_sh, 2e-3 * brute_sh + 1e-6);
            const double mse = hemispherical_mse(target, p, model);
            const double brute_true =
                brute_error(target, [&](int k, Vec3 n) { return double(evaluate(p, model, n)[k]); }, true);
            EXPECT_NEAR(mse, brute_true, 5e-3 * brute_true + 1e-6);
        }
    }
}

TEST(IrradzEncode, LeastSquaresWaMatchesBruteForceScan) {
    // The sanitizer pass (ZHC_TEST_SAMPLE_SCALE=0.1, scripts/sanitize.sh) scans the first of the same
    // five targets (test::scaled_count); the Release pass scans all five.
    const long trials = test::scaled_count(5, 1);
    std::mt19937 rng(4);
    for (long t = 0; t < trials; ++t) {
        const Sh3Irradiance target = to_irradiance(random_radiance(rng));
        const Vec3 d = upper_direction(rng, 1.2);
        for (const bool hemi : {true, false}) {
            std::array<double, 81> sphere{};
            for (int i = 0; i < 9; ++i) sphere[static_cast<size_t>(i * 10)] = 1;
            const IrradZ p = solve_w_a(target, d, Model::kHhd, hemi ? hemisphere_gram() : sphere);
            // Brute force: scan w_a in steps of 0.001, error by dense sampling of the domain
            // (the hemisphere or the whole sphere), target and basis values cached per point.
            std::vector<Vec3> pts;
            for (const Vec3 n : fibonacci_directions(40000))
                if (!hemi || n.z >= 0) pts.push_back(n);
            std::vector<std::array<double, 9>> ys;
            std::vector<std::array<double, 3>> ts;
            for (const Vec3 n : pts) {
                ys.push_back(sh3_basis(n));
                ts.push_back({sh_eval(target, 0, n), sh_eval(target, 1, n), sh_eval(target, 2, n)});
            }
            double best_w = 0, best_e = 1e300;
            for (int s = 0; s <= 1000; ++s) {
                IrradZ q = p;
                q.w_a = s / 1000.0;
                const Sh3Irradiance m = model_sh3(q, Model::kHhd);
                double e = 0;
                for (size_t j = 0; j < pts.size(); ++j)
                    for (int k = 0; k < 3; ++k) {
                        double v = 0;
                        for (int i = 0; i < 9; ++i) v += m[i][k] * ys[j][static_cast<size_t>(i)];
                        e += (ts[j][static_cast<size_t>(k)] - v) * (ts[j][static_cast<size_t>(k)] - v);
                    }
                if (e < best_e) {
                    best_e = e;
                    best_w = q.w_a;
                }
            }
            EXPECT_NEAR(p.w_a, best_w, 0.002) << "hemi=" << hemi;
        }
    }
}

TEST(IrradzEncode, RecoversAmbientPlusDirectionalExactly) {
    // HHD represents a constant hemisphere light plus a directional light exactly (talk).
    std::mt19937 rng(5);
    for (int t = 0; t < 40; ++t) {
        const Solve solve = t % 2 ? Solve::kSearch : Solve::kNewton;  // the default and the reference
        const Vec3 d = upper_direction(rng, 1.35);
        const Rgb amb{0.3f, 0.5f, 0.8f};
        // Colours proportional so a single w_a can hold them (the IrradZ constraint).
        const double s = 2.0 + t;
        const Rgb dir{static_cast<float>(s * 0.3), static_cast<float>(s * 0.5), static_cast<float>(s * 0.8)};
        const Sh3Radiance rad = project_hemisphere({0, 0, 1}, amb) + project_directional(d, dir);
        double err_search = 0, err_old = 0, err_sh_iz = 0;
        // I_z sampled in the bake (exact); then the SH3 model of the lighting equals the target.
        const Rgb iz{static_cast<float>(amb.r + dir.r / kPi * d.z), static_cast<float>(amb.g + dir.g / kPi * d.z),
                     static_cast<float>(amb.b + dir.b / kPi * d.z)};
        EncodeOptions o;
        o.solve = solve;
        o.golden_iterations = 40;  // bracket 0.618^40 ~ 4e-9: the exactness test needs the precision
        const IrradZ p = encode(rad, o, &err_search, &iz);
        // I_z from the SH3 irradiance at the normal: not exact (SH3 truncation of the clamped
        // cosine), so only close.
        const IrradZ q = encode(rad, o, &err_sh_iz);
        EXPECT_GT(dot(q.d, d), std::cos(3 * kPi / 180)) << t;
        EXPECT_NEAR(q.w_a, p.w_a, 0.06) << t;
        o.solve = Solve::kTalkBaseline;
        encode(rad, o, &err_old, &iz);
        EXPECT_NEAR(dot(p.d, d), 1.0, 1e-9) << t;
        // I_z = C_a + C_d d_z, C_d = intensity / pi.
        EXPECT_NEAR(p.i_z.g, iz.g, 1e-6 * p.i_z.g);
        EXPECT_NEAR(p.w_a, amb.g / iz.g, 1e-5);
        EXPECT_LT(err_search, 1e-8 * (1 + err_old));
        if (d.z < 0.9) { EXPECT_GT(err_old, 100 * err_search + 1e-6); }
    }
}

TEST(IrradzEncode, SearchErrorEqualsTheGeneralErrorOfItsResult) {
    // The search scores directions with a per-texel evaluator (constant products hoisted, a.G a
    // over G's non-zero entries); its reported error must be the general closed form
    // (sh_hemispherical_error: the model's SH3, then r.G r) of the I_z, w_a, d it returns. The
    // returned parameters are stored in floats, hence the relative tolerance.
    const auto texels = real_texels();
    ASSERT_FALSE(texels.empty());
    int checked = 0;
    for (const Solve solve : {Solve::kNewton, Solve::kSearch})
    for (const Model model : {Model::kHhd, Model::kAhd})
        for (size_t t = 0; t < texels.size(); ++t) {
            EncodeOptions o;
            o.model = model;
            o.solve = solve;
            double e_search = -1;
            const IrradZ p = encode(texels[t], o, &e_search);
            const Sh3Irradiance irr = to_irradiance(texels[t]);
            const double e_general = sh_hemispherical_error(irr, p, model);
            double scale = 0;  // the squared DC irradiance, for texels that fit almost exactly
            for (int k = 0; k < 3; ++k) scale += double(irr[0][k]) * double(irr[0][k]);
            EXPECT_NEAR(e_search, e_general, 1e-5 * e_general + 1e-9 * scale) << t;
            ++checked;
        }
    EXPECT_EQ(checked, 4 * static_cast<int>(texels.size()));
}

TEST(IrradzEncode, GoldenSectionIsCloseToABruteForceDirectionGrid) {
    // Brute twin of the direction search: a 1-degree grid over the whole (theta, phi) range,
    // w_a by the same least squares at every grid point.
    const auto texels = real_texels();
    ASSERT_FALSE(texels.empty());
    double sum_search = 0, sum_grid = 0, sum_old = 0, sum_newton = 0;
    int worse = 0, worse_newton = 0;
    for (size_t t = 0; t < texels.size(); t += 3) {
        const Sh3Irradiance target = to_irradiance(texels[t]);
        double e_search = 0, e_old = 0, e_newton = 0;
        EncodeOptions o;
        encode(texels[t], o, &e_newton);
        o.solve = Solve::kSearch;
        encode(texels[t], o, &e_search);
        o.solve = Solve::kTalkBaseline;
        const IrradZ old = encode(texels[t], o, &e_old);
        e_old = sh_hemispherical_error(target, old, Model::kHhd);
        double best = 1e300;
        for (int ti = 0; ti <= 85; ++ti)
            for (int pi = 0; pi < 360; pi += (ti == 0 ? 360 : 1)) {
                const double th = ti * kPi / 180, ph = pi * kPi / 180;
                const IrradZ q = solve_w_a(target, {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)},
                                           Model::kHhd, hemisphere_gram());
                best = std::min(best, sh_hemispherical_error(target, q, Model::kHhd));
            }
        sum_search += e_search;
        sum_newton += e_newton;
        if (e_newton > 1.05 * best + 1e-9) ++worse_newton;
        EXPECT_LE(e_newton, e_old * (1 + 1e-9) + 1e-12);
        sum_grid += best;
        sum_old += e_old;
        if (e_search > 1.05 * best + 1e-9) ++worse;
        EXPECT_LE(e_search, e_old * (1 + 1e-9) + 1e-12);
    }
    std::printf("direction search, SH-space hemispherical error summed over texels: golden %.6g, newton %.6g, 2D grid %.6g, "
                "old %.6g\n",
                sum_search, sum_newton, sum_grid, sum_old);
    EXPECT_LT(sum_newton, 1.05 * sum_grid);
    EXPECT_LE(worse_newton, 2);
    EXPECT_LT(sum_search, 1.05 * sum_grid);
    EXPECT_LT(sum_search, sum_old);
    EXPECT_LE(worse, 2);
}

TEST(IrradzEncode, SearchBeatsTheOldWayOnRealMaps) {
    const auto texels = real_texels();
    double mse_search = 0, mse_old = 0, mse_ahd = 0;
    for (const auto& tx : texels) {
        const Sh3Irradiance target = to_irradiance(tx);
        EncodeOptions o;
        mse_search += hemispherical_mse(target, encode(tx, o), Model::kHhd);
        o.model = Model::kAhd;
        mse_ahd += hemispherical_mse(target, encode(tx, o), Model::kAhd);
        o.model = Model::kHhd;
        o.solve = Solve::kTalkBaseline;
        mse_old += hemispherical_mse(target, encode(tx, o), Model::kHhd);
    }
    const double n = static_cast<double>(texels.size());
    std::printf("real-map texels (%zu): true hemispherical RMSE  HHD search %.5f  HHD old %.5f  AHD search %.5f\n",
                texels.size(), std::sqrt(mse_search / n), std::sqrt(mse_old / n), std::sqrt(mse_ahd / n));
    EXPECT_LT(mse_search, mse_old);
}

TEST(IrradzLinearSh, ProjectionMatchesBruteForce) {
    std::mt19937 rng(6);
    Lighting l;
    l.c_a = Rgb{0.7f, 0.4f, 0.1f};
    l.c_d = Rgb{2.0f, 1.0f, 3.0f};
    l.d = upper_direction(rng, 1.3);
    const Sh2Radiance sh = hhd_to_linear_sh(l);
    // Hemisphere part by dense sampling, delta part exactly (pi C_d Y(d)).
    const Dense& dh = dense_hemisphere();
    const auto yd = sh2_basis(l.d);
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 4; ++i) {
            double h = 0;
            for (const Vec3 w : dh.dirs) h += dh.weight * sh2_basis(w)[static_cast<size_t>(i)];
            const double ref = l.c_a[k] * h + kPi * l.c_d[k] * yd[static_cast<size_t>(i)];
            EXPECT_NEAR(sh[i][k], ref, 2e-3) << i;
        }
}

TEST(IrradzLinearSh, ClosedFormRoundTripsValidHhdExactly) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (int t = 0; t < 2000; ++t) {
        const double ca = t % 7 == 0 ? 0.0 : 3 * u(rng), cd = t % 5 == 0 ? 0.0 : 3 * u(rng);
        const Vec3 d = t % 3 == 0 ? test::uniform_direction(u(rng), u(rng)) : upper_direction(rng, kPi / 2);
        const double k = 2 / std::sqrt(kPi), s = 1 / (kY1 * kPi);
        // b_c = 2 C_a + C_d, b = C_a n_v + C_d d, written as linear SH (double, no float storage).
        const Vec3 b = Vec3{0, 0, ca} + cd * d;
        const ChannelHhd h = linear_sh_to_hhd_channel((2 * ca + cd) / k, -b.y / s, b.z / s, -b.x / s);
        // C_d = 0 makes the quadratic's roots coincide; there the root is only sqrt(eps)-conditioned.
        const double tol = (cd == 0 ? 1e-7 : 1e-9) * (1 + ca + cd);
        EXPECT_NEAR(h.c_a, ca, tol) << t;
        EXPECT_NEAR(h.c_d, cd, tol) << t;
        if (cd > 1e-6) { EXPECT_NEAR(dot(h.d, d), 1.0, 1e-9) << t; }
    }
    // The IrradZ form (float storage of the SH2 in between).
    for (int t = 0; t < 500; ++t) {
        IrradZ p;
        p.i_z = Rgb{static_cast<float>(0.1 + u(rng)), static_cast<float>(0.1 + u(rng)), static_cast<float>(0.1 + u(rng))};
        p.w_a = u(rng);
        p.d = upper_direction(rng, kMaxTheta);
        const IrradZ q = linear_sh_to_irradz(irradz_to_linear_sh(p));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(q.i_z[k], p.i_z[k], 1e-5);
        EXPECT_NEAR(q.w_a, p.w_a, 2e-4) << t;
        if (p.w_a < 0.99) { EXPECT_NEAR(dot(q.d, p.d), 1.0, 1e-5) << t; }
    }
}

TEST(IrradzLinearSh, BlendingInLinearShBeatsBlendingParameters) {
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> u(0, 1);
    double e_lin = 0, e_par = 0;
    int lin_wins = 0;
    const int cases = 300;
    for (int t = 0; t < cases; ++t) {
        std::array<IrradZ, 3> set;
        for (auto& p : set) {
            const float s = static_cast<float>(0.2 + 2 * u(rng));
            p.i_z = Rgb{s, static_cast<float>(s * (0.5 + u(rng))), static_cast<float>(s * (0.5 + u(rng)))};
            p.w_a = u(rng);
            p.d = upper_direction(rng, kMaxTheta);
        }
        std::array<double, 3> w{u(rng), u(rng), u(rng)};
        const double sum = w[0] + w[1] + w[2];
        for (double& x : w) x /= sum;
        const IrradZ lin = blend_linear_sh(set, w), par = blend_parameters(set, w);
        // Reference: the blended lighting itself, sum_i w_i E_i(n), over the hemisphere.
        const Dense& dh = dense_hemisphere();
        double el = 0, ep = 0;
        for (size_t i = 0; i < dh.dirs.size(); i += 10) {
            const Vec3 n = dh.dirs[i];
            Rgb ref{};
            for (int j = 0; j < 3; ++j) {
                const Rgb e = evaluate(set[static_cast<size_t>(j)], Model::kHhd, n);
                for (int k = 0; k < 3; ++k) ref[k] += static_cast<float>(w[static_cast<size_t>(j)] * e[k]);
            }
            const Rgb a = evaluate(lin, Model::kHhd, n), b = evaluate(par, Model::kHhd, n);
            for (int k = 0; k < 3; ++k) {
                el += std::pow(a[k] - ref[k], 2);
                ep += std::pow(b[k] - ref[k], 2);
            }
        }
        e_lin += el;
        e_par += ep;
        if (el < ep) ++lin_wins;
    }
    std::printf("blend of 3 lightmaps, %d cases: RMSE ratio linear-SH / parameter blend = %.3f, linear SH wins %d\n",
                cases, std::sqrt(e_lin / e_par), lin_wins);
    EXPECT_LT(e_lin, 0.7 * e_par);
    EXPECT_GT(lin_wins, cases / 2);
}

// Brute-force twin of cap_multiply + the HLSH least squares.
TEST(IrradzHlsh, CapMultiplyMatchesBruteProjection) {
    std::mt19937 rng(9);
    const Sh3Radiance l = random_radiance(rng);
    for (const double c : {0.0, 0.3, 0.7}) {
        const Sh3Radiance o = cap_multiply(l, c);
        const auto dirs = fibonacci_directions(200000);
        double acc[9] = {};
        for (const Vec3 w : dirs) {
            if (w.z < c) continue;
            const double v = evaluate(l, w).g;
            const auto y = sh3_basis(w);
            for (int i = 0; i < 9; ++i) acc[i] += v * y[i] * 4 * kPi / dirs.size();
        }
        for (int i = 0; i < 9; ++i) EXPECT_NEAR(o[i].g, acc[i], 5e-3) << c << " " << i;
    }
}

TEST(IrradzHlsh, LeastSquaresMatchesBruteForceAndReducesLeaks) {
    const auto paths = test::envmap_paths();
    ASSERT_FALSE(paths.empty());
    double leak_sh = 0, leak_hlsh = 0;
    for (size_t pi = 0; pi < paths.size(); ++pi) {
        const Image img = test::load_envmap(paths[pi]);
        const Sh3Radiance world = project_latlong(img.rgb.data(), img.width, img.height,
                                                  static_cast<size_t>(img.width) * 3, 2);
        for (const Vec3 n : fibonacci_directions(3)) {
            const Mat3 frame = frame_from_z(n);
            for (const double c : {0.0, 0.5}) {
                const Hlsh h = hlsh_multiply(world, frame, c);
                // Brute force: occluded SH3 irradiance target by dense cap projection + band scales,
                // then least squares over the hemisphere with I_z fixed (3x3 normal equations).
                const Sh3Radiance tangent = rotate(world, transpose(frame));
                const auto dirs = fibonacci_directions(60000);
                double o[9] = {};
                for (const Vec3 w : dirs) {
                    if (w.z < c) continue;
                    const double v = evaluate(tangent, w).g;
                    const auto y = sh3_basis(w);
                    for (int i = 0; i < 9; ++i) o[i] += v * y[i] * 4 * kPi / dirs.size();
                }
                auto target = [&](Vec3 m) {
                    const auto y = sh3_basis(m);
                    double t = 0;
                    for (int i = 0; i < 9; ++i) t += o[i] * kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)] * y[i];
                    return t;
                };
                const double iz = target({0, 0, 1});
                double a[3][3] = {}, b[3] = {};
                for (const Vec3 m : dirs) {
                    if (m.z < 0) continue;
                    const double f[3] = {1 - m.z, m.x, m.y};
                    const double r = target(m) - iz * m.z;
                    for (int i = 0; i < 3; ++i) {
                        b[i] += f[i] * r;
                        for (int j = 0; j < 3; ++j) a[i][j] += f[i] * f[j];
                    }
                }
                // a is diagonal up to sampling noise (orthogonality over the hemisphere).
                EXPECT_NEAR(h.i_z.g, iz, 2e-2 * (1 + std::abs(iz)));
                EXPECT_NEAR(h.c_a.g, b[0] / a[0][0], 2e-2 * (1 + std::abs(iz)));
                EXPECT_NEAR(h.c_x.g, b[1] / a[1][1], 2e-2 * (1 + std::abs(iz)));
                EXPECT_NEAR(h.c_y.g, b[2] / a[2][2], 2e-2 * (1 + std::abs(iz)));
                if (c != 0.0) continue;
                // Light leaks: true hemisphere-occluded irradiance (direct integration of the SH3
                // radiance over the visible hemisphere) vs HLSH and vs plain SH3 irradiance.
                for (const Vec3 m : fibonacci_directions(24)) {
                    if (m.z < 0.05) continue;
                    double occ = 0;
                    for (const Vec3 w : dirs)
                        if (w.z >= 0) occ += evaluate(tangent, w).g * std::max(0.0, dot(m, w)) * 4 * kPi / dirs.size();
                    occ /= kPi;
                    leak_sh += std::pow(irradiance(tangent, m).g - occ, 2);
                    leak_hlsh += std::pow(evaluate(h, m).g - occ, 2);
                }
            }
        }
    }
    std::printf("hemisphere occlusion (green, real maps): RMSE vs true occluded irradiance  plain SH3 %.4f  HLSH %.4f\n",
                std::sqrt(leak_sh), std::sqrt(leak_hlsh));
    EXPECT_LT(leak_hlsh, 0.5 * leak_sh);
}

}  // namespace
}  // namespace zhc
