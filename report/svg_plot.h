// Small, dependency-free SVG line and scatter plots for the HTML report: the
// page must open offline, so plots are inline SVG rather than a JavaScript
// library from the network.
#pragma once

#include <string>
#include <vector>

namespace impactlab {

struct PlotSeries {
  std::string name;  // legend entry
  std::vector<double> x, y;
  enum class Style { kLine, kMarkers, kLineAndMarkers } style = Style::kLine;
  std::string colour = "#1f77b4";
};

struct Plot {
  std::string title;
  std::string x_label, y_label;  // with units, e.g. "time (s)"
  std::vector<PlotSeries> series;
  int width_px = 720, height_px = 360;
};

// The plot as an <svg> element with axes, "nice" ticks, grid and legend.
std::string RenderSvg(const Plot& plot);

}  // namespace impactlab
