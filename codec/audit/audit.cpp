#include "codec/audit/audit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace zhc {

namespace {

// Gauss-Legendre nodes and weights on [-1, 1], four points.
constexpr double kGaussX[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
constexpr double kGaussW[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
// The rows' theta range is cut into at least this many pieces (a small map's rows are cut into
// several), each integrated with the four-point rule.
constexpr int kMinThetaPieces = 256;

// Per row, the running integrals over phi (ascending, from the map's smallest phi) of the
// radiance times 1, cos(phi) and sin(phi), per channel, at every column boundary: the row's
// radiance is constant over each pixel, so the integral from the start to any phi is a prefix sum
// plus the part of one column in closed form.
struct RowPrefix {
    double one[3], c[3], s[3];
};

struct LatLongFootprint {
    int width = 0, height = 0;
    double phi_min = 0, dphi = 0;
    std::vector<double> lo_sin, lo_cos;  // sin, cos of each column's smallest phi (ascending order)
};

// Integral over phi in [phi_min, x] of L(phi) (one, cos phi, sin phi) for one row, x in
// [phi_min, phi_min + 2 pi]; sx, cx: sin x, cos x.
inline void row_cumulative(const LatLongFootprint& g, const RowPrefix* prefix, const float* ascending_rgb, double x, double sx,
                           double cx, double out[3][3]) {
    int j = static_cast<int>(std::floor((x - g.phi_min) / g.dphi));
    j = std::clamp(j, 0, g.width - 1);
    const double lo = g.phi_min + j * g.dphi;
    const double d1 = x - lo, dc = sx - g.lo_sin[j], ds = g.lo_cos[j] - cx;
    const RowPrefix& p = prefix[j];
    const float* v = ascending_rgb + static_cast<size_t>(j) * 3;
    for (int k = 0; k < 3; ++k) {
        out[0][k] = p.one[k] + v[k] * d1;
        out[1][k] = p.c[k] + v[k] * dc;
        out[2][k] = p.s[k] + v[k] * ds;
    }
}

}  // namespace

LatLongImage downsample_for_audit(LatLongView map, int min_width, int min_height) {
    int f = 1;
    while (map.width % (2 * f) == 0 && map.height % (2 * f) == 0 && map.width / (2 * f) >= min_width &&
           map.height / (2 * f) >= min_height)
        f *= 2;
    LatLongImage out;
    out.width = map.width / f;
    out.height = map.height / f;
    out.convention = map.convention;
    out.rgb.assign(static_cast<size_t>(out.width) * static_cast<size_t>(out.height) * 3, 0.0f);
    for (int y = 0; y < out.height; ++y) {
        const double big = latlong_pixel_solid_angle(y, out.width, out.height);
        for (int x = 0; x < out.width; ++x) {
            double acc[3] = {};
            for (int sy = 0; sy < f; ++sy) {
                const double w = latlong_pixel_solid_angle(y * f + sy, map.width, map.height);
                const float* row = map.rgb + static_cast<size_t>(y * f + sy) * static_cast<size_t>(map.width) * 3;
                for (int sx = 0; sx < f; ++sx)
                    for (int k = 0; k < 3; ++k) acc[k] += w * row[(x * f + sx) * 3 + k];
            }
            for (int k = 0; k < 3; ++k)
                out.rgb[(static_cast<size_t>(y) * out.width + x) * 3 + k] = static_cast<float>(acc[k] / big);
        }
    }
    return out;
}

std::vector<Rgb> integrate_irradiance(LatLongView map, const std::vector<Vec3>& directions, int threads) {
    // E(n) = (1/pi) sum over pixels of L_pixel * integral over the pixel's footprint of
    // max(0, n . w) dw. With w = (sin t cos p, sin t sin p, cos t) and n = (A cos q, A sin q, nz),
    // n . w = a cos(p - q) + b (a = A sin t, b = nz cos t): at fixed theta the clamped cosine is
    // positive on the arc |p - q| < g, cos g = -b / a (all of the ring when b >= a, none when
    // b <= -a), and its integral against the row's piecewise-constant radiance over that arc is
    // exact (row_cumulative). The theta integral uses four-point Gauss-Legendre on pieces of each
    // row, cut where the arc appears or covers the ring (a = |b|) so that no piece holds that
    // square-root point inside.
    std::vector<Rgb> out(directions.size());
    if (map.width <= 0 || map.height <= 0 || map.rgb == nullptr) return out;
    const int w = map.width, h = map.height;
    LatLongFootprint g;
    g.width = w;
    g.height = h;
    // Column c spans phi in [s - 2 pi (c + 1) / W, s - 2 pi c / W], s = pi (kOpenExr) or 1.5 pi
    // (kGltf, latlong_direction): ascending column j = W - 1 - c starts at phi_min + j dphi.
    g.phi_min = kPi * ((map.convention == LatLongConvention::kGltf ? 1.5 : 1.0) - 2.0);
    g.dphi = 2.0 * kPi / w;
    g.lo_sin.resize(static_cast<size_t>(w) + 1);
    g.lo_cos.resize(static_cast<size_t>(w) + 1);
    for (int j = 0; j <= w; ++j) {
        const double phi = g.phi_min + j * g.dphi;
        g.lo_sin[static_cast<size_t>(j)] = std::sin(phi);
        g.lo_cos[static_cast<size_t>(j)] = std::cos(phi);
    }
    // Rows in ascending phi order and their prefix integrals (W + 1 boundaries per row).
    const size_t stride = static_cast<size_t>(w) + 1;
    std::vector<float> ascending(static_cast<size_t>(w) * static_cast<size_t>(h) * 3);
    std::vector<RowPrefix> prefix(stride * static_cast<size_t>(h));
    for (int y = 0; y < h; ++y) {
        const float* row = map.rgb + static_cast<size_t>(y) * static_cast<size_t>(w) * 3;
        float* asc = ascending.data() + static_cast<size_t>(y) * static_cast<size_t>(w) * 3;
        RowPrefix* p = prefix.data() + static_cast<size_t>(y) * stride;
        p[0] = {};
        for (int j = 0; j < w; ++j) {
            const float* v = row + static_cast<size_t>(w - 1 - j) * 3;
            const double d1 = g.dphi, dc = g.lo_sin[j + 1] - g.lo_sin[j], ds = g.lo_cos[j] - g.lo_cos[j + 1];
            for (int k = 0; k < 3; ++k) {
                asc[j * 3 + k] = v[k];
                p[j + 1].one[k] = p[j].one[k] + v[k] * d1;
                p[j + 1].c[k] = p[j].c[k] + v[k] * dc;
                p[j + 1].s[k] = p[j].s[k] + v[k] * ds;
            }
        }
    }
    const int pieces = std::max(1, (kMinThetaPieces + h - 1) / h);
    auto work = [&](size_t begin, size_t end) {
        for (size_t jd = begin; jd < end; ++jd) {
            const Vec3 nrm = directions[jd];
            const double nx = nrm.x, ny = nrm.y, nz = nrm.z;
            const double big_a = std::sqrt(nx * nx + ny * ny);
            const double cq = big_a > 0 ? nx / big_a : 1.0, sq = big_a > 0 ? ny / big_a : 0.0;
            const double q = std::atan2(sq, cq);
            // Where the arc appears or fills the ring: a = |b|, theta = atan2(|nz|, A) and pi minus it.
            const double t_star1 = std::atan2(std::fabs(nz), big_a), t_star2 = kPi - t_star1;
            double acc[3] = {0, 0, 0};
            for (int y = 0; y < h; ++y) {
                const RowPrefix* p = prefix.data() + static_cast<size_t>(y) * stride;
                const float* asc = ascending.data() + static_cast<size_t>(y) * static_cast<size_t>(w) * 3;
                const RowPrefix& total = p[w];
                double row_acc[3] = {0, 0, 0};
                const double t0 = kPi * y / h, t1 = kPi * (y + 1) / h;
                for (int s = 0; s < pieces; ++s) {
                    double cuts[4] = {t0 + (t1 - t0) * s / pieces, 0, 0, t0 + (t1 - t0) * (s + 1) / pieces};
                    int nc = 1;
                    for (double ts : {t_star1, t_star2})
                        if (ts > cuts[0] && ts < cuts[3] && (nc == 1 || ts > cuts[nc - 1])) cuts[nc++] = ts;
                    cuts[nc] = cuts[3];
                    for (int seg = 0; seg < nc; ++seg) {
                        const double lo = cuts[seg], hi = cuts[seg + 1], half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
                        if (!(half > 0)) continue;
                        for (int gi = 0; gi < 4; ++gi) {
                            const double t = mid + half * kGaussX[gi];
                            const double st = std::sin(t), ct = std::cos(t);
                            const double a = big_a * st, b = nz * ct;
                            const double wgt = kGaussW[gi] * half * st;
                            if (b >= a) {  // the whole ring faces n
                                for (int k = 0; k < 3; ++k)
                                    row_acc[k] += wgt * (a * (cq * total.c[k] + sq * total.s[k]) + b * total.one[k]);
                                continue;
                            }
                            if (b <= -a) continue;  // none of it does
                            const double cg = -b / a, sg = std::sqrt(std::max(0.0, 1.0 - cg * cg));
                            const double gamma = std::acos(std::clamp(cg, -1.0, 1.0));
                            // The arc [q - gamma, q + gamma], its start moved into [phi_min, phi_min + 2 pi).
                            double x0 = q - gamma;
                            x0 -= 2.0 * kPi * std::floor((x0 - g.phi_min) / (2.0 * kPi));
                            const double x1 = x0 + 2.0 * gamma;
                            const double s0 = sq * cg - cq * sg, c0 = cq * cg + sq * sg;  // sin, cos(q - gamma)
                            const double s1 = sq * cg + cq * sg, c1 = cq * cg - sq * sg;  // sin, cos(q + gamma)
                            double from[3][3], to[3][3];
                            row_cumulative(g, p, asc, x0, s0, c0, from);
                            const double end = g.phi_min + 2.0 * kPi;
                            double part[3][3];
                            if (x1 <= end) {
                                row_cumulative(g, p, asc, x1, s1, c1, to);
                                for (int r = 0; r < 3; ++r)
                                    for (int k = 0; k < 3; ++k) part[r][k] = to[r][k] - from[r][k];
                            } else {  // the arc wraps past the map's seam
                                row_cumulative(g, p, asc, x1 - 2.0 * kPi, s1, c1, to);
                                for (int k = 0; k < 3; ++k) {
                                    part[0][k] = total.one[k] - from[0][k] + to[0][k];
                                    part[1][k] = total.c[k] - from[1][k] + to[1][k];
                                    part[2][k] = total.s[k] - from[2][k] + to[2][k];
                                }
                            }
                            for (int k = 0; k < 3; ++k)
                                row_acc[k] += wgt * (a * (cq * part[1][k] + sq * part[2][k]) + b * part[0][k]);
                        }
                    }
                }
                for (int k = 0; k < 3; ++k) acc[k] += row_acc[k];
            }
            out[jd] = {static_cast<float>(acc[0] / kPi), static_cast<float>(acc[1] / kPi), static_cast<float>(acc[2] / kPi)};
        }
    };
    threads = std::clamp(threads, 1, 64);
    if (threads == 1) {
        work(0, directions.size());
    } else {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
            pool.emplace_back(work, directions.size() * t / threads, directions.size() * (t + 1) / threads);
        for (auto& th : pool) th.join();
    }
    return out;
}

std::vector<Rgb> sh3_irradiance(const Sh3Radiance& sh, const std::vector<Vec3>& directions) {
    const Sh3Irradiance e = to_irradiance(sh);
    std::vector<Rgb> out;
    out.reserve(directions.size());
    for (const Vec3& d : directions) out.push_back(evaluate(e, d));
    return out;
}

ErrorMetrics compare_irradiance(const std::vector<Rgb>& rec, const std::vector<Rgb>& ref) {
    MetricsAccumulator acc;
    acc.add(rec, ref);
    return acc.result();
}

void MetricsAccumulator::add(const std::vector<Rgb>& rec, const std::vector<Rgb>& ref) {
    const size_t n = std::min(rec.size(), ref.size());
    if (n == 0) return;
    if (samples_ == 0) min_ = rec[0].r;
    double mean = 0;
    for (size_t i = 0; i < n; ++i) {
        bool neg = false;
        for (int k = 0; k < 3; ++k) {
            const double d = double(rec[i][k]) - ref[i][k];
            sq_ += d * d;
            mean += ref[i][k];
            max_abs_ = std::max(max_abs_, std::fabs(d));
            min_ = std::min(min_, double(rec[i][k]));
            neg = neg || rec[i][k] < 0;
        }
        negative_ += neg ? 1 : 0;
    }
    sum_ref_ += mean;
    mean /= 3.0 * n;
    samples_ += n;
    double chroma = 0;
    size_t counted = 0;
    // Per probe: directions whose reference is darker than 1e-3 of this probe's mean are skipped.
    const double floor = 3.0 * mean * 1e-3;
    for (size_t i = 0; i < n; ++i) {
        const double sref = double(ref[i].r) + ref[i].g + ref[i].b;
        if (!(sref > floor)) continue;
        const double srec = double(rec[i].r) + rec[i].g + rec[i].b;
        // A reconstruction with no positive energy has no chromaticity: count it as the largest
        // possible shift in the rg triangle (sqrt(2)).
        double dist = std::sqrt(2.0);
        if (srec > 0) {
            const double dr = rec[i].r / srec - ref[i].r / sref, dg = rec[i].g / srec - ref[i].g / sref;
            dist = std::min(std::sqrt(dr * dr + dg * dg), std::sqrt(2.0));
        }
        chroma += dist;
        ++counted;
    }
    chroma_sum_ += chroma;
    chroma_count_ += counted;
}

ErrorMetrics MetricsAccumulator::result() const {
    ErrorMetrics m;
    if (samples_ == 0) return m;
    const double mean = sum_ref_ / (3.0 * samples_);
    m.rmse = std::sqrt(sq_ / (3.0 * samples_));
    m.relative_rmse = mean > 0 ? m.rmse / mean : 0.0;
    m.max_abs = max_abs_;
    m.min_irradiance = min_;
    m.negative_fraction = double(negative_) / samples_;
    m.chromaticity_error = chroma_count_ ? chroma_sum_ / chroma_count_ : 0.0;
    return m;
}

std::vector<RepresentationResult> audit_probe(const Sh3Radiance& hub, const std::vector<Rgb>& reference,
                                              const std::vector<Vec3>& directions,
                                              const std::vector<const Codec*>& codecs, const CodecOptions& options,
                                              bool measure_time, std::vector<std::vector<Rgb>>* reconstructed) {
    std::vector<RepresentationResult> out;
    if (reconstructed) reconstructed->clear();
    for (const Codec* c : codecs) {
        RepresentationResult r;
        r.codec = c;
        std::vector<std::uint8_t> stored(c->size_bytes);
        c->encode(hub, options, stored.data(), &r.stats);
        const std::vector<Rgb> rec = codec_irradiance(*c, stored.data(), options, directions);
        r.metrics = compare_irradiance(rec, reference);
        if (reconstructed) reconstructed->push_back(rec);
        if (measure_time) {
            // Batches of >= 20 us; median of 5 batches. The sink keeps the work observable.
            auto time_ns = [](auto&& fn) {
                int reps = 1;
                for (;;) {
                    const auto a = std::chrono::steady_clock::now();
                    for (int i = 0; i < reps; ++i) fn();
                    const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - a).count();
                    if (ns > 20000 || reps >= (1 << 20)) break;
                    reps *= 4;
                }
                std::vector<double> t;
                for (int b = 0; b < 5; ++b) {
                    const auto a = std::chrono::steady_clock::now();
                    for (int i = 0; i < reps; ++i) fn();
                    t.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - a).count() / reps);
                }
                std::sort(t.begin(), t.end());
                return t[2];
            };
            std::vector<std::uint8_t> scratch(c->size_bytes);
            volatile float sink = 0;
            r.encode_ns = time_ns([&] {
                c->encode(hub, options, scratch.data(), nullptr);
                sink = sink + scratch[0];
            });
            r.decode_ns = time_ns([&] {
                const Sh3Radiance d = c->decode(stored.data(), options);
                sink = sink + d[0].r;
            });
        }
        out.push_back(r);
    }
    return out;
}

std::vector<Rgb> codec_irradiance(const Codec& codec, const std::uint8_t* stored, const CodecOptions& options,
                                  const std::vector<Vec3>& directions) {
    std::vector<Rgb> out;
    out.reserve(directions.size());
    for (const Vec3& d : directions) out.push_back(codec.irradiance(stored, options, d));
    return out;
}

}  // namespace zhc
