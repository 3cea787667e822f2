// BC7 block decoder (formats/envmap/bc7.h). Written from the Khronos Data Format Specification,
// section "BPTC Compressed Texture Image Formats", subsection BC7: the tables below are that
// section's tables (mode parameters, bptcP2subset, bptcP3subset, bptcA2index, bptcA32index,
// bptcA33index, BPTCInterpolation) transcribed into packed form.
#include "formats/envmap/bc7.h"

namespace zhc::bc7 {

namespace {

// The mode-dependent parameters (table "Mode-dependent BPTC parameters"): NS subsets, PB partition
// bits, RB rotation bits, ISB index selection bit, CB colour bits and AB alpha bits per channel
// and endpoint, EPB endpoint P-bits, SPB shared P-bits, IB and IB2 index bits per texel.
struct Mode {
    int ns, pb, rb, isb, cb, ab, epb, spb, ib, ib2;
};
constexpr Mode kModes[8] = {
    {3, 4, 0, 0, 4, 0, 1, 0, 3, 0},  // 0
    {2, 6, 0, 0, 6, 0, 0, 1, 3, 0},  // 1
    {3, 6, 0, 0, 5, 0, 0, 0, 2, 0},  // 2
    {2, 6, 0, 0, 7, 0, 1, 0, 2, 0},  // 3
    {1, 0, 2, 1, 5, 6, 0, 0, 2, 3},  // 4
    {1, 0, 2, 0, 7, 8, 0, 0, 2, 2},  // 5
    {1, 0, 0, 0, 7, 7, 1, 0, 4, 0},  // 6
    {2, 6, 0, 0, 5, 5, 1, 0, 2, 0},  // 7
};

// Two-subset partitions (bptcP2subset): bit t is the subset of texel t (t = x + 4 y).
constexpr std::uint16_t kPartition2[64] = {
    0xCCCC, 0x8888, 0xEEEE, 0xECC8, 0xC880, 0xFEEC, 0xFEC8, 0xEC80,
    0xC800, 0xFFEC, 0xFE80, 0xE800, 0xFFE8, 0xFF00, 0xFFF0, 0xF000,
    0xF710, 0x008E, 0x7100, 0x08CE, 0x008C, 0x7310, 0x3100, 0x8CCE,
    0x088C, 0x3110, 0x6666, 0x366C, 0x17E8, 0x0FF0, 0x718E, 0x399C,
    0xAAAA, 0xF0F0, 0x5A5A, 0x33CC, 0x3C3C, 0x55AA, 0x9696, 0xA55A,
    0x73CE, 0x13C8, 0x324C, 0x3BDC, 0x6996, 0xC33C, 0x9966, 0x0660,
    0x0272, 0x04E4, 0x4E40, 0x2720, 0xC936, 0x936C, 0x39C6, 0x639C,
    0x9336, 0x9CC6, 0x817E, 0xE718, 0xCCF0, 0x0FCC, 0x7744, 0xEE22,
};
// Three-subset partitions (bptcP3subset): bits 2t, 2t+1 are the subset of texel t.
constexpr std::uint32_t kPartition3[64] = {
    0xAA685050, 0x6A5A5040, 0x5A5A4200, 0x5450A0A8, 0xA5A50000, 0xA0A05050, 0x5555A0A0, 0x5A5A5050,
    0xAA550000, 0xAA555500, 0xAAAA5500, 0x90909090, 0x94949494, 0xA4A4A4A4, 0xA9A59450, 0x2A0A4250,
    0xA5945040, 0x0A425054, 0xA5A5A500, 0x55A0A0A0, 0xA8A85454, 0x6A6A4040, 0xA4A45000, 0x1A1A0500,
    0x0050A4A4, 0xAAA59090, 0x14696914, 0x69691400, 0xA08585A0, 0xAA821414, 0x50A4A450, 0x6A5A0200,
    0xA9A58000, 0x5090A0A8, 0xA8A09050, 0x24242424, 0x00AA5500, 0x24924924, 0x24499224, 0x50A50A50,
    0x500AA550, 0xAAAA4444, 0x66660000, 0xA5A0A5A0, 0x50A050A0, 0x69286928, 0x44AAAA44, 0x66666600,
    0xAA444444, 0x54A854A8, 0x95809580, 0x96969600, 0xA85454A8, 0x80959580, 0xAA141414, 0x96960000,
    0xAAAA1414, 0xA05050A0, 0xA0A5A5A0, 0x96000000, 0x40804080, 0xA9A8A9A8, 0xAAAAAA44, 0x2A4A5254,
};
// Anchor texel of subset 1 of a two-subset partition (bptcA2index).
constexpr std::uint8_t kAnchor2[64] = {
    15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 2,  8,  2,  2,  8,  8,  15, 2,  8,  2,  2,  8,  8,  2,  2,
    15, 15, 6,  8,  2,  8,  15, 15, 2,  8,  2,  2,  2,  15, 15, 6,  6,  2,  6,  8,  15, 15, 2,  2,  15, 15, 15, 15, 15, 2,  2,  15,
};
// Anchor texels of subsets 1 and 2 of a three-subset partition (bptcA32index, bptcA33index).
constexpr std::uint8_t kAnchor3a[64] = {
    3, 3,  15, 15, 8,  3, 15, 15, 8, 8,  6,  6,  6,  5,  3, 3, 3, 3, 8, 15, 3, 3,  6, 10, 5,  8,  8, 6, 8, 5, 15, 15,
    8, 15, 3,  5,  6,  10, 8, 15, 15, 3, 15, 5,  15, 15, 15, 15, 3, 15, 5, 5, 5, 8, 5, 10, 5, 10, 8, 13, 15, 12, 3, 3,
};
constexpr std::uint8_t kAnchor3b[64] = {
    15, 8, 8,  3,  15, 15, 3, 8,  15, 15, 15, 15, 15, 15, 15, 8, 15, 8, 15, 3, 15, 8, 15, 8, 3, 15, 6, 10, 15, 15, 10, 8,
    15, 3, 15, 10, 10, 8,  9, 10, 6,  15, 8,  15, 3,  6,  6,  8, 15, 3, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 3, 15, 15, 8,
};
// Interpolation weights (BPTCInterpolation), by index bits.
constexpr std::uint8_t kWeights2[4] = {0, 21, 43, 64};
constexpr std::uint8_t kWeights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
constexpr std::uint8_t kWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

// The table's anchors are texels of the subset they anchor.
constexpr bool anchors_in_their_subsets() {
    for (int p = 0; p < 64; ++p) {
        if ((kPartition2[p] & 1) != 0 || ((kPartition2[p] >> kAnchor2[p]) & 1) != 1) return false;
        if ((kPartition3[p] & 3) != 0 || ((kPartition3[p] >> (2 * kAnchor3a[p])) & 3) != 1 ||
            ((kPartition3[p] >> (2 * kAnchor3b[p])) & 3) != 2)
            return false;
    }
    return true;
}
static_assert(anchors_in_their_subsets());

// Every mode's fields fill the 128 bits exactly.
constexpr bool modes_fill_128_bits() {
    for (int k = 0; k < 8; ++k) {
        const Mode& m = kModes[k];
        const int endpoints = 2 * m.ns * (3 * m.cb + m.ab) + 2 * m.ns * m.epb + m.ns * m.spb;
        const int indices = 16 * m.ib - m.ns + (m.ib2 ? 16 * m.ib2 - 1 : 0);
        if (k + 1 + m.pb + m.rb + m.isb + endpoints + indices != 128) return false;
    }
    return true;
}
static_assert(modes_fill_128_bits());

// Reads the 128-bit block from bit 0 upwards (bit k is bit k % 8 of byte k / 8).
class BitReader {
public:
    explicit BitReader(const std::uint8_t* b) : b_(b) {}
    unsigned read(int n) {
        unsigned v = 0;
        for (int i = 0; i < n; ++i, ++pos_) v |= static_cast<unsigned>((b_[pos_ >> 3] >> (pos_ & 7)) & 1) << i;
        return v;
    }
    int pos() const { return pos_; }

private:
    const std::uint8_t* b_;
    int pos_ = 0;
};

const std::uint8_t* weights(int bits) { return bits == 2 ? kWeights2 : bits == 3 ? kWeights3 : kWeights4; }

}  // namespace

int block_mode(const std::uint8_t block[16]) {
    for (int m = 0; m < 8; ++m)
        if ((block[0] >> m) & 1) return m;
    return 8;
}

void decode_block(const std::uint8_t block[16], std::uint8_t rgba[16][4]) {
    const int mode = block_mode(block);
    if (mode == 8) {
        for (int t = 0; t < 16; ++t)
            for (int c = 0; c < 4; ++c) rgba[t][c] = 0;
        return;
    }
    const Mode& m = kModes[mode];
    BitReader in(block);
    in.read(mode + 1);
    const unsigned part = in.read(m.pb);
    const unsigned rotation = in.read(m.rb);
    const unsigned index_selection = in.read(m.isb);

    // Endpoint e of subset s is endpoint 2 s + e; fields are ordered channel, subset, endpoint.
    const int n_endpoints = 2 * m.ns;
    unsigned ep[6][4] = {};
    for (int c = 0; c < 3; ++c)
        for (int e = 0; e < n_endpoints; ++e) ep[e][c] = in.read(m.cb);
    for (int e = 0; e < n_endpoints; ++e) ep[e][3] = in.read(m.ab);  // AB = 0: read as 0 bits
    unsigned pbit[6] = {};
    if (m.epb)
        for (int e = 0; e < n_endpoints; ++e) pbit[e] = in.read(1);
    if (m.spb)
        for (int s = 0; s < m.ns; ++s) pbit[2 * s] = pbit[2 * s + 1] = in.read(1);
    const bool has_pbit = m.epb || m.spb;
    // Each channel: the stored bits, then the P-bit below them, then the top bits repeated into
    // the rest of the byte. No alpha bits: alpha is 255.
    std::uint8_t endpoint[6][4];
    for (int e = 0; e < n_endpoints; ++e)
        for (int c = 0; c < 4; ++c) {
            const int stored = c < 3 ? m.cb : m.ab;
            if (stored == 0) {
                endpoint[e][c] = 255;
                continue;
            }
            unsigned v = ep[e][c];
            int bits = stored;
            if (has_pbit) v = (v << 1) | pbit[e], ++bits;
            v <<= 8 - bits;
            v |= v >> bits;  // bits >= 5: one repetition fills the byte
            endpoint[e][c] = static_cast<std::uint8_t>(v);
        }

    // Subset of each texel and the anchors (their indices have one bit fewer).
    int subset[16] = {};
    bool anchor[16] = {};
    anchor[0] = true;
    if (m.ns == 2) {
        for (int t = 0; t < 16; ++t) subset[t] = (kPartition2[part] >> t) & 1;
        anchor[kAnchor2[part]] = true;
    } else if (m.ns == 3) {
        for (int t = 0; t < 16; ++t) subset[t] = static_cast<int>((kPartition3[part] >> (2 * t)) & 3);
        anchor[kAnchor3a[part]] = true;
        anchor[kAnchor3b[part]] = true;
    }
    unsigned primary[16], secondary[16] = {};
    for (int t = 0; t < 16; ++t) primary[t] = in.read(m.ib - (anchor[t] ? 1 : 0));
    if (m.ib2)  // one-subset modes only: texel 0 is the only anchor
        for (int t = 0; t < 16; ++t) secondary[t] = in.read(m.ib2 - (t == 0 ? 1 : 0));

    // Colour from the secondary indices when the index selection bit is 1, else the primary;
    // alpha from the secondary indices when there are some and the selection bit is 0.
    const bool colour_secondary = m.ib2 && index_selection == 1;
    const bool alpha_secondary = m.ib2 && index_selection == 0;
    const std::uint8_t* wc = weights(colour_secondary ? m.ib2 : m.ib);
    const std::uint8_t* wa = weights(alpha_secondary ? m.ib2 : m.ib);
    for (int t = 0; t < 16; ++t) {
        const std::uint8_t* e0 = endpoint[2 * subset[t]];
        const std::uint8_t* e1 = endpoint[2 * subset[t] + 1];
        const unsigned w_colour = wc[colour_secondary ? secondary[t] : primary[t]];
        const unsigned w_alpha = wa[alpha_secondary ? secondary[t] : primary[t]];
        for (int c = 0; c < 4; ++c) {
            const unsigned w = c < 3 ? w_colour : w_alpha;
            rgba[t][c] = static_cast<std::uint8_t>(((64 - w) * e0[c] + w * e1[c] + 32) >> 6);
        }
        // Rotation 1, 2, 3 swaps alpha with red, green, blue.
        if (rotation != 0) {
            const std::uint8_t a = rgba[t][3];
            rgba[t][3] = rgba[t][rotation - 1];
            rgba[t][rotation - 1] = a;
        }
    }
}

}  // namespace zhc::bc7
