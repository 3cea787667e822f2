// zhc/formats/envmap/envmap_cube.h — environment cube maps in KTX2 and DDS (reflection / irradiance probe
// environments as game engines store them), read into an Image of layout kCubeVulkan: N wide, 6N
// high, faces +X -X +Y -Y +Z -Z of the Vulkan / D3D cube table (codec/sh/cubemap.h), row 0 of each
// face its first row in the file (t = 0). Only mip level 0 is read (further levels are checked to
// lie inside the file and otherwise ignored).
//
// KTX2: faceCount 6, 2-D (pixelHeight > 0, pixelDepth 0), pixelWidth == pixelHeight, layerCount
//   0 or 1, supercompressionScheme 0 (none) or 2 (Zstandard: level 0 is one frame whose content
//   size is the level's uncompressedByteLength, checked before allocating); vkFormat R16G16B16A16_SFLOAT (97), R16G16B16_SFLOAT (90),
//   R32G32B32A32_SFLOAT (109), R32G32B32_SFLOAT (106), E5B9G9R9_UFLOAT_PACK32 (123) or
//   BC6H_UFLOAT_BLOCK (143, zhc's own decoder). Refused with kUnsupported (exit 5): other formats
//   (BC6H_SFLOAT_BLOCK: zhc's BC6H decoder is unsigned only), faceCount 1 (a 2-D texture), cube
//   arrays (layerCount > 1), 3-D textures, supercompression BasisLZ (1) and ZLIB (3).
// DDS: magic, DDS_HEADER (124 bytes), cube map with all six faces: legacy header (caps2
//   DDSCAPS2_CUBEMAP and the six face flags) with FourCC 113 (D3DFMT_A16B16G16R16F) or 116
//   (D3DFMT_A32B32G32R32F), or 'DX10' with DXGI_FORMAT R16G16B16A16_FLOAT (10), R32G32B32A32_FLOAT
//   (2), R32G32B32_FLOAT (6), R9G9B9E5_SHAREDEXP (67) or BC6H_UF16 (95), resource dimension
//   TEXTURE2D, DDS_RESOURCE_MISC_TEXTURECUBE and arraySize 1. Data: for each face, its mip chain
//   (mipMapCount levels, 0 meaning 1). Refused with kUnsupported: partial cube maps, 2-D and
//   volume textures, cube arrays, BC6H_SF16 and other formats.
// KTX 1 (the KTX File Format Specification version 1.1, Khronos): numberOfFaces 6,
//   numberOfArrayElements 0, square 2-D faces, either byte order (endianness 0x04030201, or
//   0x01020304 for a file written on a big-endian machine: fields and glTypeSize units swapped);
//   glInternalFormat RGBA16F / RGB16F (glType HALF_FLOAT or FLOAT), RGBA32F / RGB32F (FLOAT),
//   R11F_G11F_B10F, RGB9_E5, COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT, RGBA8 / SRGB8_ALPHA8 (RGBA or
//   BGRA), RGB8 / SRGB8, S3TC DXT1 / DXT3 / DXT5, COMPRESSED_RGBA_BPTC_UNORM and their sRGB forms. Key/value data is skipped;
//   each level's imageSize is one face's bytes (rows padded to 4 bytes) or, as some writers store
//   it, six faces'. Anything else: kUnsupported naming glInternalFormat in hex.
// 8-bit formats (KTX2 R8G8B8A8 / B8G8R8A8 / R8G8B8, BC1-3 and BC7, UNORM or SRGB; DDS DXGI R8G8B8A8 /
//   B8G8R8A8 / B8G8R8X8 / BC1-3 / BC7, UNORM or UNORM_SRGB, legacy DXT1 / DXT3 / DXT5 and 32-bit RGB(A)
//   masks, which are UNORM; KTX 1 BPTC UNORM and its sRGB form): decoded by EnvmapReadOptions::ldr
//   (envmap_ldr.h; BC7 blocks by bc7.h); an UNORM format read by its own transfer function gets a
//   warning that it was read as linear.
// All: every size is checked against the file and the pixel limit before anything is allocated;
// short files are kTruncated, bytes after the last level kTrailingBytes, inconsistent fields
// kBadFormat (exit 4), sizes over the limit kTooLarge (exit 6); every message is one line naming
// the field and its byte offset.
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments. The only process-wide state touched is OpenEXR's own
// global thread pool (grown, never shrunk, when a call asks for more threads; OpenEXR
// guards it), which never changes the bytes read or written.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "formats/envmap/envmap.h"

namespace zhc {

bool is_ktx2(std::span<const std::uint8_t> bytes);  // the KTX 2.0 identifier
bool is_dds(std::span<const std::uint8_t> bytes);   // "DDS "
bool is_ktx1(std::span<const std::uint8_t> bytes);  // the KTX 1 identifier «KTX 11»
bool ktx1_declares_cube(std::span<const std::uint8_t> bytes);  // numberOfFaces 6
// The header says cube map (KTX2 faceCount 6; DDS caps2 CUBEMAP or DX10 TEXTURECUBE).
bool ktx2_declares_cube(std::span<const std::uint8_t> bytes);
bool dds_declares_cube(std::span<const std::uint8_t> bytes);

// Non-finite values are left in the image (read_envmap_memory applies the NonFinitePolicy).
Result<Image> read_ktx2_cube(std::span<const std::uint8_t> bytes, const std::string& name,
                             const EnvmapReadOptions& options, EnvmapInfo* info);
Result<Image> read_ktx1_cube(std::span<const std::uint8_t> bytes, const std::string& name,
                             const EnvmapReadOptions& options, EnvmapInfo* info);
Result<Image> read_dds_cube(std::span<const std::uint8_t> bytes, const std::string& name,
                            const EnvmapReadOptions& options, EnvmapInfo* info);

}  // namespace zhc
