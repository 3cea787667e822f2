// zhc/codec/lightmap/lightmap.h — IrradZ lightmaps as textures: the per-texel SH3 radiance hub (tangent
// frame), the IrradZ planes (I_z RGB, w_a, d), block compression to BC6H + BC5 + BC4 (2.5 bytes
// per texel), and the audit numbers. Separate from the probe codec table. Standard library only.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "codec/lightmap/bc45.h"
#include "codec/lightmap/bc6h.h"
#include "codec/lightmap/irradz.h"
#include "codec/sh/sh.h"

namespace zhc::lightmap {

// Per-texel SH3 radiance in each texel's tangent frame (surface normal = +Z), row-major.
struct ShLightmap {
    int width = 0, height = 0;
    std::vector<Sh3Radiance> texels;
};

// A synthetic lightmap: the surface of a unit sphere (texel (x, y) -> normal by the octahedral
// map of the whole sphere) lit by the world-space SH3 radiance `world`; each texel holds `world`
// rotated into its tangent frame (frame_from_z(normal)) and multiplied by the visible (upper)
// hemisphere, projected back to SH3 (irradz::cap_multiply with cos_alpha = 0), as a baker would see it.
ShLightmap synthesize_sphere(const Sh3Radiance& world, int width, int height, int threads = 1);
// Rows [y0, y1) of synthesize_sphere(world, width, height) (a band of y1 - y0 rows; the same texels).
ShLightmap synthesize_sphere_rows(const Sh3Radiance& world, int width, int height, int y0, int y1, int threads = 1);

// The stored parameters as float planes (before or after block compression).
struct IrradzPlanes {
    int width = 0, height = 0;
    std::vector<float> iz;  // 3 per texel, linear RGB
    std::vector<float> wa;  // 1 per texel, [0, 1]
    std::vector<float> d;   // 2 per texel, hemi-octahedral in [0, 1]^2 (see encode_hemioct)
    irradz::IrradZ texel(std::size_t i) const;
};

// Unit upper-hemisphere vector <-> [0, 1]^2: p = (x, y) / (|x| + |y| + z), stored as
// ((p.x + p.y + 1) / 2, (p.x - p.y + 1) / 2) (the hemisphere's octahedron rotated 45 degrees to fill
// the square). Every stored pair decodes to a unit vector with z >= 0 (total).
std::array<float, 2> encode_hemioct(Vec3 d);
Vec3 decode_hemioct(float u, float v);

IrradzPlanes encode_planes(const ShLightmap& lm, const irradz::EncodeOptions& options, int threads = 1);
// The closed-form linear SH -> IrradZ fit (irradz::linear_sh_to_irradz on each texel's L0 and L1;
// L2 is ignored), for linear-SH lightmaps: no search, exact for IrradZ-valid HHD radiance.
IrradzPlanes encode_planes_linear_sh(const ShLightmap& lm, int threads = 1);

// The lightmap side's two tables (the probe side has codecs()): every IrradZ fit and every
// block-compression preset by name, with a one-line summary. The CLI (--solve, --quality), the
// streaming pipeline, bench_lightmap and the tests take names, help text and settings from here.
enum class Fit {
    kNewton,  // irradz Solve::kNewton (the default)
    kSearch,  // irradz Solve::kSearch (golden-section reference)
    kTalkBaseline,  // irradz Solve::kTalkBaseline (the talk's baseline, its "old way")
    kLinear,  // encode_planes_linear_sh (closed form from L0 + L1)
};
struct FitEntry {
    std::string_view name;
    std::string_view summary;
    Fit fit;
};
std::span<const FitEntry> fits();  // newton (default), search, talk_baseline, linear
// Names a fit answers to besides its own: "old" (the talk's words for its baseline) stands for
// talk_baseline. The command line accepts them; nothing writes them.
struct FitAlias {
    std::string_view alias;
    std::string_view name;  // the FitEntry it stands for
};
std::span<const FitAlias> fit_aliases();
const FitEntry* find_fit(std::string_view name);  // a name or an alias; nullptr when unknown
// encode_planes with the fit's solve, or encode_planes_linear_sh for kLinear.
IrradzPlanes fit_planes(const ShLightmap& lm, Fit fit, int threads = 1);

struct QualityPreset {
    std::string_view name;
    std::string_view summary;
    bc6h::Quality bc6h;  // I_z
    bc45::Quality bc45;  // d and w_a
};
std::span<const QualityPreset> quality_presets();  // fast, default, slow
const QualityPreset* find_quality_preset(std::string_view name);  // nullptr when unknown

struct Compressed {
    int width = 0, height = 0;
    std::vector<std::uint8_t> bc6h;  // I_z, 16 bytes per 4x4 block
    std::vector<std::uint8_t> bc5;   // d, 16 bytes per block
    std::vector<std::uint8_t> bc4;   // w_a, 8 bytes per block
};
Compressed compress(const IrradzPlanes& p, bc6h::Quality q6, bc45::Quality q45, int threads = 1);
IrradzPlanes decompress(const Compressed& c);

struct Audit {
    std::size_t texels_sampled = 0;
    // True hemispherical irradiance RMSE against the SH3 irradiance (per channel, sqrt of the mean
    // over texels of irradz::hemispherical_mse / 3), and the mean SH3 irradiance at the normal for scale.
    double rmse_search = 0, rmse_old = 0, rmse_after_bc = 0, mean_iz = 0;
    double psnr_iz_log2 = 0;    // BC6H: log2-domain PSNR (see log2_psnr)
    double psnr_wa = 0;         // BC4: 20 log10(1 / RMSE)
    double psnr_d = 0;          // BC5: over both channels
    double d_mean_deg = 0, d_max_deg = 0;  // angular error of d after BC5
};
// Every `stride`-th texel is audited (the per-texel error integral costs 512 model evaluations).
Audit audit(const ShLightmap& lm, const IrradzPlanes& search, const IrradzPlanes& old_way, const IrradzPlanes& after_bc,
            std::size_t stride);

// audit() over a lightmap given band by band (streaming): add() the bands in order (rows
// top to bottom; each band's planes cover exactly its texels), then result(). The same sums in the
// same order as audit() on the whole image, so the same numbers (tested).
class AuditAccumulator {
public:
    explicit AuditAccumulator(std::size_t stride, irradz::Model after_model = irradz::Model::kHhd)
        : stride_(stride < 1 ? 1 : stride), after_model_(after_model) {}
    void add(const ShLightmap& band, const IrradzPlanes& search, const IrradzPlanes& old_way, const IrradzPlanes& after_bc);
    Audit result() const;

private:
    std::size_t stride_;
    irradz::Model after_model_;
    std::size_t next_ = 0, sampled_ = 0, texels_ = 0, iz_values_ = 0;
    double s_ = 0, o_ = 0, b_ = 0, iz_ = 0, mse_iz_ = 0, mw_ = 0, md_ = 0, ang_ = 0, amax_ = 0;
};

// The LDR range encoding of I_z (the ASTC LDR fallback, docs/lightmap-formats.md): one range per
// texture, t = (log2(v + 2^lo) - lo) / (hi - lo) in [0, 1] per channel, decoded as
// v = 2^(lo + t (hi - lo)) - 2^lo (so t = 0 is exactly 0). iz_log_range picks lo = log2 of the
// smallest positive I_z, but at least log2(max) - 16, and hi = log2(max + 2^lo) (both rounded to
// float: the file stores them as floats); an image without positive values gets lo = -14, hi = -13.
struct IzLogRange {
    float lo = -14, hi = -13;
};
IzLogRange iz_log_range(float min_positive, float max_value);
// Scans rgb (3 per texel) for the smallest positive and the largest value (NaN and negatives skipped).
void iz_extent(const std::vector<float>& rgb, float& min_positive, float& max_value);
float iz_to_ldr(float v, IzLogRange r);    // clamped to [0, 1]
float iz_from_ldr(float t, IzLogRange r);  // computed in double, rounded to float once

// log2-PSNR of HDR RGB values: l(v) = log2(max(v, 2^-14)) (v clamped to BC6H's [0, 65504]),
// PSNR = 10 log10(30^2 / MSE_l): 30 = log2(65504) - (-14) rounded, the representable log range.
double log2_psnr(const float* reference, const std::uint16_t* decoded_half, std::size_t count);
double log2_psnr(const float* reference, const float* decoded, std::size_t count);

}  // namespace zhc::lightmap
