// The codec table: concatenation of each module's entries, built once.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "codec/probe/codec.h"

// The parts of the table: one line per codec module, X(the module's part function), in table order.
// The table's order is the runtime encoding ids (the runtimes' generated tables, written by
// `cmake --build build --target update_runtime_tables`, docs/runtime.md "Generated tables"), so a
// new module's line goes after the last of zhc's own modules and no such line ever moves or goes
// (the runtime tests fail otherwise; a module split in two keeps its entries' order with two
// adjacent lines, as zh3, zh3_hallucinated and zh3_clamp do). The engine layouts
// (engine_layouts.h) come after every zhc module: the runtimes do not read them, so they have no
// runtime id, and runtime_codecs() is the prefix before them (tests/test_engine_layouts.cpp checks
// that they form the table's tail). This list is the only edit outside a new module's own files
// (plus its source line in codec/CMakeLists.txt) and the regenerated runtime tables. Static
// self-registration would need no list, but objects of a static library that nothing references
// are dropped by the linker, and the order would follow the link order.
#define ZHC_CODEC_PARTS(X)      \
    X(core_codecs)             \
    X(zh3_codecs)              \
    X(zh3_hallucinated_codecs) \
    X(zh3_clamp_codecs)        \
    X(dering_codecs)           \
    X(quantized_codecs)        \
    X(zh3_dering_codecs)       \
    X(zh3_channel_q16_codecs)  \
    X(hall_solve_codecs)       \
    /* a new zhc module's line goes here, before the engine layouts */ \
    X(engine_codecs)

namespace zhc {

#define ZHC_DECLARE_PART(part) std::span<const Codec> part();
ZHC_CODEC_PARTS(ZHC_DECLARE_PART)
#undef ZHC_DECLARE_PART

std::span<const Codec> codecs() {
    static const std::vector<Codec> table = [] {
        std::vector<Codec> all;
#define ZHC_CALL_PART(part) part(),
        for (std::span<const Codec> part : {ZHC_CODEC_PARTS(ZHC_CALL_PART)})
            all.insert(all.end(), part.begin(), part.end());
#undef ZHC_CALL_PART
        return all;
    }();
    return table;
}

std::span<const Codec> runtime_codecs() {
    static const std::span<const Codec> prefix = [] {
        const std::span<const Codec> all = codecs();
        std::size_t n = 0;
        while (n < all.size() && all[n].traits.engine.empty()) ++n;
        return all.first(n);
    }();
    return prefix;
}

std::span<const CodecAlias> codec_aliases() {
    static constexpr CodecAlias kAliases[] = {
        {"zh3_lum_dering", "zh3_lum_axis_clamp"},
        {"zh3_lum_dering_sphere", "zh3_lum_sphere_clamp"},
    };
    return kAliases;
}

const Codec* find_codec(std::string_view name) {
    for (const Codec& c : codecs())
        if (c.name == name) return &c;
    for (const CodecAlias& a : codec_aliases())
        if (a.alias == name)
            for (const Codec& c : codecs())
                if (c.name == a.name) return &c;
    return nullptr;
}

Result<std::vector<const Codec*>> select_codecs(std::string_view names) {
    std::vector<const Codec*> out;
    if (names.empty()) {
        for (const Codec& c : codecs()) out.push_back(&c);
        return out;
    }
    for (size_t begin = 0; begin <= names.size();) {
        const size_t end = std::min(names.find(',', begin), names.size());
        const std::string_view name = names.substr(begin, end - begin);
        const Codec* c = find_codec(name);
        if (!c) {
            std::string known;
            for (const Codec& k : codecs()) known += (known.empty() ? "" : ", ") + std::string(k.name);
            return make_error(ErrorCode::kInvalidArgument, "--representations: unknown representation '" +
                                                               std::string(name) + "' (known: " + known + ")");
        }
        out.push_back(c);
        begin = end + 1;
    }
    return out;
}

void store_floats(std::span<const float> values, std::uint8_t* out) {
    for (size_t i = 0; i < values.size(); ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, &values[i], 4);
        for (int b = 0; b < 4; ++b) out[i * 4 + static_cast<size_t>(b)] = static_cast<std::uint8_t>(bits >> (8 * b));
    }
}

void load_floats(const std::uint8_t* in, std::span<float> values) {
    for (size_t i = 0; i < values.size(); ++i) {
        std::uint32_t bits = 0;
        for (int b = 0; b < 4; ++b) bits |= std::uint32_t(in[i * 4 + static_cast<size_t>(b)]) << (8 * b);
        std::memcpy(&values[i], &bits, 4);
    }
}

}  // namespace zhc
