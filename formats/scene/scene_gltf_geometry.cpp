// zhc/formats/scene/scene_gltf_geometry.cpp — the mesh primitives of a glTF 2.0 scene as triangle
// occluders (docs/scene.md "glTF input"): TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN (glTF 2.0 spec
// 3.7.2.1), accessors and buffer views bound-checked, POSITION as FLOAT or KHR_mesh_quantization
// integers, EXT_/KHR_meshopt_compression buffer views (gltf_meshopt.cpp) and
// KHR_draco_mesh_compression primitives (gltf_draco.cpp); EXT_mesh_gpu_instancing nodes draw each
// primitive once per instance.
#include "formats/scene/scene_gltf_reader.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>

#include <stb_image.h>

#include "formats/io/file_io.h"
#include "formats/probes/gltf_draco.h"
#include "formats/probes/gltf_meshopt.h"
#include "formats/probes/gltf_probes_internal.h"

namespace zhc::scene_gltf_detail {

// ---- meshes -------------------------------------------------------------------------------

// The meshopt extension object of a bufferView (EXT_ or KHR_meshopt_compression), or null.
const json* Reader::meshopt_ext(const json& v, std::string* name) const {
    if (!v.contains("extensions") || !v["extensions"].is_object()) return nullptr;
    for (const char* n : {"KHR_meshopt_compression", "EXT_meshopt_compression"})
        if (v["extensions"].contains(n)) {
            *name = n;
            return &v["extensions"][n];
        }
    return nullptr;
}

// A compressed view decoded: sizes checked against the limits and against what the compressed
// bytes can hold (every codec spends at least 1 bit per 16 output bytes... in practice the
// bound below: 128 output bytes per input byte plus a 4 KiB tail) before anything is allocated.
std::vector<std::uint8_t> Reader::decode_meshopt(const json& e, std::uint64_t v_len, const std::string& ep) {
    if (!e.is_object()) fail(ErrorCode::kInvalidValue, ep, "must be an object");
    const size_t bi = index(e.contains("buffer") ? e["buffer"] : json(), ep + ".buffer", raw_.buffers.size(), "buffers");
    const std::uint64_t off = count_field(e, "byteOffset", ep, 0), len = count_field(e, "byteLength", ep, ~0ull);
    const std::uint64_t stride = count_field(e, "byteStride", ep, ~0ull), n = count_field(e, "count", ep, ~0ull);
    MeshoptView mv;
    mv.count = n;
    mv.stride = stride;
    if (!e.contains("mode") || !e["mode"].is_string()) fail(ErrorCode::kInvalidValue, ep + ".mode", "missing or not a string");
    const std::string mode = e["mode"].get<std::string>();
    if (mode == "ATTRIBUTES") mv.mode = MeshoptMode::kAttributes;
    else if (mode == "TRIANGLES") mv.mode = MeshoptMode::kTriangles;
    else if (mode == "INDICES") mv.mode = MeshoptMode::kIndices;
    else fail(ErrorCode::kUnsupported, ep + ".mode", "unknown meshopt mode \"" + mode + "\" (known: ATTRIBUTES, TRIANGLES, INDICES)");
    if (e.contains("filter")) {
        if (!e["filter"].is_string()) fail(ErrorCode::kInvalidValue, ep + ".filter", "must be a string");
        const std::string f = e["filter"].get<std::string>();
        if (f == "NONE") mv.filter = MeshoptFilter::kNone;
        else if (f == "OCTAHEDRAL") mv.filter = MeshoptFilter::kOctahedral;
        else if (f == "QUATERNION") mv.filter = MeshoptFilter::kQuaternion;
        else if (f == "EXPONENTIAL") mv.filter = MeshoptFilter::kExponential;
        else fail(ErrorCode::kUnsupported, ep + ".filter", "unknown meshopt filter \"" + f + "\" (known: NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL)");
    }
    if (const std::string why = meshopt_view_problem(mv); !why.empty()) fail(ErrorCode::kInvalidValue, ep, why);
    if (n > gltf_limits_.max_buffer_bytes / stride)
        fail(ErrorCode::kTooLarge, ep, "decoded size above the buffer limit of " + std::to_string(gltf_limits_.max_buffer_bytes) + " bytes");
    const std::uint64_t size = n * stride;
    if (size != v_len)
        fail(ErrorCode::kInvalidValue, ep, "count x byteStride = " + std::to_string(size) + " differs from the bufferView's byteLength " + std::to_string(v_len));
    const auto& buf = raw_.buffers[bi];
    if (off > buf.size() || len > buf.size() - off)
        fail(ErrorCode::kInvalidValue, ep, "byte range [" + std::to_string(off) + ", +" + std::to_string(len) + ") outside buffer " + std::to_string(bi) + " (" + std::to_string(buf.size()) + " bytes)");
    if (size > len * 128 + 4096)
        fail(ErrorCode::kInvalidValue, ep, std::to_string(len) + " compressed bytes cannot hold the " + std::to_string(size) + " bytes declared");
    decoded_total_ += size;
    if (decoded_total_ > gltf_limits_.max_total_bytes)
        fail(ErrorCode::kTooLarge, ep, "decoded buffer views exceed the limit of " + std::to_string(gltf_limits_.max_total_bytes) + " bytes");
    auto r = decode_meshopt_view(std::span<const std::uint8_t>(buf.data() + off, static_cast<size_t>(len)), mv, ep);
    if (!r) throw Fail{make_error(r.error().code, path_ + ": " + r.error().message)};
    return std::move(r).value();
}

// The bytes of bufferView `vi`: a range of its buffer, or the decoded bytes of a compressed view.
std::span<const std::uint8_t> Reader::view_bytes(size_t vi, const std::string& vp) {
    const json& v = array_of(doc_, "bufferViews")[vi];
    if (!v.is_object()) fail(ErrorCode::kInvalidValue, vp, "must be an object");
    const std::uint64_t v_len = count_field(v, "byteLength", vp, ~0ull);
    std::string ext;
    if (const json* mo = meshopt_ext(v, &ext)) {
        auto it = decoded_.find(vi);
        if (it == decoded_.end()) it = decoded_.emplace(vi, decode_meshopt(*mo, v_len, vp + ".extensions." + ext)).first;
        return it->second;
    }
    const size_t bi = index(v.contains("buffer") ? v["buffer"] : json(), vp + ".buffer", raw_.buffers.size(), "buffers");
    const std::uint64_t v_off = count_field(v, "byteOffset", vp, 0);
    const auto& buf = raw_.buffers[bi];
    if (v_off > buf.size() || v_len > buf.size() - v_off)
        fail(ErrorCode::kInvalidValue, vp, "byte range [" + std::to_string(v_off) + ", +" + std::to_string(v_len) + ") outside buffer " + std::to_string(bi) + " (" + std::to_string(buf.size()) + " bytes)");
    return {buf.data() + v_off, static_cast<size_t>(v_len)};
}

// The bytes of accessor `ai` (after its byteOffset) and the stride, bound-checked for `count`
// elements of `elem` bytes.
Reader::View Reader::accessor_view(size_t ai, std::uint64_t count, std::uint64_t elem, const std::string& ap) {
    const json& acc = array_of(doc_, "accessors")[ai];
    if (!acc.contains("bufferView")) fail(ErrorCode::kUnsupported, ap, "accessor without a bufferView (all zeros) is not read");
    const json& views = array_of(doc_, "bufferViews");
    const size_t vi = index(acc["bufferView"], ap + ".bufferView", views.size(), "bufferViews");
    const std::string vp = at("bufferViews", vi);
    const std::span<const std::uint8_t> bytes = view_bytes(vi, vp);
    const json& v = views[vi];
    const std::uint64_t v_len = bytes.size();
    const std::uint64_t stride = v.contains("byteStride") ? count_field(v, "byteStride", vp, 0) : elem;
    if (stride < elem || stride > 252) fail(ErrorCode::kInvalidValue, vp + ".byteStride", "must be in [" + std::to_string(elem) + ", 252]");
    const std::uint64_t a_off = count_field(acc, "byteOffset", ap, 0);
    // count >= 1 here; the last element ends at a_off + stride (count - 1) + elem.
    if (a_off > v_len || (count - 1) > (v_len - a_off) / stride || (count - 1) * stride + elem > v_len - a_off)
        fail(ErrorCode::kInvalidValue, ap, std::to_string(count) + " elements run past the end of " + vp);
    return {bytes.data() + a_off, v_len - a_off, stride};
}

std::uint64_t Reader::count_field(const json& obj, const char* key, const std::string& where, std::uint64_t fallback) const {
    if (!obj.contains(key)) {
        if (fallback == ~0ull) fail(ErrorCode::kInvalidValue, where + "." + key, "missing required field");
        return fallback;
    }
    return count(obj, key, where, true, 0);
}

const json& Reader::accessor(size_t ai, const std::string& ap) const {
    const json& acc = array_of(doc_, "accessors")[ai];
    if (!acc.is_object()) fail(ErrorCode::kInvalidValue, ap, "must be an object");
    if (acc.contains("sparse")) fail(ErrorCode::kUnsupported, ap, "sparse accessors are not read as occluders");
    return acc;
}

// POSITION values: FLOAT, or (KHR_mesh_quantization) BYTE/UNSIGNED_BYTE/SHORT/UNSIGNED_SHORT,
// normalized or not (glTF 2.0 spec 3.11: signed c / (2^(n-1) - 1) clamped at -1, unsigned
// c / (2^n - 1)); in the mesh's own (glTF) space, checked for finiteness.
std::vector<Vec3> Reader::read_positions(size_t pa, std::uint64_t nv) {
    const std::string pap = at("accessors", pa);
    const json& pacc = accessor(pa, pap);
    if (!pacc.contains("type") || pacc["type"] != "VEC3") fail(ErrorCode::kInvalidValue, pap, "POSITION must be a VEC3 accessor");
    const std::uint64_t ct = count(pacc, "componentType", pap, true, 0);
    const bool normalized = pacc.contains("normalized") && pacc["normalized"].is_boolean() && pacc["normalized"].get<bool>();
    const std::uint64_t csize = ct == kFloat ? 4 : ct == kByte || ct == kUbyte ? 1 : ct == kShort || ct == kUshort ? 2 : 0;
    if (csize == 0) fail(ErrorCode::kUnsupported, pap + ".componentType", "POSITION must be FLOAT, BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT (got " + std::to_string(ct) + ")");
    if (ct == kFloat && normalized) fail(ErrorCode::kInvalidValue, pap + ".normalized", "a FLOAT accessor cannot be normalized");
    const View pv = accessor_view(pa, nv, 3 * csize, pap);
    std::vector<Vec3> verts(nv);
    for (std::uint64_t i = 0; i < nv; ++i) {
        const std::uint8_t* e = pv.data + i * pv.stride;
        double f[3];
        for (int k = 0; k < 3; ++k) {
            const std::uint8_t* c = e + csize * static_cast<std::uint64_t>(k);
            switch (ct) {
                case kFloat: {
                    const std::uint32_t bits = le32(c);
                    float x;
                    std::memcpy(&x, &bits, 4);
                    f[k] = x;
                    break;
                }
                case kByte: f[k] = normalized ? std::max(static_cast<std::int8_t>(c[0]) / 127.0, -1.0) : static_cast<std::int8_t>(c[0]); break;
                case kUbyte: f[k] = normalized ? c[0] / 255.0 : c[0]; break;
                case kShort: {
                    const auto v = static_cast<std::int16_t>(static_cast<std::uint16_t>(c[0] | c[1] << 8));
                    f[k] = normalized ? std::max(v / 32767.0, -1.0) : v;
                    break;
                }
                default: {
                    const std::uint16_t v = static_cast<std::uint16_t>(c[0] | c[1] << 8);
                    f[k] = normalized ? v / 65535.0 : v;
                    break;
                }
            }
        }
        if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2]))
            fail(ErrorCode::kInvalidValue, pap, "vertex " + std::to_string(i) + " is not finite");
        verts[i] = {f[0], f[1], f[2]};
    }
    return verts;
}

Vec3 Reader::transformed(const Mat4& world, Vec3 p, const std::string& where, std::uint64_t i) {
    const Vec3 v = from_gltf(point(world, p));
    if (!finite3(v)) fail(ErrorCode::kInvalidValue, where, "transformed vertex " + std::to_string(i) + " is not finite");
    for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], v[a]);
        hi_[a] = std::max(hi_[a], v[a]);
    }
    return v;
}

// Triangles of a TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN element list (glTF 2.0 spec
// 3.7.2.1): strip triangle i is (v_i, v_{i+1}, v_{i+2}) for even i and (v_{i+1}, v_i, v_{i+2})
// for odd i (winding kept), fan triangle i is (v_{i+1}, v_{i+2}, v_0). Triangles that repeat an
// index (the joins between strips) are dropped: they have no area.
void Reader::add_triangles(const std::vector<Vec3>& verts, const std::vector<std::uint32_t>& idx, std::uint64_t mode) {
    auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        if (mode != 4 && (a == b || b == c || a == c)) return;
        occluders_.push_back(triangle_occluder(verts[a], verts[b], verts[c]));
        occluders_.back().material = current_material_;
        if (current_uvs_) {
            const auto& uv = *current_uvs_;
            occluders_.back().material = kSurfaceBit | static_cast<std::uint32_t>(surfaces_.size());
            surfaces_.push_back(SurfaceUv{current_material_, {{uv[a][0], uv[a][1]}, {uv[b][0], uv[b][1]}, {uv[c][0], uv[c][1]}}});
        }
    };
    const size_t n = idx.size();
    if (mode == 4) {
        for (size_t t = 0; t + 2 < n; t += 3) add(idx[t], idx[t + 1], idx[t + 2]);
    } else if (mode == 5) {
        for (size_t i = 0; i + 2 < n; ++i) {
            if (i % 2 == 0) add(idx[i], idx[i + 1], idx[i + 2]);
            else add(idx[i + 1], idx[i], idx[i + 2]);
        }
    } else {
        for (size_t i = 0; i + 2 < n; ++i) add(idx[i + 1], idx[i + 2], idx[0]);
    }
}

// The primitive's triangles, once per instance: each instance's world matrix is computed when it
// is used and the transformed vertices go through one reused array, so instancing costs the
// triangle occluders themselves and nothing per instance besides.
void Reader::add_instances(const std::vector<Vec3>& local, const std::vector<std::uint32_t>& idx, std::uint64_t mode,
                           const Instancing& inst, const std::string& where) {
    // Room for every triangle of every instance at once (the count was checked against the limit):
    // a mesh of n triangles then costs n occluders, not up to twice that while the vector grows.
    const std::uint64_t per = mode == 4 ? idx.size() / 3 : idx.size() > 2 ? idx.size() - 2 : 0;
    const std::uint64_t need = per * inst.count;
    if (occluders_.capacity() - occluders_.size() < need)
        occluders_.reserve(std::max<std::uint64_t>(occluders_.size() + need, 2 * occluders_.capacity()));
    std::vector<Vec3> verts(local.size());
    for (std::uint64_t k = 0; k < inst.count; ++k) {
        const Mat4 world = instance_world(inst, k);
        for (size_t i = 0; i < local.size(); ++i) verts[i] = transformed(world, local[i], where, i);
        add_triangles(verts, idx, mode);
    }
}

// `t` triangles drawn `instances` times, checked against the limit (without overflow) before
// anything is decoded.
void Reader::count_triangles(std::uint64_t t, std::uint64_t instances, const std::string& pp) {
    const std::uint64_t limit = options_.limits.max_triangles;
    if (instances != 0 && t > (limit - std::min(triangles_, limit)) / instances)
        fail(ErrorCode::kTooLarge, pp, "mesh triangles (with instances) exceed the limit of " + std::to_string(limit));
    triangles_ += t * instances;
}

// ---- EXT_mesh_gpu_instancing ----------------------------------------------------------------

// The extension object of a mesh node: TRANSLATION (VEC3 FLOAT), ROTATION (VEC4 FLOAT, or BYTE /
// SHORT normalized), SCALE (VEC3 FLOAT), all optional, every attribute (custom `_NAME` ones
// too) of the same count. A component type outside that table is kUnsupported, a wrong accessor
// type or count kInvalidValue, each naming the attribute.
Reader::Instancing Reader::read_instancing(const json& e, const Mat4& world, const std::string& ep) {
    Instancing inst;
    inst.world = world;
    inst.extension = true;
    inst.where = ep;
    const std::string ap = ep + ".attributes";
    if (!e.is_object() || !e.contains("attributes") || !e["attributes"].is_object()) fail(ErrorCode::kInvalidValue, ap, "missing or not an object");
    const json& attrs = e["attributes"];
    if (attrs.empty()) fail(ErrorCode::kInvalidValue, ap, "has no attribute (the instance count comes from them)");
    const size_t n_acc = array_of(doc_, "accessors").size();
    // The instance count: TRANSLATION's, else ROTATION's, else SCALE's, else the first custom
    // attribute's; an attribute of another count is the one named.
    std::string ref = attrs.begin().key();
    for (const char* k : {"SCALE", "ROTATION", "TRANSLATION"})
        if (attrs.contains(k)) ref = k;
    {
        const size_t ai = index(attrs[ref], ap + "." + ref, n_acc, "accessors");
        inst.count = count(accessor(ai, at("accessors", ai)), "count", at("accessors", ai), true, 0);
    }
    for (auto it = attrs.begin(); it != attrs.end(); ++it) {
        const std::string fp = ap + "." + it.key();
        const size_t ai = index(it.value(), fp, n_acc, "accessors");
        const std::string acp = at("accessors", ai);
        const json& acc = accessor(ai, acp);
        const std::uint64_t n = count(acc, "count", acp, true, 0);
        if (n != inst.count)
            fail(ErrorCode::kInvalidValue, fp, "has " + std::to_string(n) + " elements, " + ref + " " + std::to_string(inst.count) +
                                                   " (all attributes of a node must have the same count)");
        const bool t = it.key() == "TRANSLATION", r = it.key() == "ROTATION", s = it.key() == "SCALE";
        if (!t && !r && !s) continue;  // custom attributes (_ID, ...) do not move geometry
        const char* want_type = r ? "VEC4" : "VEC3";
        if (!acc.contains("type") || acc["type"] != want_type)
            fail(ErrorCode::kInvalidValue, fp, "must be a " + std::string(want_type) + " accessor (got " + (acc.contains("type") ? acc["type"].dump() : "none") + ")");
        const std::uint64_t ct = count(acc, "componentType", acp, true, 0);
        if (acc.contains("normalized") && !acc["normalized"].is_boolean()) fail(ErrorCode::kInvalidValue, acp + ".normalized", "must be true or false");
        const bool normalized = acc.contains("normalized") && acc["normalized"].get<bool>();
        const bool ok = ct == kFloat ? !normalized : r && normalized && (ct == kByte || ct == kShort);
        if (!ok)
            fail(ErrorCode::kUnsupported, fp,
                 std::string(r ? "ROTATION must be FLOAT, or BYTE or SHORT normalized" : "must be FLOAT") +
                     " (EXT_mesh_gpu_instancing; got componentType " + std::to_string(ct) + (normalized ? " normalized" : "") + ")");
        if (n == 0) continue;
        const std::uint64_t csize = ct == kFloat ? 4 : ct == kShort ? 2 : 1;
        const View v = accessor_view(ai, n, (r ? 4 : 3) * csize, acp);
        if (t) inst.t = v;
        else if (s) inst.s = v;
        else {
            inst.r = v;
            inst.r_type = ct;
        }
    }
    return inst;
}

// World matrix of instance i: NodeWorldXform * InstanceXform, InstanceXform = T * R * S (the
// extension's "Transformation Order"); without the extension the node's world matrix itself.
Mat4 Reader::instance_world(const Instancing& inst, std::uint64_t i) const {
    if (!inst.extension) return inst.world;
    auto component = [&](const View& v, std::uint64_t ct, int k) -> double {
        const std::uint8_t* c = v.data + i * v.stride + static_cast<std::uint64_t>(k) * (ct == kFloat ? 4 : ct == kShort ? 2 : 1);
        if (ct == kShort) return std::max(static_cast<std::int16_t>(static_cast<std::uint16_t>(c[0] | c[1] << 8)) / 32767.0, -1.0);
        if (ct == kByte) return std::max(static_cast<std::int8_t>(c[0]) / 127.0, -1.0);
        const std::uint32_t bits = le32(c);
        float x;
        std::memcpy(&x, &bits, 4);
        return x;
    };
    Vec3 t{0, 0, 0}, s{1, 1, 1};
    double q[4] = {0, 0, 0, 1};
    const std::string ip = inst.where + ".attributes";
    if (inst.t.data) t = {component(inst.t, kFloat, 0), component(inst.t, kFloat, 1), component(inst.t, kFloat, 2)};
    if (inst.s.data) s = {component(inst.s, kFloat, 0), component(inst.s, kFloat, 1), component(inst.s, kFloat, 2)};
    if (inst.r.data)
        for (int k = 0; k < 4; ++k) q[k] = component(inst.r, inst.r_type, k);
    if (!finite3(t) || !finite3(s) || !std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]) || !std::isfinite(q[3]))
        fail(ErrorCode::kInvalidValue, ip, "instance " + std::to_string(i) + " has a non-finite translation, rotation or scale");
    const Mat4 w = mul(inst.world, trs_matrix(t, q, s, ip + ".ROTATION: instance " + std::to_string(i)));
    for (double v : w.m)
        if (!std::isfinite(v)) fail(ErrorCode::kInvalidValue, ip, "instance " + std::to_string(i) + ": world transform is not finite");
    return w;
}

// KHR_draco_mesh_compression: the primitive's geometry from its Draco stream.
void Reader::add_draco(const json& prim, const json& ext, const std::string& pp, std::uint64_t mode, const Instancing& inst) {
    const std::string ep = pp + ".extensions.KHR_draco_mesh_compression";
    if (!ext.is_object()) fail(ErrorCode::kInvalidValue, ep, "must be an object");
    if (mode != 4) fail(ErrorCode::kUnsupported, pp + ".mode", "Draco-compressed primitives are read as TRIANGLES only");
    const size_t n_acc = array_of(doc_, "accessors").size();
    const size_t pa = index(prim["attributes"]["POSITION"], pp + ".attributes.POSITION", n_acc, "accessors");
    const std::uint64_t nv = count(accessor(pa, at("accessors", pa)), "count", at("accessors", pa), true, 0);
    std::uint64_t ni = nv;
    if (prim.contains("indices")) {
        const size_t ia = index(prim["indices"], pp + ".indices", n_acc, "accessors");
        ni = count(accessor(ia, at("accessors", ia)), "count", at("accessors", ia), true, 0);
    }
    if (ni % 3 != 0) fail(ErrorCode::kInvalidValue, pp, "TRIANGLES need a multiple of 3 indices (got " + std::to_string(ni) + ")");
    count_triangles(ni / 3, inst.count, pp);
    if (nv > options_.limits.max_triangles * 3) fail(ErrorCode::kTooLarge, pp, std::to_string(nv) + " Draco points exceed 3 x the triangle limit");
    if (!ext.contains("attributes") || !ext["attributes"].is_object() || !ext["attributes"].contains("POSITION") ||
        !ext["attributes"]["POSITION"].is_number_integer())
        fail(ErrorCode::kInvalidValue, ep + ".attributes.POSITION", "missing or not an integer");
    const std::int64_t pid = ext["attributes"]["POSITION"].get<std::int64_t>();
    if (pid < 0 || pid > std::numeric_limits<int>::max()) fail(ErrorCode::kInvalidValue, ep + ".attributes.POSITION", "not a Draco attribute id");
    const json& views = array_of(doc_, "bufferViews");
    const size_t vi = index(ext.contains("bufferView") ? ext["bufferView"] : json(), ep + ".bufferView", views.size(), "bufferViews");
    const std::span<const std::uint8_t> bytes = view_bytes(vi, at("bufferViews", vi));
    // A textured primitive's UVs: the Draco attribute of its material's TEXCOORD_n.
    int uv_id = -1;
    if (current_material_ != kNoMaterial && material_textures_[current_material_].any()) {
        const std::string key = "TEXCOORD_" + std::to_string(material_textures_[current_material_].tex_coord);
        if (ext["attributes"].contains(key) && ext["attributes"][key].is_number_integer() && ext["attributes"][key].get<std::int64_t>() >= 0 &&
            ext["attributes"][key].get<std::int64_t>() <= std::numeric_limits<int>::max())
            uv_id = static_cast<int>(ext["attributes"][key].get<std::int64_t>());
        else
            notes_.push_back(pp + ": its material is textured but its Draco stream has no " + key + ": the material's factors are used without textures");
    }
    auto mesh = decode_draco_mesh(bytes, static_cast<int>(pid), nv, ni / 3, ep, uv_id);
    if (!mesh) throw Fail{make_error(mesh.error().code, path_ + ": " + mesh.error().message)};
    std::vector<std::array<float, 2>> uvs = std::move(mesh->texcoords);
    for (size_t i = 0; i < uvs.size(); ++i)
        if (!std::isfinite(uvs[i][0]) || !std::isfinite(uvs[i][1])) fail(ErrorCode::kInvalidValue, ep, "Draco texture coordinate " + std::to_string(i) + " is not finite");
    current_uvs_ = uvs.empty() ? nullptr : &uvs;
    std::vector<Vec3> verts(mesh->positions.size());
    for (size_t i = 0; i < verts.size(); ++i) {
        const auto& q = mesh->positions[i];
        if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
            fail(ErrorCode::kInvalidValue, ep, "Draco vertex " + std::to_string(i) + " is not finite");
        verts[i] = {q[0], q[1], q[2]};
    }
    std::vector<std::uint32_t> idx;
    idx.reserve(mesh->faces.size() * 3);
    for (const auto& f : mesh->faces) idx.insert(idx.end(), f.begin(), f.end());
    add_instances(verts, idx, 4, inst, ep);
    current_uvs_ = nullptr;
}

void Reader::add_point_bounds(const json& prim, const std::string& pp, const Instancing& inst) {
    if (!prim.contains("attributes") || !prim["attributes"].is_object() || !prim["attributes"].contains("POSITION")) return;
    if (prim.contains("extensions") && prim["extensions"].is_object() && prim["extensions"].contains("KHR_draco_mesh_compression")) return;
    const size_t n_acc = array_of(doc_, "accessors").size();
    const size_t pa = index(prim["attributes"]["POSITION"], pp + ".attributes.POSITION", n_acc, "accessors");
    const std::string pap = at("accessors", pa);
    const std::uint64_t nv = count(accessor(pa, pap), "count", pap, true, 0);
    if (nv == 0 || inst.count == 0) return;
    // Bounded like triangles: the vertices times the instances count against the triangle limit.
    count_triangles((nv + 2) / 3, inst.count, pp);
    const std::vector<Vec3> verts = read_positions(pa, nv);
    for (std::uint64_t k = 0; k < inst.count; ++k) {
        const Mat4 world = instance_world(inst, k);
        for (size_t i = 0; i < verts.size(); ++i) (void)transformed(world, verts[i], pap, i);
    }
}

// The zhc material of a primitive's glTF material (glTF 2.0 spec 3.9): Lambertian albedo = base
// colour factor x (1 - metallic factor), the diffuse part of the metal-rough model; emission =
// emissive factor x KHR_materials_emissive_strength. No material (the spec's default: white,
// fully metallic) and a material that neither reflects diffusely nor emits: kNoMaterial. Its
// textures (base colour, metallic-roughness, emissive) are recorded for decode_textures; the
// factors multiply their texels (codec/bake/transport.h SceneMaterial).
std::uint32_t Reader::material_of(const json& prim, const std::string& pp) {
    if (!prim.contains("material")) return kNoMaterial;
    const json& mats = array_of(doc_, "materials");
    const size_t mi = index(prim["material"], pp + ".material", mats.size(), "materials");
    if (auto it = material_ids_.find(mi); it != material_ids_.end()) return it->second;
    const std::string mp = at("materials", mi);
    const json& m = mats[mi];
    if (!m.is_object()) fail(ErrorCode::kInvalidValue, mp, "must be an object");
    double base[4] = {1, 1, 1, 1}, metallic = 1, emissive[3] = {0, 0, 0}, strength = 1;
    MaterialTextures mt;
    SceneMaterial sm;
    bool mixed_sets = false;
    bool first_set = true;
    // A textureInfo: its texture index, texCoord set (one set per material is read) and
    // KHR_texture_transform (offset, rotation, scale: u' = T R S u, the extension's order).
    auto texture_info = [&](const json& j, const std::string& where, SceneMaterial::UvTransform* uv) -> int {
        if (!j.is_object()) fail(ErrorCode::kInvalidValue, where, "must be an object");
        const int ti = static_cast<int>(index(j.contains("index") ? j["index"] : json(), where + ".index", array_of(doc_, "textures").size(), "textures"));
        std::uint64_t set = count(j, "texCoord", where, false, 0);
        if (j.contains("extensions") && j["extensions"].is_object() && j["extensions"].contains("KHR_texture_transform")) {
            const std::string tp = where + ".extensions.KHR_texture_transform";
            const json& t = j["extensions"]["KHR_texture_transform"];
            if (!t.is_object()) fail(ErrorCode::kInvalidValue, tp, "must be an object");
            std::vector<double> off{0, 0}, scale{1, 1};
            double rot = 0;
            if (t.contains("offset")) off = numbers(t["offset"], tp + ".offset", 2);
            if (t.contains("scale")) scale = numbers(t["scale"], tp + ".scale", 2);
            if (t.contains("rotation")) rot = number(t["rotation"], tp + ".rotation");
            if (t.contains("texCoord")) set = count(t, "texCoord", tp, false, 0);
            const double c = std::cos(rot), s = std::sin(rot);
            *uv = {static_cast<float>(c * scale[0]), static_cast<float>(s * scale[1]), static_cast<float>(off[0]),
                   static_cast<float>(-s * scale[0]), static_cast<float>(c * scale[1]), static_cast<float>(off[1])};
            for (float f : *uv)
                if (!std::isfinite(f)) fail(ErrorCode::kInvalidValue, tp, "offset, rotation and scale must give a finite transform");
        }
        if (first_set) mt.tex_coord = set;
        else if (set != mt.tex_coord) mixed_sets = true;
        first_set = false;
        return ti;
    };
    if (m.contains("pbrMetallicRoughness")) {
        const json& pbr = m["pbrMetallicRoughness"];
        if (!pbr.is_object()) fail(ErrorCode::kInvalidValue, mp + ".pbrMetallicRoughness", "must be an object");
        if (pbr.contains("baseColorFactor")) {
            const std::vector<double> f = numbers(pbr["baseColorFactor"], mp + ".pbrMetallicRoughness.baseColorFactor", 4);
            for (int k = 0; k < 4; ++k) base[k] = f[static_cast<size_t>(k)];
        }
        if (pbr.contains("metallicFactor")) metallic = number(pbr["metallicFactor"], mp + ".pbrMetallicRoughness.metallicFactor");
        if (pbr.contains("baseColorTexture")) mt.base = texture_info(pbr["baseColorTexture"], mp + ".pbrMetallicRoughness.baseColorTexture", &sm.base_uv);
        if (pbr.contains("metallicRoughnessTexture"))
            mt.metal_rough = texture_info(pbr["metallicRoughnessTexture"], mp + ".pbrMetallicRoughness.metallicRoughnessTexture", &sm.metal_rough_uv);
    }
    if (m.contains("emissiveFactor")) {
        const std::vector<double> f = numbers(m["emissiveFactor"], mp + ".emissiveFactor", 3);
        for (int k = 0; k < 3; ++k) emissive[k] = f[static_cast<size_t>(k)];
    }
    if (m.contains("emissiveTexture")) mt.emissive = texture_info(m["emissiveTexture"], mp + ".emissiveTexture", &sm.emissive_uv);
    if (m.contains("extensions") && m["extensions"].is_object() && m["extensions"].contains("KHR_materials_emissive_strength")) {
        const json& e = m["extensions"]["KHR_materials_emissive_strength"];
        if (e.is_object() && e.contains("emissiveStrength"))
            strength = number(e["emissiveStrength"], mp + ".extensions.KHR_materials_emissive_strength.emissiveStrength");
    }
    sm.name = m.contains("name") && m["name"].is_string() ? m["name"].get<std::string>() : mp;
    for (int k = 0; k < 3; ++k) {
        sm.albedo[k] = static_cast<float>(std::clamp(base[k], 0.0, 1.0) * (1.0 - std::clamp(metallic, 0.0, 1.0)));
        sm.emission[k] = static_cast<float>(std::clamp(emissive[k], 0.0, 1.0) * std::max(0.0, strength));
        sm.base_factor[k] = static_cast<float>(std::clamp(base[k], 0.0, 1.0));
    }
    sm.metallic = static_cast<float>(std::clamp(metallic, 0.0, 1.0));
    if (mixed_sets) notes_.push_back(mp + ": its textures use different texCoord sets (KHR_texture_transform's included): TEXCOORD_" + std::to_string(mt.tex_coord) + " is used for all of them");
    // A metallic-roughness texture can lower the metallic factor, so base colour alone may reflect.
    const bool reflects = sm.albedo.r > 0 || sm.albedo.g > 0 || sm.albedo.b > 0 ||
                          (mt.metal_rough >= 0 && (sm.base_factor.r > 0 || sm.base_factor.g > 0 || sm.base_factor.b > 0));
    std::uint32_t id = kNoMaterial;
    if (reflects || sm.emission.r > 0 || sm.emission.g > 0 || sm.emission.b > 0) {
        id = static_cast<std::uint32_t>(materials_.size());
        materials_.push_back(sm);
        material_textures_.push_back(mt);
    }
    material_ids_[mi] = id;
    return id;
}

void Reader::add_mesh(size_t mi, const Instancing& inst) {
    const std::string mp = at("meshes", mi);
    const json& mesh = array_of(doc_, "meshes")[mi];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array())
        fail(ErrorCode::kInvalidValue, mp + ".primitives", "missing or not an array");
    const json& prims = mesh["primitives"];
    const size_t n_acc = array_of(doc_, "accessors").size();
    for (size_t pi = 0; pi < prims.size(); ++pi) {
        const std::string pp = at(mp + ".primitives", pi);
        const json& prim = prims[pi];
        if (!prim.is_object()) fail(ErrorCode::kInvalidValue, pp, "must be an object");
        const std::uint64_t mode = count(prim, "mode", pp, false, 4);
        if (mode > 6) fail(ErrorCode::kInvalidValue, pp + ".mode", "unknown primitive mode " + std::to_string(mode));
        if (mode <= 3) {
            // POINTS, LINES, LINE_LOOP, LINE_STRIP: no area, so they block nothing, but their
            // vertices are part of the scene the default probe grid spans.
            add_point_bounds(prim, pp, inst);
            continue;
        }
        current_material_ = material_of(prim, pp);
        current_uvs_ = nullptr;
        if (!prim.contains("attributes") || !prim["attributes"].is_object() || !prim["attributes"].contains("POSITION"))
            fail(ErrorCode::kInvalidValue, pp + ".attributes.POSITION", "missing");
        const bool textured = current_material_ != kNoMaterial && material_textures_[current_material_].any();
        if (prim.contains("extensions") && prim["extensions"].is_object() && prim["extensions"].contains("KHR_draco_mesh_compression")) {
            add_draco(prim, prim["extensions"]["KHR_draco_mesh_compression"], pp, mode, inst);
            current_uvs_ = nullptr;
            continue;
        }
        const size_t pa = index(prim["attributes"]["POSITION"], pp + ".attributes.POSITION", n_acc, "accessors");
        const std::string pap = at("accessors", pa);
        const std::uint64_t nv = count(accessor(pa, pap), "count", pap, true, 0);
        if (nv == 0) continue;
        // Triangles of this primitive, checked against the limit before anything is decoded.
        std::uint64_t ni = nv;
        size_t ia = 0;
        const bool indexed = prim.contains("indices");
        if (indexed) {
            ia = index(prim["indices"], pp + ".indices", n_acc, "accessors");
            ni = count(accessor(ia, at("accessors", ia)), "count", at("accessors", ia), true, 0);
        }
        if (mode == 4 && ni % 3 != 0)
            fail(ErrorCode::kInvalidValue, indexed ? at("accessors", ia) : pap,
                 "TRIANGLES need a multiple of 3 " + std::string(indexed ? "indices" : "vertices") + " (got " + std::to_string(ni) + ")");
        count_triangles(triangle_count(mode, ni), inst.count, pp);
        if (triangle_count(mode, ni) == 0 || inst.count == 0) continue;
        if (nv > options_.limits.max_triangles * 3) fail(ErrorCode::kTooLarge, pap, std::to_string(nv) + " vertices exceed 3 x the triangle limit");
        const std::vector<Vec3> verts = read_positions(pa, nv);
        std::vector<std::array<float, 2>> uvs;
        if (textured) uvs = read_uvs(prim, pp, nv);
        if (!uvs.empty()) current_uvs_ = &uvs;
        std::vector<std::uint32_t> idx(ni);
        if (indexed) {
            const std::string iap = at("accessors", ia);
            const json& iacc = array_of(doc_, "accessors")[ia];
            if (!iacc.contains("type") || iacc["type"] != "SCALAR") fail(ErrorCode::kInvalidValue, iap, "indices must be a SCALAR accessor");
            const std::uint64_t ct = count(iacc, "componentType", iap, true, 0);
            const std::uint64_t size = ct == kUbyte ? 1 : ct == kUshort ? 2 : ct == kUint ? 4 : 0;
            if (size == 0) fail(ErrorCode::kInvalidValue, iap + ".componentType", "indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
            const View iv = accessor_view(ia, ni, size, iap);
            for (std::uint64_t i = 0; i < ni; ++i) {
                const std::uint8_t* e = iv.data + i * iv.stride;
                const std::uint32_t v = size == 1 ? e[0] : size == 2 ? std::uint32_t(e[0] | e[1] << 8) : le32(e);
                if (v >= nv) fail(ErrorCode::kInvalidValue, iap, "index " + std::to_string(i) + " = " + std::to_string(v) + " is not below the vertex count " + std::to_string(nv));
                idx[i] = v;
            }
        } else {
            for (std::uint64_t i = 0; i < ni; ++i) idx[i] = static_cast<std::uint32_t>(i);
        }
        add_instances(verts, idx, mode, inst, pap);
        current_uvs_ = nullptr;
    }
}

// ---- textures -------------------------------------------------------------------------------

std::vector<std::array<float, 2>> Reader::read_uvs(const json& prim, const std::string& pp, std::uint64_t nv) {
    const MaterialTextures& mt = material_textures_[current_material_];
    const std::string key = "TEXCOORD_" + std::to_string(mt.tex_coord);
    const json& attrs = prim["attributes"];
    if (!attrs.contains(key)) {
        notes_.push_back(pp + ": its material is textured but it has no " + key + ": the material's factors are used without textures");
        return {};
    }
    const std::string kp = pp + ".attributes." + key;
    const size_t ta = index(attrs[key], kp, array_of(doc_, "accessors").size(), "accessors");
    const std::string tap = at("accessors", ta);
    const json& acc = accessor(ta, tap);
    if (!acc.contains("type") || acc["type"] != "VEC2") fail(ErrorCode::kInvalidValue, tap, key + " must be a VEC2 accessor");
    if (count(acc, "count", tap, true, 0) != nv)
        fail(ErrorCode::kInvalidValue, tap, key + " must have as many elements as POSITION (" + std::to_string(nv) + ")");
    const std::uint64_t ct = count(acc, "componentType", tap, true, 0);
    if (acc.contains("normalized") && !acc["normalized"].is_boolean()) fail(ErrorCode::kInvalidValue, tap + ".normalized", "must be true or false");
    const bool normalized = acc.contains("normalized") && acc["normalized"].get<bool>();
    const std::uint64_t csize = ct == kFloat ? 4 : ct == kByte || ct == kUbyte ? 1 : ct == kShort || ct == kUshort ? 2 : 0;
    if (csize == 0 || (ct == kFloat && normalized))
        fail(ErrorCode::kUnsupported, tap, key + " must be FLOAT, or BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT (got componentType " +
                                               std::to_string(ct) + (normalized ? " normalized" : "") + ")");
    const View v = accessor_view(ta, nv, 2 * csize, tap);
    std::vector<std::array<float, 2>> uvs(nv);
    for (std::uint64_t i = 0; i < nv; ++i)
        for (int k = 0; k < 2; ++k) {
            const std::uint8_t* c = v.data + i * v.stride + csize * static_cast<std::uint64_t>(k);
            float x;
            if (ct == kFloat) {
                const std::uint32_t bits = le32(c);
                std::memcpy(&x, &bits, 4);
                if (!std::isfinite(x)) fail(ErrorCode::kInvalidValue, tap, key + " element " + std::to_string(i) + " is not finite");
            } else {
                // KHR_mesh_quantization: integers as they are, or normalized (glTF 2.0 spec 3.11).
                double q = 0;
                switch (ct) {
                    case kByte: q = normalized ? std::max(static_cast<std::int8_t>(c[0]) / 127.0, -1.0) : static_cast<std::int8_t>(c[0]); break;
                    case kUbyte: q = normalized ? c[0] / 255.0 : c[0]; break;
                    case kShort: {
                        const auto w = static_cast<std::int16_t>(static_cast<std::uint16_t>(c[0] | c[1] << 8));
                        q = normalized ? std::max(w / 32767.0, -1.0) : w;
                        break;
                    }
                    default: {
                        const std::uint16_t w = static_cast<std::uint16_t>(c[0] | c[1] << 8);
                        q = normalized ? w / 65535.0 : w;
                        break;
                    }
                }
                x = static_cast<float>(q);
            }
            uvs[i][static_cast<size_t>(k)] = x;
        }
    return uvs;
}

namespace {

int base64_value(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+' || c == '-') return 62;
    if (c == '/' || c == '_') return 63;
    return -1;
}

// sRGB transfer function decoded (IEC 61966-2-1), for 8-bit values: a table.
const float* srgb_table() {
    static const auto table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) {
            const double c = i / 255.0;
            t[static_cast<size_t>(i)] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table.data();
}

}  // namespace

// An image's encoded bytes: its bufferView, its data: URI, or the file its URI names beside the
// asset (confined to the asset's folder as buffers are; recorded for --depfile by read_file_bytes).
std::vector<std::uint8_t> Reader::image_bytes(size_t ii, const std::string& ip) {
    namespace fs = std::filesystem;
    const json& img = array_of(doc_, "images")[ii];
    if (!img.is_object()) fail(ErrorCode::kInvalidValue, ip, "must be an object");
    if (img.contains("bufferView")) {
        const size_t vi = index(img["bufferView"], ip + ".bufferView", array_of(doc_, "bufferViews").size(), "bufferViews");
        const std::span<const std::uint8_t> b = view_bytes(vi, at("bufferViews", vi));
        return {b.begin(), b.end()};
    }
    if (!img.contains("uri") || !img["uri"].is_string()) fail(ErrorCode::kInvalidValue, ip, "has neither a uri nor a bufferView");
    const std::string uri = img["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
        const size_t comma = uri.find(',');
        if (comma == std::string::npos || comma < 12 || uri.compare(comma - 7, 7, ";base64") != 0)
            fail(ErrorCode::kBadFormat, ip + ".uri", "a data: URI that is not base64");
        if (uri.size() - comma > gltf_limits_.max_buffer_bytes / 3 * 4 + 4)
            fail(ErrorCode::kTooLarge, ip + ".uri", "data: URI above the buffer limit of " + std::to_string(gltf_limits_.max_buffer_bytes) + " bytes");
        std::vector<std::uint8_t> out;
        out.reserve((uri.size() - comma) / 4 * 3);
        std::uint32_t acc = 0;
        int bits = 0;
        for (size_t i = comma + 1; i < uri.size() && uri[i] != '='; ++i) {
            const int v = base64_value(uri[i]);
            if (v < 0) fail(ErrorCode::kBadFormat, ip + ".uri", "the data: URI's base64 has a character that is not base64 at offset " + std::to_string(i));
            acc = (acc << 6) | static_cast<std::uint32_t>(v);
            bits += 6;
            if (bits >= 8) {
                bits -= 8;
                out.push_back(static_cast<std::uint8_t>((acc >> bits) & 0xFF));
            }
        }
        return out;
    }
    const fs::path user_dir = fs::path(path_).parent_path();
    std::error_code ec;
    const fs::path base = fs::weakly_canonical(user_dir.empty() ? fs::path(".") : user_dir, ec);
    if (ec) fail(ErrorCode::kIoError, ip + ".uri", "cannot resolve the asset's folder");
    if (const std::string why = gltf_detail::uri_problem(uri); !why.empty())
        fail(ErrorCode::kBadFormat, ip + ".uri", "image '" + uri + "' is not read: " + why);
    const fs::path file = fs::weakly_canonical(base / gltf_detail::uri_path(uri), ec);
    if (ec || !gltf_detail::inside(base, file)) fail(ErrorCode::kBadFormat, ip + ".uri", "image '" + uri + "' resolves outside the input's directory");
    if (!fs::is_regular_file(file, ec))
        fail(ErrorCode::kIoError, ip + ".uri", "referenced file '" + gltf_detail::uri_path(uri) + "' not found in " + base.string());
    auto bytes = read_file_bytes(gltf_detail::user_spelling(user_dir, base, file).string(), gltf_limits_.max_buffer_bytes);
    if (!bytes) throw Fail{make_error(bytes.error().code, path_ + ": " + ip + ".uri: " + bytes.error().message)};
    return std::move(bytes).value();
}

// The zhc texture of glTF texture `ti` (decoded once per colour space): its source image decoded
// with stb_image (PNG, JPEG, ...) after its size was checked against the texel limit, sRGB
// decoded to linear for colour (base colour, emissive) or kept linear (metallic-roughness); its
// sampler's wrap modes and magnification filter.
int Reader::texture_of(int ti, bool srgb) {
    if (auto it = texture_ids_.find({ti, srgb}); it != texture_ids_.end()) return it->second;
    const std::string tp = at("textures", static_cast<size_t>(ti));
    const json& t = array_of(doc_, "textures")[static_cast<size_t>(ti)];
    if (!t.is_object()) fail(ErrorCode::kInvalidValue, tp, "must be an object");
    if (!t.contains("source"))
        fail(ErrorCode::kUnsupported, tp + ".source", "missing (an image only an extension gives, such as KTX2 or WebP, is not decoded)");
    const size_t ii = index(t["source"], tp + ".source", array_of(doc_, "images").size(), "images");
    const std::string ip = at("images", ii);
    SceneTexture tex;
    tex.name = ip;
    if (t.contains("sampler")) {
        const size_t si = index(t["sampler"], tp + ".sampler", array_of(doc_, "samplers").size(), "samplers");
        const std::string sp = at("samplers", si);
        const json& smp = array_of(doc_, "samplers")[si];
        if (!smp.is_object()) fail(ErrorCode::kInvalidValue, sp, "must be an object");
        auto wrap = [&](const char* key) {
            const std::uint64_t w = count(smp, key, sp, false, 10497);
            if (w == 10497) return TextureWrap::kRepeat;
            if (w == 33071) return TextureWrap::kClamp;
            if (w == 33648) return TextureWrap::kMirror;
            fail(ErrorCode::kInvalidValue, sp + "." + key, "must be 33071, 33648 or 10497 (got " + std::to_string(w) + ")");
        };
        tex.wrap_s = wrap("wrapS");
        tex.wrap_t = wrap("wrapT");
        tex.nearest = count(smp, "magFilter", sp, false, 9729) == 9728;
    }
    const std::vector<std::uint8_t> bytes = image_bytes(ii, ip);
    if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) fail(ErrorCode::kTooLarge, ip, "image above 2 GiB");
    int w = 0, h = 0, n = 0;
    if (!stbi_info_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &n) || w <= 0 || h <= 0)
        fail(ErrorCode::kBadFormat, ip, std::string("image does not decode: ") + (stbi_failure_reason() ? stbi_failure_reason() : "unknown format"));
    const std::uint64_t texels = std::uint64_t(w) * std::uint64_t(h);
    if (texels > options_.limits.max_texels || texels_ + texels > options_.limits.max_texels)
        fail(ErrorCode::kTooLarge, ip, std::to_string(w) + " x " + std::to_string(h) + " texels take the textures over the limit of " +
                                           std::to_string(options_.limits.max_texels) + " texels");
    texels_ += texels;
    stbi_uc* px = stbi_load_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &n, 3);
    if (!px) fail(ErrorCode::kBadFormat, ip, std::string("image does not decode: ") + (stbi_failure_reason() ? stbi_failure_reason() : "unknown"));
    tex.width = static_cast<std::uint32_t>(w);
    tex.height = static_cast<std::uint32_t>(h);
    tex.texels.resize(static_cast<size_t>(texels) * 3);
    const float* lut = srgb_table();
    for (size_t i = 0; i < tex.texels.size(); ++i) tex.texels[i] = srgb ? lut[px[i]] : static_cast<float>(px[i] / 255.0);
    stbi_image_free(px);
    const int id = static_cast<int>(textures_.size());
    textures_.push_back(std::move(tex));
    texture_ids_[{ti, srgb}] = id;
    return id;
}

void Reader::decode_textures() {
    for (size_t i = 0; i < materials_.size(); ++i) {
        const MaterialTextures& mt = material_textures_[i];
        SceneMaterial& m = materials_[i];
        if (mt.base >= 0) m.base_texture = texture_of(mt.base, true);
        if (mt.metal_rough >= 0) m.metal_rough_texture = texture_of(mt.metal_rough, false);
        if (mt.emissive >= 0) m.emissive_texture = texture_of(mt.emissive, true);
    }
}

}  // namespace zhc::scene_gltf_detail
