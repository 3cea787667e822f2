// zhc/formats/envmap/envmap_colour.cpp — an OpenEXR file's chromaticities to zhc's working space
// (linear Rec. 709 primaries, D65 white; docs/conventions.md).
//
// RGB -> XYZ of the file and XYZ -> RGB of Rec. 709 are OpenEXR's own (Imf::RGBtoXYZ,
// Imf::XYZtoRGB, which also handle primaries with y = 0 such as XYZ's). When the white points
// differ, XYZ is adapted from the file's white to D65 with the linear Bradford transform (Lam 1985,
// the one ICC profiles use): the file's white (1, 1, 1) becomes Rec. 709 white (1, 1, 1), so a
// grey stays grey, and Rec. 709 primaries Bradford-adapted to another white (the D50 "sRGB" that
// ICC-managed tools write) convert to the identity.
#include <ImfChromaticities.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "formats/envmap/envmap_internal.h"

namespace zhc::envmap_detail {

namespace {

using M3 = double[3][3];

void mul(const M3 a, const M3 b, M3 out) {
    double t[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out[i][j] = t[i][j];
}

double det(const M3 m) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

void inverse(const M3 m, M3 out) {
    const double d = det(m);
    out[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / d;
    out[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / d;
    out[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / d;
    out[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / d;
    out[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / d;
    out[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / d;
    out[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / d;
    out[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / d;
    out[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / d;
}

// Imf's matrices act on row vectors (xyz = rgb * M): the 3x3 for column vectors is the transpose.
void from_imf(const Imath::M44f& m, M3 out) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out[i][j] = double(m[j][i]);
}

// Linear Bradford cone response matrix (XYZ -> "sharpened" LMS).
constexpr double kBradford[3][3] = {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}};

// XYZ adaptation from white (sx, sy) to white (dx, dy), both of luminance 1.
void bradford(double sx, double sy, double dx, double dy, M3 out) {
    const double s_xyz[3] = {sx / sy, 1.0, (1.0 - sx - sy) / sy}, d_xyz[3] = {dx / dy, 1.0, (1.0 - dx - dy) / dy};
    M3 scale = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int i = 0; i < 3; ++i) {
        double s = 0, d = 0;
        for (int k = 0; k < 3; ++k) s += kBradford[i][k] * s_xyz[k], d += kBradford[i][k] * d_xyz[k];
        scale[i][i] = d / s;
    }
    M3 b, b_inv;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b[i][j] = kBradford[i][j];
    inverse(b, b_inv);
    mul(scale, b, out);
    mul(b_inv, out, out);
}

std::string fmt(const char* f, double a, double b = 0) {
    char buf[96];
    std::snprintf(buf, sizeof buf, f, a, b);
    return buf;
}

}  // namespace

Result<ColourConversion> exr_colour_conversion(const std::string& name, const float* c, EnvmapInfo* info) {
    ColourConversion out;
    if (!c) {
        if (info) info->colour_conversion = "none (no chromaticities attribute: Rec. 709 primaries, D65 white)";
        return out;
    }
    if (info) {
        info->has_chromaticities = true;
        for (int i = 0; i < 8; ++i) info->chromaticities[static_cast<size_t>(i)] = c[i];
    }
    for (int i = 0; i < 8; ++i)
        if (!std::isfinite(c[i]))
            return make_error(ErrorCode::kBadFormat, name + ": chromaticities: non-finite value");
    if (!(c[7] > 0.0f))
        return make_error(ErrorCode::kBadFormat, name + ": chromaticities: white point y " + fmt("%g", c[7]) +
                                                     " is not positive");
    // The primaries' xyz as columns: zero determinant = collinear, no RGB space (OpenEXR's RGBtoXYZ
    // would divide by it).
    const M3 prim = {{c[0], c[2], c[4]}, {c[1], c[3], c[5]}, {1.0 - c[0] - c[1], 1.0 - c[2] - c[3], 1.0 - c[4] - c[5]}};
    if (!(std::fabs(det(prim)) > 1e-9))
        return make_error(ErrorCode::kBadFormat, name + ": chromaticities: the red, green and blue primaries are collinear "
                                                        "(they span no RGB space)");
    const Imf::Chromaticities file_c({c[0], c[1]}, {c[2], c[3]}, {c[4], c[5]}, {c[6], c[7]});
    const Imf::Chromaticities rec709;  // OpenEXR's default: Rec. 709 primaries, D65 white
    M3 to_xyz, to_709, adapt;
    from_imf(Imf::RGBtoXYZ(file_c, 1.0f), to_xyz);
    from_imf(Imf::XYZtoRGB(rec709, 1.0f), to_709);
    bradford(c[6], c[7], rec709.white.x, rec709.white.y, adapt);
    mul(adapt, to_xyz, out.m);
    mul(to_709, out.m, out.m);
    double worst = 0;
    bool finite = true;
    for (int i = 0; i < 3; ++i) {
        double row = 0;
        for (int j = 0; j < 3; ++j) {
            finite = finite && std::isfinite(out.m[i][j]);
            row += std::fabs(out.m[i][j] - (i == j ? 1.0 : 0.0));
        }
        worst = std::max(worst, row);
    }
    if (!finite || !(std::fabs(det(out.m)) > 1e-9))
        return make_error(ErrorCode::kBadFormat, name + ": chromaticities: no invertible conversion to Rec. 709 "
                                                        "(white point outside the primaries' range)");
    out.apply = worst > kColourIdentityTolerance;
    if (info) {
        const bool same_white = std::fabs(c[6] - rec709.white.x) < 1e-5f && std::fabs(c[7] - rec709.white.y) < 1e-5f;
        if (!out.apply)
            info->colour_conversion = "none (converts to Rec. 709 / D65 within " + fmt("%.2g", worst) + ": identity)";
        else
            info->colour_conversion = std::string("to Rec. 709 / D65") +
                                      (same_white ? "" : fmt(", Bradford adaptation from white (%.4f, %.4f)", c[6], c[7]));
    }
    return out;
}

Status apply_colour_conversion(const std::string& name, const ColourConversion& c, Image& img) {
    if (!c.apply) return Ok{};
    const size_t n = img.rgb.size() / 3;
    for (size_t p = 0; p < n; ++p) {
        float* v = &img.rgb[3 * p];
        const double in[3] = {v[0], v[1], v[2]};
        float out[3];
        for (int i = 0; i < 3; ++i) {
            const double o = c.m[i][0] * in[0] + c.m[i][1] * in[1] + c.m[i][2] * in[2];
            if (!(std::fabs(o) <= double(std::numeric_limits<float>::max()))) {
                std::ostringstream msg;
                msg << name << ": pixel at column " << p % static_cast<size_t>(img.width) << ", row "
                    << p / static_cast<size_t>(img.width) << " leaves the float range when converted from the file's "
                    << "chromaticities to Rec. 709";
                return make_error(ErrorCode::kInvalidValue, msg.str());
            }
            out[i] = static_cast<float>(o);
        }
        v[0] = out[0], v[1] = out[1], v[2] = out[2];
    }
    return Ok{};
}

}  // namespace zhc::envmap_detail
