// Digitizing oscillograph photos (docs/digitizing.md): from a photo of an
// oscilloscope screen and the trace settings in the manifest, recover each
// trace as (time s, volts) samples with a per-sample confidence.
//
// The stages, each a function of its options:
//   LoadPhoto        decode the file (the only step that touches the disk)
//   PreparePhoto     a small grey working copy, the polarity (dark or bright traces)
//   FindGraticule    the grid's lattice in the working copy, then every grid line
//                    measured in the full photo and a homography plus a radial
//                    term fitted to them (its residual reported)
//   ExtractTraces    per trace: its band tracked in a rectified strip, then the
//                    centre line measured across the trace in the full photo
//   MeasurePulse     the contact trace's edges from the photo, sub-pixel
//   DrawOverlay      the photo with what was found drawn on it
// DigitizePhoto runs them all. A photo that cannot be read to the end (no
// graticule, a trace missing from its band, a photo too small) is a result
// with !ok naming the photo, the key to fix and what was not found, keeping
// what was found before (the graticule); no sample is ever made up where the
// trace is not seen. The stages run alone throw InputError instead.
//
// Conventions as in session-format.md and render/oscillograph.h: screen
// positions in graticule divisions, x from the graticule's left edge, y from its
// centre, up positive; image positions in pixels, x right, y down, pixel
// centres at integer coordinates.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "digitize/options.h"
#include "io/errors.h"
#include "io/session.h"
#include "io/trace.h"
#include "model/contact_pulse.h"

namespace impactlab {

// ---------------------------------------------------------------------------
// The photo

struct Photo {
  cv::Mat image;                 // as decoded: CV_8U or CV_16U, 1, 3 (BGR) or 4 (BGRA) channels
  std::filesystem::path source;  // the file, named in every error message
};

namespace digitize {
// The largest photo decoded, in pixels (width x height). A 1200 dpi scan of a
// 4 x 5 inch print is 29 Mpx and a phone photo 12-50 Mpx; 100 Mpx leaves room
// for those while bounding what one photo can cost: at most 100 MB for a
// JPEG (decoded to 8-bit grey), 800 MB for a 16-bit BGRA PNG or TIFF.
constexpr std::uint64_t kMaxPhotoPixels = 100'000'000;
}  // namespace digitize

// Decodes a PNG, JPEG or TIFF file, 8 or 16 bit, grey or colour; a JPEG to
// its luma only (grey), the one thing the digitizer reads from it. Throws
// InputError naming the file when it is missing, unreadable, truncated, not an
// image, or too small to hold a graticule.
Photo LoadPhoto(const std::filesystem::path& path);

// LoadPhoto's work after reading the file: `bytes` are the file's contents,
// `source` the file named in errors. Before decoding, the header's declared
// size is read and a photo over 100 megapixels (digitize::kMaxPhotoPixels,
// imagefile/image_header.h) or with an unreadable header is refused; a JPEG
// that the decoder warns about (corrupt or missing data) is refused too.
// Throws InputError naming `source` and the reason.
Photo DecodePhoto(const std::vector<unsigned char>& bytes, const std::filesystem::path& source);

// ---------------------------------------------------------------------------
// The graticule

// Where the screen lies in the photo: a homography takes (x_div, y_div, 1) to
// an undistorted image point q, then one radial term moves it,
// p = c + (q - c) (1 + k1 |q - c|^2 / r^2), c the image centre, r its half diagonal.
struct GraticuleMapping {
  cv::Matx33d homography = cv::Matx33d::eye();  // undistorted pixels from (x_div, y_div, 1)
  double radial_k1 = 0.0;                       // k1 above; < 0 is barrel distortion
  cv::Point2d distortion_centre_px;             // c above
  double distortion_radius_px = 1.0;            // r above

  cv::Point2d ImageFromScreen(cv::Point2d screen_div) const;
  // The inverse: Newton on the radial term, then the inverse homography.
  cv::Point2d ScreenFromImage(cv::Point2d image_px) const;
  // The image length of one division at a screen point (square root of the
  // local area stretch), pixels per division.
  double PixelsPerDivisionAt(cv::Point2d screen_div) const;
};

// The photo reduced for the search: what every later stage shares.
struct PreparedPhoto {
  cv::Mat image;                 // the decoded photo (shared, not copied), or descreened
  std::filesystem::path source;  // named in errors
  // A figure printed through a halftone screen: the dots' period (0: no
  // screen) and direction. `image` is then the photo low-passed so that the
  // dots merge into lines (docs/digitizing.md, "Reproduced figures").
  double halftone_period_px = 0.0;
  double halftone_angle_deg = 0.0;
  bool dark_traces = false;  // polarity used: true for dark traces on a light ground
  int shrink = 1;            // a working pixel covers shrink x shrink photo pixels
  cv::Mat1f working;         // grey "ink" in [0, 1]: traces and lines bright whatever the polarity
  cv::Mat1f ridge;           // thin bright structure of `working` (white top-hat)
  int ridge_opening_px = 5;  // `ridge` keeps what is narrower than this square (bold_lines.h)
  double prepare_ms = 0.0;   // time spent here, milliseconds

  // Photo pixel of a working pixel's centre, and back.
  cv::Point2d PhotoFromWorking(cv::Point2d w) const {
    return w * shrink + cv::Point2d(0.5 * (shrink - 1), 0.5 * (shrink - 1));
  }
  cv::Point2d WorkingFromPhoto(cv::Point2d p) const {
    return (p - cv::Point2d(0.5 * (shrink - 1), 0.5 * (shrink - 1))) * (1.0 / shrink);
  }
};

// Throws InputError for a photo that cannot be used (empty, unsupported sample
// type, too small), std::invalid_argument for bad options.
PreparedPhoto PreparePhoto(const Photo& photo, const GraticuleOptions& options);

struct GraticuleFit {
  std::array<int, 2> divisions = {10, 8};  // horizontal x vertical
  GraticuleMapping mapping;
  double residual_px = 0.0;        // RMS distance of the measured line points from the fitted lines
  double max_residual_px = 0.0;    // the largest one kept
  int samples_used = 0;            // line measurements in the final fit
  int samples_rejected = 0;        // dropped: washed out, crossed by a trace, outliers
  bool radial_fitted = false;      // whether k1 was kept
  double px_per_div = 0.0;         // at the screen's centre
  double line_width_px = 0.0;      // a grid line's full width at half maximum, photo pixels
  double line_contrast = 0.0;      // a grid line's height above the screen, ink units (0..1)
  bool from_corners_hint = false;  // started from GraticuleOptions::corners_px, not a search
  // Its lines dotted (mostly gaps along them, their dots standing clear of
  // the noise: docs/digitizing.md, "A dotted graticule"): a raster display's
  // graticule, whose traces are drawn on the same raster, each line one of
  // its pixels wide (line_width_px: a display column, which places a
  // trace's step no finer).
  bool dotted = false;
  double elapsed_ms = 0.0;  // time spent finding and fitting
};

// Finds the `divisions` grid (horizontal x vertical), or starts from the
// corners hint when options.corners_px is set. Throws InputError naming the
// photo when no such lattice is found or the fit is worse than
// max_residual_px (without a hint, the message ends by naming the
// `graticule_corners` hint), or a hinted corner lies outside the photo.
GraticuleFit FindGraticule(const PreparedPhoto& photo, std::array<int, 2> divisions,
                           const GraticuleOptions& options);

// ---------------------------------------------------------------------------
// The traces

// One trace the manifest names on this photo.
struct TraceRequest {
  std::string name;        // e.g. "right", "left", "contact"
  TraceSettings settings;  // band_div, time base, volts/div; `impact` marks a contact step
  // A calibration's trace runs one way from its release (t = 0) until the
  // bar passes equilibrium, a quarter period later: the cell's output is
  // monotone in the displacement, so the trace's height never turns back
  // there. A reading that turns back by more than half a division before
  // this time (s) is read again with its course sought one way
  // (docs/digitizing.md, "A calibration's trace runs one way"). 0: not a
  // one-way trace.
  double one_way_until_s = 0.0;
};

struct DigitizedTrace {
  std::string name;
  TraceSettings settings;
  Trace trace;                          // time_s (increasing), volts, sigma_volts
  std::vector<double> confidence;       // per sample, 0..1
  std::vector<cv::Point2d> centre_px;   // where each sample's centre was measured in the photo
  std::vector<cv::Point2d> screen_div;  // and where that is on the screen
  double coverage = 0.0;                // fraction of the sweep [0, nx] with samples
  double width_px = 0.0;                // the trace's typical full width at half maximum
  double height = 0.0;                  // its typical height above the screen, ink units
  double noise_px = 0.0;                // robust scatter of the centre about its neighbours
  // s^2 of the trace's exposure about its path (spot and blur), measured from
  // its width against writing speed; the curvature pull s^2 kappa / 2 it
  // causes is taken out of screen_div and the trace (0: not measured).
  double spread_px2 = 0.0;
  double spread_sigma_px2 = 0.0;  // its one-sigma
  int outliers = 0;               // samples dropped as outliers
  bool from_points_hint = false;  // the tracking followed settings.points_px
  // Stretches of the sweep, [from, to] divisions, whose samples lay on a hand
  // mark and were dropped (docs/digitizing.md, "Hand marks").
  std::vector<std::array<double, 2>> mark_stretches_div;
};

// Throws InputError naming the photo and the trace when a trace is not found
// in its band (coverage below min_coverage; without a points hint the
// message ends by naming the `points` hint) or a hinted point lies off its
// band, std::invalid_argument for bad options or settings. A trace's
// settings.points_px (photo pixels) make its tracking pass through them. Bands may overlap: contact
// (step) traces are taken first and what they claim is not given to the others.
std::vector<DigitizedTrace> ExtractTraces(const PreparedPhoto& photo, const GraticuleFit& graticule,
                                          const std::vector<TraceRequest>& requests,
                                          const TraceOptions& options);

// ---------------------------------------------------------------------------
// The contact pulse

// Where a contact edge was found in the photo.
struct PulseEdgeInPhoto {
  cv::Point2d centre_px;    // the half-height crossing in the photo
  bool from_image = false;  // measured in the photo (the stroke, the levels' ends), else put
                            // between the last samples of each level
};

// A contact pulse read from a photo: the pulse (its edges' times and its
// width, with their sigmas) and where its edges lie in the photo.
struct ContactPulseFit {
  ContactPulse pulse;
  PulseEdgeInPhoto rise, fall;
};

// The first complete pulse of a contact (step) trace: its levels from the
// digitized samples, its edges measured across the faint vertical strokes
// the beam writes between them. Returns nullopt when the trace shows no
// complete pulse (no two levels, or an edge off the screen).
std::optional<ContactPulseFit> MeasurePulse(const PreparedPhoto& photo,
                                            const GraticuleFit& graticule,
                                            const DigitizedTrace& trace);

// ---------------------------------------------------------------------------
// All stages

struct DigitizeResult {
  // false: the photo was not read to the end. `failed_at` (the photo, and the
  // manifest key a user can fix where there is one) and `reason` say why; the
  // graticule stays when it was found (`graticule_found`), the traces and
  // pulses are then empty.
  bool ok = true;
  InputLocation failed_at;
  std::string reason;
  bool graticule_found = false;
  GraticuleFit graticule;
  std::vector<DigitizedTrace> traces;                  // in the order requested
  std::vector<std::optional<ContactPulseFit>> pulses;  // one per trace; set for contact traces
  // What was taken for hand marks (pencil, ink, labels) on the screen and
  // kept from the traces: each mark's outline, photo pixels.
  std::vector<std::vector<cv::Point>> mark_outlines_px;
  double prepare_ms = 0.0, graticule_ms = 0.0, traces_ms = 0.0, pulse_ms = 0.0;

  double ProcessingMs() const { return prepare_ms + graticule_ms + traces_ms + pulse_ms; }
  // "FILE: KEY: reason", as an InputError names it; empty when ok.
  std::string Failure() const;
};

// Runs PreparePhoto, FindGraticule, ExtractTraces and, for traces with an
// `impact` (contact traces), MeasurePulse; a stage's refusal of the photo
// ends the run as a result with !ok. Throws std::invalid_argument for bad
// options.
DigitizeResult DigitizePhoto(const Photo& photo, std::array<int, 2> divisions,
                             const std::vector<TraceRequest>& requests,
                             const DigitizeOptions& options);

// The manual hints a digitized photo used, as the manifest names them:
// "graticule_corners, left.points" (empty: none).
std::string HintsUsed(const DigitizeResult& result);

// The traces a manifest names on a run's or a calibration's photo: those
// without a `csv` (which come from a digital scope instead).
std::vector<TraceRequest> TraceRequestsOf(const Run& run);
std::vector<TraceRequest> TraceRequestsOf(const Calibration& calibration);

struct OverlayOptions {
  // Widest overlay, pixels: a wider photo is drawn shrunk by the smallest
  // whole factor that fits (2000 px into 1200 gives 1000), marks and text
  // scaled alike (a report's page needs no more, and drawing small is cheap);
  // the insets still show the photo's own pixels. 0: the photo's own size.
  int max_width_px = 0;

  bool Check(std::string* error) const;
};

// The photo (8-bit BGR) with the fitted graticule, the bands, the traces'
// samples (coloured by confidence) and the contact pulse's edges drawn on it,
// a legend, and magnified insets of the pulse's edges.
cv::Mat DrawOverlay(const Photo& photo, const DigitizeResult& result,
                    const OverlayOptions& options = {});

// Writes `image` (PNG, JPEG by extension); throws InputError naming the file.
void WriteImage(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace impactlab
