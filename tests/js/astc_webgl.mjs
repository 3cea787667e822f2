// ASTC lightmap targets read by other programs (CTest: js.astc_webgl).
// Usage: node astc_webgl.mjs ZHC ZHC_ASTC_TEXELS WORK_DIR ENVMAP_DIR [CHROMIUM]
//
//  1. For each of the eight sample maps: `zhc lightmap synth` (a 38 x 30 sphere lightmap: partial
//     blocks at the right and bottom edges for every footprint) and `zhc lightmap encode` to
//     astc-ldr 4x4, astc-ldr 6x6 and astc (HDR) 4x4;
//  2. ktx-parse (the npm KTX 2.0 parser) reads every file: vkFormat, size, one level, the DFD's ASTC
//     colour model (162) and footprint, the LDR range key (runtime/web's parseIzLog2Range); the
//     files rewritten by ktx-parse's own writer decode in zhc to the same lightmap;
//  3. tests/runtime_c/zhc_astc_texels decodes both textures with astcenc (the encoder's twin) and
//     evaluates runtime/zhc_runtime.h's zhc_irradz_irradiance_astc at a random tangent normal per texel;
//     runtime/web's irradzIrradianceAstc on the same texels must agree (V8's Math.pow / atan2 / sin /
//     cos against glibc's: at most 1 float ulp, counted);
//  4. headless Chromium's WebGL2 on SwiftShader (WEBGL_compressed_texture_astc, profile "ldr") decodes
//     every LDR texture, an independent ASTC decoder: texel for texel against astcenc's, within
//     the bound stated below. HDR textures only if the extension lists the "hdr" profile;
//  5. runtime/zhc.wgsl's IrradZ functions (zhcIrradZIzFromLdr, zhcIrradZIrradianceAstc) in Chromium's
//     WebGPU (SwiftShader) on astcenc's texels of every case, both models, against the JS runtime:
//     I_z through the LDR range within 8 u (3 + 3|x|) (2^x + 2^lo) (exp2's 3 + 2|x| ulp and the
//     roundings of x; HDR: passed through exactly), the irradiance within that error times
//     F = 1 + (1 + 1/d_z)/d_z plus 16 u |I_z| F (the bound of test_runtime_gl's IrradZ test).
//
// LDR bound: astcenc returns the specification's decode, the unorm16 value as float16; a decoder
// with 8-bit intermediate precision (decode_unorm8 behaviour) differs by at most half an 8-bit
// step plus the float16 rounding: |webgl - astcenc| <= 1/510 + 2^-11.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { read, write } from 'ktx-parse';
import { makeRand, checker, ulpDiff, freshWork, repoRoot } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';
import { irradzIrradianceAstc, parseIzLog2Range, izFromLdr, decodeHemioct } from '../../runtime/web/zhc_runtime.mjs';

const [zhc, texelsTool, workArg, envmapDir, chromiumArg] = process.argv.slice(2);
if (!zhc || !texelsTool || !workArg || !envmapDir) {
  console.error('usage: node astc_webgl.mjs ZHC ZHC_ASTC_TEXELS WORK_DIR ENVMAP_DIR [CHROMIUM]');
  process.exit(2);
}
const chromium = chromiumArg || '/usr/bin/chromium';
const work = freshWork(workArg);
const here = path.dirname(fileURLToPath(import.meta.url));
const repo = repoRoot;
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28 }).toString();

const GL_ASTC = { '4x4': 0x93b0, '5x5': 0x93b2, '6x6': 0x93b4, '8x8': 0x93b7 };  // COMPRESSED_RGBA_ASTC_NxN_KHR
const VK_UNORM = { '4x4': 157, '5x5': 161, '6x6': 165, '8x8': 171 }, VK_SFLOAT = { '4x4': 1000066000, '5x5': 1000066002, '6x6': 1000066004, '8x8': 1000066007 };
const WIDTH = 38, HEIGHT = 30, N = WIDTH * HEIGHT;
const maps = fs.readdirSync(envmapDir).filter((f) => f.endsWith('.exr')).sort();
check(maps.length === 8, `eight sample maps in ${envmapDir} (found ${maps.length})`);
const variants = [{ target: 'astc-ldr', fp: '4x4' }, { target: 'astc-ldr', fp: '6x6' }, { target: 'astc', fp: '4x4' }];
const textures = [], cases = [];
let jsExact = 0, jsTotal = 0, jsWorstUlp = 0;
for (const map of maps) {
  const name = path.basename(map, '.exr');
  run('lightmap', 'synth', path.join(envmapDir, map), '-o', W(`${name}_lm.exr`), '--size', String(WIDTH), '--height', String(HEIGHT));
  for (const v of variants) {
    const tag = `${name}_${v.target}_${v.fp}`;
    run('lightmap', 'encode', W(`${name}_lm.exr`), '-o', W(tag), '--target', v.target, '--footprint', v.fp);
    // 2. ktx-parse reads both files.
    let range = null;
    for (const part of ['iz', 'dwa']) {
      const k = read(new Uint8Array(fs.readFileSync(W(`${tag}.${part}.ktx2`))));
      const hdr = part === 'iz' && v.target === 'astc';
      check(k.vkFormat === (hdr ? VK_SFLOAT[v.fp] : VK_UNORM[v.fp]), `${tag}.${part}: ktx-parse vkFormat ${k.vkFormat}`);
      check(k.pixelWidth === WIDTH && k.pixelHeight === HEIGHT && k.levels.length === 1, `${tag}.${part}: ktx-parse size and one level`);
      const [bx, by] = v.fp.split('x').map(Number);
      const blocks = Math.ceil(WIDTH / bx) * Math.ceil(HEIGHT / by);
      check(k.levels[0].levelData.byteLength === 16 * blocks, `${tag}.${part}: level data is ${blocks} blocks`);
      const dfd = k.dataFormatDescriptor[0];
      check(dfd.colorModel === 162 && dfd.texelBlockDimension[0] === bx - 1 && dfd.texelBlockDimension[1] === by - 1,
        `${tag}.${part}: DFD colour model ASTC and footprint ${v.fp}`);
      check(dfd.samples.length === 1 && dfd.samples[0].bitLength === 127, `${tag}.${part}: DFD one 128-bit sample`);
      if (part === 'iz' && v.target === 'astc-ldr') {
        const kv = k.keyValue['zhc.iz_log2_range'];
        check(kv instanceof Uint8Array, `${tag}.iz: key zhc.iz_log2_range present`);
        range = parseIzLog2Range(kv);
      }
      const file = `${tag}.${part}.bin`;
      fs.writeFileSync(W(file), k.levels[0].levelData);
      textures.push({ name: `${tag}.${part}`, file, width: WIDTH, height: HEIGHT, glFormat: GL_ASTC[v.fp], hdr });
    }
    // 2b. The same textures as another writer lays them out (ktx-parse's write: its own key/value
    // order, padding and level alignment): zhc reads them to the same decoded lightmap.
    for (const part of ['iz', 'dwa'])
      fs.writeFileSync(W(`${tag}_kp.${part}.ktx2`), write(read(new Uint8Array(fs.readFileSync(W(`${tag}.${part}.ktx2`))))));
    run('lightmap', 'decode', W(tag), '-o', W(`${tag}_dec.exr`));
    run('lightmap', 'decode', W(`${tag}_kp`), '-o', W(`${tag}_kp_dec.exr`));
    check(Buffer.compare(fs.readFileSync(W(`${tag}_dec.exr`)), fs.readFileSync(W(`${tag}_kp_dec.exr`))) === 0,
      `${tag}: the files as ktx-parse writes them decode to the same lightmap`);
    // 3. astcenc's texels and the C header's irradiance; the JS runtime on the same texels.
    const rand = makeRand(cases.length + 1);
    const normals = new Float64Array(3 * N);
    for (let i = 0; i < N; i++) {
      const z = rand(), phi = 2 * Math.PI * rand(), r = Math.sqrt(Math.max(0, 1 - z * z));
      normals.set([r * Math.cos(phi), r * Math.sin(phi), z], 3 * i);
    }
    fs.writeFileSync(W('normals.f64'), Buffer.from(normals.buffer));
    const out = W(`${tag}_ref`);
    fs.mkdirSync(out);
    const info = JSON.parse(execFileSync(texelsTool, [W(tag), W('normals.f64'), out]).toString());
    if (range) check(Math.fround(info.lo) === range[0] && Math.fround(info.hi) === range[1], `${tag}: ktx-parse's range = zhc's reader's`);
    const f32 = (f) => { const b = fs.readFileSync(path.join(out, f)); return new Float32Array(b.buffer, b.byteOffset, b.byteLength / 4); };
    const iz = f32('iz.f32'), dwa = f32('dwa.f32'), e = f32('e.f32');
    for (let i = 0; i < N; i++)
      for (let model = 0; model < 2; model++) {
        const got = irradzIrradianceAstc(Array.from(iz.subarray(4 * i, 4 * i + 3)), Array.from(dwa.subarray(4 * i, 4 * i + 3)), range, model,
          Array.from(normals.subarray(3 * i, 3 * i + 3)));
        for (let k = 0; k < 3; k++) {
          const want = e[6 * i + 3 * model + k], u = ulpDiff(got[k], want);
          jsTotal++;
          if (u === 0) jsExact++;
          jsWorstUlp = Math.max(jsWorstUlp, u);
        }
      }
    cases.push({ tag, iz, dwa, hdr: v.target === 'astc', range, normals });
  }
}
console.log(`JS irradzIrradianceAstc vs the C header: ${jsExact} of ${jsTotal} values bit-exact, worst ${jsWorstUlp} ulp`);
check(jsTotal === maps.length * variants.length * N * 6, 'every texel reconstructed');
check(jsWorstUlp <= 1, `JS reconstruction within 1 float ulp of the C header (worst ${jsWorstUlp})`);
check(jsExact >= 0.99 * jsTotal, `JS reconstruction bit-exact on at least 99% of values (${jsExact} / ${jsTotal})`);

// 4. Chromium's WebGL2 decoder.
fs.writeFileSync(W('spec.json'), JSON.stringify({ textures }));
const pages = await chromiumPages({ roots: { '/test/': path.join(here, 'browser'), '/work/': work }, work, chromium, check });
const report = await pages.runPage('astc_webgl.html', ['--use-angle=swiftshader'], 'webgl', 'zhc astc webgl page done');
pages.close();
if (report === null) process.exit(1);
check(report.errors.length === 0, `no page errors: ${report.errors.join('; ')}`);
console.log(`WebGL2: ${report.renderer}; WEBGL_compressed_texture_astc ${report.astc}, profiles [${report.profiles}]`);
check(report.webgl2 && report.astc, 'SwiftShader WebGL2 exposes WEBGL_compressed_texture_astc');
check(report.profiles.includes('ldr'), 'the extension lists the ldr profile');
const BOUND = 1 / 510 + 2 ** -11;
const stats = { ldr: { worst: 0, exact: 0, total: 0, textures: 0 }, hdr: { worst: 0, exact: 0, total: 0, textures: 0, worstRel: 0 } };
for (const c of cases)
  for (const part of ['iz', 'dwa']) {
    const hdr = c.hdr && part === 'iz';
    const t = report.textures[`${c.tag}.${part}`];
    if (hdr && !t) continue;  // no HDR profile: only astcenc decodes ASTC HDR here
    check(t && t.uploadError === 0 && t.drawError === 0, `${c.tag}.${part}: uploaded and drawn without a GL error`);
    if (!t) continue;
    const ref = part === 'iz' ? c.iz : c.dwa, s = stats[hdr ? 'hdr' : 'ldr'];
    s.textures++;
    let worst = 0;
    for (let i = 0; i < N; i++)
      for (let k = 0; k < 3; k++) {
        const a = t.texels[4 * i + k], b = ref[4 * i + k], d = Math.abs(a - b);
        s.total++;
        if (d === 0) s.exact++;
        if (!hdr && Math.abs(a * 255 - Math.round(a * 255)) < 1e-4) s.eightBit = (s.eightBit ?? 0) + 1;
        worst = Math.max(worst, d);
        if (hdr) s.worstRel = Math.max(s.worstRel, d / Math.max(Math.abs(b), 2 ** -14));
      }
    s.worst = Math.max(s.worst, worst);
    if (!hdr) check(worst <= BOUND, `${c.tag}.${part}: WebGL2 decode within ${BOUND.toExponential(3)} of astcenc (worst ${worst.toExponential(3)})`);
  }
console.log(`LDR: ${stats.ldr.textures} textures, ${stats.ldr.exact} of ${stats.ldr.total} texel values equal to astcenc's, worst |diff| ${stats.ldr.worst.toExponential(3)}; ` +
  `${stats.ldr.eightBit ?? 0} of the WebGL2 values are multiples of 1/255 (an 8-bit decode)`);
if (stats.hdr.textures > 0)
  console.log(`HDR: ${stats.hdr.textures} textures, ${stats.hdr.exact} of ${stats.hdr.total} equal, worst relative ${stats.hdr.worstRel.toExponential(3)}`);
else console.log('HDR: the extension has no hdr profile here; ASTC HDR I_z is decoded by astcenc only');
check(stats.ldr.textures === maps.length * 5, `every LDR texture compared (${stats.ldr.textures})`);

// 5. WGSL in WebGPU.
const items = [];
for (const c of cases)
  for (let i = 0; i < N; i++)
    for (let model = 0; model < 2; model++) items.push({ c, i, model });
const buf = new ArrayBuffer(48 * items.length), f32v = new Float32Array(buf), u32v = new Uint32Array(buf);
items.forEach(({ c, i, model }, j) => {
  f32v.set(c.iz.subarray(4 * i, 4 * i + 3), 12 * j);
  f32v.set(c.dwa.subarray(4 * i, 4 * i + 3), 12 * j + 3);
  f32v.set(c.normals.subarray(3 * i, 3 * i + 3), 12 * j + 6);
  f32v[12 * j + 9] = c.range ? c.range[0] : 0;
  f32v[12 * j + 10] = c.range ? c.range[1] : 1;
  u32v[12 * j + 11] = (c.range ? 1 : 0) | (model << 1);
});
fs.writeFileSync(W('irradz_items.bin'), Buffer.from(buf));
const gpuPages = await chromiumPages({ roots: { '/test/': path.join(here, 'browser'), '/work/': work, '/runtime/': path.join(repo, 'runtime') },
  work, chromium, check });
const wg = await gpuPages.runPage('irradz_wgsl.html', ['--disable-gpu-sandbox', '--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader',
  '--use-angle=swiftshader'], 'wgsl', 'zhc irradz wgsl page done');
gpuPages.close();
if (wg === null) process.exit(1);
check(wg.errors.length === 0, `WebGPU page without errors: ${wg.errors.join('; ')}`);
check(wg.webgpu && wg.compilation.length === 0, `zhc.wgsl + the IrradZ kernel compile without a message: ${wg.compilation.join('; ')}`);
const U = 2 ** -24;
let worstIz = 0, worstE = 0, failures = 0, compared = 0;
if (Array.isArray(wg.out) && wg.out.length === 6 * items.length)
  items.forEach(({ c, i, model }, j) => {
    const t = Array.from(c.iz.subarray(4 * i, 4 * i + 3)), dwa = Array.from(c.dwa.subarray(4 * i, 4 * i + 3)), n = Array.from(c.normals.subarray(3 * i, 3 * i + 3));
    const want = irradzIrradianceAstc(t, dwa, c.range, model, n);
    const dz = Math.max(decodeHemioct(dwa[0], dwa[1])[2], Math.cos((85 * Math.PI) / 180));
    const F = 1 + (1 + 1 / dz) / dz;
    for (let k = 0; k < 3; k++) {
      const izRef = c.range ? izFromLdr(t[k], c.range[0], c.range[1]) : Math.fround(t[k]);
      let izScale = 0;
      if (c.range) {
        const x = c.range[0] + Math.min(Math.max(t[k], 0), 1) * (c.range[1] - c.range[0]);
        izScale = U * (3 + 3 * Math.abs(x)) * (2 ** x + 2 ** c.range[0]);
      }
      const izErr = Math.abs(wg.out[6 * j + 3 + k] - izRef), eErr = Math.abs(wg.out[6 * j + k] - want[k]);
      const eScale = 16 * U * Math.abs(izRef) * F + 8 * izScale * F;
      if (c.range) worstIz = Math.max(worstIz, izErr / izScale);
      worstE = Math.max(worstE, eScale > 0 ? eErr / eScale : eErr === 0 ? 0 : Infinity);
      compared++;
      if (!(izErr <= 8 * izScale) || !(eErr <= eScale)) {
        if (failures++ < 5) console.log(`  WGSL ${c.tag} texel ${i} model ${model} channel ${k}: I_z ${wg.out[6 * j + 3 + k]} vs ${izRef}, E ${wg.out[6 * j + k]} vs ${want[k]}`);
      }
    }
  });
console.log(`WGSL (WebGPU): ${compared} values; LDR I_z worst ${worstIz.toFixed(3)} x u (3 + 3|x|) (2^x + 2^lo) (bound 8), irradiance worst ${worstE.toFixed(3)} of its bound`);
check(compared === 3 * items.length && failures === 0, `WGSL IrradZ within the bounds on every value (${failures} failures, ${compared} compared)`);
finish('astc webgl');
