#include "formats/io/json_depth.h"

namespace zhc {

Status check_json_depth(std::string_view t, const std::string& name, int max_depth) {
    int depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < t.size(); ++i) {
        const char c = t[i];
        if (in_string) {
            if (c == '\\')
                ++i;  // the escaped character (a quote or a backslash) cannot end the string
            else if (c == '"')
                in_string = false;
            continue;
        }
        if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > max_depth)
                return make_error(ErrorCode::kBadFormat, name + ": JSON nests deeper than " + std::to_string(max_depth) +
                                                             " levels (byte " + std::to_string(i) + ")");
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return Ok{};
}

Status check_json_depth(std::span<const std::uint8_t> bytes, const std::string& name, int max_depth) {
    return check_json_depth(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), name, max_depth);
}

}  // namespace zhc
