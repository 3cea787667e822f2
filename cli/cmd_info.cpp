// zhc info FILE [--json]: describe any file zhc reads or writes (environment map, .zhp, JSON probe
// list, glTF, lightmap EXR, lightmap KTX2 / DDS planes) and other 2-D KTX2 / DDS textures' headers.
#include <nlohmann/json.hpp>

#include <cmath>
#include <optional>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "cli.h"
#include "json_output.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "formats/envmap/envmap.h"
#include "formats/envmap/envmap_cube.h"
#include "formats/lightmap/astc.h"
#include "formats/lightmap/dds.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"
#include "formats/io/file_io.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"
#include "formats/report/audit_inputs.h"
#include "formats/io/json_depth.h"
#include "formats/scene/scene_gltf.h"
#include "formats/scene/scene_json.h"

namespace zhc::cli {
namespace cmd_info {  // one namespace per verb file: the CLI is a unity build
namespace {

struct Options {
    std::string path;
    bool json = false;
    bool inputs = false;  // --inputs: FILE is a scene; list the files loading it reads
};

const char* layout_name(ProbeLayoutKind k) {
    switch (k) {
        case ProbeLayoutKind::kNone: return "none";
        case ProbeLayoutKind::kGrid: return "grid";
        case ProbeLayoutKind::kPositions: return "positions";
    }
    return "?";
}
const char* dc_name(DcFormat f) {
    switch (f) {
        case DcFormat::kR11G11B10F: return "r11g11b10f";
        case DcFormat::kRGB9E5: return "rgb9e5";
        case DcFormat::kHalf: return "half";
    }
    return "?";
}
const char* zonal_name(ZonalMapping m) {
    switch (m) {
        case ZonalMapping::kAffine: return "affine";
        case ZonalMapping::kZeroPreserving: return "zero";
        case ZonalMapping::kSymmetric: return "symmetric";
    }
    return "?";
}

// The axis a ZH3-style decoder expands the zonal term along: the entry's own when the table fixes
// it (zh3_channel_q16: per channel), else the stored parameter.
const char* axis_name(const Codec& codec, const CodecOptions& p) {
    if (codec.traits.zonal_axis == ZonalAxis::kPerChannel) return "channel";
    if (codec.traits.zonal_axis == ZonalAxis::kLuminance) return "luminance";
    return p.axis_mode == ZonalAxisMode::kLuminance ? "luminance" : "channel";
}

// The one-line summary of a stored set, made from the same fields info prints beside it (the
// storage parameters the entry uses, cli.h storage_options_used, the axis and the stored kind),
// so the two cannot disagree. A float entry's bytes do not depend on the quantiser parameters: its
// table summary, plus the kind when it stores irradiance.
std::string stored_summary(const Codec& codec, const CodecOptions& p) {
    std::string s;
    if (codec.packed) {
        const StorageOptionUse use = storage_options_used(codec);
        const char* layout = codec.packed->layout == PackedLayout::kZh3Q16   ? "zh3_q16"
                             : codec.packed->layout == PackedLayout::kSh3Q28 ? "sh3_q28"
                                                                             : "sh2_q";
        const std::string dc = p.dc_format == DcFormat::kR11G11B10F ? "R11G11B10F"
                               : p.dc_format == DcFormat::kRGB9E5   ? "RGB9E5"
                                                                    : "half-float";
        s = std::string(codec.name) + " (" + layout + " layout), " + std::to_string(codec.size_bytes) + " bytes: " + dc +
            " DC + " + std::to_string(p.bits) + "-bit " + (p.sqrt_encoding ? "square-root-encoded " : "") + "ratios";
        if (use.l2_bound) s += std::string(", ") + (p.l2_bound == L2Bound::kTight ? "tight" : "loose") + " L2 bound";
        if (use.zonal_mapping) s += std::string(", ") + zonal_name(p.zonal_mapping) + " zonal mapping";
        if (codec.traits.zonal_axis != ZonalAxis::kNone) s += std::string(", zonal axis ") + axis_name(codec, p);
    } else {
        s = std::string(codec.summary);
    }
    if (p.kind == StoredKind::kIrradiance) s += "; stored as irradiance";
    return s;
}

nlohmann::ordered_json layout_json(const ProbeLayout& l) {
    nlohmann::ordered_json j;
    j["type"] = layout_name(l.kind);
    if (l.kind == ProbeLayoutKind::kGrid) {
        j["origin"] = {l.grid.origin.x, l.grid.origin.y, l.grid.origin.z};
        j["spacing"] = {l.grid.spacing.x, l.grid.spacing.y, l.grid.spacing.z};
        j["counts"] = {l.grid.counts[0], l.grid.counts[1], l.grid.counts[2]};
    }
    return j;
}

// The per-probe leak data of a set (docs/zhp-container.md; docs/runtime.md "Cell planes"), or
// nothing when it has none.
std::optional<nlohmann::ordered_json> leak_json(const ProbeSet& set) {
    if (set.validity.empty() && set.visibility.empty() && set.planes.empty()) return std::nullopt;
    nlohmann::ordered_json leak;
    if (!set.validity.empty()) {
        std::uint64_t invalid = 0;
        for (std::uint8_t v : set.validity) invalid += v == 0;
        leak["invalid_probes"] = invalid;
    }
    if (!set.visibility.empty()) leak["visibility_masks"] = true;
    if (!set.planes.empty()) {
        std::uint64_t planes = 0, regions = 0;
        for (size_t i = 0; i < set.count; ++i) {
            const CellEntryKind kind = cell_entry_kind(&set.planes[5 * i]);
            planes += kind == CellEntryKind::kPlane;
            regions += kind == CellEntryKind::kRegion;
        }
        leak["cells_with_a_plane"] = planes;
        if (regions > 0) leak["cells_with_a_corner_region"] = regions;
    }
    leak["bytes_per_probe"] = (set.validity.empty() ? 0 : 1) + (set.visibility.empty() ? 0 : 1) + (set.planes.empty() ? 0 : 5);
    return leak;
}

// Mean radiance (DC / (2 sqrt(pi))) range over probes, and probes that decode to non-finite values.
void probe_stats(const std::vector<Sh3Radiance>& hub, nlohmann::ordered_json& j) {
    double lo = INFINITY, hi = -INFINITY;
    std::uint64_t non_finite = 0;
    const LuminanceWeights w;
    for (const Sh3Radiance& sh : hub) {
        bool finite = true;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(sh[i][k]);
        if (!finite) {
            ++non_finite;
            continue;
        }
        const double mean = luminance(sh[0], w) / (2.0 * std::sqrt(kPi));
        lo = std::min(lo, mean);
        hi = std::max(hi, mean);
    }
    if (lo <= hi) j["mean_radiance_luminance"] = {lo, hi};
    j["non_finite_probes"] = non_finite;
}

// A JSON document with an "asset" object is glTF, not a probe list.
bool is_exr(const std::vector<std::uint8_t>& b) { return b.size() >= 4 && b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01; }

// A KTX2 / DDS that is not a cube map: zhc's lightmap planes, or a texture zhc does not read.
bool is_2d_texture(const std::vector<std::uint8_t>& b) {
    return (is_ktx2(b) && !ktx2_declares_cube(b)) || (is_dds(b) && !dds_declares_cube(b));
}

// Describes a 2-D KTX2 / DDS: an IrradZ plane zhc's lightmap reader reads, else the header as it
// stands (a format or shape zhc does not read says so; a damaged plane is still an error).
Status describe_2d_texture(const std::vector<std::uint8_t>& b, const std::string& path, nlohmann::ordered_json& j) {
    const bool ktx = is_ktx2(b);
    const std::string container = ktx ? "KTX2" : "DDS";
    auto img = ktx ? decode_ktx2(b, path) : decode_dds(b, path);
    if (img) {
        const std::uint32_t vk = img->vk_format;
        j["type"] = "IrradZ lightmap texture (" + container + ", 2-D)";
        if (const auto a = astc::format_of_vk(vk)) {
            // ASTC targets: I_z as HDR, or as LDR on the log2 range of its key; d and w_a in one LDR texture.
            bool ldr_iz = false;
            for (const auto& kv : img->key_values) ldr_iz = ldr_iz || kv.key == lightmap_astc::kRangeKey;
            j["format"] = "ASTC_" + std::to_string(a->footprint.x) + "x" + std::to_string(a->footprint.y) +
                          (a->hdr ? "_SFLOAT" : "_UNORM");
            j["plane"] = a->hdr  ? "I_z: linear RGB irradiance at the normal"
                         : ldr_iz ? "I_z: log2 of the irradiance on the range of key zhc.iz_log2_range (LDR)"
                                  : "d and w_a: (u, v, w_a)";
        } else {
            j["format"] = vk == kVkFormatBc6hUfloat ? "BC6H_UFLOAT" : vk == kVkFormatBc5Unorm ? "BC5_UNORM" : "BC4_UNORM";
            j["plane"] = vk == kVkFormatBc6hUfloat ? "I_z: linear RGB irradiance at the normal"
                         : vk == kVkFormatBc5Unorm ? "d: direction, hemi-octahedral (u, v)"
                                                   : "w_a: weight in [0, 1]";
        }
        j["width"] = img->width;
        j["height"] = img->height;
        j["block_bytes"] = img->blocks.size();
        return Ok{};
    }
    if (img.error().code != ErrorCode::kUnsupported) return img.error();
    auto h = ktx ? describe_ktx2_header(b, path) : describe_dds_header(b, path);
    if (!h) return h.error();
    j["type"] = container + " texture (not a cube map; not an IrradZ plane)";
    j["format"] = h->format;
    j["width"] = h->width;
    j["height"] = h->height;
    j["depth"] = h->depth;
    j["layers"] = h->layers;
    j["faces"] = h->faces;
    j["levels"] = h->levels;
    if (ktx) j["supercompression"] = h->supercompression;
    // The lightmap reader's reason, without the path it starts with.
    std::string why = img.error().message;
    if (why.rfind(path + ": ", 0) == 0) why = why.substr(path.size() + 2);
    j["read_by_zhc"] = "no: 2-D textures are read as IrradZ lightmap planes only (environment maps are cube maps); " + why;
    return Ok{};
}

bool is_gltf_json(const std::vector<std::uint8_t>& bytes) {
    // Too deep for the parser: not sniffed here; the reader it goes to refuses it by the same scan.
    if (!check_json_depth(bytes, "")) return false;
    const auto doc = nlohmann::json::parse(bytes.begin(), bytes.end(), nullptr, false);
    return doc.is_object() && doc.contains("asset") && doc["asset"].is_object();
}

void print_json_or_text(const nlohmann::ordered_json& j, bool as_json) {
    if (as_json) {
        print_json("info", j);
        return;
    }
    for (auto it = j.begin(); it != j.end(); ++it) {
        if (it.value().is_string()) std::printf("%-24s %s\n", it.key().c_str(), it.value().get<std::string>().c_str());
        else std::printf("%-24s %s\n", it.key().c_str(), it.value().dump().c_str());
    }
}

// --inputs: the files `zhc bake FILE` reads to load the scene (the scene, its environment map,
// glTF buffers), found by loading it under a FileRecorder, in the order they are opened.
int run_inputs(const Options& o) {
    FileRecorder recorder;
    std::uint64_t file_bytes = 0;
    {
        ScopedFileRecording recording(&recorder);
        auto bytes = read_file_bytes(o.path, GltfLimits{}.max_file_bytes);
        if (!bytes) return report(bytes.error());
        file_bytes = bytes->size();
        SceneLoadOptions lo;
        lo.threads = resolve_threads(0);
        auto scene = is_gltf_path(o.path) ? parse_scene_gltf(*bytes, o.path, lo, GltfLimits{}, nullptr) : read_scene_file(o.path, lo);
        if (!scene) return report(scene.error());
    }
    nlohmann::ordered_json j;
    j["path"] = o.path;
    j["file_bytes"] = file_bytes;
    j["type"] = "scene inputs";
    j["inputs"] = recorder.inputs();
    if (o.json) {
        print_json("info", j);
    } else {
        for (const std::string& f : recorder.inputs()) std::printf("%s\n", f.c_str());
    }
    return kExitOk;
}

int run(const Options& o) {
    if (o.inputs) return run_inputs(o);
    auto bytes = read_file_bytes(o.path, std::uint64_t(2) << 30);
    if (!bytes) return report(bytes.error());
    nlohmann::ordered_json j;
    j["path"] = o.path;
    j["file_bytes"] = bytes->size();
    if (looks_like_probe_file(*bytes)) {
        ProbeFileInfo info;
        auto set = parse_probe_set(*bytes, o.path, {}, &info);
        if (!set) return report(set.error());
        const Codec* codec = set->codec();
        const CodecOptions& p = set->params;
        j["type"] = "zhp probe container";
        j["version"] = info.version;
        j["representation"] = set->representation;
        j["summary"] = stored_summary(*codec, p);
        j["probes"] = set->count;
        j["bytes_per_probe"] = codec->size_bytes;
        j["payload_bytes"] = set->payload.size();
        j["header_bytes"] = kProbeFileHeaderBytes;
        j["body_bytes"] = info.raw_body_bytes;
        j["stored_body_bytes"] = info.stored_body_bytes;
        j["compression"] = info.compressed ? "zstd" : "none";
        j["layout"] = layout_json(set->layout);
        j["kind"] = p.kind == StoredKind::kIrradiance ? "irradiance" : "radiance";
        PackedLayout packed;
        if (packed_layout_from_name(set->representation, &packed)) {
            j["bits"] = p.bits;
            j["sqrt"] = p.sqrt_encoding;
            j["l2_bound"] = p.l2_bound == L2Bound::kTight ? "tight" : "loose";
            j["dc_format"] = dc_name(p.dc_format);
            j["zonal_mapping"] = zonal_name(p.zonal_mapping);
            j["axis"] = axis_name(*codec, p);
        }
        j["luminance_weights"] = {p.luminance.r, p.luminance.g, p.luminance.b};
        if (auto leak = leak_json(*set)) j["leak_data"] = *leak;
        // Scattered probes: the Delaunay tetrahedra the runtimes interpolate in (docs/runtime.md "Scattered probes").
        if (!set->tetrahedra.empty()) j["tetrahedra"] = set->tetrahedra.size();
        auto hub = decode_probe_set(*set);
        if (!hub) return report(hub.error());
        probe_stats(*hub, j);
    } else if (is_2d_texture(*bytes)) {
        if (Status s = describe_2d_texture(*bytes, o.path, j); !s) return report(s.error());
    } else if (auto lm = is_exr(*bytes) ? describe_lightmap_exr(*bytes, o.path) : Result<LightmapExrSummary>(LightmapExrSummary{});
               lm && !lm->kind.empty()) {
        // zhc's lightmap EXRs (SH lightmaps, IrradZ planes); other EXRs are environment maps.
        j["type"] = lm->kind == "sh3"         ? "SH lightmap (OpenEXR, SH3 radiance per texel)"
                    : lm->kind == "linear-sh" ? "linear SH lightmap (OpenEXR, L0 + L1 radiance per texel)"
                                              : "IrradZ lightmap planes (OpenEXR, as lightmap decode writes)";
        j["width"] = lm->width;
        j["height"] = lm->height;
        j["pixel_type"] = lm->pixel_type;
        j["channels"] = lm->channels;
    } else if (looks_like_envmap(*bytes)) {
        // info describes a file with NaN/Inf pixels instead of refusing it: it counts them, and its
        // statistics read them as 0 (what --replace-non-finite does elsewhere).
        EnvmapInfo info;
        EnvmapReadOptions ro;
        ro.non_finite = NonFinitePolicy::kReplaceZero;
        auto img = read_envmap_memory(*bytes, o.path, ro, &info);
        if (!img) return report(img.error());
        j["type"] = "environment map (" + info.layout + ")";
        j["format"] = info.format;
        j["width"] = img->width;
        j["height"] = img->height;
        j["channels"] = info.channels;
        j["compression"] = info.compression;
        if (info.format == "openexr") {
            if (info.has_chromaticities) {
                // The attribute's floats at float precision (7 significant digits), not as doubles.
                auto xy = [&](int i) {
                    nlohmann::ordered_json p = nlohmann::ordered_json::array();
                    for (int k = 0; k < 2; ++k) {
                        char buf[32];
                        std::snprintf(buf, sizeof buf, "%.7g", double(info.chromaticities[static_cast<size_t>(2 * i + k)]));
                        p.push_back(std::strtod(buf, nullptr));
                    }
                    return p;
                };
                nlohmann::ordered_json cj;
                cj["red"] = xy(0);
                cj["green"] = xy(1);
                cj["blue"] = xy(2);
                cj["white"] = xy(3);
                j["chromaticities"] = cj;
            } else {
                j["chromaticities"] = "none (Rec. 709 / D65)";
            }
            j["colour_conversion"] = info.colour_conversion;
            j["data_window"] = info.data_window;
            j["display_window"] = info.display_window;
        }
        j["non_finite_pixels"] = info.non_finite_pixels;
        j["non_finite_values"] = info.replaced_non_finite;
        const Sh3Radiance sh = project_envmap(*img);
        probe_stats({sh}, j);
    } else if (looks_like_glb(*bytes) || (looks_like_json(*bytes) && is_gltf_json(*bytes))) {
        // glTF: the asset's outline and its ZHC_light_probes volumes.
        auto s = read_gltf_probes(*bytes, o.path);
        if (!s) return report(s.error());
        j["type"] = s->binary ? "glTF 2.0 binary (GLB)" : "glTF 2.0 (JSON)";
        j["generator"] = s->generator;
        j["meshes"] = s->meshes;
        j["materials"] = s->materials;
        j["nodes"] = s->nodes;
        j["buffers"] = s->buffers;
        j["extensions_used"] = s->extensions_used;
        j["extensions_required"] = s->extensions_required;
        nlohmann::ordered_json vols = nlohmann::ordered_json::array();
        for (const GltfProbeVolume& v : s->volumes) {
            nlohmann::ordered_json vj;
            vj["name"] = v.name;
            vj["encoding"] = v.set.representation;
            vj["probes"] = v.set.count;
            vj["kind"] = v.set.params.kind == StoredKind::kIrradiance ? "irradiance" : "radiance";
            vj["layout"] = layout_json(v.set.layout);  // converted back to zhc axes
            vj["sh_axes"] = v.sh_axes == GltfShAxes::kZhc ? "zhc" : "gltf";
            vj["payload"] = v.draco ? "draco point cloud" : "accessors";
            vj["stored_bytes"] = v.stored_bytes;
            if (auto leak = leak_json(v.set)) vj["leak_data"] = *leak;
            if (!v.set.tetrahedra.empty()) vj["tetrahedra"] = v.set.tetrahedra.size();
            vj["nodes"] = v.nodes;
            auto hub = decode_probe_set(v.set);
            if (!hub) return report(hub.error());
            probe_stats(*hub, vj);
            vols.push_back(vj);
        }
        j["volumes"] = vols;
    } else if (looks_like_json(*bytes)) {
        auto list = parse_probe_json(*bytes, o.path);
        if (!list) return report(list.error());
        j["type"] = "JSON probe list (float SH3 radiance)";
        j["probes"] = list->probes.size();
        j["layout"] = layout_json(list->layout);
        probe_stats(list->probes, j);
    } else {
        return report(unknown_probe_input(o.path, *bytes));
    }
    print_json_or_text(j, o.json);
    return kExitOk;
}

const VerbRegistration registration(45, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("info", "Describe an environment map, .zhp probe container, JSON probe list or glTF asset");
    sub->add_option("FILE", o->path, "file to describe (type detected from its content)")->required();
    add_json_flag(sub, o->json);
    sub->add_flag("--inputs", o->inputs,
                  "FILE is a scene (JSON or glTF): list every file loading it reads, one per line or as \"inputs\" "
                  "(for build rules that declare inputs; docs/build-integration.md)");
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_info
}  // namespace zhc::cli
