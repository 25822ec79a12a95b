// Randomised sessions as the robustness benchmark generates them, and the
// generator's true mapping read back: for tests that pin down a photo the
// benchmark found.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "digitize/digitize.h"
#include "synth/session_generator.h"

namespace impactlab::testing {

// The generator's options for a preset, a photo style and a seed.
inline SynthOptions SynthOf(const std::string& preset, PhotoStyle style, std::uint64_t seed) {
  SynthOptions synth;
  synth.preset = preset;
  synth.style = style;
  synth.seed = seed;
  return synth;
}

// The benchmark's options for seed `seed`: the quick preset, randomised
// photos (with the photos' handling: marks, tape, prints).
inline SynthOptions RandomisedSynth(std::uint64_t seed) {
  return SynthOf("quick", PhotoStyle::kRandomised, seed);
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

// A generated session's run `id` digitized from its photo as the reducer
// asks (its manifest's traces), with its truth. Throws std::invalid_argument
// when the session has no such run.
struct DigitizedRun {
  std::vector<TraceRequest> requests;
  DigitizeResult result;
  const nlohmann::json* truth = nullptr;

  // The index of the trace named `name` in `requests` (and the result's traces).
  std::size_t IndexOf(const std::string& name) const {
    for (std::size_t k = 0; k < requests.size(); ++k) {
      if (requests[k].name == name) return k;
    }
    throw std::invalid_argument("no trace named " + name);
  }
};
inline DigitizedRun DigitizeGeneratedRun(const std::filesystem::path& folder,
                                         const SynthSummary& summary, const std::string& id) {
  const Run* run = nullptr;
  for (const Run& r : summary.manifest.runs) {
    if (r.id == id) run = &r;
  }
  DigitizedRun out;
  for (const auto& r : summary.truth["runs"]) {
    if (r["id"] == id) out.truth = &r;
  }
  if (run == nullptr || out.truth == nullptr) throw std::invalid_argument("no run " + id);
  out.requests = TraceRequestsOf(*run);
  out.result = DigitizePhoto(LoadPhoto(folder / (*out.truth)["photo"]["file"].get<std::string>()),
                             {10, 8}, out.requests, {});
  return out;
}

}  // namespace impactlab::testing
