// The test side of examples/web (tests/js/web_example.mjs, CTest js.web_example): loaded after the
// example's own main.mjs into its unchanged page, it waits until the example has drawn a few
// frames, then stops the animation and, for 8 points of the sphere's path:
//  * renders the example's scene (the asset's meshes hidden, so nothing stands between the camera
//    and the sphere; the baked lights as the example left them) into a 33 x 33 RGBA32F target with
//    a camera looking at the sphere along the direction v from the sphere to the example's camera,
//    the sphere turned so that its pole vertex (normal exactly +Y of SphereGeometry) faces it: the
//    centre pixel is the white Lambertian surface at c + r v with normal v, i.e. zhc's E there;
//  * the same with the baked lights made visible again (the double counting the example avoids);
//  * the example's irradianceAtWorld (the plugin's irradianceAt on the decoded probes) at that point.
// Then the example's own view (its camera, 160 x 120, float target, no background): how many pixels
// the asset and the sphere cover and how many of those are lit. Posts the report to /result.
import * as THREE from 'three';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function main() {
  const report = { errors: window.zhcErrors, three: THREE.REVISION };
  // Up to 120 s for 5 frames; an error in the page (the example failed to start) ends the wait.
  for (let i = 0; i < 1200 && !(window.zhcExample && window.zhcExample.frames >= 5) && window.zhcErrors.length === 0; i++) await sleep(100);
  const ex = window.zhcExample;
  report.ready = !!ex && ex.frames >= 5;
  if (!report.ready) return report;
  const { renderer, scene, mover, volume, compact } = ex;
  report.sameThree = ex.THREE === THREE;
  report.frames = ex.frames;
  report.moverPositions = ex.moverPositions;
  report.bakedLights = ex.bakedLights.map((l) => ({ type: l.type, visible: l.visible }));
  report.encoding = volume.encoding;
  report.counts = [...volume.grid.counts];
  report.masked = compact.masked;
  report.planed = compact.planed;
  report.gpuBytes = compact.gpuBytes;
  const gl = renderer.getContext();
  report.webgl2 = gl instanceof WebGL2RenderingContext;
  report.colorBufferFloat = !!gl.getExtension('EXT_color_buffer_float');

  ex.pause(0);
  const hidden = [];
  scene.traverse((o) => { if (o.isMesh && o !== mover && o.visible) { o.visible = false; hidden.push(o); } });
  const background = scene.background;
  scene.background = null;
  const SIZE = 33, MID = 16;
  const rt = new THREE.WebGLRenderTarget(SIZE, SIZE, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
  const r = mover.geometry.parameters.radius;
  const cam = new THREE.PerspectiveCamera(20, 1, r, 100 * r);
  const px = new Float32Array(4);
  const shot = () => {
    renderer.setRenderTarget(rt);
    renderer.setClearColor(0x000000, 0);
    renderer.clear();
    renderer.render(scene, cam);
    renderer.readRenderTargetPixels(rt, MID, MID, 1, 1, px);
    renderer.setRenderTarget(null);
    return [px[0], px[1], px[2], px[3]];
  };
  report.samples = [];
  for (let k = 0; k < 8; k++) {
    const t = (2 * Math.PI * k) / 8 + 0.3;
    ex.pause(t);
    const c = mover.position.clone();
    const v = ex.camera.position.clone().sub(c).normalize();
    mover.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), v);
    mover.updateMatrixWorld();
    cam.position.copy(c).addScaledVector(v, 6 * r);
    cam.up.set(Math.abs(v.y) > 0.9 ? 1 : 0, Math.abs(v.y) > 0.9 ? 0 : 1, 0);
    cam.lookAt(c);
    cam.updateMatrixWorld();
    const pixel = shot();
    for (const l of ex.bakedLights) l.visible = true;
    const withLights = shot();
    for (const l of ex.bakedLights) l.visible = false;
    const expected = ex.irradianceAtWorld(c.clone().addScaledVector(v, r), v);
    report.samples.push({ t, position: c.toArray(), pixel, withLights, expected });
  }
  for (const o of hidden) o.visible = true;
  mover.quaternion.identity();

  // The example's view: coverage and lit pixels.
  const W = 160, H = 120;
  const view = new THREE.WebGLRenderTarget(W, H, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
  const vcam = ex.camera.clone();
  vcam.aspect = W / H;
  vcam.updateProjectionMatrix();
  renderer.setRenderTarget(view);
  renderer.setClearColor(0x000000, 0);
  renderer.clear();
  renderer.render(scene, vcam);
  const img = new Float32Array(W * H * 4);
  renderer.readRenderTargetPixels(view, 0, 0, W, H, img);
  renderer.setRenderTarget(null);
  let covered = 0, lit = 0, finite = true;
  for (let i = 0; i < W * H; i++) {
    if (img[4 * i + 3] === 0) continue;
    covered++;
    if (img[4 * i] + img[4 * i + 1] + img[4 * i + 2] > 0) lit++;
    for (let k = 0; k < 3; k++) finite &&= Number.isFinite(img[4 * i + k]);
  }
  report.view = { pixels: W * H, covered, lit, finite };
  scene.background = background;
  return report;
}

let report;
try {
  report = await main();
} catch (e) {
  report = { errors: [...(window.zhcErrors ?? []), `exception: ${e.stack ?? e}`] };
}
console.log('zhc web example check done');
await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
