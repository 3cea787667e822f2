// The Delaunay tetrahedra of a points volume (ProbeSet::tetrahedra / tetra_neighbours) in glTF: the
// ZHC_light_probes accessors `tetrahedra` and `tetraNeighbours` (VEC4 UNSIGNED_INT, one element per
// tetrahedron, 4294967295 = no neighbour), docs/gltf-extension.md "Tetrahedra":
//  * embed -> read gives the same tetrahedra and neighbours, both SH axes, GLB and .gltf, quantised,
//    float and Draco, with validity; the .zhp written from the read set is the input .zhp byte for
//    byte; a volume without the two keys reads as a set without tetrahedra (as before them);
//  * the stored accessors, read here from the file's bytes: element t is tetrahedron t's probe
//    indices, positively oriented in the stored glTF positions (a double determinant computed here),
//    each neighbour sharing exactly the 3 probes of its face (a quadratic scan), 4294967295 where no
//    other tetrahedron has that face;
//  * refusals, one line naming the accessor: wrong type / componentType, unequal or zero counts, one
//    accessor of the two, tetrahedra on a grid, a probe index out of range, a neighbour out of range
//    or not sharing its face;
//  * the CLI: `zhc gltf embed` then `zhc gltf extract` give the input .zhp byte for byte, `zhc info`
//    counts the tetrahedra of a glTF volume, a tampered asset exits 4 in one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "formats/probes/tetra.h"
#include "gltf_helpers.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;
using gltf_test::Bytes;
using gltf_test::json;

// `n` probes at random positions (a box of different extents per axis) with random SH, encoded as
// `rep`, with their tetrahedra (formats/probes/tetra.h); with `validity`, a fifth of them invalid.
ProbeSet points_set(const std::string& rep, std::size_t n = 40, unsigned seed = 5, bool validity = false) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    ProbeLayout layout;
    layout.kind = ProbeLayoutKind::kPositions;
    std::vector<Sh3Radiance> hub(n);
    for (std::size_t i = 0; i < n; ++i) {
        layout.positions.push_back({-2.0f + 6.0f * u(rng), 0.5f + 2.0f * u(rng), -1.0f + 3.0f * u(rng)});
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) hub[i][c][k] = c == 0 ? 1.0f + u(rng) : 0.2f * (u(rng) - 0.5f);
    }
    auto set = encode_probe_set(hub, rep, {}, layout);
    EXPECT_TRUE(set.ok()) << set.error().message;
    const std::vector<std::string> notes = add_tetrahedra(*set);
    EXPECT_TRUE(notes.empty()) << notes.front();
    EXPECT_GE(set->tetrahedra.size(), n);
    if (validity) {
        set->validity.assign(n, 1);
        for (std::size_t i = 0; i < n; i += 5) set->validity[i] = 0;
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

std::uint32_t u32_at(const Bytes& b, std::size_t at) {
    return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 | std::uint32_t(b[at + 3]) << 24;
}

TEST(GltfTetra, RoundTripExactEitherAxesContainerAndEncoding) {
    for (const char* rep : {"zh3_q16", "sh3"})
        for (GltfShAxes axes : {GltfShAxes::kZhc, GltfShAxes::kGltf})
            for (bool binary : {true, false})
                for (bool validity : {false, true}) {
                    const ProbeSet set = points_set(rep, 40, 5, validity);
                    GltfEmbedOptions eo;
                    eo.sh_axes = axes;
                    eo.binary = binary;
                    auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", set, eo);
                    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
                    auto back = read_gltf_probes(*bytes, "out");
                    ASSERT_TRUE(back.ok()) << back.error().message;
                    ASSERT_EQ(back->volumes.size(), 1u);
                    const ProbeSet& got = back->volumes[0].set;
                    EXPECT_EQ(got.tetrahedra, set.tetrahedra) << rep << " binary " << binary;
                    EXPECT_EQ(got.tetra_neighbours, set.tetra_neighbours) << rep << " binary " << binary;
                    EXPECT_EQ(got.validity, set.validity);
                    EXPECT_TRUE(got.layout.positions == set.layout.positions);
                    // The stored bytes the reader counts: coefficients, positions, validity, 32 per tetrahedron.
                    EXPECT_EQ(back->volumes[0].stored_bytes,
                              set.payload.size() + 12 * set.count + set.validity.size() + 32 * set.tetrahedra.size());
                    if (axes == GltfShAxes::kZhc) {  // the stored coefficients are the input's: the .zhp is too
                        auto a = serialize_probe_set(set), b = serialize_probe_set(got);
                        ASSERT_TRUE(a.ok() && b.ok());
                        EXPECT_TRUE(*a == *b) << rep << ": .zhp -> glTF -> .zhp is not byte for byte";
                    }
                }
    // Draco point cloud (sequential: the point order, and so the indices, are kept).
    const ProbeSet set = points_set("sh3", 30, 9);
    GltfEmbedOptions eo;
    eo.draco = true;
    auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", set, eo);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
    auto back = read_gltf_probes(*bytes, "draco.glb");
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_TRUE(back->volumes[0].draco);
    EXPECT_EQ(back->volumes[0].set.tetrahedra, set.tetrahedra);
    EXPECT_EQ(back->volumes[0].set.tetra_neighbours, set.tetra_neighbours);
    EXPECT_TRUE(back->volumes[0].set.layout.positions == set.layout.positions);
}

TEST(GltfTetra, WithoutTetrahedraNeitherKeyAndOlderFilesRead) {
    ProbeSet plain = points_set("zh3_q16");
    plain.tetrahedra.clear();
    plain.tetra_neighbours.clear();
    GltfEmbedOptions eo;
    eo.binary = false;
    auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", plain, eo);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
    const json vol = gltf_test::gltf_json(*bytes)["extensions"]["ZHC_light_probes"]["volumes"][0];
    EXPECT_FALSE(vol.contains("tetrahedra"));
    EXPECT_FALSE(vol.contains("tetraNeighbours"));
    auto back = read_gltf_probes(*bytes, "plain.gltf");
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_TRUE(back->volumes[0].set.tetrahedra.empty());
    // A file with tetrahedra whose two keys are removed (as a file written before them): the same set without.
    auto with = embed_probes_gltf(empty_gltf(), "in.gltf", points_set("zh3_q16"), eo);
    ASSERT_TRUE(with.ok());
    json doc = gltf_test::gltf_json(*with);
    json& v = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
    ASSERT_TRUE(v.contains("tetrahedra") && v.contains("tetraNeighbours"));
    v.erase("tetrahedra");
    v.erase("tetraNeighbours");
    const std::string text = doc.dump();
    auto old = read_gltf_probes(Bytes(text.begin(), text.end()), "old.gltf");
    ASSERT_TRUE(old.ok()) << old.error().message;
    EXPECT_TRUE(old->volumes[0].set.tetrahedra.empty());
    EXPECT_TRUE(old->volumes[0].set.payload == plain.payload);
}

// The accessors in glTF terms, from the file's bytes: the glTF positions, VEC4 UNSIGNED_INT elements.
TEST(GltfTetra, StoredTetrahedraArePositiveInGltfAxesWithTheirNeighbours) {
    for (GltfShAxes axes : {GltfShAxes::kZhc, GltfShAxes::kGltf}) {
        const ProbeSet set = points_set("zh3_q16", 50, 21);
        GltfEmbedOptions eo;
        eo.sh_axes = axes;
        auto bytes = embed_probes_gltf(empty_gltf(), "in.gltf", set, eo);
        ASSERT_TRUE(bytes.ok()) << bytes.error().message;
        const json doc = gltf_test::gltf_json(*bytes);
        const json& vol = doc["extensions"]["ZHC_light_probes"]["volumes"][0];
        const json& ta = doc["accessors"][vol["tetrahedra"].get<size_t>()];
        const json& na = doc["accessors"][vol["tetraNeighbours"].get<size_t>()];
        for (const json* a : {&ta, &na}) {
            EXPECT_EQ((*a)["componentType"], 5125);
            EXPECT_EQ((*a)["type"], "VEC4");
            EXPECT_EQ((*a)["count"], set.tetrahedra.size());
            EXPECT_FALSE(a->contains("normalized"));
        }
        const Bytes tets = accessor_data(*bytes, doc, vol["tetrahedra"].get<size_t>(), 16);
        const Bytes nbrs = accessor_data(*bytes, doc, vol["tetraNeighbours"].get<size_t>(), 16);
        const Bytes pos = accessor_data(*bytes, doc, vol["positions"].get<size_t>(), 12);
        const std::size_t T = set.tetrahedra.size();
        ASSERT_EQ(tets.size(), 16 * T);
        ASSERT_EQ(nbrs.size(), 16 * T);
        auto vertex = [&](std::size_t t, std::size_t k) { return u32_at(tets, 16 * t + 4 * k); };
        auto position = [&](std::uint32_t p) {
            float c[3];
            for (std::size_t k = 0; k < 3; ++k) {
                const std::uint32_t bits = u32_at(pos, 12 * p + 4 * k);
                std::memcpy(&c[k], &bits, 4);
            }
            return Vec3{c[0], c[1], c[2]};
        };
        int hull_faces = 0;
        for (std::size_t t = 0; t < T; ++t) {
            for (std::size_t k = 0; k < 4; ++k) {
                ASSERT_LT(vertex(t, k), set.count);
                EXPECT_EQ(vertex(t, k), set.tetrahedra[t][k]) << "tetrahedron " << t;
            }
            // det[b - a, c - a, d - a] in the glTF positions, in double.
            const Vec3 a = position(vertex(t, 0)), b = position(vertex(t, 1)) - a, c = position(vertex(t, 2)) - a,
                       d = position(vertex(t, 3)) - a;
            const double det = b.x * (c.y * d.z - c.z * d.y) - b.y * (c.x * d.z - c.z * d.x) + b.z * (c.x * d.y - c.y * d.x);
            EXPECT_GT(det, 0.0) << "tetrahedron " << t << " is not positively oriented in glTF axes";
            // Neighbour j: the other tetrahedron holding the 3 probes of face j, or none (quadratic scan).
            for (std::size_t j = 0; j < 4; ++j) {
                std::vector<std::uint32_t> face;
                for (std::size_t k = 0; k < 4; ++k)
                    if (k != j) face.push_back(vertex(t, k));
                std::uint32_t expected = 0xFFFFFFFFu;
                for (std::size_t s = 0; s < T; ++s) {
                    if (s == t) continue;
                    int shared = 0;
                    for (std::uint32_t f : face)
                        for (std::size_t k = 0; k < 4; ++k) shared += vertex(s, k) == f;
                    if (shared == 3) {
                        EXPECT_EQ(expected, 0xFFFFFFFFu) << "face " << j << " of " << t << " in two other tetrahedra";
                        expected = static_cast<std::uint32_t>(s);
                    }
                }
                EXPECT_EQ(u32_at(nbrs, 16 * t + 4 * j), expected) << "tetrahedron " << t << " face " << j;
                hull_faces += expected == 0xFFFFFFFFu;
            }
        }
        EXPECT_GE(hull_faces, 4);  // a convex hull has at least 4 faces
        EXPECT_LT(hull_faces, static_cast<int>(4 * T));
    }
}

// The .gltf output of points_set() edited by `edit`: the reader's error (kInternal when it reads).
Error read_error(const std::function<void(json& doc, json& vol)>& edit) {
    GltfEmbedOptions eo;
    eo.binary = false;
    const Bytes good = *embed_probes_gltf(empty_gltf(), "in.gltf", points_set("zh3_q16"), eo);
    json doc = gltf_test::gltf_json(good);
    edit(doc, doc["extensions"]["ZHC_light_probes"]["volumes"][0]);
    const std::string text = doc.dump();
    auto r = read_gltf_probes(Bytes(text.begin(), text.end()), "x.gltf");
    return r.ok() ? Error{ErrorCode::kInternal, "read"} : r.error();
}

void expect_refused(const Error& e, ErrorCode code, const std::string& text) {
    EXPECT_EQ(e.code, code) << e.message;
    EXPECT_NE(e.message.find(text), std::string::npos) << e.message;
    EXPECT_NE(e.message.find("x.gltf: "), std::string::npos) << e.message;  // names the file
    EXPECT_EQ(e.message.find('\n'), std::string::npos) << e.message;
}

// A GLB of points_set() whose tetrahedra (or neighbours) accessor's element `t` component `k` is `value`.
Bytes glb_with(const char* key, std::size_t t, std::size_t k, std::uint32_t value) {
    Bytes b = *embed_probes_gltf(empty_gltf(), "in.gltf", points_set("zh3_q16"), {});
    const json doc = gltf_test::gltf_json(b);
    const json& acc = doc["accessors"][doc["extensions"]["ZHC_light_probes"]["volumes"][0][key].get<size_t>()];
    const json& view = doc["bufferViews"][acc["bufferView"].get<size_t>()];
    std::uint32_t json_len;
    std::memcpy(&json_len, b.data() + 12, 4);
    const std::size_t at = 28 + json_len + view["byteOffset"].get<size_t>() + 16 * t + 4 * k;
    for (int i = 0; i < 4; ++i) b[at + static_cast<size_t>(i)] = static_cast<std::uint8_t>(value >> (8 * i));
    return b;
}

TEST(GltfTetra, BadAccessorsAreRefusedNamingThem) {
    EXPECT_EQ(read_error([](json&, json&) {}).code, ErrorCode::kInternal);
    auto acc = [](const char* key) {
        return [key](json& d, json& v) -> json& { return d["accessors"][v[key].get<size_t>()]; };
    };
    const auto tet = acc("tetrahedra"), nbr = acc("tetraNeighbours");
    const std::size_t T = points_set("zh3_q16").tetrahedra.size();
    // Wrong type / componentType: SCALAR of 4 T, VEC3, UNSIGNED_SHORT, FLOAT.
    expect_refused(read_error([&](json& d, json& v) {
                       tet(d, v)["type"] = "SCALAR";
                       tet(d, v)["count"] = 4 * T;
                   }),
                   ErrorCode::kBadFormat, "volumes[0]: tetrahedra accessor");
    expect_refused(read_error([&](json& d, json& v) { tet(d, v)["type"] = "VEC3"; }), ErrorCode::kBadFormat, "wrong component type / type");
    expect_refused(read_error([&](json& d, json& v) { tet(d, v)["componentType"] = 5123; }), ErrorCode::kBadFormat, "tetrahedra accessor");
    expect_refused(read_error([&](json& d, json& v) { nbr(d, v)["componentType"] = 5126; }), ErrorCode::kBadFormat,
                   "tetraNeighbours accessor");
    // Counts: unequal, zero, more than the bufferView holds.
    expect_refused(read_error([&](json& d, json& v) { nbr(d, v)["count"] = T - 1; }), ErrorCode::kBadFormat,
                   "has " + std::to_string(T - 1) + " elements, expected " + std::to_string(T));
    expect_refused(read_error([&](json& d, json& v) { tet(d, v)["count"] = 0; }), ErrorCode::kBadFormat, "expected 1 to 2^31 - 1 tetrahedra");
    expect_refused(read_error([&](json& d, json& v) {
                       tet(d, v)["count"] = T + 1;
                       nbr(d, v)["count"] = T + 1;
                   }),
                   ErrorCode::kBadFormat, "elements run past the end of the bufferView");
    expect_refused(read_error([](json&, json& v) { v["tetrahedra"] = 999; }), ErrorCode::kBadFormat, "tetrahedra is not a valid index");
    // The coefficients accessor (SCALAR UNSIGNED_BYTE) in place of either.
    expect_refused(read_error([](json&, json& v) { v["tetraNeighbours"] = v["coefficients"]; }), ErrorCode::kBadFormat,
                   "tetraNeighbours accessor");
    // One of the two.
    expect_refused(read_error([](json&, json& v) { v.erase("tetraNeighbours"); }), ErrorCode::kBadFormat,
                   "tetrahedra without tetraNeighbours");
    expect_refused(read_error([](json&, json& v) { v.erase("tetrahedra"); }), ErrorCode::kBadFormat, "tetraNeighbours without tetrahedra");
    // Not points.
    expect_refused(read_error([](json&, json& v) {
                       v["layout"] = "none";
                       v.erase("positions");
                   }),
                   ErrorCode::kBadFormat, "tetrahedra need layout points");
}

TEST(GltfTetra, BadIndicesAreRefusedNamingThem) {
    const ProbeSet set = points_set("zh3_q16");
    const std::size_t T = set.tetrahedra.size();
    auto refused = [](const Bytes& b, const std::string& text) {
        auto r = read_gltf_probes(b, "x.glb");
        ASSERT_FALSE(r.ok()) << text;
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidValue) << r.error().message;
        EXPECT_NE(r.error().message.find(text), std::string::npos) << r.error().message;
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << r.error().message;
    };
    // A probe index at count, and far beyond.
    refused(glb_with("tetrahedra", 3, 2, static_cast<std::uint32_t>(set.count)),
            "tetrahedra accessor 2: tetrahedron 3 names probe 40, beyond the 40 probes");
    refused(glb_with("tetrahedra", T - 1, 0, 0xFFFFFFFFu), "names probe 4294967295");
    // A probe named twice in one tetrahedron.
    refused(glb_with("tetrahedra", 0, 1, set.tetrahedra[0][0]), "names probe " + std::to_string(set.tetrahedra[0][0]) + " twice");
    // A neighbour at T, one beyond 2^31 (an int32 below -1), one that does not share the face.
    refused(glb_with("tetraNeighbours", 1, 3, static_cast<std::uint32_t>(T)), "tetraNeighbours accessor 3: tetrahedron 1 face 3 names tetrahedron");
    refused(glb_with("tetraNeighbours", 1, 3, 0x80000000u), "names tetrahedron 2147483648");
    std::size_t t = 0, j = 0;
    while (set.tetra_neighbours[t][j] == -1) {  // an inner face
        if (++j == 4) j = 0, ++t;
    }
    const std::uint32_t other = static_cast<std::uint32_t>((set.tetra_neighbours[t][j] + 1) % static_cast<std::int32_t>(T)) == t
                                    ? static_cast<std::uint32_t>((set.tetra_neighbours[t][j] + 2) % static_cast<std::int32_t>(T))
                                    : static_cast<std::uint32_t>((set.tetra_neighbours[t][j] + 1) % static_cast<std::int32_t>(T));
    refused(glb_with("tetraNeighbours", t, j, other), "does not share that face");
    // A hull face given a neighbour: that one does not name it back.
    std::size_t ht = 0, hj = 0;
    while (set.tetra_neighbours[ht][hj] != -1) {
        if (++hj == 4) hj = 0, ++ht;
    }
    refused(glb_with("tetraNeighbours", ht, hj, ht == 0 ? 1u : 0u), "does not share that face");
    // Untouched: reads.
    auto ok = read_gltf_probes(glb_with("tetrahedra", 0, 0, set.tetrahedra[0][0]), "x.glb");
    ASSERT_TRUE(ok.ok()) << ok.error().message;
}

TEST(GltfTetra, CliEmbedExtractInfo) {
    const std::string dir = test::fresh_dir("gltf_tetra");
    const ProbeSet set = points_set("zh3_q16", 40, 5, true);
    const Bytes zhp = *serialize_probe_set(set);
    ASSERT_EQ(zhp[8], 2);      // version 2
    EXPECT_EQ(zhp[21], 1 | 8);  // validity and tetrahedra sections
    test::write_bytes(dir + "/in.zhp", zhp);
    test::write_bytes(dir + "/scene.gltf", empty_gltf());
    for (const char* out : {"lit.glb", "lit.gltf"}) {
        auto r = test::run_zhc({"gltf", "embed", dir + "/scene.gltf", dir + "/in.zhp", "-o", dir + "/" + out});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        r = test::run_zhc({"gltf", "extract", dir + "/" + out, "-o", dir + "/back.zhp"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_TRUE(test::read_bytes(dir + "/back.zhp") == zhp) << out << ": zhc gltf extract differs from the embedded .zhp";
        r = test::run_zhc({"info", dir + "/" + out, "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const json info = json::parse(r.out);
        EXPECT_EQ(info["volumes"][0]["tetrahedra"], set.tetrahedra.size()) << r.out;
    }
    // A points volume without tetrahedra: no count.
    ProbeSet plain = set;
    plain.tetrahedra.clear();
    plain.tetra_neighbours.clear();
    test::write_bytes(dir + "/plain.zhp", *serialize_probe_set(plain));
    auto r = test::run_zhc({"gltf", "embed", dir + "/scene.gltf", dir + "/plain.zhp", "-o", dir + "/plain.glb"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"info", dir + "/plain.glb", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(json::parse(r.out)["volumes"][0].contains("tetrahedra")) << r.out;
    // A tampered asset: exit 4, one line naming the accessor, nothing written.
    test::write_bytes(dir + "/bad.glb", glb_with("tetrahedra", 2, 1, 1000));
    r = test::run_zhc({"gltf", "extract", dir + "/bad.glb", "-o", dir + "/bad.zhp"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_NE(r.err.find("tetrahedra accessor"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/bad.zhp"));
}

}  // namespace
}  // namespace zhc
