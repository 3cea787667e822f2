// zhc/formats/envmap/envmap.cpp — OpenEXR (OpenEXR 3) environment-map I/O, format detection and projection;
// Radiance .hdr: envmap_hdr.cpp; KTX2 / DDS cube maps: envmap_cube.cpp.
#include "formats/envmap/envmap.h"

#include <ImfChannelList.h>
#include <ImfChromaticities.h>
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

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>

#include "codec/sh/cubemap.h"
#include "formats/envmap/envmap_cube.h"
#include "formats/envmap/envmap_internal.h"
#include "formats/io/exr_memory.h"
#include "formats/io/file_io.h"

namespace zhc {

namespace envmap_detail {

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
    std::uint64_t replaced = 0, pixels = 0;
    size_t last_pixel = SIZE_MAX;
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
        if (i / 3 != last_pixel) ++pixels, last_pixel = i / 3;
    }
    if (info) info->replaced_non_finite = replaced, info->non_finite_pixels = pixels;
    return Ok{};
}

std::string one_line(std::string what) {
    for (char& ch : what)
        if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = ' ';
    return what;
}

}  // namespace envmap_detail

using namespace envmap_detail;

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

bool usable_channels(const Imf::ChannelList& channels) {
    return (channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B")) ||
           channels.findChannel("Y") != nullptr;
}

// The channel names of a part, for messages: "R, G" (at most 16, each cut to 32 characters).
std::string channel_names(const Imf::ChannelList& channels) {
    std::string out;
    int n = 0;
    for (auto it = channels.begin(); it != channels.end(); ++it, ++n) {
        if (n == 16) {
            out += ", ...";
            break;
        }
        std::string c = one_line(it.name());
        if (c.size() > 32) c = c.substr(0, 32) + "...";
        out += (n ? ", " : "") + c;
    }
    return n ? out : "none";
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
        if (is_deep(h))
            return make_error(ErrorCode::kUnsupported, name + ": OpenEXR part " + part_label(h, found) + " is deep");
        if (!usable_channels(h.channels()))
            return make_error(ErrorCode::kUnsupported, name + ": OpenEXR part " + part_label(h, found) +
                                                           " has no R, G, B (or Y) channels (it has: " +
                                                           channel_names(h.channels()) + ")");
        return found;
    }
    for (int i = 0; i < parts; ++i)
        if (!is_deep(file.header(i)) && usable_channels(file.header(i).channels())) return i;
    // What each part has (at most 8 parts listed), so that an R-only or R, G file says so.
    std::string have;
    for (int i = 0; i < parts && i < 8; ++i)
        have += std::string(i ? "; " : "") + "part " + part_label(file.header(i), i) + ": " +
                (is_deep(file.header(i)) ? "deep, " : "") + channel_names(file.header(i).channels());
    if (parts > 8) have += "; ...";
    return make_error(ErrorCode::kUnsupported, name + ": OpenEXR file has no part with R, G, B (or Y) channels (" + have + ")");
}

// Luminance/chroma (Y, RY, BY as Imf::RgbaOutputFile writes with WRITE_YC/WRITE_YCA): OpenEXR's
// RgbaInputFile reconstructs full-resolution chroma and converts to RGB with the file's
// chromaticities (ImfRgbaYca), in the file's primaries; read_exr then takes them, like every EXR's
// RGB, to Rec. 709 / D65 (envmap_colour.cpp). It reads the first part only.
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

std::string window_text(const Imath::Box2i& b) {
    std::ostringstream t;
    t << "(" << b.min.x << " " << b.min.y << ") - (" << b.max.x << " " << b.max.y << ")";
    return t.str();
}

// The data window's pixels placed in an image of the display window's size: where the data window
// does not cover the display window the pixels are 0, and data outside the display window is
// dropped. Both sizes were checked against the pixel limit.
Image to_display_window(const Image& data, const Imath::Box2i& dw, const Imath::Box2i& disp) {
    Image out;
    out.width = static_cast<int>(std::int64_t(disp.max.x) - disp.min.x + 1);
    out.height = static_cast<int>(std::int64_t(disp.max.y) - disp.min.y + 1);
    out.layout = data.layout;
    out.rgb.assign(static_cast<size_t>(out.width) * static_cast<size_t>(out.height) * 3, 0.0f);
    const std::int64_t x0 = std::max(dw.min.x, disp.min.x), x1 = std::min(dw.max.x, disp.max.x);
    const std::int64_t y0 = std::max(dw.min.y, disp.min.y), y1 = std::min(dw.max.y, disp.max.y);
    if (x0 > x1 || y0 > y1) return out;
    for (std::int64_t y = y0; y <= y1; ++y)
        std::memcpy(out.row(static_cast<int>(y - disp.min.y)) + 3 * (x0 - disp.min.x),
                    data.row(static_cast<int>(y - dw.min.y)) + 3 * (x0 - dw.min.x),
                    static_cast<size_t>(x1 - x0 + 1) * 3 * sizeof(float));
    return out;
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
        // The display window is the image that maps to the sphere (or the cube); see to_display_window.
        const Imath::Box2i disp = header.displayWindow();
        const std::int64_t dw_w = std::int64_t(disp.max.x) - disp.min.x + 1, dw_h = std::int64_t(disp.max.y) - disp.min.y + 1;
        if (dw_w <= 0 || dw_h <= 0) return make_error(ErrorCode::kBadFormat, name + ": empty display window");
        if (Status s = check_size(name + ": display window", static_cast<std::uint64_t>(dw_w),
                                  static_cast<std::uint64_t>(dw_h), o);
            !s)
            return s.error();
        EnvmapLayout map_layout = EnvmapLayout::kLatLong;
        if (Imf::hasEnvmap(header)) {
            const int e = static_cast<int>(Imf::envmap(header));
            if (e == Imf::ENVMAP_CUBE) {
                if (dw_h != 6 * dw_w)
                    return make_error(ErrorCode::kBadFormat, name + ": cube-face environment map of " + std::to_string(dw_w) +
                                                                 "x" + std::to_string(dw_h) +
                                                                 " pixels (a cube map is N x 6N)");
                map_layout = EnvmapLayout::kCubeOpenExr;
            } else if (e != Imf::ENVMAP_LATLONG) {
                return make_error(ErrorCode::kUnsupported, name + ": unknown envmap attribute value " + std::to_string(e) +
                                                               " (0 lat-long and 1 cube are defined)");
            }
        }
        // Chromaticities are checked before any pixel is read (the YC path decodes with them).
        float chroma[8];
        const bool has_chroma = Imf::hasChromaticities(header);
        if (has_chroma) {
            const Imf::Chromaticities& c = Imf::chromaticities(header);
            const float v[8] = {c.red.x, c.red.y, c.green.x, c.green.y, c.blue.x, c.blue.y, c.white.x, c.white.y};
            std::copy(v, v + 8, chroma);
        }
        auto colour = exr_colour_conversion(name, has_chroma ? chroma : nullptr, info);
        if (!colour) return colour.error();
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
            info->data_window = window_text(dw);
            info->display_window = window_text(disp);
        }
        if (dw != disp) {
            const bool outside = dw.min.x < disp.min.x || dw.min.y < disp.min.y || dw.max.x > disp.max.x || dw.max.y > disp.max.y;
            const bool covers = dw.min.x <= disp.min.x && dw.min.y <= disp.min.y && dw.max.x >= disp.max.x && dw.max.y >= disp.max.y;
            std::ostringstream msg;
            msg << name << ": data window " << window_text(dw) << " differs from the display window " << window_text(disp)
                << ": the display window is the whole map";
            if (!covers) msg << ", pixels outside the data window are 0";
            if (outside) msg << ", data outside the display window is dropped";
            const std::string line = one_line(msg.str());
            if (o.warn) o.warn(line);
            else std::fprintf(stderr, "zhc: warning: %s\n", line.c_str());
            img = to_display_window(img, dw, disp);
        }
        if (Status s = check_finite(name, img, o, info); !s) return s.error();
        if (Status s = apply_colour_conversion(name, *colour, img); !s) return s.error();
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

}  // namespace

Sh3Radiance project_envmap(const Image& image, int threads) {
    if (image.layout == EnvmapLayout::kCubeOpenExr)
        return project_cube_openexr(image.rgb.data(), image.width, static_cast<size_t>(image.width) * 3, threads);
    if (image.layout == EnvmapLayout::kCubeVulkan)
        return project_cube(kCubeLayoutVulkan, image.rgb.data(), image.width, static_cast<size_t>(image.width) * 3,
                            threads);
    return project_latlong(image.rgb.data(), image.width, image.height, static_cast<size_t>(image.width) * 3, threads,
                           image.latlong);
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
    return is_exr(bytes) || is_radiance(bytes) || ktx2_declares_cube(bytes) || ktx1_declares_cube(bytes) ||
           dds_declares_cube(bytes);
}

namespace {
Result<Image> read_envmap_any(std::span<const std::uint8_t> bytes, const std::string& name,
                              const EnvmapReadOptions& options, EnvmapInfo* info) {
    if (bytes.empty()) return make_error(ErrorCode::kTruncated, name + ": file is empty");
    if (is_exr(bytes)) return read_exr(bytes, name, options, info);
    if (is_radiance(bytes)) return read_hdr(bytes, name, options, info);
    if (is_ktx2(bytes) || is_ktx1(bytes) || is_dds(bytes)) {
        auto img = is_ktx2(bytes)   ? read_ktx2_cube(bytes, name, options, info)
                   : is_ktx1(bytes) ? read_ktx1_cube(bytes, name, options, info)
                                    : read_dds_cube(bytes, name, options, info);
        if (!img) return img.error();
        if (Status s = check_finite(name, *img, options, info); !s) return s.error();
        return img;
    }
    return make_error(ErrorCode::kBadFormat,
                      name + ": not an OpenEXR, Radiance .hdr, KTX2, KTX 1 or DDS image (unknown magic bytes)" + git_lfs_hint(bytes));
}
}  // namespace

Result<Image> read_envmap_memory(std::span<const std::uint8_t> bytes, const std::string& name,
                                 const EnvmapReadOptions& options, EnvmapInfo* info) {
    auto img = read_envmap_any(bytes, name, options, info);
    if (img && img->layout == EnvmapLayout::kLatLong) img->latlong = options.latlong;
    return img;
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

}  // namespace zhc
