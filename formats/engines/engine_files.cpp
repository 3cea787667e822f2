// The table of engine file formats (engine_files.h). Each format lives in its own file of this
// folder and contributes one entry.
#include "formats/engines/engine_files.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "codec/sh/sh.h"

namespace zhc {

// Each format's file in this folder defines its entry (declared here, listed in engine_files()).
extern const EngineFile kBevyIrradianceVolumeFile;
extern const EngineFile kThreejsGridExrFile;
extern const EngineFile kThreejsGridKtx2File;
extern const EngineFile kGodotLightmapGiFile;

std::span<const EngineFile> engine_files() {
    // A function-local table: the command's verbs read it while they are registered, during static
    // initialisation (the entries themselves are constant-initialised).
    static const std::vector<EngineFile> files = [] {
        const std::vector<const EngineFile*> list = {
            &kBevyIrradianceVolumeFile,
            &kThreejsGridExrFile,
            &kThreejsGridKtx2File,
            &kGodotLightmapGiFile,
        };
        std::vector<EngineFile> v;
        for (const EngineFile* f : list) v.push_back(*f);
        return v;
    }();
    return files;
}

const EngineFile* find_engine_file(std::string_view name) {
    for (const EngineFile& f : engine_files())
        if (f.name == name) return &f;
    return nullptr;
}

EngineFileError engine_file_error(std::span<const Sh3Radiance> source, std::span<const Sh3Radiance> back) {
    static const std::vector<Vec3> normals = fibonacci_sphere(64);
    double sum_d2 = 0, sum_s2 = 0, max_d = 0, max_s = 0;
    const std::size_t n = std::min(source.size(), back.size());
    for (std::size_t i = 0; i < n; ++i)
        for (const Vec3& normal : normals) {
            const Rgb a = irradiance(source[i], normal), b = irradiance(back[i], normal);
            for (int c = 0; c < 3; ++c) {
                const double d = std::abs(double(b[c]) - double(a[c]));
                sum_d2 += d * d;
                sum_s2 += double(a[c]) * a[c];
                max_d = std::max(max_d, d);
                max_s = std::max(max_s, std::abs(double(a[c])));
            }
        }
    EngineFileError e;
    e.rms = sum_s2 > 0 ? std::sqrt(sum_d2 / sum_s2) : (sum_d2 > 0 ? INFINITY : 0.0);
    e.max = max_s > 0 ? max_d / max_s : (max_d > 0 ? INFINITY : 0.0);
    return e;
}

const EngineFile* sniff_engine_file(std::span<const std::uint8_t> bytes) {
    for (const EngineFile& f : engine_files())
        if (f.sniff && f.sniff(bytes)) return &f;
    return nullptr;
}

}  // namespace zhc
