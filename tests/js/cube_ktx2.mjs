// KTX2 cube maps written by another program: ktx-parse (the npm KTX 2.0 parser and
// serializer that glTF-Transform uses; installed with tests/js's dependencies) writes an RGBA32F
// cube map, level 0 plus mip levels, whose texels hold an SH3 radiance function evaluated at each
// texel centre's direction. The direction comes from the Vulkan "Cube Map Face Selection" table,
// written out here a third time (independently of codec/cubemap and tests/test_cube_containers),
// with API +Y = zhc +Z ((x, y, z)_zhc = (z, x, y)_API). `zhc project FILE --json` must give the
// function's coefficients back (face 64: the texel quadrature's error is about 2e-6 of |L00|;
// threshold 1e-4), and the same file read with the faces in another order must not.
// Usage: node cube_ktx2.mjs ZHC WORKDIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { createDefaultContainer, write, read } from 'ktx-parse';

const [zhc, work] = process.argv.slice(2);
if (!zhc || !work) {
  console.error('usage: node cube_ktx2.mjs ZHC WORKDIR');
  process.exit(2);
}
fs.mkdirSync(work, { recursive: true });

// zhc's SH3 basis (codec/sh/sh.h): order 00, 1-1, 10, 11, 2-2, 2-1, 20, 21, 22.
const Y00 = 1 / (2 * Math.sqrt(Math.PI)), Y1 = Math.sqrt(3 / (4 * Math.PI)), Y2 = Math.sqrt(15 / (4 * Math.PI));
const Y20 = Math.sqrt(5 / (16 * Math.PI)), Y22 = Math.sqrt(15 / (16 * Math.PI));
const basis = ([x, y, z]) => [Y00, -Y1 * y, Y1 * z, -Y1 * x, Y2 * x * y, -Y2 * y * z, Y20 * (3 * z * z - 1), -Y2 * x * z,
  Y22 * (x * x - y * y)];

// Coefficients: positive radiance everywhere (L00 dominant), every coefficient non-zero.
const coeffs = [];
for (let i = 0; i < 9; ++i) coeffs.push([0, 1, 2].map((k) => (i === 0 ? 8 + 2 * k : 0.05 + 0.03 * ((i * 3 + k) % 7) - 0.1 * ((i + k) % 2))));

// Vulkan table solved for the direction (|ma| = 1): face, sc, tc -> r (API frame).
function apiDirection(face, sc, tc) {
  switch (face) {
    case 0: return [1, -tc, -sc];
    case 1: return [-1, -tc, sc];
    case 2: return [sc, 1, tc];
    case 3: return [sc, -1, -tc];
    case 4: return [sc, -tc, 1];
    default: return [-sc, -tc, -1];
  }
}

function renderLevel(n, scale, faceOrder) {
  const data = new Float32Array(6 * n * n * 4);
  let o = 0;
  for (const face of faceOrder)
    for (let row = 0; row < n; ++row)
      for (let col = 0; col < n; ++col) {
        const r = apiDirection(face, (2 * (col + 0.5)) / n - 1, (2 * (row + 0.5)) / n - 1);
        const len = Math.hypot(r[0], r[1], r[2]);
        const d = [r[2] / len, r[0] / len, r[1] / len];  // zhc = (z, x, y)_API
        const b = basis(d);
        for (let k = 0; k < 3; ++k) {
          let v = 0;
          for (let i = 0; i < 9; ++i) v += coeffs[i][k] * b[i];
          data[o++] = v * scale;
        }
        data[o++] = 1;
      }
  return new Uint8Array(data.buffer);
}

function makeKtx2(n, levels, faceOrder) {
  const c = createDefaultContainer();
  c.vkFormat = 109;  // VK_FORMAT_R32G32B32A32_SFLOAT
  c.typeSize = 4;
  c.pixelWidth = n;
  c.pixelHeight = n;
  c.pixelDepth = 0;
  c.layerCount = 0;
  c.faceCount = 6;
  c.levelCount = levels;
  c.supercompressionScheme = 0;
  c.levels = [];
  for (let l = 0; l < levels; ++l) {
    const levelData = renderLevel(Math.max(1, n >> l), 1 / (l + 1), faceOrder);  // lower levels differ
    c.levels.push({ levelData, uncompressedByteLength: levelData.byteLength });
  }
  // Data format descriptor: linear RGBA, four 32-bit signed float samples.
  const dfd = c.dataFormatDescriptor[0];
  dfd.transferFunction = 1;
  dfd.bytesPlane = [16, 0, 0, 0, 0, 0, 0, 0];
  dfd.samples = [0, 1, 2, 15].map((ch, s) => ({
    bitOffset: 32 * s, bitLength: 31, channelType: ch | 0x80 | 0x40, samplePosition: [0, 0, 0, 0],
    sampleLower: 0xbf800000, sampleUpper: 0x3f800000,
  }));
  return write(c);
}

function project(file) {
  const out = execFileSync(zhc, ['project', file, '--json'], { encoding: 'utf8' });
  return JSON.parse(out).sh3;
}

function distance(sh) {
  let worst = 0;
  for (let i = 0; i < 9; ++i) for (let k = 0; k < 3; ++k) worst = Math.max(worst, Math.abs(sh[i][k] - coeffs[i][k]));
  return worst / Math.max(...coeffs[0]);
}

let failed = false;
const n = 64;
const good = path.join(work, 'cube_ktxparse.ktx2');
fs.writeFileSync(good, makeKtx2(n, 7, [0, 1, 2, 3, 4, 5]));
const parsed = read(fs.readFileSync(good));  // ktx-parse reads its own file back as a cube
if (parsed.faceCount !== 6 || parsed.levels.length !== 7) {
  console.error('FAIL: ktx-parse did not write a 6-face, 7-level KTX2');
  failed = true;
}
const d = distance(project(good));
console.log(`ktx-parse RGBA32F cube (face ${n}, 7 levels): zhc project is ${d.toExponential(2)} of |L00| from the function`);
if (!(d < 1e-4)) {
  console.error('FAIL: projection of the ktx-parse cube differs from the function');
  failed = true;
}
// The faces in another order (+Y and +Z swapped, -X and -Z swapped): far off, so the check above can fail.
const swapped = path.join(work, 'cube_ktxparse_swapped.ktx2');
fs.writeFileSync(swapped, makeKtx2(n, 1, [0, 5, 4, 3, 2, 1]));
const ds = distance(project(swapped));
console.log(`same cube with faces swapped: ${ds.toExponential(2)} of |L00|`);
if (!(ds > 0.01)) {
  console.error('FAIL: a face-swapped cube projects like the right one');
  failed = true;
}
process.exit(failed ? 1 : 0);
