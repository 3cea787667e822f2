// runtime/web as an npm package (CTest: js.web_package).
// Usage: node web_package.mjs ZHC_BINARY NPM WORK_DIR
//
//  1. runtime/web/package.json: not private, its version = the top-level CMakeLists.txt's project
//     VERSION, an `exports` entry with `types` and `default` per module, every module and its
//     declarations in `files`, a `three` peer range that the tested three.js (tests/js, r187)
//     satisfies and whose lowest version has LightProbeGridWebGL (three.js 0.186.0 is the first
//     release with it: 0.185.0 has only the WebGPU LightProbeGrid);
//  2. `npm pack runtime/web` writes zhc-runtime-VERSION.tgz holding exactly those files;
//  3. a consumer folder installs the tarball (`npm install --offline ./zhc-runtime-VERSION.tgz`:
//     the package has no dependencies; three, @types/three and @gltf-transform/* are linked from
//     tests/js/node_modules, installed by js.npm_install, so nothing is downloaded);
//  4. every export of every entry point, as Node imports it through the `exports` map, is declared
//     (TypeScript's own resolution of the same specifiers through the `types` conditions) as what
//     it is (function, class, value; parameter counts against the functions' and methods' lengths;
//     a class's methods), the declarations export no value the module lacks, the declared name
//     unions equal the codec table's values; web_package/consumer.ts imports every export;
//  5. `tsc --strict --noEmit` on the consumer (tests/js/web_package: consumer.ts and its tsconfig,
//     moduleResolution nodenext, then bundler) passes, @ts-expect-error misuses included; with one
//     parameter of the installed declarations widened to `any`, tsc fails on that misuse (so the
//     check can fail);
//  6. the consumer compiled by tsc runs under Node on a glTF and a .zhp baked by zhc from
//     examples/hall.gltf (`-r zh3_q16`): volume, lights hidden, the plugin's irradianceAt = the .zhp
//     volume's irradiance (1e-6 of the mean, js.runtime_volume's bound), compact volume, three.js's
//     grid, the glTF-Transform round trip keeping the probe bytes; and a default (`sh3`) bake is
//     refused by compactVolume with "encoding sh3 is not supported".
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync, spawnSync } from 'node:child_process';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { checker, freshWork, repoRoot } from './fixtures.mjs';

const [zhc, npm, workArg] = process.argv.slice(2);
if (!zhc || !npm || !workArg) {
  console.error('usage: node web_package.mjs ZHC_BINARY NPM WORK_DIR');
  process.exit(2);
}
const work = freshWork(workArg);
const here = path.dirname(fileURLToPath(import.meta.url));
const repo = repoRoot;
const webDir = path.join(repo, 'runtime', 'web');
const modules = path.join(here, 'node_modules');
const { check, finish } = checker();
for (const dep of ['typescript', '@types/three', 'three', '@gltf-transform/core', '@gltf-transform/extensions']) {
  if (!fs.existsSync(path.join(modules, dep, 'package.json'))) {
    console.error(`web_package.mjs: ${dep} is not in tests/js/node_modules (npm ci in tests/js, with its devDependencies)`);
    process.exit(1);
  }
}
const ts = createRequire(import.meta.url)('typescript');
const tsc = path.join(modules, 'typescript', 'bin', 'tsc');

// --- 1. package.json ----------------------------------------------------------------------------------
const pkg = JSON.parse(fs.readFileSync(path.join(webDir, 'package.json'), 'utf8'));
const cmakeVersion = /project\(\s*zhc\s+VERSION\s+([0-9.]+)/.exec(fs.readFileSync(path.join(repo, 'CMakeLists.txt'), 'utf8'))?.[1];
check(cmakeVersion !== undefined, 'CMakeLists.txt: project(zhc VERSION x.y.z)');
check(pkg.version === cmakeVersion, `package version ${pkg.version} = zhc's project VERSION ${cmakeVersion}`);
check(pkg.private === undefined, 'the package is not private (npm publish and npm pack take it)');
check(pkg.name === '@zhc/runtime' && pkg.type === 'module', 'name @zhc/runtime, ES modules');
const sources = fs.readdirSync(webDir).filter((f) => f.endsWith('.mjs') && !f.endsWith('.d.mts')).sort();
const entries = Object.entries(pkg.exports).filter(([key]) => key !== './package.json');
const exported = new Set();
for (const [key, value] of entries) {
  const ok = value && typeof value === 'object' && Object.keys(value)[0] === 'types' && typeof value.default === 'string' &&
    value.types === value.default.replace(/\.mjs$/, '.d.mts') && fs.existsSync(path.join(webDir, value.types)) && fs.existsSync(path.join(webDir, value.default));
  check(ok, `exports["${key}"]: "types" first, then "default", both files present (${JSON.stringify(value)})`);
  if (ok) exported.add(value.default.slice(2));
}
check(sources.every((f) => exported.has(f)), `every module of runtime/web has an exports entry (${sources.join(', ')})`);
const expectedFiles = [...sources.flatMap((f) => [f, f.replace(/\.mjs$/, '.d.mts')]), 'README.md'].sort();
check(JSON.stringify([...pkg.files].sort()) === JSON.stringify(expectedFiles), `files: every module, its declarations and README.md (${pkg.files.length})`);
const threeVersion = JSON.parse(fs.readFileSync(path.join(modules, 'three', 'package.json'), 'utf8')).version;
const semver = (v) => v.split('.').map(Number);
const atLeast = (a, b) => { for (let i = 0; i < 3; i++) if (a[i] !== b[i]) return a[i] > b[i]; return true; };
const peer = /^>=(\d+\.\d+\.\d+)$/.exec(pkg.peerDependencies?.three ?? '');
check(peer !== null, `peerDependencies.three is a lower bound ">=x.y.z" (${pkg.peerDependencies?.three})`);
if (peer) {
  check(atLeast(semver(threeVersion), semver(peer[1])), `the tested three.js ${threeVersion} is in the peer range ${peer[0]}`);
  check(atLeast(semver(peer[1]), [0, 186, 0]), `the range's lowest version ${peer[1]} has LightProbeGridWebGL (three.js >= 0.186.0)`);
}
check(['LightProbeGrid.js', 'LightProbeGridWebGL.js'].every((f) => fs.existsSync(path.join(modules, 'three', 'examples', 'jsm', 'lighting', f))),
  `three.js ${threeVersion} has LightProbeGrid and LightProbeGridWebGL`);
check(pkg.peerDependencies?.['@types/three'] === pkg.peerDependencies?.three, '@types/three has the same peer range as three');

// --- 2. npm pack -------------------------------------------------------------------------------------------
execFileSync(npm, ['pack', webDir, '--pack-destination', work, '--silent'], { cwd: work });
const tarball = path.join(work, `zhc-runtime-${pkg.version}.tgz`);
check(fs.existsSync(tarball), `npm pack wrote ${path.basename(tarball)}`);
const packed = execFileSync('tar', ['tzf', tarball]).toString().trim().split('\n').sort();
const wantPacked = [...expectedFiles, 'package.json'].map((f) => `package/${f}`).sort();
check(JSON.stringify(packed) === JSON.stringify(wantPacked), `the tarball holds the files list and package.json (${packed.length} files)`);

// --- 3. the consumer -----------------------------------------------------------------------------------
const consumer = path.join(work, 'consumer');
fs.mkdirSync(consumer);
fs.writeFileSync(path.join(consumer, 'package.json'), JSON.stringify({ name: 'zhc-runtime-consumer', private: true, type: 'module' }, null, 1));
execFileSync(npm, ['install', '--offline', '--no-audit', '--no-fund', '--silent', tarball], { cwd: consumer });
const installed = path.join(consumer, 'node_modules', '@zhc', 'runtime');
check(JSON.parse(fs.readFileSync(path.join(installed, 'package.json'), 'utf8')).version === pkg.version, `npm install put @zhc/runtime ${pkg.version} in the consumer`);
check(fs.realpathSync(installed) === installed, 'the installed package is a copy from the tarball, not a link');
const recorded = JSON.parse(fs.readFileSync(path.join(consumer, 'package.json'), 'utf8')).dependencies?.['@zhc/runtime'] ?? '';
check(recorded.endsWith(path.basename(tarball)), `the consumer's package.json depends on the tarball (${recorded})`);
for (const dep of ['three', '@types/three', '@gltf-transform/core', '@gltf-transform/extensions']) {
  fs.mkdirSync(path.dirname(path.join(consumer, 'node_modules', dep)), { recursive: true });
  fs.symlinkSync(path.join(modules, dep), path.join(consumer, 'node_modules', dep), 'dir');
}
for (const f of ['consumer.ts', 'tsconfig.json', 'draco3dgltf.d.ts', 'run_consumer.mjs']) fs.copyFileSync(path.join(here, 'web_package', f), path.join(consumer, f));

// --- 4. every export declared --------------------------------------------------------------------------
const specifiers = entries.map(([key]) => (key === '.' ? pkg.name : `${pkg.name}/${key.slice(2)}`));
const listed = spawnSync(process.execPath, ['--input-type=module', '-e',
  `const out = { shapes: {} };
   const shape = (v) => {
     if (typeof v !== 'function') return { kind: typeof v };
     if (!/^class\\b/.test(Function.prototype.toString.call(v))) return { kind: 'function', length: v.length };
     const methods = {};
     for (const n of Object.getOwnPropertyNames(v.prototype))
       if (n !== 'constructor' && !n.startsWith('_') && typeof Object.getOwnPropertyDescriptor(v.prototype, n).value === 'function') methods[n] = v.prototype[n].length;
     return { kind: 'class', length: v.length, derived: Object.getPrototypeOf(v) !== Function.prototype, methods };
   };
   for (const s of ${JSON.stringify(specifiers)}) {
     const m = await import(s);
     out[s] = Object.keys(m).sort();
     out.shapes[s] = Object.fromEntries(Object.keys(m).map((n) => [n, shape(m[n])]));
   }
   const r = await import('${pkg.name}');
   out.table = { ZhcEncodingName: r.ENCODING_TABLE.map((e) => e.name), ZhcEncodingAlias: Object.keys(r.ENCODING_ALIASES),
     ZhcLayout: [...new Set(r.ENCODING_TABLE.map((e) => e.layout))], ZhcHallucination: [...new Set(r.ENCODING_TABLE.map((e) => e.hallucination))],
     ZhcAxis: [...new Set(r.ENCODING_TABLE.map((e) => e.axis))] };
   console.log(JSON.stringify(out));`],
{ cwd: consumer });
check(listed.status === 0, `Node imports every entry point through the exports map (${listed.stderr.toString().trim().split('\n').slice(-1)[0] ?? ''})`);
const runtimeExports = listed.status === 0 ? JSON.parse(listed.stdout.toString()) : {};
const tsconfig = ts.getParsedCommandLineOfConfigFile(path.join(consumer, 'tsconfig.json'), {}, { ...ts.sys, onUnRecoverableConfigFileDiagnostic: () => {} });
const program = ts.createProgram(tsconfig.fileNames, tsconfig.options);
const checker2 = program.getTypeChecker();
// What a declared value is: a function (the number of parameters before the first optional one,
// and of all), a class (its constructor's numbers and those of the methods declared here), or
// something else.
const arity = (sig) => {
  const params = sig.getParameters().map((p) => p.valueDeclaration);
  const optional = (d) => !!(d && ts.isParameter(d) && (d.questionToken || d.initializer || d.dotDotDotToken));
  const firstOptional = params.findIndex(optional);
  return { required: firstOptional < 0 ? params.length : firstOptional, total: params.length };
};
function declaredShape(symbol) {
  const type = checker2.getTypeOfSymbol(symbol);
  const ctors = type.getConstructSignatures();
  if (ctors.length) {
    // A class (or a const typed as one): the methods this package declares on its instances.
    const methods = {};
    for (const prop of checker2.getPropertiesOfType(ctors[0].getReturnType())) {
      const d = prop.valueDeclaration;
      if (d && (ts.isMethodDeclaration(d) || ts.isMethodSignature(d)) && d.getSourceFile().fileName.startsWith(installed + path.sep))
        methods[prop.name] = checker2.getTypeOfSymbol(prop).getCallSignatures().map(arity);
    }
    return { kind: 'class', ctor: ctors.map(arity), methods };
  }
  const sigs = type.getCallSignatures();
  return sigs.length ? { kind: 'function', sigs: sigs.map(arity) } : { kind: 'other' };
}
// A JavaScript function's length counts its parameters before the first one with a default; a
// parameter without a default may still be optional (the code handles undefined).
const fits = (sigs, length) => (sigs ?? []).some((a) => a.required <= length && length <= a.total);
const consumerSource = program.getSourceFile(path.join(consumer, 'consumer.ts'));
const imported = {}, declared = {};
for (const st of consumerSource.statements) {
  if (!ts.isImportDeclaration(st)) continue;
  const spec = st.moduleSpecifier.text;
  if (!specifiers.includes(spec)) continue;
  const clause = st.importClause;
  imported[spec] ??= new Set();
  if (!clause.isTypeOnly) {
    if (clause.name) imported[spec].add('default');
    if (clause.namedBindings && ts.isNamedImports(clause.namedBindings))
      for (const e of clause.namedBindings.elements) if (!e.isTypeOnly) imported[spec].add((e.propertyName ?? e.name).text);
  }
  const moduleSymbol = checker2.getSymbolAtLocation(st.moduleSpecifier);
  if (!moduleSymbol) continue;
  const file = moduleSymbol.valueDeclaration?.getSourceFile().fileName ?? '';
  declared[spec] = { file, values: new Set(), shapes: {} };
  for (const sym of checker2.getExportsOfModule(moduleSymbol)) {
    const target = sym.flags & ts.SymbolFlags.Alias ? checker2.getAliasedSymbol(sym) : sym;
    if (!(target.flags & ts.SymbolFlags.Value)) continue;
    declared[spec].values.add(sym.name);
    declared[spec].shapes[sym.name] = declaredShape(target);
  }
}
let exportCount = 0, shapeCount = 0;
for (const spec of specifiers) {
  const names = runtimeExports[spec] ?? [];
  exportCount += names.length;
  const d = declared[spec];
  check(d !== undefined && d.file.startsWith(installed + path.sep) && d.file.endsWith('.d.mts'),
    `${spec}: TypeScript resolves the installed package's declarations (${d ? path.relative(consumer, d.file) : 'none'})`);
  if (!d) continue;
  const missing = names.filter((n) => !d.values.has(n)), extra = [...d.values].filter((n) => !names.includes(n));
  check(missing.length === 0, `${spec}: all ${names.length} exports declared${missing.length ? ` (missing: ${missing.join(', ')})` : ''}`);
  check(extra.length === 0, `${spec}: no declared value the module lacks${extra.length ? ` (${extra.join(', ')})` : ''}`);
  // Each export is declared as what it is: functions with their parameters (required <= the
  // JavaScript function's length <= all), classes with their constructor and every method (but
  // the _-prefixed helpers, internal by convention).
  const wrongShape = [];
  for (const n of names) {
    const rt = runtimeExports.shapes[spec][n], dt = d.shapes[n];
    if (!dt) continue;
    if (rt.kind === 'function') {
      if (dt.kind !== 'function' || !fits(dt.sigs, rt.length)) wrongShape.push(`${n}: function of length ${rt.length}, declared ${JSON.stringify(dt)}`);
    } else if (rt.kind === 'class') {
      // (a derived class without a constructor of its own has length 0: its parent's takes the arguments)
      if (dt.kind !== 'class' || !((rt.derived && rt.length === 0) || fits(dt.ctor, rt.length))) wrongShape.push(`${n}: class, constructor length ${rt.length}, declared ${JSON.stringify(dt)}`);
      else {
        const rm = Object.keys(rt.methods).sort(), dm = Object.keys(dt.methods).sort();
        if (JSON.stringify(rm) !== JSON.stringify(dm)) wrongShape.push(`${n}: methods ${rm.join(',')}, declared ${dm.join(',')}`);
        for (const m of rm) if (dt.methods[m] && !fits(dt.methods[m], rt.methods[m])) wrongShape.push(`${n}.${m}: length ${rt.methods[m]}, declared ${JSON.stringify(dt.methods[m])}`);
      }
    } else if (dt.kind !== 'other') wrongShape.push(`${n}: a ${rt.kind}, declared as a ${dt.kind}`);
    shapeCount++;
  }
  check(wrongShape.length === 0, `${spec}: every export declared as what it is (functions' and methods' parameters, classes)${wrongShape.length ? `: ${wrongShape.join('; ')}` : ''}`);
  const notImported = names.filter((n) => !imported[spec]?.has(n));
  check(notImported.length === 0, `${spec}: consumer.ts imports every export${notImported.length ? ` (not: ${notImported.join(', ')})` : ''}`);
}
console.log(`${exportCount} exports in ${specifiers.length} entry points, all declared and imported by the consumer; ${shapeCount} compared as function / class / value with their parameter counts`);
// The declared unions of names that the codec table generates (zhc_runtime.mjs's GENERATED block):
// each union = the table's values, so a new table entry cannot leave the declarations behind.
{
  const runtimeDecl = declared[pkg.name] ? program.getSourceFile(declared[pkg.name].file) : null;
  for (const [alias, values] of Object.entries(runtimeExports.table ?? {})) {
    const node = runtimeDecl?.statements.find((st) => ts.isTypeAliasDeclaration(st) && st.name.text === alias);
    const type = node ? checker2.getTypeAtLocation(node.name) : null;
    const members = type ? (type.isUnion() ? type.types : [type]).filter((t) => t.isStringLiteral()).map((t) => t.value).sort() : [];
    check(JSON.stringify(members) === JSON.stringify([...values].sort()),
      `type ${alias} = the codec table's ${values.length} values${members.length !== values.length ? ` (declared ${members.length})` : ''}`);
  }
  console.log(`declared unions = the codec table's values: ${Object.keys(runtimeExports.table ?? {}).join(', ')}`);
}

// --- 5. tsc --strict ------------------------------------------------------------------------------------
const runTsc = (...args) => spawnSync(process.execPath, [tsc, '-p', '.', '--strict', ...args], { cwd: consumer });
const strict = runTsc('--noEmit');
const strictOut = strict.stdout.toString() + strict.stderr.toString();
if (strict.status !== 0) console.log(strictOut);
check(strict.status === 0, 'tsc --strict --noEmit: the consumer compiles against the installed declarations (@ts-expect-error misuses rejected)');
// A bundler project (Vite, esbuild, webpack): the same consumer under moduleResolution bundler.
const bundler = runTsc('--noEmit', '--module', 'esnext', '--moduleResolution', 'bundler');
if (bundler.status !== 0) console.log(bundler.stdout.toString());
check(bundler.status === 0, 'tsc --strict --noEmit --moduleResolution bundler: the consumer compiles too');
const expectErrors = (fs.readFileSync(path.join(consumer, 'consumer.ts'), 'utf8').match(/^\s*\/\/ @ts-expect-error/gm) ?? []).length;
console.log(`tsc --strict --noEmit: 0 errors, ${expectErrors} misuses rejected as expected`);
// Mutation: widen irradiance's normal to `any`; the misuse `irradiance(one, 'up')` then compiles and
// its @ts-expect-error is unused (TS2578).
const dts = path.join(installed, 'zhc_runtime.d.mts');
const original = fs.readFileSync(dts, 'utf8');
const signature = 'export declare function irradiance(sh: ArrayLike<number>, n: Vec3Like): Vec3;';
check(original.includes(signature), 'zhc_runtime.d.mts declares irradiance(sh, n: Vec3Like)');
fs.writeFileSync(dts, original.replace(signature, 'export declare function irradiance(sh: ArrayLike<number>, n: any): Vec3;'));
const widened = runTsc('--noEmit');
const widenedOut = widened.stdout.toString();
fs.writeFileSync(dts, original);
check(widened.status !== 0 && /consumer\.ts\(\d+,\d+\): error TS2578/.test(widenedOut) && widenedOut.trim().split('\n').length === 1,
  `with irradiance's normal widened to any, tsc fails on exactly that misuse (${widenedOut.trim()})`);

// --- 6. the compiled consumer on zhc's bake -------------------------------------------------------------
const emit = runTsc();
check(emit.status === 0 && fs.existsSync(path.join(consumer, 'out', 'consumer.js')), 'tsc --strict emits the consumer');
const hall = path.join(repo, 'examples', 'hall.gltf');
for (const [out, r] of [['hall.glb', 'zh3_q16'], ['hall.zhp', 'zh3_q16'], ['hall_sh3.zhp', 'sh3']])
  execFileSync(zhc, ['bake', hall, '-o', path.join(consumer, out), '-r', r, '--quiet']);
const ran = spawnSync(process.execPath, ['run_consumer.mjs', 'hall.glb', 'hall.zhp', 'hall_sh3.zhp'], { cwd: consumer });
check(ran.status === 0, `the compiled consumer runs (${ran.stderr.toString().trim().split('\n').slice(-3).join(' | ')})`);
if (ran.status !== 0) finish('@zhc/runtime package');
const { report, sh3Refusal } = JSON.parse(ran.stdout.toString());
fs.writeFileSync(path.join(work, 'consumer_report.json'), JSON.stringify(report, null, 1));
const glbJson = (() => {
  const b = fs.readFileSync(path.join(consumer, 'hall.glb'));
  return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
})();
const vdef = glbJson.extensions.ZHC_light_probes.volumes[0];
check(report.volumes === 1 && report.encoding === 'zh3_q16' && report.layout === 'grid' && report.counts.join() === vdef.grid.counts.join(),
  `the plugin decoded the baked volume (${report.encoding} ${report.counts.join('x')} grid)`);
check(report.lightsFound === glbJson.extensions.KHR_lights_punctual.lights.length && report.lightsVisibleAfter === 0,
  `the asset's ${report.lightsFound} KHR_lights_punctual lights (${report.lightTypes.join(', ')}) found and hidden`);
let mean = 0, worst = 0;
for (const e of report.zhpIrradiance) mean += (e[0] + e[1] + e[2]) / (3 * report.zhpIrradiance.length);
report.irradianceAt.forEach((e, i) => { for (let k = 0; k < 3; k++) worst = Math.max(worst, Math.abs(e[k] - report.zhpIrradiance[i][k])); });
console.log(`irradianceAt (glTF) vs volumeIrradiance (.zhp, zhc axes): max |diff| ${worst.toExponential(2)}, mean E ${mean.toPrecision(4)}`);
check(mean > 0 && worst <= 1e-6 * mean, 'the plugin\'s irradianceAt on the .glb = volumeIrradiance on the .zhp at the same points (1e-6 of the mean)');
check(report.zhpCount === report.glbCount && report.glbCount === vdef.count, `the .zhp and the .glb hold the same ${vdef.count} probes`);
// The bake writes validity and cell planes: the compact volume holds the plane texel (8 bytes) and,
// when a probe is invalid, the mask byte.
check(report.compactSize.join() === vdef.grid.counts.join() && vdef.planes !== undefined &&
  report.compactGpuBytesPerProbe === 16 + (report.compactMasked ? 1 : 0) + 8,
  `the compact volume: one RGBA32UI texel per zh3_q16 probe plus the RG32UI plane texel${report.compactMasked ? ' and the mask byte' : ''} (${report.compactGpuBytesPerProbe} bytes)`);
check(report.patchedSame === true, 'patchMaterialWithVolume returns the material, with onBeforeCompile set');
const g = vdef.grid;
check(report.gridSize.every((s, c) => Math.abs(s - g.counts[c] * g.spacing[c]) <= 1e-12 * Math.abs(s)) && report.atlasDepth === 7 * (g.counts[2] + 2),
  `three.js's LightProbeGridWebGL: box = counts x spacing (${report.gridSize.map((x) => x.toFixed(3)).join(' x ')}), atlas depth 7 (n_z + 2)`);
check(report.probeSHLength === 27 && report.decodedFirst.length === 27 && report.decodedFirst.every(Number.isFinite), 'probe SH3: 27 finite floats');
check(report.transformKeepsBytes === true && report.transformVolumes === 1, 'glTF-Transform (WebIO with the extension) writes the probe bytes back unchanged');
check(report.configHasExtension === true && report.sameExtensionClass === true,
  'gltf-transform.config.mjs lists the extension class defineZhcLightProbes(core) returns for the same core');
check(/encoding sh3 is not supported/.test(sh3Refusal ?? ''), `a default (sh3) bake: compactVolume refuses it ("${sh3Refusal}")`);
finish('@zhc/runtime package');
