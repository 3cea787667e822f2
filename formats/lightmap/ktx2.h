// zhc/formats/lightmap/ktx2.h — KTX 2.0 files for zhc's block-compressed lightmap textures.
//
// Writes and reads exactly one kind of KTX2: a single 2-D image (no array layers, one face, one mip
// level, no supercompression) in VK_FORMAT_BC6H_UFLOAT_BLOCK (143), VK_FORMAT_BC5_UNORM_BLOCK (141),
// VK_FORMAT_BC4_UNORM_BLOCK (139) or ASTC 4x4 / 5x5 / 6x6 / 8x8 UNORM or SFLOAT (formats/lightmap/astc.h),
// with a Basic Data Format Descriptor (docs/lightmap-formats.md) and optional key/value data.
// The reader is strict and safe for untrusted bytes: sizes are checked against limits before
// anything is allocated, and each kind of problem has its own error code and message.
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

inline constexpr std::uint32_t kVkFormatBc4Unorm = 139;
inline constexpr std::uint32_t kVkFormatBc5Unorm = 141;
inline constexpr std::uint32_t kVkFormatBc6hUfloat = 143;

// One entry of the key/value data (the key without its NUL; the value as stored).
struct Ktx2KeyValue {
    std::string key;
    std::vector<std::uint8_t> value;
};

struct Ktx2Image {
    std::uint32_t vk_format = 0;
    int width = 0, height = 0;
    std::vector<std::uint8_t> blocks;  // ceil(w/bx) * ceil(h/by) blocks, row-major (bx x by: ktx2_block_dims)
    std::vector<Ktx2KeyValue> key_values;  // written in this order; read: every entry of the file
};

// The Vulkan name of a vkFormat value ("VK_FORMAT_ASTC_4x4_SRGB_BLOCK" for 158): the core formats
// 0-184 and the ASTC HDR formats 1000066000-1000066013; "" for any other value. vk_format_label:
// "VK_FORMAT_ASTC_4x4_SRGB_BLOCK (vkFormat 158)", or "vkFormat N" for a value with no name here.
std::string vk_format_name(std::uint32_t vk_format);
std::string vk_format_label(std::uint32_t vk_format);

// Bytes per block of a supported format (8 or 16); 0 if unsupported.
std::size_t ktx2_block_bytes(std::uint32_t vk_format);
// The block footprint in texels: 4x4 for BC, the ASTC footprint for ASTC.
std::array<int, 2> ktx2_block_dims(std::uint32_t vk_format);

struct Ktx2Limits {
    int max_dimension = 16384;
};

Result<std::vector<std::uint8_t>> encode_ktx2(const Ktx2Image& image);
// Streaming: everything encode_ktx2 writes before the blocks (every header field depends only on
// the format and the size: one level, no supercompression), and the level's byte length (0 for an
// unsupported format or an empty size). encode_ktx2 = ktx2_header + the blocks.
Result<std::vector<std::uint8_t>> ktx2_header(std::uint32_t vk_format, int width, int height,
                                              const std::vector<Ktx2KeyValue>& key_values = {});
std::uint64_t ktx2_level_bytes(std::uint32_t vk_format, int width, int height);

// A block file's description without its blocks (streaming reads): the format, the size and the
// byte offset of the level data, which runs to the end of the file (ceil(w/4) * ceil(h/4) blocks,
// row-major). read_ktx2_layout / read_dds_layout make every check decode_ktx2 / decode_dds make,
// from the file's first bytes and its size, without reading the blocks.
struct BlockFileLayout {
    std::uint32_t vk_format = 0;
    int width = 0, height = 0;
    std::uint64_t data_offset = 0;
    std::vector<Ktx2KeyValue> key_values;  // KTX2 only
};
// A KTX2 or DDS file's header as it stands (zhc info on textures zhc does not read: 2-D textures
// in other formats, arrays, volumes): the fields, checked to lie inside the file, nothing more.
struct TextureHeaderSummary {
    std::string container;  // "KTX2" or "DDS"
    std::string format;     // e.g. "BC7_UNORM_BLOCK (vkFormat 145)", "BC1_UNORM (DXGI 71)", "FourCC 'DXT1'"
    std::uint64_t width = 0, height = 0, depth = 0, layers = 0, faces = 0, levels = 0;
    std::string supercompression;  // KTX2: "none", "BasisLZ", "Zstandard", "ZLIB" or the number
};
Result<TextureHeaderSummary> describe_ktx2_header(std::span<const std::uint8_t> bytes, const std::string& name);
Result<TextureHeaderSummary> describe_dds_header(std::span<const std::uint8_t> bytes, const std::string& name);
Result<BlockFileLayout> read_ktx2_layout(const std::string& path, const Ktx2Limits& limits = {});
Result<Ktx2Image> decode_ktx2(std::span<const std::uint8_t> bytes, const std::string& name, const Ktx2Limits& limits = {});
Status write_ktx2(const std::string& path, const Ktx2Image& image);
Result<Ktx2Image> read_ktx2(const std::string& path, const Ktx2Limits& limits = {});

}  // namespace zhc
