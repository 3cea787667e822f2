// zhc/codec/probe/zh3_solve.cpp — ZH3 axis solve: the zonal axis (and the L1 that carries it)
// chosen to minimise the irradiance error of Eq. 11 (Sec. 3.3), with the analytic gradient of
// App. C (Eq. 27-36), by L-BFGS (codec/probe/lbfgs.h) from ranked start axes: the shared luminance
// axis (solve_luminance) and per-channel axes (solve_channel).
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md (Eq. 11 gradient).
//
// Vector form of the bands used throughout (sh.h conventions): the L1 band of a channel,
// (f1-1, f10, f11), is the vector v = (-f11, -f1-1, f10) with f1(d) = kY1 v . d; |v| = |f1| and
// the optimal linear direction is v / |v|. The L2 band evaluated at a unit direction a is
// Y2(a) . f2 = a^T Q a for a traceless symmetric Q.
#include "codec/probe/zh3.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "codec/probe/lbfgs.h"
#include "codec/probe/zh3_internal.h"

namespace zhc {
namespace {

using namespace detail;  // zh3_internal.h, sh_l1.h and lbfgs.h

constexpr double kInf = std::numeric_limits<double>::infinity();
// Start axes (see solve_luminance / solve_channel). The shared-axis solve runs L-BFGS from the best
// ranked start only: a second start leaves its converged mean error on the bench set unchanged (to 6
// digits) at 1.3-2x the cost and does not move its worst case against a brute-force axis search
// (10,000 random lightings: mean 1.000006, worst 1.029, 3 probes above 0.1 %). The per-channel
// solve runs from every distinct start (the channel's L1 axis and two principal axes of its L2
// form): from the best-ranked start alone it stops in a poorer local minimum on about 1 random
// probe in 300; from every start, never more than 0.1 % above the brute force on those 10,000 (tests/test_zh3.cpp).
constexpr int kLumStarts = 1;
constexpr int kChannelStarts = 4;
// |Y2(a)|^2 = 5 / (4 pi) on the unit sphere (Eq. 8/9).
const double kFourPiOverFive = 4.0 * kPi / 5.0;

// J_Y2^T r: gradient with respect to a of Y2(a) . r (App. C Eq. 28, the Cartesian polynomials).
Vec3 y2_jacobian_t(Vec3 a, const double* r) {
    return {kY2 * a.y * r[0] - kY2 * a.z * r[3] + 2.0 * kY22 * a.x * r[4],
            kY2 * a.x * r[0] - kY2 * a.z * r[1] - 2.0 * kY22 * a.y * r[4],
            -kY2 * a.y * r[1] + 6.0 * kY20 * a.z * r[2] - kY2 * a.x * r[3]};
}

// ---- the solve's target in irradiance vector form ------------------------------------------

struct Target {
    Vec3 t1[3];       // irradiance L1 per channel (vector form)
    double t2[3][5];  // irradiance L2 per channel
    double t2sq[3];   // |t2_k|^2
    double t1sq[3];
    double t0[3];     // irradiance DC
};

Target make_target(const Sh3Radiance& sh) {
    Target t;
    for (int k = 0; k < 3; ++k) {
        t.t0[k] = sh[0][k];
        t.t1[k] = kIrradianceBandScale[1] * l1_vector(sh.c.data(), k);
        t.t1sq[k] = dot(t.t1[k], t.t1[k]);
        t.t2sq[k] = 0;
        for (int m = 0; m < 5; ++m) {
            t.t2[k][m] = kIrradianceBandScale[2] * sh[4 + m][k];
            t.t2sq[k] += t.t2[k][m] * t.t2[k][m];
        }
    }
    return t;
}

// Scale invariance: the solves run on the target divided by the power of two at or below its
// magnitude (|(t1, t2)| of the channel, or of all three for the shared axis), so the normalised
// magnitude is in [1, 2) whatever the lighting's units. Scaling by a power of two is exact, so a
// probe scaled by 2^n gives bit-identical solver iterates; any other factor changes them only by
// the rounding of the (float) input. Tolerances are then relative by construction.
double normaliser(double magnitude) { return std::ldexp(1.0, -std::ilogb(magnitude)); }

Target normalised_target(const Target& t, double f) {
    Target n = t;
    for (int k = 0; k < 3; ++k) {
        n.t0[k] *= f;
        n.t1[k] = f * t.t1[k];
        for (int m = 0; m < 5; ++m) n.t2[k][m] *= f;
        n.t1sq[k] *= f * f;
        n.t2sq[k] *= f * f;
    }
    return n;
}

// L2 part of Eq. 11 for channel k along unit axis a: |t2|^2 - (4 pi/5) (Y2(a) . t2)^2 (the residual
// of the orthogonal projection of t2 onto Y2(a), since |Y2(a)|^2 = 5 / (4 pi)).
double l2_residual(const Target& t, int k, Vec3 a) {
    const double h = dot5(y2(a), t.t2[k]);
    return t.t2sq[k] - kFourPiOverFive * h * h;
}

// Eq. 11 for the shared axis, x = nine irradiance L1 coefficients in vector form (x[3k + j] is
// component j of channel k's vector). The gradient is App. C Eq. 27 simplified: the L2 residual
// r_k = (4 pi/5) h_k q - t2_k is orthogonal to q (|q|^2 = 5/(4 pi)), so of Eq. 27's second factor
// only -(8 pi/5) h_k t2_k^T J_Y2 J_A survives; J_A = w_k (I - a a^T) / |v| (Eq. 33-36; the sign
// permutation of Eq. 35 is absorbed by working in vector form).
double lum_objective_vec(const Target& t, const double w[3], const double* x, double* grad) {
    Vec3 v{};
    for (int k = 0; k < 3; ++k) v = v + w[k] * Vec3{x[3 * k], x[3 * k + 1], x[3 * k + 2]};
    const double len = length(v);
    if (!usable_length(len)) return kInf;
    const Vec3 a = (1.0 / len) * v;
    const auto q = y2(a);
    double e = 0, r[5] = {0, 0, 0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        const Vec3 d{x[3 * k] - t.t1[k].x, x[3 * k + 1] - t.t1[k].y, x[3 * k + 2] - t.t1[k].z};
        const double h = dot5(q, t.t2[k]);
        e += dot(d, d);
        for (int m = 0; m < 5; ++m) {  // the L2 residual vector (accurate form, see channel_objective_vec)
            const double r2 = t.t2[k][m] - kFourPiOverFive * h * q[m];
            e += r2 * r2;
        }
        for (int m = 0; m < 5; ++m) r[m] += h * t.t2[k][m];
        if (grad) {
            grad[3 * k] = 2.0 * d.x;
            grad[3 * k + 1] = 2.0 * d.y;
            grad[3 * k + 2] = 2.0 * d.z;
        }
    }
    if (grad) {
        const Vec3 de_da = (-2.0 * kFourPiOverFive) * y2_jacobian_t(a, r);
        const Vec3 de_dv = (1.0 / len) * (de_da - dot(a, de_da) * a);
        for (int k = 0; k < 3; ++k) {
            grad[3 * k] += w[k] * de_dv.x;
            grad[3 * k + 1] += w[k] * de_dv.y;
            grad[3 * k + 2] += w[k] * de_dv.z;
        }
    }
    return e;
}

// Per-channel Eq. 11 over an unnormalised axis x: L1 = projection of t1 on a, L2 = Eq. 9 fit.
//   E(a) = |t1|^2 - (a.t1)^2 + |t2|^2 - (4 pi/5) h(a)^2.
double channel_objective_vec(const Target& t, int k, Vec3 x, Vec3* grad) {
    const double len = length(x);
    if (!usable_length(len)) return kInf;
    const Vec3 a = (1.0 / len) * x;
    const double p = dot(a, t.t1[k]);
    const auto q = y2(a);
    const double h = dot5(q, t.t2[k]);
    // |t1|^2 - p^2 + |t2|^2 - (4 pi/5) h^2, summed from the residual vectors: accurate relative to E
    // itself rather than to |t|^2 (the difference form loses the last digits the solve's stopping
    // test and line search look at when the zonal fit is good).
    const Vec3 r1 = t.t1[k] - p * a;
    double e = dot(r1, r1);
    for (int m = 0; m < 5; ++m) {
        const double r2 = t.t2[k][m] - kFourPiOverFive * h * q[m];
        e += r2 * r2;
    }
    if (grad) {
        double r[5];
        for (int m = 0; m < 5; ++m) r[m] = h * t.t2[k][m];
        const Vec3 de_da = (-2.0 * p) * t.t1[k] + (-2.0 * kFourPiOverFive) * y2_jacobian_t(a, r);
        *grad = (1.0 / len) * (de_da - dot(a, de_da) * a);
    }
    return e;
}
// ---- start axes -------------------------------------------------------------------------------

// Traceless symmetric Q with Y2(d) . f2 = d^T Q d on the unit sphere (3z^2 - 1 = 2z^2 - x^2 - y^2).
void l2_quadratic_form(const double* f2, double q[3][3]) {
    const double xy = 0.5 * kY2 * f2[0], yz = -0.5 * kY2 * f2[1], xz = -0.5 * kY2 * f2[3];
    q[0][0] = -kY20 * f2[2] + kY22 * f2[4];
    q[1][1] = -kY20 * f2[2] - kY22 * f2[4];
    q[2][2] = 2.0 * kY20 * f2[2];
    q[0][1] = q[1][0] = xy;
    q[1][2] = q[2][1] = yz;
    q[0][2] = q[2][0] = xz;
}

// Eigenvectors of a traceless symmetric 3x3 matrix (an L2 band's quadratic form), as start axes.
// Eigenvalues in closed form (Smith 1961, traceless case): lambda_i = 2 sqrt(p) cos(phi + 2 pi i / 3)
// with p = tr(A^2) / 6 and cos(3 phi) = det(A) / (2 p^(3/2)); each eigenvector is the longest cross
// product of two rows of A - lambda I. Returns how many it found.
// A (nearly) repeated eigenvalue (a zonal L2 band: one light plus ambient) has a plane of
// eigenvectors, and the cross products would pick one of them from rounding noise, so that a probe
// scaled by a constant could start elsewhere. Then the plane's two start axes are chosen
// deterministically instead: `hint` (the L1 direction) projected into the plane, and its
// perpendicular in the plane (any fixed in-plane axis when the hint is normal to the plane).
int traceless_eigenvectors(const double a[3][3], Vec3 out[3], Vec3 hint) {
    const double p = (a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2] +
                      2.0 * (a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2])) / 6.0;
    if (!(p > 0) || !std::isfinite(p)) return 0;
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[1][2]) -
                       a[0][1] * (a[0][1] * a[2][2] - a[1][2] * a[0][2]) +
                       a[0][2] * (a[0][1] * a[1][2] - a[1][1] * a[0][2]);
    const double sp = std::sqrt(p);
    const double phi = std::acos(std::clamp(det / (2.0 * p * sp), -1.0, 1.0)) / 3.0;
    double lambda[3];
    for (int i = 0; i < 3; ++i) lambda[i] = 2.0 * sp * std::cos(phi + 2.0 * kPi * i / 3.0);
    auto eigenvector = [&](double l, Vec3* v) {
        const Vec3 r0{a[0][0] - l, a[0][1], a[0][2]}, r1{a[1][0], a[1][1] - l, a[1][2]}, r2{a[2][0], a[2][1], a[2][2] - l};
        Vec3 best = cross(r0, r1);
        for (const Vec3 c : {cross(r0, r2), cross(r1, r2)})
            if (dot(c, c) > dot(best, best)) best = c;
        const double len = length(best);
        if (!(len > 1e-9 * p && std::isfinite(len))) return false;
        *v = (1.0 / len) * best;
        return true;
    };
    // lambda[0] >= lambda[2] >= lambda[1]; the distinct one of a near-repeated pair.
    const double gap_high = lambda[0] - lambda[2], gap_low = lambda[2] - lambda[1];
    const double degenerate_gap = 1e-3 * sp;
    if (std::min(gap_high, gap_low) < degenerate_gap) {
        const int distinct = gap_high < gap_low ? 1 : 0;
        Vec3 d;
        if (!eigenvector(lambda[distinct], &d)) return 0;
        Vec3 u = hint - dot(hint, d) * d;
        const double ul = length(u);
        if (ul > 1e-3 * length(hint) && usable_length(ul)) {
            u = (1.0 / ul) * u;
        } else {  // the axis of d's smallest component, made perpendicular to d
            const Vec3 e = std::fabs(d.x) <= std::fabs(d.y) && std::fabs(d.x) <= std::fabs(d.z) ? Vec3{1, 0, 0}
                           : std::fabs(d.y) <= std::fabs(d.z)                                ? Vec3{0, 1, 0}
                                                                                              : Vec3{0, 0, 1};
            u = normalize_or(cross(d, e), {0, 0, 1});
        }
        out[0] = d;
        out[1] = u;
        out[2] = cross(d, u);
        return 3;
    }
    int n = 0;
    for (int i = 0; i < 3; ++i)
        if (eigenvector(lambda[i], &out[n])) ++n;
    return n;
}

struct Candidate {
    Vec3 axis;
    double error;
};

// Adds `axis` unless it is (anti)parallel to one already there (Y2 is even, so +-a are the same).
void add_candidate(Candidate* list, int* count, Vec3 axis, double error) {
    if (!std::isfinite(error)) return;
    for (int i = 0; i < *count; ++i)
        if (std::fabs(dot(list[i].axis, axis)) > 0.9999) {
            if (error < list[i].error) list[i] = {axis, error};
            return;
        }
    list[(*count)++] = {axis, error};
}

// Best (lowest profile error) first.
void sort_candidates(Candidate* list, int count) {
    for (int i = 1; i < count; ++i)  // insertion sort: at most 13 entries
        for (int j = i; j > 0 && list[j].error < list[j - 1].error; --j) std::swap(list[j], list[j - 1]);
}

// Eq. 11 of a stored ZH3 (radiance L1 as floats) against the target, exactly as decoded.
double stored_error(const Target& t, const Sh2Radiance& linear, ZonalAxisMode mode, const LuminanceWeights& w,
                    int channel_only = -1) {
    double e = 0;
    const Axes axes(linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        if (channel_only >= 0 && k != channel_only) continue;
        const Vec3 d = kIrradianceBandScale[1] * l1_vector(linear.c.data(), k) - t.t1[k];
        e += dot(d, d) + l2_residual(t, k, axes.a[k]);
    }
    return e;
}

// Sum over channels of the L2 part of Eq. 11 along unit axis a.
double l2_residual_sum(const Target& t, Vec3 a) {
    const auto q = y2(a);
    double e = 0;
    for (int k = 0; k < 3; ++k) {
        const double h = dot5(q, t.t2[k]);
        e += t.t2sq[k] - kFourPiOverFive * h * h;
    }
    return e;
}

// The shared-axis solve. Cost matters (target: a few microseconds per probe), so the work around
// the L-BFGS is kept lean: the luminance axis of a linear SH is computed once, and the candidate
// start axes are ranked by their profile error before a single L-BFGS run.
Zh3 solve_luminance(const Sh3Radiance& sh, const CodecOptions& o, EncodeStats* stats) {
    const LuminanceWeights& lw = o.luminance;
    const double w[3] = {lw.r, lw.g, lw.b};
    const double ww = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    const Target t = make_target(sh);
    Zh3 fit;
    fit.linear = truncate_to_sh2(sh);
    const Vec3 fit_axis = zh3_axis(fit.linear, ZonalAxisMode::kLuminance, 0, lw);
    for (int k = 0; k < 3; ++k) fit.zonal[k] = static_cast<float>(fit_zonal(sh, k, fit_axis));
    if (stats) stats->solver_iterations = 0;
    // Eq. 11 of the fit: its L1 is the target's, so only the L2 residuals remain.
    const double fit_error = l2_residual_sum(t, fit_axis);
    double scale = 0;
    for (int k = 0; k < 3; ++k) scale += t.t1sq[k] + t.t2sq[k];
    scale = std::sqrt(scale);
    if (!(ww > 0) || !usable_length(scale) || !std::isfinite(fit_error) || o.solver_iterations < 0) return fit;
    // The solve runs on the normalised target tn = f t (|tn| in [1, 2)); its L1 is scaled back by 1/f.
    const double f = normaliser(scale);
    const Target tn = normalised_target(t, f);
    const double scale_n = f * scale;
    const Vec3 u = w[0] * tn.t1[0] + w[1] * tn.t1[1] + w[2] * tn.t1[2];  // luminance L1 of the target

    // Profile error of an axis: the best L1 whose luminance points along +-a costs |P_perp u|^2 / |w|^2
    // (g_k = t1_k - w_k P_perp u / |w|^2), plus the L2 residuals.
    const double uu = dot(u, u);
    auto profile = [&](Vec3 a) {
        const double ua = dot(u, a);
        return (uu - ua * ua) / ww + l2_residual_sum(tn, a);
    };
    // Start axes: the luminance L1 axis (the fit's), the principal axes of the luminance L2
    // quadratic form (where a zonal L2 lobe fits best), and each channel's L1 axis and L2 principal
    // axes (largest and smallest eigenvalue), all ranked by their profile error.
    Candidate cand[13];
    int count = 0;
    if (has_zonal_axis(fit.linear, ZonalAxisMode::kLuminance, 0, lw)) add_candidate(cand, &count, fit_axis, f * f * fit_error);
    {
        double q[3][3] = {}, qk[3][3];
        for (int k = 0; k < 3; ++k) {
            l2_quadratic_form(tn.t2[k], qk);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) q[i][j] += w[k] * qk[i][j];
        }
        Vec3 e[3];
        const int n = traceless_eigenvectors(q, e, u);
        for (int j = 0; j < n; ++j) add_candidate(cand, &count, e[j], profile(e[j]));
        for (int k = 0; k < 3; ++k) {  // each channel's own L1 and L2 principal axes, ranked too
            const double len = length(tn.t1[k]);
            if (usable_length(len)) add_candidate(cand, &count, (1.0 / len) * tn.t1[k], profile((1.0 / len) * tn.t1[k]));
            l2_quadratic_form(tn.t2[k], qk);
            const int nk = std::min(traceless_eigenvectors(qk, e, tn.t1[k]), 2);
            for (int j = 0; j < nk; ++j) add_candidate(cand, &count, e[j], profile(e[j]));
        }
    }
    if (count == 0) return fit;
    sort_candidates(cand, count);

    // Keep the luminance L1 long enough that float rounding of the stored coefficients cannot
    // swing the decoded axis: the degenerate (zero luminance L1) optimum is approached, not met.
    const double min_length = 1e-3 * scale_n;
    Zh3 best = fit;
    double best_error = fit_error;
    int iterations = 0;
    const int starts = std::min(count, kLumStarts);
    for (int c = 0; c < starts; ++c) {
        const Vec3 axis = cand[c].axis;
        const double ua = dot(u, axis);
        const double along = std::fabs(ua) < min_length ? (ua < 0 ? -min_length : min_length) : ua;
        // g_k = t1_k - w_k (u - along a) / |w|^2: luminance of g is along * a.
        const Vec3 shift = (1.0 / ww) * (u - along * axis);
        double x[9];
        for (int k = 0; k < 3; ++k) {
            const Vec3 g = tn.t1[k] - w[k] * shift;
            x[3 * k] = g.x;
            x[3 * k + 1] = g.y;
            x[3 * k + 2] = g.z;
        }
        double e = 0;
        iterations += lbfgs<9, 8>([&](const double* xx, double* gg) { return lum_objective_vec(tn, w, xx, gg); },
                                  [](const double*) { return false; }, x,
                                  &e, o.solver_iterations, o.solver_tolerance * scale_n, 0.5, false);
        {
            // Re-inflate a luminance L1 the solve shrank towards zero (see min_length).
            Vec3 v{};
            for (int k = 0; k < 3; ++k) v = v + w[k] * Vec3{x[3 * k], x[3 * k + 1], x[3 * k + 2]};
            const double len = length(v);
            if (!(len >= min_length)) {
                const Vec3 dir = usable_length(len) ? (1.0 / len) * v : axis;
                const Vec3 add = ((min_length - (usable_length(len) ? len : 0.0)) / ww) * dir;
                for (int k = 0; k < 3; ++k) {
                    x[3 * k] += w[k] * add.x;
                    x[3 * k + 1] += w[k] * add.y;
                    x[3 * k + 2] += w[k] * add.z;
                }
            }
        }
        // Eq. 11 exactly as the decoder will see it: float L1, axis from the float L1.
        Zh3 z;
        for (int k = 0; k < 3; ++k) {
            z.linear[0][k] = sh[0][k];
            set_l1(z.linear.c.data(), k,
                   (1.0 / (f * kIrradianceBandScale[1])) * Vec3{x[3 * k], x[3 * k + 1], x[3 * k + 2]});
        }
        const Vec3 axis_out = zh3_axis(z.linear, ZonalAxisMode::kLuminance, 0, lw);
        double err = l2_residual_sum(t, axis_out);
        for (int k = 0; k < 3; ++k) {
            const Vec3 d = kIrradianceBandScale[1] * l1_vector(z.linear.c.data(), k) - t.t1[k];
            err += dot(d, d);
        }
        // Strictly better, with a margin far above rounding, or the fit stays.
        if (err < best_error * (1.0 - 1e-12)) {
            for (int k = 0; k < 3; ++k) z.zonal[k] = static_cast<float>(fit_zonal(sh, k, axis_out));
            best = z;
            best_error = err;
        }
    }
    if (stats) stats->solver_iterations = iterations;
    return best;
}

Zh3 solve_channel(const Sh3Radiance& sh, const CodecOptions& o, EncodeStats* stats) {
    const LuminanceWeights& lw = o.luminance;
    Zh3 out = zh3_fit(sh, ZonalAxisMode::kPerChannel, lw);
    const Target t = make_target(sh);
    int iterations = 0;
    for (int k = 0; k < 3; ++k) {
        double best_error = stored_error(t, out.linear, ZonalAxisMode::kPerChannel, lw, k);
        const double scale = std::sqrt(t.t1sq[k] + t.t2sq[k]);
        if (!usable_length(scale) || !std::isfinite(best_error) || o.solver_iterations < 0) continue;
        // The solve runs on the channel's normalised target (|(t1, t2)| in [1, 2)): the objective and
        // its gradient with respect to the axis scale with the square of the lighting's magnitude.
        const double f = normaliser(scale);
        const Target tn = normalised_target(t, f);
        const double scale_n2 = tn.t1sq[k] + tn.t2sq[k];
        Candidate cand[4];
        int count = 0;
        const double len = length(tn.t1[k]);
        auto profile = [&](Vec3 a) { return channel_objective_vec(tn, k, a, nullptr); };
        if (usable_length(len)) add_candidate(cand, &count, (1.0 / len) * tn.t1[k], profile((1.0 / len) * tn.t1[k]));
        double q[3][3];
        l2_quadratic_form(tn.t2[k], q);
        Vec3 e[3];
        // The first two are the eigenvectors of the largest and smallest eigenvalue, where |Y2(a).t2| is
        // locally largest (local minima of the L2 part). The third (middle eigenvalue: a saddle, or
        // the in-plane axis across the L1 for a repeated eigenvalue) is a stationary point where the
        // solve would crawl for many iterations before rolling into one of the others' basins.
        const int n = std::min(traceless_eigenvectors(q, e, tn.t1[k]), 2);
        for (int j = 0; j < n; ++j) add_candidate(cand, &count, e[j], profile(e[j]));
        sort_candidates(cand, count);
        // Curvature of E along the sphere is about 2 |t1|^2 + 12 (4 pi / 5) |h| |t2|: scale the
        // initial inverse Hessian by it (the axis has unit length).
        const double h0 = 1.0 / std::max(2.0 * (tn.t1sq[k] + 6.0 * tn.t2sq[k]), 1e-300);
        const int starts = std::min(count, kChannelStarts);
        // Axes the earlier starts converged to: a later start that comes within ~0.05 rad of one
        // (as an axis: +-) is taken to be in that minimum's basin and stops there (distinct minima of
        // this quartic-on-the-sphere objective lie far further apart; the brute-force test checks).
        Vec3 found[kChannelStarts];
        int found_count = 0;
        auto known = [&](const double* xx) {
            const Vec3 v{xx[0], xx[1], xx[2]};
            const double vv = dot(v, v);
            for (int j = 0; j < found_count; ++j) {
                const double d = dot(v, found[j]);
                if (d * d > (1.0 - 2.5e-3) * vv) return true;
            }
            return false;
        };
        for (int c = 0; c < starts; ++c) {
            double x[3] = {cand[c].axis.x, cand[c].axis.y, cand[c].axis.z};
            double en = 0;
            iterations += lbfgs<3, 4>(
                [&](const double* xx, double* gg) {
                    Vec3 grad;
                    const double v2 = channel_objective_vec(tn, k, {xx[0], xx[1], xx[2]}, &grad);
                    gg[0] = grad.x;
                    gg[1] = grad.y;
                    gg[2] = grad.z;
                    return v2;
                },
                known, x, &en, o.solver_iterations, o.solver_tolerance * scale_n2, h0, true);
            const Vec3 a = normalize_or({x[0], x[1], x[2]}, {0, 0, 1});
            if (!known(x)) found[found_count++] = a;
            // L1 = projection of t1 on a, kept non-zero so the decoder recovers the axis.
            double p = dot(a, t.t1[k]);
            const double min_length = 1e-3 * scale;
            if (std::fabs(p) < min_length) p = p < 0 ? -min_length : min_length;
            Zh3 z = out;
            set_l1(z.linear.c.data(), k, (p / kIrradianceBandScale[1]) * a);
            const double err = stored_error(t, z.linear, ZonalAxisMode::kPerChannel, lw, k);
            if (err < best_error) {
                z.zonal[k] = static_cast<float>(fit_zonal(sh, k, zh3_axis(z.linear, ZonalAxisMode::kPerChannel, k, lw)));
                out = z;
                best_error = err;
            }
        }
    }
    if (stats) stats->solver_iterations = iterations;
    return out;
}

}  // namespace

double zh3_eq11_error(const Sh3Radiance& target, const Sh2Radiance& linear, ZonalAxisMode mode,
                      const LuminanceWeights& w) {
    return stored_error(make_target(target), linear, mode, w);
}

double zh3_lum_objective(const Sh3Radiance& target, const LuminanceWeights& w, const double g[9], double grad[9]) {
    const Target t = make_target(target);
    const double wv[3] = {w.r, w.g, w.b};
    // SH order g[3 m + k] (m = 0, 1, 2 for f1-1, f10, f11) -> vector form x[3 k + j], v = (-f11, -f1-1, f10).
    double x[9], gx[9];
    for (int k = 0; k < 3; ++k) {
        x[3 * k] = -g[6 + k];
        x[3 * k + 1] = -g[k];
        x[3 * k + 2] = g[3 + k];
    }
    const double e = lum_objective_vec(t, wv, x, grad ? gx : nullptr);
    if (grad)
        for (int k = 0; k < 3; ++k) {
            grad[k] = -gx[3 * k + 1];
            grad[3 + k] = gx[3 * k + 2];
            grad[6 + k] = -gx[3 * k];
        }
    return e;
}

double zh3_channel_objective(const Sh3Radiance& target, int channel, Vec3 x, Vec3* grad) {
    return channel_objective_vec(make_target(target), std::clamp(channel, 0, 2), x, grad);
}

Zh3 zh3_solve(const Sh3Radiance& sh, ZonalAxisMode mode, const CodecOptions& options, EncodeStats* stats) {
    return mode == ZonalAxisMode::kLuminance ? solve_luminance(sh, options, stats) : solve_channel(sh, options, stats);
}

}  // namespace zhc
