// runtime/web's tetrahedral interpolation of scattered probes against the C header (CTest: js.runtime_tetra).
// Usage: node runtime_tetra.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR
//
//  1. `zhc convert` of JSON probe lists with positions (random sets, a lattice: cospherical cells,
//     exactly 4 probes, a set with a duplicate position) and `zhc bake` of
//     tests/data/leak_room.json with 40 probes placed in the room write `points` .zhp files with
//     their tetrahedra; a copy of each random set gets a validity section (a fifth of the probes
//     invalid);
//  2. at random points in and around each set (inside the hull, beyond its faces, edges and
//     corners; also on the lattice's planes) with random normals: the C99 zhc_volume_sample
//     (zhc_volume_from_zhp + zhc_volume_irradiance) and volumeFromZhp + volumeIrradiance give the
//     SAME float32 values (the same double operations in the same order);
//  3. volumeTetraWeights: weights >= 0 summing to 1, the start of the walk not changing the blend;
//     an affine field stored at the probes reproduced inside the hull;
//  4. parseZhp / makePointsVolume refuse inconsistent tetrahedra (index out of range, a wrong
//     neighbour, a count the bytes cannot fill, tetrahedra on a grid) and volumeFromZhp a coplanar
//     set (written without tetrahedra): "not a grid".
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { makeRand, checker } from './fixtures.mjs';

const runtime = await import('../../runtime/web/zhc_runtime.mjs');

const [zhc, sampler, work] = process.argv.slice(2);
if (!zhc || !sampler || !work) {
  console.error('usage: node runtime_tetra.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR');
  process.exit(2);
}
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28, stdio: ['ignore', 'pipe', 'pipe'] }).toString();
const f32 = Math.fround;
const throwsWith = (f, re) => { try { f(); return false; } catch (e) { return e instanceof Error && re.test(e.message); } };

function probeList(positions, rand) {
  return JSON.stringify({ format: 'zhc-probes', version: 1, layout: { type: 'positions' },
    probes: positions.map((p) => ({ position: p, sh3: Array.from({ length: 9 }, (_, i) => [0, 1, 2].map(() => (i === 0 ? 0.5 + rand() : rand() - 0.5))) })) });
}

// A points .zhp (uncompressed) with a validity section added before its tetrahedra.
function withValidity(bytes, validity) {
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const count = Number(dv.getBigUint64(56, true)), bpp = dv.getUint32(64, true);
  const split = 184 + count * 12 + count * bpp;
  const out = new Uint8Array(bytes.length + count);
  out.set(bytes.subarray(0, split));
  out.set(validity, split);
  out.set(bytes.subarray(split), split + count);
  const o = new DataView(out.buffer);
  out[21] |= 1;
  const body = BigInt(out.length - 184);
  o.setBigUint64(160, body, true);
  o.setBigUint64(168, body, true);
  o.setUint32(176, runtime.crc32(out, 184, out.length), true);
  o.setUint32(180, runtime.crc32(out, 0, 180), true);
  return out;
}

function sampleC(zhp, pts) {
  const file = W('points.txt');
  fs.writeFileSync(file, pts.map(({ p, n }) => [...p, ...n].map((x) => x.toPrecision(9)).join(' ')).join('\n') + '\n');
  const out = execFileSync(sampler, [zhp, file], { maxBuffer: 1 << 28 }).toString().trim().split('\n');
  return out.map((line) => line.trim().split(/\s+/).map((x) => f32(Number(x))));
}

function randomSamples(lo, hi, n, seed, snap = null) {
  const rand = makeRand(seed);
  const pts = [];
  for (let i = 0; i < n; i++) {
    const p = [0, 1, 2].map((c) => f32(lo[c] + (hi[c] - lo[c]) * rand()));
    if (snap && i % 3 === 0) p[i % 9 === 0 ? 0 : 2] = snap(p[i % 9 === 0 ? 0 : 2]);
    const z = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - z * z));
    pts.push({ p, n: [f32(r * Math.cos(phi)), f32(r * Math.sin(phi)), f32(z)] });
  }
  return pts;
}

let identical = 0, total = 0;
function compareWithC(file, bytes, pts, what) {
  const vol = runtime.volumeFromZhp(bytes);
  check(vol.kind === 'points', `${what}: a points volume`);
  const c = sampleC(file, pts);
  check(c.length === pts.length, `${what}: the C sampler answers every point`);
  let same = 0, inside = 0, worstSum = 0;
  pts.forEach(({ p, n }, i) => {
    const js = runtime.volumeIrradiance(vol, p, n);
    if (js.every((x, k) => Object.is(x, c[i][k]))) same++;
    const t0 = runtime.volumeTetraWeights(vol, p);
    const t1 = runtime.volumeTetraWeights(vol, p, (i * 7919) % vol.tetraCount);
    inside += t0.inside;
    const sum = t0.weights.reduce((a, b) => a + b, 0);
    worstSum = Math.max(worstSum, Math.abs(sum - 1));
    check(t0.weights.every((w) => w >= 0), `${what}: weights >= 0 at sample ${i}`);
    // The walk's start: the same probes with the same weights (within rounding).
    const a = new Map(), b = new Map();
    t0.probes.forEach((q, k) => a.set(q, (a.get(q) ?? 0) + t0.weights[k]));
    t1.probes.forEach((q, k) => b.set(q, (b.get(q) ?? 0) + t1.weights[k]));
    for (const [q, w] of a) if (w > 1e-12) check(Math.abs((b.get(q) ?? 0) - w) <= 1e-12, `${what}: sample ${i} probe ${q}: the walk's start changes its weight`);
  });
  identical += same;
  total += pts.length;
  console.log(`${what.padEnd(34)} ${pts.length} samples (${inside} inside the hull): ${same} bit-identical to the C header; max |sum w - 1| ${worstSum.toExponential(2)}`);
  check(same === pts.length, `${what}: every sample bit-identical between JS and C`);
  check(worstSum <= 1e-12, `${what}: weights sum to 1`);
  return vol;
}

// --- random sets, with and without validity ---------------------------------------------------------
for (const seed of [1, 2, 3]) {
  const rand = makeRand(seed);
  const positions = Array.from({ length: 50 + 20 * seed }, () => [0, 1, 2].map(() => f32(6 * rand())));
  fs.writeFileSync(W(`random${seed}.json`), probeList(positions, rand));
  run('convert', W(`random${seed}.json`), '-o', W(`random${seed}.zhp`), '--to', seed === 1 ? 'sh3' : seed === 2 ? 'zh3_q16' : 'sh3_q28');
  const bytes = new Uint8Array(fs.readFileSync(W(`random${seed}.zhp`)));
  compareWithC(W(`random${seed}.zhp`), bytes, randomSamples([-2, -2, -2], [8, 8, 8], 1500, seed + 10), `random set ${seed}`);
  compareWithC(W(`random${seed}.zhp`), bytes, randomSamples([1, 1, 1], [5, 5, 5], 1500, seed + 20), `random set ${seed} (core)`);
  const validity = new Uint8Array(positions.length).fill(1);
  for (let i = seed; i < validity.length; i += 5) validity[i] = 0;
  const vb = withValidity(bytes, validity);
  fs.writeFileSync(W(`random${seed}_valid.zhp`), vb);
  const vol = compareWithC(W(`random${seed}_valid.zhp`), vb, randomSamples([-1, -1, -1], [7, 7, 7], 1500, seed + 30), `random set ${seed} + validity`);
  check(vol.validity !== null && vol.validity.length === positions.length, `random set ${seed}: validity read`);
}

// --- a lattice (flat tetrahedra), its planes, and an affine field -------------------------------------
{
  const rand = makeRand(7);
  const positions = [];
  for (let z = 0; z < 3; z++) for (let y = 0; y < 4; y++) for (let x = 0; x < 5; x++) positions.push([0.5 * x, 0.5 * y, 0.5 * z]);
  fs.writeFileSync(W('lattice.json'), probeList(positions, rand));
  run('convert', W('lattice.json'), '-o', W('lattice.zhp'), '--to', 'sh3');
  const bytes = new Uint8Array(fs.readFileSync(W('lattice.zhp')));
  compareWithC(W('lattice.zhp'), bytes, randomSamples([-0.5, -0.5, -0.5], [2.5, 2, 1.5], 2000, 8, (v) => f32(0.5 * Math.round(2 * v))), 'lattice (and its planes)');
  // An affine field: coefficient i = a_i + b_i . x at each probe, exact in float32.
  const field = Array.from({ length: 27 }, (_, i) => [(i % 5) - 2, ((i * 3) % 7) - 3, (i % 3) - 1, ((i * 5) % 4) - 2].map((v) => v / 8));
  const sh = new Float32Array(positions.length * 27);
  positions.forEach((p, n) => field.forEach((f, i) => { sh[n * 27 + i] = f[0] + f[1] * p[0] + f[2] * p[1] + f[3] * p[2]; }));
  const z = runtime.parseZhp(bytes);
  const vol = runtime.makePointsVolume({ sh, positions: z.positions, tetrahedra: z.tetrahedra, neighbours: z.neighbours });
  let worst = 0, inside = 0;
  for (const { p } of randomSamples([0, 0, 0], [2, 1.5, 1], 3000, 9, (v) => f32(0.5 * Math.round(2 * v)))) {
    if (!runtime.volumeTetraWeights(vol, p).inside) continue;
    inside++;
    const got = runtime.volumeSH3(vol, p);
    field.forEach((f, i) => { worst = Math.max(worst, Math.abs(got[i] - (f[0] + f[1] * p[0] + f[2] * p[1] + f[3] * p[2]))); });
  }
  console.log(`lattice affine field: ${inside} points inside, max error ${worst.toExponential(2)}`);
  check(inside > 2500 && worst <= 1e-9, 'an affine field is reproduced inside the hull (1e-9)');
}

// --- exactly 4 probes; a duplicate position ---------------------------------------------------------
{
  const rand = makeRand(11);
  fs.writeFileSync(W('four.json'), probeList([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 0, 2]], rand));
  run('convert', W('four.json'), '-o', W('four.zhp'), '--to', 'sh3');
  const vol = compareWithC(W('four.zhp'), new Uint8Array(fs.readFileSync(W('four.zhp'))), randomSamples([-2, -2, -2], [4, 4, 4], 2000, 12), 'four probes');
  check(vol.tetraCount === 1, 'four probes: one tetrahedron');
  const dupPositions = Array.from({ length: 30 }, () => [0, 1, 2].map(() => f32(3 * rand())));
  dupPositions.push(dupPositions[4]);
  fs.writeFileSync(W('dup.json'), probeList(dupPositions, rand));
  run('convert', W('dup.json'), '-o', W('dup.zhp'), '--to', 'sh3');
  const dup = compareWithC(W('dup.zhp'), new Uint8Array(fs.readFileSync(W('dup.zhp'))), randomSamples([-0.5, -0.5, -0.5], [3.5, 3.5, 3.5], 1500, 13), 'with a duplicate');
  check(!Array.from(dup.tetrahedra).includes(30), 'a duplicate probe is no tetrahedron vertex');
}

// --- a real scene: scattered probes baked in the leak room ------------------------------------------
{
  const scene = JSON.parse(fs.readFileSync(new URL('../data/leak_room.json', import.meta.url)));
  const rand = makeRand(23);
  scene.probes = { positions: Array.from({ length: 40 }, () => [2.55 + 3.8 * rand(), 0.2 + 4.15 * rand(), -0.35 + 3.7 * rand()].map((v) => Math.round(1000 * v) / 1000)) };
  fs.writeFileSync(W('room.json'), JSON.stringify(scene));
  run('bake', W('room.json'), '-o', W('room.zhp'), '--to', 'zh3_q16', '--rays', '256:1024', '--quiet');
  compareWithC(W('room.zhp'), new Uint8Array(fs.readFileSync(W('room.zhp'))), randomSamples([2.4, 0.05, -0.5], [6.5, 4.5, 3.5], 2000, 24), 'leak room, 40 baked probes');
}

// --- refusals -------------------------------------------------------------------------------------------
{
  const bytes = new Uint8Array(fs.readFileSync(W('random1.zhp')));
  const z = runtime.parseZhp(bytes);
  const count = z.count, T = z.tetrahedra.length / 4;
  const sec = 184 + count * 12 + count * z.bytesPerProbe;
  const edited = (at, value) => {
    const b = bytes.slice();
    const dv = new DataView(b.buffer);
    dv.setUint32(at, value >>> 0, true);
    dv.setUint32(176, runtime.crc32(b, 184, b.length), true);
    dv.setUint32(180, runtime.crc32(b, 0, 180), true);
    return b;
  };
  check(throwsWith(() => runtime.parseZhp(edited(sec + 4, count)), /tetrahedron 0 vertex 0 is probe/), 'parseZhp refuses a probe index beyond the count');
  check(throwsWith(() => runtime.parseZhp(edited(sec, T + 1)), /declares \d+ tetrahedra/), 'parseZhp refuses a count the bytes cannot fill');
  let j = 0;
  while (z.neighbours[j] === -1) j++;
  check(throwsWith(() => runtime.parseZhp(edited(sec + 4 + 16 * T + 4 * j, z.neighbours[j] === 1 ? 2 : 1)), /does not share that face/),
    'parseZhp refuses a neighbour that does not share the face');
  check(throwsWith(() => runtime.makePointsVolume({ sh: new Float32Array(4 * 27), positions: [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1],
    tetrahedra: [0, 1, 2, 3], neighbours: [0, -1, -1, -1] }), /neighbour 0 is not another tetrahedron/), 'makePointsVolume refuses a tetrahedron its own neighbour');
  check(throwsWith(() => runtime.makePointsVolume({ sh: new Float32Array(4 * 27), positions: [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NaN],
    tetrahedra: [0, 1, 2, 3], neighbours: [-1, -1, -1, -1] }), /position of probe 3 is not finite/), 'makePointsVolume refuses a position that is not finite');
  fs.writeFileSync(W('flat.json'), probeList(Array.from({ length: 9 }, (_, i) => [i % 3, Math.floor(i / 3), 0.5]), makeRand(3)));
  run('convert', W('flat.json'), '-o', W('flat.zhp'), '--to', 'sh3');
  const flat = new Uint8Array(fs.readFileSync(W('flat.zhp')));
  check(runtime.parseZhp(flat).tetrahedra === null, 'a coplanar set is written without tetrahedra');
  check(throwsWith(() => runtime.volumeFromZhp(flat), /positions without tetrahedra, not a grid/), 'volumeFromZhp refuses points without tetrahedra');
  const onGrid = bytes.slice();
  onGrid[20] = 1;  // layout grid, the tetrahedra flag kept: refused before the grid fields are read
  new DataView(onGrid.buffer).setUint32(180, runtime.crc32(onGrid, 0, 180), true);
  check(throwsWith(() => runtime.parseZhp(onGrid), /tetrahedra without a positions layout/), 'parseZhp refuses tetrahedra without a positions layout');
}
console.log(`tetrahedral volumes: ${identical}/${total} samples bit-identical between JS and C`);
finish('runtime/web tetrahedral volume');
