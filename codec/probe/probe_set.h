// zhc/codec/probe/probe_set.h — a set of light probes in one stored representation, in memory.
//
// A ProbeSet is what a game ships for a volume of probes: one representation from the codec
// table (codec.h), the parameters that give its bytes their meaning, where the probes are, and
// the payload: probe i occupies bytes [i * size_bytes, (i + 1) * size_bytes). It is the in-memory
// form of the .zhp container (formats/probes/probe_file.h, docs/zhp-container.md) and what other
// consumers (glTF embedding, scene baking) build on. No I/O here.
//
// Invariants of a valid set (validate_probe_set checks them all):
//  * `representation` names a codec table entry; payload.size() == count * its size_bytes;
//  * `params` pass validate_quant_params for that representation;
//  * layout kGrid: counts multiply to `count`, origin and spacing finite;
//    layout kPositions: positions.size() == count, all finite; layout kNone: nothing.
//  * validity: empty or `count` bytes, each 0 or 1; visibility: empty, or `count` bytes with a
//    grid layout; tetrahedra: empty, or with a positions layout and consistent neighbours.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/quantize.h"
#include "codec/sh/sh.h"
#include "codec/status.h"

namespace zhc {

enum class ProbeLayoutKind : std::uint8_t {
    kNone = 0,       // probes without positions (e.g. one probe from an environment map)
    kGrid = 1,       // regular grid: probe (x, y, z) at origin + (x sx, y sy, z sz), x fastest
    kPositions = 2,  // one explicit position per probe
};

struct ProbeGrid {
    Vec3 origin;
    Vec3 spacing{1, 1, 1};
    std::array<std::uint32_t, 3> counts{0, 0, 0};  // probe index = x + nx (y + ny z)
};

struct ProbeLayout {
    ProbeLayoutKind kind = ProbeLayoutKind::kNone;
    ProbeGrid grid;                               // kGrid only
    std::vector<std::array<float, 3>> positions;  // kPositions only: one per probe
};


struct ProbeSet {
    std::string representation = "sh3";  // codec table name
    // Everything that changes how the payload decodes, as stored in a .zhp header: the storage
    // fields of CodecOptions (codec.h). The quantised layouts read all of them; the float
    // representations read only the luminance weights (ZH3 axes) and `kind` (see below).
    CodecOptions params;
    ProbeLayout layout;
    std::uint64_t count = 0;
    std::vector<std::uint8_t> payload;  // count * size_bytes, probe-major
    // Leak-avoidance data of a baked grid (docs/scene.md "Probes near geometry"), both optional:
    // empty, or exactly `count` bytes. validity[i]: 1 = valid, 0 = inside geometry (its SH is a
    // blend of valid neighbours). visibility[i] (grid layouts only): bit (cx + 2 cy + 4 cz) set =
    // the probe is visible from the grid cell on its side (cx, cy, cz), c = 1 towards +axis, 0
    // towards -axis. Sampling a cell with lower corner probe (i0, j0, k0), corner (dx, dy, dz)
    // reads bit 7 - (dx + 2 dy + 4 dz) of that corner probe.
    std::vector<std::uint8_t> validity;
    std::vector<std::uint8_t> visibility;
    // planes (grid layouts only): empty or 5 count bytes; entry i (bytes 5i..5i+4) is the separating
    // plane of the grid cell whose corner 0 is probe i (docs/runtime.md "Cell planes"): ou, ov (the
    // normal's octahedral code, zhc axes), offset (int16 little-endian from the cell's centre along
    // the normal in units of |spacing| / 65534; -32768 = no plane), sides (bit k: corner k of the
    // cell lies on the positive side); or, with offset -32768 and bit 7 of byte 4 set, a corner
    // region (docs/runtime.md "Corner regions": a 5-bit threshold per axis in bytes 0-1, a
    // direction bit per axis in byte 4). Probes that are the last along some axis of count >= 2
    // start no cell: their entries are "no plane" (byte 4 bit 7 clear).
    std::vector<std::uint8_t> planes;
    // tetrahedra (positions layouts only): empty, or a tetrahedralisation of the positions
    // (formats/probes/tetra.h: Delaunay, canonical order, positive orientation), 4 probe indices per
    // tetrahedron; tetra_neighbours (as many entries): [t][j] = the tetrahedron across face j of t
    // (the face opposite vertex j), -1 on the convex hull. The runtimes walk them
    // (docs/runtime.md "Scattered probes (`points` layout)").
    std::vector<std::array<std::uint32_t, 4>> tetrahedra;
    std::vector<std::array<std::int32_t, 4>> tetra_neighbours;

    // nullptr when `representation` is not in the table.
    const Codec* codec() const { return find_codec(representation); }
};

// Checks every invariant above; kInvalidArgument naming the first broken one.
Status validate_probe_set(const ProbeSet& set);
// The leak-data part of it: validity and visibility each empty or `count` bytes, validity values
// 0/1, visibility only with a grid layout; planes empty or 5 count bytes with a grid layout, "no
// plane" on the entries of the last probe along each axis; tetrahedra only with a positions layout
// and consistent (validate_tetrahedra).
Status validate_leak_data(const ProbeSet& set);
// The kind of a 5-byte cell entry of ProbeSet::planes: no entry (offset -32768, bit 7 of byte 4
// clear), a plane, or a corner region (offset -32768, bit 7 of byte 4 set).
enum class CellEntryKind : std::uint8_t { kNone, kPlane, kRegion };
CellEntryKind cell_entry_kind(const std::uint8_t* e);
// What is wrong with entry `e` of a probe that starts a cell (`starts_cell`) or not, empty when
// nothing: a plane or region on a probe that starts no cell, a region's reserved bits set (bit 15
// of bytes 0-1, bits 3-6 of byte 4). The one rule the .zhp and glTF readers and
// validate_leak_data apply.
std::string cell_entry_problem(const std::uint8_t* e, bool starts_cell);
// The tetrahedra of `count` probes: as many neighbour entries as tetrahedra; each tetrahedron's 4
// probe indices < count and distinct; each neighbour -1 or another tetrahedron (< the number of
// tetrahedra) that names this one as its neighbour across the same 3 probes. kInvalidArgument
// naming the first tetrahedron that breaks a rule. O(tetrahedra).
Status validate_tetrahedra(std::uint64_t count, std::span<const std::array<std::uint32_t, 4>> tetrahedra,
                           std::span<const std::array<std::int32_t, 4>> neighbours);

// Probe i's stored bytes -> hub, and hub -> stored bytes. With params.kind == kIrradiance the
// payload holds irradiance SH: the quantised layouts then use the irradiance-scaled ratio bounds
// (App. A.1) and the other representations store the band-scaled coefficients as they would a
// radiance function (every representation in the table is linear per band, so this is exact
// up to rounding). `out` must have codec->size_bytes bytes.
void encode_probe(const Codec& codec, const CodecOptions& params, const Sh3Radiance& hub, std::uint8_t* out,
                  EncodeStats* stats);
Sh3Radiance decode_probe(const Codec& codec, const CodecOptions& params, const std::uint8_t* in);

// Builds a set from hub probes. Fails (kInvalidArgument) for an unknown representation, bad
// params, or a layout that does not match hub.size(). Deterministic.
Result<ProbeSet> encode_probe_set(std::span<const Sh3Radiance> hub, std::string_view representation,
                                  const CodecOptions& params, ProbeLayout layout, EncodeStats* stats = nullptr);
// Decodes every probe to the hub. Fails only for an invalid set.
Result<std::vector<Sh3Radiance>> decode_probe_set(const ProbeSet& set);
// What the runtime would see: encode the hub probes into a representation, then decode back to
// the hub (a lossy preview, e.g. a JSON probe list "through" zh3_q16). Fails as encode_probe_set.
Result<std::vector<Sh3Radiance>> round_trip_probes(std::span<const Sh3Radiance> hub, std::string_view representation,
                                                   const CodecOptions& params, ProbeLayout layout,
                                                   EncodeStats* stats = nullptr);
// Decode then re-encode into another representation/params; the layout is kept.
Result<ProbeSet> convert_probe_set(const ProbeSet& set, std::string_view representation, const CodecOptions& params,
                                   EncodeStats* stats = nullptr);

// World position of probe i (origin for kNone). Precondition: i < count, valid set.
Vec3 probe_position(const ProbeSet& set, std::uint64_t i);
// Number of probes a layout describes (grid product, positions size), or -1 for kNone (any).
// Overflow-checked: returns -2 when the grid product does not fit in 64 bits.
std::int64_t layout_probe_count(const ProbeLayout& layout);

}  // namespace zhc
