// bench_runtime — what accuracy costs at runtime: for every encoding of the codec
// table, the irradiance evaluation of runtime/zhc.hlsl straight from the stored words,
//   (a) compiled: HLSL -> SPIR-V (glslangValidator's HLSL front end) -> spirv-opt -O, and counted:
//       instructions inside the function bodies of the spirv-dis listing (after -O everything is
//       inlined into main; OpFunction/OpFunctionParameter/OpLabel/OpFunctionEnd are not counted),
//       in total and minus the skeleton (an "empty" kernel that reads the normal and writes it);
//   (b) timed on Mesa lavapipe: one dispatch of N evaluations (N = 2^18 by default; probe i mod P of
//       P = 65536 encoded probes, one of P normals), wall clock around submit + vkQueueWaitIdle,
//       median of R = 9 repeats after a warm-up, the kernels timed in
//       interleaved rounds; the plain sh3 float evaluation in the same run is the
//       baseline, so the ratio column survives a noisy machine. A second timing ("cached") runs 16
//       evaluations per invocation on 64 probes that stay in cache: per-invocation overhead
//       amortised and fetch cheap, it separates the decode + evaluation arithmetic from the fetch.
// Two more rows: IrradZ lightmap reconstruction (HHD, AHD) from the three textures' sampled values.
// The format of each kernel is a compile-time constant (zhc_default_format), as a shader specialised
// for its asset's format would have it. Benchmarks never decide pass/fail.
//
// Usage: bench_runtime [--evals N] [--repeats R] [--json FILE] [--keep DIR]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "codec/probe/codec.h"
#include "vk_compute.h"
#include "spirv_count.h"
#include "timing.h"

namespace {

using namespace zhc;

using vk::hlsl_encoding;

constexpr std::uint32_t kProbes = 1u << 16;

// The kernel. encoding >= 0: a probe encoding; kSkeleton: normal in, normal out; kIrradzHhd/Ahd:
// an IrradZ texel (I_z rgb, w_a, d uv as 6 floats: the three textures' sampled values).
// cached = false: one evaluation per invocation, probe i mod P (P = 65536 distinct probes: the
// stored bytes are fetched from memory). cached = true: kCachedLoop evaluations per invocation in a
// loop, each on one of 64 probes (they stay in cache) at its own normal, summed: the per-invocation
// overhead is amortised and the fetch is cheap, so what is timed is mostly decode + evaluation.
constexpr int kSkeleton = -1, kIrradzHhd = -2, kIrradzAhd = -3;
constexpr std::uint32_t kCachedLoop = 16;
std::string kernel_source(int encoding, std::size_t size_bytes, bool cached) {
    std::ostringstream s;
    s << "#include \"zhc.hlsl\"\n"
         "[[vk::binding(0, 0)]] ByteAddressBuffer probes;\n"
         "[[vk::binding(1, 0)]] StructuredBuffer<float4> normals;\n"
         "[[vk::binding(2, 0)]] RWStructuredBuffer<float4> result;\n"
         "static const uint kMask = "
      << (kProbes - 1) << "u;\n";
    // Body of one evaluation: probe index `p`, normal `n`, adds to `acc`.
    std::ostringstream body;
    const std::size_t words = size_bytes / 4;
    if (encoding == kSkeleton) {
        body << "        acc += n;\n";
    } else if (encoding == kIrradzHhd || encoding == kIrradzAhd) {
        body << "        uint base = p * 24u;\n"
                "        float3 iz = asfloat(probes.Load3(base));\n"
                "        float wa = asfloat(probes.Load(base + 12u));\n"
                "        float2 uv = asfloat(probes.Load2(base + 16u));\n"
                "        n.z = abs(n.z);\n"
             << "        acc += zhc_irradz_irradiance(iz, wa, uv, "
             << (encoding == kIrradzHhd ? "ZHC_IRRADZ_HHD" : "ZHC_IRRADZ_AHD") << ", n);\n";
    } else {
        body << "        const ZhcFormat f = zhc_default_format(" << encoding << "u);\n"
             << "        uint base = p * " << size_bytes << "u;\n"
             << "        uint w[27];\n"
             << "        [unroll] for (uint j = 0u; j < 27u; ++j) w[j] = j < " << words
             << "u ? probes.Load(base + 4u * j) : 0u;\n"
             << "        acc += zhc_irradiance(w, f, n);\n";
    }
    s << "[numthreads(64, 1, 1)]\nvoid main(uint3 id : SV_DispatchThreadID)\n{\n"
         "    uint i = id.x;\n"
         "    float3 acc = 0.0f;\n";
    if (cached) {
        s << "    [loop] for (uint k = 0u; k < " << kCachedLoop << "u; ++k)\n    {\n"
          << "        uint p = (i * 7u + k) & 63u;\n"
          << "        float3 n = normals[(i + 4099u * k) & kMask].xyz;\n"
          << body.str() << "    }\n";
    } else {
        s << "    {\n"
          << "        uint p = i & kMask;\n"
          << "        float3 n = normals[(i + (i >> 16)) & kMask].xyz;\n"
          << body.str() << "    }\n";
    }
    s << "    result[i] = float4(acc, 0.0f);\n}\n";
    return s.str();
}

bool run(const std::string& command) {
    const int rc = std::system(command.c_str());
    if (rc != 0) std::fprintf(stderr, "failed (%d): %s\n", rc, command.c_str());
    return rc == 0;
}

std::string quote(const std::string& s) { return "'" + s + "'"; }

struct Compiled {
    std::vector<std::uint32_t> spirv;
    int instructions = -1;
};

// HLSL -> SPIR-V -> spirv-opt -O -> count the function-body instructions of the disassembly.
Compiled compile(const std::string& dir, const std::string& name, const std::string& source) {
    Compiled c;
    const std::string hlsl = dir + "/" + name + ".hlsl", raw = dir + "/" + name + ".spv", opt = dir + "/" + name + ".opt.spv",
                      dis = dir + "/" + name + ".opt.spvasm";
    std::ofstream(hlsl) << source;
    if (!run(quote(ZHC_GLSLANG) + " -D -V -S comp -e main -I" + quote(ZHC_RUNTIME_DIR) + " " + quote(hlsl) + " -o " +
             quote(raw) + " > " + quote(dir + "/" + name + ".log") + " 2>&1"))
        return c;
    if (!run(quote(ZHC_SPIRV_OPT) + " -O " + quote(raw) + " -o " + quote(opt))) return c;
    if (!run(quote(ZHC_SPIRV_DIS) + " --no-header " + quote(opt) + " -o " + quote(dis))) return c;
    const int count = bench::spirv_function_instructions(dis);
    c.instructions = count;
    c.spirv = vk::read_spirv(opt);
    return c;
}

// Probes to evaluate: ambient + 1..3 coloured directional lights, encoded with the codec.
std::vector<std::uint8_t> make_probes(const Codec& codec) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto dir = [&] {
        const double z = 2 * u(rng) - 1, phi = 2 * kPi * u(rng), r = std::sqrt(std::max(0.0, 1 - z * z));
        return Vec3{r * std::cos(phi), r * std::sin(phi), z};
    };
    std::vector<std::uint8_t> bytes(kProbes * codec.size_bytes);
    const CodecOptions options;
    for (std::uint32_t i = 0; i < kProbes; ++i) {
        Sh3Radiance sh = project_constant(Rgb{float(0.2 * u(rng)), float(0.2 * u(rng)), float(0.2 * u(rng))});
        for (int l = 0, n = 1 + static_cast<int>(3 * u(rng)); l < n; ++l)
            sh = sh + project_directional(dir(), Rgb{float(5 * u(rng)), float(5 * u(rng)), float(5 * u(rng))});
        codec.encode(sh, options, bytes.data() + i * codec.size_bytes, nullptr);
    }
    return bytes;
}

double finite_or(double v) { return std::isfinite(v) ? v : -1.0; }

struct Row {
    std::string name;
    double bytes = 0;            // stored bytes per probe (IrradZ: BC6H + BC4 + BC5 bytes per texel)
    int instructions = -1;
    int eval_instructions = -1;
    double ns = NAN;             // P distinct probes
    double ns_one = NAN;         // cached: 16 evaluations per invocation on 64 probes
    bool exact = false;          // an exact codec entry (CodecTraits::exact): the first is the baseline
};

// IrradZ texels: I_z, w_a, d (hemi-octahedral uv) as the sampled textures would give them.
std::vector<std::uint8_t> make_texels() {
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> v(static_cast<std::size_t>(kProbes) * 6);
    for (float& x : v) x = static_cast<float>(u(rng));
    std::vector<std::uint8_t> bytes(v.size() * 4);
    std::memcpy(bytes.data(), v.data(), bytes.size());
    return bytes;
}

}  // namespace

int main(int argc, char** argv) {
    std::uint32_t evals = 1u << 18;
    int repeats = 9;
    std::string json, keep;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--evals" && i + 1 < argc) evals = static_cast<std::uint32_t>(std::max(64L, std::atol(argv[++i])));
        else if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
        else if (a == "--json" && i + 1 < argc) json = argv[++i];
        else if (a == "--keep" && i + 1 < argc) keep = argv[++i];
        else {
            std::fprintf(stderr, "usage: %s [--evals N] [--repeats R] [--json FILE] [--keep DIR]\n", argv[0]);
            return 2;
        }
    }
    evals = (evals + 63) / 64 * 64;
    if (evals / 64 > 65535) {
        std::fprintf(stderr, "--evals: at most %u (65535 work groups of 64)\n", 65535u * 64u);
        return 2;
    }
    if (std::strlen(ZHC_LVP_ICD) > 0) vk::force_icd(ZHC_LVP_ICD);
    std::string error;
    auto context = vk::Context::create(true, &error);
    if (!context) {
        std::fprintf(stderr, "Vulkan: %s\n", error.c_str());
        return 1;
    }
    namespace fs = std::filesystem;
    const fs::path dir = keep.empty() ? fs::temp_directory_path() / ("zhc_bench_runtime_" + std::to_string(::getpid())) : fs::path(keep);
    fs::create_directories(dir);

    std::vector<float> normals(static_cast<std::size_t>(kProbes) * 4);
    {
        std::mt19937_64 rng(11);
        std::normal_distribution<double> g;
        for (std::uint32_t i = 0; i < kProbes; ++i) {
            double v[3] = {g(rng), g(rng), g(rng)};
            const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            for (int k = 0; k < 3; ++k) normals[4 * i + static_cast<std::uint32_t>(k)] = static_cast<float>(v[k] / len);
        }
    }

    // Every kernel is built first, then timed in interleaved rounds (one dispatch of each per round,
    // after a warm-up round): load changes on a shared machine then hit all rows alike.
    struct Timed {
        Row row;
        std::unique_ptr<vk::Kernel> kernel[2];  // P probes, cached
        std::vector<double> seconds[2];
    };
    std::vector<Timed> timed;
    auto make = [&](const Compiled& c, const std::vector<std::uint8_t>& probes, const std::string& name) {
        std::unique_ptr<vk::Kernel> k;
        if (c.spirv.empty()) return k;
        const std::size_t sizes[3] = {std::max<std::size_t>(16, probes.size()), normals.size() * 4, std::size_t(evals) * 16};
        k = context->make_kernel(c.spirv, sizes, &error);
        if (!k) {
            std::fprintf(stderr, "%s: %s\n", name.c_str(), error.c_str());
            return k;
        }
        if (!probes.empty()) std::memcpy(k->data(0), probes.data(), probes.size());
        std::memcpy(k->data(1), normals.data(), normals.size() * 4);
        return k;
    };
    const std::string d = dir.string();
    // One row: compile both variants, count the P-probe one.
    auto add = [&](Row row, int encoding, std::size_t load_bytes, const std::vector<std::uint8_t>& probes, int skeleton_count) {
        Timed t;
        const Compiled c = compile(d, row.name, kernel_source(encoding, load_bytes, false));
        const Compiled c1 = compile(d, row.name + ".cached", kernel_source(encoding, load_bytes, true));
        row.instructions = c.instructions;
        row.eval_instructions = c.instructions >= 0 && skeleton_count >= 0 ? c.instructions - skeleton_count : -1;
        t.kernel[0] = make(c, probes, row.name);
        t.kernel[1] = make(c1, probes, row.name);
        t.row = std::move(row);
        timed.push_back(std::move(t));
    };
    const Compiled skeleton = compile(d, "skeleton", kernel_source(kSkeleton, 0, false));
    if (skeleton.spirv.empty()) {
        std::fprintf(stderr, "skeleton kernel failed to compile\n");
        return 1;
    }
    Row sk;
    sk.name = "skeleton";
    add(sk, kSkeleton, 0, {}, skeleton.instructions);
    for (const Codec& codec : runtime_codecs()) {  // the engine layouts have no HLSL decoder (codec.h)
        Row row;
        row.name = std::string(codec.name);
        row.bytes = static_cast<double>(codec.size_bytes);
        row.exact = codec.traits.exact;
        const int id = hlsl_encoding(codec.name);
        if (id < 0) {
            std::fprintf(stderr, "%s: no HLSL encoding\n", row.name.c_str());
            timed.push_back(Timed{row, {}, {}});
            continue;
        }
        add(row, id, codec.size_bytes, make_probes(codec), skeleton.instructions);
    }
    const std::vector<std::uint8_t> texels = make_texels();
    for (int model = 0; model < 2; ++model) {
        Row row;
        row.name = model == 0 ? "irradz_hhd" : "irradz_ahd";  // lightmap texels, not probes
        row.bytes = 2.5;  // BC6H 1 + BC4 0.5 + BC5 1 byte per texel
        add(row, model == 0 ? kIrradzHhd : kIrradzAhd, 24, texels, skeleton.instructions);
    }
    for (int r = 0; r <= repeats; ++r)
        for (Timed& t : timed)
            for (int v = 0; v < 2; ++v) {
                if (!t.kernel[v]) continue;
                const double sec = t.kernel[v]->dispatch(evals / 64, &error);
                if (sec < 0) {
                    std::fprintf(stderr, "%s: %s\n", t.row.name.c_str(), error.c_str());
                    t.kernel[v].reset();
                    continue;
                }
                if (r > 0) t.seconds[v].push_back(sec);
            }
    std::vector<Row> rows;
    for (Timed& t : timed) {
        for (int v = 0; v < 2; ++v) {
            if (!t.kernel[v] || t.seconds[v].empty()) continue;
            std::sort(t.seconds[v].begin(), t.seconds[v].end());
            (v == 0 ? t.row.ns : t.row.ns_one) =
                t.seconds[v][t.seconds[v].size() / 2] / (double(evals) * (v == 0 ? 1 : kCachedLoop)) * 1e9;
        }
        rows.push_back(t.row);
    }
    timed.clear();  // kernels before the context
    // The baseline: the first exact entry (sh3, the float hub). JSON keys keep their "ratio_to_sh3" names.
    double base = NAN, base_one = NAN;
    std::string base_name = "-";
    for (const Row& r : rows)
        if (r.exact) {
            base = r.ns;
            base_one = r.ns_one;
            base_name = "vs " + r.name;
            break;
        }

    std::printf("bench_runtime: irradiance from stored words, runtime/zhc.hlsl on %s\n", context->device_name().c_str());
    std::printf("%u evaluations per dispatch, median of %d; SPIR-V after spirv-opt -O (function-body instructions)\n\n", evals,
                repeats);
    std::printf("ns/eval: one evaluation per invocation on %u distinct probes (fetch from memory);\n"
                "cached: %u evaluations per invocation on 64 probes (overhead amortised, fetch from cache)\n\n",
                kProbes, kCachedLoop);
    std::printf("%-22s %6s %8s %11s %10s %8s %14s %8s\n", "encoding", "bytes", "SPIR-V", "SPIR-V-skel", "ns/eval",
                base_name.c_str(), "ns/eval cached", base_name.c_str());
    for (const Row& r : rows)
        std::printf("%-22s %6.1f %8d %11d %10.2f %8.2f %14.2f %8.2f\n", r.name.c_str(), r.bytes, r.instructions,
                    r.eval_instructions, r.ns, r.ns / base, r.ns_one, r.ns_one / base_one);
    if (!json.empty()) {
        std::ofstream out(json);
        out << "{\n  \"benchmark\": \"runtime\",\n  \"device\": \"" << context->device_name() << "\",\n  \"evaluations\": "
            << evals << ",\n  \"repeats\": " << repeats << ",\n  \"rows\": [\n";
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const Row& r = rows[i];
            char buf[512];
            std::snprintf(buf, sizeof buf,
                          "    {\"encoding\": \"%s\", \"bytes\": %g, \"spirv_instructions\": %d, "
                          "\"spirv_instructions_minus_skeleton\": %d, \"ns_per_eval\": %.4f, \"ratio_to_sh3\": %.4f, "
                          "\"ns_per_eval_cached\": %.4f, \"ratio_to_sh3_cached\": %.4f}%s\n",
                          r.name.c_str(), r.bytes, r.instructions, r.eval_instructions, finite_or(r.ns), finite_or(r.ns / base),
                          finite_or(r.ns_one), finite_or(r.ns_one / base_one), i + 1 < rows.size() ? "," : "");
            out << buf;
        }
        if (!bench::finish_json(out, json)) return 1;
    }
    if (keep.empty()) fs::remove_all(dir);
    return 0;
}
