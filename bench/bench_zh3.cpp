// ZH3 encode cost (every zh3 codec-table entry, the hallucinated and solved 16-byte entries, plus
// sh2/sh3 for scale), ratios against zh3_lum
// (the closed-form fit) measured in the same run, and the error-vs-iterations curve of the axis
// solves. Single-threaded.
//   bench_zh3 [REPEATS]
// Probes: the eight sample maps under 64 random rotations each (512 probes) plus 512 random
// non-negative lightings (sums of deltas, sphere lights and hemispheres).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/zh3.h"
#include "formats/envmap/envmap.h"
#include "timing.h"

using namespace zhc;

namespace {

// Thread CPU time of fn() (seconds), minimum over `repeats`: robust to other processes sharing the
// machine (preemption does not count), unlike wall time.
template <class F>
double cpu_time_min(int repeats, F&& fn) {
    double best = 1e300;
    for (int i = 0; i < repeats; ++i) {
        timespec a{}, b{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &a);
        fn();
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &b);
        best = std::min(best, double(b.tv_sec - a.tv_sec) + 1e-9 * double(b.tv_nsec - a.tv_nsec));
    }
    return best;
}

struct Rng {
    std::mt19937 gen{1234};
    double u() { return std::uniform_real_distribution<double>(0, 1)(gen); }
    Vec3 dir() {
        const double z = 1 - 2 * u(), r = std::sqrt(std::max(0.0, 1 - z * z)), p = 2 * kPi * u();
        return {r * std::cos(p), r * std::sin(p), z};
    }
    Rgb colour() { return {float(0.1 + u()), float(0.1 + u()), float(0.1 + u())}; }
};

std::vector<Sh3Radiance> make_probes(std::vector<std::string>* labels) {
    Rng rng;
    std::vector<Sh3Radiance> probes;
    for (const char* n : {"city", "courtyard", "forest", "interior", "night", "studio", "sunrise", "sunset"}) {
        auto img = read_envmap(std::string(ZHC_ENVMAP_DIR) + "/" + n + ".exr");
        if (!img) {
            std::fprintf(stderr, "bench_zh3: %s\n", img.error().message.c_str());
            continue;
        }
        const Sh3Radiance sh = project_latlong(img->rgb.data(), img->width, img->height,
                                               static_cast<size_t>(img->width) * 3, 2);
        for (int r = 0; r < 64; ++r) {
            probes.push_back(rotate(sh, rotation_axis_angle(rng.dir(), 2 * kPi * rng.u())));
            labels->push_back("map");
        }
    }
    for (int i = 0; i < 512; ++i) {
        Sh3Radiance sh = project_constant({float(0.05 * rng.u()), float(0.05 * rng.u()), float(0.05 * rng.u())});
        const int n = 1 + static_cast<int>(rng.u() * 4);
        for (int j = 0; j < n; ++j) {
            const double kind = rng.u();
            if (kind < 0.35)
                sh = sh + project_directional(rng.dir(), rng.colour());
            else if (kind < 0.8)
                sh = sh + project_cone(rng.dir(), 0.05 + 1.5 * rng.u(), rng.colour());
            else
                sh = sh + project_hemisphere(rng.dir(), rng.colour());
        }
        probes.push_back(sh);
        labels->push_back("random");
    }
    return probes;
}

ZonalAxisMode mode_of(std::string_view name) {
    return name.find("channel") != std::string_view::npos ? ZonalAxisMode::kPerChannel : ZonalAxisMode::kLuminance;
}

// Mean Eq. 11 error (irradiance L1+L2 squared error against SH3) of a codec over the probes.
double mean_eq11(const Codec& c, const std::vector<Sh3Radiance>& probes, const CodecOptions& o) {
    std::vector<std::uint8_t> bytes(c.size_bytes);
    double s = 0;
    for (const Sh3Radiance& p : probes) {
        c.encode(p, o, bytes.data(), nullptr);
        const Sh3Radiance d = c.decode(bytes.data(), o);
        // the L2 band as decoded (fit or hallucinated), not re-fitted: squared irradiance error
        double e = 0;
        for (int i = 1; i < 9; ++i) {
            const double sc = i < 4 ? 2.0 / 3.0 : 0.25;
            for (int k = 0; k < 3; ++k) e += sc * sc * (double(d[i][k]) - p[i][k]) * (double(d[i][k]) - p[i][k]);
        }
        s += e;
    }
    return s / probes.size();
}

double encode_ns(const Codec& c, const std::vector<Sh3Radiance>& probes, const CodecOptions& o, int repeats,
                 double* iterations = nullptr) {
    std::vector<std::uint8_t> bytes(c.size_bytes * probes.size());
    long long its = 0;
    const double t = cpu_time_min(repeats, [&] {
        its = 0;
        for (size_t i = 0; i < probes.size(); ++i) {
            EncodeStats st;
            c.encode(probes[i], o, bytes.data() + i * c.size_bytes, &st);
            its += st.solver_iterations;
        }
        bench::keep(bytes);
    });
    if (iterations) *iterations = double(its) / probes.size();
    return t * 1e9 / probes.size();
}

}  // namespace

int main(int argc, char** argv) {
    const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 9;
    std::vector<std::string> labels;
    const std::vector<Sh3Radiance> probes = make_probes(&labels);
    const CodecOptions defaults;
    std::printf("ZH3 encode, %zu probes (8 maps x 64 rotations + 512 random lightings), single thread,\nencode time = thread CPU time, minimum of %d repeats (other jobs share this machine)\n\n",
                probes.size(), repeats);

    std::vector<const Codec*> rows = {find_codec("sh3"), find_codec("sh2")};
    for (const Codec& c : zh3_codecs()) rows.push_back(&c);
    // The hallucinated and solved 16-byte entries (codec/probe/zh3_hall_solve.cpp, quantize.cpp): their
    // solves are the costliest encodes in the table.
    for (const char* name : {"hall_curve", "hall_curve_q", "hall_solved", "hall_solved_q16", "hall_adaptive_q16", "zh3_solved_q16"})
        rows.push_back(find_codec(name));
    const Codec* lum = find_codec("zh3_lum");
    const double lum_ns = encode_ns(*lum, probes, defaults, repeats);
    const double lum_err = mean_eq11(*lum, probes, defaults);
    std::printf("%-20s %6s %12s %10s %14s %10s %8s\n", "representation", "bytes", "encode ns", "x zh3_lum",
                "mean sq. err", "x zh3_lum", "BFGS its");
    for (const Codec* c : rows) {
        if (!c) continue;
        double its = 0;
        const double ns = c == lum ? lum_ns : encode_ns(*c, probes, defaults, repeats, &its);
        const double err = mean_eq11(*c, probes, defaults);
        std::printf("%-20.*s %6zu %12.1f %10.2f %14.6g %10.3f %8.1f\n", int(c->name.size()), c->name.data(), c->size_bytes,
                    ns, ns / lum_ns, err, err / lum_err, its);
    }
    std::printf("\n(mean sq. err = irradiance-SH squared coefficient error against SH3, L1 + L2, per probe; for the\n"
                " stored-zonal entries that is Eq. 11)\n\n");

    for (const char* name : {"zh3_solved_lum", "zh3_solved_channel"}) {
        const Codec& c = *find_codec(name);
        CodecOptions converged = defaults;
        converged.solver_iterations = 500;
        converged.solver_tolerance = 0.0;
        const double conv_err = mean_eq11(c, probes, converged);
        const double fit_err = mean_eq11(*find_codec(mode_of(name) == ZonalAxisMode::kLuminance ? "zh3_lum" : "zh3_channel"),
                                         probes, defaults);
        std::printf("%s: error vs iterations (tolerance %g; converged = 500 iterations, tolerance 0: %.6g; fit %.6g)\n",
                    name, defaults.solver_tolerance, conv_err, fit_err);
        std::printf("%10s %12s %10s %16s %12s\n", "max iters", "encode ns", "x zh3_lum", "err / converged", "mean iters");
        for (int it : {0, 1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 64}) {
            CodecOptions o = defaults;
            o.solver_iterations = it;
            double its = 0;
            const double ns = encode_ns(c, probes, o, repeats, &its);
            const double err = mean_eq11(c, probes, o);
            std::printf("%10d %12.1f %10.2f %16.6f %12.2f\n", it, ns, ns / lum_ns, err / conv_err, its);
        }
        if (std::strcmp(name, "zh3_solved_lum") == 0) {
            const double ns = encode_ns(c, probes, defaults, repeats);
            const double err = mean_eq11(c, probes, defaults);
            std::printf("target zh3_solved_lum <= 4000 ns/probe at converged error: %.1f ns at defaults (%d iterations, "
                        "tolerance %g), error %.6f x converged -> %s\n",
                        ns, defaults.solver_iterations, defaults.solver_tolerance, err / conv_err,
                        ns <= 4000.0 && err <= conv_err * (1 + 1e-4) ? "MET" : "NOT MET");
        }
        std::printf("\n");
    }
    return 0;
}
