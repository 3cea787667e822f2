// Helpers shared by the 8-bit cube-map tests (test_cube_ldr, test_mesa_bc's BC7 cube maps): an
// analytic function with its SH, the sRGB curves written out, and one-level KTX2 / DDS cube-map
// writers for 8-bit formats (from the KTX 2.0 specification and Microsoft's DDS documentation).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "cube_helpers.h"

namespace zhc::cube_test {

using Bytes = std::vector<std::uint8_t>;

inline const double kSqrt4Pi = std::sqrt(4 * M_PI);

// ---- the analytic function: constant + linear gradient per channel, f_k(d) = c_k + g_k . d ------
struct Linear {
    double c[3] = {0.45, 0.5, 0.55};
    double g[3][3] = {{0.2, -0.1, 0.15}, {-0.12, 0.18, 0.1}, {0.1, 0.1, -0.2}};  // (x, y, z) per channel
    double scale = 1.0;
    Rgb operator()(Vec3 d) const {
        Rgb out;
        for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(scale * (c[k] + g[k][0] * d.x + g[k][1] * d.y + g[k][2] * d.z));
        return out;
    }
    // Its SH: L00 = sqrt(4 pi) c; with zhc's basis (Y1-1 = -Y1 y, Y10 = Y1 z, Y11 = -Y1 x,
    // Y1 = sqrt(3 / 4 pi)) and the integral of d_j^2 = 4 pi / 3: L1-1 = -Y1 (4 pi / 3) g_y, etc.
    Sh3Radiance sh() const {
        Sh3Radiance a{};
        const double y1 = std::sqrt(3 / (4 * M_PI)) * 4 * M_PI / 3;
        for (int k = 0; k < 3; ++k) {
            a[0][k] = static_cast<float>(scale * kSqrt4Pi * c[k]);
            a[1][k] = static_cast<float>(-scale * y1 * g[k][1]);
            a[2][k] = static_cast<float>(scale * y1 * g[k][2]);
            a[3][k] = static_cast<float>(-scale * y1 * g[k][0]);
        }
        return a;
    }
};

// ---- the sRGB curves -------------------------------------------------------------------------
inline double srgb_eotf_twin(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
inline double srgb_oetf_twin(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; }

// ---- containers ---------------------------------------------------------------------------------
// KTX2, one level (the 8-bit cases; float cases use cube_helpers' write_ktx2).
inline Bytes ktx2_one_level(std::uint32_t vk, std::uint32_t type_size, int n, const Bytes& level) {
    const std::uint32_t dfd_len = 44, index_end = 80 + 24;
    const std::uint64_t offset = (index_end + dfd_len + 15) / 16 * 16;
    Bytes b = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    for (std::uint32_t v : {vk, type_size, std::uint32_t(n), std::uint32_t(n), 0u, 0u, 6u, 1u, 0u, index_end, dfd_len, 0u, 0u}) put32v(b, v);
    put64v(b, 0);
    put64v(b, 0);
    put64v(b, offset);
    put64v(b, level.size());
    put64v(b, level.size());
    put32v(b, dfd_len);
    put32v(b, 0);
    put32v(b, 2u | (40u << 16));
    b.resize(offset, 0);
    b.insert(b.end(), level.begin(), level.end());
    return b;
}

// DDS: DX10 header with `dxgi`, or legacy with FourCC `fourcc`, or legacy RGB with masks.
struct DdsPf {
    std::uint32_t dxgi = 0, fourcc = 0, flags = 0x4, bits = 0, masks[4] = {0, 0, 0, 0};
};
inline Bytes dds(const DdsPf& pf, int n, const Bytes& faces) {
    Bytes b;
    put32v(b, 0x20534444);
    for (std::uint32_t v : {124u, 0x1007u, std::uint32_t(n), std::uint32_t(n), 0u, 0u, 1u}) put32v(b, v);
    for (int i = 0; i < 11; ++i) put32v(b, 0);
    put32v(b, 32);
    put32v(b, pf.dxgi ? 0x4u : pf.flags);
    put32v(b, pf.dxgi ? 0x30315844u : pf.fourcc);
    put32v(b, pf.bits);
    for (std::uint32_t m : pf.masks) put32v(b, m);
    put32v(b, 0x1008);
    put32v(b, 0x200 | 0xFC00);
    for (int i = 0; i < 3; ++i) put32v(b, 0);
    if (pf.dxgi)
        for (std::uint32_t v : {pf.dxgi, 3u, 0x4u, 1u, 0u}) put32v(b, v);
    b.insert(b.end(), faces.begin(), faces.end());
    return b;
}

}  // namespace zhc::cube_test
