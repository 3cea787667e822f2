// zhc/formats/lightmap/dds.h — DDS files for zhc's block-compressed lightmap textures (the alternative to KTX2).
//
// Writes exactly one kind of DDS: magic, DDS_HEADER, DDS_PIXELFORMAT with FourCC 'DX10', then the
// DDS_HEADER_DXT10 extension header and one 2-D image (no array, no cube, one mip level) in
// DXGI_FORMAT_BC6H_UF16 (95), DXGI_FORMAT_BC5_UNORM (83) or DXGI_FORMAT_BC4_UNORM (80). The data
// starts at byte 148 (docs/lightmap-formats.md lists every header field written).
//
// The in-memory image is the KTX2 module's Ktx2Image: the format is named by its Vulkan vkFormat
// (kVkFormatBc6hUfloat / Bc5Unorm / Bc4Unorm), which this module maps to and from the DXGI format,
// so the CLI handles both containers with one struct and the same block bytes.
//
// The reader is strict and safe for untrusted bytes (the same policy as the KTX2 reader): sizes are
// checked against limits before anything is allocated; every problem is a one-line message naming
// the file, what is wrong and the header field with its byte offset; truncation (kTruncated),
// trailing bytes (kTrailingBytes), malformed fields (kBadFormat), unsupported features (kUnsupported)
// and oversized dimensions (kTooLarge) are distinct codes. Besides 'DX10' it reads the legacy FourCCs
// 'ATI1' / 'BC4U' (as BC4_UNORM) and 'ATI2' / 'BC5U' (as BC5_UNORM), data at byte 128.
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "codec/status.h"
#include "formats/lightmap/ktx2.h"

namespace zhc {

inline constexpr std::uint32_t kDxgiFormatBc4Unorm = 80;
inline constexpr std::uint32_t kDxgiFormatBc5Unorm = 83;
inline constexpr std::uint32_t kDxgiFormatBc6hUf16 = 95;

// vkFormat <-> DXGI_FORMAT for the three supported formats; 0 for anything else.
std::uint32_t dxgi_format_for_vk(std::uint32_t vk_format);
std::uint32_t vk_format_for_dxgi(std::uint32_t dxgi_format);

// Bytes before the block data in the files zhc writes: 4 (magic) + 124 (DDS_HEADER) + 20 (DXT10).
inline constexpr std::size_t kDdsDataOffset = 148;

struct DdsLimits {
    int max_dimension = 16384;
};

Result<std::vector<std::uint8_t>> encode_dds(const Ktx2Image& image);
// Streaming: the 148 bytes encode_dds writes before the blocks (every field depends only on the
// format and the size); encode_dds = dds_header + the blocks.
Result<std::vector<std::uint8_t>> dds_header(std::uint32_t vk_format, int width, int height);
// See BlockFileLayout (ktx2.h).
Result<BlockFileLayout> read_dds_layout(const std::string& path, const DdsLimits& limits = {});
Result<Ktx2Image> decode_dds(std::span<const std::uint8_t> bytes, const std::string& name, const DdsLimits& limits = {});
Status write_dds(const std::string& path, const Ktx2Image& image);
Result<Ktx2Image> read_dds(const std::string& path, const DdsLimits& limits = {});

}  // namespace zhc
