#include "formats/report/lightmap_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "formats/io/file_io.h"
#include "formats/report/html_report.h"
#include "formats/report/raster.h"

namespace zhc {

namespace {

constexpr double kErrorCap = 1e6;  // a non-finite or absurd error counts as this (relative)
const Rgb8 kNegative{255, 0, 255};

// An RGB8 picture being built.
struct Picture {
    int w = 0, h = 0;
    std::vector<std::uint8_t> px;
    Picture(int width, int height) : w(width), h(height), px(static_cast<size_t>(width) * height * 3, 0) {}
    void set(int x, int y, Rgb8 c) {
        if (x < 0 || y < 0 || x >= w || y >= h) return;
        const size_t i = (static_cast<size_t>(y) * w + x) * 3;
        px[i] = c.r;
        px[i + 1] = c.g;
        px[i + 2] = c.b;
    }
    // Nearest-neighbour enlargement by an integer factor (pixels stay sharp at 100 %).
    Picture enlarged(int f) const {
        if (f <= 1) return *this;
        Picture out(w * f, h * f);
        for (int y = 0; y < out.h; ++y)
            for (int x = 0; x < out.w; ++x) {
                const size_t s = (static_cast<size_t>(y / f) * w + x / f) * 3, d = (static_cast<size_t>(y) * out.w + x) * 3;
                out.px[d] = px[s];
                out.px[d + 1] = px[s + 1];
                out.px[d + 2] = px[s + 2];
            }
        return out;
    }
    // A one-pixel outline of the rectangle [x0, x1) x [y0, y1), in two colours so it shows on any background.
    void outline(int x0, int y0, int x1, int y1) {
        for (int x = x0; x < x1; ++x) {
            set(x, y0, {255, 255, 255});
            set(x, y1 - 1, {255, 255, 255});
            set(x, y0 + 1, {0, 0, 0});
            set(x, y1 - 2, {0, 0, 0});
        }
        for (int y = y0; y < y1; ++y) {
            set(x0, y, {255, 255, 255});
            set(x1 - 1, y, {255, 255, 255});
            set(x0 + 1, y, {0, 0, 0});
            set(x1 - 2, y, {0, 0, 0});
        }
    }
};

// Integer enlargement so that the longer side reaches about `target` pixels (at most 8x).
int enlargement(int w, int h, int target) { return std::clamp(target / std::max({w, h, 1}), 1, 8); }

std::string img(const Picture& p, const std::string& alt) {
    const std::vector<std::uint8_t> png = encode_png_rgb8(p.px, p.w, p.h);
    return "<img src=\"data:image/png;base64," + base64_encode(png) + "\" width=\"" + std::to_string(p.w) + "\" height=\"" +
           std::to_string(p.h) + "\" alt=\"" + html_escape(alt) + "\">";
}

}  // namespace

CropWindow worst_error_window(const std::vector<double>& error, int width, int height, int size) {
    CropWindow win;
    if (width <= 0 || height <= 0 || size <= 0 || error.size() != static_cast<size_t>(width) * height) return win;
    const int cw = std::min(size, width), ch = std::min(size, height);
    win.width = cw;
    win.height = ch;
    auto e = [&](int x, int y) {
        const double v = error[static_cast<size_t>(y) * width + x];
        return std::isfinite(v) ? std::clamp(v, 0.0, kErrorCap) : kErrorCap;
    };
    // Column sums over the rows [y, y + ch), slid down one row at a time; for each y a horizontal
    // sliding window over them. O(width * height) time, O(width) memory; deterministic.
    std::vector<double> col(static_cast<size_t>(width), 0.0);
    for (int y = 0; y < ch; ++y)
        for (int x = 0; x < width; ++x) col[static_cast<size_t>(x)] += e(x, y);
    double best = -1;
    for (int y = 0; y + ch <= height; ++y) {
        if (y > 0) {
            for (int x = 0; x < width; ++x) col[static_cast<size_t>(x)] += e(x, y + ch - 1) - e(x, y - 1);
        }
        double sum = 0;
        for (int x = 0; x < cw; ++x) sum += col[static_cast<size_t>(x)];
        for (int x = 0; x + cw <= width; ++x) {
            if (x > 0) sum += col[static_cast<size_t>(x + cw - 1)] - col[static_cast<size_t>(x - 1)];
            if (sum > best * (1 + 1e-12) + 1e-300) {
                best = sum;
                win.x = x;
                win.y = y;
            }
        }
    }
    return win;
}

namespace {
// One view of the lightmap (before, after, error): the overview and, with `crop`, the worst window.
void view_html(std::ostringstream& o, const LightmapHtml& p, const std::vector<float>& before, const std::vector<float>& after,
               const std::string& heading, const std::string& what, bool crop) {
    const int w = p.width, h = p.height;
    const size_t n = w > 0 && h > 0 ? static_cast<size_t>(w) * h : 0;
    if (n > 0 && n <= (size_t(1) << 28) && before.size() == 3 * n && after.size() == 3 * n) {
        double mean = 0;
        size_t count = 0;
        for (size_t i = 0; i < n; ++i) {
            const double v = (double(before[3 * i]) + before[3 * i + 1] + before[3 * i + 2]) / 3.0;
            if (std::isfinite(v)) mean += v, ++count;
        }
        mean = std::max(count ? mean / static_cast<double>(count) : 0.0, 1e-12);
        std::vector<double> err(n);
        for (size_t i = 0; i < n; ++i) {
            double e = 0;
            for (int k = 0; k < 3; ++k) e = std::max(e, std::fabs(double(after[3 * i + k]) - before[3 * i + k]));
            err[i] = std::isfinite(e) ? std::min(e / mean, kErrorCap) : kErrorCap;
        }
        const ErrorScale scale = ErrorScale::from_percentile({err});
        const double worst = *std::max_element(err.begin(), err.end());
        auto tone = [&](const std::vector<float>& img, size_t i) -> Rgb8 {
            const float* v = &img[3 * i];
            if (v[0] < 0 || v[1] < 0 || v[2] < 0) return kNegative;
            return {tonemap_srgb8(v[0] / mean), tonemap_srgb8(v[1] / mean), tonemap_srgb8(v[2] / mean)};
        };
        // Overview: the whole lightmap box-downsampled to at most 512 on a side (the error by the
        // block's maximum, so no error disappears), enlarged when small.
        const int f = std::max(1, (std::max(w, h) + 511) / 512);
        const int ow = (w + f - 1) / f, oh = (h + f - 1) / f;
        Picture ob(ow, oh), oa(ow, oh), oe(ow, oh);
        for (int by = 0; by < oh; ++by)
            for (int bx = 0; bx < ow; ++bx) {
                double sb[3] = {0, 0, 0}, sa[3] = {0, 0, 0}, emax = 0;
                int cnt = 0;
                for (int y = by * f; y < std::min(h, (by + 1) * f); ++y)
                    for (int x = bx * f; x < std::min(w, (bx + 1) * f); ++x) {
                        const size_t i = static_cast<size_t>(y) * w + x;
                        for (int k = 0; k < 3; ++k) sb[k] += before[3 * i + k], sa[k] += after[3 * i + k];
                        emax = std::max(emax, err[i]);
                        ++cnt;
                    }
                auto px = [&](const double* s) -> Rgb8 {
                    if (s[0] < 0 || s[1] < 0 || s[2] < 0) return kNegative;
                    return {tonemap_srgb8(s[0] / cnt / mean), tonemap_srgb8(s[1] / cnt / mean), tonemap_srgb8(s[2] / cnt / mean)};
                };
                ob.set(bx, by, px(sb));
                oa.set(bx, by, px(sa));
                oe.set(bx, by, scale.colour(emax));
            }
        const CropWindow win = worst_error_window(err, w, h, 256);
        const int ou = enlargement(ow, oh, 384);
        Picture obe = ob.enlarged(ou), oae = oa.enlarged(ou), oee = oe.enlarged(ou);
        const int rx0 = win.x / f * ou, ry0 = win.y / f * ou;
        const int rx1 = std::max(rx0 + 4, (win.x + win.width + f - 1) / f * ou), ry1 = std::max(ry0 + 4, (win.y + win.height + f - 1) / f * ou);
        for (Picture* q : {&obe, &oae, &oee}) q->outline(rx0, ry0, rx1, ry1);
        // The crop, at 1:1 (enlarged when the lightmap is small).
        Picture cb(win.width, win.height), ca(win.width, win.height), ce(win.width, win.height);
        double crop_worst = 0;
        for (int y = 0; y < win.height; ++y)
            for (int x = 0; x < win.width; ++x) {
                const size_t i = static_cast<size_t>(win.y + y) * w + (win.x + x);
                cb.set(x, y, tone(before, i));
                ca.set(x, y, tone(after, i));
                ce.set(x, y, scale.colour(err[i]));
                crop_worst = std::max(crop_worst, err[i]);
            }
        const int cu = enlargement(win.width, win.height, 256);
        o << "<h2>" << html_escape(heading) << "</h2>\n<p class=\"scale\">" << what << " "
          << html_escape(p.before_label) << " and " << html_escape(p.after_label)
          << ", exposed by the mean irradiance before (" << html_number(mean)
          << ") and tone-mapped (Reinhard, sRGB); <span class=\"neg\">magenta</span> marks negative values. Error: max over "
             "channels of |after &minus; before| / mean, on a logarithmic scale (three decades, four colour bands each) "
             "whose top is the 99th percentile of the error ("
          << percent_text(scale.top) << "; largest " << percent_text(worst) << "):</p>\n"
          << colour_bar_svg(scale) << "\n";
        o << "<h3>Whole lightmap</h3>\n<p class=\"small\">" << w << "x" << h << " texels"
          << (f > 1 ? ", downsampled " + std::to_string(f) + "x (irradiance: block mean; error: block maximum)" : "")
          << (ou > 1 ? ", shown " + std::to_string(ou) + "x" : "") << "; the outlined square is the worst-error window.</p>\n<div class=\"cards\">\n"
          << "<figure class=\"card\"><figcaption>" << html_escape(p.before_label) << "</figcaption>" << img(obe, "overview " + p.before_label) << "</figure>\n"
          << "<figure class=\"card\"><figcaption>" << html_escape(p.after_label) << "</figcaption>" << img(oae, "overview " + p.after_label) << "</figure>\n"
          << "<figure class=\"card\"><figcaption>error</figcaption>" << img(oee, "overview error") << "</figure>\n</div>\n";
        if (!crop) return;
        o << "<h3>Worst-error region</h3>\n<p class=\"small\" id=\"crop\">Texels (" << win.x << ", " << win.y << ") to ("
          << win.x + win.width - 1 << ", " << win.y + win.height - 1 << "), the " << win.width << "x" << win.height
          << " window with the largest summed error, at 1:1" << (cu > 1 ? " enlarged " + std::to_string(cu) + "x" : "")
          << "; largest error in it " << percent_text(crop_worst) << ".</p>\n<div class=\"cards\">\n"
          << "<figure class=\"card\"><figcaption>" << html_escape(p.before_label) << "</figcaption>" << img(cb.enlarged(cu), "crop " + p.before_label) << "</figure>\n"
          << "<figure class=\"card\"><figcaption>" << html_escape(p.after_label) << "</figcaption>" << img(ca.enlarged(cu), "crop " + p.after_label) << "</figure>\n"
          << "<figure class=\"card\"><figcaption>error</figcaption>" << img(ce.enlarged(cu), "crop error") << "</figure>\n</div>\n";
    }
}
}  // namespace

std::string lightmap_html_report(const LightmapHtml& p) {
    std::ostringstream o;
    o << html_page_begin(p.title, p.version);
    o << "<h1>" << html_escape(p.title) << "</h1>\n<p>zhc " << html_escape(p.version) << ". " << html_escape(p.intro) << "</p>\n";
    o << "<h2>Inputs and options</h2>\n<dl class=\"settings\">\n<dt>zhc version</dt><dd>" << html_escape(p.version) << "</dd>\n";
    for (const auto& [k, v] : p.settings) o << "<dt>" << html_escape(k) << "</dt><dd>" << html_escape(v) << "</dd>\n";
    o << "<dt>size</dt><dd>" << p.width << "x" << p.height << " texels</dd>\n</dl>\n";
    o << "<h2>Summary</h2>\n<table class=\"sortable\" id=\"summary\">\n<caption>Hemispherical irradiance error against the "
         "SH3 lightmap</caption>\n<thead><tr><th scope=\"col\">representation</th><th scope=\"col\">rmse</th>"
         "<th scope=\"col\">relative rmse</th></tr></thead>\n<tbody>\n";
    for (const LightmapHtmlRow& r : p.rows)
        o << "<tr class=\"rep\"><th scope=\"row\">" << html_escape(r.name) << "</th><td data-v=\"" << html_number(r.rmse, "%.17g") << "\">"
          << html_number(r.rmse, "%.6g") << "</td><td data-v=\"" << html_number(r.relative, "%.17g") << "\">" << percent_text(r.relative)
          << "</td></tr>\n";
    o << "</tbody></table>\n";
    if (!p.metrics.empty()) {
        o << "<table class=\"metrics\">\n<tbody>\n";
        for (const auto& [k, v] : p.metrics) o << "<tr><th scope=\"row\">" << html_escape(k) << "</th><td>" << html_escape(v) << "</td></tr>\n";
        o << "</tbody></table>\n";
    }
    const size_t texels = p.width > 0 && p.height > 0 ? static_cast<size_t>(p.width) * p.height : 0;
    view_html(o, p, p.before, p.after, "Pictures: irradiance at the normal",
              "Irradiance at each texel's normal (I<sub>z</sub>, linear RGB)", true);
    if (!p.tilted_before.empty() && p.tilted_before.size() == 3 * texels && p.tilted_after.size() == 3 * texels)
        view_html(o, p, p.tilted_before, p.tilted_after, "Pictures: " + p.tilted_label, html_escape(p.tilted_what), false);
    o << html_page_end();
    return o.str();
}

Status write_lightmap_html_report(const std::string& path, const LightmapHtml& page) {
    const std::string text = lightmap_html_report(page);
    return write_file_atomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
}

LightmapHtml lightmap_audit_html(const std::string& version, std::vector<std::pair<std::string, std::string>> settings,
                                 const lightmap::IrradzPlanes& before, const lightmap::IrradzPlanes& after,
                                 const lightmap::Audit& a) {
    LightmapHtml p;
    p.version = version;
    p.settings = std::move(settings);
    p.intro = "IrradZ lightmap before and after block compression (I_z in BC6H, d in BC5, w_a in BC4: 2.5 bytes per texel). "
              "Errors of the hemispherical irradiance against the SH3 lightmap over " +
              std::to_string(a.texels_sampled) + " audited texels; pictures of I_z, the irradiance at the normal.";
    if (before.width == after.width && before.height == after.height) {
        p.width = before.width;
        p.height = before.height;
        p.before = before.iz;
        p.after = after.iz;
    }
    if (p.width > 0 && before.width == after.width && before.height == after.height) {
        const size_t n = static_cast<size_t>(before.width) * before.height;
        if (before.iz.size() == 3 * n && before.wa.size() == n && before.d.size() == 2 * n && after.iz.size() == 3 * n &&
            after.wa.size() == n && after.d.size() == 2 * n) {
            const double s = std::sqrt(0.5);
            const Vec3 tilted{s, 0, s};
            p.tilted_before.resize(3 * n);
            p.tilted_after.resize(3 * n);
            for (size_t i = 0; i < n; ++i) {
                const Rgb b = irradz::evaluate(before.texel(i), irradz::Model::kHhd, tilted);
                const Rgb a = irradz::evaluate(after.texel(i), irradz::Model::kHhd, tilted);
                for (int k = 0; k < 3; ++k) {
                    p.tilted_before[3 * i + static_cast<size_t>(k)] = static_cast<float>(b[k]);
                    p.tilted_after[3 * i + static_cast<size_t>(k)] = static_cast<float>(a[k]);
                }
            }
            p.tilted_label = "irradiance for a normal tilted 45 degrees";
            p.tilted_what = "Irradiance of the IrradZ (HHD) model for a normal tilted 45 degrees toward each texel's tangent +X, "
                            "so that the direction d (BC5) and the weight w_a (BC4) take part (not only I_z),";
        }
    }
    p.before_label = "before block compression (IrradZ fit)";
    p.after_label = "after BC6H + BC5 + BC4";
    const double m = a.mean_iz > 0 ? a.mean_iz : 1;
    p.rows = {{"old way (optimal linear direction, spherical Gram)", a.rmse_old, a.rmse_old / m},
              {"fit (hemispherical Gram, Newton on d)", a.rmse_search, a.rmse_search / m},
              {"fit after BC6H + BC5 + BC4", a.rmse_after_bc, a.rmse_after_bc / m}};
    p.metrics = {{"mean irradiance at the normal", html_number(a.mean_iz, "%.5g")},
                 {"I_z BC6H PSNR (log2 domain)", html_number(a.psnr_iz_log2, "%.2f") + " dB"},
                 {"w_a BC4 PSNR", html_number(a.psnr_wa, "%.2f") + " dB"},
                 {"d BC5 PSNR", html_number(a.psnr_d, "%.2f") + " dB"},
                 {"d angle error after BC5", "mean " + html_number(a.d_mean_deg, "%.3f") + " deg, max " + html_number(a.d_max_deg, "%.2f") + " deg"}};
    return p;
}

}  // namespace zhc
