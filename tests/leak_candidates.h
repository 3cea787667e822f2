// Candidate visibility schemes for probe volumes, measured on the leak suite (tests/leak_scenes.h,
// docs/leaks.md "Candidates"): prototypes in plain C++, bake side (functions taking the scene's
// OccluderBvh and probe grid) and sample side (one sampler skeleton), not the shipped runtimes.
//
// Sampler skeleton (every scheme): the trilinear weights of the 8 corner probes of the cell that
// contains the shading point x (zhc__volume_axis: clamped to the grid's box), each corner kept or
// dropped by the scheme, the kept weights divided by their sum (summed over corners 0..7 in order),
// the plain weights when nothing is kept; then the blended SH3 evaluated for the normal exactly as
// zhc_volume_irradiance_d does. So a constant field stays constant under every scheme, "plain" is
// zhc_volume_irradiance on a volume without leak data bit for bit and "masks" is it on a volume
// with validity + visibility bit for bit (test_leak_candidates checks both).
//
// Schemes (the tests are made at x_b = x + bias * min(spacing) * n, the normal-biased point;
// trilinear weights always at x):
//  * kPlain: every corner;
//  * kMasks: today's validity + 8-bit masks (runtime/zhc_runtime.h zhc_volume_sh3);
//  * kPlane: one separating plane per cell crossed by geometry (CellPlane: octahedral normal 2 x 8
//    bits, 16-bit offset from the cell's centre, 8 bits saying on which side each corner's probe
//    was baked): corner k is kept when it is valid and its side bit equals the side of x_b;
//  * kOctant: per probe one 8-bit distance per octant (the 8 cells around it): corner k is kept
//    when |x_b - p_k| <= the distance of its octant that holds the cell (code 0: invalid probe).
// Bake side: cell_planes() fits the planes by tracing segments between sample points of the cell
// and its corners; octant_distances() traces a fan of rays per octant; relocate_probes() moves
// probes that lie inside or near geometry to the nearest clear point, relocate_towards_planes()
// moves probes far from a wall that crosses one of their cells towards it (a moved probe is baked
// there, nothing is stored; the sampler still weights it at its grid position); masks_at() traces
// today's masks to the baked positions. build_candidates() assembles every candidate of one scene
// (docs/leaks.md "Candidates"; the chosen one is "reloc2+plane").
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "codec/bake/bake_internal.h"
#include "leak_scenes.h"

namespace zhc::leak {

// ---- grid helpers -------------------------------------------------------------------------------

struct GridInfo {
    Vec3 origin, spacing;
    std::uint32_t n[3] = {1, 1, 1};
    std::size_t count() const { return std::size_t(n[0]) * n[1] * n[2]; }
    std::size_t index(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
        return std::size_t(x) + std::size_t(n[0]) * (std::size_t(y) + std::size_t(n[1]) * z);
    }
    Vec3 position(std::size_t i) const {
        const std::uint32_t x = std::uint32_t(i % n[0]), y = std::uint32_t((i / n[0]) % n[1]),
                            z = std::uint32_t(i / (std::size_t(n[0]) * n[1]));
        return {origin.x + x * spacing.x, origin.y + y * spacing.y, origin.z + z * spacing.z};
    }
    double min_spacing() const { return std::min({spacing.x, spacing.y, spacing.z}); }
};

inline GridInfo grid_of(const Scene& s) {
    const ProbeLayout layout = probe_layout(s.probes);
    GridInfo g;
    g.origin = layout.grid.origin;
    g.spacing = layout.grid.spacing;
    for (int a = 0; a < 3; ++a) g.n[a] = layout.grid.counts[static_cast<size_t>(a)];
    return g;
}

inline Vec3 normalized(Vec3 v) {
    const double l = length(v);
    return l > 0 ? (1.0 / l) * v : Vec3{0, 0, 1};
}

// ---- the separating plane per cell (candidate 1) ------------------------------------------------

// 5 bytes per cell, as a runtime reads them: octahedral normal (ou, ov: 0..254, value code / 127 - 1, so
// the axes are exact), the plane's signed offset
// from the cell's centre along that normal in units of |spacing| / 65534 (offset kNoPlane: the cell
// has no plane, every valid corner is kept), and bit k of `sides`: corner k's probe lies on the
// plane's positive side.
struct CellPlane {
    static constexpr std::int16_t kNoPlane = std::numeric_limits<std::int16_t>::min();
    std::uint8_t ou = 0, ov = 0;
    std::int16_t offset = kNoPlane;
    std::uint8_t sides = 0;
};
constexpr double kPlaneBytesPerCell = 5;

// The stored code's normal and the nearest code: the bake's own (codec/bake/leak_planes.h), so the
// prototype's planes mean what the runtime reads.
inline Vec3 oct_decode(std::uint8_t ou, std::uint8_t ov) { return cell_plane_normal(ou, ov); }

inline void oct_encode(Vec3 n, std::uint8_t* ou, std::uint8_t* ov) { encode_cell_plane_normal(n, ou, ov); }

// Centre of the cell whose corner 0 is probe (x, y, z).
inline Vec3 cell_centre(const GridInfo& g, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return {g.origin.x + (x + 0.5) * g.spacing.x, g.origin.y + (y + 0.5) * g.spacing.y, g.origin.z + (z + 0.5) * g.spacing.z};
}

inline double plane_unit(const GridInfo& g) { return length(g.spacing) / 65534.0; }

// Signed distance of q from the quantised plane (cell centre c).
inline double plane_side_value(const CellPlane& cp, Vec3 normal, Vec3 c, double unit, Vec3 q) {
    return dot(normal, q - c) - cp.offset * unit;
}

struct PlaneFitOptions {
    int lattice = 4;  // lattice^3 sample points per cell, at (i + 0.5) / lattice
};

struct PlaneFitStats {
    std::size_t cells = 0, blocked_cells = 0, planes = 0, second_planes = 0;
    std::size_t pairs = 0, blocked_pairs = 0, wrong_pairs = 0;  // (sample point, corner) pairs of cells with a plane
    std::uint64_t rays = 0;
};

// Fits one plane per cell. `baked` holds each probe's baked position (the grid's, or a relocated
// one), `valid` its validity (invalid corners are neither scored nor kept). Per cell: the sample
// points (a lattice, minus points inside solids) and the corners; every (point, corner) segment is
// traced; if some are blocked, candidate planes (the PCA plane of the blocked segments' hit points
// on both faces, and per axis the axis-aligned planes at the hits' minimum, maximum, middle and
// median) are quantised and scored by the pairs whose visibility they predict wrongly (same side =
// visible); the best one is kept when it predicts fewer pairs wrongly than no plane (every pair
// visible). Result: one CellPlane per probe index (the cell whose corner 0 it is; kNoPlane on the
// last probe of an axis).
inline std::vector<CellPlane> cell_planes(const OccluderBvh& bvh, const GridInfo& g, const std::vector<Vec3>& baked,
                                          const std::vector<std::uint8_t>& valid, const PlaneFitOptions& opt = {},
                                          PlaneFitStats* stats = nullptr, std::vector<CellPlane>* second = nullptr,
                                          std::vector<double>* wrong_fraction = nullptr) {
    std::vector<CellPlane> out(g.count());
    if (wrong_fraction) wrong_fraction->assign(g.count(), 0.0);
    if (second) second->assign(g.count(), CellPlane{});
    PlaneFitStats st;
    const double unit = plane_unit(g);
    const std::uint32_t cx = std::max(1u, g.n[0] - 1), cy = std::max(1u, g.n[1] - 1), cz = std::max(1u, g.n[2] - 1);
    for (std::uint32_t z = 0; z < cz; ++z)
        for (std::uint32_t y = 0; y < cy; ++y)
            for (std::uint32_t x = 0; x < cx; ++x) {
                ++st.cells;
                const Vec3 c = cell_centre(g, x, y, z);
                Vec3 corner[8];
                bool cvalid[8];
                for (int k = 0; k < 8; ++k) {
                    const std::uint32_t ix = std::min(x + (k & 1), g.n[0] - 1), iy = std::min(y + ((k >> 1) & 1), g.n[1] - 1),
                                        iz = std::min(z + ((k >> 2) & 1), g.n[2] - 1);
                    const std::size_t i = g.index(ix, iy, iz);
                    corner[k] = baked[i];
                    cvalid[k] = valid[i] != 0;
                }
                std::vector<Vec3> pts;
                const int L = opt.lattice;
                for (int k = 0; k < L * L * L; ++k) {
                    const Vec3 q{g.origin.x + (x + (k % L + 0.5) / L) * g.spacing.x,
                                 g.origin.y + (y + ((k / L) % L + 0.5) / L) * g.spacing.y,
                                 g.origin.z + (z + (k / (L * L) + 0.5) / L) * g.spacing.z};
                    if (!bvh.inside_any_solid(q)) pts.push_back(q);
                }
                std::vector<std::array<std::uint8_t, 8>> vis(pts.size());
                std::vector<Vec3> hits;
                bool any_blocked = false;
                for (size_t j = 0; j < pts.size(); ++j)
                    for (int k = 0; k < 8; ++k) {
                        vis[j][k] = 1;
                        if (!cvalid[k]) continue;
                        const Vec3 v = corner[k] - pts[j];
                        const double len = length(v);
                        if (!(len > 1e-9)) continue;
                        const Vec3 d = (1.0 / len) * v;
                        ++st.rays;
                        const RayHit h = bvh.nearest(pts[j], d, 1e-9, len - 1e-9);
                        if (!h.hit) continue;
                        vis[j][k] = 0;
                        any_blocked = true;
                        hits.push_back(pts[j] + h.t * d);
                        ++st.rays;
                        const RayHit h2 = bvh.nearest(corner[k], -1.0 * d, 1e-9, len - 1e-9);
                        if (h2.hit) hits.push_back(corner[k] - h2.t * d);
                    }
                if (!any_blocked) continue;
                ++st.blocked_cells;
                // Candidate planes (normal, point on it).
                std::vector<std::pair<Vec3, Vec3>> cand;
                Vec3 mean{};
                for (const Vec3& h : hits) mean = mean + h;
                mean = (1.0 / double(hits.size())) * mean;
                double cov[3][3] = {};
                for (const Vec3& h : hits) {
                    const Vec3 d = h - mean;
                    for (int r = 0; r < 3; ++r)
                        for (int s = 0; s < 3; ++s) cov[r][s] += d[r] * d[s];
                }
                cand.push_back({zhc::smallest_eigenvector(cov), mean});
                for (int a = 0; a < 3; ++a) {
                    std::vector<double> coord;
                    for (const Vec3& h : hits) coord.push_back(h[a]);
                    std::sort(coord.begin(), coord.end());
                    Vec3 n{};
                    set_axis(n, a, 1);
                    for (double v : {coord.front(), coord.back(), 0.5 * (coord.front() + coord.back()), coord[coord.size() / 2]}) {
                        Vec3 p = c;
                        set_axis(p, a, v);
                        cand.push_back({n, p});
                    }
                }
                std::size_t blocked = 0, scored = 0;
                for (size_t j = 0; j < pts.size(); ++j)
                    for (int k = 0; k < 8; ++k)
                        if (cvalid[k]) {
                            ++scored;
                            blocked += vis[j][k] == 0;
                        }
                // Quantised candidates with their side bits and per-point sides.
                std::vector<CellPlane> qc;
                std::vector<std::vector<std::uint8_t>> qside;
                for (const auto& [n, p] : cand) {
                    CellPlane cp;
                    oct_encode(n, &cp.ou, &cp.ov);
                    const Vec3 nq = oct_decode(cp.ou, cp.ov);
                    const double off = dot(nq, p - c) / unit;
                    if (!(std::fabs(off) < 32767)) continue;
                    cp.offset = std::int16_t(std::lround(off));
                    for (int k = 0; k < 8; ++k)
                        if (plane_side_value(cp, nq, c, unit, corner[k]) >= 0) cp.sides = std::uint8_t(cp.sides | (1u << k));
                    std::vector<std::uint8_t> sd(pts.size());
                    for (size_t j = 0; j < pts.size(); ++j) sd[j] = plane_side_value(cp, nq, c, unit, pts[j]) >= 0;
                    qc.push_back(cp);
                    qside.push_back(std::move(sd));
                }
                // Wrong pairs of the planes a (and b, -1: none): visible predicted = same side of both.
                auto wrong_of = [&](int a, int b) {
                    std::size_t wrong = 0;
                    for (size_t j = 0; j < pts.size(); ++j)
                        for (int k = 0; k < 8; ++k) {
                            if (!cvalid[k]) continue;
                            bool keep = ((qc[size_t(a)].sides >> k) & 1) == qside[size_t(a)][j];
                            if (b >= 0) keep = keep && ((qc[size_t(b)].sides >> k) & 1) == qside[size_t(b)][j];
                            wrong += keep != (vis[j][k] != 0);
                        }
                    return wrong;
                };
                std::size_t best_wrong = blocked;  // no plane: every blocked pair is wrong
                int best = -1, best2 = -1;
                for (int a = 0; a < int(qc.size()); ++a) {
                    const std::size_t w = wrong_of(a, -1);
                    if (w < best_wrong) {
                        best_wrong = w;
                        best = a;
                    }
                }
                if (best < 0) continue;
                if (second && best_wrong > 0) {
                    std::size_t w2best = best_wrong;
                    for (int b = 0; b < int(qc.size()); ++b) {
                        if (b == best) continue;
                        const std::size_t w = wrong_of(best, b);
                        if (w < w2best) {
                            w2best = w;
                            best2 = b;
                        }
                    }
                    if (best2 >= 0) {
                        (*second)[g.index(x, y, z)] = qc[size_t(best2)];
                        ++st.second_planes;
                        best_wrong = w2best;
                    }
                }
                ++st.planes;
                st.pairs += scored;
                st.blocked_pairs += blocked;
                st.wrong_pairs += best_wrong;
                out[g.index(x, y, z)] = qc[size_t(best)];
                if (wrong_fraction) (*wrong_fraction)[g.index(x, y, z)] = blocked ? double(best_wrong) / double(blocked) : 0.0;
            }
    if (stats) *stats = st;
    return out;
}

// ---- per-probe distance per octant (candidate 2) ------------------------------------------------

enum class OctantStat : std::uint8_t { kMin, kMean };

// 8 bytes per probe: code 0 = invalid probe (or geometry at the probe), else the distance
// (code - 1) / 254 x |spacing| (the cell's diagonal) to the nearest hit in octant o (bit a of o: +axis
// a), the min (rounded down) or mean (rounded) over a fan of 27 rays in the octant, each capped at
// the diagonal.
inline std::vector<std::array<std::uint8_t, 8>> octant_distances(const OccluderBvh& bvh, const GridInfo& g,
                                                                 const std::vector<Vec3>& baked,
                                                                 const std::vector<std::uint8_t>& valid, OctantStat stat,
                                                                 std::uint64_t* rays = nullptr) {
    const double diag = length(g.spacing);
    std::vector<std::array<std::uint8_t, 8>> out(g.count());
    const double comp[3] = {0.02, 0.5, 1.0};
    for (std::size_t i = 0; i < g.count(); ++i) {
        for (int o = 0; o < 8; ++o) {
            std::uint8_t code = 0;
            if (valid[i] && !bvh.inside_any_solid(baked[i])) {
                double mn = diag, sum = 0;
                int cnt = 0;
                for (int t = 0; t < 27; ++t) {
                    const Vec3 d = normalized({(o & 1 ? 1 : -1) * comp[t % 3], (o & 2 ? 1 : -1) * comp[(t / 3) % 3],
                                               (o & 4 ? 1 : -1) * comp[t / 9]});
                    if (rays) ++*rays;
                    const RayHit h = bvh.nearest(baked[i], d, 1e-9, diag);
                    const double dist = h.hit ? h.t : diag;
                    mn = std::min(mn, dist);
                    sum += dist;
                    ++cnt;
                }
                const double v = (stat == OctantStat::kMin ? mn : sum / cnt) / diag * 254.0;
                code = std::uint8_t(1 + std::clamp(stat == OctantStat::kMin ? std::floor(v) : std::round(v), 0.0, 254.0));
            }
            out[i][static_cast<size_t>(o)] = code;
        }
    }
    return out;
}

// ---- probe relocation (candidate 3) -------------------------------------------------------------

struct Relocation {
    std::vector<Vec3> positions;       // where each probe is baked
    std::vector<std::uint8_t> moved;   // 1: moved
    std::size_t moved_count = 0, stuck = 0;  // stuck: needed moving, no clear point found
};

// Clear: outside every solid, and no geometry within r along 26 directions.
inline bool clear_point(const OccluderBvh& bvh, Vec3 p, double r) {
    if (bvh.inside_any_solid(p)) return false;
    for (int k = 0; k < 27; ++k) {
        if (k == 13) continue;
        const Vec3 d = normalized({double(k % 3 - 1), double((k / 3) % 3 - 1), double(k / 9 - 1)});
        if (bvh.occluded(p, d, 0.0, r)) return false;
    }
    return true;
}

// Probes not clear at radius `clearance` x min(spacing) move to the nearest clear point of
// p + s d, d over the 26 directions (axes first, then edges, then corners; in index order),
// s = clearance / 2, clearance, ... up to half the spacing.
inline Relocation relocate_probes(const OccluderBvh& bvh, const GridInfo& g, double clearance = 0.1) {
    Relocation r;
    const double h = g.min_spacing(), rad = clearance * h;
    std::vector<Vec3> dirs;
    for (int kind = 1; kind <= 3; ++kind)
        for (int k = 0; k < 27; ++k) {
            const int dx = k % 3 - 1, dy = (k / 3) % 3 - 1, dz = k / 9 - 1;
            if (std::abs(dx) + std::abs(dy) + std::abs(dz) == kind) dirs.push_back(normalized({double(dx), double(dy), double(dz)}));
        }
    for (std::size_t i = 0; i < g.count(); ++i) {
        const Vec3 p = g.position(i);
        r.positions.push_back(p);
        r.moved.push_back(0);
        if (clear_point(bvh, p, rad)) continue;
        bool found = false;
        for (double s = 0.5 * rad; s <= 0.5 * h + 1e-12 && !found; s += 0.5 * rad)
            for (const Vec3& d : dirs)
                if (clear_point(bvh, p + s * d, rad)) {
                    r.positions.back() = p + s * d;
                    r.moved.back() = 1;
                    ++r.moved_count;
                    found = true;
                    break;
                }
        if (!found) ++r.stuck;
    }
    return r;
}

// Today's 8-bit masks (the bake's grid_visibility_mask, codec/bake/bake_internal.h) traced to
// each probe's baked position instead of its grid position.
inline std::vector<std::uint8_t> masks_at(const OccluderBvh& bvh, const GridInfo& g, const std::vector<Vec3>& baked) {
    ProbeGrid pg;
    pg.origin = g.origin;
    pg.spacing = g.spacing;
    pg.counts = {g.n[0], g.n[1], g.n[2]};
    std::vector<std::uint8_t> out(g.count());
    std::uint64_t rays = 0;
    for (std::size_t i = 0; i < g.count(); ++i)
        out[i] = bake_detail::grid_visibility_mask(bvh, pg, std::uint32_t(i % g.n[0]), std::uint32_t((i / g.n[0]) % g.n[1]),
                                                   std::uint32_t(i / (std::size_t(g.n[0]) * g.n[1])), baked[i], &rays);
    return out;
}

// Relocation towards walls: a valid probe farther than `reach` x min(spacing) from the plane of one
// of its cells (planes fitted with the probes at `baked`; only planes that predict at most
// `max_wrong` of their cell's blocked pairs wrongly: a wall the plane describes) moves along the plane's normal to
// `reach` x min(spacing) from it (the largest such move over its cells), where that point is clear
// (clear_point at `clearance`) and on the same side of the plane. Returns the new positions
// (`moved` counts the moved probes).
inline std::vector<Vec3> relocate_towards_planes(const OccluderBvh& bvh, const GridInfo& g, const std::vector<Vec3>& baked,
                                                 const std::vector<std::uint8_t>& valid, const std::vector<CellPlane>& planes,
                                                 const std::vector<double>& wrong_fraction, double max_wrong, double reach,
                                                 double clearance, std::size_t* moved) {
    std::vector<Vec3> out = baked;
    const double h = g.min_spacing(), unit = plane_unit(g);
    std::size_t count = 0;
    for (std::size_t i = 0; i < g.count(); ++i) {
        if (!valid[i]) continue;
        const std::uint32_t idx[3] = {std::uint32_t(i % g.n[0]), std::uint32_t((i / g.n[0]) % g.n[1]),
                                      std::uint32_t(i / (std::size_t(g.n[0]) * g.n[1]))};
        Vec3 best{};
        double best_len = 0;
        for (int k = 0; k < 8; ++k) {  // the cell in which probe i is corner k
            long c[3];
            bool ok = true;
            for (int a = 0; a < 3; ++a) {
                c[a] = long(idx[a]) - ((k >> a) & 1);
                if (c[a] < 0 || c[a] + 1 >= long(g.n[a])) ok = false;
            }
            if (!ok) continue;
            const CellPlane& cp = planes[g.index(std::uint32_t(c[0]), std::uint32_t(c[1]), std::uint32_t(c[2]))];
            if (cp.offset == CellPlane::kNoPlane) continue;
            if (wrong_fraction[g.index(std::uint32_t(c[0]), std::uint32_t(c[1]), std::uint32_t(c[2]))] > max_wrong) continue;
            const Vec3 nq = oct_decode(cp.ou, cp.ov);
            const Vec3 centre = cell_centre(g, std::uint32_t(c[0]), std::uint32_t(c[1]), std::uint32_t(c[2]));
            const double sd = plane_side_value(cp, nq, centre, unit, baked[i]);
            if (std::fabs(sd) <= reach * h) continue;
            const double len = std::fabs(sd) - reach * h;
            if (len > best_len) {
                best_len = len;
                best = (sd > 0 ? -len : len) * nq;
            }
        }
        if (best_len <= 0) continue;
        const Vec3 q = baked[i] + best;
        if (!clear_point(bvh, q, clearance * h)) continue;
        const Vec3 v = q - baked[i];
        if (bvh.occluded(baked[i], normalized(v), 1e-9, length(v))) continue;
        out[i] = q;
        ++count;
    }
    if (moved) *moved = count;
    return out;
}

// ---- the sampler --------------------------------------------------------------------------------

enum class Scheme : std::uint8_t { kPlain, kMasks, kPlane, kOctant };

struct CandidateVolume {
    zhc_volume v{};  // the probes (sh3 .zhp without leak sections); validity / visibility unused
    Scheme scheme = Scheme::kPlain;
    double bias = 0;  // normal bias, fraction of min(spacing)
    // kPlane: a corner on the other side of the plane is replaced by the linear extrapolation
    // 2 P(k') - P(k'') along an axis from its kept edge neighbour k' and the probe k'' behind k'
    // (valid, inside the grid); dropped when there is none. The irradiance is clamped at 0.
    bool extrapolate = false;
    std::vector<std::uint8_t> validity, masks;          // per probe (kMasks; kPlane: validity)
    std::vector<CellPlane> planes;                      // per probe (kPlane)
    std::vector<CellPlane> planes2;                     // per probe (kPlane, optional second plane)
    std::vector<std::array<std::uint8_t, 8>> octant;    // per probe (kOctant)
};

// Irradiance (rgb, double) at position p for normal n under the volume's scheme.
inline void candidate_irradiance(const CandidateVolume& cv, const double position[3], const double normal[3], double rgb[3]) {
    const zhc_volume* v = &cv.v;
    uint32_t i0[3];
    double f[3], w[8], sum = 0.0, sh3[27] = {}, n[3], y[9];
    size_t index[8];
    for (int c = 0; c < 3; ++c) zhc__volume_axis(position[c], v->origin[c], v->spacing[c], v->counts[c], &i0[c], &f[c]);
    for (int corner = 0; corner < 8; ++corner) {
        const int bx = corner & 1, by = (corner >> 1) & 1, bz = (corner >> 2) & 1;
        w[corner] = (bx ? f[0] : 1.0 - f[0]) * (by ? f[1] : 1.0 - f[1]) * (bz ? f[2] : 1.0 - f[2]);
        index[corner] = (size_t)(i0[0] + (uint32_t)bx) +
                        (size_t)v->counts[0] * ((size_t)(i0[1] + (uint32_t)by) + (size_t)v->counts[1] * (size_t)(i0[2] + (uint32_t)bz));
    }
    zhc__normalize_or_z(normal, n);
    if (cv.scheme != Scheme::kPlain) {
        double xb[3];
        const double h = std::min({v->spacing[0], v->spacing[1], v->spacing[2]});
        for (int c = 0; c < 3; ++c) xb[c] = position[c] + cv.bias * h * n[c];
        int side = 0, side2 = 0;
        const CellPlane* cp = nullptr;
        const CellPlane* cp2 = nullptr;
        if (cv.scheme == Scheme::kPlane) {
            cp = &cv.planes[index[0]];
            if (cp->offset != CellPlane::kNoPlane) {
                const Vec3 nq = oct_decode(cp->ou, cp->ov);
                const double diag = std::sqrt(v->spacing[0] * v->spacing[0] + v->spacing[1] * v->spacing[1] + v->spacing[2] * v->spacing[2]);
                double s = -cp->offset * (diag / 65534.0);
                for (int c = 0; c < 3; ++c) s += nq[c] * (xb[c] - (v->origin[c] + (i0[c] + 0.5) * v->spacing[c]));
                side = s >= 0;
            } else {
                cp = nullptr;
            }
            if (!cv.planes2.empty() && cv.planes2[index[0]].offset != CellPlane::kNoPlane) {
                cp2 = &cv.planes2[index[0]];
                const Vec3 nq = oct_decode(cp2->ou, cp2->ov);
                const double diag = std::sqrt(v->spacing[0] * v->spacing[0] + v->spacing[1] * v->spacing[1] + v->spacing[2] * v->spacing[2]);
                double s = -cp2->offset * (diag / 65534.0);
                for (int c = 0; c < 3; ++c) s += nq[c] * (xb[c] - (v->origin[c] + (i0[c] + 0.5) * v->spacing[c]));
                side2 = s >= 0;
            }
        }
        double m[8];
        bool keep[8];
        for (int corner = 0; corner < 8; ++corner) {
            m[corner] = 0.0;
            keep[corner] = false;
            if (w[corner] == 0.0 && !cv.extrapolate) continue;
            if (((corner & 1) && v->counts[0] == 1) || ((corner & 2) && v->counts[1] == 1) || ((corner & 4) && v->counts[2] == 1))
                continue;  // beyond a count-1 axis: not a probe
            const size_t i = index[corner];
            switch (cv.scheme) {
                case Scheme::kMasks:
                    if (!cv.validity[i] || !((cv.masks[i] >> (7 - corner)) & 1u)) continue;
                    break;
                case Scheme::kPlane:
                    if (!cv.validity[i]) continue;
                    if (cp && (((cp->sides >> corner) & 1) != side)) continue;
                    if (cp2 && (((cp2->sides >> corner) & 1) != side2)) continue;
                    break;
                case Scheme::kOctant: {
                    const std::uint8_t code = cv.octant[i][static_cast<size_t>(7 - corner)];
                    if (code == 0) continue;
                    const double dmax = (code - 1) / 254.0 *
                                        std::sqrt(v->spacing[0] * v->spacing[0] + v->spacing[1] * v->spacing[1] + v->spacing[2] * v->spacing[2]);
                    double d2 = 0;
                    for (int c = 0; c < 3; ++c) {
                        const uint32_t ic = i0[c] + (uint32_t)((corner >> c) & 1);
                        const double e = xb[c] - (v->origin[c] + ic * v->spacing[c]);
                        d2 += e * e;
                    }
                    if (d2 > dmax * dmax) continue;
                    break;
                }
                case Scheme::kPlain: break;
            }
            keep[corner] = true;
            m[corner] = w[corner];
            sum += m[corner];
        }
        if (cv.extrapolate) {
            // Contributions (probe index, weight): kept corners, and each dropped corner as
            // 2 P(k') - P(k''); the weights sum to the kept + replaced corners' weights.
            size_t ci[24];
            double cw[24], total = 0;
            int cn = 0;
            const Vec3 nq = cp ? oct_decode(cp->ou, cp->ov) : Vec3{1, 1, 1};
            int axes[3] = {0, 1, 2};
            std::sort(axes, axes + 3, [&](int a, int b) { return std::fabs(nq[a]) > std::fabs(nq[b]); });
            for (int corner = 0; corner < 8; ++corner) {
                if (w[corner] == 0.0) continue;
                if (keep[corner]) {
                    ci[cn] = index[corner];
                    cw[cn++] = w[corner];
                    total += w[corner];
                    continue;
                }
                for (int a : axes) {
                    const int k2 = corner ^ (1 << a);
                    if (!keep[k2]) continue;
                    const int bk = (corner >> a) & 1, bk2 = (k2 >> a) & 1;
                    const long c2 = long(i0[a]) + bk2, cb = c2 - (bk - bk2);
                    if (cb < 0 || cb >= long(v->counts[a])) continue;
                    const size_t step = a == 0 ? 1 : (a == 1 ? size_t(v->counts[0]) : size_t(v->counts[0]) * v->counts[1]);
                    const size_t behind = cb < c2 ? index[k2] - step : index[k2] + step;
                    if (!cv.validity[behind]) continue;
                    ci[cn] = index[k2];
                    cw[cn++] = 2 * w[corner];
                    ci[cn] = behind;
                    cw[cn++] = -w[corner];
                    total += w[corner];
                    break;
                }
            }
            if (total > 0.0) {
                for (int k = 0; k < cn; ++k) {
                    float probe[27];
                    zhc_decode_probe(&v->format, v->probes + ci[k] * v->probe_size, probe);
                    for (int j = 0; j < 27; ++j) sh3[j] += cw[k] / total * (double)probe[j];
                }
                zhc__sh3_basis(n, y);
                rgb[0] = rgb[1] = rgb[2] = 0.0;
                for (int i = 0; i < 9; ++i) {
                    const double s = i == 0 ? 1.0 : (i < 4 ? ZHC__BAND1 : ZHC__BAND2);
                    for (int k = 0; k < 3; ++k) rgb[k] += s * sh3[i * 3 + k] * y[i];
                }
                for (int k = 0; k < 3; ++k) rgb[k] = std::max(0.0, rgb[k]);
                return;
            }
        }
        if (sum > 0.0)
            for (int corner = 0; corner < 8; ++corner) w[corner] = m[corner] / sum;
    }
    for (int corner = 0; corner < 8; ++corner) {
        float probe[27];
        if (w[corner] == 0.0) continue;
        zhc_decode_probe(&v->format, v->probes + index[corner] * v->probe_size, probe);
        for (int j = 0; j < 27; ++j) sh3[j] += w[corner] * (double)probe[j];
    }
    zhc__sh3_basis(n, y);
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    for (int i = 0; i < 9; ++i) {
        const double s = i == 0 ? 1.0 : (i < 4 ? ZHC__BAND1 : ZHC__BAND2);
        for (int k = 0; k < 3; ++k) rgb[k] += s * sh3[i * 3 + k] * y[i];
    }
}

// Whether the cell holding `position` has a plane (kPlane volumes).
inline bool cell_has_plane(const CandidateVolume& cv, Vec3 position) {
    const double p[3] = {position.x, position.y, position.z};
    uint32_t i0[3];
    double f[3];
    for (int c = 0; c < 3; ++c) zhc__volume_axis(p[c], cv.v.origin[c], cv.v.spacing[c], cv.v.counts[c], &i0[c], &f[c]);
    const size_t i = i0[0] + size_t(cv.v.counts[0]) * (i0[1] + size_t(cv.v.counts[1]) * i0[2]);
    return !cv.planes.empty() && cv.planes[i].offset != CellPlane::kNoPlane;
}

// The float API's rounding (as zhc_volume_irradiance).
inline void candidate_irradiance_f(const CandidateVolume& cv, const float position[3], const float normal[3], float rgb[3]) {
    const double p[3] = {position[0], position[1], position[2]}, n[3] = {normal[0], normal[1], normal[2]};
    double e[3];
    candidate_irradiance(cv, p, n, e);
    for (int c = 0; c < 3; ++c) rgb[c] = float(e[c]);
}

inline std::vector<double> sample_candidate(const CandidateVolume& cv, const std::vector<ShadingPoint>& pts) {
    std::vector<double> e;
    e.reserve(pts.size());
    for (const ShadingPoint& sp : pts) {
        const float p[3] = {float(sp.p.x), float(sp.p.y), float(sp.p.z)}, n[3] = {float(sp.n.x), float(sp.n.y), float(sp.n.z)};
        float rgb[3];
        candidate_irradiance_f(cv, p, n, rgb);
        e.push_back((double(rgb[0]) + double(rgb[1]) + double(rgb[2])) / 3.0);
    }
    return e;
}

// ---- the candidates on one scene ------------------------------------------------------------------

// The probes of a grid bake with the relocated probes' values replaced by a positions bake at
// their new positions (same options); the validity of a moved probe becomes 1.
struct RelocatedProbes {
    Relocation reloc;
    std::vector<Sh3Radiance> probes;
    std::vector<std::uint8_t> validity;
    std::vector<std::uint8_t> plain_zhp;  // sh3 .zhp without leak sections
    std::string error;
};

inline RelocatedProbes relocated_probes(const LeakScene& ls, const Baked& b, const OccluderBvh& bvh, double clearance = 0.1) {
    RelocatedProbes r;
    const GridInfo g = grid_of(ls.scene);
    r.reloc = relocate_probes(bvh, g, clearance);
    r.probes = b.probes;
    r.validity = b.leak.validity;
    if (r.validity.empty()) r.validity.assign(g.count(), 1);
    if (r.reloc.moved_count > 0) {
        Scene s = ls.scene;
        s.probes = {};
        s.probes.kind = ProbePlacementKind::kPositions;
        std::vector<std::size_t> which;
        for (std::size_t i = 0; i < g.count(); ++i)
            if (r.reloc.moved[i]) {
                s.probes.positions.push_back(r.reloc.positions[i]);
                which.push_back(i);
            }
        auto moved = bake_scene(s, BakeOptions{});
        if (!moved) {
            r.error = ls.name + ": " + moved.error().message;
            return r;
        }
        for (std::size_t k = 0; k < which.size(); ++k) {
            r.probes[which[k]] = (*moved)[k];
            r.validity[which[k]] = 1;
        }
    }
    auto set = encode_probe_set(r.probes, "sh3", {}, probe_layout(ls.scene.probes));
    if (!set) {
        r.error = ls.name + ": " + set.error().message;
        return r;
    }
    auto plain = serialize_probe_set(*set);
    if (!plain) {
        r.error = ls.name + ": cannot write the .zhp";
        return r;
    }
    r.plain_zhp = std::move(*plain);
    return r;
}

// Every candidate of one scene, ready to sample (the volumes point into `zhp` buffers owned here).
struct CandidateSet {
    std::vector<std::string> names;
    std::vector<double> bytes;  // extra bytes per probe a runtime reads (per-cell data counted per probe)
    std::vector<CandidateVolume> volumes;
    std::size_t moved = 0, stuck = 0;
    PlaneFitStats plane_stats, plane_reloc_stats, plane2_stats;
    std::vector<std::uint8_t> plain_zhp, reloc_zhp, towards_zhp;
    std::size_t moved_towards = 0;
    std::string error;
};

struct CandidateOptions {
    double bias = 0.0;        // normal bias of the new schemes, fraction of min(spacing)
    double clearance = 0.1;   // relocation radius, fraction of min(spacing)
    double reach = 0.4;       // relocation towards walls: the farthest a probe stays from its cells' planes
    double max_wrong = 0.02;  // ... counting only planes predicting at most this fraction of blocked pairs wrongly
};

inline std::unique_ptr<CandidateSet> build_candidates(const LeakScene& ls, const Baked& b, const CandidateOptions& opt = {}) {
    auto cs = std::make_unique<CandidateSet>();
    const OccluderBvh bvh(ls.scene.occluders);
    const GridInfo g = grid_of(ls.scene);
    cs->plain_zhp = b.plain_zhp;
    RelocatedProbes rp = relocated_probes(ls, b, bvh, opt.clearance);
    if (!rp.error.empty()) {
        cs->error = rp.error;
        return cs;
    }
    cs->reloc_zhp = std::move(rp.plain_zhp);
    cs->moved = rp.reloc.moved_count;
    cs->stuck = rp.reloc.stuck;
    std::vector<std::uint8_t> validity = b.leak.validity, masks = b.leak.visibility;
    if (validity.empty()) validity.assign(g.count(), 1);
    if (masks.empty()) masks.assign(g.count(), 0xff);
    std::vector<Vec3> grid_pos;
    for (std::size_t i = 0; i < g.count(); ++i) grid_pos.push_back(g.position(i));
    zhc_volume pv, rv;
    if (zhc_volume_from_zhp(&pv, cs->plain_zhp.data(), cs->plain_zhp.size()) != ZHC_OK ||
        zhc_volume_from_zhp(&rv, cs->reloc_zhp.data(), cs->reloc_zhp.size()) != ZHC_OK) {
        cs->error = ls.name + ": cannot open the candidate volumes";
        return cs;
    }
    auto add = [&](const char* name, double bytes, const zhc_volume& v, Scheme s, double bias) -> CandidateVolume& {
        cs->names.push_back(name);
        cs->bytes.push_back(bytes);
        CandidateVolume cv;
        cv.v = v;
        cv.scheme = s;
        cv.bias = bias;
        cs->volumes.push_back(std::move(cv));
        return cs->volumes.back();
    };
    add("plain", 0, pv, Scheme::kPlain, 0);
    {
        CandidateVolume& c = add("masks", 2, pv, Scheme::kMasks, 0);
        c.validity = validity;
        c.masks = masks;
    }
    const std::vector<CellPlane> planes = cell_planes(bvh, g, grid_pos, validity, {}, &cs->plane_stats);
    {
        CandidateVolume& c = add("plane", kPlaneBytesPerCell + 1, pv, Scheme::kPlane, opt.bias);
        c.validity = validity;
        c.planes = planes;
    }
    {
        CandidateVolume& c = add("2 planes", 2 * kPlaneBytesPerCell + 1, pv, Scheme::kPlane, opt.bias);
        c.validity = validity;
        c.planes = cell_planes(bvh, g, grid_pos, validity, {}, &cs->plane2_stats, &c.planes2);
    }
    {
        CandidateVolume& c = add("plane+extrap", kPlaneBytesPerCell + 1, pv, Scheme::kPlane, opt.bias);
        c.validity = validity;
        c.planes = planes;
        c.extrapolate = true;
    }
    {
        CandidateVolume& c = add("octant min", 8, pv, Scheme::kOctant, opt.bias);
        c.octant = octant_distances(bvh, g, grid_pos, validity, OctantStat::kMin);
    }
    {
        CandidateVolume& c = add("octant mean", 8, pv, Scheme::kOctant, opt.bias);
        c.octant = octant_distances(bvh, g, grid_pos, validity, OctantStat::kMean);
    }
    {
        CandidateVolume& c = add("reloc+masks", 2, rv, Scheme::kMasks, 0);
        c.validity = rp.validity;
        c.masks = masks_at(bvh, g, rp.reloc.positions);
    }
    {
        CandidateVolume& c = add("reloc+plane", kPlaneBytesPerCell + 1, rv, Scheme::kPlane, opt.bias);
        c.validity = rp.validity;
        c.planes = cell_planes(bvh, g, rp.reloc.positions, rp.validity, {}, &cs->plane_reloc_stats);
    }
    {
        // Relocation towards walls: probes moved to `reach` spacing from their cells' planes, baked
        // there (positions bake), the planes refitted with the corners at the new positions.
        std::vector<double> wrong;
        const std::vector<CellPlane> first = cell_planes(bvh, g, rp.reloc.positions, rp.validity, {}, nullptr, nullptr, &wrong);
        std::size_t moved2 = 0;
        const std::vector<Vec3> pos2 = relocate_towards_planes(bvh, g, rp.reloc.positions, rp.validity, first, wrong,
                                                               opt.max_wrong, opt.reach, opt.clearance, &moved2);
        cs->moved_towards = moved2;
        std::vector<Sh3Radiance> probes2 = rp.probes;
        Scene s = ls.scene;
        s.probes = {};
        s.probes.kind = ProbePlacementKind::kPositions;
        std::vector<std::size_t> which;
        for (std::size_t i = 0; i < g.count(); ++i)
            if (pos2[i].x != rp.reloc.positions[i].x || pos2[i].y != rp.reloc.positions[i].y || pos2[i].z != rp.reloc.positions[i].z) {
                s.probes.positions.push_back(pos2[i]);
                which.push_back(i);
            }
        if (!which.empty()) {
            auto baked2 = bake_scene(s, BakeOptions{});
            if (!baked2) {
                cs->error = ls.name + ": " + baked2.error().message;
                return cs;
            }
            for (std::size_t k = 0; k < which.size(); ++k) probes2[which[k]] = (*baked2)[k];
        }
        auto set = encode_probe_set(probes2, "sh3", {}, probe_layout(ls.scene.probes));
        if (!set) {
            cs->error = ls.name + ": " + set.error().message;
            return cs;
        }
        auto bytes = serialize_probe_set(*set);
        if (!bytes) {
            cs->error = ls.name + ": cannot write the relocated .zhp";
            return cs;
        }
        cs->towards_zhp = std::move(*bytes);
        zhc_volume tv;
        if (zhc_volume_from_zhp(&tv, cs->towards_zhp.data(), cs->towards_zhp.size()) != ZHC_OK) {
            cs->error = ls.name + ": cannot open the relocated volume";
            return cs;
        }
        CandidateVolume& c = add("reloc2+plane", kPlaneBytesPerCell + 1, tv, Scheme::kPlane, opt.bias);
        c.validity = rp.validity;
        c.planes = cell_planes(bvh, g, pos2, rp.validity);
    }
    {
        CandidateVolume& c = add("reloc+pl+extrap", kPlaneBytesPerCell + 1, rv, Scheme::kPlane, opt.bias);
        c.validity = rp.validity;
        c.planes = cs->volumes[cs->volumes.size() - 3].planes;  // reloc+plane's
        c.extrapolate = true;
    }
    return cs;
}

}  // namespace zhc::leak
