// zhc/formats/lightmap/lightmap_stream.h — the lightmap verbs as streaming pipelines in bounded memory
// (docs/lightmap-formats.md, "Streaming"): the SH lightmap EXR is read in bands of rows (whole rows
// of blocks: 4 rows for BC, the footprint's height as well for ASTC), each band is fitted and
// block-compressed, and its blocks are appended to the KTX2/DDS level data in temporary files
// renamed at the end (all of a target's files or none).
// Peak memory is a few bands, whatever the image size. The bytes written do not depend on the band
// height or the thread count: each 4x4 block depends only on its own texels (the last band holds the
// image's partial bottom block row, whose missing rows repeat the last row as in the whole-image
// encoder), and every per-texel fit is independent of the others.
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments (the ASTC encoder lends each astcenc context to one call at a
// time, formats/lightmap/astc.cpp). The only process-wide state touched is OpenEXR's own
// global thread pool (grown, never shrunk, when a call asks for more threads; OpenEXR
// guards it), which never changes the bytes read or written.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "codec/lightmap/lightmap.h"
#include "codec/status.h"
#include "formats/lightmap/astc.h"

namespace zhc::lightmap_stream {

using Fit = lightmap::Fit;  // the fits by name: lightmap::fits()

// Called after each band with the rows done so far and the total.
using ProgressFn = std::function<void(std::uint64_t done, std::uint64_t total)>;

// Band height for an image `width` texels wide: `requested` rounded up to a multiple of 4 if > 0,
// else about 2^18 texels per band (64 rows at 4096 wide), at least 4 rows per thread (up to 16 threads).
int band_rows(int width, int threads, int requested);

struct Timing {
    double read = 0, fit = 0, compress = 0, write = 0;  // seconds
};

// Texture targets (docs/lightmap-formats.md): bc = BC6H I_z + BC5 d + BC4 w_a (PREFIX.{iz,d,wa});
// astc = ASTC HDR I_z + ASTC LDR (u, v, w_a) (PREFIX.{iz,dwa}.ktx2); astc-ldr = the same with I_z in
// ASTC LDR through lightmap::iz_to_ldr (range in the key "zhc.iz_log2_range" of PREFIX.iz.ktx2).
enum class Target { kBc, kAstc, kAstcLdr };

// The ASTC effort of a quality preset's BC settings: fast -> kFast, default -> kMedium, slow -> kThorough.
astc::Effort astc_effort(bc6h::Quality q);

struct EncodeOptions {
    Target target = Target::kBc;
    astc::Footprint footprint;  // ASTC targets
    Fit fit = Fit::kNewton;
    bc6h::Quality bc6h_quality = bc6h::Quality::kDefault;
    bc45::Quality bc45_quality = bc45::Quality::kDefault;
    int threads = 1;
    int band_rows = 0;  // 0: automatic (see band_rows())
    bool dds = false;   // PREFIX.{iz,d,wa}.dds instead of .ktx2
    ProgressFn progress;
};
struct EncodeResult {
    int width = 0, height = 0, coefficients = 9;
    std::uint64_t block_bytes = 0;  // the levels of all textures together
    Timing timing;
};
// inputs: see ShLightmapSource (one SH3 or linear-SH EXR, or 4 / 9 per-coefficient EXRs).
// On failure, *output_failed (if given) tells an error writing the outputs from one on the input.
Result<EncodeResult> encode(const std::vector<std::string>& inputs, const std::string& prefix, const EncodeOptions& options,
                            bool* output_failed = nullptr);

struct DecodeResult {
    int width = 0, height = 0;
    Target target = Target::kBc;
    astc::Footprint footprint;
};
// PREFIX.{iz,d,wa}.{ktx2|dds} or PREFIX.{iz,dwa}.ktx2 (the target from PREFIX.iz.ktx2's vkFormat) -> IrradZ EXR (write_irradz_exr's channels and bytes), block row band
// by block row band.
Result<DecodeResult> decode(const std::string& prefix, bool dds, const std::string& output, int band_rows_requested,
                            const ProgressFn& progress, bool* output_failed = nullptr);

struct AuditOptions {
    bc6h::Quality bc6h_quality = bc6h::Quality::kDefault;
    bc45::Quality bc45_quality = bc45::Quality::kDefault;
    int threads = 1, band_rows = 0;
    std::size_t stride = 17;
    ProgressFn progress;
};
struct AuditResult {
    int width = 0, height = 0;
    lightmap::Audit audit;
    Timing timing;
};

// audit_targets: one column of the side-by-side comparison. kind "plain" is a Godot-style
// lightmap: ASTC HDR I_z only (the irradiance at the normal, no direction), rendered as the
// constant I_z (irradz::Model::kAhd with w_a = 1); split_dwa measures the two-texture packing.
struct TargetSpec {
    Target target = Target::kBc;
    astc::Footprint footprint;
    bool split_dwa = false, plain = false;
    std::string name;  // as given to --targets
};
// "bc", "astc:4x4", "astc-ldr:6x6", "astc-split:4x4", "plain-astc:4x4" (footprint optional, default 4x4).
std::optional<TargetSpec> parse_target(const std::string& s);
struct TargetAudit {
    TargetSpec spec;
    std::uint64_t bytes = 0;  // block bytes of all its textures
    double encode_seconds = 0;
    lightmap::Audit audit;  // rmse_after_bc and the PSNRs are this target's
};
// The same fit, every target compressed and decoded band by band; one TargetAudit per spec.
Result<std::vector<TargetAudit>> audit_targets(const std::vector<std::string>& inputs, const AuditOptions& options,
                                               const std::vector<TargetSpec>& targets, AuditResult* base = nullptr);
// Every row is fitted (irradz's default solve and the talk's baseline, "old way") and block-compressed; the hemispherical error integral
// is taken on every stride-th texel (lightmap::audit's sampling), the PSNRs over every texel.
Result<AuditResult> audit(const std::vector<std::string>& inputs, const AuditOptions& options);

// The synthetic sphere lightmap (lightmap::synthesize_sphere, width x height) written band by band;
// `half`: HALF channels (half the file size) instead of FLOAT.
Status synth(const Sh3Radiance& world, int width, int height, const std::string& output, bool half, int threads, int band_rows_requested,
             const ProgressFn& progress);  // every error is an output error

}  // namespace zhc::lightmap_stream
