// Page of tests/js/wgsl_test.mjs: runs runtime/zhc.wgsl in a WebGPU compute shader on the jobs the
// test server hands out and posts the raw float32 results back; the server compares them.
//
// Protocol: GET /job/next -> 204 when done, else a binary job: a 16-u32 header [kernel, count,
// outFloats, itemFloats, wordCount, 0...], the kernel's `Job` uniform (64 bytes), the ZhcFormat
// uniform (80 bytes), `wordCount` u32 probe words and `count * itemFloats` f32 item inputs (kernel 0:
// decode_kernel, kernel 1: volume_kernel, kernel 2: masked_volume_kernel, kernel 3:
// plane_volume_kernel of wgsl_kernel.wgsl, kernel 4: plane_volume_kernel with the override
// ZHC_VOLUME_PLANE_AXES_GLTF = true, kernel 5: tetra_volume_kernel). POST /job/result: the `count * outFloats` output floats.
// POST /result: a JSON summary.

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
  const code = [await text('/runtime/zhc.wgsl'), await text('/runtime/zhc_volume.wgsl'), await text('/runtime/zhc_volume_mask.wgsl'),
    await text('/runtime/zhc_volume_plane.wgsl'), await text('/test/wgsl_kernel.wgsl')].join('\n');
  device.pushErrorScope('validation');
  const module = device.createShaderModule({ code });
  const ci = await module.getCompilationInfo();
  for (const m of ci.messages) summary.compilation.push(`${m.type} ${m.lineNum}:${m.linePos} ${m.message}`);
  const pipelines = {};
  for (const entry of ['decode_kernel', 'volume_kernel', 'masked_volume_kernel', 'plane_volume_kernel', 'tetra_volume_kernel'])
    if (code.includes(`fn ${entry}(`)) pipelines[entry] = device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: entry } });
  if (code.includes('fn plane_volume_kernel(')) {
    pipelines.plane_volume_kernel_gltf = device.createComputePipeline({ layout: 'auto',
      compute: { module, entryPoint: 'plane_volume_kernel', constants: { ZHC_VOLUME_PLANE_AXES_GLTF: 1 } } });
  }
  const err = await device.popErrorScope();
  if (err) throw new Error('shader module / pipeline: ' + err.message);

  for (;;) {
    const r = await fetch('/job/next');
    if (r.status === 204) break;
    if (!r.ok) throw new Error(`/job/next: HTTP ${r.status}`);
    const buf = await r.arrayBuffer();
    const head = new Uint32Array(buf, 0, 16);
    const [kernel, count, outFloats, itemFloats, wordCount] = head;
    const jobBytes = buf.slice(64, 128);
    const fmtBytes = buf.slice(128, 208);
    const words = buf.slice(208, 208 + 4 * wordCount);
    const itemData = buf.slice(208 + 4 * wordCount, 208 + 4 * wordCount + 4 * count * itemFloats);
    const mk = (data, usage) => {
      const b = device.createBuffer({ size: Math.max(16, data.byteLength), usage: usage | GPUBufferUsage.COPY_DST });
      device.queue.writeBuffer(b, 0, data);
      return b;
    };
    const fmt = mk(fmtBytes, GPUBufferUsage.UNIFORM);
    const job = mk(jobBytes, GPUBufferUsage.UNIFORM);
    const wbuf = mk(words, GPUBufferUsage.STORAGE);
    const nbuf = mk(itemData, GPUBufferUsage.STORAGE);
    const outSize = 4 * count * outFloats;
    const out = device.createBuffer({ size: outSize, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC });
    const read = device.createBuffer({ size: outSize, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
    const pipeline = pipelines[['decode_kernel', 'volume_kernel', 'masked_volume_kernel', 'plane_volume_kernel', 'plane_volume_kernel_gltf',
      'tetra_volume_kernel'][kernel]];
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
await fetch('/result', { method: 'POST', body: JSON.stringify(summary) });
document.title = 'zhc runtime/zhc.wgsl test: done';
