// Cell-plane test data shared by the GPU runtime tests (test_runtime_gl: runtime/zhc.glsl with
// ZHC_VOLUME_PLANE, test_runtime_vk: runtime/zhc.hlsl likewise): random plane entries for a probe
// grid (docs/runtime.md "Cell planes"), their GPU words (the uvec2 / uint2 of ZHC_VOLUME_PLANE), the
// same grid in glTF axes (ZHC_VOLUME_PLANE_AXES_GLTF), and per sample point the corners the C
// header keeps and whether the point lies too close to its cell's plane or to a cell face for a
// float shader to be compared with the double header.
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

// 5 count bytes: for each probe that starts a cell (not the last along an axis of count >= 2), with
// probability `share`, a plane of random normal code through a random point of its cell with the
// sides of the cell's corners (as the bake writes them); every other entry "no plane".
inline std::vector<std::uint8_t> random_cell_planes(std::mt19937_64& rng, const double origin[3], const double spacing[3],
                                                    const std::uint32_t counts[3], double share) {
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<std::uint8_t> planes;
    for (std::uint32_t z = 0; z < counts[2]; ++z)
        for (std::uint32_t y = 0; y < counts[1]; ++y)
            for (std::uint32_t x = 0; x < counts[0]; ++x) {
                std::uint8_t e[5] = {127, 127, 0x00, 0x80, 0};
                const std::uint32_t i0[3] = {x, y, z};
                bool last = false;
                for (int c = 0; c < 3; ++c) last = last || (counts[c] > 1 && i0[c] + 1 == counts[c]);
                if (!last && u(rng) < share) {
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
// Plane entries in glTF probe order with glTF sides (normal code and offset unchanged).
inline std::vector<std::uint8_t> gltf_planes(const GltfGrid& g, const std::vector<std::uint8_t>& planes) {
    std::vector<std::uint8_t> out;
    for (std::uint32_t q : g.gltf_to_zhc) {
        const std::uint8_t* e = planes.data() + 5 * std::size_t(q);
        out.insert(out.end(), e, e + 4);
        out.push_back(gltf_sides(e[4]));
    }
    return out;
}

// One sample of a volume (zhc_volume_sh3's rules, double): the cell, the corners kept by the plane
// alone (bit k; 0xFF without a plane), the sum of the weights kept by validity, visibility and the
// plane, and whether the point is within 1e-4 |spacing| of its cell's plane or within 1e-5 cell
// widths of a face between two cells (where float and double may pick different sides or cells).
struct Sample {
    std::uint32_t i0[3];
    double f[3];
    unsigned plane_keep = 0xFF;
    double kept_sum = 0;
    bool has_plane = false, near = false;
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
            s.plane_keep = (side ? sides : ~sides) & 0xFFu;
            const double diag = std::sqrt(v.spacing[0] * v.spacing[0] + v.spacing[1] * v.spacing[1] + v.spacing[2] * v.spacing[2]);
            s.near = s.near || std::fabs(plane_value(v.planes + 5 * cell, v.origin, v.spacing, s.i0, p)) < 1e-4 * diag;
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
