#include "raster.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "file_io.h"

namespace zhc {

namespace {
// 3x5 glyphs, rows top to bottom, '#' set. Drawn for zhc; covers what labels and axes need.
struct Glyph {
    char c;
    const char* rows[5];
};
const Glyph kGlyphs[] = {
    {'A', {".#.", "#.#", "###", "#.#", "#.#"}}, {'B', {"##.", "#.#", "##.", "#.#", "##."}},
    {'C', {".##", "#..", "#..", "#..", ".##"}}, {'D', {"##.", "#.#", "#.#", "#.#", "##."}},
    {'E', {"###", "#..", "##.", "#..", "###"}}, {'F', {"###", "#..", "##.", "#..", "#.."}},
    {'G', {".##", "#..", "#.#", "#.#", ".##"}}, {'H', {"#.#", "#.#", "###", "#.#", "#.#"}},
    {'I', {"###", ".#.", ".#.", ".#.", "###"}}, {'J', {"..#", "..#", "..#", "#.#", ".#."}},
    {'K', {"#.#", "#.#", "##.", "#.#", "#.#"}}, {'L', {"#..", "#..", "#..", "#..", "###"}},
    {'M', {"#.#", "###", "###", "#.#", "#.#"}}, {'N', {"##.", "#.#", "#.#", "#.#", "#.#"}},
    {'O', {".#.", "#.#", "#.#", "#.#", ".#."}}, {'P', {"##.", "#.#", "##.", "#..", "#.."}},
    {'Q', {".#.", "#.#", "#.#", "##.", ".##"}}, {'R', {"##.", "#.#", "##.", "#.#", "#.#"}},
    {'S', {".##", "#..", ".#.", "..#", "##."}}, {'T', {"###", ".#.", ".#.", ".#.", ".#."}},
    {'U', {"#.#", "#.#", "#.#", "#.#", "###"}}, {'V', {"#.#", "#.#", "#.#", "#.#", ".#."}},
    {'W', {"#.#", "#.#", "###", "###", "#.#"}}, {'X', {"#.#", "#.#", ".#.", "#.#", "#.#"}},
    {'Y', {"#.#", "#.#", ".#.", ".#.", ".#."}}, {'Z', {"###", "..#", ".#.", "#..", "###"}},
    {'0', {"###", "#.#", "#.#", "#.#", "###"}}, {'1', {".#.", "##.", ".#.", ".#.", "###"}},
    {'2', {"##.", "..#", ".#.", "#..", "###"}}, {'3', {"##.", "..#", ".#.", "..#", "##."}},
    {'4', {"#.#", "#.#", "###", "..#", "..#"}}, {'5', {"###", "#..", "##.", "..#", "##."}},
    {'6', {".##", "#..", "###", "#.#", "###"}}, {'7', {"###", "..#", ".#.", ".#.", ".#."}},
    {'8', {"###", "#.#", "###", "#.#", "###"}}, {'9', {"###", "#.#", "###", "..#", "##."}},
    {'_', {"...", "...", "...", "...", "###"}}, {'.', {"...", "...", "...", "...", ".#."}},
    {'-', {"...", "...", "###", "...", "..."}}, {':', {"...", ".#.", "...", ".#.", "..."}},
    {'%', {"#.#", "..#", ".#.", "#..", "#.#"}}, {'(', {"..#", ".#.", ".#.", ".#.", "..#"}},
    {')', {"#..", ".#.", ".#.", ".#.", "#.."}}, {'/', {"..#", "..#", ".#.", "#..", "#.."}},
    {'=', {"...", "###", "...", "###", "..."}}, {'+', {"...", ".#.", "###", ".#.", "..."}},
    {',', {"...", "...", "...", ".#.", "#.."}}, {'<', {"..#", ".#.", "#..", ".#.", "..#"}},
    {'>', {"#..", ".#.", "..#", ".#.", "#.."}}, {'|', {".#.", ".#.", ".#.", ".#.", ".#."}},
};
const Glyph* find_glyph(char c) {
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
    for (const Glyph& g : kGlyphs)
        if (g.c == c) return &g;
    return nullptr;
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

int Canvas::text(int x, int y, const std::string& s, int scale, Rgb8 c) {
    int cx = x;
    for (char ch : s) {
        if (ch != ' ') {
            const Glyph* g = find_glyph(ch);
            for (int r = 0; r < 5; ++r)
                for (int col = 0; col < 3; ++col) {
                    const bool on = g ? g->rows[r][col] == '#' : (r == 0 || r == 4 || col == 0 || col == 2);
                    if (on) fill_rect(cx + col * scale, y + r * scale, scale, scale, c);
                }
        }
        cx += 4 * scale;
    }
    return cx - x;
}

Status write_png(const std::string& path, const Canvas& canvas) {
    std::vector<std::uint8_t> bytes;
    auto sink = [](void* ctx, void* data, int size) {
        auto* out = static_cast<std::vector<std::uint8_t>*>(ctx);
        out->insert(out->end(), static_cast<std::uint8_t*>(data), static_cast<std::uint8_t*>(data) + size);
    };
    if (!stbi_write_png_to_func(sink, &bytes, canvas.width(), canvas.height(), 3, canvas.pixels().data(),
                                canvas.width() * 3))
        return make_error(ErrorCode::kIoError, path + ": cannot encode PNG");
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

}  // namespace zhc
