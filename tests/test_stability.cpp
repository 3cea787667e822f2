// Hard cases stay numerically stable: every representation in the codec table, on each named
// case, gives finite, bounded, deterministic output. New table entries are covered automatically.
#include <cfloat>
#include <random>

#include "codec/audit/audit.h"
#include "codec/probe/codec.h"
#include "support.h"

namespace zhc {
namespace {

struct HardCase {
    std::string name;
    Sh3Radiance hub;
};

Sh3Radiance uniform_rgb(double dc, double rest) {
    Sh3Radiance s;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) s[i][k] = static_cast<float>(i == 0 ? dc : rest * (1 + 0.1 * i - 0.2 * k));
    return s;
}

std::vector<HardCase> hard_cases() {
    std::vector<HardCase> c;
    c.push_back({"black", Sh3Radiance{}});
    {
        Sh3Radiance s = uniform_rgb(0.0, 0.3);  // DC = 0 with non-zero higher bands
        c.push_back({"dc_zero_higher_bands_nonzero", s});
    }
    {
        Sh3Radiance s = project_constant({1, 1, 1});  // zero L1: undefined axis
        s[6] = {0.4f, 0.2f, 0.1f};
        s[8] = {-0.3f, 0.1f, 0.2f};
        c.push_back({"zero_l1_with_l2", s});
    }
    {
        const Vec3 a = normalize_or({0.3, 0.5, -0.8}, {0, 0, 1});
        c.push_back({"antipodal_equal_deltas", project_directional(a, {1, 1, 1}) + project_directional(-1.0 * a, {1, 1, 1})});
    }
    c.push_back({"single_delta", project_directional(normalize_or({1, -2, 0.5}, {0, 0, 1}), {3, 2, 1})});
    c.push_back({"single_delta_on_axis", project_directional({0, 0, 1}, {1, 1, 1})});
    {
        // A sun of 1e5 over a sky of 1e-3.
        const double s = 0.5 * 0.53 * kPi / 180.0;
        c.push_back({"sun_1e5_over_sky_1e-3",
                     project_cone(normalize_or({0.2, 0.3, 0.9}, {0, 0, 1}), s, {float(1e5 / (s * s)), float(0.9e5 / (s * s)), float(0.8e5 / (s * s))}) +
                         project_constant({1e-3f, 1e-3f, 2e-3f})});
    }
    c.push_back({"tiny_values_near_float_min", scale(project_cone({0, 1, 0}, 0.5, {1, 1, 1}), 1e4 * FLT_MIN)});
    c.push_back({"denormals", scale(project_cone({1, 0, 0}, 0.5, {1, 1, 1}), 1e-40)});
    c.push_back({"huge_values", scale(project_cone({0, 0, -1}, 0.5, {1, 1, 1}), 1e36)});
    {
        std::mt19937 rng(5);
        std::normal_distribution<double> g(0, 1);
        for (int t = 0; t < 20; ++t) {
            Sh3Radiance s;
            for (int i = 0; i < 9; ++i) s[i] = {float(g(rng)), float(g(rng)), float(g(rng))};
            c.push_back({"random_not_nonnegative_" + std::to_string(t), s});
        }
        // Negative DC: not the projection of any non-negative function.
        Sh3Radiance n = uniform_rgb(-1.0, 0.2);
        c.push_back({"negative_dc", n});
    }
    {
        // Real maps, including their slightly negative DWAB pixels.
        for (const std::string& p : test::envmap_paths()) {
            const Image img = test::load_envmap(p);
            c.push_back({"map_" + test::envmap_name(p), project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u)});
        }
    }
    return c;
}

TEST(Stability, EveryCodecGivesFiniteBoundedDeterministicOutputOnHardCases) {
    const CodecOptions o;
    const auto dirs = fibonacci_sphere(64);
    for (const HardCase& hc : hard_cases()) {
        const double in_max = test::max_abs(hc.hub);
        for (const Codec& c : codecs()) {
            SCOPED_TRACE(hc.name + " / " + std::string(c.name));
            std::vector<std::uint8_t> a(c.size_bytes), b(c.size_bytes);
            EncodeStats stats;
            c.encode(hc.hub, o, a.data(), &stats);
            c.encode(hc.hub, o, b.data(), nullptr);
            EXPECT_EQ(a, b) << "deterministic";
            const Sh3Radiance d = c.decode(a.data(), o);
            // Bounded: no representation may amplify its input by more than a small factor (the
            // largest legitimate growth is a hallucinated or ratio-bounded term, a few times DC).
            const double bound = 8.0 * in_max + 1e-30;
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(d[i][k])) << "coefficient " << i;
                    EXPECT_LE(std::fabs(double(d[i][k])), bound) << "coefficient " << i;
                }
            for (const Vec3& n : dirs) {
                const Rgb e = c.irradiance(a.data(), o, n);
                for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(e[k]));
            }
        }
    }
}

TEST(Stability, NonFinitePixelsAreRejectedByDefaultAndReplacedOnRequest) {
    Image img = test::render_latlong(32, 16, [](Vec3) { return Rgb{1, 1, 1}; });
    img.row(4)[7] = std::numeric_limits<float>::infinity();
    img.row(5)[8] = std::nanf("");
    const std::string path = test::temp_dir("stability") + "/nonfinite.exr";
    ASSERT_TRUE(write_exr(path, img));
    auto rejected = read_envmap(path);
    ASSERT_FALSE(rejected);
    EXPECT_EQ(rejected.error().code, ErrorCode::kInvalidValue);
    EnvmapReadOptions o;
    o.non_finite = NonFinitePolicy::kReplaceZero;
    auto replaced = read_envmap(path, o);
    ASSERT_TRUE(replaced);
    const Sh3Radiance sh = project_latlong(replaced->rgb.data(), 32, 16, 32 * 3);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(sh[i][k]));
}

TEST(Stability, ProjectionOfExtremeMapsIsFinite) {
    for (float v : {0.0f, FLT_MIN, 1e-40f, 1e30f, -1e-3f}) {
        const Image img = test::render_latlong(64, 32, [&](Vec3 d) { return d.z > 0.99 ? Rgb{v, v, v} : Rgb{}; });
        const Sh3Radiance sh = project_latlong(img.rgb.data(), 64, 32, 64 * 3);
        for (int i = 0; i < 9; ++i) EXPECT_TRUE(std::isfinite(sh[i].r)) << v;
    }
}

}  // namespace
}  // namespace zhc
