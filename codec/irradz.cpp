// zhc/codec/irradz.cpp — IrradZ / HHD / AHD lightmap maths. Derivations in docs/irradz.md.
#include "irradz.h"

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
