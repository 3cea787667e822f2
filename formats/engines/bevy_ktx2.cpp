// zhc/formats/engines/bevy_ktx2.cpp — Bevy irradiance volumes as the KTX2 3-D textures Bevy's
// IrradianceVolume component loads (docs/engine-files.md "Bevy: bevy_irradiance_volume").
//
// The texture follows bevyengine/bevy crates/bevy_pbr/src/light_probe/irradiance_volume.wesl
// irradiance_volume_light and pcwalton/bevy-baked-gi Crates/export-blender-gi/src/main.rs
// update_irradiance_grid_upstream / upstream_buffer_index (the exporter Bevy's docs name):
//  * a volume of Rx x Ry x Rz voxels is a 3-D texture of Rx x 2Ry x 3Rz texels, x fastest;
//  * the face of voxel (x, y, z) on side s (negative = 0 for +, 1 for -) of axis a (0, 1, 2 = X,
//    Y, Z) is texel (x, y + negative Ry, z + a Rz). The shader takes the negative side at
//    t + Ry ("the bottom half of each cube slice is the negative part": neg_offset 0.5 where
//    N < 0), as the exporter writes it; irradiance_volume.rs's module docs state the halves the
//    other way round, and what Bevy renders is the shader's;
//  * a fragment at world position p reads unit_pos = light_from_world p (the inverse of the
//    entity's GlobalTransform), stp = clamp((unit_pos + 0.5) R, 0.5, R - 0.5), three filtered taps
//    (one per axis, in that axis's block, on the normal's side) weighted by N.x^2, N.y^2, N.z^2,
//    times the component's intensity. The entity's unit cube [-0.5, 0.5]^3 is the volume; voxel
//    centres sit at texel centres, (i + 0.5) / R - 0.5 of it.
// The exporter writes E5B9G9R9_UFLOAT_PACK32 (vkFormat 123), as does zhc: each voxel's six faces
// are then exactly the bytes of the codec entry bevy_ambient_cube (codec/probe/engine_layouts.cpp
// bevy_encode, faces +X, -X, +Y, -Y, +Z, -Z in Bevy's axes), so a file zhc writes reads back to
// round_trip_probes(hub, "bevy_ambient_cube") bit for bit. Bevy's loader (crates/bevy_image/src/
// ktx2.rs ktx2_format_to_texture_format) also takes R16G16B16A16_SFLOAT and R32G32B32A32_SFLOAT;
// zhc reads those too (alpha unused, as the shader's .rgb).
//
// Bounds: zhc's grid (probe (i, j, k) at origin + (i, j, k) spacing) in Bevy's axes
// (EngineLayoutInfo::axes of bevy_ambient_cube: (x, y, z) = (y, z, x) of zhc's, Y up,
// right-handed) has its probes at the voxel centres when the entity's Transform has translation
// origin + spacing (n - 1) / 2, scale n spacing and no rotation. The file carries both as JSON in
// KTX2 key/value data, in Bevy's axes: "zhc.volume" {"origin", "spacing", "counts"} (as zhc's other
// KTX2 volumes) and "bevy.IrradianceVolume" {"translation", "scale", "resolution"}. Bevy reads
// neither (the Transform is the user's to set: the writer's note prints it); zhc's reader takes the
// grid from them, and from a file without them (the exporter's) the unit cube centred at the
// origin, stated in a note.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "codec/probe/engine_layouts.h"
#include "codec/probe/quantize.h"
#include "formats/engines/engine_file_common.h"
#include "formats/engines/engine_files.h"
#include "formats/engines/ktx2_volume.h"
#include "formats/io/json_depth.h"
#include "formats/io/le_bytes.h"

namespace zhc {

extern const EngineFile kBevyIrradianceVolumeFile;

namespace {

using namespace engine_file_detail;  // engine_file_common.h

constexpr const char* kCodecName = "bevy_ambient_cube";
constexpr const char* kBevyKey = "bevy.IrradianceVolume";
// At most 2^24 voxels: 6 2^24 texels, within decode_ktx2_texture's default limit of 2^28.
constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 24;
// wgpu's default Limits::max_texture_dimension_3d (Bevy's default WgpuSettings).
constexpr std::uint64_t kWgpuDefaultMax3d = 2048;
// The largest value RGB9E5 holds: (511 / 512) 2^16 (EXT_texture_shared_exponent).
constexpr double kRgb9e5Max = 65408.0;

// The grid in Bevy's axes: voxel (x, y, z) at origin + (x, y, z) spacing.
struct BevyGrid {
    std::array<std::uint32_t, 3> counts{};
    std::array<double, 3> origin{}, spacing{};
    std::uint64_t voxels() const { return std::uint64_t(counts[0]) * counts[1] * counts[2]; }
};

// Three values joined as "<open>a<sep>b<sep>c<close>" (appended piecewise: g++ 12 -O3 warns of a
// false overlap in "[" + std::string).
template <class T>
std::string join3(const std::array<T, 3>& v, const char* open, const char* sep, const char* close) {
    std::string s = open;
    for (std::size_t i = 0; i < 3; ++i) {
        if (i) s += sep;
        if constexpr (std::is_floating_point_v<T>)
            s += num(v[i]);
        else
            s += std::to_string(v[i]);
    }
    s += close;
    return s;
}

// The entity's Transform: translation = the volume's centre, scale = its size.
std::array<double, 3> translation_of(const BevyGrid& g) {
    std::array<double, 3> t{};
    for (size_t r = 0; r < 3; ++r) t[r] = g.origin[r] + 0.5 * (double(g.counts[r]) - 1) * g.spacing[r];
    return t;
}
std::array<double, 3> scale_of(const BevyGrid& g) {
    std::array<double, 3> s{};
    for (size_t r = 0; r < 3; ++r) s[r] = double(g.counts[r]) * g.spacing[r];
    return s;
}

// Zhc's probe index <-> Bevy's voxel (x, y, z).
std::array<std::uint64_t, 3> voxel_of(std::uint64_t i, const ProbeGrid& zg, const BevyGrid& g, const AxisMap& m) {
    const std::array<std::uint64_t, 3> zi = {i % zg.counts[0], (i / zg.counts[0]) % zg.counts[1],
                                             i / (std::uint64_t(zg.counts[0]) * zg.counts[1])};
    std::array<std::uint64_t, 3> v{};
    for (size_t r = 0; r < 3; ++r) {
        const std::uint64_t k = zi[static_cast<size_t>(m.col[r])];
        v[r] = m.sign[r] > 0 ? k : g.counts[r] - 1 - k;
    }
    return v;
}

// The texel of face f (0..5: +X, -X, +Y, -Y, +Z, -Z) of voxel v.
std::uint64_t texel_index(const BevyGrid& g, const std::array<std::uint64_t, 3>& v, int f) {
    const std::uint64_t nx = g.counts[0], ny = g.counts[1], nz = g.counts[2];
    const std::uint64_t axis = static_cast<std::uint64_t>(f / 2), negative = static_cast<std::uint64_t>(f % 2);
    const std::uint64_t x = v[0], y = v[1] + negative * ny, z = v[2] + axis * nz;
    return (z * 2 * ny + y) * nx + x;
}

constexpr const char* kFaceNames[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};

// ---- writing ---------------------------------------------------------------------------------

Result<EngineFileOutput> bevy_write(const EngineFileInput& in) {
    const std::string name = "bevy_irradiance_volume";
    const Codec* codec = find_codec(kCodecName);
    const EngineLayoutInfo* info = find_engine_layout(kCodecName);
    if (!codec || !info || codec->size_bytes != 24) return bad(ErrorCode::kInternal, name, "codec entry bevy_ambient_cube missing");
    if (in.layout.kind != ProbeLayoutKind::kGrid)
        return bad(ErrorCode::kInvalidArgument, name,
                   std::string("Bevy's irradiance volumes are regular grids of voxels; these probes have a ") +
                       (in.layout.kind == ProbeLayoutKind::kPositions ? "positions (scattered)" : "position-less") +
                       " layout (bake a grid, or pick an engine file for scattered probes)");
    const ProbeGrid& zg = in.layout.grid;
    for (int c = 0; c < 3; ++c) {
        if (zg.counts[static_cast<size_t>(c)] < 1 || zg.counts[static_cast<size_t>(c)] > 65535)
            return bad(ErrorCode::kInvalidArgument, name, "grid counts must be in 1..65535");
        if (!std::isfinite(zg.origin[c]) || !(zg.spacing[c] > 0) || !std::isfinite(zg.spacing[c]))
            return bad(ErrorCode::kInvalidArgument, name,
                       "grid origin must be finite and spacing > 0 (a Bevy volume is its entity's scaled unit cube)");
    }
    const std::uint64_t count = std::uint64_t(zg.counts[0]) * zg.counts[1] * zg.counts[2];
    if (count != in.hub.size())
        return bad(ErrorCode::kInvalidArgument, name,
                   "the grid holds " + std::to_string(count) + " probes, " + std::to_string(in.hub.size()) + " given");
    if (count > kMaxVoxels)
        return bad(ErrorCode::kInvalidArgument, name, "the volume would hold " + std::to_string(count) + " voxels, more than " + std::to_string(kMaxVoxels));
    if (!in.validity.empty() && in.validity.size() != count)
        return bad(ErrorCode::kInvalidArgument, name, "validity must be empty or one byte per probe");

    const AxisMap m = axis_map(kCodecName);
    BevyGrid g;
    for (size_t r = 0; r < 3; ++r) {
        const int c = m.col[r];
        const std::uint32_t n = zg.counts[static_cast<size_t>(c)];
        g.counts[r] = n;
        g.spacing[r] = zg.spacing[c];
        g.origin[r] = m.sign[r] > 0 ? zg.origin[c] : -(zg.origin[c] + (double(n) - 1) * zg.spacing[c]);
    }
    Ktx2Texture tex;
    tex.vk_format = kVkFormatE5b9g9r9UfloatPack32;
    tex.width = g.counts[0];
    tex.height = 2 * g.counts[1];
    tex.depth = 3 * g.counts[2];
    tex.texels.assign(static_cast<size_t>(6 * count * 4), 0);
    const Mat3 back = transpose(info->axes);
    std::uint64_t negative_faces = 0;
    std::uint8_t probe[24];
    for (std::uint64_t i = 0; i < count; ++i) {
        const Sh3Radiance& h = in.hub[static_cast<size_t>(i)];
        for (int k = 0; k < 9; ++k)
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(h[k][c])) return bad(ErrorCode::kInvalidArgument, name, "probe " + std::to_string(i) + " is not finite");
        // The faces' irradiance (what bevy_encode stores): RGB9E5 holds [0, 65408].
        for (int f = 0; f < 6; ++f) {
            const double s = f % 2 == 0 ? 1.0 : -1.0;
            const Vec3 d = f / 2 == 0 ? Vec3{s, 0, 0} : (f / 2 == 1 ? Vec3{0, s, 0} : Vec3{0, 0, s});
            const Rgb e = irradiance(h, back * d);
            for (int c = 0; c < 3; ++c) {
                if (e[c] > kRgb9e5Max)
                    return bad(ErrorCode::kInvalidArgument, name, "probe " + std::to_string(i) + ": face " + kFaceNames[f] + " irradiance " +
                                                                      num(e[c]) + " exceeds RGB9E5's largest value 65408 (scale the bake down)");
                if (e[c] < 0) ++negative_faces;
            }
        }
        encode_probe(*codec, CodecOptions{}, h, probe, nullptr);
        const auto v = voxel_of(i, zg, g, m);
        for (int f = 0; f < 6; ++f)
            std::memcpy(tex.texels.data() + texel_index(g, v, f) * 4, probe + 4 * f, 4);
    }
    const auto t = translation_of(g), s = scale_of(g);
    const std::string volume = "{\"origin\":" + vec_json(g.origin) + ",\"spacing\":" + vec_json(g.spacing) +
                               ",\"counts\":" + vec_json(g.counts) + "}";
    const std::string bevy = "{\"translation\":" + vec_json(t) + ",\"scale\":" + vec_json(s) + ",\"resolution\":" + vec_json(g.counts) + "}";
    tex.key_values = {{kVolumeKey, std::vector<std::uint8_t>(volume.begin(), volume.end())},
                      {kBevyKey, std::vector<std::uint8_t>(bevy.begin(), bevy.end())}};
    auto bytes = encode_ktx2_texture(tex);
    if (!bytes) return bytes.error();
    EngineFileOutput out;
    out.bytes = std::move(*bytes);
    out.notes.push_back("Bevy: spawn the volume with IrradianceVolume { voxels: <this file>, intensity: 1.0, .. } and "
                        "Transform::from_translation(Vec3::new(" + num(t[0]) + ", " + num(t[1]) + ", " + num(t[2]) +
                        ")).with_scale(Vec3::new(" + num(s[0]) + ", " + num(s[1]) + ", " + num(s[2]) +
                        ")) (Bevy's axes: Y up, right-handed; no rotation); " + std::to_string(g.counts[0]) + " x " +
                        std::to_string(g.counts[1]) + " x " + std::to_string(g.counts[2]) + " voxels, texture " +
                        std::to_string(tex.width) + " x " + std::to_string(tex.height) + " x " + std::to_string(tex.depth));
    if (std::max({std::uint64_t(tex.width), std::uint64_t(tex.height), std::uint64_t(tex.depth)}) > kWgpuDefaultMax3d)
        out.notes.push_back("the texture is larger than 2048 texels along an axis: wgpu's default max_texture_dimension_3d is 2048");
    if (negative_faces > 0)
        out.notes.push_back(std::to_string(negative_faces) + " face colour channels of negative irradiance are written as 0 (RGB9E5 is unsigned)");
    if (!in.validity.empty()) {
        const auto invalid = std::count(in.validity.begin(), in.validity.end(), std::uint8_t{0});
        if (invalid > 0)
            out.notes.push_back(std::to_string(invalid) + " probes are marked invalid: Bevy's volumes have no validity (its filter "
                                                          "blends every voxel); they are written as given");
    }
    return out;
}

// ---- reading ---------------------------------------------------------------------------------

// A key's value as a JSON object (a NUL-terminated value, which KTX2 3.11 allows, too).
Result<nlohmann::json> parse_value(const std::vector<std::uint8_t>& value, const std::string& where) {
    std::string text(value.begin(), value.end());
    if (!text.empty() && text.back() == '\0') text.pop_back();
    return parse_object(text, where);
}

// The grid of a volume of resolution `res` from the file's keys (either or both; they must agree),
// or the unit cube centred at the origin.
Result<BevyGrid> grid_from_keys(const Ktx2Texture& t, const std::array<std::uint32_t, 3>& res, const std::string& name,
                                std::vector<std::string>& notes) {
    const Ktx2KeyValue *volume = nullptr, *bevy = nullptr;
    for (const auto& e : t.key_values) {
        if (e.key == kVolumeKey) volume = &e;
        if (e.key == kBevyKey) bevy = &e;
    }
    BevyGrid g;
    g.counts = res;
    const std::string dims = join3(res, "(", ", ", ")");
    if (volume) {
        const std::string where = name + ": " + kVolumeKey;
        auto j = parse_value(volume->value, where);
        if (!j) return j.error();
        auto origin = json_vec3(*j, "origin", where);
        if (!origin) return origin.error();
        auto spacing = json_vec3(*j, "spacing", where);
        if (!spacing) return spacing.error();
        auto counts = json_counts(*j, "counts", where);
        if (!counts) return counts.error();
        for (double s : *spacing)
            if (!(s > 0)) return bad(ErrorCode::kInvalidValue, where, "\"spacing\" must be > 0");
        if (*counts != res)
            return bad(ErrorCode::kBadFormat, where, "\"counts\" differ from the texture's voxels " + dims + " (its size / (1, 2, 3))");
        g.origin = *origin;
        g.spacing = *spacing;
    }
    if (bevy) {
        const std::string where = name + ": " + kBevyKey;
        auto j = parse_value(bevy->value, where);
        if (!j) return j.error();
        auto translation = json_vec3(*j, "translation", where);
        if (!translation) return translation.error();
        auto scale = json_vec3(*j, "scale", where);
        if (!scale) return scale.error();
        auto resolution = json_counts(*j, "resolution", where);
        if (!resolution) return resolution.error();
        for (double s : *scale)
            if (!(s > 0)) return bad(ErrorCode::kInvalidValue, where, "\"scale\" must be > 0");
        if (*resolution != res)
            return bad(ErrorCode::kBadFormat, where, "\"resolution\" differs from the texture's voxels " + dims + " (its size / (1, 2, 3))");
        if (volume) {
            const auto tt = translation_of(g), ts = scale_of(g);
            for (size_t r = 0; r < 3; ++r) {
                const double sc = std::max({std::fabs(tt[r]), ts[r], 1e-30});
                if (!near((*translation)[r], tt[r], sc) || !near((*scale)[r], ts[r], sc))
                    return bad(ErrorCode::kBadFormat, name, std::string("the transform of ") + kBevyKey + " disagrees with " + kVolumeKey +
                                                                " on axis " + "xyz"[r] + " (translation = origin + spacing (counts - 1) / 2, scale = counts spacing)");
            }
        } else {
            for (size_t r = 0; r < 3; ++r) {
                g.spacing[r] = (*scale)[r] / res[r];
                g.origin[r] = (*translation)[r] - 0.5 * (*scale)[r] + 0.5 * g.spacing[r];
            }
        }
    }
    if (!volume && !bevy) {
        for (size_t r = 0; r < 3; ++r) {
            g.spacing[r] = 1.0 / res[r];
            g.origin[r] = -0.5 + 0.5 * g.spacing[r];
        }
        notes.push_back("the file holds no bounds (no zhc.volume or bevy.IrradianceVolume key): the volume is taken as the unit cube centred at the origin, "
                        "as Bevy places it under an identity Transform (give the entity's Transform to place it)");
    }
    return g;
}

bool is_ktx2(std::span<const std::uint8_t> b) {
    static constexpr std::uint8_t kId[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    return b.size() >= 104 && std::memcmp(b.data(), kId, 12) == 0;
}

// Whether the key/value data names `key` (a bounded walk of the entries; false on any doubt).
bool ktx2_has_key(std::span<const std::uint8_t> b, std::string_view key) {
    const std::uint64_t off = le::get32(b, 56), len = le::get32(b, 60);
    if (len == 0 || off + len > b.size()) return false;
    std::uint64_t at = off;
    while (at + 4 <= off + len) {
        const std::uint64_t n = le::get32(b, static_cast<size_t>(at));
        if (n > off + len - at - 4) return false;
        const char* p = reinterpret_cast<const char*>(b.data() + at + 4);
        const std::string_view entry(p, static_cast<size_t>(n));
        const size_t nul = entry.find('\0');
        if (nul != std::string_view::npos && entry.substr(0, nul) == key) return true;
        at = (at + 4 + n + 3) / 4 * 4;
    }
    return false;
}

// A KTX2 3-D texture in a format Bevy's volumes use, of size (Rx, 2Ry, 3Rz), and not a three.js atlas.
bool bevy_sniff(std::span<const std::uint8_t> b) {
    if (!is_ktx2(b)) return false;
    const std::uint32_t vk = le::get32(b, 12), h = le::get32(b, 24), d = le::get32(b, 28);
    if (ktx2_texel_bytes(vk) == 0 || h == 0 || h % 2 != 0 || d == 0 || d % 3 != 0) return false;
    return !ktx2_has_key(b, kThreeKey);
}

Result<EngineFileProbes> bevy_read(std::span<const std::uint8_t> bytes, const std::string& name) {
    const Codec* codec = find_codec(kCodecName);
    if (!codec || codec->size_bytes != 24) return bad(ErrorCode::kInternal, name, "codec entry bevy_ambient_cube missing");
    auto tex = decode_ktx2_texture(bytes, name, 6 * kMaxVoxels);
    if (!tex) return tex.error();
    const Ktx2Texture& t = *tex;
    if (t.depth == 0)
        return bad(ErrorCode::kBadFormat, name, "a 2-D texture (pixelDepth 0, byte 28): a Bevy irradiance volume is a 3-D texture of (Rx, 2Ry, 3Rz) texels");
    if (t.height % 2 != 0 || t.depth % 3 != 0)
        return bad(ErrorCode::kBadFormat, name, "texture of " + std::to_string(t.width) + " x " + std::to_string(t.height) + " x " +
                                                    std::to_string(t.depth) + " texels: a Bevy irradiance volume has (Rx, 2Ry, 3Rz) (bytes 24-31)");
    EngineFileProbes out;
    const std::array<std::uint32_t, 3> res = {t.width, t.height / 2, t.depth / 3};
    auto grid = grid_from_keys(t, res, name, out.notes);
    if (!grid) return grid.error();
    const BevyGrid& g = *grid;

    // Each voxel's 18 face values, then the hub: an RGB9E5 file's faces are the entry's bytes;
    // float faces go through the entry's decode by linearity (the hub of each unit face colour,
    // weighted by the file's values), as decode (cube_projection) is linear in the faces.
    const std::size_t tb = ktx2_texel_bytes(t.vk_format);
    std::array<std::array<Sh3Radiance, 3>, 6> basis{};
    if (t.vk_format != kVkFormatE5b9g9r9UfloatPack32) {
        for (int f = 0; f < 6; ++f)
            for (int c = 0; c < 3; ++c) {
                std::uint8_t unit[24] = {};
                const double rgb[3] = {c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0};
                std::uint32_t one = pack_rgb9e5(rgb[0], rgb[1], rgb[2]);
                std::uint8_t* p = unit + 4 * f;
                le::store(p, one, 4);
                basis[static_cast<size_t>(f)][static_cast<size_t>(c)] = decode_probe(*codec, CodecOptions{}, unit);
            }
    }
    const AxisMap m = axis_map(kCodecName);
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
    const std::uint64_t count = g.voxels();
    out.hub.resize(static_cast<size_t>(count));
    for (std::uint64_t i = 0; i < count; ++i) {
        const auto v = voxel_of(i, zg, g, m);
        if (t.vk_format == kVkFormatE5b9g9r9UfloatPack32) {
            std::uint8_t probe[24];
            for (int f = 0; f < 6; ++f) std::memcpy(probe + 4 * f, t.texels.data() + texel_index(g, v, f) * 4, 4);
            out.hub[static_cast<size_t>(i)] = decode_probe(*codec, CodecOptions{}, probe);
            continue;
        }
        double acc[9][3] = {};
        for (int f = 0; f < 6; ++f) {
            const std::uint8_t* p = t.texels.data() + texel_index(g, v, f) * tb;
            for (int c = 0; c < 3; ++c) {
                const double value = tb == 8 ? double(unpack_half(le::load16(p + 2 * c))) : double(le::load_f32(p + 4 * c));
                if (!std::isfinite(value))
                    return bad(ErrorCode::kInvalidValue, name, std::string("voxel (") + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " +
                                                                   std::to_string(v[2]) + ") face " + kFaceNames[f] + " channel " + "RGB"[c] +
                                                                   " is not finite (texel " + std::to_string(texel_index(g, v, f)) + ")");
                const Sh3Radiance& b = basis[static_cast<size_t>(f)][static_cast<size_t>(c)];
                for (int k = 0; k < 9; ++k)
                    for (int cc = 0; cc < 3; ++cc) acc[k][cc] += value * b[k][cc];
            }
        }
        Sh3Radiance& h = out.hub[static_cast<size_t>(i)];
        for (int k = 0; k < 9; ++k)
            for (int cc = 0; cc < 3; ++cc) h[k][cc] = static_cast<float>(acc[k][cc]);
    }
    out.notes.push_back("Bevy irradiance volume: " + std::to_string(res[0]) + " x " + std::to_string(res[1]) + " x " + std::to_string(res[2]) +
                        " voxels in " + vk_format_label(t.vk_format));
    return out;
}

}  // namespace

const EngineFile kBevyIrradianceVolumeFile = {
    "bevy_irradiance_volume",
    "Bevy IrradianceVolume (KTX2 3-D texture, ambient cubes, RGB9E5)",
    ".ktx2",
    kCodecName,
    "bevyengine/bevy crates/bevy_pbr/src/light_probe/irradiance_volume.wesl irradiance_volume_light, "
    "irradiance_volume.rs (module docs), crates/bevy_image/src/ktx2.rs; pcwalton/bevy-baked-gi "
    "Crates/export-blender-gi/src/main.rs update_irradiance_grid_upstream, write_ktx2",
    bevy_sniff,
    bevy_write,
    bevy_read,
};

}  // namespace zhc
