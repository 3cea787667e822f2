// Runs the Khronos glTF-Validator on each file given; exits 1 if any reports an error.
// Usage: node validate.mjs FILE...
import fs from 'node:fs';
import path from 'node:path';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 100,
    // zhc writes self-contained files: no external resources to load.
    externalResourceFunction: (uri) => Promise.reject(new Error(`unexpected external resource ${uri}`)),
  });
  const n = report.issues;
  console.log(`${file}: errors ${n.numErrors}, warnings ${n.numWarnings}, infos ${n.numInfos}, hints ${n.numHints}`);
  for (const m of n.messages) {
    if (m.severity <= 1) console.log(`  [${m.severity === 0 ? 'error' : 'warning'}] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  }
  if (n.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
