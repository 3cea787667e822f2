// Properties of the SH core (codec/sh/sh.h): basis, projection, evaluation, rotation, closed forms.
#include <random>

#include "codec/bake/sky.h"
#include "support.h"

namespace zhc {
namespace {

using test::fibonacci_directions;

// Associated Legendre polynomials without the Condon-Shortley phase, for Eq. 1 of the ZH3 paper
// (with its extraction damage fixed: sqrt(2) K cos(m phi) P).
double legendre(int l, int m, double x) {
    const double s = std::sqrt(std::max(0.0, 1 - x * x));
    if (l == 0) return 1;
    if (l == 1) return m == 0 ? x : s;
    if (m == 0) return 0.5 * (3 * x * x - 1);
    if (m == 1) return 3 * x * s;
    return 3 * s * s;
}
double factorial(int n) { return n <= 1 ? 1 : n * factorial(n - 1); }

TEST(ShBasis, MatchesSphericalFormUpToTheDocumentedSigns) {
    // Eq. 1 has no Condon-Shortley phase; Eq. 4/5 (our convention) is Eq. 1 times (-1)^m.
    for (const Vec3 d : fibonacci_directions(200)) {
        const double theta = std::acos(d.z), phi = std::atan2(d.y, d.x);
        const auto cart = sh3_basis(d);
        for (int l = 0; l <= 2; ++l)
            for (int m = -l; m <= l; ++m) {
                const int am = std::abs(m);
                const double k = std::sqrt((2 * l + 1) * factorial(l - am) / (4 * kPi * factorial(l + am)));
                double y = k * legendre(l, am, std::cos(theta));
                if (m > 0) y *= std::sqrt(2.0) * std::cos(m * phi);
                if (m < 0) y *= std::sqrt(2.0) * std::sin(am * phi);
                const double sign = (am % 2) ? -1.0 : 1.0;
                EXPECT_NEAR(cart[static_cast<size_t>(sh_index(l, m))], sign * y, 1e-12) << l << " " << m;
            }
    }
}

TEST(ShBasis, IsOrthonormalUnderDenseQuadrature) {
    const auto dirs = fibonacci_directions(200000);
    double gram[9][9] = {};
    for (const Vec3 d : dirs) {
        const auto y = sh3_basis(d);
        for (int i = 0; i < 9; ++i)
            for (int j = 0; j < 9; ++j) gram[i][j] += y[i] * y[j] * 4 * kPi / dirs.size();
    }
    for (int i = 0; i < 9; ++i)
        for (int j = 0; j < 9; ++j) EXPECT_NEAR(gram[i][j], i == j ? 1.0 : 0.0, 1e-4) << i << "," << j;
}

TEST(Projection, WhiteFurnaceLeavesOnlyL00) {
    const float value = 1.7f;
    for (auto [w, h] : {std::pair{64, 32}, std::pair{100, 37}, std::pair{1024, 512}}) {
        const Image img = test::render_latlong(w, h, [&](Vec3) { return Rgb{value, value, value}; });
        const Sh3Radiance sh = project_latlong(img.rgb.data(), w, h, static_cast<size_t>(w) * 3);
        EXPECT_NEAR(sh[0].r, 2 * std::sqrt(kPi) * value, 1e-5);
        for (int i = 1; i < 9; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(sh[i][k], 0.0, 1e-5) << "coefficient " << i;
        // and its irradiance is the radiance value everywhere (normalised kernel)
        for (const Vec3 n : fibonacci_directions(50)) EXPECT_NEAR(irradiance(sh, n).g, value, 1e-5);
    }
}

TEST(Projection, RenderedSphereLightProjectsToClosedForm) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (int trial = 0; trial < 4; ++trial) {
        const Vec3 axis = test::uniform_direction(u(rng), u(rng));
        const double sigma = 0.3 + 0.8 * u(rng);
        const Rgb radiance{2.0f, 1.0f, 0.5f};
        // Supersample each pixel so the disc edge is resolved: the reference is the exact
        // piecewise-constant integral, approximated by 8x8 sub-samples.
        const int w = 512, h = 256, ss = 8;
        Image img = test::render_latlong(w, h, [](Vec3) { return Rgb{}; });
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double inside = 0;
                for (int sy = 0; sy < ss; ++sy)
                    for (int sx = 0; sx < ss; ++sx) {
                        const Vec3 d = latlong_direction(x - 0.5 + (sx + 0.5) / ss, y - 0.5 + (sy + 0.5) / ss, w, h);
                        inside += dot(d, axis) >= std::cos(sigma) ? 1.0 : 0.0;
                    }
                inside /= ss * ss;
                for (int k = 0; k < 3; ++k) img.row(y)[x * 3 + k] = static_cast<float>(inside * radiance[k]);
            }
        const Sh3Radiance got = project_latlong(img.rgb.data(), w, h, static_cast<size_t>(w) * 3);
        const Sh3Radiance want = project_cone(axis, sigma, radiance);
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[i][k], want[i][k], 2e-3 * radiance[k]) << i;
    }
}

TEST(Projection, ClosedFormsMatchDenseSampling) {
    // Slow twin: project analytic radiance functions by dense Fibonacci sampling.
    const auto dirs = fibonacci_directions(400000);
    const Vec3 axis = normalize_or({0.3, -0.5, 0.8}, {0, 0, 1});
    auto sampled = [&](auto radiance) {
        std::vector<WeightedSample> s;
        s.reserve(dirs.size());
        for (const Vec3 d : dirs) s.push_back({d, 4 * kPi / dirs.size(), radiance(d)});
        return project_samples(s);
    };
    auto expect_close = [](const Sh3Radiance& a, const Sh3Radiance& b, double tol) {
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[i][k], b[i][k], tol) << "coefficient " << i;
    };
    expect_close(project_hemisphere(axis, {1, 2, 3}),
                 sampled([&](Vec3 d) { return dot(d, axis) > 0 ? Rgb{1, 2, 3} : Rgb{}; }), 2e-3);
    expect_close(project_cone(axis, 0.7, {1, 1, 1}),
                 sampled([&](Vec3 d) { return dot(d, axis) > std::cos(0.7) ? Rgb{1, 1, 1} : Rgb{}; }), 2e-3);
    expect_close(project_constant({0.5f, 1, 2}), sampled([](Vec3) { return Rgb{0.5f, 1, 2}; }), 1e-4);
    GradientSky sky;
    sky.up = axis;
    expect_close(project_gradient_sky(sky), sampled([&](Vec3 d) {
                     const double z = dot(d, axis);
                     if (z < 0) return sky.ground;
                     Rgb c;
                     for (int k = 0; k < 3; ++k) c[k] = static_cast<float>(sky.horizon[k] + (sky.zenith[k] - sky.horizon[k]) * z);
                     return c;
                 }),
                 2e-3);
}

TEST(Projection, DirectionalLightIrradianceIsClampedCosineOverPiInTheLimit) {
    // A narrow cone of fixed flux tends to the directional light's projection.
    const Vec3 axis{0, 0, 1};
    const double sigma = 1e-3, flux_to_radiance = 1.0 / (kPi * sigma * sigma);
    const Sh3Radiance cone = project_cone(axis, sigma, {float(flux_to_radiance), 0, 0});
    const Sh3Radiance delta = project_directional(axis, {1, 0, 0});
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(cone[i].r, delta[i].r, 1e-5);
}

TEST(Rotation, BandNormsAreInvariantAndRotationMatchesResampling) {
    std::mt19937 rng(3);
    std::normal_distribution<double> g(0, 1);
    for (int trial = 0; trial < 50; ++trial) {
        Sh3Radiance sh;
        for (int i = 0; i < 9; ++i) sh[i] = {float(g(rng)), float(g(rng)), float(g(rng))};
        const Mat3 r = rotation_axis_angle({g(rng), g(rng), g(rng)}, 3 * g(rng));
        const Sh3Radiance rot = rotate(sh, r);
        for (int l = 0; l < 3; ++l)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(band_norm(rot, l)[k], band_norm(sh, l)[k], 1e-5);
        for (const Vec3 d : fibonacci_directions(20)) {
            const Rgb a = evaluate(rot, d), b = evaluate(sh, transpose(r) * d);
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-5);
        }
        // A zonal function's rotation is the zonal function about the rotated axis.
        const Vec3 axis = normalize_or({g(rng), g(rng), g(rng)}, {0, 0, 1});
        const Sh3Radiance moved = rotate(project_cone(axis, 0.4, {1, 1, 1}), r);
        const Sh3Radiance direct = project_cone(r * axis, 0.4, {1, 1, 1});
        for (int i = 0; i < 9; ++i) EXPECT_NEAR(moved[i].r, direct[i].r, 1e-5);
    }
}

TEST(Irradiance, BandScalesGiveClampedCosineConvolution) {
    // SH3 irradiance of a hemisphere light vs. the exact irradiance. For a hemisphere about +Z
    // E(n) = (1 + n_z) / 2 exactly, and its SH3 projection represents it exactly (bands >= 3 of
    // (1 + z)/2 vanish).
    const Sh3Radiance sh = project_hemisphere({0, 0, 1}, {1, 1, 1});
    for (const Vec3 n : fibonacci_directions(100)) EXPECT_NEAR(irradiance(sh, n).r, (1 + n.z) / 2, 1e-6);
}

TEST(Projection, ResultDoesNotDependOnThreadCount) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0, 10);
    Image img = test::render_latlong(333, 171, [&](Vec3) { return Rgb{u(rng), u(rng), u(rng)}; });
    const Sh3Radiance one = project_latlong(img.rgb.data(), 333, 171, 333 * 3, 1);
    for (int t : {2, 3, 7, 64}) EXPECT_TRUE(one == project_latlong(img.rgb.data(), 333, 171, 333 * 3, t)) << t;
}

}  // namespace
}  // namespace zhc
