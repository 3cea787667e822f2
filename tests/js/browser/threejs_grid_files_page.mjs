// The browser side of tests/js/threejs_grid_files.mjs: the files test_engine_file_threejs wrote
// (/work/grid.exr, /work/grid.ktx2) loaded with three.js r187's own EXRLoader (FloatType) and
// KTX2Loader, turned into a LightProbeGridWebGL (threejs_grid_files_webgpu.html: WebGPURenderer and
// LightProbeGrid) by runtime/web/zhc_threejs_grid.mjs, lighting a white MeshLambertMaterial sphere
// per sample (no other light, tone mapping off, RGBA32F target).
// As in three_grid_page.mjs, the sphere's pole (normal exactly +Y in SphereGeometry) is turned to
// the sample's normal d and placed at the sample's point p, and the camera looks at it through the
// centre of a 33 x 33 target: the centre pixel shades world position p with world normal d, and
// Lambert shows (albedo / pi) (pi E) = E.
import * as THREE from 'three';
import { EXRLoader } from 'three/addons/loaders/EXRLoader.js';
import { KTX2Loader } from 'three/addons/loaders/KTX2Loader.js';
import { lightProbeGridFromTexture, gridBoundsFromExrHeader, gridBoundsFromKtx2 } from '/runtime/web/zhc_threejs_grid.mjs';

// threejs_grid_files_webgpu.html sets window.zhcWebGPU and maps 'three' to three.webgpu.js:
// WebGPURenderer with three.js's WebGPU LightProbeGrid (binary16 atlas: lightProbeGridFromTexture
// rounds the EXR's float32 atlas to binary16 for it).
const WEBGPU = window.zhcWebGPU === true;

async function main() {
  const expected = await (await fetch('/work/expected.json')).json();
  const canvas = document.createElement('canvas');
  const report = { webgpu: WEBGPU, three: THREE.REVISION, files: [] };
  let renderer, GridClass;
  if (WEBGPU) {
    renderer = new THREE.WebGPURenderer({ canvas, antialias: false });
    await renderer.init();
    report.webgpuBackend = renderer.backend.isWebGPUBackend === true;
    GridClass = (await import('three/addons/lighting/LightProbeGrid.js')).LightProbeGrid;
  } else {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    const gl = renderer.getContext();
    report.webgl2 = gl instanceof WebGL2RenderingContext;
    report.floatLinear = !!gl.getExtension('OES_texture_float_linear');
    GridClass = (await import('three/addons/lighting/LightProbeGridWebGL.js')).LightProbeGridWebGL;
  }
  renderer.toneMapping = THREE.NoToneMapping;
  const SIZE = 33, MID = 16;
  const rt = new (WEBGPU ? THREE.RenderTarget : THREE.WebGLRenderTarget)(SIZE, SIZE, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
  let px = new Float32Array(4);
  const throwsWith = (f, re) => { try { f(); return false; } catch (err) { return re.test(err.message); } };
  for (const f of expected.files) {
    const r = { file: f.file, samples: [] };
    let texture, bounds;
    if (f.file.endsWith('.exr')) {
      const loader = new EXRLoader().setDataType(THREE.FloatType);
      let texData;
      texture = await new Promise((resolve, reject) => loader.load(`/work/${f.file}`, (t, d) => { texData = d; resolve(t); }, undefined, reject));
      bounds = gridBoundsFromExrHeader(texData.header);
    } else {
      const bytes = await (await fetch(`/work/${f.file}`)).arrayBuffer();
      bounds = gridBoundsFromKtx2(bytes);
      const loader = new KTX2Loader().detectSupport(renderer);
      texture = await new Promise((resolve, reject) => loader.parse(bytes, resolve, reject));
      r.ktx2Data3D = texture.isData3DTexture === true && texture.type === THREE.HalfFloatType;
    }
    r.loadedType = texture.type === THREE.FloatType ? 'float' : texture.type === THREE.HalfFloatType ? 'half' : String(texture.type);
    const grid = lightProbeGridFromTexture(GridClass, texture, bounds);
    r.atlasType = grid.texture.type === THREE.FloatType ? 'float' : grid.texture.type === THREE.HalfFloatType ? 'half' : String(grid.texture.type);
    r.boundingBox = [...grid.boundingBox.min.toArray(), ...grid.boundingBox.max.toArray()];
    r.resolution = grid.resolution.toArray();
    // Refusals: bounds that do not fit the texture, a padding slice changed, a non-grid class.
    const badBounds = { volume: { ...bounds.volume, counts: [1, 1, 1] }, grid: { ...bounds.grid, resolution: [1, 1, 1] } };
    const changed = texture.clone();
    changed.image = { ...texture.image, data: texture.image.data.slice() };
    changed.image.data[0] = changed.image.data[0] === 0 ? 1 : 0;  // slice 0 is sub-volume 0's padding
    r.refusals = [
      throwsWith(() => lightProbeGridFromTexture(GridClass, texture, badBounds), /atlas is/),
      throwsWith(() => lightProbeGridFromTexture(GridClass, changed, bounds), /padding slice 0/),
      throwsWith(() => lightProbeGridFromTexture(THREE.Object3D, texture, bounds), /LightProbeGrid/),
    ];
    const spacing = bounds.volume.spacing;
    const radius = 0.05 * Math.min(...spacing);
    const mesh = new THREE.Mesh(new THREE.SphereGeometry(radius, 64, 32), new THREE.MeshLambertMaterial({ color: 0xffffff }));
    const cam = new THREE.PerspectiveCamera(20, 1, radius, 100 * radius);
    const scene = new THREE.Scene();
    scene.add(mesh, grid);
    for (const s of f.samples) {
      const d = new THREE.Vector3().fromArray(s.normal);
      const centre = new THREE.Vector3().fromArray(s.position).addScaledVector(d, -radius);
      mesh.position.copy(centre);
      mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), d);
      cam.position.copy(centre).addScaledVector(d, 6 * radius);
      cam.up.set(Math.abs(d.y) > 0.9 ? 1 : 0, Math.abs(d.y) > 0.9 ? 0 : 1, 0);
      cam.lookAt(centre);
      cam.updateMatrixWorld();
      renderer.setRenderTarget(rt);
      renderer.setClearColor(0x000000, 0);
      renderer.render(scene, cam);
      if (WEBGPU) px = await renderer.readRenderTargetPixelsAsync(rt, MID, MID, 1, 1);
      else renderer.readRenderTargetPixels(rt, MID, MID, 1, 1, px);
      renderer.setRenderTarget(null);
      r.samples.push([px[0], px[1], px[2]]);
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
console.log('zhc three.js grid files page done');
await new Promise((resolve) => setTimeout(resolve, 200));
await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
document.title = 'zhc three.js grid files test: done';
