// The compact path for three.js / WebGL2: a zhc probe grid sampled straight from its STORED bytes.
//
// The probes stay in their packed encoding (zh3_q16 and its relatives: 16 bytes per probe; sh3_q28:
// 28 bytes, padded to 32; sh2_q: 16) in an integer 3D texture (RGBA32UI, one texel per 16 bytes,
// NearestFilter, no mipmaps): probe (x, y, z) of an nx x ny x nz grid occupies texels
// (T x + j, y, z), j < T, of an (T nx) x ny x nz texture, T = texels per probe (1, or 2 for sh3_q28:
// the shader's w0, w1). The shader fetches the 8 corner probes of the cell holding the point
// (texelFetch), decodes each to SH3 radiance, blends them with trilinear weights and evaluates the
// irradiance once: the maths of zhc_volume_irradiance (runtime/zhc_runtime.h) and zhcVolumeIrradiance
// (runtime/zhc.glsl), docs/runtime.md "Probe volumes". Exact to the decode: no filtering of stored
// bytes (which would be wrong: ratios times a per-probe DC, a per-probe zonal axis), no float
// transcode; the only differences from the C header are float32 rounding in the shader.
// A grid with validity / visibility masks (a baked one) also gets its combined mask bytes
// (valid ? visibility : 0) in an R8UI 3D texture, one texel per probe, and the masked, renormalised
// weights of zhc_volume_sh3 (docs/runtime.md "Validity and visibility"); `masks: false` drops them.
// A grid with cell planes gets them in an RG32UI 3D texture, one texel per probe (the plane or
// corner region of the cell whose corner 0 is that probe: .x = bytes 0..3 little-endian, .y = byte
// 4), and the side test of zhc_volume_sh3 (docs/runtime.md "Cell planes", "Corner regions");
// `planes: false` drops them.
//
//   zhcVolumeGlsl({ encoding, params, normalAxes, masked, planes, planesAxes })   GLSL ES 3.00 chunk (zhc_irradiance's included):
//     struct ZhcVolume { vec3 origin; vec3 spacing; vec3 counts; };
//     vec3 zhcVolumeIrradiance(highp usampler3D tex, ZhcVolume v, vec3 position, vec3 normal)
//       position in the grid's frame (a glTF volume: its node's local glTF axes; a .zhp: zhc axes),
//       normal in the same frame (normalised in the shader; zero: +Z of the coefficients' axes); for
//       shAxes "zhc" volumes in glTF axes the chunk maps the normal to zhc axes (normalAxes 'gltf').
//     void zhcVolumeSh3(highp usampler3D tex, ZhcVolume v, vec3 position, out vec3 c[9])  blended SH3
//     masked: both take `highp usampler3D maskTex` after tex, and ZHC_VOLUME_MASKED is defined
//     planes: both take `highp usampler3D planeTex` after tex (and maskTex), ZHC_VOLUME_PLANES is
//       defined, and ZHC_VOLUME_PLANE_AXES_GLTF for planesAxes 'gltf'
//   compactVolume(source, { THREE, matrixWorld, masks, planes })   texture payloads + uniforms (+ Data3DTextures
//     when THREE is given) from a ZhcProbeVolume (the GLTFLoader plugin) or parseZhp(bytes)
//   patchMaterialWithVolume(material, compact, THREE)  onBeforeCompile: a stock three.js material
//     (MeshLambertMaterial, MeshStandardMaterial, MeshPhysicalMaterial, ...) gets the volume's
//     irradiance (times pi, three.js's convention) added to its indirect diffuse light.
//
// Encodings: zh3_q16, zh3_solved_q16, zh3_dering_q16, zh3_channel_q16, zh3_solved_channel_q16,
// sh3_q28, sh2_q. The hallucinating and float encodings throw (use lightProbeGrid for those).
import { zhcIrradianceGlsl } from './zhc_irradiance.glsl.mjs';
import { ENCODINGS, ENCODING_TABLE, PACKED_LAYOUTS, parseZhp } from './zhc_runtime.mjs';

// Packed layout -> RGBA32UI texels per probe (16 bytes each, the last zero padded).
export const COMPACT_TEXELS = Object.freeze({ zh3_q16: 1, sh3_q28: 2, sh2_q: 1 });
// The packed entries decoded without hallucination (the codec table's generated rows).
const COMPACT_ENCODINGS = Object.freeze(ENCODING_TABLE.filter((row) => row.layout in COMPACT_TEXELS &&
  row.hallucination === 'none').map((row) => row.name));

function compactLayout(encoding) {
  if (!COMPACT_ENCODINGS.includes(encoding))
    throw new Error(`zhc compact volume: encoding ${encoding} is not supported (${COMPACT_ENCODINGS.join(', ')}; others: lightProbeGrid)`);
  return PACKED_LAYOUTS[encoding];
}

// The volume chunk for one encoding and parameter set. normalAxes: 'gltf' when the shader's
// normals are in glTF axes and the coefficients in zhc axes (a glTF volume with shAxes "zhc", what
// zhc writes), 'same' when both share the grid's frame (a .zhp, or shAxes "gltf").
// masked: the chunk applies a grid's validity and visibility masks (docs/runtime.md "Validity and
// visibility"): it defines ZHC_VOLUME_MASKED, and zhcVolumeSh3 / zhcVolumeIrradiance take a second
// sampler, the combined mask bytes as an R8UI 3D texture (n_x x n_y x n_z, one texel per probe),
// right after the probe texture. Unmasked (the default) the chunk has neither.
// planes: the chunk applies a grid's cell planes (docs/runtime.md "Cell planes"): it defines
// ZHC_VOLUME_PLANES, and the two functions take the planes as an RG32UI 3D texture (n_x x n_y x
// n_z, texel (x, y, z) = the plane entry of the cell whose corner 0 is probe (x, y, z)) after the
// probe texture and the mask texture. planesAxes: 'zhc' when the grid's frame is the one the
// normals' code is in (a .zhp), 'gltf' when the grid is in glTF axes (a ZHC_light_probes volume:
// the decoded normal n is used as n.yzx; defines ZHC_VOLUME_PLANE_AXES_GLTF). Without planes (the
// default) the chunk has none of it.
export function zhcVolumeGlsl({ encoding, params = {}, normalAxes = 'same', masked = false, planes = false, planesAxes = 'zhc' } = {}) {
  const layout = compactLayout(encoding);
  // The *_channel_q16 encodings imply per-channel axes whatever the params say (a .zhp header's
  // axisMode field is the one of the luminance variants).
  params = { ...params, axisMode: ENCODINGS[encoding].axisMode ?? params.axisMode };
  if (normalAxes !== 'gltf' && normalAxes !== 'same') throw new Error("zhcVolumeGlsl: normalAxes must be 'gltf' or 'same'");
  const texels = COMPACT_TEXELS[layout];
  const decode = {
    zh3_q16: 'zhcSh3Zh3Q16(w0, c);',
    sh3_q28: 'zhcSh3Sh3Q28(w0, texelFetch(tex, t + ivec3(1, 0, 0), 0), c);',
    sh2_q: 'zhcSh3Sh2Q(w0, c);',
  }[layout];
  if (typeof masked !== 'boolean') throw new Error('zhcVolumeGlsl: masked must be true or false');
  if (typeof planes !== 'boolean') throw new Error('zhcVolumeGlsl: planes must be true or false');
  if (planesAxes !== 'zhc' && planesAxes !== 'gltf') throw new Error("zhcVolumeGlsl: planesAxes must be 'zhc' or 'gltf'");
  // The masked / planes chunk's additions; each is empty without them, so the plain text stays as it is.
  const kept = masked || planes;
  const maskDefine = (masked ? '#define ZHC_VOLUME_MASKED 1\n' : '') + (planes ? '#define ZHC_VOLUME_PLANES 1\n' : '') +
    (planes && planesAxes === 'gltf' ? '#define ZHC_VOLUME_PLANE_AXES_GLTF 1\n' : '');
  const maskParam = (masked ? 'highp usampler3D maskTex, ' : '') + (planes ? 'highp usampler3D planeTex, ' : '');
  const maskArg = (masked ? 'maskTex, ' : '') + (planes ? 'planeTex, ' : '');
  const maskDoc = (masked ? `
// Masked (ZHC_VOLUME_MASKED): maskTex holds each probe's combined mask byte m = valid ? visibility
// : 0 at texel (x, y, z); corner b = (bx, by, bz) keeps its weight w_b when bit 7 - (bx + 2 by +
// 4 bz) of its m is set, else 0; the kept weights are divided by their sum (summed over corners
// 0..7 in order); when every corner is dropped the plain weights stay (zhc_volume_sh3's fallback).` : '') + (planes ? `
// Cell planes (ZHC_VOLUME_PLANES): planeTex holds at texel i0 the entry of the cell whose corner 0
// is probe i0: .x = bytes 0..3 little-endian, .y = byte 4. A plane: .x = ou | ov << 8 | offset << 16
// (int16), .y = sides; side = (dot(n, p - c) - offset |spacing| / 65534 >= 0), n the decoded normal
// (zhcPlaneNormal; n.yzx for ZHC_VOLUME_PLANE_AXES_GLTF), c = origin + (i0 + 0.5) spacing. Offset
// -32768 with bit 7 of .y clear: no plane. Offset -32768 with bit 7 set: a corner region
// (docs/runtime.md "Corner regions"; its fields in the grid's axes): q_a = (.x >> 5a) & 31, d_a =
// bit a of .y; side = 1 when along every axis with q_a > 0 (d_a ? s_a >= t_a : s_a < t_a), s_a =
// (p_a - (origin_a + i0_a spacing_a)) 31, t_a = q_a spacing_a; sides = the corners k whose bit a is
// d_a along every such axis. Corner b keeps its weight only when bit (bx + 2 by + 4 bz) of sides
// equals side${masked ? ' (and its mask bit is set)' : ''}; the kept weights are divided by their sum as above, none kept: the
// plain weights.` : '');
  const planeSide = planes ? `
  // The cell's plane or corner region (1 fetch): which side of it p lies on, and the corners' sides.
  uvec2 pe = texelFetch(planeTex, i0, 0).xy;
  int planeOffset = int(pe.x >> 16u) - (pe.x >= 0x80000000u ? 65536 : 0);
  bool hasPlane = planeOffset != -32768 || (pe.y & 0x80u) != 0u;
  uint side = 0u, sides = pe.y;
  if (planeOffset != -32768) {
    vec3 pn = zhcPlaneNormal(pe.x & 255u, (pe.x >> 8u) & 255u);
#ifdef ZHC_VOLUME_PLANE_AXES_GLTF
    pn = pn.yzx;  // the code is in zhc axes, the grid in glTF axes: glTF (x, y, z) = zhc (y, z, x)
#endif
    vec3 c = v.origin + (vec3(i0) + 0.5) * v.spacing;
    side = dot(pn, p - c) - float(planeOffset) * (length(v.spacing) / 65534.0) >= 0.0 ? 1u : 0u;
  } else if (hasPlane) {
    // A corner region: per axis a threshold q_a (0: unbounded) and a direction d_a.
    uvec3 rq = (uvec3(pe.x) >> uvec3(0u, 5u, 10u)) & 31u;
    bvec3 rd = notEqual((uvec3(pe.y) >> uvec3(0u, 1u, 2u)) & 1u, uvec3(0u));
    vec3 rs = (p - (v.origin + vec3(i0) * v.spacing)) * 31.0;  // the point in 31ths of the cell
    vec3 rt = vec3(rq) * v.spacing;
    bvec3 bounded = notEqual(rq, uvec3(0u));
    bvec3 above = greaterThanEqual(rs, rt), below = lessThan(rs, rt);
    bvec3 inAxis = bvec3(!bounded.x || (rd.x ? above.x : below.x), !bounded.y || (rd.y ? above.y : below.y),
                         !bounded.z || (rd.z ? above.z : below.z));
    side = all(inAxis) ? 1u : 0u;
    sides = 0xFFu;  // the corners inside: along a bounded axis those whose bit a is d_a (bit a set: 0xAA, 0xCC, 0xF0)
    if (bounded.x) sides &= rd.x ? 0xAAu : 0x55u;
    if (bounded.y) sides &= rd.y ? 0xCCu : 0x33u;
    if (bounded.z) sides &= rd.z ? 0xF0u : 0x0Fu;
  }` : '';
  const maskWeights = kept ? `${planeSide}
  // ${masked ? 'Masked' : 'Kept'} weights first${masked ? ' (8 mask fetches)' : ''}, then the blend below with w_b = m_b / sum.
  float wm[8];
  float sum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    ivec3 b = ivec3(corner & 1, (corner >> 1) & 1, corner >> 2);
    vec3 wv = mix(1.0 - fr, fr, notEqual(b, ivec3(0)));
    float w = wv.x * wv.y * wv.z;
    wm[corner] = 0.0;
    if (w == 0.0) continue;  // also every corner beyond a count-1 axis: not fetched${planes ? `
    if (hasPlane && ((sides >> uint(corner)) & 1u) != side) continue;  // the other side of the plane / region` : ''}${masked ? `
    uint m = texelFetch(maskTex, i0 + b, 0).r;` : ''}
    ${masked ? 'if (((m >> uint(7 - corner)) & 1u) != 0u) ' : ''}wm[corner] = w;
    sum += wm[corner];
  }` : '';
  const maskUse = kept ? `
    if (sum > 0.0) w = wm[corner] / sum;  // else: every corner dropped, the plain weights` : '';
  const planeNormal = planes ? `// The unit normal of a cell plane's octahedral code (zhc_plane_normal, in float): a = min(ou, 254)
// / 127 - 1, b likewise, z = 1 - |a| - |b|; z < 0 folds (a, b) to ((1 - |b|) s(a), (1 - |a|) s(b)),
// s(t) = t < 0 ? -1 : 1; normalised.
vec3 zhcPlaneNormal(uint ou, uint ov) {
  vec2 ab = vec2(min(uvec2(ou, ov), uvec2(254u))) / 127.0 - 1.0;
  float z = 1.0 - abs(ab.x) - abs(ab.y);
  if (z < 0.0) ab = (1.0 - abs(ab.yx)) * mix(vec2(1.0), vec2(-1.0), lessThan(ab, vec2(0.0)));
  return normalize(vec3(ab, z));
}

` : '';
  return `${zhcIrradianceGlsl(params)}
// ---- zhc compact volume (runtime/web/zhc_volume.glsl.mjs): ${encoding}, ${texels} RGBA32UI texel(s) per probe ----
#define ZHC_VOLUME_TEXELS ${texels}
#define ZHC_VOLUME_NORMAL_FROM_GLTF ${normalAxes === 'gltf' ? 1 : 0}
${maskDefine}const float ZHC_SQRT3 = ${Math.fround(Math.sqrt(3)).toPrecision(9)};
struct ZhcVolume {
  vec3 origin;   // position of probe (0, 0, 0)
  vec3 spacing;  // > 0
  vec3 counts;   // integers >= 1 (as floats: exact below 2^24)
};

// Stored coefficients -> radiance (irradiance storage: L1 / (2/3), L2 / (1/4)).
void zhcStoredToRadiance(inout vec3 c[9]) {
#if ZHC_STORED_IRRADIANCE
  for (int i = 1; i < 4; ++i) c[i] *= 1.5;
  for (int i = 4; i < 9; ++i) c[i] *= 4.0;
#endif
}

// zh3_q16 family -> SH3 radiance: linear SH from the ratios, the zonal L2 expanded on the axis of
// the dequantised L1 (f20 [sqrt3 xy, -sqrt3 yz, (3z^2 - 1)/2, -sqrt3 xz, sqrt3/2 (x^2 - y^2)]).
void zhcSh3Zh3Q16(uvec4 words, out vec3 c[9]) {
  vec3 dc = zhcUnpackDc(words.x);
  vec3 v[3];
  vec3 zq;
  c[0] = dc;
  for (int k = 0; k < 3; ++k) {
    uint w = words[k + 1];
    float d = dc[k];
    c[1][k] = zhcUnit(w & 255u) * ZHC_L1_HI * d;
    c[2][k] = zhcUnit((w >> 8) & 255u) * ZHC_L1_HI * d;
    c[3][k] = zhcUnit((w >> 16) & 255u) * ZHC_L1_HI * d;
    zq[k] = zhcZonalRatio(w >> 24) * d;
  }
  for (int k = 0; k < 3; ++k) v[k] = vec3(-c[3][k], -c[1][k], c[2][k]);
  for (int k = 0; k < 3; ++k) {
    vec3 a = zhcZonalAxis(v, k);
    float f = zq[k];
    c[4][k] = f * (ZHC_SQRT3 * a.x * a.y);
    c[5][k] = f * (-ZHC_SQRT3 * a.y * a.z);
    c[6][k] = f * (0.5 * (3.0 * a.z * a.z - 1.0));
    c[7][k] = f * (-ZHC_SQRT3 * a.x * a.z);
    c[8][k] = f * (0.5 * ZHC_SQRT3 * (a.x * a.x - a.y * a.y));
  }
  zhcStoredToRadiance(c);
}

// sh3_q28 (w1.w is padding) -> SH3 radiance.
void zhcSh3Sh3Q28(uvec4 w0, uvec4 w1, out vec3 c[9]) {
  uint w[7] = uint[7](w0.x, w0.y, w0.z, w0.w, w1.x, w1.y, w1.z);
  vec3 dc = zhcUnpackDc(w[0]);
  c[0] = dc;
  for (int i = 1; i < 9; ++i)
    for (int k = 0; k < 3; ++k) c[i][k] = zhcRatio(i, (w[1 + 2 * k + (i - 1) / 4] >> (8 * ((i - 1) % 4))) & 255u) * dc[k];
  zhcStoredToRadiance(c);
}

// sh2_q -> SH3 radiance (L2 zero).
void zhcSh3Sh2Q(uvec4 words, out vec3 c[9]) {
  vec3 dc = zhcUnpackDcSlot6(words);
  c[0] = dc;
  for (int i = 1; i < 4; ++i)
    for (int k = 0; k < 3; ++k) c[i][k] = zhcRatio(i, zhcByte(words, 6 + 3 * k + i - 1)) * dc[k];
  for (int i = 4; i < 9; ++i) c[i] = vec3(0.0);
  zhcStoredToRadiance(c);
}

${planeNormal}// SH3 radiance of grid probe q (integer coordinates inside the grid).
void zhcVolumeProbe(highp usampler3D tex, ivec3 q, out vec3 c[9]) {
  ivec3 t = ivec3(q.x * ZHC_VOLUME_TEXELS, q.y, q.z);
  uvec4 w0 = texelFetch(tex, t, 0);
  ${decode}
}

// Blended SH3 radiance at p: t = clamp((p - origin) / spacing, 0, counts - 1) (NaN: 0), cell
// i0 = min(floor(t), counts - 2), weights prod (f or 1 - f), f = t - i0; probes of weight 0 skipped.${maskDoc}
void zhcVolumeSh3(highp usampler3D tex, ${maskParam}ZhcVolume v, vec3 p, out vec3 acc[9]) {
  ivec3 n = max(ivec3(v.counts), ivec3(1));
  vec3 t = (p - v.origin) / v.spacing;
  t = mix(vec3(0.0), t, greaterThanEqual(t, vec3(0.0)));  // below the box, or NaN: 0
  t = min(t, vec3(n - 1));
  ivec3 i0 = min(ivec3(t), max(n, ivec3(2)) - 2);
  vec3 fr = t - vec3(i0);${maskWeights}
  for (int i = 0; i < 9; ++i) acc[i] = vec3(0.0);
  for (int corner = 0; corner < 8; ++corner) {
    ivec3 b = ivec3(corner & 1, (corner >> 1) & 1, corner >> 2);
    vec3 wv = mix(1.0 - fr, fr, notEqual(b, ivec3(0)));
    float w = wv.x * wv.y * wv.z;${maskUse}
    if (w == 0.0) continue;
    vec3 c[9];
    zhcVolumeProbe(tex, i0 + b, c);
    for (int i = 0; i < 9; ++i) acc[i] += w * c[i];
  }
}

// Irradiance (zhc's normalised kernel: constant radiance 1 gives 1) at position p for the surface
// normal n (normalised here; zero or not finite: the frame's up), both in the grid's frame.
vec3 zhcVolumeIrradiance(highp usampler3D tex, ${maskParam}ZhcVolume v, vec3 p, vec3 n) {
  vec3 c[9];
  zhcVolumeSh3(tex, ${maskArg}v, p, c);
#if ZHC_VOLUME_NORMAL_FROM_GLTF
  n = n.zxy;
#endif
  return zhcIrradianceSh3(c, zhcNormalizeOrZ(n));
}
// ---- end zhc compact volume ----
`;
}

// The texture payload of a grid: Uint32Array((T nx) * ny * nz * 4), probe (x, y, z)'s stored bytes
// (little-endian words) at texel (T x, y, z) on, zero padded to T * 16 bytes.
export function compactVolumeWords(bytes, bytesPerProbe, counts, texels) {
  const [nx, ny, nz] = counts;
  const count = nx * ny * nz;
  if (bytes.length < count * bytesPerProbe) throw new Error(`zhc compact volume: ${count} probes need ${count * bytesPerProbe} bytes`);
  if (bytesPerProbe > 16 * texels) throw new Error('zhc compact volume: probe larger than its texels');
  if (new Uint8Array(new Uint32Array([1]).buffer)[0] !== 1) throw new Error('zhc compact volume: big-endian platform');
  const out = new Uint32Array(count * texels * 4);
  const u8 = new Uint8Array(out.buffer);
  // Probe p = x + nx (y + ny z) sits at texel T x + T nx (y + ny z) = T p of the row-major texture.
  for (let p = 0; p < count; p++) u8.set(bytes.subarray(p * bytesPerProbe, (p + 1) * bytesPerProbe), p * texels * 16);
  return out;
}

// The combined mask bytes of a grid (docs/runtime.md "Validity and visibility": what reaches the
// GPU): Uint8Array(count), probe p's byte validity[p] ? visibility[p] : 0, absent validity = valid,
// absent visibility = 0xFF; null when both are absent. Probe order = texel order of the R8UI mask
// texture (x fastest).
export function compactVolumeMask(validity, visibility, count) {
  if (!validity && !visibility) return null;
  for (const [what, a] of [['validity', validity], ['visibility', visibility]])
    if (a && a.length < count) throw new Error(`zhc compact volume: ${what} has ${a.length} bytes for ${count} probes`);
  const out = new Uint8Array(count);
  for (let p = 0; p < count; p++) out[p] = validity && !validity[p] ? 0 : visibility ? visibility[p] : 0xFF;
  return out;
}

// The plane texels of a grid (docs/runtime.md "Cell planes": what reaches the GPU):
// Uint32Array(2 count), probe p's texel (.x, .y) = (bytes 0..3 of its entry little-endian, byte 4);
// null when planes are absent or every entry is "no plane" (offset -32768 and bit 7 of byte 4
// clear: nothing to apply).
function compactVolumePlanes(planes, count) {
  if (!planes) return null;
  if (planes.length < 5 * count) throw new Error(`zhc compact volume: planes has ${planes.length} bytes for ${count} probes (5 per probe)`);
  const out = new Uint32Array(2 * count);
  let any = false;
  for (let p = 0; p < count; p++) {
    const e = 5 * p;
    out[2 * p] = (planes[e] | (planes[e + 1] << 8) | (planes[e + 2] << 16) | (planes[e + 3] << 24)) >>> 0;
    out[2 * p + 1] = planes[e + 4];
    if (!(planes[e + 2] === 0x00 && planes[e + 3] === 0x80) || (planes[e + 4] & 0x80)) any = true;  // a plane or a corner region
  }
  return any ? out : null;
}

// Column-major 4x4 helpers (three.js Matrix4.elements order), no three.js needed.
function invertAffine(m) {
  const a = [m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]];  // columns
  const det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[3] * (a[1] * a[8] - a[2] * a[7]) + a[6] * (a[1] * a[5] - a[2] * a[4]);
  if (!Number.isFinite(det) || det === 0) throw new Error('zhc compact volume: matrixWorld is singular');
  if (m[3] !== 0 || m[7] !== 0 || m[11] !== 0 || m[15] !== 1) throw new Error('zhc compact volume: matrixWorld must be affine');
  // Inverse of the 3x3 (column-major), then -inv * translation.
  const inv = [
    (a[4] * a[8] - a[5] * a[7]) / det, (a[2] * a[7] - a[1] * a[8]) / det, (a[1] * a[5] - a[2] * a[4]) / det,
    (a[5] * a[6] - a[3] * a[8]) / det, (a[0] * a[8] - a[2] * a[6]) / det, (a[2] * a[3] - a[0] * a[5]) / det,
    (a[3] * a[7] - a[4] * a[6]) / det, (a[1] * a[6] - a[0] * a[7]) / det, (a[0] * a[4] - a[1] * a[3]) / det,
  ];
  const t = [m[12], m[13], m[14]];
  const r = [0, 1, 2].map((row) => -(inv[row] * t[0] + inv[3 + row] * t[1] + inv[6 + row] * t[2]));
  return [inv[0], inv[1], inv[2], 0, inv[3], inv[4], inv[5], 0, inv[6], inv[7], inv[8], 0, r[0], r[1], r[2], 1];
}

// The compact volume of a grid: source = a ZhcProbeVolume (the GLTFLoader plugin; grid in its
// node's local glTF axes) or parseZhp(bytes) of a .zhp (grid in zhc axes). Options: THREE (the
// three.js module: adds `texture`, a Data3DTexture, and three.js `uniforms`), matrixWorld (the
// grid frame -> world, column-major 16 numbers or a Matrix4; any invertible affine map, rotations
// included; default: a ZhcProbeVolume's single node's matrixWorld, else identity), masks (default
// true: a source with validity or visibility bytes, a ZhcProbeVolume's or parseZhp's, gets the
// masked chunk and an R8UI mask texture of its combined bytes; false: the plain trilinear blend,
// 8 texel fetches per sample fewer and 1 byte per probe less, for grids whose masks do not matter
// where they are sampled or to match three.js's own grid, which cannot apply them). A source whose
// combined bytes are all 0xFF (nothing masked) gets the plain chunk: its masked weights are the
// plain ones divided by their sum, 1 up to rounding. planes (default true: a source with cell
// planes, a ZhcProbeVolume's or parseZhp's `planes`, 5 bytes per probe, gets the chunk with
// ZHC_VOLUME_PLANES and an RG32UI plane texture; false: no side test, 1 fetch per sample and 8
// bytes per probe fewer). A source whose entries are all "no plane" gets no plane texture. The
// plane normals' code is in zhc axes: a ZhcProbeVolume's grid is in glTF axes (planesAxes 'gltf'),
// a parseZhp result's in zhc axes ('zhc'); a source may name its own `planesAxes`.
// Returns { encoding, layout, texelsPerProbe, gpuBytesPerProbe (probe texels, plus 1 with masks,
// plus 8 with planes), gpuBytes (all textures), size: [w, h, d], data, masked, mask (the combined
// bytes or null), maskBytes, planed, planeData (the plane texels or null), planeBytes, planesAxes,
// grid: { origin, spacing, counts }, glsl (zhcVolumeGlsl for it), texture?, maskTexture?,
// planeTexture?, uniforms? }.
export function compactVolume(source, { THREE, matrixWorld, masks = true, planes = true } = {}) {
  const isZhp = source.payload !== undefined;
  if ((source.layout ?? 'grid') !== 'grid' || !source.grid) throw new Error(`zhc compact volume: needs a grid (layout ${source.layout})`);
  const layout = compactLayout(source.encoding);
  const texels = COMPACT_TEXELS[layout];
  const bytes = isZhp ? source.payload : source.bytes;
  const bytesPerProbe = source.bytesPerProbe;
  const { origin, spacing, counts } = source.grid;
  for (let c = 0; c < 3; c++) {
    if (!Number.isInteger(counts[c]) || counts[c] < 1) throw new Error(`zhc compact volume: counts[${c}] must be an integer >= 1`);
    if (!Number.isFinite(origin[c])) throw new Error(`zhc compact volume: origin[${c}] is not finite`);
    if (!Number.isFinite(spacing[c]) || !(spacing[c] > 0)) throw new Error(`zhc compact volume: spacing[${c}] must be finite and > 0`);
  }
  if (counts[0] * texels > 2048 || counts[1] > 2048 || counts[2] > 2048) throw new Error('zhc compact volume: grid larger than a 3D texture (2048)');
  const data = compactVolumeWords(bytes, bytesPerProbe, counts, texels);
  const normalAxes = !isZhp && source.shAxes === 'zhc' ? 'gltf' : 'same';
  if (typeof masks !== 'boolean') throw new Error('zhc compact volume: masks must be true or false');
  if (typeof planes !== 'boolean') throw new Error('zhc compact volume: planes must be true or false');
  const count = counts[0] * counts[1] * counts[2];
  let mask = masks ? compactVolumeMask(source.validity ?? null, source.visibility ?? null, count) : null;
  if (mask && mask.every((m) => m === 0xFF)) mask = null;
  const masked = mask !== null;
  const planesAxes = source.planesAxes ?? (isZhp ? 'zhc' : 'gltf');
  if (planesAxes !== 'zhc' && planesAxes !== 'gltf') throw new Error("zhc compact volume: planesAxes must be 'zhc' or 'gltf'");
  const planeData = planes ? compactVolumePlanes(source.planes ?? null, count) : null;
  const planed = planeData !== null;
  const out = {
    encoding: source.encoding, layout, texelsPerProbe: texels, gpuBytesPerProbe: 16 * texels + (masked ? 1 : 0) + (planed ? 8 : 0),
    gpuBytes: data.byteLength + (masked ? mask.byteLength : 0) + (planed ? planeData.byteLength : 0),
    size: [counts[0] * texels, counts[1], counts[2]], data, masked, mask, maskBytes: masked ? mask.byteLength : 0,
    planed, planeData, planeBytes: planed ? planeData.byteLength : 0, planesAxes,
    grid: { origin: [...origin], spacing: [...spacing], counts: [...counts] },
    normalAxes, glsl: zhcVolumeGlsl({ encoding: source.encoding, params: source.params, normalAxes, masked, planes: planed, planesAxes }),
  };
  let m = matrixWorld?.elements ?? matrixWorld;
  if (!m && !isZhp && source.nodes?.length === 1) {
    source.nodes[0].updateWorldMatrix?.(true, false);
    m = source.nodes[0].matrixWorld.elements;
  }
  m = m ? Array.from(m) : [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  out.matrixWorld = m;
  out.worldToGrid = invertAffine(m);
  if (THREE) {
    const tex = new THREE.Data3DTexture(data, out.size[0], out.size[1], out.size[2]);
    tex.format = THREE.RGBAIntegerFormat;
    tex.type = THREE.UnsignedIntType;
    tex.internalFormat = 'RGBA32UI';
    tex.minFilter = tex.magFilter = THREE.NearestFilter;
    tex.generateMipmaps = false;
    tex.unpackAlignment = 1;
    tex.needsUpdate = true;
    out.texture = tex;
    out.uniforms = {
      zhcVolumeTex: { value: tex },
      zhcVolume: { value: { origin: new THREE.Vector3(...origin), spacing: new THREE.Vector3(...spacing), counts: new THREE.Vector3(...counts) } },
      // world -> grid frame for positions; normals: n_grid = M^T n_world (M = matrixWorld's 3x3).
      zhcWorldToVolume: { value: new THREE.Matrix4().fromArray(out.worldToGrid) },
      zhcWorldNormalToVolume: { value: new THREE.Matrix3().setFromMatrix4(new THREE.Matrix4().fromArray(m)).transpose() },
    };
    if (masked) {
      // The combined mask bytes: one R8UI texel per probe, (x, y, z) at texel (x, y, z).
      const mtex = new THREE.Data3DTexture(mask, counts[0], counts[1], counts[2]);
      mtex.format = THREE.RedIntegerFormat;
      mtex.type = THREE.UnsignedByteType;
      mtex.internalFormat = 'R8UI';
      mtex.minFilter = mtex.magFilter = THREE.NearestFilter;
      mtex.generateMipmaps = false;
      mtex.unpackAlignment = 1;
      mtex.needsUpdate = true;
      out.maskTexture = mtex;
      out.uniforms.zhcVolumeMaskTex = { value: mtex };
    }
    if (planed) {
      // The cell planes: one RG32UI texel per probe, (x, y, z) at texel (x, y, z).
      const ptex = new THREE.Data3DTexture(planeData, counts[0], counts[1], counts[2]);
      ptex.format = THREE.RGIntegerFormat;
      ptex.type = THREE.UnsignedIntType;
      ptex.internalFormat = 'RG32UI';
      ptex.minFilter = ptex.magFilter = THREE.NearestFilter;
      ptex.generateMipmaps = false;
      ptex.unpackAlignment = 1;
      ptex.needsUpdate = true;
      out.planeTexture = ptex;
      out.uniforms.zhcVolumePlaneTex = { value: ptex };
    }
  }
  return out;
}

// A stock three.js material lit by the compact volume: onBeforeCompile adds pi E (three.js's
// irradiance convention; BRDF_Lambert = albedo / pi makes a white Lambertian surface show E) at the
// fragment's world position and normal, where three.js adds its light probes. The volume replaces
// nothing else (add no LightProbeGrid for the same probes). compact = compactVolume(..., { THREE }).
// WebGPURenderer's node materials (three/webgpu) have no GLSL chunks to patch: refused here, in one
// message naming what is unsupported and what to use, before any shader is built.
export function patchMaterialWithVolume(material, compact, THREE) {
  if (material?.isNodeMaterial || !THREE?.ShaderChunk?.lights_fragment_begin)
    throw new Error('zhc compact volume: patchMaterialWithVolume patches the GLSL of WebGLRenderer materials; ' +
      (material?.isNodeMaterial ? `${material.type} is a node material` : 'this three.js namespace has no ShaderChunk (three/webgpu)') +
      ', and WebGPURenderer is not supported by the compact path: render with WebGLRenderer, or light the scene with ' +
      'volume.lightProbeGrid(LightProbeGrid), which applies no validity, visibility masks or cell planes (it leaks through walls)');
  if (!compact.uniforms) throw new Error('zhc compact volume: build it with compactVolume(source, { THREE })');
  const begin = 'vec3 irradiance = getAmbientLightIrradiance( ambientLightColor );';
  if (!THREE.ShaderChunk.lights_fragment_begin.includes(begin))
    throw new Error('zhc compact volume: this three.js has no lights_fragment_begin irradiance line to patch');
  const decl = `precision highp usampler3D;
${compact.glsl}
uniform highp usampler3D zhcVolumeTex;
${compact.masked ? 'uniform highp usampler3D zhcVolumeMaskTex;\n' : ''}${compact.planed ? 'uniform highp usampler3D zhcVolumePlaneTex;\n' : ''}uniform ZhcVolume zhcVolume;
uniform mat4 zhcWorldToVolume;
uniform mat3 zhcWorldNormalToVolume;
`;
  const add = `${begin}
	{
		vec3 zhcWorldPos = ( ( vec4( geometryPosition, 1.0 ) - viewMatrix[ 3 ] ) * viewMatrix ).xyz;
		vec3 zhcWorldNormal = transformNormalByInverseViewMatrix( geometryNormal, viewMatrix );
		irradiance += PI * zhcVolumeIrradiance( zhcVolumeTex, ${compact.masked ? 'zhcVolumeMaskTex, ' : ''}${compact.planed ? 'zhcVolumePlaneTex, ' : ''}zhcVolume, ( zhcWorldToVolume * vec4( zhcWorldPos, 1.0 ) ).xyz,
			zhcWorldNormalToVolume * zhcWorldNormal );
	}`;
  const previous = material.onBeforeCompile;
  material.onBeforeCompile = (shader, renderer) => {
    previous?.call(material, shader, renderer);
    Object.assign(shader.uniforms, compact.uniforms);
    shader.fragmentShader = shader.fragmentShader
      .replace('#include <lights_pars_begin>', `#include <lights_pars_begin>\n${decl}`)
      .replace('#include <lights_fragment_begin>', THREE.ShaderChunk.lights_fragment_begin.replace(begin, add));
  };
  let h = 0x811c9dc5;  // FNV-1a of the chunk: one program per encoding and parameter set
  for (let i = 0; i < compact.glsl.length; i++) h = Math.imul(h ^ compact.glsl.charCodeAt(i), 0x01000193) >>> 0;
  const key = `zhc-compact-${h.toString(16)}`;
  const previousKey = material.customProgramCacheKey?.bind(material);
  material.customProgramCacheKey = () => `${previousKey ? previousKey() : ''}${key}`;
  material.needsUpdate = true;
  return material;
}

// parseZhp + compactVolume for a whole uncompressed .zhp file's bytes.
export function compactVolumeFromZhp(bytes, options) { return compactVolume(parseZhp(bytes), options); }
