// The leak suite (tests/leak_scenes.h, docs/leaks.md): scenes where probe volumes leak light
// through walls, their ground truth, and the measured behaviour of today's two samplings ("plain"
// trilinear and validity + visibility masks through zhc_volume_from_zhp / zhc_volume_irradiance).
//  * the truth against closed forms: the lit room's points get I max(0, cos) / (pi d^2) of the
//    point light exactly, the dark room's exactly 0 (shadow rays, also for normals facing the
//    light); an unoccluded constant sky gives its radiance for every normal; the closed box's inside
//    is exactly 0;
//  * the shading points: every surface kind on both sides, 1e-4 off real geometry, none inside a
//    solid; the corridor's dark points are all in shadow;
//  * the volumes: plain trilinear leaks in every two-room configuration, less as the wall moves
//    towards the dark probe plane; the masks cut the leak at least 10x where the wall lies on the
//    lit side of the cell's middle (a probe column inside the wall included, whose probes are
//    exactly the invalid ones); the masks take 2 bytes per probe; a probe at the shading point
//    itself (the SH3 limit) is within 10 % of the truth on the lit side and every volume is further
//    off;
//  * the default bake (probes kept out of walls, a plane per cell, 6 bytes per probe): never above
//    plain's leak; the dark side below 1 % of the lit side in every two-room configuration, in the
//    L corridor (its shadow planes) and in the closed box (its corner regions), the window room
//    within the truth's own ratio; the lit side closer to the truth than plain or within 10 % of
//    plain's mean everywhere;
//  * determinism: the same files and numbers with 1 and 2 bake threads; the metrics on known values.
// The table of every configuration is printed (docs/leaks.md has it; bench/bench_leak prints it
// with per-sample cost).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "leak_scenes.h"

namespace zhc {
namespace {

using namespace leak;

struct Case {
    LeakScene scene;
    Baked baked;
    Measured m;
};

// Every configuration, baked and measured once per process (printed as a table).
const std::vector<Case>& suite() {
    static const std::vector<Case> cases = [] {
        std::vector<LeakScene> scenes = suite_scenes();
        std::vector<Case> out;
        std::printf("%-30s %4s %3s %9s %7s | %7s %7s %7s | %7s %7s %7s %7s\n", "scene", "prb", "inv", "lit/dark", "truth", "plain",
                    "masks", "planes", "floor", "plain", "masks", "planes");
        for (LeakScene& s : scenes) {
            Case c;
            c.baked = bake_volumes(s, 2);
            EXPECT_TRUE(c.baked.error.empty()) << c.baked.error;
            c.m = measure(s, c.baked);
            std::printf("%-30s %4zu %3zu %4zu/%-4zu %6.2f%% | %6.2f%% %6.2f%% %6.2f%% | %6.1f%% %6.1f%% %6.1f%% %6.1f%%\n",
                        s.name.c_str(), c.m.probes, c.m.invalid, c.m.lit_points, c.m.dark_points, 100 * c.m.truth.leak,
                        100 * c.m.plain.leak, 100 * c.m.masks.leak, 100 * c.m.planes.leak, 100 * c.m.floor.lit_error,
                        100 * c.m.plain.lit_error, 100 * c.m.masks.lit_error, 100 * c.m.planes.lit_error);
            c.scene = std::move(s);
            out.push_back(std::move(c));
        }
        return out;
    }();
    return cases;
}

const Case& two_rooms_case(double offset, double thickness) {
    for (const Case& c : suite())
        if (c.scene.offset == offset && c.scene.thickness == thickness) return c;
    ADD_FAILURE() << "no two-room case " << offset << " " << thickness;
    return suite().front();
}
const Case& named_case(const std::string& name) {
    for (const Case& c : suite())
        if (c.scene.name == name) return c;
    ADD_FAILURE() << "no case " << name;
    return suite().front();
}

TEST(LeakSuite, MetricsOfKnownValues) {
    // Lit points 2 and 4 (truth 3 and 3), dark points 1 and 0 (truth 0).
    std::vector<ShadingPoint> pts(4);
    pts[2].side = pts[3].side = Side::kDark;
    const Metrics m = metrics(pts, {2, 4, 1, 0}, {3, 3, 0, 0});
    EXPECT_EQ(m.lit_mean, 3.0);
    EXPECT_EQ(m.dark_mean, 0.5);
    EXPECT_EQ(m.leak, 0.5 / 3.0);
    EXPECT_EQ(m.lit_error, 2.0 / 6.0);  // (|2 - 3| + |4 - 3|) / (3 + 3)
}

TEST(LeakSuite, TruthIsThePointLightsClosedFormAndZeroBehindTheWall) {
    const LeakScene ls = two_rooms(0.4, 0.10);
    const std::vector<double> truth = truth_of(ls);
    ASSERT_EQ(truth.size(), ls.points.size());
    const SceneLight& l = ls.scene.lights.at(0);
    int lit = 0, dark = 0, dark_facing = 0;
    for (size_t i = 0; i < ls.points.size(); ++i) {
        const ShadingPoint& sp = ls.points[i];
        const Vec3 v = l.position - sp.p;
        const double d = length(v), c = std::max(0.0, dot(sp.n, v) / (d * length(sp.n)));
        if (sp.side == Side::kLit) {
            // The west room is convex and holds the light: every point sees it.
            const double want = 8.0 * c / (M_PI * d * d);
            EXPECT_NEAR(truth[i], want, 1e-12 * std::max(1.0, want)) << i << " " << sp.kind;
            lit += c > 0;
        } else {
            EXPECT_EQ(truth[i], 0.0) << i << " " << sp.kind;
            dark_facing += c > 0;  // zero from the shadow ray, not the normal
            ++dark;
        }
    }
    EXPECT_GT(lit, 100);
    EXPECT_GT(dark, 100);
    EXPECT_GT(dark_facing, 20);
    // The same scene without the wall between the rooms: the east points now get the closed form.
    LeakScene open = ls;
    open.scene.occluders.pop_back();
    const std::vector<double> t2 = truth_of(open);
    double east = 0;
    for (size_t i = 0; i < open.points.size(); ++i)
        if (open.points[i].side == Side::kDark) east += t2[i];
    EXPECT_GT(east, 0.0);
}

TEST(LeakSuite, TruthOfAnOpenConstantSkyIsItsRadiance) {
    LeakScene ls = window_room();
    ls.scene.occluders.clear();
    const OccluderBvh bvh(ls.scene.occluders);
    const std::vector<Vec3> dirs = sphere_sample_directions(kTruthSkyDirections);
    for (size_t i = 0; i < ls.points.size(); i += 7)
        EXPECT_NEAR(exact_irradiance(ls.scene, bvh, ls.points[i].p, ls.points[i].n, dirs), 1.0, 2e-3) << i;
    // With its walls: the inside is lit through the window only, less than outside, more than 0.
    const Case& c = named_case("window room (sky)");
    EXPECT_GT(c.m.truth.dark_mean, 0.0);
    EXPECT_LT(c.m.truth.dark_mean, 0.2 * c.m.truth.lit_mean);
}

TEST(LeakSuite, TheClosedBoxIsExactlyDarkInsideUnderTheTruth) {
    const Case& c = named_case("closed box in a lit room");
    ASSERT_EQ(c.m.truth_e.size(), c.scene.points.size());
    int inside = 0;
    for (size_t i = 0; i < c.scene.points.size(); ++i)
        if (c.scene.points[i].side == Side::kDark) {
            EXPECT_EQ(c.m.truth_e[i], 0.0) << i;
            const Vec3 p = c.scene.points[i].p;
            EXPECT_TRUE(inside_box(p, {kBoxLo + kBoxWall, kBoxYLo + kBoxWall, kBoxLo + kBoxWall},
                                   {kBoxHi - kBoxWall, kBoxYHi - kBoxWall, kBoxHi - kBoxWall}));
            ++inside;
        }
    EXPECT_GT(inside, 150);
    EXPECT_EQ(c.scene.dropped_lit_dark, 0u);
    EXPECT_GT(c.m.truth.lit_mean, 0.01);
    // One probe lies inside the box (valid: in air), and the volumes still light the inside.
    EXPECT_EQ(c.m.invalid, 0u);
    EXPECT_GT(c.m.plain.dark_mean, 0.0);
}

TEST(LeakSuite, ShadingPointsLieOnRealSurfacesOnBothSides) {
    for (const Case& c : suite()) {
        const OccluderBvh bvh(c.scene.scene.occluders);
        std::map<std::string, int> kinds[2];
        for (const ShadingPoint& sp : c.scene.points) {
            ++kinds[sp.side == Side::kDark][sp.kind];
            EXPECT_FALSE(bvh.inside_any_solid(sp.p)) << c.scene.name;
            EXPECT_NEAR(length(sp.n), 1.0, 1e-12);
            if (sp.kind != "free") {
                EXPECT_TRUE(bvh.occluded(sp.p, -1.0 * sp.n, 0.0, 2 * kSurfaceOffset)) << c.scene.name << " " << sp.kind;
                EXPECT_FALSE(bvh.occluded(sp.p, -1.0 * sp.n, 0.0, 0.5 * kSurfaceOffset)) << c.scene.name << " " << sp.kind;
            }
        }
        for (int side = 0; side < 2; ++side) {
            // 48 free points a side; the corridor drops the dark ones that see the light.
            if (side == 1 && c.scene.dropped_lit_dark > 0) {
                EXPECT_GE(kinds[side]["free"], 24) << c.scene.name;
            } else {
                EXPECT_EQ(kinds[side]["free"], 48) << c.scene.name << " side " << side;
            }
            EXPECT_GT(kinds[side]["floor"], 0) << c.scene.name << " side " << side;
            EXPECT_GT(kinds[side]["wall"], 0) << c.scene.name << " side " << side;
            if (c.scene.offset >= 0) {
                EXPECT_GT(kinds[side]["ceiling"], 0) << c.scene.name;
            }
        }
    }
    // Only the corridor's dark region has points that see the light (past the inner corner).
    EXPECT_GT(named_case("L corridor").scene.dropped_lit_dark, 0u);
    for (const Case& c : suite())
        if (c.scene.offset >= 0) {
            EXPECT_EQ(c.scene.dropped_lit_dark, 0u);
        }
}

TEST(LeakSuite, PlainTrilinearLeaksLessAsTheWallNearsTheDarkProbes) {
    for (double th : wall_thicknesses()) {
        double previous = 1e9;
        for (double off : wall_offsets()) {
            const Case& c = two_rooms_case(off, th);
            EXPECT_EQ(c.m.truth.leak, 0.0);
            EXPECT_GT(c.m.plain.leak, 0.0) << off << " " << th;
            EXPECT_LT(c.m.plain.leak, previous) << off << " " << th;
            previous = c.m.plain.leak;
        }
        // A probe column inside the wall: the worst case of plain trilinear (over 10 %).
        EXPECT_GT(two_rooms_case(0.0, th).m.plain.leak, 0.1) << th;
    }
}

TEST(LeakSuite, MasksCutTheLeakWhenTheWallIsOnTheLitSideOfTheCellsMiddle) {
    for (double th : wall_thicknesses()) {
        // The column inside the wall: exactly its probes (3 x 5) are invalid.
        const Case& in_wall = two_rooms_case(0.0, th);
        EXPECT_EQ(in_wall.m.invalid, 15u) << th;
        const ProbeGrid g = probe_layout(in_wall.scene.scene.probes).grid;
        const double wall_lo = 5, wall_hi = 5 + th * kCell;
        for (size_t i = 0; i < in_wall.baked.leak.validity.size(); ++i) {
            const double x = g.origin[0] + double(i % g.counts[0]) * g.spacing[0];
            EXPECT_EQ(in_wall.baked.leak.validity[i], x > wall_lo && x < wall_hi ? 0 : 1) << i;
        }
        for (double off : {0.0, 0.2, 0.4}) {
            const Case& c = two_rooms_case(off, th);
            EXPECT_LE(c.m.masks.leak, 0.1 * c.m.plain.leak) << off << " " << th;
        }
    }
}

TEST(LeakSuite, BytesPerProbeAndTheSh3Floor) {
    for (const Case& c : suite()) {
        EXPECT_EQ(c.m.mask_bytes_per_probe, 2.0) << c.scene.name;
        EXPECT_EQ(c.baked.leak.visibility.size(), c.m.probes);
        EXPECT_LT(c.m.floor.lit_error, 0.1) << c.scene.name;
        EXPECT_GT(c.m.floor.lit_error, 0.0) << c.scene.name;
        EXPECT_GT(c.m.plain.lit_error, c.m.floor.lit_error) << c.scene.name;
        EXPECT_GT(c.m.masks.lit_error, c.m.floor.lit_error) << c.scene.name;
    }
}

// The default bake (probes kept out of walls, one plane per cell; what `zhc bake` writes and every
// runtime applies): the suite's targets (docs/leaks.md "Metrics").
TEST(LeakSuite, TheDefaultBakesPlanesStopTheLeakInEveryTwoRoomConfiguration) {
    for (const Case& c : suite()) {
        SCOPED_TRACE(c.scene.name);
        // 6 bytes per probe: validity (1) + the plane of the cell it starts (5).
        EXPECT_EQ(c.m.planes_bytes_per_probe, 6.0);
        EXPECT_EQ(c.baked.planes_leak.planes.size(), 5 * c.m.probes);
        EXPECT_TRUE(c.baked.planes_leak.visibility.empty());
        // Never above plain's leak (the truth's own ratio allowed where light really passes).
        EXPECT_LE(c.m.planes.leak, std::max(c.m.plain.leak, c.m.truth.leak) + 1e-12);
        // The lit side: closer to the truth than plain, or its mean within 10 % of plain's.
        const bool closer = c.m.planes.lit_error <= c.m.plain.lit_error;
        const bool near_plain = std::fabs(c.m.planes.lit_mean - c.m.plain.lit_mean) <= 0.1 * c.m.plain.lit_mean;
        EXPECT_TRUE(closer || near_plain) << c.m.planes.lit_error << " vs " << c.m.plain.lit_error;
        for (double e : c.m.planes_e) EXPECT_TRUE(std::isfinite(e)) << e;
        if (c.scene.offset >= 0) {
            // Two rooms: below 1 % of the lit side (exactly zero here), at every offset and thickness.
            EXPECT_LT(c.m.planes.leak, 0.01);
            EXPECT_LT(c.m.planes.leak, 1e-4);
            // No probe stays invalid: the in-wall column is baked beside the wall.
            EXPECT_EQ(c.baked.planes_report.left_inside, 0u);
            EXPECT_GT(c.baked.planes_report.planes.planes, 0u);
        }
    }
    // The in-wall column (offset 0): its 15 probes are moved out; the lit side then is closer to
    // the truth than plain's.
    for (double th : wall_thicknesses()) {
        const Case& c = two_rooms_case(0.0, th);
        EXPECT_GE(c.baked.planes_report.moved_out, 15u) << th;
        EXPECT_LT(c.m.planes.lit_error, c.m.plain.lit_error) << th;
    }
    // The L corridor: the point light's shadow edge past the inner corner crosses cells of open air;
    // their shadow planes keep the dark leg's points on the shadowed probes (measured 0.00 %), and
    // the lit side closer to the truth than plain.
    const Case& corridor = named_case("L corridor");
    EXPECT_GT(corridor.baked.planes_report.planes.shadow_planes, 0u);
    EXPECT_LT(corridor.m.planes.leak, 0.01);
    EXPECT_LT(corridor.m.planes.lit_error, corridor.m.plain.lit_error);
    // The closed box: the 8 cells around the enclosed probe hold corner regions; its inside reads
    // the enclosed probe alone (measured 0.00 %), the lit side closer to the truth than plain.
    const Case& box = named_case("closed box in a lit room");
    EXPECT_EQ(box.baked.planes_report.planes.regions, 8u);
    EXPECT_LT(box.m.planes.leak, 0.01);
    EXPECT_LT(box.m.planes.lit_error, box.m.plain.lit_error);
    // The window room: the outside's light inside within the truth's own ratio + 1 point.
    const Case& w = named_case("window room (sky)");
    EXPECT_LT(w.m.planes.leak, w.m.truth.leak + 0.01);
    EXPECT_LT(w.m.planes.lit_error, 0.5 * w.m.plain.lit_error);
}

TEST(LeakSuite, SameFilesAndNumbersWithOneAndTwoThreads) {
    const LeakScene a = two_rooms(0.6, 0.02), b = two_rooms(0.6, 0.02);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (size_t i = 0; i < a.points.size(); ++i) {
        EXPECT_EQ(a.points[i].p.x, b.points[i].p.x);
        EXPECT_EQ(a.points[i].n.z, b.points[i].n.z);
    }
    const Baked b1 = bake_volumes(a, 1), b2 = bake_volumes(b, 2);
    ASSERT_TRUE(b1.error.empty() && b2.error.empty());
    EXPECT_EQ(b1.plain_zhp, b2.plain_zhp);
    EXPECT_EQ(b1.masked_zhp, b2.masked_zhp);
    EXPECT_EQ(b1.planes_zhp, b2.planes_zhp);
    const Measured m1 = measure(a, b1, false), m2 = measure(b, b2, false);
    EXPECT_EQ(m1.plain_e, m2.plain_e);
    EXPECT_EQ(m1.masks_e, m2.masks_e);
    EXPECT_EQ(m1.planes_e, m2.planes_e);
    EXPECT_EQ(m1.truth_e, m2.truth_e);
    // And the suite's own bake of the same configuration (2 threads, in suite()).
    EXPECT_EQ(two_rooms_case(0.6, 0.02).baked.masked_zhp, b1.masked_zhp);
}

}  // namespace
}  // namespace zhc
