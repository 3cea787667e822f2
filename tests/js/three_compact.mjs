// zhc's compact volume path in three.js (runtime/web/zhc_volume.glsl.mjs) in headless Chromium
// (CTest: js.three_compact). Usage: node three_compact.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR [CHROMIUM]
//
//  1. zhc writes the grids: `zhc demo` (probes.glb: the 8x8x4 zh3_q16 grid, glTF; probes_sh3.zhp,
//     probes_zh3_q16.zhp: the same probes) and `zhc convert probes_sh3.zhp` to sh3_q28, sh2_q and
//     zh3_channel_q16 with non-default parameters (6 bits, sqrt, RGB9E5 DC);
//  2. 24 samples per volume: 20 points q random inside the grid's box, 4 outside it (clamped),
//     random unit directions d, in the volume's frame (glb: node-local glTF axes; .zhp: zhc axes);
//  3. headless Chromium (SwiftShader WebGL2) runs tests/js/browser/three_compact_page.mjs: the stored
//     bytes in an RGBA32UI Data3DTexture (compactVolume), (A) a ShaderMaterial writing
//     zhcVolumeIrradiance per sample, (B) white spheres with a MeshLambertMaterial patched by
//     patchMaterialWithVolume (pole at q in world space, normal d), both to RGBA32F targets;
//  4. the C header (tests/runtime_c/zhc_volume_sample: zhc_volume_from_zhp + zhc_volume_irradiance)
//     gives E(q, d) from the .zhp (the glb's samples converted to zhc axes).
//
// Tolerance: the error model of the GLSL volume test (tests/test_runtime_gl.cpp, compare_volumes):
// |pixel - E| <= (48 + 3 X) u S per channel, u = 2^-24, S = the sum over the cell's corners of
// each probe's irradiance scale (kY00 m0 + 2/3 kY1 (m1 + m2 + m3) + L2 part, m_i the coefficient
// magnitude or its ratio bound times the DC; ZH3's zonal part grows with the axis' condition
// number), X = sum over axes of (|p| + |o|) / s + t + 2 (the float grid coordinate's error).
// (C) patched MeshStandardMaterial against its LightProbe twin: 2e-5 k T, T = sum_i s_l |c_i Y_i(n)|
// of the blended SH3 (>= |E|), k the material's pixel per unit E (fitted per channel over the
// samples): three.js's 6-digit irradiance constants (relative <= 2.0e-6) and float32 shading, as
// js.three_grid's MeshStandardMaterial check.
// (B) adds the path from the world to the grid frame on the GPU (model-view matrix, inverse view,
// world-to-grid matrix, the interpolated pole normal): 16 u S + 3 x 16 u S sum over axes of
// (|p_world| + |translation|) / (scale s).
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { makeRand, checker } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';
import { parseZhp, decodeAll, kY00, kY1, kY20 } from '../../runtime/web/zhc_runtime.mjs';

const [zhc, sampler, workArg, chromiumArg] = process.argv.slice(2);
if (!zhc || !sampler || !workArg) {
  console.error('usage: node three_compact.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR [CHROMIUM]');
  process.exit(2);
}
const chromium = chromiumArg || '/usr/bin/chromium';
const work = path.resolve(workArg);
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.resolve(here, '..', '..');
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28 }).toString();
const f32 = Math.fround;
const U = 2 ** -24;

// --- 1. volumes written by zhc ---------------------------------------------------------------------
run('demo', '-o', W('demo'), '--directions', '16');
fs.copyFileSync(W('demo/probes.glb'), W('demo_probes.glb'));
run('convert', W('demo/probes_sh3.zhp'), '-o', W('demo_sh3_q28.zhp'), '-r', 'sh3_q28');
run('convert', W('demo/probes_sh3.zhp'), '-o', W('demo_sh2_q.zhp'), '-r', 'sh2_q');
run('convert', W('demo/probes_sh3.zhp'), '-o', W('demo_zh3_channel.zhp'), '-r', 'zh3_channel_q16', '--bits', '6', '--sqrt', '--dc', 'rgb9e5');

const volumes = [
  { name: 'demo zh3_q16 (glb)', glb: 'demo_probes.glb', ref: W('demo/probes_zh3_q16.zhp'), gltf: true, rootTranslation: [0.7, -0.4, 1.3], rootScale: 1.25, seed: 21 },
  { name: 'demo sh3_q28 (.zhp)', zhp: 'demo_sh3_q28.zhp', ref: W('demo_sh3_q28.zhp'), gltf: false, rootTranslation: [-1, 0.5, 2], rootScale: 0.8, seed: 22 },
  { name: 'demo sh2_q (.zhp)', zhp: 'demo_sh2_q.zhp', ref: W('demo_sh2_q.zhp'), gltf: false, rootTranslation: [0.3, 1.5, -0.5], rootScale: 1.5, seed: 23 },
  { name: 'demo zh3_channel_q16 6 bits sqrt rgb9e5 (.zhp)', zhp: 'demo_zh3_channel.zhp', ref: W('demo_zh3_channel.zhp'), gltf: false, rootTranslation: [2, -1, 0.5], rootScale: 1.1, seed: 24 },
];
const toZhc = (v) => [v[2], v[0], v[1]];  // glTF (x, y, z) = zhc (y, z, x)
const SAMPLES = 24, OUTSIDE = 4;
for (const v of volumes) {
  const z = parseZhp(new Uint8Array(fs.readFileSync(v.ref)));
  v.zhpInfo = z;
  v.sh = decodeAll(z.encoding, z.payload, z.count, z.params);
  // The grid in the sample frame: zhc axes permuted to glTF for the glb (its grid is glTF's).
  const g = z.grid;
  const perm = (a) => (v.gltf ? [a[1], a[2], a[0]] : [...a]);
  const frame = { origin: perm(g.origin), spacing: perm(g.spacing), counts: perm(g.counts) };
  const rand = makeRand(v.seed);
  v.samples = [];
  for (let i = 0; i < SAMPLES; i++) {
    const out = i >= SAMPLES - OUTSIDE;
    const q = [0, 1, 2].map((c) => {
      const size = (frame.counts[c] - 1) * frame.spacing[c];
      const t = out ? -0.2 + 1.4 * rand() : 0.02 + 0.96 * rand();
      return f32(frame.origin[c] + size * t);
    });
    if (out) q[i % 3] = f32(frame.origin[i % 3] + (i % 2 ? -0.3 : 1.3) * (frame.counts[i % 3] - 1) * frame.spacing[i % 3]);
    const zz = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - zz * zz));
    const d = [r * Math.cos(phi), r * Math.sin(phi), zz];
    const len = Math.hypot(...d);
    v.samples.push({ q, d: d.map((x) => f32(x / len)) });
  }
}
fs.writeFileSync(W('three_compact_spec.json'), JSON.stringify({
  volumes: volumes.map(({ name, glb, zhp, rootTranslation, rootScale, samples }) => ({ name, glb, zhp, rootTranslation, rootScale, samples })),
}));

// The C header at the samples (zhc axes).
for (const v of volumes) {
  const file = W('points.txt');
  const pts = v.samples.map(({ q, d }) => (v.gltf ? [...toZhc(q), ...toZhc(d)] : [...q, ...d]));
  v.zhcPoints = pts;
  fs.writeFileSync(file, pts.map((p) => p.map((x) => x.toPrecision(9)).join(' ')).join('\n') + '\n');
  v.expected = execFileSync(sampler, [v.ref, file]).toString().trim().split('\n').map((l) => l.trim().split(/\s+/).map((x) => f32(Number(x))));
}

// Irradiance scale of one decoded probe (tests/gl/runtime_gl_entries.inl probe_scale, packed
// layouts without hallucination): per channel.
function probeScale(z, sh, p) {
  const c = (i, k) => sh[p * 27 + i * 3 + k];
  const zonal = z.encoding.startsWith('zh3_');
  const hasL2 = zonal || z.encoding === 'sh3_q28';
  const tight = (z.params.l2Bound ?? 'tight') === 'tight';
  const bound = (i) => (i < 4 ? Math.sqrt(3) : i === 6 ? Math.sqrt(5) : tight ? Math.sqrt(15) / 2 : Math.sqrt(5));
  const m = [];
  for (let i = 0; i < 9; i++) m.push([0, 1, 2].map((k) => (i === 0 ? Math.abs(c(0, k)) : Math.max(Math.abs(c(i, k)), bound(i) * Math.abs(c(0, k))))));
  const vec = (k) => [-c(3, k), -c(1, k), c(2, k)];
  const vmag = (k) => Math.hypot(m[1][k], m[2][k], m[3][k]);
  const kappa = [1, 1, 1];
  if (zonal) {
    if (!z.encoding.includes('channel') && z.params.axisMode !== 'channel') {
      const w = z.params.luminanceWeights ?? [0.2126, 0.7152, 0.0722];
      const lum = [0, 0, 0];
      let mag = 0;
      for (let k = 0; k < 3; k++) { const vk = vec(k); for (let j = 0; j < 3; j++) lum[j] += w[k] * vk[j]; mag += Math.abs(w[k]) * vmag(k); }
      const len = Math.hypot(...lum), allZero = [0, 1, 2].every((k) => Math.hypot(...vec(k)) === 0);
      kappa.fill(mag === 0 || allZero ? 1 : len > 0 ? mag / len : Infinity);
    } else {
      for (let k = 0; k < 3; k++) { const len = Math.hypot(...vec(k)), mag = vmag(k); kappa[k] = mag === 0 || len === 0 ? 1 : mag / len; }
    }
  }
  return [0, 1, 2].map((k) => {
    let l2 = 0;
    if (zonal) {
      let f20 = 0;
      for (let i = 4; i < 9; i++) f20 += c(i, k) * c(i, k);
      f20 = Math.max(Math.sqrt(f20), Math.sqrt(5) * m[0][k]);
      l2 = 3 * kY20 * f20 * (1 + kappa[k]);
    } else if (hasL2) {
      for (let i = 4; i < 9; i++) l2 += 0.631 * m[i][k];
    }
    return kY00 * m[0][k] + (2 / 3) * kY1 * (m[1][k] + m[2][k] + m[3][k]) + 0.25 * l2;
  });
}
// S (sum over the cell's corners) and X (the weight-error factor) of a point in zhc axes.
function errorModel(v, pz) {
  const g = v.zhpInfo.grid, i0 = [], extra = [0];
  for (let c = 0; c < 3; c++) {
    const tt = Math.min(Math.max((pz[c] - g.origin[c]) / g.spacing[c], 0), g.counts[c] - 1);
    i0.push(Math.min(Math.floor(tt), g.counts[c] >= 2 ? g.counts[c] - 2 : 0));
    extra[0] += (Math.abs(pz[c]) + Math.abs(g.origin[c])) / g.spacing[c] + tt + 2;
  }
  const S = [0, 0, 0];
  for (let b = 0; b < 8; b++) {
    const q = [i0[0] + (b & 1), i0[1] + ((b >> 1) & 1), i0[2] + (b >> 2)];
    if (q.some((x, c) => x >= g.counts[c])) continue;
    const s = probeScale(v.zhpInfo, v.sh, q[0] + g.counts[0] * (q[1] + g.counts[1] * q[2]));
    for (let k = 0; k < 3; k++) S[k] += s[k];
  }
  return { S, X: extra[0] };
}

// --- 3. Chromium ---------------------------------------------------------------------------------
const pages = await chromiumPages({
  roots: { '/runtime/web/': path.join(repo, 'runtime', 'web'), '/three/': path.join(here, 'node_modules', 'three'), '/test/': path.join(here, 'browser'), '/work/': work },
  work, chromium, check,
});
const report = await pages.runPage('three_compact.html', ['--use-angle=swiftshader'], 'webgl', 'zhc three.js compact volume page done');
pages.close();
fs.writeFileSync(W('report.json'), JSON.stringify(report, null, 1));
if (report === null) process.exit(1);

// --- 4. assertions ---------------------------------------------------------------------------------
console.log(`Chromium: three.js r${report.three}, renderer "${report.renderer}", WebGL2 ${report.webgl2}, EXT_color_buffer_float ${report.colorBufferFloat}`);
for (const e of report.errors ?? []) console.log(`  page: ${e}`);
check((report.errors ?? []).length === 0, 'no console error, warning or exception in the page');
check(report.three === '187', 'three.js r187 (the pinned version)');
check(report.webgl2 === true && report.colorBufferFloat === true, 'WebGL2 with EXT_color_buffer_float');
check(Array.isArray(report.volumes) && report.volumes.length === volumes.length, 'every volume reported');
for (const r of report.volumes ?? []) {
  const v = volumes.find((x) => x.name === r.name);
  const z = v.zhpInfo;
  const texels = z.encoding === 'sh3_q28' ? 2 : 1;
  check(r.count === z.count && r.gpuBytes === 16 * texels * z.count && r.textureBytes === r.gpuBytes,
    `${r.name}: the texture holds ${16 * texels} bytes per probe (${r.gpuBytes} for ${r.count} probes)`);
  const [nx, ny, nz] = v.gltf ? [z.grid.counts[1], z.grid.counts[2], z.grid.counts[0]] : z.grid.counts;
  check(r.size[0] === texels * nx && r.size[1] === ny && r.size[2] === nz, `${r.name}: texture ${r.size.join('x')} = (${texels} nx) x ny x nz`);
  check(r.normalAxes === (v.gltf ? 'gltf' : 'same'), `${r.name}: normals mapped to zhc axes only for the glTF volume (${r.normalAxes})`);
  if (v.gltf) {
    check(r.defaultMatrix === true, `${r.name}: compactVolume's default placement is the volume node's matrixWorld`);
    check(Array.isArray(r.refusals) && r.refusals.length === 6 && r.refusals.every((x) => x === true),
      `${r.name}: compactVolume refuses sh3, hall_curve_q, a points layout, spacing 0, short bytes, a singular matrix (${r.refusals})`);
    // three.js's atlas: nx x ny x 7 (nz + 2) RGBA texels, 16 (float) or 8 (binary16) bytes each.
    const want = 7 * (nz + 2) / nz;
    check(r.threeFloatBytesPerProbe === 16 * want && r.threeHalfBytesPerProbe === 8 * want,
      `${r.name}: three.js's LightProbeGridWebGL atlas is ${r.threeFloatBytesPerProbe} (float) / ${r.threeHalfBytesPerProbe} (binary16) bytes per probe`);
    console.log(`${r.name}: GPU bytes per probe: compact ${r.gpuBytesPerProbe}; three.js LightProbeGridWebGL float ${r.threeFloatBytesPerProbe} ` +
      `(${(r.threeFloatBytesPerProbe / r.gpuBytesPerProbe).toFixed(2)}x; 112 = 7x without the 2 padding slices), binary16 ${r.threeHalfBytesPerProbe} ` +
      `(${(r.threeHalfBytesPerProbe / r.gpuBytesPerProbe).toFixed(2)}x; 56 without padding); atlas ${r.threeAtlasSize.join('x')}`);
  } else {
    console.log(`${r.name}: GPU bytes per probe: compact ${r.gpuBytesPerProbe}`);
  }
  check(r.unpatched.every((x) => x === 0), `${r.name}: the unpatched material renders black (only the volume lights the sphere)`);
  const st = () => ({ maxUnits: 0, maxRel: 0, sumRel: 0, n: 0, fails: 0 });
  const A = st(), B = st();
  let meanE = 0, lit = 0;
  v.samples.forEach((s, i) => {
    const E = v.expected[i];
    const { S, X } = errorModel(v, v.zhcPoints[i]);
    const boundA = 48 + 3 * X;
    let worldX = 0;
    const g = v.zhpInfo.grid;
    for (let c = 0; c < 3; c++) worldX += (r.worldMax + r.translationMax) / (r.scale * g.spacing[c]);
    const boundB = boundA + 16 + 3 * 16 * worldX;
    for (let k = 0; k < 3; k++) {
      meanE += E[k] / (3 * v.samples.length);
      const add = (stat, got, bound, what) => {
        const err = Math.abs(got - E[k]), units = err / (U * S[k]), rel = err / Math.abs(E[k]);
        stat.maxUnits = Math.max(stat.maxUnits, units);
        stat.maxRel = Math.max(stat.maxRel, rel);
        stat.sumRel += rel;
        stat.n++;
        const ok = Number.isFinite(got) && err <= bound * U * S[k];
        if (!ok) console.log(`  ${r.name} sample ${i} ch ${k} ${what}: C ${E[k]}, GPU ${got}, ${units.toFixed(1)} u S > ${bound.toFixed(1)}`);
        check(ok, `${r.name} sample ${i} channel ${k}: ${what} = C zhc_volume_irradiance within ${bound.toFixed(1)} u S`);
      };
      add(A, r.shader[i][k], boundA, 'ShaderMaterial zhcVolumeIrradiance');
      add(B, r.lambert[i][k], boundB, 'patched MeshLambertMaterial pixel');
      check(Number.isFinite(E[k]) && E[k] !== 0, `${r.name} sample ${i}: E finite and not 0`);
    }
    if (E.every((x) => x > 0)) lit++;
  });
  // sh2_q (L1 only) rings below 0 on some back-facing normals; the others are lit everywhere.
  check(lit >= (z.encoding === 'sh2_q' ? 16 : SAMPLES), `${r.name}: ${lit} of ${SAMPLES} samples lit in every channel`);
  // (C) Standard: fitted pixel-per-E k and the twin comparison.
  let worstC = 0;
  for (let k = 0; k < 3; k++) {
    let pe = 0, ee = 0;
    v.samples.forEach((_, i) => { pe += r.standardProbe[i][k] * v.expected[i][k]; ee += v.expected[i][k] ** 2; });
    const kk = pe / ee;
    check(kk > 0.1 && kk < 10, `${r.name} channel ${k}: MeshStandardMaterial shows k E with k = ${kk.toPrecision(6)}`);
    v.samples.forEach((_, i) => {
      const diff = Math.abs(r.standard[i][k] - r.standardProbe[i][k]), T = r.termScale[i][k];
      worstC = Math.max(worstC, diff / (kk * T));
      check(diff <= 2e-5 * kk * T, `${r.name} sample ${i} channel ${k}: patched MeshStandardMaterial = LightProbe twin within 2e-5 k T (${(diff / (kk * T)).toExponential(2)})`);
    });
  }
  const fmt = (s) => `max ${s.maxUnits.toFixed(2)} u S, relative max ${s.maxRel.toExponential(2)} mean ${(s.sumRel / s.n).toExponential(2)}`;
  console.log(`  ${v.samples.length} samples x 3 channels (mean E ${meanE.toPrecision(4)}) against the C header:`);
  console.log(`    ShaderMaterial (A):            ${fmt(A)}`);
  console.log(`    patched MeshLambertMaterial (B): ${fmt(B)}`);
  console.log(`    patched MeshStandardMaterial vs LightProbe twin (C): max ${worstC.toExponential(2)} k T`);
}
finish('three.js compact volume');
