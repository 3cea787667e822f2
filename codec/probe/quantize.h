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
//   L2, m != 0             [-sqrt(15)/2, sqrt(15)/2]      (tight; the older bound is +-sqrt(5))
// So the DC is stored as an HDR float triple and every other coefficient as a small fixed-point
// number: its ratio to the DC of its channel, mapped from its interval to [-1, 1].
//
// Everything here is exact-arithmetic-free of platform dependence: double arithmetic with the
// default rounding mode, no -ffast-math, so the bytes are the same on every machine.
// Full byte layouts: docs/quantization.md.
#pragma once

#include <cstdint>
#include <string>

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"
#include "codec/status.h"
#include "codec/probe/zh3.h"

namespace zhc {

// ---- bound intervals -----------------------------------------------------------------------

// Whether the stored SH are radiance or irradiance (band scales 1, 2/3, 1/4 applied). The ratio
// intervals of irradiance are the radiance ones times the band scale (App. A.1).
enum class StoredKind : std::uint8_t { kRadiance = 0, kIrradiance = 1 };

// How the asymmetric zonal interval [lo, hi] = [-sqrt(5)/2, sqrt(5)] is mapped to [-1, 1].
enum class ZonalMapping : std::uint8_t {
    // t = (2 r - (hi + lo)) / (hi - lo): the whole code range covers exactly the interval, so the
    // step is 3/4 of the symmetric one; ratio 0 falls between codes.
    kAffine = 0,
    // t = r / hi for r >= 0, r / -lo for r < 0: ratio 0 stays at code 0 (what the square-root
    // encoding wants, its precision is concentrated there); negative side has half the step.
    kZeroPreserving = 1,
    // t = r / sqrt(5): the symmetric interval of Listing 1 (Wiederien & Sloan), for comparison.
    kSymmetric = 2,
};

struct RatioInterval {
    double lo = -1, hi = 1;
};

// Interval of c_i / c_0 for SH index i in 1..8 (index 0 has none: returns [0, 0]).
RatioInterval ratio_interval(int sh_index, StoredKind kind, L2Bound l2_bound);
// The zonal L2 interval (used by the stored ZH3 coefficient, which is an m = 0 coefficient in the
// frame of its axis, so it has the zonal bound).
RatioInterval zonal_l2_interval(StoredKind kind);

// ---- the parameters a quantised layout depends on ------------------------------------------

// Everything that changes the meaning of stored quantised bytes. The codec table entries use
// quant_params(CodecOptions) (radiance, luminance axis, default zonal mapping); the probe container
// stores all of these in its header, so non-default values round-trip through files.
struct QuantParams {
    int bits = 8;                    // 2..8 per ratio; codes use the low `bits` bits of a byte
    bool sqrt_encoding = false;      // sign-preserving square root before rounding
    L2Bound l2_bound = L2Bound::kTight;
    DcFormat dc_format = DcFormat::kR11G11B10F;
    StoredKind kind = StoredKind::kRadiance;
    ZonalMapping zonal_mapping = ZonalMapping::kAffine;
    ZonalAxisMode axis_mode = ZonalAxisMode::kLuminance;  // zh3_q16 only
    LuminanceWeights luminance;                           // zh3_q16 luminance axis only
};
inline constexpr int kMinQuantBits = 2;
inline constexpr int kMaxQuantBits = 8;

QuantParams quant_params(const CodecOptions& options);
// Checks the ranges and the combination with a layout (e.g. a half DC needs 6 bytes, which only
// sh2_q has). `layout_name` may be any codec name; non-quantised names only get the range checks.
Status validate_quant_params(const QuantParams& params, std::string_view layout_name);

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
RatioCoder ratio_coder(int sh_index, const QuantParams& params);  // sh_index 1..8
RatioCoder zonal_coder(const QuantParams& params);                 // the ZH3 coefficient

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
// options.hallucinate_a/b on params.axis_mode's axis, added to decoded linear SH.
Sh3Radiance hallucinate_curve(const Sh3Radiance& linear_hub, const QuantParams& params, const CodecOptions& options);

// Quantisation controls that are not part of the stored format (they never change how bytes
// decode, only which bytes the encoder picks). Defaults are what the codec table uses.
struct QuantEncodeControls {
    // zh3_q16: fit the zonal coefficient along the axis the DECODER will derive (from the
    // dequantised L1). false = fit along the float L1's axis first and quantise afterwards.
    bool refit_zonal_after_l1 = true;
    // zh3_q16: take the L1 to quantise from the BFGS axis solve (zh3_solve, ZH3 paper Sec. 3.3,
    // Eq. 11) instead of the projection; the zonal is still refitted on the decoder's axis. The
    // bytes decode with the ordinary zh3_q16 decoder (entry "zh3_solved_q16"). Slower encode.
    bool solve_axis = false;
    CodecOptions solver;  // iterations, tolerance (luminance weights come from QuantParams)
    // zh3_q16: whole-sphere deringing (entry "zh3_dering_q16", codec/probe/zh3_window.h): the probe is
    // windowed, quantised, decoded, and windowed further while the DECODED irradiance has a
    // negative certified minimum anywhere on the sphere.
    bool dering = false;
    // Analysis only (the output is then not a valid layout): keep the DC exact instead of
    // quantising it, to split the error budget between DC and ratios. Used via quantize_roundtrip.
    bool exact_dc = false;
};

// Encodes the hub (radiance SH3) into `layout`; writes exactly packed_size_bytes(layout) bytes.
// Non-finite coefficients are stored as ratio 0 / DC 0 and counted in stats->clamped_ratios.
void encode_packed(PackedLayout layout, const Sh3Radiance& hub, const QuantParams& params, std::uint8_t* out,
                   EncodeStats* stats, const QuantEncodeControls& controls = {});
// Decodes any packed_size_bytes(layout) bytes to the hub (radiance SH3). Total: never traps.
Sh3Radiance decode_packed(PackedLayout layout, const std::uint8_t* in, const QuantParams& params);

// zh3_q16 bytes as the ZH3 they stand for (radiance linear SH and zonal coefficients, before the
// zonal is expanded along the axis): what the decoder's irradiance is made of.
Zh3 decode_zh3_q16(const std::uint8_t* in, const QuantParams& params);

// encode_packed followed by decode_packed, except that controls.exact_dc keeps the float DC
// (what the decoder would see if the DC were stored exactly). For error-budget studies.
Sh3Radiance quantize_roundtrip(PackedLayout layout, const Sh3Radiance& hub, const QuantParams& params,
                               EncodeStats* stats, const QuantEncodeControls& controls = {});

// ---- table entries that store a packed layout (Codec::packed) --------------------------------

// What the probe container needs from a quantised table entry: its layout, and its encoder and
// decoder with every storage parameter (the Codec functions only see CodecOptions, i.e. radiance,
// the affine zonal mapping and the luminance axis). Everything entry-specific (which solve, which
// axis, a hallucination at decode) lives in these two functions, never in a test of the name.
struct PackedCodec {
    PackedLayout layout;
    void (*encode)(const Sh3Radiance& hub, const QuantParams& params, const CodecOptions& options, std::uint8_t* out,
                   EncodeStats* stats);
    Sh3Radiance (*decode)(const std::uint8_t* in, const QuantParams& params, const CodecOptions& options);
};

// The Codec functions of a packed entry P: its own functions with quant_params(options).
template <const PackedCodec& P>
void packed_entry_encode(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    P.encode(in, quant_params(o), o, out, stats);
}
template <const PackedCodec& P>
Sh3Radiance packed_entry_decode(const std::uint8_t* in, const CodecOptions& o) {
    return P.decode(in, quant_params(o), o);
}
template <const PackedCodec& P>
Rgb packed_entry_irradiance(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return irradiance(P.decode(in, quant_params(o), o), n);
}
// A whole Codec entry for P; `zonal_axis` is its trait (codec.h CodecTraits).
template <const PackedCodec& P>
constexpr Codec packed_codec(std::string_view name, std::string_view summary, ZonalAxis zonal_axis) {
    return {name,          summary, packed_size_bytes(P.layout), packed_entry_encode<P>, packed_entry_decode<P>,
            packed_entry_irradiance<P>, CodecTraits{.zonal_axis = zonal_axis}, &P};
}

// The codec table part of codec/probe/quantize.cpp: zh3_q16, zh3_solved_q16, sh3_q28, sh2_q, hall_curve_q.
std::span<const Codec> quantized_codecs();

}  // namespace zhc
