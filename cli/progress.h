// zhc/cli/progress.h — progress of the long verbs on stderr (never stdout), one look for all:
//   zhc lightmap encode: 37% (1536/4096 rows) 12.3 s
// On a terminal (isatty(stderr)) by default, rewritten in place with \r; elsewhere only with
// --progress, one line per 10 %. --quiet turns it off. Output files and stdout never depend on it.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdint>
#include <string>

namespace zhc::cli {

struct ProgressFlags {
    bool force = false;  // --progress
    bool quiet = false;  // --quiet
};
// Adds --progress and --quiet to a verb.
void add_progress_flags(CLI::App* verb, ProgressFlags& flags);

class Progress {
public:
    // label: "zhc lightmap encode"; unit: "rows", "files", ...
    Progress(std::string label, std::string unit, const ProgressFlags& flags);
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;
    ~Progress();
    bool enabled() const { return enabled_; }
    void update(std::uint64_t done, std::uint64_t total);
    // Ends the line on a terminal (also done by the destructor).
    void finish();

private:
    void print(std::uint64_t done, std::uint64_t total, bool newline);
    std::string label_, unit_;
    bool enabled_ = false, tty_ = false, open_line_ = false;
    int last_decile_ = 0;  // non-terminal: the first line at 10 %
    std::chrono::steady_clock::time_point t0_, last_print_;
};

}  // namespace zhc::cli
