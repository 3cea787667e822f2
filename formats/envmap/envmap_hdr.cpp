// zhc/formats/envmap/envmap_hdr.cpp — Radiance .hdr environment maps (formats/envmap/envmap.h): the
// RGBE / XYZE reader written from the format as Radiance defines it (color.c, header.c; every
// orientation, new- and old-style run-length scanlines, bounded before allocating) and the writer
// (stb_image_write).
#include "formats/envmap/envmap_internal.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "formats/io/file_io.h"

namespace zhc {
namespace envmap_detail {

namespace {

// Radiance .hdr (Greg Ward's RGBE format, as Radiance's color.c / header.c define it): header
// lines up to an empty line ("FORMAT=32-bit_rle_rgbe" or "32-bit_rle_xyze"; other variables are
// ignored), a resolution line of two axes "[+-][XY] N [+-][XY] M" (the first is the scanline
// order, the second the pixel order within a scanline; any of the eight orientations), then
// scanlines, each either new-style run-length encoded (2 2 len_hi len_lo, then each of the four
// components run-length coded) or flat 4-byte pixels with old-style repeat runs (1 1 1 n).
// RGBE -> float: mantissa * 2^(e - 136), e == 0 is black (as stb_image and Walter's rgbe.c do).
struct HdrHeader {
    bool xyz = false;
    int width = 0, height = 0;         // image size: X extent, Y extent
    bool major_is_y = true;            // scanlines run along X (rows) when the first axis is Y
    bool major_plus = false, minor_plus = true;
    size_t data_start = 0;
};

Result<HdrHeader> parse_hdr_header(std::span<const std::uint8_t> b, const std::string& name, const EnvmapReadOptions& o) {
    HdrHeader hh;
    size_t pos = 0;
    auto next_line = [&](std::string* line) -> bool {
        line->clear();
        while (pos < b.size() && b[pos] != '\n') {
            if (line->size() > 4096) return false;
            line->push_back(static_cast<char>(b[pos++]));
        }
        if (pos >= b.size()) return false;
        ++pos;
        return true;
    };
    std::string line;
    bool format_seen = false;
    for (int n = 0;; ++n) {
        if (n > 10000 || !next_line(&line))
            return make_error(pos >= b.size() ? ErrorCode::kTruncated : ErrorCode::kBadFormat,
                              name + ": Radiance .hdr header does not end with an empty line (byte " + std::to_string(pos) + ")");
        if (line.empty()) break;
        if (line.rfind("FORMAT=", 0) == 0) {
            std::string f = line.substr(7);
            while (!f.empty() && (f.back() == ' ' || f.back() == '\t' || f.back() == '\r')) f.pop_back();
            if (f == "32-bit_rle_rgbe") {
                hh.xyz = false;
            } else if (f == "32-bit_rle_xyze") {
                hh.xyz = true;
            } else {
                return make_error(ErrorCode::kBadFormat, name + ": Radiance .hdr FORMAT '" + one_line(f.substr(0, 64)) +
                                                             "' is neither 32-bit_rle_rgbe nor 32-bit_rle_xyze");
            }
            format_seen = true;
        }
    }
    (void)format_seen;  // Radiance treats a missing FORMAT as RGBE
    const size_t res_at = pos;
    if (!next_line(&line))
        return make_error(ErrorCode::kTruncated, name + ": Radiance .hdr ends inside its resolution line (byte " +
                                                     std::to_string(res_at) + ")");
    // Two axes: sign, axis letter, space(s), decimal size.
    size_t i = 0;
    auto bad_res = [&](const std::string& what) {
        return make_error(ErrorCode::kBadFormat, name + ": Radiance .hdr resolution line '" + one_line(line.substr(0, 64)) +
                                                     "' " + what + " (byte " + std::to_string(res_at) + ")");
    };
    char axes[2];
    bool plus[2];
    std::uint64_t size[2];
    for (int a = 0; a < 2; ++a) {
        while (i < line.size() && line[i] == ' ') ++i;
        if (i + 2 > line.size() || (line[i] != '+' && line[i] != '-') || (line[i + 1] != 'X' && line[i + 1] != 'Y'))
            return bad_res("is not of the form '-Y N +X M'");
        plus[a] = line[i] == '+';
        axes[a] = line[i + 1];
        i += 2;
        while (i < line.size() && line[i] == ' ') ++i;
        if (i < line.size() && (line[i] == '-' || line[i] == '+')) return bad_res("has a signed size");
        if (i >= line.size() || line[i] < '0' || line[i] > '9') return bad_res("has no size");
        std::uint64_t v = 0;
        while (i < line.size() && line[i] >= '0' && line[i] <= '9') {
            v = std::min<std::uint64_t>(v * 10 + static_cast<std::uint64_t>(line[i] - '0'), std::uint64_t(1) << 40);
            ++i;
        }
        size[a] = v;
    }
    while (i < line.size() && (line[i] == ' ' || line[i] == '\r')) ++i;
    if (i != line.size()) return bad_res("has extra characters");
    if (axes[0] == axes[1]) return bad_res("names the same axis twice");
    if (size[0] == 0 || size[1] == 0) return bad_res("has a zero size");
    hh.major_is_y = axes[0] == 'Y';
    hh.major_plus = plus[0];
    hh.minor_plus = plus[1];
    const std::uint64_t w = hh.major_is_y ? size[1] : size[0], h = hh.major_is_y ? size[0] : size[1];
    if (Status s = check_size(name, w, h, o); !s) return s.error();
    hh.width = static_cast<int>(w);
    hh.height = static_cast<int>(h);
    hh.data_start = pos;
    return hh;
}

// Decodes one scanline of `len` pixels at `pos` into out (4 bytes per pixel; out == nullptr only
// walks the structure); advances pos.
Status read_hdr_scanline(std::span<const std::uint8_t> b, size_t* pos, int len, std::uint8_t* out, const std::string& name,
                         int scanline, int scanlines) {
    auto truncated = [&]() {
        return make_error(ErrorCode::kTruncated, name + ": Radiance .hdr data ends in scanline " + std::to_string(scanline) +
                                                     " of " + std::to_string(scanlines));
    };
    size_t p = *pos;
    const size_t n = static_cast<size_t>(len);
    if (len >= 8 && len <= 0x7fff) {
        if (p + 4 > b.size()) return truncated();
        if (b[p] == 2 && b[p + 1] == 2 && (b[p + 2] & 0x80) == 0) {
            if (((size_t(b[p + 2]) << 8) | b[p + 3]) != n)
                return make_error(ErrorCode::kBadFormat, name + ": Radiance .hdr scanline " + std::to_string(scanline) +
                                                             " declares a length other than the image's");
            p += 4;
            for (int c = 0; c < 4; ++c) {
                size_t filled = 0;
                while (filled < n) {
                    if (p >= b.size()) return truncated();
                    size_t count = b[p++];
                    const bool run = count > 128;
                    if (run) count -= 128;
                    if (count == 0 || filled + count > n)
                        return make_error(ErrorCode::kBadFormat, name + ": Radiance .hdr run overruns scanline " +
                                                                     std::to_string(scanline));
                    if (run) {
                        if (p >= b.size()) return truncated();
                        const std::uint8_t v = b[p++];
                        if (out)
                            for (size_t k = 0; k < count; ++k) out[4 * (filled + k) + static_cast<size_t>(c)] = v;
                    } else {
                        if (count > b.size() - p) return truncated();
                        if (out)
                            for (size_t k = 0; k < count; ++k) out[4 * (filled + k) + static_cast<size_t>(c)] = b[p + k];
                        p += count;
                    }
                    filled += count;
                }
            }
            *pos = p;
            return Ok{};
        }
    }
    // Flat pixels with old-style runs: (1, 1, 1, k) repeats the previous pixel k << shift times,
    // shift growing by 8 over consecutive run pixels.
    size_t filled = 0;
    int shift = 0;
    while (filled < n) {
        if (p + 4 > b.size()) return truncated();
        if (b[p] == 1 && b[p + 1] == 1 && b[p + 2] == 1) {
            if (filled == 0 || shift > 24)
                return make_error(ErrorCode::kBadFormat, name + ": Radiance .hdr old-style run without a pixel to repeat in scanline " +
                                                             std::to_string(scanline));
            const size_t count = size_t(b[p + 3]) << shift;
            if (count > n - filled)
                return make_error(ErrorCode::kBadFormat, name + ": Radiance .hdr run overruns scanline " + std::to_string(scanline));
            if (out)
                for (size_t k = 0; k < count; ++k) std::memcpy(out + 4 * (filled + k), out + 4 * (filled - 1), 4);
            filled += count;
            shift += 8;
        } else {
            if (out) std::memcpy(out + 4 * filled, &b[p], 4);
            ++filled;
            shift = 0;
        }
        p += 4;
    }
    *pos = p;
    return Ok{};
}

}  // namespace

Result<Image> read_hdr(std::span<const std::uint8_t> bytes, const std::string& name, const EnvmapReadOptions& o,
                       EnvmapInfo* info) {
    auto header = parse_hdr_header(bytes, name, o);
    if (!header) return header.error();
    const HdrHeader& hh = *header;
    const int scanlines = hh.major_is_y ? hh.height : hh.width, len = hh.major_is_y ? hh.width : hh.height;
    // First walk every scanline without allocating anything sized by the header (every scanline
    // takes at least 4 bytes: a short file declaring a huge image fails here), and find the end.
    size_t pos = hh.data_start;
    if (static_cast<std::uint64_t>(scanlines) * 4 > bytes.size() - pos)
        return make_error(ErrorCode::kTruncated, name + ": Radiance .hdr of " + std::to_string(scanlines) +
                                                     " scanlines cannot fit in the file's " + std::to_string(bytes.size()) +
                                                     " bytes");
    for (int s = 0; s < scanlines; ++s)
        if (Status st = read_hdr_scanline(bytes, &pos, len, nullptr, name, s, scanlines); !st) return st.error();
    if (pos != bytes.size())
        return make_error(ErrorCode::kTrailingBytes, name + ": " + std::to_string(bytes.size() - pos) +
                                                         " trailing bytes after the Radiance .hdr data (which ends at byte " +
                                                         std::to_string(pos) + ")");
    Image img;
    img.width = hh.width;
    img.height = hh.height;
    img.rgb.assign(static_cast<size_t>(hh.width) * static_cast<size_t>(hh.height) * 3, 0.0f);
    std::vector<std::uint8_t> line(static_cast<size_t>(len) * 4);
    pos = hh.data_start;
    for (int s = 0; s < scanlines; ++s) {
        if (Status st = read_hdr_scanline(bytes, &pos, len, line.data(), name, s, scanlines); !st) return st.error();
        // Radiance coordinates: X grows to the right, Y grows upwards; '+' walks an axis from its
        // low end, '-' from its high end. Image row 0 is the top (highest Y).
        const int major = hh.major_plus ? s : scanlines - 1 - s;
        for (int k = 0; k < len; ++k) {
            const int minor = hh.minor_plus ? k : len - 1 - k;
            const int x = hh.major_is_y ? minor : major, y = hh.major_is_y ? major : minor;
            const int row = hh.height - 1 - y;
            const std::uint8_t* e = &line[static_cast<size_t>(k) * 4];
            float v[3] = {0, 0, 0};
            if (e[3] != 0) {
                const float f = std::ldexp(1.0f, int(e[3]) - 136);
                for (int c = 0; c < 3; ++c) v[c] = float(e[c]) * f;
            }
            float* out = img.row(row) + 3 * static_cast<size_t>(x);
            if (hh.xyz) {
                // CIE XYZ -> linear Rec. 709 / sRGB primaries, D65 white (IEC 61966-2-1).
                out[0] = 3.2404542f * v[0] - 1.5371385f * v[1] - 0.4985314f * v[2];
                out[1] = -0.9692660f * v[0] + 1.8760108f * v[1] + 0.0415560f * v[2];
                out[2] = 0.0556434f * v[0] - 0.2040259f * v[1] + 1.0572252f * v[2];
            } else {
                out[0] = v[0], out[1] = v[1], out[2] = v[2];
            }
        }
    }
    if (info) {
        info->format = "radiance-hdr";
        info->compression = "rle";
        info->channels = hh.xyz ? "XYZE" : "RGBE";
    }
    if (Status s = check_finite(name, img, o, info); !s) return s.error();
    return img;
}

}  // namespace envmap_detail

Status write_hdr(const std::string& path, const Image& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgb.size() != static_cast<size_t>(image.width) * static_cast<size_t>(image.height) * 3)
        return make_error(ErrorCode::kInvalidArgument, path + ": image buffer does not match its size");
    return write_via_temporary(path, [&](const std::string& tmp) -> Status {
        if (!stbi_write_hdr(tmp.c_str(), image.width, image.height, 3, image.rgb.data()))
            return make_error(ErrorCode::kIoError, path + ": cannot write Radiance .hdr");
        return Ok{};
    });
}

}  // namespace zhc
