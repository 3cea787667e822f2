// zhc/formats/probes/gltf_probes.cpp — ZHC_light_probes (docs/gltf-extension.md) on top of tinygltf.
//
// tinygltf (Debian libtinygltf-dev, implementation in the shared library) parses and writes the
// asset; everything untrusted is checked by us first: the GLB framing, every URI (no absolute
// paths, schemes, `..` or backslashes, also percent-encoded), declared buffer sizes and data-URI
// lengths (before tinygltf allocates), and file reads go through FsCallbacks that refuse paths
// outside the input's directory. External buffers resolve in the input's directory only (a
// missing one is kIoError naming it; tinygltf's extra search of the working directory always
// finds nothing). Images are never read nor decoded: they are removed from the JSON tinygltf
// sees (their URIs are still checked). glTF 2.x only (asset.version / minVersion). Uri-less
// meshopt fallback buffers load no bytes (formats/scene/scene_gltf.cpp decodes the compressed views). The extension itself is read from our own nlohmann parse of the same JSON, so every
// index it holds is bound-checked against the arrays tinygltf loaded.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "formats/probes/gltf_probes.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "formats/io/file_io.h"
#include "formats/io/le_bytes.h"
#include "formats/probes/gltf_draco.h"
#include "formats/io/json_depth.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using le::put32;
constexpr auto le32 = le::load32;

constexpr std::uint32_t kGlbMagic = 0x46546C67;     // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;    // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;     // "BIN\0"
constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
constexpr int kUbyte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;

Error fail(ErrorCode code, const std::string& path, const std::string& what) {
    return make_error(code, path + ": " + what);
}


// ---- untrusted input: framing, URIs, sizes -------------------------------------------------

struct GlbParts {
    std::string json_text;
    bool has_bin = false;
    std::uint64_t bin_offset = 0;
    std::uint64_t bin_bytes = 0;
};

Result<GlbParts> split_glb(std::span<const std::uint8_t> b, const std::string& path) {
    if (b.size() < 20) return fail(ErrorCode::kTruncated, path, "GLB shorter than its 12-byte header and first chunk header");
    if (le32(b.data()) != kGlbMagic) return fail(ErrorCode::kBadFormat, path, "not a GLB (bad magic)");
    if (le32(b.data() + 4) != 2) return fail(ErrorCode::kUnsupported, path, "GLB version " + std::to_string(le32(b.data() + 4)) + " (only 2)");
    const std::uint64_t total = le32(b.data() + 8);
    if (total > b.size()) return fail(ErrorCode::kTruncated, path, "GLB header declares " + std::to_string(total) + " bytes, file has " + std::to_string(b.size()));
    if (total < b.size()) return fail(ErrorCode::kTrailingBytes, path, "bytes after the GLB's declared length " + std::to_string(total));
    const std::uint64_t json_len = le32(b.data() + 12);
    if (le32(b.data() + 16) != kChunkJson) return fail(ErrorCode::kBadFormat, path, "first GLB chunk is not JSON");
    if (20 + json_len > total) return fail(ErrorCode::kTruncated, path, "GLB JSON chunk (" + std::to_string(json_len) + " bytes) runs past the end");
    GlbParts parts;
    parts.json_text.assign(reinterpret_cast<const char*>(b.data() + 20), static_cast<size_t>(json_len));
    std::uint64_t at = 20 + json_len;
    if (at + 8 <= total) {
        const std::uint64_t bin_len = le32(b.data() + at);
        if (le32(b.data() + at + 4) == kChunkBin) {
            if (at + 8 + bin_len > total) return fail(ErrorCode::kTruncated, path, "GLB BIN chunk (" + std::to_string(bin_len) + " bytes) runs past the end");
            parts.has_bin = true;
            parts.bin_offset = at + 8;
            parts.bin_bytes = bin_len;
        }
    } else if (at != total) {
        return fail(ErrorCode::kBadFormat, path, "GLB: partial chunk header after the JSON chunk");
    }
    return parts;
}

// A buffer marked as the fallback of EXT_meshopt_compression / KHR_meshopt_compression.
bool is_meshopt_fallback(const json& buffer) {
    if (!buffer.is_object() || !buffer.contains("extensions") || !buffer["extensions"].is_object()) return false;
    for (const char* name : {"EXT_meshopt_compression", "KHR_meshopt_compression"}) {
        const json& e = buffer["extensions"].contains(name) ? buffer["extensions"][name] : json();
        if (e.is_object() && e.contains("fallback") && e["fallback"].is_boolean() && e["fallback"].get<bool>()) return true;
    }
    return false;
}

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// "" when the URI is an acceptable relative reference inside the input's directory (or a data
// URI), else why not. Percent escapes are decoded first (tinygltf decodes them too).
std::string uri_problem(const std::string& uri) {
    if (uri.rfind("data:", 0) == 0) return "";
    std::string d;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%') {
            if (i + 2 >= uri.size()) return "truncated percent escape";
            const int h = hex_value(uri[i + 1]), l = hex_value(uri[i + 2]);
            if (h < 0 || l < 0) return "bad percent escape";
            d.push_back(static_cast<char>(h * 16 + l));
            i += 2;
        } else {
            d.push_back(uri[i]);
        }
    }
    if (d.empty()) return "empty URI";
    if (d.find('\0') != std::string::npos) return "NUL in URI";
    if (d.find('\\') != std::string::npos) return "backslash in URI";
    if (d.find(':') != std::string::npos) return "absolute URI or scheme (only relative paths and data: URIs)";
    if (d[0] == '/') return "absolute path";
    size_t start = 0;
    while (start <= d.size()) {
        const size_t end = std::min(d.find('/', start), d.size());
        if (d.compare(start, end - start, "..") == 0) return "'..' escapes the input's directory";
        start = end + 1;
    }
    return "";
}

// The path a relative URI names (percent escapes decoded; call after uri_problem accepted it).
std::string uri_path(const std::string& uri) {
    std::string d;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex_value(uri[i + 1]) >= 0 && hex_value(uri[i + 2]) >= 0) {
            d.push_back(static_cast<char>(hex_value(uri[i + 1]) * 16 + hex_value(uri[i + 2])));
            i += 2;
        } else {
            d.push_back(uri[i]);
        }
    }
    return d;
}

Result<std::uint64_t> json_size(const json& j, const char* key, const std::string& path, const std::string& where) {
    if (!j.contains(key)) return fail(ErrorCode::kBadFormat, path, where + ": missing " + key);
    const json& v = j[key];
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0))
        return fail(ErrorCode::kBadFormat, path, where + ": " + key + " is not a non-negative integer");
    return v.get<std::uint64_t>();
}

// glTF 2.x only (asset.version "2.<minor>"; asset.minVersion, when given, at most "2.0").
Status check_version(const json& asset, const std::string& path) {
    auto parse = [](const json& v, int* major, int* minor) {
        if (!v.is_string()) return false;
        const std::string s = v.get<std::string>();
        const size_t dot = s.find('.');
        if (dot == std::string::npos || dot == 0 || dot + 1 == s.size() || dot > 4 || s.size() - dot - 1 > 4) return false;
        for (size_t i = 0; i < s.size(); ++i)
            if (i != dot && (s[i] < '0' || s[i] > '9')) return false;
        *major = std::stoi(s.substr(0, dot));
        *minor = std::stoi(s.substr(dot + 1));
        return true;
    };
    int major = 0, minor = 0;
    if (!asset.contains("version")) return fail(ErrorCode::kBadFormat, path, "asset.version missing (asset.version)");
    if (!parse(asset["version"], &major, &minor))
        return fail(ErrorCode::kBadFormat, path, "asset.version is not \"<major>.<minor>\" (asset.version)");
    if (major != 2)
        return fail(ErrorCode::kUnsupported, path, "glTF version " + asset["version"].get<std::string>() + " (zhc reads glTF 2.x) (asset.version)");
    if (asset.contains("minVersion")) {
        int min_major = 0, min_minor = 0;
        if (!parse(asset["minVersion"], &min_major, &min_minor))
            return fail(ErrorCode::kBadFormat, path, "asset.minVersion is not \"<major>.<minor>\" (asset.minVersion)");
        if (min_major != 2 || min_minor > 0)
            return fail(ErrorCode::kUnsupported, path, "the asset needs a glTF " + asset["minVersion"].get<std::string>() +
                                                           " reader (zhc reads 2.0) (asset.minVersion)");
    }
    return Ok{};
}

// Checks every declared size and URI before tinygltf allocates anything.
Status precheck(const json& doc, const std::string& path, const GltfLimits& limits, const GlbParts* glb) {
    if (!doc.is_object()) return fail(ErrorCode::kBadFormat, path, "glTF JSON is not an object");
    if (!doc.contains("asset") || !doc["asset"].is_object())
        return fail(ErrorCode::kBadFormat, path, "not a glTF asset (no \"asset\" object)");
    if (Status v = check_version(doc["asset"], path); !v) return v;
    std::uint64_t total = 0;
    if (doc.contains("buffers")) {
        const json& bufs = doc["buffers"];
        if (!bufs.is_array()) return fail(ErrorCode::kBadFormat, path, "\"buffers\" is not an array");
        for (size_t i = 0; i < bufs.size(); ++i) {
            const std::string where = "buffers[" + std::to_string(i) + "]";
            if (!bufs[i].is_object()) return fail(ErrorCode::kBadFormat, path, where + " is not an object");
            auto len = json_size(bufs[i], "byteLength", path, where);
            if (!len) return len.error();
            if (*len > limits.max_buffer_bytes)
                return fail(ErrorCode::kTooLarge, path, where + ": byteLength " + std::to_string(*len) + " above the limit " + std::to_string(limits.max_buffer_bytes));
            total += *len;
            if (total > limits.max_total_bytes)
                return fail(ErrorCode::kTooLarge, path, "buffers total above the limit " + std::to_string(limits.max_total_bytes));
            if (bufs[i].contains("uri")) {
                if (!bufs[i]["uri"].is_string()) return fail(ErrorCode::kBadFormat, path, where + ": uri is not a string");
                const std::string uri = bufs[i]["uri"].get<std::string>();
                const std::string why = uri_problem(uri);
                if (!why.empty()) return fail(ErrorCode::kBadFormat, path, where + ": uri rejected: " + why);
                if (uri.rfind("data:", 0) == 0 && uri.size() > limits.max_buffer_bytes / 3 * 4 + 256)
                    return fail(ErrorCode::kTooLarge, path, where + ": data URI above the size limit");
            } else if (is_meshopt_fallback(bufs[i]) && !(i == 0 && glb && glb->has_bin)) {
                // EXT/KHR_meshopt_compression: a fallback buffer needs no bytes (every view of it
                // is decoded from a compressed buffer); nothing is loaded for it.
            } else if (i == 0 && glb) {
                if (!glb->has_bin) return fail(ErrorCode::kBadFormat, path, where + ": no uri and the GLB has no BIN chunk");
                if (*len > glb->bin_bytes) return fail(ErrorCode::kTruncated, path, where + ": byteLength " + std::to_string(*len) + " larger than the BIN chunk (" + std::to_string(glb->bin_bytes) + ")");
            } else {
                return fail(ErrorCode::kBadFormat, path, where + ": no uri");
            }
        }
    }
    if (doc.contains("images")) {
        const json& imgs = doc["images"];
        if (!imgs.is_array()) return fail(ErrorCode::kBadFormat, path, "\"images\" is not an array");
        for (size_t i = 0; i < imgs.size(); ++i) {
            if (!imgs[i].is_object() || !imgs[i].contains("uri")) continue;
            const std::string where = "images[" + std::to_string(i) + "]";
            if (!imgs[i]["uri"].is_string()) return fail(ErrorCode::kBadFormat, path, where + ": uri is not a string");
            const std::string why = uri_problem(imgs[i]["uri"].get<std::string>());
            if (!why.empty()) return fail(ErrorCode::kBadFormat, path, where + ": uri rejected: " + why);
        }
    }
    return Ok{};
}

// File access for tinygltf: only regular files inside `base`, at most `max_bytes` each.
struct FsGuard {
    fs::path base;  // canonical
    std::uint64_t max_bytes = 0;
    std::uint64_t read_total = 0;
    std::uint64_t max_total = 0;
    std::string error;
    ErrorCode code = ErrorCode::kBadFormat;
};

bool inside(const fs::path& base, const fs::path& p) {
    auto b = base.begin(), e = base.end();
    auto q = p.begin();
    for (; b != e; ++b, ++q)
        if (q == p.end() || *q != *b) return false;
    return true;
}

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
bool fs_exists(const std::string& abs, void* user) {
    auto* g = static_cast<FsGuard*>(user);
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::path(abs), ec);
    if (ec || !inside(g->base, p)) return false;
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
    if (size > g->max_bytes || g->read_total + size > g->max_total) {
        g->code = ErrorCode::kTooLarge;
        g->error = "external file '" + abs + "' (" + std::to_string(size) + " bytes) above the size limit";
        if (err) *err += g->error + "\n";
        return false;
    }
    auto bytes = read_file_bytes(p.string(), g->max_bytes);
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

struct Loaded {
    json doc;
    tinygltf::Model model;
    bool binary = false;
    std::vector<size_t> fallback_buffers;  // uri-less meshopt fallback buffers (no bytes loaded)
};

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
    if (Status depth = check_json_depth(text, path); !depth) return depth.error();
    out.doc = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (out.doc.is_discarded()) return fail(ErrorCode::kBadFormat, path, "glTF JSON does not parse");
    auto ok = precheck(out.doc, path, limits, out.binary ? &glb : nullptr);
    if (!ok) return ok.error();

    FsGuard guard;
    std::error_code ec;
    fs::path dir = fs::path(path).parent_path();
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
        }

    // tinygltf 2.7 refuses primitives whose index accessor has no bufferView, which is exactly
    // how KHR_draco_mesh_compression meshes are written (the data is in the Draco stream). Give
    // such accessors a placeholder bufferView (appended last, so no index of the asset moves)
    // for tinygltf's eyes only; the model is used for buffer bytes, never written back.
    // Two more changes for tinygltf's eyes only: images are dropped (never decoded nor needed;
    // their URIs were checked above, and a data: URI of any MIME type is data, not a path), and a
    // uri-less meshopt fallback buffer gets a 4-byte stand-in (its bytes are never read: every
    // view of it is decoded from the compressed buffer, formats/scene/scene_gltf.cpp).
    std::vector<std::uint8_t> patched_glb;
    std::string patched_text;
    std::vector<size_t> fallback_buffers;
    if (out.doc.contains("buffers"))
        for (size_t i = 0; i < out.doc["buffers"].size(); ++i)
            if (!out.doc["buffers"][i].contains("uri") && is_meshopt_fallback(out.doc["buffers"][i]) && !(i == 0 && out.binary && glb.has_bin))
                fallback_buffers.push_back(i);
    const bool draco_patch = needs_draco_index_patch(out.doc);
    if (draco_patch || out.doc.contains("images") || !fallback_buffers.empty()) {
        json patched = out.doc;
        patched.erase("images");
        for (size_t i : fallback_buffers) patched["buffers"][i] = json{{"byteLength", 4}, {"uri", "data:application/octet-stream;base64,AAAAAA=="}};
        if (draco_patch) {
            const std::size_t fake = patched["bufferViews"].size();
            patched["bufferViews"].push_back(json{{"buffer", 0}, {"byteLength", 1}});
            for (const json& mesh : patched["meshes"])
                for (const json& prim : mesh.value("primitives", json::array()))
                    if (prim.is_object() && prim.contains("indices") && prim["indices"].is_number_unsigned()) {
                        json& acc = patched["accessors"][prim["indices"].get<size_t>()];
                        if (acc.is_object() && !acc.contains("bufferView")) acc["bufferView"] = fake;
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
    for (size_t i : fallback_buffers)
        if (i < out.model.buffers.size()) out.model.buffers[i].data.clear();
    out.fallback_buffers = fallback_buffers;
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

// Re-encodes every probe after rotating it by r (decode -> rotate -> encode).
Result<ProbeSet> rotate_set(const ProbeSet& set, const Mat3& r) {
    auto hub = decode_probe_set(set);
    if (!hub) return hub.error();
    for (Sh3Radiance& sh : *hub) sh = rotate(sh, r);
    return encode_probe_set(*hub, set.representation, set.params, set.layout);
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

    Result<GltfProbeVolume> read(const json& v) const {
        if (!v.is_object()) return bad(ErrorCode::kBadFormat, "not an object");
        GltfProbeVolume out;
        if (v.contains("name") && v["name"].is_string()) out.name = v["name"].get<std::string>();
        if (!v.contains("encoding") || !v["encoding"].is_string()) return bad(ErrorCode::kBadFormat, "missing encoding");
        ProbeSet& set = out.set;
        set.representation = v["encoding"].get<std::string>();
        const Codec* codec = set.codec();
        if (!codec) return bad(ErrorCode::kUnsupported, "unknown encoding '" + set.representation + "'");
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

Mat3 zhc_to_gltf_rotation() {
    Mat3 r;
    r.m = {0, 1, 0,   // x_glTF = y_zhc
           0, 0, 1,   // y_glTF = z_zhc
           1, 0, 0};  // z_glTF = x_zhc
    return r;
}

bool looks_like_glb(std::span<const std::uint8_t> bytes) { return bytes.size() >= 4 && le32(bytes.data()) == kGlbMagic; }

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

Result<GltfSummary> read_gltf_probes_file(const std::string& path, const GltfLimits& limits) {
    auto bytes = read_file_bytes(path, limits.max_file_bytes);
    if (!bytes) return bytes.error();
    return read_gltf_probes(*bytes, path, limits);
}

namespace {

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
        const fs::path file = fs::weakly_canonical(in_base / uri_path(uri), ec);
        if (ec || !inside(in_base, file)) return fail(ErrorCode::kBadFormat, scene_path, "image '" + uri + "' resolves outside the input's directory (" + where + ")");
        if (!fs::is_regular_file(file, ec))
            return fail(ErrorCode::kIoError, scene_path, "referenced file '" + uri_path(uri) + "' not found in " + in_base.string() + " (" + where + ")");
        if (inside(out_base, file)) {  // reachable from the output's folder without '..'
            image["uri"] = path_uri(file.lexically_relative(out_base));
            continue;
        }
        auto bytes = read_file_bytes(file.string(), limits.max_buffer_bytes);
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
    vol["encoding"] = set.representation;
    vol["kind"] = set.params.kind == StoredKind::kIrradiance ? "irradiance" : "radiance";
    vol["count"] = set.count;
    vol["shAxes"] = options.sh_axes == GltfShAxes::kZhc ? "zhc" : "gltf";
    PackedLayout packed;
    if (packed_layout_from_name(set.representation, &packed)) {
        const StorageParams& p = set.params;
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
    const auto& fallback = loaded->fallback_buffers;
    if (options.binary && !fallback.empty() && fallback[0] == 0)
        return fail(ErrorCode::kUnsupported, scene_path, "buffer 0 is a meshopt fallback buffer without bytes: embed into a .gltf output (buffers[0])");
    for (std::size_t i = 0; i < m.buffers.size(); ++i) {
        if (options.binary && i == 0) continue;
        if (std::find(fallback.begin(), fallback.end(), i) != fallback.end()) continue;  // stays uri-less
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
    if (!options.output_path.empty()) {
        auto st = relocate_images(doc, scene_path, options, limits, append_view);
        if (!st) return st.error();
    }
    while (target.size() % 4 != 0) target.push_back(0);
    json& tb = buffers[target_index];
    tb["byteLength"] = target.size();
    if (options.binary) tb.erase("uri");
    else tb["uri"] = data_uri(target);

    // The extension object (volumes appended to any existing ones), extensionsUsed, the node.
    if (!doc.contains("extensions") || !doc["extensions"].is_object()) doc["extensions"] = json::object();
    json& ext = doc["extensions"][kGltfProbeExtension];
    if (!ext.is_object()) ext = json::object();
    if (!ext.contains("volumes") || !ext["volumes"].is_array()) ext["volumes"] = json::array();
    const std::size_t volume_index = ext["volumes"].size();
    ext["volumes"].push_back(vol);
    if (!doc.contains("extensionsUsed") || !doc["extensionsUsed"].is_array()) doc["extensionsUsed"] = json::array();
    json& used = doc["extensionsUsed"];
    if (std::find(used.begin(), used.end(), json(kGltfProbeExtension)) == used.end()) used.push_back(kGltfProbeExtension);
    if (options.add_node) {
        if (!doc.contains("nodes") || !doc["nodes"].is_array()) doc["nodes"] = json::array();
        doc["nodes"].push_back(json{{"name", options.name}, {"extensions", {{kGltfProbeExtension, {{"volume", volume_index}}}}}});
        const std::size_t node = doc["nodes"].size() - 1;
        if (doc.contains("scenes") && doc["scenes"].is_array())
            for (json& scene : doc["scenes"]) {
                if (!scene.is_object()) continue;
                if (!scene.contains("nodes")) scene["nodes"] = json::array();
                scene["nodes"].push_back(node);
            }
    }
    if (options.binary) return make_glb(doc.dump(), target);
    const std::string text = doc.dump(2) + "\n";
    return std::vector<std::uint8_t>(text.begin(), text.end());
}

}  // namespace zhc
