// zhc/formats/engines/threejs_grid.cpp — three.js LightProbeGrid atlases as files a three.js app
// loads with its own loaders (docs/engine-files.md "three.js"): threejs_grid_ktx2 (the RGBA16F 3-D
// texture of the WebGPU LightProbeGrid, for KTX2Loader) and threejs_grid_exr (the RGBA32F atlas of
// LightProbeGridWebGL as a 2-D OpenEXR image, for EXRLoader).
//
// The atlas follows three.js r187: examples/jsm/lighting/LightProbeGridWebGL.js _ensureTextures
// and _repackProbes (WebGL; RGBA FloatType), examples/jsm/lighting/LightProbeGrid.js
// _ensureTextures (WebGPU; HalfFloatType): nx x ny x 7 (nz + 2) texels, x fastest, then y, then
// the slice; sub-volume t (t = 0..6) holds texel t of every probe in slices t (nz + 2) + 1 + z,
// with one padding slice at each end (slice t (nz + 2) copies data slice z = 0, slice
// t (nz + 2) + nz + 1 copies z = nz - 1). A probe's 7 texels are the bytes of the codec entries
// threejs_grid_half / threejs_grid_float (codec/probe/engine_layouts.cpp threejs_encode), whose
// irradiance is the shader's: src/renderers/shaders/ShaderChunk/lightprobes_pars_fragment.glsl.js
// getLightProbeGridIrradiance.
//
// Bounds: three.js's grid is axis-aligned, centred at its `position`, `width x height x depth`
// large, with one cell per probe and each probe at its cell's centre (LightProbeGridWebGL.js
// getProbePosition). zhc's grid (probe (i, j, k) at origin + (i, j, k) * spacing) in three.js's
// axes (EngineLayoutInfo::axes: (x, y, z) = (y, z, x) of zhc's) is therefore position =
// origin + spacing (n - 1) / 2, size = n spacing, resolution = n. Both forms travel in the file as
// JSON text: "zhc.volume" {"origin", "spacing", "counts"} and "threejs.LightProbeGrid"
// {"position", "size", "resolution", "boundingBox": {"min", "max"}}, all in three.js's axes (KTX2
// key/value entries; OpenEXR string header attributes). three.js r187 has no toJSON / fromJSON for
// the grid, so these are zhc's keys; runtime/web/zhc_threejs_grid.mjs reads them.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <exception>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "codec/probe/engine_layouts.h"
#include "formats/engines/engine_file_common.h"
#include "formats/engines/engine_files.h"
#include "formats/engines/ktx2_volume.h"
#include "formats/io/exr_memory.h"
#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"
#include "formats/io/le_bytes.h"

namespace zhc {

extern const EngineFile kThreejsGridExrFile;
extern const EngineFile kThreejsGridKtx2File;

namespace {

using namespace engine_file_detail;  // engine_file_common.h

// The most atlas texels a file may hold (reader and writer): 2^24 RGBA32F texels are 256 MiB.
constexpr std::uint64_t kMaxAtlasTexels = std::uint64_t(1) << 24;
// WebGL2's guaranteed MAX_3D_TEXTURE_SIZE: larger atlases load only where the GPU allows them.
constexpr std::uint64_t kWebgl2Min3dSize = 256;

// The grid as three.js holds it, in three.js's axes.
struct ThreeGrid {
    std::array<std::uint32_t, 3> counts{};
    std::array<double, 3> origin{}, spacing{};
    std::uint64_t depth() const { return 7 * (std::uint64_t(counts[2]) + 2); }
    std::uint64_t texels() const { return std::uint64_t(counts[0]) * counts[1] * depth(); }
};


std::array<double, 3> position_of(const ThreeGrid& g) {
    std::array<double, 3> p{};
    for (size_t r = 0; r < 3; ++r) p[r] = g.origin[r] + 0.5 * (double(g.counts[r]) - 1) * g.spacing[r];
    return p;
}
std::array<double, 3> size_of(const ThreeGrid& g) {
    std::array<double, 3> s{};
    for (size_t r = 0; r < 3; ++r) s[r] = double(g.counts[r]) * g.spacing[r];
    return s;
}

std::string volume_json(const ThreeGrid& g) {
    return std::string("{\"origin\":") + vec_json(g.origin) + ",\"spacing\":" + vec_json(g.spacing) + ",\"counts\":[" +
           std::to_string(g.counts[0]) + "," + std::to_string(g.counts[1]) + "," + std::to_string(g.counts[2]) + "]}";
}
std::string three_json(const ThreeGrid& g) {
    const auto p = position_of(g), s = size_of(g);
    std::array<double, 3> lo{}, hi{};
    for (size_t r = 0; r < 3; ++r) {
        lo[r] = p[r] - 0.5 * s[r];
        hi[r] = p[r] + 0.5 * s[r];
    }
    return std::string("{\"position\":") + vec_json(p) + ",\"size\":" + vec_json(s) + ",\"resolution\":[" +
           std::to_string(g.counts[0]) + "," + std::to_string(g.counts[1]) + "," + std::to_string(g.counts[2]) +
           "],\"boundingBox\":{\"min\":" + vec_json(lo) + ",\"max\":" + vec_json(hi) + "}}";
}

// ---- JSON bounds (engine_file_common.h reads the fields) -------------------------------------

// The grid from the file's two JSON texts, which must agree.
Result<ThreeGrid> parse_bounds(const std::string& volume, const std::string& three, const std::string& name) {
    const std::string vw = name + ": " + kVolumeKey, tw = name + ": " + kThreeKey;
    auto vj = parse_object(volume, vw);
    if (!vj) return vj.error();
    auto tj = parse_object(three, tw);
    if (!tj) return tj.error();
    ThreeGrid g;
    auto origin = json_vec3(*vj, "origin", vw);
    if (!origin) return origin.error();
    auto spacing = json_vec3(*vj, "spacing", vw);
    if (!spacing) return spacing.error();
    auto counts = json_counts(*vj, "counts", vw);
    if (!counts) return counts.error();
    g.origin = *origin;
    g.spacing = *spacing;
    g.counts = *counts;
    for (double s : g.spacing)
        if (!(s > 0)) return bad(ErrorCode::kInvalidValue, vw, "\"spacing\" must be > 0 (three.js's grid has a positive size)");
    auto position = json_vec3(*tj, "position", tw);
    if (!position) return position.error();
    auto size = json_vec3(*tj, "size", tw);
    if (!size) return size.error();
    auto resolution = json_counts(*tj, "resolution", tw);
    if (!resolution) return resolution.error();
    const auto box = tj->find("boundingBox");
    if (box == tj->end() || !box->is_object()) return bad(ErrorCode::kBadFormat, tw, "\"boundingBox\" must be an object {min, max}");
    auto lo = json_vec3(*box, "min", tw + " boundingBox");
    if (!lo) return lo.error();
    auto hi = json_vec3(*box, "max", tw + " boundingBox");
    if (!hi) return hi.error();
    if (*resolution != g.counts) return bad(ErrorCode::kBadFormat, name, std::string("\"resolution\" of ") + kThreeKey + " differs from \"counts\" of " + kVolumeKey);
    const auto p = position_of(g), s = size_of(g);
    for (size_t r = 0; r < 3; ++r) {
        const double scale = std::max({std::fabs(p[r]), s[r], 1e-30});
        if (!near((*position)[r], p[r], scale) || !near((*size)[r], s[r], scale) || !near((*lo)[r], p[r] - 0.5 * s[r], scale) ||
            !near((*hi)[r], p[r] + 0.5 * s[r], scale))
            return bad(ErrorCode::kBadFormat, name, std::string("the bounds of ") + kThreeKey + " disagree with " + kVolumeKey +
                                                        " on axis " + "xyz"[r] + " (position = origin + spacing (counts - 1) / 2, size = counts spacing)");
    }
    return g;
}

// ---- the atlas -------------------------------------------------------------------------------

// The atlas texels of a grid, `texel_bytes` bytes each (the codec entry's bytes of one texel).
struct Atlas {
    ThreeGrid grid;
    size_t texel_bytes = 0;
    std::vector<std::uint8_t> bytes;
    std::vector<std::string> notes;
};

size_t atlas_index(const ThreeGrid& g, std::uint64_t x, std::uint64_t y, std::uint64_t slice) {
    return static_cast<size_t>((slice * g.counts[1] + y) * g.counts[0] + x);
}

Result<Atlas> build_atlas(const EngineFileInput& in, std::string_view codec_name, std::string_view file_name) {
    const std::string name(file_name);
    const Codec* codec = find_codec(codec_name);
    const EngineLayoutInfo* info = find_engine_layout(codec_name);
    if (!codec || !info) return bad(ErrorCode::kInternal, name, "codec entry missing");
    if (in.layout.kind != ProbeLayoutKind::kGrid)
        return bad(ErrorCode::kInvalidArgument, name,
                   std::string("three.js's LightProbeGrid is a regular grid; these probes have a ") +
                       (in.layout.kind == ProbeLayoutKind::kPositions ? "positions (scattered)" : "position-less") +
                       " layout (bake a grid, or pick an engine file for scattered probes)");
    const ProbeGrid& zg = in.layout.grid;
    for (int c = 0; c < 3; ++c) {
        if (zg.counts[static_cast<size_t>(c)] < 1 || zg.counts[static_cast<size_t>(c)] > 65535)
            return bad(ErrorCode::kInvalidArgument, name, "grid counts must be in 1..65535");
        if (!std::isfinite(zg.origin[c]) || !(zg.spacing[c] > 0) || !std::isfinite(zg.spacing[c]))
            return bad(ErrorCode::kInvalidArgument, name, "grid origin must be finite and spacing > 0 (three.js's grid is axis-aligned with a positive size)");
    }
    const std::uint64_t count = std::uint64_t(zg.counts[0]) * zg.counts[1] * zg.counts[2];
    if (count != in.hub.size())
        return bad(ErrorCode::kInvalidArgument, name, "the grid holds " + std::to_string(count) + " probes, " + std::to_string(in.hub.size()) + " given");
    if (!in.validity.empty() && in.validity.size() != count)
        return bad(ErrorCode::kInvalidArgument, name, "validity must be empty or one byte per probe");

    Atlas a;
    const AxisMap m = axis_map(codec_name);
    for (size_t r = 0; r < 3; ++r) {
        const int c = m.col[r];
        const std::uint32_t n = zg.counts[static_cast<size_t>(c)];
        a.grid.counts[r] = n;
        a.grid.spacing[r] = zg.spacing[c];
        a.grid.origin[r] = m.sign[r] > 0 ? zg.origin[c] : -(zg.origin[c] + (double(n) - 1) * zg.spacing[c]);
    }
    const ThreeGrid& g = a.grid;
    if (g.texels() > kMaxAtlasTexels)
        return bad(ErrorCode::kInvalidArgument, name, "the atlas would hold " + std::to_string(g.texels()) + " texels, more than " + std::to_string(kMaxAtlasTexels));
    a.texel_bytes = codec->size_bytes / 7;
    a.bytes.assign(static_cast<size_t>(g.texels()) * a.texel_bytes, 0);

    const std::uint64_t nx = g.counts[0], ny = g.counts[1], nz = g.counts[2], padded = nz + 2;
    std::vector<std::uint8_t> probe(codec->size_bytes);
    const Codec* float_codec = find_codec("threejs_grid_float");
    const EngineLayoutInfo* float_info = find_engine_layout("threejs_grid_float");
    std::vector<std::uint8_t> unrounded(float_codec->size_bytes);
    double texels[kMaxEngineTexels];
    for (std::uint64_t i = 0; i < count; ++i) {
        const std::array<std::uint64_t, 3> zi = {i % zg.counts[0], (i / zg.counts[0]) % zg.counts[1], i / (std::uint64_t(zg.counts[0]) * zg.counts[1])};
        std::array<std::uint64_t, 3> ti{};
        for (size_t r = 0; r < 3; ++r) {
            const std::uint64_t k = zi[static_cast<size_t>(m.col[r])];
            ti[r] = m.sign[r] > 0 ? k : g.counts[r] - 1 - k;
        }
        // The values before rounding (float32): binary16 saturates at 65504 (pack_half), which
        // would darken the probe; such a probe is refused rather than written wrong.
        encode_probe(*float_codec, CodecOptions{}, in.hub[i], unrounded.data(), nullptr);
        float_info->texels(unrounded.data(), texels);
        for (int k = 0; k < float_info->texel_count; ++k)
            if (!std::isfinite(texels[k]) || (a.texel_bytes == 8 && std::fabs(texels[k]) > 65504))
                return bad(ErrorCode::kInvalidArgument, name, "probe " + std::to_string(i) + " does not fit the atlas's number format (" +
                                                                  (a.texel_bytes == 8 ? "binary16: |value| <= 65504" : "float32") + ")");
        encode_probe(*codec, CodecOptions{}, in.hub[i], probe.data(), nullptr);
        for (std::uint64_t t = 0; t < 7; ++t) {
            const std::uint8_t* src = probe.data() + t * a.texel_bytes;
            auto put = [&](std::uint64_t slice) {
                std::memcpy(a.bytes.data() + atlas_index(g, ti[0], ti[1], slice) * a.texel_bytes, src, a.texel_bytes);
            };
            put(t * padded + 1 + ti[2]);
            if (ti[2] == 0) put(t * padded);
            if (ti[2] == nz - 1) put(t * padded + nz + 1);
        }
    }
    const auto p = position_of(g), s = size_of(g);
    a.notes.push_back("three.js: a LightProbeGrid(" + num(s[0]) + ", " + num(s[1]) + ", " + num(s[2]) + ", " + std::to_string(nx) + ", " +
                      std::to_string(ny) + ", " + std::to_string(nz) + ") at position (" + num(p[0]) + ", " + num(p[1]) + ", " + num(p[2]) +
                      "), three.js's axes; atlas " + std::to_string(nx) + " x " + std::to_string(ny) + " x " + std::to_string(g.depth()) + " texels");
    if (std::max({nx, ny, g.depth()}) > kWebgl2Min3dSize)
        a.notes.push_back("the atlas is larger than 256 texels along an axis: WebGL2 guarantees 3-D textures up to 256 (MAX_3D_TEXTURE_SIZE)");
    if (!in.validity.empty()) {
        const auto invalid = std::count(in.validity.begin(), in.validity.end(), std::uint8_t{0});
        if (invalid > 0)
            a.notes.push_back(std::to_string(invalid) + " probes are marked invalid: three.js's grid has no validity (its filter blends every probe); they are written as given");
    }
    return a;
}

// The probes of an atlas read from a file: padding slices equal to the edge slices, sub-volume 6's
// alpha 0, every value finite; then each probe's 7 texels decoded by the codec entry.
Result<EngineFileProbes> probes_from_atlas(const Atlas& a, std::string_view codec_name, const std::string& name) {
    const Codec* codec = find_codec(codec_name);
    const EngineLayoutInfo* info = find_engine_layout(codec_name);
    const ThreeGrid& g = a.grid;
    const std::uint64_t nx = g.counts[0], ny = g.counts[1], nz = g.counts[2], padded = nz + 2;
    const size_t slice_bytes = static_cast<size_t>(nx * ny) * a.texel_bytes;
    for (std::uint64_t t = 0; t < 7; ++t) {
        const std::array<std::array<std::uint64_t, 2>, 2> pairs = {{{t * padded, t * padded + 1}, {t * padded + nz + 1, t * padded + nz}}};
        for (const auto& pr : pairs)
            if (std::memcmp(a.bytes.data() + pr[0] * slice_bytes, a.bytes.data() + pr[1] * slice_bytes, slice_bytes) != 0)
                return bad(ErrorCode::kBadFormat, name, "not a three.js LightProbeGrid atlas: padding slice " + std::to_string(pr[0]) + " of sub-volume " +
                                                            std::to_string(t) + " differs from its edge slice " + std::to_string(pr[1]));
    }
    const bool half = a.texel_bytes == 8;
    const size_t scalar = a.texel_bytes / 4;
    std::vector<std::uint8_t> probe(codec->size_bytes);
    double texels[kMaxEngineTexels];
    // Sub-volume 6's alpha is 0 in every texel three.js writes (its repack shader stores vec4(c8, 0)).
    for (std::uint64_t i = 0; i < nx * ny * padded; ++i) {
        const std::uint8_t* p = a.bytes.data() + (6 * nx * ny * padded + i) * a.texel_bytes + 3 * scalar;
        const double alpha = half ? double(unpack_half(le::load16(p))) : double(le::load_f32(p));
        if (alpha != 0)
            return bad(ErrorCode::kBadFormat, name, "not a three.js LightProbeGrid atlas: sub-volume 6's alpha is not 0 (texel " + std::to_string(i) + " of it)");
    }
    EngineFileProbes out;
    out.notes = a.notes;
    const AxisMap m = axis_map(codec_name);
    ProbeGrid zg;
    for (size_t r = 0; r < 3; ++r) {
        const size_t c = static_cast<size_t>(m.col[r]);
        zg.counts[c] = g.counts[r];
        const double sp = g.spacing[r], o = m.sign[r] > 0 ? g.origin[r] : -(g.origin[r] + (double(g.counts[r]) - 1) * sp);
        if (c == 0) zg.origin.x = o, zg.spacing.x = sp;
        if (c == 1) zg.origin.y = o, zg.spacing.y = sp;
        if (c == 2) zg.origin.z = o, zg.spacing.z = sp;
    }
    out.layout.kind = ProbeLayoutKind::kGrid;
    out.layout.grid = zg;
    const std::uint64_t count = nx * ny * nz;
    out.hub.resize(static_cast<size_t>(count));
    for (std::uint64_t i = 0; i < count; ++i) {
        const std::array<std::uint64_t, 3> zi = {i % zg.counts[0], (i / zg.counts[0]) % zg.counts[1], i / (std::uint64_t(zg.counts[0]) * zg.counts[1])};
        std::array<std::uint64_t, 3> ti{};
        for (size_t r = 0; r < 3; ++r) {
            const std::uint64_t k = zi[static_cast<size_t>(m.col[r])];
            ti[r] = m.sign[r] > 0 ? k : g.counts[r] - 1 - k;
        }
        for (std::uint64_t t = 0; t < 7; ++t)
            std::memcpy(probe.data() + t * a.texel_bytes, a.bytes.data() + atlas_index(g, ti[0], ti[1], t * padded + 1 + ti[2]) * a.texel_bytes,
                        a.texel_bytes);
        info->texels(probe.data(), texels);
        for (int k = 0; k < info->texel_count; ++k)
            if (!std::isfinite(texels[k]))
                return bad(ErrorCode::kInvalidValue, name, "probe at three.js grid index (" + std::to_string(ti[0]) + ", " + std::to_string(ti[1]) + ", " +
                                                               std::to_string(ti[2]) + ") holds a value that is not finite");
        out.hub[static_cast<size_t>(i)] = decode_probe(*codec, CodecOptions{}, probe.data());
    }
    return out;
}

// ---- sniffing: a key among a file's key/value data ---------------------------------------------

// Whether an OpenEXR file's first header has an attribute named `key` (bounded walk).
bool exr_has_attribute(std::span<const std::uint8_t> b, std::string_view key) {
    if (b.size() < 8 || !(b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01)) return false;
    size_t pos = 8;
    auto cstr = [&](std::string_view& s) {
        const size_t start = pos;
        while (pos < b.size() && b[pos] != 0 && pos - start < 256) ++pos;
        if (pos >= b.size() || b[pos] != 0) return false;
        s = std::string_view(reinterpret_cast<const char*>(b.data() + start), pos - start);
        ++pos;
        return true;
    };
    for (int attrs = 0; attrs < 4096; ++attrs) {
        std::string_view attr, type;
        if (!cstr(attr) || attr.empty() || !cstr(type) || pos + 4 > b.size()) return false;
        const std::uint32_t size = le::load32(b.data() + pos);
        pos += 4;
        if (attr == key) return true;
        if (size > b.size() - pos) return false;
        pos += size;
    }
    return false;
}

// ---- OpenEXR -----------------------------------------------------------------------------------

// An Imf::OStream into memory.
class VectorOStream final : public Imf::OStream {
public:
    VectorOStream() : Imf::OStream("memory") {}
    void write(const char c[], int n) override {
        if (n < 0) throw std::runtime_error("negative write");
        if (pos_ + static_cast<std::uint64_t>(n) > bytes.size()) bytes.resize(static_cast<size_t>(pos_) + static_cast<size_t>(n));
        std::memcpy(bytes.data() + pos_, c, static_cast<size_t>(n));
        pos_ += static_cast<std::uint64_t>(n);
    }
    std::uint64_t tellp() override { return pos_; }
    void seekp(std::uint64_t pos) override {
        pos_ = pos;
        if (pos_ > bytes.size()) bytes.resize(static_cast<size_t>(pos_));
    }
    std::vector<std::uint8_t> bytes;

private:
    std::uint64_t pos_ = 0;
};

// The EXR image: width nx, height ny * 7 (nz + 2), RGBA float32. Its rows run bottom to top: the
// image's bottom row is atlas row 0 (slice 0, y = 0), row y of slice s is image row
// (height - 1) - (s ny + y) counted from the top, because three.js's EXRLoader flips rows
// (EXRLoader.js: outLineOffset = (height - 1 - line) * outLineWidth): its data array is then the
// atlas texels in three.js's Data3DTexture order.
Result<EngineFileOutput> write_exr(const EngineFileInput& in) {
    auto atlas = build_atlas(in, "threejs_grid_float", kThreejsGridExrFile.name);
    if (!atlas) return atlas.error();
    const ThreeGrid& g = atlas->grid;
    const int w = static_cast<int>(g.counts[0]);
    const int h = static_cast<int>(std::uint64_t(g.counts[1]) * g.depth());
    std::vector<float> image(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
    for (int row = 0; row < h; ++row)
        for (size_t k = 0; k < static_cast<size_t>(w) * 4; ++k)
            image[static_cast<size_t>(row) * static_cast<size_t>(w) * 4 + k] =
                le::load_f32(atlas->bytes.data() + (static_cast<size_t>(h - 1 - row) * static_cast<size_t>(w) * 4 + k) * 4);
    VectorOStream stream;
    try {
        Imf::Header header(w, h);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const char* c : {"R", "G", "B", "A"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
        header.insert(kVolumeKey, Imf::StringAttribute(volume_json(g)));
        header.insert(kThreeKey, Imf::StringAttribute(three_json(g)));
        Imf::OutputFile file(stream, header, 0);
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(image.data());
        const size_t xs = 4 * sizeof(float), ys = xs * static_cast<size_t>(w);
        for (size_t c = 0; c < 4; ++c) fb.insert(std::string(1, "RGBA"[c]), Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.writePixels(h);
    } catch (const std::exception& e) {
        return bad(ErrorCode::kInternal, std::string(kThreejsGridExrFile.name), std::string("cannot write OpenEXR (") + e.what() + ")");
    }
    EngineFileOutput out;
    out.bytes = std::move(stream.bytes);
    out.notes = std::move(atlas->notes);
    out.notes.push_back("OpenEXR: load with EXRLoader().setDataType(THREE.FloatType); the image is the atlas's slices stacked bottom to top");
    return out;
}

bool sniff_exr(std::span<const std::uint8_t> b) { return exr_has_attribute(b, kThreeKey); }

Result<EngineFileProbes> read_exr(std::span<const std::uint8_t> b, const std::string& name) {
    if (b.size() < 4 || !(b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01))
        return bad(ErrorCode::kBadFormat, name, "not an OpenEXR file (bad magic at byte 0)" + git_lfs_hint(b));
    ExrLayout layout;
    auto check = [&](std::uint64_t w, std::uint64_t h) -> Status {
        if (w * h > kMaxAtlasTexels)
            return bad(ErrorCode::kTooLarge, name, std::to_string(w) + "x" + std::to_string(h) + " texels exceed the limit " + std::to_string(kMaxAtlasTexels));
        return Ok{};
    };
    if (Status s = validate_exr_header(b, name, check, &layout); !s) return s.error();
    if (layout.multipart || layout.single_tiled || layout.single_deep || layout.parts.size() != 1)
        return bad(ErrorCode::kUnsupported, name, "a three.js grid atlas is a single-part scanline OpenEXR image");
    auto end = exr_data_end(b, name, layout);
    if (!end) return end.error();
    if (*end != b.size())
        return bad(ErrorCode::kTrailingBytes, name, std::to_string(b.size() - *end) + " trailing bytes after the OpenEXR data (which ends at byte " + std::to_string(*end) + ")");
    try {
        Imf::Header::setMaxImageSize(1 << 20, 1 << 20);
        ExrMemoryStream stream(b, name);
        Imf::InputFile file(stream, 0);
        const Imf::Header& header = file.header();
        const Imath::Box2i dw = header.dataWindow();
        const std::int64_t w = std::int64_t(dw.max.x) - dw.min.x + 1, h = std::int64_t(dw.max.y) - dw.min.y + 1;
        const Imf::ChannelList& ch = header.channels();
        int channels = 0;
        for (auto it = ch.begin(); it != ch.end(); ++it, ++channels) {
            const std::string n = it.name();
            if (n != "R" && n != "G" && n != "B" && n != "A")
                return bad(ErrorCode::kBadFormat, name, "channel '" + n + "': a three.js grid atlas has channels R, G, B, A");
            if (it.channel().type != Imf::FLOAT || it.channel().xSampling != 1 || it.channel().ySampling != 1)
                return bad(ErrorCode::kUnsupported, name, "channel '" + n + "' is not full-resolution float32 (the atlas is RGBA32F)");
        }
        if (channels != 4) return bad(ErrorCode::kBadFormat, name, "a three.js grid atlas has channels R, G, B, A; this file has " + std::to_string(channels));
        const auto* vol = header.findTypedAttribute<Imf::StringAttribute>(kVolumeKey);
        const auto* three = header.findTypedAttribute<Imf::StringAttribute>(kThreeKey);
        if (!vol || !three)
            return bad(ErrorCode::kBadFormat, name, std::string("no '") + (vol ? kThreeKey : kVolumeKey) + "' string attribute: the grid's bounds are missing");
        auto grid = parse_bounds(vol->value(), three->value(), name);
        if (!grid) return grid.error();
        const ThreeGrid& g = *grid;
        if (std::uint64_t(w) != g.counts[0] || std::uint64_t(h) != std::uint64_t(g.counts[1]) * g.depth())
            return bad(ErrorCode::kBadFormat, name, "the image is " + std::to_string(w) + " x " + std::to_string(h) + "; counts " +
                                                        std::to_string(g.counts[0]) + " x " + std::to_string(g.counts[1]) + " x " + std::to_string(g.counts[2]) +
                                                        " make an atlas of " + std::to_string(g.counts[0]) + " x " +
                                                        std::to_string(std::uint64_t(g.counts[1]) * g.depth()) + " (x, y and 7 (nz + 2) slices stacked)");
        std::vector<float> image(static_cast<size_t>(w * h) * 4);
        Imf::FrameBuffer fb;
        const size_t xs = 4 * sizeof(float), ys = xs * static_cast<size_t>(w);
        char* base = reinterpret_cast<char*>(image.data()) - (static_cast<std::ptrdiff_t>(dw.min.x) * std::ptrdiff_t(xs) + static_cast<std::ptrdiff_t>(dw.min.y) * std::ptrdiff_t(ys));
        for (size_t c = 0; c < 4; ++c) fb.insert(std::string(1, "RGBA"[c]), Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        Atlas a;
        a.grid = g;
        a.texel_bytes = 16;
        a.bytes.resize(image.size() * 4);
        for (std::int64_t row = 0; row < h; ++row)
            for (size_t k = 0; k < static_cast<size_t>(w) * 4; ++k)
                le::store_f32(a.bytes.data() + (static_cast<size_t>(h - 1 - row) * static_cast<size_t>(w) * 4 + k) * 4,
                              image[static_cast<size_t>(row) * static_cast<size_t>(w) * 4 + k]);
        return probes_from_atlas(a, "threejs_grid_float", name);
    } catch (const std::exception& e) {
        std::string what = e.what();
        if (const auto nl = what.find('\n'); nl != std::string::npos) what.resize(nl);
        return bad(ErrorCode::kBadFormat, name, "cannot read OpenEXR (" + what + ")");
    }
}

// ---- KTX2 ---------------------------------------------------------------------------------------

// The atlas as a 3-D RGBA16F texture (formats/engines/ktx2_volume.h): width nx, height ny, depth
// 7 (nz + 2), texels in three.js's Data3DTexture order; KTX2Loader (examples/jsm/loaders/
// KTX2Loader.js createRawTexture) returns it as a Data3DTexture of HalfFloatType. The bounds are
// key/value entries, NUL-terminated UTF-8 text.
std::vector<std::uint8_t> text_value(const std::string& s) {
    std::vector<std::uint8_t> v(s.begin(), s.end());
    v.push_back(0);
    return v;
}

Result<EngineFileOutput> write_ktx2(const EngineFileInput& in) {
    auto atlas = build_atlas(in, "threejs_grid_half", kThreejsGridKtx2File.name);
    if (!atlas) return atlas.error();
    const ThreeGrid& g = atlas->grid;
    Ktx2Texture t;
    t.vk_format = kVkFormatR16g16b16a16Sfloat;
    t.width = g.counts[0];
    t.height = g.counts[1];
    t.depth = static_cast<std::uint32_t>(g.depth());
    t.texels = std::move(atlas->bytes);
    t.key_values.push_back({kThreeKey, text_value(three_json(g))});
    t.key_values.push_back({kVolumeKey, text_value(volume_json(g))});
    auto bytes = encode_ktx2_texture(t);
    if (!bytes) return bad(ErrorCode::kInternal, std::string(kThreejsGridKtx2File.name), bytes.error().message);
    EngineFileOutput out;
    out.bytes = std::move(*bytes);
    out.notes = std::move(atlas->notes);
    out.notes.push_back("KTX2: KTX2Loader returns a Data3DTexture (HalfFloatType, NearestFilter): give it to zhc_threejs_grid.mjs lightProbeGridFromTexture, which sets LinearFilter");
    return out;
}

bool sniff_ktx2(std::span<const std::uint8_t> b) {
    static const std::uint8_t magic[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    if (b.size() < 80 || std::memcmp(b.data(), magic, 12) != 0) return false;
    const std::uint64_t off = le::load32(b.data() + 56), len = le::load32(b.data() + 60);
    if (off + len > b.size()) return false;
    const std::string_view key = kThreeKey;
    for (std::uint64_t at = off; at + 4 <= off + len;) {
        const std::uint64_t n = le::load32(b.data() + at);
        if (n > off + len - at - 4) return false;
        const char* k = reinterpret_cast<const char*>(b.data() + at + 4);
        if (n > key.size() && std::memcmp(k, key.data(), key.size()) == 0 && k[key.size()] == 0) return true;
        at += 4 + (n + 3) / 4 * 4;
    }
    return false;
}

Result<EngineFileProbes> read_ktx2(std::span<const std::uint8_t> b, const std::string& name) {
    auto t = decode_ktx2_texture(b, name, kMaxAtlasTexels);
    if (!t) return t.error();
    if (t->vk_format != kVkFormatR16g16b16a16Sfloat)
        return bad(ErrorCode::kUnsupported, name, "vkFormat " + std::to_string(t->vk_format) + ": three.js's LightProbeGrid atlas is R16G16B16A16_SFLOAT (97)");
    if (t->depth == 0) return bad(ErrorCode::kBadFormat, name, "a 2-D texture: three.js's LightProbeGrid atlas is 3-D");
    const std::vector<std::uint8_t>* vol = nullptr;
    const std::vector<std::uint8_t>* three = nullptr;
    for (const auto& kv : t->key_values) {
        if (kv.key == kVolumeKey) vol = &kv.value;
        if (kv.key == kThreeKey) three = &kv.value;
    }
    if (!vol || !three) return bad(ErrorCode::kBadFormat, name, std::string("no '") + (vol ? kThreeKey : kVolumeKey) + "' key/value entry: the grid's bounds are missing");
    auto text = [](const std::vector<std::uint8_t>& v) {
        std::string s(v.begin(), v.end());
        if (!s.empty() && s.back() == '\0') s.pop_back();
        return s;
    };
    auto grid = parse_bounds(text(*vol), text(*three), name);
    if (!grid) return grid.error();
    const ThreeGrid& g = *grid;
    if (t->width != g.counts[0] || t->height != g.counts[1] || t->depth != g.depth())
        return bad(ErrorCode::kBadFormat, name, "the texture is " + std::to_string(t->width) + " x " + std::to_string(t->height) + " x " + std::to_string(t->depth) +
                                                    "; counts " + std::to_string(g.counts[0]) + " x " + std::to_string(g.counts[1]) + " x " + std::to_string(g.counts[2]) +
                                                    " make an atlas of " + std::to_string(g.counts[0]) + " x " + std::to_string(g.counts[1]) + " x " + std::to_string(g.depth()));
    Atlas a;
    a.grid = g;
    a.texel_bytes = 8;
    a.bytes = std::move(t->texels);
    return probes_from_atlas(a, "threejs_grid_half", name);
}

}  // namespace

const EngineFile kThreejsGridExrFile = {
    "threejs_grid_exr",
    "three.js LightProbeGridWebGL atlas (OpenEXR, RGBA32F, slices stacked)",
    ".exr",
    "threejs_grid_float",
    "three r187 examples/jsm/lighting/LightProbeGridWebGL.js _ensureTextures, _repackProbes; "
    "src/renderers/shaders/ShaderChunk/lightprobes_pars_fragment.glsl.js getLightProbeGridIrradiance; "
    "examples/jsm/loaders/EXRLoader.js (rows flipped on load)",
    sniff_exr,
    write_exr,
    read_exr,
};

const EngineFile kThreejsGridKtx2File = {
    "threejs_grid_ktx2",
    "three.js LightProbeGrid atlas (KTX2, RGBA16F 3-D texture)",
    ".ktx2",
    "threejs_grid_half",
    "three r187 examples/jsm/lighting/LightProbeGrid.js _ensureTextures, repackNode; "
    "examples/jsm/tsl/lighting/LightProbeGridNode.js evaluateGridIrradiance; "
    "examples/jsm/loaders/KTX2Loader.js createRawTexture (Data3DTexture)",
    sniff_ktx2,
    write_ktx2,
    read_ktx2,
};

}  // namespace zhc
