// zhc/formats/report/audit_inputs.h — what `zhc audit` reads and the pictures it writes.
#pragma once

#include <string>
#include <vector>

#include "codec/report/audit.h"
#include "codec/status.h"

namespace zhc {

struct AuditLoadOptions {
    int threads = 1;
    bool replace_non_finite = false;
    std::string part;  // EXR part (EnvmapReadOptions::part)
};

// One audited file: its probes (SH3 radiance hubs) and, for an environment map, the map itself
// (downsampled) and the true irradiance at the audit directions.
struct AuditInput {
    std::string path;
    std::string kind;         // "envmap" or "probes"
    std::string description;  // one line for the report
    std::vector<Sh3Radiance> probes;
    LatLongImage map;                  // envmaps: the flux-preserving downsample used as reference
    std::vector<Rgb> map_reference;    // envmaps: E(n) at the audit directions
    // The reference irradiance of probe p at `dirs` (the map's for an envmap, else the probe's SH3).
    std::vector<Rgb> reference_for(std::size_t probe, const std::vector<Vec3>& dirs) const;
};

// Files and folders -> the list of files to audit (folders: their .exr/.hdr/.zhp/.json files,
// sorted by name, not recursive). Missing paths are an error.
Result<std::vector<std::string>> expand_audit_inputs(const std::vector<std::string>& paths);

Result<AuditInput> load_audit_input(const std::string& path, const std::vector<Vec3>& dirs,
                                    const AuditLoadOptions& options);

// Writes DIR/<input stem>.png: one row per reference/representation, each a lat-long irradiance
// strip (tone-mapped, negative irradiance in magenta) beside a false-colour error strip, labelled.
Status write_audit_images(const std::string& dir, const AuditInput& input, const std::vector<Vec3>& dirs,
                          const std::vector<const Codec*>& codecs, const CodecOptions& options);

}  // namespace zhc
