// zhc/formats/io/exr_scanlines.h — a fast decoder for the chunks of scanline OpenEXR files
// compressed with ZIP (16 lines per chunk), ZIPS (1 line) or stored uncompressed, the forms SH
// lightmaps are written in. OpenEXR locates and validates each chunk (Imf::InputFile::rawPixelData);
// libdeflate inflates it, about twice as fast as the zlib OpenEXR 3.1 uses, and the byte
// de-interleave and delta predictor of OpenEXR's ZIP compressor are undone here with SIMD, then the
// wanted channels are converted to float straight into the caller's layout. Chunks are decoded on
// several threads; the result is the same for any count. The samples equal what
// Imf::InputFile::readPixels gives for FLOAT slices (tests/test_exr_scanlines.cpp compares them bit
// for bit); other files go through readPixels.
#pragma once

#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <cstddef>
#include <span>
#include <string>

#include "codec/status.h"

namespace zhc {

// True when `file` is one decode_exr_scanlines handles: a single-part scanline image (not tiled,
// not deep) compressed with ZIP, ZIPS or not at all, whose channels are HALF or FLOAT with x and y
// sampling 1, read on a little-endian machine.
bool exr_scanlines_supported(Imf::InputFile& file);

// One channel to decode: sample (x, r) of the rows read (x from the data window's left edge, r from
// the first row read) goes to the float at base + r * y_stride + x * x_stride (bytes).
struct ExrFloatSlice {
    std::string channel;
    char* base = nullptr;
    std::size_t x_stride = 0, y_stride = 0;
};

// Decodes rows [y0, y1) of the data window (0 = its top row) of the listed channels (each must
// exist) of `file`, which exr_scanlines_supported accepted, on up to `threads` threads.
// Fails kBadFormat (naming `path` and the chunk's first row) on a chunk whose data does not inflate
// to the size its rows need; OpenEXR's own exceptions (an unreadable chunk table entry) are caught
// and returned the same way.
Status decode_exr_scanlines(Imf::InputFile& file, const std::string& path, int y0, int y1,
                            std::span<const ExrFloatSlice> slices, int threads);

}  // namespace zhc
