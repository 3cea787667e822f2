// Shared by the container fuzzers (fuzz_ktx2, fuzz_dds): what every accepted lightmap texture must
// satisfy, whichever container it came in. Aborts (a libFuzzer finding) on any violation.
#pragma once

#include <cstdlib>
#include <string>

#include "codec/bc45.h"
#include "codec/bc6h.h"
#include "formats/ktx2.h"

namespace zhc::fuzz {

// A refusal must be a one-line message.
inline void check_refusal(const Error& e) {
    if (e.message.find('\n') != std::string::npos) std::abort();
}

// Exactly the blocks of its size, and zhc's decoders total on them (every bit pattern decodes to
// something defined: finite halves for BC6H, [0, 1] for BC4/BC5).
inline void check_texture(const Ktx2Image& img) {
    const std::size_t bw = (img.width + 3) / 4, bh = (img.height + 3) / 4;
    if (img.blocks.size() != bw * bh * ktx2_block_bytes(img.vk_format)) std::abort();
    if (img.vk_format == kVkFormatBc6hUfloat) {
        const auto halfs = bc6h::decode_image(img.blocks.data(), img.blocks.size(), img.width, img.height);
        if (halfs.size() != static_cast<std::size_t>(img.width) * img.height * 3) std::abort();
    } else {
        const int channels = img.vk_format == kVkFormatBc5Unorm ? 2 : 1;
        const auto v = bc45::decode_image(img.blocks.data(), img.blocks.size(), channels, img.width, img.height);
        for (float f : v)
            if (!(f >= 0.0f && f <= 1.0f)) std::abort();
    }
}

}  // namespace zhc::fuzz
