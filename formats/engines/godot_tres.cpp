// Godot 4 LightmapGIData probe data as a text resource (.tres): the probes Godot's LightmapGI
// captures dynamic objects with, written and read by zhc (docs/engine-files.md "Godot 4:
// godot_lightmap_gi"). Written from godotengine/godot 4.6.2-stable (version.py):
//  * scene/3d/lightmap_gi.cpp LightmapGIData::_set_probe_data / _get_probe_data (the keys of the
//    `probe_data` Dictionary: bounds, points, tetrahedra, bsp, sh, interior, baked_exposure, and the
//    optional lightprobe_hash), set_capture_data (9 Colors per point, 6 int32 per BSP node);
//  * LightmapGI::bake (the tetrahedra, 4 point indices each, in the order Delaunay3D gives them;
//    the BSP nodes as 4 floats of the plane, bit-cast, then `over`, `under`) and
//    LightmapGI::_compute_bsp_tree / _bsp_get_simplex_side (how the tree is built);
//  * servers/rendering/renderer_rd/storage_rd/light_storage.cpp LightStorage::lightmap_tap_sh_light
//    (the walk: node 0 first, `over` when normal.p > d, a negative child -(t + 1) is tetrahedron t,
//    INT32_MIN an empty leaf; barycentric weights clamped to [0, 1]), the walk's debug check that
//    children come after their node;
//  * core/variant/variant_parser.cpp VariantWriter::write (Dictionary keys sorted, one per line;
//    Packed*Array(a, b, ...); AABB(px, py, pz, sx, sy, sz); floats through rtos_fix: the shortest
//    text that reads back to the same float) and core/io/resource_format_text.cpp (the
//    `[gd_resource type="..." format=3]` header, the `[resource]` section, `name = value`).
// The values are those of the godot_l2 codec entry (codec/probe/engine_layouts.cpp): radiance SH / pi
// in Godot's axes, alpha 0. Godot reads probe_data in every 4.x release (lightprobe_hash, written
// by 4.4 and later, is optional and not written here).
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "codec/probe/engine_layouts.h"
#include "formats/engines/engine_files.h"
#include "formats/probes/tetra.h"

namespace zhc {

namespace {

constexpr std::string_view kName = "godot_lightmap_gi";
constexpr std::int32_t kEmptyLeaf = std::numeric_limits<std::int32_t>::min();
// Reader limits: points per file (Godot indexes them with int32; 2^24 probes is 2.3 GB of text),
// nesting of values (arrays, dictionaries, constructors).
constexpr std::size_t kMaxPoints = std::size_t(1) << 24;
constexpr int kMaxDepth = 64;

const EngineLayoutInfo& godot_layout() {
    static const EngineLayoutInfo* info = find_engine_layout("godot_l2");
    return *info;
}

// ---- Godot's float vector maths (real_t = float), as core/math/vector3.h and plane.h -------------

struct V3 {
    float x = 0, y = 0, z = 0;
    float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
V3 normalized(V3 v) {  // Vector3::normalize: a zero vector stays zero
    const float l2 = v.x * v.x + v.y * v.y + v.z * v.z;
    if (l2 == 0) return {0, 0, 0};
    const float l = std::sqrt(l2);
    return {v.x / l, v.y / l, v.z / l};
}

struct Plane {
    V3 n;
    float d = 0;
    bool over(V3 p) const { return dot(n, p) > d; }                                  // is_point_over
    bool has(V3 p, float eps) const { return std::abs(dot(n, p) - d) <= eps; }       // has_point
    bool is_zero() const { return n.x == 0 && n.y == 0 && n.z == 0 && d == 0; }      // == Plane()
};
// Plane(p1, p2, p3) with the default CLOCKWISE direction: normal (p1 - p3) x (p1 - p2).
Plane plane_of(V3 p1, V3 p2, V3 p3) {
    Plane pl;
    pl.n = normalized(cross(sub(p1, p3), sub(p1, p2)));
    pl.d = dot(pl.n, p1);
    return pl;
}

// ---- the BSP tree, as LightmapGI::_compute_bsp_tree builds it --------------------------------------

// LightmapGI::_bsp_get_simplex_side's faces of a simplex, in its order.
constexpr int kFaceOrder[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 1, 3}, {1, 2, 3}};

struct BspNode {
    Plane plane;
    std::int32_t over = kEmptyLeaf, under = kEmptyLeaf;
};

class BspBuilder {
public:
    BspBuilder(const std::vector<V3>& points, const std::vector<std::array<std::uint32_t, 4>>& simplices)
        : points_(points), simplices_(simplices) {
        // LightmapGI::bake gives every face a plane index, sharing one index among equal planes
        // (either side) so that a node tests each plane once. Godot merges planes equal within
        // is_equal_approx; here equal floats (after choosing the sign): the same planes wherever
        // faces share their three points or lie on one grid plane; a plane tested twice scores the
        // same twice and the first one found is kept either way (the score must be strictly higher).
        std::map<std::array<float, 4>, std::int32_t> index;
        face_plane_.resize(simplices.size());
        for (std::size_t s = 0; s < simplices.size(); ++s)
            for (int j = 0; j < 4; ++j) {
                const Plane p = face(s, j);
                std::array<float, 4> key{p.n.x, p.n.y, p.n.z, p.d};
                const bool flip = key[0] < 0 || (key[0] == 0 && (key[1] < 0 || (key[1] == 0 && key[2] < 0)));
                if (flip)
                    for (float& k : key) k = -k;
                for (float& k : key)
                    if (k == 0) k = 0;  // -0 and 0 are one key
                auto it = index.emplace(key, static_cast<std::int32_t>(index.size())).first;
                face_plane_[s][j] = it->second;
            }
        planes_tested_.assign(index.size(), 0x7FFFFFFF);
    }

    // The nodes in Godot's order (pre-order, the `under` subtree first). Every simplex index list
    // the tree splits has at least 2 entries (Godot's _compute_bsp_tree refuses fewer).
    std::vector<BspNode> build() {
        struct Task {
            std::vector<std::int32_t> simplices;
            std::int32_t parent;
            bool is_over;
        };
        std::vector<Task> stack;
        std::vector<std::int32_t> all(simplices_.size());
        for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
        stack.push_back({std::move(all), -1, false});
        while (!stack.empty()) {
            Task task = std::move(stack.back());
            stack.pop_back();
            const auto node_index = static_cast<std::int32_t>(nodes_.size());
            nodes_.emplace_back();
            if (task.parent >= 0) (task.is_over ? nodes_[task.parent].over : nodes_[task.parent].under) = node_index;
            std::vector<std::int32_t> under, over;
            nodes_[node_index].plane = split(task.simplices, node_index, under, over);
            auto child = [&](std::vector<std::int32_t>& list, bool is_over) {
                std::int32_t& slot = is_over ? nodes_[node_index].over : nodes_[node_index].under;
                if (list.empty())
                    slot = kEmptyLeaf;
                else if (list.size() == 1)
                    slot = -(list[0] + 1);
                else
                    return true;
                return false;
            };
            const bool over_subtree = child(over, true);
            const bool under_subtree = child(under, false);
            // Pushed in reverse so that the `under` subtree is numbered first, as Godot's recursion does.
            if (over_subtree) stack.push_back({std::move(over), node_index, true});
            if (under_subtree) stack.push_back({std::move(under), node_index, false});
        }
        return std::move(nodes_);
    }

private:
    Plane face(std::size_t s, int j) const {
        const auto& v = simplices_[s];
        return plane_of(points_[v[kFaceOrder[j][0]]], points_[v[kFaceOrder[j][1]]], points_[v[kFaceOrder[j][2]]]);
    }

    // _bsp_get_simplex_side: 1 all over, -1 all under, 0 crossing, -2 flat within 1/8192 (dropped).
    int side(const Plane& p, std::int32_t s) const {
        int over = 0, under = 0;
        for (int i = 0; i < 4; ++i) {
            const V3 v = points_[simplices_[static_cast<std::size_t>(s)][i]];
            if (p.has(v, 1.0f / (1 << 13))) {
            } else if (p.over(v)) {
                ++over;
            } else {
                ++under;
            }
        }
        if (under == 0 && over == 0) return -2;
        if (under == 0) return 1;
        if (over == 0) return -1;
        return 0;
    }

    Plane split(const std::vector<std::int32_t>& list, std::int32_t node_index, std::vector<std::int32_t>& under,
                std::vector<std::int32_t>& over) {
        Plane best;
        float best_score = -1.0f;
        for (const std::int32_t idx : list)
            for (int j = 0; j < 4; ++j) {
                std::int32_t& tested = planes_tested_[static_cast<std::size_t>(face_plane_[static_cast<std::size_t>(idx)][j])];
                if (tested == node_index) continue;
                tested = node_index;
                const Plane plane = face(static_cast<std::size_t>(idx), j);
                int over_count = 0, under_count = 0;
                for (const std::int32_t other : list) {
                    const int sd = side(plane, other);
                    if (sd == -2) continue;
                    if (sd < 0) ++under_count;
                    else if (sd > 0) ++over_count;
                }
                if (under_count == 0 && over_count == 0) continue;
                if (under_count > over_count) std::swap(under_count, over_count);
                float score = 0;
                if (over_count > 0) {
                    const float balance = float(under_count) / float(over_count);
                    const float separation = float(over_count + under_count) / float(list.size());
                    score = balance * separation * separation;
                }
                if (score > best_score) {
                    best = plane;
                    best_score = score;
                }
            }
        // No face separates (two simplices sharing at most a point): planes through one point of the
        // first and two of the second, as Godot tries them.
        if (best_score == 0) {
            const auto& s0 = simplices_[static_cast<std::size_t>(list[0])];
            const auto& s1 = simplices_[static_cast<std::size_t>(list[1])];
            for (int i = 0; i < 4 && best_score == 0; ++i) {
                const V3 v0 = points_[s0[i]];
                for (int j = 0; j < 3 && best_score == 0; ++j) {
                    if (s0[i] == s1[j]) break;
                    const V3 v1 = points_[s1[j]];
                    for (int k = j + 1; k < 4; ++k) {
                        if (s0[i] == s1[k]) break;
                        const Plane plane = plane_of(v0, v1, points_[s1[k]]);
                        if (plane.is_zero()) continue;
                        const int a = side(plane, list[0]), b = side(plane, list[1]);
                        if ((a == 1 && b == -1) || (a == -1 && b == 1)) {
                            best = plane;
                            best_score = 1.0f;
                            break;
                        }
                    }
                }
            }
        }
        for (const std::int32_t idx : list) {
            const int sd = side(best, idx);
            if (sd == -2) continue;
            if (sd <= 0) under.push_back(idx);
            if (sd >= 0) over.push_back(idx);
        }
        if (best_score < 0 || over.size() == list.size() || under.size() == list.size()) {
            // Godot's fallback for a triangulation its planes cannot separate: along the longest
            // axis of the simplices' bounds, the simplex with the lowest centre goes under alone,
            // the rest over. (Written as Godot's comment describes it; its code keeps the centre of
            // the first simplex only.)
            V3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
            std::vector<V3> centres;
            for (const std::int32_t idx : list) {
                V3 a = points_[simplices_[static_cast<std::size_t>(idx)][0]], b = a;
                for (int j = 1; j < 4; ++j) {
                    const V3 p = points_[simplices_[static_cast<std::size_t>(idx)][j]];
                    a = {std::min(a.x, p.x), std::min(a.y, p.y), std::min(a.z, p.z)};
                    b = {std::max(b.x, p.x), std::max(b.y, p.y), std::max(b.z, p.z)};
                }
                centres.push_back({(a.x + b.x) * 0.5f, (a.y + b.y) * 0.5f, (a.z + b.z) * 0.5f});
                lo = {std::min(lo.x, a.x), std::min(lo.y, a.y), std::min(lo.z, a.z)};
                hi = {std::max(hi.x, b.x), std::max(hi.y, b.y), std::max(hi.z, b.z)};
            }
            const V3 size = sub(hi, lo);
            const int axis = size.x >= size.y && size.x >= size.z ? 0 : (size.y >= size.z ? 1 : 2);
            std::size_t lowest = 0;
            for (std::size_t i = 1; i < centres.size(); ++i)
                if (centres[i][axis] < centres[lowest][axis]) lowest = i;
            best = Plane{};
            (axis == 0 ? best.n.x : (axis == 1 ? best.n.y : best.n.z)) = 1.0f;
            best.d = centres[lowest][axis];
            under.assign(1, list[lowest]);
            over.clear();
            for (std::size_t i = 0; i < list.size(); ++i)
                if (i != lowest) over.push_back(list[i]);
            ++fallbacks;
        }
        return best;
    }

    const std::vector<V3>& points_;
    const std::vector<std::array<std::uint32_t, 4>>& simplices_;
    std::vector<std::array<std::int32_t, 4>> face_plane_;
    std::vector<std::int32_t> planes_tested_;
    std::vector<BspNode> nodes_;

public:
    int fallbacks = 0;
};

// ---- text output ---------------------------------------------------------------------------------

// rtos_fix of a float: "0" for either zero, else the shortest text that reads back to the float.
void put_float(std::string& out, float v) {
    if (v == 0) {
        out += '0';
        return;
    }
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}
void put_int(std::string& out, std::int64_t v) {
    char buf[24];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}
std::int32_t float_bits(float f) {
    std::int32_t i;
    std::memcpy(&i, &f, 4);
    return i;
}

Result<EngineFileOutput> godot_write(const EngineFileInput& in) {
    const auto fail = [](std::string what) {
        return Error{ErrorCode::kInvalidArgument, std::string(kName) + ": " + std::move(what)};
    };
    const std::int64_t count = layout_probe_count(in.layout);
    if (in.layout.kind == ProbeLayoutKind::kNone || count < 0)
        return fail("probes without positions cannot be written (a grid or positions layout is needed)");
    if (static_cast<std::uint64_t>(count) != in.hub.size())
        return fail("the layout describes " + std::to_string(count) + " probes, " + std::to_string(in.hub.size()) +
                    " were given");
    if (!in.validity.empty() && in.validity.size() != in.hub.size())
        return fail("validity has " + std::to_string(in.validity.size()) + " entries for " +
                    std::to_string(in.hub.size()) + " probes");
    if (in.hub.size() > kMaxPoints)
        return fail(std::to_string(in.hub.size()) + " probes exceed the " + std::to_string(kMaxPoints) + " written");

    EngineFileOutput out;
    // Godot has no invalid probes: those with validity 0 (inside geometry) are left out of the
    // file, and the tetrahedra are those of the valid ones, so Godot blends valid probes only.
    std::vector<std::uint32_t> kept;  // written point -> input probe
    for (std::size_t i = 0; i < in.hub.size(); ++i)
        if (in.validity.empty() || in.validity[i] != 0) kept.push_back(static_cast<std::uint32_t>(i));
    if (kept.size() < in.hub.size())
        out.notes.push_back(std::to_string(in.hub.size() - kept.size()) +
                            " invalid probes (validity 0) left out: Godot blends the valid ones");

    std::vector<std::array<float, 3>> zhc_pos(kept.size());
    for (std::size_t k = 0; k < kept.size(); ++k) {
        const std::uint32_t i = kept[k];
        if (in.layout.kind == ProbeLayoutKind::kGrid) {
            const auto& g = in.layout.grid;
            const std::uint32_t x = i % g.counts[0], y = (i / g.counts[0]) % g.counts[1],
                                z = i / g.counts[0] / g.counts[1];
            zhc_pos[k] = {static_cast<float>(g.origin.x + x * g.spacing.x), static_cast<float>(g.origin.y + y * g.spacing.y),
                          static_cast<float>(g.origin.z + z * g.spacing.z)};
        } else {
            zhc_pos[k] = in.layout.positions[i];
        }
        for (float c : zhc_pos[k])
            if (!std::isfinite(c)) return fail("probe " + std::to_string(i) + " has a non-finite position");
    }

    // Tetrahedra: the input's when every probe is kept, else the Delaunay tetrahedra of the kept ones.
    std::vector<std::array<std::uint32_t, 4>> tets;
    if (!in.tetrahedra.empty() && kept.size() == in.hub.size()) {
        for (const auto& t : in.tetrahedra)
            for (std::uint32_t v : t)
                if (v >= kept.size()) return fail("a tetrahedron names probe " + std::to_string(v) + " of " +
                                                  std::to_string(kept.size()));
        tets.assign(in.tetrahedra.begin(), in.tetrahedra.end());
    } else {
        auto t = tetrahedralize(zhc_pos);
        if (!t) return fail("no tetrahedra for Godot's probes: " + t.error().message);
        tets = std::move(t->tetrahedra);
        if (!t->duplicates.empty())
            out.notes.push_back(std::to_string(t->duplicates.size()) +
                                " probes share a position with another: written, never blended");
        if (!t->unused.empty())
            out.notes.push_back(std::to_string(t->unused.size()) +
                                " probes are in no tetrahedron (within qhull's precision of another): written, never blended");
    }
    if (tets.empty()) return fail("no tetrahedra for Godot's probes");

    const Mat3& axes = godot_layout().axes;
    std::vector<V3> pts(kept.size());
    for (std::size_t k = 0; k < kept.size(); ++k) {
        const Vec3 e = axes * Vec3{zhc_pos[k][0], zhc_pos[k][1], zhc_pos[k][2]};
        pts[k] = {static_cast<float>(e.x), static_cast<float>(e.y), static_cast<float>(e.z)};
    }

    std::vector<BspNode> nodes;
    if (tets.size() == 1) {
        // Godot's _compute_bsp_tree builds nothing for one tetrahedron (and the walk then finds
        // none): one node whose zero plane sends every point under, to the tetrahedron.
        BspNode n;
        n.over = n.under = -1;
        nodes.push_back(n);
    } else {
        BspBuilder builder(pts, tets);
        nodes = builder.build();
        if (builder.fallbacks > 0)
            out.notes.push_back("Godot's BSP fallback split " + std::to_string(builder.fallbacks) +
                                " nodes (tetrahedra no face plane separates)");
    }

    const Codec* codec = find_codec("godot_l2");
    std::vector<std::uint8_t> stored(codec->size_bytes);

    V3 lo = pts[0], hi = pts[0];
    for (const V3& p : pts) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }

    std::string s;
    s.reserve(kept.size() * 480 + tets.size() * 40 + nodes.size() * 80 + 512);
    s += "[gd_resource type=\"LightmapGIData\" format=3]\n\n[resource]\nprobe_data = {\n";
    s += "\"baked_exposure\": 1.0,\n\"bounds\": AABB(";
    const float bounds[6] = {lo.x, lo.y, lo.z, hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
    for (int i = 0; i < 6; ++i) {
        if (i) s += ", ";
        put_float(s, bounds[i]);
    }
    s += "),\n\"bsp\": PackedInt32Array(";
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (i) s += ", ";
        const BspNode& n = nodes[i];
        for (float f : {n.plane.n.x, n.plane.n.y, n.plane.n.z, n.plane.d}) {
            put_int(s, float_bits(f));
            s += ", ";
        }
        put_int(s, n.over);
        s += ", ";
        put_int(s, n.under);
    }
    s += "),\n\"interior\": false,\n\"points\": PackedVector3Array(";
    for (std::size_t k = 0; k < pts.size(); ++k) {
        if (k) s += ", ";
        put_float(s, pts[k].x);
        s += ", ";
        put_float(s, pts[k].y);
        s += ", ";
        put_float(s, pts[k].z);
    }
    s += "),\n\"sh\": PackedColorArray(";
    for (std::size_t k = 0; k < kept.size(); ++k) {
        encode_probe(*codec, CodecOptions{}, in.hub[kept[k]], stored.data(), nullptr);
        for (int c = 0; c < 36; ++c) {
            if (k || c) s += ", ";
            float f;
            std::memcpy(&f, stored.data() + 4 * c, 4);  // little-endian float32 (le_bytes.h), as stored
            put_float(s, f);
        }
    }
    s += "),\n\"tetrahedra\": PackedInt32Array(";
    for (std::size_t t = 0; t < tets.size(); ++t)
        for (int j = 0; j < 4; ++j) {
            if (t || j) s += ", ";
            put_int(s, tets[t][j]);
        }
    s += ")\n}\n";
    out.bytes.assign(s.begin(), s.end());
    out.notes.push_back("assign the file to a LightmapGI node's light_data; the node's transform must be the identity "
                        "(the points are in its space, Godot's axes)");
    return out;
}

// ---- text input ----------------------------------------------------------------------------------

// A value of Godot's text resource grammar (VariantParser::parse_value), as much as the reader
// keeps. Every value is parsed (the grammar checked), but only a kept one stores its contents: a
// constructor's numbers, and a dictionary's entries under the keys `wanted` names; array items and
// other constructor arguments are never stored. So memory grows with what probe_data needs (8
// bytes a number, at most 4 times the text), never with what other properties hold.
struct Value {
    enum Kind { kNumber, kString, kIdent, kConstruct, kArray, kDict } kind = kNumber;
    double number = 0;
    bool integer = false;
    std::int64_t integer_value = 0;
    std::string text;             // string, identifier, constructor name
    std::vector<double> numbers;  // a kept constructor's numeric arguments
    bool all_ints = true;         // every numeric argument an integer literal
    bool other_args = false;      // arguments that are not numbers
    std::vector<Value> items;     // a kept dictionary's wanted entries: key, value, key, value ...
    int line = 0;
};
// The probe_data keys the reader keeps (LightmapGIData::_set_probe_data's).
bool wanted(const Value& key) {
    if (key.kind != Value::kString) return false;
    for (const char* k : {"bounds", "points", "tetrahedra", "bsp", "sh", "interior", "baked_exposure"})
        if (key.text == k) return true;
    return false;
}

class Parser {
public:
    Parser(std::string_view text, const std::string& name) : s_(text), name_(name) {}

    Error error(ErrorCode code, const std::string& what, int line) const {
        return Error{code, name_ + ": " + what + " (line " + std::to_string(line) + ")"};
    }

    // The whole file: header tag, then sections; returns the [resource] section's probe_data.
    Result<Value> probe_data() {
        skip_space();
        if (!starts("[gd_resource")) return error(ErrorCode::kBadFormat, "not a Godot text resource ([gd_resource expected)", line_);
        auto tag = parse_tag();
        if (!tag) return tag.error();
        if (tag->first != "gd_resource") return error(ErrorCode::kBadFormat, "the first tag is not gd_resource", 1);
        const auto& attrs = tag->second;
        auto type = attrs.find("type");
        if (type == attrs.end() || type->second.kind != Value::kString || type->second.text != "LightmapGIData")
            return error(ErrorCode::kBadFormat, "the resource is not a LightmapGIData", 1);
        auto format = attrs.find("format");
        if (format == attrs.end() || !format->second.integer)
            return error(ErrorCode::kBadFormat, "the gd_resource tag has no integer format", 1);
        if (format->second.integer_value != 3 && format->second.integer_value != 4)
            return error(ErrorCode::kUnsupported,
                         "format=" + std::to_string(format->second.integer_value) +
                             " is not Godot 4's text resource (format 3 or 4)",
                         1);
        std::string section;
        bool have = false;
        Value data;
        while (true) {
            skip_space();
            if (pos_ >= s_.size()) break;
            if (s_[pos_] == '[') {
                auto t = parse_tag();
                if (!t) return t.error();
                section = t->first;
                continue;
            }
            const int line = line_;
            auto key = parse_key();
            if (!key) return key.error();
            const bool keep = section == "resource" && *key == "probe_data";
            auto v = parse_value(0, keep);
            if (!v) return v.error();
            if (keep) {
                if (have) return error(ErrorCode::kBadFormat, "probe_data is assigned twice", line);
                data = std::move(*v);
                data.line = line;
                have = true;
            } else if (section.empty()) {
                return error(ErrorCode::kBadFormat, "a property outside any section", line);
            }
        }
        if (!have) return error(ErrorCode::kBadFormat, "no probe_data in the [resource] section", line_);
        return data;
    }

private:
    bool starts(std::string_view p) const { return s_.substr(pos_, p.size()) == p; }
    void skip_space() {
        while (pos_ < s_.size()) {
            const char c = s_[pos_];
            if (c == '\n') {
                ++line_;
                ++pos_;
            } else if (static_cast<unsigned char>(c) <= 32) {
                ++pos_;
            } else if (c == ';') {  // a comment to the end of the line (VariantParser::get_token)
                while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
            } else {
                break;
            }
        }
    }

    // [name key=value key=value]
    Result<std::pair<std::string, std::map<std::string, Value>>> parse_tag() {
        const int line = line_;
        ++pos_;  // '['
        std::string name;
        while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_'))
            name += s_[pos_++];
        if (name.empty()) return error(ErrorCode::kBadFormat, "a tag without a name", line);
        std::map<std::string, Value> attrs;
        while (true) {
            skip_space();
            if (pos_ >= s_.size()) return error(ErrorCode::kTruncated, "the tag [" + name + " is not closed", line);
            if (s_[pos_] == ']') {
                ++pos_;
                break;
            }
            std::string key;
            while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_'))
                key += s_[pos_++];
            if (key.empty() || pos_ >= s_.size() || s_[pos_] != '=')
                return error(ErrorCode::kBadFormat, "malformed attribute in the tag [" + name, line_);
            ++pos_;
            auto v = parse_value(0, false);
            if (!v) return v.error();
            attrs[key] = std::move(*v);
        }
        return std::make_pair(std::move(name), std::move(attrs));
    }

    // A property name up to '=' (resource_format_text: any characters but '=', or a quoted string).
    Result<std::string> parse_key() {
        const int line = line_;
        std::string key;
        while (pos_ < s_.size() && s_[pos_] != '=' && s_[pos_] != '\n') key += s_[pos_++];
        if (pos_ >= s_.size() || s_[pos_] != '=')
            return error(ErrorCode::kBadFormat, "a line that is neither a tag nor name = value", line);
        ++pos_;
        while (!key.empty() && static_cast<unsigned char>(key.back()) <= 32) key.pop_back();
        return key;
    }

    struct Token {
        enum Type { kEof, kPunct, kString, kNumber, kIdent } type = kEof;
        char punct = 0;
        std::string text;
        int line = 0;
    };

    Result<Token> next() {
        skip_space();
        Token t;
        t.line = line_;
        if (pos_ >= s_.size()) return t;
        const char c = s_[pos_];
        if (std::strchr("{}[](),:=", c)) {
            t.type = Token::kPunct;
            t.punct = c;
            ++pos_;
            return t;
        }
        if (c == '"' || ((c == '&' || c == '^') && pos_ + 1 < s_.size() && s_[pos_ + 1] == '"')) {
            if (c != '"') ++pos_;
            ++pos_;
            t.type = Token::kString;
            while (true) {
                if (pos_ >= s_.size()) return error(ErrorCode::kTruncated, "unterminated string", t.line);
                const char ch = s_[pos_++];
                if (ch == '"') break;
                if (ch == '\n') ++line_;
                if (ch == '\\') {
                    if (pos_ >= s_.size()) return error(ErrorCode::kTruncated, "unterminated string", t.line);
                    const char e = s_[pos_++];
                    t.text += e == 'n' ? '\n' : (e == 't' ? '\t' : e);
                } else {
                    t.text += ch;
                }
            }
            return t;
        }
        if (c == '-' || (c >= '0' && c <= '9')) {
            std::size_t e = pos_ + 1;
            while (e < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[e])) || s_[e] == '.' ||
                                     ((s_[e] == '-' || s_[e] == '+') && (s_[e - 1] == 'e' || s_[e - 1] == 'E'))))
                ++e;
            t.type = Token::kNumber;
            t.text.assign(s_.substr(pos_, e - pos_));
            pos_ = e;
            return t;
        }
        if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
            std::size_t e = pos_;
            while (e < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[e])) || s_[e] == '_')) ++e;
            t.type = Token::kIdent;
            t.text.assign(s_.substr(pos_, e - pos_));
            pos_ = e;
            return t;
        }
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02x", static_cast<unsigned char>(c));
        return error(ErrorCode::kBadFormat, std::string("unexpected character ") + hex, t.line);
    }

    Result<Value> number(const Token& t) {
        Value v;
        v.kind = Value::kNumber;
        v.line = t.line;
        const char* b = t.text.data();
        const char* e = b + t.text.size();
        if (t.text == "-inf") {  // num_scientific's negative infinity
            v.number = -INFINITY;
            return v;
        }
        const bool is_float = t.text.find_first_of(".eE") != std::string::npos;
        if (!is_float) {
            auto r = std::from_chars(b, e, v.integer_value);
            if (r.ec == std::errc() && r.ptr == e) {
                v.integer = true;
                v.number = static_cast<double>(v.integer_value);
                return v;
            }
            if (r.ec == std::errc::result_out_of_range)
                return error(ErrorCode::kInvalidValue, "integer " + t.text + " out of range", t.line);
        }
        auto r = std::from_chars(b, e, v.number);
        if (r.ec != std::errc() || r.ptr != e) return error(ErrorCode::kBadFormat, "malformed number " + t.text, t.line);
        return v;
    }

    Result<Value> parse_value(int depth, bool keep) {
        if (depth > kMaxDepth) return error(ErrorCode::kTooLarge, "values nested deeper than " + std::to_string(kMaxDepth), line_);
        auto tok = next();
        if (!tok) return tok.error();
        return value_from(*tok, depth, keep);
    }

    Result<Value> value_from(const Token& t, int depth, bool keep) {
        switch (t.type) {
            case Token::kEof:
                return error(ErrorCode::kTruncated, "the file ends where a value was expected", t.line);
            case Token::kNumber:
                return number(t);
            case Token::kString: {
                Value v;
                v.kind = Value::kString;
                v.text = t.text;
                v.line = t.line;
                return v;
            }
            case Token::kPunct:
                if (t.punct == '[' || t.punct == '{') return list(t.punct, depth, t.line, keep);
                return error(ErrorCode::kBadFormat, std::string("unexpected '") + t.punct + "'", t.line);
            case Token::kIdent:
                break;
        }
        Value v;
        v.kind = Value::kIdent;
        v.text = t.text;
        v.line = t.line;
        skip_space();
        if (pos_ < s_.size() && s_[pos_] == '[') {  // Array[Type](...), Dictionary[K, V](...)
            ++pos_;
            auto types = list('[', depth + 1, line_, false);
            if (!types) return types.error();
            skip_space();
        }
        if (pos_ < s_.size() && s_[pos_] == '(') {
            ++pos_;
            v.kind = Value::kConstruct;
            bool first = true;
            while (true) {
                auto a = next();
                if (!a) return a.error();
                if (a->type == Token::kPunct && a->punct == ')') break;
                if (!first) {
                    if (a->type != Token::kPunct || a->punct != ',')
                        return error(ErrorCode::kBadFormat, "expected ',' or ')' in " + v.text + "(...)", a->line);
                    a = next();
                    if (!a) return a.error();
                }
                first = false;
                if (a->type == Token::kNumber) {
                    auto n = number(*a);
                    if (!n) return n.error();
                    if (keep) v.numbers.push_back(n->number);
                    if (!n->integer) v.all_ints = false;
                } else if (a->type == Token::kIdent && (a->text == "nan" || a->text == "inf" || a->text == "inf_neg")) {
                    if (keep) v.numbers.push_back(a->text == "nan" ? NAN : (a->text == "inf" ? INFINITY : -INFINITY));
                    v.all_ints = false;
                } else {
                    auto item = value_from(*a, depth + 1, false);
                    if (!item) return item.error();
                    v.other_args = true;
                }
            }
        }
        return v;
    }

    // [a, b, ...] or {k: v, ...}; the opening bracket is consumed.
    Result<Value> list(char open, int depth, int line, bool keep) {
        if (depth > kMaxDepth) return error(ErrorCode::kTooLarge, "values nested deeper than " + std::to_string(kMaxDepth), line);
        Value v;
        v.kind = open == '[' ? Value::kArray : Value::kDict;
        v.line = line;
        const char close = open == '[' ? ']' : '}';
        bool first = true;
        while (true) {
            auto a = next();
            if (!a) return a.error();
            if (a->type == Token::kEof) return error(ErrorCode::kTruncated, std::string("'") + open + "' is not closed", line);
            if (a->type == Token::kPunct && a->punct == close) break;
            if (!first) {
                if (a->type != Token::kPunct || a->punct != ',')
                    return error(ErrorCode::kBadFormat, std::string("expected ',' or '") + close + "'", a->line);
                a = next();
                if (!a) return a.error();
            }
            first = false;
            auto item = value_from(*a, depth + 1, false);
            if (!item) return item.error();
            if (open == '{') {
                auto colon = next();
                if (!colon) return colon.error();
                if (colon->type != Token::kPunct || colon->punct != ':')
                    return error(ErrorCode::kBadFormat, "expected ':' in a dictionary", colon->line);
                const bool store = keep && wanted(*item);
                auto val = parse_value(depth + 1, store);
                if (!val) return val.error();
                if (store) {
                    v.items.push_back(std::move(*item));
                    v.items.push_back(std::move(*val));
                }
            }
        }
        return v;
    }

    std::string_view s_;
    const std::string& name_;
    std::size_t pos_ = 0;
    int line_ = 1;
};

Result<EngineFileProbes> godot_read(std::span<const std::uint8_t> bytes, const std::string& name) {
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    Parser parser(text, name);
    auto data = parser.probe_data();
    if (!data) return data.error();
    const auto bad = [&](ErrorCode code, const std::string& what, int line) {
        return Error{code, name + ": probe_data " + what + " (line " + std::to_string(line) + ")"};
    };
    if (data->kind != Value::kDict) return bad(ErrorCode::kBadFormat, "is not a Dictionary", data->line);
    std::map<std::string, const Value*> keys;
    for (std::size_t i = 0; i + 1 < data->items.size(); i += 2) {
        const Value& k = data->items[i];
        if (!keys.emplace(k.text, &data->items[i + 1]).second)
            return bad(ErrorCode::kBadFormat, "has the key \"" + k.text + "\" twice", k.line);
    }
    // The keys LightmapGIData::_set_probe_data requires.
    for (const char* k : {"bounds", "points", "tetrahedra", "bsp", "sh", "interior", "baked_exposure"})
        if (!keys.count(k)) return bad(ErrorCode::kBadFormat, std::string("has no \"") + k + "\"", data->line);
    const auto construct = [&](const char* key, const char* type) -> Result<const Value*> {
        const Value* v = keys[key];
        if (v->kind != Value::kConstruct || v->text != type || v->other_args)
            return bad(ErrorCode::kBadFormat, std::string("\"") + key + "\" is not a " + type + " of numbers", v->line);
        return v;
    };
    auto points = construct("points", "PackedVector3Array");
    if (!points) return points.error();
    auto sh = construct("sh", "PackedColorArray");
    if (!sh) return sh.error();
    auto tetra = construct("tetrahedra", "PackedInt32Array");
    if (!tetra) return tetra.error();
    auto bsp = construct("bsp", "PackedInt32Array");
    if (!bsp) return bsp.error();
    auto bounds = construct("bounds", "AABB");
    if (!bounds) return bounds.error();
    const Value* interior = keys["interior"];
    if (interior->kind != Value::kIdent || (interior->text != "true" && interior->text != "false"))
        return bad(ErrorCode::kBadFormat, "\"interior\" is not a bool", interior->line);
    const Value* exposure = keys["baked_exposure"];
    if (exposure->kind != Value::kNumber || !std::isfinite(exposure->number) || exposure->number <= 0)
        return bad(ErrorCode::kInvalidValue, "\"baked_exposure\" is not a positive number", exposure->line);

    const auto& pv = (*points)->numbers;
    if (pv.size() % 3) return bad(ErrorCode::kBadFormat, "\"points\" does not hold whole Vector3s", (*points)->line);
    const std::size_t n = pv.size() / 3;
    if (n > kMaxPoints)
        return bad(ErrorCode::kTooLarge, "holds " + std::to_string(n) + " points, more than " + std::to_string(kMaxPoints),
                   (*points)->line);
    if (n == 0) return bad(ErrorCode::kBadFormat, "holds no points", (*points)->line);
    if ((*sh)->numbers.size() != n * 36)
        return bad(ErrorCode::kBadFormat,
                   "\"sh\" holds " + std::to_string((*sh)->numbers.size()) + " numbers, 9 Colors per point need " +
                       std::to_string(n * 36),
                   (*sh)->line);
    if ((*bounds)->numbers.size() != 6) return bad(ErrorCode::kBadFormat, "\"bounds\" is not AABB(6 numbers)", (*bounds)->line);
    for (double b : (*bounds)->numbers)
        if (!std::isfinite(b)) return bad(ErrorCode::kInvalidValue, "\"bounds\" is not finite", (*bounds)->line);
    for (double p : pv)
        if (!std::isfinite(p) || std::abs(p) > 3.4e38) return bad(ErrorCode::kInvalidValue, "\"points\" holds a non-finite number", (*points)->line);
    for (double c : (*sh)->numbers)
        if (!std::isfinite(c) || std::abs(c) > 3.4e38) return bad(ErrorCode::kInvalidValue, "\"sh\" holds a non-finite number", (*sh)->line);

    // Tetrahedra and BSP: checked as Godot's walk relies on them (indices in range; each child after
    // its node, so the walk ends).
    // Integer literals (all_ints) held as doubles: exact within int32, checked before any cast.
    const auto& tv = (*tetra)->numbers;
    if (!(*tetra)->all_ints || tv.size() % 4)
        return bad(ErrorCode::kBadFormat, "\"tetrahedra\" is not 4 integers per tetrahedron", (*tetra)->line);
    for (double v : tv)
        if (v < 0 || v >= static_cast<double>(n))
            return bad(ErrorCode::kBadFormat, "\"tetrahedra\" names point " + std::to_string(static_cast<long long>(v)) +
                                                  " of " + std::to_string(n),
                       (*tetra)->line);
    const std::size_t tet_count = tv.size() / 4;
    const auto& bv = (*bsp)->numbers;
    if (!(*bsp)->all_ints || bv.size() % 6)
        return bad(ErrorCode::kBadFormat, "\"bsp\" is not 6 integers per node", (*bsp)->line);
    const std::size_t nodes = bv.size() / 6;
    for (std::size_t i = 0; i < bv.size(); ++i) {
        if (bv[i] < std::numeric_limits<std::int32_t>::min() || bv[i] > std::numeric_limits<std::int32_t>::max())
            return bad(ErrorCode::kBadFormat, "\"bsp\" holds " + std::to_string(static_cast<long long>(bv[i])) + ", not an int32",
                       (*bsp)->line);
        const auto v = static_cast<std::int64_t>(bv[i]);
        if (i % 6 < 4) {
            float f;
            const auto bits = static_cast<std::int32_t>(v);
            std::memcpy(&f, &bits, 4);
            if (!std::isfinite(f)) return bad(ErrorCode::kInvalidValue, "\"bsp\" node " + std::to_string(i / 6) + " has a non-finite plane", (*bsp)->line);
        } else if (v >= 0) {
            if (static_cast<std::size_t>(v) <= i / 6 || static_cast<std::size_t>(v) >= nodes)
                return bad(ErrorCode::kBadFormat,
                           "\"bsp\" node " + std::to_string(i / 6) + " has child " + std::to_string(v) +
                               " (children follow their node, " + std::to_string(nodes) + " nodes)",
                           (*bsp)->line);
        } else if (v != kEmptyLeaf && static_cast<std::size_t>(-v - 1) >= tet_count) {
            return bad(ErrorCode::kBadFormat,
                       "\"bsp\" node " + std::to_string(i / 6) + " names tetrahedron " + std::to_string(-v - 1) + " of " +
                           std::to_string(tet_count),
                       (*bsp)->line);
        }
    }

    EngineFileProbes out;
    const Mat3& axes = godot_layout().axes;
    const Codec* codec = find_codec("godot_l2");
    std::vector<std::uint8_t> stored(codec->size_bytes);
    out.hub.reserve(n);
    out.layout.kind = ProbeLayoutKind::kPositions;
    out.layout.positions.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        // v_godot = axes v_zhc with axes a signed permutation: v_zhc = axes^T v_godot.
        const Vec3 g{static_cast<float>(pv[3 * i]), static_cast<float>(pv[3 * i + 1]), static_cast<float>(pv[3 * i + 2])};
        std::array<float, 3> p{};
        for (int r = 0; r < 3; ++r)
            p[static_cast<std::size_t>(r)] = static_cast<float>(axes(0, r) * g.x + axes(1, r) * g.y + axes(2, r) * g.z);
        out.layout.positions.push_back(p);
        for (int c = 0; c < 36; ++c) {
            const float f = static_cast<float>((*sh)->numbers[36 * i + static_cast<std::size_t>(c)]);
            std::memcpy(stored.data() + 4 * c, &f, 4);
        }
        out.hub.push_back(decode_probe(*codec, CodecOptions{}, stored.data()));
    }
    if (tet_count == 0 || nodes == 0)
        out.notes.push_back("the file holds no tetrahedra or no BSP tree: Godot captures nothing from it");
    if (exposure->number != 1.0)
        out.notes.push_back("baked with exposure normalization " + std::to_string(exposure->number) +
                            ": the SH are read as stored");
    if (interior->text == "true")
        out.notes.push_back("an interior lightmap: where it overlaps exterior ones, Godot captures from it alone");
    return out;
}

bool godot_sniff(std::span<const std::uint8_t> bytes) {
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), std::min<std::size_t>(bytes.size(), 4096));
    if (text.substr(0, 12) != "[gd_resource") return false;
    const std::string_view tag = text.substr(0, text.find(']'));
    return tag.find("type=\"LightmapGIData\"") != std::string_view::npos;
}

}  // namespace

extern const EngineFile kGodotLightmapGiFile;
const EngineFile kGodotLightmapGiFile = {
    kName,
    "Godot 4 LightmapGIData (text resource)",
    ".tres",
    "godot_l2",
    "godotengine/godot 4.6 scene/3d/lightmap_gi.cpp LightmapGIData::_set_probe_data, LightmapGI::bake, "
    "_compute_bsp_tree; servers/rendering/renderer_rd/storage_rd/light_storage.cpp lightmap_tap_sh_light; "
    "core/variant/variant_parser.cpp VariantWriter::write; core/io/resource_format_text.cpp",
    godot_sniff,
    godot_write,
    godot_read,
};

}  // namespace zhc
