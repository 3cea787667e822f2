#include "formats/report/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "codec/audit/benchmark.h"
#include "formats/report/raster.h"

namespace zhc {

namespace {
constexpr int kSmall = 17, kTitle = 24;  // text sizes in pixels (DejaVu Sans)
std::string tick_label(double v) {
    char b[32];
    if (v >= 1e4 || v < 1e-2) std::snprintf(b, sizeof b, "%.0e", v);
    else std::snprintf(b, sizeof b, "%g", v);
    return b;
}
}  // namespace

PlotPoint codec_point(const Codec& codec, double x, double y) {
    return {std::string(codec.name), x, y, !codec.traits.engine.empty()};
}

std::vector<std::size_t> zhc_frontier(const ScatterPlot& plot) {
    std::vector<std::size_t> own;
    std::vector<double> x, y;
    for (std::size_t i = 0; i < plot.points.size(); ++i)
        if (!plot.points[i].engine) {
            own.push_back(i);
            x.push_back(plot.points[i].x);
            y.push_back(plot.points[i].y);
        }
    std::vector<std::size_t> front;
    for (std::size_t k : pareto_frontier(x, y)) front.push_back(own[k]);
    return front;
}

Status write_scatter_png(const std::string& path, const ScatterPlot& plot) {
    const int W = 1200, H = 720, left = 110, right = 290, top = 60, bottom = 80, row = 21;
    Canvas c(W, H, {255, 255, 255});
    const Rgb8 ink{30, 30, 30}, grid{225, 225, 225}, dot{40, 90, 200}, front{220, 60, 40}, engine{230, 140, 20};
    auto tx = [&](double v) { return plot.log_x ? std::log10(std::max(v, 1e-30)) : v; };
    auto ty = [&](double v) { return plot.log_y ? std::log10(std::max(v, 1e-30)) : v; };
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const PlotPoint& p : plot.points) {
        if (!std::isfinite(tx(p.x)) || !std::isfinite(ty(p.y))) continue;
        x0 = std::min(x0, tx(p.x));
        x1 = std::max(x1, tx(p.x));
        y0 = std::min(y0, ty(p.y));
        y1 = std::max(y1, ty(p.y));
    }
    if (x0 > x1) x0 = 0, x1 = 1;
    if (y0 > y1) y0 = 0, y1 = 1;
    if (plot.log_x) x0 = std::floor(x0 - 0.05), x1 = std::ceil(x1 + 0.05);
    else { const double m = 0.08 * std::max(x1 - x0, 1e-9); x0 -= m; x1 += m; }
    if (plot.log_y) y0 = std::floor(y0 - 0.05), y1 = std::ceil(y1 + 0.05);
    else { const double m = 0.08 * std::max(y1 - y0, 1e-9); y0 -= m; y1 += m; }
    const int pw = W - left - right, ph = H - top - bottom;
    auto px = [&](double v) { return left + (tx(v) - x0) / (x1 - x0) * pw; };
    auto py = [&](double v) { return top + ph - (ty(v) - y0) / (y1 - y0) * ph; };
    // Grid and ticks: decades on log axes, 5 divisions on linear ones.
    auto ticks = [](double a, double b, bool log) {
        std::vector<double> t;
        if (log) for (double e = std::ceil(a); e <= b + 1e-9; e += 1) t.push_back(std::pow(10.0, e));
        else for (int i = 0; i <= 5; ++i) t.push_back(a + (b - a) * i / 5);
        return t;
    };
    for (double v : ticks(x0, x1, plot.log_x)) {
        const double x = left + ((plot.log_x ? std::log10(v) : v) - x0) / (x1 - x0) * pw;
        c.line(x, top, x, top + ph, grid);
        c.text(static_cast<int>(x) - Canvas::text_width(tick_label(v), kSmall) / 2, top + ph + 8, tick_label(v), kSmall, ink);
    }
    for (double v : ticks(y0, y1, plot.log_y)) {
        const double y = top + ph - ((plot.log_y ? std::log10(v) : v) - y0) / (y1 - y0) * ph;
        c.line(left, y, left + pw, y, grid);
        c.text(left - 8 - Canvas::text_width(tick_label(v), kSmall), static_cast<int>(y) - kSmall / 2, tick_label(v), kSmall, ink);
    }
    c.line(left, top, left, top + ph, ink, 2);
    c.line(left, top + ph, left + pw, top + ph, ink, 2);
    c.text(left, 14, plot.title, kTitle, ink);
    c.text(left + pw / 2 - Canvas::text_width(plot.x_label, kSmall) / 2, H - 38, plot.x_label, kSmall, ink);
    c.text(10, top - 24, plot.y_label, kSmall, ink);
    // Frontier first (under the points).
    for (size_t i = 1; i < plot.frontier.size(); ++i) {
        const PlotPoint& a = plot.points[plot.frontier[i - 1]];
        const PlotPoint& b = plot.points[plot.frontier[i]];
        c.line(px(a.x), py(a.y), px(b.x), py(b.y), front, 3);
    }
    std::vector<bool> on_front(plot.points.size(), false);
    for (size_t i : plot.frontier)
        if (i < plot.points.size()) on_front[i] = true;
    // Labels never overprint: each sits in a column right of the plot, in the order of its point's
    // height, at least `row` pixels from the next, joined to its point by a leader line.
    std::vector<size_t> order;
    for (size_t i = 0; i < plot.points.size(); ++i)
        if (std::isfinite(py(plot.points[i].y)) && std::isfinite(px(plot.points[i].x))) order.push_back(i);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return py(plot.points[a].y) < py(plot.points[b].y); });
    std::vector<double> ly(order.size());
    for (size_t k = 0; k < order.size(); ++k) {
        ly[k] = std::max(py(plot.points[order[k]].y), static_cast<double>(top));
        if (k) ly[k] = std::max(ly[k], ly[k - 1] + row);
    }
    for (size_t k = order.size(); k-- > 0;)
        ly[k] = std::min(ly[k], k + 1 < order.size() ? ly[k + 1] - row : static_cast<double>(H - 12));
    const int lx = left + pw + 28;
    for (size_t k = 0; k < order.size(); ++k) {
        const bool f = on_front[order[k]];
        c.line(px(plot.points[order[k]].x), py(plot.points[order[k]].y), lx - 4, ly[k], f ? Rgb8{240, 170, 160} : Rgb8{200, 200, 200});
    }
    for (size_t k = 0; k < order.size(); ++k) {
        const PlotPoint& p = plot.points[order[k]];
        const bool f = on_front[order[k]];
        const int x = static_cast<int>(std::lround(px(p.x))), y = static_cast<int>(std::lround(py(p.y)));
        if (p.engine) c.fill_rect(x - 5, y - 5, 11, 11, engine);  // a bigger orange square
        else c.fill_rect(x - 4, y - 4, 9, 9, f ? front : dot);
        c.text(lx, static_cast<int>(std::lround(ly[k])) - kSmall / 2, p.label, kSmall, p.engine ? engine : (f ? front : ink));
    }
    const std::string legend = "red: Pareto frontier";
    c.text(left + pw - 12 - Canvas::text_width(legend, kSmall), top + 8, legend, kSmall, front);
    if (std::any_of(plot.points.begin(), plot.points.end(), [](const PlotPoint& p) { return p.engine; })) {
        const std::string more = "orange: engine layouts";
        c.text(left + pw - 12 - Canvas::text_width(more, kSmall), top + 8 + row, more, kSmall, engine);
    }
    return write_png(path, c);
}

}  // namespace zhc
