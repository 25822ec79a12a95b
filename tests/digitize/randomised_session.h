// Randomised sessions as the robustness benchmark generates them, and the
// generator's true mapping read back: for tests that pin down a photo the
// benchmark found.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "digitize/digitize.h"
#include "synth/session_generator.h"

namespace impactlab::testing {

// The benchmark's options for seed `seed`: the quick preset, randomised
// photos (with the photos' handling: marks, tape, prints).
inline SynthOptions RandomisedSynth(std::uint64_t seed) {
  SynthOptions synth;
  synth.preset = "quick";
  synth.style = PhotoStyle::kRandomised;
  synth.seed = seed;
  return synth;
}

// A photo's true mapping from its truth entry's "mapping".
inline GraticuleMapping MappingFromTruth(const nlohmann::json& mapping) {
  GraticuleMapping result;
  for (int i = 0; i < 9; ++i) result.homography.val[i] = mapping["homography"][i].get<double>();
  result.radial_k1 = mapping["radial_k1"].get<double>();
  result.distortion_centre_px = {mapping["distortion_centre_px"][0].get<double>(),
                                 mapping["distortion_centre_px"][1].get<double>()};
  result.distortion_radius_px = mapping["distortion_radius_px"].get<double>();
  return result;
}

// A generated session's run `id`: its manifest entry and its truth (null
// where the session has none).
struct GeneratedRun {
  const Run* run = nullptr;
  const nlohmann::json* truth = nullptr;
};
inline GeneratedRun FindGeneratedRun(const SynthSummary& summary, const std::string& id) {
  GeneratedRun found;
  for (const Run& r : summary.manifest.runs) {
    if (r.id == id) found.run = &r;
  }
  for (const auto& r : summary.truth["runs"]) {
    if (r["id"] == id) found.truth = &r;
  }
  return found;
}

}  // namespace impactlab::testing
