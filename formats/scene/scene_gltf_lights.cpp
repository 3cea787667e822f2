// zhc/formats/scene/scene_gltf_lights.cpp — KHR_lights_punctual lights of a glTF 2.0 scene
// (docs/scene.md "glTF input"): the light definitions checked against the extension's constraints,
// and each light node's instance in zhc axes and units (candela / lux -> zhc intensity); and the
// EXT_lights_image_based environment of the scene (its SH irradiance as zhc SH3 radiance).
#include "formats/scene/scene_gltf_reader.h"

#include <limits>

namespace zhc::scene_gltf_detail {

// ---- KHR_lights_punctual -------------------------------------------------------------------

void Reader::read_light_defs() {
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

void Reader::add_light(size_t li, const Mat4& world, const std::string& where) {
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

// ---- EXT_lights_image_based ----------------------------------------------------------------

// The scene's image-based light: scenes[s].extensions.EXT_lights_image_based.light indexes the root
// extensions.EXT_lights_image_based.lights. Only `irradianceCoefficients` (9 x [r, g, b]),
// `intensity` and `rotation` matter to probes; the specular cube images are not read.
//
// The coefficients are SH of the *physical* irradiance E(n) = integral L(w) max(0, n.w) dw in the
// glTF frame, with zhc's basis (docs/conventions.md) evaluated on glTF (x, y, z) — the convention
// of the extension's references (Ramamoorthi & Hanrahan 2001, E_lm = A_l L_lm with A_l = pi,
// 2 pi / 3, pi / 4) and of Babylon.js, which divides them by pi to get a Lambertian surface's
// exit radiance. zhc's irradiance is that exit radiance (normalised, E / pi), so
//     radiance L_lm = c_lm / A_l  (= to_radiance(c / pi));
// then `rotation` turns the environment (radiance from w arrives from R w, like a node's rotation
// turns its content) and the glTF frame becomes zhc's ((x, y, z)_zhc = (z, x, y)_glTF).
std::optional<SceneEnvironment> Reader::image_based_light() {
    const char* kExt = "EXT_lights_image_based";
    const json empty = json::object();
    const json& root_ext = doc_.contains("extensions") && doc_["extensions"].is_object() ? doc_["extensions"] : empty;
    size_t defined = 0;
    const std::string lp = std::string("extensions.") + kExt + ".lights";
    if (root_ext.contains(kExt)) {
        const json& e = root_ext[kExt];
        if (!e.is_object() || !e.contains("lights") || !e["lights"].is_array()) fail(ErrorCode::kInvalidValue, lp, "must be an array");
        defined = e["lights"].size();
    }
    std::optional<size_t> li;
    std::string sp;
    if (scene_) {
        sp = at("scenes", *scene_);
        const json& sc = array_of(doc_, "scenes")[*scene_];
        if (sc.contains("extensions") && sc["extensions"].is_object() && sc["extensions"].contains(kExt)) {
            const json& r = sc["extensions"][kExt];
            const std::string rp = sp + ".extensions." + kExt + ".light";
            if (!r.is_object() || !r.contains("light")) fail(ErrorCode::kInvalidValue, rp, "missing");
            li = index(r["light"], rp, defined, "extensions.EXT_lights_image_based.lights");
        }
    }
    if (!li) {
        if (defined > 0)
            notes_.push_back(std::string(kExt) + ": " + std::to_string(defined) + " image-based light(s) defined, none referenced by " +
                             (scene_ ? sp : std::string("the asset (it has no scene)")) + ": not used");
        return std::nullopt;
    }
    const std::string p = at(lp, *li);
    const json& l = root_ext[kExt]["lights"][*li];
    if (!l.is_object()) fail(ErrorCode::kInvalidValue, p, "must be an object");
    if (!l.contains("irradianceCoefficients")) fail(ErrorCode::kInvalidValue, p + ".irradianceCoefficients", "missing required field");
    const json& c = l["irradianceCoefficients"];
    const std::string cp = p + ".irradianceCoefficients";
    if (!c.is_array() || c.size() != 9) fail(ErrorCode::kInvalidValue, cp, "must be an array of 9 [r, g, b] arrays (SH bands 0..2)");
    Sh3Irradiance e;  // zhc's normalised irradiance: the coefficients / pi
    for (size_t i = 0; i < 9; ++i) {
        const auto rgb = numbers(c[i], at(cp, i), 3);
        for (int k = 0; k < 3; ++k) {
            const double v = rgb[static_cast<size_t>(k)] / kPi;
            if (!(std::fabs(v) <= 1e30)) fail(ErrorCode::kInvalidValue, at(cp, i), "too large (at most 1e30 in magnitude)");
            e[static_cast<int>(i)][k] = static_cast<float>(v);
        }
    }
    SceneEnvironment env;
    env.intensity = 1;
    if (l.contains("intensity")) {
        env.intensity = number(l["intensity"], p + ".intensity");
        if (env.intensity < 0) fail(ErrorCode::kInvalidValue, p + ".intensity", "must be >= 0");
    }
    double q[4] = {0, 0, 0, 1};
    if (l.contains("rotation")) {
        const auto v = numbers(l["rotation"], p + ".rotation", 4);
        const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
        if (!(len > 0)) fail(ErrorCode::kInvalidValue, p + ".rotation", "must be a unit quaternion (got zero)");
        for (int k = 0; k < 4; ++k) q[k] = v[static_cast<size_t>(k)] / len;
    }
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    Mat3 r;
    r.m = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
           2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
           2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    Sh3Radiance radiance = to_radiance(e);
    if (l.contains("rotation")) radiance = rotate(radiance, r);
    env.projected = rotate(radiance, transpose(zhc_to_gltf_rotation()));  // glTF frame -> zhc frame
    // The baked probes are 32-bit floats: intensity x coefficients must stay far inside their range.
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            if (!(std::fabs(double(env.projected[i][k])) * env.intensity <= 1e37))
                fail(ErrorCode::kInvalidValue, p + ".intensity", "intensity x irradianceCoefficients does not fit 32-bit floats");
    const std::string name = l.contains("name") && l["name"].is_string() ? l["name"].get<std::string>() : "";
    env.label = std::string(kExt) + " " + (name.empty() ? at("lights", *li) : "'" + name + "'");
    env.source = env.label;
    return env;
}

}  // namespace zhc::scene_gltf_detail
