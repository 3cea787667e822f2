// zhc/formats/scene/scene_gltf_reader.h — internal to formats/: the glTF scene reader shared by
// scene_gltf.cpp (node tree, default probes, the public entry points), scene_gltf_lights.cpp
// (KHR_lights_punctual, EXT_lights_image_based) and scene_gltf_geometry.cpp (mesh primitives as
// occluders: accessors, KHR_mesh_quantization, EXT_/KHR_meshopt_compression,
// KHR_draco_mesh_compression, EXT_mesh_gpu_instancing). glTF 2.0;
// the format as zhc reads it: formats/scene/scene_gltf.h, docs/scene.md.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "formats/io/le_bytes.h"
#include "formats/probes/gltf_probes.h"
#include "formats/scene/scene_gltf.h"

namespace zhc::scene_gltf_detail {

inline constexpr auto le32 = le::load32;

using json = nlohmann::json;

struct Fail {
    Error error;
};

// glTF -> zhc axes: (x, y, z)_zhc = (z, x, y)_glTF (inverse of gltf_probes' to_gltf).
inline Vec3 from_gltf(Vec3 v) { return {v.z, v.x, v.y}; }

// Column-major 4x4 as glTF stores it: m[c * 4 + r].
struct Mat4 {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    double at(int r, int c) const { return m[static_cast<size_t>(c * 4 + r)]; }
};
inline Mat4 mul(const Mat4& a, const Mat4& b) {
    Mat4 o;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a.at(r, k) * b.at(k, c);
            o.m[static_cast<size_t>(c * 4 + r)] = s;
        }
    return o;
}
inline Vec3 point(const Mat4& a, Vec3 p) {
    return {a.at(0, 0) * p.x + a.at(0, 1) * p.y + a.at(0, 2) * p.z + a.at(0, 3),
            a.at(1, 0) * p.x + a.at(1, 1) * p.y + a.at(1, 2) * p.z + a.at(1, 3),
            a.at(2, 0) * p.x + a.at(2, 1) * p.y + a.at(2, 2) * p.z + a.at(2, 3)};
}
inline Vec3 vector(const Mat4& a, Vec3 v) {
    return {a.at(0, 0) * v.x + a.at(0, 1) * v.y + a.at(0, 2) * v.z, a.at(1, 0) * v.x + a.at(1, 1) * v.y + a.at(1, 2) * v.z,
            a.at(2, 0) * v.x + a.at(2, 1) * v.y + a.at(2, 2) * v.z};
}
inline bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

inline constexpr int kByte = 5120, kUbyte = 5121, kShort = 5122, kUshort = 5123, kUint = 5125, kFloat = 5126;

struct LightDef {
    LightKind kind = LightKind::kPoint;
    std::string name;
    Rgb color{1, 1, 1};
    double intensity = 1;
    double inner = 0, outer = kPi / 4;
};

class Reader {
public:
    Reader(std::string path, const json& doc, const GltfRaw& raw, const SceneLoadOptions& options, const GltfLimits& gltf_limits)
        : path_(std::move(path)), doc_(doc), raw_(raw), options_(options), gltf_limits_(gltf_limits) {}

    [[noreturn]] void fail(ErrorCode code, const std::string& where, const std::string& what) const {
        throw Fail{make_error(code, path_ + ": " + (where.empty() ? "" : where + ": ") + what)};
    }
    static std::string at(const std::string& p, size_t i) { return p + "[" + std::to_string(i) + "]"; }

    double number(const json& j, const std::string& where) const {
        if (!j.is_number()) fail(ErrorCode::kInvalidValue, where, "must be a number (got " + std::string(j.type_name()) + ")");
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(ErrorCode::kInvalidValue, where, "must be finite");
        return v;
    }
    // A non-negative integer index below `size`.
    size_t index(const json& j, const std::string& where, size_t size, const char* what) const {
        if (!j.is_number_unsigned() || j.get<std::uint64_t>() >= size)
            fail(ErrorCode::kInvalidValue, where,
                 std::string("must be an index into ") + what + " (0.." + std::to_string(size) + "), got " + j.dump());
        return static_cast<size_t>(j.get<std::uint64_t>());
    }
    std::uint64_t count(const json& obj, const char* key, const std::string& where, bool required, std::uint64_t fallback) const {
        if (!obj.contains(key)) {
            if (required) fail(ErrorCode::kInvalidValue, where + "." + key, "missing required field");
            return fallback;
        }
        const json& j = obj[key];
        if (!j.is_number_unsigned()) fail(ErrorCode::kInvalidValue, where + "." + key, "must be a non-negative integer (got " + j.dump() + ")");
        return j.get<std::uint64_t>();
    }
    const json& array_of(const json& obj, const char* key) const {
        static const json empty = json::array();
        if (!obj.is_object() || !obj.contains(key)) return empty;
        if (!obj[key].is_array()) fail(ErrorCode::kInvalidValue, key, "must be an array");
        return obj[key];
    }
    std::vector<double> numbers(const json& j, const std::string& where, size_t n) const {
        if (!j.is_array() || j.size() != n) fail(ErrorCode::kInvalidValue, where, "must be an array of " + std::to_string(n) + " numbers");
        std::vector<double> v(n);
        for (size_t i = 0; i < n; ++i) v[i] = number(j[i], at(where, i));
        return v;
    }

    struct View {
        const std::uint8_t* data = nullptr;
        std::uint64_t length = 0, stride = 0;
    };
    // Triangles a primitive of `mode` with n elements yields (an upper bound for strips/fans).
    static std::uint64_t triangle_count(std::uint64_t mode, std::uint64_t n) { return mode == 4 ? n / 3 : n >= 3 ? n - 2 : 0; }

    // The instances a mesh node draws: the node's world matrix alone, or (EXT_mesh_gpu_instancing)
    // world x InstanceXform(i) for each of `count` instances, computed on demand from the
    // attribute accessors (never stored per instance).
    struct Instancing {
        Mat4 world;
        std::uint64_t count = 1;
        bool extension = false;
        std::string where;  // nodes[i].extensions.EXT_mesh_gpu_instancing
        View t, r, s;       // data == nullptr: attribute absent
        std::uint64_t r_type = 0;
    };

    // node tree (scene_gltf.cpp)
    Mat4 local_matrix(const json& n, const std::string& np) const;
    Mat4 trs_matrix(Vec3 t, const double q[4], Vec3 s, const std::string& where) const;
    void walk();

    // KHR_lights_punctual (scene_gltf_lights.cpp)
    void read_light_defs();
    void add_light(size_t li, const Mat4& world, const std::string& where);
    // EXT_lights_image_based (scene_gltf_lights.cpp): the environment the walked scene references
    // (its SH3 radiance in zhc axes, rotation applied, intensity kept apart), or none; a light
    // defined but not referenced leaves a note.
    std::optional<SceneEnvironment> image_based_light();

    // mesh primitives as occluders (scene_gltf_geometry.cpp)
    const json* meshopt_ext(const json& v, std::string* name) const;
    std::vector<std::uint8_t> decode_meshopt(const json& e, std::uint64_t v_len, const std::string& ep);
    std::span<const std::uint8_t> view_bytes(size_t vi, const std::string& vp);
    View accessor_view(size_t ai, std::uint64_t count, std::uint64_t elem, const std::string& ap);
    std::uint64_t count_field(const json& obj, const char* key, const std::string& where, std::uint64_t fallback) const;
    const json& accessor(size_t ai, const std::string& ap) const;
    std::vector<Vec3> read_positions(size_t pa, std::uint64_t nv);
    Vec3 transformed(const Mat4& world, Vec3 p, const std::string& where, std::uint64_t i);
    void add_triangles(const std::vector<Vec3>& verts, const std::vector<std::uint32_t>& idx, std::uint64_t mode);
    void add_instances(const std::vector<Vec3>& local, const std::vector<std::uint32_t>& idx, std::uint64_t mode,
                       const Instancing& inst, const std::string& where);
    void count_triangles(std::uint64_t t, std::uint64_t instances, const std::string& pp);
    void add_draco(const json& prim, const json& ext, const std::string& pp, std::uint64_t mode, const Instancing& inst);
    void add_mesh(size_t mi, const Instancing& inst);
    // POINTS/LINES primitives: their vertices widen the bounds (default probes), nothing occludes.
    void add_point_bounds(const json& prim, const std::string& pp, const Instancing& inst);
    // The primitive's material as a zhc SceneMaterial index (materials_), or kNoMaterial.
    std::uint32_t material_of(const json& prim, const std::string& pp);
    // A textured primitive's UVs (TEXCOORD_n of the material's texture set: FLOAT, or
    // (KHR_mesh_quantization) [UNSIGNED_]BYTE / SHORT, normalized or not), one per vertex; empty
    // (with a note) when it has none.
    std::vector<std::array<float, 2>> read_uvs(const json& prim, const std::string& pp, std::uint64_t nv);

    // Textures (scene_gltf_geometry.cpp): the glTF textures each zhc material references, decoded
    // by decode_textures (only when the bake traces reflected light) into textures_, whose
    // indices it then writes into materials_ (texture indices are materials_'s own: the caller
    // shifts nothing). `user_dir` is the asset's folder as named (external images resolve there).
    struct MaterialTextures {
        int base = -1, metal_rough = -1, emissive = -1;  // glTF texture indices
        std::uint64_t tex_coord = 0;
        bool any() const { return base >= 0 || metal_rough >= 0 || emissive >= 0; }
    };
    void decode_textures();
    int texture_of(int gltf_texture, bool srgb);
    std::vector<std::uint8_t> image_bytes(size_t ii, const std::string& ip);

    // EXT_mesh_gpu_instancing (scene_gltf_geometry.cpp)
    Instancing read_instancing(const json& e, const Mat4& world, const std::string& ep);
    Mat4 instance_world(const Instancing& inst, std::uint64_t i) const;

    std::vector<SceneLight> lights_;
    std::vector<Occluder> occluders_;
    std::vector<SceneMaterial> materials_;  // Occluder::material of occluders_ indexes these
    std::vector<MaterialTextures> material_textures_;  // per materials_ entry
    std::vector<SurfaceUv> surfaces_;       // textured triangles (Occluder::material kSurfaceBit | i)
    std::vector<SceneTexture> textures_;    // decoded (decode_textures)
    std::vector<std::string> notes_;  // what was read but is not baked, for the report
    std::optional<size_t> scene_;     // the scene walked (none: an asset without scenes)
    double lo_[3] = {INFINITY, INFINITY, INFINITY}, hi_[3] = {-INFINITY, -INFINITY, -INFINITY};

private:
    std::string path_;
    const json& doc_;
    const GltfRaw& raw_;
    const SceneLoadOptions& options_;
    const GltfLimits& gltf_limits_;
    std::vector<LightDef> defs_;
    std::uint64_t triangles_ = 0;
    std::map<size_t, std::uint32_t> material_ids_;  // glTF material -> materials_ index or kNoMaterial
    std::uint32_t current_material_ = kNoMaterial;  // of the primitive being added
    const std::vector<std::array<float, 2>>* current_uvs_ = nullptr;  // its UVs when textured
    std::map<std::pair<int, bool>, int> texture_ids_;  // (glTF texture, sRGB) -> textures_ index
    std::uint64_t texels_ = 0;                          // decoded so far (limit: max_texels)
    std::map<size_t, std::vector<std::uint8_t>> decoded_;  // meshopt-compressed views, decoded once
    std::uint64_t decoded_total_ = 0;
};

}  // namespace zhc::scene_gltf_detail
