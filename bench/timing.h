// Tiny timing helpers for the plain-main benchmarks: medians over repeats with the spread.
#pragma once

#include <algorithm>
#include <chrono>
#include <ctime>
#include <vector>

namespace zhc::bench {

struct Timing {
    double median_s = 0, min_s = 0, max_s = 0;
};

// Runs fn() `repeats` times and returns median/min/max wall time in seconds.
template <class F>
Timing time_repeats(int repeats, F&& fn) {
    std::vector<double> t;
    for (int i = 0; i < repeats; ++i) {
        const auto a = std::chrono::steady_clock::now();
        fn();
        t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
    }
    std::sort(t.begin(), t.end());
    return {t[t.size() / 2], t.front(), t.back()};
}

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

// Keeps the optimiser from discarding a computed value.
template <class T>
inline void keep(const T& value) {
    asm volatile("" : : "g"(&value) : "memory");
}

}  // namespace zhc::bench
