// zhc/formats/lightmap/astc.cpp — ASTC through astcenc (see astc.h).
#include "formats/lightmap/astc.h"

#include <astcenc.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>

namespace zhc::astc {
namespace {

// The footprints zhc writes, with their index k in the Vulkan enumerations.
struct FootprintEntry {
    Footprint f;
    std::uint32_t k;
};
constexpr FootprintEntry kFootprints[] = {{{4, 4}, 0}, {{5, 5}, 2}, {{6, 6}, 4}, {{8, 8}, 7}};
constexpr std::uint32_t kVkAstcSfloatBase = 1000066000;  // VK_FORMAT_ASTC_4x4_SFLOAT_BLOCK (VK_EXT_texture_compression_astc_hdr)
constexpr std::uint32_t kVkAstcUnormBase = 157;          // VK_FORMAT_ASTC_4x4_UNORM_BLOCK; +1 is its _SRGB_BLOCK

const FootprintEntry* find(Footprint f) {
    for (const auto& e : kFootprints)
        if (e.f == f) return &e;
    return nullptr;
}

struct ContextDeleter {
    void operator()(astcenc_context* c) const { astcenc_context_free(c); }
};
using Context = std::unique_ptr<astcenc_context, ContextDeleter>;

Result<Context> make_context_uncached(Footprint f, astcenc_profile profile, Effort effort, unsigned threads, unsigned flags) {
    astcenc_config config{};
    const float quality = effort == Effort::kFast ? ASTCENC_PRE_FAST : (effort == Effort::kMedium ? ASTCENC_PRE_MEDIUM : ASTCENC_PRE_THOROUGH);
    astcenc_error e = astcenc_config_init(profile, static_cast<unsigned>(f.x), static_cast<unsigned>(f.y), 1, quality, flags, &config);
    if (e != ASTCENC_SUCCESS) return make_error(ErrorCode::kInternal, std::string("astcenc_config_init: ") + astcenc_get_error_string(e));
    astcenc_context* raw = nullptr;
    e = astcenc_context_alloc(&config, threads, &raw);
    if (e != ASTCENC_SUCCESS) return make_error(ErrorCode::kInternal, std::string("astcenc_context_alloc: ") + astcenc_get_error_string(e));
    return Context(raw);
}

// Allocating a context builds astcenc's tables for the footprint (milliseconds): contexts are kept
// in a pool by their settings and lent out one caller at a time. A context keeps no state between
// images once reset, so a reused one writes the same bytes as a fresh one (tested: two runs).
using Key = std::tuple<int, int, int, int, unsigned, unsigned>;
std::mutex pool_mutex;
std::multimap<Key, Context>& pool() {
    static std::multimap<Key, Context> p;
    return p;
}
struct Lease {
    Key key;
    Context ctx;
    ~Lease() {
        if (!ctx) return;
        std::lock_guard<std::mutex> lock(pool_mutex);
        pool().emplace(key, std::move(ctx));
    }
    astcenc_context* get() const { return ctx.get(); }
};
Result<std::unique_ptr<Lease>> make_context(Footprint f, astcenc_profile profile, Effort effort, unsigned threads, unsigned flags) {
    auto lease = std::make_unique<Lease>();
    lease->key = Key{f.x, f.y, static_cast<int>(profile), static_cast<int>(effort), threads, flags};
    {
        std::lock_guard<std::mutex> lock(pool_mutex);
        auto it = pool().find(lease->key);
        if (it != pool().end()) {
            lease->ctx = std::move(it->second);
            pool().erase(it);
        }
    }
    if (!lease->ctx) {
        auto c = make_context_uncached(f, profile, effort, threads, flags);
        if (!c) return c.error();
        lease->ctx = std::move(*c);
    }
    if (flags & ASTCENC_FLG_DECOMPRESS_ONLY) astcenc_decompress_reset(lease->get());
    else astcenc_compress_reset(lease->get());
    return lease;
}

}  // namespace

bool footprint_supported(Footprint f) { return find(f) != nullptr; }

std::uint32_t vk_format_hdr(Footprint f) {
    const auto* e = find(f);
    return e ? kVkAstcSfloatBase + e->k : 0;
}

std::uint32_t vk_format_ldr(Footprint f) {
    const auto* e = find(f);
    return e ? kVkAstcUnormBase + 2 * e->k : 0;
}

std::optional<Format> format_of_vk(std::uint32_t vk) {
    for (const auto& e : kFootprints) {
        if (vk == kVkAstcSfloatBase + e.k) return Format{e.f, true};
        if (vk == kVkAstcUnormBase + 2 * e.k) return Format{e.f, false};
    }
    return std::nullopt;
}

std::size_t block_count(Footprint f, int width, int height) {
    if (width <= 0 || height <= 0 || f.x <= 0 || f.y <= 0) return 0;
    return static_cast<std::size_t>((width + f.x - 1) / f.x) * static_cast<std::size_t>((height + f.y - 1) / f.y);
}

Result<std::vector<std::uint8_t>> encode(const float* values, int channels, int width, int height, Footprint f, bool hdr,
                                         Effort effort, int threads) {
    if (!footprint_supported(f))
        return make_error(ErrorCode::kUnsupported, "astc: footprint " + std::to_string(f.x) + "x" + std::to_string(f.y) +
                                                       " (zhc writes 4x4, 5x5, 6x6, 8x8)");
    if (channels < 1 || channels > 3 || (hdr && channels != 3))
        return make_error(ErrorCode::kInvalidArgument, "astc: " + std::to_string(channels) + " channels (HDR: 3, LDR: 1 to 3)");
    if (width <= 0 || height <= 0) return make_error(ErrorCode::kInvalidArgument, "astc: empty image");
    const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
    // astcenc reads RGBA; the unused channels are 0 and alpha is 1 (the swizzle repeats L for L / LA).
    std::vector<float> rgba(4 * n, 0.0f);
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < channels; ++c) {
            float v = values[i * static_cast<size_t>(channels) + static_cast<size_t>(c)];
            if (!(v >= 0)) v = 0;  // NaN and negatives
            if (!hdr) v = std::min(v, 1.0f);
            else v = std::min(v, 65504.0f);
            rgba[4 * i + static_cast<size_t>(c)] = v;
        }
        if (channels < 4) rgba[4 * i + 3] = channels == 2 ? rgba[4 * i + 1] : 1.0f;
    }
    const unsigned nthreads = static_cast<unsigned>(std::clamp(threads, 1, 64));
    auto ctx = make_context(f, hdr ? ASTCENC_PRF_HDR_RGB_LDR_A : ASTCENC_PRF_LDR, effort, nthreads, 0);
    if (!ctx) return ctx.error();
    void* slice = rgba.data();
    astcenc_image image{static_cast<unsigned>(width), static_cast<unsigned>(height), 1, ASTCENC_TYPE_F32, &slice};
    astcenc_swizzle swz{ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_A};
    if (channels == 1) swz = {ASTCENC_SWZ_R, ASTCENC_SWZ_R, ASTCENC_SWZ_R, ASTCENC_SWZ_1};
    if (channels == 2) swz = {ASTCENC_SWZ_R, ASTCENC_SWZ_R, ASTCENC_SWZ_R, ASTCENC_SWZ_G};
    if (channels == 3) swz = {ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_1};
    std::vector<std::uint8_t> out(16 * block_count(f, width, height));
    std::vector<astcenc_error> errors(nthreads, ASTCENC_SUCCESS);
    auto work = [&](unsigned t) { errors[t] = astcenc_compress_image((*ctx)->get(), &image, &swz, out.data(), out.size(), t); };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < nthreads; ++t) pool.emplace_back(work, t);
    work(0);
    for (auto& t : pool) t.join();
    for (astcenc_error e : errors)
        if (e != ASTCENC_SUCCESS) return make_error(ErrorCode::kInternal, std::string("astcenc_compress_image: ") + astcenc_get_error_string(e));
    return out;
}

Result<std::vector<float>> decode_rgba(const std::uint8_t* blocks, std::size_t size, int width, int height, Footprint f, bool hdr,
                                       int first_row) {
    if (!footprint_supported(f)) return make_error(ErrorCode::kUnsupported, "astc: unsupported footprint");
    if (width <= 0 || height <= 0 || size != 16 * block_count(f, width, height))
        return make_error(ErrorCode::kInvalidArgument, "astc: block data does not match the image size");
    // Decoding as the formats say: SFLOAT decodes every block HDR-capable (ASTCENC_PRF_HDR), UNORM is LDR.
    auto ctx = make_context(f, hdr ? ASTCENC_PRF_HDR : ASTCENC_PRF_LDR, Effort::kFast, 1, ASTCENC_FLG_DECOMPRESS_ONLY);
    if (!ctx) return ctx.error();
    std::vector<float> rgba(4 * static_cast<size_t>(width) * static_cast<size_t>(height));
    void* slice = rgba.data();
    astcenc_image image{static_cast<unsigned>(width), static_cast<unsigned>(height), 1, ASTCENC_TYPE_F32, &slice};
    const astcenc_swizzle swz{ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_A};
    const astcenc_error e = astcenc_decompress_image((*ctx)->get(), blocks, size, &image, &swz, 0);
    if (e != ASTCENC_SUCCESS) return make_error(ErrorCode::kInternal, std::string("astcenc_decompress_image: ") + astcenc_get_error_string(e));
    // An invalid block (reserved or out-of-range encodings) decodes to the error colour. With float
    // output astcenc gives NaN there. For the LDR (UNORM) formats the specification's error colour is
    // opaque magenta, which is what a GPU samples, so zhc decodes to that. For HDR (SFLOAT) it is NaN,
    // which no lightmap value may be (an EXR written with it would poison what reads it): refused,
    // naming the first such block.
    if (hdr) {
        for (size_t i = 0; i < rgba.size(); i += 4)
            if (std::isnan(rgba[i]) || std::isnan(rgba[i + 1]) || std::isnan(rgba[i + 2]) || std::isnan(rgba[i + 3])) {
                const size_t x = (i / 4) % static_cast<size_t>(width), y = (i / 4) / static_cast<size_t>(width);
                return make_error(ErrorCode::kBadFormat,
                                  "invalid ASTC HDR block at block column " + std::to_string(x / static_cast<size_t>(f.x)) + ", row " +
                                      std::to_string((static_cast<size_t>(first_row) + y) / static_cast<size_t>(f.y)) +
                                      " (reserved or out-of-range encoding: it decodes to the error colour, NaN)");
            }
    }
    if (!hdr)
        for (size_t i = 0; i < rgba.size(); i += 4)
            if (std::isnan(rgba[i]) || std::isnan(rgba[i + 1]) || std::isnan(rgba[i + 2]) || std::isnan(rgba[i + 3])) {
                rgba[i] = 1.0f;
                rgba[i + 1] = 0.0f;
                rgba[i + 2] = 1.0f;
                rgba[i + 3] = 1.0f;
            }
    return rgba;
}

}  // namespace zhc::astc

// ---- IrradZ lightmaps as ASTC -----------------------------------------------------------------

namespace zhc::lightmap_astc {

Result<Compressed> compress(const lightmap::IrradzPlanes& p, const Options& o, int threads) {
    Compressed c;
    c.width = p.width;
    c.height = p.height;
    c.options = o;
    const size_t n = p.wa.size();
    std::vector<float> ldr;  // the LDR range encoding of I_z; HDR encodes p.iz as it is
    const float* iz = p.iz.data();
    if (o.ldr_iz) {
        ldr.resize(p.iz.size());
        for (size_t i = 0; i < ldr.size(); ++i) ldr[i] = lightmap::iz_to_ldr(p.iz[i], o.range);
        iz = ldr.data();
    }
    auto iz_blocks = astc::encode(iz, 3, p.width, p.height, o.footprint, !o.ldr_iz, o.effort, threads);
    if (!iz_blocks) return iz_blocks.error();
    c.iz = std::move(*iz_blocks);
    if (o.split_dwa) {
        auto d = astc::encode(p.d.data(), 2, p.width, p.height, o.footprint, false, o.effort, threads);
        if (!d) return d.error();
        auto wa = astc::encode(p.wa.data(), 1, p.width, p.height, o.footprint, false, o.effort, threads);
        if (!wa) return wa.error();
        c.dwa = std::move(*d);
        c.wa = std::move(*wa);
        return c;
    }
    std::vector<float> dwa(3 * n);
    for (size_t i = 0; i < n; ++i) {
        dwa[3 * i] = p.d[2 * i];
        dwa[3 * i + 1] = p.d[2 * i + 1];
        dwa[3 * i + 2] = p.wa[i];
    }
    auto dwa_blocks = astc::encode(dwa.data(), 3, p.width, p.height, o.footprint, false, o.effort, threads);
    if (!dwa_blocks) return dwa_blocks.error();
    c.dwa = std::move(*dwa_blocks);
    return c;
}

Result<lightmap::IrradzPlanes> decompress(const Compressed& c, int first_row) {
    const Options& o = c.options;
    auto iz = astc::decode_rgba(c.iz.data(), c.iz.size(), c.width, c.height, o.footprint, !o.ldr_iz, first_row);
    if (!iz) return iz.error();
    auto dwa = astc::decode_rgba(c.dwa.data(), c.dwa.size(), c.width, c.height, o.footprint, false);
    if (!dwa) return dwa.error();
    Result<std::vector<float>> wa = std::vector<float>{};
    if (o.split_dwa) {
        wa = astc::decode_rgba(c.wa.data(), c.wa.size(), c.width, c.height, o.footprint, false);
        if (!wa) return wa.error();
    }
    lightmap::IrradzPlanes p;
    p.width = c.width;
    p.height = c.height;
    const size_t n = static_cast<size_t>(c.width) * static_cast<size_t>(c.height);
    p.iz.resize(3 * n);
    p.wa.resize(n);
    p.d.resize(2 * n);
    for (size_t i = 0; i < n; ++i) {
        for (size_t k = 0; k < 3; ++k) {
            const float v = (*iz)[4 * i + k];
            p.iz[3 * i + k] = o.ldr_iz ? lightmap::iz_from_ldr(v, o.range) : v;
        }
        if (o.split_dwa) {
            p.d[2 * i] = (*dwa)[4 * i];      // L (= R = G = B)
            p.d[2 * i + 1] = (*dwa)[4 * i + 3];  // A
            p.wa[i] = (*wa)[4 * i];
        } else {
            p.d[2 * i] = (*dwa)[4 * i];
            p.d[2 * i + 1] = (*dwa)[4 * i + 1];
            p.wa[i] = (*dwa)[4 * i + 2];
        }
    }
    return p;
}

std::vector<std::uint8_t> range_value(lightmap::IzLogRange r) {
    char buf[64];
    const int len = std::snprintf(buf, sizeof buf, "%.9g %.9g", double(r.lo), double(r.hi));
    std::vector<std::uint8_t> v(buf, buf + std::max(0, len));
    v.push_back(0);
    return v;
}

std::optional<lightmap::IzLogRange> parse_range_value(const std::vector<std::uint8_t>& v) {
    if (v.empty() || v.back() != 0 || v.size() > 64) return std::nullopt;
    const std::string s(v.begin(), v.end() - 1);
    if (s.find('\0') != std::string::npos) return std::nullopt;
    const char* p = s.c_str();
    char* end = nullptr;
    if (*p == ' ' || *p == '\t') return std::nullopt;
    const float lo = std::strtof(p, &end);
    if (end == p || *end != ' ') return std::nullopt;
    p = end + 1;
    if (*p == ' ' || *p == '\t') return std::nullopt;
    const float hi = std::strtof(p, &end);
    if (end == p || *end != '\0') return std::nullopt;
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) return std::nullopt;
    return lightmap::IzLogRange{lo, hi};
}

}  // namespace zhc::lightmap_astc
