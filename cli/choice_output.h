// zhc/cli/choice_output.h — the choice section (codec/audit/choice.h) as JSON and as an HTML
// table, shared by `zhc audit` and `zhc demo`. Header-only like json_output.h: the verb files are
// compiled together (cli/CMakeLists.txt, unity build).
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "codec/audit/choice.h"
#include "formats/report/html_report.h"
#include "formats/report/runtime_cost.h"

namespace zhc::cli {

// Each aggregate row's SPIR-V instruction count from a --runtime-cost table (-1 where the table
// does not list the representation); empty without a table.
inline std::vector<long long> choice_instructions(const std::vector<RepresentationResult>& aggregate,
                                                  const RuntimeCostTable* gpu) {
    std::vector<long long> out;
    if (!gpu) return out;
    for (const RepresentationResult& r : aggregate) {
        auto it = gpu->by_name.find(std::string(r.codec->name));
        out.push_back(it == gpu->by_name.end() ? -1 : it->second.spirv_instructions);
    }
    return out;
}

// The "choice" object of the audit JSON (docs/schema/audit.schema.json).
inline nlohmann::ordered_json choice_json(const ChoiceResult& r) {
    using J = nlohmann::ordered_json;
    auto candidate = [](const ChoiceCandidate* k) -> J {
        if (!k) return nullptr;
        J j{{"representation", std::string(k->codec->name)},
            {"bytes_per_probe", k->codec->size_bytes},
            {"relative_rmse", k->error},
            {"max_negative_fraction", k->max_negative_fraction},
            {"min_irradiance", k->min_irradiance}};
        j["spirv_instructions"] = k->spirv_instructions >= 0 ? J(k->spirv_instructions) : J(nullptr);
        j["encode_ns"] = k->encode_ns >= 0 ? J(k->encode_ns) : J(nullptr);
        return j;
    };
    const ChoiceConstraints& c = r.constraints;
    J j;
    j["metric"] = "relative_rmse";
    j["pooling"] = r.inputs > 1 ? "mean over inputs" : "one input";
    j["cheaper_within"] = kCheaperWithin;
    j["constraints"] = {{"nonnegative", c.nonnegative},
                        {"max_instructions", c.max_instructions >= 0 ? J(c.max_instructions) : J(nullptr)},
                        {"max_encode_us", c.max_encode_us >= 0 ? J(c.max_encode_us) : J(nullptr)}};
    j["budgets"] = J::array();
    for (const BudgetChoice& b : r.budgets) {
        J e;
        e["budget_bytes"] = b.budget;
        e["fitting"] = b.fitting;
        e["qualifying"] = b.qualifying;
        e["choice"] = candidate(r.chosen(b));
        e["runner_up"] = candidate(r.second(b));
        e["margin"] = b.runner_up >= 0 ? J(b.margin) : J(nullptr);
        e["cheaper"] = candidate(r.cheaper(b));
        e["cheaper_increase"] = b.cheaper >= 0 ? J(b.cheaper_increase) : J(nullptr);
        e["reason"] = b.reason;
        j["budgets"].push_back(e);
    }
    return j;
}

// The choice as a section of an HTML report (id "choice").
inline HtmlTable choice_html(const ChoiceResult& r) {
    HtmlTable t;
    t.id = "choice";
    t.title = "Choice";
    t.intro = choice_intro(r);
    const std::vector<std::vector<std::string>> rows = choice_table(r);
    t.columns = rows[0];
    for (std::size_t i = 1; i < rows.size(); ++i) {
        const BudgetChoice& b = r.budgets[i - 1];
        const ChoiceCandidate* c = r.chosen(b);
        const ChoiceCandidate* s = r.second(b);
        std::vector<HtmlCell> row;
        for (std::size_t k = 0; k < rows[i].size(); ++k) row.push_back({rows[i][k], 0});
        const ChoiceCandidate* k = r.cheaper(b);
        row[2].sort = c ? double(c->codec->size_bytes) : -1;
        row[3].sort = c ? c->error : -1;
        row[4].sort = c ? c->max_negative_fraction : -1;
        row[5].sort = c ? c->min_irradiance : 0;
        row[7].sort = s ? double(s->codec->size_bytes) : -1;
        row[8].sort = s ? s->error : -1;
        row[9].sort = s ? b.margin : -1;
        row[10].sort = k ? double(k->codec->size_bytes) : -1;
        row[11].sort = double(b.qualifying);
        t.rows.push_back(std::move(row));
    }
    t.notes = choice_notes(r);
    return t;
}

}  // namespace zhc::cli
