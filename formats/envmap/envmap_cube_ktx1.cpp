// KTX 1 environment cube maps (formats/envmap/envmap_cube.h). Written from the KTX 1.1
// specification (Khronos) and the OpenGL format tables; the texel decoding is the KTX2 and DDS
// readers' (envmap_cube_internal.h).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <vector>

#include "formats/envmap/envmap_cube_internal.h"
#include "formats/io/le_bytes.h"

namespace zhc {

using namespace cube_detail;

namespace {
using le::get32;

constexpr std::uint8_t kKtx1Identifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
constexpr std::size_t kKtx1HeaderBytes = 64;  // identifier, 13 u32 fields

std::string hex4(std::uint32_t v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", v);
    return buf;
}

// A KTX 1 format: the texels as stored (by glType and glFormat for uncompressed data, by
// glInternalFormat for compressed data), and glTypeSize (the byte-swap unit).
struct Ktx1Format {
    Format fmt;
    std::uint32_t type_size;
};

Result<Ktx1Format> ktx1_format(std::uint32_t type, std::uint32_t format, std::uint32_t internal, const std::string& name) {
    constexpr std::uint32_t kUnsignedByte = 0x1401, kFloat = 0x1406, kHalf = 0x140B, kHalfOes = 0x8D61,
                            kUint10f11f11f = 0x8C3B, kUint5999 = 0x8C3E, kRgb = 0x1907, kRgba = 0x1908, kBgra = 0x80E1;
    const bool half = type == kHalf || type == kHalfOes;
    auto unsupported_combination = [&]() -> Error {
        return fail(ErrorCode::kUnsupported, name, "KTX 1 glType " + hex4(type) + " / glFormat " + hex4(format) + " (bytes 16, 24) with glInternalFormat " +
                                                       hex4(internal) + " (byte 28) is not supported");
    };
    // Compressed formats (glType and glFormat 0 by the specification; not used).
    switch (internal) {
        case 0x8E8F: return Ktx1Format{{Texel::kBc6hUfloat}, 1};  // GL_COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT
        case 0x83F0: return Ktx1Format{{Texel::kBc1}, 1};         // GL_COMPRESSED_RGB_S3TC_DXT1_EXT
        case 0x83F1: return Ktx1Format{{Texel::kBc1a}, 1};        // GL_COMPRESSED_RGBA_S3TC_DXT1_EXT
        case 0x83F2: return Ktx1Format{{Texel::kBc2}, 1};         // GL_COMPRESSED_RGBA_S3TC_DXT3_EXT
        case 0x83F3: return Ktx1Format{{Texel::kBc3}, 1};         // GL_COMPRESSED_RGBA_S3TC_DXT5_EXT
        case 0x8C4C: return Ktx1Format{{Texel::kBc1, true}, 1};   // GL_COMPRESSED_SRGB_S3TC_DXT1_EXT
        case 0x8C4D: return Ktx1Format{{Texel::kBc1a, true}, 1};  // GL_COMPRESSED_SRGB_ALPHA_S3TC_DXT1_EXT
        case 0x8C4E: return Ktx1Format{{Texel::kBc2, true}, 1};   // GL_COMPRESSED_SRGB_ALPHA_S3TC_DXT3_EXT
        case 0x8C4F: return Ktx1Format{{Texel::kBc3, true}, 1};   // GL_COMPRESSED_SRGB_ALPHA_S3TC_DXT5_EXT
        case 0x8E8E:
            return fail(ErrorCode::kUnsupported, name, "KTX 1 glInternalFormat 0x8E8E (GL_COMPRESSED_RGB_BPTC_SIGNED_FLOAT, byte 28) "
                                                       "is not supported: zhc's BC6H decoder reads unsigned BC6H only");
        case 0x8E8C: return Ktx1Format{{Texel::kBc7}, 1};        // GL_COMPRESSED_RGBA_BPTC_UNORM
        case 0x8E8D: return Ktx1Format{{Texel::kBc7, true}, 1};  // GL_COMPRESSED_SRGB_ALPHA_BPTC_UNORM
        default: break;
    }
    switch (internal) {
        case 0x881A:  // GL_RGBA16F
        case 0x8814:  // GL_RGBA32F
            if (format != kRgba) return unsupported_combination();
            if (half && internal == 0x881A) return Ktx1Format{{Texel::kRgba16f}, 2};
            if (type == kFloat) return Ktx1Format{{Texel::kRgba32f}, 4};
            return unsupported_combination();
        case 0x881B:  // GL_RGB16F
        case 0x8815:  // GL_RGB32F
            if (format != kRgb) return unsupported_combination();
            if (half && internal == 0x881B) return Ktx1Format{{Texel::kRgb16f}, 2};
            if (type == kFloat) return Ktx1Format{{Texel::kRgb32f}, 4};
            return unsupported_combination();
        case 0x8C3A:  // GL_R11F_G11F_B10F
            if (format == kRgb && type == kUint10f11f11f) return Ktx1Format{{Texel::kB10g11r11}, 4};
            return unsupported_combination();
        case 0x8C3D:  // GL_RGB9_E5
            if (format == kRgb && type == kUint5999) return Ktx1Format{{Texel::kE5b9g9r9}, 4};
            return unsupported_combination();
        case 0x8058:  // GL_RGBA8
        case 0x8C43:  // GL_SRGB8_ALPHA8
            if (type != kUnsignedByte || (format != kRgba && format != kBgra)) return unsupported_combination();
            return Ktx1Format{{format == kRgba ? Texel::kRgba8 : Texel::kBgra8, internal == 0x8C43}, 1};
        case 0x8051:  // GL_RGB8
        case 0x8C41:  // GL_SRGB8
            if (type != kUnsignedByte || format != kRgb) return unsupported_combination();
            return Ktx1Format{{Texel::kRgb8, internal == 0x8C41}, 1};
        default:
            return fail(ErrorCode::kUnsupported, name, "KTX 1 glInternalFormat " + hex4(internal) +
                                                           " (byte 28) is not supported (RGBA16F, RGB16F, RGBA32F, RGB32F, "
                                                           "R11F_G11F_B10F, RGB9_E5, BPTC unsigned float, RGBA8, SRGB8_ALPHA8, "
                                                           "RGB8, SRGB8, S3TC DXT1 / DXT3 / DXT5, BPTC UNORM (BC7) and their sRGB forms are)");
    }
}

// One face of a KTX 1 level: rows of uncompressed data are padded to 4 bytes (GL_UNPACK_ALIGNMENT 4).
std::uint64_t ktx1_row_bytes(const TexelInfo& f, std::uint64_t m) { return f.block ? ((m + 3) / 4) * f.bytes : (m * f.bytes + 3) / 4 * 4; }
std::uint64_t ktx1_face_bytes(const TexelInfo& f, std::uint64_t n, int level) {
    const std::uint64_t m = std::max<std::uint64_t>(1, n >> level);
    return ktx1_row_bytes(f, m) * (f.block ? (m + 3) / 4 : m);
}
std::uint64_t align4(std::uint64_t v) { return (v + 3) / 4 * 4; }

}  // namespace

bool is_ktx1(std::span<const std::uint8_t> b) { return b.size() >= 12 && std::memcmp(b.data(), kKtx1Identifier, 12) == 0; }

bool ktx1_declares_cube(std::span<const std::uint8_t> b) {
    if (!is_ktx1(b) || b.size() < kKtx1HeaderBytes) return false;
    return get32(b, 52) == 6 || get32(b, 52) == 0x06000000u;  // numberOfFaces, either byte order
}

Result<Image> read_ktx1_cube(std::span<const std::uint8_t> b, const std::string& name, const EnvmapReadOptions& o,
                             EnvmapInfo* info) {
    if (!is_ktx1(b)) return fail(ErrorCode::kBadFormat, name, "not a KTX 1 file (bad identifier at byte 0)");
    if (b.size() < kKtx1HeaderBytes)
        return fail(ErrorCode::kTruncated, name, "KTX 1 header truncated (file of " + std::to_string(b.size()) +
                                                     " bytes ends before byte 64)");
    const std::uint32_t endianness = get32(b, 12);
    if (endianness != 0x04030201u && endianness != 0x01020304u)
        return fail(ErrorCode::kBadFormat, name, "KTX 1 endianness " + hex4(endianness) + " (byte 12) is neither 0x04030201 nor "
                                                 "0x01020304");
    const bool swap = endianness == 0x01020304u;  // written on a big-endian machine: every field byte-swapped
    auto u32 = [&](std::uint64_t at) {
        const std::uint32_t v = get32(b, static_cast<size_t>(at));
        return swap ? (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24) : v;
    };
    const std::uint32_t type = u32(16), type_size = u32(20), format = u32(24), internal = u32(28), w = u32(36), h = u32(40),
                        depth = u32(44), array_elements = u32(48), faces = u32(52), mip_count = u32(56), kvd = u32(60);
    if (faces != 6) {
        if (faces == 1)
            return fail(ErrorCode::kUnsupported, name, "KTX 1 numberOfFaces 1 (byte 52): a 2-D texture, not a cube map");
        return fail(ErrorCode::kBadFormat, name, "KTX 1 numberOfFaces " + std::to_string(faces) + " (byte 52) is neither 1 nor 6");
    }
    if (array_elements != 0)
        return fail(ErrorCode::kUnsupported, name, "KTX 1 cube map array (numberOfArrayElements " + std::to_string(array_elements) +
                                                       ", byte 48): one cube map is read");
    if (w == 0 || h == 0 || w != h || depth != 0)
        return fail(ErrorCode::kBadFormat, name, "KTX 1 cube map faces are " + std::to_string(w) + "x" + std::to_string(h) + "x" +
                                                     std::to_string(depth) + " (bytes 36, 40, 44): cube faces are square and 2-D");
    auto k1 = ktx1_format(type, format, internal, name);
    if (!k1) return k1.error();
    const TexelInfo f = texel_info(k1->fmt.texel);
    if (type_size != k1->type_size)
        return fail(ErrorCode::kBadFormat, name, "KTX 1 glTypeSize " + std::to_string(type_size) + " (byte 20) does not match glInternalFormat " +
                                                     hex4(internal) + " (" + std::to_string(k1->type_size) + ")");
    if (Status s = check_cube_size(name, w, o); !s) return s.error();
    if (mip_count > static_cast<std::uint32_t>(max_levels(w)))
        return fail(ErrorCode::kBadFormat, name, "KTX 1 numberOfMipmapLevels " + std::to_string(mip_count) + " (byte 56) exceeds the " +
                                                     std::to_string(max_levels(w)) + " levels of a " + std::to_string(w) +
                                                     "-pixel face");
    const int levels = static_cast<int>(std::max<std::uint32_t>(1, mip_count));  // 0: level 0 only
    const std::uint64_t size = b.size();
    if (kvd % 4 != 0 || kvd > size - kKtx1HeaderBytes)
        return fail(kvd % 4 ? ErrorCode::kBadFormat : ErrorCode::kTruncated, name,
                    "KTX 1 bytesOfKeyValueData " + std::to_string(kvd) + " (byte 60) " +
                        (kvd % 4 ? "is not a multiple of 4" : "runs past the file's " + std::to_string(size) + " bytes"));
    // Levels: imageSize (one face's bytes for a non-array cube map; six faces' is accepted too, as
    // some writers store it), then six faces, each padded to 4 bytes (cubePadding).
    std::uint64_t pos = kKtx1HeaderBytes + kvd, level0 = 0;
    for (int l = 0; l < levels; ++l) {
        if (pos + 4 > size)
            return fail(ErrorCode::kTruncated, name, "KTX 1 level " + std::to_string(l) + ": file ends before its imageSize (byte " +
                                                         std::to_string(pos) + ")");
        const std::uint64_t image_size = u32(pos), fb = ktx1_face_bytes(f, w, l);
        if (image_size != fb && image_size != 6 * fb)
            return fail(ErrorCode::kBadFormat, name, "KTX 1 level " + std::to_string(l) + " imageSize " + std::to_string(image_size) +
                                                         " (byte " + std::to_string(pos) + "): one face of this size and format takes " +
                                                         std::to_string(fb) + " bytes");
        pos += 4;
        if (l == 0) level0 = pos;
        const std::uint64_t level_bytes = 6 * align4(fb);
        if (level_bytes > size - pos)
            return fail(ErrorCode::kTruncated, name, "KTX 1 level " + std::to_string(l) + " truncated: six faces take " +
                                                         std::to_string(level_bytes) + " bytes from byte " + std::to_string(pos) +
                                                         ", the file has " + std::to_string(size - pos));
        pos = align4(pos + level_bytes);  // mipPadding
    }
    if (pos < size)
        return fail(ErrorCode::kTrailingBytes, name, std::to_string(size - pos) + " trailing bytes after the KTX 1 data (which ends at byte " +
                                                         std::to_string(pos) + ")");
    // Level 0, each face with its row padding removed and, for a byte-swapped file, each
    // glTypeSize unit put in this machine's order.
    const int n = static_cast<int>(w);
    const std::uint64_t fb = ktx1_face_bytes(f, w, 0), packed = face_bytes(f, w, 0);
    const std::uint64_t row = ktx1_row_bytes(f, w), rows = f.block ? (w + 3) / 4 : w, packed_row = packed / rows;
    std::vector<std::uint8_t> faces_data(static_cast<size_t>(6 * packed));
    for (int face = 0; face < 6; ++face)
        for (std::uint64_t r = 0; r < rows; ++r)
            std::memcpy(faces_data.data() + face * packed + r * packed_row, b.data() + level0 + face * align4(fb) + r * row,
                        static_cast<size_t>(packed_row));
    if (swap && type_size > 1)
        for (size_t i = 0; i + type_size <= faces_data.size(); i += type_size) std::reverse(faces_data.begin() + static_cast<std::ptrdiff_t>(i),
                                                                                            faces_data.begin() + static_cast<std::ptrdiff_t>(i + type_size));
    Image img = make_cube(n);
    if (Status s = decode_cube(f, k1->fmt, faces_data.data(), packed, n, img, name, o); !s) return s.error();
    if (info) {
        info->format = "ktx1";
        info->compression = "none";
        info->channels = channels_name(f, k1->fmt.srgb);
        info->layout = "cube";
        info->part.clear();
    }
    return img;
}

}  // namespace zhc
