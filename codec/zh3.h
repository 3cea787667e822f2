// zhc/codec/zh3.h — ZH3: linear SH plus one quadratic zonal coefficient per channel
// (Roughton et al. 2024, "ZH3: Quadratic Zonal Harmonics").
//
// Stored form: the RGB linear SH (DC + L1, radiance) and, per channel, the radiance zonal
// coefficient f_2^0 in the frame of the zonal axis. The axis is never stored: it is derived from
// the stored L1 (the luminance L1's optimal linear direction, shared by all channels, or each
// channel's own), so the decoder needs nothing else.
#pragma once

#include "codec.h"
#include "sh.h"

namespace zhc {

enum class ZonalAxisMode : std::uint8_t {
    kLuminance = 0,   // one axis from the luminance-weighted L1 (Sec. 3.2), default
    kPerChannel = 1,  // each channel's own optimal linear direction (Sec. 3.1)
};

struct Zh3 {
    Sh2Radiance linear;  // DC and L1, radiance
    Rgb zonal;           // f_2^0 (radiance) along each channel's zonal axis
};

// Zonal axis of channel k (0..2) under `mode`, derived from the linear SH only.
// A zero L1 (no defined direction) gives +Z; callers that care check has_zonal_axis().
Vec3 zh3_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w);
bool has_zonal_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w);

// Least-squares zonal fit along the axis of the unchanged L1 (Eq. 9/10).
Zh3 zh3_fit(const Sh3Radiance& sh, ZonalAxisMode mode, const LuminanceWeights& w);
// Expansion to the hub: the L2 band is f_2^0 * sqrt(4 pi / 5) * Y_2(axis) per channel.
Sh3Radiance zh3_expand(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w);
// Irradiance at n straight from ZH3 (runtime path, Listing 1 style).
Rgb zh3_irradiance(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w, Vec3 n);

}  // namespace zhc
