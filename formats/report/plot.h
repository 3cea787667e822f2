// zhc/formats/report/plot.h — scatter plots as PNG (benchmark charts): labelled points, optional log
// axes, a highlighted Pareto frontier.
#pragma once

#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/status.h"

namespace zhc {

struct PlotPoint {
    std::string label;
    double x = 0, y = 0;
    // An engine's layout (codec/probe/engine_layouts.h): drawn apart from zhc's representations
    // (an orange square and an orange label, a legend line saying so).
    bool engine = false;
};

struct ScatterPlot {
    std::string title, x_label, y_label;
    std::vector<PlotPoint> points;
    std::vector<std::size_t> frontier;  // indices into points, drawn joined and highlighted
    bool log_x = true, log_y = true;
};

// The point of a codec-table entry: labelled with its name, marked when it is an engine layout.
PlotPoint codec_point(const Codec& codec, double x, double y);
// zhc's Pareto frontier: pareto_frontier (codec/audit/benchmark.h) of the points that are not
// engine layouts, as indices into plot.points. The engine layouts are drawn against it.
std::vector<std::size_t> zhc_frontier(const ScatterPlot& plot);

Status write_scatter_png(const std::string& path, const ScatterPlot& plot);

}  // namespace zhc
