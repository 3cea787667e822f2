// runtime/web in headless Chromium (CTest: js.browser).
// Usage: node browser_test.mjs ZHC_BINARY WORK_DIR [CHROMIUM]
//
//  1. `zhc bake --to zh3_q16` a small JSON scene (a 4x4x3 probe grid), `zhc gltf embed --encoding
//     zh3_q16` 120 random probes (points, special cases included), and 60 random probes converted to
//     zh3_q16 / sh3_q28 / sh2_q / hall_curve_q with non-default parameters and embedded;
//  2. zhc's own irradiance for EVERY probe in 3 directions (`zhc gltf eval`) -> WORK/spec.json;
//  3. a loopback HTTP server (127.0.0.1, ephemeral port, serves only runtime/web, three from
//     tests/js/node_modules, tests/js/browser and WORK) and headless Chromium (SwiftShader WebGL2,
//     fresh profile) open tests/js/browser/index.html: three.js GLTFLoader + ZhcLightProbesPlugin load
//     each file; irradiance of every probe in JS and in a WebGL2 shader (zhc_irradiance.glsl.mjs,
//     RGBA32F render target read back) is compared with zhc's; the page POSTs the numbers;
//  4. asserts: no console error/warning or exception, WebGL2 + EXT_color_buffer_float present, every
//     probe compared, JS bit-identical to zhc, shader (the GLSL function of the file's encoding)
//     within 2e-6 of the probe's DC irradiance term
//     (32 float ulps; see the bound in the notes below) for the packed words AND the float SH3;
//     a white MeshLambertMaterial lit only by volume.lightProbe(p) (three.js's own LightProbe
//     shading, i.e. the SphericalHarmonics3 conversion) renders zhc's irradiance within 2e-5.
// Time bounded: the whole browser part times out after 120 s (Chromium killed).
import fs from 'node:fs';
import path from 'node:path';
import { execFile, execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import { randomProbes, triangleScene, makeRand, checker } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';

const [zhc, workArg, chromiumArg] = process.argv.slice(2);
if (!zhc || !workArg) {
  console.error('usage: node browser_test.mjs ZHC_BINARY WORK_DIR [CHROMIUM]');
  process.exit(2);
}
const chromium = chromiumArg || '/usr/bin/chromium';
const work = path.resolve(workArg);
fs.mkdirSync(work, { recursive: true });
const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.resolve(here, '..', '..');
const W = (f) => path.join(work, f);
const { check, finish } = checker();

// --- 1. inputs written by zhc ----------------------------------------------------------------
fs.writeFileSync(W('scene.glb'), triangleScene());
fs.writeFileSync(W('bake_scene.json'), JSON.stringify({
  version: 1, probes: { grid: { min: [-1, -1, 0], max: [1, 1, 1.5], counts: [4, 4, 3] } }, sky: { type: 'gradient' },
  lights: [{ type: 'point', position: [0.2, -0.1, 2], intensity: [8, 6.4, 4.8], shadows: true },
    { type: 'sphere', center: [1, 1, 1], radius: 0.3, radiance: [40, 6, 3], shadows: true }],
  occluders: [{ type: 'mesh', positions: [-0.5, -0.5, 1.2, 0.5, -0.5, 1.2, 0, 0.5, 1.2] }] }));
execFileSync(zhc, ['bake', W('bake_scene.json'), '-o', W('baked_q16.glb'), '--to', 'zh3_q16', '--quiet']);
const rand = makeRand(31337);
fs.writeFileSync(W('points.json'), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
  probes: randomProbes(120, 2024).map((sh) => ({ position: [rand() * 8 - 4, rand() * 8 - 4, rand() * 3], sh3: sh })) }));
execFileSync(zhc, ['gltf', 'embed', W('scene.glb'), W('points.json'), '-o', W('points_q16.glb'), '--encoding', 'zh3_q16']);
// The other packed layouts and non-default parameters (60 probes each): .zhp by `zhc convert`, embedded.
fs.writeFileSync(W('points60.json'), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
  probes: randomProbes(60, 77).map((sh) => ({ position: [rand() * 8 - 4, rand() * 8 - 4, rand() * 3], sh3: sh })) }));
const packedCases = [
  { glb: 'q16_params.glb', enc: 'zh3_q16', flags: ['--bits', '5', '--sqrt', '--dc', 'rgb9e5', '--zonal-map', 'zero', '--axis', 'channel'] },
  { glb: 'q16_irradiance.glb', enc: 'zh3_q16', flags: ['--irradiance', '--zonal-map', 'symmetric', '--bits', '7'] },
  { glb: 'sh3_q28.glb', enc: 'sh3_q28', flags: ['--bits', '6', '--sqrt', '--bound', 'loose', '--irradiance', '--zonal-map', 'symmetric'] },
  { glb: 'sh3_q28_default.glb', enc: 'sh3_q28', flags: [] },
  { glb: 'sh2_q.glb', enc: 'sh2_q', flags: ['--dc', 'half', '--bits', '7'] },
  { glb: 'hall_curve_q.glb', enc: 'hall_curve_q', flags: ['--irradiance', '--dc', 'half'] },
  { glb: 'hall_curve_q_channel.glb', enc: 'hall_curve_q', flags: ['--axis', 'channel', '--sqrt'] },
];
for (const c of packedCases) {
  const zhp = W(c.glb.replace('.glb', '.zhp'));
  execFileSync(zhc, ['convert', W('points60.json'), '-o', zhp, '--to', c.enc, ...c.flags]);
  execFileSync(zhc, ['gltf', 'embed', W('scene.glb'), zhp, '-o', W(c.glb)]);
}
const allFiles = [{ glb: 'baked_q16.glb', enc: 'zh3_q16' }, { glb: 'points_q16.glb', enc: 'zh3_q16' }, ...packedCases];

// --- 2. zhc's irradiance for every probe -----------------------------------------------------
// Directions in glTF axes: 3 evaluated by zhc for every probe, 29 more that the page compares
// shader against JS (which is bit-identical to zhc on the first 3).
const dirs = [[0, 1, 0], [0.3, -0.8, 0.52], [-1, 0.25, -0.4]];
for (let i = 0; i < 29; i++) {  // Fibonacci sphere
  const z = 1 - (2 * i + 1) / 29, r = Math.sqrt(1 - z * z), phi = i * Math.PI * (3 - Math.sqrt(5));
  dirs.push([r * Math.cos(phi), z, r * Math.sin(phi)]);
}
const DZ = 3;
const execFileP = promisify(execFile);
async function pool(jobs, width) {
  const out = new Array(jobs.length);
  let next = 0;
  await Promise.all(Array.from({ length: width }, async () => {
    while (next < jobs.length) {
      const j = next++;
      out[j] = await jobs[j]();
    }
  }));
  return out;
}
const files = [];
for (const { glb, enc } of allFiles) {
  const info = JSON.parse(execFileSync(zhc, ['info', W(glb), '--json']).toString());
  const vols = info.volumes ?? [];
  const count = vols[0]?.probes;
  check(Number.isInteger(count) && count > 0 && vols[0].encoding === enc, `${glb}: zhc info reports a ${enc} volume`);
  const jobs = [];
  for (let p = 0; p < count; p++)
    for (let d = 0; d < DZ; d++)
      jobs.push(async () => (await execFileP(zhc, ['gltf', 'eval', W(glb), '--probe', String(p), '--dir', dirs[d].join(',')])).stdout.trim().split(/\s+/).map(Number));
  const flat = await pool(jobs, 3);
  const expected = Array.from({ length: count }, (_, p) => flat.slice(p * DZ, p * DZ + DZ));
  files.push({ glb, count, expected });
}
fs.writeFileSync(W('spec.json'), JSON.stringify({ dirs, files }));

// --- 3. server + Chromium ---------------------------------------------------------------------
const roots = {
  '/runtime/web/': path.join(repo, 'runtime', 'web'),
  '/three/': path.join(here, 'node_modules', 'three'),
  '/test/': path.join(here, 'browser'),
  '/work/': work,
};
const pages = await chromiumPages({ roots, work, chromium, check, timeoutS: 120 });
const report = await pages.runPage('index.html', ['--use-angle=swiftshader'], 'index', 'zhc runtime/web page done');
pages.close();

// --- 4. assertions -----------------------------------------------------------------------------
if (report === null) finish('runtime/web browser');
console.log(`Chromium: WebGL2 ${report.webgl2}, EXT_color_buffer_float ${report.colorBufferFloat}, renderer "${report.renderer}"`);
for (const e of report.errors ?? []) console.log(`  page: ${e}`);
check((report.errors ?? []).length === 0, 'no console error, warning or exception in the page');
check(report.webgl2 === true && report.colorBufferFloat === true, 'WebGL2 with EXT_color_buffer_float');
check(Array.isArray(report.files) && report.files.length === files.length, 'every file reported');
// Bound for the shader (float32 arithmetic): every term of E is at most ~2 Y00 |DC| (|L1| <= sqrt(3)
// DC for non-negative lighting, band scale 2/3; zonal term <= sqrt(5) DC / 4), each is formed with
// ~4 roundings and three are summed, plus the axis normalisation (<= 2.5 ulp division, sqrt) and the
// direction rounded to float: a few tens of ulp of Y00 |DC|; 2e-6 = 33.5 ulp (2^-24 = 5.96e-8).
// Probes whose ratios were clamped are inside the same envelope (the decoded ratios are bounded).
const GPU_BOUND = 2e-6;
for (const r of report.files ?? []) {
  const f = files.find((x) => x.glb === r.glb);
  console.log(`${r.glb}: ${r.count} probes x ${r.zhcDirections} directions vs zhc gltf eval: JS bit-identical ${r.jsBitExact}/${r.jsCompared} ` +
    `(worst ${r.jsWorst.toExponential(2)}); WebGL2 ${r.encoding} words worst ${r.gpuPackedWorst.toExponential(2)}, float SH3 worst ` +
    `${r.gpuSh3Worst.toExponential(2)} (|diff| / (Y00 max|DC|)); WebGL2 vs JS over ${r.directions} directions worst ` +
    `${r.gpuVsJsWorst.toExponential(2)}; non-finite ${r.gpuNonFinite}`);
  check(f && r.count === f.count && r.jsCompared === f.count * DZ && r.gpuCompared === f.count * dirs.length, `${r.glb}: every probe compared`);
  check(r.jsBitExact === r.jsCompared, `${r.glb}: JS irradiance bit-identical to zhc gltf eval`);
  check(r.gpuNonFinite === 0, `${r.glb}: shader output finite`);
  console.log(`${r.glb}: three.js MeshLambertMaterial lit by volume.lightProbe(p), ${r.threeCompared} renders vs zhc: worst ` +
    `${r.threeWorst.toExponential(2)} (|diff| / (Y00 max|DC|))`);
  // three.js's basis constants have 6 significant digits (relative errors up to 1.3e-6 per band)
  // and it shades in float32 with its own pi constants: 2e-5 of the DC term.
  check(r.threeCompared >= Math.min(16, r.count) * DZ && r.threeWorst < 2e-5, `${r.glb}: three.js LightProbe shading equals zhc's irradiance`);
  check(r.gpuPackedWorst < GPU_BOUND && r.gpuSh3Worst < GPU_BOUND && r.gpuVsJsWorst < GPU_BOUND, `${r.glb}: WebGL2 irradiance within ${GPU_BOUND} of the DC term`);
}
finish('runtime/web browser');
