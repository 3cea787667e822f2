// zhc/codec/lightmap/lightmap.cpp — IrradZ lightmap textures (see lightmap.h).
#include "codec/lightmap/lightmap.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

namespace zhc::lightmap {
namespace {

template <class F>
void parallel_rows(int rows, int threads, F&& f) {
    threads = std::max(1, std::min(threads, rows));
    std::vector<std::thread> pool;
    for (int k = 1; k < threads; ++k) pool.emplace_back([&, k] { f(rows * k / threads, rows * (k + 1) / threads); });
    f(0, rows / threads);
    for (auto& t : pool) t.join();
}

double log2_clamped(double v) { return std::log2(std::clamp(v, std::exp2(-14.0), 65504.0)); }

// Adds the squared log2 errors of decoded against reference to mse.
void add_log2_sq_errors(const float* reference, const float* decoded, std::size_t count, double& mse) {
    for (size_t i = 0; i < count; ++i) {
        const double d = log2_clamped(reference[i]) - log2_clamped(decoded[i]);
        mse += d * d;
    }
}

// Adds texel i's HHD errors of the three encodings to s, o, b and its I_z to iz.
void add_texel_errors(const ShLightmap& lm, size_t i, const IrradzPlanes& search, const IrradzPlanes& old_way,
                      const IrradzPlanes& after_bc, double& s, double& o, double& b, double& iz,
                      irradz::Model after_model = irradz::Model::kHhd) {
    const Sh3Irradiance t = to_irradiance(lm.texels[i]);
    s += irradz::hemispherical_mse(t, search.texel(i), irradz::Model::kHhd);
    o += irradz::hemispherical_mse(t, old_way.texel(i), irradz::Model::kHhd);
    b += irradz::hemispherical_mse(t, after_bc.texel(i), after_model);
    const Rgb e = evaluate(t, {0, 0, 1});
    iz += (e.r + e.g + e.b) / 3.0;
}

// Adds the w_a and d plane errors of after_bc against search: squared errors to mw and md, the
// angles between the directions (degrees) to ang and their maximum into amax.
void add_wa_d_errors(const IrradzPlanes& search, const IrradzPlanes& after_bc, double& mw, double& md, double& ang,
                     double& amax) {
    for (size_t i = 0; i < search.wa.size(); ++i) {
        mw += std::pow(double(search.wa[i]) - after_bc.wa[i], 2);
        md += std::pow(double(search.d[2 * i]) - after_bc.d[2 * i], 2) + std::pow(double(search.d[2 * i + 1]) - after_bc.d[2 * i + 1], 2);
        const double c = std::clamp(dot(decode_hemioct(search.d[2 * i], search.d[2 * i + 1]),
                                        decode_hemioct(after_bc.d[2 * i], after_bc.d[2 * i + 1])), -1.0, 1.0);
        const double deg = std::acos(c) * 180 / kPi;
        ang += deg;
        amax = std::max(amax, deg);
    }
}

}  // namespace

std::array<float, 2> encode_hemioct(Vec3 d) {
    d = normalize_or(d, {0, 0, 1});
    const double z = std::max(0.0, d.z);
    const double s = std::abs(d.x) + std::abs(d.y) + z;
    const double px = d.x / s, py = d.y / s;
    return {static_cast<float>((px + py + 1) / 2), static_cast<float>((px - py + 1) / 2)};
}

Vec3 decode_hemioct(float u, float v) {
    const double a = 2.0 * std::clamp(double(u), 0.0, 1.0) - 1, b = 2.0 * std::clamp(double(v), 0.0, 1.0) - 1;
    const double px = (a + b) / 2, py = (a - b) / 2;
    const double z = std::max(0.0, 1 - std::abs(px) - std::abs(py));  // |px| + |py| = max(|a|, |b|) <= 1
    return normalize_or({px, py, z}, {0, 0, 1});
}

irradz::IrradZ IrradzPlanes::texel(std::size_t i) const {
    irradz::IrradZ p;
    p.i_z = Rgb{iz[3 * i], iz[3 * i + 1], iz[3 * i + 2]};
    p.w_a = wa[i];
    p.d = decode_hemioct(d[2 * i], d[2 * i + 1]);
    return p;
}

ShLightmap synthesize_sphere(const Sh3Radiance& world, int width, int height, int threads) {
    return synthesize_sphere_rows(world, width, height, 0, height, threads);
}

ShLightmap synthesize_sphere_rows(const Sh3Radiance& world, int width, int height, int y_begin, int y_end, int threads) {
    ShLightmap lm;
    y_begin = std::clamp(y_begin, 0, std::max(0, height));
    y_end = std::clamp(y_end, y_begin, std::max(0, height));
    lm.width = width;
    lm.height = y_end - y_begin;
    lm.texels.resize(static_cast<size_t>(std::max(0, width)) * static_cast<size_t>(lm.height));
    parallel_rows(lm.height, threads, [&](int r0, int r1) {
        for (int r = r0; r < r1; ++r)
            for (int x = 0; x < width; ++x) {
                const int y = y_begin + r;
                // Octahedral map of the sphere: (u, v) in [-1, 1]^2 -> normal.
                const double u = 2.0 * (x + 0.5) / width - 1, v = 2.0 * (y + 0.5) / height - 1;
                Vec3 n{u, v, 1 - std::abs(u) - std::abs(v)};
                if (n.z < 0) {
                    const double ox = (1 - std::abs(v)) * (u >= 0 ? 1 : -1), oy = (1 - std::abs(u)) * (v >= 0 ? 1 : -1);
                    n.x = ox, n.y = oy;
                }
                n = normalize_or(n, {0, 0, 1});
                // The surface hides the lower hemisphere: a baker sees radiance over the visible
                // hemisphere only, so window the rotated radiance by it (SH3 hemisphere multiply).
                lm.texels[static_cast<size_t>(r) * static_cast<size_t>(width) + static_cast<size_t>(x)] =
                    irradz::cap_multiply(rotate(world, transpose(frame_from_z(n))), 0.0);
            }
    });
    return lm;
}

namespace {

// Texel i of the planes.
void store(IrradzPlanes& p, size_t i, const irradz::IrradZ& t) {
    for (int k = 0; k < 3; ++k) p.iz[3 * i + static_cast<size_t>(k)] = t.i_z[k];
    p.wa[i] = static_cast<float>(t.w_a);
    const auto uv = encode_hemioct(t.d);
    p.d[2 * i] = uv[0];
    p.d[2 * i + 1] = uv[1];
}

// Fills the planes of lm, texel i from to_irradz(lm.texels[i]), rows split over threads.
template <class ToIrradz>
IrradzPlanes encode_planes_with(const ShLightmap& lm, int threads, ToIrradz&& to_irradz) {
    IrradzPlanes p;
    p.width = lm.width;
    p.height = lm.height;
    const size_t n = lm.texels.size();
    p.iz.resize(3 * n);
    p.wa.resize(n);
    p.d.resize(2 * n);
    parallel_rows(lm.height, threads, [&](int y0, int y1) {
        for (size_t i = static_cast<size_t>(y0) * static_cast<size_t>(lm.width);
             i < static_cast<size_t>(y1) * static_cast<size_t>(lm.width); ++i) {
            store(p, i, to_irradz(lm.texels[i]));
        }
    });
    return p;
}

}  // namespace

IrradzPlanes encode_planes(const ShLightmap& lm, const irradz::EncodeOptions& options, int threads) {
    // A row at a time through encode_many (vector lanes across texels), then stored like
    // encode_planes_with does.
    IrradzPlanes p;
    p.width = lm.width;
    p.height = lm.height;
    const size_t n = lm.texels.size(), w = static_cast<size_t>(std::max(0, lm.width));
    p.iz.resize(3 * n);
    p.wa.resize(n);
    p.d.resize(2 * n);
    parallel_rows(lm.height, threads, [&](int y0, int y1) {
        std::vector<irradz::IrradZ> row(w);
        for (int y = y0; y < y1; ++y) {
            const size_t i0 = static_cast<size_t>(y) * w;
            irradz::encode_many(lm.texels.data() + i0, w, options, row.data());
            for (size_t x = 0; x < w; ++x) store(p, i0 + x, row[x]);
        }
    });
    return p;
}

IrradzPlanes encode_planes_linear_sh(const ShLightmap& lm, int threads) {
    return encode_planes_with(lm, threads, [](const auto& texel) {
        Sh2Radiance l;
        for (int c = 0; c < 4; ++c) l[c] = texel[c];
        return irradz::linear_sh_to_irradz(l);
    });
}

Compressed compress(const IrradzPlanes& p, bc6h::Quality q6, bc45::Quality q45, int threads) {
    Compressed c;
    c.width = p.width;
    c.height = p.height;
    c.bc6h = bc6h::encode_image(p.iz.data(), p.width, p.height, q6, threads);
    c.bc5 = bc45::encode_image(p.d.data(), 2, p.width, p.height, q45, threads);
    c.bc4 = bc45::encode_image(p.wa.data(), 1, p.width, p.height, q45, threads);
    return c;
}

IrradzPlanes decompress(const Compressed& c) {
    IrradzPlanes p;
    p.width = c.width;
    p.height = c.height;
    const auto half = bc6h::decode_image(c.bc6h.data(), c.bc6h.size(), c.width, c.height);
    p.iz.resize(half.size());
    for (size_t i = 0; i < half.size(); ++i) p.iz[i] = bc6h::half_to_float(half[i]);
    p.d = bc45::decode_image(c.bc5.data(), c.bc5.size(), 2, c.width, c.height);
    p.wa = bc45::decode_image(c.bc4.data(), c.bc4.size(), 1, c.width, c.height);
    return p;
}

IzLogRange iz_log_range(float min_positive, float max_value) {
    IzLogRange r;
    if (!(max_value > 0) || !std::isfinite(max_value)) return r;
    const double top = std::log2(double(max_value));
    const double lo = std::max(top - 16, min_positive > 0 ? std::log2(double(min_positive)) : top - 16);
    r.lo = static_cast<float>(lo);
    r.hi = static_cast<float>(std::log2(double(max_value) + std::exp2(double(r.lo))));
    if (!(r.hi > r.lo)) r.hi = std::nextafter(r.lo, 1e30f);
    return r;
}

void iz_extent(const std::vector<float>& rgb, float& min_positive, float& max_value) {
    for (float v : rgb) {
        if (v > 0 && (min_positive <= 0 || v < min_positive)) min_positive = v;
        if (v > max_value) max_value = v;
    }
}

float iz_to_ldr(float v, IzLogRange r) {
    const double x = v > 0 ? double(v) : 0.0;
    const double t = (std::log2(x + std::exp2(double(r.lo))) - double(r.lo)) / (double(r.hi) - double(r.lo));
    return static_cast<float>(std::clamp(t, 0.0, 1.0));
}

float iz_from_ldr(float t, IzLogRange r) {
    const double lo = r.lo, hi = r.hi, u = t >= 0 ? std::min(double(t), 1.0) : 0.0;  // NaN -> 0
    return static_cast<float>(std::exp2(lo + u * (hi - lo)) - std::exp2(lo));
}

double log2_psnr(const float* reference, const float* decoded, std::size_t count) {
    double mse = 0;
    add_log2_sq_errors(reference, decoded, count, mse);
    mse /= std::max<size_t>(1, count);
    return mse > 0 ? 10 * std::log10(30.0 * 30.0 / mse) : 999.0;
}
double log2_psnr(const float* reference, const std::uint16_t* decoded_half, std::size_t count) {
    std::vector<float> f(count);
    for (size_t i = 0; i < count; ++i) f[i] = bc6h::half_to_float(decoded_half[i]);
    return log2_psnr(reference, f.data(), count);
}

Audit audit(const ShLightmap& lm, const IrradzPlanes& search, const IrradzPlanes& old_way, const IrradzPlanes& after_bc,
            std::size_t stride) {
    Audit a;
    stride = std::max<size_t>(1, stride);
    double s = 0, o = 0, b = 0, iz = 0;
    for (size_t i = 0; i < lm.texels.size(); i += stride) {
        add_texel_errors(lm, i, search, old_way, after_bc, s, o, b, iz);
        ++a.texels_sampled;
    }
    const double n = static_cast<double>(std::max<size_t>(1, a.texels_sampled));
    a.rmse_search = std::sqrt(s / n / 3);
    a.rmse_old = std::sqrt(o / n / 3);
    a.rmse_after_bc = std::sqrt(b / n / 3);
    a.mean_iz = iz / n;
    a.psnr_iz_log2 = log2_psnr(search.iz.data(), after_bc.iz.data(), search.iz.size());
    double mw = 0, md = 0, ang = 0, amax = 0;
    add_wa_d_errors(search, after_bc, mw, md, ang, amax);
    const double m = static_cast<double>(std::max<size_t>(1, search.wa.size()));
    a.psnr_wa = mw > 0 ? 10 * std::log10(m / mw) : 999;
    a.psnr_d = md > 0 ? 10 * std::log10(2 * m / md) : 999;
    a.d_mean_deg = ang / m;
    a.d_max_deg = amax;
    return a;
}

void AuditAccumulator::add(const ShLightmap& lm, const IrradzPlanes& search, const IrradzPlanes& old_way,
                           const IrradzPlanes& after_bc) {
    // The texels audit() samples: global index next_, next_ + stride, ...
    const size_t n = lm.texels.size();
    for (; next_ < texels_ + n; next_ += stride_) {
        add_texel_errors(lm, next_ - texels_, search, old_way, after_bc, s_, o_, b_, iz_, after_model_);
        ++sampled_;
    }
    add_log2_sq_errors(search.iz.data(), after_bc.iz.data(), search.iz.size(), mse_iz_);
    iz_values_ += search.iz.size();
    add_wa_d_errors(search, after_bc, mw_, md_, ang_, amax_);
    texels_ += n;
}

Audit AuditAccumulator::result() const {
    Audit a;
    a.texels_sampled = sampled_;
    const double n = static_cast<double>(std::max<size_t>(1, sampled_));
    a.rmse_search = std::sqrt(s_ / n / 3);
    a.rmse_old = std::sqrt(o_ / n / 3);
    a.rmse_after_bc = std::sqrt(b_ / n / 3);
    a.mean_iz = iz_ / n;
    const double mse = mse_iz_ / static_cast<double>(std::max<size_t>(1, iz_values_));
    a.psnr_iz_log2 = mse > 0 ? 10 * std::log10(30.0 * 30.0 / mse) : 999.0;
    const double m = static_cast<double>(std::max<size_t>(1, texels_));
    a.psnr_wa = mw_ > 0 ? 10 * std::log10(m / mw_) : 999;
    a.psnr_d = md_ > 0 ? 10 * std::log10(2 * m / md_) : 999;
    a.d_mean_deg = ang_ / m;
    a.d_max_deg = amax_;
    return a;
}

// ---- the lightmap tables ------------------------------------------------------------------

namespace {
constexpr FitEntry kFits[] = {
    {"newton", "hemispherical Gram matrix, d by Newton on the analytic reduced error, the default", Fit::kNewton},
    {"search", "the same least squares, d by golden-section search, the reference", Fit::kSearch},
    {"talk_baseline", "the talk's baseline (its \"old way\"): optimal linear direction, spherical Gram matrix",
     Fit::kTalkBaseline},
    {"linear", "closed form from L0 + L1 for linear-SH lightmaps, L2 ignored", Fit::kLinear},
};
constexpr QualityPreset kQualityPresets[] = {
    {"fast", "BC6H fast, BC4/BC5 fast", bc6h::Quality::kFast, bc45::Quality::kFast},
    {"default", "BC6H default, BC4/BC5 default", bc6h::Quality::kDefault, bc45::Quality::kDefault},
    {"slow", "BC6H exhaustive over all modes and partitions, BC4/BC5 default", bc6h::Quality::kExhaustive,
     bc45::Quality::kDefault},
};

constexpr FitAlias kFitAliases[] = {
    {"old", "talk_baseline"},
};
}  // namespace

std::span<const FitEntry> fits() { return kFits; }
std::span<const FitAlias> fit_aliases() { return kFitAliases; }

const FitEntry* find_fit(std::string_view name) {
    for (const FitAlias& a : kFitAliases)
        if (a.alias == name) name = a.name;
    for (const FitEntry& f : kFits)
        if (f.name == name) return &f;
    return nullptr;
}

IrradzPlanes fit_planes(const ShLightmap& lm, Fit fit, int threads) {
    if (fit == Fit::kLinear) return encode_planes_linear_sh(lm, threads);
    irradz::EncodeOptions eo;
    eo.solve = fit == Fit::kTalkBaseline ? irradz::Solve::kTalkBaseline
               : fit == Fit::kSearch      ? irradz::Solve::kSearch
                                          : irradz::Solve::kNewton;
    return encode_planes(lm, eo, threads);
}

std::span<const QualityPreset> quality_presets() { return kQualityPresets; }

const QualityPreset* find_quality_preset(std::string_view name) {
    for (const QualityPreset& q : kQualityPresets)
        if (q.name == name) return &q;
    return nullptr;
}

}  // namespace zhc::lightmap
