// zhc/codec/probe/zh3_hallucinate.cpp — ZH3 hallucination: the zonal L2 coefficient guessed from
// the linear SH alone (Sec. 3.4, Listing 1), with three models of the lighting: ambient plus one
// directional light (Eq. 14), a sphere light (Eq. 15-20) and the fitted curve (Eq. 21), and the
// codec-table entries that decode with them from sh2's 12 floats (hall_{ambdir,sphere,curve}[_channel],
// zh3_hallucinated_codecs()). The encoders that solve the stored L1 for these decoders are in
// zh3_hall_solve.cpp.
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md (Eq. 20).
#include "codec/probe/zh3.h"

#include <algorithm>
#include <cmath>

#include "codec/probe/zh3_internal.h"

namespace zhc {

using namespace detail;  // zh3_internal.h and sh_l1.h

double hallucinate_zonal(Hallucination model, double f0, double f1_zonal, double curve_a, double curve_b) {
    const double f1 = std::fabs(f1_zonal);
    if (model == Hallucination::kAmbientDirectional) {
        // Eq. 14: the directional light's zonal L2 over its zonal L1 is Y20(z=1) / Y10(z=1) = sqrt(5/3).
        return std::sqrt(15.0) / 3.0 * f1;
    }
    if (!(f0 > 0) || !std::isfinite(f0)) return 0.0;
    // p = |f1^0| / f0 in [0, sqrt(3)]: sqrt(3) is a delta light (cos sigma = 1), 0 the full sphere.
    const double p = std::clamp(f1 / f0, 0.0, kSqrt3);
    if (model == Hallucination::kSphere) {
        // Eq. 20 (from Eq. 15 with cos sigma = 2 p / sqrt(3) - 1, Eq. 19).
        return (2.0 * std::sqrt(5.0) / 3.0 * p * p - std::sqrt(5.0 / 3.0) * p) * f0;
    }
    return (curve_a * p * p + curve_b * p) * f0;  // Eq. 21
}

Zh3 zh3_hallucinate(const Sh2Radiance& linear, Hallucination model, ZonalAxisMode mode, const CodecOptions& o) {
    Zh3 z;
    z.linear = linear;
    const Axes axes(linear, mode, o.luminance);
    for (int k = 0; k < 3; ++k) {
        // Listing 1: f1^0 = L1 projected on the zonal axis (the channel's |L1| for per-channel axes).
        const double f1 = dot(l1_vector(linear.c.data(), k), axes.a[k]);
        z.zonal[k] = static_cast<float>(hallucinate_zonal(model, linear[0][k], f1, o.hallucinate_a, o.hallucinate_b));
    }
    return z;
}

namespace {

// Hallucinated: the stored bytes are exactly sh2's (DC + L1, 12 floats).
void encode_linear(const Sh3Radiance& in, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    store_linear(in, out);
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

// The hall_* entries' traits: axis and the hallucination their decoder applies.
template <Hallucination H, ZonalAxisMode M>
constexpr CodecTraits kHall{.zonal_axis = M == kLum ? ZonalAxis::kLuminance : ZonalAxis::kPerChannel,
                            .hallucination = H == kAmbDir   ? ZonalHallucination::kAmbientDirectional
                                             : H == kSphere ? ZonalHallucination::kSphere
                                                            : ZonalHallucination::kCurve};

const Codec kHallucinatedCodecs[] = {
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
};

}  // namespace

std::span<const Codec> zh3_hallucinated_codecs() { return kHallucinatedCodecs; }

}  // namespace zhc
