// runtime/zhc.glsl on a real GLSL implementation: Mesa's llvmpipe through surfaceless EGL and a
// desktop GL 4.5 core context (set-up as tests/test_mesa_bc.cpp). The shader source is read from
// runtime/zhc.glsl at run time, put after "#version 450" and followed by a small compute main that
// decodes probe words from an SSBO and writes SH3 radiance and irradiance at a normal; the same
// source after "#version 310 es" runs again on llvmpipe's OpenGL ES 3.1 (smaller sample). Every entry
// of the codec table (zhc::codecs()) must have a GLSL decoder; each is compared with the C++ codec
// (decode_probe / Codec::irradiance) on >= 100,000 probes (coloured lights + ambient, random SH, the
// eight sample maps under random rotations) spread over header parameter sets, plus 20,000 probes of
// random bytes. DC unpacking (R11G11B10F, RGB9E5, half) must be bit-exact; the IrradZ lightmap
// evaluator is compared with irradz::evaluate on 200,000 texels, the HLSH one on 100,000 inputs.
//
// Error metric. The GPU computes in binary32 (u = 2^-24), the codec in double (then rounds to float).
// A sum of terms computed in float has an absolute error of a few u times the sum of the terms'
// MAGNITUDES, not of the result (which may cancel to 0), so every difference is measured in units of
// u * S, S a per-channel "probe scale" computed here in double (see Scale below):
//   S = Y00 |c0| + (2/3) Y1 sum_i M_i + (1/4) [0.631 sum_{L2} M_i  |  3 Y20 Z]      (irradiance)
// with M_i = |c_i|, or max(|c_i|, R_i |c0|) for quantised coefficients (R_i the ratio bound: a ratio
// decoded in float is off by a few u of R_i, not of the ratio), and for the zonal (ZH3) families
// Z = (|f20| + G |v|) (1 + kappa): f20 the zonal coefficient, v the L1 vector, G the hallucination's
// coefficient magnitude plus slope over p in [0, sqrt3] (0 when the zonal is stored), kappa the
// condition number of the axis (sum |w_k| |v_k| / |sum w_k v_k| for the luminance axis: the float
// error of the normalised axis is ~ kappa u; 1 per channel, and 1 when every L1 is exactly 0, where
// both sides take +Z exactly). A decoded coefficient is measured against its own M (sqrt3 Z for an
// expanded zonal L2 coefficient).
//
// The bounds (in u S) come from counting roundings on the longest path, first order, with the GLSL
// 4.50 precision rules (+, * correctly rounded; / 2.5 ulp; inversesqrt 2 ulp):
//  * evaluation of 9 terms: basis value (<= 3 roundings + 1 for the constant) times a coefficient
//    (1) times the band scale (1), summed (<= 8): 14; the codec's own float roundings of the
//    band-scaled coefficient and of the result: 1.5. Float layouts: C = 16.
//  * quantised ratio: (c - bv) / bv (2.5), sign-square (2 x 2.5 + 1), affine map (interval constants
//    2, multiply 1, add 1), times DC (1), irradiance-storage rescale (1): <= 13.5 on top of the 16
//    above, plus the codec's float rounding of the coefficient (1). Quantised: C = 32.
//  * decoded coefficients: float layouts are exact (bit copy; irradiance storage: one multiply by
//    1.5); quantised <= 14.5; expanded zonal L2: axis (kappa u, counted in Z) and <= 6 roundings of
//    the basis products. Decode: C = 16.
//  * An absolute 2^-120 covers flush-to-zero of denormals (GLSL allows it).
// A codec result that is not finite is not compared (garbage bytes: Inf/NaN DC); when S is within a
// factor 64 of FLT_MAX the float computation may overflow where double does not, so a non-finite
// GPU value is accepted there. Everything else must be within the bound.
#include "gl/egl_context.h"
#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/lightmap/irradz.h"
#include "codec/lightmap/lightmap.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "codec/probe/zh3.h"
#include "support.h"

#ifndef ZHC_RUNTIME_GLSL_PATH
#error "ZHC_RUNTIME_GLSL_PATH (path of runtime/zhc.glsl) must be defined by the build"
#endif

namespace zhc {
namespace {

constexpr double kU = 1.0 / 16777216.0;           // 2^-24, unit roundoff of binary32
const double kAbs = std::ldexp(1.0, -120);         // flush-to-zero allowance
constexpr double kCFloat = 16, kCQuant = 32, kCDecode = 16, kCLightmap = 16;
constexpr int kOutFloats = 30;  // per item: 27 SH3 radiance + 3 irradiance

// The test main appended after zhc.glsl. Modes: 0 probe decode + irradiance, 1 IrradZ texel,
// 2 DC unpacking, 3 HLSH.
const char* kTestMain = R"(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Words { uint words[]; };
layout(std430, binding = 1) readonly buffer Normals { float normals[]; };
layout(std430, binding = 2) writeonly buffer Out { float outv[]; };
uniform uint uCount;
uniform uint uStride;
uniform uint uMode;
uniform uvec4 uA;  // family, hallucination, bits, sqrtEncoding
uniform uvec4 uB;  // l2Bound, dcFormat, zonalMapping, axisMode
uniform uint uKind;
uniform vec3 uLum;
uniform vec2 uCurve;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uCount) return;
    uint o = i * 30u;
    vec3 n = vec3(normals[3u * i], normals[3u * i + 1u], normals[3u * i + 2u]);
    if (uMode == 0u) {
        ZhcFormat f = ZhcFormat(uA.x, uA.y, uA.z, uA.w, uB.x, uB.y, uB.z, uB.w, uKind, uLum, uCurve);
        uint w[27];
        for (uint k = 0u; k < 27u; ++k) w[k] = k < uStride ? words[i * uStride + k] : 0u;
        ZhcSh3 s = zhcDecode(w, f);
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) outv[o + uint(3 * c + k)] = s.c[c][k];
        vec3 e = zhcIrradiance(w, f, n);
        outv[o + 27u] = e.x; outv[o + 28u] = e.y; outv[o + 29u] = e.z;
    } else if (uMode == 1u) {
        uint b = i * 7u;
        vec3 iz = uintBitsToFloat(uvec3(words[b], words[b + 1u], words[b + 2u]));
        float wa = uintBitsToFloat(words[b + 3u]);
        vec2 uv = uintBitsToFloat(uvec2(words[b + 4u], words[b + 5u]));
        vec3 e = zhcIrradZIrradiance(iz, wa, uv, n, words[b + 6u]);
        outv[o] = e.x; outv[o + 1u] = e.y; outv[o + 2u] = e.z;
        vec3 d = zhcDecodeHemiOct(uv);
        outv[o + 3u] = d.x; outv[o + 4u] = d.y; outv[o + 5u] = d.z;
    } else if (uMode == 3u) {
        uint b = i * 12u;
        vec3 v[4];
        for (uint k = 0u; k < 4u; ++k)
            v[k] = uintBitsToFloat(uvec3(words[b + 3u * k], words[b + 3u * k + 1u], words[b + 3u * k + 2u]));
        vec3 e = zhcHlshIrradiance(v[0], v[1], v[2], v[3], n);
        outv[o] = e.x; outv[o + 1u] = e.y; outv[o + 2u] = e.z;
    } else {
        uint w = words[i];
        vec3 a = zhcUnpackR11G11B10F(w), b = zhcUnpackRGB9E5(w);
        outv[o] = a.x; outv[o + 1u] = a.y; outv[o + 2u] = a.z;
        outv[o + 3u] = b.x; outv[o + 4u] = b.y; outv[o + 5u] = b.z;
        outv[o + 6u] = zhcUnpackHalf(w & 0xFFFFu); outv[o + 7u] = zhcUnpackHalf(w >> 16);
    }
}
)";

std::string read_text(const char* path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// ---- codec table -> GLSL format ----------------------------------------------------------------------

// GLSL constants (runtime/zhc.glsl); checked against the file by glsl_entries().
enum : std::uint32_t { kSh3F32 = 0, kSh2F32 = 1, kZh3F32 = 2, kZh3Q16 = 3, kSh3Q28 = 4, kSh2Q = 5 };
enum : std::uint32_t { kHallNone = 0, kHallAmbdir = 1, kHallSphere = 2, kHallCurve = 3, kHallCurveAdaptive = 4 };

struct GlslEntry {
    std::uint32_t family, hallucination;
    ZonalAxis axis;  // the table's axis column; must equal the codec entry's CodecTraits::zonal_axis
};

// runtime/zhc.glsl's table of the codec table's entries, its lines "//   NAME ZHC_LAYOUT_* ZHC_HALL_*
// AXIS", with the values of the constants from its "const uint ZHC_... = Nu;" lines. The test takes
// every entry's GLSL format from here; an entry missing from the file fails the test.
const std::map<std::string, GlslEntry, std::less<>>& glsl_entries() {
    static const std::map<std::string, GlslEntry, std::less<>> m = [] {
        const std::string text = read_text(ZHC_RUNTIME_GLSL_PATH);
        std::map<std::string, std::uint32_t> constants;
        std::vector<std::vector<std::string>> rows;  // the table lines, split into words
        std::istringstream lines(text);
        for (std::string line; std::getline(lines, line);) {
            std::istringstream in(line);
            std::vector<std::string> w;
            for (std::string word; in >> word;) w.push_back(word);
            if (w.size() >= 5 && w[0] == "const" && w[1] == "uint" && w[3] == "=" && w[4].size() > 2 &&  // + a comment
                w[4].substr(w[4].size() - 2) == "u;")
                constants[w[2]] = static_cast<std::uint32_t>(std::stoul(w[4]));
            else if (w.size() == 5 && w[0] == "//" && w[2].rfind("ZHC_LAYOUT_", 0) == 0 && w[3].rfind("ZHC_HALL_", 0) == 0)
                rows.push_back(w);
        }
        const std::map<std::string, ZonalAxis> axes = {{"none", ZonalAxis::kNone},
                                                        {"luminance", ZonalAxis::kLuminance},
                                                        {"channel", ZonalAxis::kPerChannel},
                                                        {"header", ZonalAxis::kFromParams}};
        std::map<std::string, GlslEntry, std::less<>> out;
        for (const auto& w : rows) {
            const bool known = constants.count(w[2]) && constants.count(w[3]) && axes.count(w[4]);
            EXPECT_TRUE(known) << "runtime/zhc.glsl: unknown constant or axis in the table line of " << w[1];
            if (known) out[w[1]] = GlslEntry{constants[w[2]], constants[w[3]], axes.at(w[4])};
        }
        // The test's own copies of the constants (its bounds depend on the family) must agree.
        const std::pair<const char*, std::uint32_t> mine[] = {
            {"ZHC_LAYOUT_SH3_F32", kSh3F32}, {"ZHC_LAYOUT_SH2_F32", kSh2F32},   {"ZHC_LAYOUT_ZH3_F32", kZh3F32},
            {"ZHC_LAYOUT_ZH3_Q16", kZh3Q16}, {"ZHC_LAYOUT_SH3_Q28", kSh3Q28},   {"ZHC_LAYOUT_SH2_Q", kSh2Q},
            {"ZHC_HALL_NONE", kHallNone},    {"ZHC_HALL_AMBDIR", kHallAmbdir},  {"ZHC_HALL_SPHERE", kHallSphere},
            {"ZHC_HALL_CURVE", kHallCurve},  {"ZHC_HALL_CURVE_ADAPTIVE", kHallCurveAdaptive}};
        for (const auto& [name, value] : mine)
            EXPECT_TRUE(constants.count(name) && constants[name] == value) << name << " in runtime/zhc.glsl";
        return out;
    }();
    return m;
}

// The axis the shader is told (ZhcFormat.axisMode): the entry's fixed axis, else the header's.
std::uint32_t axis_mode(const GlslEntry& e, const CodecOptions& p) {
    if (e.axis == ZonalAxis::kLuminance) return 0;
    if (e.axis == ZonalAxis::kPerChannel) return 1;
    return static_cast<std::uint32_t>(p.axis_mode);
}

bool is_quantised(std::uint32_t family) { return family >= kZh3Q16; }
bool is_zonal(const GlslEntry& e) { return e.family == kZh3F32 || e.family == kZh3Q16 || e.hallucination != kHallNone; }
bool has_l2(const GlslEntry& e) { return e.family == kSh3F32 || e.family == kSh3Q28 || is_zonal(e); }

// ---- probes ------------------------------------------------------------------------------------------

std::vector<Sh3Radiance> envmap_probes() {
    std::vector<Sh3Radiance> out;
    for (const std::string& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        out.push_back(project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2));
    }
    return out;
}

Mat3 random_rotation(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const Vec3 axis = test::uniform_direction(u(rng), u(rng));
    return rotation_axis_angle(axis, 2 * kPi * u(rng));
}

Rgb random_colour(std::mt19937_64& rng, double scale) {
    std::uniform_real_distribution<double> u(0, 1);
    return {static_cast<float>(scale * u(rng)), static_cast<float>(scale * u(rng)), static_cast<float>(scale * u(rng))};
}

// kind 0: several coloured lights + ambient; 1: random SH; 2: a sample map, rotated.
Sh3Radiance random_probe(std::mt19937_64& rng, const std::vector<Sh3Radiance>& maps, int kind) {
    std::uniform_real_distribution<double> u(0, 1);
    const double exposure = std::pow(10.0, -3.0 + 6.0 * u(rng));
    if (kind == 0) {
        Sh3Radiance sh = project_constant(random_colour(rng, exposure * u(rng) * 0.2));
        const int lights = 1 + static_cast<int>(u(rng) * 4);
        for (int l = 0; l < lights; ++l) {
            const Vec3 d = test::uniform_direction(u(rng), u(rng));
            const Rgb c = random_colour(rng, exposure * std::pow(10.0, 2.0 * u(rng) - 1.0));
            sh = sh + (u(rng) < 0.5 ? project_directional(d, c) : project_cone(d, 0.05 + 1.5 * u(rng), c));
        }
        return sh;
    }
    if (kind == 1) {
        std::normal_distribution<double> g(0, 1);
        Sh3Radiance sh;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) sh[i][k] = static_cast<float>(exposure * g(rng));
        if (u(rng) < 0.5)
            for (int k = 0; k < 3; ++k) sh[0][k] = std::fabs(sh[0][k]) * 4;  // mostly positive
        return sh;
    }
    Sh3Radiance sh = rotate(maps[static_cast<size_t>(u(rng) * static_cast<double>(maps.size())) % maps.size()],
                            random_rotation(rng));
    return scale(sh, exposure);
}

// ---- error scale (see the file comment) ----------------------------------------------------------------

double ratio_bound_radiance(int i, L2Bound bound) {
    if (i < 4) return std::sqrt(3.0);
    if (i == 6) return std::sqrt(5.0);
    return bound == L2Bound::kTight ? std::sqrt(15.0) / 2 : std::sqrt(5.0);
}

struct Scale {
    double irradiance[3];  // S per channel
    double coeff[9][3];    // scale of each decoded coefficient
    bool defined = true;   // false: ill-conditioned axis (kappa infinite), not compared
};

Scale probe_scale(const GlslEntry& e, const CodecOptions& p, const Sh3Radiance& d) {
    Scale s;
    const bool quant = is_quantised(e.family);
    const double w[3] = {p.luminance.r, p.luminance.g, p.luminance.b};
    double m[9][3];
    for (int k = 0; k < 3; ++k) {
        const double dc = std::fabs(double(d[0][k]));
        m[0][k] = dc;
        for (int i = 1; i < 9; ++i)
            m[i][k] = quant ? std::max(std::fabs(double(d[i][k])), ratio_bound_radiance(i, p.l2_bound) * dc)
                            : std::fabs(double(d[i][k]));
    }
    // Axis condition numbers.
    double kappa[3] = {1, 1, 1};
    const std::uint32_t axis = axis_mode(e, p);
    auto vec = [&](int k) { return Vec3{-double(d[3][k]), -double(d[1][k]), double(d[2][k])}; };
    auto vmag = [&](int k) { return std::sqrt(m[1][k] * m[1][k] + m[2][k] * m[2][k] + m[3][k] * m[3][k]); };
    if (is_zonal(e)) {
        if (axis == 0) {
            Vec3 lum{};
            double mag = 0;
            for (int k = 0; k < 3; ++k) {
                lum = lum + w[k] * vec(k);
                mag += std::fabs(w[k]) * vmag(k);
            }
            const double len = length(lum);
            bool all_zero = true;  // every L1 exactly 0: both sides take +Z exactly
            for (int k = 0; k < 3; ++k) all_zero = all_zero && length(vec(k)) == 0;
            for (double& kk : kappa) kk = (mag == 0 || all_zero) ? 1 : (len > 0 ? mag / len : INFINITY);
        } else {
            for (int k = 0; k < 3; ++k) {
                const double len = length(vec(k)), mag = vmag(k);
                kappa[k] = (mag == 0 || len == 0) ? 1 : mag / len;  // v exactly 0: +Z on both sides
                if (!std::isfinite(len)) kappa[k] = INFINITY;
            }
        }
    }
    // Hallucination f20 = (A p + B) |f1| below the clamp: its rounding error is a few u of
    // (|A| p + |B|) |f1|, and the error of f1 (~ kappa u |v|) propagates with the slope 2 A p + B:
    // G = max over p in [0, sqrt3] of the sum of both factors.
    double g = 0;
    auto g_of = [](double a, double b) {
        const double pmax = std::sqrt(3.0);
        return std::fabs(a) * pmax + std::fabs(b) + std::max(std::fabs(b), std::fabs(2 * a * pmax + b));
    };
    if (e.hallucination == kHallAmbdir) g = 2 * std::sqrt(15.0) / 3;
    if (e.hallucination == kHallSphere) g = g_of(2 * std::sqrt(5.0) / 3, -std::sqrt(5.0 / 3));
    if (e.hallucination == kHallCurve) g = g_of(0.6, 0.08);
    if (e.hallucination == kHallCurveAdaptive) g = g_of(3.5 * 0.6, 3.5 * 0.08);  // largest scale code
    // Hallucination in the irradiance domain (float hall_* with irradiance storage): the stored L1
    // is 2/3 of the radiance one and the zonal 1/4: the slope in radiance units is 8/3 G.
    if (p.kind == StoredKind::kIrradiance && e.family == kSh2F32) g *= 8.0 / 3.0;
    for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(kappa[k])) s.defined = false;
        double l1 = m[1][k] + m[2][k] + m[3][k];
        double l2 = 0;
        double zonal_scale = 0;
        if (is_zonal(e)) {
            double f20 = 0;
            for (int i = 4; i < 9; ++i) f20 += double(d[i][k]) * double(d[i][k]);
            f20 = std::sqrt(f20);
            if (quant && e.hallucination == kHallNone) f20 = std::max(f20, std::sqrt(5.0) * m[0][k]);
            zonal_scale = (f20 + g * vmag(k)) * (1 + kappa[k]);
            l2 = 3 * kY20 * zonal_scale;
            // The axis also enters the hallucinated f1 = v.a (error ~ kappa u |v|), counted in G|v|.
        } else if (has_l2(e)) {
            for (int i = 4; i < 9; ++i) l2 += 0.631 * m[i][k];
        }
        s.irradiance[k] = kY00 * m[0][k] + (2.0 / 3.0) * kY1 * l1 + 0.25 * l2;
        for (int i = 0; i < 9; ++i) s.coeff[i][k] = (i >= 4 && is_zonal(e)) ? std::sqrt(3.0) * zonal_scale : m[i][k];
        // Irradiance storage rescales L1 by 3/2 and L2 by 4 in float: relative, inside the counts.
    }
    return s;
}

// Running maxima of |gpu - codec| / (u S) and the failure log of one encoding.
struct Tally {
    double max_irr = 0, max_dec = 0;
    long compared = 0, skipped_nonfinite = 0, skipped_illcond = 0, overflow_ok = 0, failures = 0;
    std::string first_failure;
};

// Compares one value; bound in units of u * scale.
void check_value(Tally& t, double* max_seen, double ref, float gpu, double scale, double c, const std::string& what) {
    if (!std::isfinite(ref)) {
        ++t.skipped_nonfinite;
        return;
    }
    ++t.compared;
    if (!std::isfinite(gpu)) {
        if (scale * 64 >= FLT_MAX) {
            ++t.overflow_ok;
            return;
        }
    } else {
        const double err = std::fabs(double(gpu) - ref);
        const double units = scale > 0 ? err / (kU * scale) : (err > 0 ? INFINITY : 0);
        if (err <= kAbs) return;
        *max_seen = std::max(*max_seen, units);
        if (err <= c * kU * scale + kAbs) return;
    }
    if (t.failures++ == 0) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%s: codec %.9g gpu %.9g scale %.6g (%.2f u S, bound %.0f)", what.c_str(), ref,
                      double(gpu), scale, std::fabs(double(gpu) - ref) / (kU * scale), c);
        t.first_failure = buf;
    }
}

// Parameter sets for batch b of an encoding.
CodecOptions batch_params(const GlslEntry& e, std::string_view name, int b, std::mt19937_64& rng) {
    CodecOptions p;
    if (b == 0) return p;  // the defaults (Codec::irradiance is the reference)
    std::uniform_real_distribution<double> u(0, 1);
    if (b % 4 == 3) p.luminance = {0.05 + u(rng), 0.05 + u(rng), 0.05 + u(rng)};
    p.kind = (b % 2) ? StoredKind::kIrradiance : StoredKind::kRadiance;
    if (is_quantised(e.family)) {
        p.bits = 2 + (b * 3) % 7;
        p.sqrt_encoding = (b / 2) % 2;
        p.l2_bound = (b / 3) % 2 ? L2Bound::kLoose : L2Bound::kTight;
        p.dc_format = static_cast<DcFormat>(b % 3);
        if (e.family != kSh2Q && p.dc_format == DcFormat::kHalf) p.dc_format = DcFormat::kRGB9E5;
        p.zonal_mapping = static_cast<ZonalMapping>((b / 2) % 3);
        p.axis_mode = (b / 4) % 2 ? ZonalAxisMode::kPerChannel : ZonalAxisMode::kLuminance;
        if (b == 1) p.bits = 8;
    }
    EXPECT_TRUE(validate_quant_params(p, name).ok()) << name << " batch " << b;
    return p;
}

bool default_irradiance_path(const CodecOptions& p) {
    const CodecOptions d;
    return p.kind == StoredKind::kRadiance && p.zonal_mapping == d.zonal_mapping && p.axis_mode == d.axis_mode;
}

// ---- tests ------------------------------------------------------------------------------------------

// ---- the GL side ------------------------------------------------------------------------------------

// kEs = false: desktop GL 4.5 core, "#version 450"; true: OpenGL ES 3.1, "#version 310 es" (the
// same zhc.glsl and test main, executed, not only validated).
template <bool kEs>
class RuntimeContext : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        // Desktop GL 4.5 core or ES 3.1: compute shaders and std430 SSBOs are core in both.
        const EGLint gl_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        const EGLint es_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 1, EGL_NONE};
        why_ = kEs ? test::make_llvmpipe_context(EGL_OPENGL_ES_API, EGL_OPENGL_ES3_BIT, es_attr, &egl_)
                   : test::make_llvmpipe_context(EGL_OPENGL_API, EGL_OPENGL_BIT, gl_attr, &egl_);
        if (!why_.empty()) return;
        renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        std::printf("GL_RENDERER: %s, GL_VERSION: %s\n", renderer_.c_str(),
                    reinterpret_cast<const char*>(glGetString(GL_VERSION)));
        const std::string library = read_text(ZHC_RUNTIME_GLSL_PATH);
        if (library.empty()) {
            why_ = std::string("cannot read ") + ZHC_RUNTIME_GLSL_PATH;
            return;
        }
        const std::string source = std::string(kEs ? "#version 310 es\n" : "#version 450\n") + library + kTestMain;
        const char* src = source.c_str();
        GLuint sh = glCreateShader(GL_COMPUTE_SHADER);
        glShaderSource(sh, 1, &src, nullptr);
        glCompileShader(sh);
        GLint ok = 0;
        glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            char log[8192] = {};
            glGetShaderInfoLog(sh, sizeof log, nullptr, log);
            why_ = std::string("compute shader does not compile: ") + log;
            glDeleteShader(sh);
            return;
        }
        program_ = glCreateProgram();
        glAttachShader(program_, sh);
        glLinkProgram(program_);
        glDeleteShader(sh);
        glGetProgramiv(program_, GL_LINK_STATUS, &ok);
        if (!ok) {
            char log[8192] = {};
            glGetProgramInfoLog(program_, sizeof log, nullptr, log);
            why_ = std::string("program does not link: ") + log;
            return;
        }
        glGenBuffers(3, buffers_);
    }
    static void TearDownTestSuite() {
        if (program_) glDeleteProgram(program_);
        if (buffers_[0]) glDeleteBuffers(3, buffers_);
        test::destroy_context(&egl_);
    }
    void SetUp() override {
        ASSERT_TRUE(why_.empty()) << why_;
        ASSERT_NE(renderer_.find("llvmpipe"), std::string::npos) << renderer_;
    }

public:
    struct Uniforms {
        std::uint32_t mode = 0, stride = 0;
        std::uint32_t a[4] = {0, 0, 0, 0}, b[4] = {0, 0, 0, 0};
        std::uint32_t kind = 0;
        float lum[3] = {0, 0, 0}, curve[2] = {0, 0};
    };

    // Runs the shader on `count` items; returns count * kOutFloats floats.
    static std::vector<float> run(const Uniforms& un, const std::vector<std::uint32_t>& words,
                                  const std::vector<float>& normals, std::size_t count) {
        auto upload = [](GLuint buf, GLuint binding, const void* data, std::size_t bytes) {
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf);
            glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), nullptr,
                         GL_DYNAMIC_DRAW);
            if (bytes) glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buf);
        };
        upload(buffers_[0], 0, words.data(), words.size() * 4);
        upload(buffers_[1], 1, normals.data(), normals.size() * 4);
        upload(buffers_[2], 2, nullptr, count * kOutFloats * 4);
        glUseProgram(program_);
        glUniform1ui(glGetUniformLocation(program_, "uCount"), static_cast<GLuint>(count));
        glUniform1ui(glGetUniformLocation(program_, "uStride"), un.stride);
        glUniform1ui(glGetUniformLocation(program_, "uMode"), un.mode);
        glUniform4ui(glGetUniformLocation(program_, "uA"), un.a[0], un.a[1], un.a[2], un.a[3]);
        glUniform4ui(glGetUniformLocation(program_, "uB"), un.b[0], un.b[1], un.b[2], un.b[3]);
        glUniform1ui(glGetUniformLocation(program_, "uKind"), un.kind);
        glUniform3f(glGetUniformLocation(program_, "uLum"), un.lum[0], un.lum[1], un.lum[2]);
        glUniform2f(glGetUniformLocation(program_, "uCurve"), un.curve[0], un.curve[1]);
        glDispatchCompute(static_cast<GLuint>((count + 63) / 64), 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<float> out(count * kOutFloats);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[2]);
        // glMapBufferRange exists in both APIs (ES has no glGetBufferSubData).
        const void* mapped =
            glMapBufferRange(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(out.size() * 4), GL_MAP_READ_BIT);
        EXPECT_NE(mapped, nullptr);
        if (mapped) std::memcpy(out.data(), mapped, out.size() * 4);
        glUnmapBuffer(GL_SHADER_STORAGE_BUFFER);
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        return out;
    }

protected:
    static inline test::EglContext egl_;
    static inline GLuint program_ = 0;
    static inline GLuint buffers_[3] = {0, 0, 0};
    static inline std::string why_, renderer_;
};

using RuntimeGl = RuntimeContext<false>;
using RuntimeGles = RuntimeContext<true>;

// Every codec table entry: kBatches x 10,000 valid probes and kGarbageBatches x 10,000 of random
// bytes through Fixture's GL implementation, against the codec.
template <class Fixture>
void compare_every_codec(int kBatches, int kGarbageBatches, long min_valid) {
    constexpr int kBatchSize = 10000;
    const std::vector<Sh3Radiance> maps = envmap_probes();
    ASSERT_EQ(maps.size(), 8u);
    // Columns: valid probes, their max irradiance / decoded-coefficient error in u S; the same for
    // random bytes; random-byte probes not compared (codec output not finite / axis of a zero
    // luminance L1 whose channels do not vanish); the bounds (irradiance / decode).
    std::printf("%-22s %7s %8s %8s %7s %8s %8s %9s %8s %s\n", "encoding", "probes", "irr uS", "dec uS", "garbage",
                "irr uS", "dec uS", "nonfinite", "illcond", "bounds");
    for (const Codec& codec : codecs()) {
        const auto it = glsl_entries().find(codec.name);
        if (it == glsl_entries().end()) {
            ADD_FAILURE() << "codec table entry '" << codec.name << "' has no GLSL decoder in runtime/zhc.glsl";
            continue;
        }
        const GlslEntry& e = it->second;
        EXPECT_EQ(e.axis, codec.traits.zonal_axis) << codec.name << ": runtime/zhc.glsl's axis column";
        std::mt19937_64 rng(0x5EED0000u + codec.size_bytes * 131 + codec.name.size());
        std::uniform_real_distribution<double> u(0, 1);
        const std::size_t words = codec.size_bytes / 4;
        ASSERT_EQ(codec.size_bytes % 4, 0u);
        Tally tv, tg;  // valid probes, random bytes
        long valid = 0, garbage = 0;
        for (int b = 0; b < kBatches + kGarbageBatches; ++b) {
            const bool is_garbage = b >= kBatches;
            const CodecOptions p = batch_params(e, codec.name, is_garbage ? b - kBatches + 1 : b, rng);
            std::vector<std::uint8_t> bytes(kBatchSize * codec.size_bytes);
            std::vector<float> normals(kBatchSize * 3);
            for (int i = 0; i < kBatchSize; ++i) {
                std::uint8_t* out = bytes.data() + static_cast<size_t>(i) * codec.size_bytes;
                if (is_garbage) {
                    for (std::size_t j = 0; j < codec.size_bytes; ++j) out[j] = static_cast<std::uint8_t>(rng());
                } else {
                    const int kind = i % 10 < 4 ? 0 : (i % 10 < 7 ? 1 : 2);
                    encode_probe(codec, p, random_probe(rng, maps, kind), out, nullptr);
                }
                const Vec3 n = test::uniform_direction(u(rng), u(rng));
                normals[3 * i] = static_cast<float>(n.x);
                normals[3 * i + 1] = static_cast<float>(n.y);
                normals[3 * i + 2] = static_cast<float>(n.z);
            }
            (is_garbage ? garbage : valid) += kBatchSize;
            std::vector<std::uint32_t> w(bytes.size() / 4);
            for (std::size_t j = 0; j < w.size(); ++j)
                w[j] = std::uint32_t(bytes[4 * j]) | std::uint32_t(bytes[4 * j + 1]) << 8 |
                       std::uint32_t(bytes[4 * j + 2]) << 16 | std::uint32_t(bytes[4 * j + 3]) << 24;
            typename Fixture::Uniforms un;
            un.mode = 0;
            un.stride = static_cast<std::uint32_t>(words);
            un.a[0] = e.family;
            un.a[1] = e.hallucination;
            un.a[2] = static_cast<std::uint32_t>(p.bits);
            un.a[3] = p.sqrt_encoding ? 1u : 0u;
            un.b[0] = static_cast<std::uint32_t>(p.l2_bound);
            un.b[1] = static_cast<std::uint32_t>(p.dc_format);
            un.b[2] = static_cast<std::uint32_t>(p.zonal_mapping);
            un.b[3] = axis_mode(e, p);
            un.kind = static_cast<std::uint32_t>(p.kind);
            un.lum[0] = static_cast<float>(p.luminance.r);
            un.lum[1] = static_cast<float>(p.luminance.g);
            un.lum[2] = static_cast<float>(p.luminance.b);
            const CodecOptions o = p;
            un.curve[0] = static_cast<float>(o.hallucinate_a);
            un.curve[1] = static_cast<float>(o.hallucinate_b);
            const std::vector<float> gpu = Fixture::run(un, w, normals, kBatchSize);
            const bool direct = default_irradiance_path(p);
            const double c_irr = is_quantised(e.family) ? kCQuant : kCFloat;
            Tally& t = is_garbage ? tg : tv;
            for (int i = 0; i < kBatchSize; ++i) {
                const std::uint8_t* in = bytes.data() + static_cast<size_t>(i) * codec.size_bytes;
                const Sh3Radiance ref = decode_probe(codec, p, in);
                const Vec3 n{normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
                const Rgb irr = direct ? codec.irradiance(in, o, n) : irradiance(ref, n);
                const Scale s = probe_scale(e, p, ref);
                if (!s.defined) {
                    bool finite = true;
                    for (int c = 0; c < 9; ++c)
                        for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(ref[c][k]);
                    ++(finite ? t.skipped_illcond : t.skipped_nonfinite);
                    continue;
                }
                const float* g = gpu.data() + static_cast<size_t>(i) * kOutFloats;
                const std::string what = std::string(codec.name) + (is_garbage ? " garbage" : "") + " batch " +
                                         std::to_string(b) + " probe " + std::to_string(i);
                for (int c = 0; c < 9; ++c)
                    for (int k = 0; k < 3; ++k)
                        check_value(t, &t.max_dec, ref[c][k], g[3 * c + k], s.coeff[c][k], kCDecode,
                                    what + " coefficient " + std::to_string(c) + "/" + std::to_string(k));
                for (int k = 0; k < 3; ++k)
                    check_value(t, &t.max_irr, irr[k], g[27 + k], s.irradiance[k], c_irr,
                                what + " irradiance " + std::to_string(k));
            }
        }
        const double c_irr = is_quantised(e.family) ? kCQuant : kCFloat;
        std::printf("%-22s %7ld %8.3f %8.3f %7ld %8.3f %8.3f %9ld %8ld %6.0f/%.0f\n", std::string(codec.name).c_str(),
                    valid, tv.max_irr, tv.max_dec, garbage, tg.max_irr, tg.max_dec, tg.skipped_nonfinite,
                    tg.skipped_illcond, c_irr, kCDecode);
        std::fflush(stdout);
        EXPECT_GE(valid, min_valid);
        for (const Tally* t : {&tv, &tg})
            EXPECT_EQ(t->failures, 0) << codec.name << ": " << t->failures << " values out of bound; first: "
                                      << t->first_failure;
        // Every valid probe is compared (finite, well-conditioned axis), and nearly all of the
        // random-byte ones (a finite value in 27 + 3 per probe).
        EXPECT_EQ(tv.skipped_nonfinite + tv.skipped_illcond, 0) << codec.name;
        EXPECT_EQ(tv.compared, valid * 30) << codec.name;
        EXPECT_GT(tg.compared, garbage * 30 / 2) << codec.name;
    }
}

TEST_F(RuntimeGl, EveryCodecDecodesAndEvaluatesLikeTheCodec) { 
    // 10,000 probes per batch; the sanitizer build runs a tenth (test::sample_count).
    compare_every_codec<RuntimeGl>(static_cast<int>(std::max(1L, test::sample_count(100000) / 10000)), 2,
                                   test::sample_count(100000));
}

// The same file as GLSL ES 3.10 (highp everywhere), executed on llvmpipe's OpenGL ES 3.1: a smaller
// sample (30,000 + 10,000 per encoding), same bounds.
TEST_F(RuntimeGles, EveryCodecDecodesAndEvaluatesLikeTheCodec) { 
    compare_every_codec<RuntimeGles>(static_cast<int>(std::max(1L, test::sample_count(30000) / 10000)), 1,
                                     test::sample_count(30000));
}

// R11G11B10F, RGB9E5 and half unpacking are integer-exact: every code of every channel.
TEST_F(RuntimeGl, DcUnpackingIsBitExact) {
    std::vector<std::uint32_t> w;
    for (std::uint32_t c = 0; c < 2048; ++c) w.push_back(c | (c << 11) | ((c & 0x3FF) << 22));  // R11G11B10F codes
    for (std::uint32_t e = 0; e < 32; ++e)
        for (std::uint32_t m = 0; m < 512; ++m) w.push_back(m | (((m * 7) & 511) << 9) | (((511 - m)) << 18) | (e << 27));
    for (std::uint32_t h = 0; h < 65536; h += 2) w.push_back(h | ((h + 1) << 16));  // every half
    std::vector<float> normals(w.size() * 3, 0.0f);
    Uniforms un;
    un.mode = 2;
    const std::vector<float> gpu = run(un, w, normals, w.size());
    long mismatches = 0;
    auto same = [](float a, float b) {
        if (std::isnan(a)) return std::isnan(b);
        std::uint32_t x, y;
        std::memcpy(&x, &a, 4);
        std::memcpy(&y, &b, 4);
        return x == y;
    };
    for (std::size_t i = 0; i < w.size(); ++i) {
        const float* g = gpu.data() + i * kOutFloats;
        const Rgb a = unpack_r11g11b10f(w[i]), b = unpack_rgb9e5(w[i]);
        const float h0 = unpack_half(static_cast<std::uint16_t>(w[i] & 0xFFFF)),
                    h1 = unpack_half(static_cast<std::uint16_t>(w[i] >> 16));
        const float want[8] = {a.r, a.g, a.b, b.r, b.g, b.b, h0, h1};
        for (int j = 0; j < 8; ++j)
            if (!same(want[j], g[j]) && mismatches++ < 5)
                ADD_FAILURE() << "word 0x" << std::hex << w[i] << std::dec << " value " << j << ": codec " << want[j]
                              << " gpu " << g[j];
    }
    EXPECT_EQ(mismatches, 0);
    std::printf("DC unpacking: %zu words, %ld mismatches (R11G11B10F, RGB9E5, binary16 all codes)\n", w.size(), mismatches);
}

// IrradZ texels (BC6H I_z, BC4 w_a, BC5 hemi-octahedral d) -> irradiance at tangent normals.
TEST_F(RuntimeGl, IrradZLightmapMatchesTheCodec) {
    constexpr int kTexels = 100000;
    std::mt19937_64 rng(0x1AAD2);
    std::uniform_real_distribution<double> u(0, 1);
    for (int model = 0; model < 2; ++model) {
        std::vector<std::uint32_t> w(kTexels * 7);
        std::vector<float> normals(kTexels * 3), in(kTexels * 6);
        for (int i = 0; i < kTexels; ++i) {
            const double ex = std::pow(10.0, -3 + 6 * u(rng));
            float v[6] = {static_cast<float>(ex * u(rng)), static_cast<float>(ex * u(rng)),
                          static_cast<float>(ex * u(rng)), static_cast<float>(-0.1 + 1.2 * u(rng)),
                          static_cast<float>(-0.05 + 1.1 * u(rng)), static_cast<float>(-0.05 + 1.1 * u(rng))};
            if (i % 7 == 0) v[3] = static_cast<float>(std::round(v[3]));  // w_a exactly 0 / 1
            for (int j = 0; j < 6; ++j) {
                in[6 * i + j] = v[j];
                std::memcpy(&w[7 * i + j], &v[j], 4);
            }
            w[7 * i + 6] = static_cast<std::uint32_t>(model);
            const Vec3 n = test::uniform_direction(u(rng), u(rng));
            normals[3 * i] = static_cast<float>(n.x);
            normals[3 * i + 1] = static_cast<float>(n.y);
            normals[3 * i + 2] = static_cast<float>(n.z);
        }
        Uniforms un;
        un.mode = 1;
        const std::vector<float> gpu = run(un, w, normals, kTexels);
        Tally t;
        double max_dir = 0;
        for (int i = 0; i < kTexels; ++i) {
            const float* v = in.data() + 6 * i;
            irradz::IrradZ p;
            p.i_z = Rgb{v[0], v[1], v[2]};
            p.w_a = v[3];
            p.d = lightmap::decode_hemioct(v[4], v[5]);
            const Vec3 n{normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
            const Rgb ref = irradz::evaluate(p, model == 0 ? irradz::Model::kHhd : irradz::Model::kAhd, n);
            const float* g = gpu.data() + static_cast<size_t>(i) * kOutFloats;
            // Direction: unit vector, each component within a few u (no cancellation: |d| = 1).
            for (int j = 0; j < 3; ++j) max_dir = std::max(max_dir, std::fabs(double(g[3 + j]) - p.d[j]) / kU);
            // Scale: |C_a| h + |C_d| max(0, n.d) with |C_d| <= |I_z| / d_z, d_z >= cos 85 deg. d_z comes
            // out of the hemi-octahedral decode and the normalisation with an ABSOLUTE error of a few
            // u, so 1 / d_z has a relative error of a few u / d_z: the directional term's error is
            // a few u |I_z| (1 + 1 / d_z) / d_z, not a few u |I_z| / d_z.
            const double dz = std::max(p.d.z, irradz::kMinDz);
            for (int k = 0; k < 3; ++k)
                check_value(t, &t.max_irr, ref[k], g[k], std::fabs(double(v[k])) * (1 + (1 + 1 / dz) / dz), kCLightmap,
                            "texel " + std::to_string(i) + " channel " + std::to_string(k));
        }
        std::printf("IrradZ %s: %d texels, max irradiance error %.3f u S (bound %.0f), direction %.2f u\n",
                    model == 0 ? "HHD" : "AHD", kTexels, t.max_irr, kCLightmap, max_dir);
        EXPECT_EQ(t.failures, 0) << t.first_failure;
        EXPECT_LE(max_dir, 8.0);  // hemi-oct: 4 roundings + normalisation (inversesqrt 2 ulp, 3 ops)
        EXPECT_EQ(t.compared, 3L * kTexels);
    }
}

// HLSH (probe occlusion): I(m) = I_z m_z + C_a (1 - m_z) + c_x m_x + c_y m_y against
// irradz::evaluate(Hlsh); scale = sum of the four terms' magnitudes, 4 products + 3 sums + the
// codec's float rounding: bound 8 u S.
TEST_F(RuntimeGl, HlshMatchesTheCodec) {
    constexpr int kCount = 100000;
    std::mt19937_64 rng(0x4151);
    std::normal_distribution<double> g(0, 1);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<std::uint32_t> w(kCount * 12);
    std::vector<float> normals(kCount * 3), in(kCount * 12);
    for (int i = 0; i < kCount; ++i) {
        const double ex = std::pow(10.0, -3 + 6 * u(rng));
        for (int j = 0; j < 12; ++j) {
            in[12 * i + j] = static_cast<float>(ex * g(rng));
            std::memcpy(&w[12 * i + j], &in[12 * i + j], 4);
        }
        const Vec3 n = test::uniform_direction(u(rng), u(rng));
        normals[3 * i] = static_cast<float>(n.x);
        normals[3 * i + 1] = static_cast<float>(n.y);
        normals[3 * i + 2] = static_cast<float>(n.z);
    }
    Uniforms un;
    un.mode = 3;
    const std::vector<float> gpu = run(un, w, normals, kCount);
    Tally t;
    for (int i = 0; i < kCount; ++i) {
        const float* v = in.data() + 12 * i;
        irradz::Hlsh h;
        h.i_z = Rgb{v[0], v[1], v[2]};
        h.c_a = Rgb{v[3], v[4], v[5]};
        h.c_x = Rgb{v[6], v[7], v[8]};
        h.c_y = Rgb{v[9], v[10], v[11]};
        const Vec3 m{normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
        const Rgb ref = irradz::evaluate(h, m);
        for (int k = 0; k < 3; ++k) {
            const double scale = std::fabs(v[k] * m.z) + std::fabs(v[3 + k] * (1 - m.z)) + std::fabs(v[6 + k] * m.x) +
                                 std::fabs(v[9 + k] * m.y);
            check_value(t, &t.max_irr, ref[k], gpu[static_cast<size_t>(i) * kOutFloats + static_cast<size_t>(k)], scale,
                        8, "HLSH " + std::to_string(i) + " channel " + std::to_string(k));
        }
    }
    std::printf("HLSH: %d evaluations, max error %.3f u S (bound 8)\n", kCount, t.max_irr);
    EXPECT_EQ(t.failures, 0) << t.first_failure;
    EXPECT_EQ(t.compared, 3L * kCount);
}

}  // namespace
}  // namespace zhc
