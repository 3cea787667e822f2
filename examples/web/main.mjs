// A glTF baked by zhc, lit by its own probes in three.js (WebGL2):
//
//   zhc bake ../hall.gltf -o hall.glb -r zh3_q16        index.html
//   zhc bake ../hall.gltf -o hall.zhp -r zh3_q16        index.html?gltf=../hall.gltf&zhp=hall.zhp
//
// 1. GLTFLoader with ZhcLightProbesPlugin loads the asset and decodes its ZHC_light_probes volume
//    (or, with ?zhp=, the probes come from a .zhp file next to an asset that has none);
// 2. the asset's KHR_lights_punctual lights are hidden: their light is already in the probes;
// 3. the compact volume (the probes' stored bytes in a 3D texture, decoded in the shader) lights the
//    asset's materials and a white sphere that moves through the volume: each fragment gets the
//    irradiance of the 8 probes around it, so the sphere's shading follows it from cell to cell.
//
// The page's state is on window.zhcExample (the test tests/js/web_example.mjs samples it).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { volumeFromZhp, volumeIrradiance } from '@zhc/runtime';
import { ZhcLightProbesPlugin } from '@zhc/runtime/three';
import { compactVolumeFromZhp, patchMaterialWithVolume } from '@zhc/runtime/volume';

const query = new URLSearchParams(location.search);
const url = query.get('gltf') ?? './hall.glb';
const zhpUrl = query.get('zhp');
const info = document.getElementById('info');

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.toneMapping = THREE.ACESFilmicToneMapping;

// 1. Load: the plugin decodes every volume into gltf.userData.zhcLightProbes.
const loader = new GLTFLoader();
loader.register((parser) => new ZhcLightProbesPlugin(parser));
const gltf = await loader.loadAsync(url);
// The probes: the asset's first volume, or a .zhp file's grid.
let volume, compact, sample;
if (zhpUrl) {
  const response = await fetch(zhpUrl);
  if (!response.ok) throw new Error(`${zhpUrl}: HTTP ${response.status}`);
  const bytes = new Uint8Array(await response.arrayBuffer());
  // A .zhp grid is in zhc's axes (Z up): (x, y, z)_glTF = (y, z, x)_zhc places it in the scene.
  const zhcToGltf = new THREE.Matrix4().set(0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 0, 0, 1);
  compact = compactVolumeFromZhp(bytes, { THREE, matrixWorld: zhcToGltf });
  const decoded = volumeFromZhp(bytes);
  volume = { name: zhpUrl, encoding: compact.encoding, grid: decoded };
  sample = (p, n) => volumeIrradiance(decoded, p, n);
} else {
  volume = gltf.userData.zhcLightProbes?.[0];
  if (!volume || volume.layout !== 'grid') throw new Error(`${url}: no ZHC_light_probes grid volume (bake with zhc bake ... -o ${url})`);
  sample = (p, n) => volume.irradianceAt(p, n);
}

// 2. The baked punctual lights: GLTFLoader creates them from KHR_lights_punctual, and the bake put
// their light into the probes. Hidden lights light nothing (and keep their nodes and targets).
const bakedLights = [];
gltf.scene.traverse((object) => { if (object.isLight) bakedLights.push(object); });
for (const light of bakedLights) light.visible = false;

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x202428);
scene.add(gltf.scene);
scene.updateMatrixWorld(true);

// A primitive without a material gets glTF's default one, fully metallic: it shows no diffuse light
// at all (examples/hall.gltf has no materials). Such meshes get a white diffuse material here.
const diffuse = new THREE.MeshStandardMaterial({ color: 0xffffff, metalness: 0, roughness: 1 });
gltf.scene.traverse((object) => {
  if (object.isMesh && gltf.parser.associations.get(object.material)?.materials === undefined) object.material = diffuse;
});

// 3. The compact volume (zh3_q16, sh3_q28, sh2_q and the other packed grids; `zhc bake -r zh3_q16`),
// placed by the volume's node; every material of the asset is patched once.
compact ??= volume.compactVolume();
const patched = new Set();
gltf.scene.traverse((object) => {
  if (!object.isMesh) return;
  for (const material of Array.isArray(object.material) ? object.material : [object.material]) {
    if (patched.has(material)) continue;
    patchMaterialWithVolume(material, compact, THREE);
    patched.add(material);
  }
});

// The grid's box in world space (the node's transform applied to its corners).
const { origin, spacing, counts } = volume.grid;
const box = new THREE.Box3();
for (let c = 0; c < 8; c++) {
  const corner = [0, 1, 2].map((a) => origin[a] + ((c >> a) & 1) * (counts[a] - 1) * spacing[a]);
  box.expandByPoint(new THREE.Vector3(...corner).applyMatrix4(new THREE.Matrix4().fromArray(compact.matrixWorld)));
}
const centre = box.getCenter(new THREE.Vector3());
const size = box.getSize(new THREE.Vector3());

// The moving object: a white Lambertian sphere lit by the same volume.
const radius = 0.08 * Math.min(size.x, size.z);
const mover = new THREE.Mesh(new THREE.SphereGeometry(radius, 64, 32),
  patchMaterialWithVolume(new THREE.MeshLambertMaterial({ color: 0xffffff }), compact, THREE));
mover.name = 'mover';
scene.add(mover);

// Its path: an ellipse through the volume at the box's mid height, 0.7 of the way to its sides.
function pathAt(t) {
  return new THREE.Vector3(centre.x + 0.35 * size.x * Math.cos(t), centre.y, centre.z + 0.35 * size.z * Math.sin(t));
}
// Irradiance at a world point for a world normal, from the decoded probes (in the grid's frame).
// Points map by the inverse of the node's matrixWorld M, normals by the transpose of M's 3x3.
const worldToNode = new THREE.Matrix4().fromArray(compact.worldToGrid);
const normalToNode = new THREE.Matrix3().setFromMatrix4(new THREE.Matrix4().fromArray(compact.matrixWorld)).transpose();
function irradianceAtWorld(point, normal) {
  const p = point.clone().applyMatrix4(worldToNode);
  const n = normal.clone().applyMatrix3(normalToNode);
  return sample(p.toArray(), n.toArray());
}

const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 200);
camera.position.set(centre.x, centre.y + 0.35 * size.y, centre.z + 1.4 * Math.max(size.z, 0.5 * size.x));
camera.lookAt(centre);

function resize() {
  const w = canvas.clientWidth || 640, h = canvas.clientHeight || 480;
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();

const state = {
  THREE, renderer, scene, camera, gltf, volume, compact, mover, bakedLights, pathAt, irradianceAtWorld,
  frames: 0, paused: false, moverPositions: [],
  // Stops the animation with the sphere at path parameter t.
  pause(t) { this.paused = true; mover.position.copy(pathAt(t)); mover.updateMatrixWorld(); },
};
window.zhcExample = state;

const timer = new THREE.Timer();
function frame(timestamp) {
  if (state.paused) return;
  timer.update(timestamp);
  const t = 0.4 * timer.getElapsed();
  mover.position.copy(pathAt(t));
  const e = irradianceAtWorld(mover.position, new THREE.Vector3(0, 1, 0));
  info.textContent = `${volume.name ?? 'volume'}: ${volume.encoding} ${counts.join('x')} grid, ${compact.gpuBytes} bytes on the GPU\n` +
    `${bakedLights.length} baked punctual light(s) hidden\n` +
    `sphere at (${mover.position.toArray().map((x) => x.toFixed(2)).join(', ')}): E(up) = ${e.map((x) => x.toFixed(3)).join(', ')}`;
  renderer.render(scene, camera);
  state.frames++;
  if (state.moverPositions.length < 8) state.moverPositions.push(mover.position.toArray());
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);
console.log('zhc example running');
