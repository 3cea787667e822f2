// zhc/codec/lightmap/bc6h.h — BC6H unsigned (BC6H_UFLOAT, DXGI_FORMAT_BC6H_UF16) encoder and decoder.
//
// Written from the format description (D3D11 "BC6H format", Khronos Data Format Specification
// "BPTC compressed formats"); see docs/lightmap-formats.md. Standard library only, no I/O.
//
// Decoder: total. Every one of the 2^128 block patterns decodes to defined half floats: the four
// reserved mode codes (10011, 10111, 11011, 11111) decode to zero in all channels, as the D3D
// specification says; everything else follows the spec bit for bit (results are always finite,
// non-negative halves <= 0x7BFF).
//
// Encoder: error is measured in the half-float bit pattern domain (a piecewise-linear log2: bits
// / 1024 ~ log2(v) + 15), which is also the domain BC6H interpolates in, so the fit is linear.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace zhc::bc6h {

enum class Quality {
    kMode11,      // baseline: one-subset 10-bit mode (mode code 00011) only, one refinement
    kFast,        // one fitting one-subset mode, no refinement; poorly fitting blocks: + the best-scoring partition
    kDefault,     // one-subset mode refined; poorly fitting blocks: 6 partitions screened, the best refined
    kExhaustive,  // all 14 modes x all 32 partitions, more refinement: the quality reference
    // All but kMode11 encode constant blocks exactly (mode 14, zero error) without a search.
};

// Half-float bits <-> float (round to nearest even; no dependence on the FPU's half support).
std::uint16_t float_to_half(float f);
float half_to_float(std::uint16_t h);
// The unsigned value BC6H_UF16 can hold for f: NaN and negatives -> 0, > 65504 -> 0x7BFF.
std::uint16_t float_to_uf16(float f);

// 16 texels in row-major order (texel x + 4 y), RGB.
void encode_block(const float rgb[16][3], Quality quality, std::uint8_t out[16]);
void decode_block(const std::uint8_t in[16], std::uint16_t out_half[16][3]);

// Mode index 0..13 in the D3D numbering minus one (mode 1 = code 00 ... mode 14 = code 01111),
// or -1 for a reserved code. For statistics and tests.
int block_mode(const std::uint8_t in[16]);
// Self-check of the header layout tables: every mode stores each endpoint bit exactly once
// (w: ep_bits per channel, x/y/z: the delta precision), and the header ends at bit 77 (two
// subsets, before the 5 partition bits) or 65 (one subset).
bool layout_is_consistent();

// Whole images (interleaved RGB float, width x height, any size: edge blocks replicate the last
// row/column). Blocks are row-major; the result does not depend on `threads`.
std::vector<std::uint8_t> encode_image(const float* rgb, int width, int height, Quality quality, int threads = 1);

// The encoder exists twice: for baseline x86-64 (SSE2) and for AVX2 (x86-64 only), chosen at run
// time (best_isa). Both write the same bytes (the same float operations in the same order; tested),
// AVX2 is faster (wider vectors). encode_block and the encode_image above use best_isa().
enum class Isa { kBaseline, kAvx2 };
bool isa_supported(Isa isa);
Isa best_isa();
const char* isa_name(Isa isa);
// encode_image with a given instruction set (unsupported: baseline). For tests and benchmarks.
std::vector<std::uint8_t> encode_image(const float* rgb, int width, int height, Quality quality, int threads, Isa isa);
// Decodes into interleaved RGB half bits (width x height).
std::vector<std::uint16_t> decode_image(const std::uint8_t* blocks, std::size_t size, int width, int height);

}  // namespace zhc::bc6h
