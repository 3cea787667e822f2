// GLSL ES 3.00 (WebGL2, three.js ShaderMaterial / RawShaderMaterial with glslVersion GLSL3) chunk
// that evaluates zhc probe irradiance in a shader:
//
//   vec3 zhcIrradianceZh3Q16(uvec4 words, vec3 n)   zh3_q16 / zh3_solved_q16 probe, 16 bytes as four
//                                                   little-endian uint32 words (zh3Q16Words below)
//   vec3 zhcIrradianceSh3Q28(uvec4 w0, uvec4 w1, vec3 n)  sh3_q28 probe: 28 bytes = w0 and w1.xyz
//   vec3 zhcIrradianceSh2Q(uvec4 words, vec3 n)     sh2_q probe (16 bytes)
//   vec3 zhcIrradianceHallCurveQ(uvec4 words, vec3 n)  hall_curve_q (sh2_q bytes + Eq. 21 zonal)
//   vec3 zhcIrradianceSh3(vec3 c[9], vec3 n)        float SH3 radiance, zhc's basis (index l(l+1)+m)
//   vec3 zhcIrradianceSh3Irr(vec3 c[9], vec3 n)     float SH3 that already holds irradiance
//   vec3 zhcDirFromGltf(vec3 d)                     glTF / three.js direction -> zhc axes (d.zxy), for
//                                                   volumes with shAxes "zhc" (what zhc writes)
//
// n is a unit normal in the axes of the coefficients. The result is zhc's normalised irradiance
// (constant radiance 1 gives 1): multiply by the albedo for the diffuse exit radiance; three.js's
// own irradiance convention (SphericalHarmonics3.getIrradianceAt, getLightProbeIrradiance) is pi
// times this.
//
// The quantisation parameters of the volume (its glTF `quantization` object, `kind` and
// `luminanceWeights`) are compiled in as #defines/constants: zhcIrradianceGlsl(params) returns the
// chunk for a volume's params (a ZhcProbeVolume's `params`, or zhc_runtime.mjs makeParams(...));
// ZHC_IRRADIANCE_GLSL is the chunk for the defaults (8 bits, no sqrt, R11G11B10F DC, affine zonal
// mapping, luminance axis, Rec. 709 weights, radiance).
//
// Precision: the shader decodes exactly (bit manipulation, no exp2/pow) but evaluates in float32,
// so it agrees with zhc's double-then-float path to a few float ulps of the probe's DC term
// (tests/js/browser_test.mjs measures it).

const fmt = (x) => {
  // A GLSL float literal that rounds (to float32) to the same value as the double x.
  let s = Math.fround(x).toPrecision(9);
  if (!/[.e]/.test(s)) s += '.0';
  return s;
};

export function zhcIrradianceGlsl(params = {}) {
  const p = {
    bits: 8, sqrt: false, dcFormat: 'r11g11b10f', zonalMapping: 'affine', axisMode: 'luminance', kind: 'radiance',
    luminanceWeights: [0.2126, 0.7152, 0.0722], ...params,
  };
  if (!Number.isInteger(p.bits) || p.bits < 2 || p.bits > 8) throw new Error('zhcIrradianceGlsl: bits must be 2..8');
  if (!['r11g11b10f', 'rgb9e5', 'half'].includes(p.dcFormat)) throw new Error('zhcIrradianceGlsl: dcFormat must be r11g11b10f, rgb9e5 or half');
  if (p.l2Bound !== undefined && p.l2Bound !== 'tight' && p.l2Bound !== 'loose') throw new Error('zhcIrradianceGlsl: l2Bound must be tight or loose');
  const w = p.luminanceWeights ?? [0.2126, 0.7152, 0.0722];
  const irr = p.kind === 'irradiance';
  // Ratio intervals (docs/quantization.md): L1 +-sqrt(3) s1, zonal [-sqrt(5)/2, sqrt(5)] s2, with the
  // irradiance band scales s1 = 2/3, s2 = 1/4 for stored irradiance.
  const s1 = irr ? 2.0 / 3.0 : 1.0, s2 = irr ? 1.0 / 4.0 : 1.0;
  const l1Hi = Math.sqrt(3.0) * s1, zLo = (-Math.sqrt(5.0) / 2.0) * s2, zHi = Math.sqrt(5.0) * s2;
  const l2Hi = (p.l2Bound === 'loose' ? Math.sqrt(5.0) : Math.sqrt(15.0) / 2.0) * s2;
  const kY00 = 1.0 / (2.0 * Math.sqrt(Math.PI)), kY1 = Math.sqrt(3.0 / (4.0 * Math.PI)), kY2 = Math.sqrt(15.0 / (4.0 * Math.PI));
  const kY20 = Math.sqrt(5.0 / (16.0 * Math.PI)), kY22 = Math.sqrt(15.0 / (16.0 * Math.PI));
  const zonal = { affine: 0, zero: 1, symmetric: 2 }[p.zonalMapping];
  if (zonal === undefined) throw new Error('zhcIrradianceGlsl: zonalMapping must be affine, zero or symmetric');
  return `// ---- zhc irradiance (runtime/web/zhc_irradiance.glsl.mjs) ----
#define ZHC_BITS ${p.bits}
#define ZHC_SQRT ${p.sqrt ? 1 : 0}
#define ZHC_DC_RGB9E5 ${p.dcFormat === 'rgb9e5' ? 1 : 0}
#define ZHC_DC_HALF ${p.dcFormat === 'half' ? 1 : 0}
#define ZHC_ZONAL_MAPPING ${zonal}
#define ZHC_AXIS_CHANNEL ${p.axisMode === 'channel' ? 1 : 0}
#define ZHC_STORED_IRRADIANCE ${irr ? 1 : 0}
const vec3 ZHC_LUMINANCE = vec3(${w.map(fmt).join(', ')});
const float ZHC_L1_HI = ${fmt(l1Hi)};
const float ZHC_ZONAL_LO = ${fmt(zLo)};
const float ZHC_ZONAL_HI = ${fmt(zHi)};
const float ZHC_L2_HI = ${fmt(l2Hi)};
const float ZHC_CURVE_A = ${fmt(p.curveA ?? 0.6)};
const float ZHC_CURVE_B = ${fmt(p.curveB ?? 0.08)};
const float ZHC_Y00 = ${fmt(kY00)};
const float ZHC_Y1 = ${fmt(kY1)};
const float ZHC_Y2 = ${fmt(kY2)};
const float ZHC_Y20 = ${fmt(kY20)};
const float ZHC_Y22 = ${fmt(kY22)};

vec3 zhcDirFromGltf(vec3 d) { return d.zxy; }

// 2^e for integer e in [-126, 127], exact.
float zhcPow2(int e) { return uintBitsToFloat(uint(e + 127) << 23); }
// Unsigned float, 5-bit exponent (bias 15), mbits mantissa bits (R11G11B10F channels).
float zhcUnpackUfloat(uint code, uint mbits) {
  uint e = code >> mbits;
  uint m = code & ((1u << mbits) - 1u);
  if (e == 0u) return float(m) * zhcPow2(-14 - int(mbits));
  if (e == 31u) return uintBitsToFloat(m == 0u ? 0x7f800000u : 0x7fc00000u);
  return uintBitsToFloat(((e + 112u) << 23) | (m << (23u - mbits)));
}
// The 4-byte DC slot (zh3_q16, sh3_q28; a half DC there reads as R11G11B10F, as the codec does).
vec3 zhcUnpackDc(uint bits) {
#if ZHC_DC_RGB9E5
  float s = zhcPow2(int(bits >> 27) - 24);
  return vec3(float(bits & 511u), float((bits >> 9) & 511u), float((bits >> 18) & 511u)) * s;
#else
  return vec3(zhcUnpackUfloat(bits & 2047u, 6u), zhcUnpackUfloat((bits >> 11) & 2047u, 6u), zhcUnpackUfloat(bits >> 22, 5u));
#endif
}
// Code -> t in [-1, 1] (codes above 2 bv decode as 2 bv).
float zhcUnit(uint code) {
  const int bv = (1 << (ZHC_BITS - 1)) - 1;
  float t = float(min(int(code), 2 * bv) - bv) / float(bv);
#if ZHC_SQRT
  t = t * abs(t);
#endif
  return t;
}
float zhcZonalRatio(uint code) {
  float t = zhcUnit(code);
#if ZHC_ZONAL_MAPPING == 0
  return 0.5 * (t * (ZHC_ZONAL_HI - ZHC_ZONAL_LO) + (ZHC_ZONAL_HI + ZHC_ZONAL_LO));
#elif ZHC_ZONAL_MAPPING == 1
  return t >= 0.0 ? t * ZHC_ZONAL_HI : t * -ZHC_ZONAL_LO;
#else
  return t * ZHC_ZONAL_HI;
#endif
}
vec3 zhcNormalizeOrZ(vec3 v) {
  float len = length(v);
  return (len > 0.0 && !isinf(len)) ? v * (1.0 / len) : vec3(0.0, 0.0, 1.0);
}

// Zonal axis of channel k: its own L1 (per-channel entries) or the luminance-weighted L1 (the rest).
vec3 zhcZonalAxis(vec3 v[3], int k) {
#if ZHC_AXIS_CHANNEL
  return zhcNormalizeOrZ(v[k]);
#else
  return zhcNormalizeOrZ(ZHC_LUMINANCE.r * v[0] + ZHC_LUMINANCE.g * v[1] + ZHC_LUMINANCE.b * v[2]);
#endif
}

float zhcUnpackHalf(uint h) {
  float mag = zhcUnpackUfloat(h & 32767u, 10u);
  return (h & 32768u) != 0u ? -mag : mag;
}
// sh2_q's 6-byte DC slot (bytes 0-5 of the probe = words.x, low half of words.y).
vec3 zhcUnpackDcSlot6(uvec4 w) {
#if ZHC_DC_HALF
  return vec3(zhcUnpackHalf(w.x & 65535u), zhcUnpackHalf(w.x >> 16), zhcUnpackHalf(w.y & 65535u));
#else
  return zhcUnpackDc(w.x);
#endif
}
// Byte b (0..15) of a 16-byte texel.
uint zhcByte(uvec4 w, int b) { return (w[b >> 2] >> (8 * (b & 3))) & 255u; }
// Ratio of SH index i (1..8) from its code (interval by band; index 6 uses the zonal mapping).
float zhcRatio(int i, uint code) {
  if (i < 4) return zhcUnit(code) * ZHC_L1_HI;
  if (i == 6) return zhcZonalRatio(code);
  return zhcUnit(code) * ZHC_L2_HI;
}
vec3 zhcIrradianceSh3Irr(vec3 c[9], vec3 n);
vec3 zhcIrradianceSh3(vec3 c[9], vec3 n);
// Stored coefficients (radiance or, with ZHC_STORED_IRRADIANCE, irradiance SH) -> irradiance.
vec3 zhcIrradianceStored(vec3 c[9], vec3 n) {
#if ZHC_STORED_IRRADIANCE
  return zhcIrradianceSh3Irr(c, n);
#else
  return zhcIrradianceSh3(c, n);
#endif
}

// sh3_q28: word 0 = DC, words 1 + 2k and 2 + 2k = channel k's SH indices 1..4 and 5..8.
vec3 zhcIrradianceSh3Q28(uvec4 w0, uvec4 w1, vec3 n) {
  uint w[7] = uint[7](w0.x, w0.y, w0.z, w0.w, w1.x, w1.y, w1.z);
  vec3 dc = zhcUnpackDc(w[0]);
  vec3 c[9];
  c[0] = dc;
  for (int i = 1; i < 9; ++i) {
    for (int k = 0; k < 3; ++k) {
      uint word = w[1 + 2 * k + (i - 1) / 4];
      c[i][k] = zhcRatio(i, (word >> (8 * ((i - 1) % 4))) & 255u) * dc[k];
    }
  }
  return zhcIrradianceStored(c, n);
}

// sh2_q: bytes 0-5 DC slot, byte 6 + 3k + (i - 1) = channel k's L1 index i.
vec3 zhcIrradianceSh2Q(uvec4 words, vec3 n) {
  vec3 dc = zhcUnpackDcSlot6(words);
  vec3 c[9];
  c[0] = dc;
  for (int i = 1; i < 4; ++i)
    for (int k = 0; k < 3; ++k) c[i][k] = zhcRatio(i, zhcByte(words, 6 + 3 * k + i - 1)) * dc[k];
  for (int i = 4; i < 9; ++i) c[i] = vec3(0.0);
  return zhcIrradianceStored(c, n);
}

// hall_curve_q: sh2_q bytes; the zonal L2 is hallucinated at decode by ZH3 Eq. 21,
// f20 = (a p^2 + b p) f0 with p = clamp(|L1 . axis| / f0, 0, sqrt 3), on the RADIANCE linear SH.
vec3 zhcIrradianceHallCurveQ(uvec4 words, vec3 n) {
  vec3 dc = zhcUnpackDcSlot6(words);
  vec3 v[3];
#if ZHC_STORED_IRRADIANCE
  const float toRad1 = 1.5;  // stored irradiance L1 -> radiance (band scale 2/3)
#else
  const float toRad1 = 1.0;
#endif
  for (int k = 0; k < 3; ++k)  // radiance L1 in vector form (-f11, -f1-1, f10)
    v[k] = toRad1 * dc[k] * vec3(-zhcUnit(zhcByte(words, 6 + 3 * k + 2)), -zhcUnit(zhcByte(words, 6 + 3 * k)),
                                 zhcUnit(zhcByte(words, 6 + 3 * k + 1))) * ZHC_L1_HI;
  vec3 e;
  for (int k = 0; k < 3; ++k) {
    vec3 a = zhcZonalAxis(v, k);
    float f0 = dc[k];
    float z20 = 0.0;
    if (f0 > 0.0 && !isinf(f0)) {
      float p = clamp(abs(dot(v[k], a)) / f0, 0.0, ${fmt(Math.sqrt(3.0))});
      z20 = (ZHC_CURVE_A * p * p + ZHC_CURVE_B * p) * f0;
    }
    float z = dot(a, n);
    e[k] = ZHC_Y00 * f0 + (2.0 / 3.0) * ZHC_Y1 * dot(v[k], n) + 0.25 * z20 * ZHC_Y20 * (3.0 * z * z - 1.0);
  }
  return e;
}

// zh3_q16: word 0 = DC, word 1 + k = channel k's (L1-1, L10, L11, zonal) codes, byte 0 first.
vec3 zhcIrradianceZh3Q16(uvec4 words, vec3 n) {
  vec3 dc = zhcUnpackDc(words.x);
  vec3 v[3];
  float zq[3];
  for (int k = 0; k < 3; ++k) {
    uint w = words[k + 1];
    float d = dc[k];
    // L1 in vector form (-f11, -f1-1, f10): f1(d) = Y1 v . d
    v[k] = vec3(-zhcUnit((w >> 16) & 255u) * ZHC_L1_HI * d, -zhcUnit(w & 255u) * ZHC_L1_HI * d, zhcUnit((w >> 8) & 255u) * ZHC_L1_HI * d);
    zq[k] = zhcZonalRatio(w >> 24) * d;
  }
#if ZHC_STORED_IRRADIANCE
  const float s1 = 1.0, s2 = 1.0;
#else
  const float s1 = 2.0 / 3.0, s2 = 0.25;
#endif
  vec3 e;
  for (int k = 0; k < 3; ++k) {
    vec3 a = zhcZonalAxis(v, k);
    float z = dot(a, n);
    e[k] = ZHC_Y00 * dc[k] + s1 * ZHC_Y1 * dot(v[k], n) + s2 * zq[k] * ZHC_Y20 * (3.0 * z * z - 1.0);
  }
  return e;
}

// Float SH3 (zhc basis, index l(l+1)+m) at unit n: irradiance-SH evaluation.
vec3 zhcIrradianceSh3Irr(vec3 c[9], vec3 n) {
  return ZHC_Y00 * c[0] - ZHC_Y1 * n.y * c[1] + ZHC_Y1 * n.z * c[2] - ZHC_Y1 * n.x * c[3]
       + ZHC_Y2 * n.x * n.y * c[4] - ZHC_Y2 * n.y * n.z * c[5] + ZHC_Y20 * (3.0 * n.z * n.z - 1.0) * c[6]
       - ZHC_Y2 * n.x * n.z * c[7] + ZHC_Y22 * (n.x * n.x - n.y * n.y) * c[8];
}
// Float SH3 RADIANCE at unit n: band scales 1, 2/3, 1/4 applied.
vec3 zhcIrradianceSh3(vec3 c[9], vec3 n) {
  vec3 s[9] = vec3[9](c[0], c[1] * (2.0 / 3.0), c[2] * (2.0 / 3.0), c[3] * (2.0 / 3.0),
                      c[4] * 0.25, c[5] * 0.25, c[6] * 0.25, c[7] * 0.25, c[8] * 0.25);
  return zhcIrradianceSh3Irr(s, n);
}
// ---- end zhc irradiance ----
`;
}

export const ZHC_IRRADIANCE_GLSL = zhcIrradianceGlsl();

// The four little-endian uint32 words of zh3_q16 probe p of a byte payload (a volume's `bytes`),
// as the shader's uvec4; zh3Q16Words(bytes, count) gives a Uint32Array(count * 4) for an
// RGBA32UI texture (one texel per probe).
// Any packed layout: probe p occupies ceil(bytesPerProbe / 16) RGBA32UI texels (zero padded),
// e.g. sh3_q28: 2 texels = the shader's (w0, w1).
export function packedWords(bytes, count, bytesPerProbe) {
  const texels = Math.ceil(bytesPerProbe / 16);
  const out = new Uint32Array(count * texels * 4);
  const u8 = new Uint8Array(out.buffer);
  for (let p = 0; p < count; p++) u8.set(bytes.subarray(p * bytesPerProbe, (p + 1) * bytesPerProbe), p * texels * 16);
  if (new Uint8Array(new Uint32Array([1]).buffer)[0] !== 1) throw new Error('packedWords: big-endian platform');
  return out;
}

export function zh3Q16Words(bytes, count) {
  const out = new Uint32Array(count * 4);
  for (let j = 0; j < count * 4; j++)
    out[j] = (bytes[4 * j] | (bytes[4 * j + 1] << 8) | (bytes[4 * j + 2] << 16) | (bytes[4 * j + 3] << 24)) >>> 0;
  return out;
}
