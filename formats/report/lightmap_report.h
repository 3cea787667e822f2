// zhc/formats/report/lightmap_report.h — `zhc lightmap audit --html`: one self-contained HTML page with the
// lightmap before and after block compression (tone-mapped irradiance at each texel's normal, I_z)
// and the error between them as a heat map with its scale printed, each as a downscaled overview
// of the whole lightmap and a crop around the worst-error region at a readable size; the error and
// PSNR tables; the inputs, options and zhc's version. Same page style and script as html_report.h.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "codec/lightmap/lightmap.h"
#include "codec/status.h"

namespace zhc {

struct LightmapHtmlRow {
    std::string name;  // e.g. "search after BC6H + BC5 + BC4"
    double rmse = 0, relative = 0;  // relative: of the mean irradiance at the normal
};

// Plain images plus numbers: what the page shows.
struct LightmapHtml {
    std::string title = "zhc lightmap audit", version, intro;
    std::vector<std::pair<std::string, std::string>> settings;  // inputs and options
    int width = 0, height = 0;
    std::vector<float> before, after;  // linear RGB, 3 per texel, row-major (width*height*3)
    std::string before_label = "before block compression", after_label = "after block compression";
    // Optional second view (overview only): e.g. the irradiance for a normal tilted away from the
    // surface normal, which also shows the d and w_a errors. Same layout as before/after.
    std::vector<float> tilted_before, tilted_after;
    std::string tilted_label, tilted_what;
    std::vector<LightmapHtmlRow> rows;                          // the summary table, one row each
    std::vector<std::pair<std::string, std::string>> metrics;  // further numbers (PSNR, angles)
};

// The page; deterministic. Images whose size does not match width*height*3 are left out.
std::string lightmap_html_report(const LightmapHtml& page);
Status write_lightmap_html_report(const std::string& path, const LightmapHtml& page);

// The numbers and pictures of `zhc lightmap audit`: I_z of the IrradZ planes before (the fit)
// and after block compression, the irradiance (HHD model) for a normal tilted 45 degrees toward the
// tangent +X, the hemispherical error rows and per-texture PSNR of `audit`.
LightmapHtml lightmap_audit_html(const std::string& version, std::vector<std::pair<std::string, std::string>> settings,
                                 const lightmap::IrradzPlanes& before, const lightmap::IrradzPlanes& after,
                                 const lightmap::Audit& audit);

// Pieces, exposed for tests.
struct CropWindow {
    int x = 0, y = 0, width = 0, height = 0;
};
// The min(size, width) x min(size, height) window with the largest summed error (error: width*height
// values; non-finite values count as the largest finite error); the first (top-most, then
// left-most) of equals. Empty window for an empty or mismatched image.
CropWindow worst_error_window(const std::vector<double>& error, int width, int height, int size);

}  // namespace zhc
