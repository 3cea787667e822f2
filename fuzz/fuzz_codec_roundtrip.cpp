// Encode then decode through every codec: a finite hub in gives a finite hub out, the same bytes
// every time, and the float hub itself round-trips exactly. Input: 27 floats (little-endian),
// non-finite ones replaced, magnitudes limited to 1e6; one byte picks the codec.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "codec/probe/codec.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto table = zhc::codecs();
    if (size < 1 + 27 * 4 || table.empty()) return 0;
    const zhc::Codec& c = table[data[0] % table.size()];
    zhc::Sh3Radiance hub;
    for (int i = 0; i < 27; ++i) {
        float v;
        std::memcpy(&v, data + 1 + i * 4, 4);
        if (!std::isfinite(v)) v = 0;
        v = std::fmax(-1e6f, std::fmin(1e6f, v));
        hub[i / 3][i % 3] = v;
    }
    zhc::CodecOptions o;
    std::vector<std::uint8_t> a(c.size_bytes), b(c.size_bytes);
    c.encode(hub, o, a.data(), nullptr);
    c.encode(hub, o, b.data(), nullptr);
    if (a != b) std::abort();  // deterministic
    const zhc::Sh3Radiance d = c.decode(a.data(), o);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(d[i][k])) std::abort();
    if (c.traits.exact && !(d == hub)) std::abort();  // exact entries (sh3) give the hub back
    return 0;
}
