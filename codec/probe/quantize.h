// zhc/codec/probe/quantize.h — ratio-bound quantisation of SH probes and the packed runtime layouts.
//
// Sources: Roughton et al. 2024 "ZH3: Quadratic Zonal Harmonics", App. A and A.1 (ratio bounds,
// DC in R11G11B10F, 16-byte ZH3); Wiederien & Sloan, ATVI-TR-24-02 (the tight sqrt(15)/2 bound for
// the non-zonal quadratic coefficients, sign-preserving square-root encoding, Listing 1).
//
// The idea (App. A): if f >= 0, the SH projection of f is a positive-weighted sum of projections
// of deltas, so every ratio c_i / c_0 lies between the smallest and largest value of
// Y_i(w) / Y_0 over directions w. Those intervals (radiance; irradiance scales L1 by 2/3, L2 by 1/4):
//   L1, every m            [-sqrt(3), sqrt(3)]
//   L2, m = 0 (zonal)      [-sqrt(5)/2, sqrt(5)]          (3z^2 - 1 ranges over [-1, 2])
//   L2, m != 0             [-sqrt(15)/2, sqrt(15)/2]      (tight; the band-length bound is +-sqrt(5))
// So the DC is stored as an HDR float triple and every other coefficient as a small fixed-point
// number: its ratio to the DC of its channel, mapped from its interval to [-1, 1].
//
// Everything here is exact-arithmetic-free of platform dependence: double arithmetic with the
// default rounding mode, no -ffast-math, so the bytes are the same on every machine.
// Full byte layouts: docs/quantization.md.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <cstdint>
#include <string>

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"
#include "codec/status.h"
#include "codec/probe/zh3.h"

namespace zhc {

// ---- bound intervals -----------------------------------------------------------------------

// StoredKind and ZonalMapping: codec/probe/codec.h (fields of CodecOptions).

struct RatioInterval {
    double lo = -1, hi = 1;
};

// Interval of c_i / c_0 for SH index i in 1..8 (index 0 has none: returns [0, 0]).
RatioInterval ratio_interval(int sh_index, StoredKind kind, L2Bound l2_bound);
// The zonal L2 interval (used by the stored ZH3 coefficient, which is an m = 0 coefficient in the
// frame of its axis, so it has the zonal bound).
RatioInterval zonal_l2_interval(StoredKind kind);

// ---- the parameters a quantised layout depends on ------------------------------------------

// The quantiser's parameters are CodecOptions (codec.h), the table's one parameter type; the
// storage fields there (bits .. axis_mode) change the meaning of stored quantised bytes, and the
// probe container stores all of them in its header, so non-default values round-trip through files.
inline constexpr int kMinQuantBits = 2;
inline constexpr int kMaxQuantBits = 8;

// Checks the ranges and the combination with a layout (e.g. a half DC needs 6 bytes, which only
// sh2_q has). `layout_name` may be any codec name; non-quantised names only get the range checks.
Status validate_quant_params(const CodecOptions& params, std::string_view layout_name);

// ---- scalar quantiser ----------------------------------------------------------------------

// Largest code magnitude: bv = 2^(bits-1) - 1 (Listing 1); codes are 0 .. 2 bv, code bv is t = 0.
inline int quant_half_range(int bits) { return (1 << (bits - 1)) - 1; }

// Maps a ratio to t in [-1, 1] (clamping; *clamped set when r was outside the interval or not
// finite) and back. `zonal` selects the zonal mapping for the zonal interval.
double ratio_to_unit(double ratio, RatioInterval interval, ZonalMapping mapping, bool zonal, bool* clamped);
double unit_to_ratio(double t, RatioInterval interval, ZonalMapping mapping, bool zonal);

// Quantises a ratio: the code in [0, 2 bv] whose decoded ratio is nearest to the clamped ratio
// (ties to the lower code). With sqrt encoding the grid is uniform in sign(t) sqrt|t|.
struct RatioCoder {
    RatioInterval interval;
    ZonalMapping mapping = ZonalMapping::kAffine;
    bool zonal = false;
    int bits = 8;
    bool sqrt_encoding = false;
    std::uint8_t encode(double ratio, bool* clamped) const;
    // Total: codes above 2 bv decode as 2 bv.
    double decode(std::uint8_t code) const;
};
RatioCoder ratio_coder(int sh_index, const CodecOptions& params);  // sh_index 1..8
RatioCoder zonal_coder(const CodecOptions& params);                 // the ZH3 coefficient

// ---- DC formats ----------------------------------------------------------------------------

// DXGI_FORMAT_R11G11B10_FLOAT: R bits 0-10, G 11-21, B 22-31; unsigned floats with a 5-bit
// exponent (bias 15) and 6/6/5-bit mantissas. Round to nearest, ties to even; negative and NaN
// store 0, values above the largest finite (65024 / 64512) store the largest finite.
std::uint32_t pack_r11g11b10f(double r, double g, double b);
// Exponent 31 decodes as +Inf (mantissa 0) or NaN, as the hardware format does.
Rgb unpack_r11g11b10f(std::uint32_t bits);
// DXGI_FORMAT_R9G9B9E5_SHAREDEXP: R bits 0-8, G 9-17, B 18-26, exponent 27-31 (bias 15), value
// m * 2^(e - 24); encoding as in EXT_texture_shared_exponent (rounding half up).
std::uint32_t pack_rgb9e5(double r, double g, double b);
Rgb unpack_rgb9e5(std::uint32_t bits);
// IEEE 754 binary16, round to nearest even, overflow stores +-65504, NaN stores 0.
std::uint16_t pack_half(double v);
float unpack_half(std::uint16_t bits);

// Stores the DC triple at `out` (little-endian) and returns what the decoder will read back.
Rgb store_dc(const Rgb& dc, DcFormat f, std::uint8_t* out);
Rgb load_dc(const std::uint8_t* in, DcFormat f);

// ---- the packed layouts --------------------------------------------------------------------

enum class PackedLayout : std::uint8_t {
    kZh3Q16 = 0,  // 16 bytes: DC (4) + per channel [L1-1, L10, L11, zonal]
    kSh3Q28 = 1,  // 28 bytes: DC (4) + per channel [L1-1 .. L22] (Listing 1's two words)
    kSh2Q = 2,    // 16 bytes: DC slot (6) + per channel [L1-1, L10, L11] + 1 zero byte
};
constexpr std::size_t packed_size_bytes(PackedLayout layout) {
    return layout == PackedLayout::kSh3Q28 ? 28 : 16;  // kZh3Q16, kSh2Q: 16
}
// The packed layout of a table entry (its Codec::packed); false for names that are not quantised
// entries.
bool packed_layout_from_name(std::string_view name, PackedLayout* out);
// The Eq. 21 hallucination of the entry "hall_curve_q": f20 = (a p^2 + b p) f0 with
// params.hallucinate_a/b on params.axis_mode's axis, added to decoded linear SH.
Sh3Radiance hallucinate_curve(const Sh3Radiance& linear_hub, const CodecOptions& params);

// Quantisation controls that are not part of the stored format (they never change how bytes
// decode, only which bytes the encoder picks). Defaults are what the codec table uses.
struct QuantEncodeControls {
    // zh3_q16: fit the zonal coefficient along the axis the DECODER will derive (from the
    // dequantised L1). false = fit along the float L1's axis first and quantise afterwards.
    bool refit_zonal_after_l1 = true;
    // zh3_q16: take the L1 to quantise from the BFGS axis solve (zh3_solve, ZH3 paper Sec. 3.3,
    // Eq. 11) instead of the projection; the zonal is still refitted on the decoder's axis. The
    // bytes decode with the ordinary zh3_q16 decoder (entry "zh3_solved_q16"). Slower encode; the
    // solve's iterations and tolerance are the params' encoder controls.
    bool solve_axis = false;
    // zh3_q16: whole-sphere deringing (entry "zh3_dering_q16", codec/probe/zh3_dering.h): the probe is
    // windowed, quantised, decoded, and windowed further while the DECODED irradiance has a
    // negative certified minimum anywhere on the sphere.
    bool dering = false;
    // Analysis only (the output is then not a valid layout): keep the DC exact instead of
    // quantising it, to split the error budget between DC and ratios. Used via quantize_roundtrip.
    bool exact_dc = false;
};

// Encodes the hub (radiance SH3) into `layout`; writes exactly packed_size_bytes(layout) bytes.
// Non-finite coefficients are stored as ratio 0 / DC 0 and counted in stats->clamped_ratios.
void encode_packed(PackedLayout layout, const Sh3Radiance& hub, const CodecOptions& params, std::uint8_t* out,
                   EncodeStats* stats, const QuantEncodeControls& controls = {});
// Decodes any packed_size_bytes(layout) bytes to the hub (radiance SH3). Total: never traps.
Sh3Radiance decode_packed(PackedLayout layout, const std::uint8_t* in, const CodecOptions& params);

// zh3_q16 bytes as the ZH3 they stand for (radiance linear SH and zonal coefficients, before the
// zonal is expanded along the axis): what the decoder's irradiance is made of.
Zh3 decode_zh3_q16(const std::uint8_t* in, const CodecOptions& params);

// encode_packed followed by decode_packed, except that controls.exact_dc keeps the float DC
// (what the decoder would see if the DC were stored exactly). For error-budget studies.
Sh3Radiance quantize_roundtrip(PackedLayout layout, const Sh3Radiance& hub, const CodecOptions& params,
                               EncodeStats* stats, const QuantEncodeControls& controls = {});

// ---- table entries that store a packed layout (Codec::packed) --------------------------------

// What the table, the container and the runtimes need from a quantised entry: its layout, and its
// encoder and decoder, which take every parameter (storage and encoder controls) in the one
// CodecOptions. Everything entry-specific (which solve, which axis, a hallucination at decode)
// lives in these two functions, never in a test of the name.
struct PackedCodec {
    PackedLayout layout;
    void (*encode)(const Sh3Radiance& hub, const CodecOptions& params, std::uint8_t* out, EncodeStats* stats);
    Sh3Radiance (*decode)(const std::uint8_t* in, const CodecOptions& params);
};

// The irradiance of a packed entry P: that of its decoded hub.
template <const PackedCodec& P>
Rgb packed_entry_irradiance(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return irradiance(P.decode(in, o), n);
}
// A whole Codec entry for P: P's encode and decode, the irradiance above; `zonal_axis` and
// `hallucination` are its traits (codec.h CodecTraits).
template <const PackedCodec& P>
constexpr Codec packed_codec(std::string_view name, std::string_view summary, ZonalAxis zonal_axis,
                             ZonalHallucination hallucination = ZonalHallucination::kNone) {
    return {name,     summary, packed_size_bytes(P.layout), P.encode, P.decode, packed_entry_irradiance<P>,
            CodecTraits{.zonal_axis = zonal_axis, .hallucination = hallucination}, &P};
}

// The codec table part of codec/probe/quantize.cpp: zh3_q16, zh3_solved_q16, sh3_q28, sh2_q, hall_curve_q.
std::span<const Codec> quantized_codecs();

}  // namespace zhc
