// Photographic styles (internal to render/): how the camera, the light, the
// film or sensor and the print or file turn the scope face into a photo. Each
// style is a StyleLook drawn at random, within the style's ranges, from the
// seed; RenderOptions' overrides replace the drawn values.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "render/camera.h"
#include "render/oscillograph.h"
#include "render/screen.h"

namespace impactlab::render {

// A hand mark tied to a trace (randomised style's handling): what an
// experimenter drew about a trace on the print.
enum class TraceMark {
  kAlong,   // a stroke beside a trace, following its course (underlining it)
  kAcross,  // a stroke across a trace (a tick at a time, a crossing-out)
  kRing,    // a ring round a point of a trace (a peak, a step)
  kArrow,   // an arrow pointing at a trace
  kLabel,   // a word or number written beside a trace
};

// The photo as a figure reproduced in a printed report and scanned
// (randomised style's handling): the photo's tones become ink coverage,
// screened as amplitude-modulated round dots, dark ink on toned paper.
struct PrintLook {
  bool halftone = false;                     // false: the photo itself
  cv::Vec3f paper_bgr{0.95f, 0.95f, 0.95f};  // the report's paper
  double paper_tone = 0.0;                   // 0 white .. 1 cream, as drawn
  cv::Vec3f ink_bgr{0.1f, 0.1f, 0.1f};       // full ink on it
  double period_px = 4.0;                    // the screen's dot period at the scan's size
  double angle_deg = 45.0;                   // the screen's angle on the page
  double floor_of_grid = 0.4;  // tone below which no ink: this far from the ground to the grid
  double grid_coverage = 0.8;  // the ink the grid lines' tone prints with (traces: more)
  double ink_spread = 0.0;     // dot gain: every dot's radius grows, fraction of period
  double paper_mottle = 0.0;   // the paper's tone varies smoothly by this, sigma
  double scan_blur_px = 0.7;   // the scanner's blur, Gaussian sigma
  double scan_noise = 0.005;   // the scanner's noise, sigma at full scale
  double skew_deg = 0.0;       // the page's skew on the scanner (in the camera's roll)
  int figure_number = 1;       // the caption's
};

// What happened to the photo after it was taken (randomised style, drawn
// from a stream of its own: RenderOptions::handling): marks about its
// traces, tape, reproduction in print.
struct HandlingLook {
  std::vector<TraceMark> trace_marks;  // drawn with StyleLook's pencil
  double mark_width_px = 5.0;          // the pencil's mean stroke at 2000 px, scaled with the photo
  int tape = 0;                        // pieces of translucent tape over a corner or edge
  float tape_opacity = 0.4f;           // how much of what is under it the tape hides
  cv::Vec3f tape_bgr{0.86f, 0.95f, 0.97f};  // its colour, display values
  PrintLook print;
};

enum class Development {
  kColour,      // colour sensor or film
  kMonochrome,  // black-and-white print, neutral or sepia-toned
  kNegative,    // black-and-white negative: dark traces on a light ground
};

struct StyleLook {
  int width_px = 2000;
  CameraPose pose;
  std::vector<cv::Point2d> framed_outline_div;  // the screen-space outline the camera frames
  ScreenLook screen;
  SurroundLook surround;

  // Light in the scene, multiplying the exposure.
  double vignetting = 0.0;        // cos^4-like falloff: 1 / (1 + v r^2)^2, r = 1 at half diagonal
  double light_gradient = 0.0;    // linear tilt of the light across the frame, fraction
  double light_angle_rad = 0.0;   // its direction
  double light_unevenness = 0.0;  // smooth random light factors across the frame, sigma
  double glare = 0.0;             // a reflection on the glass: peak exposure added
  cv::Point2d glare_centre_div;   // its centre on the screen
  double glare_radius_div = 1.5;  // its Gaussian sigma

  double blur_px = 0.0;        // lens and focus: Gaussian sigma in image pixels
  double exposure_gain = 3.0;  // exposure scale before the tone curve's shoulder
  double tone_gamma = 0.6;     // the tone curve's power: (1 - exp(-gain E))^gamma

  Development development = Development::kColour;
  cv::Vec3f paper_bgr{1.0f, 1.0f, 1.0f};  // monochrome and negative: the lightest tone
  float black_level = 0.0f;               // the darkest tone, a fraction of white
  double grain = 0.0;                     // film grain, sigma relative to full scale
  double sensor_noise = 0.0;              // shot noise sigma at full scale
  double chroma_noise = 0.0;              // independent noise per colour channel, sigma
  double sharpen = 0.0;                   // a phone's unsharp mask amount
  int dust_specks = 0;
  int scratches = 0;
  int hairs = 0;
  int scratch_width_px = 1;                  // line width of a scratch
  int hair_width_px = 1;                     // line width of a hair
  double hair_length_lo = 0.05;              // a hair's length, fraction of the photo's width:
  double hair_length_hi = 0.15;              //   drawn uniformly between these
  int hand_marks = 0;                        // grease-pencil or ink marks: words, arrows, rings
  cv::Vec3f mark_bgr{0.15f, 0.15f, 0.85f};   // their colour, display values
  std::string mark_colour = "red";           // its name
  bool print_border = false;                 // a print with a white border on a scanner bed
  cv::Rect2d print_image_div;                // the print's image area, screen divisions
  double print_border_div = 0.0;             // the white border's width
  int jpeg_quality = 0;                      // 0: no JPEG
  bool grey = false;                         // one channel (the options', or drawn)
  bool sixteen_bit = false;                  // 16-bit samples where there is no JPEG
  std::optional<double> graticule_fwhm_div;  // unset: the line is 0.75 times the beam's width
  std::string surround_kind;                 // randomised: "hood", "panel", "print" or "cropped"
  HandlingLook handling;                     // randomised, RenderOptions::handling
};

// `handling_random`: the randomised style's handling stream (HandlingStream),
// drawn from when options.handling is set.
StyleLook DrawStyleLook(const RenderOptions& options, const ScreenLayout& layout,
                        std::mt19937_64& random, std::mt19937_64& handling_random);

// The randomised style's draws (randomised_style.cpp): every factor from wide
// ranges. Sets what DrawStyleLook's common code does not.
void DrawRandomised(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random);

// The randomised style's handling (handling.cpp), from `random`, a stream
// apart from the look's: trace marks, the pencil, tape, and in a quarter of
// the photos reproduction in print, which reframes the look (the figure
// cropped to the graticule on a page, the scope's surround masked out).
void DrawHandling(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random);

// The handling's stream for a photo of seed `seed`.
std::mt19937_64 HandlingStream(std::uint64_t seed);

// What the randomised style drew, after the options' overrides, as named
// factors (RenderedPhoto::look); `image` is the finished photo.
std::vector<LookFactor> DescribeLook(const StyleLook& look, const cv::Mat& image);

// The photo's size: 4:3 landscape, like scope-camera prints and phone photos.
inline cv::Size PhotoSize(const StyleLook& look) {
  return {look.width_px, static_cast<int>(std::lround(look.width_px * 0.75))};
}

// Dust, scratches and hairs on the print or negative, as coverage masks
// (CV_8UC1, 255 = opaque); empty when the style has none. Dark dirt lies on
// top; light dirt is where the emulsion is missing; tape (HandlingLook's
// colour and opacity) and hand marks (grease pencil, ink) lie on top of
// everything, the marks in StyleLook::mark_bgr.
struct Dirt {
  cv::Mat dark;
  cv::Mat light;
  cv::Mat tape;
  cv::Mat mark;
};
Dirt DrawDirt(const StyleLook& look, cv::Size size, std::mt19937_64& random);

// `count` hand marks (randomised_style.cpp): words and numbers written on the
// print or the scope's glass, arrows, rings round a feature, underlines, in
// strokes a few pixels wide (times `width_scale`); a coverage mask like Dirt's.
cv::Mat DrawHandMarks(int count, cv::Size size, double width_scale, std::mt19937_64& random);

// How far from its trace's centre a stroke along it runs, at most, divisions
// (beyond half its own width and the beam's).
constexpr double kMarkAlongTraceMaxGapDiv = 0.25;

// The handling's trace marks (handling.cpp), about `traces` (centre_px filled
// in) at `px_per_div`, the photo's scale: a coverage mask like Dirt's, empty
// without marks. A mark that needs a trace and finds none is not drawn.
cv::Mat DrawTraceMarks(const HandlingLook& handling, cv::Size size,
                       const std::vector<TraceTruth>& traces, double px_per_div,
                       std::mt19937_64& random);

// `count` pieces of translucent tape over a corner or an edge, with ragged
// torn ends (handling.cpp); a coverage mask like Dirt's.
cv::Mat DrawTape(int count, cv::Size size, std::mt19937_64& random);

// The print reproduction (print.cpp): `photo` (8-bit grey, the photograph as
// developed, without tape and marks) printed with look.handling.print: its
// tones set so that the grid, whose lines pass through `grid_px`, prints;
// screened; a caption under the figure centred at `caption_px`, its baseline
// along `caption_along_px`, `caption_height_px` high; `dirt`'s tape and marks
// laid on the printed page; scanned: blur, noise, and the file's channels and
// depth (look.grey, look.sixteen_bit; 8 bits when look.jpeg_quality > 0).
// Changes no geometry.
cv::Mat ReproduceInPrint(const StyleLook& look, const cv::Mat& photo,
                         const std::vector<cv::Point2d>& grid_px, cv::Point2d caption_px,
                         cv::Point2d caption_along_px, double caption_height_px, const Dirt& dirt,
                         std::mt19937_64& random);

// The ink coverage (0..1) a continuous tone (CV_32FC1, 0..1, in place) prints
// as on `print`'s screen: each pixel inked where it lies within the round dot
// whose area, in its cell of the screen, is the tone averaged over about a
// cell, the dot's radius grown by the ink's spread. Anti-aliased over a pixel.
void ScreenHalftone(const PrintLook& print, cv::Mat& tone);

// The camera's processing and the file: unsharp mask, then the JPEG round trip
// when the style has one, then 16 bits when asked for (a JPEG photo's 8-bit
// values v become 257 v). `image` is 8-bit when the style has JPEG.
void FinishPhoto(const StyleLook& look, cv::Mat& image);

}  // namespace impactlab::render
