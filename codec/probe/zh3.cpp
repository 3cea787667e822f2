// zhc/codec/probe/zh3.cpp — the 15-float ZH3 layout (store_zh3 / load_zh3, zh3_internal.h) and its
// fit and solved codec-table entries (zh3_codecs()).
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md.
// The algorithms, one file each: the fit and axes (Eq. 9/10, Sec. 3.1/3.2) in zh3_fit.cpp, the
// L-BFGS axis solve (Sec. 3.3, Eq. 11, App. C) in zh3_solve.cpp, hallucination (Sec. 3.4,
// Listing 1) and the hall_* entries in zh3_hallucinate.cpp, App. B's zonal clamp and its whole-sphere
// variant with their entries in zh3_clamp.cpp, the windowed deringer (zh3_dering) in zh3_dering.cpp.
#include "codec/probe/zh3.h"

#include "codec/probe/zh3_internal.h"

namespace zhc {

namespace detail {

void store_zh3(const Zh3& z, std::uint8_t* out) {
    float v[kZh3Floats];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) v[i * 3 + k] = z.linear[i][k];
    for (int k = 0; k < 3; ++k) v[12 + k] = z.zonal[k];
    store_floats(v, out);
}
Zh3 load_zh3(const std::uint8_t* in) {
    float v[kZh3Floats];
    load_floats(in, v);
    Zh3 z;
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) z.linear[i][k] = v[i * 3 + k];
    for (int k = 0; k < 3; ++k) z.zonal[k] = v[12 + k];
    return z;
}

}  // namespace detail

namespace {

using namespace detail;

// ---- codec entries ----------------------------------------------------------------------------

template <ZonalAxisMode Mode>
void encode_fit(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats*) {
    store_zh3(zh3_fit(in, Mode, o.luminance), out);
}
template <ZonalAxisMode Mode>
void encode_solved(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    store_zh3(zh3_solve(in, Mode, o, stats), out);
}
constexpr auto kLum = ZonalAxisMode::kLuminance;
constexpr auto kChan = ZonalAxisMode::kPerChannel;

constexpr CodecTraits kLumAxis{.zonal_axis = ZonalAxis::kLuminance};
constexpr CodecTraits kChanAxis{.zonal_axis = ZonalAxis::kPerChannel};

const Codec kZh3Codecs[] = {
    {"zh3_lum", "ZH3 fit (Eq. 9/10) on the luminance L1 axis, 15 floats", kZh3Floats * 4, encode_fit<kLum>,
     decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_channel", "ZH3 fit (Eq. 9/10) on each channel's L1 axis, 15 floats", kZh3Floats * 4, encode_fit<kChan>,
     decode_zh3<kChan>, irradiance_zh3<kChan>, kChanAxis},
    {"zh3_solved_lum", "ZH3, luminance axis solved by BFGS (Eq. 11), 15 floats", kZh3Floats * 4,
     encode_solved<kLum>, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_solved_channel", "ZH3, per-channel axes solved by BFGS (Eq. 11), 15 floats", kZh3Floats * 4,
     encode_solved<kChan>, decode_zh3<kChan>, irradiance_zh3<kChan>, kChanAxis},
};

}  // namespace

std::span<const Codec> zh3_codecs() { return kZh3Codecs; }

}  // namespace zhc
