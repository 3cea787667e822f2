// zhc/cli/cli.h — what the verbs share: exit codes, error reporting, verb registration.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include <vector>

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"
#include "codec/status.h"
#include "formats/envmap/envmap.h"

namespace zhc::cli {

// Exit codes (README "Exit codes"). Stable: scripts depend on them.
enum ExitCode : int {
    kExitOk = 0,
    kExitInternal = 1,         // a bug in zhc
    kExitUsage = 2,            // bad command line: unknown verb/option, missing argument
    kExitInputUnreadable = 3,  // input file missing, unreadable or a directory
    kExitInvalidInput = 4,     // input is malformed, truncated, corrupt or holds NaN/Inf
    kExitUnsupported = 5,      // input is well-formed but uses something zhc does not support
    kExitTooLarge = 6,         // input exceeds a size limit
    kExitOutputFailed = 7,     // an output file could not be written (nothing partial is left)
    kExitGateFailed = 8,       // an audit gate (--max-rmse, ...) failed
};

// Maps a library error on an input to its exit code.
int exit_code_for(const Error& error);
// Prints "zhc: error: <message>" (one line) to stderr and returns exit_code_for(error).
int report(const Error& error);
// For errors while writing outputs: prints the message and returns kExitOutputFailed.
int report_output(const Error& error);
// For a failed write of an output file: a value the format cannot hold (kInvalidValue, e.g. NaN in
// JSON) is the input's fault (report), anything else the output's (report_output).
int report_write(const Error& error);

// --- Shared option groups: every verb spells these the same way (README "Options"). -------------
// The representation: `-r, --representations` in every verb that picks codec-table entries.
// kList: a comma-separated subset (audit, bench; empty = all). kOne: exactly one name (convert,
// bake, gltf embed). `other_name` ("--to", "--encoding") is a second name of the same option in that
// verb; the help says so. `what` completes the help text.
enum class RepresentationCount { kOne, kList };
CLI::Option* add_representations_option(CLI::App* app, std::string& names, RepresentationCount count,
                                        const std::string& what, const std::string& other_name = "");
// The codec-table entry a kOne `-r` value names. An unknown name prints select_codecs' one line
// (the name and every known name: the same words in every verb that parses `-r`) and returns null;
// the verb then exits kExitUsage.
const Codec* representation_named(const std::string& name);

// Which storage parameters (CodecOptions bits .. axis_mode, `zhc convert`'s --bits .. --axis) an
// entry's bytes depend on, from what the table says of it (Codec::packed, its layout, the
// zonal_axis trait): bits, square-root encoding and the DC format for every quantised layout; the
// non-zonal L2 bound where the layout stores non-zonal L2 ratios (sh3_q28); the zonal mapping where
// it stores a zonal ratio (zh3_q16, sh3_q28); the axis where the decoder takes it from the
// parameters (ZonalAxis::kFromParams). The stored kind (radiance/irradiance) concerns every entry.
struct StorageOptionUse {
    bool bits = false, sqrt = false, dc = false, l2_bound = false, zonal_mapping = false, axis = false;
};
StorageOptionUse storage_options_used(const Codec& codec);

// Refuses to write an output over one of the inputs: `output` and any of `inputs` name the same file
// (compared as canonical paths, and with std::filesystem::equivalent when both exist, so another
// spelling, a symlink or a hard link is caught). Prints "zhc: error: OPTION OUTPUT: is the input
// INPUT (choose another output path)" and returns kExitUsage; kExitOk when they differ. Inputs
// that are folders or do not exist never match.
int refuse_output_over_input(const std::string& option, const std::string& output, const std::vector<std::string>& inputs);

// Refuses an output whose folder takes no new files (formats/io/file_io.h check_folder_takes_files:
// missing, not a folder, read-only): prints "zhc: error: OPTION PATH: why (checked before the
// work)" and returns kExitOutputFailed; kExitOk when a file can be created there.
// main() runs it, before the verb, on every file output given (-o/--output, --html, --markdown,
// --depfile), except where the verb does it itself: demo (its -o is a folder it creates, and it
// checks --html once the folder exists) and lightmap encode's -o (a prefix: encode checks its first
// plane). main() also refuses --depfile (exit 7) before the work when the verb was given no file
// output to name as the depfile's target (audit without --markdown/--html/--images, lightmap audit
// without --html).
int refuse_unwritable_output(const std::string& option, const std::string& path);

// `--threads N`, N in 0..256, 0 = all cores (hardware_concurrency), the default of every verb
// (README "Options"). Every verb that takes it gives identical output for any count.
CLI::Option* add_threads_option(CLI::App* app, int& threads, const std::string& what);
// The worker count a --threads value means: 0 -> the machine's cores (at least 1).
int resolve_threads(int threads);
// `--json`: print one JSON object (cli/json_output.h: the versioned envelope) on stdout.
CLI::Option* add_json_flag(CLI::App* app, bool& json, const std::string& what = "");
// Environment-map reading: `--replace-non-finite` and `--part` (formats/envmap/envmap.h EnvmapReadOptions).
void add_envmap_read_options(CLI::App* app, bool* replace_non_finite, std::string& part);
// `--latlong openexr|gltf`: the orientation of a lat-long environment map (codec/sh/sh.h
// LatLongConvention, docs/conventions.md). `set` (may be null) becomes true when the option is given.
CLI::Option* add_latlong_option(CLI::App* app, LatLongConvention& convention, bool* set, const std::string& default_text);
// --ldr-encoding auto|srgb|linear|rgbm:RANGE|rgbd:RANGE (8-bit cube maps, EnvmapReadOptions::ldr).
CLI::Option* add_ldr_encoding_option(CLI::App* app, LdrDecoding& decoding);

// `--depfile FILE`: after the verb succeeds, write a Make-syntax depfile naming the files it wrote
// (targets) and every file it read (formats/io/depfile.h, docs/build-integration.md). main() runs
// the verb under a FileRecorder and writes the depfile; nothing is written when the verb fails.
CLI::Option* add_depfile_option(CLI::App* app);
// Runs `verb` and, when --depfile was given, records its files and writes the depfile (temporary
// file + rename) only if it returned kExitOk. If the depfile cannot be written (a path it cannot
// express, an I/O error, or a verb that wrote nothing) the files the verb wrote are removed again and
// the exit is kExitOutputFailed, so that no output stands without its depfile.
int run_with_depfile(const std::function<int()>& verb);

// `--paths-relative-to DIR` of the reports (--json, --markdown, --html): input paths are written
// relative to DIR, so a report cached by a build farm does not name the folder it ran in.
// shown_path(path, "") is `path` as given; else the lexical path from DIR to `path` (both made
// absolute against the working directory first; no file system look-up, so symlinks stay).
CLI::Option* add_paths_relative_to_option(CLI::App* app, std::string& base);
std::string shown_path(const std::string& path, const std::string& base);

// A verb: `setup` adds the subcommand and its options to the app and returns the function that
// runs it after parsing. Verbs register themselves with a static VerbRegistration.
using VerbSetup = std::function<std::function<int()>(CLI::App& app)>;
struct VerbRegistration {
    VerbRegistration(int order, VerbSetup setup);
};

}  // namespace zhc::cli
