// Type declarations of zhc_light_probes_plugin.mjs (`@zhc/runtime/three`): the three.js GLTFLoader
// plugin for ZHC_light_probes and the decoded volumes it attaches (three.js types: @types/three).
import type { HalfFloatType, FloatType, LightProbe, Matrix4, Object3D, SphericalHarmonics3 } from 'three';
import type { GLTF, GLTFLoaderPlugin, GLTFParser } from 'three/addons/loaders/GLTFLoader.js';
import type { Vec3, Vec3Like, ZhcEncodingName, ZhcGrid, ZhcKind, ZhcParams, ZhcTetraWeights } from './zhc_runtime.mjs';
import type { ZhcCompactOptions, ZhcCompactVolume } from './zhc_volume.glsl.mjs';

export declare const EXTENSION: 'ZHC_light_probes';

/** The fields of a decoded volume (Draco-compressed volumes carry only the first group and `draco: true`). */
export interface ZhcProbeVolumeFields {
  name?: string;
  encoding: ZhcEncodingName | string;
  kind: ZhcKind;
  count: number;
  /** 'zhc': coefficients kept in zhc axes (what zhc writes); 'gltf': in glTF axes. */
  shAxes: 'zhc' | 'gltf';
  layout: 'grid' | 'points' | 'none';
  /** The grid (layout 'grid'), in the node's local glTF axes. */
  grid?: ZhcGrid;
  draco?: boolean;
  params?: ZhcParams;
  bytesPerProbe?: number;
  /** The stored probe bytes (count x bytesPerProbe). */
  bytes?: Uint8Array;
  /** Probe positions, node-local glTF axes, count x 3. */
  positions?: Float32Array;
  /** Decoded SH3 radiance, count x 27, in the stored axes (shAxes). */
  sh?: Float32Array;
  validity?: Uint8Array | null;
  visibility?: Uint8Array | null;
  /** Cell planes (accessors planes + planeSides), 5 bytes per probe in glTF probe order: ou, ov (normal
   * code, zhc axes), offset lo, offset hi, sides (glTF corner bits), or a corner region (thresholds and
   * directions in glTF axes; docs/runtime.md "Corner regions"); null when absent. */
  planes?: Uint8Array | null;
  /** Tetrahedra of a points volume (accessor tetrahedra): 4 probe indices each; null when absent. */
  tetrahedra?: Uint32Array | null;
  /** Their neighbours (accessor tetraNeighbours): 4 each, the tetrahedron across face j, -1 on the hull; null when absent. */
  neighbours?: Int32Array | null;
  /** The Object3Ds that place the volume (one per referencing node), set by the plugin. */
  nodes?: Object3D[];
}

/** One decoded ZHC_light_probes volume: gltf.userData.zhcLightProbes[i]. Its fields are
 * ZhcProbeVolumeFields' (declaration merging: the interface below gives the class those members). */
export interface ZhcProbeVolume extends ZhcProbeVolumeFields {}
export declare class ZhcProbeVolume {
  constructor(desc: ZhcProbeVolumeFields);
  /** SH3 radiance of probe p in the stored axes, bit exact with zhc (a view). Throws RangeError for a bad index. */
  probeSH(p: number): Float32Array;
  /** SH3 radiance of probe p in glTF axes. */
  probeSHGltf(p: number): Float32Array;
  /** Irradiance of probe p at a direction in glTF / three.js axes (node-local). */
  irradiance(p: number, dir: Vec3Like): Vec3;
  /** Irradiance at any point (node-local glTF axes): a grid's 8 probes blended (masks and cell planes applied), or the 4
   * probes of a points volume's tetrahedron (validity applied). Throws for layout none and points without tetrahedra. */
  irradianceAt(position: Vec3Like, normal: Vec3Like): Vec3;
  /** The blended SH3 radiance at a point (node-local glTF axes), in glTF axes and zhc's basis. */
  shAt(position: Vec3Like): Float32Array;
  /** shAt as a three.js SphericalHarmonics3 (three.js's signs, glTF axes, radiance): a LightProbe's sh for an object there. */
  threeSHAt(position: Vec3Like, target?: SphericalHarmonics3): SphericalHarmonics3;
  /** Points volumes with tetrahedra: the tetrahedron holding a point and its 4 probes' weights (walk from `start`). */
  tetraWeights(position: Vec3Like, start?: number): ZhcTetraWeights;
  /** The compact path: stored bytes in an RGBA32UI Data3DTexture, uniforms and GLSL (three.js passed in). */
  compactVolume(options?: Omit<ZhcCompactOptions, 'THREE'>): ZhcCompactVolume;
  /** three.js's own probe grid (r187+ LightProbeGridWebGL or LightProbeGrid) filled from the decoded probes. */
  lightProbeGrid<T extends Object3D>(
    GridClass: new (width: number, height: number, depth: number, widthProbes: number, heightProbes: number, depthProbes: number) => T,
    options?: { matrixWorld?: Matrix4; type?: typeof FloatType | typeof HalfFloatType },
  ): T;
  /** Position of probe p, node-local glTF axes. */
  position(p: number): Vec3;
  /** three.js SphericalHarmonics3 of probe p (three.js's signs, glTF axes, radiance). */
  threeSH(p: number, target?: SphericalHarmonics3): SphericalHarmonics3;
  /** A THREE.LightProbe of probe p at its node-local position. */
  lightProbe(p: number, intensity?: number): LightProbe;
  /** Index of the probe nearest to a node-local point; -1 for an empty volume. */
  nearestProbe(pos: Vec3Like): number;
}

/** three.js's LightProbeGrid atlas of a grid volume: RGBA texels, x fastest, then y, then slice. */
export declare function lightProbeGridAtlas(volume: ZhcProbeVolume, half?: boolean): {
  data: Float32Array | Uint16Array;
  width: number;
  height: number;
  depth: number;
};

/** One volume's JSON definition as in the glTF file. */
export interface ZhcVolumeDefinition {
  name?: string;
  encoding: string;
  count: number;
  kind?: ZhcKind;
  shAxes?: 'zhc' | 'gltf';
  layout: 'grid' | 'points' | 'none';
  grid?: ZhcGrid;
  quantization?: {
    bits?: number;
    sqrt?: boolean;
    l2Bound?: 'tight' | 'loose';
    dcFormat?: 'r11g11b10f' | 'rgb9e5' | 'half';
    zonalMapping?: 'affine' | 'zero' | 'symmetric';
    axisMode?: 'luminance' | 'channel';
  };
  luminanceWeights?: number[];
  [key: string]: unknown;
}
/** A volume's JSON and its accessor arrays -> a decoded ZhcProbeVolume (throws Error on malformed input). */
export declare function buildVolume(
  definition: ZhcVolumeDefinition,
  coefficientsArray: ArrayBufferView,
  positionsArray: ArrayLike<number> | null,
  validityArray?: ArrayLike<number> | null,
  visibilityArray?: ArrayLike<number> | null,
  planesArray?: ArrayLike<number> | null,
  planeSidesArray?: ArrayLike<number> | null,
  tetrahedraArray?: ArrayLike<number> | null,
  tetraNeighboursArray?: ArrayLike<number> | null,
): ZhcProbeVolume;

/** What the plugin puts in gltf.userData. */
export interface ZhcGltfUserData {
  zhcLightProbes: ZhcProbeVolume[];
}

/** The GLTFLoader plugin: loader.register((parser) => new ZhcLightProbesPlugin(parser)). */
export declare class ZhcLightProbesPlugin implements GLTFLoaderPlugin {
  constructor(parser: GLTFParser);
  readonly name: 'ZHC_light_probes';
  parser: GLTFParser;
  anchors: Object3D[];
  createNodeAttachment(nodeIndex: number): Promise<Object3D> | null;
  afterRoot(result: GLTF): Promise<void>;
}
