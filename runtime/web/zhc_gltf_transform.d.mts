// Type declarations of zhc_gltf_transform.mjs (`@zhc/runtime/gltf-transform`): ZHC_light_probes as a
// glTF-Transform 4.x Extension, built on the @gltf-transform/core module the caller passes.
import { Extension, ExtensionProperty } from '@gltf-transform/core';
import type { Buffer, IProperty, PropertyType, ReaderContext, WriterContext } from '@gltf-transform/core';
import type * as GltfTransformCore from '@gltf-transform/core';

export declare const ZHC_LIGHT_PROBES: 'ZHC_light_probes';

/** The stored data of a volume's accessor property ('coefficients', 'positions', 'validity', 'visibility', 'planes', 'planeSides', 'tetrahedra', 'tetraNeighbours'). */
export interface ZhcAccessorData {
  bytes: Uint8Array;
  componentType: number;
  type: string;
  count: number;
  name?: string;
  min?: number[];
  max?: number[];
}
/** A volume's JSON without buffer indices (encoding, count, layout, grid, quantization, ...). */
export interface ZhcVolumeJson {
  name?: string;
  encoding?: string;
  count?: number;
  layout?: string;
  grid?: { origin: number[]; spacing: number[]; counts: number[] };
  [key: string]: unknown;
}
interface IZhcLightProbeVolume extends IProperty {
  definition: ZhcVolumeJson;
  accessors: Record<string, ZhcAccessorData>;
  dracoPayload: Uint8Array | null;
  buffer: Buffer;
}

/** One probe volume: its JSON definition and its stored bytes (an ExtensionProperty of a Node). */
declare class ZhcLightProbeVolumeProperty extends ExtensionProperty<IZhcLightProbeVolume> {
  static EXTENSION_NAME: 'ZHC_light_probes';
  readonly extensionName: 'ZHC_light_probes';
  readonly propertyType: 'ZhcLightProbeVolume';
  readonly parentTypes: string[];
  protected init(): void;
  getBuffer(): Buffer | null;
  setBuffer(buffer: Buffer | null): this;
  getDefinition(): ZhcVolumeJson;
  setDefinition(definition: ZhcVolumeJson): this;
  getEncoding(): string | undefined;
  getCount(): number | undefined;
  getLayout(): string | undefined;
  getGrid(): { origin: number[]; spacing: number[]; counts: number[] } | null;
  getAccessorData(key: 'coefficients' | 'positions' | 'validity' | 'visibility' | 'planes' | 'planeSides' | 'tetrahedra' | 'tetraNeighbours'): ZhcAccessorData | null;
  setAccessorData(key: 'coefficients' | 'positions' | 'validity' | 'visibility' | 'planes' | 'planeSides' | 'tetrahedra' | 'tetraNeighbours', data: ZhcAccessorData | null): this;
  getDracoPayload(): Uint8Array | null;
  setDracoPayload(bytes: Uint8Array | null): this;
}

/** The ZHC_light_probes Extension (register it with NodeIO / WebIO.registerExtensions). */
declare class ZhcLightProbesExtension extends Extension {
  static EXTENSION_NAME: 'ZHC_light_probes';
  /** The volume class. */
  static Volume: typeof ZhcLightProbeVolumeProperty;
  readonly extensionName: 'ZHC_light_probes';
  /** Creates a volume (attach it with node.setExtension('ZHC_light_probes', volume)). */
  createVolume(name?: string): ZhcLightProbeVolumeProperty;
  /** The volumes in file order. */
  listVolumes(): ZhcLightProbeVolumeProperty[];
  read(context: ReaderContext): this;
  /** Before writing buffers: the probe bytes become bufferViews of the volume's buffer. */
  prewrite(context: WriterContext, propertyType: PropertyType): this;
  write(context: WriterContext): this;
}

/** An instance of the extension (document.createExtension(ZhcLightProbes)). */
export type ZhcLightProbes = ZhcLightProbesExtension;
/** The extension class defineZhcLightProbes returns. */
export type ZhcLightProbesClass = typeof ZhcLightProbesExtension;
/** One volume of the extension. */
export type ZhcLightProbeVolume = ZhcLightProbeVolumeProperty;

/** The ZHC_light_probes Extension class built on the given @gltf-transform/core module (the copy that reads and writes the Document). */
export declare function defineZhcLightProbes(core: typeof GltfTransformCore): ZhcLightProbesClass;

export {};
