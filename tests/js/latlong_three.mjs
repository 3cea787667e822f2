// The glTF ecosystem's lat-long orientation, against a real client (CTest: js.latlong_three).
// Usage: node latlong_three.mjs ZHC_BINARY WORK_DIR CHROMIUM ENVMAP_DIR
//
// three.js (tests/js/node_modules, the pinned version) in headless Chromium (SwiftShader WebGL2)
// reads two equirectangular maps the way a glTF viewer built on it does (tests/js/browser/
// latlong_page.mjs): `axes.hdr`, written here, whose pixel holds 1 + d (R, G, B = 1 + x, 1 + y,
// 1 + z) for d its centre's direction under zhc's `gltf` convention (docs/conventions.md), and the
// real map ENVMAP_DIR/sunrise.exr (Blender's, a low sun; decoded by three's EXRLoader and
// downsampled to 128 x 64, see below). For each:
//  1. what the viewer shows: scene.background (the equirect texture, and the cube map three makes
//     of it) seen along 24 directions must be 1 + d for the axes map, with d the direction mapped
//     to zhc axes ((x, y, z)_zhc = (z, x, y)_three, glTF's mapping) — the `gltf` formula — and
//     not what the `openexr` formula says (the map turned by 90 degrees);
//  2. LightProbeGenerator.fromCubeRenderTarget (three's SH3 of its cube map of the map): its L1
//     direction per channel, in zhc axes, agrees with `zhc project --latlong gltf` within 0.5
//     degrees (measured: 0.000 on the axes map, at most 0.04 on sunrise) and is 90 +- 2 degrees
//     of azimuth away from `--latlong openexr` (the default); L00 agrees within 1%;
//  3. the cube map three made (WebGLCubeRenderTarget.fromEquirectangularTexture), written as an
//     R32G32B32A32_SFLOAT KTX2 cube with ktx-parse: `zhc project` of that cube equals
//     `zhc project --latlong gltf` of the lat-long map within 1% of L00 per coefficient (three's
//     bilinear resampling and half floats; measured 3e-4 and 5e-3) and far from `openexr`
//     (cube maps have a fixed face convention).
// Time bounded: the browser part times out after 120 s (Chromium killed).
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { createDefaultContainer, write } from 'ktx-parse';
import * as THREE from 'three';
import { EXRLoader } from 'three/examples/jsm/loaders/EXRLoader.js';
import { checker } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';

const [zhc, workArg, chromiumArg, envmapDir] = process.argv.slice(2);
if (!zhc || !workArg || !chromiumArg || !envmapDir) {
  console.error('usage: node latlong_three.mjs ZHC_BINARY WORK_DIR CHROMIUM ENVMAP_DIR');
  process.exit(2);
}
const work = path.resolve(workArg);
fs.mkdirSync(work, { recursive: true });
const here = path.dirname(fileURLToPath(import.meta.url));
const W = (f) => path.join(work, f);
const { check, finish } = checker();

// --- zhc's two lat-long conventions, written out independently of codec/sh ----------------------
// u = (col + 0.5) / W, v = (row + 0.5) / H, theta = pi v; openexr: phi = pi (1 - 2u), gltf: phi = pi (3/2 - 2u).
function latlongDir(col, row, w, h, convention) {
  const u = (col + 0.5) / w, theta = Math.PI * (row + 0.5) / h;
  const phi = Math.PI * ((convention === 'gltf' ? 1.5 : 1) - 2 * u);
  return [Math.sin(theta) * Math.cos(phi), Math.sin(theta) * Math.sin(phi), Math.cos(theta)];
}
const threeToZhc = ([x, y, z]) => [z, x, y];
const norm = (v) => { const l = Math.hypot(...v); return v.map((x) => x / l); };
const angleDeg = (a, b) => {
  const c = norm(a).reduce((s, x, i) => s + x * norm(b)[i], 0);
  return Math.acos(Math.max(-1, Math.min(1, c))) * 180 / Math.PI;
};
const azimuthDeg = (v) => Math.atan2(v[1], v[0]) * 180 / Math.PI;
const wrap = (a) => ((a % 360) + 540) % 360 - 180;

// --- 1. the axes map as a Radiance .hdr (flat RGBE scanlines, the format stb and three read) ------
const AW = 256, AH = 128;
function rgbe(r, g, b) {
  const v = Math.max(r, g, b);
  if (v < 1e-32) return [0, 0, 0, 0];
  const e = Math.floor(Math.log2(v)) + 1;  // v / 2^e in [0.5, 1)
  const s = 256 / Math.pow(2, e);
  return [Math.floor(r * s), Math.floor(g * s), Math.floor(b * s), e + 128];
}
{
  const header = Buffer.from(`#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y ${AH} +X ${AW}\n`, 'ascii');
  const px = Buffer.alloc(AW * AH * 4);
  for (let row = 0; row < AH; row++)
    for (let col = 0; col < AW; col++) {
      const d = latlongDir(col, row, AW, AH, 'gltf');
      px.set(rgbe(1 + d[0], 1 + d[1], 1 + d[2]), (row * AW + col) * 4);
    }
  fs.writeFileSync(W('axes.hdr'), Buffer.concat([header, px]));
}
// The real map, read by three's own EXR decoder (EXRLoader.parse, here under Node), box-downsampled
// 8 x 8 to 128 x 64 (weights: each row's solid angle, so the sun's flux is kept), written as .hdr:
// a cube face of 64 texels then samples it more finely than its pixels (no aliasing of the sun in
// three's cube map), and three and zhc read the very same file.
{
  const exr = new EXRLoader().setDataType(THREE.FloatType).parse(fs.readFileSync(path.join(path.resolve(envmapDir), 'sunrise.exr')).buffer);
  const { width: sw, height: sh, data } = exr;  // rows bottom to top (three's flipY = false layout), RGBA
  const f = 8, dw = sw / f, dh = sh / f;
  const header = Buffer.from(`#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y ${dh} +X ${dw}\n`, 'ascii');
  const px = Buffer.alloc(dw * dh * 4);
  for (let row = 0; row < dh; row++)
    for (let col = 0; col < dw; col++) {
      const acc = [0, 0, 0];
      let wsum = 0;
      for (let y = row * f; y < (row + 1) * f; y++) {
        const w = Math.cos(Math.PI * y / sh) - Math.cos(Math.PI * (y + 1) / sh);  // row y from the top
        const src = (sh - 1 - y) * sw;
        for (let x = col * f; x < (col + 1) * f; x++) {
          for (let k = 0; k < 3; k++) acc[k] += w * Math.max(0, data[(src + x) * 4 + k]);
          wsum += w;
        }
      }
      px.set(rgbe(acc[0] / wsum, acc[1] / wsum, acc[2] / wsum), (row * dw + col) * 4);
    }
  fs.writeFileSync(W('sunrise_128.hdr'), Buffer.concat([header, px]));
}
const maps = [
  { name: 'axes', url: '/work/axes.hdr', file: W('axes.hdr'), cube: 64 },
  { name: 'sunrise', url: '/work/sunrise_128.hdr', file: W('sunrise_128.hdr'), cube: 128 },
];
// Directions (three.js axes): a Fibonacci sphere of 24, poles excluded by construction.
const dirs = [];
for (let i = 0; i < 24; i++) {
  const y = 1 - (2 * i + 1) / 24, r = Math.sqrt(1 - y * y), phi = i * Math.PI * (3 - Math.sqrt(5));
  dirs.push([r * Math.cos(phi), y, r * Math.sin(phi)]);
}
fs.writeFileSync(W('latlong_spec.json'), JSON.stringify({ maps: maps.map(({ name, url, cube }) => ({ name, url, cube })), dirs }));

// --- 2. server + Chromium ------------------------------------------------------------------------
const roots = {
  '/three/': path.join(here, 'node_modules', 'three'),
  '/test/': path.join(here, 'browser'),
  '/work/': work,
};
const pages = await chromiumPages({ roots, work, chromium: chromiumArg, check, timeoutS: 120 });
const report = await pages.runPage('latlong.html', ['--use-angle=swiftshader'], 'latlong', 'zhc lat-long page done');
pages.close();
if (report === null) finish('lat-long');
for (const e of report.errors ?? []) console.log(`  page: ${e}`);
check((report.errors ?? []).length === 0, 'no console error, warning or exception in the page');
check(report.webgl2 === true && Array.isArray(report.maps) && report.maps.length === maps.length, 'WebGL2, every map reported');
console.log(`three.js r${report.three} in Chromium (WebGL2 ${report.webgl2})`);

// --- 3. zhc on the same files ----------------------------------------------------------------------
const project = (file, extra = []) => JSON.parse(execFileSync(zhc, ['project', file, '--json', ...extra], { encoding: 'utf8' })).sh3;
// zhc L1 of channel k as a vector (f1(d) proportional to v . d): (-f11, -f1-1, f10).
const zhcL1 = (sh, k) => [-sh[3][k], -sh[1][k], sh[2][k]];
// three's SphericalHarmonics3: Y1 = +0.488603 (y, z, x) in its order c1, c2, c3 -> v_three = (c3, c1, c2).
const threeL1 = (sh, k) => threeToZhc([sh[3][k], sh[1][k], sh[2][k]]);
const lum = (f) => [0, 1, 2].reduce((s, k) => s + [0.2126, 0.7152, 0.0722][k] * f(k), 0);
function writeKtx2(file, n, faces) {
  const c = createDefaultContainer();
  c.vkFormat = 109;  // VK_FORMAT_R32G32B32A32_SFLOAT
  c.typeSize = 4;
  c.pixelWidth = n;
  c.pixelHeight = n;
  c.pixelDepth = 0;
  c.layerCount = 0;
  c.faceCount = 6;
  c.levelCount = 1;
  c.supercompressionScheme = 0;
  // readRenderTargetPixels returns rows in texture-t order (t = 0 first): KTX2's row order.
  const levelData = new Uint8Array(new Float32Array(faces.flat()).buffer);
  c.levels = [{ levelData, uncompressedByteLength: levelData.byteLength }];
  const dfd = c.dataFormatDescriptor[0];
  dfd.transferFunction = 1;
  dfd.bytesPlane = [16, 0, 0, 0, 0, 0, 0, 0];
  dfd.samples = [0, 1, 2, 15].map((ch, s) => ({
    bitOffset: 32 * s, bitLength: 31, channelType: ch | 0x80 | 0x40, samplePosition: [0, 0, 0, 0],
    sampleLower: 0xbf800000, sampleUpper: 0x3f800000,
  }));
  fs.writeFileSync(file, write(c));
}

// three's HDRLoader decodes RGBE as m 2^(e-128) / 255, zhc (like stb_image and Walter's rgbe.c)
// as m 2^(e-128) / 256: three's values are scaled by 255/256 before magnitudes are compared.
const kRgbe = 255 / 256;
for (const m of maps) {
  const r = report.maps.find((x) => x.name === m.name);
  if (!r) continue;
  r.sh = r.sh.map((c) => c.map((x) => x * kRgbe));
  r.faces = r.faces.map((f) => f.map((x) => x * kRgbe));
  for (const bg of Object.keys(r.backgrounds)) r.backgrounds[bg] = r.backgrounds[bg].map((c) => c.map((x) => x * kRgbe));
  const gltf = project(m.file, ['--latlong', 'gltf']);
  const openexr = project(m.file);
  const openexrExplicit = project(m.file, ['--latlong', 'openexr']);
  check(JSON.stringify(openexr) === JSON.stringify(openexrExplicit), `${m.name}: --latlong openexr is the default`);
  // (2) three's SH direction against zhc's, per channel and for luminance.
  const rows = [0, 1, 2].map((k) => ({ what: 'RGB'[k], three: threeL1(r.sh, k), gltf: zhcL1(gltf, k), openexr: zhcL1(openexr, k) }));
  rows.push({ what: 'lum', three: [0, 1, 2].map((i) => lum((k) => threeL1(r.sh, k)[i])),
    gltf: [0, 1, 2].map((i) => lum((k) => zhcL1(gltf, k)[i])), openexr: [0, 1, 2].map((i) => lum((k) => zhcL1(openexr, k)[i])) });
  for (const row of rows) {
    const aG = angleDeg(row.three, row.gltf), aO = angleDeg(row.three, row.openexr);
    const dAz = wrap(azimuthDeg(row.openexr) - azimuthDeg(row.three));
    const horizontal = Math.hypot(row.three[0], row.three[1]) > 0.3 * Math.hypot(...row.three);
    console.log(`${m.name} ${row.what}: three.js LightProbeGenerator L1 direction vs zhc --latlong gltf ${aG.toFixed(3)} deg; ` +
      `vs --latlong openexr ${aO.toFixed(2)} deg (azimuth openexr - three ${dAz.toFixed(2)} deg)`);
    check(aG < 0.5, `${m.name} ${row.what}: three.js and zhc --latlong gltf agree in direction within 0.5 degrees`);
    if (horizontal) check(Math.abs(Math.abs(dAz) - 90) < 2, `${m.name} ${row.what}: --latlong openexr is 90 degrees of azimuth from three.js`);
  }
  // Magnitudes: three's basis has zhc's normalisation (orthonormal), so L00 agrees too.
  const dc = Math.max(...[0, 1, 2].map((k) => Math.abs(r.sh[0][k] - gltf[0][k]) / gltf[0][k]));
  console.log(`${m.name}: L00 three.js vs zhc relative difference ${dc.toExponential(2)}`);
  check(dc < 0.01, `${m.name}: three.js's L00 within 1% of zhc's`);
  // (1) what the viewer shows, for the axes map: 1 + d along d.
  if (m.name === 'axes') {
    for (const [bg, samples] of Object.entries(r.backgrounds)) {
      let worstGltf = 0, bestOpenexr = Infinity;
      dirs.forEach((d3, i) => {
        const d = threeToZhc(norm(d3));
        const seen = samples[i];
        // openexr: the file's pixel that zhc puts at d is the gltf pixel turned by -90 degrees about +Z,
        // which holds 1 + Rz(90) d = 1 + (-d_y, d_x, d_z).
        const turned = [-d[1], d[0], d[2]];
        worstGltf = Math.max(worstGltf, ...[0, 1, 2].map((k) => Math.abs(seen[k] - (1 + d[k]))));
        const err = Math.max(...[0, 1, 2].map((k) => Math.abs(seen[k] - (1 + turned[k]))));
        if (Math.hypot(d[0], d[1]) > 0.5) bestOpenexr = Math.min(bestOpenexr, err);
      });
      console.log(`axes map as three.js ${bg} background, ${dirs.length} directions: worst |seen - (1 + d)| under gltf ` +
        `${worstGltf.toExponential(2)}; under openexr every direction off the poles is off by at least ${bestOpenexr.toFixed(3)}`);
      check(worstGltf < 0.03, `axes ${bg} background: three.js shows what the gltf formula says`);
      check(bestOpenexr > 0.2, `axes ${bg} background: the openexr formula is far off (the check above can fail)`);
    }
  }
  // (3) three's cube map as a KTX2 cube: zhc projects it like the lat-long under gltf.
  const ktx = W(`${m.name}_three_cube.ktx2`);
  writeKtx2(ktx, r.cube, r.faces);
  const cube = project(ktx);
  let dG = 0, dO = 0;
  for (let i = 0; i < 9; i++)
    for (let k = 0; k < 3; k++) {
      dG = Math.max(dG, Math.abs(cube[i][k] - gltf[i][k]) / gltf[0][k]);
      dO = Math.max(dO, Math.abs(cube[i][k] - openexr[i][k]) / openexr[0][k]);
    }
  console.log(`${m.name}: three.js cube map (${r.cube}^2 x 6, half float) as KTX2, zhc project vs lat-long --latlong gltf: ` +
    `worst ${dG.toExponential(2)} of L00; vs openexr ${dO.toExponential(2)}`);
  check(dG < 0.01, `${m.name}: the cube three.js made projects like the lat-long under gltf`);
  check(dO > 10 * dG, `${m.name}: and not like the lat-long under openexr`);
}
finish('lat-long');
