// zhc/formats/envmap/envmap_cube_internal.h — internal to formats/: what the cube-map readers share
// (envmap_cube.cpp: KTX2 and DDS, and the texel decoding; envmap_cube_ktx1.cpp: KTX 1): the pixel
// formats whatever the container calls them, face sizes, the size limit and the six-face decode.
#pragma once

#include <cstdint>
#include <string>

#include "formats/envmap/envmap_cube.h"

namespace zhc::cube_detail {

// "<name>: <what>" as an error of `code`.
Error fail(ErrorCode code, const std::string& name, const std::string& what);

// The pixel formats read, whatever the container calls them.
enum class Texel {
    kRgba16f, kRgb16f, kRgba32f, kRgb32f, kE5b9g9r9, kBc6hUfloat, kB10g11r11,
    // 8-bit (LDR): decoded by EnvmapReadOptions::ldr and the format's transfer function
    kRgba8, kBgra8, kBgrx8, kRgb8, kBc1, kBc1a, kBc2, kBc3, kBc7
};

struct TexelInfo {
    Texel texel;
    const char* channels;  // for EnvmapInfo
    std::uint64_t bytes;   // per texel, or per 4x4 block
    bool block;
    bool ldr;
};

TexelInfo texel_info(Texel t);

// A texel format and its transfer function (sRGB formats; only 8-bit formats have one).
struct Format {
    Texel texel;
    bool srgb = false;
};

inline std::string channels_name(const TexelInfo& f, bool srgb) {
    return std::string(f.channels) + (f.ldr ? (srgb ? " sRGB" : " UNORM") : "");
}

// Bytes of one face of mip level `level` of a cube of face size n (n <= 2^20: no overflow).
std::uint64_t face_bytes(const TexelInfo& f, std::uint64_t n, int level);
// Mip levels of a face of size n: floor(log2 n) + 1.
int max_levels(std::uint64_t n);

// Decodes the six faces of level 0 (`fb` bytes each, consecutive at `stride`), then, for an 8-bit
// UNORM format read by its own transfer function, warns that it was read as linear.
Status decode_cube(const TexelInfo& f, const Format& fmt, const std::uint8_t* level0, std::uint64_t stride, int n, Image& img,
                   const std::string& name, const EnvmapReadOptions& o);
// Face size n against the pixel limit (6 n^2 pixels), before any allocation.
Status check_cube_size(const std::string& name, std::uint64_t n, const EnvmapReadOptions& o);
// An all-zero cube image of face size n (Vulkan face order).
Image make_cube(int n);

}  // namespace zhc::cube_detail
