// volume_kernels.h — the HLSL compute kernels of one probe-volume sample per GPU volume layout
// (docs/runtime.md "GPU volume layouts"), shared by bench/bench_volume.cpp (SPIR-V counts, lavapipe
// time) and tests/vk/test_volume_layouts_vk.cpp (lavapipe against the CPU model).
// Bindings (set 0): 0 the stored probe words (packed kernels), 1 the inputs (float4 position,
// float4 normal per sample; sample = invocation & 65535), 2 the results (float4 per invocation),
// 3 the grid (float4 origin, float4 spacing, uint4 counts as float bits), 4 a linear clamp-to-edge
// sampler and 5.. the layout's 3D textures (filtered kernels). Every kernel #includes "zhc.hlsl".
#pragma once

#include <cstdio>
#include <sstream>
#include <string>

#include "runtime/zhc_volume_layouts.hpp"

namespace zhc_volume_kernels {

namespace L = zhc_layouts;


inline const char* kKernelHead =
    "[[vk::binding(1, 0)]] StructuredBuffer<float4> inputs;\n"
    "[[vk::binding(2, 0)]] RWStructuredBuffer<float4> result;\n"
    "[[vk::binding(3, 0)]] StructuredBuffer<float4> grid;\n"
    "#define gOrigin grid[0]\n#define gSpacing grid[1]\n#define gCounts asuint(grid[2])\n";
inline const char* kKernelMainHead =
    "[numthreads(64, 1, 1)]\nvoid main(uint3 id : SV_DispatchThreadID)\n{\n"
    "    uint si = id.x & 65535u;\n"
    "    float3 p = inputs[2u * si].xyz;\n    float3 nrm = inputs[2u * si + 1u].xyz;\n";
inline const char* kKernelMainTail = "    result[id.x] = float4(e, 0.0f);\n}\n";

inline std::string skeleton_kernel() {
    return std::string(kKernelHead) + kKernelMainHead + "    float3 e = p + nrm;\n" + kKernelMainTail;
}

// Packed: the 8 corner probes decoded from the stored words and blended (zhc.hlsl), unrolled.
inline std::string packed_kernel(int encoding) {
    std::ostringstream s;
    s << "[[vk::binding(0, 0)]] ByteAddressBuffer probeWords;\n#define ZHC_VOLUME_WORD(i) probeWords.Load(4u * (i))\n"
         "#include \"zhc.hlsl\"\n"
      << kKernelHead << kKernelMainHead
      << "    const ZhcFormat f = zhc_default_format(" << encoding << "u);\n"
         "    uint3 n = max(gCounts.xyz, uint3(1u, 1u, 1u));\n"
         "    float3 t = (p - gOrigin.xyz) / gSpacing.xyz;\n"
         "    t = float3(t.x >= 0.0f ? t.x : 0.0f, t.y >= 0.0f ? t.y : 0.0f, t.z >= 0.0f ? t.z : 0.0f);\n"
         "    t = min(t, float3(n - 1u));\n"
         "    uint3 i0 = min(uint3(t), max(n, uint3(2u, 2u, 2u)) - 2u);\n"
         "    float3 fr = t - float3(i0);\n"
         "    ZhcSH3 acc;\n"
         "    [unroll] for (int i = 0; i < 9; ++i) acc.c[i] = float3(0.0f, 0.0f, 0.0f);\n"
         "    [unroll] for (uint c = 0u; c < 8u; ++c)\n    {\n"
         "        uint3 b = uint3(c & 1u, (c >> 1) & 1u, c >> 2);\n"
         "        float w = (b.x != 0u ? fr.x : 1.0f - fr.x) * (b.y != 0u ? fr.y : 1.0f - fr.y) * (b.z != 0u ? fr.z : 1.0f - fr.z);\n"
         "        uint3 q = i0 + b;\n"
         "        ZhcSH3 s = zhc_volume_probe(q.x + n.x * (q.y + n.y * q.z), f);\n"
         "        [unroll] for (int j = 0; j < 9; ++j) acc.c[j] += w * s.c[j];\n"
         "    }\n"
         "    float3 e = zhc_sh3_irradiance(acc, zhc_normalize_or_z(nrm));\n"
      << kKernelMainTail;
    return s.str();
}

inline std::string num(double v) {
    char b[64];
    std::snprintf(b, sizeof b, "%.9g", v);
    std::string r = b;
    if (r.find_first_of(".e") == std::string::npos) r += ".0";
    return r + "f";
}

// Filterable: one SampleLevel per texture, the reconstruction of zhc_layouts::reconstruct_sh3.
inline std::string filter_kernel(L::Layout l) {
    const auto tex = L::layout_textures(l);
    std::ostringstream s;
    s << "#include \"zhc.hlsl\"\n" << kKernelHead << "[[vk::binding(4, 0)]] SamplerState gSampler;\n";
    for (std::size_t t = 0; t < tex.size(); ++t) s << "[[vk::binding(" << 5 + t << ", 0)]] Texture3D<float4> gT" << t << ";\n";
    s << kKernelMainHead
      << "    float3 n = float3(max(gCounts.xyz, uint3(1u, 1u, 1u)));\n"
         "    float3 t = (p - gOrigin.xyz) / gSpacing.xyz;\n"
         "    t = min(float3(t.x >= 0.0f ? t.x : 0.0f, t.y >= 0.0f ? t.y : 0.0f, t.z >= 0.0f ? t.z : 0.0f), n - 1.0f);\n"
         "    float3 uvw = (t + 0.5f) / n;\n"
         "    float v[36];\n";
    for (std::size_t t = 0; t < tex.size(); ++t) {
        s << "    { float4 x = gT" << t << ".SampleLevel(gSampler, uvw, 0.0f);";
        for (int c = 0; c < 4; ++c) s << " v[" << 4 * t + static_cast<std::size_t>(c) << "] = x[" << c << "];";
        s << " }\n";
    }
    s << "    ZhcSH3 sh;\n    [unroll] for (int i = 0; i < 9; ++i) sh.c[i] = float3(0.0f, 0.0f, 0.0f);\n";
    const std::string lum = "float3(" + num(L::kLumW[0]) + ", " + num(L::kLumW[1]) + ", " + num(L::kLumW[2]) + ")";
    auto unit_to_ratio = [&](int i, const std::string& u) {
        double lo, hi;
        L::ratio_interval(i, &lo, &hi);
        return "(" + u + " * " + num((hi - lo) / 2) + " + " + num((hi + lo) / 2) + ")";
    };
    auto slot3 = [](int a) { return "float3(v[" + std::to_string(a) + "], v[" + std::to_string(a + 1) + "], v[" + std::to_string(a + 2) + "])"; };
    switch (l) {
        case L::Layout::kSh3F32:
        case L::Layout::kSh3F16:
        case L::Layout::kSh2F16:
        case L::Layout::kSh2L2GreyF16:
        case L::Layout::kSh2L2LumF16:
            for (int i = 0; i < (l == L::Layout::kSh3F32 || l == L::Layout::kSh3F16 ? 9 : 4); ++i)
                s << "    sh.c[" << i << "] = " << slot3(3 * i) << ";\n";
            if (l == L::Layout::kSh2L2LumF16) {
                s << "    float y0 = dot(" << lum << ", sh.c[0]);\n    float3 scale = y0 > 0.0f ? sh.c[0] / y0 : float3(0.0f, 0.0f, 0.0f);\n";
                for (int i = 4; i < 9; ++i) s << "    sh.c[" << i << "] = v[" << 12 + i - 4 << "] * scale;\n";
            }
            if (l == L::Layout::kSh2L2GreyF16)
                for (int i = 4; i < 9; ++i) s << "    sh.c[" << i << "] = v[" << 12 + i - 4 << "].xxx;\n";
            break;
        case L::Layout::kRatio8:
            s << "    sh.c[0] = " << slot3(0) << ";\n";
            for (int i = 1; i < 9; ++i) s << "    sh.c[" << i << "] = " << unit_to_ratio(i, slot3(4 + (i - 1) * 3)) << " * sh.c[0];\n";
            break;
        case L::Layout::kSh3Rgb9e5:
        case L::Layout::kSh2Rgb9e5:
        case L::Layout::kSh2Rgb9e5L2Lum:
            s << "    sh.c[0] = " << slot3(0) << ";\n";
            for (int i = 1; i < (l == L::Layout::kSh3Rgb9e5 ? 9 : 4); ++i)
                s << "    sh.c[" << i << "] = " << slot3(4 * i) << " - " << num(L::offset(i)) << " * sh.c[0];\n";
            if (l == L::Layout::kSh2Rgb9e5L2Lum) {
                s << "    float y0 = dot(" << lum << ", sh.c[0]);\n    float3 scale = y0 > 0.0f ? sh.c[0] / y0 : float3(0.0f, 0.0f, 0.0f);\n";
                for (int i = 4; i < 9; ++i)
                    s << "    sh.c[" << i << "] = (v[" << (i < 7 ? 16 + i - 4 : 20 + i - 7) << "] - " << num(L::offset(i)) << " * y0) * scale;\n";
            }
            break;
    }
    s << "    float3 e = zhc_sh3_irradiance(sh, zhc_normalize_or_z(nrm));\n" << kKernelMainTail;
    return s.str();
}

}  // namespace zhc_volume_kernels
