// The in-memory probe set (probe_set.h): encode/decode through the codec table.
#include "codec/probe/probe_set.h"

#include <cmath>

namespace zhc {

std::int64_t layout_probe_count(const ProbeLayout& layout) {
    switch (layout.kind) {
        case ProbeLayoutKind::kNone: return -1;
        case ProbeLayoutKind::kPositions: return static_cast<std::int64_t>(layout.positions.size());
        case ProbeLayoutKind::kGrid: {
            // Three 32-bit factors: the product of two fits in 64 bits; check the third.
            const unsigned __int128 n = static_cast<unsigned __int128>(layout.grid.counts[0]) * layout.grid.counts[1] *
                                        layout.grid.counts[2];
            if (n > static_cast<unsigned __int128>(INT64_MAX)) return -2;
            return static_cast<std::int64_t>(n);
        }
    }
    return -1;
}

namespace {
bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

Status validate_layout(const ProbeLayout& layout, std::uint64_t count) {
    switch (layout.kind) {
        case ProbeLayoutKind::kNone: return Ok{};
        case ProbeLayoutKind::kGrid: {
            const std::int64_t n = layout_probe_count(layout);
            if (n < 0 || static_cast<std::uint64_t>(n) != count)
                return make_error(ErrorCode::kInvalidArgument, "grid counts " + std::to_string(layout.grid.counts[0]) +
                                                                   "x" + std::to_string(layout.grid.counts[1]) + "x" +
                                                                   std::to_string(layout.grid.counts[2]) +
                                                                   " do not match the probe count " +
                                                                   std::to_string(count));
            if (!finite(layout.grid.origin) || !finite(layout.grid.spacing))
                return make_error(ErrorCode::kInvalidArgument, "grid origin/spacing must be finite");
            return Ok{};
        }
        case ProbeLayoutKind::kPositions: {
            if (layout.positions.size() != count)
                return make_error(ErrorCode::kInvalidArgument, std::to_string(layout.positions.size()) +
                                                                   " positions for " + std::to_string(count) +
                                                                   " probes");
            for (size_t i = 0; i < layout.positions.size(); ++i)
                for (float c : layout.positions[i])
                    if (!std::isfinite(c))
                        return make_error(ErrorCode::kInvalidArgument,
                                          "position of probe " + std::to_string(i) + " is not finite");
            return Ok{};
        }
    }
    return make_error(ErrorCode::kInvalidArgument, "unknown layout kind");
}

Sh3Radiance as_radiance_type(const Sh3Irradiance& e) {
    Sh3Radiance out;
    out.c = e.c;
    return out;
}
}  // namespace

CellEntryKind cell_entry_kind(const std::uint8_t* e) {
    if (!(e[2] == 0x00 && e[3] == 0x80)) return CellEntryKind::kPlane;
    return (e[4] & 0x80u) ? CellEntryKind::kRegion : CellEntryKind::kNone;
}

std::string cell_entry_problem(const std::uint8_t* e, bool starts_cell) {
    const CellEntryKind kind = cell_entry_kind(e);
    if (!starts_cell && kind != CellEntryKind::kNone)
        return std::string(kind == CellEntryKind::kPlane ? "a plane" : "a corner region") +
               " is set, but no cell has that probe as its first corner";
    if (kind == CellEntryKind::kRegion && ((e[1] & 0x80u) || (e[4] & 0x78u)))
        return "its corner region sets reserved bits (bit 15 of its thresholds or bits 3-6 of byte 4)";
    return {};
}

Status validate_leak_data(const ProbeSet& set) {
    if (!set.validity.empty()) {
        if (set.validity.size() != set.count)
            return make_error(ErrorCode::kInvalidArgument, "validity holds " + std::to_string(set.validity.size()) +
                                                               " bytes, expected 0 or " + std::to_string(set.count));
        for (size_t i = 0; i < set.validity.size(); ++i)
            if (set.validity[i] > 1)
                return make_error(ErrorCode::kInvalidArgument, "validity[" + std::to_string(i) + "] is " +
                                                                   std::to_string(set.validity[i]) + ", expected 0 or 1");
    }
    if (!set.visibility.empty()) {
        if (set.layout.kind != ProbeLayoutKind::kGrid)
            return make_error(ErrorCode::kInvalidArgument, "visibility masks need a grid layout");
        if (set.visibility.size() != set.count)
            return make_error(ErrorCode::kInvalidArgument, "visibility holds " + std::to_string(set.visibility.size()) +
                                                               " bytes, expected 0 or " + std::to_string(set.count));
    }
    if (!set.planes.empty()) {
        if (set.layout.kind != ProbeLayoutKind::kGrid)
            return make_error(ErrorCode::kInvalidArgument, "cell planes need a grid layout");
        if (set.planes.size() != 5 * set.count)
            return make_error(ErrorCode::kInvalidArgument, "planes hold " + std::to_string(set.planes.size()) +
                                                               " bytes, expected 0 or " + std::to_string(5 * set.count));
        const auto& n = set.layout.grid.counts;
        for (std::uint64_t i = 0; i < set.count; ++i) {
            const std::uint64_t x = i % n[0], y = (i / n[0]) % n[1], z = i / (std::uint64_t(n[0]) * n[1]);
            const bool last = (n[0] > 1 && x + 1 == n[0]) || (n[1] > 1 && y + 1 == n[1]) || (n[2] > 1 && z + 1 == n[2]);
            if (std::string why = cell_entry_problem(&set.planes[5 * i], !last); !why.empty())
                return make_error(ErrorCode::kInvalidArgument, "probe " + std::to_string(i) + ": " + why);
        }
    }
    if (!set.tetrahedra.empty() || !set.tetra_neighbours.empty()) {
        if (set.layout.kind != ProbeLayoutKind::kPositions)
            return make_error(ErrorCode::kInvalidArgument, "tetrahedra need a positions layout");
        if (Status st = validate_tetrahedra(set.count, set.tetrahedra, set.tetra_neighbours); !st) return st;
    }
    return Ok{};
}

Status validate_tetrahedra(std::uint64_t count, std::span<const std::array<std::uint32_t, 4>> tetrahedra,
                           std::span<const std::array<std::int32_t, 4>> neighbours) {
    auto fail = [](std::size_t t, const std::string& what) {
        return make_error(ErrorCode::kInvalidArgument, "tetrahedron " + std::to_string(t) + " " + what);
    };
    if (neighbours.size() != tetrahedra.size())
        return make_error(ErrorCode::kInvalidArgument, std::to_string(neighbours.size()) + " neighbour entries for " +
                                                           std::to_string(tetrahedra.size()) + " tetrahedra");
    if (tetrahedra.empty()) return make_error(ErrorCode::kInvalidArgument, "a tetrahedra section without a tetrahedron");
    if (tetrahedra.size() > 0x7FFFFFFFu) return make_error(ErrorCode::kInvalidArgument, "more than 2^31 - 1 tetrahedra");
    for (std::size_t t = 0; t < tetrahedra.size(); ++t) {
        const auto& v = tetrahedra[t];
        for (int k = 0; k < 4; ++k) {
            if (v[static_cast<std::size_t>(k)] >= count)
                return fail(t, "vertex " + std::to_string(k) + " is probe " + std::to_string(v[static_cast<std::size_t>(k)]) +
                                   ", beyond the " + std::to_string(count) + " probes");
            for (int m = 0; m < k; ++m)
                if (v[static_cast<std::size_t>(m)] == v[static_cast<std::size_t>(k)])
                    return fail(t, "names probe " + std::to_string(v[static_cast<std::size_t>(k)]) + " twice");
        }
    }
    for (std::size_t t = 0; t < tetrahedra.size(); ++t)
        for (std::size_t j = 0; j < 4; ++j) {
            const std::int32_t n = neighbours[t][j];
            if (n == -1) continue;
            if (n < -1 || static_cast<std::size_t>(n) >= tetrahedra.size() || static_cast<std::size_t>(n) == t)
                return fail(t, "face " + std::to_string(j) + ": neighbour " + std::to_string(n) + " is not another tetrahedron");
            // The neighbour names t back, across the face made of the same 3 probes.
            std::size_t back = 4, backs = 0;
            for (std::size_t k = 0; k < 4; ++k)
                if (neighbours[static_cast<std::size_t>(n)][k] == static_cast<std::int32_t>(t)) back = k, ++backs;
            bool same = backs == 1;
            for (std::size_t k = 0; k < 4 && same; ++k) {
                if (k == j) continue;
                bool found = false;
                for (std::size_t m = 0; m < 4; ++m)
                    if (m != back && tetrahedra[static_cast<std::size_t>(n)][m] == tetrahedra[t][k]) found = true;
                same = found;
            }
            if (!same)
                return fail(t, "face " + std::to_string(j) + ": neighbour " + std::to_string(n) +
                                   " does not share that face with it");
        }
    return Ok{};
}

Status validate_probe_set(const ProbeSet& set) {
    const Codec* codec = set.codec();
    if (!codec) return make_error(ErrorCode::kInvalidArgument, "unknown representation '" + set.representation + "'");
    if (Status st = validate_quant_params(set.params, set.representation); !st) return st;
    // Overflow-safe: count <= payload.size() / size_bytes is necessary for equality.
    if (set.count > set.payload.size() / codec->size_bytes || set.payload.size() != set.count * codec->size_bytes)
        return make_error(ErrorCode::kInvalidArgument, "payload holds " + std::to_string(set.payload.size()) +
                                                           " bytes, expected " + std::to_string(set.count) + " x " +
                                                           std::to_string(codec->size_bytes));
    if (Status st = validate_layout(set.layout, set.count); !st) return st;
    return validate_leak_data(set);
}

void encode_probe(const Codec& codec, const CodecOptions& params, const Sh3Radiance& hub, std::uint8_t* out,
                  EncodeStats* stats) {
    // Packed entries read every storage parameter themselves (kind: scaled bounds); the float
    // entries store what they are given, so irradiance is converted here.
    if (codec.packed || params.kind != StoredKind::kIrradiance) codec.encode(hub, params, out, stats);
    else codec.encode(as_radiance_type(to_irradiance(hub)), params, out, stats);
}

Sh3Radiance decode_probe(const Codec& codec, const CodecOptions& params, const std::uint8_t* in) {
    const Sh3Radiance stored = codec.decode(in, params);
    if (codec.packed || params.kind != StoredKind::kIrradiance) return stored;
    Sh3Irradiance e;
    e.c = stored.c;
    return to_radiance(e);
}

Result<ProbeSet> encode_probe_set(std::span<const Sh3Radiance> hub, std::string_view representation,
                                  const CodecOptions& params, ProbeLayout layout, EncodeStats* stats) {
    const Codec* codec = find_codec(representation);
    if (!codec) return make_error(ErrorCode::kInvalidArgument, "unknown representation '" + std::string(representation) + "'");
    if (Status st = validate_quant_params(params, representation); !st) return st.error();
    if (Status st = validate_layout(layout, hub.size()); !st) return st.error();
    ProbeSet set;
    set.representation = std::string(codec->name);  // an alias (codec_aliases) is never written
    set.params = params;
    set.layout = std::move(layout);
    set.count = hub.size();
    set.payload.resize(hub.size() * codec->size_bytes);
    for (size_t i = 0; i < hub.size(); ++i)
        encode_probe(*codec, params, hub[i], set.payload.data() + i * codec->size_bytes, stats);
    return set;
}

Result<std::vector<Sh3Radiance>> decode_probe_set(const ProbeSet& set) {
    if (Status st = validate_probe_set(set); !st) return st.error();
    const Codec& codec = *set.codec();
    std::vector<Sh3Radiance> out(set.count);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = decode_probe(codec, set.params, set.payload.data() + i * codec.size_bytes);
    return out;
}

Result<std::vector<Sh3Radiance>> round_trip_probes(std::span<const Sh3Radiance> hub, std::string_view representation,
                                                   const CodecOptions& params, ProbeLayout layout, EncodeStats* stats) {
    auto set = encode_probe_set(hub, representation, params, std::move(layout), stats);
    if (!set) return set.error();
    return decode_probe_set(*set);
}

Result<ProbeSet> convert_probe_set(const ProbeSet& set, std::string_view representation, const CodecOptions& params,
                                   EncodeStats* stats) {
    auto hub = decode_probe_set(set);
    if (!hub) return hub.error();
    auto out = encode_probe_set(*hub, representation, params, set.layout, stats);
    if (!out) return out;
    out->validity = set.validity;  // per-probe leak data does not depend on the representation
    out->visibility = set.visibility;
    out->planes = set.planes;
    out->tetrahedra = set.tetrahedra;
    out->tetra_neighbours = set.tetra_neighbours;
    return out;
}

Vec3 probe_position(const ProbeSet& set, std::uint64_t i) {
    switch (set.layout.kind) {
        case ProbeLayoutKind::kGrid: {
            const ProbeGrid& g = set.layout.grid;
            const std::uint64_t nx = g.counts[0], ny = g.counts[1];
            const double x = static_cast<double>(i % nx), y = static_cast<double>((i / nx) % ny),
                         z = static_cast<double>(i / (nx * ny));
            return {g.origin.x + x * g.spacing.x, g.origin.y + y * g.spacing.y, g.origin.z + z * g.spacing.z};
        }
        case ProbeLayoutKind::kPositions: {
            const auto& p = set.layout.positions[i];
            return {p[0], p[1], p[2]};
        }
        case ProbeLayoutKind::kNone: break;
    }
    return {};
}

}  // namespace zhc
