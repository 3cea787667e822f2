// zhc/codec/lightmap/irradz_newton_solve.inl — the Newton solve of irradz_newton.cpp, included there
// twice: in namespace isa_baseline (x86-64 baseline: SSE2) and isa_avx2 (compiled for AVX2, chosen at
// run time where the CPU has it). Both compute the same floats: IEEE operations per lane, no FMA
// (zhc_codec is built with -ffp-contract=off and the AVX2 target does not enable FMA).
// No include guard: included inside namespaces.

// ---- one source for one texel (double) and four texels at a time (V4) ---------------------------
//
// The evaluation of psi below is written once over the number type T: double for one texel, V4 (a
// GCC vector of four doubles) for four texels in the lanes of one vector. Each lane performs the
// operations of the scalar path in the same order (IEEE add, multiply and divide are exact per lane;
// zhc_codec is built with -ffp-contract=off, so nothing is fused), and branches become selects, so a
// lane's result is the scalar result bit for bit (tests/test_irradz_newton.cpp checks it).
// Everything here is internal to this file, so GCC's note that a 32-byte vector passed without AVX
// has another ABI than with it does not concern any interface.
#pragma GCC diagnostic ignored "-Wpsabi"
using V4 = double __attribute__((vector_size(32)));
using M4 = decltype(V4{} < V4{});  // a comparison's lane masks
inline double sel(bool m, double a, double b) { return m ? a : b; }
inline V4 sel(M4 m, V4 a, V4 b) { return m ? a : b; }
template <class T>
using Arr9 = std::array<T, 9>;

template <class T, class U>
inline T dot9t(const Arr9<T>& a, const Arr9<U>& b) {
    T s{};
    for (size_t i = 0; i < 9; ++i) s += a[i] * b[i];
    return s;
}

template <class T>
inline Arr9<T> gmul(const SparseGram& g, const Arr9<T>& v) {
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

// The reduced problem of one texel (T = double) or four (T = V4): v = h - u, G v, v.G v.
template <class T>
struct ReducedT {
    const SparseGram* g;     // sparse_gram() and newton_const(), fetched once per texel
    const NewtonConst* c;
    const Vec9* h;           // the model's constant term (the same for every lane)
    Arr9<T> v, gv, gh;       // v = h - u, G v, G h
    T vgv, hgv, hgh;         // v.G v, h.G v, h.G h
    bool hhd;
};
using Reduced = ReducedT<double>;

// psi(q) and, if wanted, its gradient and (reduced) Hessian.
template <class T>
struct PsiEvalT {
    T psi{}, s{};
    T g[2] = {T{}, T{}};
    T hxx{}, hxy{}, hyy{};
};
using PsiEval = PsiEvalT<double>;

template <class T>
inline Arr9<T> model_a(const NewtonConst& c, const T& qx, const T& qy, const T& r, const T& ir) {
    return {c.c0 * r,
            -c.c1 * qy,
            T{} + c.c1,
            -c.c1 * qx,
            c.c2 * kY2 * qx * qy * ir,
            -c.c2 * kY2 * qy * ir,
            c.c2 * kY20 * (2 - qx * qx - qy * qy) * ir,
            -c.c2 * kY2 * qx * ir,
            c.c2 * kY22 * (qx * qx - qy * qy) * ir};
}

// r = sqrt(1 + |q|^2) = 1 / d_z and ir = 1 / r come from the caller (which has them without a
// square root or with one division).
template <bool kDerivatives, class T>
PsiEvalT<T> eval_psi(const ReducedT<T>& rd, const T& qx, const T& qy, const T& r, const T& ir) {
    constexpr bool kScalar = std::is_same_v<T, double>;
    const SparseGram& G = *rd.g;
    const NewtonConst& c = *rd.c;
    const Arr9<T> a = model_a<T>(c, qx, qy, r, ir);
    Arr9<T> b, gb;
    T bgb, bgv;
    if constexpr (kDerivatives) {
        for (size_t i = 0; i < 9; ++i) b[i] = a[i] - (*rd.h)[i];
        gb = gmul(G, b);
        bgb = dot9t(b, gb);
        bgv = dot9t(gb, rd.v);
    } else {
        // psi alone: b.G b = a.G a - 2 a.G h + h.G h and b.G v = a.G v - h.G v, a.G a over G's
        // non-zero entries (the diagonal and the four pairs).
        T aga{};
        for (size_t i = 0; i < 9; ++i) aga += G.d[i] * a[i] * a[i];
        aga += 2 * (G.g02 * a[0] * a[2] + G.g15 * a[1] * a[5] + G.g26 * a[2] * a[6] + G.g37 * a[3] * a[7]);
        bgb = aga - 2 * dot9t(a, rd.gh) + rd.hgh;
        bgv = dot9t(a, rd.gv) - rd.hgv;
    }
    // s = 1 - w_a: the reference's w_a = num / den clamped (den = 0: w_a = 1).
    const T zero{}, one = zero + 1.0;
    const T s_free = sel(bgb > 0, -bgv / bgb, zero);
    const T s = sel(s_free < 0, zero, sel(1 < s_free, one, s_free));  // std::clamp(s_free, 0, 1)
    PsiEvalT<T> e;
    e.s = s;
    e.psi = rd.vgv + 2 * s * bgv + s * s * bgb;
    if constexpr (kDerivatives) {
        if constexpr (kScalar) {
            if (s <= 0) return e;  // w_a = 1: psi does not depend on q here (flat)
        }
        Arr9<T> ge;  // G e, e = v + s b
        for (size_t i = 0; i < 9; ++i) ge[i] = rd.gv[i] + s * gb[i];
        // Q_i of the l = 2 basis and their derivatives (constants kY2, kY20, kY22 folded in).
        const T q4 = kY2 * qx * qy, q5 = -kY2 * qy, q6 = kY20 * (2 - qx * qx - qy * qy), q7 = -kY2 * qx,
                q8 = kY22 * (qx * qx - qy * qy);
        const T q4x = kY2 * qy, q4y = kY2 * qx, q5y = zero - kY2, q6x = -2 * kY20 * qx, q6y = -2 * kY20 * qy,
                q7x = zero - kY2, q8x = 2 * kY22 * qx, q8y = -2 * kY22 * qy;
        const T ir3 = ir * ir * ir;
        // da/dq_x, da/dq_y.
        Arr9<T> ax{}, ay{};
        ax[0] = c.c0 * qx * ir;
        ay[0] = c.c0 * qy * ir;
        ay[1] = zero - c.c1;
        ax[3] = zero - c.c1;
        const T qs[5] = {q4, q5, q6, q7, q8};
        const T qxs[5] = {q4x, zero, q6x, q7x, q8x}, qys[5] = {q4y, q5y, q6y, zero, q8y};
        for (size_t i = 0; i < 5; ++i) {
            ax[4 + i] = c.c2 * (qxs[i] * ir - qs[i] * qx * ir3);
            ay[4 + i] = c.c2 * (qys[i] * ir - qs[i] * qy * ir3);
        }
        const Arr9<T> gax = gmul(G, ax), gay = gmul(G, ay);
        const T axe = dot9t(ax, ge), aye = dot9t(ay, ge);
        T g0 = 2 * s * axe, g1 = 2 * s * aye;
        // Second derivatives of a contracted with rho = G e: rho_0 c0 Hess(R) + c2 Hess(Qc / R),
        // Qc = sum_{i>=4} rho_i Q_i.
        const T* rho = ge.data();
        const T qc = rho[4] * q4 + rho[5] * q5 + rho[6] * q6 + rho[7] * q7 + rho[8] * q8;
        const T qcx = rho[4] * q4x + rho[6] * q6x + rho[7] * q7x + rho[8] * q8x;
        const T qcy = rho[4] * q4y + rho[5] * q5y + rho[6] * q6y + rho[8] * q8y;
        const T qcxx = -2 * kY20 * rho[6] + 2 * kY22 * rho[8], qcyy = -2 * kY20 * rho[6] - 2 * kY22 * rho[8],
                qcxy = kY2 * rho[4];
        const T ir5 = ir3 * ir * ir;
        const T rxx = (1 - qx * qx * ir * ir) * ir, ryy = (1 - qy * qy * ir * ir) * ir, rxy = -qx * qy * ir3;
        const T sxx = qcxx * ir - 2 * qcx * qx * ir3 - qc * (ir3 - 3 * qx * qx * ir5);
        const T syy = qcyy * ir - 2 * qcy * qy * ir3 - qc * (ir3 - 3 * qy * qy * ir5);
        const T sxy = qcxy * ir - (qcx * qy + qcy * qx) * ir3 + qc * 3 * qx * qy * ir5;
        const T tx = rho[0] * c.c0;
        const double t2 = c.c2;
        T hxx = 2 * s * s * dot9t(ax, gax) + 2 * s * (tx * rxx + t2 * sxx);
        T hyy = 2 * s * s * dot9t(ay, gay) + 2 * s * (tx * ryy + t2 * syy);
        T hxy = 2 * s * s * dot9t(ax, gay) + 2 * s * (tx * rxy + t2 * sxy);
        // s interior: eliminate it (Schur complement of the (q, s) Hessian).
        const T hxs = 2 * axe + 2 * s * dot9t(gax, b), hys = 2 * aye + 2 * s * dot9t(gay, b), hss = 2 * bgb;
        const auto interior = s_free < 1;
        hxx = sel(interior, hxx - hxs * hxs / hss, hxx);
        hyy = sel(interior, hyy - hys * hys / hss, hyy);
        hxy = sel(interior, hxy - hxs * hys / hss, hxy);
        if constexpr (!kScalar) {
            const M4 flat = s <= 0;
            g0 = sel(flat, zero, g0), g1 = sel(flat, zero, g1);
            hxx = sel(flat, zero, hxx), hyy = sel(flat, zero, hyy), hxy = sel(flat, zero, hxy);
        }
        e.g[0] = g0;
        e.g[1] = g1;
        e.hxx = hxx;
        e.hyy = hyy;
        e.hxy = hxy;
    }
    return e;
}

// psi and its derivatives in stereographic coordinates p of d: d = (2p, 1 - |p|^2) / (1 + |p|^2),
// q = 2p / (1 - |p|^2); theta <= 85 deg is the disk |p| <= tan(42.5 deg). q stretches the sphere
// without bound near the horizon; p keeps Newton well conditioned over the whole range.
// Chain rule: J = dq/dp = (2 / D) I + (4 / D^2) p p^T (D = 1 - |p|^2),
// sum_i g_i d2q_i/dp_j dp_k = (4 / D^2) (g_j p_k + g_k p_j + delta_jk g.p) + (16 / D^3) (g.p) p_j p_k.
// In p, with P = |p|^2: q = 2p / (1 - P), r = (1 + P) / (1 - P): one division, no square root.
template <bool kDerivatives, class T>
PsiEvalT<T> eval_psi_p(const ReducedT<T>& rd, const T& px, const T& py) {
    const T pp = px * px + py * py, dm = 1 - pp, dp = 1 + pp, inv = 1 / (dm * dp);
    const T id = dp * inv;  // 1 / (1 - P)
    const PsiEvalT<T> e0 = eval_psi<kDerivatives, T>(rd, 2 * px * id, 2 * py * id, dp * dp * inv, dm * dm * inv);
    PsiEvalT<T> e = e0;
    if constexpr (kDerivatives) {
        if constexpr (std::is_same_v<T, double>) {
            if (e.s <= 0) return e;
        }
        const T id2 = id * id;
        const T jxx = 2 * id + 4 * px * px * id2, jxy = 4 * px * py * id2, jyy = 2 * id + 4 * py * py * id2;
        const T gx = e.g[0], gy = e.g[1], gp = gx * px + gy * py;
        // H_p = J H_q J + the second-derivative term of q.
        const T mxx = e.hxx * jxx + e.hxy * jxy, mxy = e.hxx * jxy + e.hxy * jyy;
        const T myx = e.hxy * jxx + e.hyy * jxy, myy = e.hxy * jxy + e.hyy * jyy;
        const T c3 = 16 * gp * id2 * id;
        e.hxx = jxx * mxx + jxy * myx + 4 * id2 * (2 * gx * px + gp) + c3 * px * px;
        e.hxy = jxx * mxy + jxy * myy + 4 * id2 * (gx * py + gy * px) + c3 * px * py;
        e.hyy = jxy * mxy + jyy * myy + 4 * id2 * (2 * gy * py + gp) + c3 * py * py;
        e.g[0] = jxx * gx + jxy * gy;
        e.g[1] = jxy * gx + jyy * gy;
        if constexpr (!std::is_same_v<T, double>) {
            const M4 flat = e0.s <= 0;
            e.hxx = sel(flat, e0.hxx, e.hxx), e.hxy = sel(flat, e0.hxy, e.hxy), e.hyy = sel(flat, e0.hyy, e.hyy);
            e.g[0] = sel(flat, e0.g[0], e.g[0]), e.g[1] = sel(flat, e0.g[1], e.g[1]);
        }
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
//
// Written as a state machine that asks for one evaluation of psi at a time (`want` = true: at
// (nx, ny)) and takes its result in newton_result, so that one texel (newton_iterate) and many
// (fit_newton_batch, four evaluations per vector) run the same decisions.
struct NewtonState {
    double px = 0, py = 0;  // the current point
    PsiEval cur;            // psi and its derivatives there
    int it = 0;             // steps accepted
    bool have_cur = false;  // cur holds the evaluation at (px, py)
    bool want = false;      // an evaluation at (nx, ny) is wanted; false once the solve has ended
    double nx = 0, ny = 0;
    // The step being tried: (dx, dy) in the disk or dalpha along the rim, scaled by t.
    bool rim = false;
    double dx = 0, dy = 0, dalpha = 0, t = 1;
};

void newton_trial(const NewtonState& st, double t, double* nx, double* ny) {
    const double pmax = newton_tables().p_max;
    double x, y;  // (nx, ny) may be (st.px, st.py)
    if (st.rim) {
        const double c = std::cos(t * st.dalpha), s = std::sin(t * st.dalpha);
        x = c * st.px - s * st.py;
        y = s * st.px + c * st.py;
    } else {
        x = st.px + t * st.dx;
        y = st.py + t * st.dy;
        const double l = std::sqrt(x * x + y * y);
        if (l > pmax) {
            x *= pmax / l;
            y *= pmax / l;
        }
    }
    *nx = x;
    *ny = y;
}

// From an evaluated current point: the next step's first trial point (st.want), or the end.
void newton_plan(NewtonState& st, int iterations, double tolerance) {
    st.want = false;
    if (st.it >= iterations) return;
    const PsiEval& cur = st.cur;
    const double px = st.px, py = st.py;
    if (cur.s <= 0) return;  // w_a = 1: psi is flat here
    const double pmax = newton_tables().p_max;
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
        if (!std::isfinite(dalpha)) return;
    } else {
        const double shift = std::max(0.0, 1e-9 * lmax - lmin);
        const double axx = hxx + shift, ayy = hyy + shift, det = axx * ayy - hxy * hxy;
        dx = -(ayy * cur.g[0] - hxy * cur.g[1]) / det;
        dy = -(axx * cur.g[1] - hxy * cur.g[0]) / det;
        if (!std::isfinite(dx) || !std::isfinite(dy)) return;
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
    st.rim = rim;
    st.dx = dx;
    st.dy = dy;
    st.dalpha = dalpha;
    if (dx * dx + dy * dy + dalpha * dalpha * len * len <= tolerance * tolerance) {
        newton_trial(st, 1, &st.px, &st.py);  // taken without a check: the solve ends
        return;
    }
    st.t = 1;
    newton_trial(st, st.t, &st.nx, &st.ny);
    st.want = true;
}

// The evaluation st.want asked for.
void newton_result(NewtonState& st, const PsiEval& e, int iterations, double tolerance) {
    if (!st.have_cur) {
        st.cur = e;
        st.have_cur = true;
        newton_plan(st, iterations, tolerance);
        return;
    }
    if (e.psi < st.cur.psi) {  // accepted
        st.px = st.nx;
        st.py = st.ny;
        st.cur = e;
        ++st.it;
        newton_plan(st, iterations, tolerance);
        return;
    }
    st.t /= 2;  // halved until 1/64: then the solve ends where it is
    st.want = st.t > 1.0 / 64;
    if (st.want) newton_trial(st, st.t, &st.nx, &st.ny);
}

// The first request: psi and its derivatives at the start.
void newton_begin(NewtonState& st, double px, double py) {
    st = NewtonState{};
    st.px = st.nx = px;
    st.py = st.ny = py;
    st.want = true;
}

void newton_iterate(const Reduced& rd, double& px, double& py, int iterations, double tolerance) {
    NewtonState st;
    newton_begin(st, px, py);
    while (st.want) newton_result(st, eval_psi_p<true>(rd, st.nx, st.ny), iterations, tolerance);
    px = st.px;
    py = st.py;
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


// One texel's solve around the Newton iterations: the reduced problem and the four start points
// (the closed form, straight up, the rim at the closed form's azimuth and opposite it), then the
// chosen start, then the result.
struct Prepared {
    Texel x;
    Reduced rd;
    double s2 = 0;            // sum_k I_k^2: 0 means no solve (d straight up)
    double sx[4] = {}, sy[4] = {};  // the start points, the closed form first
};

void prepare(Prepared& p, const Sh3Irradiance& irr, Model model, const Rgb* sampled_iz) {
    p.x = make_texel(irr, sampled_iz);
    p.rd = make_reduced(p.x, model);
    p.s2 = p.x.iz[0] * p.x.iz[0] + p.x.iz[1] * p.x.iz[1] + p.x.iz[2] * p.x.iz[2];
    if (p.s2 > 0) {
        double px = 0, py = 0;
        newton_start(p.rd, &px, &py);
        const double len = std::sqrt(px * px + py * py), pmax = newton_tables().p_max;
        const double rx = len > 0 ? px / len * pmax : pmax, ry = len > 0 ? py / len * pmax : 0.0;
        const double pts[4][2] = {{px, py}, {0, 0}, {rx, ry}, {-rx, -ry}};
        for (int i = 0; i < 4; ++i) p.sx[i] = pts[i][0], p.sy[i] = pts[i][1];
    }
}

// The best of the four starts from psi and s there (e[0] the closed form). A start where psi is flat
// (s = 0, w_a = 1) would stop Newton at once; theta = 0 mostly avoids it, a ring of directions does
// the rest. The reference scans theta from 0 to 85 deg; symmetric targets have their best direction
// on either side, hence the rim on both sides.
void choose_start(const Prepared& p, const double psi[4], const double s[4], double* px, double* py) {
    double best = psi[0], best_s = s[0];
    *px = p.sx[0];
    *py = p.sy[0];
    for (int i = 1; i < 4; ++i)
        if (psi[i] < best) best = psi[i], best_s = s[i], *px = p.sx[i], *py = p.sy[i];
    if (!(best_s > 0)) {
        // All starts where psi is flat (s = 0: the best w_a is 1 there, symmetric targets such as
        // pure L2): a coarse ring of directions (theta 30, 60, 85 deg x 8 azimuths).
        for (int i = 1; i <= 3; ++i)
            for (int j = 0; j < 8; ++j) {
                const double r = std::tan((i < 3 ? i * kPi / 6 : kMaxTheta) / 2), ph = j * kPi / 4;
                const double x = r * std::cos(ph), y = r * std::sin(ph);
                const PsiEval e = eval_psi_p<false>(p.rd, x, y);
                if (e.psi < best && e.s > 0) best = e.psi, *px = x, *py = y;
            }
    }
}

// d from the solved p (straight up when there was no solve); w_a = 1 - s at the returned
// direction, and the error of the result, from the residuals r_k = t_k - I_k m (no cancellation):
// m = h + s (a - h).
IrradZ finish(const Prepared& p, double px, double py, double* error) {
    Vec3 d{0, 0, 1};
    if (p.s2 > 0) {
        const double r2 = px * px + py * py;
        d = clamp_to_hemisphere(Vec3{2 * px, 2 * py, 1 - r2});
    }
    const Reduced& rd = p.rd;
    const double qx = d.x / d.z, qy = d.y / d.z, r = std::sqrt(1 + qx * qx + qy * qy);
    const Vec9 a = model_a<double>(*rd.c, qx, qy, r, 1 / r);
    const double s = p.s2 > 0 ? eval_psi<false>(rd, qx, qy, r, 1 / r).s : 0.0;
    if (error) {
        const SparseGram& g = sparse_gram();
        double e = 0;
        for (size_t k = 0; k < 3; ++k) {
            Vec9 res;
            for (size_t i = 0; i < 9; ++i) res[i] = p.x.t[k][i] - p.x.iz[k] * ((*rd.h)[i] + s * (a[i] - (*rd.h)[i]));
            e += dot9(res, gmul(g, res));
        }
        *error = e;
    }
    IrradZ out;
    out.i_z = Rgb{static_cast<float>(p.x.iz[0]), static_cast<float>(p.x.iz[1]), static_cast<float>(p.x.iz[2])};
    out.w_a = 1 - s;
    out.d = d;
    return out;
}

// Lanes: the reduced problems of up to four texels in one ReducedT<V4> (missing lanes repeat the
// first), and the evaluation of psi at four points of one texel.
ReducedT<V4> broadcast(const Reduced& rd) {
    ReducedT<V4> r;
    r.g = rd.g;
    r.c = rd.c;
    r.h = rd.h;
    r.hhd = rd.hhd;
    for (size_t i = 0; i < 9; ++i) {
        r.v[i] = V4{} + rd.v[i];
        r.gv[i] = V4{} + rd.gv[i];
        r.gh[i] = V4{} + rd.gh[i];
    }
    r.vgv = V4{} + rd.vgv;
    r.hgv = V4{} + rd.hgv;
    r.hgh = V4{} + rd.hgh;
    return r;
}
void gather(const Reduced* const lanes[4], ReducedT<V4>& r) {
    r = broadcast(*lanes[0]);
    for (int l = 1; l < 4; ++l) {
        const Reduced& x = *lanes[l];
        for (size_t i = 0; i < 9; ++i) {
            r.v[i][l] = x.v[i];
            r.gv[i][l] = x.gv[i];
            r.gh[i][l] = x.gh[i];
        }
        r.vgv[l] = x.vgv;
        r.hgv[l] = x.hgv;
        r.hgh[l] = x.hgh;
    }
}
PsiEval lane(const PsiEvalT<V4>& e, int l) {
    PsiEval o;
    o.psi = e.psi[l];
    o.s = e.s[l];
    o.g[0] = e.g[0][l];
    o.g[1] = e.g[1][l];
    o.hxx = e.hxx[l];
    o.hxy = e.hxy[l];
    o.hyy = e.hyy[l];
    return o;
}

[[maybe_unused]] IrradZ fit_one(const Sh3Irradiance& irr, Model model, const EncodeOptions& options, double* error, const Rgb* sampled_iz) {
    Prepared p;
    prepare(p, irr, model, sampled_iz);
    double px = 0, py = 0;
    if (p.s2 > 0) {
        double psi[4], s[4];
        for (int i = 0; i < 4; ++i) {
            const PsiEval e = eval_psi_p<false>(p.rd, p.sx[i], p.sy[i]);
            psi[i] = e.psi;
            s[i] = e.s;
        }
        choose_start(p, psi, s, &px, &py);
        newton_iterate(p.rd, px, py, options.newton_iterations, options.newton_tolerance);
    }
    return finish(p, px, py, error);
}

void fit_many(const Sh3Irradiance* irr, std::size_t n, Model model, const EncodeOptions& options, IrradZ* out) {
    // Per-thread workspaces, grown once (a row of texels comes in chunks of the same size).
    thread_local std::vector<Prepared> prep;
    thread_local std::vector<NewtonState> st;
    thread_local std::vector<size_t> want;
    if (prep.size() < n) prep.resize(n), st.resize(n);
    for (size_t i = 0; i < n; ++i) {
        Prepared& p = prep[i];
        prepare(p, irr[i], model, nullptr);
        st[i].want = false;
        if (!(p.s2 > 0)) continue;
        // The four starts of one texel in the four lanes.
        const PsiEvalT<V4> e = eval_psi_p<false, V4>(broadcast(p.rd), V4{p.sx[0], p.sx[1], p.sx[2], p.sx[3]},
                                                     V4{p.sy[0], p.sy[1], p.sy[2], p.sy[3]});
        const double psi[4] = {e.psi[0], e.psi[1], e.psi[2], e.psi[3]}, s[4] = {e.s[0], e.s[1], e.s[2], e.s[3]};
        double px = 0, py = 0;
        choose_start(p, psi, s, &px, &py);
        newton_begin(st[i], px, py);
    }
    // Newton rounds: every texel that wants an evaluation gets one, four per vector, until none does.
    ReducedT<V4> packed;
    for (;;) {
        want.clear();
        for (size_t i = 0; i < n; ++i)
            if (st[i].want) want.push_back(i);
        if (want.empty()) break;
        for (size_t k = 0; k < want.size(); k += 4) {
            const int m = static_cast<int>(std::min<size_t>(4, want.size() - k));
            const Reduced* lanes[4];
            V4 px{}, py{};
            for (int l = 0; l < 4; ++l) {
                const size_t i = want[k + static_cast<size_t>(std::min(l, m - 1))];
                lanes[l] = &prep[i].rd;
                px[l] = st[i].nx;
                py[l] = st[i].ny;
            }
            gather(lanes, packed);
            const PsiEvalT<V4> e = eval_psi_p<true, V4>(packed, px, py);
            for (int l = 0; l < m; ++l)
                newton_result(st[want[k + static_cast<size_t>(l)]], lane(e, l), options.newton_iterations, options.newton_tolerance);
        }
    }
    for (size_t i = 0; i < n; ++i) out[i] = finish(prep[i], st[i].px, st[i].py, nullptr);
}
