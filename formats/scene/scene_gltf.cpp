#include "formats/scene/scene_gltf.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <new>

#include "formats/io/file_io.h"
#include "formats/io/le_bytes.h"
#include "formats/probes/gltf_draco.h"
#include "formats/probes/gltf_meshopt.h"

namespace zhc {
namespace {
constexpr auto le32 = le::load32;

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


constexpr int kByte = 5120, kUbyte = 5121, kShort = 5122, kUshort = 5123, kUint = 5125, kFloat = 5126;

struct LightDef {
    LightKind kind = LightKind::kPoint;
    std::string name;
    Rgb color{1, 1, 1};
    double intensity = 1;
    double inner = 0, outer = kPi / 4;
};

class Reader {
public:
    Reader(std::string path, const json& doc, const GltfRaw& raw, const SceneLoadOptions& options, const GltfLimits& gltf_limits)
        : path_(std::move(path)), doc_(doc), raw_(raw), options_(options), gltf_limits_(gltf_limits) {}

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
        std::vector<char> seen(nodes.size(), 0);
        std::vector<std::pair<size_t, Mat4>> stack;
        if (scenes.empty() && !doc_.contains("scene")) {
            // No scene (legal: the asset is a library): every node that is no node's child is a
            // root, in index order.
            std::vector<char> child(nodes.size(), 0);
            for (size_t ni = 0; ni < nodes.size(); ++ni) {
                const json& n = nodes[ni];
                if (!n.is_object() || !n.contains("children")) continue;
                const std::string np = at("nodes", ni);
                if (!n["children"].is_array()) fail(ErrorCode::kInvalidValue, np + ".children", "must be an array");
                for (size_t i = 0; i < n["children"].size(); ++i) child[index(n["children"][i], at(np + ".children", i), nodes.size(), "nodes")] = 1;
            }
            for (size_t ni = 0; ni < nodes.size(); ++ni)
                if (!child[ni]) stack.push_back({ni, Mat4{}});
        } else {
            size_t scene = 0;
            if (doc_.contains("scene")) scene = index(doc_["scene"], "scene", scenes.size(), "scenes");
            const std::string sp = at("scenes", scene);
            const json& sc = scenes[scene];
            if (!sc.is_object()) fail(ErrorCode::kInvalidValue, sp, "must be an object");
            if (sc.contains("nodes")) {
                if (!sc["nodes"].is_array()) fail(ErrorCode::kInvalidValue, sp + ".nodes", "must be an array");
                for (size_t i = 0; i < sc["nodes"].size(); ++i)
                    stack.push_back({index(sc["nodes"][i], at(sp + ".nodes", i), nodes.size(), "nodes"), Mat4{}});
            }
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
    // The meshopt extension object of a bufferView (EXT_ or KHR_meshopt_compression), or null.
    const json* meshopt_ext(const json& v, std::string* name) const {
        if (!v.contains("extensions") || !v["extensions"].is_object()) return nullptr;
        for (const char* n : {"KHR_meshopt_compression", "EXT_meshopt_compression"})
            if (v["extensions"].contains(n)) {
                *name = n;
                return &v["extensions"][n];
            }
        return nullptr;
    }
    // A compressed view decoded: sizes checked against the limits and against what the compressed
    // bytes can hold (every codec spends at least 1 bit per 16 output bytes... in practice the
    // bound below: 128 output bytes per input byte plus a 4 KiB tail) before anything is allocated.
    std::vector<std::uint8_t> decode_meshopt(const json& e, std::uint64_t v_len, const std::string& ep) {
        if (!e.is_object()) fail(ErrorCode::kInvalidValue, ep, "must be an object");
        const size_t bi = index(e.contains("buffer") ? e["buffer"] : json(), ep + ".buffer", raw_.buffers.size(), "buffers");
        const std::uint64_t off = count_field(e, "byteOffset", ep, 0), len = count_field(e, "byteLength", ep, ~0ull);
        const std::uint64_t stride = count_field(e, "byteStride", ep, ~0ull), n = count_field(e, "count", ep, ~0ull);
        MeshoptView mv;
        mv.count = n;
        mv.stride = stride;
        if (!e.contains("mode") || !e["mode"].is_string()) fail(ErrorCode::kInvalidValue, ep + ".mode", "missing or not a string");
        const std::string mode = e["mode"].get<std::string>();
        if (mode == "ATTRIBUTES") mv.mode = MeshoptMode::kAttributes;
        else if (mode == "TRIANGLES") mv.mode = MeshoptMode::kTriangles;
        else if (mode == "INDICES") mv.mode = MeshoptMode::kIndices;
        else fail(ErrorCode::kUnsupported, ep + ".mode", "unknown meshopt mode \"" + mode + "\" (known: ATTRIBUTES, TRIANGLES, INDICES)");
        if (e.contains("filter")) {
            if (!e["filter"].is_string()) fail(ErrorCode::kInvalidValue, ep + ".filter", "must be a string");
            const std::string f = e["filter"].get<std::string>();
            if (f == "NONE") mv.filter = MeshoptFilter::kNone;
            else if (f == "OCTAHEDRAL") mv.filter = MeshoptFilter::kOctahedral;
            else if (f == "QUATERNION") mv.filter = MeshoptFilter::kQuaternion;
            else if (f == "EXPONENTIAL") mv.filter = MeshoptFilter::kExponential;
            else fail(ErrorCode::kUnsupported, ep + ".filter", "unknown meshopt filter \"" + f + "\" (known: NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL)");
        }
        if (const std::string why = meshopt_view_problem(mv); !why.empty()) fail(ErrorCode::kInvalidValue, ep, why);
        if (n > gltf_limits_.max_buffer_bytes / stride)
            fail(ErrorCode::kTooLarge, ep, "decoded size above the buffer limit of " + std::to_string(gltf_limits_.max_buffer_bytes) + " bytes");
        const std::uint64_t size = n * stride;
        if (size != v_len)
            fail(ErrorCode::kInvalidValue, ep, "count x byteStride = " + std::to_string(size) + " differs from the bufferView's byteLength " + std::to_string(v_len));
        const auto& buf = raw_.buffers[bi];
        if (off > buf.size() || len > buf.size() - off)
            fail(ErrorCode::kInvalidValue, ep, "byte range [" + std::to_string(off) + ", +" + std::to_string(len) + ") outside buffer " + std::to_string(bi) + " (" + std::to_string(buf.size()) + " bytes)");
        if (size > len * 128 + 4096)
            fail(ErrorCode::kInvalidValue, ep, std::to_string(len) + " compressed bytes cannot hold the " + std::to_string(size) + " bytes declared");
        decoded_total_ += size;
        if (decoded_total_ > gltf_limits_.max_total_bytes)
            fail(ErrorCode::kTooLarge, ep, "decoded buffer views exceed the limit of " + std::to_string(gltf_limits_.max_total_bytes) + " bytes");
        auto r = decode_meshopt_view(std::span<const std::uint8_t>(buf.data() + off, static_cast<size_t>(len)), mv, ep);
        if (!r) throw Fail{make_error(r.error().code, path_ + ": " + r.error().message)};
        return std::move(r).value();
    }
    // The bytes of bufferView `vi`: a range of its buffer, or the decoded bytes of a compressed view.
    std::span<const std::uint8_t> view_bytes(size_t vi, const std::string& vp) {
        const json& v = array_of(doc_, "bufferViews")[vi];
        if (!v.is_object()) fail(ErrorCode::kInvalidValue, vp, "must be an object");
        const std::uint64_t v_len = count_field(v, "byteLength", vp, ~0ull);
        std::string ext;
        if (const json* mo = meshopt_ext(v, &ext)) {
            auto it = decoded_.find(vi);
            if (it == decoded_.end()) it = decoded_.emplace(vi, decode_meshopt(*mo, v_len, vp + ".extensions." + ext)).first;
            return it->second;
        }
        const size_t bi = index(v.contains("buffer") ? v["buffer"] : json(), vp + ".buffer", raw_.buffers.size(), "buffers");
        const std::uint64_t v_off = count_field(v, "byteOffset", vp, 0);
        const auto& buf = raw_.buffers[bi];
        if (v_off > buf.size() || v_len > buf.size() - v_off)
            fail(ErrorCode::kInvalidValue, vp, "byte range [" + std::to_string(v_off) + ", +" + std::to_string(v_len) + ") outside buffer " + std::to_string(bi) + " (" + std::to_string(buf.size()) + " bytes)");
        return {buf.data() + v_off, static_cast<size_t>(v_len)};
    }

    struct View {
        const std::uint8_t* data = nullptr;
        std::uint64_t length = 0, stride = 0;
    };
    // The bytes of accessor `ai` (after its byteOffset) and the stride, bound-checked for `count`
    // elements of `elem` bytes.
    View accessor_view(size_t ai, std::uint64_t count, std::uint64_t elem, const std::string& ap) {
        const json& acc = array_of(doc_, "accessors")[ai];
        if (!acc.contains("bufferView")) fail(ErrorCode::kUnsupported, ap, "accessor without a bufferView (all zeros) is not read");
        const json& views = array_of(doc_, "bufferViews");
        const size_t vi = index(acc["bufferView"], ap + ".bufferView", views.size(), "bufferViews");
        const std::string vp = at("bufferViews", vi);
        const std::span<const std::uint8_t> bytes = view_bytes(vi, vp);
        const json& v = views[vi];
        const std::uint64_t v_len = bytes.size();
        const std::uint64_t stride = v.contains("byteStride") ? count_field(v, "byteStride", vp, 0) : elem;
        if (stride < elem || stride > 252) fail(ErrorCode::kInvalidValue, vp + ".byteStride", "must be in [" + std::to_string(elem) + ", 252]");
        const std::uint64_t a_off = count_field(acc, "byteOffset", ap, 0);
        // count >= 1 here; the last element ends at a_off + stride (count - 1) + elem.
        if (a_off > v_len || (count - 1) > (v_len - a_off) / stride || (count - 1) * stride + elem > v_len - a_off)
            fail(ErrorCode::kInvalidValue, ap, std::to_string(count) + " elements run past the end of " + vp);
        return {bytes.data() + a_off, v_len - a_off, stride};
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

    // POSITION values: FLOAT, or (KHR_mesh_quantization) BYTE/UNSIGNED_BYTE/SHORT/UNSIGNED_SHORT,
    // normalized or not (glTF 2.0 spec 3.11: signed c / (2^(n-1) - 1) clamped at -1, unsigned
    // c / (2^n - 1)); transformed by `world` into zhc axes and bound-checked for finiteness.
    std::vector<Vec3> read_positions(size_t pa, std::uint64_t nv, const Mat4& world) {
        const std::string pap = at("accessors", pa);
        const json& pacc = accessor(pa, pap);
        if (!pacc.contains("type") || pacc["type"] != "VEC3") fail(ErrorCode::kInvalidValue, pap, "POSITION must be a VEC3 accessor");
        const std::uint64_t ct = count(pacc, "componentType", pap, true, 0);
        const bool normalized = pacc.contains("normalized") && pacc["normalized"].is_boolean() && pacc["normalized"].get<bool>();
        const std::uint64_t csize = ct == kFloat ? 4 : ct == kByte || ct == kUbyte ? 1 : ct == kShort || ct == kUshort ? 2 : 0;
        if (csize == 0) fail(ErrorCode::kUnsupported, pap + ".componentType", "POSITION must be FLOAT, BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT (got " + std::to_string(ct) + ")");
        if (ct == kFloat && normalized) fail(ErrorCode::kInvalidValue, pap + ".normalized", "a FLOAT accessor cannot be normalized");
        const View pv = accessor_view(pa, nv, 3 * csize, pap);
        std::vector<Vec3> verts(nv);
        for (std::uint64_t i = 0; i < nv; ++i) {
            const std::uint8_t* e = pv.data + i * pv.stride;
            double f[3];
            for (int k = 0; k < 3; ++k) {
                const std::uint8_t* c = e + csize * static_cast<std::uint64_t>(k);
                switch (ct) {
                    case kFloat: {
                        const std::uint32_t bits = le32(c);
                        float x;
                        std::memcpy(&x, &bits, 4);
                        f[k] = x;
                        break;
                    }
                    case kByte: f[k] = normalized ? std::max(static_cast<std::int8_t>(c[0]) / 127.0, -1.0) : static_cast<std::int8_t>(c[0]); break;
                    case kUbyte: f[k] = normalized ? c[0] / 255.0 : c[0]; break;
                    case kShort: {
                        const auto v = static_cast<std::int16_t>(static_cast<std::uint16_t>(c[0] | c[1] << 8));
                        f[k] = normalized ? std::max(v / 32767.0, -1.0) : v;
                        break;
                    }
                    default: {
                        const std::uint16_t v = static_cast<std::uint16_t>(c[0] | c[1] << 8);
                        f[k] = normalized ? v / 65535.0 : v;
                        break;
                    }
                }
            }
            if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2]))
                fail(ErrorCode::kInvalidValue, pap, "vertex " + std::to_string(i) + " is not finite");
            verts[i] = transformed(world, {f[0], f[1], f[2]}, pap, i);
        }
        return verts;
    }
    Vec3 transformed(const Mat4& world, Vec3 p, const std::string& where, std::uint64_t i) {
        const Vec3 v = from_gltf(point(world, p));
        if (!finite3(v)) fail(ErrorCode::kInvalidValue, where, "transformed vertex " + std::to_string(i) + " is not finite");
        for (int a = 0; a < 3; ++a) {
            lo_[a] = std::min(lo_[a], v[a]);
            hi_[a] = std::max(hi_[a], v[a]);
        }
        return v;
    }

    // Triangles of a TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN element list (glTF 2.0 spec
    // 3.7.2.1): strip triangle i is (v_i, v_{i+1}, v_{i+2}) for even i and (v_{i+1}, v_i, v_{i+2})
    // for odd i (winding kept), fan triangle i is (v_{i+1}, v_{i+2}, v_0). Triangles that repeat an
    // index (the joins between strips) are dropped: they have no area.
    void add_triangles(const std::vector<Vec3>& verts, const std::vector<std::uint32_t>& idx, std::uint64_t mode) {
        auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
            if (mode != 4 && (a == b || b == c || a == c)) return;
            occluders_.push_back(triangle_occluder(verts[a], verts[b], verts[c]));
        };
        const size_t n = idx.size();
        if (mode == 4) {
            for (size_t t = 0; t + 2 < n; t += 3) add(idx[t], idx[t + 1], idx[t + 2]);
        } else if (mode == 5) {
            for (size_t i = 0; i + 2 < n; ++i) {
                if (i % 2 == 0) add(idx[i], idx[i + 1], idx[i + 2]);
                else add(idx[i + 1], idx[i], idx[i + 2]);
            }
        } else {
            for (size_t i = 0; i + 2 < n; ++i) add(idx[i + 1], idx[i + 2], idx[0]);
        }
    }
    // Triangles a primitive of `mode` with n elements yields (an upper bound for strips/fans).
    static std::uint64_t triangle_count(std::uint64_t mode, std::uint64_t n) { return mode == 4 ? n / 3 : n >= 3 ? n - 2 : 0; }
    void count_triangles(std::uint64_t t, const std::string& pp) {
        triangles_ += t;
        if (triangles_ > options_.limits.max_triangles)
            fail(ErrorCode::kTooLarge, pp, "mesh triangles (with instances) exceed the limit of " + std::to_string(options_.limits.max_triangles));
    }

    // KHR_draco_mesh_compression: the primitive's geometry from its Draco stream.
    void add_draco(const json& prim, const json& ext, const std::string& pp, std::uint64_t mode, const Mat4& world) {
        const std::string ep = pp + ".extensions.KHR_draco_mesh_compression";
        if (!ext.is_object()) fail(ErrorCode::kInvalidValue, ep, "must be an object");
        if (mode != 4) fail(ErrorCode::kUnsupported, pp + ".mode", "Draco-compressed primitives are read as TRIANGLES only");
        const size_t n_acc = array_of(doc_, "accessors").size();
        const size_t pa = index(prim["attributes"]["POSITION"], pp + ".attributes.POSITION", n_acc, "accessors");
        const std::uint64_t nv = count(accessor(pa, at("accessors", pa)), "count", at("accessors", pa), true, 0);
        std::uint64_t ni = nv;
        if (prim.contains("indices")) {
            const size_t ia = index(prim["indices"], pp + ".indices", n_acc, "accessors");
            ni = count(accessor(ia, at("accessors", ia)), "count", at("accessors", ia), true, 0);
        }
        if (ni % 3 != 0) fail(ErrorCode::kInvalidValue, pp, "TRIANGLES need a multiple of 3 indices (got " + std::to_string(ni) + ")");
        count_triangles(ni / 3, pp);
        if (nv > options_.limits.max_triangles * 3) fail(ErrorCode::kTooLarge, pp, std::to_string(nv) + " Draco points exceed 3 x the triangle limit");
        if (!ext.contains("attributes") || !ext["attributes"].is_object() || !ext["attributes"].contains("POSITION") ||
            !ext["attributes"]["POSITION"].is_number_integer())
            fail(ErrorCode::kInvalidValue, ep + ".attributes.POSITION", "missing or not an integer");
        const std::int64_t pid = ext["attributes"]["POSITION"].get<std::int64_t>();
        if (pid < 0 || pid > std::numeric_limits<int>::max()) fail(ErrorCode::kInvalidValue, ep + ".attributes.POSITION", "not a Draco attribute id");
        const json& views = array_of(doc_, "bufferViews");
        const size_t vi = index(ext.contains("bufferView") ? ext["bufferView"] : json(), ep + ".bufferView", views.size(), "bufferViews");
        const std::span<const std::uint8_t> bytes = view_bytes(vi, at("bufferViews", vi));
        auto mesh = decode_draco_mesh(bytes, static_cast<int>(pid), nv, ni / 3, ep);
        if (!mesh) throw Fail{make_error(mesh.error().code, path_ + ": " + mesh.error().message)};
        std::vector<Vec3> verts(mesh->positions.size());
        for (size_t i = 0; i < verts.size(); ++i) {
            const auto& q = mesh->positions[i];
            if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
                fail(ErrorCode::kInvalidValue, ep, "Draco vertex " + std::to_string(i) + " is not finite");
            verts[i] = transformed(world, {q[0], q[1], q[2]}, ep, i);
        }
        std::vector<std::uint32_t> idx;
        idx.reserve(mesh->faces.size() * 3);
        for (const auto& f : mesh->faces) idx.insert(idx.end(), f.begin(), f.end());
        add_triangles(verts, idx, 4);
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
            if (mode > 6) fail(ErrorCode::kInvalidValue, pp + ".mode", "unknown primitive mode " + std::to_string(mode));
            if (!prim.contains("attributes") || !prim["attributes"].is_object() || !prim["attributes"].contains("POSITION"))
                fail(ErrorCode::kInvalidValue, pp + ".attributes.POSITION", "missing");
            if (prim.contains("extensions") && prim["extensions"].is_object() && prim["extensions"].contains("KHR_draco_mesh_compression")) {
                add_draco(prim, prim["extensions"]["KHR_draco_mesh_compression"], pp, mode, world);
                continue;
            }
            const size_t pa = index(prim["attributes"]["POSITION"], pp + ".attributes.POSITION", n_acc, "accessors");
            const std::string pap = at("accessors", pa);
            const std::uint64_t nv = count(accessor(pa, pap), "count", pap, true, 0);
            if (nv == 0) continue;
            // Triangles of this primitive, checked against the limit before anything is decoded.
            std::uint64_t ni = nv;
            size_t ia = 0;
            const bool indexed = prim.contains("indices");
            if (indexed) {
                ia = index(prim["indices"], pp + ".indices", n_acc, "accessors");
                ni = count(accessor(ia, at("accessors", ia)), "count", at("accessors", ia), true, 0);
            }
            if (mode == 4 && ni % 3 != 0)
                fail(ErrorCode::kInvalidValue, indexed ? at("accessors", ia) : pap,
                     "TRIANGLES need a multiple of 3 " + std::string(indexed ? "indices" : "vertices") + " (got " + std::to_string(ni) + ")");
            count_triangles(triangle_count(mode, ni), pp);
            if (triangle_count(mode, ni) == 0) continue;
            if (nv > options_.limits.max_triangles * 3) fail(ErrorCode::kTooLarge, pap, std::to_string(nv) + " vertices exceed 3 x the triangle limit");
            const std::vector<Vec3> verts = read_positions(pa, nv, world);
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
            add_triangles(verts, idx, mode);
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
    const GltfLimits& gltf_limits_;
    std::vector<LightDef> defs_;
    std::uint64_t triangles_ = 0;
    std::map<size_t, std::vector<std::uint8_t>> decoded_;  // meshopt-compressed views, decoded once
    std::uint64_t decoded_total_ = 0;
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
        Reader r(path, doc, *raw, options, gltf_limits);
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

bool is_gltf_path(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".gltf" || ext == ".glb";
}

}  // namespace zhc
