// Scattered probes through glTF and the three.js GLTFLoader plugin (CTest: js.plugin_tetra).
// Usage: node plugin_tetra.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR
//
//  1. `zhc convert` of JSON probe lists with positions (random sets in sh3 and zh3_q16, one with a
//     validity section) and `zhc bake` of tests/data/leak_room.json with 40 probes placed in the
//     room write `points` .zhp files with their tetrahedra; `zhc gltf embed` puts each in a GLB
//     (default --sh-axes zhc, and --sh-axes gltf). The Khronos glTF-Validator reports no error on
//     any of them (the tetrahedra / tetraNeighbours accessors are VEC4 UNSIGNED_INT);
//  2. the plugin's volume.tetrahedra / volume.neighbours are the .zhp's (zhc_runtime.mjs parseZhp);
//     ZhcProbeVolume.irradianceAt at random points in and around the hull (glTF axes) gives the SAME
//     float32 values as the C header's zhc_volume_irradiance on the .zhp at the same points in zhc
//     axes (shAxes zhc), within 1e-6 of the mean irradiance for shAxes gltf (rotated coefficients);
//  3. threeSHAt: three.js's own SphericalHarmonics3.getIrradianceAt(n) / pi of the returned SH agrees
//     with irradianceAt within three.js's 6-digit basis constants (2e-5 of the mean), and a
//     LightProbe given it shades as three.js documents; tetraWeights: weights >= 0 summing to 1,
//     the same blend from the last tetrahedron as from tetrahedron 0;
//  4. refusals: one accessor of the two, tetrahedra on a grid, sizes not 4 per tetrahedron or
//     unequal, an index out of range, a neighbour not sharing its face (buildVolume and the loader);
//     irradianceAt on a points volume without tetrahedra says so.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { register } from 'node:module';
import validator from 'gltf-validator';
import { makeRand, checker, triangleScene, freshWork, zhpWithSections } from './fixtures.mjs';

register('./three_resolver.mjs', import.meta.url);
const runtime = await import('../../runtime/web/zhc_runtime.mjs');
const { ZhcLightProbesPlugin, buildVolume } = await import('../../runtime/web/zhc_light_probes_plugin.mjs');
const THREE = await import('three');
const { GLTFLoader } = await import('three/examples/jsm/loaders/GLTFLoader.js');

const [zhc, sampler, workArg] = process.argv.slice(2);
if (!zhc || !sampler || !workArg) {
  console.error('usage: node plugin_tetra.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR');
  process.exit(2);
}
const work = freshWork(workArg);
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28, stdio: ['ignore', 'pipe', 'pipe'] }).toString();
const f32 = Math.fround;
const throwsWith = (f, re) => { try { f(); return false; } catch (e) { return e instanceof Error && re.test(e.message); } };
const sameArray = (a, b) => a.length === b.length && a.every((x, i) => x === b[i]);

function probeList(positions, rand) {
  return JSON.stringify({ format: 'zhc-probes', version: 1, layout: { type: 'positions' },
    probes: positions.map((p) => ({ position: p, sh3: Array.from({ length: 9 }, (_, i) => [0, 1, 2].map(() => (i === 0 ? 0.5 + rand() : rand() - 0.5))) })) });
}
// A points .zhp (uncompressed, tetrahedra section last) with a validity section added before its tetrahedra.
function withValidity(bytes, validity) {
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const count = Number(dv.getBigUint64(56, true)), bpp = dv.getUint32(64, true);
  const split = 184 + count * 12 + count * bpp;
  const head = zhpWithSections(bytes.slice(0, split), validity, null, runtime.crc32);  // header + payload + validity
  const out = new Uint8Array(head.length + bytes.length - split);
  out.set(head);
  out.set(bytes.subarray(split), head.length);
  const o = new DataView(out.buffer);
  out[21] = 1 | 8;
  const body = BigInt(out.length - 184);
  o.setBigUint64(160, body, true);
  o.setBigUint64(168, body, true);
  o.setUint32(176, runtime.crc32(out, 184, out.length), true);
  o.setUint32(180, runtime.crc32(out, 0, 180), true);
  return out;
}
// Random points in the box [lo, hi] (zhc axes) with random unit normals, float32.
function randomSamples(lo, hi, n, seed) {
  const rand = makeRand(seed);
  const pts = [];
  for (let i = 0; i < n; i++) {
    const p = [0, 1, 2].map((c) => f32(lo[c] + (hi[c] - lo[c]) * rand()));
    const z = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - z * z));
    pts.push({ p, n: [f32(r * Math.cos(phi)), f32(r * Math.sin(phi)), f32(z)] });
  }
  return pts;
}
// The C99 sampler's float32 results at the points (zhc_volume_from_zhp + zhc_volume_irradiance).
function sampleC(zhp, pts) {
  const file = W('points.txt');
  fs.writeFileSync(file, pts.map(({ p, n }) => [...p, ...n].map((x) => x.toPrecision(9)).join(' ')).join('\n') + '\n');
  const out = execFileSync(sampler, [zhp, file], { maxBuffer: 1 << 28 }).toString().trim().split('\n');
  return out.map((line) => line.trim().split(/\s+/).map((x) => f32(Number(x))));
}
async function loadThree(file) {
  const bytes = fs.readFileSync(file);
  const ab = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  return new Promise((resolve, reject) => loader.parse(ab, '', resolve, reject));
}
async function validate(file) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file), maxIssues: 100,
    externalResourceFunction: (uri) => Promise.reject(new Error(`unexpected external resource ${uri}`)),
  });
  for (const m of report.issues.messages) if (m.severity === 0) console.log(`  [error] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  return report.issues.numErrors;
}

fs.writeFileSync(W('tri.glb'), triangleScene());

// --- 1-3: files zhc wrote, against the C header -----------------------------------------------------
const cases = [];
for (const [seed, rep] of [[1, 'sh3'], [2, 'zh3_q16']]) {
  const rand = makeRand(seed);
  const positions = Array.from({ length: 60 + 20 * seed }, () => [0, 1, 2].map(() => f32(6 * rand())));
  fs.writeFileSync(W(`random${seed}.json`), probeList(positions, rand));
  run('convert', W(`random${seed}.json`), '-o', W(`random${seed}.zhp`), '--to', rep);
  cases.push({ name: `random${seed}`, zhp: W(`random${seed}.zhp`), lo: [-2, -2, -2], hi: [8, 8, 8] });
}
{
  const bytes = new Uint8Array(fs.readFileSync(W('random2.zhp')));
  const count = runtime.parseZhp(bytes).count;
  const validity = new Uint8Array(count).fill(1);
  for (let i = 1; i < count; i += 5) validity[i] = 0;
  fs.writeFileSync(W('random2_valid.zhp'), withValidity(bytes, validity));
  cases.push({ name: 'random2_valid', zhp: W('random2_valid.zhp'), lo: [-1, -1, -1], hi: [7, 7, 7] });
}
{
  const scene = JSON.parse(fs.readFileSync(new URL('../data/leak_room.json', import.meta.url)));
  const rand = makeRand(23);
  scene.probes = { positions: Array.from({ length: 40 }, () => [2.55 + 3.8 * rand(), 0.2 + 4.15 * rand(), -0.35 + 3.7 * rand()].map((v) => Math.round(1000 * v) / 1000)) };
  fs.writeFileSync(W('room.json'), JSON.stringify(scene));
  run('bake', W('room.json'), '-o', W('room.zhp'), '--to', 'zh3_q16', '--rays', '256:1024', '--quiet');
  cases.push({ name: 'room', zhp: W('room.zhp'), lo: [2.4, 0.05, -0.5], hi: [6.5, 4.5, 3.5] });
}

let seed = 100;
for (const c of cases) {
  const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(c.zhp)));
  check(z.layout === 'positions' && z.tetrahedra && z.tetrahedra.length >= 4, `${c.name}.zhp: a points set with tetrahedra`);
  check(Boolean(z.validity) === c.name.endsWith('_valid'), `${c.name}.zhp: a validity section exactly where one was added`);
  const pts = randomSamples(c.lo, c.hi, 2000, seed++);
  const want = sampleC(c.zhp, pts);
  check(want.length === pts.length, `${c.name}: the C sampler answers every point`);
  let mean = 0;
  for (const e of want) mean += (Math.abs(e[0]) + Math.abs(e[1]) + Math.abs(e[2])) / 3;
  mean /= want.length;
  for (const axes of ['zhc', 'gltf']) {
    const glbFile = W(`${c.name}_${axes}.glb`);
    run('gltf', 'embed', W('tri.glb'), c.zhp, '-o', glbFile, '--sh-axes', axes);
    check(await validate(glbFile) === 0, `${c.name}_${axes}.glb: the glTF-Validator reports no error`);
    const gltf = await loadThree(glbFile);
    const v = gltf.userData.zhcLightProbes[0];
    const def = JSON.parse(fs.readFileSync(glbFile).subarray(20, 20 + fs.readFileSync(glbFile).readUInt32LE(12)).toString('utf8'))
      .extensions.ZHC_light_probes.volumes[0];
    check(Number.isInteger(def.tetrahedra) && Number.isInteger(def.tetraNeighbours), `${c.name}_${axes}.glb: tetrahedra and tetraNeighbours accessors`);
    check(v.tetrahedra instanceof Uint32Array && sameArray(v.tetrahedra, z.tetrahedra), `${c.name}_${axes}: volume.tetrahedra is the .zhp's`);
    check(v.neighbours instanceof Int32Array && sameArray(v.neighbours, z.neighbours), `${c.name}_${axes}: volume.neighbours is the .zhp's (-1 on the hull)`);
    check(Boolean(v.validity) === Boolean(z.validity), `${c.name}_${axes}: validity read`);
    let same = 0, worst = 0, worstThree = 0, worstSum = 0, startDiff = 0, inside = 0;
    const shThree = new THREE.SphericalHarmonics3(), target = new THREE.Vector3();
    let last = 0;
    pts.forEach(({ p, n }, i) => {
      const pg = runtime.zhcToGltfDir(p), ng = runtime.zhcToGltfDir(n);  // zhc (x, y, z) -> glTF (y, z, x)
      const got = v.irradianceAt(pg, ng);
      if (got.every((x, k) => Object.is(x, want[i][k]))) same++;
      for (let k = 0; k < 3; k++) worst = Math.max(worst, Math.abs(got[k] - want[i][k]) / mean);
      // three.js: getIrradianceAt(n) = pi E(n) of the SH a LightProbe holds.
      v.threeSHAt(pg, shThree).getIrradianceAt(new THREE.Vector3(...ng), target);
      const e3 = [target.x / Math.PI, target.y / Math.PI, target.z / Math.PI];
      for (let k = 0; k < 3; k++) worstThree = Math.max(worstThree, Math.abs(e3[k] - got[k]) / mean);
      const t0 = v.tetraWeights(pg), t1 = v.tetraWeights(pg, last);
      last = t1.tetra;
      inside += t0.inside;
      worstSum = Math.max(worstSum, Math.abs(t0.weights.reduce((a, b) => a + b, 0) - 1));
      if (!t0.weights.every((w) => w >= 0)) worstSum = Infinity;
      const a = new Map(), b = new Map();
      t0.probes.forEach((q, k) => a.set(q, (a.get(q) ?? 0) + t0.weights[k]));
      t1.probes.forEach((q, k) => b.set(q, (b.get(q) ?? 0) + t1.weights[k]));
      for (const [q, w] of a) if (w > 1e-12) startDiff = Math.max(startDiff, Math.abs((b.get(q) ?? 0) - w));
    });
    console.log(`${c.name}_${axes}.glb: ${pts.length} samples (${inside} inside the hull), mean ${mean.toPrecision(6)}: ` +
      `${same} bit-identical to C, max error / mean ${worst.toExponential(2)}; three.js SH vs irradianceAt ${worstThree.toExponential(2)}; ` +
      `max |sum w - 1| ${worstSum.toExponential(2)}, start changes a weight by ${startDiff.toExponential(2)}`);
    if (axes === 'zhc') check(same === pts.length, `${c.name}_${axes}: irradianceAt bit-identical to the C header at every point`);
    else check(mean > 0 && worst <= 1e-6, `${c.name}_${axes}: irradianceAt agrees with the C header within 1e-6 of the mean`);
    check(inside > pts.length / 10 && inside < pts.length, `${c.name}_${axes}: points inside and outside the hull`);
    check(worstThree <= 2e-5, `${c.name}_${axes}: three.js's getIrradianceAt / pi of threeSHAt agrees with irradianceAt`);
    check(worstSum <= 1e-12, `${c.name}_${axes}: tetraWeights >= 0, summing to 1`);
    check(startDiff <= 1e-12, `${c.name}_${axes}: the walk's start does not change the blend`);
    c.glb = W(`${c.name}_zhc.glb`);
  }
}
// A LightProbe lit by threeSHAt: three.js's shading input is the SH it holds (a copy).
{
  const v = (await loadThree(cases[0].glb)).userData.zhcLightProbes[0];
  const probe = new THREE.LightProbe();
  const pos = [3, 3, 3];
  v.threeSHAt(pos, probe.sh);
  const direct = v.threeSHAt(pos);
  check(probe.sh.coefficients.every((c, i) => c.equals(direct.coefficients[i])) && probe.sh.coefficients[0].x > 0,
    'LightProbe.sh filled in place by threeSHAt');
}

// --- 4: refusals ------------------------------------------------------------------------------------------
{
  const def = { encoding: 'sh3', count: 5, layout: 'points', shAxes: 'zhc' };
  const coeffs = new Float32Array(5 * 27).fill(0.5);
  const pos = new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1]);
  // Two tetrahedra sharing face (1, 2, 3): (0, 1, 2, 3) and (4, 1, 3, 2) (glTF axes; orientation irrelevant here).
  const tets = new Uint32Array([0, 1, 2, 3, 4, 1, 3, 2]), nbrs = new Uint32Array([1, 0xFFFFFFFF, 0xFFFFFFFF, 0xFFFFFFFF, 0, 0xFFFFFFFF, 0xFFFFFFFF, 0xFFFFFFFF]);
  const ok = buildVolume(def, coeffs, pos, null, null, null, null, tets, nbrs);
  check(sameArray(ok.tetrahedra, tets) && sameArray(ok.neighbours, [1, -1, -1, -1, 0, -1, -1, -1]), 'buildVolume: tetrahedra, neighbours with -1 on the hull');
  // Every probe the same: any blend is that probe's irradiance.
  const e = ok.irradianceAt([0.2, 0.3, 0.1], [0.3, 1, 0]), e0 = ok.irradiance(0, [0.3, 1, 0]);
  check(e.every((x, k) => Math.abs(x - e0[k]) <= 1e-6 * Math.abs(e0[k]) && e0[k] !== 0), `buildVolume: a points volume of equal probes samples their irradiance (${e} vs ${e0})`);
  const plain = buildVolume(def, coeffs, pos);
  check(plain.tetrahedra === null && plain.neighbours === null, 'buildVolume: no tetrahedra -> null');
  check(throwsWith(() => plain.irradianceAt([0, 0, 0], [0, 1, 0]), /layout points without tetrahedra/), 'irradianceAt on points without tetrahedra says so');
  check(throwsWith(() => buildVolume(def, coeffs, pos, null, null, null, null, tets, null), /tetrahedra without tetraNeighbours/), 'refused: tetrahedra alone');
  check(throwsWith(() => buildVolume(def, coeffs, pos, null, null, null, null, null, nbrs), /tetraNeighbours without tetrahedra/), 'refused: tetraNeighbours alone');
  check(throwsWith(() => buildVolume({ ...def, layout: 'grid', grid: { origin: [0, 0, 0], spacing: [1, 1, 1], counts: [5, 1, 1] } }, coeffs, null,
    null, null, null, null, tets, nbrs), /tetrahedra need layout points/), 'refused: tetrahedra on a grid');
  check(throwsWith(() => buildVolume(def, coeffs, pos, null, null, null, null, tets.subarray(0, 7), nbrs.subarray(0, 7)), /accessor sizes/), 'refused: 7 indices');
  check(throwsWith(() => buildVolume(def, coeffs, pos, null, null, null, null, tets, nbrs.subarray(0, 4)), /accessor sizes/), 'refused: unequal sizes');
  const bad = tets.slice();
  bad[5] = 5;
  check(throwsWith(() => buildVolume(def, coeffs, pos, null, null, null, null, bad, nbrs), /probe 5, beyond the 5 probes/), 'refused: a probe index out of range');
  const badN = nbrs.slice();
  badN[1] = 1;
  check(throwsWith(() => buildVolume(def, coeffs, pos, null, null, null, null, tets, badN), /does not share that face|not another tetrahedron/), 'refused: a neighbour not sharing its face');
  badN[1] = 0x80000000;
  check(throwsWith(() => buildVolume(def, coeffs, pos, null, null, null, null, tets, badN), /not another tetrahedron/), 'refused: a neighbour 2^31');
  // Through the loader: tetraNeighbours removed from a zhc output.
  const b = fs.readFileSync(cases[0].glb);
  const n = b.readUInt32LE(12);
  const json = JSON.parse(b.subarray(20, 20 + n).toString('utf8'));
  delete json.extensions.ZHC_light_probes.volumes[0].tetraNeighbours;
  let text = Buffer.from(JSON.stringify(json));
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const out = Buffer.concat([b.subarray(0, 12), Buffer.alloc(8), text, b.subarray(20 + n)]);
  out.writeUInt32LE(out.length, 8);
  out.writeUInt32LE(text.length, 12);
  out.writeUInt32LE(0x4e4f534a, 16);
  fs.writeFileSync(W('no_neighbours.glb'), out);
  let message = '';
  try { await loadThree(W('no_neighbours.glb')); } catch (err) { message = err.message; }
  check(/tetrahedra without tetraNeighbours/.test(message), `the loader refuses tetrahedra without tetraNeighbours (${message})`);
}
finish('plugin tetrahedra');
