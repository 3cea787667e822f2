// zhc/codec/audit/audit.h — error metrics of every representation against a reference irradiance.
//
// The reference for an environment map is the true irradiance E(n) = (1/pi) int L(w) max(0, n.w) dw
// of the map (after a flux-preserving box downsample to no less than 512x256; a smaller map is
// used as it is), each pixel constant over its exact footprint as in project_latlong (sh.h), at
// directions spread uniformly over the sphere (spherical Fibonacci lattice). For
// probes without a map (containers, baked grids) the reference is the hub's SH3 irradiance.
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"

namespace zhc {

// A lat-long RGB float image view (interleaved, rows top to bottom; see sh.h for orientation).
struct LatLongView {
    const float* rgb = nullptr;
    int width = 0, height = 0;
    LatLongConvention convention = LatLongConvention::kOpenExr;
};

// Flux-preserving box downsample by integer factors until the next halving would go below
// min_width x min_height (each output pixel is the solid-angle weighted mean of its block).
struct LatLongImage {
    int width = 0, height = 0;
    std::vector<float> rgb;
    LatLongConvention convention = LatLongConvention::kOpenExr;  // the source's (a box downsample keeps it)
    LatLongView view() const { return {rgb.data(), width, height, convention}; }
};
LatLongImage downsample_for_audit(LatLongView map, int min_width = 512, int min_height = 256);

// Reference irradiance of the map at each direction: every pixel is constant over its exact
// theta x phi footprint. Along phi the clamped cosine is integrated in closed form (at each theta
// it is positive on one arc, which meets the row's pixels in whole columns and two partial ones);
// along theta, four-point Gauss-Legendre on at least 256 pieces over the sphere, cut where the arc
// appears or fills the ring. Exact for a constant map up to the rule's error (below 1e-7 relative)
// at any size, an 8x2 map included; double sums; the result does not depend on `threads`.
std::vector<Rgb> integrate_irradiance(LatLongView map, const std::vector<Vec3>& directions, int threads = 1);
// Reference irradiance of an SH3 radiance probe.
std::vector<Rgb> sh3_irradiance(const Sh3Radiance& sh, const std::vector<Vec3>& directions);

struct ErrorMetrics {
    double rmse = 0;               // over all directions and the three channels, uniformly weighted
    double relative_rmse = 0;      // rmse / mean reference irradiance (over directions and channels)
    double max_abs = 0;            // largest |reconstructed - reference| over directions and channels
    double min_irradiance = 0;     // smallest reconstructed irradiance over directions and channels
    double negative_fraction = 0;  // fraction of directions where some channel is < 0
    // Colour shift: mean over directions of the Euclidean distance between the rg chromaticities
    // (r, g) / (r + g + b) of reconstruction and reference, over directions whose reference
    // r + g + b is above 1e-3 of its mean (chromaticity of black is undefined).
    double chromaticity_error = 0;
};

ErrorMetrics compare_irradiance(const std::vector<Rgb>& reconstructed, const std::vector<Rgb>& reference);

// Pools the metrics of many probes (each with its own reference): RMSE over all their directions
// and channels, the worst max_abs and minimum, the overall negative and chromaticity fractions.
class MetricsAccumulator {
public:
    void add(const std::vector<Rgb>& reconstructed, const std::vector<Rgb>& reference);
    ErrorMetrics result() const;
    std::size_t samples() const { return samples_; }

private:
    double sq_ = 0, sum_ref_ = 0, max_abs_ = 0, min_ = 0, chroma_sum_ = 0;
    std::size_t samples_ = 0, negative_ = 0, chroma_count_ = 0;
};

// One representation's result on one probe.
struct RepresentationResult {
    const Codec* codec = nullptr;
    ErrorMetrics metrics;
    EncodeStats stats;
    double encode_ns = 0;  // per probe, median over batches (0 when timing is off)
    double decode_ns = 0;  // decode to the SH3 hub, per probe
};

// Encodes `hub` with each codec, evaluates its irradiance at `directions` through the codec's
// runtime path and compares with `reference`. With measure_time, encode and decode are timed
// (median of 5 batches, each long enough to be measurable). The returned `reconstructed` (when
// non-null) holds each codec's irradiance, in codec order.
std::vector<RepresentationResult> audit_probe(const Sh3Radiance& hub, const std::vector<Rgb>& reference,
                                              const std::vector<Vec3>& directions,
                                              const std::vector<const Codec*>& codecs, const CodecOptions& options,
                                              bool measure_time,
                                              std::vector<std::vector<Rgb>>* reconstructed = nullptr);

// Irradiance of stored bytes through the codec's runtime path at each direction.
std::vector<Rgb> codec_irradiance(const Codec& codec, const std::uint8_t* stored, const CodecOptions& options,
                                  const std::vector<Vec3>& directions);

}  // namespace zhc
