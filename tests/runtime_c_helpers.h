// Helpers shared by the C runtime tests (test_runtime_c, test_runtime_c_zhp): ulp distances, probes from
// the real maps and random ones (deltas, zeros, extremes), random valid storage parameters.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/lightmap/irradz.h"
#include "codec/lightmap/lightmap.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "formats/probes/probe_file.h"
#include "support.h"
#include "zhc_runtime.h"
#include "zhc_runtime_params.hpp"

namespace zhc::runtime_c_test {

// ---- comparison helpers ----------------------------------------------------------------------

// Distance in ulps between two floats (0 for two NaNs, huge for NaN vs number).
inline std::uint64_t ulp_distance(float a, float b) {
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : UINT64_MAX;
    auto ordered = [](float f) {
        std::int32_t i;
        std::memcpy(&i, &f, 4);
        return i < 0 ? -static_cast<std::int64_t>(i & 0x7FFFFFFF) : static_cast<std::int64_t>(i);
    };
    const std::int64_t d = ordered(a) - ordered(b);
    if (d == 0) {
        // +0 vs -0 differ in bits: count as 1 so bit equality is really checked.
        std::uint32_t ia, ib;
        std::memcpy(&ia, &a, 4);
        std::memcpy(&ib, &b, 4);
        return ia == ib ? 0 : 1;
    }
    return static_cast<std::uint64_t>(d < 0 ? -d : d);
}

struct MaxUlp {
    std::uint64_t worst = 0;
    std::string where;
    void add(float runtime, float codec, const std::string& what) {
        const std::uint64_t d = ulp_distance(runtime, codec);
        if (d > worst) {
            worst = d;
            char buf[400];
            std::snprintf(buf, sizeof buf, "%s: runtime %.9g codec %.9g", what.c_str(), runtime, codec);
            where = buf;
        }
    }
};

// ---- probes ------------------------------------------------------------------------------------

inline const std::vector<Sh3Radiance>& map_probes() {
    static const std::vector<Sh3Radiance> probes = [] {
        std::vector<Sh3Radiance> out;
        for (const std::string& path : test::envmap_paths()) {
            const Image img = test::load_envmap(path);
            out.push_back(project_latlong(img.rgb.data(), img.width, img.height, size_t(img.width) * 3, 2));
        }
        return out;
    }();
    return probes;
}

inline Vec3 random_direction(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const double a = u(rng), b = u(rng);
    return test::uniform_direction(a, b);
}

// Mixed population: coloured lights + ambient (+ a cone), random SH (positive DC), the sample maps
// under random rotations and exposures, and arbitrary SH (negative DC, huge and tiny magnitudes).
inline Sh3Radiance random_probe(std::mt19937_64& rng, std::uint64_t i) {
    std::uniform_real_distribution<double> u(0, 1);
    Sh3Radiance sh;
    switch (i % 4) {
        case 0: {
            sh = project_constant({float(u(rng) * 0.5), float(u(rng) * 0.5), float(u(rng) * 0.5)});
            const int lights = 1 + int(rng() % 4);
            for (int l = 0; l < lights; ++l)
                sh = sh + project_directional(random_direction(rng),
                                              {float(u(rng) * 10), float(u(rng) * 10), float(u(rng) * 10)});
            if (rng() % 2)
                sh = sh + project_cone(random_direction(rng), u(rng) * kPi, {float(u(rng)), float(u(rng)), float(u(rng))});
            break;
        }
        case 1:
            for (int c = 0; c < 9; ++c)
                for (int k = 0; k < 3; ++k) sh[c][k] = float(c == 0 ? 0.2 + 3 * u(rng) : 2 * u(rng) - 1);
            break;
        case 2: {
            const auto& maps = map_probes();
            const Mat3 r = rotation_axis_angle(random_direction(rng), 2 * kPi * u(rng));
            sh = scale(rotate(maps[rng() % maps.size()], r), std::exp2(8 * u(rng) - 4));
            break;
        }
        default: {
            const double mag = std::exp2(60 * u(rng) - 30);
            for (int c = 0; c < 9; ++c)
                for (int k = 0; k < 3; ++k) sh[c][k] = float((2 * u(rng) - 1) * mag);
            if (rng() % 8 == 0) sh[int(rng() % 9)][int(rng() % 3)] = 0.0f;
            break;
        }
    }
    return sh;
}

// Random storage parameters valid for `codec` (validate_quant_params).
inline CodecOptions random_params(std::mt19937_64& rng, std::string_view codec) {
    std::uniform_real_distribution<double> u(0, 1);
    CodecOptions p;
    p.bits = 2 + int(rng() % 7);
    p.sqrt_encoding = rng() % 2;
    p.l2_bound = L2Bound(rng() % 2);
    p.dc_format = DcFormat(rng() % 3);
    PackedLayout layout;
    if (p.dc_format == DcFormat::kHalf && packed_layout_from_name(codec, &layout) && layout != PackedLayout::kSh2Q)
        p.dc_format = DcFormat::kRGB9E5;
    p.kind = StoredKind(rng() % 2);
    p.zonal_mapping = ZonalMapping(rng() % 3);
    p.axis_mode = ZonalAxisMode(rng() % 2);
    if (rng() % 2) p.luminance = {u(rng), u(rng), u(rng)};
    if (rng() % 8 == 0) p.luminance = {2 * u(rng) - 1, 0.0, 2 * u(rng) - 1};
    return p;
}

}  // namespace zhc::runtime_c_test
