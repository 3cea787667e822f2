// runtime/zhc.hlsl on Vulkan (Mesa lavapipe, headless) against the C++ codec.
//
// The test kernel tests/vk/runtime_test.hlsl (#include "zhc.hlsl") is compiled to SPIR-V at build
// time by glslangValidator's HLSL front end (tests/vk/CMakeLists.txt) and dispatched once per
// encoding and format on lavapipe (the CPU Vulkan driver; the test forces its ICD and checks the
// device name). For every item the kernel writes the decoded SH3 radiance (zhc_decode_sh3) and the
// irradiance at a normal straight from the words (zhc_irradiance); the C++ reference is
// decode_probe and the codec table's irradiance (or irradiance(decode_probe) for non-default
// formats, where the table's irradiance does not apply).
//
// Error bound (float against double). The C++ decoders compute in double from the stored floats and
// bytes and round the result to float; the shader does the same operations in float. Each output
// of channel k is a short chain (<= ~20 operations: a ratio decode t * scale + offset, the product
// with the DC, a normalisation, a 9-term sum) over terms whose magnitudes are bounded by
//   T_k = sum_i |c_ik| + P_k + kappa * Z_k,
// c the decoded radiance coefficients of channel k, P_k = 8 sqrt(5) |DC_k| / s for the quantised
// layouts (the affine ratio map adds an offset of up to sqrt(5) |DC| that cancels: the absolute
// error is relative to it, not to the coefficient; s = the stored-kind L2 scale), and kappa * Z_k the
// zonal part whose axis comes from the luminance-weighted L1: its direction is computed from
// sum_j w_j v_j, which loses relative precision kappa = sum_j w_j |v_j| / |sum_j w_j v_j| when the
// channels cancel (kappa = 1 for per-channel axes); Z_k = |L1_k| + |L2_k|. Standard forward error
// analysis gives |error| <= n u T_k with u = 2^-24 per basic operation (add/mul/fma correctly
// rounded) and n the depth; Vulkan allows 2.5 ulp for division and 2 ulp for inverse sqrt, so with
// n <= ~25 operations and those wider ops the bound is 64 u T_k = 32 FLT_EPSILON T_k. Plus an
// absolute 1e-35 for results lavapipe may flush below FLT_MIN (Vulkan permits flushing denormals).
// Non-finite results (random bytes with an Inf/NaN DC) must be non-finite on both sides.
// Random float words are drawn with |value| in [2^-60, 2^60]: outside that, products and squares
// leave float's normal range where the double reference does not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/lightmap/irradz.h"
#include "codec/lightmap/lightmap.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "codec/probe/zh3.h"
#include "support.h"
#include "vk_compute.h"
#include "tetra_gpu_cases.h"
#include "volume_planes_cases.h"
#include "zhc_runtime.h"
#include "zhc_runtime_params.hpp"

namespace zhc {
namespace {

using vk::hlsl_encoding;
using vk::hlsl_encoding_count;

constexpr double kBoundEps = 32.0 * FLT_EPSILON;  // 64 u, see the header comment
constexpr double kFlushFloor = 1e-35;
constexpr std::size_t kOutFloats = 32;

std::uint32_t float_bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}
float bits_float(std::uint32_t u) {
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}

// One lavapipe device and the test kernel for the whole test program.
class Gpu {
public:
    static Gpu& get() {
        static Gpu g;
        return g;
    }
    bool ok() const { return context_ != nullptr; }
    const std::string& error() const { return error_; }
    const std::string& device_name() const { return context_->device_name(); }
    // Runs the kernel over `count` <= kCapacity items; returns kOutFloats floats per item (empty on
    // failure). One pipeline and one set of buffers serve every call (pipeline creation is the slow part).
    static constexpr std::size_t kCapacity = 1u << 17;
    // params: 16 uints, or 32 for the probe-volume mode (grid in params 16..24).
    // variant: the build of runtime_test.hlsl: kMasked ZHC_VOLUME_MASK (runtime_test_masked.spv; masks
    // at word params[25]), kPlanes ZHC_VOLUME_MASK and ZHC_VOLUME_PLANE (runtime_test_planes.spv;
    // plane entries at word params[26]), kPlanesGltf ZHC_VOLUME_PLANE alone with
    // ZHC_VOLUME_PLANE_AXES_GLTF (runtime_test_planes_gltf.spv).
    enum Variant { kPlain, kMasked, kPlanes, kPlanesGltf, kVariants };
    std::vector<float> run(const std::uint32_t* params, const std::vector<std::uint32_t>& words,
                           const std::vector<float>& normals4, std::size_t count, Variant variant = kPlain) {
        std::string err;
        std::unique_ptr<vk::Kernel>& kernel_ = kernels_[variant];
        if (!kernel_) {
            const std::size_t sizes[4] = {32 * 4, kCapacity * 27 * 4, kCapacity * 16, kCapacity * kOutFloats * 4};
            kernel_ = context_->make_kernel(spirv_[variant], sizes, &err);
            if (!kernel_) {
                ADD_FAILURE() << err;
                return {};
            }
        }
        if (count > kCapacity || words.size() > kCapacity * 27 || normals4.size() < count * 4 ||
            normals4.size() > kCapacity * 4) {
            ADD_FAILURE() << "batch too large: " << count;
            return {};
        }
        std::memcpy(kernel_->data(0), params, (params[15] == 3u ? 32 : 16) * 4);
        if (!words.empty()) std::memcpy(kernel_->data(1), words.data(), words.size() * 4);
        std::memcpy(kernel_->data(2), normals4.data(), normals4.size() * 4);  // the volume mode: 2 float4 per item
        if (kernel_->dispatch(static_cast<std::uint32_t>((count + 63) / 64), &err) < 0) {
            ADD_FAILURE() << err;
            return {};
        }
        std::vector<float> out(count * kOutFloats);
        std::memcpy(out.data(), kernel_->data(3), out.size() * 4);
        return out;
    }

private:
    Gpu() {
        vk::force_icd(ZHC_LVP_ICD);
        const char* paths[kVariants] = {ZHC_RUNTIME_TEST_SPV, ZHC_RUNTIME_TEST_MASKED_SPV, ZHC_RUNTIME_TEST_PLANES_SPV,
                                        ZHC_RUNTIME_TEST_PLANES_GLTF_SPV};
        for (int v = 0; v < kVariants; ++v) {
            spirv_[v] = vk::read_spirv(paths[v]);
            if (spirv_[v].empty()) {
                error_ = std::string("cannot read ") + paths[v];
                return;
            }
        }
        context_ = vk::Context::create(true, &error_);
    }
    std::vector<std::uint32_t> spirv_[kVariants];
    std::unique_ptr<vk::Context> context_;
    std::unique_ptr<vk::Kernel> kernels_[kVariants];  // destroyed before context_ (declared after it)
    std::string error_;
};

// ---- probe sources -------------------------------------------------------------------------------

Vec3 random_direction(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    return test::uniform_direction(u(rng), u(rng));
}

// Ambient plus 1..4 coloured lights (directional or cone), random directions and strengths.
Sh3Radiance random_lights(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto colour = [&](double scale) {
        return Rgb{static_cast<float>(scale * u(rng)), static_cast<float>(scale * u(rng)), static_cast<float>(scale * u(rng))};
    };
    const double level = std::exp2(12.0 * u(rng) - 6.0);
    Sh3Radiance sh = project_constant(colour(0.3 * level * u(rng)));
    const int lights = 1 + static_cast<int>(u(rng) * 4);
    for (int i = 0; i < lights; ++i) {
        if (u(rng) < 0.5) sh = sh + project_directional(random_direction(rng), colour(10.0 * level));
        else sh = sh + project_cone(random_direction(rng), 0.05 + 1.5 * u(rng), colour(level));
    }
    return sh;
}

// Random SH (not necessarily a non-negative function): the clamping paths of the quantisers.
Sh3Radiance random_sh(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double scale = std::exp2(8.0 * u(rng));
    Sh3Radiance sh;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) sh[i][k] = static_cast<float>(scale * u(rng) * (i == 0 ? 2.0 : 1.0));
    return sh;
}

const std::vector<Sh3Radiance>& envmap_probes() {
    static const std::vector<Sh3Radiance> probes = [] {
        std::vector<Sh3Radiance> out;
        for (const std::string& path : test::envmap_paths()) {
            const Image img = test::load_envmap(path);
            out.push_back(project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2));
        }
        return out;
    }();
    return probes;
}

Sh3Radiance random_envmap(std::mt19937_64& rng) {
    const auto& maps = envmap_probes();
    if (maps.empty()) {  // load_envmap has already failed the test; keep going without dividing by 0
        ADD_FAILURE() << "no sample maps";
        return random_lights(rng);
    }
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Sh3Radiance& base = maps[static_cast<size_t>(u(rng) * maps.size()) % maps.size()];
    return rotate(base, rotation_axis_angle(random_direction(rng), 2.0 * kPi * u(rng)));
}

// Arbitrary bytes for the quantised layouts; for float layouts finite floats of random sign with
// |v| in [2^-60, 2^60] (log-uniform) or exactly 0.
void random_bytes(std::mt19937_64& rng, bool float_layout, std::uint8_t* out, std::size_t size) {
    if (!float_layout) {
        for (std::size_t i = 0; i < size; ++i) out[i] = static_cast<std::uint8_t>(rng());
        return;
    }
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i + 4 <= size; i += 4) {
        float v = 0.0f;
        if (u(rng) > 0.02) v = static_cast<float>((u(rng) < 0.5 ? -1.0 : 1.0) * std::exp2(120.0 * u(rng) - 60.0));
        const std::uint32_t b = float_bits(v);
        for (int j = 0; j < 4; ++j) out[i + static_cast<size_t>(j)] = static_cast<std::uint8_t>(b >> (8 * j));
    }
}

bool is_packed(std::string_view name) {
    PackedLayout layout;
    return packed_layout_from_name(name, &layout);
}
// Whether the decoded zonal term uses the luminance axis (CodecTraits::zonal_axis).
bool lum_axis(const Codec& codec, const CodecOptions& p) {
    switch (codec.traits.zonal_axis) {
        case ZonalAxis::kLuminance: return true;
        case ZonalAxis::kFromParams: return p.axis_mode == ZonalAxisMode::kLuminance;
        case ZonalAxis::kNone:
        case ZonalAxis::kPerChannel: break;
    }
    return false;
}
bool is_default(const CodecOptions& p) {
    const CodecOptions d;
    return p.bits == d.bits && p.sqrt_encoding == d.sqrt_encoding && p.l2_bound == d.l2_bound &&
           p.dc_format == d.dc_format && p.kind == d.kind && p.zonal_mapping == d.zonal_mapping &&
           p.axis_mode == d.axis_mode && p.luminance.r == d.luminance.r && p.luminance.g == d.luminance.g &&
           p.luminance.b == d.luminance.b;
}

// Per-encoding results.
struct Stats {
    std::size_t items = 0, nonfinite = 0, ill_conditioned = 0, failures = 0;
    double max_rel = 0;       // max error / (eps T): how much of the bound was used (x 32)
    double max_abs_irr = 0;   // max |irradiance error|
    double max_rel_irr = 0;   // max |irradiance error| / |E| over the encoded probes (not random bytes)
                              // where E >= 1% of the channel's DC irradiance kY00 |c0|
    std::string first_failure;
};

struct Case {
    std::string label;
    CodecOptions params;
    std::vector<std::uint8_t> bytes;  // count * size
    std::vector<float> normals;       // count * 4
    std::size_t count = 0;
    bool encoded = true;              // false: random bytes
};

// The per-channel scale T_k of a decoded probe d (see the file comment) and the axis condition
// number kappa (infinite: ill-conditioned, T not finite).
void probe_scales(const Codec& codec, const CodecOptions& p, const Sh3Radiance& d, double t[3], double* kappa_out) {
    const bool packed = is_packed(codec.name);
    double kappa = 1.0;
    if (lum_axis(codec, p)) {
        double num = 0;
        Vec3 sum{};
        const double w[3] = {p.luminance.r, p.luminance.g, p.luminance.b};
        for (int k = 0; k < 3; ++k) {
            const Vec3 v{-double(d[3][k]), -double(d[1][k]), double(d[2][k])};
            num += std::fabs(w[k]) * length(v);
            sum = sum + w[k] * v;
        }
        const double den = length(sum);
        if (num > 0) kappa = den > 0 ? num / den : INFINITY;
    }
    // The stored DC (decode_probe returns radiance; DC is band 0, unscaled).
    for (int k = 0; k < 3; ++k) {
        double s = 0, z = 0;
        for (int i = 0; i < 9; ++i) {
            s += std::fabs(double(d[i][k]));
            if (i > 0) z += std::fabs(double(d[i][k]));
        }
        const double l2s = p.kind == StoredKind::kIrradiance ? 4.0 : 1.0;
        t[k] = s + (packed ? 8.0 * std::sqrt(5.0) * std::fabs(double(d[0][k])) * l2s : 0.0) + kappa * z;
    }
    *kappa_out = kappa;
}

// Compares one item; returns false (with a message) on a bound violation.
bool compare_item(const Codec& codec, const CodecOptions& p, const std::uint8_t* bytes, Vec3 n, const float* gpu,
                  bool encoded, Stats* st, std::string* msg) {
    const Sh3Radiance d = decode_probe(codec, p, bytes);
    Rgb e;
    if (is_default(p)) e = codec.irradiance(bytes, p, n);
    else e = irradiance(d, n);
    // Per-channel scale T_k.
    double t[3], kappa = 1.0;
    probe_scales(codec, p, d, t, &kappa);
    bool any_nonfinite_ref = false;
    for (int k = 0; k < 3; ++k)
        if (!std::isfinite(t[k])) any_nonfinite_ref = true;
    ++st->items;
    if (any_nonfinite_ref) {
        if (std::isinf(kappa)) ++st->ill_conditioned;
        else ++st->nonfinite;
    }
    auto check = [&](double ref, double got, int k, const char* what, int idx) {
        if (!std::isfinite(ref)) {
            if (std::isfinite(got)) {
                *msg = std::string(what) + "[" + std::to_string(idx) + "] channel " + std::to_string(k) +
                       ": reference non-finite, shader " + std::to_string(got);
                return false;
            }
            return true;
        }
        if (!std::isfinite(t[k])) return true;  // ill-conditioned axis (kappa infinite): no bound
        const double bound = kBoundEps * t[k] + kFlushFloor;
        const double err = std::fabs(got - ref);
        if (!(err <= bound)) {
            char buf[256];
            std::snprintf(buf, sizeof buf, "%s[%d] channel %d: shader %.9g, C++ %.9g, error %.3g > bound %.3g (T %.3g, kappa %.3g)",
                          what, idx, k, got, ref, err, bound, t[k], kappa);
            *msg = buf;
            return false;
        }
        st->max_rel = std::max(st->max_rel, err / (FLT_EPSILON * t[k] + kFlushFloor));
        return true;
    };
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            if (!check(d[i][k], gpu[3 * i + k], k, "sh", i)) return false;
    for (int k = 0; k < 3; ++k) {
        if (!check(e[k], gpu[27 + k], k, "irradiance", 0)) return false;
        if (std::isfinite(e[k]) && std::isfinite(t[k])) {
            const double err = std::fabs(double(gpu[27 + k]) - e[k]);
            st->max_abs_irr = std::max(st->max_abs_irr, err);
            if (encoded && std::fabs(e[k]) >= 0.01 * kY00 * std::fabs(double(d[0][k])) && e[k] != 0)
                st->max_rel_irr = std::max(st->max_rel_irr, err / std::fabs(e[k]));
        }
    }
    return true;
}

void run_case(const Codec& codec, const Case& c, Stats* st) {
    const int id = hlsl_encoding(codec.name);
    ASSERT_GE(id, 0);
    const CodecOptions& p = c.params;
    std::uint32_t params[16] = {static_cast<std::uint32_t>(id),
                                static_cast<std::uint32_t>(p.bits),
                                p.sqrt_encoding ? 1u : 0u,
                                static_cast<std::uint32_t>(p.l2_bound),
                                static_cast<std::uint32_t>(p.dc_format),
                                static_cast<std::uint32_t>(p.zonal_mapping),
                                static_cast<std::uint32_t>(p.axis_mode),
                                static_cast<std::uint32_t>(p.kind),
                                float_bits(static_cast<float>(p.luminance.r)),
                                float_bits(static_cast<float>(p.luminance.g)),
                                float_bits(static_cast<float>(p.luminance.b)),
                                float_bits(static_cast<float>(CodecOptions{}.hallucinate_a)),
                                float_bits(static_cast<float>(CodecOptions{}.hallucinate_b)),
                                static_cast<std::uint32_t>(c.count),
                                static_cast<std::uint32_t>(codec.size_bytes / 4),
                                0u};
    ASSERT_EQ(codec.size_bytes % 4, 0u);
    std::vector<std::uint32_t> words(c.bytes.size() / 4);
    for (std::size_t i = 0; i < words.size(); ++i)
        words[i] = std::uint32_t(c.bytes[4 * i]) | std::uint32_t(c.bytes[4 * i + 1]) << 8 |
                   std::uint32_t(c.bytes[4 * i + 2]) << 16 | std::uint32_t(c.bytes[4 * i + 3]) << 24;
    const std::vector<float> out = Gpu::get().run(params, words, c.normals, c.count);
    ASSERT_EQ(out.size(), c.count * kOutFloats);
    for (std::size_t i = 0; i < c.count; ++i) {
        const Vec3 n{c.normals[4 * i], c.normals[4 * i + 1], c.normals[4 * i + 2]};
        std::string msg;
        if (!compare_item(codec, p, c.bytes.data() + i * codec.size_bytes, n, out.data() + i * kOutFloats, c.encoded, st, &msg)) {
            if (st->failures++ == 0) st->first_failure = c.label + " item " + std::to_string(i) + ": " + msg;
        }
    }
}

void add_normal(std::mt19937_64& rng, std::vector<float>* normals) {
    const Vec3 n = random_direction(rng);
    normals->insert(normals->end(), {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z), 0.0f});
}

// `count` probes of one source, encoded with `p` (sources: 0 lights, 1 random SH, 2 envmaps,
// 3 random bytes).
Case make_case(const Codec& codec, const CodecOptions& p, int source, std::size_t count, std::uint64_t seed) {
    static const char* const kSources[] = {"lights", "random SH", "envmaps", "random bytes"};
    Case c;
    c.label = std::string(codec.name) + " / " + kSources[source];
    c.params = p;
    c.count = count;
    c.encoded = source != 3;
    c.bytes.resize(count * codec.size_bytes);
    std::mt19937_64 rng(seed);
    for (std::size_t i = 0; i < count; ++i) {
        std::uint8_t* out = c.bytes.data() + i * codec.size_bytes;
        if (source == 3) {
            random_bytes(rng, !is_packed(codec.name), out, codec.size_bytes);
        } else {
            const Sh3Radiance hub = source == 0 ? random_lights(rng) : (source == 1 ? random_sh(rng) : random_envmap(rng));
            encode_probe(codec, p, hub, out, nullptr);
        }
        add_normal(rng, &c.normals);
    }
    return c;
}

std::map<std::string, Stats>& results() {
    static std::map<std::string, Stats> r;
    return r;
}

class RuntimeVk : public ::testing::Test {
protected:
    void SetUp() override {
        Gpu& g = Gpu::get();
        ASSERT_TRUE(g.ok()) << "Vulkan (lavapipe) unavailable: " << g.error();
    }
};

TEST_F(RuntimeVk, RunsOnLavapipe) {
    const std::string name = Gpu::get().device_name();
    std::printf("Vulkan device: %s\n", name.c_str());
    EXPECT_NE(name.find("llvmpipe"), std::string::npos) << name;
}

TEST(RuntimeVkTable, EveryCodecHasAnHlslEncoding) {
    // The ids are the table's order (zhc_runtime.h's enum too): an entry's id never changes.
    // runtime_codecs(): the table without the engine layouts, which no zhc runtime reads (codec.h).
    const auto table = runtime_codecs();
    for (std::size_t i = 0; i < table.size(); ++i)
        EXPECT_EQ(hlsl_encoding(table[i].name), static_cast<int>(i))
            << table[i].name << ": no ZHC_" << table[i].name << " (in upper case) with its table index in runtime/zhc.hlsl";
    EXPECT_EQ(hlsl_encoding_count(), static_cast<int>(table.size()));
}

// >= 100,000 probes per encoding with the codec table's defaults: 30k lights, 20k random SH, 30k
// sample maps under random rotations, 20k random bytes.
TEST_F(RuntimeVk, EveryEncodingMatchesTheCodec) {
    const std::size_t counts[4] = {std::size_t(test::sample_count(30000)), std::size_t(test::sample_count(20000)),
                                   std::size_t(test::sample_count(30000)), std::size_t(test::sample_count(20000))};
    std::printf("%-22s %8s %10s %12s %9s %9s\n", "encoding", "items", "err/epsT", "max|dE|/E", "nonfinite", "ill-cond");
    for (const Codec& codec : runtime_codecs()) {
        Stats st;
        for (int source = 0; source < 4; ++source) {
            const Case c = make_case(codec, CodecOptions{}, source, counts[source], 1000u * static_cast<unsigned>(source) + 17u);
            run_case(codec, c, &st);
        }
        std::printf("%-22s %8zu %10.3f %12.3g %9zu %9zu\n", std::string(codec.name).c_str(), st.items, st.max_rel,
                    st.max_rel_irr, st.nonfinite, st.ill_conditioned);
        EXPECT_GE(st.items, std::size_t(test::sample_count(100000)));
        EXPECT_EQ(st.failures, 0u) << st.failures << " items out of bound; first: " << st.first_failure;
        EXPECT_LE(st.ill_conditioned, st.items / 1000) << codec.name;
        results()[std::string(codec.name)] = st;
    }
}

// The format fields the probe container stores: bits 2..8, sqrt encoding, L2 bound, DC format,
// zonal mapping, axis mode, stored kind, luminance weights; every quantised layout, and the stored
// kind / luminance weights for the float layouts too.
TEST_F(RuntimeVk, EveryFormatMatchesTheCodec) {
    std::vector<CodecOptions> variants;
    std::mt19937_64 rng(99);
    for (int bits = 2; bits <= 8; ++bits)
        for (int sq = 0; sq < 2; ++sq) {
            CodecOptions p;
            p.bits = bits;
            p.sqrt_encoding = sq != 0;
            p.l2_bound = static_cast<L2Bound>(rng() % 2);
            p.dc_format = static_cast<DcFormat>(rng() % 3);
            p.zonal_mapping = static_cast<ZonalMapping>(rng() % 3);
            p.axis_mode = static_cast<ZonalAxisMode>(rng() % 2);
            p.kind = static_cast<StoredKind>(rng() % 2);
            if (rng() % 3 == 0) p.luminance = {0.3, 0.59, 0.11};
            variants.push_back(p);
        }
    for (int dc = 0; dc < 3; ++dc)
        for (int zm = 0; zm < 3; ++zm)
            for (int kind = 0; kind < 2; ++kind) {
                CodecOptions p;
                p.dc_format = static_cast<DcFormat>(dc);
                p.zonal_mapping = static_cast<ZonalMapping>(zm);
                p.kind = static_cast<StoredKind>(kind);
                p.axis_mode = static_cast<ZonalAxisMode>(zm % 2);
                p.l2_bound = static_cast<L2Bound>(kind);
                variants.push_back(p);
            }
    std::size_t total = 0;
    for (const Codec& codec : runtime_codecs()) {
        Stats st;
        int v = 0;
        for (CodecOptions p : variants) {
            ++v;
            if (!is_packed(codec.name) && (p.bits != 8 || p.sqrt_encoding)) continue;  // only kind / weights apply
            if (!validate_quant_params(p, codec.name)) p.dc_format = DcFormat::kRGB9E5;  // half needs sh2_q's slot
            for (int source = 0; source < 4; ++source) {
                if (source == 2 && !is_packed(codec.name)) continue;
                const Case c = make_case(codec, p, source, 1500, 7919u * static_cast<unsigned>(v) + static_cast<unsigned>(source));
                run_case(codec, c, &st);
            }
        }
        total += st.items;
        std::printf("%-22s %8zu items over the formats, err/epsT %.3f, max|dE|/E %.3g\n", std::string(codec.name).c_str(),
                    st.items, st.max_rel, st.max_rel_irr);
        EXPECT_EQ(st.failures, 0u) << st.failures << " items out of bound; first: " << st.first_failure;
        EXPECT_LE(st.ill_conditioned, st.items / 1000) << codec.name;
    }
    EXPECT_GT(total, 0u);
}

// Known values of the integer DC unpacking, through the shader: a zh3_q16 probe with ratio codes
// all at t = 0 decodes to exactly its DC (radiance kind), so the SH3 DC equals the unpacked triple.
TEST_F(RuntimeVk, DcUnpackingIsExact) {
    const Codec* codec = find_codec("sh2_q");
    ASSERT_NE(codec, nullptr);
    std::mt19937_64 rng(5);
    for (int f = 0; f < 3; ++f) {
        Case c;
        c.label = "dc";
        c.params.dc_format = static_cast<DcFormat>(f);
        c.count = 4096;
        c.bytes.resize(c.count * 16);
        for (std::size_t i = 0; i < c.count; ++i) {
            std::uint8_t* b = c.bytes.data() + i * 16;
            for (int j = 0; j < 16; ++j) b[j] = static_cast<std::uint8_t>(rng());
            if (i < 2048) {  // every exponent / mantissa pattern of channel 0's low bits appears
                b[0] = static_cast<std::uint8_t>(i);
                b[1] = static_cast<std::uint8_t>((b[1] & 0xF8) | ((i >> 8) & 7));
            }
            for (int j = 6; j < 15; ++j) b[j] = 127;  // bv: ratio 0
        }
        for (std::size_t i = 0; i < c.count; ++i) add_normal(rng, &c.normals);
        Stats st;
        run_case(*codec, c, &st);
        EXPECT_EQ(st.failures, 0u) << st.first_failure;
        // Exactness: recompute the DC on the CPU and compare bit for bit (finite values).
        std::uint32_t params[16] = {static_cast<std::uint32_t>(hlsl_encoding("sh2_q")), 8, 0, 0, static_cast<std::uint32_t>(f),
                                    0, 0, 0, float_bits(0.2126f), float_bits(0.7152f), float_bits(0.0722f),
                                    float_bits(0.6f), float_bits(0.08f), static_cast<std::uint32_t>(c.count), 4u, 0u};
        std::vector<std::uint32_t> words(c.count * 4);
        std::memcpy(words.data(), c.bytes.data(), c.bytes.size());  // little-endian host (x86-64, the test platform)
        const std::vector<float> out = Gpu::get().run(params, words, c.normals, c.count);
        ASSERT_EQ(out.size(), c.count * kOutFloats);
        std::size_t mismatches = 0;
        for (std::size_t i = 0; i < c.count; ++i) {
            const Rgb dc = load_dc(c.bytes.data() + i * 16, static_cast<DcFormat>(f));
            for (int k = 0; k < 3; ++k) {
                const float g = out[i * kOutFloats + static_cast<size_t>(k)];
                if (std::isnan(dc[k]) ? !std::isnan(g) : float_bits(g) != float_bits(dc[k])) ++mismatches;
            }
        }
        EXPECT_EQ(mismatches, 0u) << "DC format " << f;
    }
}

// IrradZ lightmaps: the three textures' decoded values -> irradiance, both models, against
// lightmap::decode_hemioct + irradz::evaluate.
TEST_F(RuntimeVk, IrradzMatchesTheCodec) {
    std::mt19937_64 rng(4242);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::size_t count = 100000;
    for (int model = 0; model < 2; ++model) {
        std::vector<std::uint32_t> words(count * 6);
        std::vector<float> normals;
        for (std::size_t i = 0; i < count; ++i) {
            const double level = std::exp2(16.0 * u(rng) - 8.0);
            const float v[6] = {static_cast<float>(level * u(rng)), static_cast<float>(level * u(rng)),
                                static_cast<float>(level * u(rng)), static_cast<float>(1.2 * u(rng) - 0.1),
                                static_cast<float>(1.1 * u(rng) - 0.05), static_cast<float>(1.1 * u(rng) - 0.05)};
            for (int j = 0; j < 6; ++j) words[6 * i + static_cast<size_t>(j)] = float_bits(v[j]);
            Vec3 n = random_direction(rng);
            if (i % 4 != 0) n.z = std::fabs(n.z);  // mostly the upper hemisphere
            normals.insert(normals.end(), {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z), 0.0f});
        }
        std::uint32_t params[16] = {};
        params[13] = static_cast<std::uint32_t>(count);
        params[14] = 6;
        params[15] = model == 0 ? 1u : 2u;
        const std::vector<float> out = Gpu::get().run(params, words, normals, count);
        ASSERT_EQ(out.size(), count * kOutFloats);
        double max_rel = 0;
        std::size_t failures = 0;
        std::string first;
        for (std::size_t i = 0; i < count; ++i) {
            irradz::IrradZ p;
            p.i_z = Rgb{bits_float(words[6 * i]), bits_float(words[6 * i + 1]), bits_float(words[6 * i + 2])};
            p.w_a = bits_float(words[6 * i + 3]);
            p.d = lightmap::decode_hemioct(bits_float(words[6 * i + 4]), bits_float(words[6 * i + 5]));
            const Vec3 n{normals[4 * i], normals[4 * i + 1], normals[4 * i + 2]};
            const irradz::Model m = model == 0 ? irradz::Model::kHhd : irradz::Model::kAhd;
            const Rgb e = irradz::evaluate(p, m, n);
            const irradz::Lighting l = irradz::to_lighting(p);
            for (int k = 0; k < 3; ++k) {
                // Terms: C_a h and C_d max(0, n.d), each a few operations deep. C_d = (1 - w_a) I_z / d_z
                // carries d_z's rounding relative to d_z: d is a unit vector (absolute error ~2 ulp
                // of 1) with d_z >= cos 85 deg = 0.087, so up to ~11.5 x 2 eps relative; with the
                // rest of the chain that stays below 32 eps T (measured: ~10).
                const double t = std::fabs(double(l.c_a[k])) + std::fabs(double(l.c_d[k]));
                const double err = std::fabs(double(out[i * kOutFloats + 27 + static_cast<size_t>(k)]) - e[k]);
                const double bound = kBoundEps * t + kFlushFloor;
                if (!(err <= bound) && failures++ == 0)
                    first = "texel " + std::to_string(i) + " channel " + std::to_string(k) + ": shader " +
                            std::to_string(out[i * kOutFloats + 27 + static_cast<size_t>(k)]) + " C++ " + std::to_string(e[k]);
                if (t > 0) max_rel = std::max(max_rel, err / (FLT_EPSILON * t));
            }
        }
        std::printf("irradz %s: %zu texels, max error / (eps T) = %.3f\n", model == 0 ? "HHD" : "AHD", count, max_rel);
        EXPECT_EQ(failures, 0u) << first;
    }
}


// The ASTC LDR fallback's range decode (zhc_irradz_iz_from_ldr, mode 4) against lightmap::iz_from_ldr
// on ranges of 1 to 16 stops in [-14, 16]: the bound of RuntimeGl.AstcLdrRangeDecodeMatchesTheCodec,
// |gpu - codec| <= 8 u (3 + 3 |x|) (2^x + 2^lo), x = lo + t (hi - lo) (exp2's error grows with |x|).
TEST_F(RuntimeVk, AstcLdrRangeDecodeMatchesTheCodec) {
    std::mt19937_64 rng(0xA57C2);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::size_t count = 100000;
    std::vector<std::uint32_t> words(count * 5);
    std::vector<float> normals(count * 4, 0.0f);
    for (std::size_t i = 0; i < count; ++i) {
        const float lo = static_cast<float>(-14 + 29 * u(rng)), hi = static_cast<float>(lo + 1 + 15 * u(rng) * u(rng));
        const float v[5] = {static_cast<float>(u(rng)), static_cast<float>(i % 9 == 0 ? 0.0 : u(rng)),
                            static_cast<float>(i % 11 == 0 ? 1.0 : u(rng)), lo, hi};
        for (int j = 0; j < 5; ++j) words[5 * i + static_cast<size_t>(j)] = float_bits(v[j]);
    }
    std::uint32_t params[16] = {};
    params[13] = static_cast<std::uint32_t>(count);
    params[14] = 5;
    params[15] = 4;
    const std::vector<float> out = Gpu::get().run(params, words, normals, count);
    ASSERT_EQ(out.size(), count * kOutFloats);
    double worst = 0;
    std::size_t failures = 0;
    std::string first;
    for (std::size_t i = 0; i < count; ++i) {
        const lightmap::IzLogRange r{bits_float(words[5 * i + 3]), bits_float(words[5 * i + 4])};
        for (int k = 0; k < 3; ++k) {
            const float t = bits_float(words[5 * i + static_cast<size_t>(k)]);
            const double ref = lightmap::iz_from_ldr(t, r), g = out[i * kOutFloats + 27 + static_cast<size_t>(k)];
            const double x = double(r.lo) + double(t) * (double(r.hi) - double(r.lo));
            const double scale = (FLT_EPSILON / 2) * (3 + 3 * std::fabs(x)) * (std::exp2(x) + std::exp2(double(r.lo)));
            worst = std::max(worst, std::fabs(g - ref) / scale);
            if (!(std::fabs(g - ref) <= 8 * scale) && failures++ == 0)
                first = "item " + std::to_string(i) + " channel " + std::to_string(k) + ": shader " + std::to_string(g) + " C++ " + std::to_string(ref);
        }
    }
    std::printf("ASTC LDR range decode (HLSL): %zu items, max error %.3f x u (3 + 3|x|) (2^x + 2^lo) (bound 8)\n", count, worst);
    EXPECT_EQ(failures, 0u) << first;
}

// Probe volumes (zhc_volume_irradiance, mode 3) against the C header's zhc_volume_irradiance_d:
// every codec table entry, a 6x5x4 grid (default parameters) and a 5x1x3 grid (irradiance storage;
// packed: 5 bits, sqrt, RGB9E5, per-channel axes, zero-preserving) of probes (lights, random SH,
// sample maps), 10,000 points in and around the grid's box plus every probe position, random
// normals. Bound: each corner's decode and the evaluation 32 eps T (the bound of the single-probe
// comparisons, T summed over the cell's 8 corners), the 8-term blend 8 eps T, and the weights:
// t = (p - o) / s in float is off by ~ ((|p| + |o|) / s + t) u per axis, moving each weight by up
// to 3 times that: 1.5 eps T per unit of sum_axes ((|p| + |o|) / s + t + 2).
TEST_F(RuntimeVk, ProbeVolumesMatchTheCHeader) {
    const int samples = int(test::sample_count(10000));
    std::printf("%-22s %8s %12s\n", "volume", "samples", "max err/eps T");
    for (const Codec& codec : runtime_codecs()) {
        const int id = hlsl_encoding(codec.name);
        ASSERT_GE(id, 0) << codec.name;
        std::mt19937_64 rng(0x766Fu + codec.size_bytes * 3 + codec.name.size());
        std::uniform_real_distribution<double> u(0, 1);
        double max_rel = 0;
        long compared = 0, failures = 0;
        std::string first;
        for (int grid = 0; grid < 2; ++grid) {
            const std::uint32_t counts[3] = {grid == 0 ? 6u : 5u, grid == 0 ? 5u : 1u, grid == 0 ? 4u : 3u};
            const float origin_f[3] = {-1.5f, 2.0f, 0.25f}, spacing_f[3] = {0.75f, 0.5f, 1.25f};
            const double origin[3] = {origin_f[0], origin_f[1], origin_f[2]};
            const double spacing[3] = {spacing_f[0], spacing_f[1], spacing_f[2]};
            const std::uint32_t count = counts[0] * counts[1] * counts[2];
            CodecOptions p;
            if (grid == 1) {
                p.kind = StoredKind::kIrradiance;
                if (is_packed(codec.name)) {
                    p.bits = 5;
                    p.sqrt_encoding = true;
                    p.dc_format = DcFormat::kRGB9E5;
                    p.axis_mode = ZonalAxisMode::kPerChannel;
                    p.zonal_mapping = ZonalMapping::kZeroPreserving;
                }
            }
            ASSERT_TRUE(validate_quant_params(p, codec.name).ok()) << codec.name;
            std::vector<std::uint8_t> bytes(count * codec.size_bytes);
            std::vector<Sh3Radiance> decoded;
            for (std::uint32_t i = 0; i < count; ++i) {
                const Sh3Radiance hub = i % 3 == 0 ? random_lights(rng) : (i % 3 == 1 ? random_sh(rng) : random_envmap(rng));
                encode_probe(codec, p, hub, bytes.data() + i * codec.size_bytes, nullptr);
                decoded.push_back(decode_probe(codec, p, bytes.data() + i * codec.size_bytes));
            }
            zhc_probe_format fmt;
            ASSERT_TRUE(runtime_format(codec.name, p, &fmt));
            zhc_volume vol;
            ASSERT_EQ(zhc_volume_init(&vol, &fmt, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
            std::vector<float> items;  // position, 0, normal, 0
            for (int i = 0; i < samples + int(count); ++i) {
                for (int c = 0; c < 3; ++c) {
                    const double size = counts[c] > 1 ? (counts[c] - 1) * spacing[c] : 2 * spacing[c];
                    const double lo = counts[c] > 1 ? origin[c] - 0.25 * size : origin[c] - spacing[c];
                    const std::uint32_t node = std::uint32_t(i - samples);
                    const std::uint32_t at = c == 0 ? node % counts[0] : (c == 1 ? node / counts[0] % counts[1] : node / (counts[0] * counts[1]));
                    items.push_back(i < samples ? float(lo + 1.5 * size * u(rng)) : float(origin[c] + at * spacing[c]));
                }
                items.push_back(0.0f);
                add_normal(rng, &items);
            }
            const std::size_t n_items = items.size() / 8;
            std::uint32_t params[32] = {static_cast<std::uint32_t>(id),
                                        static_cast<std::uint32_t>(p.bits),
                                        p.sqrt_encoding ? 1u : 0u,
                                        static_cast<std::uint32_t>(p.l2_bound),
                                        static_cast<std::uint32_t>(p.dc_format),
                                        static_cast<std::uint32_t>(p.zonal_mapping),
                                        static_cast<std::uint32_t>(p.axis_mode),
                                        static_cast<std::uint32_t>(p.kind),
                                        float_bits(static_cast<float>(p.luminance.r)),
                                        float_bits(static_cast<float>(p.luminance.g)),
                                        float_bits(static_cast<float>(p.luminance.b)),
                                        float_bits(static_cast<float>(p.hallucinate_a)),
                                        float_bits(static_cast<float>(p.hallucinate_b)),
                                        static_cast<std::uint32_t>(n_items),
                                        static_cast<std::uint32_t>(codec.size_bytes / 4),
                                        3u};
            for (int c = 0; c < 3; ++c) {
                params[16 + c] = float_bits(origin_f[c]);
                params[19 + c] = float_bits(spacing_f[c]);
                params[22 + c] = counts[c];
            }
            std::vector<std::uint32_t> words(bytes.size() / 4);
            std::memcpy(words.data(), bytes.data(), bytes.size());
            const std::vector<float> out = Gpu::get().run(params, words, items, n_items);
            ASSERT_EQ(out.size(), n_items * kOutFloats);
            for (std::size_t i = 0; i < n_items; ++i) {
                const double pos[3] = {items[8 * i], items[8 * i + 1], items[8 * i + 2]};
                const double nrm[3] = {items[8 * i + 4], items[8 * i + 5], items[8 * i + 6]};
                double ref[3];
                zhc_volume_irradiance_d(&vol, pos, nrm, ref);
                std::uint32_t i0[3];
                double extra = 0;
                for (int c = 0; c < 3; ++c) {
                    const double tt = std::min(std::max((pos[c] - origin[c]) / spacing[c], 0.0), double(counts[c] - 1));
                    i0[c] = std::min(std::uint32_t(tt), counts[c] >= 2 ? counts[c] - 2 : 0u);
                    extra += (std::fabs(pos[c]) + std::fabs(origin[c])) / spacing[c] + tt + 2;
                }
                double t[3] = {0, 0, 0};
                for (int b = 0; b < 8; ++b) {
                    const std::uint32_t q[3] = {i0[0] + (b & 1), i0[1] + ((b >> 1) & 1), i0[2] + (b >> 2)};
                    if (q[0] >= counts[0] || q[1] >= counts[1] || q[2] >= counts[2]) continue;
                    double tb[3], kappa;
                    probe_scales(codec, p, decoded[q[0] + counts[0] * (q[1] + counts[1] * q[2])], tb, &kappa);
                    for (int k = 0; k < 3; ++k) t[k] += tb[k];
                }
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(t[k]) && std::isfinite(ref[k])) << codec.name << " item " << i;
                    const double got = out[i * kOutFloats + 27 + std::size_t(k)];
                    const double err = std::fabs(got - ref[k]);
                    const double bound = (40 + 1.5 * extra) * FLT_EPSILON * t[k] + kFlushFloor;
                    if (!(err <= bound) && failures++ == 0)
                        first = std::string(codec.name) + " grid " + std::to_string(grid) + " item " + std::to_string(i) +
                                " channel " + std::to_string(k) + ": shader " + std::to_string(got) + " C " + std::to_string(ref[k]);
                    max_rel = std::max(max_rel, err / (FLT_EPSILON * t[k] + kFlushFloor));
                }
                ++compared;
            }
        }
        std::printf("%-22s %8ld %12.3f\n", std::string(codec.name).c_str(), compared, max_rel);
        EXPECT_EQ(failures, 0) << first;
    }
}

// Masked probe volumes (ZHC_VOLUME_MASK, runtime_test_masked.spv) against the C header with
// zhc_volume::validity / ::visibility: a 6x5x4 grid per entry with random validity (1 in 4 invalid)
// and masks, uploaded combined (valid ? visibility : 0, 4 per word after the probe words), and an
// all-invalid grid (the fallback). Bound: ProbeVolumesMatchTheCHeader's, with the weight part
// divided by the masked weight sum M (renormalisation: m_b / M carries the m_b's absolute errors
// over M, twice); samples with 0 < M < 1e-3 (ill-conditioned: a few u of t move the only visible
// corner in or out of weight 0) are counted, not compared, and must stay under 1 %.
TEST_F(RuntimeVk, MaskedProbeVolumesMatchTheCHeader) {
    const int samples = int(test::sample_count(10000));
    std::printf("%-22s %8s %12s %8s\n", "masked volume", "samples", "max err/eps T", "skipped");
    for (const char* name : {"sh3", "zh3_q16", "sh3_q28", "hall_adaptive_q16"})
        for (int all_invalid = 0; all_invalid < 2; ++all_invalid) {
            const Codec* codec = find_codec(name);
            ASSERT_NE(codec, nullptr);
            const int id = hlsl_encoding(name);
            ASSERT_GE(id, 0) << name;
            std::mt19937_64 rng(0x6d61u + codec->size_bytes + unsigned(all_invalid));
            std::uniform_real_distribution<double> u(0, 1);
            const std::uint32_t counts[3] = {6, 5, 4};
            const float origin_f[3] = {-1.5f, 2.0f, 0.25f}, spacing_f[3] = {0.75f, 0.5f, 1.25f};
            const double origin[3] = {origin_f[0], origin_f[1], origin_f[2]};
            const double spacing[3] = {spacing_f[0], spacing_f[1], spacing_f[2]};
            const std::uint32_t count = counts[0] * counts[1] * counts[2];
            const CodecOptions p;
            std::vector<std::uint8_t> bytes(count * codec->size_bytes), validity(count), visibility(count);
            std::vector<Sh3Radiance> decoded;
            for (std::uint32_t i = 0; i < count; ++i) {
                const Sh3Radiance hub = i % 3 == 0 ? random_lights(rng) : (i % 3 == 1 ? random_sh(rng) : random_envmap(rng));
                encode_probe(*codec, p, hub, bytes.data() + i * codec->size_bytes, nullptr);
                decoded.push_back(decode_probe(*codec, p, bytes.data() + i * codec->size_bytes));
                validity[i] = all_invalid ? 0 : (rng() % 4 == 0 ? 0 : 1);
                visibility[i] = std::uint8_t(rng());
            }
            zhc_probe_format fmt;
            ASSERT_TRUE(runtime_format(name, p, &fmt));
            zhc_volume vol;
            ASSERT_EQ(zhc_volume_init(&vol, &fmt, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
            vol.validity = validity.data();
            vol.visibility = visibility.data();
            std::vector<float> items;  // position, 0, normal, 0
            for (int i = 0; i < samples; ++i) {
                for (int c = 0; c < 3; ++c) {
                    const double size = (counts[c] - 1) * spacing[c];
                    items.push_back(float(origin[c] - 0.25 * size + 1.5 * size * u(rng)));
                }
                items.push_back(0.0f);
                add_normal(rng, &items);
            }
            std::uint32_t params[32] = {static_cast<std::uint32_t>(id),
                                        static_cast<std::uint32_t>(p.bits),
                                        p.sqrt_encoding ? 1u : 0u,
                                        static_cast<std::uint32_t>(p.l2_bound),
                                        static_cast<std::uint32_t>(p.dc_format),
                                        static_cast<std::uint32_t>(p.zonal_mapping),
                                        static_cast<std::uint32_t>(p.axis_mode),
                                        static_cast<std::uint32_t>(p.kind),
                                        float_bits(static_cast<float>(p.luminance.r)),
                                        float_bits(static_cast<float>(p.luminance.g)),
                                        float_bits(static_cast<float>(p.luminance.b)),
                                        float_bits(static_cast<float>(p.hallucinate_a)),
                                        float_bits(static_cast<float>(p.hallucinate_b)),
                                        static_cast<std::uint32_t>(samples),
                                        static_cast<std::uint32_t>(codec->size_bytes / 4),
                                        3u};
            for (int c = 0; c < 3; ++c) {
                params[16 + c] = float_bits(origin_f[c]);
                params[19 + c] = float_bits(spacing_f[c]);
                params[22 + c] = counts[c];
            }
            std::vector<std::uint32_t> words(bytes.size() / 4);
            std::memcpy(words.data(), bytes.data(), bytes.size());
            params[25] = static_cast<std::uint32_t>(words.size());
            words.resize(words.size() + (count + 3) / 4, 0);
            for (std::uint32_t i = 0; i < count; ++i)
                words[params[25] + i / 4] |= std::uint32_t(validity[i] ? visibility[i] : 0) << (8 * (i % 4));
            const std::vector<float> out = Gpu::get().run(params, words, items, std::size_t(samples), Gpu::kMasked);
            ASSERT_EQ(out.size(), std::size_t(samples) * kOutFloats);
            double max_rel = 0;
            long compared = 0, failures = 0, skipped = 0, renormalised = 0;
            std::string first;
            for (int i = 0; i < samples; ++i) {
                const std::size_t at = 8 * std::size_t(i);
                const double pos[3] = {items[at], items[at + 1], items[at + 2]};
                const double nrm[3] = {items[at + 4], items[at + 5], items[at + 6]};
                double ref[3];
                zhc_volume_irradiance_d(&vol, pos, nrm, ref);
                std::uint32_t i0[3];
                double f[3], extra = 0;
                for (int c = 0; c < 3; ++c) {
                    const double tt = std::min(std::max((pos[c] - origin[c]) / spacing[c], 0.0), double(counts[c] - 1));
                    i0[c] = std::min(std::uint32_t(tt), counts[c] - 2);
                    f[c] = tt - i0[c];
                    extra += (std::fabs(pos[c]) + std::fabs(origin[c])) / spacing[c] + tt + 2;
                }
                double t[3] = {0, 0, 0}, masked_sum = 0;
                for (int b = 0; b < 8; ++b) {
                    const std::uint32_t q[3] = {i0[0] + (b & 1), i0[1] + ((b >> 1) & 1), i0[2] + (b >> 2)};
                    const std::uint32_t idx = q[0] + counts[0] * (q[1] + counts[1] * q[2]);
                    const double wb = ((b & 1) ? f[0] : 1 - f[0]) * ((b >> 1 & 1) ? f[1] : 1 - f[1]) * ((b >> 2) ? f[2] : 1 - f[2]);
                    if (validity[idx] && ((visibility[idx] >> (7 - b)) & 1)) masked_sum += wb;
                    double tb[3], kappa;
                    probe_scales(*codec, p, decoded[idx], tb, &kappa);
                    for (int k = 0; k < 3; ++k) t[k] += tb[k];
                }
                double weight_part = 1.5 * extra;
                if (masked_sum > 0) {
                    if (masked_sum < 1e-3) {
                        ++skipped;
                        continue;
                    }
                    weight_part = 2 * weight_part / masked_sum;
                    ++renormalised;
                }
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(t[k]) && std::isfinite(ref[k])) << name << " item " << i;
                    const double got = out[std::size_t(i) * kOutFloats + 27 + std::size_t(k)];
                    const double err = std::fabs(got - ref[k]);
                    const double bound = (40 + weight_part) * FLT_EPSILON * t[k] + kFlushFloor;
                    if (!(err <= bound) && failures++ == 0)
                        first = std::string(name) + " item " + std::to_string(i) + " channel " + std::to_string(k) +
                                ": shader " + std::to_string(got) + " C " + std::to_string(ref[k]);
                    max_rel = std::max(max_rel, err / (FLT_EPSILON * t[k] + kFlushFloor));
                }
                ++compared;
            }
            std::printf("%-22s %8ld %12.3f %8ld%s\n", name, compared, max_rel, skipped, all_invalid ? " (all invalid)" : "");
            EXPECT_EQ(failures, 0) << first;
            EXPECT_LE(skipped, samples / 100) << name;
            EXPECT_TRUE(all_invalid ? renormalised == 0 : renormalised > samples / 2) << name << ": " << renormalised;
        }
}

// Cell planes and corner regions (ZHC_VOLUME_PLANE, docs/runtime.md "Cell planes", "Corner
// regions") against the C header with zhc_volume::planes: a 6x5x4 grid per entry, an entry in 3 of 4
// cells, a third of them corner regions (random thresholds, some axes unbounded, random
// directions), the others planes (random normal code through a random point of the cell, the
// corners' sides as the bake writes them), 2 words per probe after the masks. runtime_test_planes.spv: with random validity (1 in 4 invalid) and visibility (each bit set
// with p = 3/4); runtime_test_planes_gltf.spv: planes alone with ZHC_VOLUME_PLANE_AXES_GLTF on the
// same volume in glTF axes (grid, probe order and sides bits permuted, normal codes kept, regions'
// per-axis fields permuted) at the permuted points, against the header on the zhc-axes volume. Per
// sample the corners the entry keeps (zhc_volume_plane_keep) equal the header's, and the irradiance
// lies within MaskedProbeVolumesMatchTheCHeader's bound with M the kept weight sum (0 < M < 1e-3:
// counted, not compared). Points within 1e-4 |spacing| of their cell's plane or of a bounding plane
// of its region (or 1e-5 cell widths of a face between cells) are counted, not compared. The
// header's region keeps equal planes_test::region_keep (the spec's twin), and samples fall both
// inside and outside regions.
TEST_F(RuntimeVk, PlaneProbeVolumesMatchTheCHeader) {
    const int samples = int(test::sample_count(10000));
    for (const bool gltf : {false, true}) {
        std::printf("%-22s %8s %12s %8s %6s %8s %9s %10s %s\n", gltf ? "planes (glTF axes)" : "masks + planes", "samples", "max err/eps T", "skipped",
                    "near", "by plane", "in region", "out region", "corner sets");
        for (const char* name : {"sh3", "zh3_q16", "sh3_q28", "hall_adaptive_q16"}) {
            const Codec* codec = find_codec(name);
            ASSERT_NE(codec, nullptr);
            const int id = hlsl_encoding(name);
            ASSERT_GE(id, 0) << name;
            std::mt19937_64 rng(0x706cu + codec->size_bytes + (gltf ? 1u : 0u));
            std::uniform_real_distribution<double> u(0, 1);
            const std::uint32_t counts[3] = {6, 5, 4};
            const float origin_f[3] = {-1.5f, 2.0f, 0.25f}, spacing_f[3] = {0.75f, 0.5f, 1.25f};
            const double origin[3] = {origin_f[0], origin_f[1], origin_f[2]};
            const double spacing[3] = {spacing_f[0], spacing_f[1], spacing_f[2]};
            const std::uint32_t count = counts[0] * counts[1] * counts[2];
            const CodecOptions p;
            std::vector<std::uint8_t> bytes(count * codec->size_bytes), validity(count), visibility(count);
            std::vector<Sh3Radiance> decoded;
            for (std::uint32_t i = 0; i < count; ++i) {
                const Sh3Radiance hub = i % 3 == 0 ? random_lights(rng) : (i % 3 == 1 ? random_sh(rng) : random_envmap(rng));
                encode_probe(*codec, p, hub, bytes.data() + i * codec->size_bytes, nullptr);
                decoded.push_back(decode_probe(*codec, p, bytes.data() + i * codec->size_bytes));
                validity[i] = rng() % 4 == 0 ? 0 : 1;
                visibility[i] = std::uint8_t(rng() | rng());
            }
            const std::vector<std::uint8_t> planes = planes_test::random_cell_planes(rng, origin, spacing, counts, 0.75, 1.0 / 3);
            zhc_probe_format fmt;
            ASSERT_TRUE(runtime_format(name, p, &fmt));
            zhc_volume vol;
            ASSERT_EQ(zhc_volume_init(&vol, &fmt, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
            if (!gltf) {
                vol.validity = validity.data();
                vol.visibility = visibility.data();
            }
            vol.planes = planes.data();
            const planes_test::GltfGrid g = planes_test::gltf_grid(origin, spacing, counts);
            std::vector<std::uint8_t> gpu_bytes = bytes;
            if (gltf)
                for (std::uint32_t j = 0; j < count; ++j)
                    std::memcpy(gpu_bytes.data() + j * codec->size_bytes, bytes.data() + g.gltf_to_zhc[j] * codec->size_bytes,
                                codec->size_bytes);
            std::vector<float> items;  // position, 0, normal, 0
            std::vector<double> positions;  // zhc axes
            for (int i = 0; i < samples; ++i) {
                float pos[3];
                for (int c = 0; c < 3; ++c) {
                    const double size = (counts[c] - 1) * spacing[c];
                    pos[c] = float(origin[c] - 0.25 * size + 1.5 * size * u(rng));
                    positions.push_back(pos[c]);
                }
                for (int c = 0; c < 3; ++c) items.push_back(gltf ? pos[(c + 1) % 3] : pos[c]);
                items.push_back(0.0f);
                add_normal(rng, &items);
            }
            std::uint32_t params[32] = {static_cast<std::uint32_t>(id),
                                        static_cast<std::uint32_t>(p.bits),
                                        p.sqrt_encoding ? 1u : 0u,
                                        static_cast<std::uint32_t>(p.l2_bound),
                                        static_cast<std::uint32_t>(p.dc_format),
                                        static_cast<std::uint32_t>(p.zonal_mapping),
                                        static_cast<std::uint32_t>(p.axis_mode),
                                        static_cast<std::uint32_t>(p.kind),
                                        float_bits(static_cast<float>(p.luminance.r)),
                                        float_bits(static_cast<float>(p.luminance.g)),
                                        float_bits(static_cast<float>(p.luminance.b)),
                                        float_bits(static_cast<float>(p.hallucinate_a)),
                                        float_bits(static_cast<float>(p.hallucinate_b)),
                                        static_cast<std::uint32_t>(samples),
                                        static_cast<std::uint32_t>(codec->size_bytes / 4),
                                        3u};
            for (int c = 0; c < 3; ++c) {
                params[16 + c] = float_bits(gltf ? float(g.origin[c]) : origin_f[c]);
                params[19 + c] = float_bits(gltf ? float(g.spacing[c]) : spacing_f[c]);
                params[22 + c] = gltf ? g.counts[c] : counts[c];
            }
            std::vector<std::uint32_t> words(gpu_bytes.size() / 4);
            std::memcpy(words.data(), gpu_bytes.data(), gpu_bytes.size());
            params[25] = static_cast<std::uint32_t>(words.size());
            words.resize(words.size() + (count + 3) / 4, 0);
            for (std::uint32_t i = 0; i < count; ++i)
                words[params[25] + i / 4] |= std::uint32_t(validity[i] ? visibility[i] : 0) << (8 * (i % 4));
            params[26] = static_cast<std::uint32_t>(words.size());
            const std::vector<std::uint32_t> pw = planes_test::plane_words(gltf ? planes_test::gltf_planes(g, planes) : planes);
            words.insert(words.end(), pw.begin(), pw.end());
            const std::vector<float> out =
                Gpu::get().run(params, words, items, std::size_t(samples), gltf ? Gpu::kPlanesGltf : Gpu::kPlanes);
            ASSERT_EQ(out.size(), std::size_t(samples) * kOutFloats);
            double max_rel = 0;
            long compared = 0, failures = 0, skipped = 0, near = 0, by_plane = 0, region_in = 0, region_out = 0, twin_wrong = 0, keep_compared = 0, keep_wrong = 0;
            std::string first, first_keep;
            for (int i = 0; i < samples; ++i) {
                const double* pos = positions.data() + 3 * std::size_t(i);
                const std::size_t at = 8 * std::size_t(i);
                const double nrm[3] = {items[at + 4], items[at + 5], items[at + 6]};
                const planes_test::Sample sm = planes_test::sample(vol, pos);
                if (sm.near) {
                    ++near;
                    continue;
                }
                const unsigned want_keep = gltf ? planes_test::gltf_sides(std::uint8_t(sm.plane_keep)) : sm.plane_keep;
                const unsigned got_keep = unsigned(out[std::size_t(i) * kOutFloats]);
                ++keep_compared;
                if (got_keep != want_keep && keep_wrong++ == 0)
                    first_keep = std::string(name) + " item " + std::to_string(i) + ": shader keeps " + std::to_string(got_keep) + ", C " +
                                 std::to_string(want_keep);
                by_plane += sm.plane_keep != 0xFF;
                if (sm.region) ++(sm.inside ? region_in : region_out);
                twin_wrong += sm.region_twin_differs;
                double ref[3];
                zhc_volume_irradiance_d(&vol, pos, nrm, ref);
                double t[3] = {0, 0, 0}, extra = 0;
                for (int c = 0; c < 3; ++c)
                    extra += (std::fabs(pos[c]) + std::fabs(origin[c])) / spacing[c] +
                             std::min(std::max((pos[c] - origin[c]) / spacing[c], 0.0), double(counts[c] - 1)) + 2;
                for (int b = 0; b < 8; ++b) {
                    const std::uint32_t q[3] = {sm.i0[0] + (b & 1), sm.i0[1] + ((b >> 1) & 1), sm.i0[2] + (b >> 2)};
                    double tb[3], kappa;
                    probe_scales(*codec, p, decoded[q[0] + counts[0] * (q[1] + counts[1] * q[2])], tb, &kappa);
                    for (int k = 0; k < 3; ++k) t[k] += tb[k];
                }
                double weight_part = 1.5 * extra;
                if (sm.kept_sum > 0) {
                    if (sm.kept_sum < 1e-3) {
                        ++skipped;
                        continue;
                    }
                    weight_part = 2 * weight_part / sm.kept_sum;
                }
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(t[k]) && std::isfinite(ref[k])) << name << " item " << i;
                    const double got = out[std::size_t(i) * kOutFloats + 27 + std::size_t(k)];
                    const double err = std::fabs(got - ref[k]);
                    const double bound = (40 + weight_part) * FLT_EPSILON * t[k] + kFlushFloor;
                    if (!(err <= bound) && failures++ == 0)
                        first = std::string(name) + " item " + std::to_string(i) + " channel " + std::to_string(k) + ": shader " +
                                std::to_string(got) + " C " + std::to_string(ref[k]);
                    max_rel = std::max(max_rel, err / (FLT_EPSILON * t[k] + kFlushFloor));
                }
                ++compared;
            }
            std::printf("%-22s %8ld %12.3f %8ld %6ld %8ld %9ld %10ld %ld of %ld equal\n", name, compared, max_rel, skipped, near, by_plane,
                        region_in, region_out,
                        keep_compared - keep_wrong, keep_compared);
            EXPECT_EQ(failures, 0) << first;
            EXPECT_EQ(keep_wrong, 0) << first_keep;
            EXPECT_LE(skipped, samples / 100) << name;
            EXPECT_LE(near, samples / 100) << name;
            EXPECT_GT(by_plane, samples / 4) << name << ": the planes act";
            EXPECT_EQ(twin_wrong, 0) << name << ": the header's corner region keeps differ from the spec's twin";
            EXPECT_GT(region_in, samples / 100) << name << ": samples inside corner regions";
            EXPECT_GT(region_out, samples / 100) << name << ": samples outside corner regions, in their cells";
        }
    }
}

// Scattered probes (zhc_volume_tetra_sh3 / zhc_volume_tetra_irradiance, mode 5; docs/runtime.md
// "Scattered probes (`points` layout)") against the C header's zhc_volume_sh3 /
// zhc_volume_irradiance_d: 150 random positions tetrahedralised by formats/probes/tetra.h (qhull),
// probes (lights, random SH, sample maps) stored as sh3, zh3_q16, sh3_q28 and hall_adaptive_q16,
// with and without validity (1 in 4 invalid), 10,000 points inside and outside the hull plus every
// probe, the kernel given the 4 probes and weights (as float) of zhc_volume_tetra_weights. Every
// weight-0 probe index is replaced by that of a probe of 0xFF bytes (decodes to NaN / Inf): the
// results stay finite only if the blend does not read it. Bound, for the blended SH3 and the
// irradiance: ProbeVolumesMatchTheCHeader's decode, evaluation and blend terms, 40 eps T with
// T = sum_k w_k T_k (the weights are a partition of unity; rounding them to float moves each by
// u w_k, inside the 40). Then analytic fields against their own double twin: every probe equal
// (sh3, zh3_q16) gives that probe's irradiance inside and outside the hull, and an SH3 field affine
// in position stored as sh3 is reproduced inside the hull, both within 40 eps T.
TEST_F(RuntimeVk, ScatteredProbesMatchTheCHeader) {
    const int samples = int(test::sample_count(10000));
    std::printf("%-22s %8s %8s %12s\n", "scattered probes", "samples", "outside", "max err/eps T");
    auto params_of = [](const char* name, const CodecOptions& p, std::size_t count, std::uint32_t stride, std::uint32_t out[16]) {
        const std::uint32_t v[16] = {static_cast<std::uint32_t>(hlsl_encoding(name)),
                                     static_cast<std::uint32_t>(p.bits),
                                     p.sqrt_encoding ? 1u : 0u,
                                     static_cast<std::uint32_t>(p.l2_bound),
                                     static_cast<std::uint32_t>(p.dc_format),
                                     static_cast<std::uint32_t>(p.zonal_mapping),
                                     static_cast<std::uint32_t>(p.axis_mode),
                                     static_cast<std::uint32_t>(p.kind),
                                     float_bits(static_cast<float>(p.luminance.r)),
                                     float_bits(static_cast<float>(p.luminance.g)),
                                     float_bits(static_cast<float>(p.luminance.b)),
                                     float_bits(static_cast<float>(p.hallucinate_a)),
                                     float_bits(static_cast<float>(p.hallucinate_b)),
                                     static_cast<std::uint32_t>(count),
                                     stride,
                                     5u};
        std::memcpy(out, v, sizeof v);
    };
    auto items_of = [](const std::vector<tetra_test::Sample>& ss) {
        std::vector<float> items;  // weights, probe indices (as floats), normal, 0
        for (const tetra_test::Sample& sm : ss) {
            for (int k = 0; k < 4; ++k) items.push_back(float(sm.weights[k]));
            for (int k = 0; k < 4; ++k) items.push_back(float(sm.probes[k]));
            items.insert(items.end(), {sm.normal[0], sm.normal[1], sm.normal[2], 0.0f});
        }
        return items;
    };
    auto direction = [](double u1, double u2) { return test::uniform_direction(u1, u2); };
    for (const char* name : {"sh3", "zh3_q16", "sh3_q28", "hall_adaptive_q16"})
        for (int with_validity = 0; with_validity < 2; ++with_validity) {
            const Codec* codec = find_codec(name);
            ASSERT_NE(codec, nullptr);
            ASSERT_GE(hlsl_encoding(name), 0) << name;
            std::mt19937_64 rng(0x7e7Au + codec->size_bytes + unsigned(with_validity));
            const std::vector<std::array<float, 3>> positions = tetra_test::random_positions(rng, 150);
            std::vector<Sh3Radiance> hubs;
            std::vector<std::uint8_t> validity;
            for (std::uint32_t i = 0; i < positions.size(); ++i) {
                hubs.push_back(i % 3 == 0 ? random_lights(rng) : (i % 3 == 1 ? random_sh(rng) : random_envmap(rng)));
                if (with_validity) validity.push_back(rng() % 4 == 0 ? 0 : 1);
            }
            const CodecOptions p{};
            tetra_test::PointsVolume v;
            tetra_test::make_points_volume(v, *codec, p, positions, hubs, validity);
            ASSERT_TRUE(v.error.empty()) << v.error;
            ASSERT_TRUE(tetra_test::nan_probe_poisons(v)) << name;
            const std::vector<tetra_test::Sample> ss = tetra_test::samples(rng, v, samples, true, direction);
            std::uint32_t params[16];
            params_of(name, p, ss.size(), std::uint32_t(codec->size_bytes / 4), params);
            std::vector<std::uint32_t> words(v.bytes.size() / 4);
            std::memcpy(words.data(), v.bytes.data(), v.bytes.size());
            const std::vector<float> out = Gpu::get().run(params, words, items_of(ss), ss.size());
            ASSERT_EQ(out.size(), ss.size() * kOutFloats);
            double max_rel = 0;
            long failures = 0, outside = 0;
            std::string first;
            for (std::size_t i = 0; i < ss.size(); ++i) {
                const tetra_test::Sample& sm = ss[i];
                const double pos[3] = {sm.pos[0], sm.pos[1], sm.pos[2]};
                const double nrm[3] = {sm.normal[0], sm.normal[1], sm.normal[2]};
                double ref[3], ref_sh[27], t[3] = {0, 0, 0};
                zhc_volume_irradiance_d(&v.vol, pos, nrm, ref);
                zhc_volume_sh3(&v.vol, pos, ref_sh);
                ASSERT_GE(sm.outside, 0);
                outside += sm.outside;
                for (int k = 0; k < 4; ++k) {
                    if (sm.weights[k] == 0.0) continue;
                    double tb[3], kappa;
                    probe_scales(*codec, p, v.decoded[sm.probes[k]], tb, &kappa);
                    for (int c = 0; c < 3; ++c) t[c] += sm.weights[k] * tb[c];
                }
                for (int j = 0; j < 30; ++j) {
                    const int c = j % 3;
                    const double want = j < 27 ? ref_sh[j] : ref[c];
                    ASSERT_TRUE(std::isfinite(t[c]) && std::isfinite(want)) << name << " item " << i;
                    const double got = out[i * kOutFloats + std::size_t(j)];
                    const double err = std::fabs(got - want);
                    if (!(err <= 40 * FLT_EPSILON * t[c] + kFlushFloor) && failures++ == 0)
                        first = std::string(name) + (with_validity ? " (validity)" : "") + " item " + std::to_string(i) + " output " +
                                std::to_string(j) + ": shader " + std::to_string(got) + " C " + std::to_string(want);
                    max_rel = std::max(max_rel, err / (FLT_EPSILON * t[c] + kFlushFloor));
                }
            }
            std::printf("%-22s %8zu %8ld %12.3f%s\n", name, ss.size(), outside, max_rel, with_validity ? " (validity)" : "");
            EXPECT_EQ(failures, 0) << first;
            EXPECT_GT(outside, long(ss.size()) / 3) << name << ": points outside the hull";
            EXPECT_LT(outside, long(ss.size()) * 9 / 10) << name << ": points inside the hull";
        }
    // Analytic fields.
    for (const char* name : {"sh3", "zh3_q16", "affine"}) {
        const bool affine = std::string(name) == "affine";
        const char* enc = affine ? "sh3" : name;
        const Codec* codec = find_codec(enc);
        ASSERT_NE(codec, nullptr);
        std::mt19937_64 rng(0xf1e1dAu + codec->size_bytes + (affine ? 1u : 0u));
        const std::vector<std::array<float, 3>> positions = tetra_test::random_positions(rng, 120);
        const Sh3Radiance constant = random_lights(rng);
        const tetra_test::AffineField field = tetra_test::random_affine(rng);
        std::vector<Sh3Radiance> hubs;
        for (const auto& q : positions) hubs.push_back(affine ? field.hub_at(q) : constant);
        const CodecOptions p{};
        tetra_test::PointsVolume v;
        tetra_test::make_points_volume(v, *codec, p, positions, hubs, {});
        ASSERT_TRUE(v.error.empty()) << v.error;
        const std::vector<tetra_test::Sample> ss = tetra_test::samples(rng, v, 4000, false, direction);
        std::uint32_t params[16];
        params_of(enc, p, ss.size(), std::uint32_t(codec->size_bytes / 4), params);
        std::vector<std::uint32_t> words(v.bytes.size() / 4);
        std::memcpy(words.data(), v.bytes.data(), v.bytes.size());
        const std::vector<float> out = Gpu::get().run(params, words, items_of(ss), ss.size());
        ASSERT_EQ(out.size(), ss.size() * kOutFloats);
        double max_rel = 0;
        long failures = 0, compared = 0;
        std::string first;
        for (std::size_t i = 0; i < ss.size(); ++i) {
            const tetra_test::Sample& sm = ss[i];
            if (affine && sm.outside) continue;
            double sh[27], want[3], t[3] = {0, 0, 0};
            if (affine) {
                const double x[3] = {sm.pos[0], sm.pos[1], sm.pos[2]};
                field.at(x, sh);
            } else {
                for (int j = 0; j < 27; ++j) sh[j] = v.decoded[0][j / 3][j % 3];
            }
            tetra_test::irradiance_twin(sh, sm.normal, want);
            for (int k = 0; k < 4; ++k) {  // constant: the probe's own T (weights sum to 1)
                double tb[3], kappa;
                probe_scales(*codec, p, v.decoded[affine ? sm.probes[k] : 0], tb, &kappa);
                for (int c = 0; c < 3; ++c) t[c] += sm.weights[k] * tb[c];
            }
            ++compared;
            for (int c = 0; c < 3; ++c) {
                const double got = out[i * kOutFloats + 27 + std::size_t(c)];
                const double err = std::fabs(got - want[c]);
                if (!(err <= 40 * FLT_EPSILON * t[c] + kFlushFloor) && failures++ == 0)
                    first = std::string(name) + " item " + std::to_string(i) + " channel " + std::to_string(c) + ": shader " +
                            std::to_string(got) + " twin " + std::to_string(want[c]);
                max_rel = std::max(max_rel, err / (FLT_EPSILON * t[c] + kFlushFloor));
            }
        }
        std::printf("%-22s %8ld samples, max err/eps T %.3f\n", affine ? "affine field (sh3)" : (std::string("constant ") + name).c_str(),
                    compared, max_rel);
        EXPECT_EQ(failures, 0) << first;
        EXPECT_GT(compared, affine ? 1000L : long(ss.size()) - 1) << name;
    }
}

}  // namespace
}  // namespace zhc
