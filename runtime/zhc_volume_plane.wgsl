// zhc/runtime/zhc_volume_plane.wgsl — probe volumes with cell planes (and validity and visibility)
// in WGSL (docs/runtime.md "Cell planes"; zhc_volume_sh3 of runtime/zhc_runtime.h with
// zhc_volume::planes set, zhcVolumeSh3 of runtime/zhc.glsl with ZHC_VOLUME_PLANE and
// ZHC_VOLUME_MASK). Concatenate it after runtime/zhc.wgsl and runtime/zhc_volume.wgsl.
//
// A separate file because WGSL has no macros and refuses calls to undeclared functions: the
// application defines, besides zhcVolumeWord, the two functions
//
//   fn zhcVolumePlane(cell: u32) -> vec2<u32>  // the plane entry of the cell whose corner 0 is probe
//                                              // `cell`: .x = bytes 0..3 little-endian
//                                              // (ou | ov << 8 | offset << 16), .y = byte 4 (sides)
//   fn zhcVolumeMask(probe: u32) -> u32        // the combined byte valid ? visibility : 0, as for
//                                              // runtime/zhc_volume_mask.wgsl
//
// e.g. 2 words per probe of a storage buffer, and no masks (a bake writes validity and planes;
// without validity either, return 0xFFu):
//
//   @group(0) @binding(4) var<storage, read> zhcPlaneWords: array<u32>;
//   fn zhcVolumePlane(i: u32) -> vec2<u32> { return vec2<u32>(zhcPlaneWords[2u * i], zhcPlaneWords[2u * i + 1u]); }
//   @group(0) @binding(5) var<storage, read> zhcValidity: array<u32>;  // 4 bytes 0/1 per word
//   fn zhcVolumeMask(i: u32) -> u32 { return select(0u, 0xFFu, ((zhcValidity[i >> 2u] >> (8u * (i & 3u))) & 0xFFu) != 0u); }
//
// When the entry's offset is not -32768 the point's side of the plane, dot(n, p - c) - offset
// |spacing| / 65534 >= 0 (n the octahedral code's normal, c the cell's centre; float), keeps the
// corners (dx, dy, dz) whose sides bit dx + 2 dy + 4 dz equals it; each kept corner also needs its
// mask bit 7 - (dx + 2 dy + 4 dz); the kept weights are divided by their sum; when none is kept
// the plain trilinear weights are used. An entry with offset -32768 and bit 7 of byte 4 set is a
// corner region (docs/runtime.md "Corner regions"): q_a = (bytes 0-1 >> 5a) & 31, d_a = bit a of
// byte 4; the point is inside when along every axis with q_a != 0, s_a = (p_a - (origin_a + i0_a
// spacing_a)) * 31 is >= q_a spacing_a (d_a = 1) or < q_a spacing_a (d_a = 0), and the corners
// inside are those whose bit a equals d_a along those axes; a point inside keeps the corners
// inside, a point outside the others. For a volume whose grid is in glTF axes (ZHC_light_probes)
// while the normal codes are in zhc axes, set the pipeline-overridable constant
// ZHC_VOLUME_PLANE_AXES_GLTF to true (GPUProgrammableStage.constants): the normal used is
// (n.y, n.z, n.x) (a region's fields are stored in the grid's axes: used as they stand). Cost over
// zhcVolumeSh3: 1 entry load, the normal's decode, a dot product (a region: 3 compares), 8 mask
// loads, ~8 selects, 8 adds, 8 divisions.

// true: the grid is in glTF axes, the plane normals' codes in zhc axes.
override ZHC_VOLUME_PLANE_AXES_GLTF: bool = false;

// The unit normal of a cell plane's octahedral code (ou, ov) (zhc_plane_normal of zhc_runtime.h, in
// float): a = min(code, 254) / 127 - 1, z = 1 - |a| - |b|, folded when z < 0.
fn zhcPlaneNormal(ou: u32, ov: u32) -> vec3<f32> {
    var ab = vec2<f32>(f32(min(ou, 254u)), f32(min(ov, 254u))) / 127.0 - 1.0;
    let z = 1.0 - abs(ab.x) - abs(ab.y);
    if (z < 0.0) { ab = (1.0 - abs(ab.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), ab >= vec2<f32>(0.0)); }
    return normalize(vec3<f32>(ab, z));
}

// The corners a corner region entry e keeps at p (zhc__volume_plane_side of zhc_runtime.h, in
// float, the same operations): inside the region, the corners inside it; outside, the others.
fn zhcVolumeRegionKeep(e: vec2<u32>, v: ZhcVolume, i0: vec3<u32>, p: vec3<f32>) -> u32 {
    let q = vec3<u32>(e.x, e.x >> 5u, e.x >> 10u) & vec3<u32>(31u);
    let d = vec3<u32>(e.y, e.y >> 1u, e.y >> 2u) & vec3<u32>(1u);
    let s = (p - (v.origin + vec3<f32>(i0) * v.spacing)) * 31.0;
    let t = vec3<f32>(q) * v.spacing;
    let axisCorners = vec3<u32>(0xAAu, 0xCCu, 0xF0u);  // the corners k whose bit a is 1
    var inside = true;
    var corners = 0xFFu;
    for (var a = 0u; a < 3u; a++) {
        if (q[a] == 0u) { continue; }  // the axis does not bound the region
        inside = inside && select(s[a] < t[a], s[a] >= t[a], d[a] != 0u);
        corners = corners & select(~axisCorners[a], axisCorners[a], d[a] != 0u);
    }
    return select(~corners, corners, inside) & 0xFFu;
}

// The corners kept by the entry e of the cell with first probe i0 at p: a plane, bit k set when
// corner k's sides bit equals p's side; a corner region, zhcVolumeRegionKeep; 0xFF when the entry
// has neither.
fn zhcVolumePlaneKeep(e: vec2<u32>, v: ZhcVolume, i0: vec3<u32>, p: vec3<f32>) -> u32 {
    let offset = bitcast<i32>(e.x) >> 16u;  // bytes 2-3, sign-extended
    if (offset == -32768) {
        if ((e.y & 0x80u) != 0u) { return zhcVolumeRegionKeep(e, v, i0, p); }
        return 0xFFu;
    }
    var nrm = zhcPlaneNormal(e.x & 0xFFu, (e.x >> 8u) & 0xFFu);
    if (ZHC_VOLUME_PLANE_AXES_GLTF) { nrm = nrm.yzx; }  // glTF (x, y, z) = zhc (y, z, x)
    let c = v.origin + (vec3<f32>(i0) + 0.5) * v.spacing;
    let s = dot(nrm, p - c) - f32(offset) * (length(v.spacing) / 65534.0);
    return select(~e.y, e.y, s >= 0.0) & 0xFFu;
}

// Blended SH3 radiance at p with the cell's plane and the masks (zhcVolumeSh3's cell and weights).
fn zhcVolumeSh3Planes(v: ZhcVolume, f: ZhcFormat, p: vec3<f32>) -> ZhcSh3 {
    let n = max(v.counts, vec3<u32>(1u));
    var t = (p - v.origin) / v.spacing;
    t = select(vec3<f32>(0.0), t, t >= vec3<f32>(0.0));  // below the box, or NaN: 0
    t = min(t, vec3<f32>(n - 1u));
    let i0 = min(vec3<u32>(t), max(n, vec3<u32>(2u)) - 2u);
    let fr = t - vec3<f32>(i0);
    let keep = zhcVolumePlaneKeep(zhcVolumePlane(i0.x + n.x * (i0.y + n.y * i0.z)), v, i0, p);
    var w: array<f32, 8>;
    var wm: array<f32, 8>;
    var sum = 0.0;
    for (var c = 0u; c < 8u; c++) {
        let b = vec3<u32>(c & 1u, (c >> 1u) & 1u, c >> 2u);
        let wv = select(1.0 - fr, fr, b != vec3<u32>(0u));
        w[c] = wv.x * wv.y * wv.z;
        let q = i0 + b;
        var bit = 0u;
        if (w[c] != 0.0 && ((keep >> c) & 1u) != 0u) { bit = (zhcVolumeMask(q.x + n.x * (q.y + n.y * q.z)) >> (7u - c)) & 1u; }
        wm[c] = select(0.0, w[c], bit != 0u);
        sum = sum + wm[c];
    }
    var acc = zhcZeroSh3();
    for (var c = 0u; c < 8u; c++) {
        var wc = w[c];
        if (sum > 0.0) { wc = wm[c] / sum; }  // else: every corner dropped, plain trilinear
        if (wc == 0.0) { continue; }
        let b = vec3<u32>(c & 1u, (c >> 1u) & 1u, c >> 2u);
        let q = i0 + b;
        let s = zhcVolumeProbe(q.x + n.x * (q.y + n.y * q.z), f);
        for (var i = 0; i < 9; i++) { acc.c[i] = acc.c[i] + wc * s.c[i]; }
    }
    return acc;
}

// Irradiance at p for the normal `normal` from the blend with planes (zhcVolumeIrradiance's
// evaluation).
fn zhcVolumeIrradiancePlanes(v: ZhcVolume, f: ZhcFormat, p: vec3<f32>, normal: vec3<f32>) -> vec3<f32> {
    return zhcIrradianceSh3(zhcVolumeSh3Planes(v, f, p), zhcNormalizeOrZ(normal));
}
