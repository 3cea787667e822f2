#include "formats/report/html_report.h"

#include <stb_image.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "codec/audit/benchmark.h"
#include "formats/io/file_io.h"
#include "formats/report/raster.h"

namespace zhc {

std::string html_number(double v, const char* format) {
    if (!std::isfinite(v)) return v != v ? "nan" : (v > 0 ? "inf" : "-inf");
    char b[64];
    std::snprintf(b, sizeof b, format, v);
    return b;
}

namespace {

// A number for sorting (data-v): plain, full precision.
std::string sort_key(double v) { return html_number(v, "%.17g"); }

const Rgb8 kOutside{56, 56, 62}, kNegative{255, 0, 255};

}  // namespace

std::string html_escape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string base64_encode(const std::vector<std::uint8_t>& bytes) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const std::uint32_t v = (std::uint32_t(bytes[i]) << 16) | (std::uint32_t(bytes[i + 1]) << 8) | bytes[i + 2];
        out += k[(v >> 18) & 63];
        out += k[(v >> 12) & 63];
        out += k[(v >> 6) & 63];
        out += k[v & 63];
    }
    const size_t rest = bytes.size() - i;
    if (rest == 1) {
        const std::uint32_t v = std::uint32_t(bytes[i]) << 16;
        out += k[(v >> 18) & 63];
        out += k[(v >> 12) & 63];
        out += "==";
    } else if (rest == 2) {
        const std::uint32_t v = (std::uint32_t(bytes[i]) << 16) | (std::uint32_t(bytes[i + 1]) << 8);
        out += k[(v >> 18) & 63];
        out += k[(v >> 12) & 63];
        out += k[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

std::vector<std::uint8_t> encode_png_rgb8(const std::vector<std::uint8_t>& rgb, int width, int height) {
    return png_bytes_rgb8(rgb.data(), rgb.size(), width, height);
}

Result<DecodedImage> decode_image_rgb8(const std::vector<std::uint8_t>& bytes) {
    if (bytes.empty() || bytes.size() > static_cast<size_t>(INT_MAX))
        return make_error(ErrorCode::kInvalidArgument, "image: empty or too large");
    int w = 0, h = 0, n = 0;
    if (!stbi_info_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &n) || w <= 0 || h <= 0 ||
        static_cast<long long>(w) * h > (1LL << 28))
        return make_error(ErrorCode::kInvalidArgument, "image: not a readable picture (or over 2^28 pixels)");
    stbi_uc* px = stbi_load_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &n, 3);
    if (!px) return make_error(ErrorCode::kInvalidArgument, std::string("image: ") + stbi_failure_reason());
    DecodedImage img;
    img.width = w;
    img.height = h;
    img.rgb.assign(px, px + static_cast<size_t>(w) * h * 3);
    stbi_image_free(px);
    return img;
}

bool sphere_pixel_normal(int x, int y, int size, Vec3* normal) {
    if (size <= 0 || x < 0 || y < 0 || x >= 2 * size || y >= size) return false;
    const int view = x / size;
    const int lx = x - view * size;
    const double u = (lx + 0.5) / size * 2.0 - 1.0;
    const double v = 1.0 - (y + 0.5) / size * 2.0;
    const double r2 = u * u + v * v;
    if (r2 > 1.0) return false;
    const double w = std::sqrt(1.0 - r2);
    // From +X: toward the viewer +X, screen right +Y, up +Z. From -X: toward -X, right -Y, up +Z.
    *normal = view == 0 ? Vec3{w, u, v} : Vec3{-w, -u, v};
    return true;
}

SpherePictures render_sphere_pictures(const AuditInput& input, const std::vector<const Codec*>& codecs,
                                      const CodecOptions& options, int size) {
    SpherePictures pics;
    if (input.probes.empty()) return pics;
    size = std::clamp(size, 8, 512);
    pics.size = size;
    const size_t n = static_cast<size_t>(2 * size) * size;
    pics.inside.assign(n, 0);
    std::vector<Vec3> dirs;
    std::vector<size_t> where;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < 2 * size; ++x) {
            Vec3 d;
            if (!sphere_pixel_normal(x, y, size, &d)) continue;
            const size_t i = static_cast<size_t>(y) * 2 * size + x;
            pics.inside[i] = 1;
            dirs.push_back(d);
            where.push_back(i);
        }
    auto scatter = [&](const std::vector<Rgb>& values) {
        std::vector<Rgb> out(n);
        for (size_t k = 0; k < where.size() && k < values.size(); ++k) out[where[k]] = values[k];
        return out;
    };
    pics.latlong_width = std::min(2 * size, 128);  // size >= 8
    pics.latlong_height = pics.latlong_width / 2;
    std::vector<Vec3> ll_dirs;
    for (int y = 0; y < pics.latlong_height; ++y)
        for (int x = 0; x < pics.latlong_width; ++x) ll_dirs.push_back(latlong_direction(x, y, pics.latlong_width, pics.latlong_height));
    if (input.kind == "envmap" && input.map.width > 0 && input.map.height > 0) {
        const LatLongImage coarse = downsample_for_audit(input.map.view(), 64, 32);
        pics.reference = scatter(integrate_irradiance(coarse.view(), dirs, 1));
        pics.latlong_reference = integrate_irradiance(coarse.view(), ll_dirs, 1);
    } else {
        pics.reference = scatter(sh3_irradiance(input.probes[0], dirs));
        pics.latlong_reference = sh3_irradiance(input.probes[0], ll_dirs);
    }
    for (const Codec* c : codecs) {
        if (!c) continue;
        std::vector<std::uint8_t> stored(c->size_bytes);
        c->encode(input.probes[0], options, stored.data(), nullptr);
        pics.names.emplace_back(c->name);
        pics.representations.push_back(scatter(codec_irradiance(*c, stored.data(), options, dirs)));
        pics.latlong_representations.push_back(codec_irradiance(*c, stored.data(), options, ll_dirs));
    }
    return pics;
}

namespace {

std::string png_data_uri(const std::vector<std::uint8_t>& rgb, int w, int h) {
    const std::vector<std::uint8_t> png = encode_png_rgb8(rgb, w, h);
    return "data:image/png;base64," + base64_encode(png);
}

std::string img_tag(const std::string& uri, int w, int h, const std::string& alt) {
    return "<img src=\"" + uri + "\" width=\"" + std::to_string(w) + "\" height=\"" + std::to_string(h) +
           "\" alt=\"" + html_escape(alt) + "\">";
}

// Relative error of one pixel: the largest channel difference over the mean reference.
double pixel_error(const Rgb& a, const Rgb& b, double mean) {
    double e = 0;
    for (int k = 0; k < 3; ++k) e = std::max(e, std::fabs(double(a[k]) - double(b[k])));
    return std::isfinite(e) ? e / mean : 1e30;
}

std::string percent(double rel) { return percent_text(rel); }

}  // namespace

std::string colour_bar_svg(const ErrorScale& s) {
    const int w = 360, bar_h = 14, n = ErrorScale::kBands;
    std::ostringstream o;
    o << "<svg class=\"bar\" width=\"" << w + 72 << "\" height=\"44\" viewBox=\"0 0 "
      << w + 72 << " 44\" role=\"img\" aria-label=\"error colour scale\">";
    for (int i = 0; i < n; ++i) {
        const Rgb8 c = ErrorScale::band_colour((i + 0.5) / n);
        o << "<rect x=\"" << 36 + i * w / n << "\" y=\"2\" width=\"" << (w / n + 1) << "\" height=\"" << bar_h
          << "\" fill=\"rgb(" << int(c.r) << "," << int(c.g) << "," << int(c.b) << ")\"/>";
    }
    for (int d = 0; d <= static_cast<int>(ErrorScale::kDecades); ++d) {
        const double rel = s.top * std::pow(10.0, d - ErrorScale::kDecades);
        const int x = 36 + static_cast<int>(std::lround(w * d / ErrorScale::kDecades));
        o << "<line x1=\"" << x << "\" y1=\"2\" x2=\"" << x << "\" y2=\"" << bar_h + 6 << "\" stroke=\"#222\"/>";
        o << "<text x=\"" << x << "\" y=\"" << bar_h + 20 << "\" text-anchor=\"middle\" font-size=\"12\">"
          << (d == 0 ? "&#8804; " : (d == 3 ? "&#8805; " : "")) << percent(rel) << "</text>";
    }
    o << "</svg>";
    return o.str();
}

namespace {

const char* kColumns[] = {"representation", "bytes", "rmse", "relative rmse", "max abs", "min irradiance",
                          "negative fraction", "chroma error", "encode ns", "decode ns"};

void table_html(std::ostringstream& o, const std::string& id, const std::string& caption, const std::vector<HtmlRow>& rows,
                bool runtime_absent_column = false) {
    o << "<table class=\"sortable\"" << (id.empty() ? "" : " id=\"" + id + "\"") << ">\n";
    if (!caption.empty()) o << "<caption>" << html_escape(caption) << "</caption>\n";
    const bool eval = std::any_of(rows.begin(), rows.end(), [](const HtmlRow& r) { return r.eval_ns >= 0; });
    o << "<thead><tr>";
    for (const char* c : kColumns) o << "<th scope=\"col\">" << c << "</th>";
    if (eval) o << "<th scope=\"col\">eval ns/sample</th>";
    const bool gpu = std::any_of(rows.begin(), rows.end(), [](const HtmlRow& r) { return r.spirv_instructions >= 0; });
    if (gpu) o << "<th scope=\"col\">runtime cost: SPIR-V instructions</th><th scope=\"col\">runtime cost: GPU ns/eval</th>";
    else if (runtime_absent_column) o << "<th scope=\"col\">runtime cost</th>";
    o << "</tr></thead>\n<tbody>\n";
    auto cell = [&](double v, const char* f) { o << "<td data-v=\"" << sort_key(v) << "\">" << html_number(v, f) << "</td>"; };
    auto time = [&](double v) {
        if (v < 0 || !std::isfinite(v)) o << "<td data-v=\"-1\">-</td>";
        else cell(v, "%.0f");
    };
    for (const HtmlRow& r : rows) {
        const ErrorMetrics& m = r.metrics;
        o << "<tr class=\"rep\"><th scope=\"row\">" << html_escape(r.name) << "</th>";
        cell(static_cast<double>(r.bytes), "%.0f");
        cell(m.rmse, "%.4g");
        cell(m.relative_rmse, "%.4f");
        if (r.all_metrics) {
            cell(m.max_abs, "%.4g");
            cell(m.min_irradiance, "%.4g");
            cell(m.negative_fraction, "%.4f");
            cell(m.chromaticity_error, "%.4f");
        } else {
            for (int k = 0; k < 4; ++k) o << "<td>-</td>";
        }
        time(r.encode_ns);
        time(r.decode_ns);
        if (eval) {
            if (r.eval_ns < 0 || !std::isfinite(r.eval_ns)) o << "<td data-v=\"-1\">-</td>";
            else cell(r.eval_ns, "%.1f");
        }
        if (gpu) {
            if (r.spirv_instructions < 0) o << "<td data-v=\"-1\">-</td><td data-v=\"-1\">-</td>";
            else {
                cell(r.spirv_instructions, "%.0f");
                if (r.gpu_ns < 0 || !std::isfinite(r.gpu_ns)) o << "<td data-v=\"-1\">-</td>";
                else cell(r.gpu_ns, "%.3g");
            }
        } else if (runtime_absent_column) {
            o << "<td class=\"na\">not given</td>";
        }
        o << "</tr>\n";
    }
    o << "</tbody></table>\n";
}

void pictures_html(std::ostringstream& o, const SpherePictures& p) {
    const int w = 2 * p.size, h = p.size;
    const size_t n = static_cast<size_t>(w) * h;
    if (p.size <= 0 || p.reference.size() != n || p.inside.size() != n) return;
    double mean = 0;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i)
        if (p.inside[i] && std::isfinite(p.reference[i].r + p.reference[i].g + p.reference[i].b)) {
            mean += (double(p.reference[i].r) + p.reference[i].g + p.reference[i].b) / 3.0;
            ++count;
        }
    mean = std::max(count ? mean / count : 0.0, 1e-12);
    // The shared error scale: its top is the 99th percentile of the worst representation's error.
    std::vector<std::vector<double>> errs;
    for (const auto& rec : p.representations) {
        if (rec.size() != n) continue;
        errs.emplace_back();
        for (size_t i = 0; i < n; ++i)
            if (p.inside[i]) errs.back().push_back(pixel_error(rec[i], p.reference[i], mean));
    }
    const ErrorScale scale = ErrorScale::from_percentile(std::move(errs));
    // Pictures: the sphere pair (pixels off the discs in the background colour) or the lat-long
    // map (every pixel a normal). `inside` empty: every pixel is inside.
    auto irradiance_uri = [&](const std::vector<Rgb>& img, int pw, int ph, const std::vector<std::uint8_t>& inside,
                              size_t* negatives) {
        const size_t m = static_cast<size_t>(pw) * ph;
        std::vector<std::uint8_t> px(m * 3);
        for (size_t i = 0; i < m && i < img.size(); ++i) {
            Rgb8 c = kOutside;
            if (inside.empty() || inside[i]) {
                const Rgb& v = img[i];
                if (v.r < 0 || v.g < 0 || v.b < 0) {
                    c = kNegative;
                    ++*negatives;
                } else {
                    c = {tonemap_srgb8(v.r / mean), tonemap_srgb8(v.g / mean), tonemap_srgb8(v.b / mean)};
                }
            }
            px[i * 3] = c.r;
            px[i * 3 + 1] = c.g;
            px[i * 3 + 2] = c.b;
        }
        return png_data_uri(px, pw, ph);
    };
    auto error_uri = [&](const std::vector<Rgb>& img, const std::vector<Rgb>& ref, int pw, int ph,
                         const std::vector<std::uint8_t>& inside) {
        const size_t m = static_cast<size_t>(pw) * ph;
        std::vector<std::uint8_t> px(m * 3);
        for (size_t i = 0; i < m && i < img.size() && i < ref.size(); ++i) {
            const Rgb8 c = inside.empty() || inside[i] ? scale.colour(pixel_error(img[i], ref[i], mean)) : kOutside;
            px[i * 3] = c.r;
            px[i * 3 + 1] = c.g;
            px[i * 3 + 2] = c.b;
        }
        return png_data_uri(px, pw, ph);
    };
    const int lw = p.latlong_width, lh = p.latlong_height;
    const size_t ln = static_cast<size_t>(std::max(lw, 0)) * std::max(lh, 0);
    const bool latlong = lw > 0 && lh > 0 && p.latlong_reference.size() == ln &&
                         p.latlong_representations.size() == p.representations.size();
    const std::vector<std::uint8_t> all_inside;
    o << "<p class=\"scale\">Lit spheres, seen from +X (left) and from &minus;X (right), +Z up: the pixel at "
         "normal n shows the irradiance E(n), exposed by the mean reference irradiance ("
      << html_number(mean) << ") and tone-mapped (Reinhard, sRGB); <span class=\"neg\">magenta</span> marks negative "
         "irradiance."
      << (latlong ? " Beside each pair, the same irradiance as a lat-long map of normals (+Z at the top, longitude "
                    "from &minus;180&deg; at the left)."
                  : "")
      << " Error maps: max over channels of |E &minus; E<sub>ref</sub>| / mean reference, on one "
         "logarithmic scale shared by every representation of this input (three decades, four colour bands each; its top is the 99th "
         "percentile of the worst representation's error on the spheres, "
      << percent(scale.top) << "):</p>\n"
      << colour_bar_svg(scale) << "\n<div class=\"cards\">\n";
    size_t neg = 0;
    o << "<figure class=\"card\"><figcaption>reference</figcaption><div class=\"pair\">"
      << img_tag(irradiance_uri(p.reference, w, h, p.inside, &neg), w, h, "reference irradiance, lit spheres");
    if (latlong) o << img_tag(irradiance_uri(p.latlong_reference, lw, lh, all_inside, &neg), lw, lh, "reference irradiance, lat-long");
    o << "</div></figure>\n";
    for (size_t r = 0; r < p.representations.size() && r < p.names.size(); ++r) {
        if (p.representations[r].size() != n) continue;
        const bool ll = latlong && p.latlong_representations[r].size() == ln;
        size_t negatives = 0, ll_negatives = 0;
        const std::string irr = irradiance_uri(p.representations[r], w, h, p.inside, &negatives);
        double worst = 0;
        for (size_t i = 0; i < n; ++i)
            if (p.inside[i]) worst = std::max(worst, pixel_error(p.representations[r][i], p.reference[i], mean));
        o << "<figure class=\"card\"><figcaption>" << html_escape(p.names[r]) << "</figcaption><div class=\"pair\">"
          << img_tag(irr, w, h, p.names[r] + " irradiance, lit spheres");
        if (ll)
            o << img_tag(irradiance_uri(p.latlong_representations[r], lw, lh, all_inside, &ll_negatives), lw, lh,
                         p.names[r] + " irradiance, lat-long");
        o << "</div><div class=\"pair\">" << img_tag(error_uri(p.representations[r], p.reference, w, h, p.inside), w, h, p.names[r] + " error, lit spheres");
        if (ll)
            o << img_tag(error_uri(p.latlong_representations[r], p.latlong_reference, lw, lh, all_inside), lw, lh,
                         p.names[r] + " error, lat-long");
        o << "</div><div class=\"small\">max error " << percent(worst);
        if (negatives) o << ", <span class=\"neg\">" << negatives << " negative px</span>";
        o << "</div></figure>\n";
    }
    o << "</div>\n";
}

}  // namespace

std::string scatter_svg(const ScatterPlot& plot) {
    const int left = 78, top = 34, pw = 520, ph = 340, bottom = 56, gap = 24, label_w = 200, row = 15;
    // On a log axis a value <= 0 has no place: such points sit on the axis's low edge, their label
    // says so, and they do not set the range.
    auto off_axis = [&](const PlotPoint& p) { return (plot.log_x && !(p.x > 0)) || (plot.log_y && !(p.y > 0)); };
    auto tx = [&](double v) { return plot.log_x ? std::log10(v) : v; };
    auto ty = [&](double v) { return plot.log_y ? std::log10(v) : v; };
    std::vector<size_t> shown;
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (size_t i = 0; i < plot.points.size(); ++i) {
        const PlotPoint& p = plot.points[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
        shown.push_back(i);
        if (!plot.log_x || p.x > 0) x0 = std::min(x0, tx(p.x)), x1 = std::max(x1, tx(p.x));
        if (!plot.log_y || p.y > 0) y0 = std::min(y0, ty(p.y)), y1 = std::max(y1, ty(p.y));
    }
    if (x0 > x1) x0 = 0, x1 = 1;
    if (y0 > y1) y0 = 0, y1 = 1;
    if (plot.log_x) x0 = std::floor(x0 - 0.05), x1 = std::ceil(x1 + 0.05);
    else { const double m = 0.08 * std::max(x1 - x0, 1e-9); x0 -= m, x1 += m; }
    if (plot.log_y) y0 = std::floor(y0 - 0.05), y1 = std::ceil(y1 + 0.05);
    else { const double m = 0.08 * std::max(y1 - y0, 1e-9); y0 -= m, y1 += m; }
    auto px = [&](double v) { return plot.log_x && !(v > 0) ? double(left) : left + (tx(v) - x0) / (x1 - x0) * pw; };
    auto py = [&](double v) { return plot.log_y && !(v > 0) ? double(top + ph) : top + ph - (ty(v) - y0) / (y1 - y0) * ph; };
    const int height = std::max(top + ph + bottom, top + static_cast<int>(shown.size()) * row + 20);
    const int width = left + pw + gap + label_w;
    std::ostringstream o;
    o << "<svg class=\"plot\" width=\"" << width << "\" height=\"" << height
      << "\" viewBox=\"0 0 " << width << ' ' << height << "\" role=\"img\" aria-label=\"" << html_escape(plot.title) << "\">\n";
    o << "<text x=\"" << left << "\" y=\"20\" font-size=\"15\" font-weight=\"bold\">" << html_escape(plot.title) << "</text>\n";
    // Ticks: decades on log axes (with 2 and 5 when there are few decades), 5 divisions on linear.
    auto ticks = [](double a, double b, bool log) {
        std::vector<double> t;
        if (log) {
            for (double e = std::ceil(a); e <= b + 1e-9 && t.size() < 40; e += 1) t.push_back(std::pow(10.0, e));
        } else {
            for (int i = 0; i <= 5; ++i) t.push_back(a + (b - a) * i / 5);
        }
        return t;
    };
    for (double v : ticks(x0, x1, plot.log_x)) {
        const double x = left + ((plot.log_x ? std::log10(v) : v) - x0) / (x1 - x0) * pw;
        o << "<line x1=\"" << html_number(x) << "\" y1=\"" << top << "\" x2=\"" << html_number(x) << "\" y2=\"" << top + ph
          << "\" stroke=\"#ddd\"/><text x=\"" << html_number(x) << "\" y=\"" << top + ph + 16
          << "\" text-anchor=\"middle\" font-size=\"12\">" << html_number(v, "%g") << "</text>\n";
    }
    for (double v : ticks(y0, y1, plot.log_y)) {
        const double y = top + ph - ((plot.log_y ? std::log10(v) : v) - y0) / (y1 - y0) * ph;
        o << "<line x1=\"" << left << "\" y1=\"" << html_number(y) << "\" x2=\"" << left + pw << "\" y2=\"" << html_number(y)
          << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << html_number(y + 4)
          << "\" text-anchor=\"end\" font-size=\"12\">" << html_number(v, "%g") << "</text>\n";
    }
    o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
      << "\" fill=\"none\" stroke=\"#222\"/>\n";
    o << "<text x=\"" << left + pw / 2 << "\" y=\"" << top + ph + 40 << "\" text-anchor=\"middle\" font-size=\"13\">"
      << html_escape(plot.x_label) << "</text>\n";
    o << "<text transform=\"translate(16 " << top + ph / 2 << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"13\">"
      << html_escape(plot.y_label) << "</text>\n";
    // Frontier.
    std::vector<bool> on_front(plot.points.size(), false);
    std::string path;
    for (size_t i : plot.frontier) {
        if (i >= plot.points.size() || !std::isfinite(plot.points[i].x) || !std::isfinite(plot.points[i].y)) continue;
        on_front[i] = true;
        path += (path.empty() ? "M" : " L") + html_number(px(plot.points[i].x)) + " " + html_number(py(plot.points[i].y));
    }
    if (!path.empty()) o << "<path d=\"" << path << "\" fill=\"none\" stroke=\"#d33\" stroke-width=\"2.5\"/>\n";
    // Labels in a column right of the plot, in the order of their points' heights, at least `row`
    // apart; a leader line joins each point to its label.
    std::vector<size_t> order = shown;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return py(plot.points[a].y) < py(plot.points[b].y); });
    std::vector<double> ly(order.size());
    for (size_t k = 0; k < order.size(); ++k) {
        ly[k] = std::max(py(plot.points[order[k]].y), static_cast<double>(top + 6));
        if (k) ly[k] = std::max(ly[k], ly[k - 1] + row);
    }
    for (size_t k = order.size(); k-- > 0;) {  // pull back up from the bottom edge
        const double limit = k + 1 < order.size() ? ly[k + 1] - row : static_cast<double>(height - 8);
        ly[k] = std::min(ly[k], limit);
    }
    const int lx = left + pw + gap;
    for (size_t k = 0; k < order.size(); ++k) {
        const PlotPoint& p = plot.points[order[k]];
        const bool f = on_front[order[k]];
        const double x = px(p.x), y = py(p.y);
        o << "<line x1=\"" << html_number(x) << "\" y1=\"" << html_number(y) << "\" x2=\"" << lx - 4 << "\" y2=\"" << html_number(ly[k])
          << "\" stroke=\"" << (f ? "#e99" : "#bbb") << "\" stroke-width=\"0.8\"/>\n";
        const std::string title = "<title>" + html_escape(p.label) + ": " + html_number(p.x) + ", " + html_number(p.y) + "</title>";
        if (p.engine)  // an engine's layout: an orange square
            o << "<rect class=\"engine\" x=\"" << html_number(x - 5) << "\" y=\"" << html_number(y - 5)
              << "\" width=\"10\" height=\"10\" fill=\"#e68a00\">" << title << "</rect>\n";
        else
            o << "<circle cx=\"" << html_number(x) << "\" cy=\"" << html_number(y) << "\" r=\"4\" fill=\"" << (f ? "#d33" : "#2a5bc8")
              << "\">" << title << "</circle>\n";
        o << "<text x=\"" << lx << "\" y=\"" << html_number(ly[k] + 4) << "\" font-size=\"12\" fill=\""
          << (p.engine ? "#b36b00" : (f ? "#c22" : "#222")) << "\">" << html_escape(p.label)
          << (off_axis(p) ? " (0: drawn on the axis)" : "") << "</text>\n";
    }
    o << "<text x=\"" << left + 8 << "\" y=\"" << top + 16 << "\" font-size=\"12\" fill=\"#c22\">red: Pareto frontier</text>\n";
    if (std::any_of(plot.points.begin(), plot.points.end(), [](const PlotPoint& p) { return p.engine; }))
        o << "<text x=\"" << left + 8 << "\" y=\"" << top + 31
          << "\" font-size=\"12\" fill=\"#b36b00\">orange squares: engine layouts (zhc's frontier drawn without them)</text>\n";
    o << "</svg>\n";
    return o.str();
}

std::string html_page_begin(const std::string& title, const std::string& version) {
    std::ostringstream o;
    o << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         "<meta name=\"generator\" content=\"zhc "
      << html_escape(version) << "\">\n<title>" << html_escape(title) << "</title>\n<style>\n"
         "body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;background:#fff;max-width:1400px}\n"
         "h1{font-size:1.6em}h2{font-size:1.3em;margin-top:1.6em;border-bottom:1px solid #ccc}\n"
         "table{border-collapse:collapse;margin:.6em 0;font-size:.9em}\n"
         "th,td{border:1px solid #ccc;padding:.25em .55em}td{text-align:right;font-variant-numeric:tabular-nums}\n"
         "thead th{background:#eef;cursor:pointer}tbody th{text-align:left;font-weight:normal;font-family:monospace}\n"
         "caption{text-align:left;font-weight:bold;padding:.3em 0}\n"
         ".cards{display:flex;flex-wrap:wrap;gap:10px}\n"
         ".card{margin:0;padding:6px;background:#f2f2f4;border:1px solid #ddd;display:flex;flex-direction:column;gap:3px}\n"
         ".card figcaption{font-family:monospace;font-weight:bold}.small{font-size:.8em}.pair{display:flex;gap:4px;align-items:center}\n"
         ".neg{color:#c0c;font-weight:bold}.ok{color:#070;font-weight:bold}.bad{color:#b00;font-weight:bold}\n"
         "dl.settings{display:grid;grid-template-columns:max-content auto;gap:.2em 1em}dl.settings dt{font-weight:bold}\n"
         "dl.settings dd{margin:0;font-family:monospace;word-break:break-all}td.na{color:#777;text-align:center}\n"
         "</style>\n</head>\n<body>\n";
    return o.str();
}

std::string html_page_end() {
    std::ostringstream o;
    o << "<script>\n"
         "(function(){\n"
         "document.querySelectorAll('table.sortable').forEach(function(t){\n"
         "  t.querySelectorAll('thead th').forEach(function(th,col){\n"
         "    th.title='sort';th.addEventListener('click',function(){\n"
         "      var tb=t.tBodies[0],rows=Array.prototype.slice.call(tb.rows),asc=th.dataset.dir!=='asc';\n"
         "      t.querySelectorAll('thead th').forEach(function(h){delete h.dataset.dir;});th.dataset.dir=asc?'asc':'desc';\n"
         "      rows.sort(function(a,b){var x=a.cells[col],y=b.cells[col];\n"
         "        var p=x.dataset.v!==undefined?parseFloat(x.dataset.v):NaN,q=y.dataset.v!==undefined?parseFloat(y.dataset.v):NaN;\n"
         "        var c=(isNaN(p)||isNaN(q))?x.textContent.localeCompare(y.textContent):p-q;return asc?c:-c;});\n"
         "      rows.forEach(function(row){tb.appendChild(row);});});});});\n"
         "window.addEventListener('load',function(){\n"
         "  var imgs=document.images,ok=0;\n"
         "  for(var i=0;i<imgs.length;i++)if(imgs[i].complete&&imgs[i].naturalWidth>0)ok++;\n"
         "  document.body.dataset.imagesOk=ok+'/'+imgs.length;\n"
         "});\n"
         "})();\n"
         "</script>\n</body>\n</html>\n";
    return o.str();
}

void apply_runtime_cost(HtmlReport& report, const RuntimeCostTable* table, const std::string& path) {
    if (!table) {
        report.runtime_cost_absent =
            "not given. It is the GPU cost of each encoding's irradiance evaluation (SPIR-V instructions and lavapipe ns per "
            "evaluation), measured by build/bench/bench_runtime --json FILE; pass that file with --runtime-cost FILE.";
        return;
    }
    report.runtime_cost_absent.clear();
    report.settings.push_back({"runtime cost", path + " (" + table->device + ")"});
    auto fill = [&](HtmlRow& row) {
        auto it = table->by_name.find(row.name);
        if (it == table->by_name.end()) return;
        row.spirv_instructions = it->second.spirv_instructions;
        row.gpu_ns = it->second.ns_per_eval;
    };
    for (HtmlRow& row : report.summary) fill(row);
    for (HtmlInputSection& in : report.inputs)
        for (HtmlRow& row : in.rows) fill(row);
    ScatterPlot plot{"Error vs runtime cost", "SPIR-V instructions per irradiance evaluation (log scale)",
                     "relative irradiance rmse (log scale)", {}, {}};
    std::vector<double> cost, err;
    for (const HtmlRow& row : report.summary)
        if (row.spirv_instructions >= 0) {
            plot.points.push_back({row.name, double(row.spirv_instructions), row.metrics.relative_rmse});
            cost.push_back(row.spirv_instructions);
            err.push_back(row.metrics.relative_rmse);
        }
    if (plot.points.empty()) return;
    plot.frontier = pareto_frontier(cost, err);
    report.plots.push_back(plot);
}

std::string html_report(const HtmlReport& r) {
    std::ostringstream o;
    o << html_page_begin(r.title, r.version);
    o << "<h1>" << html_escape(r.title) << "</h1>\n<p>zhc " << html_escape(r.version) << ". " << html_escape(r.intro) << "</p>\n";
    // Settings.
    o << "<h2>Inputs and options</h2>\n<dl class=\"settings\">\n<dt>zhc version</dt><dd>" << html_escape(r.version) << "</dd>\n";
    for (const auto& [k, v] : r.settings) o << "<dt>" << html_escape(k) << "</dt><dd>" << html_escape(v) << "</dd>\n";
    o << "</dl>\n";
    // Summary.
    o << "<h2>Summary</h2>\n";
    const bool absent = !r.runtime_cost_absent.empty();
    table_html(o, "summary", r.summary_caption, r.summary, absent);
    const bool any_gpu = std::any_of(r.summary.begin(), r.summary.end(), [](const HtmlRow& h) { return h.spirv_instructions >= 0; });
    if (absent && !any_gpu) o << "<p class=\"small\" id=\"runtime-cost\">Runtime cost: " << html_escape(r.runtime_cost_absent) << "</p>\n";
    o << "<p class=\"small\">Click a column heading to sort (needs JavaScript; the page reads without it). "
         "Errors are of irradiance against the reference; relative rmse is rmse / mean reference irradiance; "
         "times are per probe.</p>\n";
    // Gates.
    if (r.gates_configured) {
        o << "<h2>Gates</h2>\n<ul>\n";
        for (const std::string& g : r.gates) o << "<li>" << html_escape(g) << "</li>\n";
        o << "</ul>\n";
        if (r.gate_failures.empty()) o << "<p class=\"ok\" id=\"gates\">All gates passed.</p>\n";
        else {
            o << "<p class=\"bad\" id=\"gates\">" << r.gate_failures.size() << " failure(s):</p>\n<ul class=\"failures\">\n";
            for (const std::string& f : r.gate_failures) o << "<li>" << html_escape(f) << "</li>\n";
            o << "</ul>\n";
        }
    }
    // Tables of their own.
    for (const HtmlTable& t : r.tables) {
        o << "<section id=\"" << html_escape(t.id) << "\">\n<h2>" << html_escape(t.title) << "</h2>\n<p>" << html_escape(t.intro)
          << "</p>\n<table class=\"sortable\">\n<thead><tr>";
        for (const std::string& c : t.columns) o << "<th scope=\"col\">" << html_escape(c) << "</th>";
        o << "</tr></thead>\n<tbody>\n";
        for (const std::vector<HtmlCell>& row : t.rows) {
            o << "<tr>";
            for (std::size_t c = 0; c < row.size(); ++c) {
                if (c == 0) o << "<th scope=\"row\">" << html_escape(row[c].text) << "</th>";
                else o << "<td data-v=\"" << sort_key(row[c].sort) << "\">" << html_escape(row[c].text) << "</td>";
            }
            o << "</tr>\n";
        }
        o << "</tbody></table>\n";
        for (const std::string& n : t.notes) o << "<p class=\"note\">" << html_escape(n) << "</p>\n";
        o << "</section>\n";
    }
    // Plots.
    if (!r.plots.empty()) {
        o << "<h2>Plots</h2>\n";
        for (const ScatterPlot& p : r.plots) o << scatter_svg(p);
    }
    // Inputs.
    for (size_t i = 0; i < r.inputs.size(); ++i) {
        const HtmlInputSection& s = r.inputs[i];
        o << "<section id=\"input-" << i << "\">\n<h2>" << html_escape(s.title) << "</h2>\n<p>" << html_escape(s.description)
          << "</p>\n";
        if (!s.rows.empty()) table_html(o, "", "", s.rows, absent);
        pictures_html(o, s.pictures);
        o << "</section>\n";
    }
    o << html_page_end();
    return o.str();
}

Status write_html_report(const std::string& path, const HtmlReport& report) {
    const std::string text = html_report(report);
    return write_file_atomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
}

}  // namespace zhc
