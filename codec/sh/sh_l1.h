// zhc/codec/sh/sh_l1.h — internal to codec/: the L1 band of one colour channel as a vector (shared by
// the codec/probe/zh3*.cpp files).
#pragma once

#include <cstdint>

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"

namespace zhc::detail {

// (x, y, z) of the L1 band of channel k: (-f11, -f1-1, f10) in the real-SH sign convention.
inline Vec3 l1_vector(const Rgb* c, int k) { return {-double(c[3][k]), -double(c[1][k]), double(c[2][k])}; }
// Inverse of l1_vector: writes (f1-1, f10, f11) of channel k.
inline void set_l1(Rgb* c, int k, Vec3 v) {
    c[1][k] = static_cast<float>(-v.y);
    c[2][k] = static_cast<float>(v.z);
    c[3][k] = static_cast<float>(-v.x);
}

// The 48-byte linear-SH layout (sh2, hall_*): DC + L1 of any SH order, 12 little-endian floats.
template <class Sh>
void store_linear(const Sh& s, std::uint8_t* out) {
    float v[12];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) v[i * 3 + k] = s[i][k];
    store_floats(v, out);
}
inline Sh2Radiance load_linear(const std::uint8_t* in) {
    float v[12];
    load_floats(in, v);
    Sh2Radiance s;
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) s[i][k] = v[i * 3 + k];
    return s;
}

}  // namespace zhc::detail
