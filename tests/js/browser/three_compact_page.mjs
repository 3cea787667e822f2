// The browser side of tests/js/three_compact.mjs: zhc's compact volume (runtime/web/zhc_volume.glsl.mjs:
// the stored probe bytes in an RGBA32UI 3D texture, the 8-probe blend in the shader) in three.js
// r187 on WebGL2. For each volume of /work/three_compact_spec.json:
//  (A) a ShaderMaterial: one pixel per sample of an RGBA32F target, the fragment reads the sample's
//      point q and direction d (grid frame) from a float texture and writes zhcVolumeIrradiance;
//  (B) a MeshLambertMaterial patched by patchMaterialWithVolume: a white sphere per sample, alone
//      (no other light, tone mapping off, RGBA32F target), its pole vertex (normal exactly +Y in
//      SphereGeometry) turned to face the camera along the world direction of d and placed at the
//      world position of q (the volume's matrixWorld: translation, uniform scale and, for .zhp
//      volumes, the zhc -> glTF axis rotation); the centre pixel of a 33 x 33 target shades the pole.
//  (C) a patched MeshStandardMaterial (roughness 1, metalness 0) and, as its twin, the same material
//      lit by a THREE.LightProbe holding zhc's blended SH3 at q (JS volumeSH3, three.js's basis).
// A volume with validity / visibility masks gets the masked chunk and the R8UI mask texture, one
// with cell planes the planes chunk and the RG32UI plane texture (spec `masks: false` / `planes:
// false`: compactVolume's opt-outs; spec `validity` / `visibility`: synthetic masks handed to
// compactVolume with the parsed .zhp, planes dropped; spec `source`: a compact source in glTF axes
// built from a .zhp, planesAxes 'gltf'); the ShaderMaterial passes the mask and plane samplers when
// the chunk defines ZHC_VOLUME_MASKED / ZHC_VOLUME_PLANES, and the LightProbe twin blends with the
// same leak data (volumeSH3).
// Reported: the pixels, GPU bytes per probe of the compact texture and of three.js's own grid
// (LightProbeGridWebGL atlas via the plugin's lightProbeGrid, float and binary16), the mask and
// plane textures' bytes, refusals.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { LightProbeGridWebGL } from 'three/addons/lighting/LightProbeGridWebGL.js';
import { ZhcLightProbesPlugin } from '/runtime/web/zhc_light_probes_plugin.mjs';
import { compactVolume, compactVolumeFromZhp, patchMaterialWithVolume } from '/runtime/web/zhc_volume.glsl.mjs';
import { parseZhp, makeVolume, volumeSH3, rotateZhcToGltf, toThreeConvention, gltfToZhcDir } from '/runtime/web/zhc_runtime.mjs';

// zhc axes -> glTF axes: (x, y, z)_glTF = (y, z, x)_zhc (a rotation).
const ZHC_TO_GLTF = new THREE.Matrix4().set(0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 0, 0, 1);

async function main() {
  const spec = await (await fetch('/work/three_compact_spec.json')).json();
  const canvas = document.createElement('canvas');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
  const gl = renderer.getContext();
  const dbg = gl.getExtension('WEBGL_debug_renderer_info');
  const report = {
    three: THREE.REVISION, webgl2: gl instanceof WebGL2RenderingContext, colorBufferFloat: !!gl.getExtension('EXT_color_buffer_float'),
    renderer: dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER), volumes: [],
  };
  renderer.toneMapping = THREE.NoToneMapping;
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  for (const f of spec.volumes) {
    const r = { name: f.name };
    const root = new THREE.Group();
    root.position.fromArray(f.rootTranslation);
    root.scale.setScalar(f.rootScale);
    let compact, matrixWorld;
    if (f.glb) {
      const gltf = await loader.loadAsync(`/work/${f.glb}`);
      const v = gltf.userData.zhcLightProbes[0];
      root.add(gltf.scene);
      root.updateMatrixWorld(true);
      matrixWorld = v.nodes[0].matrixWorld.clone();
      r.shVolume = makeVolume({ sh: v.sh, ...v.grid, validity: v.validity, visibility: v.visibility, planes: v.planes ?? null, planesAxes: 'gltf' });
      compact = v.compactVolume();  // the plugin's method; default placement: the node's matrixWorld
      r.defaultMatrix = compact.matrixWorld.every((x, i) => x === matrixWorld.elements[i]);
      const gridF = v.lightProbeGrid(LightProbeGridWebGL);
      const gridH = v.lightProbeGrid(LightProbeGridWebGL, { type: THREE.HalfFloatType });
      const img = (g) => g.texture.image;
      r.threeFloatBytesPerProbe = img(gridF).data.byteLength / v.count;
      r.threeHalfBytesPerProbe = img(gridH).data.byteLength / v.count;
      r.threeAtlasSize = [img(gridF).width, img(gridF).height, img(gridF).depth];
      r.count = v.count;
      // Refusals: an encoding without a compact decoder, a points volume, spacing 0.
      const throwsWith = (fn, re) => { try { fn(); return false; } catch (err) { return re.test(err.message); } };
      const base = { encoding: v.encoding, params: v.params, bytes: v.bytes, bytesPerProbe: v.bytesPerProbe, shAxes: 'zhc', count: v.count, layout: 'grid' };
      r.refusals = [
        throwsWith(() => compactVolume({ ...base, encoding: 'sh3', grid: v.grid }), /not supported/),
        throwsWith(() => compactVolume({ ...base, encoding: 'hall_curve_q', grid: v.grid }), /not supported/),
        throwsWith(() => compactVolume({ ...base, layout: 'points', grid: v.grid }), /needs a grid/),
        throwsWith(() => compactVolume({ ...base, grid: { ...v.grid, spacing: [1, 0, 1] } }), /spacing\[1\]/),
        throwsWith(() => compactVolume({ ...base, bytes: v.bytes.subarray(0, 16), grid: v.grid }), /need/),
        throwsWith(() => compactVolume(v, { matrixWorld: new THREE.Matrix4().makeScale(1, 0, 1) }), /singular/),
      ];
    } else if (f.source) {
      // A compact source in glTF axes (grid, probe order, bits permuted; SH and normal codes in zhc
      // axes): the grid frame is glTF's, placed by the root alone.
      root.updateMatrixWorld(true);
      matrixWorld = root.matrixWorld.clone();
      const u8 = (a) => (a ? Uint8Array.from(a) : null);
      const src = { ...f.source, bytes: u8(f.source.bytes), validity: u8(f.source.validity), visibility: u8(f.source.visibility), planes: u8(f.source.planes) };
      compact = compactVolume(src, { THREE, matrixWorld });
      r.shVolume = makeVolume({ encoding: src.encoding, params: src.params, bytes: src.bytes, ...src.grid, validity: src.validity,
        visibility: src.visibility, planes: src.planes, planesAxes: 'gltf' });
      r.count = src.bytes.length / src.bytesPerProbe;
    } else {
      const bytes = new Uint8Array(await (await fetch(`/work/${f.zhp}`)).arrayBuffer());
      root.updateMatrixWorld(true);
      matrixWorld = root.matrixWorld.clone().multiply(ZHC_TO_GLTF);
      const z = parseZhp(bytes);
      if (f.validity) {
        // Synthetic masks (the spec's arrays) in place of the file's leak data: the source object
        // carries them, its planes dropped (`planes: false`).
        const masks = { validity: Uint8Array.from(f.validity), visibility: Uint8Array.from(f.visibility) };
        compact = compactVolume({ ...z, ...masks }, { THREE, matrixWorld, planes: false });
        r.shVolume = makeVolume({ encoding: z.encoding, params: z.params, bytes: z.payload, ...z.grid, ...masks });
      } else {
        compact = compactVolumeFromZhp(bytes, { THREE, matrixWorld, masks: f.masks, planes: f.planes });
        r.shVolume = makeVolume({ encoding: z.encoding, params: z.params, bytes: z.payload, ...z.grid, validity: f.masks ? z.validity : null,
          visibility: f.masks ? z.visibility : null, planes: f.planes ? z.planes : null });
      }
      r.count = parseZhp(bytes).count;
    }
    r.encoding = compact.encoding;
    r.gpuBytesPerProbe = compact.gpuBytesPerProbe;
    r.gpuBytes = compact.gpuBytes;
    r.textureBytes = compact.texture.image.data.byteLength;
    r.size = compact.size;
    r.normalAxes = compact.normalAxes;
    r.masked = compact.masked;
    r.glslMasked = compact.glsl.includes('#define ZHC_VOLUME_MASKED 1');
    r.maskBytes = compact.maskBytes;
    r.maskTextureBytes = compact.maskTexture ? compact.maskTexture.image.data.byteLength : 0;
    r.maskSize = compact.maskTexture ? [compact.maskTexture.image.width, compact.maskTexture.image.height, compact.maskTexture.image.depth] : null;
    r.mask = compact.mask ? Array.from(compact.mask) : null;
    r.planed = compact.planed;
    r.glslPlaned = compact.glsl.includes('#define ZHC_VOLUME_PLANES 1');
    r.glslPlaneAxesGltf = compact.glsl.includes('#define ZHC_VOLUME_PLANE_AXES_GLTF 1');
    r.planeBytes = compact.planeBytes;
    r.planeTextureBytes = compact.planeTexture ? compact.planeTexture.image.data.byteLength : 0;
    r.planeSize = compact.planeTexture ? [compact.planeTexture.image.width, compact.planeTexture.image.height, compact.planeTexture.image.depth] : null;
    r.planeData = compact.planeData ? Array.from(compact.planeData) : null;

    // (A) ShaderMaterial, one pixel per sample.
    const N = f.samples.length;
    const sdata = new Float32Array(N * 2 * 4);
    f.samples.forEach((s, i) => { sdata.set([...s.q, 1], i * 8); sdata.set([...s.d, 0], i * 8 + 4); });
    const stex = new THREE.DataTexture(sdata, 2, N, THREE.RGBAFormat, THREE.FloatType);
    stex.needsUpdate = true;
    const material = new THREE.ShaderMaterial({
      glslVersion: THREE.GLSL3,
      uniforms: { uSamples: { value: stex }, ...compact.uniforms },
      vertexShader: 'void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }',
      fragmentShader: `precision highp usampler3D;
${compact.glsl}
uniform highp sampler2D uSamples;
uniform highp usampler3D zhcVolumeTex;
#ifdef ZHC_VOLUME_MASKED
uniform highp usampler3D zhcVolumeMaskTex;
#define ZHC_MASK_ARG zhcVolumeMaskTex,
#else
#define ZHC_MASK_ARG
#endif
#ifdef ZHC_VOLUME_PLANES
uniform highp usampler3D zhcVolumePlaneTex;
#define ZHC_PLANE_ARG zhcVolumePlaneTex,
#else
#define ZHC_PLANE_ARG
#endif
uniform ZhcVolume zhcVolume;
out highp vec4 zhcOut;
void main() {
  int i = int(gl_FragCoord.x);
  vec3 q = texelFetch(uSamples, ivec2(0, i), 0).xyz;
  vec3 d = texelFetch(uSamples, ivec2(1, i), 0).xyz;
  zhcOut = vec4(zhcVolumeIrradiance(zhcVolumeTex, ZHC_MASK_ARG ZHC_PLANE_ARG zhcVolume, q, d), 1.0);
}`,
    });
    const quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material);
    quad.frustumCulled = false;
    const qscene = new THREE.Scene();
    qscene.add(quad);
    const rtA = new THREE.WebGLRenderTarget(N, 1, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false });
    renderer.setRenderTarget(rtA);
    renderer.render(qscene, new THREE.OrthographicCamera());
    const pxA = new Float32Array(N * 4);
    renderer.readRenderTargetPixels(rtA, 0, 0, N, 1, pxA);
    renderer.setRenderTarget(null);
    r.shader = f.samples.map((_, i) => [pxA[4 * i], pxA[4 * i + 1], pxA[4 * i + 2]]);

    // (B) patched MeshLambertMaterial spheres.
    const e = matrixWorld.elements;
    const scale = Math.hypot(e[0], e[1], e[2]);
    const spacingW = Math.min(...compact.grid.spacing) * scale;
    const radius = 0.05 * spacingW;
    const SIZE = 33, MID = 16;
    const rt = new THREE.WebGLRenderTarget(SIZE, SIZE, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
    const lambert = patchMaterialWithVolume(new THREE.MeshLambertMaterial({ color: 0xffffff }), compact, THREE);
    const plain = new THREE.MeshLambertMaterial({ color: 0xffffff });
    const standard = patchMaterialWithVolume(new THREE.MeshStandardMaterial({ color: 0xffffff, roughness: 1, metalness: 0 }), compact, THREE);
    const standardPlain = new THREE.MeshStandardMaterial({ color: 0xffffff, roughness: 1, metalness: 0 });
    const mesh = new THREE.Mesh(new THREE.SphereGeometry(radius, 64, 32), lambert);
    const cam = new THREE.PerspectiveCamera(20, 1, radius, 100 * radius);
    const px = new Float32Array(4);
    const shot = (material, light) => {
      mesh.material = material;
      const scene = new THREE.Scene();
      scene.add(mesh);
      if (light) scene.add(light);
      renderer.setRenderTarget(rt);
      renderer.setClearColor(0x000000, 0);
      renderer.render(scene, cam);
      renderer.readRenderTargetPixels(rt, MID, MID, 1, 1, px);
      renderer.setRenderTarget(null);
      return [px[0], px[1], px[2]];
    };
    r.lambert = [];
    r.standard = [];
    r.standardProbe = [];
    r.termScale = [];
    r.worldMax = 0;
    for (const s of f.samples) {
      const qW = new THREE.Vector3().fromArray(s.q).applyMatrix4(matrixWorld);
      const dW = new THREE.Vector3().fromArray(s.d).transformDirection(matrixWorld);
      r.worldMax = Math.max(r.worldMax, Math.abs(qW.x), Math.abs(qW.y), Math.abs(qW.z));
      const centre = qW.clone().addScaledVector(dW, -radius);
      mesh.position.copy(centre);
      mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), dW);
      cam.position.copy(centre).addScaledVector(dW, 6 * radius);
      cam.up.set(Math.abs(dW.y) > 0.9 ? 1 : 0, Math.abs(dW.y) > 0.9 ? 0 : 1, 0);
      cam.lookAt(centre);
      cam.updateMatrixWorld();
      r.lambert.push(shot(lambert));
      r.standard.push(shot(standard));
      // The twin: zhc's blended SH3 at q (grid frame; coefficients in zhc axes for both kinds of
      // volume here) rotated to glTF = world axes (the nodes are not rotated beyond zhc -> glTF).
      const blended = Float32Array.from(volumeSH3(r.shVolume, s.q));
      const g = toThreeConvention(rotateZhcToGltf(blended));
      const sh = new THREE.SphericalHarmonics3();
      for (let i = 0; i < 9; i++) sh.coefficients[i].set(g[i * 3], g[i * 3 + 1], g[i * 3 + 2]);
      r.standardProbe.push(shot(standardPlain, new THREE.LightProbe(sh)));
      // Term scale of the blended SH3 at the normal: sum_i s_l |c_i Y_i(n)| per channel (>= |E|).
      const [x, y, z] = f.gltf ? gltfToZhcDir(s.d) : s.d;
      const Y = [0.28209479177387814, 0.4886025119029199 * y, 0.4886025119029199 * z, 0.4886025119029199 * x,
        1.0925484305920792 * x * y, 1.0925484305920792 * y * z, 0.31539156525252005 * (3 * z * z - 1),
        1.0925484305920792 * x * z, 0.5462742152960396 * (x * x - y * y)];
      const sl = [1, 2 / 3, 2 / 3, 2 / 3, 0.25, 0.25, 0.25, 0.25, 0.25];
      r.termScale.push([0, 1, 2].map((k) => Y.reduce((acc, yi, i) => acc + sl[i] * Math.abs(yi * blended[i * 3 + k]), 0)));
    }
    r.unpatched = shot(plain);  // the same scene without the volume: black (nothing else lights it)
    r.translationMax = Math.max(Math.abs(e[12]), Math.abs(e[13]), Math.abs(e[14]));
    r.scale = scale;
    delete r.shVolume;
    report.volumes.push(r);
  }
  return report;
}

let report;
try {
  report = await main();
} catch (e) {
  window.zhcErrors.push('exception: ' + (e && e.stack || e));
  report = {};
}
report.errors = window.zhcErrors;
console.log('zhc three.js compact volume page done');  // the driver checks that console output reaches its log
await new Promise((resolve) => setTimeout(resolve, 200));
await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
document.title = 'zhc three.js compact volume test: done';
