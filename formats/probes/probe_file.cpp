// The .zhp container and the JSON probe list (probe_file.h, docs/zhp-container.md).
#include "formats/probes/probe_file.h"

#include "formats/io/le_bytes.h"

#include <zstd.h>

#include <array>
#include <cmath>
#include <limits>
#include <cstring>
#include <nlohmann/json.hpp>

#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"

namespace zhc {

// ---- CRC-32 --------------------------------------------------------------------------------

namespace {
std::array<std::uint32_t, 256> make_crc_table() {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        t[i] = c;
    }
    return t;
}
}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
    static const std::array<std::uint32_t, 256> table = make_crc_table();
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::uint8_t b : bytes) c = table[(c ^ b) & 0xFFu] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

// ---- header layout -------------------------------------------------------------------------

namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'Z', 'H', 'P', 0x0D, 0x0A, 0x1A, 0x0A};

// Field offsets (docs/zhp-container.md, "Header").
enum : std::size_t {
    kOffMagic = 0,
    kOffVersion = 8,        // u16
    kOffHeaderBytes = 10,   // u16
    kOffKind = 12,          // u8 0 radiance 1 irradiance
    kOffBits = 13,          // u8 2..8
    kOffDcFormat = 14,      // u8
    kOffL2Bound = 15,       // u8
    kOffSqrt = 16,          // u8 0/1
    kOffZonalMapping = 17,  // u8
    kOffAxisMode = 18,      // u8
    kOffCompression = 19,   // u8 0 none 1 zstd
    kOffLayoutKind = 20,    // u8
    kOffLeakFlags = 21,     // u8 version 2: bit 0 validity, bit 1 visibility, bit 2 planes, bit 3 tetrahedra (version 1: zero)
    kOffReserved0 = 22,     // 2 bytes zero
    kOffName = 24,          // 32 bytes ASCII, zero padded
    kNameBytes = 32,
    kOffCount = 56,         // u64
    kOffProbeBytes = 64,    // u32
    kOffReserved1 = 68,     // u32 zero
    kOffLuminance = 72,     // 3 x f64
    kOffOrigin = 96,        // 3 x f64
    kOffSpacing = 120,      // 3 x f64
    kOffCounts = 144,       // 3 x u32
    kOffReserved2 = 156,    // u32 zero
    kOffRawBody = 160,      // u64
    kOffStoredBody = 168,   // u64
    kOffBodyCrc = 176,      // u32
    kOffHeaderCrc = 180,    // u32 over [0, 180)
};
static_assert(kOffHeaderCrc + 4 == kProbeFileHeaderBytes);

Error err(ErrorCode code, const std::string& name, const std::string& what) {
    return make_error(code, name + ": " + what);
}

std::uint64_t positions_bytes(const ProbeSet& set) {
    return set.layout.kind == ProbeLayoutKind::kPositions ? set.count * 12 : 0;
}

constexpr std::uint8_t kLeakValidity = 1, kLeakVisibility = 2, kLeakPlanes = 4, kLeakTetrahedra = 8;

std::uint8_t leak_flags(const ProbeSet& set) {
    return static_cast<std::uint8_t>((set.validity.empty() ? 0 : kLeakValidity) |
                                     (set.visibility.empty() ? 0 : kLeakVisibility) |
                                     (set.planes.empty() ? 0 : kLeakPlanes) |
                                     (set.tetrahedra.empty() ? 0 : kLeakTetrahedra));
}

// The tetrahedra section: u32 count T, T x 4 u32 probe indices, T x 4 i32 neighbours.
std::uint64_t tetrahedra_bytes(const ProbeSet& set) {
    return set.tetrahedra.empty() ? 0 : 4 + 32 * static_cast<std::uint64_t>(set.tetrahedra.size());
}

}  // namespace

bool looks_like_probe_file(std::span<const std::uint8_t> bytes) {
    return bytes.size() >= sizeof kMagic && std::memcmp(bytes.data(), kMagic, sizeof kMagic) == 0;
}

// ---- writer --------------------------------------------------------------------------------

Result<std::vector<std::uint8_t>> serialize_probe_set(const ProbeSet& set, const ProbeFileWriteOptions& options) {
    if (Status st = validate_probe_set(set); !st) return st.error();
    const std::string_view rep_name = set.codec()->name;  // the entry's own name, never an alias
    if (rep_name.size() >= kNameBytes)
        return make_error(ErrorCode::kInvalidArgument, "representation name longer than 31 bytes");
    if (options.zstd_level < 0 || options.zstd_level > ZSTD_maxCLevel())
        return make_error(ErrorCode::kInvalidArgument,
                          "zstd level must be 0 (none) .. " + std::to_string(ZSTD_maxCLevel()));
    const std::uint8_t leak = leak_flags(set);
    std::vector<std::uint8_t> body(positions_bytes(set) + set.payload.size() + set.validity.size() +
                                   set.visibility.size() + set.planes.size() + tetrahedra_bytes(set));
    if (set.layout.kind == ProbeLayoutKind::kPositions)
        for (size_t i = 0; i < set.count; ++i)
            for (size_t c = 0; c < 3; ++c) le::store_f32(body.data() + 12 * i + 4 * c, set.layout.positions[i][c]);
    if (!set.payload.empty()) std::memcpy(body.data() + positions_bytes(set), set.payload.data(), set.payload.size());
    // Version 2 sections after the payload: validity, visibility (one byte per probe each), planes
    // (5 bytes per probe).
    std::size_t at = positions_bytes(set) + set.payload.size();
    for (const std::vector<std::uint8_t>* v : {&set.validity, &set.visibility, &set.planes}) {
        if (!v->empty()) std::memcpy(body.data() + at, v->data(), v->size());
        at += v->size();
    }
    // Then the tetrahedra (positions layouts): their count, the probe indices, the neighbours.
    if (!set.tetrahedra.empty()) {
        const std::size_t t_count = set.tetrahedra.size();
        le::store(body.data() + at, t_count, 4);
        for (std::size_t t = 0; t < t_count; ++t)
            for (std::size_t k = 0; k < 4; ++k) {
                le::store(body.data() + at + 4 + 16 * t + 4 * k, set.tetrahedra[t][k], 4);
                le::store(body.data() + at + 4 + 16 * (t_count + t) + 4 * k,
                          static_cast<std::uint32_t>(set.tetra_neighbours[t][k]), 4);
            }
    }
    const std::uint64_t raw_bytes = body.size();
    if (options.zstd_level > 0) {
        std::vector<std::uint8_t> packed(ZSTD_compressBound(body.size()));
        // Single-threaded one-shot compression: the output depends only on the input and level.
        const size_t n = ZSTD_compress(packed.data(), packed.size(), body.data(), body.size(), options.zstd_level);
        if (ZSTD_isError(n)) return make_error(ErrorCode::kInternal, std::string("zstd: ") + ZSTD_getErrorName(n));
        packed.resize(n);
        body.swap(packed);
    }
    std::vector<std::uint8_t> out(kProbeFileHeaderBytes + body.size(), 0);
    std::uint8_t* h = out.data();
    std::memcpy(h + kOffMagic, kMagic, sizeof kMagic);
    // A set without leak data is written as version 1, byte for byte as before version 2 existed.
    le::store(h + kOffVersion, leak ? kProbeFileVersionLeak : kProbeFileVersion, 2);
    le::store(h + kOffHeaderBytes, kProbeFileHeaderBytes, 2);
    const CodecOptions& p = set.params;
    h[kOffKind] = static_cast<std::uint8_t>(p.kind);
    h[kOffBits] = static_cast<std::uint8_t>(p.bits);
    h[kOffDcFormat] = static_cast<std::uint8_t>(p.dc_format);
    h[kOffL2Bound] = static_cast<std::uint8_t>(p.l2_bound);
    h[kOffSqrt] = p.sqrt_encoding ? 1 : 0;
    h[kOffZonalMapping] = static_cast<std::uint8_t>(p.zonal_mapping);
    h[kOffAxisMode] = static_cast<std::uint8_t>(p.axis_mode);
    h[kOffCompression] = options.zstd_level > 0 ? 1 : 0;
    h[kOffLayoutKind] = static_cast<std::uint8_t>(set.layout.kind);
    h[kOffLeakFlags] = leak;
    std::memcpy(h + kOffName, rep_name.data(), rep_name.size());
    le::store(h + kOffCount, set.count, 8);
    le::store(h + kOffProbeBytes, set.codec()->size_bytes, 4);
    le::store_f64(h + kOffLuminance, p.luminance.r);
    le::store_f64(h + kOffLuminance + 8, p.luminance.g);
    le::store_f64(h + kOffLuminance + 16, p.luminance.b);
    if (set.layout.kind == ProbeLayoutKind::kGrid) {
        const ProbeGrid& g = set.layout.grid;
        for (int c = 0; c < 3; ++c) {
            le::store_f64(h + kOffOrigin + 8 * static_cast<size_t>(c), g.origin[c]);
            le::store_f64(h + kOffSpacing + 8 * static_cast<size_t>(c), g.spacing[c]);
            le::store(h + kOffCounts + 4 * static_cast<size_t>(c), g.counts[static_cast<size_t>(c)], 4);
        }
    }
    le::store(h + kOffRawBody, raw_bytes, 8);
    le::store(h + kOffStoredBody, body.size(), 8);
    le::store(h + kOffBodyCrc, crc32(body), 4);
    le::store(h + kOffHeaderCrc, crc32({h, kOffHeaderCrc}), 4);
    if (!body.empty()) std::memcpy(out.data() + kProbeFileHeaderBytes, body.data(), body.size());
    return out;
}

// ---- reader --------------------------------------------------------------------------------

Result<ProbeSet> parse_probe_set(std::span<const std::uint8_t> bytes, const std::string& name,
                                 const ProbeFileLimits& limits, ProbeFileInfo* info) {
    if (bytes.empty()) return err(ErrorCode::kTruncated, name, "empty file (a .zhp starts with a 184-byte header)");
    const std::uint8_t* h = bytes.data();
    // 1. Magic: a short file that is a prefix of the magic is truncated, anything else is not ours.
    const size_t magic_have = std::min(bytes.size(), sizeof kMagic);
    if (std::memcmp(h, kMagic, magic_have) != 0)
        return err(ErrorCode::kBadFormat, name, "not a .zhp probe file (bad magic at byte 0)" + git_lfs_hint(bytes));
    if (bytes.size() < kOffVersion + 2)
        return err(ErrorCode::kTruncated, name, "file ends inside the header (" + std::to_string(bytes.size()) +
                                                    " of " + std::to_string(kProbeFileHeaderBytes) + " bytes)");
    // 2. Version before anything version-specific (a newer file may have another header size).
    const auto version = static_cast<std::uint16_t>(le::load(h + kOffVersion, 2));
    if (version != kProbeFileVersion && version != kProbeFileVersionLeak)
        return err(ErrorCode::kUnsupported, name, ".zhp version " + std::to_string(version) +
                                                      " is not supported (this zhc reads versions 1 and 2)");
    if (bytes.size() < kProbeFileHeaderBytes)
        return err(ErrorCode::kTruncated, name, "file ends inside the header (" + std::to_string(bytes.size()) +
                                                    " of " + std::to_string(kProbeFileHeaderBytes) + " bytes)");
    // 3. Header checksum before trusting any field.
    const auto header_crc = static_cast<std::uint32_t>(le::load(h + kOffHeaderCrc, 4));
    if (crc32({h, kOffHeaderCrc}) != header_crc)
        return err(ErrorCode::kChecksum, name, "header checksum mismatch (CRC-32 at byte 180)");
    // 4. Fields.
    if (le::load(h + kOffHeaderBytes, 2) != kProbeFileHeaderBytes)
        return err(ErrorCode::kBadFormat, name, "header size field is " + std::to_string(le::load(h + kOffHeaderBytes, 2)) +
                                                    ", versions 1 and 2 require 184 (byte 10)");
    if ((version == kProbeFileVersion && h[kOffLeakFlags]) || h[kOffReserved0] | h[kOffReserved0 + 1] ||
        le::load(h + kOffReserved1, 4) || le::load(h + kOffReserved2, 4))
        return err(ErrorCode::kBadFormat, name, "reserved header bytes are not zero (bytes 21-23, 68-71, 156-159)");
    const std::uint8_t leak = h[kOffLeakFlags];
    if (version == kProbeFileVersionLeak) {
        if (leak > (kLeakValidity | kLeakVisibility | kLeakPlanes | kLeakTetrahedra))
            return err(ErrorCode::kUnsupported, name, "unknown per-probe sections " + std::to_string(leak) + " (byte 21)");
        if (leak == 0)
            return err(ErrorCode::kBadFormat, name, "version 2 without per-probe sections (byte 21 is 0; such a file is version 1)");
        if ((leak & kLeakVisibility) && h[kOffLayoutKind] != static_cast<std::uint8_t>(ProbeLayoutKind::kGrid))
            return err(ErrorCode::kBadFormat, name, "visibility masks without a grid layout (bytes 20-21)");
        if ((leak & kLeakPlanes) && h[kOffLayoutKind] != static_cast<std::uint8_t>(ProbeLayoutKind::kGrid))
            return err(ErrorCode::kBadFormat, name, "cell planes without a grid layout (bytes 20-21)");
        if ((leak & kLeakTetrahedra) && h[kOffLayoutKind] != static_cast<std::uint8_t>(ProbeLayoutKind::kPositions))
            return err(ErrorCode::kBadFormat, name, "tetrahedra without a positions layout (bytes 20-21)");
    }
    auto enum_field = [&](std::size_t off, int max, const char* what) -> Status {
        if (h[off] > max)
            return err(ErrorCode::kUnsupported, name, std::string("unknown ") + what + " " + std::to_string(h[off]) +
                                                          " (byte " + std::to_string(off) + ")");
        return Ok{};
    };
    for (Status st : {enum_field(kOffKind, 1, "stored kind"), enum_field(kOffDcFormat, 2, "DC format"),
                      enum_field(kOffL2Bound, 1, "L2 bound"), enum_field(kOffZonalMapping, 2, "zonal mapping"),
                      enum_field(kOffAxisMode, 1, "axis mode"), enum_field(kOffCompression, 1, "compression"),
                      enum_field(kOffLayoutKind, 2, "layout kind")})
        if (!st) return st.error();
    if (h[kOffSqrt] > 1) return err(ErrorCode::kBadFormat, name, "sqrt flag must be 0 or 1 (byte 16)");
    if (h[kOffBits] < kMinQuantBits || h[kOffBits] > kMaxQuantBits)
        return err(ErrorCode::kBadFormat, name, "bits " + std::to_string(h[kOffBits]) + " outside 2..8 (byte 13)");
    // Representation: ASCII name, zero padded, zero terminated within its 32 bytes.
    std::string rep;
    {
        size_t len = 0;
        while (len < kNameBytes && h[kOffName + len] != 0) ++len;
        if (len == 0 || len == kNameBytes)
            return err(ErrorCode::kBadFormat, name, "representation name empty or not terminated (bytes 24-55)");
        for (size_t i = len; i < kNameBytes; ++i)
            if (h[kOffName + i] != 0) return err(ErrorCode::kBadFormat, name, "representation name padding not zero");
        for (size_t i = 0; i < len; ++i)
            if (h[kOffName + i] < 0x21 || h[kOffName + i] > 0x7E)
                return err(ErrorCode::kBadFormat, name, "representation name is not printable ASCII");
        rep.assign(reinterpret_cast<const char*>(h + kOffName), len);
    }
    const Codec* codec = find_codec(rep);
    if (!codec) return err(ErrorCode::kUnsupported, name, "unknown representation '" + rep + "'");
    const std::uint64_t probe_bytes = le::load(h + kOffProbeBytes, 4);
    if (probe_bytes != codec->size_bytes)
        return err(ErrorCode::kBadFormat, name, "'" + rep + "' probes are " + std::to_string(codec->size_bytes) +
                                                    " bytes, header says " + std::to_string(probe_bytes) + " (byte 64)");
    ProbeSet set;
    set.representation = std::string(codec->name);  // an alias (codec_aliases) reads as its entry
    CodecOptions& p = set.params;
    p.kind = static_cast<StoredKind>(h[kOffKind]);
    p.bits = h[kOffBits];
    p.dc_format = static_cast<DcFormat>(h[kOffDcFormat]);
    p.l2_bound = static_cast<L2Bound>(h[kOffL2Bound]);
    p.sqrt_encoding = h[kOffSqrt] != 0;
    p.zonal_mapping = static_cast<ZonalMapping>(h[kOffZonalMapping]);
    p.axis_mode = static_cast<ZonalAxisMode>(h[kOffAxisMode]);
    p.luminance = {le::load_f64(h + kOffLuminance), le::load_f64(h + kOffLuminance + 8), le::load_f64(h + kOffLuminance + 16)};
    if (!std::isfinite(p.luminance.r) || !std::isfinite(p.luminance.g) || !std::isfinite(p.luminance.b))
        return err(ErrorCode::kInvalidValue, name, "luminance weights are not finite (bytes 72-95)");
    if (Status st = validate_quant_params(p, rep); !st) return err(ErrorCode::kBadFormat, name, st.error().message);
    const std::uint64_t count = le::load(h + kOffCount, 8);
    if (count > limits.max_probes)
        return err(ErrorCode::kTooLarge, name, std::to_string(count) + " probes exceed the limit of " +
                                                   std::to_string(limits.max_probes) + " (byte 56)");
    set.count = count;
    const auto layout_kind = static_cast<ProbeLayoutKind>(h[kOffLayoutKind]);
    set.layout.kind = layout_kind;
    double grid_values[6];
    std::uint32_t counts[3];
    for (int c = 0; c < 3; ++c) {
        grid_values[c] = le::load_f64(h + kOffOrigin + 8 * static_cast<size_t>(c));
        grid_values[3 + c] = le::load_f64(h + kOffSpacing + 8 * static_cast<size_t>(c));
        counts[c] = static_cast<std::uint32_t>(le::load(h + kOffCounts + 4 * static_cast<size_t>(c), 4));
    }
    if (layout_kind == ProbeLayoutKind::kGrid) {
        for (double v : grid_values)
            if (!std::isfinite(v)) return err(ErrorCode::kInvalidValue, name, "grid origin/spacing not finite (bytes 96-143)");
        set.layout.grid.origin = {grid_values[0], grid_values[1], grid_values[2]};
        set.layout.grid.spacing = {grid_values[3], grid_values[4], grid_values[5]};
        set.layout.grid.counts = {counts[0], counts[1], counts[2]};
        const std::int64_t n = layout_probe_count(set.layout);
        if (n < 0 || static_cast<std::uint64_t>(n) != count)
            return err(ErrorCode::kBadFormat, name, "grid counts " + std::to_string(counts[0]) + "x" +
                                                        std::to_string(counts[1]) + "x" + std::to_string(counts[2]) +
                                                        " do not match the probe count " + std::to_string(count));
    } else {
        for (double v : grid_values)
            if (v != 0.0 || std::signbit(v))
                return err(ErrorCode::kBadFormat, name, "grid fields must be zero without a grid layout");
        if (counts[0] | counts[1] | counts[2])
            return err(ErrorCode::kBadFormat, name, "grid fields must be zero without a grid layout");
    }
    // Body sizes: count <= 2^26 and size_bytes < 2^8 keep these products far from overflow.
    const std::uint64_t pos_bytes = layout_kind == ProbeLayoutKind::kPositions ? count * 12 : 0;
    const std::uint64_t leak_sections =
        ((leak & kLeakValidity) ? 1u : 0u) + ((leak & kLeakVisibility) ? 1u : 0u) + ((leak & kLeakPlanes) ? 5u : 0u);
    const std::uint64_t raw_expected = pos_bytes + count * probe_bytes + count * leak_sections;
    const std::uint64_t raw_bytes = le::load(h + kOffRawBody, 8);
    if (leak & kLeakTetrahedra) {
        // The per-probe part, then the tetrahedra section: 4 bytes of count and 32 per tetrahedron (at least one).
        if (raw_bytes < raw_expected + 36 || (raw_bytes - raw_expected - 4) % 32 != 0)
            return err(ErrorCode::kBadFormat, name, "body size " + std::to_string(raw_bytes) + " does not match " +
                                                        std::to_string(count) + " probes (expected " +
                                                        std::to_string(raw_expected) +
                                                        " + 4 + 32 per tetrahedron, at least one, byte 160)");
    } else if (raw_bytes != raw_expected) {
        return err(ErrorCode::kBadFormat, name, "body size " + std::to_string(raw_bytes) + " does not match " +
                                                    std::to_string(count) + " probes (expected " +
                                                    std::to_string(raw_expected) + ", byte 160)");
    }
    if (raw_bytes > limits.max_body_bytes)
        return err(ErrorCode::kTooLarge, name, "body of " + std::to_string(raw_bytes) + " bytes exceeds the limit of " +
                                                   std::to_string(limits.max_body_bytes));
    const bool compressed = h[kOffCompression] == 1;
    const std::uint64_t stored_bytes = le::load(h + kOffStoredBody, 8);
    if (!compressed && stored_bytes != raw_bytes)
        return err(ErrorCode::kBadFormat, name, "uncompressed body: stored size " + std::to_string(stored_bytes) +
                                                    " differs from body size " + std::to_string(raw_bytes));
    if (compressed && stored_bytes > ZSTD_compressBound(raw_bytes))
        return err(ErrorCode::kBadFormat, name, "compressed body larger than zstd's bound for its size (byte 168)");
    // 5. Overall size: exactly header + stored body.
    const std::uint64_t have = bytes.size() - kProbeFileHeaderBytes;
    if (have < stored_bytes)
        return err(ErrorCode::kTruncated, name, "file ends inside the body (" + std::to_string(have) + " of " +
                                                    std::to_string(stored_bytes) + " bytes)");
    if (have > stored_bytes)
        return err(ErrorCode::kTrailingBytes, name, std::to_string(have - stored_bytes) +
                                                        " unexpected bytes after the body (from byte " +
                                                        std::to_string(kProbeFileHeaderBytes + stored_bytes) + ")");
    const std::span<const std::uint8_t> stored = bytes.subspan(kProbeFileHeaderBytes);
    const auto body_crc = static_cast<std::uint32_t>(le::load(h + kOffBodyCrc, 4));
    if (crc32(stored) != body_crc) return err(ErrorCode::kChecksum, name, "body checksum mismatch (CRC-32 at byte 176)");
    // 6. Body.
    std::vector<std::uint8_t> raw;
    std::span<const std::uint8_t> body = stored;
    if (compressed) {
        const unsigned long long declared = ZSTD_getFrameContentSize(stored.data(), stored.size());
        if (declared == ZSTD_CONTENTSIZE_ERROR || declared == ZSTD_CONTENTSIZE_UNKNOWN || declared != raw_bytes)
            return err(ErrorCode::kBadFormat, name, "zstd frame missing or declares the wrong size");
        if (ZSTD_findFrameCompressedSize(stored.data(), stored.size()) != stored.size())
            return err(ErrorCode::kBadFormat, name, "body is not exactly one zstd frame");
        raw.resize(raw_bytes);  // within limits.max_body_bytes (checked above)
        const size_t n = ZSTD_decompress(raw.data(), raw.size(), stored.data(), stored.size());
        if (ZSTD_isError(n) || n != raw_bytes)
            return err(ErrorCode::kBadFormat, name, std::string("zstd body damaged: ") +
                                                        (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short output"));
        body = raw;
    }
    if (layout_kind == ProbeLayoutKind::kPositions) {
        set.layout.positions.resize(count);
        for (size_t i = 0; i < count; ++i)
            for (int c = 0; c < 3; ++c) {
                const float v = le::load_f32(body.data() + 12 * i + 4 * static_cast<size_t>(c));
                if (!std::isfinite(v))
                    return err(ErrorCode::kInvalidValue, name, "position of probe " + std::to_string(i) + " is not finite");
                set.layout.positions[i][static_cast<size_t>(c)] = v;
            }
    }
    const std::size_t payload_end = pos_bytes + count * probe_bytes;
    set.payload.assign(body.begin() + static_cast<std::ptrdiff_t>(pos_bytes),
                       body.begin() + static_cast<std::ptrdiff_t>(payload_end));
    std::size_t at = payload_end;
    if (leak & kLeakValidity) {
        set.validity.assign(body.begin() + static_cast<std::ptrdiff_t>(at),
                            body.begin() + static_cast<std::ptrdiff_t>(at + count));
        for (size_t i = 0; i < count; ++i)
            if (set.validity[i] > 1)
                return err(ErrorCode::kInvalidValue, name, "validity of probe " + std::to_string(i) + " is " +
                                                               std::to_string(set.validity[i]) + ", expected 0 or 1");
        at += count;
    }
    if (leak & kLeakVisibility) {
        set.visibility.assign(body.begin() + static_cast<std::ptrdiff_t>(at),
                              body.begin() + static_cast<std::ptrdiff_t>(at + count));
        at += count;
    }
    if (leak & kLeakPlanes) {
        set.planes.assign(body.begin() + static_cast<std::ptrdiff_t>(at),
                          body.begin() + static_cast<std::ptrdiff_t>(at + 5 * count));
        const auto& n = set.layout.grid.counts;
        for (std::uint64_t i = 0; i < count; ++i) {
            const std::uint64_t x = i % n[0], y = (i / n[0]) % n[1], z = i / (std::uint64_t(n[0]) * n[1]);
            const bool last = (n[0] > 1 && x + 1 == n[0]) || (n[1] > 1 && y + 1 == n[1]) || (n[2] > 1 && z + 1 == n[2]);
            if (std::string why = cell_entry_problem(&set.planes[5 * i], !last); !why.empty())  // docs/runtime.md "Cell planes"
                return err(ErrorCode::kInvalidValue, name, "cell entry of probe " + std::to_string(i) + ": " + why);
        }
        at += 5 * count;
    }
    if (leak & kLeakTetrahedra) {
        const std::uint64_t t_count = le::load(body.data() + at, 4);
        const std::uint64_t fits = (raw_bytes - at - 4) / 32;
        if (t_count != fits)
            return err(ErrorCode::kBadFormat, name, "tetrahedra section declares " + std::to_string(t_count) +
                                                        " tetrahedra, its " + std::to_string(raw_bytes - at - 4) +
                                                        " bytes hold " + std::to_string(fits));
        set.tetrahedra.resize(t_count);
        set.tetra_neighbours.resize(t_count);
        for (std::size_t t = 0; t < t_count; ++t)
            for (std::size_t k = 0; k < 4; ++k) {
                set.tetrahedra[t][k] = static_cast<std::uint32_t>(le::load(body.data() + at + 4 + 16 * t + 4 * k, 4));
                set.tetra_neighbours[t][k] = static_cast<std::int32_t>(
                    static_cast<std::uint32_t>(le::load(body.data() + at + 4 + 16 * (t_count + t) + 4 * k, 4)));
            }
        if (Status st = validate_tetrahedra(count, set.tetrahedra, set.tetra_neighbours); !st)
            return err(ErrorCode::kInvalidValue, name, st.error().message);
    }
    if (info) {
        info->version = version;
        info->compressed = compressed;
        info->raw_body_bytes = raw_bytes;
        info->stored_body_bytes = stored_bytes;
        info->file_bytes = bytes.size();
        info->body_crc32 = body_crc;
    }
    return set;
}

Status write_probe_file(const std::string& path, const ProbeSet& set, const ProbeFileWriteOptions& options) {
    auto bytes = serialize_probe_set(set, options);
    if (!bytes) return make_error(bytes.error().code, path + ": " + bytes.error().message);
    return write_file_atomic(path, *bytes);
}

Result<ProbeSet> read_probe_file(const std::string& path, const ProbeFileLimits& limits, ProbeFileInfo* info) {
    auto bytes = read_file_bytes(path, limits.max_file_bytes);
    if (!bytes) return bytes.error();
    return parse_probe_set(*bytes, path, limits, info);
}

// ---- JSON probe list -----------------------------------------------------------------------

bool looks_like_json(std::span<const std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) {
        if (b == ' ' || b == '\t' || b == '\r' || b == '\n') continue;
        return b == '{';
    }
    return false;
}

namespace {
using nlohmann::json;

Result<Vec3> json_vec3(const json& j, const std::string& name, const std::string& where) {
    if (!j.is_array() || j.size() != 3)
        return err(ErrorCode::kBadFormat, name, where + " must be an array of 3 numbers");
    double v[3];
    for (size_t i = 0; i < 3; ++i) {
        if (!j[i].is_number()) return err(ErrorCode::kBadFormat, name, where + " must be an array of 3 numbers");
        v[i] = j[i].get<double>();
        if (!std::isfinite(v[i])) return err(ErrorCode::kInvalidValue, name, where + " is not finite");
        // Stored as 32-bit floats: a larger magnitude would become infinity (and be written back
        // as null; found by fuzzing with a 160-digit position).
        if (std::fabs(v[i]) > std::numeric_limits<float>::max())
            return err(ErrorCode::kInvalidValue, name, where + " is outside the 32-bit float range");
    }
    return Vec3{v[0], v[1], v[2]};
}
}  // namespace

namespace {
Result<ProbeList> parse_probe_json_impl(std::span<const std::uint8_t> bytes, const std::string& name,
                                        const ProbeJsonLimits& limits) {
    if (bytes.size() > limits.max_file_bytes)
        return err(ErrorCode::kTooLarge, name, "JSON larger than the limit of " + std::to_string(limits.max_file_bytes) + " bytes");
    if (Status depth = check_json_depth(bytes, name); !depth) return depth.error();
    json doc;
    try {
        doc = json::parse(bytes.begin(), bytes.end());
    } catch (const json::parse_error& e) {
        return err(ErrorCode::kBadFormat, name, std::string("not valid JSON (") + e.what() + ")" + git_lfs_hint(bytes));
    }
    if (!doc.is_object()) return err(ErrorCode::kBadFormat, name, "top level must be an object");
    if (doc.contains("format") && doc["format"] != "zhc-probes")
        return err(ErrorCode::kBadFormat, name, "\"format\" must be \"zhc-probes\"");
    if (doc.contains("version") && doc["version"] != 1)
        return err(ErrorCode::kUnsupported, name, "probe list \"version\" must be 1");
    bool irradiance = false;
    if (doc.contains("kind")) {
        if (doc["kind"] == "irradiance") irradiance = true;
        else if (doc["kind"] != "radiance")
            return err(ErrorCode::kBadFormat, name, "\"kind\" must be \"radiance\" or \"irradiance\"");
    }
    if (!doc.contains("probes") || !doc["probes"].is_array())
        return err(ErrorCode::kBadFormat, name, "missing array \"probes\"");
    const json& probes = doc["probes"];
    if (probes.size() > limits.max_probes)
        return err(ErrorCode::kTooLarge, name, std::to_string(probes.size()) + " probes exceed the limit of " +
                                                   std::to_string(limits.max_probes));
    ProbeList list;
    // Layout: explicit, or "positions" when every probe has one, else "none".
    std::string layout_type;
    if (doc.contains("layout")) {
        const json& l = doc["layout"];
        if (!l.is_object() || !l.contains("type") || !l["type"].is_string())
            return err(ErrorCode::kBadFormat, name, "\"layout\" must be an object with a string \"type\"");
        layout_type = l["type"].get<std::string>();
        if (layout_type == "grid") {
            list.layout.kind = ProbeLayoutKind::kGrid;
            for (const char* key : {"origin", "spacing", "counts"})
                if (!l.contains(key)) return err(ErrorCode::kBadFormat, name, std::string("grid layout needs \"") + key + "\"");
            auto o = json_vec3(l["origin"], name, "layout.origin");
            if (!o) return o.error();
            auto s = json_vec3(l["spacing"], name, "layout.spacing");
            if (!s) return s.error();
            list.layout.grid.origin = *o;
            list.layout.grid.spacing = *s;
            const json& c = l["counts"];
            if (!c.is_array() || c.size() != 3)
                return err(ErrorCode::kBadFormat, name, "layout.counts must be 3 non-negative integers");
            for (size_t i = 0; i < 3; ++i) {
                if (!c[i].is_number_unsigned() || c[i].get<std::uint64_t>() > 0xFFFFFFFFu)
                    return err(ErrorCode::kBadFormat, name, "layout.counts must be 3 non-negative integers");
                list.layout.grid.counts[i] = c[i].get<std::uint32_t>();
            }
            const std::int64_t n = layout_probe_count(list.layout);
            if (n < 0 || static_cast<std::uint64_t>(n) != probes.size())
                return err(ErrorCode::kBadFormat, name, "layout.counts do not multiply to the number of probes (" +
                                                            std::to_string(probes.size()) + ")");
        } else if (layout_type == "positions") {
            list.layout.kind = ProbeLayoutKind::kPositions;
        } else if (layout_type != "none") {
            return err(ErrorCode::kBadFormat, name, "layout.type must be \"none\", \"grid\" or \"positions\"");
        }
    } else {
        bool all = !probes.empty();
        for (const json& p : probes) all = all && p.is_object() && p.contains("position");
        if (all) list.layout.kind = ProbeLayoutKind::kPositions;
    }
    list.probes.resize(probes.size());
    for (size_t i = 0; i < probes.size(); ++i) {
        const std::string where = "probes[" + std::to_string(i) + "]";
        const json& p = probes[i];
        if (!p.is_object() || !p.contains("sh3")) return err(ErrorCode::kBadFormat, name, where + " needs \"sh3\"");
        const json& sh = p["sh3"];
        if (!sh.is_array() || sh.size() != 9)
            return err(ErrorCode::kBadFormat, name, where + ".sh3 must be 9 rows of [r, g, b]");
        Sh3Radiance c;
        for (size_t r = 0; r < 9; ++r) {
            auto row = json_vec3(sh[r], name, where + ".sh3[" + std::to_string(r) + "]");
            if (!row) return row.error();
            for (int k = 0; k < 3; ++k) c[static_cast<int>(r)][k] = static_cast<float>((*row)[k]);  // in range (json_vec3)
        }
        if (irradiance) {
            Sh3Irradiance e;
            e.c = c.c;
            c = to_radiance(e);
            // Radiance is irradiance divided by the band scales (x 3/2, x 4): it can leave the range.
            for (const Rgb& row : c.c)
                for (int k = 0; k < 3; ++k)
                    if (!std::isfinite(row[k]))
                        return err(ErrorCode::kInvalidValue, name,
                                   where + ".sh3 as radiance (irradiance / band scale) is outside the 32-bit float range");
        }
        list.probes[i] = c;
        if (list.layout.kind == ProbeLayoutKind::kPositions) {
            if (!p.contains("position")) return err(ErrorCode::kBadFormat, name, where + " needs \"position\"");
            auto pos = json_vec3(p["position"], name, where + ".position");
            if (!pos) return pos.error();
            list.layout.positions.push_back({static_cast<float>(pos->x), static_cast<float>(pos->y), static_cast<float>(pos->z)});
        }
    }
    return list;
}

}  // namespace

Result<ProbeList> parse_probe_json(std::span<const std::uint8_t> bytes, const std::string& name,
                                   const ProbeJsonLimits& limits) {
    try {
        return parse_probe_json_impl(bytes, name, limits);
    } catch (const nlohmann::json::exception& e) {  // a type mismatch the checks above missed
        return err(ErrorCode::kBadFormat, name, std::string("unexpected JSON structure (") + e.what() + ")");
    } catch (const std::bad_alloc&) {
        return err(ErrorCode::kTooLarge, name, "out of memory while parsing JSON");
    }
}

std::string probe_json(const ProbeList& list) {
    json doc;
    doc["format"] = "zhc-probes";
    doc["version"] = 1;
    doc["kind"] = "radiance";
    doc["basis"] = "zhc (ZH3 paper Eq. 4/5), index l(l+1)+m";
    json layout;
    switch (list.layout.kind) {
        case ProbeLayoutKind::kNone: layout["type"] = "none"; break;
        case ProbeLayoutKind::kPositions: layout["type"] = "positions"; break;
        case ProbeLayoutKind::kGrid: {
            const ProbeGrid& g = list.layout.grid;
            layout["type"] = "grid";
            layout["origin"] = {g.origin.x, g.origin.y, g.origin.z};
            layout["spacing"] = {g.spacing.x, g.spacing.y, g.spacing.z};
            layout["counts"] = {g.counts[0], g.counts[1], g.counts[2]};
            break;
        }
    }
    doc["layout"] = layout;
    json probes = json::array();
    for (size_t i = 0; i < list.probes.size(); ++i) {
        json p;
        if (list.layout.kind == ProbeLayoutKind::kPositions && i < list.layout.positions.size()) {
            const auto& q = list.layout.positions[i];
            p["position"] = {q[0], q[1], q[2]};
        }
        json rows = json::array();
        for (int r = 0; r < 9; ++r) rows.push_back({list.probes[i][r].r, list.probes[i][r].g, list.probes[i][r].b});
        p["sh3"] = rows;
        probes.push_back(std::move(p));
    }
    doc["probes"] = std::move(probes);
    return doc.dump() + "\n";
}

Status check_finite_probes(std::span<const Sh3Radiance> probes, const std::string& name) {
    for (size_t n = 0; n < probes.size(); ++n)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k)
                if (!std::isfinite(probes[n][i][k]))
                    return make_error(ErrorCode::kInvalidValue, name + ": probe " + std::to_string(n) + " holds NaN/Inf (coefficient " +
                                                                    std::to_string(i) + ", channel " + std::to_string(k) + ")");
    return Ok{};
}

Result<DecodedProbeSet> parse_and_decode_probe_set(std::span<const std::uint8_t> bytes, const std::string& name) {
    auto set = parse_probe_set(bytes, name);
    if (!set) return set.error();
    auto hub = decode_probe_set(*set);
    if (!hub) return make_error(ErrorCode::kBadFormat, name + ": " + hub.error().message);
    if (Status finite = check_finite_probes(*hub, name); !finite) return finite.error();
    return DecodedProbeSet{std::move(set).value(), std::move(hub).value()};
}

Status write_probe_json(const std::string& path, const ProbeList& list) {
    if (!check_finite_probes(list.probes, path))
        return make_error(ErrorCode::kInvalidValue, path + ": a probe holds NaN/Inf; JSON cannot store it");
    const std::string text = probe_json(list);
    return write_file_atomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
}

Result<ProbeList> read_probe_json(const std::string& path, const ProbeJsonLimits& limits) {
    auto bytes = read_file_bytes(path, limits.max_file_bytes);
    if (!bytes) return bytes.error();
    return parse_probe_json(*bytes, path, limits);
}

}  // namespace zhc
