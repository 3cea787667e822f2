// zhc/codec/bake/sky.h — closed-form SH3 of analytic skies and the built-in default lighting.
//
// Experimental: this API may change between minor versions (docs/api.md "Public headers").
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include "codec/sh/sh.h"

namespace zhc {

// A sky whose radiance over the upper hemisphere (about `up`) varies linearly with the
// cosine of the zenith angle, L(z) = horizon + (zenith - horizon) z for z = up.w in [0, 1], over
// a ground of constant radiance on the lower hemisphere.
struct GradientSky {
    Vec3 up{0, 0, 1};
    Rgb zenith{0.30f, 0.50f, 1.00f};
    Rgb horizon{0.80f, 0.85f, 1.00f};
    Rgb ground{0.20f, 0.17f, 0.14f};
};

// Closed form. Per channel, with L = a + b z on the upper hemisphere and P_l Legendre:
//   f_l^0 = 2 pi K_l int_0^1 (a + b z) P_l(z) dz,
//   int_0^1 P0 = 1, int_0^1 z = 1/2, int_0^1 P1 z = 1/3, int_0^1 P2 = 0, int_0^1 P2 z = 1/8,
// plus the ground hemisphere (cone of pi/2 about -up).
Sh3Radiance project_gradient_sky(const GradientSky& sky);

// A sun: a cone light of angular radius `angular_radius_rad` whose irradiance on a surface
// facing it is `irradiance` (normalised kernel: E = L sin^2(sigma) for a facing surface).
struct Sun {
    Vec3 towards_sun{0.6, 0.3, 0.74};
    double angular_radius_rad = 0.5 * 0.53 * kPi / 180.0;
    Rgb irradiance{3.2f, 3.0f, 2.7f};
};
Sh3Radiance project_sun(const Sun& sun);

// The built-in default lighting used by `zhc demo`: a gradient sky over ground plus a sun.
struct DefaultLighting {
    GradientSky sky;
    Sun sun;
};
Sh3Radiance project_default_lighting(const DefaultLighting& lighting = {});

}  // namespace zhc
