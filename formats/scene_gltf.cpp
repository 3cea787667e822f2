#include "scene_gltf.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>

#include "file_io.h"

namespace zhc {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

struct Fail {
    Error error;
};

// glTF -> zhc axes: (x, y, z)_zhc = (z, x, y)_glTF (inverse of gltf_probes' to_gltf).
Vec3 from_gltf(Vec3 v) { return {v.z, v.x, v.y}; }

// Column-major 4x4 as glTF stores it: m[c * 4 + r].
struct Mat4 {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    double at(int r, int c) const { return m[static_cast<size_t>(c * 4 + r)]; }
};
Mat4 mul(const Mat4& a, const Mat4& b) {
    Mat4 o;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a.at(r, k) * b.at(k, c);
            o.m[static_cast<size_t>(c * 4 + r)] = s;
        }
    return o;
}
Vec3 point(const Mat4& a, Vec3 p) {
    return {a.at(0, 0) * p.x + a.at(0, 1) * p.y + a.at(0, 2) * p.z + a.at(0, 3),
            a.at(1, 0) * p.x + a.at(1, 1) * p.y + a.at(1, 2) * p.z + a.at(1, 3),
            a.at(2, 0) * p.x + a.at(2, 1) * p.y + a.at(2, 2) * p.z + a.at(2, 3)};
}
Vec3 vector(const Mat4& a, Vec3 v) {
    return {a.at(0, 0) * v.x + a.at(0, 1) * v.y + a.at(0, 2) * v.z, a.at(1, 0) * v.x + a.at(1, 1) * v.y + a.at(1, 2) * v.z,
            a.at(2, 0) * v.x + a.at(2, 1) * v.y + a.at(2, 2) * v.z};
}
bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::uint32_t le32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

constexpr int kUbyte = 5121, kUshort = 5123, kUint = 5125, kFloat = 5126;

struct LightDef {
    LightKind kind = LightKind::kPoint;
    std::string name;
    Rgb color{1, 1, 1};
    double intensity = 1;
    double inner = 0, outer = kPi / 4;
};

class Reader {
public:
    Reader(std::string path, const json& doc, const GltfRaw& raw, const SceneLoadOptions& options)
        : path_(std::move(path)), doc_(doc), raw_(raw), options_(options) {}

    [[noreturn]] void fail(ErrorCode code, const std::string& where, const std::string& what) const {
        throw Fail{make_error(code, path_ + ": " + (where.empty() ? "" : where + ": ") + what)};
    }
    static std::string at(const std::string& p, size_t i) { return p + "[" + std::to_string(i) + "]"; }

    double number(const json& j, const std::string& where) const {
        if (!j.is_number()) fail(ErrorCode::kInvalidValue, where, "must be a number (got " + std::string(j.type_name()) + ")");
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(ErrorCode::kInvalidValue, where, "must be finite");
        return v;
    }
    // A non-negative integer index below `size`.
    size_t index(const json& j, const std::string& where, size_t size, const char* what) const {
        if (!j.is_number_unsigned() || j.get<std::uint64_t>() >= size)
            fail(ErrorCode::kInvalidValue, where,
                 std::string("must be an index into ") + what + " (0.." + std::to_string(size) + "), got " + j.dump());
        return static_cast<size_t>(j.get<std::uint64_t>());
    }
    std::uint64_t count(const json& obj, const char* key, const std::string& where, bool required, std::uint64_t fallback) const {
        if (!obj.contains(key)) {
            if (required) fail(ErrorCode::kInvalidValue, where + "." + key, "missing required field");
            return fallback;
        }
        const json& j = obj[key];
        if (!j.is_number_unsigned()) fail(ErrorCode::kInvalidValue, where + "." + key, "must be a non-negative integer (got " + j.dump() + ")");
        return j.get<std::uint64_t>();
    }
    const json& array_of(const json& obj, const char* key) const {
        static const json empty = json::array();
        if (!obj.is_object() || !obj.contains(key)) return empty;
        if (!obj[key].is_array()) fail(ErrorCode::kInvalidValue, key, "must be an array");
        return obj[key];
    }
    std::vector<double> numbers(const json& j, const std::string& where, size_t n) const {
        if (!j.is_array() || j.size() != n) fail(ErrorCode::kInvalidValue, where, "must be an array of " + std::to_string(n) + " numbers");
        std::vector<double> v(n);
        for (size_t i = 0; i < n; ++i) v[i] = number(j[i], at(where, i));
        return v;
    }

    // ---- KHR_lights_punctual -------------------------------------------------------------------
    void read_light_defs() {
        if (!doc_.contains("extensions")) return;
        const json& ext = doc_["extensions"];
        if (!ext.is_object()) fail(ErrorCode::kInvalidValue, "extensions", "must be an object");
        if (!ext.contains("KHR_lights_punctual")) return;
        const std::string p = "extensions.KHR_lights_punctual.lights";
        const json& k = ext["KHR_lights_punctual"];
        if (!k.is_object() || !k.contains("lights") || !k["lights"].is_array()) fail(ErrorCode::kInvalidValue, p, "must be an array");
        const json& lights = k["lights"];
        if (lights.size() > options_.limits.max_lights)
            fail(ErrorCode::kTooLarge, p, std::to_string(lights.size()) + " lights exceed the limit of " + std::to_string(options_.limits.max_lights));
        for (size_t i = 0; i < lights.size(); ++i) {
            const std::string lp = at(p, i);
            const json& l = lights[i];
            if (!l.is_object()) fail(ErrorCode::kInvalidValue, lp, "must be an object");
            LightDef d;
            if (!l.contains("type") || !l["type"].is_string()) fail(ErrorCode::kInvalidValue, lp + ".type", "missing or not a string");
            const std::string type = l["type"].get<std::string>();
            if (type == "directional") d.kind = LightKind::kDirectional;
            else if (type == "point") d.kind = LightKind::kPoint;
            else if (type == "spot") d.kind = LightKind::kSpot;
            else fail(ErrorCode::kUnsupported, lp + ".type", "unknown light type \"" + type + "\" (known: directional, point, spot)");
            d.name = l.contains("name") && l["name"].is_string() ? l["name"].get<std::string>() : "gltf light " + std::to_string(i);
            if (l.contains("color")) {
                const auto c = numbers(l["color"], lp + ".color", 3);
                for (int k2 = 0; k2 < 3; ++k2) {
                    if (c[static_cast<size_t>(k2)] < 0) fail(ErrorCode::kInvalidValue, at(lp + ".color", size_t(k2)), "must be >= 0");
                    d.color[k2] = static_cast<float>(c[static_cast<size_t>(k2)]);
                }
            }
            if (l.contains("intensity")) {
                d.intensity = number(l["intensity"], lp + ".intensity");
                if (d.intensity < 0) fail(ErrorCode::kInvalidValue, lp + ".intensity", "must be >= 0");
            }
            if (l.contains("range")) {  // a renderer's cut-off hint; zhc keeps pure inverse square
                const double range = number(l["range"], lp + ".range");
                if (!(range > 0)) fail(ErrorCode::kInvalidValue, lp + ".range", "must be > 0");
            }
            if (d.kind == LightKind::kSpot) {
                const json empty = json::object();
                const json& s = l.contains("spot") ? l["spot"] : empty;
                if (!s.is_object()) fail(ErrorCode::kInvalidValue, lp + ".spot", "must be an object");
                if (s.contains("innerConeAngle")) d.inner = number(s["innerConeAngle"], lp + ".spot.innerConeAngle");
                if (s.contains("outerConeAngle")) d.outer = number(s["outerConeAngle"], lp + ".spot.outerConeAngle");
                // The extension's constraints: 0 <= inner < outer <= pi / 2.
                if (!(d.inner >= 0 && d.inner < d.outer && d.outer <= kPi / 2))
                    fail(ErrorCode::kInvalidValue, lp + ".spot", "need 0 <= innerConeAngle < outerConeAngle <= pi/2 (got " +
                                                                     std::to_string(d.inner) + ", " + std::to_string(d.outer) + ")");
            }
            defs_.push_back(d);
        }
    }

    // ---- node tree -----------------------------------------------------------------------------
    Mat4 local_matrix(const json& n, const std::string& np) const {
        Mat4 m;
        const bool trs = n.contains("translation") || n.contains("rotation") || n.contains("scale");
        if (n.contains("matrix")) {
            if (trs) fail(ErrorCode::kInvalidValue, np, "has both matrix and translation/rotation/scale");
            const auto v = numbers(n["matrix"], np + ".matrix", 16);
            for (size_t i = 0; i < 16; ++i) m.m[i] = v[i];
            return m;
        }
        Vec3 t{0, 0, 0}, s{1, 1, 1};
        double q[4] = {0, 0, 0, 1};
        if (n.contains("translation")) {
            const auto v = numbers(n["translation"], np + ".translation", 3);
            t = {v[0], v[1], v[2]};
        }
        if (n.contains("scale")) {
            const auto v = numbers(n["scale"], np + ".scale", 3);
            s = {v[0], v[1], v[2]};
        }
        if (n.contains("rotation")) {
            const auto v = numbers(n["rotation"], np + ".rotation", 4);
            const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
            if (!(len > 0)) fail(ErrorCode::kInvalidValue, np + ".rotation", "must be a unit quaternion (got zero)");
            for (int i = 0; i < 4; ++i) q[i] = v[static_cast<size_t>(i)] / len;  // glTF requires unit; normalise rounding
        }
        // M = T * R * S (glTF 2.0 spec, 5.25 node), R from the unit quaternion (x, y, z, w).
        const double x = q[0], y = q[1], z = q[2], w = q[3];
        const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                                {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                                {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
        for (int row = 0; row < 3; ++row) {
            for (int c = 0; c < 3; ++c) m.m[static_cast<size_t>(c * 4 + row)] = r[row][c] * s[c];
            m.m[static_cast<size_t>(12 + row)] = t[row];
        }
        return m;
    }

    void walk() {
        const json& nodes = array_of(doc_, "nodes");
        const json& scenes = array_of(doc_, "scenes");
        if (scenes.empty()) fail(ErrorCode::kInvalidValue, "scenes", "the asset has no scene to bake");
        size_t scene = 0;
        if (doc_.contains("scene")) scene = index(doc_["scene"], "scene", scenes.size(), "scenes");
        const std::string sp = at("scenes", scene);
        const json& sc = scenes[scene];
        if (!sc.is_object()) fail(ErrorCode::kInvalidValue, sp, "must be an object");
        std::vector<char> seen(nodes.size(), 0);
        std::vector<std::pair<size_t, Mat4>> stack;
        if (sc.contains("nodes")) {
            if (!sc["nodes"].is_array()) fail(ErrorCode::kInvalidValue, sp + ".nodes", "must be an array");
            for (size_t i = 0; i < sc["nodes"].size(); ++i)
                stack.push_back({index(sc["nodes"][i], at(sp + ".nodes", i), nodes.size(), "nodes"), Mat4{}});
        }
        std::reverse(stack.begin(), stack.end());  // visit in document order
        while (!stack.empty()) {
            const auto [ni, parent] = stack.back();
            stack.pop_back();
            const std::string np = at("nodes", ni);
            // glTF node hierarchies are strict trees: a second visit is a cycle or a shared child.
            if (seen[ni]) fail(ErrorCode::kInvalidValue, np, "reached twice (a node has one parent; cycles are not allowed)");
            seen[ni] = 1;
            const json& n = nodes[ni];
            if (!n.is_object()) fail(ErrorCode::kInvalidValue, np, "must be an object");
            const Mat4 world = mul(parent, local_matrix(n, np));
            for (double v : world.m)
                if (!std::isfinite(v)) fail(ErrorCode::kInvalidValue, np, "world transform is not finite");
            if (n.contains("mesh")) add_mesh(index(n["mesh"], np + ".mesh", array_of(doc_, "meshes").size(), "meshes"), world);
            if (n.contains("extensions") && n["extensions"].is_object() && n["extensions"].contains("KHR_lights_punctual")) {
                const json& e = n["extensions"]["KHR_lights_punctual"];
                const std::string ep = np + ".extensions.KHR_lights_punctual.light";
                if (!e.is_object() || !e.contains("light")) fail(ErrorCode::kInvalidValue, ep, "missing");
                add_light(index(e["light"], ep, defs_.size(), "KHR_lights_punctual.lights"), world, ep);
            }
            if (n.contains("children")) {
                const json& ch = n["children"];
                if (!ch.is_array()) fail(ErrorCode::kInvalidValue, np + ".children", "must be an array");
                for (size_t i = ch.size(); i-- > 0;) stack.push_back({index(ch[i], at(np + ".children", i), nodes.size(), "nodes"), world});
            }
        }
    }

    void add_light(size_t li, const Mat4& world, const std::string& where) {
        if (lights_.size() + 1 > options_.limits.max_lights)
            fail(ErrorCode::kTooLarge, where, "light instances exceed the limit of " + std::to_string(options_.limits.max_lights));
        const LightDef& d = defs_[li];
        SceneLight l;
        l.kind = d.kind;
        l.name = d.name;
        l.position = from_gltf(point(world, {0, 0, 0}));
        // Lights shine down the node's local -Z.
        const Vec3 down = vector(world, {0, 0, -1});
        if (!(length(down) > 0)) fail(ErrorCode::kInvalidValue, where, "the light's node transform has a zero -Z axis (scale 0)");
        const Vec3 dir = from_gltf((1.0 / length(down)) * down);
        double scale = d.intensity;  // candela -> zhc intensity, 1 : 1
        if (d.kind == LightKind::kDirectional) {
            l.direction = -1.0 * dir;  // zhc: towards the light
            scale = d.intensity / kPi;  // lux -> zhc normalised irradiance E = E_lux / pi
        } else if (d.kind == LightKind::kSpot) {
            l.direction = dir;  // zhc: where the spot points
            l.inner_angle_rad = d.inner;
            l.outer_angle_rad = d.outer;
        }
        for (int k = 0; k < 3; ++k) {
            const double v = d.color[k] * scale;
            if (!(v <= std::numeric_limits<float>::max())) fail(ErrorCode::kInvalidValue, where, "colour x intensity does not fit a 32-bit float");
            l.color[k] = static_cast<float>(v);
        }
        lights_.push_back(l);
    }

    // ---- meshes -------------------------------------------------------------------------------
    struct View {
        const std::uint8_t* data = nullptr;
        std::uint64_t length = 0, stride = 0;
    };
    // The bytes of accessor `ai` (after its byteOffset) and the stride, bound-checked for `count`
    // elements of `elem` bytes.
    View accessor_view(size_t ai, std::uint64_t count, std::uint64_t elem, const std::string& ap) const {
        const json& acc = array_of(doc_, "accessors")[ai];
        if (!acc.contains("bufferView")) fail(ErrorCode::kUnsupported, ap, "accessor without a bufferView (all zeros) is not read");
        const json& views = array_of(doc_, "bufferViews");
        const size_t vi = index(acc["bufferView"], ap + ".bufferView", views.size(), "bufferViews");
        const std::string vp = at("bufferViews", vi);
        const json& v = views[vi];
        if (!v.is_object()) fail(ErrorCode::kInvalidValue, vp, "must be an object");
        const size_t bi = index(v.contains("buffer") ? v["buffer"] : json(), vp + ".buffer", raw_.buffers.size(), "buffers");
        const std::uint64_t v_off = count_field(v, "byteOffset", vp, 0), v_len = count_field(v, "byteLength", vp, ~0ull);
        const std::uint64_t stride = v.contains("byteStride") ? count_field(v, "byteStride", vp, 0) : elem;
        if (stride < elem || stride > 252) fail(ErrorCode::kInvalidValue, vp + ".byteStride", "must be in [" + std::to_string(elem) + ", 252]");
        const std::uint64_t a_off = count_field(acc, "byteOffset", ap, 0);
        const auto& buf = raw_.buffers[bi];
        if (v_off > buf.size() || v_len > buf.size() - v_off)
            fail(ErrorCode::kInvalidValue, vp, "byte range [" + std::to_string(v_off) + ", +" + std::to_string(v_len) + ") outside buffer " + std::to_string(bi) + " (" + std::to_string(buf.size()) + " bytes)");
        // count >= 1 here; the last element ends at a_off + stride (count - 1) + elem.
        if (a_off > v_len || (count - 1) > (v_len - a_off) / stride || (count - 1) * stride + elem > v_len - a_off)
            fail(ErrorCode::kInvalidValue, ap, std::to_string(count) + " elements run past the end of " + vp);
        return {buf.data() + v_off + a_off, v_len - a_off, stride};
    }
    std::uint64_t count_field(const json& obj, const char* key, const std::string& where, std::uint64_t fallback) const {
        if (!obj.contains(key)) {
            if (fallback == ~0ull) fail(ErrorCode::kInvalidValue, where + "." + key, "missing required field");
            return fallback;
        }
        return count(obj, key, where, true, 0);
    }
    const json& accessor(size_t ai, const std::string& ap) const {
        const json& acc = array_of(doc_, "accessors")[ai];
        if (!acc.is_object()) fail(ErrorCode::kInvalidValue, ap, "must be an object");
        if (acc.contains("sparse")) fail(ErrorCode::kUnsupported, ap, "sparse accessors are not read as occluders");
        return acc;
    }

    void add_mesh(size_t mi, const Mat4& world) {
        const std::string mp = at("meshes", mi);
        const json& mesh = array_of(doc_, "meshes")[mi];
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array())
            fail(ErrorCode::kInvalidValue, mp + ".primitives", "missing or not an array");
        const json& prims = mesh["primitives"];
        const size_t n_acc = array_of(doc_, "accessors").size();
        for (size_t pi = 0; pi < prims.size(); ++pi) {
            const std::string pp = at(mp + ".primitives", pi);
            const json& prim = prims[pi];
            if (!prim.is_object()) fail(ErrorCode::kInvalidValue, pp, "must be an object");
            const std::uint64_t mode = count(prim, "mode", pp, false, 4);
            if (mode <= 3) continue;  // POINTS, LINES, LINE_LOOP, LINE_STRIP: no area, block nothing
            if (mode == 5 || mode == 6) fail(ErrorCode::kUnsupported, pp + ".mode", "TRIANGLE_STRIP/TRIANGLE_FAN primitives are not read (only TRIANGLES)");
            if (mode != 4) fail(ErrorCode::kInvalidValue, pp + ".mode", "unknown primitive mode " + std::to_string(mode));
            if (prim.contains("extensions") && prim["extensions"].is_object() && prim["extensions"].contains("KHR_draco_mesh_compression"))
                fail(ErrorCode::kUnsupported, pp, "Draco-compressed primitives are not read as occluders");
            if (!prim.contains("attributes") || !prim["attributes"].is_object() || !prim["attributes"].contains("POSITION"))
                fail(ErrorCode::kInvalidValue, pp + ".attributes.POSITION", "missing");
            const size_t pa = index(prim["attributes"]["POSITION"], pp + ".attributes.POSITION", n_acc, "accessors");
            const std::string pap = at("accessors", pa);
            const json& pacc = accessor(pa, pap);
            if (count(pacc, "componentType", pap, true, 0) != kFloat || !pacc.contains("type") || pacc["type"] != "VEC3")
                fail(ErrorCode::kUnsupported, pap, "POSITION must be a VEC3 FLOAT accessor (quantised positions are not read)");
            const std::uint64_t nv = count(pacc, "count", pap, true, 0);
            if (nv == 0) continue;
            // Triangles of this primitive, checked against the limit before anything is decoded.
            std::uint64_t ni = nv;
            size_t ia = 0;
            const bool indexed = prim.contains("indices");
            if (indexed) {
                ia = index(prim["indices"], pp + ".indices", n_acc, "accessors");
                ni = count(accessor(ia, at("accessors", ia)), "count", at("accessors", ia), true, 0);
            }
            if (ni % 3 != 0)
                fail(ErrorCode::kInvalidValue, indexed ? at("accessors", ia) : pap,
                     "TRIANGLES need a multiple of 3 " + std::string(indexed ? "indices" : "vertices") + " (got " + std::to_string(ni) + ")");
            triangles_ += ni / 3;
            if (triangles_ > options_.limits.max_triangles)
                fail(ErrorCode::kTooLarge, pp, "mesh triangles (with instances) exceed the limit of " + std::to_string(options_.limits.max_triangles));
            if (ni == 0) continue;
            const View pv = accessor_view(pa, nv, 12, pap);
            std::vector<Vec3> verts(nv);
            for (std::uint64_t i = 0; i < nv; ++i) {
                const std::uint8_t* e = pv.data + i * pv.stride;
                float f[3];
                for (int k = 0; k < 3; ++k) {
                    const std::uint32_t bits = le32(e + 4 * k);
                    std::memcpy(&f[k], &bits, 4);
                }
                if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2]))
                    fail(ErrorCode::kInvalidValue, pap, "vertex " + std::to_string(i) + " is not finite");
                verts[i] = from_gltf(point(world, {f[0], f[1], f[2]}));
                if (!finite3(verts[i])) fail(ErrorCode::kInvalidValue, pap, "transformed vertex " + std::to_string(i) + " is not finite");
                for (int a = 0; a < 3; ++a) {
                    lo_[a] = std::min(lo_[a], verts[i][a]);
                    hi_[a] = std::max(hi_[a], verts[i][a]);
                }
            }
            std::vector<std::uint32_t> idx(ni);
            if (indexed) {
                const std::string iap = at("accessors", ia);
                const json& iacc = array_of(doc_, "accessors")[ia];
                if (!iacc.contains("type") || iacc["type"] != "SCALAR") fail(ErrorCode::kInvalidValue, iap, "indices must be a SCALAR accessor");
                const std::uint64_t ct = count(iacc, "componentType", iap, true, 0);
                const std::uint64_t size = ct == kUbyte ? 1 : ct == kUshort ? 2 : ct == kUint ? 4 : 0;
                if (size == 0) fail(ErrorCode::kInvalidValue, iap + ".componentType", "indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
                const View iv = accessor_view(ia, ni, size, iap);
                for (std::uint64_t i = 0; i < ni; ++i) {
                    const std::uint8_t* e = iv.data + i * iv.stride;
                    const std::uint32_t v = size == 1 ? e[0] : size == 2 ? std::uint32_t(e[0] | e[1] << 8) : le32(e);
                    if (v >= nv) fail(ErrorCode::kInvalidValue, iap, "index " + std::to_string(i) + " = " + std::to_string(v) + " is not below the vertex count " + std::to_string(nv));
                    idx[i] = v;
                }
            } else {
                for (std::uint64_t i = 0; i < ni; ++i) idx[i] = static_cast<std::uint32_t>(i);
            }
            for (std::uint64_t t = 0; t < ni; t += 3) occluders_.push_back(triangle_occluder(verts[idx[t]], verts[idx[t + 1]], verts[idx[t + 2]]));
        }
    }

    std::vector<SceneLight> lights_;
    std::vector<Occluder> occluders_;
    double lo_[3] = {INFINITY, INFINITY, INFINITY}, hi_[3] = {-INFINITY, -INFINITY, -INFINITY};

private:
    std::string path_;
    const json& doc_;
    const GltfRaw& raw_;
    const SceneLoadOptions& options_;
    std::vector<LightDef> defs_;
    std::uint64_t triangles_ = 0;
};

// Default probes: an 8 x 8 x 8 grid of cell centres over the bounds of the meshes and the
// point/spot light positions (an axis of zero extent gets one probe in its middle); with neither,
// one probe at the origin.
json default_probes(const Reader& r) {
    double lo[3], hi[3];
    bool any = !r.occluders_.empty();
    for (int a = 0; a < 3; ++a) {
        lo[a] = r.lo_[a];
        hi[a] = r.hi_[a];
    }
    for (const SceneLight& l : r.lights_)
        if (l.kind == LightKind::kPoint || l.kind == LightKind::kSpot) {
            any = true;
            for (int a = 0; a < 3; ++a) {
                lo[a] = std::min(lo[a], l.position[a]);
                hi[a] = std::max(hi[a], l.position[a]);
            }
        }
    if (!any) return {{"positions", json::array({json::array({0.0, 0.0, 0.0})})}};
    json mn = json::array(), mx = json::array(), counts = json::array();
    constexpr int kCells = 8;
    for (int a = 0; a < 3; ++a) {
        const double ext = hi[a] - lo[a];
        if (ext > 0) {
            mn.push_back(lo[a] + ext / (2 * kCells));
            mx.push_back(hi[a] - ext / (2 * kCells));
            counts.push_back(kCells);
        } else {
            mn.push_back(lo[a]);
            mx.push_back(hi[a]);
            counts.push_back(1);
        }
    }
    return {{"grid", {{"min", mn}, {"max", mx}, {"counts", counts}}}};
}

}  // namespace

namespace {
Result<Scene> parse_unchecked(std::span<const std::uint8_t> bytes, const std::string& path, const SceneLoadOptions& options,
                              const GltfLimits& gltf_limits) {
    auto raw = load_gltf_raw(bytes, path, gltf_limits);
    if (!raw) return raw.error();
    try {
        const json doc = json::parse(raw->json);
        Reader r(path, doc, *raw, options);
        r.read_light_defs();
        r.walk();
        // extras.zhc: a zhc JSON scene (zhc axes) with optional version and probes.
        json extras = json::object();
        if (doc.contains("extras") && doc["extras"].is_object() && doc["extras"].contains("zhc")) extras = doc["extras"]["zhc"];
        if (!extras.is_object()) r.fail(ErrorCode::kInvalidValue, "extras.zhc", "must be an object (a zhc scene, docs/scene.md)");
        bool shadows = !r.occluders_.empty();
        if (extras.contains("gltf_light_shadows")) {
            if (!extras["gltf_light_shadows"].is_boolean()) r.fail(ErrorCode::kInvalidValue, "extras.zhc.gltf_light_shadows", "must be true or false");
            shadows = extras["gltf_light_shadows"].get<bool>();
            extras.erase("gltf_light_shadows");
        }
        if (!extras.contains("version")) extras["version"] = 1;
        if (!extras.contains("probes")) extras["probes"] = default_probes(r);
        const std::string text = extras.dump();
        std::string dir = fs::path(path).parent_path().string();
        auto scene = parse_scene_json(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()),
                                      path + ": extras.zhc", dir, options);
        if (!scene) return scene.error();
        Scene s = std::move(scene).value();
        if (s.lights.size() + r.lights_.size() > options.limits.max_lights)
            r.fail(ErrorCode::kTooLarge, "lights", "more than the limit of " + std::to_string(options.limits.max_lights) + " lights in all");
        for (SceneLight& l : r.lights_) {
            l.shadows = shadows;
            s.lights.push_back(std::move(l));
        }
        s.occluders.insert(s.occluders.end(), r.occluders_.begin(), r.occluders_.end());
        if (Status v = validate_scene(s); !v) return make_error(v.error().code, path + ": " + v.error().message);
        if (Status b = check_ray_budget(s, options.limits, path); !b) return b.error();
        return s;
    } catch (const Fail& f) {
        return f.error;
    } catch (const json::exception& e) {
        return make_error(ErrorCode::kInvalidValue, path + ": " + e.what());
    } catch (const std::bad_alloc&) {
        return make_error(ErrorCode::kTooLarge, path + ": out of memory while reading the scene");
    }
}

}  // namespace

Result<Scene> parse_scene_gltf(std::span<const std::uint8_t> bytes, const std::string& path, const SceneLoadOptions& options,
                               const GltfLimits& gltf_limits) {
    // Messages echo names and values from the asset (and tinygltf's text): keep them one line.
    auto s = parse_unchecked(bytes, path, options, gltf_limits);
    if (!s) return make_error(s.error().code, one_line_message(s.error().message));
    return s;
}

Result<Scene> read_scene_gltf_file(const std::string& path, const SceneLoadOptions& options, const GltfLimits& gltf_limits) {
    auto bytes = read_file_bytes(path, gltf_limits.max_file_bytes);
    if (!bytes) return bytes.error();
    return parse_scene_gltf(*bytes, path, options, gltf_limits);
}

bool is_gltf_path(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".gltf" || ext == ".glb";
}

}  // namespace zhc
