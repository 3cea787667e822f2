// OpenEXR (OpenEXR 3) and Radiance .hdr (stb_image) environment-map I/O.
#include "envmap.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfTestFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>

#include "exr_memory.h"
#include "file_io.h"

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

Result<Image> read_exr(std::span<const std::uint8_t> bytes, const std::string& name, const EnvmapReadOptions& o,
                       EnvmapInfo* info) {
    if (Status s = validate_exr_header(bytes, name, [&](std::uint64_t w, std::uint64_t h) { return check_size(name, w, h, o); });
        !s)
        return s.error();
    try {
        // Bound what OpenEXR itself allocates while reading the header (its line-offset table
        // grows with the height): 2^20 per side, far above any real map; zhc's own pixel limit is
        // checked below, before the pixel buffer is allocated.
        Imf::Header::setMaxImageSize(1 << 20, 1 << 20);
        Imf::Header::setMaxTileSize(1 << 20, 1 << 20);
        ExrMemoryStream stream(bytes, name);
        Imf::InputFile file(stream);
        const Imath::Box2i dw = file.header().dataWindow();
        const std::int64_t w = std::int64_t(dw.max.x) - dw.min.x + 1, h = std::int64_t(dw.max.y) - dw.min.y + 1;
        if (w <= 0 || h <= 0) return make_error(ErrorCode::kBadFormat, name + ": empty data window");
        if (Status s = check_size(name, static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h), o); !s)
            return s.error();
        const Imf::ChannelList& channels = file.header().channels();
        const bool has_rgb = channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
        const bool has_y = channels.findChannel("Y") != nullptr;
        if (!has_rgb && !has_y)
            return make_error(ErrorCode::kUnsupported, name + ": OpenEXR file has no R, G, B (or Y) channels");
        for (const char* c : {"R", "G", "B", "Y"}) {
            const Imf::Channel* ch = channels.findChannel(c);
            if (ch && (ch->xSampling != 1 || ch->ySampling != 1))
                return make_error(ErrorCode::kUnsupported, name + ": channel " + c + " is subsampled");
        }
        Image img;
        img.width = static_cast<int>(w);
        img.height = static_cast<int>(h);
        img.rgb.assign(static_cast<size_t>(w * h * 3), 0.0f);
        Imf::FrameBuffer fb;
        // Base pointer such that base + x*xs + y*ys addresses pixel (x, y) of the data window.
        char* base = reinterpret_cast<char*>(img.rgb.data()) -
                     (std::int64_t(dw.min.x) + std::int64_t(dw.min.y) * w) * 3 * std::int64_t(sizeof(float));
        const size_t xs = 3 * sizeof(float), ys = static_cast<size_t>(w) * 3 * sizeof(float);
        if (has_rgb) {
            fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
            fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
            fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
        } else {
            fb.insert("Y", Imf::Slice(Imf::FLOAT, base, xs, ys));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        if (!has_rgb)
            for (size_t i = 0; i < img.rgb.size(); i += 3) img.rgb[i + 1] = img.rgb[i + 2] = img.rgb[i];
        if (info) {
            info->format = "openexr";
            info->compression = compression_name(file.header().compression());
            const Imf::Channel* c = channels.findChannel(has_rgb ? "R" : "Y");
            info->channels = std::string(has_rgb ? (channels.findChannel("A") ? "RGBA" : "RGB") : "Y") +
                             (c->type == Imf::HALF ? " half" : c->type == Imf::FLOAT ? " float" : " uint");
        }
        if (Status s = check_finite(name, img, o, info); !s) return s.error();
        return img;
    } catch (const std::exception& e) {
        std::string what = e.what();
        for (char& ch : what)
            if (ch == '\n' || ch == '\r') ch = ' ';
        if (what.find("exceeds the maximum") != std::string::npos)
            return make_error(ErrorCode::kTooLarge, name + ": OpenEXR image too large (" + what + ")");
        if (what.find("unexpected end of file") != std::string::npos)
            return make_error(ErrorCode::kTruncated, name + ": OpenEXR file is truncated (" + what + ")");
        return make_error(ErrorCode::kBadFormat, name + ": cannot read OpenEXR data (" + what + ")");
    }
}

// stb_image silently fills rows that a truncated .hdr is missing; walk the scanline structure
// first (new-style RLE or flat RGBE pixels) so truncation is an error. Header: lines up to an
// empty line, then the resolution line.
Status validate_hdr_scanlines(std::span<const std::uint8_t> b, const std::string& name, int width, int height) {
    size_t pos = 0;
    // Skip header lines until the blank line, then the resolution line.
    bool blank = false;
    while (pos < b.size() && !blank) {
        const size_t start = pos;
        while (pos < b.size() && b[pos] != '\n') ++pos;
        blank = pos == start;
        ++pos;
    }
    while (pos < b.size() && b[pos] != '\n') ++pos;
    ++pos;
    auto truncated = [&](int row) {
        return make_error(ErrorCode::kTruncated, name + ": Radiance .hdr data ends in scanline " + std::to_string(row) +
                                                     " of " + std::to_string(height));
    };
    for (int row = 0; row < height; ++row) {
        if (pos + 4 > b.size()) return truncated(row);
        const bool rle = width >= 8 && width < 32768 && b[pos] == 2 && b[pos + 1] == 2 && (b[pos + 2] & 0x80) == 0;
        if (!rle) {
            // Flat (or old-style RLE, which only shortens data): at most 4 bytes per pixel remain.
            const std::uint64_t need = static_cast<std::uint64_t>(width) * 4;
            if (pos + need > b.size()) {
                // Old-style RLE can be shorter than flat data; let stb decide when this is the last row.
                return row == height - 1 ? Status(Ok{}) : Status(truncated(row));
            }
            pos += need;
            continue;
        }
        pos += 4;
        for (int channel = 0; channel < 4; ++channel) {
            int filled = 0;
            while (filled < width) {
                if (pos >= b.size()) return truncated(row);
                int count = b[pos++];
                if (count > 128) {
                    count -= 128;
                    if (pos >= b.size()) return truncated(row);
                    ++pos;
                } else {
                    if (count == 0 || pos + static_cast<size_t>(count) > b.size()) return truncated(row);
                    pos += static_cast<size_t>(count);
                }
                filled += count;
            }
            if (filled != width)
                return make_error(ErrorCode::kBadFormat, name + ": Radiance .hdr run overruns scanline " + std::to_string(row));
        }
    }
    return Ok{};
}

Result<Image> read_hdr(std::span<const std::uint8_t> bytes, const std::string& name, const EnvmapReadOptions& o,
                       EnvmapInfo* info) {
    if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
        return make_error(ErrorCode::kTooLarge, name + ": file too large for the .hdr reader");
    const int len = static_cast<int>(bytes.size());
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes.data(), len, &w, &h, &comp))
        return make_error(ErrorCode::kBadFormat,
                          name + ": malformed Radiance .hdr header (" + stbi_failure_reason() + ")");
    if (Status s = check_size(name, static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h), o); !s)
        return s.error();
    if (Status s = validate_hdr_scanlines(bytes, name, w, h); !s) return s.error();
    int x = 0, y = 0, n = 0;
    std::unique_ptr<float, void (*)(void*)> data(stbi_loadf_from_memory(bytes.data(), len, &x, &y, &n, 3),
                                                 stbi_image_free);
    if (!data) return make_error(ErrorCode::kBadFormat, name + ": cannot decode Radiance .hdr (" +
                                                             std::string(stbi_failure_reason()) + ")");
    Image img;
    img.width = x;
    img.height = y;
    img.rgb.assign(data.get(), data.get() + static_cast<size_t>(x) * static_cast<size_t>(y) * 3);
    if (info) {
        info->format = "radiance-hdr";
        info->compression = "rle";
        info->channels = "RGBE";
    }
    if (Status s = check_finite(name, img, o, info); !s) return s.error();
    return img;
}

}  // namespace

bool looks_like_envmap(std::span<const std::uint8_t> bytes) { return is_exr(bytes) || is_radiance(bytes); }

Result<Image> read_envmap_memory(std::span<const std::uint8_t> bytes, const std::string& name,
                                 const EnvmapReadOptions& options, EnvmapInfo* info) {
    if (bytes.empty()) return make_error(ErrorCode::kTruncated, name + ": file is empty");
    if (is_exr(bytes)) return read_exr(bytes, name, options, info);
    if (is_radiance(bytes)) return read_hdr(bytes, name, options, info);
    return make_error(ErrorCode::kBadFormat, name + ": not an OpenEXR or Radiance .hdr image (unknown magic bytes)");
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
