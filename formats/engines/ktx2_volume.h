// zhc/formats/engines/ktx2_volume.h — uncompressed KTX 2.0 textures, 2-D or 3-D, for the engine
// files that ship probes as textures (docs/engine-files.md).
//
// Writes and reads one kind of KTX2 (https://registry.khronos.org/KTX/specs/2.0/ktxspec.v2.html):
// one image, 2-D (pixelDepth 0) or 3-D, one mip level, one face, no array layers, no
// supercompression, in one of the uncompressed formats below, with a Basic Data Format Descriptor
// and optional key/value data. The DFD zhc writes is the one Khronos' libktx (external/dfdutils
// createdfd.c createDFDUnpacked, vk2dfd.inl) writes for the format, as do the tools that use it
// (bevy-baked-gi's export-blender-gi through the vk2dfd crate).
//
// The reader is strict and safe for untrusted bytes: every header field, the level index, the
// DFD (its layout: model, transfer, bytes per texel, each sample's bit offset, bit length and
// channel; the sample bounds and the primaries are not checked, writers differ there) and the
// key/value data are checked, and the texel count is checked against a limit before anything is
// allocated. A file that uses what this reader does not (mip levels, supercompression, array layers,
// cube faces, other formats) gets one error naming all of it.
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "codec/status.h"
#include "formats/lightmap/ktx2.h"

namespace zhc {

inline constexpr std::uint32_t kVkFormatR16g16b16a16Sfloat = 97;
inline constexpr std::uint32_t kVkFormatR32g32b32a32Sfloat = 109;
inline constexpr std::uint32_t kVkFormatE5b9g9r9UfloatPack32 = 123;

// An uncompressed texture: level 0 only.
struct Ktx2Texture {
    std::uint32_t vk_format = 0;
    std::uint32_t width = 0, height = 0, depth = 0;  // depth 0 = 2-D
    std::vector<std::uint8_t> texels;                // x fastest, then y, then z; little-endian texels
    // Written sorted by key (the KTX2 spec requires it; keys unique, non-empty, without NUL);
    // read: every entry, in the file's order.
    std::vector<Ktx2KeyValue> key_values;
};

// Bytes per texel of a format encode/decode_ktx2_texture handle (8, 16, 4); 0 for any other.
std::size_t ktx2_texel_bytes(std::uint32_t vk_format);

// kInvalidArgument for an unsupported format, an empty size, texels of the wrong length or bad keys.
Result<std::vector<std::uint8_t>> encode_ktx2_texture(const Ktx2Texture& texture);
// `max_texels` bounds width * height * max(depth, 1) (kTooLarge above it). Errors name `name`.
Result<Ktx2Texture> decode_ktx2_texture(std::span<const std::uint8_t> bytes, const std::string& name,
                                        std::uint64_t max_texels = 1u << 28);

}  // namespace zhc
