// SH core: basis, evaluation, projection, rotation, closed forms. Conventions in sh.h.
//
// Sources: Roughton et al. 2024 "ZH3: Quadratic Zonal Harmonics" (Eq. 2, 4, 5, 15);
// Sloan 2008 "Stupid SH Tricks" (zonal expansion); Ramamoorthi & Hanrahan 2001 (band scales).
#include "codec/sh/sh.h"

#include <algorithm>
#include <thread>
#include <vector>

namespace zhc {

Vec3 normalize_or(Vec3 a, Vec3 fallback) {
    const double len = length(a);
    if (!(len > 0.0) || !std::isfinite(len)) return fallback;
    return (1.0 / len) * a;
}

Vec3 operator*(const Mat3& r, Vec3 v) {
    return {r(0, 0) * v.x + r(0, 1) * v.y + r(0, 2) * v.z,
            r(1, 0) * v.x + r(1, 1) * v.y + r(1, 2) * v.z,
            r(2, 0) * v.x + r(2, 1) * v.y + r(2, 2) * v.z};
}

Mat3 operator*(const Mat3& a, const Mat3& b) {
    Mat3 out;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double s = 0;
            for (int k = 0; k < 3; ++k) s += a(i, k) * b(k, j);
            out(i, j) = s;
        }
    return out;
}

Mat3 transpose(const Mat3& a) {
    Mat3 out;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out(i, j) = a(j, i);
    return out;
}

Mat3 rotation_axis_angle(Vec3 axis, double angle_rad) {
    const Vec3 k = normalize_or(axis, {0, 0, 1});
    const double c = std::cos(angle_rad), s = std::sin(angle_rad), t = 1.0 - c;
    Mat3 r;
    r.m = {t * k.x * k.x + c,       t * k.x * k.y - s * k.z, t * k.x * k.z + s * k.y,
           t * k.x * k.y + s * k.z, t * k.y * k.y + c,       t * k.y * k.z - s * k.x,
           t * k.x * k.z - s * k.y, t * k.y * k.z + s * k.x, t * k.z * k.z + c};
    return r;
}

Mat3 frame_from_z(Vec3 z_axis) {
    const Vec3 z = normalize_or(z_axis, {0, 0, 1});
    // Pick the helper axis least aligned with z for a well-conditioned cross product.
    const Vec3 helper = std::fabs(z.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 x = normalize_or(cross(helper, z), {1, 0, 0});
    const Vec3 y = cross(z, x);
    Mat3 r;
    r.m = {x.x, y.x, z.x, x.y, y.y, z.y, x.z, y.z, z.z};
    return r;
}

namespace {
template <int Order, class From, class To>
ShRgb<Order, To> scale_bands(const ShRgb<Order, From>& in, bool inverse) {
    ShRgb<Order, To> out;
    for (int l = 0; l < Order; ++l) {
        const double s = inverse ? 1.0 / kIrradianceBandScale[l] : kIrradianceBandScale[l];
        for (int m = -l; m <= l; ++m) {
            const int i = sh_index(l, m);
            for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(in[i][k] * s);
        }
    }
    return out;
}
}  // namespace

Sh3Irradiance to_irradiance(const Sh3Radiance& radiance) {
    return scale_bands<3, RadianceTag, IrradianceTag>(radiance, false);
}
Sh2Irradiance to_irradiance(const Sh2Radiance& radiance) {
    return scale_bands<2, RadianceTag, IrradianceTag>(radiance, false);
}
Sh3Radiance to_radiance(const Sh3Irradiance& irradiance) {
    return scale_bands<3, IrradianceTag, RadianceTag>(irradiance, true);
}

Sh2Radiance truncate_to_sh2(const Sh3Radiance& sh) {
    Sh2Radiance out;
    for (int i = 0; i < 4; ++i) out[i] = sh[i];
    return out;
}

Sh3Radiance extend_to_sh3(const Sh2Radiance& sh) {
    Sh3Radiance out;
    for (int i = 0; i < 4; ++i) out[i] = sh[i];
    return out;
}

template <int Order, class Kind>
Rgb evaluate(const ShRgb<Order, Kind>& sh, Vec3 d) {
    const auto basis = sh3_basis(d);
    double acc[3] = {0, 0, 0};
    for (int i = 0; i < Order * Order; ++i)
        for (int k = 0; k < 3; ++k) acc[k] += sh[i][k] * basis[static_cast<size_t>(i)];
    return {static_cast<float>(acc[0]), static_cast<float>(acc[1]), static_cast<float>(acc[2])};
}
template Rgb evaluate(const Sh2Radiance&, Vec3);
template Rgb evaluate(const Sh3Radiance&, Vec3);
template Rgb evaluate(const Sh2Irradiance&, Vec3);
template Rgb evaluate(const Sh3Irradiance&, Vec3);

Rgb irradiance(const Sh3Radiance& radiance, Vec3 n) { return evaluate(to_irradiance(radiance), n); }
Rgb irradiance(const Sh2Radiance& radiance, Vec3 n) { return evaluate(to_irradiance(radiance), n); }

Sh3Radiance project_samples(std::span<const WeightedSample> samples) {
    double acc[9][3] = {};
    for (const WeightedSample& s : samples) {
        const auto basis = sh3_basis(s.direction);
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) acc[i][k] += s.weight * s.radiance[k] * basis[static_cast<size_t>(i)];
    }
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(acc[i][k]);
    return out;
}

std::vector<Vec3> fibonacci_sphere(int n) {
    std::vector<Vec3> out;
    out.reserve(static_cast<size_t>(std::max(n, 0)));
    const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n;  // equal-area bands
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        out.push_back({r * std::cos(golden_angle * i), r * std::sin(golden_angle * i), z});
    }
    return out;
}

const char* latlong_convention_name(LatLongConvention convention) {
    return convention == LatLongConvention::kGltf ? "gltf" : "openexr";
}

bool parse_latlong_convention(std::string_view name, LatLongConvention* out) {
    if (name == "openexr") *out = LatLongConvention::kOpenExr;
    else if (name == "gltf") *out = LatLongConvention::kGltf;
    else return false;
    return true;
}

Vec3 latlong_direction(double col, double row, int width, int height, LatLongConvention convention) {
    const double u = (col + 0.5) / width, v = (row + 0.5) / height;
    const double phi = kPi * ((convention == LatLongConvention::kGltf ? 1.5 : 1.0) - 2.0 * u), theta = kPi * v;
    const double st = std::sin(theta);
    return {st * std::cos(phi), st * std::sin(phi), std::cos(theta)};
}

double latlong_pixel_solid_angle(int row, int width, int height) {
    const double t0 = kPi * row / height, t1 = kPi * (row + 1) / height;
    return (2.0 * kPi / width) * (std::cos(t0) - std::cos(t1));
}

namespace {
// Per-row partial sums of the separable lat-long projection, per channel: the pixel values times
// the column integrals of 1, cos(phi), sin(phi), cos(2 phi), sin(2 phi) over each pixel's phi range.
struct RowSums {
    double s[5][3];
};

// Columns c and W-1-c are mirror images (phi -> -phi): their integrals of 1, cos(phi), cos(2 phi)
// are equal and those of sin(phi), sin(2 phi) are opposite, so each mirrored pair needs the sum of
// its two pixels for the even factors and their difference for the odd ones: half the multiplies.
void project_rows(const float* rgb, int width, size_t row_stride, int row_begin, int row_end,
                  const std::vector<double>& column_integrals, RowSums* out) {
    const int half = width / 2;
    // With width % 4 == 0 the half-period shift (phi -> phi - pi: cos, sin change sign, cos 2phi,
    // sin 2phi do not) adds a second symmetry: columns c, W-1-c, c+W/2, W/2-1-c share one set of
    // integrals up to signs, and the five sums need four adds and five multiplies per quad.
    const bool quads = width % 4 == 0;
    for (int row = row_begin; row < row_end; ++row) {
        const float* p = rgb + static_cast<size_t>(row) * row_stride;
        double acc[5][3] = {};
        if (quads) {
            const int quarter = width / 4;
            for (int col = 0; col < quarter; ++col) {
                const double* t = &column_integrals[static_cast<size_t>(col) * 5];
                const float* a = p + col * 3;                     // phi
                const float* b = p + (width - 1 - col) * 3;       // -phi
                const float* c = p + (col + half) * 3;            // phi - pi
                const float* d = p + (half - 1 - col) * 3;        // pi - phi
                for (int k = 0; k < 3; ++k) {
                    const double ab = double(a[k]) + b[k], cd = double(c[k]) + d[k];
                    const double amb = double(a[k]) - b[k], cmd = double(c[k]) - d[k];
                    acc[0][k] += (ab + cd) * t[0];
                    acc[1][k] += (ab - cd) * t[1];
                    acc[2][k] += (amb - cmd) * t[2];
                    acc[3][k] += (ab + cd) * t[3];
                    acc[4][k] += (amb + cmd) * t[4];
                }
            }
            std::copy(&acc[0][0], &acc[0][0] + 15, &out[row].s[0][0]);
            continue;
        }
        for (int col = 0; col < half; ++col) {
            const double* t = &column_integrals[static_cast<size_t>(col) * 5];
            const float* a = p + col * 3;
            const float* b = p + (width - 1 - col) * 3;
            for (int k = 0; k < 3; ++k) {
                const double even = double(a[k]) + b[k], odd = double(a[k]) - b[k];
                acc[0][k] += even * t[0];
                acc[1][k] += even * t[1];
                acc[2][k] += odd * t[2];
                acc[3][k] += even * t[3];
                acc[4][k] += odd * t[4];
            }
        }
        if (width % 2) {  // the middle column of an odd width pairs with itself
            const double* t = &column_integrals[static_cast<size_t>(half) * 5];
            for (int k = 0; k < 3; ++k) {
                const double v = p[half * 3 + k];
                for (int j = 0; j < 5; ++j) acc[j][k] += v * t[j];
            }
        }
        std::copy(&acc[0][0], &acc[0][0] + 15, &out[row].s[0][0]);
    }
}

// Antiderivatives in z = cos(theta) of the theta factors of the basis (integrand times
// sin(theta) d theta = -dz): 1, sqrt(1 - z^2), z, 1 - z^2, z sqrt(1 - z^2), 3 z^2 - 1.
struct ZIntegrals {
    double one, s, z, ss, sz, p2;
};
ZIntegrals z_antiderivatives(double z) {
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {z, 0.5 * (z * r + std::asin(std::clamp(z, -1.0, 1.0))), 0.5 * z * z, z - z * z * z / 3.0,
            -(r * r * r) / 3.0, z * z * z - z};
}
}  // namespace

// Exact projection of the piecewise-constant map (each pixel's value over its exact footprint).
// With direction (sin t cos p, sin t sin p, cos t) every basis function is a theta factor times a
// phi factor:
//   Y00 = kY00                         Y1-1 = -kY1 sin t sin p     Y10 = kY1 cos t
//   Y11 = -kY1 sin t cos p             Y2-2 = kY2/2 sin^2 t sin 2p  Y2-1 = -kY2 sin t cos t sin p
//   Y20 = kY20 (3 cos^2 t - 1)         Y21 = -kY2 sin t cos t cos p Y22 = kY22 sin^2 t cos 2p
// so the integral over a pixel is (theta-factor integral over its row) x (phi-factor integral
// over its column), both in closed form: five column sums per row and channel suffice. A constant
// map projects to exactly 2 sqrt(pi) L in L00 and zero elsewhere, at any resolution.
Sh3Radiance latlong_quarter_turn(const Sh3Radiance& sh, LatLongConvention convention) {
    if (convention == LatLongConvention::kOpenExr) return sh;
    // g(x, y, z) = f(y, -x, z): Y1-1 (-y) -> -Y11, Y11 (-x) -> Y1-1, Y2-2 (xy) -> -Y2-2,
    // Y2-1 (-yz) -> -Y21, Y21 (-xz) -> Y2-1, Y22 (x^2 - y^2) -> -Y22; Y00, Y10, Y20 stay.
    Sh3Radiance g;
    const int from[9] = {0, 3, 2, 1, 4, 7, 6, 5, 8};
    const bool negate[9] = {false, false, false, true, true, false, false, true, true};
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) g[i][k] = negate[i] ? 0.0f - sh[from[i]][k] : sh[from[i]][k];  // 0 - 0 is +0
    return g;
}

Sh3Radiance project_latlong(const float* rgb, int width, int height, size_t row_stride, int threads,
                            LatLongConvention convention) {
    if (convention != LatLongConvention::kOpenExr)
        return latlong_quarter_turn(project_latlong(rgb, width, height, row_stride, threads, LatLongConvention::kOpenExr),
                                    convention);
    Sh3Radiance out;
    if (width <= 0 || height <= 0 || rgb == nullptr) return out;
    std::vector<double> column_integrals(static_cast<size_t>(width) * 5);
    for (int col = 0; col < width; ++col) {
        // The column spans phi in [b, a] with a = pi (1 - 2 col / W) > b = pi (1 - 2 (col + 1) / W).
        const double a = kPi * (1.0 - 2.0 * col / width), b = kPi * (1.0 - 2.0 * (col + 1) / width);
        double* t = &column_integrals[static_cast<size_t>(col) * 5];
        t[0] = a - b;
        t[1] = std::sin(a) - std::sin(b);
        t[2] = std::cos(b) - std::cos(a);
        t[3] = 0.5 * (std::sin(2.0 * a) - std::sin(2.0 * b));
        t[4] = 0.5 * (std::cos(2.0 * b) - std::cos(2.0 * a));
    }
    std::vector<RowSums> rows(static_cast<size_t>(height));
    threads = std::clamp(threads, 1, std::max(1, height));
    if (threads == 1) {
        project_rows(rgb, width, row_stride, 0, height, column_integrals, rows.data());
    } else {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t) {
            const int b = static_cast<int>(static_cast<long long>(height) * t / threads);
            const int e = static_cast<int>(static_cast<long long>(height) * (t + 1) / threads);
            pool.emplace_back(project_rows, rgb, width, row_stride, b, e, std::cref(column_integrals), rows.data());
        }
        for (auto& th : pool) th.join();
    }
    // Fixed-order reduction: identical bytes whatever the thread count.
    double acc[9][3] = {};
    ZIntegrals top = z_antiderivatives(1.0);
    for (int row = 0; row < height; ++row) {
        const ZIntegrals bottom = z_antiderivatives(std::cos(kPi * (row + 1) / height));
        // integral over the row of f(theta) sin(theta) d theta = F(z_top) - F(z_bottom)
        const double one = top.one - bottom.one, s = top.s - bottom.s, z = top.z - bottom.z,
                     ss = top.ss - bottom.ss, sz = top.sz - bottom.sz, p2 = top.p2 - bottom.p2;
        top = bottom;
        const RowSums& r = rows[static_cast<size_t>(row)];
        for (int k = 0; k < 3; ++k) {
            acc[0][k] += kY00 * one * r.s[0][k];
            acc[1][k] += -kY1 * s * r.s[2][k];
            acc[2][k] += kY1 * z * r.s[0][k];
            acc[3][k] += -kY1 * s * r.s[1][k];
            acc[4][k] += 0.5 * kY2 * ss * r.s[4][k];
            acc[5][k] += -kY2 * sz * r.s[2][k];
            acc[6][k] += kY20 * p2 * r.s[0][k];
            acc[7][k] += -kY2 * sz * r.s[1][k];
            acc[8][k] += kY22 * ss * r.s[3][k];
        }
    }
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(acc[i][k]);
    return out;
}

namespace {
// L1 band of one channel as the vector v with f1(d) = v . d.
Vec3 l1_vector(double f1m1, double f10, double f1p1) { return kY1 * Vec3{-f1p1, -f1m1, f10}; }

// L2 band of one channel as the symmetric matrix Q with f2(d) = d^T Q d on the unit sphere
// (3z^2 - 1 = 2z^2 - x^2 - y^2 there, so Q is traceless).
Mat3 l2_quadratic_form(const double a[5]) {
    Mat3 q;
    const double xy = 0.5 * kY2 * a[0], yz = -0.5 * kY2 * a[1], xz = -0.5 * kY2 * a[3];
    q.m = {-kY20 * a[2] + kY22 * a[4], xy, xz,
           xy, -kY20 * a[2] - kY22 * a[4], yz,
           xz, yz, 2.0 * kY20 * a[2]};
    return q;
}

void l2_coefficients(const Mat3& q, double a[5]) {
    a[0] = 2.0 * q(0, 1) / kY2;
    a[1] = -2.0 * q(1, 2) / kY2;
    a[2] = (2.0 * q(2, 2) - q(0, 0) - q(1, 1)) / (6.0 * kY20);
    a[3] = -2.0 * q(0, 2) / kY2;
    a[4] = (q(0, 0) - q(1, 1)) / (2.0 * kY22);
}
}  // namespace

template <int Order, class Kind>
ShRgb<Order, Kind> rotate(const ShRgb<Order, Kind>& sh, const Mat3& r) {
    ShRgb<Order, Kind> out;
    const Mat3 rt = transpose(r);
    for (int k = 0; k < 3; ++k) {
        out[0][k] = sh[0][k];
        // g(d) = f(R^T d) = v . R^T d = (R v) . d
        const Vec3 v = r * l1_vector(sh[1][k], sh[2][k], sh[3][k]);
        out[1][k] = static_cast<float>(-v.y / kY1);
        out[2][k] = static_cast<float>(v.z / kY1);
        out[3][k] = static_cast<float>(-v.x / kY1);
        if constexpr (Order >= 3) {
            double a[5];
            for (int m = 0; m < 5; ++m) a[m] = sh[4 + m][k];
            // g(d) = (R^T d)^T Q (R^T d) = d^T (R Q R^T) d
            const Mat3 q = r * l2_quadratic_form(a) * rt;
            l2_coefficients(q, a);
            for (int m = 0; m < 5; ++m) out[4 + m][k] = static_cast<float>(a[m]);
        }
    }
    return out;
}
template Sh2Radiance rotate(const Sh2Radiance&, const Mat3&);
template Sh3Radiance rotate(const Sh3Radiance&, const Mat3&);
template Sh2Irradiance rotate(const Sh2Irradiance&, const Mat3&);
template Sh3Irradiance rotate(const Sh3Irradiance&, const Mat3&);

Rgb band_norm(const Sh3Radiance& sh, int l) {
    Rgb out;
    if (l < 0 || l > 2) return out;
    for (int k = 0; k < 3; ++k) {
        double s = 0;
        for (int m = -l; m <= l; ++m) s += double(sh[sh_index(l, m)][k]) * sh[sh_index(l, m)][k];
        out[k] = static_cast<float>(std::sqrt(s));
    }
    return out;
}

Sh3Radiance expand_zonal(Vec3 axis, const std::array<ZonalCoefficients, 3>& rgb_zonal) {
    const Vec3 a = normalize_or(axis, {0, 0, 1});
    const auto y = sh3_basis(a);
    // sqrt(4 pi / (2l + 1)) per band: ZH3 paper Eq. 2 applied to a delta along `axis`.
    const double band[3] = {std::sqrt(4.0 * kPi), std::sqrt(4.0 * kPi / 3.0), std::sqrt(4.0 * kPi / 5.0)};
    Sh3Radiance out;
    for (int k = 0; k < 3; ++k) {
        const double f[3] = {rgb_zonal[static_cast<size_t>(k)].f0, rgb_zonal[static_cast<size_t>(k)].f1,
                             rgb_zonal[static_cast<size_t>(k)].f2};
        for (int l = 0; l < 3; ++l)
            for (int m = -l; m <= l; ++m)
                out[sh_index(l, m)][k] =
                    static_cast<float>(f[l] * band[l] * y[static_cast<size_t>(sh_index(l, m))]);
    }
    return out;
}

Sh3Radiance project_directional(Vec3 towards_light, Rgb intensity) {
    const auto y = sh3_basis(normalize_or(towards_light, {0, 0, 1}));
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(intensity[k] * y[static_cast<size_t>(i)]);
    return out;
}

// ZH3 paper Eq. 15, from f_l = 2 pi K_l integral_{cos sigma}^{1} P_l(z) dz:
//   f0 = sqrt(pi) (1 - cos s),  f1 = sqrt(3 pi)/2 sin^2 s,  f2 = sqrt(5 pi)/2 cos s sin^2 s.
ZonalCoefficients cone_zonal(double sigma, double radiance) {
    const double c = std::cos(sigma), s2 = 1.0 - c * c;
    return {radiance * std::sqrt(kPi) * (1.0 - c), radiance * std::sqrt(3.0 * kPi) / 2.0 * s2,
            radiance * std::sqrt(5.0 * kPi) / 2.0 * c * s2};
}

Sh3Radiance project_cone(Vec3 axis, double sigma, Rgb radiance) {
    const ZonalCoefficients unit = cone_zonal(sigma, 1.0);
    std::array<ZonalCoefficients, 3> z;
    for (int k = 0; k < 3; ++k)
        z[static_cast<size_t>(k)] = {unit.f0 * radiance[k], unit.f1 * radiance[k], unit.f2 * radiance[k]};
    return expand_zonal(axis, z);
}

Sh3Radiance project_hemisphere(Vec3 axis, Rgb radiance) { return project_cone(axis, kPi / 2.0, radiance); }

Sh3Radiance project_constant(Rgb radiance) {
    Sh3Radiance out;
    for (int k = 0; k < 3; ++k) out[0][k] = static_cast<float>(2.0 * std::sqrt(kPi) * radiance[k]);
    return out;
}

double luminance(const Rgb& c, const LuminanceWeights& w) { return w.r * c.r + w.g * c.g + w.b * c.b; }

bool optimal_linear_direction(double f1m1, double f10, double f1p1, Vec3* out) {
    const Vec3 v{-f1p1, -f1m1, f10};
    const double len = length(v);
    if (!(len > 0.0) || !std::isfinite(len)) {
        *out = {0, 0, 1};
        return false;
    }
    *out = (1.0 / len) * v;
    return true;
}

Sh3Radiance operator+(const Sh3Radiance& a, const Sh3Radiance& b) {
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = a[i][k] + b[i][k];
    return out;
}

Sh3Radiance scale(const Sh3Radiance& a, double s) {
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(a[i][k] * s);
    return out;
}

}  // namespace zhc
