// zhc project ENVMAP [--json]: SH3 radiance projection of a lat-long environment map.
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>

#include "cli.h"
#include "json_output.h"
#include "codec/sh/sh.h"
#include "formats/envmap/envmap.h"

namespace zhc::cli {
namespace cmd_project {  // one namespace per verb file: the CLI is a unity build
namespace {

struct Options {
    std::string path;
    bool json = false;
    bool replace_non_finite = false;
    std::string part;
    LatLongConvention latlong = LatLongConvention::kOpenExr;
    LdrDecoding ldr;
    int threads = 0;
};

void print_sh3_table(const Sh3Radiance& sh) {
    static const char* names[9] = {"L00", "L1-1", "L10", "L11", "L2-2", "L2-1", "L20", "L21", "L22"};
    std::printf("%-5s %15s %15s %15s\n", "coef", "r", "g", "b");
    for (int i = 0; i < 9; ++i) std::printf("%-5s %15.8g %15.8g %15.8g\n", names[i], sh[i].r, sh[i].g, sh[i].b);
}

int run(const Options& o) {
    EnvmapReadOptions ro;
    if (o.replace_non_finite) ro.non_finite = NonFinitePolicy::kReplaceZero;
    ro.part = o.part;
    ro.latlong = o.latlong;
    ro.ldr = o.ldr;
    EnvmapInfo info;
    auto img = read_envmap(o.path, ro, &info);
    if (!img) return report(img.error());
    const int threads = resolve_threads(o.threads);
    const auto t0 = std::chrono::steady_clock::now();
    const Sh3Radiance sh = project_envmap(*img, threads);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (o.json) {
        nlohmann::ordered_json j;
        j["path"] = o.path;
        j["width"] = img->width;
        j["height"] = img->height;
        j["format"] = info.format;
        j["layout"] = info.layout;
        if (img->layout == EnvmapLayout::kLatLong) j["latlong"] = latlong_convention_name(img->latlong);
        j["kind"] = "radiance";
        j["basis"] = "zhc (ZH3 paper Eq. 4/5), index l(l+1)+m";
        nlohmann::ordered_json rows = nlohmann::ordered_json::array();
        for (int i = 0; i < 9; ++i) rows.push_back({sh[i].r, sh[i].g, sh[i].b});
        j["sh3"] = rows;
        j["replaced_non_finite"] = info.replaced_non_finite;
        print_json("project", j);
    } else {
        const std::string orientation =
            img->layout == EnvmapLayout::kLatLong ? std::string(" ") + latlong_convention_name(img->latlong) + " orientation" : "";
        std::printf("%s: %dx%d %s %s%s (%s, %s)\n", o.path.c_str(), img->width, img->height, info.format.c_str(),
                    info.layout.c_str(), orientation.c_str(), info.channels.c_str(), info.compression.c_str());
        print_sh3_table(sh);
        std::printf("projected in %.3f ms\n", ms);
    }
    return kExitOk;
}

const VerbRegistration registration(20, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand("project", "Project an environment map (EXR lat-long or cube, or .hdr) to SH3 radiance");
    sub->add_option("ENVMAP", o->path, "OpenEXR or Radiance .hdr lat-long map")->required();
    add_json_flag(sub, o->json, "key \"sh3\" holds 9 rows of [r, g, b]");
    add_envmap_read_options(sub, &o->replace_non_finite, o->part);
    add_latlong_option(sub, o->latlong, nullptr, "default openexr");
    add_ldr_encoding_option(sub, o->ldr);
    add_threads_option(sub, o->threads, "result identical for any count");
    return [o] { return run(*o); };
});

}  // namespace
}  // namespace cmd_project
}  // namespace zhc::cli
