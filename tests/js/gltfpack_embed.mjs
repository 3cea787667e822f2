// gltfpack and ZHC_light_probes (CTest: js.gltfpack_embed).
// Usage: node gltfpack_embed.mjs ZHC_BINARY WORK_DIR CORPUS_DIR GLTFPACK
// gltfpack (Debian's, meshoptimizer 0.18) drops extensions it does not know, so the order is:
// optimise with gltfpack first, `zhc gltf embed` last. This test shows both halves:
//  1. gltfpack -cc of a baked asset (probes embedded) writes no ZHC_light_probes;
//  2. gltfpack -cc (EXT_meshopt_compression + its quantisation) of the unlit asset, then
//     `zhc gltf embed` of the baked probes: the Khronos glTF-Validator reports 0 errors, the
//     meshopt-compressed mesh is still there, and `zhc gltf extract` gives the same .zhp bytes and
//     float SH3 as extracting the baked asset (and the .zhp that `zhc bake` wrote).
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import validator from 'gltf-validator';
import { checker } from './fixtures.mjs';

const [zhc, work, corpus, gltfpack] = process.argv.slice(2);
if (!zhc || !work || !corpus || !gltfpack) {
  console.error('usage: node gltfpack_embed.mjs ZHC_BINARY WORK_DIR CORPUS_DIR GLTFPACK');
  process.exit(2);
}
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const W = (f) => path.join(work, f);
const { check, finish } = checker();
const run = (exe, args) => execFileSync(exe, args, { stdio: ['ignore', 'pipe', 'pipe'] });

function glbJson(file) {
  const b = fs.readFileSync(file);
  const n = b.readUInt32LE(12);
  return JSON.parse(b.subarray(20, 20 + n).toString('utf8'));
}
async function validate(file) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 200,
    externalResourceFunction: (uri) => Promise.reject(new Error(`unexpected external resource ${uri}`)),
  });
  const n = report.issues;
  console.log(`validator ${path.basename(file)}: errors ${n.numErrors}, warnings ${n.numWarnings}, infos ${n.numInfos}`);
  for (const m of n.messages) if (m.severity <= 1) console.log(`  ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  return n;
}

for (const enc of ['zh3_q16', 'sh3']) {
  const src = path.join(corpus, 'gt_list.glb');
  run(zhc, ['bake', src, '-o', W(`lit_${enc}.glb`), '-r', enc, '--quiet']);
  run(zhc, ['bake', src, '-o', W(`baked_${enc}.zhp`), '-r', enc, '--quiet']);

  // 1. gltfpack after embedding: the probes are gone (by design of gltfpack).
  run(gltfpack, ['-cc', '-i', W(`lit_${enc}.glb`), '-o', W(`lit_then_packed_${enc}.glb`)]);
  const lost = glbJson(W(`lit_then_packed_${enc}.glb`));
  check(!lost.extensions?.ZHC_light_probes && !(lost.extensionsUsed ?? []).includes('ZHC_light_probes'),
    `${enc}: gltfpack after zhc drops ZHC_light_probes (the order matters)`);

  // 2. gltfpack first, zhc gltf embed last.
  run(gltfpack, ['-cc', '-i', src, '-o', W(`packed_${enc}.glb`)]);
  const packed = glbJson(W(`packed_${enc}.glb`));
  check((packed.extensionsUsed ?? []).includes('EXT_meshopt_compression'), `${enc}: gltfpack -cc output is meshopt-compressed`);
  run(zhc, ['gltf', 'embed', W(`packed_${enc}.glb`), W(`baked_${enc}.zhp`), '-o', W(`packed_lit_${enc}.glb`)]);
  const n = await validate(W(`packed_lit_${enc}.glb`));
  check(n.numErrors === 0, `${enc}: gltfpack output + zhc gltf embed: validator errors ${n.numErrors}`);
  const lit = glbJson(W(`packed_lit_${enc}.glb`));
  check((lit.extensionsUsed ?? []).includes('EXT_meshopt_compression') && (lit.extensionsRequired ?? []).includes('EXT_meshopt_compression'),
    `${enc}: the embedded asset keeps gltfpack's meshopt compression`);
  check(lit.extensions?.ZHC_light_probes?.volumes?.length === 1 && lit.extensions.ZHC_light_probes.volumes[0].encoding === enc,
    `${enc}: one ${enc} volume embedded`);
  check(JSON.stringify(lit.meshes) === JSON.stringify(packed.meshes) && JSON.stringify(lit.accessors.slice(0, packed.accessors.length)) === JSON.stringify(packed.accessors),
    `${enc}: gltfpack's meshes and accessors are unchanged`);

  // Bit for bit: extract from the gltfpack+embed asset == extract from the baked asset.
  for (const ext of ['zhp', 'json']) {
    run(zhc, ['gltf', 'extract', W(`packed_lit_${enc}.glb`), '-o', W(`from_packed_${enc}.${ext}`)]);
    run(zhc, ['gltf', 'extract', W(`lit_${enc}.glb`), '-o', W(`from_lit_${enc}.${ext}`)]);
    check(fs.readFileSync(W(`from_packed_${enc}.${ext}`)).equals(fs.readFileSync(W(`from_lit_${enc}.${ext}`))),
      `${enc}: extract .${ext} of gltfpack+embed equals the baked asset's`);
  }
  run(zhc, ['convert', W(`baked_${enc}.zhp`), '-o', W(`baked_${enc}.json`)]);
  check(fs.readFileSync(W(`from_packed_${enc}.json`)).equals(fs.readFileSync(W(`baked_${enc}.json`))),
    `${enc}: extracted SH3 equals zhc bake's .zhp decoded`);
}

finish('gltfpack + zhc gltf embed');
