// Cell planes (ProbeSet::planes, docs/runtime.md "Cell planes") in glTF: the ZHC_light_probes
// accessors `planes` (VEC4 UNSIGNED_BYTE: ou, ov, offset lo, offset hi) and `planeSides` (SCALAR
// UNSIGNED_BYTE), docs/gltf-extension.md "Cell planes":
//  * embed -> read gives the same 5-byte entries (zhc order, zhc corner bits), both SH axes, GLB and
//    .gltf, quantised and float, and the .zhp written from the read set is the input .zhp byte for byte;
//  * the stored accessors describe the same physical planes in glTF axes: each entry sits at its
//    probe's glTF index, its normal code decodes (zhc axes) to n with n_glTF = (n.y, n.z, n.x), and
//    bit (gx + 2 gy + 4 gz) of planeSides is the side of glTF corner (gx, gy, gz) of the cell,
//    computed here from the glTF grid's own origin and spacing (independently of the writer);
//  * refusals, one line naming the accessor: wrong type / componentType / count, one accessor of the
//    two, planes on a volume without a grid layout, a plane on a probe that starts no cell;
//  * the CLI: `zhc gltf embed` then `zhc gltf extract` give the input .zhp byte for byte, a tampered
//    asset exits 4 in one line, `zhc convert` to another representation keeps the planes;
//  * a default `zhc bake` of examples/hall.gltf to .glb carries the planes the .zhp bake writes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "gltf_helpers.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;
using gltf_test::Bytes;
using gltf_test::json;

constexpr std::uint32_t kNx = 3, kNy = 2, kNz = 4;  // every axis its own count: a wrong order shows

ProbeLayout grid_layout(std::array<std::uint32_t, 3> counts) {
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kGrid;
    l.grid.origin = {-1, 0.5, 2};
    l.grid.spacing = {0.5, 1, 0.25};
    l.grid.counts = counts;
    return l;
}

// The plane normal of an octahedral code, written from the spec (docs/runtime.md "Cell planes").
Vec3 plane_normal(std::uint8_t ou, std::uint8_t ov) {
    double a = std::min<int>(ou, 254) / 127.0 - 1.0, b = std::min<int>(ov, 254) / 127.0 - 1.0;
    const double z = 1.0 - std::fabs(a) - std::fabs(b);
    if (z < 0) {
        const double na = (1.0 - std::fabs(b)) * (a < 0 ? -1.0 : 1.0), nb = (1.0 - std::fabs(a)) * (b < 0 ? -1.0 : 1.0);
        a = na;
        b = nb;
    }
    const double len = std::sqrt(a * a + b * b + z * z);
    return {a / len, b / len, z / len};
}

std::int16_t offset_of(const std::uint8_t* e) { return static_cast<std::int16_t>(std::uint16_t(e[2] | e[3] << 8)); }

// Signed distance of p from the plane of entry e of the cell with lower corner `i0`.
double plane_distance(const std::uint8_t* e, const Vec3& n, const Vec3& origin, const Vec3& spacing, const std::array<std::uint64_t, 3>& i0,
                      const Vec3& p) {
    const Vec3 c{origin.x + (double(i0[0]) + 0.5) * spacing.x, origin.y + (double(i0[1]) + 0.5) * spacing.y,
                 origin.z + (double(i0[2]) + 0.5) * spacing.z};
    return dot(n, p - c) - offset_of(e) * length(spacing) / 65534.0;
}

// A zh3_q16 (or `rep`) grid (3x2x4 unless `counts`) with a plane in most cells: random normal
// codes and offsets, the sides computed from where the corners are; "no plane" entries (offset
// -32768) on the last probe along each axis of two or more probes and on a few cells, their other
// bytes random (they must survive too). Along an axis of one probe, that probe starts a flat cell.
ProbeSet planes_set(const std::string& rep = "zh3_q16", unsigned seed = 3, std::array<std::uint32_t, 3> counts = {kNx, kNy, kNz}) {
    const std::uint64_t nx = counts[0], ny = counts[1], nz = counts[2];
    std::vector<Sh3Radiance> hub(nx * ny * nz);
    for (size_t i = 0; i < hub.size(); ++i)
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) hub[i][c][k] = c == 0 ? float(1 + i % 5 + k) : float(0.1 * std::sin(double(i * 27 + size_t(c) * 3 + size_t(k))));
    auto set = encode_probe_set(hub, rep, {}, grid_layout(counts));
    EXPECT_TRUE(set.ok());
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> byte(0, 255), offset(-32767, 32767);
    const ProbeGrid& g = set->layout.grid;
    set->planes.resize(5 * set->count);
    for (std::uint64_t i = 0; i < set->count; ++i) {
        std::uint8_t* e = set->planes.data() + 5 * i;
        const std::array<std::uint64_t, 3> i0{i % nx, (i / nx) % ny, i / (nx * ny)};
        for (int b = 0; b < 5; ++b) e[b] = static_cast<std::uint8_t>(byte(rng));
        const bool last = (nx > 1 && i0[0] + 1 == nx) || (ny > 1 && i0[1] + 1 == ny) || (nz > 1 && i0[2] + 1 == nz);
        if (last || i % 7 == 3) {
            e[2] = 0x00;
            e[3] = 0x80;
            e[4] &= 0x7F;  // "no plane" (bit 7 would make it a corner region)
            continue;
        }
        if (i % 7 == 5) {  // a corner region: random thresholds and directions (docs/runtime.md "Corner regions")
            e[1] &= 0x7F;
            e[2] = 0x00;
            e[3] = 0x80;
            e[4] = static_cast<std::uint8_t>(0x80 | (e[4] & 7));
            continue;
        }
        const std::uint16_t off = static_cast<std::uint16_t>(offset(rng) / 4);  // within the cell's reach mostly
        e[2] = static_cast<std::uint8_t>(off);
        e[3] = static_cast<std::uint8_t>(off >> 8);
        const Vec3 n = plane_normal(e[0], e[1]);
        e[4] = 0;
        for (int k = 0; k < 8; ++k) {
            const Vec3 p{g.origin.x + double(i0[0] + (k & 1)) * g.spacing.x, g.origin.y + double(i0[1] + ((k >> 1) & 1)) * g.spacing.y,
                         g.origin.z + double(i0[2] + ((k >> 2) & 1)) * g.spacing.z};
            if (plane_distance(e, n, g.origin, g.spacing, i0, p) >= 0) e[4] = static_cast<std::uint8_t>(e[4] | (1u << k));
        }
    }
    EXPECT_TRUE(validate_probe_set(*set).ok()) << validate_probe_set(*set).error().message;
    return std::move(set).value();
}

Bytes empty_gltf() {
    const std::string s = R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0})";
    return {s.begin(), s.end()};
}

// The bytes of accessor `a` of a zhc output (tightly packed, as zhc writes them).
Bytes accessor_data(const Bytes& file, const json& doc, std::size_t a, std::size_t element) {
    const json& acc = doc["accessors"][a];
    const json& view = doc["bufferViews"][acc["bufferView"].get<size_t>()];
    const Bytes buffer = gltf_test::buffer_bytes(file, view["buffer"].get<size_t>());
    const std::size_t at = view["byteOffset"].get<size_t>() + acc.value("byteOffset", size_t(0));
    return Bytes(buffer.begin() + static_cast<std::ptrdiff_t>(at),
                 buffer.begin() + static_cast<std::ptrdiff_t>(at + element * acc["count"].get<size_t>()));
}

TEST(GltfPlanes, RoundTripExactEitherAxesContainerAndEncoding) {
    for (const char* rep : {"zh3_q16", "sh3"})
        for (GltfShAxes axes : {GltfShAxes::kZhc, GltfShAxes::kGltf})
            for (bool binary : {true, false}) {
                const ProbeSet set = planes_set(rep);
                GltfEmbedOptions eo;
                eo.sh_axes = axes;
                eo.binary = binary;
                auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", set, eo);
                ASSERT_TRUE(bytes.ok()) << bytes.error().message;
                auto back = read_gltf_probes(*bytes, "out");
                ASSERT_TRUE(back.ok()) << back.error().message;
                ASSERT_EQ(back->volumes.size(), 1u);
                EXPECT_EQ(back->volumes[0].set.planes, set.planes) << rep << " binary " << binary;
                const json doc = gltf_test::gltf_json(*bytes);
                const json& vol = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
                const json& pa = doc["accessors"][vol["planes"].get<size_t>()];
                const json& sa = doc["accessors"][vol["planeSides"].get<size_t>()];
                EXPECT_EQ(pa["componentType"], 5121);
                EXPECT_EQ(pa["type"], "VEC4");
                EXPECT_EQ(pa["count"], set.count);
                EXPECT_EQ(sa["componentType"], 5121);
                EXPECT_EQ(sa["type"], "SCALAR");
                EXPECT_EQ(sa["count"], set.count);
                // The stored bytes the reader counts: coefficients + 4 + 1 per probe.
                EXPECT_EQ(back->volumes[0].stored_bytes, set.payload.size() + 5 * set.count);
                if (axes == GltfShAxes::kZhc) {  // the stored coefficients are the input's: the .zhp is too
                    auto a = serialize_probe_set(set), b = serialize_probe_set(back->volumes[0].set);
                    ASSERT_TRUE(a.ok() && b.ok());
                    EXPECT_TRUE(*a == *b) << rep << ": .zhp -> glTF -> .zhp is not byte for byte";
                }
            }
    // A flat grid (one probe along zhc y = glTF x): those probes start cells and hold planes.
    const ProbeSet flat = planes_set("zh3_q16", 5, {3, 1, 2});
    int flat_planes = 0;
    for (std::uint64_t i = 0; i < flat.count; ++i) flat_planes += offset_of(flat.planes.data() + 5 * i) != -32768;
    EXPECT_GE(flat_planes, 1);
    auto flat_bytes = embed_probes_gltf(empty_gltf(), "in.gltf", flat, {});
    ASSERT_TRUE(flat_bytes.ok()) << flat_bytes.error().message;
    auto flat_back = read_gltf_probes(*flat_bytes, "flat.glb");
    ASSERT_TRUE(flat_back.ok()) << flat_back.error().message;
    EXPECT_EQ(flat_back->volumes[0].set.planes, flat.planes);
    // Without planes: neither key.
    ProbeSet plain = planes_set();
    plain.planes.clear();
    GltfEmbedOptions eo;
    eo.binary = false;
    auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", plain, eo);
    ASSERT_TRUE(bytes.ok());
    const json vol = gltf_test::gltf_json(*bytes)["extensions"]["ZHC_light_probes"]["volumes"][0];
    EXPECT_FALSE(vol.contains("planes"));
    EXPECT_FALSE(vol.contains("planeSides"));
}

// The accessors in glTF terms: probe (gx, gy, gz) of the glTF grid, its cell's corner (cx, cy, cz)
// at origin + (g + c) spacing in glTF axes, the normal (n.y, n.z, n.x) of the zhc-axes decode.
TEST(GltfPlanes, StoredPlanesAreTheSamePlanesInGltfAxes) {
    const ProbeSet set = planes_set("zh3_q16", 11);
    auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", set, {});
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
    const json doc = gltf_test::gltf_json(*bytes);
    const json& vol = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
    const Bytes planes = accessor_data(*bytes, doc, vol["planes"].get<size_t>(), 4);
    const Bytes sides = accessor_data(*bytes, doc, vol["planeSides"].get<size_t>(), 1);
    ASSERT_EQ(planes.size(), 4 * set.count);
    ASSERT_EQ(sides.size(), set.count);
    const json& g = vol["grid"];
    const std::uint64_t gn[3] = {g["counts"][0], g["counts"][1], g["counts"][2]};
    ASSERT_EQ(gn[0], kNy);
    ASSERT_EQ(gn[1], kNz);
    ASSERT_EQ(gn[2], kNx);
    const Vec3 origin{g["origin"][0], g["origin"][1], g["origin"][2]}, spacing{g["spacing"][0], g["spacing"][1], g["spacing"][2]};
    int planes_seen = 0, regions_seen = 0, corners_checked = 0, corners_positive = 0;
    for (std::uint64_t p = 0; p < set.count; ++p) {
        const std::array<std::uint64_t, 3> gi{p % gn[0], (p / gn[0]) % gn[1], p / (gn[0] * gn[1])};
        // The same probe in zhc's grid: (x, y, z)_zhc = (gz, gx, gy); its entry's first four bytes as stored.
        const std::uint64_t z = gi[2] + kNx * (gi[0] + kNy * gi[1]);
        const std::uint8_t* e = planes.data() + 4 * p;
        const std::uint8_t* ez = set.planes.data() + 5 * z;
        if (offset_of(e) == -32768 && (sides[p] & 0x80)) {
            // A corner region: its per-axis fields in glTF axes (glTF axis a = zhc axis (a + 1) % 3),
            // so the corners inside it are zhc's corners inside it, permuted like the masks.
            ++regions_seen;
            const unsigned rg = unsigned(e[0]) | unsigned(e[1]) << 8, rz = unsigned(ez[0]) | unsigned(ez[1]) << 8;
            std::uint8_t inside_g = 0, inside_z = 0;
            for (int a = 0; a < 3; ++a) {
                EXPECT_EQ((rg >> (5 * a)) & 31u, (rz >> (5 * ((a + 1) % 3))) & 31u) << "probe " << p << " axis " << a;
                EXPECT_EQ((sides[p] >> a) & 1u, (ez[4] >> ((a + 1) % 3)) & 1u) << "probe " << p << " axis " << a;
            }
            for (int k = 0; k < 8; ++k) {
                bool in_g = true, in_z = true;
                for (int a = 0; a < 3; ++a) {
                    in_g = in_g && (((rg >> (5 * a)) & 31u) == 0 || ((sides[p] >> a) & 1u) == unsigned((k >> a) & 1));
                    in_z = in_z && (((rz >> (5 * a)) & 31u) == 0 || ((ez[4] >> a) & 1u) == unsigned((k >> a) & 1));
                }
                inside_g = static_cast<std::uint8_t>(inside_g | (in_g ? 1u << k : 0u));
                inside_z = static_cast<std::uint8_t>(inside_z | (in_z ? 1u << k : 0u));
            }
            std::uint8_t inside_z_in_gltf = 0;  // zhc corner (dx, dy, dz) is glTF corner (dy, dz, dx)
            for (int k = 0; k < 8; ++k)
                if ((inside_z >> k) & 1)
                    inside_z_in_gltf = static_cast<std::uint8_t>(inside_z_in_gltf | 1u << (((k >> 1) & 1) + 2 * ((k >> 2) & 1) + 4 * (k & 1)));
            EXPECT_EQ(inside_g, inside_z_in_gltf) << "probe " << p;
            continue;
        }
        for (int b = 0; b < 4; ++b) EXPECT_EQ(e[b], ez[b]) << "probe " << p << " byte " << b;
        if (offset_of(e) == -32768) continue;
        ++planes_seen;
        const Vec3 nz = plane_normal(e[0], e[1]);
        const Vec3 n{nz.y, nz.z, nz.x};
        for (int k = 0; k < 8; ++k) {
            const Vec3 corner{origin.x + double(gi[0] + (k & 1)) * spacing.x, origin.y + double(gi[1] + ((k >> 1) & 1)) * spacing.y,
                              origin.z + double(gi[2] + ((k >> 2) & 1)) * spacing.z};
            const double d = plane_distance(e, n, origin, spacing, gi, corner);
            if (std::fabs(d) < 1e-9) continue;  // on the plane: either side is right
            ++corners_checked;
            corners_positive += d >= 0;
            EXPECT_EQ((sides[p] >> k) & 1, d >= 0 ? 1 : 0) << "glTF probe " << p << " corner " << k << " distance " << d;
        }
    }
    EXPECT_GE(planes_seen + regions_seen, 6);
    EXPECT_GE(planes_seen, 4);
    EXPECT_GE(regions_seen, 1);
    EXPECT_GT(corners_checked, 8 * planes_seen - 4);
    EXPECT_GT(corners_positive, 0);
    EXPECT_LT(corners_positive, corners_checked);  // both sides occur
}

// The .gltf output of planes_set() edited by `edit`: the reader's error (kInternal when it reads).
Error read_error(const std::function<void(json& doc, json& vol)>& edit) {
    GltfEmbedOptions eo;
    eo.binary = false;
    const Bytes good = *embed_probes_gltf(empty_gltf(), "in.gltf", planes_set(), eo);
    json doc = gltf_test::gltf_json(good);
    edit(doc, doc["extensions"]["ZHC_light_probes"]["volumes"][0]);
    const std::string text = doc.dump();
    auto r = read_gltf_probes(Bytes(text.begin(), text.end()), "x.gltf");
    return r.ok() ? Error{ErrorCode::kInternal, "read"} : r.error();
}

void expect_refused(const Error& e, ErrorCode code, const std::string& text) {
    EXPECT_EQ(e.code, code) << e.message;
    EXPECT_NE(e.message.find(text), std::string::npos) << e.message;
    EXPECT_EQ(e.message.find('\n'), std::string::npos) << e.message;
}

TEST(GltfPlanes, BadAccessorsAreRefusedNamingThem) {
    EXPECT_EQ(read_error([](json&, json&) {}).code, ErrorCode::kInternal);
    auto planes_acc = [](json& d, json& v) -> json& { return d["accessors"][v["planes"].get<size_t>()]; };
    auto sides_acc = [](json& d, json& v) -> json& { return d["accessors"][v["planeSides"].get<size_t>()]; };
    expect_refused(read_error([&](json& d, json& v) { planes_acc(d, v)["type"] = "VEC3"; }), ErrorCode::kBadFormat,
                   "volumes[0]: planes accessor");
    expect_refused(read_error([&](json& d, json& v) { planes_acc(d, v)["componentType"] = 5123; }), ErrorCode::kBadFormat,
                   "planes accessor");
    expect_refused(read_error([&](json& d, json& v) { sides_acc(d, v)["type"] = "VEC4"; }), ErrorCode::kBadFormat,
                   "planeSides accessor");
    expect_refused(read_error([&](json& d, json& v) { planes_acc(d, v)["count"] = 23; }), ErrorCode::kBadFormat,
                   "has 23 elements, expected 24");
    expect_refused(read_error([&](json& d, json& v) { sides_acc(d, v)["count"] = 12; }), ErrorCode::kBadFormat,
                   "planeSides accessor");
    expect_refused(read_error([](json&, json& v) { v["planes"] = 999; }), ErrorCode::kBadFormat, "planes is not a valid index");
    // The coefficients accessor (count x 16 SCALAR bytes) in place of either.
    expect_refused(read_error([](json&, json& v) { v["planeSides"] = v["coefficients"]; }), ErrorCode::kBadFormat,
                   "planeSides accessor");
    // One of the two.
    expect_refused(read_error([](json&, json& v) { v.erase("planeSides"); }), ErrorCode::kBadFormat, "planes without planeSides");
    expect_refused(read_error([](json&, json& v) { v.erase("planes"); }), ErrorCode::kBadFormat, "planeSides without planes");
    // Not a grid.
    expect_refused(read_error([](json&, json& v) {
                       v["layout"] = "none";
                       v.erase("grid");
                   }),
                   ErrorCode::kBadFormat, "planes need layout grid");
}

// A GLB of planes_set() with glTF probe `probe`'s plane offset set to 0 (a plane).
Bytes glb_with_plane_on(std::uint64_t probe) {
    Bytes b = *embed_probes_gltf(empty_gltf(), "in.gltf", planes_set(), {});
    const json doc = gltf_test::gltf_json(b);
    const json& acc = doc["accessors"][doc["extensions"]["ZHC_light_probes"]["volumes"][0]["planes"].get<size_t>()];
    const json& view = doc["bufferViews"][acc["bufferView"].get<size_t>()];
    std::uint32_t json_len;
    std::memcpy(&json_len, b.data() + 12, 4);
    const std::size_t at = 28 + json_len + view["byteOffset"].get<size_t>() + 4 * probe;
    b[at + 2] = 0;
    b[at + 3] = 0;
    return b;
}

TEST(GltfPlanes, APlaneOnAProbeThatStartsNoCellIsRefused) {
    // glTF grid (ny, nz, nx) = (2, 4, 3): probe 1 is the last along glTF x (gx = 1), probe 6 the
    // last along y (gy = 3), probe 16 the last along z (gz = 2), 23 along all three; probe 0 starts a cell.
    for (std::uint64_t p : {1u, 6u, 16u, 23u}) {
        auto r = read_gltf_probes(glb_with_plane_on(p), "x.glb");
        ASSERT_FALSE(r.ok()) << p;
        expect_refused(r.error(), ErrorCode::kInvalidValue, "planes accessor");
        EXPECT_NE(r.error().message.find("probe " + std::to_string(p) + " (glTF order) is the last along an axis"), std::string::npos)
            << r.error().message;
    }
    auto ok = read_gltf_probes(glb_with_plane_on(0), "x.glb");
    ASSERT_TRUE(ok.ok()) << ok.error().message;
    EXPECT_EQ(ok->volumes[0].set.planes[2], 0);  // glTF probe 0 is zhc probe 0
    EXPECT_EQ(ok->volumes[0].set.planes[3], 0);
}

// planes_set()'s .glb with the entry of glTF probe `probe` made a corner region: offset -32768,
// thresholds `r` (bytes 0-1), planeSides `sides` (bit 7 set).
Bytes glb_with_region_on(std::uint64_t probe, std::uint16_t r, std::uint8_t sides) {
    Bytes b = *embed_probes_gltf(empty_gltf(), "in.gltf", planes_set(), {});
    const json doc = gltf_test::gltf_json(b);
    const json& vol = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
    std::uint32_t json_len;
    std::memcpy(&json_len, b.data() + 12, 4);
    const auto at = [&](const char* key, std::size_t stride) {
        const json& acc = doc["accessors"][vol[key].get<size_t>()];
        return 28 + json_len + doc["bufferViews"][acc["bufferView"].get<size_t>()]["byteOffset"].get<size_t>() + stride * probe;
    };
    const std::size_t e = at("planes", 4);
    b[e] = static_cast<std::uint8_t>(r & 0xFF);
    b[e + 1] = static_cast<std::uint8_t>(r >> 8);
    b[e + 2] = 0x00;
    b[e + 3] = 0x80;
    b[at("planeSides", 1)] = sides;
    return b;
}

// A corner region is read on a probe that starts a cell (its fields back in zhc axes), refused on one
// that starts none and with a reserved bit set.
TEST(GltfPlanes, CornerRegionsOnlyWhereACellStarts) {
    const std::uint16_t r = 3 | 7 << 5 | 11 << 10;  // glTF axes: q = 3, 7, 11
    auto ok = read_gltf_probes(glb_with_region_on(0, r, 0x80 | 0x5), "x.glb");
    ASSERT_TRUE(ok.ok()) << ok.error().message;
    const std::uint8_t* e = ok->volumes[0].set.planes.data();  // glTF probe 0 is zhc probe 0
    ASSERT_EQ(cell_entry_kind(e), CellEntryKind::kRegion);
    const unsigned rz = unsigned(e[0]) | unsigned(e[1]) << 8;
    // zhc axis a is glTF axis (a + 2) % 3: q = 11, 3, 7 and d = (1, 1, 0) from glTF's (1, 0, 1).
    EXPECT_EQ(rz, 11u | 3u << 5 | 7u << 10);
    EXPECT_EQ(e[4], 0x80 | 0x3);
    for (std::uint64_t p : {1u, 6u, 16u, 23u}) {
        auto bad = read_gltf_probes(glb_with_region_on(p, r, 0x81), "x.glb");
        ASSERT_FALSE(bad.ok()) << p;
        expect_refused(bad.error(), ErrorCode::kInvalidValue, "planes accessor");
    }
    for (const auto& [rr, sides] : {std::pair<std::uint16_t, std::uint8_t>{std::uint16_t(r | 0x8000), 0x81}, {r, 0x89}}) {
        auto bad = read_gltf_probes(glb_with_region_on(0, rr, sides), "x.glb");
        ASSERT_FALSE(bad.ok());
        EXPECT_NE(bad.error().message.find("reserved bits"), std::string::npos) << bad.error().message;
    }
}

TEST(GltfPlanes, CliEmbedExtractConvert) {
    const std::string dir = test::fresh_dir("gltf_planes");
    const ProbeSet set = planes_set();
    const Bytes zhp = *serialize_probe_set(set);
    ASSERT_EQ(zhp[8], 2);  // version 2
    EXPECT_EQ(zhp[21], 4);  // the planes section alone
    test::write_bytes(dir + "/in.zhp", zhp);
    test::write_bytes(dir + "/scene.gltf", empty_gltf());
    for (const char* out : {"lit.glb", "lit.gltf"}) {
        auto r = test::run_zhc({"gltf", "embed", dir + "/scene.gltf", dir + "/in.zhp", "-o", dir + "/" + out});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        r = test::run_zhc({"gltf", "extract", dir + "/" + out, "-o", dir + "/back.zhp"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_TRUE(test::read_bytes(dir + "/back.zhp") == zhp) << out << ": zhc gltf extract differs from the embedded .zhp";
    }
    // Another encoding on the way in keeps the planes.
    auto r = test::run_zhc({"gltf", "embed", dir + "/scene.gltf", dir + "/in.zhp", "-o", dir + "/sh3.glb", "--encoding", "sh3", "--sh-axes", "gltf"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto s = read_gltf_probes_file(dir + "/sh3.glb");
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->volumes[0].set.planes, set.planes);
    // A tampered asset: exit 4, one line naming the accessor, nothing written.
    test::write_bytes(dir + "/bad.glb", glb_with_plane_on(16));
    r = test::run_zhc({"gltf", "extract", dir + "/bad.glb", "-o", dir + "/bad.zhp"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_NE(r.err.find("planes accessor"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/bad.zhp"));
    // zhc convert to another representation carries them (and the same one keeps the file's bytes).
    r = test::run_zhc({"convert", dir + "/in.zhp", "-o", dir + "/sh2.zhp", "--to", "sh2_q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto converted = parse_probe_set(test::read_bytes(dir + "/sh2.zhp"), "sh2.zhp");
    ASSERT_TRUE(converted.ok()) << converted.error().message;
    EXPECT_EQ(converted->representation, "sh2_q");
    EXPECT_EQ(converted->planes, set.planes);
}

// A default bake of a glTF scene with walls (examples/hall.gltf) writes validity and planes; its
// glTF output carries the same planes, and extracting it gives the .zhp bake byte for byte.
TEST(GltfPlanes, BakedGlbCarriesTheBakesPlanes) {
    const std::string dir = test::fresh_dir("gltf_planes_baked");
    const std::string hall = std::string(ZHC_TEST_DATA_DIR) + "/../../examples/hall.gltf";
    auto r = test::run_zhc({"bake", hall, "-o", dir + "/hall.zhp", "-r", "zh3_q16", "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"bake", hall, "-o", dir + "/hall.glb", "-r", "zh3_q16", "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Bytes zhp = test::read_bytes(dir + "/hall.zhp");
    auto baked = parse_probe_set(zhp, "hall.zhp");
    ASSERT_TRUE(baked.ok()) << baked.error().message;
    int planes = 0;
    for (std::uint64_t i = 0; i < baked->count && !baked->planes.empty(); ++i) planes += offset_of(baked->planes.data() + 5 * i) != -32768;
    EXPECT_GE(planes, 1) << "the bake of hall.gltf writes cell planes";
    const Bytes glb = test::read_bytes(dir + "/hall.glb");
    const json vol = gltf_test::gltf_json(glb)["extensions"]["ZHC_light_probes"]["volumes"][0];
    EXPECT_TRUE(vol.contains("planes") && vol.contains("planeSides")) << vol.dump();
    auto s = read_gltf_probes(glb, "hall.glb");
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->volumes[0].set.planes, baked->planes);
    EXPECT_EQ(s->volumes[0].set.validity, baked->validity);
    r = test::run_zhc({"gltf", "extract", dir + "/hall.glb", "-o", dir + "/back.zhp"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(test::read_bytes(dir + "/back.zhp") == zhp) << "zhc gltf extract of the baked .glb differs from the baked .zhp";
}

}  // namespace
}  // namespace zhc
