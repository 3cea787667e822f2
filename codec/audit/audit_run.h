// zhc/codec/audit/audit_run.h — the audit of a set of inputs: every representation on every probe of
// every input, pooled per input and across inputs, timed, and checked against pass/fail gates.
//
// What `zhc audit` computes (the CLI only parses options, prints and maps to exit codes); reading
// files and writing pictures is formats/report/audit_inputs.h. Results do not depend on the
// thread count: probes are evaluated in parallel but pooled in probe order (MetricsAccumulator).
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
// Callbacks in the options are called on the calling thread, one at a time.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "codec/audit/audit.h"

namespace zhc {

// One audited input: its probes (SH3 radiance hubs) and, for an environment map, the map itself
// (downsampled) and the true irradiance at the audit directions. Loaded from a file by
// formats/report/audit_inputs.h (load_audit_input) or built in memory (kind "probes").
struct AuditInput {
    std::string path;
    std::string kind;         // "envmap" or "probes"
    std::string description;  // one line for the report
    // What the errors are measured against, one line (reports, JSON "reference"): the map's own
    // irradiance, or the probes' SH3 as stored; for a lossy stored representation the line says
    // that the reference is the stored data (auditing the same representation shows 0 error).
    std::string reference;
    std::vector<Sh3Radiance> probes;
    LatLongImage map;                  // envmaps: the flux-preserving downsample used as reference
    std::vector<Rgb> map_reference;    // envmaps: E(n) at the audit directions
    // The reference irradiance of probe p at `dirs` (the map's for an envmap, else the probe's SH3).
    std::vector<Rgb> reference_for(std::size_t probe, const std::vector<Vec3>& dirs) const;
};

// Pass/fail thresholds, checked on every probe separately (a negative threshold is off).
struct AuditGates {
    double max_rmse = -1;
    double max_relative_rmse = -1;
    bool fail_on_negative = false;  // fail when the reconstruction goes below 0 anywhere

    bool configured() const { return max_rmse >= 0 || max_relative_rmse >= 0 || fail_on_negative; }
    // True when one probe's metrics break a configured gate (rmse > max_rmse, relative_rmse >
    // max_relative_rmse, or min_irradiance < 0 with fail_on_negative).
    bool fails(const ErrorMetrics& probe) const;
    // One line per configured gate ("rmse <= 0.01 on every probe", ...), for reports.
    std::vector<std::string> descriptions() const;
};

struct AuditOptions {
    CodecOptions codec_options;
    bool timing = true;             // time encode/decode (audit_probe) on the first timed_probes probes
    std::size_t timed_probes = 8;   // a few probes, not all of a big grid; timed on the calling thread
                                    // (times are means over them; 0 when timing is off)
    int threads = 1;                // untimed probes evaluated in parallel (clamped to 1..256)
    AuditGates gates;
};

// One input's result.
struct InputAudit {
    std::string path;                                  // the input's path (gate messages)
    std::vector<RepresentationResult> results;         // per codec, pooled over the input's probes;
                                                       // times: mean over the timed probes
    std::vector<std::vector<std::size_t>> failing_probes;  // per codec: probes failing a gate, ascending
    // Per codec, probe by probe: the values the gates test at their worst and the first probe
    // where each occurs (gate summaries: "worst rmse 0.02 at probe 7").
    struct Extremes {
        double rmse = 0, relative_rmse = 0, min_irradiance = 0;
        std::size_t rmse_probe = 0, relative_rmse_probe = 0, min_irradiance_probe = 0;
    };
    std::vector<Extremes> extremes;
};

// Called once per probe, in probe order on the calling thread, with each codec's result on it.
using AuditProbeCallback = std::function<void(std::size_t probe, const std::vector<RepresentationResult>& per_codec)>;

// Audits every probe of `input` with each codec against input.reference_for(p, directions).
InputAudit audit_input(const AuditInput& input, const std::vector<Vec3>& directions,
                       const std::vector<const Codec*>& codecs, const AuditOptions& options,
                       const AuditProbeCallback& on_probe = {});

// Across inputs, per codec: the mean of rmse, relative rmse, negative fraction, chromaticity error
// and times; the worst max_abs and minimum irradiance; clamps summed, dering flags or-ed. Each
// input counts once whatever its probe count. Empty when `inputs` is.
std::vector<RepresentationResult> aggregate_inputs(const std::vector<InputAudit>& inputs);

// A representation failing a gate on some probes of one input.
struct GateFailure {
    std::string path;
    const Codec* codec = nullptr;
    ErrorMetrics metrics;              // the input's pooled metrics for the codec
    std::vector<std::size_t> probes;   // the failing probes, ascending
    // "PATH: NAME fails a gate (rmse R, relative_rmse Q, min_irradiance M) at probe 1,5,..."
    // (at most 10 probes listed, then ",... (N probes)").
    std::string message() const;
};

struct GateResult {
    std::vector<GateFailure> failures;  // input order, then codec order
    bool passed() const { return failures.empty(); }
    std::vector<std::string> messages() const;
};

GateResult evaluate_gates(const std::vector<InputAudit>& inputs);

// A whole audit: per input, across inputs, gates.
struct AuditRun {
    std::vector<InputAudit> inputs;
    std::vector<RepresentationResult> aggregate;
    GateResult gates;
};

// Aggregates and evaluates the gates of inputs audited one by one (audit_input).
AuditRun summarize_audit(std::vector<InputAudit> inputs);

// audit_input on each input in order (progress(done, total) after each), then summarize_audit.
AuditRun run_audit(const std::vector<AuditInput>& inputs, const std::vector<Vec3>& directions,
                   const std::vector<const Codec*>& codecs, const AuditOptions& options,
                   const std::function<void(std::size_t done, std::size_t total)>& progress = {});

// CPU time in ns of one irradiance evaluation through the codec's runtime path, on `hub` encoded
// with the codec: the median of 5 batches, each evaluating every direction once.
double eval_ns_per_sample(const Codec& codec, const Sh3Radiance& hub, const std::vector<Vec3>& directions,
                          const CodecOptions& options);

}  // namespace zhc
