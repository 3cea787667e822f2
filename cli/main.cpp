// zhc — baked-lighting codecs for asset pipelines. See README.md.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "cli.h"
#include "codec/probe/quantize.h"
#include "formats/io/depfile.h"
#include "formats/io/file_io.h"

namespace zhc::cli {

namespace {
struct Verb {
    int order;
    VerbSetup setup;
};
std::vector<Verb>& verbs() {
    static std::vector<Verb> v;
    return v;
}
}  // namespace

VerbRegistration::VerbRegistration(int order, VerbSetup setup) { verbs().push_back({order, std::move(setup)}); }

int exit_code_for(const Error& error) {
    switch (error.code) {
        case ErrorCode::kInvalidArgument: return kExitUsage;
        case ErrorCode::kIoError: return kExitInputUnreadable;
        case ErrorCode::kBadFormat:
        case ErrorCode::kTruncated:
        case ErrorCode::kTrailingBytes:
        case ErrorCode::kChecksum:
        case ErrorCode::kInvalidValue: return kExitInvalidInput;
        case ErrorCode::kUnsupported: return kExitUnsupported;
        case ErrorCode::kTooLarge: return kExitTooLarge;
        case ErrorCode::kInternal: return kExitInternal;
    }
    return kExitInternal;
}

int report(const Error& error) {
    std::fprintf(stderr, "zhc: error: %s\n", error.message.c_str());
    return exit_code_for(error);
}

int report_output(const Error& error) {
    std::fprintf(stderr, "zhc: error: %s\n", error.message.c_str());
    return kExitOutputFailed;
}

int report_write(const Error& error) {
    return error.code == ErrorCode::kInvalidValue ? report(error) : report_output(error);
}

CLI::Option* add_representations_option(CLI::App* app, std::string& names, RepresentationCount count,
                                        const std::string& what, const std::string& other_name) {
    const bool one = count == RepresentationCount::kOne;
    std::string spelling = "-r,--representations";
    if (!other_name.empty()) spelling += "," + other_name;
    std::string help = (one ? "one codec table representation (e.g. zh3_q16, sh3_q28, sh2_q, sh3)"
                            : "comma-separated subset of the codec table") + (what.empty() ? "" : "; " + what);
    if (!other_name.empty()) help += "; " + other_name + " is another name for -r, the same option";
    CLI::Option* opt = app->add_option(spelling, names, help)->type_name(one ? "NAME" : "NAME,...");
    if (one)
        opt->check(CLI::Validator(
            [](const std::string& v) -> std::string {
                return v.find(',') == std::string::npos ? std::string() : "takes one representation, not a list";
            },
            "", "single name"));
    return opt;
}

const Codec* representation_named(const std::string& name) {
    // select_codecs on the one name: its message names the value and lists the table ("," stands
    // for an empty name, which select_codecs would read as the whole table).
    auto one = select_codecs(name.empty() ? std::string_view(",") : std::string_view(name));
    if (!one) {
        report(one.error());
        return nullptr;
    }
    return one->front();
}

StorageOptionUse storage_options_used(const Codec& codec) {
    StorageOptionUse u;
    if (codec.packed) {
        u.bits = u.sqrt = u.dc = true;
        const PackedLayout layout = codec.packed->layout;
        u.l2_bound = layout == PackedLayout::kSh3Q28;
        u.zonal_mapping = layout == PackedLayout::kSh3Q28 || layout == PackedLayout::kZh3Q16;
    }
    u.axis = codec.traits.zonal_axis == ZonalAxis::kFromParams;
    return u;
}

int refuse_output_over_input(const std::string& option, const std::string& output, const std::vector<std::string>& inputs) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path out_canonical = fs::weakly_canonical(output, ec);
    const bool out_exists = fs::exists(output, ec);
    for (const std::string& input : inputs) {
        if (!fs::is_regular_file(input, ec)) continue;  // folders and missing files: never the output
        bool same = false;
        if (out_exists) {
            same = fs::equivalent(output, input, ec) && !ec;  // symlinks, hard links, other spellings
        } else {
            std::error_code ec2;
            const fs::path in_canonical = fs::weakly_canonical(input, ec2);
            same = !ec2 && !out_canonical.empty() && in_canonical == out_canonical;
        }
        if (same) {
            std::fprintf(stderr, "zhc: error: %s %s: is the input %s (choose another output path)\n", option.c_str(),
                         output.c_str(), input.c_str());
            return kExitUsage;
        }
    }
    return kExitOk;
}

CLI::Option* add_threads_option(CLI::App* app, int& threads, const std::string& what) {
    return app->add_option("--threads", threads,
                           "worker threads, 0 = all cores, the default (" + (what.empty() ? std::string("output identical for any count") : what) + ")")
        ->check(CLI::Range(0, 256))
        ->capture_default_str();
}

int resolve_threads(int threads) {
    return threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

CLI::Option* add_json_flag(CLI::App* app, bool& json, const std::string& what) {
    return app->add_flag("--json", json,
                         "print one JSON object on stdout" + (what.empty() ? std::string() : " (" + what + ")") +
                             ": {\"zhc\": version, \"command\": verb, ...}, schema docs/schema/");
}

void add_envmap_read_options(CLI::App* app, bool* replace_non_finite, std::string& part) {
    if (replace_non_finite)
        app->add_flag("--replace-non-finite", *replace_non_finite, "environment map input: replace NaN/Inf pixels by 0 instead of failing");
    app->add_option("--part", part,
                    "multi-part EXR: the part to read (its name, or its index); default: the first with R, G, B or Y channels");
}

CLI::Option* add_latlong_option(CLI::App* app, LatLongConvention& convention, bool* set, const std::string& default_text) {
    return app
        ->add_option_function<std::string>(
            "--latlong",
            [&convention, set](const std::string& name) {
                parse_latlong_convention(name, &convention);  // the check below admits only the two names
                if (set) *set = true;
            },
            "lat-long map orientation: openexr (centre column +X, phi = pi(1 - 2u)) or gltf (the glTF "
            "ecosystem's: centre column glTF +X = zhc +Y, phi = pi(3/2 - 2u)); cube maps are unaffected; " +
                default_text)
        ->check(CLI::IsMember({"openexr", "gltf"}));
}

CLI::Option* add_ldr_encoding_option(CLI::App* app, LdrDecoding& decoding) {
    return app
        ->add_option_function<std::string>(
            "--ldr-encoding", [&decoding](const std::string& text) { parse_ldr_decoding(text, &decoding); },
            "8-bit cube maps (KTX2 / KTX 1 / DDS RGBA8, BC1-3, BC7): auto (default: sRGB or linear as the format says), "
            "srgb or linear (that transfer function whatever the format says), rgbm:RANGE (rgb * a * RANGE) or "
            "rgbd:RANGE (rgb * (RANGE / 255) / a); docs/inputs.md")
        ->check(
            [](const std::string& text) {
                return parse_ldr_decoding(text, nullptr)
                           ? std::string()
                           : "must be auto, srgb, linear, rgbm:RANGE or rgbd:RANGE with 0 < RANGE <= 65504 (got '" + text + "')";
            },
            "ENCODING");
}

namespace {
std::string& depfile_path() {
    static std::string path;
    return path;
}
}  // namespace

CLI::Option* add_depfile_option(CLI::App* app) {
    return app->add_option("--depfile", depfile_path(),
                           "also write a Make/Ninja depfile here: the files written, then every file read "
                           "(docs/build-integration.md); not written when the command fails")
        ->type_name("FILE");
}

int run_with_depfile(const std::function<int()>& verb) {
    const std::string depfile = depfile_path();
    if (depfile.empty()) return verb();
    FileRecorder recorder;
    int rc;
    {
        ScopedFileRecording recording(&recorder);
        rc = verb();
    }
    if (rc != kExitOk) return rc;
    const std::vector<std::string> outputs = recorder.outputs();
    // A file the command wrote and also read (never the same as an input: refuse_output_over_input)
    // is its own product, not a prerequisite.
    std::vector<std::string> inputs;
    for (const std::string& in : recorder.inputs())
        if (std::find(outputs.begin(), outputs.end(), in) == outputs.end()) inputs.push_back(in);
    auto undo = [&](const std::string& why) {
        std::error_code ec;
        for (const std::string& out : outputs) std::filesystem::remove(out, ec);
        std::fprintf(stderr, "zhc: error: --depfile %s: %s (the files this command wrote are removed again)\n",
                     depfile.c_str(), why.c_str());
        return kExitOutputFailed;
    };
    std::vector<std::string> touched = inputs;
    touched.insert(touched.end(), outputs.begin(), outputs.end());
    for (const std::string& path : touched) {
        std::error_code ec;
        if (std::filesystem::exists(depfile, ec) && std::filesystem::exists(path, ec) &&
            std::filesystem::equivalent(depfile, path, ec) && !ec)
            return undo("is " + path + ", a file this command read or wrote (choose another path)");
    }
    auto text = make_depfile(outputs, inputs);
    if (!text) return undo(text.error().message);
    if (Status st = write_file_atomic(depfile, std::vector<std::uint8_t>(text->begin(), text->end())); !st)
        return undo(st.error().message);
    return kExitOk;
}

CLI::Option* add_paths_relative_to_option(CLI::App* app, std::string& base) {
    return app->add_option("--paths-relative-to", base,
                           "reports (--json, --markdown, --html) name input files relative to this folder "
                           "(default: as given), so a cached report names no run folder")
        ->type_name("DIR");
}

std::string shown_path(const std::string& path, const std::string& base) {
    namespace fs = std::filesystem;
    if (base.empty()) return path;
    std::error_code ec;
    const fs::path p = fs::absolute(path, ec).lexically_normal();
    const fs::path b = fs::absolute(base, ec).lexically_normal();
    const fs::path rel = p.lexically_relative(b);
    return rel.empty() ? p.generic_string() : rel.generic_string();
}

namespace {
// The value of an INT/UINT option as plain decimal: an optional sign (only '+' for UINT), then
// digits. CLI11 converts integers with base auto-detection (strtoll base 0): "020" would be octal
// 16 and "0x10" hexadecimal 16, and a word reached the range check ("abc not in range"). Leading
// zeros are dropped here, so the conversion after sees decimal.
std::string decimal_integer(std::string& value, bool is_unsigned) {
    std::string digits = value;
    std::string sign;
    if (!digits.empty() && (digits[0] == '+' || digits[0] == '-')) {
        if (digits[0] == '-') sign = "-";
        digits.erase(0, 1);
    }
    const bool all_digits = !digits.empty() && std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!all_digits) return "'" + value + "' is not a decimal integer";
    if (is_unsigned && sign == "-") return "'" + value + "' is negative: a count or size is 0 or more";
    const std::size_t first = digits.find_first_not_of('0');
    digits = first == std::string::npos ? "0" : digits.substr(first);
    value = sign + digits;
    return "";
}

void parse_integers_as_decimal(CLI::App* app) {
    for (CLI::Option* opt : app->get_options()) {
        const std::string type = opt->get_type_name();
        const bool is_unsigned = type.rfind("UINT", 0) == 0;
        if (!is_unsigned && type.rfind("INT", 0) != 0) continue;
        if (type.size() > (is_unsigned ? 4u : 3u) && type[is_unsigned ? 4 : 3] != ':') continue;  // e.g. "INTERVAL"
        // transform() runs before the checks added earlier (CLI11 puts transforms first).
        opt->transform(CLI::Validator([is_unsigned](std::string& v) { return decimal_integer(v, is_unsigned); }, "", "decimal"));
    }
    for (CLI::App* sub : app->get_subcommands({})) parse_integers_as_decimal(sub);
}

// The verb that was parsed, innermost ("lightmap encode": encode), and its words.
const CLI::App* parsed_leaf(const CLI::App& app, std::string* words) {
    const CLI::App* at = &app;
    for (;;) {
        const auto parsed = at->get_subcommands();
        if (parsed.empty()) return at;
        at = parsed.front();
        *words += (words->empty() ? "" : " ") + at->get_name();
    }
}

// The options that name a file the verb writes. The verbs check the others themselves: demo's -o is
// a folder it creates and its --html may go into that folder (demo checks it after creating the
// folder), lightmap encode's -o is a prefix (encode checks its first plane).
bool is_file_output(const std::string& verb, const CLI::Option& opt) {
    if (verb == "demo") return false;
    for (const char* name : {"--html", "--markdown", "--depfile"})
        if (opt.check_name(name)) return true;
    return opt.check_name("--output") && verb != "lightmap encode";
}

// Before the work: every file output given must go to a folder that takes new files, and
// --depfile needs a file output to name as its target. kExitOk, or the refusal's exit code.
int check_outputs_before_work(const CLI::App& app) {
    std::string verb;
    const CLI::App* leaf = parsed_leaf(app, &verb);
    bool depfile = false, writes_file = false;
    // A folder the verb creates for its pictures (audit --images) may also receive a report: a file
    // output in a folder that does not exist yet but lies inside it is the verb's to check.
    std::vector<std::filesystem::path> created;
    std::error_code ec;
    for (const CLI::Option* opt : leaf->get_options())
        if (opt->count() > 0 && opt->check_name("--images"))
            created.push_back(std::filesystem::absolute(opt->as<std::string>(), ec).lexically_normal());
    auto inside_created = [&](const std::string& path) {
        const std::filesystem::path folder = std::filesystem::absolute(path, ec).lexically_normal().parent_path();
        if (std::filesystem::exists(folder, ec)) return false;
        for (const auto& c : created) {
            const auto rel = folder.lexically_relative(c);
            if (!rel.empty() && *rel.begin() != "..") return true;
        }
        return false;
    };
    for (const CLI::Option* opt : leaf->get_options()) {
        if (opt->count() == 0) continue;
        if (opt->check_name("--depfile")) depfile = true;
        else if (opt->check_name("--output") || opt->check_name("--html") || opt->check_name("--markdown") || opt->check_name("--images"))
            writes_file = true;
        if (!is_file_output(verb, *opt) || inside_created(opt->as<std::string>())) continue;
        const std::string option = opt->check_name("--output") ? "-o" : opt->get_name();
        if (int rc = refuse_unwritable_output(option, opt->as<std::string>()); rc != kExitOk) return rc;
    }
    if (depfile && !writes_file) {
        std::fprintf(stderr, "zhc: error: --depfile %s: zhc %s writes no file here, and a depfile needs one to name as its target "
                             "(give %s; docs/build-integration.md)\n",
                     depfile_path().c_str(), verb.c_str(), verb == "audit" ? "--markdown, --html or --images" : "--html");
        return kExitOutputFailed;
    }
    return kExitOk;
}
}  // namespace

int refuse_unwritable_output(const std::string& option, const std::string& path) {
    if (Status s = check_folder_takes_files(path); !s) {
        std::fprintf(stderr, "zhc: error: %s %s: %s (checked before the work)\n", option.c_str(), path.c_str(),
                     s.error().message.c_str());
        return kExitOutputFailed;
    }
    return kExitOk;
}

// CLI11 reports a verb it does not know as "A subcommand is required": name the word instead
// ("unknown verb 'bogus'", "unknown verb 'gltf bogus'"). Empty when the verbs on the command line
// are all known.
std::string unknown_verb(const CLI::App& app, int argc, char** argv) {
    const CLI::App* at = &app;
    std::string path;
    for (int i = 1; i < argc && argv[i][0] != '-'; ++i) {
        const auto subs = at->get_subcommands({});
        if (subs.empty()) break;
        const auto it = std::find_if(subs.begin(), subs.end(), [&](const CLI::App* s) { return s->check_name(argv[i]); });
        path += (path.empty() ? "" : " ") + std::string(argv[i]);
        if (it == subs.end()) return "unknown verb '" + path + "'";
        at = *it;
    }
    return "";
}

}  // namespace zhc::cli

int main(int argc, char** argv) {
    using namespace zhc::cli;
    CLI::App app{"zhc — compress and transcode baked lighting (SH3, ZH3, quantised probes, lightmaps)", "zhc"};
    app.set_version_flag("--version", std::string("zhc ") + ZHC_VERSION);
    app.require_subcommand(1);
    app.footer("Run 'zhc VERB --help' for a verb's options. Exit codes: see README.md.");

    auto& registered = verbs();
    std::stable_sort(registered.begin(), registered.end(), [](const Verb& a, const Verb& b) { return a.order < b.order; });
    std::vector<std::function<int()>> runners;
    for (const Verb& v : registered) runners.push_back(v.setup(app));
    parse_integers_as_decimal(&app);
    // Ctrl-C, kill, a closed terminal: the temporary files of unfinished outputs go too.
    zhc::remove_temporaries_on_signals();

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line (README "Exit codes"): CLI11's message with any line breaks folded, and the
        // pointer to --help on the same line.
        std::string what = unknown_verb(app, argc, argv);
        if (what.empty()) what = e.what();
        for (char& c : what)
            if (c == '\n' || c == '\r') c = ' ';
        while (!what.empty() && what.back() == ' ') what.pop_back();
        std::fprintf(stderr, "zhc: error: %s (run 'zhc --help' for usage)\n", what.c_str());
        return kExitUsage;
    }
    // Each setup adds exactly one top-level subcommand, in `registered` order; run the parsed one.
    const auto all = app.get_subcommands({});
    for (size_t i = 0; i < all.size() && i < runners.size(); ++i) {
        if (all[i]->parsed()) {
            try {
                if (const int rc = check_outputs_before_work(app); rc != kExitOk) return rc;
                return run_with_depfile(runners[i]);
            } catch (const std::exception& e) {
                std::fprintf(stderr, "zhc: internal error: %s\n", e.what());
                return kExitInternal;
            }
        }
    }
    std::fprintf(stderr, "zhc: error: no verb given; run 'zhc --help'\n");
    return kExitUsage;
}
