// Synthetic oscillograph photos with exact ground truth (docs/rendering.md).
//
// No photo of the 1969 experiment survives, so impactlab draws its own: what a
// scope camera (Polaroid print, later scanned) or a phone would have recorded of
// a dual-beam oscilloscope screen (Tektronix 555 era, P31 green phosphor)
// showing given signals. Besides the image, the renderer returns where every
// trace's beam centre line lies in the image, to a small fraction of a pixel,
// and the exact geometric mapping it used, so a digitizer can be tested against
// them.
//
// Conventions. Screen positions are in graticule divisions (session-format.md):
// x from the left edge of the graticule, y from its centre, up positive; the
// graticule spans x in [0, nx] and y in [-ny/2, ny/2] for divisions {nx, ny}.
// Image positions are in pixels, x to the right, y down, with pixel centres at
// integer coordinates (OpenCV's convention: pixel (col, row) covers
// [col - 0.5, col + 0.5] x [row - 0.5, row + 0.5]).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "io/session.h"

namespace impactlab {

// How a beam shared by several traces is switched between them.
enum class BeamMode {
  kContinuous,  // the trace is drawn without gaps
  kChopped,     // dashes alternating between the chopped traces with the same `beam`
  kAlternate,   // alternate sweeps: on a single-sweep photo each trace looks continuous
};

// One signal as the scope shows it. The beam follows the straight segments
// between consecutive samples on screen: x_div = t0_div + t / time_per_div,
// y_div = zero_div + volts / volts_per_div.
struct ScreenTrace {
  std::string name;            // e.g. "right", "left", "contact", "calibration"
  std::vector<double> time_s;  // non-decreasing sample times
  std::vector<double> volts;   // one value per sample
  TraceSettings settings;      // time_per_div, volts_per_div, zero_div, t0_div are used
  BeamMode mode = BeamMode::kContinuous;
  int beam = 0;             // chopped traces with the same beam index share the chopper
  double brightness = 1.0;  // the beam's intensity control: exposure relative to 1, > 0
};

struct OscillographScene {
  std::array<int, 2> divisions = {10, 8};  // graticule divisions, horizontal x vertical
  std::vector<ScreenTrace> traces;
};

enum class PhotoStyle {
  kClean,     // straight, sharp, green phosphor on a dark screen, little noise
  kPolaroid,  // scanned grey or sepia scope-camera print: border, tilt, grain, dust, scratches
  kPhone,     // colour phone photo at an angle: perspective, barrel, vignetting, glare, JPEG
  kNegative,  // dark traces on a light ground (a scanned negative)
  kLowres,    // small, blurred, heavily JPEG-compressed
  // Domain randomisation: every factor of the look (camera, light, film or
  // sensor, graticule, surround, dirt and hand marks, size, bit depth, polarity,
  // JPEG) drawn per seed from wide ranges (docs/rendering.md).
  kRandomised,
  // A phone photo of a digital scope's screen: a dotted graticule on part of
  // an LCD, coloured pixelated waveforms, on-screen text and markers
  // (render/digital_screen.h).
  kDigital,
};

// "clean", "polaroid", "phone", "negative", "lowres", "randomised", "digital".
std::string_view PhotoStyleName(PhotoStyle style);
std::optional<PhotoStyle> ParsePhotoStyle(std::string_view name);

struct RenderOptions {
  PhotoStyle style = PhotoStyle::kClean;
  int width_px = 0;          // image width, 200..8000; 0: the style's (2000, lowres 1000)
  std::uint64_t seed = 1;    // every random choice follows from it (std::mt19937_64)
  bool sixteen_bit = false;  // CV_16U samples instead of CV_8U (randomised: or as drawn)
  bool grey = false;         // one channel instead of BGR (randomised: or as drawn)
  // Randomised style: what happened to the photo after it was taken (marks
  // about its traces, tape, a quarter reproduced in print and scanned), drawn
  // from a stream of its own. Off, a seed's photo is the same but for them.
  bool handling = true;

  // Style overrides; unset values are drawn from the style's range with the seed.
  std::optional<double> rotation_deg;  // screen rotation in the photo, counter-clockwise, |.| <= 15
  std::optional<double> tilt_deg;      // camera axis off the screen normal (perspective), 0..35
  std::optional<double> barrel_k1;     // radial distortion at the half diagonal (< 0: barrel)
  std::optional<double> blur_px;       // optical blur, Gaussian sigma in image pixels
  std::optional<int> jpeg_quality;     // 1..100, 0: no JPEG

  // The beam on the screen.
  double beam_fwhm_div = 0.02;  // full width at half maximum of the beam's core
  double chop_dash_div = 0.2;   // length of one chopper slot along the sweep
  double chop_duty = 0.75;      // fraction of its slot a chopped trace is unblanked
  double chop_phase_div = 0.0;  // where the chopper's slots start along the sweep, divisions

  // True when every field is in range; otherwise `error` says which is not.
  bool Check(std::string* error) const;
};

// Where the screen lands in the photo. A screen point goes through the
// homography to an undistorted image point q, then radial distortion moves it:
// p = c + (q - c) * (1 + k1 * |q - c|^2 / r^2).
struct CameraMapping {
  cv::Matx33d homography = cv::Matx33d::eye();  // undistorted pixels from (x_div, y_div, 1)
  double radial_k1 = 0.0;                       // k1 above; < 0 is barrel distortion
  cv::Point2d distortion_centre_px;             // c above
  double distortion_radius_px = 1.0;            // r above: the image's half diagonal

  cv::Point2d ImageFromScreen(cv::Point2d screen_div) const;
  // The inverse (Newton on the radial term), exact to about 1e-9 px.
  cv::Point2d ScreenFromImage(cv::Point2d image_px) const;
};

// Where one trace was drawn: the beam centre line at every signal sample whose
// screen position lies on the graticule (x in [0, nx], y in [-ny/2, ny/2]).
// Between samples the beam runs straight on the screen.
struct TraceTruth {
  std::string name;
  std::vector<double> time_s;           // the sample times
  std::vector<cv::Point2d> screen_div;  // the samples' screen positions
  std::vector<cv::Point2d> centre_px;   // ImageFromScreen(screen_div)
  std::vector<bool> drawn;              // false where the chopper blanks the beam
};

// One factor of a photo's look as its style drew it, for benchmarks that ask
// which factor breaks what: a number (`category` empty) or a category.
struct LookFactor {
  std::string name;      // e.g. "blur_px", "polarity"
  double value = 0.0;    // numbers, in the unit the name says
  std::string category;  // categories, e.g. "negative"; empty for numbers
};

struct RenderedPhoto {
  cv::Mat image;                   // CV_8UC3 / CV_16UC3 (BGR) or CV_8UC1 / CV_16UC1 (grey)
  std::vector<TraceTruth> traces;  // one per scene trace, in the scene's order
  CameraMapping mapping;           // the exact mapping the image was drawn with
  int jpeg_quality = 0;            // the JPEG round trip the image went through; 0: none
  std::vector<LookFactor> look;    // the randomised style's drawn factors; empty for the others

  cv::Point2d ImageFromScreen(cv::Point2d screen_div) const {
    return mapping.ImageFromScreen(screen_div);
  }
};

// Draws the photo. Deterministic: the same scene and options give the same
// bytes. Throws std::invalid_argument when the options fail Check() or the
// scene is malformed (sizes differ, times decrease, non-finite values, zero
// time_per_div or volts_per_div, divisions < 1).
RenderedPhoto RenderOscillograph(const OscillographScene& scene, const RenderOptions& options);

}  // namespace impactlab
