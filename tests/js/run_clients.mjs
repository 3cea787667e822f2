// Real glTF clients against files zhc writes (CTest: js.gltf_clients).
// Usage: node run_clients.mjs ZHC_BINARY WORK_DIR
//  1. writes a small scene (GLB, a triangle + material) and probe lists (grid, scattered);
//  2. `zhc gltf embed` them in every mode (grid sh3 / zh3_q16 / .gltf, scattered sh3, Draco,
//     --sh-axes gltf);
//  3. Khronos glTF-Validator: 0 errors on every output;
//  4. three.js GLTFLoader + ZhcLightProbesPlugin (runtime/web): loads each GLB, finds the volume and its
//     node, and the irradiance it evaluates in several directions (float and quantised encodings)
//     equals `zhc gltf eval` (zhc's own numbers; bit for bit: tests/js/runtime_decode.mjs);
//  5. `zhc bake -o OUT.glb|.gltf` of a glTF scene (lights + mesh) and of a JSON scene: validator
//     clean, the plugin finds the volume.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { register } from 'node:module';
import validator from 'gltf-validator';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { glb, triangleSceneParts, checker } from './fixtures.mjs';

// The plugin lives in runtime/web (issue 15); its bare 'three' import resolves to tests/js/node_modules.
register('./three_resolver.mjs', import.meta.url);
const { ZhcLightProbesPlugin } = await import('../../runtime/web/zhc_light_probes_plugin.mjs');

const [zhc, work] = process.argv.slice(2);
if (!zhc || !work) {
  console.error('usage: node run_clients.mjs ZHC_BINARY WORK_DIR');
  process.exit(2);
}
fs.mkdirSync(work, { recursive: true });
const { check, finish } = checker();

// --- inputs -------------------------------------------------------------------------------
const { json: scene, bin: tri } = triangleSceneParts();
fs.writeFileSync(path.join(work, 'scene.glb'), glb(scene, tri));

// Deterministic, physically plausible probes: a sky-ish DC plus directional lobes.
let seed = 12345;
const rand = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);
const probe = () => Array.from({ length: 9 }, (_, i) =>
  Array.from({ length: 3 }, () => (i === 0 ? 1 + rand() : (rand() - 0.5) * (i < 4 ? 0.8 : 0.4))));
const grid = { format: 'zhc-probes', version: 1, kind: 'radiance',
  layout: { type: 'grid', origin: [-1, 0.5, 2], spacing: [0.5, 1, 2], counts: [3, 2, 4] },
  probes: Array.from({ length: 24 }, () => ({ sh3: probe() })) };
const points = { format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
  probes: Array.from({ length: 200 }, () => ({ position: [rand() * 10 - 5, rand() * 4, rand() * 10 - 5], sh3: probe() })) };
fs.writeFileSync(path.join(work, 'grid.json'), JSON.stringify(grid));
fs.writeFileSync(path.join(work, 'points.json'), JSON.stringify(points));

// --- zhc writes every mode ------------------------------------------------------------------
const cases = [
  { out: 'grid_sh3.glb', probes: 'grid.json', args: [] },
  { out: 'grid_zh3_q16.glb', probes: 'grid.json', args: ['--encoding', 'zh3_q16'] },
  { out: 'grid_sh3_q28.gltf', probes: 'grid.json', args: ['--encoding', 'sh3_q28'] },
  { out: 'points_sh3.glb', probes: 'points.json', args: [] },
  { out: 'points_gltf_axes.glb', probes: 'points.json', args: ['--sh-axes', 'gltf'] },
  { out: 'points_draco.glb', probes: 'points.json', args: ['--draco'] },
  { out: 'points_draco14.glb', probes: 'points.json', args: ['--draco', '--draco-bits', '14'] },
];
for (const c of cases) {
  execFileSync(zhc, ['gltf', 'embed', path.join(work, 'scene.glb'), path.join(work, c.probes), '-o', path.join(work, c.out), ...c.args]);
}

// --- 1. Khronos glTF-Validator -----------------------------------------------------------------
for (const c of cases) {
  const file = path.join(work, c.out);
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: c.out,
    externalResourceFunction: (uri) => Promise.reject(new Error(`unexpected external resource ${uri}`)),
  });
  const n = report.issues;
  console.log(`validator ${c.out}: errors ${n.numErrors}, warnings ${n.numWarnings}, infos ${n.numInfos}`);
  for (const m of n.messages) if (m.severity <= 1) console.log(`  ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  check(n.numErrors === 0, `${c.out}: validator errors`);
  check(n.numWarnings === 0, `${c.out}: validator warnings`);
}

// --- 2. three.js GLTFLoader with the plugin ----------------------------------------------------
async function loadThree(file) {
  const bytes = fs.readFileSync(file);
  const ab = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  return new Promise((resolve, reject) => loader.parse(ab, '', resolve, reject));
}
const dirs = [[0, 1, 0], [0, -1, 0], [1, 0, 0], [0, 0, 1], [0.3, 0.8, -0.52], [-0.6, 0.2, 0.77]];
for (const c of cases.filter((c) => c.out.endsWith('.glb'))) {
  const file = path.join(work, c.out);
  const gltf = await loadThree(file);
  const vols = gltf.userData.zhcLightProbes;
  check(Array.isArray(vols) && vols.length === 1, `${c.out}: three.js plugin found the volume`);
  if (!vols || !vols.length) continue;
  const v = vols[0];
  // The node that references the volume is in the scene graph.
  let anchor = null;
  gltf.scene.traverse((o) => { if (o.userData.zhcLightProbeVolume !== undefined) anchor = o; });
  check(anchor && anchor.userData.zhcLightProbeVolume === 0, `${c.out}: node attachment for the volume`);
  check(gltf.scene.getObjectByName('tri') !== undefined, `${c.out}: the original mesh node still loads`);
  if (v.draco) continue;
  const bytesPerProbe = { sh3: 108, zh3_q16: 16, sh3_q28: 28 }[v.encoding];
  check(v.bytes && v.bytes.length === v.count * bytesPerProbe, `${c.out}: stored ${v.encoding} bytes length`);
  check(anchor.userData.zhcLightProbes === v, `${c.out}: the node attachment carries the decoded volume`);
  let worst = 0;
  const probes = v.layout === 'grid' ? [0, 5, 23] : [0, 17, 199];
  for (const p of probes) {
    for (const d of dirs) {
      const got = v.irradiance(p, d);
      const out = execFileSync(zhc, ['gltf', 'eval', file, '--probe', String(p), '--dir', d.join(',')]).toString();
      const want = out.trim().split(/\s+/).map(Number);
      for (let k = 0; k < 3; k++) worst = Math.max(worst, Math.abs(got[k] - want[k]) / (1e-6 + Math.abs(want[k])));
    }
  }
  console.log(`three.js ${c.out}: ${v.encoding} ${v.layout} shAxes=${v.shAxes}, worst relative irradiance difference vs zhc ${worst.toExponential(2)}`);
  check(worst < 1e-5, `${c.out}: three.js irradiance equals zhc's`);
}

// --- 3. zhc bake -o OUT.glb|.gltf: a glTF scene with a KHR_lights_punctual light over the
// triangle (the mesh occludes), and a JSON scene into a minimal asset; every output validates and
// the three.js plugin finds the baked volume.
const litScene = JSON.parse(JSON.stringify(scene));
litScene.nodes.push({ name: 'lamp', translation: [0.3, 0.2, 2], extensions: { KHR_lights_punctual: { light: 0 } } });
litScene.scenes[0].nodes.push(1);
litScene.extensionsUsed = ['KHR_lights_punctual'];
litScene.extensions = { KHR_lights_punctual: { lights: [{ type: 'point', intensity: 20, color: [1, 0.9, 0.8] }] } };
litScene.extras = { zhc: { sky: { type: 'constant', radiance: 0.1 } } };
fs.writeFileSync(path.join(work, 'lit_scene.glb'), glb(litScene, tri));
fs.writeFileSync(path.join(work, 'bake_scene.json'), JSON.stringify({
  version: 1, probes: { grid: { min: [-1, -1, 0], max: [1, 1, 1], counts: [3, 3, 2] } }, sky: { type: 'gradient' },
  lights: [{ type: 'point', position: [0, 0, 2], intensity: 5, shadows: true }],
  occluders: [{ type: 'mesh', positions: [-0.5, -0.5, 1.5, 0.5, -0.5, 1.5, 0, 0.5, 1.5] }] }));
const bakes = [
  { out: 'baked_lit_scene.glb', input: 'lit_scene.glb', args: [] },
  { out: 'baked_lit_scene_q16.gltf', input: 'lit_scene.glb', args: ['--to', 'zh3_q16'] },
  { out: 'baked_json_scene.glb', input: 'bake_scene.json', args: [] },
];
for (const b of bakes) {
  execFileSync(zhc, ['bake', path.join(work, b.input), '-o', path.join(work, b.out), '--quiet', ...b.args]);
  const file = path.join(work, b.out);
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: b.out,
    externalResourceFunction: (uri) => Promise.reject(new Error(`unexpected external resource ${uri}`)),
  });
  const n = report.issues;
  console.log(`validator ${b.out}: errors ${n.numErrors}, warnings ${n.numWarnings}, infos ${n.numInfos}`);
  for (const m of n.messages) if (m.severity <= 1) console.log(`  ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  check(n.numErrors === 0, `${b.out}: validator errors`);
  check(n.numWarnings === 0, `${b.out}: validator warnings`);
  if (b.out.endsWith('.glb')) {
    const gltf = await loadThree(file);
    const vols = gltf.userData.zhcLightProbes;
    check(Array.isArray(vols) && vols.length === 1, `${b.out}: three.js plugin found the baked volume`);
    if (b.input.endsWith('.glb')) check(gltf.scene.getObjectByName('tri') !== undefined, `${b.out}: the input's mesh is kept`);
  }
}

finish('glTF client');
