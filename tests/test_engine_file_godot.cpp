// godot_lightmap_gi (formats/engines/godot_tres.cpp): Godot 4 LightmapGIData probe data as a text
// resource. The round trip against the godot_l2 codec entry; a twin of Godot's capture written here
// from Godot's code (the BSP walk and barycentric blend of light_storage.cpp
// LightStorage::lightmap_tap_sh_light, the SH evaluation of scene_forward_clustered.glsl's lightmap
// capture), reading the numbers straight from the written text, against zhc's tetrahedral
// irradiance of the same probes; the BSP against a brute-force search; hostile files; determinism.
//
// Godot itself is not installable here: Debian packages Godot 3 only (godot3), whose LightmapGIData
// does not exist (Godot 3 has BakedLightmapData), so no test runs Godot.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "codec/probe/probe_set.h"
#include "formats/engines/engine_files.h"
#include "formats/probes/tetra.h"
#include "support.h"

namespace zhc {
namespace {

const EngineFile& godot() {
    const EngineFile* f = find_engine_file("godot_lightmap_gi");
    EXPECT_NE(f, nullptr);
    return *f;
}

// Probes with a dominant ambient term and random directional content (irradiance stays positive).
std::vector<Sh3Radiance> random_hub(std::size_t n, unsigned seed) {
    test::Rng rng(seed);
    std::vector<Sh3Radiance> hub(n);
    for (auto& p : hub)
        for (int i = 0; i < 9; ++i)
            for (int c = 0; c < 3; ++c)
                p[i][c] = static_cast<float>(i == 0 ? 1.0 + rng.u() : (rng.u() - 0.5) * (i < 4 ? 0.8 : 0.4));
    return hub;
}

ProbeLayout grid_layout() {
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kGrid;
    l.grid.origin = {-1.5, 0.25, 2.0};
    l.grid.spacing = {1.0, 0.75, 1.25};
    l.grid.counts = {4, 3, 3};
    return l;
}

ProbeLayout points_layout(std::size_t n, unsigned seed) {
    test::Rng rng(seed);
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kPositions;
    for (std::size_t i = 0; i < n; ++i) {
        const float x = static_cast<float>(rng.u() * 6 - 3);
        const float y = static_cast<float>(rng.u() * 4 - 1);
        const float z = static_cast<float>(rng.u() * 3);
        l.positions.push_back({x, y, z});
    }
    return l;
}

std::vector<std::array<float, 3>> positions_of(const ProbeLayout& l) {
    if (l.kind == ProbeLayoutKind::kPositions) return l.positions;
    std::vector<std::array<float, 3>> p;
    const auto& g = l.grid;
    for (std::uint32_t z = 0; z < g.counts[2]; ++z)
        for (std::uint32_t y = 0; y < g.counts[1]; ++y)
            for (std::uint32_t x = 0; x < g.counts[0]; ++x)
                p.push_back({static_cast<float>(g.origin.x + x * g.spacing.x), static_cast<float>(g.origin.y + y * g.spacing.y),
                             static_cast<float>(g.origin.z + z * g.spacing.z)});
    return p;
}

std::string text_of(const std::vector<std::uint8_t>& b) { return std::string(b.begin(), b.end()); }
std::vector<std::uint8_t> bytes_of(const std::string& s) { return std::vector<std::uint8_t>(s.begin(), s.end()); }

// ---- the file's numbers, read here independently of the reader -------------------------------

// The numbers of `"key": Ctor(...)` in the text (strtod on each comma-separated field).
std::vector<double> numbers_of(const std::string& text, const std::string& key, const std::string& ctor) {
    const std::string head = "\"" + key + "\": " + ctor + "(";
    const std::size_t at = text.find(head);
    EXPECT_NE(at, std::string::npos) << head;
    std::vector<double> out;
    if (at == std::string::npos) return out;
    const char* p = text.c_str() + at + head.size();
    while (*p != ')') {
        char* end = nullptr;
        out.push_back(std::strtod(p, &end));
        EXPECT_NE(end, p);
        if (end == p) return out;
        p = end;
        if (*p == ',') p += 2;
    }
    return out;
}

struct GodotData {
    std::vector<std::array<float, 3>> points;
    std::vector<std::array<float, 4>> sh;  // 9 per point
    std::vector<std::array<std::int32_t, 4>> tetrahedra;
    struct Node {
        float plane[4];
        std::int32_t over, under;
    };
    std::vector<Node> bsp;
};

GodotData parse_text(const std::string& text) {
    GodotData d;
    const auto pts = numbers_of(text, "points", "PackedVector3Array");
    for (std::size_t i = 0; i + 2 < pts.size(); i += 3)
        d.points.push_back({float(pts[i]), float(pts[i + 1]), float(pts[i + 2])});
    const auto sh = numbers_of(text, "sh", "PackedColorArray");
    for (std::size_t i = 0; i + 3 < sh.size(); i += 4) d.sh.push_back({float(sh[i]), float(sh[i + 1]), float(sh[i + 2]), float(sh[i + 3])});
    const auto tets = numbers_of(text, "tetrahedra", "PackedInt32Array");
    for (std::size_t i = 0; i + 3 < tets.size(); i += 4)
        d.tetrahedra.push_back({std::int32_t(tets[i]), std::int32_t(tets[i + 1]), std::int32_t(tets[i + 2]), std::int32_t(tets[i + 3])});
    const auto bsp = numbers_of(text, "bsp", "PackedInt32Array");
    for (std::size_t i = 0; i + 5 < bsp.size(); i += 6) {
        GodotData::Node n;
        for (int k = 0; k < 4; ++k) {
            const auto bits = static_cast<std::int32_t>(bsp[i + k]);
            std::memcpy(&n.plane[k], &bits, 4);
        }
        n.over = std::int32_t(bsp[i + 4]);
        n.under = std::int32_t(bsp[i + 5]);
        d.bsp.push_back(n);
    }
    return d;
}

// ---- the twin of Godot's capture (float, as real_t) --------------------------------------------

struct F3 {
    float x, y, z;
};
F3 fsub(F3 a, F3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
float fdot(F3 a, F3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
F3 fcross(F3 a, F3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
F3 f3(const std::array<float, 3>& a) { return {a[0], a[1], a[2]}; }

// The BSP walk of lightmap_tap_sh_light: the tetrahedron index, or -1 for an empty leaf.
int walk(const GodotData& d, F3 p) {
    std::int32_t node = 0;
    int steps = 0;
    while (node >= 0) {
        const auto& n = d.bsp[static_cast<std::size_t>(node)];
        const bool over = n.plane[0] * p.x + n.plane[1] * p.y + n.plane[2] * p.z > n.plane[3];
        node = over ? n.over : n.under;
        if (++steps > 100000) return -2;
    }
    if (node == std::numeric_limits<std::int32_t>::min()) return -1;
    return -node - 1;
}

// Geometry3D::tetrahedron_get_barycentric_coords.
std::array<float, 4> barycentric(F3 a, F3 b, F3 c, F3 d, F3 p) {
    const F3 vap = fsub(p, a), vbp = fsub(p, b), vab = fsub(b, a), vac = fsub(c, a), vad = fsub(d, a), vbc = fsub(c, b),
             vbd = fsub(d, b);
    auto stp = [](F3 x, F3 y, F3 z) { return fdot(x, fcross(y, z)); };
    const float va6 = stp(vbp, vbd, vbc), vb6 = stp(vap, vac, vad), vc6 = stp(vap, vad, vab), vd6 = stp(vap, vab, vac);
    const float v6 = 1 / stp(vab, vac, vad);
    return {va6 * v6, vb6 * v6, vc6 * v6, vd6 * v6};
}

// Godot's capture at p (Godot's axes) and its shader at the normal n (Godot's axes): the blended
// nine colours, then scene_forward_clustered.glsl's lightmap capture formula (the scene shader's
// `INSTANCE_FLAGS_USE_LIGHTMAP_CAPTURE` branch).
bool godot_capture(const GodotData& d, F3 p, F3 n, double out[3], int* tet_out = nullptr) {
    const int t = walk(d, p);
    if (tet_out) *tet_out = t;
    if (t < 0) return false;
    const auto& tet = d.tetrahedra[static_cast<std::size_t>(t)];
    const auto w = barycentric(f3(d.points[tet[0]]), f3(d.points[tet[1]]), f3(d.points[tet[2]]), f3(d.points[tet[3]]), p);
    float sh[9][4] = {};
    for (int i = 0; i < 4; ++i) {
        const float c = std::clamp(w[i], 0.0f, 1.0f);
        for (int j = 0; j < 9; ++j)
            for (int k = 0; k < 4; ++k) sh[j][k] += d.sh[static_cast<std::size_t>(tet[i]) * 9 + j][k] * c;
    }
    // Godot 4.6's form of the polynomial (c[0..4]; earlier 4.x write the same with c1..c5 = 0.429043,
    // 0.511664, 0.743125, 0.886227, 0.247708), times IBL_exposure_normalization (1 without camera
    // attributes).
    const double c[5] = {0.886227, 1.023327, 0.858086, 0.247708, 0.429043};
    const double x = n.x, y = n.y, z = n.z;
    for (int k = 0; k < 3; ++k)
        out[k] = c[0] * sh[0][k] + c[1] * sh[1][k] * y + c[1] * sh[2][k] * z + c[1] * sh[3][k] * x +
                 c[2] * sh[4][k] * x * y + c[2] * sh[5][k] * y * z + c[3] * sh[6][k] * (3.0 * z * z - 1.0) +
                 c[2] * sh[7][k] * x * z + c[4] * sh[8][k] * (x * x - y * y);
    return true;
}

// Godot's axes (glTF's: Y up, right-handed) from zhc's: (x, y, z)_Godot = (y, z, x)_zhc.
F3 to_godot(Vec3 v) { return {float(v.y), float(v.z), float(v.x)}; }

// zhc's tetrahedral irradiance: the tetrahedron containing p (brute force, double), barycentric
// blend of the probes, irradiance(). false outside every tetrahedron.
bool zhc_irradiance(const std::vector<std::array<float, 3>>& pos, const std::vector<std::array<std::uint32_t, 4>>& tets,
                    const std::vector<Sh3Radiance>& hub, Vec3 p, Vec3 n, double out[3]) {
    for (const auto& t : tets) {
        Vec3 v[4];
        for (int i = 0; i < 4; ++i) v[i] = {pos[t[i]][0], pos[t[i]][1], pos[t[i]][2]};
        auto det = [](Vec3 a, Vec3 b, Vec3 c) {
            return a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
        };
        const double all = det(v[1] - v[0], v[2] - v[0], v[3] - v[0]);
        if (std::abs(all) < 1e-12) continue;
        double w[4];
        w[1] = det(p - v[0], v[2] - v[0], v[3] - v[0]) / all;
        w[2] = det(v[1] - v[0], p - v[0], v[3] - v[0]) / all;
        w[3] = det(v[1] - v[0], v[2] - v[0], p - v[0]) / all;
        w[0] = 1 - w[1] - w[2] - w[3];
        if (std::min({w[0], w[1], w[2], w[3]}) < -1e-9) continue;
        Sh3Radiance blend;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 9; ++j)
                for (int c = 0; c < 3; ++c) blend[j][c] += static_cast<float>(w[i] * hub[t[i]][j][c]);
        const Rgb e = irradiance(blend, n);
        for (int c = 0; c < 3; ++c) out[c] = e[c];
        return true;
    }
    return false;
}

// A random point inside the tetrahedra (a random tetrahedron, random barycentric weights).
Vec3 random_inside(const std::vector<std::array<float, 3>>& pos, const std::vector<std::array<std::uint32_t, 4>>& tets,
                   test::Rng& rng) {
    const auto& t = tets[static_cast<std::size_t>(rng.u() * tets.size()) % tets.size()];
    double w[4], s = 0;
    for (double& x : w) {
        x = -std::log(1 - rng.u());
        s += x;
    }
    Vec3 p;
    for (int i = 0; i < 4; ++i) p = p + (w[i] / s) * Vec3{pos[t[i]][0], pos[t[i]][1], pos[t[i]][2]};
    return p;
}

// ---- tests -------------------------------------------------------------------------------------

struct Case {
    const char* name;
    ProbeLayout layout;
    std::vector<Sh3Radiance> hub;
};
std::vector<Case> cases() {
    std::vector<Case> c;
    c.push_back({"grid", grid_layout(), random_hub(36, 11)});
    c.push_back({"points", points_layout(40, 12), random_hub(40, 13)});
    return c;
}

TEST(EngineFileGodot, Registered) {
    const EngineFile& f = godot();
    EXPECT_EQ(f.extension, ".tres");
    EXPECT_EQ(f.layout_codec, "godot_l2");
    EXPECT_EQ(sniff_engine_file(bytes_of("[gd_resource type=\"LightmapGIData\" format=3]\n")), &f);
    EXPECT_EQ(sniff_engine_file(bytes_of("[gd_resource type=\"Mesh\" format=3]\n")), nullptr);
    EXPECT_FALSE(f.sniff(bytes_of("[gd_scene format=3]\n")));
}

TEST(EngineFileGodot, RoundTripEqualsCodecEntry) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name);
        EngineFileInput in;
        in.hub = c.hub;
        in.layout = c.layout;
        auto w = godot().write(in);
        ASSERT_TRUE(w) << w.error().message;
        auto r = godot().read(w->bytes, "out.tres");
        ASSERT_TRUE(r) << r.error().message;
        auto expect = round_trip_probes(c.hub, "godot_l2", CodecOptions{}, c.layout);
        ASSERT_TRUE(expect);
        ASSERT_EQ(r->hub.size(), expect->size());
        double worst = 0;
        for (std::size_t i = 0; i < expect->size(); ++i)
            worst = std::max(worst, test::max_abs_diff(r->hub[i], (*expect)[i]) / test::max_abs((*expect)[i]));
        // Every float is written as the shortest text that reads back to it: the probes come back
        // as the codec entry stores them, to the float.
        EXPECT_LE(worst, 1e-6);
        std::printf("[ measure ] %s: round trip vs round_trip_probes(godot_l2): max relative difference %.3g\n", c.name, worst);
        // Positions: Godot's axes there and back, exactly.
        const auto pos = positions_of(c.layout);
        ASSERT_EQ(r->layout.kind, ProbeLayoutKind::kPositions);
        ASSERT_EQ(r->layout.positions.size(), pos.size());
        for (std::size_t i = 0; i < pos.size(); ++i)
            for (int k = 0; k < 3; ++k) EXPECT_EQ(r->layout.positions[i][k], pos[i][k]) << i;
        // The file is in Godot's axes: zhc's +Z (up) is Godot's +Y.
        const GodotData d = parse_text(text_of(w->bytes));
        ASSERT_EQ(d.points.size(), pos.size());
        for (std::size_t i = 0; i < pos.size(); ++i) {
            EXPECT_EQ(d.points[i][0], pos[i][1]);
            EXPECT_EQ(d.points[i][1], pos[i][2]);
            EXPECT_EQ(d.points[i][2], pos[i][0]);
        }
    }
}

TEST(EngineFileGodot, GodotCaptureTwinMatchesZhcTetrahedralIrradiance) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name);
        EngineFileInput in;
        in.hub = c.hub;
        in.layout = c.layout;
        auto w = godot().write(in);
        ASSERT_TRUE(w) << w.error().message;
        const GodotData d = parse_text(text_of(w->bytes));
        ASSERT_EQ(d.sh.size(), d.points.size() * 9);
        ASSERT_FALSE(d.bsp.empty());
        const auto pos = positions_of(c.layout);
        auto tz = tetrahedralize(pos);
        ASSERT_TRUE(tz);
        auto rt = round_trip_probes(c.hub, "godot_l2", CodecOptions{}, c.layout);
        ASSERT_TRUE(rt);
        test::Rng rng(77);
        const auto normals = test::fibonacci_directions(24);
        double worst = 0;
        int compared = 0;
        for (int s = 0; s < 400; ++s) {
            const Vec3 p = random_inside(pos, tz->tetrahedra, rng);
            for (const Vec3& n : normals) {
                double g[3], z[3];
                ASSERT_TRUE(godot_capture(d, to_godot(p), to_godot(n), g)) << "Godot's walk found no tetrahedron";
                ASSERT_TRUE(zhc_irradiance(pos, tz->tetrahedra, *rt, p, n, z));
                const double scale = std::max({std::abs(z[0]), std::abs(z[1]), std::abs(z[2])});
                for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(g[k] - z[k]) / scale);
                ++compared;
            }
        }
        EXPECT_LE(worst, 1e-4);
        std::printf("[ measure ] %s: Godot capture twin vs zhc tetrahedral irradiance, %d samples: max relative "
                    "difference %.3g\n",
                    c.name, compared, worst);
    }
}

TEST(EngineFileGodot, BspFindsTheContainingTetrahedron) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name);
        EngineFileInput in;
        in.hub = c.hub;
        in.layout = c.layout;
        auto w = godot().write(in);
        ASSERT_TRUE(w);
        const GodotData d = parse_text(text_of(w->bytes));
        // Every child comes after its node (the walk's debug check), leaves name real tetrahedra.
        for (std::size_t i = 0; i < d.bsp.size(); ++i)
            for (std::int32_t ch : {d.bsp[i].over, d.bsp[i].under}) {
                if (ch >= 0) {
                    EXPECT_GT(static_cast<std::size_t>(ch), i);
                } else if (ch != std::numeric_limits<std::int32_t>::min()) {
                    EXPECT_LT(static_cast<std::size_t>(-ch - 1), d.tetrahedra.size());
                }
            }
        test::Rng rng(5);
        F3 lo = f3(d.points[0]), hi = lo;
        for (const auto& p : d.points) {
            lo = {std::min(lo.x, p[0]), std::min(lo.y, p[1]), std::min(lo.z, p[2])};
            hi = {std::max(hi.x, p[0]), std::max(hi.y, p[1]), std::max(hi.z, p[2])};
        }
        int inside = 0;
        for (int s = 0; s < 3000; ++s) {
            const F3 p{static_cast<float>(lo.x + rng.u() * (hi.x - lo.x)), static_cast<float>(lo.y + rng.u() * (hi.y - lo.y)),
                       static_cast<float>(lo.z + rng.u() * (hi.z - lo.z))};
            // Brute force: every tetrahedron whose barycentric weights (double) are all >= -1e-6.
            std::vector<int> containing;
            for (std::size_t t = 0; t < d.tetrahedra.size(); ++t) {
                const auto& tet = d.tetrahedra[t];
                Vec3 v[4];
                for (int i = 0; i < 4; ++i) {
                    const auto& q = d.points[static_cast<std::size_t>(tet[i])];
                    v[i] = {q[0], q[1], q[2]};
                }
                auto det = [](Vec3 a, Vec3 b, Vec3 cc) {
                    return a.x * (b.y * cc.z - b.z * cc.y) - a.y * (b.x * cc.z - b.z * cc.x) + a.z * (b.x * cc.y - b.y * cc.x);
                };
                const Vec3 pp{p.x, p.y, p.z};
                const double all = det(v[1] - v[0], v[2] - v[0], v[3] - v[0]);
                const double w1 = det(pp - v[0], v[2] - v[0], v[3] - v[0]) / all;
                const double w2 = det(v[1] - v[0], pp - v[0], v[3] - v[0]) / all;
                const double w3 = det(v[1] - v[0], v[2] - v[0], pp - v[0]) / all;
                if (std::min({1 - w1 - w2 - w3, w1, w2, w3}) >= -1e-6) containing.push_back(static_cast<int>(t));
            }
            const int found = walk(d, p);
            ASSERT_NE(found, -2) << "the walk does not end";
            if (containing.empty()) continue;  // outside the hull: Godot clamps whatever it finds
            ++inside;
            EXPECT_NE(std::find(containing.begin(), containing.end(), found), containing.end())
                << "point " << p.x << " " << p.y << " " << p.z << ": BSP gives " << found << ", brute force " << containing[0];
        }
        EXPECT_GT(inside, 300);
        std::printf("[ measure ] %s: %zu tetrahedra, %zu BSP nodes, %d points inside checked\n", c.name, d.tetrahedra.size(),
                    d.bsp.size(), inside);
    }
}

TEST(EngineFileGodot, GivenTetrahedraAreKept) {
    const ProbeLayout layout = points_layout(25, 21);
    const auto hub = random_hub(25, 22);
    auto tz = tetrahedralize(layout.positions);
    ASSERT_TRUE(tz);
    // The input's own tetrahedra (vertex order rotated) are written as given.
    std::vector<std::array<std::uint32_t, 4>> tets = tz->tetrahedra;
    for (auto& t : tets) std::rotate(t.begin(), t.begin() + 1, t.end());
    EngineFileInput in;
    in.hub = hub;
    in.layout = layout;
    in.tetrahedra = tets;
    auto w = godot().write(in);
    ASSERT_TRUE(w) << w.error().message;
    const GodotData d = parse_text(text_of(w->bytes));
    ASSERT_EQ(d.tetrahedra.size(), tets.size());
    for (std::size_t t = 0; t < tets.size(); ++t)
        for (int j = 0; j < 4; ++j) EXPECT_EQ(static_cast<std::uint32_t>(d.tetrahedra[t][j]), tets[t][j]);
    // and Godot's capture over them still matches zhc's tetrahedral irradiance.
    auto rt = round_trip_probes(hub, "godot_l2", CodecOptions{}, layout);
    ASSERT_TRUE(rt);
    test::Rng rng(3);
    for (int s = 0; s < 200; ++s) {
        const Vec3 p = random_inside(layout.positions, tz->tetrahedra, rng);
        const Vec3 n = rng.dir();
        double g[3], z[3];
        ASSERT_TRUE(godot_capture(d, to_godot(p), to_godot(n), g));
        ASSERT_TRUE(zhc_irradiance(layout.positions, tz->tetrahedra, *rt, p, n, z));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(g[k], z[k], 1e-4 * std::abs(z[k]) + 1e-6);
    }
}

TEST(EngineFileGodot, InvalidProbesAreLeftOut) {
    const ProbeLayout layout = grid_layout();
    const auto hub = random_hub(36, 31);
    std::vector<std::uint8_t> validity(36, 1);
    validity[5] = validity[17] = 0;  // two interior probes
    EngineFileInput in;
    in.hub = hub;
    in.layout = layout;
    in.validity = validity;
    auto w = godot().write(in);
    ASSERT_TRUE(w) << w.error().message;
    EXPECT_FALSE(w->notes.empty());
    auto r = godot().read(w->bytes, "v.tres");
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->hub.size(), 34u);
    const auto pos = positions_of(layout);
    auto rt = round_trip_probes(hub, "godot_l2", CodecOptions{}, layout);
    ASSERT_TRUE(rt);
    std::size_t k = 0;
    for (std::size_t i = 0; i < 36; ++i) {
        if (!validity[i]) continue;
        EXPECT_EQ(r->layout.positions[k], pos[i]);
        EXPECT_EQ(r->hub[k], (*rt)[i]);
        ++k;
    }
    const GodotData d = parse_text(text_of(w->bytes));
    for (const auto& t : d.tetrahedra)
        for (std::int32_t v : t) EXPECT_LT(v, 34);
}

TEST(EngineFileGodot, Deterministic) {
    for (const Case& c : cases()) {
        EngineFileInput in;
        in.hub = c.hub;
        in.layout = c.layout;
        auto a = godot().write(in);
        auto b = godot().write(in);
        ASSERT_TRUE(a && b);
        EXPECT_EQ(a->bytes, b->bytes);
        // Godot's layout of the text: header, [resource], the sorted keys of probe_data.
        const std::string t = text_of(a->bytes);
        EXPECT_EQ(t.rfind("[gd_resource type=\"LightmapGIData\" format=3]\n\n[resource]\nprobe_data = {\n\"baked_exposure\": 1.0,\n"
                          "\"bounds\": AABB(",
                          0),
                  0u);
        std::size_t last = 0;
        for (const char* k : {"\"bounds\"", "\"bsp\"", "\"interior\"", "\"points\"", "\"sh\"", "\"tetrahedra\""}) {
            const std::size_t at = t.find(k);
            ASSERT_NE(at, std::string::npos) << k;
            EXPECT_GT(at, last) << k;
            last = at;
        }
    }
}

TEST(EngineFileGodot, RefusesWhatGodotCannotHold) {
    // A flat set (one plane of probes) has no tetrahedra.
    ProbeLayout flat;
    flat.kind = ProbeLayoutKind::kGrid;
    flat.grid.counts = {3, 3, 1};
    const auto hub = random_hub(9, 1);
    EngineFileInput in;
    in.hub = hub;
    in.layout = flat;
    auto w = godot().write(in);
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("godot_lightmap_gi"), std::string::npos);
    ProbeLayout none;
    in.layout = none;
    EXPECT_FALSE(godot().write(in));
}

TEST(EngineFileGodot, OneTetrahedronHasAWalkableTree) {
    // Godot's _compute_bsp_tree builds no node for a single tetrahedron; the file holds one node
    // that sends every point to it.
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kPositions;
    l.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
    const auto hub = random_hub(4, 51);
    EngineFileInput in;
    in.hub = hub;
    in.layout = l;
    auto w = godot().write(in);
    ASSERT_TRUE(w) << w.error().message;
    const GodotData d = parse_text(text_of(w->bytes));
    ASSERT_EQ(d.tetrahedra.size(), 1u);
    ASSERT_EQ(d.bsp.size(), 1u);
    auto rt = round_trip_probes(hub, "godot_l2", CodecOptions{}, l);
    ASSERT_TRUE(rt);
    std::vector<std::array<std::uint32_t, 4>> tets = {{static_cast<std::uint32_t>(d.tetrahedra[0][0]),
                                                        static_cast<std::uint32_t>(d.tetrahedra[0][1]),
                                                        static_cast<std::uint32_t>(d.tetrahedra[0][2]),
                                                        static_cast<std::uint32_t>(d.tetrahedra[0][3])}};
    test::Rng rng(9);
    for (int s = 0; s < 100; ++s) {
        const Vec3 p = random_inside(l.positions, tets, rng);
        const Vec3 n = rng.dir();
        double g[3], z[3];
        ASSERT_TRUE(godot_capture(d, to_godot(p), to_godot(n), g));
        ASSERT_TRUE(zhc_irradiance(l.positions, tets, *rt, p, n, z));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(g[k], z[k], 1e-4 * std::abs(z[k]) + 1e-6);
    }
}

// ---- hostile files -----------------------------------------------------------------------------

std::string small_file() {
    ProbeLayout l = points_layout(6, 41);
    static const auto hub = random_hub(6, 42);
    EngineFileInput in;
    in.hub = hub;
    in.layout = l;
    auto w = godot().write(in);
    EXPECT_TRUE(w);
    return w ? text_of(w->bytes) : std::string();
}

std::string replace_value(std::string t, const std::string& key, const std::string& value) {
    const std::string head = "\"" + key + "\": ";
    const std::size_t at = t.find(head);
    EXPECT_NE(at, std::string::npos);
    std::size_t end = t.find('\n', at);
    if (t[end - 1] == ',') --end;
    return t.replace(at + head.size(), end - at - head.size(), value);
}

void expect_error(const std::string& text, const std::string& what, ErrorCode code) {
    auto r = godot().read(bytes_of(text), "bad.tres");
    ASSERT_FALSE(r) << what;
    EXPECT_EQ(r.error().code, code) << what << ": " << r.error().message;
    EXPECT_EQ(r.error().message.rfind("bad.tres: ", 0), 0u) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("(line "), std::string::npos) << r.error().message;
}

TEST(EngineFileGodot, OtherPropertiesAndSectionsAreSkipped) {
    const std::string base = small_file();
    auto plain = godot().read(bytes_of(base), "a.tres");
    ASSERT_TRUE(plain) << plain.error().message;
    // What Godot's own saver writes beside probe_data (4.6's LightmapGIData properties, an external
    // texture, a sub-resource).
    std::string t = base;
    t.replace(0, t.find("\n\n[resource]"),
              "[gd_resource type=\"LightmapGIData\" load_steps=3 format=3 uid=\"uid://b1x2y3z4\"]\n\n"
              "[ext_resource type=\"CompressedTexture2DArray\" uid=\"uid://c5\" path=\"res://lm.exr\" id=\"1_ab\"]\n\n"
              "[sub_resource type=\"Resource\" id=\"Resource_x\"]\nresource_name = \"a = b\"\nmetadata/x = {\n\"k\": [1, 2.5, -inf, nan]\n}");
    const std::size_t at = t.find("probe_data = ");
    t.insert(at, "lightmap_textures = Array[TextureLayered]([ExtResource(\"1_ab\")])\nuses_spherical_harmonics = true\n"
                 "user_data = [NodePath(\"Floor\"), Rect2(0, 0, 1, 1), 0, -1, &\"name\", SubResource(\"Resource_x\")]\n"
                 "_uses_packed_directional = true\n");
    auto r = godot().read(bytes_of(t), "b.tres");
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->hub.size(), plain->hub.size());
    for (std::size_t i = 0; i < r->hub.size(); ++i) EXPECT_EQ(r->hub[i], plain->hub[i]);
    // A large property beside probe_data (parsed, not stored), and keys probe_data does not need.
    std::string big = base;
    std::string zeros = "metadata/big = [";
    for (int i = 0; i < 200000; ++i) zeros += i ? ", 0" : "0";
    big.insert(big.find("probe_data = "), zeros + "]\n");
    big.insert(big.find("\"points\""), "\"extra\": {\"a\": [1, 2], 3: PackedInt32Array(1)},\n");
    auto r3 = godot().read(bytes_of(big), "big.tres");
    ASSERT_TRUE(r3) << r3.error().message;
    EXPECT_EQ(r3->hub.size(), plain->hub.size());
    // Keys in another order, a lightprobe_hash (4.4+), an exposure other than 1 (noted).
    std::string u = base;
    u = replace_value(u, "baked_exposure", "0.5");
    u.insert(u.find("\"points\""), "\"lightprobe_hash\": 12345,\n");
    auto r2 = godot().read(bytes_of(u), "c.tres");
    ASSERT_TRUE(r2) << r2.error().message;
    EXPECT_FALSE(r2->notes.empty());
}

TEST(EngineFileGodot, HostileFilesGiveErrors) {
    const std::string base = small_file();
    ASSERT_TRUE(godot().read(bytes_of(base), "ok.tres"));
    // Every truncation before the dictionary closes.
    const std::size_t close = base.rfind('}');
    for (std::size_t cut = 0; cut <= close; cut += (cut < 200 ? 1 : 37)) {
        auto r = godot().read(bytes_of(base.substr(0, cut)), "cut.tres");
        EXPECT_FALSE(r) << "cut at " << cut;
    }
    expect_error("[gd_resource type=\"LightmapGIData\" format=2]\n\n[resource]\n", "Godot 3's format", ErrorCode::kUnsupported);
    expect_error("[gd_resource type=\"Mesh\" format=3]\n\n[resource]\n", "another type", ErrorCode::kBadFormat);
    expect_error("[gd_resource type=\"LightmapGIData\" format=3]\n\n[resource]\n", "no probe_data", ErrorCode::kBadFormat);
    expect_error(replace_value(base, "points", "PackedInt32Array(1, 2, 3)"), "points of the wrong type", ErrorCode::kBadFormat);
    expect_error(replace_value(base, "interior", "5"), "interior not a bool", ErrorCode::kBadFormat);
    expect_error(replace_value(base, "bounds", "AABB(0, 0, 0)"), "short AABB", ErrorCode::kBadFormat);
    expect_error(replace_value(base, "sh", "PackedColorArray(1, 2, 3, 4)"), "sh count", ErrorCode::kBadFormat);
    expect_error(replace_value(base, "tetrahedra", "PackedInt32Array(0, 1, 2, 999999)"), "tetrahedron out of range",
                 ErrorCode::kBadFormat);
    expect_error(replace_value(base, "tetrahedra", "PackedInt32Array(0, 1, 2)"), "partial tetrahedron", ErrorCode::kBadFormat);
    expect_error(replace_value(base, "tetrahedra", "PackedInt32Array(0, 1, 2, 99999999999999999999)"), "integer overflow",
                 ErrorCode::kInvalidValue);
    // A BSP node pointing back to itself (the walk would never end), and one naming a missing tetrahedron.
    expect_error(replace_value(base, "bsp", "PackedInt32Array(0, 0, 0, 0, 0, -1)"), "BSP loop", ErrorCode::kBadFormat);
    expect_error(replace_value(base, "bsp", "PackedInt32Array(0, 0, 0, 0, -1000, -1)"), "BSP leaf out of range",
                 ErrorCode::kBadFormat);
    expect_error(replace_value(base, "bsp", "PackedInt32Array(2143289344, 0, 0, 0, -1, -1)"), "NaN plane",
                 ErrorCode::kInvalidValue);
    // NaN and infinities in the probes.
    std::string nan_sh = base;
    const std::size_t sh_at = nan_sh.find("\"sh\": PackedColorArray(") + 23;
    nan_sh.replace(sh_at, nan_sh.find(',', sh_at) - sh_at, "nan");
    expect_error(nan_sh, "NaN in sh", ErrorCode::kInvalidValue);
    std::string inf_pt = base;
    const std::size_t pt_at = inf_pt.find("\"points\": PackedVector3Array(") + 29;
    inf_pt.replace(pt_at, inf_pt.find(',', pt_at) - pt_at, "inf");
    expect_error(inf_pt, "inf in points", ErrorCode::kInvalidValue);
    expect_error(replace_value(base, "baked_exposure", "nan"), "NaN exposure", ErrorCode::kInvalidValue);
    // Nesting bomb in a skipped property: refused, no stack overflow.
    std::string bomb = base;
    bomb.insert(bomb.find("probe_data = "), "user_data = " + std::string(100000, '[') + std::string(100000, ']') + "\n");
    expect_error(bomb, "nesting bomb", ErrorCode::kTooLarge);
    // A key twice, a line that is not an assignment, garbage bytes.
    std::string twice = base;
    twice.insert(twice.find("\"points\""), "\"bsp\": PackedInt32Array(),\n");
    expect_error(twice, "key twice", ErrorCode::kBadFormat);
    std::string junk = base;
    junk.insert(junk.find("probe_data = "), "this is not an assignment\n");
    expect_error(junk, "junk line", ErrorCode::kBadFormat);
    std::string binary = base;
    binary.insert(binary.find("\"points\""), std::string("\x01\xff\x00\x7f", 4));
    expect_error(binary, "binary bytes", ErrorCode::kBadFormat);
    EXPECT_FALSE(godot().read({}, "empty.tres"));
}

TEST(EngineFileGodot, RandomByteChangesNeverCrash) {
    // Random bytes replaced (printable and not): the reader answers every file, with probes that
    // agree with their layout or with a one-line error.
    const std::string base = small_file();
    test::Rng rng(99);
    int errors = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        std::string t = base;
        const int edits = 1 + static_cast<int>(rng.u() * 4);
        for (int e = 0; e < edits; ++e) {
            const std::size_t at = static_cast<std::size_t>(rng.u() * t.size()) % t.size();
            const char* pool = "0123456789-.,()[]{}:=\"e \nnainf\x01\xff";
            t[at] = pool[static_cast<std::size_t>(rng.u() * 32) % 32];
        }
        auto r = godot().read(bytes_of(t), "flip.tres");
        if (r) {
            EXPECT_EQ(r->hub.size(), r->layout.positions.size());
        } else {
            ++errors;
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << r.error().message;
        }
    }
    EXPECT_GT(errors, 1000);
}

}  // namespace
}  // namespace zhc
