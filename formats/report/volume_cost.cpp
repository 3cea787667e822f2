#include "formats/report/volume_cost.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"

namespace zhc {
namespace {

using nlohmann::json;

// A SAX pass that only tracks where it is (rows[3].demo.mean) so that text which is not JSON (a NaN
// or Infinity literal, a cut file) is reported at the field being read when the parser stopped.
class WhereParser : public nlohmann::json_sax<json> {
public:
    std::string where;  // set by parse_error
    std::size_t byte = 0;

    bool null() override { return value(); }
    bool boolean(bool) override { return value(); }
    bool number_integer(number_integer_t) override { return value(); }
    bool number_unsigned(number_unsigned_t) override { return value(); }
    bool number_float(number_float_t, const string_t&) override { return value(); }
    bool string(string_t&) override { return value(); }
    bool binary(binary_t&) override { return value(); }
    bool start_object(std::size_t) override {
        value();
        stack_.push_back({false, 0, false, {}});
        return true;
    }
    bool key(string_t& k) override {
        if (!stack_.empty()) stack_.back().key = k;
        return true;
    }
    bool end_object() override { return pop(); }
    bool start_array(std::size_t) override {
        value();
        stack_.push_back({true, 0, false, {}});
        return true;
    }
    bool end_array() override { return pop(); }
    bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception&) override {
        byte = position;
        for (const Frame& f : stack_) {
            if (f.array) {  // the element being read
                where.push_back('[');
                where.append(std::to_string(f.count));
                where.push_back(']');
            } else if (!f.key.empty()) {
                if (!where.empty()) where.push_back('.');
                where.append(f.key);
            }
        }
        return false;
    }

private:
    struct Frame {
        bool array;
        std::size_t count;  // array: the index of the element being read
        bool started;       // array: some element has started
        std::string key;    // object: the last key
    };
    std::vector<Frame> stack_;
    // A value starts: in an array it is the next element. count is the index of the element being
    // read once it has started, so it advances when the following one starts.
    bool value() {
        if (!stack_.empty() && stack_.back().array) {
            if (stack_.back().started) ++stack_.back().count;
            stack_.back().started = true;
        }
        return true;
    }
    bool pop() {
        if (!stack_.empty()) stack_.pop_back();
        return true;
    }
};

}  // namespace

Result<VolumeCostTable> read_volume_cost(const std::string& path) {
    auto bytes = read_file_bytes(path, std::uint64_t(16) << 20);
    if (!bytes) return bytes.error();
    auto bad = [&](const std::string& what) { return make_error(ErrorCode::kBadFormat, path + ": " + what); };
    if (Status depth = check_json_depth(*bytes, path); !depth) return depth.error();
    json doc = json::parse(bytes->begin(), bytes->end(), nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded()) {
        WhereParser w;
        json::sax_parse(bytes->begin(), bytes->end(), &w, nlohmann::detail::input_format_t::json, /*strict=*/true);
        return bad((w.where.empty() ? std::string() : w.where + ": ") + "not valid JSON at byte " + std::to_string(w.byte) +
                   " (NaN and Infinity are not JSON numbers; expected bench_volume --json output)");
    }
    if (!doc.is_object()) return bad("not a JSON object (expected bench_volume --json output)");
    VolumeCostTable table;
    if (!doc.contains("device") || !doc["device"].is_string()) return bad("device: missing or not a string");
    table.device = doc["device"].get<std::string>();
    if (doc.contains("grids")) {
        const json& g = doc["grids"];
        if (!g.is_array() || g.size() != 2 || !g[0].is_string() || !g[1].is_string())
            return bad("grids: not an array of two names");
        table.gltf_grid = g[1].get<std::string>();
    }
    if (!doc.contains("rows") || !doc["rows"].is_array()) return bad("rows: missing or not an array");
    const json& rows = doc["rows"];
    if (rows.empty()) return bad("rows: empty");
    if (rows.size() > 10000) return bad("rows: more than 10000 layouts");
    std::set<std::string> names;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const json& r = rows[i];
        const std::string where = "rows[" + std::to_string(i) + "]";
        if (!r.is_object()) return bad(where + ": not an object");
        VolumeLayoutCost c;
        auto text = [&](const json& o, const std::string& at, const char* key, bool required, std::string* out) -> Status {
            if (!o.contains(key)) {
                if (required) return bad(at + "." + key + ": missing");
                return Ok{};
            }
            if (!o[key].is_string()) return bad(at + "." + key + ": not a string");
            *out = o[key].get<std::string>();
            return Ok{};
        };
        // A finite number in [lo, hi], or exactly -1 where `unmeasured` allows it.
        auto number = [&](const json& o, const std::string& at, const char* key, double lo, double hi, bool unmeasured,
                          bool integer, double* out) -> Status {
            const std::string field = at + "." + key;
            if (!o.contains(key)) return bad(field + ": missing");
            if (!o[key].is_number()) return bad(field + ": not a number");
            const double v = o[key].get<double>();
            if (!std::isfinite(v)) return bad(field + ": not finite");
            if (unmeasured && v == -1) {
                *out = v;
                return Ok{};
            }
            if (v < lo || v > hi) return bad(field + ": " + std::to_string(v) + " out of range");
            if (integer && v != std::floor(v)) return bad(field + ": not an integer");
            *out = v;
            return Ok{};
        };
        if (Status s = text(r, where, "layout", true, &c.layout); !s) return s.error();
        if (c.layout.empty()) return bad(where + ".layout: empty");
        if (!names.insert(c.layout).second) return bad(where + ".layout: '" + c.layout + "' listed twice");
        if (Status s = text(r, where, "kind", false, &c.kind); !s) return s.error();
        if (Status s = text(r, where, "textures", false, &c.textures); !s) return s.error();
        double fetches = 0, spirv = 0;
        if (Status s = number(r, where, "bytes_per_probe", 1e-9, 1e6, false, false, &c.bytes_per_probe); !s) return s.error();
        if (Status s = number(r, where, "fetches", 0, 1e6, false, true, &fetches); !s) return s.error();
        if (Status s = number(r, where, "spirv_instructions_minus_skeleton", 0, 1e9, true, true, &spirv); !s) return s.error();
        if (Status s = number(r, where, "lavapipe_ns_per_sample", 0, 1e15, true, false, &c.lavapipe_ns); !s) return s.error();
        c.fetches = static_cast<int>(fetches);
        c.spirv_instructions = static_cast<int>(spirv);
        for (const char* grid : {"demo", "gltf"}) {
            const std::string at = where + "." + grid;
            if (!r.contains(grid) || !r[grid].is_object()) return bad(at + ": missing or not an object");
            VolumeGridError& e = std::string(grid) == "demo" ? c.demo : c.gltf;
            const double big = std::numeric_limits<double>::max();
            if (Status s = number(r[grid], at, "mean", 0, big, false, false, &e.mean); !s) return s.error();
            if (Status s = number(r[grid], at, "p95", 0, big, false, false, &e.p95); !s) return s.error();
            if (Status s = number(r[grid], at, "max", 0, big, false, false, &e.max); !s) return s.error();
        }
        table.rows.push_back(std::move(c));
    }
    return table;
}

double volume_ratio_to_sh3(const VolumeCostTable& table, const VolumeLayoutCost& row) {
    for (const VolumeLayoutCost& r : table.rows)
        if (r.layout == "sh3") return r.lavapipe_ns > 0 && row.lavapipe_ns >= 0 ? row.lavapipe_ns / r.lavapipe_ns : -1;
    return -1;
}

std::vector<std::size_t> volume_best_per_byte(const VolumeCostTable& table) {
    std::vector<std::size_t> order(table.rows.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    // Unmeasured time (-1) ranks after any measured time in a tie.
    auto ns = [&](std::size_t i) {
        const double t = table.rows[i].lavapipe_ns;
        return t < 0 ? std::numeric_limits<double>::infinity() : t;
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const VolumeLayoutCost &x = table.rows[a], &y = table.rows[b];
        if (x.bytes_per_probe != y.bytes_per_probe) return x.bytes_per_probe < y.bytes_per_probe;
        if (x.worst_mean() != y.worst_mean()) return x.worst_mean() < y.worst_mean();
        return ns(a) < ns(b);
    });
    std::vector<std::size_t> best;
    for (std::size_t i : order)
        if (best.empty() || table.rows[i].worst_mean() < table.rows[best.back()].worst_mean()) best.push_back(i);
    return best;
}

}  // namespace zhc
