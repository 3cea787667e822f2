// zhc/formats/scene/scene_gltf_lights.cpp — KHR_lights_punctual lights of a glTF 2.0 scene
// (docs/scene.md "glTF input"): the light definitions checked against the extension's constraints,
// and each light node's instance in zhc axes and units (candela / lux -> zhc intensity).
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

}  // namespace zhc::scene_gltf_detail
