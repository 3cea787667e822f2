// zhc/formats/envmap/envmap.h — environment maps: OpenEXR and Radiance .hdr in, OpenEXR out.
//
// Orientation (also in codec/sh/sh.h and the README): a latitude-longitude map, row 0 at the top
// (+Z, zhc is Z-up), the centre column looking along +X, longitude decreasing left to right:
//   phi = pi (1 - 2 (col + 0.5) / W),  theta = pi (row + 0.5) / H,
//   direction = (sin theta cos phi, sin theta sin phi, cos theta).
// That is OpenEXR's Imf::LatLongMap orientation with (x, y, z)_zhc = (z, x, y)_OpenEXR.
// EnvmapReadOptions::latlong selects the glTF ecosystem's orientation instead (phi = pi (3/2 - 2u),
// codec/sh/sh.h LatLongConvention); the image keeps it in Image::latlong.
// Any width and height are accepted (not only 2:1).
//
// EXR files whose "envmap" attribute says cube (OpenEXR's cube layout, N x 6N, see
// codec/sh/cubemap.h) are read as cube maps: Image::layout tells the two apart, and
// project_envmap projects either with exact per-pixel solid angles. KTX2 and DDS cube maps (the
// containers game engines use for reflection/irradiance probes) are read in the graphics APIs'
// cube layout (kCubeVulkan, codec/sh/cubemap.h; formats/envmap/envmap_cube.h lists the variants).
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments. The only process-wide state touched is OpenEXR's own
// global thread pool (grown, never shrunk, when a call asks for more threads; OpenEXR
// guards it), which never changes the bytes read or written.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "codec/sh/sh.h"
#include "codec/status.h"

namespace zhc {

enum class EnvmapLayout {
    kLatLong,     // docs/conventions.md
    kCubeOpenExr,  // OpenEXR's cube layout: width N, height 6N, faces +X -X +Y -Y +Z -Z (codec/sh/cubemap.h)
    kCubeVulkan    // KTX2 / DDS: width N, height 6N, faces +X -X +Y -Y +Z -Z of Vulkan's / D3D's table
};

// An owning RGB float image, interleaved, rows top to bottom.
struct Image {
    int width = 0;
    int height = 0;
    EnvmapLayout layout = EnvmapLayout::kLatLong;
    LatLongConvention latlong = LatLongConvention::kOpenExr;  // how a kLatLong image's columns turn
    std::vector<float> rgb;  // width * height * 3
    float* row(int y) { return rgb.data() + static_cast<size_t>(y) * static_cast<size_t>(width) * 3; }
    const float* row(int y) const { return rgb.data() + static_cast<size_t>(y) * static_cast<size_t>(width) * 3; }
};

enum class NonFinitePolicy {
    kReject,       // default: NaN/Inf pixels are an error naming the first one
    kReplaceZero,  // replace each non-finite channel value by 0 and count them
};

// How an 8-bit (LDR) cube map's texels become radiance (docs/inputs.md "8-bit cube maps"):
// kAsFormat (default): the format's transfer function (sRGB formats: the sRGB EOTF; UNORM: as is);
// kSrgb / kLinear: that transfer function whatever the format says; kRgbm: rgb * a * range;
// kRgbd: rgb * (range / 255) / a (rgb by the format's transfer function, alpha linear). Float
// formats ignore it.
enum class LdrEncoding { kAsFormat, kSrgb, kLinear, kRgbm, kRgbd };
struct LdrDecoding {
    LdrEncoding encoding = LdrEncoding::kAsFormat;
    float range = 1.0f;  // kRgbm / kRgbd: the largest value the encoding holds
};
// "auto", "srgb", "linear", "rgbm:RANGE", "rgbd:RANGE" (RANGE a finite number in (0, 65504]).
// False for anything else.
bool parse_ldr_decoding(const std::string& text, LdrDecoding* out);
std::string ldr_decoding_name(const LdrDecoding& d);

struct EnvmapReadOptions {
    std::uint64_t max_pixels = std::uint64_t(1) << 26;  // 8192 x 8192; checked before allocating
    std::uint64_t max_file_bytes = std::uint64_t(2) << 30;
    NonFinitePolicy non_finite = NonFinitePolicy::kReject;
    // Multi-part EXR: the part to read, by its "name" attribute (or by its index when no part has
    // that name). Empty: the first part with R, G, B or Y channels that is not deep.
    std::string part;
    // The orientation of a lat-long map (cube maps have one fixed by their format).
    LatLongConvention latlong = LatLongConvention::kOpenExr;
    // 8-bit cube maps: how texels become radiance (LdrDecoding above).
    LdrDecoding ldr;
    // Non-fatal findings, one line each naming the file (an EXR whose data window differs from its
    // display window). Empty: printed on stderr as "zhc: warning: <line>".
    std::function<void(const std::string&)> warn;
};

struct EnvmapInfo {
    std::string format;       // "openexr", "radiance-hdr", "ktx2", "ktx1" or "dds"
    std::string compression;  // EXR compression name, "rle" or "flat" for .hdr
    std::string channels;     // e.g. "RGBA half"
    std::uint64_t replaced_non_finite = 0;  // channel values replaced by 0 (NonFinitePolicy::kReplaceZero)
    std::uint64_t non_finite_pixels = 0;    // pixels with at least one such value
    std::string layout = "lat-long";  // or "cube" (OpenEXR's or, for KTX2 / DDS, the APIs' layout)
    std::string part;                 // EXR: the part read ("#index" when it has no name)
    // EXR colour: the chromaticities attribute (red, green, blue, white as x, y pairs) when present,
    // and what the reader did with it (see docs/inputs.md "Colour spaces").
    bool has_chromaticities = false;
    std::array<float, 8> chromaticities{};
    std::string colour_conversion;
    // EXR windows, "(xmin ymin) - (xmax ymax)": the display window is what maps to the sphere.
    std::string data_window, display_window;
};

// Reads an EXR (RGB or RGBA or Y or luminance/chroma Y RY BY, half/float/uint, any compression
// OpenEXR supports, scanline or tiled, single- or multi-part, lat-long or cube) or a Radiance .hdr
// (RGBE or XYZE, any of the eight orientations) or a KTX2 / DDS cube map (formats/envmap/envmap_cube.h),
// or a KTX 1 cube map, detected by its magic bytes (not by the extension). Bytes after the data are an error (kTrailingBytes). See docs/inputs.md.
// EXR pixels come out in zhc's working space (linear Rec. 709 primaries, D65 white), converted from
// the file's chromaticities; the image is the EXR's display window (pixels outside the data window
// are 0).
Result<Image> read_envmap(const std::string& path, const EnvmapReadOptions& options = {},
                          EnvmapInfo* info = nullptr);
// The same from bytes in memory; `name` is used in messages. Safe for untrusted input.
Result<Image> read_envmap_memory(std::span<const std::uint8_t> bytes, const std::string& name,
                                 const EnvmapReadOptions& options = {}, EnvmapInfo* info = nullptr);

// SH3 radiance projection of an image read by read_envmap, lat-long (in its Image::latlong
// orientation) or cube.
Sh3Radiance project_envmap(const Image& image, int threads = 1);

// The image as a width x height lat-long map (a lat-long image is returned unchanged when the
// size matches, in its own orientation). A cube map is resampled (into kOpenExr orientation): each output pixel is the mean of 4 x 4 point samples of
// the cube (nearest pixel), for consumers that need lat-long pixels (the audit reference).
Image envmap_as_latlong(const Image& image, int width, int height);

// True when the bytes start like an EXR or a Radiance file, or a KTX2 / DDS file whose header says
// cube map (a 2-D KTX2 / DDS is a lightmap texture, not an environment map).
bool looks_like_envmap(std::span<const std::uint8_t> bytes);

// Writes a float RGB OpenEXR (ZIP compression), atomically.
Status write_exr(const std::string& path, const Image& image);
// Writes a Radiance .hdr (RGBE, run-length encoded), atomically.
Status write_hdr(const std::string& path, const Image& image);

}  // namespace zhc
