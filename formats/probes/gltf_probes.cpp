// zhc/formats/probes/gltf_probes.cpp — ZHC_light_probes (docs/gltf-extension.md) on top of tinygltf:
// loading an untrusted glTF 2.0 asset (shared by reading and embedding) and the zhc <-> glTF frames.
// Reading the extension: gltf_probes_read.cpp; embedding: gltf_probes_write.cpp; what the three
// share: gltf_probes_internal.h.
//
// tinygltf (Debian libtinygltf-dev, implementation in the shared library) parses and writes the
// asset; everything untrusted is checked by us first: the GLB framing, every URI (no absolute
// paths, schemes, `..` or backslashes, also percent-encoded), declared buffer sizes and data-URI
// lengths (before tinygltf allocates), and file reads go through FsCallbacks that refuse paths
// outside the input's directory. External buffers resolve in the input's directory only (a
// missing one is kIoError naming it; tinygltf's extra search of the working directory always
// finds nothing). Images are never read nor decoded: they are removed from the JSON tinygltf
// sees (their URIs are still checked). glTF 2.x only (asset.version / minVersion). Uri-less
// meshopt fallback buffers load no bytes (formats/scene/scene_gltf_geometry.cpp decodes the compressed views). The extension itself is read from our own nlohmann parse of the same JSON, so every
// index it holds is bound-checked against the arrays tinygltf loaded.
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

constexpr std::uint32_t kGlbMagic = 0x46546C67;     // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;    // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;     // "BIN\0"

Error fail(ErrorCode code, const std::string& path, const std::string& what) {
    return make_error(code, path + ": " + what);
}

namespace {

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

}  // namespace

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

namespace {

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
                if (uri.rfind("data:", 0) == 0) {
                    // Named here rather than by tinygltf's "Failed to decode 'uri'".
                    const size_t comma = uri.find(',');
                    if (comma == std::string::npos || comma < 12 || uri.compare(comma - 7, 7, ";base64") != 0)
                        return fail(ErrorCode::kBadFormat, path, where + ".uri: a data: URI that is not base64 (';base64,' is what glTF buffers use)");
                    const size_t n = uri.size() - comma - 1;
                    for (size_t k = comma + 1; k < uri.size(); ++k) {
                        const char c = uri[k];
                        const bool pad = c == '=' && k + 2 >= uri.size() && (k + 1 == uri.size() || uri[k + 1] == '=');
                        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/' || pad))
                            return fail(ErrorCode::kBadFormat, path, where + ".uri: the data: URI's base64 has a character that is not base64 at offset " +
                                                                     std::to_string(k - comma - 1) + " of its data");
                    }
                    if (n % 4 != 0)
                        return fail(ErrorCode::kBadFormat, path, where + ".uri: the data: URI's base64 is " + std::to_string(n) +
                                                                 " characters, not a multiple of 4");
                }
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

// The glTF 2.0 schema's required properties (and KHR_lights_punctual's, with its spot light's
// "spot" object), checked before tinygltf so that a missing one is named by its glTF path
// ("accessors[2].componentType") rather than by tinygltf's text ("'componentType' property is
// missing in Accessor."). Only objects are looked into: a wrong type is reported by the readers
// (or by tinygltf).
Status check_required(const json& doc, const std::string& path) {
    struct Need {
        const char* array;                 // top-level array (or extensions.KHR_lights_punctual.lights)
        const char* child;                 // "" or a member array/object of each element
        std::vector<const char*> required;
    };
    auto missing = [&](const std::string& where, const char* prop) {
        return fail(ErrorCode::kBadFormat, path, where + "." + prop + ": required property is missing");
    };
    auto check_object = [&](const json& o, const std::string& where, const std::vector<const char*>& props) -> Status {
        if (!o.is_object()) return Ok{};
        for (const char* p : props)
            if (!o.contains(p)) return missing(where, p);
        return Ok{};
    };
    auto each = [&](const json& parent, const char* key, const std::string& where,
                    const std::function<Status(const json&, const std::string&)>& f) -> Status {
        if (!parent.is_object() || !parent.contains(key) || !parent[key].is_array()) return Ok{};
        const json& a = parent[key];
        for (size_t i = 0; i < a.size(); ++i)
            if (Status s = f(a[i], where + (where.empty() ? "" : ".") + key + "[" + std::to_string(i) + "]"); !s) return s;
        return Ok{};
    };
    auto member = [&](const json& o, const char* key, const std::string& where, const std::vector<const char*>& props) -> Status {
        if (!o.is_object() || !o.contains(key)) return Ok{};
        return check_object(o[key], where + "." + key, props);
    };
    Status s = each(doc, "accessors", "", [&](const json& a, const std::string& w) -> Status {
        if (Status t = check_object(a, w, {"componentType", "count", "type"}); !t) return t;
        if (Status t = member(a, "sparse", w, {"count", "indices", "values"}); !t) return t;
        if (a.is_object() && a.contains("sparse") && a["sparse"].is_object()) {
            if (Status t = member(a["sparse"], "indices", w + ".sparse", {"bufferView", "componentType"}); !t) return t;
            if (Status t = member(a["sparse"], "values", w + ".sparse", {"bufferView"}); !t) return t;
        }
        return Ok{};
    });
    if (!s) return s;
    s = each(doc, "animations", "", [&](const json& a, const std::string& w) -> Status {
        if (Status t = check_object(a, w, {"channels", "samplers"}); !t) return t;
        if (Status t = each(a, "channels", w, [&](const json& c, const std::string& cw) -> Status {
                if (Status u = check_object(c, cw, {"sampler", "target"}); !u) return u;
                return member(c, "target", cw, {"path"});
            });
            !t)
            return t;
        return each(a, "samplers", w, [&](const json& c, const std::string& cw) { return check_object(c, cw, {"input", "output"}); });
    });
    if (!s) return s;
    s = each(doc, "bufferViews", "", [&](const json& b, const std::string& w) { return check_object(b, w, {"buffer", "byteLength"}); });
    if (!s) return s;
    s = each(doc, "cameras", "", [&](const json& c, const std::string& w) -> Status {
        if (Status t = check_object(c, w, {"type"}); !t) return t;
        if (Status t = member(c, "perspective", w, {"yfov", "znear"}); !t) return t;
        return member(c, "orthographic", w, {"xmag", "ymag", "zfar", "znear"});
    });
    if (!s) return s;
    s = each(doc, "meshes", "", [&](const json& m, const std::string& w) -> Status {
        if (Status t = check_object(m, w, {"primitives"}); !t) return t;
        return each(m, "primitives", w, [&](const json& p, const std::string& pw) { return check_object(p, pw, {"attributes"}); });
    });
    if (!s) return s;
    s = each(doc, "skins", "", [&](const json& k, const std::string& w) { return check_object(k, w, {"joints"}); });
    if (!s) return s;
    if (doc.contains("extensions") && doc["extensions"].is_object() && doc["extensions"].contains("KHR_lights_punctual"))
        s = each(doc["extensions"]["KHR_lights_punctual"], "lights", "extensions.KHR_lights_punctual",
                 [&](const json& l, const std::string& w) -> Status {
                     if (Status t = check_object(l, w, {"type"}); !t) return t;
                     if (l.is_object() && l["type"] == "spot" && !l.contains("spot"))
                         return fail(ErrorCode::kBadFormat, path, w + ".spot: required for a spot light, missing");
                     return Ok{};
                 });
    return s;
}

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
    // their URIs were checked above, and a data: URI of any MIME type is data, not a path), and a
    // uri-less meshopt fallback buffer gets a 4-byte stand-in (its bytes are never read: every
    // view of it is decoded from the compressed buffer, formats/scene/scene_gltf_geometry.cpp).
    std::vector<std::uint8_t> patched_glb;
    std::string patched_text;
    std::vector<size_t> fallback_buffers;
    if (out.doc.contains("buffers"))
        for (size_t i = 0; i < out.doc["buffers"].size(); ++i)
            if (!out.doc["buffers"][i].contains("uri") && is_meshopt_fallback(out.doc["buffers"][i]) && !(i == 0 && out.binary && glb.has_bin))
                fallback_buffers.push_back(i);
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
    if (draco_patch || out.doc.contains("images") || !fallback_buffers.empty() || !long_data_uris.empty()) {
        json patched = out.doc;
        patched.erase("images");
        for (size_t i : fallback_buffers) patched["buffers"][i] = json{{"byteLength", 4}, {"uri", "data:application/octet-stream;base64,AAAAAA=="}};
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
    for (size_t i : fallback_buffers)
        if (i < out.model.buffers.size()) out.model.buffers[i].data.clear();
    for (const auto& [i, declared] : long_data_uris)
        if (i < out.model.buffers.size() && out.model.buffers[i].data.size() > declared) out.model.buffers[i].data.resize(static_cast<size_t>(declared));
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
    auto out = encode_probe_set(*hub, set.representation, set.params, set.layout);
    if (!out) return out;
    out->validity = set.validity;  // per-probe data, independent of the SH axes
    out->visibility = set.visibility;
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
