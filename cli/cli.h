// zhc/cli/cli.h — what the verbs share: exit codes, error reporting, verb registration.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "codec/status.h"

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

// A verb: `setup` adds the subcommand and its options to the app and returns the function that
// runs it after parsing. Verbs register themselves with a static VerbRegistration.
using VerbSetup = std::function<std::function<int()>(CLI::App& app)>;
struct VerbRegistration {
    VerbRegistration(int order, VerbSetup setup);
};

}  // namespace zhc::cli
