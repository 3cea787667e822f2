// Writes zhc's glTF real-world test set (tests/data/gltf) with glTF-Transform (npm
// @gltf-transform/core + extensions, meshoptimizer's and Draco's own npm encoders) and, when it
// is installed, Debian's gltfpack. The files are committed; this script documents how they were
// made and remakes them:  node tests/js/make_gltf_corpus.mjs tests/data/gltf
//
// One scene, written in several variants another program encodes: a floor, a floating box and a
// wall (glTF axes, +Y up), a point light and a directional light, and explicit probes in
// extras.zhc (zhc axes) so every variant bakes the same probe positions.
//   gt_list.glb / gt_list.gltf(+.bin, tex.png)   triangle lists (indexed), the reference
//   gt_strip.glb        TRIANGLE_STRIP (one strip per object, joined by degenerate triangles)
//   gt_fan.glb          TRIANGLE_FAN (one fan per quad face; one of them unindexed)
//   gt_meshopt.glb      EXT_meshopt_compression (lossless: float positions, no filter),
//                       with its uri-less fallback buffer
//   gt_meshopt_strip.glb  strips + meshopt (index sequence mode)
//   gt_draco.glb        KHR_draco_mesh_compression (edgebreaker, 16-bit positions)
//   gp_meshopt.glb      gltfpack -c -noq of gt_list.glb (if gltfpack is installed)
//   gp_list.glb         gltfpack -noq of gt_list.glb (gltfpack's own plain version)
//   gp_quant.glb, gp_quant_norm.glb, gp_quant_meshopt.glb, gp_fallback.gltf (+.bin,
//                       .fallback.bin)  gltfpack's quantised defaults (KHR_mesh_quantization)
// Variants edited from those (hostile or unusual but legal):
//   noscene.gltf        no `scene`/`scenes` (legal: nothing needs rendering)
//   datauri_image.gltf  the image as a data: URI
//   missing_bin.gltf    buffer uri names a file that does not exist
//   version3.gltf       asset.version "3.0"; minversion.gltf asset.minVersion "2.1"
//   noversion.gltf      asset without version
import { Document, NodeIO, Primitive } from '@gltf-transform/core';
import { KHRLightsPunctual, Light, KHRDracoMeshCompression, EXTMeshoptCompression, ALL_EXTENSIONS } from '@gltf-transform/extensions';
import draco3d from 'draco3dgltf';
import { MeshoptEncoder, MeshoptDecoder } from 'meshoptimizer';
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import { execFileSync } from 'node:child_process';

const out = process.argv[2] || 'tests/data/gltf';
fs.mkdirSync(out, { recursive: true });

// ---- geometry: quads (a, b, c, d counter-clockwise seen from outside) -----------------------
const quads = [];
const floor = [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]];
quads.push({ obj: 'floor', q: floor });
const box = (x0, y0, z0, x1, y1, z1) => [
  [[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]], // bottom
  [[x0, y1, z0], [x0, y1, z1], [x1, y1, z1], [x1, y1, z0]], // top
  [[x0, y0, z0], [x0, y1, z0], [x1, y1, z0], [x1, y0, z0]], // -z
  [[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], // +z
  [[x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0]], // -x
  [[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]], // +x
];
for (const q of box(-0.5, 1, -0.5, 0.5, 1.6, 0.5)) quads.push({ obj: 'box', q });
quads.push({ obj: 'wall', q: [[1.5, 0, -1], [1.5, 2, -1], [1.5, 2, 1], [1.5, 0, 1]] });
const objects = ['floor', 'box', 'wall'];

// Probes (zhc axes, +Z up): a 4 x 4 x 3 grid under, beside and above the box.
const extras = { zhc: { probes: { grid: { min: [-1.5, -1.5, 0.3], max: [1.5, 1.5, 2.4], counts: [4, 4, 3] } } } };

async function makeIO() {
  return new NodeIO().registerExtensions(ALL_EXTENSIONS).registerDependencies({
    'draco3d.encoder': await draco3d.createEncoderModule(),
    'draco3d.decoder': await draco3d.createDecoderModule(),
    'meshopt.encoder': MeshoptEncoder,
    'meshopt.decoder': MeshoptDecoder,
  });
}

function png2x2() {
  const crc = (b) => { const v = Buffer.alloc(4); v.writeUInt32BE(zlib.crc32(b) >>> 0); return v; };
  const chunk = (type, data) => {
    const len = Buffer.alloc(4); len.writeUInt32BE(data.length);
    const td = Buffer.concat([Buffer.from(type, 'ascii'), data]);
    return Buffer.concat([len, td, crc(td)]);
  };
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(2, 0); ihdr.writeUInt32BE(2, 4); ihdr[8] = 8; ihdr[9] = 2; // 8-bit RGB
  const raw = Buffer.from([0, 255, 0, 0, 0, 255, 0, 0, 0, 0, 255, 255, 255, 255]);
  return Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk('IHDR', ihdr),
    chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]);
}

// mode: 'list' | 'strip' | 'fan'
function build(mode, { texture = false } = {}) {
  const doc = new Document();
  doc.getRoot().setExtras(extras);
  const buffer = doc.createBuffer();
  const scene = doc.createScene('scene');
  doc.getRoot().setDefaultScene(scene);
  let material = null;
  if (texture) {
    const tex = doc.createTexture('checker').setImage(png2x2()).setMimeType('image/png').setURI('tex.png');
    material = doc.createMaterial('checker').setBaseColorTexture(tex);
  }
  const mesh = doc.createMesh('scene mesh');
  for (const obj of objects) {
    const qs = quads.filter((x) => x.obj === obj).map((x) => x.q);
    const pos = [];
    for (const q of qs) for (const v of q) pos.push(...v);
    const positions = doc.createAccessor(obj + ' positions').setType('VEC3').setArray(new Float32Array(pos)).setBuffer(buffer);
    const add = (indices, m, acc = positions) => {
      const p = doc.createPrimitive().setAttribute('POSITION', acc).setMode(m);
      if (indices) p.setIndices(doc.createAccessor().setType('SCALAR').setArray(new Uint16Array(indices)).setBuffer(buffer));
      if (material) {
        // a textured material needs TEXCOORD_0: (0,0) (1,0) (1,1) (0,1) around each quad
        const uv = [];
        for (let i = 0; i < acc.getCount() / 4; ++i) uv.push(0, 0, 1, 0, 1, 1, 0, 1);
        p.setAttribute('TEXCOORD_0', doc.createAccessor().setType('VEC2').setArray(new Float32Array(uv)).setBuffer(buffer));
        p.setMaterial(material);
      }
      mesh.addPrimitive(p);
    };
    if (mode === 'list') {
      const idx = [];
      qs.forEach((_, k) => { const a = 4 * k, b = a + 1, c = a + 2, d = a + 3; idx.push(b, c, a, a, c, d); });
      add(idx, Primitive.Mode.TRIANGLES);
    } else if (mode === 'strip') {
      // quad [b, c, a, d] -> (b, c, a), (a, c, d); quads joined by repeating the last and the
      // next first vertex (two degenerate... four degenerate triangles, parity kept).
      const idx = [];
      qs.forEach((_, k) => {
        const a = 4 * k, b = a + 1, c = a + 2, d = a + 3;
        if (idx.length) idx.push(idx[idx.length - 1], b);
        idx.push(b, c, a, d);
      });
      add(idx, Primitive.Mode.TRIANGLE_STRIP);
    } else {
      // quad as fan [a, b, c, d] -> (b, c, a), (c, d, a); the wall's fan is unindexed.
      qs.forEach((q, k) => {
        const a = 4 * k;
        if (obj === 'wall') {
          const own = doc.createAccessor('wall fan').setType('VEC3').setArray(new Float32Array(q.flat())).setBuffer(buffer);
          add(null, Primitive.Mode.TRIANGLE_FAN, own);
        } else {
          add([a, a + 1, a + 2, a + 3], Primitive.Mode.TRIANGLE_FAN);
        }
      });
    }
  }
  scene.addChild(doc.createNode('geometry').setMesh(mesh));
  const lights = doc.createExtension(KHRLightsPunctual);
  const point = lights.createLight('lamp').setType(Light.Type.POINT).setIntensity(40).setColor([1, 0.9, 0.8]);
  scene.addChild(doc.createNode('lamp').setTranslation([0.3, 2.6, 0.2]).setExtension('KHR_lights_punctual', point));
  const sun = lights.createLight('sun').setType(Light.Type.DIRECTIONAL).setIntensity(3).setColor([1, 1, 1]);
  // -Z rotated: pointing down and sideways (unit quaternion).
  const s = Math.SQRT1_2;
  scene.addChild(doc.createNode('sun').setRotation([-0.5, 0.1, 0.1, 0.85].map((x) => x / Math.hypot(0.5, 0.1, 0.1, 0.85))).setExtension('KHR_lights_punctual', sun));
  void s;
  return doc;
}

const io = await makeIO();
async function write(name, doc) {
  await io.write(path.join(out, name), doc);
  console.log('wrote', name);
}

await write('gt_list.glb', build('list'));
await write('gt_list.gltf', build('list', { texture: true }));
await write('gt_strip.glb', build('strip'));
await write('gt_fan.glb', build('fan'));
{
  const d = build('list');
  d.createExtension(EXTMeshoptCompression).setRequired(true).setEncoderOptions({ method: EXTMeshoptCompression.EncoderMethod.QUANTIZE });
  await write('gt_meshopt.glb', d);
}
{
  const d = build('strip');
  d.createExtension(EXTMeshoptCompression).setRequired(true).setEncoderOptions({ method: EXTMeshoptCompression.EncoderMethod.QUANTIZE });
  await write('gt_meshopt_strip.glb', d);
}
{
  const d = build('list');
  d.createExtension(KHRDracoMeshCompression).setRequired(true).setEncoderOptions({
    method: KHRDracoMeshCompression.EncoderMethod.EDGEBREAKER,
    quantizationBits: { POSITION: 16 },
  });
  await write('gt_draco.glb', d);
}

// gltfpack (Debian), when installed: its own plain and meshopt versions of the reference.
try {
  execFileSync('gltfpack', ['-noq', '-i', path.join(out, 'gt_list.glb'), '-o', path.join(out, 'gp_list.glb')], { stdio: 'inherit' });
  execFileSync('gltfpack', ['-c', '-noq', '-i', path.join(out, 'gt_list.glb'), '-o', path.join(out, 'gp_meshopt.glb')], { stdio: 'inherit' });
  // gltfpack's defaults: KHR_mesh_quantization (14-bit UNSIGNED_SHORT positions, dequantised by
  // the node's scale/translation), also normalized (-vpn), also with meshopt (-c), and a .gltf
  // with an external fallback buffer file (-cf).
  execFileSync('gltfpack', ['-i', path.join(out, 'gt_list.glb'), '-o', path.join(out, 'gp_quant.glb')], { stdio: 'inherit' });
  execFileSync('gltfpack', ['-vpn', '-i', path.join(out, 'gt_list.glb'), '-o', path.join(out, 'gp_quant_norm.glb')], { stdio: 'inherit' });
  execFileSync('gltfpack', ['-c', '-i', path.join(out, 'gt_list.glb'), '-o', path.join(out, 'gp_quant_meshopt.glb')], { stdio: 'inherit' });
  execFileSync('gltfpack', ['-cf', '-i', path.join(out, 'gt_list.glb'), '-o', path.join(out, 'gp_fallback.gltf')], { stdio: 'inherit' });
  console.log('wrote gp_list.glb gp_meshopt.glb gp_quant*.glb gp_fallback.gltf');
} catch (e) {
  console.log('gltfpack not run:', e.message);
}

// ---- variants edited from gt_list.gltf --------------------------------------------------------
const base = JSON.parse(fs.readFileSync(path.join(out, 'gt_list.gltf'), 'utf8'));
const variant = (name, edit) => {
  const j = structuredClone(base);
  edit(j);
  fs.writeFileSync(path.join(out, name), JSON.stringify(j, null, 2) + '\n');
  console.log('wrote', name);
};
variant('noscene.gltf', (j) => { delete j.scene; delete j.scenes; });
variant('datauri_image.gltf', (j) => {
  j.images[0].uri = 'data:image/png;base64,' + fs.readFileSync(path.join(out, 'tex.png')).toString('base64');
});
variant('datauri_webp_image.gltf', (j) => {
  // a MIME type tinygltf does not know as a data URI (the bytes are not decoded by zhc)
  j.images[0].uri = 'data:image/webp;base64,UklGRhoAAABXRUJQVlA4TA0AAAAvAAAAEAcQERGIiP4HAA==';
  j.images[0].mimeType = 'image/webp';
});
variant('missing_bin.gltf', (j) => { j.buffers[0].uri = 'missing.bin'; });
variant('missing_image.gltf', (j) => { j.images[0].uri = 'missing.png'; });
variant('version3.gltf', (j) => { j.asset.version = '3.0'; });
variant('minversion.gltf', (j) => { j.asset.minVersion = '2.1'; });
variant('noversion.gltf', (j) => { delete j.asset.version; });
