// Hallucinate-solve (hall_solved, hall_solved_q16) and the adaptive hallucination scale
// (hall_adaptive_q16): codec/zh3_hall.h, issue 18 items 3-4.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>

#include "codec/audit.h"
#include "codec/codec.h"
#include "codec/probe_set.h"
#include "codec/quantize.h"
#include "codec/zh3.h"
#include "codec/zh3_hall.h"
#include "tests/support.h"

namespace zhc {
namespace {

struct Rng {
    std::mt19937 gen;
    explicit Rng(unsigned seed) : gen(seed) {}
    double u() { return std::uniform_real_distribution<double>(0, 1)(gen); }
    Vec3 dir() {
        const double u1 = u();
        return test::uniform_direction(u1, u());
    }
};

// Synthetic interior: a dim coloured ambient plus 2-5 coloured lights (deltas, spheres) from
// different directions; non-negative lighting.
Sh3Radiance synthetic_interior(Rng& rng) {
    const float amb = static_cast<float>(0.02 + 0.1 * rng.u());
    Sh3Radiance sh = project_constant({amb, static_cast<float>(amb * (0.6 + 0.8 * rng.u())), static_cast<float>(amb * (0.6 + 0.8 * rng.u()))});
    const int lights = 2 + static_cast<int>(rng.u() * 4);
    for (int l = 0; l < lights; ++l) {
        const Vec3 d = rng.dir();
        const double i = 0.2 + 3.0 * rng.u();
        const double r = rng.u(), g = rng.u(), b = rng.u();
        const Rgb c{static_cast<float>(i * (0.1 + r)), static_cast<float>(i * (0.1 + g)), static_cast<float>(i * (0.1 + b))};
        Sh3Radiance add;
        if (rng.u() < 0.5) add = project_directional(d, c);
        else add = project_cone(d, 0.05 + 0.6 * rng.u(), c);
        for (int j = 0; j < 9; ++j)
            for (int k = 0; k < 3; ++k) sh[j][k] += add[j][k];
    }
    return sh;
}

// A sample map: its SH3 (exact projection, as `zhc audit`) and the audit's reference irradiance
// (flux-preserving downsample, direct integration) at given directions.
struct Map {
    std::string name;
    Sh3Radiance sh;
    LatLongImage small;
};
const std::vector<Map>& maps() {
    static const std::vector<Map> out = [] {
        std::vector<Map> v;
        for (const std::string& path : test::envmap_paths()) {
            const Image img = test::load_envmap(path);
            if (img.width == 0) continue;
            Map m;
            m.name = test::envmap_name(path);
            m.sh = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
            m.small = downsample_for_audit({img.rgb.data(), img.width, img.height}, 256, 128);
            v.push_back(std::move(m));
        }
        return v;
    }();
    return out;
}

// RMSE of a codec's runtime irradiance against a reference at directions (the audit's metric).
double codec_rmse(const Codec& c, const Sh3Radiance& sh, const std::vector<Vec3>& dirs, const std::vector<Rgb>& ref) {
    std::vector<std::uint8_t> bytes(c.size_bytes);
    c.encode(sh, {}, bytes.data(), nullptr);
    return compare_irradiance(codec_irradiance(c, bytes.data(), {}, dirs), ref).rmse;
}

TEST(HallExperiment, DISABLED_BestScaleDistribution) {
    // Which per-probe hallucination scales the solve wants (continuous grid), on rotated maps and
    // synthetic interiors; coefficient metric against SH3.
    Rng rng(7);
    std::vector<Sh3Radiance> probes;
    for (const Map& m : maps())
        for (int r = 0; r < 16; ++r) probes.push_back(rotate(m.sh, rotation_axis_angle(rng.dir(), 2 * kPi * rng.u())));
    for (int i = 0; i < 200; ++i) probes.push_back(synthetic_interior(rng));
    std::map<int, int> hist;
    const CodecOptions o;
    std::vector<double> grid;
    for (int g = 0; g <= 24; ++g) grid.push_back(0.125 * g);
    std::vector<double> sum_err(grid.size(), 0.0);
    double sum_sh2 = 0, sum_best = 0;
    for (const Sh3Radiance& p : probes) {
        const double e2 = irradiance_sq_error(p, extend_to_sh3(truncate_to_sh2(p)));
        double best = 1e300;
        int bi = 0;
        for (size_t g = 0; g < grid.size(); ++g) {
            const double e = irradiance_sq_error(p, hall_scaled_expand(hall_solve(p, grid[g], ZonalAxisMode::kLuminance, o, nullptr), grid[g], ZonalAxisMode::kLuminance, o));
            sum_err[g] += std::sqrt(e / e2);
            if (e < best) {
                best = e;
                bi = static_cast<int>(g);
            }
        }
        hist[bi]++;
        sum_sh2 += 1;
        sum_best += std::sqrt(best / e2);
    }
    for (auto [g, n] : hist) std::printf("best s %.3f: %d\n", grid[static_cast<size_t>(g)], n);
    for (size_t g = 0; g < grid.size(); ++g) std::printf("fixed s %.3f: mean ratio %.4f\n", grid[g], sum_err[g] / probes.size());
    std::printf("per-probe best: mean ratio %.4f\n", sum_best / sum_sh2);
}

}  // namespace
}  // namespace zhc
