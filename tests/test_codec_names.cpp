// What the codec table's names promise (codec/probe/codec.h codec_aliases): an entry whose name
// says "dering" keeps irradiance non-negative; the aliases resolve to their entries on the command
// line and in .zhp and glTF files that zhc wrote under those names (tests/data/aliases, written by
// `zhc convert maps.json -r zh3_lum_dering` and `zhc gltf embed`, maps.json = the eight sample maps'
// SH3), and writers write the entry's own name.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/probe_set.h"
#include "formats/probes/gltf_probes.h"
#include "formats/probes/probe_file.h"
#include "support.h"

namespace zhc {
namespace {

const std::string kAliasDir = std::string(ZHC_TEST_DATA_DIR) + "/aliases/";

// The audit's sample maps (the eight envmaps' SH3) plus the lightings where a zonal clamp cannot
// help: a directional light, small cones (one over a dim ambient) and two opposite lights.
std::vector<Sh3Radiance> lightings() {
    std::vector<Sh3Radiance> out;
    for (const std::string& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        out.push_back(project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u));
    }
    out.push_back(project_directional({0, 0, 1}, {1, 1, 1}));
    out.push_back(project_directional(normalize_or({1, -2, 0.5}, {0, 0, 1}), {3, 1, 0.2f}));
    out.push_back(project_cone(normalize_or({1, 2, 3}, {0, 0, 1}), 0.3, {5, 4, 3}) + project_constant({0.1f, 0.1f, 0.1f}));
    out.push_back(project_cone({0, 1, 0}, 0.05, {2, 2, 2}));
    out.push_back(project_directional({1, 0, 0}, {1, 1, 1}) + project_directional({-1, 0, 0}, {0.5f, 0.5f, 0.5f}));
    return out;
}

// Smallest irradiance (any channel) of the entry's stored bytes over the audit's 2048 directions.
double min_irradiance(const Codec& c, const Sh3Radiance& hub, const std::vector<Vec3>& dirs) {
    const CodecOptions o;
    std::vector<std::uint8_t> bytes(c.size_bytes);
    c.encode(hub, o, bytes.data(), nullptr);
    double m = 1e300;
    for (const Vec3& n : dirs) {
        const Rgb e = c.irradiance(bytes.data(), o, n);
        m = std::min({m, double(e[0]), double(e[1]), double(e[2])});
    }
    return m;
}

TEST(CodecNames, DeringNamesAreNonNegative) {
    const std::vector<Vec3> dirs = fibonacci_sphere(2048);  // zhc audit's default directions
    const std::vector<Sh3Radiance> hubs = lightings();
    int dering_entries = 0;
    for (const Codec& c : codecs()) {
        if (c.name.find("dering") == std::string_view::npos) continue;
        ++dering_entries;
        for (size_t i = 0; i < hubs.size(); ++i)
            EXPECT_GE(min_irradiance(c, hubs[i], dirs), 0.0) << c.name << " goes negative on lighting " << i;
    }
    EXPECT_EQ(dering_entries, 3);  // sh3_dering, zh3_dering, zh3_dering_q16
    // The same lightings catch the entries the aliases name: App. B's clamps go negative on them
    // (so they could not keep a "dering" name).
    for (const CodecAlias& a : codec_aliases()) {
        const Codec* c = find_codec(a.name);
        ASSERT_NE(c, nullptr) << a.name;
        double worst = 1e300;
        for (const Sh3Radiance& hub : hubs) worst = std::min(worst, min_irradiance(*c, hub, dirs));
        EXPECT_LT(worst, 0.0) << a.name;
    }
}

TEST(CodecNames, AliasesResolveToTheirEntries) {
    ASSERT_EQ(codec_aliases().size(), 2u);
    EXPECT_EQ(find_codec("zh3_lum_dering"), find_codec("zh3_lum_axis_clamp"));
    EXPECT_EQ(find_codec("zh3_lum_dering_sphere"), find_codec("zh3_lum_sphere_clamp"));
    for (const CodecAlias& a : codec_aliases()) {
        const Codec* c = find_codec(a.alias);
        ASSERT_NE(c, nullptr) << a.alias;
        EXPECT_EQ(c->name, a.name);
        EXPECT_EQ(c->name.find("dering"), std::string_view::npos) << c->name;
        for (const Codec& e : codecs()) EXPECT_NE(e.name, a.alias) << "an alias may not name a table entry";
        // The command line's list resolves it to the entry, in place.
        auto chosen = select_codecs("sh3," + std::string(a.alias));
        ASSERT_TRUE(chosen) << chosen.error().message;
        ASSERT_EQ(chosen->size(), 2u);
        EXPECT_EQ((*chosen)[1], c);
        // encode_probe_set takes the alias and stores the entry's name.
        const Sh3Radiance hub = project_directional({0, 0, 1}, {1, 1, 1});
        auto set = encode_probe_set(std::span(&hub, 1), a.alias, CodecOptions{}, ProbeLayout{});
        ASSERT_TRUE(set) << set.error().message;
        EXPECT_EQ(set->representation, a.name);
    }
    EXPECT_EQ(find_codec("zh3_lum_dering_"), nullptr);
}

// The .zhp files zhc wrote under the aliases: read as the entries, the same bytes as encoding the
// same probes now, written back under the entry's name (and that file reads the same).
TEST(CodecNames, OldZhpFilesRead) {
    auto list = read_probe_json(kAliasDir + "maps.json");
    ASSERT_TRUE(list) << list.error().message;
    ASSERT_EQ(list->probes.size(), 8u);
    for (const CodecAlias& a : codec_aliases()) {
        const std::string path = kAliasDir + std::string(a.alias) + ".zhp";
        const std::vector<std::uint8_t> old_bytes = test::read_bytes(path);
        ASSERT_GE(old_bytes.size(), 56u);
        EXPECT_EQ(std::string(reinterpret_cast<const char*>(old_bytes.data() + 24)), a.alias) << "fixture holds the alias";
        auto set = parse_probe_set(old_bytes, path);
        ASSERT_TRUE(set) << set.error().message;
        EXPECT_EQ(set->representation, a.name);
        auto fresh = encode_probe_set(list->probes, a.name, CodecOptions{}, ProbeLayout{});
        ASSERT_TRUE(fresh) << fresh.error().message;
        EXPECT_EQ(set->payload, fresh->payload) << a.name << ": the encoder's bytes";
        auto rewritten = serialize_probe_set(*set);
        ASSERT_TRUE(rewritten) << rewritten.error().message;
        EXPECT_EQ(std::string(reinterpret_cast<const char*>(rewritten->data() + 24)), a.name);
        ASSERT_EQ(rewritten->size(), old_bytes.size());
        // Only the name field and the header CRC differ from the old file.
        for (size_t i = 0; i < old_bytes.size(); ++i)
            if (i < 24 || (i >= 56 && i < 180) || i >= 184) {
                EXPECT_EQ((*rewritten)[i], old_bytes[i]) << "byte " << i;
            }
        auto again = parse_probe_set(*rewritten, "rewritten");
        ASSERT_TRUE(again) << again.error().message;
        EXPECT_EQ(again->representation, a.name);
        EXPECT_EQ(again->payload, set->payload);
    }
}

// The glTF file zhc embedded under the alias reads as the entry; embedding it again writes the
// entry's name.
TEST(CodecNames, OldGltfFilesRead) {
    const std::string path = kAliasDir + "zh3_lum_dering.gltf";
    const std::vector<std::uint8_t> bytes = test::read_bytes(path);
    const std::string text(bytes.begin(), bytes.end());
    ASSERT_NE(text.find("\"encoding\": \"zh3_lum_dering\""), std::string::npos) << "fixture holds the alias";
    auto summary = read_gltf_probes(bytes, path);
    ASSERT_TRUE(summary) << summary.error().message;
    ASSERT_EQ(summary->volumes.size(), 1u);
    const ProbeSet& set = summary->volumes[0].set;
    EXPECT_EQ(set.representation, "zh3_lum_axis_clamp");
    auto zhp = parse_probe_set(test::read_bytes(kAliasDir + "zh3_lum_dering.zhp"), "zhp");
    ASSERT_TRUE(zhp) << zhp.error().message;
    EXPECT_EQ(set.payload, zhp->payload);
    GltfEmbedOptions o;
    o.binary = false;
    const std::string scene = R"({"asset":{"version":"2.0"}})";
    auto out = embed_probes_gltf(std::span(reinterpret_cast<const std::uint8_t*>(scene.data()), scene.size()), "scene.gltf", set, o);
    ASSERT_TRUE(out) << out.error().message;
    const std::string written(out->begin(), out->end());
    EXPECT_NE(written.find("\"zh3_lum_axis_clamp\""), std::string::npos);
    EXPECT_EQ(written.find("dering"), std::string::npos);
}

}  // namespace
}  // namespace zhc
