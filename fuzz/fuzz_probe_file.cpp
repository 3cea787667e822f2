// .zhp probe container parsing (formats/probe_file.h) from untrusted bytes. A successful parse must
// give a valid set that decodes, and re-serialises to a file that parses to the same set.
#include <cstdint>
#include <cstdlib>

#include "formats/probe_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::ProbeFileLimits limits;
    limits.max_probes = 1 << 14;  // keeps executions fast; limit checks are still exercised
    limits.max_body_bytes = 1 << 22;
    auto set = zhc::parse_probe_set({data, size}, "fuzz-input", limits);
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
