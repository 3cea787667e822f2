// .zhp probe container parsing (formats/probes/probe_file.h) from untrusted bytes. A successful parse must
// give a valid set that decodes, and re-serialises to a file that parses to the same set.
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "formats/probes/probe_file.h"

namespace {
int check(std::span<const std::uint8_t> bytes) {
    zhc::ProbeFileLimits limits;
    limits.max_probes = 1 << 14;  // keeps executions fast; limit checks are still exercised
    limits.max_body_bytes = 1 << 22;
    auto set = zhc::parse_probe_set(bytes, "fuzz-input", limits);
    if (!set) {
        if (set.error().message.empty()) std::abort();
        return 0;
    }
    if (!zhc::validate_probe_set(*set)) std::abort();
    if (!zhc::decode_probe_set(*set)) std::abort();
    auto again = zhc::serialize_probe_set(*set);
    if (!again) std::abort();
    auto back = zhc::parse_probe_set(*again, "fuzz-again", limits);
    if (!back || back->payload != set->payload || back->count != set->count) std::abort();
    return 0;
}

void put_crc(std::vector<std::uint8_t>& b, std::size_t at, std::span<const std::uint8_t> over) {
    const std::uint32_t c = zhc::crc32(over);
    for (int i = 0; i < 4; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(c >> (8 * i));
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    check({data, size});
    // Again with both CRCs made valid, so mutations reach the field checks and the body decoding.
    if (size >= zhc::kProbeFileHeaderBytes) {
        std::vector<std::uint8_t> b(data, data + size);
        put_crc(b, 176, {b.data() + zhc::kProbeFileHeaderBytes, b.size() - zhc::kProbeFileHeaderBytes});
        put_crc(b, 180, {b.data(), 180});
        check(b);
    }
    return 0;
}
