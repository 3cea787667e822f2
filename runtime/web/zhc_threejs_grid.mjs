// three.js LightProbeGrid from the files `zhc convert --engine threejs_grid_exr | threejs_grid_ktx2`
// writes (docs/engine-files.md "three.js"), loaded with three.js's own EXRLoader or KTX2Loader: no
// zhc decoder involved. The files hold three.js r187's atlas (examples/jsm/lighting/
// LightProbeGridWebGL.js, LightProbeGrid.js: nx x ny x 7 (nz + 2) RGBA texels, one padding slice at
// each end of the 7 sub-volumes) and the grid's bounds as JSON text: "zhc.volume" {origin, spacing,
// counts} and "threejs.LightProbeGrid" {position, size, resolution, boundingBox}, in three.js's axes
// (OpenEXR string attributes, KTX2 key/value entries). three.js r187 has no JSON form for the
// grid; these keys are zhc's.
//
//   const loader = new EXRLoader().setDataType(THREE.FloatType);
//   loader.load('grid.exr', (texture, texData) => {
//     scene.add(lightProbeGridFromTexture(LightProbeGridWebGL, texture, gridBoundsFromExrHeader(texData.header)));
//   });
//
//   const bytes = await (await fetch('grid.ktx2')).arrayBuffer();
//   const ktx2 = new KTX2Loader().detectSupport(renderer);
//   const texture = await new Promise((resolve, reject) => ktx2.parse(bytes, resolve, reject));  // a Data3DTexture
//   scene.add(lightProbeGridFromTexture(LightProbeGridWebGL, texture, gridBoundsFromKtx2(bytes)));
//
// The grid is placed as ZhcProbeVolume.lightProbeGrid (zhc_light_probes_plugin.mjs) places it:
// new GridClass(size..., resolution...), position = the volume's centre, updateBoundingBox(), and
// the atlas as a Data3DTexture (LinearFilter, no mipmaps).
import * as THREE from 'three';

export const ZHC_VOLUME_KEY = 'zhc.volume';
export const THREEJS_GRID_KEY = 'threejs.LightProbeGrid';

const parseJson = (text, key) => {
  if (typeof text === 'object' && text !== null) return text;
  if (typeof text !== 'string') throw new Error(`zhc: the grid file has no "${key}" entry (the grid's bounds)`);
  try {
    return JSON.parse(text);
  } catch (e) {
    throw new Error(`zhc: "${key}" is not JSON (${e.message})`);
  }
};

// The bounds from EXRLoader's texData.header (the second argument of its onLoad).
export function gridBoundsFromExrHeader(header) {
  if (!header || typeof header !== 'object') throw new TypeError('zhc: gridBoundsFromExrHeader needs EXRLoader\'s texData.header');
  return { volume: parseJson(header[ZHC_VOLUME_KEY], ZHC_VOLUME_KEY), grid: parseJson(header[THREEJS_GRID_KEY], THREEJS_GRID_KEY) };
}

// The bounds from a KTX2 file's key/value data (KTX 2.0 section 3.11: uint32 keyAndValueByteLength,
// key, NUL, value, padding to 4 bytes). `bytes`: ArrayBuffer or Uint8Array of the whole file.
export function gridBoundsFromKtx2(bytes) {
  const b = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
  const magic = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
  if (b.length < 80 || magic.some((m, i) => b[i] !== m)) throw new Error('zhc: not a KTX2 file');
  const view = new DataView(b.buffer, b.byteOffset, b.byteLength);
  const kvdOffset = view.getUint32(56, true), kvdLength = view.getUint32(60, true);
  if (kvdOffset + kvdLength > b.length) throw new Error('zhc: KTX2 key/value data past the end of the file');
  const entries = {};
  const decoder = new TextDecoder();
  for (let p = kvdOffset; p + 4 <= kvdOffset + kvdLength;) {
    const len = view.getUint32(p, true);
    const start = p + 4;
    if (start + len > kvdOffset + kvdLength) throw new Error('zhc: KTX2 key/value entry past its section');
    const entry = b.subarray(start, start + len);
    const nul = entry.indexOf(0);
    if (nul < 0) throw new Error('zhc: KTX2 key without its NUL');
    let value = entry.subarray(nul + 1);
    if (value.length && value[value.length - 1] === 0) value = value.subarray(0, value.length - 1);
    entries[decoder.decode(entry.subarray(0, nul))] = decoder.decode(value);
    p = start + Math.ceil(len / 4) * 4;
  }
  return { volume: parseJson(entries[ZHC_VOLUME_KEY], ZHC_VOLUME_KEY), grid: parseJson(entries[THREEJS_GRID_KEY], THREEJS_GRID_KEY) };
}

const vec3 = (v, what) => {
  if (!Array.isArray(v) || v.length !== 3 || !v.every(Number.isFinite)) throw new Error(`zhc: ${what} must be 3 finite numbers`);
  return v;
};

// A ready LightProbeGridWebGL / LightProbeGrid (GridClass: three.js's class) from the loaded
// texture: EXRLoader's DataTexture (the atlas's slices stacked, FloatType or HalfFloatType) or
// KTX2Loader's Data3DTexture (RGBA16F). bounds: {volume, grid} from gridBoundsFromExrHeader /
// gridBoundsFromKtx2. The WebGPU LightProbeGrid gets a binary16 atlas (rgba32float is not
// filterable in WebGPU without "float32-filterable"): a float texture is rounded to binary16 for it.
export function lightProbeGridFromTexture(GridClass, texture, bounds, { name } = {}) {
  if (typeof GridClass !== 'function') throw new TypeError('zhc: lightProbeGridFromTexture needs three.js\'s LightProbeGridWebGL or LightProbeGrid class');
  if (!texture || !texture.image || !texture.image.data) throw new TypeError('zhc: lightProbeGridFromTexture needs a loaded DataTexture or Data3DTexture');
  if (!bounds || !bounds.grid || !bounds.volume) throw new TypeError('zhc: lightProbeGridFromTexture needs the bounds {volume, grid}');
  const g = bounds.grid;
  const position = vec3(g.position, 'threejs.LightProbeGrid position');
  const size = vec3(g.size, 'threejs.LightProbeGrid size');
  const res = g.resolution;
  if (!Array.isArray(res) || res.length !== 3 || !res.every((n) => Number.isInteger(n) && n >= 1)) throw new Error('zhc: threejs.LightProbeGrid resolution must be 3 integers >= 1');
  if (!size.every((s) => s > 0)) throw new Error('zhc: threejs.LightProbeGrid size must be > 0');
  const counts = bounds.volume.counts;
  if (!Array.isArray(counts) || counts.some((n, c) => n !== res[c])) throw new Error('zhc: zhc.volume counts differ from threejs.LightProbeGrid resolution');
  const [nx, ny, nz] = res, padded = nz + 2, depth = 7 * padded;
  const img = texture.image;
  const rows = texture.isData3DTexture ? img.height * img.depth : img.height;
  if (img.width !== nx || rows !== ny * depth)
    throw new Error(`zhc: the texture is ${img.width} x ${rows} texel rows; a ${nx} x ${ny} x ${nz} grid's atlas is ${nx} x ${ny * depth} (${nx} x ${ny} x ${depth})`);
  if (texture.format !== undefined && texture.format !== THREE.RGBAFormat) throw new Error('zhc: the atlas must be RGBA');
  let type = texture.type, data = img.data;
  if (type === THREE.FloatType ? !(data instanceof Float32Array) : type === THREE.HalfFloatType ? !(data instanceof Uint16Array) : true)
    throw new Error('zhc: the atlas must be FloatType (Float32Array) or HalfFloatType (Uint16Array)');
  if (data.length !== nx * ny * depth * 4) throw new Error('zhc: the atlas data has the wrong length');
  // three.js's padding slices copy the edge slices of each sub-volume.
  const slice = nx * ny * 4;
  for (let t = 0; t < 7; t++)
    for (const [pad, edge] of [[t * padded, t * padded + 1], [t * padded + nz + 1, t * padded + nz]])
      for (let i = 0; i < slice; i++)
        if (!Object.is(data[pad * slice + i], data[edge * slice + i])) throw new Error(`zhc: not a three.js LightProbeGrid atlas (padding slice ${pad} differs from slice ${edge})`);
  const grid = new GridClass(size[0], size[1], size[2], nx, ny, nz);
  if (grid.isLightProbeGrid !== true) throw new TypeError('zhc: lightProbeGridFromTexture needs three.js\'s LightProbeGridWebGL or LightProbeGrid class');
  if (grid.type !== 'LightProbeGridWebGL' && type === THREE.FloatType) {
    const half = new Uint16Array(data.length);
    for (let i = 0; i < data.length; i++) half[i] = THREE.DataUtils.toHalfFloat(data[i]);
    data = half;
    type = THREE.HalfFloatType;
  }
  grid.name = name ?? 'zhc (LightProbeGrid)';
  grid.position.fromArray(position);
  grid.updateMatrixWorld();
  grid.updateBoundingBox();
  const tex = new THREE.Data3DTexture(data, nx, ny, depth);
  tex.format = THREE.RGBAFormat;
  tex.type = type;
  tex.minFilter = THREE.LinearFilter;
  tex.magFilter = THREE.LinearFilter;
  tex.generateMipmaps = false;
  tex.unpackAlignment = 1;
  tex.needsUpdate = true;
  grid.texture = tex;
  return grid;
}
