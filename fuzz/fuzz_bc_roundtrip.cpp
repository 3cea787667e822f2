// Block codecs round trip: 16 texels from the input, encoded (fast quality) then decoded.
// BC4: error within the palette's reach, (max - min) / 7 + 2/255 per texel. BC6H: finite,
// non-negative output, and a constant block decodes within 1 % (+ half-float resolution).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "codec/lightmap/bc45.h"
#include "codec/lightmap/bc6h.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1 + 16) return 0;
    const bool bc6 = data[0] & 1;
    const bool constant = data[0] & 2;
    if (!bc6) {
        float v[16];
        for (int i = 0; i < 16; ++i) v[i] = data[1 + (constant ? 0 : i)] / 255.0f;
        std::uint8_t block[8];
        zhc::bc45::encode_bc4_block(v, zhc::bc45::Quality::kFast, block);
        float out[16];
        zhc::bc45::decode_bc4_block(block, out);
        const float lo = *std::min_element(v, v + 16), hi = *std::max_element(v, v + 16);
        for (int i = 0; i < 16; ++i)
            if (std::fabs(out[i] - v[i]) > (hi - lo) / 7.0f + 2.0f / 255.0f) std::abort();
        return 0;
    }
    if (size < 1 + 16 * 3 * 2) return 0;
    float rgb[16][3];
    for (int i = 0; i < 16; ++i)
        for (int k = 0; k < 3; ++k) {
            std::uint16_t h;
            std::memcpy(&h, data + 1 + ((constant ? 0 : i) * 3 + k) * 2, 2);
            h &= 0x7BFF;  // non-negative, finite half
            rgb[i][k] = zhc::bc6h::half_to_float(h);
        }
    std::uint8_t block[16];
    zhc::bc6h::encode_block(rgb, zhc::bc6h::Quality::kFast, block);
    std::uint16_t out[16][3];
    zhc::bc6h::decode_block(block, out);
    for (int i = 0; i < 16; ++i)
        for (int k = 0; k < 3; ++k) {
            const float f = zhc::bc6h::half_to_float(out[i][k]);
            if (!std::isfinite(f) || f < 0) std::abort();
            if (constant && std::fabs(f - rgb[i][k]) > 0.01f * rgb[i][k] + 1e-4f) std::abort();
        }
    return 0;
}
