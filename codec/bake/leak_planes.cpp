// zhc/codec/bake/leak_planes.cpp — probe relocation and the plane per cell (leak_planes.h).
#include "codec/bake/leak_planes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>

#include "codec/bake/bake_internal.h"

namespace zhc {

namespace {

using bake_detail::kRayEpsilon;
using bake_detail::parallel_blocks;

void set_axis(Vec3& v, int a, double x) { (a == 0 ? v.x : (a == 1 ? v.y : v.z)) = x; }

Vec3 unit_or_z(Vec3 v) {
    const double l = length(v);
    return l > 0 ? Vec3{v.x / l, v.y / l, v.z / l} : Vec3{0, 0, 1};
}

// The 26 directions: axes, then edges, then corners, each group in index order k = (dx + 1) +
// 3 (dy + 1) + 9 (dz + 1).
const std::vector<Vec3>& directions26() {
    static const std::vector<Vec3> dirs = [] {
        std::vector<Vec3> d;
        for (int kind = 1; kind <= 3; ++kind)
            for (int k = 0; k < 27; ++k) {
                const int dx = k % 3 - 1, dy = (k / 3) % 3 - 1, dz = k / 9 - 1;
                if (std::abs(dx) + std::abs(dy) + std::abs(dz) == kind)
                    d.push_back(unit_or_z({double(dx), double(dy), double(dz)}));
            }
        return d;
    }();
    return dirs;
}

// Geometry within r of p along one of the 26 directions?
bool near_geometry(const OccluderBvh& bvh, Vec3 p, double r, std::uint64_t* rays) {
    for (const Vec3& d : directions26()) {
        ++*rays;
        if (bvh.occluded(p, d, 0.0, r)) return true;
    }
    return false;
}

bool clear_point(const OccluderBvh& bvh, const InsideTest& test, Vec3 p, double r, std::uint64_t* rays) {
    if (bvh.inside_any_solid(p)) return false;
    if (near_geometry(bvh, p, r, rays)) return false;
    return !inside_geometry(bvh, test, p, rays);
}

std::uint32_t axis_index(std::size_t i, const ProbeGrid& g, int a) {
    const std::size_t nx = g.counts[0], ny = g.counts[1];
    return a == 0 ? std::uint32_t(i % nx) : a == 1 ? std::uint32_t((i / nx) % ny) : std::uint32_t(i / (nx * ny));
}

std::size_t grid_index(const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return std::size_t(x) + std::size_t(g.counts[0]) * (std::size_t(y) + std::size_t(g.counts[1]) * z);
}

Vec3 grid_point(const ProbeGrid& g, std::size_t i) {
    return {g.origin.x + axis_index(i, g, 0) * g.spacing.x, g.origin.y + axis_index(i, g, 1) * g.spacing.y,
            g.origin.z + axis_index(i, g, 2) * g.spacing.z};
}

double min_spacing(const ProbeGrid& g) {
    // Axes of count 1 have no spacing that matters.
    double h = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a)
        if (g.counts[static_cast<size_t>(a)] > 1) h = std::min(h, g.spacing[a]);
    return std::isfinite(h) ? h : std::min({g.spacing.x, g.spacing.y, g.spacing.z});
}

// Does probe (x, y, z) start a cell? (Not the last along an axis of count >= 2.)
bool starts_cell(const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    const std::uint32_t idx[3] = {x, y, z};
    for (int a = 0; a < 3; ++a)
        if (g.counts[static_cast<size_t>(a)] > 1 && idx[a] + 1 == g.counts[static_cast<size_t>(a)]) return false;
    return true;
}

struct CellFit {
    CellPlane plane;
    double wrong_fraction = 0;
    PlaneFitStats stats;
};

// The plane predicting the fewest (point, valid corner) pairs' visibility `vis` wrongly among the
// candidates (for the hit points, then the shadow edge's points: the least-squares plane of the
// points, and per axis the axis-aligned planes at their minimum, maximum, middle and median),
// quantised as stored; "no plane" when none beats predicting
// every pair visible. blocked: the pairs `vis` calls blocked; wrong / leaking: the chosen plane's.
CellPlane best_plane(const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z, const std::vector<Vec3>& hits,
                     const std::vector<Vec3>& edge, const std::vector<Vec3>& pts,
                     const std::vector<std::array<std::uint8_t, 8>>& vis, const Vec3 corner[8], const bool cvalid[8],
                     std::uint64_t* blocked_out, std::uint64_t* wrong_out, std::uint64_t* leaking_out) {
    CellPlane chosen;
    const Vec3 c = cell_centre(g, x, y, z);
    const double unit = cell_plane_unit(g);
    // Candidate planes (normal, a point on it): those of the hit points, then those of the edge's.
    std::vector<std::pair<Vec3, Vec3>> cand;
    for (const std::vector<Vec3>* set : {&hits, &edge}) {
        if (set->empty()) continue;
        Vec3 mean{};
        for (const Vec3& h : *set) mean = mean + h;
        mean = (1.0 / double(set->size())) * mean;
        double cov[3][3] = {};
        for (const Vec3& h : *set) {
            const Vec3 d = h - mean;
            for (int r = 0; r < 3; ++r)
                for (int s = 0; s < 3; ++s) cov[r][s] += d[r] * d[s];
        }
        cand.push_back({smallest_eigenvector(cov), mean});
        for (int a = 0; a < 3; ++a) {
            std::vector<double> coord;
            coord.reserve(set->size());
            for (const Vec3& h : *set) coord.push_back(h[a]);
            std::sort(coord.begin(), coord.end());
            Vec3 n{};
            set_axis(n, a, 1);
            for (double v : {coord.front(), coord.back(), 0.5 * (coord.front() + coord.back()), coord[coord.size() / 2]}) {
                Vec3 p = c;
                set_axis(p, a, v);
                cand.push_back({n, p});
            }
        }
    }
    std::uint64_t blocked = 0;
    for (size_t j = 0; j < pts.size(); ++j)
        for (int k = 0; k < 8; ++k) blocked += cvalid[k] && vis[j][static_cast<size_t>(k)] == 0;
    // Quantise each candidate, then count the pairs it predicts wrongly.
    std::uint64_t best_wrong = blocked, best_leaking = blocked;  // no plane: every blocked pair is predicted visible
    for (const auto& [n, p] : cand) {
        CellPlane cp;
        encode_cell_plane_normal(n, &cp.ou, &cp.ov);
        const Vec3 nq = cell_plane_normal(cp.ou, cp.ov);
        const double off = dot(nq, p - c) / unit;
        if (!(std::fabs(off) < 32767)) continue;
        cp.offset = static_cast<std::int16_t>(std::lround(off));
        for (int k = 0; k < 8; ++k)
            if (cell_plane_value(cp, g, x, y, z, corner[k]) >= 0) cp.sides = static_cast<std::uint8_t>(cp.sides | (1u << k));
        std::uint64_t wrong = 0, leaking = 0;
        for (size_t j = 0; j < pts.size(); ++j) {
            const unsigned side = cell_plane_value(cp, g, x, y, z, pts[j]) >= 0 ? 1u : 0u;
            for (int k = 0; k < 8; ++k) {
                if (!cvalid[k]) continue;
                const bool keep = ((cp.sides >> k) & 1u) == side, visible = vis[j][static_cast<size_t>(k)] != 0;
                wrong += keep != visible;
                leaking += keep && !visible;
            }
        }
        if (wrong < best_wrong) {
            best_wrong = wrong;
            best_leaking = leaking;
            chosen = cp;
        }
    }
    *blocked_out = blocked;
    *wrong_out = best_wrong;
    *leaking_out = best_leaking;
    return chosen;
}

// The pairs an entry (plane or corner region) predicts wrongly against `vis`, and of them those it
// still blends (*leaking).
std::uint64_t entry_wrong(const CellPlane& cp, const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z,
                          const std::vector<Vec3>& pts, const std::vector<std::array<std::uint8_t, 8>>& vis, const bool cvalid[8],
                          std::uint64_t* leaking) {
    std::uint64_t wrong = 0;
    *leaking = 0;
    const std::uint8_t sides = cp.region() ? cell_region_corners(cp) : cp.sides;
    for (size_t j = 0; j < pts.size(); ++j) {
        const unsigned side = !cp.any() ? 0u
                              : cp.region() ? (cell_region_inside(cp, g, x, y, z, pts[j]) ? 1u : 0u)
                                            : (cell_plane_value(cp, g, x, y, z, pts[j]) >= 0 ? 1u : 0u);
        for (int k = 0; k < 8; ++k) {
            if (!cvalid[k]) continue;
            const bool keep = !cp.any() || ((sides >> k) & 1u) == side, visible = vis[j][static_cast<size_t>(k)] != 0;
            wrong += keep != visible;
            *leaking += keep && !visible;
        }
    }
    return wrong;
}

// The corner region (docs/runtime.md "Corner regions") predicting the fewest pairs of `vis` wrongly
// among those that bound every axis of the cell (q = 0 only along a flat axis), so each holds one
// corner (an enclosed pocket seen from its cells: a closed box's inside): per axis the thresholds (in
// 31ths of the cell, quantised as stored) in the middle of a wall across it and at the hit points'
// minimum, maximum, middle and median along it, the region grown from each of the 8 corners.
// *wrong_out: its wrong pairs ("no entry", and its count, when none beats it).
CellPlane best_region(const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z, const std::vector<Vec3>& hits,
                      const std::vector<Vec3>& pts, const std::vector<std::array<std::uint8_t, 8>>& vis, const bool cvalid[8],
                      std::uint64_t* wrong_out) {
    CellPlane chosen;
    std::uint64_t leaking = 0, best_wrong = entry_wrong(chosen, g, x, y, z, pts, vis, cvalid, &leaking);
    std::array<std::vector<int>, 3> qs;
    for (int a = 0; a < 3; ++a) {
        std::vector<int>& qa = qs[static_cast<size_t>(a)];
        qa = {};
        if (g.counts[static_cast<size_t>(a)] < 2) {  // a flat axis bounds nothing
            qa = {0};
            continue;
        }
        if (hits.empty()) return chosen;
        std::vector<int> q;
        const double lo = g.origin[a] + double(a == 0 ? x : (a == 1 ? y : z)) * g.spacing[a];
        // The middle of a wall across this axis first (ties keep the first candidate): the hits
        // on a wall's two faces pile up at two coordinates, the two fullest bins of a histogram in
        // quarters of a threshold step; the lattice of sample points cannot tell thresholds within
        // the wall apart, and shading points on the wall's faces need it inside the wall.
        std::array<int, 125> bins{};
        for (const Vec3& h : hits) ++bins[static_cast<size_t>(std::clamp(int(std::floor((h[a] - lo) / g.spacing[a] * 124.0)), 0, 124))];
        int b1 = 0, b2 = -1;
        for (int b = 1; b < 125; ++b)
            if (bins[static_cast<size_t>(b)] > bins[static_cast<size_t>(b1)]) b1 = b;
        for (int b = 0; b < 125; ++b)
            if (b != b1 && std::abs(b - b1) <= 16 && bins[static_cast<size_t>(b)] > 0 && (b2 < 0 || bins[static_cast<size_t>(b)] > bins[static_cast<size_t>(b2)]))
                b2 = b;
        const double mid = b2 < 0 ? (b1 + 0.5) / 124.0 : (0.5 * (b1 + b2) + 0.5) / 124.0;
        qa.insert(qa.begin(), std::clamp(int(std::lround(mid * 31.0)), 1, 31));
        for (const Vec3& h : hits) q.push_back(std::clamp(int(std::lround((h[a] - lo) / g.spacing[a] * 31.0)), 1, 31));
        std::sort(q.begin(), q.end());
        for (int v : {q.front(), q.back(), (q.front() + q.back()) / 2, q[q.size() / 2]})
            if (std::find(qa.begin(), qa.end(), v) == qa.end()) qa.push_back(v);
    }
    for (int anchor = 0; anchor < 8; ++anchor)
        for (int qx : qs[0])
            for (int qy : qs[1])
                for (int qz : qs[2]) {
                    if (qx == 0 && qy == 0 && qz == 0) continue;  // a single flat cell: nothing to bound
                    const CellPlane cp = cell_region(qx, qy, qz, anchor);
                    const std::uint64_t wrong = entry_wrong(cp, g, x, y, z, pts, vis, cvalid, &leaking);
                    if (wrong < best_wrong) {
                        best_wrong = wrong;
                        chosen = cp;
                    }
                }
    *wrong_out = best_wrong;
    return chosen;
}

// Does `q` receive the light's direct light (inside a spot's outer cone, its shadow ray unblocked)?
bool receives(const OccluderBvh& bvh, const ShadowLight& l, Vec3 q, std::uint64_t* rays) {
    ++*rays;
    if (l.directional) return !bvh.occluded(q, l.direction, kRayEpsilon, std::numeric_limits<double>::infinity());
    const Vec3 v = l.position - q;
    const double d = length(v);
    if (!(d > 2 * kRayEpsilon)) return true;
    if (l.cos_outer > -1 && dot(l.spot_axis, (-1.0 / d) * v) < l.cos_outer) return false;
    return !bvh.occluded(q, (1.0 / d) * v, kRayEpsilon, d - kRayEpsilon);
}

// The hard shadow edge in a cell (leak_planes.h "Shadow planes"): of the lights that reach some of
// its valid corners and not others, the one whose direct light at a receiving corner is strongest.
// Each (point, valid corner) pair `vis` calls visible that disagrees on receiving it becomes
// blocked, and where the edge crosses the pair (6 bisection steps) goes to `edge`. False (nothing
// changed) when no light has an edge between the corners.
bool split_at_shadow_edge(const OccluderBvh& bvh, std::span<const ShadowLight> lights, const Vec3 corner[8], const bool cvalid[8],
                          const std::vector<Vec3>& pts, std::vector<std::array<std::uint8_t, 8>>& vis, std::vector<Vec3>& edge,
                          std::uint64_t* rays) {
    if (lights.empty() || pts.empty()) return false;
    int chosen = -1;
    double chosen_strength = 0;
    std::array<std::uint8_t, 8> chosen_lit{};
    for (size_t li = 0; li < lights.size(); ++li) {
        const ShadowLight& l = lights[li];
        std::array<std::uint8_t, 8> lit{};
        int n_lit = 0, n_valid = 0;
        double strength = 0;
        for (int k = 0; k < 8; ++k) {
            if (!cvalid[k]) continue;
            ++n_valid;
            lit[static_cast<size_t>(k)] = receives(bvh, l, corner[k], rays) ? 1 : 0;
            if (!lit[static_cast<size_t>(k)]) continue;
            ++n_lit;
            const double d2 = l.directional ? 1.0 : dot(l.position - corner[k], l.position - corner[k]);
            strength = std::max(strength, l.intensity / std::max(d2, 1e-12));
        }
        if (n_lit == 0 || n_lit == n_valid) continue;  // no shadow edge between the corners
        if (chosen < 0 || strength > chosen_strength) {
            chosen = static_cast<int>(li);
            chosen_strength = strength;
            chosen_lit = lit;
        }
    }
    if (chosen < 0) return false;
    const ShadowLight& l = lights[static_cast<size_t>(chosen)];
    for (size_t j = 0; j < pts.size(); ++j) {
        const std::uint8_t pt_lit = receives(bvh, l, pts[j], rays) ? 1 : 0;
        for (int k = 0; k < 8; ++k) {
            if (!cvalid[k] || !vis[j][static_cast<size_t>(k)] || pt_lit == chosen_lit[static_cast<size_t>(k)]) continue;
            vis[j][static_cast<size_t>(k)] = 0;
            Vec3 a = pts[j], b = corner[k];
            for (int step = 0; step < 6; ++step) {
                const Vec3 m = 0.5 * (a + b);
                ((receives(bvh, l, m, rays) ? 1 : 0) == pt_lit ? a : b) = m;
            }
            edge.push_back(0.5 * (a + b));
        }
    }
    return true;
}

CellFit fit_one_cell(const OccluderBvh& bvh, const ProbeGrid& g, const std::vector<Vec3>& baked,
                     const std::vector<std::uint8_t>& valid, int lattice, std::span<const ShadowLight> lights, bool regions,
                     std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    CellFit out;
    const std::uint32_t base[3] = {x, y, z};
    Vec3 corner[8];
    bool cvalid[8];
    for (int k = 0; k < 8; ++k) {
        std::uint32_t idx[3];
        for (int a = 0; a < 3; ++a) idx[a] = std::min(base[a] + std::uint32_t((k >> a) & 1), g.counts[static_cast<size_t>(a)] - 1);
        const std::size_t i = grid_index(g, idx[0], idx[1], idx[2]);
        corner[k] = baked[i];
        cvalid[k] = valid[i] != 0;
    }
    // The cell's sample points: lattice^3 (1 along an axis of count 1: the probes' own plane).
    int L[3];
    for (int a = 0; a < 3; ++a) L[a] = g.counts[static_cast<size_t>(a)] > 1 ? lattice : 1;
    Vec3 lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
        const double o = g.origin[a] + base[a] * g.spacing[a];
        set_axis(lo, a, o);
        set_axis(hi, a, g.counts[static_cast<size_t>(a)] > 1 ? o + g.spacing[a] : o);
    }
    for (const Vec3& q : corner)
        for (int a = 0; a < 3; ++a) {
            set_axis(lo, a, std::min(lo[a], q[a]));
            set_axis(hi, a, std::max(hi[a], q[a]));
        }
    // Every segment lies in the box around the cell and its corners: nothing there to block them
    // (the shadow of a light may still cross the cell).
    const bool near_occluder = bvh.overlaps_box(lo, hi);
    if (!near_occluder && lights.empty()) return out;
    std::vector<Vec3> pts;
    for (int kz = 0; kz < L[2]; ++kz)
        for (int ky = 0; ky < L[1]; ++ky)
            for (int kx = 0; kx < L[0]; ++kx) {
                const int kk[3] = {kx, ky, kz};
                Vec3 q{};
                for (int a = 0; a < 3; ++a)
                    set_axis(q, a, g.counts[static_cast<size_t>(a)] > 1 ? g.origin[a] + (base[a] + (kk[a] + 0.5) / L[a]) * g.spacing[a]
                                                                        : g.origin[a] + base[a] * g.spacing[a]);
                if (!bvh.inside_any_solid(q)) pts.push_back(q);
            }
    std::vector<std::array<std::uint8_t, 8>> vis(pts.size());
    std::vector<Vec3> hits;
    for (size_t j = 0; j < pts.size(); ++j)
        for (int k = 0; k < 8; ++k) {
            vis[j][static_cast<size_t>(k)] = 1;
            if (!cvalid[k] || !near_occluder) continue;
            const Vec3 v = corner[k] - pts[j];
            const double len = length(v);
            if (!(len > 2 * kRayEpsilon)) continue;
            const Vec3 d = (1.0 / len) * v;
            ++out.stats.rays;
            const RayHit h = bvh.nearest(pts[j], d, kRayEpsilon, len - kRayEpsilon);
            if (!h.hit) continue;
            vis[j][static_cast<size_t>(k)] = 0;
            hits.push_back(pts[j] + h.t * d);
            ++out.stats.rays;
            const RayHit h2 = bvh.nearest(corner[k], -1.0 * d, kRayEpsilon, len - kRayEpsilon);
            if (h2.hit) hits.push_back(corner[k] - h2.t * d);
        }
    // Blocked by geometry only: what a corner region is scored on (a copy only where one may be tried).
    const std::vector<std::array<std::uint8_t, 8>> vis_geometry = regions && !hits.empty() ? vis : decltype(vis){};
    std::vector<Vec3> edge;
    const bool shadowed = split_at_shadow_edge(bvh, lights, corner, cvalid, pts, vis, edge, &out.stats.rays) && !edge.empty();
    if (hits.empty() && !shadowed) return out;
    ++out.stats.crossed_cells;
    std::uint64_t blocked = 0, best_wrong = 0, best_leaking = 0;
    out.plane = best_plane(g, x, y, z, hits, edge, pts, vis, corner, cvalid, &blocked, &best_wrong, &best_leaking);
    // A corner region replaces the plane where geometry crosses the cell, the plane predicts over
    // a tenth of the geometry-blocked pairs wrongly, and the region at most half as many (a closed
    // box's inside: three faces around one corner), also when the cell holds a shadow edge too (light
    // through walls first). A wall keeps its plane (which also moves probes towards it).
    if (regions && !hits.empty()) {
        std::uint64_t region_wrong = 0, unused = 0, blocked_geometry = 0;
        for (size_t j = 0; j < pts.size(); ++j)
            for (int k = 0; k < 8; ++k) blocked_geometry += cvalid[k] && vis_geometry[j][static_cast<size_t>(k)] == 0;
        const std::uint64_t plane_wrong = entry_wrong(out.plane, g, x, y, z, pts, vis_geometry, cvalid, &unused);
        const CellPlane region = 10 * plane_wrong > blocked_geometry ? best_region(g, x, y, z, hits, pts, vis_geometry, cvalid, &region_wrong)
                                                                     : CellPlane{};
        std::uint64_t region_leaking = 0;
        const std::uint64_t region_all = region.region() ? entry_wrong(region, g, x, y, z, pts, vis, cvalid, &region_leaking) : 0;
        if (region.region() && 2 * region_wrong <= plane_wrong) {
            out.plane = region;
            best_wrong = region_all;
            best_leaking = region_leaking;
        }
    }
    if (shadowed && out.plane.any()) ++out.stats.shadow_planes;
    if (out.plane.region()) ++out.stats.regions;
    if (!out.plane.any()) {
        out.stats.unresolved_pairs += blocked;
        return out;
    }
    std::uint64_t scored = 0;
    for (int k = 0; k < 8; ++k) scored += cvalid[k] ? pts.size() : 0;
    ++out.stats.planes;
    out.stats.pairs += scored;
    out.stats.blocked_pairs += blocked;
    out.stats.wrong_pairs += best_wrong;
    out.stats.leaking_pairs += best_leaking;
    out.stats.dropped_pairs += best_wrong - best_leaking;
    out.wrong_fraction = blocked ? double(best_wrong) / double(blocked) : 0.0;
    return out;
}

}  // namespace

Vec3 smallest_eigenvector(double a[3][3]) {
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 32; ++sweep) {
        const double off = std::fabs(a[0][1]) + std::fabs(a[0][2]) + std::fabs(a[1][2]);
        if (off < 1e-15) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (std::fabs(a[p][q]) < 1e-300) continue;
                const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                const double t = (theta >= 0 ? 1 : -1) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
                const double c = 1 / std::sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; ++k) {  // A = J^T A J
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    int m = 0;
    for (int i = 1; i < 3; ++i)
        if (a[i][i] < a[m][m]) m = i;
    return {v[0][m], v[1][m], v[2][m]};
}

Vec3 cell_plane_normal(std::uint8_t ou, std::uint8_t ov) {
    double a = double(ou < 254 ? ou : 254) / 127.0 - 1.0, b = double(ov < 254 ? ov : 254) / 127.0 - 1.0;
    const double z = 1.0 - std::fabs(a) - std::fabs(b);
    if (z < 0.0) {
        const double a0 = a;
        a = (1.0 - std::fabs(b)) * (a0 < 0.0 ? -1.0 : 1.0);
        b = (1.0 - std::fabs(a0)) * (b < 0.0 ? -1.0 : 1.0);
    }
    const double l = std::sqrt(a * a + b * b + z * z);
    return {a / l, b / l, z / l};
}

void encode_cell_plane_normal(Vec3 n, std::uint8_t* ou, std::uint8_t* ov) {
    n = unit_or_z(n);
    const double s = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
    double a = n.x / s, b = n.y / s;
    if (n.z < 0) {
        const double a0 = a;
        a = (1 - std::fabs(b)) * (a0 < 0 ? -1 : 1);
        b = (1 - std::fabs(a0)) * (b < 0 ? -1 : 1);
    }
    const int u0 = int(std::lround((a + 1) * 127)), v0 = int(std::lround((b + 1) * 127));
    double best = -2;
    for (int du = -1; du <= 1; ++du)
        for (int dv = -1; dv <= 1; ++dv) {
            const int u = std::clamp(u0 + du, 0, 254), v = std::clamp(v0 + dv, 0, 254);
            const double c = dot(cell_plane_normal(std::uint8_t(u), std::uint8_t(v)), n);
            if (c > best) {
                best = c;
                *ou = std::uint8_t(u);
                *ov = std::uint8_t(v);
            }
        }
}

double cell_plane_unit(const ProbeGrid& g) {
    return std::sqrt(g.spacing.x * g.spacing.x + g.spacing.y * g.spacing.y + g.spacing.z * g.spacing.z) / 65534.0;
}

Vec3 cell_centre(const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return {g.origin.x + (x + 0.5) * g.spacing.x, g.origin.y + (y + 0.5) * g.spacing.y, g.origin.z + (z + 0.5) * g.spacing.z};
}

double cell_plane_value(const CellPlane& cp, const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z, Vec3 q) {
    // The runtime's operations and order (zhc__volume_plane_side): -offset unit, then per axis.
    const Vec3 n = cell_plane_normal(cp.ou, cp.ov);
    const std::uint32_t idx[3] = {x, y, z};
    double s = -double(cp.offset) * cell_plane_unit(g);
    for (int a = 0; a < 3; ++a) s += n[a] * (q[a] - (g.origin[a] + (double(idx[a]) + 0.5) * g.spacing[a]));
    return s;
}

CellPlane cell_region(int qx, int qy, int qz, int anchor) {
    CellPlane cp;
    const unsigned r = unsigned(qx & 31) | unsigned(qy & 31) << 5 | unsigned(qz & 31) << 10;
    cp.ou = static_cast<std::uint8_t>(r & 0xFFu);
    cp.ov = static_cast<std::uint8_t>(r >> 8);
    cp.offset = CellPlane::kNoPlane;
    cp.sides = static_cast<std::uint8_t>(0x80u | (unsigned(anchor) & 7u));
    return cp;
}

int cell_region_threshold(const CellPlane& cp, int a) { return int(((unsigned(cp.ou) | unsigned(cp.ov) << 8) >> (5 * a)) & 31u); }

std::uint8_t cell_region_corners(const CellPlane& cp) {
    std::uint8_t inside = 0xFF;
    for (int a = 0; a < 3; ++a) {
        if (cell_region_threshold(cp, a) == 0) continue;
        const unsigned d = (cp.sides >> a) & 1u;
        for (int k = 0; k < 8; ++k)
            if (unsigned((k >> a) & 1) != d) inside = static_cast<std::uint8_t>(inside & ~(1u << k));
    }
    return inside;
}

bool cell_region_inside(const CellPlane& cp, const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z, Vec3 q) {
    // The runtime's operations (zhc__volume_plane_side): one subtraction, one product, one comparison per axis.
    const std::uint32_t i0[3] = {x, y, z};
    for (int a = 0; a < 3; ++a) {
        const int qa = cell_region_threshold(cp, a);
        if (qa == 0) continue;
        const double s_a = (q[a] - (g.origin[a] + double(i0[a]) * g.spacing[a])) * 31.0, t_a = double(qa) * g.spacing[a];
        if (!(((cp.sides >> a) & 1u) ? s_a >= t_a : s_a < t_a)) return false;
    }
    return true;
}

std::vector<std::uint8_t> cell_planes_bytes(const std::vector<CellPlane>& planes) {
    std::vector<std::uint8_t> out(5 * planes.size());
    for (size_t i = 0; i < planes.size(); ++i) {
        const std::uint16_t off = static_cast<std::uint16_t>(planes[i].offset);
        out[5 * i] = planes[i].ou;
        out[5 * i + 1] = planes[i].ov;
        out[5 * i + 2] = static_cast<std::uint8_t>(off & 0xFF);
        out[5 * i + 3] = static_cast<std::uint8_t>(off >> 8);
        out[5 * i + 4] = planes[i].sides;
    }
    return out;
}

std::vector<CellPlane> cell_planes_from_bytes(const std::vector<std::uint8_t>& bytes) {
    std::vector<CellPlane> out(bytes.size() / 5);
    for (size_t i = 0; i < out.size(); ++i) {
        out[i].ou = bytes[5 * i];
        out[i].ov = bytes[5 * i + 1];
        out[i].offset = static_cast<std::int16_t>(static_cast<std::uint16_t>(bytes[5 * i + 2] | (bytes[5 * i + 3] << 8)));
        out[i].sides = bytes[5 * i + 4];
    }
    return out;
}

std::vector<CellPlane> fit_cell_planes(const OccluderBvh& bvh, const ProbeGrid& g, const std::vector<Vec3>& baked,
                                       const std::vector<std::uint8_t>& valid, int lattice, int threads,
                                       PlaneFitStats* stats, std::vector<double>* wrong_fraction,
                                       std::span<const ShadowLight> shadow_lights, bool regions) {
    const std::size_t count = std::size_t(g.counts[0]) * g.counts[1] * g.counts[2];
    std::vector<CellPlane> out(count);
    std::vector<double> wrong(count, 0.0);
    std::vector<PlaneFitStats> per(count);
    if (!bvh.empty())
        parallel_blocks(count, 16, threads, [&](size_t lo, size_t hi, int) {
            for (size_t i = lo; i < hi; ++i) {
                const std::uint32_t x = axis_index(i, g, 0), y = axis_index(i, g, 1), z = axis_index(i, g, 2);
                if (!starts_cell(g, x, y, z)) continue;
                const CellFit f = fit_one_cell(bvh, g, baked, valid, std::max(1, lattice), shadow_lights, regions, x, y, z);
                out[i] = f.plane;
                wrong[i] = f.wrong_fraction;
                per[i] = f.stats;
            }
        });
    if (stats) {
        *stats = {};
        for (size_t i = 0; i < count; ++i) {
            stats->cells += starts_cell(g, axis_index(i, g, 0), axis_index(i, g, 1), axis_index(i, g, 2)) ? 1 : 0;
            stats->crossed_cells += per[i].crossed_cells;
            stats->planes += per[i].planes;
            stats->pairs += per[i].pairs;
            stats->blocked_pairs += per[i].blocked_pairs;
            stats->wrong_pairs += per[i].wrong_pairs;
            stats->leaking_pairs += per[i].leaking_pairs;
            stats->dropped_pairs += per[i].dropped_pairs;
            stats->unresolved_pairs += per[i].unresolved_pairs;
            stats->shadow_planes += per[i].shadow_planes;
            stats->regions += per[i].regions;
            stats->rays += per[i].rays;
        }
    }
    if (wrong_fraction) *wrong_fraction = std::move(wrong);
    return out;
}

bool inside_geometry(const OccluderBvh& bvh, const InsideTest& test, Vec3 p, std::uint64_t* rays) {
    if (bvh.inside_any_solid(p)) return true;
    if (!test.dirs) return false;
    const std::uint64_t n = test.dirs->size();
    std::uint64_t back = 0, seen = 0;
    for (const Vec3& d : *test.dirs) {
        ++*rays;
        ++seen;
        const RayHit h = bvh.nearest(p, d, kRayEpsilon, std::numeric_limits<double>::infinity());
        back += h.back;
        if (back > test.invalid_limit) return true;
        if (back + (n - seen) <= test.invalid_limit) return false;  // the rest cannot reach the limit
    }
    return false;
}

ProbeRelocation relocate_grid_probes(const OccluderBvh& bvh, const ProbeGrid& g, const InsideTest& test,
                                     const LeakPlacementOptions& options, bool move, int threads) {
    ProbeRelocation r;
    const std::size_t count = std::size_t(g.counts[0]) * g.counts[1] * g.counts[2];
    const double h = min_spacing(g), rad = options.clearance * h;
    r.positions.resize(count);
    r.valid.assign(count, 1);
    std::vector<std::uint8_t> kind(count, 0);  // 1 moved out, 2 left inside, 3 left near
    std::vector<std::uint64_t> rays(count, 0);
    parallel_blocks(count, 64, threads, [&](size_t lo, size_t hi, int) {
        for (size_t i = lo; i < hi; ++i) {
            const Vec3 p = grid_point(g, i);
            r.positions[i] = p;
            std::uint64_t* ri = &rays[i];
            const bool inside = inside_geometry(bvh, test, p, ri);
            if (!move) {
                r.valid[i] = inside ? 0 : 1;
                continue;
            }
            if (!inside && !near_geometry(bvh, p, rad, ri)) continue;
            bool found = false;
            const int steps = static_cast<int>(std::floor((0.5 * h) / (0.5 * rad) + 1e-9));
            for (int k = 1; k <= steps && !found; ++k) {
                const double s = 0.5 * rad * k;
                for (const Vec3& d : directions26())
                    if (clear_point(bvh, test, p + s * d, rad, ri)) {
                        r.positions[i] = p + s * d;
                        kind[i] = 1;
                        found = true;
                        break;
                    }
            }
            if (!found) {
                kind[i] = inside ? 2 : 3;
                r.valid[i] = inside ? 0 : 1;
            }
        }
    });
    for (size_t i = 0; i < count; ++i) {
        r.moved_out += kind[i] == 1;
        r.left_inside += kind[i] == 2;
        r.left_near += kind[i] == 3;
        r.rays += rays[i];
    }
    if (!move) return r;

    // Towards walls: the first fit with the probes where step 1 put them.
    std::vector<double> wrong;
    // Planes only: relocation moves probes towards the walls planes describe.
    const std::vector<CellPlane> first =
        fit_cell_planes(bvh, g, r.positions, r.valid, options.lattice, threads, &r.first_fit, &wrong, {}, /*regions=*/false);
    r.rays += r.first_fit.rays;
    std::vector<Vec3> moved = r.positions;
    std::vector<std::uint8_t> did(count, 0);
    std::fill(rays.begin(), rays.end(), 0);
    parallel_blocks(count, 64, threads, [&](size_t lo, size_t hi, int) {
        for (size_t i = lo; i < hi; ++i) {
            if (!r.valid[i]) continue;
            const std::uint32_t idx[3] = {axis_index(i, g, 0), axis_index(i, g, 1), axis_index(i, g, 2)};
            Vec3 best{};
            double best_len = 0;
            for (int k = 0; k < 8; ++k) {  // the cell in which probe i is corner k
                long c[3];
                bool ok = true;
                for (int a = 0; a < 3; ++a) {
                    const long n = long(g.counts[static_cast<size_t>(a)]);
                    c[a] = long(idx[a]) - ((k >> a) & 1);
                    if (n > 1 ? (c[a] < 0 || c[a] + 1 >= n) : (k >> a) & 1) ok = false;
                }
                if (!ok) continue;
                const std::size_t ci = grid_index(g, std::uint32_t(c[0]), std::uint32_t(c[1]), std::uint32_t(c[2]));
                const CellPlane& cp = first[ci];
                if (!cp.present() || wrong[ci] > options.max_wrong) continue;
                const Vec3 nq = cell_plane_normal(cp.ou, cp.ov);
                const double sd = cell_plane_value(cp, g, std::uint32_t(c[0]), std::uint32_t(c[1]), std::uint32_t(c[2]), r.positions[i]);
                if (std::fabs(sd) <= options.reach * h) continue;
                const double len = std::fabs(sd) - options.reach * h;
                if (len > best_len) {
                    best_len = len;
                    best = (sd > 0 ? -len : len) * nq;
                }
            }
            if (best_len <= 0) continue;
            const Vec3 q = r.positions[i] + best;
            if (!clear_point(bvh, test, q, rad, &rays[i])) continue;
            ++rays[i];
            if (bvh.occluded(r.positions[i], unit_or_z(best), kRayEpsilon, best_len)) continue;
            moved[i] = q;
            did[i] = 1;
        }
    });
    for (size_t i = 0; i < count; ++i) {
        r.moved_towards += did[i];
        r.rays += rays[i];
    }
    r.positions = std::move(moved);
    return r;
}

}  // namespace zhc
