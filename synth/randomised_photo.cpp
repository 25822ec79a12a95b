#include "synth/randomised_photo.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace impactlab {

namespace {

double Uniform(std::mt19937_64& random, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(random);
}

double LogUniform(std::mt19937_64& random, double lo, double hi) {
  return std::exp(Uniform(random, std::log(lo), std::log(hi)));
}

// The screen's usable height: 8 divisions less a margin, so that no trace
// touches the graticule's edge.
constexpr double kScreenTopDiv = 3.9;
constexpr double kUsableDiv = 7.8;

}  // namespace

RunBands DrawRunBands(std::mt19937_64& random) {
  double right_h = Uniform(random, 1.5, 3.6), left_h = Uniform(random, 1.5, 3.6);
  double contact_h = Uniform(random, 0.6, 1.6);
  double gap_1 = Uniform(random, 0.0, 0.6), gap_2 = Uniform(random, 0.0, 0.6);
  const double total = right_h + left_h + contact_h + gap_1 + gap_2;
  if (total > kUsableDiv) {
    const double shrink = kUsableDiv / total;
    for (double* v : {&right_h, &left_h, &contact_h, &gap_1, &gap_2}) *v *= shrink;
  }
  const double used = right_h + left_h + contact_h + gap_1 + gap_2;
  RunBands bands;
  const int contact_index = std::uniform_int_distribution<int>(0, 2)(random);
  bands.contact_position = contact_index == 0 ? "above" : contact_index == 1 ? "between" : "below";
  const bool right_on_top = Uniform(random, 0.0, 1.0) < 0.5;
  std::vector<std::pair<std::array<double, 2>*, double>> order = {
      {right_on_top ? &bands.right : &bands.left, right_on_top ? right_h : left_h},
      {right_on_top ? &bands.left : &bands.right, right_on_top ? left_h : right_h}};
  order.insert(order.begin() + contact_index, {&bands.contact, contact_h});
  double top = kScreenTopDiv - Uniform(random, 0.0, kUsableDiv - used);
  const double gaps[2] = {gap_1, gap_2};
  for (std::size_t i = 0; i < order.size(); ++i) {
    *order[i].first = {top - order[i].second, top};
    if (i < 2) top -= order[i].second + gaps[i];
  }
  bands.contact_step_fraction = Uniform(random, 0.4, 0.85);
  return bands;
}

std::array<double, 2> DrawCalibrationBand(std::mt19937_64& random) {
  const double height = Uniform(random, 3.0, kUsableDiv);
  const double top = kScreenTopDiv - Uniform(random, 0.0, kUsableDiv - height);
  return {top - height, top};
}

BeamLook DrawBeamLook(std::mt19937_64& random) {
  BeamLook look;
  look.chop_slot_div = LogUniform(random, 0.005, 0.5);
  look.chop_duty = Uniform(random, 0.2, 1.0);
  look.chop_phase_div = Uniform(random, 0.0, 2.0 * look.chop_slot_div);
  look.beam_fwhm_div = LogUniform(random, 0.01, 0.06);
  look.slow_brightness = LogUniform(random, 0.3, 2.0);
  look.contact_brightness = LogUniform(random, 0.3, 2.0);
  return look;
}

void ApplyBeamLook(const BeamLook& look, RenderOptions& options) {
  options.chop_dash_div = look.chop_slot_div;
  options.chop_duty = look.chop_duty;
  options.chop_phase_div = look.chop_phase_div;
  options.beam_fwhm_div = look.beam_fwhm_div;
}

nlohmann::json LookJson(const RenderedPhoto& photo, const BeamLook& beam, const RunBands* bands,
                        const std::array<int, 2>& divisions) {
  nlohmann::json look = nlohmann::json::object();
  for (const LookFactor& factor : photo.look) {
    if (factor.category.empty()) {
      look[factor.name] = factor.value;
    } else {
      look[factor.name] = factor.category;
    }
  }
  // The scale at the screen's centre: the geometric mean of a division's
  // image length across and along.
  const cv::Point2d centre(divisions[0] / 2.0, 0.0);
  const cv::Point2d c = photo.ImageFromScreen(centre);
  const double across = cv::norm(photo.ImageFromScreen(centre + cv::Point2d(1, 0)) - c);
  const double along = cv::norm(photo.ImageFromScreen(centre + cv::Point2d(0, 1)) - c);
  const double px_per_div = std::sqrt(across * along);
  look["px_per_div"] = px_per_div;
  look["beam_fwhm_div"] = beam.beam_fwhm_div;
  look["beam_fwhm_px"] = beam.beam_fwhm_div * px_per_div;
  look["slow_brightness"] = beam.slow_brightness;
  look["contact_brightness"] = beam.contact_brightness;
  // How much light a line puts across itself, in pixels at a slow trace
  // core's brightness: what a reading has to go on, whatever made the line
  // faint (a dim lamp, a thin line, a small photo). A grid line's is its
  // brightness times its width in this photo's pixels; a slow trace's, its
  // brightness times the beam's width.
  if (look.contains("graticule_brightness") && look.contains("graticule_fwhm_div")) {
    look["graticule_line_px"] = look["graticule_brightness"].get<double>() *
                                look["graticule_fwhm_div"].get<double>() * px_per_div;
  }
  look["beam_line_px"] = beam.slow_brightness * beam.beam_fwhm_div * px_per_div;
  if (bands != nullptr) {
    look["chop_slot_div"] = beam.chop_slot_div;
    look["chop_period_px"] = 2.0 * beam.chop_slot_div * px_per_div;
    look["chop_duty"] = beam.chop_duty;
    look["chop_phase_div"] = beam.chop_phase_div;
    // The longest stretch a trace is blanked: the other trace's slot and the
    // undrawn rest of its own.
    look["chop_gap_div"] = beam.chop_slot_div * (2.0 - beam.chop_duty);
    look["contact_position"] = bands->contact_position;
    look["band_right_div"] = bands->right;
    look["band_left_div"] = bands->left;
    look["band_contact_div"] = bands->contact;
  }
  return look;
}

}  // namespace impactlab
