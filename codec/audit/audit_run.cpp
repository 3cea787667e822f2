#include "codec/audit/audit_run.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

namespace zhc {

namespace {

std::string fmt(double v, const char* f = "%.4g") {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

// One probe's evaluation: its reference, each codec's result and reconstruction.
struct ProbeSlot {
    std::vector<Rgb> reference;
    std::vector<RepresentationResult> results;
    std::vector<std::vector<Rgb>> reconstructed;
};

}  // namespace

std::vector<Rgb> AuditInput::reference_for(std::size_t probe, const std::vector<Vec3>& dirs) const {
    if (kind == "envmap" && probe == 0 && map_reference.size() == dirs.size()) return map_reference;
    return sh3_irradiance(probes[probe], dirs);
}

bool AuditGates::fails(const ErrorMetrics& m) const {
    return (max_rmse >= 0 && m.rmse > max_rmse) || (max_relative_rmse >= 0 && m.relative_rmse > max_relative_rmse) ||
           (fail_on_negative && m.min_irradiance < 0);
}

std::vector<std::string> AuditGates::descriptions() const {
    std::vector<std::string> out;
    if (max_rmse >= 0) out.push_back("rmse <= " + fmt(max_rmse) + " on every probe");
    if (max_relative_rmse >= 0) out.push_back("relative rmse <= " + fmt(max_relative_rmse) + " on every probe");
    if (fail_on_negative) out.push_back("no negative irradiance on any probe");
    return out;
}

InputAudit audit_input(const AuditInput& input, const std::vector<Vec3>& directions,
                       const std::vector<const Codec*>& codecs, const AuditOptions& options,
                       const AuditProbeCallback& on_probe) {
    const size_t nc = codecs.size(), probes = input.probes.size();
    InputAudit out;
    out.path = input.path;
    out.failing_probes.resize(nc);
    out.extremes.resize(nc);
    std::vector<MetricsAccumulator> acc(nc);
    std::vector<double> enc(nc), dec(nc);
    std::vector<EncodeStats> stats(nc);
    const size_t timed = options.timing ? std::min(probes, options.timed_probes) : 0;
    // Pools one probe, in probe order (the accumulators' sums depend on the order).
    auto pool = [&](size_t p, const ProbeSlot& s) {
        for (size_t c = 0; c < nc; ++c) {
            acc[c].add(s.reconstructed[c], s.reference);
            if (p < timed) {
                enc[c] += s.results[c].encode_ns / static_cast<double>(timed);
                dec[c] += s.results[c].decode_ns / static_cast<double>(timed);
            }
            stats[c].clamped_ratios += s.results[c].stats.clamped_ratios;
            stats[c].dering_clamped = stats[c].dering_clamped || s.results[c].stats.dering_clamped;
            if (options.gates.fails(s.results[c].metrics)) out.failing_probes[c].push_back(p);
            const ErrorMetrics& m = s.results[c].metrics;
            InputAudit::Extremes& x = out.extremes[c];
            if (p == 0 || m.rmse > x.rmse) {
                x.rmse = m.rmse;
                x.rmse_probe = p;
            }
            if (p == 0 || m.relative_rmse > x.relative_rmse) {
                x.relative_rmse = m.relative_rmse;
                x.relative_rmse_probe = p;
            }
            if (p == 0 || m.min_irradiance < x.min_irradiance) {
                x.min_irradiance = m.min_irradiance;
                x.min_irradiance_probe = p;
            }
        }
        if (on_probe) on_probe(p, s.results);
    };
    auto evaluate = [&](size_t p, bool measure_time, ProbeSlot& s) {
        s.reference = input.reference_for(p, directions);
        s.results = audit_probe(input.probes[p], s.reference, directions, codecs, options.codec_options, measure_time,
                                &s.reconstructed);
    };
    // The timed probes one after another on this thread: nothing else competes with the clock.
    size_t p = 0;
    for (ProbeSlot s; p < timed; ++p) {
        evaluate(p, true, s);
        pool(p, s);
    }
    // The rest in blocks of 2 x threads probes evaluated in parallel, then pooled in order (the
    // reconstructions of one block are held, not those of the whole input).
    const size_t threads = static_cast<size_t>(std::clamp(options.threads, 1, 256));
    std::vector<ProbeSlot> block(std::min(2 * threads, probes - p));
    while (p < probes) {
        const size_t n = std::min(block.size(), probes - p);
        const size_t workers = std::min(threads, n);
        auto work = [&, p, n, workers](size_t first) {
            for (size_t i = first; i < n; i += workers) evaluate(p + i, false, block[i]);
        };
        if (workers == 1) {
            work(0);
        } else {
            std::vector<std::thread> pool_threads;
            for (size_t t = 0; t < workers; ++t) pool_threads.emplace_back(work, t);
            for (std::thread& t : pool_threads) t.join();
        }
        for (size_t i = 0; i < n; ++i) pool(p + i, block[i]);
        p += n;
    }
    for (size_t c = 0; c < nc; ++c) {
        RepresentationResult r;
        r.codec = codecs[c];
        r.metrics = acc[c].result();
        r.encode_ns = enc[c];
        r.decode_ns = dec[c];
        r.stats = stats[c];
        out.results.push_back(r);
    }
    return out;
}

std::vector<RepresentationResult> aggregate_inputs(const std::vector<InputAudit>& inputs) {
    if (inputs.empty()) return {};
    const size_t nc = inputs[0].results.size();
    const double n = static_cast<double>(inputs.size());
    std::vector<RepresentationResult> aggregate(nc);
    for (size_t c = 0; c < nc; ++c) {
        RepresentationResult& a = aggregate[c];
        a.codec = inputs[0].results[c].codec;
        a.metrics.min_irradiance = inputs[0].results[c].metrics.min_irradiance;
        for (const InputAudit& in : inputs) {
            if (c >= in.results.size()) continue;  // inputs audited with fewer codecs: not pooled
            const RepresentationResult& r = in.results[c];
            a.metrics.rmse += r.metrics.rmse / n;
            a.metrics.relative_rmse += r.metrics.relative_rmse / n;
            a.metrics.max_abs = std::max(a.metrics.max_abs, r.metrics.max_abs);
            a.metrics.min_irradiance = std::min(a.metrics.min_irradiance, r.metrics.min_irradiance);
            a.metrics.negative_fraction += r.metrics.negative_fraction / n;
            a.metrics.chromaticity_error += r.metrics.chromaticity_error / n;
            a.encode_ns += r.encode_ns / n;
            a.decode_ns += r.decode_ns / n;
            a.stats.clamped_ratios += r.stats.clamped_ratios;
            a.stats.dering_clamped = a.stats.dering_clamped || r.stats.dering_clamped;
        }
    }
    return aggregate;
}

std::string GateFailure::message() const {
    std::string list;
    for (size_t i = 0; i < probes.size() && i < 10; ++i) {
        if (i) list += ',';
        list += std::to_string(probes[i]);
    }
    if (probes.size() > 10) list += ",... (" + std::to_string(probes.size()) + " probes)";
    return path + ": " + (codec ? std::string(codec->name) : std::string("?")) + " fails a gate (rmse " +
           fmt(metrics.rmse) + ", relative_rmse " + fmt(metrics.relative_rmse) + ", min_irradiance " +
           fmt(metrics.min_irradiance) + ") at probe " + list;
}

std::vector<std::string> GateResult::messages() const {
    std::vector<std::string> out;
    for (const GateFailure& f : failures) out.push_back(f.message());
    return out;
}

GateResult evaluate_gates(const std::vector<InputAudit>& inputs) {
    GateResult g;
    for (const InputAudit& in : inputs)
        for (size_t c = 0; c < in.failing_probes.size() && c < in.results.size(); ++c) {
            if (in.failing_probes[c].empty()) continue;
            g.failures.push_back({in.path, in.results[c].codec, in.results[c].metrics, in.failing_probes[c]});
        }
    return g;
}

AuditRun summarize_audit(std::vector<InputAudit> inputs) {
    AuditRun run;
    run.inputs = std::move(inputs);
    run.aggregate = aggregate_inputs(run.inputs);
    run.gates = evaluate_gates(run.inputs);
    return run;
}

AuditRun run_audit(const std::vector<AuditInput>& inputs, const std::vector<Vec3>& directions,
                   const std::vector<const Codec*>& codecs, const AuditOptions& options,
                   const std::function<void(std::size_t, std::size_t)>& progress) {
    std::vector<InputAudit> audited;
    for (const AuditInput& in : inputs) {
        audited.push_back(audit_input(in, directions, codecs, options));
        if (progress) progress(audited.size(), inputs.size());
    }
    return summarize_audit(std::move(audited));
}

double eval_ns_per_sample(const Codec& codec, const Sh3Radiance& hub, const std::vector<Vec3>& directions,
                          const CodecOptions& options) {
    std::vector<std::uint8_t> stored(codec.size_bytes);
    codec.encode(hub, options, stored.data(), nullptr);
    std::vector<double> t;
    volatile float sink = 0;
    for (int b = 0; b < 5; ++b) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<Rgb> e = codec_irradiance(codec, stored.data(), options, directions);
        t.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() /
                    static_cast<double>(std::max<size_t>(1, directions.size())));
        if (!e.empty()) sink = sink + e[0].r;
    }
    std::nth_element(t.begin(), t.begin() + 2, t.end());
    return t[2];
}

}  // namespace zhc
