// BC7 block decoder (formats/envmap/bc7.h). Written from the Khronos Data Format Specification,
// section "BPTC Compressed Texture Image Formats", subsection BC7: the tables below are that
// section's tables (mode parameters, bptcP2subset, bptcP3subset, bptcA2index, bptcA32index,
// bptcA33index, BPTCInterpolation) transcribed into packed form.
#include "formats/envmap/bc7.h"

#include "codec/lightmap/bptc_tables.h"

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

using bptc::kAnchor2;
using bptc::kAnchor3a;
using bptc::kAnchor3b;
using bptc::kPartition2;
using bptc::kPartition3;
using bptc::kWeights2;
using bptc::kWeights3;
using bptc::kWeights4;

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

const int* weights(int bits) { return bits == 2 ? kWeights2 : bits == 3 ? kWeights3 : kWeights4; }

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
    const int* wc = weights(colour_secondary ? m.ib2 : m.ib);
    const int* wa = weights(alpha_secondary ? m.ib2 : m.ib);
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
