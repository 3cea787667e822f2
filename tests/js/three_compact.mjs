// zhc's compact volume path in three.js (runtime/web/zhc_volume.glsl.mjs) in headless Chromium
// (CTest: js.three_compact). Usage: node three_compact.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR [CHROMIUM]
//
//  1. zhc writes the grids: `zhc demo` (probes.glb: the 8x8x4 zh3_q16 grid, glTF; probes_sh3.zhp,
//     probes_zh3_q16.zhp: the same probes) and `zhc convert probes_sh3.zhp` to sh3_q28, sh2_q and
//     zh3_channel_q16 with non-default parameters (6 bits, sqrt, RGB9E5 DC); `zhc bake` of a small
//     scene whose 4x4x3 grid a wall cuts between two probe columns and a box encloses one probe:
//     zh3_q16 (.glb and .zhp) and sh3_q28 (.zhp), with the leak data the bake writes (validity and
//     cell planes); `zhc bake` of two closed rooms split by a solid wall, a point light in the west
//     room only (zh3_q16 .zhp, validity and planes); the demo's zh3_q16 .zhp with synthetic masks
//     handed to compactVolume with `planes: false` (random invalid probes and cleared bits; the
//     bottom two probe layers fully masked, so that their cells take the all-masked fallback, the
//     plain weights); a hand-made 4x3x2 zh3_q16 grid whose first probe column is black, an axis
//     plane in the cells of its first cell column (the "wall") and an oblique one in the third
//     (.zhp; the same with random validity and visibility; and in glTF axes as a compact source:
//     grid, probe order and sides bits permuted, planesAxes 'gltf'); the same probes with corner
//     regions (docs/runtime.md "Corner regions"): cell column 0 the region x < -1 + 11/31 holding
//     the black corners, cell column 1 random regions, cell column 2 the oblique plane and a region
//     bounded along all three axes (.zhp, with masks, and in glTF axes with the regions' fields
//     permuted), at least 4 samples inside and 4 outside a region in its cell;
//  2. 24 samples per volume: 20 points q random inside the grid's box, 4 outside it (clamped),
//     random unit directions d, in the volume's frame (glb / glTF source: node-local glTF axes;
//     .zhp: zhc axes); on grids with masks or planes no coordinate within 1e-3 of a cell face (a
//     masked blend is not continuous across cell faces, so float32 and double could pick different
//     cells there) and no point within 1e-4 |spacing| of its cell's plane or of a bounding plane of
//     its cell's corner region (float32 and double may put such a point on different sides); the
//     two rooms and the hand-made grids: 10 of the 20 in the dark region (in the cells the wall or
//     the black corners' region crosses, on its dark side);
//  3. headless Chromium (SwiftShader WebGL2) runs tests/js/browser/three_compact_page.mjs: the stored
//     bytes in an RGBA32UI Data3DTexture (compactVolume), (A) a ShaderMaterial writing
//     zhcVolumeIrradiance per sample, (B) white spheres with a MeshLambertMaterial patched by
//     patchMaterialWithVolume (pole at q in world space, normal d), both to RGBA32F targets;
//  4. the C header (tests/runtime_c/zhc_volume_sample: zhc_volume_from_zhp + zhc_volume_irradiance)
//     gives E(q, d) from the .zhp (glTF samples converted to zhc axes), with the file's validity,
//     visibility and planes, or without them (`--plain`: the baked .zhp built with `masks: false,
//     planes: false`); for the synthetic masks the JS runtime's volumeIrradiance with them (the C
//     header's doubles in the same order, bit for bit: js.runtime_volume), and in the fully masked
//     cells the plain C header, bit for bit;
//  5. masks and planes: compactVolume's combined mask texture and RG32UI plane texture against
//     twins (glTF volumes: the .zhp's bytes with probe order, bits and region fields permuted to
//     glTF; entries that are all corner regions get the texture too), the chunk
//     defines ZHC_VOLUME_PLANES (and ZHC_VOLUME_PLANE_AXES_GLTF for glTF volumes) exactly when the
//     volume has planes, the leak data move the C header's E beyond the tolerance at >= 4 samples
//     of the baked and hand-made grids (ignoring them would fail); in the dark regions the C header
//     reads 0 and so do both GPU pixels, exactly, where the plain blend does not; and in Node (no
//     browser) the chunk's text: unchanged without masks and planes, `masks: false` / `planes:
//     false` drop them, each added line set keeps every line of the plain chunk.
//
// Tolerance: the error model of the GLSL volume test (tests/test_runtime_gl.cpp, compare_volumes):
// |pixel - E| <= (48 + 3 X) u S per channel, u = 2^-24, S = the sum over the cell's corners of
// each probe's irradiance scale (kY00 m0 + 2/3 kY1 (m1 + m2 + m3) + L2 part, m_i the coefficient
// magnitude or its ratio bound times the DC; ZH3's zonal part grows with the axis' condition
// number), X = sum over axes of (|p| + |o|) / s + t + 2 (the float grid coordinate's error).
// Masks and planes: the kept weights are divided by their sum M (<= 1), which scales their errors by
// up to 1 / M: X / M (the division's own rounding is a few u, inside the 48).
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
import { makeRand, checker, freshWork, repoRoot } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';
import { parseZhp, decodeAll, makeVolume, volumeIrradiance, crc32, kY00, kY1, kY20 } from '../../runtime/web/zhc_runtime.mjs';
import { zhpWithPlanes, encodeNormal, decodeNormal, planeEntry, planesSection, planeMargin, planeSideAt, gltfProbeOrder, gltfBits, gltfPlanes,
  regionEntry, isRegion } from './planes_fixtures.mjs';
import { zhcVolumeGlsl, compactVolume, compactVolumeMask } from '../../runtime/web/zhc_volume.glsl.mjs';

const [zhc, sampler, workArg, chromiumArg] = process.argv.slice(2);
if (!zhc || !sampler || !workArg) {
  console.error('usage: node three_compact.mjs ZHC_BINARY ZHC_VOLUME_SAMPLE WORK_DIR [CHROMIUM]');
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
const U = 2 ** -24;

// --- 1. volumes written by zhc ---------------------------------------------------------------------
run('demo', '-o', W('demo'), '--directions', '16');
fs.copyFileSync(W('demo/probes.glb'), W('demo_probes.glb'));
run('convert', W('demo/probes_sh3.zhp'), '-o', W('demo_sh3_q28.zhp'), '-r', 'sh3_q28');
run('convert', W('demo/probes_sh3.zhp'), '-o', W('demo_sh2_q.zhp'), '-r', 'sh2_q');
run('convert', W('demo/probes_sh3.zhp'), '-o', W('demo_zh3_channel.zhp'), '-r', 'zh3_channel_q16', '--bits', '6', '--sqrt', '--dc', 'rgb9e5');
// A baked grid with leak data: probes at x = -1, -1/3, 1/3, 1; a double-sided wall at x = 0.2 cuts
// the middle column of cells, the point light sits on the wall's +x side, the blue sphere light on
// its -x side; the box encloses probe (1, -1, 0). invalid_fraction 0.6: the single-sided wall's back
// face (at most half a probe's rays) invalidates no probe.
fs.writeFileSync(W('masked_scene.json'), JSON.stringify({
  version: 1, probes: { grid: { min: [-1, -1, 0], max: [1, 1, 1.5], counts: [4, 4, 3] } }, sky: { type: 'gradient' },
  occlusion: { invalid_fraction: 0.6 },
  lights: [{ type: 'point', position: [0.7, 0.1, 0.8], intensity: [8, 6.4, 4.8], shadows: true },
    { type: 'sphere', center: [-0.7, 0.8, 1.2], radius: 0.15, radiance: [3, 6, 40], shadows: true }],
  occluders: [{ type: 'mesh', positions: [0.2, -2, -1, 0.2, 2, -1, 0.2, 2, 3, 0.2, -2, 3], indices: [0, 1, 2, 0, 2, 3] },
    { type: 'box', min: [0.8, -1.2, -0.2], max: [1.2, -0.8, 0.2] }],
}));
run('bake', W('masked_scene.json'), '-o', W('baked_masked.glb'), '--to', 'zh3_q16', '--quiet');
run('bake', W('masked_scene.json'), '-o', W('baked_masked.zhp'), '--to', 'zh3_q16', '--quiet');
run('bake', W('masked_scene.json'), '-o', W('baked_masked_sh3_q28.zhp'), '--to', 'sh3_q28', '--quiet');
// Two closed 5 x 3 x 6 m rooms (x 0..5 and 5.2..10.2) split by a solid wall 0.2 m thick (x 5..5.2),
// an 8 cd point light in the west room, no sky, no reflected light (--bounces 0): the east room's
// light is exactly 0. The 7x3x5 grid (spacing 1.5 along x) has a probe plane 0.45 m west of the
// wall's centre: the wall crosses the cells of x 4.65..6.15 off their middle (docs/leaks.md); the
// dark region is their part east of the wall (x 5.2..6.15).
const TWO_ROOMS_WALL = [5, 5.2];
const box = (min, max) => ({ type: 'box', min, max });
fs.writeFileSync(W('two_rooms.json'), JSON.stringify({
  version: 1, probes: { grid: { min: [0.15, 0.25, 0.25], max: [9.15, 2.75, 5.75], counts: [7, 3, 5] } },
  lights: [{ type: 'point', position: [2.5, 2.0, 3.0], intensity: [8, 8, 8], shadows: true }],
  occluders: [box([-0.2, -0.2, -0.2], [10.4, 0, 6.2]), box([-0.2, 3, -0.2], [10.4, 3.2, 6.2]), box([-0.2, 0, 0], [0, 3, 6]),
    box([10.2, 0, 0], [10.4, 3, 6]), box([-0.2, 0, -0.2], [10.4, 3, 0]), box([-0.2, 0, 6], [10.4, 3, 6.2]),
    box([TWO_ROOMS_WALL[0], 0, 0], [TWO_ROOMS_WALL[1], 3, 6])],
}));
run('bake', W('two_rooms.json'), '-o', W('two_rooms.zhp'), '--to', 'zh3_q16', '--bounces', '0', '--quiet');
// The hand-made grid (zhc axes): 4x3x2 probes from (-1, 0.5, 0), spacing (1, 0.8, 1.2); probe
// column x = 0 black, the others lit (DC and L1 varying with the probe). Cells of cell column 0:
// the plane x = -0.65 (normal +x, sides 0xAA: the dark corners on its negative side); cell column
// 2: an oblique plane (normal (1, 0.6, -0.3) normalised, 0.1 from the cell's centre).
const handGrid = { origin: [-1, 0.5, 0], spacing: [1, 0.8, 1.2], counts: [4, 3, 2] };
const HAND_WALL = -0.65;
{
  const probes = [];
  for (let z = 0; z < 2; z++) for (let y = 0; y < 3; y++) for (let x = 0; x < 4; x++) {
    const dc = x === 0 ? [0, 0, 0] : [1 + 0.3 * x, 0.8 + 0.1 * y, 0.5 + 0.2 * z];
    const dir = [Math.cos(x + 2 * y), Math.sin(x + 2 * y), 0.5 - z];
    const sh3 = Array.from({ length: 9 }, () => [0, 0, 0]);
    for (let k = 0; k < 3; k++) {
      sh3[0][k] = 2 * Math.sqrt(Math.PI) * dc[k];
      // L1 (index 1, 2, 3 = y, z, x with zhc's signs: -y, z, -x) a third of the DC along dir.
      sh3[1][k] = -0.3 * dc[k] * dir[1];
      sh3[2][k] = 0.3 * dc[k] * dir[2];
      sh3[3][k] = -0.3 * dc[k] * dir[0];
    }
    probes.push({ sh3 });
  }
  fs.writeFileSync(W('hand.json'), JSON.stringify({ format: 'zhc-probes', version: 1, layout: { type: 'grid', ...handGrid }, probes }));
  run('convert', W('hand.json'), '-o', W('hand_v1.zhp'), '--to', 'zh3_q16');
  const oblique = encodeNormal([1, 0.6, -0.3]);
  const planes = planesSection(handGrid, (i0) => {
    if (i0[0] === 0) return planeEntry(handGrid, i0, encodeNormal([1, 0, 0]), [HAND_WALL, 0, 0]);
    if (i0[0] !== 2) return null;
    const n = decodeNormal(...oblique), c = [0, 1, 2].map((a) => handGrid.origin[a] + (i0[a] + 0.5) * handGrid.spacing[a]);
    return planeEntry(handGrid, i0, oblique, c.map((x, a) => x + 0.1 * n[a]));
  });
  const v1 = new Uint8Array(fs.readFileSync(W('hand_v1.zhp')));
  fs.writeFileSync(W('hand_planes.zhp'), zhpWithPlanes(v1, { planes }, crc32));
  const mr = makeRand(77), count = planes.length / 5;
  const validity = Uint8Array.from({ length: count }, () => (mr() < 0.15 ? 0 : 1));
  const visibility = Uint8Array.from({ length: count }, () => { let m = 0; for (let j = 0; j < 8; j++) if (mr() >= 0.25) m |= 1 << j; return m; });
  fs.writeFileSync(W('hand_all.zhp'), zhpWithPlanes(v1, { validity, visibility, planes }, crc32));
  // Corner regions (docs/runtime.md "Corner regions") on the same probes: cell column 0, the region
  // x < -1 + 11/31 (q = (11, 0, 0), d = 0: the black corners inside it, the "wall" at HAND_REGION_WALL);
  // cell column 1, random regions (some axes unbounded); cell column 2, the oblique plane at y = 0
  // and a region bounded on all three axes (d = (1, 0, 1)) at y = 1.
  const rr = makeRand(78);
  const regions = planesSection(handGrid, (i0) => {
    if (i0[0] === 0) return regionEntry([11, 0, 0], [0, 0, 0]);
    if (i0[0] === 1) return regionEntry([0, 1, 2].map(() => (rr() < 0.25 ? 0 : 1 + Math.floor(rr() * 31))), [0, 1, 2].map(() => (rr() < 0.5 ? 0 : 1)));
    if (i0[1] === 1) return regionEntry([20, 15, 10], [1, 0, 1]);
    const n = decodeNormal(...oblique), c = [0, 1, 2].map((a) => handGrid.origin[a] + (i0[a] + 0.5) * handGrid.spacing[a]);
    return planeEntry(handGrid, i0, oblique, c.map((x, a) => x + 0.1 * n[a]));
  });
  fs.writeFileSync(W('hand_regions.zhp'), zhpWithPlanes(v1, { planes: regions }, crc32));
  fs.writeFileSync(W('hand_regions_all.zhp'), zhpWithPlanes(v1, { validity, visibility, planes: regions }, crc32));
}
const HAND_REGION_WALL = handGrid.origin[0] + 11 * handGrid.spacing[0] / 31;

// What the GPU applies, in zhc axes: `leak` = the volume's validity / visibility / planes (null each
// when absent or dropped); derived from the data, not assumed.
const hasMasks = (z) => (compactVolumeMask(z.validity, z.visibility, z.count) ?? []).some((m) => m !== 0xFF);
const hasPlanes = (z) => !!z.planes && Array.from({ length: z.count }, (_, i) => !(z.planes[5 * i + 2] === 0 && z.planes[5 * i + 3] === 0x80) ||
  isRegion(z.planes, 5 * i)).some((x) => x);
// The demo's grids carry a few leak data near its occluders (`fewLeakData`: they need not move E
// at 4 of the samples there). `dark`: [axis, lo, hi] of the dark region in zhc axes; `blackProbes`:
// some probes are black, so E may be 0 (and then the GPU pixels must be 0 too).
const volumes = [
  { name: 'demo zh3_q16 (glb)', fewLeakData: true, glb: 'demo_probes.glb', ref: W('demo/probes_zh3_q16.zhp'), gltf: true, rootTranslation: [0.7, -0.4, 1.3], rootScale: 1.25, seed: 21 },
  { name: 'demo sh3_q28 (.zhp)', fewLeakData: true, zhp: 'demo_sh3_q28.zhp', ref: W('demo_sh3_q28.zhp'), gltf: false, rootTranslation: [-1, 0.5, 2], rootScale: 0.8, seed: 22 },
  { name: 'demo sh2_q (.zhp)', fewLeakData: true, zhp: 'demo_sh2_q.zhp', ref: W('demo_sh2_q.zhp'), gltf: false, rootTranslation: [0.3, 1.5, -0.5], rootScale: 1.5, seed: 23 },
  { name: 'demo zh3_channel_q16 6 bits sqrt rgb9e5 (.zhp)', fewLeakData: true, zhp: 'demo_zh3_channel.zhp', ref: W('demo_zh3_channel.zhp'), gltf: false, rootTranslation: [2, -1, 0.5], rootScale: 1.1, seed: 24 },
  { name: 'demo zh3_q16 synthetic masks, planes: false (.zhp)', zhp: 'demo/probes_zh3_q16.zhp', ref: W('demo/probes_zh3_q16.zhp'), gltf: false, synthetic: 31, noPlanes: true, rootTranslation: [-0.5, 0.3, 0.9], rootScale: 0.7, seed: 28 },
  { name: 'baked zh3_q16 (glb)', glb: 'baked_masked.glb', ref: W('baked_masked.zhp'), gltf: true, rootTranslation: [-0.6, 0.9, 0.4], rootScale: 1.3, seed: 25 },
  { name: 'baked zh3_q16 (.zhp)', zhp: 'baked_masked.zhp', ref: W('baked_masked.zhp'), gltf: false, rootTranslation: [1.2, 0.2, -0.7], rootScale: 0.9, seed: 26 },
  { name: 'baked sh3_q28 (.zhp)', zhp: 'baked_masked_sh3_q28.zhp', ref: W('baked_masked_sh3_q28.zhp'), gltf: false, rootTranslation: [0.4, -0.8, 1.1], rootScale: 1.2, seed: 27 },
  // The same baked .zhp with compactVolume(..., { masks: false, planes: false }): the plain blend.
  { name: 'baked zh3_q16 masks: false, planes: false (.zhp)', zhp: 'baked_masked.zhp', ref: W('baked_masked.zhp'), gltf: false, dropAll: true, rootTranslation: [1.2, 0.2, -0.7], rootScale: 0.9, seed: 26 },
  { name: 'two rooms zh3_q16 (.zhp)', zhp: 'two_rooms.zhp', ref: W('two_rooms.zhp'), gltf: false, requirePlanes: true, blackProbes: true, dark: [0, TWO_ROOMS_WALL[1], 6.15], rootTranslation: [-3, 0.5, -1], rootScale: 0.6, seed: 29 },
  { name: 'hand-made planes (.zhp)', zhp: 'hand_planes.zhp', ref: W('hand_planes.zhp'), gltf: false, requirePlanes: true, blackProbes: true, dark: [0, -1, HAND_WALL], rootTranslation: [0.2, -0.3, 0.6], rootScale: 1.4, seed: 32 },
  { name: 'hand-made planes + masks (.zhp)', zhp: 'hand_all.zhp', ref: W('hand_all.zhp'), gltf: false, requirePlanes: true, blackProbes: true, rootTranslation: [-0.4, 0.1, 0.3], rootScale: 1.1, seed: 33 },
  { name: 'hand-made planes in glTF axes (source)', source: 'hand_planes.zhp', ref: W('hand_planes.zhp'), gltf: true, requirePlanes: true, blackProbes: true, dark: [0, -1, HAND_WALL], rootTranslation: [0.5, 0.2, -0.8], rootScale: 0.9, seed: 34 },
  { name: 'hand-made corner regions (.zhp)', zhp: 'hand_regions.zhp', ref: W('hand_regions.zhp'), gltf: false, requirePlanes: true, regions: true, blackProbes: true, dark: [0, -1, HAND_REGION_WALL], rootTranslation: [-0.3, 0.4, 0.2], rootScale: 1.2, seed: 35 },
  { name: 'hand-made corner regions + masks (.zhp)', zhp: 'hand_regions_all.zhp', ref: W('hand_regions_all.zhp'), gltf: false, requirePlanes: true, regions: true, blackProbes: true, rootTranslation: [0.6, -0.2, -0.4], rootScale: 0.8, seed: 36 },
  { name: 'hand-made corner regions in glTF axes (source)', source: 'hand_regions.zhp', ref: W('hand_regions.zhp'), gltf: true, requirePlanes: true, regions: true, blackProbes: true, dark: [0, -1, HAND_REGION_WALL], rootTranslation: [0.1, -0.6, 0.7], rootScale: 1.3, seed: 37 },
];
const toZhc = (v) => [v[2], v[0], v[1]];  // glTF (x, y, z) = zhc (y, z, x)
const SAMPLES = 24, OUTSIDE = 4, DARK = 10;
for (const v of volumes) {
  let z = parseZhp(new Uint8Array(fs.readFileSync(v.ref)));
  if (v.synthetic) {
    // ~15 % invalid probes, each visibility bit cleared with probability 0.3; probes of the two
    // lowest z layers (zhc axes) fully masked: every corner of a cell with i0_z = 0 is dropped.
    const mr = makeRand(v.synthetic), [nx, ny] = z.grid.counts;
    const validity = new Uint8Array(z.count), visibility = new Uint8Array(z.count);
    for (let p = 0; p < z.count; p++) {
      validity[p] = mr() < 0.15 ? 0 : 1;
      for (let j = 0; j < 8; j++) if (mr() >= 0.3) visibility[p] |= 1 << j;
      if (Math.floor(p / (nx * ny)) < 2) visibility[p] = 0;
    }
    z = { ...z, validity, visibility };
    v.validity = Array.from(validity);
    v.visibility = Array.from(visibility);
  }
  v.zhpInfo = z;
  v.masked = !v.dropAll && hasMasks(z);
  v.planed = !v.dropAll && !v.noPlanes && hasPlanes(z);
  v.leak = { validity: v.masked ? z.validity : null, visibility: v.masked ? z.visibility : null, planes: v.planed ? z.planes : null };
  if (v.requirePlanes) check(v.planed, `${v.name}: the file has cell planes`);
  v.sh = decodeAll(z.encoding, z.payload, z.count, z.params);
  if (v.source) {
    // The grid as a compact source in glTF axes: probe order, validity and the bits of visibility
    // and sides permuted, stored bytes and normal codes unchanged (shAxes "zhc").
    const order = gltfProbeOrder(z.grid.counts), bpp = z.bytesPerProbe;
    const bytes = new Uint8Array(z.count * bpp);
    order.forEach((q, g) => bytes.set(z.payload.subarray(q * bpp, (q + 1) * bpp), g * bpp));
    const perm = (a) => [a[1], a[2], a[0]];
    v.sourceSpec = {
      encoding: z.encoding, params: z.params, bytes: Array.from(bytes), bytesPerProbe: bpp, layout: 'grid', shAxes: 'zhc',
      grid: { origin: perm(z.grid.origin), spacing: perm(z.grid.spacing), counts: perm(z.grid.counts) },
      validity: z.validity ? order.map((q) => z.validity[q]) : null,
      visibility: z.visibility ? order.map((q) => gltfBits(z.visibility[q])) : null,
      planes: z.planes ? Array.from(gltfPlanes(z.grid.counts, z.planes)) : null,
    };
  }
  // The grid in the sample frame: zhc axes permuted to glTF for the glTF volumes.
  const g = z.grid;
  const perm = (a) => (v.gltf ? [a[1], a[2], a[0]] : [...a]);
  const frame = { origin: perm(g.origin), spacing: perm(g.spacing), counts: perm(g.counts) };
  const rand = makeRand(v.seed);
  v.samples = [];
  const zhcOf = (q) => (v.gltf ? toZhc(q) : q);
  // Grid coordinate of q along axis c strictly inside the box and within 1e-3 of a cell face; or
  // q within 1e-4 |spacing| of its cell's plane.
  const nearFace = (q) => q.some((x, c) => {
    const t = (x - frame.origin[c]) / frame.spacing[c];
    return t > 0 && t < frame.counts[c] - 1 && Math.abs(t - Math.round(t)) < 1e-3;
  });
  const nearPlane = (q) => v.planed && planeMargin(g, z.planes, zhcOf(q)) <= 1e-4;
  for (let i = 0; i < SAMPLES; i++) {
    const out = i >= SAMPLES - OUTSIDE, inDark = v.dark && i < DARK;
    let q;
    do {
      q = [0, 1, 2].map((c) => {
        const size = (frame.counts[c] - 1) * frame.spacing[c];
        const t = out ? -0.2 + 1.4 * rand() : 0.02 + 0.96 * rand();
        return f32(frame.origin[c] + size * t);
      });
      if (out) q[i % 3] = f32(frame.origin[i % 3] + (i % 2 ? -0.3 : 1.3) * (frame.counts[i % 3] - 1) * frame.spacing[i % 3]);
      if (inDark) {
        // The dark region's axis (zhc axes; glTF axis (a + 2) % 3) between its bounds.
        const [a, lo, hi] = v.dark, ga = v.gltf ? (a + 2) % 3 : a;
        q[ga] = f32(lo + (hi - lo) * (0.01 + 0.98 * rand()));
      }
    } while ((v.masked || v.planed || v.dropAll) && (nearFace(q) || nearPlane(q)));
    const zz = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - zz * zz));
    const d = [r * Math.cos(phi), r * Math.sin(phi), zz];
    const len = Math.hypot(...d);
    v.samples.push({ q, d: d.map((x) => f32(x / len)) });
  }
  if (v.regions) {
    // Samples in corner region cells, inside and outside the region (planes_fixtures' twin of the rule).
    v.regionSides = [0, 0];
    for (const { q } of v.samples) {
      const ps = planeSideAt(g, z.planes, zhcOf(q));
      if (ps && ps.region) v.regionSides[ps.side]++;
    }
    console.log(`${v.name}: ${v.regionSides[1]} samples inside a corner region, ${v.regionSides[0]} outside one in its cell`);
    check(v.regionSides[1] >= 4 && v.regionSides[0] >= 4, `${v.name}: samples on both sides of corner regions (${v.regionSides[1]} inside, ${v.regionSides[0]} outside; >= 4 each)`);
  }
}
fs.writeFileSync(W('three_compact_spec.json'), JSON.stringify({
  volumes: volumes.map(({ name, glb, zhp, sourceSpec, dropAll, noPlanes, validity, visibility, gltf, rootTranslation, rootScale, samples }) =>
    ({ name, glb, zhp, source: sourceSpec, masks: !dropAll, planes: !dropAll && !noPlanes, validity, visibility, gltf, rootTranslation, rootScale, samples })),
}));

// The C header at the samples (zhc axes): with the file's leak data (its default), and plain
// (--plain); the synthetic masks from the JS runtime.
for (const v of volumes) {
  const file = W('points.txt');
  const pts = v.samples.map(({ q, d }) => (v.gltf ? [...toZhc(q), ...toZhc(d)] : [...q, ...d]));
  v.zhcPoints = pts;
  fs.writeFileSync(file, pts.map((p) => p.map((x) => x.toPrecision(9)).join(' ')).join('\n') + '\n');
  const sample = (plain) => execFileSync(sampler, [v.ref, file, ...(plain ? ['--plain'] : [])]).toString().trim().split('\n')
    .map((l) => l.trim().split(/\s+/).map((x) => f32(Number(x))));
  v.expectedPlain = sample(true);
  if (v.synthetic) {
    // No .zhp holds these masks: the JS runtime's twin of zhc_volume_irradiance applies them.
    const z = v.zhpInfo;
    const vol = makeVolume({ encoding: z.encoding, params: z.params, bytes: z.payload, ...z.grid, validity: z.validity, visibility: z.visibility });
    v.expected = pts.map((p) => volumeIrradiance(vol, p.slice(0, 3), p.slice(3)));
    // Cells with i0_z = 0 (t_z < 1, clamped) have every corner masked: the plain blend, bit for bit.
    let fallback = 0, same = 0;
    pts.forEach((p, i) => {
      if ((p[2] - z.grid.origin[2]) / z.grid.spacing[2] >= 1) return;
      fallback++;
      if (v.expected[i].every((x, k) => x === v.expectedPlain[i][k])) same++;
    });
    console.log(`${v.name}: ${fallback} samples in fully masked cells, ${same} equal to the plain C header bit for bit`);
    check(fallback >= 4 && same === fallback, `${v.name}: ${same} of ${fallback} samples in fully masked cells equal the plain C header bit for bit (>= 4)`);
  } else {
    v.expected = v.dropAll ? v.expectedPlain : sample(false);
  }
  v.expectedLeak = v.dropAll ? sample(false) : v.expected;
}

// --- 1b. Node (no browser): the chunk's text, the combined mask bytes and the plane texels -----------
const throws = (fn, re) => { try { fn(); return false; } catch (e) { return re.test(e.message); } };
{
  // Masks: the demo grid with its synthetic masks (planes left out).
  const z = { ...volumes.find((x) => x.synthetic).zhpInfo, planes: null };
  for (const encoding of ['zh3_q16', 'sh3_q28', 'sh2_q', 'zh3_channel_q16'])
    for (const normalAxes of ['same', 'gltf']) {
      const plain = zhcVolumeGlsl({ encoding, params: z.params, normalAxes });
      const off = zhcVolumeGlsl({ encoding, params: z.params, normalAxes, masked: false, planes: false });
      check(plain === off && !/MASK|maskTex|PLANE|planeTex/.test(plain), `${encoding} ${normalAxes}: the plain chunk has no mask or plane code`);
      for (const [masked, planes, planesAxes] of [[true, false, 'zhc'], [false, true, 'zhc'], [false, true, 'gltf'], [true, true, 'gltf']]) {
        const on = zhcVolumeGlsl({ encoding, params: z.params, normalAxes, masked, planes, planesAxes });
        const what = `${encoding} ${normalAxes}${masked ? ' masked' : ''}${planes ? ` planes (${planesAxes})` : ''}`;
        const samplers = `${masked ? 'highp usampler3D maskTex, ' : ''}${planes ? 'highp usampler3D planeTex, ' : ''}`;
        check(on.includes('#define ZHC_VOLUME_MASKED 1') === masked && on.includes('#define ZHC_VOLUME_PLANES 1') === planes &&
          on.includes('#define ZHC_VOLUME_PLANE_AXES_GLTF 1') === (planes && planesAxes === 'gltf') &&
          on.includes(`zhcVolumeSh3(highp usampler3D tex, ${samplers}ZhcVolume v`) && on.includes(`zhcVolumeIrradiance(highp usampler3D tex, ${samplers}ZhcVolume v`),
          `${what}: the chunk defines what it applies and takes its samplers after the probe texture`);
        // The chunk is the plain one plus lines: removing the added lines gives it back.
        const a = plain.split('\n'), b = on.split('\n');
        let j = 0;
        const strip = (line) => line.replace(samplers, '').replace(`${masked ? 'maskTex, ' : ''}${planes ? 'planeTex, ' : ''}`, '');
        for (const line of b) if (j < a.length && (line === a[j] || strip(line) === a[j])) j++;
        check(j === a.length, `${what}: the chunk keeps every line of the plain one in order`);
      }
    }
  check(zhcVolumeGlsl({ encoding: 'zh3_q16', masked: true }) === zhcVolumeGlsl({ encoding: 'zh3_q16', masked: true, planes: false, planesAxes: 'gltf' }),
    'without planes, planesAxes changes nothing');
  const cm = compactVolume(z), cmOff = compactVolume(z, { masks: false });
  const cmNone = compactVolume({ ...z, validity: null, visibility: null });
  const cmFF = compactVolume({ ...z, validity: new Uint8Array(z.count).fill(1), visibility: new Uint8Array(z.count).fill(0xFF) });
  check(cm.masked === true && !cm.planed && cm.glsl.includes('ZHC_VOLUME_MASKED') && cm.maskBytes === z.count && cm.gpuBytes === 17 * z.count && cm.gpuBytesPerProbe === 17,
    `compactVolume of the masked .zhp is masked, ${cm.gpuBytes} GPU bytes (${cm.gpuBytesPerProbe} per probe)`);
  check(!cmOff.masked && cmOff.mask === null && cmOff.glsl === cmNone.glsl && cmOff.gpuBytes === 16 * z.count && cmOff.gpuBytesPerProbe === 16,
    'masks: false gives the chunk and bytes of a grid without masks');
  check(!cmFF.masked && cmFF.glsl === cmNone.glsl, 'all-valid, all-0xFF masks give the plain chunk');
  const twin = Array.from({ length: z.count }, (_, p) => (z.validity[p] === 0 ? 0 : z.visibility[p]));
  check(Array.from(cm.mask).every((m, p) => m === twin[p]), 'the combined mask bytes are valid ? visibility : 0 probe by probe');
  check(Array.from(compactVolumeMask(null, z.visibility, z.count)).every((m, p) => m === z.visibility[p]) &&
    Array.from(compactVolumeMask(z.validity, null, z.count)).every((m, p) => m === (z.validity[p] ? 0xFF : 0)) &&
    compactVolumeMask(null, null, z.count) === null, 'absent validity counts as valid, absent visibility as 0xFF');
  check(throws(() => compactVolume(z, { masks: 'no' }), /masks must be/) &&
    throws(() => compactVolume({ ...z, visibility: z.visibility.subarray(0, 5) }), /visibility has 5 bytes/) &&
    throws(() => zhcVolumeGlsl({ encoding: 'zh3_q16', masked: 'yes' }), /masked must be true or false/),
    'compactVolume refuses a non-boolean masks option and short mask bytes, zhcVolumeGlsl a non-boolean masked');

  // Planes: the hand-made grid (.zhp: zhc axes) and as a glTF-axes compact source.
  const h = volumes.find((x) => x.name === 'hand-made planes (.zhp)').zhpInfo;
  const hs = volumes.find((x) => x.source).sourceSpec;
  const cp = compactVolume(h), cpOff = compactVolume(h, { planes: false }), cpNone = compactVolume({ ...h, planes: null });
  const cpNoPlane = compactVolume({ ...h, planes: planesSection(h.grid, () => null) });
  const cg = compactVolume({ ...hs, bytes: Uint8Array.from(hs.bytes), planes: Uint8Array.from(hs.planes) });
  check(cp.planed && !cp.masked && cp.planesAxes === 'zhc' && cp.glsl.includes('#define ZHC_VOLUME_PLANES 1') && !cp.glsl.includes('#define ZHC_VOLUME_PLANE_AXES_GLTF') &&
    cp.planeBytes === 8 * h.count && cp.gpuBytes === 24 * h.count && cp.gpuBytesPerProbe === 24,
    `compactVolume of the hand-made .zhp applies its planes in zhc axes, ${cp.gpuBytes} GPU bytes (${cp.gpuBytesPerProbe} per probe)`);
  check(cg.planed && cg.planesAxes === 'gltf' && cg.normalAxes === 'gltf' && cg.glsl.includes('#define ZHC_VOLUME_PLANE_AXES_GLTF 1'),
    'a glTF-axes source (no payload) gets planesAxes gltf');
  check(compactVolume({ ...hs, bytes: Uint8Array.from(hs.bytes), planes: Uint8Array.from(hs.planes), planesAxes: 'zhc' }).planesAxes === 'zhc',
    "a source's own planesAxes is kept");
  check(!cpOff.planed && cpOff.planeData === null && cpOff.glsl === cpNone.glsl && cpOff.gpuBytes === 16 * h.count && cpOff.gpuBytesPerProbe === 16,
    'planes: false gives the chunk and bytes of a grid without planes');
  check(!cpNoPlane.planed && cpNoPlane.glsl === cpNone.glsl, 'planes whose entries are all "no plane" give the plain chunk');
  const onlyRegions = planesSection(h.grid, () => regionEntry([3, 0, 0], [1, 0, 0]));
  const cpRegions = compactVolume({ ...h, planes: onlyRegions });
  check(cpRegions.planed && cpRegions.glsl === cp.glsl && cpRegions.planeData[1] === 0x81 && cpRegions.planeData[0] === 0x80000003,
    'entries that are all corner regions (offset -32768, bit 7 set) get the planes chunk and texture');
  const wordsOk = (data, planes) => Array.from({ length: planes.length / 5 }, (_, p) =>
    data[2 * p] === ((planes[5 * p] | (planes[5 * p + 1] << 8) | (planes[5 * p + 2] << 16) | (planes[5 * p + 3] << 24)) >>> 0) &&
    data[2 * p + 1] === planes[5 * p + 4]).every((x) => x);
  check(cp.planeData.length === 2 * h.count && wordsOk(cp.planeData, h.planes), 'the plane texels are (bytes 0..3 little-endian, byte 4) probe by probe');
  check(throws(() => compactVolume(h, { planes: 'no' }), /planes must be/) &&
    throws(() => compactVolume({ ...h, planes: h.planes.subarray(0, 7) }), /planes has 7 bytes/) &&
    throws(() => compactVolume({ ...h, planesAxes: 'yzx' }), /planesAxes must be/) &&
    throws(() => zhcVolumeGlsl({ encoding: 'zh3_q16', planes: 1 }), /planes must be true or false/) &&
    throws(() => zhcVolumeGlsl({ encoding: 'zh3_q16', planes: true, planesAxes: 'same' }), /planesAxes must be/),
    'compactVolume refuses a non-boolean planes option, short planes and a bad planesAxes; zhcVolumeGlsl a non-boolean planes and a bad planesAxes');
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
// S (sum over the cell's corners) and X (the weight-error factor) of a point in zhc axes; M the sum
// of the kept weights (1 without masks and planes, or when no corner is kept: the plain weights).
// leak: the validity / visibility / planes applied (default v.leak).
function errorModel(v, pz, leak = v.leak) {
  const g = v.zhpInfo.grid, i0 = [], extra = [0];
  for (let c = 0; c < 3; c++) {
    const tt = Math.min(Math.max((pz[c] - g.origin[c]) / g.spacing[c], 0), g.counts[c] - 1);
    i0.push(Math.min(Math.floor(tt), g.counts[c] >= 2 ? g.counts[c] - 2 : 0));
    extra[0] += (Math.abs(pz[c]) + Math.abs(g.origin[c])) / g.spacing[c] + tt + 2;
  }
  const S = [0, 0, 0];
  let M = 0;
  const z = v.zhpInfo;
  const plane = leak.planes ? planeSideAt(g, leak.planes, pz) : null;
  for (let b = 0; b < 8; b++) {
    const q = [i0[0] + (b & 1), i0[1] + ((b >> 1) & 1), i0[2] + (b >> 2)];
    if (q.some((x, c) => x >= g.counts[c])) continue;
    const p = q[0] + g.counts[0] * (q[1] + g.counts[1] * q[2]);
    const s = probeScale(z, v.sh, p);
    for (let k = 0; k < 3; k++) S[k] += s[k];
    let w = 1;
    for (let c = 0; c < 3; c++) {
      const tt = Math.min(Math.max((pz[c] - g.origin[c]) / g.spacing[c], 0), g.counts[c] - 1), f = g.counts[c] >= 2 ? tt - i0[c] : 0;
      w *= (q[c] - i0[c]) ? f : 1 - f;
    }
    const keep = (!leak.validity || leak.validity[p]) && (!leak.visibility || ((leak.visibility[p] >> (7 - b)) & 1)) &&
      (!plane || ((plane.sides >> b) & 1) === plane.side);
    if (keep) M += w;
  }
  if (!(leak.validity || leak.visibility || leak.planes) || !(M > 0)) M = 1;
  return { S, X: extra[0] / M, M };
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
  const maskBytes = v.masked ? z.count : 0, planeBytes = v.planed ? 8 * z.count : 0;
  check(r.count === z.count && r.textureBytes === 16 * texels * z.count && r.gpuBytes === r.textureBytes + maskBytes + planeBytes &&
    r.maskTextureBytes === maskBytes && r.maskBytes === maskBytes && r.planeTextureBytes === planeBytes && r.planeBytes === planeBytes &&
    r.gpuBytesPerProbe === 16 * texels + (v.masked ? 1 : 0) + (v.planed ? 8 : 0),
    `${r.name}: the texture holds ${16 * texels} bytes per probe, the mask texture ${v.masked ? 1 : 0}, the plane texture ${v.planed ? 8 : 0} (${r.gpuBytes} for ${r.count} probes)`);
  const [nx, ny, nz] = v.gltf ? [z.grid.counts[1], z.grid.counts[2], z.grid.counts[0]] : z.grid.counts;
  check(r.size[0] === texels * nx && r.size[1] === ny && r.size[2] === nz, `${r.name}: texture ${r.size.join('x')} = (${texels} nx) x ny x nz`);
  check(r.masked === !!v.masked && r.glslMasked === !!v.masked, `${r.name}: masked chunk and mask texture exactly when the volume has masks and keeps them (${r.masked})`);
  check(r.planed === !!v.planed && r.glslPlaned === !!v.planed && r.glslPlaneAxesGltf === (!!v.planed && v.gltf),
    `${r.name}: the chunk applies planes exactly when the volume has planes and keeps them (${r.planed}), in glTF axes for a glTF volume (${r.glslPlaneAxesGltf})`);
  // glTF volumes: glTF probe (gx, gy, gz) is zhc probe (gz, gx, gy), and glTF bit (gx + 2 gy + 4 gz)
  // of a mask or sides byte is zhc bit (gz + 2 gx + 4 gy).
  const order = v.gltf ? gltfProbeOrder(z.grid.counts) : Array.from({ length: z.count }, (_, p) => p);
  const bitsOf = v.gltf ? gltfBits : (m) => m;
  if (v.planed) {
    check(r.planeSize[0] === nx && r.planeSize[1] === ny && r.planeSize[2] === nz, `${r.name}: plane texture ${r.planeSize.join('x')} = nx x ny x nz`);
    // glTF volumes: the entries in glTF probe order, sides bits and corner regions' fields in glTF axes.
    const e = v.gltf ? gltfPlanes(z.grid.counts, v.leak.planes) : v.leak.planes;
    const want = Array.from({ length: z.count }, (_, g) =>
      [(e[5 * g] | (e[5 * g + 1] << 8) | (e[5 * g + 2] << 16) | (e[5 * g + 3] << 24)) >>> 0, e[5 * g + 4]]).flat();
    check(r.planeData.length === want.length && r.planeData.every((x, i) => x === want[i]),
      `${r.name}: the plane texture holds (bytes 0..3, byte 4) per probe${v.gltf ? ' (glTF probe order, sides bits and region fields)' : ''}`);
  }
  if (v.masked) {
    check(r.maskSize[0] === nx && r.maskSize[1] === ny && r.maskSize[2] === nz, `${r.name}: mask texture ${r.maskSize.join('x')} = nx x ny x nz`);
    // Twin of the combined bytes from the .zhp (zhc axes), permuted for the glTF volumes.
    const { validity, visibility } = v.leak;
    const combined = (p) => (validity && !validity[p] ? 0 : visibility ? visibility[p] : 0xFF);
    const want = order.map((p) => bitsOf(combined(p)));
    check(r.mask.length === want.length && r.mask.every((m, i) => m === want[i]), `${r.name}: the mask texture holds valid ? visibility : 0 per probe${v.gltf ? ' (glTF axes and bits)' : ''}`);
  }
  check(r.normalAxes === (v.gltf ? 'gltf' : 'same'), `${r.name}: normals mapped to zhc axes only for the glTF volume (${r.normalAxes})`);
  if (v.glb) {
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
  let meanE = 0, lit = 0, moved = 0, movedMax = 0, movedRel = 0, darkZero = 0, darkPlainLit = 0, zeroOk = 0, zeros = 0;
  const leakFull = { validity: z.validity, visibility: z.visibility, planes: v.noPlanes ? null : z.planes };
  const leakAny = !!(leakFull.validity || leakFull.visibility || leakFull.planes);
  v.samples.forEach((s, i) => {
    const E = v.expected[i];
    const { S, X } = errorModel(v, v.zhcPoints[i]);
    const boundA = 48 + 3 * X;
    // The leak data's effect: the C header with them against the plain one, in the units of the
    // comparison (the bound of the volume with them: its X / M is the larger).
    if (leakAny) {
      const bound = 48 + 3 * errorModel(v, v.zhcPoints[i], leakFull).X;
      let over = false;
      for (let k = 0; k < 3; k++) {
        const d = Math.abs(v.expectedLeak[i][k] - v.expectedPlain[i][k]);
        if (d > 0) movedMax = Math.max(movedMax, d / (U * S[k]));
        if (v.expectedPlain[i][k] !== 0) movedRel = Math.max(movedRel, d / Math.abs(v.expectedPlain[i][k]));
        if (d > bound * U * S[k]) over = true;
      }
      if (over) moved++;
    }
    let worldX = 0;
    const g = v.zhpInfo.grid;
    for (let c = 0; c < 3; c++) worldX += (r.worldMax + r.translationMax) / (r.scale * g.spacing[c]);
    const boundB = boundA + 16 + 3 * 16 * worldX;
    for (let k = 0; k < 3; k++) {
      meanE += E[k] / (3 * v.samples.length);
      const add = (stat, got, bound, what) => {
        const err = Math.abs(got - E[k]), units = err === 0 ? 0 : err / (U * S[k]), rel = E[k] !== 0 ? err / Math.abs(E[k]) : err === 0 ? 0 : Infinity;
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
      if (!v.blackProbes) check(Number.isFinite(E[k]) && E[k] !== 0, `${r.name} sample ${i}: E finite and not 0`);
    }
    if (E.every((x) => x > 0)) lit++;
    // Where the C header reads 0 (the dark side) both pixels read 0, exactly.
    if (E.every((x) => x === 0)) {
      zeros++;
      if (r.shader[i].every((x) => x === 0) && r.lambert[i].every((x) => x === 0)) zeroOk++;
      else console.log(`  ${r.name} sample ${i}: C 0, ShaderMaterial ${r.shader[i]}, MeshLambertMaterial ${r.lambert[i]}`);
    }
    if (v.dark && i < DARK) {
      if (E.every((x) => x === 0)) darkZero++;
      if (v.expectedPlain[i].some((x) => x !== 0)) darkPlainLit++;
    }
  });
  if (v.dark) {
    // The dark side: 0 in the C header at every dark-region sample, where the plain blend (what
    // three.js's LightProbeGrid shows) leaks the lit side's light at half of them or more.
    console.log(`  dark side: the C header reads 0 at ${darkZero} of ${DARK} dark-region samples (the plain blend is not 0 at ${darkPlainLit})`);
    check(darkZero === DARK, `${r.name}: the C header reads 0 at every dark-region sample (${darkZero} of ${DARK})`);
    check(darkPlainLit >= DARK / 2, `${r.name}: the plain blend leaks light to ${darkPlainLit} of the ${DARK} dark-region samples (>= ${DARK / 2})`);
  }
  if (v.blackProbes) {
    console.log(`  ${zeros} samples read 0 in the C header, ${zeroOk} of them 0 in both GPU pixels`);
    check(zeroOk === zeros, `${r.name}: both GPU pixels read 0 wherever the C header does (${zeroOk} of ${zeros})`);
    check(lit >= 4, `${r.name}: ${lit} samples lit in every channel (>= 4)`);
  } else {
    // sh2_q (L1 only) rings below 0 on some back-facing normals; the others are lit everywhere.
    check(lit >= (z.encoding === 'sh2_q' ? 16 : SAMPLES), `${r.name}: ${lit} of ${SAMPLES} samples lit in every channel`);
  }
  if (leakAny) {
    if (!v.fewLeakData) check(moved >= 4, `${r.name}: the leak data move E beyond the tolerance at ${moved} of ${SAMPLES} samples (>= 4)`);
    console.log(`  the leak data move the C header's E at ${moved} of ${SAMPLES} samples beyond the bound: max ${movedMax.toExponential(3)} u S (${(movedMax * U).toExponential(2)} S), relative ${movedRel.toExponential(2)}`);
  }
  // (C) Standard: fitted pixel-per-E k and the twin comparison.
  let worstC = 0;
  for (let k = 0; k < 3; k++) {
    let pe = 0, ee = 0;
    v.samples.forEach((_, i) => { pe += r.standardProbe[i][k] * v.expected[i][k]; ee += v.expected[i][k] ** 2; });
    const kk = pe / ee;
    check(kk > 0.1 && kk < 10, `${r.name} channel ${k}: MeshStandardMaterial shows k E with k = ${kk.toPrecision(6)}`);
    v.samples.forEach((_, i) => {
      const diff = Math.abs(r.standard[i][k] - r.standardProbe[i][k]), T = r.termScale[i][k];
      if (diff > 0) worstC = Math.max(worstC, diff / (kk * T));
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
