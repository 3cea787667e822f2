// zhc/codec/lightmap/irradz_newton.cpp — the Newton solve of the IrradZ direction (Solve::kNewton,
// the default): the colours collapse to one 9-vector problem, w_a is eliminated in closed form, and
// the reduced error psi is minimised by damped Newton with its analytic gradient and Hessian in
// stereographic coordinates, from the best of four starts (the linear-SH closed form, straight up,
// the rim). zhc's own derivation, docs/irradz.md ("The Newton solve of d").
//
// Source: Roughton, "IrradZ" (SIGGRAPH 2024 Advances in Real-Time Rendering talk);
// the slide formulas are re-derived in docs/irradz.md.
#include "codec/lightmap/irradz.h"

#include <algorithm>
#include <cmath>

#include "codec/lightmap/irradz_internal.h"

namespace zhc::irradz {
namespace {

using namespace detail;  // irradz_internal.h

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

IrradZ detail::fit_newton(const Sh3Irradiance& irr, Model model, const EncodeOptions& options, double* error,
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

}  // namespace zhc::irradz
