// runtime/zhc_volume_layouts.hpp: GPU volume layouts (docs/runtime.md "GPU volume layouts").
// The storage roundings against the runtime header's decoders and exhaustive / brute-force twins,
// the CPU model of hardware trilinear filtering against a slow twin (hat weights over every texel,
// texels decoded independently), the float32 atlas against zhc_volume_irradiance, and the headline
// of bench_volume on the demo's baked grid and a baked glTF scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "codec/bake/scene.h"
#include "codec/probe/probe_set.h"
#include "formats/io/file_io.h"
#include "formats/scene/scene_gltf.h"
#include "runtime/zhc_runtime.h"
#include "runtime/zhc_volume_layouts.hpp"

namespace {

using namespace zhc;
namespace L = zhc_layouts;

TEST(VolumeLayouts, HalfRoundsToNearestEven) {
    // Every finite binary16 value converts back to its own bits.
    for (std::uint32_t h = 0; h < 0x10000u; ++h) {
        if ((h & 0x7C00u) == 0x7C00u) continue;  // inf / NaN
        const float f = zhc_unpack_half(static_cast<std::uint16_t>(h));
        ASSERT_EQ(L::float_to_half(f), h) << h;
    }
    // Midpoints between neighbours go to the even one; just above / below to the nearer one.
    for (std::uint32_t h = 0; h < 0x7BFFu; ++h) {
        const double a = zhc_unpack_half(static_cast<std::uint16_t>(h)), b = zhc_unpack_half(static_cast<std::uint16_t>(h + 1));
        const float mid = static_cast<float>((a + b) / 2);  // exact: fewer than 24 significant bits
        ASSERT_EQ(double(mid), (a + b) / 2);
        const std::uint32_t even = (h & 1u) ? h + 1 : h;
        ASSERT_EQ(L::float_to_half(mid), even) << h;
        ASSERT_EQ(L::float_to_half(-mid), even | 0x8000u) << h;
        ASSERT_EQ(L::float_to_half(std::nextafter(mid, 0.0f)), h) << h;
        ASSERT_EQ(L::float_to_half(std::nextafter(mid, 1e30f)), h + 1) << h;
    }
    EXPECT_EQ(L::float_to_half(65519.99f), 0x7BFFu);
    EXPECT_EQ(L::float_to_half(65520.0f), 0x7C00u);
    EXPECT_EQ(L::float_to_half(-1e9f), 0xFC00u);
    EXPECT_EQ(L::float_to_half(1e-9f), 0u);
}

// Twin of pack_rgb9e5: the smallest shared exponent at which the largest value rounds (half up)
// to at most 511, found by trying every exponent.
std::uint32_t rgb9e5_twin(const double v[3]) {
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = std::min(std::max(v[k], 0.0), 511.0 / 512.0 * 65536.0);
    const double mx = std::max({c[0], c[1], c[2]});
    for (int e = 0; e < 32; ++e) {
        const double q = std::ldexp(1.0, e - 24);
        if (std::floor(mx / q + 0.5) > 511.0) continue;
        std::uint32_t bits = static_cast<std::uint32_t>(e) << 27;
        for (int k = 0; k < 3; ++k) bits |= static_cast<std::uint32_t>(std::floor(c[k] / q + 0.5)) << (9 * k);
        return bits;
    }
    return 0xFFFFFFFFu;
}

TEST(VolumeLayouts, Rgb9e5PackMatchesTheSmallestExponentTwin) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 200000; ++i) {
        double v[3];
        const double scale = std::ldexp(1.0, static_cast<int>(u(rng) * 44) - 26);
        for (double& x : v) x = (u(rng) < 0.05 ? -1 : 1) * u(rng) * scale;
        const std::uint32_t bits = L::pack_rgb9e5(v);
        ASSERT_EQ(bits, rgb9e5_twin(v)) << v[0] << " " << v[1] << " " << v[2];
        float back[3];
        zhc_unpack_rgb9e5(bits, back);
        const double q = std::ldexp(1.0, static_cast<int>(bits >> 27) - 24);
        for (int k = 0; k < 3; ++k) ASSERT_LE(std::fabs(back[k] - std::clamp(v[k], 0.0, 65408.0)), q / 2 * (1 + 1e-12));
    }
}

// A grid volume over float sh3 probes that it owns.
struct OwnedVolume {
    std::vector<std::uint8_t> bytes;
    zhc_volume v{};
    OwnedVolume(const std::vector<Sh3Radiance>& probes, const ProbeLayout& layout, const char* rep = "sh3") {
        auto set = encode_probe_set(probes, rep, CodecOptions{}, layout);
        EXPECT_TRUE(set.ok());
        if (!set.ok()) return;
        bytes = set->payload;
        zhc_probe_format f;
        EXPECT_EQ(zhc_probe_format_init(&f, rep), ZHC_OK);
        const ProbeGrid& g = layout.grid;
        const double o[3] = {g.origin.x, g.origin.y, g.origin.z}, s[3] = {g.spacing.x, g.spacing.y, g.spacing.z};
        const std::uint32_t n[3] = {g.counts[0], g.counts[1], g.counts[2]};
        EXPECT_EQ(zhc_volume_init(&v, &f, bytes.data(), bytes.size(), o, s, n), ZHC_OK);
    }
};

struct Baked {
    std::vector<Sh3Radiance> probes;
    ProbeLayout layout;
};

Baked demo_grid() {
    const Scene scene = default_scene();
    auto b = bake_scene(scene);
    EXPECT_TRUE(b.ok());
    return {b.ok() ? *b : std::vector<Sh3Radiance>{}, probe_layout(scene.probes)};
}

Baked gltf_grid() {
    const std::string path = std::string(ZHC_TEST_DATA_DIR) + "/gltf/gi_nodes.glb";
    auto bytes = read_file_bytes(path, 1u << 26);
    EXPECT_TRUE(bytes.ok());
    if (!bytes.ok()) return {};
    auto scene = parse_scene_gltf(*bytes, path);
    EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
    if (!scene.ok()) return {};
    auto b = bake_scene(*scene);
    EXPECT_TRUE(b.ok());
    return {b.ok() ? *b : std::vector<Sh3Radiance>{}, probe_layout(scene->probes)};
}

// Random probes of non-negative radiance (ambient + directional lights) on a grid with a count-1 axis.
Baked random_grid() {
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(0, 1);
    Baked b;
    b.layout.kind = ProbeLayoutKind::kGrid;
    b.layout.grid.origin = Vec3{-1.0, 2.0, 0.5};
    b.layout.grid.spacing = Vec3{0.7, 1.3, 0.4};
    b.layout.grid.counts = {5, 1, 3};
    for (int i = 0; i < 15; ++i) {
        Sh3Radiance sh = project_constant(Rgb{float(0.3 * u(rng)), float(0.3 * u(rng)), float(0.3 * u(rng))});
        const double z = 2 * u(rng) - 1, phi = 6.283185307179586 * u(rng), r = std::sqrt(1 - z * z);
        sh = sh + project_directional(Vec3{r * std::cos(phi), r * std::sin(phi), z},
                                      Rgb{float(4 * u(rng)), float(2 * u(rng)), float(u(rng))});
        b.probes.push_back(sh);
    }
    return b;
}

// Texel value decoded independently of texel_value: its own byte reads and decoders.
double twin_texel(const std::vector<std::uint8_t>& payload, L::TextureSpec t, std::size_t index, int c) {
    const std::uint8_t* p = payload.data();
    switch (t.storage) {
        case L::Storage::kF32: {
            float f;
            std::memcpy(&f, p + 16 * index + 4 * static_cast<std::size_t>(c), 4);
            return f;
        }
        case L::Storage::kF16: {
            const std::size_t at = 8 * index + 2 * static_cast<std::size_t>(c);
            return zhc_unpack_half(static_cast<std::uint16_t>(p[at] + 256 * p[at + 1]));
        }
        case L::Storage::kSnorm8: {
            const int s = static_cast<int>(p[static_cast<std::size_t>(t.components) * index + static_cast<std::size_t>(c)]);
            return std::max(-1.0, (s >= 128 ? s - 256 : s) / 127.0);
        }
        case L::Storage::kRgb9e5: {
            std::uint32_t bits = 0;
            for (int b = 3; b >= 0; --b) bits = bits * 256 + p[4 * index + static_cast<std::size_t>(b)];
            const double m = static_cast<double>((bits >> (9 * c)) & 511u);
            return m * std::pow(2.0, static_cast<double>(bits >> 27) - 24.0);
        }
    }
    return 0;
}

// Slow twin of sample_sh3: hat weights prod_c max(0, 1 - |t_c - x_c|) over every texel (t clamped
// to the box), every component of every texture, then the layout's reconstruction.
void twin_sample(const zhc_volume& g, L::Layout l, const std::vector<std::vector<std::uint8_t>>& tex, const double p[3], double sh[27]) {
    const auto spec = L::layout_textures(l);
    double vals[L::kSlots] = {0};
    double t[3];
    for (int c = 0; c < 3; ++c) {
        t[c] = (p[c] - g.origin[c]) / g.spacing[c];
        t[c] = std::clamp(std::isnan(t[c]) ? 0.0 : t[c], 0.0, double(g.counts[c] - 1));
    }
    for (std::uint32_t z = 0; z < g.counts[2]; ++z)
        for (std::uint32_t y = 0; y < g.counts[1]; ++y)
            for (std::uint32_t x = 0; x < g.counts[0]; ++x) {
                const double w = std::max(0.0, 1 - std::fabs(t[0] - x)) * std::max(0.0, 1 - std::fabs(t[1] - y)) *
                                 std::max(0.0, 1 - std::fabs(t[2] - z));
                if (w == 0) continue;
                const std::size_t index = x + g.counts[0] * (y + std::size_t(g.counts[1]) * z);
                for (std::size_t s = 0; s < spec.size(); ++s)
                    for (int c = 0; c < spec[s].components; ++c) vals[4 * s + static_cast<std::size_t>(c)] += w * twin_texel(tex[s], spec[s], index, c);
            }
    L::reconstruct_sh3(l, vals, sh);
}

TEST(VolumeLayouts, FilterModelEqualsPerTexelTwin) {
    for (const Baked& b : {demo_grid(), random_grid()}) {
        OwnedVolume vol(b.probes, b.layout);
        const zhc_volume& g = vol.v;
        ASSERT_NE(g.probes, nullptr);
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> u(-0.25, 1.25);  // in and around the box
        for (L::Layout l : L::kAllLayouts) {
            const auto tex = L::volume_textures(g, l);
            const std::size_t count = std::size_t(g.counts[0]) * g.counts[1] * g.counts[2];
            ASSERT_EQ(tex.size(), L::layout_textures(l).size());
            std::size_t bytes = 0;
            for (const auto& t : tex) bytes += t.size();
            EXPECT_EQ(bytes, count * L::layout_bytes_per_probe(l)) << L::layout_name(l);
            double worst = 0, scale = 0;
            for (int s = 0; s < 2000; ++s) {
                double p[3];
                for (int c = 0; c < 3; ++c) p[c] = g.origin[c] + u(rng) * g.spacing[c] * std::max(1.0, double(g.counts[c] - 1));
                double a[27], t[27];
                L::sample_sh3(g, l, tex, p, a);
                twin_sample(g, l, tex, p, t);
                for (int j = 0; j < 27; ++j) {
                    worst = std::max(worst, std::fabs(a[j] - t[j]));
                    scale = std::max(scale, std::fabs(t[j]));
                }
            }
            EXPECT_GT(scale, 0) << L::layout_name(l);
            EXPECT_LE(worst, 1e-12 * scale) << L::layout_name(l);
        }
    }
}

TEST(VolumeLayouts, LinearLayoutsReconstructTheirCoefficientsBeforeRounding) {
    const Baked b = random_grid();
    for (const Sh3Radiance& sh : b.probes) {
        float f[27];
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) f[i * 3 + k] = sh[i][k];
        for (L::Layout l : {L::Layout::kSh3F32, L::Layout::kSh3F16, L::Layout::kSh2F16, L::Layout::kSh3Rgb9e5, L::Layout::kSh2Rgb9e5,
                            L::Layout::kRatio8}) {
            double v[L::kSlots], out[27];
            L::probe_values(l, f, v);
            L::reconstruct_sh3(l, v, out);
            const int n = (l == L::Layout::kSh2F16 || l == L::Layout::kSh2Rgb9e5) ? 12 : 27;
            for (int j = 0; j < 27; ++j) EXPECT_NEAR(out[j], j < n ? f[j] : 0.0, 1e-6 * std::fabs(f[0])) << L::layout_name(l) << " " << j;
            // Stored values of the RGB9_E5 layouts are >= 0 (non-negative radiance), ratio codes in [-1, 1].
            if (l == L::Layout::kSh3Rgb9e5 || l == L::Layout::kSh2Rgb9e5) {
                for (int j = 0; j < L::kSlots; ++j) EXPECT_GE(v[j], -1e-6 * f[0]);
            }
            if (l == L::Layout::kRatio8) {
                for (int j = 4; j < 28; ++j) EXPECT_LE(std::fabs(v[j]), 1 + 1e-9);
            }
        }
        // The luminance-L2 layouts are exact for grey probes.
        float grey[27];
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) grey[i * 3 + k] = sh[i][1];
        for (L::Layout l : {L::Layout::kSh2L2GreyF16, L::Layout::kSh2L2LumF16, L::Layout::kSh2Rgb9e5L2Lum}) {
            double v[L::kSlots], out[27];
            L::probe_values(l, grey, v);
            L::reconstruct_sh3(l, v, out);
            for (int j = 0; j < 27; ++j) EXPECT_NEAR(out[j], grey[j], 1e-6 * std::fabs(grey[0])) << L::layout_name(l) << " " << j;
        }
    }
}

TEST(VolumeLayouts, Float32AtlasReproducesVolumeIrradiance) {
    const Baked b = demo_grid();
    OwnedVolume vol(b.probes, b.layout);
    const auto tex = L::volume_textures(vol.v, L::Layout::kSh3F32);
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(-0.25, 1.25);
    std::normal_distribution<double> g;
    double worst = 0, mean = 0;
    const int n = 10000;
    for (int s = 0; s < n; ++s) {
        float p[3], nn[3], ref[3];
        double pd[3], nd[3], e[3];
        for (int c = 0; c < 3; ++c) {
            p[c] = static_cast<float>(vol.v.origin[c] + u(rng) * vol.v.spacing[c] * (vol.v.counts[c] - 1));
            nn[c] = static_cast<float>(g(rng));
            pd[c] = p[c];
            nd[c] = nn[c];
        }
        zhc_volume_irradiance(&vol.v, p, nn, ref);
        L::sample_irradiance(vol.v, L::Layout::kSh3F32, tex, pd, nd, e);
        for (int k = 0; k < 3; ++k) {
            worst = std::max(worst, std::fabs(e[k] - ref[k]));
            mean += std::fabs(ref[k]) / (3.0 * n);
        }
    }
    EXPECT_GT(mean, 0.1);
    EXPECT_LE(worst, 1e-6 * mean);
}

// Mean |dE| / mean |E_ref| of a layout over random points and normals, against the exact volume.
double mean_error(const zhc_volume& ref, L::Layout l) {
    const auto tex = L::volume_textures(ref, l);
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> u(0, 1);
    std::normal_distribution<double> g;
    double err = 0, mag = 0;
    for (int s = 0; s < 20000; ++s) {
        double p[3], n[3], a[3], e[3];
        for (int c = 0; c < 3; ++c) {
            p[c] = ref.origin[c] + u(rng) * ref.spacing[c] * (ref.counts[c] - 1);
            n[c] = g(rng);
        }
        zhc_volume_irradiance_d(&ref, p, n, a);
        L::sample_irradiance(ref, l, tex, p, n, e);
        err += std::sqrt((e[0] - a[0]) * (e[0] - a[0]) + (e[1] - a[1]) * (e[1] - a[1]) + (e[2] - a[2]) * (e[2] - a[2]));
        mag += std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    }
    return err / mag;
}

// The headline of docs/runtime.md's table: zhc's RGB9_E5 layouts beat three.js's half layouts
// (b) sh3_rgba16f, (c) sh2_rgba16f, (d) sh2_l2grey_rgba16f (and its luminance-scaled variant) in
// error per GPU byte.
TEST(VolumeLayouts, Rgb9e5LayoutsBeatTheHalfLayoutsPerByte) {
    for (const Baked& b : {demo_grid(), gltf_grid()}) {
        OwnedVolume vol(b.probes, b.layout);
        ASSERT_NE(vol.v.probes, nullptr);
        using LL = L::Layout;
        const double e_b = mean_error(vol.v, LL::kSh3F16), e_c = mean_error(vol.v, LL::kSh2F16), e_d = mean_error(vol.v, LL::kSh2L2GreyF16),
                     e_d_lum = mean_error(vol.v, LL::kSh2L2LumF16);
        const double e_full = mean_error(vol.v, LL::kSh3Rgb9e5), e_l1 = mean_error(vol.v, LL::kSh2Rgb9e5),
                     e_lum = mean_error(vol.v, LL::kSh2Rgb9e5L2Lum), e_ratio = mean_error(vol.v, LL::kRatio8);
        // Full colour L2 in 36 bytes: below (d)'s error at fewer bytes, within 0.5% of the exact volume,
        // and 0.64 of (b)'s bytes.
        EXPECT_LT(L::layout_bytes_per_probe(LL::kSh3Rgb9e5), L::layout_bytes_per_probe(LL::kSh2L2LumF16));
        EXPECT_LT(L::layout_bytes_per_probe(LL::kSh3Rgb9e5), L::layout_bytes_per_probe(LL::kSh3F16));
        EXPECT_LT(e_full, e_d);
        EXPECT_LT(e_full, e_d_lum);
        EXPECT_LT(e_full, 5e-3);
        EXPECT_LT(e_b, e_full);  // half floats are the more precise: (b) keeps its place at 56 bytes
        // The same error as (c) and (d) (within 25%) at 2/3 and 3/5 of their bytes.
        EXPECT_LT(L::layout_bytes_per_probe(LL::kSh2Rgb9e5), L::layout_bytes_per_probe(LL::kSh2F16));
        EXPECT_LT(L::layout_bytes_per_probe(LL::kSh2Rgb9e5L2Lum), L::layout_bytes_per_probe(LL::kSh2L2LumF16));
        EXPECT_LT(e_l1, 1.25 * e_c);
        // Within 25% of the better of the two 40-byte luminance-L2 half layouts (grey wins on the demo
        // grid, 0.047 vs 0.054; luminance-scaled on the glTF scene, 0.0037 vs 0.037).
        EXPECT_LT(e_lum, 1.25 * std::min(e_d, e_d_lum));
        // Filtering ratios is not filtering the SH: the 8-bit ratio layout is worse than RGB9_E5 at 32 bytes.
        EXPECT_GT(e_ratio, 3 * e_full);
    }
}

}  // namespace
