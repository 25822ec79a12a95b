#include "report/dygraph_plot.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "report/dygraph_source.h"  // generated: kDygraphJs, kDygraphCss
#include "report/html_escape.h"

namespace impactlab {
namespace {

// A JavaScript string literal that cannot end the <script> it is in.
std::string JsString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '<':
        out += "\\u003c";
        break;
      case '>':
        out += "\\u003e";
        break;
      case '&':
        out += "\\u0026";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<int>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string JsNumber(double v) { return std::isfinite(v) ? fmt::format("{}", v) : "null"; }

}  // namespace

std::string DygraphLibrary() {
  return fmt::format("<style>{}</style>\n<script>{}</script>\n", kDygraphCss, kDygraphJs);
}

std::string RenderDygraph(const Plot& plot, const std::string& id) {
  // dygraphs draws rows of [x, series...]: the series' x values merged, and
  // null where a series has no point (joined across for lines).
  std::map<double, std::vector<std::string>> rows;
  const std::size_t n = plot.series.size();
  const bool error_bars = std::any_of(plot.series.begin(), plot.series.end(),
                                      [](const PlotSeries& s) { return !s.sigma.empty(); });
  for (std::size_t k = 0; k < n; ++k) {
    const PlotSeries& s = plot.series[k];
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i])) continue;
      auto& row = rows.try_emplace(s.x[i], std::vector<std::string>(n, "null")).first->second;
      const double sigma = i < s.sigma.size() ? s.sigma[i] : 0.0;
      row[k] =
          error_bars ? fmt::format("[{},{}]", JsNumber(s.y[i]), JsNumber(sigma)) : JsNumber(s.y[i]);
    }
  }
  std::string data = "[";
  for (const auto& [x, values] : rows) {
    data += fmt::format("[{},{}],", JsNumber(x), fmt::join(values, ","));
  }
  data += "]";
  std::string labels = JsString(plot.x_label), colours, series;
  for (const PlotSeries& s : plot.series) {
    labels += "," + JsString(s.name);
    colours += (colours.empty() ? "" : ",") + JsString(s.colour);
    const bool markers = s.style != PlotSeries::Style::kLine;
    series += fmt::format("{}:{{strokeWidth:{},drawPoints:{},pointSize:{}}},", JsString(s.name),
                          s.style == PlotSeries::Style::kMarkers ? 0 : 1.5,
                          markers ? "true" : "false", markers ? 3 : 1);
  }
  return fmt::format(
      "<div class=\"plot\"><div id=\"{0}\" class=\"graph\"></div>"
      "<div id=\"{0}-legend\" class=\"legend\"></div></div>\n"
      "<script>new Dygraph(document.getElementById(\"{0}\"),{1},{{labels:[{2}],"
      "title:{3},xlabel:{4},ylabel:{5},colors:[{6}],series:{{{7}}},errorBars:{8},sigma:1,"
      "connectSeparatedPoints:true,legend:\"always\",labelsSeparateLines:true,"
      "axes:{{y:{{axisLabelWidth:72}}}},"
      "labelsDiv:\"{0}-legend\",animatedZooms:false}});</script>\n",
      id, data, labels, JsString(plot.title), JsString(plot.x_label), JsString(plot.y_label),
      colours, series, error_bars ? "true" : "false");
}

}  // namespace impactlab
