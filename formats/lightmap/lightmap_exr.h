// zhc/formats/lightmap/lightmap_exr.h — lightmap hub files: per-texel SH3 radiance in the tangent frame as
// OpenEXR, and the decoded IrradZ planes as OpenEXR (docs/lightmap-formats.md).
//
// SH lightmap EXR: 27 channels named "sh<i>.<C>", i = 0..8 in zhc's coefficient order (l(l+1)+m),
// C in {R, G, B}: "sh0.R", "sh0.G", "sh0.B", ..., "sh8.B". HALF or FLOAT; radiance (not irradiance),
// in each texel's tangent frame (surface normal = +Z), zhc's SH basis (codec/sh/sh.h). Other channels
// are ignored.
// IrradZ EXR (what `zhc lightmap decode` writes): FLOAT channels "Iz.R", "Iz.G", "Iz.B", "wa",
// "d.X", "d.Y", "d.Z" (d a unit tangent-frame vector).
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments. The only process-wide state touched is OpenEXR's own
// global thread pool (grown, never shrunk, when a call asks for more threads; OpenEXR
// guards it), which never changes the bytes read or written.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "codec/lightmap/lightmap.h"
#include "codec/status.h"

namespace zhc {

struct LightmapReadOptions {
    std::uint64_t max_texels = std::uint64_t(1) << 24;  // 4096 x 4096; checked before allocating
    std::uint64_t max_file_bytes = std::uint64_t(4) << 30;
    // Threads for OpenEXR's block decompression (> 1 grows OpenEXR's process-wide thread pool to
    // this size). The pixels read are the same for any count.
    int threads = 1;
};

// ---- streaming (bounded memory) ------------------------------------------------------------
//
// Input forms a ShLightmapSource accepts (docs/lightmap-formats.md):
//  - one EXR with "sh0.R" .. "sh8.B" (27 channels): SH3;
//  - one EXR with "sh0.R" .. "sh3.B" and none of sh4..sh8 (12 channels): linear SH (L0 + L1);
//  - 4 or 9 EXRs, one per coefficient in zhc's order (sh0, sh1 = Y1-1, sh2 = Y1,0, sh3 = Y1,1, ...),
//    each with channels "R", "G", "B" (4 files: linear SH). All the same size.
// Linear SH is read into the SH3 hub with a zero L2 band. Values in zhc's SH basis (codec/sh/sh.h).
struct LightmapStreamOptions {
    std::uint64_t max_texels = std::uint64_t(1) << 28;      // 16384 x 16384
    std::uint64_t max_file_bytes = std::uint64_t(1) << 40;  // the file is mapped, not read into memory
    int threads = 1;                                        // OpenEXR block decompression threads
};

class ShLightmapSource {
public:
    virtual ~ShLightmapSource() = default;
    static Result<std::unique_ptr<ShLightmapSource>> open(const std::vector<std::string>& paths,
                                                          const LightmapStreamOptions& options = {});
    virtual int width() const = 0;
    virtual int height() const = 0;
    // 9 (SH3 input) or 4 (linear SH input: L2 of every texel read is 0).
    virtual int coefficients() const = 0;
    // Rows [y0, y1) (0 = the top of the data window) into `band` (resized to width x (y1 - y0)).
    // Fails kInvalidValue on a non-finite value (naming the channel and the texel).
    virtual Status read_rows(int y0, int y1, lightmap::ShLightmap& band) = 0;
};

// Writes an EXR (FLOAT or HALF channels, ZIP) band by band through OpenEXR's scanline writer, to a
// temporary file renamed over `path` by commit(); destroyed without commit, nothing is left.
class ExrBandWriter {
public:
    virtual ~ExrBandWriter() = default;
    // names: the channels, in the order of the floats of each texel in write_rows' data.
    // threads > 1: OpenEXR compresses on that many threads (the same bytes).
    static Result<std::unique_ptr<ExrBandWriter>> open(const std::string& path, int width, int height,
                                                       const std::vector<std::string>& names, bool half, int threads = 1);
    // The next `rows` rows: rows * width * names.size() floats, interleaved per texel.
    virtual Status write_rows(const float* data, int rows) = 0;
    virtual Status commit() = 0;
};
// The channel names of the two kinds of lightmap EXR zhc writes.
std::vector<std::string> sh_lightmap_channel_names();
std::vector<std::string> irradz_channel_names();

// What a lightmap EXR is, from its header (zhc info): kind "sh3" (sh0.R .. sh8.B), "linear-sh"
// (sh0.R .. sh3.B, none of sh4 .. sh8), "irradz" (Iz.R, Iz.G, Iz.B, wa, d.X, d.Y, d.Z) or ""
// (none of these: not a lightmap EXR; an R, G, B coefficient file of a 4- or 9-file set is an
// ordinary RGB image). The whole file is checked as the readers check it (truncation, trailing bytes).
struct LightmapExrSummary {
    std::string kind;
    int width = 0, height = 0;
    std::vector<std::string> channels;  // every channel of the first part, in the file's order
    std::string pixel_type;             // "half", "float", "uint" or "mixed"
};
Result<LightmapExrSummary> describe_lightmap_exr(std::span<const std::uint8_t> bytes, const std::string& name,
                                                 std::uint64_t max_texels = std::uint64_t(1) << 28);
Result<lightmap::ShLightmap> read_sh_lightmap_exr(const std::string& path, const LightmapReadOptions& options = {});
Status write_sh_lightmap_exr(const std::string& path, const lightmap::ShLightmap& lm);
Status write_irradz_exr(const std::string& path, const lightmap::IrradzPlanes& planes);

}  // namespace zhc
