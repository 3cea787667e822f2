// zhc/examples/make_inputs.cpp — the example inputs that are images, made from the sample maps so that
// no image is checked in (scripts/make_examples.sh runs it; examples/README.md lists the files).
//
//   zhc_example_inputs MAPDIR OUTDIR
//
// writes into OUTDIR:
//   sky.hdr                    sunrise.exr as a Radiance .hdr (RGBE)
//   render_diffuse.exr,        two RGB EXRs (city.exr at half intensity, and city.exr) that
//   render_beauty.exr          scripts/make_examples.sh combines into the two-part render.exr
//   linear.exr                 a 64 x 64 linear-SH lightmap: channels sh0.R .. sh3.B of the synthetic
//                              sphere lightmap that `zhc lightmap synth` writes for sunset.exr
//   L0.exr .. L8.exr           the same SH3 lightmap, one EXR per coefficient (channels R, G, B)
// Exit 0, or 1 with one line on stderr naming the file that could not be read or written.
#include <cstdio>
#include <string>
#include <vector>

#include "codec/lightmap/lightmap.h"
#include "formats/envmap/envmap.h"
#include "formats/lightmap/lightmap_exr.h"

namespace {

constexpr int kLightmapSize = 64;

bool fail(const std::string& what) {
    std::fprintf(stderr, "zhc_example_inputs: %s\n", what.c_str());
    return false;
}

// One EXR of `width` x `height` texels with the given channels, from `floats` (interleaved per texel).
bool write_channels(const std::string& path, int width, int height, const std::vector<std::string>& names,
                    const std::vector<float>& floats) {
    auto writer = zhc::ExrBandWriter::open(path, width, height, names, /*half=*/false);
    if (!writer) return fail(path + ": " + writer.error().message);
    if (auto s = (*writer)->write_rows(floats.data(), height); !s) return fail(path + ": " + s.error().message);
    if (auto s = (*writer)->commit(); !s) return fail(path + ": " + s.error().message);
    return true;
}

bool run(const std::string& maps, const std::string& out) {
    auto sunrise = zhc::read_envmap(maps + "/sunrise.exr");
    if (!sunrise) return fail(maps + "/sunrise.exr: " + sunrise.error().message);
    if (auto s = zhc::write_hdr(out + "/sky.hdr", *sunrise); !s) return fail(out + "/sky.hdr: " + s.error().message);

    auto city = zhc::read_envmap(maps + "/city.exr");
    if (!city) return fail(maps + "/city.exr: " + city.error().message);
    if (auto s = zhc::write_exr(out + "/render_beauty.exr", *city); !s) return fail(s.error().message);
    zhc::Image diffuse = *city;
    for (float& v : diffuse.rgb) v *= 0.5f;
    if (auto s = zhc::write_exr(out + "/render_diffuse.exr", diffuse); !s) return fail(s.error().message);

    auto sunset = zhc::read_envmap(maps + "/sunset.exr");
    if (!sunset) return fail(maps + "/sunset.exr: " + sunset.error().message);
    const zhc::lightmap::ShLightmap lm =
        zhc::lightmap::synthesize_sphere(zhc::project_envmap(*sunset), kLightmapSize, kLightmapSize);
    const size_t texels = lm.texels.size();

    std::vector<std::string> linear_names;
    for (int i = 0; i < 4; ++i)
        for (const char* c : {"R", "G", "B"}) linear_names.push_back("sh" + std::to_string(i) + "." + c);
    std::vector<float> linear;
    linear.reserve(texels * 12);
    for (const auto& t : lm.texels)
        for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k) linear.push_back(t[i][k]);
    if (!write_channels(out + "/linear.exr", lm.width, lm.height, linear_names, linear)) return false;

    for (int i = 0; i < 9; ++i) {
        std::vector<float> plane;
        plane.reserve(texels * 3);
        for (const auto& t : lm.texels)
            for (int k = 0; k < 3; ++k) plane.push_back(t[i][k]);
        if (!write_channels(out + "/L" + std::to_string(i) + ".exr", lm.width, lm.height, {"R", "G", "B"}, plane))
            return false;
    }
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: zhc_example_inputs MAPDIR OUTDIR\n");
        return 2;
    }
    return run(argv[1], argv[2]) ? 0 : 1;
}
