// zhc/codec/probe/runtime_table.h — what the runtimes (runtime/: C, HLSL, GLSL, WGSL, JavaScript)
// must agree on with the codec table, derived from it.
//
// Each runtime decodes an entry's bytes by its layout (how the bytes are laid out), the zonal term
// its decoder hallucinates and the zonal axis, never by the entry's name or id; ids are the table's
// order. runtime_entry() derives those three from the entry (Codec::packed, size_bytes, traits),
// and tools/gen_runtime_tables.cpp writes them, with the names, sizes and the CodecOptions
// defaults, into the runtime files between "BEGIN GENERATED" / "END GENERATED" lines
// (docs/runtime.md, "Generated tables"). So a new entry whose bytes one of these layouts holds
// reaches every runtime through the generator alone; an entry with a new layout needs a new layout
// here and a decoder in each runtime.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "codec/probe/codec.h"
#include "codec/status.h"

namespace zhc {

// The runtimes' byte layouts ("families" in the shaders). Values are the runtimes' constants.
enum class RuntimeLayout : std::uint8_t {
    kSh3F32 = 0,  // 27 little-endian floats, [coefficient][R, G, B]
    kSh2F32 = 1,  // 12 floats: DC and L1 (L2 hallucinated or zero)
    kZh3F32 = 2,  // 15 floats: DC, L1, then the zonal coefficient of R, G, B
    kZh3Q16 = 3,  // PackedLayout::kZh3Q16 (16 bytes)
    kSh3Q28 = 4,  // PackedLayout::kSh3Q28 (28 bytes)
    kSh2Q = 5,    // PackedLayout::kSh2Q (16 bytes)
};
inline constexpr int kRuntimeLayoutCount = 6;
inline constexpr int kZonalHallucinationCount = 5;  // codec.h ZonalHallucination
inline constexpr int kZonalAxisCount = 4;           // codec.h ZonalAxis

// Lower-case names the generated tables use ("sh3_f32", "none", "curve_adaptive", "luminance").
std::string_view runtime_layout_name(RuntimeLayout layout);
// Stored bytes of one probe in a layout (108, 48, 60, then the packed layouts' 16, 28, 16).
std::size_t runtime_layout_bytes(RuntimeLayout layout);
std::string_view zonal_hallucination_name(ZonalHallucination h);
std::string_view zonal_axis_name(ZonalAxis a);  // "none", "luminance", "channel", "format"

struct RuntimeEntry {
    std::string_view name, summary;
    std::size_t size_bytes = 0;
    RuntimeLayout layout = RuntimeLayout::kSh3F32;
    ZonalHallucination hallucination = ZonalHallucination::kNone;
    ZonalAxis axis = ZonalAxis::kNone;
};

// The runtime description of `c`: packed entries take their PackedLayout; float entries are named
// by size and traits (108 bytes without zonal axis: sh3_f32; 48 bytes: sh2_f32, hallucinated when
// the entry says so; 60 bytes with a zonal axis and no hallucination: zh3_f32). kUnsupported naming
// the entry when no runtime layout holds its bytes or the traits contradict the layout (a
// hallucination outside sh2_f32 / sh2_q, sh2_q with a model other than the two curves, the
// adaptive curve outside sh2_q, an axis "format" on a float layout), and for every engine layout
// (CodecTraits::engine: the runtimes read zhc's representations only, codec.h runtime_codecs()).
Result<RuntimeEntry> runtime_entry(const Codec& c);

}  // namespace zhc
