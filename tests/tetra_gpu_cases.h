// Scattered-probe (`points` volume) test data shared by the GPU runtime tests (test_runtime_gl:
// zhcVolumeTetraIrradiance of runtime/zhc.glsl, test_runtime_vk: zhc_volume_tetra_irradiance of
// runtime/zhc.hlsl): a set of random probe positions tetrahedralised by formats/probes/tetra.h
// (qhull, as `zhc convert` / `zhc bake` do), the probes encoded with a codec entry, the C header's
// points volume over them (zhc_volume_init_points), and sample points inside and outside the hull
// with the 4 probes and weights zhc_volume_tetra_weights gives (what an application hands the
// shader, docs/runtime.md "Scattered probes (`points` layout)").
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/probe_set.h"
#include "formats/probes/tetra.h"
#include "zhc_runtime.h"
#include "zhc_runtime_params.hpp"

namespace zhc::tetra_test {

// The probe box: positions uniform in [lo, lo + size] per axis.
constexpr double kLo[3] = {-1.5, 2.0, 0.25}, kSize[3] = {4.0, 2.5, 3.0};

struct PointsVolume {
    std::vector<std::array<float, 3>> positions;
    std::vector<std::uint8_t> bytes;  // the stored probes, then (nan_probe) one probe of 0xFF bytes
    std::vector<std::uint32_t> tetrahedra;  // 4 per tetrahedron
    std::vector<std::int32_t> neighbours;   // 4 per tetrahedron, -1 on the hull
    std::vector<std::uint8_t> validity;     // empty: none
    std::vector<Sh3Radiance> decoded;       // per probe (decode_probe)
    std::uint32_t count = 0, nan_probe = 0;  // probes; index of the 0xFF probe in `bytes`
    zhc_volume vol{};
    std::string error;  // non-empty when the set could not be built
};

inline std::vector<std::array<float, 3>> random_positions(std::mt19937_64& rng, std::uint32_t n) {
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<std::array<float, 3>> p(n);
    for (auto& q : p)
        for (int c = 0; c < 3; ++c) q[size_t(c)] = float(kLo[c] + kSize[c] * u(rng));
    return p;
}

// The points volume of `hubs` (one per position) stored as `codec` with `p`, with `validity` (empty:
// none). Fills out.error on failure. Probe bytes, tetrahedra and neighbours stay in `out`, which the
// volume points into: do not copy `out` after this.
inline void make_points_volume(PointsVolume& out, const Codec& codec, const CodecOptions& p,
                               const std::vector<std::array<float, 3>>& positions, const std::vector<Sh3Radiance>& hubs,
                               const std::vector<std::uint8_t>& validity) {
    out.positions = positions;
    out.count = std::uint32_t(positions.size());
    out.validity = validity;
    auto tz = tetrahedralize(positions);
    if (!tz.ok()) {
        out.error = "tetrahedralize: " + tz.error().message;
        return;
    }
    if (!tz->duplicates.empty() || !tz->unused.empty() || tz->flat != 0) {
        out.error = "the random set has duplicates, unused or flat tetrahedra";
        return;
    }
    for (std::size_t t = 0; t < tz->tetrahedra.size(); ++t)
        for (int k = 0; k < 4; ++k) {
            out.tetrahedra.push_back(tz->tetrahedra[t][size_t(k)]);
            out.neighbours.push_back(tz->neighbours[t][size_t(k)]);
        }
    out.bytes.assign((out.count + 1) * codec.size_bytes, 0xFF);
    for (std::uint32_t i = 0; i < out.count; ++i) {
        encode_probe(codec, p, hubs[i], out.bytes.data() + i * codec.size_bytes, nullptr);
        out.decoded.push_back(decode_probe(codec, p, out.bytes.data() + i * codec.size_bytes));
    }
    out.nan_probe = out.count;
    zhc_probe_format fmt;
    if (!runtime_format(codec.name, p, &fmt)) {
        out.error = "no runtime format for " + std::string(codec.name);
        return;
    }
    const int r = zhc_volume_init_points(&out.vol, &fmt, out.bytes.data(), out.bytes.size(), out.positions.data(), out.count,
                                         out.tetrahedra.data(), out.neighbours.data(), std::uint32_t(tz->tetrahedra.size()));
    if (r != ZHC_OK) {
        out.error = "zhc_volume_init_points: " + std::to_string(r);
        return;
    }
    if (!out.validity.empty()) out.vol.validity = out.validity.data();
}

// Whether the 0xFF probe decodes (zhc_decode_probe) to a non-finite coefficient: then a shader that
// read it at weight 0 would return NaN or Inf.
inline bool nan_probe_poisons(const PointsVolume& v) {
    float sh[27];
    zhc_decode_probe(&v.vol.format, v.bytes.data() + std::size_t(v.nan_probe) * v.vol.probe_size, sh);
    for (float x : sh)
        if (!std::isfinite(x)) return true;
    return false;
}

struct Sample {
    float pos[3];
    float normal[3];
    std::uint32_t probes[4];   // of zhc_volume_tetra_weights; weight-0 entries replaced by nan_probe
    double weights[4];
    int outside = 0;           // zhc_volume_tetra_weights' return value
};

// n samples: a third inside the probe box (mostly inside the hull), the rest in the box grown by
// half its size on every side (mostly outside), and the probe positions themselves; random unit
// normals. Weights from zhc_volume_tetra_weights walking from tetrahedron 0 (zhc_volume_sh3's call).
// `poison`: the probe index of every weight-0 entry becomes v.nan_probe (not read by the blend).
template <class Direction>
std::vector<Sample> samples(std::mt19937_64& rng, const PointsVolume& v, int n, bool poison, Direction direction) {
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Sample> out;
    for (int i = 0; i < n + int(v.count); ++i) {
        Sample s{};
        for (int c = 0; c < 3; ++c) {
            if (i >= n) s.pos[c] = v.positions[size_t(i - n)][size_t(c)];
            else if (i % 3 == 0) s.pos[c] = float(kLo[c] + kSize[c] * u(rng));
            else s.pos[c] = float(kLo[c] - 0.5 * kSize[c] + 2.0 * kSize[c] * u(rng));
        }
        const auto d = direction(u(rng), u(rng));
        s.normal[0] = float(d.x);
        s.normal[1] = float(d.y);
        s.normal[2] = float(d.z);
        const double x[3] = {s.pos[0], s.pos[1], s.pos[2]};
        std::uint32_t t = 0;
        s.outside = zhc_volume_tetra_weights(&v.vol, x, &t, s.probes, s.weights);
        if (poison)
            for (int k = 0; k < 4; ++k)
                if (s.weights[k] == 0.0) s.probes[k] = v.nan_probe;
        out.push_back(s);
    }
    return out;
}

// The slow twin of an SH3 radiance's irradiance: E_k(n) = sum_i s_l(i) c_ik Y_i(n / |n|), in double
// with codec/sh/sh.h's basis and band scales (constant radiance 1 gives 1).
inline void irradiance_twin(const double sh[27], const float n_in[3], double e[3]) {
    const double len = std::sqrt(double(n_in[0]) * n_in[0] + double(n_in[1]) * n_in[1] + double(n_in[2]) * n_in[2]);
    const std::array<double, 9> y = sh3_basis(Vec3{n_in[0] / len, n_in[1] / len, n_in[2] / len});
    for (int k = 0; k < 3; ++k) {
        e[k] = 0;
        for (int i = 0; i < 9; ++i) e[k] += kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)] * sh[3 * i + k] * y[size_t(i)];
    }
}

// A field of SH3 radiance affine in position: coefficient j = a[j] + sum_c b[j][c] x_c.
struct AffineField {
    double a[27];
    double b[27][3];
    void at(const double x[3], double sh[27]) const {
        for (int j = 0; j < 27; ++j) sh[j] = a[j] + b[j][0] * x[0] + b[j][1] * x[1] + b[j][2] * x[2];
    }
    Sh3Radiance hub_at(const std::array<float, 3>& p) const {
        const double x[3] = {p[0], p[1], p[2]};
        double sh[27];
        at(x, sh);
        Sh3Radiance h;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) h[i][k] = float(sh[3 * i + k]);
        return h;
    }
};

// DC in [1, 2], other coefficients in [-0.5, 0.5], slopes up to 0.3 per unit of position.
inline AffineField random_affine(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    AffineField f;
    for (int j = 0; j < 27; ++j) {
        f.a[j] = j < 3 ? 1.5 + 0.5 * u(rng) : 0.5 * u(rng);
        for (int c = 0; c < 3; ++c) f.b[j][c] = 0.3 * u(rng);
    }
    return f;
}

}  // namespace zhc::tetra_test
