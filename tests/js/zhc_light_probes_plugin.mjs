// A three.js GLTFLoader plugin for ZHC_light_probes (docs/gltf-extension.md).
//
// After loading, `gltf.userData.zhcLightProbes` holds one entry per volume: the encoding, layout,
// positions (glTF axes) and, for the float encodings sh3/sh2, the coefficients as a Float32Array
// with an `irradiance(probe, dir)` evaluator (dir in glTF axes; shAxes "zhc" is handled by the
// swizzle (x, y, z)_zhc = (z, x, y)_glTF). Other encodings are exposed as their raw stored bytes.
// Nodes that reference a volume get a child Object3D named "ZHC_light_probes" with
// userData.zhcLightProbeVolume (three.js may use it as the node object itself when the node has
// nothing else), so probes move with their node.
import * as THREE from 'three';

export const EXTENSION = 'ZHC_light_probes';

// zhc's real SH basis (docs/conventions.md): index l(l+1)+m, Y1 = sqrt(3/4pi) [-y, z, -x], ...
export function shBasis(x, y, z) {
  const pi = Math.PI;
  const y00 = 1 / (2 * Math.sqrt(pi));
  const y1 = Math.sqrt(3 / (4 * pi));
  const y2 = Math.sqrt(15 / (4 * pi));
  const y20 = Math.sqrt(5 / (16 * pi));
  const y22 = Math.sqrt(15 / (16 * pi));
  return [y00, -y1 * y, y1 * z, -y1 * x, y2 * x * y, -y2 * y * z, y20 * (3 * z * z - 1), -y2 * x * z, y22 * (x * x - y * y)];
}
// Normalised clamped-cosine convolution: band scales 1, 2/3, 1/4.
const BAND_SCALE = [1, 2 / 3, 2 / 3, 2 / 3, 1 / 4, 1 / 4, 1 / 4, 1 / 4, 1 / 4];

export class ZhcLightProbesPlugin {
  constructor(parser) {
    this.parser = parser;
    this.name = EXTENSION;
  }

  createNodeAttachment(nodeIndex) {
    const node = this.parser.json.nodes[nodeIndex];
    const ext = node.extensions && node.extensions[EXTENSION];
    if (!ext) return null;
    const anchor = new THREE.Object3D();
    anchor.name = EXTENSION;
    anchor.userData.zhcLightProbeVolume = ext.volume;
    return Promise.resolve(anchor);
  }

  async afterRoot(result) {
    const root = this.parser.json.extensions && this.parser.json.extensions[EXTENSION];
    if (!root) return;
    const volumes = [];
    for (const v of root.volumes) {
      const out = { name: v.name, encoding: v.encoding, kind: v.kind ?? 'radiance', count: v.count,
                    shAxes: v.shAxes ?? 'gltf', layout: v.layout, grid: v.grid };
      if (v.draco) {
        out.draco = true;  // decoding needs the Draco decoder (not part of this test plugin)
        volumes.push(out);
        continue;
      }
      if (v.positions !== undefined) out.positions = (await this.parser.getDependency('accessor', v.positions)).array;
      const coeffs = await this.parser.getDependency('accessor', v.coefficients);
      if (v.encoding === 'sh3' || v.encoding === 'sh2') {
        const n = v.encoding === 'sh3' ? 9 : 4;
        const c = coeffs.array;  // Float32Array, probe-major, RGB per coefficient
        out.coefficients = c;
        out.irradiance = (probe, d) => {
          const len = Math.hypot(d[0], d[1], d[2]);
          let [x, y, z] = [d[0] / len, d[1] / len, d[2] / len];
          if (out.shAxes === 'zhc') [x, y, z] = [z, x, y];
          const basis = shBasis(x, y, z);
          const e = [0, 0, 0];
          for (let i = 0; i < n; i++) {
            // Stored irradiance already has the band scales applied.
            const s = out.kind === 'irradiance' ? 1 : BAND_SCALE[i];
            for (let k = 0; k < 3; k++) e[k] += s * c[(probe * n + i) * 3 + k] * basis[i];
          }
          return e;
        };
      } else {
        out.bytes = coeffs.array;  // Uint8Array of the stored bytes (docs/quantization.md)
      }
      volumes.push(out);
    }
    result.userData = result.userData || {};
    result.userData.zhcLightProbes = volumes;
  }
}
