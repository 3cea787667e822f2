// zhc/cli/progress.cpp — see progress.h.
#include "progress.h"

#include <unistd.h>

#include <cstdio>

namespace zhc::cli {

void add_progress_flags(CLI::App* verb, ProgressFlags& flags) {
    verb->add_flag("--progress", flags.force, "progress on stderr even when it is not a terminal (one line per 10 %)");
    verb->add_flag("--quiet", flags.quiet, "no progress on stderr");
}

Progress::Progress(std::string label, std::string unit, const ProgressFlags& flags)
    : label_(std::move(label)), unit_(std::move(unit)) {
    tty_ = ::isatty(STDERR_FILENO) == 1;
    enabled_ = !flags.quiet && (flags.force || tty_);
    t0_ = last_print_ = std::chrono::steady_clock::now();
}

Progress::~Progress() { finish(); }

void Progress::print(std::uint64_t done, std::uint64_t total, bool newline) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    const int pct = total > 0 ? static_cast<int>(done * 100 / total) : 100;
    std::fprintf(stderr, "%s%s: %d%% (%llu/%llu %s) %.1f s%s", tty_ ? "\r" : "", label_.c_str(), pct,
                 static_cast<unsigned long long>(done), static_cast<unsigned long long>(total), unit_.c_str(), s,
                 newline ? "\n" : "\x1b[K");
    std::fflush(stderr);
}

void Progress::update(std::uint64_t done, std::uint64_t total) {
    if (!enabled_) return;
    done = std::min(done, total);
    const auto now = std::chrono::steady_clock::now();
    if (tty_) {
        // In place, at most 10 times a second (and always at the end).
        if (done < total && now - last_print_ < std::chrono::milliseconds(100)) return;
        last_print_ = now;
        print(done, total, false);
        open_line_ = true;
        if (done == total) finish();
        return;
    }
    const int decile = total > 0 ? static_cast<int>(done * 10 / total) : 10;
    if (decile <= last_decile_) return;
    last_decile_ = decile;
    print(done, total, true);
}

void Progress::finish() {
    if (open_line_) {
        std::fputc('\n', stderr);
        std::fflush(stderr);
        open_line_ = false;
    }
}

}  // namespace zhc::cli
