// KTX2 and DDS environment cube maps (formats/envmap/envmap_cube.h), and the texel decoding every
// cube-map reader shares (envmap_cube_internal.h; KTX 1: envmap_cube_ktx1.cpp). Written from the
// KTX 2.0 specification (Khronos), Microsoft's DDS documentation (DDS_HEADER, DDS_HEADER_DXT10,
// DDS_PIXELFORMAT) and the Vulkan / D3D cube-map face tables; standard library plus zhc's BC6H
// decoder.
#include "formats/envmap/envmap_cube.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include <zstd.h>

#include "codec/lightmap/bc6h.h"
#include "formats/envmap/bc7.h"
#include "formats/lightmap/ktx2.h"
#include "formats/envmap/envmap_ldr.h"
#include "codec/sh/cubemap.h"
#include "formats/envmap/envmap_cube_internal.h"
#include "formats/io/le_bytes.h"

namespace zhc {

namespace cube_detail {

Error fail(ErrorCode code, const std::string& name, const std::string& what) { return make_error(code, name + ": " + what); }

TexelInfo texel_info(Texel t) {
    switch (t) {
        case Texel::kRgba16f: return {t, "RGBA half", 8, false, false};
        case Texel::kRgb16f: return {t, "RGB half", 6, false, false};
        case Texel::kRgba32f: return {t, "RGBA float", 16, false, false};
        case Texel::kRgb32f: return {t, "RGB float", 12, false, false};
        case Texel::kE5b9g9r9: return {t, "RGB9E5", 4, false, false};
        case Texel::kBc6hUfloat: return {t, "BC6H ufloat", 16, true, false};
        case Texel::kB10g11r11: return {t, "B10G11R11 ufloat", 4, false, false};
        case Texel::kRgba8: return {t, "RGBA8", 4, false, true};
        case Texel::kBgra8: return {t, "BGRA8", 4, false, true};
        case Texel::kBgrx8: return {t, "BGRX8", 4, false, true};
        case Texel::kRgb8: return {t, "RGB8", 3, false, true};
        case Texel::kBc1: return {t, "BC1 RGB", 8, true, true};
        case Texel::kBc1a: return {t, "BC1 RGBA", 8, true, true};
        case Texel::kBc2: return {t, "BC2", 16, true, true};
        case Texel::kBc7: return {t, "BC7", 16, true, true};
        default: return {t, "BC3", 16, true, true};
    }
}

// Bytes of one face of mip level `level` of a cube of face size n (n <= 2^20: no overflow).
std::uint64_t face_bytes(const TexelInfo& f, std::uint64_t n, int level) {
    const std::uint64_t m = std::max<std::uint64_t>(1, n >> level);
    if (f.block) return ((m + 3) / 4) * ((m + 3) / 4) * f.bytes;
    return m * m * f.bytes;
}

int max_levels(std::uint64_t n) {
    int l = 1;
    while ((n >> l) > 0) ++l;
    return l;  // floor(log2 n) + 1
}

}  // namespace cube_detail

using namespace cube_detail;

namespace {
using le::get32;
using le::get64;
constexpr auto get16 = le::load16;
constexpr auto getf32 = le::load_f32;

constexpr std::uint8_t kKtx2Identifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};

// E5B9G9R9 (Vulkan) / R9G9B9E5_SHAREDEXP (DXGI): R bits 0-8, G 9-17, B 18-26, exponent 27-31;
// value = mantissa * 2^(exponent - 15 - 9).
void decode_e5b9g9r9(std::uint32_t v, float out[3]) {
    const int e = static_cast<int>(v >> 27);
    for (int c = 0; c < 3; ++c) out[c] = std::ldexp(static_cast<float>((v >> (9 * c)) & 0x1ff), e - 24);
}

// The encoded RGBA (in [0, 1]) of an uncompressed 8-bit texel.
void ldr_texel(Texel t, const std::uint8_t* p, float rgba[4]) {
    constexpr float k = 1.0f / 255.0f;
    switch (t) {
        case Texel::kRgba8: for (int c = 0; c < 4; ++c) rgba[c] = p[c] * k; break;
        case Texel::kRgb8: for (int c = 0; c < 3; ++c) rgba[c] = p[c] * k; rgba[3] = 1.0f; break;
        default:  // BGRA / BGRX
            rgba[0] = p[2] * k, rgba[1] = p[1] * k, rgba[2] = p[0] * k;
            rgba[3] = t == Texel::kBgrx8 ? 1.0f : p[3] * k;
            break;
    }
}

// Decodes one face (level 0, face size n) from `src` (face_bytes(f, n, 0) bytes, rows packed)
// into rows face*n .. face*n + n - 1 of img. 8-bit formats by `ldr` and `srgb`; kInvalidValue
// naming the texel for an RGBD texel with alpha 0.
Status decode_face(const TexelInfo& f, bool srgb, const LdrDecoding& ldr, const std::uint8_t* src, int n, int face, Image& img,
                   const std::string& name) {
    const size_t nn = static_cast<size_t>(n);
    auto put_ldr = [&](const float rgba[4], size_t r, size_t c) -> Status {
        if (!ldr::decode_ldr_texel(rgba, srgb, ldr, img.row(face * n + static_cast<int>(r)) + 3 * c))
            return fail(ErrorCode::kInvalidValue, name, "face " + std::to_string(face) + " texel (" + std::to_string(c) + ", " +
                                                            std::to_string(r) + ") has alpha 0, which RGBD (--ldr-encoding " +
                                                            ldr_decoding_name(ldr) + ") cannot decode");
        return Ok{};
    };
    if (f.block && f.texel == Texel::kBc6hUfloat) {
        const auto half = bc6h::decode_image(src, static_cast<size_t>(face_bytes(f, nn, 0)), n, n);
        for (size_t r = 0; r < nn; ++r) {
            float* out = img.row(face * n + static_cast<int>(r));
            for (size_t i = 0; i < 3 * nn; ++i) out[i] = bc6h::half_to_float(half[r * 3 * nn + i]);
        }
        return Ok{};
    }
    if (f.block) {
        const size_t bw = (nn + 3) / 4;
        float rgba[16][4];
        for (size_t by = 0; by < bw; ++by)
            for (size_t bx = 0; bx < bw; ++bx) {
                const std::uint8_t* blk = src + (by * bw + bx) * f.bytes;
                switch (f.texel) {
                    case Texel::kBc1: ldr::decode_bc1(blk, false, rgba); break;
                    case Texel::kBc1a: ldr::decode_bc1(blk, true, rgba); break;
                    case Texel::kBc2: ldr::decode_bc2(blk, rgba); break;
                    case Texel::kBc7: {
                        std::uint8_t texels[16][4];
                        bc7::decode_block(blk, texels);
                        for (int t = 0; t < 16; ++t)
                            for (int c = 0; c < 4; ++c) rgba[t][c] = static_cast<float>(texels[t][c]) / 255.0f;
                        break;
                    }
                    default: ldr::decode_bc3(blk, rgba); break;
                }
                for (size_t y = 0; y < 4 && 4 * by + y < nn; ++y)
                    for (size_t x = 0; x < 4 && 4 * bx + x < nn; ++x)
                        if (Status s = put_ldr(rgba[4 * y + x], 4 * by + y, 4 * bx + x); !s) return s;
            }
        return Ok{};
    }
    for (size_t r = 0; r < nn; ++r) {
        float* out = img.row(face * n + static_cast<int>(r));
        const std::uint8_t* p = src + r * nn * f.bytes;
        for (size_t c = 0; c < nn; ++c, p += f.bytes) {
            float* o = out + 3 * c;
            if (f.ldr) {
                float rgba[4];
                ldr_texel(f.texel, p, rgba);
                if (Status s = put_ldr(rgba, r, c); !s) return s;
                continue;
            }
            switch (f.texel) {
                case Texel::kRgba16f:
                case Texel::kRgb16f:
                    for (int k = 0; k < 3; ++k) o[k] = bc6h::half_to_float(get16(p + 2 * k));
                    break;
                case Texel::kRgba32f:
                case Texel::kRgb32f:
                    for (int k = 0; k < 3; ++k) o[k] = getf32(p + 4 * k);
                    break;
                case Texel::kB10g11r11: ldr::decode_r11g11b10(get32({p, 4}, 0), o); break;
                default: decode_e5b9g9r9(get32({p, 4}, 0), o); break;
            }
        }
    }
    return Ok{};
}

}  // namespace

namespace cube_detail {

// Decodes the six faces of level 0 (`fb` bytes each, consecutive at `stride`), then, for an 8-bit
// UNORM format read by its own transfer function, warns that it was read as linear.
Status decode_cube(const TexelInfo& f, const Format& fmt, const std::uint8_t* level0, std::uint64_t stride, int n, Image& img,
                   const std::string& name, const EnvmapReadOptions& o) {
    for (int face = 0; face < 6; ++face)
        if (Status s = decode_face(f, fmt.srgb, o.ldr, level0 + static_cast<std::uint64_t>(face) * stride, n, face, img, name); !s)
            return s;
    if (f.ldr && !fmt.srgb && o.ldr.encoding == LdrEncoding::kAsFormat) {
        const std::string line = name + ": 8-bit UNORM cube map (" + channels_name(f, false) +
                                 ") read as linear values, as its format says; if it stores sRGB colours or an HDR "
                                 "encoding, say so with --ldr-encoding srgb|rgbm:RANGE|rgbd:RANGE";
        if (o.warn) o.warn(line);
        else std::fprintf(stderr, "zhc: warning: %s\n", line.c_str());
    }
    return Ok{};
}

// Face size n against the pixel limit (6 n^2 pixels), before any allocation.
Status check_cube_size(const std::string& name, std::uint64_t n, const EnvmapReadOptions& o) {
    if (n > (std::uint64_t(1) << 20) || 6 * n * n > o.max_pixels)
        return fail(ErrorCode::kTooLarge, name, "cube map of face size " + std::to_string(n) + " (6 x " + std::to_string(n) +
                                                    "^2 pixels) exceeds the limit of " + std::to_string(o.max_pixels) +
                                                    " pixels");
    return Ok{};
}

Image make_cube(int n) {
    Image img;
    img.width = n;
    img.height = 6 * n;
    img.layout = EnvmapLayout::kCubeVulkan;
    img.rgb.assign(static_cast<size_t>(n) * static_cast<size_t>(6 * n) * 3, 0.0f);
    return img;
}

}  // namespace cube_detail

namespace {

// ---- KTX2 ----

constexpr std::size_t kKtx2HeaderBytes = 80;  // identifier, 9 u32 fields, index (4 u32, 2 u64)

Result<Format> ktx2_texel(std::uint32_t vk, const std::string& name) {
    switch (vk) {
        case 97: return Format{Texel::kRgba16f};   // VK_FORMAT_R16G16B16A16_SFLOAT
        case 90: return Format{Texel::kRgb16f};    // VK_FORMAT_R16G16B16_SFLOAT
        case 109: return Format{Texel::kRgba32f};  // VK_FORMAT_R32G32B32A32_SFLOAT
        case 106: return Format{Texel::kRgb32f};   // VK_FORMAT_R32G32B32_SFLOAT
        case 123: return Format{Texel::kE5b9g9r9}; // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
        case 122: return Format{Texel::kB10g11r11}; // VK_FORMAT_B10G11R11_UFLOAT_PACK32
        case 143: return Format{Texel::kBc6hUfloat};
        case 37: return Format{Texel::kRgba8};         // VK_FORMAT_R8G8B8A8_UNORM
        case 43: return Format{Texel::kRgba8, true};   // VK_FORMAT_R8G8B8A8_SRGB
        case 44: return Format{Texel::kBgra8};         // VK_FORMAT_B8G8R8A8_UNORM
        case 50: return Format{Texel::kBgra8, true};   // VK_FORMAT_B8G8R8A8_SRGB
        case 23: return Format{Texel::kRgb8};          // VK_FORMAT_R8G8B8_UNORM
        case 29: return Format{Texel::kRgb8, true};    // VK_FORMAT_R8G8B8_SRGB
        case 131: return Format{Texel::kBc1};          // VK_FORMAT_BC1_RGB_UNORM_BLOCK
        case 132: return Format{Texel::kBc1, true};    // VK_FORMAT_BC1_RGB_SRGB_BLOCK
        case 133: return Format{Texel::kBc1a};         // VK_FORMAT_BC1_RGBA_UNORM_BLOCK
        case 134: return Format{Texel::kBc1a, true};   // VK_FORMAT_BC1_RGBA_SRGB_BLOCK
        case 135: return Format{Texel::kBc2};          // VK_FORMAT_BC2_UNORM_BLOCK
        case 136: return Format{Texel::kBc2, true};    // VK_FORMAT_BC2_SRGB_BLOCK
        case 137: return Format{Texel::kBc3};          // VK_FORMAT_BC3_UNORM_BLOCK
        case 138: return Format{Texel::kBc3, true};    // VK_FORMAT_BC3_SRGB_BLOCK
        case 144:
            return fail(ErrorCode::kUnsupported, name,
                        "KTX2 vkFormat 144 (BC6H_SFLOAT_BLOCK, byte 12) is not supported: zhc's BC6H decoder reads "
                        "unsigned BC6H only");
        case 145: return Format{Texel::kBc7};          // VK_FORMAT_BC7_UNORM_BLOCK
        case 146: return Format{Texel::kBc7, true};    // VK_FORMAT_BC7_SRGB_BLOCK
        default:
            return fail(ErrorCode::kUnsupported, name,
                        "KTX2 vkFormat " + std::to_string(vk) + " (" +
                            (vk_format_name(vk).empty() ? std::string() : vk_format_name(vk) + ", ") +
                            "byte 12) is not supported for cube maps (R16G16B16A16_SFLOAT, R16G16B16_SFLOAT, "
                            "R32G32B32A32_SFLOAT, R32G32B32_SFLOAT, E5B9G9R9_UFLOAT_PACK32, B10G11R11_UFLOAT_PACK32, "
                            "BC6H_UFLOAT_BLOCK, R8G8B8A8, B8G8R8A8, R8G8B8, BC1, BC2, BC3, BC7 UNORM / SRGB are)");
    }
}

std::uint32_t ktx2_type_size(Texel t) {
    switch (t) {
        case Texel::kRgba16f:
        case Texel::kRgb16f: return 2;
        case Texel::kRgba32f:
        case Texel::kRgb32f:
        case Texel::kE5b9g9r9:
        case Texel::kB10g11r11: return 4;
        default: return 1;
    }
}

// ---- DDS ----

constexpr std::uint32_t kDdsMagic = 0x20534444;          // "DDS "
constexpr std::uint32_t kFourCcDx10 = 0x30315844;        // "DX10"
constexpr std::uint32_t kDdpfFourCc = 0x4;
constexpr std::uint32_t kDdpfAlphaPixels = 0x1;
constexpr std::uint32_t kDdpfRgb = 0x40;
constexpr std::uint32_t kFourCcDxt1 = 0x31545844;  // "DXT1"
constexpr std::uint32_t kFourCcDxt3 = 0x33545844;  // "DXT3"
constexpr std::uint32_t kFourCcDxt5 = 0x35545844;  // "DXT5"

// A FourCC as its four characters when they are printable, else its number.
std::string fourcc_text(std::uint32_t v) {
    std::string t;
    for (int k = 0; k < 4; ++k) {
        const char c = static_cast<char>((v >> (8 * k)) & 0xff);
        if (c < 0x20 || c > 0x7e) return std::to_string(v);
        t += c;
    }
    return std::to_string(v) + " '" + t + "'";
}
constexpr std::uint32_t kCaps2Cubemap = 0x200;
constexpr std::uint32_t kCaps2AllFaces = 0xFC00;         // +X -X +Y -Y +Z -Z
constexpr std::uint32_t kCaps2Volume = 0x200000;
constexpr std::uint32_t kMiscTextureCube = 0x4;

Result<Format> dxgi_texel(std::uint32_t f, const std::string& name) {
    switch (f) {
        case 10: return Format{Texel::kRgba16f};  // DXGI_FORMAT_R16G16B16A16_FLOAT
        case 2: return Format{Texel::kRgba32f};   // DXGI_FORMAT_R32G32B32A32_FLOAT
        case 6: return Format{Texel::kRgb32f};    // DXGI_FORMAT_R32G32B32_FLOAT
        case 67: return Format{Texel::kE5b9g9r9}; // DXGI_FORMAT_R9G9B9E5_SHAREDEXP
        case 26: return Format{Texel::kB10g11r11}; // DXGI_FORMAT_R11G11B10_FLOAT
        case 95: return Format{Texel::kBc6hUfloat};
        case 28: return Format{Texel::kRgba8};        // DXGI_FORMAT_R8G8B8A8_UNORM
        case 29: return Format{Texel::kRgba8, true};  // DXGI_FORMAT_R8G8B8A8_UNORM_SRGB
        case 87: return Format{Texel::kBgra8};        // DXGI_FORMAT_B8G8R8A8_UNORM
        case 91: return Format{Texel::kBgra8, true};  // DXGI_FORMAT_B8G8R8A8_UNORM_SRGB
        case 88: return Format{Texel::kBgrx8};        // DXGI_FORMAT_B8G8R8X8_UNORM
        case 93: return Format{Texel::kBgrx8, true};  // DXGI_FORMAT_B8G8R8X8_UNORM_SRGB
        case 71: return Format{Texel::kBc1a};         // DXGI_FORMAT_BC1_UNORM
        case 72: return Format{Texel::kBc1a, true};   // DXGI_FORMAT_BC1_UNORM_SRGB
        case 74: return Format{Texel::kBc2};          // DXGI_FORMAT_BC2_UNORM
        case 75: return Format{Texel::kBc2, true};    // DXGI_FORMAT_BC2_UNORM_SRGB
        case 77: return Format{Texel::kBc3};          // DXGI_FORMAT_BC3_UNORM
        case 78: return Format{Texel::kBc3, true};    // DXGI_FORMAT_BC3_UNORM_SRGB
        case 96:
            return fail(ErrorCode::kUnsupported, name,
                        "DDS DXGI format 96 (BC6H_SF16, byte 128) is not supported: zhc's BC6H decoder reads unsigned "
                        "BC6H only");
        case 98: return Format{Texel::kBc7};          // DXGI_FORMAT_BC7_UNORM
        case 99: return Format{Texel::kBc7, true};    // DXGI_FORMAT_BC7_UNORM_SRGB
        default:
            return fail(ErrorCode::kUnsupported, name,
                        "DDS DXGI format " + std::to_string(f) +
                            " (byte 128) is not supported for cube maps (R16G16B16A16_FLOAT, R32G32B32A32_FLOAT, "
                            "R32G32B32_FLOAT, R9G9B9E5_SHAREDEXP, R11G11B10_FLOAT, BC6H_UF16, R8G8B8A8, B8G8R8A8, "
                            "B8G8R8X8, BC1, BC2, BC3, BC7 UNORM / UNORM_SRGB are)");
    }
}

}  // namespace

bool is_ktx2(std::span<const std::uint8_t> b) { return b.size() >= 12 && std::memcmp(b.data(), kKtx2Identifier, 12) == 0; }
bool is_dds(std::span<const std::uint8_t> b) { return b.size() >= 4 && get32(b, 0) == kDdsMagic; }


bool ktx2_declares_cube(std::span<const std::uint8_t> b) { return is_ktx2(b) && b.size() >= 40 && get32(b, 36) == 6; }

bool dds_declares_cube(std::span<const std::uint8_t> b) {
    if (!is_dds(b) || b.size() < 128) return false;
    if ((get32(b, 112) & kCaps2Cubemap) != 0) return true;
    return b.size() >= 148 && (get32(b, 80) & kDdpfFourCc) && get32(b, 84) == kFourCcDx10 &&
           (get32(b, 136) & kMiscTextureCube) != 0;
}

Result<Image> read_ktx2_cube(std::span<const std::uint8_t> b, const std::string& name, const EnvmapReadOptions& o,
                             EnvmapInfo* info) {
    if (!is_ktx2(b)) return fail(ErrorCode::kBadFormat, name, "not a KTX2 file (bad identifier at byte 0)");
    if (b.size() < kKtx2HeaderBytes)
        return fail(ErrorCode::kTruncated, name, "KTX2 header truncated (file of " + std::to_string(b.size()) +
                                                     " bytes ends before byte 80)");
    const std::uint32_t vk = get32(b, 12), type_size = get32(b, 16), w = get32(b, 20), h = get32(b, 24),
                        depth = get32(b, 28), layers = get32(b, 32), faces = get32(b, 36), level_count = get32(b, 40),
                        scheme = get32(b, 44);
    if (faces != 6) {
        if (faces == 1)
            return fail(ErrorCode::kUnsupported, name, "KTX2 faceCount 1 (byte 36): a 2-D texture, not a cube map");
        return fail(ErrorCode::kBadFormat, name, "KTX2 faceCount " + std::to_string(faces) + " (byte 36) is neither 1 nor 6");
    }
    if (w == 0 || h == 0)
        return fail(ErrorCode::kBadFormat, name, "KTX2 cube map with pixelWidth " + std::to_string(w) + " / pixelHeight " +
                                                     std::to_string(h) + " (bytes 20, 24): cube faces are 2-D");
    if (w != h)
        return fail(ErrorCode::kBadFormat, name, "KTX2 cube map faces are " + std::to_string(w) + "x" + std::to_string(h) +
                                                     " (bytes 20, 24): cube faces are square");
    if (depth != 0)
        return fail(ErrorCode::kBadFormat, name, "KTX2 cube map with pixelDepth " + std::to_string(depth) + " (byte 28)");
    if (layers > 1)
        return fail(ErrorCode::kUnsupported, name, "KTX2 cube map array of " + std::to_string(layers) +
                                                       " layers (layerCount, byte 32): one cube map is read");
    const bool zstd = scheme == 2;
    if (scheme != 0 && !zstd) {
        const char* what = scheme == 1 ? "BasisLZ" : scheme == 3 ? "ZLIB" : "unknown";
        return fail(ErrorCode::kUnsupported, name, "KTX2 supercompressionScheme " + std::to_string(scheme) + " (" + what +
                                                       ", byte 44) is not supported for cube maps");
    }
    auto fmt = ktx2_texel(vk, name);
    if (!fmt) return fmt.error();
    const TexelInfo f = texel_info(fmt->texel);
    if (type_size != ktx2_type_size(fmt->texel))
        return fail(ErrorCode::kBadFormat, name, "KTX2 typeSize " + std::to_string(type_size) + " (byte 16) does not match vkFormat " +
                                                     std::to_string(vk));
    if (Status s = check_cube_size(name, w, o); !s) return s.error();
    const int levels = static_cast<int>(std::max<std::uint32_t>(1, std::min<std::uint32_t>(level_count, 64)));
    if (level_count > static_cast<std::uint32_t>(max_levels(w)))
        return fail(ErrorCode::kBadFormat, name, "KTX2 levelCount " + std::to_string(level_count) + " (byte 40) exceeds the " +
                                                     std::to_string(max_levels(w)) + " levels of a " + std::to_string(w) +
                                                     "-pixel face");
    const std::uint64_t size = b.size();
    const std::uint64_t index_end = kKtx2HeaderBytes + 24 * static_cast<std::uint64_t>(levels);
    if (index_end > size)
        return fail(ErrorCode::kTruncated, name, "KTX2 level index truncated (file ends before byte " + std::to_string(index_end) + ")");
    std::uint64_t end = index_end;
    // Descriptor, key/value data and supercompression global data (byte ranges; 0 length = absent).
    const struct {
        const char* what;
        std::uint64_t offset, length;
        int at;
    } regions[3] = {{"dfd", get32(b, 48), get32(b, 52), 48}, {"kvd", get32(b, 56), get32(b, 60), 56}, {"sgd", get64(b, 64), get64(b, 72), 64}};
    for (const auto& r : regions) {
        if (r.length == 0) continue;
        if (r.offset > size || r.length > size - r.offset)
            return fail(ErrorCode::kTruncated, name, std::string("KTX2 ") + r.what + " bytes " + std::to_string(r.offset) + " + " +
                                                         std::to_string(r.length) + " (byte " + std::to_string(r.at) +
                                                         ") lie beyond the file's " + std::to_string(size) + " bytes");
        end = std::max(end, r.offset + r.length);
    }
    std::uint64_t level0_offset = 0, level0_length = 0;
    for (int l = 0; l < levels; ++l) {
        const size_t at = kKtx2HeaderBytes + 24 * static_cast<size_t>(l);
        const std::uint64_t off = get64(b, at), len = get64(b, at + 8), ulen = get64(b, at + 16);
        const std::uint64_t want = 6 * face_bytes(f, w, l);
        if (ulen != want || (!zstd && len != want) || (zstd && len == 0))
            return fail(ErrorCode::kBadFormat, name, "KTX2 level " + std::to_string(l) + " declares " + std::to_string(len) + " / " +
                                                         std::to_string(ulen) + " bytes (bytes " + std::to_string(at + 8) +
                                                         ", " + std::to_string(at + 16) + "); six faces of this size and format take " +
                                                         std::to_string(want));
        if (off > size || len > size - off)
            return fail(ErrorCode::kTruncated, name, "KTX2 level " + std::to_string(l) + " (bytes " + std::to_string(off) + " + " +
                                                         std::to_string(len) + ", byte " + std::to_string(at) +
                                                         ") lies beyond the file's " + std::to_string(size) + " bytes");
        if (off < index_end)
            return fail(ErrorCode::kBadFormat, name, "KTX2 level " + std::to_string(l) + " starts at byte " + std::to_string(off) +
                                                         ", inside the header and level index");
        if (l == 0) level0_offset = off, level0_length = len;
        end = std::max(end, off + len);
    }
    if (end != size)
        return fail(ErrorCode::kTrailingBytes, name, std::to_string(size - end) + " trailing bytes after the KTX2 data (which ends at byte " +
                                                         std::to_string(end) + ")");
    const std::uint64_t fb = face_bytes(f, w, 0);
    const std::uint8_t* level0 = b.data() + level0_offset;
    std::vector<std::uint8_t> inflated;
    if (zstd) {
        // Level 0 is one Zstandard frame whose content size must be the level's declared size
        // (bounded by the pixel limit checked above) before the buffer is allocated.
        const unsigned long long content = ZSTD_getFrameContentSize(level0, static_cast<size_t>(level0_length));
        if (content != 6 * fb)
            return fail(ErrorCode::kBadFormat, name, "KTX2 level 0 is not a Zstandard frame of " + std::to_string(6 * fb) +
                                                         " bytes (supercompressionScheme 2)");
        inflated.resize(static_cast<size_t>(6 * fb));
        const size_t got = ZSTD_decompress(inflated.data(), inflated.size(), level0, static_cast<size_t>(level0_length));
        if (ZSTD_isError(got) || got != inflated.size())
            return fail(ErrorCode::kBadFormat, name, std::string("KTX2 level 0: Zstandard data is corrupt (") +
                                                         (ZSTD_isError(got) ? ZSTD_getErrorName(got) : "short") + ")");
        level0 = inflated.data();
    }
    const int n = static_cast<int>(w);
    Image img = make_cube(n);
    if (Status s = decode_cube(f, *fmt, level0, fb, n, img, name, o); !s) return s.error();
    if (info) {
        info->format = "ktx2";
        info->compression = zstd ? "zstd" : "none";
        info->channels = channels_name(f, fmt->srgb);
        info->layout = "cube";
        info->part.clear();
    }
    return img;
}

Result<Image> read_dds_cube(std::span<const std::uint8_t> b, const std::string& name, const EnvmapReadOptions& o,
                            EnvmapInfo* info) {
    if (!is_dds(b)) return fail(ErrorCode::kBadFormat, name, "not a DDS file (bad magic at byte 0)");
    if (b.size() < 128)
        return fail(ErrorCode::kTruncated, name, "DDS header truncated (file of " + std::to_string(b.size()) +
                                                     " bytes ends before byte 128)");
    if (get32(b, 4) != 124 || get32(b, 76) != 32)
        return fail(ErrorCode::kBadFormat, name, "DDS header size " + std::to_string(get32(b, 4)) + " (byte 4) or pixel format size " +
                                                     std::to_string(get32(b, 76)) + " (byte 76) is not 124 / 32");
    const std::uint32_t h = get32(b, 12), w = get32(b, 16), mip_count = get32(b, 28), pf_flags = get32(b, 80),
                        fourcc = get32(b, 84), caps2 = get32(b, 112);
    std::size_t data_offset = 128;
    bool ignore_alpha = false;
    Format fmt{Texel::kRgba16f};
    if ((pf_flags & kDdpfFourCc) && fourcc == kFourCcDx10) {
        if (b.size() < 148)
            return fail(ErrorCode::kTruncated, name, "DDS DX10 header truncated (file ends before byte 148)");
        data_offset = 148;
        const std::uint32_t dim = get32(b, 132), misc = get32(b, 136), array_size = get32(b, 140);
        if (dim != 3)
            return fail(ErrorCode::kUnsupported, name, "DDS resource dimension " + std::to_string(dim) +
                                                           " (byte 132) is not TEXTURE2D (3), as a cube map's is");
        if (!(misc & kMiscTextureCube))
            return fail(ErrorCode::kUnsupported, name, "DDS 2-D texture without DDS_RESOURCE_MISC_TEXTURECUBE (byte 136): "
                                                       "not a cube map");
        if (array_size == 0)
            return fail(ErrorCode::kBadFormat, name, "DDS arraySize 0 (byte 140)");
        if (array_size > 1)
            return fail(ErrorCode::kUnsupported, name, "DDS cube map array of " + std::to_string(array_size) +
                                                           " cubes (arraySize, byte 140): one cube map is read");
        if ((caps2 & kCaps2Cubemap) && (caps2 & kCaps2AllFaces) != kCaps2AllFaces)
            return fail(ErrorCode::kUnsupported, name, "DDS partial cube map (caps2 at byte 112 lacks some of the six face flags)");
        auto t = dxgi_texel(get32(b, 128), name);
        if (!t) return t.error();
        fmt = *t;
    } else {
        if (caps2 & kCaps2Volume)
            return fail(ErrorCode::kUnsupported, name, "DDS volume texture (caps2, byte 112): not a cube map");
        if (!(caps2 & kCaps2Cubemap))
            return fail(ErrorCode::kUnsupported, name, "DDS 2-D texture (caps2 at byte 112 without DDSCAPS2_CUBEMAP): not a cube map");
        if ((caps2 & kCaps2AllFaces) != kCaps2AllFaces)
            return fail(ErrorCode::kUnsupported, name, "DDS partial cube map (caps2 at byte 112 lacks some of the six face flags)");
        if (!(pf_flags & kDdpfFourCc)) {
            // Uncompressed: 32-bit RGB(A) with 8-bit channel masks (D3DFMT_A8R8G8B8 / X8R8G8B8 /
            // A8B8G8R8 / X8B8G8R8). The legacy header has no colour space: UNORM.
            const std::uint32_t bits = get32(b, 88), rm = get32(b, 92), gm = get32(b, 96), bm = get32(b, 100),
                                am = (pf_flags & kDdpfAlphaPixels) ? get32(b, 104) : 0;
            if ((pf_flags & kDdpfRgb) && bits == 32 && gm == 0x0000ff00u && (am == 0 || am == 0xff000000u) &&
                ((rm == 0x00ff0000u && bm == 0x000000ffu) || (rm == 0x000000ffu && bm == 0x00ff0000u))) {
                const bool bgr = rm == 0x00ff0000u;
                fmt.texel = bgr ? (am ? Texel::kBgra8 : Texel::kBgrx8) : Texel::kRgba8;
                if (!bgr && !am) fmt.texel = Texel::kRgba8, ignore_alpha = true;
            } else {
                char buf[160];
                std::snprintf(buf, sizeof buf,
                              "DDS uncompressed pixel format (flags 0x%x at byte 80, %u bits, masks R %08x G %08x B %08x "
                              "A %08x)",
                              pf_flags, bits, rm, gm, bm, am);
                return fail(ErrorCode::kUnsupported, name, std::string(buf) +
                                                               " is not supported for cube maps (32-bit RGBA / BGRA / "
                                                               "BGRX with 8-bit channels is)");
            }
        } else if (fourcc == 113) fmt.texel = Texel::kRgba16f;  // D3DFMT_A16B16G16R16F
        else if (fourcc == 116) fmt.texel = Texel::kRgba32f;    // D3DFMT_A32B32G32R32F
        else if (fourcc == kFourCcDxt1) fmt.texel = Texel::kBc1a;
        else if (fourcc == kFourCcDxt3) fmt.texel = Texel::kBc2;
        else if (fourcc == kFourCcDxt5) fmt.texel = Texel::kBc3;
        else
            return fail(ErrorCode::kUnsupported, name, "DDS FourCC " + fourcc_text(fourcc) +
                                                           " (byte 84) is not supported for cube maps (113 A16B16G16R16F, 116 "
                                                           "A32B32G32R32F, DXT1, DXT3, DXT5 and DX10 are)");
    }
    if (w == 0 || h == 0 || w != h)
        return fail(ErrorCode::kBadFormat, name, "DDS cube map faces are " + std::to_string(w) + "x" + std::to_string(h) +
                                                     " (bytes 16, 12): cube faces are square and not empty");
    if (Status s = check_cube_size(name, w, o); !s) return s.error();
    const TexelInfo f = texel_info(fmt.texel);
    if (mip_count > static_cast<std::uint32_t>(max_levels(w)))
        return fail(ErrorCode::kBadFormat, name, "DDS mipMapCount " + std::to_string(mip_count) + " (byte 28) exceeds the " +
                                                     std::to_string(max_levels(w)) + " levels of a " + std::to_string(w) +
                                                     "-pixel face");
    const int levels = static_cast<int>(std::max<std::uint32_t>(1, mip_count));
    std::uint64_t chain = 0;  // one face's mip chain
    for (int l = 0; l < levels; ++l) chain += face_bytes(f, w, l);
    const std::uint64_t need = 6 * chain, have = b.size() - data_offset;
    if (have < need)
        return fail(ErrorCode::kTruncated, name, "DDS data truncated: six faces of " + std::to_string(levels) + " mip level(s) take " +
                                                     std::to_string(need) + " bytes after byte " + std::to_string(data_offset) +
                                                     ", the file has " + std::to_string(have));
    // Bytes after the six faces: zero padding is ignored (DirectXTex's loader reads the bytes the
    // header describes and ignores any after them; IBLBaker pads its cube maps with zeros); other
    // bytes are refused, since data the header does not describe (an undeclared mip chain puts
    // face 1 where face 0's second level is) would mean the faces are read from the wrong place.
    if (have > need) {
        const auto tail = b.subspan(static_cast<size_t>(data_offset + need));
        const auto nonzero = std::find_if(tail.begin(), tail.end(), [](std::uint8_t v) { return v != 0; });
        if (nonzero != tail.end())
            return fail(ErrorCode::kTrailingBytes, name, std::to_string(have - need) + " trailing bytes after the DDS data (which ends at byte " +
                                                             std::to_string(data_offset + need) + "), not all zero (byte " +
                                                             std::to_string(data_offset + need + static_cast<std::uint64_t>(nonzero - tail.begin())) +
                                                             " is not): only zero padding is ignored");
    }
    const int n = static_cast<int>(w);
    Image img = make_cube(n);
    if (ignore_alpha) {
        // X8B8G8R8: no alpha channel; decoded as RGBA8 with alpha 1.
        std::vector<std::uint8_t> copy(b.begin() + static_cast<std::ptrdiff_t>(data_offset),
                                       b.begin() + static_cast<std::ptrdiff_t>(data_offset + need));
        for (size_t i = 3; i < copy.size(); i += 4) copy[i] = 255;
        if (Status s = decode_cube(f, fmt, copy.data(), chain, n, img, name, o); !s) return s.error();
    } else if (Status s = decode_cube(f, fmt, b.data() + data_offset, chain, n, img, name, o); !s) {
        return s.error();
    }
    if (info) {
        info->format = "dds";
        info->compression = "none";
        info->channels = channels_name(f, fmt.srgb);
        info->layout = "cube";
        info->part.clear();
    }
    return img;
}

}  // namespace zhc
