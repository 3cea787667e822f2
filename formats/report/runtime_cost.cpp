#include "formats/report/runtime_cost.h"

#include <nlohmann/json.hpp>

#include <cmath>

#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"

namespace zhc {

Result<RuntimeCostTable> read_runtime_cost(const std::string& path) {
    using nlohmann::json;
    auto bytes = read_file_bytes(path, std::uint64_t(16) << 20);
    if (!bytes) return bytes.error();
    auto bad = [&](const std::string& what) { return make_error(ErrorCode::kBadFormat, path + ": " + what); };
    if (Status depth = check_json_depth(*bytes, path); !depth) return depth.error();
    json doc = json::parse(bytes->begin(), bytes->end(), nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded() || !doc.is_object()) return bad("not a JSON object (expected bench_runtime --json output)");
    if (!doc.contains("rows") || !doc["rows"].is_array()) return bad("no \"rows\" array");
    RuntimeCostTable table;
    if (doc.contains("device") && doc["device"].is_string()) table.device = doc["device"].get<std::string>();
    const json& rows = doc["rows"];
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const json& r = rows[i];
        const std::string where = "rows[" + std::to_string(i) + "]";
        if (!r.is_object() || !r.contains("encoding") || !r["encoding"].is_string())
            return bad(where + ".encoding: missing or not a string");
        auto number = [&](const char* key, double* out) -> bool {
            if (!r.contains(key) || !r[key].is_number()) return false;
            *out = r[key].get<double>();
            return std::isfinite(*out) && *out >= 0;
        };
        double instructions = 0;
        RuntimeCost c;
        if (!number("spirv_instructions", &instructions) || instructions > 1e9)
            return bad(where + ".spirv_instructions: missing or not a count");
        if (!number("ns_per_eval", &c.ns_per_eval)) return bad(where + ".ns_per_eval: missing or not a time");
        if (!number("ratio_to_sh3", &c.ratio_to_sh3)) return bad(where + ".ratio_to_sh3: missing or not a ratio");
        c.spirv_instructions = static_cast<int>(instructions);
        table.by_name[r["encoding"].get<std::string>()] = c;
    }
    return table;
}

}  // namespace zhc
