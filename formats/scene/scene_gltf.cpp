// zhc/formats/scene/scene_gltf.cpp — a lighting scene from a glTF 2.0 asset (formats/scene/scene_gltf.h,
// docs/scene.md "glTF input"): the node tree walked from the default scene (matrix or TRS, glTF 2.0
// spec 5.25), default probes over the bounds, `extras.zhc` merged as a zhc JSON scene. Lights:
// scene_gltf_lights.cpp (KHR_lights_punctual); meshes: scene_gltf_geometry.cpp; the shared reader
// class: scene_gltf_reader.h.
#include "formats/scene/scene_gltf.h"

#include <algorithm>
#include <filesystem>
#include <new>

#include "formats/io/file_io.h"
#include "formats/scene/scene_gltf_reader.h"

namespace zhc {
namespace scene_gltf_detail {

// ---- node tree -----------------------------------------------------------------------------

Mat4 Reader::local_matrix(const json& n, const std::string& np) const {
    Mat4 m;
    const bool trs = n.contains("translation") || n.contains("rotation") || n.contains("scale");
    if (n.contains("matrix")) {
        if (trs) fail(ErrorCode::kInvalidValue, np, "has both matrix and translation/rotation/scale");
        const auto v = numbers(n["matrix"], np + ".matrix", 16);
        for (size_t i = 0; i < 16; ++i) m.m[i] = v[i];
        return m;
    }
    Vec3 t{0, 0, 0}, s{1, 1, 1};
    double q[4] = {0, 0, 0, 1};
    if (n.contains("translation")) {
        const auto v = numbers(n["translation"], np + ".translation", 3);
        t = {v[0], v[1], v[2]};
    }
    if (n.contains("scale")) {
        const auto v = numbers(n["scale"], np + ".scale", 3);
        s = {v[0], v[1], v[2]};
    }
    if (n.contains("rotation")) {
        const auto v = numbers(n["rotation"], np + ".rotation", 4);
        for (int i = 0; i < 4; ++i) q[i] = v[static_cast<size_t>(i)];
    }
    return trs_matrix(t, q, s, np + ".rotation");
}

// M = T * R * S (glTF 2.0 spec, 5.25 node), R from the quaternion (x, y, z, w) normalised (glTF
// requires unit quaternions; this absorbs rounding and quantisation).
Mat4 Reader::trs_matrix(Vec3 t, const double q_in[4], Vec3 s, const std::string& where) const {
    const double len = std::sqrt(q_in[0] * q_in[0] + q_in[1] * q_in[1] + q_in[2] * q_in[2] + q_in[3] * q_in[3]);
    if (!(len > 0)) fail(ErrorCode::kInvalidValue, where, "must be a unit quaternion (got zero)");
    double q[4];
    for (int i = 0; i < 4; ++i) q[i] = q_in[i] / len;
    Mat4 m;
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int row = 0; row < 3; ++row) {
        for (int c = 0; c < 3; ++c) m.m[static_cast<size_t>(c * 4 + row)] = r[row][c] * s[c];
        m.m[static_cast<size_t>(12 + row)] = t[row];
    }
    return m;
}

void Reader::walk() {
    const json& nodes = array_of(doc_, "nodes");
    const json& scenes = array_of(doc_, "scenes");
    std::vector<char> seen(nodes.size(), 0);
    std::vector<std::pair<size_t, Mat4>> stack;
    if (scenes.empty() && !doc_.contains("scene")) {
        // No scene (legal: the asset is a library): every node that is no node's child is a
        // root, in index order.
        std::vector<char> child(nodes.size(), 0);
        for (size_t ni = 0; ni < nodes.size(); ++ni) {
            const json& n = nodes[ni];
            if (!n.is_object() || !n.contains("children")) continue;
            const std::string np = at("nodes", ni);
            if (!n["children"].is_array()) fail(ErrorCode::kInvalidValue, np + ".children", "must be an array");
            for (size_t i = 0; i < n["children"].size(); ++i) child[index(n["children"][i], at(np + ".children", i), nodes.size(), "nodes")] = 1;
        }
        for (size_t ni = 0; ni < nodes.size(); ++ni)
            if (!child[ni]) stack.push_back({ni, Mat4{}});
    } else {
        size_t scene = 0;
        if (doc_.contains("scene")) scene = index(doc_["scene"], "scene", scenes.size(), "scenes");
        scene_ = scene;
        const std::string sp = at("scenes", scene);
        const json& sc = scenes[scene];
        if (!sc.is_object()) fail(ErrorCode::kInvalidValue, sp, "must be an object");
        if (sc.contains("nodes")) {
            if (!sc["nodes"].is_array()) fail(ErrorCode::kInvalidValue, sp + ".nodes", "must be an array");
            for (size_t i = 0; i < sc["nodes"].size(); ++i)
                stack.push_back({index(sc["nodes"][i], at(sp + ".nodes", i), nodes.size(), "nodes"), Mat4{}});
        }
    }
    std::reverse(stack.begin(), stack.end());  // visit in document order
    while (!stack.empty()) {
        const auto [ni, parent] = stack.back();
        stack.pop_back();
        const std::string np = at("nodes", ni);
        // glTF node hierarchies are strict trees: a second visit is a cycle or a shared child.
        if (seen[ni]) fail(ErrorCode::kInvalidValue, np, "reached twice (a node has one parent; cycles are not allowed)");
        seen[ni] = 1;
        const json& n = nodes[ni];
        if (!n.is_object()) fail(ErrorCode::kInvalidValue, np, "must be an object");
        const Mat4 world = mul(parent, local_matrix(n, np));
        for (double v : world.m)
            if (!std::isfinite(v)) fail(ErrorCode::kInvalidValue, np, "world transform is not finite");
        if (n.contains("mesh")) {
            const size_t mi = index(n["mesh"], np + ".mesh", array_of(doc_, "meshes").size(), "meshes");
            // EXT_mesh_gpu_instancing: the mesh is drawn once per instance and not by itself.
            Instancing inst;
            inst.world = world;
            if (n.contains("extensions") && n["extensions"].is_object() && n["extensions"].contains("EXT_mesh_gpu_instancing"))
                inst = read_instancing(n["extensions"]["EXT_mesh_gpu_instancing"], world, np + ".extensions.EXT_mesh_gpu_instancing");
            add_mesh(mi, inst);
        }
        if (n.contains("extensions") && n["extensions"].is_object() && n["extensions"].contains("KHR_lights_punctual")) {
            const json& e = n["extensions"]["KHR_lights_punctual"];
            const std::string ep = np + ".extensions.KHR_lights_punctual.light";
            if (!e.is_object() || !e.contains("light")) fail(ErrorCode::kInvalidValue, ep, "missing");
            add_light(index(e["light"], ep, defs_.size(), "KHR_lights_punctual.lights"), world, ep);
        }
        if (n.contains("children")) {
            const json& ch = n["children"];
            if (!ch.is_array()) fail(ErrorCode::kInvalidValue, np + ".children", "must be an array");
            for (size_t i = ch.size(); i-- > 0;) stack.push_back({index(ch[i], at(np + ".children", i), nodes.size(), "nodes"), world});
        }
    }
}

// Default probes: an 8 x 8 x 8 grid of cell centres over the bounds of the meshes and the
// point/spot light positions (an axis of zero extent gets one probe in its middle); with neither,
// one probe at the origin.
json default_probes(const Reader& r) {
    double lo[3], hi[3];
    bool any = r.lo_[0] <= r.hi_[0];  // some mesh vertex (triangles, lines or points)
    for (int a = 0; a < 3; ++a) {
        lo[a] = r.lo_[a];
        hi[a] = r.hi_[a];
    }
    for (const SceneLight& l : r.lights_)
        if (l.kind == LightKind::kPoint || l.kind == LightKind::kSpot) {
            any = true;
            for (int a = 0; a < 3; ++a) {
                lo[a] = std::min(lo[a], l.position[a]);
                hi[a] = std::max(hi[a], l.position[a]);
            }
        }
    if (!any) return {{"positions", json::array({json::array({0.0, 0.0, 0.0})})}};
    json mn = json::array(), mx = json::array(), counts = json::array();
    constexpr int kCells = 8;
    for (int a = 0; a < 3; ++a) {
        const double ext = hi[a] - lo[a];
        if (ext > 0) {
            mn.push_back(lo[a] + ext / (2 * kCells));
            mx.push_back(hi[a] - ext / (2 * kCells));
            counts.push_back(kCells);
        } else {
            mn.push_back(lo[a]);
            mx.push_back(hi[a]);
            counts.push_back(1);
        }
    }
    return {{"grid", {{"min", mn}, {"max", mx}, {"counts", counts}}}};
}

}  // namespace scene_gltf_detail

namespace {

using namespace scene_gltf_detail;
namespace fs = std::filesystem;

Result<Scene> parse_unchecked(std::span<const std::uint8_t> bytes, const std::string& path, const SceneLoadOptions& options,
                              const GltfLimits& gltf_limits, std::vector<std::string>* notes) {
    auto raw = load_gltf_raw(bytes, path, gltf_limits);
    if (!raw) return raw.error();
    try {
        const json doc = json::parse(raw->json);
        Reader r(path, doc, *raw, options, gltf_limits);
        r.read_light_defs();
        r.walk();
        std::optional<SceneEnvironment> ibl = r.image_based_light();
        // extras.zhc: a zhc JSON scene (zhc axes) with optional version and probes.
        json extras = json::object();
        if (doc.contains("extras") && doc["extras"].is_object() && doc["extras"].contains("zhc")) extras = doc["extras"]["zhc"];
        if (!extras.is_object()) r.fail(ErrorCode::kInvalidValue, "extras.zhc", "must be an object (a zhc scene, docs/scene.md)");
        bool shadows = !r.occluders_.empty();
        if (extras.contains("gltf_light_shadows")) {
            if (!extras["gltf_light_shadows"].is_boolean()) r.fail(ErrorCode::kInvalidValue, "extras.zhc.gltf_light_shadows", "must be true or false");
            shadows = extras["gltf_light_shadows"].get<bool>();
            extras.erase("gltf_light_shadows");
        }
        // An environment or sky in extras.zhc is the asset's zhc-specific instruction: it wins over
        // an EXT_lights_image_based light, which is then not baked (and said so).
        if (ibl && (extras.contains("environment") || extras.contains("sky"))) {
            r.notes_.push_back(ibl->label + ": not used: extras.zhc." + (extras.contains("environment") ? "environment" : "sky") +
                               " gives the scene's environment");
            ibl.reset();
        }
        if (!extras.contains("version")) extras["version"] = 1;
        if (!extras.contains("probes")) {
            extras["probes"] = default_probes(r);
            const json& g = extras["probes"];
            if (g.contains("positions") || (g["grid"]["counts"] == json::array({1, 1, 1})))
                r.notes_.push_back("the default probe grid is a single probe: the meshes and point/spot lights span no volume "
                                   "(give extras.zhc.probes for a useful grid)");
        }
        const std::string text = extras.dump();
        std::string dir = fs::path(path).parent_path().string();
        // A glTF scene's environment map is in the glTF ecosystem's lat-long orientation unless
        // extras.zhc.environment.latlong says otherwise.
        SceneLoadOptions json_options = options;
        json_options.default_latlong = LatLongConvention::kGltf;
        auto scene = parse_scene_json(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()),
                                      path + ": extras.zhc", dir, json_options);
        if (!scene) return scene.error();
        Scene s = std::move(scene).value();
        if (s.lights.size() + r.lights_.size() > options.limits.max_lights)
            r.fail(ErrorCode::kTooLarge, "lights", "more than the limit of " + std::to_string(options.limits.max_lights) + " lights in all");
        for (SceneLight& l : r.lights_) {
            l.shadows = shadows;
            s.lights.push_back(std::move(l));
        }
        // The glTF materials follow extras.zhc's: their occluders' and surfaces' indices shift by
        // that many (a textured triangle's material is its surface's: kSurfaceBit).
        if (!s.materials.empty()) {
            for (Occluder& o : r.occluders_)
                if (o.material != kNoMaterial && !is_surface(o.material)) o.material += static_cast<std::uint32_t>(s.materials.size());
            for (SurfaceUv& u : r.surfaces_) u.material += static_cast<std::uint32_t>(s.materials.size());
        }
        const size_t first_gltf_material = s.materials.size();
        s.materials.insert(s.materials.end(), r.materials_.begin(), r.materials_.end());
        // Moved, not copied, when extras.zhc adds none: the mesh triangles are the bulk of the memory.
        if (s.occluders.empty()) s.occluders = std::move(r.occluders_);
        else s.occluders.insert(s.occluders.end(), r.occluders_.begin(), r.occluders_.end());
        std::vector<Occluder>().swap(r.occluders_);
        if (ibl) s.environment = std::move(ibl);
        // Textures are decoded only for a bake that traces reflected light; otherwise (and for
        // materials with no UVs) the factors alone stand and no image is read.
        // The decision sees the textures as present (a metallic-roughness texture can make a fully
        // metallic factor reflect), with no image read yet.
        s.surfaces = std::move(r.surfaces_);
        auto set_textures = [&](bool provisional) {
            for (size_t i = 0; i < r.materials_.size(); ++i) {
                SceneMaterial& m = s.materials[first_gltf_material + i];
                const Reader::MaterialTextures& mt = r.material_textures_[i];
                m.base_texture = provisional ? (mt.base >= 0 ? 0 : -1) : r.materials_[i].base_texture;
                m.metal_rough_texture = provisional ? (mt.metal_rough >= 0 ? 0 : -1) : r.materials_[i].metal_rough_texture;
                m.emissive_texture = provisional ? (mt.emissive >= 0 ? 0 : -1) : r.materials_[i].emissive_texture;
            }
        };
        set_textures(true);
        if (options.bounces >= 0) s.transport.max_bounces = options.bounces;
        if (!s.surfaces.empty() && scene_has_transport(s)) {
            r.decode_textures();
            set_textures(false);
            s.textures = std::move(r.textures_);
        } else {
            set_textures(false);  // none decoded: -1
            for (Occluder& o : s.occluders)
                if (is_surface(o.material)) o.material = s.surfaces[o.material & ~kSurfaceBit].material;
            std::vector<SurfaceUv>().swap(s.surfaces);
        }
        if (notes) *notes = r.notes_;
        if (Status v = validate_scene(s); !v) return make_error(v.error().code, path + ": " + v.error().message);
        if (Status b = check_ray_budget(s, options.limits, path); !b) return b.error();
        return s;
    } catch (const Fail& f) {
        return f.error;
    } catch (const json::exception& e) {
        return make_error(ErrorCode::kInvalidValue, path + ": " + e.what());
    } catch (const std::bad_alloc&) {
        return make_error(ErrorCode::kTooLarge, path + ": out of memory while reading the scene");
    }
}

}  // namespace

Result<Scene> parse_scene_gltf(std::span<const std::uint8_t> bytes, const std::string& path, const SceneLoadOptions& options,
                               const GltfLimits& gltf_limits, std::vector<std::string>* notes) {
    // Messages echo names and values from the asset (and tinygltf's text): keep them one line.
    if (notes) notes->clear();
    auto s = parse_unchecked(bytes, path, options, gltf_limits, notes);
    if (!s) return make_error(s.error().code, one_line_message(s.error().message));
    return s;
}

bool is_gltf_path(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".gltf" || ext == ".glb";
}

}  // namespace zhc
