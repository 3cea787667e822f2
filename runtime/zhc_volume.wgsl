// zhc/runtime/zhc_volume.wgsl — probe volumes in WGSL: the irradiance at any point of a grid of
// stored probes (docs/runtime.md "Probe volumes"; zhc_volume_* of runtime/zhc_runtime.h,
// zhcVolume* of runtime/zhc.glsl, which this file mirrors). Concatenate it after runtime/zhc.wgsl.
//
// A grid of probes: probe (x, y, z) is number x + nx (y + ny z) at origin + (x, y, z) * spacing,
// its stored words at (number * words per probe) in the application's buffer. The irradiance at a
// point blends the DECODED SH3 of the 8 probes of the cell containing it (the point clamped to the
// grid's box) with trilinear weights, then evaluates once: the trilinear blend of the 8 probes'
// irradiance (linearity). The stored words themselves must not be blended (ZH3's axis is per
// probe, the packed coefficients are ratios times the DC); hardware filtering of stored bytes is
// therefore wrong, and this does 8 fetches + decodes instead (probes of weight 0 are skipped).
//
// Binding: WGSL has neither macros nor storage-buffer pointer parameters in its core language, so
// the application defines the fetch, a function `zhcVolumeWord(index: u32) -> u32` returning word
// `index` of the probe words (the .zhp payload / glTF accessor bytes as-is; WGSL resolves the name
// wherever it is declared in the module), e.g.
//
//   @group(0) @binding(0) var<storage, read> zhcProbeWords: array<u32>;
//   fn zhcVolumeWord(i: u32) -> u32 { return zhcProbeWords[i]; }
//   @group(0) @binding(1) var<uniform> uVolume: ZhcVolume;  // grid of the .zhp header / glTF "grid"
//   @group(0) @binding(2) var<uniform> uFormat: ZhcFormat;
//   ...
//   let e = zhcVolumeIrradiance(uVolume, uFormat, worldPosition, worldNormal);
//
// Both position and normal are in the probe set's frame (zhc axes for a .zhp).

// The grid (uniform-buffer layout: origin at 0, spacing at 16, counts at 32; 48 bytes).
struct ZhcVolume {
    origin: vec3<f32>,   // position of probe (0, 0, 0)
    spacing: vec3<f32>,  // > 0 (the application checks, as zhc_volume_init)
    counts: vec3<u32>,   // >= 1 each
}

// SH3 radiance of probe `probe` of the volume's buffer.
fn zhcVolumeProbe(probe: u32, f: ZhcFormat) -> ZhcSh3 {
    let stride = zhcFamilyWords(f.family);
    var w: array<u32, 27>;
    for (var k = 0u; k < stride; k++) { w[k] = zhcVolumeWord(probe * stride + k); }
    return zhcDecode(w, f);
}

// Blended SH3 radiance at p: t = clamp((p - origin) / spacing, 0, counts - 1) (NaN: 0), cell
// i0 = min(floor(t), counts - 2), weights prod (f or 1 - f), f = t - i0. ~8 x (fetch + decode +
// 27 fma) + 20 flops.
fn zhcVolumeSh3(v: ZhcVolume, f: ZhcFormat, p: vec3<f32>) -> ZhcSh3 {
    let n = max(v.counts, vec3<u32>(1u));
    var t = (p - v.origin) / v.spacing;
    t = select(vec3<f32>(0.0), t, t >= vec3<f32>(0.0));  // below the box, or NaN: 0
    t = min(t, vec3<f32>(n - 1u));
    let i0 = min(vec3<u32>(t), max(n, vec3<u32>(2u)) - 2u);
    let fr = t - vec3<f32>(i0);
    var acc = zhcZeroSh3();
    for (var c = 0u; c < 8u; c++) {
        let b = vec3<u32>(c & 1u, (c >> 1u) & 1u, c >> 2u);
        let wv = select(1.0 - fr, fr, b != vec3<u32>(0u));
        let w = wv.x * wv.y * wv.z;
        if (w == 0.0) { continue; }
        let q = i0 + b;
        let s = zhcVolumeProbe(q.x + n.x * (q.y + n.y * q.z), f);
        for (var i = 0; i < 9; i++) { acc.c[i] = acc.c[i] + w * s.c[i]; }
    }
    return acc;
}

// Irradiance (zhc's normalised kernel) at position p for the surface normal `normal` (normalised
// here; zero or not finite: +Z).
fn zhcVolumeIrradiance(v: ZhcVolume, f: ZhcFormat, p: vec3<f32>, normal: vec3<f32>) -> vec3<f32> {
    return zhcIrradianceSh3(zhcVolumeSh3(v, f, p), zhcNormalizeOrZ(normal));
}

// Scattered probes (a `points` volume; docs/runtime.md "Scattered probes (`points` layout)"). The
// tetrahedron around a point is found on the CPU, once per object (volumeTetraWeights of
// runtime/web/zhc_runtime.mjs, or zhc_volume_tetra_weights of zhc_runtime.h: its 4 probe indices
// and weights, validity already applied), as Godot does per instance at its AABB centre
// (RendererSceneCull::_update_instance_lightmap_captures, servers/rendering/renderer_scene_cull.cpp,
// which also blends there); the shader blends those 4 stored probes, read through the same
// zhcVolumeWord as the grid functions, e.g.
//
//   struct Tetra { probes: vec4<u32>, weights: vec4<f32> }   // probes, weights (as f32) of the search
//   @group(1) @binding(0) var<uniform> uTetra: Tetra;
//   let e = zhcVolumeTetraIrradiance(uTetra.probes, uTetra.weights, uFormat, worldNormal);
//
// The blend is zhc_volume_sh3's points branch in f32: probes k = 0..3 in order, each decoded to SH3
// and added with its weight, probes of weight 0 not read (a weight below f32's range counts as 0).
// The probe indices must lie below the probe count (zhcVolumeWord is asked for their words as given).
fn zhcVolumeTetraSh3(probes: vec4<u32>, weights: vec4<f32>, f: ZhcFormat) -> ZhcSh3 {
    var acc = zhcZeroSh3();
    for (var k = 0u; k < 4u; k++) {
        let w = weights[k];
        if (w == 0.0) { continue; }
        let s = zhcVolumeProbe(probes[k], f);
        for (var i = 0; i < 9; i++) { acc.c[i] = acc.c[i] + w * s.c[i]; }
    }
    return acc;
}

// Irradiance (zhc's normalised kernel) of zhcVolumeTetraSh3's blend for the surface normal `normal`
// (normalised here; zero or not finite: +Z), evaluated once as zhcVolumeIrradiance does.
fn zhcVolumeTetraIrradiance(probes: vec4<u32>, weights: vec4<f32>, f: ZhcFormat, normal: vec3<f32>) -> vec3<f32> {
    return zhcIrradianceSh3(zhcVolumeTetraSh3(probes, weights, f), zhcNormalizeOrZ(normal));
}
