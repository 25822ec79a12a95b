// What the randomised style (render/randomised_style.cpp) leaves to the
// session generator, because it belongs to the scope's settings rather than to
// the photo: the chopper's pattern, the beams' width and intensity, and where
// the traces sit on the screen (docs/synth.md, "The randomised style").
// Every draw follows from the generator's own per-photo random stream.
#pragma once

#include <array>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "render/oscillograph.h"

namespace impactlab {

// Where a run photo's three traces sit: bands in screen divisions (y up).
struct RunBands {
  std::array<double, 2> right{0.4, 4.0};
  std::array<double, 2> left{-2.4, 0.0};
  std::array<double, 2> contact{-4.0, -2.5};  // holds the step, -3.875 to -2.675 div
  std::string contact_position = "below";  // "above", "between" or "below" the slow traces
  double contact_step_fraction = 0.0;      // of its band the contact step spans; 0: fixed 2 V/div
};

// The fixed layout of the other styles.
inline RunBands FixedRunBands() { return {}; }

// Any order (contact above, between or below; right above or below left),
// band heights and gaps drawn, all within the 8-division screen.
RunBands DrawRunBands(std::mt19937_64& random);

// A calibration photo's band: [-3.6, 3.6] for the fixed styles; drawn here.
std::array<double, 2> DrawCalibrationBand(std::mt19937_64& random);

// The beams' look on the scope for one photo.
struct BeamLook {
  double chop_slot_div = 0.01;      // one chopped trace's slot; a trace's period is 2 slots
  double chop_duty = 0.75;          // the part of its slot a trace is drawn
  double chop_phase_div = 0.0;      // where the slots start
  double beam_fwhm_div = 0.02;      // the beam's width
  double slow_brightness = 1.0;     // the slow beam's intensity (right and left traces)
  double contact_brightness = 1.0;  // the second beam's intensity (contact, calibration)
};

// Slot 0.005-0.5 div (log-uniform: a trace's dash period from about a pixel to a
// tenth of the screen), duty 0.2-1, any phase, width 0.01-0.06 div,
// intensities 0.3-2.
BeamLook DrawBeamLook(std::mt19937_64& random);

// Sets the render options' beam fields from `look`.
void ApplyBeamLook(const BeamLook& look, RenderOptions& options);

// The truth's "look": the renderer's drawn factors, the beam look, the bands
// (when given) and the photo's scale (pixels per division at the screen's centre).
nlohmann::json LookJson(const RenderedPhoto& photo, const BeamLook& beam, const RunBands* bands,
                        const std::array<int, 2>& divisions);

}  // namespace impactlab
