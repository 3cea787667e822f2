// Deringing speed (Sloan 2017, codec/probe/dering.h): the conservative bound (with and without the
// early out), the whole per-probe deringing search, and, as the baseline measured in the same run,
// the numerical minimum (2048 Fibonacci samples + Newton refinement) a dense-sampling deringer
// would need per evaluation. Accuracy next to time: the bound's mean gap below the true minimum.
// Plain timing main, no data files: random HDR lighting (sums of deltas, sphere and hemisphere
// lights), fixed seed.
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "codec/probe/dering.h"
#include "timing.h"

using namespace zhc;

namespace {

Vec3 random_direction(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const double z = 1 - 2 * u(rng), r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u(rng);
    return {r * std::cos(phi), r * std::sin(phi), z};
}

std::vector<Sh3Radiance> make_probes(int n) {
    std::mt19937_64 rng(2017);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Sh3Radiance> out;
    for (int i = 0; i < n; ++i) {
        Sh3Radiance sh = project_constant({0.05f, 0.05f, 0.05f});
        const auto c = [&] {
            const double s = std::pow(10.0, 3 * u(rng) - 1);
            return Rgb{float(s * (0.2 + u(rng))), float(s * (0.2 + u(rng))), float(s * (0.2 + u(rng)))};
        };
        for (int k = 0, m = 1 + int(u(rng) * 3); k < m; ++k) sh = sh + project_directional(random_direction(rng), c());
        if (u(rng) < 0.5) sh = sh + project_cone(random_direction(rng), 0.05 + u(rng), c());
        if (u(rng) < 0.3) sh = sh + project_hemisphere(random_direction(rng), c());
        out.push_back(sh);
    }
    return out;
}

// Median over 5 repeats (bench/timing.h), per item.
template <class F>
double time_ns_per(int n, F&& f) {
    return zhc::bench::time_repeats(5, f).median_s * 1e9 / n;
}

volatile double g_sink = 0;

}  // namespace

int main() {
    const int n = 20000;
    const auto probes = make_probes(n);
    std::vector<Sh3Channel> irr;
    for (const auto& sh : probes)
        for (int k = 0; k < 3; ++k) {
            Sh3Channel f = channel_of(sh, k);
            for (int i = 1; i < 9; ++i) f[size_t(i)] *= kIrradianceBandScale[i < 4 ? 1 : 2];
            irr.push_back(f);
        }
    const int m = static_cast<int>(irr.size());
    double sum = 0;
    const double t_form = time_ns_per(m, [&] {
        for (const auto& f : irr) sum += sh3_axis_form(f).linear;
    });
    std::vector<Sh3AxisForm> forms;
    for (const auto& f : irr) forms.push_back(sh3_axis_form(f));
    const double t_bound = time_ns_per(m, [&] {
        for (const auto& f : forms) sum += sh3_min_bound(f);
    });
    const double t_early = time_ns_per(m, [&] {
        for (const auto& f : forms) sum += sh3_min_bound(f, 1, 1, true);
    });
    const int mn = 2000;  // the baseline is slow: a subset
    const double t_numeric = time_ns_per(mn, [&] {
        for (int i = 0; i < mn; ++i) sum += sh3_min_numeric(irr[size_t(i)], 2048, 6).value;
    });
    double gap = 0, mean = 0;
    for (int i = 0; i < mn; ++i) {
        gap += sh3_min_numeric(irr[size_t(i)], 2048, 6).value - sh3_min_bound(forms[size_t(i)]);
        mean += kY00 * irr[size_t(i)][0];
    }
    const double t_dering = time_ns_per(n, [&] {
        for (const auto& sh : probes) sum += dering_sh3(sh).window;
    });
    int windowed = 0;
    for (const auto& sh : probes) windowed += dering_sh3(sh).windowed ? 1 : 0;
    g_sink = sum;
    std::printf("bench_dering: %d probes (%d channels) of random HDR lighting, irradiance; median of 5 runs\n", n, m);
    std::printf("%-44s %12s %10s\n", "step", "ns/channel", "vs numeric");
    std::printf("%-44s %12.1f %10.5f\n", "axis form (rotate into optimal linear frame)", t_form, t_form / t_numeric);
    std::printf("%-44s %12.1f %10.5f\n", "conservative bound (full)", t_bound, t_bound / t_numeric);
    std::printf("%-44s %12.1f %10.5f\n", "conservative bound (early out, sign only)", t_early, t_early / t_numeric);
    std::printf("%-44s %12.1f %10.5f\n", "numerical minimum (2048 samples + Newton)", t_numeric, 1.0);
    std::printf("%-44s %12.1f %10s\n", "dering_sh3 per probe (3 channels, 24 steps)", t_dering, "-");
    std::printf("windowed probes: %d / %d; mean gap (true - bound) / mean irradiance: %.4f\n", windowed, n,
                gap / mean);
    return 0;
}
