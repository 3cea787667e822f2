// Tiny timing helpers for the plain-main benchmarks: medians over repeats with the spread; the
// process's resident memory from /proc.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include <time.h>

namespace zhc::bench {

// A "Vm...:" line of /proc/self/status in bytes (VmRSS: the resident set, VmHWM: its high-water
// mark); -1 where /proc does not tell.
inline double proc_status_bytes(const char* key) {
    std::ifstream in("/proc/self/status");
    std::string line;
    const std::string k = key;
    while (std::getline(in, line))
        if (line.rfind(k, 0) == 0) return std::atof(line.c_str() + k.size()) * 1024.0;
    return -1;
}
// Resets VmHWM to the current resident set (Linux >= 4.0: 5 to /proc/self/clear_refs).
inline bool reset_peak() {
    std::ofstream out("/proc/self/clear_refs");
    out << "5";
    out.flush();
    return bool(out);
}

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

// The same in CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID): for single-threaded work on a
// shared machine, where wall time also counts the time other processes held the core.
template <class F>
Timing time_repeats_cpu(int repeats, F&& fn) {
    auto now = [] {
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
    };
    std::vector<double> t;
    for (int i = 0; i < repeats; ++i) {
        const double a = now();
        fn();
        t.push_back(now() - a);
    }
    std::sort(t.begin(), t.end());
    return {t[t.size() / 2], t.front(), t.back()};
}

// Keeps the optimiser from discarding a computed value.
template <class T>
inline void keep(const T& value) {
    asm volatile("" : : "g"(&value) : "memory");
}

// Closes the JSON document written to `out` (the file `path`: an array in an object) and says where
// it went; false, after a message on stderr, when the stream failed.
inline bool finish_json(std::ostream& out, const std::string& path) {
    out << "  ]\n}\n";
    if (!out) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        return false;
    }
    std::printf("\nwrote %s\n", path.c_str());
    return true;
}

}  // namespace zhc::bench
