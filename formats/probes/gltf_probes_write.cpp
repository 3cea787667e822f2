// zhc/formats/probes/gltf_probes_write.cpp — embedding a probe set into a glTF 2.0 asset as the
// ZHC_light_probes extension (docs/gltf-extension.md): the input's own JSON kept (order and values),
// the probe data appended to the GLB binary buffer or a new data-URI buffer, accessors or a Draco
// point cloud (gltf_draco.cpp), images the output could no longer reach relocated or embedded, and
// the volume, extensionsUsed and a node added (or a volume of the same name replaced in place).
#include "formats/probes/gltf_probes_internal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <optional>

#include "formats/io/file_io.h"
#include "formats/probes/gltf_draco.h"

namespace zhc {
using namespace gltf_detail;

namespace {

const char* dc_name(DcFormat f) {
    switch (f) {
        case DcFormat::kR11G11B10F: return "r11g11b10f";
        case DcFormat::kRGB9E5: return "rgb9e5";
        case DcFormat::kHalf: return "half";
    }
    return "r11g11b10f";
}
const char* zonal_name(ZonalMapping m) {
    switch (m) {
        case ZonalMapping::kAffine: return "affine";
        case ZonalMapping::kZeroPreserving: return "zero";
        case ZonalMapping::kSymmetric: return "symmetric";
    }
    return "affine";
}

std::vector<std::uint8_t> float_bytes(const std::vector<std::array<float, 3>>& v) {
    std::vector<std::uint8_t> out(v.size() * 12);
    for (size_t i = 0; i < v.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            std::uint32_t bits;
            std::memcpy(&bits, &v[i][static_cast<size_t>(k)], 4);
            for (int b = 0; b < 4; ++b) out[i * 12 + static_cast<size_t>(k) * 4 + static_cast<size_t>(b)] = static_cast<std::uint8_t>(bits >> (8 * b));
        }
    return out;
}


// The MIME type of an image to embed: its mimeType, else from its first bytes.
std::string image_mime(const json& image, const std::vector<std::uint8_t>& b) {
    if (image.contains("mimeType") && image["mimeType"].is_string()) return image["mimeType"].get<std::string>();
    auto starts = [&](std::initializer_list<int> m, size_t at = 0) {
        if (b.size() < at + m.size()) return false;
        size_t i = at;
        for (int c : m)
            if (b[i++] != c) return false;
        return true;
    };
    if (starts({0x89, 'P', 'N', 'G'})) return "image/png";
    if (starts({0xFF, 0xD8, 0xFF})) return "image/jpeg";
    if (starts({'R', 'I', 'F', 'F'}) && starts({'W', 'E', 'B', 'P'}, 8)) return "image/webp";
    if (starts({0xAB, 'K', 'T', 'X', ' ', '2', '0'})) return "image/ktx2";
    return "";
}

// A relative URI for `rel` (a relative path): '/'-separated, percent-encoding all but RFC 3986
// unreserved characters.
std::string path_uri(const fs::path& rel) {
    static const char* hex = "0123456789ABCDEF";
    std::string out;
    for (const char c : rel.generic_string()) {
        const auto u = static_cast<unsigned char>(c);
        if (std::isalnum(u) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
            out.push_back(c);
        } else {
            out.push_back('%');
            out.push_back(hex[u >> 4]);
            out.push_back(hex[u & 15]);
        }
    }
    return out;
}

// Images referenced by relative URIs, made to resolve from the output (GltfEmbedOptions::output_path).
template <class AppendView>
Status relocate_images(json& doc, const std::string& scene_path, const GltfEmbedOptions& options, const GltfLimits& limits,
                       AppendView&& append_view) {
    if (!doc.contains("images") || !doc["images"].is_array()) return Ok{};
    std::error_code ec;
    fs::path in_dir = fs::path(scene_path).parent_path();
    const fs::path in_dir_as_named = in_dir;
    if (in_dir.empty()) in_dir = ".";
    fs::path out_dir = fs::absolute(fs::path(options.output_path), ec).parent_path();
    const fs::path in_base = fs::weakly_canonical(in_dir, ec);
    if (ec) return fail(ErrorCode::kIoError, scene_path, "cannot resolve the input's directory");
    const fs::path out_base = fs::weakly_canonical(out_dir, ec);
    if (ec) return fail(ErrorCode::kIoError, options.output_path, "cannot resolve the output's directory");
    if (in_base == out_base) return Ok{};
    std::uint64_t total = 0;
    for (size_t i = 0; i < doc["images"].size(); ++i) {
        json& image = doc["images"][i];
        if (!image.is_object() || !image.contains("uri") || !image["uri"].is_string()) continue;
        const std::string uri = image["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) continue;
        const std::string where = "images[" + std::to_string(i) + "].uri";
        if (const std::string why = uri_problem(uri); !why.empty())
            return fail(ErrorCode::kBadFormat, scene_path, "image '" + uri + "' cannot be carried to the output's folder: " + why + " (" + where + ")");
        const fs::path file = fs::weakly_canonical(in_base / uri_path(uri), ec);
        if (ec || !inside(in_base, file)) return fail(ErrorCode::kBadFormat, scene_path, "image '" + uri + "' resolves outside the input's directory (" + where + ")");
        if (!fs::is_regular_file(file, ec))
            return fail(ErrorCode::kIoError, scene_path, "referenced file '" + uri_path(uri) + "' not found in " + in_base.string() + " (" + where + ")");
        if (inside(out_base, file)) {  // reachable from the output's folder without '..'
            image["uri"] = path_uri(file.lexically_relative(out_base));
            continue;
        }
        auto bytes = read_file_bytes(user_spelling(in_dir_as_named, in_base, file).string(), limits.max_buffer_bytes);
        if (!bytes) return bytes.error();
        total += bytes->size();
        if (total > limits.max_total_bytes) return fail(ErrorCode::kTooLarge, scene_path, "images to embed exceed the limit of " + std::to_string(limits.max_total_bytes) + " bytes");
        const std::string mime = image_mime(image, *bytes);
        if (mime.empty()) return fail(ErrorCode::kUnsupported, scene_path, "image '" + uri + "' has no mimeType and is not PNG, JPEG, WebP or KTX2: cannot embed it (" + where + ")");
        image.erase("uri");
        if (options.binary) {
            image["bufferView"] = append_view(*bytes, "image " + std::to_string(i));
            image["mimeType"] = mime;
        } else {
            image["uri"] = "data:" + mime + ";base64," + base64(*bytes);
        }
    }
    return Ok{};
}

// Every field of the input the embedding reads, appends to or extends has the type glTF gives it
// (checked before anything is changed, like the readers check theirs): an object where an array
// belongs is refused naming it (kBadFormat), never replaced nor appended to.
Status check_embed_fields(const json& doc, const std::string& path) {
    auto bad = [&](const std::string& where, const char* want, const json& got) {
        return fail(ErrorCode::kBadFormat, path, where + ": must be " + want + " (got " + got.type_name() + ")");
    };
    for (const char* key : {"bufferViews", "accessors", "nodes", "scenes", "images", "extensionsUsed"})
        if (doc.contains(key) && !doc[key].is_array()) return bad(key, "an array", doc[key]);
    if (doc.contains("scenes"))
        for (size_t i = 0; i < doc["scenes"].size(); ++i) {
            const std::string sp = "scenes[" + std::to_string(i) + "]";
            const json& sc = doc["scenes"][i];
            if (!sc.is_object()) return bad(sp, "an object", sc);
            if (sc.contains("nodes") && !sc["nodes"].is_array()) return bad(sp + ".nodes", "an array", sc["nodes"]);
        }
    if (doc.contains("images"))
        for (size_t i = 0; i < doc["images"].size(); ++i)
            if (!doc["images"][i].is_object()) return bad("images[" + std::to_string(i) + "]", "an object", doc["images"][i]);
    if (doc.contains("extensions")) {
        const json& e = doc["extensions"];
        if (!e.is_object()) return bad("extensions", "an object", e);
        if (e.contains(kGltfProbeExtension)) {
            const std::string ep = std::string("extensions.") + kGltfProbeExtension;
            const json& z = e[kGltfProbeExtension];
            if (!z.is_object()) return bad(ep, "an object", z);
            if (z.contains("volumes") && !z["volumes"].is_array()) return bad(ep + ".volumes", "an array", z["volumes"]);
        }
    }
    return Ok{};
}

}  // namespace

Result<std::vector<std::uint8_t>> embed_probes_gltf(std::span<const std::uint8_t> scene_bytes, const std::string& scene_path,
                                                    const ProbeSet& input_set, const GltfEmbedOptions& options,
                                                    const GltfLimits& limits) {
    auto valid = validate_probe_set(input_set);
    if (!valid) return valid.error();
    if (options.draco && (input_set.layout.kind != ProbeLayoutKind::kPositions || !is_float_vec3_encoding(input_set.representation)))
        return make_error(ErrorCode::kInvalidArgument, "--draco needs a probe set with explicit positions in a float encoding (sh3, sh2)");
    auto loaded = load(scene_bytes, scene_path, limits);
    if (!loaded) return loaded.error();
    if (Status fields = check_embed_fields(loaded->doc, scene_path); !fields) return fields.error();
    // A volume of the same name already in the asset: refused, or replaced in place (options.replace).
    std::optional<std::size_t> replaced;
    if (loaded->doc.contains("extensions") && loaded->doc["extensions"].contains(kGltfProbeExtension) &&
        loaded->doc["extensions"][kGltfProbeExtension].contains("volumes")) {
        const json& volumes = loaded->doc["extensions"][kGltfProbeExtension]["volumes"];  // checked: an array
        for (std::size_t i = 0; i < volumes.size() && !replaced; ++i)
            if (volumes[i].is_object() && volumes[i].contains("name") && volumes[i]["name"] == options.name) replaced = i;
        if (replaced && !options.replace)
            return make_error(ErrorCode::kInvalidArgument, scene_path + ": already has a " + kGltfProbeExtension + " volume named '" +
                                                               options.name + "' (extensions." + kGltfProbeExtension + ".volumes[" +
                                                               std::to_string(*replaced) + "]): refusing to add a second one of that name "
                                                               "(zhc gltf embed --replace replaces it, --name NAME adds a volume of another name)");
    }
    // The output is the input's own JSON (order and values kept by ordered_json) with our
    // additions; tinygltf's model only supplies the bytes of each buffer.
    json doc = loaded->doc;
    const tinygltf::Model& m = loaded->model;
    const Codec* codec = input_set.codec();
    const std::size_t size = codec->size_bytes;

    // The set as stored: SH axes, then glTF probe order and positions.
    ProbeSet set = input_set;
    if (options.sh_axes == GltfShAxes::kGltf) {
        auto rotated = rotate_set(set, zhc_to_gltf_rotation());
        if (!rotated) return rotated.error();
        set = std::move(rotated).value();
    }
    json vol = json::object();
    vol["name"] = options.name;
    vol["encoding"] = std::string(codec->name);  // the entry's own name, never an alias
    vol["kind"] = set.params.kind == StoredKind::kIrradiance ? "irradiance" : "radiance";
    vol["count"] = set.count;
    vol["shAxes"] = options.sh_axes == GltfShAxes::kZhc ? "zhc" : "gltf";
    PackedLayout packed;
    if (packed_layout_from_name(set.representation, &packed)) {
        const CodecOptions& p = set.params;
        vol["quantization"] = {{"bits", p.bits},
                               {"sqrt", p.sqrt_encoding},
                               {"l2Bound", p.l2_bound == L2Bound::kTight ? "tight" : "loose"},
                               {"dcFormat", dc_name(p.dc_format)},
                               {"zonalMapping", zonal_name(p.zonal_mapping)},
                               {"axisMode", p.axis_mode == ZonalAxisMode::kLuminance ? "luminance" : "channel"}};
    }
    const LuminanceWeights defaults;
    const LuminanceWeights& w = set.params.luminance;
    if (w.r != defaults.r || w.g != defaults.g || w.b != defaults.b) vol["luminanceWeights"] = {w.r, w.g, w.b};

    std::vector<std::uint8_t> payload = set.payload;
    std::vector<std::array<float, 3>> positions;
    switch (set.layout.kind) {
        case ProbeLayoutKind::kGrid: {
            const ProbeGrid& g = set.layout.grid;
            const Vec3 o = to_gltf(g.origin), sp = to_gltf(g.spacing);
            vol["layout"] = "grid";
            vol["grid"] = {{"origin", {o.x, o.y, o.z}},
                           {"spacing", {sp.x, sp.y, sp.z}},
                           {"counts", {g.counts[1], g.counts[2], g.counts[0]}}};
            payload = reorder_grid(payload, size, g.counts, /*to_gltf_order=*/true);
            break;
        }
        case ProbeLayoutKind::kPositions:
            vol["layout"] = "points";
            positions.reserve(set.layout.positions.size());
            for (const auto& p : set.layout.positions) positions.push_back(to_gltf(p));
            break;
        case ProbeLayoutKind::kNone: vol["layout"] = "none"; break;
    }

    // Buffers: GLB output keeps buffer 0 as the BIN chunk (its bytes stay a prefix) and appends
    // there; .gltf output appends a new buffer. Every other buffer keeps its bytes; buffers that
    // lived in a GLB chunk or an external file become data URIs so the output is self-contained.
    if (!doc.contains("buffers")) doc["buffers"] = json::array();
    if (!doc.contains("bufferViews")) doc["bufferViews"] = json::array();
    if (!doc.contains("accessors")) doc["accessors"] = json::array();
    json& buffers = doc["buffers"];
    if (m.buffers.size() != buffers.size()) return fail(ErrorCode::kBadFormat, scene_path, "buffers could not all be loaded");
    std::vector<std::uint8_t> target;  // the buffer we append to
    std::size_t target_index = 0;
    if (options.binary) {
        if (buffers.empty()) buffers.push_back(json::object());
        else target.assign(m.buffers[0].data.begin(), m.buffers[0].data.end());
        target_index = 0;
    } else {
        target_index = buffers.size();
        buffers.push_back(json{{"name", options.name}});
    }
    const auto& placeholders = loaded->placeholder_buffers;
    if (options.binary && !placeholders.empty() && placeholders[0] == 0)
        return fail(ErrorCode::kUnsupported, scene_path, "buffer 0 is a meshopt placeholder buffer without bytes: embed into a .gltf output (buffers[0])");
    for (std::size_t i = 0; i < m.buffers.size(); ++i) {
        if (options.binary && i == 0) continue;
        if (std::find(placeholders.begin(), placeholders.end(), i) != placeholders.end()) continue;  // stays uri-less
        json& b = buffers[i];
        const bool data = b.contains("uri") && b["uri"].get<std::string>().rfind("data:", 0) == 0;
        if (!data) b["uri"] = data_uri(m.buffers[i].data);
    }
    auto append_view = [&](const std::vector<std::uint8_t>& bytes, const std::string& name) {
        while (target.size() % 8 != 0) target.push_back(0);
        doc["bufferViews"].push_back(json{{"buffer", target_index}, {"byteOffset", target.size()}, {"byteLength", bytes.size()}, {"name", name}});
        target.insert(target.end(), bytes.begin(), bytes.end());
        return doc["bufferViews"].size() - 1;
    };
    auto add_accessor = [&](std::size_t view, int component, const char* type, std::size_t count, const std::string& name) {
        doc["accessors"].push_back(json{{"bufferView", view}, {"componentType", component}, {"count", count}, {"type", type}, {"name", name}});
        return doc["accessors"].size() - 1;
    };
    if (options.draco) {
        auto encoded = encode_probe_point_cloud(positions, payload, set.representation, options.draco_bits);
        if (!encoded) return encoded.error();
        const std::size_t view = append_view(encoded->bytes, options.name + " draco");
        json attrs = json::object();
        for (const auto& [k, v] : encoded->attributes) attrs[k] = v;
        vol["draco"] = {{"bufferView", view}, {"quantizationBits", options.draco_bits}, {"attributes", attrs}};
    } else {
        if (set.layout.kind == ProbeLayoutKind::kPositions) {
            const std::size_t view = append_view(float_bytes(positions), options.name + " positions");
            const std::size_t acc = add_accessor(view, kFloat, "VEC3", positions.size(), options.name + " positions");
            std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
            for (const auto& p : positions)
                for (size_t k = 0; k < 3; ++k) {
                    lo[k] = std::min(lo[k], p[k]);
                    hi[k] = std::max(hi[k], p[k]);
                }
            doc["accessors"][acc]["min"] = lo;
            doc["accessors"][acc]["max"] = hi;
            vol["positions"] = acc;
        }
        const std::size_t view = append_view(payload, options.name + " coefficients");
        vol["coefficients"] = is_float_vec3_encoding(set.representation)
                                  ? add_accessor(view, kFloat, "VEC3", set.count * (size / 12), options.name + " coefficients")
                                  : add_accessor(view, kUbyte, "SCALAR", set.count * size, options.name + " coefficients");
    }
    // Leak-avoidance data in the volume's probe order: one UNSIGNED_BYTE per probe (validity,
    // visibility masks in the glTF grid's axes) and the cell planes (docs/gltf-extension.md "Cell planes").
    if (!set.validity.empty()) {
        std::vector<std::uint8_t> bytes = set.validity;
        if (set.layout.kind == ProbeLayoutKind::kGrid) bytes = reorder_grid(bytes, 1, set.layout.grid.counts, /*to_gltf_order=*/true);
        vol["validity"] = add_accessor(append_view(bytes, options.name + " validity"), kUbyte, "SCALAR", set.count,
                                       options.name + " validity");
    }
    if (!set.visibility.empty()) {  // grid only (validate_probe_set)
        std::vector<std::uint8_t> bytes = reorder_grid(set.visibility, 1, set.layout.grid.counts, /*to_gltf_order=*/true);
        for (std::uint8_t& b : bytes) b = visibility_to_gltf(b);
        vol["visibility"] = add_accessor(append_view(bytes, options.name + " visibility"), kUbyte, "SCALAR", set.count,
                                         options.name + " visibility");
    }
    if (!set.planes.empty()) {  // grid only (validate_probe_set): the 5-byte entries split in two accessors
        const std::vector<std::uint8_t> entries = reorder_grid(set.planes, 5, set.layout.grid.counts, /*to_gltf_order=*/true);
        std::vector<std::uint8_t> planes(4 * set.count), sides(set.count);
        for (std::size_t i = 0; i < set.count; ++i) {
            std::uint8_t e[5];
            std::memcpy(e, entries.data() + 5 * i, 5);
            if (cell_entry_kind(e) == CellEntryKind::kRegion) {
                region_entry_axes(e, /*to_gltf=*/true);  // a corner region: its per-axis fields in glTF axes
            } else {
                e[4] = visibility_to_gltf(e[4]);  // a plane's corner bits, permuted like the masks
            }
            std::memcpy(planes.data() + 4 * i, e, 4);  // ou, ov, offset lo, offset hi (a region: its thresholds)
            sides[i] = e[4];
        }
        vol["planes"] = add_accessor(append_view(planes, options.name + " planes"), kUbyte, "VEC4", set.count, options.name + " planes");
        vol["planeSides"] = add_accessor(append_view(sides, options.name + " planeSides"), kUbyte, "SCALAR", set.count,
                                         options.name + " planeSides");
    }
    if (!set.tetrahedra.empty()) {  // positions only (validate_probe_set): docs/gltf-extension.md "Tetrahedra"
        // Probe indices into the volume's probe order, which for points is the set's own order; the
        // axis change (x, y, z)_glTF = (y, z, x)_zhc is a rotation, so every tetrahedron keeps its
        // orientation and the canonical form (formats/probes/tetra.h) holds in glTF axes too. A
        // neighbour of -1 (the hull) is stored as its 32-bit pattern, 4294967295.
        const std::size_t t_count = set.tetrahedra.size();
        std::vector<std::uint8_t> tets(16 * t_count), nbrs(16 * t_count);
        for (std::size_t t = 0; t < t_count; ++t)
            for (std::size_t k = 0; k < 4; ++k) {
                le::store(tets.data() + 16 * t + 4 * k, set.tetrahedra[t][k], 4);
                le::store(nbrs.data() + 16 * t + 4 * k, static_cast<std::uint32_t>(set.tetra_neighbours[t][k]), 4);
            }
        vol["tetrahedra"] = add_accessor(append_view(tets, options.name + " tetrahedra"), kUint, "VEC4", t_count, options.name + " tetrahedra");
        vol["tetraNeighbours"] = add_accessor(append_view(nbrs, options.name + " tetraNeighbours"), kUint, "VEC4", t_count,
                                              options.name + " tetraNeighbours");
    }
    if (!options.output_path.empty()) {
        auto st = relocate_images(doc, scene_path, options, limits, append_view);
        if (!st) return st.error();
    }
    while (target.size() % 4 != 0) target.push_back(0);
    json& tb = buffers[target_index];
    tb["byteLength"] = target.size();
    if (options.binary) tb.erase("uri");
    else tb["uri"] = data_uri(target);

    // The extension object (the volume appended to any existing ones, or replacing the one of its
    // name), extensionsUsed, the node.
    if (!doc.contains("extensions")) doc["extensions"] = json::object();
    json& ext = doc["extensions"][kGltfProbeExtension];  // checked: absent (null) or an object
    if (ext.is_null()) ext = json::object();
    if (!ext.contains("volumes")) ext["volumes"] = json::array();
    const std::size_t volume_index = replaced ? *replaced : ext["volumes"].size();
    if (replaced) ext["volumes"][volume_index] = vol;  // the nodes that referenced the old volume reference this one
    else ext["volumes"].push_back(vol);
    if (!doc.contains("extensionsUsed")) doc["extensionsUsed"] = json::array();
    json& used = doc["extensionsUsed"];
    if (std::find(used.begin(), used.end(), json(kGltfProbeExtension)) == used.end()) used.push_back(kGltfProbeExtension);
    if (options.add_node && !replaced) {
        if (!doc.contains("nodes")) doc["nodes"] = json::array();
        doc["nodes"].push_back(json{{"name", options.name}, {"extensions", {{kGltfProbeExtension, {{"volume", volume_index}}}}}});
        const std::size_t node = doc["nodes"].size() - 1;
        if (doc.contains("scenes"))
            for (json& scene : doc["scenes"]) {  // checked: objects whose nodes, if any, are arrays
                if (!scene.contains("nodes")) scene["nodes"] = json::array();
                scene["nodes"].push_back(node);
            }
    }
    if (options.binary) return make_glb(doc.dump(), target);
    const std::string text = doc.dump(2) + "\n";
    return std::vector<std::uint8_t>(text.begin(), text.end());
}

}  // namespace zhc
