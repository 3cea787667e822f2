// zhc runtime for the web: decoders for every probe encoding zhc stores (the codec table of
// codec/probe/codec.h, the packed layouts of docs/quantization.md) to the hub, float SH3 radiance, and
// irradiance at a normal. No dependencies, no build step: an ES module for browsers and Node.
//
// Output convention: an SH3 probe is a Float32Array(27), element i * 3 + k = coefficient i
// (i = l(l+1)+m, zhc's real SH basis, docs/conventions.md) of channel k (R, G, B), RADIANCE.
//
// Exactness. Every decoder is a port of the C++ codec doing the same double arithmetic in the same
// order and rounding to float32 (Math.fround) exactly where the C++ code stores a float. JavaScript
// numbers are IEEE doubles with round-to-nearest, Math.sqrt is correctly rounded, and the codec is
// compiled with -ffp-contract=off (no FMA), so `decodeProbe` returns the SAME float32 values as
// zhc's decode_probe (codec/probe/probe_set.cpp) for every encoding and parameter set, and `irradiance`
// the same float32 values as zhc's irradiance(hub, n) (what `zhc gltf eval` prints). Powers of two
// are built from exponent bits (ldexp), never with Math.pow. The functions that are NOT bit exact
// are marked "(not bit exact)" with their bound: rotateZhcToGltf / rotateGltfToZhc (the two L2
// coefficients Y20, Y22 mix with weights 1/2 and sqrt(3)/2: one double rounding each, then float)
// and zh3Q16IrradianceFast (the shader-style formula, a few float ulps of the probe's DC).
//
// Bad input: every decoder accepts ANY bytes (garbage in gives finite-or-NaN numbers out) and
// never throws; the parsers (parseZhp, volume parsing in the plugin) throw Error on malformed data.

export const PI = 3.14159265358979323846;  // == Math.PI (kPi of codec/sh/sh.h)

// ---- basis constants (codec/sh/sh.h) -----------------------------------------------------------
export const kY00 = 1.0 / (2.0 * Math.sqrt(PI));
export const kY1 = Math.sqrt(3.0 / (4.0 * PI));
export const kY2 = Math.sqrt(15.0 / (4.0 * PI));
export const kY20 = Math.sqrt(5.0 / (16.0 * PI));
export const kY22 = Math.sqrt(15.0 / (16.0 * PI));
// Band scales of the normalised clamped-cosine convolution (radiance -> irradiance).
export const IRRADIANCE_BAND_SCALE = [1.0, 2.0 / 3.0, 1.0 / 4.0];
const BAND_OF = [0, 1, 1, 1, 2, 2, 2, 2, 2];
const kSqrt3 = Math.sqrt(3.0);
const kSqrtFourPiOverFive = Math.sqrt(4.0 * PI / 5.0);
const f32 = Math.fround;

export const DEFAULT_LUMINANCE = Object.freeze([0.2126, 0.7152, 0.0722]);

// ---- exact powers of two (std::ldexp) -------------------------------------------------------
const pow2Buf = new DataView(new ArrayBuffer(8));
// 2^e for integer e in [-1022, 1023], exact (built from the exponent bits).
function pow2(e) {
  pow2Buf.setUint32(0, ((e + 1023) << 20) >>> 0, false);
  pow2Buf.setUint32(4, 0, false);
  return pow2Buf.getFloat64(0, false);
}
// x * 2^e, exact when the result is a normal double (all uses here: |e| <= 40, x a small integer
// or in [1, 2)).
function ldexp(x, e) { return x * pow2(e); }

// ---- SH helpers -----------------------------------------------------------------------------

// The nine SH3 basis functions at a unit direction, exactly sh3_basis (codec/sh/sh.h).
export function shBasis(x, y, z) {
  return [kY00, -kY1 * y, kY1 * z, -kY1 * x, kY2 * x * y, -kY2 * y * z, kY20 * (3.0 * z * z - 1.0),
    -kY2 * x * z, kY22 * (x * x - y * y)];
}

// normalize_or (codec/sh/sh.cpp): (1 / |a|) a, or `fallback` when |a| is 0 or not finite.
export function normalizeOr(a, fallback = [0, 0, 1]) {
  const len = Math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  if (!(len > 0.0) || !Number.isFinite(len)) return [fallback[0], fallback[1], fallback[2]];
  const s = 1.0 / len;
  return [s * a[0], s * a[1], s * a[2]];
}

// Value of SH3 `sh` (27 floats, radiance or irradiance) at unit direction d: evaluate() of sh.cpp.
export function evaluate(sh, d) {
  const b = shBasis(d[0], d[1], d[2]);
  const acc = [0, 0, 0];
  for (let i = 0; i < 9; i++)
    for (let k = 0; k < 3; k++) acc[k] += sh[i * 3 + k] * b[i];
  return [f32(acc[0]), f32(acc[1]), f32(acc[2])];
}

// Radiance SH3 -> irradiance SH3 (to_irradiance: float(c * s), s = 1, 2/3, 1/4).
export function toIrradiance(sh) {
  const out = new Float32Array(27);
  for (let i = 0; i < 9; i++)
    for (let k = 0; k < 3; k++) out[i * 3 + k] = f32(sh[i * 3 + k] * IRRADIANCE_BAND_SCALE[BAND_OF[i]]);
  return out;
}
// Irradiance SH3 -> radiance SH3 (to_radiance: float(c * (1 / s))).
export function toRadiance(sh) {
  const out = new Float32Array(27);
  for (let i = 0; i < 9; i++) {
    const s = 1.0 / IRRADIANCE_BAND_SCALE[BAND_OF[i]];
    for (let k = 0; k < 3; k++) out[i * 3 + k] = f32(sh[i * 3 + k] * s);
  }
  return out;
}

// Irradiance at unit normal n (in the SH's axes) from SH3 radiance: irradiance(Sh3Radiance, n) of
// codec/sh/sh.cpp, float32 RGB. E is normalised: constant radiance 1 gives 1 (docs/conventions.md).
export function irradiance(sh, n) { return evaluate(toIrradiance(sh), n); }

// ---- quantiser (codec/probe/quantize.cpp) ---------------------------------------------------------

const kL1Bound = Math.sqrt(3.0);
const kL2ZonalLo = -Math.sqrt(5.0) / 2.0;
const kL2ZonalHi = Math.sqrt(5.0);
const kL2TightBound = Math.sqrt(15.0) / 2.0;
const kL2LooseBound = Math.sqrt(5.0);

// Quantisation parameters (the storage fields of CodecOptions, codec/probe/codec.h) with their glTF spellings.
export const DEFAULT_PARAMS = Object.freeze({
  bits: 8, sqrt: false, l2Bound: 'tight', dcFormat: 'r11g11b10f', kind: 'radiance',
  zonalMapping: 'affine', axisMode: 'luminance', luminanceWeights: DEFAULT_LUMINANCE,
});
export function makeParams(p = {}) {
  const out = { ...DEFAULT_PARAMS, ...p };
  out.luminanceWeights = [...(p.luminanceWeights ?? DEFAULT_LUMINANCE)];
  const oneOf = (key, values) => {
    if (!values.includes(out[key])) throw new Error(`zhc: ${key} must be one of ${values.join(', ')}, got ${out[key]}`);
  };
  if (!Number.isInteger(out.bits) || out.bits < 2 || out.bits > 8) throw new Error(`zhc: bits must be 2..8, got ${out.bits}`);
  if (typeof out.sqrt !== 'boolean') throw new Error('zhc: sqrt must be a boolean');
  oneOf('l2Bound', ['tight', 'loose']);
  oneOf('dcFormat', ['r11g11b10f', 'rgb9e5', 'half']);
  oneOf('kind', ['radiance', 'irradiance']);
  oneOf('zonalMapping', ['affine', 'zero', 'symmetric']);
  oneOf('axisMode', ['luminance', 'channel']);
  if (out.luminanceWeights.length !== 3 || !out.luminanceWeights.every(Number.isFinite))
    throw new Error('zhc: luminanceWeights must be 3 finite numbers');
  return out;
}

function bandScale(kind, l) { return kind === 'irradiance' ? IRRADIANCE_BAND_SCALE[l] : 1.0; }

function zonalInterval(kind) {
  const s = bandScale(kind, 2);
  return [kL2ZonalLo * s, kL2ZonalHi * s];
}
// Interval [lo, hi] of c_i / c_0 for SH index i in 1..8 (ratio_interval).
export function ratioInterval(i, kind, l2Bound) {
  const l = BAND_OF[i];
  const s = bandScale(kind, l);
  if (l === 1) return [-kL1Bound * s, kL1Bound * s];
  if (i === 6) return zonalInterval(kind);
  const b = (l2Bound === 'tight' ? kL2TightBound : kL2LooseBound) * s;
  return [-b, b];
}

function unitToRatio(t, iv, mapping, zonal) {
  const [lo, hi] = iv;
  if (!zonal || mapping === 'affine') return 0.5 * (t * (hi - lo) + (hi + lo));
  if (mapping === 'zero') return t >= 0 ? t * hi : t * -lo;
  return t * Math.max(hi, -lo);
}

// RatioCoder::decode: code -> ratio (total: codes above 2 bv decode as 2 bv).
export function decodeRatio(code, iv, params, zonal) {
  const bv = (1 << (params.bits - 1)) - 1;
  const c = Math.min(code, 2 * bv);
  let t = (c - bv) / bv;
  if (params.sqrt) t = t * Math.abs(t);
  return unitToRatio(t, iv, params.zonalMapping, zonal);
}

// ---- DC formats -----------------------------------------------------------------------------

// Unsigned float with a 5-bit exponent (bias 15) and `mbits` mantissa bits (unpack_ufloat).
export function unpackUfloat(code, mbits) {
  const e = code >>> mbits, m = code & ((1 << mbits) - 1);
  if (e === 0) return f32(ldexp(m, -14 - mbits));
  if (e === 31) return m === 0 ? Infinity : NaN;
  return f32(ldexp(1.0 + ldexp(m, -mbits), e - 15));
}
export function unpackR11G11B10F(bits) {
  return [unpackUfloat(bits & 0x7ff, 6), unpackUfloat((bits >>> 11) & 0x7ff, 6), unpackUfloat(bits >>> 22, 5)];
}
export function unpackRgb9e5(bits) {
  const e = (bits >>> 27) - 15 - 9;
  return [f32(ldexp(bits & 0x1ff, e)), f32(ldexp((bits >>> 9) & 0x1ff, e)), f32(ldexp((bits >>> 18) & 0x1ff, e))];
}
export function unpackHalf(bits) {
  const mag = unpackUfloat(bits & 0x7fff, 10);
  return (bits & 0x8000) ? -mag : mag;
}

const u32 = (b, o) => (b[o] | (b[o + 1] << 8) | (b[o + 2] << 16) | (b[o + 3] << 24)) >>> 0;

// load_dc: the DC triple of a packed probe. `slotBytes` 4 (zh3_q16, sh3_q28) or 6 (sh2_q); a half
// DC in a 4-byte slot reads as R11G11B10F, as the codec does (files never carry it).
function loadDc(b, o, format, slotBytes) {
  if (format === 'half' && slotBytes < 6) format = 'r11g11b10f';
  if (format === 'rgb9e5') return unpackRgb9e5(u32(b, o));
  if (format === 'half') return [0, 1, 2].map((k) => unpackHalf(b[o + 2 * k] | (b[o + 2 * k + 1] << 8)));
  return unpackR11G11B10F(u32(b, o));
}

// ---- ZH3 axes (codec/probe/zh3.cpp) ---------------------------------------------------------------

// L1 band of channel k in vector form (-f11, -f1-1, f10); c = float coefficients, index i*3+k.
function l1Vector(c, k) { return [-c[9 + k], -c[3 + k], c[6 + k]]; }

// zh3_axis for the three channels: the luminance-weighted L1 (shared) or each channel's own,
// normalised, +Z when zero. `c` holds float32 DC/L1 (at least 12 values, index i*3+k).
export function zh3Axes(c, axisMode, w) {
  if (axisMode === 'luminance') {
    const v0 = l1Vector(c, 0), v1 = l1Vector(c, 1), v2 = l1Vector(c, 2);
    const lum = [0, 1, 2].map((j) => (w[0] * v0[j] + w[1] * v1[j]) + w[2] * v2[j]);
    const a = normalizeOr(lum, [0, 0, 1]);
    return [a, a, a];
  }
  return [0, 1, 2].map((k) => normalizeOr(l1Vector(c, k), [0, 0, 1]));
}

// y2 of zh3.cpp: the L2 basis at unit a.
function y2(a) {
  return [kY2 * a[0] * a[1], -kY2 * a[1] * a[2], kY20 * (3.0 * a[2] * a[2] - 1.0), -kY2 * a[0] * a[2],
    kY22 * (a[0] * a[0] - a[1] * a[1])];
}

// zh3_expand: linear (12 floats) + zonal (3 floats) -> SH3 radiance.
function zh3Expand(linear, zonal, axisMode, w) {
  const out = new Float32Array(27);
  for (let j = 0; j < 12; j++) out[j] = linear[j];
  const axes = zh3Axes(linear, axisMode, w);
  for (let k = 0; k < 3; k++) {
    const q = y2(axes[k]);
    for (let m = 0; m < 5; m++) out[(4 + m) * 3 + k] = f32(zonal[k] * kSqrtFourPiOverFive * q[m]);
  }
  return out;
}

// hallucinate_zonal (ZH3 paper Eq. 14 / 20 / 21).
export const HALLUCINATE_CURVE_A = 0.6, HALLUCINATE_CURVE_B = 0.08;  // CodecOptions defaults
function clamp(v, lo, hi) { return v < lo ? lo : (hi < v ? hi : v); }  // std::clamp (NaN stays)
export function hallucinateZonal(model, f0, f1Zonal, a = HALLUCINATE_CURVE_A, b = HALLUCINATE_CURVE_B) {
  const f1 = Math.abs(f1Zonal);
  if (model === 'ambdir') return Math.sqrt(15.0) / 3.0 * f1;
  if (!(f0 > 0) || !Number.isFinite(f0)) return 0.0;
  const p = clamp(f1 / f0, 0.0, kSqrt3);
  if (model === 'sphere') return (2.0 * Math.sqrt(5.0) / 3.0 * p * p - Math.sqrt(5.0 / 3.0) * p) * f0;
  return (a * p * p + b * p) * f0;
}
// zh3_hallucinate then zh3_expand: linear (>= 12 float32 values) -> SH3 radiance.
// `scale` multiplies the curve's a and b (hall_adaptive_q16; codec/probe/zh3_hall_solve.cpp hall_scaled_expand).
function hallucinateExpand(linear, model, axisMode, w, scale = 1) {
  const axes = zh3Axes(linear, axisMode, w);
  const zonal = [0, 0, 0];
  for (let k = 0; k < 3; k++) {
    const v = l1Vector(linear, k), a = axes[k];
    const f1 = v[0] * a[0] + v[1] * a[1] + v[2] * a[2];
    zonal[k] = f32(hallucinateZonal(model, linear[k], f1, scale * HALLUCINATE_CURVE_A, scale * HALLUCINATE_CURVE_B));
  }
  return zh3Expand(linear.subarray ? linear.subarray(0, 12) : linear.slice(0, 12), zonal, axisMode, w);
}

// ---- packed layouts (decode_packed) ---------------------------------------------------------

export const PACKED_LAYOUTS = Object.freeze({ zh3_q16: 'zh3_q16', zh3_solved_q16: 'zh3_q16', zh3_dering_q16: 'zh3_q16', sh3_q28: 'sh3_q28',
  sh2_q: 'sh2_q', hall_curve_q: 'sh2_q', zh3_channel_q16: 'zh3_q16', zh3_solved_channel_q16: 'zh3_q16',
  hall_solved_q16: 'sh2_q', hall_adaptive_q16: 'sh2_q' });

function ratioOffset(layout, k, i) {
  if (layout === 'zh3_q16') return 4 + 4 * k + (i - 1);
  if (layout === 'sh3_q28') return 4 + 8 * k + (i - 1);
  return 6 + 3 * k + (i - 1);
}

// Packed bytes (at b[o ..]) -> SH3 radiance (Float32Array(27)); exactly decode_packed.
export function decodePacked(layout, b, o, params) {
  const p = params;
  const q = new Float64Array(27);  // the stored (radiance or irradiance) coefficients, in double
  const dc = loadDc(b, o, p.dcFormat, layout === 'sh2_q' ? 6 : 4);
  const last = layout === 'sh3_q28' ? 8 : 3;
  const ivs = [];
  for (let i = 1; i <= last; i++) ivs[i] = ratioInterval(i, p.kind, p.l2Bound);
  for (let k = 0; k < 3; k++) {
    q[k] = dc[k];
    for (let i = 1; i <= last; i++) q[i * 3 + k] = decodeRatio(b[o + ratioOffset(layout, k, i)], ivs[i], p, i === 6) * dc[k];
  }
  if (layout === 'zh3_q16') {
    const linear = new Float32Array(12);
    for (let j = 0; j < 12; j++) linear[j] = q[j];  // axes_from_l1 rounds the L1 to float first
    const axes = zh3Axes(linear, p.axisMode, p.luminanceWeights);
    const iv = zonalInterval(p.kind);
    for (let k = 0; k < 3; k++) {
      // zonal_l2_direction: sqrt(4 pi / 5) * sh3_basis(axis)[4..8]
      const a = axes[k];
      const y = shBasis(a[0], a[1], a[2]);
      const zq = decodeRatio(b[o + 4 + 4 * k + 3], iv, p, true) * dc[k];
      for (let m = 0; m < 5; m++) q[(4 + m) * 3 + k] = zq * (kSqrtFourPiOverFive * y[4 + m]);
    }
  }
  const out = new Float32Array(27);
  for (let i = 0; i < 9; i++)
    for (let k = 0; k < 3; k++) out[i * 3 + k] = q[i * 3 + k] / bandScale(p.kind, BAND_OF[i]);
  return out;
}

// ---- the codec table ------------------------------------------------------------------------

function loadFloats(b, o, n) {
  const dv = new DataView(b.buffer, b.byteOffset + o, n * 4);
  const v = new Float32Array(n);
  for (let j = 0; j < n; j++) v[j] = dv.getFloat32(j * 4, true);
  return v;
}
function padTo27(v) {
  const out = new Float32Array(27);
  out.set(v.subarray(0, Math.min(27, v.length)));
  return out;
}
const zh3Float = (mode) => (b, o, p) => {
  const v = loadFloats(b, o, 15);
  return zh3Expand(v.subarray(0, 12), v.subarray(12, 15), mode, p.luminanceWeights);
};
const hallFloat = (model, mode) => (b, o, p) => hallucinateExpand(loadFloats(b, o, 12), model, mode, p.luminanceWeights);
const packed = (layout) => (b, o, p) => decodePacked(layout, b, o, p);
const packedPerChannel = (b, o, p) => decodePacked('zh3_q16', b, o, { ...p, axisMode: 'channel' });

// Every entry of zhc's codec table (codecs() in codec/probe/codec_table.cpp): bytes per probe, whether
// the entry is a packed (quantised) layout, and the decoder to radiance SH3 (before the `kind`
// handling of decodeProbe).
export const ENCODINGS = Object.freeze({
  sh3: { bytes: 108, decode: (b, o) => loadFloats(b, o, 27) },
  sh2: { bytes: 48, decode: (b, o) => padTo27(loadFloats(b, o, 12)) },
  zh3_lum: { bytes: 60, decode: zh3Float('luminance') },
  zh3_channel: { bytes: 60, decode: zh3Float('channel') },
  zh3_solved_lum: { bytes: 60, decode: zh3Float('luminance') },
  zh3_solved_channel: { bytes: 60, decode: zh3Float('channel') },
  hall_ambdir: { bytes: 48, decode: hallFloat('ambdir', 'luminance') },
  hall_sphere: { bytes: 48, decode: hallFloat('sphere', 'luminance') },
  hall_curve: { bytes: 48, decode: hallFloat('curve', 'luminance') },
  hall_ambdir_channel: { bytes: 48, decode: hallFloat('ambdir', 'channel') },
  hall_sphere_channel: { bytes: 48, decode: hallFloat('sphere', 'channel') },
  hall_curve_channel: { bytes: 48, decode: hallFloat('curve', 'channel') },
  zh3_lum_axis_clamp: { bytes: 60, decode: zh3Float('luminance') },
  zh3_lum_sphere_clamp: { bytes: 60, decode: zh3Float('luminance') },
  zh3_dering: { bytes: 60, decode: zh3Float('luminance') },
  sh3_dering: { bytes: 108, decode: (b, o) => loadFloats(b, o, 27) },
  zh3_q16: { bytes: 16, packed: true, decode: packed('zh3_q16') },
  zh3_solved_q16: { bytes: 16, packed: true, decode: packed('zh3_q16') },
  zh3_dering_q16: { bytes: 16, packed: true, decode: packed('zh3_q16') },
  sh3_q28: { bytes: 28, packed: true, decode: packed('sh3_q28') },
  sh2_q: { bytes: 16, packed: true, decode: packed('sh2_q') },
  hall_curve_q: { bytes: 16, packed: true, decode: (b, o, p) => hallucinateExpand(decodePacked('sh2_q', b, o, p), 'curve', p.axisMode, p.luminanceWeights) },
  // zh3_q16 bytes with each channel's own axis, whatever params.axisMode says (`axisMode`: the
  // entry's fixed axis, for code that builds params for a shader, e.g. the glTF plugin).
  zh3_channel_q16: { bytes: 16, packed: true, axisMode: 'channel', decode: packedPerChannel },
  zh3_solved_channel_q16: { bytes: 16, packed: true, axisMode: 'channel', decode: packedPerChannel },
  hall_solved: { bytes: 48, decode: hallFloat('curve', 'luminance') },
  hall_solved_q16: { bytes: 16, packed: true, decode: (b, o, p) => hallucinateExpand(decodePacked('sh2_q', b, o, p), 'curve', p.axisMode, p.luminanceWeights) },
  // byte 15: scale code, s = 0.5 min(code, 7) times the Eq. 21 curve (docs/quantization.md)
  hall_adaptive_q16: { bytes: 16, packed: true, decode: (b, o, p) => hallucinateExpand(decodePacked('sh2_q', b, o, p), 'curve', p.axisMode, p.luminanceWeights, 0.5 * Math.min(b[o + 15], 7)) },
});

// Other names an encoding answers to in files (codec/probe/codec_table.cpp codec_aliases(): App. B's
// zonal clamps leave irradiance negative where no zonal value helps, so only entries that keep it
// >= 0 carry "dering" in their names): alias -> the entry's own name.
export const ENCODING_ALIASES = Object.freeze({
  zh3_lum_dering: 'zh3_lum_axis_clamp',
  zh3_lum_dering_sphere: 'zh3_lum_sphere_clamp',
});

// The entry's own name for a name or an alias of one (anything else is returned unchanged).
export function encodingName(name) {
  return Object.prototype.hasOwnProperty.call(ENCODING_ALIASES, name) ? ENCODING_ALIASES[name] : name;
}

export function encodingInfo(name) {
  name = encodingName(name);
  const e = Object.prototype.hasOwnProperty.call(ENCODINGS, name) ? ENCODINGS[name] : null;
  if (!e) throw new Error(`zhc: unknown encoding '${name}' (known: ${Object.keys(ENCODINGS).join(', ')})`);
  return e;
}

// Probe bytes (b[o .. o + bytes)) -> SH3 radiance, Float32Array(27): decode_probe of
// codec/probe/probe_set.cpp. `params` from makeParams (kind 'irradiance': the packed layouts use the
// irradiance intervals, the float ones store band-scaled coefficients; both return radiance).
export function decodeProbe(encoding, bytes, offset = 0, params = DEFAULT_PARAMS) {
  const e = encodingInfo(encoding);
  if (offset < 0 || offset + e.bytes > bytes.length) throw new Error('zhc: probe bytes out of range');
  const sh = e.decode(bytes, offset, params);
  if (e.packed || params.kind !== 'irradiance') return sh;
  return toRadiance(sh);
}

// Irradiance of probe bytes at unit normal n (in the SH axes): irradiance(decode_probe(...), n).
export function probeIrradiance(encoding, bytes, offset, params, n) {
  return irradiance(decodeProbe(encoding, bytes, offset, params), n);
}

// The shader formula for zh3_q16 bytes (what zhc_irradiance.glsl.mjs evaluates), in double:
// DC, L1 and the zonal term straight from the words, the axis from the L1 (luminance or per
// channel). (not bit exact) It differs from irradiance(decodeProbe(...)) only by rounding: the
// hub rounds its 27 coefficients to float; relative to the probe's DC the difference is < 1e-6.
export function zh3Q16IrradianceFast(b, o, params, n) {
  const p = params;
  const dc = loadDc(b, o, p.dcFormat, 4);
  const iv1 = ratioInterval(1, p.kind, p.l2Bound), ivz = zonalInterval(p.kind);
  const s1 = p.kind === 'irradiance' ? 1.0 : IRRADIANCE_BAND_SCALE[1];
  const s2 = p.kind === 'irradiance' ? 1.0 : IRRADIANCE_BAND_SCALE[2];
  const lin = new Float32Array(12);
  for (let k = 0; k < 3; k++) {
    lin[k] = dc[k];
    for (let i = 1; i <= 3; i++) lin[i * 3 + k] = decodeRatio(b[o + 4 + 4 * k + i - 1], iv1, p, false) * dc[k];
  }
  const axes = zh3Axes(lin, p.axisMode, p.luminanceWeights);
  const e = [0, 0, 0];
  for (let k = 0; k < 3; k++) {
    const v = l1Vector(lin, k), a = axes[k];
    const z = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    const zq = decodeRatio(b[o + 4 + 4 * k + 3], ivz, p, true) * dc[k];
    e[k] = kY00 * dc[k] + s1 * kY1 * (v[0] * n[0] + v[1] * n[1] + v[2] * n[2]) + s2 * zq * kY20 * (3 * z * z - 1);
  }
  return e;
}

// ---- axes: zhc (Z-up) <-> glTF (Y-up) -------------------------------------------------------
//
// (x, y, z)_glTF = (y, z, x)_zhc. A direction d in glTF axes is (d.z, d.x, d.y) in zhc axes.
export function gltfToZhcDir(d) { return [d[2], d[0], d[1]]; }
export function zhcToGltfDir(d) { return [d[1], d[2], d[0]]; }

// Coefficients g of the same function in glTF axes: g(d) = f(gltfToZhcDir(d)). L0, L1 and
// Y2-2, Y2-1, Y21 are signed permutations (exact); (Y20, Y22) rotate by 120 degrees:
//   g20 = -c20/2 + (sqrt3/2) c22,  g22 = -(sqrt3/2) c20 - c22/2.
// (not bit exact for Y20/Y22: one double rounding of the products, then float32.)
const kHalfSqrt3 = Math.sqrt(3.0) / 2.0;
export function rotateZhcToGltf(c) {
  const g = new Float32Array(27);
  for (let k = 0; k < 3; k++) {
    const C = (i) => c[i * 3 + k];
    g[0 + k] = C(0);
    g[3 + k] = -C(2); g[6 + k] = -C(3); g[9 + k] = C(1);
    g[12 + k] = -C(5); g[15 + k] = C(7); g[21 + k] = -C(4);
    g[18 + k] = -0.5 * C(6) + kHalfSqrt3 * C(8);
    g[24 + k] = -kHalfSqrt3 * C(6) - 0.5 * C(8);
  }
  return g;
}
// The inverse: coefficients in glTF axes -> zhc axes. (not bit exact for Y20/Y22, as above.)
export function rotateGltfToZhc(g) {
  const c = new Float32Array(27);
  for (let k = 0; k < 3; k++) {
    const G = (i) => g[i * 3 + k];
    c[0 + k] = G(0);
    c[3 + k] = G(3); c[6 + k] = -G(1); c[9 + k] = -G(2);
    c[15 + k] = -G(4); c[21 + k] = G(5); c[12 + k] = -G(7);
    c[18 + k] = -0.5 * G(6) - kHalfSqrt3 * G(8);
    c[24 + k] = kHalfSqrt3 * G(6) - 0.5 * G(8);
  }
  return c;
}

// three.js's SphericalHarmonics3 basis (src/math/SphericalHarmonics3.js) has no Condon-Shortley
// phase: its Y1-1, Y11, Y2-1, Y21 are the negatives of zhc's (same index order, same
// normalisation, three's constants rounded to 6 digits). Coefficients in glTF axes (= three.js
// world axes) -> three.js's convention: negate indices 1, 3, 5, 7.
export const THREE_SIGNS = Object.freeze([1, -1, 1, -1, 1, -1, 1, -1, 1]);
export function toThreeConvention(gltfAxesSh) {
  const out = new Float32Array(27);
  for (let i = 0; i < 9; i++)
    for (let k = 0; k < 3; k++) out[i * 3 + k] = THREE_SIGNS[i] * gltfAxesSh[i * 3 + k];
  return out;
}

// ---- .zhp container (docs/zhp-container.md), uncompressed bodies ----------------------------

const CRC_TABLE = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let j = 0; j < 8; j++) c = (c & 1) ? (0xedb88320 ^ (c >>> 1)) : (c >>> 1);
    t[n] = c >>> 0;
  }
  return t;
})();
export function crc32(bytes, start = 0, end = bytes.length) {
  let c = 0xffffffff;
  for (let i = start; i < end; i++) c = CRC_TABLE[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

// Parses a .zhp file (Uint8Array). Returns {encoding, params, count, bytesPerProbe, layout,
// payload (Uint8Array view), positions (Float32Array or null), grid}. Throws on anything the C++
// reader rejects that matters here; zstd-compressed bodies are not supported (throws).
export function parseZhp(bytes) {
  const magic = [0x89, 0x5a, 0x48, 0x50, 0x0d, 0x0a, 0x1a, 0x0a];
  if (bytes.length < 184 || magic.some((m, i) => bytes[i] !== m)) throw new Error('zhp: not a .zhp file');
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (crc32(bytes, 0, 180) !== dv.getUint32(180, true)) throw new Error('zhp: header CRC mismatch');
  if (dv.getUint16(8, true) !== 1) throw new Error('zhp: unsupported version');
  if (dv.getUint16(10, true) !== 184) throw new Error('zhp: bad header size');
  const enumOf = (off, names) => {
    const v = bytes[off];
    if (v >= names.length) throw new Error(`zhp: unknown enum value ${v} at byte ${off}`);
    return names[v];
  };
  const bits = bytes[13];
  if (bits < 2 || bits > 8) throw new Error('zhp: bits out of range');
  if (bytes[16] > 1) throw new Error('zhp: bad sqrt flag');
  if (bytes[19] !== 0) throw new Error('zhp: compressed bodies are not supported by the web runtime');
  let name = '';
  for (let i = 24; i < 56 && bytes[i] !== 0; i++) name += String.fromCharCode(bytes[i]);
  const enc = encodingInfo(name);
  const params = makeParams({
    kind: enumOf(12, ['radiance', 'irradiance']), bits, dcFormat: enumOf(14, ['r11g11b10f', 'rgb9e5', 'half']),
    l2Bound: enumOf(15, ['tight', 'loose']), sqrt: bytes[16] === 1, zonalMapping: enumOf(17, ['affine', 'zero', 'symmetric']),
    axisMode: enumOf(18, ['luminance', 'channel']),
    luminanceWeights: [dv.getFloat64(72, true), dv.getFloat64(80, true), dv.getFloat64(88, true)],
  });
  const layout = enumOf(20, ['none', 'grid', 'positions']);
  const count = Number(dv.getBigUint64(56, true));
  const bpp = dv.getUint32(64, true);
  if (bpp !== enc.bytes) throw new Error('zhp: bytes per probe does not match the encoding');
  const body = Number(dv.getBigUint64(160, true));
  const posBytes = layout === 'positions' ? count * 12 : 0;
  if (body !== posBytes + count * bpp || 184 + body > bytes.length) throw new Error('zhp: body size mismatch');
  if (crc32(bytes, 184, 184 + body) !== dv.getUint32(176, true)) throw new Error('zhp: body CRC mismatch');
  const grid = layout === 'grid' ? {
    origin: [0, 1, 2].map((j) => dv.getFloat64(96 + 8 * j, true)),
    spacing: [0, 1, 2].map((j) => dv.getFloat64(120 + 8 * j, true)),
    counts: [0, 1, 2].map((j) => dv.getUint32(144 + 4 * j, true)),
  } : null;
  let positions = null;
  if (layout === 'positions') {
    positions = new Float32Array(count * 3);
    for (let j = 0; j < count * 3; j++) positions[j] = dv.getFloat32(184 + 4 * j, true);
  }
  const payload = bytes.subarray(184 + posBytes, 184 + body);
  return { encoding: name, params, count, bytesPerProbe: bpp, layout, grid, positions, payload };
}

// Decodes every probe of a payload: Float32Array(count * 27), probe p at p * 27.
export function decodeAll(encoding, payload, count, params = DEFAULT_PARAMS) {
  const e = encodingInfo(encoding);
  if (payload.length < count * e.bytes) throw new Error('zhc: payload shorter than count * bytes per probe');
  const out = new Float32Array(count * 27);
  for (let p = 0; p < count; p++) out.set(decodeProbe(encoding, payload, p * e.bytes, params), p * 27);
  return out;
}

// ---- probe volumes (docs/runtime.md "Probe volumes"; zhc_volume_* of runtime/zhc_runtime.h) -------
//
// A grid of probes decoded once to SH3 radiance; a sample blends the 8 probes of the cell around the
// point (trilinear weights, the point clamped to the grid's box) on the DECODED SH3, then evaluates
// the irradiance once. The same double operations in the same order as zhc_volume_irradiance of the
// C header: volumeIrradiance returns the same float32 values (tests/js/runtime_decode.mjs).

// A volume from its parts: { encoding, params (makeParams), bytes (Uint8Array: count x bytes per
// probe, at least), origin, spacing, counts } (the grid as in .zhp / glTF: probe (x, y, z) is number
// x + nx (y + ny z) at origin + (x sx, y sy, z sz)), or { sh (Float32Array(count x 27), decoded
// radiance), origin, spacing, counts }. Throws Error naming the problem: counts integers >= 1,
// origin and spacing finite, spacing > 0, far corner finite (zhc_volume_init's rules).
export function makeVolume({ encoding, params = DEFAULT_PARAMS, bytes, sh, origin, spacing, counts }) {
  const arr3 = (a, what) => {
    if (!a || a.length !== 3) throw new Error(`zhc volume: ${what} must have 3 entries`);
    return [Number(a[0]), Number(a[1]), Number(a[2])];
  };
  const o = arr3(origin, 'origin'), s = arr3(spacing, 'spacing'), n = arr3(counts, 'counts');
  let count = 1;
  for (let c = 0; c < 3; c++) {
    if (!Number.isInteger(n[c]) || n[c] < 1 || n[c] > 0xffffffff) throw new Error(`zhc volume: counts[${c}] must be an integer >= 1`);
    if (!Number.isFinite(o[c])) throw new Error(`zhc volume: origin[${c}] is not finite`);
    if (!Number.isFinite(s[c]) || !(s[c] > 0)) throw new Error(`zhc volume: spacing[${c}] must be finite and > 0`);
    if (!Number.isFinite(o[c] + (n[c] - 1) * s[c])) throw new Error(`zhc volume: the grid's far corner along axis ${c} is not finite`);
    count *= n[c];
    if (count > 2 ** 26) throw new Error('zhc volume: more than 2^26 probes');
  }
  let decoded = sh;
  if (!decoded) {
    const e = encodingInfo(encoding);
    if (!bytes || bytes.length < count * e.bytes) throw new Error(`zhc volume: ${count} probes need ${count * e.bytes} bytes`);
    decoded = decodeAll(encoding, bytes, count, params);
  } else if (decoded.length < count * 27) {
    throw new Error(`zhc volume: ${count} probes need ${count * 27} SH3 floats`);
  }
  return Object.freeze({ origin: o, spacing: s, counts: n, count, sh: decoded });
}

// A volume from a whole .zhp file (Uint8Array): parseZhp's checks, then a grid layout (throws
// "not a grid" for none / positions: see docs/runtime.md for scattered probes) and makeVolume's.
export function volumeFromZhp(bytes) {
  const z = parseZhp(bytes);
  if (z.layout !== 'grid') throw new Error(`zhc volume: the .zhp layout is ${z.layout}, not a grid`);
  return makeVolume({ encoding: z.encoding, params: z.params, bytes: z.payload, ...z.grid });
}

// Grid coordinate along one axis: [first probe of the cell, weight of the next] (zhc__volume_axis).
function volumeAxis(p, origin, spacing, n) {
  let t = (p - origin) / spacing;
  const hi = n - 1;
  if (!(t >= 0.0)) t = 0.0;  // below the box, or NaN
  if (t > hi) t = hi;
  let i = Math.floor(t);
  if (n >= 2 && i > n - 2) i = n - 2;
  return [i, n >= 2 ? t - i : 0.0];
}

// Blended SH3 radiance at `position` (the volume's frame): Float64Array(27), index i*3+k
// (zhc_volume_sh3). Probes of weight 0 are skipped.
export function volumeSH3(vol, position) {
  const out = new Float64Array(27);
  const [ix, fx] = volumeAxis(position[0], vol.origin[0], vol.spacing[0], vol.counts[0]);
  const [iy, fy] = volumeAxis(position[1], vol.origin[1], vol.spacing[1], vol.counts[1]);
  const [iz, fz] = volumeAxis(position[2], vol.origin[2], vol.spacing[2], vol.counts[2]);
  const nx = vol.counts[0], ny = vol.counts[1], sh = vol.sh;
  for (let corner = 0; corner < 8; corner++) {
    const bx = corner & 1, by = (corner >> 1) & 1, bz = (corner >> 2) & 1;
    const w = (bx ? fx : 1.0 - fx) * (by ? fy : 1.0 - fy) * (bz ? fz : 1.0 - fz);
    if (w === 0.0) continue;
    const base = ((ix + bx) + nx * ((iy + by) + ny * (iz + bz))) * 27;
    for (let j = 0; j < 27; j++) out[j] += w * sh[base + j];
  }
  return out;
}

// Irradiance (zhc's normalised kernel) at `position` for the surface normal `normal` (normalised
// here; zero or not finite: +Z), both in the volume's frame (zhc axes for a .zhp): float32 RGB,
// the values zhc_volume_irradiance of the C header returns. volumeIrradianceD: the doubles.
export function volumeIrradianceD(vol, position, normal) {
  const sh = volumeSH3(vol, position);
  const n = normalizeOr([normal[0], normal[1], normal[2]]);
  const y = shBasis(n[0], n[1], n[2]);
  const e = [0.0, 0.0, 0.0];
  for (let i = 0; i < 9; i++) {
    const s = IRRADIANCE_BAND_SCALE[BAND_OF[i]];
    for (let k = 0; k < 3; k++) e[k] += s * sh[i * 3 + k] * y[i];
  }
  return e;
}
export function volumeIrradiance(vol, position, normal) {
  const e = volumeIrradianceD(vol, position, normal);
  return [f32(e[0]), f32(e[1]), f32(e[2])];
}
