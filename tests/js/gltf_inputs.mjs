// glTF inputs other programs wrote, checked with the Khronos glTF-Validator:
//  1. the corpus tests/data/gltf written by glTF-Transform and gltfpack is valid glTF (so zhc's
//     tests read real, conforming files), including its legal no-scene and data-URI variants;
//  2. `zhc bake IN.gltf -o OTHER/out.gltf|.glb` (and into the parent folder) writes outputs whose
//     image references resolve from the output's own folder: the validator, loading external
//     resources relative to the output, reports no IO_ERROR and no error at all.
// Usage: node gltf_inputs.mjs ZHC WORKDIR CORPUSDIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import validator from 'gltf-validator';

const [zhc, work, corpus] = process.argv.slice(2);
if (!zhc || !work || !corpus) {
  console.error('usage: node gltf_inputs.mjs ZHC WORKDIR CORPUSDIR');
  process.exit(2);
}
let failed = false;

async function validate(file) {
  const dir = path.dirname(file);
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        const p = path.join(dir, decodeURIComponent(uri));
        fs.readFile(p, (err, data) => (err ? reject(err) : resolve(new Uint8Array(data))));
      }),
  });
  return report.issues;
}

function check(file, issues, what) {
  const io = issues.messages.filter((m) => m.code === 'IO_ERROR');
  const errors = issues.messages.filter((m) => m.severity === 0);
  const ok = io.length === 0 && issues.numErrors === 0;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}: ${file}: errors ${issues.numErrors}, IO_ERROR ${io.length}`);
  for (const m of errors) console.log(`     ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  if (!ok) failed = true;
}

// 1. The corpus inputs.
for (const name of ['gt_list.glb', 'gt_list.gltf', 'gt_strip.glb', 'gt_fan.glb', 'gt_meshopt.glb', 'gt_meshopt_strip.glb',
  'gt_draco.glb', 'gp_list.glb', 'gp_meshopt.glb', 'gp_quant.glb', 'gp_quant_norm.glb', 'gp_quant_meshopt.glb', 'gp_fallback.gltf',
  'noscene.gltf', 'datauri_image.gltf']) {
  const file = path.join(corpus, name);
  if (!fs.existsSync(file)) continue;  // gltfpack's files are optional
  check(file, await validate(file), 'corpus input');
}

// 2. Outputs written away from the input's folder.
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(path.join(work, 'in'), { recursive: true });
fs.mkdirSync(path.join(work, 'other'), { recursive: true });
for (const f of ['gt_list.gltf', 'gt_list.bin', 'tex.png']) fs.copyFileSync(path.join(corpus, f), path.join(work, 'in', f));
for (const out of ['other/out.gltf', 'other/out.glb', 'up.gltf', 'in/same.gltf']) {
  const file = path.join(work, out);
  execFileSync(zhc, ['bake', path.join(work, 'in', 'gt_list.gltf'), '-o', file, '--quiet'], { stdio: 'inherit' });
  const issues = await validate(file);
  if (issues.numErrors === 0 && JSON.stringify(issues).includes('IO_ERROR')) failed = true;
  check(file, issues, 'bake output');
}
process.exit(failed ? 1 : 0);
