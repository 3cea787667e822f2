#include "formats/scene/scene_json.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <filesystem>
#include <initializer_list>
#include <new>

#include "formats/envmap/envmap.h"
#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"

namespace zhc {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

constexpr double kDeg = kPi / 180.0;

// A failed check: carries the error out of the nested field readers (caught in parse_scene_json,
// never crosses the API).
struct Fail {
    Error error;
};

class Reader {
public:
    explicit Reader(std::string name) : name_(std::move(name)) {}

    [[noreturn]] void fail(ErrorCode code, const std::string& path, const std::string& what) const {
        throw Fail{make_error(code, name_ + ": " + (path.empty() ? "" : path + ": ") + what)};
    }
    static std::string type_of(const json& j) { return j.type_name(); }

    const json& object(const json& j, const std::string& path, std::initializer_list<const char*> allowed) const {
        if (!j.is_object()) fail(ErrorCode::kInvalidValue, path, "must be an object (got " + type_of(j) + ")");
        for (auto it = j.begin(); it != j.end(); ++it) {
            bool ok = false;
            for (const char* a : allowed) ok = ok || it.key() == a;
            if (!ok) {
                std::string list;
                for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
                fail(ErrorCode::kInvalidValue, join(path, it.key()), "unknown field (allowed here: " + list + ")");
            }
        }
        return j;
    }
    static std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
    static std::string index(const std::string& path, size_t i) { return path + "[" + std::to_string(i) + "]"; }

    const json& field(const json& obj, const std::string& path, const char* key) const {
        if (!obj.contains(key)) fail(ErrorCode::kInvalidValue, join(path, key), "missing required field");
        return obj.at(key);
    }
    double number(const json& j, const std::string& path) const {
        if (!j.is_number()) fail(ErrorCode::kInvalidValue, path, "must be a number (got " + type_of(j) + ")");
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(ErrorCode::kInvalidValue, path, "must be finite");
        return v;
    }
    double number_or(const json& obj, const std::string& path, const char* key, double fallback) const {
        return obj.contains(key) ? number(obj.at(key), join(path, key)) : fallback;
    }
    double non_negative(const json& j, const std::string& path) const {
        const double v = number(j, path);
        if (v < 0) fail(ErrorCode::kInvalidValue, path, "must be >= 0 (got " + fmt(v) + ")");
        return v;
    }
    double positive(const json& j, const std::string& path) const {
        const double v = number(j, path);
        if (!(v > 0)) fail(ErrorCode::kInvalidValue, path, "must be > 0 (got " + fmt(v) + ")");
        return v;
    }
    Vec3 vec3(const json& j, const std::string& path) const {
        if (!j.is_array() || j.size() != 3)
            fail(ErrorCode::kInvalidValue, path, "must be an array of 3 numbers (got " + type_of(j) + ")");
        return {number(j[0], index(path, 0)), number(j[1], index(path, 1)), number(j[2], index(path, 2))};
    }
    Vec3 direction(const json& j, const std::string& path) const {
        const Vec3 v = vec3(j, path);
        if (!(length(v) > 0)) fail(ErrorCode::kInvalidValue, path, "must be a non-zero vector");
        return v;
    }
    // One colour channel: finite, >= 0 and representable as a 32-bit float (colours are stored as
    // floats; a larger value would become Inf and could not be written back).
    float channel(const json& j, const std::string& path) const {
        const double v = non_negative(j, path);
        if (v > std::numeric_limits<float>::max())
            fail(ErrorCode::kInvalidValue, path, "must fit in a 32-bit float (got " + fmt(v) + ")");
        return static_cast<float>(v);
    }
    // A colour: [r, g, b] or one number for grey; every channel finite and >= 0.
    Rgb colour(const json& j, const std::string& path) const {
        if (j.is_number()) {
            const float v = channel(j, path);
            return {v, v, v};
        }
        if (!j.is_array() || j.size() != 3)
            fail(ErrorCode::kInvalidValue, path, "must be [r, g, b] or one number (got " + type_of(j) + ")");
        Rgb c;
        for (int k = 0; k < 3; ++k) c[k] = channel(j[static_cast<size_t>(k)], index(path, size_t(k)));
        return c;
    }
    bool boolean(const json& j, const std::string& path) const {
        if (!j.is_boolean()) fail(ErrorCode::kInvalidValue, path, "must be true or false (got " + type_of(j) + ")");
        return j.get<bool>();
    }
    std::string string(const json& j, const std::string& path) const {
        if (!j.is_string()) fail(ErrorCode::kInvalidValue, path, "must be a string (got " + type_of(j) + ")");
        return j.get<std::string>();
    }
    const json& array(const json& j, const std::string& path, std::uint64_t max, const char* what) const {
        if (!j.is_array()) fail(ErrorCode::kInvalidValue, path, "must be an array (got " + type_of(j) + ")");
        if (j.size() > max)
            fail(ErrorCode::kTooLarge, path, std::to_string(j.size()) + " " + what + " exceed the limit of " + std::to_string(max));
        return j;
    }
    static std::string fmt(double v) {
        char b[64];
        std::snprintf(b, sizeof b, "%g", v);
        return b;
    }

private:
    std::string name_;
};

ProbePlacement read_probes(const Reader& r, const json& j, const SceneJsonLimits& limits) {
    const std::string path = "probes";
    r.object(j, path, {"grid", "positions"});
    if (j.contains("grid") == j.contains("positions"))
        r.fail(ErrorCode::kInvalidValue, path, "needs exactly one of \"grid\" or \"positions\"");
    ProbePlacement pl;
    if (j.contains("grid")) {
        const std::string gp = "probes.grid";
        const json& g = r.object(j["grid"], gp, {"min", "max", "counts"});
        pl.kind = ProbePlacementKind::kGrid;
        pl.min = r.vec3(r.field(g, gp, "min"), gp + ".min");
        pl.max = r.vec3(r.field(g, gp, "max"), gp + ".max");
        for (int a = 0; a < 3; ++a)
            if (pl.min[a] > pl.max[a])
                r.fail(ErrorCode::kInvalidValue, gp, "min must be <= max on every axis (axis " + std::to_string(a) + ")");
        const json& c = r.field(g, gp, "counts");
        const std::string cp = gp + ".counts";
        if (!c.is_array() || c.size() != 3) r.fail(ErrorCode::kInvalidValue, cp, "must be an array of 3 integers");
        std::uint64_t total = 1;
        for (size_t a = 0; a < 3; ++a) {
            const std::string ap = Reader::index(cp, a);
            if (!c[a].is_number_integer()) r.fail(ErrorCode::kInvalidValue, ap, "must be an integer (got " + Reader::type_of(c[a]) + ")");
            if (c[a].is_number_unsigned() ? false : c[a].get<std::int64_t>() < 1)
                r.fail(ErrorCode::kInvalidValue, ap, "must be >= 1");
            const std::uint64_t n = c[a].is_number_unsigned() ? c[a].get<std::uint64_t>() : std::uint64_t(c[a].get<std::int64_t>());
            if (n < 1) r.fail(ErrorCode::kInvalidValue, ap, "must be >= 1");
            if (n > limits.max_probes || total * n > limits.max_probes)
                r.fail(ErrorCode::kTooLarge, cp, "grid holds more than the limit of " + std::to_string(limits.max_probes) + " probes");
            total *= n;
            pl.counts[a] = static_cast<std::uint32_t>(n);
        }
    } else {
        pl.kind = ProbePlacementKind::kPositions;
        const json& a = r.array(j["positions"], "probes.positions", limits.max_probes, "positions");
        if (a.empty()) r.fail(ErrorCode::kInvalidValue, "probes.positions", "must hold at least one position");
        for (size_t i = 0; i < a.size(); ++i) pl.positions.push_back(r.vec3(a[i], Reader::index("probes.positions", i)));
    }
    return pl;
}

SceneSky read_sky(const Reader& r, const json& j) {
    const std::string p = "sky";
    if (!j.is_object()) r.object(j, p, {});
    const std::string type = r.string(r.field(j, p, "type"), p + ".type");
    SceneSky sky;
    if (type == "constant") {
        r.object(j, p, {"type", "radiance"});
        sky.kind = SkyKind::kConstant;
        sky.radiance = r.colour(r.field(j, p, "radiance"), p + ".radiance");
    } else if (type == "gradient") {
        r.object(j, p, {"type", "zenith", "horizon", "ground", "up"});
        sky.kind = SkyKind::kGradient;
        if (j.contains("zenith")) sky.gradient.zenith = r.colour(j["zenith"], p + ".zenith");
        if (j.contains("horizon")) sky.gradient.horizon = r.colour(j["horizon"], p + ".horizon");
        if (j.contains("ground")) sky.gradient.ground = r.colour(j["ground"], p + ".ground");
        if (j.contains("up")) sky.gradient.up = r.direction(j["up"], p + ".up");
    } else {
        r.fail(ErrorCode::kUnsupported, p + ".type", "unknown sky type \"" + type + "\" (known: constant, gradient)");
    }
    return sky;
}

SceneOcclusion read_occlusion(const Reader& r, const json& j) {
    const std::string p = "occlusion";
    r.object(j, p, {"sky_samples", "invalid_fraction", "move_probes", "shadow_planes", "corner_regions"});
    SceneOcclusion o;
    if (j.contains("sky_samples")) {
        const json& s = j["sky_samples"];
        const std::string sp = p + ".sky_samples";
        if (!s.is_number_integer()) r.fail(ErrorCode::kInvalidValue, sp, "must be an integer (got " + Reader::type_of(s) + ")");
        const std::int64_t n = s.is_number_unsigned() ? std::int64_t(std::min<std::uint64_t>(s.get<std::uint64_t>(), 1u << 30)) : s.get<std::int64_t>();
        if (n < 0) r.fail(ErrorCode::kInvalidValue, sp, "must be >= 0 (got " + s.dump() + ")");
        if (n > 65536) r.fail(ErrorCode::kTooLarge, sp, "above the limit of 65536");
        o.sky_samples = static_cast<int>(n);
    }
    if (j.contains("invalid_fraction")) {
        const double f = r.non_negative(j["invalid_fraction"], p + ".invalid_fraction");
        if (f > 1) r.fail(ErrorCode::kInvalidValue, p + ".invalid_fraction", "must be in [0, 1] (got " + j["invalid_fraction"].dump() + ")");
        o.invalid_fraction = f;
    }
    if (j.contains("move_probes")) o.move_probes = r.boolean(j["move_probes"], p + ".move_probes");
    if (j.contains("shadow_planes")) o.shadow_planes = r.boolean(j["shadow_planes"], p + ".shadow_planes");
    if (j.contains("corner_regions")) o.corner_regions = r.boolean(j["corner_regions"], p + ".corner_regions");
    return o;
}

SceneLight read_light(const Reader& r, const json& j, const std::string& p, const SceneJsonLimits& limits) {
    if (!j.is_object()) r.object(j, p, {});
    const std::string type = r.string(r.field(j, p, "type"), p + ".type");
    SceneLight l;
    auto common = [&](std::initializer_list<const char*> extra) {
        // Every light takes type, name, shadows, shadow_samples.
        std::vector<const char*> keys{"type", "name", "shadows", "shadow_samples"};
        keys.insert(keys.end(), extra.begin(), extra.end());
        for (auto it = j.begin(); it != j.end(); ++it) {
            bool ok = false;
            for (const char* k : keys) ok = ok || it.key() == k;
            if (!ok) {
                std::string list;
                for (const char* k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
                r.fail(ErrorCode::kInvalidValue, Reader::join(p, it.key()),
                       "unknown field for a " + type + " light (allowed: " + list + ")");
            }
        }
        if (j.contains("name")) l.name = r.string(j["name"], p + ".name");
        if (j.contains("shadows")) l.shadows = r.boolean(j["shadows"], p + ".shadows");
        if (j.contains("shadow_samples")) {
            const json& s = j["shadow_samples"];
            const std::string sp = p + ".shadow_samples";
            if (!s.is_number_integer()) r.fail(ErrorCode::kInvalidValue, sp, "must be an integer (got " + Reader::type_of(s) + ")");
            const std::int64_t n = s.is_number_unsigned() ? std::int64_t(std::min<std::uint64_t>(s.get<std::uint64_t>(), 1u << 30)) : s.get<std::int64_t>();
            if (n < 1) r.fail(ErrorCode::kInvalidValue, sp, "must be >= 1");
            if (n > limits.max_shadow_samples)
                r.fail(ErrorCode::kTooLarge, sp, "above the limit of " + std::to_string(limits.max_shadow_samples));
            l.shadow_samples = static_cast<int>(n);
        }
    };
    if (type == "directional") {
        common({"direction", "irradiance", "angular_radius_deg"});
        l.kind = LightKind::kDirectional;
        l.direction = r.direction(r.field(j, p, "direction"), p + ".direction");
        l.color = r.colour(r.field(j, p, "irradiance"), p + ".irradiance");
        const double deg = j.contains("angular_radius_deg") ? r.non_negative(j["angular_radius_deg"], p + ".angular_radius_deg") : 0.0;
        if (deg >= 90) r.fail(ErrorCode::kInvalidValue, p + ".angular_radius_deg", "must be < 90 (got " + Reader::fmt(deg) + ")");
        l.angular_radius_rad = deg * kDeg;
    } else if (type == "point") {
        common({"position", "intensity"});
        l.kind = LightKind::kPoint;
        l.position = r.vec3(r.field(j, p, "position"), p + ".position");
        l.color = r.colour(r.field(j, p, "intensity"), p + ".intensity");
    } else if (type == "spot") {
        common({"position", "direction", "intensity", "inner_angle_deg", "outer_angle_deg"});
        l.kind = LightKind::kSpot;
        l.position = r.vec3(r.field(j, p, "position"), p + ".position");
        l.direction = r.direction(r.field(j, p, "direction"), p + ".direction");
        l.color = r.colour(r.field(j, p, "intensity"), p + ".intensity");
        const double outer = r.non_negative(r.field(j, p, "outer_angle_deg"), p + ".outer_angle_deg");
        if (outer > 180) r.fail(ErrorCode::kInvalidValue, p + ".outer_angle_deg", "must be <= 180 (got " + Reader::fmt(outer) + ")");
        const double inner = j.contains("inner_angle_deg") ? r.non_negative(j["inner_angle_deg"], p + ".inner_angle_deg") : outer;
        if (inner > outer)
            r.fail(ErrorCode::kInvalidValue, p + ".inner_angle_deg", "must be <= outer_angle_deg (got " + Reader::fmt(inner) + ")");
        l.inner_angle_rad = inner * kDeg;
        l.outer_angle_rad = outer * kDeg;
    } else if (type == "sphere") {
        common({"center", "radius", "radiance"});
        l.kind = LightKind::kSphere;
        l.center = r.vec3(r.field(j, p, "center"), p + ".center");
        l.radius = r.positive(r.field(j, p, "radius"), p + ".radius");
        l.color = r.colour(r.field(j, p, "radiance"), p + ".radiance");
    } else if (type == "hemisphere") {
        common({"direction", "radiance"});
        l.kind = LightKind::kHemisphere;
        l.direction = r.direction(r.field(j, p, "direction"), p + ".direction");
        l.color = r.colour(r.field(j, p, "radiance"), p + ".radiance");
    } else {
        r.fail(ErrorCode::kUnsupported, p + ".type",
               "unknown light type \"" + type + "\" (known: directional, point, spot, sphere, hemisphere)");
    }
    return l;
}

// The material of an occluder entry: "albedo" (diffuse reflectance in [0, 1], [r, g, b] or one
// number) and "emission" (radiance); neither: kNoMaterial (absorbs, emits nothing). Equal materials
// share one entry.
std::uint32_t read_material(const Reader& r, const json& j, const std::string& p, std::vector<SceneMaterial>& materials) {
    if (!j.contains("albedo") && !j.contains("emission")) return kNoMaterial;
    SceneMaterial m;
    if (j.contains("albedo")) {
        m.albedo = r.colour(j["albedo"], p + ".albedo");
        for (int k = 0; k < 3; ++k)
            if (m.albedo[k] > 1) r.fail(ErrorCode::kInvalidValue, p + ".albedo", "must be in [0, 1] (got " + j["albedo"].dump() + ")");
    }
    if (j.contains("emission")) m.emission = r.colour(j["emission"], p + ".emission");
    for (size_t i = 0; i < materials.size(); ++i) {
        const SceneMaterial& q = materials[i];
        bool same = true;
        for (int k = 0; k < 3; ++k) same = same && q.albedo[k] == m.albedo[k] && q.emission[k] == m.emission[k];
        if (same) return static_cast<std::uint32_t>(i);
    }
    materials.push_back(m);
    return static_cast<std::uint32_t>(materials.size() - 1);
}

SceneTransport read_transport(const Reader& r, const json& j) {
    const std::string p = "transport";
    r.object(j, p, {"bounces", "max_noise", "min_rays", "max_rays"});
    SceneTransport t;
    auto integer = [&](const char* key, int lo, int hi, int fallback) {
        if (!j.contains(key)) return fallback;
        const json& v = j[key];
        const std::string kp = p + "." + key;
        if (!v.is_number_integer()) r.fail(ErrorCode::kInvalidValue, kp, "must be an integer (got " + Reader::type_of(v) + ")");
        if (v.is_number_unsigned() ? v.get<std::uint64_t>() > std::uint64_t(hi) : (v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi))
            r.fail(ErrorCode::kInvalidValue, kp, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + v.dump() + ")");
        return static_cast<int>(v.get<std::int64_t>());
    };
    t.max_bounces = integer("bounces", 0, 1024, t.max_bounces);
    t.min_rays = integer("min_rays", 1, 1 << 20, t.min_rays);
    t.max_rays = integer("max_rays", 1, 1 << 20, std::max(t.max_rays, t.min_rays));
    if (t.max_rays < t.min_rays) r.fail(ErrorCode::kInvalidValue, p + ".max_rays", "must be >= min_rays");
    if (j.contains("max_noise")) {
        t.max_noise = r.positive(j["max_noise"], p + ".max_noise");
        if (t.max_noise > 1) r.fail(ErrorCode::kInvalidValue, p + ".max_noise", "must be in (0, 1] (got " + j["max_noise"].dump() + ")");
    }
    return t;
}

// Appends the occluder(s) of one "occluders" entry; `triangles` counts mesh triangles so far.
void read_occluder(const Reader& r, const json& j, const std::string& p, const SceneJsonLimits& limits,
                   std::vector<Occluder>& out, std::uint64_t& triangles, std::vector<SceneMaterial>& materials) {
    if (!j.is_object()) r.object(j, p, {});
    const std::string type = r.string(r.field(j, p, "type"), p + ".type");
    Occluder o;
    if (type == "sphere") {
        r.object(j, p, {"type", "name", "center", "radius", "albedo", "emission"});
        const Vec3 c = r.vec3(r.field(j, p, "center"), p + ".center");
        o = sphere_occluder(c, r.positive(r.field(j, p, "radius"), p + ".radius"));
    } else if (type == "box") {
        r.object(j, p, {"type", "name", "min", "max", "albedo", "emission"});
        const Vec3 lo = r.vec3(r.field(j, p, "min"), p + ".min");
        o = box_occluder(lo, r.vec3(r.field(j, p, "max"), p + ".max"));
        for (int a = 0; a < 3; ++a)
            if (o.min()[a] > o.max()[a]) r.fail(ErrorCode::kInvalidValue, p, "min must be <= max on every axis");
    } else if (type == "mesh") {
        // Flat vertex list [x0, y0, z0, x1, ...] and optional flat triangle list [i0, i1, i2, ...]
        // (without indices, consecutive vertex triples are the triangles).
        r.object(j, p, {"type", "name", "positions", "indices", "albedo", "emission"});
        const std::uint32_t material = read_material(r, j, p, materials);
        const std::string pp = p + ".positions";
        const json& pos = r.array(r.field(j, p, "positions"), pp, 9 * limits.max_triangles, "numbers");
        if (pos.size() % 3 != 0 || pos.empty())
            r.fail(ErrorCode::kInvalidValue, pp, "must hold 3 numbers per vertex (got " + std::to_string(pos.size()) + " numbers)");
        std::vector<Vec3> v(pos.size() / 3);
        for (size_t i = 0; i < v.size(); ++i)
            v[i] = {r.number(pos[3 * i], Reader::index(pp, 3 * i)), r.number(pos[3 * i + 1], Reader::index(pp, 3 * i + 1)),
                    r.number(pos[3 * i + 2], Reader::index(pp, 3 * i + 2))};
        std::vector<std::uint32_t> idx;
        if (j.contains("indices")) {
            const std::string ip = p + ".indices";
            const json& ind = r.array(j["indices"], ip, 3 * limits.max_triangles, "indices");
            if (ind.size() % 3 != 0 || ind.empty())
                r.fail(ErrorCode::kInvalidValue, ip, "must hold 3 vertex indices per triangle (got " + std::to_string(ind.size()) + ")");
            idx.reserve(ind.size());
            for (size_t i = 0; i < ind.size(); ++i) {
                const json& x = ind[i];
                if (!x.is_number_unsigned() || x.get<std::uint64_t>() >= v.size())
                    r.fail(ErrorCode::kInvalidValue, Reader::index(ip, i),
                           "must be an integer vertex index in [0, " + std::to_string(v.size()) + ") (got " + x.dump() + ")");
                idx.push_back(static_cast<std::uint32_t>(x.get<std::uint64_t>()));
            }
        } else {
            if (v.size() % 3 != 0)
                r.fail(ErrorCode::kInvalidValue, pp, "without \"indices\", the vertex count must be a multiple of 3 (got " +
                                                         std::to_string(v.size()) + " vertices)");
            for (size_t i = 0; i < v.size(); ++i) idx.push_back(static_cast<std::uint32_t>(i));
        }
        triangles += idx.size() / 3;
        if (triangles > limits.max_triangles)
            r.fail(ErrorCode::kTooLarge, p, "mesh triangles exceed the limit of " + std::to_string(limits.max_triangles) + " in all");
        for (size_t t = 0; t + 2 < idx.size(); t += 3) {
            out.push_back(triangle_occluder(v[idx[t]], v[idx[t + 1]], v[idx[t + 2]]));
            out.back().material = material;
        }
        if (j.contains("name")) (void)r.string(j["name"], p + ".name");
        return;
    } else {
        r.fail(ErrorCode::kUnsupported, p + ".type", "unknown occluder type \"" + type + "\" (known: sphere, box, mesh)");
    }
    if (j.contains("name")) (void)r.string(j["name"], p + ".name");
    o.material = read_material(r, j, p, materials);
    out.push_back(o);
}

Scene parse(const Reader& r, const json& doc, const std::string& name, const std::string& base_dir,
            const SceneLoadOptions& options) {
    const SceneJsonLimits& limits = options.limits;
    r.object(doc, "", {"format", "version", "description", "probes", "environment", "sky", "lights", "occluders", "occlusion", "transport"});
    if (doc.contains("format") && r.string(doc["format"], "format") != "zhc-scene")
        r.fail(ErrorCode::kBadFormat, "format", "must be \"zhc-scene\"");
    const json& version = r.field(doc, "", "version");
    if (!version.is_number_integer()) r.fail(ErrorCode::kInvalidValue, "version", "must be an integer (got " + Reader::type_of(version) + ")");
    if (version != 1) r.fail(ErrorCode::kUnsupported, "version", "unsupported scene version " + version.dump() + " (this zhc reads 1)");
    if (doc.contains("description")) (void)r.string(doc["description"], "description");
    Scene s;
    s.probes = read_probes(r, r.field(doc, "", "probes"), limits);
    if (doc.contains("environment") && doc.contains("sky"))
        r.fail(ErrorCode::kInvalidValue, "sky", "a scene has either \"environment\" or \"sky\", not both");
    if (doc.contains("environment")) {
        const std::string p = "environment";
        const json& e = r.object(doc["environment"], p, {"map", "intensity", "rotation_deg", "latlong", "ldr_encoding"});
        SceneEnvironment env;
        const std::string map = r.string(r.field(e, p, "map"), p + ".map");
        if (map.empty()) r.fail(ErrorCode::kInvalidValue, p + ".map", "must not be empty");
        env.intensity = e.contains("intensity") ? r.non_negative(e["intensity"], p + ".intensity") : 1.0;
        env.rotation_rad = r.number_or(e, p, "rotation_deg", 0.0) * kDeg;
        env.latlong = options.default_latlong;
        if (e.contains("latlong")) {
            const std::string name = r.string(e["latlong"], p + ".latlong");
            if (!parse_latlong_convention(name, &env.latlong))
                r.fail(ErrorCode::kInvalidValue, p + ".latlong", "must be \"openexr\" or \"gltf\" (got \"" + name + "\")");
        }
        LdrDecoding ldr;
        if (e.contains("ldr_encoding")) {
            env.ldr_encoding = r.string(e["ldr_encoding"], p + ".ldr_encoding");
            if (!parse_ldr_decoding(env.ldr_encoding, &ldr))
                r.fail(ErrorCode::kInvalidValue, p + ".ldr_encoding",
                       "must be \"auto\", \"srgb\", \"linear\", \"rgbm:RANGE\" or \"rgbd:RANGE\" with 0 < RANGE <= 65504 (got \"" +
                           env.ldr_encoding + "\")");
        }
        const fs::path mp(map);
        env.source = mp.is_absolute() || base_dir.empty() ? map : (fs::path(base_dir) / mp).string();
        if (options.load_environment) {
            EnvmapReadOptions ro;
            ro.latlong = env.latlong;
            ro.ldr = ldr;
            auto img = read_envmap(env.source, ro);
            if (!img) throw Fail{make_error(img.error().code, name + ": environment.map: " + img.error().message)};
            env.latlong_map = img->layout == EnvmapLayout::kLatLong;
            env.projected = project_envmap(*img, std::max(1, options.threads));
        }
        s.environment = env;
    }
    if (doc.contains("sky")) s.sky = read_sky(r, doc["sky"]);
    if (doc.contains("occlusion")) s.occlusion = read_occlusion(r, doc["occlusion"]);
    if (doc.contains("lights")) {
        const json& a = r.array(doc["lights"], "lights", limits.max_lights, "lights");
        for (size_t i = 0; i < a.size(); ++i) s.lights.push_back(read_light(r, a[i], Reader::index("lights", i), limits));
    }
    if (doc.contains("occluders")) {
        const json& a = r.array(doc["occluders"], "occluders", limits.max_occluders, "occluders");
        std::uint64_t triangles = 0;
        for (size_t i = 0; i < a.size(); ++i)
            read_occluder(r, a[i], Reader::index("occluders", i), limits, s.occluders, triangles, s.materials);
    }
    if (doc.contains("transport")) s.transport = read_transport(r, doc["transport"]);
    if (options.bounces >= 0) s.transport.max_bounces = options.bounces;
    if (Status budget = check_ray_budget(s, limits, ""); !budget) throw Fail{make_error(budget.error().code, name + ": " + budget.error().message)};
    return s;
}

json vec_json(Vec3 v) { return json::array({v.x, v.y, v.z}); }
json rgb_json(Rgb c) { return json::array({c.r, c.g, c.b}); }

}  // namespace

Status check_ray_budget(const Scene& s, const SceneJsonLimits& limits, const std::string& name) {
    // Probes x samples over the lights that trace.
    if (s.occluders.empty()) return Ok{};
    const std::uint64_t probes = s.probes.kind == ProbePlacementKind::kGrid
                                     ? std::uint64_t(s.probes.counts[0]) * s.probes.counts[1] * s.probes.counts[2]
                                     : s.probes.positions.size();
    std::uint64_t per_probe = 0;
    for (const SceneLight& l : s.lights) {
        if (!l.shadows) continue;
        const bool punctual = l.kind == LightKind::kPoint || l.kind == LightKind::kSpot ||
                              (l.kind == LightKind::kDirectional && l.angular_radius_rad == 0);
        per_probe += punctual ? 1 : static_cast<std::uint64_t>(l.shadow_samples);
    }
    // The occlusion pass (sky/environment, validity) and the visibility masks (8 cells per probe).
    const bool grid = s.probes.kind == ProbePlacementKind::kGrid;
    if (s.occlusion.sky_samples > 0 && (grid || s.sky || s.environment))
        per_probe += static_cast<std::uint64_t>(s.occlusion.sky_samples) + (grid ? 8u * kMaskPoints : 0u);
    if (per_probe > 0 && probes > limits.max_rays / per_probe)
        return make_error(ErrorCode::kTooLarge, (name.empty() ? "" : name + ": ") + "lights: the bake would cast " +
                                                    std::to_string(probes) + " x " + std::to_string(per_probe) +
                                                     " shadow rays, above the limit of " + std::to_string(limits.max_rays));
    return Ok{};
}

std::string one_line_message(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7f) {
            char b[8];
            std::snprintf(b, sizeof b, "\\x%02x", u);
            out += b;
        } else {
            out += c;
        }
    }
    return out;
}

namespace {
Result<Scene> parse_scene_json_unchecked(std::span<const std::uint8_t> bytes, const std::string& name,
                                         const std::string& base_dir, const SceneLoadOptions& options) {
    if (bytes.size() > options.limits.max_file_bytes)
        return make_error(ErrorCode::kTooLarge, name + ": scene file larger than the limit of " +
                                                    std::to_string(options.limits.max_file_bytes) + " bytes");
    if (Status depth = check_json_depth(bytes, name); !depth) return depth.error();
    json doc;
    try {
        doc = json::parse(bytes.begin(), bytes.end());
    } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers like 1e999
        return make_error(ErrorCode::kBadFormat, name + ": not valid JSON (" + e.what() + ")" + git_lfs_hint(bytes));
    } catch (const std::bad_alloc&) {
        return make_error(ErrorCode::kTooLarge, name + ": out of memory while reading the scene");
    }
    const Reader r(name);
    try {
        Scene s = parse(r, doc, name, base_dir, options);
        if (Status v = validate_scene(s); !v) return make_error(v.error().code, name + ": " + v.error().message);
        return s;
    } catch (const Fail& f) {
        return f.error;
    } catch (const json::exception& e) {  // a type mismatch the checks above missed
        return make_error(ErrorCode::kInvalidValue, name + ": " + e.what());
    } catch (const std::bad_alloc&) {
        return make_error(ErrorCode::kTooLarge, name + ": out of memory while reading the scene");
    }
}
}  // namespace

Result<Scene> parse_scene_json(std::span<const std::uint8_t> bytes, const std::string& name,
                               const std::string& base_dir, const SceneLoadOptions& options) {
    // Messages echo field names and values from the input: keep them one line.
    auto s = parse_scene_json_unchecked(bytes, name, base_dir, options);
    if (!s) return make_error(s.error().code, one_line_message(s.error().message));
    return s;
}

Result<Scene> read_scene_file(const std::string& path, const SceneLoadOptions& options) {
    auto bytes = read_file_bytes(path, options.limits.max_file_bytes);
    if (!bytes) return bytes.error();
    const std::string dir = fs::path(path).parent_path().string();
    return parse_scene_json(*bytes, path, dir, options);
}

std::string scene_json(const Scene& s) {
    json doc;
    doc["format"] = "zhc-scene";
    doc["version"] = 1;
    if (s.probes.kind == ProbePlacementKind::kGrid) {
        doc["probes"]["grid"] = {{"min", vec_json(s.probes.min)},
                                 {"max", vec_json(s.probes.max)},
                                 {"counts", json::array({s.probes.counts[0], s.probes.counts[1], s.probes.counts[2]})}};
    } else {
        json a = json::array();
        for (const Vec3& p : s.probes.positions) a.push_back(vec_json(p));
        doc["probes"]["positions"] = a;
    }
    if (s.environment)
        doc["environment"] = {{"map", s.environment->source},
                              {"intensity", s.environment->intensity},
                              {"rotation_deg", s.environment->rotation_rad / kDeg},
                              {"latlong", latlong_convention_name(s.environment->latlong)}};
    if (s.environment && s.environment->ldr_encoding != "auto") doc["environment"]["ldr_encoding"] = s.environment->ldr_encoding;
    if (s.sky) {
        if (s.sky->kind == SkyKind::kConstant) {
            doc["sky"] = {{"type", "constant"}, {"radiance", rgb_json(s.sky->radiance)}};
        } else {
            const GradientSky& g = s.sky->gradient;
            doc["sky"] = {{"type", "gradient"}, {"zenith", rgb_json(g.zenith)}, {"horizon", rgb_json(g.horizon)},
                          {"ground", rgb_json(g.ground)}, {"up", vec_json(g.up)}};
        }
    }
    const SceneOcclusion defaults;
    if (s.occlusion.sky_samples != defaults.sky_samples || s.occlusion.invalid_fraction != defaults.invalid_fraction ||
        s.occlusion.move_probes != defaults.move_probes || s.occlusion.shadow_planes != defaults.shadow_planes ||
        s.occlusion.corner_regions != defaults.corner_regions) {
        doc["occlusion"] = {{"sky_samples", s.occlusion.sky_samples}, {"invalid_fraction", s.occlusion.invalid_fraction}};
        if (s.occlusion.move_probes != defaults.move_probes) doc["occlusion"]["move_probes"] = s.occlusion.move_probes;
        if (s.occlusion.shadow_planes != defaults.shadow_planes) doc["occlusion"]["shadow_planes"] = s.occlusion.shadow_planes;
        if (s.occlusion.corner_regions != defaults.corner_regions) doc["occlusion"]["corner_regions"] = s.occlusion.corner_regions;
    }
    json lights = json::array();
    for (const SceneLight& l : s.lights) {
        json j;
        j["type"] = light_kind_name(l.kind);
        if (!l.name.empty()) j["name"] = l.name;
        switch (l.kind) {
            case LightKind::kDirectional:
                j["direction"] = vec_json(l.direction);
                j["irradiance"] = rgb_json(l.color);
                j["angular_radius_deg"] = l.angular_radius_rad / kDeg;
                break;
            case LightKind::kPoint:
                j["position"] = vec_json(l.position);
                j["intensity"] = rgb_json(l.color);
                break;
            case LightKind::kSpot:
                j["position"] = vec_json(l.position);
                j["direction"] = vec_json(l.direction);
                j["intensity"] = rgb_json(l.color);
                j["inner_angle_deg"] = l.inner_angle_rad / kDeg;
                j["outer_angle_deg"] = l.outer_angle_rad / kDeg;
                break;
            case LightKind::kSphere:
                j["center"] = vec_json(l.center);
                j["radius"] = l.radius;
                j["radiance"] = rgb_json(l.color);
                break;
            case LightKind::kHemisphere:
                j["direction"] = vec_json(l.direction);
                j["radiance"] = rgb_json(l.color);
                break;
        }
        if (l.shadows) {
            j["shadows"] = true;
            j["shadow_samples"] = l.shadow_samples;
        }
        lights.push_back(j);
    }
    if (!lights.empty()) doc["lights"] = lights;
    json occ = json::array();
    // A textured triangle is written with its material's factors (JSON scenes hold no textures).
    auto material_of = [&](std::uint32_t material) {
        if (is_surface(material) && (material & ~kSurfaceBit) < s.surfaces.size()) return s.surfaces[material & ~kSurfaceBit].material;
        return material;
    };
    auto with_material = [&](json j, std::uint32_t material) {
        material = material_of(material);
        if (material < s.materials.size()) {
            j["albedo"] = rgb_json(s.materials[material].albedo);
            j["emission"] = rgb_json(s.materials[material].emission);
        }
        return j;
    };
    for (size_t i = 0; i < s.occluders.size(); ++i) {
        const Occluder& o = s.occluders[i];
        if (o.kind == OccluderKind::kSphere) {
            occ.push_back(with_material({{"type", "sphere"}, {"center", vec_json(o.center())}, {"radius", o.radius()}}, o.material));
        } else if (o.kind == OccluderKind::kBox) {
            occ.push_back(with_material({{"type", "box"}, {"min", vec_json(o.min())}, {"max", vec_json(o.max())}}, o.material));
        } else {
            // Consecutive triangles of one material are one mesh entry.
            json pos = json::array();
            for (; i < s.occluders.size() && s.occluders[i].kind == OccluderKind::kTriangle && material_of(s.occluders[i].material) == material_of(o.material); ++i)
                for (const Vec3& v : {s.occluders[i].v0, s.occluders[i].v1, s.occluders[i].v2})
                    for (int a = 0; a < 3; ++a) pos.push_back(v[a]);
            --i;
            occ.push_back(with_material({{"type", "mesh"}, {"positions", pos}}, o.material));
        }
    }
    if (!occ.empty()) doc["occluders"] = occ;
    const SceneTransport dt;
    const SceneTransport& t = s.transport;
    if (t.max_bounces != dt.max_bounces || t.max_noise != dt.max_noise || t.min_rays != dt.min_rays || t.max_rays != dt.max_rays)
        doc["transport"] = {{"bounces", t.max_bounces}, {"max_noise", t.max_noise}, {"min_rays", t.min_rays}, {"max_rays", t.max_rays}};
    return doc.dump(2) + "\n";
}

}  // namespace zhc
