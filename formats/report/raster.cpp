#include "formats/report/raster.h"

#include <png.h>
#include <stb_truetype.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "formats/io/file_io.h"

namespace zhc {

// The font's bytes: formats/pictures.cmake embeds the installed DejaVuSans.ttf at build time.
extern const unsigned char kEmbeddedFont[];
extern const std::size_t kEmbeddedFontSize;

namespace {

struct Font {
    stbtt_fontinfo info{};
    bool ok = false;
    int ascent = 0, descent = 0;
    Font() {
        if (kEmbeddedFontSize < 12 || kEmbeddedFontSize > (std::size_t(64) << 20)) return;
        const int offset = stbtt_GetFontOffsetForIndex(kEmbeddedFont, 0);
        if (offset < 0 || !stbtt_InitFont(&info, kEmbeddedFont, offset)) return;
        int gap = 0;
        stbtt_GetFontVMetrics(&info, &ascent, &descent, &gap);
        ok = ascent > descent;
    }
};
// Initialised once (thread-safe); stb_truetype only reads it afterwards.
const Font& font() {
    static const Font f;
    return f;
}

// Next code point of UTF-8 text at s[*i]; advances *i. Invalid or overlong sequences give U+FFFD.
int next_code_point(const std::string& s, std::size_t* i) {
    const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
    const unsigned c = b((*i)++);
    if (c < 0x80) return static_cast<int>(c);
    int extra = c >= 0xF0 && c < 0xF5 ? 3 : (c >= 0xE0 ? (c < 0xF0 ? 2 : -1) : (c >= 0xC2 ? 1 : -1));
    if (extra < 0) return 0xFFFD;
    unsigned cp = c & (0x3Fu >> extra);
    for (int k = 0; k < extra; ++k) {
        if (*i >= s.size() || (b(*i) & 0xC0) != 0x80) return 0xFFFD;
        cp = (cp << 6) | (b((*i)++) & 0x3F);
    }
    static const unsigned kMin[4] = {0, 0x80, 0x800, 0x10000};
    if (cp < kMin[extra] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0xFFFD;
    return static_cast<int>(cp);
}

// Lays the text out: calls draw(glyph, pen_x) for every glyph; returns the advance in pixels.
template <class F>
double layout(const std::string& s, double scale, F&& draw) {
    const Font& f = font();
    double pen = 0;
    int prev = 0;
    for (std::size_t i = 0; i < s.size();) {
        const int glyph = stbtt_FindGlyphIndex(&f.info, next_code_point(s, &i));
        if (prev) pen += scale * stbtt_GetGlyphKernAdvance(&f.info, prev, glyph);
        draw(glyph, pen);
        int advance = 0, lsb = 0;
        stbtt_GetGlyphHMetrics(&f.info, glyph, &advance, &lsb);
        pen += scale * advance;
        prev = glyph;
    }
    return pen;
}

}  // namespace

Canvas::Canvas(int width, int height, Rgb8 bg) : w_(std::max(1, width)), h_(std::max(1, height)) {
    px_.resize(static_cast<size_t>(w_) * h_ * 3);
    for (size_t i = 0; i < px_.size(); i += 3) {
        px_[i] = bg.r;
        px_[i + 1] = bg.g;
        px_[i + 2] = bg.b;
    }
}

void Canvas::set(int x, int y, Rgb8 c) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
    const size_t i = (static_cast<size_t>(y) * w_ + x) * 3;
    px_[i] = c.r;
    px_[i + 1] = c.g;
    px_[i + 2] = c.b;
}

void Canvas::fill_rect(int x, int y, int w, int h, Rgb8 c) {
    for (int yy = std::max(0, y); yy < std::min(h_, y + h); ++yy)
        for (int xx = std::max(0, x); xx < std::min(w_, x + w); ++xx) set(xx, yy, c);
}

void Canvas::line(double x0, double y0, double x1, double y1, Rgb8 c, int thickness) {
    const double len = std::max(std::fabs(x1 - x0), std::fabs(y1 - y0));
    const int steps = std::max(1, static_cast<int>(std::ceil(len)));
    for (int i = 0; i <= steps; ++i) {
        const double t = double(i) / steps;
        const int x = static_cast<int>(std::lround(x0 + (x1 - x0) * t)), y = static_cast<int>(std::lround(y0 + (y1 - y0) * t));
        fill_rect(x - thickness / 2, y - thickness / 2, thickness, thickness, c);
    }
}

void Canvas::blend(int x, int y, Rgb8 c, int alpha) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_ || alpha <= 0) return;
    alpha = std::min(alpha, 255);
    const size_t i = (static_cast<size_t>(y) * w_ + x) * 3;
    const std::uint8_t src[3] = {c.r, c.g, c.b};
    for (int k = 0; k < 3; ++k) px_[i + k] = static_cast<std::uint8_t>((src[k] * alpha + px_[i + k] * (255 - alpha) + 127) / 255);
}

int Canvas::text(int x, int y, const std::string& s, int size_px, Rgb8 c) {
    const Font& f = font();
    if (!f.ok || size_px <= 0 || size_px > 512) return 0;
    const float scale = stbtt_ScaleForPixelHeight(&f.info, static_cast<float>(size_px));
    const int baseline = y + static_cast<int>(std::lround(f.ascent * scale));
    std::vector<unsigned char> bitmap;
    const double advance = layout(s, scale, [&](int glyph, double pen) {
        const double gx = x + pen;
        const int ix = static_cast<int>(std::floor(gx));
        const float shift = static_cast<float>(gx - ix);
        int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
        stbtt_GetGlyphBitmapBoxSubpixel(&f.info, glyph, scale, scale, shift, 0, &x0, &y0, &x1, &y1);
        const int gw = x1 - x0, gh = y1 - y0;
        if (gw <= 0 || gh <= 0 || gw > 4 * 512 || gh > 4 * 512) return;
        bitmap.assign(static_cast<size_t>(gw) * gh, 0);
        stbtt_MakeGlyphBitmapSubpixel(&f.info, bitmap.data(), gw, gh, gw, scale, scale, shift, 0, glyph);
        for (int yy = 0; yy < gh; ++yy)
            for (int xx = 0; xx < gw; ++xx) blend(ix + x0 + xx, baseline + y0 + yy, c, bitmap[static_cast<size_t>(yy) * gw + xx]);
    });
    return static_cast<int>(std::ceil(advance));
}

int Canvas::text_width(const std::string& s, int size_px) {
    const Font& f = font();
    if (!f.ok || size_px <= 0 || size_px > 512) return 0;
    return static_cast<int>(std::ceil(layout(s, stbtt_ScaleForPixelHeight(&f.info, static_cast<float>(size_px)), [](int, double) {})));
}

std::vector<std::uint8_t> png_bytes_rgb8(const std::uint8_t* rgb, std::size_t size, int width, int height) {
    std::vector<std::uint8_t> bytes;
    if (!rgb || width <= 0 || height <= 0 || width > (1 << 14) || height > (1 << 14) ||
        size != static_cast<size_t>(width) * height * 3)
        return bytes;
    // libpng's simplified API (no setjmp here): first the size, then the bytes.
    png_image image;
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    image.width = static_cast<png_uint_32>(width);
    image.height = static_cast<png_uint_32>(height);
    image.format = PNG_FORMAT_RGB;
    png_alloc_size_t n = 0;
    if (!png_image_write_to_memory(&image, nullptr, &n, 0, rgb, width * 3, nullptr) || n == 0) {
        png_image_free(&image);
        return bytes;
    }
    bytes.resize(n);
    if (!png_image_write_to_memory(&image, bytes.data(), &n, 0, rgb, width * 3, nullptr)) bytes.clear();
    else bytes.resize(n);
    png_image_free(&image);
    return bytes;
}

Status write_png(const std::string& path, const Canvas& canvas) {
    const std::vector<std::uint8_t> bytes =
        png_bytes_rgb8(canvas.pixels().data(), canvas.pixels().size(), canvas.width(), canvas.height());
    if (bytes.empty()) return make_error(ErrorCode::kIoError, path + ": cannot encode PNG");
    return write_file_atomic(path, bytes);
}

std::uint8_t tonemap_srgb8(double x) {
    if (!(x > 0)) return 0;
    double v = x / (1.0 + x);
    v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L));
}

Rgb8 false_colour(double t) {
    t = std::clamp(std::isfinite(t) ? t : 1.0, 0.0, 1.0);
    // Piecewise-linear through five stops.
    static const double stops[5][3] = {{0, 0, 0}, {30, 60, 200}, {0, 170, 170}, {240, 220, 40}, {220, 30, 30}};
    const double s = t * 4.0;
    const int i = std::min(3, static_cast<int>(s));
    const double f = s - i;
    Rgb8 c;
    c.r = static_cast<std::uint8_t>(std::lround(stops[i][0] + (stops[i + 1][0] - stops[i][0]) * f));
    c.g = static_cast<std::uint8_t>(std::lround(stops[i][1] + (stops[i + 1][1] - stops[i][1]) * f));
    c.b = static_cast<std::uint8_t>(std::lround(stops[i][2] + (stops[i + 1][2] - stops[i][2]) * f));
    return c;
}

double ErrorScale::t(double e) const {
    if (!(e > 0)) return 0;
    if (!std::isfinite(e)) return 1;
    return std::clamp((std::log10(e) - std::log10(top)) / kDecades + 1.0, 0.0, 1.0);
}

Rgb8 ErrorScale::band_colour(double t) {
    t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 1.0;
    const int b = std::min(kBands - 1, static_cast<int>(t * kBands));
    return false_colour((b + 0.5) / kBands);
}

ErrorScale ErrorScale::from_percentile(std::vector<std::vector<double>> errors, double quantile) {
    ErrorScale s;
    quantile = std::isfinite(quantile) ? std::clamp(quantile, 0.0, 1.0) : 0.99;
    for (std::vector<double>& e : errors) {
        e.erase(std::remove_if(e.begin(), e.end(), [](double v) { return !std::isfinite(v); }), e.end());
        if (e.empty()) continue;
        const size_t k = std::min(e.size() - 1, static_cast<size_t>(quantile * static_cast<double>(e.size())));
        std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(k), e.end());
        s.top = std::max(s.top, e[k]);
    }
    return s;
}

std::string percent_text(double rel) {
    const double p = rel * 100.0;
    char b[64];
    if (!std::isfinite(p)) return "inf%";
    if (p >= 10) std::snprintf(b, sizeof b, "%.0f%%", p);
    else if (p >= 1) std::snprintf(b, sizeof b, "%.1f%%", p);
    else std::snprintf(b, sizeof b, "%.2g%%", p);
    return b;
}

}  // namespace zhc
