// zhc/formats/probes/tetra.h — Delaunay tetrahedralisation of scattered probe positions (the
// `points` layout), the data the runtimes' tetrahedral interpolation walks (docs/runtime.md
// "Scattered probes (`points` layout)", docs/zhp-container.md "tetrahedra").
//
// The Delaunay subdivision is qhull's (Debian libqhull-dev, reentrant libqhull_r, options
// `d Qbb Qz`: Delaunay by lifting to a paraboloid, the paraboloid scaled to [0, max], a point at
// infinity against cospherical sites). Cospherical sites (any lattice) form one Delaunay region, a
// convex polytope, which is triangulated here by its pulling triangulation in probe order (cones
// from its lowest probe over the faces without it, each face a fan from its own lowest probe), so
// that two regions triangulate their common face the same way: the tetrahedra are conforming, and
// none is flat. (qhull's own `Qt` triangulation instead holds flat tetrahedra between regions whose
// common faces it splits differently, across which the interpolation jumps.) Then one canonical
// form, so that the same positions always give the same bytes:
//  * duplicates: probes at exactly the same position are merged: the first (lowest index) of each
//    group is the vertex, the others are never referenced (listed in `duplicates`);
//  * tetrahedra sorted by their probe indices (ascending), neighbours derived from shared faces:
//    neighbours[t][j] is the tetrahedron across face j (the face opposite vertex j), -1 on the
//    convex hull;
//  * each tetrahedron (a, b, c, d): a < b < c < d, then c and d swapped for a consistent
//    orientation, which the runtimes' walk relies on: a solid tetrahedron is positively oriented
//    (det[b - a, c - a, d - a] > 0 in double); a flat one (|det| <= 1e-12 L^3, L the longest edge:
//    qhull's `Qt` output, or sites within its precision of a plane) takes the orientation in which
//    every face it shares appears in opposite orders in the two tetrahedra, as between solid ones
//    (breadth-first from the solid ones).
// No threads, no randomness (qhull runs without joggle): deterministic for any thread count.
//
// Degenerate sets are refused with kInvalidArgument and a one-line reason: fewer than 4 distinct
// positions, all positions on one line or in one plane (within 1e-6 of the set's extent). The CLI
// then writes the set without tetrahedra (and says so).
//
// Thread safety: reentrant (each call owns its qhull state).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "codec/probe/probe_set.h"
#include "codec/status.h"

namespace zhc {

struct Tetrahedralization {
    std::vector<std::array<std::uint32_t, 4>> tetrahedra;  // probe indices, canonical (above)
    std::vector<std::array<std::int32_t, 4>> neighbours;   // across face j; -1 = convex hull
    // (probe, the first probe at the same position): merged duplicates, never a vertex.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> duplicates;
    // Probes at distinct positions that are no vertex of any tetrahedron (qhull drops a site
    // within its precision of another); empty for ordinary sets.
    std::vector<std::uint32_t> unused;
    std::uint32_t flat = 0;  // flat tetrahedra (|det| <= 1e-12 L^3)
};

// The tetrahedralisation of `positions` (one per probe, at most 2^26). kInvalidArgument for a
// degenerate set (message: why), kInternal when qhull fails otherwise (its first message line).
// qhull_triangulated: qhull's `Qt` triangulation of the regions instead (flat tetrahedra where sites
// are cospherical; the tests use it to exercise the runtimes on flat tetrahedra). It is also the
// fallback when a region's ridges do not form polygon faces (not seen).
Result<Tetrahedralization> tetrahedralize(std::span<const std::array<float, 3>> positions, bool qhull_triangulated = false);

// The neighbours of a list of tetrahedra, derived from shared faces (as tetrahedralize does):
// kInvalidArgument when a face is shared by more than two tetrahedra.
Result<std::vector<std::array<std::int32_t, 4>>> tetra_neighbours_of(std::span<const std::array<std::uint32_t, 4>> tetrahedra);

// For a set with a positions layout: fills set.tetrahedra / set.tetra_neighbours (replacing what
// was there) and returns the lines to show the user (merged duplicates, probes left out, or why a
// degenerate set got none: then the two vectors are empty). Other layouts: nothing, no lines.
std::vector<std::string> add_tetrahedra(ProbeSet& set);

}  // namespace zhc
