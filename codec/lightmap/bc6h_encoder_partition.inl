// zhc/codec/lightmap/bc6h_encoder_partition.inl — BC6H encoder, the two-subset partition choice: all
// 32 partitions scored at once by what a line cannot fit (per subset trace(C) - lambda_max(C) in 3D,
// or the smaller eigenvalue in the plane of the block's two principal axes in 2D) from subset moment
// sums computed as one masked product, and both subsets' lines for a chosen partition from those
// moments (zhc's own screening; docs/lightmap-formats.md "BC6H"). The partition table: Microsoft,
// "BC6H Format" (Direct3D 11) and the Khronos Data Format Specification (BPTC float).
//
// Part of the BC6H block encoder: included by codec/lightmap/bc6h_encoder.inl at this point of its
// text (so once per instruction set, inside each copy's namespace; see codec/lightmap/bc6h.cpp), never
// on its own. Not a header: no include guard, no includes; it uses the types and helpers defined
// above its #include there. Both copies perform the same IEEE operations in the same order.

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
