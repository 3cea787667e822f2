// Every codec's decoder and runtime irradiance on arbitrary stored bytes: the first byte picks
// the codec, the rest (zero-padded) is its stored probe. Decoders must be total.
#include <cstdint>
#include <cstring>
#include <vector>

#include "codec/probe/codec.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto table = zhc::codecs();
    if (size < 1 || table.empty()) return 0;
    const zhc::Codec& c = table[data[0] % table.size()];
    std::vector<std::uint8_t> stored(c.size_bytes, 0);
    std::memcpy(stored.data(), data + 1, std::min(size - 1, stored.size()));
    zhc::CodecOptions o;
    const zhc::Sh3Radiance d = c.decode(stored.data(), o);
    const zhc::Rgb e = c.irradiance(stored.data(), o, {0.6, 0.0, 0.8});
    volatile float sink = d[0].r + e.g;
    (void)sink;
    return 0;
}
