// zhc/runtime/zhc.glsl — GPU decoders and evaluators for every stored zhc probe format and for the
// IrradZ lightmap. An include file: no #version line; prepend "#version 450" (desktop)
// or "#version 310 es" (GLSL ES 3.10), compute or fragment stage. No extensions are used.
//
// Source of truth: the C++ codec (codec/probe/quantize.cpp, codec/probe/zh3.cpp, codec/probe/core_codecs.cpp,
// codec/probe/dering.cpp, codec/probe/probe_set.cpp, codec/lightmap/irradz.cpp, codec/lightmap/lightmap.cpp). Every function
// here computes what the codec computes, in float instead of double; tests/test_runtime_gl.cpp
// runs this file on Mesa llvmpipe and compares with the codec on >= 100,000 probes per encoding.
//
// Conventions (docs/conventions.md): SH index i = l(l+1)+m, [Y00, Y1-1, Y10, Y11, Y2-2, Y2-1,
// Y20, Y21, Y22]; Cartesian basis of the ZH3 paper (signs included); zhc's world frame is Z-up.
// Irradiance is E(n) = (1/pi) integral L(w) max(0, n.w) dw (constant radiance 1 -> irradiance 1),
// i.e. band scales 1, 2/3, 1/4 on the radiance SH.
//
// Upload: every probe is its stored bytes, little-endian, read as 32-bit words (byte j of the probe
// is bits 8 (j % 4) .. 8 (j % 4) + 7 of word j / 4). 16-byte layouts are one uvec4, sh3_q28 seven
// uints, the float layouts 12 / 15 / 27 uints (uintBitsToFloat of each word).
//
// Example #1: irradiance from a zh3_q16 probe set in a compute or fragment shader.
//
//   layout(std430, binding = 0) readonly buffer Probes { uvec4 probes[]; };   // .zhp payload as-is
//   uniform ZhcFormat uFormat;  // family ZHC_LAYOUT_ZH3_Q16, other fields from the .zhp header
//   ...
//   vec3 e = zhcIrradianceZh3Q16(probes[probeIndex], uFormat, worldNormal);
//
// Example #2: decode to SH3 radiance first (to blend neighbouring probes, rotate, ...), then
// evaluate: irradiance is linear in the coefficients, so blending decoded probes is exact.
//
//   ZhcSh3 a = zhcDecodeSh3Q28(wordsA, uFormat), b = zhcDecodeSh3Q28(wordsB, uFormat);
//   for (int i = 0; i < 9; ++i) a.c[i] = mix(a.c[i], b.c[i], t);
//   vec3 e = zhcIrradianceSh3(a, worldNormal);
//
// Example #3: an IrradZ lightmap texel (three BC textures, tangent-space normal).
//
//   vec3 e = zhcIrradZIrradiance(texture(uBc6hIz, uv).rgb, texture(uBc4Wa, uv).r,
//                                texture(uBc5Dir, uv).rg, tangentNormal, ZHC_IRRADZ_HHD);
//
// Robustness: every function is total. Garbage words give finite-or-NaN/Inf results, never a
// hang: there are no data-dependent loops; shifts and array indices are clamped.
//
// Accuracy (tests/test_runtime_gl.cpp, Mesa llvmpipe, GLSL 4.50 and ES 3.10): DC unpacking is
// bit-exact; decoded coefficients of the float layouts are bit copies; irradiance is within 4 u S
// of the double-precision codec (u = 2^-24, S = the sum of the magnitudes of the evaluation's
// terms, quantised coefficients counted at their ratio bound times the DC), decoded quantised /
// zonal coefficients within 3.4 u of theirs; IrradZ within 1.8 u |I_z| (1 + (1 + 1/d_z)/d_z).
//
// Cost notes count scalar float operations (mul/add/fma ~ 1, div / inversesqrt ~ 4) per probe.

precision highp float;
precision highp int;

// ---- format description ------------------------------------------------------------------------

// Every codec table entry (zhc::codecs(), same order): its layout family (how the words are laid
// out), the zonal L2 hallucinated at decode, and the zonal axis: luminance / channel = fixed by the
// entry (set axisMode to it), header = the .zhp header's axis mode, none = no zonal term. One line
// per entry; tests/test_runtime_gl.cpp reads these lines (an entry missing here fails it).
//   name                   family              hallucination                 axis
//   sh3                    ZHC_LAYOUT_SH3_F32  ZHC_HALL_MODE_NONE            none
//   sh2                    ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_NONE            none
//   zh3_lum                ZHC_LAYOUT_ZH3_F32  ZHC_HALL_MODE_NONE            luminance
//   zh3_channel            ZHC_LAYOUT_ZH3_F32  ZHC_HALL_MODE_NONE            channel
//   zh3_solved_lum         ZHC_LAYOUT_ZH3_F32  ZHC_HALL_MODE_NONE            luminance
//   zh3_solved_channel     ZHC_LAYOUT_ZH3_F32  ZHC_HALL_MODE_NONE            channel
//   hall_ambdir            ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_AMBDIR          luminance
//   hall_sphere            ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_SPHERE          luminance
//   hall_curve             ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_CURVE           luminance
//   hall_ambdir_channel    ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_AMBDIR          channel
//   hall_sphere_channel    ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_SPHERE          channel
//   hall_curve_channel     ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_CURVE           channel
//   zh3_lum_axis_clamp     ZHC_LAYOUT_ZH3_F32  ZHC_HALL_MODE_NONE            luminance
//   zh3_lum_sphere_clamp   ZHC_LAYOUT_ZH3_F32  ZHC_HALL_MODE_NONE            luminance
//   sh3_dering             ZHC_LAYOUT_SH3_F32  ZHC_HALL_MODE_NONE            none
//   zh3_q16                ZHC_LAYOUT_ZH3_Q16  ZHC_HALL_MODE_NONE            header
//   zh3_solved_q16         ZHC_LAYOUT_ZH3_Q16  ZHC_HALL_MODE_NONE            header
//   sh3_q28                ZHC_LAYOUT_SH3_Q28  ZHC_HALL_MODE_NONE            none
//   sh2_q                  ZHC_LAYOUT_SH2_Q    ZHC_HALL_MODE_NONE            none
//   hall_curve_q           ZHC_LAYOUT_SH2_Q    ZHC_HALL_MODE_CURVE           header
//   zh3_dering             ZHC_LAYOUT_ZH3_F32  ZHC_HALL_MODE_NONE            luminance
//   zh3_dering_q16         ZHC_LAYOUT_ZH3_Q16  ZHC_HALL_MODE_NONE            header
//   zh3_channel_q16        ZHC_LAYOUT_ZH3_Q16  ZHC_HALL_MODE_NONE            channel
//   zh3_solved_channel_q16 ZHC_LAYOUT_ZH3_Q16  ZHC_HALL_MODE_NONE            channel
//   hall_solved            ZHC_LAYOUT_SH2_F32  ZHC_HALL_MODE_CURVE           luminance
//   hall_solved_q16        ZHC_LAYOUT_SH2_Q    ZHC_HALL_MODE_CURVE           header
//   hall_adaptive_q16      ZHC_LAYOUT_SH2_Q    ZHC_HALL_MODE_CURVE_ADAPTIVE  header
// (sh3 27 words, sh2 12, the ZH3 floats 15, sh3_q28 seven uints, the other quantised layouts uvec4.)
const uint ZHC_LAYOUT_SH3_F32 = 0u;
const uint ZHC_LAYOUT_SH2_F32 = 1u;
const uint ZHC_LAYOUT_ZH3_F32 = 2u;
const uint ZHC_LAYOUT_ZH3_Q16 = 3u;
const uint ZHC_LAYOUT_SH3_Q28 = 4u;
const uint ZHC_LAYOUT_SH2_Q = 5u;

// Zonal L2 hallucinated at decode (ZH3 paper Sec. 3.4; codec zh3_hallucinate).
const uint ZHC_HALL_MODE_NONE = 0u;
const uint ZHC_HALL_MODE_AMBDIR = 1u;  // Eq. 14: f20 = sqrt(15)/3 |f1|
const uint ZHC_HALL_MODE_SPHERE = 2u;  // Eq. 20: f20 = (2 sqrt(5)/3 p^2 - sqrt(5/3) p) f0
const uint ZHC_HALL_MODE_CURVE = 3u;   // Eq. 21: f20 = (a p^2 + b p) f0
// hall_adaptive_q16 (ZHC_LAYOUT_SH2_Q only): Eq. 21 with a, b times s = 0.5 min(byte 15, 7).
const uint ZHC_HALL_MODE_CURVE_ADAPTIVE = 4u;

// .zhp header enums (codec/probe/quantize.h, same numeric values as the file).
const uint ZHC_DC_R11G11B10F = 0u;
const uint ZHC_DC_RGB9E5 = 1u;
const uint ZHC_DC_HALF = 2u;  // sh2_q / hall_curve_q only (6-byte slot); elsewhere read as R11G11B10F
const uint ZHC_L2_TIGHT = 0u;  // non-zonal L2 ratio bound sqrt(15)/2 (Wiederien & Sloan)
const uint ZHC_L2_LOOSE = 1u;  // sqrt(5)
const uint ZHC_ZONAL_AFFINE = 0u;
const uint ZHC_ZONAL_ZERO_PRESERVING = 1u;
const uint ZHC_ZONAL_SYMMETRIC = 2u;
const uint ZHC_AXIS_LUMINANCE = 0u;
const uint ZHC_AXIS_PER_CHANNEL = 1u;
const uint ZHC_KIND_RADIANCE = 0u;
const uint ZHC_KIND_IRRADIANCE = 1u;  // stored SH are irradiance (band scales applied)

// Everything that gives stored words their meaning (the .zhp header fields plus the layout family
// and, for the hall_* entries, the hallucination model). All uint/vec so it fits a UBO (std140).
struct ZhcFormat {
    uint family;         // ZHC_LAYOUT_* (the layout family)
    uint hallucination;  // ZHC_HALL_MODE_*
    uint bits;           // 2..8 bits per ratio (quantised layouts)
    uint sqrtEncoding;   // 1: sign-preserving square-root encoding of the ratios
    uint l2Bound;        // ZHC_L2_*
    uint dcFormat;       // ZHC_DC_*
    uint zonalMapping;   // ZHC_ZONAL_*
    uint axisMode;       // ZHC_AXIS_* (ZH3 / hallucination axis)
    uint kind;           // ZHC_KIND_*
    vec3 luminance;      // luminance weights of the shared axis (default Rec. 709 0.2126, 0.7152, 0.0722)
    vec2 curve;          // Eq. 21 a, b (codec defaults 0.6, 0.08; not stored in .zhp)
};

// The hub: SH3 RGB coefficients, c[i].rgb = coefficient i of the three channels.
struct ZhcSh3 {
    vec3 c[9];
};

// ---- constants ---------------------------------------------------------------------------------

const float ZHC_Y00 = 0.28209479177387814;   // 1 / (2 sqrt(pi))
const float ZHC_Y1 = 0.48860251190291992;    // sqrt(3 / 4pi)
const float ZHC_Y2 = 1.0925484305920792;     // sqrt(15 / 4pi)
const float ZHC_Y20 = 0.31539156525252005;   // sqrt(5 / 16pi)
const float ZHC_Y22 = 0.54627421529603959;   // sqrt(15 / 16pi)
const float ZHC_SQRT3 = 1.7320508075688772;
const float ZHC_SQRT5 = 2.2360679774997897;
const float ZHC_SQRT15 = 3.8729833462074169;
// cos / sin of 85 degrees: IrradZ keeps its direction at d_z >= cos(85 deg) (codec/lightmap/irradz.h).
const float ZHC_IRRADZ_MIN_DZ = 0.087155742747658166;
const float ZHC_IRRADZ_MAX_SIN = 0.99619469809174555;

// ---- bit-exact small-float unpacking (integer ops only) -----------------------------------------

// Non-finite test on the bits, immune to compilers that assume finite maths.
bool zhcIsFinite(float x) { return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u; }
bool zhcIsFinite3(vec3 v) { return zhcIsFinite(v.x) && zhcIsFinite(v.y) && zhcIsFinite(v.z); }

// 2^e as a float for e in [-126, 127], built from the exponent field (exact, no exp2()).
float zhcPow2(int e) { return uintBitsToFloat(uint(clamp(e, -126, 127) + 127) << 23); }

// Unsigned float with a 5-bit exponent (bias 15) and `mbits` mantissa bits (R11G11B10F channels:
// 6, 6, 5; binary16 magnitude: 10). e = 0: m 2^(-14 - mbits) (denormal, a normal float: exact);
// e = 31: +Inf (m = 0) or NaN; else the fields are moved into a binary32 (exact). ~6 int ops.
float zhcUnpackUfloat(uint code, uint mbits) {
    uint e = code >> mbits;
    uint m = code & ((1u << mbits) - 1u);
    if (e == 0u) return float(m) * zhcPow2(-14 - int(mbits));
    if (e == 31u) return uintBitsToFloat(m == 0u ? 0x7F800000u : 0x7FC00000u);
    return uintBitsToFloat(((e + 112u) << 23) | (m << (23u - mbits)));
}

// DXGI_FORMAT_R11G11B10_FLOAT: R bits 0-10, G 11-21, B 22-31. Bit-exact (codec unpack_r11g11b10f).
vec3 zhcUnpackR11G11B10F(uint w) {
    return vec3(zhcUnpackUfloat(w & 0x7FFu, 6u), zhcUnpackUfloat((w >> 11) & 0x7FFu, 6u),
                zhcUnpackUfloat(w >> 22, 5u));
}

// DXGI_FORMAT_R9G9B9E5_SHAREDEXP: mantissas at 0, 9, 18, exponent 27-31; m 2^(e - 24). The product
// of a 9-bit integer and a power of two >= 2^-24 is exact in binary32.
vec3 zhcUnpackRGB9E5(uint w) {
    float s = zhcPow2(int(w >> 27) - 24);
    return vec3(float(w & 0x1FFu), float((w >> 9) & 0x1FFu), float((w >> 18) & 0x1FFu)) * s;
}

// IEEE binary16 in the low 16 bits of h (denormals, Inf, NaN kept; unpackHalf2x16 may flush).
float zhcUnpackHalf(uint h) {
    float mag = zhcUnpackUfloat(h & 0x7FFFu, 10u);
    return (h & 0x8000u) != 0u ? -mag : mag;
}

// ---- SH evaluation --------------------------------------------------------------------------------

// Value at unit direction n of SH3 with per-band scales s (s = (1, 2/3, 1/4): irradiance from
// radiance; s = (1, 1, 1): the function itself). Basis as sh.h; 9 basis values (~12 flops) and
// 27 multiply-adds per RGB: ~45 flops.
vec3 zhcEvalSh3Scaled(ZhcSh3 sh, vec3 n, vec3 s) {
    float x = n.x, y = n.y, z = n.z;
    vec3 e = sh.c[0] * (s.x * ZHC_Y00);
    vec3 l1 = sh.c[1] * (-y) + sh.c[2] * z + sh.c[3] * (-x);
    vec3 l2 = sh.c[4] * (ZHC_Y2 * x * y) + sh.c[5] * (-ZHC_Y2 * y * z) +
              sh.c[6] * (ZHC_Y20 * (3.0 * z * z - 1.0)) + sh.c[7] * (-ZHC_Y2 * x * z) +
              sh.c[8] * (ZHC_Y22 * (x * x - y * y));
    return e + l1 * (s.y * ZHC_Y1) + l2 * s.z;
}

// Irradiance at unit normal n from SH3 radiance (codec irradiance(Sh3Radiance, n)).
vec3 zhcIrradianceSh3(ZhcSh3 radiance, vec3 n) {
    return zhcEvalSh3Scaled(radiance, n, vec3(1.0, 2.0 / 3.0, 0.25));
}

// Radiance of SH3 at direction d (no convolution).
vec3 zhcEvalSh3(ZhcSh3 sh, vec3 d) { return zhcEvalSh3Scaled(sh, d, vec3(1.0)); }

// Band scales that take the STORED coefficients to irradiance: radiance storage needs (1, 2/3,
// 1/4), irradiance storage is evaluated as it is.
vec3 zhcStoredToIrradianceScales(ZhcFormat f) {
    return f.kind == ZHC_KIND_IRRADIANCE ? vec3(1.0) : vec3(1.0, 2.0 / 3.0, 0.25);
}

// Stored SH -> radiance hub (codec to_radiance for irradiance storage: divide by 2/3, 1/4).
ZhcSh3 zhcStoredToRadiance(ZhcSh3 s, ZhcFormat f) {
    if (f.kind == ZHC_KIND_IRRADIANCE) {
        for (int i = 1; i < 4; ++i) s.c[i] *= 1.5;
        for (int i = 4; i < 9; ++i) s.c[i] *= 4.0;
    }
    return s;
}

ZhcSh3 zhcZeroSh3() {
    ZhcSh3 s;
    for (int i = 0; i < 9; ++i) s.c[i] = vec3(0.0);
    return s;
}

// ---- ZH3: zonal axes, expansion, evaluation (ZH3 paper Sec. 3, codec/probe/zh3.cpp) ----------------------

// The L1 band of channel k as a vector: v = (-f11, -f1-1, f10), f1(d) = Y1 v.d.
vec3 zhcL1Vector(ZhcSh3 s, int k) { return vec3(-s.c[3][k], -s.c[1][k], s.c[2][k]); }

// Unit vector along v; +Z when v is zero or not finite (codec normalize_or). v is first scaled by
// a power of two so that its largest component is in [1, 2): the squared length can then neither
// overflow nor underflow (the codec works in double). ~12 flops + inversesqrt.
vec3 zhcNormalizeOrZ(vec3 v) {
    if (!zhcIsFinite3(v)) return vec3(0.0, 0.0, 1.0);
    vec3 a = abs(v);
    float m = max(a.x, max(a.y, a.z));
    if (!(m > 0.0)) return vec3(0.0, 0.0, 1.0);
    int e;
    frexp(m, e);
    vec3 w = v * zhcPow2(1 - e);  // exact (power of two); m * 2^(1 - e) in [1, 2)
    return w * inversesqrt(dot(w, w));
}

// Zonal axis of each channel (codec Axes / zh3_axis): the shared axis is the optimal linear
// direction of the luminance-weighted L1, sum_k w_k v_k; per-channel axes are each channel's own.
// The nine components are scaled together by a power of two first (exact) so the weighted sum
// cannot overflow for any finite input. ~40 flops, one or three inversesqrt.
void zhcZonalAxes(ZhcSh3 s, ZhcFormat f, out vec3 axis[3]) {
    vec3 v0 = zhcL1Vector(s, 0), v1 = zhcL1Vector(s, 1), v2 = zhcL1Vector(s, 2);
    if (f.axisMode == ZHC_AXIS_PER_CHANNEL) {
        axis[0] = zhcNormalizeOrZ(v0);
        axis[1] = zhcNormalizeOrZ(v1);
        axis[2] = zhcNormalizeOrZ(v2);
        return;
    }
    vec3 lum = vec3(0.0, 0.0, 1.0);
    if (zhcIsFinite3(v0) && zhcIsFinite3(v1) && zhcIsFinite3(v2) && zhcIsFinite3(f.luminance)) {
        vec3 a = max(abs(v0), max(abs(v1), abs(v2)));
        float m = max(a.x, max(a.y, a.z));
        int e;
        frexp(m, e);
        float scale = m > 0.0 ? zhcPow2(1 - e) : 1.0;
        lum = zhcNormalizeOrZ(f.luminance.r * (v0 * scale) + f.luminance.g * (v1 * scale) +
                              f.luminance.b * (v2 * scale));
    }
    axis[0] = axis[1] = axis[2] = lum;
}

// ZH3 expansion (ZH3 paper Eq. 2 on a zonal function, codec zh3_expand): the L2 band of channel k
// is f20_k sqrt(4pi/5) Y2(a_k) = f20_k [sqrt3 xy, -sqrt3 yz, (3z^2 - 1)/2, -sqrt3 xz,
// sqrt3/2 (x^2 - y^2)], a_k = (x, y, z). Writes c[4..8] of s in place. ~30 flops.
void zhcExpandZonal(inout ZhcSh3 s, vec3 zonal, vec3 axis[3]) {
    for (int k = 0; k < 3; ++k) {
        vec3 a = axis[k];
        float f = zonal[k];
        s.c[4][k] = f * (ZHC_SQRT3 * a.x * a.y);
        s.c[5][k] = f * (-ZHC_SQRT3 * a.y * a.z);
        s.c[6][k] = f * (0.5 * (3.0 * a.z * a.z - 1.0));
        s.c[7][k] = f * (-ZHC_SQRT3 * a.x * a.z);
        s.c[8][k] = f * (0.5 * ZHC_SQRT3 * (a.x * a.x - a.y * a.y));
    }
}

// ZH3 irradiance straight from linear SH + zonal coefficients (ZH3 paper Listing 1, codec
// zh3_irradiance): E_k = Y00 c0 + s1 Y1 v_k.n + s2 Y20 f20_k (3 (a_k.n)^2 - 1), with s = band
// scales from stored to irradiance. ~30 flops per probe after the axes.
vec3 zhcIrradianceZh3(ZhcSh3 linear, vec3 zonal, vec3 axis[3], vec3 n, vec3 s) {
    vec3 l1 = linear.c[1] * (-n.y) + linear.c[2] * n.z + linear.c[3] * (-n.x);
    vec3 z = vec3(dot(axis[0], n), dot(axis[1], n), dot(axis[2], n));
    return linear.c[0] * (s.x * ZHC_Y00) + l1 * (s.y * ZHC_Y1) + zonal * (3.0 * z * z - 1.0) * (s.z * ZHC_Y20);
}

// Hallucinated zonal coefficients (ZH3 paper Sec. 3.4, codec hallucinate_zonal / zh3_hallucinate):
// f1_k = v_k . a_k (the L1 along the zonal axis), p = clamp(|f1| / f0, 0, sqrt3), f20 = (A p^2 +
// B p) f0 (Eq. 20: A = 2 sqrt5/3, B = -sqrt(5/3); Eq. 21: A, B = f.curve); Eq. 14: sqrt15/3 |f1|.
// f0 <= 0 or not finite gives 0 (Eq. 20/21). Below the clamp the same value is computed as
// (A p + B) |f1|: p * f0 would lose everything when p underflows binary32 (|f1| / f0 < 2^-126
// happens for probes with a tiny L1 next to a huge DC), |f1| itself never does.
// ~15 flops + 3 divisions.
vec3 zhcHallucinateZonal(ZhcSh3 linear, vec3 axis[3], ZhcFormat f) {
    vec3 zonal = vec3(0.0);
    vec2 ab = f.hallucination == ZHC_HALL_MODE_SPHERE ? vec2(2.0 * ZHC_SQRT5 / 3.0, -sqrt(5.0 / 3.0)) : f.curve;
    for (int k = 0; k < 3; ++k) {
        float f1 = abs(dot(zhcL1Vector(linear, k), axis[k]));
        float f0 = linear.c[0][k];
        if (f.hallucination == ZHC_HALL_MODE_AMBDIR) {
            zonal[k] = (ZHC_SQRT15 / 3.0) * f1;
        } else if (f.hallucination != ZHC_HALL_MODE_NONE && zhcIsFinite(f0) && f0 > 0.0) {
            float p = f1 / f0;  // >= 0, +Inf or NaN (NaN only from NaN inputs: stays NaN)
            zonal[k] = p >= ZHC_SQRT3 ? (ab.x * 3.0 + ab.y * ZHC_SQRT3) * f0 : (ab.x * p + ab.y) * f1;
        }
    }
    return zonal;
}

// ---- ratio quantisation (ZH3 paper App. A.1, Wiederien & Sloan Listing 1; codec RatioCoder) --------

// Ratio interval [lo, hi] of c_i / c_0 for SH index i (1..8) in the STORED domain: L1 +-sqrt3;
// zonal L2 [-sqrt5/2, sqrt5]; other L2 +-sqrt15/2 (tight) or +-sqrt5 (loose); times the band scale
// (2/3, 1/4) for irradiance storage.
vec2 zhcRatioInterval(int i, ZhcFormat f) {
    bool irr = f.kind == ZHC_KIND_IRRADIANCE;
    if (i < 4) {
        float b = ZHC_SQRT3 * (irr ? 2.0 / 3.0 : 1.0);
        return vec2(-b, b);
    }
    float s = irr ? 0.25 : 1.0;
    if (i == 6) return vec2(-0.5 * ZHC_SQRT5, ZHC_SQRT5) * s;
    float b = (f.l2Bound == ZHC_L2_LOOSE ? ZHC_SQRT5 : 0.5 * ZHC_SQRT15) * s;
    return vec2(-b, b);
}

// Code -> ratio: bv = 2^(bits-1) - 1, c = min(code, 2 bv), t = (c - bv) / bv in [-1, 1]; sqrt
// encoding squares it keeping the sign; then t is mapped onto the interval (affine for every
// non-zonal coefficient; the zonal one by f.zonalMapping). ~8 flops + 1 division.
float zhcDecodeRatio(uint code, vec2 iv, bool zonal, ZhcFormat f) {
    int bits = clamp(int(f.bits), 2, 8);
    int bv = (1 << (bits - 1)) - 1;
    int c = min(int(code & 0xFFu), 2 * bv);
    float t = float(c - bv) / float(bv);
    if (f.sqrtEncoding != 0u) t *= abs(t);
    if (!zonal || f.zonalMapping == ZHC_ZONAL_AFFINE) return 0.5 * (t * (iv.y - iv.x) + (iv.y + iv.x));
    if (f.zonalMapping == ZHC_ZONAL_ZERO_PRESERVING) return t >= 0.0 ? t * iv.y : t * -iv.x;
    return t * max(iv.y, -iv.x);
}

// Byte j (0..15) of a 16-byte probe.
uint zhcByte16(uvec4 w, int j) { return (w[clamp(j, 0, 15) >> 2] >> (8 * (j & 3))) & 0xFFu; }

// The DC triple of a packed probe: R11G11B10F or RGB9E5 in word 0; half (sh2_q only) in bytes 0..5.
vec3 zhcLoadDc(uvec4 w, bool sixByteSlot, ZhcFormat f) {
    if (f.dcFormat == ZHC_DC_RGB9E5) return zhcUnpackRGB9E5(w.x);
    if (f.dcFormat == ZHC_DC_HALF && sixByteSlot)
        return vec3(zhcUnpackHalf(w.x & 0xFFFFu), zhcUnpackHalf(w.x >> 16), zhcUnpackHalf(w.y & 0xFFFFu));
    return zhcUnpackR11G11B10F(w.x);
}

// ---- stored-domain decoders (coefficients as stored: radiance or irradiance SH) -----------------

// zh3_q16 bytes: [0,4) DC; byte 4 + 4k + j: channel k, j = 0..2 the L1 ratios (SH 1..3), j = 3 the
// zonal ratio. Returns the linear SH in `s` (c[4..8] zero) and the zonal coefficients.
void zhcLoadZh3Q16(uvec4 w, ZhcFormat f, out ZhcSh3 s, out vec3 zonal) {
    s = zhcZeroSh3();
    vec3 dc = zhcLoadDc(w, false, f);
    s.c[0] = dc;
    vec2 ivz = vec2(-0.5 * ZHC_SQRT5, ZHC_SQRT5) * (f.kind == ZHC_KIND_IRRADIANCE ? 0.25 : 1.0);
    for (int k = 0; k < 3; ++k) {
        for (int i = 1; i <= 3; ++i)
            s.c[i][k] = zhcDecodeRatio(zhcByte16(w, 4 + 4 * k + i - 1), zhcRatioInterval(i, f), false, f) * dc[k];
        zonal[k] = zhcDecodeRatio(zhcByte16(w, 4 + 4 * k + 3), ivz, true, f) * dc[k];
    }
}

// sh2_q bytes: [0,6) DC slot; byte 6 + 3k + (i - 1): channel k, SH index i = 1..3; byte 15 unused.
ZhcSh3 zhcLoadSh2Q(uvec4 w, ZhcFormat f) {
    ZhcSh3 s = zhcZeroSh3();
    vec3 dc = zhcLoadDc(w, true, f);
    s.c[0] = dc;
    for (int k = 0; k < 3; ++k)
        for (int i = 1; i <= 3; ++i)
            s.c[i][k] = zhcDecodeRatio(zhcByte16(w, 6 + 3 * k + i - 1), zhcRatioInterval(i, f), false, f) * dc[k];
    return s;
}

// sh3_q28 bytes: [0,4) DC; byte 4 + 8k + (i - 1): channel k, SH index i = 1..8.
ZhcSh3 zhcLoadSh3Q28(uint w[7], ZhcFormat f) {
    ZhcSh3 s;
    vec3 dc = f.dcFormat == ZHC_DC_RGB9E5 ? zhcUnpackRGB9E5(w[0]) : zhcUnpackR11G11B10F(w[0]);
    s.c[0] = dc;
    for (int k = 0; k < 3; ++k)
        for (int i = 1; i <= 8; ++i) {
            int j = 4 + 8 * k + i - 1;
            uint code = (w[clamp(j >> 2, 0, 6)] >> (8 * (j & 3))) & 0xFFu;
            s.c[i][k] = zhcDecodeRatio(code, zhcRatioInterval(i, f), i == 6, f) * dc[k];
        }
    return s;
}

// Float layouts: word 3 i + k is coefficient i of channel k (12 / 27 words); zh3 adds the three
// zonal coefficients in words 12..14.
ZhcSh3 zhcLoadSh3F32(uint w[27]) {
    ZhcSh3 s;
    for (int i = 0; i < 9; ++i) s.c[i] = uintBitsToFloat(uvec3(w[3 * i], w[3 * i + 1], w[3 * i + 2]));
    return s;
}
ZhcSh3 zhcLoadSh2F32(uint w[12]) {
    ZhcSh3 s = zhcZeroSh3();
    for (int i = 0; i < 4; ++i) s.c[i] = uintBitsToFloat(uvec3(w[3 * i], w[3 * i + 1], w[3 * i + 2]));
    return s;
}
void zhcLoadZh3F32(uint w[15], out ZhcSh3 s, out vec3 zonal) {
    s = zhcZeroSh3();
    for (int i = 0; i < 4; ++i) s.c[i] = uintBitsToFloat(uvec3(w[3 * i], w[3 * i + 1], w[3 * i + 2]));
    zonal = uintBitsToFloat(uvec3(w[12], w[13], w[14]));
}

// ---- public decoders: stored words -> SH3 radiance (codec decode_probe) ---------------------------

// sh3 / sh3_dering: 27 floats. Cost: 27 loads (+ 8 mul for irradiance storage).
ZhcSh3 zhcDecodeSh3F32(uint w[27], ZhcFormat f) { return zhcStoredToRadiance(zhcLoadSh3F32(w), f); }

// sh2 and hall_*: 12 floats; hall_* (f.hallucination != NONE) add the hallucinated zonal L2 on the
// axis of f.axisMode, in the stored domain. ~120 flops with hallucination.
ZhcSh3 zhcDecodeSh2F32(uint w[12], ZhcFormat f) {
    ZhcSh3 s = zhcLoadSh2F32(w);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        vec3 axis[3];
        zhcZonalAxes(s, f, axis);
        zhcExpandZonal(s, zhcHallucinateZonal(s, axis, f), axis);
    }
    return zhcStoredToRadiance(s, f);
}

// zh3_*: 15 floats (linear SH + zonal per channel), L2 expanded on the axes of f.axisMode. ~90 flops.
ZhcSh3 zhcDecodeZh3F32(uint w[15], ZhcFormat f) {
    ZhcSh3 s;
    vec3 zonal;
    zhcLoadZh3F32(w, s, zonal);
    vec3 axis[3];
    zhcZonalAxes(s, f, axis);
    zhcExpandZonal(s, zonal, axis);
    return zhcStoredToRadiance(s, f);
}

// zh3_q16 / zh3_solved_q16 (16 bytes). Axis from the DEQUANTISED L1 (as the codec). ~160 flops.
ZhcSh3 zhcDecodeZh3Q16(uvec4 w, ZhcFormat f) {
    ZhcSh3 s;
    vec3 zonal;
    zhcLoadZh3Q16(w, f, s, zonal);
    vec3 axis[3];
    zhcZonalAxes(s, f, axis);
    zhcExpandZonal(s, zonal, axis);
    return zhcStoredToRadiance(s, f);
}

// sh3_q28 (28 bytes = 7 words). 24 ratio decodes: ~250 flops.
ZhcSh3 zhcDecodeSh3Q28(uint w[7], ZhcFormat f) { return zhcStoredToRadiance(zhcLoadSh3Q28(w, f), f); }

// sh2_q and hall_curve_q (16 bytes). hall_curve_q hallucinates on the RADIANCE linear SH (codec
// hallucinate_curve after decode_packed), whatever the stored kind. ~100 / ~200 flops.
// hall_adaptive_q16's per-probe scale of the curve (byte 15), as plain Eq. 21 afterwards.
ZhcFormat zhcHallAdaptive(uvec4 w, ZhcFormat f) {
    if (f.hallucination == ZHC_HALL_MODE_CURVE_ADAPTIVE) {
        f.curve *= 0.5 * float(min(w.w >> 24u, 7u));
        f.hallucination = ZHC_HALL_MODE_CURVE;
    }
    return f;
}

ZhcSh3 zhcDecodeSh2Q(uvec4 w, ZhcFormat f) {
    f = zhcHallAdaptive(w, f);
    ZhcSh3 s = zhcStoredToRadiance(zhcLoadSh2Q(w, f), f);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        vec3 axis[3];
        zhcZonalAxes(s, f, axis);
        zhcExpandZonal(s, zhcHallucinateZonal(s, axis, f), axis);
    }
    return s;
}

// ---- public evaluators: irradiance at unit normal n straight from the stored words ------------------
// (codec Codec::irradiance for radiance storage; irradiance(decode_probe(...), n) in general).

vec3 zhcIrradianceSh3F32(uint w[27], ZhcFormat f, vec3 n) {
    return zhcEvalSh3Scaled(zhcLoadSh3F32(w), n, zhcStoredToIrradianceScales(f));
}

// sh2 (linear: ~20 flops) and hall_* (ZH3 evaluation with hallucinated zonal: ~90 flops; the L2
// band is never expanded).
vec3 zhcIrradianceSh2F32(uint w[12], ZhcFormat f, vec3 n) {
    ZhcSh3 s = zhcLoadSh2F32(w);
    vec3 zonal = vec3(0.0);
    vec3 axis[3];
    axis[0] = axis[1] = axis[2] = vec3(0.0, 0.0, 1.0);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        zhcZonalAxes(s, f, axis);
        zonal = zhcHallucinateZonal(s, axis, f);
    }
    return zhcIrradianceZh3(s, zonal, axis, n, zhcStoredToIrradianceScales(f));
}

// zh3_* (Listing 1): ~60 flops + the axes.
vec3 zhcIrradianceZh3F32(uint w[15], ZhcFormat f, vec3 n) {
    ZhcSh3 s;
    vec3 zonal;
    zhcLoadZh3F32(w, s, zonal);
    vec3 axis[3];
    zhcZonalAxes(s, f, axis);
    return zhcIrradianceZh3(s, zonal, axis, n, zhcStoredToIrradianceScales(f));
}

vec3 zhcIrradianceZh3Q16(uvec4 w, ZhcFormat f, vec3 n) {
    ZhcSh3 s;
    vec3 zonal;
    zhcLoadZh3Q16(w, f, s, zonal);
    vec3 axis[3];
    zhcZonalAxes(s, f, axis);
    return zhcIrradianceZh3(s, zonal, axis, n, zhcStoredToIrradianceScales(f));
}

vec3 zhcIrradianceSh3Q28(uint w[7], ZhcFormat f, vec3 n) {
    return zhcEvalSh3Scaled(zhcLoadSh3Q28(w, f), n, zhcStoredToIrradianceScales(f));
}

vec3 zhcIrradianceSh2Q(uvec4 w, ZhcFormat f, vec3 n) {
    f = zhcHallAdaptive(w, f);
    ZhcSh3 s = zhcStoredToRadiance(zhcLoadSh2Q(w, f), f);
    vec3 zonal = vec3(0.0);
    vec3 axis[3];
    axis[0] = axis[1] = axis[2] = vec3(0.0, 0.0, 1.0);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        zhcZonalAxes(s, f, axis);
        zonal = zhcHallucinateZonal(s, axis, f);
    }
    return zhcIrradianceZh3(s, zonal, axis, n, vec3(1.0, 2.0 / 3.0, 0.25));
}

// ---- one entry point for every layout (words of one probe in w[0 .. 26]) --------------------------

ZhcSh3 zhcDecode(uint w[27], ZhcFormat f) {
    if (f.family == ZHC_LAYOUT_SH3_F32) return zhcDecodeSh3F32(w, f);
    if (f.family == ZHC_LAYOUT_SH2_F32)
        return zhcDecodeSh2F32(uint[12](w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8], w[9], w[10], w[11]), f);
    if (f.family == ZHC_LAYOUT_ZH3_F32)
        return zhcDecodeZh3F32(uint[15](w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8], w[9], w[10], w[11],
                                        w[12], w[13], w[14]), f);
    if (f.family == ZHC_LAYOUT_ZH3_Q16) return zhcDecodeZh3Q16(uvec4(w[0], w[1], w[2], w[3]), f);
    if (f.family == ZHC_LAYOUT_SH3_Q28) return zhcDecodeSh3Q28(uint[7](w[0], w[1], w[2], w[3], w[4], w[5], w[6]), f);
    if (f.family == ZHC_LAYOUT_SH2_Q) return zhcDecodeSh2Q(uvec4(w[0], w[1], w[2], w[3]), f);
    return zhcZeroSh3();
}

vec3 zhcIrradiance(uint w[27], ZhcFormat f, vec3 n) {
    if (f.family == ZHC_LAYOUT_SH3_F32) return zhcIrradianceSh3F32(w, f, n);
    if (f.family == ZHC_LAYOUT_SH2_F32)
        return zhcIrradianceSh2F32(uint[12](w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8], w[9], w[10], w[11]),
                                   f, n);
    if (f.family == ZHC_LAYOUT_ZH3_F32)
        return zhcIrradianceZh3F32(uint[15](w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8], w[9], w[10], w[11],
                                            w[12], w[13], w[14]), f, n);
    if (f.family == ZHC_LAYOUT_ZH3_Q16) return zhcIrradianceZh3Q16(uvec4(w[0], w[1], w[2], w[3]), f, n);
    if (f.family == ZHC_LAYOUT_SH3_Q28)
        return zhcIrradianceSh3Q28(uint[7](w[0], w[1], w[2], w[3], w[4], w[5], w[6]), f, n);
    if (f.family == ZHC_LAYOUT_SH2_Q) return zhcIrradianceSh2Q(uvec4(w[0], w[1], w[2], w[3]), f, n);
    return vec3(0.0);
}

// ---- IrradZ lightmaps (codec/lightmap/irradz.h, codec/lightmap/lightmap.cpp, docs/irradz.md) --------------------------

const uint ZHC_IRRADZ_HHD = 0u;  // E(n) = C_a (1 + n_z) / 2 + C_d max(0, n.d)  (hemisphere + direction)
const uint ZHC_IRRADZ_AHD = 1u;  // E(n) = C_a + C_d max(0, n.d)                (ambient + direction)

// Hemi-octahedral direction from the two BC5 channels (UNORM, [0, 1]; codec decode_hemioct):
// a = 2u - 1, b = 2v - 1, p = ((a + b)/2, (a - b)/2), z = max(0, 1 - |px| - |py|), normalised.
// ~12 flops + inversesqrt.
vec3 zhcDecodeHemiOct(vec2 uv) {
    vec2 ab = 2.0 * clamp(uv, 0.0, 1.0) - 1.0;
    vec2 p = vec2(ab.x + ab.y, ab.x - ab.y) * 0.5;
    return zhcNormalizeOrZ(vec3(p, max(0.0, 1.0 - abs(p.x) - abs(p.y))));
}

// IrradZ texel -> irradiance at the tangent-space unit normal n (surface normal = +Z):
// d is kept at d_z >= cos 85 deg (same azimuth), w = clamp(w_a, 0, 1), C_a = w I_z,
// C_d = (1 - w) I_z / d_z (so E(+Z) = I_z exactly in the HHD model), then the model above.
// Inputs as sampled: iz = BC6H rgb, wa = BC4 red, dUv = BC5 rg. ~35 flops + 1 division.
vec3 zhcIrradZIrradiance(vec3 iz, float wa, vec2 dUv, vec3 n, uint model) {
    vec3 d = zhcDecodeHemiOct(dUv);
    if (!(d.z >= ZHC_IRRADZ_MIN_DZ)) {
        // Below 85 degrees: keep the azimuth (d.xy is not zero here since |d| = 1 and d.z < 0.09).
        vec2 h = d.xy * inversesqrt(dot(d.xy, d.xy));
        d = vec3(h * ZHC_IRRADZ_MAX_SIN, ZHC_IRRADZ_MIN_DZ);
    }
    float w = clamp(wa, 0.0, 1.0);
    vec3 ca = w * iz;
    vec3 cd = (1.0 - w) * iz / d.z;
    float h = model == ZHC_IRRADZ_HHD ? (1.0 + n.z) * 0.5 : 1.0;
    return ca * h + cd * max(0.0, dot(n, d));
}

// HLSH (probe occlusion, codec irradz::evaluate(Hlsh)): I(m) = I_z m_z + C_a (1 - m_z) + c_x m_x +
// c_y m_y, m in the frame of the normal. 12 flops.
vec3 zhcHlshIrradiance(vec3 iz, vec3 ca, vec3 cx, vec3 cy, vec3 m) {
    return iz * m.z + ca * (1.0 - m.z) + cx * m.x + cy * m.y;
}

// ---- probe volumes (docs/runtime.md "Probe volumes"; zhc_volume_* of runtime/zhc_runtime.h) --------
//
// A grid of probes: probe (x, y, z) is number x + nx (y + ny z) at origin + (x, y, z) * spacing,
// its stored words at (number * words per probe) in the application's buffer. The irradiance at a
// point blends the DECODED SH3 of the 8 probes of the cell containing it (the point clamped to the
// grid's box) with trilinear weights, then evaluates once: the trilinear blend of the 8 probes'
// irradiance (linearity). The stored words themselves must not be blended (ZH3's axis is per
// probe, the packed coefficients are ratios times the DC); hardware filtering of stored bytes is
// therefore wrong, and this does 8 fetches + decodes instead (probes of weight 0 are skipped).
//
// Binding: define ZHC_VOLUME_WORD(index) before including this file, as an expression giving the
// uint at word `index` of the probe words (the .zhp payload / glTF accessor bytes as-is), e.g.
//
//   layout(std430, binding = 0) readonly buffer ZhcProbes { uint zhcProbeWords[]; };
//   #define ZHC_VOLUME_WORD(i) zhcProbeWords[i]
//   #include "zhc.glsl"                  // (or pasted: GLSL has no #include)
//   uniform ZhcVolume uVolume;           // grid of the .zhp header / glTF "grid"
//   uniform ZhcFormat uFormat;
//   ...
//   vec3 e = zhcVolumeIrradiance(uVolume, uFormat, worldPosition, worldNormal);
//
// Without ZHC_VOLUME_WORD the volume functions are not compiled (ZhcVolume and zhcFamilyWords are).

struct ZhcVolume {
    vec3 origin;   // position of probe (0, 0, 0)
    vec3 spacing;  // > 0 (the application checks, as zhc_volume_init)
    uvec3 counts;  // >= 1 each
};

// Words per probe of a layout family (27, 12, 15, 4, 7, 4).
uint zhcFamilyWords(uint family) {
    if (family == ZHC_LAYOUT_SH3_F32) return 27u;
    if (family == ZHC_LAYOUT_SH2_F32) return 12u;
    if (family == ZHC_LAYOUT_ZH3_F32) return 15u;
    if (family == ZHC_LAYOUT_SH3_Q28) return 7u;
    return 4u;
}

#ifdef ZHC_VOLUME_WORD
// SH3 radiance of probe `probe` of the volume's buffer.
ZhcSh3 zhcVolumeProbe(uint probe, ZhcFormat f) {
    uint stride = zhcFamilyWords(f.family);
    uint w[27];
    for (uint k = 0u; k < 27u; ++k) w[k] = k < stride ? ZHC_VOLUME_WORD(probe * stride + k) : 0u;
    return zhcDecode(w, f);
}

// Blended SH3 radiance at p: t = clamp((p - origin) / spacing, 0, counts - 1) (NaN: 0), cell
// i0 = min(floor(t), counts - 2), weights prod (f or 1 - f), f = t - i0. ~8 x (fetch + decode +
// 27 fma) + 20 flops.
ZhcSh3 zhcVolumeSh3(ZhcVolume v, ZhcFormat f, vec3 p) {
    uvec3 n = max(v.counts, uvec3(1u));
    vec3 t = (p - v.origin) / v.spacing;
    t = mix(vec3(0.0), t, greaterThanEqual(t, vec3(0.0)));  // below the box, or NaN: 0 (a select)
    t = min(t, vec3(n - 1u));
    uvec3 i0 = min(uvec3(t), max(n, uvec3(2u)) - 2u);
    vec3 fr = t - vec3(i0);
    ZhcSh3 acc = zhcZeroSh3();
    for (uint c = 0u; c < 8u; ++c) {
        uvec3 b = uvec3(c & 1u, (c >> 1) & 1u, c >> 2);
        vec3 wv = mix(1.0 - fr, fr, notEqual(b, uvec3(0u)));
        float w = wv.x * wv.y * wv.z;
        if (w == 0.0) continue;
        uvec3 q = i0 + b;
        ZhcSh3 s = zhcVolumeProbe(q.x + n.x * (q.y + n.y * q.z), f);
        for (int i = 0; i < 9; ++i) acc.c[i] += w * s.c[i];
    }
    return acc;
}

// Irradiance (zhc's normalised kernel) at position p for the surface normal `normal` (normalised
// here; zero or not finite: +Z), both in the probe set's frame (zhc axes for a .zhp).
vec3 zhcVolumeIrradiance(ZhcVolume v, ZhcFormat f, vec3 p, vec3 normal) {
    return zhcIrradianceSh3(zhcVolumeSh3(v, f, p), zhcNormalizeOrZ(normal));
}
#endif
