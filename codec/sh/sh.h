// zhc/codec/sh/sh.h — the one header that fixes zhc's spherical-harmonic conventions.
//
// Standard library only; no I/O. Every other part of zhc uses these types and functions.
//
// Conventions (see docs/conventions.md):
//
//  * Coefficient index i = l(l+1) + m:  [Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22].
//  * Real SH basis exactly as the Cartesian forms of the ZH3 paper (Roughton et al. 2024, Eq. 4, 5),
//    signs included, for a unit direction (x, y, z):
//      Y00  = 1 / (2 sqrt(pi))
//      Y1   = sqrt(3 / 4pi) [-y, z, -x]
//      Y2   = [ sqrt(15/4pi) xy, -sqrt(15/4pi) yz, sqrt(5/16pi)(3z^2 - 1), -sqrt(15/4pi) xz,
//               sqrt(15/16pi)(x^2 - y^2) ]
//  * zhc's world frame is right-handed and Z-up. Latitude-longitude maps: row 0 is the top (+Z),
//    the centre column looks along +X, and longitude phi decreases from +pi at the left edge to -pi
//    at the right edge, so pixel (col, row) of a W x H map has its centre at
//      u = (col + 0.5) / W,  v = (row + 0.5) / H,  phi = pi (1 - 2u),  theta = pi v,
//      direction = (sin theta cos phi, sin theta sin phi, cos theta).
//    This is OpenEXR's Imf::LatLongMap orientation with (x, y, z)_zhc = (z, x, y)_OpenEXR (its +Y up
//    becomes our +Z; its +Z, the image centre, becomes our +X), sampled at pixel centres.
//    The glTF ecosystem's lat-long orientation (LatLongConvention::kGltf below) has the same rows
//    and phi = pi (3/2 - 2u): the same map turned by +90 degrees about +Z.
//  * Radiance and irradiance are distinct types. Irradiance is radiance convolved with the
//    normalised clamped-cosine kernel, E(n) = (1/pi) * integral L(w) max(0, n.w) dw, so a constant
//    radiance of 1 gives irradiance 1. In SH that is the per-band scale 1, 2/3, 1/4.
//  * Colour is linear RGB; luminance weights default to Rec. 709.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace zhc {

inline constexpr double kPi = 3.14159265358979323846;

// ---- small vector types --------------------------------------------------------------------

struct Vec3 {
    double x = 0, y = 0, z = 0;
    constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};
inline constexpr Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline constexpr Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline constexpr Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline constexpr double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline constexpr Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(Vec3 a) { return std::sqrt(dot(a, a)); }
// Unit vector along a; returns `fallback` when a is zero or not finite.
Vec3 normalize_or(Vec3 a, Vec3 fallback);

// Row-major 3x3 matrix; used for rotations (applied as R * v).
struct Mat3 {
    std::array<double, 9> m{1, 0, 0, 0, 1, 0, 0, 0, 1};
    constexpr double operator()(int r, int c) const { return m[static_cast<size_t>(r * 3 + c)]; }
    double& operator()(int r, int c) { return m[static_cast<size_t>(r * 3 + c)]; }
};
Vec3 operator*(const Mat3& r, Vec3 v);
Mat3 operator*(const Mat3& a, const Mat3& b);
Mat3 transpose(const Mat3& a);
// Rotation by `angle_rad` about the unit axis `axis` (right-hand rule).
Mat3 rotation_axis_angle(Vec3 axis, double angle_rad);
// A rotation whose third column is `z_axis`: maps +Z onto z_axis (a frame around z_axis).
Mat3 frame_from_z(Vec3 z_axis);

// Linear RGB triple. Storage is float (the hub is 27 floats per probe); arithmetic that
// accumulates is done in double by the callers.
struct Rgb {
    float r = 0, g = 0, b = 0;
    constexpr float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
    float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
};

struct LuminanceWeights {
    double r = 0.2126, g = 0.7152, b = 0.0722;  // Rec. 709 / sRGB primaries
};

// ---- basis ---------------------------------------------------------------------------------

inline constexpr int sh_index(int l, int m) { return l * (l + 1) + m; }

// Normalisation constants of the Cartesian forms (ZH3 paper Eq. 4/5).
inline const double kY00 = 1.0 / (2.0 * std::sqrt(kPi));        // 1 / (2 sqrt(pi))
inline const double kY1 = std::sqrt(3.0 / (4.0 * kPi));         // sqrt(3/4pi)
inline const double kY2 = std::sqrt(15.0 / (4.0 * kPi));        // sqrt(15/4pi)
inline const double kY20 = std::sqrt(5.0 / (16.0 * kPi));       // sqrt(5/16pi)
inline const double kY22 = std::sqrt(15.0 / (16.0 * kPi));      // sqrt(15/16pi)

// Band scales of the normalised clamped-cosine convolution (radiance -> irradiance).
inline constexpr double kIrradianceBandScale[3] = {1.0, 2.0 / 3.0, 1.0 / 4.0};

// The nine SH3 basis functions at a unit direction (inline: the IrradZ direction search calls it
// tens of times per texel).
inline std::array<double, 9> sh3_basis(Vec3 d) {
    const double x = d.x, y = d.y, z = d.z;
    return {kY00,
            -kY1 * y,
            kY1 * z,
            -kY1 * x,
            kY2 * x * y,
            -kY2 * y * z,
            kY20 * (3.0 * z * z - 1.0),
            -kY2 * x * z,
            kY22 * (x * x - y * y)};
}
// The four SH2 basis functions at a unit direction.
inline std::array<double, 4> sh2_basis(Vec3 d) { return {kY00, -kY1 * d.y, kY1 * d.z, -kY1 * d.x}; }

// ---- RGB SH types --------------------------------------------------------------------------

struct RadianceTag {};
struct IrradianceTag {};

// RGB spherical harmonics of order `Order` (Order^2 coefficients per channel); Kind tags whether
// the function is radiance or irradiance so the two are never mixed up.
template <int Order, class Kind>
struct ShRgb {
    static constexpr int kOrder = Order;
    static constexpr int kCount = Order * Order;
    std::array<Rgb, kCount> c{};

    Rgb& operator[](int i) { return c[static_cast<size_t>(i)]; }
    const Rgb& operator[](int i) const { return c[static_cast<size_t>(i)]; }
    friend bool operator==(const ShRgb& a, const ShRgb& b) {
        for (int i = 0; i < kCount; ++i)
            for (int k = 0; k < 3; ++k)
                if (a.c[static_cast<size_t>(i)][k] != b.c[static_cast<size_t>(i)][k]) return false;
        return true;
    }
};

using Sh2Radiance = ShRgb<2, RadianceTag>;
using Sh3Radiance = ShRgb<3, RadianceTag>;
using Sh2Irradiance = ShRgb<2, IrradianceTag>;
using Sh3Irradiance = ShRgb<3, IrradianceTag>;

// Radiance -> irradiance (band scales 1, 2/3, 1/4).
Sh3Irradiance to_irradiance(const Sh3Radiance& radiance);
Sh2Irradiance to_irradiance(const Sh2Radiance& radiance);
// Irradiance -> radiance (inverse band scales). Exact inverse of to_irradiance.
Sh3Radiance to_radiance(const Sh3Irradiance& irradiance);

// Truncation and extension between orders (the L2 band is dropped / zero-filled).
Sh2Radiance truncate_to_sh2(const Sh3Radiance& sh);
Sh3Radiance extend_to_sh3(const Sh2Radiance& sh);

// ---- evaluation ----------------------------------------------------------------------------

// Value of the SH function at unit direction d (radiance or irradiance, as its type says).
template <int Order, class Kind>
Rgb evaluate(const ShRgb<Order, Kind>& sh, Vec3 d);
// Irradiance at unit normal n from SH radiance (applies the band scales on the fly).
Rgb irradiance(const Sh3Radiance& radiance, Vec3 n);
Rgb irradiance(const Sh2Radiance& radiance, Vec3 n);

// ---- projection ----------------------------------------------------------------------------

struct WeightedSample {
    Vec3 direction;   // unit
    double weight;    // solid angle (sr) the sample stands for
    Rgb radiance;
};
// SH3 projection of weighted direction samples: c_i = sum_k w_k L_k Y_i(d_k), in double.
Sh3Radiance project_samples(std::span<const WeightedSample> samples);

// n directions spread uniformly over the sphere (spherical Fibonacci lattice), deterministic.
std::vector<Vec3> fibonacci_sphere(int n);

// Which longitude a lat-long map's column stands for (docs/conventions.md). Both conventions have
// u = (col + 0.5) / W, v = (row + 0.5) / H, theta = pi v (row 0 at the top, +Z) and
// direction = (sin theta cos phi, sin theta sin phi, cos theta) in zhc's frame; they differ in phi:
//   kOpenExr: phi = pi (1 - 2u)    centre column +X_zhc (OpenEXR's Imf::LatLongMap, its +Z)
//   kGltf:    phi = pi (3/2 - 2u)  centre column +Y_zhc = glTF's +X; in glTF's Y-up axes
//             u = 1/2 + atan2(z, x) / (2 pi), v = acos(y) / pi (three.js's equirectUv with its
//             image flipped so row 0 is up, the Khronos glTF-IBL-Sampler, Blender, Bevy)
// A kGltf map is the kOpenExr map turned by +90 degrees about +Z.
enum class LatLongConvention : std::uint8_t { kOpenExr, kGltf };
// "openexr" / "gltf", the spelling of the CLI's --latlong and the scenes' "latlong" key.
const char* latlong_convention_name(LatLongConvention convention);
// Parses that spelling; false for anything else.
bool parse_latlong_convention(std::string_view name, LatLongConvention* out);

// Direction of the centre of pixel (col, row) in a width x height latitude-longitude map.
Vec3 latlong_direction(double col, double row, int width, int height,
                       LatLongConvention convention = LatLongConvention::kOpenExr);
// Exact solid angle of row `row` of a lat-long map of the given size, per pixel:
// (2 pi / width) * (cos theta_top - cos theta_bottom).
double latlong_pixel_solid_angle(int row, int width, int height);

// SH3 projection of a latitude-longitude map (interleaved RGB floats, `row_stride` floats per
// row, `width` * 3 <= row_stride), accumulated in double. Each pixel is integrated exactly over
// its footprint (its value times the basis integrated over the pixel's theta/phi rectangle), a
// refinement of "centre value times exact solid angle" that is exact for constant maps at any
// resolution. Uses the separable form (per-row Legendre-factor integrals, per-column cos/sin(m phi)
// integrals) and splits rows over `threads` workers; the result does not depend on the thread
// count (fixed-order reduction of per-row sums).
// `convention` says how the map's columns turn (kGltf: the kOpenExr projection turned by a
// quarter turn about +Z, exactly: latlong_quarter_turn).
Sh3Radiance project_latlong(const float* rgb, int width, int height, size_t row_stride,
                            int threads = 1, LatLongConvention convention = LatLongConvention::kOpenExr);
// The SH of a map read under `convention`, given its SH read under kOpenExr: unchanged for
// kOpenExr; for kGltf the rotation by +90 degrees about +Z (g(x, y, z) = f(y, -x, z)), which only
// moves and negates coefficients: [c0, c3, c2, -c1, -c4, c7, c6, -c5, -c8].
Sh3Radiance latlong_quarter_turn(const Sh3Radiance& openexr, LatLongConvention convention);

// ---- rotation ------------------------------------------------------------------------------

// Rotate an SH function by R: the result g satisfies g(d) = f(R^T d), i.e. a light that was in
// direction w is now in direction R w. Bands are rotated exactly (L1 as a vector, L2 as the
// traceless quadratic form Q -> R Q R^T).
template <int Order, class Kind>
ShRgb<Order, Kind> rotate(const ShRgb<Order, Kind>& sh, const Mat3& r);

// Per-channel L2 norm of band l (rotation invariant).
Rgb band_norm(const Sh3Radiance& sh, int l);

// ---- closed-form projections ---------------------------------------------------------------

// Zonal coefficients f_l^0 (l = 0, 1, 2) of a radiance function with rotational symmetry about +Z.
struct ZonalCoefficients {
    double f0 = 0, f1 = 0, f2 = 0;
};
// Zonal SH3 function (per channel) rotated so its axis is the unit vector `axis`:
// f_l^m = f_l^0 * sqrt(4 pi / (2l + 1)) * Y_l^m(axis).
Sh3Radiance expand_zonal(Vec3 axis, const std::array<ZonalCoefficients, 3>& rgb_zonal);

// A directional (delta) light: radiance integrating to `intensity` (W m^-2 sr^0: irradiance it
// gives a surface facing it is intensity / pi under zhc's normalised kernel) arriving from unit
// direction `towards_light`.
Sh3Radiance project_directional(Vec3 towards_light, Rgb intensity);
// A constant-radiance cone (spherical light) of half-angle sigma around `axis`; ZH3 paper Eq. 15
// (valid for every sigma in [0, pi]; sigma = pi/2 is the hemisphere).
ZonalCoefficients cone_zonal(double sigma, double radiance = 1.0);
Sh3Radiance project_cone(Vec3 axis, double sigma, Rgb radiance);
// A hemisphere of constant radiance around `axis` (cone with sigma = pi / 2).
Sh3Radiance project_hemisphere(Vec3 axis, Rgb radiance);
// Constant radiance over the whole sphere: only L00 = 2 sqrt(pi) * radiance is non-zero.
Sh3Radiance project_constant(Rgb radiance);

// ---- small helpers -------------------------------------------------------------------------

// Luminance-weighted combination of the three channels of coefficient i.
double luminance(const Rgb& c, const LuminanceWeights& w);
// The "optimal linear direction" of an L1 band given as SH coefficients (f1-1, f10, f11):
// normalize(-f11, -f1-1, f10). Returns false (and +Z) when the band is zero.
bool optimal_linear_direction(double f1m1, double f10, double f1p1, Vec3* out);

Sh3Radiance operator+(const Sh3Radiance& a, const Sh3Radiance& b);
Sh3Radiance scale(const Sh3Radiance& a, double s);

}  // namespace zhc
