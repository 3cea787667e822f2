// zhc/codec/bake/leak_planes.h — probes kept out of walls, and one separating plane per grid cell,
// so that a runtime blends only the probes on a shading point's side of a wall (docs/leaks.md
// "Candidates", docs/scene.md "Probes near geometry", docs/runtime.md "Cell planes").
//
// A grid bake with occluders (bake_scene) runs, before it bakes any probe:
//  1. relocation out of geometry: a probe that is not clear (inside a box or sphere, meeting a
//     triangle's back face first on more than `invalid_fraction` of the occlusion rays, or geometry
//     within r = clearance x min(spacing) along any of the 26 axis, edge and corner directions) is
//     baked at the first clear point p + s d, s = r/2, r, 3r/2, ... up to half the spacing, d over
//     the 26 directions (axes, then edges, then corners; each group in index order);
//  2. a first plane fit (below) with the probes where step 1 put them;
//  3. relocation towards walls: a valid probe farther than reach x min(spacing) from the plane of
//     one of its cells, where that plane predicts at most max_wrong of its cell's blocked pairs
//     wrongly, is baked at reach x min(spacing) from it along its normal (the largest such move),
//     when that point is clear and the segment to it unblocked;
// and after the bake fits the planes again with every probe where it was baked. Nothing about a
// move is stored: runtimes weight each probe at its grid position.
//
// The plane fit, per cell: sample points on a lattice^3 lattice inside the cell (minus points
// inside boxes and spheres) and the 8 corner probes where they were baked; every (point, valid
// corner) segment is traced; when some are blocked, candidate planes (the least-squares plane of
// the blocked segments' hit points seen from both ends, and per axis the axis-aligned planes at the
// hits' minimum, maximum, middle and median) are quantised to the stored 5 bytes and scored by the
// pairs whose visibility they predict wrongly (visible predicted = point and corner on the same
// side); the best is kept when it predicts fewer pairs wrongly than no plane. Where the best plane
// still predicts some pair wrongly, corner regions (docs/runtime.md "Corner regions") are scored
// too (per axis the thresholds at the points' minimum, maximum, middle and median, or none, grown
// from each of the 8 corners); one replaces the plane when it predicts fewer pairs wrongly. Cells whose box (and
// their corners' baked positions) meets no occluder's bounds trace nothing and get no plane.
//
// Shadow planes: a cell where no (point, corner) segment is blocked, but the light of one of
// `shadow_lights` reaches some of its valid corners and not others, gets the plane along that
// light's shadow edge: the same candidates and scoring, with "visible" read as "the point and the
// corner agree on receiving the light" and the candidates fitted to where the edge crosses the
// disagreeing segments (6 bisection steps each). Of several such lights, the one whose direct light
// at a receiving corner is strongest. A hard shadow edge in open air is then kept within the cell:
// the points in the shadow blend the probes in the shadow (the probes hold the same light, less
// that light), the lit points the lit probes. Soft shadows (the sky, cone lights) get none.
//
// Deterministic: every probe and every cell is computed alone, so any thread count gives the same
// bytes. Experimental: this API may change between minor versions (docs/api.md "Public headers").
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "codec/bake/occluders.h"
#include "codec/probe/probe_set.h"

namespace zhc {

// One cell's plane as stored (5 bytes, ProbeSet::planes): octahedral normal code (ou, ov), offset
// from the cell's centre along the normal in units of |spacing| / 65534 (kNoPlane: none), and bit k
// of `sides` set when corner k = dx + 2 dy + 4 dz was baked on the positive side.
struct CellPlane {
    static constexpr std::int16_t kNoPlane = std::numeric_limits<std::int16_t>::min();
    std::uint8_t ou = 0, ov = 0;
    std::int16_t offset = kNoPlane;
    std::uint8_t sides = 0;
    bool present() const { return offset != kNoPlane; }  // a plane
    // A corner region (docs/runtime.md "Corner regions"): offset kNoPlane, bit 7 of sides; the
    // thresholds q_a = ((ou | ov << 8) >> 5a) & 31, the directions in bits 0-2 of sides.
    bool region() const { return offset == kNoPlane && (sides & 0x80u) != 0; }
    bool any() const { return present() || region(); }
};

// The unit normal of code (ou, ov), the same operations as runtime/zhc_runtime.h zhc_plane_normal
// (bit for bit): a = min(ou, 254) / 127 - 1, b likewise, z = 1 - |a| - |b|, folded when z < 0.
Vec3 cell_plane_normal(std::uint8_t ou, std::uint8_t ov);
// The code whose decoded normal is nearest to n (by angle, among the 3 x 3 codes around the rounded
// one). The axes are exact.
void encode_cell_plane_normal(Vec3 n, std::uint8_t* ou, std::uint8_t* ov);
// |spacing| / 65534: the offset's unit.
double cell_plane_unit(const ProbeGrid& g);
// Centre of the cell whose corner 0 is probe (x, y, z).
Vec3 cell_centre(const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z);
// The corner region with thresholds (qx, qy, qz) (0..31; 0: the axis does not bound it) that holds
// corner `anchor` (its direction bits are the anchor's coordinates).
CellPlane cell_region(int qx, int qy, int qz, int anchor);
// Threshold q_a of a region, the corners inside it (bit k), and whether q lies inside it, with the
// runtime's operations (bit for bit).
int cell_region_threshold(const CellPlane& cp, int a);
std::uint8_t cell_region_corners(const CellPlane& cp);
bool cell_region_inside(const CellPlane& cp, const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z, Vec3 q);
// n . (q - c) - offset unit: >= 0 on the positive side. `cp` must be present().
double cell_plane_value(const CellPlane& cp, const ProbeGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z, Vec3 q);
// The unit eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix (cyclic Jacobi
// rotations; `a` is overwritten): the normal of the least-squares plane of points whose
// covariance `a` is.
Vec3 smallest_eigenvector(double a[3][3]);
// 5 bytes per entry (ProbeSet::planes), and back.
std::vector<std::uint8_t> cell_planes_bytes(const std::vector<CellPlane>& planes);
std::vector<CellPlane> cell_planes_from_bytes(const std::vector<std::uint8_t>& bytes);

struct LeakPlacementOptions {
    double clearance = 0.1;   // r / min(spacing): geometry nearer than this makes a probe move
    double reach = 0.4;       // towards walls: the farthest a probe stays from its cells' planes / min(spacing)
    double max_wrong = 0.02;  // ... counting only planes that predict at most this fraction of blocked pairs wrongly
    int lattice = 4;          // plane fit: lattice^3 sample points per cell
};

struct PlaneFitStats {
    std::uint64_t cells = 0;          // cells of the grid
    std::uint64_t crossed_cells = 0;  // cells with some blocked (point, corner) pair
    std::uint64_t planes = 0;         // cells given a plane
    std::uint64_t pairs = 0, blocked_pairs = 0, wrong_pairs = 0;  // over cells with a plane
    // wrong_pairs = leaking_pairs (blocked, yet on the same side: still blended) + dropped_pairs
    // (visible, yet on the other side: light lost).
    std::uint64_t leaking_pairs = 0, dropped_pairs = 0;
    std::uint64_t unresolved_pairs = 0;  // blocked pairs of crossed cells left without a plane (all blended)
    // Of `planes`, those fitted with a light's shadow edge in the cell (pairs across it count as
    // blocked: in the counts above).
    std::uint64_t shadow_planes = 0;
    // Of `planes`, the corner regions (a box's corner in the cell: three faces no plane separates).
    std::uint64_t regions = 0;
    std::uint64_t rays = 0;
};

// A light whose shadow has a hard edge (point and spot lights, directional lights of zero angular
// radius, each casting shadows): what a shadow plane follows.
struct ShadowLight {
    bool directional = false;
    Vec3 position;             // point, spot
    Vec3 direction{0, 0, 1};   // directional: towards the light
    Vec3 spot_axis{0, 0, 1};   // spot: where it points
    double cos_outer = -2;     // spot: cos of its outer half-angle (points outside receive nothing); -2: no cone
    double intensity = 0;      // luminance of its intensity (point, spot) or irradiance (directional)
};

// The fit described above (`regions` false: planes only). `baked`: each probe's baked position; `valid`: its validity (invalid
// corners are neither scored nor kept). Returns one entry per probe index (the cell whose corner 0
// it is; the last probe of an axis gets none). `wrong_fraction`, when given: per entry the fraction
// of the cell's blocked pairs its plane predicts wrongly (0 without a plane).
std::vector<CellPlane> fit_cell_planes(const OccluderBvh& bvh, const ProbeGrid& g, const std::vector<Vec3>& baked,
                                       const std::vector<std::uint8_t>& valid, int lattice, int threads,
                                       PlaneFitStats* stats, std::vector<double>* wrong_fraction = nullptr,
                                       std::span<const ShadowLight> shadow_lights = {}, bool regions = true);

// Where each grid probe is baked (steps 1-3 above) and what the steps found.
struct ProbeRelocation {
    std::vector<Vec3> positions;      // where each probe is baked
    std::vector<std::uint8_t> valid;  // 1: baked outside geometry (the bake's validity test)
    std::uint64_t moved_out = 0;      // step 1 moved it
    std::uint64_t left_inside = 0;    // step 1 found no clear point and the probe is inside geometry (invalid)
    std::uint64_t left_near = 0;      // step 1 found no clear point, the probe is outside geometry but near it
    std::uint64_t moved_towards = 0;  // step 3 moved it
    std::uint64_t rays = 0;
    PlaneFitStats first_fit;          // step 2
};

// The test the relocation and the bake's validity share: `dirs` are the bake's occlusion directions
// and `invalid_limit` its threshold (inside when more than invalid_limit of them meet a back face
// first, or the point is inside a box or sphere).
struct InsideTest {
    const std::vector<Vec3>* dirs = nullptr;
    std::uint64_t invalid_limit = 0;
};
bool inside_geometry(const OccluderBvh& bvh, const InsideTest& test, Vec3 p, std::uint64_t* rays);

// Steps 1-3 for the grid `g` (positions at the grid points). `move` false: every probe stays at its
// grid point (validity is still computed).
ProbeRelocation relocate_grid_probes(const OccluderBvh& bvh, const ProbeGrid& g, const InsideTest& test,
                                     const LeakPlacementOptions& options, bool move, int threads);

}  // namespace zhc
