// Helpers shared by the ZH3 tests (test_zh3, test_zh3_solve, test_zh3_clamp): codec lookup and round
// trip, coefficient distances, random lightings and rotations, the eight real maps.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/zh3.h"
#include "support.h"

namespace zhc::zh3_test {

using test::fibonacci_directions;

inline constexpr const char* kZh3Names[] = {
    "zh3_lum",     "zh3_channel",         "zh3_solved_lum",      "zh3_solved_channel",
    "hall_ambdir", "hall_sphere",         "hall_curve",          "hall_ambdir_channel",
    "hall_sphere_channel", "hall_curve_channel", "zh3_lum_axis_clamp", "zh3_lum_sphere_clamp"};

inline const Codec& codec(const char* name) {
    const Codec* c = find_codec(name);
    if (!c) {
        ADD_FAILURE() << "missing codec " << name;
        return *find_codec("sh3");
    }
    return *c;
}

inline Sh3Radiance round_trip(const Codec& c, const Sh3Radiance& in, const CodecOptions& o = {}, EncodeStats* stats = nullptr) {
    std::vector<std::uint8_t> bytes(c.size_bytes);
    c.encode(in, o, bytes.data(), stats);
    return c.decode(bytes.data(), o);
}

inline double coefficient_distance(const Sh3Radiance& a, const Sh3Radiance& b, int from = 0, int to = 9) {
    double s = 0;
    for (int i = from; i < to; ++i)
        for (int k = 0; k < 3; ++k) s += (double(a[i][k]) - b[i][k]) * (double(a[i][k]) - b[i][k]);
    return std::sqrt(s);
}
inline double coefficient_norm(const Sh3Radiance& a, int from = 0, int to = 9) { return coefficient_distance(a, Sh3Radiance{}, from, to); }

// ---- inputs -----------------------------------------------------------------------------------

struct Rng : test::Rng {
    using test::Rng::Rng;
    Rgb colour() { return {float(0.1 + u()), float(0.1 + u()), float(0.1 + u())}; }
};

// A sum of deltas, sphere lights and hemispheres with random colours: a non-negative lighting.
inline Sh3Radiance random_lighting(Rng& rng) {
    Sh3Radiance sh = project_constant({float(0.05 * rng.u()), float(0.05 * rng.u()), float(0.05 * rng.u())});
    const int n = 1 + static_cast<int>(rng.u() * 4);
    for (int i = 0; i < n; ++i) {
        const double kind = rng.u();
        const Vec3 d = rng.dir();
        if (kind < 0.35) {
            sh = sh + project_directional(d, rng.colour());
        } else if (kind < 0.8) {
            const double sigma = 0.05 + 1.5 * rng.u();
            sh = sh + project_cone(d, sigma, rng.colour());
        } else {
            sh = sh + project_hemisphere(d, rng.colour());
        }
    }
    return sh;
}
// Random coefficients (not necessarily from a non-negative function), DC kept positive.
inline Sh3Radiance random_coefficients(Rng& rng) {
    Sh3Radiance sh;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) sh[i][k] = static_cast<float>(i == 0 ? 1.0 + rng.u() : 2.0 * rng.u() - 1.0);
    return sh;
}

struct RealMap {
    std::string name;
    Sh3Radiance sh;
    std::vector<Rgb> true_irradiance;  // at reference_directions(), from the 256x128 downsample
};
inline const std::vector<Vec3>& reference_directions() {
    static const std::vector<Vec3> dirs = fibonacci_directions(2048);
    return dirs;
}
// Reference irradiance of a map at reference_directions() by direct integration.
inline void add_true_irradiance(const Image& img, RealMap* out) {
    // Same sum as test::integrate_irradiance (flux-preserving 4x box downsample to 256x128), with the
    // pixel directions and solid angles computed once instead of per direction.
    RealMap& m = *out;
    const Image small = test::downsample_latlong(img, 4);
    std::vector<Vec3> pixel_dir;
    std::vector<double> pixel_weight;
    for (int y = 0; y < small.height; ++y)
        for (int x = 0; x < small.width; ++x) {
            pixel_dir.push_back(latlong_direction(x, y, small.width, small.height));
            pixel_weight.push_back(latlong_pixel_solid_angle(y, small.width, small.height));
        }
    for (const Vec3 n : reference_directions()) {
        double acc[3] = {};
        for (size_t i = 0; i < pixel_dir.size(); ++i) {
            const double c = dot(n, pixel_dir[i]);
            if (c <= 0) continue;
            for (int k = 0; k < 3; ++k) acc[k] += pixel_weight[i] * c * small.rgb[i * 3 + static_cast<size_t>(k)];
        }
        m.true_irradiance.push_back({float(acc[0] / kPi), float(acc[1] / kPi), float(acc[2] / kPi)});
    }
    // spot check against the support twin
    const Rgb twin = test::integrate_irradiance(small, reference_directions()[100]);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(twin[k], m.true_irradiance[100][k], 1e-5 * (1 + std::fabs(twin[k])));
}

// The eight maps; with_true_irradiance also integrates the reference irradiance (slower).
inline std::vector<RealMap> load_real_maps(bool with_true_irradiance) {
    std::vector<RealMap> out;
    {
        for (const std::string& path : test::envmap_paths()) {
            const Image img = test::load_envmap(path);
            if (img.width == 0) continue;
            RealMap m;
            m.name = test::envmap_name(path);
            m.sh = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
            if (with_true_irradiance) add_true_irradiance(img, &m);
            out.push_back(std::move(m));
        }
    }
    return out;
}
// The eight maps projected exactly at full resolution, loaded once per test process.
inline const std::vector<RealMap>& real_maps() {
    static const std::vector<RealMap> maps = load_real_maps(false);
    return maps;
}

inline Mat3 random_rotation(Rng& rng) {
    const Vec3 axis = rng.dir();
    return rotation_axis_angle(axis, 2 * kPi * rng.u());
}

}  // namespace zhc::zh3_test
