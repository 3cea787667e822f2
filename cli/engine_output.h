// zhc/cli/engine_output.h — writing an engine's probe file (formats/engines/engine_files.h), shared
// by `zhc convert --engine` and `zhc bake --engine`. Header-only like json_output.h: the verb files
// are compiled together (cli/CMakeLists.txt, unity build).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "cli.h"
#include "formats/engines/engine_files.h"
#include "formats/io/file_io.h"

namespace zhc::cli {

// The --engine option: the names of engine_files(), each with its extension, in the help.
inline CLI::Option* add_engine_option(CLI::App* sub, std::string& engine) {
    std::vector<std::string> names;
    std::string list;
    for (const EngineFile& f : engine_files()) {
        names.emplace_back(f.name);
        list += (list.empty() ? "" : ", ") + std::string(f.name) + " (" + std::string(f.extension) + ")";
    }
    return sub->add_option("--engine", engine, "write the probes as an engine loads them: " + list + " (docs/engine-files.md)")
        ->check(CLI::IsMember(names));
}

// The entry --engine names, with the output's extension checked against it; nullptr after printing
// the error (exit 2).
inline const EngineFile* engine_for_output(const std::string& name, const std::string& output) {
    const EngineFile* engine = find_engine_file(name);
    if (!engine) {  // the option's check lists the names
        std::fprintf(stderr, "zhc: error: --engine %s: no such engine file format\n", name.c_str());
        return nullptr;
    }
    if (file_extension(output) != engine->extension) {
        std::fprintf(stderr, "zhc: error: %s: --engine %s writes a %s file: the output must end in %s\n", output.c_str(),
                     name.c_str(), std::string(engine->engine).c_str(), std::string(engine->extension).c_str());
        return nullptr;
    }
    return engine;
}

// Writes the engine's file for `in` to `output` (atomically), after reading the bytes back: what
// is printed is the file's irradiance error against the input, as the engine will see the probes.
inline int write_engine_output(const EngineFile& engine, const EngineFileInput& in, const std::string& output) {
    auto out = engine.write(in);
    if (!out) return report(out.error());
    auto back = engine.read(out->bytes, output);
    if (!back) {
        std::fprintf(stderr, "zhc: error: %s: the written %s file does not read back: %s\n", output.c_str(),
                     std::string(engine.name).c_str(), back.error().message.c_str());
        return kExitInternal;
    }
    if (back->hub.size() != in.hub.size()) {
        std::fprintf(stderr, "zhc: error: %s: the written file reads back %zu probes, not %zu\n", output.c_str(), back->hub.size(),
                     in.hub.size());
        return kExitInternal;
    }
    if (Status st = write_file_atomic(output, out->bytes); !st) return report_output(st.error());
    for (const std::string& line : out->notes) std::fprintf(stderr, "zhc: note: %s: %s\n", output.c_str(), line.c_str());
    const EngineFileError err = engine_file_error(in.hub, back->hub);
    std::printf("%s: %zu probes for %s (layout %s), %zu bytes; irradiance against the input: RMS error %.3g %%, max %.3g %%\n",
                output.c_str(), in.hub.size(), std::string(engine.engine).c_str(), std::string(engine.layout_codec).c_str(),
                out->bytes.size(), 100.0 * err.rms, 100.0 * err.max);
    return kExitOk;
}

}  // namespace zhc::cli
