// Test kernel of tests/test_runtime_vk.cpp: one invocation per probe (or lightmap texel).
//   binding 0  params: 16 uints [encoding, bits, sqrt, l2Bound, dcFormat, zonalMapping, axisMode, kind,
//              lumR, lumG, lumB, hallA, hallB (float bits), count, strideWords, mode]
//   binding 1  the probes' words (strideWords per probe), or per texel 6 floats (I_z rgb, w_a, d uv)
//   binding 2  unit normals (float4, w unused)
//   binding 3  output, 32 floats per item: decoded SH3 radiance (27), irradiance (3)
// mode 0: probes; 1: IrradZ HHD; 2: IrradZ AHD (irradiance in floats 27..29); 3: probe volume
// (params 16..24: grid origin, spacing (float bits), counts; binding 2 holds position, normal as two
// float4 per item; irradiance in floats 27..29); 4: the ASTC LDR fallback's I_z decode
// (zhc_irradz_iz_from_ldr; per item 5 floats t rgb, lo, hi; result in floats 27..29); 5: scattered
// probes (zhc_volume_tetra_sh3 / zhc_volume_tetra_irradiance; binding 2 holds the 4 weights, the 4
// probe indices as floats and the normal as three float4 per item; blended SH3 in floats 0..26,
// irradiance in 27..29).
// Compiled four times: plain; with -DZHC_TEST_MASKED (ZHC_VOLUME_MASK: validity and visibility masks
// at word params[25] of binding 1); with -DZHC_TEST_MASKED -DZHC_TEST_PLANES (and ZHC_VOLUME_PLANE:
// cell-plane entries, 2 words per probe, at word params[26]; mode 3 also writes the corners the
// cell's plane keeps in float 0); with -DZHC_TEST_PLANES -DZHC_VOLUME_PLANE_AXES_GLTF (planes alone,
// the grid in glTF axes).
[[vk::binding(0, 0)]] StructuredBuffer<uint> params;
[[vk::binding(1, 0)]] ByteAddressBuffer words;
[[vk::binding(2, 0)]] StructuredBuffer<float4> normals;
[[vk::binding(3, 0)]] RWStructuredBuffer<float> results;

#define ZHC_VOLUME_WORD(i) words.Load(4u * (i))
#ifdef ZHC_TEST_MASKED
// The masked build (runtime_test_masked.spv): combined masks, 4 per word, after the probe words at
// word params[25].
#define ZHC_VOLUME_MASK(i) ((words.Load(4u * (params[25] + ((i) >> 2))) >> (8u * ((i) & 3u))) & 0xFFu)
#endif
#ifdef ZHC_TEST_PLANES
// The plane builds: entry of cell i (ou | ov << 8 | offset << 16, sides) at word params[26] + 2 i.
#define ZHC_VOLUME_PLANE(i) words.Load2(4u * (params[26] + 2u * (i)))
#endif
#include "zhc.hlsl"

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID)
{
    uint i = id.x;
    if (i >= params[13]) return;
    uint stride = params[14];
    uint mode = params[15];
    float3 n = normals[i].xyz;
    uint o = 32u * i;
    if (mode == 3u)
    {
        ZhcFormat f = zhc_default_format(params[0]);
        f.bits = params[1];
        f.sqrtEncoding = params[2];
        f.l2Bound = params[3];
        f.dcFormat = params[4];
        f.zonalMapping = params[5];
        f.axisMode = params[6];
        f.kind = params[7];
        f.lumR = asfloat(params[8]);
        f.lumG = asfloat(params[9]);
        f.lumB = asfloat(params[10]);
        f.hallA = asfloat(params[11]);
        f.hallB = asfloat(params[12]);
        ZhcVolume v;
        v.origin = asfloat(uint3(params[16], params[17], params[18]));
        v.spacing = asfloat(uint3(params[19], params[20], params[21]));
        v.counts = uint3(params[22], params[23], params[24]);
        float3 e = zhc_volume_irradiance(v, f, normals[2u * i].xyz, normals[2u * i + 1u].xyz);
        results[o + 27u] = e.x;
        results[o + 28u] = e.y;
        results[o + 29u] = e.z;
#ifdef ZHC_VOLUME_PLANE
        {  // the corners the cell's plane keeps (zhc_volume_sh3's cell)
            float3 p = normals[2u * i].xyz;
            uint3 cn = max(v.counts, uint3(1u, 1u, 1u));
            float3 t = (p - v.origin) / v.spacing;
            t = min(float3(t.x >= 0.0f ? t.x : 0.0f, t.y >= 0.0f ? t.y : 0.0f, t.z >= 0.0f ? t.z : 0.0f), float3(cn - 1u));
            uint3 i0 = min(uint3(t), max(cn, uint3(2u, 2u, 2u)) - 2u);
            results[o] = float(zhc_volume_plane_keep(ZHC_VOLUME_PLANE(i0.x + cn.x * (i0.y + cn.y * i0.z)), v, i0, p));
        }
#endif
        return;
    }
    if (mode == 5u)
    {
        ZhcFormat f = zhc_default_format(params[0]);
        f.bits = params[1];
        f.sqrtEncoding = params[2];
        f.l2Bound = params[3];
        f.dcFormat = params[4];
        f.zonalMapping = params[5];
        f.axisMode = params[6];
        f.kind = params[7];
        f.lumR = asfloat(params[8]);
        f.lumG = asfloat(params[9]);
        f.lumB = asfloat(params[10]);
        f.hallA = asfloat(params[11]);
        f.hallB = asfloat(params[12]);
        float4 wt = normals[3u * i];
        uint4 q = uint4(normals[3u * i + 1u]);
        ZhcSH3 sh = zhc_volume_tetra_sh3(q, wt, f);
        [unroll] for (uint c = 0u; c < 9u; ++c)
        {
            results[o + 3u * c] = sh.c[c].x;
            results[o + 3u * c + 1u] = sh.c[c].y;
            results[o + 3u * c + 2u] = sh.c[c].z;
        }
        float3 e = zhc_volume_tetra_irradiance(q, wt, f, normals[3u * i + 2u].xyz);
        results[o + 27u] = e.x;
        results[o + 28u] = e.y;
        results[o + 29u] = e.z;
        return;
    }
    if (mode == 4u)
    {
        uint b = 20u * i;
        float3 e = zhc_irradz_iz_from_ldr(asfloat(words.Load3(b)), asfloat(words.Load2(b + 12u)));
        results[o + 27u] = e.x;
        results[o + 28u] = e.y;
        results[o + 29u] = e.z;
        return;
    }
    if (mode != 0u)
    {
        uint b = 4u * stride * i;
        float3 iz = asfloat(words.Load3(b));
        float wa = asfloat(words.Load(b + 12u));
        float2 uv = asfloat(words.Load2(b + 16u));
        float3 e = zhc_irradz_irradiance(iz, wa, uv, mode == 1u ? ZHC_IRRADZ_HHD : ZHC_IRRADZ_AHD, n);
        results[o + 27u] = e.x;
        results[o + 28u] = e.y;
        results[o + 29u] = e.z;
        return;
    }
    ZhcFormat f;
    f.encoding = params[0];
    f.bits = params[1];
    f.sqrtEncoding = params[2];
    f.l2Bound = params[3];
    f.dcFormat = params[4];
    f.zonalMapping = params[5];
    f.axisMode = params[6];
    f.kind = params[7];
    f.lumR = asfloat(params[8]);
    f.lumG = asfloat(params[9]);
    f.lumB = asfloat(params[10]);
    f.hallA = asfloat(params[11]);
    f.hallB = asfloat(params[12]);
    uint w[27];
    [unroll] for (uint j = 0u; j < 27u; ++j) w[j] = j < stride ? words.Load(4u * (stride * i + j)) : 0u;
    ZhcSH3 sh = zhc_decode_sh3(w, f);
    [unroll] for (uint c = 0u; c < 9u; ++c)
    {
        results[o + 3u * c] = sh.c[c].x;
        results[o + 3u * c + 1u] = sh.c[c].y;
        results[o + 3u * c + 2u] = sh.c[c].z;
    }
    float3 e = zhc_irradiance(w, f, n);
    results[o + 27u] = e.x;
    results[o + 28u] = e.y;
    results[o + 29u] = e.z;
}
