// GPU volume layouts on Mesa lavapipe (docs/runtime.md "GPU volume layouts"): every layout's HLSL
// sampling kernel (tests/vk/volume_kernels.h, the kernels bench_volume counts and times), compiled at
// run time by glslangValidator and run with its 3D textures in Vulkan images behind a linear
// clamp-to-edge sampler (packed rows: the stored words in a buffer), against the CPU model of
// runtime/zhc_volume_layouts.hpp (packed rows: zhc_volume_irradiance_d) at the same float inputs:
// 65,536 points in and around the demo's baked grid and a 5x1x3 grid (a count-1 axis), random normals.
// Bound: 1e-5 of the mean |E| (float shading of <= 27 terms and float filtering; measured max 2.2e-6).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "codec/bake/scene.h"
#include "codec/probe/probe_set.h"
#include "runtime/zhc_runtime.h"
#include "runtime/zhc_volume_layouts.hpp"
#include "support.h"
#include "tests/vk/volume_kernels.h"
#include "vk_compute.h"

namespace {

using namespace zhc;
namespace L = zhc_layouts;
namespace K = zhc_volume_kernels;

struct Grid {
    std::vector<Sh3Radiance> probes;
    ProbeLayout layout;
};

Grid demo_grid() {
    const Scene scene = default_scene();
    auto b = bake_scene(scene);
    EXPECT_TRUE(b.ok());
    return {b.ok() ? *b : std::vector<Sh3Radiance>{}, probe_layout(scene.probes)};
}

Grid small_grid() {
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(0, 1);
    Grid g;
    g.layout.kind = ProbeLayoutKind::kGrid;
    g.layout.grid.origin = Vec3{-1.0, 2.0, 0.5};
    g.layout.grid.spacing = Vec3{0.7, 1.3, 0.4};
    g.layout.grid.counts = {5, 1, 3};
    for (int i = 0; i < 15; ++i) {
        Sh3Radiance sh = project_constant(Rgb{float(0.3 * u(rng)), float(0.3 * u(rng)), float(0.3 * u(rng))});
        const double z = 2 * u(rng) - 1, phi = 6.283185307179586 * u(rng), r = std::sqrt(1 - z * z);
        sh = sh + project_directional(Vec3{r * std::cos(phi), r * std::sin(phi), z}, Rgb{float(4 * u(rng)), float(2 * u(rng)), float(u(rng))});
        g.probes.push_back(sh);
    }
    return g;
}

struct Encoded {
    std::vector<std::uint8_t> bytes;
    zhc_volume v{};
};

void encode(const Grid& g, const char* rep, Encoded* e) {
    auto set = encode_probe_set(g.probes, rep, CodecOptions{}, g.layout);
    ASSERT_TRUE(set.ok());
    e->bytes = set->payload;
    zhc_probe_format f;
    ASSERT_EQ(zhc_probe_format_init(&f, rep), ZHC_OK);
    const ProbeGrid& pg = g.layout.grid;
    const double o[3] = {pg.origin.x, pg.origin.y, pg.origin.z}, s[3] = {pg.spacing.x, pg.spacing.y, pg.spacing.z};
    const std::uint32_t n[3] = {pg.counts[0], pg.counts[1], pg.counts[2]};
    ASSERT_EQ(zhc_volume_init(&e->v, &f, e->bytes.data(), e->bytes.size(), o, s, n), ZHC_OK);
}

std::vector<std::uint32_t> compile(const std::string& dir, const std::string& name, const std::string& source) {
    const std::string hlsl = dir + "/" + name + ".hlsl", spv = dir + "/" + name + ".spv";
    test::write_bytes(hlsl, std::vector<std::uint8_t>(source.begin(), source.end()));
    const std::string cmd = std::string("'") + ZHC_GLSLANG + "' -D -V -S comp -e main '-I" + ZHC_RUNTIME_DIR + "' '" + hlsl + "' -o '" +
                            spv + "' > '" + dir + "/" + name + ".log' 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    return vk::read_spirv(spv);
}

TEST(VolumeLayoutsVk, EveryLayoutOnLavapipeEqualsTheCpuModel) {
    vk::force_icd(ZHC_LVP_ICD);
    std::string error;
    auto context = vk::Context::create(true, &error);
    ASSERT_TRUE(context) << error;
    const std::string dir = test::fresh_dir("volume_layouts_vk");
    constexpr std::uint32_t kSamples = 65536;
    int checked = 0;
    for (const Grid& g : {demo_grid(), small_grid()}) {
        Encoded ref;
        encode(g, "sh3", &ref);
        ASSERT_NE(ref.v.probes, nullptr);
        std::mt19937_64 rng(41);
        std::uniform_real_distribution<double> u(-0.25, 1.25);
        std::normal_distribution<double> gauss;
        std::vector<float> inputs(kSamples * 8);
        for (std::uint32_t i = 0; i < kSamples; ++i)
            for (int c = 0; c < 3; ++c) {
                inputs[8 * i + static_cast<std::uint32_t>(c)] =
                    static_cast<float>(ref.v.origin[c] + u(rng) * ref.v.spacing[c] * std::max(1.0, double(ref.v.counts[c] - 1)));
                inputs[8 * i + 4 + static_cast<std::uint32_t>(c)] = static_cast<float>(gauss(rng));
            }
        float grid_buf[12] = {};
        for (int c = 0; c < 3; ++c) {
            grid_buf[c] = static_cast<float>(ref.v.origin[c]);
            grid_buf[4 + c] = static_cast<float>(ref.v.spacing[c]);
            std::memcpy(&grid_buf[8 + c], &ref.v.counts[c], 4);
        }
        struct Case {
            std::string name;
            bool filtered;
            L::Layout layout;
        };
        std::vector<Case> cases = {{"zh3_q16", false, L::Layout::kSh3F32}, {"sh3_q28", false, L::Layout::kSh3F32}};
        for (L::Layout l : L::kAllLayouts) cases.push_back({L::layout_name(l), true, l});
        for (const Case& c : cases) {
            SCOPED_TRACE(c.name);
            Encoded packed;
            std::vector<std::vector<std::uint8_t>> tex;
            std::vector<vk::Image3D> images;
            std::string source;
            if (c.filtered) {
                tex = L::volume_textures(ref.v, c.layout);
                const auto spec = L::layout_textures(c.layout);
                for (std::size_t i = 0; i < spec.size(); ++i) {
                    VkFormat f = VK_FORMAT_E5B9G9R9_UFLOAT_PACK32;
                    if (spec[i].storage == L::Storage::kF32) f = VK_FORMAT_R32G32B32A32_SFLOAT;
                    if (spec[i].storage == L::Storage::kF16) f = VK_FORMAT_R16G16B16A16_SFLOAT;
                    if (spec[i].storage == L::Storage::kSnorm8) f = spec[i].components == 4 ? VK_FORMAT_R8G8B8A8_SNORM : VK_FORMAT_R8_SNORM;
                    images.push_back({static_cast<std::uint32_t>(f), ref.v.counts[0], ref.v.counts[1], ref.v.counts[2], tex[i]});
                }
                source = K::filter_kernel(c.layout);
            } else {
                encode(g, c.name.c_str(), &packed);
                source = K::packed_kernel(zhc_encoding_from_name(c.name.c_str()));
            }
            const auto spirv = compile(dir, c.name, source);
            ASSERT_FALSE(spirv.empty());
            const std::size_t sizes[4] = {std::max<std::size_t>(16, packed.bytes.size()), inputs.size() * 4, std::size_t(kSamples) * 16,
                                          sizeof grid_buf};
            auto kernel = context->make_kernel(spirv, sizes, images, &error);
            ASSERT_TRUE(kernel) << error;
            if (!packed.bytes.empty()) std::memcpy(kernel->data(0), packed.bytes.data(), packed.bytes.size());
            std::memcpy(kernel->data(1), inputs.data(), inputs.size() * 4);
            std::memcpy(kernel->data(3), grid_buf, sizeof grid_buf);
            ASSERT_GE(kernel->dispatch(kSamples / 64, &error), 0) << error;
            const float* out = reinterpret_cast<const float*>(kernel->data(2));
            double worst = 0, mean = 0;
            for (std::uint32_t i = 0; i < kSamples; ++i) {
                double p[3], n[3], e[3];
                for (int k = 0; k < 3; ++k) {
                    p[k] = inputs[8 * i + static_cast<std::uint32_t>(k)];
                    n[k] = inputs[8 * i + 4 + static_cast<std::uint32_t>(k)];
                }
                if (c.filtered) L::sample_irradiance(ref.v, c.layout, tex, p, n, e);
                else zhc_volume_irradiance_d(&packed.v, p, n, e);
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(out[4 * i + static_cast<std::uint32_t>(k)]));
                    worst = std::max(worst, std::fabs(out[4 * i + static_cast<std::uint32_t>(k)] - e[k]));
                    mean += std::fabs(e[k]) / (3.0 * kSamples);
                }
            }
            EXPECT_GT(mean, 0.01);
            EXPECT_LE(worst, 1e-5 * mean) << "max " << worst / mean << " of the mean";
            ++checked;
        }
    }
    EXPECT_EQ(checked, 2 * (2 + static_cast<int>(std::size(L::kAllLayouts))));
}

}  // namespace
