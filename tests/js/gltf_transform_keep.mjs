// glTF-Transform pipelines keep ZHC_light_probes (CTest: js.gltf_transform_keep).
// Usage: node gltf_transform_keep.mjs ZHC_BINARY WORK_DIR CORPUS_DIR
//  1. inputs zhc wrote: the demo's probes.glb (zh3_q16 grid), baked glTF scenes (`zhc bake` of the
//     corpus' gt_list.glb / gt_draco.glb: meshes, lights, a grid in sh3, zh3_q16, sh3_q28, with the
//     bake's validity and cell planes accessors), and `zhc gltf embed` outputs with a second volume
//     (Draco point cloud, float points with positions, --sh-axes gltf), one with the probe nodes
//     under a transformed parent, one .gltf, a grid with validity, visibility and random cell
//     planes (grid_leak.glb), scattered probes with their tetrahedra accessors (points_tetra.glb);
//  2. the real CLI (node_modules/.bin/gltf-transform, @gltf-transform/cli 4.x) runs
//     copy, optimize, meshopt, draco, dedup, prune, quantize, flatten, sparse, weld on each
//     with --config runtime/web/gltf-transform.config.mjs;
//  3. every output: Khronos glTF-Validator 0 errors; the same volumes (definitions equal up to
//     buffer indices); `zhc gltf extract --volume i` gives the same .zhp bytes and the same float
//     SH3 JSON as for the input; each volume's nodes have the same world matrices;
//  4. without --config the CLI drops the extension (zhc gltf extract then fails), so the checks
//     above can fail; a volume key this version cannot renumber makes the CLI fail, not write;
//  5. the Extension used from a script (NodeIO, cloneDocument) keeps the volumes too.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync, spawnSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import validator from 'gltf-validator';
import * as core from '@gltf-transform/core';
import { ALL_EXTENSIONS } from '@gltf-transform/extensions';
import { cloneDocument } from '@gltf-transform/functions';
import { glb, triangleSceneParts, randomProbes, checker, makeRand } from './fixtures.mjs';
import { zhpWithPlanes, randomPlanes } from './planes_fixtures.mjs';
import { crc32 } from '../../runtime/web/zhc_runtime.mjs';
import { defineZhcLightProbes } from '../../runtime/web/zhc_gltf_transform.mjs';

const [zhc, work, corpus] = process.argv.slice(2);
if (!zhc || !work || !corpus) {
  console.error('usage: node gltf_transform_keep.mjs ZHC_BINARY WORK_DIR CORPUS_DIR');
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const cli = path.join(here, 'node_modules', '.bin', 'gltf-transform');
const config = path.resolve(here, '../../runtime/web/gltf-transform.config.mjs');
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (args) => execFileSync(zhc, args, { stdio: ['ignore', 'pipe', 'pipe'] });

// --- glTF JSON of a .glb / .gltf ------------------------------------------------------------------
function readJson(file) {
  const b = fs.readFileSync(file);
  if (b.readUInt32LE(0) !== 0x46546c67) return { json: JSON.parse(b.toString('utf8')), bin: null };
  const n = b.readUInt32LE(12);
  const json = JSON.parse(b.subarray(20, 20 + n).toString('utf8'));
  const bin = 20 + n + 8 <= b.length ? b.subarray(28 + n, 28 + n + b.readUInt32LE(20 + n)) : null;
  return { json, bin };
}

// Column-major 4x4 matrices (glTF's convention).
function mul(a, b) {
  const r = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let i = 0; i < 4; i++) for (let k = 0; k < 4; k++) r[c * 4 + i] += a[k * 4 + i] * b[c * 4 + k];
  return r;
}
function localMatrix(n) {
  if (n.matrix) return n.matrix.slice();
  const [tx, ty, tz] = n.translation ?? [0, 0, 0];
  const [x, y, z, w] = n.rotation ?? [0, 0, 0, 1];
  const [sx, sy, sz] = n.scale ?? [1, 1, 1];
  const r = [1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
    2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
    2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)];
  return [r[0] * sx, r[1] * sx, r[2] * sx, 0, r[3] * sy, r[4] * sy, r[5] * sy, 0, r[6] * sz, r[7] * sz, r[8] * sz, 0, tx, ty, tz, 1];
}
// For each volume: the world matrices of the nodes that reference it (in every scene).
function placements(json) {
  const out = (json.extensions?.ZHC_light_probes?.volumes ?? []).map(() => []);
  const nodes = json.nodes ?? [];
  const visit = (i, parent) => {
    const m = mul(parent, localMatrix(nodes[i]));
    const v = nodes[i].extensions?.ZHC_light_probes?.volume;
    if (v !== undefined && out[v]) out[v].push(m);
    for (const c of nodes[i].children ?? []) visit(c, m);
  };
  const I = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  for (const scene of json.scenes ?? []) for (const r of scene.nodes ?? []) visit(r, I);
  return out;
}
// Same multiset of world matrices per volume (node order may change: flatten reorders roots).
function samePlacements(a, b) {
  const near = (m, n) => m.every((x, e) => Math.abs(x - n[e]) <= 1e-5 * (1 + Math.abs(x)));
  if (a.length !== b.length) return false;
  for (let v = 0; v < a.length; v++) {
    if (a[v].length !== b[v].length) return false;
    const left = b[v].slice();
    for (const m of a[v]) {
      const k = left.findIndex((n) => near(m, n));
      if (k < 0) return false;
      left.splice(k, 1);
    }
  }
  return true;
}
// A volume's definition without buffer indices.
function definition(vol) {
  const d = JSON.parse(JSON.stringify(vol));
  delete d.coefficients;
  delete d.positions;
  delete d.validity;
  delete d.visibility;
  delete d.planes;
  delete d.planeSides;
  delete d.tetrahedra;
  delete d.tetraNeighbours;
  if (d.draco) delete d.draco.bufferView;
  return JSON.stringify(d);
}

async function validate(file) {
  const dir = path.dirname(file);
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 200,
    externalResourceFunction: (uri) => Promise.resolve(new Uint8Array(fs.readFileSync(path.join(dir, decodeURIComponent(uri))))),
  });
  const n = report.issues;
  for (const m of n.messages) if (m.severity === 0) console.log(`  [error] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  return n;
}

// `zhc gltf extract` of every volume: .zhp bytes and float SH3 JSON text.
function extractAll(file, count, tag) {
  const out = [];
  for (let v = 0; v < count; v++) {
    const zhp = W(`${tag}.v${v}.zhp`), js = W(`${tag}.v${v}.json`);
    run(['gltf', 'extract', file, '-o', zhp, '--volume', String(v)]);
    run(['gltf', 'extract', file, '-o', js, '--volume', String(v)]);
    out.push({ zhp: fs.readFileSync(zhp), json: fs.readFileSync(js, 'utf8') });
  }
  return out;
}

// --- 1. inputs ----------------------------------------------------------------------------------
const inputs = [];
run(['demo', '-o', W('demo'), '--threads', '2']);
inputs.push({ name: 'demo_probes.glb', file: W('demo/probes.glb') });
run(['bake', path.join(corpus, 'gt_list.glb'), '-o', W('baked_zh3_q16.glb'), '-r', 'zh3_q16', '--quiet']);
run(['bake', path.join(corpus, 'gt_list.glb'), '-o', W('baked_sh3.glb'), '-r', 'sh3', '--quiet']);
run(['bake', path.join(corpus, 'gt_draco.glb'), '-o', W('baked_draco_mesh_sh3_q28.glb'), '-r', 'sh3_q28', '--quiet']);
inputs.push({ name: 'baked_zh3_q16.glb', file: W('baked_zh3_q16.glb') });
inputs.push({ name: 'baked_sh3.glb', file: W('baked_sh3.glb') });
inputs.push({ name: 'baked_draco_mesh_sh3_q28.glb', file: W('baked_draco_mesh_sh3_q28.glb') });

// Scattered probes (positions) and a second grid, embedded as further volumes.
const probes = randomProbes(300, 77);
let s = 5;
const rand = () => ((s = (s * 1103515245 + 12345) % 2147483648) / 2147483648);
fs.writeFileSync(W('points.json'), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
  probes: probes.map((sh3) => ({ position: [rand() * 4 - 2, rand() * 4 - 2, rand() * 3], sh3 })) }));
fs.writeFileSync(W('grid.json'), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance',
  layout: { type: 'grid', origin: [-1, 0.5, 2], spacing: [0.5, 1, 2], counts: [3, 2, 4] },
  probes: probes.slice(0, 24).map((sh3) => ({ sh3 })) }));
const { json: triJson, bin: triBin } = triangleSceneParts();
fs.writeFileSync(W('tri.glb'), glb(triJson, triBin));
run(['gltf', 'embed', W('baked_zh3_q16.glb'), W('points.json'), '-o', W('two_volumes_draco14.glb'), '--draco', '--draco-bits', '14',
  '--name', 'points_draco14']);
run(['gltf', 'embed', W('two_volumes_draco14.glb'), W('points.json'), '-o', W('three_volumes_draco_lossless.glb'), '--draco',
  '--name', 'points_draco_lossless']);
run(['gltf', 'embed', W('tri.glb'), W('points.json'), '-o', W('points_sh3_gltf_axes.glb'), '--sh-axes', 'gltf']);
run(['gltf', 'embed', W('tri.glb'), W('grid.json'), '-o', W('grid_sh2_q.gltf'), '--encoding', 'sh2_q']);
inputs.push({ name: 'two_volumes_draco14.glb', file: W('two_volumes_draco14.glb') });
inputs.push({ name: 'three_volumes_draco_lossless.glb', file: W('three_volumes_draco_lossless.glb') });
inputs.push({ name: 'points_sh3_gltf_axes.glb', file: W('points_sh3_gltf_axes.glb') });
inputs.push({ name: 'grid_sh2_q.gltf', file: W('grid_sh2_q.gltf') });
// A grid with validity, visibility and cell planes accessors: a version 2 .zhp embedded.
{
  run(['convert', W('grid.json'), '-o', W('grid_q16.zhp'), '--to', 'zh3_q16']);
  const validity = Uint8Array.from({ length: 24 }, (_, i) => (i % 5 === 2 ? 0 : 1));
  const visibility = Uint8Array.from({ length: 24 }, (_, i) => (i * 37 + 11) & 0xff);
  const planes = randomPlanes({ origin: [-1, 0.5, 2], spacing: [0.5, 1, 2], counts: [3, 2, 4] }, makeRand(38));
  fs.writeFileSync(W('grid_leak.zhp'), zhpWithPlanes(new Uint8Array(fs.readFileSync(W('grid_q16.zhp'))), { validity, visibility, planes }, crc32));
  run(['gltf', 'embed', W('tri.glb'), W('grid_leak.zhp'), '-o', W('grid_leak.glb')]);
  const vol = readJson(W('grid_leak.glb')).json.extensions.ZHC_light_probes.volumes[0];
  check(['validity', 'visibility', 'planes', 'planeSides'].every((k) => Number.isInteger(vol[k])),
    'grid_leak.glb: validity, visibility, planes and planeSides accessors');
  inputs.push({ name: 'grid_leak.glb', file: W('grid_leak.glb'), leak: true });
}
// Scattered probes with their tetrahedra (`zhc convert` of the positions list writes them) and validity.
{
  run(['convert', W('points.json'), '-o', W('points_tetra.zhp'), '--to', 'zh3_q16']);
  run(['gltf', 'embed', W('tri.glb'), W('points_tetra.zhp'), '-o', W('points_tetra.glb')]);
  const vol = readJson(W('points_tetra.glb')).json.extensions.ZHC_light_probes.volumes[0];
  check(Number.isInteger(vol.tetrahedra) && Number.isInteger(vol.tetraNeighbours), 'points_tetra.glb: tetrahedra and tetraNeighbours accessors');
  inputs.push({ name: 'points_tetra.glb', file: W('points_tetra.glb'), tetra: true });
}
// The default bake of a scene with walls writes cell planes into the glTF output too.
for (const name of ['baked_zh3_q16.glb', 'baked_sh3.glb']) {
  const vol = readJson(W(name)).json.extensions.ZHC_light_probes.volumes[0];
  check(Number.isInteger(vol.planes) && Number.isInteger(vol.planeSides), `${name}: the bake's planes and planeSides accessors`);
}

// Node placement that a transform could get wrong: the probe nodes of the two-volume file under a
// translated, rotated, scaled parent, the first with its own offset, the second volume placed twice.
{
  const { json, bin } = readJson(W('two_volumes_draco14.glb'));
  const probeNodes = json.nodes.map((n, i) => (n.extensions?.ZHC_light_probes ? i : -1)).filter((i) => i >= 0);
  check(probeNodes.length === 2, 'two_volumes_draco14.glb: one node per volume');
  const q = [0.1, 0.7, -0.2, 0.6], ql = Math.hypot(...q);
  json.nodes.push({ name: 'rig', translation: [1, 2, -3], rotation: q.map((c) => c / ql), scale: [2, 2, 2], children: probeNodes });
  json.nodes[probeNodes[0]].translation = [0.5, 0, 0.25];
  json.nodes.push({ name: 'second copy', translation: [-4, 0, 0], extensions: { ZHC_light_probes: { volume: 1 } } });
  const sc = json.scenes[json.scene ?? 0];
  sc.nodes = sc.nodes.filter((i) => !probeNodes.includes(i)).concat([json.nodes.length - 2, json.nodes.length - 1]);
  fs.writeFileSync(W('placed.glb'), glb(json, Buffer.from(bin)));
  inputs.push({ name: 'placed.glb', file: W('placed.glb') });
}

// Inputs: valid, and their reference extractions.
for (const inp of inputs) {
  const n = await validate(inp.file);
  check(n.numErrors === 0, `${inp.name}: input validates`);
  inp.json = readJson(inp.file).json;
  inp.volumes = inp.json.extensions.ZHC_light_probes.volumes;
  inp.placements = placements(inp.json);
  inp.extracted = extractAll(inp.file, inp.volumes.length, `in_${inp.name}`);
  console.log(`input ${inp.name}: ${inp.volumes.map((v) => `${v.encoding}/${v.layout}${v.draco ? '/draco' : ''}`).join(', ')}`);
  if (inp.leak) {  // the extraction is the embedded version 2 .zhp (sections: 24 + 24 + 5 x 24 bytes)
    const z = inp.extracted[0].zhp, src = fs.readFileSync(W('grid_leak.zhp'));
    check(z[8] === 2 && z[21] === 7 && z.equals(src),
      'grid_leak.glb: zhc gltf extract gives the .zhp it was embedded from (validity, visibility, planes)');
  }
  if (inp.tetra) {  // the extraction is the embedded version 2 .zhp with its tetrahedra section
    const z = inp.extracted[0].zhp, src = fs.readFileSync(W('points_tetra.zhp'));
    check(z[8] === 2 && z[21] === 8 && z.equals(src), 'points_tetra.glb: zhc gltf extract gives the .zhp it was embedded from (tetrahedra)');
  }
}

// --- 2./3. the CLI with the config ----------------------------------------------------------------
// Every command on the inputs that cover the encodings' storage kinds (quantised grid, float
// grid with a Draco-compressed mesh... see `full`), copy and optimize on all of them.
const commands = ['copy', 'optimize', 'meshopt', 'draco', 'dedup', 'prune', 'quantize', 'flatten', 'sparse', 'weld'];
const full = new Set(['demo_probes.glb', 'baked_zh3_q16.glb', 'placed.glb', 'points_sh3_gltf_axes.glb', 'grid_leak.glb', 'points_tetra.glb']);
function gltfTransform(args) {
  return spawnSync(cli, args, { encoding: 'utf8', cwd: work });
}
const kept = {};
for (const inp of inputs) {
  for (const cmd of commands) {
    if (!full.has(inp.name) && cmd !== 'copy' && cmd !== 'optimize') continue;
    const out = W(`out_${cmd}_${inp.name.replace(/\.gltf$/, '.glb')}`);
    const tag = `${cmd} ${inp.name}`;
    const r = gltfTransform([cmd, inp.file, out, '--config', config]);
    if (r.status !== 0 || !fs.existsSync(out)) {
      check(false, `${tag}: gltf-transform failed: ${r.stderr}`);
      continue;
    }
    check(!/ZHC_light_probes/.test(r.stderr + r.stdout), `${tag}: no warning about ZHC_light_probes`);
    const n = await validate(out);
    check(n.numErrors === 0, `${tag}: validator errors ${n.numErrors}`);
    const { json } = readJson(out);
    const vols = json.extensions?.ZHC_light_probes?.volumes ?? [];
    check(json.extensionsUsed?.includes('ZHC_light_probes'), `${tag}: ZHC_light_probes in extensionsUsed`);
    check(!(json.extensionsRequired ?? []).includes('ZHC_light_probes'), `${tag}: ZHC_light_probes not required`);
    check(vols.length === inp.volumes.length, `${tag}: ${vols.length} volumes, expected ${inp.volumes.length}`);
    if (vols.length !== inp.volumes.length) continue;
    for (let v = 0; v < vols.length; v++)
      check(definition(vols[v]) === definition(inp.volumes[v]), `${tag}: volume ${v} definition (encoding, count, grid, quantization, ...)`);
    check(samePlacements(placements(json), inp.placements), `${tag}: each volume's nodes keep their world placement`);
    const got = extractAll(out, vols.length, `out_${cmd}_${inp.name}`);
    let same = true;
    for (let v = 0; v < vols.length; v++) {
      same &&= got[v].zhp.equals(inp.extracted[v].zhp) && got[v].json === inp.extracted[v].json;
    }
    check(same, `${tag}: zhc gltf extract gives the same .zhp bytes and SH3 as the input's`);
    if (same) (kept[cmd] ??= []).push(inp.name);
  }
}
for (const cmd of commands) {
  const tried = inputs.filter((i) => full.has(i.name) || cmd === 'copy' || cmd === 'optimize').length;
  console.log(`gltf-transform ${cmd} --config ...: probes kept bit for bit in ${(kept[cmd] ?? []).length}/${tried} inputs`);
}

// .gltf output (probe data in the external .bin) and merge (volumes of two assets in one).
{
  const inp = inputs.find((i) => i.name === 'placed.glb');
  fs.mkdirSync(W('sep'), { recursive: true });
  const r = gltfTransform(['copy', inp.file, W('sep/placed.gltf'), '--config', config]);
  check(r.status === 0 && fs.existsSync(W('sep/placed.bin')), 'copy to .gltf + .bin');
  if (r.status === 0) {
    check((await validate(W('sep/placed.gltf'))).numErrors === 0, 'copy to .gltf: validator errors');
    const got = extractAll(W('sep/placed.gltf'), 2, 'sep_placed');
    check(got.every((g, v) => g.zhp.equals(inp.extracted[v].zhp) && g.json === inp.extracted[v].json), 'copy to .gltf keeps the probe bytes');
  }
  const a = inputs.find((i) => i.name === 'demo_probes.glb'), b = inputs.find((i) => i.name === 'baked_sh3.glb');
  const m = gltfTransform(['merge', a.file, b.file, W('merged.glb'), '--config', config]);
  check(m.status === 0, `merge: ${m.stderr}`);
  if (m.status === 0) {
    const got = extractAll(W('merged.glb'), 2, 'merged');
    check(got[0].zhp.equals(a.extracted[0].zhp) && got[1].zhp.equals(b.extracted[0].zhp), 'merge keeps both assets\' volumes, in order');
    check(samePlacements(placements(readJson(W('merged.glb')).json), [...a.placements, ...b.placements]), 'merge keeps placements');
  }
}

// Something actually happened to the rest of the asset (else the test proves little): meshopt
// and draco compressed the baked scene's mesh, quantize quantised it.
{
  const used = (cmd) => readJson(W(`out_${cmd}_baked_zh3_q16.glb`)).json.extensionsUsed ?? [];
  check(used('meshopt').includes('EXT_meshopt_compression'), 'meshopt output uses EXT_meshopt_compression');
  check(used('optimize').includes('EXT_meshopt_compression'), 'optimize output uses EXT_meshopt_compression');
  check(used('draco').includes('KHR_draco_mesh_compression'), 'draco output uses KHR_draco_mesh_compression');
  check(used('quantize').includes('KHR_mesh_quantization'), 'quantize output uses KHR_mesh_quantization');
}

// --- 4. without the config the probes are lost (the failure the config fixes) ---------------------
for (const inp of inputs.slice(0, 2)) {
  const out = W(`noconfig_${inp.name}`);
  const r = gltfTransform(['copy', inp.file, out]);
  check(r.status === 0 && /Missing optional extension, "ZHC_light_probes"/.test(r.stderr + r.stdout),
    `${inp.name}: plain gltf-transform copy warns "Missing optional extension"`);
  const { json } = readJson(out);
  check(!json.extensions?.ZHC_light_probes && !(json.extensionsUsed ?? []).includes('ZHC_light_probes'), `${inp.name}: plain copy drops the extension`);
  const x = spawnSync(zhc, ['gltf', 'extract', out, '-o', W(`noconfig_${inp.name}.zhp`)]);
  check(x.status !== 0, `${inp.name}: zhc gltf extract of the plain copy fails (exit ${x.status})`);
}
// A volume key this version cannot renumber (it might be an index): refused, nothing written.
{
  const { json, bin } = readJson(W('baked_zh3_q16.glb'));
  json.extensions.ZHC_light_probes.volumes[0].futureAccessor = 0;
  fs.writeFileSync(W('unknown_key.glb'), glb(json, Buffer.from(bin)));
  const r = gltfTransform(['copy', W('unknown_key.glb'), W('out_unknown_key.glb'), '--config', config]);
  check(r.status !== 0 && /futureAccessor/.test(r.stderr + r.stdout) && !fs.existsSync(W('out_unknown_key.glb')),
    `a volume with an unknown numeric key is refused (exit ${r.status})`);
  // Index-free unknown keys (strings, booleans) and extras are carried verbatim.
  const j2 = readJson(W('baked_zh3_q16.glb')).json;
  j2.extensions.ZHC_light_probes.volumes[0].note = 'kept';
  j2.extensions.ZHC_light_probes.volumes[0].extras = { tag: [1, 2] };
  j2.extensions.ZHC_light_probes.extras = { rootTag: true };
  fs.writeFileSync(W('string_key.glb'), glb(j2, Buffer.from(bin)));
  const r2 = gltfTransform(['optimize', W('string_key.glb'), W('out_string_key.glb'), '--config', config]);
  const e2 = r2.status === 0 ? readJson(W('out_string_key.glb')).json.extensions?.ZHC_light_probes : null;
  check(e2 && e2.volumes[0].note === 'kept' && JSON.stringify(e2.volumes[0].extras) === '{"tag":[1,2]}' && e2.extras?.rootTag === true,
    'index-free unknown volume keys and extras are carried');
}

// --- 5. the Extension from a script ----------------------------------------------------------------
{
  const ZhcLightProbes = defineZhcLightProbes(core);
  check(defineZhcLightProbes(core) === ZhcLightProbes, 'defineZhcLightProbes returns one class per core module');
  const io = new core.NodeIO().registerExtensions([...ALL_EXTENSIONS, ZhcLightProbes]);
  const inp = inputs.find((i) => i.name === 'placed.glb');
  const doc = await io.read(inp.file);
  const ext = doc.getRoot().listExtensionsUsed().find((e) => e.extensionName === 'ZHC_light_probes');
  const vols = ext ? ext.listVolumes() : [];
  check(vols.length === 2, 'script: two volumes read');
  if (vols.length === 2) {
    check(vols[0].getEncoding() === 'zh3_q16' && vols[0].getLayout() === 'grid' && vols[0].getCount() === vols[0].getGrid().counts.reduce((a, b) => a * b, 1),
      'script: volume 0 is the zh3_q16 grid');
    check(vols[1].getDracoPayload() instanceof Uint8Array && vols[1].getAccessorData('coefficients') === null, 'script: volume 1 holds its Draco payload');
    const coeff = vols[0].getAccessorData('coefficients');
    check(coeff && coeff.bytes.length === 16 * vols[0].getCount() && coeff.componentType === 5121, 'script: volume 0 coefficient bytes');
    check(vols[1].listParents().filter((p) => p.propertyType === 'Node').length === 2, 'script: volume 1 is placed by two nodes');
  }
  const copy = cloneDocument(doc);
  await io.write(W('script_clone.glb'), copy);
  const got = extractAll(W('script_clone.glb'), 2, 'script_clone');
  check(got.every((g, v) => g.zhp.equals(inp.extracted[v].zhp)), 'script: cloneDocument + write keeps the probe bytes');
  check(samePlacements(placements(readJson(W('script_clone.glb')).json), inp.placements), 'script: clone keeps placements');
}

finish('glTF-Transform keep');
