// DDS lightmap textures from untrusted bytes, then their BC6H/BC5/BC4 blocks through zhc's
// decoders (which must be total: every bit pattern decodes to something defined). An accepted file
// must also survive a write/read round trip with the same blocks.
#include <cstdint>
#include <cstdlib>

#include "formats/dds.h"
#include "texture_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::DdsLimits limits;
    limits.max_dimension = 1024;
    auto img = zhc::decode_dds({data, size}, "fuzz-input", limits);
    if (!img) {
        zhc::fuzz::check_refusal(img.error());
        return 0;
    }
    zhc::fuzz::check_texture(*img);
    auto again = zhc::encode_dds(*img);
    if (!again) std::abort();
    auto back = zhc::decode_dds(*again, "fuzz-reencoded", limits);
    if (!back || back->blocks != img->blocks || back->vk_format != img->vk_format) std::abort();
    return 0;
}
