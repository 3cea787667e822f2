// --depfile and the file recorder (formats/io/depfile.h, formats/io/file_io.h FileRecorder): the
// escaping against a reader written from Ninja's and Make's rules, the recorder across threads,
// and `zhc ... --depfile` on real scenes, glTF assets and lightmaps (docs/build-integration.md).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "formats/io/depfile.h"
#include "formats/io/file_io.h"
#include "formats/lightmap/lightmap_exr.h"
#include "support.h"

namespace fs = std::filesystem;
using namespace zhc;
using namespace zhc::test;

namespace {

// The slow twin of make_depfile: a reader of one rule as Ninja's depfile parser reads it (and GNU
// Make for these escapes): `\ ` is a space, `\#` a '#', `\:` a ':', `$$` a '$', backslash-newline a
// separator, an unescaped ':' followed by whitespace ends the targets.
struct Rule {
    std::vector<std::string> targets, prerequisites;
};
Rule read_rule(const std::string& text) {
    Rule r;
    std::vector<std::string>* into = &r.targets;
    std::string word;
    auto flush = [&] {
        if (!word.empty()) into->push_back(word);
        word.clear();
    };
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        const char n = i + 1 < text.size() ? text[i + 1] : '\0';
        if (c == '\\' && (n == ' ' || n == '#' || n == ':')) {
            word += n;
            ++i;
        } else if (c == '\\' && n == '\n') {
            flush();
            ++i;
        } else if (c == '$' && n == '$') {
            word += '$';
            ++i;
        } else if (c == ':' && (n == ' ' || n == '\n' || n == '\0') && into == &r.targets) {
            flush();
            into = &r.prerequisites;
        } else if (c == ' ' || c == '\n') {
            flush();
        } else {
            word += c;
        }
    }
    flush();
    return r;
}

std::string text_of(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

}  // namespace

TEST(Depfile, EscapesAsNinjaAndMakeExpect) {
    EXPECT_EQ(*escape_depfile_path("plain/path.exr"), "plain/path.exr");
    EXPECT_EQ(*escape_depfile_path("a b"), "a\\ b");
    EXPECT_EQ(*escape_depfile_path("c#1"), "c\\#1");
    EXPECT_EQ(*escape_depfile_path("$HOME"), "$$HOME");
    EXPECT_EQ(*escape_depfile_path("C:/maps/x.exr"), "C\\:/maps/x.exr");
    EXPECT_EQ(*escape_depfile_path("back\\slash"), "back\\slash");  // a backslash before other bytes is literal
    for (const std::string& bad : {std::string(), std::string("new\nline"), std::string("tab\there"), std::string("cr\r"),
                                  std::string("nul\0x", 5), std::string("ends\\"), std::string("a\\ b"),
                                  std::string("a\\#b"), std::string("a\\:b"), std::string("colon:")}) {
        auto e = escape_depfile_path(bad);
        ASSERT_FALSE(e) << bad;
        EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument);
        EXPECT_NE(e.error().message.find("a depfile cannot name this path"), std::string::npos);
    }
}

TEST(Depfile, RuleRoundTripsThroughAReader) {
    const std::vector<std::string> outs = {"out dir/probes.zhp", "x$y#z.glb"};
    const std::vector<std::string> ins = {"scenes/room.json", "../maps dir/c#it$y.exr", "a:b/c d.bin", "k\\l", "\xc3\xa9t\xc3\xa9.hdr"};
    auto text = make_depfile(outs, ins);
    ASSERT_TRUE(text);
    EXPECT_EQ(text->back(), '\n');
    const Rule r = read_rule(*text);
    EXPECT_EQ(r.targets, outs);
    EXPECT_EQ(r.prerequisites, ins);
    // No inputs: a rule with targets only. No outputs: refused.
    EXPECT_EQ(*make_depfile({"a"}, {}), "a:\n");
    EXPECT_FALSE(make_depfile({}, {"x"}));
    EXPECT_FALSE(make_depfile({"ok"}, {"bad\n"}));
}

TEST(Depfile, RecorderKeepsFirstSeenOrderOnceAcrossThreads) {
    const std::string dir = fresh_dir("depfile_recorder");
    std::vector<std::string> files;
    for (int i = 0; i < 8; ++i) {
        files.push_back(dir + "/f" + std::to_string(i));
        write_bytes(files.back(), {std::uint8_t(i)});
    }
    FileRecorder rec;
    {
        ScopedFileRecording on(&rec);
        ASSERT_TRUE(read_file_bytes(files[0], 16));
        std::vector<std::thread> workers;
        for (int t = 0; t < 4; ++t)
            workers.emplace_back([&] {
                for (int k = 0; k < 50; ++k)
                    for (size_t i = 1; i < files.size(); ++i) {
                        auto b = read_file_prefix(files[i], 1);
                        ASSERT_TRUE(b);
                    }
            });
        for (auto& w : workers) w.join();
        EXPECT_FALSE(read_file_bytes(dir + "/missing", 16));  // a failed open is not a read
        ASSERT_TRUE(write_file_atomic(dir + "/out", {1, 2, 3}));
        ASSERT_TRUE(write_files_atomic({{dir + "/o1", {1}}, {dir + "/o2", {2}}}));
    }
    ASSERT_TRUE(read_file_bytes(files[1], 16));  // after the scope: not recorded
    const auto inputs = rec.inputs();
    ASSERT_EQ(inputs.size(), files.size());
    EXPECT_EQ(inputs[0], files[0]);
    EXPECT_EQ(std::vector<std::string>(inputs.begin() + 1, inputs.end()).size(), files.size() - 1);
    for (const auto& f : files) EXPECT_NE(std::find(inputs.begin(), inputs.end(), f), inputs.end()) << f;
    EXPECT_EQ(rec.outputs(), (std::vector<std::string>{dir + "/out", dir + "/o1", dir + "/o2"}));
}

TEST(DepfileCli, BakeNamesSceneAndEnvironmentMap) {
    const std::string dir = fresh_dir("depfile_bake");
    fs::create_directories(dir + "/maps dir");
    fs::create_directories(dir + "/scenes");
    const std::string map = dir + "/maps dir/c#it$y.exr";
    fs::copy_file(std::string(ZHC_ENVMAP_DIR) + "/city.exr", map);
    const std::string scene = dir + "/scenes/room.json";
    std::ofstream(scene) << R"({"format":"zhc-scene","version":1,"probes":{"grid":{"min":[0,0,0],"max":[1,1,1],"counts":[2,2,2]}},
                                "environment":{"map":"../maps dir/c#it$y.exr"}})";
    const std::string out = dir + "/out.zhp", dep = dir + "/out.d";
    auto r = run_zhc({"bake", scene, "-o", out, "--depfile", dep, "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Rule rule = read_rule(text_of(dep));
    EXPECT_EQ(rule.targets, std::vector<std::string>{out});
    ASSERT_EQ(rule.prerequisites.size(), 2u) << text_of(dep);
    EXPECT_EQ(rule.prerequisites[0], scene);
    EXPECT_EQ(rule.prerequisites[1], dir + "/scenes/../maps dir/c#it$y.exr");  // as opened: relative to the scene
    EXPECT_TRUE(fs::equivalent(rule.prerequisites[1], map));

    // `zhc info --inputs` lists the same files, without baking (for rules that declare inputs).
    auto info = run_zhc({"info", "--inputs", scene});
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_EQ(info.out, rule.prerequisites[0] + "\n" + rule.prerequisites[1] + "\n");

    // A failing command leaves an earlier depfile alone, and writes none where there was none.
    const std::string before = text_of(dep);
    fs::remove(map);
    r = run_zhc({"bake", scene, "-o", dir + "/other.zhp", "--depfile", dep, "--quiet"});
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_EQ(text_of(dep), before);
    fs::remove(dep);
    r = run_zhc({"bake", scene, "-o", dir + "/other.zhp", "--depfile", dep, "--quiet"});
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_FALSE(fs::exists(dep));
    EXPECT_FALSE(fs::exists(dir + "/other.zhp"));
}

TEST(DepfileCli, GltfSceneNamesItsBuffersAndEmbeddedImages) {
    const std::string dir = fresh_dir("depfile_gltf");
    fs::create_directories(dir + "/in");
    fs::create_directories(dir + "/out");
    for (const char* f : {"gt_list.gltf", "gt_list.bin", "tex.png"})
        fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/gltf/" + f, dir + "/in/" + f);
    // -o .glb in another folder embeds the image: the bake reads the asset, its buffer and its image.
    const std::string out = dir + "/out/lit.glb", dep = dir + "/out/lit.d";
    auto r = run_zhc({"bake", dir + "/in/gt_list.gltf", "-o", out, "--depfile", dep, "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Rule rule = read_rule(text_of(dep));
    EXPECT_EQ(rule.targets, std::vector<std::string>{out});
    EXPECT_EQ(rule.prerequisites,
              (std::vector<std::string>{dir + "/in/gt_list.gltf", dir + "/in/gt_list.bin", dir + "/in/tex.png"}));
    // info --inputs: what loading the scene reads (-o .zhp reads exactly these; the image only
    // when a glTF output in another folder embeds it).
    auto info = run_zhc({"info", "--inputs", dir + "/in/gt_list.gltf"});
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_EQ(info.out, dir + "/in/gt_list.gltf\n" + dir + "/in/gt_list.bin\n");
    // gltf embed: the asset, its buffer and image, and the probe set.
    const std::string probes = dir + "/out/p.zhp";
    ASSERT_EQ(run_zhc({"bake", dir + "/in/gt_list.gltf", "-o", probes, "--quiet"}).exit_code, 0);
    r = run_zhc({"gltf", "embed", dir + "/in/gt_list.gltf", probes, "-o", dir + "/out/e.glb", "--depfile", dep});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Rule embed = read_rule(text_of(dep));
    EXPECT_EQ(embed.targets, std::vector<std::string>{dir + "/out/e.glb"});
    for (const std::string& f : {dir + "/in/gt_list.gltf", dir + "/in/gt_list.bin", dir + "/in/tex.png", probes})
        EXPECT_NE(std::find(embed.prerequisites.begin(), embed.prerequisites.end(), f), embed.prerequisites.end()) << f << "\n" << text_of(dep);
}

TEST(DepfileCli, LightmapEncodeNamesEveryPartAndEveryOutput) {
    const std::string dir = fresh_dir("depfile_lightmap");
    const std::string sh = dir + "/sh.exr";
    auto r = run_zhc({"lightmap", "synth", std::string(ZHC_ENVMAP_DIR) + "/studio.exr", "-o", sh, "--size", "16", "--depfile", dir + "/synth.d"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    Rule rule = read_rule(text_of(dir + "/synth.d"));
    EXPECT_EQ(rule.targets, std::vector<std::string>{sh});
    EXPECT_EQ(rule.prerequisites, std::vector<std::string>{std::string(ZHC_ENVMAP_DIR) + "/studio.exr"});

    // The report names its input relative to --paths-relative-to, else as given.
    r = run_zhc({"lightmap", "audit", sh, "--json", "--quality", "fast", "--paths-relative-to", dir + "/x/.."});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\"input\": \"sh.exr\""), std::string::npos) << r.out;
    r = run_zhc({"lightmap", "audit", sh, "--json", "--quality", "fast"});
    EXPECT_NE(r.out.find("\"input\": \"" + sh + "\""), std::string::npos) << r.out;
    r = run_zhc({"lightmap", "audit", sh, "--json", "--quality", "fast", "--targets", "bc", "--paths-relative-to", dir});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\"input\": \"sh.exr\""), std::string::npos) << r.out;

    r = run_zhc({"lightmap", "encode", sh, "-o", dir + "/lm", "--quality", "fast", "--depfile", dir + "/enc.d"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    rule = read_rule(text_of(dir + "/enc.d"));
    EXPECT_EQ(rule.targets, (std::vector<std::string>{dir + "/lm.iz.ktx2", dir + "/lm.d.ktx2", dir + "/lm.wa.ktx2"}));
    EXPECT_EQ(rule.prerequisites, std::vector<std::string>{sh});

    // A {i} name: the depfile names the parts it expanded to (here 4: no coef4..8 exist).
    std::vector<std::string> parts;
    for (int i = 0; i < 4; ++i) {
        parts.push_back(dir + "/coef" + std::to_string(i) + ".exr");
        std::vector<float> rgb(8 * 8 * 3, i == 0 ? 1.0f : 0.1f);
        auto w = ExrBandWriter::open(parts.back(), 8, 8, {"R", "G", "B"}, false);
        ASSERT_TRUE(w.ok());
        ASSERT_TRUE((*w)->write_rows(rgb.data(), 8).ok());
        ASSERT_TRUE((*w)->commit().ok());
    }
    r = run_zhc({"lightmap", "encode", dir + "/coef{i}.exr", "-o", dir + "/lin", "--solve", "linear", "--quiet", "--depfile", dir + "/lin.d"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    rule = read_rule(text_of(dir + "/lin.d"));
    EXPECT_EQ(rule.targets, (std::vector<std::string>{dir + "/lin.iz.ktx2", dir + "/lin.d.ktx2", dir + "/lin.wa.ktx2"}));
    EXPECT_EQ(rule.prerequisites, parts);

    r = run_zhc({"lightmap", "decode", dir + "/lm", "-o", dir + "/back.exr", "--depfile", dir + "/dec.d"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    rule = read_rule(text_of(dir + "/dec.d"));
    EXPECT_EQ(rule.targets, std::vector<std::string>{dir + "/back.exr"});
    EXPECT_EQ(rule.prerequisites, (std::vector<std::string>{dir + "/lm.iz.ktx2", dir + "/lm.d.ktx2", dir + "/lm.wa.ktx2"}));
}

TEST(DepfileCli, RefusesAnInputAsDepfileAndAVerbThatWroteNothing) {
    const std::string dir = fresh_dir("depfile_refuse");
    const std::string env = std::string(ZHC_ENVMAP_DIR) + "/studio.exr";
    fs::copy_file(env, dir + "/in.exr");
    auto r = run_zhc({"convert", dir + "/in.exr", "-o", dir + "/p.zhp", "-r", "sh3", "--depfile", dir + "/in.exr"});
    EXPECT_EQ(r.exit_code, 7) << r.err;
    EXPECT_NE(r.err.find("--depfile"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/p.zhp"));  // no output stands without its depfile
    EXPECT_EQ(read_bytes(dir + "/in.exr"), read_bytes(env));
    // audit without --markdown/--html/--images writes nothing: nothing to name as the target.
    r = run_zhc({"audit", env, "-r", "sh3", "--no-timing", "--threads", "2", "--depfile", dir + "/a.d"});
    EXPECT_EQ(r.exit_code, 7) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/a.d"));
    r = run_zhc({"audit", env, "-r", "sh3", "--no-timing", "--threads", "2", "--markdown", dir + "/a.md", "--depfile", dir + "/a.d"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Rule rule = read_rule(text_of(dir + "/a.d"));
    EXPECT_EQ(rule.targets, std::vector<std::string>{dir + "/a.md"});
    EXPECT_EQ(rule.prerequisites, std::vector<std::string>{env});
}
