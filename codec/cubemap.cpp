#include "cubemap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <thread>
#include <vector>

namespace zhc {

namespace {

// Face coordinate of pixel index i (centre to centre; n == 1: the face centre).
double face_coord(double i, int n) { return n > 1 ? 2.0 * i / (n - 1) - 1.0 : 0.0; }

// Footprint [lo, hi] of pixel i along one face axis, clipped to [-1, 1].
void footprint(int i, int n, double* lo, double* hi) {
    if (n <= 1) {
        *lo = -1.0;
        *hi = 1.0;
        return;
    }
    const double half = 1.0 / (n - 1), c = face_coord(i, n);
    *lo = std::max(-1.0, c - half);
    *hi = std::min(1.0, c + half);
}

double rect_f(double a, double b) { return std::atan2(a * b, std::sqrt(1.0 + a * a + b * b)); }

Vec3 face_vector(int face, double u, double v) {
    double x = 0, y = 0, z = 0;  // OpenEXR frame
    switch (face) {
        case 0: x = 1, y = -v, z = u; break;
        case 1: x = -1, y = -v, z = -u; break;
        case 2: x = u, y = 1, z = -v; break;
        case 3: x = u, y = -1, z = v; break;
        case 4: x = -u, y = -v, z = 1; break;
        default: x = u, y = -v, z = -1; break;
    }
    const double r = std::sqrt(x * x + y * y + z * z);
    return {z / r, x / r, y / r};  // (x, y, z)_zhc = (z, x, y)_OpenEXR
}

}  // namespace

Vec3 cube_openexr_direction(int face, double col, double row, int n) {
    return face_vector(face, face_coord(col, n), face_coord(row, n));
}

double cube_openexr_pixel_solid_angle(int col, int row, int n) {
    double u0, u1, v0, v1;
    footprint(col, n, &u0, &u1);
    footprint(row, n, &v0, &v1);
    return rect_f(u1, v1) - rect_f(u0, v1) - rect_f(u1, v0) + rect_f(u0, v0);
}

Sh3Radiance project_cube_openexr(const float* rgb, int n, size_t row_stride, int threads) {
    if (n <= 0) return {};
    // Per face-local pixel: weight and footprint centre (the same on every face).
    std::vector<double> weight(static_cast<size_t>(n) * static_cast<size_t>(n));
    std::vector<double> centre(static_cast<size_t>(n) * 2);
    for (int i = 0; i < n; ++i) {
        double lo, hi;
        footprint(i, n, &lo, &hi);
        centre[static_cast<size_t>(i)] = 0.5 * (lo + hi);
    }
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            weight[static_cast<size_t>(r) * static_cast<size_t>(n) + static_cast<size_t>(c)] =
                cube_openexr_pixel_solid_angle(c, r, n);
    const int rows = 6 * n;
    std::vector<std::array<double, 27>> row_sums(static_cast<size_t>(rows));
    auto work = [&](int first, int last) {
        for (int y = first; y < last; ++y) {
            const int face = y / n, r = y % n;
            const float* p = rgb + static_cast<size_t>(y) * row_stride;
            std::array<double, 27> acc{};
            for (int c = 0; c < n; ++c) {
                const double w = weight[static_cast<size_t>(r) * static_cast<size_t>(n) + static_cast<size_t>(c)];
                const auto basis =
                    sh3_basis(face_vector(face, centre[static_cast<size_t>(c)], centre[static_cast<size_t>(r)]));
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

}  // namespace zhc
