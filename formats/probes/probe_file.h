// zhc/formats/probes/probe_file.h — the .zhp probe-set container and the JSON probe list.
//
// .zhp (spec: docs/zhp-container.md): a fixed 184-byte little-endian header (magic, version,
// storage parameters, representation name, probe count, layout, body sizes, CRC-32 of the body
// and of the header) followed by the body: explicit positions (if any) then the payload, then
// (version 2 only) the sections: validity and/or visibility bytes and cell planes per probe, the
// tetrahedra of a positions layout; the whole body optionally zstd-compressed. A set without any
// section is written as version 1. The reader is strict and safe for untrusted input: it
// checks limits before allocating and reports each problem with its own error code:
//   kTruncated      the bytes end before the header or the declared body ends
//   kTrailingBytes  bytes after the declared body
//   kBadFormat      wrong magic, malformed field, reserved bytes set, zstd stream damaged
//   kUnsupported    unknown version, representation, or enum value (a newer writer)
//   kChecksum       header or body CRC-32 mismatch
//   kTooLarge       probe count or body size above the limits
//   kInvalidValue   non-finite positions, grid or luminance weights
//
// JSON probe list (schema: docs/zhp-container.md, "JSON probe list"): float SH3 per probe, the
// interchange/debugging form:
//   {"format": "zhc-probes", "version": 1, "kind": "radiance",
//    "layout": {"type": "grid", "origin": [x,y,z], "spacing": [x,y,z], "counts": [nx,ny,nz]},
//    "probes": [{"position": [x,y,z], "sh3": [[r,g,b], ... 9 rows]}, ...]}
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "codec/probe/probe_set.h"
#include "codec/status.h"

namespace zhc {

inline constexpr std::uint16_t kProbeFileVersion = 1;      // no per-probe sections
inline constexpr std::uint16_t kProbeFileVersionLeak = 2;  // sections: validity, visibility, planes, tetrahedra
inline constexpr std::size_t kProbeFileHeaderBytes = 184;

struct ProbeFileLimits {
    std::uint64_t max_probes = std::uint64_t(1) << 26;      // 67M probes
    std::uint64_t max_body_bytes = std::uint64_t(1) << 31;  // 2 GiB decompressed
    std::uint64_t max_file_bytes = std::uint64_t(1) << 31;
};

struct ProbeFileWriteOptions {
    int zstd_level = 0;  // 0: store the body uncompressed; 1..22: zstd level
};

// What the header said, for `zhc info`.
struct ProbeFileInfo {
    std::uint16_t version = 0;
    bool compressed = false;
    std::uint64_t raw_body_bytes = 0;
    std::uint64_t stored_body_bytes = 0;
    std::uint64_t file_bytes = 0;
    std::uint32_t body_crc32 = 0;
};

// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, initial and final XOR 0xFFFFFFFF).
std::uint32_t crc32(std::span<const std::uint8_t> bytes);

// True when the bytes start with the .zhp magic.
bool looks_like_probe_file(std::span<const std::uint8_t> bytes);

// Serialises a valid set (validate_probe_set); deterministic for a given zstd level.
Result<std::vector<std::uint8_t>> serialize_probe_set(const ProbeSet& set, const ProbeFileWriteOptions& options = {});
// Parses a whole file; `name` is used in messages.
Result<ProbeSet> parse_probe_set(std::span<const std::uint8_t> bytes, const std::string& name,
                                 const ProbeFileLimits& limits = {}, ProbeFileInfo* info = nullptr);

// parse_probe_set, then every probe decoded to the hub and checked with check_finite_probes: what
// the verbs that compute with a file's probes (convert, audit, gltf embed) read.
struct DecodedProbeSet {
    ProbeSet set;
    std::vector<Sh3Radiance> hub;
};
Result<DecodedProbeSet> parse_and_decode_probe_set(std::span<const std::uint8_t> bytes, const std::string& name);

Status write_probe_file(const std::string& path, const ProbeSet& set, const ProbeFileWriteOptions& options = {});
Result<ProbeSet> read_probe_file(const std::string& path, const ProbeFileLimits& limits = {},
                                 ProbeFileInfo* info = nullptr);

// ok when every coefficient of every probe is finite, else kInvalidValue naming `name` and the
// first probe with NaN/Inf. A .zhp or glTF payload can hold them (float entries store any bits; a
// half or R11G11B10F DC can encode Inf/NaN): the verbs that compute with probes (convert, audit,
// gltf embed) refuse such input (exit 4) instead of encoding or averaging NaN; zhc info describes
// it (non_finite_probes).
Status check_finite_probes(std::span<const Sh3Radiance> probes, const std::string& name);

// ---- JSON probe list -----------------------------------------------------------------------

struct ProbeList {
    std::vector<Sh3Radiance> probes;  // hub (radiance) — irradiance input is converted on read
    ProbeLayout layout;
};

struct ProbeJsonLimits {
    std::uint64_t max_probes = std::uint64_t(1) << 22;
    std::uint64_t max_file_bytes = std::uint64_t(1) << 30;
};

// True when the first non-blank byte is '{'.
bool looks_like_json(std::span<const std::uint8_t> bytes);
Result<ProbeList> parse_probe_json(std::span<const std::uint8_t> bytes, const std::string& name,
                                   const ProbeJsonLimits& limits = {});
std::string probe_json(const ProbeList& list);
Status write_probe_json(const std::string& path, const ProbeList& list);
Result<ProbeList> read_probe_json(const std::string& path, const ProbeJsonLimits& limits = {});

}  // namespace zhc
