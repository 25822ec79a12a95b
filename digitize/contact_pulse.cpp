// MeasurePulse: the contact trace's levels from its samples, its edges from
// the photo. A contact circuit switches in about a microsecond, far faster
// than the sweep, so the beam writes each edge as a faint vertical stroke
// between the levels; its centre at half height is the edge's time. The
// stroke is measured across (along the sweep) at several heights between the
// levels, and a straight line through those centres (the edge may lean when
// the switching is slower) is read at half height.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "digitize/digitize.h"
#include "digitize/ink_sampler.h"
#include "digitize/line_profile.h"
#include "digitize/screen_geometry.h"

namespace impactlab {

namespace {

using digitize::CentreSettings;
using digitize::FindLineCentre;
using digitize::GridCrossings;
using digitize::InkSampler;
using digitize::LineCentre;
using digitize::Profile;
using digitize::ReadProfile;
using digitize::ScreenFromPixel;

double Median(std::vector<double> values) {
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Splits the heights into two groups with the largest between-group variance
// (Otsu); returns the two groups' medians, low first.
std::optional<std::pair<double, double>> TwoLevels(std::vector<double> y) {
  const std::size_t n = y.size();
  if (n < 10) return std::nullopt;
  std::sort(y.begin(), y.end());
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + y[i];
  double best = -1.0;
  std::size_t split = 0;
  const std::size_t least = std::max<std::size_t>(3, n / 20);
  for (std::size_t k = least; k + least <= n; ++k) {
    const double m0 = prefix[k] / k, m1 = (prefix[n] - prefix[k]) / (n - k);
    const double between = static_cast<double>(k) * (n - k) * (m1 - m0) * (m1 - m0);
    if (between > best) best = between, split = k;
  }
  if (split == 0) return std::nullopt;
  return std::make_pair(y[(split - 1) / 2], y[split + (n - split) / 2]);
}

// The summed profile's noise: the robust scatter of differences two pixels
// apart (four samples; nearer ones share pixels) in its outer fifths, which a
// slope of the background does not inflate.
double ProfileNoise(const std::vector<float>& values) {
  constexpr std::size_t kLag = 4;
  const std::size_t n = values.size(), fifth = std::max<std::size_t>(kLag + 2, n / 5);
  std::vector<double> differences;
  for (std::size_t i = 0; i + kLag < fifth; ++i) {
    differences.push_back(std::abs(values[i + kLag] - values[i]));
    differences.push_back(std::abs(values[n - 1 - i] - values[n - 1 - i - kLag]));
  }
  return 1.4826 * Median(differences) / std::sqrt(2.0) + 1e-6;
}

// Where the faint stroke between the levels crosses half height, near screen x
// `guess_div`, searched within `reach_div` either side. Every photo row in the
// middle half between the levels is read along the sweep; the rows are summed
// in kGroups bands (a faint stroke needs the averaging), each band's centre
// is measured, and a straight line x(y) through them is read at half height.
std::optional<PulseEdge> EdgeFromStroke(const InkSampler& ink, const GraticuleFit& graticule,
                                        const GridCrossings& grid, double guess_div,
                                        double reach_div, double low_div, double high_div,
                                        double width_px) {
  constexpr int kGroups = 6;
  constexpr double kDeltaDiv = 0.01;
  const GraticuleMapping& mapping = graticule.mapping;
  const ScreenFromPixel screen_from_pixel(mapping);
  const double mid_div = 0.5 * (low_div + high_div);
  const double px_per_div = cv::norm(mapping.ImageFromScreen({guess_div + kDeltaDiv, mid_div}) -
                                     mapping.ImageFromScreen({guess_div - kDeltaDiv, mid_div})) /
                            (2.0 * kDeltaDiv);
  const int rows = std::clamp(
      static_cast<int>(0.5 * std::abs(high_div - low_div) * px_per_div / kGroups) * kGroups,
      kGroups * 2, kGroups * 40);
  // One length for every row, so that the profiles' samples line up (each
  // row's profile runs along the screen's x, so the stroke and any vertical
  // grid line sit at the same offset in every row).
  const double half_length = reach_div * px_per_div + 3.0 * width_px;
  CentreSettings settings;
  settings.search_px = reach_div * px_per_div;
  settings.crossing_height = graticule.line_contrast;

  std::vector<Profile> groups;
  std::vector<double> group_y;
  std::vector<float> total;
  for (int g = 0; g < kGroups; ++g) {
    Profile sum;
    int used = 0;
    double y_sum = 0.0;
    for (int k = 0; k < rows / kGroups; ++k) {
      const int j = g * (rows / kGroups) + k;
      // The middle half between the levels: clear of the corners' glow.
      const double y = low_div + (high_div - low_div) * (0.25 + 0.5 * (j + 0.5) / rows);
      const cv::Point2d origin = mapping.ImageFromScreen({guess_div, y});
      const cv::Point2d along = mapping.ImageFromScreen({guess_div + kDeltaDiv, y}) -
                                mapping.ImageFromScreen({guess_div - kDeltaDiv, y});
      Profile p = ReadProfile(ink, origin, along / cv::norm(along), half_length, 0.5);
      // A row along a minor tick of the vertical axis would add the tick's
      // light to a stretch of it: such rows are left out.
      const int n = static_cast<int>(p.values.size());
      grid.AddTo(p, screen_from_pixel(p.PointAt(p.OffsetAt(0))),
                 screen_from_pixel(p.PointAt(p.OffsetAt(n - 1))));
      if (p.beside_short_line) continue;
      if (used++ == 0) {
        sum = p;
      } else {
        for (std::size_t i = 0; i < sum.values.size(); ++i) sum.values[i] += p.values[i];
      }
      y_sum += y;
    }
    if (used == 0) continue;
    for (float& v : sum.values) v /= used;
    // The band's profile, placed on its mean row.
    const double y = y_sum / used;
    const cv::Point2d along = mapping.ImageFromScreen({guess_div + kDeltaDiv, y}) -
                              mapping.ImageFromScreen({guess_div - kDeltaDiv, y});
    sum.origin_px = mapping.ImageFromScreen({guess_div, y});
    sum.direction = along / cv::norm(along);
    sum.crossings.clear();
    const int n = static_cast<int>(sum.values.size());
    grid.AddTo(sum, screen_from_pixel(sum.PointAt(sum.OffsetAt(0))),
               screen_from_pixel(sum.PointAt(sum.OffsetAt(n - 1))));
    sum.beside_short_line = false;
    if (total.empty()) total.assign(sum.values.size(), 0.0f);
    for (int i = 0; i < n; ++i) total[i] += sum.values[i];
    group_y.push_back(y);
    groups.push_back(std::move(sum));
  }
  if (groups.size() < 2) return std::nullopt;
  for (float& v : total) v /= static_cast<float>(groups.size());
  // The whole: is there a stroke, standing out of the noise?
  Profile whole = groups[groups.size() / 2];
  whole.values = total;
  const LineCentre stroke = FindLineCentre(whole, settings);
  if (!stroke.found || stroke.height < 4.0 * ProfileNoise(total)) return std::nullopt;

  // Each band's centre near the whole's; a line x(y) through them.
  settings.search_px = std::max(2.0, stroke.fwhm_px);
  std::vector<double> xs, ys;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    Profile p = groups[g];
    p.origin_px = p.PointAt(stroke.offset_px);
    p.start_px -= stroke.offset_px;
    for (Profile::Crossing& crossing : p.crossings) crossing.offset_px -= stroke.offset_px;
    const LineCentre c = FindLineCentre(p, settings);
    if (!c.found || c.height < 0.3 * stroke.height) continue;
    xs.push_back(screen_from_pixel(p.PointAt(c.offset_px)).x);
    ys.push_back(group_y[g]);
  }
  PulseEdge edge;
  edge.from_image = true;
  if (xs.size() >= 4) {
    const double my = std::accumulate(ys.begin(), ys.end(), 0.0) / ys.size();
    const double mx = std::accumulate(xs.begin(), xs.end(), 0.0) / xs.size();
    double syy = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
      syy += (ys[i] - my) * (ys[i] - my);
      sxy += (xs[i] - mx) * (ys[i] - my);
    }
    const double lean = sxy / syy;  // dx/dy
    double rss = 0.0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
      const double r = xs[i] - (mx + lean * (ys[i] - my));
      rss += r * r;
    }
    const double sigma = std::sqrt(rss / (xs.size() - 2));
    edge.time_s = mx + lean * (mid_div - my);  // screen x for now
    edge.sigma_s = sigma * std::sqrt(1.0 / xs.size() + (mid_div - my) * (mid_div - my) / syy);
  } else {
    // Too faint band by band: the whole's centre.
    edge.time_s = screen_from_pixel(whole.PointAt(stroke.offset_px)).x;
    edge.sigma_s =
        0.5 * stroke.fwhm_px / std::max(1.0, stroke.height / ProfileNoise(total)) / px_per_div;
  }
  edge.centre_px = mapping.ImageFromScreen({edge.time_s, mid_div});
  return edge;
}

}  // namespace

std::optional<ContactPulseFit> MeasurePulse(const PreparedPhoto& photo,
                                            const GraticuleFit& graticule,
                                            const DigitizedTrace& trace) {
  const std::vector<cv::Point2d>& screen = trace.screen_div;
  std::vector<double> y;
  for (const cv::Point2d& p : screen) y.push_back(p.y);
  const auto levels = TwoLevels(y);
  if (!levels) return std::nullopt;
  auto [low, high] = *levels;
  const TraceSettings& s = trace.settings;
  // The pulse is the higher voltage (a contact circuit is high while the bars touch).
  const bool inverted = s.volts_per_div < 0.0;
  const double pulse_level = inverted ? low : high, rest_level = inverted ? high : low;
  const double px_per_div = graticule.px_per_div;
  if (std::abs(high - low) * px_per_div < 4.0 * std::max(trace.width_px, 1.0)) return std::nullopt;

  // Runs of samples at each level, in order; the first rest -> pulse -> rest.
  const double middle = 0.5 * (low + high);
  auto at_pulse = [&](double v) { return (v > middle) == (pulse_level > middle); };
  constexpr int kRun = 3;  // samples in a row that make a level
  int rise_after = -1, rise_before = -1, fall_after = -1, fall_before = -1;
  const int n = static_cast<int>(screen.size());
  auto run_at = [&](int from, bool pulse) {
    if (from + kRun > n) return false;
    for (int k = from; k < from + kRun; ++k) {
      if (at_pulse(screen[k].y) != pulse) return false;
    }
    return true;
  };
  for (int i = kRun - 1; i + 1 < n; ++i) {
    if (rise_after < 0) {
      if (!at_pulse(screen[i].y) && run_at(i + 1, true) && run_at(i - kRun + 1, false)) {
        rise_before = i, rise_after = i + 1;
      }
    } else if (!at_pulse(screen[i + 1].y) && at_pulse(screen[i].y) && run_at(i + 1, false)) {
      fall_before = i, fall_after = i + 1;
      break;
    }
  }
  if (rise_after < 0 || fall_after < 0) return std::nullopt;

  const InkSampler ink(photo.image, photo.dark_traces);
  // A faint stroke beside a grid line needs the line's light modelled.
  constexpr double kGridReachWidths = 1.5;
  const GridCrossings grid(graticule.divisions, graticule.line_width_px / px_per_div,
                           kGridReachWidths);
  const double low_div = rest_level, high_div = pulse_level;
  auto edge_at = [&](int before, int after) {
    const double x0 = screen[before].x, x1 = screen[after].x;
    const double guess = 0.5 * (x0 + x1);
    // The edge lies between the last sample of one level and the first of
    // the other (each level is followed right into its corner).
    const double width_div = trace.width_px / px_per_div;
    const double reach = 0.5 * (x1 - x0) + width_div;
    std::optional<PulseEdge> edge =
        EdgeFromStroke(ink, graticule, grid, guess, reach, low_div, high_div, trace.width_px);
    if (edge && (edge->time_s < x0 - 0.5 * width_div || edge->time_s > x1 + 0.5 * width_div)) {
      edge.reset();  // something else: a speck, a scratch
    }
    // The ends of the centre axis's minor ticks (0.1 division either side of
    // it) look like short strokes too.
    const double axis = 0.5 * graticule.divisions[0];
    if (edge && std::min(std::abs(edge->time_s - (axis - 0.1)),
                         std::abs(edge->time_s - (axis + 0.1))) < 0.5 * width_div) {
      edge.reset();
    }
    if (edge) {
      // A vertical grid line within two widths (or the centre axis with its
      // ticks) overlaps the stroke: the fit cannot tell all of their light
      // apart, so the levels' ends bound the uncertainty too.
      const double x = edge->time_s;
      const bool near_line = std::abs(x - std::round(x)) < 2.0 * width_div ||
                             std::abs(x - 0.5 * graticule.divisions[0]) < 0.1 + 2.0 * width_div;
      if (near_line) edge->sigma_s = std::hypot(edge->sigma_s, (x1 - x0) / std::sqrt(12.0));
    }
    if (!edge) {
      // No stroke to be seen: between the levels' ends, as a sampled trace would.
      edge = PulseEdge{};
      edge->time_s = guess;
      edge->sigma_s = (x1 - x0) / std::sqrt(12.0);
      edge->centre_px = graticule.mapping.ImageFromScreen({guess, 0.5 * (low_div + high_div)});
    }
    // The mapping's own uncertainty along the sweep.
    const double mapping_sigma_div = 0.5 * graticule.residual_px / px_per_div;
    edge->sigma_s = std::hypot(edge->sigma_s, mapping_sigma_div);
    // Screen x to seconds.
    edge->time_s = (edge->time_s - s.t0_div) * s.time_per_div;
    edge->sigma_s *= s.time_per_div;
    return *edge;
  };
  ContactPulseFit fit;
  fit.rise = edge_at(rise_before, rise_after);
  fit.fall = edge_at(fall_before, fall_after);
  fit.width_s = fit.fall.time_s - fit.rise.time_s;
  fit.width_sigma_s = std::hypot(fit.rise.sigma_s, fit.fall.sigma_s);
  fit.low_volts = (std::min(low, high) - s.zero_div) * s.volts_per_div;
  fit.high_volts = (std::max(low, high) - s.zero_div) * s.volts_per_div;
  if (fit.low_volts > fit.high_volts) std::swap(fit.low_volts, fit.high_volts);
  return fit;
}

}  // namespace impactlab
