// A TypeScript project that uses the installed @zhc/runtime package (tests/js/web_package.mjs,
// CTest js.web_package): it imports every export of every entry point of the package by name,
// compiles under `tsc --strict` against the package's declarations and @types/three, and its
// `run` (compiled, then called by the test under Node) loads a glTF baked by zhc with three.js's
// GLTFLoader and the plugin, hides the asset's KHR_lights_punctual lights, lights a mesh with the
// compact volume and samples the probes, and round-trips the file through glTF-Transform.
// Each `@ts-expect-error` line is a misuse the declarations must reject: tsc fails when one of
// them compiles (an `any` or a too-wide type in the declarations).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { LightProbeGridWebGL } from 'three/addons/lighting/LightProbeGridWebGL.js';
import * as core from '@gltf-transform/core';
import { ALL_EXTENSIONS } from '@gltf-transform/extensions';
import {
  CODEC_DEFAULTS, DEFAULT_LUMINANCE, DEFAULT_PARAMS, ENCODINGS, ENCODING_ALIASES, ENCODING_TABLE, HALLUCINATE_CURVE_A,
  HALLUCINATE_CURVE_B, IRRADIANCE_BAND_SCALE, IRRADZ_AHD, IRRADZ_HHD, PACKED_LAYOUTS, PARAM_VALUES, PI, THREE_SIGNS, crc32,
  decodeAll, decodeHemioct, decodePacked, decodeProbe, decodeRatio, encodingInfo, encodingName, evaluate, gltfToZhcDir,
  hallucinateZonal, irradiance, irradzIrradiance, irradzIrradianceAstc, irradzIrradianceTexel, izFromLdr, kY00, kY1, kY2, kY20,
  kY22, makeParams, makeVolume, normalizeOr, parseIzLog2Range, parseZhp, probeIrradiance, ratioInterval, rotateGltfToZhc,
  rotateZhcToGltf, shBasis, toIrradiance, toRadiance, toThreeConvention, unpackHalf, unpackR11G11B10F, unpackRgb9e5,
  unpackUfloat, volumeFromZhp, volumeIrradiance, volumeIrradianceD, volumeSH3, zh3Axes, zh3Q16IrradianceFast, zhcToGltfDir,
  checkTetrahedra, makePointsVolume, volumeTetraWeights,
} from '@zhc/runtime';
import type { Vec3, ZhcEncodingName, ZhcParams, ZhcPointsVolume, ZhcTetraWeights, ZhcVolume, ZhpFile } from '@zhc/runtime';
import { EXTENSION, ZhcLightProbesPlugin, ZhcProbeVolume, buildVolume, lightProbeGridAtlas } from '@zhc/runtime/three';
import type { ZhcGltfUserData } from '@zhc/runtime/three';
import { ZHC_IRRADIANCE_GLSL, packedWords, zh3Q16Words, zhcIrradianceGlsl } from '@zhc/runtime/glsl';
import {
  COMPACT_TEXELS, compactVolume, compactVolumeFromZhp, compactVolumeMask, compactVolumeWords, patchMaterialWithVolume, zhcVolumeGlsl,
} from '@zhc/runtime/volume';
import type { ZhcCompactVolume } from '@zhc/runtime/volume';
import { ZHC_LIGHT_PROBES, defineZhcLightProbes } from '@zhc/runtime/gltf-transform';
import type { ZhcLightProbes as ZhcLightProbesInstance } from '@zhc/runtime/gltf-transform';
import config, { ZhcLightProbes } from '@zhc/runtime/gltf-transform.config.mjs';
import { THREEJS_GRID_KEY, ZHC_VOLUME_KEY, gridBoundsFromExrHeader, gridBoundsFromKtx2, lightProbeGridFromTexture } from '@zhc/runtime/threejs-grid';

export interface ConsumerReport {
  volumes: number;
  encoding: string;
  layout: string;
  counts: number[];
  lightsFound: number;
  lightsVisibleAfter: number;
  lightTypes: string[];
  irradianceAt: Vec3[];
  zhpIrradiance: Vec3[];
  zhpCount: number;
  glbCount: number;
  compactSize: [number, number, number];
  compactGpuBytesPerProbe: number;
  compactMasked: boolean;
  patchedSame: boolean;
  gridSize: number[];
  atlasDepth: number;
  probeSHLength: number;
  transformKeepsBytes: boolean;
  transformVolumes: number;
  configHasExtension: boolean;
  sameExtensionClass: boolean;
  constants: number[];
  decodedFirst: number[];
  threeSignsLength: number;
  tableLength: number;
}

// The sample points (node-local glTF axes) and normals the test compares with the .zhp.
export const SAMPLES: { p: Vec3; n: Vec3 }[] = [
  { p: [0, 1.5, 0], n: [0, 1, 0] },
  { p: [-2.5, 2, 1], n: [1, 0, 0] },
  { p: [3, 1, -2], n: [0, 0.6, 0.8] },
];

// glb: a .glb written by `zhc bake SCENE.gltf -o lit.glb -r zh3_q16`; zhp: the same bake as .zhp.
export async function run(glb: ArrayBuffer, zhp: Uint8Array): Promise<ConsumerReport> {
  // --- three.js: the plugin, the lights, the volume ---------------------------------------------
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  const gltf = await loader.parseAsync(glb, '');
  const volumes: ZhcProbeVolume[] = (gltf.userData as ZhcGltfUserData).zhcLightProbes;
  const volume = volumes[0];
  // The asset's KHR_lights_punctual lights are already in the probes: hide them.
  const lights: THREE.Light[] = [];
  gltf.scene.traverse((o) => { if ((o as THREE.Light).isLight) lights.push(o as THREE.Light); });
  for (const light of lights) light.visible = false;

  const scene = new THREE.Scene();
  scene.add(gltf.scene);
  scene.updateMatrixWorld(true);
  const irradianceAt = SAMPLES.map(({ p, n }) => volume.irradianceAt(p, n));
  const probe: THREE.LightProbe = volume.lightProbe(volume.nearestProbe([0, 1.5, 0]));
  scene.add(probe);
  const sh: THREE.SphericalHarmonics3 = volume.threeSH(0);
  const grid: LightProbeGridWebGL = volume.lightProbeGrid(LightProbeGridWebGL, { type: THREE.HalfFloatType });
  scene.add(grid);
  const atlas = lightProbeGridAtlas(volume);

  const compact: ZhcCompactVolume = volume.compactVolume();
  const material = new THREE.MeshLambertMaterial({ color: 0xffffff });
  const patched: THREE.MeshLambertMaterial = patchMaterialWithVolume(material, compact, THREE);
  scene.add(new THREE.Mesh(new THREE.SphereGeometry(0.25), patched));

  // --- plain decoding: the .zhp -------------------------------------------------------------------
  const file: ZhpFile = parseZhp(zhp);
  const vol: ZhcVolume = volumeFromZhp(zhp);
  const zhpIrradiance = SAMPLES.map(({ p, n }) => volumeIrradiance(vol, gltfToZhcDir(p), gltfToZhcDir(n)));
  const params: ZhcParams = makeParams({ bits: file.params.bits, luminanceWeights: file.params.luminanceWeights });
  const all: Float32Array = decodeAll(file.encoding, file.payload, file.count, file.params);
  const one: Float32Array = decodeProbe(file.encoding, file.payload, 0, file.params);
  const name: ZhcEncodingName = 'zh3_q16';
  const e0: Vec3 = probeIrradiance(name, file.payload, 0, file.params, [0, 0, 1]);
  const fast: Vec3 = zh3Q16IrradianceFast(file.payload, 0, file.params, [0, 0, 1]);
  const packed: Float32Array = decodePacked('zh3_q16', file.payload, 0, params);
  const blended: Float64Array = volumeSH3(vol, [0, 0, 1]);
  const eD: Vec3 = volumeIrradianceD(vol, [0, 0, 1], [0, 0, 1]);
  const made: ZhcVolume = makeVolume({ sh: all, ...file.grid! });
  const sameVolume = makeVolume({ encoding: file.encoding, params: file.params, bytes: file.payload, ...file.grid! });
  // Scattered probes: one tetrahedron of four probes.
  checkTetrahedra([0, 1, 2, 3], [-1, -1, -1, -1], 4);
  const points: ZhcPointsVolume = makePointsVolume({ sh: all.subarray(0, 4 * 27), positions: [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1],
    tetrahedra: [0, 1, 2, 3], neighbours: [-1, -1, -1, -1] });
  const tetra: ZhcTetraWeights = volumeTetraWeights(points, [0.25, 0.25, 0.25], 0);
  const pointsSH: Float64Array = volumeSH3(points, [0.25, 0.25, 0.25]);
  const fromZhp: ZhcCompactVolume = compactVolumeFromZhp(zhp, { THREE, masks: false });
  const fromFile = compactVolume(file, { matrixWorld: new THREE.Matrix4() });
  const words: Uint32Array = compactVolumeWords(file.payload, file.bytesPerProbe, file.grid!.counts, COMPACT_TEXELS.zh3_q16);
  const mask: Uint8Array | null = compactVolumeMask(file.validity, file.visibility, file.count);
  const glsl: string = zhcVolumeGlsl({ encoding: file.encoding, params: file.params, masked: mask !== null }) + zhcIrradianceGlsl(params) +
    ZHC_IRRADIANCE_GLSL;
  const texWords: Uint32Array = packedWords(file.payload, file.count, file.bytesPerProbe);
  const zh3Words: Uint32Array = zh3Q16Words(file.payload, file.count);
  const rebuilt: ZhcProbeVolume = buildVolume({ encoding: file.encoding, count: file.count, layout: 'grid', grid: file.grid!, shAxes: 'zhc' },
    file.payload, null);
  const desc = new ZhcProbeVolume({ encoding: 'sh3', kind: 'radiance', count: 0, shAxes: 'zhc', layout: 'none' });

  // --- the helpers, each once with the types it returns --------------------------------------------
  const d: Vec3 = normalizeOr([0, 2, 0]);
  const basis: number[] = shBasis(d[0], d[1], d[2]);
  const rad: Float32Array = toRadiance(toIrradiance(one));
  const ev: Vec3 = evaluate(rad, d);
  const irr: Vec3 = irradiance(one, zhcToGltfDir(d));
  const rot: Float32Array = rotateGltfToZhc(rotateZhcToGltf(one));
  const three: Float32Array = toThreeConvention(rot);
  const iv: [number, number] = ratioInterval(1, 'radiance', 'tight');
  const ratio: number = decodeRatio(200, iv, DEFAULT_PARAMS, false);
  const axes: [Vec3, Vec3, Vec3] = zh3Axes(one, 'luminance', DEFAULT_LUMINANCE);
  const zonal: number = hallucinateZonal('curve', 1, 0.5, HALLUCINATE_CURVE_A, HALLUCINATE_CURVE_B);
  const dc: Vec3 = unpackR11G11B10F(0x3c00_0000);
  const dc2: Vec3 = unpackRgb9e5(0x7c00_0000);
  const h: number = unpackHalf(0x3c00) + unpackUfloat(0x3c0, 6);
  const crc: number = crc32(zhp, 0, 180);
  const hemi: Vec3 = decodeHemioct(0.5, 0.5);
  const iz: Vec3 = irradzIrradiance([1, 1, 1], 0.5, hemi, IRRADZ_HHD, [0, 0, 1]);
  const izT: Vec3 = irradzIrradianceTexel([1, 1, 1], 0.5, 0.5, 0.5, IRRADZ_AHD, [0, 0, 1]);
  const range: [number, number] = parseIzLog2Range(new TextEncoder().encode('-8 4\0'));
  const izA: Vec3 = irradzIrradianceAstc([0.5, 0.5, 0.5], [0.5, 0.5, 0.5], range, IRRADZ_HHD, [0, 0, 1]);
  const ldr: number = izFromLdr(0.5, range[0], range[1]);
  const info = encodingInfo(encodingName('zh3_lum_dering'));
  const layout = PACKED_LAYOUTS.sh3_q28;
  const aliasTarget: ZhcEncodingName = ENCODING_ALIASES.zh3_lum_dering;
  const kinds: readonly string[] = PARAM_VALUES.kind;

  // --- glTF-Transform: the extension through the config and through the factory ----------------------
  const ZhcExt = defineZhcLightProbes(core);
  const io = new core.WebIO().registerExtensions([...ALL_EXTENSIONS, ZhcExt]);
  const doc = await io.readBinary(new Uint8Array(glb));
  const ext = doc.getRoot().listExtensionsUsed().find((x) => x.extensionName === ZHC_LIGHT_PROBES) as ZhcLightProbesInstance;
  const before = ext.listVolumes()[0].getAccessorData('coefficients')!.bytes;
  const out = await io.writeBinary(doc);
  const again = await io.readBinary(out);
  const extAgain = again.getRoot().listExtensionsUsed().find((x) => x.extensionName === ZHC_LIGHT_PROBES) as ZhcLightProbesInstance;
  const after = extAgain.listVolumes()[0].getAccessorData('coefficients')!.bytes;
  const created = doc.createExtension(ZhcLightProbes).createVolume('extra');
  created.setDefinition({ encoding: 'sh3', count: 1, layout: 'none' });

  // --- misuses the declarations reject (compiled, never called) ---------------------------------------
  const misuses = (): void => {
    // @ts-expect-error a direction is three numbers, not a string
    irradiance(one, 'up');
    // @ts-expect-error dcFormat has three spellings
    makeParams({ dcFormat: 'bc6h' });
    // @ts-expect-error irradianceAt needs a normal
    volume.irradianceAt([0, 0, 0]);
    // @ts-expect-error masks is a boolean
    compactVolume(volume, { masks: 'yes' });
    // @ts-expect-error patchMaterialWithVolume takes a three.js material
    patchMaterialWithVolume('lambert', compact, THREE);
    // @ts-expect-error the plugin needs the GLTFParser
    new ZhcLightProbesPlugin();
    // @ts-expect-error lightProbeGrid takes three.js's grid class
    volume.lightProbeGrid(THREE.Mesh);
    // @ts-expect-error IrradZ models are IRRADZ_HHD and IRRADZ_AHD
    irradzIrradiance([1, 1, 1], 0.5, hemi, 2, [0, 0, 1]);
    // @ts-expect-error accessor properties are coefficients, positions, validity, visibility
    created.setAccessorData('colors', null);
    // @ts-expect-error decodeAll returns a Float32Array
    const wrong: number[] = decodeAll(file.encoding, file.payload, file.count);
    void wrong;
  };
  void misuses;
  const keep = [aliasTarget, sh, basis, ev, irr, three, ratio, axes, zonal, dc, dc2, h, crc, iz, izT, izA, ldr, info, layout, kinds, packed,
    blended, eD, made, sameVolume, points, tetra, pointsSH, fromZhp, fromFile, words, glsl, texWords, zh3Words, rebuilt, desc, e0, fast, EXTENSION];
  return {
    volumes: volumes.length,
    encoding: volume.encoding,
    layout: volume.layout,
    counts: volume.grid ? [...volume.grid.counts] : [],
    lightsFound: lights.length,
    lightsVisibleAfter: lights.filter((l) => l.visible).length,
    lightTypes: lights.map((l) => l.type),
    irradianceAt,
    zhpIrradiance,
    zhpCount: file.count,
    glbCount: volume.count,
    compactSize: compact.size,
    compactGpuBytesPerProbe: compact.gpuBytesPerProbe,
    compactMasked: compact.masked,
    patchedSame: patched === material && typeof material.onBeforeCompile === 'function',
    gridSize: [grid.width, grid.height, grid.depth],
    atlasDepth: atlas.depth,
    probeSHLength: volume.probeSH(0).length,
    transformKeepsBytes: before.length === after.length && before.every((b, i) => b === after[i]),
    transformVolumes: extAgain.listVolumes().length,
    configHasExtension: config.extensions.includes(ZhcLightProbes),
    sameExtensionClass: ZhcLightProbes === ZhcExt,
    constants: [PI, kY00, kY1, kY2, kY20, kY22, IRRADIANCE_BAND_SCALE[2], CODEC_DEFAULTS.bits, keep.length],
    decodedFirst: Array.from(one),
    threeSignsLength: THREE_SIGNS.length,
    tableLength: ENCODING_TABLE.length + Object.keys(ENCODINGS).length,
  };
}

// @zhc/runtime/threejs-grid (type-checked, not run here: js.threejs_grid_files runs it in Chromium):
// a LightProbeGridWebGL from EXRLoader's texture and header, and the bounds of a KTX2 file.
export function threejsGridFromFiles(exr: THREE.DataTexture, header: Record<string, unknown>, ktx2: ArrayBuffer): [LightProbeGridWebGL, number[], string] {
  const grid: LightProbeGridWebGL = lightProbeGridFromTexture(LightProbeGridWebGL, exr, gridBoundsFromExrHeader(header), { name: 'grid' });
  return [grid, gridBoundsFromKtx2(ktx2).grid.resolution, `${ZHC_VOLUME_KEY} ${THREEJS_GRID_KEY}`];
}
