// js.astc_webgl's WebGPU page: runtime/zhc.wgsl's IrradZ functions on the items of /work/irradz_items.bin
// (per item 12 words: I_z texel rgb, dwa rgb, normal xyz (f32), lo, hi (f32), flags (u32: bit 0 LDR
// I_z, bit 1 AHD)); posts 6 floats per item: the irradiance and the I_z used (decoded for LDR).
const report = { errors: window.zhcErrors, webgpu: false, compilation: [] };
try {
  if (!navigator.gpu) throw new Error('navigator.gpu is missing (WebGPU disabled)');
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) throw new Error('no WebGPU adapter');
  const device = await adapter.requestDevice();
  device.addEventListener('uncapturederror', (e) => window.zhcErrors.push('uncaptured WebGPU error: ' + e.error.message));
  report.webgpu = true;
  const kernel = `
@group(0) @binding(0) var<storage, read> items: array<u32>;
@group(0) @binding(1) var<storage, read_write> outv: array<f32>;
@compute @workgroup_size(64) fn irradz_kernel(@builtin(global_invocation_id) gid: vec3<u32>) {
  let i = gid.x;
  if (i >= arrayLength(&items) / 12u) { return; }
  let b = 12u * i;
  let f = items[b + 11u];
  let t = vec3<f32>(bitcast<f32>(items[b]), bitcast<f32>(items[b + 1u]), bitcast<f32>(items[b + 2u]));
  let dwa = vec3<f32>(bitcast<f32>(items[b + 3u]), bitcast<f32>(items[b + 4u]), bitcast<f32>(items[b + 5u]));
  let n = vec3<f32>(bitcast<f32>(items[b + 6u]), bitcast<f32>(items[b + 7u]), bitcast<f32>(items[b + 8u]));
  var iz = t;
  if ((f & 1u) != 0u) { iz = zhcIrradZIzFromLdr(t, vec2<f32>(bitcast<f32>(items[b + 9u]), bitcast<f32>(items[b + 10u]))); }
  let e = zhcIrradZIrradianceAstc(iz, dwa, n, (f >> 1u) & 1u);
  let o = 6u * i;
  outv[o] = e.x; outv[o + 1u] = e.y; outv[o + 2u] = e.z;
  outv[o + 3u] = iz.x; outv[o + 4u] = iz.y; outv[o + 5u] = iz.z;
}`;
  const code = (await (await fetch('/runtime/zhc.wgsl')).text()) + '\n' + kernel;
  device.pushErrorScope('validation');
  const module = device.createShaderModule({ code });
  const ci = await module.getCompilationInfo();
  for (const m of ci.messages) report.compilation.push(`${m.type} ${m.lineNum}:${m.linePos} ${m.message}`);
  const pipeline = device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: 'irradz_kernel' } });
  const items = new Uint8Array(await (await fetch('/work/irradz_items.bin')).arrayBuffer());
  const count = items.byteLength / 48;
  const inBuf = device.createBuffer({ size: items.byteLength, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_DST });
  device.queue.writeBuffer(inBuf, 0, items);
  const outSize = 24 * count;
  const out = device.createBuffer({ size: outSize, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC });
  const read = device.createBuffer({ size: outSize, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
  const bind = device.createBindGroup({ layout: pipeline.getBindGroupLayout(0), entries: [
    { binding: 0, resource: { buffer: inBuf } }, { binding: 1, resource: { buffer: out } }] });
  const enc = device.createCommandEncoder();
  const pass = enc.beginComputePass();
  pass.setPipeline(pipeline);
  pass.setBindGroup(0, bind);
  pass.dispatchWorkgroups(Math.ceil(count / 64));
  pass.end();
  enc.copyBufferToBuffer(out, 0, read, 0, outSize);
  device.queue.submit([enc.finish()]);
  const err = await device.popErrorScope();
  if (err) throw new Error('pipeline / dispatch: ' + err.message);
  await read.mapAsync(GPUMapMode.READ);
  report.out = Array.from(new Float32Array(read.getMappedRange().slice(0)));
  read.unmap();
} catch (e) {
  window.zhcErrors.push('exception: ' + (e && e.stack || e));
}
console.log('zhc irradz wgsl page done');
await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
