// Ratio-bound quantisation and the packed runtime layouts (zh3_q16, sh3_q28, sh2_q).
//
// Sources: ZH3 paper (Roughton et al. 2024) App. A (bounds of c_i / c_0 for projections of
// non-negative functions) and App. A.1 (DC as 11f/11f/10f, ratios remapped to [-1, 1], irradiance
// scales in the bounds, square-root encoding); Wiederien & Sloan ATVI-TR-24-02 Sec. 3 (tight
// non-zonal bound sqrt(15)/2) and Listing 1 (bv = 2^(bits-1) - 1, codes bv + t bv).
// Byte layouts: docs/quantization.md.
#include "codec/probe/quantize.h"

#include "codec/probe/zh3_dering.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace zhc {

// ---- bound intervals -----------------------------------------------------------------------

namespace {
// App. A: Y_1m / Y_0 = sqrt(3) * (a unit-vector component): [-sqrt(3), sqrt(3)].
const double kL1Bound = std::sqrt(3.0);
// App. A: Y_20 / Y_0 = sqrt(5) (3 z^2 - 1) / 2, and 3 z^2 - 1 in [-1, 2].
const double kL2ZonalLo = -std::sqrt(5.0) / 2.0;
const double kL2ZonalHi = std::sqrt(5.0);
// Wiederien & Sloan Sec. 3.2: max of sqrt(15) x y (etc.) on the sphere is at x = y = 1/sqrt(2).
const double kL2TightBound = std::sqrt(15.0) / 2.0;
// The looser band-length bound sqrt(2l + 1) applied to each coefficient.
const double kL2LooseBound = std::sqrt(5.0);

double band_scale(StoredKind kind, int l) {
    return kind == StoredKind::kIrradiance ? kIrradianceBandScale[l] : 1.0;
}
// SH index of Y_20, the zonal quadratic coefficient.
constexpr int kZonalL2Index = sh_index(2, 0);
int band_of(int sh_index) { return sh_index == 0 ? 0 : (sh_index < 4 ? 1 : 2); }
}  // namespace

RatioInterval zonal_l2_interval(StoredKind kind) {
    const double s = band_scale(kind, 2);
    return {kL2ZonalLo * s, kL2ZonalHi * s};
}

RatioInterval ratio_interval(int sh_index, StoredKind kind, L2Bound l2_bound) {
    const int l = band_of(sh_index);
    const double s = band_scale(kind, l);
    if (sh_index <= 0 || sh_index > 8) return {0, 0};
    if (l == 1) return {-kL1Bound * s, kL1Bound * s};
    if (sh_index == kZonalL2Index) return zonal_l2_interval(kind);
    const double b = (l2_bound == L2Bound::kTight ? kL2TightBound : kL2LooseBound) * s;
    return {-b, b};
}

// ---- parameters ----------------------------------------------------------------------------

Status validate_quant_params(const CodecOptions& p, std::string_view layout_name) {
    if (p.bits < kMinQuantBits || p.bits > kMaxQuantBits)
        return make_error(ErrorCode::kInvalidArgument, "quantisation bits must be " + std::to_string(kMinQuantBits) +
                                                           ".." + std::to_string(kMaxQuantBits) + ", got " +
                                                           std::to_string(p.bits));
    if (static_cast<int>(p.dc_format) > 2) return make_error(ErrorCode::kInvalidArgument, "unknown DC format");
    if (static_cast<int>(p.l2_bound) > 1) return make_error(ErrorCode::kInvalidArgument, "unknown L2 bound");
    if (static_cast<int>(p.kind) > 1) return make_error(ErrorCode::kInvalidArgument, "unknown stored kind");
    if (static_cast<int>(p.zonal_mapping) > 2) return make_error(ErrorCode::kInvalidArgument, "unknown zonal mapping");
    if (static_cast<int>(p.axis_mode) > 1) return make_error(ErrorCode::kInvalidArgument, "unknown axis mode");
    const LuminanceWeights& w = p.luminance;
    if (!std::isfinite(w.r) || !std::isfinite(w.g) || !std::isfinite(w.b))
        return make_error(ErrorCode::kInvalidArgument, "luminance weights must be finite");
    PackedLayout layout;
    if (packed_layout_from_name(layout_name, &layout) && p.dc_format == DcFormat::kHalf &&
        layout != PackedLayout::kSh2Q)
        return make_error(ErrorCode::kInvalidArgument,
                          std::string(layout_name) +
                              ": a half-float DC needs 6 bytes; only sh2_q has a 6-byte DC slot "
                              "(use r11g11b10f or rgb9e5)");
    return Ok{};
}

// ---- scalar quantiser ----------------------------------------------------------------------

double ratio_to_unit(double r, RatioInterval iv, ZonalMapping mapping, bool zonal, bool* clamped) {
    bool out_of_range = false;
    if (std::isnan(r)) {
        r = 0.0;
        out_of_range = true;
    }
    if (r < iv.lo) {
        r = iv.lo;
        out_of_range = true;
    } else if (r > iv.hi) {
        r = iv.hi;
        out_of_range = true;
    }
    if (clamped) *clamped = out_of_range;
    double t;
    if (!zonal || mapping == ZonalMapping::kAffine) {
        t = (2.0 * r - (iv.hi + iv.lo)) / (iv.hi - iv.lo);
    } else if (mapping == ZonalMapping::kZeroPreserving) {
        t = r >= 0 ? r / iv.hi : r / -iv.lo;
    } else {  // kSymmetric: Listing 1 divides by the larger magnitude of the interval
        t = r / std::max(iv.hi, -iv.lo);
    }
    return std::clamp(t, -1.0, 1.0);
}

double unit_to_ratio(double t, RatioInterval iv, ZonalMapping mapping, bool zonal) {
    if (!zonal || mapping == ZonalMapping::kAffine) return 0.5 * (t * (iv.hi - iv.lo) + (iv.hi + iv.lo));
    if (mapping == ZonalMapping::kZeroPreserving) return t >= 0 ? t * iv.hi : t * -iv.lo;
    return t * std::max(iv.hi, -iv.lo);
}

double RatioCoder::decode(std::uint8_t code) const {
    const int bv = quant_half_range(bits);
    const int c = std::min<int>(code, 2 * bv);
    double t = static_cast<double>(c - bv) / bv;
    if (sqrt_encoding) t = t * std::fabs(t);  // sign-preserving square (Listing 1, Unpack4)
    return unit_to_ratio(t, interval, mapping, zonal);
}

std::uint8_t RatioCoder::encode(double ratio, bool* clamped) const {
    const int bv = quant_half_range(bits);
    const double t = ratio_to_unit(ratio, interval, mapping, zonal, clamped);
    const double target = unit_to_ratio(t, interval, mapping, zonal);  // the clamped ratio
    const double u = sqrt_encoding ? std::copysign(std::sqrt(std::fabs(t)), t) : t;
    // The two codes around u; keep the one whose decoded ratio is nearest (ties: lower code).
    int c0 = static_cast<int>(std::floor(u * bv + bv));
    c0 = std::clamp(c0, 0, 2 * bv - 1);
    const double e0 = std::fabs(decode(static_cast<std::uint8_t>(c0)) - target);
    const double e1 = std::fabs(decode(static_cast<std::uint8_t>(c0 + 1)) - target);
    return static_cast<std::uint8_t>(e1 < e0 ? c0 + 1 : c0);
}

RatioCoder ratio_coder(int sh_index, const CodecOptions& p) {
    RatioCoder c;
    c.interval = ratio_interval(sh_index, p.kind, p.l2_bound);
    c.mapping = p.zonal_mapping;
    c.zonal = sh_index == kZonalL2Index;
    c.bits = p.bits;
    c.sqrt_encoding = p.sqrt_encoding;
    return c;
}

RatioCoder zonal_coder(const CodecOptions& p) {
    RatioCoder c;
    c.interval = zonal_l2_interval(p.kind);
    c.mapping = p.zonal_mapping;
    c.zonal = true;
    c.bits = p.bits;
    c.sqrt_encoding = p.sqrt_encoding;
    return c;
}

// ---- DC formats ----------------------------------------------------------------------------

namespace {
// Unsigned float with a 5-bit exponent (bias 15) and `mbits` mantissa bits, no sign: the
// channel format of R11G11B10F (mbits 6, 5) and, plus a sign, of binary16 (mbits 10).
std::uint32_t pack_ufloat(double v, int mbits) {
    const std::uint32_t max_code = (30u << mbits) | ((1u << mbits) - 1u);  // largest finite
    if (!(v > 0.0)) return 0;                                              // <= 0 or NaN
    if (std::isinf(v)) return max_code;
    int e;
    std::frexp(v, &e);  // v in [2^(e-1), 2^e)
    const int exp = e - 1;
    if (exp > 15) return max_code;
    std::uint32_t code;
    if (exp < -14) {
        // Denormal: v = m 2^(-14 - mbits); a carry to m = 2^mbits is the smallest normal.
        code = static_cast<std::uint32_t>(std::nearbyint(std::ldexp(v, 14 + mbits)));
    } else {
        // Exact in double: the scaling is by a power of two and the subtraction is of numbers in [1, 2).
        const double m = std::nearbyint((std::ldexp(v, -exp) - 1.0) * std::ldexp(1.0, mbits));
        code = (static_cast<std::uint32_t>(exp + 15) << mbits) + static_cast<std::uint32_t>(m);
    }
    return std::min(code, max_code);
}

float unpack_ufloat(std::uint32_t code, int mbits) {
    const std::uint32_t e = code >> mbits, m = code & ((1u << mbits) - 1u);
    if (e == 0) return static_cast<float>(std::ldexp(static_cast<double>(m), -14 - mbits));
    if (e == 31) return m == 0 ? INFINITY : NAN;
    return static_cast<float>(std::ldexp(1.0 + std::ldexp(static_cast<double>(m), -mbits), static_cast<int>(e) - 15));
}

void put_u32(std::uint8_t* out, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out[b] = static_cast<std::uint8_t>(v >> (8 * b));
}
std::uint32_t get_u32(const std::uint8_t* in) {
    std::uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= std::uint32_t(in[b]) << (8 * b);
    return v;
}
}  // namespace

std::uint32_t pack_r11g11b10f(double r, double g, double b) {
    return pack_ufloat(r, 6) | (pack_ufloat(g, 6) << 11) | (pack_ufloat(b, 5) << 22);
}

Rgb unpack_r11g11b10f(std::uint32_t bits) {
    return {unpack_ufloat(bits & 0x7FFu, 6), unpack_ufloat((bits >> 11) & 0x7FFu, 6), unpack_ufloat(bits >> 22, 5)};
}

std::uint32_t pack_rgb9e5(double r, double g, double b) {
    // EXT_texture_shared_exponent, "Encoding": N = 9 mantissa bits, B = 15 exponent bias.
    constexpr int kN = 9, kB = 15;
    const double max_value = (511.0 / 512.0) * 65536.0;  // (2^N - 1) / 2^N * 2^(Emax - B)
    auto clampc = [&](double v) { return v > 0.0 ? std::min(v, max_value) : 0.0; };  // NaN -> 0
    const double rc = clampc(r), gc = clampc(g), bc = clampc(b);
    const double maxc = std::max({rc, gc, bc});
    int floor_log2 = -kB - 1;
    if (maxc > 0.0) {
        int e;
        std::frexp(maxc, &e);
        floor_log2 = std::max(floor_log2, e - 1);
    }
    int exp_shared = floor_log2 + 1 + kB;
    const double max_s = std::floor(std::ldexp(maxc, -(exp_shared - kB - kN)) + 0.5);
    if (max_s >= 512.0) ++exp_shared;
    auto mant = [&](double v) {
        return static_cast<std::uint32_t>(std::min(511.0, std::floor(std::ldexp(v, -(exp_shared - kB - kN)) + 0.5)));
    };
    return mant(rc) | (mant(gc) << 9) | (mant(bc) << 18) | (static_cast<std::uint32_t>(exp_shared) << 27);
}

Rgb unpack_rgb9e5(std::uint32_t bits) {
    const int e = static_cast<int>(bits >> 27) - 15 - 9;
    return {static_cast<float>(std::ldexp(static_cast<double>(bits & 0x1FFu), e)),
            static_cast<float>(std::ldexp(static_cast<double>((bits >> 9) & 0x1FFu), e)),
            static_cast<float>(std::ldexp(static_cast<double>((bits >> 18) & 0x1FFu), e))};
}

std::uint16_t pack_half(double v) {
    if (std::isnan(v)) return 0;
    const std::uint32_t mag = pack_ufloat(std::fabs(v), 10);  // max finite 0x7BFF = 65504
    return static_cast<std::uint16_t>(mag | ((v < 0 && mag != 0) ? 0x8000u : 0u));
}

float unpack_half(std::uint16_t bits) {
    const float mag = unpack_ufloat(bits & 0x7FFFu, 10);
    return (bits & 0x8000u) ? -mag : mag;
}


Rgb store_dc(const Rgb& dc, DcFormat f, std::uint8_t* out) {
    switch (f) {
        case DcFormat::kRGB9E5: {
            const std::uint32_t v = pack_rgb9e5(dc.r, dc.g, dc.b);
            put_u32(out, v);
            return unpack_rgb9e5(v);
        }
        case DcFormat::kHalf: {
            Rgb back;
            for (int k = 0; k < 3; ++k) {
                const std::uint16_t h = pack_half(dc[k]);
                out[2 * k] = static_cast<std::uint8_t>(h);
                out[2 * k + 1] = static_cast<std::uint8_t>(h >> 8);
                back[k] = unpack_half(h);
            }
            return back;
        }
        case DcFormat::kR11G11B10F:
        default: {
            const std::uint32_t v = pack_r11g11b10f(dc.r, dc.g, dc.b);
            put_u32(out, v);
            return unpack_r11g11b10f(v);
        }
    }
}

Rgb load_dc(const std::uint8_t* in, DcFormat f) {
    switch (f) {
        case DcFormat::kRGB9E5: return unpack_rgb9e5(get_u32(in));
        case DcFormat::kHalf: {
            Rgb out;
            for (int k = 0; k < 3; ++k) out[k] = unpack_half(static_cast<std::uint16_t>(in[2 * k] | (in[2 * k + 1] << 8)));
            return out;
        }
        case DcFormat::kR11G11B10F:
        default: return unpack_r11g11b10f(get_u32(in));
    }
}

// ---- packed layouts ------------------------------------------------------------------------

bool packed_layout_from_name(std::string_view name, PackedLayout* out) {
    const Codec* c = find_codec(name);
    if (!c || !c->packed) return false;
    *out = c->packed->layout;
    return true;
}

namespace {

// Where each field lives (docs/quantization.md):
//  zh3_q16: [0,4) DC; byte 4 + 4k + j: channel k, j = 0..2 -> L1 index j + 1, j = 3 -> zonal.
//  sh3_q28: [0,4) DC; byte 4 + 8k + (i - 1): channel k, SH index i = 1..8.
//  sh2_q:   [0,6) DC slot; byte 6 + 3k + (i - 1): channel k, i = 1..3; byte 15 = 0.
int dc_slot_bytes(PackedLayout layout) { return layout == PackedLayout::kSh2Q ? 6 : 4; }
// The 4-byte DC slots cannot hold a half triple; there kHalf means R11G11B10F for encoder and
// decoder alike (validate_quant_params rejects the combination, so files never carry it).
DcFormat effective_dc_format(PackedLayout layout, DcFormat f) {
    return (f == DcFormat::kHalf && dc_slot_bytes(layout) < 6) ? DcFormat::kR11G11B10F : f;
}
int ratio_offset(PackedLayout layout, int channel, int sh_index) {
    switch (layout) {
        case PackedLayout::kZh3Q16: return 4 + 4 * channel + (sh_index - 1);
        case PackedLayout::kSh3Q28: return 4 + 8 * channel + (sh_index - 1);
        case PackedLayout::kSh2Q: return 6 + 3 * channel + (sh_index - 1);
    }
    return 0;
}
int zonal_offset(int channel) { return 4 + 4 * channel + 3; }
int last_ratio_index(PackedLayout layout) { return layout == PackedLayout::kSh3Q28 ? 8 : 3; }

// The stored SH: the hub itself, or its irradiance (band scales 1, 2/3, 1/4), in double.
using Coeffs = std::array<std::array<double, 3>, 9>;
Coeffs stored_coefficients(const Sh3Radiance& hub, StoredKind kind) {
    Coeffs c{};
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) c[static_cast<size_t>(i)][static_cast<size_t>(k)] = hub[i][k] * band_scale(kind, band_of(i));
    return c;
}
Sh3Radiance hub_from_stored(const Coeffs& c, StoredKind kind) {
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            out[i][k] = static_cast<float>(c[static_cast<size_t>(i)][static_cast<size_t>(k)] / band_scale(kind, band_of(i)));
    return out;
}

// Ratio of a coefficient to the (decoded) DC of its channel. DC <= 0 (R11G11B10F cannot hold a
// negative) or not finite leaves no usable scale: the ratio is 0 unless the coefficient is
// non-zero, when the ratio is "out of range" (NaN) and gets clamped and counted.
double ratio_of(double c, double dc) {
    if (!std::isfinite(c)) return std::isnan(c) ? NAN : c;  // +-Inf clamps to the interval end
    if (!(dc > 0.0) || !std::isfinite(dc)) return c == 0.0 ? 0.0 : NAN;
    return c / dc;
}

// The unit vector v with the L2 band of a zonal function along `axis` equal to f20 * v:
// v_m = sqrt(4 pi / 5) Y_2m(axis) (ZH3 paper Eq. 2 / 6); |v| = 1, so the least-squares zonal
// coefficient of an L2 band b is b . v (Eq. 9).
std::array<double, 5> zonal_l2_direction(Vec3 axis) {
    const auto y = sh3_basis(axis);
    const double s = std::sqrt(4.0 * kPi / 5.0);
    return {s * y[4], s * y[5], s * y[6], s * y[7], s * y[8]};
}

// Zonal axes from (dequantised) L1, per channel: shares zh3.h's definition (luminance-weighted L1
// or each channel's own optimal linear direction; +Z when the L1 is zero).
std::array<Vec3, 3> axes_from_l1(const Coeffs& c, const CodecOptions& p) {
    Sh2Radiance linear;
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) linear[i][k] = static_cast<float>(c[static_cast<size_t>(i)][static_cast<size_t>(k)]);
    std::array<Vec3, 3> axes;
    for (int k = 0; k < 3; ++k) axes[static_cast<size_t>(k)] = zh3_axis(linear, p.axis_mode, k, p.luminance);
    return axes;
}

// The unit L2 directions of the three channels' axes (computed once when they share one axis).
using ZonalDirections = std::array<std::array<double, 5>, 3>;
ZonalDirections zonal_directions(const std::array<Vec3, 3>& axes, ZonalAxisMode mode) {
    ZonalDirections v;
    v[0] = zonal_l2_direction(axes[0]);
    for (size_t k = 1; k < 3; ++k) v[k] = mode == ZonalAxisMode::kLuminance ? v[0] : zonal_l2_direction(axes[k]);
    return v;
}

double zonal_fit(const Coeffs& c, int k, const std::array<double, 5>& v) {
    double z = 0;
    for (int m = 0; m < 5; ++m) z += c[static_cast<size_t>(4 + m)][static_cast<size_t>(k)] * v[static_cast<size_t>(m)];
    return z;
}

void encode_impl(PackedLayout layout, const Sh3Radiance& hub, const CodecOptions& p, std::uint8_t* out,
                 EncodeStats* stats, const QuantEncodeControls& controls, Coeffs* decoded) {
    const size_t size = packed_size_bytes(layout);
    std::memset(out, 0, size);
    Coeffs c = stored_coefficients(hub, p.kind);
    if (layout == PackedLayout::kZh3Q16 && controls.solve_axis) {
        // Replace the L1 by the solved one (same DC); L2 stays the target for the zonal refit.
        EncodeStats solve_stats;
        const Zh3 z = zh3_solve(hub, p.axis_mode, p, &solve_stats);
        if (stats) stats->solver_iterations += solve_stats.solver_iterations;
        for (int i = 1; i < 4; ++i)
            for (int k = 0; k < 3; ++k)
                c[static_cast<size_t>(i)][static_cast<size_t>(k)] = z.linear[i][k] * band_scale(p.kind, 1);
    }
    Rgb dc_in{static_cast<float>(c[0][0]), static_cast<float>(c[0][1]), static_cast<float>(c[0][2])};
    Rgb dc = store_dc(dc_in, effective_dc_format(layout, p.dc_format), out);
    if (controls.exact_dc) dc = dc_in;
    int clamped_count = 0;
    Coeffs q{};  // what the decoder reconstructs (stored domain)
    for (int k = 0; k < 3; ++k) {
        const double d = dc[k];
        q[0][static_cast<size_t>(k)] = d;
        for (int i = 1; i <= last_ratio_index(layout); ++i) {
            const RatioCoder coder = ratio_coder(i, p);
            bool clamped = false;
            const std::uint8_t code = coder.encode(ratio_of(c[static_cast<size_t>(i)][static_cast<size_t>(k)], d), &clamped);
            clamped_count += clamped;
            out[ratio_offset(layout, k, i)] = code;
            q[static_cast<size_t>(i)][static_cast<size_t>(k)] = coder.decode(code) * d;
        }
    }
    if (layout == PackedLayout::kZh3Q16) {
        // The decoder derives each axis from the dequantised L1; fitting the zonal coefficient
        // along that axis (rather than the float L1's) makes it the least-squares best for what
        // is actually reconstructed (Eq. 9 with the decoder's axis).
        const ZonalDirections decoder_dirs = zonal_directions(axes_from_l1(q, p), p.axis_mode);
        const ZonalDirections fit_dirs =
            controls.refit_zonal_after_l1 ? decoder_dirs : zonal_directions(axes_from_l1(c, p), p.axis_mode);
        const RatioCoder coder = zonal_coder(p);
        for (int k = 0; k < 3; ++k) {
            const double z = zonal_fit(c, k, fit_dirs[static_cast<size_t>(k)]);
            bool clamped = false;
            const std::uint8_t code = coder.encode(ratio_of(z, dc[k]), &clamped);
            clamped_count += clamped;
            out[zonal_offset(k)] = code;
            const double zq = coder.decode(code) * dc[k];
            const auto& v = decoder_dirs[static_cast<size_t>(k)];
            for (int m = 0; m < 5; ++m) q[static_cast<size_t>(4 + m)][static_cast<size_t>(k)] = zq * v[static_cast<size_t>(m)];
        }
    }
    if (stats) stats->clamped_ratios += clamped_count;
    if (decoded) *decoded = q;
}

}  // namespace

namespace {
// Certified: every channel with a positive DC has a non-negative irradiance minimum once decoded.
bool decoded_non_negative(const std::uint8_t* bytes, const CodecOptions& p) {
    const Zh3 d = decode_zh3_q16(bytes, p);
    for (int k = 0; k < 3; ++k)
        if (d.linear[0][k] > 0.0f && zh3_min_irradiance_bound(d, p.axis_mode, p.luminance, k) < 0.0) return false;
    return true;
}

// zh3_dering_q16 (codec/probe/zh3_dering.h): window, quantise, decode, check; window further while the
// decoded probe goes negative (the DC's rounding, the L1 codes and the decoder's axis all move
// it). The caps after the float window s: s (1 - 2^-12), s (1 - 2^-8), s (1 - 2^-4), then halving
// down to 0, where only the DC and the zonal code nearest 0 are left (always non-negative: the
// zonal step is far below the DC).
void encode_dering_q16(const Sh3Radiance& hub, const CodecOptions& p, std::uint8_t* out, EncodeStats* stats,
                       const QuantEncodeControls& controls) {
    QuantEncodeControls inner = controls;
    inner.dering = false;
    const Zh3 fit = zh3_fit(hub, p.axis_mode, p.luminance);
    double cap = 1.0, first = 1.0;
    for (int attempt = 0;; ++attempt) {
        Zh3 z = fit;
        const double s = zh3_dering_window(&z, p.axis_mode, p.luminance, cap);
        if (attempt == 0) first = s;
        EncodeStats round_stats;
        encode_impl(PackedLayout::kZh3Q16, zh3_expand(z, p.axis_mode, p.luminance), p, out, &round_stats, inner,
                    nullptr);
        if (decoded_non_negative(out, p) || s == 0.0 || attempt >= 16) {
            if (stats) {
                stats->clamped_ratios += round_stats.clamped_ratios;
                stats->dering_clamped = stats->dering_clamped || s < 1.0;
            }
            return;
        }
        cap = attempt < 3 ? first * (1.0 - std::ldexp(1.0, -12 + 4 * attempt)) : (attempt < 15 ? s * 0.5 : 0.0);
    }
}
}  // namespace

void encode_packed(PackedLayout layout, const Sh3Radiance& hub, const CodecOptions& params, std::uint8_t* out,
                   EncodeStats* stats, const QuantEncodeControls& controls) {
    QuantEncodeControls stored = controls;
    stored.exact_dc = false;  // the bytes always hold the quantised DC
    if (layout == PackedLayout::kZh3Q16 && controls.dering) return encode_dering_q16(hub, params, out, stats, stored);
    encode_impl(layout, hub, params, out, stats, stored, nullptr);
}

Zh3 decode_zh3_q16(const std::uint8_t* in, const CodecOptions& p) {
    const Sh3Radiance hub = decode_packed(PackedLayout::kZh3Q16, in, p);
    const Rgb dc = load_dc(in, effective_dc_format(PackedLayout::kZh3Q16, p.dc_format));
    const RatioCoder coder = zonal_coder(p);
    Zh3 z;
    z.linear = truncate_to_sh2(hub);
    for (int k = 0; k < 3; ++k)
        z.zonal[k] = static_cast<float>(coder.decode(in[zonal_offset(k)]) * dc[k] / band_scale(p.kind, 2));
    return z;
}

Sh3Radiance decode_packed(PackedLayout layout, const std::uint8_t* in, const CodecOptions& p) {
    Coeffs q{};
    const Rgb dc = load_dc(in, effective_dc_format(layout, p.dc_format));
    for (int k = 0; k < 3; ++k) {
        q[0][static_cast<size_t>(k)] = dc[k];
        for (int i = 1; i <= last_ratio_index(layout); ++i)
            q[static_cast<size_t>(i)][static_cast<size_t>(k)] = ratio_coder(i, p).decode(in[ratio_offset(layout, k, i)]) * dc[k];
    }
    if (layout == PackedLayout::kZh3Q16) {
        const ZonalDirections dirs = zonal_directions(axes_from_l1(q, p), p.axis_mode);
        const RatioCoder coder = zonal_coder(p);
        for (int k = 0; k < 3; ++k) {
            const double zq = coder.decode(in[zonal_offset(k)]) * dc[k];
            const auto& v = dirs[static_cast<size_t>(k)];
            for (int m = 0; m < 5; ++m) q[static_cast<size_t>(4 + m)][static_cast<size_t>(k)] = zq * v[static_cast<size_t>(m)];
        }
    }
    return hub_from_stored(q, p.kind);
}

Sh3Radiance quantize_roundtrip(PackedLayout layout, const Sh3Radiance& hub, const CodecOptions& params,
                               EncodeStats* stats, const QuantEncodeControls& controls) {
    std::uint8_t bytes[32];
    Coeffs q{};
    encode_impl(layout, hub, params, bytes, stats, controls, &q);
    return hub_from_stored(q, params.kind);
}

Sh3Radiance hallucinate_curve(const Sh3Radiance& linear_hub, const CodecOptions& params) {
    // ZH3 paper Sec. 3.4.3, Eq. 21 on the decoder's axis (luminance by default).
    const Zh3 z = zh3_hallucinate(truncate_to_sh2(linear_hub), Hallucination::kCurve, params.axis_mode, params);
    return zh3_expand(z, params.axis_mode, params.luminance);
}

// ---- codec table entries -------------------------------------------------------------------

namespace {
template <PackedLayout L>
void encode_plain(const Sh3Radiance& in, const CodecOptions& p, std::uint8_t* out, EncodeStats* stats) {
    encode_packed(L, in, p, out, stats);
}
template <PackedLayout L>
Sh3Radiance decode_plain(const std::uint8_t* in, const CodecOptions& p) {
    return decode_packed(L, in, p);
}

void encode_solved_q16(const Sh3Radiance& in, const CodecOptions& p, std::uint8_t* out, EncodeStats* stats) {
    QuantEncodeControls c;
    c.solve_axis = true;  // the solver's iterations and tolerance: p's encoder controls
    encode_packed(PackedLayout::kZh3Q16, in, p, out, stats, c);
}

Sh3Radiance decode_hall_curve(const std::uint8_t* in, const CodecOptions& p) {
    return hallucinate_curve(decode_packed(PackedLayout::kSh2Q, in, p), p);
}

constexpr PackedCodec kZh3Q16{PackedLayout::kZh3Q16, encode_plain<PackedLayout::kZh3Q16>,
                              decode_plain<PackedLayout::kZh3Q16>};
constexpr PackedCodec kZh3SolvedQ16{PackedLayout::kZh3Q16, encode_solved_q16, decode_plain<PackedLayout::kZh3Q16>};
constexpr PackedCodec kSh3Q28{PackedLayout::kSh3Q28, encode_plain<PackedLayout::kSh3Q28>,
                              decode_plain<PackedLayout::kSh3Q28>};
constexpr PackedCodec kSh2Q{PackedLayout::kSh2Q, encode_plain<PackedLayout::kSh2Q>, decode_plain<PackedLayout::kSh2Q>};
constexpr PackedCodec kHallCurveQ{PackedLayout::kSh2Q, encode_plain<PackedLayout::kSh2Q>, decode_hall_curve};

constexpr auto kAxisFromParams = ZonalAxis::kFromParams;
const Codec kQuantized[] = {
    packed_codec<kZh3Q16>("zh3_q16", "ZH3 (luminance axis), 16 bytes: R11G11B10F DC + 8-bit L1/zonal ratios (App. A.1)",
                          kAxisFromParams),
    packed_codec<kZh3SolvedQ16>("zh3_solved_q16",
                                "zh3_q16 bytes; encoder quantises the BFGS-solved L1 (Eq. 11), zonal refitted",
                                kAxisFromParams),
    packed_codec<kSh3Q28>("sh3_q28", "quadratic SH, 28 bytes: R11G11B10F DC + 24 8-bit ratios (tight L2 bound)",
                          ZonalAxis::kNone),
    packed_codec<kSh2Q>("sh2_q",
                        "linear SH, 16 bytes: DC slot + 9 8-bit L1 ratios (padded; hallucination decodes from it)",
                        ZonalAxis::kNone),
    packed_codec<kHallCurveQ>("hall_curve_q",
                              "sh2_q bytes, zonal L2 hallucinated at decode by the Eq. 21 curve (luminance axis)",
                              kAxisFromParams, ZonalHallucination::kCurve),
};
}  // namespace

std::span<const Codec> quantized_codecs() { return kQuantized; }

}  // namespace zhc
