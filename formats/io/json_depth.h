// zhc/formats/io/json_depth.h — a pre-scan that refuses deeply nested JSON before any parser sees it.
//
// nlohmann::json and tinygltf handle nesting with recursion in places (a 30,000-level glTF ended in
// SIGSEGV), so every JSON zhc reads (probe lists, scene files, glTF/GLB JSON chunks, dering's probe
// lists, info's type sniffing) first passes this scan: arrays and objects may nest at most
// kMaxJsonDepth levels. The scan is one linear pass that only tracks whether it is inside a
// string (honouring backslash escapes), so brackets inside strings do not count.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "codec/status.h"

namespace zhc {

inline constexpr int kMaxJsonDepth = 512;

// kBadFormat "NAME: JSON nests deeper than 512 levels (byte N)" when too deep; Ok otherwise (the
// text need not be valid JSON: the parser reports that).
Status check_json_depth(std::span<const std::uint8_t> bytes, const std::string& name, int max_depth = kMaxJsonDepth);
Status check_json_depth(std::string_view text, const std::string& name, int max_depth = kMaxJsonDepth);

}  // namespace zhc
