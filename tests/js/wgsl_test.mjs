// runtime/zhc.wgsl in headless Chromium's WebGPU (CTest: js.wgsl).
// Usage: node wgsl_test.mjs ZHC_BINARY WORK_DIR [CHROMIUM]
//
// Reference chain: runtime/web/zhc_runtime.mjs returns the same float32 numbers as the codec's
// decode_probe and irradiance(hub, n) (bit for bit, shown by js.runtime_decode against `zhc convert`),
// and the C header runtime/zhc_runtime.h is compared with the same codec by test_runtime_c; the
// WGSL results are compared here with the JS runtime, with the error metric and bounds of the GLSL /
// HLSL tests (tests/gl/runtime_gl_entries.inl, ported below): every difference in units of u S,
// u = 2^-24, S = the per-channel sum of the magnitudes of the evaluation's terms (quantised
// coefficients counted at their ratio bound times the DC); bounds 16 (float layouts) / 32
// (quantised) for irradiance, 16 for decoded coefficients, plus 2^-120 absolute (denormal flush).
//
//  1. every entry of the runtime's generated encoding table (ENCODING_TABLE of zhc_runtime.mjs;
//     runtime_tables.check keeps it and zhc.wgsl's equal to the codec table) takes its family,
//     hallucination and axis from there; zhc.wgsl's ids and constants must agree;
//  2. 10 batches x 10,000 probes per encoding (lit scenes with coloured directional / blurred lights
//     and ambient, random Gaussian SH, fixtures' bake-like probes and special cases; exposure
//     10^-3..10^3), each batch with its own header parameters (bits, sqrt, bound, DC format, zonal
//     mapping, axis mode, radiance / irradiance storage, luminance weights), encoded by `zhc convert`;
//     plus 2 batches x 10,000 probes of random bytes;
//  3. a loopback HTTP server and headless Chromium (WebGPU on SwiftShader): tests/js/browser/
//     wgsl_page.mjs compiles zhc.wgsl + tests/js/browser/wgsl_kernel.wgsl and runs every batch in a
//     compute shader (zhcDecode + zhcIrradiance per probe, uniform random normals), posting the floats;
//  4. probe volumes (runtime/zhc_volume.wgsl, zhcVolumeIrradiance) per encoding on two grids of
//     encoded probes (6x5x4 default parameters, 5x1x3 non-default ones, a count-1 axis), 10,000
//     points in and around the box plus every probe's position, against the JS runtime's
//     volumeIrradianceD (a port of the C header's zhc_volume_irradiance_d, bit-identical per
//     js.runtime_volume) and the test's own double twin, with the bound of test_runtime_gl's volume test;
//     Masked volumes (runtime/zhc_volume_mask.wgsl) with random validity and visibility, and volumes
//     with cell planes (runtime/zhc_volume_plane.wgsl, zhcVolumeIrradiancePlanes): random planes
//     and corner regions (tests/js/planes_fixtures.mjs) with validity and masks in zhc axes, and
//     planes and regions alone on the same grid in glTF axes (the override
//     ZHC_VOLUME_PLANE_AXES_GLTF), against the runtime's volumeIrradianceD on the zhc-axes volume;
//     the corners each plane or region keeps must equal the JS side's, and samples must fall both
//     inside and outside regions;
//     Scattered probes (zhc_volume.wgsl's zhcVolumeTetraSh3 / zhcVolumeTetraIrradiance): `points`
//     .zhp files written by `zhc convert` (its qhull tetrahedra) of 150 random positions, as sh3,
//     zh3_q16, sh3_q28 and hall_adaptive_q16, with and without validity, the kernel given the 4
//     probes and weights of the runtime's volumeTetraWeights (the C header's zhc_volume_tetra_weights,
//     bit-identical per js.runtime_tetra), against volumeSH3 / volumeIrradianceD at points inside and
//     outside the hull and at every probe; weight-0 probes point at a probe of 0xFF bytes (NaN / Inf),
//     which the blend must not read; every probe equal (sh3, zh3_q16) and an affine field (sh3)
//     against their own double twin;
//  5. asserts: no console error or WebGPU validation error, no compilation message, every probe and
//     sample of every encoding compared, every value within its bound; prints the per-encoding maxima.
// Time bounded: the browser part times out after 420 s (Chromium killed).
import fs from 'node:fs';
import path from 'node:path';
import { execFile } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import { randomProbes, makeRand, checker } from './fixtures.mjs';
import { randomPlanes, planeMargin, planeSideAt, gltfProbeOrder, gltfPlanes, gltfBits } from './planes_fixtures.mjs';
import { chromiumPages, readBody } from './chromium_page.mjs';
import * as runtime from '../../runtime/web/zhc_runtime.mjs';

const t0 = Date.now();
const [zhc, workArg, chromiumArg] = process.argv.slice(2);
if (!zhc || !workArg) {
  console.error('usage: node wgsl_test.mjs ZHC_BINARY WORK_DIR [CHROMIUM]');
  process.exit(2);
}
const chromium = chromiumArg || '/usr/bin/chromium';
const work = path.resolve(workArg);
fs.mkdirSync(work, { recursive: true });
const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.resolve(here, '..', '..');
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const execFileP = promisify(execFile);

const kBatches = 10, kGarbageBatches = 2, kBatchSize = 10000;
const kU = 2 ** -24, kAbs = 2 ** -120;
const kCFloat = 16, kCQuant = 32, kCDecode = 16;

// --- 1. zhc.wgsl's encoding table ------------------------------------------------------------------
const wgslText = fs.readFileSync(path.join(repo, 'runtime', 'zhc.wgsl'), 'utf8');
const constants = {};
for (const m of wgslText.matchAll(/^const (ZHC_\w+): u32 = (\d+)u;/gm)) constants[m[1]] = Number(m[2]);
// The test's own copies of the constants (the bounds depend on the family) must agree with the file.
const F = { SH3_F32: 0, SH2_F32: 1, ZH3_F32: 2, ZH3_Q16: 3, SH3_Q28: 4, SH2_Q: 5 };
const H = { NONE: 0, AMBDIR: 1, SPHERE: 2, CURVE: 3, CURVE_ADAPTIVE: 4 };
for (const [k, v] of Object.entries(F)) check(constants[`ZHC_LAYOUT_${k}`] === v, `zhc.wgsl: ZHC_LAYOUT_${k} = ${v}u`);
for (const [k, v] of Object.entries(H)) check(constants[`ZHC_HALL_MODE_${k}`] === v, `zhc.wgsl: ZHC_HALL_MODE_${k} = ${v}u`);
// Every entry's WGSL format comes from the runtime's generated table (ENCODING_TABLE of
// zhc_runtime.mjs: layout, hallucination, axis), whose rows zhc.wgsl's generated table holds too
// (runtime_tables.check compares both files with the codec table); the file's ids must be the rows'.
const familyBytes = [108, 48, 60, 16, 28, 16];
const encodings = [];
check(constants.ZHC_ENCODING_COUNT === runtime.ENCODING_TABLE.length, `zhc.wgsl: ZHC_ENCODING_COUNT = ${runtime.ENCODING_TABLE.length}u`);
runtime.ENCODING_TABLE.forEach((row, id) => {
  const name = row.name;
  check(constants[`ZHC_ENC_${name.toUpperCase()}`] === id, `zhc.wgsl: ZHC_ENC_${name.toUpperCase()} = ${id}u`);
  const e = { family: constants[`ZHC_LAYOUT_${row.layout.toUpperCase()}`], hallucination: constants[`ZHC_HALL_MODE_${row.hallucination.toUpperCase()}`], axis: row.axis };
  check(e.family !== undefined && e.hallucination !== undefined, `${name}: zhc.wgsl defines its family and hallucination`);
  const info = runtime.ENCODINGS[name];
  check(familyBytes[e.family] === info.bytes, `${name}: zhc.wgsl's family has the entry's ${info.bytes} bytes`);
  if (info.axisMode) check(e.axis === info.axisMode, `${name}: the table's axis is the runtime's fixed '${info.axisMode}'`);
  if (!process.env.ZHC_WGSL_ONLY || process.env.ZHC_WGSL_ONLY.split(',').includes(name))  // debugging aid
    encodings.push({ name, ...e, bytes: info.bytes, packed: !!info.packed });
});

// A second, independent WGSL front end (npm wgsl_reflect, a parser + reflection; Chromium's Tint is
// the only full validator available): zhc.wgsl alone and with zhc_volume.wgsl and the test kernels
// parse, the uniform layouts are the ones the file header documents (and formatBytes below writes),
// the documented functions exist, and a broken copy is rejected (the check can fail).
{
  const { WgslReflect } = await import('wgsl_reflect/wgsl_reflect.module.js');  // (its package "main" does not load as ESM)
  const volumeText = ['zhc_volume.wgsl', 'zhc_volume_mask.wgsl', 'zhc_volume_plane.wgsl']
    .map((f) => fs.readFileSync(path.join(repo, 'runtime', f), 'utf8')).join('\n');
  const kernelText = fs.readFileSync(path.join(here, 'browser', 'wgsl_kernel.wgsl'), 'utf8');
  const parse = (code) => {
    try {
      return new WgslReflect(code);
    } catch (err) {
      return { error: String(err?.message ?? err) };
    }
  };
  const alone = parse(wgslText), full = parse([wgslText, volumeText, kernelText].join('\n'));
  check(!alone.error, `wgsl_reflect parses runtime/zhc.wgsl ${alone.error ?? ''}`);
  check(!full.error, `wgsl_reflect parses zhc.wgsl + zhc_volume.wgsl + the test kernels ${full.error ?? ''}`);
  check(!!parse(wgslText.replace('fn zhcNeg(x: f32) -> f32 {', 'fn zhcNeg(x: f32) -> f32 { let = ;')).error, 'wgsl_reflect rejects a broken copy');
  if (!full.error) {
    const layout = (name) => {
      const st = full.structs.find((x) => x.name === name);
      return st ? `${st.size}: ${st.members.map((m) => `${m.name}@${m.offset}`).join(' ')}` : 'missing';
    };
    check(layout('ZhcFormat') === '80: family@0 hallucination@4 bits@8 sqrtEncoding@12 l2Bound@16 dcFormat@20 zonalMapping@24 axisMode@28 kind@32 luminance@48 curve@64',
      `ZhcFormat uniform layout (${layout('ZhcFormat')})`);
    check(layout('ZhcVolume') === '48: origin@0 spacing@16 counts@32', `ZhcVolume uniform layout (${layout('ZhcVolume')})`);
    const fns = new Set(full.functions.map((f) => f.name));
    for (const f of ['zhcDecode', 'zhcIrradiance', 'zhcIrradianceSh3', 'zhcEvalSh3', 'zhcDecodeSh3F32', 'zhcDecodeSh2F32', 'zhcDecodeZh3F32',
      'zhcDecodeZh3Q16', 'zhcDecodeSh3Q28', 'zhcDecodeSh2Q', 'zhcIrradianceSh3F32', 'zhcIrradianceSh2F32', 'zhcIrradianceZh3F32',
      'zhcIrradianceZh3Q16', 'zhcIrradianceSh3Q28', 'zhcIrradianceSh2Q', 'zhcVolumeSh3', 'zhcVolumeIrradiance', 'zhcVolumeSh3Masked',
      'zhcVolumeIrradianceMasked', 'zhcPlaneNormal', 'zhcVolumePlaneKeep', 'zhcVolumeSh3Planes', 'zhcVolumeIrradiancePlanes',
      'zhcVolumeTetraSh3', 'zhcVolumeTetraIrradiance'])
      check(fns.has(f), `WGSL function ${f} exists`);
    check(!alone.error && alone.entry.compute.length === 0 && alone.storage.length === 0 && alone.uniforms.length === 0,
      'runtime/zhc.wgsl declares no bindings and no entry points');
  }
}

const isQuantised = (e) => e.family >= F.ZH3_Q16;
const isZonal = (e) => e.family === F.ZH3_F32 || e.family === F.ZH3_Q16 || e.hallucination !== H.NONE;
const hasL2 = (e) => e.family === F.SH3_F32 || e.family === F.SH3_Q28 || isZonal(e);
// The axis the shader is told: the entry's fixed one, else the header's.
const axisMode = (e, p) => (e.axis === 'luminance' ? 0 : e.axis === 'channel' ? 1 : (p.axisMode === 'channel' ? 1 : 0));

// --- 2. probes and parameters -------------------------------------------------------------------
// Header parameters of batch b (tests/gl/runtime_gl_entries.inl batch_params): `flags` for zhc convert.
function batchParams(e, b, rand) {
  const p = { ...runtime.DEFAULT_PARAMS, luminanceWeights: [...runtime.DEFAULT_LUMINANCE] };
  const flags = [];
  if (b === 0) return { p, flags };
  if (b % 4 === 3) p.luminanceWeights = [0.05 + rand(), 0.05 + rand(), 0.05 + rand()];
  if (b % 2) {
    p.kind = 'irradiance';
    flags.push('--irradiance');
  }
  if (isQuantised(e)) {
    p.bits = b === 1 ? 8 : 2 + (b * 3) % 7;
    p.sqrt = ((b >> 1) % 2) === 1;
    p.dcFormat = ['r11g11b10f', 'rgb9e5', 'half'][b % 3];
    if (e.family !== F.SH2_Q && p.dcFormat === 'half') p.dcFormat = 'rgb9e5';
    flags.push('--bits', String(p.bits), '--dc', p.dcFormat);
    if (p.sqrt) flags.push('--sqrt');
    // `zhc convert` refuses a storage option the entry does not use (cli storage_options_used):
    // those stay at their defaults, which is what the file's header then holds.
    if (e.family === F.SH3_Q28) {
      p.l2Bound = (Math.floor(b / 3) % 2) ? 'loose' : 'tight';
      flags.push('--bound', p.l2Bound);
    }
    if (e.family === F.SH3_Q28 || e.family === F.ZH3_Q16) {
      p.zonalMapping = ['affine', 'zero', 'symmetric'][(b >> 1) % 3];
      flags.push('--zonal-map', p.zonalMapping);
    }
    if (e.axis === 'format') {
      p.axisMode = ((b >> 2) % 2) ? 'channel' : 'luminance';
      flags.push('--axis', p.axisMode);
    }
  }
  return { p, flags };
}

// Probe kinds (i % 10): 0-3 lit scenes, 4-6 random Gaussian SH, 7-9 fixtures' bake-like probes and
// special cases; every probe times an exposure 10^(-3..3).
const kY = (x, y, z) => runtime.shBasis(x, y, z);
function batchProbes(seed) {
  const rand = makeRand(seed);
  const gauss = () => Math.sqrt(-2 * Math.log(1 - rand())) * Math.cos(2 * Math.PI * rand());
  const dir = () => {
    const z = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - z * z));
    return [r * Math.cos(phi), r * Math.sin(phi), z];
  };
  const fixtures = randomProbes(kBatchSize, seed ^ 0x5a5a);
  const out = [];
  for (let i = 0; i < kBatchSize; i++) {
    const exposure = 10 ** (-3 + 6 * rand());
    const sh = Array.from({ length: 9 }, () => [0, 0, 0]);
    const kind = i % 10;
    if (kind < 4) {
      const amb = [0, 1, 2].map(() => exposure * rand() * 0.2);
      for (let k = 0; k < 3; k++) sh[0][k] = amb[k] * 2 * Math.sqrt(Math.PI);
      const lights = 1 + Math.floor(rand() * 4);
      for (let l = 0; l < lights; l++) {
        const d = dir(), b = kY(...d), s = exposure * 10 ** (2 * rand() - 1);
        const col = [s * rand(), s * rand(), s * rand()];
        // directional, or blurred (band l damped by exp(-w l (l + 1)): a smooth lobe)
        const w = rand() < 0.5 ? 0 : 2 * rand();
        for (let i2 = 0; i2 < 9; i2++) {
          const l2 = i2 === 0 ? 0 : i2 < 4 ? 1 : 2;
          const damp = Math.exp(-w * l2 * (l2 + 1));
          for (let k = 0; k < 3; k++) sh[i2][k] += col[k] * b[i2] * damp;
        }
      }
    } else if (kind < 7) {
      for (let i2 = 0; i2 < 9; i2++) for (let k = 0; k < 3; k++) sh[i2][k] = exposure * gauss();
      if (rand() < 0.5) for (let k = 0; k < 3; k++) sh[0][k] = Math.abs(sh[0][k]) * 4;
    } else {
      const f = fixtures[i];
      const scale = i < 7 ? 1 : exposure;  // the special cases as they are
      for (let i2 = 0; i2 < 9; i2++) for (let k = 0; k < 3; k++) sh[i2][k] = f[i2][k] * scale;
    }
    out.push(sh);
  }
  return out;
}

async function pool(jobs, width) {
  const res = new Array(jobs.length);
  let next = 0;
  await Promise.all(Array.from({ length: width }, async () => {
    while (next < jobs.length) {
      const j = next++;
      res[j] = await jobs[j]();
    }
  }));
  return res;
}

// sh3 .zhp of every batch's probes, then every encoding x batch by `zhc convert`.
const cases = [];  // { e, b, garbage, zhp | bytes, p }
{
  const jobs = [];
  for (let b = 0; b < kBatches; b++) {
    fs.writeFileSync(W(`batch${b}.json`), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
      probes: batchProbes(1000 + b).map((sh, i) => ({ position: [i % 100, Math.floor(i / 100), 0], sh3: sh })) }));
    jobs.push(() => execFileP(zhc, ['convert', W(`batch${b}.json`), '-o', W(`batch${b}.zhp`), '--to', 'sh3']));
  }
  await pool(jobs, 2);
  const rand = makeRand(4711);
  const convert = [];
  for (const e of encodings) {
    for (let b = 0; b < kBatches + kGarbageBatches; b++) {
      const garbage = b >= kBatches;
      const { p, flags } = batchParams(e, garbage ? b - kBatches + 1 : b, rand);
      const c = { e, b, garbage, p };
      if (!garbage) {
        c.zhp = W(`${e.name}_${b}.zhp`);
        convert.push(() => execFileP(zhc, ['convert', W(`batch${b}.zhp`), '-o', c.zhp, '--to', e.name, ...flags]));
      }
      cases.push(c);
    }
  }
  await pool(convert, 2);
}
const tEncoded = Date.now();
console.log(`encoded ${encodings.length} encodings x ${kBatches} batches of ${kBatchSize} probes with zhc convert in ${((tEncoded - t0) / 1000).toFixed(1)} s`);

// The job of one case: its probe bytes, header parameters (from the .zhp itself for encoded ones;
// the batch's luminance weights override the header's, both sides decode with them), normals.
function loadCase(c, rand) {
  if (c.garbage) {
    c.bytes = new Uint8Array(kBatchSize * c.e.bytes);
    for (let j = 0; j < c.bytes.length; j++) c.bytes[j] = Math.floor(rand() * 256);
  } else {
    const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(c.zhp)));
    check(z.encoding === c.e.name && z.count === kBatchSize, `${c.zhp}: ${kBatchSize} ${c.e.name} probes`);
    for (const key of ['bits', 'sqrt', 'l2Bound', 'dcFormat', 'zonalMapping', 'axisMode', 'kind'])
      if (c.e.packed || key === 'kind') check(z.params[key] === c.p[key], `${c.zhp}: header ${key} ${z.params[key]} is the batch's ${c.p[key]}`);
    c.p = { ...z.params, luminanceWeights: c.p.luminanceWeights };
    c.bytes = z.payload;
  }
  c.normals = new Float32Array(kBatchSize * 3);
  for (let i = 0; i < kBatchSize; i++) {
    const z = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - z * z));
    c.normals.set([r * Math.cos(phi), r * Math.sin(phi), z], 3 * i);
  }
}
const enumIndex = {
  l2Bound: ['tight', 'loose'], dcFormat: ['r11g11b10f', 'rgb9e5', 'half'], zonalMapping: ['affine', 'zero', 'symmetric'],
  kind: ['radiance', 'irradiance'],
};
// ZhcFormat in the uniform address space: 9 u32 at 0..32, luminance vec3 at 48, curve vec2 at 64; 80 bytes.
function formatBytes(e, p) {
  const buf = new ArrayBuffer(80);
  const u = new Uint32Array(buf), f = new Float32Array(buf);
  u.set([e.family, e.hallucination, p.bits, p.sqrt ? 1 : 0, enumIndex.l2Bound.indexOf(p.l2Bound),
    enumIndex.dcFormat.indexOf(p.dcFormat), enumIndex.zonalMapping.indexOf(p.zonalMapping), axisMode(e, p),
    enumIndex.kind.indexOf(p.kind)]);
  f.set(p.luminanceWeights, 12);
  f.set([runtime.HALLUCINATE_CURVE_A, runtime.HALLUCINATE_CURVE_B], 16);
  return new Uint8Array(buf);
}
// A job for the page (wgsl_page.mjs): header, the kernel's Job uniform (stride, count, grid), the
// format uniform, the probe words, the item inputs.
function jobBytes(kernel, count, outFloats, itemFloats, stride, grid, fmt, words, itemData, maskOffset = 0, planeOffset = 0) {
  const head = new Uint32Array(16);
  head.set([kernel, count, outFloats, itemFloats, words.length]);
  const job = new ArrayBuffer(64);
  new Uint32Array(job, 0, 4).set([stride, count, maskOffset, planeOffset]);
  if (grid) {
    new Float32Array(job, 16, 8).set([...grid.origin, 0, ...grid.spacing, 0]);
    new Uint32Array(job, 48, 4).set([...grid.counts, 0]);
  }
  return Buffer.concat([Buffer.from(head.buffer), Buffer.from(job), Buffer.from(fmt), Buffer.from(words.buffer, words.byteOffset, words.byteLength),
    Buffer.from(itemData.buffer, itemData.byteOffset, itemData.byteLength)]);
}
function wordsOf(bytes) {
  const words = new Uint32Array(bytes.length / 4);
  new Uint8Array(words.buffer).set(bytes);
  return words;
}

// --- error scale (tests/gl/runtime_gl_entries.inl probe_scale, check_value) -----------------------
const ratioBoundRadiance = (i, bound) => (i < 4 ? Math.sqrt(3) : i === 6 ? Math.sqrt(5) : bound === 'tight' ? Math.sqrt(15) / 2 : Math.sqrt(5));
function probeScale(e, p, d) {
  const s = { irradiance: [0, 0, 0], coeff: Array.from({ length: 9 }, () => [0, 0, 0]), defined: true };
  const quant = isQuantised(e);
  const w = p.luminanceWeights;
  const m = Array.from({ length: 9 }, () => [0, 0, 0]);
  for (let k = 0; k < 3; k++) {
    const dc = Math.abs(d[k]);
    m[0][k] = dc;
    for (let i = 1; i < 9; i++) m[i][k] = quant ? Math.max(Math.abs(d[i * 3 + k]), ratioBoundRadiance(i, p.l2Bound) * dc) : Math.abs(d[i * 3 + k]);
  }
  const kappa = [1, 1, 1];
  const vec = (k) => [-d[9 + k], -d[3 + k], d[6 + k]];
  const len = (v) => Math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  const vmag = (k) => Math.sqrt(m[1][k] * m[1][k] + m[2][k] * m[2][k] + m[3][k] * m[3][k]);
  if (isZonal(e)) {
    if (axisMode(e, p) === 0) {
      const lum = [0, 0, 0];
      let mag = 0, allZero = true;
      for (let k = 0; k < 3; k++) {
        const v = vec(k);
        for (let j = 0; j < 3; j++) lum[j] += w[k] * v[j];
        mag += Math.abs(w[k]) * vmag(k);
        allZero = allZero && len(v) === 0;
      }
      const l = len(lum);
      kappa.fill((mag === 0 || allZero) ? 1 : (l > 0 ? mag / l : Infinity));
    } else {
      for (let k = 0; k < 3; k++) {
        const l = len(vec(k)), mag = vmag(k);
        kappa[k] = (mag === 0 || l === 0) ? 1 : mag / l;
        if (!Number.isFinite(l)) kappa[k] = Infinity;
      }
    }
  }
  const gOf = (a, b) => {
    const pmax = Math.sqrt(3);
    return Math.abs(a) * pmax + Math.abs(b) + Math.max(Math.abs(b), Math.abs(2 * a * pmax + b));
  };
  let g = 0;
  if (e.hallucination === H.AMBDIR) g = 2 * Math.sqrt(15) / 3;
  if (e.hallucination === H.SPHERE) g = gOf(2 * Math.sqrt(5) / 3, -Math.sqrt(5 / 3));
  if (e.hallucination === H.CURVE) g = gOf(0.6, 0.08);
  if (e.hallucination === H.CURVE_ADAPTIVE) g = gOf(3.5 * 0.6, 3.5 * 0.08);
  if (p.kind === 'irradiance' && e.family === F.SH2_F32) g *= 8 / 3;
  for (let k = 0; k < 3; k++) {
    if (!Number.isFinite(kappa[k])) s.defined = false;
    const l1 = m[1][k] + m[2][k] + m[3][k];
    let l2 = 0, zonalScale = 0;
    if (isZonal(e)) {
      let f20 = 0;
      for (let i = 4; i < 9; i++) f20 += d[i * 3 + k] * d[i * 3 + k];
      f20 = Math.sqrt(f20);
      if (quant && e.hallucination === H.NONE) f20 = Math.max(f20, Math.sqrt(5) * m[0][k]);
      zonalScale = (f20 + g * vmag(k)) * (1 + kappa[k]);
      l2 = 3 * runtime.kY20 * zonalScale;
    } else if (hasL2(e)) {
      for (let i = 4; i < 9; i++) l2 += 0.631 * m[i][k];
    }
    s.irradiance[k] = runtime.kY00 * m[0][k] + (2 / 3) * runtime.kY1 * l1 + 0.25 * l2;
    for (let i = 0; i < 9; i++) s.coeff[i][k] = (i >= 4 && isZonal(e)) ? Math.sqrt(3) * zonalScale : m[i][k];
  }
  return s;
}
const FLT_MAX = 3.4028234663852886e38;
function checkValue(t, key, ref, gpu, scale, c, what) {
  if (!Number.isFinite(ref)) {
    t.skippedNonfinite++;
    return;
  }
  t.compared++;
  if (!Number.isFinite(gpu)) {
    if (scale * 64 >= FLT_MAX) {
      t.overflowOk++;
      return;
    }
  } else {
    const err = Math.abs(gpu - ref);
    const units = scale > 0 ? err / (kU * scale) : (err > 0 ? Infinity : 0);
    if (err <= kAbs) return;
    t[key] = Math.max(t[key], units);
    if (err <= c * kU * scale + kAbs) return;
  }
  if (t.failures++ === 0) t.firstFailure = `${what()}: reference ${ref} wgsl ${gpu} scale ${scale.toExponential(4)} (${(Math.abs(gpu - ref) / (kU * scale)).toFixed(2)} u S, bound ${c})`;
}
const tally = () => ({ maxIrr: 0, maxDec: 0, compared: 0, skippedNonfinite: 0, skippedIllcond: 0, overflowOk: 0, failures: 0, firstFailure: '', probes: 0 });
const tallies = new Map(encodings.map((e) => [e.name, { valid: tally(), garbage: tally() }]));

// Compares one case's WGSL output (30 floats per probe) with the JS runtime.
function compareCase(c, gpu) {
  const t = tallies.get(c.e.name)[c.garbage ? 'garbage' : 'valid'];
  const cIrr = isQuantised(c.e) ? kCQuant : kCFloat;
  t.probes += kBatchSize;
  for (let i = 0; i < kBatchSize; i++) {
    const ref = runtime.decodeProbe(c.e.name, c.bytes, i * c.e.bytes, c.p);
    const n = [c.normals[3 * i], c.normals[3 * i + 1], c.normals[3 * i + 2]];
    const irr = runtime.irradiance(ref, n);
    const s = probeScale(c.e, c.p, ref);
    if (!s.defined) {
      ++t[ref.every(Number.isFinite) ? 'skippedIllcond' : 'skippedNonfinite'];
      continue;
    }
    const what = (v) => {  // built only for the first failure
      const hex = Array.from(c.bytes.subarray(i * c.e.bytes, (i + 1) * c.e.bytes), (x) => x.toString(16).padStart(2, '0')).join('');
      return `${c.e.name}${c.garbage ? ' random bytes' : ''} batch ${c.b} probe ${i} (bytes ${hex}, normal ${n.join(',')}) ${v}`;
    };
    for (let j = 0; j < 27; j++)
      checkValue(t, 'maxDec', ref[j], gpu[30 * i + j], s.coeff[Math.floor(j / 3)][j % 3], kCDecode, () => what(`coefficient ${Math.floor(j / 3)}/${j % 3}`));
    for (let k = 0; k < 3; k++) checkValue(t, 'maxIrr', irr[k], gpu[30 * i + 27 + k], s.irradiance[k], cIrr, () => what(`irradiance ${k}`));
  }
}

function decodeJob(c) {
  loadCase(c, caseRand);
  c.outFloats = kBatchSize * 30;
  return jobBytes(0, kBatchSize, 30, 3, c.e.bytes / 4, null, formatBytes(c.e, c.p), wordsOf(c.bytes), c.normals);
}

// --- probe volumes (zhc_volume.wgsl) against a double twin of zhc_volume_irradiance_d -------------
// Two grids per encoding, as test_runtime_gl's compare_volumes: 6x5x4 probes of batch 0 (default
// parameters) and 5x1x3 of batch 5 (irradiance storage, 3 bits, loose bound, symmetric zonal map,
// per-channel axes, RGB9E5 / half DC); 10,000 points in and around the box (1.5 times its size, a
// count-1 axis 2 spacings wide) and every probe's own position, random unit normals.
const kVolumeSamples = 10000;
const volumeGrids = [{ counts: [6, 5, 4], batch: 0 }, { counts: [5, 1, 3], batch: 5 }];
const volumeOrigin = [-1.5, 2.0, 0.25], volumeSpacing = [0.75, 0.5, 1.25];  // exact in float
const volumeTallies = new Map(encodings.map((e) => [e.name, { ...tally(), samples: 0, skipped: 0, twinMismatch: 0 }]));
function volumeJob(c) {
  const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(c.zhp)));
  const counts = c.grid.counts, count = counts[0] * counts[1] * counts[2];
  c.p = z.params;
  c.bytes = z.payload.slice(0, count * c.e.bytes);
  c.decoded = Array.from({ length: count }, (_, q) => runtime.decodeProbe(c.e.name, c.bytes, q * c.e.bytes, c.p));
  if (c.masked) {  // validity (1 in 4 invalid, or all invalid) and random visibility masks
    c.validity = Uint8Array.from({ length: count }, () => (c.masked === 'all invalid' || caseRand() < 0.25 ? 0 : 1));
    c.visibility = Uint8Array.from({ length: count }, () => Math.floor(caseRand() * 256));
  }
  if (c.planes) return planeVolumeJob(c, counts, count);
  c.vol = runtime.makeVolume({ encoding: c.e.name, params: c.p, bytes: c.bytes, origin: volumeOrigin, spacing: volumeSpacing, counts,
    validity: c.validity ?? null, visibility: c.visibility ?? null });
  const n = kVolumeSamples + count;
  c.items = new Float32Array(6 * n);
  for (let i = 0; i < n; i++) {
    for (let a = 0; a < 3; a++) {
      const size = counts[a] > 1 ? (counts[a] - 1) * volumeSpacing[a] : 2 * volumeSpacing[a];
      const lo = counts[a] > 1 ? volumeOrigin[a] - 0.25 * size : volumeOrigin[a] - volumeSpacing[a];
      const node = i - kVolumeSamples;
      const at = a === 0 ? node % counts[0] : a === 1 ? Math.floor(node / counts[0]) % counts[1] : Math.floor(node / (counts[0] * counts[1]));
      c.items[6 * i + a] = i < kVolumeSamples ? lo + 1.5 * size * caseRand() : volumeOrigin[a] + at * volumeSpacing[a];
    }
    const zz = 2 * caseRand() - 1, phi = 2 * Math.PI * caseRand(), r = Math.sqrt(Math.max(0, 1 - zz * zz));
    c.items.set([r * Math.cos(phi), r * Math.sin(phi), zz], 6 * i + 3);
  }
  c.samples = n;
  c.outFloats = 3 * n;
  if (c.masked) {  // combined masks valid ? visibility : 0, 4 per word, after the probe words
    const probeWords = wordsOf(c.bytes), words = new Uint32Array(probeWords.length + Math.ceil(count / 4));
    words.set(probeWords);
    for (let q = 0; q < count; q++) words[probeWords.length + (q >> 2)] |= (c.validity[q] ? c.visibility[q] : 0) << (8 * (q & 3));
    return jobBytes(2, n, 3, 6, c.e.bytes / 4, { origin: volumeOrigin, spacing: volumeSpacing, counts }, formatBytes(c.e, c.p),
      words, c.items, probeWords.length);
  }
  return jobBytes(1, n, 3, 6, c.e.bytes / 4, { origin: volumeOrigin, spacing: volumeSpacing, counts }, formatBytes(c.e, c.p),
    wordsOf(c.bytes), c.items);
}
// Cell of one axis (zhc__volume_axis of zhc_runtime.h): t clamped to [0, n - 1] (NaN: 0), i0 =
// min(floor(t), n - 2), f = t - i0 (0 for n = 1).
function volumeAxis(x, o, sp, n) {
  let t = (x - o) / sp;
  if (!(t >= 0)) t = 0;
  if (t > n - 1) t = n - 1;
  let i = Math.floor(t);
  if (n >= 2 && i > n - 2) i = n - 2;
  return { i0: i, f: n >= 2 ? t - i : 0, t };
}
// The test's own twin of zhc_volume_irradiance_d, written from docs/runtime.md "Probe volumes": blend
// of the decoded SH3 (float32, = zhc_decode_probe) in double, normalised normal (+Z when zero / not
// finite), band scales 1, 2/3, 1/4; also lists the cell's corners for the error scale.
function volumeIrradianceD(c, pos, nrm) {
  const counts = c.grid.counts;
  const ax = [0, 1, 2].map((a) => volumeAxis(pos[a], volumeOrigin[a], volumeSpacing[a], counts[a]));
  const sh = new Float64Array(27);
  const corners = [];
  for (let corner = 0; corner < 8; corner++) {
    const b = [corner & 1, (corner >> 1) & 1, corner >> 2];
    const w = (b[0] ? ax[0].f : 1 - ax[0].f) * (b[1] ? ax[1].f : 1 - ax[1].f) * (b[2] ? ax[2].f : 1 - ax[2].f);
    const q = b.map((bb, a) => ax[a].i0 + bb);
    if (q.every((qq, a) => qq < counts[a])) corners.push(q[0] + counts[0] * (q[1] + counts[1] * q[2]));
    if (w === 0) continue;
    const d = c.decoded[q[0] + counts[0] * (q[1] + counts[1] * q[2])];
    for (let j = 0; j < 27; j++) sh[j] += w * d[j];
  }
  let len = Math.hypot(nrm[0], nrm[1], nrm[2]);
  const n = len > 0 && Number.isFinite(len) ? nrm.map((x) => x / len) : [0, 0, 1];
  const y = runtime.shBasis(n[0], n[1], n[2]);
  const rgb = [0, 0, 0];
  for (let i = 0; i < 9; i++) {
    const s = i === 0 ? 1 : i < 4 ? 2 / 3 : 0.25;
    for (let k = 0; k < 3; k++) rgb[k] += s * sh[i * 3 + k] * y[i];
  }
  return { rgb, corners, ax };
}
// Reference: the runtime's volumeIrradianceD (the C header's zhc_volume_irradiance_d ported, the same
// double operations: js.runtime_volume shows volumeIrradiance bit-identical with the C header), and
// the twin above must agree with it to 1e-12 of S.
// Bound (test_runtime_gl compare_volumes): u times the summed probe scales S of the cell's corners,
// times 48 (decode and evaluation 32, blending 16) + 3 sum_axes ((|p| + |o|) / s + t + 2) (the
// float error of t = (p - o) / s moves each weight by at most 3 times it).
// Masked cases (zhc_volume_mask.wgsl): the reference is the runtime's masked volumeIrradianceD (bit
// for bit the C header's, js.runtime_volume); bound as test_runtime_gl's compare_masked_volumes: the
// weight part divided by the masked weight sum M, twice; samples with 0 < M < 1e-3 (ill-conditioned)
// and the probe positions (f = 0 exactly in double, not always in float) are counted, not compared.
const maskedTallies = new Map(encodings.map((e) => [e.name, { ...tally(), samples: 0, skipped: 0, renormalised: 0 }]));
function compareMaskedVolume(c, gpu) {
  const t = maskedTallies.get(c.e.name + (c.masked === 'all invalid' ? ' all invalid' : ''));
  const counts = c.grid.counts;
  for (let i = 0; i < kVolumeSamples; i++) {
    const pos = [c.items[6 * i], c.items[6 * i + 1], c.items[6 * i + 2]];
    const nrm = [c.items[6 * i + 3], c.items[6 * i + 4], c.items[6 * i + 5]];
    const { corners, ax } = volumeIrradianceD(c, pos, nrm);
    const rgb = runtime.volumeIrradianceD(c.vol, pos, nrm);
    let extra = 0, masked = 0;
    for (let a = 0; a < 3; a++) extra += (Math.abs(pos[a]) + Math.abs(volumeOrigin[a])) / volumeSpacing[a] + ax[a].t + 2;
    for (let corner = 0; corner < 8; corner++) {
      const b = [corner & 1, (corner >> 1) & 1, corner >> 2];
      const w = (b[0] ? ax[0].f : 1 - ax[0].f) * (b[1] ? ax[1].f : 1 - ax[1].f) * (b[2] ? ax[2].f : 1 - ax[2].f);
      const q = (ax[0].i0 + b[0]) + counts[0] * ((ax[1].i0 + b[1]) + counts[1] * (ax[2].i0 + b[2]));
      if (w !== 0 && c.validity[q] && (c.visibility[q] >> (7 - corner)) & 1) masked += w;
    }
    let weightPart = 3 * extra;
    if (masked > 0) {
      if (masked < 1e-3) { t.skipped++; continue; }
      weightPart = 2 * weightPart / masked;
      t.renormalised++;
    }
    const scale = [0, 0, 0];
    for (const q of corners) {
      const sc = probeScale(c.e, c.p, c.decoded[q]);
      for (let k = 0; k < 3; k++) scale[k] += sc.irradiance[k];
    }
    t.samples++;
    for (let k = 0; k < 3; k++)
      checkValue(t, 'maxIrr', rgb[k], gpu[3 * i + k], scale[k], 48 + weightPart,
        () => `${c.e.name} masked sample ${i} (position ${pos.join(',')}) channel ${k}`);
  }
}
for (const e of encodings) maskedTallies.set(e.name + ' all invalid', { ...tally(), samples: 0, skipped: 0, renormalised: 0 });

// Volumes with cell planes (zhc_volume_plane.wgsl). c.planes 'zhc': random validity (1 in 4
// invalid), visibility (each bit set with p = 3/4) and cell entries (1 in 4 cells without; of the
// others 1 in 3 a corner region with random thresholds, some axes unbounded, and directions, the
// rest planes, 1 in 5 with random sides bits, the others with the corners' own sides), uploaded in
// zhc axes; 'gltf': the same entries alone, the probe words, grid and entries in glTF axes (sides
// bits and regions' per-axis fields permuted; masks all 0xFF), the points permuted, the kernel with
// ZHC_VOLUME_PLANE_AXES_GLTF = true. Reference: the runtime's
// volumeIrradianceD on the zhc-axes volume (bit for bit the C header's, js.runtime_volume).
function planeVolumeJob(c, counts, count) {
  const grid = { origin: volumeOrigin, spacing: volumeSpacing, counts };
  const gltf = c.planes === 'gltf';
  c.validity = gltf ? null : Uint8Array.from({ length: count }, () => (caseRand() < 0.25 ? 0 : 1));
  c.visibility = gltf ? null : Uint8Array.from({ length: count }, () => Math.floor(caseRand() * 256) | Math.floor(caseRand() * 256));
  c.planeBytes = randomPlanes(grid, caseRand, { pNone: 0.25, pRandomSides: 0.2, pRegion: 1 / 3 });
  c.vol = runtime.makeVolume({ encoding: c.e.name, params: c.p, bytes: c.bytes, ...grid, validity: c.validity, visibility: c.visibility,
    planes: c.planeBytes });
  c.items = new Float32Array(6 * kVolumeSamples);  // zhc axes
  for (let i = 0; i < kVolumeSamples; i++) {
    for (let a = 0; a < 3; a++) {
      const size = (counts[a] - 1) * volumeSpacing[a];
      c.items[6 * i + a] = volumeOrigin[a] - 0.25 * size + 1.5 * size * caseRand();
    }
    const zz = 2 * caseRand() - 1, phi = 2 * Math.PI * caseRand(), r = Math.sqrt(Math.max(0, 1 - zz * zz));
    c.items.set([r * Math.cos(phi), r * Math.sin(phi), zz], 6 * i + 3);
  }
  c.samples = kVolumeSamples;
  c.outFloats = 4 * kVolumeSamples;
  const order = gltf ? gltfProbeOrder(counts) : null;  // glTF probe j = zhc probe order[j]
  const bpp = c.e.bytes;
  let probeBytes = c.bytes, gpuItems = c.items, gpuGrid = grid, gpuPlanes = c.planeBytes;
  if (gltf) {
    probeBytes = new Uint8Array(count * bpp);
    order.forEach((q, j) => probeBytes.set(c.bytes.subarray(q * bpp, (q + 1) * bpp), j * bpp));
    const perm = (v) => [v[1], v[2], v[0]];  // glTF (x, y, z) = zhc (y, z, x)
    gpuGrid = { origin: perm(volumeOrigin), spacing: perm(volumeSpacing), counts: perm(counts) };
    gpuPlanes = gltfPlanes(counts, c.planeBytes);
    gpuItems = new Float32Array(c.items);
    for (let i = 0; i < kVolumeSamples; i++) gpuItems.set(perm(c.items.subarray(6 * i, 6 * i + 3)), 6 * i);
  }
  const probeWords = wordsOf(probeBytes), maskWords = Math.ceil(count / 4);
  const words = new Uint32Array(probeWords.length + maskWords + 2 * count);
  words.set(probeWords);
  for (let q = 0; q < count; q++) {
    const m = gltf ? 0xff : (c.validity[q] ? c.visibility[q] : 0);
    words[probeWords.length + (q >> 2)] |= m << (8 * (q & 3));
    const e = gpuPlanes.subarray(5 * q, 5 * q + 5);
    words[probeWords.length + maskWords + 2 * q] = (e[0] | (e[1] << 8) | (e[2] << 16) | (e[3] << 24)) >>> 0;
    words[probeWords.length + maskWords + 2 * q + 1] = e[4];
  }
  return jobBytes(gltf ? 4 : 3, kVolumeSamples, 4, 6, bpp / 4, gpuGrid, formatBytes(c.e, c.p), words, gpuItems,
    probeWords.length, probeWords.length + maskWords);
}
// Per sample (zhc axes): points within 1e-4 |spacing| of their cell's plane, of a bounding plane of
// its cell's region or 1e-5 cell widths of a face between cells (float and double may pick
// different sides or cells) are counted, not compared; else the corners the plane or region keeps
// (the kernel's zhcVolumePlaneKeep, glTF corner bits for 'gltf') equal planeSideAt's, and the irradiance lies within compareMaskedVolume's bound with
// M the weight kept by validity, masks and plane (0 < M < 1e-3: counted, not compared).
const planeTallies = new Map();
for (const e of encodings)
  for (const axes of ['zhc', 'gltf'])
    planeTallies.set(`${e.name} ${axes}`, { ...tally(), samples: 0, skipped: 0, near: 0, byPlane: 0, regionIn: 0, regionOut: 0, keepWrong: 0,
      firstKeep: '' });
function comparePlaneVolume(c, gpu) {
  const t = planeTallies.get(`${c.e.name} ${c.planes}`);
  const counts = c.grid.counts, grid = { origin: volumeOrigin, spacing: volumeSpacing, counts };
  for (let i = 0; i < kVolumeSamples; i++) {
    const pos = [c.items[6 * i], c.items[6 * i + 1], c.items[6 * i + 2]];
    const nrm = [c.items[6 * i + 3], c.items[6 * i + 4], c.items[6 * i + 5]];
    const { corners, ax } = volumeIrradianceD(c, pos, nrm);
    let nearFace = false;
    for (let a = 0; a < 3; a++) {
      const tt = (pos[a] - volumeOrigin[a]) / volumeSpacing[a];
      for (let face = 1; face + 1 < counts[a]; face++) nearFace = nearFace || Math.abs(tt - face) < 1e-5;
    }
    if (nearFace || planeMargin(grid, c.planeBytes, pos) < 1e-4) { t.near++; continue; }
    const ps = planeSideAt(grid, c.planeBytes, pos);
    const keep = ps ? (ps.side ? ps.sides : ~ps.sides & 0xff) : 0xff;
    const wantKeep = c.planes === 'gltf' ? gltfBits(keep) : keep;
    if (gpu[4 * i + 3] !== wantKeep && t.keepWrong++ === 0)
      t.firstKeep = `${c.e.name} ${c.planes} sample ${i} (position ${pos.join(',')}): wgsl keeps ${gpu[4 * i + 3]}, JS ${wantKeep}`;
    if (keep !== 0xff) t.byPlane++;
    if (ps && ps.region) t[ps.side ? 'regionIn' : 'regionOut']++;
    let extra = 0, kept = 0;
    for (let a = 0; a < 3; a++) extra += (Math.abs(pos[a]) + Math.abs(volumeOrigin[a])) / volumeSpacing[a] + ax[a].t + 2;
    for (let corner = 0; corner < 8; corner++) {
      const b = [corner & 1, (corner >> 1) & 1, corner >> 2];
      const w = (b[0] ? ax[0].f : 1 - ax[0].f) * (b[1] ? ax[1].f : 1 - ax[1].f) * (b[2] ? ax[2].f : 1 - ax[2].f);
      const q = (ax[0].i0 + b[0]) + counts[0] * ((ax[1].i0 + b[1]) + counts[1] * (ax[2].i0 + b[2]));
      const seen = !c.validity || (c.validity[q] && (c.visibility[q] >> (7 - corner)) & 1);
      if (w !== 0 && seen && (keep >> corner) & 1) kept += w;
    }
    let weightPart = 3 * extra;
    if (kept > 0) {
      if (kept < 1e-3) { t.skipped++; continue; }
      weightPart = 2 * weightPart / kept;
    }
    const rgb = runtime.volumeIrradianceD(c.vol, pos, nrm);
    const scale = [0, 0, 0];
    for (const q of corners) {
      const sc = probeScale(c.e, c.p, c.decoded[q]);
      for (let k = 0; k < 3; k++) scale[k] += sc.irradiance[k];
    }
    t.samples++;
    for (let k = 0; k < 3; k++)
      checkValue(t, 'maxIrr', rgb[k], gpu[4 * i + k], scale[k], 48 + weightPart,
        () => `${c.e.name} ${c.planes} planes sample ${i} (position ${pos.join(',')}) channel ${k}`);
  }
}
function compareVolume(c, gpu) {
  if (c.planes) return comparePlaneVolume(c, gpu);
  if (c.masked) return compareMaskedVolume(c, gpu);
  const t = volumeTallies.get(c.e.name);
  for (let i = 0; i < c.samples; i++) {
    const pos = [c.items[6 * i], c.items[6 * i + 1], c.items[6 * i + 2]];
    const nrm = [c.items[6 * i + 3], c.items[6 * i + 4], c.items[6 * i + 5]];
    const { rgb: twin, corners, ax } = volumeIrradianceD(c, pos, nrm);
    const rgb = runtime.volumeIrradianceD(c.vol, pos, nrm);
    let extra = 0;
    for (let a = 0; a < 3; a++) extra += (Math.abs(pos[a]) + Math.abs(volumeOrigin[a])) / volumeSpacing[a] + ax[a].t + 2;
    const scale = [0, 0, 0];
    let defined = true;
    for (const q of corners) {
      const sc = probeScale(c.e, c.p, c.decoded[q]);
      defined = defined && sc.defined;
      for (let k = 0; k < 3; k++) scale[k] += sc.irradiance[k];
    }
    if (!defined) {
      t.skipped++;
      continue;
    }
    t.samples++;
    for (let k = 0; k < 3; k++) {
      const d = Math.abs(twin[k] - rgb[k]);
      if (!(d <= 1e-12 * scale[k] + kAbs)) t.twinMismatch++;
    }
    for (let k = 0; k < 3; k++)
      checkValue(t, 'maxIrr', rgb[k], gpu[3 * i + k], scale[k], 48 + 3 * extra,
        () => `${c.e.name} grid ${c.grid.counts.join('x')} sample ${i} (position ${pos.join(',')}, normal ${nrm.join(',')}) channel ${k}`);
  }
}
for (const e of encodings)
  for (const grid of volumeGrids) cases.push({ e, volume: true, grid, zhp: W(`${e.name}_${grid.batch}.zhp`) });
for (const e of encodings)
  for (const masked of ['random', 'all invalid'])
    cases.push({ e, volume: true, masked, grid: volumeGrids[0], zhp: W(`${e.name}_${volumeGrids[0].batch}.zhp`) });
for (const e of encodings)
  for (const planes of ['zhc', 'gltf'])
    cases.push({ e, volume: true, planes, grid: volumeGrids[0], zhp: W(`${e.name}_${volumeGrids[0].batch}.zhp`) });

// Scattered probes (zhc_volume.wgsl's zhcVolumeTetraSh3 / zhcVolumeTetraIrradiance). Sets written by
// `zhc convert` from JSON probe lists with positions (its tetrahedra: formats/probes/tetra.h, qhull):
// 150 random positions in a box with batch 0's first probes, stored as each encoding of tetraNames
// (cases 'random', and 'validity' with a quarter of the probes invalid, given to makePointsVolume);
// the same positions with every probe equal to one lit probe (sh3, zh3_q16: 'constant'); an SH3 field
// affine in position stored as sh3 ('affine'). Samples: 10,000 points, a third in the box, the rest
// in the box grown by half its size on every side, plus every probe; the kernel gets the 4 probes and
// weights (as f32) of volumeTetraWeights walking from tetrahedron 0 (volumeSH3's call). Reference:
// the runtime's volumeSH3 / volumeIrradianceD (the C header's doubles, js.runtime_tetra) for 'random'
// and 'validity', where every weight-0 probe index is replaced by that of a probe of 0xFF bytes
// appended to the words (it decodes to NaN / Inf: the results stay finite only if the blend skips
// it); the double twin of the field itself for 'constant' (everywhere) and 'affine' (inside the
// hull). Bound (test_runtime_gl compare_tetra_volumes): 48 u S, S = sum_k w_k S_k; decoded SH3
// kCDecode + 8 u of sum_k w_k M_k.
const kTetraSamples = 10000, kTetraProbes = 150;
const tetraNames = ['sh3', 'zh3_q16', 'sh3_q28', 'hall_adaptive_q16'];
const tetraTallies = new Map();
{
  const rand = makeRand(7607);
  const lo = [-1.5, 2.0, 0.25], size = [4.0, 2.5, 3.0];
  const positions = Array.from({ length: kTetraProbes }, () => [0, 1, 2].map((a) => Math.fround(lo[a] + size[a] * rand())));
  const lit = batchProbes(1000);
  const list = (sh) => JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
    probes: positions.map((q, i) => ({ position: q, sh3: sh(q, i) })) });
  const affine = { a: Array.from({ length: 27 }, (_, j) => (j < 3 ? 1.5 + 0.5 * (2 * rand() - 1) : 0.5 * (2 * rand() - 1))),
    b: Array.from({ length: 27 }, () => [0, 1, 2].map(() => 0.3 * (2 * rand() - 1))) };
  const affineAt = (x) => affine.a.map((a, j) => a + affine.b[j][0] * x[0] + affine.b[j][1] * x[1] + affine.b[j][2] * x[2]);
  fs.writeFileSync(W('tetra_random.json'), list((q, i) => lit[i]));
  fs.writeFileSync(W('tetra_constant.json'), list(() => lit[0]));
  fs.writeFileSync(W('tetra_affine.json'), list((q) => {
    const c = affineAt(q);
    return Array.from({ length: 9 }, (_, i) => [c[3 * i], c[3 * i + 1], c[3 * i + 2]]);
  }));
  const jobs = [], push = (e, tetra, set) => {
    const zhp = W(`tetra_${set}_${e.name}.zhp`);
    jobs.push(() => execFileP(zhc, ['convert', W(`tetra_${set}.json`), '-o', zhp, '--to', e.name]));
    return zhp;
  };
  for (const e of encodings) {
    if (!tetraNames.includes(e.name)) continue;
    const zhp = push(e, 'random', 'random');
    for (const tetra of ['random', 'validity']) cases.push({ e, tetra, zhp });
    if (e.name === 'sh3' || e.name === 'zh3_q16') cases.push({ e, tetra: 'constant', zhp: push(e, 'constant', 'constant') });
    if (e.name === 'sh3') cases.push({ e, tetra: 'affine', zhp: push(e, 'affine', 'affine'), affineAt });
  }
  await pool(jobs, 2);
  for (const c of cases) if (c.tetra) tetraTallies.set(`${c.e.name} ${c.tetra}`, { ...tally(), samples: 0, outside: 0, dropped: 0, nanProbe: false });
}
function tetraJob(c) {
  const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(c.zhp)));
  check(z.layout === 'positions' && z.tetrahedra !== null && z.count === kTetraProbes, `${c.zhp}: ${kTetraProbes} probes with tetrahedra`);
  const count = z.count, bpp = c.e.bytes;
  c.p = z.params;
  c.validity = c.tetra === 'validity' ? Uint8Array.from({ length: count }, () => (caseRand() < 0.25 ? 0 : 1)) : null;
  c.vol = runtime.makePointsVolume({ encoding: c.e.name, params: c.p, bytes: z.payload, positions: z.positions, tetrahedra: z.tetrahedra,
    neighbours: z.neighbours, validity: c.validity });
  c.decoded = Array.from({ length: count }, (_, q) => runtime.decodeProbe(c.e.name, z.payload, q * bpp, c.p));
  const bytes = new Uint8Array((count + 1) * bpp).fill(0xFF);  // the probes, then one of 0xFF bytes
  bytes.set(z.payload.subarray(0, count * bpp));
  const poison = c.tetra === 'random' || c.tetra === 'validity';
  tetraTallies.get(`${c.e.name} ${c.tetra}`).nanProbe = !runtime.decodeProbe(c.e.name, bytes, count * bpp, c.p).every(Number.isFinite);
  const lo = [0, 1, 2].map((a) => Math.min(...Array.from({ length: count }, (_, q) => z.positions[3 * q + a])));
  const hi = [0, 1, 2].map((a) => Math.max(...Array.from({ length: count }, (_, q) => z.positions[3 * q + a])));
  const n = kTetraSamples + count;
  c.samples = n;
  c.items = new Float32Array(11 * n);
  c.ref = [];
  for (let i = 0; i < n; i++) {
    const pos = [0, 1, 2].map((a) => Math.fround(i >= kTetraSamples ? z.positions[3 * (i - kTetraSamples) + a]
      : i % 3 === 0 ? lo[a] + (hi[a] - lo[a]) * caseRand() : lo[a] - 0.5 * (hi[a] - lo[a]) + 2 * (hi[a] - lo[a]) * caseRand()));
    const zz = 2 * caseRand() - 1, phi = 2 * Math.PI * caseRand(), r = Math.sqrt(Math.max(0, 1 - zz * zz));
    const nrm = [r * Math.cos(phi), r * Math.sin(phi), zz].map(Math.fround);
    const tw = runtime.volumeTetraWeights(c.vol, pos, 0);
    const probes = tw.probes.map((q, k) => (poison && tw.weights[k] === 0 ? count : q));
    c.items.set([...tw.weights, ...probes, ...nrm], 11 * i);
    c.ref.push({ pos, nrm, inside: tw.inside, probes: tw.probes, weights: tw.weights });
  }
  c.outFloats = 30 * n;
  return jobBytes(5, n, 30, 11, bpp / 4, null, formatBytes(c.e, c.p), wordsOf(bytes), c.items);
}
// The double twin of an SH3 radiance's irradiance (band scales 1, 2/3, 1/4; normal normalised).
function irradianceTwin(sh, nrm) {
  const len = Math.hypot(nrm[0], nrm[1], nrm[2]);
  const y = runtime.shBasis(nrm[0] / len, nrm[1] / len, nrm[2] / len);
  const rgb = [0, 0, 0];
  for (let i = 0; i < 9; i++) for (let k = 0; k < 3; k++) rgb[k] += (i === 0 ? 1 : i < 4 ? 2 / 3 : 0.25) * sh[3 * i + k] * y[i];
  return rgb;
}
function compareTetra(c, gpu) {
  const t = tetraTallies.get(`${c.e.name} ${c.tetra}`);
  for (let i = 0; i < c.samples; i++) {
    const { pos, nrm, inside, probes, weights } = c.ref[i];
    t.outside += inside ? 0 : 1;
    if (c.tetra === 'affine' && !inside) continue;
    const scale = [0, 0, 0], coeff = Array.from({ length: 9 }, () => [0, 0, 0]);
    let defined = true;
    for (let k = 0; k < 4; k++) {
      if (weights[k] === 0) {
        if (c.tetra === 'validity' && inside && i < kTetraSamples) t.dropped++;  // not at a probe
        continue;
      }
      const sc = probeScale(c.e, c.p, c.decoded[c.tetra === 'constant' ? 0 : probes[k]]);
      defined = defined && sc.defined;
      for (let a = 0; a < 3; a++) {
        scale[a] += weights[k] * sc.irradiance[a];
        for (let j = 0; j < 9; j++) coeff[j][a] += weights[k] * sc.coeff[j][a];
      }
    }
    if (!defined) {
      t.skippedIllcond++;
      continue;
    }
    t.samples++;
    const what = (v) => () => `${c.e.name} ${c.tetra} sample ${i} (position ${pos.join(',')}, normal ${nrm.join(',')}) ${v}`;
    let rgb, sh = null;
    if (c.tetra === 'constant') rgb = irradianceTwin(c.decoded[0], nrm);
    else if (c.tetra === 'affine') rgb = irradianceTwin(c.affineAt(pos), nrm);
    else {
      rgb = runtime.volumeIrradianceD(c.vol, pos, nrm);
      sh = runtime.volumeSH3(c.vol, pos);
    }
    for (let k = 0; k < 3; k++) checkValue(t, 'maxIrr', rgb[k], gpu[30 * i + 27 + k], scale[k], 48, what(`channel ${k}`));
    if (sh)
      for (let j = 0; j < 27; j++)
        checkValue(t, 'maxDec', sh[j], gpu[30 * i + j], coeff[Math.floor(j / 3)][j % 3], kCDecode + 8, what(`coefficient ${j}`));
  }
}

// --- 3. server + Chromium ---------------------------------------------------------------------
const roots = { '/runtime/': path.join(repo, 'runtime'), '/test/': path.join(here, 'browser') };
const caseRand = makeRand(99991);
let nextCase = 0, current = null, jobsDone = 0;
let compareMs = 0;
const routes = {
  'GET /job/next': (req, res) => {
    if (nextCase >= cases.length) {
      res.writeHead(204);
      res.end();
      return;
    }
    current = cases[nextCase++];
    res.writeHead(200, { 'Content-Type': 'application/octet-stream' });
    res.end(current.tetra ? tetraJob(current) : current.volume ? volumeJob(current) : decodeJob(current));
  },
  'POST /job/result': async (req, res) => {
    const body = await readBody(req);
    const gpu = new Float32Array(body.buffer.slice(body.byteOffset, body.byteOffset + body.byteLength));
    const want = current ? current.outFloats : 0;
    check(current && gpu.length === want, `result of job ${nextCase - 1}: ${want} floats`);
    if (current && gpu.length === want) {
      const tc = Date.now();
      (current.tetra ? compareTetra : current.volume ? compareVolume : compareCase)(current, gpu);
      compareMs += Date.now() - tc;
      current.bytes = current.normals = current.items = current.decoded = current.vol = current.validity = current.visibility = null;
      current.planeBytes = current.ref = null;
      jobsDone++;
    }
    res.end('ok');
  },
};
const pages = await chromiumPages({ roots, work, chromium, check, routes, timeoutS: 420 });
const report = await pages.runPage('wgsl.html', ['--disable-gpu-sandbox', '--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader',
  '--use-angle=swiftshader'], 'wgsl', 'zhc wgsl page done');
pages.close();
const tBrowser = Date.now();

// --- 4. assertions -----------------------------------------------------------------------------
if (report === null) {
  console.log(`jobs done: ${jobsDone} of ${cases.length}`);
  finish('runtime/zhc.wgsl');
}
console.log(`Chromium WebGPU: ${report.webgpu}, adapter "${report.adapter}", ${report.jobs} jobs`);
for (const e of report.errors ?? []) console.log(`  page: ${e}`);
for (const m of report.compilation ?? []) console.log(`  compilation: ${m}`);
check(report.webgpu === true, 'WebGPU adapter and device');
check((report.errors ?? []).length === 0, 'no console error, warning, exception or WebGPU error in the page');
check((report.compilation ?? []).length === 0, 'zhc.wgsl + kernel compile without any message');
check(jobsDone === cases.length, `every job ran (${jobsDone} of ${cases.length})`);

console.log('max error in u S (irradiance) / u M (decoded coefficients) of WGSL vs the JS runtime (= the codec\'s floats):');
console.log(`${'encoding'.padEnd(22)} ${'probes'.padStart(7)} ${'irr uS'.padStart(8)} ${'dec uS'.padStart(8)} ${'garbage'.padStart(7)} ${'irr uS'.padStart(8)} ${'dec uS'.padStart(8)} ${'nonfinite'.padStart(9)} ${'illcond'.padStart(8)} bounds`);
for (const e of encodings) {
  const { valid: v, garbage: g } = tallies.get(e.name);
  const cIrr = isQuantised(e) ? kCQuant : kCFloat;
  console.log(`${e.name.padEnd(22)} ${String(v.probes).padStart(7)} ${v.maxIrr.toFixed(3).padStart(8)} ${v.maxDec.toFixed(3).padStart(8)} ` +
    `${String(g.probes).padStart(7)} ${g.maxIrr.toFixed(3).padStart(8)} ${g.maxDec.toFixed(3).padStart(8)} ${String(g.skippedNonfinite).padStart(9)} ` +
    `${String(g.skippedIllcond).padStart(8)} ${cIrr}/${kCDecode}`);
  check(v.probes >= 100000, `${e.name}: >= 100,000 valid probes (${v.probes})`);
  for (const [what, t] of [['valid', v], ['random bytes', g]])
    check(t.failures === 0, `${e.name} ${what}: ${t.failures} values out of bound; first: ${t.firstFailure}`);
  check(v.skippedNonfinite + v.skippedIllcond === 0 && v.compared === v.probes * 30, `${e.name}: every valid probe compared (${v.compared} values)`);
  check(g.compared > g.probes * 30 / 2, `${e.name}: most random-byte values compared (${g.compared})`);
}
console.log('probe volumes: max error in u S (S summed over the cell\'s corners) of zhcVolumeIrradiance vs volumeIrradianceD (= zhc_volume_irradiance_d):');
for (const e of encodings) {
  const t = volumeTallies.get(e.name);
  console.log(`${e.name.padEnd(22)} ${String(t.samples).padStart(7)} samples ${t.maxIrr.toFixed(3).padStart(8)} u S, skipped ${t.skipped}`);
  check(t.failures === 0, `${e.name} volume: ${t.failures} values out of bound; first: ${t.firstFailure}`);
  check(t.twinMismatch === 0, `${e.name} volume: the test's twin equals runtime volumeIrradianceD (${t.twinMismatch} values differ)`);
  check(t.skipped === 0 && t.samples === volumeGrids.reduce((acc, g) => acc + kVolumeSamples + g.counts[0] * g.counts[1] * g.counts[2], 0) && t.compared === 3 * t.samples, `${e.name} volume: every sample compared (${t.samples})`);
}
console.log('masked probe volumes (zhc_volume_mask.wgsl): max error in u S of zhcVolumeIrradianceMasked vs the masked volumeIrradianceD:');
for (const [name, t] of maskedTallies) {
  console.log(`${name.padEnd(34)} ${String(t.samples).padStart(7)} samples ${t.maxIrr.toFixed(3).padStart(8)} u S, renormalised ${t.renormalised}, skipped ${t.skipped}`);
  check(t.failures === 0, `${name} masked volume: ${t.failures} values out of bound; first: ${t.firstFailure}`);
  check(t.samples + t.skipped === kVolumeSamples && t.skipped <= kVolumeSamples / 100 && t.compared === 3 * t.samples,
    `${name} masked volume: every sample compared or counted (${t.samples} + ${t.skipped} skipped)`);
  check(name.endsWith('all invalid') ? t.renormalised === 0 : t.renormalised > kVolumeSamples / 2, `${name}: the masks act (${t.renormalised} renormalised)`);
}
console.log('probe volumes with cell planes (zhc_volume_plane.wgsl): max error in u S of zhcVolumeIrradiancePlanes vs volumeIrradianceD:');
for (const [name, t] of planeTallies) {
  console.log(`${name.padEnd(34)} ${String(t.samples).padStart(7)} samples ${t.maxIrr.toFixed(3).padStart(8)} u S, skipped ${t.skipped}, ` +
    `near a plane or face ${t.near}, cut by a plane ${t.byPlane}, in a region ${t.regionIn}, outside one in its cell ${t.regionOut}, ` +
    `kept corners differ ${t.keepWrong}`);
  check(t.failures === 0, `${name} planes volume: ${t.failures} values out of bound; first: ${t.failures ? t.firstFailure : ''}`);
  check(t.keepWrong === 0, `${name} planes volume: the kept corners equal the JS side's; first: ${t.firstKeep}`);
  check(t.samples + t.skipped + t.near === kVolumeSamples && t.skipped <= kVolumeSamples / 100 && t.near <= kVolumeSamples / 100 &&
    t.compared === 3 * t.samples, `${name} planes volume: every sample compared or counted (${t.samples} + ${t.skipped} + ${t.near})`);
  check(t.byPlane > kVolumeSamples / 4, `${name}: the planes act (${t.byPlane} samples cut)`);
  check(t.regionIn > kVolumeSamples / 100 && t.regionOut > kVolumeSamples / 100,
    `${name}: samples inside corner regions (${t.regionIn}) and outside them in their cells (${t.regionOut})`);
}
console.log('scattered probes (zhcVolumeTetraIrradiance / zhcVolumeTetraSh3): max error in u S (S = sum_k w_k S_k) / u M vs volumeIrradianceD / volumeSH3 (random, validity) or the field\'s twin (constant, affine):');
for (const [name, t] of tetraTallies) {
  const [enc, kind] = name.split(' ');
  console.log(`${name.padEnd(34)} ${String(t.samples).padStart(7)} samples (${t.outside} outside the hull) ${t.maxIrr.toFixed(3).padStart(8)} u S ${t.maxDec.toFixed(3).padStart(8)} u M`);
  check(t.failures === 0, `${name}: ${t.failures} values out of bound; first: ${t.firstFailure}`);
  const n = kTetraSamples + kTetraProbes;
  check(t.skippedIllcond === 0 && t.skippedNonfinite === 0 && t.compared === t.samples * (kind === 'random' || kind === 'validity' ? 30 : 3),
    `${name}: every sample compared (${t.samples}, ${t.compared} values)`);
  check(t.outside > n / 3 && t.outside < n * 0.9, `${name}: points inside and outside the hull (${t.outside} outside)`);
  check(kind === 'affine' ? t.samples === n - t.outside : t.samples === n, `${name}: ${t.samples} samples`);
  if (kind === 'random' || kind === 'validity') check(t.nanProbe, `${enc}: a probe of 0xFF bytes decodes to NaN or Inf`);
  if (kind === 'validity') check(t.dropped > n / 10, `${name}: validity drops probes inside the hull (${t.dropped})`);
  if (!tetraNames.includes(enc)) check(false, `${name}: unexpected encoding`);
}
check(process.env.ZHC_WGSL_ONLY || tetraTallies.size === 2 * tetraNames.length + 3, `scattered probes: ${tetraTallies.size} cases`);
console.log(`wall time: encoding ${((tEncoded - t0) / 1000).toFixed(1)} s, browser + comparison ${((tBrowser - tEncoded) / 1000).toFixed(1)} s ` +
  `(of which JS reference + comparison ${(compareMs / 1000).toFixed(1)} s), total ${((Date.now() - t0) / 1000).toFixed(1)} s`);
finish('runtime/zhc.wgsl');
