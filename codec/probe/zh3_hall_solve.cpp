// Hallucinate-solve and the adaptive hallucination scale (codec/probe/zh3_hall_solve.h; derivation in docs/zh3.md).
//
// Vector form as codec/probe/zh3_internal.h: channel k's radiance L1 (f1-1, f10, f11) is v = (-f11, -f1-1, f10).
// Error in irradiance SH (band scales 1, 2/3, 1/4), per channel, with u the target's L1 vector, T2
// its radiance L2, q = sqrt(4 pi/5) Y2(a) (a unit 5-vector) and h = q . T2:
//   e = (4/9) |v - u|^2 + (1/16) (f20^2 - 2 f20 h + |T2|^2),   f20 = G(|v . a| / f0) f0.
// Write v = alpha a + beta (beta orthogonal to a). The decoder's axis is a exactly when the axis
// source (luminance: sum_k w_k v_k; per channel: v_k) is along a, i.e. sum_k w_k beta_k = 0 (beta = 0
// per channel). The beta part then costs (4/9) |P_perp U|^2 / |w|^2 (U = sum_k w_k u_k, the ZH3
// solve's profile) at beta_k = P_perp u_k - w_k P_perp U / |w|^2, and each alpha_k is a 1-D problem:
// with x = |alpha| / f0, gamma = |u . a| / f0, eta = h / f0 (alpha takes the sign of u . a):
//   F(x) = (4/9) (x - gamma)^2 + (1/16) (G(x)^2 - 2 G(x) eta),  G(x) = s (A p^2 + B p), p = min(x, sqrt 3)
// F' on [0, sqrt 3] is the cubic (A'^2/4) x^3 + (3 A'B'/8) x^2 + (B'^2/8 - A' eta/4 + 8/9) x
// - (B' eta/8 + 8 gamma/9) (A' = s A, B' = s B); above sqrt 3, G is constant and F is least at
// max(gamma, sqrt 3). The minimum is among x = 0, the cubic's roots in [0, sqrt 3] and that point.
#include "codec/probe/zh3_hall_solve.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "codec/sh/sh_l1.h"

namespace zhc {
namespace {

const double kSqrt3 = std::sqrt(3.0);
const double kSqrtFourPiOverFive = std::sqrt(4.0 * kPi / 5.0);
constexpr double kL1Weight = 4.0 / 9.0;   // (2/3)^2
constexpr double kL2Weight = 1.0 / 16.0;  // (1/4)^2

using detail::l1_vector;
using detail::set_l1;

// q = sqrt(4 pi / 5) Y2(a): the unit L2 direction of a zonal function along a.
std::array<double, 5> zonal_dir(Vec3 a) {
    const double s = kSqrtFourPiOverFive;
    return {s * kY2 * a.x * a.y, -s * kY2 * a.y * a.z, s * kY20 * (3.0 * a.z * a.z - 1.0), -s * kY2 * a.x * a.z,
            s * kY22 * (a.x * a.x - a.y * a.y)};
}
// Gradient with respect to a of q(a) . r (the Cartesian polynomials differentiated).
Vec3 zonal_dir_grad(Vec3 a, const double* r) {
    const double s = kSqrtFourPiOverFive;
    return {s * (kY2 * a.y * r[0] - kY2 * a.z * r[3] + 2.0 * kY22 * a.x * r[4]),
            s * (kY2 * a.x * r[0] - kY2 * a.z * r[1] - 2.0 * kY22 * a.y * r[4]),
            s * (-kY2 * a.y * r[1] + 6.0 * kY20 * a.z * r[2] - kY2 * a.x * r[3])};
}

// The solve's data, normalised (multiplied by a power of two near 1 / magnitude).
struct Problem {
    double f0[3];
    Vec3 u[3];
    double t2[3][5];
    double t2sq[3];
    double w[3];      // axis-source weights of the channels in the group (luminance, or 1 for the one channel)
    int first = 0, last = 2;  // channels in the group
    double A = 0, B = 0;      // s * hallucinate_a, s * hallucinate_b
};

// min over x >= 0 of F (header comment); returns x.
double solve_alpha_ratio(double gamma, double eta, double A, double B) {
    auto G = [&](double x) {
        const double p = std::min(x, kSqrt3);
        return A * p * p + B * p;
    };
    auto F = [&](double x) {
        const double g = G(x);
        return kL1Weight * (x - gamma) * (x - gamma) + kL2Weight * (g * g - 2.0 * g * eta);
    };
    const double c3 = A * A / 4.0, c2 = 3.0 * A * B / 8.0, c1 = B * B / 8.0 - A * eta / 4.0 + 8.0 / 9.0,
                 c0 = -(B * eta / 8.0 + 8.0 * gamma / 9.0);
    auto P = [&](double x) { return ((c3 * x + c2) * x + c1) * x + c0; };
    auto dP = [&](double x) { return (3.0 * c3 * x + 2.0 * c2) * x + c1; };
    // Monotone pieces of P on [0, sqrt 3]: split at the real roots of P'.
    double cuts[4] = {0.0, kSqrt3, kSqrt3, kSqrt3};
    int n = 1;
    const double qa = 3.0 * c3, qb = 2.0 * c2, qc = c1;
    if (qa != 0.0) {
        const double disc = qb * qb - 4.0 * qa * qc;
        if (disc > 0.0) {
            const double sq = std::sqrt(disc);
            // Numerically stable pair of roots.
            const double t = -0.5 * (qb + std::copysign(sq, qb));
            double r1 = t / qa, r2 = t != 0.0 ? qc / t : r1;
            if (r1 > r2) std::swap(r1, r2);
            for (double r : {r1, r2})
                if (r > 0.0 && r < kSqrt3) cuts[n++] = r;
        }
    }
    cuts[n++] = kSqrt3;
    double best_x = 0.0, best_f = F(0.0);
    auto consider = [&](double x) {
        const double f = F(x);
        if (f < best_f) {
            best_f = f;
            best_x = x;
        }
    };
    for (int i = 0; i + 1 < n; ++i) {
        double lo = cuts[i], hi = cuts[i + 1];
        double plo = P(lo), phi = P(hi);
        if (!(plo < 0.0 && phi > 0.0)) {  // a minimum of F needs F' going from - to +
            consider(hi);
            continue;
        }
        // Safeguarded Newton on the bracket [lo, hi].
        double x = 0.5 * (lo + hi);
        for (int it = 0; it < 100; ++it) {
            const double px = P(x);
            if (px == 0.0) break;
            if (px < 0.0) lo = x;
            else hi = x;
            const double d = dP(x);
            double next = d > 0.0 ? x - px / d : 0.5 * (lo + hi);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
            if (std::fabs(next - x) <= 1e-14 * (x + 1e-3) || hi - lo <= 1e-15 * hi) {
                x = next;
                break;
            }
            x = next;
        }
        consider(x);
    }
    consider(std::max(gamma, kSqrt3));
    return best_x;
}

struct ChannelSolution {
    double alpha = 0, g = 0;  // L1 along the axis (signed), hallucinated zonal f20
};

// Profile at unit axis a (header comment) and, optionally, its gradient with respect to a (envelope
// theorem: the inner minimisers are held fixed) and the minimisers.
double profile(const Problem& pr, Vec3 a, Vec3* grad, ChannelSolution* sol) {
    const auto q = zonal_dir(a);
    Vec3 U{};
    double ww = 0;
    for (int k = pr.first; k <= pr.last; ++k) {
        U = U + pr.w[k] * pr.u[k];
        ww += pr.w[k] * pr.w[k];
    }
    const double ua = dot(U, a);
    const Vec3 perp = U - ua * a;
    double e = kL1Weight * dot(perp, perp) / ww;
    Vec3 g = (-2.0 * kL1Weight * ua / ww) * U;
    for (int k = pr.first; k <= pr.last; ++k) {
        const double c = dot(pr.u[k], a);
        double h = 0;
        for (int m = 0; m < 5; ++m) h += q[static_cast<size_t>(m)] * pr.t2[k][m];
        ChannelSolution s;
        if (pr.f0[k] > 0.0 && std::isfinite(pr.f0[k]) && (pr.A != 0.0 || pr.B != 0.0)) {
            const double f0 = pr.f0[k];
            const double x = solve_alpha_ratio(std::fabs(c) / f0, h / f0, pr.A, pr.B);
            const double p = std::min(x, kSqrt3);
            s.alpha = std::copysign(x * f0, c);
            s.g = (pr.A * p * p + pr.B * p) * f0;
        } else {
            s.alpha = c;
        }
        e += kL1Weight * (s.alpha - c) * (s.alpha - c) + kL2Weight * (s.g * s.g - 2.0 * s.g * h + pr.t2sq[k]);
        if (grad && s.g != 0.0) g = g - (2.0 * kL2Weight * s.g) * zonal_dir_grad(a, pr.t2[k]);
        if (grad) g = g - (2.0 * kL1Weight * (s.alpha - c)) * pr.u[k];
        if (sol) sol[k] = s;
    }
    if (grad) *grad = g;
    return e;
}

// Symmetric 3x3 eigenvectors by cyclic Jacobi (deterministic, a fixed sweep count).
void eigenvectors(double m[3][3], Vec3 out[3]) {
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 12; ++sweep) {
        for (int p = 0; p < 2; ++p)
            for (int r = p + 1; r < 3; ++r) {
                if (std::fabs(m[p][r]) < 1e-300) continue;
                const double theta = 0.5 * (m[r][r] - m[p][p]) / m[p][r];
                const double t = std::copysign(1.0, theta) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) {
                    const double mkp = m[k][p], mkr = m[k][r];
                    m[k][p] = c * mkp - s * mkr;
                    m[k][r] = s * mkp + c * mkr;
                }
                for (int k = 0; k < 3; ++k) {
                    const double mpk = m[p][k], mrk = m[r][k];
                    m[p][k] = c * mpk - s * mrk;
                    m[r][k] = s * mpk + c * mrk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkr = v[k][r];
                    v[k][p] = c * vkp - s * vkr;
                    v[k][r] = s * vkp + c * vkr;
                }
            }
    }
    for (int j = 0; j < 3; ++j) out[j] = {v[0][j], v[1][j], v[2][j]};
}

// The traceless quadratic form of a radiance L2 band: Y2(a) . f2 = a^T Q a on the unit sphere.
void l2_form(const double* f2, double q[3][3]) {
    const double xy = 0.5 * kY2 * f2[0], yz = -0.5 * kY2 * f2[1], xz = -0.5 * kY2 * f2[3];
    const double z = kY20 * f2[2], d = kY22 * f2[4];
    q[0][0] = -z + d;
    q[1][1] = -z - d;
    q[2][2] = 2.0 * z;
    q[0][1] = q[1][0] = xy;
    q[1][2] = q[2][1] = yz;
    q[0][2] = q[2][0] = xz;
}

// BFGS over the axis in the gnomonic chart around a0: a(x) = normalize(a0 + x0 e1 + x1 e2), which
// covers every axis not orthogonal to a0 (a and -a are the same decoder axis). Returns the error.
double refine(const Problem& pr, Vec3* axis, int max_iterations, int* iterations) {
    const Vec3 a0 = *axis;
    const Mat3 frame = frame_from_z(a0);
    const Vec3 e1{frame(0, 0), frame(1, 0), frame(2, 0)}, e2{frame(0, 1), frame(1, 1), frame(2, 1)};
    auto eval = [&](const double x[2], double g[2], Vec3* a_out) {
        const Vec3 y = a0 + x[0] * e1 + x[1] * e2;
        const double len = length(y);
        const Vec3 a = (1.0 / len) * y;
        Vec3 ga;
        const double f = profile(pr, a, &ga, nullptr);
        const Vec3 gy = (1.0 / len) * (ga - dot(ga, a) * a);  // (I - a a^T) / |y|
        g[0] = dot(gy, e1);
        g[1] = dot(gy, e2);
        if (a_out) *a_out = a;
        return f;
    };
    double x[2] = {0, 0}, g[2];
    Vec3 a = a0;
    double f = eval(x, g, &a);
    double H[2][2] = {{1, 0}, {0, 1}};
    // Scale of the objective (normalised target: O(1)); the stop is relative to it.
    const double fscale = std::max(f, 1e-300);
    int it = 0;
    for (; it < max_iterations; ++it) {
        const double gn = std::sqrt(g[0] * g[0] + g[1] * g[1]);
        if (!(gn > 1e-6 * std::sqrt(fscale)) || !std::isfinite(f)) break;
        double d[2] = {-(H[0][0] * g[0] + H[0][1] * g[1]), -(H[1][0] * g[0] + H[1][1] * g[1])};
        double slope = d[0] * g[0] + d[1] * g[1];
        if (!(slope < 0.0)) {
            H[0][0] = H[1][1] = 1;
            H[0][1] = H[1][0] = 0;
            d[0] = -g[0];
            d[1] = -g[1];
            slope = -(gn * gn);
        }
        // Cap the step in the chart (axes far from a0 are badly conditioned there).
        const double dn = std::sqrt(d[0] * d[0] + d[1] * d[1]);
        double t = dn > 0.5 ? 0.5 / dn : 1.0;
        double xn[2], gnew[2], fn = f;
        Vec3 an = a;
        bool accepted = false;
        for (int ls = 0; ls < 30; ++ls) {
            xn[0] = x[0] + t * d[0];
            xn[1] = x[1] + t * d[1];
            fn = eval(xn, gnew, &an);
            if (fn <= f + 1e-4 * t * slope) {
                accepted = true;
                break;
            }
            t *= 0.5;
        }
        if (!accepted) break;
        const double s[2] = {xn[0] - x[0], xn[1] - x[1]};
        const double yv[2] = {gnew[0] - g[0], gnew[1] - g[1]};
        const double sy = s[0] * yv[0] + s[1] * yv[1];
        const double step = std::sqrt(s[0] * s[0] + s[1] * s[1]);
        const double df = f - fn;
        x[0] = xn[0];
        x[1] = xn[1];
        g[0] = gnew[0];
        g[1] = gnew[1];
        f = fn;
        a = an;
        if (sy > 1e-300) {
            // BFGS inverse update: H = (I - r s y^T) H (I - r y s^T) + r s s^T.
            const double r = 1.0 / sy;
            const double Hy[2] = {H[0][0] * yv[0] + H[0][1] * yv[1], H[1][0] * yv[0] + H[1][1] * yv[1]};
            const double yHy = yv[0] * Hy[0] + yv[1] * Hy[1];
            for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j)
                    H[i][j] += (1.0 + r * yHy) * r * s[i] * s[j] - r * (Hy[i] * s[j] + s[i] * Hy[j]);
        }
        if (step <= 1e-12 * (1.0 + std::sqrt(x[0] * x[0] + x[1] * x[1])) || df <= 1e-12 * fscale) {
            ++it;
            break;
        }
    }
    *axis = a;
    if (iterations) *iterations += it;
    return f;
}

Problem make_problem(const Sh3Radiance& target, double scale, const CodecOptions& o, double norm) {
    Problem pr;
    for (int k = 0; k < 3; ++k) {
        pr.f0[k] = norm * target[0][k];
        pr.u[k] = norm * l1_vector(target.c.data(), k);
        pr.t2sq[k] = 0;
        for (int m = 0; m < 5; ++m) {
            pr.t2[k][m] = norm * target[4 + m][k];
            pr.t2sq[k] += pr.t2[k][m] * pr.t2[k][m];
        }
    }
    pr.A = scale * o.hallucinate_a;
    pr.B = scale * o.hallucinate_b;
    pr.w[0] = o.luminance.r;
    pr.w[1] = o.luminance.g;
    pr.w[2] = o.luminance.b;
    return pr;
}

double magnitude(const Sh3Radiance& t) {
    double m = 0;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) m += double(t[i][k]) * t[i][k];
    return std::sqrt(m);
}

// Best axis for the group in `pr`: candidates ranked by the profile, the best one refined. With a
// warm start (the axis solved for a neighbouring scale) the candidates are that axis and the target's
// L1 axis only.
Vec3 solve_axis(const Problem& pr, const Vec3& fallback, int* iterations, const Vec3* warm) {
    Vec3 cands[12];
    int n = 0;
    auto add = [&](Vec3 v) {
        const double len = length(v);
        if (len > 0.0 && std::isfinite(len)) cands[n++] = (1.0 / len) * v;
    };
    Vec3 U{};
    double f2[5] = {};
    for (int k = pr.first; k <= pr.last; ++k) {
        U = U + pr.w[k] * pr.u[k];
        for (int m = 0; m < 5; ++m) f2[m] += pr.w[k] * pr.t2[k][m];
    }
    if (warm) add(*warm);
    add(U);
    if (!warm) {
        double q[3][3];
        l2_form(f2, q);
        Vec3 ev[3];
        eigenvectors(q, ev);
        for (const Vec3& e : ev) add(e);
        if (pr.first != pr.last)
            for (int k = pr.first; k <= pr.last; ++k) add(pr.u[k]);
    }
    if (n == 0) return fallback;
    double err[12];
    int order[12];
    for (int i = 0; i < n; ++i) {
        err[i] = profile(pr, cands[i], nullptr, nullptr);
        order[i] = i;
    }
    std::stable_sort(order, order + n, [&](int a, int b) { return err[a] < err[b]; });
    Vec3 best = cands[order[0]];
    double best_err = err[order[0]];
    const int starts = std::min(n, 1);
    for (int s = 0; s < starts; ++s) {
        Vec3 a = cands[order[s]];
        const double e = refine(pr, &a, 100, iterations);
        if (e < best_err) {
            best_err = e;
            best = a;
        }
    }
    return best;
}

}  // namespace

double irradiance_sq_error(const Sh3Radiance& target, const Sh3Radiance& decoded) {
    double e = 0;
    for (int i = 0; i < 9; ++i) {
        const double s = kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)];
        for (int k = 0; k < 3; ++k) {
            const double d = s * (double(decoded[i][k]) - double(target[i][k]));
            e += d * d;
        }
    }
    return e;
}

Sh3Radiance hall_scaled_expand(const Sh2Radiance& linear, double scale, ZonalAxisMode mode, const CodecOptions& o) {
    CodecOptions s = o;
    s.hallucinate_a = scale * o.hallucinate_a;
    s.hallucinate_b = scale * o.hallucinate_b;
    return zh3_expand(zh3_hallucinate(linear, Hallucination::kCurve, mode, s), mode, o.luminance);
}

double hall_axis_profile(const Sh3Radiance& target, double scale, ZonalAxisMode mode, int channel, Vec3 axis,
                         const CodecOptions& o) {
    Problem pr = make_problem(target, scale, o, 1.0);
    if (mode == ZonalAxisMode::kPerChannel) {
        pr.first = pr.last = std::clamp(channel, 0, 2);
        pr.w[pr.first] = 1.0;
    }
    return profile(pr, normalize_or(axis, {0, 0, 1}), nullptr, nullptr);
}

namespace {
// hall_solve with optional warm-start axes (one per channel; all equal for the luminance axis),
// updated to the solved axes.
Sh2Radiance solve_impl(const Sh3Radiance& target, double scale, ZonalAxisMode mode, const CodecOptions& o,
                       EncodeStats* stats, Vec3* warm, bool use_warm) {
    const Sh2Radiance plain = truncate_to_sh2(target);
    const double mag = magnitude(target);
    const double ww = o.luminance.r * o.luminance.r + o.luminance.g * o.luminance.g + o.luminance.b * o.luminance.b;
    if (!(scale != 0.0) || !std::isfinite(scale) || !(mag > 0.0) || !std::isfinite(mag) ||
        (mode == ZonalAxisMode::kLuminance && !(ww > 0.0 && std::isfinite(ww))))
        return plain;
    // Scale invariance: work on the target times a power of two (exact), so |target| is in [1, 2).
    const double norm = std::ldexp(1.0, -std::ilogb(mag));
    Problem pr = make_problem(target, scale, o, norm);
    int iterations = 0;
    Sh2Radiance out = plain;
    auto write_group = [&](const Problem& p, Vec3 a) {
        ChannelSolution sol[3];
        profile(p, a, nullptr, sol);
        Vec3 U{};
        double wsum = 0;
        for (int k = p.first; k <= p.last; ++k) {
            U = U + p.w[k] * p.u[k];
            wsum += p.w[k] * p.w[k];
        }
        const Vec3 Uperp = U - dot(U, a) * a;
        for (int k = p.first; k <= p.last; ++k) {
            const Vec3 uperp = p.u[k] - dot(p.u[k], a) * a;
            const Vec3 beta = uperp - (p.w[k] / wsum) * Uperp;
            set_l1(out.c.data(), k, (1.0 / norm) * (sol[k].alpha * a + beta));
        }
    };
    if (mode == ZonalAxisMode::kLuminance) {
        const Vec3 a = solve_axis(pr, {0, 0, 1}, &iterations, use_warm ? &warm[0] : nullptr);
        write_group(pr, a);
        if (warm) warm[0] = warm[1] = warm[2] = a;
    } else {
        for (int k = 0; k < 3; ++k) {
            Problem p = pr;
            p.first = p.last = k;
            p.w[k] = 1.0;
            const Vec3 a = solve_axis(p, {0, 0, 1}, &iterations, use_warm ? &warm[k] : nullptr);
            write_group(p, a);
            if (warm) warm[k] = a;
        }
    }
    if (stats) stats->solver_iterations += iterations;
    // Guarantee, on what the decoder actually computes: never worse than the target's own L1.
    const double e_out = irradiance_sq_error(target, hall_scaled_expand(out, scale, mode, o));
    const double e_plain = irradiance_sq_error(target, hall_scaled_expand(plain, scale, mode, o));
    return e_out < e_plain ? out : plain;
}
}  // namespace

Sh2Radiance hall_solve(const Sh3Radiance& target, double scale, ZonalAxisMode mode, const CodecOptions& o,
                       EncodeStats* stats) {
    return solve_impl(target, scale, mode, o, stats, nullptr, false);
}

double hall_scale_of_code(std::uint8_t code) {
    return 0.5 * std::min<int>(code, kHallScaleCodeCount - 1);
}

// ---- packed entries ---------------------------------------------------------------------------

namespace {
constexpr int kScaleByte = 15;

Sh3Radiance with_target_dc(const Sh2Radiance& linear) { return extend_to_sh3(linear); }

Sh3Radiance decode_packed_hall(bool adaptive, const std::uint8_t* in, const CodecOptions& p) {
    const Sh3Radiance linear = decode_packed(PackedLayout::kSh2Q, in, p);
    const double s = adaptive ? hall_scale_of_code(in[kScaleByte]) : 1.0;
    return hall_scaled_expand(truncate_to_sh2(linear), s, p.axis_mode, p);
}

// Encodes the candidate linear SH with scale code `code` and returns the decoder's error.
double encode_candidate(bool adaptive, const Sh3Radiance& target, const Sh2Radiance& linear, std::uint8_t code,
                        const CodecOptions& p, std::uint8_t* out, EncodeStats* stats) {
    encode_packed(PackedLayout::kSh2Q, with_target_dc(linear), p, out, stats);
    if (adaptive) out[kScaleByte] = code;
    return irradiance_sq_error(target, decode_packed_hall(adaptive, out, p));
}

void encode_hall_packed(bool adaptive, const Sh3Radiance& hub, const CodecOptions& p, std::uint8_t* out,
                        EncodeStats* stats) {
    std::uint8_t best[16], cand[16];
    // Candidate 0: the target's own L1 (s = 0 for the adaptive layout: exactly sh2_q plus a zero
    // byte; s = 1 for hall_solved_q16: exactly hall_curve_q's bytes).
    EncodeStats best_stats, cand_stats;
    const Sh2Radiance plain = truncate_to_sh2(hub);
    double best_err = encode_candidate(adaptive, hub, plain, 0, p, best, &best_stats);
    int iterations = 0;
    const int first = adaptive ? 1 : 0;
    const int last = adaptive ? kHallScaleCodeCount - 1 : 0;
    // The scales are solved in increasing order, each starting from the previous scale's axes (the
    // optimum moves little between neighbouring scales; the first is a full multi-candidate solve).
    Vec3 warm[3];
    for (int code = first; code <= last; ++code) {
        const double s = adaptive ? hall_scale_of_code(static_cast<std::uint8_t>(code)) : 1.0;
        EncodeStats solve_stats;
        const Sh2Radiance lin = solve_impl(hub, s, p.axis_mode, p, &solve_stats, warm, code > first);
        iterations += solve_stats.solver_iterations;
        cand_stats = {};
        const double e = encode_candidate(adaptive, hub, lin, static_cast<std::uint8_t>(code), p, cand, &cand_stats);
        if (e < best_err) {
            best_err = e;
            std::memcpy(best, cand, 16);
            best_stats = cand_stats;
        }
    }
    std::memcpy(out, best, 16);
    if (stats) {
        stats->clamped_ratios += best_stats.clamped_ratios;
        stats->solver_iterations += iterations;
    }
}
}  // namespace

// ---- codec table entries ------------------------------------------------------------------------

namespace {

using detail::load_linear;
using detail::store_linear;

void encode_solved(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    store_linear(hall_solve(in, 1.0, ZonalAxisMode::kLuminance, o, stats), out);
}
Sh3Radiance decode_solved(const std::uint8_t* in, const CodecOptions& o) {
    return hall_scaled_expand(load_linear(in), 1.0, ZonalAxisMode::kLuminance, o);
}
Rgb irradiance_solved(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return zh3_irradiance(zh3_hallucinate(load_linear(in), Hallucination::kCurve, ZonalAxisMode::kLuminance, o),
                          ZonalAxisMode::kLuminance, o.luminance, n);
}

// The packed entries' encoder/decoder (Codec::packed), with every parameter in one CodecOptions.
template <bool Adaptive>
void encode_q(const Sh3Radiance& hub, const CodecOptions& params, std::uint8_t* out, EncodeStats* stats) {
    encode_hall_packed(Adaptive, hub, params, out, stats);
}
template <bool Adaptive>
Sh3Radiance decode_q(const std::uint8_t* in, const CodecOptions& params) {
    return decode_packed_hall(Adaptive, in, params);
}

constexpr PackedCodec kHallSolvedQ16{PackedLayout::kSh2Q, encode_q<false>, decode_q<false>};
constexpr PackedCodec kHallAdaptiveQ16{PackedLayout::kSh2Q, encode_q<true>, decode_q<true>};

const Codec kHallSolveCodecs[] = {
    {"hall_solved", "hall_curve's bytes and decoder; encoder solves the L1 for the error after hallucination", 48,
     encode_solved, decode_solved, irradiance_solved,
     {.zonal_axis = ZonalAxis::kLuminance, .hallucination = ZonalHallucination::kCurve}},
    packed_codec<kHallSolvedQ16>("hall_solved_q16",
                                 "hall_curve_q's bytes and decoder; encoder solves the L1 (quantised, checked)",
                                 ZonalAxis::kFromParams, ZonalHallucination::kCurve),
    packed_codec<kHallAdaptiveQ16>("hall_adaptive_q16",
                                   "sh2_q bytes + per-probe hallucination scale code (byte 15), L1 solved for it",
                                   ZonalAxis::kFromParams, ZonalHallucination::kCurveAdaptive),
};
}  // namespace

std::span<const Codec> hall_solve_codecs() { return kHallSolveCodecs; }

}  // namespace zhc
