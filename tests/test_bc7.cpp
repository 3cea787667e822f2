// BC7 decoder (formats/envmap/bc7.h): known-answer blocks derived by hand from the Khronos Data
// Format Specification's BC7 section. Each block is assembled field by field at the absolute bit
// positions of the specification's "Bit layout for BC7 modes" table (not by the decoder's
// sequential reader), and the expected texels were worked out from its endpoint expansion
// (stored bits, P-bit, top bits repeated), the interpolation weights and
// ((64 - w) E0 + w E1 + 32) >> 6 (the arithmetic is in the comments). test_mesa_bc compares the
// decoder with Mesa's on random blocks of every mode; test_cube_ldr reads BC7 cube maps.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <initializer_list>

#include "formats/envmap/bc7.h"

namespace zhc {
namespace {

struct Block {
    std::array<std::uint8_t, 16> bytes{};
    // Field of `n` bits starting at absolute bit `first` (LSB first), value v.
    void put(int first, int n, unsigned v) {
        for (int i = 0; i < n; ++i)
            if ((v >> i) & 1) bytes[static_cast<size_t>((first + i) / 8)] |= static_cast<std::uint8_t>(1u << ((first + i) % 8));
    }
};

using Texel = std::array<int, 4>;
Texel texel(const std::uint8_t rgba[16][4], int t) { return {rgba[t][0], rgba[t][1], rgba[t][2], rgba[t][3]}; }

TEST(Bc7, Mode6EndpointPbitsAndFourBitIndices) {
    Block b;
    b.put(6, 1, 1);  // mode 6: bits 0..6 = 0000001
    b.put(7, 7, 100), b.put(14, 7, 20);    // R0, R1
    b.put(21, 7, 0), b.put(28, 7, 127);    // G0, G1
    b.put(35, 7, 64), b.put(42, 7, 64);    // B0, B1
    b.put(49, 7, 127), b.put(56, 7, 0);    // A0, A1
    b.put(63, 1, 1), b.put(64, 1, 0);      // P-bits of endpoint 0 and 1
    // E0 = (100<<1|1, 0<<1|1, 64<<1|1, 127<<1|1) = (201, 1, 129, 255); E1 = (40, 254, 128, 0).
    b.put(65, 3, 7);               // texel 0 (anchor): 3 bits, index 7 -> weight 30
    b.put(68, 4, 15);              // texel 1: bits 68..71, index 15 -> weight 64
    b.put(68 + 4 * 4, 4, 9);       // texel 5: index 9 -> weight 38
    ASSERT_EQ(bc7::block_mode(b.bytes.data()), 6);
    std::uint8_t out[16][4];
    bc7::decode_block(b.bytes.data(), out);
    // Texel 0: R (34*201 + 30*40 + 32) >> 6 = 8066 >> 6 = 126; G (34 + 30*254 + 32) >> 6 = 120;
    // B (34*129 + 30*128 + 32) >> 6 = 129; A (34*255 + 32) >> 6 = 135.
    EXPECT_EQ(texel(out, 0), (Texel{126, 120, 129, 135}));
    EXPECT_EQ(texel(out, 1), (Texel{40, 254, 128, 0}));  // weight 64: E1
    // Texel 5: R (26*201 + 38*40 + 32) >> 6 = 6778 >> 6 = 105; G (26 + 38*254 + 32) >> 6 = 151;
    // B (26*129 + 38*128 + 32) >> 6 = 128; A (26*255 + 32) >> 6 = 104.
    EXPECT_EQ(texel(out, 5), (Texel{105, 151, 128, 104}));
    EXPECT_EQ(texel(out, 2), (Texel{201, 1, 129, 255}));  // index 0: E0
}

TEST(Bc7, Mode5RotationSwapsAlphaAndGreen) {
    Block b;
    b.put(5, 1, 1);                       // mode 5
    b.put(6, 2, 2);                       // rotation 2: swap A and G
    b.put(8, 7, 127), b.put(15, 7, 0);    // R0 = 127 -> 255, R1 = 0
    b.put(22, 7, 64), b.put(29, 7, 32);   // G0 = 64 -> 129 (128 | 64>>6), G1 = 32 -> 64
    b.put(36, 7, 10), b.put(43, 7, 100);  // B0 = 10 -> 20, B1 = 100 -> 201
    b.put(50, 8, 200), b.put(58, 8, 10);  // A0 = 200, A1 = 10
    b.put(67 + 2 * 2, 2, 2);              // texel 3 colour index 2 (weight 43): bits 71..72
    b.put(98 + 2 * 2, 2, 1);              // texel 3 alpha index 1 (weight 21): bits 102..103
    std::uint8_t out[16][4];
    bc7::decode_block(b.bytes.data(), out);
    // R (21*255 + 32) >> 6 = 84; G (21*129 + 43*64 + 32) >> 6 = 5493 >> 6 = 85;
    // B (21*20 + 43*201 + 32) >> 6 = 9095 >> 6 = 142; A (43*200 + 21*10 + 32) >> 6 = 8842 >> 6 = 138;
    // then G and A swap.
    EXPECT_EQ(texel(out, 3), (Texel{84, 138, 142, 85}));
    // Texel 0: indices 0 -> (255, 129, 20, 200), G and A swapped.
    EXPECT_EQ(texel(out, 0), (Texel{255, 200, 20, 129}));
}

TEST(Bc7, Mode4IndexSelectionTakesColourFromTheThreeBitIndices) {
    Block b;
    b.put(4, 1, 1);                       // mode 4, rotation 0 (bits 5..6)
    b.put(7, 1, 1);                       // index selection 1
    b.put(8, 5, 31), b.put(13, 5, 0);     // R0 = 31 -> 255, R1 = 0
    b.put(18, 5, 16), b.put(23, 5, 16);   // G0 = G1 = 16 -> 132 (128 | 16>>2)
    b.put(28, 5, 0), b.put(33, 5, 31);    // B0 = 0, B1 = 31 -> 255
    b.put(38, 6, 63), b.put(44, 6, 0);    // A0 = 63 -> 255, A1 = 0
    b.put(51 + 2 * 1, 2, 1);              // texel 2, 2-bit index 1 (weight 21): bits 53..54
    b.put(83 + 3 * 1, 3, 5);              // texel 2, 3-bit index 5 (weight 46): bits 86..88
    std::uint8_t out[16][4];
    bc7::decode_block(b.bytes.data(), out);
    // Colour by weight 46: R (18*255 + 32) >> 6 = 72, G 132, B (46*255 + 32) >> 6 = 183;
    // alpha by weight 21: (43*255 + 32) >> 6 = 171.
    EXPECT_EQ(texel(out, 2), (Texel{72, 132, 183, 171}));
    // The same block with index selection 0: colour by weight 21, alpha by weight 46.
    b.bytes[0] &= 0x7F;
    bc7::decode_block(b.bytes.data(), out);
    // R (43*255 + 32) >> 6 = 171, B (21*255 + 32) >> 6 = 84, A (18*255 + 32) >> 6 = 72.
    EXPECT_EQ(texel(out, 2), (Texel{171, 132, 84, 72}));
}

TEST(Bc7, Mode1PartitionSharedPbitsAndAnchorInTheMiddle) {
    Block b;
    b.put(1, 1, 1);      // mode 1
    b.put(2, 6, 17);     // partition 17: texels 1, 2, 3, 7 in subset 1; anchor of subset 1 is texel 2
    b.put(8, 6, 0), b.put(14, 6, 63), b.put(20, 6, 0), b.put(26, 6, 0);    // R0..R3
    b.put(32, 6, 0), b.put(38, 6, 0), b.put(44, 6, 10), b.put(50, 6, 50);  // G0..G3
    b.put(56, 6, 0), b.put(62, 6, 0), b.put(68, 6, 63), b.put(74, 6, 63);  // B0..B3
    b.put(80, 1, 0), b.put(81, 1, 1);  // shared P-bits of subsets 0 and 1
    // Subset 0: E0 = (0, 0, 0), E1 R = 63<<1|0 = 126 -> 126<<1 | 126>>6 = 253.
    // Subset 1: E2 = (0<<1|1 = 1 -> 2, 10<<1|1 = 21 -> 42, 127 -> 255), E3 = (2, 101 -> 203, 255).
    // Index bits from 82: texel 0 2 bits, texel 1 3 bits, texel 2 (anchor) 2 bits (87..88), then 3 bits.
    b.put(87, 2, 3);            // texel 2: index 3 of the 3-bit table -> weight 27
    b.put(89 + 3 * 1, 3, 6);    // texel 4 (subset 0): index 6 -> weight 55
    b.put(89 + 3 * 4, 3, 1);    // texel 7 (subset 1): index 1 -> weight 9
    std::uint8_t out[16][4];
    bc7::decode_block(b.bytes.data(), out);
    // Texel 2: G (37*42 + 27*203 + 32) >> 6 = 7067 >> 6 = 110.
    EXPECT_EQ(texel(out, 2), (Texel{2, 110, 255, 255}));
    // Texel 4: R (9*0 + 55*253 + 32) >> 6 = 13947 >> 6 = 217.
    EXPECT_EQ(texel(out, 4), (Texel{217, 0, 0, 255}));
    // Texel 7: G (55*42 + 9*203 + 32) >> 6 = 4169 >> 6 = 65.
    EXPECT_EQ(texel(out, 7), (Texel{2, 65, 255, 255}));
    EXPECT_EQ(texel(out, 1), (Texel{2, 42, 255, 255}));  // subset 1, index 0: E2
}

TEST(Bc7, ReservedModeDecodesToZero) {
    Block b;
    for (int i = 1; i < 16; ++i) b.bytes[static_cast<size_t>(i)] = static_cast<std::uint8_t>(37 * i + 11);
    ASSERT_EQ(bc7::block_mode(b.bytes.data()), 8);
    std::uint8_t out[16][4];
    for (auto& t : out)
        for (auto& c : t) c = 99;
    bc7::decode_block(b.bytes.data(), out);
    for (int t = 0; t < 16; ++t) EXPECT_EQ(texel(out, t), (Texel{0, 0, 0, 0})) << t;
}

}  // namespace
}  // namespace zhc
