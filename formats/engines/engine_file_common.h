// zhc/formats/engines/engine_file_common.h — what the grid formats of formats/engines/ share: an
// engine's axes as a signed permutation, the shortest round-trip text of a number, and the strict
// readers of the JSON bounds they carry in key/value data or header attributes. Internal to
// formats/engines (not installed).
#pragma once

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "codec/probe/engine_layouts.h"
#include "codec/status.h"
#include "formats/io/json_depth.h"

namespace zhc::engine_file_detail {

// The key / attribute holding zhc's grid as JSON {"origin", "spacing", "counts"} in the engine's
// axes, and the one naming a three.js atlas's grid (whose presence also tells a three.js KTX2 from
// a Bevy volume).
inline constexpr const char* kVolumeKey = "zhc.volume";
inline constexpr const char* kThreeKey = "threejs.LightProbeGrid";

// Engine axis r is zhc axis col[r] times sign[r] (EngineLayoutInfo::axes is a signed permutation).
struct AxisMap {
    std::array<int, 3> col{};
    std::array<int, 3> sign{};
};
inline AxisMap axis_map(std::string_view codec_name) {
    const Mat3& a = find_engine_layout(codec_name)->axes;
    AxisMap m;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (a(r, c) != 0) {
                m.col[static_cast<size_t>(r)] = c;
                m.sign[static_cast<size_t>(r)] = a(r, c) > 0 ? 1 : -1;
            }
    return m;
}

// The shortest text that reads back to v.
inline std::string num(double v) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}
// "[a,b,c]" (appended piecewise: g++ 12 -O3 warns of a false overlap in "[" + std::string).
template <class T>
std::string vec_json(const std::array<T, 3>& v) {
    std::string out = "[";
    for (size_t i = 0; i < 3; ++i) {
        if (i) out += ',';
        if constexpr (std::is_floating_point_v<T>) {
            out += num(double(v[i]));
        } else {
            out += std::to_string(v[i]);
        }
    }
    out += ']';
    return out;
}

inline Error bad(ErrorCode code, const std::string& name, const std::string& what) { return make_error(code, name + ": " + what); }

// j[key] as 3 finite numbers / 3 integers in 1..65535; kBadFormat (kInvalidValue: not finite) naming
// `where` and the key otherwise.
inline Result<std::array<double, 3>> json_vec3(const nlohmann::json& j, const char* key, const std::string& where) {
    const auto it = j.find(key);
    const std::string msg = std::string("\"") + key + "\" must be an array of 3 numbers";
    if (it == j.end() || !it->is_array() || it->size() != 3) return bad(ErrorCode::kBadFormat, where, msg);
    std::array<double, 3> v{};
    for (size_t i = 0; i < 3; ++i) {
        if (!(*it)[i].is_number()) return bad(ErrorCode::kBadFormat, where, msg);
        v[i] = (*it)[i].get<double>();
        if (!std::isfinite(v[i])) return bad(ErrorCode::kInvalidValue, where, std::string("\"") + key + "\" is not finite");
    }
    return v;
}
inline Result<std::array<std::uint32_t, 3>> json_counts(const nlohmann::json& j, const char* key, const std::string& where) {
    const auto it = j.find(key);
    const std::string msg = std::string("\"") + key + "\" must be 3 integers in 1..65535";
    if (it == j.end() || !it->is_array() || it->size() != 3) return bad(ErrorCode::kBadFormat, where, msg);
    std::array<std::uint32_t, 3> n{};
    for (size_t i = 0; i < 3; ++i) {
        const auto& e = (*it)[i];
        if (!e.is_number_integer() || e.get<std::int64_t>() < 1 || e.get<std::int64_t>() > 65535) return bad(ErrorCode::kBadFormat, where, msg);
        n[i] = static_cast<std::uint32_t>(e.get<std::int64_t>());
    }
    return n;
}
// A JSON object from untrusted text (nesting depth checked first).
inline Result<nlohmann::json> parse_object(const std::string& text, const std::string& where) {
    if (Status s = check_json_depth(std::string_view(text), where); !s) return s.error();
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return bad(ErrorCode::kBadFormat, where, "not a JSON object");
    return j;
}
// a == b within 1e-6 of `scale` (bounds written by two JSON texts that must agree).
inline bool near(double a, double b, double scale) { return std::fabs(a - b) <= 1e-6 * scale; }

}  // namespace zhc::engine_file_detail
