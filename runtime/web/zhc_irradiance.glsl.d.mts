// Type declarations of zhc_irradiance.glsl.mjs (`@zhc/runtime/glsl`): the GLSL ES 3.00 irradiance
// chunk for WebGL2 / three.js ShaderMaterial and the packed words of probe bytes for RGBA32UI textures.
import type { ZhcParamsInput } from './zhc_runtime.mjs';

/** The chunk with a volume's quantisation parameters compiled in (throws Error on a bad parameter). */
export declare function zhcIrradianceGlsl(params?: ZhcParamsInput): string;
/** The chunk for the default parameters. */
export declare const ZHC_IRRADIANCE_GLSL: string;
/** Probe p of `bytes` at texel p * ceil(bytesPerProbe / 16) of an RGBA32UI texture (zero padded). */
export declare function packedWords(bytes: Uint8Array, count: number, bytesPerProbe: number): Uint32Array;
/** The four little-endian words of each zh3_q16 probe: Uint32Array(count * 4). */
export declare function zh3Q16Words(bytes: ArrayLike<number>, count: number): Uint32Array;
