#include "codec/audit/choice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace zhc {

namespace {

std::string fmt(double v, const char* f = "%.4g") {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

std::string count_of(std::size_t n, const char* one, const char* many) { return std::to_string(n) + " " + (n == 1 ? one : many); }

}  // namespace

std::string ChoiceConstraints::text() const {
    std::string s;
    auto add = [&](const std::string& part) {
        if (!s.empty()) s += ", ";
        s += part;
    };
    if (nonnegative) add("non-negative on every input");
    if (max_instructions >= 0) add("<= " + std::to_string(max_instructions) + " SPIR-V instructions");
    if (max_encode_us >= 0) add("encode <= " + fmt(max_encode_us) + " us per probe");
    return s.empty() ? "none" : s;
}

std::vector<std::size_t> choice_budgets(const std::vector<std::size_t>& extra) {
    std::vector<std::size_t> out = default_choice_budgets();
    for (std::size_t b : extra)
        if (b > 0) out.push_back(b);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

ChoiceResult choose_representations(const std::vector<InputAudit>& inputs,
                                    const std::vector<RepresentationResult>& aggregate,
                                    const std::vector<long long>& instructions, bool timed,
                                    const ChoiceConstraints& constraints, const std::vector<std::size_t>& budgets) {
    ChoiceResult out;
    out.constraints = constraints;
    out.inputs = inputs.size();
    for (std::size_t c = 0; c < aggregate.size(); ++c) {
        // The engine layouts are measured beside zhc's representations but are no choice: zhc's
        // runtimes and containers' readers serve zhc's own (CodecTraits::engine, codec.h).
        if (!aggregate[c].codec->traits.engine.empty()) continue;
        ChoiceCandidate k;
        k.codec = aggregate[c].codec;
        k.error = aggregate[c].metrics.relative_rmse;
        k.min_irradiance = aggregate[c].metrics.min_irradiance;
        for (const InputAudit& in : inputs)
            if (c < in.results.size()) {
                k.max_negative_fraction = std::max(k.max_negative_fraction, in.results[c].metrics.negative_fraction);
                k.min_irradiance = std::min(k.min_irradiance, in.results[c].metrics.min_irradiance);
            }
        k.encode_ns = timed ? aggregate[c].encode_ns : -1;
        k.spirv_instructions = c < instructions.size() ? instructions[c] : -1;
        k.error_not_finite = !std::isfinite(k.error);
        k.goes_negative = constraints.nonnegative && !(k.max_negative_fraction == 0);
        if (constraints.max_instructions >= 0) {
            k.cost_unknown = k.spirv_instructions < 0;
            k.over_instructions = !k.cost_unknown && k.spirv_instructions > constraints.max_instructions;
        }
        // Not measured counts as not meeting the bound (the CLI refuses the bound without timing).
        k.over_encode = constraints.max_encode_us >= 0 && !(k.encode_ns >= 0 && k.encode_ns <= constraints.max_encode_us * 1e3);
        out.candidates.push_back(k);
    }
    std::size_t smallest = std::numeric_limits<std::size_t>::max();
    for (const ChoiceCandidate& k : out.candidates) smallest = std::min(smallest, k.codec->size_bytes);
    for (std::size_t budget : budgets) {
        BudgetChoice b;
        b.budget = budget;
        std::vector<int> ranked;
        std::size_t negative = 0, over_instructions = 0, unknown = 0, over_encode = 0, not_finite = 0;
        for (std::size_t c = 0; c < out.candidates.size(); ++c) {
            const ChoiceCandidate& k = out.candidates[c];
            if (k.codec->size_bytes > budget) continue;
            ++b.fitting;
            negative += k.goes_negative ? 1 : 0;
            over_instructions += k.over_instructions ? 1 : 0;
            unknown += k.cost_unknown ? 1 : 0;
            over_encode += k.over_encode ? 1 : 0;
            not_finite += k.error_not_finite ? 1 : 0;
            if (k.qualifies()) ranked.push_back(static_cast<int>(c));
        }
        b.qualifying = ranked.size();
        // Lowest error, then fewer bytes, then table order (stable sort keeps the table order).
        std::stable_sort(ranked.begin(), ranked.end(), [&](int x, int y) {
            const ChoiceCandidate &a = out.candidates[x], &c = out.candidates[y];
            if (a.error != c.error) return a.error < c.error;
            return a.codec->size_bytes < c.codec->size_bytes;
        });
        if (!ranked.empty()) {
            b.choice = ranked[0];
            const ChoiceCandidate& k = out.candidates[b.choice];
            b.reason = (b.qualifying == 1 ? std::string("the only representation")
                                          : "lowest relative rmse of the " + std::to_string(b.qualifying) + " representations") +
                       " of at most " + std::to_string(budget) + " bytes" +
                       (constraints.any() ? " meeting the constraints" : "") + " (" + fmt(k.error) + ")";
            if (ranked.size() > 1) {
                b.runner_up = ranked[1];
                b.margin = out.candidates[b.runner_up].error - k.error;
            }
            // The cheaper one: fewest bytes below the choice's within kCheaperWithin of its error;
            // `ranked` is in error order, so the first of the fewest bytes has the lowest error.
            const double limit = k.error * (1.0 + kCheaperWithin);
            for (int c : ranked) {
                const ChoiceCandidate& x = out.candidates[c];
                if (x.codec->size_bytes >= k.codec->size_bytes || !(x.error <= limit)) continue;
                if (b.cheaper < 0 || x.codec->size_bytes < out.candidates[b.cheaper].codec->size_bytes) b.cheaper = c;
            }
            if (b.cheaper >= 0)
                b.cheaper_increase = k.error > 0 ? out.candidates[b.cheaper].error / k.error - 1.0 : 0.0;
        } else if (b.fitting == 0) {
            b.reason = "none: no audited representation stores at most " + std::to_string(budget) + " bytes per probe" +
                       (out.candidates.empty() ? std::string() : " (the smallest: " + std::to_string(smallest) + " bytes)");
        } else {
            std::string why;
            auto add = [&](std::size_t n, const std::string& what) {
                if (n == 0) return;
                if (!why.empty()) why += ", ";
                why += std::to_string(n);
                why += ' ';
                why += what;
            };
            add(negative, "go negative on some input");
            add(over_instructions, "need more than " + std::to_string(constraints.max_instructions) + " SPIR-V instructions");
            add(unknown, "have no runtime cost in the --runtime-cost table");
            add(over_encode, "encode slower than " + fmt(constraints.max_encode_us) + " us per probe");
            add(not_finite, "have a non-finite error");
            b.reason = "none: " + count_of(b.fitting, "representation fits", "representations fit") +
                       ", none meets the constraints (" + why + ")";
        }
        out.budgets.push_back(b);
    }
    return out;
}

std::vector<std::vector<std::string>> choice_table(const ChoiceResult& r) {
    std::vector<std::vector<std::string>> rows{{"budget", "choice", "bytes", "rel_rmse", "neg_frac", "min_irr", "runner_up",
                                                "bytes", "rel_rmse", "margin", "cheaper_" + fmt(100.0 * kCheaperWithin, "%.0f%%"),
                                                "qualifying"}};
    for (const BudgetChoice& b : r.budgets) {
        std::vector<std::string> row{std::to_string(b.budget)};
        const ChoiceCandidate* c = r.chosen(b);
        const ChoiceCandidate* s = r.second(b);
        if (c)
            row.insert(row.end(), {std::string(c->codec->name), std::to_string(c->codec->size_bytes), fmt(c->error, "%.4f"),
                                   fmt(c->max_negative_fraction, "%.4f"), fmt(c->min_irradiance)});
        else
            row.insert(row.end(), {"none", "-", "-", "-", "-"});
        if (s) {
            std::string margin = fmt(b.margin, "+%.4f");
            if (c->error > 0) margin += fmt(100.0 * b.margin / c->error, " (+%.1f%%)");
            row.insert(row.end(), {std::string(s->codec->name), std::to_string(s->codec->size_bytes), fmt(s->error, "%.4f"), margin});
        } else {
            row.insert(row.end(), {"-", "-", "-", "-"});
        }
        const ChoiceCandidate* k = r.cheaper(b);
        row.push_back(k ? std::string(k->codec->name) + " " + std::to_string(k->codec->size_bytes) + " B " +
                              fmt(100.0 * b.cheaper_increase, "%+.1f%%")
                        : "-");
        row.push_back(std::to_string(b.qualifying) + " of " + std::to_string(b.fitting));
        rows.push_back(std::move(row));
    }
    return rows;
}

std::string choice_intro(const ChoiceResult& r) {
    return "Per byte budget, the representation with the lowest relative irradiance rmse (rmse / mean reference "
           "irradiance" +
           std::string(r.inputs > 1 ? ", the mean over the " + std::to_string(r.inputs) + " inputs" : "") +
           ") among those storing at most that many bytes per probe and meeting the constraints (" + r.constraints.text() +
           "); ties go to fewer bytes, then table order. The runner-up is the next best; margin: its relative rmse minus "
           "the choice's (and that as a percentage of the choice's). neg_frac and min_irr: the choice's largest fraction of "
           "directions reconstructing below 0 on an input and its smallest irradiance. cheaper_" +
           fmt(100.0 * kCheaperWithin, "%.0f%%") + ": the smallest representation with fewer bytes whose relative rmse is at most " +
           fmt(100.0 * kCheaperWithin, "%.0f%%") + " above the choice's, its bytes and how much above. qualifying: "
           "representations meeting the constraints of those that fit.";
}

std::vector<EngineComparison> compare_engine_layouts(const std::vector<InputAudit>& inputs,
                                                     const std::vector<RepresentationResult>& aggregate) {
    auto negative = [&](std::size_t c) {
        double worst = 0;
        for (const InputAudit& in : inputs)
            if (c < in.results.size()) worst = std::max(worst, in.results[c].metrics.negative_fraction);
        return worst;
    };
    std::vector<EngineComparison> out;
    for (std::size_t e = 0; e < aggregate.size(); ++e) {
        const Codec* engine = aggregate[e].codec;
        if (engine->traits.engine.empty()) continue;
        EngineComparison k;
        k.engine = engine;
        k.error = aggregate[e].metrics.relative_rmse;
        k.max_negative_fraction = negative(e);
        for (std::size_t c = 0; c < aggregate.size(); ++c) {
            const Codec* z = aggregate[c].codec;
            const double err = aggregate[c].metrics.relative_rmse;
            if (!z->traits.engine.empty() || z->size_bytes > engine->size_bytes || !std::isfinite(err)) continue;
            if (k.zhc && (err > k.zhc_error || (err == k.zhc_error && z->size_bytes >= k.zhc->size_bytes))) continue;
            k.zhc = z;
            k.zhc_error = err;
            k.zhc_max_negative_fraction = negative(c);
        }
        out.push_back(k);
    }
    return out;
}

namespace {
constexpr double kEqualWithin = 1.005, kEqualBelow = 1e-5;
}  // namespace

std::vector<std::vector<std::string>> engine_table(const std::vector<EngineComparison>& rows) {
    std::vector<std::vector<std::string>> t{{"engine_layout", "engine", "bytes", "rel_rmse", "neg_frac", "zhc_best", "bytes",
                                             "rel_rmse", "neg_frac", "lower_error"}};
    for (const EngineComparison& k : rows) {
        std::vector<std::string> row{std::string(k.engine->name), std::string(k.engine->traits.engine),
                                     std::to_string(k.engine->size_bytes), fmt(k.error, "%.4f"),
                                     fmt(k.max_negative_fraction, "%.4f")};
        if (k.zhc) {
            // Within 0.5 % of each other, or both below 1e-5: equal (float rounding, the shaders' rounded
            // constants and a clamp at 0 move errors that little; against an exact reference the float
            // layouts have errors of that size).
            std::string lead = "equal";
            const bool tiny = std::max(k.error, k.zhc_error) < kEqualBelow;
            if (!tiny && k.zhc_error * kEqualWithin < k.error) lead = k.zhc_error > 0 ? "zhc " + fmt(k.error / k.zhc_error, "%.2fx") : "zhc";
            else if (!tiny && k.error * kEqualWithin < k.zhc_error) lead = k.error > 0 ? "engine " + fmt(k.zhc_error / k.error, "%.2fx") : "engine";
            row.insert(row.end(), {std::string(k.zhc->name), std::to_string(k.zhc->size_bytes), fmt(k.zhc_error, "%.4f"),
                                   fmt(k.zhc_max_negative_fraction, "%.4f"), lead});
        } else {
            row.insert(row.end(), {"none", "-", "-", "-", "-"});
        }
        t.push_back(std::move(row));
    }
    return t;
}

std::string engine_intro() {
    return "The engines' own probe layouts (docs/engine-layouts.md: each stores a probe as its engine does and evaluates "
           "irradiance as the engine's shader does) beside zhc's best representation at the same size: the lowest relative "
           "rmse among zhc's representations storing at most as many bytes per probe. lower_error: which is lower and by "
           "what factor (equal: within 0.5 %, or both below 1e-5). neg_frac: the largest fraction of directions reconstructing below 0 on an input.";
}

std::vector<std::string> choice_notes(const ChoiceResult& r) {
    std::vector<std::string> out;
    for (const BudgetChoice& b : r.budgets)
        if (b.choice < 0) out.push_back(std::to_string(b.budget) + " bytes: " + b.reason);
    return out;
}

}  // namespace zhc
