// Runs the compiled consumer (out/consumer.js) of tests/js/web_package.mjs in the consumer folder:
// node run_consumer.mjs LIT.glb LIT.zhp SH3.zhp -> one JSON line { report, sh3Refusal } on stdout.
import fs from 'node:fs';
import { compactVolumeFromZhp } from '@zhc/runtime/volume';
import { run } from './out/consumer.js';

const [glbFile, zhpFile, sh3File] = process.argv.slice(2);
const b = fs.readFileSync(glbFile);
const report = await run(b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength), new Uint8Array(fs.readFileSync(zhpFile)));
let sh3Refusal = null;
try {
  compactVolumeFromZhp(new Uint8Array(fs.readFileSync(sh3File)));
} catch (e) {
  sh3Refusal = e.message;
}
console.log(JSON.stringify({ report, sh3Refusal }));
