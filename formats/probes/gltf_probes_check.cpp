// zhc/formats/probes/gltf_probes_check.cpp — the checks an untrusted glTF 2.0 asset passes before
// tinygltf sees it (gltf_probes.cpp load): the GLB framing, glTF 2.x only (asset.version /
// minVersion), every declared buffer size and data-URI length (before anything is allocated),
// every buffer URI (no absolute paths, schemes, `..` or backslashes, also percent-encoded), uri-less
// meshopt placeholder buffers, and the schema's required properties named by their glTF path.
#include "formats/probes/gltf_probes_internal.h"

#include <algorithm>
#include <cctype>
#include <functional>

namespace zhc {
namespace gltf_detail {

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

namespace {

// A buffer marked as the fallback of EXT_meshopt_compression / KHR_meshopt_compression.
bool is_meshopt_fallback(const json& buffer) {
    if (!buffer.is_object() || !buffer.contains("extensions") || !buffer["extensions"].is_object()) return false;
    for (const char* name : {"EXT_meshopt_compression", "KHR_meshopt_compression"}) {
        const json& e = buffer["extensions"].contains(name) ? buffer["extensions"][name] : json();
        if (e.is_object() && e.contains("fallback") && e["fallback"].is_boolean() && e["fallback"].get<bool>()) return true;
    }
    return false;
}

// The EXT_/KHR_meshopt_compression object of a bufferView, or null.
const json* meshopt_of_view(const json& view) {
    if (!view.is_object() || !view.contains("extensions") || !view["extensions"].is_object()) return nullptr;
    for (const char* name : {"EXT_meshopt_compression", "KHR_meshopt_compression"})
        if (view["extensions"].contains(name) && view["extensions"][name].is_object()) return &view["extensions"][name];
    return nullptr;
}

// The buffer index an object's "buffer" names, or n (none, or not an index below n).
size_t buffer_of(const json& obj, size_t n) {
    if (!obj.is_object() || !obj.contains("buffer") || !obj["buffer"].is_number_unsigned()) return n;
    const std::uint64_t b = obj["buffer"].get<std::uint64_t>();
    return b < n ? static_cast<size_t>(b) : n;
}

}  // namespace

std::vector<bool> meshopt_placeholders(const json& doc) {
    if (!doc.is_object() || !doc.contains("buffers") || !doc["buffers"].is_array()) return {};
    const json& buffers = doc["buffers"];
    const size_t n = buffers.size();
    // Per buffer, one pass over the views: 1 = a compressed view decodes into it, 2 = its bytes
    // are read (a plain view, or the source of a compressed view).
    std::vector<std::uint8_t> use(n, 0);
    if (doc.contains("bufferViews") && doc["bufferViews"].is_array())
        for (const json& view : doc["bufferViews"]) {
            const json* mo = meshopt_of_view(view);
            if (mo) {
                if (const size_t src = buffer_of(*mo, n); src < n) use[src] |= 2;
                if (const size_t dst = buffer_of(view, n); dst < n) use[dst] |= 1;
            } else if (const size_t b = buffer_of(view, n); b < n) {
                use[b] |= 2;
            }
        }
    std::vector<bool> out(n);
    for (size_t i = 0; i < n; ++i) out[i] = is_meshopt_fallback(buffers[i]) || use[i] == 1;
    return out;
}

namespace {

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

}  // namespace

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

}  // namespace

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
        const std::vector<bool> placeholder = meshopt_placeholders(doc);
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
            } else if (placeholder[i] && !(i == 0 && glb && glb->has_bin)) {
                // EXT/KHR_meshopt_compression: a placeholder buffer needs no bytes (every view of
                // it is decoded from a compressed buffer); nothing is loaded for it.
            } else if (i == 0 && glb) {
                if (!glb->has_bin) return fail(ErrorCode::kBadFormat, path, where + ": no uri and the GLB has no BIN chunk");
                if (*len > glb->bin_bytes) return fail(ErrorCode::kTruncated, path, where + ": byteLength " + std::to_string(*len) + " larger than the BIN chunk (" + std::to_string(glb->bin_bytes) + ")");
            } else {
                return fail(ErrorCode::kBadFormat, path, where + ": no uri (only a GLB's BIN chunk buffer and a buffer used only by meshopt-compressed views may have none)");
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
            // Where the URI points is checked only where the image is read or embedded
            // (gltf_probes_write.cpp): images are never read here.
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

}  // namespace gltf_detail
}  // namespace zhc
