// zhc/formats/raster.h — a minimal RGB8 canvas for the pictures zhc writes (audit images, plots):
// rectangles, lines, a built-in 3x5 pixel font (upper-case, digits, a few symbols), PNG output.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

struct Rgb8 {
    std::uint8_t r = 0, g = 0, b = 0;
};

class Canvas {
public:
    Canvas(int width, int height, Rgb8 background = {255, 255, 255});
    int width() const { return w_; }
    int height() const { return h_; }
    void set(int x, int y, Rgb8 c);  // ignores pixels outside the canvas
    void fill_rect(int x, int y, int w, int h, Rgb8 c);
    void line(double x0, double y0, double x1, double y1, Rgb8 c, int thickness = 1);
    // Text in the built-in 3x5 font scaled by `scale` (lower case is drawn as upper case; unknown
    // characters as a box). Returns the width drawn in pixels.
    int text(int x, int y, const std::string& s, int scale, Rgb8 c);
    static int text_width(const std::string& s, int scale) { return static_cast<int>(s.size()) * 4 * scale; }
    const std::vector<std::uint8_t>& pixels() const { return px_; }

private:
    int w_, h_;
    std::vector<std::uint8_t> px_;
};

// Writes the canvas as a PNG, atomically.
Status write_png(const std::string& path, const Canvas& canvas);

// Linear [0, inf) -> display: Reinhard x / (1 + x) then the sRGB transfer curve, to 8 bits.
std::uint8_t tonemap_srgb8(double linear);
// A perceptually ordered false-colour ramp for t in [0, 1]: black, blue, teal, yellow, red.
Rgb8 false_colour(double t);

}  // namespace zhc
