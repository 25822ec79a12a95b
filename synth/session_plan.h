// The plan of a synthetic session (`impactlab synth`, docs/synth.md): which runs
// it holds, in what form, and every random choice the session makes. The
// choices are all drawn here, before anything is simulated, in the order the
// generator has always drawn them, so that a seed writes the same bytes; the
// simulation (synth/session_simulation.h) then follows from the plan alone.
// Part of synth/session_generator.cpp's plan -> simulate -> write.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "synth/experiment.h"
#include "synth/photocell.h"
#include "synth/randomised_photo.h"
#include "synth/session_generator.h"

namespace impactlab {

// The thesis's apparatus, as every synthetic session has it.
inline constexpr double kSynthPendulumLength = 22.0;  // in
inline constexpr double kSynthGravity = 385.644;      // in/s^2
inline constexpr double kSynthWeight = 2.23;          // lbf, one bar
inline constexpr double kSynthStiffness = 4.6e5;      // lbf/in, about the thesis's K avg
inline constexpr int kSynthShownImpact = 2;           // the thesis showed the second impact

enum class RunForm {
  kPhoto,  // a run photo and a calibration photo per cell
  kCsv,    // a digital scope's CSV traces, calibrations too
  kTyped,  // maxima and contact time typed in by hand
};

const char* RunFormName(RunForm form);  // "photo", "csv" or "typed-in"

// One photo's file and its own draws.
struct PhotoPlan {
  std::string stem;  // relative to the session folder, without the extension the photo picks
  std::uint64_t render_seed = 0;
  std::optional<BeamLook> look;   // the randomised style: the beams' look for this photo
  bool tiff_if_lossless = false;  // the randomised style stores one lossless photo in four as TIFF
};

// A cell's calibration: one bar released alone from its X0.
struct CalibrationPlan {
  std::string id;                                // "R-<run>" or "L-<run>"
  std::string cell;                              // "right" or "left"
  std::uint64_t noise_seed = 0;                  // the trace's electronic noise
  std::array<double, 2> band_div = {-3.6, 3.6};  // where the trace sits on the screen
  std::optional<PhotoPlan> photo;                // photo runs
  std::optional<std::string> csv_file;           // CSV runs, relative to the session folder
};

struct RunPlan {
  std::string id;
  RunForm form = RunForm::kPhoto;
  double zeta = 0.0;             // the preset's damping ratio (truth)
  ExperimentOptions experiment;  // X0, the drawn asymmetries and the contact element
  PhotocellOptions photocells;   // both cells' range and nonlinearity
  std::uint64_t right_cell_seed = 0, left_cell_seed = 0;
  double trace_noise = 0.0;  // electronic noise on each trace, fraction of its span
  std::vector<CalibrationPlan> calibrations;  // right, then left; none for typed-in maxima
  std::uint64_t right_noise_seed = 0, left_noise_seed = 0;  // the run's slow traces
  RunBands bands;  // where the run's traces sit on the screen
  // The randomised style: where the contact step's low level sits in its band,
  // as a fraction of the band's height from its bottom; none: the fixed 2 V/div.
  std::optional<double> contact_low_position;
  std::optional<PhotoPlan> photo;  // photo runs
  // CSV runs: "right", "left" and "contact" traces' files, relative to the session folder.
  std::map<std::string, std::string> csv_files;
};

struct SessionPlan {
  SynthOptions options;
  std::vector<RunPlan> runs;
};

// Every draw follows from options.seed. Expects options that pass Check().
SessionPlan PlanSession(const SynthOptions& options);

}  // namespace impactlab
