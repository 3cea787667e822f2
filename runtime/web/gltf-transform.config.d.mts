// Type declarations of gltf-transform.config.mjs (`@zhc/runtime/gltf-transform.config.mjs`): a
// glTF-Transform CLI configuration with glTF-Transform's ALL_EXTENSIONS and ZHC_light_probes.
import type { Extension } from '@gltf-transform/core';
import type { ZhcLightProbesClass } from './zhc_gltf_transform.mjs';

/** The extension class built on the @gltf-transform/core copy the running program resolves. */
export declare const ZhcLightProbes: ZhcLightProbesClass;
declare const config: { extensions: (typeof Extension)[] };
export default config;
