// zhc/formats/report/raster.h — a minimal RGB8 canvas for the pictures zhc writes (audit images, plots):
// rectangles, lines, anti-aliased text in DejaVu Sans (Debian fonts-dejavu-core, embedded at build
// time by formats/pictures.cmake, rendered with stb_truetype), PNG output through libpng.
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
    // Blends c over the pixel with coverage alpha in [0, 255].
    void blend(int x, int y, Rgb8 c, int alpha);
    // UTF-8 text in DejaVu Sans, anti-aliased, `size_px` pixels from the top of the ascenders to
    // the bottom of the descenders (capitals are about 0.63 size_px tall); (x, y) is the top left
    // of that line box. Characters the font lacks draw as its missing-glyph box; bytes that are not
    // UTF-8 as U+FFFD. Returns the advance in pixels.
    int text(int x, int y, const std::string& s, int size_px, Rgb8 c);
    static int text_width(const std::string& s, int size_px);
    const std::vector<std::uint8_t>& pixels() const { return px_; }

private:
    int w_, h_;
    std::vector<std::uint8_t> px_;
};

// Writes the canvas as a PNG, atomically.
Status write_png(const std::string& path, const Canvas& canvas);
// RGB8 pixels (w*h*3, `size` bytes) -> PNG bytes (Debian libpng: zlib with adaptive row filters,
// about a third smaller than stb_image_write's deflate); empty when the size does not match or a
// side is over 2^14.
std::vector<std::uint8_t> png_bytes_rgb8(const std::uint8_t* rgb, std::size_t size, int width, int height);

// The shared heat-map scale of the error pictures: logarithmic over three decades whose top is
// `top` (an error >= top gets the top colour), four colour bands per decade of the false-colour
// ramp (read as contours; they also compress far better than a continuous ramp).
struct ErrorScale {
    double top = 1e-6;
    static constexpr double kDecades = 3;
    static constexpr int kBands = 4 * static_cast<int>(kDecades);
    double t(double e) const;        // [0, 1]
    static Rgb8 band_colour(double t);
    Rgb8 colour(double e) const { return band_colour(t(e)); }
    // The top for a set of error samples per picture: the largest 99th percentile (non-finite
    // samples ignored; at least 1e-6).
    static ErrorScale from_percentile(std::vector<std::vector<double>> errors_per_picture, double quantile = 0.99);
};
// A relative error as a short percentage ("52%", "5.2%", "0.052%").
std::string percent_text(double relative);

// Linear [0, inf) -> display: Reinhard x / (1 + x) then the sRGB transfer curve, to 8 bits.
std::uint8_t tonemap_srgb8(double linear);
// A perceptually ordered false-colour ramp for t in [0, 1]: black, blue, teal, yellow, red.
Rgb8 false_colour(double t);

}  // namespace zhc
