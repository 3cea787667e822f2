// Shadow planes (codec/bake/leak_planes.h "Shadow planes", docs/scene.md "Probes near geometry"):
// a hard shadow edge in open air gets the plane of the cell it crosses, so that the points in the
// shadow blend the probes in the shadow.
//
// The scene: a tall pillar (x 1..1.4, z -0.2..0.2) between a point light at (0, 1.5, 0) and a probe
// grid entirely beyond it (x 2.5..8.5): no geometry lies in any cell, and the shadow is the wedge
// |z| <= 0.2 x (the pillar's near face at x = 1 bounds it), written here in closed form as the
// analytic twin of the bake's shadow rays. Asserted:
//  * every plane is a shadow plane, only cells whose corners the wedge splits get one, and every
//    such cell does;
//  * per cell, the corners a point keeps agree with the point on being in the wedge for at least
//    97 % of 512 points (the wedge's two edges are planes; a cell holding both edges near the
//    pillar loses the rest);
//  * sampled through the C runtime at points in and out of the wedge: the shadow's mean / the lit
//    mean is below 1 % (without shadow planes: over 10 %), and the lit mean moves closer to the
//    truth than without;
//  * a directional light (zero radius) makes planes too; a sky alone, a sun disc and
//    `occlusion.shadow_planes` false make none; the bake is the same with 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "leak_scenes.h"

namespace zhc {
namespace {

using namespace leak;

constexpr double kPillarLo = 1.0, kPillarHi = 1.4, kPillarHalf = 0.2;
const Vec3 kLight{0, 1.5, 0};

bool in_wedge(Vec3 p) { return std::fabs(p.z) <= kPillarHalf * p.x / kPillarLo; }

LeakScene pillar_scene(bool point_light_kind = true) {
    LeakScene ls;
    ls.name = "pillar";
    ls.cell = 1.5;
    Scene s = empty_scene();
    s.occluders.push_back(box_occluder({kPillarLo, -10, -kPillarHalf}, {kPillarHi, 10, kPillarHalf}));
    if (point_light_kind) {
        s.lights.push_back(point_light(kLight, 8));
    } else {
        SceneLight sun;
        sun.kind = LightKind::kDirectional;
        sun.name = "sun";
        sun.direction = {-1, 0, 0};  // towards the light: it shines along +x, the shadow a slab |z| <= 0.2
        sun.color = {1, 1, 1};
        sun.shadows = true;
        s.lights.push_back(sun);
    }
    set_grid(s, {2.5, 0, -3}, {8.5, 3, 3}, {5, 3, 7});
    ls.scene = std::move(s);
    // Points in the grid's box with random normals, the truth's own shadow rays decide the side.
    std::mt19937_64 rng(11);
    for (int i = 0; i < 4000; ++i) {
        ShadingPoint sp;
        sp.p = {2.5 + 6 * u01(rng), 3 * u01(rng), -3 + 6 * u01(rng)};
        const double z = 2 * u01(rng) - 1, phi = 2 * kPi * u01(rng), r = std::sqrt(1 - z * z);
        sp.n = {r * std::cos(phi), r * std::sin(phi), z};
        sp.kind = "free";
        if (std::fabs(std::fabs(sp.p.z) - kPillarHalf * sp.p.x) < 0.05) continue;  // off the edge itself
        sp.side = (point_light_kind ? in_wedge(sp.p) : std::fabs(sp.p.z) <= kPillarHalf) ? Side::kDark : Side::kLit;
        ls.points.push_back(sp);
    }
    return ls;
}

const Baked& baked(bool shadow_planes) {
    static const Baked with = bake_volumes(pillar_scene(), 2, true), without = bake_volumes(pillar_scene(), 2, false);
    return shadow_planes ? with : without;
}

TEST(ShadowPlanes, OnlyTheCellsTheShadowEdgeSplitsGetOne) {
    const Baked& b = baked(true);
    ASSERT_TRUE(b.error.empty()) << b.error;
    const PlaneFitStats& st = b.planes_report.planes;
    EXPECT_GT(st.shadow_planes, 0u);
    EXPECT_EQ(st.shadow_planes, st.planes);  // no geometry in any cell
    const ProbeGrid g = probe_layout(pillar_scene().scene.probes).grid;
    const std::vector<CellPlane> planes = cell_planes_from_bytes(b.planes_leak.planes);
    std::size_t split = 0, with_plane = 0;
    for (std::uint32_t z = 0; z + 1 < g.counts[2]; ++z)
        for (std::uint32_t y = 0; y + 1 < g.counts[1]; ++y)
            for (std::uint32_t x = 0; x + 1 < g.counts[0]; ++x) {
                const std::size_t i = x + g.counts[0] * (y + std::size_t(g.counts[1]) * z);
                int in = 0;
                for (int k = 0; k < 8; ++k) {
                    const Vec3 c{g.origin.x + (x + (k & 1)) * g.spacing.x, g.origin.y + (y + ((k >> 1) & 1)) * g.spacing.y,
                                 g.origin.z + (z + ((k >> 2) & 1)) * g.spacing.z};
                    in += in_wedge(c);
                }
                const bool is_split = in > 0 && in < 8;
                split += is_split;
                with_plane += planes[i].present();
                EXPECT_EQ(planes[i].present(), is_split) << x << " " << y << " " << z << ": " << in << " corners in the shadow";
            }
    EXPECT_GT(split, 0u);
    EXPECT_EQ(with_plane, split);
}

TEST(ShadowPlanes, TheKeptCornersShareThePointsSideOfTheShadow) {
    const Baked& b = baked(true);
    ASSERT_TRUE(b.error.empty()) << b.error;
    const ProbeGrid g = probe_layout(pillar_scene().scene.probes).grid;
    const std::vector<CellPlane> planes = cell_planes_from_bytes(b.planes_leak.planes);
    std::mt19937_64 rng(5);
    std::size_t cells = 0;
    for (std::size_t i = 0; i < planes.size(); ++i) {
        if (!planes[i].present()) continue;
        ++cells;
        const std::uint32_t x = std::uint32_t(i % g.counts[0]), y = std::uint32_t(i / g.counts[0] % g.counts[1]),
                            z = std::uint32_t(i / (std::size_t(g.counts[0]) * g.counts[1]));
        Vec3 corner[8];
        for (int k = 0; k < 8; ++k)
            corner[k] = {g.origin.x + (x + (k & 1)) * g.spacing.x, g.origin.y + (y + ((k >> 1) & 1)) * g.spacing.y,
                         g.origin.z + (z + ((k >> 2) & 1)) * g.spacing.z};
        int agree = 0;
        const int n = 512;
        for (int j = 0; j < n; ++j) {
            const Vec3 p{corner[0].x + u01(rng) * g.spacing.x, corner[0].y + u01(rng) * g.spacing.y, corner[0].z + u01(rng) * g.spacing.z};
            const unsigned side = cell_plane_value(planes[i], g, x, y, z, p) >= 0 ? 1u : 0u;
            bool all = true;
            int kept = 0;
            for (int k = 0; k < 8; ++k) {
                if (((planes[i].sides >> k) & 1u) != side) continue;
                ++kept;
                all = all && in_wedge(corner[k]) == in_wedge(p);
            }
            agree += kept > 0 && all;
        }
        EXPECT_GE(agree, int(0.97 * n)) << "cell " << x << " " << y << " " << z;
    }
    EXPECT_GT(cells, 0u);
}

TEST(ShadowPlanes, TheShadowStaysDarkInTheRuntime) {
    const LeakScene ls = pillar_scene();
    const std::vector<double> truth = truth_of(ls);
    Metrics m[2];
    for (int with = 0; with < 2; ++with) {
        const Baked& b = baked(with == 1);
        ASSERT_TRUE(b.error.empty()) << b.error;
        zhc_volume v;
        ASSERT_TRUE(open_volume(b.planes_zhp, &v));
        m[with] = metrics(ls.points, sample_points(v, ls.points), truth);
    }
    std::printf("pillar: leak %.3f %% with shadow planes, %.3f %% without; lit error %.2f %% and %.2f %%\n", 100 * m[1].leak,
                100 * m[0].leak, 100 * m[1].lit_error, 100 * m[0].lit_error);
    double dark_truth = 0;
    for (size_t i = 0; i < ls.points.size(); ++i)
        if (ls.points[i].side == Side::kDark) dark_truth += truth[i];
    EXPECT_EQ(dark_truth, 0.0);  // the analytic wedge is the bake's shadow
    EXPECT_LT(m[1].leak, 0.01);
    EXPECT_GT(m[0].leak, 0.1);
    EXPECT_LT(m[1].lit_error, m[0].lit_error);
}

TEST(ShadowPlanes, DirectionalLightsTooSoftLightsAndTheSwitchNone) {
    {
        const Baked b = bake_volumes(pillar_scene(false), 1, true);
        ASSERT_TRUE(b.error.empty()) << b.error;
        EXPECT_GT(b.planes_report.planes.shadow_planes, 0u);
    }
    {
        LeakScene ls = pillar_scene(false);
        ls.scene.lights[0].angular_radius_rad = 0.05;  // a sun disc: a soft edge
        const Baked b = bake_volumes(ls, 1, true);
        ASSERT_TRUE(b.error.empty()) << b.error;
        EXPECT_EQ(b.planes_report.planes.shadow_planes, 0u);
        EXPECT_EQ(b.planes_report.planes.planes, 0u);
    }
    {
        LeakScene ls = pillar_scene();
        ls.scene.lights.clear();
        ls.scene.sky = SceneSky{};
        const Baked b = bake_volumes(ls, 1, true);
        ASSERT_TRUE(b.error.empty()) << b.error;
        EXPECT_EQ(b.planes_report.planes.planes, 0u);
    }
    const Baked& off = baked(false);
    ASSERT_TRUE(off.error.empty()) << off.error;
    EXPECT_EQ(off.planes_report.planes.planes, 0u);
    EXPECT_EQ(off.planes_report.planes.shadow_planes, 0u);
}

TEST(ShadowPlanes, SameBytesWithOneAndTwoThreads) {
    const Baked one = bake_volumes(pillar_scene(), 1, true);
    ASSERT_TRUE(one.error.empty()) << one.error;
    EXPECT_EQ(one.planes_zhp, baked(true).planes_zhp);
}

}  // namespace
}  // namespace zhc
