// Page of tests/js/wgsl_test.mjs: runs runtime/zhc.wgsl in a WebGPU compute shader on the jobs the
// test server hands out and posts the raw float32 results back; the server compares them.
//
// Protocol: GET /job/next -> 204 when done, else a binary job: a 16-u32 header [kernel, stride,
// count, reserved...], the ZhcFormat uniform (80 bytes), then `count * stride` u32 probe words and
// `count * 3` f32 normals (kernel 0: decode + irradiance of one probe per item, 30 floats out;
// other kernels: see wgsl_kernel.wgsl). POST /job/result: the output floats. POST /done: a JSON summary.

const errors = window.zhcErrors;
const summary = { webgpu: false, adapter: '', jobs: 0, compilation: [], errors };

async function text(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r.text();
}

async function main() {
  if (!navigator.gpu) throw new Error('navigator.gpu is missing (WebGPU disabled)');
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) throw new Error('no WebGPU adapter');
  const info = adapter.info ?? {};
  summary.adapter = [info.vendor, info.architecture, info.device, info.description].filter(Boolean).join(' / ');
  const device = await adapter.requestDevice({ requiredLimits: { maxStorageBufferBindingSize: adapter.limits.maxStorageBufferBindingSize } });
  device.addEventListener('uncapturederror', (e) => errors.push('uncaptured WebGPU error: ' + e.error.message));
  summary.webgpu = true;
  const code = (await text('/runtime/zhc.wgsl')) + '\n' + (await text('/test/wgsl_kernel.wgsl'));
  device.pushErrorScope('validation');
  const module = device.createShaderModule({ code });
  const ci = await module.getCompilationInfo();
  for (const m of ci.messages) summary.compilation.push(`${m.type} ${m.lineNum}:${m.linePos} ${m.message}`);
  const pipelines = {};
  for (const entry of ['decode_kernel', 'volume_kernel'])
    if (code.includes(`fn ${entry}(`)) pipelines[entry] = device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: entry } });
  const err = await device.popErrorScope();
  if (err) throw new Error('shader module / pipeline: ' + err.message);

  for (;;) {
    const r = await fetch('/job/next');
    if (r.status === 204) break;
    if (!r.ok) throw new Error(`/job/next: HTTP ${r.status}`);
    const buf = await r.arrayBuffer();
    const head = new Uint32Array(buf, 0, 16);
    const [kernel, stride, count, outFloats, normalFloats] = head;
    const fmtBytes = buf.slice(64, 144);
    const words = buf.slice(144, 144 + 4 * count * stride);
    const normals = buf.slice(144 + 4 * count * stride, 144 + 4 * count * stride + 4 * count * normalFloats);
    const mk = (data, usage) => {
      const b = device.createBuffer({ size: Math.max(16, data.byteLength), usage: usage | GPUBufferUsage.COPY_DST });
      device.queue.writeBuffer(b, 0, data);
      return b;
    };
    const fmt = mk(fmtBytes, GPUBufferUsage.UNIFORM);
    const job = mk(new Uint32Array([stride, count, 0, 0]), GPUBufferUsage.UNIFORM);
    const wbuf = mk(words, GPUBufferUsage.STORAGE);
    const nbuf = mk(normals, GPUBufferUsage.STORAGE);
    const outSize = 4 * count * outFloats;
    const out = device.createBuffer({ size: outSize, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC });
    const read = device.createBuffer({ size: outSize, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
    const pipeline = pipelines[kernel === 0 ? 'decode_kernel' : 'volume_kernel'];
    if (!pipeline) throw new Error(`kernel ${kernel} is not in the shader`);
    device.pushErrorScope('validation');
    const bind = device.createBindGroup({ layout: pipeline.getBindGroupLayout(0), entries: [
      { binding: 0, resource: { buffer: fmt } }, { binding: 1, resource: { buffer: job } },
      { binding: 2, resource: { buffer: wbuf } }, { binding: 3, resource: { buffer: nbuf } },
      { binding: 4, resource: { buffer: out } }] });
    const enc = device.createCommandEncoder();
    const pass = enc.beginComputePass();
    pass.setPipeline(pipeline);
    pass.setBindGroup(0, bind);
    pass.dispatchWorkgroups(Math.ceil(count / 64));
    pass.end();
    enc.copyBufferToBuffer(out, 0, read, 0, outSize);
    device.queue.submit([enc.finish()]);
    const e2 = await device.popErrorScope();
    if (e2) throw new Error('dispatch: ' + e2.message);
    await read.mapAsync(GPUMapMode.READ);
    const result = read.getMappedRange().slice(0);
    read.unmap();
    for (const b of [fmt, job, wbuf, nbuf, out, read]) b.destroy();
    const p = await fetch('/job/result', { method: 'POST', body: result });
    if (!p.ok) throw new Error(`/job/result: HTTP ${p.status}`);
    summary.jobs++;
  }
}

try {
  await main();
} catch (e) {
  errors.push('exception: ' + (e && e.stack || e));
}
console.log('zhc wgsl page done');
await fetch('/done', { method: 'POST', body: JSON.stringify(summary) });
document.title = 'zhc runtime/zhc.wgsl test: done';
