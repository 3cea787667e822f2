// The probe layouts engines ship (engine_layouts.h, docs/engine-layouts.md): one codec-table entry
// per engine layout. Each entry's comment names the engine files and functions it follows; the
// code is written from what they do (their formulas and packing), not copied.
//
// Common ground. An SH3 irradiance function is, on the unit sphere, a polynomial of degree 2 in the
// normal: E(n) = a + b.n + n^T Q n with Q symmetric and traceless. Engines write that polynomial
// (or the SH coefficients it has in their own axes and basis) in their own scale; engine_irradiance_sh
// gives its coefficients in an engine's axes in the basis without the Condon-Shortley sign
// (Y1 = k1 (y, z, x), ...), from which every SH entry below derives what its engine stores:
//   radiance SH (three.js, RealityKit):       t_i / band scale
//   radiance SH / pi (Godot's lightmapper):   t_i / band scale / pi
//   the polynomial's coefficients (Unity):    a = k0 t0, b = k1 (t3, t1, t2), ...
//   radiance SH with the Condon-Shortley sign (Unreal): t_i / band scale, coefficients 1, 3, 5, 7 negated
#include "codec/probe/engine_layouts.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "codec/probe/quantize.h"

namespace zhc {

namespace {

// ---- axes -----------------------------------------------------------------------------------

constexpr Mat3 mat(double a, double b, double c, double d, double e, double f, double g, double h, double i) {
    return Mat3{{a, b, c, d, e, f, g, h, i}};
}
// glTF's axes, Y up, right-handed: (x, y, z)_glTF = (y, z, x)_zhc (docs/gltf-extension.md).
// three.js, Godot, Bevy and RealityKit use them.
constexpr Mat3 kAxesYUpRight = mat(0, 1, 0, 0, 0, 1, 1, 0, 0);
// Unity's axes, Y up, left-handed: glTF's with x negated, as Unity's glTF importers (glTFast,
// UnityGLTF) map them: (x, y, z)_Unity = (-y, z, x)_zhc.
constexpr Mat3 kAxesUnity = mat(0, -1, 0, 0, 0, 1, 1, 0, 0);
// Unreal's axes, Z up, left-handed: (x, y, z)_Unreal = (x, -y, z)_zhc.
constexpr Mat3 kAxesUnreal = mat(1, 0, 0, 0, -1, 0, 0, 0, 1);
// Source's axes, Z up, right-handed, as zhc's.
constexpr Mat3 kAxesZUpRight = mat(1, 0, 0, 0, 1, 0, 0, 0, 1);

Vec3 to_engine(const Mat3& axes, Vec3 n) { return axes * n; }

// ---- the SH3 polynomial ---------------------------------------------------------------------

// E(n) = a + b.n + n^T Q n per channel, Q symmetric and traceless.
struct Poly {
    double a[3] = {};
    double b[3][3] = {};     // [axis][channel]
    double q[3][3][3] = {};  // [row][column][channel]
};

// zhc's basis (sh.h) has the Condon-Shortley sign: Y1 = k1 (-y, z, -x), Y2 = k2 xy, -k2 yz, k20
// (3z^2 - 1), -k2 xz, k22 (x^2 - y^2); 3z^2 - 1 = 2z^2 - x^2 - y^2 on the sphere.
Poly poly_of_hub(const Sh3Radiance& hub) {
    Poly p;
    for (int c = 0; c < 3; ++c) {
        double e[9];
        for (int i = 0; i < 9; ++i) e[i] = double(hub[i][c]) * kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)];
        p.a[c] = kY00 * e[0];
        p.b[0][c] = -kY1 * e[3];
        p.b[1][c] = -kY1 * e[1];
        p.b[2][c] = kY1 * e[2];
        p.q[0][0][c] = -kY20 * e[6] + kY22 * e[8];
        p.q[1][1][c] = -kY20 * e[6] - kY22 * e[8];
        p.q[2][2][c] = 2.0 * kY20 * e[6];
        p.q[0][1][c] = p.q[1][0][c] = 0.5 * kY2 * e[4];
        p.q[1][2][c] = p.q[2][1][c] = -0.5 * kY2 * e[5];
        p.q[0][2][c] = p.q[2][0][c] = -0.5 * kY2 * e[7];
    }
    return p;
}

Sh3Radiance hub_of_poly(const Poly& p) {
    Sh3Radiance hub;
    for (int c = 0; c < 3; ++c) {
        const double e[9] = {p.a[c] / kY00,
                             -p.b[1][c] / kY1,
                             p.b[2][c] / kY1,
                             -p.b[0][c] / kY1,
                             2.0 * p.q[0][1][c] / kY2,
                             -2.0 * p.q[1][2][c] / kY2,
                             p.q[2][2][c] / (2.0 * kY20),
                             -2.0 * p.q[0][2][c] / kY2,
                             (p.q[0][0][c] - p.q[1][1][c]) / (2.0 * kY22)};
        for (int i = 0; i < 9; ++i)
            hub[i][c] = static_cast<float>(e[i] / kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)]);
    }
    return hub;
}

// The polynomial in axes v' = R v: b' = R b, Q' = R Q R^T (n'^T Q' n' = n^T Q n for n' = R n).
Poly turn(const Poly& p, const Mat3& r) {
    Poly o;
    for (int c = 0; c < 3; ++c) {
        o.a[c] = p.a[c];
        for (int i = 0; i < 3; ++i) {
            double s = 0;
            for (int j = 0; j < 3; ++j) s += r(i, j) * p.b[j][c];
            o.b[i][c] = s;
        }
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double s = 0;
                for (int k = 0; k < 3; ++k)
                    for (int l = 0; l < 3; ++l) s += r(i, k) * p.q[k][l][c] * r(j, l);
                o.q[i][j][c] = s;
            }
    }
    return o;
}

// The polynomial <-> its coefficients in the basis without the Condon-Shortley sign (same axes).
EngineSh sh_of_poly(const Poly& p) {
    EngineSh t{};
    for (int c = 0; c < 3; ++c) {
        t[0][c] = p.a[c] / kY00;
        t[1][c] = p.b[1][c] / kY1;
        t[2][c] = p.b[2][c] / kY1;
        t[3][c] = p.b[0][c] / kY1;
        t[4][c] = 2.0 * p.q[0][1][c] / kY2;
        t[5][c] = 2.0 * p.q[1][2][c] / kY2;
        t[6][c] = p.q[2][2][c] / (2.0 * kY20);
        t[7][c] = 2.0 * p.q[0][2][c] / kY2;
        t[8][c] = (p.q[0][0][c] - p.q[1][1][c]) / (2.0 * kY22);
    }
    return t;
}

Poly poly_of_sh(const EngineSh& t) {
    Poly p;
    for (int c = 0; c < 3; ++c) {
        p.a[c] = kY00 * t[0][c];
        p.b[0][c] = kY1 * t[3][c];
        p.b[1][c] = kY1 * t[1][c];
        p.b[2][c] = kY1 * t[2][c];
        p.q[0][1][c] = p.q[1][0][c] = 0.5 * kY2 * t[4][c];
        p.q[1][2][c] = p.q[2][1][c] = 0.5 * kY2 * t[5][c];
        p.q[0][2][c] = p.q[2][0][c] = 0.5 * kY2 * t[7][c];
        p.q[2][2][c] = 2.0 * kY20 * t[6][c];
        p.q[0][0][c] = kY22 * t[8][c] - kY20 * t[6][c];
        p.q[1][1][c] = -kY22 * t[8][c] - kY20 * t[6][c];
    }
    return p;
}

int band(int i) { return i == 0 ? 0 : (i < 4 ? 1 : 2); }

// ---- little-endian storage and the engines' number formats ---------------------------------

void put_u16(std::uint8_t* out, std::uint16_t v) {
    out[0] = static_cast<std::uint8_t>(v);
    out[1] = static_cast<std::uint8_t>(v >> 8);
}
std::uint16_t get_u16(const std::uint8_t* in) { return static_cast<std::uint16_t>(in[0] | (in[1] << 8)); }
void put_u32(std::uint8_t* out, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out[b] = static_cast<std::uint8_t>(v >> (8 * b));
}
std::uint32_t get_u32(const std::uint8_t* in) {
    std::uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= std::uint32_t(in[b]) << (8 * b);
    return v;
}
void put_f32(std::uint8_t* out, float v) {
    std::uint32_t u;
    std::memcpy(&u, &v, 4);
    put_u32(out, u);
}
float get_f32(const std::uint8_t* in) {
    const std::uint32_t u = get_u32(in);
    float v;
    std::memcpy(&v, &u, 4);
    return v;
}
double half_at(const std::uint8_t* in) { return unpack_half(get_u16(in)); }

// ---- three.js LightProbeGrid ----------------------------------------------------------------
// three.js r187 (tests/js/node_modules/three). Storage: examples/jsm/lighting/LightProbeGridWebGL.js
// _ensureTextures (one RGBA FloatType 3D atlas of 7 sub-volumes: 112 bytes a probe) and
// examples/jsm/lighting/LightProbeGrid.js _ensureTextures (WebGPU: HalfFloatType, 56 bytes);
// repackNode packs coefficient c_i's R, G, B at floats 3i .. 3i + 2 of the 28 a probe's 7 texels
// hold, the 28th is 0. The coefficients are radiance SH in three.js's axes (Y up), projected in
// LightProbeGridWebGL.js's projection shader with the basis 0.282095, 0.488603 y, z, x, 1.092548
// xy, yz, 0.315392 (3z^2 - 1), 1.092548 xz, 0.546274 (x^2 - y^2). Evaluation:
// src/renderers/shaders/ShaderChunk/lightprobes_pars_fragment.glsl.js getLightProbeGridIrradiance
// and examples/jsm/tsl/lighting/LightProbeGridNode.js evaluateGridIrradiance: sum c_i A_l Y_i(n)
// with the rounded constants below, then max(., 0). That is pi times zhc's normalised irradiance;
// the entry returns it divided by pi.
template <bool Half>
void threejs_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    const EngineSh t = engine_irradiance_sh(hub, kAxesYUpRight);
    for (int i = 0; i < 28; ++i) {
        const double v = i < 27 ? t[static_cast<size_t>(i / 3)][static_cast<size_t>(i % 3)] / kIrradianceBandScale[band(i / 3)] : 0.0;
        if (Half) put_u16(out + 2 * i, pack_half(v));
        else put_f32(out + 4 * i, static_cast<float>(v));
    }
}

// Texels: the 28 values of the 7 RGBA texels.
template <bool Half>
void threejs_texels(const std::uint8_t* in, double* t) {
    for (int k = 0; k < 28; ++k) t[k] = Half ? half_at(in + 2 * k) : double(get_f32(in + 4 * k));
}

Sh3Radiance threejs_hub(const double* tex) {
    EngineSh t{};
    for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c) t[i][c] = tex[3 * i + c] * kIrradianceBandScale[band(i)];
    return hub_from_engine_irradiance_sh(t, kAxesYUpRight);
}

Rgb threejs_shade(const double* tex, Vec3 n) {
    const Vec3 e = to_engine(kAxesYUpRight, n);
    const double x = e.x, y = e.y, z = e.z;
    Rgb out;
    for (int c = 0; c < 3; ++c) {
        auto s = [&](int i) { return tex[3 * i + c]; };
        double r = s(0) * 0.886227;
        r += s(1) * 2.0 * 0.511664 * y;
        r += s(2) * 2.0 * 0.511664 * z;
        r += s(3) * 2.0 * 0.511664 * x;
        r += s(4) * 2.0 * 0.429043 * x * y;
        r += s(5) * 2.0 * 0.429043 * y * z;
        r += s(6) * (0.743125 * z * z - 0.247708);
        r += s(7) * 2.0 * 0.429043 * x * z;
        r += s(8) * 0.429043 * (x * x - y * y);
        out[c] = static_cast<float>(std::max(r, 0.0) / kPi);  // NaN bytes: NaN stays (std::max returns r)
    }
    return out;
}

// ---- Unity Adaptive Probe Volumes -----------------------------------------------------------
// Unity-Technologies/Graphics, Packages/com.unity.render-pipelines.core/Runtime/Lighting/ProbeVolume.
// Storage, ProbeBrickPool.cs CreateDataLocation: L0_L1Rx R16G16B16A16_SFloat (L0 R, G, B and L1
// red x), L1G_L1Ry and L1B_L1Rz R8G8B8A8_UNorm (L1 green / blue x, y, z and L1 red y / z), and for
// L2 four more R8G8B8A8_UNorm (L2_0..2: red, green, blue (xy, yz, zz, zx); L2_3: the x^2 - y^2 term
// of R, G, B, its alpha unused); the bake writes them in ProbeGIBaking.Serialization.cs
// WriteToShaderCoeffsL0L1 / WriteToShaderCoeffsL2 with SHFloatToHalf (min(v, 65504) to half) and
// SHFloatToByte ((byte)(clamp(v, 0, 1) * 255): truncation). The entry's bytes are those texels in
// that order (16 bytes; 32 with L2; the validity texture, R8, is not lighting and is left out).
// Encoding, DecodeSH.hlsl: L1 is stored as l1 / l0 / (2 * APV_L1_ENCODING_SCALE) + 0.5 (scale 2;
// 0.5 where l0 is 0); L2 as l2 / l0 / APV_L2_ENCODING_SCALE + 0.5 (scale 3.5777088, 0 for l0 = 0)
// with the zz slot holding a third of the decoded zz coefficient and that third added to l0
// (EncodeSH_L2); the entry writes what DecodeSH / DecodeSH_L2 invert. Evaluation, ProbeVolume.hlsl
// EvaluateAdaptiveProbeVolume: decode, then L0 + SHEvalLinearL1 (dot(L1, N) per channel) +
// SHEvalLinearL2 (dot(L2, N.xyzz * N.yzzx) + L2_C (x^2 - y^2)); no clamp. Unity's probes are in
// zhc's normalised irradiance units (the lightmapper's ConvertToUnityFormat divides by pi).
constexpr float kApvL1Scale = 2.0f;
constexpr float kApvL2Scale = 3.5777088f;

std::uint16_t unity_half(float v) { return pack_half(std::min(v, 65504.0f)); }  // Mathf.Min(NaN, 65504) is 65504
std::uint8_t unity_byte(float v) {
    if (!(v > 0.0f)) return 0;  // negative and NaN
    return static_cast<std::uint8_t>(std::min(v, 1.0f) * 255.0f);
}

// The polynomial coefficients of one channel in Unity's axes: L0 = a, L1 = b (x, y, z), L2 =
// (xy, yz, zz / 3 as stored, zx) and the x^2 - y^2 term.
struct ApvChannel {
    float l0, l1[3], l2[4], c;
};
ApvChannel apv_channel(const EngineSh& t, int c) {
    ApvChannel a;
    a.l0 = static_cast<float>(kY00 * t[0][c]);
    a.l1[0] = static_cast<float>(kY1 * t[3][c]);
    a.l1[1] = static_cast<float>(kY1 * t[1][c]);
    a.l1[2] = static_cast<float>(kY1 * t[2][c]);
    a.l2[0] = static_cast<float>(kY2 * t[4][c]);
    a.l2[1] = static_cast<float>(kY2 * t[5][c]);
    a.l2[2] = static_cast<float>(kY20 * t[6][c]);  // d of d (3 z^2 - 1): EncodeSH_L2's zz / 3
    a.l2[3] = static_cast<float>(kY2 * t[7][c]);
    a.c = static_cast<float>(kY22 * t[8][c]);
    return a;
}

template <bool L2>
void apv_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    const EngineSh t = engine_irradiance_sh(hub, kAxesUnity);
    ApvChannel ch[3];
    float l1[3][3];  // encoded, [channel][axis]
    for (int c = 0; c < 3; ++c) {
        ch[c] = apv_channel(t, c);
        for (int k = 0; k < 3; ++k)
            l1[c][k] = ch[c].l0 == 0.0f ? 0.5f : ch[c].l1[k] * (1.0f / ch[c].l0) / (2.0f * kApvL1Scale) + 0.5f;
    }
    for (int c = 0; c < 3; ++c) put_u16(out + 2 * c, unity_half(ch[c].l0));
    put_u16(out + 6, unity_half(l1[0][0]));
    out[8] = unity_byte(l1[1][0]), out[9] = unity_byte(l1[1][1]), out[10] = unity_byte(l1[1][2]), out[11] = unity_byte(l1[0][1]);
    out[12] = unity_byte(l1[2][0]), out[13] = unity_byte(l1[2][1]), out[14] = unity_byte(l1[2][2]), out[15] = unity_byte(l1[0][2]);
    if (!L2) return;
    for (int c = 0; c < 3; ++c) {
        const float r = ch[c].l0 == 0.0f ? 0.0f : 1.0f / ch[c].l0;
        for (int k = 0; k < 4; ++k) out[16 + 4 * c + k] = unity_byte(0.5f + ch[c].l2[k] * (1.0f / kApvL2Scale) * r);
        out[28 + c] = unity_byte(0.5f + ch[c].c * (1.0f / kApvL2Scale) * r);
    }
    out[31] = 0;
}

// The decoded sample as ProbeVolume.hlsl's APVSample::Decode leaves it: L0 (with L2: minus the zz
// third), L1 and L2 per channel.
struct ApvDecoded {
    double l0[3], l1[3][3], l2[3][4], c[3];
};
// Texels, as the textures return them: L0_L1Rx (4 halves), L1G_L1Ry and L1B_L1Rz (unorm: byte /
// 255), with L2 L2_0, L2_1, L2_2, L2_3: 12 or 28 values. The shader decodes after the filter.
template <bool L2>
void apv_texels(const std::uint8_t* in, double* t) {
    for (int k = 0; k < 4; ++k) t[k] = half_at(in + 2 * k);
    for (int k = 8; k < (L2 ? 32 : 16); ++k) t[k - 4] = in[k] / 255.0;
}

template <bool L2>
ApvDecoded apv_decode_sample(const double* t) {
    ApvDecoded d{};
    double enc[3][3];  // [channel][axis]
    for (int c = 0; c < 3; ++c) d.l0[c] = t[c];
    enc[0][0] = t[3], enc[0][1] = t[7], enc[0][2] = t[11];
    for (int k = 0; k < 3; ++k) enc[1][k] = t[4 + k], enc[2][k] = t[8 + k];
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) d.l1[c][k] = (enc[c][k] - 0.5) * (2.0 * kApvL1Scale * d.l0[c]);
    if (L2) {
        for (int c = 0; c < 3; ++c) {
            for (int k = 0; k < 4; ++k) d.l2[c][k] = (t[12 + 4 * c + k] - 0.5) * (kApvL2Scale * d.l0[c]);
            d.c[c] = (t[24 + c] - 0.5) * kApvL2Scale * d.l0[c];
            d.l0[c] -= d.l2[c][2];
            d.l2[c][2] *= 3.0;
        }
    }
    return d;
}

template <bool L2>
Rgb apv_shade(const double* t, Vec3 n) {
    const ApvDecoded d = apv_decode_sample<L2>(t);
    const Vec3 e = to_engine(kAxesUnity, n);
    const double vb[4] = {e.x * e.y, e.y * e.z, e.z * e.z, e.z * e.x}, vc = e.x * e.x - e.y * e.y;
    Rgb out;
    for (int c = 0; c < 3; ++c) {
        double r = d.l1[c][0] * e.x + d.l1[c][1] * e.y + d.l1[c][2] * e.z;
        if (L2) r += d.l2[c][0] * vb[0] + d.l2[c][1] * vb[1] + d.l2[c][2] * vb[2] + d.l2[c][3] * vb[3] + d.c[c] * vc;
        out[c] = static_cast<float>(r + d.l0[c]);
    }
    return out;
}

template <bool L2>
Sh3Radiance apv_hub(const double* tex) {
    const ApvDecoded d = apv_decode_sample<L2>(tex);
    EngineSh t{};
    for (int c = 0; c < 3; ++c) {
        // Decoded L0 + d2 z^2 (d2 = 3 d) is L0 + d (3 z^2 - 1) with L0 the stored one.
        const double dz = L2 ? d.l2[c][2] / 3.0 : 0.0;
        t[0][c] = (d.l0[c] + dz) / kY00;
        t[3][c] = d.l1[c][0] / kY1, t[1][c] = d.l1[c][1] / kY1, t[2][c] = d.l1[c][2] / kY1;
        if (L2) {
            t[4][c] = d.l2[c][0] / kY2, t[5][c] = d.l2[c][1] / kY2, t[6][c] = dz / kY20, t[7][c] = d.l2[c][3] / kY2;
            t[8][c] = d.c[c] / kY22;
        }
    }
    return hub_from_engine_irradiance_sh(t, kAxesUnity);
}

// ---- Unreal volumetric lightmap -------------------------------------------------------------
// Epic's source is not public; the layout follows Unreal's public API reference
// (PrecomputedVolumetricLightmap.h, FVolumetricLightmapBasicBrickDataLayers: AmbientVector,
// SHCoefficients[6], SkyBentNormal, DirectionalLightShadowing) and the decode quoted in public
// discussions of VolumetricLightmapShared.ush (GetVolumetricLightmapSH3): AmbientVector is
// R11G11B10F, the DC of radiance SH in Unreal's axes and basis (Condon-Shortley sign, as zhc's);
// SHCoefficients[0..5] are B8G8R8A8: [2c] coefficients 1-4 and [2c + 1] coefficients 5-8 of channel
// c, each stored as coefficient / (ambient * scale) mapped from [-1, 1] to [0, 1], scales
// (0.488603, 0.488603, 0.488603, 1.092548) / 0.282095 and (1.092548, 4 * 0.315392, 1.092548,
// 2 * 0.546274) / 0.282095. Lighting: max(0, DotSH3(SH, CalcDiffuseTransferSH3(N, 1))) / pi, which
// is zhc's normalised irradiance clamped at 0. The entry stores the 28 bytes of SH (sky bent normal,
// 4 bytes, and directional shadowing, 1 byte, are not lighting SH: docs/engine-layouts.md). The
// encoder's details are not public: the entry takes the ratios to the float ambient floored at
// 1e-4, rounds bytes to nearest and packs the ambient as pack_r11g11b10f (quantize.h), the choices
// that invert the public decode.
constexpr double kUeBasis[9] = {0.282095, 0.488603, 0.488603, 0.488603, 1.092548, 1.092548, 0.315392, 1.092548, 0.546274};
constexpr double kUeScale[8] = {0.488603 / 0.282095, 0.488603 / 0.282095, 0.488603 / 0.282095, 1.092548 / 0.282095,
                                1.092548 / 0.282095, 4.0 * 0.315392 / 0.282095, 1.092548 / 0.282095, 2.0 * 0.546274 / 0.282095};
constexpr double kUeSign[9] = {1, -1, 1, -1, 1, -1, 1, -1, 1};  // Condon-Shortley

std::uint8_t unorm8_round(double v) {
    if (!(v > 0.0)) return 0;
    return static_cast<std::uint8_t>(std::lround(std::min(v, 1.0) * 255.0));
}

void unreal_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    const EngineSh t = engine_irradiance_sh(hub, kAxesUnreal);
    double u[9][3];
    for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c) u[i][c] = kUeSign[i] * t[i][c] / kIrradianceBandScale[band(i)];
    put_u32(out, pack_r11g11b10f(u[0][0], u[0][1], u[0][2]));
    for (int c = 0; c < 3; ++c)
        for (int half = 0; half < 2; ++half) {
            std::uint8_t rgba[4];
            const double inv_ambient = 1.0 / std::max(u[0][c], 1e-4);  // NaN ambient: 1e-4
            for (int k = 0; k < 4; ++k) {
                const int i = 1 + 4 * half + k;
                rgba[k] = unorm8_round(u[i][c] * inv_ambient / kUeScale[i - 1] * 0.5 + 0.5);
            }
            std::uint8_t* p = out + 4 + 4 * (2 * c + half);
            p[0] = rgba[2], p[1] = rgba[1], p[2] = rgba[0], p[3] = rgba[3];  // B8G8R8A8 in memory
        }
}

// Texels: the ambient's R, G, B, then each SHCoefficients texel's R, G, B, A (unorm; the bytes are
// B, G, R, A in memory): 27 values.
void unreal_texels(const std::uint8_t* in, double* t) {
    const Rgb ambient = unpack_r11g11b10f(get_u32(in));
    for (int c = 0; c < 3; ++c) t[c] = ambient[c];
    for (int j = 0; j < 6; ++j) {
        const std::uint8_t* p = in + 4 + 4 * j;
        t[3 + 4 * j] = p[2] / 255.0, t[4 + 4 * j] = p[1] / 255.0, t[5 + 4 * j] = p[0] / 255.0, t[6 + 4 * j] = p[3] / 255.0;
    }
}

// The nine radiance coefficients (Unreal's basis and axes) the shader reconstructs.
void unreal_coefficients(const double* t, double u[9][3]) {
    for (int c = 0; c < 3; ++c) {
        u[0][c] = t[c];
        for (int half = 0; half < 2; ++half)
            for (int k = 0; k < 4; ++k) {
                const int i = 1 + 4 * half + k;
                u[i][c] = (t[3 + 4 * (2 * c + half) + k] * 2.0 - 1.0) * t[c] * kUeScale[i - 1];
            }
    }
}

Sh3Radiance unreal_hub(const double* tex) {
    double u[9][3];
    unreal_coefficients(tex, u);
    EngineSh t{};
    for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c) t[i][c] = kUeSign[i] * u[i][c] * kIrradianceBandScale[band(i)];
    return hub_from_engine_irradiance_sh(t, kAxesUnreal);
}

Rgb unreal_shade(const double* tex, Vec3 n) {
    double u[9][3];
    unreal_coefficients(tex, u);
    const Vec3 e = to_engine(kAxesUnreal, n);
    const double x = e.x, y = e.y, z = e.z;
    // SHBasisFunction3 (Condon-Shortley sign) times CalcDiffuseTransferSH3's band factors pi, 2pi/3, pi/4.
    const double basis[9] = {kUeBasis[0],          -kUeBasis[1] * y,     kUeBasis[2] * z,
                             -kUeBasis[3] * x,     kUeBasis[4] * x * y,  -kUeBasis[5] * y * z,
                             kUeBasis[6] * (3.0 * z * z - 1.0), -kUeBasis[7] * x * z, kUeBasis[8] * (x * x - y * y)};
    const double lobe[3] = {kPi, 2.0 * kPi / 3.0, kPi / 4.0};
    Rgb out;
    for (int c = 0; c < 3; ++c) {
        double r = 0;
        for (int i = 0; i < 9; ++i) r += u[i][c] * basis[i] * lobe[band(i)];
        out[c] = static_cast<float>(std::max(r, 0.0) / kPi);
    }
    return out;
}

// ---- Godot 4 LightmapGI ---------------------------------------------------------------------
// godotengine/godot. Storage: scene/3d/lightmap_gi.cpp (LightmapGI::bake: probe_sh, 9 Colors a
// probe from the lightmapper; LightmapGIData::_get_probe_data "sh", a PackedColorArray: 9 x RGBA
// float32 = 144 bytes a probe). Values: modules/lightmapper_rd/lm_compute.glsl MODE_LIGHT_PROBES:
// radiance projected on the basis 0.282095, 0.488603 y, z, x, 1.092548 xy, yz, 0.315392
// (3z^2 - 1), 1.092548 xz, 0.546274 (x^2 - y^2) with weights 4 / rays (so radiance SH / pi, in
// Godot's axes, Y up), alpha left at 0. Evaluation (one blended probe per object, tetrahedral
// interpolation on the CPU): servers/rendering/renderer_rd/shaders/forward_clustered/
// scene_forward_clustered.glsl, lightmap capture: c4 sh0 + 2 c2 (sh1 y + sh2 z + sh3 x) + c3 sh6 z^2
// - c5 sh6 + c1 sh8 (x^2 - y^2) + 2 c1 (sh4 xy + sh7 xz + sh5 yz), constants c1..c5 = 0.429043,
// 0.511664, 0.743125, 0.886227, 0.247708, times the exposure normalisation (1 here); no clamp. That
// is zhc's normalised irradiance.
void godot_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    const EngineSh t = engine_irradiance_sh(hub, kAxesYUpRight);
    for (int i = 0; i < 9; ++i) {
        for (int c = 0; c < 3; ++c)
            put_f32(out + 16 * i + 4 * c, static_cast<float>(t[i][c] / kIrradianceBandScale[band(i)] / kPi));
        put_f32(out + 16 * i + 12, 0.0f);
    }
}

// Texels: the nine colours' R, G, B, A (the engine blends them on the CPU per object): 36 values.
void godot_texels(const std::uint8_t* in, double* t) {
    for (int k = 0; k < 36; ++k) t[k] = get_f32(in + 4 * k);
}

Sh3Radiance godot_hub(const double* tex) {
    EngineSh t{};
    for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c) t[i][c] = tex[4 * i + c] * kPi * kIrradianceBandScale[band(i)];
    return hub_from_engine_irradiance_sh(t, kAxesYUpRight);
}

Rgb godot_shade(const double* tex, Vec3 n) {
    const Vec3 e = to_engine(kAxesYUpRight, n);
    const double x = e.x, y = e.y, z = e.z;
    constexpr double c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
    Rgb out;
    for (int c = 0; c < 3; ++c) {
        auto s = [&](int i) { return tex[4 * i + c]; };
        out[c] = static_cast<float>(c1 * s(8) * (x * x - y * y) + c3 * s(6) * z * z + c4 * s(0) - c5 * s(6) +
                                    2.0 * c1 * s(4) * x * y + 2.0 * c1 * s(7) * x * z + 2.0 * c1 * s(5) * y * z +
                                    2.0 * c2 * s(3) * x + 2.0 * c2 * s(1) * y + 2.0 * c2 * s(2) * z);
    }
    return out;
}

// ---- VRChat Light Volumes -------------------------------------------------------------------
// REDSIM/VRCLightVolumes (Packages/red.sim.lightvolumes). Bake, Scripts/LightVolume.cs
// Save3DTexturesProgressive: from Unity's probes (L0 and L1 in Unity's format: zhc's normalised
// irradiance DC and linear term, Unity's axes) three RGBAHalf 3D textures, tex0 = (L0 r, g, b,
// 1.65 L1r.z), tex1 = 1.65 (L1r.x, L1g.x, L1b.x, L1g.z), tex2 = 1.65 (L1r.y, L1g.y, L1b.y, L1b.z):
// 24 bytes a probe. Atlas, Scripts/Texture3DAtlasGenerator.cs PostProcessSphericalHarmonics with
// the default colour correction (exposure 0, shadows 0, highlights 0): per channel
// LVUtils.LinearizeSingleSH halves L1 and scales it by min(L0 / |L1|, 1.13) (when |L1| > 0 and L0
// > 0), which deringes it (|L1| <= L0 keeps L0 + L1.n >= 0), then CorrectVector (v.normalized *
// |v|: Unity's normalized is 0 below magnitude 1e-5) on L1 and on the L0 colour, written as halves
// again. Evaluation, Shaders/LightVolumes.cginc LV_SampleLightVolumeTex and LightVolumeEvaluate:
// L0 + dot(L1, N) per channel (LV_EvaluateSH), no clamp. The C# steps run in float32, as here.
float unity_magnitude(const float v[3]) {
    return static_cast<float>(std::sqrt(double(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])));
}
void unity_correct_vector(float v[3]) {  // CorrectVector(v, 0, 1, 0) of Texture3DAtlasGenerator.cs
    const float mag = unity_magnitude(v);
    const float keep = std::max(mag, 0.0f);
    for (int k = 0; k < 3; ++k) v[k] = mag > 1e-5f ? v[k] / mag * keep : 0.0f;
}

void vrchat_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    constexpr float kCoeff = 1.65f;  // LightVolume.cs "To transform to bakery non-linear data format"
    const EngineSh t = engine_irradiance_sh(hub, kAxesUnity);
    float l0[3], l1[3][3];
    for (int c = 0; c < 3; ++c) {
        l0[c] = static_cast<float>(kY00 * t[0][c]);
        l1[c][0] = static_cast<float>(kY1 * t[3][c]);
        l1[c][1] = static_cast<float>(kY1 * t[1][c]);
        l1[c][2] = static_cast<float>(kY1 * t[2][c]);
    }
    // The bake's three textures, as halves.
    auto h = [](float v) { return unpack_half(pack_half(v)); };
    float tex[3][4] = {{h(l0[0]), h(l0[1]), h(l0[2]), h(l1[0][2] * kCoeff)},
                       {h(l1[0][0] * kCoeff), h(l1[1][0] * kCoeff), h(l1[2][0] * kCoeff), h(l1[1][2] * kCoeff)},
                       {h(l1[0][1] * kCoeff), h(l1[1][1] * kCoeff), h(l1[2][1] * kCoeff), h(l1[2][2] * kCoeff)}};
    // The atlas's post-processing.
    float L0[3] = {tex[0][0], tex[0][1], tex[0][2]};
    float L1[3][3] = {{tex[1][0], tex[2][0], tex[0][3]}, {tex[1][1], tex[2][1], tex[1][3]}, {tex[1][2], tex[2][2], tex[2][3]}};
    for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) L1[c][k] *= 0.5f;
        const float len = unity_magnitude(L1[c]);
        if (len > 0.0f && L0[c] > 0.0f) {
            const float s = std::min(L0[c] / len, 1.13f);
            for (int k = 0; k < 3; ++k) L1[c][k] *= s;
        }
        unity_correct_vector(L1[c]);
    }
    unity_correct_vector(L0);
    const float texel[3][4] = {{L0[0], L0[1], L0[2], L1[0][2]},
                               {L1[0][0], L1[1][0], L1[2][0], L1[1][2]},
                               {L1[0][1], L1[1][1], L1[2][1], L1[2][2]}};
    for (int k = 0; k < 12; ++k) put_u16(out + 2 * k, pack_half(texel[k / 4][k % 4]));
}

// Texels: the three texels' R, G, B, A (halves): 12 values.
void vrchat_texels(const std::uint8_t* in, double* t) {
    for (int k = 0; k < 12; ++k) t[k] = half_at(in + 2 * k);
}

// L0 and L1 (x, y, z) of channel c as LV_SampleLightVolumeTex packs them.
void vrchat_sample(const double* t, double l0[3], double l1[3][3]) {
    for (int c = 0; c < 3; ++c) {
        l0[c] = t[c];
        l1[c][0] = t[4 + c];
        l1[c][1] = t[8 + c];
        l1[c][2] = t[4 * c + 3];  // z: tex0.a (red), tex1.a (green), tex2.a (blue)
    }
}

Rgb vrchat_shade(const double* tex, Vec3 n) {
    double l0[3], l1[3][3];
    vrchat_sample(tex, l0, l1);
    const Vec3 e = to_engine(kAxesUnity, n);
    Rgb out;
    for (int c = 0; c < 3; ++c) out[c] = static_cast<float>(l0[c] + l1[c][0] * e.x + l1[c][1] * e.y + l1[c][2] * e.z);
    return out;
}

Sh3Radiance vrchat_hub(const double* tex) {
    double l0[3], l1[3][3];
    vrchat_sample(tex, l0, l1);
    EngineSh t{};
    for (int c = 0; c < 3; ++c) {
        t[0][c] = l0[c] / kY00;
        t[3][c] = l1[c][0] / kY1, t[1][c] = l1[c][1] / kY1, t[2][c] = l1[c][2] / kY1;
    }
    return hub_from_engine_irradiance_sh(t, kAxesUnity);
}

// ---- RealityKit -----------------------------------------------------------------------------
// No source is public. Inferred from public descriptions of Apple's RealityKit (2026) probe lighting:
// L1 radiance SH as float32, 48 bytes a probe, tetrahedral interpolation. The entry stores the four
// coefficients (DC, then y, z, x, the basis without the Condon-Shortley sign) x R, G, B in glTF's
// axes (RealityKit is Y up, right-handed) and evaluates sum c_i A_l Y_i(n) / pi, no clamp: zhc's sh2
// in RealityKit's axes, so it measures as sh2 does.
void realitykit_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    const EngineSh t = engine_irradiance_sh(hub, kAxesYUpRight);
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c) put_f32(out + 12 * i + 4 * c, static_cast<float>(t[i][c] / kIrradianceBandScale[band(i)]));
}

// Texels: the 12 floats.
void realitykit_texels(const std::uint8_t* in, double* t) {
    for (int k = 0; k < 12; ++k) t[k] = get_f32(in + 4 * k);
}

Sh3Radiance realitykit_hub(const double* tex) {
    EngineSh t{};
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c) t[i][c] = tex[3 * i + c] * kIrradianceBandScale[band(i)];
    return hub_from_engine_irradiance_sh(t, kAxesYUpRight);
}

Rgb realitykit_shade(const double* tex, Vec3 n) {
    const Vec3 e = to_engine(kAxesYUpRight, n);
    Rgb out;
    for (int c = 0; c < 3; ++c) {
        auto s = [&](int i) { return tex[3 * i + c]; };
        out[c] = static_cast<float>((kPi * kY00 * s(0) + (2.0 * kPi / 3.0) * kY1 * (s(1) * e.y + s(2) * e.z + s(3) * e.x)) / kPi);
    }
    return out;
}

// ---- ambient cubes (Bevy, Source 2) ---------------------------------------------------------
// Valve's ambient cube (Mitchell 2006, "Shading in Valve's Source Engine", slides 27-28): six
// colours, the irradiance seen by a surface facing +X, -X, +Y, -Y, +Z, -Z; a normal n gets
// sum over axes of n_a^2 times the colour of the face on n_a's side. Not an SH3 function: the
// entries' irradiance is their own and decode returns its least-squares SH3 projection
// (IrradianceModel::kOwn). Faces are stored in the order +X, -X, +Y, -Y, +Z, -Z of the engine's axes.

// The six face colours from a hub: zhc's normalised irradiance at each face's direction, as the
// bakers store them (Blender EEVEE's irradiance grid, which bevy's export reads, filters each face as
// the cosine-weighted mean radiance of its hemisphere: that irradiance).
void cube_faces(const Sh3Radiance& hub, const Mat3& axes, Rgb faces[6]) {
    const Mat3 back = transpose(axes);
    for (int f = 0; f < 6; ++f) {
        Vec3 d{};
        const double s = f % 2 == 0 ? 1.0 : -1.0;
        d = f / 2 == 0 ? Vec3{s, 0, 0} : (f / 2 == 1 ? Vec3{0, s, 0} : Vec3{0, 0, s});
        faces[f] = irradiance(hub, back * d);
    }
}

Rgb cube_evaluate(const double faces[6][3], Vec3 e) {
    const double n[3] = {e.x, e.y, e.z};
    Rgb out;
    for (int c = 0; c < 3; ++c) {
        double r = 0;
        for (int a = 0; a < 3; ++a) r += n[a] * n[a] * faces[2 * a + (n[a] < 0 ? 1 : 0)][c];  // the face on n_a's side
        out[c] = static_cast<float>(r);
    }
    return out;
}

// The least-squares SH3 projection of a cube's reconstruction: with S = (C+ + C-) / 2 and
// D = (C+ - C-) / 2 per axis, sum S_a n_a^2 is in SH3 exactly and n_a |n_a| projects onto
// (3/4) n_a (its Y1 coefficient is pi k1, pi k1^2 = 3/4; its L0 and L2 parts vanish by symmetry).
Sh3Radiance cube_projection(const double faces[6][3], const Mat3& axes) {
    Poly p;
    for (int c = 0; c < 3; ++c) {
        double s[3];
        for (int a = 0; a < 3; ++a) {
            s[a] = 0.5 * (faces[2 * a][c] + faces[2 * a + 1][c]);
            p.b[a][c] = 0.375 * (faces[2 * a][c] - faces[2 * a + 1][c]);
        }
        p.a[c] = (s[0] + s[1] + s[2]) / 3.0;
        for (int a = 0; a < 3; ++a) p.q[a][a][c] = s[a] - p.a[c];
    }
    return hub_of_poly(turn(p, transpose(axes)));
}

// Bevy irradiance volumes. bevyengine/bevy crates/bevy_pbr/src/light_probe/irradiance_volume.rs
// (module docs: a voxel's six sides in a 3D texture of (Rx, 2Ry, 3Rz), 24 bytes a voxel, chosen so
// that RGB9E5 works) and irradiance_volume.wgsl irradiance_volume_light (one trilinear tap per axis,
// the negative side where N < 0, rgb_x N.x^2 + rgb_y N.y^2 + rgb_z N.z^2, times the intensity, 1 here).
// Bevy's axes are glTF's. Faces as RGB9E5 (pack_rgb9e5, quantize.h).
void bevy_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    Rgb faces[6];
    cube_faces(hub, kAxesYUpRight, faces);
    for (int f = 0; f < 6; ++f) put_u32(out + 4 * f, pack_rgb9e5(faces[f].r, faces[f].g, faces[f].b));
}
// Texels: each face's R, G, B (one filtered tap per face the normal's signs select): 18 values.
void bevy_texels(const std::uint8_t* in, double* t) {
    for (int f = 0; f < 6; ++f) {
        const Rgb v = unpack_rgb9e5(get_u32(in + 4 * f));
        for (int c = 0; c < 3; ++c) t[3 * f + c] = v[c];
    }
}
Rgb bevy_shade(const double* tex, Vec3 n) {
    double faces[6][3];
    for (int k = 0; k < 18; ++k) faces[k / 3][k % 3] = tex[k];
    return cube_evaluate(faces, to_engine(kAxesYUpRight, n));
}
Sh3Radiance bevy_hub(const double* tex) {
    double faces[6][3];
    for (int k = 0; k < 18; ++k) faces[k / 3][k % 3] = tex[k];
    return cube_projection(faces, kAxesYUpRight);
}

// Source 2. No source is public. Inferred from public descriptions (ambient cube, RGBM, 24 bytes a
// probe) and Valve's ambient cube above; Source's axes (Z up, right-handed) are zhc's. RGBM with an
// 8-bit multiplier over the range kRgbmRange (engine_layouts.h): m = ceil(max(r, g, b) / range * 255)
// / 255, each colour round(c / (m range) * 255), decoded as byte / 255 * m * range.
void source2_encode(const Sh3Radiance& hub, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    Rgb faces[6];
    cube_faces(hub, kAxesZUpRight, faces);
    for (int f = 0; f < 6; ++f) {
        double v[3];
        for (int c = 0; c < 3; ++c) v[c] = faces[f][c] > 0.0f ? double(faces[f][c]) : 0.0;  // NaN and negative: 0
        const double top = std::max({v[0], v[1], v[2]}) / kRgbmRange;
        const double m = std::min(255.0, std::ceil(std::min(top, 1.0) * 255.0));
        std::uint8_t* p = out + 4 * f;
        p[3] = static_cast<std::uint8_t>(m);
        for (int c = 0; c < 3; ++c) p[c] = m > 0 ? unorm8_round(v[c] / (m / 255.0 * kRgbmRange)) : 0;
    }
}
// Texels: each face's R, G, B, M (unorm), filtered before the multiply: 24 values.
void source2_texels(const std::uint8_t* in, double* t) {
    for (int k = 0; k < 24; ++k) t[k] = in[k] / 255.0;
}
void source2_faces(const double* t, double faces[6][3]) {
    for (int f = 0; f < 6; ++f)
        for (int c = 0; c < 3; ++c) faces[f][c] = t[4 * f + c] * t[4 * f + 3] * kRgbmRange;
}
Rgb source2_shade(const double* tex, Vec3 n) {
    double faces[6][3];
    source2_faces(tex, faces);
    return cube_evaluate(faces, to_engine(kAxesZUpRight, n));
}
Sh3Radiance source2_hub(const double* tex) {
    double faces[6][3];
    source2_faces(tex, faces);
    return cube_projection(faces, kAxesZUpRight);
}

// ---- the table part -------------------------------------------------------------------------

// Every entry's decode and irradiance go through its texels, as the engine's shader reads them.
template <int N, void (*Texels)(const std::uint8_t*, double*), Sh3Radiance (*Hub)(const double*)>
Sh3Radiance via_texels_decode(const std::uint8_t* in, const CodecOptions&) {
    double t[N];
    Texels(in, t);
    return Hub(t);
}
template <int N, void (*Texels)(const std::uint8_t*, double*), Rgb (*Shade)(const double*, Vec3)>
Rgb via_texels_irradiance(const std::uint8_t* in, const CodecOptions&, Vec3 n) {
    double t[N];
    Texels(in, t);
    return Shade(t, n);
}
#define ZHC_ENGINE_FUNCTIONS(N, texels, hub, shade) via_texels_decode<N, texels, hub>, via_texels_irradiance<N, texels, shade>

constexpr CodecTraits engine_traits(std::string_view engine, IrradianceModel model) {
    CodecTraits t;
    t.irradiance_model = model;
    t.engine = engine;
    return t;
}

const Codec kEngineCodecs[] = {
    {"threejs_grid_float", "three.js LightProbeGrid (WebGL): L2 radiance SH, 7 RGBA32F texels, clamped at 0", 112,
     threejs_encode<false>, ZHC_ENGINE_FUNCTIONS(28, threejs_texels<false>, threejs_hub, threejs_shade),
     engine_traits("three.js", IrradianceModel::kSh3Clamped)},
    {"threejs_grid_half", "three.js LightProbeGrid (WebGPU): L2 radiance SH, 7 RGBA16F texels, clamped at 0", 56,
     threejs_encode<true>, ZHC_ENGINE_FUNCTIONS(28, threejs_texels<true>, threejs_hub, threejs_shade),
     engine_traits("three.js", IrradianceModel::kSh3Clamped)},
    {"unity_apv_l1", "Unity APV L1: L0 + L1 red x in RGBA16F, L1 as ratios to L0 in 2 RGBA8", 16, apv_encode<false>,
     ZHC_ENGINE_FUNCTIONS(12, apv_texels<false>, apv_hub<false>, apv_shade<false>),
     engine_traits("Unity APV", IrradianceModel::kSh3)},
    {"unity_apv_l2", "Unity APV L2: the L1 texels + L2 as ratios to L0 in 4 RGBA8", 32, apv_encode<true>,
     ZHC_ENGINE_FUNCTIONS(28, apv_texels<true>, apv_hub<true>, apv_shade<true>),
     engine_traits("Unity APV", IrradianceModel::kSh3)},
    {"unreal_vlm_l2", "Unreal volumetric lightmap: L2 radiance SH, R11G11B10F ambient + 6 BGRA8 ratios, clamped at 0",
     28, unreal_encode, ZHC_ENGINE_FUNCTIONS(27, unreal_texels, unreal_hub, unreal_shade),
     engine_traits("Unreal", IrradianceModel::kSh3Clamped)},
    {"bevy_ambient_cube", "Bevy irradiance volume: ambient cube, 6 faces in RGB9E5", 24, bevy_encode,
     ZHC_ENGINE_FUNCTIONS(18, bevy_texels, bevy_hub, bevy_shade), engine_traits("Bevy", IrradianceModel::kOwn)},
    {"vrchat_lv_l1", "VRChat Light Volumes: L0 + deringed L1 in 3 RGBA16F texels", 24, vrchat_encode,
     ZHC_ENGINE_FUNCTIONS(12, vrchat_texels, vrchat_hub, vrchat_shade),
     engine_traits("VRChat Light Volumes", IrradianceModel::kSh3)},
    {"godot_l2", "Godot 4 LightmapGI probes: L2 radiance SH / pi, 9 RGBA32F colours", 144, godot_encode,
     ZHC_ENGINE_FUNCTIONS(36, godot_texels, godot_hub, godot_shade), engine_traits("Godot", IrradianceModel::kSh3)},
    {"realitykit_l1", "RealityKit probes (inferred): L1 radiance SH, 12 float32", 48, realitykit_encode,
     ZHC_ENGINE_FUNCTIONS(12, realitykit_texels, realitykit_hub, realitykit_shade),
     engine_traits("RealityKit", IrradianceModel::kSh3)},
    {"source2_ambient_cube", "Source 2 (inferred): ambient cube, 6 faces in RGBM8", 24, source2_encode,
     ZHC_ENGINE_FUNCTIONS(24, source2_texels, source2_hub, source2_shade), engine_traits("Source 2", IrradianceModel::kOwn)},
};
#undef ZHC_ENGINE_FUNCTIONS

const EngineLayoutInfo kLayouts[] = {
    {"threejs_grid_float", "three.js LightProbeGrid, WebGL (r184+)",
     "three r187 examples/jsm/lighting/LightProbeGridWebGL.js _ensureTextures, repack; "
     "src/renderers/shaders/ShaderChunk/lightprobes_pars_fragment.glsl.js getLightProbeGridIrradiance",
     kAxesYUpRight, 112, 0, 7, "hardware trilinear, 7 taps of one RGBA atlas", true, 28, threejs_texels<false>, threejs_shade},
    {"threejs_grid_half", "three.js LightProbeGrid, WebGPU (r184+)",
     "three r187 examples/jsm/lighting/LightProbeGrid.js _ensureTextures, repackNode; "
     "examples/jsm/tsl/lighting/LightProbeGridNode.js evaluateGridIrradiance",
     kAxesYUpRight, 56, 0, 7, "hardware trilinear, 7 taps of one RGBA atlas", true, 28, threejs_texels<true>, threejs_shade},
    {"unity_apv_l1", "Unity Adaptive Probe Volumes, L1",
     "Unity-Technologies/Graphics core Runtime/Lighting/ProbeVolume: ProbeBrickPool.cs CreateDataLocation, "
     "DecodeSH.hlsl, ProbeVolume.hlsl SampleAPV / EvaluateAdaptiveProbeVolume; "
     "Editor ProbeGIBaking.Serialization.cs WriteToShaderCoeffsL0L1",
     kAxesUnity, 16, 16, 3, "hardware trilinear in 4x4x4 bricks", true, 12, apv_texels<false>, apv_shade<false>},
    {"unity_apv_l2", "Unity Adaptive Probe Volumes, L2",
     "as unity_apv_l1, plus DecodeSH.hlsl DecodeSH_L2 and WriteToShaderCoeffsL2", kAxesUnity, 32, 32, 7,
     "hardware trilinear in 4x4x4 bricks", true, 28, apv_texels<true>, apv_shade<true>},
    {"unreal_vlm_l2", "Unreal volumetric lightmap",
     "Unreal's public API reference (PrecomputedVolumetricLightmap.h FVolumetricLightmapBasicBrickDataLayers) and "
     "the decode of VolumetricLightmapShared.ush as quoted publicly; Epic's source is not public",
     kAxesUnreal, 33, 33, 7, "hardware trilinear in bricks (indirection texture)", true, 27, unreal_texels,
     unreal_shade},
    {"bevy_ambient_cube", "Bevy irradiance volume",
     "bevyengine/bevy crates/bevy_pbr/src/light_probe/irradiance_volume.rs (layout), irradiance_volume.wgsl "
     "irradiance_volume_light", kAxesYUpRight, 24, 24, 3, "hardware trilinear, 3 taps (one per axis)", true, 18,
     bevy_texels, bevy_shade},
    {"vrchat_lv_l1", "VRChat Light Volumes",
     "REDSIM/VRCLightVolumes Scripts/LightVolume.cs Save3DTexturesProgressive, Scripts/Texture3DAtlasGenerator.cs "
     "PostProcessSphericalHarmonics, Scripts/LVUtils.cs LinearizeSingleSH, Shaders/LightVolumes.cginc "
     "LV_SampleLightVolumeTex / LightVolumeEvaluate",
     kAxesUnity, 24, 24, 3, "hardware trilinear, 3 taps of one RGBA16F atlas", true, 12, vrchat_texels, vrchat_shade},
    {"godot_l2", "Godot 4 LightmapGI probes",
     "godotengine/godot scene/3d/lightmap_gi.cpp LightmapGI::bake, LightmapGIData::_get_probe_data; "
     "modules/lightmapper_rd/lm_compute.glsl MODE_LIGHT_PROBES; scene_forward_clustered.glsl lightmap capture",
     kAxesYUpRight, 0, 144, 9, "tetrahedral on the CPU, once per object (9 RGBA of the blended probe)", false, 36,
     godot_texels, godot_shade},
    {"realitykit_l1", "RealityKit probe lighting (inferred)",
     "no public source: public descriptions (L1 float, 48 bytes, tetrahedra)", kAxesYUpRight, 0, 48, 3,
     "tetrahedral, per object (inferred)", false, 12, realitykit_texels, realitykit_shade},
    {"source2_ambient_cube", "Source 2 light probes (inferred)",
     "no public source: public descriptions (ambient cube, RGBM, 24 bytes) and Mitchell 2006 (Valve's ambient cube)",
     kAxesZUpRight, 24, 24, 3, "volume texture, hardware trilinear (inferred)", true, 24, source2_texels, source2_shade},
};
static_assert(sizeof kLayouts / sizeof kLayouts[0] == sizeof kEngineCodecs / sizeof kEngineCodecs[0]);

}  // namespace

EngineSh engine_irradiance_sh(const Sh3Radiance& hub, const Mat3& axes) { return sh_of_poly(turn(poly_of_hub(hub), axes)); }

Sh3Radiance hub_from_engine_irradiance_sh(const EngineSh& sh, const Mat3& axes) {
    return hub_of_poly(turn(poly_of_sh(sh), transpose(axes)));
}

std::span<const Codec> engine_codecs() { return kEngineCodecs; }

std::span<const EngineLayoutInfo> engine_layouts() { return kLayouts; }

const EngineLayoutInfo* find_engine_layout(std::string_view codec_name) {
    for (const EngineLayoutInfo& l : kLayouts)
        if (l.codec == codec_name) return &l;
    return nullptr;
}

}  // namespace zhc
