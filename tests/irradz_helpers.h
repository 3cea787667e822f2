// Helpers shared by the IrradZ tests (test_irradz, test_irradz_newton): dense hemisphere quadrature,
// brute-force error twin, random radiance and directions, tangent-frame texels from the real maps.
#pragma once

#include <cstdio>
#include <limits>
#include <random>

#include "codec/lightmap/irradz.h"
#include "support.h"

namespace zhc::irradz_test {

using namespace irradz;
using test::fibonacci_directions;

// Dense quadrature points on the upper hemisphere (Fibonacci points of the sphere with z >= 0),
// each standing for 4 pi / N steradians.
struct Dense {
    std::vector<Vec3> dirs;
    double weight;
};
inline const Dense& dense_hemisphere() {
    static const Dense d = [] {
        Dense d;
        const int n = 200000;
        for (const Vec3 v : fibonacci_directions(n))
            if (v.z >= 0) d.dirs.push_back(v);
        d.weight = 4 * kPi / n;
        return d;
    }();
    return d;
}

inline double sh_eval(const Sh3Irradiance& s, int k, Vec3 n) {
    const auto y = sh3_basis(n);
    double t = 0;
    for (int i = 0; i < 9; ++i) t += s[i][k] * y[static_cast<size_t>(i)];
    return t;
}

// Brute twin of sh_hemispherical_error / hemispherical_mse: dense hemisphere integration.
inline double brute_error(const Sh3Irradiance& target, const std::function<double(int, Vec3)>& model, bool mean) {
    const Dense& d = dense_hemisphere();
    double e = 0;
    for (const Vec3 n : d.dirs)
        for (int k = 0; k < 3; ++k) {
            const double r = sh_eval(target, k, n) - model(k, n);
            e += d.weight * r * r;
        }
    return mean ? e / (2 * kPi) : e;
}

inline Sh3Radiance random_radiance(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-0.5, 1.0);
    Sh3Radiance s;
    for (int k = 0; k < 3; ++k) {
        s[0][k] = static_cast<float>(3.0 + u(rng));
        for (int i = 1; i < 9; ++i) s[i][k] = static_cast<float>(u(rng));
    }
    return s;
}

inline Vec3 upper_direction(std::mt19937& rng, double max_theta) {
    std::uniform_real_distribution<double> u(0, 1);
    const double th = max_theta * u(rng), ph = 2 * kPi * u(rng);
    return {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
}

// Tangent-frame radiance of a texel from a real map: SH3 of the map rotated so `normal` is +Z.
inline std::vector<Sh3Radiance> real_texels() {
    std::vector<Sh3Radiance> out;
    for (const auto& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        const Sh3Radiance world = project_latlong(img.rgb.data(), img.width, img.height,
                                                  static_cast<size_t>(img.width) * 3, 2);
        for (const Vec3 n : fibonacci_directions(6)) out.push_back(rotate(world, transpose(frame_from_z(n))));
    }
    return out;
}

}  // namespace zhc::irradz_test
