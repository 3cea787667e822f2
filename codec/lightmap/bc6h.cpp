// zhc/codec/lightmap/bc6h.cpp — BC6H unsigned encoder and decoder (see bc6h.h, docs/lightmap-formats.md).
#include "codec/lightmap/bc6h.h"
#include "codec/lightmap/bptc_tables.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <thread>

#include "codec/isa.h"  // the AVX2 twin of the encoder

namespace zhc::bc6h {
namespace {

// ---- format tables (D3D11 BC6H / Khronos BPTC float) -----------------------------------------

// One run of endpoint bits in the block header: `field` = endpoint * 3 + channel (endpoints w, x,
// y, z = 0..3; channels r, g, b = 0..2); bits are stored in stream order first, first +- 1, ...,
// last (a descending run, e.g. "rw11-10" in modes 13/14, stores the high bit first).
struct Seg {
    std::uint8_t field, first, last;
};

struct Mode {
    std::uint8_t code;       // mode bits as they appear in the low bits of byte 0
    std::uint8_t code_bits;  // 2 or 5
    bool transformed;        // endpoints other than w stored as signed deltas from w
    bool two_subsets;
    int ep_bits;             // endpoint precision
    int delta_bits[3];       // stored precision of x, y, z per channel (== ep_bits if not transformed)
    std::string_view layout; // the header after the mode bits, in stream order
    std::array<Seg, 32> segs{};
    int nsegs = 0;
};

// The header layouts, transcribed from the format's per-mode bit tables into a compact notation:
// "<channel><endpoint><bit>" or "<channel><endpoint><first>-<last>" in stream order.
std::array<Mode, 14> make_modes() {
    std::array<Mode, 14> m = {{
        {0x00, 2, true, true, 10, {5, 5, 5},
         "gy4 by4 bz4 rw0-9 gw0-9 bw0-9 rx0-4 gz4 gy0-3 gx0-4 bz0 gz0-3 bx0-4 bz1 by0-3 ry0-4 bz2 rz0-4 bz3"},
        {0x01, 2, true, true, 7, {6, 6, 6},
         "gy5 gz4 gz5 rw0-6 bz0 bz1 by4 gw0-6 by5 bz2 gy4 bw0-6 bz3 bz5 bz4 rx0-5 gy0-3 gx0-5 gz0-3 bx0-5 by0-3 ry0-5 rz0-5"},
        {0x02, 5, true, true, 11, {5, 4, 4},
         "rw0-9 gw0-9 bw0-9 rx0-4 rw10 gy0-3 gx0-3 gw10 bz0 gz0-3 bx0-3 bw10 bz1 by0-3 ry0-4 bz2 rz0-4 bz3"},
        {0x06, 5, true, true, 11, {4, 5, 4},
         "rw0-9 gw0-9 bw0-9 rx0-3 rw10 gz4 gy0-3 gx0-4 gw10 gz0-3 bx0-3 bw10 bz1 by0-3 ry0-3 bz0 bz2 rz0-3 gy4 bz3"},
        {0x0A, 5, true, true, 11, {4, 4, 5},
         "rw0-9 gw0-9 bw0-9 rx0-3 rw10 by4 gy0-3 gx0-3 gw10 bz0 gz0-3 bx0-4 bw10 by0-3 ry0-3 bz1 bz2 rz0-3 bz4 bz3"},
        {0x0E, 5, true, true, 9, {5, 5, 5},
         "rw0-8 by4 gw0-8 gy4 bw0-8 bz4 rx0-4 gz4 gy0-3 gx0-4 bz0 gz0-3 bx0-4 bz1 by0-3 ry0-4 bz2 rz0-4 bz3"},
        {0x12, 5, true, true, 8, {6, 5, 5},
         "rw0-7 gz4 by4 gw0-7 bz2 gy4 bw0-7 bz3 bz4 rx0-5 gy0-3 gx0-4 bz0 gz0-3 bx0-4 bz1 by0-3 ry0-5 rz0-5"},
        {0x16, 5, true, true, 8, {5, 6, 5},
         "rw0-7 bz0 by4 gw0-7 gy5 gy4 bw0-7 gz5 bz4 rx0-4 gz4 gy0-3 gx0-5 gz0-3 bx0-4 bz1 by0-3 ry0-4 bz2 rz0-4 bz3"},
        {0x1A, 5, true, true, 8, {5, 5, 6},
         "rw0-7 bz1 by4 gw0-7 by5 gy4 bw0-7 bz5 bz4 rx0-4 gz4 gy0-3 gx0-4 bz0 gz0-3 bx0-5 by0-3 ry0-4 bz2 rz0-4 bz3"},
        {0x1E, 5, false, true, 6, {6, 6, 6},
         "rw0-5 gz4 bz0 bz1 by4 gw0-5 gy5 by5 bz2 gy4 bw0-5 gz5 bz3 bz5 bz4 rx0-5 gy0-3 gx0-5 gz0-3 bx0-5 by0-3 ry0-5 rz0-5"},
        {0x03, 5, false, false, 10, {10, 10, 10}, "rw0-9 gw0-9 bw0-9 rx0-9 gx0-9 bx0-9"},
        {0x07, 5, true, false, 11, {9, 9, 9}, "rw0-9 gw0-9 bw0-9 rx0-8 rw10 gx0-8 gw10 bx0-8 bw10"},
        {0x0B, 5, true, false, 12, {8, 8, 8}, "rw0-9 gw0-9 bw0-9 rx0-7 rw11-10 gx0-7 gw11-10 bx0-7 bw11-10"},
        {0x0F, 5, true, false, 16, {4, 4, 4}, "rw0-9 gw0-9 bw0-9 rx0-3 rw15-10 gx0-3 gw15-10 bx0-3 bw15-10"},
    }};
    for (Mode& md : m) {
        std::string_view s = md.layout;
        while (!s.empty()) {
            while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
            if (s.empty()) break;
            const int ch = s[0] == 'r' ? 0 : (s[0] == 'g' ? 1 : 2);
            const int ep = s[1] == 'w' ? 0 : (s[1] == 'x' ? 1 : (s[1] == 'y' ? 2 : 3));
            s.remove_prefix(2);
            auto number = [&] {
                int v = 0;
                while (!s.empty() && s.front() >= '0' && s.front() <= '9') {
                    v = v * 10 + (s.front() - '0');
                    s.remove_prefix(1);
                }
                return v;
            };
            const int first = number();
            int last = first;
            if (!s.empty() && s.front() == '-') {
                s.remove_prefix(1);
                last = number();
            }
            md.segs[static_cast<size_t>(md.nsegs++)] = {static_cast<std::uint8_t>(ep * 3 + ch),
                                                        static_cast<std::uint8_t>(first),
                                                        static_cast<std::uint8_t>(last)};
        }
    }
    return m;
}
const std::array<Mode, 14>& modes() {
    static const std::array<Mode, 14> m = make_modes();
    return m;
}

// A mode's header as runs of bits at fixed stream positions, so that packing (encoder) and
// unpacking (decode_block) need no position bookkeeping. Stream bits [64 word + pos, + len) =
// bits [shift, shift + len) of the field; reversed runs ("rw11-10") are split into single bits,
// and runs that cross the 64-bit boundary into two ops.
struct PackOp {
    std::uint8_t field, shift, word, pos;
    std::uint32_t mask;  // (1 << len) - 1
};
struct PackPlan {
    std::array<PackOp, 40> ops{};
    int nops = 0;
    int header_bits = 0;  // mode bits + endpoint bits
};
const std::array<PackPlan, 14>& pack_plans() {
    static const std::array<PackPlan, 14> plans = [] {
        std::array<PackPlan, 14> out{};
        for (size_t m = 0; m < 14; ++m) {
            const Mode& md = modes()[m];
            PackPlan& pl = out[m];
            int pos = md.code_bits;
            auto add = [&](int field, int shift, int len) {
                while (len > 0) {
                    const int here = std::min(len, 64 - pos % 64);
                    pl.ops[static_cast<size_t>(pl.nops++)] = {
                        static_cast<std::uint8_t>(field), static_cast<std::uint8_t>(shift),
                        static_cast<std::uint8_t>(pos / 64), static_cast<std::uint8_t>(pos % 64),
                        static_cast<std::uint32_t>((std::uint64_t{1} << here) - 1)};
                    pos += here, shift += here, len -= here;
                }
            };
            for (int k = 0; k < md.nsegs; ++k) {
                const Seg& g = md.segs[static_cast<size_t>(k)];
                if (g.last >= g.first) {
                    add(g.field, g.first, g.last - g.first + 1);
                } else {
                    for (int b = g.first; b >= g.last; --b) add(g.field, b, 1);
                }
            }
            pl.header_bits = pos;
        }
        return out;
    }();
    return plans;
}

// The BPTC tables (codec/lightmap/bptc_tables.h): BC6H's two-subset modes use the first 32
// partitions and their anchors; 3- and 4-bit index weights.
constexpr const std::uint16_t (&kPartition)[64] = bptc::kPartition2;
constexpr const std::uint8_t (&kAnchor2)[64] = bptc::kAnchor2;
constexpr const int (&kWeights3)[8] = bptc::kWeights3;
constexpr const int (&kWeights4)[16] = bptc::kWeights4;
// evaluate's vectorised search computes the weights as round(64 j / (n - 1)) in floats: checked
// here against the tables, with the same float expression.
template <int N>
constexpr bool weights_are_rounded_ramp(const int (&w)[N]) {
    for (int j = 0; j < N; ++j)
        if (static_cast<int>(static_cast<float>(j) * (64.0f / static_cast<float>(N - 1)) + 0.5f) != w[j]) return false;
    return true;
}
static_assert(weights_are_rounded_ramp(kWeights3) && weights_are_rounded_ramp(kWeights4));

// Nearest index to a palette position: entry k holds the index whose weight w_j / 64 is nearest
// to k / 128 (ties to the lower index). Used by the fast index selection.
template <int N>
constexpr std::array<std::uint8_t, 129> make_nearest(const int (&w)[N]) {
    std::array<std::uint8_t, 129> lut{};
    auto dist = [](int v) { return v < 0 ? -v : v; };  // std::abs is not constexpr before C++23 (clang rejects it)
    for (int k = 0; k <= 128; ++k) {
        int best = 0;
        for (int j = 1; j < N; ++j)
            if (dist(2 * w[j] - k) < dist(2 * w[best] - k)) best = j;
        lut[static_cast<size_t>(k)] = static_cast<std::uint8_t>(best);
    }
    return lut;
}
constexpr std::array<std::uint8_t, 129> kNearest3 = make_nearest(kWeights3);
constexpr std::array<std::uint8_t, 129> kNearest4 = make_nearest(kWeights4);
// The same lookup in arithmetic, as evaluate's vectorised loop computes it (a table lookup per
// texel is a gather): k / 2 lies in [64 j0 / (n - 1), 64 (j0 + 1) / (n - 1)) for j0 = floor(k (n -
// 1) / 128), the weights are within 1/2 of that ramp and at least 3.2 apart, so the nearest is j0
// or j0 + 1 (the lower on a tie). Checked equal to the tables for every k.
[[gnu::always_inline]] constexpr int ramp_weight(int j, float wscale) {
    return static_cast<int>(static_cast<float>(j) * wscale + 0.5f);
}
[[gnu::always_inline]] constexpr int nearest_index(int k, int n, float wscale) {
    const int j0 = (k * (n - 1)) >> 7;
    const int d0 = 2 * ramp_weight(j0, wscale) - k, d1 = 2 * ramp_weight(j0 + 1, wscale) - k;
    return j0 + static_cast<int>(d1 * d1 < d0 * d0);
}
template <int N>
constexpr bool nearest_is_arithmetic(const std::array<std::uint8_t, 129>& lut) {
    for (int k = 0; k <= 128; ++k)
        if (nearest_index(k, N, 64.0f / static_cast<float>(N - 1)) != lut[static_cast<size_t>(k)]) return false;
    return true;
}
static_assert(nearest_is_arithmetic<8>(kNearest3) && nearest_is_arithmetic<16>(kNearest4));

// Mode index (0..13) from the first byte, or -1 for the reserved codes.
int mode_index(std::uint8_t b0) {
    if ((b0 & 2) == 0) return b0 & 1;  // 2-bit codes 00, 01
    switch (b0 & 0x1F) {
        case 0x02: return 2;
        case 0x06: return 3;
        case 0x0A: return 4;
        case 0x0E: return 5;
        case 0x12: return 6;
        case 0x16: return 7;
        case 0x1A: return 8;
        case 0x1E: return 9;
        case 0x03: return 10;
        case 0x07: return 11;
        case 0x0B: return 12;
        case 0x0F: return 13;
        default: return -1;  // 0x13, 0x17, 0x1B, 0x1F: reserved
    }
}

int unquantize(int q, int bits) {
    if (bits >= 15) return q;
    if (q == 0) return 0;
    if (q == (1 << bits) - 1) return 0xFFFF;
    return ((q << 15) + 0x4000) >> (bits - 1);
}
int sign_extend(int v, int bits) {
    const int m = 1 << (bits - 1);
    v &= (1 << bits) - 1;
    return (v ^ m) - m;
}
// Decoded half bits of a palette entry: interpolate unquantized endpoints, then scale by 31/64.
inline int finish(int a, int b, int w) { return (((a * (64 - w) + b * w + 32) >> 6) * 31) >> 6; }

}  // namespace

std::uint16_t float_to_half(float f) {
    std::uint32_t x;
    std::memcpy(&x, &f, 4);
    const std::uint32_t sign = (x >> 16) & 0x8000;
    const std::uint32_t ax = x & 0x7FFFFFFF;
    if (ax >= 0x7F800000) return static_cast<std::uint16_t>(sign | 0x7C00 | (ax > 0x7F800000 ? 0x200 : 0));
    if (ax >= 0x477FF000) return static_cast<std::uint16_t>(sign | 0x7C00);  // rounds to >= 65520: inf
    if (ax < 0x33000001) return static_cast<std::uint16_t>(sign);            // < 2^-25 (ties to 0)
    std::uint32_t e = ax >> 23;
    std::uint32_t m = (ax & 0x7FFFFF) | 0x800000;
    int shift;
    std::uint32_t base;
    if (e < 113) {  // subnormal half
        shift = static_cast<int>(126 - e);
        base = 0;
    } else {
        shift = 13;
        base = (e - 112) << 10;
        m &= 0x7FFFFF;
    }
    std::uint32_t r = m >> shift;
    const std::uint32_t rem = m & ((1u << shift) - 1), halfway = 1u << (shift - 1);
    if (rem > halfway || (rem == halfway && (r & 1))) ++r;
    return static_cast<std::uint16_t>(sign | (base + r));
}

float half_to_float(std::uint16_t h) {
    const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000) << 16;
    const std::uint32_t e = (h >> 10) & 0x1F, m = h & 0x3FF;
    std::uint32_t x;
    if (e == 0) {
        if (m == 0) {
            x = sign;
        } else {
            const float v = static_cast<float>(m) * (1.0f / 16777216.0f);  // m * 2^-24
            std::memcpy(&x, &v, 4);
            x |= sign;
        }
    } else if (e == 31) {
        x = sign | 0x7F800000 | (m << 13);
    } else {
        x = sign | ((e + 112) << 23) | (m << 13);
    }
    float f;
    std::memcpy(&f, &x, 4);
    return f;
}

std::uint16_t float_to_uf16(float f) {
    if (!(f > 0)) return 0;  // NaN, zero, negatives
    const std::uint16_t h = float_to_half(f);
    return h > 0x7BFF ? 0x7BFF : h;
}

int block_mode(const std::uint8_t in[16]) { return mode_index(in[0]); }

bool layout_is_consistent() {
    for (const Mode& md : modes()) {
        std::uint32_t seen[12] = {};
        int total = md.code_bits;
        for (int s = 0; s < md.nsegs; ++s) {
            const Seg& g = md.segs[static_cast<size_t>(s)];
            const int step = g.last >= g.first ? 1 : -1;
            for (int b = g.first;; b += step) {
                if (seen[g.field] >> b & 1) return false;
                seen[g.field] |= 1u << b;
                ++total;
                if (b == g.last) break;
            }
        }
        const int ns = md.two_subsets ? 2 : 1;
        for (int f = 0; f < 12; ++f) {
            const int e = f / 3, c = f % 3;
            const int want = e >= 2 * ns ? 0 : (e == 0 ? md.ep_bits : md.delta_bits[c]);
            if (seen[f] != (want == 0 ? 0u : ((1u << want) - 1))) return false;
        }
        if (!md.transformed && md.delta_bits[0] != md.ep_bits) return false;
        if (total != (md.two_subsets ? 77 : 65)) return false;
    }
    return true;
}

void decode_block(const std::uint8_t in[16], std::uint16_t out[16][3]) {
    const int mi = mode_index(in[0]);
    if (mi < 0) {
        std::memset(out, 0, sizeof(std::uint16_t) * 48);
        return;
    }
    const Mode& md = modes()[static_cast<size_t>(mi)];
    // The block as two little-endian words; the header's bit runs read at their fixed positions.
    std::uint64_t w[2] = {0, 0};
    for (int k = 0; k < 16; ++k) w[k >> 3] |= static_cast<std::uint64_t>(in[k]) << (8 * (k & 7));
    const PackPlan& plan = pack_plans()[static_cast<size_t>(mi)];
    int e[4][3] = {};
    for (int k = 0; k < plan.nops; ++k) {
        const PackOp& op = plan.ops[static_cast<size_t>(k)];
        e[op.field / 3][op.field % 3] |= static_cast<int>((w[op.word] >> op.pos) & op.mask) << op.shift;
    }
    const int ns = md.two_subsets ? 2 : 1;
    if (md.transformed) {
        const int mask = (1 << md.ep_bits) - 1;
        for (int i = 1; i < 2 * ns; ++i)
            for (int c = 0; c < 3; ++c) e[i][c] = (e[0][c] + sign_extend(e[i][c], md.delta_bits[c])) & mask;
    }
    for (int i = 0; i < 2 * ns; ++i)
        for (int c = 0; c < 3; ++c) e[i][c] = unquantize(e[i][c], md.ep_bits);
    // After the header (which ends at bit 65 or 77) the rest of the block is word 1's top bits:
    // the partition (two subsets), then the indices.
    std::uint64_t rest = w[1] >> (plan.header_bits - 64);
    int partition = 0;
    if (md.two_subsets) partition = static_cast<int>(rest & 31), rest >>= 5;
    const std::uint16_t pmask = md.two_subsets ? kPartition[partition] : 0;
    const int anchor2 = md.two_subsets ? kAnchor2[partition] : -1;
    const int ib = md.two_subsets ? 3 : 4;
    const int* wts = md.two_subsets ? kWeights3 : kWeights4;
    for (int i = 0; i < 16; ++i) {
        const int nb = (i == 0 || i == anchor2) ? ib - 1 : ib;
        const int idx = static_cast<int>(rest & ((1u << nb) - 1));
        rest >>= nb;
        const int s = pmask >> i & 1;
        for (int c = 0; c < 3; ++c)
            out[i][c] = static_cast<std::uint16_t>(finish(e[2 * s][c], e[2 * s + 1][c], wts[idx]));
    }
}

// ---- encoder: compiled twice, for baseline x86-64 and for AVX2 ----------------------------------
// bc6h_encoder.inl (with the two parts it includes) is the whole encoder; it is included once per
// instruction set, each time in its own namespace with internal linkage, so no function compiled
// for AVX2 can be picked by the linker for a baseline caller (the shared helpers above and the
// standard library's templates are defined before the target pragma and keep the baseline
// target). The encoder's loops are written to vectorise; AVX2 doubles their width. It uses no FMA
// (the target adds none, and the library is built with -ffp-contract=off) and no reassociation, so
// both versions compute the same floats in the same order and write the same bytes (tested on real
// maps for every quality).
// The encoder's 16-lane vector types never cross a function boundary (always inlined), so GCC's
// note that passing them by value would change with AVX-512 does not apply (clang reads this
// pragma too).
#pragma GCC diagnostic ignored "-Wpsabi"
namespace isa_baseline {
namespace {
#include "codec/lightmap/bc6h_encoder.inl"
}  // namespace
}  // namespace isa_baseline

#if ZHC_AVX2_TWIN
ZHC_AVX2_BEGIN
namespace isa_avx2 {
namespace {
#include "codec/lightmap/bc6h_encoder.inl"
}  // namespace
}  // namespace isa_avx2
ZHC_AVX2_END
#endif

bool isa_supported(Isa isa) {
    switch (isa) {
        case Isa::kBaseline:
            return true;
        case Isa::kAvx2:
            return cpu_has_avx2();
    }
    return false;
}

Isa best_isa() {
    static const Isa best = isa_supported(Isa::kAvx2) ? Isa::kAvx2 : Isa::kBaseline;
    return best;
}

const char* isa_name(Isa isa) { return isa == Isa::kAvx2 ? "avx2" : "baseline"; }

namespace {
using EncodeFn = void (*)(const float rgb[16][3], Quality quality, std::uint8_t out[16]);
EncodeFn encoder_for(Isa isa) {
#if ZHC_AVX2_TWIN
    if (isa == Isa::kAvx2 && isa_supported(Isa::kAvx2)) return isa_avx2::encode_block_impl;
#endif
    (void)isa;
    return isa_baseline::encode_block_impl;
}
}  // namespace

void encode_block(const float rgb[16][3], Quality quality, std::uint8_t out[16]) {
    encoder_for(best_isa())(rgb, quality, out);
}

std::vector<std::uint8_t> encode_image(const float* rgb, int width, int height, Quality quality, int threads) {
    return encode_image(rgb, width, height, quality, threads, best_isa());
}

std::vector<std::uint8_t> encode_image(const float* rgb, int width, int height, Quality quality, int threads, Isa isa) {
    const EncodeFn encode = encoder_for(isa);
    const int bw = (width + 3) / 4, bh = (height + 3) / 4;
    std::vector<std::uint8_t> out(static_cast<size_t>(bw) * static_cast<size_t>(bh) * 16);
    auto work = [&](int row_begin, int row_end) {
        float block[16][3];
        for (int by = row_begin; by < row_end; ++by)
            for (int bx = 0; bx < bw; ++bx) {
                if (bx * 4 + 3 < width && by * 4 + 3 < height) {  // interior: four runs of 4 texels
                    for (int r = 0; r < 4; ++r)
                        std::memcpy(block[4 * r],
                                    rgb + (static_cast<size_t>(by * 4 + r) * static_cast<size_t>(width) + static_cast<size_t>(bx * 4)) * 3,
                                    sizeof(float) * 12);
                } else {  // edge: texels past the image repeat the last row / column
                    for (int i = 0; i < 16; ++i) {
                        const int x = std::min(bx * 4 + (i & 3), width - 1), y = std::min(by * 4 + (i >> 2), height - 1);
                        const float* p = rgb + (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 3;
                        block[i][0] = p[0], block[i][1] = p[1], block[i][2] = p[2];
                    }
                }
                encode(block, quality, out.data() + (static_cast<size_t>(by) * static_cast<size_t>(bw) + static_cast<size_t>(bx)) * 16);
            }
    };
    threads = std::max(1, std::min(threads, bh));
    if (threads == 1) {
        work(0, bh);
    } else {
        std::vector<std::thread> pool;
        for (int k = 0; k < threads; ++k) pool.emplace_back(work, bh * k / threads, bh * (k + 1) / threads);
        for (auto& th : pool) th.join();
    }
    return out;
}

std::vector<std::uint16_t> decode_image(const std::uint8_t* blocks, std::size_t size, int width, int height) {
    std::vector<std::uint16_t> out(static_cast<size_t>(width) * static_cast<size_t>(height) * 3, 0);
    const int bw = (width + 3) / 4, bh = (height + 3) / 4;
    std::uint16_t px[16][3];
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            const size_t off = (static_cast<size_t>(by) * static_cast<size_t>(bw) + static_cast<size_t>(bx)) * 16;
            if (off + 16 > size) return out;  // missing blocks stay zero (callers validate sizes)
            decode_block(blocks + off, px);
            for (int i = 0; i < 16; ++i) {
                const int x = bx * 4 + (i & 3), y = by * 4 + (i >> 2);
                if (x >= width || y >= height) continue;
                for (int c = 0; c < 3; ++c)
                    out[(static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 3 + static_cast<size_t>(c)] = px[i][c];
            }
        }
    return out;
}

}  // namespace zhc::bc6h
