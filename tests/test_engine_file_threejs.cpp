// three.js LightProbeGrid files (formats/engines/threejs_grid.cpp, docs/engine-files.md "three.js"):
//  * write then read equals round_trip_probes(hub, the entry's codec) (exactly: the files hold the
//    codec's float32 / binary16 values), the grid's layout back exactly, on grids whose axes all
//    differ in count (an axis mix-up shows), one of them a single slice deep;
//  * the atlas read here with OpenEXR (rows bottom to top, as three.js's EXRLoader hands them to
//    a Data3DTexture) holds each probe's 7 texels at the index written here from the axes
//    ((x, y, z) three.js = (y, z, x) zhc) and the padding slices equal the edge slices;
//  * a twin of three.js's lightprobes_pars_fragment.glsl.js getLightProbeGridIrradiance (bounds,
//    the half-cell normal offset, the clamp, the 7 taps through a trilinear RGBA 3-D texture
//    filter on the atlas, the unpacking and the SH evaluation) on the written atlas equals the
//    entry's irradiance of the corner probes blended in zhc's grid;
//  * the bounds JSON ("zhc.volume", "threejs.LightProbeGrid") states what three.js's
//    LightProbeGrid takes (position, size, resolution, boundingBox);
//  * hostile inputs: every prefix, trailing bytes, random byte flips, and files written here with
//    one thing wrong each (no bounds, bad JSON, disagreeing bounds, wrong size, a padding slice
//    that differs, alpha not 0, a NaN, other channels, half channels); refused layouts on write;
//  * determinism: the same bytes on every call and from concurrent threads; sniffing.
// With ZHC_THREEJS_GRID_FIXTURES=DIR, ThreejsGridFixtures writes the files and the expected
// irradiance that tests/js/threejs_grid_files.mjs checks in three.js itself.
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "codec/probe/engine_layouts.h"
#include "codec/probe/probe_set.h"
#include "formats/engines/engine_files.h"
#include "formats/engines/ktx2_volume.h"
#include "formats/io/exr_memory.h"
#include "tests/support.h"

namespace zhc {
namespace {

const double kPiD = 3.14159265358979323846;

// Random radiance probes: a positive DC with smaller, signed higher bands.
std::vector<Sh3Radiance> random_hub(size_t n, unsigned seed) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Sh3Radiance> hub(n);
    for (auto& p : hub)
        for (int i = 0; i < 9; ++i)
            for (int c = 0; c < 3; ++c) {
                const double v = u(gen);
                p[i][c] = static_cast<float>(i == 0 ? 2.0 + v : (i < 4 ? 0.8 : 0.3) * v);
            }
    return hub;
}

ProbeLayout grid_layout(Vec3 origin, Vec3 spacing, std::array<std::uint32_t, 3> counts) {
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kGrid;
    l.grid.origin = origin;
    l.grid.spacing = spacing;
    l.grid.counts = counts;
    return l;
}

const EngineFile& exr_file() {
    const EngineFile* f = find_engine_file("threejs_grid_exr");
    EXPECT_NE(f, nullptr);
    return *f;
}

// ---- OpenEXR, written and read here (independent of the entry's code) -------------------------

class MemOStream final : public Imf::OStream {
public:
    MemOStream() : Imf::OStream("test") {}
    void write(const char c[], int n) override {
        if (pos + size_t(n) > bytes.size()) bytes.resize(pos + size_t(n));
        std::memcpy(bytes.data() + pos, c, size_t(n));
        pos += size_t(n);
    }
    std::uint64_t tellp() override { return pos; }
    void seekp(std::uint64_t p) override { pos = size_t(p); }
    std::vector<std::uint8_t> bytes;
    size_t pos = 0;
};

struct ExrImage {
    int w = 0, h = 0;
    std::vector<float> rgba;  // top row first, as stored
    std::map<std::string, std::string> strings;
};

ExrImage read_exr(const std::vector<std::uint8_t>& bytes) {
    ExrMemoryStream s(bytes, "test.exr");
    Imf::InputFile f(s, 0);
    const Imath::Box2i dw = f.header().dataWindow();
    ExrImage im;
    im.w = dw.max.x - dw.min.x + 1;
    im.h = dw.max.y - dw.min.y + 1;
    im.rgba.resize(size_t(im.w) * size_t(im.h) * 4);
    Imf::FrameBuffer fb;
    for (int c = 0; c < 4; ++c)
        fb.insert(std::string(1, "RGBA"[c]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(im.rgba.data() + c), 16, 16 * size_t(im.w)));
    f.setFrameBuffer(fb);
    f.readPixels(0, im.h - 1);
    for (auto it = f.header().begin(); it != f.header().end(); ++it)
        if (const auto* a = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) im.strings[it.name()] = a->value();
    return im;
}

// An EXR with the given channels (each FLOAT, or HALF), image and string attributes.
std::vector<std::uint8_t> write_exr(const ExrImage& im, const std::vector<std::string>& channels = {"R", "G", "B", "A"},
                                    Imf::PixelType type = Imf::FLOAT) {
    MemOStream s;
    {
        Imf::Header h(im.w, im.h);
        h.compression() = Imf::NO_COMPRESSION;
        for (const auto& c : channels) h.channels().insert(c, Imf::Channel(type));
        for (const auto& [k, v] : im.strings) h.insert(k, Imf::StringAttribute(v));
        Imf::OutputFile f(s, h, 0);
        Imf::FrameBuffer fb;
        std::vector<half> halves(im.rgba.size());
        for (size_t i = 0; i < halves.size(); ++i) halves[i] = half(im.rgba[i]);
        for (size_t c = 0; c < channels.size(); ++c) {
            char* base = type == Imf::HALF ? reinterpret_cast<char*>(halves.data() + c % 4) : reinterpret_cast<char*>(const_cast<float*>(im.rgba.data()) + c % 4);
            const size_t xs = (type == Imf::HALF ? 2 : 4) * 4;
            fb.insert(channels[c], Imf::Slice(type, base, xs, xs * size_t(im.w)));
        }
        f.setFrameBuffer(fb);
        f.writePixels(im.h);
    }
    return s.bytes;
}

// ---- the atlas as three.js holds it -------------------------------------------------------------

// The Data3DTexture's data: EXRLoader flips the rows (row r of its array = stored row h - 1 - r).
struct Atlas3d {
    int nx = 0, ny = 0, depth = 0;
    std::vector<float> data;  // RGBA, x fastest, then y, then slice
    const float* texel(int x, int y, int s) const { return data.data() + ((size_t(s) * ny + size_t(y)) * nx + size_t(x)) * 4; }
};
Atlas3d atlas_of(const ExrImage& im, int ny) {
    Atlas3d a;
    a.nx = im.w;
    a.ny = ny;
    a.depth = im.h / ny;
    a.data.resize(im.rgba.size());
    for (int r = 0; r < im.h; ++r)
        std::memcpy(a.data.data() + size_t(r) * size_t(im.w) * 4, im.rgba.data() + size_t(im.h - 1 - r) * size_t(im.w) * 4, size_t(im.w) * 16);
    return a;
}

// three.js's grid from zhc's: (x, y, z) three.js = (y, z, x) zhc (glTF's axes).
struct Grid3 {
    int n[3];
    double origin[3], spacing[3];
};
Grid3 three_grid(const ProbeGrid& g) {
    return {{int(g.counts[1]), int(g.counts[2]), int(g.counts[0])}, {g.origin.y, g.origin.z, g.origin.x}, {g.spacing.y, g.spacing.z, g.spacing.x}};
}
Vec3 to_three(Vec3 v) { return {v.y, v.z, v.x}; }

// Trilinear filtering of an RGBA 3-D texture (LinearFilter, ClampToEdgeWrapping), as OpenGL ES 3.0
// section 3.8.10 defines it: texel coordinates u W - 1/2, the eight texels around, clamped.
std::array<double, 4> sample3d(const Atlas3d& a, double u, double v, double w) {
    const double p[3] = {u * a.nx - 0.5, v * a.ny - 0.5, w * a.depth - 0.5};
    const int size[3] = {a.nx, a.ny, a.depth};
    int i0[3];
    double f[3];
    for (int k = 0; k < 3; ++k) {
        i0[k] = int(std::floor(p[k]));
        f[k] = p[k] - i0[k];
    }
    std::array<double, 4> out{};
    for (int corner = 0; corner < 8; ++corner) {
        int idx[3];
        double wt = 1;
        for (int k = 0; k < 3; ++k) {
            const int bit = (corner >> k) & 1;
            idx[k] = std::clamp(i0[k] + bit, 0, size[k] - 1);
            wt *= bit ? f[k] : 1 - f[k];
        }
        const float* t = a.texel(idx[0], idx[1], idx[2]);
        for (int c = 0; c < 4; ++c) out[size_t(c)] += wt * t[c];
    }
    return out;
}

// getLightProbeGridIrradiance (lightprobes_pars_fragment.glsl.js), in double: pi E.
std::array<double, 3> shader_twin(const Atlas3d& atlas, const double pmin[3], const double pmax[3], const int res[3], Vec3 pos, Vec3 nrm) {
    double uvw[3];
    const double wp[3] = {pos.x, pos.y, pos.z}, wn[3] = {nrm.x, nrm.y, nrm.z};
    for (int k = 0; k < 3; ++k) {
        const double range = pmax[k] - pmin[k], spacing = range / res[k];
        const double sp = wp[k] + wn[k] * spacing * 0.5;
        uvw[k] = std::clamp((sp - pmin[k]) / range, 0.5 / res[k], 1.0 - 0.5 / res[k]);
    }
    const double nz = res[2], padded = nz + 2, depth = 7 * padded, base = uvw[2] * nz + 1;
    std::array<std::array<double, 4>, 7> s{};
    for (int t = 0; t < 7; ++t) s[size_t(t)] = sample3d(atlas, uvw[0], uvw[1], (base + t * padded) / depth);
    double v[28];
    for (int k = 0; k < 28; ++k) v[k] = s[size_t(k / 4)][size_t(k % 4)];
    const double x = nrm.x, y = nrm.y, z = nrm.z;
    std::array<double, 3> r{};
    for (int c = 0; c < 3; ++c) {
        auto cc = [&](int i) { return v[3 * i + c]; };
        double e = cc(0) * 0.886227;
        e += cc(1) * 2.0 * 0.511664 * y;
        e += cc(2) * 2.0 * 0.511664 * z;
        e += cc(3) * 2.0 * 0.511664 * x;
        e += cc(4) * 2.0 * 0.429043 * x * y;
        e += cc(5) * 2.0 * 0.429043 * y * z;
        e += cc(6) * (0.743125 * z * z - 0.247708);
        e += cc(7) * 2.0 * 0.429043 * x * z;
        e += cc(8) * 0.429043 * (x * x - y * y);
        r[size_t(c)] = std::max(e, 0.0);
    }
    return r;
}

// The entry's irradiance at zhc point p, normal n: the texels of the eight corner probes of zhc's
// grid blended trilinearly at p + n spacing / 2 (clamped to the probes), then the entry's shade.
Rgb entry_blend(const std::vector<Sh3Radiance>& hub, const ProbeGrid& g, std::string_view codec_name, Vec3 p, Vec3 n,
                double* abs_blended = nullptr) {
    const Codec& codec = *find_codec(codec_name);
    const EngineLayoutInfo& info = *find_engine_layout(codec_name);
    const double pp[3] = {p.x + n.x * g.spacing.x * 0.5, p.y + n.y * g.spacing.y * 0.5, p.z + n.z * g.spacing.z * 0.5};
    const double o[3] = {g.origin.x, g.origin.y, g.origin.z}, s[3] = {g.spacing.x, g.spacing.y, g.spacing.z};
    int i0[3];
    double f[3];
    for (int k = 0; k < 3; ++k) {
        const int cnt = int(g.counts[size_t(k)]);
        const double q = std::clamp((pp[k] - o[k]) / s[k], 0.0, double(cnt - 1));
        i0[k] = std::min(int(std::floor(q)), std::max(cnt - 2, 0));
        f[k] = q - i0[k];
    }
    double blend[kMaxEngineTexels] = {}, abs_blend[kMaxEngineTexels] = {};
    std::vector<std::uint8_t> bytes(codec.size_bytes);
    for (int corner = 0; corner < 8; ++corner) {
        int idx[3];
        double wt = 1;
        for (int k = 0; k < 3; ++k) {
            const int bit = (corner >> k) & 1;
            idx[k] = std::min(i0[k] + bit, int(g.counts[size_t(k)]) - 1);
            wt *= bit ? f[k] : 1 - f[k];
        }
        const size_t i = size_t(idx[0]) + g.counts[0] * (size_t(idx[1]) + g.counts[1] * size_t(idx[2]));
        encode_probe(codec, CodecOptions{}, hub[i], bytes.data(), nullptr);
        double t[kMaxEngineTexels];
        info.texels(bytes.data(), t);
        for (int k = 0; k < info.texel_count; ++k) {
            blend[k] += wt * t[k];
            abs_blend[k] += wt * std::fabs(t[k]);
        }
    }
    if (abs_blended) std::copy(abs_blend, abs_blend + info.texel_count, abs_blended);
    return info.shade(blend, n);
}

struct Case {
    ProbeGrid grid;
    unsigned seed;
};
std::vector<Case> cases() {
    return {
        {grid_layout({-1.5, 0.25, 0.5}, {0.5, 0.75, 0.4}, {3, 4, 5}).grid, 1},
        {grid_layout({2, -3, 1}, {1.25, 0.5, 2}, {2, 3, 1}).grid, 2},
        {grid_layout({0, 0, 0}, {1, 1, 1}, {1, 1, 1}).grid, 3},
    };
}

// ---- write -> read ------------------------------------------------------------------------------

TEST(ThreejsGridExr, WriteReadEqualsRoundTripThroughTheCodec) {
    for (const Case& c : cases()) {
        const ProbeLayout layout = grid_layout(c.grid.origin, c.grid.spacing, c.grid.counts);
        const auto hub = random_hub(size_t(c.grid.counts[0]) * c.grid.counts[1] * c.grid.counts[2], c.seed);
        auto out = exr_file().write({hub, layout, {}, {}});
        ASSERT_TRUE(out.ok()) << out.error().message;
        auto back = exr_file().read(out->bytes, "grid.exr");
        ASSERT_TRUE(back.ok()) << back.error().message;
        auto expected = round_trip_probes(hub, "threejs_grid_float", CodecOptions{}, layout);
        ASSERT_TRUE(expected.ok());
        ASSERT_EQ(back->hub.size(), hub.size());
        for (size_t i = 0; i < hub.size(); ++i) EXPECT_TRUE(back->hub[i] == (*expected)[i]) << "probe " << i;
        EXPECT_EQ(back->layout.kind, ProbeLayoutKind::kGrid);
        EXPECT_EQ(back->layout.grid.counts, c.grid.counts);
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(back->layout.grid.origin[k], c.grid.origin[k]);
            EXPECT_EQ(back->layout.grid.spacing[k], c.grid.spacing[k]);
        }
        EXPECT_TRUE(back->validity.empty());
    }
}

TEST(ThreejsGridExr, AtlasLayoutPaddingAndBounds) {
    for (const Case& c : cases()) {
        const ProbeLayout layout = grid_layout(c.grid.origin, c.grid.spacing, c.grid.counts);
        const auto hub = random_hub(size_t(c.grid.counts[0]) * c.grid.counts[1] * c.grid.counts[2], c.seed);
        auto out = exr_file().write({hub, layout, {}, {}});
        ASSERT_TRUE(out.ok());
        const ExrImage im = read_exr(out->bytes);
        const Grid3 g = three_grid(c.grid);
        const int padded = g.n[2] + 2;
        ASSERT_EQ(im.w, g.n[0]);
        ASSERT_EQ(im.h, g.n[1] * 7 * padded);
        const Atlas3d a = atlas_of(im, g.n[1]);
        // Every probe's 7 texels at three.js's index; padding slices copy the edge slices.
        const Codec& codec = *find_codec("threejs_grid_float");
        std::vector<std::uint8_t> bytes(codec.size_bytes);
        for (std::uint32_t k = 0; k < c.grid.counts[2]; ++k)
            for (std::uint32_t j = 0; j < c.grid.counts[1]; ++j)
                for (std::uint32_t i = 0; i < c.grid.counts[0]; ++i) {
                    const size_t p = i + c.grid.counts[0] * (j + c.grid.counts[1] * size_t(k));
                    encode_probe(codec, CodecOptions{}, hub[p], bytes.data(), nullptr);
                    const int tx = int(j), ty = int(k), tz = int(i);  // (x, y, z) three.js = (y, z, x) zhc
                    for (int t = 0; t < 7; ++t) {
                        std::vector<int> slices = {t * padded + 1 + tz};
                        if (tz == 0) slices.push_back(t * padded);
                        if (tz == g.n[2] - 1) slices.push_back(t * padded + g.n[2] + 1);
                        for (int s : slices)
                            EXPECT_EQ(std::memcmp(a.texel(tx, ty, s), bytes.data() + 16 * t, 16), 0) << "probe " << p << " texel " << t << " slice " << s;
                    }
                }
        // The bounds as three.js's LightProbeGrid takes them.
        ASSERT_TRUE(im.strings.count("zhc.volume") && im.strings.count("threejs.LightProbeGrid"));
        const auto vol = nlohmann::json::parse(im.strings.at("zhc.volume"));
        const auto three = nlohmann::json::parse(im.strings.at("threejs.LightProbeGrid"));
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(vol["counts"][size_t(k)].get<int>(), g.n[k]);
            EXPECT_EQ(vol["origin"][size_t(k)].get<double>(), g.origin[k]);
            EXPECT_EQ(vol["spacing"][size_t(k)].get<double>(), g.spacing[k]);
            EXPECT_EQ(three["resolution"][size_t(k)].get<int>(), g.n[k]);
            const double size = g.n[k] * g.spacing[k], centre = g.origin[k] + (g.n[k] - 1) * g.spacing[k] / 2;
            EXPECT_NEAR(three["size"][size_t(k)].get<double>(), size, 1e-12 * (1 + size));
            EXPECT_NEAR(three["position"][size_t(k)].get<double>(), centre, 1e-12 * (1 + std::fabs(centre)));
            // The first probe sits half a cell inside the box (LightProbeGridWebGL.getProbePosition).
            EXPECT_NEAR(three["boundingBox"]["min"][size_t(k)].get<double>(), g.origin[k] - g.spacing[k] / 2, 1e-12 * (1 + std::fabs(g.origin[k])));
            EXPECT_NEAR(three["boundingBox"]["max"][size_t(k)].get<double>(), g.origin[k] + (g.n[k] - 0.5) * g.spacing[k], 1e-12 * (1 + std::fabs(g.origin[k]) + size));
        }
    }
}

// The shader twin on the written atlas against the entry's irradiance blended in zhc's grid.
TEST(ThreejsGridExr, ShaderTwinOnTheAtlasEqualsTheEntry) {
    std::mt19937 gen(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (const Case& c : cases()) {
        const ProbeLayout layout = grid_layout(c.grid.origin, c.grid.spacing, c.grid.counts);
        const auto hub = random_hub(size_t(c.grid.counts[0]) * c.grid.counts[1] * c.grid.counts[2], c.seed);
        auto out = exr_file().write({hub, layout, {}, {}});
        ASSERT_TRUE(out.ok());
        const ExrImage im = read_exr(out->bytes);
        const Grid3 g = three_grid(c.grid);
        const Atlas3d a = atlas_of(im, g.n[1]);
        const double pmin[3] = {g.origin[0] - g.spacing[0] / 2, g.origin[1] - g.spacing[1] / 2, g.origin[2] - g.spacing[2] / 2};
        const double pmax[3] = {pmin[0] + g.n[0] * g.spacing[0], pmin[1] + g.n[1] * g.spacing[1], pmin[2] + g.n[2] * g.spacing[2]};
        for (int s = 0; s < 200; ++s) {
            // zhc point in the grid's box (probes half a cell inside), random unit normal.
            const double lo[3] = {c.grid.origin.x - c.grid.spacing.x / 2, c.grid.origin.y - c.grid.spacing.y / 2, c.grid.origin.z - c.grid.spacing.z / 2};
            Vec3 p{lo[0] + u(gen) * c.grid.counts[0] * c.grid.spacing.x, lo[1] + u(gen) * c.grid.counts[1] * c.grid.spacing.y,
                   lo[2] + u(gen) * c.grid.counts[2] * c.grid.spacing.z};
            const double z = 2 * u(gen) - 1, phi = 2 * kPiD * u(gen), r = std::sqrt(1 - z * z);
            const Vec3 n{r * std::cos(phi), r * std::sin(phi), z};
            const auto twin = shader_twin(a, pmin, pmax, g.n, to_three(p), to_three(n));
            const Rgb want = entry_blend(hub, c.grid, "threejs_grid_float", p, n);
            for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(twin[size_t(ch)] / kPiD, want[ch], 1e-6 * (1 + std::fabs(want[ch]))) << "sample " << s;
        }
    }
}

// ---- write refusals, notes ------------------------------------------------------------------------

TEST(ThreejsGridExr, RefusesWhatThreejsCannotHold) {
    const auto hub = random_hub(8, 4);
    ProbeLayout points;
    points.kind = ProbeLayoutKind::kPositions;
    for (int i = 0; i < 8; ++i) points.positions.push_back({float(i), float(i % 2), float(i % 3)});
    auto r = exr_file().write({hub, points, {}, {}});
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("positions"), std::string::npos) << r.error().message;
    r = exr_file().write({hub, ProbeLayout{}, {}, {}});
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    r = exr_file().write({hub, grid_layout({0, 0, 0}, {1, 0, 1}, {2, 2, 2}), {}, {}});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("spacing"), std::string::npos);
    r = exr_file().write({hub, grid_layout({0, 0, 0}, {1, 1, 1}, {2, 2, 3}), {}, {}});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("12 probes, 8 given"), std::string::npos) << r.error().message;
    r = exr_file().write({hub, grid_layout({0, 0, 0}, {1, 1, 1}, {2, 2, 2000}), {}, {}});  // 8000 probes
    ASSERT_FALSE(r.ok());
    // Validity has no place in three.js's grid: said, not dropped silently.
    const std::vector<std::uint8_t> validity = {1, 1, 0, 1, 1, 1, 0, 1};
    r = exr_file().write({hub, grid_layout({0, 0, 0}, {1, 1, 1}, {2, 2, 2}), validity, {}});
    ASSERT_TRUE(r.ok());
    bool said = false;
    for (const auto& n : r->notes) said = said || n.find("2 probes are marked invalid") != std::string::npos;
    EXPECT_TRUE(said);
}

// ---- hostile files -----------------------------------------------------------------------------

struct Good {
    std::vector<Sh3Radiance> hub;
    ProbeLayout layout;
    std::vector<std::uint8_t> bytes;
    ExrImage image;
};
Good good_file() {
    Good g;
    g.layout = grid_layout({-1, 0.5, 2}, {0.5, 1, 0.25}, {2, 3, 2});
    g.hub = random_hub(12, 9);
    auto out = exr_file().write({g.hub, g.layout, {}, {}});
    EXPECT_TRUE(out.ok());
    g.bytes = out->bytes;
    g.image = read_exr(g.bytes);
    return g;
}

// three.js's terms of a "zhc.volume" object, computed here: what the bounds JSON must say.
nlohmann::json three_terms(const nlohmann::json& vol) {
    nlohmann::json t;
    for (size_t k = 0; k < 3; ++k) {
        const double o = vol["origin"][k].get<double>(), sp = vol["spacing"][k].get<double>();
        const int n = vol["counts"][k].get<int>();
        t["position"][k] = o + (n - 1) * sp / 2;
        t["size"][k] = n * sp;
        t["resolution"][k] = n;
        t["boundingBox"]["min"][k] = o - sp / 2;
        t["boundingBox"]["max"][k] = o + (n - 0.5) * sp;
    }
    return t;
}

void expect_refused(const std::vector<std::uint8_t>& bytes, const std::string& needle, const std::string& what) {
    auto r = exr_file().read(bytes, "bad.exr");
    ASSERT_FALSE(r.ok()) << what;
    EXPECT_EQ(r.error().message.rfind("bad.exr", 0), 0u) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_NE(r.error().message.find(needle), std::string::npos) << what << ": " << r.error().message;
}

TEST(ThreejsGridExr, HostileFiles) {
    const Good g = good_file();
    // The file rewritten here uncompressed still reads (the reader does not depend on the writer's choices).
    {
        auto r = exr_file().read(write_exr(g.image), "plain.exr");
        ASSERT_TRUE(r.ok()) << r.error().message;
        auto direct = exr_file().read(g.bytes, "grid.exr");
        ASSERT_TRUE(direct.ok());
        for (size_t i = 0; i < g.hub.size(); ++i) EXPECT_TRUE(r->hub[i] == direct->hub[i]);
    }
    auto with = [&](auto edit) {
        ExrImage im = g.image;
        edit(im);
        return write_exr(im);
    };
    expect_refused(with([](ExrImage& im) { im.strings.erase("zhc.volume"); }), "zhc.volume", "no zhc.volume");
    expect_refused(with([](ExrImage& im) { im.strings.erase("threejs.LightProbeGrid"); }), "threejs.LightProbeGrid", "no three.js bounds");
    expect_refused(with([](ExrImage& im) { im.strings["zhc.volume"] = "{\"origin\":[0,0"; }), "not a JSON object", "bad JSON");
    expect_refused(with([](ExrImage& im) { im.strings["zhc.volume"] = std::string(2000, '[') + std::string(2000, ']'); }), "nests deeper", "deep JSON");
    expect_refused(with([](ExrImage& im) {
                       auto j = nlohmann::json::parse(im.strings["zhc.volume"]);
                       j["spacing"][1] = -1;
                       im.strings["zhc.volume"] = j.dump();
                   }),
                   "spacing", "negative spacing");
    expect_refused(with([](ExrImage& im) {
                       auto j = nlohmann::json::parse(im.strings["zhc.volume"]);
                       j["counts"][0] = 2.5;
                       im.strings["zhc.volume"] = j.dump();
                   }),
                   "counts", "fractional count");
    expect_refused(with([](ExrImage& im) {
                       auto j = nlohmann::json::parse(im.strings["threejs.LightProbeGrid"]);
                       j["position"][2] = j["position"][2].get<double>() + 0.01;
                       im.strings["threejs.LightProbeGrid"] = j.dump();
                   }),
                   "disagree", "moved position");
    expect_refused(with([](ExrImage& im) {
                       auto j = nlohmann::json::parse(im.strings["threejs.LightProbeGrid"]);
                       j["resolution"][1] = 4;
                       im.strings["threejs.LightProbeGrid"] = j.dump();
                   }),
                   "resolution", "resolution differs");
    expect_refused(with([](ExrImage& im) {
                       auto j = nlohmann::json::parse(im.strings["zhc.volume"]);
                       j["counts"][1] = 3;
                       im.strings["zhc.volume"] = j.dump();
                       im.strings["threejs.LightProbeGrid"] = three_terms(j).dump();
                   }),
                   "the image is", "counts that do not fit the image");
    // three.js grid: nx = 3 (zhc y), ny = 2 (zhc z), nz = 2 (zhc x): 7 * 4 slices of 3 x 2.
    const int nx = 3, ny = 2, padded = 4, h = ny * 7 * padded;
    auto at = [&](ExrImage& im, int x, int y, int slice) { return im.rgba.data() + (size_t(h - 1 - (slice * ny + y)) * nx + size_t(x)) * 4; };
    expect_refused(with([&](ExrImage& im) { at(im, 1, 1, 2 * padded)[2] += 0.5f; }), "padding slice 8", "padding slice differs");
    expect_refused(with([&](ExrImage& im) { at(im, 0, 0, 5 * padded + 3)[1] += 0.5f; }), "padding slice 23", "end padding differs");
    expect_refused(with([&](ExrImage& im) {
                       for (int s : {6 * padded, 6 * padded + 1}) at(im, 2, 1, s)[3] = 1.0f;
                   }),
                   "alpha", "alpha not 0");
    expect_refused(with([&](ExrImage& im) { at(im, 2, 0, 3 * padded + 1 + 0)[0] = at(im, 2, 0, 3 * padded)[0] = NAN; }), "not finite", "NaN");
    expect_refused(write_exr(g.image, {"R", "G", "B", "A", "Z"}), "channel", "five channels");
    expect_refused(write_exr(g.image, {"R", "G", "B"}), "channels", "three channels");
    expect_refused(write_exr(g.image, {"R", "G", "B", "A"}, Imf::HALF), "float32", "half channels");
    // Trailing bytes, every prefix, random corruption: one-line errors, no crash.
    auto longer = g.bytes;
    longer.push_back(0);
    expect_refused(longer, "trailing", "trailing byte");
    for (size_t n = 0; n < g.bytes.size(); ++n) {
        auto r = exr_file().read(std::span(g.bytes.data(), n), "bad.exr");
        ASSERT_FALSE(r.ok()) << "prefix " << n;
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    }
    std::mt19937 gen(5);
    const auto plain = write_exr(g.image);
    for (int t = 0; t < 2000; ++t) {
        auto b = t % 2 ? plain : g.bytes;
        for (int k = 0; k < 1 + t % 4; ++k) b[gen() % b.size()] ^= std::uint8_t(1u << (gen() % 8));
        auto r = exr_file().read(b, "bad.exr");
        if (!r.ok()) {
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
        }
    }
}

// ---- determinism, sniffing -----------------------------------------------------------------------

TEST(ThreejsGridExr, DeterministicAndSniffed) {
    const Good g = good_file();
    std::vector<std::vector<std::uint8_t>> results(4);
    std::vector<std::thread> threads;
    for (auto& r : results)
        threads.emplace_back([&] {
            auto out = exr_file().write({g.hub, g.layout, {}, {}});
            if (out.ok()) r = out->bytes;
        });
    for (auto& t : threads) t.join();
    for (const auto& r : results) EXPECT_EQ(r, g.bytes);
    EXPECT_EQ(sniff_engine_file(g.bytes), find_engine_file("threejs_grid_exr"));
    ExrImage other = g.image;
    other.strings.erase("threejs.LightProbeGrid");
    EXPECT_EQ(sniff_engine_file(write_exr(other)), nullptr);
    EXPECT_EQ(sniff_engine_file(std::span(g.bytes.data(), 40)), nullptr);
    EXPECT_EQ(exr_file().extension, ".exr");
    EXPECT_EQ(exr_file().layout_codec, "threejs_grid_float");
}

// ---- KTX2 (RGBA16F 3-D texture) -----------------------------------------------------------------

const EngineFile& ktx2_file() {
    const EngineFile* f = find_engine_file("threejs_grid_ktx2");
    EXPECT_NE(f, nullptr);
    return *f;
}

std::uint32_t u32(const std::vector<std::uint8_t>& b, size_t at) {
    return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 | std::uint32_t(b[at + 3]) << 24;
}

// The texture as KTX2Loader's createRawTexture hands it to a Data3DTexture, read here from the
// KTX 2.0 header (pixelWidth/Height/Depth at bytes 20/24/28, level 0's byteOffset at 80), the
// binary16 texels widened; and the key/value entries (text, the NUL dropped).
Atlas3d ktx2_atlas(const std::vector<std::uint8_t>& b, std::map<std::string, std::string>* kv) {
    Atlas3d a;
    a.nx = int(u32(b, 20));
    a.ny = int(u32(b, 24));
    a.depth = int(u32(b, 28));
    const size_t off = u32(b, 80), n = size_t(a.nx) * size_t(a.ny) * size_t(a.depth) * 4;
    a.data.resize(n);
    for (size_t i = 0; i < n; ++i) {
        half h;
        h.setBits(std::uint16_t(b[off + 2 * i] | b[off + 2 * i + 1] << 8));
        a.data[i] = float(h);
    }
    for (size_t at = u32(b, 56), end = at + u32(b, 60); at + 4 <= end;) {
        const size_t len = u32(b, at);
        const std::string entry(b.begin() + std::ptrdiff_t(at + 4), b.begin() + std::ptrdiff_t(at + 4 + len));
        const size_t nul = entry.find('\0');
        std::string value = entry.substr(nul + 1);
        if (!value.empty() && value.back() == '\0') value.pop_back();
        (*kv)[entry.substr(0, nul)] = value;
        at += 4 + (len + 3) / 4 * 4;
    }
    return a;
}

TEST(ThreejsGridKtx2, WriteReadLayoutAndShaderTwin) {
    std::mt19937 gen(17);
    std::uniform_real_distribution<double> u(0, 1);
    for (const Case& c : cases()) {
        const ProbeLayout layout = grid_layout(c.grid.origin, c.grid.spacing, c.grid.counts);
        const auto hub = random_hub(size_t(c.grid.counts[0]) * c.grid.counts[1] * c.grid.counts[2], c.seed);
        auto out = ktx2_file().write({hub, layout, {}, {}});
        ASSERT_TRUE(out.ok()) << out.error().message;
        auto back = ktx2_file().read(out->bytes, "grid.ktx2");
        ASSERT_TRUE(back.ok()) << back.error().message;
        auto expected = round_trip_probes(hub, "threejs_grid_half", CodecOptions{}, layout);
        ASSERT_TRUE(expected.ok());
        for (size_t i = 0; i < hub.size(); ++i) EXPECT_TRUE(back->hub[i] == (*expected)[i]) << "probe " << i;
        EXPECT_EQ(back->layout.grid.counts, c.grid.counts);
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(back->layout.grid.origin[k], c.grid.origin[k]);
            EXPECT_EQ(back->layout.grid.spacing[k], c.grid.spacing[k]);
        }
        std::map<std::string, std::string> kv;
        const Atlas3d a = ktx2_atlas(out->bytes, &kv);
        const Grid3 g = three_grid(c.grid);
        const int padded = g.n[2] + 2;
        ASSERT_EQ(a.nx, g.n[0]);
        ASSERT_EQ(a.ny, g.n[1]);
        ASSERT_EQ(a.depth, 7 * padded);
        EXPECT_EQ(u32(out->bytes, 12), 97u);  // VK_FORMAT_R16G16B16A16_SFLOAT
        // The texels: each probe's binary16 values at three.js's index; padding = edge slices.
        const Codec& codec = *find_codec("threejs_grid_half");
        std::vector<std::uint8_t> bytes(codec.size_bytes);
        for (std::uint32_t k = 0; k < c.grid.counts[2]; ++k)
            for (std::uint32_t j = 0; j < c.grid.counts[1]; ++j)
                for (std::uint32_t i = 0; i < c.grid.counts[0]; ++i) {
                    const size_t p = i + c.grid.counts[0] * (j + c.grid.counts[1] * size_t(k));
                    encode_probe(codec, CodecOptions{}, hub[p], bytes.data(), nullptr);
                    const int tx = int(j), ty = int(k), tz = int(i);
                    for (int t = 0; t < 7; ++t)
                        for (int s : {t * padded + 1 + tz, tz == 0 ? t * padded : -1, tz == g.n[2] - 1 ? t * padded + g.n[2] + 1 : -1}) {
                            if (s < 0) continue;
                            for (int ch = 0; ch < 4; ++ch) {
                                half h;
                                h.setBits(std::uint16_t(bytes[size_t(8 * t + 2 * ch)] | bytes[size_t(8 * t + 2 * ch + 1)] << 8));
                                EXPECT_EQ(a.texel(tx, ty, s)[ch], float(h)) << "probe " << p << " texel " << t << " slice " << s;
                            }
                        }
                }
        // Bounds, as in the EXR.
        ASSERT_TRUE(kv.count("zhc.volume") && kv.count("threejs.LightProbeGrid"));
        const auto vol = nlohmann::json::parse(kv.at("zhc.volume"));
        const auto three = nlohmann::json::parse(kv.at("threejs.LightProbeGrid"));
        const auto want = three_terms(vol);
        for (size_t k = 0; k < 3; ++k) {
            EXPECT_EQ(vol["counts"][k].get<int>(), g.n[k]);
            EXPECT_EQ(vol["origin"][k].get<double>(), g.origin[k]);
            EXPECT_EQ(three["resolution"][k], want["resolution"][k]);
            EXPECT_NEAR(three["position"][k].get<double>(), want["position"][k].get<double>(), 1e-12);
            EXPECT_NEAR(three["size"][k].get<double>(), want["size"][k].get<double>(), 1e-12);
        }
        // The shader twin on the binary16 atlas against the threejs_grid_half entry.
        const double pmin[3] = {g.origin[0] - g.spacing[0] / 2, g.origin[1] - g.spacing[1] / 2, g.origin[2] - g.spacing[2] / 2};
        const double pmax[3] = {pmin[0] + g.n[0] * g.spacing[0], pmin[1] + g.n[1] * g.spacing[1], pmin[2] + g.n[2] * g.spacing[2]};
        for (int s = 0; s < 200; ++s) {
            const double lo[3] = {c.grid.origin.x - c.grid.spacing.x / 2, c.grid.origin.y - c.grid.spacing.y / 2, c.grid.origin.z - c.grid.spacing.z / 2};
            Vec3 p{lo[0] + u(gen) * c.grid.counts[0] * c.grid.spacing.x, lo[1] + u(gen) * c.grid.counts[1] * c.grid.spacing.y,
                   lo[2] + u(gen) * c.grid.counts[2] * c.grid.spacing.z};
            const double z = 2 * u(gen) - 1, phi = 2 * kPiD * u(gen), r = std::sqrt(1 - z * z);
            const Vec3 n{r * std::cos(phi), r * std::sin(phi), z};
            const auto twin = shader_twin(a, pmin, pmax, g.n, to_three(p), to_three(n));
            const Rgb want_e = entry_blend(hub, c.grid, "threejs_grid_half", p, n);
            for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(twin[size_t(ch)] / kPiD, want_e[ch], 1e-6 * (1 + std::fabs(want_e[ch]))) << "sample " << s;
        }
    }
}

// A Ktx2Texture of the good file, for editing one thing at a time.
Ktx2Texture ktx2_of(const std::vector<std::uint8_t>& bytes) {
    auto t = decode_ktx2_texture(bytes, "good.ktx2");
    EXPECT_TRUE(t.ok());
    return *t;
}

void expect_ktx2_refused(const std::vector<std::uint8_t>& bytes, const std::string& needle, const std::string& what) {
    auto r = ktx2_file().read(bytes, "bad.ktx2");
    ASSERT_FALSE(r.ok()) << what;
    EXPECT_EQ(r.error().message.rfind("bad.ktx2", 0), 0u) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_NE(r.error().message.find(needle), std::string::npos) << what << ": " << r.error().message;
}

TEST(ThreejsGridKtx2, HostileFilesRefusalsDeterminismSniffing) {
    const ProbeLayout layout = grid_layout({-1, 0.5, 2}, {0.5, 1, 0.25}, {2, 3, 2});
    const auto hub = random_hub(12, 9);
    auto out = ktx2_file().write({hub, layout, {}, {}});
    ASSERT_TRUE(out.ok());
    const std::vector<std::uint8_t> good = out->bytes;
    auto edited = [&](auto edit) {
        Ktx2Texture t = ktx2_of(good);
        edit(t);
        auto b = encode_ktx2_texture(t);
        EXPECT_TRUE(b.ok()) << b.error().message;
        return *b;
    };
    auto erase_key = [](Ktx2Texture& t, const std::string& key) {
        t.key_values.erase(std::remove_if(t.key_values.begin(), t.key_values.end(), [&](const Ktx2KeyValue& kv) { return kv.key == key; }), t.key_values.end());
    };
    expect_ktx2_refused(edited([&](Ktx2Texture& t) { erase_key(t, "zhc.volume"); }), "zhc.volume", "no zhc.volume");
    expect_ktx2_refused(edited([&](Ktx2Texture& t) { erase_key(t, "threejs.LightProbeGrid"); }), "threejs.LightProbeGrid", "no three.js bounds");
    expect_ktx2_refused(edited([](Ktx2Texture& t) {
                            for (auto& kv : t.key_values)
                                if (kv.key == "zhc.volume") kv.value.assign({'{', '}', 0});
                        }),
                        "origin", "empty object");
    // three.js grid nx = 3, ny = 2, nz = 2: texel (x, y, slice) at ((slice 2 + y) 3 + x) 8 bytes.
    auto texel = [](Ktx2Texture& t, int x, int y, int slice) { return t.texels.data() + ((size_t(slice) * 2 + size_t(y)) * 3 + size_t(x)) * 8; };
    expect_ktx2_refused(edited([&](Ktx2Texture& t) { texel(t, 2, 1, 4)[0] ^= 1; }), "padding slice 4", "padding differs");
    expect_ktx2_refused(edited([&](Ktx2Texture& t) {
                            for (int s : {6 * 4, 6 * 4 + 1}) texel(t, 0, 1, s)[7] = 0x3c;  // alpha 1.0
                        }),
                        "alpha", "alpha not 0");
    expect_ktx2_refused(edited([&](Ktx2Texture& t) {
                            for (int s : {2 * 4 + 2, 2 * 4 + 3}) texel(t, 1, 0, s)[1] = 0x7e;  // NaN
                        }),
                        "not finite", "NaN");
    expect_ktx2_refused(edited([](Ktx2Texture& t) {
                            t.depth = 0;
                            t.height *= 28;
                        }),
                        "2-D", "2-D texture");
    expect_ktx2_refused(edited([](Ktx2Texture& t) {
                            t.vk_format = kVkFormatR32g32b32a32Sfloat;
                            t.texels.resize(t.texels.size() * 2);
                        }),
                        "vkFormat 109", "float texture");
    expect_ktx2_refused(edited([](Ktx2Texture& t) {
                            t.depth = 7 * 3;
                            t.texels.resize(size_t(3) * 2 * 21 * 8);
                        }),
                        "the texture is", "wrong depth");
    for (size_t n = 0; n < good.size(); ++n) {
        auto r = ktx2_file().read(std::span(good.data(), n), "bad.ktx2");
        ASSERT_FALSE(r.ok()) << "prefix " << n;
    }
    auto longer = good;
    longer.insert(longer.end(), {0, 0, 0, 0});
    EXPECT_FALSE(ktx2_file().read(longer, "bad.ktx2").ok());
    std::mt19937 gen(3);
    for (int t = 0; t < 3000; ++t) {
        auto b = good;
        for (int k = 0; k < 1 + t % 4; ++k) b[gen() % b.size()] ^= std::uint8_t(1u << (gen() % 8));
        auto r = ktx2_file().read(b, "bad.ktx2");
        if (!r.ok()) {
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
        }
    }
    // binary16 holds |v| <= 65504: a brighter probe is refused on write, naming the limit.
    auto bright = hub;
    bright[5][0].r = 2e5f;
    auto r = ktx2_file().write({bright, layout, {}, {}});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("65504"), std::string::npos) << r.error().message;
    EXPECT_TRUE(exr_file().write({bright, layout, {}, {}}).ok());  // float32 holds it
    // Determinism and sniffing.
    for (int k = 0; k < 3; ++k) EXPECT_EQ(ktx2_file().write({hub, layout, {}, {}})->bytes, good);
    EXPECT_EQ(sniff_engine_file(good), find_engine_file("threejs_grid_ktx2"));
    EXPECT_EQ(sniff_engine_file(edited([&](Ktx2Texture& t) { erase_key(t, "threejs.LightProbeGrid"); })), nullptr);
    EXPECT_EQ(ktx2_file().extension, ".ktx2");
    EXPECT_EQ(ktx2_file().layout_codec, "threejs_grid_half");
}

// ---- fixtures for tests/js/threejs_grid_files.mjs ---------------------------------------------------

// Writes DIR/grid.exr, DIR/grid.ktx2 and DIR/expected.json: the bounds, sample points and normals
// in three.js's world axes, the entry's irradiance there (zhc units) and the term scale S. DIR is
// $ZHC_THREEJS_GRID_FIXTURES (tests/js/threejs_grid_files.mjs), else a test folder: the files are
// then checked to exist and the expectations to name both files with 16 samples each.
TEST(ThreejsGridFixtures, WriteForThreejs) {
    const char* env = std::getenv("ZHC_THREEJS_GRID_FIXTURES");
    const std::string dir_name = env ? std::string(env) : test::fresh_dir("threejs_grid_fixtures");
    const char* dir = dir_name.c_str();
    const ProbeLayout layout = grid_layout({-1, -0.5, 0.25}, {0.5, 0.4, 0.6}, {4, 3, 5});
    const auto hub = random_hub(60, 21);
    nlohmann::json files = nlohmann::json::array();
    for (const char* name : {"threejs_grid_exr", "threejs_grid_ktx2"}) {
        const EngineFile* f = find_engine_file(name);
        if (!f) continue;
        auto out = f->write({hub, layout, {}, {}});
        ASSERT_TRUE(out.ok()) << out.error().message;
        const std::string file = std::string("grid") + std::string(f->extension);
        std::ofstream(std::filesystem::path(dir) / file, std::ios::binary).write(reinterpret_cast<const char*>(out->bytes.data()), std::streamsize(out->bytes.size()));
        std::mt19937 gen(31);
        std::uniform_real_distribution<double> u(0, 1);
        nlohmann::json samples = nlohmann::json::array();
        for (int s = 0; s < 16; ++s) {
            const ProbeGrid& g = layout.grid;
            // Inside the probes' span, as float32 values (three.js's world coordinates are float32).
            Vec3 p{float(g.origin.x + (0.05 + 0.9 * u(gen)) * (g.counts[0] - 1) * g.spacing.x),
                   float(g.origin.y + (0.05 + 0.9 * u(gen)) * (g.counts[1] - 1) * g.spacing.y),
                   float(g.origin.z + (0.05 + 0.9 * u(gen)) * (g.counts[2] - 1) * g.spacing.z)};
            const double z = 2 * u(gen) - 1, phi = 2 * kPiD * u(gen), r = std::sqrt(1 - z * z);
            Vec3 n{float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
            double abs_blend[kMaxEngineTexels];
            const Rgb e = entry_blend(hub, g, f->layout_codec, p, n, abs_blend);
            const Vec3 tp = to_three(p), tn = to_three(n);
            // Term scale S: the magnitudes of the shader's nine terms (three.js's axes) / pi, summed
            // over the corner probes with their weights (>= |E|; a relative error e of every stored
            // value moves E by at most e S).
            const double x = tn.x, y = tn.y, zz = tn.z;
            const double basis[9] = {0.886227, 2 * 0.511664 * y, 2 * 0.511664 * zz, 2 * 0.511664 * x, 2 * 0.429043 * x * y,
                                     2 * 0.429043 * y * zz, 0.743125 * zz * zz - 0.247708, 2 * 0.429043 * x * zz, 0.429043 * (x * x - y * y)};
            std::array<double, 3> scale{};
            for (int ch = 0; ch < 3; ++ch)
                for (int i = 0; i < 9; ++i) scale[size_t(ch)] += abs_blend[3 * i + ch] * std::fabs(basis[i]) / kPiD;
            samples.push_back({{"position", {tp.x, tp.y, tp.z}}, {"normal", {tn.x, tn.y, tn.z}}, {"irradiance", {e.r, e.g, e.b}}, {"termScale", scale}});
        }
        auto back = f->read(out->bytes, file);
        ASSERT_TRUE(back.ok()) << back.error().message;
        nlohmann::json bounds = three_terms(nlohmann::json{{"origin", {three_grid(layout.grid).origin[0], three_grid(layout.grid).origin[1], three_grid(layout.grid).origin[2]}},
                                                           {"spacing", {three_grid(layout.grid).spacing[0], three_grid(layout.grid).spacing[1], three_grid(layout.grid).spacing[2]}},
                                                           {"counts", {three_grid(layout.grid).n[0], three_grid(layout.grid).n[1], three_grid(layout.grid).n[2]}}});
        files.push_back({{"file", file}, {"engine", name}, {"codec", std::string(f->layout_codec)}, {"bounds", bounds}, {"samples", samples}});
    }
    std::ofstream(std::filesystem::path(dir) / "expected.json") << nlohmann::json{{"files", files}}.dump(1);
    ASSERT_EQ(files.size(), 2u);
    for (const auto& f : files) {
        EXPECT_TRUE(std::filesystem::is_regular_file(std::filesystem::path(dir) / f["file"].get<std::string>()));
        EXPECT_EQ(f["samples"].size(), 16u);
    }
    std::ifstream back(std::filesystem::path(dir) / "expected.json");
    const nlohmann::json written = nlohmann::json::parse(back, nullptr, false);
    EXPECT_EQ(written, (nlohmann::json{{"files", files}}));
}

}  // namespace
}  // namespace zhc
