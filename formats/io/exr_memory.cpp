#include "formats/io/exr_memory.h"

#include "formats/io/le_bytes.h"

#include <algorithm>
#include <cstring>

namespace zhc {

// Walks the OpenEXR header(s) without allocating before OpenEXR sees them: every attribute must
// fit inside the file (OpenEXR would otherwise allocate an attribute's declared size, up to 2 GiB,
// before noticing the file is short), and the data window's declared size is checked against
// zhc's limits first. Header layout: magic, version, then attributes "name\0type\0" int32 size,
// value; a 0 byte ends a header; multi-part files (version bit 12) end the list with another 0.
namespace {

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
        const std::uint64_t w = le::load32(v.data()), h = le::load32(v.data() + 4);
        return w * h * 4 + 8 == v.size() ? Status(Ok{}) : Status(bad("does not match its width x height"));
    }
    if (raw_type == "stringvector") {
        size_t p = 0;
        while (p < v.size()) {
            if (p + 4 > v.size()) return bad("ends inside a string length");
            const std::uint32_t n = le::load32(v.data() + p);
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
                           const std::function<Status(std::uint64_t, std::uint64_t)>& check_size,
                           ExrLayout* layout) {
    if (b.size() < 8) return make_error(ErrorCode::kTruncated, name + ": OpenEXR file ends inside its magic/version");
    std::uint32_t version;
    std::memcpy(&version, b.data() + 4, 4);
    const bool multipart = (version & 0x1000u) != 0;
    if (layout) {
        *layout = ExrLayout{};
        layout->multipart = multipart;
        layout->single_tiled = (version & 0x200u) != 0;
        layout->single_deep = (version & 0x800u) != 0;
    }
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
        ExrPartLayout pl;
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
            const std::uint8_t* value = b.data() + pos;
            if (attr == "type" && type == "string") pl.type.assign(reinterpret_cast<const char*>(value), static_cast<size_t>(size));
            if (attr == "compression" && type == "compression") pl.compression = value[0];
            if (attr == "chunkCount" && type == "int") {
                std::int32_t v;
                std::memcpy(&v, value, 4);
                pl.chunk_count = v;
            }
            if (attr == "tiles" && type == "tiledesc") {
                pl.has_tiles = true;
                pl.tile_x = le::load32(value);
                pl.tile_y = le::load32(value + 4);
                pl.tile_mode = value[8];
            }
            if (attr == "dataWindow" && type == "box2i" && size == 16) {
                std::int32_t v[4];
                std::memcpy(v, b.data() + pos, 16);
                pl.has_window = true;
                for (int i = 0; i < 4; ++i) pl.window[i] = v[i];
                const std::int64_t w = std::int64_t(v[2]) - v[0] + 1, h = std::int64_t(v[3]) - v[1] + 1;
                if (w <= 0 || h <= 0) return make_error(ErrorCode::kBadFormat, name + ": OpenEXR data window is empty");
                if (Status st = check_size(static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h)); !st)
                    return st;
            }
            pos += static_cast<size_t>(size);
        }
        if (layout) layout->parts.push_back(pl);
        if (!multipart) {
            if (layout) layout->tables_start = pos;
            return Ok{};
        }
        if (pos >= b.size()) return truncated();
        if (b[pos] == 0) {  // end of the header list
            if (layout) layout->tables_start = pos + 1;
            return Ok{};
        }
    }
    return make_error(ErrorCode::kUnsupported, name + ": OpenEXR file has more than 64 parts");
}

}  // namespace zhc

namespace zhc {

namespace {

// Scanlines per chunk of each OpenEXR compression (ImfCompression.h order: none, rle, zips, zip,
// piz, pxr24, b44, b44a, dwaa, dwab).
int lines_per_chunk(int compression) {
    static constexpr int kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    return compression >= 0 && compression < 10 ? kLines[compression] : 0;
}

// OpenEXR's level arithmetic (ImfTiledMisc): number of levels for a size, and a level's size.
std::uint64_t level_count(std::uint64_t size, bool round_up) {
    std::uint64_t n = 0, s = size;
    bool exact = true;
    while (s > 1) {
        if (s & 1) exact = false;
        s >>= 1;
        ++n;
    }
    return n + ((round_up && !exact) ? 1 : 0) + 1;
}
std::uint64_t level_size(std::uint64_t size, std::uint64_t level, bool round_up) {
    if (level >= 63) return 1;
    const std::uint64_t b = std::uint64_t(1) << level;
    std::uint64_t s = size / b;
    if (round_up && s * b < size) ++s;
    return std::max<std::uint64_t>(s, 1);
}
std::uint64_t tiles_in(std::uint64_t w, std::uint64_t h, std::uint64_t tx, std::uint64_t ty) {
    return ((w + tx - 1) / tx) * ((h + ty - 1) / ty);
}

}  // namespace

Result<std::uint64_t> exr_data_end(std::span<const std::uint8_t> b, const std::string& name, const ExrLayout& layout) {
    const std::uint64_t size = b.size();
    struct PartChunks {
        std::uint64_t count;
        bool tiled, deep;
    };
    std::vector<PartChunks> parts;
    std::uint64_t total = 0;
    for (size_t p = 0; p < layout.parts.size(); ++p) {
        const ExrPartLayout& pl = layout.parts[p];
        const std::string where = layout.multipart ? " of part " + std::to_string(p) : "";
        const bool deep = layout.multipart ? pl.type.rfind("deep", 0) == 0 : layout.single_deep;
        const bool tiled = layout.multipart ? (pl.type == "tiledimage" || pl.type == "deeptile") : layout.single_tiled;
        if (!pl.has_window)
            return make_error(ErrorCode::kBadFormat, name + ": OpenEXR header" + where + " has no dataWindow");
        const std::uint64_t w = static_cast<std::uint64_t>(pl.window[2] - pl.window[0] + 1);
        const std::uint64_t h = static_cast<std::uint64_t>(pl.window[3] - pl.window[1] + 1);
        const int lines = lines_per_chunk(pl.compression);
        if (lines == 0)
            return make_error(ErrorCode::kUnsupported, name + ": OpenEXR compression " + std::to_string(pl.compression) + where +
                                                           " is not one zhc knows");
        std::uint64_t count = 0;
        if (tiled) {
            if (!pl.has_tiles || pl.tile_x == 0 || pl.tile_y == 0)
                return make_error(ErrorCode::kBadFormat, name + ": tiled OpenEXR part" + where + " has no valid tiles attribute");
            const int level_mode = pl.tile_mode & 0xf;
            const bool round_up = (pl.tile_mode >> 4) != 0;
            if (level_mode > 2 || (pl.tile_mode >> 4) > 1)
                return make_error(ErrorCode::kBadFormat, name + ": OpenEXR tiles attribute" + where + " has an unknown level mode");
            if (level_mode == 0) {
                count = tiles_in(w, h, pl.tile_x, pl.tile_y);
            } else if (level_mode == 1) {
                const std::uint64_t levels = level_count(std::max(w, h), round_up);
                for (std::uint64_t l = 0; l < levels; ++l)
                    count += tiles_in(level_size(w, l, round_up), level_size(h, l, round_up), pl.tile_x, pl.tile_y);
            } else {
                const std::uint64_t lx = level_count(w, round_up), ly = level_count(h, round_up);
                for (std::uint64_t j = 0; j < ly; ++j)
                    for (std::uint64_t i = 0; i < lx; ++i)
                        count += tiles_in(level_size(w, i, round_up), level_size(h, j, round_up), pl.tile_x, pl.tile_y);
            }
        } else {
            count = (h + static_cast<std::uint64_t>(lines) - 1) / static_cast<std::uint64_t>(lines);
        }
        if (layout.multipart) {
            if (pl.chunk_count < 0)
                return make_error(ErrorCode::kBadFormat, name + ": multi-part OpenEXR header" + where + " has no chunkCount");
            if (!deep && static_cast<std::uint64_t>(pl.chunk_count) != count)
                return make_error(ErrorCode::kBadFormat, name + ": OpenEXR chunkCount" + where + " is " +
                                                             std::to_string(pl.chunk_count) + ", its data window needs " +
                                                             std::to_string(count));
            count = static_cast<std::uint64_t>(pl.chunk_count);
        }
        parts.push_back({count, tiled, deep});
        total += count;
        if (total > size) break;  // the tables alone cannot fit; reported below
    }
    const std::uint64_t start = layout.tables_start;
    if (start > size || total > (size - start) / 8)
        return make_error(ErrorCode::kTruncated, name + ": OpenEXR chunk offset table of " + std::to_string(total) +
                                                     " entries (from byte " + std::to_string(start) +
                                                     ") does not fit in the file of " + std::to_string(size) + " bytes");
    const std::uint64_t tables_end = start + total * 8;
    std::uint64_t end = tables_end;
    std::uint64_t entry = start;
    for (size_t p = 0; p < parts.size(); ++p) {
        const std::string where = layout.multipart ? " of part " + std::to_string(p) : "";
        for (std::uint64_t k = 0; k < parts[p].count; ++k, entry += 8) {
            const std::uint64_t at = le::load64(b.data() + entry);
            auto chunk_error = [&](ErrorCode code, const std::string& what) {
                return make_error(code, name + ": OpenEXR chunk " + std::to_string(k) + where + " (offset " +
                                            std::to_string(at) + ") " + what);
            };
            if (at == 0) return chunk_error(ErrorCode::kTruncated, "is missing from the offset table (incomplete file)");
            if (at < tables_end) return chunk_error(ErrorCode::kBadFormat, "points into the header or offset tables");
            std::uint64_t q = at;
            auto need = [&](std::uint64_t n) { return q <= size && n <= size - q; };
            if (layout.multipart) {
                if (!need(4)) return chunk_error(ErrorCode::kTruncated, "lies beyond the end of the file");
                std::int32_t part_number;
                std::memcpy(&part_number, b.data() + q, 4);
                if (part_number != static_cast<std::int32_t>(p))
                    return chunk_error(ErrorCode::kBadFormat, "names part " + std::to_string(part_number));
                q += 4;
            }
            const std::uint64_t coords = parts[p].tiled ? 16 : 4;
            if (parts[p].deep) {
                if (!need(coords + 24)) return chunk_error(ErrorCode::kTruncated, "lies beyond the end of the file");
                const std::uint64_t table = le::load64(b.data() + q + coords), samples = le::load64(b.data() + q + coords + 8);
                q += coords + 24;
                if (table > size || samples > size || !need(table + samples))
                    return chunk_error(ErrorCode::kTruncated, "ends beyond the end of the file");
                q += table + samples;
            } else {
                if (!need(coords + 4)) return chunk_error(ErrorCode::kTruncated, "lies beyond the end of the file");
                std::int32_t packed;
                std::memcpy(&packed, b.data() + q + coords, 4);
                q += coords + 4;
                if (packed < 0) return chunk_error(ErrorCode::kBadFormat, "has a negative data size");
                if (!need(static_cast<std::uint64_t>(packed)))
                    return chunk_error(ErrorCode::kTruncated, "of " + std::to_string(packed) + " bytes ends beyond the end of the file (" +
                                                                  std::to_string(size) + " bytes)");
                q += static_cast<std::uint64_t>(packed);
            }
            end = std::max(end, q);
        }
    }
    return end;
}

}  // namespace zhc
