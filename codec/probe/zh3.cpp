// ZH3 representations: fit (Eq. 9/10), luminance axis (Sec. 3.2), BFGS axis solve (Sec. 3.3,
// Eq. 11, App. C), hallucination (Sec. 3.4, Listing 1) and ZH3 deringing (App. B).
//
// Source: Roughton, Sloan, Silvennoinen, Iwanicki, Shirley, "ZH3: Quadratic Zonal Harmonics",
// I3D 2024. Derivations redone in docs/zh3.md (Eq. 11 gradient, Eq. 20, the App. B interval).
//
// Vector form of the bands used throughout (sh.h conventions): the L1 band of a channel,
// (f1-1, f10, f11), is the vector v = (-f11, -f1-1, f10) with f1(d) = kY1 v . d; |v| = |f1| and
// the optimal linear direction is v / |v|. The L2 band evaluated at a unit direction a is
// Y2(a) . f2 = a^T Q a for a traceless symmetric Q.
#include "codec/probe/zh3.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "codec/sh/sh_l1.h"

namespace zhc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Start axes (see solve_luminance / solve_channel). The shared-axis solve runs L-BFGS from the best
// ranked start only: a second start left its converged mean error on the bench set unchanged (to 6
// digits) at 1.3-2x the cost and did not move its worst case against a brute-force axis search
// (10,000 random lightings: mean 1.000006, worst 1.029, 3 probes above 0.1 %). The per-channel
// solve runs from every distinct start (the channel's L1 axis and two principal axes of its L2
// form): from the best-ranked start alone it stopped in a poorer local minimum on about 1 random
// probe in 300; now never more than 0.1 % above the brute force on those 10,000 (tests/test_zh3.cpp).
constexpr int kLumStarts = 1;
constexpr int kChannelStarts = 4;
// Relative step below which L-BFGS stops (|x_new - x| <= kStepTolerance |x|): the iteration cap is
// a guard, not the usual stop.
constexpr double kStepTolerance = 1e-12;
// |Y2(a)|^2 = 5 / (4 pi) on the unit sphere (Eq. 8/9).
const double kFourPiOverFive = 4.0 * kPi / 5.0;
const double kSqrtFourPiOverFive = std::sqrt(4.0 * kPi / 5.0);
const double kSqrt3 = std::sqrt(3.0);

using detail::l1_vector;
using detail::set_l1;
using detail::load_linear;

std::array<double, 5> y2(Vec3 a) {
    return {kY2 * a.x * a.y, -kY2 * a.y * a.z, kY20 * (3.0 * a.z * a.z - 1.0), -kY2 * a.x * a.z,
            kY22 * (a.x * a.x - a.y * a.y)};
}
double dot5(const std::array<double, 5>& a, const double* b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4];
}
// J_Y2^T r: gradient with respect to a of Y2(a) . r (App. C Eq. 28, the Cartesian polynomials).
Vec3 y2_jacobian_t(Vec3 a, const double* r) {
    return {kY2 * a.y * r[0] - kY2 * a.z * r[3] + 2.0 * kY22 * a.x * r[4],
            kY2 * a.x * r[0] - kY2 * a.z * r[1] - 2.0 * kY22 * a.y * r[4],
            -kY2 * a.y * r[1] + 6.0 * kY20 * a.z * r[2] - kY2 * a.x * r[3]};
}

Vec3 luminance_l1(const Rgb* c, const LuminanceWeights& w) {
    return w.r * l1_vector(c, 0) + w.g * l1_vector(c, 1) + w.b * l1_vector(c, 2);
}

// Axis source vector of channel k (not normalised).
Vec3 axis_source(const Rgb* c, ZonalAxisMode mode, int k, const LuminanceWeights& w) {
    return mode == ZonalAxisMode::kLuminance ? luminance_l1(c, w) : l1_vector(c, k);
}

bool usable_length(double len) { return len > 0.0 && std::isfinite(len); }

// The three channels' zonal axes, the shared luminance axis computed once.
struct Axes {
    Vec3 a[3];
    Axes(const Sh2Radiance& linear, ZonalAxisMode mode, const LuminanceWeights& w) {
        if (mode == ZonalAxisMode::kLuminance) {
            a[0] = a[1] = a[2] = normalize_or(luminance_l1(linear.c.data(), w), {0, 0, 1});
        } else {
            for (int k = 0; k < 3; ++k) a[k] = normalize_or(l1_vector(linear.c.data(), k), {0, 0, 1});
        }
    }
};

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

// ---- L-BFGS (Nocedal & Wright, Alg. 7.4/7.5) with a backtracking Armijo line search ----------
//
// The inverse Hessian is held as the last M curvature pairs (two-loop recursion), which is cheaper
// than a dense N x N BFGS update and, while fewer than M pairs exist, gives exactly the BFGS
// iterates for the same initial matrix. Initial inverse Hessian: h0 * I, or with `rescale` the
// N&W Eq. 7.20 scaling s.y / y.y of the latest pair. Few function evaluations per iteration: the
// full step is tried first and then shrunk by a safeguarded quadratic interpolation.
//
// `known(x)` ends the run early when x has reached (the basin of) a minimum already found by an
// earlier start: it is checked before every iteration.
template <int N, int M, class F, class K>
int lbfgs(F&& f, K&& known, double* x, double* fx, int max_iterations, double gradient_tolerance, double h0,
          bool rescale) {
    // Every constant below is either relative or, for the absolute ones (1e-300), meant for the
    // normalised problems the callers pass in (|target| in [1, 2), see normalised_target()).
    double g[N], gn[N], xn[N], p[N], q[N];
    double s[M][N], y[M][N], rho[M], alpha[M];
    int stored = 0, head = 0;
    double gamma = h0;
    double e = f(x, g);
    int it = 0;
    for (; it < max_iterations; ++it) {
        double gg = 0;
        for (int i = 0; i < N; ++i) gg += g[i] * g[i];
        if (!(std::sqrt(gg) > gradient_tolerance) || known(x)) break;
        // Two-loop recursion: p = -H g.
        for (int i = 0; i < N; ++i) q[i] = g[i];
        for (int j = 0; j < stored; ++j) {
            const int m = (head - 1 - j + M) % M;
            double d = 0;
            for (int i = 0; i < N; ++i) d += s[m][i] * q[i];
            alpha[m] = rho[m] * d;
            for (int i = 0; i < N; ++i) q[i] -= alpha[m] * y[m][i];
        }
        for (int i = 0; i < N; ++i) q[i] *= gamma;
        for (int j = stored - 1; j >= 0; --j) {
            const int m = (head - 1 - j + M) % M;
            double d = 0;
            for (int i = 0; i < N; ++i) d += y[m][i] * q[i];
            const double beta = rho[m] * d;
            for (int i = 0; i < N; ++i) q[i] += (alpha[m] - beta) * s[m][i];
        }
        double slope = 0;
        for (int i = 0; i < N; ++i) {
            p[i] = -q[i];
            slope += p[i] * g[i];
        }
        if (!(slope < 0)) {  // not a descent direction: forget the pairs, steepest descent
            stored = 0;
            gamma = h0;
            for (int i = 0; i < N; ++i) p[i] = -h0 * g[i];
            slope = -h0 * gg;
        }
        double step = 1.0, en = kInf;
        bool accepted = false;
        for (int ls = 0; ls < 12; ++ls) {
            for (int i = 0; i < N; ++i) xn[i] = x[i] + step * p[i];
            en = f(xn, gn);
            if (en <= e + 1e-4 * step * slope) {
                accepted = true;
                break;
            }
            // Minimiser of the quadratic through e, slope and en, kept within [0.1, 0.5] step.
            double next = 0.5 * step;
            if (std::isfinite(en)) {
                const double denom = 2.0 * (en - e - slope * step);
                if (denom > 0) next = std::clamp(-slope * step * step / denom, 0.1 * step, 0.5 * step);
            }
            step = next;
        }
        if (!accepted) break;
        double sy = 0, yy = 0, ss = 0, xx = 0;
        for (int i = 0; i < N; ++i) {
            s[head][i] = xn[i] - x[i];
            y[head][i] = gn[i] - g[i];
            sy += s[head][i] * y[head][i];
            yy += y[head][i] * y[head][i];
            ss += s[head][i] * s[head][i];
            xx += xn[i] * xn[i];
            x[i] = xn[i];
            g[i] = gn[i];
        }
        e = en;
        if (ss <= kStepTolerance * kStepTolerance * xx) {  // converged in x: this step counts, stop
            ++it;
            break;
        }
        if (sy > 1e-300 && yy > 0) {  // curvature condition; otherwise skip the pair
            rho[head] = 1.0 / sy;
            head = (head + 1) % M;
            stored = std::min(stored + 1, M);
            if (rescale) gamma = sy / yy;
        }
    }
    *fx = e;
    return it;
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

// The zonal coefficient (radiance, Eq. 10) of channel k of `sh` along unit axis a.
double fit_zonal(const Sh3Radiance& sh, int k, Vec3 a) {
    const auto q = y2(a);
    double f2[5];
    for (int m = 0; m < 5; ++m) f2[m] = sh[4 + m][k];
    return kSqrtFourPiOverFive * dot5(q, f2);
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

// ---- codec entries ----------------------------------------------------------------------------

constexpr std::size_t kZh3Floats = 15;
constexpr std::size_t kLinearFloats = 12;

void store_zh3(const Zh3& z, std::uint8_t* out) {
    float v[kZh3Floats];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) v[i * 3 + k] = z.linear[i][k];
    for (int k = 0; k < 3; ++k) v[12 + k] = z.zonal[k];
    store_floats(v, out);
}
Zh3 load_zh3(const std::uint8_t* in) {
    float v[kZh3Floats];
    load_floats(in, v);
    Zh3 z;
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) z.linear[i][k] = v[i * 3 + k];
    for (int k = 0; k < 3; ++k) z.zonal[k] = v[12 + k];
    return z;
}

template <ZonalAxisMode Mode>
void encode_fit(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats*) {
    store_zh3(zh3_fit(in, Mode, o.luminance), out);
}
template <ZonalAxisMode Mode>
void encode_solved(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    store_zh3(zh3_solve(in, Mode, o, stats), out);
}
void encode_lum_dering(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, o.luminance);
    const bool clamped = zh3_dering(&z, ZonalAxisMode::kLuminance, o.luminance);
    if (stats) stats->dering_clamped = clamped;
    store_zh3(z, out);
}
void encode_lum_dering_sphere(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, o.luminance);
    const bool clamped = zh3_dering_sphere(&z, ZonalAxisMode::kLuminance, o.luminance);
    if (stats) stats->dering_clamped = clamped;
    store_zh3(z, out);
}
template <ZonalAxisMode Mode>
Sh3Radiance decode_zh3(const std::uint8_t* in, const CodecOptions& o) {
    return zh3_expand(load_zh3(in), Mode, o.luminance);
}
template <ZonalAxisMode Mode>
Rgb irradiance_zh3(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return zh3_irradiance(load_zh3(in), Mode, o.luminance, n);
}

// Hallucinated: the stored bytes are exactly sh2's (DC + L1, 12 floats).
void encode_linear(const Sh3Radiance& in, const CodecOptions&, std::uint8_t* out, EncodeStats*) {
    detail::store_linear(in, out);
}
template <Hallucination Model, ZonalAxisMode Mode>
Sh3Radiance decode_hall(const std::uint8_t* in, const CodecOptions& o) {
    return zh3_expand(zh3_hallucinate(load_linear(in), Model, Mode, o), Mode, o.luminance);
}
template <Hallucination Model, ZonalAxisMode Mode>
Rgb irradiance_hall(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return zh3_irradiance(zh3_hallucinate(load_linear(in), Model, Mode, o), Mode, o.luminance, n);
}

constexpr auto kLum = ZonalAxisMode::kLuminance;
constexpr auto kChan = ZonalAxisMode::kPerChannel;
constexpr auto kAmbDir = Hallucination::kAmbientDirectional;
constexpr auto kSphere = Hallucination::kSphere;
constexpr auto kCurve = Hallucination::kCurve;

constexpr CodecTraits kLumAxis{.zonal_axis = ZonalAxis::kLuminance};
constexpr CodecTraits kChanAxis{.zonal_axis = ZonalAxis::kPerChannel};

const Codec kZh3Codecs[] = {
    {"zh3_lum", "ZH3 fit (Eq. 9/10) on the luminance L1 axis, 15 floats", kZh3Floats * 4, encode_fit<kLum>,
     decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_channel", "ZH3 fit (Eq. 9/10) on each channel's L1 axis, 15 floats", kZh3Floats * 4, encode_fit<kChan>,
     decode_zh3<kChan>, irradiance_zh3<kChan>, kChanAxis},
    {"zh3_solved_lum", "ZH3, luminance axis solved by BFGS (Eq. 11), 15 floats", kZh3Floats * 4,
     encode_solved<kLum>, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_solved_channel", "ZH3, per-channel axes solved by BFGS (Eq. 11), 15 floats", kZh3Floats * 4,
     encode_solved<kChan>, decode_zh3<kChan>, irradiance_zh3<kChan>, kChanAxis},
    {"hall_ambdir", "linear SH + zonal L2 hallucinated, ambient+directional (Eq. 14), luminance axis",
     kLinearFloats * 4, encode_linear, decode_hall<kAmbDir, kLum>, irradiance_hall<kAmbDir, kLum>, kLumAxis},
    {"hall_sphere", "linear SH + zonal L2 hallucinated, sphere light (Eq. 20), luminance axis", kLinearFloats * 4,
     encode_linear, decode_hall<kSphere, kLum>, irradiance_hall<kSphere, kLum>, kLumAxis},
    {"hall_curve", "linear SH + zonal L2 hallucinated, curve fit (Eq. 21), luminance axis", kLinearFloats * 4,
     encode_linear, decode_hall<kCurve, kLum>, irradiance_hall<kCurve, kLum>, kLumAxis},
    {"hall_ambdir_channel", "linear SH + zonal L2 hallucinated, ambient+directional (Eq. 14), channel axes",
     kLinearFloats * 4, encode_linear, decode_hall<kAmbDir, kChan>, irradiance_hall<kAmbDir, kChan>, kChanAxis},
    {"hall_sphere_channel", "linear SH + zonal L2 hallucinated, sphere light (Eq. 20), channel axes",
     kLinearFloats * 4, encode_linear, decode_hall<kSphere, kChan>, irradiance_hall<kSphere, kChan>, kChanAxis},
    {"hall_curve_channel", "linear SH + zonal L2 hallucinated, curve fit (Eq. 21), channel axes",
     kLinearFloats * 4, encode_linear, decode_hall<kCurve, kChan>, irradiance_hall<kCurve, kChan>, kChanAxis},
    {"zh3_lum_dering", "zh3_lum with the zonal L2 clamped for non-negative irradiance (App. B)",
     kZh3Floats * 4, encode_lum_dering, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
    {"zh3_lum_dering_sphere", "zh3_lum, zonal L2 nearest to the fit with irradiance >= 0 on the whole sphere",
     kZh3Floats * 4, encode_lum_dering_sphere, decode_zh3<kLum>, irradiance_zh3<kLum>, kLumAxis},
};

}  // namespace

// ---- public API -------------------------------------------------------------------------------

Vec3 zh3_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w) {
    return normalize_or(axis_source(linear.c.data(), mode, std::clamp(channel, 0, 2), w), {0, 0, 1});
}

bool has_zonal_axis(const Sh2Radiance& linear, ZonalAxisMode mode, int channel, const LuminanceWeights& w) {
    return usable_length(length(axis_source(linear.c.data(), mode, std::clamp(channel, 0, 2), w)));
}

// Eq. 9/10: l20 = sqrt(4 pi / 5) Y2(axis) . f2, the least-squares zonal coefficient along the axis.
Zh3 zh3_fit(const Sh3Radiance& sh, ZonalAxisMode mode, const LuminanceWeights& w) {
    Zh3 z;
    z.linear = truncate_to_sh2(sh);
    const Axes axes(z.linear, mode, w);
    for (int k = 0; k < 3; ++k) z.zonal[k] = static_cast<float>(fit_zonal(sh, k, axes.a[k]));
    return z;
}

Sh3Radiance zh3_expand(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w) {
    Sh3Radiance out = extend_to_sh3(zh3.linear);
    const Axes axes(zh3.linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        // Eq. 2 on a zonal function: f_2^m = f_2^0 sqrt(4 pi / 5) Y_2^m(axis).
        const auto q = y2(axes.a[k]);
        for (int m = 0; m < 5; ++m) out[4 + m][k] = static_cast<float>(zh3.zonal[k] * kSqrtFourPiOverFive * q[static_cast<size_t>(m)]);
    }
    return out;
}

Rgb zh3_irradiance(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w, Vec3 n) {
    Rgb out;
    const Rgb* c = zh3.linear.c.data();
    const Axes axes(zh3.linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        const Vec3 a = axes.a[k];
        const double z = dot(a, n);
        // Listing 1: linear SH with the L1 band scaled by 2/3, plus 1/4 of the zonal L2 term.
        const double e = kY00 * c[0][k] + kIrradianceBandScale[1] * kY1 * dot(l1_vector(c, k), n) +
                         kIrradianceBandScale[2] * zh3.zonal[k] * kY20 * (3.0 * z * z - 1.0);
        out[k] = static_cast<float>(e);
    }
    return out;
}

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

double hallucinate_zonal(Hallucination model, double f0, double f1_zonal, double curve_a, double curve_b) {
    const double f1 = std::fabs(f1_zonal);
    if (model == Hallucination::kAmbientDirectional) {
        // Eq. 14: the directional light's zonal L2 over its zonal L1 is Y20(z=1) / Y10(z=1) = sqrt(5/3).
        return std::sqrt(15.0) / 3.0 * f1;
    }
    if (!(f0 > 0) || !std::isfinite(f0)) return 0.0;
    // p = |f1^0| / f0 in [0, sqrt(3)]: sqrt(3) is a delta light (cos sigma = 1), 0 the full sphere.
    const double p = std::clamp(f1 / f0, 0.0, kSqrt3);
    if (model == Hallucination::kSphere) {
        // Eq. 20 (from Eq. 15 with cos sigma = 2 p / sqrt(3) - 1, Eq. 19).
        return (2.0 * std::sqrt(5.0) / 3.0 * p * p - std::sqrt(5.0 / 3.0) * p) * f0;
    }
    return (curve_a * p * p + curve_b * p) * f0;  // Eq. 21
}

Zh3 zh3_hallucinate(const Sh2Radiance& linear, Hallucination model, ZonalAxisMode mode, const CodecOptions& o) {
    Zh3 z;
    z.linear = linear;
    const Axes axes(linear, mode, o.luminance);
    for (int k = 0; k < 3; ++k) {
        // Listing 1: f1^0 = L1 projected on the zonal axis (the channel's |L1| for per-channel axes).
        const double f1 = dot(l1_vector(linear.c.data(), k), axes.a[k]);
        z.zonal[k] = static_cast<float>(hallucinate_zonal(model, linear[0][k], f1, o.hallucinate_a, o.hallucinate_b));
    }
    return z;
}

// App. B, re-derived (docs/zh3.md). Along the zonal axis, irradiance / (Y00 f0) is
//   g(z) = 1 + a z + b (3 z^2 - 1),  a = 2 f1 / (sqrt(3) f0),  b = sqrt(5) f20 / (8 f0)   (Eq. 23).
// With a >= 0 (g(-z) swaps the sign of a): the end z = -1 needs b >= (a - 1) / 2; for b >= a / 6
// the vertex z* = -a / (6 b) lies in [-1, 0] and needs 12 b^2 - 12 b + a^2 <= 0, i.e.
// b in [b-, b+] = [(1 -+ sqrt(1 - a^2 / 3)) / 2]. Together:
//   a <= 3/2:           b in [(a - 1) / 2, b+]
//   3/2 < a <= sqrt(3): b in [b-, b+]          (the paper's Eq. 25 lower bound is too low here)
//   a > sqrt(3):        infeasible; b = a / (2 sqrt(3)) maximises min g (= 1 - a / sqrt(3)).
// The paper's upper bound sqrt(5)/4 (Eq. 24-26) is neither b+ (which runs from 1 to 1/2) nor safe
// near a = sqrt(3); see docs/zh3.md.
ZonalInterval zh3_dering_interval(double f0, double f1_zonal) {
    ZonalInterval out;
    if (!(f0 > 0) || !std::isfinite(f0) || !std::isfinite(f1_zonal)) return out;  // nothing is safe
    const double a = std::fabs(2.0 * f1_zonal / (kSqrt3 * f0));
    const double to_f20 = 8.0 * f0 / std::sqrt(5.0);  // f20 = b * 8 f0 / sqrt(5)
    if (a > kSqrt3) {
        out.lo = out.hi = a / (2.0 * kSqrt3) * to_f20;
        return out;
    }
    const double root = std::sqrt(std::max(0.0, 1.0 - a * a / 3.0));
    const double lo = a <= 1.5 ? (a - 1.0) / 2.0 : (1.0 - root) / 2.0;
    out.lo = lo * to_f20;
    out.hi = (1.0 + root) / 2.0 * to_f20;
    out.feasible = true;
    return out;
}

bool zh3_dering(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w) {
    bool clamped = false;
    const Axes axes(zh3->linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        // Only the L1 component along the zonal axis enters g(z); see docs/zh3.md for what that
        // guarantees when the channel's L1 is not parallel to the axis.
        const double f1 = dot(l1_vector(zh3->linear.c.data(), k), axes.a[k]);
        const ZonalInterval iv = zh3_dering_interval(zh3->linear[0][k], f1);
        const double f20 = zh3->zonal[k];
        const double c = std::isfinite(f20) ? std::clamp(f20, iv.lo, iv.hi) : iv.lo;
        if (c != f20) {
            zh3->zonal[k] = static_cast<float>(c);
            clamped = true;
        }
    }
    return clamped;
}

namespace {
// h(theta) = 1 + a cos t - c sin t + b (3 cos^2 t - 1) over [0, pi]: a trigonometric polynomial of
// degree 2 (1 + b/2 + a cos t - c sin t + (3b/2) cos 2t), so it has at most four critical points
// per period. Sampling 33 points (tabulated) and polishing every sampled local minimum by Newton
// finds the minimum to rounding.
struct SampleTable {
    static constexpr int kSamples = 32;
    double cos_t[kSamples + 1], sin_t[kSamples + 1];
    SampleTable() {
        for (int i = 0; i <= kSamples; ++i) {
            cos_t[i] = std::cos(kPi * i / kSamples);
            sin_t[i] = std::sin(kPi * i / kSamples);
        }
    }
};

double sphere_min_ratio(double a, double c, double b) {
    static const SampleTable table;
    constexpr int n = SampleTable::kSamples;
    auto h = [&](double ct, double st) { return 1.0 + a * ct - c * st + b * (3.0 * ct * ct - 1.0); };
    double v[n + 1];
    for (int i = 0; i <= n; ++i) v[i] = h(table.cos_t[i], table.sin_t[i]);
    double best = 1e300;
    for (int i = 0; i <= n; ++i) {
        best = std::min(best, v[i]);
        // Newton from every discrete local minimum, the end samples included: with a small c the
        // minimum can sit between the last two samples while v[n] < v[n - 1] (h'(pi) = c > 0), and
        // the end sample alone would overestimate it (a test found 1.5e-4 of the DC this way).
        if (!((i == 0 || v[i] <= v[i - 1]) && (i == n || v[i] <= v[i + 1]))) continue;
        // Newton on theta, carried as (cos, sin) and rotated by the step: every iterate is a real
        // direction, so h there is an upper bound of the minimum that converges to it. Steps stay
        // within one sample spacing (pi/32), where the Taylor rotation is accurate to ~1e-10.
        double ct = table.cos_t[i], st = table.sin_t[i];
        const double max_step = kPi / n;
        for (int it = 0; it < 5; ++it) {
            const double d1 = -a * st - c * ct - 6.0 * b * st * ct;            // h'
            const double d2 = -a * ct + c * st - 6.0 * b * (ct * ct - st * st);  // h''
            if (!(d2 > 0)) break;
            const double delta = std::clamp(-d1 / d2, -max_step, max_step);
            const double d2s = delta * delta;
            const double cd = 1.0 - d2s / 2.0 * (1.0 - d2s / 12.0), sd = delta * (1.0 - d2s / 6.0 * (1.0 - d2s / 20.0));
            double nc = ct * cd - st * sd, ns = st * cd + ct * sd;
            if (ns < 0) break;  // left [0, pi]: the end samples cover it
            const double len = std::sqrt(nc * nc + ns * ns);
            nc /= len;
            ns /= len;
            ct = nc;
            st = ns;
            if (std::fabs(delta) < 1e-12) break;
        }
        best = std::min(best, h(ct, st));
    }
    return best;
}
}  // namespace

double zh3_dering_sphere_zonal(double f0, double f1_zonal, double f1_perp, double f20, bool* clamped) {
    *clamped = false;
    if (!(f0 > 0) || !std::isfinite(f0) || !std::isfinite(f1_zonal) || !std::isfinite(f1_perp)) {
        *clamped = f20 != 0.0;
        return 0.0;
    }
    const double a = 2.0 * f1_zonal / (kSqrt3 * f0), c = std::fabs(2.0 * f1_perp / (kSqrt3 * f0));
    const double to_f20 = 8.0 * f0 / std::sqrt(5.0);
    const double b0 = std::isfinite(f20) ? f20 / to_f20 : 0.0;
    // F(b) = min over the sphere is concave in b (a minimum of affine functions), so {F >= 0} is an
    // interval and the nearest feasible b lies between b0 and the maximiser of F.
    auto f = [&](double b) { return sphere_min_ratio(a, c, b); };
    if (std::isfinite(f20) && f(b0) >= 0) return f20;
    *clamped = true;
    // F(b) <= 1 - b - c at z = 0 and <= 1 + 2b - |a| at z = -+1: the maximiser lies in this bracket.
    const double r = std::sqrt(a * a + c * c);
    double lo = -1.0 - r, hi = 1.0 + r;
    const double phi = (std::sqrt(5.0) - 1.0) / 2.0;
    double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo), f1 = f(x1), f2 = f(x2);
    for (int it = 0; it < 60 && hi - lo > 1e-9 * (1.0 + r); ++it) {  // golden section on concave F
        if (f1 < f2) {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + phi * (hi - lo);
            f2 = f(x2);
        } else {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - phi * (hi - lo);
            f1 = f(x1);
        }
    }
    const double bstar = f1 >= f2 ? x1 : x2;
    if (!(f(bstar) >= 0) || !std::isfinite(b0)) return bstar * to_f20;  // nothing is safe: least negative
    // Bisection between the infeasible b0 and the feasible bstar; keep the feasible end.
    double bad = b0, good = bstar;
    for (int it = 0; it < 60 && std::fabs(good - bad) > 1e-9 * (1.0 + r); ++it) {
        const double mid = 0.5 * (bad + good);
        (f(mid) >= 0 ? good : bad) = mid;
    }
    return good * to_f20;
}

bool zh3_dering_sphere(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w) {
    bool any = false;
    const Axes axes(zh3->linear, mode, w);
    for (int k = 0; k < 3; ++k) {
        const Vec3 axis = axes.a[k];
        const Vec3 v = l1_vector(zh3->linear.c.data(), k);
        const double along = dot(v, axis);
        const double across = length(v - along * axis);
        bool clamped = false;
        const double c = zh3_dering_sphere_zonal(zh3->linear[0][k], along, across, zh3->zonal[k], &clamped);
        if (clamped) {
            // The stored value is a float: step it by ulps further into the feasible side (away from
            // the infeasible original) until the stored value itself passes.
            const double f0 = zh3->linear[0][k];
            const float from = zh3->zonal[k];
            float cf = static_cast<float>(c);
            if (f0 > 0 && std::isfinite(from) &&
                sphere_min_ratio(2.0 * along / (kSqrt3 * f0), 2.0 * across / (kSqrt3 * f0), c * std::sqrt(5.0) / (8.0 * f0)) >= 0) {
                const float toward = c > from ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
                const double a = 2.0 * along / (kSqrt3 * f0), cc = 2.0 * across / (kSqrt3 * f0);
                for (int step = 0; step < 8 && sphere_min_ratio(a, cc, cf * std::sqrt(5.0) / (8.0 * f0)) < 0; ++step)
                    cf = std::nextafter(cf, toward);
            }
            zh3->zonal[k] = cf;
            any = true;
        }
    }
    return any;
}

std::span<const Codec> zh3_codecs() { return kZh3Codecs; }

}  // namespace zhc
