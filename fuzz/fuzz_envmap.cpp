// Environment-map loading (OpenEXR through OpenEXR after zhc's header and chunk-table walk,
// Radiance .hdr and KTX2 / KTX 1 / DDS cube maps through zhc's own readers) from untrusted bytes; a successful load must be finite
// and in limits and project (lat-long or cube) to finite SH; an error is one non-empty line.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "formats/envmap/envmap.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::EnvmapReadOptions o;
    o.max_pixels = 1 << 12;  // keeps executions fast; size checks are still exercised
    o.max_file_bytes = 1 << 24;
    // Warnings (an EXR's windows, an 8-bit UNORM cube read as linear) must be one line too.
    o.warn = [](const std::string& line) {
        if (line.empty() || line.find('\n') != std::string::npos) std::abort();
    };
    // Seeds choose the 8-bit decoding by their first byte's low bits, so RGBM / RGBD (a division
    // by alpha) are exercised as well as the format's own transfer function.
    if (size > 0) {
        const char* choices[] = {"auto", "srgb", "rgbm:8", "rgbd:255"};
        (void)zhc::parse_ldr_decoding(choices[data[size - 1] & 3], &o.ldr);
    }
    auto img = zhc::read_envmap_memory({data, size}, "fuzz-input", o);
    if (img) {
        if (static_cast<std::uint64_t>(img->width) * img->height > o.max_pixels) std::abort();
        if (img->rgb.size() != static_cast<size_t>(img->width) * img->height * 3) std::abort();
        for (float v : img->rgb)
            if (!std::isfinite(v)) std::abort();
        if (img->layout != zhc::EnvmapLayout::kLatLong && img->height != 6 * img->width) std::abort();
        (void)zhc::project_envmap(*img);  // sums of finite floats times weights: no UB
    } else if (img.error().message.empty() || img.error().message.find('\n') != std::string::npos) {
        std::abort();
    }
    return 0;
}
