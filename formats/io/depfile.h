// zhc/formats/io/depfile.h — Make-syntax dependency files (`--depfile`, docs/build-integration.md).
#pragma once

#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

// One path escaped for a depfile rule as GNU Make and Ninja (1.10+) both read it back: a space is
// written `\ `, `#` is `\#`, `$` is `$$`, and `:` is `\:`. Other bytes pass through. Refused
// (kInvalidArgument, the message names the path): an empty path, a newline, carriage return, tab or
// NUL, a backslash before a space, `#` or `:` or at the end (Make and Ninja would read it as an
// escape), and a `:` at the end of the path. docs/build-integration.md "What a depfile cannot say".
Result<std::string> escape_depfile_path(const std::string& path);

// The depfile text: one rule `OUT1 OUT2 ...: IN1 IN2 ...`, one input per continuation line, ending
// in a newline. At least one output is required; inputs may be empty.
Result<std::string> make_depfile(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

}  // namespace zhc
