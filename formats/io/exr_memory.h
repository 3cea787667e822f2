// zhc/formats/io/exr_memory.h — reading OpenEXR from untrusted bytes in memory (shared by every
// EXR reader in formats/): an Imf::IStream over a byte span, and a header walk that runs before
// OpenEXR allocates anything sized by the header.
#pragma once

#include <ImfIO.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

// An in-memory Imf::IStream; reading past the end throws, which OpenEXR turns into an error.
class ExrMemoryStream final : public Imf::IStream {
public:
    ExrMemoryStream(std::span<const std::uint8_t> bytes, const std::string& name)
        : Imf::IStream(name.c_str()), bytes_(bytes) {}
    bool read(char c[], int n) override {
        if (n < 0 || pos_ + static_cast<std::uint64_t>(n) > bytes_.size())
            throw std::runtime_error("unexpected end of file");
        std::memcpy(c, bytes_.data() + pos_, static_cast<size_t>(n));
        pos_ += static_cast<std::uint64_t>(n);
        return pos_ < bytes_.size();
    }
    std::uint64_t tellg() override { return pos_; }
    void seekg(std::uint64_t pos) override { pos_ = std::min<std::uint64_t>(pos, bytes_.size()); }

private:
    std::span<const std::uint8_t> bytes_;
    std::uint64_t pos_ = 0;
};

// What the chunk walk needs from each part's header.
struct ExrPartLayout {
    std::string type;               // "type" attribute ("scanlineimage", "tiledimage", "deep..."), or ""
    bool has_window = false;
    std::int64_t window[4] = {};    // dataWindow min.x min.y max.x max.y
    int compression = -1;
    bool has_tiles = false;
    std::uint32_t tile_x = 0, tile_y = 0;
    std::uint8_t tile_mode = 0;     // level mode | rounding mode << 4
    std::int64_t chunk_count = -1;  // "chunkCount" attribute, -1 when absent
};
struct ExrLayout {
    bool multipart = false;
    bool single_tiled = false;  // version flag 0x200 (single-part tiled file)
    bool single_deep = false;   // version flag 0x800 (single-part deep file)
    size_t tables_start = 0;    // first byte after the header(s): the chunk offset tables
    std::vector<ExrPartLayout> parts;
};

// Fails (kTruncated / kBadFormat / kUnsupported) unless every attribute of every header fits in the
// file; calls check_size(width, height) with the declared data window, whose error is returned.
// With `layout`, also returns what exr_data_end needs.
Status validate_exr_header(std::span<const std::uint8_t> bytes, const std::string& name,
                           const std::function<Status(std::uint64_t, std::uint64_t)>& check_size,
                           ExrLayout* layout = nullptr);

// Walks the chunk offset tables and every chunk's own header (part number, coordinates, packed
// size) of a file whose header(s) validate_exr_header accepted, and returns the byte just past the
// last chunk: the file's true end. Fails kTruncated when a table or a chunk does not fit in the
// file (or an offset is 0: an incomplete file), kBadFormat when an offset points into the tables
// or a chunk names the wrong part, kUnsupported for an unknown compression. Nothing is allocated
// in proportion to the declared image size: the table size is checked against the file first.
Result<std::uint64_t> exr_data_end(std::span<const std::uint8_t> bytes, const std::string& name,
                                   const ExrLayout& layout);

}  // namespace zhc
