// bench_leak_candidates — visibility schemes per shading point measured side by side on the leak
// suite (tests/leak_scenes.h scenes, truth and metrics; tests/leak_candidates.h the prototypes;
// docs/leaks.md "Candidates" has the table and the choice).
//
// Per scene and candidate: leak (mean irradiance of the dark points / of the lit points), lit err
// (mean |E - E_true| / mean E_true over the lit points); per candidate: extra bytes per probe a
// runtime reads, CPU ns per sample of the prototype sampler (thread CPU time, median of interleaved
// rounds over every shading point) as a ratio against "plain" through the same sampler in the same
// run, and the summary over the suite: worst leak, configurations with the dark side under 1 % of
// the lit side, configurations where the leak exceeds plain's ("never worse than plain": 0), and
// where the lit side is neither within 10 % of plain's mean nor closer to the truth.
// Benchmarks never decide pass/fail (tests/test_leak_candidates.cpp asserts the chosen scheme).
//
// Usage: bench_leak_candidates [--points N] [--bias B] [--clearance C] [--rounds N]
//   --points: shading points per surface of a region (default 96); --bias: normal bias of the new
//   schemes as a fraction of the spacing (default 0); --clearance: relocation radius (default 0.1);
//   --rounds: timing rounds (default 5; 0: no timing)
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/leak_candidates.h"
#include "timing.h"

namespace {

using namespace zhc;
using namespace zhc::leak;

std::vector<double> time_all(const CandidateSet& cs, const std::vector<ShadingPoint>& pts, int rounds) {
    std::vector<float> p, n;
    for (const ShadingPoint& sp : pts) {
        p.insert(p.end(), {float(sp.p.x), float(sp.p.y), float(sp.p.z)});
        n.insert(n.end(), {float(sp.n.x), float(sp.n.y), float(sp.n.z)});
    }
    const int inner = std::max(1, 60000 / int(pts.size()));
    std::vector<std::vector<double>> t(cs.volumes.size());
    for (int round = 0; round < rounds; ++round)
        for (size_t which = 0; which < cs.volumes.size(); ++which) {
            const CandidateVolume& cv = cs.volumes[which];
            const bench::Timing tm = bench::time_repeats_cpu(1, [&] {
                float acc = 0;
                for (int r = 0; r < inner; ++r)
                    for (size_t i = 0; i < pts.size(); ++i) {
                        float rgb[3];
                        candidate_irradiance_f(cv, &p[3 * i], &n[3 * i], rgb);
                        acc += rgb[0];
                    }
                bench::keep(acc);
            });
            t[which].push_back(tm.median_s * 1e9 / double(inner * pts.size()));
        }
    std::vector<double> out;
    for (auto& x : t) {
        std::sort(x.begin(), x.end());
        out.push_back(x.empty() ? 0 : x[x.size() / 2]);
    }
    return out;
}

struct Summary {
    double worst_leak = 0, ratio_sum = 0;
    int under_1 = 0, above_plain = 0, lit_off = 0, rows = 0, ratio_rows = 0;
    double worst_lit_err = 0;
};

}  // namespace

int main(int argc, char** argv) {
    int per_face = 96, rounds = 5;
    CandidateOptions opt;
    std::vector<double> offsets, thicknesses;  // --walls: two rooms at these only, instead of the suite
    auto list = [](const char* text) {
        std::vector<double> v;
        for (const char* p = text; *p;) {
            char* end = nullptr;
            v.push_back(std::strtod(p, &end));
            if (end == p) return std::vector<double>{};
            p = *end == ',' ? end + 1 : end;
        }
        return v;
    };
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--points" && i + 1 < argc) per_face = std::max(1, std::atoi(argv[++i]));
        else if (a == "--bias" && i + 1 < argc) opt.bias = std::atof(argv[++i]);
        else if (a == "--clearance" && i + 1 < argc) opt.clearance = std::atof(argv[++i]);
        else if (a == "--rounds" && i + 1 < argc) rounds = std::max(0, std::atoi(argv[++i]));
        else if (a == "--reach" && i + 1 < argc) opt.reach = std::atof(argv[++i]);
        else if (a == "--max-wrong" && i + 1 < argc) opt.max_wrong = std::atof(argv[++i]);
        else if (a == "--walls" && i + 2 < argc && !(offsets = list(argv[i + 1])).empty() && !(thicknesses = list(argv[i + 2])).empty())
            i += 2;
        else {
            std::fprintf(stderr, "usage: %s [--points N] [--bias B] [--clearance C] [--reach R] [--max-wrong W] [--rounds N]\n"
                                 "          [--walls OFFSETS THICKNESSES]   (comma lists, fractions of the cell: two rooms only)\n", argv[0]);
            return 2;
        }
    }
    std::vector<LeakScene> scenes;
    if (offsets.empty()) {
        scenes = suite_scenes(per_face);
    } else {
        for (double th : thicknesses)
            for (double off : offsets) scenes.push_back(two_rooms(off, th, per_face));
    }
    std::printf("Leak suite, candidates (tests/leak_candidates.h): %d points per surface, normal bias %.3f, relocation "
                "radius %.3f of the spacing.\nPer cell: leak %% / lit err %%; '*' leak above plain's, '!' lit side neither "
                "within 10 %% of plain's mean nor closer to the truth.\n\n",
                per_face, opt.bias, opt.clearance);
    std::vector<Summary> sum;
    std::vector<std::string> lit_lines;  // mean irradiance on the lit side: truth and every candidate
    std::vector<std::string> names;
    std::vector<double> bytes;
    bool header = false;
    for (const LeakScene& ls : scenes) {
        const Baked b = bake_volumes(ls, 1, false);
        if (!b.error.empty()) {
            std::fprintf(stderr, "%s\n", b.error.c_str());
            return 1;
        }
        const auto cs = build_candidates(ls, b, opt);
        if (!cs->error.empty()) {
            std::fprintf(stderr, "%s\n", cs->error.c_str());
            return 1;
        }
        if (!header) {
            names = cs->names;
            bytes = cs->bytes;
            sum.resize(names.size());
            std::printf("%-28s %5s", "scene", "truth");
            for (const std::string& nm : names) std::printf(" | %-15s", nm.c_str());
            std::printf(" | moved, towards walls | dark pts in plane cells | plane fit: cells crossed, with a plane, pairs wrong / blocked\n");
            header = true;
        }
        const std::vector<double> truth = truth_of(ls);
        const Metrics tm = metrics(ls.points, truth, truth);
        std::vector<Metrics> ms;
        for (const CandidateVolume& cv : cs->volumes) ms.push_back(metrics(ls.points, sample_candidate(cv, ls.points), truth));
        {
            char buf[64];
            std::string line = ls.name;
            line.resize(28, ' ');
            std::snprintf(buf, sizeof buf, " %7.4f", tm.lit_mean);
            line += buf;
            for (const Metrics& m : ms) {
                std::snprintf(buf, sizeof buf, " %7.4f", m.lit_mean);
                line += buf;
            }
            lit_lines.push_back(line);
        }
        std::printf("%-28s %4.1f%%", ls.name.c_str(), 100 * tm.leak);
        for (size_t k = 0; k < ms.size(); ++k) {
            const Metrics& m = ms[k];
            const bool above = m.leak > ms[0].leak + 1e-6;
            const bool lit_ok = m.lit_error <= ms[0].lit_error + 1e-9 || std::fabs(m.lit_mean / ms[0].lit_mean - 1) <= 0.10;
            std::printf(" | %5.2f%s %5.1f%s  ", 100 * m.leak, above ? "*" : " ", 100 * m.lit_error, lit_ok ? " " : "!");
            Summary& s = sum[k];
            s.worst_leak = std::max(s.worst_leak, m.leak);
            s.worst_lit_err = std::max(s.worst_lit_err, m.lit_error);
            s.under_1 += m.leak < 0.01;
            s.above_plain += above;
            s.lit_off += !lit_ok;
            ++s.rows;
        }
        std::size_t dark = 0, dark_plane = 0;
        for (const ShadingPoint& sp : ls.points)
            if (sp.side == Side::kDark) {
                ++dark;
                dark_plane += cell_has_plane(cs->volumes[2], sp.p);
            }
        const leak::PlaneFitStats& pf = cs->plane_reloc_stats;
        std::printf(" | %3zu %3zu | %5.1f%% | %3zu %3zu %5zu / %-5zu\n", cs->moved, cs->moved_towards, dark ? 100.0 * double(dark_plane) / double(dark) : 0.0,
                    pf.blocked_cells, pf.planes, pf.wrong_pairs, pf.blocked_pairs);
        if (rounds > 0) {
            const std::vector<double> ns = time_all(*cs, ls.points, rounds);
            for (size_t k = 0; k < ns.size(); ++k)
                if (ns[0] > 0) {
                    sum[k].ratio_sum += ns[k] / ns[0];
                    ++sum[k].ratio_rows;
                }
            std::printf("%-28s %5s", "  ns per sample", "");
            for (size_t k = 0; k < ns.size(); ++k) std::printf(" | %5.0f  %5.2fx   ", ns[k], ns[0] > 0 ? ns[k] / ns[0] : 0.0);
            std::printf(" |\n");
        }
        std::fflush(stdout);
    }
    std::printf("\n%-16s %6s %9s %9s %8s %11s %8s %8s\n", "candidate", "B/prb", "worst", "leak<1%", "> plain", "lit off",
                "worst", "ns /");
    std::printf("%-16s %6s %9s %9s %8s %11s %8s %8s\n", "", "", "leak", "configs", "configs", "configs", "lit err", "plain");
    for (size_t k = 0; k < names.size(); ++k) {
        const Summary& s = sum[k];
        std::printf("%-16s %6.0f %8.2f%% %5d/%-3d %8d %11d %7.1f%% %7.2fx\n", names[k].c_str(), bytes[k],
                    100 * s.worst_leak, s.under_1, s.rows, s.above_plain, s.lit_off, 100 * s.worst_lit_err,
                    s.ratio_rows ? s.ratio_sum / s.ratio_rows : 0.0);
    }
    std::printf("\nMean irradiance on the lit side:\n%-28s %7s", "scene", "truth");
    for (const std::string& nm : names) std::printf(" %7.7s", nm.c_str());
    std::printf("\n");
    for (const std::string& l : lit_lines) std::printf("%s\n", l.c_str());
    return 0;
}
