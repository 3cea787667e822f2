// KTX2 and DDS environment cube maps (formats/envmap/envmap_cube.h). Written from the KTX 2.0
// specification (Khronos), Microsoft's DDS documentation (DDS_HEADER, DDS_HEADER_DXT10,
// DDS_PIXELFORMAT) and the Vulkan / D3D cube-map face tables; standard library plus zhc's BC6H
// decoder.
#include "formats/envmap/envmap_cube.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <zstd.h>

#include "codec/lightmap/bc6h.h"
#include "codec/sh/cubemap.h"
#include "formats/io/le_bytes.h"

namespace zhc {

namespace {
using le::get32;
using le::get64;
constexpr auto get16 = le::load16;
constexpr auto getf32 = le::load_f32;

constexpr std::uint8_t kKtx2Identifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};


Error fail(ErrorCode code, const std::string& name, const std::string& what) { return make_error(code, name + ": " + what); }

// The pixel formats read, whatever the container calls them.
enum class Texel { kRgba16f, kRgb16f, kRgba32f, kRgb32f, kE5b9g9r9, kBc6hUfloat };

struct TexelInfo {
    Texel texel;
    const char* channels;  // for EnvmapInfo
    std::uint64_t bytes;   // per texel, or per 4x4 block
    bool block;
};

TexelInfo texel_info(Texel t) {
    switch (t) {
        case Texel::kRgba16f: return {t, "RGBA half", 8, false};
        case Texel::kRgb16f: return {t, "RGB half", 6, false};
        case Texel::kRgba32f: return {t, "RGBA float", 16, false};
        case Texel::kRgb32f: return {t, "RGB float", 12, false};
        case Texel::kE5b9g9r9: return {t, "RGB9E5", 4, false};
        default: return {t, "BC6H ufloat", 16, true};
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

// E5B9G9R9 (Vulkan) / R9G9B9E5_SHAREDEXP (DXGI): R bits 0-8, G 9-17, B 18-26, exponent 27-31;
// value = mantissa * 2^(exponent - 15 - 9).
void decode_e5b9g9r9(std::uint32_t v, float out[3]) {
    const int e = static_cast<int>(v >> 27);
    for (int c = 0; c < 3; ++c) out[c] = std::ldexp(static_cast<float>((v >> (9 * c)) & 0x1ff), e - 24);
}

// Decodes one face (level 0, face size n) from `src` (face_bytes(f, n, 0) bytes) into rows
// face*n .. face*n + n - 1 of img.
void decode_face(const TexelInfo& f, const std::uint8_t* src, int n, int face, Image& img) {
    const size_t nn = static_cast<size_t>(n);
    if (f.block) {
        const auto half = bc6h::decode_image(src, static_cast<size_t>(face_bytes(f, nn, 0)), n, n);
        for (size_t r = 0; r < nn; ++r) {
            float* out = img.row(face * n + static_cast<int>(r));
            for (size_t i = 0; i < 3 * nn; ++i) out[i] = bc6h::half_to_float(half[r * 3 * nn + i]);
        }
        return;
    }
    for (size_t r = 0; r < nn; ++r) {
        float* out = img.row(face * n + static_cast<int>(r));
        const std::uint8_t* p = src + r * nn * f.bytes;
        for (size_t c = 0; c < nn; ++c, p += f.bytes) {
            float* o = out + 3 * c;
            switch (f.texel) {
                case Texel::kRgba16f:
                case Texel::kRgb16f:
                    for (int k = 0; k < 3; ++k) o[k] = bc6h::half_to_float(get16(p + 2 * k));
                    break;
                case Texel::kRgba32f:
                case Texel::kRgb32f:
                    for (int k = 0; k < 3; ++k) o[k] = getf32(p + 4 * k);
                    break;
                default: decode_e5b9g9r9(get32({p, 4}, 0), o); break;
            }
        }
    }
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

// ---- KTX2 ----

constexpr std::size_t kKtx2HeaderBytes = 80;  // identifier, 9 u32 fields, index (4 u32, 2 u64)

Result<Texel> ktx2_texel(std::uint32_t vk, const std::string& name) {
    switch (vk) {
        case 97: return Texel::kRgba16f;   // VK_FORMAT_R16G16B16A16_SFLOAT
        case 90: return Texel::kRgb16f;    // VK_FORMAT_R16G16B16_SFLOAT
        case 109: return Texel::kRgba32f;  // VK_FORMAT_R32G32B32A32_SFLOAT
        case 106: return Texel::kRgb32f;   // VK_FORMAT_R32G32B32_SFLOAT
        case 123: return Texel::kE5b9g9r9; // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
        case 143: return Texel::kBc6hUfloat;
        case 144:
            return fail(ErrorCode::kUnsupported, name,
                        "KTX2 vkFormat 144 (BC6H_SFLOAT_BLOCK, byte 12) is not supported: zhc's BC6H decoder reads "
                        "unsigned BC6H only");
        default:
            return fail(ErrorCode::kUnsupported, name,
                        "KTX2 vkFormat " + std::to_string(vk) +
                            " (byte 12) is not supported for cube maps (R16G16B16A16_SFLOAT, R16G16B16_SFLOAT, "
                            "R32G32B32A32_SFLOAT, R32G32B32_SFLOAT, E5B9G9R9_UFLOAT_PACK32, BC6H_UFLOAT_BLOCK are)");
    }
}

std::uint32_t ktx2_type_size(Texel t) {
    switch (t) {
        case Texel::kRgba16f:
        case Texel::kRgb16f: return 2;
        case Texel::kBc6hUfloat: return 1;
        default: return 4;
    }
}

// ---- DDS ----

constexpr std::uint32_t kDdsMagic = 0x20534444;          // "DDS "
constexpr std::uint32_t kFourCcDx10 = 0x30315844;        // "DX10"
constexpr std::uint32_t kDdpfFourCc = 0x4;
constexpr std::uint32_t kCaps2Cubemap = 0x200;
constexpr std::uint32_t kCaps2AllFaces = 0xFC00;         // +X -X +Y -Y +Z -Z
constexpr std::uint32_t kCaps2Volume = 0x200000;
constexpr std::uint32_t kMiscTextureCube = 0x4;

Result<Texel> dxgi_texel(std::uint32_t f, const std::string& name) {
    switch (f) {
        case 10: return Texel::kRgba16f;  // DXGI_FORMAT_R16G16B16A16_FLOAT
        case 2: return Texel::kRgba32f;   // DXGI_FORMAT_R32G32B32A32_FLOAT
        case 6: return Texel::kRgb32f;    // DXGI_FORMAT_R32G32B32_FLOAT
        case 67: return Texel::kE5b9g9r9; // DXGI_FORMAT_R9G9B9E5_SHAREDEXP
        case 95: return Texel::kBc6hUfloat;
        case 96:
            return fail(ErrorCode::kUnsupported, name,
                        "DDS DXGI format 96 (BC6H_SF16, byte 128) is not supported: zhc's BC6H decoder reads unsigned "
                        "BC6H only");
        default:
            return fail(ErrorCode::kUnsupported, name,
                        "DDS DXGI format " + std::to_string(f) +
                            " (byte 128) is not supported for cube maps (R16G16B16A16_FLOAT, R32G32B32A32_FLOAT, "
                            "R32G32B32_FLOAT, R9G9B9E5_SHAREDEXP, BC6H_UF16 are)");
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
    auto texel = ktx2_texel(vk, name);
    if (!texel) return texel.error();
    const TexelInfo f = texel_info(*texel);
    if (type_size != ktx2_type_size(*texel))
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
    for (int face = 0; face < 6; ++face) decode_face(f, level0 + static_cast<std::uint64_t>(face) * fb, n, face, img);
    if (info) {
        info->format = "ktx2";
        info->compression = zstd ? "zstd" : "none";
        info->channels = f.channels;
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
    Texel texel;
    if (!(pf_flags & kDdpfFourCc))
        return fail(ErrorCode::kUnsupported, name, "DDS pixel format without FourCC (flags at byte 80): uncompressed 8-bit "
                                                   "formats are not supported for cube maps");
    if (fourcc == kFourCcDx10) {
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
        texel = *t;
    } else {
        if (caps2 & kCaps2Volume)
            return fail(ErrorCode::kUnsupported, name, "DDS volume texture (caps2, byte 112): not a cube map");
        if (!(caps2 & kCaps2Cubemap))
            return fail(ErrorCode::kUnsupported, name, "DDS 2-D texture (caps2 at byte 112 without DDSCAPS2_CUBEMAP): not a cube map");
        if ((caps2 & kCaps2AllFaces) != kCaps2AllFaces)
            return fail(ErrorCode::kUnsupported, name, "DDS partial cube map (caps2 at byte 112 lacks some of the six face flags)");
        if (fourcc == 113) texel = Texel::kRgba16f;       // D3DFMT_A16B16G16R16F
        else if (fourcc == 116) texel = Texel::kRgba32f;  // D3DFMT_A32B32G32R32F
        else
            return fail(ErrorCode::kUnsupported, name, "DDS FourCC " + std::to_string(fourcc) +
                                                           " (byte 84) is not supported for cube maps (113 A16B16G16R16F, 116 "
                                                           "A32B32G32R32F and DX10 are)");
    }
    if (w == 0 || h == 0 || w != h)
        return fail(ErrorCode::kBadFormat, name, "DDS cube map faces are " + std::to_string(w) + "x" + std::to_string(h) +
                                                     " (bytes 16, 12): cube faces are square and not empty");
    if (Status s = check_cube_size(name, w, o); !s) return s.error();
    const TexelInfo f = texel_info(texel);
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
    if (have > need)
        return fail(ErrorCode::kTrailingBytes, name, std::to_string(have - need) + " trailing bytes after the DDS data (which ends at byte " +
                                                         std::to_string(data_offset + need) + ")");
    const int n = static_cast<int>(w);
    Image img = make_cube(n);
    for (int face = 0; face < 6; ++face)
        decode_face(f, b.data() + data_offset + static_cast<std::uint64_t>(face) * chain, n, face, img);
    if (info) {
        info->format = "dds";
        info->compression = "none";
        info->channels = f.channels;
        info->layout = "cube";
        info->part.clear();
    }
    return img;
}

}  // namespace zhc
