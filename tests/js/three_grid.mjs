// three.js's own probe grid lit by zhc's probes, in headless Chromium (CTest: js.three_grid).
// Usage: node three_grid.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR [CHROMIUM]
//
//  1. zhc writes the grids: `zhc demo` (probes.glb: an 8x8x4 zh3_q16 grid baked from the demo scene,
//     and the same probes as probes_zh3_q16.zhp) and `zhc bake --to zh3_q16` of a small scene with
//     a point light, an emissive sphere and an occluder (a 4x4x3 grid; .glb and .zhp);
//  2. 24 sample points q per file, random in the grid's box (node-local glTF axes), random unit
//     directions d;
//  3. headless Chromium (SwiftShader WebGL2) runs tests/js/browser/three_grid_page.mjs: GLTFLoader +
//     ZhcLightProbesPlugin, volume.lightProbeGrid(LightProbeGridWebGL) (three.js r187's class, its
//     own shader chunk), the file's node under a translated, scaled root; a white Lambertian sphere
//     per sample, no other light, tone mapping off, RGBA32F target, the pixel that shades the pole
//     facing the camera (world normal d, three.js's sample point q);
//     then the same with WebGPURenderer and three.js's WebGPU LightProbeGrid (Chromium's WebGPU on
//     SwiftShader: --enable-unsafe-webgpu --use-webgpu-adapter=swiftshader; binary16 atlas only);
//  4. the C header (tests/runtime_c/zhc_volume_sample: zhc_volume_from_zhp + zhc_volume_irradiance
//     on the .zhp, q and d converted to zhc axes) gives E(q, d); three.js's MeshLambertMaterial
//     shows BRDF_Lambert * irradiance = (albedo / pi) * (pi E) = E, so the pixel must equal E.
//
// Tolerances, per channel, in units of the sample's term scale S = sum over the cell's corners of
// w_b sum_i |s_l c_bi Y_i(d)| (>= |E|; computed in the page):
//  * float atlas: 2e-5 S. three.js's irradiance constants have 6 digits (0.886227, 0.511664,
//    0.429043, 0.743125, 0.247708: relative errors <= 2.0e-6 against pi Y_lm s_l), the shader and the
//    texture filter compute in float32 (a few 2^-24 per operation), the sample point and normal are
//    float32 world coordinates; the rest of the budget is margin for the filter's weights. The
//    float atlas holds the blend's input exactly (float32 coefficients, glTF rotation: one rounding).
//  * binary16 atlas: 2^-11 S + 2e-5 S (each stored coefficient rounded to binary16, relative 2^-11).
//  * MeshStandardMaterial (roughness 1, metalness 0) with the grid against the same material lit by
//    a THREE.LightProbe holding zhc's blended SH3 at q: 2e-5 of the probe render (same BRDF code).
//  * WebGPU MeshStandardMaterial: its grid is binary16, the LightProbe twin float: 2^-11 S + 2e-5 S.
// Time bounded: each browser page times out after 180 s (Chromium killed).
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { makeRand, checker, freshWork, repoRoot } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';

const [zhc, sampler, workArg, chromiumArg] = process.argv.slice(2);
if (!zhc || !sampler || !workArg) {
  console.error('usage: node three_grid.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR [CHROMIUM]');
  process.exit(2);
}
const chromium = chromiumArg || '/usr/bin/chromium';
const work = freshWork(workArg);
const here = path.dirname(fileURLToPath(import.meta.url));
const repo = repoRoot;
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28 }).toString();
const f32 = Math.fround;

// --- 1. grids written by zhc ------------------------------------------------------------------
run('demo', '-o', W('demo'), '--directions', '16');
fs.copyFileSync(W('demo/probes.glb'), W('demo_probes.glb'));
fs.writeFileSync(W('bake_scene.json'), JSON.stringify({
  version: 1, probes: { grid: { min: [-1, -1, 0], max: [1, 1, 1.5], counts: [4, 4, 3] } }, sky: { type: 'gradient' },
  lights: [{ type: 'point', position: [0.2, -0.1, 2], intensity: [8, 6.4, 4.8], shadows: true },
    { type: 'sphere', center: [1, 1, 1], radius: 0.3, radiance: [40, 6, 3], shadows: true }],
  occluders: [{ type: 'mesh', positions: [-0.5, -0.5, 1.2, 0.5, -0.5, 1.2, 0, 0.5, 1.2] }] }));
run('bake', W('bake_scene.json'), '-o', W('baked_q16.glb'), '--to', 'zh3_q16', '--quiet');
run('bake', W('bake_scene.json'), '-o', W('baked_q16.zhp'), '--to', 'zh3_q16', '--quiet');

// The first ZHC_light_probes grid of a .glb (JSON chunk).
function gltfGrid(file) {
  const b = fs.readFileSync(file);
  const json = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
  return json.extensions.ZHC_light_probes.volumes[0].grid;
}

// --- 2. samples -----------------------------------------------------------------------------------
const files = [
  { glb: 'demo_probes.glb', zhp: W('demo/probes_zh3_q16.zhp'), rootTranslation: [0.7, -0.4, 1.3], rootScale: 1.25, seed: 11 },
  { glb: 'baked_q16.glb', zhp: W('baked_q16.zhp'), rootTranslation: [-2, 0.5, 0.25], rootScale: 0.8, seed: 12 },
];
const SAMPLES = 24;
for (const f of files) {
  const g = gltfGrid(W(f.glb));
  const rand = makeRand(f.seed);
  f.samples = [];
  for (let i = 0; i < SAMPLES; i++) {
    const q = [0, 1, 2].map((c) => f32(g.origin[c] + (g.counts[c] - 1) * g.spacing[c] * (0.02 + 0.96 * rand())));
    const z = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - z * z));
    const d = [r * Math.cos(phi), r * Math.sin(phi), z];
    const len = Math.hypot(...d);
    f.samples.push({ q, d: d.map((x) => f32(x / len)) });
  }
}
fs.writeFileSync(W('three_grid_spec.json'), JSON.stringify({ files: files.map(({ glb, rootTranslation, rootScale, samples }) => ({ glb, rootTranslation, rootScale, samples })) }));

// The C header at the samples: glTF (x, y, z) = zhc (y, z, x), so zhc = (z, x, y) of glTF.
// `plain`: the leak data dropped (three.js's grid is a texture blended by trilinear filtering, which
// cannot apply validity, visibility masks or cell planes; the plugin's irradianceAt does apply them).
function sampleC(zhp, samples, plain = false) {
  const toZhc = (v) => [v[2], v[0], v[1]];
  const file = W('points.txt');
  fs.writeFileSync(file, samples.map(({ q, d }) => [...toZhc(q), ...toZhc(d)].map((x) => x.toPrecision(9)).join(' ')).join('\n') + '\n');
  return execFileSync(sampler, [zhp, file, ...(plain ? ['--plain'] : [])]).toString().trim().split('\n').map((l) => l.trim().split(/\s+/).map((x) => f32(Number(x))));
}
for (const f of files) {
  f.expected = sampleC(f.zhp, f.samples, true);
  f.expectedMasked = sampleC(f.zhp, f.samples);
  // Also at the shaded point itself, q - d * spacing / 2 (node-local): what three.js's half-cell
  // offset changes (information, not an error: the pixel is compared at three.js's sample point).
  const g = gltfGrid(W(f.glb));
  f.atSurface = sampleC(f.zhp, f.samples.map(({ q, d }) => ({ q: q.map((x, c) => x - 0.5 * d[c] * g.spacing[c]), d })), true);
}

// --- 3. server + Chromium (tests/js/chromium_page.mjs) -----------------------------------------
const pages = await chromiumPages({
  roots: { '/runtime/web/': path.join(repo, 'runtime', 'web'), '/three/': path.join(here, 'node_modules', 'three'), '/test/': path.join(here, 'browser'), '/work/': work },
  work, chromium, check,
});
const DONE = 'zhc three.js LightProbeGrid page done';
const reports = {
  webgl: await pages.runPage('three_grid.html', ['--use-angle=swiftshader'], 'webgl', DONE),
  webgpu: await pages.runPage('three_grid_webgpu.html', ['--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader', '--use-angle=swiftshader'], 'webgpu', DONE),
};
pages.close();

// --- 4. assertions -----------------------------------------------------------------------------
fs.writeFileSync(W('report.json'), JSON.stringify(reports, null, 1));
if (reports.webgl === null || reports.webgpu === null) process.exit(1);
for (const [tag, report] of Object.entries(reports)) {
  console.log(`Chromium ${tag}: three.js r${report.three}, renderer "${report.renderer}"` + (tag === 'webgl'
    ? `, WebGL2 ${report.webgl2}, EXT_color_buffer_float ${report.colorBufferFloat}, OES_texture_float_linear ${report.floatLinear}`
    : `, WebGPU backend ${report.webgpuBackend}`));
  for (const e of report.errors ?? []) console.log(`  page: ${e}`);
  check((report.errors ?? []).length === 0, `${tag}: no console error, warning or exception in the page`);
  check(report.three === '187', `${tag}: three.js r187 (the pinned version)`);
  check(Array.isArray(report.files) && report.files.length === files.length, `${tag}: every file reported`);
}
check(reports.webgl.webgl2 === true && reports.webgl.colorBufferFloat === true && reports.webgl.floatLinear === true,
  'webgl: WebGL2 with EXT_color_buffer_float and OES_texture_float_linear');
check(reports.webgpu.webgpuBackend === true, 'webgpu: WebGPURenderer runs on its WebGPU backend (not the WebGL fallback)');
const TOL_FLOAT = 2e-5, TOL_HALF = 2 ** -11 + 2e-5, TOL_STANDARD = 2e-5, TOL_HALF_STORAGE = 2 ** -11;
for (const [tag, report] of Object.entries(reports)) for (const r of report.files ?? []) {
  const f = files.find((x) => x.glb === r.glb);
  const gpu = tag === 'webgpu';
  check(r.samples.length === SAMPLES, `${tag} ${r.glb}: ${SAMPLES} spheres rendered`);
  check(r.rotationRefused === true, `${tag} ${r.glb}: a rotated node is refused (three.js's grid is axis-aligned)`);
  check(Array.isArray(r.refusals) && r.refusals.length === 5 && r.refusals.every((x) => x === true),
    `${tag} ${r.glb}: lightProbeGrid refuses a non-grid class, a byte type, a mirror, a points volume, spacing 0 (${r.refusals})`);
  check(r.halfAtlasType === true, `${tag} ${r.glb}: the binary16 atlas (WebGPU: lightProbeGrid's default) is HalfFloatType`);
  // Bounds: the node's world matrix (translation + scale) moves the box [origin - s/2, origin + (n - 1/2) s].
  const g = gltfGrid(W(f.glb)), e = r.nodeMatrix;
  let boundsErr = 0;
  for (let c = 0; c < 3; c++) {
    const lo = e[12 + c] + e[5 * c] * (g.origin[c] - 0.5 * g.spacing[c]);
    const hi = e[12 + c] + e[5 * c] * (g.origin[c] + (g.counts[c] - 0.5) * g.spacing[c]);
    boundsErr = Math.max(boundsErr, Math.abs(r.boundsHalf[c] - lo), Math.abs(r.boundsHalf[3 + c] - hi));
    if (!gpu) boundsErr = Math.max(boundsErr, Math.abs(r.boundsFloat[c] - lo), Math.abs(r.boundsFloat[3 + c] - hi));
  }
  check(boundsErr < 1e-9, `${tag} ${r.glb}: the grid's world box is the node's probe box grown by half a cell (error ${boundsErr})`);
  const stat = () => ({ max: 0, sum: 0, n: 0, worstScaled: 0 });
  const lf = stat(), lh = stat(), sg = stat(), js = stat(), ht = stat(), hs = stat(), off = stat();
  let meanE = 0, jsAbs = 0, maskMoves = 0;
  r.samples.forEach((s, i) => {
    const want = f.expected[i];
    for (let k = 0; k < 3; k++) {
      const E = want[k], S = s.termScale[k];
      meanE += E / (3 * r.samples.length);
      const add = (st, got, ref, tol, scaleBy) => {
        const rel = Math.abs(got - ref) / Math.abs(ref);
        st.max = Math.max(st.max, rel);
        st.sum += rel;
        st.n++;
        st.worstScaled = Math.max(st.worstScaled, Math.abs(got - ref) / scaleBy);
        return Math.abs(got - ref) <= tol * scaleBy;
      };
      const okF = gpu || add(lf, s.lambertFloat[k], E, TOL_FLOAT, S);
      const okH = add(lh, s.lambertHalf[k], E, TOL_HALF, S);
      // WebGPU: its grid is the binary16 atlas, the LightProbe holds float SH: 2^-11 S more.
      const okS = gpu ? add(sg, s.standardGrid[k], s.standardProbe[k], TOL_HALF, S)
        : add(sg, s.standardGrid[k], s.standardProbe[k], TOL_STANDARD, Math.abs(s.standardProbe[k]));
      const Em = f.expectedMasked[i][k];
      add(js, s.js[k], Em, 0, 1);
      maskMoves = Math.max(maskMoves, Math.abs(Em - E) / S);
      add(off, f.atSurface[i][k], E, 0, S);
      // binary16 atlas = the half twin (rendering error) and the half twin vs the exact probes
      // (storage: each coefficient within 2^-11 relative, so E within 2^-11 S; 1e-7 absolute for
      // coefficients in binary16's subnormal range, whose error is <= 2^-25).
      const okHT = add(ht, s.lambertHalf[k], s.halfTwin[k], TOL_FLOAT, S);
      const okHS = add(hs, s.halfTwin[k], E, TOL_HALF_STORAGE, S) || Math.abs(s.halfTwin[k] - E) <= TOL_HALF_STORAGE * S + 1e-7;
      check(okHT, `${tag} ${r.glb} sample ${i}: binary16 atlas pixel = its double twin within ${TOL_FLOAT} S`);
      check(okHS, `${tag} ${r.glb} sample ${i}: binary16 storage moves E by at most 2^-11 S`);
      jsAbs = Math.max(jsAbs, Math.abs(s.js[k] - Em));
      if (!okF || !okH || !okS)
        console.log(`  ${tag} ${r.glb} sample ${i} ch ${k}: q ${s.q} d ${s.d}: C ${E}, Lambert float ${gpu ? '-' : s.lambertFloat[k]}, half ` +
          `${s.lambertHalf[k]}, Standard grid ${s.standardGrid[k]} vs LightProbe ${s.standardProbe[k]}, S ${S}`);
      check(okF, `${tag} ${r.glb} sample ${i}: float atlas pixel = C zhc_volume_irradiance within ${TOL_FLOAT} S`);
      check(okH, `${tag} ${r.glb} sample ${i}: binary16 atlas pixel within ${TOL_HALF.toExponential(3)} S`);
      check(okS, `${tag} ${r.glb} sample ${i}: MeshStandardMaterial with the grid = with a LightProbe of the blended SH`);
      check(E > 0 && s.standardGrid[k] > 0, `${tag} ${r.glb} sample ${i}: lit (E > 0, Standard pixel > 0)`);
    }
  });
  const fmt = (st) => `max ${st.max.toExponential(2)}, mean ${(st.sum / st.n).toExponential(2)} (max |diff|/S ${st.worstScaled.toExponential(2)})`;
  console.log(`${tag}: ${r.glb} (${r.encoding} ${r.counts.join('x')} grid, node at scale ${f.rootScale}, mean E ${meanE.toPrecision(4)}): ` +
    `${r.samples.length} spheres x 3 channels, relative error against the C header:`);
  if (!gpu) console.log(`  MeshLambertMaterial, float atlas:    ${fmt(lf)}`);
  console.log(`  MeshLambertMaterial, binary16 atlas: ${fmt(lh)}`);
  console.log(`    binary16 atlas pixel vs its twin (rendering): ${fmt(ht)}`);
  console.log(`    binary16 twin vs C (what half storage loses): ${fmt(hs)}`);
  console.log(`  MeshStandardMaterial grid vs LightProbe(blended SH): ${fmt(sg)}`);
  console.log(`  (three.js's half-cell offset: E at the shaded point vs at three.js's sample point differs by mean ` +
    `${(off.sum / off.n).toExponential(2)}, max ${off.max.toExponential(2)} relative)`);
  console.log(`  JS irradianceAt (glTF, leak data applied) vs C (.zhp, zhc axes, leak data applied): max |diff| / mean E ${(jsAbs / meanE).toExponential(2)}`);
  console.log(`  (the leak data (validity, masks, cell planes), which the grid texture cannot apply, move E by up to ${maskMoves.toExponential(2)} S here)`);
  check(jsAbs <= 1e-6 * meanE, `${tag} ${r.glb}: the plugin's irradianceAt agrees with the C header (1e-6 of the mean, js.runtime_volume's bound)`);
}
finish('three.js LightProbeGrid');
