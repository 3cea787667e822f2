// zhc/codec/probe/lbfgs.h — internal to codec/: L-BFGS (limited-memory BFGS, two-loop recursion)
// with a backtracking Armijo line search, for the ZH3 axis solves (zh3_solve.cpp).
//
// Source: Nocedal & Wright, "Numerical Optimization" (2nd ed., 2006), Alg. 7.4 (two-loop
// recursion), Alg. 7.5 (L-BFGS), Eq. 7.20 (initial scaling); Armijo condition Eq. 3.6a.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace zhc::detail {

// Relative step below which L-BFGS stops (|x_new - x| <= kLbfgsStepTolerance |x|): the iteration
// cap is a guard, not the usual stop.
inline constexpr double kLbfgsStepTolerance = 1e-12;

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
        double step = 1.0, en = std::numeric_limits<double>::infinity();
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
        if (ss <= kLbfgsStepTolerance * kLbfgsStepTolerance * xx) {  // converged in x: this step counts, stop
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

}  // namespace zhc::detail
