// Writes zhc's EXT_mesh_gpu_instancing test files (tests/data/gltf/gi_*.glb, gp_instanced.glb)
// with glTF-Transform (npm @gltf-transform/core + extensions) and, when it is installed, Debian's
// gltfpack. The files are committed; this script documents how they were made and remakes them:
//   node tests/js/make_instancing_corpus.mjs tests/data/gltf
//
// One scene: a unit box mesh (12 triangles) drawn 125 times (5 x 5 x 5, each with its own
// translation, rotation and scale) under a parent node with a transform of its own, a sun
// (directional light, tilted) and a point light; no extras, so zhc places its default probe grid
// over the bounds of every drawn box.
//   gi_nodes.glb        125 plain nodes sharing the mesh (the reference)
//   gi_float.glb        one node + EXT_mesh_gpu_instancing, TRANSLATION / ROTATION / SCALE FLOAT
//   gi_rot_short.glb    the same with ROTATION as SHORT normalized
//   gi_rot_byte.glb     the same with ROTATION as BYTE normalized
//   gi_nodes_uniform.glb  gi_nodes with uniform scales (gltfpack's input: gltfpack folds the parent
//                       transform into the instances, which is exact only for uniform scale)
//   gp_instanced.glb    gltfpack -mi -noq of gi_nodes_uniform.glb (gltfpack's own instancing; it
//                       writes ROTATION as SHORT normalized), if gltfpack is installed
// Variants the extension does not allow (zhc refuses them naming the attribute):
//   gi_scale_byte.glb   SCALE as BYTE (the extension allows FLOAT only): exit 5
//   gi_count.glb        ROTATION with 124 elements against 125 translations: exit 4
// Every value is a float32 (Math.fround), so node TRS and accessor values are the same numbers.
import { Document, NodeIO } from '@gltf-transform/core';
import { ALL_EXTENSIONS, EXTMeshGPUInstancing, KHRLightsPunctual } from '@gltf-transform/extensions';
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';

const out = process.argv[2] || 'tests/data/gltf';
fs.mkdirSync(out, { recursive: true });
const f = Math.fround;

// The 125 instance transforms (glTF axes, +Y up).
const instances = [];
for (let i = 0; i < 5; i++)
  for (let j = 0; j < 5; j++)
    for (let k = 0; k < 5; k++) {
      const axis = [i - 2, 1, k - 2];
      const len = Math.hypot(...axis);
      const angle = 0.3 * (i + 2 * j + 3 * k);
      const s = Math.sin(angle / 2) / len;
      instances.push({
        t: [f(i * 2.5), f(j * 2.2 + 0.5), f(k * 2.5)],
        r: [f(axis[0] * s), f(axis[1] * s), f(axis[2] * s), f(Math.cos(angle / 2))],
        s: [f(1 + 0.1 * i), f(1 + 0.05 * j), f(0.8 + 0.1 * k)],
      });
    }

// variant: 'nodes' | 'nodes_uniform' | 'float' | 'short' | 'byte' | 'scale_byte' | 'count'
function makeDoc(variant) {
  const doc = new Document();
  const buffer = doc.createBuffer();
  const box = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]];
  const idx = [0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3];
  const position = doc.createAccessor('box positions').setType('VEC3').setArray(new Float32Array(box.flat())).setBuffer(buffer);
  const indices = doc.createAccessor('box indices').setType('SCALAR').setArray(new Uint16Array(idx)).setBuffer(buffer);
  const mesh = doc.createMesh('box').addPrimitive(doc.createPrimitive().setAttribute('POSITION', position).setIndices(indices));
  const scene = doc.createScene('instances');
  const group = doc.createNode('group').setTranslation([f(1), f(0.5), f(-2)]).setRotation([0, f(Math.sin(0.25)), 0, f(Math.cos(0.25))]);
  scene.addChild(group);
  if (variant === 'nodes' || variant === 'nodes_uniform') {
    instances.forEach((x, n) => group.addChild(doc.createNode(`box ${n}`).setMesh(mesh).setTranslation(x.t).setRotation(x.r)
      .setScale(variant === 'nodes' ? x.s : [x.s[0], x.s[0], x.s[0]])));
  } else {
    const ext = doc.createExtension(EXTMeshGPUInstancing).setRequired(true);
    const count = variant === 'count' ? instances.length - 1 : instances.length;
    const t = doc.createAccessor('instance translations').setType('VEC3').setBuffer(buffer)
      .setArray(new Float32Array(instances.flatMap((x) => x.t)));
    let r;
    const rot = instances.slice(0, count).flatMap((x) => x.r);
    if (variant === 'short') r = doc.createAccessor().setArray(new Int16Array(rot.map((v) => Math.round(v * 32767)))).setNormalized(true);
    else if (variant === 'byte') r = doc.createAccessor().setArray(new Int8Array(rot.map((v) => Math.round(v * 127)))).setNormalized(true);
    else r = doc.createAccessor().setArray(new Float32Array(rot));
    r.setName('instance rotations').setType('VEC4').setBuffer(buffer);
    const scales = instances.flatMap((x) => x.s);
    const s = (variant === 'scale_byte'
      ? doc.createAccessor().setArray(new Int8Array(scales.map((v) => Math.round(v * 10))))
      : doc.createAccessor().setArray(new Float32Array(scales))).setName('instance scales').setType('VEC3').setBuffer(buffer);
    const batch = ext.createInstancedMesh().setAttribute('TRANSLATION', t).setAttribute('ROTATION', r).setAttribute('SCALE', s);
    group.addChild(doc.createNode('boxes').setMesh(mesh).setExtension('EXT_mesh_gpu_instancing', batch));
  }
  const lights = doc.createExtension(KHRLightsPunctual);
  const sun = lights.createLight('sun').setType('directional').setIntensity(f(3)).setColor([1, f(0.9), f(0.8)]);
  // The sun shines down its node's -Z: tilt -Z towards -Y (down) and a little sideways.
  group.addChild(doc.createNode('sun').setExtension('KHR_lights_punctual', sun)
    .setRotation([f(-0.5), f(0.1), 0, f(Math.sqrt(1 - 0.25 - 0.01))]));
  const bulb = lights.createLight('bulb').setType('point').setIntensity(f(20));
  scene.addChild(doc.createNode('bulb').setExtension('KHR_lights_punctual', bulb).setTranslation([f(6), f(14), f(5)]));
  return doc;
}

const io = new NodeIO().registerExtensions(ALL_EXTENSIONS);
const names = { nodes: 'gi_nodes', nodes_uniform: 'gi_nodes_uniform', float: 'gi_float', short: 'gi_rot_short', byte: 'gi_rot_byte', scale_byte: 'gi_scale_byte', count: 'gi_count' };
for (const [variant, name] of Object.entries(names)) {
  await io.write(path.join(out, `${name}.glb`), makeDoc(variant));
  console.log(`${name}.glb`);
}

let gltfpack = null;
try {
  execFileSync('gltfpack', ['-h'], { stdio: 'ignore' });
  gltfpack = 'gltfpack';
} catch (e) {
  if (e.status !== undefined && e.status !== null) gltfpack = 'gltfpack'; // -h exits non-zero but ran
}
if (gltfpack) {
  execFileSync(gltfpack, ['-i', path.join(out, 'gi_nodes_uniform.glb'), '-o', path.join(out, 'gp_instanced.glb'), '-mi', '-noq'], { stdio: 'inherit' });
  console.log('gp_instanced.glb');
} else {
  console.log('gltfpack not installed: gp_instanced.glb not remade');
}
