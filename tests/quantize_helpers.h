// Helper shared by the ratio-bound quantisation tests (test_quantize, test_quantize_real_maps): the
// scalar quantiser's error bound for one ratio.
#pragma once

#include <algorithm>
#include <cmath>

#include "codec/probe/quantize.h"
#include "support.h"

namespace zhc::quantize_test {

using test::fibonacci_directions;

// Largest |decoded - ratio| for a ratio inside the interval (half a step; with sqrt, half a step
// of the square-root grid pushed through t = u |u|, i.e. (|u| + h)^2 - u^2 with h = 1 / (2 bv)).
inline double max_ratio_error(const RatioCoder& c, double ratio) {
    const double bv = quant_half_range(c.bits), h = 0.5 / bv;
    double half_t;  // error bound in t
    double t = ratio_to_unit(ratio, c.interval, c.mapping, c.zonal, nullptr);
    if (c.sqrt_encoding) {
        const double u = std::sqrt(std::fabs(t));
        half_t = (u + h) * (u + h) - u * u;
    } else {
        half_t = h;
    }
    // d ratio / d t: the interval half-width (zero-preserving: the larger side, conservative).
    const double slope = (!c.zonal || c.mapping == ZonalMapping::kAffine) ? 0.5 * (c.interval.hi - c.interval.lo)
                                                                          : std::max(c.interval.hi, -c.interval.lo);
    return half_t * slope * (1 + 1e-9);
}

}  // namespace zhc::quantize_test
