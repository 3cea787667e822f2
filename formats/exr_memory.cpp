#include "exr_memory.h"

namespace zhc {

// Walks the OpenEXR header(s) without allocating before OpenEXR sees them: every attribute must
// fit inside the file (OpenEXR would otherwise allocate an attribute's declared size, up to 2 GiB,
// before noticing the file is short), and the data window's declared size is checked against
// zhc's limits first. Header layout: magic, version, then attributes "name\0type\0" int32 size,
// value; a 0 byte ends a header; multi-part files (version bit 12) end the list with another 0.
Status validate_exr_header(std::span<const std::uint8_t> b, const std::string& name,
                           const std::function<Status(std::uint64_t, std::uint64_t)>& check_size) {
    if (b.size() < 8) return make_error(ErrorCode::kTruncated, name + ": OpenEXR file ends inside its magic/version");
    std::uint32_t version;
    std::memcpy(&version, b.data() + 4, 4);
    const bool multipart = (version & 0x1000u) != 0;
    const size_t max_name = (version & 0x400u) ? 255 : 31;
    size_t pos = 8;
    auto truncated = [&]() {
        return make_error(ErrorCode::kTruncated, name + ": OpenEXR header ends early (byte " + std::to_string(pos) + ")");
    };
    auto read_cstr = [&](std::string* out) -> bool {
        out->clear();
        while (pos < b.size() && b[pos] != 0 && out->size() <= max_name) out->push_back(static_cast<char>(b[pos++]));
        if (pos >= b.size() || b[pos] != 0) return false;
        ++pos;
        return true;
    };
    for (int part = 0; part < 64; ++part) {
        for (int attrs = 0;; ++attrs) {
            if (pos >= b.size()) return truncated();
            if (b[pos] == 0) {
                ++pos;
                break;
            }
            if (attrs >= 1024) return make_error(ErrorCode::kBadFormat, name + ": OpenEXR header has too many attributes");
            const size_t at = pos;
            std::string attr, type;
            if (!read_cstr(&attr) || !read_cstr(&type)) {
                if (pos >= b.size()) return truncated();
                return make_error(ErrorCode::kBadFormat,
                                  name + ": malformed OpenEXR attribute name or type at byte " + std::to_string(at));
            }
            if (pos + 4 > b.size()) return truncated();
            std::int32_t size;
            std::memcpy(&size, b.data() + pos, 4);
            pos += 4;
            if (size < 0) return make_error(ErrorCode::kBadFormat, name + ": OpenEXR attribute '" + attr + "' has a negative size");
            if (pos + static_cast<size_t>(size) > b.size()) return truncated();
            if (attr == "dataWindow" && type == "box2i" && size == 16) {
                std::int32_t v[4];
                std::memcpy(v, b.data() + pos, 16);
                const std::int64_t w = std::int64_t(v[2]) - v[0] + 1, h = std::int64_t(v[3]) - v[1] + 1;
                if (w <= 0 || h <= 0) return make_error(ErrorCode::kBadFormat, name + ": OpenEXR data window is empty");
                if (Status st = check_size(static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h)); !st)
                    return st;
            }
            pos += static_cast<size_t>(size);
        }
        if (!multipart) return Ok{};
        if (pos >= b.size()) return truncated();
        if (b[pos] == 0) return Ok{};  // end of the header list
    }
    return make_error(ErrorCode::kUnsupported, name + ": OpenEXR file has more than 64 parts");
}

}  // namespace zhc
