// Delaunay tetrahedralisation of probe positions with qhull (tetra.h).
#include "formats/probes/tetra.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace zhc {

namespace {

using P = std::array<double, 3>;

P sub(const P& a, const P& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot3(const P& a, const P& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
P cross3(const P& a, const P& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double orient(const P& a, const P& b, const P& c, const P& d) { return dot3(sub(b, a), cross3(sub(c, a), sub(d, a))); }

// Why a set of distinct points spans fewer than 3 dimensions, or "" when it spans 3: p1 the point
// farthest from p0, p2 the farthest from the line p0 p1, p3 the farthest from the plane p0 p1 p2;
// a distance within 1e-6 of the extent |p1 - p0| counts as zero.
std::string degenerate_reason(const std::vector<P>& pts) {
    const std::size_t n = pts.size();
    if (n < 4) return "fewer than 4 distinct probe positions (" + std::to_string(n) + ")";
    std::size_t i1 = 0;
    double best = -1;
    for (std::size_t i = 0; i < n; ++i) {
        const P d = sub(pts[i], pts[0]);
        if (dot3(d, d) > best) best = dot3(d, d), i1 = i;
    }
    const double extent = std::sqrt(best);
    const double tol = 1e-6 * extent;
    const P e1 = sub(pts[i1], pts[0]);
    std::size_t i2 = 0;
    best = -1;
    for (std::size_t i = 0; i < n; ++i) {
        const P c = cross3(e1, sub(pts[i], pts[0]));
        if (dot3(c, c) > best) best = dot3(c, c), i2 = i;
    }
    if (std::sqrt(best) <= tol * extent) return "all " + std::to_string(n) + " probe positions lie on one line";
    const P nrm = cross3(e1, sub(pts[i2], pts[0]));
    const double nl = std::sqrt(dot3(nrm, nrm));
    best = 0;
    for (std::size_t i = 0; i < n; ++i) best = std::max(best, std::fabs(dot3(nrm, sub(pts[i], pts[0]))) / nl);
    if (best <= tol) return "all " + std::to_string(n) + " probe positions lie in one plane";
    return "";
}

// The orientation tetrahedron t gives its face j (the face without vertex j): (-1)^j times the sign
// of the permutation that sorts the face's probes in t's order. Two tetrahedra sharing a face in a
// consistently oriented tetrahedralisation give it opposite signs (runtime/zhc_runtime.h
// zhc__tetra_volumes relies on it).
int face_sign(const std::array<std::uint32_t, 4>& t, int j) {
    std::uint32_t f[3];
    int n = 0, sign = (j & 1) ? -1 : 1;
    for (int k = 0; k < 4; ++k)
        if (k != j) f[n++] = t[static_cast<std::size_t>(k)];
    if (f[0] > f[1]) std::swap(f[0], f[1]), sign = -sign;
    if (f[1] > f[2]) std::swap(f[1], f[2]), sign = -sign;
    if (f[0] > f[1]) std::swap(f[0], f[1]), sign = -sign;
    return sign;
}

// One Delaunay region of qhull's output (a lower facet of the lifted hull): its sites, and when it
// is not a tetrahedron (cospherical sites merged into one region: every cell of a lattice) its
// ridges: triangles of its boundary, each with the region across it (-1: the convex hull).
struct Region {
    std::vector<std::uint32_t> sites;
    std::vector<std::pair<std::int64_t, std::array<std::uint32_t, 3>>> ridges;
};

// qhull's Delaunay regions of `pts` (indices into pts), or an error. triangulated: option 'Qt'
// (every region a tetrahedron, flat ones where sites are cospherical).
Result<std::vector<Region>> run_qhull(const std::vector<P>& pts, bool triangulated) {
    std::vector<coordT> coords(3 * pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i)
        for (int c = 0; c < 3; ++c) coords[3 * i + static_cast<std::size_t>(c)] = pts[i][static_cast<std::size_t>(c)];
    // qhull's messages go to a memory stream: the first line becomes the error message.
    char* err_text = nullptr;
    std::size_t err_size = 0;
    FILE* err = open_memstream(&err_text, &err_size);
    if (!err) return make_error(ErrorCode::kInternal, "tetrahedralisation: cannot open a message stream for qhull");
    qhT qh_storage;
    qhT* qh = &qh_storage;
    qh_zero(qh, err);
    // Without 'Qt' cospherical sites stay one region, triangulated below so that neighbouring
    // regions agree on their common faces.
    char merged[] = "qhull d Qbb Qz", split[] = "qhull d Qt Qbb Qz";
    const int exitcode = qh_new_qhull(qh, 3, static_cast<int>(pts.size()), coords.data(), False, triangulated ? split : merged, nullptr, err);
    std::vector<Region> regions;
    bool bad = false;
    auto site = [&](vertexT* vertex, std::uint32_t* out) {
        const int id = qh_pointid(qh, vertex->point);
        if (id < 0 || static_cast<std::size_t>(id) >= pts.size()) return false;
        *out = static_cast<std::uint32_t>(id);
        return true;
    };
    if (exitcode == 0) {
        facetT* facet;
        vertexT *vertex, **vertexp;
        ridgeT *ridge, **ridgep;
        FORALLfacets {
            if (facet->upperdelaunay) continue;
            Region r;
            FOREACHvertex_(facet->vertices) {
                std::uint32_t id = 0;
                if (site(vertex, &id)) r.sites.push_back(id);
                else bad = true;
            }
            if (r.sites.size() < 4) bad = true;
            if (!triangulated && (r.sites.size() > 4 || !facet->simplicial)) {
                if (!facet->ridges) bad = true;
                else
                    FOREACHridge_(facet->ridges) {
                        facetT* other = otherfacet_(ridge, facet);
                        std::array<std::uint32_t, 3> tri{};
                        int k = 0;
                        FOREACHvertex_(ridge->vertices) {
                            if (k < 3 && site(vertex, &tri[static_cast<std::size_t>(k)])) ++k;
                            else bad = true;
                        }
                        if (k != 3) bad = true;
                        r.ridges.emplace_back(other && !other->upperdelaunay ? std::int64_t(other->id) : -1, tri);
                    }
            }
            regions.push_back(std::move(r));
        }
    }
    qh_freeqhull(qh, !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(qh, &curlong, &totlong);
    std::fclose(err);
    std::string message(err_text ? err_text : "", err_size);
    std::free(err_text);
    if (exitcode != 0) {
        std::string line;
        for (char ch : message) {
            if (ch == '\n' && !line.empty()) break;
            if (ch != '\n') line += ch;
        }
        return make_error(ErrorCode::kInternal, "tetrahedralisation: qhull failed (exit " + std::to_string(exitcode) + "): " + line);
    }
    if (bad) return make_error(ErrorCode::kInternal, "tetrahedralisation: qhull returned a Delaunay region zhc cannot read");
    if (regions.empty()) return make_error(ErrorCode::kInternal, "tetrahedralisation: qhull returned no Delaunay region");
    return regions;
}

// The tetrahedra of one region (sites as indices into pts). A tetrahedron as it is; a merged region
// (a convex polytope of cospherical sites) by its pulling triangulation in site order: every face
// that does not hold the region's lowest site v, triangulated by the fan from its own lowest site,
// coned from v. A face between two regions is then triangulated the same from both sides (its fan
// depends on its sites only; when it holds v, v is also its lowest site and the cones from v induce
// that same fan), so no flat tetrahedra fill mismatched faces. Faces are the ridges grouped by the
// region across them (their boundary chained into the polygon); on the convex hull, where no other
// region needs to agree, qhull's own ridge triangles are coned, those in v's plane left out.
// false when the ridges do not form such faces (the caller then falls back).
bool triangulate_region(const Region& r, const std::vector<P>& pts, std::vector<std::array<std::uint32_t, 4>>& out) {
    if (r.ridges.empty()) {
        if (r.sites.size() != 4) return false;
        out.push_back({r.sites[0], r.sites[1], r.sites[2], r.sites[3]});
        return true;
    }
    const std::uint32_t v = *std::min_element(r.sites.begin(), r.sites.end());
    std::map<std::int64_t, std::vector<std::array<std::uint32_t, 3>>> faces;
    double extent2 = 0;
    for (std::uint32_t a : r.sites) extent2 = std::max(extent2, dot3(sub(pts[a], pts[v]), sub(pts[a], pts[v])));
    for (const auto& [other, tri] : r.ridges) {
        if (other >= 0) {
            faces[other].push_back(tri);
            continue;
        }
        // A hull ridge: coned from v unless v lies in its plane.
        if (tri[0] == v || tri[1] == v || tri[2] == v) continue;
        const double o = orient(pts[v], pts[tri[0]], pts[tri[1]], pts[tri[2]]);
        if (std::fabs(o) <= 1e-12 * extent2 * std::sqrt(extent2)) continue;
        out.push_back({v, tri[0], tri[1], tri[2]});
    }
    for (const auto& [other, tris] : faces) {
        // The polygon: boundary edges (used by one triangle of the face) chained into a cycle.
        std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
        bool holds_v = false;
        for (const auto& t : tris)
            for (int e = 0; e < 3; ++e) {
                std::uint32_t a = t[static_cast<std::size_t>(e)], b = t[static_cast<std::size_t>((e + 1) % 3)];
                holds_v = holds_v || a == v;
                if (a > b) std::swap(a, b);
                ++uses[{a, b}];
            }
        if (holds_v) continue;
        std::map<std::uint32_t, std::vector<std::uint32_t>> next;
        for (const auto& [edge, n] : uses)
            if (n == 1) {
                next[edge.first].push_back(edge.second);
                next[edge.second].push_back(edge.first);
            }
        if (next.size() < 3) return false;
        std::vector<std::uint32_t> cycle = {next.begin()->first};  // starts at the face's lowest site
        std::uint32_t prev = cycle[0];
        if (next[cycle[0]].size() != 2) return false;
        std::uint32_t cur = std::min(next[cycle[0]][0], next[cycle[0]][1]);
        while (cur != cycle[0]) {
            if (next[cur].size() != 2 || cycle.size() > next.size()) return false;
            cycle.push_back(cur);
            const std::uint32_t step = next[cur][0] == prev ? next[cur][1] : next[cur][0];
            prev = cur;
            cur = step;
        }
        if (cycle.size() != next.size()) return false;
        for (std::size_t i = 1; i + 1 < cycle.size(); ++i) out.push_back({v, cycle[0], cycle[i], cycle[i + 1]});
    }
    return true;
}

}  // namespace

Result<std::vector<std::array<std::int32_t, 4>>> tetra_neighbours_of(std::span<const std::array<std::uint32_t, 4>> tets) {
    struct Face {
        std::array<std::uint32_t, 3> key;
        std::uint32_t tet;
        int j;
    };
    std::vector<Face> faces;
    faces.reserve(4 * tets.size());
    for (std::size_t t = 0; t < tets.size(); ++t)
        for (int j = 0; j < 4; ++j) {
            std::array<std::uint32_t, 3> key{};
            int k = 0;
            for (int v = 0; v < 4; ++v)
                if (v != j) key[static_cast<std::size_t>(k++)] = tets[t][static_cast<std::size_t>(v)];
            std::sort(key.begin(), key.end());
            faces.push_back({key, static_cast<std::uint32_t>(t), j});
        }
    std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
        return a.key != b.key ? a.key < b.key : (a.tet != b.tet ? a.tet < b.tet : a.j < b.j);
    });
    std::vector<std::array<std::int32_t, 4>> nb(tets.size(), {-1, -1, -1, -1});
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t e = i + 1;
        while (e < faces.size() && faces[e].key == faces[i].key) ++e;
        if (e - i > 2)
            return make_error(ErrorCode::kInvalidArgument, "face (" + std::to_string(faces[i].key[0]) + ", " +
                                                               std::to_string(faces[i].key[1]) + ", " +
                                                               std::to_string(faces[i].key[2]) + ") is shared by " +
                                                               std::to_string(e - i) + " tetrahedra");
        if (e - i == 2) {
            nb[faces[i].tet][static_cast<std::size_t>(faces[i].j)] = static_cast<std::int32_t>(faces[i + 1].tet);
            nb[faces[i + 1].tet][static_cast<std::size_t>(faces[i + 1].j)] = static_cast<std::int32_t>(faces[i].tet);
        }
        i = e;
    }
    return nb;
}

Result<Tetrahedralization> tetrahedralize(std::span<const std::array<float, 3>> positions, bool qhull_triangulated) {
    if (positions.size() > (std::size_t(1) << 26))
        return make_error(ErrorCode::kInvalidArgument, "tetrahedralisation: more than 2^26 probes");
    Tetrahedralization out;
    // Merge exact duplicates: the first probe of each position is the vertex.
    std::vector<std::uint32_t> order(positions.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return positions[a] < positions[b]; });
    std::vector<std::uint32_t> unique_ids;  // probe index of each distinct position, ascending
    for (std::size_t k = 0; k < order.size(); ++k) {
        if (k > 0 && positions[order[k]] == positions[order[k - 1]]) {
            std::size_t first = k - 1;
            while (first > 0 && positions[order[first - 1]] == positions[order[k]]) --first;
            out.duplicates.emplace_back(order[k], order[first]);  // stable sort: order[first] is the lowest index
        } else {
            unique_ids.push_back(order[k]);
        }
    }
    std::sort(unique_ids.begin(), unique_ids.end());
    std::sort(out.duplicates.begin(), out.duplicates.end());
    std::vector<P> pts(unique_ids.size());
    for (std::size_t i = 0; i < unique_ids.size(); ++i)
        for (std::size_t c = 0; c < 3; ++c) pts[i][c] = positions[unique_ids[i]][c];
    if (std::string why = degenerate_reason(pts); !why.empty())
        return make_error(ErrorCode::kInvalidArgument, "tetrahedralisation: " + why);
    // qhull's Delaunay regions, merged regions triangulated consistently; when their ridges do not
    // form polygon faces (not seen), qhull's own triangulation ('Qt') instead.
    auto regions = run_qhull(pts, qhull_triangulated);
    if (!regions) return regions.error();
    std::vector<std::array<std::uint32_t, 4>> local;
    bool consistent = true;
    for (const Region& r : *regions) consistent = consistent && triangulate_region(r, pts, local);
    if (!consistent) {
        regions = run_qhull(pts, true);
        if (!regions) return regions.error();
        local.clear();
        for (const Region& r : *regions) triangulate_region(r, pts, local);
    }
    const auto* raw = &local;
    // Canonical form: sorted by their probe indices (ascending), each ascending, then oriented.
    std::vector<std::array<std::uint32_t, 4>> tets;
    tets.reserve(raw->size());
    for (const auto& r : *raw) {
        std::array<std::uint32_t, 4> t{};
        for (std::size_t k = 0; k < 4; ++k) t[k] = unique_ids[r[k]];
        std::sort(t.begin(), t.end());
        tets.push_back(t);
    }
    std::sort(tets.begin(), tets.end());
    for (std::size_t i = 1; i < tets.size(); ++i)
        if (tets[i - 1] == tets[i])
            return make_error(ErrorCode::kInternal, "tetrahedralisation: qhull returned the same tetrahedron twice");
    auto nb = tetra_neighbours_of(tets);  // faces are sets of probes: the orientation does not change them
    if (!nb) return make_error(ErrorCode::kInternal, "tetrahedralisation: " + nb.error().message);
    // Solid tetrahedra: positive orientation (c and d swapped when det[b - a, c - a, d - a] < 0).
    // Flat ones (|det| <= 1e-12 L^3, L the longest edge; qhull's triangulation of cospherical sites
    // holds them): the orientation that makes every face they share appear in opposite orders in
    // the two tetrahedra, as between solid ones, found breadth-first from the solid ones.
    std::vector<int> state(tets.size(), 0);  // 1 solid, 2 flat decided, 0 flat undecided
    std::vector<std::uint32_t> queue;
    for (std::size_t t = 0; t < tets.size(); ++t) {
        P q[4];
        for (std::size_t k = 0; k < 4; ++k)
            for (std::size_t c = 0; c < 3; ++c) q[k][c] = positions[tets[t][k]][c];
        double l2 = 0;
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b) l2 = std::max(l2, dot3(sub(q[b], q[a]), sub(q[b], q[a])));
        const double o = orient(q[0], q[1], q[2], q[3]);
        if (std::fabs(o) > 1e-12 * l2 * std::sqrt(l2)) {
            if (o < 0) std::swap(tets[t][2], tets[t][3]), std::swap((*nb)[t][2], (*nb)[t][3]);
            state[t] = 1;
            queue.push_back(static_cast<std::uint32_t>(t));
        } else {
            ++out.flat;
        }
    }
    for (std::size_t head = 0; head < queue.size(); ++head) {
        const std::uint32_t t = queue[head];
        for (int j = 0; j < 4; ++j) {
            const std::int32_t n = (*nb)[t][static_cast<std::size_t>(j)];
            if (n < 0 || state[static_cast<std::size_t>(n)] != 0) continue;
            auto& u = tets[static_cast<std::size_t>(n)];
            int back = 0;
            while ((*nb)[static_cast<std::size_t>(n)][static_cast<std::size_t>(back)] != static_cast<std::int32_t>(t)) ++back;
            if (face_sign(tets[t], j) == face_sign(u, back))
                std::swap(u[2], u[3]), std::swap((*nb)[static_cast<std::size_t>(n)][2], (*nb)[static_cast<std::size_t>(n)][3]);
            state[static_cast<std::size_t>(n)] = 2;
            queue.push_back(static_cast<std::uint32_t>(n));
        }
    }
    std::vector<bool> used(positions.size(), false);
    for (const auto& t : tets)
        for (std::uint32_t v : t) used[v] = true;
    for (std::uint32_t id : unique_ids)
        if (!used[id]) out.unused.push_back(id);
    out.tetrahedra = std::move(tets);
    out.neighbours = std::move(nb).value();
    return out;
}

std::vector<std::string> add_tetrahedra(ProbeSet& set) {
    std::vector<std::string> lines;
    set.tetrahedra.clear();
    set.tetra_neighbours.clear();
    if (set.layout.kind != ProbeLayoutKind::kPositions) return lines;
    auto t = tetrahedralize(set.layout.positions);
    if (!t) {
        lines.push_back(t.error().message + ": no tetrahedra stored, the runtimes cannot interpolate these probes");
        return lines;
    }
    auto list = [](const std::vector<std::string>& items) {
        std::string s;
        for (std::size_t i = 0; i < items.size() && i < 8; ++i) s += (i ? ", " : "") + items[i];
        if (items.size() > 8) s += ", ... (" + std::to_string(items.size()) + " in all)";
        return s;
    };
    if (!t->duplicates.empty()) {
        std::vector<std::string> items;
        for (const auto& [probe, first] : t->duplicates) items.push_back(std::to_string(probe) + " (= " + std::to_string(first) + ")");
        lines.push_back("probes at the position of an earlier probe are merged into it (the tetrahedra use the earlier one): " + list(items));
    }
    if (!t->unused.empty()) {
        std::vector<std::string> items;
        for (std::uint32_t probe : t->unused) items.push_back(std::to_string(probe));
        lines.push_back("probes within qhull's precision of another are no tetrahedron vertex: " + list(items));
    }
    set.tetrahedra = std::move(t->tetrahedra);
    set.tetra_neighbours = std::move(t->neighbours);
    return lines;
}

}  // namespace zhc
