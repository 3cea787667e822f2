// The browser side of tests/js/browser_test.mjs: loads each packed-encoding .glb with three.js's
// GLTFLoader + ZhcLightProbesPlugin, evaluates irradiance for every probe in JS and in a WebGL2
// shader (zhc_irradiance.glsl.mjs, rendered into an RGBA32F target and read back), compares with
// zhc's values from /work/spec.json and POSTs the measurements to /result.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { ZhcLightProbesPlugin } from '/runtime/web/zhc_light_probes_plugin.mjs';
import { zhcIrradianceGlsl, packedWords } from '/runtime/web/zhc_irradiance.glsl.mjs';
import { gltfToZhcDir, kY00, normalizeOr } from '/runtime/web/zhc_runtime.mjs';

async function main() {
  const spec = await (await fetch('/work/spec.json')).json();
  const canvas = document.createElement('canvas');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
  const gl = renderer.getContext();
  const dbg = gl.getExtension('WEBGL_debug_renderer_info');
  const report = {
    webgl2: gl instanceof WebGL2RenderingContext,
    colorBufferFloat: !!gl.getExtension('EXT_color_buffer_float'),
    renderer: dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER),
    files: [],
  };
  const loader = new GLTFLoader();
  loader.register((parser) => new ZhcLightProbesPlugin(parser));
  for (const f of spec.files) {
    const gltf = await loader.loadAsync(`/work/${f.glb}`);
    const v = gltf.userData.zhcLightProbes[0];
    const count = v.count, dirs = spec.dirs, D = dirs.length, DZ = f.expected[0].length;
    const r = { glb: f.glb, encoding: v.encoding, count, directions: D, zhcDirections: DZ, jsCompared: 0, jsBitExact: 0,
      jsWorst: 0, gpuCompared: 0, gpuPackedWorst: 0, gpuSh3Worst: 0, gpuVsJsWorst: 0, gpuNonFinite: 0 };
    // Per probe scale: the DC term of the irradiance, Y00 * max_k |c0_k|.
    const scale = (p) => kY00 * Math.max(Math.abs(v.sh[p * 27]), Math.abs(v.sh[p * 27 + 1]), Math.abs(v.sh[p * 27 + 2]));
    const js = [];
    for (let p = 0; p < count; p++) {
      js.push(dirs.map((d) => v.irradiance(p, d)));
      for (let d = 0; d < DZ; d++) {
        const want = f.expected[p][d], got = js[p][d];
        r.jsCompared++;
        if (want.every((w, k) => Object.is(Math.fround(w), got[k]))) r.jsBitExact++;
        for (let k = 0; k < 3; k++) if (scale(p) > 0) r.jsWorst = Math.max(r.jsWorst, Math.abs(got[k] - Math.fround(want[k])) / scale(p));
      }
    }
    // GPU: row d < D: the packed words (zhcIrradiance<Encoding>); row D + d: the float SH3 hub (decoded by zhc_runtime.mjs).
    const texels = Math.ceil(v.bytesPerProbe / 16);
    const words = new THREE.DataTexture(packedWords(v.bytes, count, v.bytesPerProbe), count * texels, 1, THREE.RGBAIntegerFormat, THREE.UnsignedIntType);
    const call = {
      zh3_q16: 'zhcIrradianceZh3Q16(texelFetch(uWords, ivec2(px.x, 0), 0), n)',
      zh3_solved_q16: 'zhcIrradianceZh3Q16(texelFetch(uWords, ivec2(px.x, 0), 0), n)',
      sh3_q28: 'zhcIrradianceSh3Q28(texelFetch(uWords, ivec2(2 * px.x, 0), 0), texelFetch(uWords, ivec2(2 * px.x + 1, 0), 0), n)',
      sh2_q: 'zhcIrradianceSh2Q(texelFetch(uWords, ivec2(px.x, 0), 0), n)',
      hall_curve_q: 'zhcIrradianceHallCurveQ(texelFetch(uWords, ivec2(px.x, 0), 0), n)',
    }[v.encoding];
    words.internalFormat = 'RGBA32UI';
    const shData = new Float32Array(count * 9 * 4);
    for (let p = 0; p < count; p++)
      for (let i = 0; i < 9; i++)
        for (let k = 0; k < 3; k++) shData[(p * 9 + i) * 4 + k] = v.sh[p * 27 + i * 3 + k];
    const sh = new THREE.DataTexture(shData, 9, count, THREE.RGBAFormat, THREE.FloatType);
    sh.internalFormat = 'RGBA32F';
    const dirData = new Float32Array(D * 4);
    dirs.forEach((d, j) => dirData.set(gltfToZhcDir(normalizeOr(d, [0, 1, 0])), j * 4));
    const dirTex = new THREE.DataTexture(dirData, D, 1, THREE.RGBAFormat, THREE.FloatType);
    dirTex.internalFormat = 'RGBA32F';
    for (const t of [words, sh, dirTex]) {
      t.minFilter = t.magFilter = THREE.NearestFilter;
      t.generateMipmaps = false;
      t.needsUpdate = true;
    }
    const material = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3,
      uniforms: { uWords: { value: words }, uSh: { value: sh }, uDirs: { value: dirTex }, uD: { value: D } },
      vertexShader: 'in vec3 position;\nvoid main() { gl_Position = vec4(position.xy, 0.0, 1.0); }\n',
      fragmentShader: `precision highp float;
precision highp int;
precision highp usampler2D;
precision highp sampler2D;
uniform usampler2D uWords;
uniform sampler2D uSh;
uniform sampler2D uDirs;
uniform int uD;
out vec4 outColor;
${zhcIrradianceGlsl(v.params)}
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec3 n = texelFetch(uDirs, ivec2(px.y % uD, 0), 0).xyz;
  vec3 e;
  if (px.y < uD) {
    e = ${call};
  } else {
    vec3 c[9];
    for (int i = 0; i < 9; ++i) c[i] = texelFetch(uSh, ivec2(i, px.x), 0).xyz;
    e = zhcIrradianceSh3(c, n);
  }
  outColor = vec4(e, 1.0);
}
`,
    });
    const scene = new THREE.Scene();
    scene.add(new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material));
    const camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
    const target = new THREE.WebGLRenderTarget(count, 2 * D, { type: THREE.FloatType, format: THREE.RGBAFormat,
      minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, depthBuffer: false });
    renderer.setRenderTarget(target);
    renderer.render(scene, camera);
    const pixels = new Float32Array(count * 2 * D * 4);
    renderer.readRenderTargetPixels(target, 0, 0, count, 2 * D, pixels);
    renderer.setRenderTarget(null);
    for (let p = 0; p < count; p++) {
      const s = scale(p);
      for (let d = 0; d < D; d++)
        for (const [row, key] of [[d, 'gpuPackedWorst'], [D + d, 'gpuSh3Worst']]) {
          const px = pixels.subarray((row * count + p) * 4, (row * count + p) * 4 + 3);
          if (!px.every(Number.isFinite)) r.gpuNonFinite++;
          if (row === d) r.gpuCompared++;
          for (let k = 0; k < 3; k++) {
            if (!(s > 0)) continue;
            if (d < DZ) r[key] = Math.max(r[key], Math.abs(px[k] - f.expected[p][d][k]) / s);
            r.gpuVsJsWorst = Math.max(r.gpuVsJsWorst, Math.abs(px[k] - js[p][d][k]) / s);
          }
        }
    }
    // three.js itself: a white MeshLambertMaterial plane lit only by volume.lightProbe(p) (three's
    // LightProbe shading, pi-scaled irradiance times BRDF_Lambert = albedo / pi) shows E(n) in a
    // linear float target. Plane normal = the direction (glTF = three.js world axes).
    r.threeCompared = 0;
    r.threeWorst = 0;
    {
      const lit = new THREE.Scene();
      const plane = new THREE.Mesh(new THREE.PlaneGeometry(4, 4), new THREE.MeshLambertMaterial({ color: 0xffffff }));
      lit.add(plane);
      const cam = new THREE.OrthographicCamera(-1, 1, 1, -1, 0.1, 10);
      const rt = new THREE.WebGLRenderTarget(2, 2, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
      const px = new Float32Array(4);
      const step = Math.max(1, Math.floor(count / 16));
      for (let p = 0; p < count; p += step) {
        const probe = v.lightProbe(p);
        probe.position.set(0, 0, 0);
        lit.add(probe);
        for (let d = 0; d < DZ; d++) {
          const n = new THREE.Vector3(...dirs[d]).normalize();
          plane.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), n);
          cam.position.copy(n).multiplyScalar(2);
          cam.up.set(Math.abs(n.y) > 0.9 ? 1 : 0, Math.abs(n.y) > 0.9 ? 0 : 1, 0);
          cam.lookAt(0, 0, 0);
          cam.updateMatrixWorld();
          renderer.setRenderTarget(rt);
          renderer.render(lit, cam);
          renderer.readRenderTargetPixels(rt, 1, 1, 1, 1, px);
          renderer.setRenderTarget(null);
          r.threeCompared++;
          for (let k = 0; k < 3; k++) if (scale(p) > 0) r.threeWorst = Math.max(r.threeWorst, Math.abs(px[k] - f.expected[p][d][k]) / scale(p));
        }
        lit.remove(probe);
      }
    }
    report.files.push(r);
  }
  return report;
}

let report;
try {
  report = await main();
} catch (e) {
  window.zhcErrors.push('exception: ' + (e && e.stack || e));
  report = {};
}
report.errors = window.zhcErrors;
console.log('zhc runtime/web page done');  // the driver checks that console output reaches its log
await new Promise((resolve) => setTimeout(resolve, 200));
await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
document.title = 'zhc runtime/web browser test: done';
