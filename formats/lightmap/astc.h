// zhc/formats/lightmap/astc.h — ASTC block compression of lightmap planes through ARM's astcenc
// (Debian libastcenc-dev, astcenc 4.2), and the KTX2 vkFormat numbers of the footprints zhc writes.
//
// Footprints: square 4x4, 5x5, 6x6 and 8x8 (16 bytes per block: 1, 0.64, 0.44, 0.25 bytes per texel).
// HDR: astcenc's ASTCENC_PRF_HDR_RGB_LDR_A profile (RGB HDR, alpha 1), read back as
// VK_FORMAT_ASTC_NxN_SFLOAT_BLOCK. LDR: ASTCENC_PRF_LDR (linear, not sRGB), VK_FORMAT_ASTC_NxN_UNORM_BLOCK;
// one to three channels (swizzles rrr1, rrrg, rgb1 as astcenc's own tool does for L, LA, RGB).
//
// Determinism: astcenc compresses each block from its own texels only, whichever of the context's
// threads takes it (the work is split by block index), so the bytes do not depend on the thread
// count (tested: 1, 2 and 4 threads, and band by band against the whole image).
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety: every function here is reentrant; astcenc contexts are pooled behind a mutex and
// lent to one call at a time. Determinism: one `zhc lightmap encode` gives the same bytes for any
// thread count and band height (tested), but astcenc 4.2 keeps some state between images inside a
// process, so a process that encodes several footprints can see its later results move slightly
// (docs/lightmap-formats.md "Determinism").
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "codec/lightmap/lightmap.h"
#include "codec/status.h"

namespace zhc::astc {

struct Footprint {
    int x = 4, y = 4;
    bool operator==(const Footprint&) const = default;
};
// 4x4, 5x5, 6x6, 8x8.
bool footprint_supported(Footprint f);

enum class Effort { kFast, kMedium, kThorough };  // astcenc ASTCENC_PRE_FAST / MEDIUM / THOROUGH

// VK_FORMAT_ASTC_NxN_SFLOAT_BLOCK (1000066000 + k) and VK_FORMAT_ASTC_NxN_UNORM_BLOCK (157 + 2 k); 0 if unsupported.
std::uint32_t vk_format_hdr(Footprint f);
std::uint32_t vk_format_ldr(Footprint f);
struct Format {
    Footprint footprint;
    bool hdr = false;
};
// The footprint and profile of a vkFormat zhc writes; nullopt for anything else (sRGB included).
std::optional<Format> format_of_vk(std::uint32_t vk_format);

std::size_t block_count(Footprint f, int width, int height);  // ceil(w/x) * ceil(h/y)

// Interleaved `channels` floats per texel (HDR: 3, linear RGB >= 0; LDR: 1..3 in [0, 1]), width x height.
// Edge blocks: astcenc repeats the last row / column. kUnsupported for a footprint outside the list;
// kInternal if astcenc reports an error.
Result<std::vector<std::uint8_t>> encode(const float* values, int channels, int width, int height, Footprint f, bool hdr,
                                         Effort effort, int threads = 1);
// astcenc's decompressor: RGBA float per texel (HDR: the block's float16 values; LDR: the
// unorm16 / 65535 value rounded to float16, as the ASTC specification decodes without decode_unorm8).
// An invalid block decodes to the specification's error colour: opaque magenta in LDR (what a GPU
// samples); in HDR, where that colour is NaN, kBadFormat naming the block (its row counted from
// `first_row`, the texel row the blocks start at in the whole image).
Result<std::vector<float>> decode_rgba(const std::uint8_t* blocks, std::size_t size, int width, int height, Footprint f, bool hdr,
                                       int first_row = 0);

}  // namespace zhc::astc

// ---- IrradZ lightmaps as ASTC (docs/lightmap-formats.md, "ASTC targets") ----------------------

namespace zhc::lightmap_astc {

// I_z: ASTC HDR RGB (target astc) or ASTC LDR RGB of lightmap::iz_to_ldr (target astc-ldr, the range
// in the KTX2 key "zhc.iz_log2_range"). d and w_a: one ASTC LDR RGB texture (u, v, w_a), same footprint.
// split_dwa (measurement only, never written to files): d as an LA texture and w_a as an L texture.
struct Options {
    astc::Footprint footprint;
    astc::Effort effort = astc::Effort::kMedium;
    bool ldr_iz = false;
    lightmap::IzLogRange range;  // ldr_iz: the texture's range
    bool split_dwa = false;
};
struct Compressed {
    int width = 0, height = 0;
    Options options;
    std::vector<std::uint8_t> iz, dwa, wa;  // wa: split_dwa only
    std::size_t bytes() const { return iz.size() + dwa.size() + wa.size(); }
};
Result<Compressed> compress(const lightmap::IrradzPlanes& p, const Options& o, int threads = 1);
// The texture values (astcenc's decoder) turned into planes: I_z as decoded (HDR) or iz_from_ldr
// of the decoded value (LDR); (u, v, w_a) as decoded.
Result<lightmap::IrradzPlanes> decompress(const Compressed& c, int first_row = 0);

// The KTX2 key of the LDR range and its value: "lo hi" as two decimal floats (%.9g, exact), NUL-terminated.
inline constexpr const char* kRangeKey = "zhc.iz_log2_range";
std::vector<std::uint8_t> range_value(lightmap::IzLogRange r);
// nullopt unless the value is exactly two finite floats with lo < hi, NUL-terminated.
std::optional<lightmap::IzLogRange> parse_range_value(const std::vector<std::uint8_t>& v);

}  // namespace zhc::lightmap_astc
