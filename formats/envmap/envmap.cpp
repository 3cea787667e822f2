// OpenEXR (OpenEXR 3) and Radiance .hdr (stb_image) environment-map I/O.
#include "formats/envmap/envmap.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfRgbaFile.h>
#include <ImfThreading.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfStandardAttributes.h>
#include <ImfTestFile.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>

#include "codec/sh/cubemap.h"
#include "formats/envmap/envmap_cube.h"
#include "formats/io/exr_memory.h"
#include "formats/io/file_io.h"

namespace zhc {

namespace {

bool is_exr(std::span<const std::uint8_t> b) {
    return b.size() >= 4 && b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01;
}
bool is_radiance(std::span<const std::uint8_t> b) {
    auto starts = [&](const char* s) {
        const size_t n = std::strlen(s);
        return b.size() >= n && std::memcmp(b.data(), s, n) == 0;
    };
    return starts("#?RADIANCE") || starts("#?RGBE");
}

const char* compression_name(Imf::Compression c) {
    switch (c) {
        case Imf::NO_COMPRESSION: return "none";
        case Imf::RLE_COMPRESSION: return "rle";
        case Imf::ZIPS_COMPRESSION: return "zips";
        case Imf::ZIP_COMPRESSION: return "zip";
        case Imf::PIZ_COMPRESSION: return "piz";
        case Imf::PXR24_COMPRESSION: return "pxr24";
        case Imf::B44_COMPRESSION: return "b44";
        case Imf::B44A_COMPRESSION: return "b44a";
        case Imf::DWAA_COMPRESSION: return "dwaa";
        case Imf::DWAB_COMPRESSION: return "dwab";
        default: return "unknown";
    }
}

Status check_size(const std::string& name, std::uint64_t w, std::uint64_t h, const EnvmapReadOptions& o) {
    if (w == 0 || h == 0) return make_error(ErrorCode::kBadFormat, name + ": image has zero width or height");
    if (w > static_cast<std::uint64_t>(std::numeric_limits<int>::max()) ||
        h > static_cast<std::uint64_t>(std::numeric_limits<int>::max()) || w * h > o.max_pixels)
        return make_error(ErrorCode::kTooLarge, name + ": image of " + std::to_string(w) + "x" + std::to_string(h) +
                                                    " pixels exceeds the limit of " + std::to_string(o.max_pixels) +
                                                    " pixels");
    return Ok{};
}

Status check_finite(const std::string& name, Image& img, const EnvmapReadOptions& o, EnvmapInfo* info) {
    std::uint64_t replaced = 0;
    for (size_t i = 0; i < img.rgb.size(); ++i) {
        if (std::isfinite(img.rgb[i])) continue;
        if (o.non_finite == NonFinitePolicy::kReject) {
            const size_t pixel = i / 3;
            std::ostringstream msg;
            msg << name << ": non-finite pixel value (" << img.rgb[i] << ") at column "
                << pixel % static_cast<size_t>(img.width) << ", row " << pixel / static_cast<size_t>(img.width)
                << ", channel " << "RGB"[i % 3] << " (use --replace-non-finite to replace such values by 0)";
            return make_error(ErrorCode::kInvalidValue, msg.str());
        }
        img.rgb[i] = 0.0f;
        ++replaced;
    }
    if (info) info->replaced_non_finite = replaced;
    return Ok{};
}

std::string one_line(std::string what) {
    for (char& ch : what)
        if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = ' ';
    return what;
}

bool usable_channels(const Imf::ChannelList& channels) {
    return (channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B")) ||
           channels.findChannel("Y") != nullptr;
}

bool is_deep(const Imf::Header& h) {
    return h.hasType() && (h.type() == Imf::DEEPSCANLINE || h.type() == Imf::DEEPTILE);
}

std::string part_label(const Imf::Header& h, int index) {
    std::string out;
    if (h.hasName()) {
        out.push_back('\'');
        out.append(h.name());
        out.push_back('\'');
    } else {
        out.push_back('#');
        out.append(std::to_string(index));
    }
    return out;
}

// Chooses the part to read: by name (or index) when asked, else the first non-deep part with
// R, G, B or Y channels.
Result<int> choose_part(const Imf::MultiPartInputFile& file, const std::string& name, const std::string& wanted) {
    const int parts = file.parts();
    std::string labels;
    for (int i = 0; i < parts; ++i) labels += (i ? ", " : "") + part_label(file.header(i), i);
    if (!wanted.empty()) {
        int found = -1;
        for (int i = 0; i < parts && found < 0; ++i)
            if (file.header(i).hasName() && file.header(i).name() == wanted) found = i;
        if (found < 0 && !wanted.empty() && wanted.size() < 4 &&
            wanted.find_first_not_of("0123456789") == std::string::npos && std::stoi(wanted) < parts)
            found = std::stoi(wanted);
        if (found < 0)
            return make_error(ErrorCode::kInvalidArgument,
                              name + ": OpenEXR file has no part named '" + wanted + "' (parts: " + labels + ")");
        const Imf::Header& h = file.header(found);
        if (is_deep(h) || !usable_channels(h.channels()))
            return make_error(ErrorCode::kUnsupported, name + ": OpenEXR part " + part_label(h, found) +
                                                           " has no R, G, B (or Y) channels or is deep");
        return found;
    }
    for (int i = 0; i < parts; ++i)
        if (!is_deep(file.header(i)) && usable_channels(file.header(i).channels())) return i;
    return make_error(ErrorCode::kUnsupported, name + ": OpenEXR file has no part with R, G, B (or Y) channels (parts: " +
                                                   labels + ")");
}

// Luminance/chroma (Y, RY, BY as Imf::RgbaOutputFile writes with WRITE_YC/WRITE_YCA): OpenEXR's
// RgbaInputFile reconstructs full-resolution chroma and converts to RGB with the file's
// chromaticities (ImfRgbaYca). It reads the first part only.
Status read_yc(std::span<const std::uint8_t> bytes, const std::string& name, Image& img, const Imath::Box2i& dw) {
    ExrMemoryStream stream(bytes, name);
    Imf::RgbaInputFile in(stream);
    const size_t w = static_cast<size_t>(img.width), h = static_cast<size_t>(img.height);
    std::vector<Imf::Rgba> px(w * h);
    // Base pointer such that base + x + y * w addresses pixel (x, y) of the data window; computed
    // in integers (a pointer outside the buffer would be UB).
    const std::ptrdiff_t origin = -(std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * std::ptrdiff_t(w));
    in.setFrameBuffer(reinterpret_cast<Imf::Rgba*>(reinterpret_cast<std::uintptr_t>(px.data()) +
                                                   static_cast<std::uintptr_t>(origin * std::ptrdiff_t(sizeof(Imf::Rgba)))),
                      1, w);
    in.readPixels(dw.min.y, dw.max.y);
    for (size_t i = 0; i < w * h; ++i) {
        img.rgb[3 * i] = px[i].r;
        img.rgb[3 * i + 1] = px[i].g;
        img.rgb[3 * i + 2] = px[i].b;
    }
    return Ok{};
}

Result<Image> read_exr(std::span<const std::uint8_t> bytes, const std::string& name, const EnvmapReadOptions& o,
                       EnvmapInfo* info) {
    ExrLayout layout;
    if (Status s = validate_exr_header(bytes, name, [&](std::uint64_t w, std::uint64_t h) { return check_size(name, w, h, o); },
                                       &layout);
        !s)
        return s.error();
    // Every chunk must lie inside the file before anything sized by the header is allocated, and
    // the last chunk's end is the file's end: more bytes are an error.
    auto end = exr_data_end(bytes, name, layout);
    if (!end) return end.error();
    if (*end != bytes.size())
        return make_error(ErrorCode::kTrailingBytes, name + ": " + std::to_string(bytes.size() - *end) +
                                                         " trailing bytes after the OpenEXR data (which ends at byte " +
                                                         std::to_string(*end) + ")");
    try {
        // Bound what OpenEXR itself allocates while reading the header (its line-offset table
        // grows with the height): 2^20 per side, far above any real map; zhc's own pixel limit is
        // checked below, before the pixel buffer is allocated.
        Imf::Header::setMaxImageSize(1 << 20, 1 << 20);
        Imf::Header::setMaxTileSize(1 << 20, 1 << 20);
        ExrMemoryStream stream(bytes, name);
        Imf::MultiPartInputFile file(stream, Imf::globalThreadCount(), /*reconstructChunkOffsetTable=*/false);
        auto chosen = choose_part(file, name, o.part);
        if (!chosen) return chosen.error();
        const Imf::Header& header = file.header(*chosen);
        const Imath::Box2i dw = header.dataWindow();
        const std::int64_t w = std::int64_t(dw.max.x) - dw.min.x + 1, h = std::int64_t(dw.max.y) - dw.min.y + 1;
        if (w <= 0 || h <= 0) return make_error(ErrorCode::kBadFormat, name + ": empty data window");
        if (Status s = check_size(name, static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h), o); !s)
            return s.error();
        EnvmapLayout map_layout = EnvmapLayout::kLatLong;
        if (Imf::hasEnvmap(header)) {
            const int e = static_cast<int>(Imf::envmap(header));
            if (e == Imf::ENVMAP_CUBE) {
                if (h != 6 * w)
                    return make_error(ErrorCode::kBadFormat, name + ": cube-face environment map of " + std::to_string(w) + "x" +
                                                                 std::to_string(h) + " pixels (a cube map is N x 6N)");
                map_layout = EnvmapLayout::kCubeOpenExr;
            } else if (e != Imf::ENVMAP_LATLONG) {
                return make_error(ErrorCode::kUnsupported, name + ": unknown envmap attribute value " + std::to_string(e) +
                                                               " (0 lat-long and 1 cube are defined)");
            }
        }
        const Imf::ChannelList& channels = header.channels();
        const bool has_rgb = channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
        const bool yc = !has_rgb && channels.findChannel("Y") && channels.findChannel("RY") && channels.findChannel("BY");
        for (const char* c : {"R", "G", "B", "Y"}) {
            const Imf::Channel* ch = channels.findChannel(c);
            if (ch && (ch->xSampling != 1 || ch->ySampling != 1))
                return make_error(ErrorCode::kUnsupported, name + ": channel " + c + " is subsampled");
        }
        Image img;
        img.width = static_cast<int>(w);
        img.height = static_cast<int>(h);
        img.layout = map_layout;
        img.rgb.assign(static_cast<size_t>(w * h * 3), 0.0f);
        if (yc) {
            if (*chosen != 0)
                return make_error(ErrorCode::kUnsupported, name + ": luminance/chroma (Y RY BY) part " +
                                                               part_label(header, *chosen) + " is not the first part");
            if (Status s = read_yc(bytes, name, img, dw); !s) return s.error();
        } else {
            Imf::InputPart part(file, *chosen);
            Imf::FrameBuffer fb;
            // Base such that base + x*xs + y*ys addresses pixel (x, y) of the data window (as an
            // integer: OpenEXR only adds offsets that land inside the buffer).
            const std::int64_t origin = -(std::int64_t(dw.min.x) + std::int64_t(dw.min.y) * w) * 3 * std::int64_t(sizeof(float));
            char* base = reinterpret_cast<char*>(reinterpret_cast<std::uintptr_t>(img.rgb.data()) +
                                                 static_cast<std::uintptr_t>(origin));
            const size_t xs = 3 * sizeof(float), ys = static_cast<size_t>(w) * 3 * sizeof(float);
            if (has_rgb) {
                fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
                fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
                fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
            } else {
                fb.insert("Y", Imf::Slice(Imf::FLOAT, base, xs, ys));
            }
            part.setFrameBuffer(fb);
            part.readPixels(dw.min.y, dw.max.y);
            if (!has_rgb)
                for (size_t i = 0; i < img.rgb.size(); i += 3) img.rgb[i + 1] = img.rgb[i + 2] = img.rgb[i];
        }
        if (info) {
            info->format = "openexr";
            info->compression = compression_name(header.compression());
            const Imf::Channel* c = channels.findChannel(has_rgb ? "R" : "Y");
            info->channels = std::string(has_rgb ? (channels.findChannel("A") ? "RGBA" : "RGB")
                                                 : (yc ? (channels.findChannel("A") ? "YCA" : "YC") : "Y")) +
                             (c->type == Imf::HALF ? " half" : c->type == Imf::FLOAT ? " float" : " uint");
            info->layout = map_layout == EnvmapLayout::kCubeOpenExr ? "cube" : "lat-long";
            info->part = part_label(header, *chosen);
        }
        if (Status s = check_finite(name, img, o, info); !s) return s.error();
        return img;
    } catch (const std::exception& e) {
        const std::string what = one_line(e.what());
        if (what.find("exceeds the maximum") != std::string::npos)
            return make_error(ErrorCode::kTooLarge, name + ": OpenEXR image too large (" + what + ")");
        if (what.find("unexpected end of file") != std::string::npos)
            return make_error(ErrorCode::kTruncated, name + ": OpenEXR file is truncated (" + what + ")");
        return make_error(ErrorCode::kBadFormat, name + ": cannot read OpenEXR data (" + what + ")");
    }
}

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

}  // namespace

Sh3Radiance project_envmap(const Image& image, int threads) {
    if (image.layout == EnvmapLayout::kCubeOpenExr)
        return project_cube_openexr(image.rgb.data(), image.width, static_cast<size_t>(image.width) * 3, threads);
    if (image.layout == EnvmapLayout::kCubeVulkan)
        return project_cube(kCubeLayoutVulkan, image.rgb.data(), image.width, static_cast<size_t>(image.width) * 3,
                            threads);
    return project_latlong(image.rgb.data(), image.width, image.height, static_cast<size_t>(image.width) * 3, threads);
}

namespace {
// Pixel of a cube map seen in zhc direction d: the nearest pixel centre.
const float* cube_pixel(const Image& cube, Vec3 d) {
    const CubeLayout& layout = cube.layout == EnvmapLayout::kCubeVulkan ? kCubeLayoutVulkan : kCubeLayoutOpenExr;
    int face, col, row;
    cube_nearest_pixel(layout, d, cube.width, &face, &col, &row);
    return cube.row(face * cube.width + row) + 3 * static_cast<size_t>(col);
}
}  // namespace

Image envmap_as_latlong(const Image& image, int width, int height) {
    if (image.layout == EnvmapLayout::kLatLong) return image;
    Image out;
    out.width = width;
    out.height = height;
    out.rgb.assign(static_cast<size_t>(width) * static_cast<size_t>(height) * 3, 0.0f);
    constexpr int kSub = 4;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double acc[3] = {0, 0, 0};
            for (int j = 0; j < kSub; ++j)
                for (int i = 0; i < kSub; ++i) {
                    const Vec3 d = latlong_direction(x + (i + 0.5) / kSub - 0.5, y + (j + 0.5) / kSub - 0.5, width, height);
                    const float* p = cube_pixel(image, d);
                    for (int c = 0; c < 3; ++c) acc[c] += p[c];
                }
            for (int c = 0; c < 3; ++c) out.row(y)[3 * x + c] = static_cast<float>(acc[c] / (kSub * kSub));
        }
    return out;
}

bool looks_like_envmap(std::span<const std::uint8_t> bytes) {
    return is_exr(bytes) || is_radiance(bytes) || ktx2_declares_cube(bytes) || dds_declares_cube(bytes);
}

Result<Image> read_envmap_memory(std::span<const std::uint8_t> bytes, const std::string& name,
                                 const EnvmapReadOptions& options, EnvmapInfo* info) {
    if (bytes.empty()) return make_error(ErrorCode::kTruncated, name + ": file is empty");
    if (is_exr(bytes)) return read_exr(bytes, name, options, info);
    if (is_radiance(bytes)) return read_hdr(bytes, name, options, info);
    if (is_ktx2(bytes) || is_dds(bytes)) {
        auto img = is_ktx2(bytes) ? read_ktx2_cube(bytes, name, options, info) : read_dds_cube(bytes, name, options, info);
        if (!img) return img.error();
        if (Status s = check_finite(name, *img, options, info); !s) return s.error();
        return img;
    }
    return make_error(ErrorCode::kBadFormat,
                      name + ": not an OpenEXR, Radiance .hdr, KTX2 or DDS image (unknown magic bytes)");
}

Result<Image> read_envmap(const std::string& path, const EnvmapReadOptions& options, EnvmapInfo* info) {
    auto bytes = read_file_bytes(path, options.max_file_bytes);
    if (!bytes) return bytes.error();
    return read_envmap_memory(*bytes, path, options, info);
}

Status write_exr(const std::string& path, const Image& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgb.size() != static_cast<size_t>(image.width) * static_cast<size_t>(image.height) * 3)
        return make_error(ErrorCode::kInvalidArgument, path + ": image buffer does not match its size");
    return write_via_temporary(path, [&](const std::string& tmp) -> Status {
        try {
            Imf::Header header(image.width, image.height);
            header.compression() = Imf::ZIP_COMPRESSION;
            for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
            Imf::addEnvmap(header, Imf::ENVMAP_LATLONG);
            Imf::OutputFile out(tmp.c_str(), header);
            Imf::FrameBuffer fb;
            char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgb.data()));
            const size_t xs = 3 * sizeof(float), ys = static_cast<size_t>(image.width) * xs;
            fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
            fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
            fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
            out.setFrameBuffer(fb);
            out.writePixels(image.height);
            return Ok{};
        } catch (const std::exception& e) {
            return make_error(ErrorCode::kIoError, path + ": cannot write OpenEXR (" + e.what() + ")");
        }
    });
}

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
