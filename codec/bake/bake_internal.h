// zhc/codec/bake/bake_internal.h — helpers the bake's files share (not installed, not API).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "codec/bake/scene.h"

namespace zhc::bake_detail {

// Shadow-ray start offset: rays start a hair off the probe so a probe lying exactly on an
// occluder's surface is not blocked by that surface's own boundary test. Scale-free enough for
// scenes in metres (1e-9 m).
constexpr double kRayEpsilon = 1e-9;

// acc (27 doubles, coefficient-major RGB) += w[k] * Y(d).
void add_weighted_basis(Vec3 d, const double w[3], double acc[27]);
bool finite3(Vec3 v);
// Finite and >= 0 in every channel.
bool colour_ok(Rgb c);
// The report's name of a light: "sun 'key'", "point 'lamp'", "directional", ...
std::string effect_name(const SceneLight& l);
// The 8-bit visibility mask of grid probe (x, y, z) (codec/bake/scene.cpp), its rays aimed at
// `target`; *rays counts them.
std::uint8_t grid_visibility_mask(const OccluderBvh& bvh, const ProbeGrid& g, std::uint32_t x, std::uint32_t y,
                                  std::uint32_t z, Vec3 target, std::uint64_t* rays);

// Runs fn(lo, hi, thread) over [0, count) in blocks of `block`, on `threads` threads. Each block is
// independent, so the results do not depend on the thread count.
template <class Fn>
void parallel_blocks(std::size_t count, std::size_t block, int threads, Fn&& fn) {
    const std::size_t blocks = (count + block - 1) / block;
    const int n = std::max(1, std::min<int>(threads, static_cast<int>(std::max<std::size_t>(blocks, 1))));
    std::atomic<std::size_t> next{0};
    auto worker = [&](int t) {
        for (std::size_t b = next++; b < blocks; b = next++) fn(b * block, std::min(count, (b + 1) * block), t);
    };
    if (n == 1) {
        worker(0);
        return;
    }
    std::vector<std::thread> pool;
    for (int t = 0; t < n; ++t) pool.emplace_back(worker, t);
    for (auto& th : pool) th.join();
}

}  // namespace zhc::bake_detail
