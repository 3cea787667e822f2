// zhc/codec/bake/lights.cpp — the closed forms of the lights, the sky and the sample directions
// (codec/bake/scene.h, docs/scene.md "What each effect computes").
#include <algorithm>
#include <cmath>

#include "codec/bake/bake_internal.h"
#include "codec/bake/scene.h"

namespace zhc {
using namespace bake_detail;
namespace {

// Zonal factors of ZH3 paper Eq. 15 times the sqrt(4 pi / (2l + 1)) of the rotation to `axis`
// (Eq. 2), so a cone contributes  L * F_l(c, s2) * Y_lm(axis)  to coefficient (l, m):
//   f0 = sqrt(pi) (1 - c),  f1 = sqrt(3 pi) / 2 s^2,  f2 = sqrt(5 pi) / 2 c s^2.
const double kSqrtPi = std::sqrt(kPi);
const double kBand0 = std::sqrt(4.0 * kPi), kBand1 = std::sqrt(4.0 * kPi / 3.0), kBand2 = std::sqrt(4.0 * kPi / 5.0);

// Cone of half-angle sigma (cos_s = cos sigma, sin2 = sin^2 sigma) around unit `axis`.
void add_cone(Vec3 axis, double cos_s, double sin2, Rgb radiance, double acc[27]) {
    const double f[3] = {kSqrtPi * (1.0 - cos_s) * kBand0, std::sqrt(3.0 * kPi) / 2.0 * sin2 * kBand1,
                         std::sqrt(5.0 * kPi) / 2.0 * cos_s * sin2 * kBand2};
    const auto y = sh3_basis(axis);
    for (int i = 0; i < 9; ++i) {
        const int l = i == 0 ? 0 : (i < 4 ? 1 : 2);
        const double fy = f[l] * y[static_cast<size_t>(i)];
        for (int k = 0; k < 3; ++k) acc[i * 3 + k] += fy * radiance[k];
    }
}

void add_delta(Vec3 d, double scale, Rgb color, double acc[27]) {
    const double w[3] = {scale * color.r, scale * color.g, scale * color.b};
    add_weighted_basis(d, w, acc);
}

double smoothstep(double e0, double e1, double x) {
    if (e1 <= e0) return x >= e0 ? 1.0 : 0.0;
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

}  // namespace

namespace bake_detail {

void add_weighted_basis(Vec3 d, const double w[3], double acc[27]) {
    const auto y = sh3_basis(d);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) acc[i * 3 + k] += w[k] * y[static_cast<size_t>(i)];
}

bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool colour_ok(Rgb c) {
    for (int k = 0; k < 3; ++k)
        if (!std::isfinite(c[k]) || c[k] < 0) return false;
    return true;
}

std::string effect_name(const SceneLight& l) {
    std::string n = l.kind == LightKind::kDirectional ? "sun" : light_kind_name(l.kind);
    if (l.kind == LightKind::kDirectional && l.angular_radius_rad == 0) n = "directional";
    if (!l.name.empty()) n += " '" + l.name + "'";
    return n;
}

}  // namespace bake_detail

const char* light_kind_name(LightKind kind) {
    switch (kind) {
        case LightKind::kDirectional: return "directional";
        case LightKind::kPoint: return "point";
        case LightKind::kSpot: return "spot";
        case LightKind::kSphere: return "sphere";
        case LightKind::kHemisphere: return "hemisphere";
    }
    return "?";
}

void add_light_closed_form(const SceneLight& light, Vec3 p, double acc[27]) {
    switch (light.kind) {
        case LightKind::kDirectional: {
            const Vec3 d = normalize_or(light.direction, {0, 0, 1});
            if (light.angular_radius_rad <= 0) {
                // A delta whose normalised irradiance on a facing surface is E: integral L dw = pi E.
                add_delta(d, kPi, light.color, acc);
            } else {
                const double s = std::sin(light.angular_radius_rad), c = std::cos(light.angular_radius_rad);
                const double to_radiance = 1.0 / (s * s);  // E = L sin^2 sigma (codec/bake/sky.h Sun)
                const Rgb L{float(light.color.r * to_radiance), float(light.color.g * to_radiance),
                            float(light.color.b * to_radiance)};
                add_cone(d, c, s * s, L, acc);
            }
            return;
        }
        case LightKind::kPoint:
        case LightKind::kSpot: {
            const Vec3 v = light.position - p;
            const double d2 = dot(v, v);
            if (!(d2 > 0)) return;  // probe at the light: undefined, contributes nothing (docs/scene.md)
            const double d = std::sqrt(d2);
            const Vec3 w = (1.0 / d) * v;
            double scale = 1.0 / d2;  // inverse square: integral L dw = I / d^2
            if (light.kind == LightKind::kSpot) {
                const Vec3 axis = normalize_or(light.direction, {0, 0, -1});
                scale *= smoothstep(std::cos(light.outer_angle_rad), std::cos(light.inner_angle_rad), -dot(axis, w));
                if (scale == 0) return;
            }
            add_delta(w, scale, light.color, acc);
            return;
        }
        case LightKind::kSphere: {
            const Vec3 v = light.center - p;
            const double d2 = dot(v, v), r2 = light.radius * light.radius;
            if (d2 <= r2) {  // inside: constant radiance over the whole sphere, L00 = 2 sqrt(pi) L
                for (int k = 0; k < 3; ++k) acc[k] += 2.0 * kSqrtPi * light.color[k];
                return;
            }
            const double d = std::sqrt(d2);
            const double sin2 = r2 / d2;  // sin sigma = r / d
            add_cone((1.0 / d) * v, std::sqrt(1.0 - sin2), sin2, light.color, acc);
            return;
        }
        case LightKind::kHemisphere:
            add_cone(normalize_or(light.direction, {0, 0, 1}), 0.0, 1.0, light.color, acc);
            return;
    }
}

std::vector<Vec3> cone_sample_directions(Vec3 axis, double sigma, int count) {
    // Equal-area spiral over the cap: z uniform in [cos sigma, 1] (Archimedes: equal z steps are
    // equal areas), azimuth stepped by the golden angle pi (3 - sqrt 5).
    std::vector<Vec3> out;
    if (count <= 0) return out;
    out.reserve(static_cast<size_t>(count));
    const Mat3 frame = frame_from_z(normalize_or(axis, {0, 0, 1}));
    const double c = std::cos(sigma), golden = kPi * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < count; ++k) {
        const double z = 1.0 - (k + 0.5) / count * (1.0 - c);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = golden * k;
        out.push_back(frame * Vec3{r * std::cos(phi), r * std::sin(phi), z});
    }
    return out;
}

std::vector<Vec3> sphere_sample_directions(int count) { return fibonacci_sphere(count); }

void sky_radiance(const SceneSky& sky, Vec3 d, double rgb[3]) {
    if (sky.kind == SkyKind::kConstant) {
        for (int k = 0; k < 3; ++k) rgb[k] = sky.radiance[k];
        return;
    }
    const GradientSky& g = sky.gradient;
    const double z = dot(normalize_or(g.up, {0, 0, 1}), d);
    for (int k = 0; k < 3; ++k)
        rgb[k] = z >= 0 ? double(g.horizon[k]) + (double(g.zenith[k]) - g.horizon[k]) * z : double(g.ground[k]);
}

}  // namespace zhc
