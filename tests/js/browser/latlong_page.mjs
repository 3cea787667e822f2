// The browser side of tests/js/latlong_three.mjs: three.js's own equirectangular path, as a glTF
// viewer built on three uses it. For each map in /work/latlong_spec.json:
//  * load it with three's loader (HDRLoader for .hdr, EXRLoader for .exr), mapping
//    EquirectangularReflectionMapping;
//  * make a cube map of it with WebGLCubeRenderTarget.fromEquirectangularTexture (three's
//    CubeCamera inside) and read its six faces back (half float -> numbers);
//  * LightProbeGenerator.fromCubeRenderTarget: three's SH3 of that cube map (three's basis and
//    Y-up axes);
//  * what the viewer shows: the map as scene.background (the equirect texture and the cube render
//    target), a narrow camera looking along each of spec.dirs (three axes), the centre pixel read back.
// POSTs everything to /result.
import * as THREE from 'three';
import { HDRLoader } from 'three/addons/loaders/HDRLoader.js';
import { EXRLoader } from 'three/addons/loaders/EXRLoader.js';
import { LightProbeGenerator } from 'three/addons/lights/LightProbeGenerator.js';

async function main() {
  const spec = await (await fetch('/work/latlong_spec.json')).json();
  const canvas = document.createElement('canvas');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
  const gl = renderer.getContext();
  const report = { webgl2: gl instanceof WebGL2RenderingContext, three: THREE.REVISION, maps: [] };
  // A 4x4 float target for the background samples; a 2-degree camera so the 4x4 pixels see one
  // small patch of the sky around its axis.
  const probeTarget = new THREE.WebGLRenderTarget(4, 4, { type: THREE.FloatType });
  const camera = new THREE.PerspectiveCamera(2, 1, 0.1, 10);
  const pixels = new Float32Array(4 * 4 * 4);
  for (const m of spec.maps) {
    const loader = m.url.endsWith('.hdr') ? new HDRLoader() : new EXRLoader();
    const tex = await loader.loadAsync(m.url);
    tex.mapping = THREE.EquirectangularReflectionMapping;
    const rt = new THREE.WebGLCubeRenderTarget(m.cube, { type: THREE.HalfFloatType });
    rt.fromEquirectangularTexture(renderer, tex);
    const probe = await LightProbeGenerator.fromCubeRenderTarget(renderer, rt);
    const faces = [];
    const half = new Uint16Array(m.cube * m.cube * 4);
    for (let f = 0; f < 6; f++) {
      await renderer.readRenderTargetPixelsAsync(rt, 0, 0, m.cube, m.cube, half, f);
      faces.push(Array.from(half, (h) => THREE.DataUtils.fromHalfFloat(h)));
    }
    const backgrounds = {};
    for (const [name, background] of [['equirect', tex], ['cube', rt.texture]]) {
      const scene = new THREE.Scene();
      scene.background = background;
      const samples = [];
      for (const d of spec.dirs) {
        camera.position.set(0, 0, 0);
        camera.up.set(Math.abs(d[1]) > 0.9 ? 1 : 0, Math.abs(d[1]) > 0.9 ? 0 : 1, 0);
        camera.lookAt(d[0], d[1], d[2]);
        renderer.setRenderTarget(probeTarget);
        renderer.render(scene, camera);
        renderer.readRenderTargetPixels(probeTarget, 0, 0, 4, 4, pixels);
        const rgb = [0, 0, 0];
        for (let i = 0; i < 16; i++) for (let k = 0; k < 3; k++) rgb[k] += pixels[i * 4 + k] / 16;
        samples.push(rgb);
      }
      renderer.setRenderTarget(null);
      backgrounds[name] = samples;
    }
    report.maps.push({ name: m.name, sh: probe.sh.coefficients.map((v) => [v.x, v.y, v.z]), cube: m.cube, faces, backgrounds,
      width: tex.image.width, height: tex.image.height, flipY: tex.flipY });
    rt.dispose();
    tex.dispose();
  }
  report.errors = window.zhcErrors;
  console.log('zhc lat-long page done');
  await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
}

main().catch((e) => {
  window.zhcErrors.push('exception: ' + (e && e.stack || e));
  fetch('/result', { method: 'POST', body: JSON.stringify({ errors: window.zhcErrors }) });
});
