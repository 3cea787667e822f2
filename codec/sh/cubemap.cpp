#include "codec/sh/cubemap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <thread>
#include <vector>

namespace zhc {

const CubeLayout kCubeLayoutOpenExr = {{
                                          {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}},    // +X: ( 1, -v,  u)
                                          {{-1, 0, 0}, {0, 0, -1}, {0, -1, 0}},  // -X: (-1, -v, -u)
                                          {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},    // +Y: ( u,  1, -v)
                                          {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},    // -Y: ( u, -1,  v)
                                          {{0, 0, 1}, {-1, 0, 0}, {0, -1, 0}},   // +Z: (-u, -v,  1)
                                          {{0, 0, -1}, {1, 0, 0}, {0, -1, 0}},   // -Z: ( u, -v, -1)
                                      },
                                      true};

const CubeLayout kCubeLayoutVulkan = {{
                                         {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},   // +X: ( 1, -v, -u)
                                         {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},   // -X: (-1, -v,  u)
                                         {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},     // +Y: ( u,  1,  v)
                                         {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},   // -Y: ( u, -1, -v)
                                         {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},    // +Z: ( u, -v,  1)
                                         {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}},  // -Z: (-u, -v, -1)
                                     },
                                     false};

namespace {

// Face coordinate of pixel index i (centre to centre, n == 1: the face centre; or texel centres).
double face_coord(const CubeLayout& l, double i, int n) {
    if (!l.centre_to_centre) return (2.0 * i + 1.0) / n - 1.0;
    return n > 1 ? 2.0 * i / (n - 1) - 1.0 : 0.0;
}

// Footprint [lo, hi] of pixel i along one face axis, clipped to [-1, 1].
void footprint(const CubeLayout& l, int i, int n, double* lo, double* hi) {
    if (!l.centre_to_centre) {
        *lo = 2.0 * i / n - 1.0;
        *hi = i + 1 == n ? 1.0 : 2.0 * (i + 1) / n - 1.0;
        return;
    }
    if (n <= 1) {
        *lo = -1.0;
        *hi = 1.0;
        return;
    }
    const double half = 1.0 / (n - 1), c = face_coord(l, i, n);
    *lo = std::max(-1.0, c - half);
    *hi = std::min(1.0, c + half);
}

double rect_f(double a, double b) { return std::atan2(a * b, std::sqrt(1.0 + a * a + b * b)); }

Vec3 face_vector(const CubeLayout& l, int face, double u, double v) {
    const CubeFaceAxes& f = l.face[std::clamp(face, 0, 5)];
    double s[3];  // source frame; the coefficients are 0 or +-1, so this is exact
    for (int k = 0; k < 3; ++k) s[k] = f.major[k] + u * f.u_axis[k] + v * f.v_axis[k];
    const double r = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    return {s[2] / r, s[0] / r, s[1] / r};  // (x, y, z)_zhc = (z, x, y)_source
}

}  // namespace

Vec3 cube_direction(const CubeLayout& layout, int face, double col, double row, int n) {
    return face_vector(layout, face, face_coord(layout, col, n), face_coord(layout, row, n));
}

double cube_pixel_solid_angle(const CubeLayout& layout, int col, int row, int n) {
    double u0, u1, v0, v1;
    footprint(layout, col, n, &u0, &u1);
    footprint(layout, row, n, &v0, &v1);
    return rect_f(u1, v1) - rect_f(u0, v1) - rect_f(u1, v0) + rect_f(u0, v0);
}

void cube_nearest_pixel(const CubeLayout& layout, Vec3 d, int n, int* face, int* col, int* row) {
    const double s[3] = {d.y, d.z, d.x};  // source frame
    int best = 0;
    double best_dot = -2.0;
    for (int f = 0; f < 6; ++f) {
        double dot = 0;
        for (int k = 0; k < 3; ++k) dot += s[k] * layout.face[f].major[k];
        if (dot > best_dot) best = f, best_dot = dot;
    }
    const CubeFaceAxes& f = layout.face[best];
    double u = 0, v = 0;
    for (int k = 0; k < 3; ++k) u += s[k] * f.u_axis[k], v += s[k] * f.v_axis[k];
    if (best_dot > 0) u /= best_dot, v /= best_dot;  // else d is not a direction: the face centre
    else u = v = 0;
    auto index = [&](double t) {
        const double p = layout.centre_to_centre ? (t + 1.0) * 0.5 * (n - 1) : (t + 1.0) * 0.5 * n - 0.5;
        if (!(p > 0)) return 0;
        if (p >= n - 1) return std::max(0, n - 1);
        return static_cast<int>(std::lround(p));
    };
    *face = best;
    *col = index(u);
    *row = index(v);
}

Sh3Radiance project_cube(const CubeLayout& layout, const float* rgb, int n, size_t row_stride, int threads) {
    if (n <= 0) return {};
    // Per face-local pixel: weight and footprint centre (the same on every face).
    std::vector<double> weight(static_cast<size_t>(n) * static_cast<size_t>(n));
    std::vector<double> centre(static_cast<size_t>(n) * 2);
    for (int i = 0; i < n; ++i) {
        double lo, hi;
        footprint(layout, i, n, &lo, &hi);
        centre[static_cast<size_t>(i)] = 0.5 * (lo + hi);
    }
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            weight[static_cast<size_t>(r) * static_cast<size_t>(n) + static_cast<size_t>(c)] =
                cube_pixel_solid_angle(layout, c, r, n);
    const int rows = 6 * n;
    std::vector<std::array<double, 27>> row_sums(static_cast<size_t>(rows));
    auto work = [&](int first, int last) {
        for (int y = first; y < last; ++y) {
            const int face = y / n, r = y % n;
            const float* p = rgb + static_cast<size_t>(y) * row_stride;
            std::array<double, 27> acc{};
            for (int c = 0; c < n; ++c) {
                const double w = weight[static_cast<size_t>(r) * static_cast<size_t>(n) + static_cast<size_t>(c)];
                const auto basis = sh3_basis(
                    face_vector(layout, face, centre[static_cast<size_t>(c)], centre[static_cast<size_t>(r)]));
                for (int k = 0; k < 3; ++k) {
                    const double v = w * static_cast<double>(p[3 * c + k]);
                    for (int i = 0; i < 9; ++i) acc[static_cast<size_t>(i * 3 + k)] += v * basis[static_cast<size_t>(i)];
                }
            }
            row_sums[static_cast<size_t>(y)] = acc;
        }
    };
    const int t = std::clamp(threads, 1, 64);
    if (t == 1) {
        work(0, rows);
    } else {
        std::vector<std::thread> pool;
        for (int i = 0; i < t; ++i) pool.emplace_back(work, rows * i / t, rows * (i + 1) / t);
        for (auto& th : pool) th.join();
    }
    std::array<double, 27> total{};
    for (const auto& a : row_sums)
        for (size_t i = 0; i < 27; ++i) total[i] += a[i];
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(total[static_cast<size_t>(i * 3 + k)]);
    return out;
}

Vec3 cube_openexr_direction(int face, double col, double row, int n) {
    return cube_direction(kCubeLayoutOpenExr, face, col, row, n);
}
double cube_openexr_pixel_solid_angle(int col, int row, int n) {
    return cube_pixel_solid_angle(kCubeLayoutOpenExr, col, row, n);
}
Sh3Radiance project_cube_openexr(const float* rgb, int n, size_t row_stride, int threads) {
    return project_cube(kCubeLayoutOpenExr, rgb, n, row_stride, threads);
}

}  // namespace zhc
