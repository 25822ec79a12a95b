#include "render/beam.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace impactlab::render {

namespace {

// Which of the chopped traces on one beam this is, and how many share it.
struct ChopSlot {
  int index = 0;
  int count = 1;
};

// Whether the chopper lets trace `slot` through at screen x: the sweep is cut
// into slots of `dash_div`, handed round the traces in turn, each unblanked for
// the middle `duty` of its slot.
bool ChopperOpen(double x_div, const ChopSlot& slot, const ChopperSettings& chopper) {
  const double period_div = chopper.dash_div * slot.count;
  const double x = x_div - chopper.phase_div;  // exact for the default phase 0
  const double phase_div = x - period_div * std::floor(x / period_div);
  const double start_div = chopper.dash_div * (slot.index + 0.5 * (1.0 - chopper.duty));
  return phase_div >= start_div && phase_div < start_div + chopper.dash_div * chopper.duty;
}

// Parameters in (0, 1) where the segment's x crosses a chopper edge, sorted.
std::vector<double> ChopperEdges(double from_x, double to_x, const ChopSlot& slot,
                                 const ChopperSettings& chopper) {
  std::vector<double> edges;
  if (from_x == to_x) return edges;
  const double period_div = chopper.dash_div * slot.count;
  const double lo = std::min(from_x, to_x), hi = std::max(from_x, to_x);
  const double start_div =
      chopper.phase_div + chopper.dash_div * (slot.index + 0.5 * (1.0 - chopper.duty));
  for (const double edge_div : {start_div, start_div + chopper.dash_div * chopper.duty}) {
    for (double k = std::ceil((lo - edge_div) / period_div); edge_div + k * period_div < hi; ++k) {
      edges.push_back((edge_div + k * period_div - from_x) / (to_x - from_x));
    }
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

// Liang-Barsky: clips the segment to `box`; false when nothing is left.
bool ClipToBox(cv::Point2d& from, cv::Point2d& to, const cv::Rect2d& box) {
  const cv::Point2d delta = to - from;
  double enter = 0.0, leave = 1.0;
  const double p[4] = {-delta.x, delta.x, -delta.y, delta.y};
  const double q[4] = {from.x - box.x, box.x + box.width - from.x, from.y - box.y,
                       box.y + box.height - from.y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) {
      enter = std::max(enter, t);
    } else {
      leave = std::min(leave, t);
    }
  }
  if (enter > leave) return false;
  const cv::Point2d start = from;
  from = start + delta * enter;
  to = start + delta * leave;
  return true;
}

cv::Point2d ScreenPosition(const ScreenTrace& trace, std::size_t i) {
  const TraceSettings& s = trace.settings;
  return {s.t0_div + trace.time_s[i] / s.time_per_div,
          s.zero_div + trace.volts[i] / s.volts_per_div};
}

TraceBeam LayOutBeam(const ScreenTrace& trace, const std::optional<ChopSlot>& slot,
                     const ChopperSettings& chopper, const cv::Rect2d& graticule_div,
                     const cv::Rect2d& visible_div) {
  TraceBeam beam;
  beam.truth.name = trace.name;
  const double sweep_speed_div_per_s = 1.0 / std::abs(trace.settings.time_per_div);
  const std::size_t n = trace.time_s.size();
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Point2d p = ScreenPosition(trace, i);
    if (p.x >= graticule_div.x && p.x <= graticule_div.x + graticule_div.width &&
        p.y >= graticule_div.y && p.y <= graticule_div.y + graticule_div.height) {
      beam.truth.time_s.push_back(trace.time_s[i]);
      beam.truth.screen_div.push_back(p);
      beam.truth.drawn.push_back(!slot || ChopperOpen(p.x, *slot, chopper));
    }
    if (i + 1 == n) break;

    const cv::Point2d q = ScreenPosition(trace, i + 1);
    const double dt_s = trace.time_s[i + 1] - trace.time_s[i];
    const double length_div = std::hypot(q.x - p.x, q.y - p.y);
    // Exposure per unit length falls as 1 / writing speed.
    const double relative_speed = dt_s > 0.0 ? length_div / dt_s / sweep_speed_div_per_s : HUGE_VAL;
    // The intensity control scales it (a no-op at the default 1).
    const float brightness =
        std::clamp(static_cast<float>(1.0 / relative_speed), kMinBeamBrightness, 1.0f) *
        static_cast<float>(trace.brightness);

    std::vector<double> cuts = {0.0};
    if (slot) {
      const std::vector<double> edges = ChopperEdges(p.x, q.x, *slot, chopper);
      cuts.insert(cuts.end(), edges.begin(), edges.end());
    }
    cuts.push_back(1.0);
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
      cv::Point2d from = p + (q - p) * cuts[c], to = p + (q - p) * cuts[c + 1];
      if (slot && !ChopperOpen(0.5 * (from.x + to.x), *slot, chopper)) continue;
      if (!ClipToBox(from, to, visible_div)) continue;
      beam.segments.push_back({from, to, brightness});
    }
  }
  return beam;
}

}  // namespace

std::vector<TraceBeam> LayOutBeams(const OscillographScene& scene, const ChopperSettings& chopper,
                                   const cv::Rect2d& graticule_div, const cv::Rect2d& visible_div) {
  std::map<int, int> chopped_per_beam;
  for (const ScreenTrace& trace : scene.traces) {
    if (trace.mode == BeamMode::kChopped) ++chopped_per_beam[trace.beam];
  }
  std::map<int, int> next_slot;
  std::vector<TraceBeam> beams;
  for (const ScreenTrace& trace : scene.traces) {
    std::optional<ChopSlot> slot;
    if (trace.mode == BeamMode::kChopped) {
      slot = ChopSlot{next_slot[trace.beam]++, chopped_per_beam[trace.beam]};
    }
    beams.push_back(LayOutBeam(trace, slot, chopper, graticule_div, visible_div));
  }
  return beams;
}

void DrawBeam(const std::vector<BeamSegment>& segments, const cv::Matx23d& canvas_from_screen,
              double sigma_px, cv::Mat& layer) {
  CV_Assert(layer.type() == CV_32FC1);
  const double reach_px = 3.5 * sigma_px;  // exp(-3.5^2 / 2) = 0.002: invisible
  const double reach2 = reach_px * reach_px;
  const double inv_two_sigma2 = 1.0 / (2.0 * sigma_px * sigma_px);
  // Long segments are drawn in pieces so that each piece's bounding box stays
  // small even when the segment runs diagonally.
  const double piece_px = std::max(4.0, 6.0 * sigma_px);
  auto to_canvas = [&](cv::Point2d p) {
    return cv::Point2d(
        canvas_from_screen(0, 0) * p.x + canvas_from_screen(0, 1) * p.y + canvas_from_screen(0, 2),
        canvas_from_screen(1, 0) * p.x + canvas_from_screen(1, 1) * p.y + canvas_from_screen(1, 2));
  };
  for (const BeamSegment& segment : segments) {
    const cv::Point2d a = to_canvas(segment.from_div), b = to_canvas(segment.to_div);
    const cv::Point2d ab = b - a;
    const double length2 = ab.dot(ab);
    const int pieces = std::max(1, static_cast<int>(std::ceil(std::sqrt(length2) / piece_px)));
    for (int piece = 0; piece < pieces; ++piece) {
      const cv::Point2d from = a + ab * (static_cast<double>(piece) / pieces);
      const cv::Point2d to = a + ab * (static_cast<double>(piece + 1) / pieces);
      const int col0 = std::max(0, static_cast<int>(std::floor(std::min(from.x, to.x) - reach_px)));
      const int col1 =
          std::min(layer.cols - 1, static_cast<int>(std::ceil(std::max(from.x, to.x) + reach_px)));
      const int row0 = std::max(0, static_cast<int>(std::floor(std::min(from.y, to.y) - reach_px)));
      const int row1 =
          std::min(layer.rows - 1, static_cast<int>(std::ceil(std::max(from.y, to.y) + reach_px)));
      for (int row = row0; row <= row1; ++row) {
        float* out = layer.ptr<float>(row);
        for (int col = col0; col <= col1; ++col) {
          // Distance to the whole segment, not the piece: identical inside the
          // piece's box, and it keeps the pieces seamless.
          const cv::Point2d ap(col - a.x, row - a.y);
          const double t = length2 > 0.0 ? std::clamp(ap.dot(ab) / length2, 0.0, 1.0) : 0.0;
          const cv::Point2d off = ap - ab * t;
          const double d2 = off.dot(off);
          if (d2 >= reach2) continue;
          const float value =
              segment.brightness * static_cast<float>(std::exp(-d2 * inv_two_sigma2));
          out[col] = std::max(out[col], value);
        }
      }
    }
  }
}

}  // namespace impactlab::render
