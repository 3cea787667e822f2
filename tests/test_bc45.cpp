// BC4 / BC5 (codec/lightmap/bc45.h): decoder against the format's palette formula, totality, and the
// encoder against a brute-force optimum (every endpoint pair, best indices).
#include <cstdio>
#include <cstring>
#include <random>

#include "codec/lightmap/bc45.h"
#include "codec/lightmap/lightmap.h"
#include "support.h"

namespace zhc {
namespace {

using namespace bc45;

double sse(const float v[16], const std::uint8_t blk[8]) {
    float d[16];
    decode_bc4_block(blk, d);
    double e = 0;
    for (int i = 0; i < 16; ++i) e += (double(d[i]) - std::clamp(double(v[i]), 0.0, 1.0)) * (double(d[i]) - std::clamp(double(v[i]), 0.0, 1.0));
    return e;
}

// Brute force: every (r0, r1) pair, each texel's nearest palette entry (the true optimum).
double brute_optimum(const float v[16]) {
    double best = 1e30;
    for (int r0 = 0; r0 < 256; ++r0)
        for (int r1 = 0; r1 < 256; ++r1) {
            double pal[8] = {double(r0), double(r1)};
            if (r0 > r1) {
                for (int j = 1; j <= 6; ++j) pal[j + 1] = ((7 - j) * r0 + j * r1) / 7.0;
            } else {
                for (int j = 1; j <= 4; ++j) pal[j + 1] = ((5 - j) * r0 + j * r1) / 5.0;
                pal[6] = 0, pal[7] = 255;
            }
            double e = 0;
            for (int i = 0; i < 16 && e < best; ++i) {
                double m = 1e30;
                for (double p : pal) m = std::min(m, (p / 255 - v[i]) * (p / 255 - v[i]));
                e += m;
            }
            best = std::min(best, e);
        }
    return best;
}

TEST(Bc4Decode, MatchesThePaletteFormulaAndIsTotal) {
    std::mt19937_64 rng(1);
    for (int t = 0; t < 20000; ++t) {
        std::uint8_t b[8];
        const std::uint64_t v = rng();
        std::memcpy(b, &v, 8);
        float d[16];
        decode_bc4_block(b, d);
        std::uint64_t bits = 0;
        for (int k = 0; k < 6; ++k) bits |= std::uint64_t(b[2 + k]) << (8 * k);
        for (int i = 0; i < 16; ++i) {
            const int j = (bits >> (3 * i)) & 7, r0 = b[0], r1 = b[1];
            double want;
            if (j == 0) want = r0;
            else if (j == 1) want = r1;
            else if (r0 > r1) want = ((8 - j) * r0 + (j - 1) * r1) / 7.0;
            else if (j < 6) want = ((6 - j) * r0 + (j - 1) * r1) / 5.0;
            else want = j == 6 ? 0 : 255;
            ASSERT_NEAR(d[i], want / 255, 1e-6);
        }
    }
}

TEST(Bc4Encode, CloseToTheBruteForceOptimum) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(0, 1);
    double sum_def = 0, sum_fast = 0, sum_opt = 0;
    for (int t = 0; t < 24; ++t) {
        float v[16];
        const float a = u(rng), b = u(rng);
        for (int i = 0; i < 16; ++i) {
            switch (t % 4) {
                case 0: v[i] = a + (b - a) * i / 15.0f; break;                       // gradient
                case 1: v[i] = a + 0.1f * (u(rng) - 0.5f); break;                     // noise around a
                case 2: v[i] = u(rng); break;                                          // full noise
                default: v[i] = (i % 5 == 0) ? 0.0f : (i % 7 == 0 ? 1.0f : 0.3f + 0.2f * u(rng));  // 0/1 outliers
            }
            v[i] = std::clamp(v[i], 0.0f, 1.0f);
        }
        std::uint8_t d[8], f[8];
        encode_bc4_block(v, Quality::kDefault, d);
        encode_bc4_block(v, Quality::kFast, f);
        const double opt = brute_optimum(v);
        sum_def += sse(v, d), sum_fast += sse(v, f), sum_opt += opt;
        EXPECT_GE(sse(v, d), opt * (1 - 1e-4));  // float decode rounding
        EXPECT_LE(sse(v, d), 1.5 * opt + 16 * 0.25 / 255 / 255) << t;
    }
    std::printf("BC4 SSE summed over 24 blocks: default %.4g fast %.4g brute-force optimum %.4g\n", sum_def, sum_fast, sum_opt);
    EXPECT_LE(sum_def, 1.15 * sum_opt);
    EXPECT_LE(sum_def, sum_fast);
}

TEST(Bc5, TwoIndependentBc4BlocksAndImageRoundTrip) {
    const int w = 13, h = 9;
    std::vector<float> rg(static_cast<size_t>(w) * h * 2);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            rg[(static_cast<size_t>(y) * w + x) * 2] = x / float(w);
            rg[(static_cast<size_t>(y) * w + x) * 2 + 1] = 1.0f - y / float(h);
        }
    const auto a = encode_image(rg.data(), 2, w, h, Quality::kDefault, 1);
    const auto b = encode_image(rg.data(), 2, w, h, Quality::kDefault, 2);
    EXPECT_EQ(a, b);
    ASSERT_EQ(a.size(), static_cast<size_t>(4 * 3 * 16));
    const auto dec = decode_image(a.data(), a.size(), 2, w, h);
    // A block spans at most 3/9 of the green ramp; eight palette entries => error <= (3/9)/14 + 1/255.
    for (size_t i = 0; i < rg.size(); ++i) EXPECT_NEAR(dec[i], rg[i], (3.0 / 9) / 14 + 1.0 / 255) << i;
    // The green block of BC5 is a BC4 block on its own.
    float g[16], rgd[16][2];
    decode_bc4_block(a.data() + 8, g);
    decode_bc5_block(a.data(), rgd);
    for (int i = 0; i < 16; ++i) EXPECT_EQ(g[i], rgd[i][1]);
    // Out-of-range and NaN inputs are clamped, not propagated.
    float bad[16];
    for (int i = 0; i < 16; ++i) bad[i] = i % 3 == 0 ? std::nanf("") : (i % 3 == 1 ? -5.0f : 7.0f);
    std::uint8_t blk[8];
    encode_bc4_block(bad, Quality::kDefault, blk);
    float out[16];
    decode_bc4_block(blk, out);
    for (int i = 0; i < 16; ++i) EXPECT_NEAR(out[i], i % 3 == 2 ? 1.0f : 0.0f, 1e-6) << i;
}

// The SSE2 and AVX2 index searches of encode_bc4_block against their scalar twin, bit for bit: random blocks
// (uniform, clustered, at the ends of the range, with exact 0 / 1 texels, constant, out of range,
// NaN) and every block of the IrradZ d and w_a planes of the 8 sample maps' synthetic lightmaps,
// both qualities.
TEST(Bc4Encode, FastPathMatchesTheScalarTwinBitForBit) {
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> u(0, 1);
    auto same = [](const float v[16], Quality q) {
        std::uint8_t a[8], b[8], c[8];
        encode_bc4_block(v, q, a);  // AVX2 where the CPU has it
        detail::encode_bc4_block_scalar(v, q, b);
        detail::encode_bc4_block_sse2(v, q, c);
        return std::memcmp(a, b, 8) == 0 && std::memcmp(c, b, 8) == 0;
    };
    long blocks = 0;
    for (int t = 0; t < 20000; ++t) {
        float v[16];
        // Every fifth block sits at an end of the range (endpoints near 0 or 255: the local search
        // clamps there).
        const float c = t % 5 == 0 ? (t % 10 == 0 ? 0.997f : 0.003f) : u(rng);
        const float spread = t % 5 == 0 ? 0.02f * u(rng) : t % 4 == 0 ? 1.0f : 0.05f * u(rng);
        for (int i = 0; i < 16; ++i) {
            v[i] = c + spread * (u(rng) - 0.5f);
            if (t % 7 == 0 && i % 5 == 0) v[i] = i % 2 ? 1.0f : 0.0f;
            if (t % 11 == 0) v[i] = c;
            if (t % 13 == 0 && i == 3) v[i] = t % 2 ? std::nanf("") : 3.0f;
        }
        for (Quality q : {Quality::kFast, Quality::kDefault}) {
            ASSERT_TRUE(same(v, q)) << "random block " << t;
            ++blocks;
        }
    }
    for (const std::string& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        const Sh3Radiance world = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
        const lightmap::ShLightmap lm = lightmap::synthesize_sphere(world, 32, 32, 1);
        const lightmap::IrradzPlanes p = lightmap::encode_planes(lm, {}, 2);
        for (int c = 0; c < 3; ++c)
            for (int by = 0; by < 8; ++by)
                for (int bx = 0; bx < 8; ++bx) {
                    float v[16];
                    for (int i = 0; i < 16; ++i) {
                        const size_t t = static_cast<size_t>(by * 4 + (i >> 2)) * 32 + static_cast<size_t>(bx * 4 + (i & 3));
                        v[i] = c < 2 ? p.d[2 * t + static_cast<size_t>(c)] : p.wa[t];
                    }
                    for (Quality q : {Quality::kFast, Quality::kDefault}) {
                        ASSERT_TRUE(same(v, q)) << path << " plane " << c << " block " << bx << "," << by;
                        ++blocks;
                    }
                }
    }
    std::printf("%ld blocks encoded identically by the fast path and the scalar twin\n", blocks);
}

}  // namespace
}  // namespace zhc
