// zhc/codec/audit/choice.h — which representation to use: per byte budget, the audited
// representation with the lowest error that fits the budget and meets the user's constraints.
//
// The error is the audit's main metric, the relative irradiance rmse (rmse over the mean
// reference irradiance), pooled across inputs as the audit's aggregate does (the mean over inputs,
// each input counting once). A representation fits a budget of B bytes when it stores at most B
// bytes per probe. Constraints (each off unless set):
//   nonnegative       negative_fraction 0 on every input (no audited direction of any probe
//                     reconstructs below 0 in any channel);
//   max_instructions  the SPIR-V instruction count of its GPU evaluation (bench_runtime --json,
//                     `--runtime-cost`) is at most N; a representation the cost table does not
//                     list does not qualify;
//   max_encode_us     its mean encode time per probe (the audit's timing) is at most N us.
// The engine layouts (CodecTraits::engine) are never candidates: the choice is among the
// representations zhc's runtimes read. Among the qualifying representations the lowest error wins; ties go to fewer bytes, then to
// the audit's order (the codec table's unless --representations lists another), so the choice is
// deterministic. The runner-up is the next one in that
// order; the margin is the runner-up's error minus the choice's.
//
// Beside each choice: its negativity (the largest fraction of audited directions where some
// channel reconstructs below 0, over the inputs, and the smallest irradiance reconstructed on any
// input), and the cheaper representation: among the qualifying ones that fit, the one with the
// fewest bytes per probe below the choice's whose error is at most kCheaperWithin (5 %) above the
// choice's (ties: lower error, then the audit's order); none when no smaller one is that close.
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "codec/audit/audit_run.h"

namespace zhc {

// How much more relative rmse (as a fraction of the choice's) a smaller representation may have to
// be named as the cheaper one: 0.05, 5 %.
inline constexpr double kCheaperWithin = 0.05;

struct ChoiceConstraints {
    bool nonnegative = false;
    long long max_instructions = -1;  // < 0: off
    double max_encode_us = -1;        // < 0: off
    bool any() const { return nonnegative || max_instructions >= 0 || max_encode_us >= 0; }
    // "none", or the constraints in words: "non-negative on every input, <= 200 SPIR-V
    // instructions, encode <= 5 us per probe".
    std::string text() const;
};

// The budgets every choice reports: 16, 28, 48, 60 and 108 bytes (the table's sizes: the 16-byte
// packed layouts, sh3_q28, linear SH, ZH3, SH3).
inline const std::vector<std::size_t>& default_choice_budgets() {
    static const std::vector<std::size_t> budgets{16, 28, 48, 60, 108};
    return budgets;
}
// The default budgets and `extra`, ascending, each once (0 is dropped).
std::vector<std::size_t> choice_budgets(const std::vector<std::size_t>& extra);

// What the choice knows of one audited representation.
struct ChoiceCandidate {
    const Codec* codec = nullptr;
    double error = 0;                   // aggregate relative rmse
    double max_negative_fraction = 0;   // the largest negative_fraction over the inputs
    double min_irradiance = 0;          // the smallest min_irradiance over the inputs
    double encode_ns = -1;              // aggregate mean encode time per probe; < 0: not measured
    long long spirv_instructions = -1;  // < 0: not known
    // The constraints it breaks (none: it qualifies).
    bool goes_negative = false, over_instructions = false, cost_unknown = false, over_encode = false,
         error_not_finite = false;
    bool qualifies() const {
        return !goes_negative && !over_instructions && !cost_unknown && !over_encode && !error_not_finite;
    }
};

struct BudgetChoice {
    std::size_t budget = 0;      // bytes per probe
    std::size_t fitting = 0;     // representations of at most `budget` bytes
    std::size_t qualifying = 0;  // of those, the ones meeting the constraints
    int choice = -1;             // index into ChoiceResult::candidates; -1: none qualifies
    int runner_up = -1;          // -1: none
    double margin = 0;           // runner-up error minus the choice's (0 without a runner-up)
    int cheaper = -1;            // fewer bytes, error within kCheaperWithin of the choice's; -1: none
    double cheaper_increase = 0; // the cheaper one's error over the choice's, minus 1 (0.015: +1.5 %)
    // One line: why the choice (or "none: ..." and why nothing qualifies).
    std::string reason;
};

struct ChoiceResult {
    ChoiceConstraints constraints;
    std::size_t inputs = 0;                   // inputs pooled
    std::vector<ChoiceCandidate> candidates;  // in the audit's (aggregate) order, engine layouts left out
    std::vector<BudgetChoice> budgets;        // ascending
    const ChoiceCandidate* chosen(const BudgetChoice& b) const { return b.choice < 0 ? nullptr : &candidates[b.choice]; }
    const ChoiceCandidate* second(const BudgetChoice& b) const {
        return b.runner_up < 0 ? nullptr : &candidates[b.runner_up];
    }
    const ChoiceCandidate* cheaper(const BudgetChoice& b) const { return b.cheaper < 0 ? nullptr : &candidates[b.cheaper]; }
};

// The choice for each budget from an audit's per-input results and aggregate (AuditRun).
// `instructions` holds each aggregate row's SPIR-V instruction count (< 0: not known); it may be
// empty when no runtime cost was given (then max_instructions disqualifies everything). encode_ns
// is taken from the aggregate when `timed`.
ChoiceResult choose_representations(const std::vector<InputAudit>& inputs,
                                    const std::vector<RepresentationResult>& aggregate,
                                    const std::vector<long long>& instructions, bool timed,
                                    const ChoiceConstraints& constraints, const std::vector<std::size_t>& budgets);

// The choice as a table for text and Markdown (row 0 is the header): budget, choice, bytes,
// rel_rmse, neg_frac and min_irr (the choice's negativity), runner_up, bytes, rel_rmse, margin
// ("+0.0184 (+16.5%)": the difference and the percentage of the choice's error), cheaper_5%
// ("sh3_q28 28 B +1.5%": the cheaper representation, its bytes and its error over the choice's; "-"
// when none), qualifying ("12 of 14": qualifying of fitting). A budget with no choice shows "none"
// and "-".
std::vector<std::vector<std::string>> choice_table(const ChoiceResult& result);
// One paragraph: the metric, the pooling, the constraints, how ties break.
std::string choice_intro(const ChoiceResult& result);
// The reasons of the budgets with no choice, one line each ("8 bytes: none: ...").
std::vector<std::string> choice_notes(const ChoiceResult& result);

// ---- the engine layouts beside zhc's representations -------------------------------------------

// One audited engine layout (CodecTraits::engine, codec/probe/engine_layouts.h) against zhc's best
// representation at its size: zhc's representation with the lowest error among the audited ones
// storing at most as many bytes per probe (the error and pooling of the choice above; ties: fewer
// bytes, then the audit's order; a non-finite error never wins).
struct EngineComparison {
    const Codec* engine = nullptr;
    double error = 0;                  // aggregate relative rmse
    double max_negative_fraction = 0;  // the largest negative_fraction over the inputs
    const Codec* zhc = nullptr;        // nullptr: no audited zhc representation is that small
    double zhc_error = 0;
    double zhc_max_negative_fraction = 0;
};
// The audited engine layouts, in the audit's order (empty when none was audited).
std::vector<EngineComparison> compare_engine_layouts(const std::vector<InputAudit>& inputs,
                                                     const std::vector<RepresentationResult>& aggregate);
// As a table (row 0 the header): engine_layout, engine, bytes, rel_rmse, neg_frac, zhc_best, bytes,
// rel_rmse, neg_frac, lower_error ("zhc 3.1x": the lower error's side and the other's error over
// it; "equal" when within 0.5 % of each other or both below 1e-5; "-" without a zhc representation).
std::vector<std::vector<std::string>> engine_table(const std::vector<EngineComparison>& rows);
// One paragraph: what the table compares.
std::string engine_intro();

}  // namespace zhc
