// zhc/codec/bc6h.cpp — BC6H unsigned encoder and decoder (see bc6h.h, docs/lightmap-formats.md).
#include "bc6h.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <thread>

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

// Two-subset partitions (the first 32 of BC7's): bit t set = texel t belongs to subset 1.
constexpr std::uint16_t kPartition[32] = {
    0xcccc, 0x8888, 0xeeee, 0xecc8, 0xc880, 0xfeec, 0xfec8, 0xec80, 0xc800, 0xffec, 0xfe80,
    0xe800, 0xffe8, 0xff00, 0xfff0, 0xf000, 0xf710, 0x008e, 0x7100, 0x08ce, 0x008c, 0x7310,
    0x3100, 0x8cce, 0x088c, 0x3110, 0x6666, 0x366c, 0x17e8, 0x0ff0, 0x718e, 0x399c};
// Anchor texel of subset 1 (subset 0's anchor is texel 0).
constexpr std::uint8_t kAnchor2[32] = {15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
                                       15, 2,  8,  2,  2,  8,  8,  15, 2,  8,  2,  2,  8,  8,  2,  2};
constexpr int kWeights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
constexpr int kWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

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

struct BitReader {
    const std::uint8_t* p;
    int pos = 0;
    int bit() {
        const int b = (p[pos >> 3] >> (pos & 7)) & 1;
        ++pos;
        return b;
    }
    int bits(int n) {
        int v = 0;
        for (int i = 0; i < n; ++i) v |= bit() << i;
        return v;
    }
};
struct BitWriter {
    std::uint8_t* p;
    int pos = 0;
    void bit(int b) {
        if (b) p[pos >> 3] = static_cast<std::uint8_t>(p[pos >> 3] | (1 << (pos & 7)));
        ++pos;
    }
    void bits(int v, int n) {
        for (int i = 0; i < n; ++i) bit((v >> i) & 1);
    }
};

// ---- encoder ---------------------------------------------------------------------------------

struct Target {
    int h[16][3];    // target half bits (the error domain)
    float u[16][3];  // the same in the unquantized 16-bit domain: h * 64 / 31
};

struct Encoded {
    int mode = 10, partition = 0;
    int q[4][3] = {};  // quantized endpoints as stored (deltas already resolved: absolute values)
    std::uint8_t idx[16] = {};
    std::int64_t err = std::numeric_limits<std::int64_t>::max();
};

int quantize(float u, int bits) {
    const int maxq = (1 << bits) - 1;
    u = std::clamp(u, 0.0f, 65535.0f);
    if (bits >= 15) return std::clamp(static_cast<int>(u + 0.5f), 0, maxq);
    const int q0 = std::clamp(static_cast<int>(u * static_cast<float>(maxq + 1) / 65536.0f), 0, maxq);
    int best = q0;
    float be = std::abs(static_cast<float>(unquantize(q0, bits)) - u);
    for (int q : {q0 - 1, q0 + 1}) {
        if (q < 0 || q > maxq) continue;
        const float e = std::abs(static_cast<float>(unquantize(q, bits)) - u);
        if (e < be) be = e, best = q;
    }
    return best;
}

// Endpoints of the line that best fits the subset's texels (principal axis by power iteration),
// spanning the extreme projections. In the unquantized domain.
void initial_endpoints(const Target& t, std::uint16_t mask, float a[3], float b[3]) {
    float mean[3] = {0, 0, 0};
    int n = 0;
    for (int i = 0; i < 16; ++i)
        if (mask >> i & 1) {
            for (int c = 0; c < 3; ++c) mean[c] += t.u[i][c];
            ++n;
        }
    if (n == 0) {
        for (int c = 0; c < 3; ++c) a[c] = b[c] = 0;
        return;
    }
    for (float& m : mean) m /= static_cast<float>(n);
    float cov[6] = {0, 0, 0, 0, 0, 0};
    for (int i = 0; i < 16; ++i)
        if (mask >> i & 1) {
            const float d0 = t.u[i][0] - mean[0], d1 = t.u[i][1] - mean[1], d2 = t.u[i][2] - mean[2];
            cov[0] += d0 * d0, cov[1] += d0 * d1, cov[2] += d0 * d2;
            cov[3] += d1 * d1, cov[4] += d1 * d2, cov[5] += d2 * d2;
        }
    float ax[3] = {1, 1, 1};
    for (int it = 0; it < 4; ++it) {
        const float x = cov[0] * ax[0] + cov[1] * ax[1] + cov[2] * ax[2];
        const float y = cov[1] * ax[0] + cov[3] * ax[1] + cov[4] * ax[2];
        const float z = cov[2] * ax[0] + cov[4] * ax[1] + cov[5] * ax[2];
        const float m = std::max({std::abs(x), std::abs(y), std::abs(z)});
        if (m <= 0) break;
        ax[0] = x / m, ax[1] = y / m, ax[2] = z / m;
    }
    const float len2 = ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2];
    float lo = 0, hi = 0;
    for (int i = 0; i < 16; ++i)
        if (mask >> i & 1) {
            const float p = ((t.u[i][0] - mean[0]) * ax[0] + (t.u[i][1] - mean[1]) * ax[1] +
                             (t.u[i][2] - mean[2]) * ax[2]) / len2;
            lo = std::min(lo, p), hi = std::max(hi, p);
        }
    for (int c = 0; c < 3; ++c) {
        a[c] = std::clamp(mean[c] + lo * ax[c], 0.0f, 65535.0f);
        b[c] = std::clamp(mean[c] + hi * ax[c], 0.0f, 65535.0f);
    }
}

struct SubsetFit {
    float a[3], b[3];  // unquantized-domain endpoints
};

// Quantize endpoints for mode `md` (resolving the delta constraints by clamping), assign indices
// (anchor texels restricted to the first half) and measure the error exactly.
std::int64_t evaluate(const Target& t, int mode_i, int partition, SubsetFit fit[2], Encoded& out) {
    const Mode& md = modes()[static_cast<size_t>(mode_i)];
    const int ns = md.two_subsets ? 2 : 1;
    const int ib = md.two_subsets ? 3 : 4, n = 1 << ib;
    const int* wts = md.two_subsets ? kWeights3 : kWeights4;
    const std::uint16_t pmask = md.two_subsets ? kPartition[partition] : 0;
    const int anchor[2] = {0, md.two_subsets ? kAnchor2[partition] : 0};
    int q[4][3];
    for (int s = 0; s < ns; ++s)
        for (int c = 0; c < 3; ++c) {
            q[2 * s][c] = quantize(fit[s].a[c], md.ep_bits);
            q[2 * s + 1][c] = quantize(fit[s].b[c], md.ep_bits);
        }
    // Orient each subset so its anchor texel falls into the first half of the palette (its index
    // MSB is implicit 0): swapping the endpoints mirrors the palette exactly (w_j + w_{n-1-j} = 64).
    for (int s = 0; s < ns; ++s) {
        const int i = anchor[s];
        float pa = 0, pb = 0;
        for (int c = 0; c < 3; ++c) {
            const float d = static_cast<float>(unquantize(q[2 * s + 1][c], md.ep_bits) - unquantize(q[2 * s][c], md.ep_bits));
            pa += d * (t.u[i][c] - static_cast<float>(unquantize(q[2 * s][c], md.ep_bits)));
            pb += d * d;
        }
        if (pb > 0 && pa > 0.5f * pb)
            for (int c = 0; c < 3; ++c) std::swap(q[2 * s][c], q[2 * s + 1][c]);
    }
    if (md.transformed) {
        const int mask = (1 << md.ep_bits) - 1;
        for (int e = 1; e < 2 * ns; ++e)
            for (int c = 0; c < 3; ++c) {
                const int db = md.delta_bits[c];
                int d = sign_extend(q[e][c] - q[0][c], md.ep_bits);  // wrap-around allowed (decode masks)
                d = std::clamp(d, -(1 << (db - 1)), (1 << (db - 1)) - 1);
                q[e][c] = (q[0][c] + d) & mask;
            }
    }
    int pal[2][16][3];
    for (int s = 0; s < ns; ++s) {
        int ua[3], ub[3];
        for (int c = 0; c < 3; ++c) {
            ua[c] = unquantize(q[2 * s][c], md.ep_bits);
            ub[c] = unquantize(q[2 * s + 1][c], md.ep_bits);
        }
        for (int j = 0; j < n; ++j)
            for (int c = 0; c < 3; ++c) pal[s][j][c] = finish(ua[c], ub[c], wts[j]);
    }
    // Index per texel: project onto the palette's axis, then test the nearest index and its two
    // neighbours exactly (the palette is linear in the weight up to integer rounding, and the
    // weights are within 1/64 of uniform, so the best index is among those three).
    float axis[2][3], inv_len2[2];
    for (int s = 0; s < ns; ++s) {
        float l2 = 0;
        for (int c = 0; c < 3; ++c) {
            axis[s][c] = static_cast<float>(pal[s][n - 1][c] - pal[s][0][c]);
            l2 += axis[s][c] * axis[s][c];
        }
        inv_len2[s] = l2 > 0 ? static_cast<float>(n - 1) / l2 : 0.0f;
    }
    std::int64_t err = 0;
    std::uint8_t idx[16];
    for (int i = 0; i < 16; ++i) {
        const int s = pmask >> i & 1;
        const int lim = (i == anchor[s]) ? n / 2 : n;
        const float proj = (static_cast<float>(t.h[i][0] - pal[s][0][0]) * axis[s][0] +
                            static_cast<float>(t.h[i][1] - pal[s][0][1]) * axis[s][1] +
                            static_cast<float>(t.h[i][2] - pal[s][0][2]) * axis[s][2]) * inv_len2[s];
        const int j0 = std::clamp(static_cast<int>(proj + 0.5f), 0, lim - 1);  // proj < 0 truncates to 0
        // 64-bit: three squared differences of up to 0x7BFF each overflow int32.
        int best = 0;
        std::int64_t be = std::numeric_limits<std::int64_t>::max();
        for (int j = std::max(0, j0 - 1); j <= std::min(lim - 1, j0 + 1); ++j) {
            const std::int64_t d0 = pal[s][j][0] - t.h[i][0], d1 = pal[s][j][1] - t.h[i][1], d2 = pal[s][j][2] - t.h[i][2];
            const std::int64_t e = d0 * d0 + d1 * d1 + d2 * d2;
            if (e < be) be = e, best = j;
        }
        idx[i] = static_cast<std::uint8_t>(best);
        err += be;
        if (err >= out.err) return err;  // cannot win any more
    }
    if (err < out.err) {
        out.err = err;
        out.mode = mode_i;
        out.partition = partition;
        std::memcpy(out.q, q, sizeof q);
        std::memcpy(out.idx, idx, sizeof idx);
    }
    return err;
}

// Least-squares endpoints for the given indices (per subset, per channel 2x2 normal equations).
void refine(const Target& t, const Encoded& e, SubsetFit fit[2]) {
    const Mode& md = modes()[static_cast<size_t>(e.mode)];
    const int ns = md.two_subsets ? 2 : 1;
    const int* wts = md.two_subsets ? kWeights3 : kWeights4;
    const std::uint16_t pmask = md.two_subsets ? kPartition[e.partition] : 0;
    for (int s = 0; s < ns; ++s) {
        float aa = 0, ab = 0, bb = 0, ra[3] = {0, 0, 0}, rb[3] = {0, 0, 0};
        for (int i = 0; i < 16; ++i) {
            if ((pmask >> i & 1) != s) continue;
            const float w = static_cast<float>(wts[e.idx[i]]) / 64.0f, v = 1 - w;
            aa += v * v, ab += v * w, bb += w * w;
            for (int c = 0; c < 3; ++c) ra[c] += v * t.u[i][c], rb[c] += w * t.u[i][c];
        }
        const float det = aa * bb - ab * ab;
        if (std::abs(det) < 1e-6f) continue;
        for (int c = 0; c < 3; ++c) {
            fit[s].a[c] = std::clamp((bb * ra[c] - ab * rb[c]) / det, 0.0f, 65535.0f);
            fit[s].b[c] = std::clamp((aa * rb[c] - ab * ra[c]) / det, 0.0f, 65535.0f);
        }
    }
}

// Whether the quantized initial endpoints of both subsets fit the mode's delta precision.
bool deltas_fit(const Mode& md, const SubsetFit fit[2]) {
    if (!md.transformed) return true;
    int q[4][3];
    for (int s = 0; s < 2; ++s)
        for (int c = 0; c < 3; ++c) {
            q[2 * s][c] = quantize(fit[s].a[c], md.ep_bits);
            q[2 * s + 1][c] = quantize(fit[s].b[c], md.ep_bits);
        }
    // Either orientation of subset 0 may become the base after the anchor fix: test both.
    for (int flip = 0; flip < 2; ++flip) {
        const int base = flip;
        bool ok = true;
        for (int e = 0; e < 4 && ok; ++e) {
            if (e == base) continue;
            for (int c = 0; c < 3; ++c) {
                const int d = sign_extend(q[e][c] - q[base][c], md.ep_bits);
                const int lim = 1 << (md.delta_bits[c] - 1);
                if (d < -lim || d >= lim) ok = false;
            }
        }
        if (ok) return true;
    }
    return false;
}

// The most precise one-subset delta mode (16/4, 12/8, 11/9 bits) whose delta range holds the
// endpoint span: 2^(db-1) - 1 steps of 2^(16 - ep) in the unquantized domain; -1 if none.
int best_delta_mode(const SubsetFit& f) {
    float span = 0;
    for (int c = 0; c < 3; ++c) span = std::max(span, std::abs(f.b[c] - f.a[c]));
    for (int m : {13, 12, 11}) {
        const Mode& md = modes()[static_cast<size_t>(m)];
        if (span < static_cast<float>((1 << (md.delta_bits[0] - 1)) - 1) * static_cast<float>(1 << (16 - md.ep_bits)))
            return m;
    }
    return -1;
}

// Fit one (mode, partition) with `iters` refinement rounds; updates `best`.
void try_mode(const Target& t, int mode_i, int partition, const SubsetFit init[2], int iters, Encoded& best) {
    SubsetFit fit[2] = {init[0], init[1]};
    Encoded local;
    evaluate(t, mode_i, partition, fit, local);
    for (int it = 0; it < iters; ++it) {
        refine(t, local, fit);
        const std::int64_t before = local.err;
        evaluate(t, mode_i, partition, fit, local);
        if (local.err >= before) break;
    }
    if (local.err < best.err) best = local;
}

// Cheap score of every partition: for each subset the squared residual orthogonal to its
// principal axis (what a line fit cannot represent), from per-subset moments. Subset 0's moments
// are the block's minus subset 1's, so each partition costs one masked sum.
void partition_scores(const Target& t, float score[32]) {
    float m[16][9];
    float total[9] = {};
    for (int i = 0; i < 16; ++i) {
        const float x = t.u[i][0] * (1.0f / 256), y = t.u[i][1] * (1.0f / 256), z = t.u[i][2] * (1.0f / 256);
        const float v[9] = {x, y, z, x * x, x * y, x * z, y * y, y * z, z * z};
        for (int k = 0; k < 9; ++k) m[i][k] = v[k], total[k] += v[k];
    }
    for (int p = 0; p < 32; ++p) {
        float s1[9] = {};
        int n1 = 0;
        for (int i = 0; i < 16; ++i)
            if (kPartition[p] >> i & 1) {
                for (int k = 0; k < 9; ++k) s1[k] += m[i][k];
                ++n1;
            }
        float sc = 0;
        for (int s = 0; s < 2; ++s) {
            float a[9];
            const int n = s ? n1 : 16 - n1;
            for (int k = 0; k < 9; ++k) a[k] = s ? s1[k] : total[k] - s1[k];
            const float inv = 1.0f / static_cast<float>(n);
            const float cov[6] = {a[3] - a[0] * a[0] * inv, a[4] - a[0] * a[1] * inv, a[5] - a[0] * a[2] * inv,
                                  a[6] - a[1] * a[1] * inv, a[7] - a[1] * a[2] * inv, a[8] - a[2] * a[2] * inv};
            float ax[3] = {1, 1, 1}, lambda = 0;
            for (int it = 0; it < 4; ++it) {
                const float x = cov[0] * ax[0] + cov[1] * ax[1] + cov[2] * ax[2];
                const float y = cov[1] * ax[0] + cov[3] * ax[1] + cov[4] * ax[2];
                const float z = cov[2] * ax[0] + cov[4] * ax[1] + cov[5] * ax[2];
                const float len = std::sqrt(x * x + y * y + z * z);
                if (!(len > 0)) break;
                lambda = len;
                ax[0] = x / len, ax[1] = y / len, ax[2] = z / len;
            }
            sc += std::max(0.0f, cov[0] + cov[3] + cov[5] - lambda);
        }
        score[p] = sc;
    }
}

void make_target(const float rgb[16][3], Target& t) {
    for (int i = 0; i < 16; ++i)
        for (int c = 0; c < 3; ++c) {
            const int h = float_to_uf16(rgb[i][c]);
            t.h[i][c] = h;
            t.u[i][c] = static_cast<float>(h) * (64.0f / 31.0f);
        }
}

void pack(const Encoded& e, std::uint8_t out[16]) {
    const Mode& md = modes()[static_cast<size_t>(e.mode)];
    std::memset(out, 0, 16);
    BitWriter w{out};
    w.bits(md.code, md.code_bits);
    const int ns = md.two_subsets ? 2 : 1;
    int stored[4][3];
    for (int i = 0; i < 2 * ns; ++i)
        for (int c = 0; c < 3; ++c)
            stored[i][c] = (md.transformed && i > 0) ? ((e.q[i][c] - e.q[0][c]) & ((1 << md.delta_bits[c]) - 1)) : e.q[i][c];
    for (int s = 0; s < md.nsegs; ++s) {
        const Seg& g = md.segs[static_cast<size_t>(s)];
        const int v = stored[g.field / 3][g.field % 3];
        const int step = g.last >= g.first ? 1 : -1;
        for (int b = g.first;; b += step) {
            w.bit(v >> b & 1);
            if (b == g.last) break;
        }
    }
    const int ib = md.two_subsets ? 3 : 4;
    if (md.two_subsets) w.bits(e.partition, 5);
    const int anchor2 = md.two_subsets ? kAnchor2[e.partition] : -1;
    for (int i = 0; i < 16; ++i) w.bits(e.idx[i], (i == 0 || i == anchor2) ? ib - 1 : ib);
}

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
    BitReader r{in, md.code_bits};
    int e[4][3] = {};
    for (int s = 0; s < md.nsegs; ++s) {
        const Seg& g = md.segs[static_cast<size_t>(s)];
        const int step = g.last >= g.first ? 1 : -1;
        for (int b = g.first;; b += step) {
            e[g.field / 3][g.field % 3] |= r.bit() << b;
            if (b == g.last) break;
        }
    }
    const int ns = md.two_subsets ? 2 : 1;
    if (md.transformed) {
        const int mask = (1 << md.ep_bits) - 1;
        for (int i = 1; i < 2 * ns; ++i)
            for (int c = 0; c < 3; ++c) e[i][c] = (e[0][c] + sign_extend(e[i][c], md.delta_bits[c])) & mask;
    }
    for (int i = 0; i < 2 * ns; ++i)
        for (int c = 0; c < 3; ++c) e[i][c] = unquantize(e[i][c], md.ep_bits);
    const int partition = md.two_subsets ? r.bits(5) : 0;
    const std::uint16_t pmask = md.two_subsets ? kPartition[partition] : 0;
    const int anchor2 = md.two_subsets ? kAnchor2[partition] : -1;
    const int ib = md.two_subsets ? 3 : 4;
    const int* wts = md.two_subsets ? kWeights3 : kWeights4;
    for (int i = 0; i < 16; ++i) {
        const int idx = r.bits((i == 0 || i == anchor2) ? ib - 1 : ib);
        const int s = pmask >> i & 1;
        for (int c = 0; c < 3; ++c)
            out[i][c] = static_cast<std::uint16_t>(finish(e[2 * s][c], e[2 * s + 1][c], wts[idx]));
    }
}

void encode_block(const float rgb[16][3], Quality quality, std::uint8_t out[16]) {
    Target t;
    make_target(rgb, t);
    Encoded best;
    SubsetFit one[2];
    initial_endpoints(t, 0xFFFF, one[0].a, one[0].b);
    one[1] = one[0];
    switch (quality) {
        case Quality::kMode11:
            try_mode(t, 10, 0, one, 1, best);
            break;
        case Quality::kFast: {
            // Mode 11 (10-bit absolute) plus the most precise delta mode whose deltas fit.
            try_mode(t, 10, 0, one, 1, best);
            const int dm = best_delta_mode(one[0]);
            if (dm >= 0) try_mode(t, dm, 0, one, 1, best);
            // Blocks with a large error (> ~6 half ULPs rms per value): the single best-scoring
            // partition with its most precise fitting mode.
            if (best.err > 48 * 36) {
                float score[32];
                partition_scores(t, score);
                const int bp = static_cast<int>(std::min_element(score, score + 32) - score);
                SubsetFit two[2];
                initial_endpoints(t, static_cast<std::uint16_t>(~kPartition[bp]), two[0].a, two[0].b);
                initial_endpoints(t, kPartition[bp], two[1].a, two[1].b);
                int mode2 = 9;
                for (const int m : {2, 3, 4, 0, 5, 6, 7, 8, 1})
                    if (deltas_fit(modes()[static_cast<size_t>(m)], two)) {
                        mode2 = m;
                        break;
                    }
                try_mode(t, mode2, bp, two, 1, best);
            }
            break;
        }
        case Quality::kDefault:
        case Quality::kExhaustive: {
            const bool ex = quality == Quality::kExhaustive;
            const int iters = ex ? 4 : 2;
            if (ex) {
                for (int m = 10; m < 14; ++m) try_mode(t, m, 0, one, iters, best);
            } else {
                try_mode(t, 10, 0, one, iters, best);
                const int dm = best_delta_mode(one[0]);
                if (dm >= 0) try_mode(t, dm, 0, one, iters, best);
            }
            // Two subsets: exhaustive tries every partition with every mode.
            // Default: two subsets only for blocks above ~3 half ULPs rms per value, and only the
            // 3 partitions whose subsets are closest to lines (tuned with bench_bc6h).
            const int npart = 3;
            if (!ex && best.err <= 48 * 9) break;
            int order[32];
            for (int p = 0; p < 32; ++p) order[p] = p;
            int count = 32;
            if (!ex) {
                float score[32];
                partition_scores(t, score);
                std::partial_sort(order, order + npart, order + 32,
                                  [&](int a, int b) { return score[a] < score[b] || (score[a] == score[b] && a < b); });
                count = npart;
            }
            for (int k = 0; k < count; ++k) {
                const int p = order[k];
                SubsetFit two[2];
                initial_endpoints(t, static_cast<std::uint16_t>(~kPartition[p]), two[0].a, two[0].b);
                initial_endpoints(t, kPartition[p], two[1].a, two[1].b);
                if (ex) {
                    for (int m = 0; m < 10; ++m) try_mode(t, m, p, two, iters, best);
                    continue;
                }
                // Default: the two most precise modes whose deltas hold the initial endpoints
                // without clamping; the absolute 6-bit mode when none does.
                int tried = 0;
                for (const int m : {2, 3, 4, 0, 5, 6, 7, 8, 1}) {
                    if (!deltas_fit(modes()[static_cast<size_t>(m)], two)) continue;
                    try_mode(t, m, p, two, iters, best);
                    if (++tried == 2) break;
                }
                if (tried == 0) try_mode(t, 9, p, two, iters, best);
            }
            break;
        }
    }
    pack(best, out);
}

std::vector<std::uint8_t> encode_image(const float* rgb, int width, int height, Quality quality, int threads) {
    const int bw = (width + 3) / 4, bh = (height + 3) / 4;
    std::vector<std::uint8_t> out(static_cast<size_t>(bw) * static_cast<size_t>(bh) * 16);
    auto work = [&](int row_begin, int row_end) {
        float block[16][3];
        for (int by = row_begin; by < row_end; ++by)
            for (int bx = 0; bx < bw; ++bx) {
                for (int i = 0; i < 16; ++i) {
                    const int x = std::min(bx * 4 + (i & 3), width - 1), y = std::min(by * 4 + (i >> 2), height - 1);
                    const float* p = rgb + (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 3;
                    block[i][0] = p[0], block[i][1] = p[1], block[i][2] = p[2];
                }
                encode_block(block, quality, out.data() + (static_cast<size_t>(by) * static_cast<size_t>(bw) + static_cast<size_t>(bx)) * 16);
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
