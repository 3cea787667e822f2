#include "codec/audit/audit.h"

#include <algorithm>
#include <chrono>
#include <thread>

namespace zhc {

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
    // Pixel directions and solid-angle-weighted radiance, structure of arrays for the inner loop.
    const size_t n = static_cast<size_t>(map.width) * static_cast<size_t>(map.height);
    std::vector<double> px(n), py(n), pz(n), wr(n), wg(n), wb(n);
    for (int y = 0; y < map.height; ++y) {
        const double w = latlong_pixel_solid_angle(y, map.width, map.height);
        for (int x = 0; x < map.width; ++x) {
            const size_t i = static_cast<size_t>(y) * map.width + x;
            const Vec3 d = latlong_direction(x, y, map.width, map.height, map.convention);
            px[i] = d.x;
            py[i] = d.y;
            pz[i] = d.z;
            wr[i] = w * map.rgb[i * 3];
            wg[i] = w * map.rgb[i * 3 + 1];
            wb[i] = w * map.rgb[i * 3 + 2];
        }
    }
    std::vector<Rgb> out(directions.size());
    auto work = [&](size_t begin, size_t end) {
        for (size_t j = begin; j < end; ++j) {
            const Vec3 nrm = directions[j];
            double r = 0, g = 0, b = 0;
            for (size_t i = 0; i < n; ++i) {
                const double c = std::max(0.0, nrm.x * px[i] + nrm.y * py[i] + nrm.z * pz[i]);
                r += c * wr[i];
                g += c * wg[i];
                b += c * wb[i];
            }
            out[j] = {static_cast<float>(r / kPi), static_cast<float>(g / kPi), static_cast<float>(b / kPi)};
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
