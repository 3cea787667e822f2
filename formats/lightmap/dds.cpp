// zhc/formats/lightmap/dds.cpp — DDS (DX10 extension header) writer and strict reader (see dds.h).
//
// Layout from Microsoft's "DDS" programming guide (DDS_HEADER, DDS_PIXELFORMAT, DDS_HEADER_DXT10),
// all fields little-endian u32:
//   0 magic "DDS "   4 DDS_HEADER (124 bytes, ddspf at 76)   128 DDS_HEADER_DXT10 (20 bytes)   148 data
#include "formats/lightmap/dds.h"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <utility>

#include "formats/io/file_io.h"
#include "formats/io/le_bytes.h"

namespace zhc {
namespace {
using le::get32;
using le::put32;

constexpr std::uint32_t fourcc(char a, char b, char c, char d) {
    return static_cast<std::uint32_t>(static_cast<std::uint8_t>(a)) | (static_cast<std::uint32_t>(static_cast<std::uint8_t>(b)) << 8) |
           (static_cast<std::uint32_t>(static_cast<std::uint8_t>(c)) << 16) | (static_cast<std::uint32_t>(static_cast<std::uint8_t>(d)) << 24);
}

constexpr std::uint32_t kMagic = fourcc('D', 'D', 'S', ' ');
constexpr std::uint32_t kFourCcDx10 = fourcc('D', 'X', '1', '0');
// Legacy FourCCs for the two RGTC formats (read only; DirectXTex maps them to the UNORM formats).
constexpr std::uint32_t kFourCcAti1 = fourcc('A', 'T', 'I', '1'), kFourCcBc4u = fourcc('B', 'C', '4', 'U');
constexpr std::uint32_t kFourCcAti2 = fourcc('A', 'T', 'I', '2'), kFourCcBc5u = fourcc('B', 'C', '5', 'U');

constexpr std::uint32_t kHeaderSize = 124, kPixelFormatSize = 32;
constexpr std::size_t kLegacyDataOffset = 4 + kHeaderSize;  // 128: no DXT10 header

// DDS_HEADER.dwFlags
constexpr std::uint32_t kDdsdCaps = 0x1, kDdsdHeight = 0x2, kDdsdWidth = 0x4, kDdsdPixelFormat = 0x1000,
                        kDdsdLinearSize = 0x80000;
// DDS_PIXELFORMAT.dwFlags
constexpr std::uint32_t kDdpfFourCc = 0x4;
// dwCaps / dwCaps2
constexpr std::uint32_t kDdscapsTexture = 0x1000;
constexpr std::uint32_t kDdscaps2Cubemap = 0x200, kDdscaps2Volume = 0x200000;
// DDS_HEADER_DXT10
constexpr std::uint32_t kDimensionTexture1d = 2, kDimensionTexture2d = 3, kDimensionTexture3d = 4;
constexpr std::uint32_t kMiscTextureCube = 0x4;
constexpr std::uint32_t kAlphaModeOpaque = 3, kAlphaModeMax = 4;  // DDS_ALPHA_MODE_CUSTOM = 4

// Byte offsets of the header fields, for messages.
struct Field {
    std::size_t offset;
    const char* name;
};
constexpr Field kFields[] = {
    {0, "magic"},
    {4, "dwSize"},
    {8, "dwFlags"},
    {12, "dwHeight"},
    {16, "dwWidth"},
    {20, "dwPitchOrLinearSize"},
    {24, "dwDepth"},
    {28, "dwMipMapCount"},
    {32, "dwReserved1"},
    {76, "ddspf.dwSize"},
    {80, "ddspf.dwFlags"},
    {84, "ddspf.dwFourCC"},
    {88, "ddspf.dwRGBBitCount"},
    {92, "ddspf.dwRBitMask"},
    {96, "ddspf.dwGBitMask"},
    {100, "ddspf.dwBBitMask"},
    {104, "ddspf.dwABitMask"},
    {108, "dwCaps"},
    {112, "dwCaps2"},
    {116, "dwCaps3"},
    {120, "dwCaps4"},
    {124, "dwReserved2"},
    {128, "dxgiFormat"},
    {132, "resourceDimension"},
    {136, "miscFlag"},
    {140, "arraySize"},
    {144, "miscFlags2"},
};

// "field X at byte N" for the field holding byte `at` (a header offset < 148).
std::string field_at(std::size_t at) {
    const Field* f = &kFields[0];
    for (const Field& g : kFields)
        if (g.offset <= at) f = &g;
    return std::string(f->name) + " at byte " + std::to_string(f->offset);
}


std::string fourcc_text(std::uint32_t v) {
    std::string s = "'";
    for (int k = 0; k < 4; ++k) {
        const char c = static_cast<char>(v >> (8 * k));
        if (c < 0x20 || c > 0x7E) {
            char hex[16];
            std::snprintf(hex, sizeof hex, "0x%08X", v);
            return hex;
        }
        s += c;
    }
    return s + "'";
}

Error bad(ErrorCode code, const std::string& name, const std::string& what) { return make_error(code, name + ": " + what); }

}  // namespace

std::uint32_t dxgi_format_for_vk(std::uint32_t vk_format) {
    switch (vk_format) {
        case kVkFormatBc4Unorm: return kDxgiFormatBc4Unorm;
        case kVkFormatBc5Unorm: return kDxgiFormatBc5Unorm;
        case kVkFormatBc6hUfloat: return kDxgiFormatBc6hUf16;
        default: return 0;
    }
}

std::uint32_t vk_format_for_dxgi(std::uint32_t dxgi_format) {
    switch (dxgi_format) {
        case kDxgiFormatBc4Unorm: return kVkFormatBc4Unorm;
        case kDxgiFormatBc5Unorm: return kVkFormatBc5Unorm;
        case kDxgiFormatBc6hUf16: return kVkFormatBc6hUfloat;
        default: return 0;
    }
}

Result<std::vector<std::uint8_t>> encode_dds(const Ktx2Image& img) {
    const std::uint32_t dxgi = dxgi_format_for_vk(img.vk_format);
    if (dxgi == 0) return make_error(ErrorCode::kInvalidArgument, "dds: unsupported vkFormat " + std::to_string(img.vk_format));
    if (img.width <= 0 || img.height <= 0) return make_error(ErrorCode::kInvalidArgument, "dds: empty image");
    if (img.blocks.size() != ktx2_level_bytes(img.vk_format, img.width, img.height))
        return make_error(ErrorCode::kInvalidArgument, "dds: block data does not match the image size");
    auto out = dds_header(img.vk_format, img.width, img.height);
    if (!out) return out;
    out->insert(out->end(), img.blocks.begin(), img.blocks.end());
    return out;
}

Result<std::vector<std::uint8_t>> dds_header(std::uint32_t vk_format, int width, int height) {
    const std::uint32_t dxgi = dxgi_format_for_vk(vk_format);
    if (dxgi == 0) return make_error(ErrorCode::kInvalidArgument, "dds: unsupported vkFormat " + std::to_string(vk_format));
    if (width <= 0 || height <= 0) return make_error(ErrorCode::kInvalidArgument, "dds: empty image");
    const std::uint64_t level_bytes = ktx2_level_bytes(vk_format, width, height);
    if (level_bytes > 0xFFFFFFFFu)
        return make_error(ErrorCode::kInvalidArgument, "dds: level larger than dwPitchOrLinearSize (32 bits) can state");
    std::vector<std::uint8_t> out;
    out.reserve(kDdsDataOffset);
    put32(out, kMagic);
    // DDS_HEADER. DDSD_MIPMAPCOUNT is left out (Microsoft: "required in a mipmapped texture"), but
    // dwMipMapCount still says 1, so readers that honour the count without the flag and readers that
    // read a missing flag as one level agree.
    put32(out, kHeaderSize);
    put32(out, kDdsdCaps | kDdsdHeight | kDdsdWidth | kDdsdPixelFormat | kDdsdLinearSize);
    put32(out, static_cast<std::uint32_t>(height));
    put32(out, static_cast<std::uint32_t>(width));
    put32(out, static_cast<std::uint32_t>(level_bytes));  // dwPitchOrLinearSize: the whole level (DDSD_LINEARSIZE)
    put32(out, 0);                                        // dwDepth
    put32(out, 1);                                        // dwMipMapCount
    for (int k = 0; k < 11; ++k) put32(out, 0);           // dwReserved1
    // DDS_PIXELFORMAT: FourCC 'DX10', the format is in the extension header.
    put32(out, kPixelFormatSize);
    put32(out, kDdpfFourCc);
    put32(out, kFourCcDx10);
    for (int k = 0; k < 5; ++k) put32(out, 0);  // RGB bit count and masks: unused with DDPF_FOURCC
    put32(out, kDdscapsTexture);                // dwCaps
    for (int k = 0; k < 4; ++k) put32(out, 0);  // dwCaps2 (no cube, no volume), dwCaps3, dwCaps4, dwReserved2
    // DDS_HEADER_DXT10
    put32(out, dxgi);
    put32(out, kDimensionTexture2d);
    put32(out, 0);                 // miscFlag: not a cube map
    put32(out, 1);                 // arraySize
    put32(out, kAlphaModeOpaque);  // miscFlags2: BC4/BC5/BC6H have no alpha; samplers return 1
    return out;
}

namespace {
// decode_dds's checks on the first bytes `b` of a file of `size` bytes (b holds at least
// min(size, 148) bytes): the image description without its blocks, and the data offset.
Result<Ktx2Image> decode_dds_layout(std::span<const std::uint8_t> b, std::uint64_t size, const std::string& name,
                                    const DdsLimits& limits, std::uint64_t* data_offset_out) {
    if (size < 4 || b.size() < 4 || get32(b, 0) != kMagic) return bad(ErrorCode::kBadFormat, name, "not a DDS file (bad magic at byte 0)" + git_lfs_hint(b));
    if (size < kLegacyDataOffset || b.size() < kLegacyDataOffset)
        return bad(ErrorCode::kTruncated, name, "header truncated: file ends at byte " + std::to_string(size) +
                                                    ", inside " + field_at(static_cast<size_t>(size)) + " (the header needs 128 bytes)");
    if (const std::uint32_t size = get32(b, 4); size != kHeaderSize)
        return bad(ErrorCode::kBadFormat, name, "dwSize " + std::to_string(size) + " (byte 4), must be 124");
    if (const std::uint32_t size = get32(b, 76); size != kPixelFormatSize)
        return bad(ErrorCode::kBadFormat, name, "ddspf.dwSize " + std::to_string(size) + " (byte 76), must be 32");
    if ((get32(b, 80) & kDdpfFourCc) == 0)
        return bad(ErrorCode::kUnsupported, name,
                   "pixel format without DDPF_FOURCC (ddspf.dwFlags at byte 80): uncompressed DDS is not supported");
    const std::uint32_t four = get32(b, 84);
    Ktx2Image img;
    std::size_t data_offset = kLegacyDataOffset;
    if (four == kFourCcDx10) {
        if (size < kDdsDataOffset || b.size() < kDdsDataOffset)
            return bad(ErrorCode::kTruncated, name, "DX10 header truncated: file ends at byte " + std::to_string(size) +
                                                        ", inside " + field_at(static_cast<size_t>(size)) + " (the header needs 148 bytes)");
        data_offset = kDdsDataOffset;
        const std::uint32_t dxgi = get32(b, 128), dim = get32(b, 132), misc = get32(b, 136), array = get32(b, 140),
                            misc2 = get32(b, 144);
        img.vk_format = vk_format_for_dxgi(dxgi);
        if (img.vk_format == 0)
            return bad(ErrorCode::kUnsupported, name, "unsupported dxgiFormat " + std::to_string(dxgi) +
                                                          " (byte 128; zhc reads 80 BC4_UNORM, 83 BC5_UNORM, 95 BC6H_UF16)");
        if (dim == kDimensionTexture1d || dim == kDimensionTexture3d)
            return bad(ErrorCode::kUnsupported, name, std::string(dim == kDimensionTexture1d ? "1-D" : "3-D") +
                                                          " texture (resourceDimension at byte 132): only 2-D textures are supported");
        if (dim != kDimensionTexture2d)
            return bad(ErrorCode::kBadFormat, name, "resourceDimension " + std::to_string(dim) + " (byte 132) is not a texture dimension");
        if (misc & kMiscTextureCube)
            return bad(ErrorCode::kUnsupported, name, "cube map (miscFlag at byte 136): only single 2-D images are supported");
        if (misc != 0) return bad(ErrorCode::kBadFormat, name, "unknown miscFlag bits " + std::to_string(misc) + " (byte 136)");
        if (array == 0) return bad(ErrorCode::kBadFormat, name, "arraySize 0 (byte 140)");
        if (array != 1)
            return bad(ErrorCode::kUnsupported, name, "arraySize " + std::to_string(array) + " (byte 140): only single 2-D images are supported");
        if (misc2 > kAlphaModeMax)
            return bad(ErrorCode::kBadFormat, name, "miscFlags2 " + std::to_string(misc2) + " (byte 144): not an alpha mode 0..4");
    } else if (four == kFourCcAti1 || four == kFourCcBc4u) {
        img.vk_format = kVkFormatBc4Unorm;
    } else if (four == kFourCcAti2 || four == kFourCcBc5u) {
        img.vk_format = kVkFormatBc5Unorm;
    } else {
        return bad(ErrorCode::kUnsupported, name, "unsupported FourCC " + fourcc_text(four) +
                                                      " (ddspf.dwFourCC at byte 84; zhc reads 'DX10', 'ATI1'/'BC4U', 'ATI2'/'BC5U')");
    }
    const std::uint32_t h = get32(b, 12), w = get32(b, 16), pitch = get32(b, 20), depth = get32(b, 24), mips = get32(b, 28),
                        caps2 = get32(b, 112);
    if (w == 0 || h == 0) return bad(ErrorCode::kBadFormat, name, "zero dwWidth/dwHeight (bytes 12-19)");
    if (w > static_cast<std::uint32_t>(limits.max_dimension) || h > static_cast<std::uint32_t>(limits.max_dimension))
        return bad(ErrorCode::kTooLarge, name, std::to_string(w) + "x" + std::to_string(h) + " exceeds the limit " +
                                                   std::to_string(limits.max_dimension) + " (dwHeight/dwWidth, bytes 12-19)");
    if (depth > 1 || (caps2 & kDdscaps2Volume))
        return bad(ErrorCode::kUnsupported, name, "volume texture (dwDepth at byte 24 / dwCaps2 at byte 112): only 2-D images are supported");
    if (caps2 & kDdscaps2Cubemap)
        return bad(ErrorCode::kUnsupported, name, "cube map (dwCaps2 at byte 112): only single 2-D images are supported");
    if (mips > 1)
        return bad(ErrorCode::kUnsupported, name, "dwMipMapCount " + std::to_string(mips) + " (byte 28): zhc reads exactly one mip level");
    const std::size_t bb = ktx2_block_bytes(img.vk_format);
    const std::uint64_t expected = static_cast<std::uint64_t>((w + 3) / 4) * ((h + 3) / 4) * bb;
    if (pitch != 0 && pitch != expected)
        return bad(ErrorCode::kBadFormat, name, "dwPitchOrLinearSize " + std::to_string(pitch) + " (byte 20) but " + std::to_string(w) +
                                                    "x" + std::to_string(h) + " needs " + std::to_string(expected) + " (or 0)");
    const std::uint64_t have = size - data_offset;
    if (have < expected)
        return bad(ErrorCode::kTruncated, name, "file ends inside the block data (needs " + std::to_string(data_offset + expected) +
                                                    " bytes, has " + std::to_string(size) + ")");
    if (have > expected)
        return bad(ErrorCode::kTrailingBytes, name, std::to_string(have - expected) + " bytes after the block data (byte " +
                                                        std::to_string(data_offset + expected) + ")");
    img.width = static_cast<int>(w);
    img.height = static_cast<int>(h);
    *data_offset_out = data_offset;
    return img;
}
}  // namespace

Result<TextureHeaderSummary> describe_dds_header(std::span<const std::uint8_t> b, const std::string& name) {
    if (b.size() < 4 || get32(b, 0) != kMagic) return bad(ErrorCode::kBadFormat, name, "not a DDS file (bad magic at byte 0)" + git_lfs_hint(b));
    if (b.size() < kLegacyDataOffset) return bad(ErrorCode::kTruncated, name, "header truncated (file ends before byte 128)");
    TextureHeaderSummary out;
    out.container = "DDS";
    out.height = get32(b, 12), out.width = get32(b, 16);
    const std::uint32_t flags = get32(b, 8), caps2 = get32(b, 112);
    out.depth = (flags & 0x800000u) ? get32(b, 24) : 0;  // DDSD_DEPTH
    out.levels = std::max<std::uint32_t>(1, get32(b, 28));
    out.faces = (caps2 & 0x200u) ? static_cast<std::uint64_t>(std::popcount(caps2 & 0xFC00u)) : 1;
    out.layers = 1;
    const std::uint32_t pf_flags = get32(b, 80), fourcc = get32(b, 84);
    if ((pf_flags & kDdpfFourCc) && fourcc == kFourCcDx10) {
        if (b.size() < kLegacyDataOffset + 20) return bad(ErrorCode::kTruncated, name, "DX10 header truncated (file ends before byte 148)");
        static const std::pair<std::uint32_t, const char*> kNames[] = {
            {2, "R32G32B32A32_FLOAT"}, {6, "R32G32B32_FLOAT"}, {10, "R16G16B16A16_FLOAT"}, {26, "R11G11B10_FLOAT"},
            {28, "R8G8B8A8_UNORM"}, {29, "R8G8B8A8_UNORM_SRGB"}, {67, "R9G9B9E5_SHAREDEXP"}, {71, "BC1_UNORM"},
            {72, "BC1_UNORM_SRGB"}, {74, "BC2_UNORM"}, {75, "BC2_UNORM_SRGB"}, {77, "BC3_UNORM"}, {78, "BC3_UNORM_SRGB"},
            {80, "BC4_UNORM"}, {81, "BC4_SNORM"}, {83, "BC5_UNORM"}, {84, "BC5_SNORM"}, {87, "B8G8R8A8_UNORM"},
            {88, "B8G8R8X8_UNORM"}, {91, "B8G8R8A8_UNORM_SRGB"}, {93, "B8G8R8X8_UNORM_SRGB"}, {95, "BC6H_UF16"},
            {96, "BC6H_SF16"}, {98, "BC7_UNORM"}, {99, "BC7_UNORM_SRGB"}};
        const std::uint32_t dxgi = get32(b, 128);
        out.format = "DXGI " + std::to_string(dxgi);
        for (const auto& [v, n] : kNames)
            if (v == dxgi) out.format = std::string(n) + " (DXGI " + std::to_string(dxgi) + ")";
        out.layers = get32(b, 140);
        if (get32(b, 136) & 0x4u) out.faces = 6;  // DDS_RESOURCE_MISC_TEXTURECUBE
        if (get32(b, 132) == 4) out.depth = std::max<std::uint64_t>(out.depth, 1);  // TEXTURE3D
    } else if (pf_flags & kDdpfFourCc) {
        std::string t;
        for (int k = 0; k < 4; ++k) {
            const char c = static_cast<char>((fourcc >> (8 * k)) & 0xff);
            t += (c >= 0x20 && c <= 0x7e) ? c : '?';
        }
        out.format = "FourCC '" + t + "' (" + std::to_string(fourcc) + ")";
    } else {
        char masks[96];
        std::snprintf(masks, sizeof masks, "masks R 0x%08X, G 0x%08X, B 0x%08X, A 0x%08X", get32(b, 92), get32(b, 96), get32(b, 100),
                      get32(b, 104));
        out.format = std::to_string(get32(b, 88)) + "-bit uncompressed (" + masks + ")";
    }
    return out;
}

Result<Ktx2Image> decode_dds(std::span<const std::uint8_t> b, const std::string& name, const DdsLimits& limits) {
    std::uint64_t off = 0;
    auto img = decode_dds_layout(b, b.size(), name, limits, &off);
    if (!img) return img;
    img->blocks.assign(b.begin() + static_cast<std::ptrdiff_t>(off), b.end());
    return img;
}

Result<BlockFileLayout> read_dds_layout(const std::string& path, const DdsLimits& limits) {
    auto prefix = read_file_prefix(path, kDdsDataOffset);
    if (!prefix) return prefix.error();
    BlockFileLayout l;
    auto img = decode_dds_layout(prefix->bytes, prefix->file_size, path, limits, &l.data_offset);
    if (!img) return img.error();
    l.vk_format = img->vk_format;
    l.width = img->width;
    l.height = img->height;
    return l;
}


Status write_dds(const std::string& path, const Ktx2Image& image) {
    auto bytes = encode_dds(image);
    if (!bytes) return make_error(bytes.error().code, path + ": " + bytes.error().message);
    return write_file_atomic(path, *bytes);
}

Result<Ktx2Image> read_dds(const std::string& path, const DdsLimits& limits) {
    const std::uint64_t dim = static_cast<std::uint64_t>(limits.max_dimension);
    auto bytes = read_file_bytes(path, 4096 + (dim + 3) / 4 * ((dim + 3) / 4) * 16);
    if (!bytes) return bytes.error();
    return decode_dds(*bytes, path, limits);
}

}  // namespace zhc
