// Helpers shared by the deringing tests (test_dering_bound, test_dering): the irradiance of one channel
// and a generator of random lightings (deltas, spheres, hemispheres, mixtures, raw coefficients).
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "codec/probe/codec.h"
#include "codec/probe/dering.h"
#include "support.h"

namespace zhc::dering_test {

using test::fibonacci_directions;

inline Sh3Channel irradiance_channel(const Sh3Radiance& radiance, int k) {
    Sh3Channel f = channel_of(radiance, k);
    for (int i = 1; i < 9; ++i) f[static_cast<size_t>(i)] *= kIrradianceBandScale[i < 4 ? 1 : 2];
    return f;
}

// ---- random lighting --------------------------------------------------------------------------

struct Generator {
    std::mt19937_64 rng;
    std::uniform_real_distribution<double> u{0.0, 1.0};
    explicit Generator(std::uint64_t seed) : rng(seed) {}
    double uni() { return u(rng); }
    Vec3 dir() {  // sequenced: argument evaluation order differs between compilers
        const double u1 = uni();
        return test::uniform_direction(u1, uni());
    }
    Rgb colour(double scale) {
        return {static_cast<float>(scale * (0.2 + uni())), static_cast<float>(scale * (0.2 + uni())),
                static_cast<float>(scale * (0.2 + uni()))};
    }
    // Intensities spread over decades (HDR).
    double intensity() { return std::pow(10.0, 3.0 * uni() - 1.0); }

    Sh3Radiance deltas(int n) {
        Sh3Radiance sh;
        for (int i = 0; i < n; ++i) sh = sh + project_directional(dir(), colour(intensity()));
        return sh;
    }
    Sh3Radiance spheres(int n) {
        Sh3Radiance sh;
        for (int i = 0; i < n; ++i) sh = sh + project_cone(dir(), 0.02 + 1.5 * uni(), colour(intensity()));
        return sh;
    }
    Sh3Radiance hemispheres(int n) {
        Sh3Radiance sh;
        for (int i = 0; i < n; ++i) sh = sh + project_hemisphere(dir(), colour(intensity()));
        return sh;
    }
    Sh3Radiance mixed() {
        Sh3Radiance sh = deltas(static_cast<int>(uni() * 3)) + spheres(static_cast<int>(uni() * 3)) +
                         hemispheres(static_cast<int>(uni() * 2));
        if (uni() < 0.3) sh = sh + project_constant(colour(0.1 * intensity()));
        return sh;
    }
    // Not from a non-negative function: independent Gaussian coefficients, random band weights.
    Sh3Channel random_coefficients() {
        std::normal_distribution<double> n(0.0, 1.0);
        Sh3Channel f{};
        const double w1 = std::pow(10.0, 2.0 * uni() - 1.0), w2 = std::pow(10.0, 2.0 * uni() - 1.0);
        for (int i = 0; i < 9; ++i) f[static_cast<size_t>(i)] = n(rng) * (i == 0 ? 1.0 : (i < 4 ? w1 : w2));
        // Structured special cases: no L1 (axis undefined), no |m| = 1 pair, only the |m| = 1 pair.
        const double r = uni();
        if (r < 0.05) f[1] = f[2] = f[3] = 0;
        else if (r < 0.10) f[5] = f[7] = 0;
        else if (r < 0.15) f[4] = f[6] = f[8] = 0;
        return f;
    }
    // One of the input families, as a single SH3 channel: lighting families give their irradiance
    // (or, every other time, their radiance) in a random channel.
    Sh3Channel any(int index) {
        const int family = index % 5;
        Sh3Radiance sh;
        switch (family) {
            case 0: sh = deltas(1 + static_cast<int>(uni() * 8)); break;
            case 1: sh = spheres(1 + static_cast<int>(uni() * 4)); break;
            case 2: sh = hemispheres(1 + static_cast<int>(uni() * 3)); break;
            case 3: sh = mixed(); break;
            default: return random_coefficients();
        }
        const int k = static_cast<int>(uni() * 3);
        return (index / 5) % 2 ? channel_of(sh, k) : irradiance_channel(sh, k);
    }
};

}  // namespace zhc::dering_test
