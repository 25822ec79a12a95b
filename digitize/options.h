// The digitizer's options (digitize/digitize.h), apart from OpenCV so that
// the pipeline's options (pipeline/stage_options.h) can hold them. Their
// range checks are in options.cpp.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "io/session.h"
#include "options/settings.h"

namespace impactlab {

enum class Polarity {
  kAuto,          // decided from the photo: are thin features brighter or darker than the screen?
  kBrightTraces,  // light traces on a dark screen (a print, a phone photo)
  kDarkTraces,    // dark traces on a light ground (a negative)
};
constexpr std::array<SettingName<Polarity>, 3> SettingNames(Polarity) {
  return {{{Polarity::kAuto, "auto"},
           {Polarity::kBrightTraces, "bright_traces"},
           {Polarity::kDarkTraces, "dark_traces"}}};
}

enum class RadialModel {
  kAuto,    // fit k1, keep it only when it lowers the residual by `radial_min_gain`
  kNone,    // homography only
  kAlways,  // always fit k1
};
constexpr std::array<SettingName<RadialModel>, 3> SettingNames(RadialModel) {
  return {{{RadialModel::kAuto, "auto"},
           {RadialModel::kNone, "none"},
           {RadialModel::kAlways, "always"}}};
}

struct GraticuleOptions {
  // Width of the grey working copy the lattice is searched in, pixels. The
  // photo is shrunk by the whole factor that comes nearest; smaller is faster
  // and blinder to faint grid lines.
  int detect_width_px = 500;
  Polarity polarity = Polarity::kAuto;
  RadialModel radial = RadialModel::kAuto;
  // Relative drop of the RMS residual a radial term must bring to be kept, 1.
  double radial_min_gain = 0.15;
  // Measurements across each grid line per division of its length (taken
  // clear of the crossings and of the centre axes' minor ticks).
  int samples_per_div = 3;
  // Length of grid line each measurement averages over (parallel profiles
  // 1.5 px apart), divisions: longer is steadier in noise and slower.
  double line_average_div = 0.04;
  // The fit is refused above this RMS residual, pixels of the photo, or
  // above `max_residual_widths` of a grid line's measured width where that is
  // more: a line's centre is measured to a share of its width, and a wide
  // line (a blurred scan, a printed figure's descreened dots) is measured
  // less finely than a sharp one, while a lattice in the wrong place misses
  // by a good part of a division whatever the lines' width.
  double max_residual_px = 1.0;
  double max_residual_widths = 0.2;
  // ... or above this share of a division where more: a large photo of a
  // faint grid measures its lines to a pixel or two, while a lattice in the
  // wrong place misses them by a good part of a division. On a halftone
  // print no more than a fifth of its screen's period: the screen's rows of
  // dots lie within half a period of any line, so a lattice anywhere along
  // them finds "lines" it misses by a period / sqrt(12) RMS.
  double max_residual_div = 0.02;
  // Largest rotation of the screen in the photo searched for, degrees.
  double max_rotation_deg = 20.0;
  // Manual hint (the manifest's `graticule_corners`, docs/manifest.md): the
  // grid's outer corners in photo pixels, top-left, top-right, bottom-right,
  // bottom-left as seen on the screen. When given, the homography through
  // them replaces the lattice search; the grid lines are then measured and
  // fitted, and the fit checked, as after a search. Unset: searched.
  std::optional<GraticuleCorners> corners_px;

  // The settings (options/settings.h); the corners are a photo's hint, not a setting.
  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("detect_width_px", self.detect_width_px, "width of the copy the grid is searched in, px");
    visit("polarity", self.polarity, "traces brighter or darker than the screen");
    visit("radial", self.radial, "radial lens distortion term k1");
    visit("radial_min_gain", self.radial_min_gain, "residual drop k1 must bring to be kept, 1");
    visit("samples_per_div", self.samples_per_div, "measurements across each grid line per div");
    visit("line_average_div", self.line_average_div, "grid line length each averages, div");
    visit("max_residual_px", self.max_residual_px, "grid fit refused above this RMS residual, px");
    visit("max_residual_widths", self.max_residual_widths,
          "or above this many grid line widths where more, 1");
    visit("max_residual_div", self.max_residual_div,
          "or above this share of a division where more, div");
    visit("max_rotation_deg", self.max_rotation_deg, "largest screen rotation searched, deg");
  }

  // True when every field is in range; otherwise `error` says which is not.
  bool Check(std::string* error) const;
};

enum class SubpixelMethod {
  kCentroid,  // intensity-weighted centroid of the part above `centroid_level`
  kGaussian,  // least-squares Gaussian (a parabola in log intensity) across the line
  kParabola,  // three-point parabola through the brightest sample: fastest, coarsest
};
constexpr std::array<SettingName<SubpixelMethod>, 3> SettingNames(SubpixelMethod) {
  return {{{SubpixelMethod::kCentroid, "centroid"},
           {SubpixelMethod::kGaussian, "gaussian"},
           {SubpixelMethod::kParabola, "parabola"}}};
}

struct TraceOptions {
  SubpixelMethod method = SubpixelMethod::kCentroid;
  // Output samples per photo pixel along the sweep (1: one per pixel column of
  // the screen), 1/pixel.
  double samples_per_px = 1.0;
  // Centroid: only the profile above this fraction of the peak (over the
  // background) is weighed, 1. Higher ignores more of the glow and grid lines.
  double centroid_level = 0.5;
  // Half-length of the profile taken across the trace, in trace widths (FWHM)
  // beyond the tracking's uncertainty; the region of interest around the line.
  double profile_half_widths = 2.5;
  // Resolution of the strip each band is tracked in, pixels per division;
  // 0: the working copy's own.
  double track_px_per_div = 0.0;
  // Longest gap in a trace (a chopper's blanking, dust) the tracking bridges
  // on the trace's course; after longer ones the trace may reappear anywhere
  // at a fixed cost, divisions.
  double max_gap_div = 0.8;
  // A sample is kept when its height above the background is at least this
  // fraction of the trace's typical height, 1.
  double min_relative_height = 0.3;
  // A sample dimmer than this fraction of the brightest within 0.06 division
  // along the same unbroken stretch is dropped: it sees a dash's end (or a
  // speck's shadow) from the side, and its centre slides off the line, 1.
  double min_local_height = 0.75;
  // A sample whose line is wider than this many times the trace's usual width
  // (FWHM) is dropped: two stretches merge there (a cusp, a crossing), 1.
  double max_relative_width = 1.4;
  // A sample further than this many robust sigmas (at least 0.1 px) from a
  // parabola through its neighbours is an outlier (dust, glare), 1.
  double outlier_sigmas = 4.0;
  // Samples less confident than this (dim, pulled by a grid line, straying
  // from their neighbours: see docs/digitizing.md) are not reported, 0..1.
  double min_confidence = 0.25;
  // A trace lying on the grid's horizontal lines for half its samples and no
  // brighter than this many times the graticule's lines (its
  // typical height above the screen where its line is seen whole, dash ends
  // left out) is taken for a grid line: missing, 1.
  double min_height_over_grid = 1.3;
  // A trace covering less than this fraction of the sweep is reported missing, 1.
  double min_coverage = 0.05;
  // A grid line's light is taken to reach this many of its widths (FWHM)
  // either side of it: the peak search discounts it there, and a profile
  // running along a short line (a minor tick) within it is skipped; 0
  // ignores the grid, 1.
  double grid_reach_widths = 1.5;
  // Where a grid line reaches a trace's core, find the centre by symmetry
  // with the grid line's light modelled (docs/digitizing.md) instead of by
  // `method`. Measured: no better on this project's photos (a saturated core
  // hides a grid line under it), so off; the contact edges always use it.
  bool grid_model = false;
  // Hand marks (pencil strokes, rings, written labels: ink much wider than
  // the traces, docs/digitizing.md) are kept from the traces. Off: every
  // line is offered to the tracking, as a scratch is.
  bool hand_marks = true;
  // Not a setting: a trace on the grid's lines no brighter than them is
  // still taken when it is far wider than they are (a bold trace saturated
  // like them). The digitizer turns it on only to read again a photo whose
  // every reading failed (docs/digitizing.md).
  bool tell_bold_by_width = false;
  // Not a setting: a trace refused as a grid line followed by mistake is
  // tracked again with the horizontal grid lines' rows withheld. The
  // digitizer turns it on only to read again a photo whose every reading
  // failed (docs/digitizing.md).
  bool off_grid_rows = false;
  // Not a setting: a one-way trace's course (TraceRequest::one_way_until_s, a
  // calibration's) is sought never turning back in height. The digitizer
  // turns it on only to read again a calibration whose reading turns back
  // (docs/digitizing.md, "A calibration's trace runs one way").
  bool one_way_courses = false;

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("method", self.method, "sub-pixel centre across the trace");
    visit("samples_per_px", self.samples_per_px, "output samples per photo pixel along the sweep");
    visit("centroid_level", self.centroid_level, "centroid: fraction of the peak weighed, 1");
    visit("profile_half_widths", self.profile_half_widths, "profile half-length, trace widths");
    visit("track_px_per_div", self.track_px_per_div, "tracking strip resolution, px/div (0: own)");
    visit("max_gap_div", self.max_gap_div, "longest gap bridged on the trace's course, div");
    visit("min_relative_height", self.min_relative_height, "sample kept above this height, 1");
    visit("min_local_height", self.min_local_height, "dimmer than this of its neighbours: dropped");
    visit("max_relative_width", self.max_relative_width, "wider than this many widths: dropped");
    visit("outlier_sigmas", self.outlier_sigmas, "outlier beyond this many robust sigmas");
    visit("min_confidence", self.min_confidence, "samples less confident are not reported");
    visit("min_height_over_grid", self.min_height_over_grid,
          "dimmer traces on grid lines: missing");
    visit("min_coverage", self.min_coverage, "trace covering less of the sweep: missing");
    visit("grid_reach_widths", self.grid_reach_widths, "a grid line's light reach, its widths");
    visit("grid_model", self.grid_model, "centre by symmetry where a grid line reaches the core");
    visit("hand_marks", self.hand_marks, "keep ink much wider than the traces from them");
  }

  bool Check(std::string* error) const;
};

struct DigitizeOptions {
  GraticuleOptions graticule;
  TraceOptions traces;

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("graticule", self.graticule, "");
    visit("traces", self.traces, "");
  }

  bool Check(std::string* error) const;
};

}  // namespace impactlab
