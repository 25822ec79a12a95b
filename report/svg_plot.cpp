#include "report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include <fmt/format.h>

#include "report/html_escape.h"

namespace impactlab {
namespace {

struct Axis {
  double lo = 0.0, hi = 1.0, step = 0.1;
};

// A range covering [lo, hi] with 4-8 ticks on a 1-2-5 step.
Axis NiceAxis(double lo, double hi) {
  if (!(hi > lo)) {
    const double pad = lo == 0.0 ? 1.0 : 0.1 * std::abs(lo);
    lo -= pad;
    hi += pad;
  }
  const double raw = (hi - lo) / 8.0;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10.0 * decade;
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * decade >= raw) {
      step = m * decade;
      break;
    }
  }
  return {std::floor(lo / step) * step, std::ceil(hi / step) * step, step};
}

std::string TickLabel(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(v) < 1e-12 * step) v = 0.0;
  if (step >= 1e5 || step < 1e-4) return fmt::format("{:.3g}", v);
  return fmt::format("{:.{}f}", v, decimals);
}

}  // namespace

std::string RenderSvg(const Plot& plot) {
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (const PlotSeries& s : plot.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const double sigma = i < s.sigma.size() && std::isfinite(s.sigma[i]) ? s.sigma[i] : 0.0;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i] - sigma);
      y_hi = std::max(y_hi, s.y[i] + sigma);
    }
  }
  if (!std::isfinite(x_lo)) x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
  // A margin, so that points at the extremes do not sit on the frame.
  const double x_pad = 0.03 * (x_hi - x_lo), y_pad = 0.05 * (y_hi - y_lo);
  x_lo -= x_pad, x_hi += x_pad, y_lo -= y_pad, y_hi += y_pad;
  const Axis ax = NiceAxis(x_lo, x_hi), ay = NiceAxis(y_lo, y_hi);
  const double left = 70, right = 20, top = 34, bottom = 48;
  const double legend_rows = static_cast<double>(plot.series.size());
  const int height_px = plot.height_px + static_cast<int>(16.0 * legend_rows);
  const double w = plot.width_px - left - right, h = plot.height_px - top - bottom;
  const auto px = [&](double x) { return left + (x - ax.lo) / (ax.hi - ax.lo) * w; };
  const auto py = [&](double y) { return top + (ay.hi - y) / (ay.hi - ay.lo) * h; };

  std::string svg = fmt::format(
      R"svg(<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {0} {1}" width="{0}" height="{1}" font-family="sans-serif" font-size="12">)svg",
      plot.width_px, height_px);
  svg += fmt::format(R"svg(<text x="{}" y="20" font-size="14" font-weight="bold">{}</text>)svg",
                     left, EscapeHtml(plot.title));
  // Grid and ticks.
  for (double x = ax.lo; x <= ax.hi + 0.5 * ax.step; x += ax.step) {
    svg += fmt::format(
        R"svg(<line x1="{0:.1f}" y1="{1:.1f}" x2="{0:.1f}" y2="{2:.1f}" stroke="#ddd"/>)svg", px(x),
        top, top + h);
    svg += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" text-anchor="middle">{}</text>)svg", px(x),
                       top + h + 16, TickLabel(x, ax.step));
  }
  for (double y = ay.lo; y <= ay.hi + 0.5 * ay.step; y += ay.step) {
    svg += fmt::format(
        R"svg(<line x1="{0:.1f}" y1="{1:.1f}" x2="{2:.1f}" y2="{1:.1f}" stroke="#ddd"/>)svg", left,
        py(y), left + w);
    svg += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" text-anchor="end">{}</text>)svg", left - 6,
                       py(y) + 4, TickLabel(y, ay.step));
  }
  svg +=
      fmt::format(R"svg(<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#333"/>)svg",
                  left, top, w, h);
  svg += fmt::format(R"svg(<text x="{:.1f}" y="{}" text-anchor="middle">{}</text>)svg",
                     left + 0.5 * w, plot.height_px - 10, EscapeHtml(plot.x_label));
  svg += fmt::format(
      R"svg(<text x="16" y="{0:.1f}" text-anchor="middle" transform="rotate(-90 16 {0:.1f})">{1}</text>)svg",
      top + 0.5 * h, EscapeHtml(plot.y_label));
  // Series, clipped to the frame.
  // Ids are document-wide in HTML: one per plot, from its title and labels.
  const std::size_t id = std::hash<std::string>{}(plot.title + plot.x_label + plot.y_label);
  svg += fmt::format(
      R"svg(<clipPath id="clip{}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath>)svg", id,
      left, top, w, h);
  svg += fmt::format(R"svg(<g clip-path="url(#clip{})">)svg", id);
  for (const PlotSeries& s : plot.series) {
    const bool line = s.style != PlotSeries::Style::kMarkers;
    const bool markers = s.style != PlotSeries::Style::kLine;
    if (line) {
      std::string points;
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
          points += fmt::format("{:.1f},{:.1f} ", px(s.x[i]), py(s.y[i]));
        }
      }
      svg +=
          fmt::format(R"svg(<polyline points="{}" fill="none" stroke="{}" stroke-width="1.3"/>)svg",
                      points, s.colour);
    }
    for (std::size_t i = 0; i < s.sigma.size() && i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || !(s.sigma[i] > 0.0)) continue;
      svg += fmt::format(
          R"svg(<line x1="{0:.1f}" y1="{1:.1f}" x2="{0:.1f}" y2="{2:.1f}" stroke="{3}"/>)svg",
          px(s.x[i]), py(s.y[i] - s.sigma[i]), py(s.y[i] + s.sigma[i]), s.colour);
    }
    if (markers) {
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        svg += fmt::format(R"svg(<circle cx="{:.1f}" cy="{:.1f}" r="3.2" fill="{}"/>)svg",
                           px(s.x[i]), py(s.y[i]), s.colour);
      }
    }
  }
  svg += "</g>";
  // Legend, beneath the axis label.
  double ly = plot.height_px + 4;
  for (const PlotSeries& s : plot.series) {
    const double lx = left;
    svg += fmt::format(R"svg(<rect x="{:.1f}" y="{:.1f}" width="14" height="4" fill="{}"/>)svg", lx,
                       ly - 6, s.colour);
    svg += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}">{}</text>)svg", lx + 20, ly,
                       EscapeHtml(s.name));
    ly += 16;
  }
  return svg + "</svg>";
}

}  // namespace impactlab
