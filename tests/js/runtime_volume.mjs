// runtime/web probe volumes against the C header (CTest: js.runtime_volume).
// Usage: node runtime_volume.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR
//
//  1. `zhc demo` writes the demo grid (probes_sh3.zhp, probes_zh3_q16.zhp, probes.glb); `zhc convert`
//     turns probes_sh3.zhp into every entry of runtime/web's ENCODINGS (= the codec table: checked by
//     js.runtime_decode), plus a non-default parameter set for every packed entry;
//  2. 10,000 random points in and around the grid with random normals (float32 values): the C99
//     tests/runtime_c/zhc_volume_sample (zhc_volume_from_zhp + zhc_volume_irradiance) and
//     volumeFromZhp + volumeIrradiance must give the SAME float32 values (the JS volume is a port of
//     the C one, the same double operations in the same order, as the decoders are);
//  3. the GLTFLoader plugin's ZhcProbeVolume.irradianceAt on the demo's probes.glb (glTF axes)
//     against the C sampler on probes_zh3_q16.zhp at the same points in zhc axes: within 1e-6 of the
//     mean irradiance (the plugin blends in glTF probe order: a different order of the same sums);
//  3b. the same with validity and visibility sections (version 2 files), fallback included;
//  3c. cell planes (byte 21 bit 2): random planes (random codes, offsets, geometric or random sides,
//      "no plane" cells) and corner regions (random thresholds, some axes unbounded, random
//      directions) alone and with validity and visibility, bit for bit against the C header, with
//      samples inside and outside regions in every file, and the regions changing the result;
//      all "no plane": the masks-only result bit for bit; a hand-made 3x2x2 grid of constant probes
//      with two axis planes: each side shows its own probe's value, a plane whose corners all lie
//      on the other side falls back to the plain blend; a hand-made 2x2x2 grid with one corner
//      region (d = 0 on two axes, d = 1 on three): inside it only the colour of the corners inside,
//      outside none of it; constant probes stay constant under any planes and regions; the same
//      volumes in glTF axes (planesAxes 'gltf': the grid, probe order and sides bits permuted, the
//      normal code kept, the regions' fields permuted) against the C header on the .zhp, and
//      regions left unpermuted would be wrong;
//  4. volumeFromZhp refuses a points file and a spacing <= 0 grid; irradianceAt refuses non-grids;
//     parseZhp refuses a plane, a corner region or bit 7 of byte 4 on a probe that starts no cell,
//     a corner region's reserved bits and planes without a grid, makeVolume short planes and a bad
//     planesAxes.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { register } from 'node:module';
import { makeRand, checker, triangleScene } from './fixtures.mjs';
import { zhpWithPlanes, encodeNormal, planeEntry, planesSection, randomPlanes, gltfProbeOrder, gltfBits, gltfPlanes, NO_PLANE,
  regionEntry, isRegion, planeSideAt } from './planes_fixtures.mjs';

register('./three_resolver.mjs', import.meta.url);
const runtime = await import('../../runtime/web/zhc_runtime.mjs');
const { ZhcLightProbesPlugin } = await import('../../runtime/web/zhc_light_probes_plugin.mjs');
await import('three');
const { GLTFLoader } = await import('three/examples/jsm/loaders/GLTFLoader.js');

const [zhc, sampler, work] = process.argv.slice(2);
if (!zhc || !sampler || !work) {
  console.error('usage: node runtime_volume.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR');
  process.exit(2);
}
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28 }).toString();
const f32 = Math.fround;
const throwsWith = (f, re) => { try { f(); return false; } catch (e) { return e instanceof Error && re.test(e.message); } };

run('demo', '-o', W('demo'), '--directions', '16');
const sh3File = W('demo/probes_sh3.zhp');

// Random points around a grid (its box grown by a quarter on each side), unit normals, as float32.
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
// The C99 sampler's float32 results at the points.
function sampleC(zhp, pts) {
  const file = W('points.txt');
  fs.writeFileSync(file, pts.map(({ p, n }) => [...p, ...n].map((x) => x.toPrecision(9)).join(' ')).join('\n') + '\n');
  const out = execFileSync(sampler, [zhp, file], { maxBuffer: 1 << 28 }).toString().trim().split('\n');
  return out.map((line) => line.trim().split(/\s+/).map((x) => f32(Number(x))));
}

// --- 1 + 2: every encoding, JS volume vs the C header ------------------------------------------------
const cases = [];
for (const enc of Object.keys(runtime.ENCODINGS)) {
  cases.push({ enc, flags: [] });
  // Non-default storage parameters; `zhc convert` refuses one the entry does not use: --axis only
  // for the entries that take the zonal axis from the parameters (not sh3_q28, sh2_q, the *_channel ones).
  const takesAxis = !['sh3_q28', 'sh2_q'].includes(enc) && !runtime.ENCODINGS[enc].axisMode;
  if (runtime.ENCODINGS[enc].packed)
    cases.push({ enc, flags: ['--bits', '5', '--sqrt', '--irradiance', '--dc', 'rgb9e5', ...(takesAxis ? ['--axis', 'channel'] : [])] });
}
let total = 0, identical = 0;
cases.forEach((c, idx) => {
  const file = c.enc === 'sh3' && c.flags.length === 0 ? sh3File : W(`c${idx}_${c.enc}.zhp`);
  if (file !== sh3File) run('convert', sh3File, '--to', c.enc, '-o', file, ...c.flags);
  const vol = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(file)));
  const pts = randomPoints(vol, 10000, 100 + idx);
  const want = sampleC(file, pts);
  check(want.length === pts.length, `${c.enc}: the C sampler printed ${want.length} of ${pts.length} results`);
  let same = 0, first = true;
  pts.forEach(({ p, n }, i) => {
    const got = runtime.volumeIrradiance(vol, p, n);
    const ok = want[i] && got.every((g, k) => Object.is(g, want[i][k]));
    if (ok) same++;
    else if (first) {
      first = false;
      console.log(`  ${c.enc}: point ${i} (${p}) normal (${n}): js ${got}, C ${want[i]}`);
    }
  });
  console.log(`volume ${c.enc} ${c.flags.join(' ') || '(defaults)'}: ${same}/${pts.length} samples bit-identical to the C header`);
  check(same === pts.length, `${c.enc} ${c.flags.join(' ')}: volumeIrradiance equals zhc_volume_irradiance bit for bit`);
  total += pts.length;
  identical += same;
});
check(cases.length >= 2 * 10, 'every encoding and every packed one twice');

// --- 3: the glTF plugin on the demo's probes.glb ------------------------------------------------------
async function loadThree(file) {
  const bytes = fs.readFileSync(file);
  const ab = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  return new Promise((resolve, reject) => loader.parse(ab, '', resolve, reject));
}
{
  const gltf = await loadThree(W('demo/probes.glb'));
  const v = gltf.userData.zhcLightProbes[0];
  check(v && v.layout === 'grid' && v.encoding === 'zh3_q16', 'probes.glb: a zh3_q16 grid volume');
  const zhpFile = W('demo/probes_zh3_q16.zhp');
  const zvol = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(zhpFile)));
  const pts = randomPoints(zvol, 10000, 7);
  const want = sampleC(zhpFile, pts);
  let mean = 0;
  for (const e of want) mean += (Math.abs(e[0]) + Math.abs(e[1]) + Math.abs(e[2])) / 3;
  mean /= want.length;
  let worst = 0;
  pts.forEach(({ p, n }, i) => {
    // zhc (x, y, z) -> glTF (y, z, x)
    const got = v.irradianceAt(runtime.zhcToGltfDir(p), runtime.zhcToGltfDir(n));
    for (let k = 0; k < 3; k++) worst = Math.max(worst, Math.abs(got[k] - want[i][k]) / mean);
  });
  console.log(`plugin irradianceAt (probes.glb, glTF axes) vs C zhc_volume_irradiance (probes_zh3_q16.zhp): ` +
    `${pts.length} samples, mean irradiance ${mean.toPrecision(6)}, max error / mean ${worst.toExponential(2)}`);
  check(mean > 0 && worst <= 1e-6, 'plugin irradianceAt agrees with the C header within 1e-6 of the mean');
}

// --- 3b: validity and visibility (a version 2 .zhp) ---------------------------------------------------
// The demo's files rewritten as version 2 with random validity (1 in 4 invalid) and visibility masks
// (each bit set with p = 1/2), plus an all-invalid one (the fallback): JS and the C sampler
// (zhc_volume_from_zhp fills zhc_volume::validity / ::visibility) give the same float32 values.
// (zhpWithPlanes: the demo's files may carry a planes section, which these replace too.)
const withSections = (bytes, validity, visibility) => zhpWithPlanes(bytes, { validity, visibility }, runtime.crc32);
{
  const rand = makeRand(27);
  let masked = 0, differ = 0;
  for (const [name, mode] of [['probes_sh3.zhp', 3], ['probes_zh3_q16.zhp', 3], ['probes_zh3_q16.zhp', 1], ['probes_sh3.zhp', 2], ['probes_zh3_q16.zhp', 0]]) {
    const v1 = new Uint8Array(fs.readFileSync(W('demo/' + name)));
    const count = runtime.parseZhp(v1).count;
    const validity = mode & 1 ? Uint8Array.from({ length: count }, () => (rand() < 0.25 ? 0 : 1))
      : mode === 0 ? new Uint8Array(count) : null;  // mode 0: every probe invalid
    const visibility = mode & 2 ? Uint8Array.from({ length: count }, () => Math.floor(rand() * 256)) : null;
    const file = W(`leak_${mode}_${name}`);
    fs.writeFileSync(file, withSections(v1, validity, visibility));
    const vol = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(file)));
    // The demo's files carry the bake's own sections: the plain blend is the volume without them.
    const plain = Object.freeze({ ...runtime.volumeFromZhp(v1), validity: null, visibility: null, planes: null });
    check((vol.validity !== null) === Boolean(validity) && (vol.visibility !== null) === Boolean(visibility), `${file}: sections read`);
    const pts = randomPoints(vol, 5000, 300 + mode);
    const want = sampleC(file, pts);
    let same = 0, diff = 0;
    pts.forEach(({ p, n }, i) => {
      const got = runtime.volumeIrradiance(vol, p, n);
      if (want[i] && got.every((g, k) => Object.is(g, want[i][k]))) same++;
      const base = runtime.volumeIrradiance(plain, p, n);
      if (!got.every((g, k) => Object.is(g, base[k]))) diff++;
    });
    console.log(`volume with sections ${mode} (${name}): ${same}/${pts.length} bit-identical to the C header, ${diff} differ from the plain blend`);
    check(same === pts.length, `${name} sections ${mode}: masked volumeIrradiance equals the C header bit for bit`);
    if (mode === 0) check(diff === 0, 'every probe invalid: the fallback is the plain trilinear blend, bit for bit');
    else check(diff > pts.length / 4, `${name} sections ${mode}: the masks change the result`);
    masked += same;
    differ += diff;
  }
  // Refusals: validity 2, visibility without a grid is refused by parseZhp (checked via the flags).
  const v1 = new Uint8Array(fs.readFileSync(W('demo/probes_zh3_q16.zhp')));
  const count = runtime.parseZhp(v1).count;
  const bad = new Uint8Array(count).fill(1);
  bad[count >> 1] = 2;
  check(throwsWith(() => runtime.parseZhp(withSections(v1, bad, null)), /validity/), 'parseZhp refuses a validity byte 2');
  console.log(`masked volumes: ${masked} samples bit-identical between JS and C`);
  // The glTF plugin on the masked zh3_q16 grid embedded by `zhc gltf embed` (validity and
  // visibility accessors, glTF probe order and mask axes) against the C sampler on the .zhp.
  fs.writeFileSync(W('tri.glb'), triangleScene());
  const leakZhp = W('leak_3_probes_zh3_q16.zhp');
  run('gltf', 'embed', W('tri.glb'), leakZhp, '-o', W('leak.glb'));
  const gltf = await loadThree(W('leak.glb'));
  const v = gltf.userData.zhcLightProbes[0];
  check(v.validity && v.visibility, 'leak.glb: the plugin reads validity and visibility');
  const zvol = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(leakZhp)));
  const pts = randomPoints(zvol, 5000, 8);
  const want = sampleC(leakZhp, pts);
  let mean = 0, worst = 0;
  for (const e of want) mean += (Math.abs(e[0]) + Math.abs(e[1]) + Math.abs(e[2])) / 3;
  mean /= want.length;
  pts.forEach(({ p, n }, i) => {
    const got = v.irradianceAt(runtime.zhcToGltfDir(p), runtime.zhcToGltfDir(n));
    for (let k = 0; k < 3; k++) worst = Math.max(worst, Math.abs(got[k] - want[i][k]) / mean);
  });
  console.log(`plugin irradianceAt with masks (leak.glb) vs C (the .zhp): max error / mean ${worst.toExponential(2)}`);
  check(mean > 0 && worst <= 1e-6, 'masked plugin irradianceAt agrees with the C header within 1e-6 of the mean');
}

// --- 3c: cell planes ---------------------------------------------------------------------------------
{
  const rand = makeRand(38);
  const same = (a, b) => a.every((x, k) => Object.is(x, b[k]));
  let planeSamples = 0;
  for (const [name, withValidity, withVisibility] of [['probes_sh3.zhp', false, false], ['probes_zh3_q16.zhp', false, false],
    ['probes_zh3_q16.zhp', true, false], ['probes_sh3.zhp', true, true]]) {
    const v1 = new Uint8Array(fs.readFileSync(W('demo/' + name)));
    const z1 = runtime.parseZhp(v1);
    const count = z1.count;
    const validity = withValidity ? Uint8Array.from({ length: count }, () => (rand() < 0.2 ? 0 : 1)) : null;
    const visibility = withVisibility ? Uint8Array.from({ length: count }, () => Math.floor(rand() * 256)) : null;
    const planes = randomPlanes(z1.grid, rand, { pRegion: 0.3 });
    // The same entries with every corner region replaced by "no plane" (a reader without regions).
    const planesOnly = planes.slice();
    for (let i = 0; i < count; i++) if (isRegion(planes, 5 * i)) planesOnly.set(NO_PLANE, 5 * i);
    const file = W(`planes_${validity ? 'v' : ''}${visibility ? 'm' : ''}_${name}`);
    fs.writeFileSync(file, zhpWithPlanes(v1, { validity, visibility, planes }, runtime.crc32));
    const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(file)));
    check(z.planes && z.planes.length === 5 * count && z.planes.every((x, i) => x === planes[i]), `${file}: parseZhp returns the planes section`);
    const vol = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(file)));
    // The same volume without planes (masks only, or plain), and with every entry "no plane".
    const masksOnly = runtime.makeVolume({ encoding: z.encoding, params: z.params, bytes: z.payload, ...z.grid, validity, visibility });
    const noPlanes = runtime.makeVolume({ encoding: z.encoding, params: z.params, bytes: z.payload, ...z.grid, validity, visibility,
      planes: planesSection(z.grid, () => null) });
    const withoutRegions = runtime.makeVolume({ encoding: z.encoding, params: z.params, bytes: z.payload, ...z.grid, validity, visibility,
      planes: planesOnly });
    let regionCells = 0;
    for (let i = 0; i < count; i++) if (isRegion(planes, 5 * i)) regionCells++;
    const pts = randomPoints(vol, 5000, 400 + planeSamples);
    const want = sampleC(file, pts);
    let identical = 0, differ = 0, noneSame = 0, inRegion = 0, outRegion = 0, regionDiffer = 0, regionSame = 0;
    pts.forEach(({ p, n }, i) => {
      const got = runtime.volumeIrradiance(vol, p, n);
      const ok = want[i] && same(got, want[i]);
      if (ok) identical++;
      const base = runtime.volumeIrradiance(masksOnly, p, n);
      if (!same(got, base)) differ++;
      if (same(runtime.volumeIrradiance(noPlanes, p, n), base)) noneSame++;
      // Samples in a corner region's cell, on either side of it (the fixtures' twin of the rule).
      const ps = planeSideAt(z.grid, planes, p);
      if (ps && ps.region) {
        if (ps.side) inRegion++;
        else outRegion++;
        if (ok) regionSame++;
        if (!same(got, runtime.volumeIrradiance(withoutRegions, p, n))) regionDiffer++;
      }
    });
    console.log(`volume with planes and corner regions${validity ? ' + validity' : ''}${visibility ? ' + visibility' : ''} (${name}): ` +
      `${identical}/${pts.length} bit-identical to the C header, ${differ} differ from the volume without planes; ` +
      `${regionCells} region cells, samples in them ${inRegion} inside / ${outRegion} outside (${regionSame} bit-identical), ` +
      `${regionDiffer} differ from the regions read as "no plane"`);
    check(identical === pts.length, `${name} planes${validity ? ' validity' : ''}${visibility ? ' visibility' : ''}: volumeIrradiance equals the C header bit for bit`);
    check(differ > pts.length / 4, `${name} planes: the planes change the result (${differ} of ${pts.length})`);
    check(noneSame === pts.length, `${name}: every entry "no plane" gives the result without planes bit for bit`);
    check(inRegion >= 50 && outRegion >= 50 && regionSame === inRegion + outRegion,
      `${name}: corner regions sampled on both sides (${inRegion} inside, ${outRegion} outside), bit-identical to the C header`);
    check(regionDiffer > (inRegion + outRegion) / 4, `${name}: the corner regions change the result (${regionDiffer} of ${inRegion + outRegion})`);
    planeSamples += identical;

    // glTF axes: grid and probe order permuted, sides and mask bits permuted, the normal codes kept;
    // SH in zhc axes (what zhc writes, shAxes "zhc"), so the normal passed is in zhc axes.
    const order = gltfProbeOrder(z.grid.counts);
    const sh = runtime.decodeAll(z.encoding, z.payload, count, z.params);
    const shG = new Float32Array(count * 27);
    order.forEach((q, g) => shG.set(sh.subarray(q * 27, q * 27 + 27), g * 27));
    const perm = (a) => [a[1], a[2], a[0]];
    const gridG = { origin: perm(z.grid.origin), spacing: perm(z.grid.spacing), counts: perm(z.grid.counts) };
    const gltfVol = (planesAxes) => runtime.makeVolume({ sh: shG, ...gridG,
      validity: validity && Uint8Array.from(order, (q) => validity[q]),
      visibility: visibility && Uint8Array.from(order, (q) => gltfBits(visibility[q])),
      planes: gltfPlanes(z.grid.counts, planes), planesAxes });
    const gvol = gltfVol('gltf'), wrong = gltfVol('zhc');
    // Corner regions left in zhc axes (not permuted with the grid): must be wrong somewhere.
    const unpermuted = gltfPlanes(z.grid.counts, planes);
    order.forEach((q, g) => { if (isRegion(planes, 5 * q)) unpermuted.set(planes.subarray(5 * q, 5 * q + 5), 5 * g); });
    const rawRegions = runtime.makeVolume({ ...gvol, planes: unpermuted });
    let mean = 0, worst = 0, wrongFar = 0, rawFar = 0;
    for (const e of want) mean += (Math.abs(e[0]) + Math.abs(e[1]) + Math.abs(e[2])) / 3;
    mean /= want.length;
    const off = (a, i) => a.some((x, k) => Math.abs(x - want[i][k]) > 1e-6 * mean);
    pts.forEach(({ p, n }, i) => {
      const got = runtime.volumeIrradiance(gvol, runtime.zhcToGltfDir(p), n);
      for (let k = 0; k < 3; k++) worst = Math.max(worst, Math.abs(got[k] - want[i][k]) / mean);
      if (off(runtime.volumeIrradiance(wrong, runtime.zhcToGltfDir(p), n), i)) wrongFar++;
      if (off(runtime.volumeIrradiance(rawRegions, runtime.zhcToGltfDir(p), n), i)) rawFar++;
    });
    console.log(`  the same in glTF axes (planesAxes 'gltf'): max error / mean ${worst.toExponential(2)} against the C header; ` +
      `the normal code read in the grid's axes ('zhc') is off at ${wrongFar} of ${pts.length}, regions not permuted to glTF axes at ${rawFar}`);
    check(mean > 0 && worst <= 1e-6, `${name} planes in glTF axes: volumeIrradiance agrees with the C header within 1e-6 of the mean`);
    check(wrongFar > pts.length / 20, `${name} planes in glTF axes: planesAxes 'zhc' (no swizzle) would be wrong (${wrongFar})`);
    check(rawFar > (inRegion + outRegion) / 10, `${name} corner regions in glTF axes: their fields left in zhc axes would be wrong (${rawFar})`);
  }
  console.log(`volumes with planes: ${planeSamples} samples bit-identical between JS and C`);

  // Hand-made: a 3x2x2 grid (spacing 2, 1, 1.5), probe columns x = 0, 1, 2 of constant radiance
  // A, B, C. Cell (0, 0, 0): the plane x = 0.6 (normal +x: corners dx = 1 positive); cell (1, 0, 0):
  // the plane x = 3 with normal -x (corners dx = 0 positive). Left of 0.6: A alone; 0.6..3: B alone;
  // right of 3: C alone. Cell (0, 0, 0) with sides 0xFF in a second file: a point on the negative
  // side keeps no corner and takes the plain blend.
  const grid = { origin: [0, 0, 0], spacing: [2, 1, 1.5], counts: [3, 2, 2] };
  const colour = [[1.0, 0.5, 0.25], [0.125, 0.25, 2.0], [3.0, 0.75, 0.5]];
  const probes = [];
  for (let i = 0; i < 12; i++) {
    const dc = colour[i % 3];
    probes.push({ sh3: Array.from({ length: 9 }, (_, j) => (j === 0 ? dc.map((c) => c * 2 * Math.sqrt(Math.PI)) : [0, 0, 0])) });
  }
  fs.writeFileSync(W('hand.json'), JSON.stringify({ format: 'zhc-probes', version: 1, layout: { type: 'grid', ...grid }, probes }));
  run('convert', W('hand.json'), '-o', W('hand_v1.zhp'), '--to', 'sh3');
  const handV1 = new Uint8Array(fs.readFileSync(W('hand_v1.zhp')));
  const plusX = encodeNormal([1, 0, 0]), minusX = encodeNormal([-1, 0, 0]);
  check(plusX[0] === 254 && plusX[1] === 127 && minusX[0] === 0 && minusX[1] === 127, 'the +x and -x codes are (254, 127) and (0, 127)');
  const handPlanes = (sides0) => planesSection(grid, (i0) => {
    if (i0[1] !== 0 || i0[2] !== 0) return null;
    return i0[0] === 0 ? planeEntry(grid, i0, plusX, [0.6, 0, 0], sides0) : planeEntry(grid, i0, minusX, [3, 0, 0]);
  });
  const planesA = handPlanes(null);
  check(planesA[4] === 0xAA && planesA[5 + 4] === 0x55, `hand-made sides: 0xAA (dx = 1 positive) and 0x55 (${planesA[4]}, ${planesA[9]})`);
  fs.writeFileSync(W('hand.zhp'), zhpWithPlanes(handV1, { planes: planesA }, runtime.crc32));
  fs.writeFileSync(W('hand_ff.zhp'), zhpWithPlanes(handV1, { planes: handPlanes(0xFF) }, runtime.crc32));
  const hand = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(W('hand.zhp'))));
  const handFF = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(W('hand_ff.zhp'))));
  const handPlain = runtime.volumeFromZhp(handV1);
  const hr = makeRand(5);
  const handPts = [];
  for (let i = 0; i < 400; i++) {
    // x avoids the planes by 1e-3; y, z inside the box (cells i0_y = i0_z = 0: the planes' cells).
    let x;
    do x = f32(4 * hr()); while (Math.abs(x - 0.6) < 1e-3 || Math.abs(x - 3) < 1e-3);
    const zz = 2 * hr() - 1, phi = 2 * Math.PI * hr(), r = Math.sqrt(1 - zz * zz);
    handPts.push({ p: [x, f32(hr()), f32(1.5 * hr())], n: [f32(r * Math.cos(phi)), f32(r * Math.sin(phi)), f32(zz)] });
  }
  const wantHand = sampleC(W('hand.zhp'), handPts), wantFF = sampleC(W('hand_ff.zhp'), handPts);
  let handSame = 0, sideOk = 0, ffSame = 0, ffPlain = 0, ffNeg = 0;
  handPts.forEach(({ p, n }, i) => {
    const got = runtime.volumeIrradiance(hand, p, n);
    if (same(got, wantHand[i])) handSame++;
    const column = p[0] < 0.6 ? 0 : p[0] < 3 ? 1 : 2;
    const own = runtime.irradiance(handPlain.sh.subarray(column * 27, column * 27 + 27), runtime.normalizeOr(n));
    if (got.every((g, k) => Math.abs(g - own[k]) <= 1e-6 * Math.abs(own[k]))) sideOk++;
    const gotFF = runtime.volumeIrradiance(handFF, p, n);
    if (same(gotFF, wantFF[i])) ffSame++;
    if (p[0] < 0.6) {
      ffNeg++;
      if (same(gotFF, runtime.volumeIrradiance(handPlain, p, n))) ffPlain++;
    }
  });
  console.log(`hand-made planes: ${handSame}/${handPts.length} bit-identical to the C header, ${sideOk} show their side's probe alone; ` +
    `sides 0xFF: ${ffSame} bit-identical, ${ffPlain}/${ffNeg} on the negative side equal the plain blend`);
  check(handSame === handPts.length && ffSame === handPts.length, 'hand-made planes: bit-identical to the C header');
  check(sideOk === handPts.length, 'hand-made planes: every point shows the probe column on its side of the plane (within 1e-6)');
  check(ffNeg >= 50 && ffPlain === ffNeg, 'a plane with every corner on the positive side: points on the negative side take the plain blend');
  // Hand-made corner regions: a 2x2x2 grid (spacing 2, 1, 1.5) of DC-only probes whose irradiance is
  // red (1, 0, 0) at corners 0 and 2 (x = 0, z = 0), blue (0, 0, 1) at corner 7, green elsewhere.
  // Region A: q = (10, 0, 20), d = (0, 0, 0): x < 20/31, z < 30/31, any y; inside it corners 0 and 2
  // only, so red exactly, outside no red at all. Region B: q = (21, 9, 3), d = (1, 1, 1): inside it
  // corner 7 only (blue exactly), outside no blue.
  {
    const g2 = { origin: [0, 0, 0], spacing: [2, 1, 1.5], counts: [2, 2, 2] };
    const colourOf = (k) => (k === 0 || k === 2 ? [1, 0, 0] : k === 7 ? [0, 0, 1] : [0, 1, 0]);
    const probes2 = Array.from({ length: 8 }, (_, k) => ({
      sh3: Array.from({ length: 9 }, (_, j) => (j === 0 ? colourOf(k).map((c) => c * 2 * Math.sqrt(Math.PI)) : [0, 0, 0])) }));
    fs.writeFileSync(W('region.json'), JSON.stringify({ format: 'zhc-probes', version: 1, layout: { type: 'grid', ...g2 }, probes: probes2 }));
    run('convert', W('region.json'), '-o', W('region_v1.zhp'), '--to', 'sh3');
    const rv1 = new Uint8Array(fs.readFileSync(W('region_v1.zhp')));
    const regionCases = [
      { tag: 'A', entry: regionEntry([10, 0, 20], [0, 0, 0]), d: 0, channel: 0, bounds: [[0, 10], [2, 20]] },
      { tag: 'B', entry: regionEntry([21, 9, 3], [1, 1, 1]), d: 1, channel: 2, bounds: [[0, 21], [1, 9], [2, 3]] },
    ];
    const rr = makeRand(6);
    for (const rc of regionCases) {
      const planesR = planesSection(g2, () => rc.entry);
      const file = W(`region_${rc.tag}.zhp`);
      fs.writeFileSync(file, zhpWithPlanes(rv1, { planes: planesR }, runtime.crc32));
      const vol = runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(file)));
      const pts = [];
      while (pts.length < 600) {
        const p = [0, 1, 2].map((a) => f32(g2.spacing[a] * rr()));
        // 1e-3 away from the region's faces (x_a = q_a spacing_a / 31).
        if (rc.bounds.some(([a, q]) => Math.abs(p[a] - q * g2.spacing[a] / 31) < 1e-3)) continue;
        const zz = 2 * rr() - 1, phi = 2 * Math.PI * rr(), r = Math.sqrt(1 - zz * zz);
        pts.push({ p, n: [f32(r * Math.cos(phi)), f32(r * Math.sin(phi)), f32(zz)] });
      }
      const want = sampleC(file, pts);
      let bit = 0, inside = 0, insideExact = 0, outside = 0, outsideNone = 0;
      pts.forEach(({ p, n }, i) => {
        const got = runtime.volumeIrradiance(vol, p, n);
        if (same(got, want[i])) bit++;
        // The region by its definition: x_a < q_a s_a / 31 (d_a = 0) or >= (d_a = 1) on its axes.
        const inR = rc.bounds.every(([a, q]) => (rc.d ? p[a] >= q * g2.spacing[a] / 31 : p[a] < q * g2.spacing[a] / 31));
        if (inR) {
          inside++;
          if (got.every((x, k) => Math.abs(x - (k === rc.channel ? 1 : 0)) <= 1e-6)) insideExact++;
        } else {
          outside++;
          if (got[rc.channel] === 0) outsideNone++;
        }
      });
      console.log(`hand-made corner region ${rc.tag}: ${bit}/${pts.length} bit-identical to the C header; inside ${insideExact}/${inside} ` +
        `show only its corners' colour, outside ${outsideNone}/${outside} none of it`);
      check(bit === pts.length, `hand-made corner region ${rc.tag}: bit-identical to the C header`);
      check(inside >= 30 && insideExact === inside, `hand-made corner region ${rc.tag}: every point inside shows only the corners inside (1e-6)`);
      check(outside >= 30 && outsideNone === outside, `hand-made corner region ${rc.tag}: no point outside gets any weight from the corners inside`);
    }
  }

  // Constant probes stay constant under any planes (the kept weights are renormalised).
  const one = new Float32Array(27 * 12);
  for (let p = 0; p < 12; p++) one.set([0.7, 0.4, 0.2, 0.1, -0.05, 0.02, 0.3, 0.1, 0, 0.01, 0.02, 0.03].concat(Array(15).fill(0.01)), 27 * p);
  const constVol = runtime.makeVolume({ sh: one, ...grid, planes: randomPlanes(grid, makeRand(9), { pNone: 0, pRandomSides: 0.5, pRegion: 0.4 }) });
  let constWorst = 0;
  const ref = (n) => runtime.irradiance(one.subarray(0, 27), runtime.normalizeOr(n));
  handPts.forEach(({ p, n }) => {
    const got = runtime.volumeIrradiance(constVol, p, n), e = ref(n);
    for (let k = 0; k < 3; k++) constWorst = Math.max(constWorst, Math.abs(got[k] - e[k]) / (Math.abs(e[k]) + 1e-3));
  });
  console.log(`constant probes under random planes and corner regions: max relative difference ${constWorst.toExponential(2)}`);
  check(constWorst <= 1e-6, 'constant probes stay constant under random planes and corner regions (1e-6)');
}

// --- 4: refusals ----------------------------------------------------------------------------------------
fs.writeFileSync(W('points.json'), JSON.stringify({ format: 'zhc-probes', version: 1, layout: { type: 'positions' },
  probes: [{ position: [0, 0, 0], sh3: Array.from({ length: 9 }, () => [1, 1, 1]) }] }));
run('convert', W('points.json'), '-o', W('points.zhp'), '--to', 'zh3_q16');
check(throwsWith(() => runtime.volumeFromZhp(new Uint8Array(fs.readFileSync(W('points.zhp')))), /not a grid/),
  'volumeFromZhp refuses a positions layout');
{
  const bytes = new Uint8Array(fs.readFileSync(W('demo/probes_zh3_q16.zhp')));
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  dv.setFloat64(128, 0, true);  // spacing y
  dv.setUint32(180, runtime.crc32(bytes, 0, 180), true);
  check(throwsWith(() => runtime.volumeFromZhp(bytes), /spacing\[1\]/), 'volumeFromZhp refuses spacing 0');
  dv.setFloat64(128, -1, true);
  dv.setUint32(180, runtime.crc32(bytes, 0, 180), true);
  check(throwsWith(() => runtime.volumeFromZhp(bytes), /spacing\[1\]/), 'volumeFromZhp refuses a negative spacing');
}
check(throwsWith(() => runtime.makeVolume({ sh: new Float32Array(27), origin: [0, 0, 0], spacing: [1, 1, 1], counts: [1, 0, 1] }), /counts\[1\]/),
  'makeVolume refuses a zero count');
check(throwsWith(() => runtime.makeVolume({ sh: new Float32Array(27), origin: [0, 0, 0], spacing: [1, 1, 1], counts: [2, 1, 1] }), /SH3 floats/),
  'makeVolume refuses too few probes');
{
  const sh = new Float32Array(54), grid = { origin: [0, 0, 0], spacing: [1, 1, 1], counts: [2, 1, 1] };
  check(throwsWith(() => runtime.makeVolume({ sh, ...grid, planes: new Uint8Array(9) }), /planes has 9 bytes for 2 probes/),
    'makeVolume refuses planes shorter than 5 bytes per probe');
  check(throwsWith(() => runtime.makeVolume({ sh, ...grid, planes: new Uint8Array(10), planesAxes: 'yzx' }), /planesAxes must be 'zhc' or 'gltf'/),
    'makeVolume refuses a planesAxes other than zhc / gltf');
  // A plane on the last probe along x (it starts no cell), and planes on a points file.
  const v1 = new Uint8Array(fs.readFileSync(W('demo/probes_zh3_q16.zhp')));
  const z = runtime.parseZhp(v1);
  const planes = planesSection(z.grid, () => null);
  const last = z.grid.counts[0] - 1;  // probe (nx - 1, 0, 0)
  planes.set([127, 127, 0, 0, 0x0F], 5 * last);
  check(throwsWith(() => runtime.parseZhp(zhpWithPlanes(v1, { planes }, runtime.crc32)), new RegExp(`probe ${last} is the last along an axis`)),
    'parseZhp refuses a plane on a probe that starts no cell');
  planes.set(regionEntry([5, 0, 7], [1, 0, 0]), 5 * last);
  check(throwsWith(() => runtime.parseZhp(zhpWithPlanes(v1, { planes }, runtime.crc32)), new RegExp(`probe ${last} is the last along an axis`)),
    'parseZhp refuses a corner region on a probe that starts no cell');
  planes.set([0, 0, 0x00, 0x80, 0x80], 5 * last);  // bit 7 alone: a region with every axis unbounded
  check(throwsWith(() => runtime.parseZhp(zhpWithPlanes(v1, { planes }, runtime.crc32)), new RegExp(`probe ${last} is the last along an axis`)),
    'parseZhp refuses bit 7 of byte 4 on a probe that starts no cell');
  planes.set(NO_PLANE, 5 * last);
  check(runtime.parseZhp(zhpWithPlanes(v1, { planes }, runtime.crc32)).planes !== null, 'the same file with "no plane" there is read');
  // Corner regions' reserved bits (bit 15 of r, bits 3..6 of byte 4) on probe 0, which starts a cell.
  planes.set(regionEntry([5, 0, 7], [1, 0, 0]), 0);
  check(runtime.parseZhp(zhpWithPlanes(v1, { planes }, runtime.crc32)).planes[4] === 0x81, 'a corner region on probe 0 is read');
  for (const [b, bit] of [[1, 0x80], [4, 0x08], [4, 0x40]]) {
    const bad = planes.slice();
    bad[b] |= bit;
    check(throwsWith(() => runtime.parseZhp(zhpWithPlanes(v1, { planes: bad }, runtime.crc32)), /probe 0's corner region sets reserved bits/),
      `parseZhp refuses a corner region with bit ${bit.toString(16)} of byte ${b} set`);
  }
  const pts = new Uint8Array(fs.readFileSync(W('points.zhp')));
  check(throwsWith(() => runtime.parseZhp(zhpWithPlanes(pts, { planes: new Uint8Array(5).fill(0) }, runtime.crc32)), /cell planes without a grid layout/),
    'parseZhp refuses planes without a grid layout');
}
console.log(`volumes: ${cases.length} files, ${identical}/${total} samples bit-identical between JS and C`);
finish('runtime/web volume');
