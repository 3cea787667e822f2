// Scene baking (codec/bake/scene.h, codec/bake/occluders.h), the scene JSON (formats/scene/scene_json.h) and the
// bake/demo verbs: closed forms against their slow twins (dense sphere sampling), inverse square,
// environment-only == `zhc project`, occluders removing exactly the shadowed light, the effects
// report, determinism across thread counts, and the parser's errors and exit codes.
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "codec/bake/occluders.h"
#include "codec/bake/scene.h"
#include "codec/probe/zh3.h"
#include "formats/probes/probe_file.h"
#include "formats/scene/scene_json.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;

Sh3Radiance bake_one(const Scene& s, BakeReport* rep = nullptr, int threads = 1) {
    BakeOptions o;
    o.threads = threads;
    auto r = bake_scene(s, o, rep);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() && !r->empty() ? (*r)[0] : Sh3Radiance{};
}

Scene at_positions(std::vector<Vec3> ps) {
    Scene s;
    s.probes.kind = ProbePlacementKind::kPositions;
    s.probes.positions = std::move(ps);
    return s;
}


// Slow twin: radiance of the scene's lights as a function of direction, integrated over a dense
// Fibonacci sphere (each direction stands for 4 pi / n sr). `visible(d, t_max)` masks occlusion.
template <class Radiance>
Sh3Radiance dense_projection(int n, Radiance&& radiance) {
    const std::vector<Vec3> dirs = test::fibonacci_directions(n);
    std::vector<WeightedSample> samples;
    samples.reserve(dirs.size());
    for (const Vec3& d : dirs) samples.push_back({d, 4.0 * kPi / n, radiance(d)});
    return project_samples(samples);
}

// Distance along unit d from p to the sphere (c, r), or -1 when missed.
double hit_sphere(Vec3 p, Vec3 d, Vec3 c, double r) {
    const Vec3 oc = p - c;
    const double b = dot(d, oc), cc = dot(oc, oc) - r * r, disc = b * b - cc;
    if (disc < 0) return -1;
    const double t = -b - std::sqrt(disc);
    return t > 0 ? t : -1;
}

SceneLight sphere_light(Vec3 c, double r, Rgb L) {
    SceneLight l;
    l.kind = LightKind::kSphere;
    l.center = c;
    l.radius = r;
    l.color = L;
    return l;
}
SceneLight point_light(Vec3 p, Rgb I) {
    SceneLight l;
    l.kind = LightKind::kPoint;
    l.position = p;
    l.color = I;
    return l;
}

// ---- closed forms ---------------------------------------------------------------------------

TEST(SceneBake, SphereLightEqualsClosedFormAndDenseSampling) {
    const Vec3 c{0.7, -0.4, 1.9};
    const double r = 0.45;
    const Rgb L{12.0f, 5.0f, 2.0f};
    const std::vector<Vec3> probes{{0, 0, 0}, {1.5, 1.0, 0.2}, {0.7, -0.4, 3.0}, {-2, 2, 5}};
    Scene s = at_positions(probes);
    s.lights.push_back(sphere_light(c, r, L));
    auto baked = bake_scene(s);
    ASSERT_TRUE(baked.ok());
    for (size_t i = 0; i < probes.size(); ++i) {
        const Vec3 v = c - probes[i];
        const double d = length(v);
        const Sh3Radiance closed = project_cone((1.0 / d) * v, std::asin(r / d), L);
        EXPECT_LT(test::max_abs_diff((*baked)[i], closed), 1e-5 * test::max_abs(closed)) << "probe " << i;
        // Slow twin: the sphere's radiance where a ray hits it, dense sampling (400k directions).
        const Sh3Radiance dense = dense_projection(400000, [&](Vec3 w) {
            return hit_sphere(probes[i], w, c, r) > 0 ? L : Rgb{};
        });
        EXPECT_LT(test::max_abs_diff((*baked)[i], dense), 2e-3 * test::max_abs(closed) + 1e-4) << "probe " << i;
        // A single cone light is zonal about one axis for all channels: the luminance-axis ZH3 fit
        // reproduces it exactly (ZH3 paper Sec. 3).
        const Zh3 z = zh3_fit((*baked)[i], ZonalAxisMode::kLuminance, LuminanceWeights{});
        const Sh3Radiance back = zh3_expand(z, ZonalAxisMode::kLuminance, LuminanceWeights{});
        EXPECT_LT(test::max_abs_diff(back, (*baked)[i]), 1e-5 * test::max_abs(closed)) << "probe " << i;
    }
}

TEST(SceneBake, ProbeInsideSphereLightSeesConstantRadiance) {
    Scene s = at_positions({{0.1, 0.0, 0.0}});
    s.lights.push_back(sphere_light({0, 0, 0}, 1.0, {2, 3, 4}));
    const Sh3Radiance sh = bake_one(s);
    EXPECT_LT(test::max_abs_diff(sh, project_constant({2, 3, 4})), 1e-6);
}

TEST(SceneBake, PointLightFollowsInverseSquare) {
    const Vec3 light{0.3, -0.2, 2.0};
    const Vec3 w = normalize_or({0.2, 0.5, -1.0}, {0, 0, 1});  // from the light to the probes
    const double d1 = 1.5, d2 = 3.0;
    Scene s = at_positions({light + d1 * w, light + d2 * w});
    s.lights.push_back(point_light(light, {5, 4, 3}));
    auto baked = bake_scene(s);
    ASSERT_TRUE(baked.ok());
    const Sh3Radiance& a = (*baked)[0];
    const Sh3Radiance& b = (*baked)[1];
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            if (std::abs(a[i][k]) > 1e-6) {
                EXPECT_NEAR(a[i][k] / b[i][k], (d2 * d2) / (d1 * d1), 1e-5);
            }
    // And it is the delta of integral I / d^2 towards the light.
    const Sh3Radiance closed = project_directional(-1.0 * w, {float(5 / (d1 * d1)), float(4 / (d1 * d1)), float(3 / (d1 * d1))});
    EXPECT_LT(test::max_abs_diff(a, closed), 1e-6);
    // SH3 irradiance of a surface facing the light: the delta's band energies sum_m Y_lm(w)^2 =
    // (2l + 1) / 4pi times the band scales 1, 2/3, 1/4: (I / d^2) (1 + 2 + 5/4) / (4 pi).
    EXPECT_NEAR(irradiance(a, -1.0 * w).r, 5 / (d1 * d1) * 4.25 / (4 * kPi), 1e-5);
}

TEST(SceneBake, DirectionalAndHemisphereMatchClosedForms) {
    Scene s = at_positions({{1, 2, 3}});
    SceneLight sun;
    sun.kind = LightKind::kDirectional;
    const Sun ref;
    sun.direction = ref.towards_sun;
    sun.angular_radius_rad = ref.angular_radius_rad;
    sun.color = ref.irradiance;
    s.lights.push_back(sun);
    EXPECT_LT(test::max_abs_diff(bake_one(s), project_sun(ref)), 1e-5 * test::max_abs(project_sun(ref)));
    // Zero radius: a delta with integral pi E.
    s.lights[0].angular_radius_rad = 0;
    EXPECT_LT(test::max_abs_diff(bake_one(s), project_directional(ref.towards_sun, {float(kPi * 3.2), float(kPi * 3.0), float(kPi * 2.7)})), 1e-5);
    // Hemisphere light vs its dense twin.
    SceneLight h;
    h.kind = LightKind::kHemisphere;
    h.direction = normalize_or({0.3, -0.5, 0.8}, {0, 0, 1});
    h.color = {0.5f, 0.7f, 1.0f};
    s.lights = {h};
    const Sh3Radiance dense = dense_projection(200000, [&](Vec3 w) { return dot(w, h.direction) > 0 ? h.color : Rgb{}; });
    EXPECT_LT(test::max_abs_diff(bake_one(s), dense), 2e-3);
    EXPECT_LT(test::max_abs_diff(bake_one(s), project_hemisphere(h.direction, h.color)), 1e-6);
}

TEST(SceneBake, SpotConeAttenuationIsTheDocumentedSmoothstep) {
    SceneLight spot;
    spot.kind = LightKind::kSpot;
    spot.position = {0, 0, 4};
    spot.direction = {0, 0, -1};
    spot.color = {10, 10, 10};
    spot.inner_angle_rad = 20 * kPi / 180;
    spot.outer_angle_rad = 30 * kPi / 180;
    const double d = 2.0;
    auto probe_at = [&](double angle_deg) {
        const double a = angle_deg * kPi / 180;
        return spot.position + d * Vec3{std::sin(a), 0, -std::cos(a)};
    };
    Scene s = at_positions({probe_at(10), probe_at(25), probe_at(35)});
    s.lights.push_back(spot);
    SceneLight pt = point_light(spot.position, spot.color);
    Scene sp = s;
    sp.lights = {pt};
    auto a = bake_scene(s);
    auto b = bake_scene(sp);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_LT(test::max_abs_diff((*a)[0], (*b)[0]), 1e-7);  // inside the inner cone: the point light
    EXPECT_EQ(test::max_abs((*a)[2]), 0.0);                  // outside the outer cone: nothing
    const double c0 = std::cos(spot.outer_angle_rad), c1 = std::cos(spot.inner_angle_rad);
    const double t = (std::cos(25 * kPi / 180) - c0) / (c1 - c0), expected = t * t * (3 - 2 * t);
    EXPECT_NEAR((*a)[1][0].r / (*b)[1][0].r, expected, 1e-6);
    EXPECT_GT(expected, 0.05);
    EXPECT_LT(expected, 0.95);
}

// ---- environment ---------------------------------------------------------------------------

TEST(SceneBake, EnvironmentOnlySceneEqualsZhcProjectAtEveryProbe) {
    const auto maps = test::envmap_paths();
    ASSERT_FALSE(maps.empty());
    const std::string dir = test::temp_dir("scene_env");
    for (size_t m = 0; m < maps.size(); m += 3) {  // three of the eight maps (each ~0.5 s in CLI runs)
        const std::string scene_path = dir + "/env.json";
        nlohmann::json j = {{"version", 1},
                            {"probes", {{"grid", {{"min", {0, 0, 0}}, {"max", {2, 1, 1}}, {"counts", {3, 2, 2}}}}}},
                            {"environment", {{"map", fs::absolute(maps[m]).string()}}}};
        test::write_bytes(scene_path, [&] { const std::string t = j.dump(); return std::vector<std::uint8_t>(t.begin(), t.end()); }());
        const auto bake = test::run_zhc({"bake", scene_path, "-o", dir + "/env_probes.json", "--threads", "2"});
        ASSERT_EQ(bake.exit_code, 0) << bake.err;
        EXPECT_NE(bake.out.find("environment"), std::string::npos);
        const auto proj = test::run_zhc({"project", maps[m], "--json"});
        ASSERT_EQ(proj.exit_code, 0) << proj.err;
        const auto pj = nlohmann::json::parse(proj.out);
        auto list = read_probe_json(dir + "/env_probes.json");
        ASSERT_TRUE(list.ok()) << list.error().message;
        ASSERT_EQ(list->probes.size(), 12u);
        for (const Sh3Radiance& p : list->probes)
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k)
                    EXPECT_EQ(p[i][k], pj["sh3"][static_cast<size_t>(i)][static_cast<size_t>(k)].get<float>())
                        << test::envmap_name(maps[m]) << " coefficient " << i;
    }
}

TEST(SceneBake, EnvironmentIntensityAndRotation) {
    const auto maps = test::envmap_paths();
    ASSERT_FALSE(maps.empty());
    const Image img = test::load_envmap(maps[0]);
    const Sh3Radiance sh = project_latlong(img.rgb.data(), img.width, img.height, size_t(img.width) * 3);
    nlohmann::json j = {{"version", 1},
                        {"probes", {{"positions", {{0, 0, 0}}}}},
                        {"environment", {{"map", fs::absolute(maps[0]).string()}, {"intensity", 2.5}, {"rotation_deg", 90}}}};
    const std::string t = j.dump();
    auto scene = parse_scene_json(std::vector<std::uint8_t>(t.begin(), t.end()), "env.json", "");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    const Sh3Radiance baked = bake_one(*scene);
    const Sh3Radiance expected = scale(rotate(sh, rotation_axis_angle({0, 0, 1}, kPi / 2)), 2.5);
    EXPECT_LT(test::max_abs_diff(baked, expected), 1e-5 * test::max_abs(expected));
    // Rotating by 90 degrees about +Z moves what was along +X to +Y: L1 (-y, z, -x) components swap.
    EXPECT_NEAR(baked[1].g, -(-2.5f * sh[3].g), 1e-4 * std::abs(sh[3].g) + 1e-6);
}

// ---- occluders -----------------------------------------------------------------------------

TEST(SceneBake, BoxOccluderRemovesOnlyTheShadowedLight) {
    // Probe 0 is behind a thin box (a wall) from light A; probe 1 sees everything.
    Scene s = at_positions({{0, 0, 0}, {3, 0, 0}});
    SceneSky sky;
    sky.kind = SkyKind::kGradient;
    s.sky = sky;
    SceneLight a = point_light({0, 0, 4}, {6, 5, 4});
    a.name = "A";
    a.shadows = true;
    SceneLight b = sphere_light({-3, 1, 0.5}, 0.4, {3, 9, 3});
    b.name = "B";
    b.shadows = true;
    SceneLight c = sphere_light({0, 0, 6}, 0.5, {1, 1, 8});  // also behind the wall but unshadowed
    c.name = "C";
    s.lights = {a, b, c};
    Occluder wall = box_occluder({-1, -1, 2}, {1, 1, 2.05});
    s.occluders = {wall};
    // About the lights' shadows: the sky stays unoccluded here (occlusion.sky_samples 0), so the
    // references without occluders differ only by the lights (sky occlusion: test_scene_occlusion).
    s.occlusion.sky_samples = 0;
    BakeReport rep;
    auto with = bake_scene(s, {}, &rep);
    ASSERT_TRUE(with.ok());
    Scene without_a = s;
    without_a.lights = {b, c};
    without_a.occluders.clear();
    Scene no_occluders = s;
    no_occluders.occluders.clear();
    auto ref_without = bake_scene(without_a);
    auto ref_all = bake_scene(no_occluders);
    ASSERT_TRUE(ref_without.ok() && ref_all.ok());
    EXPECT_GT(test::max_abs_diff((*ref_all)[0], (*ref_without)[0]), 0.1);            // A matters there
    EXPECT_LT(test::max_abs_diff((*with)[0], (*ref_without)[0]), 1e-6);              // and is gone
    EXPECT_LT(test::max_abs_diff((*with)[1], (*ref_all)[1]), 1e-6);                  // probe 1: nothing changed
    EXPECT_GT(rep.rays, 0u);
    // Same with a sphere light behind the wall (cone sampling, all samples blocked -> exactly 0).
    Scene cone = at_positions({{0, 0, 0}});
    SceneLight big = sphere_light({0, 0, 5}, 0.6, {4, 4, 4});
    big.shadows = true;
    cone.lights = {big};
    cone.occluders = {wall};
    EXPECT_EQ(test::max_abs(bake_one(cone)), 0.0);
}

TEST(SceneBake, PartialShadowMatchesDenseVisibleProjection) {
    // A sphere light half hidden by a box edge: the baked result equals the projection of only the
    // visible part of the light, computed by dense sampling (the slow twin).
    const Vec3 p{0, 0, 0}, c{0, 0, 4};
    const double r = 1.0;
    Scene s = at_positions({p});
    SceneLight l = sphere_light(c, r, {5, 5, 5});
    l.shadows = true;
    l.shadow_samples = 4096;
    s.lights = {l};
    Occluder half = box_occluder({0.0, -3, 2}, {3, 3, 2.1});
    s.occluders = {half};
    const Sh3Radiance baked = bake_one(s);
    const Sh3Radiance dense = dense_projection(1000000, [&](Vec3 w) {
        if (hit_sphere(p, w, c, r) <= 0) return Rgb{};
        return ray_hits(half, p, w, 1e-9, 1e30) ? Rgb{} : l.color;
    });
    const Sh3Radiance full = project_cone({0, 0, 1}, std::asin(r / 4), l.color);
    EXPECT_GT(baked[0].r, 0.3 * full[0].r);
    EXPECT_LT(baked[0].r, 0.7 * full[0].r);
    EXPECT_LT(test::max_abs_diff(baked, dense), 0.01 * test::max_abs(full));
    // The shadow moves the L1 direction: the visible half lies at x < 0, so L11 (= -sqrt(3/4pi) x
    // weighted) turns positive where the unshadowed cone (axis +Z) has none; the bake keeps that.
    EXPECT_NEAR(full[3].r, 0.0, 1e-6);
    EXPECT_GT(dense[3].r, 0.02 * test::max_abs(full));
    EXPECT_NEAR(baked[3].r, dense[3].r, 0.1 * dense[3].r);
}

TEST(SceneBake, ShadowedProbeInsideSphereLight) {
    // Inside a sphere light with a slab just above the probe: only the lower half of the light's
    // surrounding radiance arrives (rays go to the far side of the sphere) — a downward hemisphere.
    Scene s = at_positions({{0, 0, 0}});
    SceneLight l = sphere_light({0.1, 0, 0}, 1.0, {2, 3, 4});
    l.shadows = true;
    l.shadow_samples = 4096;
    s.lights = {l};
    Occluder slab = box_occluder({-3, -3, 0.05}, {3, 3, 0.1});
    s.occluders = {slab};
    const Sh3Radiance baked = bake_one(s);
    // Slow twin: dense directions, visible unless the slab is hit before the ray leaves the sphere
    // (near-horizontal upward rays pass under the slab's far edge: not exactly a hemisphere).
    const Sh3Radiance dense = dense_projection(400000, [&](Vec3 w) {
        const Vec3 v = l.center;  // centre - probe
        const double b = dot(w, v), t_exit = b + std::sqrt(b * b - dot(v, v) + l.radius * l.radius);
        return ray_hits(slab, {0, 0, 0}, w, 1e-9, t_exit) ? Rgb{} : l.color;
    });
    const Sh3Radiance hemisphere = project_hemisphere({0, 0, -1}, l.color);
    EXPECT_LT(test::max_abs_diff(baked, dense), 0.01 * test::max_abs(hemisphere));
    EXPECT_LT(test::max_abs_diff(baked, hemisphere), 0.1 * test::max_abs(hemisphere));  // and close to the half
}

TEST(Occluders, BvhAgreesWithBruteForce) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-5, 5), u01(0, 1);
    std::vector<Occluder> occ;
    for (int i = 0; i < 300; ++i) {
        Occluder o;
        if (i % 2) {
            const Vec3 c{u(rng), u(rng), u(rng)};
            o = sphere_occluder(c, 0.05 + 0.3 * u01(rng));
        } else {
            const Vec3 a{u(rng), u(rng), u(rng)};
            o = box_occluder(a, a + Vec3{0.5 * u01(rng), 0.5 * u01(rng), 0.5 * u01(rng)});
        }
        occ.push_back(o);
    }
    const OccluderBvh bvh(occ);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 o{u(rng), u(rng), u(rng)};
        const Vec3 d = test::uniform_direction(u01(rng), u01(rng));
        const double t_max = i % 3 ? 1e30 : 3 * u01(rng);
        bool brute = false;
        for (const Occluder& x : occ) brute = brute || ray_hits(x, o, d, 1e-9, t_max);
        ASSERT_EQ(bvh.occluded(o, d, 1e-9, t_max), brute) << "ray " << i;
        hits += brute;
    }
    EXPECT_GT(hits, 1000);
    EXPECT_LT(hits, 19000);
    // Analytic cases: a sphere straight ahead, behind, beyond t_max; a box from inside.
    Occluder sph = sphere_occluder({0, 0, 5}, 1);
    EXPECT_TRUE(ray_hits(sph, {0, 0, 0}, {0, 0, 1}, 1e-9, 1e30));
    EXPECT_FALSE(ray_hits(sph, {0, 0, 0}, {0, 0, -1}, 1e-9, 1e30));
    EXPECT_FALSE(ray_hits(sph, {0, 0, 0}, {0, 0, 1}, 1e-9, 3.9));
    Occluder box = box_occluder({-1, -1, -1}, {1, 1, 1});
    EXPECT_TRUE(ray_hits(box, {0, 0, 0}, {1, 0, 0}, 1e-9, 1e30));
    EXPECT_TRUE(ray_hits(box, {-3, 0.5, 0}, {1, 0, 0}, 1e-9, 1e30));
    EXPECT_FALSE(ray_hits(box, {-3, 0.5, 0}, {1, 0, 0}, 1e-9, 1.9));
}

TEST(SceneBake, ConeSamplesAreEqualAreaInsideTheCone) {
    const Vec3 axis = normalize_or({1, 2, 3}, {0, 0, 1});
    const double sigma = 0.3;
    const auto dirs = cone_sample_directions(axis, sigma, 2000);
    ASSERT_EQ(dirs.size(), 2000u);
    double mean_z = 0;
    for (const Vec3& d : dirs) {
        EXPECT_NEAR(length(d), 1.0, 1e-12);
        EXPECT_GE(dot(d, axis), std::cos(sigma) - 1e-12);
        mean_z += dot(d, axis) / dirs.size();
    }
    // Uniform over the cap: mean cos = (1 + cos sigma) / 2.
    EXPECT_NEAR(mean_z, (1 + std::cos(sigma)) / 2, 1e-9);
}

// ---- report and determinism ----------------------------------------------------------------

TEST(SceneBake, ReportListsExactlyTheSceneEffects) {
    Scene s = at_positions({{0, 0, 0}});
    SceneSky sky;
    sky.kind = SkyKind::kConstant;
    s.sky = sky;
    SceneLight p = point_light({1, 0, 0}, {1, 1, 1});
    p.name = "lamp";
    SceneLight h;
    h.kind = LightKind::kHemisphere;
    h.shadows = true;  // asks for shadows, but there are no occluders: nothing traced
    s.lights = {p, h};
    BakeReport rep;
    bake_one(s, &rep);
    ASSERT_EQ(rep.effects.size(), 3u);
    EXPECT_EQ(rep.effects[0].name, "sky (constant)");
    EXPECT_EQ(rep.effects[1].name, "point 'lamp'");
    EXPECT_EQ(rep.effects[2].name, "hemisphere");
    for (const BakeEffect& e : rep.effects) EXPECT_EQ(e.method, "closed form");
    EXPECT_EQ(rep.rays, 0u);
    // An occluder: only the shadowed light traces.
    Occluder o = sphere_occluder({5, 5, 5}, 1);
    s.occluders = {o};
    bake_one(s, &rep);
    EXPECT_EQ(rep.effects[1].method, "closed form");
    EXPECT_EQ(rep.effects[1].rays, 0u);
    EXPECT_EQ(rep.effects[2].rays, 64u);
    EXPECT_EQ(rep.effects[2].method, "closed form, shadowed: 64 rays");
    EXPECT_NE(rep.summary().find("hemisphere (closed form, shadowed: 64 rays)"), std::string::npos);
    // An empty scene simulates nothing.
    Scene empty = at_positions({{0, 0, 0}});
    bake_one(empty, &rep);
    EXPECT_TRUE(rep.effects.empty());
}

std::string write_scene(const std::string& dir, const std::string& name, const std::string& text) {
    const std::string p = dir + "/" + name;
    test::write_bytes(p, std::vector<std::uint8_t>(text.begin(), text.end()));
    return p;
}

TEST(SceneCli, BakeIsDeterministicAcrossThreadsAndReportsEffects) {
    const std::string dir = test::temp_dir("scene_det");
    const Scene s = default_scene();
    Scene big = s;
    big.probes.counts = {20, 16, 8};  // 2560 probes: several blocks per thread
    const std::string path = write_scene(dir, "scene.json", scene_json(big));
    const auto r1 = test::run_zhc({"bake", path, "-o", dir + "/t1.zhp", "--threads", "1"});
    const auto r2 = test::run_zhc({"bake", path, "-o", dir + "/t2.zhp", "--threads", "2"});
    ASSERT_EQ(r1.exit_code, 0) << r1.err;
    ASSERT_EQ(r2.exit_code, 0) << r2.err;
    EXPECT_EQ(test::read_bytes(dir + "/t1.zhp"), test::read_bytes(dir + "/t2.zhp"));
    for (const char* name : {"sky (gradient)", "sun 'sun'", "sphere 'red'", "sphere 'green'", "sphere 'blue'"})
        EXPECT_NE(r1.out.find(name), std::string::npos) << name << "\n" << r1.out;
    EXPECT_NE(r1.out.find("sun 'sun'                (closed form, shadowed: 40960 rays)"), std::string::npos) << r1.out;
    EXPECT_EQ(r1.out.find("environment"), std::string::npos);
    // The file round-trips the in-memory bake.
    auto set = read_probe_file(dir + "/t1.zhp");
    ASSERT_TRUE(set.ok()) << set.error().message;
    auto hub = decode_probe_set(*set);
    auto direct = bake_scene(big);
    ASSERT_TRUE(hub.ok() && direct.ok());
    EXPECT_EQ(*hub, *direct);
    EXPECT_EQ(set->layout.kind, ProbeLayoutKind::kGrid);
    EXPECT_EQ(set->layout.grid.counts, (std::array<std::uint32_t, 3>{20, 16, 8}));
}

// BakeOptions::progress: serialised calls, done increasing to the probe count, bytes unchanged;
// the CLI prints it on stderr only with --progress and never with --quiet.
TEST(SceneCli, BakeProgressIsMonotonicOnStderrAndChangesNothing) {
    Scene big = default_scene();
    big.probes.counts = {20, 16, 8};  // 2560 probes: three blocks of 1024
    BakeOptions plain;
    plain.threads = 2;
    const auto reference = bake_scene(big, plain);
    ASSERT_TRUE(reference.ok());
    BakeOptions with = plain;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> calls;
    with.progress = [&](std::uint64_t done, std::uint64_t total) { calls.emplace_back(done, total); };
    const auto baked = bake_scene(big, with);
    ASSERT_TRUE(baked.ok());
    EXPECT_EQ(*baked, *reference);
    ASSERT_EQ(calls.size(), 3u);
    for (std::size_t i = 0; i < calls.size(); ++i) {
        EXPECT_EQ(calls[i].second, 2560u);
        if (i) {
            EXPECT_GT(calls[i].first, calls[i - 1].first);
        }
    }
    EXPECT_EQ(calls.back().first, 2560u);

    const std::string dir = test::temp_dir("scene_progress");
    const std::string path = write_scene(dir, "scene.json", scene_json(big));
    const auto quiet = test::run_zhc({"bake", path, "-o", dir + "/q.zhp", "--threads", "2", "--quiet"});
    const auto shown = test::run_zhc({"bake", path, "-o", dir + "/p.zhp", "--threads", "2", "--progress"});
    ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
    ASSERT_EQ(shown.exit_code, 0) << shown.err;
    EXPECT_EQ(test::read_bytes(dir + "/q.zhp"), test::read_bytes(dir + "/p.zhp"));
    EXPECT_EQ(quiet.err, "");
    EXPECT_NE(shown.err.find("zhc bake: 100% (2560/2560 probes)"), std::string::npos) << shown.err;
    EXPECT_EQ(shown.out.find("zhc bake: "), std::string::npos) << shown.out;  // progress lines go to stderr only
    const auto both = test::run_zhc({"bake", path, "-o", dir + "/b.zhp", "--progress", "--quiet"});
    ASSERT_EQ(both.exit_code, 0) << both.err;
    EXPECT_EQ(both.err, "");
}

TEST(SceneCli, ParserErrorsAreClearWithExitCodes) {
    const std::string dir = test::temp_dir("scene_err");
    struct Case {
        const char* name;
        const char* text;
        int exit_code;
        const char* message;
    };
    const Case cases[] = {
        {"missing_field", R"({"version":1,"probes":{"grid":{"min":[0,0,0],"counts":[2,2,2]}}})", 4,
         "probes.grid.max: missing required field"},
        {"wrong_type", R"({"version":1,"probes":{"positions":[[0,0,0]]},"lights":[{"type":"point","position":"here","intensity":1}]})",
         4, "lights[0].position: must be an array of 3 numbers"},
        {"unknown_field", R"({"version":1,"probes":{"positions":[[0,0,0]]},"lihgts":[]})", 4, "lihgts: unknown field"},
        {"bad_version", R"({"version":2,"probes":{"positions":[[0,0,0]]}})", 5, "version: unsupported scene version 2"},
        {"negative_colour", R"({"version":1,"probes":{"positions":[[0,0,0]]},"sky":{"type":"constant","radiance":[1,-1,1]}})", 4,
         "sky.radiance[1]: must be >= 0"},
        {"too_many_rays",
         R"({"version":1,"probes":{"grid":{"min":[0,0,0],"max":[1,1,1],"counts":[1024,1024,4]}},
             "lights":[{"type":"hemisphere","direction":[0,0,1],"radiance":1,"shadows":true,"shadow_samples":4096}],
             "occluders":[{"type":"sphere","center":[0,0,9],"radius":1}]})",
         6, "shadow rays, above the limit"},
    };
    for (const Case& c : cases) {
        const std::string path = write_scene(dir, std::string(c.name) + ".json", c.text);
        const std::string out = dir + "/" + c.name + ".zhp";
        const auto r = test::run_zhc({"bake", path, "-o", out});
        EXPECT_EQ(r.exit_code, c.exit_code) << c.name << ": " << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ": " << r.err;
        EXPECT_NE(r.err.find(path), std::string::npos) << c.name << ": the message names the file: " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.name << ": one line: " << r.err;
        EXPECT_FALSE(fs::exists(out)) << c.name;
    }
    // Missing, negative radius, unknown light, huge grid, cut and overflowing JSON, missing map;
    // bad -o extension, unknown representation, unwritable output: tests/conformance scenejson_*.
}

TEST(SceneBake, DefaultSceneProbesAreOutsideLightsAndOccluders) {
    // The demo's pictures should show lighting, not a probe buried in a lamp or a wall.
    const Scene s = default_scene();
    for (const Vec3& p : probe_positions(s.probes)) {
        for (const SceneLight& l : s.lights)
            if (l.kind == LightKind::kSphere) {
                EXPECT_GT(length(p - l.center), 1.5 * l.radius);
            }
        for (const Occluder& o : s.occluders) EXPECT_FALSE(ray_hits(o, p, {0, 0, 1}, 0, 1e-6));
    }
    // Its shadows do something: some probes see the sun, some do not (the sky's occlusion, which
    // touches every probe a little, is left out here: test_scene_occlusion covers it).
    Scene no_occ = s;
    no_occ.occlusion.sky_samples = 0;
    no_occ.occluders.clear();
    Scene sky_open = s;
    sky_open.occlusion.sky_samples = 0;
    auto a = bake_scene(sky_open), b = bake_scene(no_occ);
    ASSERT_TRUE(a.ok() && b.ok());
    int changed = 0;
    for (size_t i = 0; i < a->size(); ++i) changed += test::max_abs_diff((*a)[i], (*b)[i]) > 1e-3;
    EXPECT_GT(changed, 5);
    EXPECT_LT(changed, static_cast<int>(a->size()) - 5);
}

TEST(SceneJson, RoundTripBakesTheSame) {
    Scene s = default_scene();
    SceneLight spot;
    spot.kind = LightKind::kSpot;
    spot.position = {0, 0, 3};
    spot.direction = {0.1, 0, -1};
    spot.color = {3, 2, 1};
    spot.inner_angle_rad = 0.25;
    spot.outer_angle_rad = 0.5;
    s.lights.push_back(spot);
    s.lights.push_back(point_light({1, 1, 1}, {2, 2, 2}));
    const std::string text = scene_json(s);
    auto back = parse_scene_json(std::vector<std::uint8_t>(text.begin(), text.end()), "rt.json", "");
    ASSERT_TRUE(back.ok()) << back.error().message;
    auto a = bake_scene(s), b = bake_scene(*back);
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_EQ(a->size(), b->size());
    double worst = 0;
    for (size_t i = 0; i < a->size(); ++i) worst = std::max(worst, test::max_abs_diff((*a)[i], (*b)[i]));
    EXPECT_LT(worst, 1e-4);
}

TEST(SceneCli, DemoWritesEveryOutput) {
    const std::string dir = test::temp_dir("scene_demo") + "/out";
    const auto r = test::run_zhc({"demo", "-o", dir, "--directions", "128"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* f : {"scene.json", "probes_sh3.zhp", "probes_zh3_q16.zhp", "audit.md"}) {
        EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
        EXPECT_NE(r.out.find(f), std::string::npos) << f;
    }
    EXPECT_TRUE(fs::exists(dir + "/images/probe_0.png"));
    // Every representation is in the audit table, and sh3 (the reference) has zero error.
    for (const Codec& c : codecs()) EXPECT_NE(r.out.find(std::string(c.name) + " "), std::string::npos) << c.name;
    auto set = read_probe_file(dir + "/probes_zh3_q16.zhp");
    ASSERT_TRUE(set.ok());
    EXPECT_EQ(set->count, 256u);
    EXPECT_EQ(set->payload.size(), 256u * 16u);
    // The written scene re-bakes to the same container.
    const auto rb = test::run_zhc({"bake", dir + "/scene.json", "-o", dir + "/rebake.zhp", "--quiet"});
    ASSERT_EQ(rb.exit_code, 0) << rb.err;
    EXPECT_EQ(test::read_bytes(dir + "/rebake.zhp"), test::read_bytes(dir + "/probes_sh3.zhp"));
}

}  // namespace
}  // namespace zhc
