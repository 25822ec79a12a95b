// Small, dependency-free SVG line and scatter plots: the static figures of
// `report --figures DIR`, for papers. The HTML report draws the same Plots
// interactively (report/dygraph_plot.h).
#pragma once

#include <string>
#include <vector>

namespace impactlab {

struct PlotSeries {
  std::string name;  // legend entry
  std::vector<double> x, y;
  std::vector<double> sigma;  // one standard error per point, drawn as a bar (empty: none)
  enum class Style { kLine, kMarkers, kLineAndMarkers } style = Style::kLine;
  std::string colour = "#1f77b4";
};

struct Plot {
  std::string title;
  std::string x_label, y_label;  // with units, e.g. "time (s)"
  std::vector<PlotSeries> series;
  int width_px = 720, height_px = 360;
};

// The plot as an <svg> element with axes, "nice" ticks, grid, error bars and
// the legend beneath the frame (never over the data).
std::string RenderSvg(const Plot& plot);

}  // namespace impactlab
