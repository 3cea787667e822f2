// Type declarations of zhc_runtime.mjs (`@zhc/runtime`): decoders for every probe encoding zhc
// stores, irradiance, `.zhp` parsing, probe volumes, axis and three.js conversions, IrradZ texels.
// Conventions (README.md): an SH3 probe is 27 floats, element i * 3 + k = coefficient i of channel
// k, radiance, zhc's real SH basis; irradiance uses zhc's normalised kernel.

/** Three numbers: an RGB triple or a direction. */
export type Vec3 = [number, number, number];
/** Any three numbers (an array, a tuple or a typed array) given as a direction or a point. */
export type Vec3Like = ArrayLike<number>;

/** Every entry of zhc's codec table, by its own name. */
export type ZhcEncodingName =
  | 'sh3' | 'sh2' | 'zh3_lum' | 'zh3_channel' | 'zh3_solved_lum' | 'zh3_solved_channel'
  | 'hall_ambdir' | 'hall_sphere' | 'hall_curve' | 'hall_ambdir_channel' | 'hall_sphere_channel' | 'hall_curve_channel'
  | 'zh3_lum_axis_clamp' | 'zh3_lum_sphere_clamp' | 'sh3_dering' | 'zh3_q16' | 'zh3_solved_q16' | 'sh3_q28' | 'sh2_q'
  | 'hall_curve_q' | 'zh3_dering' | 'zh3_dering_q16' | 'zh3_channel_q16' | 'zh3_solved_channel_q16' | 'hall_solved'
  | 'hall_solved_q16' | 'hall_adaptive_q16';
/** Names an entry answers to besides its own (read, never written). */
export type ZhcEncodingAlias = 'zh3_lum_dering' | 'zh3_lum_dering_sphere';
/** An encoding name as found in a file: a table name, an alias, or any string (checked at run time: unknown names throw). */
export type ZhcEncodingInput = ZhcEncodingName | ZhcEncodingAlias | (string & {});

/** Storage layouts of the codec table. */
export type ZhcLayout = 'sh3_f32' | 'sh2_f32' | 'zh3_f32' | 'zh3_q16' | 'sh3_q28' | 'sh2_q';
/** The packed (quantised) layouts. */
export type ZhcPackedLayout = 'zh3_q16' | 'sh3_q28' | 'sh2_q';
export type ZhcHallucination = 'none' | 'ambdir' | 'sphere' | 'curve' | 'curve_adaptive';
export type ZhcAxis = 'none' | 'luminance' | 'channel' | 'format';
export type ZhcKind = 'radiance' | 'irradiance';
export type ZhcL2Bound = 'tight' | 'loose';
export type ZhcDcFormat = 'r11g11b10f' | 'rgb9e5' | 'half';
export type ZhcZonalMapping = 'affine' | 'zero' | 'symmetric';
export type ZhcAxisMode = 'luminance' | 'channel';

/** Quantisation parameters with their glTF spellings (what makeParams returns). */
export interface ZhcParams {
  bits: number;
  sqrt: boolean;
  l2Bound: ZhcL2Bound;
  dcFormat: ZhcDcFormat;
  kind: ZhcKind;
  zonalMapping: ZhcZonalMapping;
  axisMode: ZhcAxisMode;
  luminanceWeights: readonly number[];
}
/** makeParams's input: any subset of the parameters. */
export type ZhcParamsInput = Partial<Omit<ZhcParams, 'luminanceWeights'>> & { luminanceWeights?: ArrayLike<number> };

/** One row of ENCODING_TABLE. */
export interface ZhcEncodingRow {
  readonly name: ZhcEncodingName;
  readonly bytes: number;
  readonly layout: ZhcLayout;
  readonly hallucination: ZhcHallucination;
  readonly axis: ZhcAxis;
}
/** One entry of ENCODINGS. */
export interface ZhcEncodingInfo {
  readonly bytes: number;
  /** Present (true) for the packed layouts. */
  readonly packed?: true;
  /** The axis mode a packed entry fixes (the *_channel_q16 entries), absent otherwise. */
  readonly axisMode?: ZhcAxisMode;
  readonly layout: ZhcLayout;
  readonly hallucination: ZhcHallucination;
  readonly axis: ZhcAxis;
  /** Probe bytes at b[o ..] -> SH3 (radiance for radiance files; see decodeProbe). */
  decode(bytes: Uint8Array, offset: number, params: ZhcParams): Float32Array;
}

/** A probe grid as stored in .zhp and glTF: probe (x, y, z) is number x + nx (y + ny z) at origin + (x sx, y sy, z sz). */
export interface ZhcGrid {
  origin: Vec3;
  spacing: Vec3;
  counts: Vec3;
}

/** parseZhp's result. */
export interface ZhpFile {
  encoding: string;
  params: ZhcParams;
  count: number;
  bytesPerProbe: number;
  layout: 'none' | 'grid' | 'positions';
  grid: ZhcGrid | null;
  positions: Float32Array | null;
  /** The stored probe bytes (a view into the file). */
  payload: Uint8Array;
  validity: Uint8Array | null;
  visibility: Uint8Array | null;
  /** Cell planes (byte 21 bit 2): 5 bytes per probe, the plane or corner region of the cell whose corner 0 is the probe. */
  planes: Uint8Array | null;
  /** Tetrahedra of a positions layout (byte 21 bit 3): 4 probe indices each. */
  tetrahedra: Uint32Array | null;
  /** Their neighbours: 4 each, the tetrahedron across face j (the face without vertex j), -1 on the convex hull. */
  neighbours: Int32Array | null;
}

/** makeVolume's input: the stored bytes (encoding, params, bytes) or the decoded SH3 (sh), and the grid. */
export interface ZhcVolumeInput {
  encoding?: ZhcEncodingInput;
  params?: ZhcParams;
  bytes?: Uint8Array;
  /** Decoded SH3 radiance, count x 27 floats (takes the place of encoding / bytes). */
  sh?: ArrayLike<number>;
  origin: Vec3Like;
  spacing: Vec3Like;
  counts: Vec3Like;
  validity?: ArrayLike<number> | null;
  visibility?: ArrayLike<number> | null;
  /** Cell planes, 5 bytes per probe (ou, ov, offset lo, offset hi, sides; or a corner region: thresholds r lo, r hi, 0x00, 0x80, 0x80 | directions), probe order. */
  planes?: ArrayLike<number> | null;
  /** 'zhc' (default): the grid is in the axes of the normals' code; 'gltf': the grid in glTF axes, the codes in zhc axes (corner regions: in the grid's axes either way). */
  planesAxes?: 'zhc' | 'gltf';
}
/** A decoded probe grid (frozen): makeVolume / volumeFromZhp. */
export interface ZhcGridVolume {
  readonly kind: 'grid';
  readonly origin: Vec3;
  readonly spacing: Vec3;
  readonly counts: Vec3;
  readonly count: number;
  readonly sh: ArrayLike<number>;
  readonly validity: ArrayLike<number> | null;
  readonly visibility: ArrayLike<number> | null;
  readonly planes: ArrayLike<number> | null;
  readonly planesAxes: 'zhc' | 'gltf';
}
/** makePointsVolume's input: the stored bytes (encoding, params, bytes) or the decoded SH3 (sh), positions and tetrahedra. */
export interface ZhcPointsVolumeInput {
  encoding?: ZhcEncodingInput;
  params?: ZhcParams;
  bytes?: Uint8Array;
  sh?: ArrayLike<number>;
  /** 3 floats per probe (float32 values). */
  positions: ArrayLike<number>;
  /** 4 probe indices per tetrahedron, consistently oriented (as zhc writes them). */
  tetrahedra: ArrayLike<number>;
  /** 4 per tetrahedron: the tetrahedron across face j, -1 on the convex hull. */
  neighbours: ArrayLike<number>;
  validity?: ArrayLike<number> | null;
}
/** Scattered probes decoded once with their tetrahedra (frozen): makePointsVolume / volumeFromZhp. */
export interface ZhcPointsVolume {
  readonly kind: 'points';
  readonly count: number;
  readonly sh: ArrayLike<number>;
  readonly positions: Float32Array;
  readonly tetrahedra: Uint32Array;
  readonly neighbours: Int32Array;
  readonly tetraCount: number;
  readonly validity: ArrayLike<number> | null;
}
/** Either kind of volume: what volumeFromZhp returns and the samplers take. */
export type ZhcVolume = ZhcGridVolume | ZhcPointsVolume;
/** volumeTetraWeights's result: the 4 probes blended at a point and their weights (validity applied). */
export interface ZhcTetraWeights {
  /** false: outside the convex hull, clamped to its nearest face. */
  inside: boolean;
  /** The tetrahedron used (start the next nearby point's walk there). */
  tetra: number;
  probes: number[];
  weights: number[];
}

export declare const PI: number;
export declare const kY00: number;
export declare const kY1: number;
export declare const kY2: number;
export declare const kY20: number;
export declare const kY22: number;
/** Band scales of the normalised clamped-cosine convolution: 1, 2/3, 1/4. */
export declare const IRRADIANCE_BAND_SCALE: number[];

export declare const ENCODING_TABLE: readonly ZhcEncodingRow[];
export declare const ENCODING_ALIASES: Readonly<Record<ZhcEncodingAlias, ZhcEncodingName>>;
/** Defaults of the format, enum fields as their numeric values. */
export declare const CODEC_DEFAULTS: Readonly<{
  bits: number;
  sqrtEncoding: number;
  l2Bound: number;
  dcFormat: number;
  kind: number;
  zonalMapping: number;
  axisMode: number;
  luminanceWeights: readonly number[];
  hallucinateA: number;
  hallucinateB: number;
}>;
/** Rec. 709 luminance weights. */
export declare const DEFAULT_LUMINANCE: readonly number[];

/** The nine SH3 basis functions at a unit direction. */
export declare function shBasis(x: number, y: number, z: number): number[];
/** a / |a|, or `fallback` (default +Z) when |a| is 0 or not finite. */
export declare function normalizeOr(a: Vec3Like, fallback?: Vec3Like): Vec3;
/** Value of SH3 coefficients at unit direction d, float32 RGB. */
export declare function evaluate(sh: ArrayLike<number>, d: Vec3Like): Vec3;
export declare function toIrradiance(sh: ArrayLike<number>): Float32Array;
export declare function toRadiance(sh: ArrayLike<number>): Float32Array;
/** Irradiance at unit normal n (in the SH's axes) from SH3 radiance, float32 RGB. */
export declare function irradiance(sh: ArrayLike<number>, n: Vec3Like): Vec3;

/** The glTF spellings of the enum fields, indexed by their values. */
export declare const PARAM_VALUES: Readonly<{
  l2Bound: readonly ZhcL2Bound[];
  dcFormat: readonly ZhcDcFormat[];
  kind: readonly ZhcKind[];
  zonalMapping: readonly ZhcZonalMapping[];
  axisMode: readonly ZhcAxisMode[];
}>;
export declare const DEFAULT_PARAMS: Readonly<ZhcParams>;
/** Complete, checked parameters (throws Error on a value out of range). */
export declare function makeParams(p?: ZhcParamsInput): ZhcParams;
/** Interval [lo, hi] of c_i / c_0 for SH index i in 1..8. */
export declare function ratioInterval(i: number, kind: ZhcKind, l2Bound: ZhcL2Bound): [number, number];
/** A stored ratio code -> the ratio. */
export declare function decodeRatio(code: number, iv: readonly [number, number],
  params: Pick<ZhcParams, 'bits' | 'sqrt' | 'zonalMapping'>, zonal: boolean): number;
/** Unsigned float with a 5-bit exponent and `mbits` mantissa bits. */
export declare function unpackUfloat(code: number, mbits: number): number;
export declare function unpackR11G11B10F(bits: number): Vec3;
export declare function unpackRgb9e5(bits: number): Vec3;
export declare function unpackHalf(bits: number): number;
/** The zonal axes of the three channels from float DC/L1 coefficients (at least 12 values). */
export declare function zh3Axes(c: ArrayLike<number>, axisMode: ZhcAxisMode, w: ArrayLike<number>): [Vec3, Vec3, Vec3];
export declare const HALLUCINATE_CURVE_A: number;
export declare const HALLUCINATE_CURVE_B: number;
/** The hallucinated zonal L2 coefficient (ZH3 paper Eq. 14 / 20 / 21). */
export declare function hallucinateZonal(model: 'ambdir' | 'sphere' | 'curve', f0: number, f1Zonal: number, a?: number, b?: number): number;
/** The packed entries' layouts, by entry name. */
export declare const PACKED_LAYOUTS: Readonly<Partial<Record<ZhcEncodingName, ZhcPackedLayout>>>;
/** Packed bytes at b[o ..] -> SH3 radiance. */
export declare function decodePacked(layout: ZhcPackedLayout, bytes: ArrayLike<number>, offset: number, params: ZhcParams): Float32Array;
/** Every entry of the codec table, by name. */
export declare const ENCODINGS: Readonly<Record<ZhcEncodingName, ZhcEncodingInfo>>;
/** The entry's own name for a name or an alias of one; anything else unchanged. */
export declare function encodingName(name: string): string;
/** The ENCODINGS entry of a name or alias (throws Error for an unknown name). */
export declare function encodingInfo(name: ZhcEncodingInput): ZhcEncodingInfo;
/** One probe's bytes -> SH3 radiance, Float32Array(27), bit exact with zhc's decode_probe. */
export declare function decodeProbe(encoding: ZhcEncodingInput, bytes: Uint8Array, offset?: number, params?: ZhcParams): Float32Array;
/** irradiance(decodeProbe(...), n). */
export declare function probeIrradiance(encoding: ZhcEncodingInput, bytes: Uint8Array, offset: number, params: ZhcParams, n: Vec3Like): Vec3;
/** The shader formula for zh3_q16 bytes, in double (not bit exact: < 1e-6 of the DC term). */
export declare function zh3Q16IrradianceFast(bytes: ArrayLike<number>, offset: number, params: ZhcParams, n: Vec3Like): Vec3;

/** glTF direction (x, y, z) -> zhc axes (z, x, y). */
export declare function gltfToZhcDir(d: Vec3Like): Vec3;
/** zhc direction (x, y, z) -> glTF axes (y, z, x). */
export declare function zhcToGltfDir(d: Vec3Like): Vec3;
/** SH3 coefficients in zhc axes -> the same function in glTF axes. */
export declare function rotateZhcToGltf(c: ArrayLike<number>): Float32Array;
/** SH3 coefficients in glTF axes -> zhc axes. */
export declare function rotateGltfToZhc(g: ArrayLike<number>): Float32Array;
/** Signs that turn zhc's basis into three.js's (no Condon-Shortley phase). */
export declare const THREE_SIGNS: readonly number[];
/** SH3 in glTF axes -> three.js's SphericalHarmonics3 convention (coefficients 1, 3, 5, 7 negated). */
export declare function toThreeConvention(gltfAxesSh: ArrayLike<number>): Float32Array;

/** CRC-32 (the .zhp checksums) of bytes[start, end). */
export declare function crc32(bytes: ArrayLike<number>, start?: number, end?: number): number;
/** Parses an uncompressed .zhp file (throws Error on a malformed one or a zstd body). */
export declare function parseZhp(bytes: Uint8Array): ZhpFile;
/** Decodes every probe of a payload: Float32Array(count * 27). */
export declare function decodeAll(encoding: ZhcEncodingInput, payload: Uint8Array, count: number, params?: ZhcParams): Float32Array;

/** A probe grid decoded once (throws Error naming a bad grid). */
export declare function makeVolume(input: ZhcVolumeInput): ZhcGridVolume;
/** Throws Error naming the first tetrahedron whose indices or neighbours are inconsistent. */
export declare function checkTetrahedra(tetrahedra: ArrayLike<number>, neighbours: ArrayLike<number>, count: number): void;
/** Scattered probes decoded once, with their tetrahedra (throws Error naming a problem). */
export declare function makePointsVolume(input: ZhcPointsVolumeInput): ZhcPointsVolume;
/** A volume from a whole .zhp file: a grid, or scattered probes with tetrahedra (throws "not a grid" otherwise). */
export declare function volumeFromZhp(bytes: Uint8Array): ZhcVolume;
/** Where a point falls in scattered probes: the tetrahedron (walk from `start`, default 0), its 4 probes and weights. */
export declare function volumeTetraWeights(vol: ZhcPointsVolume, position: Vec3Like, start?: number): ZhcTetraWeights;
/** Blended SH3 radiance at a point of the volume's frame, Float64Array(27). */
export declare function volumeSH3(vol: ZhcVolume, position: Vec3Like): Float64Array;
/** Irradiance at a point for a surface normal (volume frame), in double. */
export declare function volumeIrradianceD(vol: ZhcVolume, position: Vec3Like, normal: Vec3Like): Vec3;
/** Irradiance at a point for a surface normal (volume frame), float32 RGB: the C header's values. */
export declare function volumeIrradiance(vol: ZhcVolume, position: Vec3Like, normal: Vec3Like): Vec3;

/** IrradZ models: hemispherical and ambient + highlight direction. */
export declare const IRRADZ_HHD: 0;
export declare const IRRADZ_AHD: 1;
export type IrradzModel = typeof IRRADZ_HHD | typeof IRRADZ_AHD;
/** Hemi-octahedral (u, v) in [0, 1]^2 -> unit direction with z >= 0. */
export declare function decodeHemioct(u: number, v: number): Vec3;
/** IrradZ irradiance at a tangent-space unit normal, float32 RGB. */
export declare function irradzIrradiance(iz: ArrayLike<number>, wa: number, d: Vec3Like, model: IrradzModel, n: Vec3Like): Vec3;
/** LDR fallback texel t in [0, 1] -> I_z. */
export declare function izFromLdr(t: number, lo: number, hi: number): number;
/** The "zhc.iz_log2_range" key/value bytes of a KTX2 file -> [lo, hi] (throws on a malformed value). */
export declare function parseIzLog2Range(bytes: Uint8Array): [number, number];
/** BC texel: I_z, w_a, (u, v) -> irradiance. */
export declare function irradzIrradianceTexel(iz: ArrayLike<number>, wa: number, u: number, v: number, model: IrradzModel, n: Vec3Like): Vec3;
/** ASTC texel: I_z texel RGB (range null: HDR; [lo, hi]: LDR fallback), (u, v, w_a) texel RGB -> irradiance. */
export declare function irradzIrradianceAstc(izTexel: readonly number[] | Float32Array | Float64Array, dwa: ArrayLike<number>,
  range: readonly [number, number] | null, model: IrradzModel, n: Vec3Like): Vec3;
