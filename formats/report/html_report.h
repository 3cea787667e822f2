// zhc/formats/report/html_report.h — one self-contained HTML report (audit, demo, bench): a sortable
// summary table, the gates, the inputs and options, lit-sphere pictures of every representation
// beside the reference with error heat maps on one shared scale per input, and SVG scatter plots.
//
// The file needs nothing else: pictures are PNGs inlined as data: URIs, plots are inline SVG with
// real text, there is no external script, font or style sheet. It reads with JavaScript disabled;
// a small inline script only makes tables sortable and marks (data-images-ok on <body>) that
// every picture decoded, for the browser test.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "formats/report/audit_inputs.h"
#include "codec/audit/audit.h"
#include "codec/status.h"
#include "formats/report/plot.h"
#include "formats/report/raster.h"
#include "formats/report/runtime_cost.h"

namespace zhc {

// One representation in a table.
struct HtmlRow {
    std::string name;
    std::size_t bytes = 0;
    ErrorMetrics metrics;
    double encode_ns = -1, decode_ns = -1;  // < 0: not measured (shown as "-")
    // false: only rmse and relative rmse are known (bench); the other metrics show as "-".
    bool all_metrics = true;
    double eval_ns = -1;  // per irradiance sample; the column appears when some row has it
    // GPU runtime evaluation cost (bench_runtime --json, formats/report/runtime_cost.h); < 0: not known.
    int spirv_instructions = -1;
    double gpu_ns = -1;
};

// Lit spheres: orthographic views of a unit sphere whose pixel at normal n shows E(n). Two views,
// side by side in one picture of 2*size x size: from +X (screen right +Y, up +Z) and from -X
// (right -Y, up +Z), so every normal appears. Pixels outside the discs have no direction.
struct SpherePictures {
    int size = 0;
    std::vector<std::uint8_t> inside;              // 2*size*size, 1 where the pixel is on a disc
    std::vector<Rgb> reference;                    // 2*size*size irradiance (0 outside)
    std::vector<std::string> names;                // per representation
    std::vector<std::vector<Rgb>> representations;  // per representation, 2*size*size
    // The same irradiance as a lat-long map of normals (latlong_direction: +Z up at the top row,
    // the same convention as the environment maps), latlong_width x latlong_height; 0: none.
    int latlong_width = 0, latlong_height = 0;
    std::vector<Rgb> latlong_reference;
    std::vector<std::vector<Rgb>> latlong_representations;  // per representation
};

// The normal shown at pixel (x, y) of a 2*size x size sphere picture; false outside the discs.
bool sphere_pixel_normal(int x, int y, int size, Vec3* normal);

// Evaluates the reference (an environment map: integrate_irradiance, each pixel over its exact
// footprint, of the map box-downsampled to 64x32; probes: probe 0's SH3 irradiance) and every codec's runtime irradiance of probe 0 at the
// sphere pictures' normals, and on a lat-long map of normals of 2*size x size pixels, at most 128 x 64
// (irradiance is smooth, and the report stays small). size is clamped to [8, 512].
SpherePictures render_sphere_pictures(const AuditInput& input, const std::vector<const Codec*>& codecs,
                                      const CodecOptions& options, int size = 96);

struct HtmlInputSection {
    std::string title;        // e.g. the input's path
    std::string description;  // one line
    std::vector<HtmlRow> rows;
    SpherePictures pictures;  // size 0: none
};

// A table of its own section (e.g. bench's GPU volume layouts): a heading, a paragraph, a sortable
// table whose first column heads the rows, and notes under it.
struct HtmlCell {
    std::string text;
    double sort = 0;  // the sort key of numeric cells (ignored in the first column)
};
struct HtmlTable {
    std::string id;     // the section's id attribute
    std::string title;  // heading
    std::string intro;  // one paragraph
    std::vector<std::string> columns;
    std::vector<std::vector<HtmlCell>> rows;
    std::vector<std::string> notes;  // paragraphs under the table
};

struct HtmlReport {
    std::string title;    // "zhc audit"
    std::string version;  // zhc's version
    std::string intro;    // one paragraph of plain text (what the reference is, etc.)
    std::vector<std::pair<std::string, std::string>> settings;  // inputs and options, to reproduce
    std::string summary_caption;
    std::vector<HtmlRow> summary;  // one row per representation
    bool gates_configured = false;
    std::vector<std::string> gates;          // the gates in force (text)
    std::vector<std::string> gate_failures;  // which probes failed which gate; empty = passed
    std::vector<HtmlInputSection> inputs;
    std::vector<ScatterPlot> plots;  // drawn as SVG
    std::vector<HtmlTable> tables;   // sections after the gates, before the plots
    // The runtime evaluation cost columns: shown when some row has a cost; otherwise, when this is
    // non-empty, one "runtime cost" column whose cells say it was not given, and this note (how to
    // give it) under the table.
    std::string runtime_cost_absent;
};

// The runtime evaluation cost of every row (summary and inputs), by representation name, from
// bench_runtime's table read from `path`: adds the cost columns, a "runtime cost" setting and an
// error-vs-runtime-cost plot. table == nullptr: the report says the cost was not given (the
// column's cells and a note naming the option).
void apply_runtime_cost(HtmlReport& report, const RuntimeCostTable* table, const std::string& path);

// The whole document. Deterministic: the same report gives the same bytes.
std::string html_report(const HtmlReport& report);
// Writes it atomically.
Status write_html_report(const std::string& path, const HtmlReport& report);

// The page around a report's content: doctype, head with the inline style, <body>; and the inline
// script (sortable tables, the images-decoded marker) with the closing tags. Shared by every kind
// of report (formats/report/lightmap_report.h too).
std::string html_page_begin(const std::string& title, const std::string& version);
std::string html_page_end();
// The heat-map colour bar as inline SVG, its decades labelled ("<= 0.052%" .. ">= 52%").
std::string colour_bar_svg(const ErrorScale& scale);

// Pieces, exposed for tests.
std::string html_escape(const std::string& text);
// A number for a report: printf format ("%.4g" by default); nan, inf, -inf spelled out.
std::string html_number(double v, const char* format = "%.4g");
std::string base64_encode(const std::vector<std::uint8_t>& bytes);
// RGB8 pixels (w*h*3) -> PNG bytes; empty on failure.
std::vector<std::uint8_t> encode_png_rgb8(const std::vector<std::uint8_t>& rgb, int width, int height);
// PNG (or any format stb_image reads) -> RGB8; kInvalidArgument when it does not decode.
struct DecodedImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;  // width*height*3
};
Result<DecodedImage> decode_image_rgb8(const std::vector<std::uint8_t>& bytes);
// An SVG scatter plot: log axes with decade ticks and units from the plot's labels, the Pareto
// frontier joined and marked, engine layouts (PlotPoint::engine) as orange squares with a legend
// line, every point's label in a column beside the plot with a leader line (labels are spaced so
// they never overprint).
std::string scatter_svg(const ScatterPlot& plot);

}  // namespace zhc
