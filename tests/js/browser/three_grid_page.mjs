// The browser side of tests/js/three_grid.mjs: three.js r187's own LightProbeGridWebGL (or, from
// three_grid_webgpu.html, LightProbeGrid with WebGPURenderer) filled by
// ZhcProbeVolume.lightProbeGrid from a zhc grid volume, lighting stock materials. For each sample
// (/work/three_grid_spec.json) a white sphere is rendered alone (no other light, tone mapping off,
// linear RGBA32F target): the sphere is turned so that its pole vertex (normal exactly +Y in
// SphereGeometry) faces the camera along the sample's direction d, and the camera looks at the pole
// through the centre of a 33 x 33 target, so the centre pixel shades the pole: world normal d, world
// position c + r d. three.js samples its grid at position + d * spacing / 2 (lightprobes_pars_fragment),
// so the sphere centre c is placed for that sample point to be the spec's point q.
// Reported per sample: the pixels (MeshLambertMaterial with a float and a binary16 atlas;
// MeshStandardMaterial roughness 1 metalness 0 with the grid and, as a twin, with a THREE.LightProbe
// holding the blended SH at q), q and d in the volume node's local glTF axes, and the JS volume
// (irradianceAt, bit-identical to the C header) with the term scale of the sample.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { ZhcLightProbesPlugin, ZhcProbeVolume } from '/runtime/web/zhc_light_probes_plugin.mjs';
import { makeVolume, volumeSH3, volumeIrradiance, rotateZhcToGltf, rotateGltfToZhc, toThreeConvention, gltfToZhcDir } from '/runtime/web/zhc_runtime.mjs';

// |Y_i(n)| times zhc's band scale (1, 2/3, 1/4): the magnitude of coefficient i's term in E(n).
function termWeights(n) {
  const [x, y, z] = n;
  const Y = [0.28209479177387814, 0.4886025119029199 * y, 0.4886025119029199 * z, 0.4886025119029199 * x,
    1.0925484305920792 * x * y, 1.0925484305920792 * y * z, 0.31539156525252005 * (3 * z * z - 1),
    1.0925484305920792 * x * z, 0.5462742152960396 * (x * x - y * y)];
  const s = [1, 2 / 3, 2 / 3, 2 / 3, 0.25, 0.25, 0.25, 0.25, 0.25];
  return Y.map((v, i) => Math.abs(v) * s[i]);
}

// three_grid_webgpu.html sets window.zhcWebGPU and maps 'three' to three.webgpu.js: WebGPURenderer
// with three.js's WebGPU LightProbeGrid (same atlas; binary16 by default, no float atlas: rgba32float
// is not filterable in WebGPU without "float32-filterable").
const WEBGPU = window.zhcWebGPU === true;

async function main() {
  const spec = await (await fetch('/work/three_grid_spec.json')).json();
  const canvas = document.createElement('canvas');
  const report = { webgpu: WEBGPU, three: THREE.REVISION, files: [] };
  let renderer, GridClass;
  if (WEBGPU) {
    renderer = new THREE.WebGPURenderer({ canvas, antialias: false });
    await renderer.init();
    report.webgpuBackend = renderer.backend.isWebGPUBackend === true;
    const info = renderer.backend.device?.adapterInfo ?? renderer.backend.adapter?.info;
    report.renderer = info ? `${info.vendor} ${info.architecture} ${info.device} ${info.description}` : 'unknown';
    GridClass = (await import('three/addons/lighting/LightProbeGrid.js')).LightProbeGrid;
  } else {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    const gl = renderer.getContext();
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    report.webgl2 = gl instanceof WebGL2RenderingContext;
    report.colorBufferFloat = !!gl.getExtension('EXT_color_buffer_float');
    report.floatLinear = !!gl.getExtension('OES_texture_float_linear');
    report.renderer = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    GridClass = (await import('three/addons/lighting/LightProbeGridWebGL.js')).LightProbeGridWebGL;
  }
  renderer.toneMapping = THREE.NoToneMapping;
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  const SIZE = 33, MID = 16;
  const rt = new (WEBGPU ? THREE.RenderTarget : THREE.WebGLRenderTarget)(SIZE, SIZE, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
  let px = new Float32Array(4);
  for (const f of spec.files) {
    const gltf = await loader.loadAsync(`/work/${f.glb}`);
    const v = gltf.userData.zhcLightProbes[0];
    const r = { glb: f.glb, encoding: v.encoding, counts: v.grid.counts, samples: [] };
    // Where the volume's node is: the file's own node transform under a translated, scaled root.
    const root = new THREE.Group();
    root.position.fromArray(f.rootTranslation);
    root.scale.setScalar(f.rootScale);
    root.add(gltf.scene);
    root.updateMatrixWorld(true);
    const node = v.nodes[0];
    const m = node.matrixWorld.clone();
    r.nodeMatrix = Array.from(m.elements);
    // Default type (WebGL: float; WebGPU: binary16) at the node's matrixWorld (the default placement).
    const gridF = WEBGPU ? null : v.lightProbeGrid(GridClass);
    const gridH = WEBGPU ? v.lightProbeGrid(GridClass) : v.lightProbeGrid(GridClass, { matrixWorld: m, type: THREE.HalfFloatType });
    r.halfAtlasType = gridH.texture.type === THREE.HalfFloatType;
    r.boundsFloat = gridF ? [...gridF.boundingBox.min.toArray(), ...gridF.boundingBox.max.toArray()] : null;
    r.boundsHalf = [...gridH.boundingBox.min.toArray(), ...gridH.boundingBox.max.toArray()];
    // Refusals: a rotated node, a non-grid class argument.
    const rot = new THREE.Matrix4().makeRotationY(0.3).premultiply(m);
    r.rotationRefused = (() => { try { v.lightProbeGrid(GridClass, { matrixWorld: rot }); return false; } catch (e) { return /axis-aligned/.test(e.message); } })();
    const throwsWith = (f, re) => { try { f(); return false; } catch (err) { return re.test(err.message); } };
    const one = { name: 'one', encoding: 'sh3', count: 1, shAxes: 'zhc', sh: new Float32Array(27), positions: new Float32Array(3) };
    r.refusals = [
      throwsWith(() => v.lightProbeGrid(THREE.Object3D), /LightProbeGridWebGL or LightProbeGrid class/),
      throwsWith(() => v.lightProbeGrid(GridClass, { type: THREE.UnsignedByteType }), /FloatType or THREE.HalfFloatType/),
      throwsWith(() => v.lightProbeGrid(GridClass, { matrixWorld: new THREE.Matrix4().makeScale(1, -1, 1) }), /axis-aligned/),
      throwsWith(() => new ZhcProbeVolume({ ...one, layout: 'points' }).lightProbeGrid(GridClass), /needs a grid/),
      throwsWith(() => new ZhcProbeVolume({ ...one, layout: 'grid', grid: { origin: [0, 0, 0], spacing: [1, 0, 1], counts: [1, 1, 1] } })
        .lightProbeGrid(GridClass), /spacing\[1\]/),
    ];
    const e = m.elements, scale = [e[0], e[5], e[10]], t = [e[12], e[13], e[14]];
    const spacingW = [0, 1, 2].map((c) => scale[c] * v.grid.spacing[c]);
    const radius = 0.05 * Math.min(...spacingW);
    const sphere = new THREE.SphereGeometry(radius, 64, 32);
    const lambert = new THREE.MeshLambertMaterial({ color: 0xffffff });
    const standard = new THREE.MeshStandardMaterial({ color: 0xffffff, roughness: 1, metalness: 0 });
    const mesh = new THREE.Mesh(sphere, lambert);
    const cam = new THREE.PerspectiveCamera(20, 1, radius, 100 * radius);
    const shVol = makeVolume({ sh: v.sh, ...v.grid });
    // The binary16 twin: every probe's atlas coefficients (three.js convention, glTF axes) rounded
    // to binary16 as lightProbeGrid(..., HalfFloatType) stores them, back to zhc's stored axes, and
    // zhc's volume blend in double: what the half atlas holds, without the GPU.
    if (v.shAxes !== 'zhc') throw new Error('the test expects shAxes "zhc"');
    const halfSh = new Float32Array(v.sh.length);
    for (let p = 0; p < v.count; p++) {
      const c = toThreeConvention(v.probeSHGltf(p)).map((x) => THREE.DataUtils.fromHalfFloat(THREE.DataUtils.toHalfFloat(x)));
      halfSh.set(rotateGltfToZhc(toThreeConvention(c)), p * 27);
    }
    const halfVol = makeVolume({ sh: halfSh, ...v.grid });
    const shot = async (scene) => {
      renderer.setRenderTarget(rt);
      renderer.setClearColor(0x000000, 0);
      renderer.render(scene, cam);
      if (WEBGPU) px = await renderer.readRenderTargetPixelsAsync(rt, MID, MID, 1, 1);
      else renderer.readRenderTargetPixels(rt, MID, MID, 1, 1, px);
      renderer.setRenderTarget(null);
      return [px[0], px[1], px[2]];
    };
    for (const s of f.samples) {
      // s.q: the sample point in the node's local glTF axes; s.d: unit direction (world = local).
      const d = new THREE.Vector3().fromArray(s.d);
      const qW = new THREE.Vector3(...[0, 1, 2].map((c) => t[c] + scale[c] * s.q[c]));
      const centre = qW.clone().sub(d.clone().multiplyScalar(radius)).sub(d.clone().multiply(new THREE.Vector3(...spacingW)).multiplyScalar(0.5));
      mesh.position.copy(centre);
      mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), d);
      cam.position.copy(centre).addScaledVector(d, 6 * radius);
      cam.up.set(Math.abs(d.y) > 0.9 ? 1 : 0, Math.abs(d.y) > 0.9 ? 0 : 1, 0);
      cam.lookAt(centre);
      cam.updateMatrixWorld();
      const out = { q: s.q, d: s.d };
      const shots = WEBGPU ? [['lambertHalf', gridH, lambert], ['standardGrid', gridH, standard]]
        : [['lambertFloat', gridF, lambert], ['lambertHalf', gridH, lambert], ['standardGrid', gridF, standard]];
      for (const [key, grid, material] of shots) {
        const scene = new THREE.Scene();
        mesh.material = material;
        scene.add(mesh, grid);
        out[key] = await shot(scene);
      }
      // The twin of the Standard render: three.js's LightProbe holding the SH blended by zhc's volume at q.
      {
        const blended = volumeSH3(shVol, s.q.map((x, c) => x));  // stored axes (zhc for shAxes "zhc")
        const g = toThreeConvention(v.shAxes === 'zhc' ? rotateZhcToGltf(Float32Array.from(blended)) : Float32Array.from(blended));
        const sh = new THREE.SphericalHarmonics3();
        for (let i = 0; i < 9; i++) sh.coefficients[i].set(g[i * 3], g[i * 3 + 1], g[i * 3 + 2]);
        const scene = new THREE.Scene();
        mesh.material = standard;
        scene.add(mesh, new THREE.LightProbe(sh));
        out.standardProbe = await shot(scene);
      }
      out.js = v.irradianceAt(s.q, s.d);
      out.halfTwin = volumeIrradiance(halfVol, s.q, gltfToZhcDir(s.d));
      // Term scale S per channel: sum over the 8 corners of w_b sum_i |s_l c_bi Y_i(n)| (>= |E|).
      {
        const nz = v.shAxes === 'zhc' ? gltfToZhcDir(s.d) : s.d;
        const tw = termWeights(nz);
        const S = [0, 0, 0];
        const probeAt = (c) => {
          const tt = Math.min(Math.max((s.q[c] - v.grid.origin[c]) / v.grid.spacing[c], 0), v.grid.counts[c] - 1);
          const i = Math.min(Math.floor(tt), Math.max(0, v.grid.counts[c] - 2));
          return [i, v.grid.counts[c] > 1 ? tt - i : 0];
        };
        const [ix, fx] = probeAt(0), [iy, fy] = probeAt(1), [iz, fz] = probeAt(2);
        const [nx, ny] = v.grid.counts;
        for (let b = 0; b < 8; b++) {
          const bx = b & 1, by = (b >> 1) & 1, bz = b >> 2;
          const w = (bx ? fx : 1 - fx) * (by ? fy : 1 - fy) * (bz ? fz : 1 - fz);
          if (w === 0) continue;
          const sh = v.probeSH(ix + bx + nx * (iy + by + ny * (iz + bz)));
          for (let k = 0; k < 3; k++) for (let i = 0; i < 9; i++) S[k] += w * tw[i] * Math.abs(sh[i * 3 + k]);
        }
        out.termScale = S;
      }
      r.samples.push(out);
    }
    report.files.push(r);
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
console.log('zhc three.js LightProbeGrid page done');  // the driver checks that console output reaches its log
await new Promise((resolve) => setTimeout(resolve, 200));
await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
document.title = 'zhc three.js LightProbeGrid test: done';
