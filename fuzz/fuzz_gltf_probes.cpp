// ZHC_light_probes reading (formats/probes/gltf_probes.h) from untrusted GLB / glTF JSON bytes. Inputs
// live in a directory that does not exist, so any external URI fails (the URI checks and the
// file-system guard are exercised without touching real files). A successful read gives valid sets;
// embedding one back into the same asset (as a volume of a new name) and reading again gives the
// same bytes.
#include <cstdint>
#include <cstdlib>

#include "formats/probes/gltf_probes.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::GltfLimits limits;
    limits.max_file_bytes = 1 << 22;
    limits.max_buffer_bytes = 1 << 20;  // keeps executions fast; limit checks are still exercised
    limits.max_total_bytes = 1 << 21;
    limits.max_probes = 1 << 12;
    const std::string path = "/nonexistent-zhc-fuzz/input.glb";
    auto s = zhc::read_gltf_probes({data, size}, path, limits);
    if (!s) {
        if (s.error().message.empty()) std::abort();
        return 0;
    }
    for (const zhc::GltfProbeVolume& v : s->volumes) {
        if (!zhc::validate_probe_set(v.set)) std::abort();
        if (!zhc::decode_probe_set(v.set)) std::abort();
    }
    if (s->volumes.empty() || s->volumes[0].set.count > 256) return 0;
    const zhc::ProbeSet& set = s->volumes[0].set;
    zhc::GltfEmbedOptions o;
    o.binary = (size & 1) != 0;
    o.name = "zhc_fuzz_embedded";  // a volume of a name the asset already has is refused (GltfEmbedOptions::replace)
    auto out = zhc::embed_probes_gltf({data, size}, path, set, o, limits);
    if (!out) return 0;  // e.g. the grown asset exceeds a limit
    auto back = zhc::read_gltf_probes(*out, path, limits);
    if (!back || back->volumes.size() != s->volumes.size() + 1) std::abort();
    // Float sets rotated from glTF axes are re-encoded on read; the zhc-axes path is exact.
    const zhc::GltfProbeVolume& last = back->volumes.back();
    if (last.set.count != set.count || last.set.representation != set.representation) std::abort();
    if (last.set.payload != set.payload) std::abort();
    return 0;
}
