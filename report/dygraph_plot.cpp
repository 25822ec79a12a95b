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

// Five significant digits: a hundredth of a pixel on any screen, and half
// the bytes of the shortest exact text.
std::string JsNumber(double v) { return std::isfinite(v) ? fmt::format("{:.5g}", v) : "null"; }

// A line's points as a screen shows them: at most two per bucket of
// consecutive points (its lowest and highest, in order), so that a peak a
// pixel wide survives and a history of ten thousand samples costs a few
// hundred rows. Markers and points with errors are kept as they are.
constexpr std::size_t kLineBuckets = 200;

PlotSeries ThinnedLine(const PlotSeries& s) {
  const std::size_t n = std::min(s.x.size(), s.y.size());
  if (s.style != PlotSeries::Style::kLine || !s.sigma.empty() || n <= 2 * kLineBuckets) return s;
  PlotSeries out = s;
  out.x.clear();
  out.y.clear();
  for (std::size_t b = 0; b < kLineBuckets; ++b) {
    const std::size_t begin = b * n / kLineBuckets, end = (b + 1) * n / kLineBuckets;
    std::size_t lo = begin, hi = begin;
    for (std::size_t i = begin; i < end; ++i) {
      if (s.y[i] < s.y[lo]) lo = i;
      if (s.y[i] > s.y[hi]) hi = i;
    }
    const std::size_t first = std::min(lo, hi), second = std::max(lo, hi);
    out.x.push_back(s.x[first]);
    out.y.push_back(s.y[first]);
    if (second != first) {
      out.x.push_back(s.x[second]);
      out.y.push_back(s.y[second]);
    }
  }
  return out;
}

// Markers with error bars drawn as bars, as the SVG figures have them
// (dygraphs' own draws a band between the points, which reads as a curve).
constexpr const char* kErrorBarPlotter = R"(function impactlabErrorBars(e){
var c=e.drawingContext,a=e.plotArea;c.strokeStyle=e.color;c.fillStyle=e.color;c.lineWidth=1.2;
for(var i=0;i<e.points.length;i++){var p=e.points[i];if(p.yval===null||isNaN(p.canvasy))continue;
var t=a.y+a.h*p.y_top,b=a.y+a.h*p.y_bottom;if(!isNaN(t)&&!isNaN(b)){c.beginPath();
c.moveTo(p.canvasx,t);c.lineTo(p.canvasx,b);c.moveTo(p.canvasx-4,t);c.lineTo(p.canvasx+4,t);
c.moveTo(p.canvasx-4,b);c.lineTo(p.canvasx+4,b);c.stroke();}
c.beginPath();c.arc(p.canvasx,p.canvasy,3.5,0,2*Math.PI);c.fill();}})";

// A figure is drawn when it comes within a screen of the view, or, once the
// page has loaded, in its turn, one per task, so that the reader's first
// screen is drawn at once and the page stays responsive: a session's page has
// dozens of figures, and drawing them all before the load event kept the
// reader waiting seconds. Its <div> has its size from the style sheet, so
// the page does not move when it is drawn.
constexpr const char* kDrawWhenSeen = R"(var impactlabFigures=[];
function impactlabPlot(id,draw){var f={done:false,run:function(){if(!f.done){f.done=true;draw();}}};
impactlabFigures.push(f);if('IntersectionObserver' in window){
var o=new IntersectionObserver(function(es){for(var i=0;i<es.length;i++){if(es[i].isIntersecting){
o.disconnect();f.run();return;}}},{rootMargin:'100% 0px'});o.observe(document.getElementById(id));}}
addEventListener('load',function(){var i=0;(function next(){
while(i<impactlabFigures.length&&impactlabFigures[i].done)i++;
if(i<impactlabFigures.length){impactlabFigures[i].run();setTimeout(next,0);}})();});)";

}  // namespace

std::string DygraphLibrary() {
  return fmt::format("<style>{}</style>\n<script>{}\n{}\n{}</script>\n", kDygraphCss, kDygraphJs,
                     kErrorBarPlotter, kDrawWhenSeen);
}

std::string RenderDygraph(const Plot& plot, const std::string& id) {
  // dygraphs draws rows of [x, series...]: the series' x values merged, and
  // null where a series has no point (joined across for lines).
  std::map<double, std::vector<std::string>> rows;
  const std::size_t n = plot.series.size();
  const bool error_bars = std::any_of(plot.series.begin(), plot.series.end(),
                                      [](const PlotSeries& s) { return !s.sigma.empty(); });
  for (std::size_t k = 0; k < n; ++k) {
    const PlotSeries s = ThinnedLine(plot.series[k]);
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
    // Points with errors: each with its bar, none joined to the next.
    const bool bars = s.style == PlotSeries::Style::kMarkers && !s.sigma.empty();
    series +=
        fmt::format("{}:{{strokeWidth:{},drawPoints:{},pointSize:{}{}}},", JsString(s.name),
                    s.style == PlotSeries::Style::kMarkers ? 0 : 1.5, markers ? "true" : "false",
                    markers ? 3 : 1, bars ? ",plotter:impactlabErrorBars" : "");
  }
  return fmt::format(
      "<div class=\"plot\"><div id=\"{0}\" class=\"graph\"></div>"
      "<div id=\"{0}-legend\" class=\"legend\"></div></div>\n"
      "<script>impactlabPlot(\"{0}\",function(){{new Dygraph(document.getElementById(\"{0}\"),"
      "{1},{{labels:[{2}],"
      "title:{3},xlabel:{4},ylabel:{5},colors:[{6}],series:{{{7}}},errorBars:{8},sigma:1,"
      "connectSeparatedPoints:true,legend:\"always\",labelsSeparateLines:true,"
      "xRangePad:14,yRangePad:14,axes:{{y:{{axisLabelWidth:72}}}},"
      "labelsDiv:\"{0}-legend\",animatedZooms:false}});}});</script>\n",
      id, data, labels, JsString(plot.title), JsString(plot.x_label), JsString(plot.y_label),
      colours, series, error_bars ? "true" : "false");
}

}  // namespace impactlab
