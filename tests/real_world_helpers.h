// Helpers shared by test_real_world.cpp and test_real_world_hostile.cpp (files written by other
// programs): shell quoting, the CLI's projection, one-line errors, OpenEXR writers.
#pragma once

#include <ImfChannelList.h>
#include <ImfEnvmap.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "codec/sh/cubemap.h"
#include "support.h"

namespace zhc::real_world {

inline std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) {
        if (c == '\'')
            q += "'\\''";
        else
            q += c;
    }
    return q + "'";
}

inline int sh_run(const std::string& cmd) {
    const int st = std::system((cmd + " > /dev/null 2>&1").c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128;
}

inline Sh3Radiance parse_sh(const std::string& json_text) {
    const auto j = nlohmann::json::parse(json_text);
    Sh3Radiance s;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) s[i][k] = j["sh3"][static_cast<size_t>(i)][static_cast<size_t>(k)].get<float>();
    return s;
}

// `zhc project FILE --json` (plus extra arguments): the CLI path end to end.
inline Sh3Radiance cli_project(const std::string& path, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"project", path, "--json"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = test::run_zhc(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    if (r.exit_code != 0) return {};
    return parse_sh(r.out);
}

inline void expect_one_line_error(const test::CommandResult& r, int exit_code, const std::string& what) {
    EXPECT_EQ(r.exit_code, exit_code) << what << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << ": " << r.err;
    EXPECT_EQ(r.err.rfind("zhc: error: ", 0), 0u) << what << ": " << r.err;
}

// Writes float RGB pixels (rows top to bottom) with OpenEXR's API, optionally as a cube map.
inline void write_float_exr(const std::string& path, int w, int h, const std::vector<float>& rgb, bool cube,
                     Imf::Compression compression = Imf::ZIP_COMPRESSION, bool envmap_attribute = true) {
    Imf::Header header(w, h);
    header.compression() = compression;
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    if (envmap_attribute) Imf::addEnvmap(header, cube ? Imf::ENVMAP_CUBE : Imf::ENVMAP_LATLONG);
    Imf::OutputFile out(path.c_str(), header);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(const_cast<float*>(rgb.data()));
    const size_t xs = 3 * sizeof(float), ys = static_cast<size_t>(w) * xs;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + 4, xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 8, xs, ys));
    out.setFrameBuffer(fb);
    out.writePixels(h);
}

// Texel values f(direction of the texel centre) of an n x 6n OpenEXR cube map.
template <class F>
std::vector<float> render_cube(int n, F&& f) {
    std::vector<float> rgb(static_cast<size_t>(n) * 6 * static_cast<size_t>(n) * 3);
    for (int y = 0; y < 6 * n; ++y)
        for (int x = 0; x < n; ++x) {
            const Rgb c = f(cube_openexr_direction(y / n, x, y % n, n));
            float* p = &rgb[(static_cast<size_t>(y) * static_cast<size_t>(n) + static_cast<size_t>(x)) * 3];
            p[0] = c.r, p[1] = c.g, p[2] = c.b;
        }
    return rgb;
}

}  // namespace zhc::real_world
