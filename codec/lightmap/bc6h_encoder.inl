// zhc/codec/lightmap/bc6h_encoder.inl — the BC6H (unsigned, BC6H_UF16) block encoder. Included twice by
// codec/lightmap/bc6h.cpp: once for baseline x86-64 and once under an AVX2 target pragma, each copy in its
// own namespace; both perform the same IEEE operations in the same order, so they write the same
// bytes (docs/lightmap-formats.md "Two builds of the encoder, one output").
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

// Nearest quantized endpoint to u, in closed form (checked equal to the search over q0 - 1, q0,
// q0 + 1 it replaced, ties included, on a 1/8 grid of [-10, 65600) for every precision). Below 15
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

// Endpoints of the line that best fits the subset's texels (principal axis by power iteration),
// spanning the extreme projections. In the unquantized domain.
// Branch-free over the mask (texels outside weigh 0), one pass for the moments: coordinates are
// taken relative to texel 0, which bounds them by the block's range (no cancellation in
// E[x x] - E[x] E[x] for bright blocks), loops over the texels vectorise.
void initial_endpoints(const Target& t, std::uint16_t mask, float a[3], float b[3], float axis_out[3] = nullptr) {
    const float n = static_cast<float>(std::popcount(static_cast<unsigned>(mask)));
    if (n == 0) {
        for (int c = 0; c < 3; ++c) a[c] = b[c] = 0;
        return;
    }
    const V16 in = mask16(mask);
    V16 d[3];
    for (int c = 0; c < 3; ++c) d[c] = (load16(t.u[c]) - t.u[c][0]) * in;
    const float s[3] = {sum16(d[0]), sum16(d[1]), sum16(d[2])};
    const float m2[6] = {sum16(d[0] * d[0]), sum16(d[0] * d[1]), sum16(d[0] * d[2]),
                         sum16(d[1] * d[1]), sum16(d[1] * d[2]), sum16(d[2] * d[2])};
    const float inv_n = 1.0f / n;
    const float mr[3] = {s[0] * inv_n, s[1] * inv_n, s[2] * inv_n};  // mean relative to texel 0
    const float cov[6] = {m2[0] - s[0] * mr[0], m2[1] - s[0] * mr[1], m2[2] - s[0] * mr[2],
                          m2[3] - s[1] * mr[1], m2[4] - s[1] * mr[2], m2[5] - s[2] * mr[2]};
    float ax[3] = {1, 1, 1};
    for (int it = 0; it < 4; ++it) {
        const float x = cov[0] * ax[0] + cov[1] * ax[1] + cov[2] * ax[2];
        const float y = cov[1] * ax[0] + cov[3] * ax[1] + cov[4] * ax[2];
        const float z = cov[2] * ax[0] + cov[4] * ax[1] + cov[5] * ax[2];
        const float m = std::max({std::abs(x), std::abs(y), std::abs(z)});
        if (!(m > 0)) break;
        const float im = 1.0f / m;
        ax[0] = x * im, ax[1] = y * im, ax[2] = z * im;
    }
    if (axis_out) std::copy(ax, ax + 3, axis_out);
    const float inv_len2 = 1.0f / (ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    float proj[16];
    store16(proj, ((d[0] - mr[0]) * ax[0] + (d[1] - mr[1]) * ax[1] + (d[2] - mr[2]) * ax[2]) * in);
    float hi;  // texels outside the mask project to 0, inside [lo, hi] already
    float lo = min_max16(proj, hi);
    lo *= inv_len2, hi *= inv_len2;
    for (int c = 0; c < 3; ++c) {
        const float mean = t.u[c][0] + mr[c];
        a[c] = std::clamp(mean + lo * ax[c], 0.0f, 65535.0f);
        b[c] = std::clamp(mean + hi * ax[c], 0.0f, 65535.0f);
    }
}


// Quantize endpoints for mode `md` (resolving the delta constraints by clamping), assign indices
// (anchor texels restricted to the first half) and measure the error exactly.
//
// Index selection: `search` = project on the palette axis, then test the nearest index and its two
// neighbours exactly. Without `search` (fast quality): the index whose weight is nearest to the
// projection (kNearest, computed by nearest_index). The palette points lie on a line up to the decoder's integer
// rounding (< 1 half ULP), and for collinear points the squared distance is |d|^2 (t - t*)^2 +
// const, so the nearest weight to the projection t* is the best index up to that rounding.
// Compiled per subset count NS (= md.two_subsets + 1) and index selection, so that the one-subset
// loops carry no second subset and no selects (evaluate below picks the instance).
template <int NS, bool search>
std::int64_t evaluate_ns(const Target& t, int mode_i, int partition, SubsetFit fit[2], Encoded& out) {
    const Mode& md = modes()[static_cast<size_t>(mode_i)];
    constexpr int ns = NS;
    constexpr int ib = NS == 2 ? 3 : 4, n = 1 << ib;
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
            pa += d * (t.u[c][i] - static_cast<float>(unquantize(q[2 * s][c], md.ep_bits)));
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
    // The palette's end points (weights 0 and 64): the projection's origin and axis.
    int pal0[2][3], pal1[2][3];
    for (int s = 0; s < ns; ++s)
        for (int c = 0; c < 3; ++c) {
            const int ua = unquantize(q[2 * s][c], md.ep_bits), ub = unquantize(q[2 * s + 1][c], md.ep_bits);
            pal0[s][c] = finish(ua, ub, 0), pal1[s][c] = finish(ua, ub, 64);
        }
    // Index per texel: project onto the palette's axis, then test the nearest index and its two
    // neighbours exactly (the palette is linear in the weight up to integer rounding, and the
    // weights are within 1/64 of uniform, so the best index is among those three).
    float axis[2][3], inv_len2[2];
    for (int s = 0; s < ns; ++s) {
        float l2 = 0;
        for (int c = 0; c < 3; ++c) {
            axis[s][c] = static_cast<float>(pal1[s][c] - pal0[s][c]);
            l2 += axis[s][c] * axis[s][c];
        }
        inv_len2[s] = l2 > 0 ? static_cast<float>(search ? n - 1 : 128) / l2 : 0.0f;
    }
    std::int64_t err = 0;
    std::uint8_t idx[16];
    {
        // Straight-line passes over the 16 texels that vectorise (no early exit; callers only use
        // the error when it wins, and the screening in encode_block only its minimum). Per texel:
        // both subsets' projections, the texel's one selected, the candidate indices, and their
        // palette entries computed instead of looked up: the weight w_j = round(64 j / (n - 1))
        // (the format's tables; 64 j / (n - 1) is never within 1/30 of a half-integer, so the
        // float product rounds correctly), and finish(a, b, w) in floats, exact because every
        // intermediate is an integer below 2^24 (a, b <= 65535). Squared differences are < 2^30,
        // their sum over 3 channels < 2^32: unsigned 32-bit.
        float pr[2][16];
        for (int ss = 0; ss < ns; ++ss)
            for (int i = 0; i < 16; ++i)
                pr[ss][i] = (static_cast<float>(t.h[0][i] - pal0[ss][0]) * axis[ss][0] +
                             static_cast<float>(t.h[1][i] - pal0[ss][1]) * axis[ss][1] +
                             static_cast<float>(t.h[2][i] - pal0[ss][2]) * axis[ss][2]) * inv_len2[ss];
        float ua[2][3], ub[2][3];
        for (int ss = 0; ss < ns; ++ss)
            for (int c = 0; c < 3; ++c) {
                ua[ss][c] = static_cast<float>(unquantize(q[2 * ss][c], md.ep_bits));
                ub[ss][c] = static_cast<float>(unquantize(q[2 * ss + 1][c], md.ep_bits));
            }
        int limm1[16];
        for (int i = 0; i < 16; ++i) limm1[i] = n - 1;
        limm1[0] = n / 2 - 1;  // texel 0 is subset 0's anchor (subset 0 in every partition)
        if constexpr (ns == 2) limm1[anchor[1]] = n / 2 - 1;
        const float wscale = 64.0f / static_cast<float>(n - 1);
        // Per texel its subset's endpoints and projection (selects, no branches).
        float A[3][16], B[3][16], proj[16];
        for (int i = 0; i < 16; ++i) {
            if constexpr (ns == 2) {
                const int one = pmask >> i & 1;
                proj[i] = one ? pr[1][i] : pr[0][i];
                for (int c = 0; c < 3; ++c) A[c][i] = one ? ua[1][c] : ua[0][c], B[c][i] = one ? ub[1][c] : ub[0][c];
            } else {
                proj[i] = pr[0][i];
                for (int c = 0; c < 3; ++c) A[c][i] = ua[0][c], B[c][i] = ub[0][c];
            }
        }
        std::uint32_t errs[16];
        int bidx[16];
        auto cand = [&](int i, int j) {
            const float w = static_cast<float>(ramp_weight(j, wscale));
            std::uint32_t e = 0;
            for (int c = 0; c < 3; ++c) {
                const int v = static_cast<int>((A[c][i] * (64.0f - w) + B[c][i] * w + 32.0f) * (1.0f / 64.0f));
                const int d = ((v * 31) >> 6) - t.h[c][i];
                e += static_cast<std::uint32_t>(d * d);
            }
            return e;
        };
        if constexpr (search) {
            for (int i = 0; i < 16; ++i) {
                int j0 = static_cast<int>(proj[i] + 0.5f);
                j0 = j0 < 0 ? 0 : j0;
                j0 = j0 > limm1[i] ? limm1[i] : j0;
                const int jl = j0 - 1 < 0 ? 0 : j0 - 1, jh = j0 + 1 > limm1[i] ? limm1[i] : j0 + 1;
                const std::uint32_t el = cand(i, jl), em = cand(i, j0), eh = cand(i, jh);
                std::uint32_t be = el;
                int bj = jl;
                bj = em < be ? j0 : bj;
                be = em < be ? em : be;
                bj = eh < be ? jh : bj;
                be = eh < be ? eh : be;
                errs[i] = be;
                bidx[i] = bj;
            }
        } else {
            // proj = 128 t*, clamped to the palette; the nearest weight's index (kNearest in
            // arithmetic); the anchor's MSB-0 limit applies after.
            for (int i = 0; i < 16; ++i) {
                // |proj| < 2^24 (128 |texel - origin| / |axis| with |axis| >= 1): no int overflow.
                int k = static_cast<int>(proj[i] + 0.5f);
                k = k < 0 ? 0 : k;
                k = k > 128 ? 128 : k;
                int j = nearest_index(k, n, wscale);
                j = j > limm1[i] ? limm1[i] : j;
                errs[i] = cand(i, j);
                bidx[i] = j;
            }
        }
        for (int i = 0; i < 16; ++i) err += errs[i], idx[i] = static_cast<std::uint8_t>(bidx[i]);
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

std::int64_t evaluate(const Target& t, int mode_i, int partition, SubsetFit fit[2], Encoded& out, bool search = true) {
    if (modes()[static_cast<size_t>(mode_i)].two_subsets)
        return search ? evaluate_ns<2, true>(t, mode_i, partition, fit, out) : evaluate_ns<2, false>(t, mode_i, partition, fit, out);
    return search ? evaluate_ns<1, true>(t, mode_i, partition, fit, out) : evaluate_ns<1, false>(t, mode_i, partition, fit, out);
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
            for (int c = 0; c < 3; ++c) ra[c] += v * t.u[c][i], rb[c] += w * t.u[c][i];
        }
        const float det = aa * bb - ab * ab;
        if (std::abs(det) < 1e-6f) continue;
        for (int c = 0; c < 3; ++c) {
            fit[s].a[c] = std::clamp((bb * ra[c] - ab * rb[c]) / det, 0.0f, 65535.0f);
            fit[s].b[c] = std::clamp((aa * rb[c] - ab * ra[c]) / det, 0.0f, 65535.0f);
        }
    }
}

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

// Per-partition constants for partition_scores, laid out partition-minor so that the loops over
// the 32 partitions auto-vectorise: in1[i][p] = 1 if texel i is in subset 1 of partition p.
struct PartitionTables {
    float in1[16][32];
    float n0[32], n1[32];
};
const PartitionTables& partition_tables() {
    static const PartitionTables tb = [] {
        PartitionTables t{};
        for (int p = 0; p < 32; ++p) {
            int n1 = 0;
            for (int i = 0; i < 16; ++i) {
                const int b = kPartition[p] >> i & 1;
                t.in1[i][p] = static_cast<float>(b);
                n1 += b;
            }
            t.n1[p] = static_cast<float>(n1);
            t.n0[p] = static_cast<float>(16 - n1);
        }
        return t;
    }();
    return tb;
}

// Cheap score of every partition: for each subset the squared residual orthogonal to its
// principal axis (trace of the subset covariance minus its largest eigenvalue: what a line fit
// cannot represent). Moments are taken about the block mean (no cancellation for bright blocks);
// subset 1's sums are one masked sum per partition (a 16 x 32 product with the mask table),
// subset 0's are the block's minus subset 1's. The largest eigenvalue is the Rayleigh quotient
// after two power steps from the block's principal axis `ax0`: v1 = C ax0, v2 = C v1,
// lambda ~ (v1 . v2) / (v1 . v1), a lower bound that converges quadratically in the power steps.
// Per-partition moments kept from partition_scores for fit_partition: texel coordinates are
// x_i = (u_i - mean) / 256 (u domain, about the block mean); m[k][i] = texel i's moment k of
// (x, y, z, xx, xy, xz, yy, yz, zz) (so m[0..2] are the coordinates); total = their sums over the
// block; s1[k][p] = the same sums over subset 1 of partition p.
struct PartitionMoments {
    float mean[3];
    float m[9][16];
    float total[9];
    float s1[9][32];
};

// Sums of one per-texel moment over subset 1 of all 32 partitions: out[p] = sum_i in1[i][p] m[i],
// added in sum16's order (texel i + texel i + 8, then by halves), each step for all 32
// partitions at once (8 vector registers per step; the halving shortens the dependency chains).
inline void subset1_sums(const PartitionTables& tb, const float m[16], float out[32]) {
    float t8[8][32];
    for (int i = 0; i < 8; ++i)
        for (int p = 0; p < 32; ++p) t8[i][p] = tb.in1[i][p] * m[i] + tb.in1[i + 8][p] * m[i + 8];
    for (int i = 0; i < 4; ++i)
        for (int p = 0; p < 32; ++p) t8[i][p] += t8[i + 4][p];
    for (int p = 0; p < 32; ++p) out[p] = (t8[0][p] + t8[2][p]) + (t8[1][p] + t8[3][p]);
}

// The block part of PartitionMoments: mean, the per-texel moments m and their totals (summed by
// halves, sum16).
void block_moments(const Target& t, PartitionMoments& pm) {
    V16 x[3];
    for (int c = 0; c < 3; ++c) {
        const V16 u = load16(t.u[c]);
        const float mean = sum16(u) * (1.0f / 16);
        pm.mean[c] = mean;
        x[c] = (u - mean) * (1.0f / 256);
    }
    const V16 m[9] = {x[0], x[1], x[2], x[0] * x[0], x[0] * x[1], x[0] * x[2], x[1] * x[1], x[1] * x[2], x[2] * x[2]};
    for (int k = 0; k < 9; ++k) store16(pm.m[k], m[k]), pm.total[k] = sum16(m[k]);
}

// Subset 1's moment sums pm.s1[.][p] for one partition, bit-identical to partition_scores' (the
// same products, mask16's lanes being the table's 0/1 values, added in the same order), so
// fit_partition gives the same lines whichever function filled them.
void partition_moments(int p, PartitionMoments& pm) {
    const V16 in = mask16(kPartition[p]);
    for (int k = 0; k < 9; ++k) pm.s1[k][p] = sum16(in * load16(pm.m[k]));
}

void partition_scores(const Target& t, const float ax0[3], float score[32], PartitionMoments& pm) {
    const PartitionTables& tb = partition_tables();
    float* total = pm.total;
    auto& s1 = pm.s1;
    block_moments(t, pm);
    for (int k = 0; k < 9; ++k) subset1_sums(tb, pm.m[k], s1[k]);
    const float v0x = ax0[0], v0y = ax0[1], v0z = ax0[2];
    // Straight-line per partition (no branches) so that the loop vectorises.
    auto residual = [=](float a0, float a1, float a2, float a3, float a4, float a5, float a6, float a7, float a8,
                        float inv) {
        const float c0 = a3 - a0 * a0 * inv, c1 = a4 - a0 * a1 * inv, c2 = a5 - a0 * a2 * inv,
                    c3 = a6 - a1 * a1 * inv, c4 = a7 - a1 * a2 * inv, c5 = a8 - a2 * a2 * inv;
        const float x1 = c0 * v0x + c1 * v0y + c2 * v0z, y1 = c1 * v0x + c3 * v0y + c4 * v0z,
                    z1 = c2 * v0x + c4 * v0y + c5 * v0z;
        const float x2 = c0 * x1 + c1 * y1 + c2 * z1, y2 = c1 * x1 + c3 * y1 + c4 * z1, z2 = c2 * x1 + c4 * y1 + c5 * z1;
        const float n11 = x1 * x1 + y1 * y1 + z1 * z1, n12 = x1 * x2 + y1 * y2 + z1 * z2;
        const float lambda = n12 / std::max(n11, 1e-30f);
        return std::max(0.0f, c0 + c3 + c5 - lambda);
    };
    for (int p = 0; p < 32; ++p) {
        const float r1 = residual(s1[0][p], s1[1][p], s1[2][p], s1[3][p], s1[4][p], s1[5][p], s1[6][p], s1[7][p],
                                  s1[8][p], 1.0f / tb.n1[p]);
        const float r0 = residual(total[0] - s1[0][p], total[1] - s1[1][p], total[2] - s1[2][p], total[3] - s1[3][p],
                                  total[4] - s1[4][p], total[5] - s1[5][p], total[6] - s1[6][p], total[7] - s1[7][p],
                                  total[8] - s1[8][p], 1.0f / tb.n0[p]);
        score[p] = r0 + r1;
    }
}

// A cheaper score of every partition (fast and default): the texels projected onto the plane of
// the block's two principal axes e1, e2 (t = x . e1, s = x . e2), and per subset the residual of
// the best line in that plane, in closed form: the subset's 2 x 2 covariance [[a, b], [b, c]] has
// the eigenvalues (a + c) / 2 +- sqrt(((a - c) / 2)^2 + b^2), the residual is the smaller one.
// 5 moment sums per partition instead of 9 and no power steps; it ignores the spread along the
// block's least axis e3 (the smallest of the three by construction). e1 is the block's axis ax0,
// e2 the principal axis of the block covariance restricted to the plane orthogonal to e1.
// Fills pm's block part (for partition_moments); not pm.s1.
void partition_scores_2d(const Target& t, const float ax0[3], float score[32], PartitionMoments& pm) {
    const PartitionTables& tb = partition_tables();
    block_moments(t, pm);
    const float* T = pm.total;  // block sums about the mean: T[3..8] is the covariance (times 16)
    float e1[3] = {ax0[0], ax0[1], ax0[2]};
    {
        const float l2 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
        const float il = l2 > 0 ? 1.0f / std::sqrt(l2) : 0.0f;
        for (float& v : e1) v *= il;
    }
    // u: the coordinate axis least aligned with e1, made orthogonal to it; v = e1 x u.
    const int k = (std::abs(e1[0]) <= std::abs(e1[1]) && std::abs(e1[0]) <= std::abs(e1[2])) ? 0
                  : (std::abs(e1[1]) <= std::abs(e1[2]))                                  ? 1
                                                                                          : 2;
    float u[3] = {-e1[k] * e1[0], -e1[k] * e1[1], -e1[k] * e1[2]};
    u[k] += 1.0f;
    {
        const float l2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
        const float il = l2 > 0 ? 1.0f / std::sqrt(l2) : 0.0f;
        for (float& x : u) x *= il;
    }
    const float v[3] = {e1[1] * u[2] - e1[2] * u[1], e1[2] * u[0] - e1[0] * u[2], e1[0] * u[1] - e1[1] * u[0]};
    auto quad = [&](const float p[3], const float q[3]) {  // p^T C q
        return p[0] * (T[3] * q[0] + T[4] * q[1] + T[5] * q[2]) + p[1] * (T[4] * q[0] + T[6] * q[1] + T[7] * q[2]) +
               p[2] * (T[5] * q[0] + T[7] * q[1] + T[8] * q[2]);
    };
    const float a = quad(u, u), b = quad(u, v), c = quad(v, v);
    const float lam = 0.5f * (a + c) + std::sqrt(0.25f * (a - c) * (a - c) + b * b);
    // Eigenvector for lam: (b, lam - a) or (lam - c, b), whichever is longer (both vanish only
    // when the plane's covariance is isotropic: then any direction, u).
    float w0 = b, w1 = lam - a;
    if (std::abs(lam - c) + std::abs(b) > std::abs(b) + std::abs(lam - a)) w0 = lam - c, w1 = b;
    if (w0 == 0 && w1 == 0) w0 = 1;
    float e2[3] = {w0 * u[0] + w1 * v[0], w0 * u[1] + w1 * v[1], w0 * u[2] + w1 * v[2]};
    {
        const float l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
        const float il = l2 > 0 ? 1.0f / std::sqrt(l2) : 0.0f;
        for (float& x : e2) x *= il;
    }
    float m5[5][16];
    float tot[5];
    for (int i = 0; i < 16; ++i) {
        const float ti = pm.m[0][i] * e1[0] + pm.m[1][i] * e1[1] + pm.m[2][i] * e1[2];
        const float si = pm.m[0][i] * e2[0] + pm.m[1][i] * e2[1] + pm.m[2][i] * e2[2];
        m5[0][i] = ti, m5[1][i] = si, m5[2][i] = ti * ti, m5[3][i] = ti * si, m5[4][i] = si * si;
    }
    for (int q = 0; q < 5; ++q) tot[q] = sum16(load16(m5[q]));
    float s1[5][32];
    for (int q = 0; q < 5; ++q) subset1_sums(tb, m5[q], s1[q]);
    // Residual per subset: (a + c) / 2 - sqrt(((a - c) / 2)^2 + b^2); the square roots in a
    // separate pass over a vector of arguments >= 0.
    float half_tr[64], disc[64];
    for (int p = 0; p < 32; ++p) {
        const float i1 = 1.0f / tb.n1[p], i0 = 1.0f / tb.n0[p];
        const float t1 = s1[0][p], q1 = s1[1][p];
        const float a1 = s1[2][p] - t1 * t1 * i1, b1 = s1[3][p] - t1 * q1 * i1, c1 = s1[4][p] - q1 * q1 * i1;
        const float t0 = tot[0] - t1, q0 = tot[1] - q1;
        const float a0 = (tot[2] - s1[2][p]) - t0 * t0 * i0, b0 = (tot[3] - s1[3][p]) - t0 * q0 * i0,
                    c0 = (tot[4] - s1[4][p]) - q0 * q0 * i0;
        half_tr[p] = 0.5f * (a1 + c1), disc[p] = 0.25f * (a1 - c1) * (a1 - c1) + b1 * b1;
        half_tr[32 + p] = 0.5f * (a0 + c0), disc[32 + p] = 0.25f * (a0 - c0) * (a0 - c0) + b0 * b0;
    }
    float res[64];
    for (int j = 0; j < 64; ++j) res[j] = std::max(0.0f, half_tr[j] - std::sqrt(disc[j]));
    for (int p = 0; p < 32; ++p) score[p] = res[p] + res[32 + p];
}

// Both subsets' lines for partition p from the moments partition_scores kept (instead of two
// initial_endpoints passes): subset mean and covariance from the sums, principal axis by three
// power steps from the block's axis `ax0` (the subset is a point if they vanish: any axis),
// endpoints at the extreme projections of the subset's texels.
void fit_partition(const PartitionMoments& pm, int p, const float ax0[3], SubsetFit two[2]) {
    const PartitionTables& tb = partition_tables();
    for (int s = 0; s < 2; ++s) {
        float a[9];
        for (int k = 0; k < 9; ++k) a[k] = s ? pm.s1[k][p] : pm.total[k] - pm.s1[k][p];
        const float inv = 1.0f / (s ? tb.n1[p] : tb.n0[p]);
        const float m[3] = {a[0] * inv, a[1] * inv, a[2] * inv};
        const float c0 = a[3] - a[0] * m[0], c1 = a[4] - a[0] * m[1], c2 = a[5] - a[0] * m[2], c3 = a[6] - a[1] * m[1],
                    c4 = a[7] - a[1] * m[2], c5 = a[8] - a[2] * m[2];
        float ax[3] = {ax0[0], ax0[1], ax0[2]};
        for (int it = 0; it < 3; ++it) {
            const float x = c0 * ax[0] + c1 * ax[1] + c2 * ax[2];
            const float y = c1 * ax[0] + c3 * ax[1] + c4 * ax[2];
            const float z = c2 * ax[0] + c4 * ax[1] + c5 * ax[2];
            const float mx = std::max({std::abs(x), std::abs(y), std::abs(z)});
            if (!(mx > 0)) break;
            const float im = 1.0f / mx;
            ax[0] = x * im, ax[1] = y * im, ax[2] = z * im;
        }
        const float l2 = ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2];
        const float inv_l2 = l2 > 0 ? 1.0f / l2 : 0.0f;
        // Membership from the mask bits: the same 0/1 values as tb.in1[i][p] and 1 - tb.in1[i][p].
        const V16 in = mask16(s ? kPartition[p] : ~static_cast<unsigned>(kPartition[p]));
        float proj[16];
        store16(proj, ((load16(pm.m[0]) - m[0]) * ax[0] + (load16(pm.m[1]) - m[1]) * ax[1] +
                       (load16(pm.m[2]) - m[2]) * ax[2]) * in);
        float hi_out;
        // members' projections about their mean straddle 0 (non-members project to 0)
        float lo = min_max16(proj, hi_out);
        float hi = hi_out;
        lo *= inv_l2, hi *= inv_l2;
        for (int c = 0; c < 3; ++c) {
            two[s].a[c] = std::clamp(pm.mean[c] + 256.0f * (m[c] + lo * ax[c]), 0.0f, 65535.0f);
            two[s].b[c] = std::clamp(pm.mean[c] + 256.0f * (m[c] + hi * ax[c]), 0.0f, 65535.0f);
        }
    }
}

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
            // time on lightmaps; from 12 ULPs (the previous threshold) the maps gain 0.01 dB and
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
            // loses to the previous exhaustive (which used only the first).
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
