// KTX2 lightmap textures from untrusted bytes, then their BC6H/BC5/BC4 blocks through zhc's
// decoders (which must be total: every bit pattern decodes to something defined).
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "codec/bc45.h"
#include "codec/bc6h.h"
#include "formats/ktx2.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::Ktx2Limits limits;
    limits.max_dimension = 1024;
    auto img = zhc::decode_ktx2({data, size}, "fuzz-input", limits);
    if (!img) return 0;
    const std::size_t bw = (img->width + 3) / 4, bh = (img->height + 3) / 4;
    if (img->blocks.size() != bw * bh * zhc::ktx2_block_bytes(img->vk_format)) std::abort();
    if (img->vk_format == zhc::kVkFormatBc6hUfloat) {
        const auto halfs = zhc::bc6h::decode_image(img->blocks.data(), img->blocks.size(), img->width, img->height);
        if (halfs.size() != static_cast<std::size_t>(img->width) * img->height * 3) std::abort();
    } else {
        const int channels = img->vk_format == zhc::kVkFormatBc5Unorm ? 2 : 1;
        const auto v = zhc::bc45::decode_image(img->blocks.data(), img->blocks.size(), channels, img->width, img->height);
        for (float f : v)
            if (!(f >= 0.0f && f <= 1.0f)) std::abort();
    }
    return 0;
}
