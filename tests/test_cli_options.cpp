// The CLI's shared option names: every verb spells the representation, thread count,
// JSON output and environment-map reading options the same way (cli/cli.h add_*_option), keeps
// its alias (--to, --encoding) where it has one, and takes --threads over the same range.
#include <algorithm>
#include <sstream>

#include "support.h"

namespace zhc {
namespace {

struct VerbOptions {
    std::vector<std::string> verb;   // e.g. {"lightmap", "audit"}
    std::vector<std::string> names;  // the option spellings its --help must list, exactly so
};

// The table: one row per verb that takes any shared option. A verb or subverb that is missing
// here fails SharedOptions.EveryVerbIsInTheTable.
const std::vector<VerbOptions>& table() {
    static const std::vector<VerbOptions> t = {
        {{"demo"}, {"--threads"}},
        {{"bake"}, {"-r,--representations,--to", "--threads", "--progress", "--quiet", "--depfile"}},
        {{"project"}, {"--json", "--threads", "--replace-non-finite", "--part", "--latlong", "--ldr-encoding"}},
        {{"audit"}, {"-r,--representations", "--json", "--threads", "--replace-non-finite", "--part", "--latlong", "--ldr-encoding", "--progress", "--quiet", "--depfile", "--paths-relative-to"}},
        {{"convert"}, {"-r,--representations,--to", "--threads", "--replace-non-finite", "--part", "--latlong", "--ldr-encoding", "--depfile"}},
        {{"info"}, {"--json"}},
        {{"bench"}, {"-r,--representations", "--json"}},
        {{"dering"}, {"--threads", "--replace-non-finite", "--part", "--latlong", "--ldr-encoding", "--depfile", "--paths-relative-to"}},
        {{"gltf", "embed"}, {"-r,--representations,--encoding", "--depfile"}},
        {{"gltf", "extract"}, {"--depfile"}},
        {{"gltf", "eval"}, {}},
        {{"lightmap", "encode"}, {"--threads", "--progress", "--quiet", "--depfile"}},
        {{"lightmap", "decode"}, {"--progress", "--quiet", "--depfile"}},
        {{"lightmap", "audit"}, {"--json", "--threads", "--progress", "--quiet", "--depfile", "--paths-relative-to"}},
        {{"lightmap", "synth"}, {"--threads", "--part", "--latlong", "--progress", "--quiet", "--depfile"}},
    };
    return t;
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : " ") + x;
    return s;
}

// The option column of --help: the first token of each line that starts (after spaces) with '-'.
std::vector<std::string> listed_options(const std::string& help) {
    std::vector<std::string> out;
    std::istringstream in(help);
    std::string line;
    while (std::getline(in, line)) {
        const size_t b = line.find_first_not_of(' ');
        if (b == std::string::npos || line[b] != '-' || b > 4) continue;
        const size_t e = line.find(' ', b);
        out.push_back(line.substr(b, e == std::string::npos ? std::string::npos : e - b));
    }
    return out;
}

std::vector<std::string> with(std::vector<std::string> v, std::vector<std::string> more) {
    v.insert(v.end(), more.begin(), more.end());
    return v;
}

TEST(SharedOptions, EveryVerbListsTheSharedNames) {
    // Spellings that may only appear as aliases beside the shared name, never alone.
    const std::vector<std::string> old_alone = {"--to", "--encoding", "--representations", "-r"};
    for (const VerbOptions& v : table()) {
        const auto r = test::run_zhc(with(v.verb, {"--help"}));
        ASSERT_EQ(r.exit_code, 0) << joined(v.verb) << ": " << r.err;
        const std::vector<std::string> listed = listed_options(r.out);
        for (const std::string& name : v.names)
            EXPECT_NE(std::find(listed.begin(), listed.end(), name), listed.end())
                << "zhc " << joined(v.verb) << " --help does not list " << name << ":\n" << r.out;
        for (const std::string& o : listed) {
            EXPECT_EQ(std::find(old_alone.begin(), old_alone.end(), o), old_alone.end())
                << "zhc " << joined(v.verb) << ": " << o << " outside the shared -r,--representations spelling";
            // Every shared option this verb takes is in its row (a new one must be added there).
            const bool shared = o.find("--representations") != std::string::npos || o == "--threads" || o == "--json" ||
                                o == "--part" || o == "--replace-non-finite" || o == "--latlong" || o == "--ldr-encoding" || o == "--progress" || o == "--quiet" ||
                                o == "--depfile" || o == "--paths-relative-to";
            if (shared) {
                EXPECT_NE(std::find(v.names.begin(), v.names.end(), o), v.names.end())
                    << "zhc " << joined(v.verb) << " lists " << o << " but its row in the table does not";
            }
        }
        // --threads: the same range and meaning everywhere.
        if (std::find(v.names.begin(), v.names.end(), "--threads") != v.names.end()) {
            EXPECT_NE(r.out.find("--threads INT:INT in [0 - 256]"), std::string::npos) << joined(v.verb) << ":\n" << r.out;
            EXPECT_NE(r.out.find("0 = all cores"), std::string::npos) << joined(v.verb);
        }
    }
}

// `zhc --help` and `zhc gltf/lightmap --help` name no verb the table lacks.
TEST(SharedOptions, EveryVerbIsInTheTable) {
    auto subcommands = [](const std::string& help) {
        std::vector<std::string> names;
        std::istringstream in(help);
        std::string line;
        bool in_list = false;
        while (std::getline(in, line)) {
            if (line == "Subcommands:") {
                in_list = true;
                continue;
            }
            if (!in_list) continue;
            if (line.rfind("  ", 0) != 0) break;
            const size_t b = line.find_first_not_of(' ');
            names.push_back(line.substr(b, line.find(' ', b) - b));
        }
        return names;
    };
    auto in_table = [](const std::vector<std::string>& verb) {
        for (const VerbOptions& v : table())
            if (v.verb == verb || (verb.size() == 1 && v.verb.size() == 2 && v.verb[0] == verb[0])) return true;
        return false;
    };
    const auto top = test::run_zhc({"--help"});
    ASSERT_EQ(top.exit_code, 0);
    const auto verbs = subcommands(top.out);
    EXPECT_GE(verbs.size(), 10u) << top.out;
    for (const std::string& verb : verbs) {
        EXPECT_TRUE(in_table({verb})) << "verb " << verb << " is not in test_cli_options' table";
        const auto sub = test::run_zhc({verb, "--help"});
        for (const std::string& s : subcommands(sub.out))
            EXPECT_TRUE(in_table({verb, s})) << "zhc " << verb << " " << s << " is not in test_cli_options' table";
    }
}

// The aliases are the same option: the old spelling writes the same bytes as -r/--representations.
TEST(SharedOptions, OldSpellingsAreAliases) {
    const std::string dir = test::fresh_dir("cli_options_alias");
    const std::string map = test::envmap_paths()[0];
    for (const std::string spelling : {"-r", "--representations", "--to"})
        ASSERT_EQ(test::run_zhc({"convert", map, "-o", dir + "/c" + spelling + ".zhp", spelling, "zh3_q16"}).exit_code, 0) << spelling;
    const auto ref = test::read_bytes(dir + "/c-r.zhp");
    EXPECT_GT(ref.size(), 16u);
    EXPECT_EQ(test::read_bytes(dir + "/c--representations.zhp"), ref);
    EXPECT_EQ(test::read_bytes(dir + "/c--to.zhp"), ref);
    const std::string scene = std::string(ZHC_TEST_DATA_DIR) + "/gltf/gt_list.glb";
    ASSERT_EQ(test::run_zhc({"gltf", "embed", scene, dir + "/c-r.zhp", "-o", dir + "/e1.glb", "--encoding", "sh3"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"gltf", "embed", scene, dir + "/c-r.zhp", "-o", dir + "/e2.glb", "-r", "sh3"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(dir + "/e1.glb"), test::read_bytes(dir + "/e2.glb"));
    EXPECT_NE(test::read_bytes(dir + "/e1.glb").size(), 0u);
    // A verb that stores one representation refuses a list (exit 2), one that audits takes it:
    // tests/conformance cli_usage_one_repr, ok_audit.
}

// --threads 0 (all cores) is accepted wherever --threads is, and changes no output.
TEST(SharedOptions, ThreadsZeroMeansAllCoresAndSameOutput) {
    const std::string map = test::envmap_paths()[0];
    const auto one = test::run_zhc({"project", map, "--json", "--threads", "1"});
    const auto all = test::run_zhc({"project", map, "--json", "--threads", "0"});
    ASSERT_EQ(one.exit_code, 0) << one.err;
    ASSERT_EQ(all.exit_code, 0) << all.err;
    EXPECT_EQ(one.out, all.out);  // 257 and -1: exit 2 (conformance cli_usage_threads_*)
    const std::string dir = test::fresh_dir("cli_options_threads");
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "--size", "8", "-o", dir + "/a.exr", "--threads", "0"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"lightmap", "synth", map, "--size", "8", "-o", dir + "/b.exr", "--threads", "1"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(dir + "/a.exr"), test::read_bytes(dir + "/b.exr"));
    ASSERT_EQ(test::run_zhc({"convert", map, "-o", dir + "/a.json", "--threads", "0"}).exit_code, 0);
    ASSERT_EQ(test::run_zhc({"convert", map, "-o", dir + "/b.json", "--threads", "1"}).exit_code, 0);
    EXPECT_EQ(test::read_bytes(dir + "/a.json"), test::read_bytes(dir + "/b.json"));
}

}  // namespace
}  // namespace zhc
