// Bevy irradiance volumes (formats/engines/bevy_ktx2.cpp, entry bevy_irradiance_volume): write ->
// read equals round_trip_probes through bevy_ambient_cube; a twin of Bevy's shader
// (crates/bevy_pbr/src/light_probe/irradiance_volume.wesl irradiance_volume_light), written here
// from that shader, sampling the written bytes equals the entry's irradiance (the corner probes'
// texels blended trilinearly, then the entry's shade) at random points and normals; the float
// formats Bevy's loader also takes; Bevy's own example volume (written by bevy-baked-gi's
// export-blender-gi); hostile inputs; determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/engine_layouts.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "formats/engines/engine_files.h"
#include "formats/engines/ktx2_volume.h"

namespace zhc {
namespace {

const EngineFile& bevy_file() {
    const EngineFile* f = find_engine_file("bevy_irradiance_volume");
    EXPECT_NE(f, nullptr);
    return *f;
}

std::vector<std::uint8_t> read_all(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// Random radiance probes whose irradiance is mostly positive (a strong L0, smaller L1 / L2).
std::vector<Sh3Radiance> random_hub(std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0), dc(0.2, 3.0);
    std::vector<Sh3Radiance> hub(n);
    for (auto& h : hub)
        for (int c = 0; c < 3; ++c) {
            const double l0 = dc(rng);
            h[0][c] = static_cast<float>(l0);
            for (int k = 1; k < 9; ++k) h[k][c] = static_cast<float>(0.4 * l0 * u(rng));
        }
    return hub;
}

ProbeLayout grid_layout(std::array<std::uint32_t, 3> counts, Vec3 origin, Vec3 spacing) {
    ProbeLayout l;
    l.kind = ProbeLayoutKind::kGrid;
    l.grid.counts = counts;
    l.grid.origin = origin;
    l.grid.spacing = spacing;
    return l;
}

// ---- the test's own reading of a file -------------------------------------------------------

std::uint32_t u32(const std::vector<std::uint8_t>& b, std::size_t at) {
    return std::uint32_t(b.at(at)) | std::uint32_t(b.at(at + 1)) << 8 | std::uint32_t(b.at(at + 2)) << 16 |
           std::uint32_t(b.at(at + 3)) << 24;
}
std::uint64_t u64(const std::vector<std::uint8_t>& b, std::size_t at) { return u32(b, at) | std::uint64_t(u32(b, at + 4)) << 32; }

// A KTX2 volume's texels as RGB doubles, read with the KTX 2.0 header offsets and each format's
// definition (E5B9G9R9: EXT_texture_shared_exponent, value = mantissa 2^(exponent - 15 - 9)).
struct Volume3d {
    std::uint32_t w = 0, h = 0, d = 0;
    std::vector<std::array<double, 3>> rgb;
    std::array<double, 3> at(std::int64_t x, std::int64_t y, std::int64_t z) const {
        x = std::clamp<std::int64_t>(x, 0, w - 1);  // clamp-to-edge addressing
        y = std::clamp<std::int64_t>(y, 0, h - 1);
        z = std::clamp<std::int64_t>(z, 0, d - 1);
        return rgb[static_cast<std::size_t>((z * h + y) * w + x)];
    }
};
Volume3d parse_volume(const std::vector<std::uint8_t>& f) {
    Volume3d v;
    const std::uint32_t vk = u32(f, 12);
    v.w = u32(f, 20), v.h = u32(f, 24), v.d = u32(f, 28);
    const std::size_t off = static_cast<std::size_t>(u64(f, 80));
    const std::size_t n = std::size_t(v.w) * v.h * v.d;
    v.rgb.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (vk == 123) {
            const std::uint32_t t = u32(f, off + 4 * i);
            const double scale = std::pow(2.0, double(t >> 27) - 24.0);
            v.rgb[i] = {double(t & 511) * scale, double((t >> 9) & 511) * scale, double((t >> 18) & 511) * scale};
        } else if (vk == 97) {
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t hbits = f.at(off + 8 * i + 2 * c) | (f.at(off + 8 * i + 2 * c + 1) << 8);
                const int e = (hbits >> 10) & 31, m = hbits & 1023;
                const double mag = e == 0 ? std::ldexp(m, -24) : std::ldexp(1024 + m, e - 25);
                v.rgb[i][static_cast<std::size_t>(c)] = (hbits & 0x8000) ? -mag : mag;
            }
        } else {
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t bits = u32(f, off + 16 * i + 4 * c);
                float x;
                std::memcpy(&x, &bits, 4);
                v.rgb[i][static_cast<std::size_t>(c)] = x;
            }
        }
    }
    return v;
}

// textureSampleLevel with a linear filter: texel centres at (i + 0.5) / size, the eight nearest
// blended by their distances (the GPU's trilinear filtering, in double).
std::array<double, 3> sample_linear(const Volume3d& v, std::array<double, 3> uvw) {
    const double x = uvw[0] * v.w - 0.5, y = uvw[1] * v.h - 0.5, z = uvw[2] * v.d - 0.5;
    const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    const double ax = x - fx, ay = y - fy, az = z - fz;
    std::array<double, 3> out{};
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const double wgt = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay) * (dz ? az : 1 - az);
                const auto t = v.at(std::int64_t(fx) + dx, std::int64_t(fy) + dy, std::int64_t(fz) + dz);
                for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(c)] += wgt * t[static_cast<std::size_t>(c)];
            }
    return out;
}

// irradiance_volume_light for one volume of intensity 1 whose entity has translation T and scale
// S (no rotation): world position and normal in Bevy's axes.
std::array<double, 3> bevy_shader(const Volume3d& v, std::array<double, 3> T, std::array<double, 3> S, std::array<double, 3> p,
                                  std::array<double, 3> N) {
    const std::array<double, 3> atlas = {double(v.w), double(v.h), double(v.d)};
    const std::array<double, 3> resolution = {double(v.w), double(v.h / 2), double(v.d / 3)};
    std::array<double, 3> uvw{}, neg{};
    for (std::size_t a = 0; a < 3; ++a) {
        const double unit_pos = (p[a] - T[a]) / S[a];
        const double stp = std::clamp((unit_pos + 0.5) * resolution[a], 0.5, resolution[a] - 0.5);
        uvw[a] = stp / atlas[a];
        neg[a] = N[a] < 0 ? 0.5 : 0.0;
    }
    const auto rgb_x = sample_linear(v, {uvw[0], uvw[1] + neg[0], uvw[2]});
    const auto rgb_y = sample_linear(v, {uvw[0], uvw[1] + neg[1], uvw[2] + 1.0 / 3.0});
    const auto rgb_z = sample_linear(v, {uvw[0], uvw[1] + neg[2], uvw[2] + 2.0 / 3.0});
    std::array<double, 3> out{};
    for (std::size_t c = 0; c < 3; ++c) out[c] = rgb_x[c] * N[0] * N[0] + rgb_y[c] * N[1] * N[1] + rgb_z[c] * N[2] * N[2];
    return out;
}

// The key's JSON from a file.
nlohmann::json key_json(const std::vector<std::uint8_t>& file, const std::string& key) {
    auto t = decode_ktx2_texture(file, "k");
    EXPECT_TRUE(t.ok());
    for (const auto& e : t->key_values)
        if (e.key == key) return nlohmann::json::parse(std::string(e.value.begin(), e.value.end()));
    ADD_FAILURE() << "no key " << key;
    return {};
}

// The entry's irradiance at a point of zhc's grid: the eight corner probes' texels blended
// trilinearly (positions clamped to the grid), then the entry's shade.
Rgb entry_irradiance(const std::vector<Sh3Radiance>& hub, const ProbeGrid& g, Vec3 p, Vec3 n) {
    const Codec* codec = find_codec("bevy_ambient_cube");
    const EngineLayoutInfo* info = find_engine_layout("bevy_ambient_cube");
    const double q[3] = {(p.x - g.origin.x) / g.spacing.x, (p.y - g.origin.y) / g.spacing.y, (p.z - g.origin.z) / g.spacing.z};
    std::array<std::uint32_t, 3> i0{};
    std::array<double, 3> f{};
    for (std::size_t a = 0; a < 3; ++a) {
        const double c = std::clamp(q[a], 0.0, double(g.counts[a] - 1));
        i0[a] = std::min<std::uint32_t>(static_cast<std::uint32_t>(c), g.counts[a] - 1);
        f[a] = c - i0[a];
    }
    std::vector<double> blend(static_cast<std::size_t>(info->texel_count), 0.0);
    std::vector<std::uint8_t> bytes(codec->size_bytes);
    double tex[kMaxEngineTexels];
    for (int corner = 0; corner < 8; ++corner) {
        std::array<std::uint32_t, 3> idx{};
        double w = 1;
        for (std::size_t a = 0; a < 3; ++a) {
            const int bit = (corner >> a) & 1;
            idx[a] = std::min(i0[a] + bit, g.counts[a] - 1);
            w *= bit ? f[a] : 1 - f[a];
        }
        const std::size_t i = idx[0] + g.counts[0] * (idx[1] + std::size_t(g.counts[1]) * idx[2]);
        encode_probe(*codec, CodecOptions{}, hub[i], bytes.data(), nullptr);
        info->texels(bytes.data(), tex);
        for (int k = 0; k < info->texel_count; ++k) blend[static_cast<std::size_t>(k)] += w * tex[k];
    }
    return info->shade(blend.data(), n);
}

Vec3 to_zhc(std::array<double, 3> v) {
    const Mat3& a = find_engine_layout("bevy_ambient_cube")->axes;
    return transpose(a) * Vec3{v[0], v[1], v[2]};
}

// ---- tests -----------------------------------------------------------------------------------

TEST(EngineFileBevy, EntryDescribesTheFormat) {
    const EngineFile& f = bevy_file();
    EXPECT_EQ(f.extension, ".ktx2");
    EXPECT_EQ(f.layout_codec, "bevy_ambient_cube");
    EXPECT_NE(find_codec(f.layout_codec), nullptr);
    EXPECT_NE(find_engine_layout(f.layout_codec), nullptr);
}

TEST(EngineFileBevy, WriteThenReadEqualsRoundTripProbes) {
    const auto layout = grid_layout({3, 4, 2}, {1.5, -2.0, 0.25}, {0.5, 0.75, 1.25});
    const auto hub = random_hub(24, 11);
    EngineFileInput in;
    in.hub = hub;
    in.layout = layout;
    auto out = bevy_file().write(in);
    ASSERT_TRUE(out.ok()) << out.error().message;
    EXPECT_EQ(sniff_engine_file(out->bytes), find_engine_file("bevy_irradiance_volume"));
    auto back = bevy_file().read(out->bytes, "v.ktx2");
    ASSERT_TRUE(back.ok()) << back.error().message;
    auto expected = round_trip_probes(hub, "bevy_ambient_cube", CodecOptions{}, layout);
    ASSERT_TRUE(expected.ok());
    ASSERT_EQ(back->hub.size(), expected->size());
    for (std::size_t i = 0; i < hub.size(); ++i) EXPECT_EQ(back->hub[i], (*expected)[i]) << "probe " << i;
    EXPECT_EQ(back->layout.kind, ProbeLayoutKind::kGrid);
    EXPECT_EQ(back->layout.grid.counts, layout.grid.counts);
    for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(back->layout.grid.origin[a], layout.grid.origin[a]);
        EXPECT_EQ(back->layout.grid.spacing[a], layout.grid.spacing[a]);
    }
    // The texture: (Rx, 2Ry, 3Rz) in Bevy's axes (x, y, z) = zhc's (y, z, x), RGB9E5.
    EXPECT_EQ(u32(out->bytes, 12), 123u);
    EXPECT_EQ(u32(out->bytes, 20), 4u);
    EXPECT_EQ(u32(out->bytes, 24), 2u * 2);
    EXPECT_EQ(u32(out->bytes, 28), 3u * 3);
    // Deterministic.
    auto again = bevy_file().write(in);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again->bytes, out->bytes);
    EXPECT_EQ(again->notes, out->notes);
}

// The transform the note prints and the key holds puts Bevy's voxel centres on zhc's probes: the
// shader's twin on the file's bytes equals the entry's irradiance everywhere in the volume.
TEST(EngineFileBevy, ShaderTwinOnTheFileEqualsTheEntry) {
    const auto layout = grid_layout({4, 3, 5}, {-1.0, 2.0, 0.5}, {0.8, 1.1, 0.6});
    const auto hub = random_hub(60, 5);
    EngineFileInput in;
    in.hub = hub;
    in.layout = layout;
    auto out = bevy_file().write(in);
    ASSERT_TRUE(out.ok()) << out.error().message;
    const auto j = key_json(out->bytes, "bevy.IrradianceVolume");
    const std::array<double, 3> T = j["translation"].get<std::array<double, 3>>(), S = j["scale"].get<std::array<double, 3>>();
    // Bevy's axes: (x, y, z) = zhc's (y, z, x); translation = the grid's centre, scale = n spacing.
    EXPECT_DOUBLE_EQ(T[0], 2.0 + 0.5 * 2 * 1.1);
    EXPECT_DOUBLE_EQ(T[1], 0.5 + 0.5 * 4 * 0.6);
    EXPECT_DOUBLE_EQ(T[2], -1.0 + 0.5 * 3 * 0.8);
    EXPECT_DOUBLE_EQ(S[0], 3 * 1.1);
    EXPECT_DOUBLE_EQ(S[1], 5 * 0.6);
    EXPECT_DOUBLE_EQ(S[2], 4 * 0.8);
    // The note prints the same numbers.
    ASSERT_FALSE(out->notes.empty());
    auto printed = [&](const std::string& call) {
        const std::size_t at = out->notes[0].find(call + "(Vec3::new(");
        EXPECT_NE(at, std::string::npos) << out->notes[0];
        std::array<double, 3> v{};
        const char* p = out->notes[0].c_str() + at + call.size() + std::strlen("(Vec3::new(");
        for (auto& x : v) {
            char* end = nullptr;
            x = std::strtod(p, &end);
            p = end + 2;  // ", "
        }
        return v;
    };
    EXPECT_EQ(printed("Transform::from_translation"), T);
    EXPECT_EQ(printed("with_scale"), S);

    const Volume3d vol = parse_volume(out->bytes);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    std::normal_distribution<double> g(0, 1);
    double worst = 0;
    for (int s = 0; s < 2000; ++s) {
        std::array<double, 3> p{}, N{};
        for (std::size_t a = 0; a < 3; ++a) p[a] = T[a] + S[a] * u(rng);  // inside the entity's box, edges included
        for (std::size_t a = 0; a < 3; ++a) N[a] = g(rng);
        const double len = std::sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
        for (auto& c : N) c /= len;
        const auto got = bevy_shader(vol, T, S, p, N);
        const Rgb want = entry_irradiance(hub, layout.grid, to_zhc(p), to_zhc(N));
        for (int c = 0; c < 3; ++c) {
            const double err = std::fabs(got[static_cast<std::size_t>(c)] - want[c]);
            worst = std::max(worst, err / (std::fabs(want[c]) + 1e-3));
            ASSERT_NEAR(got[static_cast<std::size_t>(c)], want[c], 1e-5 * (std::fabs(want[c]) + 1e-2)) << "sample " << s;
        }
    }
    RecordProperty("worst_relative_error", std::to_string(worst));
}

// Bevy's loader takes RGBA16F and RGBA32F too: the same voxels in those formats read to the same
// probes (RGB9E5 values are exact in both), and the twin reads them alike.
TEST(EngineFileBevy, ReadsHalfAndFloatVolumes) {
    const auto layout = grid_layout({2, 3, 2}, {0, 0, 0}, {1, 1, 1});
    const auto hub = random_hub(12, 9);
    EngineFileInput in;
    in.hub = hub;
    in.layout = layout;
    auto out = bevy_file().write(in);
    ASSERT_TRUE(out.ok());
    auto ref = bevy_file().read(out->bytes, "ref.ktx2");
    ASSERT_TRUE(ref.ok());
    auto tex = decode_ktx2_texture(out->bytes, "ref.ktx2");
    ASSERT_TRUE(tex.ok());
    const std::size_t n = tex->texels.size() / 4;
    for (const std::uint32_t vk : {97u, 109u}) {
        Ktx2Texture t = *tex;
        t.vk_format = vk;
        t.texels.clear();
        for (std::size_t i = 0; i < n; ++i) {
            const Rgb v = unpack_rgb9e5(u32(tex->texels, 4 * i));
            for (int c = 0; c < 4; ++c) {
                const double x = c < 3 ? double(v[c]) : 1.0;
                if (vk == 97) {
                    const std::uint16_t hb = pack_half(x);
                    ASSERT_EQ(double(unpack_half(hb)), x);
                    t.texels.push_back(static_cast<std::uint8_t>(hb));
                    t.texels.push_back(static_cast<std::uint8_t>(hb >> 8));
                } else {
                    const float fx = static_cast<float>(x);
                    std::uint8_t b[4];
                    std::memcpy(b, &fx, 4);
                    t.texels.insert(t.texels.end(), b, b + 4);
                }
            }
        }
        auto bytes = encode_ktx2_texture(t);
        ASSERT_TRUE(bytes.ok());
        EXPECT_EQ(sniff_engine_file(*bytes), find_engine_file("bevy_irradiance_volume"));
        auto got = bevy_file().read(*bytes, "f.ktx2");
        ASSERT_TRUE(got.ok()) << got.error().message;
        ASSERT_EQ(got->hub.size(), ref->hub.size());
        for (std::size_t i = 0; i < ref->hub.size(); ++i)
            for (int k = 0; k < 9; ++k)
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(got->hub[i][k][c], ref->hub[i][k][c], 1e-6 * (std::fabs(ref->hub[i][0][c]) + 1e-3)) << vk << " probe " << i;
        const Volume3d a = parse_volume(out->bytes), b = parse_volume(*bytes);
        for (std::size_t i = 0; i < a.rgb.size(); ++i) EXPECT_EQ(a.rgb[i], b.rgb[i]) << vk << " texel " << i;
    }
}

// Bevy's example volume (assets/irradiance_volumes/Example.vxgi.ktx2, export-blender-gi).
TEST(EngineFileBevy, ReadsBevysExampleVolume) {
    const auto file = read_all(std::string(ZHC_TEST_DATA_DIR) + "/engines/bevy_example.vxgi.ktx2");
    ASSERT_EQ(file.size(), 4836u);
    EXPECT_EQ(sniff_engine_file(file), find_engine_file("bevy_irradiance_volume"));
    auto got = bevy_file().read(file, "Example.vxgi.ktx2");
    ASSERT_TRUE(got.ok()) << got.error().message;
    // 8 x 8 x 3 voxels in Bevy's axes; zhc's x is Bevy's z.
    ASSERT_EQ(got->layout.kind, ProbeLayoutKind::kGrid);
    EXPECT_EQ(got->layout.grid.counts, (std::array<std::uint32_t, 3>{3, 8, 8}));
    EXPECT_DOUBLE_EQ(got->layout.grid.spacing.x, 1.0 / 3);
    EXPECT_DOUBLE_EQ(got->layout.grid.spacing.y, 1.0 / 8);
    EXPECT_DOUBLE_EQ(got->layout.grid.origin.x, -0.5 + 1.0 / 6);
    EXPECT_DOUBLE_EQ(got->layout.grid.origin.z, -0.5 + 1.0 / 16);
    bool unit_cube_note = false;
    for (const auto& n : got->notes) unit_cube_note |= n.find("unit cube centred at the origin") != std::string::npos;
    EXPECT_TRUE(unit_cube_note);
    // Each probe is the entry's decode of its six faces, gathered here by Bevy's addressing:
    // face (axis a, negative s) of voxel (x, y, z) at texel (x, y + s Ry, z + a Rz).
    const Codec* codec = find_codec("bevy_ambient_cube");
    const std::size_t off = static_cast<std::size_t>(u64(file, 80));
    const std::size_t W = 8, H = 16, Rx = 8, Ry = 8, Rz = 3;
    ASSERT_EQ(got->hub.size(), Rx * Ry * Rz);
    for (std::size_t z = 0; z < Rz; ++z)
        for (std::size_t y = 0; y < Ry; ++y)
            for (std::size_t x = 0; x < Rx; ++x) {
                std::uint8_t bytes[24];
                for (int f = 0; f < 6; ++f) {
                    const std::size_t texel = ((z + std::size_t(f / 2) * Rz) * H + y + std::size_t(f % 2) * Ry) * W + x;
                    std::memcpy(bytes + 4 * f, file.data() + off + 4 * texel, 4);
                }
                // zhc's x is Bevy's z, zhc's y Bevy's x, zhc's z Bevy's y.
                const std::size_t i = z + 3 * (x + 8 * y);
                EXPECT_EQ(got->hub[i], decode_probe(*codec, CodecOptions{}, bytes)) << x << " " << y << " " << z;
            }
}

// The grid from "bevy.IrradianceVolume" alone, and the keys checked against each other.
TEST(EngineFileBevy, GridFromEitherKeyAndKeysMustAgree) {
    const auto layout = grid_layout({2, 2, 3}, {0.25, -1, 4}, {0.5, 2, 0.125});
    const auto hub = random_hub(12, 2);
    EngineFileInput in;
    in.hub = hub;
    in.layout = layout;
    auto out = bevy_file().write(in);
    ASSERT_TRUE(out.ok());
    auto tex = *decode_ktx2_texture(out->bytes, "x");
    auto with_keys = [&](std::vector<Ktx2KeyValue> kv) {
        Ktx2Texture t = tex;
        t.key_values = std::move(kv);
        return *encode_ktx2_texture(t);
    };
    auto value = [](const std::string& s) { return std::vector<std::uint8_t>(s.begin(), s.end()); };
    std::vector<Ktx2KeyValue> bevy_only;
    for (const auto& e : tex.key_values)
        if (e.key == "bevy.IrradianceVolume") bevy_only.push_back(e);
    ASSERT_EQ(bevy_only.size(), 1u);
    auto got = bevy_file().read(with_keys(bevy_only), "b.ktx2");
    ASSERT_TRUE(got.ok()) << got.error().message;
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(got->layout.grid.origin[a], layout.grid.origin[a], 1e-12);
        EXPECT_NEAR(got->layout.grid.spacing[a], layout.grid.spacing[a], 1e-12);
    }
    // Disagreeing keys, bad JSON, counts that are not the texture's.
    struct Case {
        std::vector<Ktx2KeyValue> kv;
        ErrorCode code;
        const char* says;
    };
    const std::string good_volume(tex.key_values[1].value.begin(), tex.key_values[1].value.end());
    ASSERT_EQ(tex.key_values[1].key, "zhc.volume");
    const Case cases[] = {
        {{bevy_only[0], {"zhc.volume", value("{\"origin\":[0,0,0],\"spacing\":[2,0.125,0.5],\"counts\":[2,3,2]}")}},
         ErrorCode::kBadFormat, "disagrees"},
        {{{"zhc.volume", value("[1,2]")}}, ErrorCode::kBadFormat, "not a JSON object"},
        {{{"zhc.volume", value("{\"origin\":[0,0],\"spacing\":[1,1,1],\"counts\":[2,3,2]}")}}, ErrorCode::kBadFormat, "\"origin\""},
        {{{"zhc.volume", value("{\"origin\":[0,0,0],\"spacing\":[1,0,1],\"counts\":[2,3,2]}")}}, ErrorCode::kInvalidValue, "\"spacing\""},
        {{{"zhc.volume", value("{\"origin\":[0,0,0],\"spacing\":[1,1,1],\"counts\":[2,2,2]}")}}, ErrorCode::kBadFormat, "\"counts\" differ"},
        {{{"zhc.volume", value("{\"origin\":[0,0,0],\"spacing\":[1,1,1],\"counts\":[2,3,2.5]}")}}, ErrorCode::kBadFormat, "\"counts\""},
        {{{"zhc.volume", value(std::string(1000, '[') + std::string(1000, ']'))}}, ErrorCode::kBadFormat, "deeper"},
        {{{"bevy.IrradianceVolume", value("{\"translation\":[0,0,0],\"scale\":[1,-1,1],\"resolution\":[2,3,2]}")}}, ErrorCode::kInvalidValue, "\"scale\""},
        {{{"bevy.IrradianceVolume", value("{\"translation\":[0,0,0],\"scale\":[1,1,1],\"resolution\":[3,3,2]}")}}, ErrorCode::kBadFormat, "\"resolution\""},
    };
    for (const auto& c : cases) {
        auto r = bevy_file().read(with_keys(c.kv), "k.ktx2");
        ASSERT_FALSE(r.ok()) << c.says;
        EXPECT_EQ(r.error().code, c.code) << r.error().message;
        EXPECT_NE(r.error().message.find(c.says), std::string::npos) << r.error().message;
        EXPECT_EQ(r.error().message.rfind("k.ktx2: ", 0), 0u) << r.error().message;
    }
    // The good volume key alone reads.
    EXPECT_TRUE(bevy_file().read(with_keys({{"zhc.volume", value(good_volume)}}), "v.ktx2").ok());
}

TEST(EngineFileBevy, HostileFilesRefused) {
    const auto layout = grid_layout({2, 2, 2}, {0, 0, 0}, {1, 1, 1});
    EngineFileInput in;
    const auto hub = random_hub(8, 4);
    in.hub = hub;
    in.layout = layout;
    auto out = bevy_file().write(in);
    ASSERT_TRUE(out.ok());
    // Every truncation and one extra byte.
    for (std::size_t n = 0; n < out->bytes.size(); ++n) {
        const std::vector<std::uint8_t> cut(out->bytes.begin(), out->bytes.begin() + static_cast<std::ptrdiff_t>(n));
        EXPECT_FALSE(bevy_file().read(cut, "t.ktx2").ok()) << n;
    }
    auto longer = out->bytes;
    longer.push_back(0);
    EXPECT_FALSE(bevy_file().read(longer, "t.ktx2").ok());
    // Shapes that are not (Rx, 2Ry, 3Rz) 3-D textures.
    auto shaped = [](std::uint32_t w, std::uint32_t h, std::uint32_t d) {
        Ktx2Texture t;
        t.vk_format = 123;
        t.width = w, t.height = h, t.depth = d;
        t.texels.assign(4 * std::size_t(w) * h * std::max<std::uint32_t>(d, 1), 0);
        return *encode_ktx2_texture(t);
    };
    for (const auto& [bytes, says] : std::vector<std::pair<std::vector<std::uint8_t>, std::string>>{
             {shaped(2, 4, 0), "2-D texture"}, {shaped(2, 3, 3), "(Rx, 2Ry, 3Rz)"}, {shaped(2, 4, 4), "(Rx, 2Ry, 3Rz)"}}) {
        EXPECT_EQ(sniff_engine_file(bytes), nullptr);
        auto r = bevy_file().read(bytes, "s.ktx2");
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, ErrorCode::kBadFormat);
        EXPECT_NE(r.error().message.find(says), std::string::npos) << r.error().message;
    }
    // A non-finite value in a half-float volume names the voxel and face.
    Ktx2Texture t;
    t.vk_format = 97;
    t.width = 1, t.height = 2, t.depth = 3;
    t.texels.assign(8 * 6, 0);
    t.texels[8 * 3 + 2] = 0x00, t.texels[8 * 3 + 3] = 0x7C;  // texel 3 = voxel 0's face -Y, green = +inf
    auto r = bevy_file().read(*encode_ktx2_texture(t), "inf.ktx2");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidValue);
    EXPECT_NE(r.error().message.find("voxel (0, 0, 0) face -Y channel G is not finite"), std::string::npos) << r.error().message;
    // A three.js atlas (its key) is not sniffed as a Bevy volume.
    Ktx2Texture three = *decode_ktx2_texture(shaped(2, 4, 6), "x");
    three.key_values = {{"threejs.LightProbeGrid", {'{', '}'}}};
    const auto three_bytes = *encode_ktx2_texture(three);
    EXPECT_NE(sniff_engine_file(three_bytes), find_engine_file("bevy_irradiance_volume"));
    EXPECT_EQ(sniff_engine_file(shaped(2, 4, 6)), find_engine_file("bevy_irradiance_volume"));
}

// Exactly one entry of the table claims a Bevy volume (zhc's and the exporter's), so `zhc convert`
// reads it whatever the table's order.
TEST(EngineFileBevy, OnlyTheBevyEntrySniffsBevyVolumes) {
    EngineFileInput in;
    const auto hub = random_hub(8, 6);
    in.hub = hub;
    in.layout = grid_layout({2, 2, 2}, {0, 0, 0}, {1, 1, 1});
    auto out = bevy_file().write(in);
    ASSERT_TRUE(out.ok());
    const auto example = read_all(std::string(ZHC_TEST_DATA_DIR) + "/engines/bevy_example.vxgi.ktx2");
    const std::vector<const std::vector<std::uint8_t>*> files = {&out->bytes, &example};
    for (const auto* bytes : files) {
        std::vector<std::string> claimed;
        for (const EngineFile& f : engine_files())
            if (f.sniff && f.sniff(*bytes)) claimed.emplace_back(f.name);
        EXPECT_EQ(claimed, std::vector<std::string>{"bevy_irradiance_volume"});
    }
}

TEST(EngineFileBevy, WriterRefusesWhatBevyCannotHold) {
    const auto hub = random_hub(8, 1);
    EngineFileInput in;
    in.hub = hub;
    auto expect_refused = [&](const char* says) {
        auto r = bevy_file().write(in);
        ASSERT_FALSE(r.ok()) << says;
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
        EXPECT_NE(r.error().message.find(says), std::string::npos) << r.error().message;
    };
    in.layout.kind = ProbeLayoutKind::kPositions;
    in.layout.positions.assign(8, {0, 0, 0});
    expect_refused("regular grids");
    in.layout = ProbeLayout{};
    expect_refused("position-less");
    in.layout = grid_layout({2, 2, 3}, {0, 0, 0}, {1, 1, 1});
    expect_refused("holds 12 probes, 8 given");
    in.layout = grid_layout({2, 2, 2}, {0, 0, 0}, {1, 0, 1});
    expect_refused("spacing > 0");
    in.layout = grid_layout({2, 2, 2}, {0, 0, 0}, {1, 1, 1});
    auto nan_hub = hub;
    nan_hub[5][3][1] = std::nanf("");
    in.hub = nan_hub;
    expect_refused("probe 5 is not finite");
    auto bright = hub;
    bright[2][0][0] = 1e6f;
    in.hub = bright;
    expect_refused("exceeds RGB9E5's largest value 65408");
    // Validity is noted, not refused.
    in.hub = hub;
    const std::vector<std::uint8_t> validity = {1, 1, 0, 1, 1, 1, 0, 1};
    in.validity = validity;
    auto ok = bevy_file().write(in);
    ASSERT_TRUE(ok.ok());
    bool noted = false;
    for (const auto& n : ok->notes) noted |= n.find("2 probes are marked invalid") != std::string::npos;
    EXPECT_TRUE(noted);
}

}  // namespace
}  // namespace zhc
