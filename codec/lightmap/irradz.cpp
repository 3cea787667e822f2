// zhc/codec/lightmap/irradz.cpp — IrradZ / HHD / AHD lightmap maths. Derivations in docs/irradz.md.
#include "codec/lightmap/irradz.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace zhc::irradz {
namespace {

using Vec9 = std::array<double, 9>;
using Mat9 = std::array<double, 81>;

double dot9(const Vec9& a, const Vec9& b) {
    double s = 0;
    for (int i = 0; i < 9; ++i) s += a[static_cast<size_t>(i)] * b[static_cast<size_t>(i)];
    return s;
}
Vec9 mul(const Mat9& g, const Vec9& v) {
    Vec9 r{};
    for (int i = 0; i < 9; ++i) {
        double s = 0;
        for (int j = 0; j < 9; ++j) s += g[static_cast<size_t>(i * 9 + j)] * v[static_cast<size_t>(j)];
        r[static_cast<size_t>(i)] = s;
    }
    return r;
}

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

// Constant tables: SH3 irradiance coefficients of the hemisphere light (1 + z)/2 and of the
// constant 1, and the HLSH projection vectors over the upper hemisphere.
struct Tables {
    Vec9 hemi{}, ambient{};
    Vec9 g_hemi_hemi{}, g_hemi_ambient{};  // G_hemi times the two constant terms
    // Non-zero entries of G_hemi: over z >= 0 the phi integral only pairs basis functions of the
    // same m (and sin/cos type), so 19 of the 81 entries are non-zero.
    std::array<std::uint8_t, 81> nz_i{}, nz_j{};
    int nnz = 0;
    Vec9 p_one_minus_z{}, p_x{}, p_y{};  // integral over z >= 0 of Y_i * (1 - z), Y_i x, Y_i y
    Vec9 y_up{};                         // Y_i(+Z)
    Mat9 g_hemi{}, g_sphere{};
};
const Tables& tables() {
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

// SH3 irradiance coefficients of max(0, n.d): Funk-Hecke, pi * {1, 2/3, 1/4}_l * Y_i(d).
Vec9 clamped_cosine_sh(Vec3 d) {
    const auto y = sh3_basis(d);
    Vec9 r{};
    for (int i = 0; i < 9; ++i) {
        const int l = i == 0 ? 0 : (i < 4 ? 1 : 2);
        r[static_cast<size_t>(i)] = kPi * kIrradianceBandScale[l] * y[static_cast<size_t>(i)];
    }
    return r;
}

Vec3 direction_from_angles(double theta, double phi) {
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// Keeps d in the stored range: d_z >= kMinDz, azimuth kept.
Vec3 clamp_to_hemisphere(Vec3 d) {
    d = normalize_or(d, {0, 0, 1});
    if (d.z >= kMinDz) return d;
    const double phi = std::atan2(d.y, d.x);
    return direction_from_angles(kMaxTheta, phi);
}

struct Target {
    std::array<Vec9, 3> t{};   // SH3 irradiance per channel
    std::array<Vec9, 3> gt{};  // G t
    std::array<double, 3> tgt{};
    std::array<double, 3> iz{};
};

Target make_target(const Sh3Irradiance& irr, const Mat9& g, const Rgb* sampled_iz = nullptr) {
    Target tg;
    const Tables& tb = tables();
    for (int k = 0; k < 3; ++k) {
        auto& t = tg.t[static_cast<size_t>(k)];
        for (int i = 0; i < 9; ++i) t[static_cast<size_t>(i)] = irr[i][k];
        tg.gt[static_cast<size_t>(k)] = mul(g, t);
        tg.tgt[static_cast<size_t>(k)] = dot9(t, tg.gt[static_cast<size_t>(k)]);
        // I_z = E(n_v) from the SH irradiance, clamped at 0 (I_z is stored unsigned).
        tg.iz[static_cast<size_t>(k)] = std::max(0.0, sampled_iz ? double((*sampled_iz)[k]) : dot9(t, tb.y_up));
    }
    return tg;
}

// For a fixed d: the least-squares w_a (clamped to [0, 1]) and the error, all in closed form.
// Model per channel: m = I (A + w B), A = C(d)/d_z, B = H - A (H: hemisphere or ambient term).
struct Fit {
    double w = 1, err = 0;
};
// w_a (least squares, clamped to [0, 1]) and the error for one d, from the products the closed
// form needs: aga = a.G a, agh = a.G h, hgh = h.G h, agt_k = a.G t_k, hgt_k = h.G t_k.
Fit fit_from_products(const Target& tg, double aga, double agh, double hgh, const double agt[3], const double hgt[3]) {
    const double bgb = hgh - 2 * agh + aga;
    double r0[3], bgr[3], num = 0, den = 0;
    for (size_t k = 0; k < 3; ++k) {
        const double i = tg.iz[k];
        r0[k] = tg.tgt[k] - 2 * i * agt[k] + i * i * aga;
        bgr[k] = hgt[k] - i * agh - agt[k] + i * aga;
        num += i * bgr[k];
        den += i * i * bgb;
    }
    Fit f;
    f.w = den > 0 ? std::clamp(num / den, 0.0, 1.0) : 1.0;
    for (size_t k = 0; k < 3; ++k) {
        const double i = tg.iz[k];
        f.err += r0[k] - 2 * f.w * i * bgr[k] + f.w * f.w * i * i * bgb;
    }
    f.err = std::max(0.0, f.err);
    return f;
}

Fit fit_direction(const Target& tg, Vec3 d, Model model, const Mat9& g) {
    const Tables& tb = tables();
    const Vec9& h = model == Model::kHhd ? tb.hemi : tb.ambient;
    Vec9 a = clamped_cosine_sh(d);
    for (double& v : a) v /= d.z;
    Vec9 ga{};
    if (&g == &tb.g_hemi) {
        for (int k = 0; k < tb.nnz; ++k) {
            const size_t i = tb.nz_i[static_cast<size_t>(k)], j = tb.nz_j[static_cast<size_t>(k)];
            ga[i] += g[i * 9 + j] * a[j];
        }
    } else {
        ga = mul(g, a);
    }
    // G h is constant; reuse the precomputed product for the hemispherical Gram matrix.
    const Vec9 gh = &g == &tb.g_hemi ? (model == Model::kHhd ? tb.g_hemi_hemi : tb.g_hemi_ambient) : mul(g, h);
    double agt[3], hgt[3];
    for (size_t k = 0; k < 3; ++k) agt[k] = dot9(a, tg.gt[k]), hgt[k] = dot9(h, tg.gt[k]);
    return fit_from_products(tg, dot9(a, ga), dot9(a, gh), dot9(h, gh), agt, hgt);
}

// fit_direction for the hemispherical Gram matrix, as the search calls it ~60 times per texel:
// everything that does not depend on d is computed once per texel (h.G t_k, h.G h, and the
// columns G t_0, G t_1, G t_2, G h side by side so that a.(each) is one pass over a), and a.G a
// is summed over G's non-zero entries directly (G a itself is not needed): the diagonal and the
// four symmetric pairs (0, 2), (1, 5), (2, 6), (3, 7) of basis functions with the same m. The same formulas
// as fit_direction; only the order of some additions differs (tested against it).
class HemiEvaluator {
public:
    HemiEvaluator(const Target& tg, Model model) : tg_(tg) {
        const Tables& tb = tables();
        const Vec9& h = model == Model::kHhd ? tb.hemi : tb.ambient;
        const Vec9& gh = model == Model::kHhd ? tb.g_hemi_hemi : tb.g_hemi_ambient;
        for (size_t j = 0; j < 9; ++j) {
            cols_[j][0] = V2d{tg.gt[0][j], tg.gt[1][j]};
            cols_[j][1] = V2d{tg.gt[2][j], gh[j]};
        }
        hgh_ = dot9(h, gh);
        for (size_t k = 0; k < 3; ++k) hgt_[k] = dot9(h, tg.gt[k]);
        // a.G a over G's non-zero entries: the diagonal, and each symmetric pair i < j once, doubled.
        for (int k = 0; k < tb.nnz; ++k) {
            const size_t i = tb.nz_i[static_cast<size_t>(k)], j = tb.nz_j[static_cast<size_t>(k)];
            const double g = tb.g_hemi[i * 9 + j];
            if (i == j) diag_[i] = g;
            if (i < j) pairs_[static_cast<size_t>(npairs_++)] = {i, j, 2 * g};
        }
    }
    Fit operator()(Vec3 d) const {
        Vec9 a = clamped_cosine_sh(d);
        const double inv_dz = 1.0 / d.z;
        for (double& v : a) v *= inv_dz;
        double aga = 0;
        for (size_t i = 0; i < 9; ++i) aga += diag_[i] * a[i] * a[i];
        for (int k = 0; k < npairs_; ++k) {
            const Pair& e = pairs_[static_cast<size_t>(k)];
            aga += e.g2 * a[e.i] * a[e.j];
        }
        // a.G t_0, a.G t_1 | a.G t_2, a.G h, two lanes each (SSE2-native vectors; each lane adds
        // in j order, as a scalar loop would).
        V2d d01 = {0, 0}, d23 = {0, 0};
        for (size_t j = 0; j < 9; ++j) d01 += a[j] * cols_[j][0], d23 += a[j] * cols_[j][1];
        const double agt[3] = {d01[0], d01[1], d23[0]};
        return fit_from_products(tg_, aga, d23[1], hgh_, agt, hgt_);
    }

private:
    struct Pair {
        size_t i, j;
        double g2;  // 2 G_ij
    };
    typedef double V2d __attribute__((vector_size(16)));
    const Target& tg_;
    V2d cols_[9][2];
    double hgh_ = 0, hgt_[3] = {};
    Vec9 diag_{};
    std::array<Pair, 36> pairs_{};
    int npairs_ = 0;
};

IrradZ make(const Target& tg, double w, Vec3 d) {
    IrradZ p;
    p.i_z = Rgb{static_cast<float>(tg.iz[0]), static_cast<float>(tg.iz[1]), static_cast<float>(tg.iz[2])};
    p.w_a = w;
    p.d = d;
    return p;
}


// ---- Newton solve (Solve::kNewton) ------------------------------------------------------------
//
// The colours collapse: sum_k |t_k - I_k m|_G^2 = C + S |m - u|_G^2 with S = sum_k I_k^2 and
// u = sum_k I_k t_k / S, so per texel the fit is one 9-vector problem. The direction is held in
// gnomonic coordinates q = (d_x, d_y) / d_z (theta <= 85 deg is the disk |q| <= tan 85) and
// s = 1 - w_a. With R = sqrt(1 + |q|^2) the model is m = h + s (a(q) - h), where a = C(d) / d_z:
//   a_0 = c0 R,  (a_1, a_2, a_3) = c1 (-q_y, 1, -q_x),  a_{4..8} = c2 Q_i(q_x, q_y, 1) / R
// (c0 = pi Y00, c1 = (2 pi / 3) kY1, c2 = pi / 4; Q_i the quadratic forms of the l = 2 basis).
// For fixed q the best s is closed form (clamped to [0, 1]); the reduced error psi(q) = min_s is
// minimised by Newton with the analytic gradient and Hessian (docs/irradz.md).
struct SparseGram {
    // G_hemi's non-zero entries: the diagonal and the pairs (0,2), (1,5), (2,6), (3,7).
    double d[9], g02, g15, g26, g37;
};
const SparseGram& sparse_gram() {
    static const SparseGram s = [] {
        const Mat9& g = tables().g_hemi;
        SparseGram r{};
        for (size_t i = 0; i < 9; ++i) r.d[i] = g[i * 10];
        r.g02 = g[0 * 9 + 2];
        r.g15 = g[1 * 9 + 5];
        r.g26 = g[2 * 9 + 6];
        r.g37 = g[3 * 9 + 7];
        return r;
    }();
    return s;
}
inline Vec9 gmul(const SparseGram& g, const Vec9& v) {
    return {g.d[0] * v[0] + g.g02 * v[2],
            g.d[1] * v[1] + g.g15 * v[5],
            g.d[2] * v[2] + g.g02 * v[0] + g.g26 * v[6],
            g.d[3] * v[3] + g.g37 * v[7],
            g.d[4] * v[4],
            g.d[5] * v[5] + g.g15 * v[1],
            g.d[6] * v[6] + g.g26 * v[2],
            g.d[7] * v[7] + g.g37 * v[3],
            g.d[8] * v[8]};
}

struct NewtonConst {
    double c0, c1, c2;
    double tan_max;  // tan(kMaxTheta): the disk |q| <= tan_max
};
const NewtonConst& newton_const() {
    static const NewtonConst c{kPi * kY00, (2.0 * kPi / 3.0) * kY1, kPi / 4.0, std::tan(kMaxTheta)};
    return c;
}

// The reduced problem of one texel: v = h - u, G v, v.G v.
struct Reduced {
    const SparseGram* g;     // sparse_gram() and newton_const(), fetched once per texel
    const NewtonConst* c;
    const Vec9* h;
    Vec9 v, gv, gh;          // v = h - u, G v, G h
    double vgv, hgv, hgh;    // v.G v, h.G v, h.G h
    bool hhd;
};

// psi(q) and, if wanted, its gradient and (reduced) Hessian.
struct PsiEval {
    double psi = 0, s = 0;
    double g[2] = {0, 0};
    double hxx = 0, hxy = 0, hyy = 0;
};

inline Vec9 model_a(const NewtonConst& c, double qx, double qy, double r, double ir) {
    return {c.c0 * r,
            -c.c1 * qy,
            c.c1,
            -c.c1 * qx,
            c.c2 * kY2 * qx * qy * ir,
            -c.c2 * kY2 * qy * ir,
            c.c2 * kY20 * (2 - qx * qx - qy * qy) * ir,
            -c.c2 * kY2 * qx * ir,
            c.c2 * kY22 * (qx * qx - qy * qy) * ir};
}

// r = sqrt(1 + |q|^2) = 1 / d_z and ir = 1 / r come from the caller (which has them without a
// square root or with one division).
template <bool kDerivatives>
PsiEval eval_psi(const Reduced& rd, double qx, double qy, double r, double ir) {
    const SparseGram& G = *rd.g;
    const NewtonConst& c = *rd.c;
    const Vec9 a = model_a(c, qx, qy, r, ir);
    Vec9 b, gb;
    double bgb, bgv;
    if constexpr (kDerivatives) {
        for (size_t i = 0; i < 9; ++i) b[i] = a[i] - (*rd.h)[i];
        gb = gmul(G, b);
        bgb = dot9(b, gb);
        bgv = dot9(gb, rd.v);
    } else {
        // psi alone: b.G b = a.G a - 2 a.G h + h.G h and b.G v = a.G v - h.G v, a.G a over G's
        // non-zero entries (the diagonal and the four pairs).
        double aga = 0;
        for (size_t i = 0; i < 9; ++i) aga += G.d[i] * a[i] * a[i];
        aga += 2 * (G.g02 * a[0] * a[2] + G.g15 * a[1] * a[5] + G.g26 * a[2] * a[6] + G.g37 * a[3] * a[7]);
        bgb = aga - 2 * dot9(a, rd.gh) + rd.hgh;
        bgv = dot9(a, rd.gv) - rd.hgv;
    }
    // s = 1 - w_a: the reference's w_a = num / den clamped (den = 0: w_a = 1).
    const double s_free = bgb > 0 ? -bgv / bgb : 0.0;
    const double s = std::clamp(s_free, 0.0, 1.0);
    PsiEval e;
    e.s = s;
    e.psi = rd.vgv + 2 * s * bgv + s * s * bgb;
    if constexpr (kDerivatives) {
        if (s <= 0) return e;  // w_a = 1: psi does not depend on q here (flat)
        Vec9 ge;  // G e, e = v + s b
        for (size_t i = 0; i < 9; ++i) ge[i] = rd.gv[i] + s * gb[i];
        // Q_i of the l = 2 basis and their derivatives (constants kY2, kY20, kY22 folded in).
        const double q4 = kY2 * qx * qy, q5 = -kY2 * qy, q6 = kY20 * (2 - qx * qx - qy * qy), q7 = -kY2 * qx,
                     q8 = kY22 * (qx * qx - qy * qy);
        const double q4x = kY2 * qy, q4y = kY2 * qx, q5y = -kY2, q6x = -2 * kY20 * qx, q6y = -2 * kY20 * qy,
                     q7x = -kY2, q8x = 2 * kY22 * qx, q8y = -2 * kY22 * qy;
        const double ir3 = ir * ir * ir;
        // da/dq_x, da/dq_y.
        Vec9 ax{}, ay{};
        ax[0] = c.c0 * qx * ir;
        ay[0] = c.c0 * qy * ir;
        ay[1] = -c.c1;
        ax[3] = -c.c1;
        const double qs[5] = {q4, q5, q6, q7, q8};
        const double qxs[5] = {q4x, 0, q6x, q7x, q8x}, qys[5] = {q4y, q5y, q6y, 0, q8y};
        for (size_t i = 0; i < 5; ++i) {
            ax[4 + i] = c.c2 * (qxs[i] * ir - qs[i] * qx * ir3);
            ay[4 + i] = c.c2 * (qys[i] * ir - qs[i] * qy * ir3);
        }
        const Vec9 gax = gmul(G, ax), gay = gmul(G, ay);
        const double axe = dot9(ax, ge), aye = dot9(ay, ge);
        e.g[0] = 2 * s * axe;
        e.g[1] = 2 * s * aye;
        // Second derivatives of a contracted with rho = G e: rho_0 c0 Hess(R) + c2 Hess(Qc / R),
        // Qc = sum_{i>=4} rho_i Q_i.
        const double* rho = ge.data();
        const double qc = rho[4] * q4 + rho[5] * q5 + rho[6] * q6 + rho[7] * q7 + rho[8] * q8;
        const double qcx = rho[4] * q4x + rho[6] * q6x + rho[7] * q7x + rho[8] * q8x;
        const double qcy = rho[4] * q4y + rho[5] * q5y + rho[6] * q6y + rho[8] * q8y;
        const double qcxx = -2 * kY20 * rho[6] + 2 * kY22 * rho[8], qcyy = -2 * kY20 * rho[6] - 2 * kY22 * rho[8],
                     qcxy = kY2 * rho[4];
        const double ir5 = ir3 * ir * ir;
        const double rxx = (1 - qx * qx * ir * ir) * ir, ryy = (1 - qy * qy * ir * ir) * ir, rxy = -qx * qy * ir3;
        const double sxx = qcxx * ir - 2 * qcx * qx * ir3 - qc * (ir3 - 3 * qx * qx * ir5);
        const double syy = qcyy * ir - 2 * qcy * qy * ir3 - qc * (ir3 - 3 * qy * qy * ir5);
        const double sxy = qcxy * ir - (qcx * qy + qcy * qx) * ir3 + qc * 3 * qx * qy * ir5;
        const double tx = rho[0] * c.c0, t2 = c.c2;
        e.hxx = 2 * s * s * dot9(ax, gax) + 2 * s * (tx * rxx + t2 * sxx);
        e.hyy = 2 * s * s * dot9(ay, gay) + 2 * s * (tx * ryy + t2 * syy);
        e.hxy = 2 * s * s * dot9(ax, gay) + 2 * s * (tx * rxy + t2 * sxy);
        if (s_free < 1) {
            // s interior: eliminate it (Schur complement of the (q, s) Hessian).
            const double hxs = 2 * axe + 2 * s * dot9(gax, b), hys = 2 * aye + 2 * s * dot9(gay, b), hss = 2 * bgb;
            e.hxx -= hxs * hxs / hss;
            e.hyy -= hys * hys / hss;
            e.hxy -= hxs * hys / hss;
        }
    }
    return e;
}

// psi and its derivatives in stereographic coordinates p of d: d = (2p, 1 - |p|^2) / (1 + |p|^2),
// q = 2p / (1 - |p|^2); theta <= 85 deg is the disk |p| <= tan(42.5 deg). q stretches the sphere
// without bound near the horizon; p keeps Newton well conditioned over the whole range.
// Chain rule: J = dq/dp = (2 / D) I + (4 / D^2) p p^T (D = 1 - |p|^2),
// sum_i g_i d2q_i/dp_j dp_k = (4 / D^2) (g_j p_k + g_k p_j + delta_jk g.p) + (16 / D^3) (g.p) p_j p_k.
// In p, with P = |p|^2: q = 2p / (1 - P), r = (1 + P) / (1 - P): one division, no square root.
template <bool kDerivatives>
PsiEval eval_psi_p(const Reduced& rd, double px, double py) {
    const double pp = px * px + py * py, dm = 1 - pp, dp = 1 + pp, inv = 1 / (dm * dp);
    const double id = dp * inv;  // 1 / (1 - P)
    PsiEval e = eval_psi<kDerivatives>(rd, 2 * px * id, 2 * py * id, dp * dp * inv, dm * dm * inv);
    if constexpr (kDerivatives) {
        if (e.s <= 0) return e;
        const double id2 = id * id;
        const double jxx = 2 * id + 4 * px * px * id2, jxy = 4 * px * py * id2, jyy = 2 * id + 4 * py * py * id2;
        const double gx = e.g[0], gy = e.g[1], gp = gx * px + gy * py;
        // H_p = J H_q J + the second-derivative term of q.
        const double mxx = e.hxx * jxx + e.hxy * jxy, mxy = e.hxx * jxy + e.hxy * jyy;
        const double myx = e.hxy * jxx + e.hyy * jxy, myy = e.hxy * jxy + e.hyy * jyy;
        const double c3 = 16 * gp * id2 * id;
        e.hxx = jxx * mxx + jxy * myx + 4 * id2 * (2 * gx * px + gp) + c3 * px * px;
        e.hxy = jxx * mxy + jxy * myy + 4 * id2 * (gx * py + gy * px) + c3 * px * py;
        e.hyy = jxy * mxy + jyy * myy + 4 * id2 * (2 * gy * py + gp) + c3 * py * py;
        e.g[0] = jxx * gx + jxy * gy;
        e.g[1] = jxy * gx + jyy * gy;
    }
    return e;
}

struct NewtonTables {
    double p_max;  // tan(kMaxTheta / 2): the rim in p
};
const NewtonTables& newton_tables() {
    static const NewtonTables t{std::tan(kMaxTheta / 2)};
    return t;
}

// Start: match the model's L0 and L1 to u exactly (the linear-SH closed form of the reduced
// problem). HHD: the L1 z component is fixed (c1), s q = beta = -(u_3, u_1) / c1 and
// c0 sqrt(s^2 + |beta|^2) - 2 c0 s = u_0 - 2 c0. AHD: s = u_2 / c1. Returned in p.
void newton_start(const Reduced& rd, double* px, double* py) {
    const NewtonConst& c = newton_const();
    Vec9 u;
    for (size_t i = 0; i < 9; ++i) u[i] = (*rd.h)[i] - rd.v[i];
    const double bx = -u[3] / c.c1, by = -u[1] / c.c1, b2 = bx * bx + by * by;
    double s;
    if (rd.hhd) {
        const double kappa = (u[0] - 2 * c.c0) / c.c0;
        s = (-2 * kappa + std::sqrt(kappa * kappa + 3 * b2)) / 3;
    } else {
        s = u[2] / c.c1;
    }
    s = std::clamp(std::isfinite(s) ? s : 1.0, 0.05, 1.0);
    double qx = bx / s, qy = by / s;
    if (!std::isfinite(qx) || !std::isfinite(qy)) qx = qy = 0;
    // p = q / (1 + sqrt(1 + |q|^2)) (tan(theta / 2) from tan(theta)), clamped to the rim.
    const double k = 1 / (1 + std::sqrt(1 + qx * qx + qy * qy));
    *px = qx * k;
    *py = qy * k;
    const double len = std::sqrt(*px * *px + *py * *py), pmax = newton_tables().p_max;
    if (len > pmax) {
        *px *= pmax / len;
        *py *= pmax / len;
    }
}

// Damped Newton on psi(p) inside the disk |p| <= p_max. Where the Hessian is not positive definite
// it is shifted until it is; a step that does not lower psi is halved (psi has kinks where s reaches
// its bounds). On the rim with the descent pointing outwards, the step runs along the rim (1-D
// Newton in arc length, with the rim's curvature term). A step shorter than `tolerance` (in p; 1e-4
// is about 2e-4 rad) is taken without checking and ends the solve: Newton converges quadratically,
// so what remains after it is of order tolerance^2.
void newton_iterate(const Reduced& rd, double& px, double& py, int iterations, double tolerance) {
    const double pmax = newton_tables().p_max;
    PsiEval cur = eval_psi_p<true>(rd, px, py);
    for (int it = 0; it < iterations; ++it) {
        if (cur.s <= 0) break;  // w_a = 1: psi is flat here
        const double hxx = cur.hxx, hyy = cur.hyy, hxy = cur.hxy;
        const double tr = hxx + hyy, disc = std::sqrt((hxx - hyy) * (hxx - hyy) + 4 * hxy * hxy);
        const double lmin = (tr - disc) / 2, lmax = std::max(std::abs((tr + disc) / 2), 1e-300);
        const double len = std::sqrt(px * px + py * py);
        const bool rim = len >= pmax * (1 - 1e-12) && cur.g[0] * px + cur.g[1] * py < 0;
        // The step: (dx, dy) in the disk, or an angle along the rim; at most kMaxStep long (a trust
        // region: an indefinite Hessian's shifted step can be arbitrarily long).
        constexpr double kMaxStep = 0.25;
        double dx = 0, dy = 0, dalpha = 0;
        if (rim) {
            const double tx = -py / len, ty = px / len;
            const double gt = cur.g[0] * tx + cur.g[1] * ty, gr = (cur.g[0] * px + cur.g[1] * py) / len;
            const double ht = tx * tx * hxx + 2 * tx * ty * hxy + ty * ty * hyy - gr / len;
            dalpha = std::clamp(-gt / std::max(ht, 1e-9 * lmax) / len, -kMaxStep / len, kMaxStep / len);
            // A saddle on the rim (symmetric targets): leave it along the rim.
            if (ht < 0 && std::abs(gt) <= 1e-6 * -ht) dalpha = gt > 0 ? -kMaxStep / len : kMaxStep / len;
            if (!std::isfinite(dalpha)) break;
        } else {
            const double shift = std::max(0.0, 1e-9 * lmax - lmin);
            const double axx = hxx + shift, ayy = hyy + shift, det = axx * ayy - hxy * hxy;
            dx = -(ayy * cur.g[0] - hxy * cur.g[1]) / det;
            dy = -(axx * cur.g[1] - hxy * cur.g[0]) / det;
            if (!std::isfinite(dx) || !std::isfinite(dy)) break;
            if (lmin < -1e-9 * lmax && std::abs(cur.g[0]) + std::abs(cur.g[1]) <= 1e-6 * -lmin) {
                // A saddle (symmetric targets: zero L1, pure L2): leave along the eigenvector of
                // the negative eigenvalue, downhill if the gradient tells, else towards +.
                double vx = hxy, vy = lmin - hxx;
                if (std::abs(vx) + std::abs(vy) < 1e-12 * lmax) vx = lmin - hyy, vy = hxy;
                if (std::abs(vx) + std::abs(vy) < 1e-12 * lmax) vx = 1, vy = 0;
                const double vl = std::sqrt(vx * vx + vy * vy), sg = vx * cur.g[0] + vy * cur.g[1] > 0 ? -1.0 : 1.0;
                dx = sg * kMaxStep * vx / vl;
                dy = sg * kMaxStep * vy / vl;
            }
            const double l = std::sqrt(dx * dx + dy * dy);
            if (l > kMaxStep) dx *= kMaxStep / l, dy *= kMaxStep / l;
        }
        auto trial = [&](double t, double* nx, double* ny) {
            if (rim) {
                const double c = std::cos(t * dalpha), s = std::sin(t * dalpha);
                *nx = c * px - s * py;
                *ny = s * px + c * py;
                return;
            }
            *nx = px + t * dx;
            *ny = py + t * dy;
            const double l = std::sqrt(*nx * *nx + *ny * *ny);
            if (l > pmax) {
                *nx *= pmax / l;
                *ny *= pmax / l;
            }
        };
        double nx, ny;
        if (dx * dx + dy * dy + dalpha * dalpha * len * len <= tolerance * tolerance) {
            trial(1, &nx, &ny);
            px = nx;
            py = ny;
            break;
        }
        bool accepted = false;
        for (double t = 1; t > 1.0 / 64; t /= 2) {
            trial(t, &nx, &ny);
            const PsiEval next = eval_psi_p<true>(rd, nx, ny);
            if (next.psi < cur.psi) {
                px = nx;
                py = ny;
                cur = next;
                accepted = true;
                break;
            }
        }
        if (!accepted) break;
    }
}

// The texel as the Newton solve needs it: t_k and I_k only (no Gram products).
struct Texel {
    std::array<Vec9, 3> t{};
    std::array<double, 3> iz{};
};
Texel make_texel(const Sh3Irradiance& irr, const Rgb* sampled_iz) {
    const Tables& tb = tables();
    Texel x;
    for (size_t k = 0; k < 3; ++k) {
        for (size_t i = 0; i < 9; ++i) x.t[k][i] = irr[static_cast<int>(i)][static_cast<int>(k)];
        // The same I_z as make_target (the reference).
        x.iz[k] = std::max(0.0, sampled_iz ? double((*sampled_iz)[static_cast<int>(k)]) : dot9(x.t[k], tb.y_up));
    }
    return x;
}

Reduced make_reduced(const Texel& x, Model model) {
    const Tables& tb = tables();
    const double s2 = x.iz[0] * x.iz[0] + x.iz[1] * x.iz[1] + x.iz[2] * x.iz[2];
    Reduced rd;
    rd.g = &sparse_gram();
    rd.c = &newton_const();
    rd.hhd = model == Model::kHhd;
    rd.h = rd.hhd ? &tb.hemi : &tb.ambient;
    for (size_t i = 0; i < 9; ++i) {
        const double u = s2 > 0 ? (x.iz[0] * x.t[0][i] + x.iz[1] * x.t[1][i] + x.iz[2] * x.t[2][i]) / s2 : 0.0;
        rd.v[i] = (*rd.h)[i] - u;
    }
    rd.gv = gmul(sparse_gram(), rd.v);
    rd.vgv = dot9(rd.v, rd.gv);
    rd.gh = gmul(sparse_gram(), *rd.h);
    rd.hgv = dot9(*rd.h, rd.gv);
    rd.hgh = dot9(*rd.h, rd.gh);
    return rd;
}
}  // namespace
ReducedError reduced_error(const Sh3Irradiance& target, Model model, double qx, double qy, const Rgb* sampled_iz) {
    const Reduced rd = make_reduced(make_texel(target, sampled_iz), model);
    const double rr = std::sqrt(1 + qx * qx + qy * qy);
    const PsiEval e = eval_psi<true>(rd, qx, qy, rr, 1 / rr);
    ReducedError r;
    r.psi = e.psi;
    r.s = e.s;
    r.grad[0] = e.g[0];
    r.grad[1] = e.g[1];
    r.hess[0] = e.hxx;
    r.hess[1] = e.hxy;
    r.hess[2] = e.hyy;
    return r;
}
namespace {
IrradZ fit_newton(const Sh3Irradiance& irr, Model model, const EncodeOptions& options, double* error,
                  const Rgb* sampled_iz) {
    const Texel x = make_texel(irr, sampled_iz);
    const Reduced rd = make_reduced(x, model);
    const double s2 = x.iz[0] * x.iz[0] + x.iz[1] * x.iz[1] + x.iz[2] * x.iz[2];
    Vec3 d{0, 0, 1};
    if (s2 > 0) {
        double px = 0, py = 0;
        newton_start(rd, &px, &py);
        // The best of four starts: the closed form, straight up (theta = 0) and the rim (theta = 85
        // deg) at the closed form's azimuth and opposite it (the reference scans theta from 0 to 85
        // deg; symmetric targets have their best direction on either side). A start where psi is flat (s = 0, w_a = 1) would
        // stop Newton at once; theta = 0 mostly avoids it, a ring of directions does the rest.
        const PsiEval e0 = eval_psi_p<false>(rd, px, py);
        double best = e0.psi, best_s = e0.s;
        const double len = std::sqrt(px * px + py * py), pmax = newton_tables().p_max;
        const double rx = len > 0 ? px / len * pmax : pmax, ry = len > 0 ? py / len * pmax : 0.0;
        const double starts[3][2] = {{0, 0}, {rx, ry}, {-rx, -ry}};
        for (const auto& st : starts) {
            const PsiEval e = eval_psi_p<false>(rd, st[0], st[1]);
            if (e.psi < best) best = e.psi, best_s = e.s, px = st[0], py = st[1];
        }
        if (!(best_s > 0)) {
            // All three starts where psi is flat (s = 0: the best w_a is 1 there, symmetric targets
            // such as pure L2): a coarse ring of directions (theta 30, 60, 85 deg x 8 azimuths).
            for (int i = 1; i <= 3; ++i)
                for (int j = 0; j < 8; ++j) {
                    const double r = std::tan((i < 3 ? i * kPi / 6 : kMaxTheta) / 2), ph = j * kPi / 4;
                    const double x = r * std::cos(ph), y = r * std::sin(ph);
                    const PsiEval e = eval_psi_p<false>(rd, x, y);
                    if (e.psi < best && e.s > 0) best = e.psi, px = x, py = y;
                }
        }
        newton_iterate(rd, px, py, options.newton_iterations, options.newton_tolerance);
        const double r2 = px * px + py * py;
        d = clamp_to_hemisphere(Vec3{2 * px, 2 * py, 1 - r2});
    }
    // w_a = 1 - s at the returned direction, and the error of the result, from the residuals
    // r_k = t_k - I_k m (no cancellation): m = h + s (a - h).
    const double qx = d.x / d.z, qy = d.y / d.z, r = std::sqrt(1 + qx * qx + qy * qy);
    const Vec9 a = model_a(*rd.c, qx, qy, r, 1 / r);
    const double s = s2 > 0 ? eval_psi<false>(rd, qx, qy, r, 1 / r).s : 0.0;
    if (error) {
        const SparseGram& g = sparse_gram();
        double e = 0;
        for (size_t k = 0; k < 3; ++k) {
            Vec9 res;
            for (size_t i = 0; i < 9; ++i) res[i] = x.t[k][i] - x.iz[k] * ((*rd.h)[i] + s * (a[i] - (*rd.h)[i]));
            e += dot9(res, gmul(g, res));
        }
        *error = e;
    }
    IrradZ p;
    p.i_z = Rgb{static_cast<float>(x.iz[0]), static_cast<float>(x.iz[1]), static_cast<float>(x.iz[2])};
    p.w_a = 1 - s;
    p.d = d;
    return p;
}

}  // namespace

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

IrradZ solve_w_a(const Sh3Irradiance& target, Vec3 d, Model model, const std::array<double, 81>& gram) {
    const Target tg = make_target(target, gram);
    d = clamp_to_hemisphere(d);
    return make(tg, fit_direction(tg, d, model, gram).w, d);
}

IrradZ encode(const Sh3Radiance& tangent_radiance, const EncodeOptions& options, double* error,
              const Rgb* sampled_iz) {
    const Sh3Irradiance irr = to_irradiance(tangent_radiance);
    if (options.solve == Solve::kNewton) return fit_newton(irr, options.model, options, error, sampled_iz);
    const Tables& tb = tables();
    // Optimal linear direction of the luminance L1 band (also the azimuth of the search plane).
    const LuminanceWeights& lw = options.luminance;
    Vec3 old_dir;
    const bool has_dir =
        optimal_linear_direction(luminance(irr[1], lw), luminance(irr[2], lw), luminance(irr[3], lw), &old_dir);
    if (!has_dir) old_dir = {0, 0, 1};

    if (options.solve == Solve::kOld) {
        const Target tg = make_target(irr, tb.g_sphere, sampled_iz);
        const Vec3 d = clamp_to_hemisphere(old_dir);
        const IrradZ p = make(tg, fit_direction(tg, d, options.model, tb.g_sphere).w, d);
        if (error) *error = sh_hemispherical_error(irr, p, options.model);
        return p;
    }


    // Search (talk): the hemisphere term only adds to the z component of L1, so the azimuth of the
    // optimal linear direction is kept and theta is searched in [0, kMaxTheta]. A coarse scan of
    // `scan_steps` samples brackets the best theta (the error need not be unimodal over the whole
    // range), then golden-section search refines inside [theta_{j-1}, theta_{j+1}].
    const Target tg = make_target(irr, tb.g_hemi, sampled_iz);
    double phi = std::hypot(old_dir.x, old_dir.y) > 1e-12 ? std::atan2(old_dir.y, old_dir.x) : 0.0;
    double theta = 0;
    const HemiEvaluator fit_at(tg, options.model);
    // direction_from_angles(th, ph) with the fixed angle's sine and cosine computed once per search
    // (the same products, so the same directions).
    auto over_theta = [&](double ph) {
        const double cp = std::cos(ph), sp = std::sin(ph);
        return [&fit_at, cp, sp](double th) {
            const double st = std::sin(th);
            return fit_at(Vec3{st * cp, st * sp, std::cos(th)});
        };
    };
    auto over_phi = [&](double th) {
        const double st = std::sin(th), ct = std::cos(th);
        return [&fit_at, st, ct](double ph) { return fit_at(Vec3{st * std::cos(ph), st * std::sin(ph), ct}); };
    };
    const int steps = std::max(2, options.scan_steps);
    auto scan = over_theta(phi);
    Fit best = scan(0.0);
    for (int j = 1; j < steps; ++j) {
        const double th = kMaxTheta * j / (steps - 1);
        const Fit f = scan(th);
        if (f.err < best.err) {
            best = f;
            theta = th;
        }
    }
    // Golden-section search for the minimum of err over [lo, hi]; keeps the best point seen.
    auto golden = [&](double lo, double hi, auto&& f_of, double& arg) {
        const double inv_phi = (std::sqrt(5.0) - 1.0) / 2.0;  // 1 / golden ratio
        double x1 = hi - inv_phi * (hi - lo), x2 = lo + inv_phi * (hi - lo);
        Fit f1 = f_of(x1), f2 = f_of(x2);
        for (int it = 0; it < options.golden_iterations; ++it) {
            if (f1.err < f2.err) {
                hi = x2, x2 = x1, f2 = f1;
                x1 = hi - inv_phi * (hi - lo);
                f1 = f_of(x1);
            } else {
                lo = x1, x1 = x2, f1 = f2;
                x2 = lo + inv_phi * (hi - lo);
                f2 = f_of(x2);
            }
        }
        if (f1.err < best.err) best = f1, arg = x1;
        if (f2.err < best.err) best = f2, arg = x2;
    };
    const double step = kMaxTheta / (steps - 1);
    golden(std::max(0.0, theta - step), std::min(kMaxTheta, theta + step), over_theta(phi), theta);
    // Refinement beyond the talk: with higher-band energy the best azimuth moves away from the L1
    // azimuth, so alternate a phi search (bracket +-45 degrees) and a theta search (+-1 scan step).
    for (int round = 0; round < options.azimuth_rounds && theta > 1e-6; ++round) {
        golden(phi - kPi / 4, phi + kPi / 4, over_phi(theta), phi);
        golden(std::max(0.0, theta - step), std::min(kMaxTheta, theta + step), over_theta(phi), theta);
    }
    const IrradZ p = make(tg, best.w, direction_from_angles(theta, phi));
    if (error) *error = best.err;
    return p;
}

// ---- linear SH <-> HHD ----------------------------------------------------------------------

Sh2Radiance hhd_to_linear_sh(const Lighting& l) {
    // Radiance: C_a over the hemisphere z >= 0 plus a delta of integral pi C_d along d.
    //  l0 = C_a * sqrt(pi) + pi C_d / (2 sqrt(pi)) = sqrt(pi) (C_a + C_d / 2)
    //  L1 = kY1 * V swizzled, V = pi (C_a n_v + C_d d) (integral of w over the hemisphere is pi n_v).
    Sh2Radiance sh;
    for (int k = 0; k < 3; ++k) {
        const double ca = l.c_a[k], cd = l.c_d[k];
        const Vec3 v = kPi * (Vec3{0, 0, ca} + cd * l.d);
        sh[0][k] = static_cast<float>(std::sqrt(kPi) * (ca + cd / 2));
        sh[1][k] = static_cast<float>(-kY1 * v.y);
        sh[2][k] = static_cast<float>(kY1 * v.z);
        sh[3][k] = static_cast<float>(-kY1 * v.x);
    }
    return sh;
}
Sh2Radiance irradz_to_linear_sh(const IrradZ& p) { return hhd_to_linear_sh(to_lighting(p)); }

ChannelHhd linear_sh_to_hhd_channel(double l0, double l1m1, double l10, double l1p1) {
    // b_c = 2 l0 / sqrt(pi) = 2 C_a + C_d;  b = L1 / (kY1 pi) = C_a n_v + C_d d.
    const double s = 1.0 / (kY1 * kPi);  // = 2 / sqrt(3 pi)
    const double bc = 2.0 * l0 / std::sqrt(kPi);
    const Vec3 b{-l1p1 * s, -l1m1 * s, l10 * s};
    const double iz = b.z;  // I_z = b . n_v
    // |b - C_a n_v|^2 = (b_c - 2 C_a)^2  =>  3 C_a^2 - 2 (2 b_c - I_z) C_a + (b_c^2 - |b|^2) = 0;
    // the smaller root is C_a for every valid HHD (the other is C_a + C_d (4 - 2 d_z) / 3).
    const double q = 2 * bc - iz;
    const double disc = std::max(0.0, q * q - 3 * (bc * bc - dot(b, b)));
    ChannelHhd h;
    h.c_a = std::max(0.0, (q - std::sqrt(disc)) / 3);
    const Vec3 v = b - Vec3{0, 0, h.c_a};
    h.c_d = length(v);
    h.d = h.c_d > 1e-30 ? (1.0 / h.c_d) * v : Vec3{0, 0, 1};
    return h;
}

IrradZ linear_sh_to_irradz(const Sh2Radiance& sh, const LuminanceWeights& w) {
    const ChannelHhd lum =
        linear_sh_to_hhd_channel(luminance(sh[0], w), luminance(sh[1], w), luminance(sh[2], w), luminance(sh[3], w));
    const double s = 1.0 / (kY1 * kPi);
    IrradZ p;
    for (int k = 0; k < 3; ++k) p.i_z[k] = static_cast<float>(std::max(0.0, double(sh[2][k]) * s));
    const double iz_lum = luminance(sh[2], w) * s;
    p.d = clamp_to_hemisphere(lum.d);
    p.w_a = iz_lum > 0 ? std::clamp(lum.c_a / iz_lum, 0.0, 1.0) : 1.0;
    return p;
}

IrradZ blend_linear_sh(std::span<const IrradZ> texels, std::span<const double> weights) {
    double acc[4][3] = {};
    for (size_t t = 0; t < texels.size() && t < weights.size(); ++t) {
        const Sh2Radiance sh = irradz_to_linear_sh(texels[t]);
        for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k) acc[i][k] += weights[t] * sh[i][k];
    }
    Sh2Radiance sum;
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) sum[i][k] = static_cast<float>(acc[i][k]);
    return linear_sh_to_irradz(sum);
}

IrradZ blend_parameters(std::span<const IrradZ> texels, std::span<const double> weights) {
    double iz[3] = {}, wa = 0, wsum = 0;
    Vec3 d{0, 0, 0};
    for (size_t t = 0; t < texels.size() && t < weights.size(); ++t) {
        for (int k = 0; k < 3; ++k) iz[k] += weights[t] * texels[t].i_z[k];
        wa += weights[t] * texels[t].w_a;
        wsum += weights[t];
        d = d + weights[t] * texels[t].d;
    }
    IrradZ p;
    for (int k = 0; k < 3; ++k) p.i_z[k] = static_cast<float>(iz[k]);
    p.w_a = wsum > 0 ? std::clamp(wa / wsum, 0.0, 1.0) : 1.0;
    p.d = clamp_to_hemisphere(d);
    return p;
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
