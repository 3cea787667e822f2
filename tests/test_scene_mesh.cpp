// Triangle-mesh occluders (codec/bake/occluders.h) and mesh scenes (formats/scene/scene_json.h "mesh"):
// Moller-Trumbore against a slow twin (plane intersection + edge functions), the bake's tracer
// (OccluderBvh: Embree) against a brute-force loop over every triangle and against its reference
// twin (tests/reference_bvh.h) on real glTF meshes, seams without leaks, and a quad of two
// triangles removing exactly the light it hides.
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include <nlohmann/json.hpp>

#include "codec/bake/occluders.h"
#include "codec/bake/scene.h"
#include "formats/scene/scene_gltf.h"
#include "formats/scene/scene_json.h"
#include "reference_bvh.h"
#include "support.h"

namespace zhc {
namespace {

// Slow twin of the ray/triangle test: intersect the supporting plane, then the three edge
// functions (n . ((b - a) x (q - a))) must share the sign of n . n. Returns the signed distance
// of q to the nearest edge relative to the triangle's size through *margin (for skipping
// rays that graze an edge, where rounding legitimately decides).
bool slow_hit(const Occluder& t, Vec3 o, Vec3 d, double t_min, double t_max, double* margin) {
    const Vec3 n = cross(t.v1 - t.v0, t.v2 - t.v0);
    const double nn = dot(n, n), dn = dot(d, n);
    *margin = 1.0;
    if (nn == 0 || dn == 0) return false;
    const double dist = dot(n, t.v0 - o) / dn;
    const Vec3 q = o + dist * d;
    const Vec3 v[3] = {t.v0, t.v1, t.v2};
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
        const Vec3 a = v[k], b = v[(k + 1) % 3];
        const double e = dot(n, cross(b - a, q - a)) / nn;  // barycentric weight of the opposite vertex
        *margin = std::min(*margin, std::abs(e));
        inside = inside && e >= 0;
    }
    const double scale = std::max({1.0, std::abs(t_min), std::abs(dist)});
    *margin = std::min(*margin, std::abs(dist - t_min) / scale);
    if (std::isfinite(t_max)) *margin = std::min(*margin, std::abs(dist - t_max) / scale);
    return inside && dist > t_min && dist < t_max;
}

TEST(TriangleOccluder, MatchesSlowTwinOnRandomRays) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-2, 2), u01(0, 1);
    int hits = 0, compared = 0;
    for (int i = 0; i < 200000; ++i) {
        const Occluder t = triangle_occluder({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
        const Vec3 o{3 * u(rng), 3 * u(rng), 3 * u(rng)};
        // Aim at a random point of the triangle's neighbourhood so about half the rays hit.
        const double a = 1.4 * u01(rng) - 0.2, b = (1.2 - a) * u01(rng) - 0.1;
        const Vec3 target = t.v0 + a * (t.v1 - t.v0) + b * (t.v2 - t.v0);
        const Vec3 d = normalize_or(target - o, {0, 0, 1});
        const double t_max = i % 4 ? 1e30 : 4 * u01(rng);
        double margin = 0;
        const bool slow = slow_hit(t, o, d, 1e-9, t_max, &margin);
        if (margin < 1e-9) continue;  // grazing an edge or an end of the interval
        ++compared;
        ASSERT_EQ(ray_hits(t, o, d, 1e-9, t_max), slow) << "ray " << i;
        hits += slow;
    }
    EXPECT_GT(compared, 190000);
    EXPECT_GT(hits, compared / 5);
    EXPECT_LT(hits, compared * 4 / 5);
}

TEST(TriangleOccluder, PolicyCases) {
    const Occluder t = triangle_occluder({-1, -1, 2}, {1, -1, 2}, {0, 1, 2});
    const Occluder flipped = triangle_occluder({-1, -1, 2}, {0, 1, 2}, {1, -1, 2});
    EXPECT_TRUE(ray_hits(t, {0, 0, 0}, {0, 0, 1}, 1e-9, 1e30));        // front
    EXPECT_TRUE(ray_hits(flipped, {0, 0, 0}, {0, 0, 1}, 1e-9, 1e30));  // either winding
    EXPECT_TRUE(ray_hits(t, {0, 0, 4}, {0, 0, -1}, 1e-9, 1e30));       // back face blocks too
    EXPECT_FALSE(ray_hits(t, {0, 0, 0}, {0, 0, -1}, 1e-9, 1e30));      // behind the origin
    EXPECT_FALSE(ray_hits(t, {0, 0, 0}, {0, 0, 1}, 1e-9, 2.0));        // open interval: t == t_max misses
    EXPECT_TRUE(ray_hits(t, {0, 0, 0}, {0, 0, 1}, 1e-9, 2.0 + 1e-12));
    EXPECT_FALSE(ray_hits(t, {-3, 0, 2}, {1, 0, 0}, 1e-9, 1e30));      // in the plane: edge-on, misses
    EXPECT_TRUE(ray_hits(t, {-1, -1, 0}, {0, 0, 1}, 1e-9, 1e30));      // exactly through a vertex
    EXPECT_TRUE(ray_hits(t, {0, -1, 0}, {0, 0, 1}, 1e-9, 1e30));       // exactly through an edge
    const Occluder degenerate = triangle_occluder({0, 0, 2}, {1, 0, 2}, {2, 0, 2});
    EXPECT_FALSE(ray_hits(degenerate, {0.5, 0, 0}, {0, 0, 1}, 1e-9, 1e30));
}

TEST(TriangleOccluder, BvhAgreesWithBruteForceOnMeshes) {
    // A 20k-triangle sphere, a random triangle soup and a few spheres/boxes in one tree.
    std::vector<Occluder> occ = uv_sphere_triangles({0.5, -0.3, 0.2}, 1.5, 100, 100);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-4, 4), u01(0, 1);
    for (int i = 0; i < 3000; ++i) {
        const Vec3 a{u(rng), u(rng), u(rng)};
        occ.push_back(triangle_occluder(a, a + Vec3{0.3 * u01(rng), 0.3 * u01(rng), 0}, a + Vec3{0, 0.2 * u01(rng), 0.3 * u01(rng)}));
    }
    Occluder s = sphere_occluder({3, 3, 3}, 0.4);
    occ.push_back(s);
    Occluder b = box_occluder({-3.5, 2, -1}, {-3, 2.5, 1});
    occ.push_back(b);
    ASSERT_GT(occ.size(), 22000u);
    const OccluderBvh bvh(occ);
    // Memory: the 80-byte occluders, Embree's float vertices and indices (48 bytes per triangle)
    // and its BVH.
    const double per_primitive = static_cast<double>(bvh.memory_bytes()) / static_cast<double>(occ.size());
    std::printf("OccluderBvh: %.1f bytes per primitive\n", per_primitive);
    EXPECT_GT(per_primitive, 80.0 + 48.0);
    EXPECT_LT(per_primitive, 256.0);
    Vec3 lo, hi;
    bvh.root_bounds(&lo, &hi);
    const double half = 0.5 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    // The same answer as the loop over every occluder, except for rays within 1e-5 of the scene's
    // half size of a triangle's edge: there Embree's float test decides (it grows each triangle by
    // 2^-18 of the half size, so it may block a ray the double test lets pass by that much).
    int hits = 0, near_edge = 0, differ = 0;
    for (int i = 0; i < 6000; ++i) {
        const Vec3 o{0.75 * u(rng), 0.75 * u(rng), 0.75 * u(rng)};
        const Vec3 d = test::uniform_direction(u01(rng), u01(rng));
        const double t_max = i % 3 ? 1e30 : 5 * u01(rng);
        bool brute = false;
        for (const Occluder& x : occ) brute = brute || ray_hits(x, o, d, 1e-9, t_max);
        hits += brute;
        if (bvh.occluded(o, d, 1e-9, t_max) == brute) continue;
        ++differ;
        ASSERT_TRUE(grazes_an_edge(occ, o, d, 1e-9, t_max, 1e-5 * half)) << "ray " << i;
        ++near_edge;
    }
    std::printf("occluded: %d of 6000 rays differ from the brute-force loop, all within 1e-5 of an edge\n", differ);
    EXPECT_LE(differ, 3);  // a few in 10^4 at most: the band within 1e-5 of an edge is that thin
    EXPECT_GT(hits, 1000);  // both outcomes well represented
    EXPECT_LT(hits, 5000);
}

// The bake's tracer (Embree, double decisions) against the reference twin (tests/reference_bvh.h:
// zhc's own double-precision BVH, the brute-force loop's answers) on real meshes: loaders.gl's
// photogrammetry tile (9,439 triangles, Draco) and gltf-pipeline's multiple-boxes (Blender export),
// random rays and rays aimed exactly at vertices and edge points. Agreement: hit or miss the same,
// except within 1e-5 of the scene's half size of an edge; where both hit, the same distance to the
// last bit when the same triangle is hit, else within 1e-5 relative (two triangles meeting at the
// hit point) or an edge grazed.
TEST(TriangleOccluder, RealMeshesAgreeWithReferenceTwin) {
    for (const char* rel : {"/gltf/loaders.gl/tile.glb", "/gltf/gltf-pipeline/multiple-boxes/multiple-boxes.gltf"}) {
        const std::string file = std::string(ZHC_TEST_DATA_DIR) + rel;
        std::ifstream in(file, std::ios::binary);
        const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ASSERT_FALSE(bytes.empty()) << file;
        auto scene = parse_scene_gltf(bytes, file, {}, {});
        ASSERT_TRUE(scene.ok()) << scene.error().message;
        const std::vector<Occluder>& occ = scene->occluders;
        ASSERT_GT(occ.size(), 10u);
        const OccluderBvh bvh(occ);
        const ReferenceBvh ref(occ);
        Vec3 lo, hi;
        bvh.root_bounds(&lo, &hi);
        const Vec3 c = 0.5 * (lo + hi), ext = hi - lo;
        const double half = 0.5 * std::max({ext.x, ext.y, ext.z}), tol = 1e-5 * half;
        std::mt19937_64 rng(17);
        std::uniform_real_distribution<double> u01(0, 1);
        // Per kind of ray (0: random, 1: aimed at a vertex or an edge point): rays, hits, the same
        // triangle at the same distance, another triangle at the same point, a nearer triangle grazed
        // at its edge by one tracer only, hit or miss differing at an edge.
        int rays[2] = {}, hits[2] = {}, same_prim[2] = {}, tie[2] = {}, edge[2] = {}, miss_edge[2] = {};
        for (int i = 0; i < 40000; ++i) {
            const int aimed = i % 2;
            Vec3 o{c.x + ext.x * (1.2 * u01(rng) - 0.6), c.y + ext.y * (1.2 * u01(rng) - 0.6), c.z + ext.z * (1.2 * u01(rng) - 0.6)};
            Vec3 d = test::uniform_direction(u01(rng), u01(rng));
            if (aimed) {  // at a vertex (every third) or a point on an edge
                const Occluder& t = occ[rng() % occ.size()];
                const double w = i % 3 == 0 ? 0.0 : u01(rng);
                d = normalize_or((1 - w) * t.v0 + w * t.v1 - o, {0, 0, 1});
            }
            const double t_min = 1e-9, t_max = i % 5 == 0 ? 0.5 * half * u01(rng) : std::numeric_limits<double>::infinity();
            ++rays[aimed];
            const RayHit e = bvh.nearest(o, d, t_min, t_max);
            RayHit r = ref.nearest(o, d, t_min, t_max);
            if (r.hit) r.prim = ref.original_index(r.prim);
            EXPECT_EQ(bvh.occluded(o, d, t_min, t_max), e.hit) << file << " ray " << i;
            EXPECT_EQ(ref.occluded(o, d, t_min, t_max), r.hit) << file << " ray " << i;
            if (e.hit != r.hit) {
                const Occluder& hit = occ[e.hit ? e.prim : r.prim];
                ASSERT_LT(edge_distance(hit, o, d), tol) << file << " ray " << i << ": hit or miss differ away from an edge";
                ++miss_edge[aimed];
                continue;
            }
            if (!e.hit) continue;
            ++hits[aimed];
            if (e.prim == r.prim) {
                ASSERT_EQ(e.t, r.t) << file << " ray " << i;
                ASSERT_EQ(e.back, r.back) << file << " ray " << i;
                ++same_prim[aimed];
            } else if (std::fabs(e.t - r.t) <= 1e-5 * std::max(e.t, r.t)) {
                // Two triangles meet where the ray hits (an edge or vertex both contain): the bake's
                // tracer takes the lower index, the twin the first it visits.
                ++tie[aimed];
            } else {
                // One tracer hit a nearer triangle the other let pass: at its edge.
                const Occluder& nearer = occ[e.t < r.t ? e.prim : r.prim];
                ASSERT_LT(edge_distance(nearer, o, d), tol) << file << " ray " << i << ": distances " << e.t << " and " << r.t;
                ++edge[aimed];
            }
        }
        for (int aimed = 0; aimed < 2; ++aimed)
            std::printf("%s: %zu triangles, %d %s rays, %d hits: same triangle and distance %d, another triangle at the same point %d, "
                        "nearer triangle grazed at an edge %d, hit or miss differ at an edge %d\n",
                        rel, occ.size(), rays[aimed], aimed ? "aimed (vertices, edges)" : "random", hits[aimed], same_prim[aimed], tie[aimed],
                        edge[aimed], miss_edge[aimed]);
        EXPECT_GT(hits[0], rays[0] / 8);  // both outcomes represented
        // Random rays meet an edge (within float rounding) or a tie rarely: at most 1 in 1000.
        EXPECT_GE(same_prim[0], hits[0] - rays[0] / 1000);
        // Rays aimed at edges: the differences that change what is hit stay under 1 %.
        EXPECT_LT(edge[1] + miss_edge[1], rays[1] / 100);
    }
}

// Spheres and boxes are Embree user geometry running the double tests themselves: the same answers
// as a loop over every occluder, to the last bit (distances, faces, which primitive), for rays,
// inside_any_solid and overlaps_box. A ray starting inside a solid is blocked at t_min (back);
// primitives hit at the same distance go to the lowest index.
TEST(TriangleOccluder, SolidsTiesAndPointQueriesMatchTheLoop) {
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-5, 5), u01(0, 1);
    std::vector<Occluder> occ;
    for (int i = 0; i < 300; ++i) {
        const Vec3 c{u(rng), u(rng), u(rng)};
        if (i % 3 == 0) occ.push_back(sphere_occluder(c, 0.05 + 0.4 * u01(rng)));
        else if (i % 3 == 1) occ.push_back(box_occluder(c, c + Vec3{0.6 * u01(rng), 0.6 * u01(rng), 0.6 * u01(rng)}));
        else occ.push_back(triangle_occluder(c, c + Vec3{0.5 * u01(rng), 0.3, 0}, c + Vec3{0, 0.5 * u01(rng), 0.4}));
    }
    const OccluderBvh bvh(occ);
    Vec3 lo, hi;
    bvh.root_bounds(&lo, &hi);
    const double half = 0.5 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    int inside = 0, overlaps = 0, compared = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 o{u(rng), u(rng), u(rng)};
        const Vec3 d = test::uniform_direction(u01(rng), u01(rng));
        const double t_max = i % 3 ? std::numeric_limits<double>::infinity() : 6 * u01(rng);
        RayHit best;
        bool any = false;
        for (std::uint32_t k = 0; k < occ.size(); ++k) {
            any = any || ray_hits(occ[k], o, d, 1e-9, t_max);
            const RayHit h = ray_nearest(occ[k], o, d, 1e-9, t_max);
            if (h.hit && (!best.hit || h.t < best.t)) best = {true, h.back, h.t, k};
        }
        bool solid_in = false;
        for (const Occluder& x : occ) solid_in = solid_in || inside_solid(x, o);
        ASSERT_EQ(bvh.inside_any_solid(o), solid_in) << i;
        inside += solid_in;
        const Vec3 blo = o, bhi = o + Vec3{u01(rng), u01(rng), u01(rng)};
        bool box_hit = false;
        for (const Occluder& x : occ) {
            Vec3 a, b;
            occluder_bounds(x, &a, &b);
            box_hit = box_hit || !(b.x < blo.x || a.x > bhi.x || b.y < blo.y || a.y > bhi.y || b.z < blo.z || a.z > bhi.z);
        }
        ASSERT_EQ(bvh.overlaps_box(blo, bhi), box_hit) << i;
        overlaps += box_hit;
        if (grazes_an_edge(occ, o, d, 1e-9, t_max, 1e-5 * half)) continue;  // Embree's float decides there
        ++compared;
        ASSERT_EQ(bvh.occluded(o, d, 1e-9, t_max), any) << i;
        const RayHit h = bvh.nearest(o, d, 1e-9, t_max);
        ASSERT_EQ(h.hit, best.hit) << i;
        if (!h.hit) continue;
        ASSERT_EQ(h.t, best.t) << i;
        ASSERT_EQ(h.back, best.back) << i;
        ASSERT_EQ(h.prim, best.prim) << i;
        ASSERT_EQ(&bvh.primitive(h.prim), &bvh.primitive(best.prim));
    }
    EXPECT_GT(compared, 19900);
    EXPECT_GT(inside, 100);
    EXPECT_GT(overlaps, 1000);
    EXPECT_LT(overlaps, 19000);
    // Inside two overlapping boxes and a sphere: blocked at t_min, back face, the lowest index.
    const std::vector<Occluder> nested = {triangle_occluder({-9, -9, 5}, {9, -9, 5}, {0, 9, 5}), box_occluder({-1, -1, -1}, {1, 1, 1}),
                                          sphere_occluder({0, 0, 0}, 0.5), box_occluder({-2, -2, -2}, {2, 2, 2})};
    const OccluderBvh nb(nested);
    const RayHit in = nb.nearest({0.1, 0.2, 0.3}, {0, 0, 1}, 1e-3, 100);
    EXPECT_TRUE(in.hit && in.back);
    EXPECT_EQ(in.t, 1e-3);
    EXPECT_EQ(in.prim, 1u);
    EXPECT_TRUE(nb.occluded({0.1, 0.2, 0.3}, {0, 0, 1}, 1e-3, 100));
    EXPECT_TRUE(nb.inside_any_solid({1.5, 0, 0}));
    EXPECT_FALSE(nb.inside_any_solid({2.5, 0, 0}));
    // The same triangle twice, and a box whose face lies in its plane: all hit at t = 5 exactly; the
    // lowest index wins whatever order they are given in.
    const Occluder tri = triangle_occluder({-3, -3, 5}, {3, -3, 5}, {0, 3, 5});
    const Occluder slab = box_occluder({-4, -4, 5}, {4, 4, 6});
    for (const auto& order : {std::vector<Occluder>{tri, tri, slab}, std::vector<Occluder>{slab, tri, tri}}) {
        const OccluderBvh tb(order);
        const RayHit h = tb.nearest({0.25, 0.5, 0}, {0, 0, 1}, 1e-9, 100);
        ASSERT_TRUE(h.hit);
        EXPECT_EQ(h.t, 5.0);
        EXPECT_EQ(h.prim, 0u);
        EXPECT_EQ(tb.primitive(h.prim).kind, order[0].kind);
    }
}

TEST(TriangleOccluder, ClosedMeshHasNoLeaksAlongSeams) {
    // Rays from the centre of a tessellated sphere aimed exactly at its vertices and edge
    // midpoints (the seams where two triangles meet) are all blocked.
    const int n_lat = 24, n_lon = 48;
    const Vec3 c{0.1, 0.2, 0.3};
    const std::vector<Occluder> mesh = uv_sphere_triangles(c, 2.0, n_lat, n_lon);
    const OccluderBvh bvh(mesh);
    int rays = 0;
    for (const Occluder& t : mesh)
        for (const Vec3& target : {t.v0, t.v1, t.v2, 0.5 * (t.v0 + t.v1), 0.5 * (t.v1 + t.v2), 0.5 * (t.v2 + t.v0)}) {
            const Vec3 d = normalize_or(target - c, {0, 0, 1});
            ASSERT_TRUE(bvh.occluded(c, d, 1e-9, 1e30)) << "leak towards (" << target.x << ", " << target.y << ", " << target.z << ")";
            ++rays;
        }
    EXPECT_GT(rays, 6000);
    // A plane tiled with 2 x 10 x 10 triangles, hit exactly at every grid vertex and edge midpoint.
    std::vector<Occluder> plane;
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j) {
            const Vec3 a{i - 5.0, j - 5.0, 3}, b{i - 4.0, j - 5.0, 3}, cc{i - 4.0, j - 4.0, 3}, d{i - 5.0, j - 4.0, 3};
            plane.push_back(triangle_occluder(a, b, cc));
            plane.push_back(triangle_occluder(a, cc, d));
        }
    const OccluderBvh pb(plane);
    for (int i = 0; i <= 20; ++i)
        for (int j = 0; j <= 20; ++j) {
            const Vec3 target{-5 + 0.5 * i, -5 + 0.5 * j, 3};
            const Vec3 o{0.3, -0.2, 0};
            ASSERT_TRUE(pb.occluded(o, normalize_or(target - o, {0, 0, 1}), 1e-9, 1e30)) << i << " " << j;
        }
}

// ---- a quad of two triangles between a light and a probe ---------------------------------------

Scene two_probes() {
    Scene s;
    s.probes.kind = ProbePlacementKind::kPositions;
    s.probes.positions = {{0, 0, 0}, {3, 0, 0}};
    return s;
}


// Occluders that no effect traces (no shadowed light; sky samples 0, or sky samples but neither
// distant lighting nor a grid): the bake builds no tree, the probes are those of the scene without
// occluders bit for bit, through both bake_scene overloads; each effect that traces turns the tree on.
TEST(TriangleOccluder, UntracedOccludersBuildNoTreeAndChangeNothing) {
    Scene s = two_probes();
    SceneLight l;
    l.kind = LightKind::kPoint;
    l.position = {0, 0, 4};
    l.color = {6, 5, 4};
    l.shadows = false;
    s.lights = {l};
    s.occluders = uv_sphere_triangles({0, 0, 2}, 0.5, 20, 20);  // between the light and probe 0
    Scene bare = s;
    bare.occluders.clear();
    auto ref = bake_scene(bare);
    ASSERT_TRUE(ref.ok());
    for (int sky_samples : {0, 64}) {  // positions, no sky or environment: sky samples trace nothing
        s.occlusion.sky_samples = sky_samples;
        EXPECT_FALSE(bake_traces_occluders(s));
        auto a = bake_scene(s);
        Scene given = s;
        auto b = bake_scene(std::move(given));
        ASSERT_TRUE(a.ok() && b.ok());
        EXPECT_TRUE(given.occluders.empty());
        for (size_t p = 0; p < ref->size(); ++p) {
            EXPECT_EQ(std::memcmp(&(*a)[p], &(*ref)[p], sizeof(Sh3Radiance)), 0) << p;
            EXPECT_EQ(std::memcmp(&(*b)[p], &(*ref)[p], sizeof(Sh3Radiance)), 0) << p;
        }
    }
    Scene shadowed = s;
    shadowed.lights[0].shadows = true;
    EXPECT_TRUE(bake_traces_occluders(shadowed));
    auto sh = bake_scene(shadowed);
    ASSERT_TRUE(sh.ok());
    EXPECT_GT(test::max_abs_diff((*sh)[0], (*ref)[0]), 0.1);  // the sphere shadows probe 0 then
    Scene grid = s;
    grid.probes.kind = ProbePlacementKind::kGrid;
    grid.probes.min = {-1, -1, 0};
    grid.probes.max = {1, 1, 1};
    grid.probes.counts = {2, 2, 2};
    grid.occlusion.sky_samples = 16;  // validity and masks trace on a grid
    EXPECT_TRUE(bake_traces_occluders(grid));
    grid.occlusion.sky_samples = 0;
    EXPECT_FALSE(bake_traces_occluders(grid));
    Scene sky = s;
    SceneSky gradient;
    gradient.kind = SkyKind::kGradient;
    sky.sky = gradient;
    sky.occlusion.sky_samples = 16;
    EXPECT_TRUE(bake_traces_occluders(sky));
}

TEST(TriangleOccluder, QuadRemovesExactlyTheLightItHides) {
    Scene s = two_probes();
    SceneSky sky;
    sky.kind = SkyKind::kGradient;
    s.sky = sky;
    SceneLight a;  // above probe 0, hidden by the quad
    a.kind = LightKind::kPoint;
    a.position = {0, 0, 4};
    a.color = {6, 5, 4};
    a.shadows = true;
    SceneLight b;  // to the side: visible from both probes
    b.kind = LightKind::kSphere;
    b.center = {-3, 1, 0.5};
    b.radius = 0.4;
    b.color = {3, 9, 3};
    b.shadows = true;
    SceneLight c;  // also above the quad but not shadowed
    c.kind = LightKind::kSphere;
    c.center = {0, 0, 6};
    c.radius = 0.5;
    c.color = {1, 1, 8};
    s.lights = {a, b, c};
    // The quad [-1, 1]^2 at z = 2, as two triangles sharing the diagonal the ray to A crosses
    // (the ray from (0,0,0) to (0,0,4) passes exactly through the shared edge).
    const Vec3 q0{-1, -1, 2}, q1{1, -1, 2}, q2{1, 1, 2}, q3{-1, 1, 2};
    s.occluders = {triangle_occluder(q0, q1, q2), triangle_occluder(q0, q2, q3)};
    // About the lights' shadows: the sky stays unoccluded here (occlusion.sky_samples 0), so the
    // references without occluders differ only by the lights (sky occlusion: test_scene_occlusion).
    s.occlusion.sky_samples = 0;
    BakeReport rep;
    auto with = bake_scene(s, {}, &rep);
    Scene without_a = s;
    without_a.lights = {b, c};
    without_a.occluders.clear();
    Scene no_occluders = s;
    no_occluders.occluders.clear();
    auto ref_without = bake_scene(without_a), ref_all = bake_scene(no_occluders);
    ASSERT_TRUE(with.ok() && ref_without.ok() && ref_all.ok());
    EXPECT_GT(test::max_abs_diff((*ref_all)[0], (*ref_without)[0]), 0.1);  // A matters at probe 0
    EXPECT_LT(test::max_abs_diff((*with)[0], (*ref_without)[0]), 1e-6);    // and is removed there
    EXPECT_LT(test::max_abs_diff((*with)[1], (*ref_all)[1]), 1e-6);        // probe 1: unchanged
    EXPECT_GT(rep.rays, 0u);
    // The same quad as a box of zero thickness gives the same bake (two twins of one plane).
    Scene as_box = s;
    Occluder box = box_occluder({-1, -1, 2}, {1, 1, 2});
    as_box.occluders = {box};
    auto boxed = bake_scene(as_box);
    ASSERT_TRUE(boxed.ok());
    for (size_t p = 0; p < 2; ++p) EXPECT_LT(test::max_abs_diff((*with)[p], (*boxed)[p]), 1e-6) << p;
}

// ---- JSON "mesh" occluders ---------------------------------------------------------------------

Result<Scene> parse_text(const std::string& t) {
    return parse_scene_json(std::vector<std::uint8_t>(t.begin(), t.end()), "mesh.json", "");
}

TEST(SceneJsonMesh, ParsesIndexedAndUnindexedMeshes) {
    auto s = parse_text(R"({"version":1,"probes":{"positions":[[0,0,0]]},
        "occluders":[{"type":"mesh","name":"quad","positions":[-1,-1,2, 1,-1,2, 1,1,2, -1,1,2],"indices":[0,1,2, 0,2,3]},
                     {"type":"box","min":[5,5,5],"max":[6,6,6]},
                     {"type":"mesh","positions":[0,0,9, 1,0,9, 0,1,9]}]})");
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_EQ(s->occluders.size(), 4u);
    EXPECT_EQ(s->occluders[0].kind, OccluderKind::kTriangle);
    EXPECT_EQ(s->occluders[1].v2.y, 1.0);  // second triangle: vertices 0, 2, 3
    EXPECT_EQ(s->occluders[1].v2.x, -1.0);
    EXPECT_EQ(s->occluders[2].kind, OccluderKind::kBox);
    EXPECT_EQ(s->occluders[3].v1.x, 1.0);
    // Round trip: runs of triangles become one unindexed mesh each, same triangles.
    const std::string text = scene_json(*s);
    auto back = parse_text(text);
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_EQ(back->occluders.size(), 4u);
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(back->occluders[i].kind, s->occluders[i].kind);
        EXPECT_EQ(back->occluders[i].v2.x, s->occluders[i].v2.x);
    }
    EXPECT_EQ(nlohmann::json::parse(text)["occluders"][0]["positions"].size(), 18u);
}

TEST(SceneJsonMesh, StrictErrors) {
    struct Case {
        const char* occluder;
        ErrorCode code;
        const char* message;
    };
    const Case cases[] = {
        {R"({"type":"mesh","positions":[0,0,0, 1,0,0, 0,1]})", ErrorCode::kInvalidValue, "occluders[0].positions: must hold 3 numbers per vertex"},
        {R"({"type":"mesh","positions":[0,0,0, 1,0,0, 0,1,0],"indices":[0,1,3]})", ErrorCode::kInvalidValue,
         "occluders[0].indices[2]: must be an integer vertex index in [0, 3) (got 3)"},
        {R"({"type":"mesh","positions":[0,0,0, 1,0,0, 0,1,0],"indices":[0,1,-1]})", ErrorCode::kInvalidValue, "occluders[0].indices[2]"},
        {R"({"type":"mesh","positions":[0,0,0, 1,0,0, 0,1,0],"indices":[0,1]})", ErrorCode::kInvalidValue,
         "occluders[0].indices: must hold 3 vertex indices per triangle"},
        {R"({"type":"mesh","positions":[0,0,0, 1,0,0, 0,1,0, 1,1,1]})", ErrorCode::kInvalidValue, "vertex count must be a multiple of 3"},
        {R"({"type":"mesh","positions":[0,0,0, 1,0,"x", 0,1,0]})", ErrorCode::kInvalidValue, "occluders[0].positions[5]: must be a number"},
        {R"({"type":"mesh","positions":[]})", ErrorCode::kInvalidValue, "occluders[0].positions: must hold 3 numbers per vertex"},
        {R"({"type":"mesh","positions":[0,0,0, 1,0,0, 0,1,0],"normals":[]})", ErrorCode::kInvalidValue, "occluders[0].normals: unknown field"},
        {R"({"type":"mesh"})", ErrorCode::kInvalidValue, "occluders[0].positions: missing required field"},
        {R"({"type":"cone"})", ErrorCode::kUnsupported, "(known: sphere, box, mesh)"},
    };
    for (const Case& c : cases) {
        auto s = parse_text(std::string(R"({"version":1,"probes":{"positions":[[0,0,0]]},"occluders":[)") + c.occluder + "]}");
        ASSERT_FALSE(s.ok()) << c.occluder;
        EXPECT_EQ(s.error().code, c.code) << c.occluder << ": " << s.error().message;
        EXPECT_NE(s.error().message.find(c.message), std::string::npos) << s.error().message;
        EXPECT_EQ(s.error().message.find('\n'), std::string::npos);
    }
    // The triangle limit counts over all meshes.
    SceneLoadOptions small;
    small.limits.max_triangles = 3;
    const std::string two = R"({"version":1,"probes":{"positions":[[0,0,0]]},"occluders":[
        {"type":"mesh","positions":[0,0,0, 1,0,0, 0,1,0, 0,0,1, 1,0,1, 0,1,1]},
        {"type":"mesh","positions":[0,0,0, 1,0,0, 0,1,0, 0,0,1, 1,0,1, 0,1,1]}]})";
    auto s = parse_scene_json(std::vector<std::uint8_t>(two.begin(), two.end()), "mesh.json", "", small);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kTooLarge);
    EXPECT_NE(s.error().message.find("occluders[1]: mesh triangles exceed the limit of 3"), std::string::npos) << s.error().message;
}

}  // namespace
}  // namespace zhc
