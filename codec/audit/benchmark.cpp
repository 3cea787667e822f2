#include "codec/audit/benchmark.h"

#include <algorithm>
#include <chrono>
#include <numeric>

namespace zhc {

namespace {
template <class F>
Spread time_batches(int repeats, double units, F&& fn) {
    std::vector<double> t;
    for (int r = 0; r < std::max(1, repeats); ++r) {
        const auto a = std::chrono::steady_clock::now();
        fn();
        t.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - a).count() / units);
    }
    std::sort(t.begin(), t.end());
    return {t[t.size() / 2], t.front(), t.back()};
}
}  // namespace

std::vector<BenchRow> benchmark_codecs(const std::vector<BenchProbe>& probes, const std::vector<Vec3>& directions,
                                       const std::vector<const Codec*>& codecs, const CodecOptions& options,
                                       int repeats) {
    std::vector<BenchRow> rows;
    if (probes.empty()) return rows;
    volatile float sink = 0;
    for (const Codec* c : codecs) {
        BenchRow row;
        row.codec = c;
        std::vector<std::vector<std::uint8_t>> stored(probes.size(), std::vector<std::uint8_t>(c->size_bytes));
        for (size_t p = 0; p < probes.size(); ++p) {
            c->encode(probes[p].hub, options, stored[p].data(), nullptr);
            const ErrorMetrics m = compare_irradiance(codec_irradiance(*c, stored[p].data(), options, directions),
                                                      probes[p].reference);
            row.mean_rmse += m.rmse / probes.size();
            row.mean_relative_rmse += m.relative_rmse / probes.size();
        }
        // Encode: each batch encodes every probe enough times to last >= ~2 ms.
        std::vector<std::uint8_t> scratch(c->size_bytes);
        int inner = 1;
        for (;;) {
            const auto a = std::chrono::steady_clock::now();
            for (int i = 0; i < inner; ++i)
                for (const BenchProbe& p : probes) c->encode(p.hub, options, scratch.data(), nullptr);
            if (std::chrono::steady_clock::now() - a > std::chrono::milliseconds(2) || inner > (1 << 20)) break;
            inner *= 2;
        }
        const double units = double(inner) * probes.size();
        row.encode_ns = time_batches(repeats, units, [&] {
            for (int i = 0; i < inner; ++i)
                for (const BenchProbe& p : probes) {
                    c->encode(p.hub, options, scratch.data(), nullptr);
                    sink = sink + scratch[0];
                }
        });
        row.decode_ns = time_batches(repeats, double(probes.size()) * 64, [&] {
            for (int i = 0; i < 64; ++i)
                for (const auto& s : stored) sink = sink + c->decode(s.data(), options)[0].r;
        });
        row.eval_ns = time_batches(repeats, double(probes.size()) * directions.size(), [&] {
            for (const auto& s : stored)
                for (const Vec3& d : directions) sink = sink + c->irradiance(s.data(), options, d).g;
        });
        rows.push_back(row);
    }
    return rows;
}

std::vector<std::size_t> pareto_frontier(const std::vector<double>& cost, const std::vector<double>& error) {
    std::vector<std::size_t> order(cost.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return cost[a] != cost[b] ? cost[a] < cost[b] : error[a] < error[b];
    });
    std::vector<std::size_t> frontier;
    double best = std::numeric_limits<double>::infinity();
    for (size_t i : order)
        if (error[i] < best) {
            frontier.push_back(i);
            best = error[i];
        }
    return frontier;
}

}  // namespace zhc
