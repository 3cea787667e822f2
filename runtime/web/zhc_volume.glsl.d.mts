// Type declarations of zhc_volume.glsl.mjs (`@zhc/runtime/volume`): the compact path, a probe grid's
// stored bytes in an RGBA32UI 3D texture decoded and blended in the shader.
import type { Data3DTexture, Material, Matrix3, Matrix4, Vector3 } from 'three';
import type * as THREE_NAMESPACE from 'three';
import type { ZhcEncodingInput, ZhcGrid, ZhcPackedLayout, ZhcParams, ZhcParamsInput, ZhpFile } from './zhc_runtime.mjs';
import type { ZhcProbeVolume } from './zhc_light_probes_plugin.mjs';

/** RGBA32UI texels per probe of each packed layout. */
export declare const COMPACT_TEXELS: Readonly<Record<ZhcPackedLayout, number>>;

export interface ZhcVolumeGlslOptions {
  encoding: ZhcEncodingInput;
  params?: ZhcParamsInput;
  /** 'gltf': normals in glTF axes, coefficients in zhc axes (shAxes "zhc"); 'same' (default): one frame. */
  normalAxes?: 'gltf' | 'same';
  /** Apply validity / visibility masks (a second sampler after the probe texture). */
  masked?: boolean;
  /** Apply cell planes (an RG32UI sampler after the probe and mask textures). */
  planes?: boolean;
  /** 'zhc' (default): the grid is in the axes of the plane normals' code; 'gltf': the grid in glTF axes (n used as n.yzx). */
  planesAxes?: 'zhc' | 'gltf';
}
/** The GLSL ES 3.00 volume chunk for one encoding and parameter set (throws for an encoding without a compact decoder). */
export declare function zhcVolumeGlsl(options?: ZhcVolumeGlslOptions): string;
/** The texture payload of a grid: Uint32Array((T nx) * ny * nz * 4). */
export declare function compactVolumeWords(bytes: Uint8Array, bytesPerProbe: number, counts: ArrayLike<number>, texels: number): Uint32Array;
/** The combined mask bytes (valid ? visibility : 0) of a grid, or null when both are absent. */
export declare function compactVolumeMask(validity: ArrayLike<number> | null, visibility: ArrayLike<number> | null, count: number): Uint8Array | null;

/** A source compactVolume takes besides a ZhcProbeVolume or a ZhpFile: the stored bytes of a grid. */
export interface ZhcCompactSource {
  encoding: ZhcEncodingInput;
  params?: ZhcParams | ZhcParamsInput;
  bytes: Uint8Array;
  bytesPerProbe: number;
  layout?: string;
  grid: ZhcGrid;
  shAxes?: 'zhc' | 'gltf';
  validity?: ArrayLike<number> | null;
  visibility?: ArrayLike<number> | null;
  /** Cell planes, 5 bytes per probe in probe order (planes or corner regions, docs/runtime.md "Corner regions"). */
  planes?: ArrayLike<number> | null;
  /** The axes of the grid relative to the planes' normal code (default 'gltf'; a ZhpFile: 'zhc'). */
  planesAxes?: 'zhc' | 'gltf';
}
export interface ZhcCompactOptions {
  /** The three.js module: adds `texture`, `maskTexture` and `uniforms`. */
  THREE?: typeof THREE_NAMESPACE;
  /** Grid frame -> world (column-major 16 numbers or a Matrix4); any invertible affine map. */
  matrixWorld?: Matrix4 | ArrayLike<number>;
  /** false: the plain trilinear blend, masks dropped (default true). */
  masks?: boolean;
  /** false: cell planes dropped (default true). */
  planes?: boolean;
}
/** The uniforms patchMaterialWithVolume and a ShaderMaterial use. */
export interface ZhcCompactUniforms {
  zhcVolumeTex: { value: Data3DTexture };
  zhcVolume: { value: { origin: Vector3; spacing: Vector3; counts: Vector3 } };
  zhcWorldToVolume: { value: Matrix4 };
  zhcWorldNormalToVolume: { value: Matrix3 };
  /** With masks (masked: true). */
  zhcVolumeMaskTex?: { value: Data3DTexture };
  /** With cell planes (planed: true). */
  zhcVolumePlaneTex?: { value: Data3DTexture };
}
export interface ZhcCompactVolume {
  encoding: string;
  layout: ZhcPackedLayout;
  texelsPerProbe: number;
  gpuBytesPerProbe: number;
  gpuBytes: number;
  size: [number, number, number];
  data: Uint32Array;
  masked: boolean;
  mask: Uint8Array | null;
  maskBytes: number;
  /** Whether the chunk applies cell planes (an RG32UI plane texture). */
  planed: boolean;
  /** The plane texels, 2 words per probe (bytes 0..3 little-endian, byte 4), or null. */
  planeData: Uint32Array | null;
  planeBytes: number;
  planesAxes: 'zhc' | 'gltf';
  grid: ZhcGrid;
  normalAxes: 'gltf' | 'same';
  glsl: string;
  /** Grid frame -> world, column-major. */
  matrixWorld: number[];
  /** World -> grid frame, column-major. */
  worldToGrid: number[];
  /** With the THREE option: */
  texture?: Data3DTexture;
  maskTexture?: Data3DTexture;
  planeTexture?: Data3DTexture;
  uniforms?: ZhcCompactUniforms;
}
/** The compact volume of a grid (throws Error naming the problem: not a grid, an encoding without a compact decoder, ...). */
export declare function compactVolume(source: ZhcProbeVolume | ZhpFile | ZhcCompactSource, options?: ZhcCompactOptions): ZhcCompactVolume;
/** A stock three.js material lit by the compact volume (onBeforeCompile); returns the material. */
export declare function patchMaterialWithVolume<M extends Material>(material: M, compact: ZhcCompactVolume, THREE: typeof THREE_NAMESPACE): M;
/** parseZhp + compactVolume for a whole uncompressed .zhp file. */
export declare function compactVolumeFromZhp(bytes: Uint8Array, options?: ZhcCompactOptions): ZhcCompactVolume;
