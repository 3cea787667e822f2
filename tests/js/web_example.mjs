// examples/web in headless Chromium, as its README runs it (CTest: js.web_example).
// Usage: node web_example.mjs ZHC_BINARY NPM WORK_DIR [CHROMIUM]
//
//  1. the site: examples/web's index.html and main.mjs, `zhc bake examples/hall.gltf -o hall.glb
//     -r zh3_q16` (the command of runtime/web/README.md) and `-o hall.zhp`, examples/hall.gltf,
//     node_modules/@zhc/runtime unpacked from the tarball `npm pack runtime/web` writes,
//     node_modules/three = tests/js's three.js (r187);
//  2. the example's page, unchanged but for two scripts put in its head: browser/collect_errors.js
//     (console errors and exceptions) and browser/web_example_check.mjs (after main.mjs), in
//     headless Chromium (SwiftShader WebGL2): index.html (hall.glb: the probes in the asset) and
//     index.html?gltf=hall.gltf&zhp=hall.zhp (the asset without probes, the probes from the .zhp);
//  3. assertions: the page ran (frames drawn, the sphere moved), the asset's three KHR_lights_punctual
//     lights are hidden, and at 8 points of the sphere's path the white sphere's pixel facing the
//     example's camera equals the irradiance of the decoded probes there (the plugin's irradianceAt:
//     a different code path from the shader's) within 1e-4 relative; with the baked lights shown
//     the same pixel is brighter by far more (so the comparison can fail); the irradiance changes
//     along the path; the example's own view is covered and lit; the .zhp page shows the .glb
//     page's irradiance along the same path.
// Time bounded: the page times out after 180 s (Chromium killed).
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { checker, freshWork, repoRoot } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';

const [zhc, npm, workArg, chromiumArg] = process.argv.slice(2);
if (!zhc || !npm || !workArg) {
  console.error('usage: node web_example.mjs ZHC_BINARY NPM WORK_DIR [CHROMIUM]');
  process.exit(2);
}
const chromium = chromiumArg || '/usr/bin/chromium';
const work = freshWork(workArg);
const here = path.dirname(fileURLToPath(import.meta.url));
const repo = repoRoot;
const exampleDir = path.join(repo, 'examples', 'web');
const { check, finish } = checker();

// --- 1. the site ---------------------------------------------------------------------------------
const site = path.join(work, 'site');
fs.mkdirSync(path.join(site, 'node_modules', '@zhc', 'runtime'), { recursive: true });
for (const f of ['index.html', 'main.mjs']) fs.copyFileSync(path.join(exampleDir, f), path.join(site, f));
for (const out of ['hall.glb', 'hall.zhp'])
  execFileSync(zhc, ['bake', path.join(repo, 'examples', 'hall.gltf'), '-o', path.join(site, out), '-r', 'zh3_q16', '--quiet']);
fs.copyFileSync(path.join(repo, 'examples', 'hall.gltf'), path.join(site, 'hall.gltf'));
const version = JSON.parse(fs.readFileSync(path.join(repo, 'runtime', 'web', 'package.json'), 'utf8')).version;
execFileSync(npm, ['pack', path.join(repo, 'runtime', 'web'), '--pack-destination', work, '--silent'], { cwd: work });
const tarball = path.join(work, `zhc-runtime-${version}.tgz`);
check(fs.existsSync(tarball), `npm pack wrote ${path.basename(tarball)}`);
execFileSync('tar', ['xzf', tarball, '-C', path.join(site, 'node_modules', '@zhc', 'runtime'), '--strip-components=1']);
fs.symlinkSync(path.join(here, 'node_modules', 'three'), path.join(site, 'node_modules', 'three'), 'dir');
const glbJson = (() => {
  const b = fs.readFileSync(path.join(site, 'hall.glb'));
  return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
})();
const khrLights = glbJson.extensions.KHR_lights_punctual.lights;

// --- 2. the page -----------------------------------------------------------------------------------
const html = fs.readFileSync(path.join(exampleDir, 'index.html'), 'utf8');
check(html.includes('<script type="module" src="./main.mjs"></script>'), 'index.html loads main.mjs');
const injected = html
  .replace('<head>', '<head>\n<script src="/harness/collect_errors.js"></script>')
  .replace('<script type="module" src="./main.mjs"></script>',
    '<script type="module" src="./main.mjs"></script>\n<script type="module" src="/harness/web_example_check.mjs"></script>');
const pages = await chromiumPages({
  roots: { '/harness/': path.join(here, 'browser'), '/test/': site },
  routes: { 'GET /test/index.html': async (req, res) => { res.writeHead(200, { 'Content-Type': 'text/html' }); res.end(injected); } },
  work, chromium, check,
});
const DONE = 'zhc web example check done';
const reports = {
  glb: await pages.runPage('index.html', ['--use-angle=swiftshader', '--window-size=640,480'], 'glb', DONE),
  zhp: await pages.runPage('index.html?gltf=hall.gltf&zhp=hall.zhp', ['--use-angle=swiftshader', '--window-size=640,480'], 'zhp', DONE),
};
pages.close();

// --- 3. assertions ---------------------------------------------------------------------------------
fs.writeFileSync(path.join(work, 'report.json'), JSON.stringify(reports, null, 1));
if (reports.glb === null || reports.zhp === null) process.exit(1);
// The grid's counts: glTF axes in the .glb, zhc axes in the .zhp ((x, y, z)_glTF = (y, z, x)_zhc).
const gltfCounts = glbJson.extensions.ZHC_light_probes.volumes[0].grid.counts;
const gridCounts = { glb: gltfCounts.join('x'), zhp: [gltfCounts[2], gltfCounts[0], gltfCounts[1]].join('x') };
for (const [tag, report] of Object.entries(reports)) {
  const what = tag === 'glb' ? 'hall.glb (the probes in the asset)' : 'hall.gltf + hall.zhp (the probes in a .zhp)';
  console.log(`${what}:`);
  for (const e of report.errors ?? []) console.log(`  page: ${e}`);
  check((report.errors ?? []).length === 0, `${tag}: no console error, warning or exception in the page`);
  check(report.ready === true, `${tag}: the example drew at least 5 frames`);
  if (!report.ready) continue;
  check(report.three === '187' && report.sameThree === true, `${tag}: three.js r187, one copy shared by the example and the check`);
  check(report.webgl2 === true && report.colorBufferFloat === true, `${tag}: WebGL2 with EXT_color_buffer_float`);
  check(report.encoding === 'zh3_q16' && report.counts.join('x') === gridCounts[tag], `${tag}: the baked zh3_q16 grid (${report.counts.join('x')})`);
  check(report.planed === true, `${tag}: the compact volume applies the bake's cell planes (validity too when a probe is invalid: ${report.masked})`);
  const moved = new Set(report.moverPositions.map((p) => p.map((x) => x.toFixed(6)).join(','))).size;
  check(moved >= 2, `${tag}: the sphere moved while the page animated (${moved} distinct positions in its first ${report.moverPositions.length} frames)`);
  check(report.bakedLights.length === khrLights.length && khrLights.length === 3,
    `${tag}: the example found the asset's ${khrLights.length} KHR_lights_punctual lights (${report.bakedLights.map((l) => l.type).join(', ')})`);
  check(report.bakedLights.every((l) => l.visible === false), `${tag}: every baked light is hidden`);

  let worst = 0, minExcess = Infinity, lumMin = Infinity, lumMax = 0;
  for (const s of report.samples) {
    const E = s.expected, P = s.pixel, L = s.withLights;
    let err = 0, excess = 0;
    for (let k = 0; k < 3; k++) {
      err = Math.max(err, Math.abs(P[k] - E[k]) / Math.max(Math.abs(E[k]), 1e-6));
      excess = Math.max(excess, (L[k] - P[k]) / Math.abs(E[k]));
    }
    worst = Math.max(worst, err);
    minExcess = Math.min(minExcess, excess);
    const lum = 0.2126 * E[0] + 0.7152 * E[1] + 0.0722 * E[2];
    lumMin = Math.min(lumMin, lum);
    lumMax = Math.max(lumMax, lum);
    console.log(`  t ${s.t.toFixed(3)} at (${s.position.map((x) => x.toFixed(2)).join(', ')}): pixel ${P.slice(0, 3).map((x) => x.toPrecision(6)).join(' ')}, ` +
      `probes ${E.map((x) => x.toPrecision(6)).join(' ')}, with the baked lights ${L.slice(0, 3).map((x) => x.toPrecision(4)).join(' ')}`);
    check(P[3] > 0 && E.every((x) => x > 0), `${tag} t ${s.t.toFixed(3)}: the sphere covers the centre pixel and is lit (E > 0)`);
    check(err <= 1e-4, `${tag} t ${s.t.toFixed(3)}: the sphere's pixel = the probes' irradiance there within 1e-4 relative (${err.toExponential(2)})`);
  }
  check(report.samples.length === 8, `${tag}: 8 points of the path sampled`);
  console.log(`  sphere pixel vs the probes' irradiance: max relative error ${worst.toExponential(2)} over ${report.samples.length} points x 3 channels`);
  console.log(`  irradiance along the path: luminance ${lumMin.toPrecision(4)} .. ${lumMax.toPrecision(4)}; ` +
    `the baked lights shown add at least ${(100 * minExcess).toFixed(0)} % (max over channels, min over points)`);
  check(lumMax > 1.1 * lumMin, `${tag}: the sphere's irradiance changes as it moves through the volume (max > 1.1 min)`);
  check(minExcess > 0.05, `${tag}: showing the baked lights changes every sampled pixel by > 5 %: the hidden lights are what the comparison sees`);
  const v = report.view;
  console.log(`  the example's view: ${v.covered} of ${v.pixels} pixels covered, ${v.lit} lit`);
  check(v.finite && v.covered > 0.2 * v.pixels && v.lit > 0.95 * v.covered, `${tag}: the example's view: the asset covers > 20 % of it and > 95 % of that is lit, all finite`);
}
// The same bake as .glb and as .zhp: the same path (the grid's box is the same in the scene) and
// the same irradiance along it (the plugin's irradianceAt in glTF axes, volumeIrradiance in zhc axes).
if (reports.glb.ready && reports.zhp.ready) {
  let worstPos = 0, worstE = 0, mean = 0;
  reports.glb.samples.forEach((s, i) => {
    const z = reports.zhp.samples[i];
    for (let k = 0; k < 3; k++) {
      worstPos = Math.max(worstPos, Math.abs(s.position[k] - z.position[k]));
      worstE = Math.max(worstE, Math.abs(s.expected[k] - z.expected[k]), Math.abs(s.pixel[k] - z.pixel[k]));
      mean += s.expected[k] / (3 * reports.glb.samples.length);
    }
  });
  console.log(`.glb vs .zhp page: path points within ${worstPos.toExponential(2)}, irradiance and pixels within ${worstE.toExponential(2)} (mean E ${mean.toPrecision(4)})`);
  check(worstPos <= 1e-9 && worstE <= 1e-5 * mean, 'the .zhp page moves the sphere along the same path and shows the same irradiance as the .glb page (1e-5 of the mean)');
}
finish('examples/web');
