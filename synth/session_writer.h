// The files of a synthetic session (docs/synth.md): the folder, each run's CSV
// traces and photos, and session.toml. Writes what it is given and nothing
// else. Part of synth/session_generator.cpp's plan -> simulate -> write.
#pragma once

#include <filesystem>

#include "synth/manifest_writer.h"
#include "synth/session_photos.h"
#include "synth/session_plan.h"
#include "synth/session_simulation.h"

namespace impactlab {

// Creates `folder` and its calibration/, runs/ and traces/. Throws InputError
// when it exists and is not empty, or cannot be created.
void CreateSessionFolder(const std::filesystem::path& folder);

// A CSV run's traces and calibrations, at the plan's file names.
void WriteCsvTraces(const std::filesystem::path& folder, const RunPlan& plan,
                    const SimulatedRun& run);

// JPEG at the photo's quality, else PNG (compression 6) or TIFF by the extension.
void WritePhotos(const std::filesystem::path& folder, const RunPhotos& photos);

// Writes session.toml and removes the subfolders nothing was written to.
void FinishSessionFolder(const std::filesystem::path& folder, const SessionManifest& manifest);

}  // namespace impactlab
