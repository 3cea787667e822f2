// The engine layouts (codec/probe/engine_layouts.h, docs/engine-layouts.md): each codec entry against
// a slow twin written here from the same engine sources (the stored bytes and the shader's formula,
// in double, with the exact constants where the shader rounds them), plus the properties each
// layout's source promises.
//
// The twins do not share code with the entries: an engine's coefficients come from a numerical
// projection (Gauss-Legendre in cos theta, uniform in phi, exact for the polynomials involved) of
// the hub's radiance in the engine's axes, written from the engines' own axis conventions below;
// the shaders' formulas and the packings are written again from the cited files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "codec/audit/benchmark.h"
#include "codec/probe/codec.h"
#include "codec/probe/engine_layouts.h"
#include "codec/probe/quantize.h"
#include "codec/probe/runtime_table.h"
#include "formats/report/html_report.h"
#include "formats/report/plot.h"
#include "support.h"

namespace zhc {
namespace {

const double kPiD = 3.14159265358979323846;

// ---- axes, written from each engine's convention --------------------------------------------

struct Axes {
    double m[3][3];
    Vec3 to_engine(Vec3 v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    Vec3 to_zhc(Vec3 e) const {
        return {m[0][0] * e.x + m[1][0] * e.y + m[2][0] * e.z, m[0][1] * e.x + m[1][1] * e.y + m[2][1] * e.z,
                m[0][2] * e.x + m[1][2] * e.y + m[2][2] * e.z};
    }
};
// glTF (three.js, Godot, Bevy, RealityKit): Y up, right-handed; zhc's +Z (up) is +Y, zhc's +X is
// glTF's +Z, zhc's +Y is glTF's +X (docs/gltf-extension.md).
const Axes kGltf{{{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}};
// Unity (APV, VRChat): glTF's axes with x negated (glTFast / UnityGLTF import).
const Axes kUnity{{{0, -1, 0}, {0, 0, 1}, {1, 0, 0}}};
// Unreal: Z up, left-handed: zhc's y negated.
const Axes kUnreal{{{1, 0, 0}, {0, -1, 0}, {0, 0, 1}}};
// Source: Z up, right-handed: zhc's.
const Axes kSource{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

const Axes& axes_of(const std::string& name) {
    static const std::map<std::string, const Axes*> m = {
        {"threejs_grid_float", &kGltf}, {"threejs_grid_half", &kGltf}, {"unity_apv_l1", &kUnity},
        {"unity_apv_l2", &kUnity},      {"unreal_vlm_l2", &kUnreal},   {"bevy_ambient_cube", &kGltf},
        {"vrchat_lv_l1", &kUnity},      {"godot_l2", &kGltf},          {"realitykit_l1", &kGltf},
        {"source2_ambient_cube", &kSource}};
    return *m.at(name);
}

// ---- numerical projection -------------------------------------------------------------------

// The real SH basis without the Condon-Shortley sign, exact constants.
std::array<double, 9> plain_basis(Vec3 d) {
    const double a0 = 0.5 / std::sqrt(kPiD), a1 = std::sqrt(3.0 / (4 * kPiD)), a2 = std::sqrt(15.0 / (4 * kPiD)),
                 a20 = std::sqrt(5.0 / (16 * kPiD)), a22 = std::sqrt(15.0 / (16 * kPiD));
    return {a0, a1 * d.y, a1 * d.z, a1 * d.x, a2 * d.x * d.y, a2 * d.y * d.z, a20 * (3 * d.z * d.z - 1), a2 * d.x * d.z,
            a22 * (d.x * d.x - d.y * d.y)};
}
const double kBand[9] = {1, 2.0 / 3, 2.0 / 3, 2.0 / 3, 0.25, 0.25, 0.25, 0.25, 0.25};

struct Quadrature {
    std::vector<Vec3> dirs;
    std::vector<double> weights;
};
// Gauss-Legendre in cos theta (n nodes) times 2n uniform phi: exact for polynomials of degree < 2n.
Quadrature quadrature(int n) {
    std::vector<double> x(n), w(n);
    for (int i = 0; i < n; ++i) {  // Newton on P_n
        double z = std::cos(kPiD * (i + 0.75) / (n + 0.5)), pp = 0;
        for (int it = 0; it < 100; ++it) {
            double p1 = 1, p2 = 0;
            for (int j = 1; j <= n; ++j) {
                const double p3 = p2;
                p2 = p1;
                p1 = ((2 * j - 1) * z * p2 - (j - 1) * p3) / j;
            }
            pp = n * (z * p1 - p2) / (z * z - 1);
            const double dz = p1 / pp;
            z -= dz;
            if (std::fabs(dz) < 1e-15) break;
        }
        x[i] = z;
        w[i] = 2 / ((1 - z * z) * pp * pp);
    }
    Quadrature q;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < 2 * n; ++j) {
            const double phi = 2 * kPiD * (j + 0.5) / (2 * n), s = std::sqrt(1 - x[i] * x[i]);
            q.dirs.push_back({s * std::cos(phi), s * std::sin(phi), x[i]});
            q.weights.push_back(w[i] * kPiD / n);
        }
    return q;
}

// The hub's radiance projected on the plain basis in the engine's axes: r[i][c].
using Coeffs = std::array<std::array<double, 3>, 9>;
Coeffs engine_radiance(const Sh3Radiance& hub, const Axes& ax) {
    static const Quadrature q = quadrature(8);
    Coeffs r{};
    for (size_t k = 0; k < q.dirs.size(); ++k) {
        const Vec3 e = q.dirs[k];
        const std::array<double, 9> y = sh3_basis(ax.to_zhc(e)), t = plain_basis(e);
        for (int c = 0; c < 3; ++c) {
            double radiance = 0;
            for (int i = 0; i < 9; ++i) radiance += double(hub[i][c]) * y[i];
            for (int j = 0; j < 9; ++j) r[j][c] += q.weights[k] * radiance * t[j];
        }
    }
    return r;
}

// ---- the twins: stored bytes and the shader's irradiance ------------------------------------

void put16(std::vector<std::uint8_t>& b, size_t o, std::uint16_t v) {
    b[o] = std::uint8_t(v), b[o + 1] = std::uint8_t(v >> 8);
}
std::uint16_t get16(const std::uint8_t* p) { return std::uint16_t(p[0] | p[1] << 8); }
void putf(std::vector<std::uint8_t>& b, size_t o, double v) {
    const float f = float(v);
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    for (int i = 0; i < 4; ++i) b[o + i] = std::uint8_t(u >> (8 * i));
}
double getf(const std::uint8_t* p) {
    const std::uint32_t u = std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}
double geth(const std::uint8_t* p) { return unpack_half(get16(p)); }
std::uint32_t get32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

// Sloan's constants, as Unity's GetShaderConstantsFromNormalizedSH uses them: radiance SH to the
// normalised irradiance polynomial (L0, L1 x y z, L2 xy yz, (3z^2-1), xz, x^2-y^2).
const double kFC0 = 1 / (2 * std::sqrt(kPiD)), kFC1 = std::sqrt(3.0) / (3 * std::sqrt(kPiD)),
             kFC2 = std::sqrt(15.0) / (8 * std::sqrt(kPiD)), kFC3 = std::sqrt(5.0) / (16 * std::sqrt(kPiD)), kFC4 = 0.5 * kFC2;
struct PolyTerms {
    double l0, l1[3], xy, yz, d, xz, c;
};
PolyTerms poly_terms(const Coeffs& r, int c) {
    return {kFC0 * r[0][c], {kFC1 * r[3][c], kFC1 * r[1][c], kFC1 * r[2][c]}, kFC2 * r[4][c], kFC2 * r[5][c],
            kFC3 * r[6][c], kFC2 * r[7][c], kFC4 * r[8][c]};
}

// Irradiance from plain-basis radiance coefficients in engine axes (A_l Y / pi).
double sh_irradiance(const Coeffs& r, int c, Vec3 e, int count = 9) {
    const std::array<double, 9> t = plain_basis(e);
    double s = 0;
    for (int i = 0; i < count; ++i) s += r[i][c] * t[i] * kBand[i];
    return s;
}

std::uint8_t trunc_byte(double v) { return v > 0 ? std::uint8_t(std::min(v, 1.0) * 255.0) : 0; }
std::uint8_t round_byte(double v) { return v > 0 ? std::uint8_t(std::floor(std::min(v, 1.0) * 255.0 + 0.5)) : 0; }

// The ambient cube faces (+X, -X, +Y, -Y, +Z, -Z in engine axes): the irradiance there.
std::array<std::array<double, 3>, 6> twin_faces(const Coeffs& r) {
    std::array<std::array<double, 3>, 6> f{};
    for (int k = 0; k < 6; ++k) {
        Vec3 e{};
        const double s = k % 2 ? -1 : 1;
        (k / 2 == 0 ? e.x : k / 2 == 1 ? e.y : e.z) = s;
        for (int c = 0; c < 3; ++c) f[k][c] = sh_irradiance(r, c, e);
    }
    return f;
}
double cube_value(const double f[6][3], int c, Vec3 e) {
    const double n[3] = {e.x, e.y, e.z};
    double s = 0;
    for (int a = 0; a < 3; ++a) s += n[a] * n[a] * f[2 * a + (n[a] < 0)][c];
    return s;
}

std::vector<std::uint8_t> twin_encode(const std::string& name, const Sh3Radiance& hub) {
    const Coeffs r = engine_radiance(hub, axes_of(name));
    std::vector<std::uint8_t> b(find_codec(name)->size_bytes, 0);
    if (name == "threejs_grid_float" || name == "threejs_grid_half") {
        // 7 RGBA texels: coefficient i's R, G, B at 3i..3i+2 (repackNode), the 28th value 0.
        for (int k = 0; k < 27; ++k) {
            if (name == "threejs_grid_float") putf(b, 4 * k, r[k / 3][k % 3]);
            else put16(b, 2 * k, pack_half(r[k / 3][k % 3]));
        }
    } else if (name == "godot_l2") {
        // 9 Colors (RGBA float): radiance SH / pi (lm_compute.glsl's 4 / rays), alpha 0.
        for (int i = 0; i < 9; ++i)
            for (int c = 0; c < 3; ++c) putf(b, 16 * i + 4 * c, r[i][c] / kPiD);
    } else if (name == "realitykit_l1") {
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c) putf(b, 12 * i + 4 * c, r[i][c]);
    } else if (name == "unity_apv_l1" || name == "unity_apv_l2") {
        PolyTerms p[3];
        double enc1[3][3];
        for (int c = 0; c < 3; ++c) {
            p[c] = poly_terms(r, c);
            for (int k = 0; k < 3; ++k) enc1[c][k] = p[c].l1[k] / p[c].l0 / 4.0 + 0.5;
        }
        for (int c = 0; c < 3; ++c) put16(b, 2 * c, pack_half(p[c].l0));
        put16(b, 6, pack_half(enc1[0][0]));
        for (int k = 0; k < 3; ++k) b[8 + k] = trunc_byte(enc1[1][k]), b[12 + k] = trunc_byte(enc1[2][k]);
        b[11] = trunc_byte(enc1[0][1]), b[15] = trunc_byte(enc1[0][2]);
        if (name == "unity_apv_l2") {
            for (int c = 0; c < 3; ++c) {
                const double s = 1.0 / (p[c].l0 * 3.5777088);
                const double v[4] = {p[c].xy, p[c].yz, p[c].d, p[c].xz};
                for (int k = 0; k < 4; ++k) b[16 + 4 * c + k] = trunc_byte(0.5 + v[k] * s);
                b[28 + c] = trunc_byte(0.5 + p[c].c * s);
            }
        }
    } else if (name == "unreal_vlm_l2") {
        const double sign[9] = {1, -1, 1, -1, 1, -1, 1, -1, 1};
        double u[9][3];
        for (int i = 0; i < 9; ++i)
            for (int c = 0; c < 3; ++c) u[i][c] = sign[i] * r[i][c];
        const std::uint32_t amb = pack_r11g11b10f(u[0][0], u[0][1], u[0][2]);
        for (int k = 0; k < 4; ++k) b[k] = std::uint8_t(amb >> (8 * k));
        const double scale[8] = {0.488603 / 0.282095, 0.488603 / 0.282095, 0.488603 / 0.282095, 1.092548 / 0.282095,
                                 1.092548 / 0.282095, 4 * 0.315392 / 0.282095, 1.092548 / 0.282095, 2 * 0.546274 / 0.282095};
        for (int c = 0; c < 3; ++c)
            for (int h = 0; h < 2; ++h) {
                std::uint8_t v[4];
                for (int k = 0; k < 4; ++k) v[k] = round_byte(u[1 + 4 * h + k][c] / std::max(u[0][c], 1e-4) / scale[4 * h + k] * 0.5 + 0.5);
                const size_t o = 4 + 4 * (2 * c + h);
                b[o] = v[2], b[o + 1] = v[1], b[o + 2] = v[0], b[o + 3] = v[3];  // BGRA
            }
    } else if (name == "vrchat_lv_l1") {
        // Unity's format (L0, L1 x y z), x 1.65, the atlas's LinearizeSingleSH (halve, then scale by
        // min(L0 / |L1|, 1.13)), as halves; in double here (the entry runs the C# steps in float).
        double l0[3], l1[3][3];
        for (int c = 0; c < 3; ++c) {
            const PolyTerms p = poly_terms(r, c);
            l0[c] = p.l0;
            const double len = 0.825 * std::sqrt(p.l1[0] * p.l1[0] + p.l1[1] * p.l1[1] + p.l1[2] * p.l1[2]);
            const double s = len > 0 && l0[c] > 0 ? 0.825 * std::min(l0[c] / len, 1.13) : 0.825;
            for (int k = 0; k < 3; ++k) l1[c][k] = p.l1[k] * s;
        }
        const double t[12] = {l0[0],    l0[1],    l0[2],    l1[0][2], l1[0][0], l1[1][0],
                              l1[2][0], l1[1][2], l1[0][1], l1[1][1], l1[2][1], l1[2][2]};
        for (int k = 0; k < 12; ++k) put16(b, 2 * k, pack_half(t[k]));
    } else if (name == "bevy_ambient_cube") {
        const auto f = twin_faces(r);
        for (int k = 0; k < 6; ++k) {
            const std::uint32_t v = pack_rgb9e5(f[k][0], f[k][1], f[k][2]);
            for (int j = 0; j < 4; ++j) b[4 * k + j] = std::uint8_t(v >> (8 * j));
        }
    } else if (name == "source2_ambient_cube") {
        const auto f = twin_faces(r);
        for (int k = 0; k < 6; ++k) {
            const double top = std::max({f[k][0], f[k][1], f[k][2], 0.0});
            const double m = std::ceil(std::min(top / kRgbmRange, 1.0) * 255.0);
            b[4 * k + 3] = std::uint8_t(m);
            for (int c = 0; c < 3; ++c) b[4 * k + c] = m > 0 ? round_byte(f[k][c] / (m / 255.0 * kRgbmRange)) : 0;
        }
    } else {
        ADD_FAILURE() << "no twin for " << name;
    }
    return b;
}

// The shader's irradiance from stored bytes, in zhc's units, at zhc normal n.
Rgb twin_irradiance(const std::string& name, const std::uint8_t* b, Vec3 n) {
    const Vec3 e = axes_of(name).to_engine(n);
    Rgb out;
    for (int c = 0; c < 3; ++c) {
        double v = 0;
        if (name == "threejs_grid_float" || name == "threejs_grid_half") {
            Coeffs r{};
            for (int k = 0; k < 27; ++k) r[k / 3][k % 3] = name == "threejs_grid_float" ? getf(b + 4 * k) : geth(b + 2 * k);
            v = std::max(sh_irradiance(r, c, e), 0.0);
        } else if (name == "godot_l2") {
            Coeffs r{};
            for (int i = 0; i < 9; ++i) r[i][c] = getf(b + 16 * i + 4 * c) * kPiD;
            v = sh_irradiance(r, c, e);
        } else if (name == "realitykit_l1") {
            Coeffs r{};
            for (int i = 0; i < 4; ++i) r[i][c] = getf(b + 12 * i + 4 * c);
            v = sh_irradiance(r, c, e, 4);
        } else if (name == "unity_apv_l1" || name == "unity_apv_l2") {
            const double l0 = geth(b + 2 * c);
            const double enc[3][3] = {{geth(b + 6), b[11] / 255.0, b[15] / 255.0},
                                      {b[8] / 255.0, b[9] / 255.0, b[10] / 255.0},
                                      {b[12] / 255.0, b[13] / 255.0, b[14] / 255.0}};
            v = l0;
            for (int k = 0; k < 3; ++k) v += (enc[c][k] - 0.5) * 4.0 * l0 * (k == 0 ? e.x : k == 1 ? e.y : e.z);
            if (name == "unity_apv_l2") {
                double l2[4];
                for (int k = 0; k < 4; ++k) l2[k] = (b[16 + 4 * c + k] / 255.0 - 0.5) * 3.5777088 * l0;
                const double cc = (b[28 + c] / 255.0 - 0.5) * 3.5777088 * l0;
                // DecodeSH_L2: L0 -= zz slot, zz slot *= 3.
                v += -l2[2] + l2[0] * e.x * e.y + l2[1] * e.y * e.z + 3 * l2[2] * e.z * e.z + l2[3] * e.z * e.x +
                     cc * (e.x * e.x - e.y * e.y);
            }
        } else if (name == "unreal_vlm_l2") {
            const Rgb amb = unpack_r11g11b10f(get32(b));
            const double scale[8] = {0.488603 / 0.282095, 0.488603 / 0.282095, 0.488603 / 0.282095, 1.092548 / 0.282095,
                                     1.092548 / 0.282095, 4 * 0.315392 / 0.282095, 1.092548 / 0.282095, 2 * 0.546274 / 0.282095};
            const double sign[9] = {1, -1, 1, -1, 1, -1, 1, -1, 1};
            Coeffs r{};
            r[0][c] = amb[c];
            for (int h = 0; h < 2; ++h) {
                const std::uint8_t* p = b + 4 + 4 * (2 * c + h);
                const double rgba[4] = {p[2] / 255.0, p[1] / 255.0, p[0] / 255.0, p[3] / 255.0};
                for (int k = 0; k < 4; ++k) r[1 + 4 * h + k][c] = sign[1 + 4 * h + k] * (2 * rgba[k] - 1) * amb[c] * scale[4 * h + k];
            }
            v = std::max(sh_irradiance(r, c, e), 0.0);
        } else if (name == "vrchat_lv_l1") {
            double t[12];
            for (int k = 0; k < 12; ++k) t[k] = geth(b + 2 * k);
            v = t[c] + t[4 + c] * e.x + t[8 + c] * e.y + t[4 * c + 3] * e.z;
        } else if (name == "bevy_ambient_cube" || name == "source2_ambient_cube") {
            double f[6][3];
            for (int k = 0; k < 6; ++k) {
                if (name == "bevy_ambient_cube") {
                    const Rgb x = unpack_rgb9e5(get32(b + 4 * k));
                    for (int j = 0; j < 3; ++j) f[k][j] = x[j];
                } else {
                    for (int j = 0; j < 3; ++j) f[k][j] = b[4 * k + j] / 255.0 * (b[4 * k + 3] / 255.0) * kRgbmRange;
                }
            }
            v = cube_value(f, c, e);
        }
        out[c] = float(v);
    }
    return out;
}

std::vector<std::string> engine_names() {
    std::vector<std::string> out;
    for (const Codec& c : codecs())
        if (!c.traits.engine.empty()) out.emplace_back(c.name);
    return out;
}

std::vector<Sh3Radiance> hubs() {
    std::vector<Sh3Radiance> out;
    for (const std::string& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        out.push_back(project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u));
    }
    test::Rng rng(40);
    for (int i = 0; i < 40; ++i) {  // non-negative lightings: a sky and one to three lights
        Sh3Radiance h = project_constant({float(0.05 + rng.u()), float(0.05 + rng.u()), float(0.05 + rng.u())});
        const int lights = 1 + i % 3;
        for (int l = 0; l < lights; ++l) {
            const Vec3 d = rng.dir();
            const double sigma = 0.05 + 1.2 * rng.u();
            h = h + project_cone(d, sigma, {float(3 * rng.u()), float(3 * rng.u()), float(3 * rng.u())});
        }
        out.push_back(h);
    }
    out.push_back(project_directional({0, 0, 1}, {1, 1, 1}));
    return out;
}

double scale_of(const Sh3Radiance& h) { return std::max({double(h[0].r), double(h[0].g), double(h[0].b), 1e-6}); }

// ---- the table ------------------------------------------------------------------------------

TEST(EngineLayouts, AreTheTablesTailWithTheirInfoAndNoRuntimeRow) {
    const auto all = codecs();
    const auto rt = runtime_codecs();
    ASSERT_LT(rt.size(), all.size());
    EXPECT_EQ(rt.data(), all.data());  // a prefix: runtime ids are the table's places
    for (size_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i].traits.engine.empty(), i < rt.size()) << all[i].name;
    const std::vector<std::string> names = engine_names();
    ASSERT_EQ(names.size(), engine_layouts().size());
    for (size_t i = 0; i < names.size(); ++i) {
        const EngineLayoutInfo& info = engine_layouts()[i];
        EXPECT_EQ(info.codec, names[i]);
        EXPECT_EQ(find_engine_layout(names[i]), &info);
        const Codec* c = find_codec(names[i]);
        EXPECT_FALSE(c->traits.exact) << names[i];
        EXPECT_EQ(c->traits.float_bands, 0) << names[i];
        EXPECT_EQ(c->packed, nullptr) << names[i];
        EXPECT_FALSE(info.source.empty());
        EXPECT_GE(std::max(info.gpu_bytes, info.disk_bytes), c->size_bytes) << names[i];
        // No runtime row: the generator and the runtime tests walk runtime_codecs() only.
        const auto e = runtime_entry(*c);
        ASSERT_FALSE(e.ok()) << names[i];
        EXPECT_NE(e.error().message.find("engine layout"), std::string::npos) << e.error().message;
        // The twin's axes are the entry's.
        const Axes& ax = axes_of(names[i]);
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) EXPECT_EQ(info.axes(r, k), ax.m[r][k]) << names[i];
    }
    EXPECT_EQ(find_engine_layout("sh3"), nullptr);
}

// Up is up, and the handedness is the engine's: zhc's +Z is +Y in the Y-up engines and +Z in the
// Z-up ones; the left-handed engines (Unity, Unreal) have determinant -1.
TEST(EngineLayouts, AxesPutUpWhereTheEngineHasIt) {
    for (const EngineLayoutInfo& info : engine_layouts()) {
        const Vec3 up = info.axes * Vec3{0, 0, 1};
        const bool z_up = info.engine.find("Unreal") != std::string_view::npos || info.engine.find("Source") != std::string_view::npos;
        EXPECT_EQ(up.x, 0.0) << info.codec;
        EXPECT_EQ(up.y, z_up ? 0.0 : 1.0) << info.codec;
        EXPECT_EQ(up.z, z_up ? 1.0 : 0.0) << info.codec;
        const Mat3& m = info.axes;
        const double det = m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0)) +
                           m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
        const bool left = info.engine.find("Unity") != std::string_view::npos || info.engine.find("VRChat") != std::string_view::npos ||
                          info.engine.find("Unreal") != std::string_view::npos;
        EXPECT_EQ(det, left ? -1.0 : 1.0) << info.codec;
    }
}

// engine_irradiance_sh and its inverse against the numerical projection.
TEST(EngineLayouts, EngineShIsTheProjectionInTheEnginesAxes) {
    for (const Sh3Radiance& hub : hubs()) {
        for (const Axes* ax : {&kGltf, &kUnity, &kUnreal, &kSource}) {
            Mat3 m;
            for (int r = 0; r < 3; ++r)
                for (int k = 0; k < 3; ++k) m(r, k) = ax->m[r][k];
            const EngineSh t = engine_irradiance_sh(hub, m);
            const Coeffs r = engine_radiance(hub, *ax);
            for (int i = 0; i < 9; ++i)
                for (int c = 0; c < 3; ++c) EXPECT_NEAR(t[i][c], r[i][c] * kBand[i], 1e-9 * (1 + std::fabs(r[i][c])));
            const Sh3Radiance back = hub_from_engine_irradiance_sh(t, m);
            EXPECT_LT(test::max_abs_diff(back, hub), 1e-5 * (1 + test::max_abs(hub)));
        }
    }
}

// ---- each entry against its twin ------------------------------------------------------------

class EngineEntry : public ::testing::TestWithParam<std::string> {};

// The stored bytes: float layouts to float rounding, quantised ones byte for byte except where the
// entry's float32 arithmetic (the engines' C# and shaders compute in float) and the twin's double
// round to neighbouring codes.
TEST_P(EngineEntry, StoresWhatTheEngineStores) {
    const std::string name = GetParam();
    const Codec& c = *find_codec(name);
    long bytes = 0, off_by_one = 0;
    double worst_float = 0;
    for (const Sh3Radiance& hub : hubs()) {
        std::vector<std::uint8_t> got(c.size_bytes);
        c.encode(hub, CodecOptions{}, got.data(), nullptr);
        const std::vector<std::uint8_t> want = twin_encode(name, hub);
        const double s = scale_of(hub);
        if (name == "threejs_grid_float" || name == "godot_l2" || name == "realitykit_l1") {
            for (size_t o = 0; o < got.size(); o += 4) worst_float = std::max(worst_float, std::fabs(getf(&got[o]) - getf(&want[o])) / s);
        } else if (name == "threejs_grid_half" || name == "vrchat_lv_l1") {
            for (size_t o = 0; o < got.size(); o += 2)
                worst_float = std::max(worst_float, std::fabs(geth(&got[o]) - geth(&want[o])) / s);
        } else if (name == "bevy_ambient_cube") {
            for (size_t o = 0; o < got.size(); o += 4) {
                const Rgb a = unpack_rgb9e5(get32(&got[o])), b = unpack_rgb9e5(get32(&want[o]));
                for (int k = 0; k < 3; ++k) worst_float = std::max(worst_float, std::fabs(double(a[k]) - b[k]) / s);
            }
        } else {
            // Unity's first 8 bytes are halves, Unreal's first 4 the R11G11B10F ambient: compared as values below.
            const size_t first = name == "unreal_vlm_l2" ? 4 : (name == "source2_ambient_cube" ? 0 : 8);
            for (size_t o = first; o < got.size(); ++o) {
                ++bytes;
                const int d = std::abs(int(got[o]) - int(want[o]));
                EXPECT_LE(d, 1) << name << " byte " << o;
                off_by_one += d != 0;
            }
            if (name == "unity_apv_l1" || name == "unity_apv_l2")
                for (size_t o = 0; o < 8; o += 2) worst_float = std::max(worst_float, std::fabs(geth(&got[o]) - geth(&want[o])) / s);
            if (name == "unreal_vlm_l2") {
                const Rgb a = unpack_r11g11b10f(get32(got.data())), b = unpack_r11g11b10f(get32(want.data()));
                for (int k = 0; k < 3; ++k) worst_float = std::max(worst_float, std::fabs(double(a[k]) - b[k]) / s);
            }
        }
    }
    // Halves and shared exponents: one step of their rounding at most (2^-10 of the value, here
    // relative to the probe's DC); float32 layouts: float rounding.
    const double tol = name == "threejs_grid_float" || name == "godot_l2" || name == "realitykit_l1" ? 1e-6 : 2e-3;
    EXPECT_LT(worst_float, tol) << name;
    if (bytes) {
        EXPECT_LT(double(off_by_one) / bytes, 0.02) << name << ": " << off_by_one << " of " << bytes << " bytes differ";
    }
    std::printf("%-22s worst value difference %.3g of DC, %ld of %ld bytes one code apart\n", name.c_str(), worst_float,
                off_by_one, bytes);
}

// Irradiance from the entry's own bytes: the entry and the twin's shader formula agree (the
// shaders' rounded constants, such as three.js's 0.886227 for pi / (2 sqrt(pi)), are the only
// difference).
TEST_P(EngineEntry, IrradianceIsTheShadersFormula) {
    const std::string name = GetParam();
    const Codec& c = *find_codec(name);
    const auto dirs = test::fibonacci_directions(200);
    double worst = 0;
    for (const Sh3Radiance& hub : hubs()) {
        std::vector<std::uint8_t> s(c.size_bytes);
        c.encode(hub, CodecOptions{}, s.data(), nullptr);
        const double scale = scale_of(hub);
        for (const Vec3 n : dirs) {
            const Rgb a = c.irradiance(s.data(), CodecOptions{}, n), b = twin_irradiance(name, s.data(), n);
            for (int k = 0; k < 3; ++k) worst = std::max(worst, std::fabs(double(a[k]) - b[k]) / scale);
        }
    }
    EXPECT_LT(worst, 2e-6) << name;
}

// What a layout loses against the hub it stored, at most: the float SH layouts nothing but float
// rounding (and three.js and Unreal their clamp at 0), the L1 ones the L2 band, the quantised ones
// their steps. Bounds are relative to the largest DC channel.
class EngineShEntry : public ::testing::TestWithParam<std::string> {};
TEST_P(EngineShEntry, ErrorAgainstTheHubIsItsQuantisation) {
    const std::string name = GetParam();
    const Codec& c = *find_codec(name);
    const auto dirs = test::fibonacci_directions(300);
    const std::map<std::string, double> bound = {
        {"threejs_grid_float", 1e-5}, {"threejs_grid_half", 2e-3}, {"godot_l2", 1e-5},   {"realitykit_l1", 1e-5},
        {"unity_apv_l1", 0.04},       {"unity_apv_l2", 0.06},      {"unreal_vlm_l2", 0.06}, {"vrchat_lv_l1", 0.3}};
    const bool linear = name == "realitykit_l1" || name == "unity_apv_l1" || name == "vrchat_lv_l1";
    const bool clamps = c.traits.irradiance_model == IrradianceModel::kSh3Clamped;
    ASSERT_NE(c.traits.irradiance_model, IrradianceModel::kOwn);
    double worst = 0;
    for (const Sh3Radiance& hub : hubs()) {
        Sh3Radiance ref = hub;
        if (linear)
            for (int i = 4; i < 9; ++i) ref[i] = {0, 0, 0};
        std::vector<std::uint8_t> s(c.size_bytes);
        c.encode(hub, CodecOptions{}, s.data(), nullptr);
        for (const Vec3 n : dirs) {
            const Rgb a = c.irradiance(s.data(), CodecOptions{}, n), b = irradiance(ref, n);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::fabs(double(a[k]) - (clamps ? std::max(double(b[k]), 0.0) : double(b[k]))) / scale_of(hub));
        }
    }
    EXPECT_LT(worst, bound.at(name)) << name;
    std::printf("%-22s largest irradiance difference from the hub%s: %.3g of DC\n", name.c_str(), linear ? " (L1 band)" : "", worst);
}

INSTANTIATE_TEST_SUITE_P(All, EngineEntry, ::testing::ValuesIn(engine_names()), [](const auto& info) { return info.param; });
// The SH layouts (the ambient cubes: AmbientCubesHoldTheIrradianceAtTheirFaces).
std::vector<std::string> engine_sh_names() {
    std::vector<std::string> out;
    for (const std::string& n : engine_names())
        if (find_codec(n)->traits.irradiance_model != IrradianceModel::kOwn) out.push_back(n);
    return out;
}
INSTANTIATE_TEST_SUITE_P(Sh, EngineShEntry, ::testing::ValuesIn(engine_sh_names()), [](const auto& info) { return info.param; });

// ---- what the sources promise ---------------------------------------------------------------

// VRChat's atlas deringing (LinearizeSingleSH): |L1| <= L0 per channel, so irradiance >= 0 for
// every non-negative lighting (up to the halves' rounding).
TEST(EngineLayouts, VrchatLightVolumesAreNonNegative) {
    const Codec& c = *find_codec("vrchat_lv_l1");
    const auto dirs = test::fibonacci_directions(2048);
    int clamped_probes = 0;
    for (const Sh3Radiance& hub : hubs()) {
        std::vector<std::uint8_t> s(c.size_bytes);
        c.encode(hub, CodecOptions{}, s.data(), nullptr);
        double lo = 1e300;
        for (const Vec3 n : dirs) {
            const Rgb e = c.irradiance(s.data(), CodecOptions{}, n);
            lo = std::min({lo, double(e.r), double(e.g), double(e.b)});
        }
        EXPECT_GE(lo, -2e-3 * scale_of(hub));
        // The plain L1 of the same hub goes negative on the directional light: the deringing is what helps.
        Sh3Radiance l1 = hub;
        for (int i = 4; i < 9; ++i) l1[i] = {0, 0, 0};
        double plain = 1e300;
        for (const Vec3 n : dirs) plain = std::min(plain, double(irradiance(l1, n).g));
        clamped_probes += plain < -1e-3 * scale_of(hub);
    }
    EXPECT_GT(clamped_probes, 0);
}

// An ambient cube's face is the irradiance at its direction, and the cube reproduces it there (up
// to RGB9E5 / RGBM); decode is the least-squares SH3 projection of the cube's reconstruction.
TEST(EngineLayouts, AmbientCubesHoldTheIrradianceAtTheirFaces) {
    const Quadrature fine = quadrature(96);
    for (const char* name : {"bevy_ambient_cube", "source2_ambient_cube"}) {
        const Codec& c = *find_codec(name);
        ASSERT_EQ(c.traits.irradiance_model, IrradianceModel::kOwn);
        const Axes& ax = axes_of(name);
        for (const Sh3Radiance& hub : hubs()) {
            std::vector<std::uint8_t> s(c.size_bytes);
            c.encode(hub, CodecOptions{}, s.data(), nullptr);
            const double scale = scale_of(hub);
            for (int k = 0; k < 6; ++k) {
                Vec3 e{};
                (k / 2 == 0 ? e.x : k / 2 == 1 ? e.y : e.z) = k % 2 ? -1 : 1;
                const Vec3 n = ax.to_zhc(e);
                const Rgb got = c.irradiance(s.data(), CodecOptions{}, n), want = irradiance(hub, n);
                const double top = std::max({double(want.r), double(want.g), double(want.b), 0.0});
                // Half a step: RGBM's step is m range / 255 with m <= top / range + 1 / 255; RGB9E5's
                // is at most 2^-8 of the face's largest channel. RGBM saturates at its range.
                const bool rgbm = std::string(name) == "source2_ambient_cube";
                const double step = rgbm ? 0.5 * (top + kRgbmRange / 255.0) / 255.0 : 4e-3 * top;
                if (rgbm && top > kRgbmRange) continue;
                for (int j = 0; j < 3; ++j)  // the formats hold no negative value
                    EXPECT_NEAR(got[j], std::max(double(want[j]), 0.0), step + 1e-6 * scale) << name << " face " << k;
            }
            // Decode: the residual of the reconstruction against decode's SH3 irradiance is orthogonal
            // to every SH3 basis function (its projection is zero), up to the quadrature's error.
            const Sh3Radiance d = c.decode(s.data(), CodecOptions{});
            double residual[9][3] = {};
            for (size_t q = 0; q < fine.dirs.size(); ++q) {
                const Vec3 n = fine.dirs[q];
                const Rgb own = c.irradiance(s.data(), CodecOptions{}, n), sh = irradiance(d, n);
                const std::array<double, 9> y = sh3_basis(n);
                for (int i = 0; i < 9; ++i)
                    for (int j = 0; j < 3; ++j) residual[i][j] += fine.weights[q] * (double(own[j]) - sh[j]) * y[i];
            }
            for (int i = 0; i < 9; ++i)
                for (int j = 0; j < 3; ++j) EXPECT_NEAR(residual[i][j], 0.0, 2e-4 * scale) << name << " coefficient " << i;
        }
    }
}

// The float layouts give the hub back (three.js and Godot the whole SH3, RealityKit its L1), in the
// engine's scale: Godot stores radiance / pi, three.js radiance.
TEST(EngineLayouts, FloatLayoutsDecodeToTheHub) {
    for (const char* name : {"threejs_grid_float", "godot_l2", "realitykit_l1"}) {
        const Codec& c = *find_codec(name);
        for (const Sh3Radiance& hub : hubs()) {
            std::vector<std::uint8_t> s(c.size_bytes);
            c.encode(hub, CodecOptions{}, s.data(), nullptr);
            Sh3Radiance want = hub;
            if (std::string(name) == "realitykit_l1")
                for (int i = 4; i < 9; ++i) want[i] = {0, 0, 0};
            EXPECT_LT(test::max_abs_diff(c.decode(s.data(), CodecOptions{}), want), 2e-6 * (1 + test::max_abs(hub))) << name;
        }
    }
    // Godot's DC: a constant radiance of 1 is stored as 2 sqrt(pi) / pi in every channel.
    const Codec& g = *find_codec("godot_l2");
    std::vector<std::uint8_t> s(g.size_bytes);
    g.encode(project_constant({1, 1, 1}), CodecOptions{}, s.data(), nullptr);
    EXPECT_NEAR(getf(s.data()), 2 * std::sqrt(kPiD) / kPiD, 1e-6);
    EXPECT_EQ(getf(s.data() + 12), 0.0);  // alpha
}

// three.js and Unreal clamp at 0 where the SH goes negative; the unclamped SH is what decode gives.
TEST(EngineLayouts, ClampingShadersClampAndDecodeKeepsTheStoredSh) {
    const Sh3Radiance dir = project_directional({0.3, -0.5, 0.81}, {2, 1, 0.5});
    for (const char* name : {"threejs_grid_float", "unreal_vlm_l2"}) {
        const Codec& c = *find_codec(name);
        std::vector<std::uint8_t> s(c.size_bytes);
        c.encode(dir, CodecOptions{}, s.data(), nullptr);
        const Sh3Radiance d = c.decode(s.data(), CodecOptions{});
        int negative = 0;
        for (const Vec3 n : test::fibonacci_directions(500)) {
            const Rgb e = c.irradiance(s.data(), CodecOptions{}, n), sh = irradiance(d, n);
            for (int k = 0; k < 3; ++k) {
                EXPECT_GE(e[k], 0.0f);
                EXPECT_NEAR(e[k], std::max(sh[k], 0.0f), 1e-5 * 2);
                negative += sh[k] < 0;
            }
        }
        EXPECT_GT(negative, 0) << name << ": the directional light's L2 rings below 0 somewhere";
    }
}

// The texels are what the shader reads (irradiance is the shader on them, bit for bit); the float
// SH layouts' shaders are linear in their texels, so a hardware filter's blend of the corners is the
// blend of their irradiance, while Unity's ratio decode multiplies by the blended L0 and is not.
TEST(EngineLayouts, TexelsAreWhatTheShaderReads) {
    const std::vector<Sh3Radiance> h = hubs();
    const auto dirs = test::fibonacci_directions(50);
    for (const EngineLayoutInfo& info : engine_layouts()) {
        ASSERT_GT(info.texel_count, 0);
        ASSERT_LE(info.texel_count, kMaxEngineTexels);
        const Codec& c = *find_codec(info.codec);
        std::vector<std::uint8_t> a(c.size_bytes), b(c.size_bytes);
        double ta[kMaxEngineTexels], tb[kMaxEngineTexels], mid[kMaxEngineTexels];
        double worst_linear = 0;
        for (size_t i = 0; i + 1 < h.size(); ++i) {
            c.encode(h[i], CodecOptions{}, a.data(), nullptr);
            c.encode(h[i + 1], CodecOptions{}, b.data(), nullptr);
            info.texels(a.data(), ta);
            info.texels(b.data(), tb);
            for (int k = 0; k < info.texel_count; ++k) mid[k] = 0.5 * (ta[k] + tb[k]);
            for (const Vec3 n : dirs) {
                const Rgb direct = c.irradiance(a.data(), CodecOptions{}, n), shaded = info.shade(ta, n);
                for (int k = 0; k < 3; ++k) ASSERT_EQ(direct[k], shaded[k]) << info.codec;
                const Rgb m = info.shade(mid, n), ea = info.shade(ta, n), eb = info.shade(tb, n);
                for (int k = 0; k < 3; ++k)
                    worst_linear = std::max(worst_linear, std::fabs(m[k] - 0.5 * (double(ea[k]) + eb[k])) /
                                                              std::max(scale_of(h[i]), scale_of(h[i + 1])));
            }
        }
        const std::string name(info.codec);
        if (name == "godot_l2" || name == "realitykit_l1" || name == "vrchat_lv_l1" || name == "bevy_ambient_cube") {
            EXPECT_LT(worst_linear, 1e-6) << name << ": linear in its texels";
        }
        if (name == "unity_apv_l1" || name == "unity_apv_l2" || name == "unreal_vlm_l2" || name == "source2_ambient_cube") {
            EXPECT_GT(worst_linear, 1e-3) << name << ": its decode multiplies blended texels";
        }
    }
}

// ---- the reports ----------------------------------------------------------------------------

// The plots draw zhc's Pareto frontier without the engine layouts and mark those apart.
TEST(EngineReport, PlotsDrawZhcsFrontierAndTheEngineLayoutsApart) {
    ScatterPlot plot{"Error vs bytes per probe", "bytes", "error", {}, {}};
    test::Rng rng(3);
    for (const Codec& c : codecs()) plot.points.push_back(codec_point(c, double(c.size_bytes), 0.01 + rng.u()));
    // An engine layout better than everything: still not on zhc's frontier.
    for (PlotPoint& p : plot.points)
        if (p.label == "unity_apv_l1") p.y = 1e-4;
    const std::vector<std::size_t> front = zhc_frontier(plot);
    std::vector<double> x, y;
    std::vector<std::size_t> own;
    int engines = 0;
    for (std::size_t i = 0; i < plot.points.size(); ++i) {
        EXPECT_EQ(plot.points[i].engine, !find_codec(plot.points[i].label)->traits.engine.empty());
        if (plot.points[i].engine) {
            ++engines;
            continue;
        }
        own.push_back(i), x.push_back(plot.points[i].x), y.push_back(plot.points[i].y);
    }
    std::vector<std::size_t> want;
    for (std::size_t k : pareto_frontier(x, y)) want.push_back(own[k]);
    EXPECT_EQ(front, want);
    ASSERT_FALSE(front.empty());
    plot.frontier = front;
    const std::string svg = scatter_svg(plot);
    std::size_t squares = 0;
    for (std::size_t at = svg.find("<rect class=\"engine\""); at != std::string::npos; at = svg.find("<rect class=\"engine\"", at + 1))
        ++squares;
    EXPECT_EQ(squares, std::size_t(engines));
    EXPECT_NE(svg.find("orange squares: engine layouts"), std::string::npos);
    // Without engine layouts, no legend line for them.
    ScatterPlot own_only = plot;
    own_only.points.erase(std::remove_if(own_only.points.begin(), own_only.points.end(), [](const PlotPoint& p) { return p.engine; }),
                          own_only.points.end());
    own_only.frontier = zhc_frontier(own_only);
    EXPECT_EQ(scatter_svg(own_only).find("engine layouts"), std::string::npos);
}

// zhc audit reports every engine layout beside zhc's best at its size: the JSON's engine_layouts
// against a twin over its own aggregate, the Markdown and HTML sections, the text table.
TEST(EngineReport, AuditComparesEachEngineLayoutWithZhcsBestAtItsSize) {
    const std::string dir = test::fresh_dir("engine_audit");
    const std::string map = test::envmap_paths().at(0);
    const auto r = test::run_zhc({"audit", map, "--no-timing", "--directions", "256", "--json", "--markdown", dir + "/a.md",
                                  "--html", dir + "/a.html"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json doc = nlohmann::json::parse(r.out);
    const nlohmann::json& agg = doc.at("aggregate").at("representations");
    const nlohmann::json& rows = doc.at("engine_layouts");
    ASSERT_EQ(rows.size(), engine_layouts().size());
    for (const nlohmann::json& row : rows) {
        const std::string name = row.at("representation");
        const Codec* e = find_codec(name);
        ASSERT_NE(e, nullptr);
        EXPECT_EQ(row.at("engine"), std::string(e->traits.engine));
        EXPECT_EQ(row.at("relative_rmse").get<double>(), agg.at(name).at("relative_rmse").get<double>());
        // The twin: the lowest relative rmse among zhc's entries of at most as many bytes.
        std::string best;
        double best_err = 1e300;
        for (const Codec& c : runtime_codecs()) {
            const double err = agg.at(std::string(c.name)).at("relative_rmse").get<double>();
            if (c.size_bytes <= e->size_bytes && err < best_err) best = std::string(c.name), best_err = err;
        }
        ASSERT_FALSE(row.at("zhc_best").is_null()) << name;  // 16 bytes is zhc's smallest, and no engine layout is smaller
        EXPECT_EQ(row.at("zhc_best").at("representation"), best) << name;
        EXPECT_EQ(row.at("zhc_best").at("relative_rmse").get<double>(), best_err);
        EXPECT_LE(row.at("zhc_best").at("bytes_per_probe").get<std::size_t>(), e->size_bytes);
    }
    const std::vector<std::uint8_t> md = test::read_bytes(dir + "/a.md"), html = test::read_bytes(dir + "/a.html");
    const std::string m(md.begin(), md.end()), h(html.begin(), html.end());
    EXPECT_NE(m.find("\n## Engine layouts\n"), std::string::npos);
    EXPECT_NE(m.find("| unity_apv_l1 "), std::string::npos);
    EXPECT_NE(h.find("id=\"engine-layouts\""), std::string::npos);
    EXPECT_NE(h.find("<rect class=\"engine\""), std::string::npos);
    // Only zhc's representations: no engine section at all.
    const auto plain = test::run_zhc({"audit", map, "--no-timing", "--directions", "64", "-r", "sh3,zh3_q16", "--markdown", dir + "/b.md"});
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    EXPECT_EQ(plain.out.find("engine layouts"), std::string::npos);
    const std::vector<std::uint8_t> b = test::read_bytes(dir + "/b.md");
    EXPECT_EQ(std::string(b.begin(), b.end()).find("Engine layouts"), std::string::npos);
    const auto text = test::run_zhc({"audit", map, "--no-timing", "--directions", "64", "-r", "sh3,unity_apv_l2"});
    ASSERT_EQ(text.exit_code, 0) << text.err;
    EXPECT_NE(text.out.find("engine layouts:"), std::string::npos);
    EXPECT_NE(text.out.find("unity_apv_l2"), std::string::npos);
}

}  // namespace
}  // namespace zhc
