// Reflected and emitted light (codec/bake/transport.h, docs/scene.md "Reflected light"): the
// furnace (a closed surface of albedo a emitting L_e: every probe inside sees L_e / (1 - a)), one
// bounce off an infinite plane lit by a sun (closed form) and by a point light (a slow quadrature
// twin), a two-room house (the dark room stays dark, the lit room gains its reflected light),
// determinism across threads, noise that falls with rays, scenes that reflect nothing baking the
// same bytes as without materials, and the JSON and glTF material readers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "codec/bake/occluders.h"
#include "codec/bake/scene.h"
#include "formats/scene/scene_gltf.h"
#include "formats/scene/scene_json.h"
#include "support.h"

namespace zhc {
namespace {

std::vector<Sh3Radiance> bake(const Scene& s, int threads = 1, BakeReport* rep = nullptr) {
    BakeOptions o;
    o.threads = threads;
    auto r = bake_scene(s, o, rep);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? *r : std::vector<Sh3Radiance>{};
}

// Normalised irradiance (constant radiance 1 -> 1) of channel k for unit normal n.
double irradiance(const Sh3Radiance& sh, Vec3 n, int k) {
    const auto y = sh3_basis(n);
    double e = 0;
    for (int i = 0; i < 9; ++i) e += (i == 0 ? 1.0 : i < 4 ? 2.0 / 3.0 : 0.25) * y[static_cast<size_t>(i)] * sh[i][k];
    return e;
}

const Vec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

// Closed cube of 12 triangles, all of material m.
std::vector<Occluder> cube(Vec3 lo, Vec3 hi, std::uint32_t m) {
    auto v = [&](int i) { return Vec3{(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z}; };
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    std::vector<Occluder> out;
    for (const auto& q : quads) {
        out.push_back(triangle_occluder(v(q[0]), v(q[1]), v(q[2])));
        out.push_back(triangle_occluder(v(q[0]), v(q[2]), v(q[3])));
    }
    for (Occluder& o : out) o.material = m;
    return out;
}

Scene at_positions(std::vector<Vec3> ps) {
    Scene s;
    s.probes.kind = ProbePlacementKind::kPositions;
    s.probes.positions = std::move(ps);
    s.occlusion.sky_samples = 0;
    return s;
}

// The furnace: inside a closed surface of uniform albedo a and emission L_e, radiance is
// L_e (1 + a + a^2 + ...) = L_e / (1 - a) in every direction, so each axis irradiance is that too.
void furnace(std::vector<Occluder> shell, double a, Rgb le, double tolerance) {
    Scene s = at_positions({{0, 0, 0}, {0.3, -0.2, 0.1}, {-0.4, 0.35, -0.3}});
    SceneMaterial m;
    m.albedo = {float(a), float(a), float(a)};
    m.emission = le;
    s.materials.push_back(m);
    s.occluders = std::move(shell);
    s.transport.min_rays = s.transport.max_rays = 16384;
    BakeReport rep;
    const auto probes = bake(s, 1, &rep);
    ASSERT_EQ(probes.size(), 3u);
    EXPECT_TRUE(rep.transport.traced);
    std::printf("furnace a=%.2f: %llu paths, %llu rays, mean path %.2f vertices (deepest %d), noise median %.4f\n", a,
                (unsigned long long)rep.transport.paths, (unsigned long long)rep.transport.rays,
                double(rep.transport.vertices) / double(rep.transport.paths), rep.transport.max_depth, rep.transport.noise_median);
    for (const Sh3Radiance& p : probes)
        for (int k = 0; k < 3; ++k) {
            const double want = le[k] / (1 - a);
            for (const Vec3& n : kAxes) EXPECT_NEAR(irradiance(p, n, k), want, tolerance * want);
        }
    // Every path is 3 vertices long at least (Russian roulette starts at the third); there the
    // throughput is a^3, the survival probability, after which each vertex continues with
    // probability a: 3 + a^3 / (1 - a) vertices on average in a closed room.
    const double mean_vertices = 3 + a * a * a / (1 - a);
    EXPECT_NEAR(double(rep.transport.vertices) / double(rep.transport.paths), mean_vertices, 0.03 * mean_vertices);
}

TEST(Transport, FurnaceCube) { furnace(cube({-1, -1, -1}, {1, 1, 1}, 0), 0.8, {1.0f, 0.5f, 0.25f}, 0.03); }
TEST(Transport, FurnaceSphereMesh) {
    std::vector<Occluder> shell = uv_sphere_triangles({0, 0, 0}, 1.2, 24, 48);
    for (Occluder& o : shell) o.material = 0;
    furnace(std::move(shell), 0.5, {2.0f, 2.0f, 2.0f}, 0.02);
}

// The plane z = 0 as a square of half-size R (two triangles) of grey albedo rho, material 0.
void add_plane(Scene& s, double R, double rho) {
    SceneMaterial m;
    m.albedo = {float(rho), float(rho), float(rho)};
    s.materials.push_back(m);
    s.occluders.push_back(triangle_occluder({-R, -R, 0}, {R, -R, 0}, {R, R, 0}));
    s.occluders.push_back(triangle_occluder({-R, -R, 0}, {R, R, 0}, {-R, R, 0}));
    for (Occluder& o : s.occluders) o.material = static_cast<std::uint32_t>(s.materials.size() - 1);
}

// One bounce with a closed form: a sun of normalised irradiance E0 at elevation theta over a plane
// of albedo rho lights it with E = pi E0 cos theta, so the plane's radiance is rho E0 cos theta
// everywhere; a probe above it sees that radiance over the lower hemisphere (a hemisphere light)
// plus the sun itself.
TEST(Transport, SunOverInfinitePlane) {
    Scene s = at_positions({{0, 0, 1}, {3, -2, 0.5}});
    const double rho = 0.6;
    add_plane(s, 1e5, rho);
    SceneLight sun;
    sun.kind = LightKind::kDirectional;
    sun.direction = normalize_or({0.3, 0.2, 1.0}, {0, 0, 1});
    sun.color = {1.0f, 0.5f, 0.25f};
    s.lights.push_back(sun);
    s.transport.min_rays = s.transport.max_rays = 4096;
    const auto probes = bake(s);
    ASSERT_EQ(probes.size(), 2u);
    SceneLight below;
    below.kind = LightKind::kHemisphere;
    below.direction = {0, 0, -1};
    const double c = sun.direction.z;
    below.color = {float(rho * c * 1.0), float(rho * c * 0.5), float(rho * c * 0.25)};
    for (const Sh3Radiance& p : probes) {
        double want[27] = {};
        add_light_closed_form(sun, {0, 0, 0}, want);
        add_light_closed_form(below, {0, 0, 0}, want);
        Sh3Radiance w;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) w[i][k] = float(want[i * 3 + k]);
        for (int k = 0; k < 3; ++k)
            for (const Vec3& n : kAxes) {
                const double e = irradiance(w, n, k);
                EXPECT_NEAR(irradiance(p, n, k), e, 0.01 * irradiance(w, {0, 0, 1}, k) + 1e-6) << "axis " << n.x << n.y << n.z;
            }
    }
}

// A point light of intensity I at height hl over the plane z = 0 (albedo rho): the plane's radiance
// at r is rho / pi * I hl / d^3 (d the distance from the light). The slow twin integrates what the
// probe sees over the lower hemisphere with a fine midpoint rule in (theta, phi).
TEST(Transport, PointLightOverPlaneAgainstQuadrature) {
    const Vec3 probe{0.4, -0.3, 1.0}, light{0, 0, 2.0};
    const double rho = 0.7, I = 5.0;
    Scene s = at_positions({probe});
    add_plane(s, 1e4, rho);
    SceneLight l;
    l.kind = LightKind::kPoint;
    l.position = light;
    l.color = {float(I), float(I), float(I)};
    l.shadows = true;
    s.lights.push_back(l);
    s.transport.min_rays = s.transport.max_rays = 16384;
    const auto probes = bake(s);
    ASSERT_EQ(probes.size(), 1u);
    // Slow twin: sum over the lower hemisphere of L(hit) Y(w) dw, plus the light's closed form.
    double want[27] = {};
    add_light_closed_form(l, probe, want);
    const int nt = 600, np = 1200;
    for (int i = 0; i < nt; ++i) {
        const double th = kPi / 2 + (i + 0.5) * (kPi / 2) / nt;
        for (int j = 0; j < np; ++j) {
            const double ph = (j + 0.5) * 2 * kPi / np;
            const Vec3 w{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
            const double t = -probe.z / w.z;
            const Vec3 x = probe + t * w;
            const Vec3 v = light - x;
            const double d = length(v);
            const double L = rho / kPi * I * light.z / (d * d * d);
            const double dw = std::sin(th) * (kPi / 2 / nt) * (2 * kPi / np);
            const auto y = sh3_basis(w);
            for (int c = 0; c < 9; ++c)
                for (int k = 0; k < 3; ++k) want[c * 3 + k] += L * y[static_cast<size_t>(c)] * dw;
        }
    }
    Sh3Radiance w;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) w[i][k] = float(want[i * 3 + k]);
    for (const Vec3& n : kAxes) {
        const double e = irradiance(w, n, 0), got = irradiance(probes[0], n, 0);
        std::printf("point over plane, normal (%g %g %g): twin %.6f, bake %.6f\n", n.x, n.y, n.z, e, got);
        EXPECT_NEAR(got, e, 0.01 * irradiance(w, {0, 0, -1}, 0));
    }
}

// Two rooms split by a solid wall, a point light in the west room: the east room's probes see
// nothing (no leak through the wall), the west room's gain reflected light on every side, most
// of all on the sides that do not face the lamp.
Scene house() {
    Scene s;
    s.probes.kind = ProbePlacementKind::kPositions;
    s.probes.positions = {{-3, 0.5, 1.5}, {-1, -1.5, 1.0}, {3, 0.5, 1.5}, {1.2, 1, 2}};
    SceneMaterial grey;
    grey.albedo = {0.8f, 0.8f, 0.8f};
    s.materials.push_back(grey);
    // Outer box of the house (inside faces matter; both faces of every triangle reflect).
    auto add = [&](std::vector<Occluder> t) { s.occluders.insert(s.occluders.end(), t.begin(), t.end()); };
    add(cube({-5.1, -3, 0}, {5.1, 3, 3}, 0));
    add(cube({-0.1, -3, 0}, {0.1, 3, 3}, 0));  // the dividing wall
    SceneLight l;
    l.kind = LightKind::kPoint;
    l.position = {-2.5, 0, 2.2};
    l.color = {8, 8, 8};
    l.shadows = true;
    s.lights.push_back(l);
    s.occlusion.sky_samples = 0;
    s.transport.max_noise = 0.02;
    return s;
}

TEST(Transport, HouseLitRoomAndDarkRoom) {
    Scene s = house();
    BakeReport rep;
    const auto lit = bake(s, 2, &rep);
    ASSERT_EQ(lit.size(), 4u);
    std::printf("house: %s\n", rep.summary().c_str());
    std::printf("house: %llu paths, %llu rays, deepest %d, noise median %.4f max %.4f, energy left <= %.2e\n",
                (unsigned long long)rep.transport.paths, (unsigned long long)rep.transport.rays, rep.transport.max_depth,
                rep.transport.noise_median, rep.transport.noise_max, rep.transport.energy_left);
    Scene direct_only = house();
    direct_only.transport.max_bounces = 0;
    const auto direct = bake(direct_only);
    // East room: exactly dark, with or without reflected light.
    for (size_t p : {size_t(2), size_t(3)})
        for (int i = 0; i < 9; ++i) {
            EXPECT_EQ(direct[p][i][0], 0.0f);
            EXPECT_EQ(lit[p][i][0], 0.0f) << "probe " << p << " coefficient " << i;
        }
    // West room: every axis gains light; an axis facing away from the lamp gets only reflected light.
    for (size_t p : {size_t(0), size_t(1)})
        for (const Vec3& n : kAxes) {
            const double d = irradiance(direct[p], n, 0), t = irradiance(lit[p], n, 0);
            EXPECT_GT(t, d + 0.02 * std::max(d, 0.05)) << "probe " << p;
        }
    EXPECT_LE(rep.transport.noise_max, s.transport.max_noise + 1e-12);
    EXPECT_LT(rep.transport.energy_left, 1e-5);
}

TEST(Transport, SameBytesForAnyThreadCount) {
    Scene s = house();
    s.transport.min_rays = s.transport.max_rays = 512;
    const auto a = bake(s, 1), b = bake(s, 2), c = bake(s, 3);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Sh3Radiance)), 0);
    EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(Sh3Radiance)), 0);
}

// Standard error falls as 1 / sqrt(rays): the reported noise at 4x the rays is about half.
TEST(Transport, NoiseFallsWithRays) {
    Scene s = house();
    s.transport.max_noise = 1e-9;  // never reached: every probe takes max_rays
    double noise[2];
    int i = 0;
    for (int rays : {2048, 8192}) {
        s.transport.min_rays = s.transport.max_rays = rays;
        BakeReport rep;
        (void)bake(s, 2, &rep);
        noise[i++] = rep.transport.noise_median;
        std::printf("house at %d rays/probe: noise median %.4f, %.1f ms\n", rays, rep.transport.noise_median, rep.transport.milliseconds);
    }
    EXPECT_GT(noise[0] / noise[1], 1.4);
    EXPECT_LT(noise[0] / noise[1], 2.9);
}

// A scene whose surfaces reflect and emit nothing traces nothing and bakes the bytes of the same
// scene without materials.
TEST(Transport, BlackMaterialsBakeAsNoMaterials) {
    Scene a = house();
    a.materials[0].albedo = {0, 0, 0};
    Scene b = house();
    b.materials.clear();
    for (Occluder& o : b.occluders) o.material = kNoMaterial;
    BakeReport ra, rb;
    const auto pa = bake(a, 1, &ra), pb = bake(b, 1, &rb);
    EXPECT_FALSE(ra.transport.traced);
    EXPECT_FALSE(rb.transport.traced);
    EXPECT_FALSE(scene_has_transport(a));
    ASSERT_EQ(pa.size(), pb.size());
    EXPECT_EQ(std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(Sh3Radiance)), 0);
}

// Emission alone lights a scene with no listed light: a glowing sphere mesh seen from outside
// within its cone, L00 = closed form of a sphere light of that radiance (the bake's own closed form).
TEST(Transport, EmissiveSphereMatchesSphereLight) {
    Scene s = at_positions({{0, 0, 3}});
    std::vector<Occluder> ball = uv_sphere_triangles({0, 0, 0}, 1.0, 64, 128);
    for (Occluder& o : ball) o.material = 0;
    s.occluders = std::move(ball);
    SceneMaterial m;
    m.emission = {3, 2, 1};
    s.materials.push_back(m);
    s.transport.min_rays = s.transport.max_rays = 65536;
    const auto probes = bake(s);
    ASSERT_EQ(probes.size(), 1u);
    SceneLight sl;
    sl.kind = LightKind::kSphere;
    sl.center = {0, 0, 0};
    sl.radius = 1.0;
    sl.color = m.emission;
    double want[27] = {};
    add_light_closed_form(sl, {0, 0, 3}, want);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(probes[0][0][k], want[k], 0.02 * want[k]);
    // Facing the sphere (-z), the irradiance is the sphere light's within the mesh's faceting.
    Sh3Radiance w;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) w[i][k] = float(want[i * 3 + k]);
    EXPECT_NEAR(irradiance(probes[0], {0, 0, -1}, 0), irradiance(w, {0, 0, -1}, 0), 0.02 * irradiance(w, {0, 0, -1}, 0));
}

TEST(Transport, JsonMaterialsAndLimits) {
    const std::string text = R"({"format":"zhc-scene","version":1,
        "probes":{"positions":[[0,0,1]]},
        "lights":[{"type":"point","position":[0,0,2],"intensity":[1,1,1],"shadows":true}],
        "occluders":[{"type":"mesh","positions":[-5,-5,0, 5,-5,0, 5,5,0],"albedo":0.5},
                     {"type":"mesh","positions":[-5,-5,0, 5,5,0, -5,5,0],"albedo":[0.5,0.5,0.5]},
                     {"type":"box","min":[3,3,0],"max":[4,4,1],"emission":[1,0,0]}],
        "transport":{"bounces":8,"max_noise":0.05,"min_rays":256,"max_rays":1024}})";
    auto s = parse_scene_json(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), "t.json", "", SceneLoadOptions{});
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_EQ(s->materials.size(), 2u);  // equal materials are shared
    EXPECT_EQ(s->occluders[0].material, 0u);
    EXPECT_EQ(s->occluders[1].material, 0u);
    EXPECT_EQ(s->occluders[2].material, 1u);
    EXPECT_FLOAT_EQ(s->materials[1].emission.r, 1.0f);
    EXPECT_EQ(s->transport.max_bounces, 8);
    EXPECT_EQ(s->transport.max_rays, 1024);
    // Round trip through the writer.
    const std::string back = scene_json(*s);
    auto s2 = parse_scene_json(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(back.data()), back.size()), "t2.json", "", SceneLoadOptions{});
    ASSERT_TRUE(s2.ok()) << s2.error().message;
    EXPECT_EQ(s2->materials.size(), 2u);
    EXPECT_EQ(s2->transport.max_noise, 0.05);
    for (const char* bad : {R"("albedo":1.5)", R"("albedo":-1)", R"("emission":[1,2])"}) {
        std::string t = R"({"format":"zhc-scene","version":1,"probes":{"positions":[[0,0,1]]},"occluders":[{"type":"sphere","center":[0,0,0],"radius":1,)" +
                        std::string(bad) + "}]}";
        auto r = parse_scene_json(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(t.data()), t.size()), "bad.json", "", SceneLoadOptions{});
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_NE(r.error().message.find("occluders[0]"), std::string::npos) << r.error().message;
    }
    for (const char* bad : {R"({"bounces":-1})", R"({"max_noise":0})", R"({"min_rays":100,"max_rays":10})", R"({"rays":5})"}) {
        std::string t = R"({"format":"zhc-scene","version":1,"probes":{"positions":[[0,0,1]]},"transport":)" + std::string(bad) + "}";
        auto r = parse_scene_json(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(t.data()), t.size()), "bad.json", "", SceneLoadOptions{});
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_NE(r.error().message.find("transport"), std::string::npos) << r.error().message;
    }
}

// Texture sampling (codec/bake/transport.h sample_texture): nearest and bilinear, each glTF wrap
// mode on UVs outside [0, 1], v along the rows.
TEST(Transport, TextureSamplingAndWrapModes) {
    SceneTexture t;
    t.width = 4;
    t.height = 2;
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            for (int k = 0; k < 3; ++k) t.texels.push_back(float(x + 10 * y + 100 * k));
    double c[3];
    t.nearest = true;
    struct Case {
        TextureWrap w;
        double u;
        double want;
    };
    // Texel column = floor(4 u) wrapped: repeat mod 4; clamp to [0, 3]; mirror over a period of 8.
    for (const Case& k : {Case{TextureWrap::kRepeat, 1.1, 0}, Case{TextureWrap::kClamp, 1.1, 3}, Case{TextureWrap::kMirror, 1.1, 3},
                          Case{TextureWrap::kRepeat, -0.1, 3}, Case{TextureWrap::kClamp, -0.1, 0}, Case{TextureWrap::kMirror, -0.1, 0},
                          Case{TextureWrap::kRepeat, 2.6, 2}, Case{TextureWrap::kMirror, 1.6, 1}, Case{TextureWrap::kMirror, -1.1, 3},
                          Case{TextureWrap::kClamp, 1e12, 3}, Case{TextureWrap::kRepeat, 0.3, 1}}) {
        t.wrap_s = k.w;
        sample_texture(t, k.u, 0.25, c);
        EXPECT_EQ(c[0], k.want) << "wrap " << int(k.w) << " u " << k.u;
        EXPECT_EQ(c[2], k.want + 200) << "wrap " << int(k.w) << " u " << k.u;
    }
    // Far outside [0, 1] (no fractional bits left) every mode still names a texel of the texture.
    for (TextureWrap w : {TextureWrap::kRepeat, TextureWrap::kClamp, TextureWrap::kMirror})
        for (double u : {-1e30, -123456789.123, 987654321.5, 1e30, double(NAN), double(INFINITY)}) {
            t.wrap_s = t.wrap_t = w;
            sample_texture(t, u, u, c);
            EXPECT_TRUE(c[0] >= 0 && c[0] <= 13 && c[0] == std::floor(c[0])) << int(w) << " " << u << " " << c[0];
        }
    t.wrap_t = TextureWrap::kRepeat;
    t.wrap_s = TextureWrap::kRepeat;
    sample_texture(t, 0.3, 0.75, c);  // second row
    EXPECT_EQ(c[0], 11);
    t.wrap_t = TextureWrap::kClamp;
    sample_texture(t, 0.3, 7.0, c);
    EXPECT_EQ(c[0], 11);
    // Bilinear between texel centres (u = (i + 0.5) / 4): halfway between columns 1 and 2 is 1.5.
    t.nearest = false;
    t.wrap_t = TextureWrap::kClamp;
    sample_texture(t, 0.5, 0.25, c);
    EXPECT_DOUBLE_EQ(c[0], 1.5);
    sample_texture(t, 0.5, 0.5, c);  // halfway between the rows too
    EXPECT_DOUBLE_EQ(c[0], 6.5);
    // Repeat blends the last column with the first across the edge; clamp holds the edge texel.
    t.wrap_s = TextureWrap::kRepeat;
    sample_texture(t, 1.0, 0.25, c);
    EXPECT_DOUBLE_EQ(c[0], 1.5);  // (3 + 0) / 2
    t.wrap_s = TextureWrap::kClamp;
    sample_texture(t, 1.0, 0.25, c);
    EXPECT_DOUBLE_EQ(c[0], 3.0);
    t.wrap_s = TextureWrap::kMirror;
    sample_texture(t, 1.0, 0.25, c);
    EXPECT_DOUBLE_EQ(c[0], 3.0);  // the mirrored neighbour of column 3 is column 3
}

// A floor of four triangles (x < 0 and x > 0 halves) under a sun, probes above it. `textured`:
// one white-factor material whose base colour texture is black over u < 0.5 and white (albedo
// `rho` via the factor) over u > 0.5, u = (x + R) / 2R; else the left half has a black material
// and the right half one of albedo rho.
Scene split_floor(bool textured, bool nearest, int texels, TextureWrap wrap = TextureWrap::kClamp, float u_shift = 0) {
    Scene s = at_positions({{-2, 0.5, 1}, {0, 0, 0.7}, {2.5, -1, 1.5}, {0.3, 0.2, 0.2}});
    const double R = 50, rho = 0.7;
    const Vec3 a{-R, -R, 0}, b{0, -R, 0}, c{0, R, 0}, d{-R, R, 0}, e{R, -R, 0}, f{R, R, 0};
    s.occluders = {triangle_occluder(a, b, c), triangle_occluder(a, c, d), triangle_occluder(b, e, f), triangle_occluder(b, f, c)};
    SceneLight sun;
    sun.kind = LightKind::kDirectional;
    sun.direction = normalize_or({0.3, 0.2, 1.0}, {0, 0, 1});
    sun.color = {1.0f, 0.8f, 0.6f};
    s.lights.push_back(sun);
    s.transport.min_rays = s.transport.max_rays = 1024;
    if (!textured) {
        SceneMaterial black, white;
        white.albedo = {float(rho), float(rho), float(rho)};
        s.materials = {black, white};
        for (size_t i = 0; i < 4; ++i) s.occluders[i].material = i < 2 ? 0 : 1;
        return s;
    }
    SceneMaterial m;
    m.base_factor = {float(rho), float(rho), float(rho)};
    m.metallic = 0;
    m.albedo = m.base_factor;
    m.base_texture = 0;
    s.materials = {m};
    SceneTexture t;
    t.width = static_cast<std::uint32_t>(texels);
    t.height = 1;
    t.nearest = nearest;
    t.wrap_s = t.wrap_t = wrap;
    for (int x = 0; x < texels; ++x)
        for (int k = 0; k < 3; ++k) t.texels.push_back(x < texels / 2 ? 0.0f : 1.0f);
    s.textures = {t};
    for (size_t i = 0; i < 4; ++i) {
        SurfaceUv uv;
        uv.material = 0;
        const Occluder& o = s.occluders[i];
        const Vec3 v[3] = {o.v0, o.v1, o.v2};
        for (int j = 0; j < 3; ++j) {
            uv.uv[j][0] = float((v[j].x + R) / (2 * R)) + u_shift;
            uv.uv[j][1] = float((v[j].y + R) / (2 * R));
        }
        s.surfaces.push_back(uv);
        s.occluders[i].material = kSurfaceBit | static_cast<std::uint32_t>(i);
    }
    return s;
}

// A half black, half white texture equals the floor split into two materials: the same bytes
// with nearest sampling (every hit sees the same albedo, so the paths are the same), within the
// bilinear blend band's share with a 256-texel bilinear texture; the same bytes for any thread count.
TEST(Transport, HalfBlackHalfWhiteTextureEqualsTwoMaterials) {
    const Scene two = split_floor(false, false, 0);
    const Scene tex = split_floor(true, true, 2);
    ASSERT_TRUE(validate_scene(tex).ok());
    EXPECT_TRUE(scene_has_transport(tex));
    BakeReport r_two, r_tex;
    const auto p_two = bake(two, 1, &r_two), p_tex = bake(tex, 1, &r_tex);
    ASSERT_EQ(p_two.size(), 4u);
    ASSERT_EQ(p_tex.size(), 4u);
    EXPECT_TRUE(r_tex.transport.traced);
    EXPECT_EQ(r_two.transport.vertices, r_tex.transport.vertices);
    EXPECT_EQ(std::memcmp(p_two.data(), p_tex.data(), p_two.size() * sizeof(Sh3Radiance)), 0);
    const auto p_tex3 = bake(tex, 3);
    EXPECT_EQ(std::memcmp(p_tex.data(), p_tex3.data(), p_tex.size() * sizeof(Sh3Radiance)), 0);
    // Bilinear over 256 texels: a blend band of 1/256 of the floor's width around x = 0.
    const auto p_bil = bake(split_floor(true, false, 256), 2);
    // Repeat with UVs shifted by 2 (outside [0, 1]) samples the same texels.
    const auto p_rep = bake(split_floor(true, false, 256, TextureWrap::kRepeat, 2.0f), 2);
    ASSERT_EQ(p_bil.size(), 4u);
    ASSERT_EQ(p_rep.size(), 4u);
    for (size_t i = 0; i < 4; ++i)
        for (const Vec3& n : kAxes)
            for (int k = 0; k < 3; ++k) {
                const double ref = irradiance(p_two[i], n, k), scale = irradiance(p_two[i], {0, 0, 1}, k);
                EXPECT_NEAR(irradiance(p_bil[i], n, k), ref, 0.02 * scale) << "probe " << i;
                EXPECT_NEAR(irradiance(p_rep[i], n, k), ref, 0.02 * scale) << "probe " << i;
            }
    // Clamp with UVs shifted by 2 reads the white edge everywhere: more light below each probe.
    const auto p_clamp = bake(split_floor(true, false, 256, TextureWrap::kClamp, 2.0f), 2);
    for (size_t i = 0; i < 4; ++i) EXPECT_GT(irradiance(p_clamp[i], {0, 0, -1}, 0), irradiance(p_two[i], {0, 0, -1}, 0) * 1.05) << i;
}

// A constant texture of 1 (base colour, metallic-roughness blue channel, emissive) equals the
// factors alone within 1e-6, and a texel c scales the albedo as a factor of c does.
TEST(Transport, ConstantTextureEqualsFactors) {
    auto floor = [](SceneMaterial m, bool textured, float base_texel, float metal_texel) {
        Scene s = split_floor(false, false, 0);
        s.materials = {m};
        if (textured) {
            for (int ti = 0; ti < 3; ++ti) {
                SceneTexture t;
                t.width = t.height = 3;
                const float v = ti == 0 ? base_texel : ti == 1 ? metal_texel : 1.0f;
                t.texels.assign(27, v);
                s.textures.push_back(t);
            }
            s.materials[0].base_texture = 0;
            s.materials[0].metal_rough_texture = 1;
            s.materials[0].emissive_texture = 2;
            for (size_t i = 0; i < 4; ++i) {
                SurfaceUv uv;
                uv.uv[1][0] = 3.5f;   // far outside [0, 1]: constant anyway
                uv.uv[2][1] = -2.0f;
                s.surfaces.push_back(uv);
                s.occluders[i].material = kSurfaceBit | static_cast<std::uint32_t>(i);
            }
        } else {
            for (Occluder& o : s.occluders) o.material = 0;
        }
        return s;
    };
    SceneMaterial plain;
    plain.albedo = {0.45f, 0.3f, 0.15f};  // base (0.6, 0.4, 0.2) x (1 - 0.25)
    plain.emission = {0.2f, 0.1f, 0.05f};
    SceneMaterial tex = plain;
    tex.base_factor = {0.6f, 0.4f, 0.2f};
    tex.metallic = 0.25f;
    const auto a = bake(floor(plain, false, 1, 1)), b = bake(floor(tex, true, 1, 1));
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(b[i][c][k], a[i][c][k], 1e-6 * (1 + std::fabs(a[i][c][k]))) << i << " " << c;
    // Base texel 0.5 and metallic blue 0.4: albedo = base x 0.5 x (1 - 0.25 x 0.4) = base x 0.45.
    SceneMaterial scaled = plain;
    scaled.albedo = {0.6f * 0.45f, 0.4f * 0.45f, 0.2f * 0.45f};
    const auto c = bake(floor(scaled, false, 1, 1)), d = bake(floor(tex, true, 0.5f, 0.4f));
    for (size_t i = 0; i < c.size(); ++i)
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(d[i][0][k], c[i][0][k], 1e-5 * (1 + std::fabs(c[i][0][k]))) << i;
}

// A texture's UV transform (KHR_texture_transform): an offset of half the texture with REPEAT swaps
// the black and the white half, so the floor bakes as the split floor with its materials swapped.
TEST(Transport, UvTransformOffsetSwapsHalves) {
    Scene tex = split_floor(true, true, 2, TextureWrap::kRepeat);
    tex.materials[0].base_uv = {1, 0, 0.5f, 0, 1, 0};
    Scene two = split_floor(false, false, 0);
    std::swap(two.materials[0], two.materials[1]);
    const auto a = bake(tex), b = bake(two);
    ASSERT_EQ(a.size(), 4u);
    ASSERT_EQ(b.size(), 4u);
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Sh3Radiance)), 0);
    Scene bad = tex;
    bad.materials[0].base_uv[2] = INFINITY;
    EXPECT_FALSE(validate_scene(bad).ok());
}

// validate_scene checks the texture and surface tables.
TEST(Transport, TextureTablesValidated) {
    Scene s = split_floor(true, true, 2);
    ASSERT_TRUE(validate_scene(s).ok());
    Scene bad = s;
    bad.materials[0].base_texture = 1;
    EXPECT_FALSE(validate_scene(bad).ok());
    bad = s;
    bad.textures[0].texels.pop_back();
    EXPECT_FALSE(validate_scene(bad).ok());
    bad = s;
    bad.surfaces[0].material = 3;
    EXPECT_FALSE(validate_scene(bad).ok());
    bad = s;
    bad.occluders[3].material = kSurfaceBit | 4u;
    auto r = validate_scene(bad);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("occluders[3]"), std::string::npos) << r.error().message;
    bad = s;
    bad.surfaces[1].uv[0][0] = std::nanf("");
    EXPECT_FALSE(validate_scene(bad).ok());
}

}  // namespace
}  // namespace zhc

namespace zhc {
namespace {

// The command line: --bounces/--max-noise/--rays reach the bake (the report's lines name them),
// a bad --rays exits 2 in one line before any work, and a scene whose every probe is zero gets a
// warning.
TEST(TransportCli, OptionsReportAndRefusals) {
    const std::string dir = test::fresh_dir("transport_cli");
    const std::string scene = dir + "/room.json";
    const std::string text = R"({"format":"zhc-scene","version":1,"probes":{"positions":[[0,0,1],[0.5,0.5,1.5]]},
        "lights":[{"type":"point","position":[0,0,2],"intensity":5,"shadows":true}],
        "occluders":[{"type":"mesh","positions":[-5,-5,0, 5,-5,0, 5,5,0, -5,-5,0, 5,5,0, -5,5,0],"albedo":0.5}]})";
    test::write_bytes(scene, std::vector<std::uint8_t>(text.begin(), text.end()));
    const auto ok = test::run_zhc({"bake", scene, "-o", dir + "/out.json", "--bounces", "7", "--max-noise", "0.5", "--rays", "256:256"});
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_NE(ok.out.find("(path traced: "), std::string::npos) << ok.out;
    EXPECT_NE(ok.out.find("(256 per probe)"), std::string::npos) << ok.out;
    EXPECT_NE(ok.out.find("of at most 7)"), std::string::npos) << ok.out;
    const auto off = test::run_zhc({"bake", scene, "-o", dir + "/off.json", "--bounces", "0"});
    ASSERT_EQ(off.exit_code, 0) << off.err;
    EXPECT_EQ(off.out.find("path traced"), std::string::npos) << off.out;
    for (const char* bad : {"0", "10:5", "abc", "5:", "2000000"}) {
        const auto r = test::run_zhc({"bake", scene, "-o", dir + "/bad.json", "--rays", bad});
        EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
        EXPECT_NE(r.err.find("--rays"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(std::filesystem::exists(dir + "/bad.json")) << bad;
    }
    const std::string dark = R"({"format":"zhc-scene","version":1,"probes":{"positions":[[0,0,1]]}})";
    test::write_bytes(dir + "/dark.json", std::vector<std::uint8_t>(dark.begin(), dark.end()));
    const auto z = test::run_zhc({"bake", dir + "/dark.json", "-o", dir + "/dark_out.json"});
    ASSERT_EQ(z.exit_code, 0) << z.err;
    EXPECT_NE(z.err.find("warning: " + dir + "/dark.json: every probe is zero"), std::string::npos) << z.err;
}

}  // namespace
}  // namespace zhc
