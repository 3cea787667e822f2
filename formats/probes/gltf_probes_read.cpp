// zhc/formats/probes/gltf_probes_read.cpp — reading the ZHC_light_probes extension (docs/gltf-extension.md)
// of a glTF 2.0 asset loaded by gltf_probes.cpp: every volume checked (encoding, quantisation, layout,
// counts), its coefficients and positions taken from bound-checked accessors or a Draco point cloud
// (gltf_draco.cpp), grid order and axes converted back to zhc's. The extension is read from our own
// nlohmann parse of the JSON, so every index it holds is checked against the arrays tinygltf loaded.
#include "formats/probes/gltf_probes_internal.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include "formats/io/file_io.h"
#include "formats/probes/gltf_draco.h"

namespace zhc {
using namespace gltf_detail;

namespace {

// ---- reading the extension ------------------------------------------------------------------

struct VolumeReader {
    const Loaded& in;
    const std::string& path;
    const GltfLimits& limits;
    std::string where;

    Error bad(ErrorCode code, const std::string& what) const { return fail(code, path, where + ": " + what); }

    Result<std::uint64_t> index(const json& v, const char* key, std::size_t size, bool required = true) const {
        if (!v.contains(key)) {
            if (required) return bad(ErrorCode::kBadFormat, std::string("missing ") + key);
            return std::numeric_limits<std::uint64_t>::max();
        }
        const json& x = v[key];
        if (!x.is_number_integer() || x.get<std::int64_t>() < 0 || x.get<std::uint64_t>() >= size)
            return bad(ErrorCode::kBadFormat, std::string(key) + " is not a valid index (0.." + std::to_string(size) + ")");
        return x.get<std::uint64_t>();
    }

    Result<Vec3> vec3(const json& v, const char* key) const {
        if (!v.contains(key) || !v[key].is_array() || v[key].size() != 3) return bad(ErrorCode::kBadFormat, std::string(key) + " is not [x, y, z]");
        double c[3];
        for (int k = 0; k < 3; ++k) {
            const json& e = v[key][static_cast<size_t>(k)];
            if (!e.is_number() || !std::isfinite(e.get<double>())) return bad(ErrorCode::kInvalidValue, std::string(key) + " holds a non-finite or non-number value");
            c[k] = e.get<double>();
        }
        return Vec3{c[0], c[1], c[2]};
    }

    // The bytes of accessor `acc`, checked to be `count` tightly packed elements of the type.
    Result<std::span<const std::uint8_t>> accessor_bytes(std::uint64_t acc, int component, int type, std::uint64_t count,
                                                         const char* what) const {
        const tinygltf::Model& m = in.model;
        const tinygltf::Accessor& a = m.accessors[static_cast<size_t>(acc)];
        const std::string an = std::string(what) + " accessor " + std::to_string(acc);
        if (a.sparse.isSparse) return bad(ErrorCode::kUnsupported, an + " is sparse");
        if (a.componentType != component || a.type != type)
            return bad(ErrorCode::kBadFormat, an + " has the wrong component type / type");
        if (a.count != count)
            return bad(ErrorCode::kBadFormat, an + " has " + std::to_string(a.count) + " elements, expected " + std::to_string(count));
        if (a.bufferView < 0 || static_cast<size_t>(a.bufferView) >= m.bufferViews.size())
            return bad(ErrorCode::kBadFormat, an + ": bufferView index out of range");
        const tinygltf::BufferView& v = m.bufferViews[static_cast<size_t>(a.bufferView)];
        const std::uint64_t elem = static_cast<std::uint64_t>(tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(component))) *
                                   static_cast<std::uint64_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(type)));
        if (v.byteStride != 0 && v.byteStride != elem) return bad(ErrorCode::kUnsupported, an + ": interleaved bufferView");
        if (v.buffer < 0 || static_cast<size_t>(v.buffer) >= m.buffers.size())
            return bad(ErrorCode::kBadFormat, an + ": buffer index out of range");
        const std::vector<unsigned char>& data = m.buffers[static_cast<size_t>(v.buffer)].data;
        const std::uint64_t view_off = v.byteOffset, view_len = v.byteLength, acc_off = a.byteOffset;
        if (count > limits.max_buffer_bytes / elem) return bad(ErrorCode::kTooLarge, an + " too large");
        const std::uint64_t need = count * elem;
        if (view_off > data.size() || view_len > data.size() - view_off)
            return bad(ErrorCode::kBadFormat, an + ": bufferView range outside its buffer");
        if (acc_off > view_len || need > view_len - acc_off)
            return bad(ErrorCode::kBadFormat, an + ": elements run past the end of the bufferView");
        return std::span<const std::uint8_t>(data.data() + view_off + acc_off, static_cast<size_t>(need));
    }

    // Optional cell planes (docs/gltf-extension.md "Cell planes"): `planes` (VEC4 UNSIGNED_BYTE: ou,
    // ov, offset lo, offset hi) and `planeSides` (SCALAR UNSIGNED_BYTE, corner bits in the glTF
    // grid's axes), both or neither, `count` elements in glTF probe order, grid layouts only. Into
    // set.planes (zhc order, zhc corner bits); `set` has its layout.
    Status read_planes(const json& v, ProbeSet& set, std::uint64_t& stored_bytes) const {
        const bool has_planes = v.contains("planes"), has_sides = v.contains("planeSides");
        if (!has_planes && !has_sides) return Ok{};
        if (has_planes != has_sides)
            return bad(ErrorCode::kBadFormat, has_planes ? "planes without planeSides (the cell planes need both accessors)"
                                                         : "planeSides without planes (the cell planes need both accessors)");
        if (set.layout.kind != ProbeLayoutKind::kGrid) return bad(ErrorCode::kBadFormat, "planes need layout grid");
        const tinygltf::Model& m = in.model;
        auto pa = index(v, "planes", m.accessors.size());
        if (!pa) return pa.error();
        auto pb = accessor_bytes(*pa, kUbyte, TINYGLTF_TYPE_VEC4, set.count, "planes");
        if (!pb) return pb.error();
        auto sa = index(v, "planeSides", m.accessors.size());
        if (!sa) return sa.error();
        auto sb = accessor_bytes(*sa, kUbyte, TINYGLTF_TYPE_SCALAR, set.count, "planeSides");
        if (!sb) return sb.error();
        const auto& zc = set.layout.grid.counts;
        const std::uint64_t gx_n = zc[1], gy_n = zc[2], gz_n = zc[0];  // glTF (nx, ny, nz) = zhc (ny, nz, nx)
        std::vector<std::uint8_t> entries(5 * set.count);
        for (std::uint64_t g = 0; g < set.count; ++g) {
            const std::uint8_t* e = pb->data() + 4 * g;
            const std::uint64_t gx = g % gx_n, gy = (g / gx_n) % gy_n, gz = g / (gx_n * gy_n);
            // The last probe along an axis of two or more starts no cell (along an axis of one, the
            // probe starts a flat cell: validate_leak_data).
            const bool last = (gx_n > 1 && gx + 1 == gx_n) || (gy_n > 1 && gy + 1 == gy_n) || (gz_n > 1 && gz + 1 == gz_n);
            if (last && !(e[2] == 0x00 && e[3] == 0x80 && !((*sb)[g] & 0x80u)))
                return bad(ErrorCode::kInvalidValue, "planes accessor " + std::to_string(*pa) + ": probe " + std::to_string(g) +
                                                         " (glTF order) is the last along an axis and starts no cell, but its plane is set "
                                                         "(offset " + std::to_string(static_cast<std::int16_t>(e[2] | e[3] << 8)) +
                                                         ", expected -32768 = no plane)");
            std::uint8_t* out = entries.data() + 5 * g;
            std::memcpy(out, e, 4);
            out[4] = (*sb)[g];
            if (cell_entry_kind(out) == CellEntryKind::kRegion) {
                region_entry_axes(out, /*to_gltf=*/false);  // a corner region: its per-axis fields back in zhc axes
            } else {
                out[4] = visibility_from_gltf(out[4]);
            }
        }
        set.planes = reorder_grid(entries, 5, zc, /*to_gltf_order=*/false);
        stored_bytes += pb->size() + sb->size();
        return Ok{};
    }

    // Optional tetrahedra (docs/gltf-extension.md "Tetrahedra"): `tetrahedra` and `tetraNeighbours`,
    // both or neither, VEC4 UNSIGNED_INT accessors of the same count (one element per tetrahedron),
    // points layouts only. Indices are into the volume's probe order (the set's own for points) and
    // keep their orientation (the glTF axes are a rotation of zhc's); a neighbour 4294967295 is -1
    // (the hull). Into set.tetrahedra / set.tetra_neighbours; validate_probe_set then checks them
    // (indices below count, neighbours sharing their faces) as the .zhp reader does.
    Status read_tetrahedra(const json& v, ProbeSet& set, std::uint64_t& stored_bytes) const {
        const bool has_tets = v.contains("tetrahedra"), has_nbrs = v.contains("tetraNeighbours");
        if (!has_tets && !has_nbrs) return Ok{};
        if (has_tets != has_nbrs)
            return bad(ErrorCode::kBadFormat, has_tets ? "tetrahedra without tetraNeighbours (the tetrahedra need both accessors)"
                                                       : "tetraNeighbours without tetrahedra (the tetrahedra need both accessors)");
        if (set.layout.kind != ProbeLayoutKind::kPositions) return bad(ErrorCode::kBadFormat, "tetrahedra need layout points");
        const tinygltf::Model& m = in.model;
        auto ta = index(v, "tetrahedra", m.accessors.size());
        if (!ta) return ta.error();
        const std::uint64_t t_count = m.accessors[static_cast<size_t>(*ta)].count;
        if (t_count == 0 || t_count > 0x7FFFFFFFu)
            return bad(ErrorCode::kBadFormat, "tetrahedra accessor " + std::to_string(*ta) + " has " + std::to_string(t_count) +
                                                  " elements, expected 1 to 2^31 - 1 tetrahedra");
        auto tb = accessor_bytes(*ta, kUint, TINYGLTF_TYPE_VEC4, t_count, "tetrahedra");
        if (!tb) return tb.error();
        auto na = index(v, "tetraNeighbours", m.accessors.size());
        if (!na) return na.error();
        auto nb = accessor_bytes(*na, kUint, TINYGLTF_TYPE_VEC4, t_count, "tetraNeighbours");
        if (!nb) return nb.error();
        set.tetrahedra.resize(static_cast<size_t>(t_count));
        set.tetra_neighbours.resize(static_cast<size_t>(t_count));
        for (std::uint64_t t = 0; t < t_count; ++t)
            for (std::size_t k = 0; k < 4; ++k) {
                const std::uint32_t vertex = le32(tb->data() + 16 * t + 4 * k), n = le32(nb->data() + 16 * t + 4 * k);
                if (vertex >= set.count)
                    return bad(ErrorCode::kInvalidValue, "tetrahedra accessor " + std::to_string(*ta) + ": tetrahedron " + std::to_string(t) +
                                                             " names probe " + std::to_string(vertex) + ", beyond the " +
                                                             std::to_string(set.count) + " probes");
                if (n != 0xFFFFFFFFu && n >= t_count)
                    return bad(ErrorCode::kInvalidValue, "tetraNeighbours accessor " + std::to_string(*na) + ": tetrahedron " +
                                                             std::to_string(t) + " face " + std::to_string(k) + " names tetrahedron " +
                                                             std::to_string(n) + ", beyond the " + std::to_string(t_count) +
                                                             " tetrahedra (4294967295: none)");
                set.tetrahedra[static_cast<size_t>(t)][k] = vertex;
                set.tetra_neighbours[static_cast<size_t>(t)][k] = n == 0xFFFFFFFFu ? -1 : static_cast<std::int32_t>(n);
            }
        if (Status st = validate_tetrahedra(set.count, set.tetrahedra, set.tetra_neighbours); !st)
            return bad(ErrorCode::kInvalidValue, st.error().message);
        stored_bytes += tb->size() + nb->size();
        return Ok{};
    }

    Result<GltfProbeVolume> read(const json& v) const {
        if (!v.is_object()) return bad(ErrorCode::kBadFormat, "not an object");
        GltfProbeVolume out;
        if (v.contains("name") && v["name"].is_string()) out.name = v["name"].get<std::string>();
        if (!v.contains("encoding") || !v["encoding"].is_string()) return bad(ErrorCode::kBadFormat, "missing encoding");
        ProbeSet& set = out.set;
        set.representation = v["encoding"].get<std::string>();
        const Codec* codec = set.codec();
        if (!codec) return bad(ErrorCode::kUnsupported, "unknown encoding '" + set.representation + "'");
        set.representation = std::string(codec->name);  // an alias (codec_aliases) reads as its entry
        if (!v.contains("count") || !v["count"].is_number_unsigned() || v["count"].get<std::uint64_t>() == 0)
            return bad(ErrorCode::kBadFormat, "count is not a positive integer");
        set.count = v["count"].get<std::uint64_t>();
        if (set.count > limits.max_probes) return bad(ErrorCode::kTooLarge, "count " + std::to_string(set.count) + " above the limit");
        if (v.contains("kind")) {
            const std::string k = v["kind"].is_string() ? v["kind"].get<std::string>() : "";
            if (k == "irradiance") set.params.kind = StoredKind::kIrradiance;
            else if (k != "radiance") return bad(ErrorCode::kUnsupported, "kind must be radiance or irradiance");
        }
        out.sh_axes = GltfShAxes::kGltf;
        if (v.contains("shAxes")) {
            const std::string a = v["shAxes"].is_string() ? v["shAxes"].get<std::string>() : "";
            if (a == "zhc") out.sh_axes = GltfShAxes::kZhc;
            else if (a != "gltf") return bad(ErrorCode::kUnsupported, "shAxes must be gltf or zhc");
        }
        if (v.contains("quantization")) {
            const json& q = v["quantization"];
            if (!q.is_object()) return bad(ErrorCode::kBadFormat, "quantization is not an object");
            auto str = [&](const char* key, const char* def) {
                return q.contains(key) && q[key].is_string() ? q[key].get<std::string>() : std::string(def);
            };
            if (q.contains("bits")) {
                if (!q["bits"].is_number_integer()) return bad(ErrorCode::kBadFormat, "quantization.bits is not an integer");
                const std::int64_t b = q["bits"].get<std::int64_t>();
                if (b < kMinQuantBits || b > kMaxQuantBits) return bad(ErrorCode::kBadFormat, "quantization.bits out of range");
                set.params.bits = static_cast<int>(b);
            }
            if (q.contains("sqrt")) {
                if (!q["sqrt"].is_boolean()) return bad(ErrorCode::kBadFormat, "quantization.sqrt is not a boolean");
                set.params.sqrt_encoding = q["sqrt"].get<bool>();
            }
            const std::string bound = str("l2Bound", "tight"), dc = str("dcFormat", "r11g11b10f"),
                              zm = str("zonalMapping", "affine"), ax = str("axisMode", "luminance");
            if (bound == "loose") set.params.l2_bound = L2Bound::kLoose;
            else if (bound != "tight") return bad(ErrorCode::kUnsupported, "unknown l2Bound");
            if (dc == "rgb9e5") set.params.dc_format = DcFormat::kRGB9E5;
            else if (dc == "half") set.params.dc_format = DcFormat::kHalf;
            else if (dc != "r11g11b10f") return bad(ErrorCode::kUnsupported, "unknown dcFormat");
            if (zm == "zero") set.params.zonal_mapping = ZonalMapping::kZeroPreserving;
            else if (zm == "symmetric") set.params.zonal_mapping = ZonalMapping::kSymmetric;
            else if (zm != "affine") return bad(ErrorCode::kUnsupported, "unknown zonalMapping");
            if (ax == "channel") set.params.axis_mode = ZonalAxisMode::kPerChannel;
            else if (ax != "luminance") return bad(ErrorCode::kUnsupported, "unknown axisMode");
        }
        if (v.contains("luminanceWeights")) {
            auto w = vec3(v, "luminanceWeights");
            if (!w) return w.error();
            set.params.luminance = {w->x, w->y, w->z};
        }
        auto pv = validate_quant_params(set.params, set.representation);
        if (!pv) return bad(ErrorCode::kBadFormat, pv.error().message);

        const std::string layout = v.contains("layout") && v["layout"].is_string() ? v["layout"].get<std::string>() : "";
        const std::size_t size = codec->size_bytes;
        const tinygltf::Model& m = in.model;
        std::vector<std::array<float, 3>> gltf_positions;
        if (v.contains("draco")) {
            out.draco = true;
            if (layout != "points") return bad(ErrorCode::kBadFormat, "draco needs layout points");
            const json& d = v["draco"];
            if (!d.is_object()) return bad(ErrorCode::kBadFormat, "draco is not an object");
            auto view = index(d, "bufferView", m.bufferViews.size());
            if (!view) return view.error();
            const tinygltf::BufferView& bv = m.bufferViews[static_cast<size_t>(*view)];
            if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= m.buffers.size())
                return bad(ErrorCode::kBadFormat, "draco bufferView: buffer index out of range");
            const std::vector<unsigned char>& data = m.buffers[static_cast<size_t>(bv.buffer)].data;
            if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
                return bad(ErrorCode::kBadFormat, "draco bufferView range outside its buffer");
            out.stored_bytes = bv.byteLength;
            if (set.count > limits.max_buffer_bytes / size)
                return bad(ErrorCode::kTooLarge, "Draco volume decodes to more than the buffer size limit");
            if (!d.contains("attributes") || !d["attributes"].is_object()) return bad(ErrorCode::kBadFormat, "draco.attributes is not an object");
            std::map<std::string, int> attrs;
            for (auto a = d["attributes"].begin(); a != d["attributes"].end(); ++a) {
                if (!a.value().is_number_unsigned() || a.value().get<std::uint64_t>() > 1000000)
                    return bad(ErrorCode::kBadFormat, "draco.attributes." + a.key() + " is not a valid unique id");
                attrs[a.key()] = a.value().get<int>();
            }
            auto decoded = decode_probe_point_cloud(std::span<const std::uint8_t>(data.data() + bv.byteOffset, bv.byteLength),
                                                    set.representation, set.count, attrs, path + ": " + where);
            if (!decoded) return decoded.error();
            gltf_positions = std::move(decoded->positions);
            set.payload = std::move(decoded->payload);
        } else {
            auto acc = index(v, "coefficients", m.accessors.size());
            if (!acc) return acc.error();
            Result<std::span<const std::uint8_t>> bytes =
                is_float_vec3_encoding(set.representation)
                    ? accessor_bytes(*acc, kFloat, TINYGLTF_TYPE_VEC3, set.count * (size / 12), "coefficients")
                    : accessor_bytes(*acc, kUbyte, TINYGLTF_TYPE_SCALAR, set.count * size, "coefficients");
            if (!bytes) return bytes.error();
            set.payload.assign(bytes->begin(), bytes->end());
            out.stored_bytes = bytes->size();
            if (layout == "points") {
                auto pacc = index(v, "positions", m.accessors.size());
                if (!pacc) return pacc.error();
                auto pb = accessor_bytes(*pacc, kFloat, TINYGLTF_TYPE_VEC3, set.count, "positions");
                if (!pb) return pb.error();
                gltf_positions.resize(set.count);
                for (std::uint64_t i = 0; i < set.count; ++i)
                    for (int k = 0; k < 3; ++k) {
                        std::uint32_t bits = le32(pb->data() + i * 12 + static_cast<size_t>(k) * 4);
                        std::memcpy(&gltf_positions[i][static_cast<size_t>(k)], &bits, 4);
                    }
                out.stored_bytes += pb->size();
            }
        }
        if (layout == "grid") {
            if (!v.contains("grid") || !v["grid"].is_object()) return bad(ErrorCode::kBadFormat, "layout grid without a grid object");
            const json& g = v["grid"];
            auto origin = vec3(g, "origin");
            if (!origin) return origin.error();
            auto spacing = vec3(g, "spacing");
            if (!spacing) return spacing.error();
            if (!g.contains("counts") || !g["counts"].is_array() || g["counts"].size() != 3) return bad(ErrorCode::kBadFormat, "grid.counts is not [nx, ny, nz]");
            std::array<std::uint32_t, 3> gc{};
            for (int k = 0; k < 3; ++k) {
                const json& c = g["counts"][static_cast<size_t>(k)];
                if (!c.is_number_unsigned() || c.get<std::uint64_t>() == 0 || c.get<std::uint64_t>() > 0xFFFFFFFFu)
                    return bad(ErrorCode::kBadFormat, "grid.counts entries must be positive 32-bit integers");
                gc[static_cast<size_t>(k)] = static_cast<std::uint32_t>(c.get<std::uint64_t>());
            }
            set.layout.kind = ProbeLayoutKind::kGrid;
            set.layout.grid.origin = from_gltf(*origin);
            set.layout.grid.spacing = from_gltf(*spacing);
            set.layout.grid.counts = {gc[2], gc[0], gc[1]};  // glTF (y, z, x)_zhc
            if (layout_probe_count(set.layout) != static_cast<std::int64_t>(set.count))
                return bad(ErrorCode::kBadFormat, "grid counts do not multiply to count");
            set.payload = reorder_grid(set.payload, size, set.layout.grid.counts, /*to_gltf_order=*/false);
        } else if (layout == "points") {
            set.layout.kind = ProbeLayoutKind::kPositions;
            set.layout.positions.resize(gltf_positions.size());
            for (size_t i = 0; i < gltf_positions.size(); ++i) {
                for (float c : gltf_positions[i])
                    if (!std::isfinite(c)) return bad(ErrorCode::kInvalidValue, "non-finite probe position " + std::to_string(i));
                set.layout.positions[i] = from_gltf(gltf_positions[i]);
            }
        } else if (layout != "none") {
            return bad(ErrorCode::kUnsupported, "layout must be grid, points or none");
        }
        // Optional leak-avoidance data: UNSIGNED_BYTE SCALAR accessors of `count` elements.
        for (const char* key : {"validity", "visibility"}) {
            if (!v.contains(key)) continue;
            auto a = index(v, key, m.accessors.size());
            if (!a) return a.error();
            auto b = accessor_bytes(*a, kUbyte, TINYGLTF_TYPE_SCALAR, set.count, key);
            if (!b) return b.error();
            std::vector<std::uint8_t> data(b->begin(), b->end());
            const bool is_validity = std::string(key) == "validity";
            if (!is_validity && set.layout.kind != ProbeLayoutKind::kGrid)
                return bad(ErrorCode::kBadFormat, "visibility needs layout grid");
            if (is_validity)
                for (size_t i = 0; i < data.size(); ++i)
                    if (data[i] > 1)
                        return bad(ErrorCode::kInvalidValue, "validity of probe " + std::to_string(i) + " is " +
                                                                 std::to_string(data[i]) + ", expected 0 or 1");
            if (set.layout.kind == ProbeLayoutKind::kGrid)
                data = reorder_grid(data, 1, set.layout.grid.counts, /*to_gltf_order=*/false);
            if (!is_validity)
                for (std::uint8_t& x : data) x = visibility_from_gltf(x);
            out.stored_bytes += b->size();
            (is_validity ? set.validity : set.visibility) = std::move(data);
        }
        if (auto planes = read_planes(v, set, out.stored_bytes); !planes) return planes.error();
        if (auto tets = read_tetrahedra(v, set, out.stored_bytes); !tets) return tets.error();
        auto valid = validate_probe_set(set);
        if (!valid) return bad(ErrorCode::kBadFormat, valid.error().message);
        if (out.sh_axes == GltfShAxes::kGltf) {
            auto back = rotate_set(set, transpose(zhc_to_gltf_rotation()));
            if (!back) return bad(ErrorCode::kBadFormat, back.error().message);
            set = std::move(back).value();
        }
        return out;
    }
};

}  // namespace

Result<GltfSummary> read_gltf_probes(std::span<const std::uint8_t> bytes, const std::string& path, const GltfLimits& limits) {
    auto loaded = load(bytes, path, limits);
    if (!loaded) return loaded.error();
    const Loaded& in = *loaded;
    const tinygltf::Model& m = in.model;
    GltfSummary s;
    s.binary = in.binary;
    s.generator = m.asset.generator;
    s.meshes = m.meshes.size();
    s.materials = m.materials.size();
    s.nodes = m.nodes.size();
    s.buffers = m.buffers.size();
    s.accessors = m.accessors.size();
    s.images = in.doc.contains("images") && in.doc["images"].is_array() ? in.doc["images"].size() : 0;
    s.extensions_used = m.extensionsUsed;
    s.extensions_required = m.extensionsRequired;
    if (!in.doc.contains("extensions") || !in.doc["extensions"].is_object() || !in.doc["extensions"].contains(kGltfProbeExtension))
        return s;
    const json& ext = in.doc["extensions"][kGltfProbeExtension];
    if (!ext.is_object() || !ext.contains("volumes") || !ext["volumes"].is_array())
        return fail(ErrorCode::kBadFormat, path, std::string(kGltfProbeExtension) + ": volumes is not an array");
    const json& vols = ext["volumes"];
    for (size_t i = 0; i < vols.size(); ++i) {
        VolumeReader r{in, path, limits, std::string(kGltfProbeExtension) + ".volumes[" + std::to_string(i) + "]"};
        auto v = r.read(vols[i]);
        if (!v) return v.error();
        s.volumes.push_back(std::move(v).value());
    }
    if (in.doc.contains("nodes") && in.doc["nodes"].is_array()) {
        const json& nodes = in.doc["nodes"];
        for (size_t n = 0; n < nodes.size(); ++n) {
            if (!nodes[n].is_object() || !nodes[n].contains("extensions") || !nodes[n]["extensions"].is_object() ||
                !nodes[n]["extensions"].contains(kGltfProbeExtension))
                continue;
            const json& ne = nodes[n]["extensions"][kGltfProbeExtension];
            if (!ne.is_object() || !ne.contains("volume") || !ne["volume"].is_number_unsigned() ||
                ne["volume"].get<std::uint64_t>() >= s.volumes.size())
                return fail(ErrorCode::kBadFormat, path, "nodes[" + std::to_string(n) + "]." + kGltfProbeExtension + ".volume is not a valid volume index");
            s.volumes[ne["volume"].get<size_t>()].nodes.push_back(static_cast<int>(n));
        }
    }
    return s;
}

Result<GltfSummary> read_gltf_probes_file(const std::string& path, const GltfLimits& limits) {
    auto bytes = read_file_bytes(path, limits.max_file_bytes);
    if (!bytes) return bytes.error();
    return read_gltf_probes(*bytes, path, limits);
}

}  // namespace zhc
