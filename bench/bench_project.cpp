// Lat-long projection throughput on the eight 1024x512 sample maps, next to a plain read pass over
// the same float buffers (the memory-bound floor), measured in the same run.
//   bench_project [REPEATS]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "codec/sh/sh.h"
#include "formats/envmap/envmap.h"
#include "timing.h"

using namespace zhc;

namespace {
// The floor: touch every float once (sum per channel), split over `threads` like the projection.
double read_pass(const std::vector<Image>& maps, int threads) {
    double total = 0;
    for (const Image& m : maps) {
        std::vector<double> part(static_cast<size_t>(threads), 0.0);
        auto work = [&](int t) {
            const size_t n = m.rgb.size(), b = n * t / threads, e = n * (t + 1) / threads;
            double s0 = 0, s1 = 0, s2 = 0;
            for (size_t i = b; i + 2 < e; i += 3) {
                s0 += m.rgb[i];
                s1 += m.rgb[i + 1];
                s2 += m.rgb[i + 2];
            }
            part[static_cast<size_t>(t)] = s0 + s1 + s2;
        };
        if (threads == 1) {
            work(0);
        } else {
            std::vector<std::thread> pool;
            for (int t = 0; t < threads; ++t) pool.emplace_back(work, t);
            for (auto& th : pool) th.join();
        }
        for (double p : part) total += p;
    }
    return total;
}
}  // namespace

int main(int argc, char** argv) {
    const int repeats = argc > 1 ? std::atoi(argv[1]) : 15;
    std::vector<Image> maps;
    for (const char* n : {"city", "courtyard", "forest", "interior", "night", "studio", "sunrise", "sunset"}) {
        auto img = read_envmap(std::string(ZHC_ENVMAP_DIR) + "/" + n + ".exr");
        if (!img) {
            std::fprintf(stderr, "%s\n", img.error().message.c_str());
            return 1;
        }
        maps.push_back(std::move(img).value());
    }
    double mpix = 0;
    for (const Image& m : maps) mpix += double(m.width) * m.height / 1e6;
    const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::printf("lat-long SH3 projection, 8 maps (%.2f Mpixel per pass), median of %d repeats [min, max]\n", mpix,
                repeats);
    std::printf("%-28s %10s %12s %10s\n", "pass", "Mpixel/s", "ms/pass", "vs floor");
    for (int threads : {1, hw}) {
        const bench::Timing floor = bench::time_repeats(repeats, [&] { bench::keep(read_pass(maps, threads)); });
        const bench::Timing proj = bench::time_repeats(repeats, [&] {
            for (const Image& m : maps)
                bench::keep(project_latlong(m.rgb.data(), m.width, m.height, m.width * 3u, threads));
        });
        std::printf("%-28s %10.1f %7.2f [%.2f, %.2f] %6s\n", ("read pass, " + std::to_string(threads) + " thread(s)").c_str(),
                    mpix / floor.median_s, floor.median_s * 1e3, floor.min_s * 1e3, floor.max_s * 1e3, "1.00x");
        std::printf("%-28s %10.1f %7.2f [%.2f, %.2f] %5.2fx\n", ("projection, " + std::to_string(threads) + " thread(s)").c_str(),
                    mpix / proj.median_s, proj.median_s * 1e3, proj.min_s * 1e3, proj.max_s * 1e3,
                    proj.median_s / floor.median_s);
        if (hw == 1) break;
    }
    return 0;
}
