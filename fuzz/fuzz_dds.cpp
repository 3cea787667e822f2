// DDS lightmap textures from untrusted bytes, then their BC6H/BC5/BC4 blocks through zhc's
// decoders (which must be total: every bit pattern decodes to something defined). An accepted file
// must also survive a write/read round trip with the same blocks.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "codec/bc45.h"
#include "codec/bc6h.h"
#include "formats/dds.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::DdsLimits limits;
    limits.max_dimension = 1024;
    auto img = zhc::decode_dds({data, size}, "fuzz-input", limits);
    if (!img) {
        if (img.error().message.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    const std::size_t bw = (img->width + 3) / 4, bh = (img->height + 3) / 4;
    if (img->blocks.size() != bw * bh * zhc::ktx2_block_bytes(img->vk_format)) std::abort();
    auto again = zhc::encode_dds(*img);
    if (!again) std::abort();
    auto back = zhc::decode_dds(*again, "fuzz-reencoded", limits);
    if (!back || back->blocks != img->blocks || back->vk_format != img->vk_format) std::abort();
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
