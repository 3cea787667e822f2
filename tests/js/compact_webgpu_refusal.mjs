// The compact path on WebGPU: patchMaterialWithVolume refuses a node material (three/webgpu) and a
// three namespace without GLSL chunks in one message that names what is unsupported and what to use,
// before any shader is built, and still patches a WebGL material (onBeforeCompile set).
import * as THREE_GPU from 'three/webgpu';
import * as THREE from 'three';
import { patchMaterialWithVolume } from '../../runtime/web/zhc_volume.glsl.mjs';

let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? 'ok' : 'FAILED'}: ${what}`);
  if (!ok) failures++;
};
const compact = { uniforms: {}, glsl: 'vec3 zhcVolumeIrradiance() { return vec3(0.0); }', masked: false };
const refusal = (material, namespace) => {
  try {
    patchMaterialWithVolume(material, compact, namespace);
    return null;
  } catch (e) {
    return e.message;
  }
};
for (const [name, material, ns] of [
  ['MeshStandardNodeMaterial with three/webgpu', new THREE_GPU.MeshStandardNodeMaterial(), THREE_GPU],
  ['MeshStandardMaterial with three/webgpu', new THREE_GPU.MeshStandardMaterial(), THREE_GPU],
  ['MeshStandardNodeMaterial with three', new THREE_GPU.MeshStandardNodeMaterial(), THREE],
]) {
  const m = refusal(material, ns);
  check(m !== null && m.startsWith('zhc compact volume:') && m.includes('WebGPURenderer is not supported') &&
        m.includes('lightProbeGrid') && !m.includes('Cannot read properties'), `${name} refused clearly: ${m}`);
  check(material.onBeforeCompile.toString() === new THREE.Material().onBeforeCompile.toString(), `${name}: nothing patched`);
}
const webgl = new THREE.MeshStandardMaterial();
const before = webgl.onBeforeCompile;
check(refusal(webgl, THREE) === null && webgl.onBeforeCompile !== before, 'a WebGL MeshStandardMaterial is still patched (onBeforeCompile set)');
check(webgl.customProgramCacheKey().includes('zhc-compact-'), 'its program cache key names the chunk');
console.log(failures ? `${failures} check(s) failed` : 'every check passed');
process.exit(failures ? 1 : 0);
