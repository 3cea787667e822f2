// zhc/formats/envmap/envmap_internal.h — internal to formats/: what the OpenEXR reader (envmap.cpp)
// and the Radiance .hdr reader (envmap_hdr.cpp) share: the size limit, the non-finite policy and
// one-line messages.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "formats/envmap/envmap.h"

namespace zhc::envmap_detail {

// kBadFormat for a zero size, kTooLarge above EnvmapReadOptions::max_pixels or INT_MAX per axis.
Status check_size(const std::string& name, std::uint64_t w, std::uint64_t h, const EnvmapReadOptions& o);
// Applies EnvmapReadOptions::non_finite to every value (reject naming the pixel, or replace by 0).
Status check_finite(const std::string& name, Image& img, const EnvmapReadOptions& o, EnvmapInfo* info);
// Control characters replaced by spaces (text from a file, quoted in a one-line message).
std::string one_line(std::string what);

// EXR colour (envmap_colour.cpp): the 3x3 matrix (column vectors: out = m * in) taking linear RGB
// in the primaries and white point of an OpenEXR chromaticities attribute (red, green, blue,
// white as x, y pairs) to linear Rec. 709 / D65, with Bradford adaptation when the white points
// differ. `apply` is false when there is nothing to do: no attribute, or a matrix within
// kColourIdentityTolerance of the identity (the pixels are then left bit for bit as read).
struct ColourConversion {
    bool apply = false;
    double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
};
// Largest row sum of |m - I| left untransformed: half float's unit roundoff, 2^-11.
inline constexpr double kColourIdentityTolerance = 1.0 / 2048.0;
// kBadFormat naming the attribute when the chromaticities define no RGB space (non-finite values,
// white y <= 0, collinear primaries). Fills info->has_chromaticities, chromaticities and
// colour_conversion.
Result<ColourConversion> exr_colour_conversion(const std::string& name, const float* chromaticities_or_null,
                                               EnvmapInfo* info);
// Applies the matrix to every pixel; kInvalidValue naming the pixel if a result leaves the float range.
Status apply_colour_conversion(const std::string& name, const ColourConversion& c, Image& img);

// A Radiance .hdr image (envmap_hdr.cpp).
Result<Image> read_hdr(std::span<const std::uint8_t> bytes, const std::string& name, const EnvmapReadOptions& o,
                       EnvmapInfo* info);

}  // namespace zhc::envmap_detail
