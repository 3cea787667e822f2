// zhc/codec/lightmap/irradz_search.cpp — the IrradZ encoder (encode) and its reference solve of the
// direction d: a scan over theta at the azimuth of the optimal linear direction then golden-section
// search (the talk), and rounds of golden section in phi and theta (beyond the talk), each
// direction with the closed-form least-squares w_a under the hemispherical Gram matrix; also the
// "old way" (optimal linear direction, whole-sphere w_a) kept for comparison. The default solve,
// Newton, is in irradz_newton.cpp. Derivations in docs/irradz.md ("Encoder").
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

}  // namespace

IrradZ solve_w_a(const Sh3Irradiance& target, Vec3 d, Model model, const std::array<double, 81>& gram) {
    const Target tg = make_target(target, gram);
    d = clamp_to_hemisphere(d);
    return make(tg, fit_direction(tg, d, model, gram).w, d);
}

void encode_many(const Sh3Radiance* tangent_radiance, std::size_t n, const EncodeOptions& options, IrradZ* out) {
    if (options.solve != Solve::kNewton) {
        for (std::size_t i = 0; i < n; ++i) out[i] = encode(tangent_radiance[i], options);
        return;
    }
    constexpr std::size_t kChunk = 64;
    Sh3Irradiance irr[kChunk];
    for (std::size_t i0 = 0; i0 < n; i0 += kChunk) {
        const std::size_t m = std::min(kChunk, n - i0);
        for (std::size_t i = 0; i < m; ++i) irr[i] = to_irradiance(tangent_radiance[i0 + i]);
        detail::fit_newton_many(irr, m, options.model, options, out + i0);
    }
}

IrradZ encode(const Sh3Radiance& tangent_radiance, const EncodeOptions& options, double* error,
              const Rgb* sampled_iz) {
    const Sh3Irradiance irr = to_irradiance(tangent_radiance);
    if (options.solve == Solve::kNewton) return detail::fit_newton(irr, options.model, options, error, sampled_iz);
    const Tables& tb = tables();
    // Optimal linear direction of the luminance L1 band (also the azimuth of the search plane).
    const LuminanceWeights& lw = options.luminance;
    Vec3 old_dir;
    const bool has_dir =
        optimal_linear_direction(luminance(irr[1], lw), luminance(irr[2], lw), luminance(irr[3], lw), &old_dir);
    if (!has_dir) old_dir = {0, 0, 1};

    if (options.solve == Solve::kTalkBaseline) {
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

}  // namespace zhc::irradz
