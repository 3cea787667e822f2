// Cell planes through glTF and the three.js GLTFLoader plugin (CTest: js.plugin_planes).
// Usage: node plugin_planes.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR
//
//  1. `zhc demo`'s zh3_q16 grid with random cell planes and corner regions (tests/js/planes_fixtures.mjs),
//     alone and with random validity and visibility, written as version 2 .zhp files and embedded by
//     `zhc gltf embed`: the plugin's volume.planes holds the entries in glTF probe order with the
//     sides bits in glTF corner bits and the regions' fields in glTF axes (planes_fixtures'
//     gltfPlanes, computed here from the .zhp), and ZhcProbeVolume.irradianceAt at 5000 random
//     points (glTF axes) agrees with the C header's zhc_volume_irradiance on the .zhp at the same
//     points in zhc axes within 1e-6 of the mean irradiance (the tolerance of the mask tests: the
//     plugin blends in glTF probe order); the planes change the result at more than a quarter of
//     the points; points inside and outside corner regions (>= 50 each), where the regions change
//     the result at more than a tenth;
//  2. a hand-made 3x2x2 grid of three constant probe columns with the planes x = 0.6 and x = 3 (zhc
//     axes): irradianceAt gives exactly the colour of the point's side of the wall; a default
//     `zhc bake` of examples/hall.gltf (validity + planes) to .glb against the C header on the same
//     bake's .zhp, as in 1;
//  3. refusals: one accessor of the two, planes on a volume without a grid, a wrong size, a plane, a
//     corner region or bit 7 of planeSides on a probe that starts no cell, a corner region's reserved
//     bits (buildVolume and the loader).
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { register } from 'node:module';
import { makeRand, checker, triangleScene, freshWork, repoRoot } from './fixtures.mjs';
import { zhpWithPlanes, encodeNormal, planeEntry, planesSection, randomPlanes, gltfPlanes, NO_PLANE, regionEntry, gltfRegion, isRegion,
  planeSideAt } from './planes_fixtures.mjs';

register('./three_resolver.mjs', import.meta.url);
const runtime = await import('../../runtime/web/zhc_runtime.mjs');
const { ZhcLightProbesPlugin, ZhcProbeVolume, buildVolume } = await import('../../runtime/web/zhc_light_probes_plugin.mjs');
await import('three');
const { GLTFLoader } = await import('three/examples/jsm/loaders/GLTFLoader.js');

const [zhc, sampler, workArg] = process.argv.slice(2);
if (!zhc || !sampler || !workArg) {
  console.error('usage: node plugin_planes.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR');
  process.exit(2);
}
const work = freshWork(workArg);
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28 }).toString();
const f32 = Math.fround;
const throwsWith = (f, re) => { try { f(); return false; } catch (e) { return e instanceof Error && re.test(e.message); } };
const sameBytes = (a, b) => a.length === b.length && a.every((x, i) => x === b[i]);

// Random points around a zhc grid (its box grown by a quarter on each side), unit normals, float32.
function randomPoints(grid, n, seed) {
  const rand = makeRand(seed);
  const pts = [];
  for (let i = 0; i < n; i++) {
    const p = [0, 1, 2].map((c) => {
      const size = grid.counts[c] > 1 ? (grid.counts[c] - 1) * grid.spacing[c] : 2 * grid.spacing[c];
      const lo = grid.counts[c] > 1 ? grid.origin[c] - 0.25 * size : grid.origin[c] - grid.spacing[c];
      return f32(lo + 1.5 * size * rand());
    });
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
// The same decoded volume without its planes (a fresh ZhcProbeVolume of the same fields).
const withoutPlanes = (v) => new ZhcProbeVolume({ ...v, planes: null });

fs.writeFileSync(W('tri.glb'), triangleScene());

// --- 1: the demo grid with random planes ---------------------------------------------------------------
run('demo', '-o', W('demo'), '--directions', '16');
{
  const v1 = new Uint8Array(fs.readFileSync(W('demo/probes_zh3_q16.zhp')));
  const z = runtime.parseZhp(v1);
  const count = z.count;
  const rand = makeRand(38);
  let total = 0;
  for (const withMasks of [false, true]) {
    const planes = randomPlanes(z.grid, rand, { pRegion: 0.3 });
    const validity = withMasks ? Uint8Array.from({ length: count }, () => (rand() < 0.25 ? 0 : 1)) : null;
    const visibility = withMasks ? Uint8Array.from({ length: count }, () => Math.floor(rand() * 256)) : null;
    const tag = withMasks ? 'planes_masks' : 'planes';
    const zhpFile = W(`${tag}.zhp`), glbFile = W(`${tag}.glb`);
    fs.writeFileSync(zhpFile, zhpWithPlanes(v1, { validity, visibility, planes }, runtime.crc32));
    run('gltf', 'embed', W('tri.glb'), zhpFile, '-o', glbFile);
    const gltf = await loadThree(glbFile);
    const v = gltf.userData.zhcLightProbes[0];
    check(v.planes instanceof Uint8Array && v.planes.length === 5 * count, `${tag}.glb: volume.planes holds 5 bytes per probe`);
    check(v.planes && sameBytes(v.planes, gltfPlanes(z.grid.counts, planes)),
      `${tag}.glb: volume.planes is the .zhp's planes in glTF probe order with the sides in glTF corner bits`);
    check(Boolean(v.validity) === withMasks && Boolean(v.visibility) === withMasks, `${tag}.glb: validity / visibility read`);
    const pts = randomPoints(z.grid, 5000, 90 + total);
    const want = sampleC(zhpFile, pts);
    check(want.length === pts.length, `${tag}: the C sampler printed ${want.length} of ${pts.length} results`);
    const plain = withoutPlanes(v);
    // The plugin's volume with its corner regions read as "no plane" (a reader without them).
    const noRegions = v.planes.slice();
    for (let g = 0; g < count; g++) if (isRegion(noRegions, 5 * g)) noRegions.set(NO_PLANE, 5 * g);
    const planesOnly = new ZhcProbeVolume({ ...v, planes: noRegions });
    let mean = 0, worst = 0, differ = 0, inRegion = 0, outRegion = 0, regionWorst = 0, regionDiffer = 0;
    for (const e of want) mean += (Math.abs(e[0]) + Math.abs(e[1]) + Math.abs(e[2])) / 3;
    mean /= want.length;
    pts.forEach(({ p, n }, i) => {
      const pg = runtime.zhcToGltfDir(p), ng = runtime.zhcToGltfDir(n);  // zhc (x, y, z) -> glTF (y, z, x)
      const got = v.irradianceAt(pg, ng);
      const base = plain.irradianceAt(pg, ng);
      let d = false, e = 0;
      for (let k = 0; k < 3; k++) {
        e = Math.max(e, Math.abs(got[k] - want[i][k]) / mean);
        if (Math.abs(got[k] - base[k]) > 1e-6 * mean) d = true;
      }
      worst = Math.max(worst, e);
      if (d) differ++;
      const ps = planeSideAt(z.grid, planes, p);  // the sample's cell entry on the .zhp (zhc axes)
      if (ps && ps.region) {
        if (ps.side) inRegion++;
        else outRegion++;
        regionWorst = Math.max(regionWorst, e);
        const r = planesOnly.irradianceAt(pg, ng);
        if (r.some((x, k) => Math.abs(x - got[k]) > 1e-6 * mean)) regionDiffer++;
      }
    });
    console.log(`plugin irradianceAt with planes and corner regions${withMasks ? ' + validity + visibility' : ''} (${tag}.glb) vs C on the .zhp: ` +
      `${pts.length} samples, mean ${mean.toPrecision(6)}, max error / mean ${worst.toExponential(2)}, ${differ} differ from the volume without planes; ` +
      `in region cells ${inRegion} inside / ${outRegion} outside (max error / mean ${regionWorst.toExponential(2)}), ${regionDiffer} differ from the regions read as "no plane"`);
    check(mean > 0 && worst <= 1e-6, `${tag}: plugin irradianceAt agrees with the C header within 1e-6 of the mean`);
    check(differ > pts.length / 4, `${tag}: the planes change the plugin's result (${differ} of ${pts.length})`);
    check(inRegion >= 50 && outRegion >= 50, `${tag}: corner regions sampled on both sides (${inRegion} inside, ${outRegion} outside)`);
    check(regionDiffer > (inRegion + outRegion) / 10, `${tag}: the corner regions change the plugin's result (${regionDiffer})`);
    total += pts.length;
  }
}

// --- 2: hand-made walls -----------------------------------------------------------------------------------
// zhc grid 3x2x2 (spacing 2, 1, 1.5), columns x = 0, 1, 2 of constant radiance A, B, C. Cell (0, 0, 0):
// the plane x = 0.6 (normal +x), cell (1, 0, 0): x = 3 (normal -x). In glTF axes zhc x is z.
{
  const grid = { origin: [0, 0, 0], spacing: [2, 1, 1.5], counts: [3, 2, 2] };
  const colour = [[1.0, 0.5, 0.25], [0.125, 0.25, 2.0], [3.0, 0.75, 0.5]];
  const probes = [];
  for (let i = 0; i < 12; i++) {
    const dc = colour[i % 3];
    probes.push({ sh3: Array.from({ length: 9 }, (_, j) => (j === 0 ? dc.map((c) => c * 2 * Math.sqrt(Math.PI)) : [0, 0, 0])) });
  }
  fs.writeFileSync(W('hand.json'), JSON.stringify({ format: 'zhc-probes', version: 1, layout: { type: 'grid', ...grid }, probes }));
  run('convert', W('hand.json'), '-o', W('hand_v1.zhp'), '--to', 'sh3');
  const planes = planesSection(grid, (i0) => {
    if (i0[1] !== 0 || i0[2] !== 0) return null;
    return i0[0] === 0 ? planeEntry(grid, i0, encodeNormal([1, 0, 0]), [0.6, 0, 0]) : planeEntry(grid, i0, encodeNormal([-1, 0, 0]), [3, 0, 0]);
  });
  fs.writeFileSync(W('hand.zhp'), zhpWithPlanes(new Uint8Array(fs.readFileSync(W('hand_v1.zhp'))), { planes }, runtime.crc32));
  run('gltf', 'embed', W('tri.glb'), W('hand.zhp'), '-o', W('hand.glb'));
  const v = (await loadThree(W('hand.glb'))).userData.zhcLightProbes[0];
  const plain = withoutPlanes(v);
  // zhc points (x, y, z) with y, z inside cell (*, 0, 0); the expected colour by x.
  const cases = [[0.1, 'A', 0], [0.55, 'A', 0], [0.65, 'B', 1], [2.0, 'B', 1], [2.95, 'B', 1], [3.05, 'C', 2], [3.9, 'C', 2]];
  let exact = 0, plainOff = 0;
  for (const [x, name, c] of cases)
    for (const [y, z] of [[0.25, 0.3], [0.8, 1.2]]) {
      const pg = runtime.zhcToGltfDir([x, y, z]);
      const got = v.irradianceAt(pg, [0, 1, 0]);
      if (got.every((g, k) => Math.abs(g - colour[c][k]) <= 1e-6 * colour[c][k])) exact++;
      else console.log(`  hand-made: zhc x = ${x}: ${got}, expected ${name} = ${colour[c]}`);
      const base = plain.irradianceAt(pg, [0, 1, 0]);
      if (!base.every((g, k) => Math.abs(g - colour[c][k]) <= 1e-3 * colour[c][k])) plainOff++;
    }
  console.log(`hand-made walls (hand.glb): ${exact}/${2 * cases.length} points get their side's colour; the plain blend misses ${plainOff}`);
  check(exact === 2 * cases.length, 'hand-made walls: irradianceAt gives the colour of the point\'s side');
  check(plainOff >= 2 * cases.length - 4, 'hand-made walls: without the planes the blend mixes the sides');
}

// --- 2b: a baked volume ------------------------------------------------------------------------------------
// A default `zhc bake` of examples/hall.gltf (walls: validity and cell planes) to .zhp and to .glb: the
// plugin's irradianceAt on the .glb against the C header on the .zhp at random points.
{
  const hall = path.join(repoRoot, 'examples', 'hall.gltf');
  run('bake', hall, '-o', W('hall.zhp'), '-r', 'zh3_q16', '--quiet');
  run('bake', hall, '-o', W('hall.glb'), '-r', 'zh3_q16', '--quiet');
  const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(W('hall.zhp'))));
  let cells = 0;
  for (let i = 0; i < z.count && z.planes; i++) if (!(z.planes[5 * i + 2] === 0x00 && z.planes[5 * i + 3] === 0x80)) cells++;
  check(cells >= 1, `hall.zhp: the bake writes cell planes (${cells} cells with a plane)`);
  const v = (await loadThree(W('hall.glb'))).userData.zhcLightProbes[0];
  check(v.planes && z.planes && sameBytes(v.planes, gltfPlanes(z.grid.counts, z.planes)), 'hall.glb: volume.planes is the baked .zhp\'s in glTF order and bits');
  const pts = randomPoints(z.grid, 5000, 71);
  const want = sampleC(W('hall.zhp'), pts);
  const plain = withoutPlanes(v);
  let mean = 0, worst = 0, differ = 0;
  for (const e of want) mean += (Math.abs(e[0]) + Math.abs(e[1]) + Math.abs(e[2])) / 3;
  mean /= want.length;
  pts.forEach(({ p, n }, i) => {
    const pg = runtime.zhcToGltfDir(p), ng = runtime.zhcToGltfDir(n);
    const got = v.irradianceAt(pg, ng), base = plain.irradianceAt(pg, ng);
    let d = false;
    for (let k = 0; k < 3; k++) {
      worst = Math.max(worst, Math.abs(got[k] - want[i][k]) / mean);
      if (Math.abs(got[k] - base[k]) > 1e-6 * mean) d = true;
    }
    if (d) differ++;
  });
  console.log(`baked hall.glb (${cells} cells with a plane): plugin irradianceAt vs C on hall.zhp: max error / mean ${worst.toExponential(2)}, ` +
    `${differ} of ${pts.length} differ from the volume without planes`);
  check(mean > 0 && worst <= 1e-6, 'baked hall.glb: plugin irradianceAt agrees with the C header within 1e-6 of the mean');
  check(differ >= pts.length / 100, `baked hall.glb: the planes change the result somewhere (${differ})`);
}

// --- 3: refusals --------------------------------------------------------------------------------------------
{
  const def = { encoding: 'sh3', count: 12, layout: 'grid', shAxes: 'zhc', grid: { origin: [0, 0, 0], spacing: [1, 1, 1], counts: [2, 2, 3] } };
  const coeffs = new Float32Array(12 * 27).fill(0.5);
  // A valid planes pair: "no plane" everywhere except probe 0 (the first cell's corner 0).
  const quad = new Uint8Array(48), sides = new Uint8Array(12);
  for (let p = 0; p < 12; p++) quad.set(NO_PLANE.slice(0, 4), 4 * p);
  quad.set([254, 127, 0, 0], 0);
  sides[0] = 0xAA;
  const ok = buildVolume(def, coeffs, null, null, null, quad, sides);
  check(ok.planes && ok.planes.length === 60 && sameBytes(ok.planes.subarray(0, 5), [254, 127, 0, 0, 0xAA]), 'buildVolume: planes + planeSides -> 5 bytes per probe');
  check(buildVolume(def, coeffs, null).planes === null, 'buildVolume: no planes -> null');
  check(throwsWith(() => buildVolume(def, coeffs, null, null, null, quad, null), /planes without planeSides/), 'refused: planes without planeSides');
  check(throwsWith(() => buildVolume(def, coeffs, null, null, null, null, sides), /planeSides without planes/), 'refused: planeSides without planes');
  check(throwsWith(() => buildVolume(def, coeffs, null, null, null, quad.subarray(0, 44), sides), /planes accessor size/), 'refused: planes of 11 elements');
  check(throwsWith(() => buildVolume(def, coeffs, null, null, null, quad, sides.subarray(0, 11)), /planeSides accessor size/), 'refused: planeSides of 11 elements');
  check(throwsWith(() => buildVolume({ ...def, layout: 'none', grid: undefined }, coeffs, null, null, null, quad, sides), /planes need layout grid/),
    'refused: planes on a volume without a grid');
  for (const p of [1, 3, 8, 11]) {  // glTF grid 2x2x3: 1 last along x, 3 along x and y, 8 along z, 11 all three
    const bad = quad.slice();
    bad.set([254, 127, 0, 0], 4 * p);
    check(throwsWith(() => buildVolume(def, coeffs, null, null, null, bad, sides), new RegExp(`probe ${p} is the last along an axis`)),
      `refused: a plane on glTF probe ${p}, which starts no cell`);
    // A corner region there (offset -32768 with bit 7 of planeSides), or bit 7 alone.
    for (const [entry, what] of [[regionEntry([4, 9, 0], [0, 1, 0]), 'a corner region'], [[0, 0, 0x00, 0x80, 0x80], 'bit 7 of planeSides']]) {
      const bq = quad.slice(), bs = sides.slice();
      bq.set(entry.slice(0, 4), 4 * p);
      bs[p] = entry[4];
      check(throwsWith(() => buildVolume(def, coeffs, null, null, null, bq, bs), new RegExp(`probe ${p} is the last along an axis and starts no cell, but its corner region is set`)),
        `refused: ${what} on glTF probe ${p}, which starts no cell`);
    }
  }
  // A corner region on probe 0 (which starts a cell) is read as it stands; its reserved bits are refused.
  {
    const rq = quad.slice(), rs = sides.slice();
    const entry = regionEntry([4, 9, 31], [0, 1, 1]);
    rq.set(entry.slice(0, 4), 0);
    rs[0] = entry[4];
    const rv = buildVolume(def, coeffs, null, null, null, rq, rs);
    check(sameBytes(rv.planes.subarray(0, 5), entry), 'buildVolume: a corner region on probe 0 is kept as it stands (glTF axes)');
    for (const [b, bit] of [[1, 0x80], [4, 0x08], [4, 0x40]]) {
      const bq = rq.slice(), bs = rs.slice();
      if (b === 4) bs[0] |= bit;
      else bq[b] |= bit;
      check(throwsWith(() => buildVolume(def, coeffs, null, null, null, bq, bs), /probe 0's corner region sets reserved bits/),
        `refused: a corner region with bit ${bit.toString(16)} of ${b === 4 ? 'planeSides' : `planes byte ${b}`} set`);
    }
  }
  // Through the loader: planeSides removed from the hand-made asset.
  const b = fs.readFileSync(W('hand.glb'));
  const n = b.readUInt32LE(12);
  const json = JSON.parse(b.subarray(20, 20 + n).toString('utf8'));
  delete json.extensions.ZHC_light_probes.volumes[0].planeSides;
  let text = Buffer.from(JSON.stringify(json));
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const out = Buffer.concat([b.subarray(0, 12), Buffer.alloc(8), text, b.subarray(20 + n)]);
  out.writeUInt32LE(out.length, 8);
  out.writeUInt32LE(text.length, 12);
  out.writeUInt32LE(0x4e4f534a, 16);
  fs.writeFileSync(W('no_sides.glb'), out);
  let message = '';
  try { await loadThree(W('no_sides.glb')); } catch (e) { message = e.message; }
  check(/planes without planeSides/.test(message), `the loader refuses planes without planeSides (${message})`);
}
finish('plugin cell planes');
