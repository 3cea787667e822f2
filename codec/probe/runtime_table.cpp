// The codec table's runtime descriptions (runtime_table.h).
#include "codec/probe/runtime_table.h"

#include <string>

#include "codec/probe/quantize.h"

namespace zhc {

std::size_t runtime_layout_bytes(RuntimeLayout layout) {
    switch (layout) {
        case RuntimeLayout::kSh3F32: return 27 * 4;
        case RuntimeLayout::kSh2F32: return 12 * 4;
        case RuntimeLayout::kZh3F32: return 15 * 4;
        case RuntimeLayout::kZh3Q16: return packed_size_bytes(PackedLayout::kZh3Q16);
        case RuntimeLayout::kSh3Q28: return packed_size_bytes(PackedLayout::kSh3Q28);
        case RuntimeLayout::kSh2Q: return packed_size_bytes(PackedLayout::kSh2Q);
    }
    return 0;
}

std::string_view runtime_layout_name(RuntimeLayout layout) {
    switch (layout) {
        case RuntimeLayout::kSh3F32: return "sh3_f32";
        case RuntimeLayout::kSh2F32: return "sh2_f32";
        case RuntimeLayout::kZh3F32: return "zh3_f32";
        case RuntimeLayout::kZh3Q16: return "zh3_q16";
        case RuntimeLayout::kSh3Q28: return "sh3_q28";
        case RuntimeLayout::kSh2Q: return "sh2_q";
    }
    return "?";
}

std::string_view zonal_hallucination_name(ZonalHallucination h) {
    switch (h) {
        case ZonalHallucination::kNone: return "none";
        case ZonalHallucination::kAmbientDirectional: return "ambdir";
        case ZonalHallucination::kSphere: return "sphere";
        case ZonalHallucination::kCurve: return "curve";
        case ZonalHallucination::kCurveAdaptive: return "curve_adaptive";
    }
    return "?";
}

std::string_view zonal_axis_name(ZonalAxis a) {
    switch (a) {
        case ZonalAxis::kNone: return "none";
        case ZonalAxis::kLuminance: return "luminance";
        case ZonalAxis::kPerChannel: return "channel";
        case ZonalAxis::kFromParams: return "format";
    }
    return "?";
}

Result<RuntimeEntry> runtime_entry(const Codec& c) {
    RuntimeEntry e{c.name, c.summary, c.size_bytes, RuntimeLayout::kSh3F32, c.traits.hallucination,
                   c.traits.zonal_axis};
    const auto refuse = [&](const std::string& what) {
        return make_error(ErrorCode::kUnsupported, "codec table entry '" + std::string(c.name) + "': " + what);
    };
    const bool hall = e.hallucination != ZonalHallucination::kNone;
    // An engine layout's bytes are that engine's format (engine_layouts.h); zhc's runtimes read none
    // of them, whatever its size (realitykit_l1 has sh2_f32's 48 bytes, in other axes).
    if (!c.traits.engine.empty()) return refuse("an engine layout (" + std::string(c.traits.engine) + "): no zhc runtime reads it");
    if (c.packed) {
        switch (c.packed->layout) {
            case PackedLayout::kZh3Q16: e.layout = RuntimeLayout::kZh3Q16; break;
            case PackedLayout::kSh3Q28: e.layout = RuntimeLayout::kSh3Q28; break;
            case PackedLayout::kSh2Q: e.layout = RuntimeLayout::kSh2Q; break;
        }
        if (c.size_bytes != packed_size_bytes(c.packed->layout)) return refuse("size differs from its packed layout's");
    } else if (c.size_bytes == runtime_layout_bytes(RuntimeLayout::kSh3F32) && e.axis == ZonalAxis::kNone) {
        e.layout = RuntimeLayout::kSh3F32;
    } else if (c.size_bytes == runtime_layout_bytes(RuntimeLayout::kSh2F32)) {
        e.layout = RuntimeLayout::kSh2F32;
    } else if (c.size_bytes == runtime_layout_bytes(RuntimeLayout::kZh3F32) && e.axis != ZonalAxis::kNone) {
        e.layout = RuntimeLayout::kZh3F32;
    } else {
        return refuse("no runtime layout holds " + std::to_string(c.size_bytes) +
                      " float bytes with this zonal axis (runtime_table.h)");
    }
    if (hall && e.layout != RuntimeLayout::kSh2F32 && e.layout != RuntimeLayout::kSh2Q)
        return refuse("a hallucinated zonal term needs linear SH bytes (sh2_f32 or sh2_q)");
    if (e.hallucination == ZonalHallucination::kCurveAdaptive && e.layout != RuntimeLayout::kSh2Q)
        return refuse("the adaptive curve reads byte 15 of the sh2_q layout");
    if (e.layout == RuntimeLayout::kSh2Q && hall && e.hallucination != ZonalHallucination::kCurve &&
        e.hallucination != ZonalHallucination::kCurveAdaptive)
        return refuse("the sh2_q layout's decoders hallucinate by the Eq. 21 curve only");
    if (hall && e.axis == ZonalAxis::kNone) return refuse("a hallucinated zonal term needs a zonal axis");
    if (e.layout == RuntimeLayout::kSh2F32 && !hall && e.axis != ZonalAxis::kNone)
        return refuse("linear float SH without hallucination have no zonal axis");
    if (e.axis == ZonalAxis::kFromParams && e.layout != RuntimeLayout::kZh3Q16 && e.layout != RuntimeLayout::kSh2Q)
        return refuse("only the zh3_q16 and sh2_q layouts take the zonal axis from the format");
    if ((e.layout == RuntimeLayout::kSh3Q28 || (e.layout == RuntimeLayout::kSh2Q && !hall)) &&
        e.axis != ZonalAxis::kNone)
        return refuse("a layout without zonal term has no zonal axis");
    if ((e.layout == RuntimeLayout::kZh3Q16) && e.axis == ZonalAxis::kNone)
        return refuse("the zh3_q16 layout needs a zonal axis");
    return e;
}

}  // namespace zhc
