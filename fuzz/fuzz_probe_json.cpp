// JSON probe list parsing (formats/probes/probe_file.h) from untrusted bytes. A successful parse must give
// finite probes whose layout matches their count, and write back to JSON that parses identically.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "formats/probes/probe_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::ProbeJsonLimits limits;
    limits.max_probes = 1 << 12;
    limits.max_file_bytes = 1 << 20;
    auto list = zhc::parse_probe_json({data, size}, "fuzz-input", limits);
    if (!list) {
        if (list.error().message.empty()) std::abort();
        return 0;
    }
    const std::int64_t n = zhc::layout_probe_count(list->layout);
    if (n >= 0 && static_cast<std::size_t>(n) != list->probes.size()) std::abort();
    for (const auto& sh : list->probes)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k)
                if (!std::isfinite(sh[i][k])) std::abort();
    const std::string text = zhc::probe_json(*list);
    auto back = zhc::parse_probe_json({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()}, "again", limits);
    if (!back || back->probes.size() != list->probes.size()) std::abort();
    for (std::size_t p = 0; p < list->probes.size(); ++p)
        if (!(back->probes[p] == list->probes[p])) std::abort();
    return 0;
}
