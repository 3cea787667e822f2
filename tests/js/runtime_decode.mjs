// runtime/web against zhc's C++ codec (CTest: js.runtime_decode).
// Usage: node runtime_decode.mjs ZHC_BINARY WORK_DIR
//
//  1. writes 3000 random probes (a points layout) and a 5x4x3 grid as JSON probe lists;
//  2. for every encoding of the codec table and many quantisation parameter sets:
//     `zhc convert probes.json -o X.zhp --to ENC [flags]`, then `zhc convert X.zhp -o X.json` (zhc's
//     decoded SH3, printed with round-trip precision); zhc_runtime.mjs parses X.zhp and decodes every
//     probe: every float32 coefficient must be BIT-IDENTICAL to zhc's;
//  3. custom luminance weights: the .zhp header's weights are rewritten (CRC fixed) and both sides
//     decode again (they change the ZH3 axes);
//  4. `zhc gltf embed` of a subset: three.js GLTFLoader + ZhcLightProbesPlugin decodes the volume
//     bit-identically, its positions are the glTF-axis permutation of zhc's, and its irradiance
//     equals `zhc gltf eval` bit for bit (shAxes zhc) for sampled probes and directions, for every
//     probe of a grid volume (glTF probe order), within 1e-6 of the DC for shAxes gltf;
//  5. three.js conventions: volume.threeSH(p).getIrradianceAt(n) / pi against zhc gltf eval
//     (three's 6-digit basis constants) and the zhc <-> glTF SH rotation against zhc's own.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { register } from 'node:module';
import { randomProbes, triangleScene, makeRand, checker, ulpDiff } from './fixtures.mjs';

register('./three_resolver.mjs', import.meta.url);
const runtime = await import('../../runtime/web/zhc_runtime.mjs');
const { ZhcLightProbesPlugin } = await import('../../runtime/web/zhc_light_probes_plugin.mjs');
const THREE = await import('three');
const { GLTFLoader } = await import('three/examples/jsm/loaders/GLTFLoader.js');

const [zhc, work] = process.argv.slice(2);
if (!zhc || !work) {
  console.error('usage: node runtime_decode.mjs ZHC_BINARY WORK_DIR');
  process.exit(2);
}
fs.mkdirSync(work, { recursive: true });
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (...args) => execFileSync(zhc, args, { maxBuffer: 1 << 28 }).toString();

// --- inputs -----------------------------------------------------------------------------------
const N = 3000;
const rand = makeRand(777);
const probes = randomProbes(N, 4242);
fs.writeFileSync(W('points.json'), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
  probes: probes.map((sh) => ({ position: [rand() * 20 - 10, rand() * 20 - 10, rand() * 5], sh3: sh })) }));
const gridProbes = randomProbes(60, 99);
fs.writeFileSync(W('grid.json'), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance',
  layout: { type: 'grid', origin: [-2, 1, 0.5], spacing: [0.5, 1.25, 2], counts: [5, 4, 3] }, probes: gridProbes.map((sh) => ({ sh3: sh })) }));
fs.writeFileSync(W('scene.glb'), triangleScene());

// --- decoded SH3 vs zhc -------------------------------------------------------------------------
// Compares a Float32Array(count * 27) with zhc's JSON probe list; returns the number of
// coefficients that differ in any bit (and logs the first few).
function compareWithJson(what, sh, jsonFile, quiet = false) {
  const doc = JSON.parse(fs.readFileSync(jsonFile, 'utf8'));
  let bad = 0, worstUlp = 0, n = 0;
  doc.probes.forEach((pr, p) => {
    const zi = p;
    for (let i = 0; i < 9; i++)
      for (let k = 0; k < 3; k++) {
        const want = Math.fround(pr.sh3[i][k]), got = sh[p * 27 + i * 3 + k];
        n++;
        if (!Object.is(want, got)) {
          if (bad < 3 && !quiet) console.log(`  ${what}: probe ${zi} coefficient ${i} channel ${k}: js ${got} zhc ${want}`);
          bad++;
          worstUlp = Math.max(worstUlp, ulpDiff(want, got));
        }
      }
  });
  return { bad, n, worstUlp, probes: doc.probes.length };
}

// The codec table as zhc reports it (`zhc audit --json` keys every entry by name, with its size):
// runtime/web must decode every entry zhc's runtimes read, with the same size, and know no other
// name. The engine layouts (`engine_layouts`: the engines' own formats, docs/engine-layouts.md)
// are not runtime encodings, and runtime/web must not know them.
fs.writeFileSync(W('two.json'), JSON.stringify({ format: 'zhc-probes', version: 1, kind: 'radiance', layout: { type: 'positions' },
  probes: probes.slice(0, 2).map((sh, i) => ({ position: [i, 0, 0], sh3: sh })) }));
const audited = JSON.parse(run('audit', W('two.json'), '--json', '--no-timing'));
const engineNames = new Set(audited.engine_layouts.map((e) => e.representation));
check(engineNames.size > 0, 'zhc audit lists the engine layouts');
for (const name of engineNames) check(!(name in runtime.ENCODINGS), `runtime/web ENCODINGS.${name} is an engine layout`);
const table = Object.fromEntries(Object.entries(audited.aggregate.representations).filter(([name]) => !engineNames.has(name)));
const tableNames = Object.keys(table);
check(tableNames.length > 0, 'zhc audit lists the codec table');
for (const name of tableNames)
  check(Object.prototype.hasOwnProperty.call(runtime.ENCODINGS, name) && runtime.ENCODINGS[name].bytes === table[name].bytes_per_probe,
    `codec table entry ${name} (${table[name].bytes_per_probe} bytes): runtime/web ENCODINGS has no entry of that size`);
for (const name of Object.keys(runtime.ENCODINGS)) check(name in table, `runtime/web ENCODINGS.${name} is not a codec table entry`);
// Aliases (ENCODING_ALIASES, generated from the codec's codec_aliases()): zhc takes each on the
// command line as the entry it names, and the runtime decodes it as that entry.
check(Object.keys(runtime.ENCODING_ALIASES).length > 0, 'runtime/web ENCODING_ALIASES lists the aliases');
for (const [alias, name] of Object.entries(runtime.ENCODING_ALIASES)) {
  check(!(alias in table) && name in table, `alias ${alias} -> ${name}: not an entry, names one`);
  const named = Object.keys(JSON.parse(run('audit', W('two.json'), '-r', alias, '--json', '--no-timing')).aggregate.representations);
  check(named.length === 1 && named[0] === name, `zhc audit -r ${alias} audits ${name} (got ${named.join()})`);
  check(runtime.encodingName(alias) === name && runtime.encodingInfo(alias) === runtime.encodingInfo(name), `encodingInfo('${alias}')`);
  const bytes = new Uint8Array(runtime.encodingInfo(name).bytes).map((_, i) => (i * 37 + 11) & 255);
  const a = runtime.decodeProbe(alias, bytes), b = runtime.decodeProbe(name, bytes);
  check(a.length === 27 && a.every((x, i) => Object.is(x, b[i])), `decodeProbe('${alias}') = decodeProbe('${name}')`);
}
check(runtime.encodingName('zh3_lum_dering_') === 'zh3_lum_dering_', 'encodingName leaves other names alone');

// Every entry with the defaults, the float ones also as irradiance; then parameter sets chosen
// for some of the quantised entries (an entry not named below still gets its defaults and one
// combination of every quantisation flag).
const cases = [];
for (const e of tableNames) cases.push({ enc: e, flags: [] });
for (const e of ['sh3', 'sh2', 'zh3_channel', 'hall_curve', 'hall_sphere_channel']) cases.push({ enc: e, flags: ['--irradiance'] });
for (const flags of [['--bits', '5'], ['--bits', '2', '--sqrt'], ['--dc', 'rgb9e5'], ['--zonal-map', 'zero', '--sqrt'],
  ['--zonal-map', 'symmetric', '--bits', '7'], ['--axis', 'channel'], ['--irradiance'],
  ['--irradiance', '--axis', 'channel', '--zonal-map', 'zero', '--bits', '6', '--dc', 'rgb9e5'], ['--bits', '3', '--sqrt', '--zonal-map', 'symmetric']])
  cases.push({ enc: 'zh3_q16', flags });
cases.push({ enc: 'zh3_solved_q16', flags: ['--bits', '6', '--axis', 'channel'] });
cases.push({ enc: 'zh3_dering_q16', flags: ['--bits', '5', '--sqrt', '--irradiance'] });
for (const flags of [['--bound', 'loose'], ['--sqrt', '--bits', '4'], ['--dc', 'rgb9e5', '--irradiance'], ['--zonal-map', 'zero'],
  ['--zonal-map', 'symmetric', '--bits', '3', '--bound', 'loose', '--sqrt'], ['--irradiance', '--zonal-map', 'zero', '--sqrt', '--bits', '2']])
  cases.push({ enc: 'sh3_q28', flags });
for (const flags of [['--dc', 'half'], ['--dc', 'rgb9e5', '--bits', '7', '--sqrt'], ['--irradiance', '--dc', 'half', '--bits', '4']])
  cases.push({ enc: 'sh2_q', flags });
for (const flags of [['--axis', 'channel', '--dc', 'half'], ['--irradiance', '--sqrt']]) cases.push({ enc: 'hall_curve_q', flags });
for (const enc of ['zh3_channel_q16', 'zh3_solved_channel_q16'])
  cases.push({ enc, flags: ['--bits', '5', '--sqrt', '--irradiance', '--dc', 'rgb9e5', '--zonal-map', 'zero'] });
for (const enc of ['hall_solved_q16', 'hall_adaptive_q16'])
  for (const flags of [['--axis', 'channel', '--dc', 'half'], ['--irradiance', '--sqrt', '--bits', '6']]) cases.push({ enc, flags });
for (const e of tableNames)
  if (runtime.ENCODINGS[e]?.packed && cases.filter((c) => c.enc === e).length === 1)
    cases.push({ enc: e, flags: ['--bits', '5', '--sqrt', '--irradiance', '--dc', 'rgb9e5', '--zonal-map', 'zero', '--axis', 'channel'] });

let totalCoefficients = 0, totalCases = 0;
const ENC_PACKED = new Set(Object.keys(runtime.ENCODINGS).filter((name) => runtime.ENCODINGS[name].packed));
cases.forEach((c, idx) => {
  c.name = `c${idx}_${c.enc}`;
  run('convert', W('points.json'), '-o', W(`${c.name}.zhp`), '--to', c.enc, ...c.flags);
  run('convert', W(`${c.name}.zhp`), '-o', W(`${c.name}.json`));
  const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(W(`${c.name}.zhp`))));
  check(z.encoding === c.enc && z.count === N, `${c.name}: zhp header`);
  const sh = runtime.decodeAll(z.encoding, z.payload, z.count, z.params);
  const r = compareWithJson(c.name, sh, W(`${c.name}.json`));
  console.log(`decode ${c.enc} ${c.flags.join(' ') || '(defaults)'}: ${r.probes} probes, ${r.n - r.bad}/${r.n} coefficients bit-identical` +
    (r.bad ? `, worst ${r.worstUlp} ulp` : ''));
  check(r.bad === 0 && r.probes === N, `${c.name}: JS decode equals zhc's bit for bit`);
  totalCoefficients += r.n;
  totalCases++;
});

// --- custom luminance weights (.zhp header rewritten) --------------------------------------------
for (const c of cases.filter((c) => ['zh3_q16', 'zh3_lum', 'hall_curve_q', 'hall_sphere', 'zh3_solved_q16'].includes(c.enc) && !c.flags.includes('--axis'))) {
  const bytes = new Uint8Array(fs.readFileSync(W(`${c.name}.zhp`)));
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  [0.3, 0.59, 0.11].forEach((w, j) => dv.setFloat64(72 + 8 * j, w, true));
  dv.setUint32(180, runtime.crc32(bytes, 0, 180), true);
  fs.writeFileSync(W(`${c.name}_lw.zhp`), bytes);
  run('convert', W(`${c.name}_lw.zhp`), '-o', W(`${c.name}_lw.json`));
  const z = runtime.parseZhp(bytes);
  check(z.params.luminanceWeights[1] === 0.59, `${c.name}: luminance weights read`);
  const r = compareWithJson(`${c.name}_lw`, runtime.decodeAll(z.encoding, z.payload, z.count, z.params), W(`${c.name}_lw.json`));
  const base = compareWithJson(`${c.name}_lw(default weights)`, runtime.decodeAll(z.encoding, z.payload, z.count, runtime.makeParams({ ...z.params, luminanceWeights: undefined })), W(`${c.name}_lw.json`), true);
  console.log(`decode ${c.enc} ${c.flags.join(' ') || '(defaults)'} luminance weights (0.3, 0.59, 0.11): ${r.n - r.bad}/${r.n} bit-identical` +
    ` (decoding with the default weights instead differs in ${base.bad})`);
  check(r.bad === 0, `${c.name}: luminance weights decode equals zhc's`);
  check(base.bad > 0, `${c.name}: the luminance weights matter (the check can fail)`);
  totalCoefficients += r.n;
  totalCases++;
}

// --- arbitrary stored bytes: the decoders are total and still equal zhc's ----------------------
// The payload of a packed .zhp is replaced by random bytes (CRCs fixed): ratio codes above 2 bv
// (and with high bits set for bits < 8), any DC mantissa/exponent. DC exponent fields are kept
// below 31 (Inf/NaN decode fine but zhc refuses to print non-finite JSON).
for (const c of cases.filter((c) => ENC_PACKED.has(c.enc))) {
  const bytes = new Uint8Array(fs.readFileSync(W(`${c.name}.zhp`)));
  const z = runtime.parseZhp(bytes);
  const r = makeRand(c.name.length * 7919 + 1);
  const payload = z.payload;  // a view into `bytes`
  for (let j = 0; j < payload.length; j++) payload[j] = Math.floor(r() * 256);
  for (let p = 0; p < z.count; p++) {
    const o = p * z.bytesPerProbe;
    if (z.params.dcFormat === 'half') {  // sh2_q / hall_curve_q only (6-byte DC slot)
      for (let k = 0; k < 3; k++) if (((payload[o + 2 * k + 1] >> 2) & 31) === 31) payload[o + 2 * k + 1] &= ~0x04;
    } else if (z.params.dcFormat !== 'rgb9e5') {
      let w = (payload[o] | (payload[o + 1] << 8) | (payload[o + 2] << 16) | (payload[o + 3] << 24)) >>> 0;
      for (const [shift, mb] of [[0, 6], [11, 6], [22, 5]]) if (((w >>> (shift + mb)) & 31) === 31) w = (w & ~(1 << (shift + mb))) >>> 0;
      [0, 1, 2, 3].forEach((b) => { payload[o + b] = (w >>> (8 * b)) & 255; });
    }
  }
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const body = Number(dv.getBigUint64(160, true));
  dv.setUint32(176, runtime.crc32(bytes, 184, 184 + body), true);
  dv.setUint32(180, runtime.crc32(bytes, 0, 180), true);
  fs.writeFileSync(W(`${c.name}_rnd.zhp`), bytes);
  run('convert', W(`${c.name}_rnd.zhp`), '-o', W(`${c.name}_rnd.json`));
  const z2 = runtime.parseZhp(bytes);
  const res = compareWithJson(`${c.name}_rnd`, runtime.decodeAll(z2.encoding, z2.payload, z2.count, z2.params), W(`${c.name}_rnd.json`));
  console.log(`decode ${c.enc} ${c.flags.join(' ') || '(defaults)'} random stored bytes: ${res.n - res.bad}/${res.n} bit-identical`);
  check(res.bad === 0, `${c.name}: random bytes decode equals zhc's`);
  totalCoefficients += res.n;
  totalCases++;
}

// --- glTF: the plugin --------------------------------------------------------------------------
async function loadThree(file) {
  const bytes = fs.readFileSync(file);
  const ab = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  return new Promise((resolve, reject) => loader.parse(ab, '', resolve, reject));
}
const evalZhc = (file, p, d) => run('gltf', 'eval', file, '--probe', String(p), '--dir', d.join(',')).trim().split(/\s+/).map(Number);
const dirs = [[0, 1, 0], [0.3, -0.8, 0.52], [-1, 0.25, 0.4], [0, 0, -2]];
const samples = [0, 1, 2, 3, 4, 5, 17, 404, 1234, 2999];
const pointsJson = JSON.parse(fs.readFileSync(W('points.json'), 'utf8'));
let evalCount = 0, evalBad = 0;
let threeWorst = 0;
for (const c of cases.filter((c, i) => i % 3 === 0 || c.enc === 'zh3_q16' || c.flags.includes('half'))) {
  const file = W(`${c.name}.glb`);
  run('gltf', 'embed', W('scene.glb'), W(`${c.name}.zhp`), '-o', file);
  const gltf = await loadThree(file);
  const v = gltf.userData.zhcLightProbes && gltf.userData.zhcLightProbes[0];
  check(v && v.count === N && v.encoding === c.enc && v.shAxes === 'zhc', `${c.name}.glb: plugin volume`);
  if (!v) continue;
  const r = compareWithJson(`${c.name}.glb`, v.sh, W(`${c.name}.json`));
  check(r.bad === 0, `${c.name}.glb: plugin decode equals zhc's bit for bit`);
  let posOk = true;
  pointsJson.probes.forEach((pr, p) => {
    const want = [pr.position[1], pr.position[2], pr.position[0]].map(Math.fround);  // (x,y,z)_glTF = (y,z,x)_zhc
    if (!want.every((w, j) => Object.is(w, v.positions[p * 3 + j]))) posOk = false;
  });
  check(posOk, `${c.name}.glb: positions are zhc's in glTF axes`);
  let bad = 0, count = 0;
  for (const p of samples)
    for (const d of dirs.slice(0, 2)) {
      const want = evalZhc(file, p, d).map(Math.fround), got = v.irradiance(p, d);
      count++;
      if (!want.every((w, k) => Object.is(w, got[k]))) {
        bad++;
        console.log(`  ${c.name}.glb probe ${p} dir ${d}: js ${got} zhc ${want}`);
      }
      const t = v.threeSH(p).getIrradianceAt(new THREE.Vector3(...d).normalize(), new THREE.Vector3());
      const dcE = runtime.kY00 * Math.max(...[0, 1, 2].map((k) => Math.abs(v.probeSH(p)[k])));
      [t.x, t.y, t.z].forEach((x, k) => { if (dcE > 0) threeWorst = Math.max(threeWorst, Math.abs(x / Math.PI - want[k]) / dcE); });
    }
  evalCount += count;
  evalBad += bad;
  console.log(`glTF ${c.enc} ${c.flags.join(' ') || '(defaults)'}: plugin decode ${r.n - r.bad}/${r.n} bit-identical; irradiance = zhc gltf eval in ${count - bad}/${count}`);
  check(bad === 0, `${c.name}.glb: plugin irradiance equals zhc gltf eval bit for bit`);
}
console.log(`three.js SphericalHarmonics3.getIrradianceAt / pi vs zhc: worst |diff| / (Y00 DC) = ${threeWorst.toExponential(2)}`);
check(threeWorst < 2e-5, 'three.js conversion agrees with zhc within its 6-digit basis constants');

// Grid volume: glTF probe order (reordered by the exporter), every probe evaluated by zhc.
{
  run('convert', W('grid.json'), '-o', W('grid_q16.zhp'), '--to', 'zh3_q16', '--dc', 'rgb9e5', '--axis', 'channel');
  run('gltf', 'embed', W('scene.glb'), W('grid_q16.zhp'), '-o', W('grid_q16.glb'));
  const v = (await loadThree(W('grid_q16.glb'))).userData.zhcLightProbes[0];
  let bad = 0;
  for (let p = 0; p < v.count; p++) {
    const d = dirs[p % dirs.length];
    const want = evalZhc(W('grid_q16.glb'), p, d).map(Math.fround), got = v.irradiance(p, d);
    if (!want.every((w, k) => Object.is(w, got[k]))) bad++;
  }
  evalCount += v.count;
  evalBad += bad;
  // Positions: origin + index * spacing in glTF axes, zhc's grid permuted.
  const [nx, ny] = v.grid.counts;
  const g = JSON.parse(fs.readFileSync(W('grid.json'), 'utf8')).layout;
  const og = [g.origin[1], g.origin[2], g.origin[0]], sg = [g.spacing[1], g.spacing[2], g.spacing[0]];
  const p = 1 + nx * (2 + ny * 1);  // glTF (1, 2, 1)
  check(v.grid.counts.join() === '4,3,5' && v.position(p).every((x, j) => Math.abs(x - (og[j] + [1, 2, 1][j] * sg[j])) < 1e-12),
    'grid volume: counts and positions in glTF axes');
  console.log(`glTF grid zh3_q16 (rgb9e5, channel axes), ${v.count} probes in glTF order: irradiance = zhc gltf eval in ${v.count - bad}/${v.count}`);
  check(bad === 0, 'grid volume: plugin irradiance equals zhc gltf eval for every probe');
}

// Custom luminance weights through glTF (the volume's "luminanceWeights"): plugin decode and eval.
for (const c of cases.filter((c) => ['zh3_q16', 'hall_curve_q'].includes(c.enc) && c.flags.length === 0)) {
  const file = W(`${c.name}_lw.glb`);
  run('gltf', 'embed', W('scene.glb'), W(`${c.name}_lw.zhp`), '-o', file);
  const doc = await loadThree(file);
  const v = doc.userData.zhcLightProbes[0];
  check(v.params.luminanceWeights.join() === '0.3,0.59,0.11', `${c.name}_lw.glb: luminanceWeights read from glTF`);
  const r = compareWithJson(`${c.name}_lw.glb`, v.sh, W(`${c.name}_lw.json`));
  let bad = 0;
  for (const p of samples) {
    const want = evalZhc(file, p, dirs[1]).map(Math.fround), got = v.irradiance(p, dirs[1]);
    if (!want.every((w, k) => Object.is(w, got[k]))) bad++;
  }
  evalCount += samples.length;
  evalBad += bad;
  console.log(`glTF ${c.enc} luminanceWeights (0.3, 0.59, 0.11): plugin decode ${r.n - r.bad}/${r.n} bit-identical; irradiance = zhc gltf eval in ${samples.length - bad}/${samples.length}`);
  check(r.bad === 0 && bad === 0, `${c.name}_lw.glb: plugin with luminance weights equals zhc`);
}

// shAxes "gltf" (coefficients rotated by zhc in double, rounded once) and the runtime's rotation.
{
  run('gltf', 'embed', W('scene.glb'), W('points.json'), '-o', W('points_sh3_gltfaxes.glb'), '--sh-axes', 'gltf');
  run('gltf', 'embed', W('scene.glb'), W('points.json'), '-o', W('points_sh3.glb'));
  const vg = (await loadThree(W('points_sh3_gltfaxes.glb'))).userData.zhcLightProbes[0];
  const vz = (await loadThree(W('points_sh3.glb'))).userData.zhcLightProbes[0];
  check(vg.shAxes === 'gltf' && vz.shAxes === 'zhc', 'shAxes read');
  let worstRot = 0, worstEval = 0, worstInv = 0;
  for (let p = 0; p < N; p++) {
    const a = vz.probeSHGltf(p), b = vg.probeSH(p);
    // and back: rotateGltfToZhc of zhc's glTF-axes coefficients is the original (zhc axes).
    const back = runtime.rotateGltfToZhc(b), orig = vz.probeSH(p);
    let scale = 0;
    for (let j = 0; j < 27; j++) scale = Math.max(scale, Math.abs(b[j]));
    for (let j = 0; j < 27; j++) if (scale > 0) {
      worstRot = Math.max(worstRot, Math.abs(a[j] - b[j]) / scale);
      worstInv = Math.max(worstInv, Math.abs(back[j] - orig[j]) / scale);
    }
  }
  for (const p of samples)
    for (const d of dirs) {
      const want = evalZhc(W('points_sh3_gltfaxes.glb'), p, d), got = vg.irradiance(p, d);
      const dcE = runtime.kY00 * Math.max(...[0, 1, 2].map((k) => Math.abs(vg.probeSH(p)[k])));
      for (let k = 0; k < 3; k++) if (dcE > 0) worstEval = Math.max(worstEval, Math.abs(got[k] - want[k]) / dcE);
    }
  console.log(`shAxes gltf: runtime rotation vs zhc's rotated coefficients, worst |diff| / max|c| = ${worstRot.toExponential(2)}; ` +
    `irradiance vs zhc gltf eval worst |diff| / (Y00 DC) = ${worstEval.toExponential(2)}`);
  check(worstRot < 2.4e-7, 'rotateZhcToGltf agrees with zhc\'s rotation within 2 float roundings');
  console.log(`rotateGltfToZhc(zhc's glTF-axes coefficients) vs the zhc-axes original: worst |diff| / max|c| = ${worstInv.toExponential(2)}`);
  check(worstInv < 3.6e-7, 'rotateGltfToZhc inverts the rotation within 3 float roundings');
  check(worstEval < 1e-6, 'shAxes gltf irradiance agrees with zhc gltf eval');
}

// The shader-style zh3_q16 formula (what the GLSL chunk computes) against the exact path.
{
  let worst = 0;
  for (const c of cases.filter((c) => c.enc === 'zh3_q16')) {
    const z = runtime.parseZhp(new Uint8Array(fs.readFileSync(W(`${c.name}.zhp`))));
    for (let p = 0; p < z.count; p++) {
      const n = runtime.normalizeOr(dirs[p % dirs.length]);
      const a = runtime.zh3Q16IrradianceFast(z.payload, p * 16, z.params, n), b = runtime.probeIrradiance('zh3_q16', z.payload, p * 16, z.params, n);
      const sh = runtime.decodeProbe('zh3_q16', z.payload, p * 16, z.params);
      const dcE = runtime.kY00 * Math.max(Math.abs(sh[0]), Math.abs(sh[1]), Math.abs(sh[2]));
      for (let k = 0; k < 3; k++) if (dcE > 0) worst = Math.max(worst, Math.abs(a[k] - b[k]) / dcE);
    }
  }
  console.log(`zh3Q16IrradianceFast vs exact decode: worst |diff| / (Y00 DC) = ${worst.toExponential(2)}`);
  check(worst < 1e-6, 'zh3Q16IrradianceFast within 1e-6 of the DC');
}

// Bad input: decoders are total (random bytes, every encoding), parsers throw Errors.
{
  const r = makeRand(5);
  let threw = 0;
  for (const [name, e] of Object.entries(runtime.ENCODINGS)) {
    for (let t = 0; t < 200; t++) {
      const b = new Uint8Array(e.bytes).map(() => Math.floor(r() * 256));
      const params = runtime.makeParams({ bits: 2 + (t % 7), sqrt: t % 2 === 0, dcFormat: name === 'sh2_q' ? 'half' : 'rgb9e5' });
      try {
        const sh = runtime.decodeProbe(name, b, 0, params);
        runtime.irradiance(sh, [0, 0, 1]);
        if (sh.length !== 27) threw++;
      } catch {
        threw++;
      }
    }
  }
  check(threw === 0, 'decoders accept any bytes');
  let parseErrors = 0;
  const good = new Uint8Array(fs.readFileSync(W(`${cases[0].name}.zhp`)));
  for (const mutate of [(b) => b.subarray(0, 100), (b) => { b[13] = 9; }, (b) => { b[200] ^= 1; }, (b) => { b[0] = 0; }]) {
    const b = new Uint8Array(good);
    const m = mutate(b) ?? b;
    try { runtime.parseZhp(m); } catch (e) { if (e instanceof Error) parseErrors++; }
  }
  check(parseErrors === 4, 'parseZhp rejects truncated / damaged files');
}

console.log(`${totalCases} decode cases, ${totalCoefficients} coefficients compared bit for bit; ${evalCount - evalBad}/${evalCount} irradiance evaluations equal zhc gltf eval`);
finish('runtime/web decode');
