// zhc/formats/lightmap_exr.h — lightmap hub files: per-texel SH3 radiance in the tangent frame as
// OpenEXR, and the decoded IrradZ planes as OpenEXR (docs/lightmap-formats.md).
//
// SH lightmap EXR: 27 channels named "sh<i>.<C>", i = 0..8 in zhc's coefficient order (l(l+1)+m),
// C in {R, G, B}: "sh0.R", "sh0.G", "sh0.B", ..., "sh8.B". HALF or FLOAT; radiance (not irradiance),
// in each texel's tangent frame (surface normal = +Z), zhc's SH basis (codec/sh.h). Other channels
// are ignored.
// IrradZ EXR (what `zhc lightmap decode` writes): FLOAT channels "Iz.R", "Iz.G", "Iz.B", "wa",
// "d.X", "d.Y", "d.Z" (d a unit tangent-frame vector).
#pragma once

#include <cstdint>
#include <string>

#include "codec/lightmap.h"
#include "codec/status.h"

namespace zhc {

struct LightmapReadOptions {
    std::uint64_t max_texels = std::uint64_t(1) << 24;  // 4096 x 4096; checked before allocating
    std::uint64_t max_file_bytes = std::uint64_t(4) << 30;
    // Threads for OpenEXR's block decompression (> 1 grows OpenEXR's process-wide thread pool to
    // this size). The pixels read are the same for any count.
    int threads = 1;
};

Result<lightmap::ShLightmap> read_sh_lightmap_exr(const std::string& path, const LightmapReadOptions& options = {});
Status write_sh_lightmap_exr(const std::string& path, const lightmap::ShLightmap& lm);
Status write_irradz_exr(const std::string& path, const lightmap::IrradzPlanes& planes);

}  // namespace zhc
