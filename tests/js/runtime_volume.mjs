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
//  4. volumeFromZhp refuses a points file and a spacing <= 0 grid; irradianceAt refuses non-grids.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { register } from 'node:module';
import { makeRand, checker, zhpWithSections, triangleScene } from './fixtures.mjs';

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
const withSections = (bytes, validity, visibility) => zhpWithSections(bytes, validity, visibility, runtime.crc32);
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
    // The demo's files carry the bake's own masks: the plain blend is the volume without them.
    const plain = Object.freeze({ ...runtime.volumeFromZhp(v1), validity: null, visibility: null });
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
console.log(`volumes: ${cases.length} files, ${identical}/${total} samples bit-identical between JS and C`);
finish('runtime/web volume');
