// A simulated run (synth/session_simulation.h) photographed: the run photo and
// the calibration photos, drawn by render/ as a scope camera would take them,
// each with its file name and its truth, ready to be written. Part of
// synth/session_generator.cpp's plan -> simulate -> write.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "synth/session_plan.h"
#include "synth/session_simulation.h"

namespace impactlab {

struct SessionPhoto {
  std::string file;      // relative to the session folder, e.g. "runs/0.405.jpg"
  cv::Mat image;         // as it is to be stored
  int jpeg_quality = 0;  // JPEG at this quality; 0: lossless, PNG or TIFF by the file's extension
  nlohmann::json truth;  // the truth's "photo": file, size, mapping, traces (and look)
};

struct RunPhotos {
  std::vector<std::optional<SessionPhoto>> calibrations;  // as the plan's calibrations
  std::optional<SessionPhoto> run;
};

// Photographs what the plan photographs (nothing for CSV and typed-in runs).
RunPhotos PhotographRun(const RunPlan& plan, const SimulatedRun& run, const SynthOptions& options);

}  // namespace impactlab
