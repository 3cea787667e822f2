// The engines' probe files (formats/engines/engine_files.h) from untrusted bytes: at most one entry
// sniffs the bytes as its own, and every entry's reader runs on every input (sniffed or not). A reader either fails with a message or gives probes
// that are finite, match their layout's count (and validity's), and, for small sets, write back
// into a file the same reader reads with the same count and layout kind.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "formats/engines/engine_files.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::uint8_t> bytes(data, size);
    int claimed = 0;  // the entries' sniffs are exclusive: at most one claims any bytes
    for (const zhc::EngineFile& f : zhc::engine_files()) claimed += f.sniff(bytes) ? 1 : 0;
    if (claimed > 1) std::abort();
    for (const zhc::EngineFile& f : zhc::engine_files()) {
        auto probes = f.read(bytes, "fuzz-input");
        if (!probes) {
            if (probes.error().message.empty()) std::abort();
            continue;
        }
        const std::int64_t n = zhc::layout_probe_count(probes->layout);
        if (n < 0 || static_cast<std::size_t>(n) != probes->hub.size()) std::abort();
        if (!probes->validity.empty() && probes->validity.size() != probes->hub.size()) std::abort();
        for (const zhc::Sh3Radiance& sh : probes->hub)
            for (int i = 0; i < 9; ++i)
                for (int c = 0; c < 3; ++c)
                    if (!std::isfinite(sh[i][c])) std::abort();
        if (probes->hub.size() > 64) continue;  // writing back: small sets only (tetrahedra, BSP)
        zhc::EngineFileInput in;
        in.hub = probes->hub;
        in.layout = probes->layout;
        in.validity = probes->validity;
        auto out = f.write(in);
        if (!out) {
            if (out.error().message.empty()) std::abort();
            continue;
        }
        auto back = f.read(out->bytes, "again");
        if (!back || back->layout.kind != probes->layout.kind) std::abort();
    }
    return 0;
}
