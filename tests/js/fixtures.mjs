// Shared inputs of the runtime/web tests: a minimal GLB scene and deterministic probe lists; the
// repository root and a test's emptied work folder.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');

// The absolute work folder `dir`, emptied (removed and made again).
export function freshWork(dir) {
  const work = path.resolve(dir);
  fs.rmSync(work, { recursive: true, force: true });
  fs.mkdirSync(work, { recursive: true });
  return work;
}
export function glb(jsonObj, bin) {
  let jsonBytes = Buffer.from(JSON.stringify(jsonObj));
  jsonBytes = Buffer.concat([jsonBytes, Buffer.alloc((4 - (jsonBytes.length % 4)) % 4, 0x20)]);
  const binPadded = Buffer.concat([bin, Buffer.alloc((4 - (bin.length % 4)) % 4)]);
  const header = Buffer.alloc(12);
  header.writeUInt32LE(0x46546c67, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + jsonBytes.length + 8 + binPadded.length, 8);
  const c0 = Buffer.alloc(8);
  c0.writeUInt32LE(jsonBytes.length, 0);
  c0.writeUInt32LE(0x4e4f534a, 4);
  const c1 = Buffer.alloc(8);
  c1.writeUInt32LE(binPadded.length, 0);
  c1.writeUInt32LE(0x004e4942, 4);
  return Buffer.concat([header, c0, jsonBytes, c1, binPadded]);
}

// One triangle with a material: the glTF JSON and its binary chunk.
export function triangleSceneParts() {
  const tri = Buffer.from(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]).buffer);
  const scene = {
    asset: { version: '2.0', generator: 'zhc tests/js' },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0, name: 'tri' }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 }, material: 0 }] }],
    materials: [{ name: 'red', pbrMetallicRoughness: { baseColorFactor: [0.8, 0.1, 0.1, 1] } }],
    buffers: [{ byteLength: tri.length }],
    bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: tri.length, target: 34962 }],
    accessors: [{ bufferView: 0, componentType: 5126, count: 3, type: 'VEC3', min: [0, 0, 0], max: [1, 1, 0] }],
  };
  return { json: scene, bin: tri };
}

// The same as a GLB.
export function triangleScene() {
  const { json, bin } = triangleSceneParts();
  return glb(json, bin);
}

// Deterministic LCG in [0, 1).
export function makeRand(seed) {
  let s = seed >>> 0;
  return () => ((s = (Math.imul(s, 1664525) + 1013904223) >>> 0) / 4294967296);
}

// zhc's SH3 basis (docs/conventions.md) at unit (x, y, z).
function basis(x, y, z) {
  const pi = Math.PI, y1 = Math.sqrt(3 / (4 * pi)), y2 = Math.sqrt(15 / (4 * pi));
  return [1 / (2 * Math.sqrt(pi)), -y1 * y, y1 * z, -y1 * x, y2 * x * y, -y2 * y * z,
    Math.sqrt(5 / (16 * pi)) * (3 * z * z - 1), -y2 * x * z, Math.sqrt(15 / (16 * pi)) * (x * x - y * y)];
}
function randomDir(rand) {
  const z = 2 * rand() - 1, phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - z * z));
  return [r * Math.cos(phi), r * Math.sin(phi), z];
}

// A mix of probes: mostly projections of non-negative lighting (ambient + a few coloured delta
// lights of random strength, as bakes produce), some with arbitrary coefficients (ratios outside
// the bounds: clamped by the quantiser) and special cases (black, tiny / huge DC, zero L1,
// one dark channel, one negative DC channel).
export function randomProbes(count, seed) {
  const rand = makeRand(seed);
  const probes = [];
  for (let p = 0; p < count; p++) {
    const sh = Array.from({ length: 9 }, () => [0, 0, 0]);
    const kind = p % 10;
    if (p < 7) {
      const dc = [[0, 0, 0], [1e-6, 2e-6, 5e-7], [3e3, 2e3, 4e3], [1, 1, 1], [0.5, 0, 0.2], [2, 1.5, 1], [-0.4, 1, 0.3]][p];
      for (let k = 0; k < 3; k++) sh[0][k] = dc[k];
      if (p >= 4) for (let i = 1; i < 9; i++) for (let k = 0; k < 3; k++) sh[i][k] = 0.3 * (rand() - 0.5) * (sh[0][k] + 0.1);
    } else if (kind < 8) {
      const amb = 0.05 + rand();
      for (let k = 0; k < 3; k++) sh[0][k] = 2 * Math.sqrt(Math.PI) * amb * (0.5 + rand());
      const lights = 1 + Math.floor(rand() * 3);
      for (let l = 0; l < lights; l++) {
        const d = randomDir(rand), b = basis(...d), strength = Math.exp(4 * rand() - 1);
        const col = [rand(), rand(), rand()];
        for (let i = 0; i < 9; i++) for (let k = 0; k < 3; k++) sh[i][k] += strength * col[k] * b[i];
      }
    } else {
      for (let k = 0; k < 3; k++) sh[0][k] = 0.1 + 5 * rand();
      for (let i = 1; i < 9; i++) for (let k = 0; k < 3; k++) sh[i][k] = (rand() - 0.5) * 2.5 * sh[0][k];
    }
    probes.push(sh);
  }
  return probes;
}

// The checks of one test script: check(ok, what) prints "FAIL: what" and counts; finish(what)
// prints the summary and exits 0 only when every check passed.
export function checker() {
  let failures = 0;
  const check = (ok, what) => {
    if (!ok) {
      failures++;
      console.log(`FAIL: ${what}`);
    }
  };
  const finish = (what) => {
    console.log(failures === 0 ? `all ${what} checks passed` : `${failures} ${what} checks FAILED`);
    process.exit(failures === 0 ? 0 : 1);
  };
  return { check, finish };
}

// Distance in units in the last place between two float32 values, on the ordered integer line
// (+0 and -0 are 0 apart, a value and its neighbour across zero 1 apart).
export function ulpDiff(a, b) {
  const buf = new DataView(new ArrayBuffer(8));
  buf.setFloat32(0, a, true);
  buf.setFloat32(4, b, true);
  const ia = buf.getInt32(0, true), ib = buf.getInt32(4, true);
  return Math.abs((ia < 0 ? 0x80000000 - ia : ia) - (ib < 0 ? 0x80000000 - ib : ib));
}

// An uncompressed .zhp (Uint8Array; version 1, or version 2 whose sections are replaced) rewritten
// as version 2 with validity and/or visibility sections (Uint8Array of count bytes each, or null):
// docs/zhp-container.md "Per-probe sections". `crc32`: runtime/web's (bytes, start, end).
export function zhpWithSections(bytes, validity, visibility, crc32) {
  if (bytes[8] === 2) {  // drop the sections it has (they follow the payload)
    const hv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const count = Number(hv.getBigUint64(56, true));
    const had = (bytes[21] & 1) + ((bytes[21] >> 1) & 1);
    bytes = bytes.slice(0, 184 + Number(hv.getBigUint64(160, true)) - had * count);
  }
  const extra = (validity ? validity.length : 0) + (visibility ? visibility.length : 0);
  const out = new Uint8Array(bytes.length + extra);
  out.set(bytes);
  if (validity) out.set(validity, bytes.length);
  if (visibility) out.set(visibility, bytes.length + (validity ? validity.length : 0));
  const dv = new DataView(out.buffer);
  dv.setUint16(8, 2, true);
  out[21] = (validity ? 1 : 0) | (visibility ? 2 : 0);
  const body = BigInt(out.length - 184);
  dv.setBigUint64(160, body, true);
  dv.setBigUint64(168, body, true);
  dv.setUint32(176, crc32(out, 184, out.length), true);
  dv.setUint32(180, crc32(out, 0, 180), true);
  return out;
}
