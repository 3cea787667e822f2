// bench_runtime — what accuracy costs at runtime (issue 15 item 3): for every encoding of the codec
// table, the irradiance evaluation of runtime/zhc.hlsl straight from the stored words,
//   (a) compiled: HLSL -> SPIR-V (glslangValidator's HLSL front end) -> spirv-opt -O, and counted:
//       instructions inside the function bodies of the spirv-dis listing (after -O everything is
//       inlined into main; OpFunction/OpFunctionParameter/OpLabel/OpFunctionEnd are not counted),
//       in total and minus the skeleton (an "empty" kernel that reads the normal and writes it);
//   (b) timed on Mesa lavapipe: one dispatch of N evaluations (N = 2^18 by default; probe i mod P of
//       P = 65536 encoded probes, one of P normals), wall clock around submit + vkQueueWaitIdle,
//       median of R = 9 repeats after a warm-up, the kernels timed in
//       interleaved rounds; the plain sh3 float evaluation in the same run is the
//       baseline, so the ratio column survives a noisy machine.
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

#include "codec/codec.h"
#include "vk_compute.h"

namespace {

using namespace zhc;

// zhc.hlsl's encoding ids (ZHC_* macros), by name.
const char* const kHlslEncodings[] = {
    "sh3", "sh2", "zh3_lum", "zh3_channel", "zh3_solved_lum", "zh3_solved_channel", "hall_ambdir", "hall_sphere",
    "hall_curve", "hall_ambdir_channel", "hall_sphere_channel", "hall_curve_channel", "zh3_lum_dering",
    "zh3_lum_dering_sphere", "sh3_dering", "zh3_q16", "zh3_solved_q16", "sh3_q28", "sh2_q", "hall_curve_q",
};
int hlsl_encoding(std::string_view name) {
    for (int i = 0; i < static_cast<int>(std::size(kHlslEncodings)); ++i)
        if (name == kHlslEncodings[i]) return i;
    return -1;
}

constexpr std::uint32_t kProbes = 1u << 16;

// The kernel: encoding < 0 is the skeleton (normal in, normal out).
std::string kernel_source(int encoding, std::size_t size_bytes) {
    std::ostringstream s;
    s << "#include \"zhc.hlsl\"\n"
         "[[vk::binding(0, 0)]] ByteAddressBuffer probes;\n"
         "[[vk::binding(1, 0)]] StructuredBuffer<float4> normals;\n"
         "[[vk::binding(2, 0)]] RWStructuredBuffer<float4> result;\n"
         "static const uint kMask = "
      << (kProbes - 1) << "u;\n";
    s << "[numthreads(64, 1, 1)]\nvoid main(uint3 id : SV_DispatchThreadID)\n{\n"
         "    uint i = id.x;\n"
         "    float3 n = normals[(i + (i >> 16)) & kMask].xyz;\n";
    if (encoding < 0) {
        s << "    result[i] = float4(n, 0.0f);\n}\n";
        return s.str();
    }
    const std::size_t words = size_bytes / 4;
    s << "    const ZhcFormat f = zhc_default_format(" << encoding << "u);\n"
      << "    uint base = (i & kMask) * " << size_bytes << "u;\n"
      << "    uint w[27];\n"
      << "    [unroll] for (uint j = 0u; j < 27u; ++j) w[j] = j < " << words << "u ? probes.Load(base + 4u * j) : 0u;\n"
      << "    result[i] = float4(zhc_irradiance(w, f, n), 0.0f);\n}\n";
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
    std::ifstream in(dis);
    std::string line;
    bool inside = false;
    int count = 0;
    while (std::getline(in, line)) {
        auto has = [&](const char* op) {
            const std::size_t p = line.find(op);
            if (p == std::string::npos) return false;
            const std::size_t e = p + std::strlen(op);
            return e == line.size() || line[e] == ' ';
        };
        if (has("OpFunction")) {
            inside = true;
            continue;
        }
        if (has("OpFunctionEnd")) {
            inside = false;
            continue;
        }
        if (!inside || has("OpFunctionParameter") || has("OpLabel")) continue;
        if (line.find_first_not_of(' ') != std::string::npos) ++count;
    }
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

struct Row {
    std::string name;
    std::size_t bytes = 0;
    int instructions = -1;
    int eval_instructions = -1;
    double ns = NAN;
};

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
        std::unique_ptr<vk::Kernel> kernel;
        std::vector<double> seconds;
    };
    std::vector<Timed> timed;
    auto add = [&](Row row, const Compiled& c, const std::vector<std::uint8_t>& probes) {
        Timed t;
        t.row = std::move(row);
        if (!c.spirv.empty()) {
            const std::size_t sizes[3] = {std::max<std::size_t>(16, probes.size()), normals.size() * 4, std::size_t(evals) * 16};
            t.kernel = context->make_kernel(c.spirv, sizes, &error);
            if (!t.kernel) std::fprintf(stderr, "%s: %s\n", t.row.name.c_str(), error.c_str());
            else {
                if (!probes.empty()) std::memcpy(t.kernel->data(0), probes.data(), probes.size());
                std::memcpy(t.kernel->data(1), normals.data(), normals.size() * 4);
            }
        }
        timed.push_back(std::move(t));
    };
    const Compiled skeleton = compile(dir.string(), "skeleton", kernel_source(-1, 0));
    if (skeleton.spirv.empty()) {
        std::fprintf(stderr, "skeleton kernel failed to compile\n");
        return 1;
    }
    Row sk;
    sk.name = "(skeleton)";
    sk.instructions = skeleton.instructions;
    sk.eval_instructions = 0;
    add(sk, skeleton, {});
    for (const Codec& codec : codecs()) {
        Row row;
        row.name = std::string(codec.name);
        row.bytes = codec.size_bytes;
        const int id = hlsl_encoding(codec.name);
        if (id < 0) {
            std::fprintf(stderr, "%s: no HLSL encoding\n", row.name.c_str());
            add(row, Compiled{}, {});
            continue;
        }
        const Compiled c = compile(dir.string(), row.name, kernel_source(id, codec.size_bytes));
        row.instructions = c.instructions;
        row.eval_instructions = c.instructions >= 0 ? c.instructions - skeleton.instructions : -1;
        add(row, c, make_probes(codec));
    }
    for (int r = 0; r <= repeats; ++r)
        for (Timed& t : timed) {
            if (!t.kernel) continue;
            const double s = t.kernel->dispatch(evals / 64, &error);
            if (s < 0) {
                std::fprintf(stderr, "%s: %s\n", t.row.name.c_str(), error.c_str());
                t.kernel.reset();
                continue;
            }
            if (r > 0) t.seconds.push_back(s);
        }
    std::vector<Row> rows;
    for (Timed& t : timed) {
        if (t.kernel && !t.seconds.empty()) {
            std::sort(t.seconds.begin(), t.seconds.end());
            t.row.ns = t.seconds[t.seconds.size() / 2] / evals * 1e9;
        }
        rows.push_back(t.row);
    }
    timed.clear();  // kernels before the context
    double base = NAN;
    for (const Row& r : rows)
        if (r.name == "sh3") base = r.ns;

    std::printf("bench_runtime: irradiance from stored words, runtime/zhc.hlsl on %s\n", context->device_name().c_str());
    std::printf("%u evaluations per dispatch, median of %d; SPIR-V after spirv-opt -O (function-body instructions)\n\n", evals,
                repeats);
    std::printf("%-22s %6s %10s %12s %12s %10s\n", "encoding", "bytes", "SPIR-V", "SPIR-V-skel", "ns/eval", "vs sh3");
    for (const Row& r : rows)
        std::printf("%-22s %6zu %10d %12d %12.2f %10.2f\n", r.name.c_str(), r.bytes, r.instructions, r.eval_instructions, r.ns,
                    r.ns / base);
    if (!json.empty()) {
        std::ofstream out(json);
        out << "{\n  \"benchmark\": \"runtime\",\n  \"device\": \"" << context->device_name() << "\",\n  \"evaluations\": "
            << evals << ",\n  \"repeats\": " << repeats << ",\n  \"rows\": [\n";
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const Row& r = rows[i];
            char buf[512];
            std::snprintf(buf, sizeof buf,
                          "    {\"encoding\": \"%s\", \"bytes\": %zu, \"spirv_instructions\": %d, "
                          "\"spirv_instructions_minus_skeleton\": %d, \"ns_per_eval\": %.4f, \"ratio_to_sh3\": %.4f}%s\n",
                          r.name.c_str(), r.bytes, r.instructions, r.eval_instructions, std::isfinite(r.ns) ? r.ns : -1.0,
                          std::isfinite(r.ns / base) ? r.ns / base : -1.0, i + 1 < rows.size() ? "," : "");
            out << buf;
        }
        out << "  ]\n}\n";
        if (!out) {
            std::fprintf(stderr, "cannot write %s\n", json.c_str());
            return 1;
        }
        std::printf("\nwrote %s\n", json.c_str());
    }
    if (keep.empty()) fs::remove_all(dir);
    return 0;
}
