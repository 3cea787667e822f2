// Shared by the container fuzzers (fuzz_ktx2, fuzz_dds): what every accepted lightmap texture must
// satisfy, whichever container it came in, and the whole per-input check. Aborts (a libFuzzer
// finding) on any violation.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "codec/lightmap/bc45.h"
#include "codec/lightmap/bc6h.h"
#include "formats/lightmap/astc.h"
#include "formats/lightmap/ktx2.h"

namespace zhc::fuzz {

// A refusal must be a one-line message.
inline void check_refusal(const Error& e) {
    if (e.message.find('\n') != std::string::npos) std::abort();
}

// Exactly the blocks of its size, and zhc's decoders total on them (every bit pattern decodes to
// something defined: finite halves for BC6H, [0, 1] for BC4/BC5 and LDR ASTC), except that an HDR
// ASTC block with an invalid encoding (the error colour, NaN) is refused in one line, never
// decoded to NaN.
inline void check_texture(const Ktx2Image& img) {
    const auto dims = ktx2_block_dims(img.vk_format);
    const std::size_t bw = (img.width + dims[0] - 1) / dims[0], bh = (img.height + dims[1] - 1) / dims[1];
    if (img.blocks.size() != bw * bh * ktx2_block_bytes(img.vk_format)) std::abort();
    if (const auto f = astc::format_of_vk(img.vk_format)) {
        // ASTC (KTX2 only): astcenc's decoder on every block; LDR values stay in [0, 1].
        auto v = astc::decode_rgba(img.blocks.data(), img.blocks.size(), img.width, img.height, f->footprint, f->hdr);
        if (!v) {
            if (!f->hdr || v.error().code != ErrorCode::kBadFormat) std::abort();
            check_refusal(v.error());
            return;
        }
        for (float x : *v)
            if (f->hdr ? std::isnan(x) : !(x >= 0.0f && x <= 1.0f)) std::abort();
    } else if (img.vk_format == kVkFormatBc6hUfloat) {
        const auto halfs = bc6h::decode_image(img.blocks.data(), img.blocks.size(), img.width, img.height);
        if (halfs.size() != static_cast<std::size_t>(img.width) * img.height * 3) std::abort();
    } else {
        const int channels = img.vk_format == kVkFormatBc5Unorm ? 2 : 1;
        const auto v = bc45::decode_image(img.blocks.data(), img.blocks.size(), channels, img.width, img.height);
        for (float f : v)
            if (!(f >= 0.0f && f <= 1.0f)) std::abort();
    }
}

// One fuzz input through a container's reader and writer (decode_ktx2/encode_ktx2 or
// decode_dds/encode_dds): a refusal is one line; an accepted texture passes check_texture and
// survives a write/read round trip with the same blocks and format.
template <class Limits>
int fuzz_container(const std::uint8_t* data, std::size_t size,
                   Result<Ktx2Image> (*decode)(std::span<const std::uint8_t>, const std::string&, const Limits&),
                   Result<std::vector<std::uint8_t>> (*encode)(const Ktx2Image&)) {
    Limits limits;
    limits.max_dimension = 1024;
    auto img = decode({data, size}, "fuzz-input", limits);
    if (!img) {
        check_refusal(img.error());
        return 0;
    }
    check_texture(*img);
    auto again = encode(*img);
    if (!again) std::abort();
    auto back = decode(*again, "fuzz-reencoded", limits);
    if (!back || back->blocks != img->blocks || back->vk_format != img->vk_format) std::abort();
    return 0;
}

}  // namespace zhc::fuzz
