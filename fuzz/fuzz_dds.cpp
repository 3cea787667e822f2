// DDS lightmap textures from untrusted bytes, then their BC6H/BC5/BC4 blocks through zhc's
// decoders (which must be total: every bit pattern decodes to something defined). An accepted file
// must also survive a write/read round trip with the same blocks.
#include <cstdint>

#include "formats/lightmap/dds.h"
#include "texture_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return zhc::fuzz::fuzz_container<zhc::DdsLimits>(data, size, zhc::decode_dds, zhc::encode_dds);
}
