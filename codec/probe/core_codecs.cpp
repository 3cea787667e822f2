// The hub itself (sh3, 27 floats) and linear SH (sh2, the L2 band dropped).
#include "codec/probe/codec.h"

namespace zhc {
namespace {

template <int Count>
void encode_floats(const Sh3Radiance& in, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    float v[Count * 3];
    for (int i = 0; i < Count; ++i)
        for (int k = 0; k < 3; ++k) v[i * 3 + k] = in[i][k];
    store_floats(v, out);
}

template <int Count>
Sh3Radiance decode_floats(const std::uint8_t* in, const CodecOptions&) {
    float v[Count * 3];
    load_floats(in, v);
    Sh3Radiance out;
    for (int i = 0; i < Count; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = v[i * 3 + k];
    return out;
}

template <int Count>
Rgb irradiance_floats(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return irradiance(decode_floats<Count>(in, o), n);
}

const Codec kCore[] = {
    {"sh3", "quadratic SH, 27 floats (the hub)", 27 * 4, encode_floats<9>, decode_floats<9>,
     irradiance_floats<9>, {.exact = true, .float_bands = 3}},
    {"sh2", "linear SH, 12 floats (L2 band dropped)", 12 * 4, encode_floats<4>, decode_floats<4>,
     irradiance_floats<4>, {.float_bands = 2}},
};

}  // namespace

std::span<const Codec> core_codecs() { return kCore; }

}  // namespace zhc
