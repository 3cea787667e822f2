// zhc/runtime/zhc_volume_mask.wgsl — probe volumes with validity and visibility in WGSL
// (docs/runtime.md "Validity and visibility"; zhc_volume_sh3 of runtime/zhc_runtime.h with
// zhc_volume::validity / ::visibility set, zhcVolumeSh3 of runtime/zhc.glsl with ZHC_VOLUME_MASK).
// Concatenate it after runtime/zhc.wgsl and runtime/zhc_volume.wgsl.
//
// A separate file because WGSL has no macros: the application defines, besides zhcVolumeWord, a
// function `zhcVolumeMask(probe: u32) -> u32` returning probe `probe`'s combined mask byte
// `valid ? visibility : 0` (absent validity: valid; absent visibility: 0xFF), e.g. 4 masks per
// word of a storage buffer:
//
//   @group(0) @binding(3) var<storage, read> zhcProbeMasks: array<u32>;
//   fn zhcVolumeMask(i: u32) -> u32 { return (zhcProbeMasks[i >> 2u] >> (8u * (i & 3u))) & 0xFFu; }
//
// Corner (dx, dy, dz) of the cell weighs its trilinear weight times bit 7 - (dx + 2 dy + 4 dz) of
// its mask; the weights are divided by their sum; when all eight vanish the plain trilinear
// weights are used. Cost over zhcVolumeSh3: 8 mask loads, ~8 selects, 8 adds, 8 divisions.

// Masked blended SH3 radiance at p (zhcVolumeSh3's cell and weights, then the masks).
fn zhcVolumeSh3Masked(v: ZhcVolume, f: ZhcFormat, p: vec3<f32>) -> ZhcSh3 {
    let n = max(v.counts, vec3<u32>(1u));
    var t = (p - v.origin) / v.spacing;
    t = select(vec3<f32>(0.0), t, t >= vec3<f32>(0.0));  // below the box, or NaN: 0
    t = min(t, vec3<f32>(n - 1u));
    let i0 = min(vec3<u32>(t), max(n, vec3<u32>(2u)) - 2u);
    let fr = t - vec3<f32>(i0);
    var w: array<f32, 8>;
    var wm: array<f32, 8>;
    var sum = 0.0;
    for (var c = 0u; c < 8u; c++) {
        let b = vec3<u32>(c & 1u, (c >> 1u) & 1u, c >> 2u);
        let wv = select(1.0 - fr, fr, b != vec3<u32>(0u));
        w[c] = wv.x * wv.y * wv.z;
        let q = i0 + b;
        var bit = 0u;
        if (w[c] != 0.0) { bit = (zhcVolumeMask(q.x + n.x * (q.y + n.y * q.z)) >> (7u - c)) & 1u; }
        wm[c] = select(0.0, w[c], bit != 0u);
        sum = sum + wm[c];
    }
    var acc = zhcZeroSh3();
    for (var c = 0u; c < 8u; c++) {
        var wc = w[c];
        if (sum > 0.0) { wc = wm[c] / sum; }  // else: every corner masked, plain trilinear
        if (wc == 0.0) { continue; }
        let b = vec3<u32>(c & 1u, (c >> 1u) & 1u, c >> 2u);
        let q = i0 + b;
        let s = zhcVolumeProbe(q.x + n.x * (q.y + n.y * q.z), f);
        for (var i = 0; i < 9; i++) { acc.c[i] = acc.c[i] + wc * s.c[i]; }
    }
    return acc;
}

// Irradiance at p for the normal `normal` from the masked blend (zhcVolumeIrradiance's evaluation).
fn zhcVolumeIrradianceMasked(v: ZhcVolume, f: ZhcFormat, p: vec3<f32>, normal: vec3<f32>) -> vec3<f32> {
    return zhcIrradianceSh3(zhcVolumeSh3Masked(v, f, p), zhcNormalizeOrZ(normal));
}
