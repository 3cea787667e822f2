// zhc/codec/probe/zh3.cpp — the ZH3 codec-table entries (zh3_codecs()): the 15-float ZH3 layout
// (fit, solved, deringed) and the hallucinated ones on the 12-float linear-SH layout.
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md.
// The algorithms, one file each: the fit and axes (Eq. 9/10, Sec. 3.1/3.2) in zh3_fit.cpp, the
// L-BFGS axis solve (Sec. 3.3, Eq. 11, App. C) in zh3_solve.cpp, hallucination (Sec. 3.4,
// Listing 1) in zh3_hallucinate.cpp, the two deringers (App. B; whole sphere) in zh3_dering.cpp.
#include "codec/probe/zh3.h"

#include "codec/sh/sh_l1.h"

namespace zhc {
namespace {

using detail::load_linear;

// ---- codec entries ----------------------------------------------------------------------------

constexpr std::size_t kZh3Floats = 15;
constexpr std::size_t kLinearFloats = 12;

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

template <ZonalAxisMode Mode>
void encode_fit(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats*) {
    store_zh3(zh3_fit(in, Mode, o.luminance), out);
}
template <ZonalAxisMode Mode>
void encode_solved(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    store_zh3(zh3_solve(in, Mode, o, stats), out);
}
void encode_lum_dering(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, o.luminance);
    const bool clamped = zh3_dering(&z, ZonalAxisMode::kLuminance, o.luminance);
    if (stats) stats->dering_clamped = clamped;
    store_zh3(z, out);
}
void encode_lum_dering_sphere(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, o.luminance);
    const bool clamped = zh3_dering_sphere(&z, ZonalAxisMode::kLuminance, o.luminance);
    if (stats) stats->dering_clamped = clamped;
    store_zh3(z, out);
}
template <ZonalAxisMode Mode>
Sh3Radiance decode_zh3(const std::uint8_t* in, const CodecOptions& o) {
    return zh3_expand(load_zh3(in), Mode, o.luminance);
}
template <ZonalAxisMode Mode>
Rgb irradiance_zh3(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return zh3_irradiance(load_zh3(in), Mode, o.luminance, n);
}

// Hallucinated: the stored bytes are exactly sh2's (DC + L1, 12 floats).
void encode_linear(const Sh3Radiance& in, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    detail::store_linear(in, out);
}
template <Hallucination Model, ZonalAxisMode Mode>
Sh3Radiance decode_hall(const std::uint8_t* in, const CodecOptions& o) {
    return zh3_expand(zh3_hallucinate(load_linear(in), Model, Mode, o), Mode, o.luminance);
}
template <Hallucination Model, ZonalAxisMode Mode>
Rgb irradiance_hall(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return zh3_irradiance(zh3_hallucinate(load_linear(in), Model, Mode, o), Mode, o.luminance, n);
}

constexpr auto kLum = ZonalAxisMode::kLuminance;
constexpr auto kChan = ZonalAxisMode::kPerChannel;
constexpr auto kAmbDir = Hallucination::kAmbientDirectional;
constexpr auto kSphere = Hallucination::kSphere;
constexpr auto kCurve = Hallucination::kCurve;

constexpr CodecTraits kLumAxis{.zonal_axis = ZonalAxis::kLuminance};
constexpr CodecTraits kChanAxis{.zonal_axis = ZonalAxis::kPerChannel};
// The hall_* entries' traits: axis and the hallucination their decoder applies.
template <Hallucination H, ZonalAxisMode M>
constexpr CodecTraits kHall{.zonal_axis = M == kLum ? ZonalAxis::kLuminance : ZonalAxis::kPerChannel,
                            .hallucination = H == kAmbDir   ? ZonalHallucination::kAmbientDirectional
                                             : H == kSphere ? ZonalHallucination::kSphere
                                                            : ZonalHallucination::kCurve};

const Codec kZh3Codecs[] = {
    {"zh3_lum", "ZH3 fit (Eq. 9/10) on the luminance L1 axis, 15 floats", kZh3Floats * 4, encode_fit<kLum>,
     decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_channel", "ZH3 fit (Eq. 9/10) on each channel's L1 axis, 15 floats", kZh3Floats * 4, encode_fit<kChan>,
     decode_zh3<kChan>, irradiance_zh3<kChan>, kChanAxis},
    {"zh3_solved_lum", "ZH3, luminance axis solved by BFGS (Eq. 11), 15 floats", kZh3Floats * 4,
     encode_solved<kLum>, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_solved_channel", "ZH3, per-channel axes solved by BFGS (Eq. 11), 15 floats", kZh3Floats * 4,
     encode_solved<kChan>, decode_zh3<kChan>, irradiance_zh3<kChan>, kChanAxis},
    {"hall_ambdir", "linear SH + zonal L2 hallucinated, ambient+directional (Eq. 14), luminance axis",
     kLinearFloats * 4, encode_linear, decode_hall<kAmbDir, kLum>, irradiance_hall<kAmbDir, kLum>, kHall<kAmbDir, kLum>},
    {"hall_sphere", "linear SH + zonal L2 hallucinated, sphere light (Eq. 20), luminance axis", kLinearFloats * 4,
     encode_linear, decode_hall<kSphere, kLum>, irradiance_hall<kSphere, kLum>, kHall<kSphere, kLum>},
    {"hall_curve", "linear SH + zonal L2 hallucinated, curve fit (Eq. 21), luminance axis", kLinearFloats * 4,
     encode_linear, decode_hall<kCurve, kLum>, irradiance_hall<kCurve, kLum>, kHall<kCurve, kLum>},
    {"hall_ambdir_channel", "linear SH + zonal L2 hallucinated, ambient+directional (Eq. 14), channel axes",
     kLinearFloats * 4, encode_linear, decode_hall<kAmbDir, kChan>, irradiance_hall<kAmbDir, kChan>, kHall<kAmbDir, kChan>},
    {"hall_sphere_channel", "linear SH + zonal L2 hallucinated, sphere light (Eq. 20), channel axes",
     kLinearFloats * 4, encode_linear, decode_hall<kSphere, kChan>, irradiance_hall<kSphere, kChan>, kHall<kSphere, kChan>},
    {"hall_curve_channel", "linear SH + zonal L2 hallucinated, curve fit (Eq. 21), channel axes",
     kLinearFloats * 4, encode_linear, decode_hall<kCurve, kChan>, irradiance_hall<kCurve, kChan>, kHall<kCurve, kChan>},
    {"zh3_lum_dering", "zh3_lum with the zonal L2 clamped for non-negative irradiance (App. B)",
     kZh3Floats * 4, encode_lum_dering, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_lum_dering_sphere", "zh3_lum, zonal L2 nearest to the fit with irradiance >= 0 on the whole sphere",
     kZh3Floats * 4, encode_lum_dering_sphere, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
};

}  // namespace

std::span<const Codec> zh3_codecs() { return kZh3Codecs; }

}  // namespace zhc
