// zhc/codec/lightmap/bc6h_encoder_fit.inl — BC6H encoder, one (mode, partition) fitted: the initial
// endpoints on each subset's principal axis (power iteration on the covariance, the extreme
// projections), quantization to the mode's precision with the anchor-index orientation and delta
// clamping, index selection (projection on the palette axis, or that plus an exact test of the two
// neighbours) with the exact error, and least-squares endpoint refinement for fixed indices (per
// subset and channel, 2x2 normal equations): the classic block-compression fit (I. Castano, "High
// Quality DXT Compression using CUDA", NVIDIA, 2007, for BC1; here per BC6H subset and mode). The
// format: Microsoft, "BC6H Format" (Direct3D 11) and the Khronos Data Format Specification (BPTC
// float). docs/lightmap-formats.md "BC6H".
//
// Part of the BC6H block encoder: included by codec/lightmap/bc6h_encoder.inl at this point of its
// text (so once per instruction set, inside each copy's namespace; see codec/lightmap/bc6h.cpp), never
// on its own. Not a header: no include guard, no includes; it uses the types and helpers defined
// above its #include there. Both copies perform the same IEEE operations in the same order.

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
