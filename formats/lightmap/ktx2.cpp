// zhc/formats/lightmap/ktx2.cpp — KTX 2.0 writer and strict reader (see ktx2.h).
#include "formats/lightmap/ktx2.h"

#include <cstring>
#include <utility>

#include "formats/lightmap/astc.h"

#include "formats/io/file_io.h"
#include "formats/io/le_bytes.h"

namespace zhc {
namespace {
using le::get32;
using le::get64;
using le::put32;
using le::put64;

constexpr std::uint8_t kIdentifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
constexpr std::size_t kHeaderBytes = 12 + 9 * 4;     // identifier + 9 u32 fields
constexpr std::size_t kIndexBytes = 4 * 4 + 2 * 8;   // dfd/kvd offsets+lengths, sgd offset+length
constexpr std::size_t kLevelIndexBytes = 3 * 8;      // one level
constexpr std::size_t kDfdStart = kHeaderBytes + kIndexBytes + kLevelIndexBytes;  // 104
// Key/value data is read whole from the file's first 64 KiB by read_ktx2_layout as well: at most 32 KiB.
constexpr std::uint32_t kMaxKvdBytes = 32768;

// Khronos Data Format: colour models and sample layout for the three formats.
constexpr std::uint32_t kModelBc4 = 131, kModelBc5 = 132, kModelBc6h = 133, kModelAstc = 162;
constexpr std::uint32_t kPrimariesBt709 = 1, kTransferLinear = 1;
constexpr std::uint32_t kQualifierFloat = 0x80, kQualifierSigned = 0x40;  // in the channelType|qualifiers byte


// The DFD zhc writes (and the only one it accepts) for a format: dfdTotalSize + one basic block.
std::vector<std::uint8_t> make_dfd(std::uint32_t vk_format) {
    if (const auto astc_format = astc::format_of_vk(vk_format)) {
        // ASTC: one 128-bit sample of KHR_DF_CHANNEL_ASTC_DATA (0); SFLOAT (HDR) marks it float and
        // signed with the range [-1, 1] (as libktx's vk2dfd), UNORM (LDR) is [0, 0xFFFFFFFF].
        const bool hdr = astc_format->hdr;
        std::vector<std::uint8_t> d;
        put32(d, 4 + 24 + 16);
        put32(d, 0);
        put32(d, 2u | (40u << 16));
        put32(d, kModelAstc | (kPrimariesBt709 << 8) | (kTransferLinear << 16));
        put32(d, static_cast<std::uint32_t>(astc_format->footprint.x - 1) | (static_cast<std::uint32_t>(astc_format->footprint.y - 1) << 8));
        put32(d, 16);
        put32(d, 0);
        put32(d, (127u << 16) | ((hdr ? kQualifierFloat | kQualifierSigned : 0u) << 24));
        put32(d, 0);
        put32(d, hdr ? 0xBF800000u : 0u);
        put32(d, hdr ? 0x3F800000u : 0xFFFFFFFFu);
        return d;
    }
    const bool bc5 = vk_format == kVkFormatBc5Unorm, bc6 = vk_format == kVkFormatBc6hUfloat;
    const std::uint32_t samples = bc5 ? 2 : 1;
    const std::uint32_t block_size = 24 + 16 * samples;
    const std::uint32_t bytes = static_cast<std::uint32_t>(ktx2_block_bytes(vk_format));
    std::vector<std::uint8_t> d;
    put32(d, 4 + block_size);                     // dfdTotalSize
    put32(d, 0);                                  // vendorId 0 (Khronos), descriptorType 0 (basic)
    put32(d, 2u | (block_size << 16));            // versionNumber 2 (KDF 1.3), descriptorBlockSize
    const std::uint32_t model = bc6 ? kModelBc6h : (bc5 ? kModelBc5 : kModelBc4);
    put32(d, model | (kPrimariesBt709 << 8) | (kTransferLinear << 16));  // flags 0 (straight alpha)
    put32(d, 3u | (3u << 8));                     // texelBlockDimension 4x4x1x1 (stored minus one)
    put32(d, bytes);                              // bytesPlane0
    put32(d, 0);                                  // bytesPlane4..7
    for (std::uint32_t s = 0; s < samples; ++s) {
        const std::uint32_t bit_length = (bc5 || !bc6) ? 63 : 127;  // stored minus one
        const std::uint32_t channel = s | (bc6 ? kQualifierFloat : 0);
        put32(d, (s * 64) | (bit_length << 16) | (channel << 24));  // bitOffset, bitLength, channel
        put32(d, 0);                                                // samplePosition 0,0,0,0
        put32(d, 0);                                                // sampleLower: 0 (0.0f / 0)
        put32(d, bc6 ? 0x3F800000u : 0xFFFFFFFFu);                  // sampleUpper: 1.0f / max
    }
    return d;
}

std::size_t align_up(std::size_t v, std::size_t a) { return (v + a - 1) / a * a; }

Error bad(ErrorCode code, const std::string& name, const std::string& what) {
    return make_error(code, name + ": " + what);
}

}  // namespace

std::size_t ktx2_block_bytes(std::uint32_t vk_format) {
    if (astc::format_of_vk(vk_format)) return 16;
    switch (vk_format) {
        case kVkFormatBc4Unorm: return 8;
        case kVkFormatBc5Unorm:
        case kVkFormatBc6hUfloat: return 16;
        default: return 0;
    }
}

std::array<int, 2> ktx2_block_dims(std::uint32_t vk_format) {
    if (const auto f = astc::format_of_vk(vk_format)) return {f->footprint.x, f->footprint.y};
    return {4, 4};
}

std::vector<std::uint8_t> encode_ktx2_key_values(const std::vector<Ktx2KeyValue>& kv) {
    std::vector<std::uint8_t> out;
    for (const auto& e : kv) {
        put32(out, static_cast<std::uint32_t>(e.key.size() + 1 + e.value.size()));
        out.insert(out.end(), e.key.begin(), e.key.end());
        out.push_back(0);
        out.insert(out.end(), e.value.begin(), e.value.end());
        out.resize(align_up(out.size(), 4), 0);
    }
    return out;
}

Result<std::vector<std::uint8_t>> ktx2_header(std::uint32_t vk_format, int width, int height, const std::vector<Ktx2KeyValue>& key_values) {
    const std::size_t bb = ktx2_block_bytes(vk_format);
    if (bb == 0) return make_error(ErrorCode::kInvalidArgument, "ktx2: unsupported vkFormat " + std::to_string(vk_format));
    if (width <= 0 || height <= 0) return make_error(ErrorCode::kInvalidArgument, "ktx2: empty image");
    const std::size_t level_bytes = ktx2_level_bytes(vk_format, width, height);
    const auto dfd = make_dfd(vk_format);
    const auto kvd = encode_ktx2_key_values(key_values);
    if (kvd.size() > kMaxKvdBytes) return make_error(ErrorCode::kInvalidArgument, "ktx2: key/value data above 32768 bytes");
    const std::size_t kvd_offset = kvd.empty() ? 0 : kDfdStart + dfd.size();
    const std::size_t level_offset = align_up(kDfdStart + dfd.size() + kvd.size(), bb);  // lcm(block bytes, 4) = block bytes
    std::vector<std::uint8_t> out(kIdentifier, kIdentifier + 12);
    put32(out, vk_format);
    put32(out, 1);  // typeSize: 1 for block-compressed formats
    put32(out, static_cast<std::uint32_t>(width));
    put32(out, static_cast<std::uint32_t>(height));
    put32(out, 0);  // pixelDepth
    put32(out, 0);  // layerCount
    put32(out, 1);  // faceCount
    put32(out, 1);  // levelCount
    put32(out, 0);  // supercompressionScheme: none
    put32(out, static_cast<std::uint32_t>(kDfdStart));
    put32(out, static_cast<std::uint32_t>(dfd.size()));
    put32(out, static_cast<std::uint32_t>(kvd_offset));
    put32(out, static_cast<std::uint32_t>(kvd.size()));
    put64(out, 0);  // sgdByteOffset
    put64(out, 0);  // sgdByteLength
    put64(out, level_offset);
    put64(out, level_bytes);
    put64(out, level_bytes);  // uncompressedByteLength (no supercompression)
    out.insert(out.end(), dfd.begin(), dfd.end());
    out.insert(out.end(), kvd.begin(), kvd.end());
    out.resize(level_offset, 0);
    return out;
}

Result<std::vector<std::uint8_t>> encode_ktx2(const Ktx2Image& img) {
    auto out = ktx2_header(img.vk_format, img.width, img.height, img.key_values);
    if (!out) return out;
    if (img.blocks.size() != ktx2_level_bytes(img.vk_format, img.width, img.height))
        return make_error(ErrorCode::kInvalidArgument, "ktx2: block data does not match the image size");
    out->insert(out->end(), img.blocks.begin(), img.blocks.end());
    return out;
}

// The Vulkan name of a vkFormat ("VK_FORMAT_ASTC_4x4_SRGB_BLOCK"): the core formats 0-184 and the
// ASTC HDR (SFLOAT) formats 1000066000-1000066013; "" for any other value.
std::string vk_format_name(std::uint32_t vk) {
    static const char* const kCore[185] = {
        "UNDEFINED", "R4G4_UNORM_PACK8", "R4G4B4A4_UNORM_PACK16", "B4G4R4A4_UNORM_PACK16", "R5G6B5_UNORM_PACK16",
        "B5G6R5_UNORM_PACK16", "R5G5B5A1_UNORM_PACK16", "B5G5R5A1_UNORM_PACK16", "A1R5G5B5_UNORM_PACK16", "R8_UNORM",
        "R8_SNORM", "R8_USCALED", "R8_SSCALED", "R8_UINT", "R8_SINT", "R8_SRGB", "R8G8_UNORM", "R8G8_SNORM",
        "R8G8_USCALED", "R8G8_SSCALED", "R8G8_UINT", "R8G8_SINT", "R8G8_SRGB", "R8G8B8_UNORM", "R8G8B8_SNORM",
        "R8G8B8_USCALED", "R8G8B8_SSCALED", "R8G8B8_UINT", "R8G8B8_SINT", "R8G8B8_SRGB", "B8G8R8_UNORM", "B8G8R8_SNORM",
        "B8G8R8_USCALED", "B8G8R8_SSCALED", "B8G8R8_UINT", "B8G8R8_SINT", "B8G8R8_SRGB", "R8G8B8A8_UNORM",
        "R8G8B8A8_SNORM", "R8G8B8A8_USCALED", "R8G8B8A8_SSCALED", "R8G8B8A8_UINT", "R8G8B8A8_SINT", "R8G8B8A8_SRGB",
        "B8G8R8A8_UNORM", "B8G8R8A8_SNORM", "B8G8R8A8_USCALED", "B8G8R8A8_SSCALED", "B8G8R8A8_UINT", "B8G8R8A8_SINT",
        "B8G8R8A8_SRGB", "A8B8G8R8_UNORM_PACK32", "A8B8G8R8_SNORM_PACK32", "A8B8G8R8_USCALED_PACK32",
        "A8B8G8R8_SSCALED_PACK32", "A8B8G8R8_UINT_PACK32", "A8B8G8R8_SINT_PACK32", "A8B8G8R8_SRGB_PACK32",
        "A2R10G10B10_UNORM_PACK32", "A2R10G10B10_SNORM_PACK32", "A2R10G10B10_USCALED_PACK32",
        "A2R10G10B10_SSCALED_PACK32", "A2R10G10B10_UINT_PACK32", "A2R10G10B10_SINT_PACK32", "A2B10G10R10_UNORM_PACK32",
        "A2B10G10R10_SNORM_PACK32", "A2B10G10R10_USCALED_PACK32", "A2B10G10R10_SSCALED_PACK32", "A2B10G10R10_UINT_PACK32",
        "A2B10G10R10_SINT_PACK32", "R16_UNORM", "R16_SNORM", "R16_USCALED", "R16_SSCALED", "R16_UINT", "R16_SINT",
        "R16_SFLOAT", "R16G16_UNORM", "R16G16_SNORM", "R16G16_USCALED", "R16G16_SSCALED", "R16G16_UINT", "R16G16_SINT",
        "R16G16_SFLOAT", "R16G16B16_UNORM", "R16G16B16_SNORM", "R16G16B16_USCALED", "R16G16B16_SSCALED", "R16G16B16_UINT",
        "R16G16B16_SINT", "R16G16B16_SFLOAT", "R16G16B16A16_UNORM", "R16G16B16A16_SNORM", "R16G16B16A16_USCALED",
        "R16G16B16A16_SSCALED", "R16G16B16A16_UINT", "R16G16B16A16_SINT", "R16G16B16A16_SFLOAT", "R32_UINT", "R32_SINT",
        "R32_SFLOAT", "R32G32_UINT", "R32G32_SINT", "R32G32_SFLOAT", "R32G32B32_UINT", "R32G32B32_SINT",
        "R32G32B32_SFLOAT", "R32G32B32A32_UINT", "R32G32B32A32_SINT", "R32G32B32A32_SFLOAT", "R64_UINT", "R64_SINT",
        "R64_SFLOAT", "R64G64_UINT", "R64G64_SINT", "R64G64_SFLOAT", "R64G64B64_UINT", "R64G64B64_SINT",
        "R64G64B64_SFLOAT", "R64G64B64A64_UINT", "R64G64B64A64_SINT", "R64G64B64A64_SFLOAT", "B10G11R11_UFLOAT_PACK32",
        "E5B9G9R9_UFLOAT_PACK32", "D16_UNORM", "X8_D24_UNORM_PACK32", "D32_SFLOAT", "S8_UINT", "D16_UNORM_S8_UINT",
        "D24_UNORM_S8_UINT", "D32_SFLOAT_S8_UINT", "BC1_RGB_UNORM_BLOCK", "BC1_RGB_SRGB_BLOCK", "BC1_RGBA_UNORM_BLOCK",
        "BC1_RGBA_SRGB_BLOCK", "BC2_UNORM_BLOCK", "BC2_SRGB_BLOCK", "BC3_UNORM_BLOCK", "BC3_SRGB_BLOCK",
        "BC4_UNORM_BLOCK", "BC4_SNORM_BLOCK", "BC5_UNORM_BLOCK", "BC5_SNORM_BLOCK", "BC6H_UFLOAT_BLOCK",
        "BC6H_SFLOAT_BLOCK", "BC7_UNORM_BLOCK", "BC7_SRGB_BLOCK", "ETC2_R8G8B8_UNORM_BLOCK", "ETC2_R8G8B8_SRGB_BLOCK",
        "ETC2_R8G8B8A1_UNORM_BLOCK", "ETC2_R8G8B8A1_SRGB_BLOCK", "ETC2_R8G8B8A8_UNORM_BLOCK", "ETC2_R8G8B8A8_SRGB_BLOCK",
        "EAC_R11_UNORM_BLOCK", "EAC_R11_SNORM_BLOCK", "EAC_R11G11_UNORM_BLOCK", "EAC_R11G11_SNORM_BLOCK",
        "ASTC_4x4_UNORM_BLOCK", "ASTC_4x4_SRGB_BLOCK", "ASTC_5x4_UNORM_BLOCK", "ASTC_5x4_SRGB_BLOCK",
        "ASTC_5x5_UNORM_BLOCK", "ASTC_5x5_SRGB_BLOCK", "ASTC_6x5_UNORM_BLOCK", "ASTC_6x5_SRGB_BLOCK",
        "ASTC_6x6_UNORM_BLOCK", "ASTC_6x6_SRGB_BLOCK", "ASTC_8x5_UNORM_BLOCK", "ASTC_8x5_SRGB_BLOCK",
        "ASTC_8x6_UNORM_BLOCK", "ASTC_8x6_SRGB_BLOCK", "ASTC_8x8_UNORM_BLOCK", "ASTC_8x8_SRGB_BLOCK",
        "ASTC_10x5_UNORM_BLOCK", "ASTC_10x5_SRGB_BLOCK", "ASTC_10x6_UNORM_BLOCK", "ASTC_10x6_SRGB_BLOCK",
        "ASTC_10x8_UNORM_BLOCK", "ASTC_10x8_SRGB_BLOCK", "ASTC_10x10_UNORM_BLOCK", "ASTC_10x10_SRGB_BLOCK",
        "ASTC_12x10_UNORM_BLOCK", "ASTC_12x10_SRGB_BLOCK", "ASTC_12x12_UNORM_BLOCK", "ASTC_12x12_SRGB_BLOCK",
    };
    if (vk < 185) return std::string("VK_FORMAT_") + kCore[vk];
    // VK_EXT_texture_compression_astc_hdr: the ASTC footprints in the order of the core UNORM ones
    // (157, 159, ..., 183).
    if (vk >= 1000066000u && vk <= 1000066013u) {
        std::string unorm = kCore[157 + 2 * (vk - 1000066000u)];  // "ASTC_4x4_UNORM_BLOCK"
        return "VK_FORMAT_" + unorm.replace(unorm.find("UNORM"), 5, "SFLOAT");
    }
    return "";
}

std::string vk_format_label(std::uint32_t vk) {
    const std::string name = vk_format_name(vk);
    return name.empty() ? "vkFormat " + std::to_string(vk) : name + " (vkFormat " + std::to_string(vk) + ")";
}

Result<TextureHeaderSummary> describe_ktx2_header(std::span<const std::uint8_t> b, const std::string& name) {
    if (b.size() < 12 || std::memcmp(b.data(), kIdentifier, 12) != 0)
        return bad(ErrorCode::kBadFormat, name, "not a KTX2 file (bad identifier at byte 0)" + git_lfs_hint(b));
    if (b.size() < 48) return bad(ErrorCode::kTruncated, name, "header truncated (file ends before byte 48)");
    static const std::pair<std::uint32_t, const char*> kNames[] = {
        {23, "R8G8B8_UNORM"}, {29, "R8G8B8_SRGB"}, {37, "R8G8B8A8_UNORM"}, {43, "R8G8B8A8_SRGB"}, {44, "B8G8R8A8_UNORM"},
        {50, "B8G8R8A8_SRGB"}, {90, "R16G16B16_SFLOAT"}, {97, "R16G16B16A16_SFLOAT"}, {106, "R32G32B32_SFLOAT"},
        {109, "R32G32B32A32_SFLOAT"}, {122, "B10G11R11_UFLOAT_PACK32"}, {123, "E5B9G9R9_UFLOAT_PACK32"},
        {131, "BC1_RGB_UNORM_BLOCK"}, {132, "BC1_RGB_SRGB_BLOCK"}, {133, "BC1_RGBA_UNORM_BLOCK"}, {134, "BC1_RGBA_SRGB_BLOCK"},
        {135, "BC2_UNORM_BLOCK"}, {136, "BC2_SRGB_BLOCK"}, {137, "BC3_UNORM_BLOCK"}, {138, "BC3_SRGB_BLOCK"},
        {139, "BC4_UNORM_BLOCK"}, {140, "BC4_SNORM_BLOCK"}, {141, "BC5_UNORM_BLOCK"}, {142, "BC5_SNORM_BLOCK"},
        {143, "BC6H_UFLOAT_BLOCK"}, {144, "BC6H_SFLOAT_BLOCK"}, {145, "BC7_UNORM_BLOCK"}, {146, "BC7_SRGB_BLOCK"}};
    TextureHeaderSummary out;
    out.container = "KTX2";
    const std::uint32_t vk = get32(b, 12);
    out.format = vk_format_label(vk);
    for (const auto& [v, n] : kNames)
        if (v == vk) out.format = std::string(n) + " (vkFormat " + std::to_string(vk) + ")";
    if (vk == 0) out.format = "VK_FORMAT_UNDEFINED (vkFormat 0: Basis Universal or another format the DFD describes)";
    out.width = get32(b, 20), out.height = get32(b, 24), out.depth = get32(b, 28);
    out.layers = get32(b, 32), out.faces = get32(b, 36), out.levels = get32(b, 40);
    const std::uint32_t scheme = get32(b, 44);
    const char* schemes[] = {"none", "BasisLZ", "Zstandard", "ZLIB"};
    out.supercompression = scheme < 4 ? schemes[scheme] : std::to_string(scheme);
    return out;
}

std::uint64_t ktx2_level_bytes(std::uint32_t vk_format, int width, int height) {
    if (width <= 0 || height <= 0) return 0;
    const auto [bx, by] = ktx2_block_dims(vk_format);
    return static_cast<std::uint64_t>((width + bx - 1) / bx) * static_cast<std::uint64_t>((height + by - 1) / by) * ktx2_block_bytes(vk_format);
}

namespace {
// decode_ktx2's checks on the first bytes `b` of a file of `size` bytes (b holds at least
// min(size, 104 + the DFD's length) bytes): the image description without its blocks, and the
// byte offset of the level data.
Result<Ktx2Image> decode_ktx2_layout(std::span<const std::uint8_t> b, std::uint64_t size, const std::string& name,
                                     const Ktx2Limits& limits, std::uint64_t* data_offset) {
    if (b.size() < 12 || std::memcmp(b.data(), kIdentifier, 12) != 0)
        return bad(ErrorCode::kBadFormat, name, "not a KTX2 file (bad identifier at byte 0)" + git_lfs_hint(b));
    if (size < kDfdStart || b.size() < kDfdStart) return bad(ErrorCode::kTruncated, name, "header truncated (file ends before byte 104)");
    Ktx2Image img;
    img.vk_format = get32(b, 12);
    const std::uint32_t type_size = get32(b, 16), w = get32(b, 20), h = get32(b, 24), depth = get32(b, 28),
                        layers = get32(b, 32), faces = get32(b, 36), levels = get32(b, 40), scheme = get32(b, 44);
    const std::size_t bb = ktx2_block_bytes(img.vk_format);
    if (bb == 0)
        return bad(ErrorCode::kUnsupported, name, "unsupported " + vk_format_label(img.vk_format) +
                                                      " (byte 12; zhc reads 139 BC4, 141 BC5, 143 BC6H_UFLOAT, ASTC 4x4/5x5/6x6/8x8 UNORM and SFLOAT)");
    if (type_size != 1) return bad(ErrorCode::kBadFormat, name, "typeSize must be 1 for block formats (byte 16)");
    if (w == 0 || h == 0) return bad(ErrorCode::kBadFormat, name, "zero pixelWidth/pixelHeight (bytes 20-27)");
    if (w > static_cast<std::uint32_t>(limits.max_dimension) || h > static_cast<std::uint32_t>(limits.max_dimension))
        return bad(ErrorCode::kTooLarge, name, std::to_string(w) + "x" + std::to_string(h) + " exceeds the limit " +
                                                   std::to_string(limits.max_dimension) + " (bytes 20-27)");
    if (depth != 0 || layers != 0 || faces != 1)
        return bad(ErrorCode::kUnsupported, name, "only single 2-D images are supported (pixelDepth 0, layerCount 0, faceCount 1; bytes 28-39)");
    if (levels != 1) return bad(ErrorCode::kUnsupported, name, "levelCount " + std::to_string(levels) + " (byte 40): zhc reads exactly one mip level");
    if (scheme != 0) return bad(ErrorCode::kUnsupported, name, "supercompressionScheme " + std::to_string(scheme) + " (byte 44): only 0 (none)");
    const std::uint32_t dfd_off = get32(b, 48), dfd_len = get32(b, 52), kvd_off = get32(b, 56), kvd_len = get32(b, 60);
    const std::uint64_t sgd_off = get64(b, 64), sgd_len = get64(b, 72);
    const std::uint64_t lvl_off = get64(b, 80), lvl_len = get64(b, 88), lvl_ulen = get64(b, 96);
    if (sgd_off != 0 || sgd_len != 0) return bad(ErrorCode::kBadFormat, name, "supercompression global data without a scheme (bytes 64-79)");
    const auto expected_dfd = make_dfd(img.vk_format);
    if (dfd_off != kDfdStart || dfd_len != expected_dfd.size())
        return bad(ErrorCode::kBadFormat, name, "data format descriptor not where/as long as expected (bytes 48-55)");
    if (static_cast<std::uint64_t>(dfd_off) + dfd_len > size || static_cast<std::uint64_t>(dfd_off) + dfd_len > b.size())
        return bad(ErrorCode::kTruncated, name, "file ends inside the data format descriptor (byte " + std::to_string(dfd_off) + ")");
    if (std::memcmp(b.data() + dfd_off, expected_dfd.data(), expected_dfd.size()) != 0)
        return bad(ErrorCode::kBadFormat, name, "data format descriptor does not describe vkFormat " + std::to_string(img.vk_format) +
                                                    " (byte " + std::to_string(dfd_off) + ")");
    if (kvd_len > kMaxKvdBytes)
        return bad(ErrorCode::kBadFormat, name, "key/value data of " + std::to_string(kvd_len) + " bytes exceeds the limit " +
                                                    std::to_string(kMaxKvdBytes) + " (byte 60)");
    if (kvd_len != 0) {
        // Key/value data must lie between the DFD and the level data; every entry is parsed.
        if (kvd_off < dfd_off + dfd_len || static_cast<std::uint64_t>(kvd_off) + kvd_len > lvl_off ||
            static_cast<std::uint64_t>(kvd_off) + kvd_len > b.size())
            return bad(ErrorCode::kBadFormat, name, "key/value data outside its place (bytes 56-63)");
        // Entries: u32 keyAndValueByteLength, NUL-terminated key, value, padding to 4 bytes.
        std::size_t at = kvd_off;
        const std::size_t end = static_cast<std::size_t>(kvd_off) + kvd_len;
        while (at < end) {
            if (end - at < 4) return bad(ErrorCode::kBadFormat, name, "key/value entry truncated (byte " + std::to_string(at) + ")");
            const std::uint32_t len = get32(b, at);
            if (len > end - at - 4) return bad(ErrorCode::kBadFormat, name, "key/value entry longer than the data (byte " + std::to_string(at) + ")");
            const auto* p = b.data() + at + 4;
            const auto* nul = static_cast<const std::uint8_t*>(std::memchr(p, 0, len));
            if (nul == nullptr || nul == p)
                return bad(ErrorCode::kBadFormat, name, "key/value entry without a NUL-terminated key (byte " + std::to_string(at) + ")");
            Ktx2KeyValue e;
            e.key.assign(reinterpret_cast<const char*>(p), static_cast<std::size_t>(nul - p));
            e.value.assign(nul + 1, p + len);
            img.key_values.push_back(std::move(e));
            at = align_up(at + 4 + len, 4);
        }
    } else if (kvd_off != 0) {
        return bad(ErrorCode::kBadFormat, name, "kvdByteOffset without kvdByteLength (byte 56)");
    }
    const std::uint64_t expected = ktx2_level_bytes(img.vk_format, static_cast<int>(w), static_cast<int>(h));
    if (lvl_len != expected || lvl_ulen != expected)
        return bad(ErrorCode::kBadFormat, name, "level 0 byteLength " + std::to_string(lvl_len) + " but " +
                                                    std::to_string(w) + "x" + std::to_string(h) + " needs " +
                                                    std::to_string(expected) + " (bytes 88-103)");
    if (lvl_off % bb != 0 || lvl_off < dfd_off + dfd_len)
        return bad(ErrorCode::kBadFormat, name, "level 0 byteOffset " + std::to_string(lvl_off) + " misaligned or overlapping (byte 80)");
    if (lvl_off > size || size - lvl_off < lvl_len)
        return bad(ErrorCode::kTruncated, name, "file ends inside the level data (needs " + std::to_string(lvl_off + lvl_len) +
                                                    " bytes, has " + std::to_string(size) + ")");
    if (size != lvl_off + lvl_len)
        return bad(ErrorCode::kTrailingBytes, name, std::to_string(size - lvl_off - lvl_len) + " bytes after the level data (byte " +
                                                        std::to_string(lvl_off + lvl_len) + ")");
    img.width = static_cast<int>(w);
    img.height = static_cast<int>(h);
    *data_offset = lvl_off;
    return img;
}
}  // namespace

Result<Ktx2Image> decode_ktx2(std::span<const std::uint8_t> b, const std::string& name, const Ktx2Limits& limits) {
    std::uint64_t off = 0;
    auto img = decode_ktx2_layout(b, b.size(), name, limits, &off);
    if (!img) return img;
    img->blocks.assign(b.begin() + static_cast<std::ptrdiff_t>(off), b.end());
    return img;
}

Result<BlockFileLayout> read_ktx2_layout(const std::string& path, const Ktx2Limits& limits) {
    auto prefix = read_file_prefix(path, 1 << 16);
    if (!prefix) return prefix.error();
    BlockFileLayout l;
    auto img = decode_ktx2_layout(prefix->bytes, prefix->file_size, path, limits, &l.data_offset);
    if (!img) return img.error();
    l.vk_format = img->vk_format;
    l.key_values = std::move(img->key_values);
    l.width = img->width;
    l.height = img->height;
    return l;
}


Status write_ktx2(const std::string& path, const Ktx2Image& image) {
    auto bytes = encode_ktx2(image);
    if (!bytes) return make_error(bytes.error().code, path + ": " + bytes.error().message);
    return write_file_atomic(path, *bytes);
}

Result<Ktx2Image> read_ktx2(const std::string& path, const Ktx2Limits& limits) {
    const std::uint64_t dim = static_cast<std::uint64_t>(limits.max_dimension);
    auto bytes = read_file_bytes(path, 4096 + (dim + 3) / 4 * ((dim + 3) / 4) * 16);
    if (!bytes) return bytes.error();
    return decode_ktx2(*bytes, path, limits);
}

}  // namespace zhc
