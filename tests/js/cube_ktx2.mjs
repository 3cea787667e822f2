// KTX2 cube maps written by another program: ktx-parse (the npm KTX 2.0 parser and
// serializer that glTF-Transform uses; installed with tests/js's dependencies) writes an RGBA32F
// cube map, level 0 plus mip levels, whose texels hold an SH3 radiance function evaluated at each
// texel centre's direction. The direction comes from the Vulkan "Cube Map Face Selection" table,
// written out here a third time (independently of codec/cubemap and tests/test_cube_containers),
// with API +Y = zhc +Z ((x, y, z)_zhc = (z, x, y)_API). `zhc project FILE --json` must give the
// function's coefficients back (face 64: the texel quadrature's error is about 2e-6 of |L00|;
// threshold 1e-4), and the same file read with the faces in another order must not.
// An R8G8B8A8_SRGB cube written by ktx-parse checks the 8-bit sRGB decoding the same way.
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

// An 8-bit sRGB cube (VK_FORMAT_R8G8B8A8_SRGB) written by ktx-parse: texels hold the sRGB OETF of
// f(d) = c + g . d (per channel), rounded to 8 bits. zhc decodes them with the sRGB EOTF; its SH
// must be within sqrt(4 pi) e / |L00| + 1e-4 of f's, e the largest texel error of the bytes as
// decoded here (an SH coefficient moves by at most e times the integral of |Y_i| <= sqrt(4 pi)).
const lc = [0.45, 0.5, 0.55];
const lg = [[0.2, -0.1, 0.15], [-0.12, 0.18, 0.1], [0.1, 0.1, -0.2]];
const linearAt = (d, k) => lc[k] + lg[k][0] * d[0] + lg[k][1] * d[1] + lg[k][2] * d[2];
const oetf = (v) => (v <= 0.0031308 ? 12.92 * v : 1.055 * v ** (1 / 2.4) - 0.055);
const eotf = (v) => (v <= 0.04045 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4);
const y1 = Math.sqrt(3 / (4 * Math.PI)) * (4 * Math.PI) / 3;
const linearSh = [];
for (let i = 0; i < 9; ++i) linearSh.push([0, 0, 0]);
for (let k = 0; k < 3; ++k) {
  linearSh[0][k] = Math.sqrt(4 * Math.PI) * lc[k];
  linearSh[1][k] = -y1 * lg[k][1];
  linearSh[2][k] = y1 * lg[k][2];
  linearSh[3][k] = -y1 * lg[k][0];
}
let texelError = 0;
function makeSrgbKtx2(m) {
  const data = new Uint8Array(6 * m * m * 4);
  let o = 0;
  for (let face = 0; face < 6; ++face)
    for (let row = 0; row < m; ++row)
      for (let col = 0; col < m; ++col) {
        const r = apiDirection(face, (2 * (col + 0.5)) / m - 1, (2 * (row + 0.5)) / m - 1);
        const len = Math.hypot(r[0], r[1], r[2]);
        const d = [r[2] / len, r[0] / len, r[1] / len];
        for (let k = 0; k < 3; ++k) {
          const v = linearAt(d, k);
          const byte = Math.round(Math.min(1, Math.max(0, oetf(v))) * 255);
          texelError = Math.max(texelError, Math.abs(eotf(byte / 255) - v));
          data[o++] = byte;
        }
        data[o++] = 255;
      }
  const c = createDefaultContainer();
  c.vkFormat = 43;  // VK_FORMAT_R8G8B8A8_SRGB
  c.typeSize = 1;
  c.pixelWidth = m;
  c.pixelHeight = m;
  c.pixelDepth = 0;
  c.layerCount = 0;
  c.faceCount = 6;
  c.levelCount = 1;
  c.supercompressionScheme = 0;
  c.levels = [{ levelData: data, uncompressedByteLength: data.byteLength }];
  const dfd = c.dataFormatDescriptor[0];
  dfd.transferFunction = 2;  // KHR_DF_TRANSFER_SRGB
  dfd.bytesPlane = [4, 0, 0, 0, 0, 0, 0, 0];
  dfd.samples = [0, 1, 2, 15].map((ch, s) => ({
    bitOffset: 8 * s, bitLength: 7, channelType: ch | (ch === 15 ? 0x40 : 0), samplePosition: [0, 0, 0, 0],
    sampleLower: 0, sampleUpper: 255,
  }));
  return write(c);
}
function distanceTo(sh, ref) {
  let worst = 0;
  for (let i = 0; i < 9; ++i) for (let k = 0; k < 3; ++k) worst = Math.max(worst, Math.abs(sh[i][k] - ref[i][k]));
  return worst / Math.max(...ref[0]);
}
const srgbFile = path.join(work, 'cube_ktxparse_srgb8.ktx2');
fs.writeFileSync(srgbFile, makeSrgbKtx2(64));
const bound = (Math.sqrt(4 * Math.PI) * texelError) / Math.max(...linearSh[0]) + 1e-4;
const ds8 = distanceTo(project(srgbFile), linearSh);
console.log(`ktx-parse R8G8B8A8_SRGB cube (face 64): ${ds8.toExponential(2)} of |L00| (texel error ${texelError.toFixed(4)}, bound ${bound.toExponential(2)})`);
if (!(ds8 < bound)) {
  console.error('FAIL: the sRGB cube does not project to its function within the 8-bit bound');
  failed = true;
}
const asLinear = JSON.parse(execFileSync(zhc, ['project', srgbFile, '--json', '--ldr-encoding', 'linear'], { encoding: 'utf8' })).sh3;
const dl = distanceTo(asLinear, linearSh);
console.log(`same cube read with --ldr-encoding linear: ${dl.toExponential(2)} of |L00|`);
if (!(dl > 0.1)) {
  console.error('FAIL: --ldr-encoding linear does not change the sRGB cube');
  failed = true;
}
process.exit(failed ? 1 : 0);
