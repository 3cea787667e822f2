// Scene description parsing (formats/scene/scene_json.h) and baking (codec/bake/scene.h) from untrusted
// bytes. A successful parse must bake without crashing to exactly one probe per position, and
// write back to JSON that parses to a scene with the same probe count and lights.
#include <cstdint>
#include <cstdlib>

#include "codec/bake/scene.h"
#include "formats/scene/scene_json.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    zhc::SceneLoadOptions options;
    options.load_environment = false;  // no file access from fuzz input
    options.limits.max_file_bytes = 1 << 20;
    options.limits.max_probes = 1 << 10;
    options.limits.max_lights = 16;
    options.limits.max_occluders = 64;
    options.limits.max_shadow_samples = 64;
    options.limits.max_rays = 1 << 16;
    auto scene = zhc::parse_scene_json({data, size}, "fuzz-input", "", options);
    if (!scene) {
        if (scene.error().message.empty() || scene.error().message.find('\n') != std::string::npos) std::abort();  // one line
        return 0;
    }
    auto probes = zhc::bake_scene(*scene);
    if (!probes) std::abort();  // a parsed scene is a valid scene
    if (probes->size() != zhc::probe_positions(scene->probes).size()) std::abort();
    const std::string text = zhc::scene_json(*scene);
    auto back = zhc::parse_scene_json({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()}, "again", "", options);
    if (!back || back->lights.size() != scene->lights.size() || back->occluders.size() != scene->occluders.size())
        std::abort();
    return 0;
}
