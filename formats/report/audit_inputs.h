// zhc/formats/report/audit_inputs.h — what `zhc audit` reads and the pictures it writes.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "codec/audit/audit_run.h"
#include "codec/status.h"
#include "formats/envmap/envmap.h"

namespace zhc {

struct AuditLoadOptions {
    int threads = 1;
    bool replace_non_finite = false;
    std::string part;  // EXR part (EnvmapReadOptions::part)
    LatLongConvention latlong = LatLongConvention::kOpenExr;  // EnvmapReadOptions::latlong
    LdrDecoding ldr;  // EnvmapReadOptions::ldr (8-bit cube maps)
};

// Files and folders -> the list of files to audit (folders: their .exr/.hdr/.zhp/.json files,
// sorted by name, not recursive). Missing paths are an error. A folder's JSON file that is not a
// probe list (a zhc-scene file, a glTF file, a document with no "probes" array) is left out and,
// when `skipped` is given, listed there as "PATH: why"; a file named on its own is always kept.
Result<std::vector<std::string>> expand_audit_inputs(const std::vector<std::string>& paths,
                                                     std::vector<std::string>* skipped = nullptr);
// The error for a file of no format audit, convert and info read (exit 4, kBadFormat), with the
// Git LFS hint when the bytes are an LFS pointer; for a KTX2, KTX 1 or DDS texture that is not a
// cube map, the environment-map reader's own error (exit 5, kUnsupported, as `zhc project` gives).
Error unknown_probe_input(const std::string& path, std::span<const std::uint8_t> bytes);

// Reads one file as an AuditInput (codec/audit/audit_run.h): an environment map (.exr, .hdr; its
// reference integrated at `dirs`), a probe container or a JSON probe list.
Result<AuditInput> load_audit_input(const std::string& path, const std::vector<Vec3>& dirs,
                                    const AuditLoadOptions& options);

// The audit of files: each is loaded (load_audit_input) and audited (audit_input) in order; then
// aggregated and gated (summarize_audit). `after_input` (if set) runs after each input's audit,
// e.g. to write its pictures; a failure there stops the audit and is returned as is.
struct AuditedFiles {
    std::vector<AuditInput> inputs;  // as loaded, in file order
    AuditRun run;                    // run.inputs[i] is the audit of inputs[i]
};
using AuditFileHook = std::function<Status(const AuditInput& input, const InputAudit& audit, std::size_t index)>;
Result<AuditedFiles> audit_files(const std::vector<std::string>& files, const std::vector<Vec3>& dirs,
                                 const std::vector<const Codec*>& codecs, const AuditOptions& options,
                                 const AuditLoadOptions& load, const AuditFileHook& after_input = {});

// Writes DIR/<input stem>.png: one row per reference/representation, each a lat-long irradiance
// strip (tone-mapped, negative irradiance in magenta) beside a false-colour error strip, labelled.
Status write_audit_images(const std::string& dir, const AuditInput& input, const std::vector<Vec3>& dirs,
                          const std::vector<const Codec*>& codecs, const CodecOptions& options);

}  // namespace zhc
