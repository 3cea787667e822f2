// zhc/codec/lightmap/irradz.cpp — IrradZ / HHD / AHD lightmap maths: the two lighting models and
// their evaluation, the hemispherical quadrature (Gauss-Legendre in z times a uniform rule in phi)
// and the Gram matrices over a cap, the error integrals (SH-space hemispherical error, true
// hemispherical MSE), and the HLSH hemisphere / cone multiply. Derivations in docs/irradz.md.
// The encoder's solves: irradz_search.cpp (golden section, the reference) and irradz_newton.cpp
// (Newton, the default); linear SH <-> HHD and blending: irradz_linear_sh.cpp.
//
// Source: Roughton, "IrradZ" (SIGGRAPH 2024 Advances in Real-Time Rendering talk);
// the slide formulas are re-derived in docs/irradz.md.
#include "codec/lightmap/irradz.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "codec/lightmap/irradz_internal.h"

namespace zhc::irradz {
namespace {

using namespace detail;  // irradz_internal.h

// Gauss-Legendre nodes/weights on [-1, 1] (Newton on P_n); n = 10 integrates polynomials of degree
// <= 19 exactly, far more than the degree-4 (Gram) and degree-3 (HLSH) integrands need.
struct GaussLegendre {
    std::vector<double> x, w;
};
GaussLegendre gauss_legendre(int n) {
    GaussLegendre g;
    g.x.resize(static_cast<size_t>(n));
    g.w.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
        double dp = 1;
        for (int it = 0; it < 100; ++it) {
            double p0 = 1, p1 = z;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2.0 * k - 1) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1);
            const double dz = p1 / dp;
            z -= dz;
            if (std::abs(dz) < 1e-16) break;
        }
        g.x[static_cast<size_t>(i)] = z;
        g.w[static_cast<size_t>(i)] = 2.0 / ((1 - z * z) * dp * dp);
    }
    return g;
}

// Product rule over the cap z >= c: Gauss-Legendre in z (the area element is dz dphi) and a uniform
// rule in phi with 16 points (exact for trigonometric polynomials of order <= 15).
template <class F>
void for_cap_nodes(double c, F&& f) {
    static const GaussLegendre gl = gauss_legendre(10);
    constexpr int kPhi = 16;
    const double half = (1 - c) / 2;
    for (size_t i = 0; i < gl.x.size(); ++i) {
        const double z = c + half * (gl.x[i] + 1);
        const double s = std::sqrt(std::max(0.0, 1 - z * z));
        const double wz = half * gl.w[i] * 2 * kPi / kPhi;
        for (int j = 0; j < kPhi; ++j) {
            const double phi = 2 * kPi * (j + 0.5) / kPhi;
            f(Vec3{s * std::cos(phi), s * std::sin(phi), z}, wz);
        }
    }
}

}  // namespace

const Tables& detail::tables() {
    static const Tables t = [] {
        Tables t;
        // (1 + z)/2 and 1 in SH3 (exact; the tests check them against project_hemisphere/constant).
        t.hemi[0] = std::sqrt(kPi);                 // integral of (1/2) Y00 over the sphere
        t.hemi[2] = (2.0 * kPi / 3.0) * kY1;        // integral of (z/2) kY1 z = kY1 * (4 pi / 3) / 2
        t.ambient[0] = 2.0 * std::sqrt(kPi);        // integral of Y00
        for_cap_nodes(0.0, [&](Vec3 w, double wt) {
            const auto y = sh3_basis(w);
            for (size_t i = 0; i < 9; ++i) {
                t.p_one_minus_z[i] += wt * y[i] * (1 - w.z);
                t.p_x[i] += wt * y[i] * w.x;
                t.p_y[i] += wt * y[i] * w.y;
            }
        });
        t.y_up = sh3_basis({0, 0, 1});
        t.g_hemi = cap_gram(0.0);
        for (int i = 0; i < 9; ++i)
            for (int j = 0; j < 9; ++j)
                if (std::abs(t.g_hemi[static_cast<size_t>(i * 9 + j)]) > 1e-12) {
                    t.nz_i[static_cast<size_t>(t.nnz)] = static_cast<std::uint8_t>(i);
                    t.nz_j[static_cast<size_t>(t.nnz++)] = static_cast<std::uint8_t>(j);
                }
        t.g_hemi_hemi = mul(t.g_hemi, t.hemi);
        t.g_hemi_ambient = mul(t.g_hemi, t.ambient);
        for (int i = 0; i < 9; ++i) t.g_sphere[static_cast<size_t>(i * 10)] = 1.0;
        return t;
    }();
    return t;
}

Lighting to_lighting(const IrradZ& p) {
    const Vec3 d = clamp_to_hemisphere(p.d);
    const double w = std::clamp(p.w_a, 0.0, 1.0);
    Lighting l;
    l.d = d;
    for (int k = 0; k < 3; ++k) {
        l.c_a[k] = static_cast<float>(w * p.i_z[k]);
        l.c_d[k] = static_cast<float>((1 - w) * p.i_z[k] / d.z);
    }
    return l;
}

Rgb evaluate(const Lighting& l, Model model, Vec3 n) {
    const double h = model == Model::kHhd ? (1 + n.z) / 2 : 1.0;
    const double c = std::max(0.0, dot(n, l.d));
    Rgb r;
    for (int k = 0; k < 3; ++k) r[k] = static_cast<float>(l.c_a[k] * h + l.c_d[k] * c);
    return r;
}
Rgb evaluate(const IrradZ& p, Model model, Vec3 n) { return evaluate(to_lighting(p), model, n); }

std::array<double, 81> cap_gram(double cos_alpha) {
    Mat9 g{};
    for_cap_nodes(std::clamp(cos_alpha, -1.0, 1.0), [&](Vec3 w, double wt) {
        const auto y = sh3_basis(w);
        for (size_t i = 0; i < 9; ++i)
            for (size_t j = 0; j < 9; ++j) g[i * 9 + j] += wt * y[i] * y[j];
    });
    return g;
}
const std::array<double, 81>& hemisphere_gram() { return tables().g_hemi; }

Sh3Irradiance model_sh3(const IrradZ& p, Model model) {
    const Lighting l = to_lighting(p);
    const Tables& tb = tables();
    const Vec9& h = model == Model::kHhd ? tb.hemi : tb.ambient;
    const Vec9 c = clamped_cosine_sh(l.d);
    Sh3Irradiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            out[i][k] = static_cast<float>(l.c_a[k] * h[static_cast<size_t>(i)] + l.c_d[k] * c[static_cast<size_t>(i)]);
    return out;
}

double sh_hemispherical_error(const Sh3Irradiance& target, const IrradZ& p, Model model) {
    const Sh3Irradiance m = model_sh3(p, model);
    const Mat9& g = hemisphere_gram();
    double e = 0;
    for (int k = 0; k < 3; ++k) {
        Vec9 r{};
        for (int i = 0; i < 9; ++i) r[static_cast<size_t>(i)] = double(target[i][k]) - double(m[i][k]);
        e += dot9(r, mul(g, r));
    }
    return e;
}

double hemispherical_mse(const Sh3Irradiance& target, const IrradZ& p, Model model) {
    struct Node {
        Vec3 n;
        double w;
        std::array<double, 9> y;
    };
    static const std::vector<Node> nodes = [] {
        std::vector<Node> v;
        const GaussLegendre gl = gauss_legendre(16);
        constexpr int kPhi = 32;
        for (size_t i = 0; i < gl.x.size(); ++i) {
            const double z = (gl.x[i] + 1) / 2, s = std::sqrt(std::max(0.0, 1 - z * z));
            for (int j = 0; j < kPhi; ++j) {
                const double phi = 2 * kPi * (j + 0.5) / kPhi;
                const Vec3 n{s * std::cos(phi), s * std::sin(phi), z};
                v.push_back({n, gl.w[i] / 2 / kPhi, sh3_basis(n)});  // weights sum to 1
            }
        }
        return v;
    }();
    const Lighting l = to_lighting(p);
    double e = 0;
    for (const Node& nd : nodes) {
        const Rgb m = evaluate(l, model, nd.n);
        for (int k = 0; k < 3; ++k) {
            double t = 0;
            for (int i = 0; i < 9; ++i) t += target[i][k] * nd.y[static_cast<size_t>(i)];
            e += nd.w * (t - m[k]) * (t - m[k]);
        }
    }
    return e;
}

// ---- HLSH ----------------------------------------------------------------------------------

Rgb evaluate(const Hlsh& h, Vec3 m) {
    Rgb r;
    for (int k = 0; k < 3; ++k)
        r[k] = static_cast<float>(h.i_z[k] * m.z + h.c_a[k] * (1 - m.z) + h.c_x[k] * m.x + h.c_y[k] * m.y);
    return r;
}

Sh3Radiance cap_multiply(const Sh3Radiance& l, double cos_alpha) {
    const Mat9 g = cos_alpha == 0.0 ? hemisphere_gram() : cap_gram(cos_alpha);
    Sh3Radiance o;
    for (int k = 0; k < 3; ++k) {
        Vec9 v{};
        for (int i = 0; i < 9; ++i) v[static_cast<size_t>(i)] = l[i][k];
        const Vec9 r = mul(g, v);
        for (int i = 0; i < 9; ++i) o[i][k] = static_cast<float>(r[static_cast<size_t>(i)]);
    }
    return o;
}

Hlsh hlsh_multiply(const Sh3Radiance& world_radiance, const Mat3& frame, double cos_alpha) {
    // rotate(f, R) gives g(d) = f(R^T d); with R = frame^T, g(t) = f(frame t): tangent t -> world.
    const Sh3Radiance tangent = rotate(world_radiance, transpose(frame));
    const Sh3Irradiance t = to_irradiance(cap_multiply(tangent, cos_alpha));
    const Tables& tb = tables();
    // Over z >= 0 the HLSH functions (1 - z), x, y are mutually orthogonal, so the least-squares
    // fit with I_z fixed separates:  C_a = <T - I_z z, 1 - z> / <1 - z, 1 - z>,  c_x = <T, x>/<x, x>.
    // <1-z,1-z> = 2 pi / 3, <z, 1-z> = pi / 3, <x, x> = <y, y> = 2 pi / 3.
    const double n11 = 2 * kPi / 3, nz1 = kPi / 3, nxx = 2 * kPi / 3;
    Hlsh h;
    for (int k = 0; k < 3; ++k) {
        Vec9 v{};
        for (int i = 0; i < 9; ++i) v[static_cast<size_t>(i)] = t[i][k];
        const double iz = dot9(v, tb.y_up);
        h.i_z[k] = static_cast<float>(iz);
        h.c_a[k] = static_cast<float>((dot9(v, tb.p_one_minus_z) - iz * nz1) / n11);
        h.c_x[k] = static_cast<float>(dot9(v, tb.p_x) / nxx);
        h.c_y[k] = static_cast<float>(dot9(v, tb.p_y) / nxx);
    }
    return h;
}

}  // namespace zhc::irradz
