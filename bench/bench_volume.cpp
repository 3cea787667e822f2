// bench_volume — GPU volume layouts: error per GPU byte (docs/runtime.md, "GPU volume layouts").
//
// Two baked probe grids: the demo's (codec/bake default_scene, 8x8x4, as `zhc demo` bakes it) and a
// baked glTF scene (tests/data/gltf/gi_nodes.glb: 1,500 instanced triangles, KHR_lights_punctual,
// the default 8x8x8 grid over its bounds). Reference: the exact trilinear SH3 volume of the baked
// probes stored as sh3 (float), sampled with zhc_volume_irradiance_d (double).
// Rows:
//  * packed encodings in an integer texture, the 8-probe decode + blend in the shader: exactly
//    zhc_volume_irradiance_d of that encoding's volume (error = the encoding's own error);
//  * filterable layouts (runtime/zhc_volume_layouts.hpp): texel values rounded to their storage
//    format, hardware trilinear = the trilinear blend of the rounded values (filter-weight
//    quantisation of real GPUs not modelled), reconstructed SH3, irradiance in double.
// Error of one sample: |E - E_ref| (RGB Euclidean) / mean over the grid's samples of |E_ref|;
// reported: mean, 95th percentile and max over N random points in the grid's box with random unit
// normals (N = 100,000 by default, fixed seeds). Benchmarks never decide pass/fail.
//
// Sample cost (when built with glslangValidator, spirv-opt and spirv-dis): one HLSL compute kernel
// per row that reads a position and a normal and writes the irradiance of one sample (packed rows:
// zhc.hlsl's decode of the 8 corner probes, unrolled, no weight-0 skip; filterable rows: one
// SampleLevel per texture at uvw = (clamp((p - origin) / spacing, 0, n - 1) + 0.5) / n, the
// reconstruction, zhc_sh3_irradiance), HLSL -> SPIR-V (glslangValidator) -> spirv-opt -O, counted as
// bench_runtime counts (function-body instructions), minus a skeleton kernel that writes p + n.
// Timed (when built with Vulkan): the same kernels on Mesa lavapipe through tests/vk's harness
// (sampled 3D images, linear clamp-to-edge sampler), demo grid, 65,536 distinct samples, 2^18
// invocations per dispatch, median of 9 after a warm-up, kernels in interleaved rounds; the packed
// sh3 row is the baseline. The GPU's results are compared with the CPU model at the same inputs.
//
// Leak data's cost (a second table, "leak_rows" in the JSON): zh3_q16 stored bytes on the demo grid
// in two kernel families, each plain, with masks (the demo bake's validity and visibility, combined:
// ZHC_VOLUME_MASK), with planes (the demo bake's cell planes: ZHC_VOLUME_PLANE), with a plane through
// the centre of every cell (every sample cut), and with validity + planes (what a default bake
// writes); masks and plane entries follow the probe words in the buffer. "8 fetches": the packed
// rows' kernel (8 corner decodes unrolled, none skipped) with the weights kept by zhc.hlsl's
// zhc_volume_plane_keep and the masks, renormalised; "zhc.hlsl": zhc_volume_irradiance itself (a
// corner loop that skips weight-0 corners, and so dropped ones). SPIR-V and lavapipe ns as above, in
// the same interleaved rounds; "vs plain": the ratio to the family's plain row; "cut": the share of
// the timed samples where the data drops a corner of non-zero weight. The GPU's results are
// compared with zhc_volume_irradiance_d of the same volume.
//
// Engine layouts (a third table, "engine_rows" in the JSON; codec/probe/engine_layouts.h,
// docs/engine-layouts.md): each engine's stored bytes of every probe, the texel values its shader
// reads, blended trilinearly at the sample (what a hardware filter does to the textures, before the
// shader decodes: Unity's ratios then multiply the blended L0, Source 2's RGBM the blended
// multiplier; Godot and RealityKit blend on the CPU, tetrahedrally in the engine, trilinearly here),
// then the engine's shader; error against the same reference, on both grids. Beside it: the
// entry's bytes, the engine's GPU and file bytes per probe, its fetches per sample, its
// interpolation, whether it can carry zhc's leak data (a hardware-filtered layout blends the
// corners before the shader: no corner can be dropped), and the CPU model's ns per sample (one
// thread, double: the blend of the texels and the shader; the engines' GPU shaders are not
// compiled here).
//
// Usage: bench_volume [--samples N] [--gltf FILE] [--json FILE] [--keep DIR]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <random>
#include <string>
#include <vector>

#include "codec/bake/scene.h"
#include "codec/probe/codec.h"
#include "codec/probe/engine_layouts.h"
#include "codec/probe/probe_set.h"
#include "formats/io/file_io.h"
#include "formats/scene/scene_gltf.h"
#include "runtime/zhc_runtime.h"
#include "runtime/zhc_volume_layouts.hpp"
#include "tests/vk/volume_kernels.h"
#include "spirv_count.h"
#include "timing.h"
#ifdef ZHC_VK_TIMING
#include <vulkan/vulkan.h>

#include "vk_compute.h"
#endif

#include <unistd.h>

namespace {

using namespace zhc;
namespace L = zhc_layouts;

struct Grid {
    std::string name;
    std::vector<Sh3Radiance> probes;
    ProbeLayout layout;
    ProbeLeakData leak;  // the bake's validity, visibility masks and cell planes
};

struct Stats {
    double mean = 0, p95 = 0, max = 0;
};

struct Row {
    std::string name, kind, textures;
    double bytes = 0;
    int fetches = 0;       // texture fetches (filterable) or probe decodes (packed) per sample
    int spirv = -1;        // SPIR-V instructions minus the skeleton; -1 not measured
    std::string source;    // the HLSL kernel
    std::vector<std::uint32_t> spv;  // its optimised SPIR-V
    bool filtered = false;
    L::Layout layout = L::Layout::kSh3F32;
    double ns = NAN;         // lavapipe ns per sample; NAN not measured
    double vs_model = NAN;   // max |GPU - CPU model| / mean |model| over the timed samples
    Stats err[2];
    // Leak-data rows (zhc_volume_irradiance of zh3_q16 with masks / planes): which data the kernel and
    // the timed volume use; leak_row false for the layout rows above.
    bool leak_row = false, unrolled = false, masks = false, planes = false, every_cell = false;
    double cut = NAN;  // share of the timed samples where the leak data drops a corner
    // Engine rows (codec/probe/engine_layouts.h): the layout, and the CPU model's ns per sample.
    const EngineLayoutInfo* engine = nullptr;
    double cpu_ns = NAN;
};

// An engine layout's volume: every probe's texels (engine_layouts.h), blended trilinearly at the
// sample as the engine's filter or CPU does, then its shader. Corners as zhc__volume_axis gives
// them (an axis of one probe: that probe).
struct EngineVolume {
    const EngineLayoutInfo* info = nullptr;
    std::vector<double> texels;  // count x texel_count
    void sample(const zhc_volume& grid, const double p[3], const double n[3], double out[3]) const {
        std::uint32_t i0[3], i1[3];
        double f[3];
        for (int c = 0; c < 3; ++c) {
            zhc__volume_axis(p[c], grid.origin[c], grid.spacing[c], grid.counts[c], &i0[c], &f[c]);
            i1[c] = std::min(i0[c] + 1, grid.counts[c] - 1);
        }
        const int nt = info->texel_count;
        double blend[kMaxEngineTexels] = {};
        for (int k = 0; k < 8; ++k) {
            const double w = ((k & 1) ? f[0] : 1 - f[0]) * ((k >> 1 & 1) ? f[1] : 1 - f[1]) * ((k >> 2) ? f[2] : 1 - f[2]);
            if (w == 0) continue;
            const std::size_t q = ((k & 1) ? i1[0] : i0[0]) +
                                  std::size_t(grid.counts[0]) * (((k >> 1) & 1 ? i1[1] : i0[1]) + std::size_t(grid.counts[1]) * ((k >> 2) ? i1[2] : i0[2]));
            for (int t = 0; t < nt; ++t) blend[t] += w * texels[q * std::size_t(nt) + std::size_t(t)];
        }
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const Vec3 unit = len > 0 ? Vec3{n[0] / len, n[1] / len, n[2] / len} : Vec3{0, 0, 1};
        const Rgb e = info->shade(blend, unit);
        for (int c = 0; c < 3; ++c) out[c] = e[c];
    }
};

EngineVolume engine_volume(const std::vector<Sh3Radiance>& probes, const EngineLayoutInfo& info) {
    EngineVolume v;
    v.info = &info;
    const Codec& codec = *find_codec(info.codec);
    std::vector<std::uint8_t> bytes(codec.size_bytes);
    v.texels.resize(probes.size() * std::size_t(info.texel_count));
    for (std::size_t i = 0; i < probes.size(); ++i) {
        codec.encode(probes[i], CodecOptions{}, bytes.data(), nullptr);
        info.texels(bytes.data(), v.texels.data() + i * std::size_t(info.texel_count));
    }
    return v;
}

bool encode(const Grid& g, const char* rep, std::vector<std::uint8_t>* payload, zhc_volume* vol, zhc_probe_format* fmt) {
    auto set = encode_probe_set(g.probes, rep, CodecOptions{}, g.layout);
    if (!set) {
        std::fprintf(stderr, "%s: %s\n", rep, set.error().message.c_str());
        return false;
    }
    *payload = set->payload;
    if (zhc_probe_format_init(fmt, rep) != ZHC_OK) return false;
    const ProbeGrid& pg = g.layout.grid;
    const double origin[3] = {pg.origin.x, pg.origin.y, pg.origin.z}, spacing[3] = {pg.spacing.x, pg.spacing.y, pg.spacing.z};
    const std::uint32_t counts[3] = {pg.counts[0], pg.counts[1], pg.counts[2]};
    return zhc_volume_init(vol, fmt, payload->data(), payload->size(), origin, spacing, counts) == ZHC_OK;
}

Stats stats(std::vector<double> e) {
    Stats s;
    if (e.empty()) return s;
    std::sort(e.begin(), e.end());
    double sum = 0;
    for (double x : e) sum += x;
    s.mean = sum / double(e.size());
    s.p95 = e[std::min(e.size() - 1, static_cast<std::size_t>(0.95 * double(e.size())))];
    s.max = e.back();
    return s;
}

double norm3(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// ---- SPIR-V instruction counts (kernels: tests/vk/volume_kernels.h) --------------------------

using zhc_volume_kernels::filter_kernel;
using zhc_volume_kernels::packed_kernel;
using zhc_volume_kernels::skeleton_kernel;

#ifdef ZHC_GLSLANG
bool run(const std::string& command) {
    const int rc = std::system(command.c_str());
    if (rc != 0) std::fprintf(stderr, "failed (%d): %s\n", rc, command.c_str());
    return rc == 0;
}
std::string quote(const std::string& s) { return "'" + s + "'"; }

// HLSL -> SPIR-V -> spirv-opt -O -> function-body instructions of the disassembly (-1: failed);
// the optimised binary in *words when given.
int spirv_instructions(const std::string& dir, const std::string& name, const std::string& source,
                       std::vector<std::uint32_t>* words = nullptr) {
    const std::string hlsl = dir + "/" + name + ".hlsl", raw = dir + "/" + name + ".spv", opt = dir + "/" + name + ".opt.spv",
                      dis = dir + "/" + name + ".opt.spvasm";
    std::ofstream(hlsl) << source;
    if (!run(quote(ZHC_GLSLANG) + " -D -V -S comp -e main -I" + quote(ZHC_RUNTIME_DIR) + " " + quote(hlsl) + " -o " + quote(raw) +
             " > " + quote(dir + "/" + name + ".log") + " 2>&1"))
        return -1;
    if (!run(quote(ZHC_SPIRV_OPT) + " -O " + quote(raw) + " -o " + quote(opt))) return -1;
    if (!run(quote(ZHC_SPIRV_DIS) + " --no-header " + quote(opt) + " -o " + quote(dis))) return -1;
    const int count = bench::spirv_function_instructions(dis);
#ifdef ZHC_VK_TIMING
    if (words) *words = vk::read_spirv(opt);
#else
    (void)words;
#endif
    return count;
}
#endif

// The leak-data kernels: zh3_q16 words at word 0 of binding 0, the combined masks (4 per word) at
// word `mask_base`, the plane entries (2 words per probe) at `plane_base`. unrolled false:
// zhc_volume_irradiance of zhc.hlsl with ZHC_VOLUME_MASK and / or ZHC_VOLUME_PLANE (a loop over the
// corners that skips weight-0 ones); true: the packed rows' kernel (8 corner decodes unrolled, none
// skipped) with the weights kept by zhc.hlsl's zhc_volume_plane_keep and the masks, renormalised.
std::string leak_kernel(bool masks, bool planes, bool unrolled, std::uint32_t mask_base, std::uint32_t plane_base) {
    std::ostringstream s;
    s << zhc_volume_kernels::kKernelHead
      << "[[vk::binding(0, 0)]] ByteAddressBuffer probeWords;\n#define ZHC_VOLUME_WORD(i) probeWords.Load(4u * (i))\n";
    if (masks) s << "#define ZHC_VOLUME_MASK(i) ((probeWords.Load(4u * (" << mask_base << "u + ((i) >> 2))) >> (8u * ((i) & 3u))) & 0xFFu)\n";
    if (planes) s << "#define ZHC_VOLUME_PLANE(i) probeWords.Load2(4u * (" << plane_base << "u + 2u * (i)))\n";
    s << "#include \"zhc.hlsl\"\n"
      << zhc_volume_kernels::kKernelMainHead
      << "    ZhcVolume v;\n    v.origin = gOrigin.xyz;\n    v.spacing = gSpacing.xyz;\n    v.counts = gCounts.xyz;\n"
         "    const ZhcFormat f = zhc_default_format("
      << ZHC_ENC_ZH3_Q16 << "u);\n";
    if (!unrolled) {
        s << "    float3 e = zhc_volume_irradiance(v, f, p, nrm);\n";
    } else {
        s << "    uint3 n = max(v.counts, uint3(1u, 1u, 1u));\n"
             "    float3 t = (p - v.origin) / v.spacing;\n"
             "    t = float3(t.x >= 0.0f ? t.x : 0.0f, t.y >= 0.0f ? t.y : 0.0f, t.z >= 0.0f ? t.z : 0.0f);\n"
             "    t = min(t, float3(n - 1u));\n"
             "    uint3 i0 = min(uint3(t), max(n, uint3(2u, 2u, 2u)) - 2u);\n"
             "    float3 fr = t - float3(i0);\n"
             "    uint keep = 0xFFu;\n";
        if (planes) s << "    keep = zhc_volume_plane_keep(ZHC_VOLUME_PLANE(i0.x + n.x * (i0.y + n.y * i0.z)), v, i0, p);\n";
        s << "    float w[8], wm[8];\n    float sum = 0.0f;\n"
             "    [unroll] for (uint m = 0u; m < 8u; ++m)\n    {\n"
             "        uint3 b = uint3(m & 1u, (m >> 1) & 1u, m >> 2);\n"
             "        w[m] = (b.x != 0u ? fr.x : 1.0f - fr.x) * (b.y != 0u ? fr.y : 1.0f - fr.y) * (b.z != 0u ? fr.z : 1.0f - fr.z);\n"
             "        uint bit = (keep >> m) & 1u;\n";
        if (masks) s << "        uint3 q = i0 + b;\n        bit &= (ZHC_VOLUME_MASK(q.x + n.x * (q.y + n.y * q.z)) >> (7u - m)) & 1u;\n";
        s << "        wm[m] = bit != 0u ? w[m] : 0.0f;\n        sum += wm[m];\n    }\n"
             "    ZhcSH3 acc;\n"
             "    [unroll] for (int i = 0; i < 9; ++i) acc.c[i] = float3(0.0f, 0.0f, 0.0f);\n"
             "    [unroll] for (uint c = 0u; c < 8u; ++c)\n    {\n"
             "        uint3 b = uint3(c & 1u, (c >> 1) & 1u, c >> 2);\n"
             "        float wc = sum > 0.0f ? wm[c] / sum : w[c];\n"
             "        uint3 q = i0 + b;\n"
             "        ZhcSH3 s = zhc_volume_probe(q.x + n.x * (q.y + n.y * q.z), f);\n"
             "        [unroll] for (int j = 0; j < 9; ++j) acc.c[j] += wc * s.c[j];\n"
             "    }\n"
             "    float3 e = zhc_sh3_irradiance(acc, zhc_normalize_or_z(nrm));\n";
    }
    s << zhc_volume_kernels::kKernelMainTail;
    return s.str();
}

// A plane through the centre of every cell (random normal code, the corners' sides), "no plane" on
// the probes that start no cell: every sample of the grid is cut by its cell's plane.
std::vector<std::uint8_t> planes_every_cell(const zhc_volume& v, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<std::uint8_t> out;
    for (std::uint32_t z = 0; z < v.counts[2]; ++z)
        for (std::uint32_t y = 0; y < v.counts[1]; ++y)
            for (std::uint32_t x = 0; x < v.counts[0]; ++x) {
                std::uint8_t e[5] = {127, 127, 0x00, 0x80, 0};
                const std::uint32_t i0[3] = {x, y, z};
                bool last = false;
                for (int c = 0; c < 3; ++c) last = last || (v.counts[c] > 1 && i0[c] + 1 == v.counts[c]);
                if (!last) {
                    e[0] = std::uint8_t(rng() % 255);
                    e[1] = std::uint8_t(rng() % 255);
                    e[2] = e[3] = 0;  // offset 0: through the centre
                    double n[3];
                    zhc_plane_normal(e[0], e[1], n);
                    for (int k = 0; k < 8; ++k) {
                        double s = 0;
                        for (int c = 0; c < 3; ++c) s += n[c] * ((((k >> c) & 1) - 0.5) * v.spacing[c]);
                        if (s >= 0) e[4] = std::uint8_t(e[4] | (1u << k));
                    }
                }
                out.insert(out.end(), e, e + 5);
            }
    return out;
}

// Whether the leak data of v drops a corner of non-zero weight at p (zhc_volume_sh3's rules).
bool leak_cuts(const zhc_volume& v, const double p[3]) {
    std::uint32_t i0[3];
    double f[3];
    for (int c = 0; c < 3; ++c) zhc__volume_axis(p[c], v.origin[c], v.spacing[c], v.counts[c], &i0[c], &f[c]);
    const std::size_t cell = i0[0] + std::size_t(v.counts[0]) * (i0[1] + std::size_t(v.counts[1]) * i0[2]);
    int side = 0, has = 0;
    unsigned sides = 0;
    if (v.planes) has = zhc__volume_plane_side(&v, cell, i0, p, &side, &sides);
    for (int k = 0; k < 8; ++k) {
        const double w = ((k & 1) ? f[0] : 1 - f[0]) * ((k >> 1 & 1) ? f[1] : 1 - f[1]) * ((k >> 2) ? f[2] : 1 - f[2]);
        if (w == 0) continue;
        const std::size_t q = cell + std::size_t(k & 1) + std::size_t(v.counts[0]) * (std::size_t((k >> 1) & 1) + std::size_t(v.counts[1]) * std::size_t(k >> 2));
        if (v.validity && !v.validity[q]) return true;
        if (v.visibility && !((v.visibility[q] >> (7 - k)) & 1)) return true;
        if (has && int((sides >> k) & 1) != side) return true;
    }
    return false;
}

}  // namespace

int main(int argc, char** argv) {
    int samples = 100000;
    std::string json, keep, gltf = ZHC_GLTF_SCENE;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--samples" && i + 1 < argc) samples = std::max(100, std::atoi(argv[++i]));
        else if (a == "--gltf" && i + 1 < argc) gltf = argv[++i];
        else if (a == "--json" && i + 1 < argc) json = argv[++i];
        else if (a == "--keep" && i + 1 < argc) keep = argv[++i];
        else {
            std::fprintf(stderr, "usage: %s [--samples N] [--gltf FILE] [--json FILE] [--keep DIR]\n", argv[0]);
            return 2;
        }
    }
    std::vector<Grid> grids;
    {
        const Scene scene = default_scene();
        BakeOptions options;
        options.visibility_masks = true;  // the leak rows' masks
        ProbeLeakData leak;
        auto baked = bake_scene(scene, options, nullptr, &leak);
        if (!baked) {
            std::fprintf(stderr, "demo bake: %s\n", baked.error().message.c_str());
            return 1;
        }
        grids.push_back({"demo", *baked, probe_layout(scene.probes), leak});
    }
    {
        auto bytes = read_file_bytes(gltf, std::uint64_t(1) << 30);
        if (!bytes) {
            std::fprintf(stderr, "%s\n", bytes.error().message.c_str());
            return 1;
        }
        auto scene = parse_scene_gltf(*bytes, gltf);
        if (!scene) {
            std::fprintf(stderr, "%s\n", scene.error().message.c_str());
            return 1;
        }
        auto baked = bake_scene(*scene);
        if (!baked) {
            std::fprintf(stderr, "%s: %s\n", gltf.c_str(), baked.error().message.c_str());
            return 1;
        }
        grids.push_back({"gltf", *baked, probe_layout(scene->probes), {}});
    }

    const char* packed[] = {"sh3", "zh3_q16", "sh2_q", "sh3_q28"};
    std::string device;
    std::vector<Row> rows;
    for (const char* p : packed) {
        Row r;
        r.name = p;
        r.kind = "integer texture, 8-probe decode + blend in the shader";
        r.textures = "stored bytes";
        r.bytes = double(find_codec(p)->size_bytes);
        r.fetches = 8;
        r.source = packed_kernel(zhc_encoding_from_name(p));
        rows.push_back(r);
    }
    for (L::Layout l : L::kAllLayouts) {
        Row r;
        r.name = L::layout_name(l);
        r.kind = "hardware trilinear";
        r.bytes = double(L::layout_bytes_per_probe(l));
        std::vector<L::TextureSpec> t = L::layout_textures(l);
        for (std::size_t i = 0; i < t.size();) {
            std::size_t j = i;
            while (j < t.size() && t[j].storage == t[i].storage && t[j].components == t[i].components) ++j;
            if (!r.textures.empty()) r.textures += " + ";
            r.textures += std::to_string(j - i) + " " + L::storage_name(t[i].storage, t[i].components);
            i = j;
        }
        r.fetches = static_cast<int>(t.size());
        r.source = filter_kernel(l);
        r.filtered = true;
        r.layout = l;
        rows.push_back(r);
    }
    for (const EngineLayoutInfo& info : engine_layouts()) {
        Row r;
        r.name = std::string(info.codec);
        r.kind = std::string(info.interpolation);
        r.textures = std::string(info.engine);
        r.bytes = double(find_codec(info.codec)->size_bytes);
        r.fetches = info.fetches;
        r.engine = &info;
        rows.push_back(r);
    }
    {
        // Leak rows on the demo grid: masks after the zh3_q16 words, plane entries after the masks.
        const std::uint64_t count = std::uint64_t(grids[0].layout.grid.counts[0]) * grids[0].layout.grid.counts[1] *
                                    grids[0].layout.grid.counts[2];
        const std::uint32_t mask_base = static_cast<std::uint32_t>(count * 4), plane_base = mask_base + static_cast<std::uint32_t>((count + 3) / 4);
        const struct {
            const char* name;
            bool masks, planes, every_cell;
        } leak_rows[] = {{"plain", false, false, false},
                         {"+ masks", true, false, false},
                         {"+ planes", false, true, false},
                         {"+ planes, every cell", false, true, true},
                         {"+ validity + planes", true, true, false}};
        for (int unrolled = 1; unrolled >= 0; --unrolled)
        for (const auto& lr : leak_rows) {
            Row r;
            r.name = std::string(unrolled ? "8 fetches " : "zhc.hlsl ") + lr.name;
            r.kind = unrolled ? "zh3_q16 stored bytes, 8 corner decodes unrolled (the packed rows' kernel), kept weights"
                              : "zh3_q16 stored bytes, zhc.hlsl zhc_volume_irradiance (corner loop, weight-0 corners skipped)";
            r.textures = "stored bytes";
            r.bytes = 16 + (lr.masks ? 1 : 0) + (lr.planes ? 5 : 0);
            r.fetches = 8;
            r.source = leak_kernel(lr.masks, lr.planes, unrolled != 0, mask_base, plane_base);
            r.leak_row = true;
            r.unrolled = unrolled != 0;
            r.masks = lr.masks;
            r.planes = lr.planes;
            r.every_cell = lr.every_cell;
            rows.push_back(r);
        }
    }

    for (std::size_t gi = 0; gi < grids.size(); ++gi) {
        const Grid& g = grids[gi];
        std::vector<std::uint8_t> ref_bytes;
        zhc_volume ref;
        zhc_probe_format ref_fmt;
        if (!encode(g, "sh3", &ref_bytes, &ref, &ref_fmt)) return 1;
        // Sample points and normals, and the reference.
        std::mt19937_64 rng(1234 + gi);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        std::normal_distribution<double> gauss;
        std::vector<std::array<double, 6>> pts(static_cast<std::size_t>(samples));
        std::vector<std::array<double, 3>> eref(pts.size());
        double mean_ref = 0;
        for (std::size_t s = 0; s < pts.size(); ++s) {
            for (int c = 0; c < 3; ++c)
                pts[s][static_cast<std::size_t>(c)] = ref.origin[c] + u(rng) * ref.spacing[c] * double(ref.counts[c] - 1);
            for (int c = 3; c < 6; ++c) pts[s][static_cast<std::size_t>(c)] = gauss(rng);
            zhc_volume_irradiance_d(&ref, pts[s].data(), pts[s].data() + 3, eref[s].data());
            mean_ref += norm3(eref[s].data());
        }
        mean_ref /= double(pts.size());
        std::size_t ri = 0;
        for (const char* p : packed) {
            std::vector<std::uint8_t> bytes;
            zhc_volume vol;
            zhc_probe_format fmt;
            if (!encode(g, p, &bytes, &vol, &fmt)) return 1;
            std::vector<double> e(pts.size());
            for (std::size_t s = 0; s < pts.size(); ++s) {
                double rgb[3];
                zhc_volume_irradiance_d(&vol, pts[s].data(), pts[s].data() + 3, rgb);
                const double d[3] = {rgb[0] - eref[s][0], rgb[1] - eref[s][1], rgb[2] - eref[s][2]};
                e[s] = norm3(d) / mean_ref;
            }
            rows[ri++].err[gi] = stats(e);
        }
        for (L::Layout l : L::kAllLayouts) {
            const auto tex = L::volume_textures(ref, l);
            std::vector<double> e(pts.size());
            for (std::size_t s = 0; s < pts.size(); ++s) {
                double rgb[3];
                L::sample_irradiance(ref, l, tex, pts[s].data(), pts[s].data() + 3, rgb);
                const double d[3] = {rgb[0] - eref[s][0], rgb[1] - eref[s][1], rgb[2] - eref[s][2]};
                e[s] = norm3(d) / mean_ref;
            }
            rows[ri++].err[gi] = stats(e);
        }
        for (const EngineLayoutInfo& info : engine_layouts()) {
            const EngineVolume ev = engine_volume(g.probes, info);
            std::vector<double> e(pts.size());
            const auto t0 = std::chrono::steady_clock::now();
            for (std::size_t s = 0; s < pts.size(); ++s) {
                double rgb[3];
                ev.sample(ref, pts[s].data(), pts[s].data() + 3, rgb);
                const double d[3] = {rgb[0] - eref[s][0], rgb[1] - eref[s][1], rgb[2] - eref[s][2]};
                e[s] = norm3(d) / mean_ref;
            }
            const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / double(pts.size());
            if (gi == 0) rows[ri].cpu_ns = ns;
            rows[ri++].err[gi] = stats(e);
        }
        std::printf("grid %s: %u x %u x %u probes, %d samples, mean |E_ref| %.4g\n", g.name.c_str(), ref.counts[0], ref.counts[1],
                    ref.counts[2], samples, mean_ref);
    }

#ifdef ZHC_GLSLANG
    {
        namespace fs = std::filesystem;
        const fs::path dir = keep.empty() ? fs::temp_directory_path() / ("zhc_bench_volume_" + std::to_string(::getpid())) : fs::path(keep);
        fs::create_directories(dir);
        const int skeleton = spirv_instructions(dir.string(), "skeleton", skeleton_kernel());
        for (Row& r : rows) {
            if (r.engine) continue;  // the engines' shaders are not compiled here
            const int c = spirv_instructions(dir.string(), r.name, r.source, &r.spv);
            r.spirv = c >= 0 && skeleton >= 0 ? c - skeleton : -1;
        }
        if (keep.empty()) fs::remove_all(dir);
    }
#else
    if (!keep.empty()) std::fprintf(stderr, "--keep: built without glslangValidator / spirv-opt / spirv-dis: no SPIR-V counts\n");
#endif
#ifdef ZHC_VK_TIMING
    // lavapipe: every kernel on the demo grid, 65,536 distinct samples, 2^18 invocations per
    // dispatch, median of 9 after a warm-up round, kernels in interleaved rounds.
    {
        if (std::strlen(ZHC_LVP_ICD) > 0) vk::force_icd(ZHC_LVP_ICD);
        std::string error;
        auto context = vk::Context::create(true, &error);
        if (!context) {
            std::fprintf(stderr, "Vulkan: %s (no lavapipe timing)\n", error.c_str());
        } else {
            device = context->device_name();
            const Grid& g = grids[0];
            std::vector<std::uint8_t> ref_bytes;
            zhc_volume ref;
            zhc_probe_format ref_fmt;
            if (!encode(g, "sh3", &ref_bytes, &ref, &ref_fmt)) return 1;
            constexpr std::uint32_t kSamples = 65536, kEvals = 1u << 18;
            constexpr int kRepeats = 9;
            std::vector<float> inputs(kSamples * 8);
            std::mt19937_64 rng(99);
            std::uniform_real_distribution<double> u(0.0, 1.0);
            std::normal_distribution<double> gauss;
            for (std::uint32_t i = 0; i < kSamples; ++i) {
                for (int c = 0; c < 3; ++c) {
                    inputs[8 * i + static_cast<std::uint32_t>(c)] =
                        static_cast<float>(ref.origin[c] + u(rng) * ref.spacing[c] * double(ref.counts[c] - 1));
                    inputs[8 * i + 4 + static_cast<std::uint32_t>(c)] = static_cast<float>(gauss(rng));
                }
            }
            float grid_buf[12] = {};
            for (int c = 0; c < 3; ++c) {
                grid_buf[c] = static_cast<float>(ref.origin[c]);
                grid_buf[4 + c] = static_cast<float>(ref.spacing[c]);
                std::memcpy(&grid_buf[8 + c], &ref.counts[c], 4);
            }
            struct Timed {
                Row* row;
                std::unique_ptr<vk::Kernel> kernel;
                std::vector<double> seconds;
                zhc_volume vol{};
                std::vector<std::uint8_t> bytes;
                std::vector<std::vector<std::uint8_t>> tex;
                std::vector<std::uint8_t> payload, validity, visibility, planes;  // leak rows: what vol points at
            };
            std::vector<Timed> timed;
            timed.reserve(rows.size());
            for (Row& r : rows) {
                if (r.spv.empty()) continue;
                Timed t;
                t.row = &r;
                std::vector<vk::Image3D> images;
                if (r.filtered) {
                    t.tex = L::volume_textures(ref, r.layout);
                    const auto spec = L::layout_textures(r.layout);
                    for (std::size_t i = 0; i < spec.size(); ++i) {
                        VkFormat f = VK_FORMAT_E5B9G9R9_UFLOAT_PACK32;
                        if (spec[i].storage == L::Storage::kF32) f = VK_FORMAT_R32G32B32A32_SFLOAT;
                        if (spec[i].storage == L::Storage::kF16) f = VK_FORMAT_R16G16B16A16_SFLOAT;
                        if (spec[i].storage == L::Storage::kSnorm8) f = spec[i].components == 4 ? VK_FORMAT_R8G8B8A8_SNORM : VK_FORMAT_R8_SNORM;
                        images.push_back({static_cast<std::uint32_t>(f), ref.counts[0], ref.counts[1], ref.counts[2], t.tex[i]});
                    }
                } else if (r.leak_row) {
                    zhc_probe_format fmt;
                    if (!encode(g, "zh3_q16", &t.bytes, &t.vol, &fmt)) return 1;
                    const std::size_t count = g.probes.size();
                    const bool has_leak = g.leak.validity.size() == count && g.leak.planes.size() == 5 * count;
                    if (!has_leak && (r.masks || r.planes)) {
                        std::fprintf(stderr, "%s: the demo bake has no validity or planes\n", r.name.c_str());
                        continue;
                    }
                    // Words: the probes, then the combined masks (valid ? visibility : 0, 4 per word;
                    // absent visibility: 0xFF), then 2 words per plane entry; the model's volume sees
                    // the same data.
                    t.payload = t.bytes;
                    t.validity = g.leak.validity;
                    t.visibility = g.leak.visibility;
                    t.planes = r.every_cell ? planes_every_cell(t.vol, 38) : g.leak.planes;
                    t.bytes.resize(t.payload.size() + 4 * ((count + 3) / 4) + 8 * count, 0);
                    // The masks row: validity and visibility; the validity + planes row: validity alone.
                    const bool use_visibility = r.masks && !r.planes && t.visibility.size() == count;
                    for (std::size_t i = 0; i < count && has_leak; ++i) {
                        const std::uint8_t m = t.validity[i] ? (use_visibility ? t.visibility[i] : 0xFF) : 0;
                        t.bytes[t.payload.size() + i] = m;  // little-endian: byte i of the mask words
                        for (int b = 0; b < 5; ++b) t.bytes[t.payload.size() + 4 * ((count + 3) / 4) + 8 * i + std::size_t(b)] = t.planes[5 * i + std::size_t(b)];
                    }
                    t.vol.probes = t.payload.data();
                    if (r.masks) t.vol.validity = t.validity.data();
                    if (use_visibility) t.vol.visibility = t.visibility.data();
                    if (r.planes) t.vol.planes = t.planes.data();
                } else {
                    zhc_probe_format fmt;
                    if (!encode(g, r.name.c_str(), &t.bytes, &t.vol, &fmt)) return 1;
                }
                const std::size_t sizes[4] = {std::max<std::size_t>(16, t.bytes.size()), inputs.size() * 4, std::size_t(kEvals) * 16,
                                              sizeof grid_buf};
                t.kernel = context->make_kernel(r.spv, sizes, images, &error);
                if (!t.kernel) {
                    std::fprintf(stderr, "%s: %s\n", r.name.c_str(), error.c_str());
                    continue;
                }
                if (!t.bytes.empty()) std::memcpy(t.kernel->data(0), t.bytes.data(), t.bytes.size());
                std::memcpy(t.kernel->data(1), inputs.data(), inputs.size() * 4);
                std::memcpy(t.kernel->data(3), grid_buf, sizeof grid_buf);
                timed.push_back(std::move(t));
            }
            for (int rep = 0; rep <= kRepeats; ++rep)
                for (Timed& t : timed) {
                    if (!t.kernel) continue;
                    const double sec = t.kernel->dispatch(kEvals / 64, &error);
                    if (sec < 0) {
                        std::fprintf(stderr, "%s: %s\n", t.row->name.c_str(), error.c_str());
                        t.kernel.reset();
                        continue;
                    }
                    if (rep > 0) t.seconds.push_back(sec);
                }
            for (Timed& t : timed) {
                if (!t.kernel || t.seconds.empty()) continue;
                std::sort(t.seconds.begin(), t.seconds.end());
                t.row->ns = t.seconds[t.seconds.size() / 2] / double(kEvals) * 1e9;
                // The GPU's results against the CPU model at the same (float) inputs.
                const float* out = reinterpret_cast<const float*>(t.kernel->data(2));
                double worst = 0, mag = 0;
                for (std::uint32_t i = 0; i < kSamples; ++i) {
                    double pd[3], nd[3], e[3];
                    for (int c = 0; c < 3; ++c) {
                        pd[c] = inputs[8 * i + static_cast<std::uint32_t>(c)];
                        nd[c] = inputs[8 * i + 4 + static_cast<std::uint32_t>(c)];
                    }
                    if (t.row->filtered) L::sample_irradiance(ref, t.row->layout, t.tex, pd, nd, e);
                    else zhc_volume_irradiance_d(&t.vol, pd, nd, e);
                    const double d[3] = {out[4 * i] - e[0], out[4 * i + 1] - e[1], out[4 * i + 2] - e[2]};
                    worst = std::max(worst, norm3(d));
                    mag += norm3(e) / kSamples;
                }
                t.row->vs_model = worst / mag;
                if (t.row->leak_row) {
                    std::uint32_t cut = 0;
                    for (std::uint32_t i = 0; i < kSamples; ++i) {
                        double pd[3];
                        for (int c = 0; c < 3; ++c) pd[c] = inputs[8 * i + static_cast<std::uint32_t>(c)];
                        cut += leak_cuts(t.vol, pd);
                    }
                    t.row->cut = double(cut) / kSamples;
                }
            }
            timed.clear();  // kernels before the context
        }
    }
#endif
    std::printf("\nerror of one sample vs the exact trilinear SH3 volume: |dE| / mean |E_ref| (demo | gltf)\n");
    std::printf("fetches: texture samples (filterable) or probe decodes (packed) per sample; SPIR-V: instructions after\n"
                "spirv-opt -O minus the skeleton kernel's (-1: not measured)\n\n");
    double base_ns = NAN;
    for (const Row& r : rows)
        if (r.name == "sh3") base_ns = r.ns;
    std::printf("lavapipe: ns per sample on the demo grid (median of 9 dispatches of 2^18), vs sh3: ratio to the packed sh3\n"
                "row; GPU-model: max |GPU - CPU model| / mean |E| (NaN: not measured)\n\n");
    std::printf("%-22s %6s  %-26s %7s %6s %10s %10s %10s | %10s %10s %10s %8s %6s %9s\n", "layout", "B/probe", "textures", "fetches",
                "SPIR-V", "mean", "p95", "max", "mean", "p95", "max", "ns", "vs sh3", "GPU-model");
    for (const Row& r : rows)
        if (!r.leak_row && !r.engine)
        std::printf("%-22s %6.0f  %-26s %7d %6d %10.3g %10.3g %10.3g | %10.3g %10.3g %10.3g %8.1f %6.2f %9.2g\n", r.name.c_str(), r.bytes,
                    r.textures.c_str(), r.fetches, r.spirv, r.err[0].mean, r.err[0].p95, r.err[0].max, r.err[1].mean, r.err[1].p95,
                    r.err[1].max, r.ns, r.ns / base_ns, r.vs_model);
    // The plain row of each leak-row family (8 fetches unrolled, zhc.hlsl's loop).
    auto plain_ns = [&](const Row& row) {
        for (const Row& r : rows)
            if (r.leak_row && r.unrolled == row.unrolled && !r.masks && !r.planes) return r.ns;
        return double(NAN);
    };
    std::printf("\nleak data's cost (demo grid, zh3_q16 stored bytes; \"8 fetches\": the packed rows' unrolled kernel with the kept\n"
                "weights, \"zhc.hlsl\": zhc_volume_irradiance's corner loop that skips weight-0 corners): B/probe with the leak\n"
                "data, SPIR-V as above, lavapipe ns (same rounds), vs plain: ratio to its family's plain row, cut: share of the\n"
                "timed samples where the data drops a corner\n\n");
    std::printf("%-32s %7s %6s %8s %8s %6s %9s\n", "kernel", "B/probe", "SPIR-V", "ns", "vs plain", "cut", "GPU-model");
    for (const Row& r : rows)
        if (r.leak_row)
            std::printf("%-32s %7.0f %6d %8.1f %8.3f %6.3f %9.2g\n", r.name.c_str(), r.bytes, r.spirv, r.ns, r.ns / plain_ns(r), r.cut,
                        r.vs_model);
    std::printf("\nengine layouts (codec/probe/engine_layouts.h): the engine's texels blended trilinearly, then its shader;\n"
                "error as above (demo | gltf); B/probe: the entry's stored bytes, GPU and file bytes per probe in the engine\n"
                "(0: none: the CPU blends per object, or no file format); leak data: whether zhc's validity, masks and\n"
                "planes could apply (no: the hardware filter blends the corners first); CPU ns: the model, one thread\n\n");
    std::printf("%-22s %7s %5s %5s %7s %-5s %10s %10s %10s | %10s %10s %10s %7s  %s\n", "layout", "B/probe", "GPU", "file",
                "fetches", "leak", "mean", "p95", "max", "mean", "p95", "max", "CPU ns", "interpolation");
    for (const Row& r : rows)
        if (r.engine)
            std::printf("%-22s %7.0f %5zu %5zu %7d %-5s %10.3g %10.3g %10.3g | %10.3g %10.3g %10.3g %7.0f  %s\n", r.name.c_str(), r.bytes,
                        r.engine->gpu_bytes, r.engine->disk_bytes, r.fetches, r.engine->hardware_filtered ? "no" : "yes",
                        r.err[0].mean, r.err[0].p95, r.err[0].max, r.err[1].mean, r.err[1].p95, r.err[1].max, r.cpu_ns,
                        r.kind.c_str());
    if (!json.empty()) {
        std::ofstream out(json);
        out << "{\n  \"benchmark\": \"volume\",\n  \"device\": \"" << device << "\",\n  \"samples\": " << samples << ",\n  \"grids\": [\"demo\", \"" << gltf
            << "\"],\n  \"rows\": [\n";
        std::vector<const Row*> layout_rows, leak_rows, engine_rows;
        for (const Row& r : rows) (r.engine ? engine_rows : r.leak_row ? leak_rows : layout_rows).push_back(&r);
        for (std::size_t i = 0; i < layout_rows.size(); ++i) {
            const Row& r = *layout_rows[i];
            char buf[1024];
            std::snprintf(buf, sizeof buf,
                          "    {\"layout\": \"%s\", \"kind\": \"%s\", \"textures\": \"%s\", \"bytes_per_probe\": %g, \"fetches\": %d, "
                          "\"spirv_instructions_minus_skeleton\": %d, \"lavapipe_ns_per_sample\": %.4g, "
                          "\"ratio_to_sh3\": %.4g, \"gpu_vs_model\": %.4g, "
                          "\"demo\": {\"mean\": %.6g, \"p95\": %.6g, \"max\": %.6g}, "
                          "\"gltf\": {\"mean\": %.6g, \"p95\": %.6g, \"max\": %.6g}}%s\n",
                          r.name.c_str(), r.kind.c_str(), r.textures.c_str(), r.bytes, r.fetches, r.spirv, std::isfinite(r.ns) ? r.ns : -1.0,
                          std::isfinite(r.ns / base_ns) ? r.ns / base_ns : -1.0, std::isfinite(r.vs_model) ? r.vs_model : -1.0, r.err[0].mean, r.err[0].p95, r.err[0].max,
                          r.err[1].mean, r.err[1].p95, r.err[1].max, i + 1 < layout_rows.size() ? "," : "");
            out << buf;
        }
        out << "  ],\n  \"leak_rows\": [\n";
        for (std::size_t i = 0; i < leak_rows.size(); ++i) {
            const Row& r = *leak_rows[i];
            char buf[1024];
            std::snprintf(buf, sizeof buf,
                          "    {\"kernel\": \"%s\", \"unrolled\": %s, \"masks\": %s, \"planes\": %s, \"planes_every_cell\": %s, \"bytes_per_probe\": %g, "
                          "\"spirv_instructions_minus_skeleton\": %d, \"lavapipe_ns_per_sample\": %.4g, \"ratio_to_plain\": %.4g, "
                          "\"cut\": %.4g, \"gpu_vs_model\": %.4g}%s\n",
                          r.name.c_str(), r.unrolled ? "true" : "false", r.masks ? "true" : "false", r.planes ? "true" : "false",
                          r.every_cell ? "true" : "false", r.bytes, r.spirv, std::isfinite(r.ns) ? r.ns : -1.0,
                          std::isfinite(r.ns / plain_ns(r)) ? r.ns / plain_ns(r) : -1.0,
                          std::isfinite(r.cut) ? r.cut : -1.0, std::isfinite(r.vs_model) ? r.vs_model : -1.0, i + 1 < leak_rows.size() ? "," : "");
            out << buf;
        }
        out << "  ],\n  \"engine_rows\": [\n";
        for (std::size_t i = 0; i < engine_rows.size(); ++i) {
            const Row& r = *engine_rows[i];
            char buf[1024];
            std::snprintf(buf, sizeof buf,
                          "    {\"layout\": \"%s\", \"engine\": \"%s\", \"interpolation\": \"%s\", \"bytes_per_probe\": %g, "
                          "\"gpu_bytes_per_probe\": %zu, \"file_bytes_per_probe\": %zu, \"fetches\": %d, \"hardware_filtered\": %s, "
                          "\"carries_leak_data\": %s, \"cpu_model_ns_per_sample\": %.4g, "
                          "\"demo\": {\"mean\": %.6g, \"p95\": %.6g, \"max\": %.6g}, "
                          "\"gltf\": {\"mean\": %.6g, \"p95\": %.6g, \"max\": %.6g}}%s\n",
                          r.name.c_str(), std::string(r.engine->engine).c_str(), r.kind.c_str(), r.bytes, r.engine->gpu_bytes,
                          r.engine->disk_bytes, r.fetches, r.engine->hardware_filtered ? "true" : "false",
                          r.engine->hardware_filtered ? "false" : "true", r.cpu_ns, r.err[0].mean, r.err[0].p95, r.err[0].max,
                          r.err[1].mean, r.err[1].p95, r.err[1].max, i + 1 < engine_rows.size() ? "," : "");
            out << buf;
        }
        if (!bench::finish_json(out, json)) return 1;
    }
    return 0;
}
