#include "codec/bake/sky.h"

namespace zhc {

Sh3Radiance project_gradient_sky(const GradientSky& sky) {
    // K_l = sqrt((2l+1) / 4pi); f_l^0 = 2 pi K_l * (Legendre moments of a + b z on [0, 1]).
    const double k0 = std::sqrt(1.0 / (4.0 * kPi)), k1 = std::sqrt(3.0 / (4.0 * kPi)),
                 k2 = std::sqrt(5.0 / (4.0 * kPi));
    std::array<ZonalCoefficients, 3> z;
    for (int c = 0; c < 3; ++c) {
        const double a = sky.horizon[c], b = double(sky.zenith[c]) - sky.horizon[c];
        z[static_cast<size_t>(c)] = {2.0 * kPi * k0 * (a + b / 2.0), 2.0 * kPi * k1 * (a / 2.0 + b / 3.0),
                                     2.0 * kPi * k2 * (b / 8.0)};
    }
    const Vec3 up = normalize_or(sky.up, {0, 0, 1});
    return expand_zonal(up, z) + project_hemisphere(-1.0 * up, sky.ground);
}

Sh3Radiance project_sun(const Sun& sun) {
    const double s = std::sin(sun.angular_radius_rad);
    const double to_radiance = 1.0 / (s * s);
    const Rgb radiance{static_cast<float>(sun.irradiance.r * to_radiance),
                       static_cast<float>(sun.irradiance.g * to_radiance),
                       static_cast<float>(sun.irradiance.b * to_radiance)};
    return project_cone(sun.towards_sun, sun.angular_radius_rad, radiance);
}

Sh3Radiance project_default_lighting(const DefaultLighting& lighting) {
    return project_gradient_sky(lighting.sky) + project_sun(lighting.sun);
}

}  // namespace zhc
