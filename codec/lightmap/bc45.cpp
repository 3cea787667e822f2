// zhc/codec/lightmap/bc45.cpp — BC4 / BC5 UNORM (see bc45.h).
#include "codec/lightmap/bc45.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include "codec/isa.h"  // the AVX2 index search
#if ZHC_AVX2_TWIN && defined(__SSE2__)
#define ZHC_BC45_AVX2 1
#include <immintrin.h>
#else
#define ZHC_BC45_AVX2 0
#endif

namespace zhc::bc45 {
namespace {

// Palette in 0..255 units (real-valued, as the format defines it).
void palette(int r0, int r1, float pal[8]) {
    pal[0] = static_cast<float>(r0);
    pal[1] = static_cast<float>(r1);
    if (r0 > r1) {
        for (int j = 1; j <= 6; ++j) pal[j + 1] = static_cast<float>((7 - j) * r0 + j * r1) / 7.0f;
    } else {
        for (int j = 1; j <= 4; ++j) pal[j + 1] = static_cast<float>((5 - j) * r0 + j * r1) / 5.0f;
        pal[6] = 0.0f;
        pal[7] = 255.0f;
    }
}

// palette() with the quotients looked up: n / 7.0f and n / 5.0f for every numerator n the format
// can form (at most 7 * 255), computed by the same float division, so the same bits.
struct Quotients {
    float by7[7 * 255 + 1], by5[5 * 255 + 1];
};
[[maybe_unused]] const Quotients& quotients() {
    static const Quotients q = [] {
        Quotients r{};
        for (int n = 0; n <= 7 * 255; ++n) r.by7[n] = static_cast<float>(n) / 7.0f;
        for (int n = 0; n <= 5 * 255; ++n) r.by5[n] = static_cast<float>(n) / 5.0f;
        return r;
    }();
    return q;
}
[[maybe_unused]] void palette_fast(int r0, int r1, float pal[8]) {
    const Quotients& q = quotients();
    pal[0] = static_cast<float>(r0);
    pal[1] = static_cast<float>(r1);
    if (r0 > r1) {
        for (int j = 1; j <= 6; ++j) pal[j + 1] = q.by7[(7 - j) * r0 + j * r1];
    } else {
        for (int j = 1; j <= 4; ++j) pal[j + 1] = q.by5[(5 - j) * r0 + j * r1];
        pal[6] = 0.0f;
        pal[7] = 255.0f;
    }
}

// Best indices and squared error (255 units) for the endpoint pair: each texel's first palette entry
// of least squared distance, the errors summed in texel order. assign_scalar is the obviously
// correct form; assign_fast computes the same floats (the same subtractions and products, the
// same strict comparisons in the same entry order, the same summation order) four texels at a
// time, so both give the same bits.
float assign_scalar(const float v[16], int r0, int r1, std::uint8_t idx[16]) {
    float pal[8];
    palette(r0, r1, pal);
    float err = 0;
    for (int i = 0; i < 16; ++i) {
        int best = 0;
        float be = 1e30f;
        for (int j = 0; j < 8; ++j) {
            const float d = pal[j] - v[i];
            if (d * d < be) be = d * d, best = j;
        }
        idx[i] = static_cast<std::uint8_t>(best);
        err += be;
    }
    return err;
}

#if defined(__SSE2__)
// `bound`: the caller keeps the result only if it is below `bound`. When the four-lane sum of the
// errors exceeds bound (1 + 1e-5), the texel-order sum exceeds bound too (two float sums of the same
// 16 non-negative terms differ by at most about 20 ulp-units of the total, 1.2e-6 relative), so
// the pair is dropped without the ordered sum and the index bytes (returns +inf). Otherwise the
// result is assign_scalar's, bit for bit.
float assign_fast(const float v[16], int r0, int r1, std::uint8_t idx[16], float bound) {
    float pal[8];
    palette_fast(r0, r1, pal);
    __m128 x[4], be[4];
    __m128i bi[4];
    for (int q = 0; q < 4; ++q) {
        x[q] = _mm_loadu_ps(v + 4 * q);
        be[q] = _mm_set1_ps(1e30f);
        bi[q] = _mm_setzero_si128();
    }
    for (int j = 0; j < 8; ++j) {
        const __m128 p = _mm_set1_ps(pal[j]);
        const __m128i jj = _mm_set1_epi32(j);
        for (int q = 0; q < 4; ++q) {
            const __m128 d = _mm_sub_ps(p, x[q]);
            const __m128 dd = _mm_mul_ps(d, d);
            const __m128 lt = _mm_cmplt_ps(dd, be[q]);
            be[q] = _mm_or_ps(_mm_and_ps(lt, dd), _mm_andnot_ps(lt, be[q]));
            const __m128i m = _mm_castps_si128(lt);
            bi[q] = _mm_or_si128(_mm_and_si128(m, jj), _mm_andnot_si128(m, bi[q]));
        }
    }
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, _mm_add_ps(_mm_add_ps(be[0], be[1]), _mm_add_ps(be[2], be[3])));
    if ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) > bound * (1 + 1e-5f)) return std::numeric_limits<float>::infinity();
    alignas(16) float e[16];
    alignas(16) std::int32_t k[16];
    for (int q = 0; q < 4; ++q) {
        _mm_store_ps(e + 4 * q, be[q]);
        _mm_store_si128(reinterpret_cast<__m128i*>(k + 4 * q), bi[q]);
    }
    float err = 0;
    for (int i = 0; i < 16; ++i) {
        idx[i] = static_cast<std::uint8_t>(k[i]);
        err += e[i];
    }
    return err;
}
#else
float assign_fast(const float v[16], int r0, int r1, std::uint8_t idx[16], float) { return assign_scalar(v, r0, r1, idx); }
#endif

#if ZHC_BC45_AVX2
// assign_fast eight texels at a time (AVX2): per texel the same subtraction, product and strict
// comparison in the same entry order, the texel-order sum; only the early-out's sum runs in another
// order, which the bound's margin covers (see assign_fast).
__attribute__((target("avx2"))) float assign_avx2(const float v[16], int r0, int r1, std::uint8_t idx[16], float bound) {
    float pal[8];
    palette_fast(r0, r1, pal);
    __m256 x[2], be[2];
    __m256i bi[2];
    for (int q = 0; q < 2; ++q) {
        x[q] = _mm256_loadu_ps(v + 8 * q);
        be[q] = _mm256_set1_ps(1e30f);
        bi[q] = _mm256_setzero_si256();
    }
    for (int j = 0; j < 8; ++j) {
        const __m256 p = _mm256_set1_ps(pal[j]);
        const __m256i jj = _mm256_set1_epi32(j);
        for (int q = 0; q < 2; ++q) {
            const __m256 d = _mm256_sub_ps(p, x[q]);
            const __m256 dd = _mm256_mul_ps(d, d);
            const __m256 lt = _mm256_cmp_ps(dd, be[q], _CMP_LT_OQ);
            be[q] = _mm256_blendv_ps(be[q], dd, lt);
            bi[q] = _mm256_blendv_epi8(bi[q], jj, _mm256_castps_si256(lt));
        }
    }
    const __m256 s8 = _mm256_add_ps(be[0], be[1]);
    const __m128 s4 = _mm_add_ps(_mm256_castps256_ps128(s8), _mm256_extractf128_ps(s8, 1));
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, s4);
    if ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) > bound * (1 + 1e-5f)) return std::numeric_limits<float>::infinity();
    alignas(32) float e[16];
    alignas(32) std::int32_t k[16];
    for (int q = 0; q < 2; ++q) {
        _mm256_store_ps(e + 8 * q, be[q]);
        _mm256_store_si256(reinterpret_cast<__m256i*>(k + 8 * q), bi[q]);
    }
    float err = 0;
    for (int i = 0; i < 16; ++i) {
        idx[i] = static_cast<std::uint8_t>(k[i]);
        err += e[i];
    }
    return err;
}
bool have_avx2() { return cpu_has_avx2(); }
#else
float assign_avx2(const float v[16], int r0, int r1, std::uint8_t idx[16], float bound) { return assign_fast(v, r0, r1, idx, bound); }
bool have_avx2() { return false; }
#endif

// The index search paths: the scalar twin, SSE2 (four texels a vector), AVX2 (eight).
enum Path { kScalar = 0, kSse2 = 1, kAvx2 = 2 };

// Interpolation weight of endpoint 1 for index j (0 for r0, 1 for r1); -1 for the constants.
float weight(bool eight, int j) {
    if (j == 0) return 0;
    if (j == 1) return 1;
    if (eight) return static_cast<float>(j - 1) / 7.0f;
    if (j <= 5) return static_cast<float>(j - 1) / 5.0f;
    return -1;
}

struct Best {
    int r0 = 0, r1 = 0;
    float err = 1e30f;
    std::uint8_t idx[16] = {};
};
template <int kPath>
void consider(const float v[16], int r0, int r1, Best& b) {
    r0 = std::clamp(r0, 0, 255), r1 = std::clamp(r1, 0, 255);
    std::uint8_t idx[16];
    const float e = kPath == kAvx2   ? assign_avx2(v, r0, r1, idx, b.err)
                    : kPath == kSse2 ? assign_fast(v, r0, r1, idx, b.err)
                                     : assign_scalar(v, r0, r1, idx);
    if (e < b.err) {
        b.err = e, b.r0 = r0, b.r1 = r1;
        std::memcpy(b.idx, idx, 16);
    }
}

// Least-squares endpoints for fixed indices, then rounded; ordered for the palette kind.
template <int kPath>
void refine(const float v[16], Best& b) {
    const bool eight = b.r0 > b.r1;
    float aa = 0, ab = 0, bb = 0, ra = 0, rb = 0;
    for (int i = 0; i < 16; ++i) {
        const float w = weight(eight, b.idx[i]);
        if (w < 0) continue;
        const float u = 1 - w;
        aa += u * u, ab += u * w, bb += w * w, ra += u * v[i], rb += w * v[i];
    }
    const float det = aa * bb - ab * ab;
    if (std::abs(det) < 1e-6f) return;
    const float e0 = (bb * ra - ab * rb) / det, e1 = (aa * rb - ab * ra) / det;
    const int a = std::clamp(static_cast<int>(std::lround(e0)), 0, 255);
    const int c = std::clamp(static_cast<int>(std::lround(e1)), 0, 255);
    if (eight && a > c) consider<kPath>(v, a, c, b);
    if (!eight && a <= c) consider<kPath>(v, a, c, b);
}

void write_block(const Best& b, std::uint8_t out[8]) {
    out[0] = static_cast<std::uint8_t>(b.r0);
    out[1] = static_cast<std::uint8_t>(b.r1);
    std::uint64_t bits = 0;
    for (int i = 0; i < 16; ++i) bits |= static_cast<std::uint64_t>(b.idx[i] & 7) << (3 * i);
    for (int k = 0; k < 6; ++k) out[2 + k] = static_cast<std::uint8_t>(bits >> (8 * k));
}

template <int kPath>
void encode_bc4(const float in[16], Quality quality, std::uint8_t out[8]) {
    float v[16];
    float lo = 255, hi = 0;
    for (int i = 0; i < 16; ++i) {
        const float x = in[i] > 0 ? std::min(in[i], 1.0f) * 255.0f : 0.0f;  // NaN -> 0
        v[i] = x;
        lo = std::min(lo, x), hi = std::max(hi, x);
    }
    Best b;
    const int l = static_cast<int>(std::floor(lo)), h = static_cast<int>(std::ceil(hi));
    // Eight-value palette (r0 > r1) spanning the range; and the six-value one (r0 <= r1) with the
    // range excluding exact 0 and 1 texels (those use the constant entries).
    consider<kPath>(v, std::max(h, l + 1), l, b);
    float lo6 = 255, hi6 = 0;
    for (int i = 0; i < 16; ++i)
        if (v[i] > 0 && v[i] < 255) lo6 = std::min(lo6, v[i]), hi6 = std::max(hi6, v[i]);
    if (lo6 <= hi6) consider<kPath>(v, static_cast<int>(std::floor(lo6)), static_cast<int>(std::ceil(hi6)), b);
    if (h == l) consider<kPath>(v, l, l, b);
    const int rounds = quality == Quality::kFast ? 1 : 3;
    for (int it = 0; it < rounds; ++it) refine<kPath>(v, b);
    if (quality == Quality::kDefault) {
        // Local search around the best pair (keeps its palette kind).
        const Best start = b;
        // The fast path skips repeats: the start pair (b.err is its error already) and a pair that
        // clamps to one already tried (it cannot beat it); the others in the same order.
        int tried[25], n = 0;
        for (int d0 = -2; d0 <= 2; ++d0)
            for (int d1 = -2; d1 <= 2; ++d1) {
                const int a = start.r0 + d0, c = start.r1 + d1;
                if ((start.r0 > start.r1) != (a > c)) continue;
                if constexpr (kPath != kScalar) {
                    const int key = std::clamp(a, 0, 255) * 256 + std::clamp(c, 0, 255);
                    if (key == start.r0 * 256 + start.r1 || std::find(tried, tried + n, key) != tried + n) continue;
                    tried[n++] = key;
                }
                consider<kPath>(v, a, c, b);
            }
        refine<kPath>(v, b);
    }
    write_block(b, out);
}

}  // namespace

void encode_bc4_block(const float in[16], Quality quality, std::uint8_t out[8]) {
    if (have_avx2()) return encode_bc4<kAvx2>(in, quality, out);
    encode_bc4<kSse2>(in, quality, out);
}

namespace detail {
void encode_bc4_block_scalar(const float in[16], Quality quality, std::uint8_t out[8]) {
    encode_bc4<kScalar>(in, quality, out);
}
void encode_bc4_block_sse2(const float in[16], Quality quality, std::uint8_t out[8]) { encode_bc4<kSse2>(in, quality, out); }
}  // namespace detail

void decode_bc4_block(const std::uint8_t in[8], float out[16]) {
    float pal[8];
    palette(in[0], in[1], pal);
    std::uint64_t bits = 0;
    for (int k = 0; k < 6; ++k) bits |= static_cast<std::uint64_t>(in[2 + k]) << (8 * k);
    for (int i = 0; i < 16; ++i) out[i] = pal[(bits >> (3 * i)) & 7] / 255.0f;
}

void encode_bc5_block(const float rg[16][2], Quality quality, std::uint8_t out[16]) {
    float r[16], g[16];
    for (int i = 0; i < 16; ++i) r[i] = rg[i][0], g[i] = rg[i][1];
    encode_bc4_block(r, quality, out);
    encode_bc4_block(g, quality, out + 8);
}

void decode_bc5_block(const std::uint8_t in[16], float out[16][2]) {
    float r[16], g[16];
    decode_bc4_block(in, r);
    decode_bc4_block(in + 8, g);
    for (int i = 0; i < 16; ++i) out[i][0] = r[i], out[i][1] = g[i];
}

std::vector<std::uint8_t> encode_image(const float* values, int channels, int width, int height, Quality quality,
                                       int threads) {
    const int bw = (width + 3) / 4, bh = (height + 3) / 4;
    const size_t bytes = channels == 1 ? 8 : 16;
    std::vector<std::uint8_t> out(static_cast<size_t>(bw) * static_cast<size_t>(bh) * bytes);
    auto work = [&](int y0, int y1) {
        float block[16][2];
        for (int by = y0; by < y1; ++by)
            for (int bx = 0; bx < bw; ++bx) {
                for (int i = 0; i < 16; ++i) {
                    const int x = std::min(bx * 4 + (i & 3), width - 1), y = std::min(by * 4 + (i >> 2), height - 1);
                    const float* p = values + (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * static_cast<size_t>(channels);
                    block[i][0] = p[0];
                    block[i][1] = channels > 1 ? p[1] : 0.0f;
                }
                std::uint8_t* dst = out.data() + (static_cast<size_t>(by) * static_cast<size_t>(bw) + static_cast<size_t>(bx)) * bytes;
                if (channels == 1) {
                    float v[16];
                    for (int i = 0; i < 16; ++i) v[i] = block[i][0];
                    encode_bc4_block(v, quality, dst);
                } else {
                    encode_bc5_block(block, quality, dst);
                }
            }
    };
    threads = std::max(1, std::min(threads, bh));
    std::vector<std::thread> pool;
    for (int k = 1; k < threads; ++k) pool.emplace_back(work, bh * k / threads, bh * (k + 1) / threads);
    work(0, bh / threads);
    for (auto& t : pool) t.join();
    return out;
}

std::vector<float> decode_image(const std::uint8_t* blocks, std::size_t size, int channels, int width, int height) {
    std::vector<float> out(static_cast<size_t>(width) * static_cast<size_t>(height) * static_cast<size_t>(channels), 0.0f);
    const int bw = (width + 3) / 4, bh = (height + 3) / 4;
    const size_t bytes = channels == 1 ? 8 : 16;
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            const size_t off = (static_cast<size_t>(by) * static_cast<size_t>(bw) + static_cast<size_t>(bx)) * bytes;
            if (off + bytes > size) return out;
            float px[16][2];
            if (channels == 1) {
                float v[16];
                decode_bc4_block(blocks + off, v);
                for (int i = 0; i < 16; ++i) px[i][0] = v[i];
            } else {
                decode_bc5_block(blocks + off, px);
            }
            for (int i = 0; i < 16; ++i) {
                const int x = bx * 4 + (i & 3), y = by * 4 + (i >> 2);
                if (x >= width || y >= height) continue;
                for (int c = 0; c < channels; ++c)
                    out[(static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * static_cast<size_t>(channels) + static_cast<size_t>(c)] = px[i][c];
            }
        }
    return out;
}

}  // namespace zhc::bc45
