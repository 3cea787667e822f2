// Tetrahedral interpolation of scattered probes in runtime/zhc_runtime.h (zhc_volume_from_zhp on a
// `points` .zhp, zhc_volume_tetra_weights, zhc_volume_sh3 / zhc_volume_irradiance), against a
// brute-force twin written here from the spec (docs/runtime.md "Scattered probes (`points`
// layout)"): for every tetrahedron the barycentric coordinates of the point by Gaussian elimination
// in double, the first that contains it; outside every one, the nearest point of the hull faces (the
// faces of exactly one tetrahedron) by exhaustive search with the region-by-region closest point
// of a triangle; validity applied as for grids. Checked:
//  * random sets, points inside and outside the hull, with and without validity: within 1e-6;
//  * any affine field stored at the probes is reproduced to 1e-9 inside the hull (random sets and a
//    lattice with flat tetrahedra, also on the lattice's planes) and continuous across the hull;
//  * the walk's start does not change the result (beyond rounding), nor the number of calls;
//  * degenerate sets: exactly 4 probes (inside, beyond faces, edges and corners), duplicates (the
//    first probe is the one sampled), coplanar (no volume: ZHC_ERR_NOT_GRID);
//  * a scattered set from a real scene: zhc bake of tests/data/leak_room.json with probes at 48
//    seeded positions inside the room, against the twin, and the C99 sampler (zhc_volume_sample)
//    giving the same floats as this translation unit;
//  * zhc_volume_init_points refusing bad arguments.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "codec/probe/probe_set.h"
#include "formats/probes/probe_file.h"
#include "formats/probes/tetra.h"
#include "runtime/zhc_runtime.h"
#include "support.h"

namespace zhc {
namespace {

using Pos = std::array<float, 3>;
using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// ---- the twin -------------------------------------------------------------------------------

struct Twin {
    std::vector<V3> pos;
    std::vector<std::array<std::uint32_t, 4>> tets;
    std::vector<std::uint8_t> validity;
    std::vector<std::array<double, 27>> sh;  // decoded probes
    std::vector<std::array<std::uint32_t, 3>> hull;  // faces of exactly one tetrahedron (hull_faces)
};

// The faces that belong to one tetrahedron only: the convex hull's.
void hull_faces(Twin& tw) {
    std::map<std::array<std::uint32_t, 3>, int> faces;
    for (const auto& t : tw.tets)
        for (int j = 0; j < 4; ++j) {
            std::array<std::uint32_t, 3> f;
            int n = 0;
            for (int k = 0; k < 4; ++k)
                if (k != j) f[size_t(n++)] = t[size_t(k)];
            std::sort(f.begin(), f.end());
            ++faces[f];
        }
    tw.hull.clear();
    for (const auto& [f, uses] : faces)
        if (uses == 1) tw.hull.push_back(f);
}

// Barycentric coordinates of p in tetrahedron (a, b, c, d): solve [b-a c-a d-a] x = p - a by
// Gaussian elimination with partial pivoting; false for a (near) flat tetrahedron.
bool barycentric(const V3& a, const V3& b, const V3& c, const V3& d, const V3& p, double w[4]) {
    double m[3][4];
    const V3 e[3] = {sub(b, a), sub(c, a), sub(d, a)};
    const V3 r = sub(p, a);
    double scale = 0;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m[i][j] = e[j][size_t(i)];
        m[i][3] = r[size_t(i)];
        scale = std::max(scale, dot(e[i], e[i]));
    }
    double det = 1;
    for (int col = 0; col < 3; ++col) {
        int piv = col;
        for (int i = col + 1; i < 3; ++i)
            if (std::abs(m[i][col]) > std::abs(m[piv][col])) piv = i;
        if (piv != col)
            for (int j = 0; j < 4; ++j) std::swap(m[piv][j], m[col][j]);
        det *= m[col][col];
        if (m[col][col] == 0) return false;
        for (int i = col + 1; i < 3; ++i) {
            const double f = m[i][col] / m[col][col];
            for (int j = col; j < 4; ++j) m[i][j] -= f * m[col][j];
        }
    }
    if (std::abs(det) <= 1e-12 * scale * std::sqrt(scale)) return false;
    double x[3];
    for (int i = 2; i >= 0; --i) {
        double s = m[i][3];
        for (int j = i + 1; j < 3; ++j) s -= m[i][j] * x[j];
        x[i] = s / m[i][i];
    }
    w[0] = 1 - x[0] - x[1] - x[2];
    w[1] = x[0];
    w[2] = x[1];
    w[3] = x[2];
    return true;
}

// Closest point of triangle (a, b, c) to p by Voronoi regions (vertex, edge, face): barycentric
// weights and squared distance.
double closest_on_triangle(const V3& p, const V3& a, const V3& b, const V3& c, double w[3]) {
    const V3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    auto at = [&](double u, double v, double t) {
        w[0] = u, w[1] = v, w[2] = t;
        V3 q;
        for (int k = 0; k < 3; ++k) q[size_t(k)] = u * a[size_t(k)] + v * b[size_t(k)] + t * c[size_t(k)] - p[size_t(k)];
        return dot(q, q);
    };
    if (d1 <= 0 && d2 <= 0) return at(1, 0, 0);
    const V3 bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return at(0, 1, 0);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double v = d1 / (d1 - d3);
        return at(1 - v, v, 0);
    }
    const V3 cp = sub(p, c);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return at(0, 0, 1);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double t = d2 / (d2 - d6);
        return at(1 - t, 0, t);
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(0, 1 - t, t);
    }
    const double den = 1 / (va + vb + vc);
    const double v = vb * den, t = vc * den;
    return at(1 - v - t, v, t);
}

struct TwinResult {
    bool inside = false;
    std::array<std::uint32_t, 4> probes{};
    std::array<double, 4> w{};
};

TwinResult twin_weights(const Twin& tw, const V3& p) {
    TwinResult r;
    for (const auto& t : tw.tets) {
        double w[4];
        if (!barycentric(tw.pos[t[0]], tw.pos[t[1]], tw.pos[t[2]], tw.pos[t[3]], p, w)) continue;
        if (std::min({w[0], w[1], w[2], w[3]}) < -1e-12) continue;
        r.inside = true;
        r.probes = t;
        for (int k = 0; k < 4; ++k) r.w[size_t(k)] = std::max(0.0, w[k]);
        break;
    }
    if (!r.inside) {
        double best = INFINITY;
        for (const auto& f : tw.hull) {
            double w[3];
            const double d = closest_on_triangle(p, tw.pos[f[0]], tw.pos[f[1]], tw.pos[f[2]], w);
            if (d < best) {
                best = d;
                r.probes = {f[0], f[1], f[2], f[0]};
                r.w = {w[0], w[1], w[2], 0};
            }
        }
    }
    if (!tw.validity.empty()) {
        double kept[4], sum = 0;
        for (int k = 0; k < 4; ++k) {
            kept[k] = r.w[size_t(k)] > 0 && tw.validity[r.probes[size_t(k)]] ? r.w[size_t(k)] : 0;
            sum += kept[k];
        }
        if (sum > 0)
            for (int k = 0; k < 4; ++k) r.w[size_t(k)] = kept[k] / sum;
    }
    return r;
}

std::array<double, 27> twin_sh3(const Twin& tw, const V3& p, bool* inside = nullptr) {
    const TwinResult r = twin_weights(tw, p);
    if (inside) *inside = r.inside;
    std::array<double, 27> out{};
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < 27; ++i) out[size_t(i)] += r.w[size_t(k)] * tw.sh[r.probes[size_t(k)]][size_t(i)];
    return out;
}

// ---- sets ---------------------------------------------------------------------------------

struct Volume {
    std::vector<std::uint8_t> bytes;
    zhc_volume v{};
    Twin twin;
};

// A `points` .zhp of float SH3 (sh3) probes: hub[i] at p[i]; the twin from the same set. qt: with
// qhull's Qt triangulation (flat tetrahedra where sites are cospherical) instead of zhc's.
Volume make_volume(const std::vector<Pos>& p, const std::vector<Sh3Radiance>& hub, const std::vector<std::uint8_t>& validity = {},
                   bool qt = false) {
    Volume out;
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kPositions;
    layout.positions = p;
    auto set = encode_probe_set(hub, "sh3", {}, layout);
    EXPECT_TRUE(set.ok());
    auto tz = tetrahedralize(p, qt);
    EXPECT_TRUE(tz.ok());
    set->tetrahedra = tz->tetrahedra;
    set->tetra_neighbours = tz->neighbours;
    EXPECT_FALSE(set->tetrahedra.empty());
    set->validity = validity;
    out.bytes = *serialize_probe_set(*set);
    EXPECT_EQ(zhc_volume_from_zhp(&out.v, out.bytes.data(), out.bytes.size()), ZHC_OK);
    for (const Pos& q : p) out.twin.pos.push_back({q[0], q[1], q[2]});
    out.twin.tets = set->tetrahedra;
    out.twin.validity = validity;
    for (const Sh3Radiance& h : hub) {
        std::array<double, 27> s;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) s[size_t(3 * i + k)] = h[i][k];
        out.twin.sh.push_back(s);
    }
    hull_faces(out.twin);
    return out;
}

std::vector<Sh3Radiance> random_hub(unsigned seed, size_t n) {
    test::Rng rng(seed);
    std::vector<Sh3Radiance> hub(n);
    for (auto& h : hub)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) h[i][k] = float(i == 0 ? 0.5 + rng.u() : rng.u() - 0.5);
    return hub;
}

std::vector<Pos> random_positions(unsigned seed, int n, float scale) {
    test::Rng rng(seed);
    std::vector<Pos> p(static_cast<size_t>(n));
    for (auto& q : p)
        for (auto& c : q) c = float(scale * rng.u());
    return p;
}

double max_diff(const double* a, const std::array<double, 27>& b) {
    double d = 0;
    for (int i = 0; i < 27; ++i) d = std::max(d, std::abs(a[i] - b[size_t(i)]));
    return d;
}

// Compares the header with the twin at n seeded points of the box [lo, hi]; returns how many were
// inside the hull.
int compare_with_twin(const Volume& vol, unsigned seed, int n, V3 lo, V3 hi, const std::string& what) {
    test::Rng rng(seed);
    int inside = 0;
    double worst = 0;
    for (int s = 0; s < n; ++s) {
        V3 p;
        for (size_t c = 0; c < 3; ++c) p[c] = lo[c] + (hi[c] - lo[c]) * rng.u();
        double sh[27];
        zhc_volume_sh3(&vol.v, p.data(), sh);
        bool in = false;
        const auto ref = twin_sh3(vol.twin, p, &in);
        inside += in;
        const double d = max_diff(sh, ref);
        worst = std::max(worst, d);
        EXPECT_LE(d, 1e-6) << what << " sample " << s << " at " << p[0] << " " << p[1] << " " << p[2] << (in ? " inside" : " outside");
        uint32_t t = 0, q[4];
        double w[4];
        EXPECT_EQ(zhc_volume_tetra_weights(&vol.v, p.data(), &t, q, w), in ? 0 : 1) << what << " sample " << s;
    }
    std::printf("%-28s %d samples (%d inside the hull), max |C - twin| %.3g\n", what.c_str(), n, inside, worst);
    return inside;
}

TEST(TetraRuntime, RandomSetsMatchTheBruteForceTwin) {
    for (unsigned seed : {1u, 2u}) {
        const auto p = random_positions(seed, 60, 5.0f);
        const Volume vol = make_volume(p, random_hub(seed + 10, p.size()));
        // Around the set (mostly outside its hull) and within it (mostly inside).
        int inside = compare_with_twin(vol, seed + 20, 2000, {-1.5, -1.5, -1.5}, {6.5, 6.5, 6.5}, "random set " + std::to_string(seed));
        EXPECT_GT(inside, 150);
        EXPECT_LT(inside, 1000);
        inside = compare_with_twin(vol, seed + 40, 2000, {0.5, 0.5, 0.5}, {4.5, 4.5, 4.5}, "random set (core) " + std::to_string(seed));
        EXPECT_GT(inside, 1000);
        // With validity: a fifth of the probes invalid.
        std::vector<std::uint8_t> valid(p.size(), 1);
        for (size_t i = 0; i < valid.size(); i += 5) valid[i] = 0;
        const Volume vv = make_volume(p, random_hub(seed + 10, p.size()), valid);
        ASSERT_NE(vv.v.validity, nullptr);
        compare_with_twin(vv, seed + 30, 2000, {-0.5, -0.5, -0.5}, {5.5, 5.5, 5.5}, "random set + validity " + std::to_string(seed));
    }
}

TEST(TetraRuntime, ValidityDropsInvalidCornersAndFallsBackWhenAllAreInvalid) {
    const std::vector<Pos> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const auto hub = random_hub(3, 4);
    const V3 x = {0.2, 0.3, 0.1};
    {
        const Volume vol = make_volume(p, hub, {1, 0, 1, 1});
        uint32_t t = 0, q[4];
        double w[4];
        ASSERT_EQ(zhc_volume_tetra_weights(&vol.v, x.data(), &t, q, w), 0);
        for (int k = 0; k < 4; ++k) {
            if (q[k] == 1) {
                EXPECT_EQ(w[k], 0.0);
            } else {
                const double plain[4] = {0.4, 0.2, 0.3, 0.1};
                EXPECT_NEAR(w[k], plain[q[k]] / 0.8, 1e-15);
            }
        }
    }
    {
        const Volume vol = make_volume(p, hub, {0, 0, 0, 0});  // none valid: the plain weights
        uint32_t t = 0, q[4];
        double w[4];
        ASSERT_EQ(zhc_volume_tetra_weights(&vol.v, x.data(), &t, q, w), 0);
        const double plain[4] = {0.4, 0.2, 0.3, 0.1};
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(w[k], plain[q[k]], 1e-15);
    }
}

// hub whose coefficient i is a_i + b_i . x at the probe's position: dyadic positions and slopes
// keep every stored float exact.
std::vector<Sh3Radiance> affine_hub(const std::vector<Pos>& p, std::array<std::array<double, 4>, 27>& field) {
    test::Rng rng(77);
    for (auto& f : field)
        for (auto& c : f) c = std::round(16 * (rng.u() - 0.5)) / 8;
    std::vector<Sh3Radiance> hub(p.size());
    for (size_t n = 0; n < p.size(); ++n)
        for (int i = 0; i < 27; ++i) {
            const auto& f = field[size_t(i)];
            hub[n][i / 3][i % 3] = float(f[0] + f[1] * p[n][0] + f[2] * p[n][1] + f[3] * p[n][2]);
            EXPECT_EQ(double(hub[n][i / 3][i % 3]), f[0] + f[1] * p[n][0] + f[2] * p[n][1] + f[3] * p[n][2]);
        }
    return hub;
}

void expect_affine_inside(const Volume& vol, const std::array<std::array<double, 4>, 27>& field, const std::vector<V3>& points,
                          const std::string& what) {
    double worst = 0;
    int inside = 0;
    for (const V3& x : points) {
        bool in = false;
        twin_sh3(vol.twin, x, &in);
        if (!in) continue;
        ++inside;
        double sh[27];
        zhc_volume_sh3(&vol.v, x.data(), sh);
        for (int i = 0; i < 27; ++i) {
            const auto& f = field[size_t(i)];
            const double e = f[0] + f[1] * x[0] + f[2] * x[1] + f[3] * x[2];
            worst = std::max(worst, std::abs(sh[i] - e));
            EXPECT_NEAR(sh[i], e, 1e-9) << what << " at " << x[0] << " " << x[1] << " " << x[2];
        }
    }
    std::printf("%-28s affine field at %d points inside: max error %.3g\n", what.c_str(), inside, worst);
    EXPECT_GT(inside, 0);
}

TEST(TetraRuntime, AffineFieldsAreReproducedInsideTheHull) {
    // Random dyadic positions (multiples of 1/256 in [0, 4]).
    test::Rng rng(5);
    std::vector<Pos> p(80);
    for (auto& q : p)
        for (auto& c : q) c = float(std::floor(1024 * rng.u()) / 256);
    std::array<std::array<double, 4>, 27> field;
    auto hub = affine_hub(p, field);
    const Volume vol = make_volume(p, hub);
    std::vector<V3> pts;
    for (int s = 0; s < 3000; ++s) pts.push_back({4 * rng.u(), 4 * rng.u(), 4 * rng.u()});
    expect_affine_inside(vol, field, pts, "random dyadic set");
    // A lattice: flat tetrahedra everywhere; points anywhere, and on the lattice planes.
    std::vector<Pos> l;
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 5; ++x) l.push_back({0.5f * float(x), 0.5f * float(y), 0.5f * float(z)});
    auto lhub = affine_hub(l, field);
    std::vector<V3> lp;
    for (int s = 0; s < 2000; ++s) lp.push_back({2 * rng.u(), 1.5 * rng.u(), 1 * rng.u()});
    for (int s = 0; s < 1000; ++s) lp.push_back({2 * rng.u(), 1.5 * rng.u(), 0.5 * std::floor(3 * rng.u())});
    for (int s = 0; s < 1000; ++s) lp.push_back({0.5 * std::floor(5 * rng.u()), 1.5 * rng.u(), 1 * rng.u()});
    // zhc's triangulation, and qhull's Qt one whose flat tetrahedra the walk must cross.
    for (bool qt : {false, true}) {
        const Volume lat = make_volume(l, lhub, {}, qt);
        const std::string what = qt ? "lattice (Qt, flat)" : "lattice";
        expect_affine_inside(lat, field, lp, what);
        compare_with_twin(lat, 8, 3000, {-0.5, -0.5, -0.5}, {2.5, 2, 1.5}, what);
        compare_with_twin(lat, 9, 2000, {0.1, 0.1, 0.1}, {1.9, 1.4, 0.9}, what + " (core)");
    }
}

// Random (non-affine) probes on a lattice: across the lattice's planes the blend is continuous with
// zhc's triangulation (neighbouring cubes split their common square the same way); with qhull's Qt
// triangulation it jumps there (the flat tetrahedra between differently split squares).
TEST(TetraRuntime, TheLatticeBlendIsContinuousAcrossItsPlanes) {
    std::vector<Pos> l;
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 4; ++x) l.push_back({float(x), float(y), float(z)});
    const auto hub = random_hub(31, l.size());
    test::Rng rng(32);
    double jump[2] = {0, 0};
    for (bool qt : {false, true}) {
        const Volume lat = make_volume(l, hub, {}, qt);
        for (int s = 0; s < 3000; ++s) {
            // Either side of the plane x = 1, 2 (or y = 1, z = 1), 1e-9 apart.
            V3 a = {0.05 + 2.9 * rng.u(), 0.05 + 1.9 * rng.u(), 0.05 + 1.9 * rng.u()};
            const int axis = s % 3;
            a[size_t(axis)] = axis == 0 ? double(1 + s % 2) : 1.0;
            V3 lo = a, hi = a;
            lo[size_t(axis)] -= 1e-9;
            hi[size_t(axis)] += 1e-9;
            double shl[27], shh[27];
            zhc_volume_sh3(&lat.v, lo.data(), shl);
            zhc_volume_sh3(&lat.v, hi.data(), shh);
            for (int i = 0; i < 27; ++i) jump[qt] = std::max(jump[qt], std::abs(shl[i] - shh[i]));
        }
    }
    std::printf("largest change across a lattice plane (1e-9 apart): zhc %.3g, qhull Qt %.3g\n", jump[0], jump[1]);
    EXPECT_LT(jump[0], 1e-7);
    EXPECT_GT(jump[1], 1e-2);
}

TEST(TetraRuntime, TheWalkStartAndCallOrderDoNotChangeTheResult) {
    const auto p = random_positions(6, 120, 8.0f);
    const Volume vol = make_volume(p, random_hub(6, p.size()));
    test::Rng rng(9);
    for (int s = 0; s < 500; ++s) {
        const V3 x = {-1 + 10 * rng.u(), -1 + 10 * rng.u(), -1 + 10 * rng.u()};
        uint32_t t0 = 0, q0[4];
        double w0[4];
        const int r0 = zhc_volume_tetra_weights(&vol.v, x.data(), &t0, q0, w0);
        uint32_t t1 = uint32_t(rng.u() * vol.v.tetra_count), q1[4];
        double w1[4];
        const int r1 = zhc_volume_tetra_weights(&vol.v, x.data(), &t1, q1, w1);
        EXPECT_EQ(r0, r1) << s;
        // Same point of the same blend: compare as per-probe weights.
        std::map<uint32_t, double> a, b;
        for (int k = 0; k < 4; ++k) a[q0[k]] += w0[k], b[q1[k]] += w1[k];
        for (const auto& [probe, w] : a) {
            if (w > 1e-12) {
                EXPECT_NEAR(b[probe], w, 1e-12) << s << " probe " << probe;
            }
        }
        // Repeated call: bit for bit.
        uint32_t t2 = 0, q2[4];
        double w2[4];
        zhc_volume_tetra_weights(&vol.v, x.data(), &t2, q2, w2);
        EXPECT_EQ(t2, t0);
        EXPECT_EQ(std::memcmp(w2, w0, sizeof w0), 0);
    }
}

TEST(TetraRuntime, FourProbesDuplicatesAndCoplanarSets) {
    // Exactly 4 probes: inside, and beyond each face, edge and corner (the nearest hull point).
    const std::vector<Pos> p = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
    const Volume four = make_volume(p, random_hub(11, 4));
    EXPECT_EQ(four.v.tetra_count, 1u);
    compare_with_twin(four, 12, 3000, {-2, -2, -2}, {4, 4, 4}, "four probes");
    compare_with_twin(four, 13, 1000, {0, 0, 0}, {1, 1, 1}, "four probes (core)");
    {
        // Beyond the corner (2, 0, 0): that probe alone; beyond the face x + y + z = 2: its projection.
        uint32_t t = 0, q[4];
        double w[4];
        const V3 corner = {5, -1, -1};
        EXPECT_EQ(zhc_volume_tetra_weights(&four.v, corner.data(), &t, q, w), 1);
        for (int k = 0; k < 4; ++k) EXPECT_EQ(w[k], q[k] == 1 ? 1.0 : 0.0);
        const V3 face = {1, 1, 1};  // projects to (2/3, 2/3, 2/3)
        EXPECT_EQ(zhc_volume_tetra_weights(&four.v, face.data(), &t, q, w), 1);
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(w[k], q[k] == 0 ? 0.0 : 1.0 / 3, 1e-15);
    }
    // Duplicates: the first probe at a position is the one sampled there.
    auto dp = random_positions(13, 30, 3.0f);
    dp.push_back(dp[4]);
    auto hub = random_hub(14, dp.size());
    const Volume dup = make_volume(dp, hub);
    {
        const V3 at = {dp[4][0], dp[4][1], dp[4][2]};
        double sh[27];
        zhc_volume_sh3(&dup.v, at.data(), sh);
        for (int i = 0; i < 27; ++i) EXPECT_NEAR(sh[i], hub[4][i / 3][i % 3], 1e-12) << i;
        compare_with_twin(dup, 15, 2000, {-0.5, -0.5, -0.5}, {3.5, 3.5, 3.5}, "with a duplicate");
    }
    // Coplanar: no tetrahedra, no volume.
    std::vector<Pos> flat;
    for (int i = 0; i < 16; ++i) flat.push_back({float(i % 4), float(i / 4), 1});
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kPositions;
    layout.positions = flat;
    auto set = encode_probe_set(random_hub(16, 16), "sh3", {}, layout);
    ASSERT_TRUE(set.ok());
    const auto lines = add_tetrahedra(*set);
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_NE(lines[0].find("all 16 probe positions lie in one plane"), std::string::npos) << lines[0];
    const auto bytes = *serialize_probe_set(*set);
    zhc_volume v;
    EXPECT_EQ(zhc_volume_from_zhp(&v, bytes.data(), bytes.size()), ZHC_ERR_NOT_GRID);
    EXPECT_EQ(v.probes, nullptr);
}

TEST(TetraRuntime, OutsideTheHullTheValueIsClampedAndContinuous) {
    const auto p = random_positions(17, 40, 4.0f);
    const Volume vol = make_volume(p, random_hub(17, p.size()));
    // Along random lines through the set, the sampled SH changes by at most L * step (a Lipschitz
    // bound over the segment) between neighbouring points: no jump at the hull.
    test::Rng rng(18);
    int crossings = 0;
    for (int line = 0; line < 50; ++line) {
        V3 a, dir;
        for (auto& c : a) c = 4 * rng.u();
        const Vec3 d = rng.dir();
        dir = {d.x, d.y, d.z};
        double prev[27];
        bool prev_in = true;
        double max_step = 0;
        for (int s = 0; s <= 2000; ++s) {
            const double t = -6 + 12 * s / 2000.0;
            const V3 x = {a[0] + t * dir[0], a[1] + t * dir[1], a[2] + t * dir[2]};
            double sh[27];
            zhc_volume_sh3(&vol.v, x.data(), sh);
            uint32_t tt = 0, q[4];
            double w[4];
            const bool in = zhc_volume_tetra_weights(&vol.v, x.data(), &tt, q, w) == 0;
            if (s > 0) {
                double step = 0;
                for (int i = 0; i < 27; ++i) step = std::max(step, std::abs(sh[i] - prev[i]));
                max_step = std::max(max_step, step);
                crossings += in != prev_in;
            }
            std::memcpy(prev, sh, sizeof sh);
            prev_in = in;
        }
        // Probe values lie in [-0.5, 1.5]; the blend moves at most 2 per probe spacing (>= ~0.05 here):
        // a step of 0.006 along the line changes it by far less than a jump would.
        EXPECT_LT(max_step, 0.3) << "line " << line;
    }
    EXPECT_GT(crossings, 40);
}

TEST(TetraRuntime, InitPointsRefusesBadArguments) {
    const std::vector<Pos> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const Volume vol = make_volume(p, random_hub(19, 4));
    const zhc_volume& g = vol.v;
    zhc_volume v;
    EXPECT_EQ(zhc_volume_init_points(&v, &g.format, g.probes, 4 * g.probe_size, g.positions, 4, g.tetrahedra, g.neighbours, 1), ZHC_OK);
    EXPECT_EQ(zhc_volume_init_points(&v, &g.format, g.probes, 4 * g.probe_size - 1, g.positions, 4, g.tetrahedra, g.neighbours, 1),
              ZHC_ERR_TRUNCATED);
    EXPECT_EQ(zhc_volume_init_points(&v, &g.format, g.probes, 4 * g.probe_size, g.positions, 0, g.tetrahedra, g.neighbours, 1),
              ZHC_ERR_INVALID_VALUE);
    EXPECT_EQ(zhc_volume_init_points(&v, &g.format, g.probes, 4 * g.probe_size, g.positions, 3, g.tetrahedra, g.neighbours, 1),
              ZHC_ERR_INVALID_VALUE);  // probe 3 beyond the count
    EXPECT_EQ(zhc_volume_init_points(&v, &g.format, g.probes, 4 * g.probe_size, g.positions, 4, g.tetrahedra, g.neighbours, 0),
              ZHC_ERR_INVALID_VALUE);
    EXPECT_EQ(zhc_volume_init_points(&v, &g.format, nullptr, 0, g.positions, 4, g.tetrahedra, g.neighbours, 1), ZHC_ERR_ARGUMENT);
    EXPECT_EQ(v.probes, nullptr);
    std::vector<std::uint8_t> pos(g.positions, g.positions + 48);
    const float nan = NAN;
    std::memcpy(pos.data() + 20, &nan, 4);
    EXPECT_EQ(zhc_volume_init_points(&v, &g.format, g.probes, 4 * g.probe_size, pos.data(), 4, g.tetrahedra, g.neighbours, 1),
              ZHC_ERR_INVALID_VALUE);
    // A grid call on a points volume's functions: a zeroed volume samples zeros.
    zhc_volume zero;
    std::memset(&zero, 0, sizeof zero);
    uint32_t t = 0, q[4];
    double w[4];
    const V3 x = {0.1, 0.1, 0.1};
    EXPECT_EQ(zhc_volume_tetra_weights(&zero, x.data(), &t, q, w), -1);
    // A position that is not finite: vertex 0 of tetrahedron 0.
    const V3 bad = {NAN, 0, 0};
    EXPECT_EQ(zhc_volume_tetra_weights(&g, bad.data(), &t, q, w), 1);
    EXPECT_EQ(w[0], 1.0);
}

// ---- a real scene ---------------------------------------------------------------------------

TEST(TetraRuntime, ScatteredProbesBakedInALeakRoom) {
    const std::string dir = test::fresh_dir("tetra_room");
    std::ifstream in(std::string(ZHC_TEST_DATA_DIR) + "/leak_room.json");
    nlohmann::json scene = nlohmann::json::parse(in);
    // 48 probes at seeded positions inside the room (x 2.4..6.5, y 0.05..4.5, z -0.5..3.5),
    // 0.15 from the walls, placed on a level's scale (millimetres).
    test::Rng rng(23);
    nlohmann::json pts = nlohmann::json::array();
    for (int i = 0; i < 48; ++i) {
        const double x = 2.55 + 3.8 * rng.u(), y = 0.2 + 4.15 * rng.u(), z = -0.35 + 3.7 * rng.u();
        pts.push_back({std::round(1000 * x) / 1000, std::round(1000 * y) / 1000, std::round(1000 * z) / 1000});
    }
    scene["probes"] = {{"positions", pts}};
    {
        std::ofstream out(dir + "/room.json");
        out << scene.dump();
    }
    auto r = test::run_zhc({"bake", dir + "/room.json", "-o", dir + "/room.zhp", "--to", "zh3_q16", "--rays", "256:1024", "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto bytes = test::read_bytes(dir + "/room.zhp");
    auto set = parse_probe_set(bytes, "room.zhp");
    ASSERT_TRUE(set.ok()) << set.error().message;
    ASSERT_FALSE(set->tetrahedra.empty());
    auto hub = decode_probe_set(*set);
    ASSERT_TRUE(hub.ok());
    Volume vol;
    ASSERT_EQ(zhc_volume_from_zhp(&vol.v, bytes.data(), bytes.size()), ZHC_OK);
    for (const Pos& q : set->layout.positions) vol.twin.pos.push_back({q[0], q[1], q[2]});
    vol.twin.tets = set->tetrahedra;
    vol.twin.validity = set->validity;
    for (const Sh3Radiance& h : *hub) {
        std::array<double, 27> s;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) s[size_t(3 * i + k)] = h[i][k];
        vol.twin.sh.push_back(s);
    }
    hull_faces(vol.twin);
    const int inside = compare_with_twin(vol, 24, 2000, {2.4, 0.05, -0.5}, {6.5, 4.5, 3.5}, "leak room, 48 probes");
    EXPECT_GT(inside, 600);
    EXPECT_LT(inside, 1900);
    // The strict-C99 sampler reads the same file to the same floats.
    test::Rng pr(25);
    std::vector<std::array<float, 6>> samples;
    {
        std::ofstream pts_out(dir + "/points.txt");
        for (int s = 0; s < 300; ++s) {
            const Vec3 n = pr.dir();
            std::array<float, 6> smp = {float(2.4 + 4.1 * pr.u()), float(4.4 * pr.u()), float(-0.5 + 4 * pr.u()), float(n.x), float(n.y), float(n.z)};
            char line[256];
            std::snprintf(line, sizeof line, "%.9g %.9g %.9g %.9g %.9g %.9g\n", smp[0], smp[1], smp[2], smp[3], smp[4], smp[5]);
            pts_out << line;
            samples.push_back(smp);
        }
    }
    const std::string cmd = std::string("'") + ZHC_VOLUME_SAMPLE + "' '" + dir + "/room.zhp' '" + dir + "/points.txt'";
    FILE* pipe = popen(cmd.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::vector<std::array<float, 3>> c99;
    std::array<float, 3> rgb;
    while (std::fscanf(pipe, "%f %f %f", &rgb[0], &rgb[1], &rgb[2]) == 3) c99.push_back(rgb);
    ASSERT_EQ(pclose(pipe), 0) << cmd;
    ASSERT_EQ(c99.size(), samples.size());
    for (size_t i = 0; i < samples.size(); ++i) {
        float e[3];
        zhc_volume_irradiance(&vol.v, samples[i].data(), samples[i].data() + 3, e);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(std::memcmp(&e[k], &c99[i][size_t(k)], 4), 0) << "sample " << i;
    }
}

}  // namespace
}  // namespace zhc
