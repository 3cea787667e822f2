// Compute kernels of tests/js/wgsl_test.mjs, appended to runtime/zhc.wgsl by the page.
// decode_kernel: item i = the probe words words[i * stride .. + stride) (stride <= 27) and the unit
// normal normals[3 i .. 3 i + 2]; writes zhcDecode (27 floats, SH3 radiance) and zhcIrradiance
// (3 floats) at out[30 i ..].

@group(0) @binding(0) var<uniform> fmt: ZhcFormat;
@group(0) @binding(1) var<uniform> job: vec4<u32>;  // stride, count
@group(0) @binding(2) var<storage, read> words: array<u32>;
@group(0) @binding(3) var<storage, read> normals: array<f32>;
@group(0) @binding(4) var<storage, read_write> outv: array<f32>;

@compute @workgroup_size(64)
fn decode_kernel(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let stride = min(job.x, 27u);
    if (i >= job.y) { return; }
    var w: array<u32, 27>;
    for (var j = 0u; j < stride; j++) { w[j] = words[i * job.x + j]; }
    let n = vec3<f32>(normals[3u * i], normals[3u * i + 1u], normals[3u * i + 2u]);
    let sh = zhcDecode(w, fmt);
    for (var c = 0u; c < 9u; c++) {
        outv[30u * i + 3u * c] = sh.c[c].x;
        outv[30u * i + 3u * c + 1u] = sh.c[c].y;
        outv[30u * i + 3u * c + 2u] = sh.c[c].z;
    }
    let e = zhcIrradiance(w, fmt, n);
    outv[30u * i + 27u] = e.x;
    outv[30u * i + 28u] = e.y;
    outv[30u * i + 29u] = e.z;
}
