// BC6H unsigned (codec/lightmap/bc6h.h): half conversion, decoder totality, layout, encoder quality.
// The bit-exactness against an independent decoder (Mesa) is tests/test_mesa_bc.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "codec/lightmap/bc6h.h"
#include "support.h"

namespace zhc {
namespace {

using namespace bc6h;

TEST(Bc6hHalf, RoundTripsEveryHalfAndRoundsToNearest) {
    for (int h = 0; h < 65536; ++h) {
        const int e = (h >> 10) & 31;
        if (e == 31 && (h & 0x3FF)) continue;  // NaN payloads
        EXPECT_EQ(float_to_half(half_to_float(static_cast<std::uint16_t>(h))), h);
    }
    // Brute-force twin of rounding: the nearest of all finite positive halves (ties to even).
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-27.0f, 16.5f);
    for (int t = 0; t < 20000; ++t) {
        const float f = std::exp2(u(rng));
        const std::uint16_t h = float_to_half(f);
        if (f >= 65520.0f) {
            EXPECT_EQ(h, 0x7C00);
            continue;
        }
        // Only neighbours can be nearer (monotone), check h-1 and h+1.
        const double d = std::abs(double(half_to_float(h)) - f);
        if (h > 0) {
            EXPECT_LE(d, std::abs(double(half_to_float(static_cast<std::uint16_t>(h - 1))) - f));
        }
        if (h < 0x7BFF) {
            EXPECT_LE(d, std::abs(double(half_to_float(static_cast<std::uint16_t>(h + 1))) - f));
        }
    }
    EXPECT_EQ(float_to_uf16(-1.0f), 0);
    EXPECT_EQ(float_to_uf16(std::nanf("")), 0);
    EXPECT_EQ(float_to_uf16(1e9f), 0x7BFF);
}

TEST(Bc6hDecode, LayoutTablesAreConsistent) { EXPECT_TRUE(layout_is_consistent()); }

TEST(Bc6hDecode, IsTotalAndReservedModesDecodeToZero) {
    std::mt19937_64 rng(2);
    std::uint8_t b[16];
    std::uint16_t px[16][3];
    int reserved = 0;
    for (int t = 0; t < 200000; ++t) {
        for (int k = 0; k < 16; k += 8) {
            const std::uint64_t v = rng();
            std::memcpy(b + k, &v, 8);
        }
        decode_block(b, px);
        const int m = block_mode(b);
        for (int i = 0; i < 16; ++i)
            for (int c = 0; c < 3; ++c) {
                ASSERT_LE(px[i][c], 0x7BFF);  // finite, non-negative
                if (m < 0) {
                    ASSERT_EQ(px[i][c], 0);
                }
            }
        reserved += m < 0;
    }
    EXPECT_GT(reserved, 0);
    for (const std::uint8_t code : {0x13, 0x17, 0x1B, 0x1F}) {
        std::memset(b, 0xFF, 16);
        b[0] = static_cast<std::uint8_t>(0xE0 | code);
        EXPECT_EQ(block_mode(b), -1);
        decode_block(b, px);
        EXPECT_EQ(px[5][1], 0);
    }
}

TEST(Bc6hDecode, AllOnesEndpointsDecodeToMaxHalf) {
    // Mode 11 (code 00011), all endpoint bits set, index 0: unquantize gives 0xFFFF, and
    // 0xFFFF * 31 / 64 = 0x7BFF (65504, the largest finite half).
    std::uint8_t b[16] = {};
    b[0] = 0x03;
    for (int bit = 5; bit < 65; ++bit) b[bit >> 3] = static_cast<std::uint8_t>(b[bit >> 3] | (1 << (bit & 7)));
    std::uint16_t px[16][3];
    decode_block(b, px);
    EXPECT_EQ(px[0][0], 0x7BFF);
    EXPECT_EQ(px[15][2], 0x7BFF);
}

// Log2-space error of a decoded block against the source (half-bit domain squared error).
double block_error(const float src[16][3], const std::uint8_t blk[16]) {
    std::uint16_t px[16][3];
    decode_block(blk, px);
    double e = 0;
    for (int i = 0; i < 16; ++i)
        for (int c = 0; c < 3; ++c) {
            const double d = double(px[i][c]) - double(float_to_uf16(src[i][c]));
            e += d * d;
        }
    return e;
}

TEST(Bc6hEncode, ConstantAndTwoToneBlocks) {
    for (const float v : {0.0f, 1e-6f, 0.01f, 0.5f, 1.0f, 3.14159f, 100.0f, 60000.0f, 1e6f}) {
        float src[16][3];
        for (auto& p : src) p[0] = v, p[1] = v * 0.5f, p[2] = v * 0.25f;
        for (const Quality q : {Quality::kMode11, Quality::kFast, Quality::kDefault, Quality::kExhaustive}) {
            std::uint8_t blk[16];
            encode_block(src, q, blk);
            std::uint16_t px[16][3];
            decode_block(blk, px);
            for (int c = 0; c < 3; ++c) {
                const int want = float_to_uf16(src[0][c]);
                // Mode 11 stores 10-bit endpoints: steps of 64 in the unquantized domain, ~31 half
                // ULPs; the 16-bit mode stores constants to within a half ULP.
                EXPECT_NEAR(px[3][c], want, q == Quality::kMode11 ? 32 : 1) << v << " q=" << int(q);
            }
        }
    }
    // Three non-collinear colours, two of them left (rows alternate) and one right: no single
    // line fits, partition 0 (columns 0-1 | 2-3) with small deltas fits exactly.
    float src[16][3];
    for (int i = 0; i < 16; ++i) {
        const bool right = (i & 3) >= 2, odd = (i >> 2) & 1;
        src[i][0] = right ? 1.3f : 1.0f;
        src[i][1] = right ? 1.0f : (odd ? 1.3f : 1.0f);
        src[i][2] = right ? 1.1f : 1.0f;
    }
    std::uint8_t ex[16], md11[16], def[16];
    encode_block(src, Quality::kExhaustive, ex);
    encode_block(src, Quality::kDefault, def);
    encode_block(src, Quality::kMode11, md11);
    EXPECT_LT(block_mode(ex), 10);  // a two-subset mode
    EXPECT_LT(block_mode(def), 10);
    EXPECT_LT(block_error(src, ex), 0.05 * block_error(src, md11));
}

TEST(Bc6hEncode, QualityLevelsAreOrderedOnRealMaps) {
    const auto paths = test::envmap_paths();
    ASSERT_FALSE(paths.empty());
    double e[4] = {};
    int blocks = 0;
    std::mt19937 rng(3);
    for (const auto& path : paths) {
        const Image img = test::load_envmap(path);
        std::uniform_int_distribution<int> bx(0, img.width / 4 - 1), by(0, img.height / 4 - 1);
        for (int t = 0; t < 150; ++t) {
            const int x0 = bx(rng) * 4, y0 = by(rng) * 4;
            float src[16][3];
            for (int i = 0; i < 16; ++i)
                for (int c = 0; c < 3; ++c) src[i][c] = img.row(y0 + (i >> 2))[(x0 + (i & 3)) * 3 + c];
            double be[4];
            int k = 0;
            for (const Quality q : {Quality::kMode11, Quality::kFast, Quality::kDefault, Quality::kExhaustive}) {
                std::uint8_t blk[16];
                encode_block(src, q, blk);
                be[k] = block_error(src, blk);
                e[k] += be[k];
                ++k;
            }
            // Exhaustive tries a superset of default's candidates with more refinement.
            EXPECT_LE(be[3], be[2]);
            ++blocks;
        }
    }
    std::printf("BC6H half-domain MSE over %d real blocks: mode11 %.2f fast %.2f default %.2f exhaustive %.2f\n", blocks,
                e[0] / blocks / 48, e[1] / blocks / 48, e[2] / blocks / 48, e[3] / blocks / 48);
    EXPECT_LE(e[1], e[0]);
    EXPECT_LE(e[2], e[1]);
    EXPECT_LE(e[3], e[2]);
    // The quality targets in this error domain (half bits, a piecewise-linear log2, the
    // domain the encoder minimises): fast within 1.5 dB of exhaustive, default within 0.3 dB.
    const double fast_db = 10 * std::log10(e[1] / e[3]), default_db = 10 * std::log10(e[2] / e[3]);
    std::printf("  fast %.3f dB, default %.3f dB above exhaustive\n", fast_db, default_db);
    EXPECT_LE(fast_db, 1.5);
    EXPECT_LE(default_db, 0.3);
}

TEST(Bc6hEncode, ConstantBlocksAreExactWithoutSearch) {
    // Every half value 0..0x7BFF in each channel (the three channels offset so that they differ):
    // fast, default and exhaustive store a constant block in mode 14 (index 13) and it decodes
    // to exactly the input half bits. Mode 11 (the baseline) has no early-out.
    for (int h = 0; h <= 0x7BFF; ++h) {
        float src[16][3];
        const int hc[3] = {h, (h + 9999) % 0x7C00, 0x7BFF - h};
        for (auto& p : src)
            for (int c = 0; c < 3; ++c) p[c] = half_to_float(static_cast<std::uint16_t>(hc[c]));
        for (const Quality q : {Quality::kFast, Quality::kDefault, Quality::kExhaustive}) {
            std::uint8_t blk[16];
            encode_block(src, q, blk);
            ASSERT_EQ(block_mode(blk), 13) << "h=" << h;
            std::uint16_t px[16][3];
            decode_block(blk, px);
            for (int i = 0; i < 16; ++i)
                for (int c = 0; c < 3; ++c) ASSERT_EQ(px[i][c], hc[c]) << "h=" << h << " texel " << i;
        }
    }
    // Random floats (not exactly halves; zero, negative, subnormal-half, overflowing and NaN
    // included): the encoder's block-wide float -> half conversion rounds like float_to_uf16.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> lg(-30.0f, 17.0f);
    for (int trial = 0; trial < 20000; ++trial) {
        float v[3];
        for (float& x : v) x = std::exp2(lg(rng));
        if (trial % 7 == 0) v[trial % 3] = trial % 2 ? -v[trial % 3] : 0.0f;
        if (trial % 11 == 0) v[1] = std::nanf("");
        float src[16][3];
        for (auto& p : src) std::copy(v, v + 3, p);
        std::uint8_t blk[16];
        encode_block(src, Quality::kFast, blk);
        std::uint16_t px[16][3];
        decode_block(blk, px);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(px[9][c], float_to_uf16(v[c])) << v[c];
    }
    // Nearly constant (one texel one ULP off) is not constant: it goes through the search and
    // still comes back within a ULP (mode 14's 4-bit deltas hold it).
    float src[16][3];
    for (auto& p : src) p[0] = p[1] = p[2] = 1.5f;
    src[7][1] = half_to_float(static_cast<std::uint16_t>(float_to_half(1.5f) + 1));
    for (const Quality q : {Quality::kFast, Quality::kDefault, Quality::kExhaustive}) {
        std::uint8_t blk[16];
        encode_block(src, q, blk);
        EXPECT_LE(block_error(src, blk), 1.0) << int(q);
    }
}

TEST(Bc6hEncode, ExtremeRangeBlocksDoNotOverflowTheErrorSum) {
    // Grey texels at 0 and at the top of the half range (one line fits them exactly): a wrong index
    // costs 3 * 31571^2 > 2^31, so a 32-bit error sum would overflow and prefer wrong indices.
    float src[16][3];
    for (int i = 0; i < 16; ++i)
        for (int c = 0; c < 3; ++c) src[i][c] = (i % 3 == 0) ? 60000.0f : 0.0f;
    for (const Quality q : {Quality::kMode11, Quality::kFast, Quality::kDefault, Quality::kExhaustive}) {
        std::uint8_t blk[16];
        encode_block(src, q, blk);
        std::uint16_t px[16][3];
        decode_block(blk, px);
        for (int i = 0; i < 16; ++i)
            for (int c = 0; c < 3; ++c) {
                const double want = double(float_to_uf16(src[i][c]));
                EXPECT_NEAR(double(px[i][c]), want, 64) << "q=" << int(q) << " texel " << i << " ch " << c;
            }
    }
}

TEST(Bc6hImage, ThreadCountDoesNotChangeBytesAndEdgesReplicate) {
    const Image img = test::load_envmap(test::envmap_paths().front());
    const int w = 37, h = 23;  // not multiples of 4
    std::vector<float> crop(static_cast<size_t>(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w * 3; ++x) crop[static_cast<size_t>(y) * w * 3 + x] = img.row(y + 200)[x + 900];
    const auto a = encode_image(crop.data(), w, h, Quality::kDefault, 1);
    const auto b = encode_image(crop.data(), w, h, Quality::kDefault, 3);
    EXPECT_EQ(a, b);
    ASSERT_EQ(a.size(), static_cast<size_t>(10 * 6 * 16));
    const auto dec = decode_image(a.data(), a.size(), w, h);
    double worst = 0;
    for (size_t i = 0; i < crop.size(); ++i)
        worst = std::max(worst, std::abs(double(dec[i]) - double(float_to_uf16(crop[i]))));
    EXPECT_LT(worst, 400);  // within a few hundred half ULPs (~log2 error < 0.4) everywhere
}

// The encoder's baseline and AVX2 twins (codec/lightmap/bc6h.cpp) must write the same bytes: crops of every
// real map, from the detailed middle rows, at every quality.
TEST(Bc6hIsa, BaselineAndAvx2WriteTheSameBytesOnRealMaps) {
    if (!isa_supported(Isa::kAvx2)) GTEST_SKIP() << "this CPU has no AVX2: only the baseline encoder runs here";
    const auto paths = test::envmap_paths();
    ASSERT_FALSE(paths.empty());
    size_t blocks = 0;
    for (const auto& path : paths) {
        const Image img = test::load_envmap(path);
        for (const Quality q : {Quality::kMode11, Quality::kFast, Quality::kDefault, Quality::kExhaustive}) {
            // Exhaustive is ~100x slower: a smaller crop.
            const int w = q == Quality::kExhaustive ? 32 : 256, h = q == Quality::kExhaustive ? 16 : 64;
            const int x0 = img.width / 2 - w / 2, y0 = img.height / 2 - h / 2;
            std::vector<float> crop(static_cast<size_t>(w) * h * 3);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w * 3; ++x) crop[static_cast<size_t>(y) * w * 3 + x] = img.row(y0 + y)[x0 * 3 + x];
            const auto base = encode_image(crop.data(), w, h, q, 1, Isa::kBaseline);
            const auto avx2 = encode_image(crop.data(), w, h, q, 1, Isa::kAvx2);
            ASSERT_EQ(base.size(), avx2.size());
            EXPECT_TRUE(base == avx2) << path << " quality " << static_cast<int>(q);
            blocks += base.size() / 16;
        }
    }
    std::printf("baseline == AVX2 on %zu blocks\n", blocks);
    EXPECT_EQ(best_isa(), Isa::kAvx2);
}

}  // namespace
}  // namespace zhc
