// IrradZ Newton solve (codec/lightmap/irradz.h, Solve::kNewton, the default) against the reference
// search (Solve::kSearch): derivatives by finite differences, texel by texel on real maps, hard
// analytic cases, scale invariance, non-finite input (helpers: irradz_helpers.h).
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>

#include "codec/lightmap/irradz.h"
#include "codec/lightmap/irradz_internal.h"
#include "irradz_helpers.h"
#include "support.h"

namespace zhc {
namespace {

using namespace irradz_test;

// ---- Newton solve (Solve::kNewton, the default) against the reference search (Solve::kSearch) ----

namespace newton {

EncodeOptions with(Solve s, Model m) {
    EncodeOptions o;
    o.solve = s;
    o.model = m;
    return o;
}

// Sphere lightmaps synthesised from every sample map (as `zhc lightmap synth` makes them).
std::vector<std::vector<Sh3Radiance>> sample_lightmaps(int size) {
    std::vector<std::vector<Sh3Radiance>> out;
    for (const auto& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        const Sh3Radiance world = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
        // synthesize_sphere (codec/lightmap/lightmap.h) without the dependency: octahedral normals, windowed.
        std::vector<Sh3Radiance> texels;
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const double u = 2.0 * (x + 0.5) / size - 1, v = 2.0 * (y + 0.5) / size - 1;
                Vec3 n{u, v, 1 - std::abs(u) - std::abs(v)};
                if (n.z < 0) n = Vec3{(1 - std::abs(v)) * (u >= 0 ? 1 : -1), (1 - std::abs(u)) * (v >= 0 ? 1 : -1), n.z};
                n = normalize_or(n, {0, 0, 1});
                texels.push_back(cap_multiply(rotate(world, transpose(frame_from_z(n))), 0.0));
            }
        out.push_back(std::move(texels));
    }
    return out;
}

double dc_scale(const Sh3Irradiance& irr) {
    double s = 0;
    for (int k = 0; k < 3; ++k) s += double(irr[0][k]) * double(irr[0][k]);
    return s;
}

}  // namespace newton

TEST(IrradzNewton, GradientAndHessianMatchFiniteDifferences) {
    // The analytic derivatives of the reduced error psi(q) (q = (d_x, d_y) / d_z) against central
    // differences, on random and real targets, for both models; and psi itself against the general
    // error: sh_hemispherical_error(w_a = 1 - s, d(q)) - S psi(q) is the same constant for every q.
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-1, 1);
    auto texels = real_texels();
    for (int t = 0; t < 8; ++t) texels.push_back(random_radiance(rng));
    int checked_h = 0, checked_g = 0;
    for (const Model model : {Model::kHhd, Model::kAhd})
        for (size_t t = 0; t < texels.size(); ++t) {
            const Sh3Irradiance irr = to_irradiance(texels[t]);
            double iz2 = 0;
            for (int k = 0; k < 3; ++k) iz2 += std::pow(std::max(0.0, double(evaluate(irr, Vec3{0, 0, 1})[k])), 2);
            double constant = 0;
            for (int j = 0; j < 6; ++j) {
                const double qx = 4 * u(rng), qy = 4 * u(rng);
                const ReducedError r = reduced_error(irr, model, qx, qy);
                IrradZ p = encode(texels[t], newton::with(Solve::kTalkBaseline, model));  // I_z
                p.w_a = 1 - r.s;
                p.d = normalize_or(Vec3{qx, qy, 1}, {0, 0, 1});
                const double c = sh_hemispherical_error(irr, p, model) - iz2 * r.psi;
                const double scale = newton::dc_scale(irr) + std::abs(constant) + 1e-12;
                if (j == 0) constant = c;
                else EXPECT_NEAR(c, constant, 1e-5 * scale) << t << " " << j;
                if (r.s <= 0) continue;  // flat (w_a = 1)
                const double h = 1e-5;
                ReducedError e[4];
                const double dq[4][2] = {{h, 0}, {-h, 0}, {0, h}, {0, -h}};
                bool same_side = true;  // s clamped at 1 on all or none of the points (psi has a kink)
                for (int k = 0; k < 4; ++k) {
                    e[k] = reduced_error(irr, model, qx + dq[k][0], qy + dq[k][1]);
                    same_side = same_side && ((e[k].s >= 1) == (r.s >= 1)) && e[k].s > 0;
                }
                if (!same_side) continue;
                const double gs = 1e-7 * (std::abs(r.grad[0]) + std::abs(r.grad[1]) + r.psi + 1e-3);
                EXPECT_NEAR(r.grad[0], (e[0].psi - e[1].psi) / (2 * h), gs) << t;
                EXPECT_NEAR(r.grad[1], (e[2].psi - e[3].psi) / (2 * h), gs) << t;
                const double hs = 1e-5 * (std::abs(r.hess[0]) + std::abs(r.hess[1]) + std::abs(r.hess[2]) + 1e-3);
                EXPECT_NEAR(r.hess[0], (e[0].grad[0] - e[1].grad[0]) / (2 * h), hs) << t;
                EXPECT_NEAR(r.hess[1], (e[0].grad[1] - e[1].grad[1]) / (2 * h), hs) << t;
                EXPECT_NEAR(r.hess[1], (e[2].grad[0] - e[3].grad[0]) / (2 * h), hs) << t;
                EXPECT_NEAR(r.hess[2], (e[2].grad[1] - e[3].grad[1]) / (2 * h), hs) << t;
                ++checked_g;
                checked_h += r.s < 1;
            }
        }
    std::printf("reduced error derivatives checked at %d points (%d with s interior)\n", checked_g, checked_h);
    EXPECT_GT(checked_g, 200);
    EXPECT_GT(checked_h, 50);
}

TEST(IrradzNewton, MatchesTheReferenceSearchTexelByTexel) {
    // Real texels and 48 x 48 sphere lightmaps of every sample map, both models: the Newton solve's
    // SH-space error against the golden-section reference texel by texel, and the audited (true)
    // hemispherical error per map (the acceptance: at most 0.5 % above the reference).
    auto maps = newton::sample_lightmaps(48);
    maps.push_back(real_texels());
    ASSERT_EQ(maps.size(), test::envmap_paths().size() + 1);
    for (const Model model : {Model::kHhd, Model::kAhd}) {
        double total_n = 0, total_s = 0;
        size_t texels = 0, worse = 0, better = 0;
        double worst = 0;
        for (size_t m = 0; m < maps.size(); ++m) {
            double mse_n = 0, mse_s = 0;
            for (const Sh3Radiance& tx : maps[m]) {
                const Sh3Irradiance irr = to_irradiance(tx);
                double e_n = 0, e_s = 0;
                const IrradZ pn = encode(tx, newton::with(Solve::kNewton, model), &e_n);
                const IrradZ ps = encode(tx, newton::with(Solve::kSearch, model), &e_s);
                // Same I_z, w_a in range, d in the stored range.
                for (int k = 0; k < 3; ++k) EXPECT_EQ(pn.i_z[k], ps.i_z[k]);
                EXPECT_GE(pn.w_a, 0.0);
                EXPECT_LE(pn.w_a, 1.0);
                EXPECT_NEAR(length(pn.d), 1.0, 1e-12);
                EXPECT_GE(pn.d.z, kMinDz - 1e-12);
                const double tol = 1e-6 * e_s + 1e-12 * newton::dc_scale(irr);
                if (e_n > e_s + tol) ++worse, worst = std::max(worst, (e_n - e_s) / (e_s + 1e-300));
                if (e_n < e_s - tol) ++better;
                mse_n += hemispherical_mse(irr, pn, model);
                mse_s += hemispherical_mse(irr, ps, model);
                ++texels;
            }
            const std::string name = m < test::envmap_paths().size() ? test::envmap_name(test::envmap_paths()[m]) : "real texels";
            std::printf("%s %-12s audited hemispherical MSE: search %.6e  newton %.6e  (%+.3f %%)\n",
                        model == Model::kHhd ? "HHD" : "AHD", name.c_str(), mse_s, mse_n, 100 * (mse_n / mse_s - 1));
            EXPECT_LE(mse_n, 1.005 * mse_s) << name;
            total_n += mse_n;
            total_s += mse_s;
        }
        std::printf("%s: %zu texels, newton better on %zu, worse on %zu (worst +%.1f %%); audited MSE %+.3f %%\n",
                    model == Model::kHhd ? "HHD" : "AHD", texels, better, worse, 100 * worst, 100 * (total_n / total_s - 1));
        // Newton lands in another local minimum on a few texels (both solves are local); rarely.
        EXPECT_LT(worse, texels / 200);
        EXPECT_GT(better, worse);
        EXPECT_LE(total_n, total_s);
    }
}

TEST(IrradzNewton, HardAnalyticCases) {
    // Zero L1, pure L2, negative lobes, near-grazing and below-horizon lights, zero and tiny I_z:
    // never worse than the reference by more than 1e-3 relative (plus rounding), results in range.
    std::vector<Sh3Radiance> cases;
    const Rgb grey{1, 1, 1}, warm{1.0f, 0.6f, 0.3f};
    cases.push_back(project_hemisphere({0, 0, 1}, grey));             // hemisphere only: w_a = 1
    Sh3Radiance l0;  // constant radiance (zero L1 and L2)
    for (int k = 0; k < 3; ++k) l0[0][k] = 2.0f;
    cases.push_back(l0);
    for (int i = 4; i < 9; ++i) {  // pure L2 (each basis function, both signs), plus L0
        Sh3Radiance s = l0;
        s[i] = Rgb{1.5f, 1.5f, 1.5f};
        cases.push_back(s);
        s[i] = Rgb{-1.5f, -1.0f, -0.5f};
        cases.push_back(s);
        Sh3Radiance pure;
        pure[i] = Rgb{1, 1, 1};
        cases.push_back(pure);
    }
    Sh3Radiance neg = l0;  // negative lobe along +x
    neg[3] = Rgb{1.5f, 1.5f, 1.5f};
    cases.push_back(neg);
    for (const double deg : {0.0, 30.0, 60.0, 80.0, 84.0, 85.0, 86.0, 89.0, 90.0, 95.0, 120.0, 180.0}) {
        const double th = deg * kPi / 180;
        const Vec3 d{std::sin(th) * std::cos(0.7), std::sin(th) * std::sin(0.7), std::cos(th)};
        cases.push_back(project_directional(d, warm));
        cases.push_back(project_hemisphere({0, 0, 1}, Rgb{0.2f, 0.2f, 0.2f}) + project_directional(d, warm));
        cases.push_back(cap_multiply(project_directional(d, warm), 0.0));  // windowed, as a baker sees it
    }
    cases.push_back(Sh3Radiance{});  // black
    int n = 0;
    for (const Model model : {Model::kHhd, Model::kAhd})
        for (const Sh3Radiance& c : cases) {
            double e_n = 0, e_s = 0;
            const IrradZ pn = encode(c, newton::with(Solve::kNewton, model), &e_n);
            encode(c, newton::with(Solve::kSearch, model), &e_s);
            const Sh3Irradiance irr = to_irradiance(c);
            EXPECT_LE(e_n, e_s * (1 + 1e-3) + 1e-9 * (newton::dc_scale(irr) + 1e-30)) << n;
            EXPECT_NEAR(e_n, sh_hemispherical_error(irr, pn, model), 1e-5 * e_n + 1e-9 * newton::dc_scale(irr) + 1e-20) << n;
            EXPECT_GE(pn.w_a, 0.0);
            EXPECT_LE(pn.w_a, 1.0);
            EXPECT_NEAR(length(pn.d), 1.0, 1e-12);
            EXPECT_GE(pn.d.z, kMinDz - 1e-12);
            ++n;
        }
    // Black: w_a = 1, d = +Z, error 0 (as the reference).
    const IrradZ black = encode(Sh3Radiance{});
    EXPECT_EQ(black.w_a, 1.0);
    EXPECT_EQ(black.d.z, 1.0);
}

TEST(IrradzNewton, ScaleInvariant) {
    // Scaling the radiance by a power of two scales every float and double exactly, so w_a and d
    // are bit-identical; other scales (very bright, very dim) agree to rounding.
    auto texels = real_texels();
    std::mt19937 rng(22);
    for (int t = 0; t < 8; ++t) texels.push_back(random_radiance(rng));
    for (const Model model : {Model::kHhd, Model::kAhd})
        for (const Sh3Radiance& tx : texels) {
            const IrradZ p = encode(tx, newton::with(Solve::kNewton, model));
            for (const double s : {0x1p-100, 0x1p-40, 0x1p40, 0x1p100}) {
                const IrradZ q = encode(scale(tx, s), newton::with(Solve::kNewton, model));
                EXPECT_EQ(q.w_a, p.w_a);
                EXPECT_EQ(q.d.x, p.d.x);
                EXPECT_EQ(q.d.y, p.d.y);
                EXPECT_EQ(q.d.z, p.d.z);
            }
            for (const double s : {1e-30, 3e-7, 7e5, 1e30}) {
                const IrradZ q = encode(scale(tx, s), newton::with(Solve::kNewton, model));
                EXPECT_NEAR(q.w_a, p.w_a, 1e-4);
                EXPECT_GT(dot(q.d, p.d), std::cos(1e-3));
            }
        }
}

TEST(IrradzNewton, NonFiniteInputIsHandled) {
    // Total on any float input (the EXR reader rejects non-finite values; the fit must not hang or
    // crash on them anyway): it returns, with w_a in [0, 1] or NaN-free d where defined.
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                         -std::numeric_limits<float>::infinity(), 3e38f, -3e38f};
    for (const float b : bad)
        for (int i = 0; i < 9; ++i)
            for (const Model model : {Model::kHhd, Model::kAhd}) {
                Sh3Radiance s;
                for (int k = 0; k < 3; ++k) s[0][k] = 1.0f;
                s[i] = Rgb{b, b, b};
                double e = 0;
                const IrradZ p = encode(s, newton::with(Solve::kNewton, model), &e);
                EXPECT_FALSE(p.w_a < 0.0 || p.w_a > 1.0);
                EXPECT_FALSE(std::isnan(p.d.z) ? false : p.d.z < kMinDz - 1e-12);
            }
}

TEST(IrradzNewton, RandomTargetsAgainstTheReference) {
    // Rough random SH3 targets (coefficients down to -2, far from a physical lightmap): the total error
    // and the share of texels where Newton ends in a worse local minimum than the search.
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-2.0, 1.0);
    for (const Model model : {Model::kHhd, Model::kAhd}) {
        double sum_n = 0, sum_s = 0;
        int worse = 0, better = 0;
        const int n = 4000;
        for (int t = 0; t < n; ++t) {
            Sh3Radiance s;
            for (int k = 0; k < 3; ++k) {
                s[0][k] = static_cast<float>(3.0 + u(rng));
                for (int i = 1; i < 9; ++i) s[i][k] = static_cast<float>(u(rng));
            }
            double e_n = 0, e_s = 0;
            encode(s, newton::with(Solve::kNewton, model), &e_n);
            encode(s, newton::with(Solve::kSearch, model), &e_s);
            sum_n += e_n;
            sum_s += e_s;
            worse += e_n > e_s * (1 + 1e-3);
            better += e_n < e_s * (1 - 1e-3);
        }
        std::printf("%s, %d random targets: error newton / search %.4f, newton better on %d, worse on %d\n",
                    model == Model::kHhd ? "HHD" : "AHD", n, sum_n / sum_s, better, worse);
        EXPECT_LT(sum_n, sum_s);
        EXPECT_LT(worse, n / 100);
        EXPECT_GT(better, 10 * worse);
    }
}

}  // namespace
}  // namespace zhc

namespace zhc {
namespace {

// encode_many (the texels' evaluations four at a time in vector lanes, the lightmap path) against
// encode (one texel, scalar), bit for bit: real lightmap texels of every sample map, the hard
// analytic cases (flat starts that take the ring, grazing lights on the rim, black), rough random
// targets and non-finite input, in both models, with counts that leave partial vectors.
TEST(IrradzNewton, EncodeManyMatchesEncodeBitForBit) {
    std::vector<Sh3Radiance> texels;
    for (const auto& lm : newton::sample_lightmaps(24)) texels.insert(texels.end(), lm.begin(), lm.end());
    const Rgb warm{1.0f, 0.6f, 0.3f};
    Sh3Radiance l0;
    for (int k = 0; k < 3; ++k) l0[0][k] = 2.0f;
    texels.push_back(l0);
    texels.push_back(Sh3Radiance{});
    for (int i = 4; i < 9; ++i) {
        Sh3Radiance pure;
        pure[i] = Rgb{1, 1, 1};
        texels.push_back(pure);
        Sh3Radiance s = l0;
        s[i] = Rgb{-1.5f, -1.0f, -0.5f};
        texels.push_back(s);
    }
    for (const double deg : {0.0, 60.0, 84.0, 85.0, 86.0, 89.0, 95.0, 180.0}) {
        const double th = deg * kPi / 180;
        const Vec3 d{std::sin(th) * std::cos(0.7), std::sin(th) * std::sin(0.7), std::cos(th)};
        texels.push_back(project_directional(d, warm));
        texels.push_back(cap_multiply(project_directional(d, warm), 0.0));
    }
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> u(-2.0, 1.0);
    for (int t = 0; t < 600; ++t) {
        Sh3Radiance s;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) s[i][k] = static_cast<float>(u(rng));
        texels.push_back(s);
    }
    Sh3Radiance nan = l0;
    nan[5] = Rgb{std::numeric_limits<float>::quiet_NaN(), 1, 1};
    texels.push_back(nan);
    texels.push_back(l0);  // an odd count: the last vector is partial
    ASSERT_NE(texels.size() % 4, 0u);
    int rim = 0;
    for (const Model model : {Model::kHhd, Model::kAhd}) {
        const EncodeOptions o = newton::with(Solve::kNewton, model);
        std::vector<IrradZ> many(texels.size()), base(texels.size());
        encode_many(texels.data(), texels.size(), o, many.data());
        // The baseline (SSE2) build of the lanes too, where encode_many took the AVX2 one.
        std::vector<Sh3Irradiance> irr;
        for (const Sh3Radiance& t : texels) irr.push_back(to_irradiance(t));
        detail::fit_newton_many(irr.data(), irr.size(), model, o, base.data(), false);
        for (size_t i = 0; i < texels.size(); ++i) {
            const IrradZ one = encode(texels[i], o);
            const double a[5] = {one.w_a, one.d.x, one.d.y, one.d.z, double(one.i_z[0])};
            for (const IrradZ* m : {&many[i], &base[i]}) {
                const double b[5] = {m->w_a, m->d.x, m->d.y, m->d.z, double(m->i_z[0])};
                EXPECT_EQ(std::memcmp(a, b, sizeof a), 0) << "texel " << i << " model " << int(model) << (m == &base[i] ? " baseline" : "");
            }
            rim += one.d.z < kMinDz + 1e-9;
        }
    }
    EXPECT_GT(rim, 0);  // some solves end on the rim (the rim steps ran)
}

}  // namespace
}  // namespace zhc
