// Cell-plane test data shared by the GPU runtime tests (test_runtime_gl: runtime/zhc.glsl with
// ZHC_VOLUME_PLANE, test_runtime_vk: runtime/zhc.hlsl likewise): random plane and corner region
// entries for a probe grid (docs/runtime.md "Cell planes", "Corner regions"), their GPU words (the
// uvec2 / uint2 of ZHC_VOLUME_PLANE), the same grid in glTF axes (ZHC_VOLUME_PLANE_AXES_GLTF), and
// per sample point the corners the C header keeps and whether the point lies too close to its
// cell's plane, to a bounding plane of its cell's region or to a cell face for a float shader to be
// compared with the double header.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "zhc_runtime.h"

namespace zhc::planes_test {

// The offset code of the plane of normal code (ou, ov) through `at`, for the cell with first probe
// i0 (rounded and clamped to +-32767).
inline int offset_through(std::uint8_t ou, std::uint8_t ov, const double origin[3], const double spacing[3], const std::uint32_t i0[3],
                          const double at[3]) {
    double n[3], dot = 0;
    zhc_plane_normal(ou, ov, n);
    for (int c = 0; c < 3; ++c) dot += n[c] * (at[c] - (origin[c] + (double(i0[c]) + 0.5) * spacing[c]));
    const double diag = std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
    return int(std::lround(std::clamp(dot * 65534.0 / diag, -32767.0, 32767.0)));
}

// n . (x - c) - offset |spacing| / 65534 for the entry e of the cell with first probe i0 (double;
// e must hold a plane).
inline double plane_value(const std::uint8_t* e, const double origin[3], const double spacing[3], const std::uint32_t i0[3],
                          const double x[3]) {
    double n[3], s = 0;
    zhc_plane_normal(e[0], e[1], n);
    for (int c = 0; c < 3; ++c) s += n[c] * (x[c] - (origin[c] + (double(i0[c]) + 0.5) * spacing[c]));
    const double diag = std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
    const int offset = int(std::int16_t(std::uint16_t(e[2] | (e[3] << 8))));
    return s - double(offset) * diag / 65534.0;
}

// A corner region entry in double (docs/runtime.md "Corner regions"): is e one, and the signed
// distance of x_a from the region's bounding plane along axis a, x_a - (origin_a + i0_a spacing_a) -
// q_a spacing_a / 31 (the bound is s_a >= t_a with s_a = (x_a - cell corner) * 31, t_a = q_a
// spacing_a), NaN along an axis with q_a = 0 (no bound).
inline bool is_region(const std::uint8_t* e) { return e[2] == 0x00 && e[3] == 0x80 && (e[4] & 0x80u); }
inline double region_distance(const std::uint8_t* e, const double origin[3], const double spacing[3], const std::uint32_t i0[3],
                              const double x[3], int a) {
    const unsigned q = ((unsigned(e[0]) | unsigned(e[1]) << 8) >> (5 * a)) & 31u;
    if (q == 0) return std::nan("");
    return x[a] - (origin[a] + double(i0[a]) * spacing[a]) - double(q) * spacing[a] / 31.0;
}

// The corners a corner region entry keeps at x, written from docs/runtime.md "Corner regions"
// corner by corner (the slow twin of zhc__volume_plane_side's region branch): the point is inside
// when every bounded axis holds it (d_a ? s_a >= t_a : s_a < t_a), corner k is inside when along
// every bounded axis its bit a equals d_a; inside, the corners inside are kept, outside the others.
inline unsigned region_keep(const std::uint8_t* e, const double origin[3], const double spacing[3], const std::uint32_t i0[3],
                            const double x[3]) {
    const unsigned r = unsigned(e[0]) | unsigned(e[1]) << 8;
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
        const unsigned q = (r >> (5 * a)) & 31u;
        const bool d = (e[4] >> a) & 1u;
        const double s = (x[a] - (origin[a] + double(i0[a]) * spacing[a])) * 31.0, t = double(q) * spacing[a];
        if (q != 0 && !(d ? s >= t : s < t)) inside = false;
    }
    unsigned keep = 0;
    for (int k = 0; k < 8; ++k) {
        bool corner_inside = true;
        for (int a = 0; a < 3; ++a)
            if (((r >> (5 * a)) & 31u) != 0 && unsigned((k >> a) & 1) != ((e[4] >> a) & 1u)) corner_inside = false;
        if (corner_inside == inside) keep |= 1u << k;
    }
    return keep;
}

// 5 count bytes: for each probe that starts a cell (not the last along an axis of count >= 2), with
// probability `share`, a cell entry, else "no plane". An entry is, with probability `region_share`,
// a corner region (each axis unbounded, q = 0, with probability 1/4, else a threshold q uniform in
// 1..31; random direction bits; reserved bits 0), else a plane of random normal code through a
// random point of its cell with the sides of the cell's corners (as the bake writes them).
inline std::vector<std::uint8_t> random_cell_planes(std::mt19937_64& rng, const double origin[3], const double spacing[3],
                                                    const std::uint32_t counts[3], double share, double region_share) {
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<std::uint8_t> planes;
    for (std::uint32_t z = 0; z < counts[2]; ++z)
        for (std::uint32_t y = 0; y < counts[1]; ++y)
            for (std::uint32_t x = 0; x < counts[0]; ++x) {
                std::uint8_t e[5] = {127, 127, 0x00, 0x80, 0};
                const std::uint32_t i0[3] = {x, y, z};
                bool last = false;
                for (int c = 0; c < 3; ++c) last = last || (counts[c] > 1 && i0[c] + 1 == counts[c]);
                const bool set = !last && u(rng) < share;
                if (set && u(rng) < region_share) {
                    unsigned r = 0;
                    for (int c = 0; c < 3; ++c)
                        if (rng() % 4 != 0) r |= unsigned(1 + rng() % 31) << (5 * c);
                    e[0] = std::uint8_t(r & 0xFF);
                    e[1] = std::uint8_t(r >> 8);
                    e[4] = std::uint8_t(0x80u | (rng() & 7u));
                } else if (set) {
                    e[0] = std::uint8_t(rng());
                    e[1] = std::uint8_t(rng());
                    double at[3];
                    for (int c = 0; c < 3; ++c) at[c] = origin[c] + (double(i0[c]) + (counts[c] > 1 ? u(rng) : 0.0)) * spacing[c];
                    const std::uint16_t o = std::uint16_t(std::int16_t(offset_through(e[0], e[1], origin, spacing, i0, at)));
                    e[2] = std::uint8_t(o & 0xFF);
                    e[3] = std::uint8_t(o >> 8);
                    for (int k = 0; k < 8; ++k) {
                        const double corner[3] = {origin[0] + (x + (k & 1)) * spacing[0], origin[1] + (y + ((k >> 1) & 1)) * spacing[1],
                                                  origin[2] + (z + (k >> 2)) * spacing[2]};
                        if (plane_value(e, origin, spacing, i0, corner) >= 0) e[4] = std::uint8_t(e[4] | (1u << k));
                    }
                }
                planes.insert(planes.end(), e, e + 5);
            }
    return planes;
}

// The GPU words of plane entries: 2 per probe, bytes 0..3 little-endian and byte 4.
inline std::vector<std::uint32_t> plane_words(const std::vector<std::uint8_t>& planes) {
    std::vector<std::uint32_t> w;
    for (std::size_t i = 0; i + 5 <= planes.size(); i += 5) {
        w.push_back(std::uint32_t(planes[i]) | std::uint32_t(planes[i + 1]) << 8 | std::uint32_t(planes[i + 2]) << 16 |
                    std::uint32_t(planes[i + 3]) << 24);
        w.push_back(planes[i + 4]);
    }
    return w;
}

// A zhc-axes grid in glTF axes ((x, y, z)_glTF = (y, z, x)_zhc): counts, origin and spacing
// permuted, and gltf_to_zhc[j] = the zhc probe index of glTF probe j.
struct GltfGrid {
    std::uint32_t counts[3];
    double origin[3], spacing[3];
    std::vector<std::uint32_t> gltf_to_zhc;
};
inline GltfGrid gltf_grid(const double origin[3], const double spacing[3], const std::uint32_t counts[3]) {
    GltfGrid g;
    for (int c = 0; c < 3; ++c) {
        g.counts[c] = counts[(c + 1) % 3];
        g.origin[c] = origin[(c + 1) % 3];
        g.spacing[c] = spacing[(c + 1) % 3];
    }
    for (std::uint32_t gz = 0; gz < g.counts[2]; ++gz)
        for (std::uint32_t gy = 0; gy < g.counts[1]; ++gy)
            for (std::uint32_t gx = 0; gx < g.counts[0]; ++gx) {
                const std::uint32_t x = gz, y = gx, z = gy;  // zhc (x, y, z) = glTF (z, x, y)
                g.gltf_to_zhc.push_back(x + counts[0] * (y + counts[1] * z));
            }
    return g;
}
// The sides byte in glTF corner order: glTF corner (gx, gy, gz) is zhc corner (gz, gx, gy).
inline std::uint8_t gltf_sides(std::uint8_t zhc_sides) {
    std::uint8_t s = 0;
    for (int kg = 0; kg < 8; ++kg) {
        const int gx = kg & 1, gy = (kg >> 1) & 1, gz = kg >> 2;
        const int k = gz + 2 * gx + 4 * gy;
        if ((zhc_sides >> k) & 1) s = std::uint8_t(s | (1u << kg));
    }
    return s;
}
// Cell entries in glTF probe order: a plane with glTF sides (normal code and offset unchanged), a
// corner region with its per-axis fields permuted (glTF axis a's threshold and direction = zhc axis
// (a + 1) % 3's, as the glTF writer stores them: docs/runtime.md "Corner regions").
inline std::vector<std::uint8_t> gltf_planes(const GltfGrid& g, const std::vector<std::uint8_t>& planes) {
    std::vector<std::uint8_t> out;
    for (std::uint32_t q : g.gltf_to_zhc) {
        const std::uint8_t* e = planes.data() + 5 * std::size_t(q);
        if (is_region(e)) {
            const unsigned r = unsigned(e[0]) | unsigned(e[1]) << 8;
            unsigned rg = 0, dg = 0x80u;
            for (int a = 0; a < 3; ++a) {
                rg |= ((r >> (5 * ((a + 1) % 3))) & 31u) << (5 * a);
                dg |= ((unsigned(e[4]) >> ((a + 1) % 3)) & 1u) << a;
            }
            const std::uint8_t ge[5] = {std::uint8_t(rg & 0xFF), std::uint8_t(rg >> 8), e[2], e[3], std::uint8_t(dg)};
            out.insert(out.end(), ge, ge + 5);
        } else {
            out.insert(out.end(), e, e + 4);
            out.push_back(gltf_sides(e[4]));
        }
    }
    return out;
}

// One sample of a volume (zhc_volume_sh3's rules, double): the cell, the corners kept by the plane
// or corner region alone (bit k; 0xFF without either), the sum of the weights kept by validity,
// visibility and the entry, whether the cell's entry is a region and the point inside it, and
// whether the point is within 1e-4 |spacing| of its cell's plane, of one of its cell's region's
// bounding planes (along an axis with q_a != 0) or within 1e-5 cell widths of a face between two
// cells (where float and double may pick different sides or cells).
struct Sample {
    std::uint32_t i0[3];
    double f[3];
    unsigned plane_keep = 0xFF;
    double kept_sum = 0;
    bool has_plane = false, region = false, inside = false, near = false;
    bool region_twin_differs = false;  // the header's region keep differs from region_keep's
};
inline Sample sample(const zhc_volume& v, const double p[3]) {
    Sample s;
    for (int c = 0; c < 3; ++c) {
        zhc__volume_axis(p[c], v.origin[c], v.spacing[c], v.counts[c], &s.i0[c], &s.f[c]);
        const double t = (p[c] - v.origin[c]) / v.spacing[c];
        for (std::uint32_t face = 1; face + 1 < v.counts[c]; ++face) s.near = s.near || std::fabs(t - double(face)) < 1e-5;
    }
    const std::size_t cell = s.i0[0] + std::size_t(v.counts[0]) * (s.i0[1] + std::size_t(v.counts[1]) * s.i0[2]);
    if (v.planes) {
        int side = 0;
        unsigned sides = 0;
        s.has_plane = zhc__volume_plane_side(&v, cell, s.i0, p, &side, &sides) != 0;
        if (s.has_plane) {
            const std::uint8_t* e = v.planes + 5 * cell;
            s.plane_keep = (side ? sides : ~sides) & 0xFFu;
            const double diag = std::sqrt(v.spacing[0] * v.spacing[0] + v.spacing[1] * v.spacing[1] + v.spacing[2] * v.spacing[2]);
            s.region = is_region(e);
            s.inside = s.region && side;
            if (s.region) {
                s.region_twin_differs = s.plane_keep != region_keep(e, v.origin, v.spacing, s.i0, p);
                for (int a = 0; a < 3; ++a) s.near = s.near || std::fabs(region_distance(e, v.origin, v.spacing, s.i0, p, a)) < 1e-4 * diag;
            } else {
                s.near = s.near || std::fabs(plane_value(e, v.origin, v.spacing, s.i0, p)) < 1e-4 * diag;
            }
        }
    }
    for (int b = 0; b < 8; ++b) {
        const std::uint32_t q[3] = {s.i0[0] + std::uint32_t(b & 1), s.i0[1] + std::uint32_t((b >> 1) & 1), s.i0[2] + std::uint32_t(b >> 2)};
        const double w = ((b & 1) ? s.f[0] : 1 - s.f[0]) * ((b >> 1 & 1) ? s.f[1] : 1 - s.f[1]) * ((b >> 2) ? s.f[2] : 1 - s.f[2]);
        if (w == 0) continue;
        const std::size_t idx = q[0] + std::size_t(v.counts[0]) * (q[1] + std::size_t(v.counts[1]) * q[2]);
        if (v.validity && !v.validity[idx]) continue;
        if (v.visibility && !((v.visibility[idx] >> (7 - b)) & 1)) continue;
        if (!((s.plane_keep >> b) & 1)) continue;
        s.kept_sum += w;
    }
    return s;
}

}  // namespace zhc::planes_test
