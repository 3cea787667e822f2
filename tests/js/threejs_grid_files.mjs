// three.js loads zhc's LightProbeGrid files with its own loaders (CTest: js.threejs_grid_files).
// Usage: node threejs_grid_files.mjs TEST_ENGINE_FILE_THREEJS WORK_DIR [CHROMIUM]
//
//  1. test_engine_file_threejs --gtest_filter=ThreejsGridFixtures.* with ZHC_THREEJS_GRID_FIXTURES
//     writes grid.exr (threejs_grid_exr) and grid.ktx2 (threejs_grid_ktx2) of a 4 x 3 x 5 grid of
//     random probes, and expected.json: 16 points and normals per file (three.js's world axes) with
//     the entry's irradiance there (the 8 corner probes' texels blended at p + d spacing / 2, then
//     the shader's SH evaluation / pi: zhc units) and the sample's term scale S (the sum of the
//     terms' magnitudes, >= |E|);
//  2. headless Chromium runs tests/js/browser/threejs_grid_files_page.mjs twice: EXRLoader (FloatType)
//     / KTX2Loader, runtime/web/zhc_threejs_grid.mjs lightProbeGridFromTexture with LightProbeGridWebGL
//     (SwiftShader WebGL2), then with WebGPURenderer and LightProbeGrid (Chromium's WebGPU on
//     SwiftShader), a white Lambertian sphere per sample, the pixel that shades the point;
//  3. the pixel equals the expected irradiance within 2e-5 S per channel (float32 arithmetic in the
//     shader and the texture filter, float32 sample points; the files' values are what the entry
//     evaluates: the binary16 rounding of the KTX2 atlas is in the expectation); WebGPU's grid is
//     binary16, so the EXR's float32 atlas rounded for it: 2^-11 S + 2e-5 S;
//     the bounds three.js's grid gets equal the file's, KTX2Loader returns a HalfFloatType
//     Data3DTexture, EXRLoader a FloatType texture, and lightProbeGridFromTexture refuses bounds that
//     do not fit, a changed padding slice and a non-grid class.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { checker, freshWork, repoRoot } from './fixtures.mjs';
import { chromiumPages } from './chromium_page.mjs';

const [writer, workArg, chromiumArg] = process.argv.slice(2);
if (!writer || !workArg) {
  console.error('usage: node threejs_grid_files.mjs TEST_ENGINE_FILE_THREEJS WORK_DIR [CHROMIUM]');
  process.exit(2);
}
const chromium = chromiumArg || '/usr/bin/chromium';
const work = freshWork(workArg);
const here = path.dirname(fileURLToPath(import.meta.url));
const { check, finish } = checker();

execFileSync(writer, ['--gtest_filter=ThreejsGridFixtures.*'], { env: { ...process.env, ZHC_THREEJS_GRID_FIXTURES: work }, stdio: 'inherit' });
const expected = JSON.parse(fs.readFileSync(path.join(work, 'expected.json'), 'utf8'));
check(expected.files.map((f) => f.file).join(',') === 'grid.exr,grid.ktx2', 'the writer wrote grid.exr and grid.ktx2');

const pages = await chromiumPages({
  roots: { '/runtime/web/': path.join(repoRoot, 'runtime', 'web'), '/three/': path.join(here, 'node_modules', 'three'), '/test/': path.join(here, 'browser'), '/work/': work },
  work, chromium, check,
});
const DONE = 'zhc three.js grid files page done';
const reports = {
  webgl: await pages.runPage('threejs_grid_files.html', ['--use-angle=swiftshader'], 'webgl', DONE),
  webgpu: await pages.runPage('threejs_grid_files_webgpu.html', ['--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader', '--use-angle=swiftshader'], 'webgpu', DONE),
};
pages.close();
fs.writeFileSync(path.join(work, 'report.json'), JSON.stringify(reports, null, 1));
if (reports.webgl === null || reports.webgpu === null) process.exit(1);
check(reports.webgl.webgl2 === true && reports.webgl.floatLinear === true, 'webgl: WebGL2 with OES_texture_float_linear');
check(reports.webgpu.webgpuBackend === true, 'webgpu: WebGPURenderer runs on its WebGPU backend (not the WebGL fallback)');
const TOL = 2e-5, TOL_HALF = 2 ** -11 + 2e-5;
for (const [tag, report] of Object.entries(reports)) {
  for (const e of report.errors ?? []) console.log(`  ${tag} page: ${e}`);
  check((report.errors ?? []).length === 0, `${tag}: no console error, warning or exception in the page`);
  check(report.three === '187', `${tag}: three.js r187 (the pinned version)`);
  check(Array.isArray(report.files) && report.files.length === expected.files.length, `${tag}: every file reported`);
  for (const r of report.files ?? []) {
    const f = expected.files.find((x) => x.file === r.file);
    const isKtx2 = r.file.endsWith('.ktx2');
    const what = `${tag} ${r.file}`;
    check(r.loadedType === (isKtx2 ? 'half' : 'float'), `${what}: the loader's texture type (${r.loadedType})`);
    if (isKtx2) check(r.ktx2Data3D === true, `${what}: KTX2Loader returns a HalfFloatType Data3DTexture`);
    // WebGPU's grid is binary16: the float32 EXR atlas is rounded for it.
    const half = isKtx2 || tag === 'webgpu';
    check(r.atlasType === (half ? 'half' : 'float'), `${what}: the grid's atlas type (${r.atlasType})`);
    check(r.refusals.length === 3 && r.refusals.every((x) => x === true), `${what}: refusals (${r.refusals})`);
    check(JSON.stringify(r.resolution) === JSON.stringify(f.bounds.resolution), `${what}: resolution ${r.resolution}`);
    const box = [...f.bounds.boundingBox.min, ...f.bounds.boundingBox.max];
    check(r.boundingBox.every((x, i) => Math.abs(x - box[i]) <= 1e-6 * (1 + Math.abs(box[i]))), `${what}: bounding box ${r.boundingBox} = ${box}`);
    check(r.samples.length === f.samples.length, `${what}: every sample rendered`);
    // The expectation holds the file's values: the KTX2's binary16, the EXR's float32 (which the
    // WebGPU grid rounds to binary16: relative 2^-11 per coefficient, within 2^-11 S).
    const tol = tag === 'webgpu' && !isKtx2 ? TOL_HALF : TOL;
    let worst = 0;
    r.samples.forEach((px, i) => {
      const s = f.samples[i];
      for (let c = 0; c < 3; c++) worst = Math.max(worst, Math.abs(px[c] - s.irradiance[c]) / s.termScale[c]);
    });
    console.log(`${what}: worst |pixel - E| / S = ${worst.toExponential(3)} over ${r.samples.length} samples (tolerance ${tol.toExponential(3)})`);
    check(worst <= tol, `${what}: pixels equal the entry's irradiance within ${tol.toExponential(3)} S`);
  }
}
finish('three.js grid files');
