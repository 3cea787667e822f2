// The codec table: concatenation of each module's entries, built once.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/zh3_window.h"

namespace zhc {

std::span<const Codec> codecs() {
    static const std::vector<Codec> table = [] {
        std::vector<Codec> all;
        // New entries go last: the runtime decoders (runtime/) number encodings by table order.
        for (auto part : {core_codecs(), zh3_codecs(), dering_codecs(), quantized_codecs(), zh3_window_codecs(),
                          zh3_channel_q16_codecs(), hall_codecs()})
            all.insert(all.end(), part.begin(), part.end());
        return all;
    }();
    return table;
}

const Codec* find_codec(std::string_view name) {
    for (const Codec& c : codecs())
        if (c.name == name) return &c;
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
