// Delaunay tetrahedra of scattered probes (formats/probes/tetra.h) and their .zhp section
// (docs/zhp-container.md "tetrahedra"):
//  * random sets: every tetrahedron positively oriented, canonical and sorted, no probe inside any
//    circumsphere (a brute-force Delaunay check), hull faces that have every probe on their inner
//    side, tetrahedra whose volumes add up to the hull's: a tiling of the convex hull;
//  * a cospherical lattice (qhull's triangulated output holds flat tetrahedra): still a tiling;
//  * the same result on every call and from concurrent threads;
//  * degenerate sets refused with the reason (too few, collinear, coplanar, duplicates reducing a
//    set to 3); duplicates merged into their first probe; exactly 4 probes;
//  * .zhp: round trip (also zstd), body size, convert_probe_set keeping them; hostile files
//    (every prefix, trailing bytes, a count the bytes cannot fill, indices out of range or
//    repeated, neighbours out of range or inconsistent, the section on a grid) with zhc's reader
//    and runtime/zhc_runtime.h giving the same error class;
//  * the CLI: zhc convert (JSON list, .zhp) and zhc bake write the section for `points`, warn and
//    write none for a coplanar set, zhc info counts them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <thread>
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
using Tet = std::array<std::uint32_t, 4>;

std::vector<Pos> random_positions(unsigned seed, int n, float scale = 4.0f) {
    test::Rng rng(seed);
    std::vector<Pos> p(static_cast<size_t>(n));
    for (auto& q : p)
        for (auto& c : q) c = static_cast<float>(scale * rng.u());
    return p;
}

std::vector<Pos> lattice(int nx, int ny, int nz, float step = 1.0f) {
    std::vector<Pos> p;
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) p.push_back({step * float(x), step * float(y), step * float(z)});
    return p;
}

using D3 = std::array<long double, 3>;
D3 d3(const Pos& p) { return {p[0], p[1], p[2]}; }
D3 operator-(const D3& a, const D3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
long double dotl(const D3& a, const D3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
D3 crossl(const D3& a, const D3& b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
long double orient(const std::vector<Pos>& p, const Tet& t) {
    return dotl(d3(p[t[1]]) - d3(p[t[0]]), crossl(d3(p[t[2]]) - d3(p[t[0]]), d3(p[t[3]]) - d3(p[t[0]])));
}

// How tetrahedron t orients its face j (the face without vertex j), as a sign: (-1)^j times the
// parity of the face's probes in t's order against ascending order. In a consistently oriented
// tetrahedralisation the two tetrahedra of a shared face give it opposite signs.
int face_order(const Tet& t, int j) {
    std::vector<std::uint32_t> f;
    for (int k = 0; k < 4; ++k)
        if (k != j) f.push_back(t[size_t(k)]);
    int inversions = 0;
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) inversions += f[size_t(a)] > f[size_t(b)];
    return ((inversions + j) % 2 == 0) ? 1 : -1;
}

long double hull_volume_from_faces(const std::vector<Pos>& p, const Tetrahedralization& tz) {
    // Sum over hull faces of the signed volume of the cone from probe 0, each face oriented
    // outwards (away from its tetrahedron's fourth vertex).
    long double v = 0;
    for (size_t t = 0; t < tz.tetrahedra.size(); ++t)
        for (int j = 0; j < 4; ++j) {
            if (tz.neighbours[t][size_t(j)] != -1) continue;
            Tet f = tz.tetrahedra[t];
            // The face opposite j keeps the tetrahedron's orientation with j replaced by the apex.
            Tet cone = f;
            cone[size_t(j)] = 0;
            // orient(cone) = det with vertex j moved to probe 0: positive when probe 0 is on the inner side.
            v += orient(p, cone);
        }
    return v / 6;
}

// Checks the tetrahedra tile the convex hull of p and are Delaunay (empty circumspheres within `tol`
// of the radius); flat tetrahedra (orientation 0) are allowed only when allow_flat.
void expect_delaunay_tiling(const std::vector<Pos>& p, const Tetrahedralization& tz, bool allow_flat) {
    ASSERT_TRUE(validate_tetrahedra(p.size(), tz.tetrahedra, tz.neighbours).ok());
    long double total = 0, extent = 0;
    for (const Pos& q : p) extent = std::max(extent, std::sqrt(dotl(d3(q) - d3(p[0]), d3(q) - d3(p[0]))));
    for (size_t t = 0; t < tz.tetrahedra.size(); ++t) {
        const Tet& v = tz.tetrahedra[t];
        // Canonical: ascending, or with the last two swapped.
        EXPECT_LT(v[0], std::min({v[1], v[2], v[3]})) << t;
        EXPECT_LT(v[1], std::min(v[2], v[3])) << t;
        const long double o = orient(p, v);
        if (allow_flat) {
            EXPECT_GE(o, -1e-12L * extent * extent * extent) << t;
        } else {
            EXPECT_GT(o, 0) << t;
        }
        // Consistent orientation: a shared face appears in opposite orders in its two tetrahedra.
        for (int j = 0; j < 4; ++j) {
            const std::int32_t n = tz.neighbours[t][size_t(j)];
            if (n < 0) continue;
            int back = 0;
            while (tz.neighbours[size_t(n)][size_t(back)] != std::int32_t(t)) ++back;
            EXPECT_EQ(face_order(v, j), -face_order(tz.tetrahedra[size_t(n)], back)) << t << " face " << j;
        }
        total += o / 6;
        if (t > 0) {
            Tet a = tz.tetrahedra[t - 1], b = v;
            std::sort(a.begin(), a.end());
            std::sort(b.begin(), b.end());
            EXPECT_LT(a, b) << "sorted " << t;
        }
        // Circumsphere (solid tetrahedra): centre c with |c - a|^2 = |c - x|^2 for x = b, c, d.
        if (o <= 1e-9L * extent * extent * extent) continue;
        const D3 a = d3(p[v[0]]), e1 = d3(p[v[1]]) - a, e2 = d3(p[v[2]]) - a, e3 = d3(p[v[3]]) - a;
        const D3 c23 = crossl(e2, e3), c31 = crossl(e3, e1), c12 = crossl(e1, e2);
        const long double den = 2 * dotl(e1, c23);
        D3 c;
        for (int k = 0; k < 3; ++k)
            c[size_t(k)] = (dotl(e1, e1) * c23[size_t(k)] + dotl(e2, e2) * c31[size_t(k)] + dotl(e3, e3) * c12[size_t(k)]) / den;
        const long double r2 = dotl(c, c);
        for (size_t i = 0; i < p.size(); ++i) {
            const D3 d = d3(p[i]) - a - c;
            EXPECT_GE(dotl(d, d), r2 * (1 - 1e-9L)) << "probe " << i << " inside the circumsphere of tetrahedron " << t;
        }
    }
    // Hull faces: every probe on the inner side; the cones from probe 0 over them add up to the
    // tetrahedra's volume: no gap, no overlap.
    for (size_t t = 0; t < tz.tetrahedra.size(); ++t)
        for (int j = 0; j < 4; ++j) {
            if (tz.neighbours[t][size_t(j)] != -1) continue;
            for (size_t i = 0; i < p.size(); ++i) {
                Tet cone = tz.tetrahedra[t];
                cone[size_t(j)] = static_cast<std::uint32_t>(i);
                EXPECT_GE(orient(p, cone), -1e-9L * extent * extent * extent) << "probe " << i << " beyond hull face " << t << "/" << j;
            }
        }
    EXPECT_NEAR(double(total), double(hull_volume_from_faces(p, tz)), 1e-9 * double(extent * extent * extent));
}

TEST(Tetra, RandomSetsAreDelaunayTilingsOfTheHull) {
    for (unsigned seed : {1u, 2u, 3u}) {
        const auto p = random_positions(seed, 150);
        auto tz = tetrahedralize(p);
        ASSERT_TRUE(tz.ok()) << tz.error().message;
        EXPECT_EQ(tz->flat, 0u);
        EXPECT_TRUE(tz->duplicates.empty());
        EXPECT_TRUE(tz->unused.empty());
        // Euler: a tetrahedralisation of n points in general position has between n - 3 and O(n^2) tetrahedra.
        EXPECT_GT(tz->tetrahedra.size(), p.size());
        expect_delaunay_tiling(p, *tz, false);
    }
}

TEST(Tetra, CosphericalLatticeIsTriangulatedWithoutFlatTetrahedra) {
    const auto p = lattice(4, 3, 3, 0.5f);
    auto tz = tetrahedralize(p);
    ASSERT_TRUE(tz.ok()) << tz.error().message;
    // Every cube is one Delaunay region; its pulling triangulation from its lowest corner cones the
    // 3 squares without that corner, 2 triangles each: 6 tetrahedra per cube, none flat.
    EXPECT_EQ(tz->flat, 0u);
    EXPECT_EQ(tz->tetrahedra.size(), 12u * 6u);
    expect_delaunay_tiling(p, *tz, false);
    long double total = 0;
    for (const Tet& t : tz->tetrahedra) total += orient(p, t) / 6;
    EXPECT_DOUBLE_EQ(double(total), 1.5 * 1.0 * 1.0);  // the box 1.5 x 1 x 1
    // A larger lattice with a probe at the centre of the square between two cubes.
    auto q = lattice(5, 4, 3, 1.0f);
    q.push_back({2.5f, 1.5f, 1.0f});
    auto tq = tetrahedralize(q);
    ASSERT_TRUE(tq.ok()) << tq.error().message;
    EXPECT_EQ(tq->flat, 0u);
    expect_delaunay_tiling(q, *tq, false);
    // qhull's own Qt triangulation of the same lattice: flat tetrahedra between cubes, still a
    // consistently oriented tiling (what the runtimes are tested with for flat tetrahedra).
    auto qt = tetrahedralize(p, true);
    ASSERT_TRUE(qt.ok()) << qt.error().message;
    EXPECT_GT(qt->flat, 0u);
    expect_delaunay_tiling(p, *qt, true);
}

TEST(Tetra, SameResultOnEveryCallAndFromConcurrentThreads) {
    const auto p = random_positions(9, 400, 10.0f);
    auto first = tetrahedralize(p);
    ASSERT_TRUE(first.ok());
    std::vector<Tetrahedralization> outs(4);
    std::vector<std::thread> threads;
    for (size_t i = 0; i < outs.size(); ++i)
        threads.emplace_back([&, i] {
            auto r = tetrahedralize(p);
            if (r.ok()) outs[i] = std::move(r).value();
        });
    for (auto& t : threads) t.join();
    for (const auto& o : outs) {
        EXPECT_EQ(o.tetrahedra, first->tetrahedra);
        EXPECT_EQ(o.neighbours, first->neighbours);
    }
}

TEST(Tetra, DegenerateSetsAreRefusedWithTheReason) {
    auto why = [](const std::vector<Pos>& p) {
        auto r = tetrahedralize(p);
        EXPECT_FALSE(r.ok());
        if (r.ok()) return std::string();
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
        return r.error().message;
    };
    EXPECT_NE(why({}).find("fewer than 4 distinct probe positions (0)"), std::string::npos);
    EXPECT_NE(why({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}).find("fewer than 4 distinct probe positions (3)"), std::string::npos);
    // Five probes, two pairs of duplicates: three distinct positions.
    EXPECT_NE(why({{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 1, 0}, {1, 0, 0}}).find("fewer than 4 distinct probe positions (3)"),
              std::string::npos);
    std::vector<Pos> line, plane, tilted;
    for (int i = 0; i < 7; ++i) line.push_back({float(i), 2.0f * float(i), -float(i)});
    EXPECT_NE(why(line).find("all 7 probe positions lie on one line"), std::string::npos);
    for (int i = 0; i < 12; ++i) plane.push_back({float(i % 4), float(i / 4), 1.5f});
    EXPECT_NE(why(plane).find("all 12 probe positions lie in one plane"), std::string::npos);
    // A tilted plane, its points rounded to float: still one plane.
    test::Rng rng(4);
    for (int i = 0; i < 30; ++i) {
        const double u = 10 * rng.u(), v = 10 * rng.u();
        tilted.push_back({float(u), float(v), float(0.3 * u - 0.7 * v + 2)});
    }
    EXPECT_NE(why(tilted).find("all 30 probe positions lie in one plane"), std::string::npos);
    // Lifted by 1e-3 of the extent: a (thin) volume, tetrahedralised.
    tilted.push_back({5, 5, float(0.3 * 5 - 0.7 * 5 + 2 + 0.01)});
    EXPECT_TRUE(tetrahedralize(tilted).ok());
}

TEST(Tetra, DuplicatesMergeIntoTheirFirstProbe) {
    auto p = random_positions(5, 30);
    auto base = tetrahedralize(p);
    ASSERT_TRUE(base.ok());
    p.push_back(p[3]);   // probe 30 = probe 3
    p.push_back(p[7]);   // probe 31 = probe 7
    p.push_back(p[3]);   // probe 32 = probe 3
    auto tz = tetrahedralize(p);
    ASSERT_TRUE(tz.ok()) << tz.error().message;
    EXPECT_EQ(tz->tetrahedra, base->tetrahedra);  // the later copies are never a vertex
    EXPECT_EQ(tz->neighbours, base->neighbours);
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> dups = {{30, 3}, {31, 7}, {32, 3}};
    EXPECT_EQ(tz->duplicates, dups);
    // A duplicate before its original in index order: the lower index wins.
    std::vector<Pos> q = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    q.insert(q.begin(), q[2]);  // probe 0 and probe 3 at (0, 1, 0)
    auto tq = tetrahedralize(q);
    ASSERT_TRUE(tq.ok());
    ASSERT_EQ(tq->tetrahedra.size(), 1u);
    EXPECT_EQ(tq->duplicates, (std::vector<std::pair<std::uint32_t, std::uint32_t>>{{3, 0}}));
    Tet s = tq->tetrahedra[0];
    std::sort(s.begin(), s.end());
    EXPECT_EQ(s, (Tet{0, 1, 2, 4}));
}

TEST(Tetra, ExactlyFourProbesMakeOneTetrahedron) {
    const std::vector<Pos> p = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}};  // negatively ordered as given
    auto tz = tetrahedralize(p);
    ASSERT_TRUE(tz.ok()) << tz.error().message;
    ASSERT_EQ(tz->tetrahedra.size(), 1u);
    EXPECT_EQ(tz->tetrahedra[0], (Tet{0, 1, 3, 2}));  // ascending, then the last two swapped: positive
    EXPECT_GT(orient(p, tz->tetrahedra[0]), 0);
    EXPECT_EQ(tz->neighbours[0], (std::array<std::int32_t, 4>{-1, -1, -1, -1}));
}

TEST(Tetra, ValidateTetrahedraNamesTheBrokenRule) {
    const std::vector<Tet> two = {{0, 1, 2, 3}, {1, 2, 3, 4}};
    const std::vector<std::array<std::int32_t, 4>> nb = {{1, -1, -1, -1}, {-1, -1, -1, 0}};
    EXPECT_TRUE(validate_tetrahedra(5, two, nb).ok());
    auto msg = [](const Status& s) { return s.ok() ? std::string("ok") : s.error().message; };
    EXPECT_NE(msg(validate_tetrahedra(4, two, nb)).find("tetrahedron 1 vertex 3 is probe 4, beyond the 4 probes"), std::string::npos);
    EXPECT_NE(msg(validate_tetrahedra(5, {{{0, 1, 2, 1}}}, {{{-1, -1, -1, -1}}})).find("tetrahedron 0 names probe 1 twice"),
              std::string::npos);
    auto bad = nb;
    bad[0][0] = 2;
    EXPECT_NE(msg(validate_tetrahedra(5, two, bad)).find("tetrahedron 0 face 0: neighbour 2 is not another tetrahedron"), std::string::npos);
    bad = nb;
    bad[1][3] = -1;  // not reciprocal
    EXPECT_NE(msg(validate_tetrahedra(5, two, bad)).find("tetrahedron 0 face 0: neighbour 1 does not share that face"), std::string::npos);
    bad = nb;
    bad[0] = {-1, 1, -1, -1};  // face 1 = (0, 2, 3) is not a face of tetrahedron 1
    bad[1] = {-1, -1, -1, 0};
    EXPECT_NE(msg(validate_tetrahedra(5, two, bad)).find("tetrahedron 0 face 1: neighbour 1 does not share that face"), std::string::npos);
    EXPECT_FALSE(validate_tetrahedra(5, two, {}).ok());
    EXPECT_FALSE(validate_tetrahedra(5, {}, {}).ok());
    // In a set: only with a positions layout.
    ProbeSet set;
    set.count = 5;
    set.layout.kind = ProbeLayoutKind::kGrid;
    set.layout.grid.counts = {5, 1, 1};
    set.payload.resize(5 * 108);
    set.tetrahedra = two;
    set.tetra_neighbours = nb;
    EXPECT_NE(msg(validate_probe_set(set)).find("tetrahedra need a positions layout"), std::string::npos);
}

// ---- .zhp -----------------------------------------------------------------------------------------

std::vector<Sh3Radiance> hub_of(size_t n) {
    std::vector<Sh3Radiance> hub(n);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) hub[i][c][k] = c == 0 ? float(1 + i % 7 + k) : float(0.05 * std::sin(double(i * 27 + size_t(c) * 3 + size_t(k))));
    return hub;
}

ProbeSet points_set(const std::vector<Pos>& p, const std::string& rep = "zh3_q16") {
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kPositions;
    layout.positions = p;
    auto set = encode_probe_set(hub_of(p.size()), rep, {}, layout);
    EXPECT_TRUE(set.ok());
    EXPECT_TRUE(add_tetrahedra(*set).empty());
    return std::move(set).value();
}

ErrorCode code_of(const std::vector<std::uint8_t>& b) {
    auto r = parse_probe_set(b, "mem");
    return r.ok() ? ErrorCode::kInternal : r.error().code;
}

// zhc's reader and the C header agree on the error class (the same numbers, codec/status.h).
void expect_both(const std::vector<std::uint8_t>& b, ErrorCode code, const std::string& what) {
    EXPECT_EQ(code_of(b), code) << what;
    zhc_probe_format f;
    zhc_zhp_info info;
    const int c = zhc_zhp_open(&f, &info, b.data(), b.size());
    EXPECT_EQ(c, code == ErrorCode::kInternal ? ZHC_OK : static_cast<int>(code)) << what;
}

std::vector<std::uint8_t> fix_body_crc(std::vector<std::uint8_t> b) {
    const std::uint32_t crc = crc32({b.data() + kProbeFileHeaderBytes, b.size() - kProbeFileHeaderBytes});
    return test::zhp_with_header_edit(b, 176, {std::uint8_t(crc), std::uint8_t(crc >> 8), std::uint8_t(crc >> 16),
                                                std::uint8_t(crc >> 24)});
}

void put32(std::vector<std::uint8_t>& b, size_t at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b[at + size_t(k)] = std::uint8_t(v >> (8 * k));
}

std::vector<std::uint8_t> with_body_size(std::vector<std::uint8_t> b, std::uint64_t raw) {
    b = test::zhp_with_header_edit(b, 160, {std::uint8_t(raw), std::uint8_t(raw >> 8), std::uint8_t(raw >> 16), std::uint8_t(raw >> 24), 0, 0, 0, 0});
    b = test::zhp_with_header_edit(b, 168, {std::uint8_t(raw), std::uint8_t(raw >> 8), std::uint8_t(raw >> 16), std::uint8_t(raw >> 24), 0, 0, 0, 0});
    return fix_body_crc(b);
}

TEST(TetraContainer, RoundTripBodySizeAndConvert) {
    const auto p = random_positions(11, 40);
    ProbeSet set = points_set(p);
    ASSERT_FALSE(set.tetrahedra.empty());
    const size_t t_count = set.tetrahedra.size();
    for (int level : {0, 5}) {
        ProbeFileWriteOptions wo;
        wo.zstd_level = level;
        auto bytes = serialize_probe_set(set, wo);
        ASSERT_TRUE(bytes.ok());
        EXPECT_EQ(test::get32(*bytes, 8) & 0xFFFF, 2u);
        EXPECT_EQ((*bytes)[21], 8);
        EXPECT_EQ(test::get32(*bytes, 160), 40 * 12 + 40 * 16 + 4 + 32 * t_count);
        ProbeFileInfo info;
        auto back = parse_probe_set(*bytes, "mem", {}, &info);
        ASSERT_TRUE(back.ok()) << back.error().message;
        EXPECT_EQ(back->tetrahedra, set.tetrahedra);
        EXPECT_EQ(back->tetra_neighbours, set.tetra_neighbours);
        EXPECT_EQ(back->payload, set.payload);
    }
    // With validity too: bits 0 and 3, validity before the tetrahedra.
    set.validity.assign(40, 1);
    set.validity[5] = 0;
    auto bytes = *serialize_probe_set(set);
    EXPECT_EQ(bytes[21], 9);
    const size_t sec = kProbeFileHeaderBytes + 40 * 12 + 40 * 16 + 40;
    EXPECT_EQ(test::get32(bytes, sec), t_count);
    EXPECT_EQ(test::get32(bytes, sec + 4), set.tetrahedra[0][0]);
    EXPECT_EQ(test::get32(bytes, sec + 4 + 16 * t_count), std::uint32_t(set.tetra_neighbours[0][0]));
    auto back = parse_probe_set(bytes, "mem");
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->validity, set.validity);
    EXPECT_EQ(back->tetrahedra, set.tetrahedra);
    // The C header finds the section where zhc wrote it.
    zhc_probe_format f;
    zhc_zhp_info info;
    ASSERT_EQ(zhc_zhp_open(&f, &info, bytes.data(), bytes.size()), ZHC_OK);
    EXPECT_EQ(info.tetrahedra_offset, sec);
    EXPECT_EQ(info.tetra_count, t_count);
    // convert_probe_set keeps them.
    auto other = convert_probe_set(set, "sh3", {});
    ASSERT_TRUE(other.ok());
    EXPECT_EQ(other->tetrahedra, set.tetrahedra);
    EXPECT_EQ(other->tetra_neighbours, set.tetra_neighbours);
}

TEST(TetraContainer, HostileFilesGetDistinctErrorsInZhcAndTheCHeader) {
    const auto p = random_positions(12, 12);
    const ProbeSet set = points_set(p);
    const auto good = *serialize_probe_set(set);
    const size_t t_count = set.tetrahedra.size();
    const size_t sec = kProbeFileHeaderBytes + 12 * 12 + 12 * 16;
    expect_both(good, ErrorCode::kInternal, "good");
    for (size_t n = 0; n < good.size(); ++n)
        expect_both(std::vector<std::uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(n)), ErrorCode::kTruncated,
                    "prefix " + std::to_string(n));
    auto longer = good;
    longer.push_back(0);
    expect_both(longer, ErrorCode::kTrailingBytes, "trailing");
    // A count the bytes cannot fill, or that leaves bytes over: malformed.
    for (std::uint32_t c : {std::uint32_t(t_count + 1), std::uint32_t(t_count - 1), 0u, 0xFFFFFFFFu}) {
        auto bad = good;
        put32(bad, sec, c);
        expect_both(fix_body_crc(bad), ErrorCode::kBadFormat, "count " + std::to_string(c));
    }
    {
        auto r = parse_probe_set(
            [&] {
                auto bad = good;
                put32(bad, sec, std::uint32_t(t_count + 1));
                return fix_body_crc(bad);
            }(),
            "f.zhp");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message.find("f.zhp: tetrahedra section declares " + std::to_string(t_count + 1) + " tetrahedra"),
                  std::string::npos)
            << r.error().message;
    }
    // A body size that is not 4 + 32 T after the probes, or holds no tetrahedron: malformed before
    // anything is read.
    const std::uint64_t raw = good.size() - kProbeFileHeaderBytes;
    for (std::uint64_t r : {raw + 1, raw - 1, raw - 32 * t_count, raw - 32 * t_count - 4, std::uint64_t(12 * 12 + 12 * 16)}) {
        auto bad = good;
        bad.resize(kProbeFileHeaderBytes + r, 0);
        expect_both(with_body_size(bad, r), ErrorCode::kBadFormat, "body " + std::to_string(r));
    }
    // Indices out of range or repeated, neighbours out of range, self, not reciprocal, or across a
    // different face: invalid values.
    auto edit = [&](size_t at, std::uint32_t v) {
        auto bad = good;
        put32(bad, at, v);
        return fix_body_crc(bad);
    };
    const size_t idx = sec + 4, nbr = sec + 4 + 16 * t_count;
    expect_both(edit(idx + 4, 12), ErrorCode::kInvalidValue, "index = count");
    expect_both(edit(idx + 4, 0xFFFFFFFFu), ErrorCode::kInvalidValue, "index -1");
    expect_both(edit(idx + 4, set.tetrahedra[0][0]), ErrorCode::kInvalidValue, "repeated index");
    expect_both(edit(nbr, std::uint32_t(t_count)), ErrorCode::kInvalidValue, "neighbour = count");
    expect_both(edit(nbr, 0), ErrorCode::kInvalidValue, "neighbour = self");
    expect_both(edit(nbr, 0xFFFFFFFEu), ErrorCode::kInvalidValue, "neighbour -2");
    {
        // Tetrahedron 0's first interior face points elsewhere: not reciprocal / another face.
        size_t j = 0;
        while (set.tetra_neighbours[0][j] < 0) ++j;
        const std::uint32_t other = std::uint32_t(set.tetra_neighbours[0][j] == 1 ? 2 : 1);
        expect_both(edit(nbr + 4 * j, other), ErrorCode::kInvalidValue, "wrong neighbour");
        expect_both(edit(nbr + 4 * j, 0xFFFFFFFFu), ErrorCode::kInvalidValue, "a hull face on one side only");
        auto r = parse_probe_set(edit(nbr + 4 * j, other), "f.zhp");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message.find("f.zhp: tetrahedron "), std::string::npos) << r.error().message;
    }
    // Section flags: bit 3 on a grid file (body fixed up to hold it) is malformed; bit 4 is unknown.
    {
        ProbeLayout g;
        g.kind = ProbeLayoutKind::kGrid;
        g.grid.counts = {2, 2, 3};
        auto grid = *encode_probe_set(hub_of(12), "zh3_q16", {}, g);
        grid.validity.assign(12, 1);
        auto bytes = *serialize_probe_set(grid);
        auto bad = test::zhp_with_header_edit(bytes, 21, {9});
        bad.insert(bad.end(), good.begin() + std::ptrdiff_t(sec), good.end());
        expect_both(with_body_size(bad, bad.size() - kProbeFileHeaderBytes), ErrorCode::kBadFormat, "tetrahedra on a grid");
    }
    expect_both(test::zhp_with_header_edit(good, 21, {8 | 16}), ErrorCode::kUnsupported, "bit 4");
    // Bit 3 cleared: the body is too long for the probes alone.
    expect_both(test::zhp_with_header_edit(good, 21, {1}), ErrorCode::kBadFormat, "section undeclared");
}

// ---- CLI ------------------------------------------------------------------------------------------

std::string points_json(const std::vector<Pos>& p) {
    nlohmann::json doc;
    doc["probes"] = nlohmann::json::array();
    const auto hub = hub_of(p.size());
    for (size_t i = 0; i < p.size(); ++i) {
        nlohmann::json rows = nlohmann::json::array();
        for (int c = 0; c < 9; ++c) rows.push_back({hub[i][c][0], hub[i][c][1], hub[i][c][2]});
        doc["probes"].push_back({{"position", {p[i][0], p[i][1], p[i][2]}}, {"sh3", rows}});
    }
    return doc.dump();
}

void write_text(const std::string& path, const std::string& s) { test::write_bytes(path, std::vector<std::uint8_t>(s.begin(), s.end())); }

TEST(TetraCli, ConvertAndBakeWriteTheSectionForPoints) {
    const std::string dir = test::fresh_dir("tetra_cli");
    auto p = random_positions(21, 25);
    p.push_back(p[4]);  // a duplicate: merged, said so
    write_text(dir + "/pts.json", points_json(p));
    auto r = test::run_zhc({"convert", dir + "/pts.json", "-o", dir + "/pts.zhp", "--to", "sh3"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("pts.zhp: probes at the position of an earlier probe are merged into it (the tetrahedra use the earlier one): 25 (= 4)"),
              std::string::npos)
        << r.err;
    auto set = read_probe_file(dir + "/pts.zhp");
    ASSERT_TRUE(set.ok()) << set.error().message;
    auto tz = tetrahedralize(p);
    ASSERT_TRUE(tz.ok());
    EXPECT_EQ(set->tetrahedra, tz->tetrahedra);
    EXPECT_EQ(set->tetra_neighbours, tz->neighbours);
    // .zhp -> .zhp in another representation keeps the section; zhc info counts it.
    r = test::run_zhc({"convert", dir + "/pts.zhp", "-o", dir + "/q16.zhp", "--to", "zh3_q16"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto q16 = read_probe_file(dir + "/q16.zhp");
    ASSERT_TRUE(q16.ok());
    EXPECT_EQ(q16->tetrahedra, tz->tetrahedra);
    r = test::run_zhc({"info", dir + "/q16.zhp", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out).value("tetrahedra", 0), tz->tetrahedra.size()) << r.out;
    // A coplanar list: written without tetrahedra, with a warning; the C header then refuses it as
    // no volume.
    std::vector<Pos> flat;
    for (int i = 0; i < 9; ++i) flat.push_back({float(i % 3), float(i / 3), 0.5f});
    write_text(dir + "/flat.json", points_json(flat));
    r = test::run_zhc({"convert", dir + "/flat.json", "-o", dir + "/flat.zhp", "--to", "sh3"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("zhc: warning: " + dir + "/flat.zhp: tetrahedralisation: all 9 probe positions lie in one plane: no tetrahedra stored"),
              std::string::npos)
        << r.err;
    auto fb = test::read_bytes(dir + "/flat.zhp");
    EXPECT_EQ(fb[8], 1) << "version 1: no section";
    zhc_volume v;
    EXPECT_EQ(zhc_volume_from_zhp(&v, fb.data(), fb.size()), ZHC_ERR_NOT_GRID);
    // JSON output: no tetrahedra (the list has no place for them), no warning.
    r = test::run_zhc({"convert", dir + "/pts.zhp", "-o", dir + "/back.json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    // zhc bake of a scene with probes.positions.
    nlohmann::json scene = {{"format", "zhc-scene"},
                            {"version", 1},
                            {"sky", {{"type", "constant"}, {"radiance", {0.3, 0.4, 0.6}}}},
                            {"probes", {{"positions", nlohmann::json::array()}}}};
    for (const Pos& q : random_positions(22, 12)) scene["probes"]["positions"].push_back({q[0], q[1], q[2]});
    write_text(dir + "/scene.json", scene.dump());
    r = test::run_zhc({"bake", dir + "/scene.json", "-o", dir + "/baked.zhp", "--to", "zh3_q16", "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto baked = read_probe_file(dir + "/baked.zhp");
    ASSERT_TRUE(baked.ok()) << baked.error().message;
    auto tb = tetrahedralize(baked->layout.positions);
    ASSERT_TRUE(tb.ok());
    EXPECT_EQ(baked->tetrahedra, tb->tetrahedra);
    EXPECT_FALSE(baked->tetrahedra.empty());
}

}  // namespace
}  // namespace zhc
