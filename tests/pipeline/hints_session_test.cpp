// Manual hints through `reduce`: a generated session whose manifest gives one
// run's graticule corners and points on its left trace (from the generator's
// truth) reduces as well as without them, the results file says which hints
// the run's photo used, and the hints change the run's fingerprint, so a
// reduce with --reuse measures it afresh.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "pipeline/run_fingerprint.h"
#include "render/oscillograph.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

// The generator's true mapping of a photo (its truth's "mapping").
CameraMapping TrueMapping(const nlohmann::json& photo) {
  CameraMapping m;
  const auto& h = photo["mapping"]["homography"];
  for (int i = 0; i < 9; ++i) m.homography.val[i] = h[i].get<double>();
  m.radial_k1 = photo["mapping"]["radial_k1"];
  m.distortion_centre_px = {photo["mapping"]["distortion_centre_px"][0].get<double>(),
                            photo["mapping"]["distortion_centre_px"][1].get<double>()};
  m.distortion_radius_px = photo["mapping"]["distortion_radius_px"];
  return m;
}

// `line` inserted after the first line of `text` that starts with `after`
// at or beyond `from`.
std::string InsertAfter(const std::string& text, std::size_t from, const std::string& after,
                        const std::string& line) {
  const std::size_t at = text.find("\n" + after, from);
  REQUIRE(at != std::string::npos);
  const std::size_t end = text.find('\n', at + 1);
  return text.substr(0, end + 1) + line + "\n" + text.substr(end + 1);
}

}  // namespace

TEST_CASE("hints_session: a session with hints reduces and its results say which were used") {
  testing::TempDir dir;
  SynthOptions synth;
  synth.preset = "quick";
  synth.style = PhotoStyle::kClean;
  synth.seed = 5;
  const SynthSummary summary = GenerateSession(dir.path() / "s", synth);
  const Session plain = ReadManifest(dir.path() / "s").session;

  // The first run's corners and three points of its left trace, from the truth.
  const nlohmann::json& truth = summary.truth["runs"][0];
  const std::string id = truth["id"];
  const CameraMapping mapping = TrueMapping(truth["photo"]);
  std::string corners = "graticule_corners = [";
  const cv::Point2d screen[4] = {{0.0, 4.0}, {10.0, 4.0}, {10.0, -4.0}, {0.0, -4.0}};
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d p = mapping.ImageFromScreen(screen[i]);
    corners += fmt::format("{}[{:.1f}, {:.1f}]", i ? ", " : "", p.x, p.y);
  }
  corners += "]";
  std::string points = "points = [";
  for (const auto& trace : truth["photo"]["traces"]) {
    if (trace["name"] != "left") continue;
    const auto& samples = trace["points_t_x_y_px"];
    for (int k = 1; k <= 3; ++k) {
      const auto& s = samples[k * samples.size() / 4];
      points += fmt::format("{}[{:.1f}, {:.1f}]", k > 1 ? ", " : "", s[1].get<double>(),
                            s[2].get<double>());
    }
  }
  points += "]";
  const std::filesystem::path manifest = dir.path() / "s" / "session.toml";
  std::stringstream text;
  text << std::ifstream(manifest).rdbuf();
  const std::size_t run_at = text.str().find(fmt::format("id = \"{}\"", id));
  REQUIRE(run_at != std::string::npos);
  std::string hinted_text = InsertAfter(text.str(), run_at, "photo = ", corners);
  hinted_text = InsertAfter(hinted_text, run_at, "[run.traces.left]", points);
  std::ofstream(manifest) << hinted_text;
  const ManifestReadResult read = ReadManifest(dir.path() / "s");
  CHECK(read.warnings.empty());
  const Session& hinted = read.session;
  REQUIRE(hinted.rejected.empty());
  REQUIRE(hinted.runs[0].id == id);
  REQUIRE(hinted.runs[0].graticule_corners_px.has_value());
  REQUIRE(hinted.runs[0].traces.at("left").points_px.size() == 3);

  // The hints change the hinted run's fingerprint, and only its.
  CHECK(RunFingerprint(hinted.runs[0], hinted, {}) != RunFingerprint(plain.runs[0], plain, {}));
  CHECK(RunFingerprint(hinted.runs[1], hinted, {}) == RunFingerprint(plain.runs[1], plain, {}));

  ReduceOptions options;
  options.jobs = 2;
  WriteResults(ReduceSession(hinted, options), dir.path() / "r.h5");
  const SessionResult result = ReadResults(dir.path() / "r.h5");
  for (const RunResult& run : result.runs) {
    INFO(run.id << ": " << run.Status());
    REQUIRE(run.ok);
    REQUIRE(run.measured.overlays.size() == 1);
    CHECK(run.measured.overlays[0].hints == (run.id == id ? "graticule_corners, left.points" : ""));
    // As well measured with the hints as the tolerances of photo_session ask.
    const nlohmann::json* run_truth = nullptr;
    for (const auto& t : summary.truth["runs"]) {
      if (t["id"] == run.id) run_truth = &t;
    }
    REQUIRE(run_truth != nullptr);
    const double x0 = (*run_truth)["initial_displacement"];
    const auto& xmax = (*run_truth)["rebounds"]["xmax"];
    CHECK(run.measured.xmax.size() >= 3);
    for (std::size_t n = 0; n < run.measured.xmax.size() && n < xmax.size(); ++n) {
      CHECK(100.0 * std::abs(run.measured.xmax[n] - xmax[n].get<double>()) / x0 < 0.2);
    }
  }
}

}  // namespace impactlab
