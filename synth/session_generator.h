// `impactlab synth`: a whole lab session, simulated and photographed, with its
// ground truth (docs/synth.md).
//
// Each run is a simulated experiment (synth/experiment.h) seen through two
// photocells (synth/photocell.h) on a dual-beam oscilloscope: the right and
// left displacement traces chopped on one beam over a slow sweep, the contact
// circuit's step on the second beam's fast delayed sweep at a chosen impact.
// Each cell is calibrated per run by a photo of one bar swinging alone from
// X0 (thesis Chapter III). The folder follows docs/session-format.md; the
// truth file is written outside it.
//
// The generator plans the session (synth/session_plan.h), simulates each run
// (synth/session_simulation.h, synth/session_photos.h) and writes it
// (synth/session_writer.h, synth/manifest_writer.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "render/oscillograph.h"
#include "synth/manifest_writer.h"

namespace impactlab {

// A run written, for SynthOptions::on_progress.
struct SynthProgress {
  std::string run;  // its id
  int photos = 0;   // of this run, its calibrations' included
  std::size_t done = 0, total = 0;
};

struct SynthOptions {
  std::string preset = "thesis";  // "thesis" (8 runs, the thesis's X0) or "quick" (2 small runs)
  PhotoStyle style = PhotoStyle::kPolaroid;
  std::uint64_t seed = 1;  // every random choice follows from it
  int width_px = 0;        // photo width; 0: the preset's (thesis 2000, quick 1000)
  // Randomised style: marks, tape and print reproductions on the photos
  // (RenderOptions::handling); off, the same photos without them.
  bool photo_handling = true;
  // Support-wire forcing with the non-physical heavy wire that reproduces the
  // thesis's anomalies (rebounds exceeding their predecessor, durations a few
  // % short); see SupportWireOptions::kThesisAnomalyMassPerLength.
  bool wire_anomalies = false;
  // The bars' contact element: "kelvin-voigt" (K, C from the preset's zeta) or
  // "poynting-thomson" (K1 = 0.75 K, K2 = 0.5 K, C = 4 zeta sqrt(K M)).
  std::string contact_model = "kelvin-voigt";
  bool csv_run = false;        // add a run (with its calibrations) given as CSV traces
  bool typed_run = false;      // add a run with typed-in maxima (rounded to 0.001)
  double trace_noise = 0.002;  // electronic noise on each trace, fraction of its span
  // Photocell curves: 0 linear, 1 strongly nonlinear (slope varying ~7x), 1.
  double photocell_nonlinearity = 0.6;
  // Called after each run's photos and traces are written (a thesis session
  // takes seconds: the command shows it on a terminal).
  std::function<void(const SynthProgress&)> on_progress;

  bool Check(std::string* error) const;
};

struct SynthSummary {
  int runs = 0;
  int photos = 0;
  double simulate_seconds = 0.0;
  double render_seconds = 0.0;  // all photos, encoding included
  nlohmann::json truth;         // what --truth writes (schema in docs/synth.md)
  SessionManifest manifest;     // what session.toml says
};

// Writes the session into `folder` (created; it must not exist or be empty).
// Throws std::invalid_argument for bad options and InputError for a folder
// that cannot be written.
SynthSummary GenerateSession(const std::filesystem::path& folder, const SynthOptions& options);

}  // namespace impactlab
