// zhc/runtime/zhc.hlsl — shader-side decoders and evaluators for zhc's stored probes and IrradZ
// lightmaps (HLSL, shader model 5.0+ / 6.x; also compiles with glslang's HLSL front end to SPIR-V).
//
// Source of truth: the C++ codec (codec/probe/quantize.cpp, codec/probe/zh3.cpp, codec/probe/core_codecs.cpp,
// codec/probe/dering.cpp, codec/probe/probe_set.cpp decode_probe, codec/lightmap/irradz.h, codec/lightmap/lightmap.cpp). Every
// function here computes what its C++ twin computes, in float instead of double;
// tests/test_runtime_vk.cpp runs them on Vulkan (Mesa lavapipe) against the C++ codec.
//
// Conventions (docs/conventions.md): SH index i = l(l+1)+m, [Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20,
// Y21, Y22], the Cartesian basis of the ZH3 paper (Roughton et al. 2024, Eq. 4/5) signs included;
// Z-up world. Irradiance uses the NORMALISED clamped-cosine kernel, E(n) = (1/pi) int L max(0, n.w),
// so radiance 1 everywhere gives irradiance 1: band scales 1, 2/3, 1/4 (no pi).
//
// Stored words: a probe is read as little-endian 32-bit words (ByteAddressBuffer.Load4 etc.):
//   sh3, sh3_dering                     27 float words   [coefficient i][channel k] at 3i + k
//   sh2, hall_*                         12 float words   DC + L1 as above
//   zh3_lum/_channel/_solved_*/_dering* 15 float words   DC + L1 (12), then the zonal f20 per channel
//   zh3_q16, zh3_solved_q16, sh2_q,
//   hall_curve_q, hall_solved_q16,
//   hall_adaptive_q16                   uint4            (docs/quantization.md)
//   sh3_q28                             seven uints
// Byte b of a probe is bits 8 (b & 3) .. of word b >> 2.
//
// Irradiance here is E / pi of libraries that use the unnormalised kernel (e.g. SHforHLSL's
// CalculateIrradiance): multiply by pi for those, or by albedo for diffuse radiance directly.
//
// Example 1: a 16-byte zh3_q16 probe set in a ByteAddressBuffer, format fixed at compile time
// (the constant folds away: see the instruction counts in docs/runtime.md).
//
//   ByteAddressBuffer probes;
//   float3 ProbeIrradiance(uint probe, float3 n)
//   {
//       const ZhcFormat f = zhc_default_format(ZHC_ZH3_Q16);
//       return zhc_irradiance_zh3_q16(probes.Load4(16u * probe), f, n);
//   }
//
// Example 2: any encoding, format from the probe container's header (a constant buffer), and the
// decoded SH3 radiance for blending probes before evaluating:
//
//   uint w[27];
//   [unroll] for (uint j = 0u; j < 27u; ++j) w[j] = j < zhc_encoding_bytes(f.encoding) / 4u ? probes.Load(base + 4u * j) : 0u;
//   ZhcSH3 sh = zhc_decode_sh3(w, f);            // radiance SH3, what zhc's decode_probe gives
//   float3 e = zhc_sh3_irradiance(sh, n);        // == zhc_irradiance(w, f, n) up to rounding
//
// Example 3: an IrradZ lightmap texel (tangent frame, normal-mapped n):
//
//   float3 e = zhc_irradz_irradiance(izTex.Sample(s, uv).rgb, waTex.Sample(s, uv).r,
//                                    dTex.Sample(s, uv).rg, ZHC_IRRADZ_HHD, nTangent);
//
// Cost (bench/bench_runtime.cpp): SPIR-V instructions of "load the probe's words, irradiance at n"
// after spirv-opt -O with the default format as a constant, the kernel skeleton subtracted:
//   sh3 174, sh2 100, zh3 (luminance axis) 120, zh3 (per-channel axes) 182,
//   hall_ambdir 134 / 178 (channel), hall_sphere 188 / 232, hall_curve 185 / 229,
//   zh3_q16 220, sh3_q28 313, sh2_q 160, hall_curve_q 276, IrradZ texel (HHD / AHD) 123 / 121.
// Other per-function notes below are estimates of the arithmetic.
#ifndef ZHC_HLSL_INCLUDED
#define ZHC_HLSL_INCLUDED

// ---- encodings (the order of zhc::codecs()) -----------------------------------------------------
// One "#define ZHC_<entry name in upper case> <index in the table>u" per codec table entry, new
// entries appended; tests/test_runtime_vk.cpp and bench/bench_runtime.cpp read these lines.
#define ZHC_SH3 0u
#define ZHC_SH2 1u
#define ZHC_ZH3_LUM 2u
#define ZHC_ZH3_CHANNEL 3u
#define ZHC_ZH3_SOLVED_LUM 4u
#define ZHC_ZH3_SOLVED_CHANNEL 5u
#define ZHC_HALL_AMBDIR 6u
#define ZHC_HALL_SPHERE 7u
#define ZHC_HALL_CURVE 8u
#define ZHC_HALL_AMBDIR_CHANNEL 9u
#define ZHC_HALL_SPHERE_CHANNEL 10u
#define ZHC_HALL_CURVE_CHANNEL 11u
#define ZHC_ZH3_LUM_AXIS_CLAMP 12u
#define ZHC_ZH3_LUM_SPHERE_CLAMP 13u
#define ZHC_SH3_DERING 14u
#define ZHC_ZH3_Q16 15u
#define ZHC_ZH3_SOLVED_Q16 16u
#define ZHC_SH3_Q28 17u
#define ZHC_SH2_Q 18u
#define ZHC_HALL_CURVE_Q 19u
#define ZHC_ZH3_DERING 20u       // zh3_lum's 15 floats (whole-sphere deringing happens at encode)
#define ZHC_ZH3_DERING_Q16 21u   // zh3_q16's 16 bytes
#define ZHC_ZH3_CHANNEL_Q16 22u  // zh3_q16's 16 bytes, each channel's own axis (f.axisMode unused)
#define ZHC_ZH3_SOLVED_CHANNEL_Q16 23u  // zh3_channel_q16's 16 bytes
#define ZHC_HALL_SOLVED 24u      // hall_curve's 12 floats (the L1 is solved at encode: codec/probe/zh3_hall_solve.cpp)
#define ZHC_HALL_SOLVED_Q16 25u  // hall_curve_q's 16 bytes
#define ZHC_HALL_ADAPTIVE_Q16 26u  // sh2_q's 16 bytes, byte 15 = scale code: Eq. 21 times 0.5 min(code, 7)
#define ZHC_ENCODING_COUNT 27u
// Other names of encodings (zhc::codec_aliases(): only entries that keep irradiance >= 0 carry
// "dering" in their names; .zhp and glTF files may name these two by their aliases).
#define ZHC_ZH3_LUM_DERING ZHC_ZH3_LUM_AXIS_CLAMP
#define ZHC_ZH3_LUM_DERING_SPHERE ZHC_ZH3_LUM_SPHERE_CLAMP

// Stored bytes per probe of each encoding (all multiples of 4).
uint zhc_encoding_bytes(uint encoding)
{
    if (encoding == ZHC_SH3 || encoding == ZHC_SH3_DERING) return 108u;
    if (encoding == ZHC_ZH3_DERING) return 60u;
    if (encoding == ZHC_HALL_SOLVED) return 48u;
    if (encoding >= ZHC_ZH3_Q16) return encoding == ZHC_SH3_Q28 ? 28u : 16u;
    if (encoding == ZHC_SH2 || (encoding >= ZHC_HALL_AMBDIR && encoding <= ZHC_HALL_CURVE_CHANNEL)) return 48u;
    return 60u;  // the 15-float ZH3 layouts
}

// ---- format (what the probe container's header stores; CodecOptions storage fields, codec/probe/codec.h) --------
#define ZHC_DC_R11G11B10F 0u
#define ZHC_DC_RGB9E5 1u
#define ZHC_DC_HALF 2u
#define ZHC_L2_TIGHT 0u   // non-zonal L2 ratios in [-sqrt(15)/2, sqrt(15)/2] (Wiederien & Sloan)
#define ZHC_L2_LOOSE 1u   // [-sqrt(5), sqrt(5)]
#define ZHC_ZONAL_AFFINE 0u
#define ZHC_ZONAL_ZERO_PRESERVING 1u
#define ZHC_ZONAL_SYMMETRIC 2u
#define ZHC_AXIS_LUMINANCE 0u
#define ZHC_AXIS_PER_CHANNEL 1u
#define ZHC_KIND_RADIANCE 0u
#define ZHC_KIND_IRRADIANCE 1u   // stored SH are irradiance (band scales 1, 2/3, 1/4 applied)

struct ZhcFormat
{
    uint encoding;       // ZHC_SH3 ...
    uint bits;           // 2..8 bits per quantised ratio (clamped into that range here)
    uint sqrtEncoding;   // 0 / 1: sign-preserving square-root encoding of the ratios
    uint l2Bound;        // ZHC_L2_*
    uint dcFormat;       // ZHC_DC_* (half only fits sh2_q's 6-byte slot; elsewhere it means R11G11B10F)
    uint zonalMapping;   // ZHC_ZONAL_*
    uint axisMode;       // ZHC_AXIS_*: zh3_q16 / zh3_solved_q16 / hall_curve_q (float layouts: by name)
    uint kind;           // ZHC_KIND_*
    float lumR, lumG, lumB;  // luminance weights of the shared zonal axis (Rec. 709 by default)
    float hallA, hallB;      // Eq. 21 curve, f20 = (a p^2 + b p) f0 (defaults 0.6, 0.08)
};

// The codec table's defaults (CodecOptions defaults) for an encoding.
ZhcFormat zhc_default_format(uint encoding)
{
    ZhcFormat f;
    f.encoding = encoding;
    f.bits = 8u;
    f.sqrtEncoding = 0u;
    f.l2Bound = ZHC_L2_TIGHT;
    f.dcFormat = ZHC_DC_R11G11B10F;
    f.zonalMapping = ZHC_ZONAL_AFFINE;
    f.axisMode = ZHC_AXIS_LUMINANCE;
    f.kind = ZHC_KIND_RADIANCE;
    f.lumR = 0.2126f;
    f.lumG = 0.7152f;
    f.lumB = 0.0722f;
    f.hallA = 0.6f;
    f.hallB = 0.08f;
    return f;
}

// ---- SH constants and basis ---------------------------------------------------------------------
static const float kZhcPi = 3.14159265358979323846f;
static const float kZhcY00 = 0.28209479177387814f;   // 1 / (2 sqrt(pi))
static const float kZhcY1 = 0.48860251190291992f;    // sqrt(3 / 4pi)
static const float kZhcY2 = 1.09254843059207907f;    // sqrt(15 / 4pi)
static const float kZhcY20 = 0.31539156525252001f;   // sqrt(5 / 16pi)
static const float kZhcY22 = 0.54627421529603954f;   // sqrt(15 / 16pi)
static const float kZhcSqrt4PiOver5 = 1.58533091904240440f;  // sqrt(4 pi / 5): |Y2(a)| = 1 / this
static const float kZhcSqrt3 = 1.73205080756887729f;
static const float kZhcSqrt5 = 2.23606797749978970f;
static const float kZhcSqrt15Over2 = 1.93649167310370844f;
static const float kZhcSqrt15Over3 = 1.29099444873580562f;   // Eq. 14
static const float kZhcSqrt5Over3 = 1.29099444873580562f;    // sqrt(5/3) (Eq. 20) = sqrt(15)/3
static const float kZhcTwoSqrt5Over3 = 1.49071198499985780f; // 2 sqrt(5) / 3 (Eq. 20)

// RGB SH3 radiance: c[i] holds coefficient i of the three channels.
struct ZhcSH3
{
    float3 c[9];
};

// The nine SH3 basis functions at unit direction d (ZH3 paper Eq. 4/5). 11 mul, 3 add.
void zhc_sh3_basis(float3 d, out float y[9])
{
    y[0] = kZhcY00;
    y[1] = -kZhcY1 * d.y;
    y[2] = kZhcY1 * d.z;
    y[3] = -kZhcY1 * d.x;
    y[4] = kZhcY2 * d.x * d.y;
    y[5] = -kZhcY2 * d.y * d.z;
    y[6] = kZhcY20 * (3.0f * d.z * d.z - 1.0f);
    y[7] = -kZhcY2 * d.x * d.z;
    y[8] = kZhcY22 * (d.x * d.x - d.y * d.y);
}

// The unit L2 direction of a zonal function along unit axis a: v_m = sqrt(4 pi / 5) Y_2m(a), so a
// zonal L2 of coefficient f20 is f20 * v (ZH3 paper Eq. 2 / 6).
void zhc_zonal_l2_direction(float3 a, out float v[5])
{
    v[0] = kZhcSqrt4PiOver5 * kZhcY2 * a.x * a.y;
    v[1] = -kZhcSqrt4PiOver5 * kZhcY2 * a.y * a.z;
    v[2] = kZhcSqrt4PiOver5 * kZhcY20 * (3.0f * a.z * a.z - 1.0f);
    v[3] = -kZhcSqrt4PiOver5 * kZhcY2 * a.x * a.z;
    v[4] = kZhcSqrt4PiOver5 * kZhcY22 * (a.x * a.x - a.y * a.y);
}

// Irradiance at unit normal n from SH3 radiance: sum_i c_i Y_i(n) times the band scale
// (1, 2/3, 1/4). ~30 mul/add for RGB. (The sh3 baseline of the cost table.)
float3 zhc_sh3_irradiance(ZhcSH3 sh, float3 n)
{
    float y[9];
    zhc_sh3_basis(n, y);
    float3 l1 = sh.c[1] * y[1] + sh.c[2] * y[2] + sh.c[3] * y[3];
    float3 l2 = sh.c[4] * y[4] + sh.c[5] * y[5] + sh.c[6] * y[6] + sh.c[7] * y[7] + sh.c[8] * y[8];
    return sh.c[0] * y[0] + (2.0f / 3.0f) * l1 + 0.25f * l2;
}

// Value of the SH3 function itself at d (no band scales): for SH3 that already are irradiance.
float3 zhc_sh3_evaluate(ZhcSH3 sh, float3 d)
{
    float y[9];
    zhc_sh3_basis(d, y);
    float3 r = 0.0f;
    [unroll] for (int i = 0; i < 9; ++i) r += sh.c[i] * y[i];
    return r;
}

// Band scale of the stored kind: irradiance-stored SH are the radiance ones times 1, 2/3, 1/4.
float zhc_band_scale(uint kind, uint band)
{
    if (kind != ZHC_KIND_IRRADIANCE) return 1.0f;
    return band == 0u ? 1.0f : (band == 1u ? 2.0f / 3.0f : 0.25f);
}

// Stored-domain SH3 -> radiance SH3 (divides bands 1 and 2 by their stored-kind scale).
ZhcSH3 zhc_radiance_from_stored(ZhcSH3 s, uint kind)
{
    if (kind == ZHC_KIND_IRRADIANCE)
    {
        [unroll] for (int i = 1; i < 4; ++i) s.c[i] *= 1.5f;
        [unroll] for (int j = 4; j < 9; ++j) s.c[j] *= 4.0f;
    }
    return s;
}

// ---- small vector helpers ------------------------------------------------------------------------

// Unit vector along v, or +Z when v is zero or not finite (C++ normalize_or(v, {0, 0, 1})). v is
// scaled by its largest component first, so any finite float v normalises without the squares
// overflowing or underflowing (the C++ twin works in double). ~12 instructions more than normalize().
float3 zhc_normalize_or_z(float3 v)
{
    float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    if (!all(abs(v) <= 3.402823466e38f) || !(m > 0.0f)) return float3(0.0f, 0.0f, 1.0f);  // NaN/Inf: +Z
    float3 u = v * (1.0f / m);
    return u * rsqrt(dot(u, u));
}

// The L1 band of channel k (f1-1, f10, f11) as the vector v = (-f11, -f1-1, f10): f1(d) = kY1 v.d,
// and v / |v| is the channel's optimal linear direction.
float3 zhc_l1_vector(float3 c1m1, float3 c10, float3 c11, uint k)
{
    return float3(-c11[k], -c1m1[k], c10[k]);
}

// ---- DC formats: unpacking by integer operations -------------------------------------------------

// Unsigned float with a 5-bit exponent (bias 15) and `mbits` mantissa bits (R11G11B10F channels:
// 6 / 5; binary16 magnitude: 10). Normal codes map to float bits directly (exponent + 112);
// exponent 31 is Inf (mantissa 0) or NaN; exponent 0 is the denormal m 2^(-14 - mbits). Exact.
float zhc_unpack_ufloat(uint code, uint mbits)
{
    uint e = code >> mbits;
    uint m = code & ((1u << mbits) - 1u);
    if (e == 0u) return float(m) * asfloat((113u - mbits) << 23);  // m * 2^(-14 - mbits)
    uint fe = e == 31u ? 255u : e + 112u;
    return asfloat((fe << 23) | (m << (23u - mbits)));
}

// DXGI_FORMAT_R11G11B10_FLOAT: R bits 0-10, G 11-21, B 22-31.
float3 zhc_unpack_r11g11b10f(uint w)
{
    return float3(zhc_unpack_ufloat(w & 0x7FFu, 6u), zhc_unpack_ufloat((w >> 11) & 0x7FFu, 6u),
                  zhc_unpack_ufloat(w >> 22, 5u));
}

// DXGI_FORMAT_R9G9B9E5_SHAREDEXP: mantissas at bits 0, 9, 18; exponent bits 27-31 (bias 15);
// value = m 2^(e - 24). 2^(e - 24) is a normal float for every e in 0..31, so this is exact.
float3 zhc_unpack_rgb9e5(uint w)
{
    float scale = asfloat(((w >> 27) + 103u) << 23);  // 2^(e - 24): biased exponent e - 24 + 127
    return float3(float(w & 0x1FFu), float((w >> 9) & 0x1FFu), float((w >> 18) & 0x1FFu)) * scale;
}

// IEEE binary16 in the low 16 bits of h (integer ops; same as f16tof32 including denormals).
float zhc_unpack_half(uint h)
{
    float mag = zhc_unpack_ufloat(h & 0x7FFFu, 10u);
    return (h & 0x8000u) != 0u ? -mag : mag;
}

// The DC triple of a quantised layout: w0 = bytes 0..3, w1 = bytes 4..7 (only a half DC, which needs
// the 6-byte slot of sh2_q, reads w1). `sixByteSlot` false turns half into R11G11B10F as the C++
// decoder does for the 4-byte slots.
float3 zhc_load_dc(uint w0, uint w1, uint dcFormat, bool sixByteSlot)
{
    if (dcFormat == ZHC_DC_RGB9E5) return zhc_unpack_rgb9e5(w0);
    if (dcFormat == ZHC_DC_HALF && sixByteSlot)
        return float3(zhc_unpack_half(w0 & 0xFFFFu), zhc_unpack_half(w0 >> 16), zhc_unpack_half(w1 & 0xFFFFu));
    return zhc_unpack_r11g11b10f(w0);
}

// ---- ratio decoding (codec/probe/quantize.cpp RatioCoder::decode) ----------------------------------------

// Byte b (0..31) of a probe given as words.
uint zhc_byte(uint w, uint b) { return (w >> (8u * (b & 3u))) & 0xFFu; }

// The interval [lo, hi] of c_i / c_0 and how it maps to t in [-1, 1]. Ratios: L1 [-sqrt3, sqrt3];
// zonal L2 [-sqrt5/2, sqrt5]; other L2 +-sqrt(15)/2 (tight) or +-sqrt5; times the band scale when
// the stored kind is irradiance (ZH3 paper App. A / A.1; Wiederien & Sloan Sec. 3).
struct ZhcRatioMap
{
    float bv;         // 2^(bits - 1) - 1: code bv is t = 0, codes 0 .. 2 bv
    float invBv;
    bool sqrtEnc;
    float scalePos;   // ratio = t * scalePos + offset for t >= 0,
    float scaleNeg;   //         t * scaleNeg + offset for t < 0
    float offset;
};

ZhcRatioMap zhc_ratio_map(ZhcFormat f, uint band, bool zonal)
{
    ZhcRatioMap r;
    uint bits = clamp(f.bits, 2u, 8u);
    r.bv = float((1u << (bits - 1u)) - 1u);
    r.invBv = 1.0f / r.bv;
    r.sqrtEnc = f.sqrtEncoding != 0u;
    float s = zhc_band_scale(f.kind, band);
    float lo, hi;
    if (band == 1u) { hi = kZhcSqrt3 * s; lo = -hi; }
    else if (zonal) { hi = kZhcSqrt5 * s; lo = -0.5f * kZhcSqrt5 * s; }
    else { hi = (f.l2Bound == ZHC_L2_LOOSE ? kZhcSqrt5 : kZhcSqrt15Over2) * s; lo = -hi; }
    if (!zonal || f.zonalMapping == ZHC_ZONAL_AFFINE)
    {
        r.scalePos = 0.5f * (hi - lo);
        r.scaleNeg = r.scalePos;
        r.offset = 0.5f * (hi + lo);
    }
    else if (f.zonalMapping == ZHC_ZONAL_ZERO_PRESERVING)
    {
        r.scalePos = hi;
        r.scaleNeg = -lo;
        r.offset = 0.0f;
    }
    else
    {
        r.scalePos = max(hi, -lo);
        r.scaleNeg = r.scalePos;
        r.offset = 0.0f;
    }
    return r;
}

// Ratio of a code: t = (min(code, 2 bv) - bv) / bv, squared keeping the sign under the sqrt
// encoding (Listing 1 Unpack4), mapped onto the interval. ~6 instructions with the map folded.
float zhc_decode_ratio(uint code, ZhcRatioMap r)
{
    float t = (min(float(code), 2.0f * r.bv) - r.bv) * r.invBv;
    if (r.sqrtEnc) t *= abs(t);
    return t * (t >= 0.0f ? r.scalePos : r.scaleNeg) + r.offset;
}

// ---- zonal axes and the ZH3 evaluation ------------------------------------------------------------

// The three channels' zonal axes from the L1 band (C++ Axes): the luminance-weighted L1's direction
// shared by all channels, or each channel's own; +Z when undefined.
void zhc_zonal_axes(float3 c1m1, float3 c10, float3 c11, uint axisMode, float3 lum, out float3 a[3])
{
    if (axisMode == ZHC_AXIS_PER_CHANNEL)
    {
        [unroll] for (uint k = 0u; k < 3u; ++k) a[k] = zhc_normalize_or_z(zhc_l1_vector(c1m1, c10, c11, k));
    }
    else
    {
        float3 v = float3(-dot(lum, c11), -dot(lum, c1m1), dot(lum, c10));
        a[0] = zhc_normalize_or_z(v);
        a[1] = a[0];
        a[2] = a[0];
    }
}

// Irradiance at n of DC + L1 + a zonal L2 f20[k] along axis a[k] (ZH3 paper Listing 1):
//   E_k = kY00 c0 + w1 kY1 (v_k . n) + w2 f20_k kY20 (3 (a_k . n)^2 - 1),
// w1, w2 = 2/3, 1/4 for radiance; 1, 1 for SH that are stored as irradiance.
float3 zhc_zh3_evaluate(float3 c0, float3 c1m1, float3 c10, float3 c11, float3 f20, float3 a[3], float3 n,
                        float w1, float w2)
{
    float3 l1 = -c1m1 * n.y + c10 * n.z - c11 * n.x;
    float3 z = float3(dot(a[0], n), dot(a[1], n), dot(a[2], n));
    return kZhcY00 * c0 + (w1 * kZhcY1) * l1 + (w2 * kZhcY20) * f20 * (3.0f * z * z - 1.0f);
}

// The L2 band of a zonal L2 f20[k] along a[k], into sh.c[4..8].
void zhc_expand_zonal(inout ZhcSH3 sh, float3 f20, float3 a[3])
{
    float v0[5], v1[5], v2[5];
    zhc_zonal_l2_direction(a[0], v0);
    zhc_zonal_l2_direction(a[1], v1);
    zhc_zonal_l2_direction(a[2], v2);
    [unroll] for (int m = 0; m < 5; ++m) sh.c[4 + m] = f20 * float3(v0[m], v1[m], v2[m]);
}

// ---- hallucination (ZH3 paper Sec. 3.4, Listing 1; codec/probe/zh3.cpp hallucinate_zonal) ---------------
#define ZHC_HALL_MODEL_AMBDIR 0u   // Eq. 14: f20 = sqrt(15)/3 |f1|
#define ZHC_HALL_MODEL_SPHERE 1u   // Eq. 20: f20 = (2 sqrt5/3 p^2 - sqrt(5/3) p) f0
#define ZHC_HALL_MODEL_CURVE 2u    // Eq. 21: f20 = (a p^2 + b p) f0

// f1 = the channel's L1 projected on its zonal axis; p = |f1| / f0 clamped to [0, sqrt3];
// f0 <= 0 or not finite gives 0 (except Eq. 14, which does not use f0).
float zhc_hallucinate_zonal(uint model, float f0, float f1, float curveA, float curveB)
{
    float af1 = abs(f1);
    if (model == ZHC_HALL_MODEL_AMBDIR) return kZhcSqrt15Over3 * af1;
    if (!(f0 > 0.0f) || !(f0 <= 3.402823466e38f)) return 0.0f;
    float p = min(af1 / f0, kZhcSqrt3);
    if (model == ZHC_HALL_MODEL_SPHERE) return (kZhcTwoSqrt5Over3 * p * p - kZhcSqrt5Over3 * p) * f0;
    return (curveA * p * p + curveB * p) * f0;
}

float3 zhc_hallucinate(uint model, float3 c0, float3 c1m1, float3 c10, float3 c11, float3 a[3], ZhcFormat f)
{
    float3 r;
    [unroll] for (uint k = 0u; k < 3u; ++k)
        r[k] = zhc_hallucinate_zonal(model, c0[k], dot(zhc_l1_vector(c1m1, c10, c11, k), a[k]), f.hallA, f.hallB);
    return r;
}

// ---- float layouts ---------------------------------------------------------------------------------

// What a float layout holds, by encoding.
uint zhc_axis_mode_of(uint encoding, ZhcFormat f)
{
    if (encoding == ZHC_ZH3_CHANNEL || encoding == ZHC_ZH3_SOLVED_CHANNEL || encoding == ZHC_HALL_AMBDIR_CHANNEL ||
        encoding == ZHC_HALL_SPHERE_CHANNEL || encoding == ZHC_HALL_CURVE_CHANNEL ||
        encoding == ZHC_ZH3_CHANNEL_Q16 || encoding == ZHC_ZH3_SOLVED_CHANNEL_Q16)
        return ZHC_AXIS_PER_CHANNEL;
    if (encoding == ZHC_ZH3_DERING || encoding == ZHC_HALL_SOLVED) return ZHC_AXIS_LUMINANCE;
    if (encoding >= ZHC_ZH3_Q16) return f.axisMode;  // quantised layouts: the container's axis mode
    return ZHC_AXIS_LUMINANCE;
}
uint zhc_hall_model_of(uint encoding)
{
    if (encoding == ZHC_HALL_AMBDIR || encoding == ZHC_HALL_AMBDIR_CHANNEL) return ZHC_HALL_MODEL_AMBDIR;
    if (encoding == ZHC_HALL_SPHERE || encoding == ZHC_HALL_SPHERE_CHANNEL) return ZHC_HALL_MODEL_SPHERE;
    return ZHC_HALL_MODEL_CURVE;
}

float3 zhc_word3(uint w[27], uint i) { return asfloat(uint3(w[3u * i], w[3u * i + 1u], w[3u * i + 2u])); }

// sh3 / sh3_dering (27 words), sh2 (12 words, L2 zero), stored-domain SH3.
ZhcSH3 zhc_stored_sh3_floats(uint w[27], uint count)
{
    ZhcSH3 s;
    [unroll] for (uint i = 0u; i < 9u; ++i) s.c[i] = i < count ? zhc_word3(w, i) : 0.0f;
    return s;
}

// The ZH3 float layouts (15 words) and the hall_* layouts (12 words; f20 hallucinated).
void zhc_zh3_floats(uint w[27], uint encoding, ZhcFormat f, out float3 c[4], out float3 f20, out float3 a[3])
{
    [unroll] for (uint i = 0u; i < 4u; ++i) c[i] = zhc_word3(w, i);
    float3 lum = float3(f.lumR, f.lumG, f.lumB);
    zhc_zonal_axes(c[1], c[2], c[3], zhc_axis_mode_of(encoding, f), lum, a);
    if ((encoding >= ZHC_HALL_AMBDIR && encoding <= ZHC_HALL_CURVE_CHANNEL) || encoding == ZHC_HALL_SOLVED)
        f20 = zhc_hallucinate(zhc_hall_model_of(encoding), c[0], c[1], c[2], c[3], a, f);
    else
        f20 = zhc_word3(w, 4u);
}

// ---- quantised layouts -----------------------------------------------------------------------------

// zh3_q16 / zh3_solved_q16 / zh3_channel_q16 ... (uint4): DC in word 0 (R11G11B10F or RGB9E5); word 1 + k holds channel
// k's codes [L1-1, L10, L11, zonal] in bytes 0..3. Output: stored-domain DC + L1, f20, axes.
void zhc_zh3_q16(uint4 p, ZhcFormat f, out float3 c[4], out float3 f20, out float3 a[3])
{
    float3 dc = zhc_load_dc(p.x, 0u, f.dcFormat, false);
    ZhcRatioMap m1 = zhc_ratio_map(f, 1u, false);
    ZhcRatioMap mz = zhc_ratio_map(f, 2u, true);
    c[0] = dc;
    [unroll] for (uint j = 1u; j < 4u; ++j)
        c[j] = float3(zhc_decode_ratio(zhc_byte(p.y, j - 1u), m1), zhc_decode_ratio(zhc_byte(p.z, j - 1u), m1),
                      zhc_decode_ratio(zhc_byte(p.w, j - 1u), m1)) * dc;
    f20 = float3(zhc_decode_ratio(zhc_byte(p.y, 3u), mz), zhc_decode_ratio(zhc_byte(p.z, 3u), mz),
                 zhc_decode_ratio(zhc_byte(p.w, 3u), mz)) * dc;
    // f.axisMode, except for the entries that fix each channel's own axis (zh3_channel_q16, ...).
    zhc_zonal_axes(c[1], c[2], c[3], zhc_axis_mode_of(f.encoding, f), float3(f.lumR, f.lumG, f.lumB), a);
}

// sh2_q / hall_curve_q (uint4): DC slot bytes 0..5; channel k's L1 codes at bytes 6 + 3k + j.
void zhc_sh2_q(uint4 p, ZhcFormat f, out float3 c[4])
{
    uint w[4] = { p.x, p.y, p.z, p.w };
    float3 dc = zhc_load_dc(p.x, p.y, f.dcFormat, true);
    ZhcRatioMap m1 = zhc_ratio_map(f, 1u, false);
    c[0] = dc;
    [unroll] for (uint j = 1u; j < 4u; ++j)
    {
        float3 r;
        [unroll] for (uint k = 0u; k < 3u; ++k)
        {
            uint b = 6u + 3u * k + (j - 1u);
            r[k] = zhc_decode_ratio(zhc_byte(w[b >> 2], b), m1);
        }
        c[j] = r * dc;
    }
}

// sh3_q28 (seven uints): DC in word 0; channel k's codes for SH index i = 1..8 at byte 4 + 8k + i - 1,
// i.e. words 1 + 2k (L1-1, L10, L11, L2-2) and 2 + 2k (L2-1, L20, L21, L22). Stored-domain SH3.
ZhcSH3 zhc_sh3_q28_stored(uint w[7], ZhcFormat f)
{
    ZhcSH3 s;
    float3 dc = zhc_load_dc(w[0], 0u, f.dcFormat, false);
    ZhcRatioMap m1 = zhc_ratio_map(f, 1u, false);
    ZhcRatioMap m2 = zhc_ratio_map(f, 2u, false);
    ZhcRatioMap mz = zhc_ratio_map(f, 2u, true);
    s.c[0] = dc;
    [unroll] for (uint i = 1u; i < 9u; ++i)
    {
        ZhcRatioMap m = i < 4u ? m1 : (i == 6u ? mz : m2);
        float3 r;
        [unroll] for (uint k = 0u; k < 3u; ++k)
        {
            uint b = 4u + 8u * k + (i - 1u);
            r[k] = zhc_decode_ratio(zhc_byte(w[b >> 2], b), m);
        }
        s.c[i] = r * dc;
    }
    return s;
}

// ---- per-encoding entry points: irradiance at a unit normal straight from the stored words ---------

// Irradiance at n from any float layout (w holds the probe's words, unused ones ignored).
float3 zhc_irradiance_floats(uint w[27], ZhcFormat f, float3 n)
{
    bool irr = f.kind == ZHC_KIND_IRRADIANCE;
    if (f.encoding == ZHC_SH3 || f.encoding == ZHC_SH3_DERING || f.encoding == ZHC_SH2)
    {
        ZhcSH3 s = zhc_stored_sh3_floats(w, f.encoding == ZHC_SH2 ? 4u : 9u);
        return irr ? zhc_sh3_evaluate(s, n) : zhc_sh3_irradiance(s, n);
    }
    float3 c[4], f20, a[3];
    zhc_zh3_floats(w, f.encoding, f, c, f20, a);
    return zhc_zh3_evaluate(c[0], c[1], c[2], c[3], f20, a, n, irr ? 1.0f : 2.0f / 3.0f, irr ? 1.0f : 0.25f);
}

// zh3_q16 / zh3_solved_q16: 16 bytes. Cost: 12 ratio decodes, one axis, one zonal evaluation.
float3 zhc_irradiance_zh3_q16(uint4 p, ZhcFormat f, float3 n)
{
    float3 c[4], f20, a[3];
    zhc_zh3_q16(p, f, c, f20, a);
    bool irr = f.kind == ZHC_KIND_IRRADIANCE;
    return zhc_zh3_evaluate(c[0], c[1], c[2], c[3], f20, a, n, irr ? 1.0f : 2.0f / 3.0f, irr ? 1.0f : 0.25f);
}

// sh2_q: 16 bytes, linear SH (9 ratio decodes).
float3 zhc_irradiance_sh2_q(uint4 p, ZhcFormat f, float3 n)
{
    float3 c[4];
    zhc_sh2_q(p, f, c);
    float w1 = f.kind == ZHC_KIND_IRRADIANCE ? 1.0f : 2.0f / 3.0f;
    return kZhcY00 * c[0] + (w1 * kZhcY1) * (-c[1] * n.y + c[2] * n.z - c[3] * n.x);
}

// hall_adaptive_q16: the curve's a and b times s = 0.5 min(byte 15, 7) (codec/probe/zh3_hall_solve.cpp); 1 for
// hall_curve_q / hall_solved_q16.
ZhcFormat zhc_hall_scaled(uint4 p, ZhcFormat f)
{
    float s = f.encoding == ZHC_HALL_ADAPTIVE_Q16 ? 0.5f * float(min(zhc_byte(p.w, 3u), 7u)) : 1.0f;
    f.hallA *= s;
    f.hallB *= s;
    return f;
}

// hall_curve_q (and hall_solved_q16, hall_adaptive_q16): sh2_q bytes, then (on the RADIANCE linear
// SH, as decode_probe does) the Eq. 21 curve along f.axisMode's axis.
float3 zhc_irradiance_hall_curve_q(uint4 p, ZhcFormat f, float3 n)
{
    float3 c[4], a[3];
    zhc_sh2_q(p, f, c);
    f = zhc_hall_scaled(p, f);
    float s1 = f.kind == ZHC_KIND_IRRADIANCE ? 1.5f : 1.0f;  // stored -> radiance L1
    c[1] *= s1; c[2] *= s1; c[3] *= s1;
    zhc_zonal_axes(c[1], c[2], c[3], f.axisMode, float3(f.lumR, f.lumG, f.lumB), a);
    float3 f20 = zhc_hallucinate(ZHC_HALL_MODEL_CURVE, c[0], c[1], c[2], c[3], a, f);
    return zhc_zh3_evaluate(c[0], c[1], c[2], c[3], f20, a, n, 2.0f / 3.0f, 0.25f);
}

// sh3_q28: 28 bytes, 24 ratio decodes, full SH3 evaluation.
float3 zhc_irradiance_sh3_q28(uint w[7], ZhcFormat f, float3 n)
{
    ZhcSH3 s = zhc_sh3_q28_stored(w, f);
    return f.kind == ZHC_KIND_IRRADIANCE ? zhc_sh3_evaluate(s, n) : zhc_sh3_irradiance(s, n);
}

// ---- any encoding from up to 27 words (f.encoding selects; the uber-path of the tests) -------------

// The encodings stored in zh3_q16's 16 bytes (decoded by zhc_decode_zh3_q16).
bool zhc_zh3_q16_bytes(uint e)
{
    return e == ZHC_ZH3_Q16 || e == ZHC_ZH3_SOLVED_Q16 || e == ZHC_ZH3_DERING_Q16 || e == ZHC_ZH3_CHANNEL_Q16 ||
           e == ZHC_ZH3_SOLVED_CHANNEL_Q16;
}

float3 zhc_irradiance(uint w[27], ZhcFormat f, float3 n)
{
    if (zhc_zh3_q16_bytes(f.encoding))
        return zhc_irradiance_zh3_q16(uint4(w[0], w[1], w[2], w[3]), f, n);
    if (f.encoding == ZHC_SH2_Q) return zhc_irradiance_sh2_q(uint4(w[0], w[1], w[2], w[3]), f, n);
    if (f.encoding == ZHC_HALL_CURVE_Q || f.encoding == ZHC_HALL_SOLVED_Q16 || f.encoding == ZHC_HALL_ADAPTIVE_Q16)
        return zhc_irradiance_hall_curve_q(uint4(w[0], w[1], w[2], w[3]), f, n);
    if (f.encoding == ZHC_SH3_Q28)
    {
        uint q[7] = { w[0], w[1], w[2], w[3], w[4], w[5], w[6] };
        return zhc_irradiance_sh3_q28(q, f, n);
    }
    return zhc_irradiance_floats(w, f, n);
}

// ---- decode to the hub: SH3 RADIANCE (what decode_probe returns) ---------------------------------

// DC + L1 + zonal L2 along the axes, stored domain -> radiance SH3.
ZhcSH3 zhc_sh3_from_zh3(float3 c[4], float3 f20, float3 a[3], uint kind)
{
    ZhcSH3 s;
    [unroll] for (int i = 0; i < 4; ++i) s.c[i] = c[i];
    zhc_expand_zonal(s, f20, a);
    return zhc_radiance_from_stored(s, kind);
}

ZhcSH3 zhc_decode_zh3_q16(uint4 p, ZhcFormat f)
{
    float3 c[4], f20, a[3];
    zhc_zh3_q16(p, f, c, f20, a);
    return zhc_sh3_from_zh3(c, f20, a, f.kind);
}

ZhcSH3 zhc_decode_sh2_q(uint4 p, ZhcFormat f)
{
    float3 c[4];
    zhc_sh2_q(p, f, c);
    ZhcSH3 s;
    [unroll] for (int i = 0; i < 9; ++i) s.c[i] = i < 4 ? c[i] : 0.0f;
    return zhc_radiance_from_stored(s, f.kind);
}

// sh2_q bytes; the zonal L2 is hallucinated (Eq. 21) on the radiance linear SH.
ZhcSH3 zhc_decode_hall_curve_q(uint4 p, ZhcFormat f)
{
    float3 c[4], a[3];
    zhc_sh2_q(p, f, c);
    f = zhc_hall_scaled(p, f);
    float s1 = f.kind == ZHC_KIND_IRRADIANCE ? 1.5f : 1.0f;
    c[1] *= s1; c[2] *= s1; c[3] *= s1;
    zhc_zonal_axes(c[1], c[2], c[3], f.axisMode, float3(f.lumR, f.lumG, f.lumB), a);
    float3 f20 = zhc_hallucinate(ZHC_HALL_MODEL_CURVE, c[0], c[1], c[2], c[3], a, f);
    return zhc_sh3_from_zh3(c, f20, a, ZHC_KIND_RADIANCE);  // already radiance
}

ZhcSH3 zhc_decode_sh3_q28(uint w[7], ZhcFormat f) { return zhc_radiance_from_stored(zhc_sh3_q28_stored(w, f), f.kind); }

// Float layouts (sh3, sh2, sh3_dering, the 15-float ZH3 and 12-float hall_* layouts).
ZhcSH3 zhc_decode_floats(uint w[27], ZhcFormat f)
{
    uint e = f.encoding;
    if (e == ZHC_SH3 || e == ZHC_SH3_DERING || e == ZHC_SH2)
        return zhc_radiance_from_stored(zhc_stored_sh3_floats(w, e == ZHC_SH2 ? 4u : 9u), f.kind);
    float3 c[4], f20, a[3];
    zhc_zh3_floats(w, e, f, c, f20, a);
    return zhc_sh3_from_zh3(c, f20, a, f.kind);
}

// Any encoding from up to 27 words (f.encoding selects).
ZhcSH3 zhc_decode_sh3(uint w[27], ZhcFormat f)
{
    uint e = f.encoding;
    uint4 p = uint4(w[0], w[1], w[2], w[3]);
    if (zhc_zh3_q16_bytes(e)) return zhc_decode_zh3_q16(p, f);
    if (e == ZHC_SH2_Q) return zhc_decode_sh2_q(p, f);
    if (e == ZHC_HALL_CURVE_Q || e == ZHC_HALL_SOLVED_Q16 || e == ZHC_HALL_ADAPTIVE_Q16) return zhc_decode_hall_curve_q(p, f);
    if (e == ZHC_SH3_Q28)
    {
        uint q[7] = { w[0], w[1], w[2], w[3], w[4], w[5], w[6] };
        return zhc_decode_sh3_q28(q, f);
    }
    return zhc_decode_floats(w, f);
}

// ---- IrradZ lightmaps (codec/lightmap/irradz.h, Roughton SIGGRAPH 2024 Advances) ------------------------------
//
// Three textures per lightmap: BC6H I_z (rgb irradiance at the surface normal), BC4 w_a, BC5 d
// (hemi-octahedral). Pass the SAMPLED (decoded, filtered) values; everything is in the tangent frame
// (surface normal = +Z). Models:
//   HHD: E(n) = C_a (1 + n_z) / 2 + C_d max(0, n.d)      AHD: E(n) = C_a + C_d max(0, n.d)
// with C_a = w_a I_z and C_d = (1 - w_a) I_z / d_z, so E(+Z) = I_z exactly.
#define ZHC_IRRADZ_HHD 0u
#define ZHC_IRRADZ_AHD 1u
static const float kZhcIrradzMinDz = 0.08715574274765817f;  // cos 85 deg: d is kept above the horizon
static const float kZhcIrradzMaxSin = 0.99619469809174553f; // sin 85 deg

// BC5 (u, v) in [0, 1]^2 -> unit direction in the upper hemisphere (codec/lightmap/lightmap.cpp decode_hemioct).
float3 zhc_decode_hemioct(float2 uv)
{
    float2 ab = 2.0f * saturate(uv) - 1.0f;
    float px = 0.5f * (ab.x + ab.y), py = 0.5f * (ab.x - ab.y);
    return zhc_normalize_or_z(float3(px, py, max(0.0f, 1.0f - abs(px) - abs(py))));
}

struct ZhcIrradzLighting
{
    float3 ca, cd;   // hemisphere / ambient colour and directional colour
    float3 d;        // unit highlight direction, d.z >= cos 85 deg
};

// IrradZ parameters -> model colours (irradz::to_lighting): d clamped to theta <= 85 deg keeping its
// azimuth, w_a to [0, 1].
ZhcIrradzLighting zhc_irradz_lighting(float3 iz, float wa, float3 d)
{
    ZhcIrradzLighting l;
    d = zhc_normalize_or_z(d);
    if (d.z < kZhcIrradzMinDz)
    {
        float2 h = d.xy * rsqrt(dot(d.xy, d.xy));  // d.xy != 0 here: |d| = 1 and d.z < cos 85
        d = float3(h * kZhcIrradzMaxSin, kZhcIrradzMinDz);
    }
    float w = saturate(wa);
    l.d = d;
    l.ca = w * iz;
    l.cd = (1.0f - w) * iz / d.z;
    return l;
}

// Irradiance at tangent-frame unit normal n. ~15 instructions after the lighting is built.
float3 zhc_irradz_evaluate(ZhcIrradzLighting l, uint model, float3 n)
{
    float h = model == ZHC_IRRADZ_HHD ? 0.5f * (1.0f + n.z) : 1.0f;
    return l.ca * h + l.cd * max(0.0f, dot(n, l.d));
}

// All in one: the three textures' sampled values -> irradiance at n.
float3 zhc_irradz_irradiance(float3 iz, float wa, float2 dHemiOct, uint model, float3 n)
{
    return zhc_irradz_evaluate(zhc_irradz_lighting(iz, wa, zhc_decode_hemioct(dHemiOct)), model, n);
}

// ---- probe volumes (docs/runtime.md "Probe volumes"; zhc_volume_* of runtime/zhc_runtime.h) ------
//
// A grid of probes: probe (x, y, z) is number x + nx (y + ny z) at origin + (x, y, z) * spacing, its
// stored words at (number * words per probe) in the application's buffer. The irradiance at a point
// blends the DECODED SH3 of the 8 probes of the cell containing it (the point clamped to the grid's
// box) with trilinear weights and evaluates once: by linearity, the trilinear blend of the 8 probes'
// irradiance. Stored words must not be blended (ZH3's axis is per probe; packed coefficients are
// ratios times the DC), so this fetches and decodes up to 8 probes (weight-0 probes are skipped).
//
// Binding: define ZHC_VOLUME_WORD(index) before including this file, as an expression giving the
// uint at word `index` of the probe words (the .zhp payload / glTF accessor bytes as-is), e.g.
//
//   ByteAddressBuffer probeWords;
//   #define ZHC_VOLUME_WORD(i) probeWords.Load(4u * (i))
//   #include "zhc.hlsl"
//   cbuffer Volume { ZhcVolume gVolume; ZhcFormat gFormat; };   // grid + format from the header
//   float3 e = zhc_volume_irradiance(gVolume, gFormat, worldPosition, worldNormal);
//
// Without ZHC_VOLUME_WORD only the ZhcVolume struct is declared.
struct ZhcVolume
{
    float3 origin;   // position of probe (0, 0, 0)
    float3 spacing;  // > 0 (the application checks, as zhc_volume_init)
    uint3 counts;    // >= 1 each
};

#ifdef ZHC_VOLUME_WORD
// SH3 radiance of probe `probe` of the volume's buffer.
ZhcSH3 zhc_volume_probe(uint probe, ZhcFormat f)
{
    uint stride = zhc_encoding_bytes(f.encoding) / 4u;
    uint w[27];
    [unroll] for (uint k = 0u; k < 27u; ++k) w[k] = k < stride ? ZHC_VOLUME_WORD(probe * stride + k) : 0u;
    return zhc_decode_sh3(w, f);
}

// Blended SH3 radiance at p: t = clamp((p - origin) / spacing, 0, counts - 1) (NaN: 0), cell
// i0 = min(floor(t), counts - 2), weights prod (f or 1 - f), f = t - i0.
ZhcSH3 zhc_volume_sh3(ZhcVolume v, ZhcFormat f, float3 p)
{
    uint3 n = max(v.counts, uint3(1u, 1u, 1u));
    float3 t = (p - v.origin) / v.spacing;
    t = float3(t.x >= 0.0f ? t.x : 0.0f, t.y >= 0.0f ? t.y : 0.0f, t.z >= 0.0f ? t.z : 0.0f);  // below, or NaN: 0
    t = min(t, float3(n - 1u));
    uint3 i0 = min(uint3(t), max(n, uint3(2u, 2u, 2u)) - 2u);
    float3 fr = t - float3(i0);
    ZhcSH3 acc;
    [unroll] for (int i = 0; i < 9; ++i) acc.c[i] = float3(0.0f, 0.0f, 0.0f);
    [loop] for (uint c = 0u; c < 8u; ++c)
    {
        uint3 b = uint3(c & 1u, (c >> 1) & 1u, c >> 2);
        float wx = b.x != 0u ? fr.x : 1.0f - fr.x;
        float wy = b.y != 0u ? fr.y : 1.0f - fr.y;
        float wz = b.z != 0u ? fr.z : 1.0f - fr.z;
        float w = wx * wy * wz;
        if (w == 0.0f) continue;
        uint3 q = i0 + b;
        ZhcSH3 s = zhc_volume_probe(q.x + n.x * (q.y + n.y * q.z), f);
        [unroll] for (int j = 0; j < 9; ++j) acc.c[j] += w * s.c[j];
    }
    return acc;
}

// Irradiance (zhc's normalised kernel) at position p for the surface normal `normal` (normalised
// here; zero or not finite: +Z), both in the probe set's frame (zhc axes for a .zhp).
float3 zhc_volume_irradiance(ZhcVolume v, ZhcFormat f, float3 p, float3 normal)
{
    return zhc_sh3_irradiance(zhc_volume_sh3(v, f, p), zhc_normalize_or_z(normal));
}
#endif

#endif  // ZHC_HLSL_INCLUDED
