// The table of engine file formats (engine_files.h). Each format lives in its own file of this
// folder and contributes one entry.
#include "formats/engines/engine_files.h"

#include <vector>

namespace zhc {

namespace {

// One line per format: its file in this folder defines the entry.
const std::vector<const EngineFile*> kFiles = {
};

}  // namespace

std::span<const EngineFile> engine_files() {
    static const std::vector<EngineFile> files = [] {
        std::vector<EngineFile> v;
        for (const EngineFile* f : kFiles) v.push_back(*f);
        return v;
    }();
    return files;
}

const EngineFile* find_engine_file(std::string_view name) {
    for (const EngineFile& f : engine_files())
        if (f.name == name) return &f;
    return nullptr;
}

const EngineFile* sniff_engine_file(std::span<const std::uint8_t> bytes) {
    for (const EngineFile& f : engine_files())
        if (f.sniff && f.sniff(bytes)) return &f;
    return nullptr;
}

}  // namespace zhc
