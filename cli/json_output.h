// zhc/cli/json_output.h — the one shape of every `--json` output: a versioned envelope.
//
//   {"zhc": "<version>", "command": "<verb>", ...the verb's own keys...}
//
// "zhc" is the version of the zhc that wrote the object (the project version, as `zhc --version`
// prints it); "command" is the verb as typed ("audit", "lightmap audit"). The verb's keys follow in
// the order the verb adds them. docs/schema/<verb>.schema.json describes each verb's object
// (<verb> with spaces as dashes: lightmap-audit.schema.json); tests/cli_json validates every one.
// Header-only: the verb files that print JSON are compiled together (cli/CMakeLists.txt, unity
// build), so nlohmann::json is parsed once per batch, not once more for this helper.
#pragma once

#include <nlohmann/json.hpp>

#include <iostream>
#include <string_view>

namespace zhc::cli {

// The envelope for `command` with `body`'s keys after "zhc" and "command" (a body key of either
// name would be a bug in the verb: the envelope's value wins).
template <class Json>
nlohmann::ordered_json json_envelope(std::string_view command, const Json& body) {
    nlohmann::ordered_json out;
    out["zhc"] = ZHC_VERSION;
    out["command"] = std::string(command);
    for (auto it = body.begin(); it != body.end(); ++it)
        if (it.key() != "zhc" && it.key() != "command") out[it.key()] = *it;
    return out;
}

// Prints json_envelope(command, body) on stdout, indented by two spaces, with a final newline.
template <class Json>
void print_json(std::string_view command, const Json& body) {
    std::cout << json_envelope(command, body).dump(2) << "\n";
    std::cout.flush();
}

}  // namespace zhc::cli
