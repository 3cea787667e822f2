// Storage benchmark: encode / decode / irradiance time per probe of the quantised
// layouts next to the float hub (sh3) measured in the same run, with the accuracy of each
// (relative irradiance RMSE vs SH3 over the same synthetic probes). No data files needed.
// Plain timing main: ./build/bench/bench_storage [probes]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Non-negative probes: a constant plus two cones of random direction and width.
std::vector<zhc::Sh3Radiance> make_probes(size_t n) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<zhc::Sh3Radiance> out(n);
    for (auto& sh : out) {
        sh = zhc::project_constant({float(0.1 + u(rng)), float(0.1 + u(rng)), float(0.1 + u(rng))});
        for (int j = 0; j < 2; ++j) {
            const double z = 1 - 2 * u(rng), r = std::sqrt(1 - z * z), phi = 2 * zhc::kPi * u(rng);
            sh = sh + zhc::project_cone({r * std::cos(phi), r * std::sin(phi), z}, 0.1 + u(rng),
                                        {float(3 * u(rng)), float(3 * u(rng)), float(3 * u(rng))});
        }
    }
    return out;
}

double irradiance_energy(const zhc::Sh3Radiance& a, const zhc::Sh3Radiance& b) {
    double s = 0;
    for (int i = 0; i < 9; ++i) {
        const double band = zhc::kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)];
        for (int k = 0; k < 3; ++k) s += std::pow(band * (double(a[i][k]) - b[i][k]), 2);
    }
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    const size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 100000;
    const auto probes = make_probes(n);
    const zhc::CodecOptions options;
    std::printf("%zu probes; times per probe; x = ratio to sh3 (float hub) in this run\n", n);
    std::printf("%-16s %6s %10s %8s %10s %8s %10s %8s %12s\n", "codec", "bytes", "encode ns", "x", "decode ns", "x",
                "irrad ns", "x", "rel RMSE");
    double base[3] = {0, 0, 0};
    // The rows (the first is the exact baseline); a probe cap for the slow encoders.
    const std::pair<const char*, size_t> rows[] = {{"sh3", n},     {"sh2", n},          {"zh3_lum", n},
                                                   {"zh3_q16", n}, {"zh3_solved_q16", 5000}, {"sh3_q28", n},
                                                   {"sh2_q", n},   {"hall_curve_q", n}};
    for (const auto& [name, cap] : rows) {
        const zhc::Codec* c = zhc::find_codec(name);
        if (!c) continue;
        const size_t m = std::min(n, cap);
        std::vector<std::uint8_t> bytes(m * c->size_bytes);
        auto t0 = Clock::now();
        for (size_t i = 0; i < m; ++i) c->encode(probes[i], options, bytes.data() + i * c->size_bytes, nullptr);
        const double enc = seconds_since(t0) / m * 1e9;
        std::vector<zhc::Sh3Radiance> decoded(m);
        t0 = Clock::now();
        for (size_t i = 0; i < m; ++i) decoded[i] = c->decode(bytes.data() + i * c->size_bytes, options);
        const double dec = seconds_since(t0) / m * 1e9;
        double sink = 0;
        t0 = Clock::now();
        for (size_t i = 0; i < m; ++i) sink += c->irradiance(bytes.data() + i * c->size_bytes, options, {0.3, 0.5, 0.81}).g;
        const double irr = seconds_since(t0) / m * 1e9;
        double num = 0, den = 0;
        for (size_t i = 0; i < m; ++i) {
            num += irradiance_energy(decoded[i], probes[i]);
            den += irradiance_energy(probes[i], zhc::Sh3Radiance{});
        }
        if (c->traits.exact && base[0] == 0) base[0] = enc, base[1] = dec, base[2] = irr;
        std::printf("%-16s %6zu %10.1f %8.2f %10.1f %8.2f %10.1f %8.2f %11.4f%%%s\n", name, c->size_bytes, enc,
                    enc / base[0], dec, dec / base[1], irr, irr / base[2], 100 * std::sqrt(num / den),
                    sink == 12345.678 ? "!" : "");
    }
    return 0;
}
