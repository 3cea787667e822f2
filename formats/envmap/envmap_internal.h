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

// A Radiance .hdr image (envmap_hdr.cpp).
Result<Image> read_hdr(std::span<const std::uint8_t> bytes, const std::string& name, const EnvmapReadOptions& o,
                       EnvmapInfo* info);

}  // namespace zhc::envmap_detail
