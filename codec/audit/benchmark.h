// zhc/codec/audit/benchmark.h — what accuracy costs in time: per representation, bytes per probe,
// encode ns/probe, irradiance evaluation ns/sample and error, over a set of probes.
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <vector>

#include "codec/audit/audit.h"
#include "codec/probe/codec.h"

namespace zhc {

struct BenchProbe {
    Sh3Radiance hub;
    std::vector<Rgb> reference;  // true irradiance at the benchmark directions
};

struct Spread {
    double median = 0, min = 0, max = 0;  // over repeats
};

struct BenchRow {
    const Codec* codec = nullptr;
    double mean_rmse = 0;           // mean over probes of the irradiance RMSE
    double mean_relative_rmse = 0;  // mean over probes of RMSE / mean reference irradiance
    Spread encode_ns;               // per probe
    Spread decode_ns;               // per probe, to the SH3 hub
    Spread eval_ns;                 // per irradiance sample through the codec's runtime path
};

// Each timing: `repeats` batches over all probes (and all directions for evaluation); the
// per-probe or per-sample time of each batch; median, min and max over batches. Single-threaded.
std::vector<BenchRow> benchmark_codecs(const std::vector<BenchProbe>& probes, const std::vector<Vec3>& directions,
                                       const std::vector<const Codec*>& codecs, const CodecOptions& options,
                                       int repeats);

// Indices of the rows on the Pareto frontier of (cost, error): no other row has both lower-or-
// equal cost and lower error. Sorted by cost.
std::vector<std::size_t> pareto_frontier(const std::vector<double>& cost, const std::vector<double>& error);

}  // namespace zhc
