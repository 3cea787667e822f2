// `zhc convert --engine` and `zhc bake --engine` (cli/engine_output.h): every entry of
// engine_files() written from a baked grid and read back by `zhc convert` as input, against the
// probes of its engine layout (round_trip_probes through layout_codec); the printed error is the
// file's; engine files are recognised before environment maps (three.js's atlas is an OpenEXR);
// the refusals (extension, options that do not apply, a damaged file) exit with their documented
// codes and write nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "formats/engines/engine_files.h"
#include "formats/probes/probe_file.h"
#include "tests/support.h"

namespace zhc {
namespace {

const std::string kRoom = std::string(ZHC_TEST_DATA_DIR) + "/../../examples/room.json";

// The room's baked grid, once (a .zhp of sh3 probes).
const std::string& room_zhp() {
    static const std::string path = [] {
        const std::string dir = test::temp_dir("engine_file_cli_room");
        const std::string p = dir + "/room.zhp";
        const auto r = test::run_zhc({"bake", kRoom, "-o", p, "--quiet"});
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return p;
    }();
    return path;
}

double max_abs(const Sh3Radiance& a) {
    double m = 0;
    for (int i = 0; i < 9; ++i)
        for (int c = 0; c < 3; ++c) m = std::max(m, std::fabs(double(a[i][c])));
    return m;
}

TEST(EngineFileCli, EveryEngineFileRoundTripsThroughTheCommand) {
    const std::string dir = test::fresh_dir("engine_file_cli");
    auto source = read_probe_file(room_zhp());
    ASSERT_TRUE(source.ok()) << source.error().message;
    auto hub = decode_probe_set(*source);
    ASSERT_TRUE(hub.ok());
    ASSERT_FALSE(engine_files().empty());
    for (const EngineFile& f : engine_files()) {
        SCOPED_TRACE(std::string(f.name));
        const std::string out = dir + "/probes_" + std::string(f.name) + std::string(f.extension);
        const auto w = test::run_zhc({"convert", room_zhp(), "-o", out, "--engine", std::string(f.name)});
        ASSERT_EQ(w.exit_code, 0) << w.err;
        EXPECT_NE(w.out.find("irradiance against the input: RMS error"), std::string::npos) << w.out;
        EXPECT_NE(w.out.find(std::string(f.layout_codec)), std::string::npos) << w.out;
        EXPECT_TRUE(f.sniff(test::read_bytes(out)));
        // The file as input: the probes of its layout (what the engine sees), in the grid's order.
        const std::string back = dir + "/back_" + std::string(f.name) + ".json";
        const auto r = test::run_zhc({"convert", out, "-o", back});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        auto list = read_probe_json(back);
        ASSERT_TRUE(list.ok()) << list.error().message;
        ASSERT_EQ(list->probes.size(), hub->size());
        EXPECT_NE(list->layout.kind, ProbeLayoutKind::kNone);  // a grid, or (Godot) the grid's points
        auto expected = round_trip_probes(*hub, f.layout_codec, source->params, source->layout);
        ASSERT_TRUE(expected.ok()) << expected.error().message;
        double worst = 0;
        for (size_t p = 0; p < hub->size(); ++p) {
            const double scale = std::max(max_abs((*expected)[p]), 1e-6);
            for (int i = 0; i < 9; ++i)
                for (int c = 0; c < 3; ++c)
                    worst = std::max(worst, std::fabs(double(list->probes[p][i][c]) - double((*expected)[p][i][c])) / scale);
        }
        // The file stores the layout's own values (floats printed to round trip; halves; RGB9E5):
        // back through the engine's decode they are its probes up to float rounding.
        EXPECT_LT(worst, 1e-5) << f.name;
        std::printf("%-24s %s: worst difference from %s's probes %.2e of the probe's largest coefficient\n",
                    std::string(f.name).c_str(), std::string(f.extension).c_str(), std::string(f.layout_codec).c_str(), worst);
    }
}

TEST(EngineFileCli, BakeWritesTheEngineFileAsConvertDoes) {
    const std::string dir = test::fresh_dir("engine_file_cli_bake");
    const auto b = test::run_zhc({"bake", kRoom, "-o", dir + "/room.tres", "--engine", "godot_lightmap_gi", "--quiet"});
    ASSERT_EQ(b.exit_code, 0) << b.err;
    const auto c = test::run_zhc({"convert", room_zhp(), "-o", dir + "/conv.tres", "--engine", "godot_lightmap_gi"});
    ASSERT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(test::read_bytes(dir + "/room.tres"), test::read_bytes(dir + "/conv.tres"));
}

TEST(EngineFileCli, RefusalsWriteNothing) {
    const std::string dir = test::fresh_dir("engine_file_cli_refusals");
    struct Case {
        std::vector<std::string> args;
        int code;
        const char* says;
    };
    const std::string out = dir + "/out.tres";
    const Case cases[] = {
        {{"convert", room_zhp(), "-o", dir + "/out.ktx2", "--engine", "godot_lightmap_gi"}, 2, "the output must end in .tres"},
        {{"convert", room_zhp(), "-o", out, "--engine", "godot_lightmap_gi", "-r", "zh3_q16"}, 2, "do not apply"},
        {{"convert", room_zhp(), "-o", out, "--engine", "godot_lightmap_gi", "--zstd", "3"}, 2, "do not apply"},
        {{"convert", room_zhp(), "-o", out, "--engine", "no_such_engine"}, 2, "no_such_engine"},
        {{"bake", kRoom, "-o", dir + "/out.ktx2", "--engine", "bevy_irradiance_volume", "--zstd", "3"}, 2, "do not apply"},
        {{"bake", kRoom, "-o", out, "--engine", "bevy_irradiance_volume"}, 2, "the output must end in .ktx2"},
        {{"convert", room_zhp(), "-o", dir + "/out.tres"}, 2, "--engine NAME"},
    };
    for (const Case& c : cases) {
        const auto r = test::run_zhc(c.args);
        EXPECT_EQ(r.exit_code, c.code) << c.args[3] << " " << r.err;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir));
    // A damaged engine file as input: one line, exit 4, no output.
    const auto w = test::run_zhc({"convert", room_zhp(), "-o", dir + "/good.tres", "--engine", "godot_lightmap_gi"});
    ASSERT_EQ(w.exit_code, 0) << w.err;
    std::vector<std::uint8_t> bytes = test::read_bytes(dir + "/good.tres");
    bytes.resize(bytes.size() / 2);
    test::write_bytes(dir + "/bad.tres", bytes);
    const auto r = test::run_zhc({"convert", dir + "/bad.tres", "-o", dir + "/bad.json"});
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("bad.tres"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/bad.json"));
}

// three.js's atlas is an OpenEXR: `zhc convert` reads it as the grid it holds, not as an
// environment map (one probe).
TEST(EngineFileCli, ThreejsAtlasIsNotReadAsAnEnvironmentMap) {
    const std::string dir = test::fresh_dir("engine_file_cli_exr");
    const auto w = test::run_zhc({"convert", room_zhp(), "-o", dir + "/grid.exr", "--engine", "threejs_grid_exr"});
    ASSERT_EQ(w.exit_code, 0) << w.err;
    const auto r = test::run_zhc({"convert", dir + "/grid.exr", "-o", dir + "/grid.json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto list = read_probe_json(dir + "/grid.json");
    ASSERT_TRUE(list.ok());
    auto source = read_probe_file(room_zhp());
    ASSERT_TRUE(source.ok());
    EXPECT_EQ(list->probes.size(), source->count);
    EXPECT_EQ(list->layout.kind, ProbeLayoutKind::kGrid);
}

}  // namespace
}  // namespace zhc
