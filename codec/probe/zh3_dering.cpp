// ZH3 deringing on the whole sphere by windowing L1 and the zonal term together (zhc's extension of
// ZH3 paper App. B in the spirit of Sloan 2017; see zh3_dering.h and docs/zh3.md).
#include "codec/probe/zh3_dering.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "codec/probe/quantize.h"

namespace zhc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Vector form of channel k's L1 band: f1(d) = kY1 v . d (codec/probe/zh3_internal.h uses the same).
Vec3 l1_vector(const Sh2Radiance& s, int k) { return {-double(s[3][k]), -double(s[1][k]), double(s[2][k])}; }

// Channel k's irradiance as a function of the angle theta to its zonal axis, at the worst azimuth:
//   E(theta) = Y00 f0 + A cos(theta) - C sin(theta) + B (3 cos^2(theta) - 1)
// with A = (2/3) kY1 (v . axis), C = (2/3) kY1 |v - (v . axis) axis| (>= 0), B = (1/4) kY20 f20.
// (For a direction at angle theta to the axis, v . n = A' cos + |v_perp| sin cos(phi), and the
// zonal term depends on theta only: phi = pi, i.e. n leaning away from v_perp, is the minimum.)
struct Profile {
    double dc = 0;  // Y00 f0
    double a = 0, c = 0, b = 0;
};
Profile channel_profile(const Zh3& z, ZonalAxisMode mode, const LuminanceWeights& w, int k) {
    const Vec3 axis = zh3_axis(z.linear, mode, k, w);
    const Vec3 v = l1_vector(z.linear, k);
    const double along = dot(v, axis);
    Profile p;
    p.dc = kY00 * z.linear[0][k];
    p.a = kIrradianceBandScale[1] * kY1 * along;
    p.c = kIrradianceBandScale[1] * kY1 * length(v - along * axis);
    p.b = kIrradianceBandScale[2] * kY20 * z.zonal[k];
    return p;
}

// Certified minimum of DC + s (a cos - c sin) + b (3 cos^2 - 1).
double profile_lower(const Profile& p, double s_linear, double b) {
    return p.dc + zh3_profile_minimum(s_linear * p.a, s_linear * p.c, b).lower;
}

bool feasible(const Profile& p, double s_linear, double b) {
    return profile_lower(p, s_linear, b) >= kZh3DeringMargin * p.dc;
}

}  // namespace

// Branch and bound on theta in [0, 2 pi). With h(t) = a cos t - c sin t + b (3 cos^2 t - 1):
//   h'(t)  = -a sin t - c cos t - 3 b sin 2t,
//   |h''|  = |-a cos t + c sin t - 6 b cos 2t| <= sqrt(a^2 + c^2) + 6 |b| =: M,
// so on [m - r, m + r]:  h >= h(m) - |h'(m)| r - M r^2 / 2  (Taylor with the remainder bound).
// An interval whose bound is within `tolerance` of the best value found is closed (its bound joins
// `lower`); otherwise it is halved. Depth first with a fixed stack: no allocation.
ProfileMinimum zh3_profile_minimum(double a, double c, double b, double tolerance) {
    if (!std::isfinite(a) || !std::isfinite(c) || !std::isfinite(b)) return {-kInf, kInf};
    const double scale = std::fabs(a) + std::fabs(c) + 2.0 * std::fabs(b);
    if (scale == 0.0) return {0.0, 0.0};
    const double tol = tolerance * scale;
    const double m2 = std::sqrt(a * a + c * c) + 6.0 * std::fabs(b);
    struct Node {
        double mid, half, value, slope;
    };
    auto eval = [&](double t, double half) {
        const double ct = std::cos(t), st = std::sin(t);
        return Node{t, half, a * ct - c * st + b * (3.0 * ct * ct - 1.0), -a * st - c * ct - 6.0 * b * ct * st};
    };
    constexpr int kStart = 64, kStack = 512, kBudget = 20000;
    Node stack[kStack];
    int top = 0, evaluations = 0;
    double upper = kInf, lower = kInf;
    const double half0 = kPi / kStart;
    for (int i = 0; i < kStart; ++i) {
        stack[top] = eval((2 * i + 1) * half0, half0);
        upper = std::min(upper, stack[top].value);
        ++top;
    }
    evaluations = kStart;
    while (top > 0) {
        const Node n = stack[--top];
        const double bound = n.value - std::fabs(n.slope) * n.half - 0.5 * m2 * n.half * n.half;
        if (bound >= upper - tol || evaluations + 2 > kBudget || top + 2 > kStack) {
            lower = std::min(lower, bound);
            continue;
        }
        const double h = 0.5 * n.half;
        const Node left = eval(n.mid - h, h), right = eval(n.mid + h, h);
        evaluations += 2;
        upper = std::min({upper, left.value, right.value});
        stack[top++] = left;
        stack[top++] = right;
    }
    return {std::min(lower, upper), upper};
}

double zh3_min_irradiance_bound(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w, int channel) {
    const Profile p = channel_profile(zh3, mode, w, std::clamp(channel, 0, 2));
    return profile_lower(p, 1.0, p.b);
}

double zh3_dering_window_scale(const Zh3& zh3, ZonalAxisMode mode, const LuminanceWeights& w) {
    double s = 1.0;
    for (int k = 0; k < 3; ++k) {
        const Profile p = channel_profile(zh3, mode, w, k);
        const double m = zh3_profile_minimum(p.a, p.c, p.b).lower;  // min of the non-DC part, <= 0
        if (!(p.dc > 0.0) || !std::isfinite(p.dc) || !std::isfinite(m)) {
            if (p.a != 0.0 || p.c != 0.0 || p.b != 0.0) s = 0.0;  // only DC can be kept
            continue;
        }
        // DC + s m >= margin DC  <=>  s <= (1 - margin) DC / -m.
        if (m < 0.0) s = std::min(s, (1.0 - kZh3DeringMargin) * p.dc / -m);
    }
    return std::clamp(s, 0.0, 1.0);
}

double zh3_dering_window(Zh3* zh3, ZonalAxisMode mode, const LuminanceWeights& w, double max_scale) {
    const Zh3 fit = *zh3;
    const double s = std::min(zh3_dering_window_scale(fit, mode, w), std::clamp(max_scale, 0.0, 1.0));
    if (s >= 1.0) return 1.0;
    // The window: L1 and zonal scaled by s (the luminance axis, from the L1, is unchanged).
    for (int k = 0; k < 3; ++k) {
        for (int i = 1; i < 4; ++i) zh3->linear[i][k] = static_cast<float>(fit.linear[i][k] * s);
        zh3->zonal[k] = static_cast<float>(fit.zonal[k] * s);
    }
    // Step 3: each zonal back towards its fit while the whole sphere stays >= margin. The profile's
    // L1 part is taken from the STORED (float) L1, so the check is on what the decoder sees.
    for (int k = 0; k < 3; ++k) {
        const Profile p = channel_profile(*zh3, mode, w, k);
        const double to_b = kIrradianceBandScale[2] * kY20;
        const double b_fit = fit.zonal[k] * to_b, b_win = double(zh3->zonal[k]) * to_b;
        if (!(p.dc > 0.0) || !std::isfinite(b_fit) || !feasible(p, 1.0, b_win)) continue;
        double good = b_win, bad = b_fit;
        if (feasible(p, 1.0, b_fit)) {
            good = b_fit;
        } else {
            for (int it = 0; it < 48 && std::fabs(good - bad) > 1e-12 * std::fabs(b_fit); ++it) {
                const double mid = 0.5 * (good + bad);
                (feasible(p, 1.0, mid) ? good : bad) = mid;
            }
        }
        // The float nearest `good` may lie on the infeasible side: step back towards the window's
        // value (which passed) until the stored float itself passes.
        float stored = static_cast<float>(good / to_b);
        for (int step = 0; step < 64 && !feasible(p, 1.0, double(stored) * to_b); ++step)
            stored = std::nextafter(stored, zh3->zonal[k]);
        if (feasible(p, 1.0, double(stored) * to_b)) zh3->zonal[k] = stored;
    }
    return s;
}

// ---- codec-table entries ----------------------------------------------------------------------

namespace {

constexpr std::size_t kZh3Bytes = 15 * 4;

void encode_zh3_dering(const Sh3Radiance& in, const CodecOptions& o, std::uint8_t* out, EncodeStats* stats) {
    Zh3 z = zh3_fit(in, ZonalAxisMode::kLuminance, o.luminance);
    const Zh3 fit = z;
    double cap = 1.0;
    // The window is chosen on doubles and stored as floats; confirm on the stored values (the
    // margin makes a second round practically never needed).
    for (int round = 0; round < 8; ++round) {
        z = fit;
        const double s = zh3_dering_window(&z, ZonalAxisMode::kLuminance, o.luminance, cap);
        bool ok = true;
        for (int k = 0; k < 3; ++k)
            ok = ok && !(zh3_min_irradiance_bound(z, ZonalAxisMode::kLuminance, o.luminance, k) < 0.0 &&
                         z.linear[0][k] > 0.0f);
        if (stats) stats->dering_clamped = s < 1.0;
        if (ok) break;
        cap = s * (1.0 - std::ldexp(1.0, -16 + 2 * round));
    }
    float v[15];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) v[i * 3 + k] = z.linear[i][k];
    for (int k = 0; k < 3; ++k) v[12 + k] = z.zonal[k];
    store_floats(v, out);
}

// The stored bytes are zh3_lum's: the same decoder and evaluator.
const Codec& zh3_lum_entry() {
    static const Codec* entry = [] {
        for (const Codec& c : zh3_codecs())
            if (c.name == "zh3_lum") return &c;
        return static_cast<const Codec*>(nullptr);
    }();
    return *entry;
}
Sh3Radiance decode_zh3_lum(const std::uint8_t* in, const CodecOptions& o) { return zh3_lum_entry().decode(in, o); }
Rgb irradiance_zh3_lum(const std::uint8_t* in, const CodecOptions& o, Vec3 n) {
    return zh3_lum_entry().irradiance(in, o, n);
}

void encode_dering_q16(const Sh3Radiance& in, const CodecOptions& p, std::uint8_t* out, EncodeStats* stats) {
    QuantEncodeControls c;
    c.dering = true;
    encode_packed(PackedLayout::kZh3Q16, in, p, out, stats, c);
}
Sh3Radiance decode_q16(const std::uint8_t* in, const CodecOptions& p) {
    return decode_packed(PackedLayout::kZh3Q16, in, p);
}
constexpr PackedCodec kDeringQ16{PackedLayout::kZh3Q16, encode_dering_q16, decode_q16};

const Codec kDeringCodecs[] = {
    {"zh3_dering", "zh3_lum with L1 and zonal windowed together: irradiance >= 0 on the whole sphere", kZh3Bytes,
     encode_zh3_dering, decode_zh3_lum, irradiance_zh3_lum, {.zonal_axis = ZonalAxis::kLuminance}},
    packed_codec<kDeringQ16>("zh3_dering_q16",
                             "zh3_dering in zh3_q16 bytes; the decoded probe is checked and windowed further if needed",
                             ZonalAxis::kFromParams),
};

}  // namespace

std::span<const Codec> zh3_dering_codecs() { return kDeringCodecs; }

}  // namespace zhc
