// Type declarations of zhc_threejs_grid.mjs (`@zhc/runtime/threejs-grid`): three.js's LightProbeGrid
// from zhc's threejs_grid_exr / threejs_grid_ktx2 files loaded by EXRLoader / KTX2Loader.
import type { Data3DTexture, DataTexture, Object3D } from 'three';

export declare const ZHC_VOLUME_KEY: 'zhc.volume';
export declare const THREEJS_GRID_KEY: 'threejs.LightProbeGrid';

type Vec3 = [number, number, number];

/** "zhc.volume": probe (i, j, k) at origin + (i, j, k) spacing, three.js's axes. */
export interface ZhcThreejsGridVolume {
  origin: Vec3;
  spacing: Vec3;
  counts: Vec3;
}
/** "threejs.LightProbeGrid": what three.js's grid takes (position = the box's centre, size, probes per axis). */
export interface ZhcThreejsGridTerms {
  position: Vec3;
  size: Vec3;
  resolution: Vec3;
  boundingBox: { min: Vec3; max: Vec3 };
}
export interface ZhcThreejsGridBounds {
  volume: ZhcThreejsGridVolume;
  grid: ZhcThreejsGridTerms;
}

/** The bounds from EXRLoader's texData.header (the second argument of its onLoad). */
export declare function gridBoundsFromExrHeader(header: Record<string, unknown>): ZhcThreejsGridBounds;
/** The bounds from a KTX2 file's key/value data (the whole file's bytes). */
export declare function gridBoundsFromKtx2(bytes: ArrayBuffer | Uint8Array): ZhcThreejsGridBounds;
/** A ready LightProbeGridWebGL / LightProbeGrid from the loaded atlas texture and its bounds. */
export declare function lightProbeGridFromTexture<T extends Object3D>(
  GridClass: new (width: number, height: number, depth: number, widthProbes: number, heightProbes: number, depthProbes: number) => T,
  texture: DataTexture | Data3DTexture,
  bounds: ZhcThreejsGridBounds,
  options?: { name?: string },
): T;
