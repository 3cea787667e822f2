// zhc/codec/lightmap/bc6h_encoder.inl — the BC6H (unsigned, BC6H_UF16) block encoder. Included twice by
// codec/lightmap/bc6h.cpp: once for baseline x86-64 and once under an AVX2 target pragma, each copy in its
// own namespace; both perform the same IEEE operations in the same order, so they write the same
// bytes (docs/lightmap-formats.md "Two builds of the encoder, one output"). Two parts live in their
// own files and are included below at the point of the text where they belong (so each copy holds
// them too): bc6h_encoder_fit.inl (one mode and partition: endpoints, quantization, indices,
// refinement) and bc6h_encoder_partition.inl (the partition screening). This file keeps the types
// and vector helpers, the mode choice, the block target and packing, and the search per quality.
//
// Algorithm (docs/lightmap-formats.md "BC6H", with the quality levels' table):
//  * Error: squared differences of half-float bit patterns (a piecewise-linear log2, the space BC6H
//    interpolates in); inputs clamped to [0, 65504].
//  * Per (mode, partition): endpoints = the subset's principal axis (power iteration on the
//    covariance) spanning its extreme projections; quantize to the mode's precision (closed-form
//    nearest level); anchor-index orientation and delta clamping; index selection (projection on
//    the palette axis, or that plus an exact test of the two neighbours); least-squares endpoint
//    refinement for the chosen indices (per subset and channel, 2x2 normal equations), repeated
//    while the error drops. Principal-axis endpoints refined by least squares for fixed indices
//    is the classic block-compression fit (I. Castano, "High Quality DXT Compression using CUDA",
//    NVIDIA, 2007, for BC1; here per BC6H subset and mode).
//  * Mode choice: the most precise mode whose delta range holds the endpoints (closed form, no
//    trial of coarser modes); constant blocks directly in mode 14 (exact).
//  * Partition choice: all 32 two-subset partitions scored at once by what a line cannot fit —
//    per subset trace(C) - lambda_max(C) (3D, exhaustive) or the smaller eigenvalue in the plane
//    of the block's two principal axes (2D, fast and default) — from subset moment sums computed
//    as one masked product; the best few are then fitted. (zhc's own screening.)
// Sources: the format — Microsoft, "BC6H Format" (Direct3D 11 texture block compression
// documentation) and the Khronos Data Format Specification (BPTC float, BC6H); the decoder these
// bytes are checked against is Mesa's llvmpipe (tests/test_mesa_bc.cpp). Written from those
// descriptions, not from another encoder's code.

// ---- encoder ---------------------------------------------------------------------------------

struct Target {
    // Channel-major (h[c][i]: channel c of texel i) so that loops over the 16 texels vectorise.
    int h[3][16];    // target half bits (the error domain)
    float u[3][16];  // the same in the unquantized 16-bit domain: h * 64 / 31
    bool constant;   // all 16 texels have the same half bits
};

struct Encoded {
    int mode = 10, partition = 0;
    int q[4][3] = {};  // quantized endpoints as stored (deltas already resolved: absolute values)
    std::uint8_t idx[16] = {};
    std::int64_t err = std::numeric_limits<std::int64_t>::max();
};

// Nearest quantized endpoint to u, in closed form (checked equal to a search over q0 - 1, q0,
// q0 + 1, ties included, on a 1/8 grid of [-10, 65600) for every precision). Below 15
// bits the unquantized levels are 0, (q + 1/2) S for 0 < q < M, and 0xFFFF for q = M (S = 2^(16 -
// bits), M = 2^bits - 1): the interior levels are the centres of the bins [q S, (q + 1) S), so
// floor(u / S) is nearest except in the end bins, which compare with their one neighbour.
[[gnu::always_inline]] inline int quantize(float u, int bits) {
    const int maxq = (1 << bits) - 1;
    u = std::clamp(u, 0.0f, 65535.0f);
    if (bits >= 15) return std::clamp(static_cast<int>(u + 0.5f), 0, maxq);
    const float step = static_cast<float>(1 << (16 - bits));
    // 1 / step = 2^-(16 - bits) exactly, built from its exponent bits (no division).
    const float inv_step = std::bit_cast<float>(static_cast<std::uint32_t>(127 - (16 - bits)) << 23);
    const int q = static_cast<int>(u * inv_step);
    if (q == 0) return std::abs(1.5f * step - u) < u ? 1 : 0;
    if (q >= maxq) {
        const float below = static_cast<float>(maxq) * step - 0.5f * step;  // level of maxq - 1
        return std::abs(below - u) < 65535.0f - u ? maxq - 1 : maxq;
    }
    return q;
}

struct SubsetFit {
    float a[3], b[3];  // unquantized-domain endpoints
};

// 16 lanes of float / int32 (GCC/clang vector extensions: two AVX2 or four SSE2 registers). Used
// where the straight-line vectoriser leaves fully unrolled 16-texel loops scalar; lane-wise the
// same float operations in the same order as the scalar loops they replace.
typedef float V16 __attribute__((vector_size(64)));
typedef std::int32_t V16i __attribute__((vector_size(64)));
[[gnu::always_inline]] inline V16 load16(const float* p) {
    V16 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
[[gnu::always_inline]] inline void store16(float* p, const V16& v) { std::memcpy(p, &v, sizeof v); }
// Lane i = 1.0f if bit i of `bits` is set, else 0.0f: the bit itself (0 or 2^i) converted and
// scaled by 2^-i, both exact (only and, convert and multiply: GCC scalarises 16-lane compares).
[[gnu::always_inline]] inline V16 mask16(unsigned bits) {
    const V16i bit = {1 << 0, 1 << 1, 1 << 2,  1 << 3,  1 << 4,  1 << 5,  1 << 6,  1 << 7,
                      1 << 8, 1 << 9, 1 << 10, 1 << 11, 1 << 12, 1 << 13, 1 << 14, 1 << 15};
    const V16 scale = {1.0f,    0x1p-1f, 0x1p-2f,  0x1p-3f,  0x1p-4f,  0x1p-5f,  0x1p-6f,  0x1p-7f,
                       0x1p-8f, 0x1p-9f, 0x1p-10f, 0x1p-11f, 0x1p-12f, 0x1p-13f, 0x1p-14f, 0x1p-15f};
    return __builtin_convertvector(bit & static_cast<std::int32_t>(bits), V16) * scale;
}
// The sum of the 16 lanes by halves: (v[0..7] + v[8..15]), then 4, 2 and 1 lanes.
[[gnu::always_inline]] inline float sum16(const V16& v) {
    typedef float V8 __attribute__((vector_size(32)));
    typedef float V4 __attribute__((vector_size(16)));
    const V8 a = __builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7) + __builtin_shufflevector(v, v, 8, 9, 10, 11, 12, 13, 14, 15);
    const V4 b = __builtin_shufflevector(a, a, 0, 1, 2, 3) + __builtin_shufflevector(a, a, 4, 5, 6, 7);
    return (b[0] + b[2]) + (b[1] + b[3]);
}

// The bitwise OR of the 16 lanes (folded by halves; bitwise operations only, which GCC keeps in
// vector registers, unlike 16-lane compares).
[[gnu::always_inline]] inline std::int32_t or16(const V16i& v) {
    typedef std::int32_t V8i __attribute__((vector_size(32)));
    typedef std::int32_t V4i __attribute__((vector_size(16)));
    const V8i a = __builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7) | __builtin_shufflevector(v, v, 8, 9, 10, 11, 12, 13, 14, 15);
    const V4i b = __builtin_shufflevector(a, a, 0, 1, 2, 3) | __builtin_shufflevector(a, a, 4, 5, 6, 7);
    return (b[0] | b[2]) | (b[1] | b[3]);
}

// The minimum and maximum of 16 values and 0 (returns the minimum, the maximum in `hi`) by halving:
// elementwise min/max of the two halves vectorise. The same values as a running std::min/max from
// 0 (min and max are exact; only the sign of a zero result may differ, and the callers only add
// it to or scale it into other values).
[[gnu::always_inline]] inline float min_max16(const float v[16], float& hi) {
    float mn[8], mx[8];
    for (int i = 0; i < 8; ++i) mn[i] = std::min(v[i], v[i + 8]), mx[i] = std::max(v[i], v[i + 8]);
    for (int i = 0; i < 4; ++i) mn[i] = std::min(mn[i], mn[i + 4]), mx[i] = std::max(mx[i], mx[i + 4]);
    for (int i = 0; i < 2; ++i) mn[i] = std::min(mn[i], mn[i + 2]), mx[i] = std::max(mx[i], mx[i + 2]);
    hi = std::max(std::max(mx[0], mx[1]), 0.0f);
    return std::min(std::min(mn[0], mn[1]), 0.0f);
}

// The index of the first minimum of 32 values (std::min_element's answer; the callers' values are
// never NaN): the minimum by halving (vectorises), then the first value equal to it.
[[gnu::always_inline]] inline int argmin32(const float v[32]) {
    float m[16];
    for (int i = 0; i < 16; ++i) m[i] = std::min(v[i], v[i + 16]);
    for (int w = 8; w >= 1; w /= 2)
        for (int i = 0; i < w; ++i) m[i] = std::min(m[i], m[i + w]);
    std::uint32_t eq = 0;
    for (int i = 0; i < 32; ++i) eq |= static_cast<std::uint32_t>(v[i] == m[0]) << i;
    return std::countr_zero(eq);
}

// One (mode, partition): initial endpoints, quantization, indices, error, refinement.
#include "codec/lightmap/bc6h_encoder_fit.inl"

// The two-subset transformed modes, most precise first (11-bit endpoints with 5/4/4-bit deltas
// ... 7-bit with 6-bit deltas), whose delta range holds the quantized initial endpoints of both
// subsets; writes up to `max` of them to `out` and returns how many. Either orientation of subset
// 0 may become the base after evaluate's anchor fix, so a mode fits if its deltas fit from either
// endpoint of subset 0. One 4-lane vector per endpoint (r, g, b, unused), quantized once per
// precision (modes 2-4 share 11 bits, 6-8 share 8): when every value lies in the interior bins
// [S, maxq S), quantize() is the plain floor(u / S); otherwise lane by lane. A delta d fits db
// signed bits iff (d + 2^(db-1)) & ~(2^db - 1) == 0 (lane 3 is masked out by a zero `keep`).
// (4-lane vectors are native to SSE2 and AVX2 alike; GCC builds 16-lane ones from scalars
// through memory, which stalled on store forwarding.)
int fitting_two_subset_modes(const SubsetFit fit[2], int max, int out[9]) {
    typedef float V4 __attribute__((vector_size(16)));
    typedef std::int32_t V4i __attribute__((vector_size(16)));
    const float* ep[4] = {fit[0].a, fit[0].b, fit[1].a, fit[1].b};
    V4 u[4];
    float vmin = ep[0][0], vmax = ep[0][0];
    for (int e = 0; e < 4; ++e) {
        u[e] = V4{ep[e][0], ep[e][1], ep[e][2], 0.0f};
        for (int c = 0; c < 3; ++c) vmin = std::min(vmin, ep[e][c]), vmax = std::max(vmax, ep[e][c]);
    }
    struct Limits {
        V4i add[14], keep[14];  // per mode and channel: 2^(db-1) and ~(2^db - 1); lane 3: 0
    };
    static const Limits lims = [] {
        Limits l{};
        for (int m = 0; m < 14; ++m)
            for (int c = 0; c < 3; ++c) {
                const int db = modes()[static_cast<size_t>(m)].delta_bits[c];
                l.add[m][c] = 1 << (db - 1);
                l.keep[m][c] = ~((1 << db) - 1);
            }
        return l;
    }();
    int count = 0, qbits = -1;
    V4i d0[4] = {}, d1[4] = {};  // each endpoint's delta from subset 0's endpoint a (d0) and b (d1)
    for (const int m : {2, 3, 4, 0, 5, 6, 7, 8, 1}) {
        const Mode& md = modes()[static_cast<size_t>(m)];
        if (md.ep_bits != qbits) {
            qbits = md.ep_bits;
            const float step = static_cast<float>(1 << (16 - qbits));
            const float inv_step = std::bit_cast<float>(static_cast<std::uint32_t>(127 - (16 - qbits)) << 23);
            V4i q[4];
            if (vmin >= step && vmax < static_cast<float>((1 << qbits) - 1) * step) {
                for (int e = 0; e < 4; ++e) q[e] = __builtin_convertvector(u[e] * inv_step, V4i);
            } else {
                for (int e = 0; e < 4; ++e)
                    q[e] = V4i{quantize(ep[e][0], qbits), quantize(ep[e][1], qbits), quantize(ep[e][2], qbits), 0};
            }
            const std::int32_t mask = (1 << qbits) - 1, sign = 1 << (qbits - 1);
            for (int e = 0; e < 4; ++e) {
                d0[e] = (((q[e] - q[0]) & mask) ^ sign) - sign;  // sign_extend(q - base, qbits)
                d1[e] = (((q[e] - q[1]) & mask) ^ sign) - sign;
            }
        }
        const V4i add = lims.add[m], keep = lims.keep[m];
        const V4i f0 = ((d0[0] + add) & keep) | ((d0[1] + add) & keep) | ((d0[2] + add) & keep) | ((d0[3] + add) & keep);
        const V4i f1 = ((d1[0] + add) & keep) | ((d1[1] + add) & keep) | ((d1[2] + add) & keep) | ((d1[3] + add) & keep);
        if ((f0[0] | f0[1] | f0[2]) != 0 && (f1[0] | f1[1] | f1[2]) != 0) continue;
        out[count++] = m;
        if (count == max) break;
    }
    return count;
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

// Index selection for try_mode: projected (kProject) or searched (kSearch), see evaluate.
// (Projected indices during default's refinement rounds and one search on the best endpoints at
// the end was tried: +0.02 dB but 4 % more instructions; the search exits early, projection not.)
enum class Indices { kProject, kSearch };

// Fit one (mode, partition) with `iters` refinement rounds; updates `best`.
void try_mode(const Target& t, int mode_i, int partition, const SubsetFit init[2], int iters, Encoded& best,
              Indices ind = Indices::kSearch) {
    SubsetFit fit[2] = {init[0], init[1]};
    Encoded local;
    const bool search = ind == Indices::kSearch;
    evaluate(t, mode_i, partition, fit, local, search);
    for (int it = 0; it < iters; ++it) {
        refine(t, local, fit);
        const std::int64_t before = local.err;
        evaluate(t, mode_i, partition, fit, local, search);
        if (local.err >= before) break;
    }
    if (local.err < best.err) best = local;
}

// The partition screening: scores of all 32 partitions and the subsets' lines.
#include "codec/lightmap/bc6h_encoder_partition.inl"

// float_to_uf16 for a whole block, branch-free for the common case so that it vectorises: for
// f >= 2^-14 (a normal half or above) the half bits are the float bits rebased by 112 exponent
// steps and shifted right 13 with round-to-nearest-even (add 0xFFF + the lowest kept bit; a carry
// into the exponent is the correct rounding up), clamped to 0x7BFF (also catches +inf). NaN,
// zero and negatives give 0. Only 0 < f < 2^-14 (subnormal halves) takes float_to_uf16; the
// constant-block test checks every half value and random floats against float_to_uf16.
void make_target(const float rgb[16][3], Target& t) {
    std::uint32_t x[48];
    std::memcpy(x, rgb, sizeof x);
    const float* f = &rgb[0][0];
    int h[48];
    for (int k = 0; k < 48; ++k) {
        const std::uint32_t r = (x[k] - (112u << 23) + 0xFFFu + ((x[k] >> 13) & 1u)) >> 13;
        h[k] = f[k] >= 0x1p-14f ? static_cast<int>(std::min(r, 0x7BFFu)) : 0;
    }
    // 0 < f < 2^-14 on the bits: 1 <= x <= 0x387FFFFF (negatives and NaNs have larger bits as
    // unsigned), an integer compare that vectorises.
    int small = 0;
    for (int k = 0; k < 48; ++k) small |= (x[k] - 1u) < 0x387FFFFFu;
    if (small)
        for (int k = 0; k < 48; ++k)
            if (f[k] > 0 && f[k] < 0x1p-14f) h[k] = float_to_uf16(f[k]);
    // Channel-major through locals (stores to t would otherwise block vectorising the loops).
    int hc[48];  // hc[16 c + i]
    for (int i = 0; i < 16; ++i)
        for (int c = 0; c < 3; ++c) hc[16 * c + i] = h[3 * i + c];
    float uc[48];
    for (int k = 0; k < 48; ++k) uc[k] = static_cast<float>(hc[k]) * (64.0f / 31.0f);
    V16i differ = {};
    for (int c = 0; c < 3; ++c) {
        V16i v;
        std::memcpy(&v, hc + 16 * c, sizeof v);
        differ |= v ^ hc[16 * c];
    }
    std::memcpy(t.h, hc, sizeof hc);
    std::memcpy(t.u, uc, sizeof uc);
    t.constant = or16(differ) == 0;
}

// A constant block exactly, in mode 14 (code 01111: 16-bit endpoints, 4-bit deltas): both
// endpoints e = ceil(64 h / 31), all deltas and indices 0. 16-bit endpoints are not rescaled by
// unquantize, interpolating e with itself gives e, and the output (31 e) >> 6 = h because
// 64 h <= 31 e < 64 h + 31 (e <= 65535 for every h <= 0x7BFF). Zero error, so no mode can beat it.
Encoded constant_block(const Target& t) {
    Encoded e;
    e.mode = 13;
    for (int c = 0; c < 3; ++c) e.q[0][c] = e.q[1][c] = (64 * t.h[c][0] + 30) / 31;
    e.err = 0;
    return e;
}

// The 128 block bits in two words (bit k of the stream = bit k % 64 of word k / 64), stored
// little-endian; the header from the mode's pack plan.
void pack(const Encoded& e, std::uint8_t out[16]) {
    const Mode& md = modes()[static_cast<size_t>(e.mode)];
    const PackPlan& plan = pack_plans()[static_cast<size_t>(e.mode)];
    const int ns = md.two_subsets ? 2 : 1;
    std::uint32_t stored[12] = {};  // indexed by Seg::field = endpoint * 3 + channel
    for (int i = 0; i < 2 * ns; ++i)
        for (int c = 0; c < 3; ++c)
            stored[3 * i + c] = static_cast<std::uint32_t>(
                (md.transformed && i > 0) ? ((e.q[i][c] - e.q[0][c]) & ((1 << md.delta_bits[c]) - 1)) : e.q[i][c]);
    std::uint64_t w[2] = {md.code, 0};
    for (int k = 0; k < plan.nops; ++k) {
        const PackOp& op = plan.ops[static_cast<size_t>(k)];
        w[op.word] |= static_cast<std::uint64_t>((stored[op.field] >> op.shift) & op.mask) << op.pos;
    }
    // The partition (5 bits) and the indices (63 or 46 bits) gathered into one word, then placed
    // after the header, which ends at bit 65 (one subset) or 77 (two subsets, then the partition):
    // in both cases the rest of the block fills word 1 exactly.
    const int ib = md.two_subsets ? 3 : 4;
    const int anchor2 = md.two_subsets ? kAnchor2[e.partition] : -1;
    std::uint64_t iv = 0;
    int n = 0;
    if (md.two_subsets) iv = static_cast<std::uint64_t>(e.partition), n = 5;
    for (int i = 0; i < 16; ++i) {
        iv |= static_cast<std::uint64_t>(e.idx[i]) << n;
        n += (i == 0 || i == anchor2) ? ib - 1 : ib;
    }
    const int pos = plan.header_bits;  // >= 64 in every mode, and pos + n == 128
    w[1] |= iv << (pos - 64);
    for (int k = 0; k < 16; ++k) out[k] = static_cast<std::uint8_t>(w[k >> 3] >> (8 * (k & 7)));
}


void encode_block_impl(const float rgb[16][3], Quality quality, std::uint8_t out[16]) {
    Target t;
    make_target(rgb, t);
    if (t.constant && quality != Quality::kMode11) {
        pack(constant_block(t), out);
        return;
    }
    Encoded best;
    SubsetFit one[2];
    float axis[3];
    initial_endpoints(t, 0xFFFF, one[0].a, one[0].b, axis);
    one[1] = one[0];
    // Two-subset candidates for partition p: each subset's principal-axis line, and the modes to
    // try, most precise first (11-bit endpoints with 5/4/4 deltas ... 7-bit with 6-bit deltas),
    // those whose delta range holds the initial endpoints; the absolute 6-bit mode if none does.
    PartitionMoments pm;
    auto two_subsets = [&](int p, int max_modes, int iters, Indices search) {
        SubsetFit two[2];
        fit_partition(pm, p, axis, two);
        int list[9];
        const int count = fitting_two_subset_modes(two, max_modes, list);
        for (int k = 0; k < count; ++k) try_mode(t, list[k], p, two, iters, best, search);
        if (count == 0) try_mode(t, 9, p, two, iters, best, search);
    };
    // The default search (also the first candidate set of exhaustive, which so stays a superset).
    auto run_default = [&] {
        // One subset: the most precise fitting mode (mode 11 if none fits), up to 3
        // refinements (they stop when the error stops dropping).
        const int iters = 3;
        const int dm = best_delta_mode(one[0]);
        try_mode(t, dm >= 0 ? dm : 10, 0, one, iters, best, Indices::kSearch);
        // Two subsets only for blocks above ~3 half ULPs rms per value (tuned with bench_bc6h).
        if (best.err <= 48 * 9) return;
        // Screen the kScreen partitions whose subsets are closest to lines with one cheap
        // evaluation each (most precise fitting mode, projected indices, no refinement), then
        // fit the best of them properly (index search, up to 3 refinements). Tuned with
        // bench_bc6h: screening 6 and refining 1 is as good as refining 3 unscreened (the old
        // default) at about half the time; refining 2 or trying the second fitting mode
        // gained <= 0.02 dB.
        constexpr int kScreen = 6, kRefine = 1;
        // (The 2D score of partition_scores_2d: 1.5 % fewer instructions than the 3D one for
        // <= 0.003 dB.)
        float score[32];
        partition_scores_2d(t, axis, score, pm);
        int order[32];
        for (int p = 0; p < 32; ++p) order[p] = p;
        std::partial_sort(order, order + kScreen, order + 32,
                          [&](int a, int b) { return score[a] < score[b] || (score[a] == score[b] && a < b); });
        // One Encoded for all screens: each evaluation stops once it reaches the best screen so
        // far (its error then is >= that best, so the minimum and its first index are unchanged).
        std::int64_t screen_err[kScreen];
        Encoded screen;
        for (int k = 0; k < kScreen; ++k) {
            const int p = order[k];
            partition_moments(p, pm);
            SubsetFit two[2];
            fit_partition(pm, p, axis, two);
            int list[1];
            const int m = fitting_two_subset_modes(two, 1, list) ? list[0] : 9;
            screen_err[k] = evaluate(t, m, p, two, screen, false);
        }
        int rank[kScreen];
        for (int k = 0; k < kScreen; ++k) rank[k] = k;
        std::partial_sort(rank, rank + kRefine, rank + kScreen, [&](int a, int b) {
            return screen_err[a] < screen_err[b] || (screen_err[a] == screen_err[b] && a < b);
        });
        for (int k = 0; k < kRefine; ++k) two_subsets(order[rank[k]], 1, iters, Indices::kSearch);
    };
    switch (quality) {
        case Quality::kMode11:
            try_mode(t, 10, 0, one, 1, best);
            break;
        case Quality::kFast: {
            // One subset: only the most precise mode whose delta range holds the span (a more
            // precise mode that fits cannot lose to a coarser one), mode 11 when none does; one
            // evaluation with projected indices, no refinement (refining costs ~2x the time for
            // ~0.4 dB, measured with bench_bc6h).
            const int dm = best_delta_mode(one[0]);
            try_mode(t, dm >= 0 ? dm : 10, 0, one, 0, best, Indices::kProject);
            // Blocks with a large error (> 16 half ULPs rms per value): the single best-scoring
            // partition with its most precise fitting mode, evaluated the same way. (Tuned with
            // bench_bc6h: from 6 ULPs the maps gain 0.01 dB, the lightmaps 0.3 dB, for 1.5x the
            // time on lightmaps; from 12 ULPs the maps gain 0.01 dB and
            // the lightmaps 0.27 dB for 4 % / 15 % more instructions per pixel; from 20 ULPs the
            // lightmaps lose another 0.23 dB, beyond the 1.5 dB bound. Guessing the partition
            // from a split along the principal axis instead of scoring was 1.1 dB worse.)
            if (best.err > 48 * 256) {
                float score[32];
                partition_scores_2d(t, axis, score, pm);
                const int p = argmin32(score);
                partition_moments(p, pm);
                two_subsets(p, 1, 0, Indices::kProject);
            }
            break;
        }
        case Quality::kDefault:
            run_default();
            break;
        case Quality::kExhaustive: {
            // Default's candidates (so that exhaustive is never worse, whichever index selection
            // default uses), then every one-subset mode, every partition with every two-subset mode.
            run_default();
            const int iters = 4;
            for (int m = 10; m < 14; ++m) try_mode(t, m, 0, one, iters, best);
            float score[32];
            partition_scores(t, axis, score, pm);
            // Both initial line fits per partition: the per-subset power iteration from (1, 1, 1)
            // (initial_endpoints) and fit_partition's (what fast and default start from), so that
            // exhaustive stays a superset of default's candidates (tested per block) and never
            // loses to a search from the first alone.
            for (int p = 0; p < 32; ++p) {
                SubsetFit two[2];
                initial_endpoints(t, static_cast<std::uint16_t>(~kPartition[p]), two[0].a, two[0].b);
                initial_endpoints(t, kPartition[p], two[1].a, two[1].b);
                for (int m = 0; m < 10; ++m) try_mode(t, m, p, two, iters, best);
                fit_partition(pm, p, axis, two);
                for (int m = 0; m < 10; ++m) try_mode(t, m, p, two, iters, best);
            }
            break;
        }
    }
    pack(best, out);
}
