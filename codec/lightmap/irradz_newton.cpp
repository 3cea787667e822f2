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
#include <type_traits>
#include <vector>

#include "codec/isa.h"
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
}  // namespace

// The solve, twice (see irradz_newton_solve.inl and codec/isa.h).
namespace isa_baseline {
namespace {
#include "codec/lightmap/irradz_newton_solve.inl"
}  // namespace
}  // namespace isa_baseline
#if ZHC_AVX2_TWIN
ZHC_AVX2_BEGIN
namespace isa_avx2 {
namespace {
#include "codec/lightmap/irradz_newton_solve.inl"
}  // namespace
}  // namespace isa_avx2
ZHC_AVX2_END
#endif


ReducedError reduced_error(const Sh3Irradiance& target, Model model, double qx, double qy, const Rgb* sampled_iz) {
    const isa_baseline::Reduced rd = isa_baseline::make_reduced(isa_baseline::make_texel(target, sampled_iz), model);
    const double rr = std::sqrt(1 + qx * qx + qy * qy);
    const isa_baseline::PsiEval e = isa_baseline::eval_psi<true>(rd, qx, qy, rr, 1 / rr);
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


// One texel: the baseline build (the AVX2 twin gives the same floats; fit_newton_many uses it).
IrradZ detail::fit_newton(const Sh3Irradiance& irr, Model model, const EncodeOptions& options, double* error,
                          const Rgb* sampled_iz) {
    return isa_baseline::fit_one(irr, model, options, error, sampled_iz);
}

void detail::fit_newton_many(const Sh3Irradiance* irr, std::size_t n, Model model, const EncodeOptions& options, IrradZ* out,
                             bool allow_avx2) {
#if ZHC_AVX2_TWIN
    if (cpu_has_avx2() && allow_avx2) return isa_avx2::fit_many(irr, n, model, options, out);
#endif
    (void)allow_avx2;
    isa_baseline::fit_many(irr, n, model, options, out);
}

}  // namespace zhc::irradz
