// Corner regions (docs/runtime.md "Corner regions", codec/bake/leak_planes.h): the bake's second
// kind of cell entry, on the leak suite's closed box (tests/leak_scenes.h closed_box: a hollow box,
// 0.1 m walls, around the grid probe (3, 1.5, 3), in a room lit by a point light).
//  * the 8 cells around the enclosed probe get a corner region each, holding exactly that probe's
//    corner, each threshold inside the box's wall on its axis; no other cell gets one;
//  * every shading point inside the box reads exactly 0 through the C runtime (only the enclosed
//    probe, which no direct light reaches), where one plane per cell (corner_regions false) leaks over
//    10 % of the outside's light; the points 1e-4 off the box's outer faces lie outside the regions;
//  * the bake's region test (cell_region_inside) and the C header's side
//    (zhc__volume_plane_side) agree at 20,000 random points of the region cells;
//  * occlusion.corner_regions false: no region; the bake is the same with 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "leak_scenes.h"

namespace zhc {
namespace {

using namespace leak;

const LeakScene& box_scene() {
    static const LeakScene ls = closed_box(24);
    return ls;
}

const Baked& baked(bool regions) {
    static const Baked with = bake_volumes(box_scene(), 2, true), without = [] {
        LeakScene ls = box_scene();
        ls.scene.occlusion.corner_regions = false;
        return bake_volumes(ls, 2, true);
    }();
    return regions ? with : without;
}

std::array<std::uint32_t, 3> cell_of(const ProbeGrid& g, std::size_t i) {
    return {std::uint32_t(i % g.counts[0]), std::uint32_t(i / g.counts[0] % g.counts[1]),
            std::uint32_t(i / (std::size_t(g.counts[0]) * g.counts[1]))};
}

TEST(CornerRegions, TheEightCellsAroundTheEnclosedProbeHoldIt) {
    const Baked& b = baked(true);
    ASSERT_TRUE(b.error.empty()) << b.error;
    const ProbeGrid g = probe_layout(box_scene().scene.probes).grid;
    const std::vector<CellPlane> entries = cell_planes_from_bytes(b.planes_leak.planes);
    // The enclosed probe: (3, 1.5, 3) is grid point (2, 1, 2).
    const std::uint32_t centre[3] = {2, 1, 2};
    int regions = 0;
    for (std::size_t i = 0; i < entries.size(); ++i) {
        if (!entries[i].region()) continue;
        ++regions;
        const auto c = cell_of(g, i);
        const std::uint8_t inside = cell_region_corners(entries[i]);
        ASSERT_EQ(__builtin_popcount(inside), 1) << i;
        const int k = __builtin_ctz(inside);
        for (int a = 0; a < 3; ++a) {
            EXPECT_EQ(c[size_t(a)] + std::uint32_t((k >> a) & 1), centre[a]) << "cell " << i << " axis " << a;
            // The threshold lies inside the box's wall on this axis: between its outer and inner
            // faces on the cell's side of the box.
            const int q = cell_region_threshold(entries[i], a);
            ASSERT_GT(q, 0);
            const double at = g.origin[a] + (double(c[size_t(a)]) + q / 31.0) * g.spacing[a];
            const double lo = a == 1 ? kBoxYLo : kBoxLo, hi = a == 1 ? kBoxYHi : kBoxHi;
            const bool below = c[size_t(a)] < centre[a];  // the cell lies on the box's low side along a
            const double outer = below ? lo : hi, inner = below ? lo + kBoxWall : hi - kBoxWall;
            EXPECT_GT(at, std::min(outer, inner)) << "cell " << i << " axis " << a << " q " << q;
            EXPECT_LT(at, std::max(outer, inner)) << "cell " << i << " axis " << a << " q " << q;
        }
    }
    EXPECT_EQ(regions, 8);
    EXPECT_EQ(b.planes_report.planes.regions, 8u);
}

TEST(CornerRegions, TheBoxIsDarkInsideInTheRuntimeAndItsFacesLit) {
    const LeakScene& ls = box_scene();
    const std::vector<double> truth = truth_of(ls);
    Metrics m[2];
    double max_dark = 0;
    for (int with = 0; with < 2; ++with) {
        const Baked& b = baked(with == 1);
        ASSERT_TRUE(b.error.empty()) << b.error;
        zhc_volume v;
        ASSERT_TRUE(open_volume(b.planes_zhp, &v));
        const std::vector<double> e = sample_points(v, ls.points);
        m[with] = metrics(ls.points, e, truth);
        if (with)
            for (size_t i = 0; i < e.size(); ++i)
                if (ls.points[i].side == Side::kDark) max_dark = std::max(max_dark, std::fabs(e[i]));
    }
    std::printf("closed box: leak %.3f %% with corner regions (lit error %.1f %%), %.3f %% with one plane per cell (%.1f %%)\n",
                100 * m[1].leak, 100 * m[1].lit_error, 100 * m[0].leak, 100 * m[0].lit_error);
    EXPECT_EQ(max_dark, 0.0);
    EXPECT_GT(m[0].leak, 0.1);
    // The lit points on the box's outer faces (1e-4 off them) lie outside every region.
    const ProbeGrid g = probe_layout(ls.scene.probes).grid;
    const std::vector<CellPlane> entries = cell_planes_from_bytes(baked(true).planes_leak.planes);
    int on_faces = 0;
    for (const ShadingPoint& sp : ls.points) {
        if (sp.side != Side::kLit || sp.kind == "free") continue;
        const bool near_box = sp.p.x > kBoxLo - 1e-3 && sp.p.x < kBoxHi + 1e-3 && sp.p.z > kBoxLo - 1e-3 && sp.p.z < kBoxHi + 1e-3 &&
                              sp.p.y > kBoxYLo - 1e-3 && sp.p.y < kBoxYHi + 1e-3;
        if (!near_box) continue;
        std::uint32_t i0[3];
        for (int a = 0; a < 3; ++a)
            i0[a] = std::min(std::uint32_t(std::clamp((sp.p[a] - g.origin[a]) / g.spacing[a], 0.0, double(g.counts[size_t(a)] - 1))),
                             g.counts[size_t(a)] - 2);
        const CellPlane& cp = entries[i0[0] + g.counts[0] * (i0[1] + std::size_t(g.counts[1]) * i0[2])];
        if (!cp.region()) continue;
        ++on_faces;
        EXPECT_FALSE(cell_region_inside(cp, g, i0[0], i0[1], i0[2], sp.p)) << sp.p.x << " " << sp.p.y << " " << sp.p.z;
    }
    EXPECT_GT(on_faces, 50);
}

TEST(CornerRegions, TheBakesTestIsTheHeadersSide) {
    const Baked& b = baked(true);
    ASSERT_TRUE(b.error.empty()) << b.error;
    zhc_volume v;
    ASSERT_TRUE(open_volume(b.planes_zhp, &v));
    const ProbeGrid g = probe_layout(box_scene().scene.probes).grid;
    const std::vector<CellPlane> entries = cell_planes_from_bytes(b.planes_leak.planes);
    std::mt19937_64 rng(9);
    int compared = 0, inside = 0;
    for (std::size_t i = 0; i < entries.size(); ++i) {
        if (!entries[i].region()) continue;
        const auto c = cell_of(g, i);
        for (int s = 0; s < 2500; ++s) {
            const Vec3 p{g.origin.x + (c[0] + u01(rng)) * g.spacing.x, g.origin.y + (c[1] + u01(rng)) * g.spacing.y,
                         g.origin.z + (c[2] + u01(rng)) * g.spacing.z};
            const double pd[3] = {p.x, p.y, p.z};
            int side = -1;
            unsigned sides = 0;
            ASSERT_EQ(zhc__volume_plane_side(&v, i, c.data(), pd, &side, &sides), 1);
            EXPECT_EQ(side == 1, cell_region_inside(entries[i], g, c[0], c[1], c[2], p));
            EXPECT_EQ(sides, cell_region_corners(entries[i]));
            inside += side;
            ++compared;
        }
    }
    EXPECT_EQ(compared, 8 * 2500);
    EXPECT_GT(inside, 1000);  // both sides
    EXPECT_LT(inside, compared - 1000);
}

TEST(CornerRegions, TheSwitchAndThreads) {
    const Baked& off = baked(false);
    ASSERT_TRUE(off.error.empty()) << off.error;
    EXPECT_EQ(off.planes_report.planes.regions, 0u);
    for (const CellPlane& cp : cell_planes_from_bytes(off.planes_leak.planes)) EXPECT_FALSE(cp.region());
    const Baked one = bake_volumes(box_scene(), 1, true);
    ASSERT_TRUE(one.error.empty()) << one.error;
    EXPECT_EQ(one.planes_zhp, baked(true).planes_zhp);
}

}  // namespace
}  // namespace zhc
