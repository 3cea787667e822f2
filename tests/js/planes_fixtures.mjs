// Cell planes for the runtime/web tests (js.runtime_volume, js.three_compact): .zhp files with a
// planes section, hand-made and random plane entries, the glTF axis permutation of a grid's
// per-probe bytes, and a point's distance to its cell's plane. The entry layout is the one of
// docs/runtime.md "Cell planes" (runtime/zhc_runtime.h zhc__volume_plane_side): per probe i, the
// plane of the cell whose corner 0 is probe i: ou, ov (octahedral normal code, zhc axes), offset
// (int16 little-endian, units of |spacing| / 65534 from the cell's centre along the normal;
// -32768 = no plane), sides (bit k = dx + 2 dy + 4 dz: corner k on the positive side); or a corner
// region (docs/runtime.md "Corner regions": offset -32768 and bit 7 of byte 4 set; bytes 0, 1 = r,
// uint16 little-endian, q_a = (r >> 5a) & 31; byte 4 bits 0..2 = d_a; zhc_cell_entry_is_region).

// The "no plane" entry.
export const NO_PLANE = Object.freeze([0, 0, 0x00, 0x80, 0]);

// Whether the 5 bytes of `e` from `at` are a corner region (zhc_cell_entry_is_region).
export const isRegion = (e, at = 0) => e[at + 2] === 0x00 && e[at + 3] === 0x80 && (e[at + 4] & 0x80) !== 0;

// The corner region entry with thresholds q = [q_x, q_y, q_z] (0..31, 0: the axis does not bound it)
// and directions d = [d_x, d_y, d_z] (0 / 1).
export function regionEntry(q, d) {
  const r = q[0] | (q[1] << 5) | (q[2] << 10);
  return [r & 0xff, r >> 8, 0x00, 0x80, 0x80 | d[0] | (d[1] << 1) | (d[2] << 2)];
}

// An uncompressed .zhp (version 1, or version 2 whose sections are replaced) rewritten as version 2
// with the given per-probe sections (Uint8Array or null each; planes 5 bytes per probe), in the
// container's order: validity, visibility, planes. `crc32`: runtime/web's (bytes, start, end).
export function zhpWithPlanes(bytes, { validity = null, visibility = null, planes = null }, crc32) {
  const hv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const count = Number(hv.getBigUint64(56, true));
  if (bytes[8] === 2) {  // drop the sections it has (they follow the payload)
    const had = (bytes[21] & 1) + ((bytes[21] >> 1) & 1) + 5 * ((bytes[21] >> 2) & 1);
    bytes = bytes.slice(0, 184 + Number(hv.getBigUint64(160, true)) - had * count);
  }
  const parts = [validity, visibility, planes].filter((a) => a);
  const out = new Uint8Array(bytes.length + parts.reduce((n, a) => n + a.length, 0));
  out.set(bytes);
  let at = bytes.length;
  for (const a of parts) {
    out.set(a, at);
    at += a.length;
  }
  const dv = new DataView(out.buffer);
  dv.setUint16(8, 2, true);
  out[21] = (validity ? 1 : 0) | (visibility ? 2 : 0) | (planes ? 4 : 0);
  const body = BigInt(out.length - 184);
  dv.setBigUint64(160, body, true);
  dv.setBigUint64(168, body, true);
  dv.setUint32(176, crc32(out, 184, out.length), true);
  dv.setUint32(180, crc32(out, 0, 180), true);
  return out;
}

// The octahedral code (ou, ov) of a direction (zhc axes), each rounded to the nearest code: the
// inverse of zhc_plane_normal up to that rounding (the 6 axes exactly).
export function encodeNormal(n) {
  const l1 = Math.abs(n[0]) + Math.abs(n[1]) + Math.abs(n[2]);
  let a = n[0] / l1, b = n[1] / l1;
  if (n[2] < 0) {
    const a0 = a;
    a = (1 - Math.abs(b)) * (a0 < 0 ? -1 : 1);
    b = (1 - Math.abs(a0)) * (b < 0 ? -1 : 1);
  }
  const code = (t) => Math.min(254, Math.max(0, Math.round((t + 1) * 127)));
  return [code(a), code(b)];
}

// zhc_plane_normal in doubles (the decoded unit normal of a code, zhc axes).
export function decodeNormal(ou, ov) {
  let a = Math.min(ou, 254) / 127 - 1, b = Math.min(ov, 254) / 127 - 1;
  const z = 1 - Math.abs(a) - Math.abs(b);
  if (z < 0) {
    const a0 = a;
    a = (1 - Math.abs(b)) * (a0 < 0 ? -1 : 1);
    b = (1 - Math.abs(a0)) * (b < 0 ? -1 : 1);
  }
  const l = Math.hypot(a, b, z);
  return [a / l, b / l, z / l];
}

const diagonal = (grid) => Math.hypot(grid.spacing[0], grid.spacing[1], grid.spacing[2]);
const cellCentre = (grid, i0) => [0, 1, 2].map((c) => grid.origin[c] + (i0[c] + 0.5) * grid.spacing[c]);

// The entry of cell i0 (its corner-0 probe's coordinates) of a zhc-axes grid for the plane with
// code (ou, ov) through the point `through`; `sides` computed from the corners' positions unless given.
export function planeEntry(grid, i0, [ou, ov], through, sides = null) {
  const n = decodeNormal(ou, ov), c = cellCentre(grid, i0), unit = diagonal(grid) / 65534;
  const offset = Math.round((n[0] * (through[0] - c[0]) + n[1] * (through[1] - c[1]) + n[2] * (through[2] - c[2])) / unit);
  if (offset < -32767 || offset > 32767) throw new Error('planeEntry: the plane is too far from the cell');
  if (sides === null) {
    sides = 0;
    for (let k = 0; k < 8; k++) {
      const d = [k & 1, (k >> 1) & 1, k >> 2];
      let s = -offset * unit;
      for (let a = 0; a < 3; a++) s += n[a] * (grid.origin[a] + (i0[a] + d[a]) * grid.spacing[a] - c[a]);
      if (s >= 0) sides |= 1 << k;
    }
  }
  return [ou, ov, offset & 0xff, (offset >> 8) & 0xff, sides];
}

// The planes section of a zhc-axes grid: entry(i0) for every cell (x < nx - 1 or nx = 1, ...), an
// array of 5 bytes or null for "no plane"; the last probe along each axis of count >= 2 gets "no
// plane" (along an axis of count 1 the one probe starts the flat cell).
export function planesSection(grid, entry) {
  const [nx, ny, nz] = grid.counts;
  const out = new Uint8Array(5 * nx * ny * nz);
  for (let z = 0; z < nz; z++) for (let y = 0; y < ny; y++) for (let x = 0; x < nx; x++) {
    const i = x + nx * (y + ny * z);
    const last = (nx > 1 && x + 1 === nx) || (ny > 1 && y + 1 === ny) || (nz > 1 && z + 1 === nz);
    out.set((!last && entry([x, y, z])) || NO_PLANE, 5 * i);
  }
  return out;
}

// Random planes: per cell, "no plane" with probability pNone, else (probability pRegion) a corner
// region whose thresholds are each 0 with probability 1/4, else uniform in 1..31, with random
// directions; else a random code (255 included: it reads as 254), an offset within the cell's reach
// and sides either from the corners' positions or (probability pRandomSides) random bits, which
// also makes cells whose kept set is empty. With pRegion 0 (the default) no extra numbers are drawn:
// a seed gives the planes it gives without the option.
export function randomPlanes(grid, rand, { pNone = 0.2, pRandomSides = 0.3, pRegion = 0 } = {}) {
  return planesSection(grid, (i0) => {
    if (rand() < pNone) return null;
    if (pRegion > 0 && rand() < pRegion) {
      const q = [0, 1, 2].map(() => (rand() < 0.25 ? 0 : 1 + Math.floor(rand() * 31)));
      return regionEntry(q, [0, 1, 2].map(() => (rand() < 0.5 ? 0 : 1)));
    }
    const code = [Math.floor(rand() * 256), Math.floor(rand() * 256)];
    const c = cellCentre(grid, i0), n = decodeNormal(...code);
    const t = (rand() - 0.5) * 0.9 * diagonal(grid);
    const through = [0, 1, 2].map((a) => c[a] + t * n[a]);
    return planeEntry(grid, i0, code, through, rand() < pRandomSides ? Math.floor(rand() * 256) : null);
  });
}

// Grid coordinate of p along one axis, as zhc__volume_axis: [i0, f].
function axis(p, origin, spacing, n) {
  let t = (p - origin) / spacing;
  if (!(t >= 0)) t = 0;
  if (t > n - 1) t = n - 1;
  let i = Math.floor(t);
  if (n >= 2 && i > n - 2) i = n - 2;
  return [i, n >= 2 ? t - i : 0];
}

// A corner region's fields (docs/runtime.md "Corner regions"): { q: [q_x, q_y, q_z], d: [...] }.
export function regionFields(e, at = 0) {
  const r = e[at] | (e[at + 1] << 8);
  return { q: [0, 1, 2].map((a) => (r >> (5 * a)) & 31), d: [0, 1, 2].map((a) => (e[at + 4] >> a) & 1) };
}

// The distance of point p (zhc axes) from the plane of its cell in units of |spacing|, Infinity
// when the cell has no plane (a zhc-axes grid and its planes section). A corner region: the distance
// to the nearest of its bounding planes x_a = origin_a + (i0_a + q_a / 31) spacing_a (q_a > 0).
export function planeMargin(grid, planes, p) {
  const i0 = [0, 1, 2].map((c) => axis(p[c], grid.origin[c], grid.spacing[c], grid.counts[c])[0]);
  const cell = i0[0] + grid.counts[0] * (i0[1] + grid.counts[1] * i0[2]);
  const e = planes.subarray(5 * cell, 5 * cell + 5);
  if (isRegion(e)) {
    const { q } = regionFields(e);
    let m = Infinity;
    for (let a = 0; a < 3; a++)
      if (q[a] > 0) m = Math.min(m, Math.abs(p[a] - (grid.origin[a] + (i0[a] + q[a] / 31) * grid.spacing[a])));
    return m / diagonal(grid);
  }
  const offset = (e[2] | (e[3] << 8)) << 16 >> 16;
  if (offset === -32768) return Infinity;
  const n = decodeNormal(e[0], e[1]), c = cellCentre(grid, i0), unit = diagonal(grid) / 65534;
  return Math.abs(n[0] * (p[0] - c[0]) + n[1] * (p[1] - c[1]) + n[2] * (p[2] - c[2]) - offset * unit) / diagonal(grid);
}

// glTF probe (gx, gy, gz) of a zhc grid with counts (NX, NY, NZ) is zhc probe (gz, gx, gy): glTF
// (x, y, z) = zhc (y, z, x). The zhc index of each glTF probe, in glTF order.
export function gltfProbeOrder(counts) {
  const [NX, NY, NZ] = counts;
  const out = [];
  for (let gz = 0; gz < NX; gz++) for (let gy = 0; gy < NZ; gy++) for (let gx = 0; gx < NY; gx++) out.push(gz + NX * (gx + NY * gy));
  return out;
}
// A corner / side bit byte in zhc bits -> glTF bits: glTF bit (gx + 2 gy + 4 gz) = zhc bit
// (gz + 2 gx + 4 gy).
export function gltfBits(m) {
  let g = 0;
  for (let j = 0; j < 8; j++) if ((m >> ((j >> 2) + 2 * (j & 1) + 4 * ((j >> 1) & 1))) & 1) g |= 1 << j;
  return g;
}
// A corner region's per-axis fields in glTF axes: glTF axis a's threshold and direction are zhc
// axis (a + 1) % 3's (glTF (x, y, z) = zhc (y, z, x)); reserved bits kept.
export function gltfRegion(e, at = 0) {
  const r = e[at] | (e[at + 1] << 8);
  let g = r & 0x8000, d = e[at + 4] & ~7;
  for (let a = 0; a < 3; a++) {
    const from = (a + 1) % 3;
    g |= ((r >> (5 * from)) & 31) << (5 * a);
    d |= ((e[at + 4] >> from) & 1) << a;
  }
  return [g & 0xff, g >> 8, e[at + 2], e[at + 3], d];
}

// A zhc grid's planes section in glTF probe order with the sides bits permuted, the normal codes
// and offsets unchanged, corner regions' fields permuted to glTF axes (docs/gltf-extension.md,
// docs/runtime.md "Corner regions"; what ZHC_light_probes' planes / planeSides hold).
export function gltfPlanes(counts, planes) {
  const order = gltfProbeOrder(counts);
  const out = new Uint8Array(planes.length);
  order.forEach((p, g) => {
    if (isRegion(planes, 5 * p)) {
      out.set(gltfRegion(planes, 5 * p), 5 * g);
      return;
    }
    out.set(planes.subarray(5 * p, 5 * p + 4), 5 * g);
    out[5 * g + 4] = gltfBits(planes[5 * p + 4]);
  });
  return out;
}

// The side of its cell's plane that point p (zhc axes) lies on, in doubles (zhc__volume_plane_side's
// rule): null when the cell has no plane, else { side, sides, cell, region }. A corner region
// (region true): side 1 when p is inside it, sides = the corners inside it, both from the rules of
// docs/runtime.md "Corner regions" written out per axis (p in the cell's 31ths against q_a).
export function planeSideAt(grid, planes, p) {
  const i0 = [0, 1, 2].map((c) => axis(p[c], grid.origin[c], grid.spacing[c], grid.counts[c])[0]);
  const cell = i0[0] + grid.counts[0] * (i0[1] + grid.counts[1] * i0[2]);
  const e = planes.subarray(5 * cell, 5 * cell + 5);
  if (isRegion(e)) {
    const { q, d } = regionFields(e);
    let side = 1, sides = 0;
    for (let a = 0; a < 3; a++) {
      if (q[a] === 0) continue;
      const s = (p[a] - (grid.origin[a] + i0[a] * grid.spacing[a])) * 31, t = q[a] * grid.spacing[a];
      if (!(d[a] ? s >= t : s < t)) side = 0;
    }
    for (let k = 0; k < 8; k++)
      if ([0, 1, 2].every((a) => q[a] === 0 || ((k >> a) & 1) === d[a])) sides |= 1 << k;
    return { side, sides, cell, region: true };
  }
  const offset = (e[2] | (e[3] << 8)) << 16 >> 16;
  if (offset === -32768) return null;
  const n = decodeNormal(e[0], e[1]), c = cellCentre(grid, i0), unit = diagonal(grid) / 65534;
  let s = -offset * unit;
  for (let a = 0; a < 3; a++) s += n[a] * (p[a] - c[a]);
  return { side: s >= 0 ? 1 : 0, sides: e[4], cell, region: false };
}
