// Compute kernels of tests/js/wgsl_test.mjs, appended to runtime/zhc.wgsl + runtime/zhc_volume.wgsl
// + runtime/zhc_volume_mask.wgsl + runtime/zhc_volume_plane.wgsl by the page.
// decode_kernel: item i = the probe words words[i * stride .. + stride) (stride <= 27) and the unit
// normal items[3 i .. 3 i + 2]; writes zhcDecode (27 floats, SH3 radiance) and zhcIrradiance
// (3 floats) at out[30 i ..].
// volume_kernel: item i = position items[6 i ..], normal items[6 i + 3 ..]; the grid's probe words
// in words[]; writes zhcVolumeIrradiance (3 floats) at out[3 i ..].
// masked_volume_kernel: the same with zhcVolumeIrradianceMasked; the combined masks (4 per word) in
// words[] from word job.pad0 on.
// plane_volume_kernel: the same with zhcVolumeIrradiancePlanes; the masks as above, the plane
// entries (2 words per probe) from word job.pad1 on; writes 4 floats per item at out[4 i ..]: the
// irradiance and the corners the cell's plane keeps (zhcVolumePlaneKeep, as a float).
// tetra_volume_kernel: item i = the 4 weights items[11 i ..], the 4 probe indices (as floats)
// items[11 i + 4 ..] and the normal items[11 i + 8 ..]; writes zhcVolumeTetraSh3 (27 floats) and
// zhcVolumeTetraIrradiance (3 floats) at out[30 i ..].

struct Job {
    stride: u32,
    count: u32,
    pad0: u32,
    pad1: u32,
    origin: vec4<f32>,
    spacing: vec4<f32>,
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> fmt: ZhcFormat;
@group(0) @binding(1) var<uniform> job: Job;
@group(0) @binding(2) var<storage, read> words: array<u32>;
@group(0) @binding(3) var<storage, read> items: array<f32>;
@group(0) @binding(4) var<storage, read_write> outv: array<f32>;

// The specialised-format example of zhc.wgsl's header, compiled as written (not called).
override ZHC_BITS: u32 = 8u;
fn zhcMyFormat() -> ZhcFormat {
    return ZhcFormat(ZHC_LAYOUT_ZH3_Q16, ZHC_HALL_MODE_NONE, ZHC_BITS, 0u, ZHC_L2_TIGHT, ZHC_DC_R11G11B10F,
                     ZHC_ZONAL_AFFINE, ZHC_AXIS_LUMINANCE, ZHC_KIND_RADIANCE,
                     vec3f(0.2126, 0.7152, 0.0722), vec2f(0.6, 0.08));
}

// The probe words of zhc_volume.wgsl's functions, and the masks of zhc_volume_mask.wgsl's.
fn zhcVolumeWord(i: u32) -> u32 { return words[i]; }
fn zhcVolumeMask(i: u32) -> u32 { return (words[job.pad0 + (i >> 2u)] >> (8u * (i & 3u))) & 0xFFu; }
fn zhcVolumePlane(i: u32) -> vec2<u32> { return vec2<u32>(words[job.pad1 + 2u * i], words[job.pad1 + 2u * i + 1u]); }

@compute @workgroup_size(64)
fn decode_kernel(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let stride = min(job.stride, 27u);
    if (i >= job.count) { return; }
    var w: array<u32, 27>;
    for (var j = 0u; j < stride; j++) { w[j] = words[i * job.stride + j]; }
    let n = vec3<f32>(items[3u * i], items[3u * i + 1u], items[3u * i + 2u]);
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

@compute @workgroup_size(64)
fn volume_kernel(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= job.count) { return; }
    let p = vec3<f32>(items[6u * i], items[6u * i + 1u], items[6u * i + 2u]);
    let n = vec3<f32>(items[6u * i + 3u], items[6u * i + 4u], items[6u * i + 5u]);
    let e = zhcVolumeIrradiance(ZhcVolume(job.origin.xyz, job.spacing.xyz, job.counts.xyz), fmt, p, n);
    outv[3u * i] = e.x;
    outv[3u * i + 1u] = e.y;
    outv[3u * i + 2u] = e.z;
}

@compute @workgroup_size(64)
fn masked_volume_kernel(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= job.count) { return; }
    let p = vec3<f32>(items[6u * i], items[6u * i + 1u], items[6u * i + 2u]);
    let n = vec3<f32>(items[6u * i + 3u], items[6u * i + 4u], items[6u * i + 5u]);
    let e = zhcVolumeIrradianceMasked(ZhcVolume(job.origin.xyz, job.spacing.xyz, job.counts.xyz), fmt, p, n);
    outv[3u * i] = e.x;
    outv[3u * i + 1u] = e.y;
    outv[3u * i + 2u] = e.z;
}

@compute @workgroup_size(64)
fn plane_volume_kernel(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= job.count) { return; }
    let p = vec3<f32>(items[6u * i], items[6u * i + 1u], items[6u * i + 2u]);
    let n = vec3<f32>(items[6u * i + 3u], items[6u * i + 4u], items[6u * i + 5u]);
    let v = ZhcVolume(job.origin.xyz, job.spacing.xyz, job.counts.xyz);
    let e = zhcVolumeIrradiancePlanes(v, fmt, p, n);
    // zhcVolumeSh3Planes' cell, and the corners its plane keeps.
    let cn = max(v.counts, vec3<u32>(1u));
    var t = (p - v.origin) / v.spacing;
    t = min(select(vec3<f32>(0.0), t, t >= vec3<f32>(0.0)), vec3<f32>(cn - 1u));
    let i0 = min(vec3<u32>(t), max(cn, vec3<u32>(2u)) - 2u);
    let keep = zhcVolumePlaneKeep(zhcVolumePlane(i0.x + cn.x * (i0.y + cn.y * i0.z)), v, i0, p);
    outv[4u * i] = e.x;
    outv[4u * i + 1u] = e.y;
    outv[4u * i + 2u] = e.z;
    outv[4u * i + 3u] = f32(keep);
}

@compute @workgroup_size(64)
fn tetra_volume_kernel(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= job.count) { return; }
    let b = 11u * i;
    let w = vec4<f32>(items[b], items[b + 1u], items[b + 2u], items[b + 3u]);
    let q = vec4<u32>(vec4<f32>(items[b + 4u], items[b + 5u], items[b + 6u], items[b + 7u]));
    let n = vec3<f32>(items[b + 8u], items[b + 9u], items[b + 10u]);
    let sh = zhcVolumeTetraSh3(q, w, fmt);
    for (var c = 0u; c < 9u; c++) {
        outv[30u * i + 3u * c] = sh.c[c].x;
        outv[30u * i + 3u * c + 1u] = sh.c[c].y;
        outv[30u * i + 3u * c + 2u] = sh.c[c].z;
    }
    let e = zhcVolumeTetraIrradiance(q, w, fmt, n);
    outv[30u * i + 27u] = e.x;
    outv[30u * i + 28u] = e.y;
    outv[30u * i + 29u] = e.z;
}
