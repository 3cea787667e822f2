// zhc/formats/probes/gltf_probes.cpp — ZHC_light_probes (docs/gltf-extension.md) on top of tinygltf:
// loading an untrusted glTF 2.0 asset (shared by reading and embedding) and the zhc <-> glTF frames.
// Reading the extension: gltf_probes_read.cpp; embedding: gltf_probes_write.cpp; what the three
// share: gltf_probes_internal.h.
//
// tinygltf (Debian libtinygltf-dev, implementation in the shared library) parses and writes the
// asset; everything untrusted is checked by us first (gltf_probes_check.cpp: the GLB framing,
// every buffer URI, declared buffer sizes and data-URI lengths before tinygltf allocates), and
// file reads go through FsCallbacks that refuse paths outside the input's directory. External
// buffers resolve in the input's directory only (a missing one is kIoError naming it; tinygltf's
// extra search of the working directory always finds nothing). Images are never read nor decoded
// here: they are removed from the JSON tinygltf sees, and their URIs are checked only where an
// image is read or embedded (gltf_probes_write.cpp). Uri-less meshopt placeholder buffers load no
// bytes (formats/scene/scene_gltf_geometry.cpp decodes the compressed views). The extension
// itself is read from our own nlohmann parse of the same JSON, so every index it holds is
// bound-checked against the arrays tinygltf loaded.
#include "formats/probes/gltf_probes_internal.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <functional>
#include <deque>
#include <filesystem>
#include <map>

#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"

namespace zhc {
namespace gltf_detail {

using le::put32;

Error fail(ErrorCode code, const std::string& path, const std::string& what) {
    return make_error(code, path + ": " + what);
}

namespace {

// File access for tinygltf: only regular files inside `base`, at most `max_bytes` each.
struct FsGuard {
    fs::path base;      // canonical
    fs::path user_dir;  // the same folder as the caller named it (files are opened by that spelling)
    std::uint64_t max_bytes = 0;
    std::uint64_t read_total = 0;
    std::uint64_t max_total = 0;
    std::string error;
    ErrorCode code = ErrorCode::kBadFormat;
    // External buffer files by canonical path: (buffer index, byteLength) in buffer order, the
    // order tinygltf reads them in.
    std::map<std::string, std::deque<std::pair<size_t, std::uint64_t>>> buffers;
};

}  // namespace

bool inside(const fs::path& base, const fs::path& p) {
    auto b = base.begin(), e = base.end();
    auto q = p.begin();
    for (; b != e; ++b, ++q)
        if (q == p.end() || *q != *b) return false;
    return true;
}

fs::path user_spelling(const fs::path& user_dir, const fs::path& base, const fs::path& file) {
    return user_dir / file.lexically_relative(base);
}

namespace {

bool guard_resolve(FsGuard* g, const std::string& abs, fs::path* out) {
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::path(abs), ec);
    if (ec || !inside(g->base, p)) {
        g->error = "refusing to read '" + abs + "' outside the input's directory";
        return false;
    }
    *out = p;
    return true;
}

// tinygltf looks for a file in the asset's directory and then in the working directory: only
// the first can succeed here (a probe elsewhere is answered "no", it is not an error), so where
// a URI resolves never depends on the working directory.
// A path that lies inside the directory as written but resolves outside it (a symbolic link that
// escapes) is refused with its own message rather than answered "not found".
bool fs_exists(const std::string& abs, void* user) {
    auto* g = static_cast<FsGuard*>(user);
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::path(abs), ec);
    if (ec) return false;
    if (!inside(g->base, p)) {
        if (g->error.empty() && inside(g->base, fs::path(abs).lexically_normal()) && fs::exists(p, ec))
            g->error = "refusing to read '" + abs + "' outside the input's directory";
        return false;
    }
    return fs::is_regular_file(p, ec);
}
std::string fs_expand(const std::string& p, void*) { return p; }
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& abs, void* user) {
    auto* g = static_cast<FsGuard*>(user);
    fs::path p;
    if (!guard_resolve(g, abs, &p)) {
        if (err) *err += g->error + "\n";
        return false;
    }
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(p, ec);
    if (ec) {
        g->code = ErrorCode::kIoError;
        g->error = "cannot read external file '" + abs + "'";
        if (err) *err += g->error + "\n";
        return false;
    }
    // A buffer's file holds at least its byteLength bytes; the first byteLength are the buffer
    // (a longer file is valid glTF, as the Khronos validator has it), a shorter one is refused.
    if (auto it = g->buffers.find(p.string()); it != g->buffers.end() && !it->second.empty()) {
        const auto [index, length] = it->second.front();
        it->second.pop_front();
        if (size < length) {
            g->code = ErrorCode::kTruncated;
            // A Git LFS pointer left where the data belongs gets a hint.
            auto head = read_file_prefix(p.string(), 1024);
            g->error = "buffers[" + std::to_string(index) + "]: file '" + p.filename().string() + "' has " + std::to_string(size) +
                       " bytes, fewer than the buffer's byteLength " + std::to_string(length) +
                       (head ? git_lfs_hint(head->bytes) : std::string());
            if (err) *err += g->error + "\n";
            return false;
        }
        if (g->read_total + length > g->max_total) {
            g->code = ErrorCode::kTooLarge;
            g->error = "buffers[" + std::to_string(index) + "]: external files above the size limit";
            if (err) *err += g->error + "\n";
            return false;
        }
        auto prefix = read_file_prefix(user_spelling(g->user_dir, g->base, p).string(), static_cast<std::size_t>(length));
        if (!prefix || prefix->bytes.size() != length) {
            g->code = prefix ? ErrorCode::kTruncated : prefix.error().code;
            g->error = prefix ? "buffers[" + std::to_string(index) + "]: file '" + p.filename().string() + "' changed while read"
                              : prefix.error().message;
            if (err) *err += g->error + "\n";
            return false;
        }
        g->read_total += length;
        out->assign(prefix->bytes.begin(), prefix->bytes.end());
        return true;
    }
    if (size > g->max_bytes || g->read_total + size > g->max_total) {
        g->code = ErrorCode::kTooLarge;
        g->error = "external file '" + abs + "' (" + std::to_string(size) + " bytes) above the size limit";
        if (err) *err += g->error + "\n";
        return false;
    }
    auto bytes = read_file_bytes(user_spelling(g->user_dir, g->base, p).string(), g->max_bytes);
    if (!bytes) {
        g->code = bytes.error().code;
        g->error = bytes.error().message;
        if (err) *err += g->error + "\n";
        return false;
    }
    g->read_total += bytes->size();
    out->assign(bytes->begin(), bytes->end());
    return true;
}
bool fs_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

// Never decode images: keep the reference (uri / bufferView) only.
bool no_image_decode(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                     void*) {
    return true;
}

// A primitive whose index accessor has no bufferView (a Draco-compressed mesh), with a buffer 0
// for the placeholder to point at.
bool needs_draco_index_patch(const json& doc) {
    if (!doc.contains("meshes") || !doc["meshes"].is_array() || !doc.contains("accessors") || !doc["accessors"].is_array() ||
        !doc.contains("buffers") || !doc["buffers"].is_array() || doc["buffers"].empty())
        return false;
    if (doc.contains("bufferViews") && !doc["bufferViews"].is_array()) return false;
    for (const json& mesh : doc["meshes"]) {
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
        for (const json& prim : mesh["primitives"]) {
            if (!prim.is_object() || !prim.contains("indices") || !prim["indices"].is_number_unsigned()) continue;
            const std::uint64_t a = prim["indices"].get<std::uint64_t>();
            if (a < doc["accessors"].size() && doc["accessors"][a].is_object() && !doc["accessors"][a].contains("bufferView"))
                return true;
        }
    }
    return false;
}

}  // namespace

// GLB 2.0: header, JSON chunk padded with spaces, optional BIN chunk padded with zeros.
std::vector<std::uint8_t> make_glb(const std::string& json_text, std::span<const std::uint8_t> bin) {
    const std::size_t json_len = (json_text.size() + 3) & ~std::size_t(3);
    const std::size_t bin_len = (bin.size() + 3) & ~std::size_t(3);
    std::vector<std::uint8_t> out;
    out.reserve(12 + 8 + json_len + (bin.empty() ? 0 : 8 + bin_len));
    put32(out, kGlbMagic);
    put32(out, 2);
    put32(out, static_cast<std::uint32_t>(12 + 8 + json_len + (bin.empty() ? 0 : 8 + bin_len)));
    put32(out, static_cast<std::uint32_t>(json_len));
    put32(out, kChunkJson);
    out.insert(out.end(), json_text.begin(), json_text.end());
    out.resize(20 + json_len, ' ');
    if (!bin.empty()) {
        put32(out, static_cast<std::uint32_t>(bin_len));
        put32(out, kChunkBin);
        out.insert(out.end(), bin.begin(), bin.end());
        out.resize(out.size() + (bin_len - bin.size()), 0);
    }
    return out;
}

std::string base64(std::span<const std::uint8_t> b) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((b.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < b.size(); i += 3) {
        const std::uint32_t v = std::uint32_t(b[i]) << 16 | (i + 1 < b.size() ? std::uint32_t(b[i + 1]) << 8 : 0) |
                                (i + 2 < b.size() ? std::uint32_t(b[i + 2]) : 0);
        out.push_back(k[(v >> 18) & 63]);
        out.push_back(k[(v >> 12) & 63]);
        out.push_back(i + 1 < b.size() ? k[(v >> 6) & 63] : '=');
        out.push_back(i + 2 < b.size() ? k[v & 63] : '=');
    }
    return out;
}

std::string data_uri(std::span<const std::uint8_t> b) { return "data:application/octet-stream;base64," + base64(b); }

Result<Loaded> load(std::span<const std::uint8_t> bytes, const std::string& path, const GltfLimits& limits) {
    if (bytes.size() > limits.max_file_bytes)
        return fail(ErrorCode::kTooLarge, path, "file above the size limit " + std::to_string(limits.max_file_bytes));
    Loaded out;
    GlbParts glb;
    std::string text;
    out.binary = looks_like_glb(bytes);
    if (out.binary) {
        auto parts = split_glb(bytes, path);
        if (!parts) return parts.error();
        glb = std::move(parts).value();
        text = glb.json_text;
    } else {
        text.assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    }
    if (looks_like_git_lfs_pointer(bytes)) return fail(ErrorCode::kBadFormat, path, "not a glTF asset" + git_lfs_hint(bytes));
    if (Status depth = check_json_depth(text, path); !depth) return depth.error();
    // Where the JSON breaks: line and column (in a GLB they count in its JSON chunk).
    try {
        out.doc = json::parse(text);
    } catch (const json::parse_error& e) {
        const std::string what = e.what();
        const size_t at = what.find("at line ");
        const std::string where = at == std::string::npos ? what : what.substr(at);
        return fail(ErrorCode::kBadFormat, path, std::string("not valid glTF JSON") + (out.binary ? " (GLB JSON chunk) " : " ") + where);
    } catch (const json::exception& e) {  // out_of_range: a number like 1e999
        return fail(ErrorCode::kBadFormat, path, std::string("not valid glTF JSON (") + e.what() + ")");
    }
    auto ok = precheck(out.doc, path, limits, out.binary ? &glb : nullptr);
    if (!ok) return ok.error();
    if (Status req = check_required(out.doc, path); !req) return req.error();

    FsGuard guard;
    std::error_code ec;
    fs::path dir = fs::path(path).parent_path();
    guard.user_dir = dir;
    if (dir.empty()) dir = ".";
    guard.base = fs::weakly_canonical(dir, ec);
    if (ec) return fail(ErrorCode::kIoError, path, "cannot resolve the input's directory");
    guard.max_bytes = limits.max_buffer_bytes;
    guard.max_total = limits.max_total_bytes;
    // External buffers resolve in the asset's directory (never the working directory); a missing
    // one is named here (exit 3), before tinygltf's own search.
    if (out.doc.contains("buffers"))
        for (size_t i = 0; i < out.doc["buffers"].size(); ++i) {
            const json& b = out.doc["buffers"][i];
            if (!b.contains("uri") || b["uri"].get<std::string>().rfind("data:", 0) == 0) continue;
            const std::string rel = uri_path(b["uri"].get<std::string>());
            std::error_code fe;
            if (!fs::is_regular_file(guard.base / rel, fe))
                return fail(ErrorCode::kIoError, path,
                            "referenced file '" + rel + "' not found in " + guard.base.string() + " (buffers[" + std::to_string(i) + "].uri)");
            const fs::path file = fs::weakly_canonical(guard.base / rel, fe);
            if (!fe) guard.buffers[file.string()].push_back({i, b["byteLength"].get<std::uint64_t>()});
        }

    // tinygltf 2.7 refuses primitives whose index accessor has no bufferView, which is exactly
    // how KHR_draco_mesh_compression meshes are written (the data is in the Draco stream). Give
    // such accessors a placeholder bufferView (appended last, so no index of the asset moves)
    // for tinygltf's eyes only; the model is used for buffer bytes, never written back.
    // Two more changes for tinygltf's eyes only: images are dropped (never decoded nor needed;
    // a data: URI of any MIME type is data, not a path), and a uri-less meshopt placeholder
    // buffer gets a 4-byte stand-in (its bytes are never read: every view of it is decoded from
    // the compressed buffer, formats/scene/scene_gltf_geometry.cpp).
    std::vector<std::uint8_t> patched_glb;
    std::string patched_text;
    std::vector<size_t> placeholder_buffers;
    if (out.doc.contains("buffers")) {
        const std::vector<bool> placeholder = meshopt_placeholders(out.doc);
        for (size_t i = 0; i < out.doc["buffers"].size(); ++i)
            if (!out.doc["buffers"][i].contains("uri") && placeholder[i] && !(i == 0 && out.binary && glb.has_bin))
                placeholder_buffers.push_back(i);
    }
    // A base64 data: URI holding more bytes than its buffer's byteLength is valid glTF (as a
    // longer .bin file is): tinygltf is shown the decoded length and the buffer is cut back to
    // byteLength after loading. One holding fewer is refused here, naming the buffer.
    std::vector<std::pair<size_t, std::uint64_t>> long_data_uris;  // (buffer, declared byteLength)
    if (out.doc.contains("buffers"))
        for (size_t i = 0; i < out.doc["buffers"].size(); ++i) {
            const json& b = out.doc["buffers"][i];
            if (!b.contains("uri")) continue;
            const std::string& uri = b["uri"].get_ref<const std::string&>();
            const size_t comma = uri.find(',');
            if (uri.rfind("data:", 0) != 0 || comma == std::string::npos || comma < 12 || uri.compare(comma - 7, 7, ";base64") != 0) continue;
            const std::uint64_t chars = uri.size() - comma - 1;
            if (chars % 4 != 0) continue;  // not base64: tinygltf refuses it
            const std::uint64_t pad = chars == 0 ? 0 : (uri.back() == '=') + (chars >= 2 && uri[uri.size() - 2] == '=');
            const std::uint64_t decoded = chars / 4 * 3 - pad, declared = b["byteLength"].get<std::uint64_t>();
            if (decoded < declared)
                return fail(ErrorCode::kTruncated, path, "buffers[" + std::to_string(i) + "]: the data: URI holds " + std::to_string(decoded) +
                                                             " bytes, fewer than the buffer's byteLength " + std::to_string(declared));
            if (decoded > declared) long_data_uris.push_back({i, declared});
        }
    const bool draco_patch = needs_draco_index_patch(out.doc);
    if (draco_patch || out.doc.contains("images") || !placeholder_buffers.empty() || !long_data_uris.empty()) {
        json patched = out.doc;
        patched.erase("images");
        for (size_t i : placeholder_buffers) patched["buffers"][i] = json{{"byteLength", 4}, {"uri", "data:application/octet-stream;base64,AAAAAA=="}};
        for (const auto& [i, declared] : long_data_uris) {
            const std::string& uri = patched["buffers"][i]["uri"].get_ref<const std::string&>();
            const std::uint64_t chars = uri.size() - uri.find(',') - 1;
            patched["buffers"][i]["byteLength"] = chars / 4 * 3 - (uri.back() == '=') - (uri[uri.size() - 2] == '=');
        }
        if (draco_patch) {
            const std::size_t fake = patched["bufferViews"].size();
            patched["bufferViews"].push_back(json{{"buffer", 0}, {"byteLength", 1}});
            // Only well-formed entries are touched (type-checked like needs_draco_index_patch);
            // tinygltf then reports whatever else is malformed.
            for (const json& mesh : patched["meshes"]) {
                if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
                for (const json& prim : mesh["primitives"])
                    if (prim.is_object() && prim.contains("indices") && prim["indices"].is_number_unsigned() &&
                        prim["indices"].get<std::uint64_t>() < patched["accessors"].size()) {
                        json& acc = patched["accessors"][prim["indices"].get<size_t>()];
                        if (acc.is_object() && !acc.contains("bufferView")) acc["bufferView"] = fake;
                    }
            }
        }
        patched_text = patched.dump();
        if (out.binary) {
            const std::span<const std::uint8_t> bin =
                glb.has_bin ? bytes.subspan(glb.bin_offset, glb.bin_bytes)
                            : std::span<const std::uint8_t>();
            patched_glb = make_glb(patched_text, bin);
        } else {
            text = patched_text;
        }
    }
    const std::span<const std::uint8_t> glb_bytes = patched_glb.empty() ? bytes : std::span<const std::uint8_t>(patched_glb);

    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks(tinygltf::FsCallbacks{&fs_exists, &fs_expand, &fs_read, &fs_write, &guard});
    loader.SetImageLoader(&no_image_decode, nullptr);
    loader.SetStoreOriginalJSONForExtrasAndExtensions(false);
    std::string err, warn;
    const std::string base = guard.base.string();
    bool loaded;
    if (out.binary)
        loaded = loader.LoadBinaryFromMemory(&out.model, &err, &warn, glb_bytes.data(), static_cast<unsigned>(glb_bytes.size()), base);
    else
        loaded = loader.LoadASCIIFromString(&out.model, &err, &warn, text.data(), static_cast<unsigned>(text.size()), base);
    if (!guard.error.empty()) return fail(guard.code, path, guard.error);
    if (!loaded) {
        std::string first = err.substr(0, err.find('\n'));
        if (first.empty()) first = "tinygltf could not load the asset";
        return fail(ErrorCode::kBadFormat, path, first);
    }
    for (size_t i : placeholder_buffers)
        if (i < out.model.buffers.size()) out.model.buffers[i].data.clear();
    for (const auto& [i, declared] : long_data_uris)
        if (i < out.model.buffers.size() && out.model.buffers[i].data.size() > declared) out.model.buffers[i].data.resize(static_cast<size_t>(declared));
    out.placeholder_buffers = placeholder_buffers;
    return out;
}

// ---- frames ---------------------------------------------------------------------------------

std::array<float, 3> to_gltf(const std::array<float, 3>& p) { return {p[1], p[2], p[0]}; }
std::array<float, 3> from_gltf(const std::array<float, 3>& p) { return {p[2], p[0], p[1]}; }
Vec3 to_gltf(Vec3 v) { return {v.y, v.z, v.x}; }
Vec3 from_gltf(Vec3 v) { return {v.z, v.x, v.y}; }

// The entry's bytes are float RGB triples (CodecTraits::float_bands): a float VEC3 accessor.
bool is_float_vec3_encoding(const std::string& name) {
    const Codec* c = find_codec(name);
    return c && c->traits.float_bands > 0;
}

// Re-encodes every probe after rotating it by r (decode -> rotate -> encode); validity, visibility
// and cell planes are kept.
Result<ProbeSet> rotate_set(const ProbeSet& set, const Mat3& r) {
    auto hub = decode_probe_set(set);
    if (!hub) return hub.error();
    for (Sh3Radiance& sh : *hub) sh = rotate(sh, r);
    auto out = encode_probe_set(*hub, set.representation, set.params, set.layout);
    if (!out) return out;
    out->validity = set.validity;  // per-probe data, independent of the SH axes
    out->visibility = set.visibility;
    out->planes = set.planes;
    out->tetrahedra = set.tetrahedra;  // probe indices: the positions do not move
    out->tetra_neighbours = set.tetra_neighbours;
    return out;
}

std::uint8_t visibility_to_gltf(std::uint8_t mask) {
    std::uint8_t out = 0;
    for (int b = 0; b < 8; ++b) {
        if (!((mask >> b) & 1)) continue;
        const int cx = b & 1, cy = (b >> 1) & 1, cz = (b >> 2) & 1;  // zhc axes
        out = static_cast<std::uint8_t>(out | (1u << (cy + 2 * cz + 4 * cx)));  // glTF (x, y, z) = zhc (y, z, x)
    }
    return out;
}

// A corner region's per-axis fields (5-bit thresholds in bytes 0-1, direction bits 0-2 of byte 4;
// docs/runtime.md "Corner regions") in the other axis order: to glTF, field a of glTF axis a =
// zhc's field of axis (a + 1) % 3; back, zhc axis a = glTF axis (a + 2) % 3. Reserved bits kept.
void region_entry_axes(std::uint8_t e[5], bool to_gltf) {
    const unsigned r = unsigned(e[0]) | unsigned(e[1]) << 8;
    unsigned q = r & 0x8000u, d = e[4] & ~7u;
    for (unsigned a = 0; a < 3; ++a) {
        const unsigned from = to_gltf ? (a + 1) % 3 : (a + 2) % 3;
        q |= ((r >> (5 * from)) & 31u) << (5 * a);
        d |= ((unsigned(e[4]) >> from) & 1u) << a;
    }
    e[0] = static_cast<std::uint8_t>(q & 0xFFu);
    e[1] = static_cast<std::uint8_t>(q >> 8);
    e[4] = static_cast<std::uint8_t>(d);
}


std::uint8_t visibility_from_gltf(std::uint8_t mask) {
    std::uint8_t out = 0;
    for (int b = 0; b < 8; ++b) {
        if (!((mask >> b) & 1)) continue;
        const int gx = b & 1, gy = (b >> 1) & 1, gz = (b >> 2) & 1;  // glTF axes
        out = static_cast<std::uint8_t>(out | (1u << (gz + 2 * gx + 4 * gy)));  // zhc (x, y, z) = glTF (z, x, y)
    }
    return out;
}

// Grid probe order zhc (i fastest, zhc axes) <-> glTF (glTF x = zhc y fastest).
std::vector<std::uint8_t> reorder_grid(const std::vector<std::uint8_t>& payload, std::size_t size,
                                       const std::array<std::uint32_t, 3>& zc, bool to_gltf_order) {
    std::vector<std::uint8_t> out(payload.size());
    const std::uint64_t nx = zc[0], ny = zc[1], nz = zc[2];
    for (std::uint64_t k = 0; k < nz; ++k)
        for (std::uint64_t j = 0; j < ny; ++j)
            for (std::uint64_t i = 0; i < nx; ++i) {
                const std::uint64_t z_index = i + nx * (j + ny * k);
                const std::uint64_t g_index = j + ny * (k + nz * i);
                const std::uint64_t from = to_gltf_order ? z_index : g_index;
                const std::uint64_t to = to_gltf_order ? g_index : z_index;
                std::memcpy(out.data() + to * size, payload.data() + from * size, size);
            }
    return out;
}

}  // namespace gltf_detail

using namespace gltf_detail;

Mat3 zhc_to_gltf_rotation() {
    Mat3 r;
    r.m = {0, 1, 0,   // x_glTF = y_zhc
           0, 0, 1,   // y_glTF = z_zhc
           1, 0, 0};  // z_glTF = x_zhc
    return r;
}

bool looks_like_glb(std::span<const std::uint8_t> bytes) { return bytes.size() >= 4 && le32(bytes.data()) == kGlbMagic; }

Result<GltfRaw> load_gltf_raw(std::span<const std::uint8_t> bytes, const std::string& path, const GltfLimits& limits) {
    auto loaded = load(bytes, path, limits);
    if (!loaded) return loaded.error();
    GltfRaw raw;
    raw.binary = loaded->binary;
    raw.json = loaded->doc.dump();
    raw.buffers.reserve(loaded->model.buffers.size());
    for (tinygltf::Buffer& b : loaded->model.buffers) raw.buffers.push_back(std::move(b.data));
    return raw;
}

}  // namespace zhc
