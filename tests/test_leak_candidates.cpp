// The visibility candidates of tests/leak_candidates.h on the leak suite (docs/leaks.md
// "Candidates"), 24 points per surface:
//  * the sampler skeleton: "plain" is zhc_volume_irradiance on the volume without leak data and
//    "masks" is it on the volume with validity + visibility, bit for bit, at every shading point;
//    a constant field stays constant under every candidate;
//  * the plane quantisation: the axes are exact through the octahedral code; the fitted plane of a
//    wall through the middle of a cell is axis-aligned and lies inside the wall;
//  * the chosen scheme (probes relocated out of geometry and towards the walls that a cell's plane
//    describes, + one separating plane per cell, 6 bytes per probe): no leak in any of the 18
//    two-room configurations, the lit side within 1.5 points of plain's error or closer, the
//    window room below plain and below 3 %, never above plain's leak anywhere; 15 probes moved out
//    of the wall; the failures that set the choice apart (masks above plain, per-octant distances
//    above 1 % in the two rooms, the plane without relocation 2.5x plain's lit error with the
//    probe column inside the wall and 10 points above it with the wall at 0.8);
//  * a normal bias of 5 % of the cell lets light through a 2 % wall (why the scheme uses none).
// The bakes compared follow geometry only (occlusion.shadow_planes false): shadow planes are the
// default bake's addition, measured by tests/test_leak_suite.cpp and tests/test_shadow_planes.cpp.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "leak_candidates.h"

namespace zhc {
namespace {

using namespace leak;

struct Case {
    LeakScene scene;
    Baked baked;
    std::unique_ptr<CandidateSet> cs;
    std::vector<double> truth;
    std::vector<Metrics> m;  // per candidate
};

int candidate(const Case& c, const std::string& name) {
    for (size_t k = 0; k < c.cs->names.size(); ++k)
        if (c.cs->names[k] == name) return int(k);
    ADD_FAILURE() << "no candidate " << name;
    return 0;
}

const std::vector<Case>& suite() {
    static const std::vector<Case> cases = [] {
        std::vector<LeakScene> scenes = suite_scenes();
        std::vector<Case> out;
        for (LeakScene& s : scenes) {
            Case c;
            c.baked = bake_volumes(s, 2, false);
            EXPECT_TRUE(c.baked.error.empty()) << c.baked.error;
            c.cs = build_candidates(s, c.baked);
            EXPECT_TRUE(c.cs->error.empty()) << c.cs->error;
            c.truth = truth_of(s);
            std::printf("%-28s", s.name.c_str());
            for (const CandidateVolume& cv : c.cs->volumes) {
                c.m.push_back(metrics(s.points, sample_candidate(cv, s.points), c.truth));
                std::printf(" %6.2f%% %5.1f%%", 100 * c.m.back().leak, 100 * c.m.back().lit_error);
            }
            std::printf("  moved %zu\n", c.cs->moved);
            c.scene = std::move(s);
            out.push_back(std::move(c));
        }
        return out;
    }();
    return cases;
}

TEST(LeakCandidates, SkeletonIsTheRuntimeForPlainAndMasks) {
    for (const Case& c : suite()) {
        zhc_volume plain, masked;
        ASSERT_TRUE(open_volume(c.baked.plain_zhp, &plain));
        ASSERT_TRUE(open_volume(c.baked.masked_zhp, &masked));
        const std::vector<double> rp = sample_points(plain, c.scene.points), rm = sample_points(masked, c.scene.points);
        const std::vector<double> sp = sample_candidate(c.cs->volumes[size_t(candidate(c, "plain"))], c.scene.points);
        const std::vector<double> sm = sample_candidate(c.cs->volumes[size_t(candidate(c, "masks"))], c.scene.points);
        for (size_t i = 0; i < rp.size(); ++i) {
            ASSERT_EQ(std::memcmp(&rp[i], &sp[i], sizeof(double)), 0) << c.scene.name << " point " << i;
            ASSERT_EQ(std::memcmp(&rm[i], &sm[i], sizeof(double)), 0) << c.scene.name << " point " << i;
        }
    }
}

TEST(LeakCandidates, ConstantFieldStaysConstant) {
    for (const Case& c : suite()) {
        const zhc_volume& pv = c.cs->volumes[0].v;
        const std::size_t count = std::size_t(pv.counts[0]) * pv.counts[1] * pv.counts[2];
        std::vector<float> sh(27 * count, 0.0f);
        for (std::size_t i = 0; i < count; ++i) {  // constant radiance (0.25, 0.5, 1) / Y00 on the DC term
            sh[27 * i + 0] = float(0.25 / kY00);
            sh[27 * i + 1] = float(0.5 / kY00);
            sh[27 * i + 2] = float(1.0 / kY00);
        }
        zhc_probe_format f;
        ASSERT_EQ(zhc_probe_format_init(&f, "sh3"), ZHC_OK);
        zhc_volume cv0;
        ASSERT_EQ(zhc_volume_init(&cv0, &f, sh.data(), sh.size() * sizeof(float), pv.origin, pv.spacing, pv.counts), ZHC_OK);
        for (size_t k = 0; k < c.cs->volumes.size(); ++k) {
            CandidateVolume cv = c.cs->volumes[k];
            cv.v = cv0;
            for (const ShadingPoint& sp : c.scene.points) {
                const double p[3] = {sp.p.x, sp.p.y, sp.p.z}, n[3] = {sp.n.x, sp.n.y, sp.n.z};
                double rgb[3];
                candidate_irradiance(cv, p, n, rgb);
                ASSERT_NEAR(rgb[0], 0.25, 1e-6) << c.scene.name << " " << c.cs->names[k];
                ASSERT_NEAR(rgb[1], 0.5, 1e-6) << c.scene.name << " " << c.cs->names[k];
                ASSERT_NEAR(rgb[2], 1.0, 1e-6) << c.scene.name << " " << c.cs->names[k];
            }
        }
    }
}

TEST(LeakCandidates, PlaneQuantisation) {
    for (int a = 0; a < 3; ++a)
        for (double s : {-1.0, 1.0}) {
            Vec3 n{};
            set_axis(n, a, s);
            std::uint8_t u = 0, v = 0;
            oct_encode(n, &u, &v);
            const Vec3 d = oct_decode(u, v);
            EXPECT_EQ(d.x, n.x);
            EXPECT_EQ(d.y, n.y);
            EXPECT_EQ(d.z, n.z);
        }
    // The wall through the middle of the cells: an x plane inside the wall in each crossed cell.
    const LeakScene ls = two_rooms(0.5, 0.10);
    const Baked b = bake_volumes(ls, 1, false);
    ASSERT_TRUE(b.error.empty()) << b.error;
    const OccluderBvh bvh(ls.scene.occluders);
    const GridInfo g = grid_of(ls.scene);
    std::vector<Vec3> pos;
    for (std::size_t i = 0; i < g.count(); ++i) pos.push_back(g.position(i));
    leak::PlaneFitStats st;
    const std::vector<leak::CellPlane> planes = cell_planes(bvh, g, pos, b.leak.validity, {}, &st);
    const double t = 0.10 * kCell, centre = 5 + 0.5 * t;
    std::size_t crossed = 0;
    for (std::uint32_t z = 0; z + 1 < g.n[2]; ++z)
        for (std::uint32_t y = 0; y + 1 < g.n[1]; ++y)
            for (std::uint32_t x = 0; x + 1 < g.n[0]; ++x) {
                const leak::CellPlane& cp = planes[g.index(x, y, z)];
                const Vec3 lo = g.position(g.index(x, y, z));
                const bool crosses = lo.x < centre && lo.x + g.spacing.x > centre;
                EXPECT_EQ(cp.offset != leak::CellPlane::kNoPlane, crosses) << x << " " << y << " " << z;
                if (!crosses) continue;
                ++crossed;
                const Vec3 nq = oct_decode(cp.ou, cp.ov), c = cell_centre(g, x, y, z);
                EXPECT_EQ(std::fabs(nq.x), 1.0);
                const double px = c.x + nq.x * cp.offset * plane_unit(g);  // the plane's x
                EXPECT_GT(px, 5.0);
                EXPECT_LT(px, 5.0 + t);
                // The lit corners (x index x) on one side, the dark ones on the other.
                for (int k = 0; k < 8; ++k)
                    EXPECT_EQ((cp.sides >> k) & 1, (cp.sides & 1) ^ (k & 1)) << "corner " << k;
            }
    EXPECT_EQ(crossed, std::size_t(2 * 4));
    EXPECT_EQ(st.planes, crossed);
    EXPECT_EQ(st.wrong_pairs, 0u);  // a plane separates every blocked pair from every visible one
}

TEST(LeakCandidates, ChosenSchemeStopsTheLeaksItCan) {
    for (const Case& c : suite()) {
        const int plain = candidate(c, "plain"), chosen = candidate(c, "reloc2+plane");
        const Metrics& p = c.m[size_t(plain)];
        const Metrics& m = c.m[size_t(chosen)];
        EXPECT_EQ(c.cs->bytes[size_t(chosen)], 6.0);
        // Never above plain's leak.
        EXPECT_LE(m.leak, p.leak + 1e-9) << c.scene.name;
        if (c.scene.offset >= 0) {
            // No light on the dark side of any two-room configuration (measured 0.00 %).
            EXPECT_LT(m.leak, 1e-4) << c.scene.name;
            // The lit side as close to the truth as plain's or closer, within 1.5 points (measured
            // -7.2 to +0.8 points).
            EXPECT_LT(m.lit_error, p.lit_error + 0.015) << c.scene.name;
            // One or two columns of 15 probes moved towards the wall (measured 15 or 30).
            EXPECT_TRUE(c.cs->moved_towards == 15 || c.cs->moved_towards == 30) << c.scene.name << " " << c.cs->moved_towards;
            if (c.scene.offset == 0.0) {
                EXPECT_EQ(c.cs->moved, 15u) << c.scene.name;  // the probe column inside the wall
                EXPECT_EQ(c.cs->stuck, 0u);
                // Closer to the truth than plain (measured 13.9-15.9 % against 17-21 %).
                EXPECT_LT(m.lit_error, p.lit_error - 0.01) << c.scene.name;
                // Without relocation the lit side keeps the plane 1.5 m from the wall (measured 55-68 %).
                EXPECT_GT(c.m[size_t(candidate(c, "plane"))].lit_error, 2.5 * p.lit_error) << c.scene.name;
            }
            if (c.scene.offset == 0.2) {
                // Per-octant min distances let the dark side through (measured 1.6-1.8 %).
                EXPECT_GT(c.m[size_t(candidate(c, "octant min"))].leak, 0.01) << c.scene.name;
            }
            if (c.scene.offset == 0.8 && c.scene.thickness < 0.2) {
                // Without relocation towards the wall the lit side keeps the probe plane 1.2 m from
                // it (measured 42-44 % against plain's 28 %; relocated 25 %).
                EXPECT_GT(c.m[size_t(candidate(c, "reloc+plane"))].lit_error, p.lit_error + 0.10) << c.scene.name;
                EXPECT_LT(m.lit_error, p.lit_error - 0.02) << c.scene.name;
            }
            if (c.scene.offset >= 0.6 && c.scene.thickness < 0.2) {  // today's masks: 4x plain's leak or more
                EXPECT_GT(c.m[size_t(candidate(c, "masks"))].leak, 3 * p.leak) << c.scene.name;
            }
        }
    }
    const Case& window = suite()[suite().size() - 2];
    ASSERT_EQ(window.scene.name, "window room (sky)");
    const Metrics& wm = window.m[size_t(candidate(window, "reloc2+plane"))];
    const Metrics& wp = window.m[size_t(candidate(window, "plain"))];
    EXPECT_LT(wm.leak, 0.03);                      // measured 2.2 % (truth 2.6 %; plain 5.6 %)
    EXPECT_LT(wm.lit_error, 0.5 * wp.lit_error);   // measured 7.9 % against 30 %
    // What it does not stop (docs/leaks.md "Candidates"): the corridor's shadow boundary in open
    // air and the box needing 3 planes per cell; both stay above 1 % and at or below plain.
    const Case& corridor = suite()[suite().size() - 3];
    const Case& box = suite().back();
    EXPECT_GT(corridor.m[size_t(candidate(corridor, "reloc2+plane"))].leak, 0.10);
    EXPECT_GT(box.m[size_t(candidate(box, "reloc2+plane"))].leak, 0.10);
    EXPECT_EQ(corridor.cs->moved_towards, 24u);  // only walls a plane describes (measured 24 and 0)
    EXPECT_EQ(box.cs->moved_towards, 0u);
}

// The bake's own implementation (codec/bake/leak_planes.h, the default `zhc bake`) against this
// prototype, written separately: the same moved probes, the same planes byte for byte, and the C
// runtime's samples of its .zhp equal to the prototype sampler's at every shading point.
TEST(LeakCandidates, TheBakeIsThePrototypeOfTheChosenScheme) {
    for (const Case& c : suite()) {
        SCOPED_TRACE(c.scene.name);
        const int chosen = candidate(c, "reloc2+plane");
        const CandidateVolume& cv = c.cs->volumes[size_t(chosen)];
        ASSERT_EQ(c.baked.planes_leak.planes.size(), 5 * cv.planes.size());
        for (size_t i = 0; i < cv.planes.size(); ++i) {
            const std::uint8_t* e = &c.baked.planes_leak.planes[5 * i];
            const std::int16_t off = std::int16_t(std::uint16_t(e[2] | (e[3] << 8)));
            EXPECT_EQ(off, cv.planes[i].offset) << i;
            if (off == cv.planes[i].offset && off != leak::CellPlane::kNoPlane) {
                EXPECT_EQ(e[0], cv.planes[i].ou) << i;
                EXPECT_EQ(e[1], cv.planes[i].ov) << i;
                EXPECT_EQ(e[4], cv.planes[i].sides) << i;
            }
        }
        EXPECT_EQ(c.baked.planes_leak.validity, cv.validity);
        EXPECT_EQ(c.baked.planes_report.moved_out, c.cs->moved);
        EXPECT_EQ(c.baked.planes_report.moved_towards, c.cs->moved_towards);
        // The probes: the prototype bakes the moved ones as positions; the bake bakes them in place.
        auto proto = parse_probe_set(c.cs->towards_zhp, "prototype");
        auto bake = parse_probe_set(c.baked.planes_zhp, "bake");
        ASSERT_TRUE(proto.ok() && bake.ok());
        EXPECT_EQ(proto->payload, bake->payload);
        zhc_volume v;
        ASSERT_TRUE(open_volume(c.baked.planes_zhp, &v));
        ASSERT_NE(v.planes, nullptr);
        EXPECT_EQ(sample_points(v, c.scene.points), sample_candidate(cv, c.scene.points));
    }
}

// A normal bias above half the wall's thickness moves free points near a 2 % wall (3 cm) through
// it: the plane then leaks (measured 0.33 % at 96 points per surface); without bias it does not.
TEST(LeakCandidates, NormalBiasThroughAThinWallLeaks) {
    const LeakScene ls = two_rooms(0.2, 0.02, 96);  // 96 points per surface: the bench's
    const Baked b = bake_volumes(ls, 1, false);
    ASSERT_TRUE(b.error.empty()) << b.error;
    CandidateOptions opt;
    opt.bias = 0.05;
    const auto biased = build_candidates(ls, b, opt);
    const auto unbiased = build_candidates(ls, b);
    ASSERT_TRUE(biased->error.empty() && unbiased->error.empty());
    const std::vector<double> truth = truth_of(ls);
    const int k = 2;
    ASSERT_EQ(biased->names[size_t(k)], "plane");
    const Metrics mb = metrics(ls.points, sample_candidate(biased->volumes[size_t(k)], ls.points), truth);
    const Metrics mu = metrics(ls.points, sample_candidate(unbiased->volumes[size_t(k)], ls.points), truth);
    std::printf("plane, 2 %% wall at 0.2: leak %.3f %% with bias 0.05, %.3f %% without\n", 100 * mb.leak, 100 * mu.leak);
    EXPECT_GT(mb.leak, 1e-3);
    EXPECT_LT(mu.leak, 1e-4);
}

}  // namespace
}  // namespace zhc
