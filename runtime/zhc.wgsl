// zhc/runtime/zhc.wgsl — WGSL decoders and evaluators for every stored zhc probe format, for WebGPU
// engines (Bevy, three.js WebGPURenderer, Babylon.js WebGPU, plain WebGPU). A module fragment to
// concatenate in front of the engine's own WGSL (WGSL has no #include): it declares only `const`s,
// structs and functions, no bindings and no entry points, so it works in any stage.
//
// Source of truth: the C++ codec, through the C header runtime/zhc_runtime.h and the GLSL port
// runtime/zhc.glsl, of which this file is a line-for-line translation (same functions, same order of
// operations, same comments on cost). tests/js/wgsl_test.mjs runs it in headless Chromium's WebGPU
// (Tint + SwiftShader, compute shader) on >= 100,000 probes per encoding plus random bytes and
// compares with runtime/web/zhc_runtime.mjs, which is bit-identical with the codec's float results.
//
// Selecting the encoding and its parameters. WGSL has no preprocessor; a probe set is described at
// run time by a `ZhcFormat` value (every field u32 / vec, so the struct can live in a uniform buffer
// as-is, or be built with a struct constructor from `override` constants or literals):
//
//   @group(0) @binding(0) var<uniform> uFormat: ZhcFormat;             // one per probe set
//   @group(0) @binding(1) var<storage, read> probes: array<vec4<u32>>;  // .zhp payload as-is
//   ...
//   let e = zhcIrradianceZh3Q16(probes[i], uFormat, worldNormal);
//
// A shader specialised to one encoding builds the format from constants (`const`, or `override`
// values set per pipeline through GPUProgrammableStage.constants); every branch on `f.family` /
// `f.hallucination` then folds away in the compiler:
//
//   override ZHC_BITS: u32 = 8u;
//   fn zhcMyFormat() -> ZhcFormat {
//       return ZhcFormat(ZHC_LAYOUT_ZH3_Q16, ZHC_HALL_MODE_NONE, ZHC_BITS, 0u, ZHC_L2_TIGHT, ZHC_DC_R11G11B10F,
//                        ZHC_ZONAL_AFFINE, ZHC_AXIS_LUMINANCE, ZHC_KIND_RADIANCE,
//                        vec3f(0.2126, 0.7152, 0.0722), vec2f(0.6, 0.08));
//   }
// (tests/js/browser/wgsl_kernel.wgsl compiles this example.)
//
// Decode to SH3 radiance first (to blend neighbouring probes, rotate, ...), then evaluate:
// irradiance is linear in the coefficients, so blending decoded probes is exact:
//
//   var a = zhcDecodeSh3Q28(wordsA, uFormat); let b = zhcDecodeSh3Q28(wordsB, uFormat);
//   for (var i = 0; i < 9; i++) { a.c[i] = mix(a.c[i], b.c[i], t); }
//   let e = zhcIrradianceSh3(a, worldNormal);
//
// Conventions (docs/conventions.md): SH index i = l(l+1)+m, [Y00, Y1-1, Y10, Y11, Y2-2, Y2-1,
// Y20, Y21, Y22]; Cartesian basis of the ZH3 paper (signs included); zhc's world frame is Z-up.
// Irradiance is E(n) = (1/pi) integral L(w) max(0, n.w) dw (constant radiance 1 -> irradiance 1),
// i.e. band scales 1, 2/3, 1/4 on the radiance SH.
//
// Upload: every probe is its stored bytes, little-endian, read as 32-bit words (byte j of the probe
// is bits 8 (j % 4) .. 8 (j % 4) + 7 of word j / 4). 16-byte layouts are one vec4<u32>, sh3_q28
// array<u32, 7>, the float layouts array<u32, 12 / 15 / 27> (bitcast<f32> of each word).
//
// WGSL specifics handled here: f32 only; no implicit conversions (every literal typed where it
// matters); non-finite tests on the bits (WGSL has no isnan/isinf and lets compilers assume finite
// maths); powers of two built from exponent bits (no exp2, no frexp); subnormals may be flushed by
// the implementation, so halves are unpacked with integer ops (not unpack2x16float) and the L1
// vectors that give the zonal axes are rescaled from their bits (zhcScaledComponent); arrays indexed dynamically only
// through `var` copies.
//
// Accuracy (tests/js/wgsl_test.mjs, Chromium 156 WebGPU on SwiftShader; metric and bounds of the
// GLSL test, docs/runtime.md): irradiance within 4 u S of the codec (u = 2^-24, S = the sum of the
// magnitudes of the evaluation's terms, quantised coefficients counted at their ratio bound times
// the DC), decoded coefficients within 3.4 u of theirs; random bytes within 4.5 u S and 3.3 u where
// the codec's result is finite. Probe volumes (zhc_volume.wgsl) within 5.6 u S of the C sampler.
//
// Robustness: every function is total. Garbage words give finite-or-NaN/Inf results, never a
// hang: there are no data-dependent loops; shifts and array indices are clamped.
//
// Cost notes count scalar float operations (mul/add/fma ~ 1, div / inverseSqrt ~ 4) per probe.

// ---- format description ------------------------------------------------------------------------

// The codec table's runtime description, generated from codec/probe/codec_table.cpp by
// tools/gen_runtime_tables.cpp (docs/runtime.md, "Generated tables"): layout families (how a
// probe's words are laid out), the zonal L2 hallucinated at decode, where the zonal axis comes
// from, every entry's id, the format's defaults, and zhcEncodingBytes / Family / Hallucination /
// Axis of an id. A format for encoding e: family zhcEncodingFamily(e), hallucination
// zhcEncodingHallucination(e), axisMode ZHC_AXIS_LUMINANCE / ZHC_AXIS_PER_CHANNEL when
// zhcEncodingAxis(e) is ZHC_ENTRY_AXIS_LUMINANCE / _CHANNEL, the header's axis mode when it is
// ZHC_ENTRY_AXIS_FORMAT. (sh3_f32 27 words, sh2_f32 12, zh3_f32 15, sh3_q28 seven u32, the
// other quantised layouts vec4<u32>.)
// BEGIN GENERATED by zhc_gen_tables from codec/probe/codec_table.cpp; do not edit (cmake --build build --target update_runtime_tables)
// Layout families: how a probe's words are laid out (codec/probe/runtime_table.h RuntimeLayout).
const ZHC_LAYOUT_SH3_F32: u32 = 0u;  // 27 floats
const ZHC_LAYOUT_SH2_F32: u32 = 1u;  // 12 floats: DC, L1
const ZHC_LAYOUT_ZH3_F32: u32 = 2u;  // 15 floats: DC, L1, zonal f20 per channel
const ZHC_LAYOUT_ZH3_Q16: u32 = 3u;  // 16 bytes: DC (4) + per channel [L1-1, L10, L11, zonal]
const ZHC_LAYOUT_SH3_Q28: u32 = 4u;  // 28 bytes: DC (4) + per channel [L1-1 .. L22]
const ZHC_LAYOUT_SH2_Q: u32 = 5u;  // 16 bytes: DC slot (6) + per channel [L1-1, L10, L11] + byte 15
// 32-bit words per probe of a layout family (0 for an unknown family).
fn zhcFamilyWords(family: u32) -> u32 {
    if (family == ZHC_LAYOUT_SH3_F32) { return 27u; }
    if (family == ZHC_LAYOUT_SH2_F32) { return 12u; }
    if (family == ZHC_LAYOUT_ZH3_F32) { return 15u; }
    if (family == ZHC_LAYOUT_ZH3_Q16) { return 4u; }
    if (family == ZHC_LAYOUT_SH3_Q28) { return 7u; }
    if (family == ZHC_LAYOUT_SH2_Q) { return 4u; }
    return 0u;
}
// Zonal L2 hallucinated at decode (ZH3 paper Sec. 3.4; codec zh3_hallucinate).
const ZHC_HALL_MODE_NONE: u32 = 0u;  // no hallucination (L2 stored or absent)
const ZHC_HALL_MODE_AMBDIR: u32 = 1u;  // Eq. 14: f20 = sqrt(15)/3 |f1|
const ZHC_HALL_MODE_SPHERE: u32 = 2u;  // Eq. 20: f20 = (2 sqrt(5)/3 p^2 - sqrt(5/3) p) f0
const ZHC_HALL_MODE_CURVE: u32 = 3u;  // Eq. 21: f20 = (a p^2 + b p) f0
const ZHC_HALL_MODE_CURVE_ADAPTIVE: u32 = 4u;  // Eq. 21 with a, b times s = 0.5 min(byte 15, 7) (sh2_q layout)
// Where an encoding's zonal axis comes from (luminance / channel: set axisMode to it).
const ZHC_ENTRY_AXIS_NONE: u32 = 0u;  // no zonal term
const ZHC_ENTRY_AXIS_LUMINANCE: u32 = 1u;  // the luminance-weighted L1 axis, fixed by the encoding
const ZHC_ENTRY_AXIS_CHANNEL: u32 = 2u;  // each channel's own L1 axis, fixed by the encoding
const ZHC_ENTRY_AXIS_FORMAT: u32 = 3u;  // the format's axis mode (.zhp header / glTF axisMode)
// Every codec table entry (zhc::codecs(); the id is the place in the table).
const ZHC_ENC_SH3: u32 = 0u;  // quadratic SH, 27 floats (the hub)
const ZHC_ENC_SH2: u32 = 1u;  // linear SH, 12 floats (L2 band dropped)
const ZHC_ENC_ZH3_LUM: u32 = 2u;  // ZH3 fit (Eq. 9/10) on the luminance L1 axis, 15 floats
const ZHC_ENC_ZH3_CHANNEL: u32 = 3u;  // ZH3 fit (Eq. 9/10) on each channel's L1 axis, 15 floats
const ZHC_ENC_ZH3_SOLVED_LUM: u32 = 4u;  // ZH3, luminance axis solved by BFGS (Eq. 11), 15 floats
const ZHC_ENC_ZH3_SOLVED_CHANNEL: u32 = 5u;  // ZH3, per-channel axes solved by BFGS (Eq. 11), 15 floats
const ZHC_ENC_HALL_AMBDIR: u32 = 6u;  // linear SH + zonal L2 hallucinated, ambient+directional (Eq. 14), luminance axis
const ZHC_ENC_HALL_SPHERE: u32 = 7u;  // linear SH + zonal L2 hallucinated, sphere light (Eq. 20), luminance axis
const ZHC_ENC_HALL_CURVE: u32 = 8u;  // linear SH + zonal L2 hallucinated, curve fit (Eq. 21), luminance axis
const ZHC_ENC_HALL_AMBDIR_CHANNEL: u32 = 9u;  // linear SH + zonal L2 hallucinated, ambient+directional (Eq. 14), channel axes
const ZHC_ENC_HALL_SPHERE_CHANNEL: u32 = 10u;  // linear SH + zonal L2 hallucinated, sphere light (Eq. 20), channel axes
const ZHC_ENC_HALL_CURVE_CHANNEL: u32 = 11u;  // linear SH + zonal L2 hallucinated, curve fit (Eq. 21), channel axes
const ZHC_ENC_ZH3_LUM_AXIS_CLAMP: u32 = 12u;  // zh3_lum with the zonal L2 clamped for irradiance >= 0 along the axis (App. B)
const ZHC_ENC_ZH3_LUM_SPHERE_CLAMP: u32 = 13u;  // zh3_lum, zonal L2 nearest to the fit with irradiance >= 0 on the whole sphere if one exists
const ZHC_ENC_SH3_DERING: u32 = 14u;  // quadratic SH windowed to non-negative irradiance (Sloan 2017), 27 floats
const ZHC_ENC_ZH3_Q16: u32 = 15u;  // ZH3 (luminance axis), 16 bytes: R11G11B10F DC + 8-bit L1/zonal ratios (App. A.1)
const ZHC_ENC_ZH3_SOLVED_Q16: u32 = 16u;  // zh3_q16 bytes; encoder quantises the BFGS-solved L1 (Eq. 11), zonal refitted
const ZHC_ENC_SH3_Q28: u32 = 17u;  // quadratic SH, 28 bytes: R11G11B10F DC + 24 8-bit ratios (tight L2 bound)
const ZHC_ENC_SH2_Q: u32 = 18u;  // linear SH, 16 bytes: DC slot + 9 8-bit L1 ratios (padded; hallucination decodes from it)
const ZHC_ENC_HALL_CURVE_Q: u32 = 19u;  // sh2_q bytes, zonal L2 hallucinated at decode by the Eq. 21 curve (luminance axis)
const ZHC_ENC_ZH3_DERING: u32 = 20u;  // zh3_lum with L1 and zonal windowed together: irradiance >= 0 on the whole sphere
const ZHC_ENC_ZH3_DERING_Q16: u32 = 21u;  // zh3_dering in zh3_q16 bytes; the decoded probe is checked and windowed further if needed
const ZHC_ENC_ZH3_CHANNEL_Q16: u32 = 22u;  // zh3_q16 bytes on per-channel axes (each from its decoded L1); zonal refitted
const ZHC_ENC_ZH3_SOLVED_CHANNEL_Q16: u32 = 23u;  // zh3_channel_q16 bytes; encoder searches the L1/zonal codes for the least decoded error (Eq. 11)
const ZHC_ENC_HALL_SOLVED: u32 = 24u;  // hall_curve's bytes and decoder; encoder solves the L1 for the error after hallucination
const ZHC_ENC_HALL_SOLVED_Q16: u32 = 25u;  // hall_curve_q's bytes and decoder; encoder solves the L1 (quantised, checked)
const ZHC_ENC_HALL_ADAPTIVE_Q16: u32 = 26u;  // sh2_q bytes + per-probe hallucination scale code (byte 15), L1 solved for it
const ZHC_ENCODING_COUNT: u32 = 27u;
// Defaults of the format (codec/probe/codec.h CodecOptions).
const ZHC_DEFAULT_BITS: u32 = 8u;
const ZHC_DEFAULT_SQRT_ENCODING: u32 = 0u;
const ZHC_DEFAULT_L2_BOUND: u32 = 0u;
const ZHC_DEFAULT_DC_FORMAT: u32 = 0u;
const ZHC_DEFAULT_KIND: u32 = 0u;
const ZHC_DEFAULT_ZONAL_MAPPING: u32 = 0u;
const ZHC_DEFAULT_AXIS_MODE: u32 = 0u;
const ZHC_DEFAULT_LUMINANCE: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);
const ZHC_DEFAULT_CURVE: vec2<f32> = vec2<f32>(0.6, 0.08);

// Row e of the table: bytes in bits 0-11, family 12-15, hallucination 16-19, axis 20-23; 0 out of range.
fn zhcEncodingRow(e: u32) -> u32 {
    var rows = array<u32, 27>(
        0x6cu,  // sh3
        0x1030u,  // sh2
        0x10203cu,  // zh3_lum
        0x20203cu,  // zh3_channel
        0x10203cu,  // zh3_solved_lum
        0x20203cu,  // zh3_solved_channel
        0x111030u,  // hall_ambdir
        0x121030u,  // hall_sphere
        0x131030u,  // hall_curve
        0x211030u,  // hall_ambdir_channel
        0x221030u,  // hall_sphere_channel
        0x231030u,  // hall_curve_channel
        0x10203cu,  // zh3_lum_axis_clamp
        0x10203cu,  // zh3_lum_sphere_clamp
        0x6cu,  // sh3_dering
        0x303010u,  // zh3_q16
        0x303010u,  // zh3_solved_q16
        0x401cu,  // sh3_q28
        0x5010u,  // sh2_q
        0x335010u,  // hall_curve_q
        0x10203cu,  // zh3_dering
        0x303010u,  // zh3_dering_q16
        0x203010u,  // zh3_channel_q16
        0x203010u,  // zh3_solved_channel_q16
        0x131030u,  // hall_solved
        0x335010u,  // hall_solved_q16
        0x345010u  // hall_adaptive_q16
    );
    return select(0u, rows[min(e, 26u)], e < ZHC_ENCODING_COUNT);
}
// Stored bytes per probe (0 for an unknown encoding), family, hallucination and axis of encoding e.
fn zhcEncodingBytes(e: u32) -> u32 { return zhcEncodingRow(e) & 0xFFFu; }
fn zhcEncodingFamily(e: u32) -> u32 { return (zhcEncodingRow(e) >> 12u) & 0xFu; }
fn zhcEncodingHallucination(e: u32) -> u32 { return (zhcEncodingRow(e) >> 16u) & 0xFu; }
fn zhcEncodingAxis(e: u32) -> u32 { return (zhcEncodingRow(e) >> 20u) & 0xFu; }
// END GENERATED by zhc_gen_tables

// .zhp header enums (codec/probe/quantize.h, same numeric values as the file).
const ZHC_DC_R11G11B10F: u32 = 0u;
const ZHC_DC_RGB9E5: u32 = 1u;
const ZHC_DC_HALF: u32 = 2u;  // sh2_q / hall_curve_q only (6-byte slot); elsewhere read as R11G11B10F
const ZHC_L2_TIGHT: u32 = 0u;  // non-zonal L2 ratio bound sqrt(15)/2 (Wiederien & Sloan)
const ZHC_L2_LOOSE: u32 = 1u;  // sqrt(5)
const ZHC_ZONAL_AFFINE: u32 = 0u;
const ZHC_ZONAL_ZERO_PRESERVING: u32 = 1u;
const ZHC_ZONAL_SYMMETRIC: u32 = 2u;
const ZHC_AXIS_LUMINANCE: u32 = 0u;
const ZHC_AXIS_PER_CHANNEL: u32 = 1u;
const ZHC_KIND_RADIANCE: u32 = 0u;
const ZHC_KIND_IRRADIANCE: u32 = 1u;  // stored SH are irradiance (band scales applied)

// Everything that gives stored words their meaning (the .zhp header fields plus the layout family
// and, for the hall_* entries, the hallucination model). Uniform-buffer layout: 9 u32 at offsets
// 0..32, luminance at 48 (vec3 alignment 16), curve at 64; 80 bytes.
struct ZhcFormat {
    family: u32,         // ZHC_LAYOUT_* (the layout family)
    hallucination: u32,  // ZHC_HALL_MODE_*
    bits: u32,           // 2..8 bits per ratio (quantised layouts)
    sqrtEncoding: u32,   // 1: sign-preserving square-root encoding of the ratios
    l2Bound: u32,        // ZHC_L2_*
    dcFormat: u32,       // ZHC_DC_*
    zonalMapping: u32,   // ZHC_ZONAL_*
    axisMode: u32,       // ZHC_AXIS_* (ZH3 / hallucination axis)
    kind: u32,           // ZHC_KIND_*
    luminance: vec3<f32>,  // luminance weights of the shared axis (default Rec. 709 0.2126, 0.7152, 0.0722)
    curve: vec2<f32>,      // Eq. 21 a, b (codec defaults 0.6, 0.08; not stored in .zhp)
}

// The hub: SH3 RGB coefficients, c[i] = coefficient i of the three channels.
struct ZhcSh3 {
    c: array<vec3<f32>, 9>,
}

// Linear SH (c[4..8] zero) plus the zonal L2 coefficient of each channel.
struct ZhcZh3 {
    linear: ZhcSh3,
    zonal: vec3<f32>,
}

// ---- constants ---------------------------------------------------------------------------------

const ZHC_Y00: f32 = 0.28209479177387814;   // 1 / (2 sqrt(pi))
const ZHC_Y1: f32 = 0.48860251190291992;    // sqrt(3 / 4pi)
const ZHC_Y2: f32 = 1.0925484305920792;     // sqrt(15 / 4pi)
const ZHC_Y20: f32 = 0.31539156525252005;   // sqrt(5 / 16pi)
const ZHC_Y22: f32 = 0.54627421529603959;   // sqrt(15 / 16pi)
const ZHC_SQRT3: f32 = 1.7320508075688772;
const ZHC_SQRT5: f32 = 2.2360679774997897;
const ZHC_SQRT15: f32 = 3.8729833462074169;
const ZHC_SQRT5_3: f32 = 1.2909944487358056;  // sqrt(5/3)

// ---- bit-exact small-float unpacking (integer ops only) -----------------------------------------

// Non-finite test on the bits, immune to compilers that assume finite maths.
fn zhcIsFinite(x: f32) -> bool { return (bitcast<u32>(x) & 0x7F800000u) != 0x7F800000u; }
fn zhcIsFinite3(v: vec3<f32>) -> bool { return zhcIsFinite(v.x) && zhcIsFinite(v.y) && zhcIsFinite(v.z); }

// 2^e as a float for e in [-126, 127], built from the exponent field (exact, no exp2()).
fn zhcPow2(e: i32) -> f32 { return bitcast<f32>(u32(clamp(e, -126, 127) + 127) << 23u); }

// Unsigned float with a 5-bit exponent (bias 15) and `mbits` mantissa bits (R11G11B10F channels:
// 6, 6, 5; binary16 magnitude: 10). e = 0: m 2^(-14 - mbits) (denormal, a normal float: exact);
// e = 31: +Inf (m = 0) or NaN; else the fields are moved into a binary32 (exact). ~6 int ops.
fn zhcUnpackUfloat(code: u32, mbits: u32) -> f32 {
    let e = code >> mbits;
    let m = code & ((1u << mbits) - 1u);
    if (e == 0u) { return f32(m) * zhcPow2(-14 - i32(mbits)); }
    if (e == 31u) { return bitcast<f32>(select(0x7FC00000u, 0x7F800000u, m == 0u)); }
    return bitcast<f32>(((e + 112u) << 23u) | (m << (23u - mbits)));
}

// DXGI_FORMAT_R11G11B10_FLOAT: R bits 0-10, G 11-21, B 22-31. Bit-exact (codec unpack_r11g11b10f).
fn zhcUnpackR11G11B10F(w: u32) -> vec3<f32> {
    return vec3<f32>(zhcUnpackUfloat(w & 0x7FFu, 6u), zhcUnpackUfloat((w >> 11u) & 0x7FFu, 6u),
                     zhcUnpackUfloat(w >> 22u, 5u));
}

// DXGI_FORMAT_R9G9B9E5_SHAREDEXP: mantissas at 0, 9, 18, exponent 27-31; m 2^(e - 24). The product
// of a 9-bit integer and a power of two >= 2^-24 is exact in binary32.
fn zhcUnpackRGB9E5(w: u32) -> vec3<f32> {
    let s = zhcPow2(i32(w >> 27u) - 24);
    return vec3<f32>(f32(w & 0x1FFu), f32((w >> 9u) & 0x1FFu), f32((w >> 18u) & 0x1FFu)) * s;
}

// IEEE binary16 in the low 16 bits of h (denormals, Inf, NaN kept; unpack2x16float may flush
// denormals to zero, so the magnitude goes through the integer path).
fn zhcUnpackHalf(h: u32) -> f32 {
    let mag = zhcUnpackUfloat(h & 0x7FFFu, 10u);
    return select(mag, -mag, (h & 0x8000u) != 0u);
}

// ---- SH evaluation --------------------------------------------------------------------------------

// Value at unit direction n of SH3 with per-band scales s (s = (1, 2/3, 1/4): irradiance from
// radiance; s = (1, 1, 1): the function itself). 9 basis values (~12 flops) and 27 multiply-adds
// per RGB: ~45 flops.
fn zhcEvalSh3Scaled(sh: ZhcSh3, n: vec3<f32>, s: vec3<f32>) -> vec3<f32> {
    let x = n.x;
    let y = n.y;
    let z = n.z;
    let e = sh.c[0] * (s.x * ZHC_Y00);
    let l1 = sh.c[1] * (-y) + sh.c[2] * z + sh.c[3] * (-x);
    let l2 = sh.c[4] * (ZHC_Y2 * x * y) + sh.c[5] * (-ZHC_Y2 * y * z) +
             sh.c[6] * (ZHC_Y20 * (3.0 * z * z - 1.0)) + sh.c[7] * (-ZHC_Y2 * x * z) +
             sh.c[8] * (ZHC_Y22 * (x * x - y * y));
    return e + l1 * (s.y * ZHC_Y1) + l2 * s.z;
}

// Irradiance at unit normal n from SH3 radiance (codec irradiance(Sh3Radiance, n)).
fn zhcIrradianceSh3(radiance: ZhcSh3, n: vec3<f32>) -> vec3<f32> {
    return zhcEvalSh3Scaled(radiance, n, vec3<f32>(1.0, 2.0 / 3.0, 0.25));
}

// Radiance of SH3 at direction d (no convolution).
fn zhcEvalSh3(sh: ZhcSh3, d: vec3<f32>) -> vec3<f32> { return zhcEvalSh3Scaled(sh, d, vec3<f32>(1.0)); }

// Band scales that take the STORED coefficients to irradiance: radiance storage needs (1, 2/3,
// 1/4), irradiance storage is evaluated as it is.
fn zhcStoredToIrradianceScales(f: ZhcFormat) -> vec3<f32> {
    return select(vec3<f32>(1.0, 2.0 / 3.0, 0.25), vec3<f32>(1.0), f.kind == ZHC_KIND_IRRADIANCE);
}

// Stored SH -> radiance hub (codec to_radiance for irradiance storage: multiply by 3/2, 4).
fn zhcStoredToRadiance(s: ZhcSh3, f: ZhcFormat) -> ZhcSh3 {
    var r = s;
    if (f.kind == ZHC_KIND_IRRADIANCE) {
        for (var i = 1; i < 4; i++) { r.c[i] = r.c[i] * 1.5; }
        for (var i = 4; i < 9; i++) { r.c[i] = r.c[i] * 4.0; }
    }
    return r;
}

fn zhcZeroSh3() -> ZhcSh3 { return ZhcSh3(array<vec3<f32>, 9>()); }

// ---- ZH3: zonal axes, expansion, evaluation (ZH3 paper Sec. 3, codec/probe/zh3.cpp) ----------------

// -x by flipping the sign bit: an arithmetic negation may flush a subnormal x to zero.
fn zhcNeg(x: f32) -> f32 { return bitcast<f32>(bitcast<u32>(x) ^ 0x80000000u); }

// The L1 band of channel k as a vector: v = (-f11, -f1-1, f10), f1(d) = Y1 v.d.
fn zhcL1Vector(s: ZhcSh3, k: i32) -> vec3<f32> { return vec3<f32>(zhcNeg(s.c[3][k]), zhcNeg(s.c[1][k]), s.c[2][k]); }

// Largest magnitude of v as the bit pattern of |component| (positive floats order like their bits).
fn zhcMaxMagnitudeBits(v: vec3<f32>) -> u32 {
    let b = bitcast<vec3<u32>>(v) & vec3<u32>(0x7FFFFFFFu);
    return max(b.x, max(b.y, b.z));
}

// x 2^e for e in [-252, 254] as two exact power-of-two multiplies (each factor in range).
fn zhcLdexp(x: f32, e: i32) -> f32 { return x * zhcPow2(e >> 1u) * zhcPow2(e - (e >> 1u)); }

// The exponent p of the magnitude with bit pattern mb > 0 (finite): |x| in [2^p, 2^(p+1)); subnormals
// from the position of their leading mantissa bit.
fn zhcExponentOfBits(mb: u32) -> i32 {
    let eb = i32(mb >> 23u);
    return select(eb - 127, i32(firstLeadingBit(mb)) - 149, eb == 0);
}

// x 2^s, exact whenever the result is a normal float, also for a subnormal x (rebuilt from its
// integer mantissa): WGSL lets implementations flush subnormal operands to zero (SwiftShader does),
// which would lose the tiny components of an L1 vector that the codec (double) keeps, and turn the
// axis of a tiny L1 into +Z. s in [-127, 149].
fn zhcScaledComponent(x: f32, s: i32) -> f32 {
    let b = bitcast<u32>(x);
    if ((b & 0x7F800000u) != 0u) { return zhcLdexp(x, s); }
    let r = zhcLdexp(f32(b & 0x007FFFFFu), max(s - 149, -252));
    return select(r, -r, (b & 0x80000000u) != 0u);
}
fn zhcScaled3(v: vec3<f32>, s: i32) -> vec3<f32> {
    return vec3<f32>(zhcScaledComponent(v.x, s), zhcScaledComponent(v.y, s), zhcScaledComponent(v.z, s));
}

// Unit vector along v; +Z when v is zero or not finite (codec normalize_or). v is first scaled by
// a power of two so that its largest component is in [1, 2) (exact, subnormal components
// included): the squared length can then neither overflow nor underflow (the codec works in
// double). ~12 flops + inverseSqrt.
fn zhcNormalizeOrZ(v: vec3<f32>) -> vec3<f32> {
    if (!zhcIsFinite3(v)) { return vec3<f32>(0.0, 0.0, 1.0); }
    let mb = zhcMaxMagnitudeBits(v);
    if (mb == 0u) { return vec3<f32>(0.0, 0.0, 1.0); }
    let w = zhcScaled3(v, -zhcExponentOfBits(mb));
    return w * inverseSqrt(dot(w, w));
}

// Zonal axis of each channel (codec Axes / zh3_axis): the shared axis is the optimal linear
// direction of the luminance-weighted L1, sum_k w_k v_k; per-channel axes are each channel's own.
// The nine components are scaled together by a power of two first (exact, as above) so the
// weighted sum can neither overflow nor lose subnormal components. ~40 flops, one or three
// inverseSqrt.
fn zhcZonalAxes(s: ZhcSh3, f: ZhcFormat) -> array<vec3<f32>, 3> {
    let v0 = zhcL1Vector(s, 0);
    let v1 = zhcL1Vector(s, 1);
    let v2 = zhcL1Vector(s, 2);
    if (f.axisMode == ZHC_AXIS_PER_CHANNEL) {
        return array<vec3<f32>, 3>(zhcNormalizeOrZ(v0), zhcNormalizeOrZ(v1), zhcNormalizeOrZ(v2));
    }
    var lum = vec3<f32>(0.0, 0.0, 1.0);
    if (zhcIsFinite3(v0) && zhcIsFinite3(v1) && zhcIsFinite3(v2) && zhcIsFinite3(f.luminance)) {
        let mb = max(zhcMaxMagnitudeBits(v0), max(zhcMaxMagnitudeBits(v1), zhcMaxMagnitudeBits(v2)));
        let e = select(0, -zhcExponentOfBits(mb), mb != 0u);
        lum = zhcNormalizeOrZ(f.luminance.r * zhcScaled3(v0, e) + f.luminance.g * zhcScaled3(v1, e) +
                              f.luminance.b * zhcScaled3(v2, e));
    }
    return array<vec3<f32>, 3>(lum, lum, lum);
}

// ZH3 expansion (ZH3 paper Eq. 2 on a zonal function, codec zh3_expand): the L2 band of channel k
// is f20_k sqrt(4pi/5) Y2(a_k) = f20_k [sqrt3 xy, -sqrt3 yz, (3z^2 - 1)/2, -sqrt3 xz,
// sqrt3/2 (x^2 - y^2)], a_k = (x, y, z). Returns s with c[4..8] replaced. ~30 flops.
fn zhcExpandZonal(s: ZhcSh3, zonal: vec3<f32>, axis: array<vec3<f32>, 3>) -> ZhcSh3 {
    var r = s;
    var ax = axis;
    for (var k = 0; k < 3; k++) {
        let a = ax[k];
        let f = zonal[k];
        r.c[4][k] = f * (ZHC_SQRT3 * a.x * a.y);
        r.c[5][k] = f * (-ZHC_SQRT3 * a.y * a.z);
        r.c[6][k] = f * (0.5 * (3.0 * a.z * a.z - 1.0));
        r.c[7][k] = f * (-ZHC_SQRT3 * a.x * a.z);
        r.c[8][k] = f * (0.5 * ZHC_SQRT3 * (a.x * a.x - a.y * a.y));
    }
    return r;
}

// ZH3 irradiance straight from linear SH + zonal coefficients (ZH3 paper Listing 1, codec
// zh3_irradiance): E_k = Y00 c0 + s1 Y1 v_k.n + s2 Y20 f20_k (3 (a_k.n)^2 - 1), with s = band
// scales from stored to irradiance. ~30 flops per probe after the axes.
fn zhcIrradianceZh3(linear: ZhcSh3, zonal: vec3<f32>, axis: array<vec3<f32>, 3>, n: vec3<f32>,
                    s: vec3<f32>) -> vec3<f32> {
    let l1 = linear.c[1] * (-n.y) + linear.c[2] * n.z + linear.c[3] * (-n.x);
    let z = vec3<f32>(dot(axis[0], n), dot(axis[1], n), dot(axis[2], n));
    return linear.c[0] * (s.x * ZHC_Y00) + l1 * (s.y * ZHC_Y1) + zonal * (3.0 * z * z - 1.0) * (s.z * ZHC_Y20);
}

// Hallucinated zonal coefficients (ZH3 paper Sec. 3.4, codec hallucinate_zonal / zh3_hallucinate):
// f1_k = v_k . a_k (the L1 along the zonal axis), p = clamp(|f1| / f0, 0, sqrt3), f20 = (A p^2 +
// B p) f0 (Eq. 20: A = 2 sqrt5/3, B = -sqrt(5/3); Eq. 21: A, B = f.curve); Eq. 14: sqrt15/3 |f1|.
// f0 <= 0 or not finite gives 0 (Eq. 20/21). Below the clamp the same value is computed as
// (A p + B) |f1|: p * f0 would lose everything when p underflows binary32, |f1| itself never does.
// ~15 flops + 3 divisions.
fn zhcHallucinateZonal(linear: ZhcSh3, axis: array<vec3<f32>, 3>, f: ZhcFormat) -> vec3<f32> {
    var zonal = vec3<f32>(0.0);
    var ax = axis;
    let ab = select(f.curve, vec2<f32>(2.0 * ZHC_SQRT5 / 3.0, -ZHC_SQRT5_3), f.hallucination == ZHC_HALL_MODE_SPHERE);
    for (var k = 0; k < 3; k++) {
        let f1 = abs(dot(zhcL1Vector(linear, k), ax[k]));
        let f0 = linear.c[0][k];
        if (f.hallucination == ZHC_HALL_MODE_AMBDIR) {
            zonal[k] = (ZHC_SQRT15 / 3.0) * f1;
        } else if (f.hallucination != ZHC_HALL_MODE_NONE && zhcIsFinite(f0) && f0 > 0.0) {
            let p = f1 / f0;  // >= 0, +Inf or NaN (NaN only from NaN inputs: stays NaN)
            zonal[k] = select((ab.x * p + ab.y) * f1, (ab.x * 3.0 + ab.y * ZHC_SQRT3) * f0, p >= ZHC_SQRT3);
        }
    }
    return zonal;
}

// ---- ratio quantisation (ZH3 paper App. A.1, Wiederien & Sloan Listing 1; codec RatioCoder) --------

// Ratio interval [lo, hi] of c_i / c_0 for SH index i (1..8) in the STORED domain: L1 +-sqrt3;
// zonal L2 [-sqrt5/2, sqrt5]; other L2 +-sqrt15/2 (tight) or +-sqrt5 (loose); times the band scale
// (2/3, 1/4) for irradiance storage.
fn zhcRatioInterval(i: i32, f: ZhcFormat) -> vec2<f32> {
    let irr = f.kind == ZHC_KIND_IRRADIANCE;
    if (i < 4) {
        let b = ZHC_SQRT3 * select(1.0, 2.0 / 3.0, irr);
        return vec2<f32>(-b, b);
    }
    let s = select(1.0, 0.25, irr);
    if (i == 6) { return vec2<f32>(-0.5 * ZHC_SQRT5, ZHC_SQRT5) * s; }
    let b = select(0.5 * ZHC_SQRT15, ZHC_SQRT5, f.l2Bound == ZHC_L2_LOOSE) * s;
    return vec2<f32>(-b, b);
}

// Code -> ratio: bv = 2^(bits-1) - 1, c = min(code, 2 bv), t = (c - bv) / bv in [-1, 1]; sqrt
// encoding squares it keeping the sign; then t is mapped onto the interval (affine for every
// non-zonal coefficient; the zonal one by f.zonalMapping). ~8 flops + 1 division.
fn zhcDecodeRatio(code: u32, iv: vec2<f32>, zonal: bool, f: ZhcFormat) -> f32 {
    let bits = clamp(i32(min(f.bits, 8u)), 2, 8);
    let bv = (1 << u32(bits - 1)) - 1;
    let c = min(i32(code & 0xFFu), 2 * bv);
    var t = f32(c - bv) / f32(bv);
    if (f.sqrtEncoding != 0u) { t = t * abs(t); }
    if (!zonal || f.zonalMapping == ZHC_ZONAL_AFFINE) { return 0.5 * (t * (iv.y - iv.x) + (iv.y + iv.x)); }
    if (f.zonalMapping == ZHC_ZONAL_ZERO_PRESERVING) { return select(t * -iv.x, t * iv.y, t >= 0.0); }
    return t * max(iv.y, -iv.x);
}

// Byte j (0..15) of a 16-byte probe.
fn zhcByte16(w: vec4<u32>, j: i32) -> u32 {
    let jj = clamp(j, 0, 15);
    return (w[jj >> 2u] >> (8u * u32(jj & 3))) & 0xFFu;
}

// The DC triple of a packed probe: R11G11B10F or RGB9E5 in word 0; half (sh2_q only) in bytes 0..5.
fn zhcLoadDc(w: vec4<u32>, sixByteSlot: bool, f: ZhcFormat) -> vec3<f32> {
    if (f.dcFormat == ZHC_DC_RGB9E5) { return zhcUnpackRGB9E5(w.x); }
    if (f.dcFormat == ZHC_DC_HALF && sixByteSlot) {
        return vec3<f32>(zhcUnpackHalf(w.x & 0xFFFFu), zhcUnpackHalf(w.x >> 16u), zhcUnpackHalf(w.y & 0xFFFFu));
    }
    return zhcUnpackR11G11B10F(w.x);
}

// ---- stored-domain decoders (coefficients as stored: radiance or irradiance SH) -----------------

// zh3_q16 bytes: [0,4) DC; byte 4 + 4k + j: channel k, j = 0..2 the L1 ratios (SH 1..3), j = 3 the
// zonal ratio. Returns the linear SH (c[4..8] zero) and the zonal coefficients.
fn zhcLoadZh3Q16(w: vec4<u32>, f: ZhcFormat) -> ZhcZh3 {
    var s = zhcZeroSh3();
    var zonal = vec3<f32>(0.0);
    let dc = zhcLoadDc(w, false, f);
    s.c[0] = dc;
    let ivz = vec2<f32>(-0.5 * ZHC_SQRT5, ZHC_SQRT5) * select(1.0, 0.25, f.kind == ZHC_KIND_IRRADIANCE);
    for (var k = 0; k < 3; k++) {
        for (var i = 1; i <= 3; i++) {
            s.c[i][k] = zhcDecodeRatio(zhcByte16(w, 4 + 4 * k + i - 1), zhcRatioInterval(i, f), false, f) * dc[k];
        }
        zonal[k] = zhcDecodeRatio(zhcByte16(w, 4 + 4 * k + 3), ivz, true, f) * dc[k];
    }
    return ZhcZh3(s, zonal);
}

// sh2_q bytes: [0,6) DC slot; byte 6 + 3k + (i - 1): channel k, SH index i = 1..3; byte 15 unused.
fn zhcLoadSh2Q(w: vec4<u32>, f: ZhcFormat) -> ZhcSh3 {
    var s = zhcZeroSh3();
    let dc = zhcLoadDc(w, true, f);
    s.c[0] = dc;
    for (var k = 0; k < 3; k++) {
        for (var i = 1; i <= 3; i++) {
            s.c[i][k] = zhcDecodeRatio(zhcByte16(w, 6 + 3 * k + i - 1), zhcRatioInterval(i, f), false, f) * dc[k];
        }
    }
    return s;
}

// sh3_q28 bytes: [0,4) DC; byte 4 + 8k + (i - 1): channel k, SH index i = 1..8.
fn zhcLoadSh3Q28(words: array<u32, 7>, f: ZhcFormat) -> ZhcSh3 {
    var w = words;
    var s = zhcZeroSh3();
    let dc = select(zhcUnpackR11G11B10F(w[0]), zhcUnpackRGB9E5(w[0]), f.dcFormat == ZHC_DC_RGB9E5);
    s.c[0] = dc;
    for (var k = 0; k < 3; k++) {
        for (var i = 1; i <= 8; i++) {
            let j = 4 + 8 * k + i - 1;
            let code = (w[clamp(j >> 2u, 0, 6)] >> (8u * u32(j & 3))) & 0xFFu;
            s.c[i][k] = zhcDecodeRatio(code, zhcRatioInterval(i, f), i == 6, f) * dc[k];
        }
    }
    return s;
}

// Float layouts: word 3 i + k is coefficient i of channel k (12 / 27 words); zh3 adds the three
// zonal coefficients in words 12..14.
fn zhcLoadSh3F32(words: array<u32, 27>) -> ZhcSh3 {
    var w = words;
    var s = zhcZeroSh3();
    for (var i = 0; i < 9; i++) { s.c[i] = bitcast<vec3<f32>>(vec3<u32>(w[3 * i], w[3 * i + 1], w[3 * i + 2])); }
    return s;
}
fn zhcLoadSh2F32(words: array<u32, 12>) -> ZhcSh3 {
    var w = words;
    var s = zhcZeroSh3();
    for (var i = 0; i < 4; i++) { s.c[i] = bitcast<vec3<f32>>(vec3<u32>(w[3 * i], w[3 * i + 1], w[3 * i + 2])); }
    return s;
}
fn zhcLoadZh3F32(words: array<u32, 15>) -> ZhcZh3 {
    var w = words;
    var s = zhcZeroSh3();
    for (var i = 0; i < 4; i++) { s.c[i] = bitcast<vec3<f32>>(vec3<u32>(w[3 * i], w[3 * i + 1], w[3 * i + 2])); }
    return ZhcZh3(s, bitcast<vec3<f32>>(vec3<u32>(w[12], w[13], w[14])));
}

// ---- public decoders: stored words -> SH3 radiance (codec decode_probe) ---------------------------

// sh3 / sh3_dering: 27 floats. Cost: 27 loads (+ 8 mul for irradiance storage).
fn zhcDecodeSh3F32(w: array<u32, 27>, f: ZhcFormat) -> ZhcSh3 { return zhcStoredToRadiance(zhcLoadSh3F32(w), f); }

// sh2 and hall_*: 12 floats; hall_* (f.hallucination != NONE) add the hallucinated zonal L2 on the
// axis of f.axisMode, in the stored domain. ~120 flops with hallucination.
fn zhcDecodeSh2F32(w: array<u32, 12>, f: ZhcFormat) -> ZhcSh3 {
    var s = zhcLoadSh2F32(w);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        let axis = zhcZonalAxes(s, f);
        s = zhcExpandZonal(s, zhcHallucinateZonal(s, axis, f), axis);
    }
    return zhcStoredToRadiance(s, f);
}

// zh3_*: 15 floats (linear SH + zonal per channel), L2 expanded on the axes of f.axisMode. ~90 flops.
fn zhcDecodeZh3F32(w: array<u32, 15>, f: ZhcFormat) -> ZhcSh3 {
    let z = zhcLoadZh3F32(w);
    return zhcStoredToRadiance(zhcExpandZonal(z.linear, z.zonal, zhcZonalAxes(z.linear, f)), f);
}

// zh3_q16 / zh3_solved_q16 (16 bytes). Axis from the DEQUANTISED L1 (as the codec). ~160 flops.
fn zhcDecodeZh3Q16(w: vec4<u32>, f: ZhcFormat) -> ZhcSh3 {
    let z = zhcLoadZh3Q16(w, f);
    return zhcStoredToRadiance(zhcExpandZonal(z.linear, z.zonal, zhcZonalAxes(z.linear, f)), f);
}

// sh3_q28 (28 bytes = 7 words). 24 ratio decodes: ~250 flops.
fn zhcDecodeSh3Q28(w: array<u32, 7>, f: ZhcFormat) -> ZhcSh3 { return zhcStoredToRadiance(zhcLoadSh3Q28(w, f), f); }

// hall_adaptive_q16's per-probe scale of the curve (byte 15), as plain Eq. 21 afterwards.
fn zhcHallAdaptive(w: vec4<u32>, f: ZhcFormat) -> ZhcFormat {
    var g = f;
    if (f.hallucination == ZHC_HALL_MODE_CURVE_ADAPTIVE) {
        g.curve = g.curve * (0.5 * f32(min(w.w >> 24u, 7u)));
        g.hallucination = ZHC_HALL_MODE_CURVE;
    }
    return g;
}

// sh2_q and hall_curve_q (16 bytes). hall_curve_q hallucinates on the RADIANCE linear SH (codec
// hallucinate_curve after decode_packed), whatever the stored kind. ~100 / ~200 flops.
fn zhcDecodeSh2Q(w: vec4<u32>, format: ZhcFormat) -> ZhcSh3 {
    let f = zhcHallAdaptive(w, format);
    var s = zhcStoredToRadiance(zhcLoadSh2Q(w, f), f);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        let axis = zhcZonalAxes(s, f);
        s = zhcExpandZonal(s, zhcHallucinateZonal(s, axis, f), axis);
    }
    return s;
}

// ---- public evaluators: irradiance at unit normal n straight from the stored words ------------------
// (codec Codec::irradiance for radiance storage; irradiance(decode_probe(...), n) in general).

fn zhcIrradianceSh3F32(w: array<u32, 27>, f: ZhcFormat, n: vec3<f32>) -> vec3<f32> {
    return zhcEvalSh3Scaled(zhcLoadSh3F32(w), n, zhcStoredToIrradianceScales(f));
}

// sh2 (linear: ~20 flops) and hall_* (ZH3 evaluation with hallucinated zonal: ~90 flops; the L2
// band is never expanded).
fn zhcIrradianceSh2F32(w: array<u32, 12>, f: ZhcFormat, n: vec3<f32>) -> vec3<f32> {
    let s = zhcLoadSh2F32(w);
    var zonal = vec3<f32>(0.0);
    let up = vec3<f32>(0.0, 0.0, 1.0);
    var axis = array<vec3<f32>, 3>(up, up, up);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        axis = zhcZonalAxes(s, f);
        zonal = zhcHallucinateZonal(s, axis, f);
    }
    return zhcIrradianceZh3(s, zonal, axis, n, zhcStoredToIrradianceScales(f));
}

// zh3_* (Listing 1): ~60 flops + the axes.
fn zhcIrradianceZh3F32(w: array<u32, 15>, f: ZhcFormat, n: vec3<f32>) -> vec3<f32> {
    let z = zhcLoadZh3F32(w);
    return zhcIrradianceZh3(z.linear, z.zonal, zhcZonalAxes(z.linear, f), n, zhcStoredToIrradianceScales(f));
}

fn zhcIrradianceZh3Q16(w: vec4<u32>, f: ZhcFormat, n: vec3<f32>) -> vec3<f32> {
    let z = zhcLoadZh3Q16(w, f);
    return zhcIrradianceZh3(z.linear, z.zonal, zhcZonalAxes(z.linear, f), n, zhcStoredToIrradianceScales(f));
}

fn zhcIrradianceSh3Q28(w: array<u32, 7>, f: ZhcFormat, n: vec3<f32>) -> vec3<f32> {
    return zhcEvalSh3Scaled(zhcLoadSh3Q28(w, f), n, zhcStoredToIrradianceScales(f));
}

fn zhcIrradianceSh2Q(w: vec4<u32>, format: ZhcFormat, n: vec3<f32>) -> vec3<f32> {
    let f = zhcHallAdaptive(w, format);
    let s = zhcStoredToRadiance(zhcLoadSh2Q(w, f), f);
    var zonal = vec3<f32>(0.0);
    let up = vec3<f32>(0.0, 0.0, 1.0);
    var axis = array<vec3<f32>, 3>(up, up, up);
    if (f.hallucination != ZHC_HALL_MODE_NONE) {
        axis = zhcZonalAxes(s, f);
        zonal = zhcHallucinateZonal(s, axis, f);
    }
    return zhcIrradianceZh3(s, zonal, axis, n, vec3<f32>(1.0, 2.0 / 3.0, 0.25));
}

// ---- one entry point for every layout (words of one probe in w[0 .. 26]) --------------------------

fn zhcWords12(w: array<u32, 27>) -> array<u32, 12> {
    return array<u32, 12>(w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8], w[9], w[10], w[11]);
}
fn zhcWords15(w: array<u32, 27>) -> array<u32, 15> {
    return array<u32, 15>(w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8], w[9], w[10], w[11], w[12], w[13], w[14]);
}
fn zhcWords7(w: array<u32, 27>) -> array<u32, 7> { return array<u32, 7>(w[0], w[1], w[2], w[3], w[4], w[5], w[6]); }

fn zhcDecode(w: array<u32, 27>, f: ZhcFormat) -> ZhcSh3 {
    if (f.family == ZHC_LAYOUT_SH3_F32) { return zhcDecodeSh3F32(w, f); }
    if (f.family == ZHC_LAYOUT_SH2_F32) { return zhcDecodeSh2F32(zhcWords12(w), f); }
    if (f.family == ZHC_LAYOUT_ZH3_F32) { return zhcDecodeZh3F32(zhcWords15(w), f); }
    if (f.family == ZHC_LAYOUT_ZH3_Q16) { return zhcDecodeZh3Q16(vec4<u32>(w[0], w[1], w[2], w[3]), f); }
    if (f.family == ZHC_LAYOUT_SH3_Q28) { return zhcDecodeSh3Q28(zhcWords7(w), f); }
    if (f.family == ZHC_LAYOUT_SH2_Q) { return zhcDecodeSh2Q(vec4<u32>(w[0], w[1], w[2], w[3]), f); }
    return zhcZeroSh3();
}

fn zhcIrradiance(w: array<u32, 27>, f: ZhcFormat, n: vec3<f32>) -> vec3<f32> {
    if (f.family == ZHC_LAYOUT_SH3_F32) { return zhcIrradianceSh3F32(w, f, n); }
    if (f.family == ZHC_LAYOUT_SH2_F32) { return zhcIrradianceSh2F32(zhcWords12(w), f, n); }
    if (f.family == ZHC_LAYOUT_ZH3_F32) { return zhcIrradianceZh3F32(zhcWords15(w), f, n); }
    if (f.family == ZHC_LAYOUT_ZH3_Q16) { return zhcIrradianceZh3Q16(vec4<u32>(w[0], w[1], w[2], w[3]), f, n); }
    if (f.family == ZHC_LAYOUT_SH3_Q28) { return zhcIrradianceSh3Q28(zhcWords7(w), f, n); }
    if (f.family == ZHC_LAYOUT_SH2_Q) { return zhcIrradianceSh2Q(vec4<u32>(w[0], w[1], w[2], w[3]), f, n); }
    return vec3<f32>(0.0);
}

// ---- IrradZ lightmaps (codec/lightmap/irradz.h, codec/lightmap/lightmap.cpp, docs/irradz.md) ----------
// The sampled texture values -> irradiance at the tangent-space unit normal n (surface normal +Z),
// as zhcIrradZIrradiance of zhc.glsl. BC: iz = BC6H rgb, wa = BC4 r, dUv = BC5 rg. ASTC targets
// (docs/lightmap-formats.md "ASTC targets"): iz = the ASTC HDR texture's rgb, or for the LDR fallback
// zhcIrradZIzFromLdr(its rgb, vec2(lo, hi)) with the KTX2 key "zhc.iz_log2_range"; dwa = the
// (u, v, w_a) texture's rgb.
const ZHC_IRRADZ_HHD: u32 = 0u;  // E(n) = C_a (1 + n_z) / 2 + C_d max(0, n.d)
const ZHC_IRRADZ_AHD: u32 = 1u;  // E(n) = C_a + C_d max(0, n.d)
const ZHC_IRRADZ_MIN_DZ: f32 = 0.087155742747658166;  // cos 85 deg
const ZHC_IRRADZ_MAX_SIN: f32 = 0.99619469809174555;  // sin 85 deg

// Hemi-octahedral (u, v) -> unit direction with z >= 0 (codec decode_hemioct).
fn zhcDecodeHemiOct(uv: vec2<f32>) -> vec3<f32> {
    let ab = 2.0 * clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0)) - 1.0;
    let p = vec2<f32>(ab.x + ab.y, ab.x - ab.y) * 0.5;
    return zhcNormalizeOrZ(vec3<f32>(p, max(0.0, 1.0 - abs(p.x) - abs(p.y))));
}

fn zhcIrradZIrradiance(iz: vec3<f32>, wa: f32, dUv: vec2<f32>, n: vec3<f32>, model: u32) -> vec3<f32> {
    var d = zhcDecodeHemiOct(dUv);
    if (!(d.z >= ZHC_IRRADZ_MIN_DZ)) {
        // Below 85 degrees: keep the azimuth (d.xy is not zero: |d| = 1 and d.z < 0.09).
        let h = d.xy * inverseSqrt(dot(d.xy, d.xy));
        d = vec3<f32>(h * ZHC_IRRADZ_MAX_SIN, ZHC_IRRADZ_MIN_DZ);
    }
    let w = clamp(wa, 0.0, 1.0);
    let ca = w * iz;
    let cd = (1.0 - w) * iz / d.z;
    var h = 1.0;
    if (model == ZHC_IRRADZ_HHD) { h = (1.0 + n.z) * 0.5; }
    return ca * h + cd * max(0.0, dot(n, d));
}

// The ASTC LDR fallback: I_z = 2^(lo + t (hi - lo)) - 2^lo per channel (codec iz_from_ldr).
fn zhcIrradZIzFromLdr(t: vec3<f32>, loHi: vec2<f32>) -> vec3<f32> {
    let x = loHi.x + clamp(t, vec3<f32>(0.0), vec3<f32>(1.0)) * (loHi.y - loHi.x);
    return exp2(x) - exp2(loHi.x);
}

fn zhcIrradZIrradianceAstc(iz: vec3<f32>, dwa: vec3<f32>, n: vec3<f32>, model: u32) -> vec3<f32> {
    return zhcIrradZIrradiance(iz, dwa.z, dwa.xy, n, model);
}
