// A three.js GLTFLoader plugin for ZHC_light_probes (docs/gltf-extension.md).
//
//   import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
//   import { ZhcLightProbesPlugin } from './zhc_light_probes_plugin.mjs';
//   const loader = new GLTFLoader();
//   loader.register((parser) => new ZhcLightProbesPlugin(parser));
//   const gltf = await loader.loadAsync('lit.glb');
//   const volume = gltf.userData.zhcLightProbes[0];        // a ZhcProbeVolume
//   volume.irradiance(7, [0, 1, 0]);                        // RGB, glTF / three.js axes
//   scene.add(volume.lightProbe(7));                        // THREE.LightProbe for probe 7
//   volume.irradianceAt([1, 2, 3], [0, 1, 0]);              // anywhere: a grid, or points with tetrahedra
//   volume.threeSHAt(objectPosition, objectProbe.sh);       // per object: a LightProbe's SH at its position
//
// Every volume is decoded at load by zhc_runtime.mjs into SH3 radiance (bit exact with zhc's own
// decoder). Nodes that reference a volume get a child Object3D named "ZHC_light_probes" with
// userData.zhcLightProbeVolume (the index) and userData.zhcLightProbes (the ZhcProbeVolume), listed
// in the volume's `nodes`; three.js
// may use it as the node object itself when the node has nothing else. Positions and SH are in that
// node's local space: for world space, transform positions by anchor.matrixWorld and rotate
// world directions by the inverse of the anchor's world rotation before a lookup.
import * as THREE from 'three';
import {
  PACKED_LAYOUTS, checkTetrahedra, decodeAll, encodingInfo, encodingName, gltfToZhcDir, irradiance as shIrradiance, makeParams, normalizeOr,
  makePointsVolume, makeVolume, rotateZhcToGltf, toThreeConvention, volumeIrradiance, volumeSH3, volumeTetraWeights,
} from './zhc_runtime.mjs';
import { compactVolume } from './zhc_volume.glsl.mjs';

export const EXTENSION = 'ZHC_light_probes';

// One decoded volume.
export class ZhcProbeVolume {
  constructor(desc) {
    Object.assign(this, desc);
  }

  // SH3 radiance of probe p (Float32Array(27), index i*3+k) in the STORED axes (`shAxes`): the
  // values zhc's decoder gives, bit for bit. A view into this.sh.
  probeSH(p) {
    this.#check(p);
    return this.sh.subarray(p * 27, p * 27 + 27);
  }

  // SH3 radiance of probe p in glTF axes (= three.js axes), zhc's basis and signs. For shAxes
  // "zhc" this is a rotation (exact except Y20/Y22, see zhc_runtime.mjs).
  probeSHGltf(p) {
    const sh = this.probeSH(p);
    return this.shAxes === 'zhc' ? rotateZhcToGltf(sh) : new Float32Array(sh);
  }

  // Irradiance (normalised kernel: constant radiance 1 gives 1; multiply by albedo for the diffuse
  // exit radiance) of probe p at direction `dir` given in glTF / three.js axes (node-local). The
  // direction is normalised as zhc does (zero -> +Y). For shAxes "zhc" the result is bit exact with
  // `zhc gltf eval FILE --probe p --dir x,y,z`.
  irradiance(p, dir) {
    const d = normalizeOr([dir[0], dir[1], dir[2]], [0, 1, 0]);
    return shIrradiance(this.probeSH(p), this.shAxes === 'zhc' ? gltfToZhcDir(d) : d);
  }

  // Irradiance at any point of the volume, evaluated at `normal`; position and normal in glTF /
  // three.js axes, node-local. The normal is normalised (zero: +Y).
  //  * GRID: the trilinear blend of the 8 surrounding probes' decoded SH3 (the point clamped to the
  //    grid's box; docs/runtime.md "Probe volumes"). With validity / visibility accessors the weights
  //    are masked and renormalised (docs/runtime.md "Validity and visibility"); with cell planes
  //    (`planes`) a corner on the other side of its cell's plane (or corner region) from the
  //    position is dropped too (docs/gltf-extension.md "Cell planes").
  //  * POINTS with tetrahedra (docs/gltf-extension.md "Tetrahedra"): the barycentric blend of the 4
  //    probes of the tetrahedron holding the point (outside the hull: the nearest hull face), valid
  //    probes only (zhc_runtime.mjs volumeTetraWeights, walked from tetrahedron 0). The walk runs
  //    in zhc's axes (positions permuted back, exact), so the weights are the C header's
  //    (zhc_volume_irradiance on the .zhp) to the bit.
  // Throws for layout none, points without tetrahedra, and a grid whose spacing is not > 0.
  irradianceAt(position, normal) {
    const vol = this.#sampler('irradianceAt');
    const d = normalizeOr([normal[0], normal[1], normal[2]], [0, 1, 0]);
    return volumeIrradiance(vol, this.#samplePoint(position), this.shAxes === 'zhc' ? gltfToZhcDir(d) : d);
  }

  // The blended SH3 radiance at `position` (glTF axes, node-local) in glTF axes and zhc's basis
  // (Float32Array(27), index i*3+k): the weights of irradianceAt applied to the decoded probes
  // (in doubles), then rotated from the stored axes (exact except Y20/Y22, as probeSHGltf).
  shAt(position) {
    const sh = volumeSH3(this.#sampler('shAt'), this.#samplePoint(position));
    return this.shAxes === 'zhc' ? rotateZhcToGltf(sh) : Float32Array.from(sh);
  }

  // shAt(position) as a THREE.SphericalHarmonics3 in three.js's convention (as threeSH): what a
  // THREE.LightProbe lighting an object at `position` holds, e.g. per object each frame
  //   volume.threeSHAt(mesh.getWorldPosition(v), probe.sh)   (position in the volume's node space)
  // then three.js's shading gives albedo * E, E = irradianceAt(position, n) up to its 6-digit
  // basis constants (getIrradianceAt(n) = pi * E).
  threeSHAt(position, target = new THREE.SphericalHarmonics3()) {
    const c = toThreeConvention(this.shAt(position));
    for (let i = 0; i < 9; i++) target.coefficients[i].set(c[i * 3], c[i * 3 + 1], c[i * 3 + 2]);
    return target;
  }

  // Where `position` (glTF axes, node-local) falls in a POINTS volume with tetrahedra:
  // { inside, tetra, probes [4], weights [4] } of zhc_runtime.mjs volumeTetraWeights, the walk
  // starting at tetrahedron `start` (a moving object passes the last `tetra` for a short walk; the
  // blend does not depend on the start).
  tetraWeights(position, start = 0) {
    if (this.layout !== 'points') throw new Error(`zhc: volume '${this.name}' has layout ${this.layout}: tetraWeights needs points`);
    return volumeTetraWeights(this.#sampler('tetraWeights'), this.#samplePoint(position), start);
  }

  // The compact path (zhc_volume.glsl.mjs): the stored probe bytes as an RGBA32UI Data3DTexture,
  // its uniforms and GLSL chunk; patchMaterialWithVolume(material, volume.compactVolume(), THREE)
  // lights a stock material with it. Validity / visibility masks (an R8UI mask texture) and cell
  // planes (an RG32UI texture; glTF-axes grid, normal codes in zhc axes) are applied.
  // Options: matrixWorld (default: the single node's), masks and planes (false: without them).
  compactVolume(options = {}) {
    if (this.draco) throw new Error(`zhc: volume '${this.name}' is Draco-compressed (not decoded)`);
    return compactVolume(this, { THREE, ...options });
  }

  // three.js's own probe grid (r187+: `LightProbeGridWebGL` for WebGLRenderer, `LightProbeGrid` for
  // WebGPURenderer; pass the class, from 'three/addons/lighting/...') filled from this GRID volume's
  // decoded probes, no bake: stock materials (MeshStandardMaterial, MeshLambertMaterial, ...) are then
  // lit by zhc's probes. Add the returned grid to the scene ROOT: three.js reads its `position` as
  // the world-space centre and its grid is axis-aligned. Options:
  //   matrixWorld: where the volume's node is (default: the node's matrixWorld when the volume is
  //     referenced by exactly one node, else identity); translation and positive scale only, a
  //     rotation or mirror throws (three.js's grid cannot rotate). Call again after moving the node.
  //   type: THREE.FloatType (default for LightProbeGridWebGL, what its own bake stores; filtering
  //     needs OES_texture_float_linear) or THREE.HalfFloatType (default for the WebGPU LightProbeGrid,
  //     whose bake stores half floats: rgba32float is not filterable in WebGPU without
  //     "float32-filterable"; binary16 rounds each coefficient by up to 2^-11 relative).
  // Layout (lightprobes_pars_fragment): one RGBA 3D texture n_x x n_y x 7 (n_z + 2); sub-volume t
  // holds floats 4t..4t+3 of the 27 coefficients c_i,k (index 3i + k, three.js's SH convention, glTF
  // axes, radiance), with a copy of its first / last slice on either side; probe (x, y, z) sits at its
  // texel centre, so the hardware trilinear filter blends the same 8 probes with the same weights as
  // zhc's volume. three.js samples at `position + normal * spacing / 2` (its offset against
  // self-shadowing) and shades BRDF_Lambert * pi E, i.e. albedo * zhc's E there. The volume's
  // validity / visibility masks and cell planes are not applied (a filtered texture cannot drop corners): the grid
  // shows the plain trilinear blend (docs/runtime.md, three.js section).
  lightProbeGrid(GridClass, { matrixWorld, type } = {}) {
    if (typeof GridClass !== 'function') throw new TypeError('zhc: lightProbeGrid needs three.js\'s LightProbeGridWebGL or LightProbeGrid class');
    if (this.layout !== 'grid') throw new Error(`zhc: volume '${this.name}' has layout ${this.layout}: lightProbeGrid needs a grid`);
    if (!this.sh) this.#check(0);
    const vol = makeVolume({ sh: this.sh, ...this.grid });  // validates origin, spacing > 0, counts
    const n = vol.counts, o = vol.origin, s = vol.spacing;
    let m = matrixWorld;
    if (m === undefined) {
      if (this.nodes && this.nodes.length === 1) {
        this.nodes[0].updateWorldMatrix(true, false);
        m = this.nodes[0].matrixWorld;
      } else m = new THREE.Matrix4();
    }
    const e = m.elements;  // column-major
    const scale = [e[0], e[5], e[10]];
    const offDiagonal = Math.max(Math.abs(e[1]), Math.abs(e[2]), Math.abs(e[4]), Math.abs(e[6]), Math.abs(e[8]), Math.abs(e[9]));
    if (!(scale.every((x) => x > 0 && Number.isFinite(x)) && offDiagonal <= 1e-6 * Math.max(...scale) && e[3] === 0 && e[7] === 0 && e[11] === 0 && e[15] === 1))
      throw new Error(`zhc: volume '${this.name}': three.js's probe grid is axis-aligned; its node may be translated and scaled, not rotated, mirrored or projected`);
    const centre = [0, 1, 2].map((c) => e[12 + c] + scale[c] * (o[c] + 0.5 * (n[c] - 1) * s[c]));
    const size = [0, 1, 2].map((c) => scale[c] * n[c] * s[c]);
    const grid = new GridClass(size[0], size[1], size[2], n[0], n[1], n[2]);
    if (grid.isLightProbeGrid !== true) throw new TypeError('zhc: lightProbeGrid needs three.js\'s LightProbeGridWebGL or LightProbeGrid class');
    if (type === undefined) type = grid.type === 'LightProbeGridWebGL' ? THREE.FloatType : THREE.HalfFloatType;
    if (type !== THREE.FloatType && type !== THREE.HalfFloatType) throw new Error('zhc: lightProbeGrid type must be THREE.FloatType or THREE.HalfFloatType');
    grid.name = `${this.name ?? 'zhc'} (LightProbeGrid)`;
    grid.position.fromArray(centre);
    grid.updateMatrixWorld();
    grid.updateBoundingBox();
    const atlas = lightProbeGridAtlas(this, type === THREE.HalfFloatType);
    const tex = new THREE.Data3DTexture(atlas.data, atlas.width, atlas.height, atlas.depth);
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

  // Position of probe p in glTF axes (node-local), [x, y, z].
  position(p) {
    this.#check(p);
    return [this.positions[p * 3], this.positions[p * 3 + 1], this.positions[p * 3 + 2]];
  }

  // THREE.SphericalHarmonics3 of probe p in three.js's convention (its basis has no
  // Condon-Shortley phase: coefficients 1, 3, 5, 7 change sign) and axes (glTF axes), holding
  // RADIANCE coefficients: what THREE.LightProbe expects. three.js evaluates
  // sh.getIrradianceAt(n) = pi * E(n) with its 6-digit basis constants.
  threeSH(p, target = new THREE.SphericalHarmonics3()) {
    const c = toThreeConvention(this.probeSHGltf(p));
    for (let i = 0; i < 9; i++) target.coefficients[i].set(c[i * 3], c[i * 3 + 1], c[i * 3 + 2]);
    return target;
  }

  // A THREE.LightProbe of probe p placed at its (node-local) position.
  lightProbe(p, intensity = 1) {
    const probe = new THREE.LightProbe(this.threeSH(p), intensity);
    probe.position.fromArray(this.position(p));
    probe.name = `${this.name ?? 'zhc'}#${p}`;
    return probe;
  }

  // Index of the probe nearest to `pos` (glTF axes, node-local); -1 for an empty volume.
  nearestProbe(pos) {
    let best = -1, bestD = Infinity;
    for (let p = 0; p < this.count; p++) {
      const dx = this.positions[p * 3] - pos[0], dy = this.positions[p * 3 + 1] - pos[1], dz = this.positions[p * 3 + 2] - pos[2];
      const d = dx * dx + dy * dy + dz * dz;
      if (d < bestD) { bestD = d; best = p; }
    }
    return best;
  }

  #volume = null;

  // The zhc_runtime.mjs volume irradianceAt / shAt sample: a grid in glTF axes (makeVolume), or the
  // points with their tetrahedra in zhc axes (makePointsVolume: positions (x, y, z)_zhc =
  // (z, x, y)_glTF, a permutation of floats, so the walk's arithmetic is the C header's on the .zhp).
  #sampler(what) {
    if (this.#volume) return this.#volume;
    if (this.layout === 'grid') {
      if (!this.sh) this.#check(0);
      this.#volume = makeVolume({ sh: this.sh, ...this.grid, validity: this.validity ?? null, visibility: this.visibility ?? null,
        planes: this.planes ?? null, planesAxes: 'gltf' });
    } else if (this.layout === 'points' && this.tetrahedra) {
      if (!this.sh) this.#check(0);
      const zhc = new Float32Array(3 * this.count);
      for (let p = 0; p < this.count; p++) {
        zhc[3 * p] = this.positions[3 * p + 2];
        zhc[3 * p + 1] = this.positions[3 * p];
        zhc[3 * p + 2] = this.positions[3 * p + 1];
      }
      this.#volume = makePointsVolume({ sh: this.sh, positions: zhc, tetrahedra: this.tetrahedra, neighbours: this.neighbours,
        validity: this.validity ?? null });
    } else {
      throw new Error(`zhc: volume '${this.name}' has layout ${this.layout}${this.layout === 'points' ? ' without tetrahedra' : ''}: ` +
        `${what} needs a grid or points with tetrahedra`);
    }
    return this.#volume;
  }

  // A glTF-axes position in the sampler's frame (the points sampler's is zhc's).
  #samplePoint(position) {
    return this.layout === 'points' ? gltfToZhcDir(position) : position;
  }

  #check(p) {
    if (!this.sh) throw new Error(`zhc: volume '${this.name}' is not decoded (Draco point clouds need the Draco decoder)`);
    if (!Number.isInteger(p) || p < 0 || p >= this.count) throw new RangeError(`zhc: probe ${p} out of range (${this.count} probes)`);
  }
}

// The texture data of three.js r187's LightProbeGridWebGL / LightProbeGrid atlas for a grid volume
// (see ZhcProbeVolume.lightProbeGrid): {data, width: n_x, height: n_y, depth: 7 (n_z + 2)}, data a
// Float32Array (or Uint16Array of binary16 when `half`) of RGBA texels, x fastest, then y, then slice.
export function lightProbeGridAtlas(volume, half = false) {
  const [nx, ny, nz] = volume.grid.counts;
  const padded = nz + 2, depth = 7 * padded;
  const data = half ? new Uint16Array(nx * ny * depth * 4) : new Float32Array(nx * ny * depth * 4);
  const put = (x, y, slice, j, value) => {
    data[((slice * ny + y) * nx + x) * 4 + j] = half ? THREE.DataUtils.toHalfFloat(value) : value;
  };
  for (let p = 0; p < volume.count; p++) {
    const x = p % nx, y = Math.floor(p / nx) % ny, z = Math.floor(p / (nx * ny));
    const c = toThreeConvention(volume.probeSHGltf(p));
    for (let t = 0; t < 7; t++) {
      const slices = [t * padded + 1 + z];
      if (z === 0) slices.push(t * padded);
      if (z === nz - 1) slices.push(t * padded + nz + 1);
      for (const slice of slices)
        for (let j = 0; j < 4; j++) put(x, y, slice, j, 4 * t + j < 27 ? c[4 * t + j] : 0);
    }
  }
  return { data, width: nx, height: ny, depth };
}

// Parses one volume's JSON (and the accessor arrays already loaded) into a ZhcProbeVolume.
// Throws Error naming the problem on malformed input.
// validityArray / visibilityArray: the optional `validity` / `visibility` accessors (count bytes,
// glTF probe order, masks in glTF grid axes: docs/gltf-extension.md), or null. planesArray /
// planeSidesArray: the optional `planes` (4 count bytes) / `planeSides` (count bytes) accessors,
// both or neither (docs/gltf-extension.md "Cell planes"), or null. tetrahedraArray /
// neighboursArray: the optional `tetrahedra` / `tetraNeighbours` accessors (4 per tetrahedron,
// UNSIGNED_INT; a neighbour 4294967295 = none), both or neither (docs/gltf-extension.md
// "Tetrahedra"), or null.
export function buildVolume(v, coefficientsArray, positionsArray, validityArray = null, visibilityArray = null,
  planesArray = null, planeSidesArray = null, tetrahedraArray = null, neighboursArray = null) {
  if (typeof v.encoding !== 'string') throw new Error('ZHC_light_probes: missing encoding');
  const enc = encodingInfo(v.encoding);
  const count = v.count;
  if (!Number.isInteger(count) || count < 1) throw new Error('ZHC_light_probes: count must be an integer >= 1');
  const q = v.quantization ?? {};
  const params = makeParams({
    bits: q.bits ?? 8, sqrt: q.sqrt ?? false, l2Bound: q.l2Bound ?? 'tight', dcFormat: q.dcFormat ?? 'r11g11b10f',
    zonalMapping: q.zonalMapping ?? 'affine', axisMode: enc.axisMode ?? q.axisMode ?? 'luminance', kind: v.kind ?? 'radiance',
    luminanceWeights: v.luminanceWeights ?? undefined,
  });
  const shAxes = v.shAxes ?? 'gltf';
  if (shAxes !== 'gltf' && shAxes !== 'zhc') throw new Error('ZHC_light_probes: shAxes must be gltf or zhc');
  if (enc.packed && params.dcFormat === 'half' && PACKED_LAYOUTS[v.encoding] !== 'sh2_q')
    throw new Error(`ZHC_light_probes: a half DC needs 6 bytes; only the sh2_q layout has it (${v.encoding})`);
  // The stored bytes: float accessors are viewed as their little-endian bytes (every browser
  // and Node platform is little-endian).
  const a = coefficientsArray;
  const bytes = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
  if (bytes.length !== count * enc.bytes)
    throw new Error(`ZHC_light_probes: coefficients hold ${bytes.length} bytes, expected ${count} x ${enc.bytes}`);
  let positions;
  if (v.layout === 'grid') {
    const g = v.grid;
    if (!g || !Array.isArray(g.origin) || !Array.isArray(g.spacing) || !Array.isArray(g.counts)) throw new Error('ZHC_light_probes: bad grid');
    const [nx, ny, nz] = g.counts;
    if (nx * ny * nz !== count) throw new Error('ZHC_light_probes: grid counts do not multiply to count');
    positions = new Float32Array(count * 3);
    for (let p = 0; p < count; p++) {
      const x = p % nx, y = Math.floor(p / nx) % ny, z = Math.floor(p / (nx * ny));
      positions[p * 3] = g.origin[0] + x * g.spacing[0];
      positions[p * 3 + 1] = g.origin[1] + y * g.spacing[1];
      positions[p * 3 + 2] = g.origin[2] + z * g.spacing[2];
    }
  } else if (v.layout === 'points') {
    if (!positionsArray || positionsArray.length !== count * 3) throw new Error('ZHC_light_probes: positions accessor size');
    positions = new Float32Array(positionsArray);
  } else {
    positions = new Float32Array(count * 3);  // layout none: every probe at the node origin
  }
  const perProbe = (a, what) => {
    if (!a) return null;
    if (a.length !== count) throw new Error(`ZHC_light_probes: ${what} accessor size`);
    const b = Uint8Array.from(a);
    if (what === 'validity' && b.some((x) => x > 1)) throw new Error('ZHC_light_probes: validity byte other than 0 or 1');
    return b;
  };
  const validity = perProbe(validityArray, 'validity'), visibility = perProbe(visibilityArray, 'visibility');
  if (visibility && v.layout !== 'grid') throw new Error('ZHC_light_probes: visibility needs layout grid');
  const planes = cellPlanes(v, count, planesArray, planeSidesArray);
  const { tetrahedra, neighbours } = tetrahedraOf(v, count, tetrahedraArray, neighboursArray);
  return new ZhcProbeVolume({
    name: v.name, encoding: encodingName(v.encoding), kind: params.kind, count, shAxes, layout: v.layout, grid: v.grid,
    params, bytesPerProbe: enc.bytes, bytes, positions, sh: decodeAll(v.encoding, bytes, count, params),
    validity, visibility, planes, tetrahedra, neighbours,
  });
}

// The `tetrahedra` / `tetraNeighbours` accessors as a Uint32Array of probe indices and an
// Int32Array of neighbours (4294967295 read as -1), 4 per tetrahedron; both null when absent.
// Throws for one without the other, a layout other than points, sizes that are not 4 per
// tetrahedron or differ, and what checkTetrahedra refuses (an index out of range, a neighbour that
// does not share its face: zhc_runtime.mjs checkTetrahedra).
function tetrahedraOf(v, count, tetsArray, nbrsArray) {
  if (!tetsArray && !nbrsArray) return { tetrahedra: null, neighbours: null };
  if (!tetsArray || !nbrsArray)
    throw new Error(`ZHC_light_probes: ${tetsArray ? 'tetrahedra without tetraNeighbours' : 'tetraNeighbours without tetrahedra'} (the tetrahedra need both accessors)`);
  if (v.layout !== 'points') throw new Error('ZHC_light_probes: tetrahedra need layout points');
  if (tetsArray.length === 0 || tetsArray.length % 4 !== 0 || nbrsArray.length !== tetsArray.length)
    throw new Error(`ZHC_light_probes: tetrahedra / tetraNeighbours accessor sizes (${tetsArray.length}, ${nbrsArray.length}): ` +
      'VEC4, one element per tetrahedron, the same count');
  const tetrahedra = Uint32Array.from(tetsArray);
  const neighbours = new Int32Array(nbrsArray.length);
  for (let j = 0; j < nbrsArray.length; j++) {
    const n = nbrsArray[j];
    if (!Number.isInteger(n) || n < 0 || n > 0xFFFFFFFF) throw new Error(`ZHC_light_probes: tetraNeighbours element ${j} is ${n}`);
    neighbours[j] = n === 0xFFFFFFFF ? -1 : n > 0x7FFFFFFF ? -2 : n;  // -2: refused by checkTetrahedra
  }
  try {
    checkTetrahedra(tetrahedra, neighbours, count);
  } catch (e) {
    throw new Error(`ZHC_light_probes: tetrahedra: ${e.message}`);
  }
  return { tetrahedra, neighbours };
}

// The `planes` / `planeSides` accessors as one Uint8Array of 5 bytes per probe in glTF probe
// order (ou, ov, offset lo, offset hi as stored, then the sides byte in glTF corner bits; a corner
// region, docs/runtime.md "Corner regions": its thresholds and directions in glTF axes), or null
// when both are absent. Throws for one without the other, a layout other than grid, a wrong size,
// a plane or corner region on a probe that starts no cell (the last along a glTF grid axis of two
// or more probes), or a corner region with reserved bits set (bit 15 of its thresholds, bits 3..6
// of its planeSides byte).
function cellPlanes(v, count, planesArray, sidesArray) {
  if (!planesArray && !sidesArray) return null;
  if (!planesArray || !sidesArray)
    throw new Error(`ZHC_light_probes: ${planesArray ? 'planes without planeSides' : 'planeSides without planes'} (the cell planes need both accessors)`);
  if (v.layout !== 'grid') throw new Error('ZHC_light_probes: planes need layout grid');
  if (planesArray.length !== 4 * count) throw new Error('ZHC_light_probes: planes accessor size (VEC4, count elements)');
  if (sidesArray.length !== count) throw new Error('ZHC_light_probes: planeSides accessor size');
  const [nx, ny, nz] = v.grid.counts;
  const out = new Uint8Array(5 * count);
  for (let p = 0; p < count; p++) {
    for (let b = 0; b < 4; b++) out[5 * p + b] = planesArray[4 * p + b];
    out[5 * p + 4] = sidesArray[p];
    const x = p % nx, y = Math.floor(p / nx) % ny, z = Math.floor(p / (nx * ny));
    const last = (nx > 1 && x + 1 === nx) || (ny > 1 && y + 1 === ny) || (nz > 1 && z + 1 === nz);
    const noneOrRegion = out[5 * p + 2] === 0x00 && out[5 * p + 3] === 0x80, region = noneOrRegion && (out[5 * p + 4] & 0x80) !== 0;
    if (last && !(noneOrRegion && !region))
      throw new Error(`ZHC_light_probes: planes accessor: probe ${p} is the last along an axis and starts no cell, but its ${region ? 'corner region' : 'plane'} is set`);
    if (region && ((out[5 * p + 1] & 0x80) || (out[5 * p + 4] & 0x78)))
      throw new Error(`ZHC_light_probes: planes accessor: probe ${p}'s corner region sets reserved bits (bit 15 of its thresholds or bits 3-6 of planeSides)`);
  }
  return out;
}

export class ZhcLightProbesPlugin {
  constructor(parser) {
    this.parser = parser;
    this.name = EXTENSION;
    this.anchors = [];
  }

  createNodeAttachment(nodeIndex) {
    const node = this.parser.json.nodes[nodeIndex];
    const ext = node.extensions && node.extensions[EXTENSION];
    if (!ext) return null;
    const anchor = new THREE.Object3D();
    anchor.name = EXTENSION;
    anchor.userData.zhcLightProbeVolume = ext.volume;
    this.anchors.push(anchor);
    return Promise.resolve(anchor);
  }

  async afterRoot(result) {
    const root = this.parser.json.extensions && this.parser.json.extensions[EXTENSION];
    if (!root) return;
    const volumes = [];
    for (const v of root.volumes ?? []) {
      if (v.draco) {
        // Draco point clouds need the Draco decoder (KHR_draco_mesh_compression's); not decoded here.
        volumes.push(new ZhcProbeVolume({ name: v.name, encoding: encodingName(v.encoding), kind: v.kind ?? 'radiance', count: v.count,
          shAxes: v.shAxes ?? 'gltf', layout: v.layout, grid: v.grid, draco: true }));
        continue;
      }
      const coeffs = (await this.parser.getDependency('accessor', v.coefficients)).array;
      const pos = v.positions !== undefined ? (await this.parser.getDependency('accessor', v.positions)).array : null;
      const acc = async (key) => (v[key] !== undefined ? (await this.parser.getDependency('accessor', v[key])).array : null);
      volumes.push(buildVolume(v, coeffs, pos, await acc('validity'), await acc('visibility'), await acc('planes'), await acc('planeSides'),
        await acc('tetrahedra'), await acc('tetraNeighbours')));
    }
    for (const v of volumes) v.nodes = [];
    for (const anchor of this.anchors) {
      const v = volumes[anchor.userData.zhcLightProbeVolume];
      anchor.userData.zhcLightProbes = v;
      if (v) v.nodes.push(anchor);
    }
    result.userData = result.userData || {};
    result.userData.zhcLightProbes = volumes;
  }
}
