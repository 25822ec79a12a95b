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
  bool print_border = false;                 // a print with a white border on a scanner bed
  cv::Rect2d print_image_div;                // the print's image area, screen divisions
  double print_border_div = 0.0;             // the white border's width
  int jpeg_quality = 0;                      // 0: no JPEG
  bool grey = false;                         // one channel (the options', or drawn)
  bool sixteen_bit = false;                  // 16-bit samples where there is no JPEG
  std::optional<double> graticule_fwhm_div;  // unset: the line is 0.75 times the beam's width
  std::string surround_kind;                 // randomised: "hood", "panel", "print" or "cropped"
};

StyleLook DrawStyleLook(const RenderOptions& options, const ScreenLayout& layout,
                        std::mt19937_64& random);

// The randomised style's draws (randomised_style.cpp): every factor from wide
// ranges. Sets what DrawStyleLook's common code does not.
void DrawRandomised(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random);

// What the randomised style drew, after the options' overrides, as named
// factors (RenderedPhoto::look); `image` is the finished photo.
std::vector<LookFactor> DescribeLook(const StyleLook& look, const cv::Mat& image);

// The photo's size: 4:3 landscape, like scope-camera prints and phone photos.
inline cv::Size PhotoSize(const StyleLook& look) {
  return {look.width_px, static_cast<int>(std::lround(look.width_px * 0.75))};
}

// Dust, scratches and hairs on the print or negative, as coverage masks
// (CV_8UC1, 255 = opaque); empty when the style has none. Dark dirt lies on
// top; light dirt is where the emulsion is missing; hand marks (grease pencil,
// ink) lie on top of everything in StyleLook::mark_bgr.
struct Dirt {
  cv::Mat dark;
  cv::Mat light;
  cv::Mat mark;
};
Dirt DrawDirt(const StyleLook& look, cv::Size size, std::mt19937_64& random);

// `count` hand marks (randomised_style.cpp): words and numbers written on the
// print or the scope's glass, arrows, rings round a feature, underlines, in
// strokes a few pixels wide; a coverage mask like Dirt's.
cv::Mat DrawHandMarks(int count, cv::Size size, std::mt19937_64& random);

// The camera's processing and the file: unsharp mask, then the JPEG round trip
// when the style has one, then 16 bits when asked for (a JPEG photo's 8-bit
// values v become 257 v). `image` is 8-bit when the style has JPEG.
void FinishPhoto(const StyleLook& look, cv::Mat& image);

}  // namespace impactlab::render
