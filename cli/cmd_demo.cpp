// zhc demo: the main job on the built-in default (no input files).
#include <chrono>
#include <cstdio>

#include "cli.h"
#include "codec/sky.h"

namespace zhc::cli {
namespace {

int run() {
    const DefaultLighting lighting;
    const auto t0 = std::chrono::steady_clock::now();
    const Sh3Radiance sh = project_default_lighting(lighting);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    std::printf("zhc demo: built-in default scene (gradient sky over ground + sun of %.2f deg radius)\n",
                lighting.sun.angular_radius_rad * 180.0 / kPi);
    std::printf("baked one SH3 radiance probe in %.2f us (closed form)\n", us);
    static const char* names[9] = {"L00", "L1-1", "L10", "L11", "L2-2", "L2-1", "L20", "L21", "L22"};
    std::printf("%-5s %13s %13s %13s\n", "coef", "r", "g", "b");
    for (int i = 0; i < 9; ++i) std::printf("%-5s %13.6f %13.6f %13.6f\n", names[i], sh[i].r, sh[i].g, sh[i].b);
    const Rgb up = irradiance(sh, {0, 0, 1});
    std::printf("irradiance at +Z: %.5f %.5f %.5f\n", up.r, up.g, up.b);
    return kExitOk;
}

const VerbRegistration registration(10, [](CLI::App& app) -> std::function<int()> {
    app.add_subcommand("demo", "Run the main job on the built-in default scene (no input files needed)");
    return [] { return run(); };
});

}  // namespace
}  // namespace zhc::cli
