// zhc/formats/report/plot.h — scatter plots as PNG (benchmark charts): labelled points, optional log
// axes, a highlighted Pareto frontier.
#pragma once

#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

struct PlotPoint {
    std::string label;
    double x = 0, y = 0;
};

struct ScatterPlot {
    std::string title, x_label, y_label;
    std::vector<PlotPoint> points;
    std::vector<std::size_t> frontier;  // indices into points, drawn joined and highlighted
    bool log_x = true, log_y = true;
};

Status write_scatter_png(const std::string& path, const ScatterPlot& plot);

}  // namespace zhc
