#include "exr_memory.h"

#include <cstring>

namespace zhc {

// Walks the OpenEXR header(s) without allocating before OpenEXR sees them: every attribute must
// fit inside the file (OpenEXR would otherwise allocate an attribute's declared size, up to 2 GiB,
// before noticing the file is short), and the data window's declared size is checked against
// zhc's limits first. Header layout: magic, version, then attributes "name\0type\0" int32 size,
// value; a 0 byte ends a header; multi-part files (version bit 12) end the list with another 0.
namespace {

std::uint32_t load_u32(const std::uint8_t* p) {
    std::uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

// OpenEXR's typed attribute readers parse their own value and ignore the declared size: a fixed
// type reads its fixed number of bytes, a channel list reads until its empty name, a preview reads
// width x height x 4 bytes from its own header. When the declared size disagrees, OpenEXR goes on
// reading the next attribute from the wrong position, where any 4 bytes can become a huge
// declared size (a fuzzer found a 1.7 GB allocation from a 263-byte file this way). So the value
// of every type OpenEXR knows must parse to exactly its declared size. Unknown types are kept as
// opaque bytes of the declared size, which the caller has already bounded by the file.
// Attribute names and types come from the file: control and non-ASCII bytes are shown as \xNN so
// an error message stays one printable line.
std::string printable(const std::string& s) {
    std::string out;
    for (unsigned char c : s) {
        if (c >= 0x20 && c < 0x7f) {
            out.push_back(static_cast<char>(c));
        } else {
            static const char* hex = "0123456789abcdef";
            out += "\\x";
            out.push_back(hex[c >> 4]);
            out.push_back(hex[c & 15]);
        }
    }
    return out;
}

Status check_attribute_value(std::span<const std::uint8_t> v, const std::string& name, const std::string& raw_attr,
                             const std::string& raw_type) {
    const std::string attr = printable(raw_attr), type = printable(raw_type);
    auto bad = [&](const char* what) {
        return make_error(ErrorCode::kBadFormat, name + ": OpenEXR attribute '" + attr + "' of type '" + type + "' " +
                                                     what + " (declared size " + std::to_string(v.size()) + ")");
    };
    struct Fixed {
        const char* type;
        size_t size;
    };
    static constexpr Fixed kFixed[] = {
        {"box2i", 16},  {"box2f", 16},    {"chromaticities", 32}, {"compression", 1}, {"double", 8},
        {"envmap", 1},  {"float", 4},     {"int", 4},             {"keycode", 28},    {"lineOrder", 1},
        {"m33f", 36},   {"m33d", 72},     {"m44f", 64},           {"m44d", 128},      {"rational", 8},
        {"tiledesc", 9}, {"timecode", 8}, {"v2i", 8},             {"v2f", 8},         {"v2d", 16},
        {"v3i", 12},    {"v3f", 12},      {"v3d", 24},            {"deepImageState", 1},
    };
    for (const Fixed& f : kFixed)
        if (raw_type == f.type) return v.size() == f.size ? Status(Ok{}) : Status(bad("has the wrong size for its type"));
    if (raw_type == "chlist") {
        // Entries: name\0, pixel type (4), pLinear + 3 reserved (4), x/y sampling (4 + 4); an
        // empty name ends the list.
        size_t p = 0;
        for (;;) {
            if (p >= v.size()) return bad("is not terminated");
            if (v[p] == 0) return p + 1 == v.size() ? Status(Ok{}) : Status(bad("does not end where declared"));
            size_t n = 0;
            while (p < v.size() && v[p] != 0 && n <= 255) ++p, ++n;
            if (p >= v.size() || v[p] != 0) return bad("has a malformed channel name");
            p += 1 + 16;
            if (p > v.size()) return bad("ends inside a channel");
        }
    }
    if (raw_type == "preview") {
        if (v.size() < 8) return bad("is too short");
        const std::uint64_t w = load_u32(v.data()), h = load_u32(v.data() + 4);
        return w * h * 4 + 8 == v.size() ? Status(Ok{}) : Status(bad("does not match its width x height"));
    }
    if (raw_type == "stringvector") {
        size_t p = 0;
        while (p < v.size()) {
            if (p + 4 > v.size()) return bad("ends inside a string length");
            const std::uint32_t n = load_u32(v.data() + p);
            p += 4;
            if (n > v.size() - p) return bad("has a string longer than the attribute");
            p += n;
        }
        return Ok{};
    }
    if (raw_type == "floatvector" && v.size() % 4 != 0) return bad("is not a whole number of floats");
    // OpenEXR 3.1 reads an idmanifest as an 8-byte size plus (declared size - 4) bytes, 4 bytes
    // past its end (found by fuzzing: the next "size" became 1.9 GB). ID manifests belong to ID
    // and deep images, not environment maps or lightmaps: refuse them rather than model the quirk.
    if (raw_type == "idmanifest")
        return make_error(ErrorCode::kUnsupported, name + ": OpenEXR attribute '" + attr +
                                                       "' has type idmanifest, which zhc does not read");
    return Ok{};
}

}  // namespace

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
            if (size < 0) return make_error(ErrorCode::kBadFormat, name + ": OpenEXR attribute '" + printable(attr) + "' has a negative size");
            if (pos + static_cast<size_t>(size) > b.size()) return truncated();
            if (Status st = check_attribute_value(b.subspan(pos, static_cast<size_t>(size)), name, attr, type); !st)
                return st;
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
