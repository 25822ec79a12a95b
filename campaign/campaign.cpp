// Reading a campaign's inputs: results files as they are, session folders
// reduced first (reusing their unchanged runs, as `reduce` does).
#include "campaign/campaign.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <set>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "campaign/campaign_internal.h"
#include "io/atomic_file.h"
#include "io/manifest.h"
#include "pipeline/previous_results.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

std::string NowUtc() {
  return fmt::format(
      "{:%Y-%m-%dT%H:%M:%SZ}",
      fmt::gmtime(std::chrono::system_clock::to_time_t(std::chrono::system_clock::now())));
}

// The input's name for the tables, made unique with " (2)", " (3)", ...
std::string UniqueName(const std::string& base, std::set<std::string>& taken) {
  std::string name = base.empty() ? "session" : base;
  for (int k = 2; taken.contains(name); ++k) name = fmt::format("{} ({})", base, k);
  taken.insert(name);
  return name;
}

// A session folder reduced into options.reduced_folder/<name>.h5, reusing the
// unchanged runs of the file already there.
SessionResult ReduceFolder(const fs::path& folder, const std::string& name,
                           const CampaignOptions& options, std::string* file) {
  const ManifestReadResult manifest = ReadManifest(folder);
  fs::create_directories(options.reduced_folder);
  const fs::path output = options.reduced_folder / (name + ".h5");
  CheckOutputPath(output, folder);  // never into the session, the lab's record
  std::vector<std::string> notes;
  const std::optional<SessionResult> previous = PreviousResults(output, manifest.session, &notes);
  ReduceOptions reduce;
  reduce.producer = options.producer;
  reduce.jobs = options.jobs;
  if (previous) reduce.previous = &*previous;
  SessionResult result = ReduceSession(manifest.session, reduce);
  for (const ManifestWarning& w : manifest.warnings) {
    result.warnings.insert(result.warnings.begin(),
                           fmt::format("{}: {}", FormatLocation(w.where), w.message));
  }
  WriteResults(result, output);
  *file = output.string();
  return result;
}

// Where a material stands in the tables: named materials first, by name,
// then the sessions whose material is not given.
bool GroupedBefore(const CampaignSession& a, const CampaignSession& b) {
  const bool a_unnamed = a.material == kMaterialNotGiven;
  const bool b_unnamed = b.material == kMaterialNotGiven;
  return std::tie(a_unnamed, a.material, a.geometry) < std::tie(b_unnamed, b.material, b.geometry);
}

}  // namespace

Campaign MakeCampaign(const std::vector<fs::path>& inputs, const CampaignOptions& options) {
  Campaign campaign;
  campaign.producer = options.producer;
  campaign.created = NowUtc();
  std::set<std::string> taken;
  struct Read {
    SessionResult result;
    std::string input, name, file;
  };
  std::vector<Read> read;
  for (const fs::path& input : inputs) {
    campaign.inputs.push_back(input.string());
    try {
      std::error_code error;
      Read r;
      r.input = input.string();
      if (fs::is_directory(input, error)) {
        const fs::path folder = input.has_filename() ? input : input.parent_path();
        r.name = UniqueName(folder.filename().string(), taken);
        r.result = ReduceFolder(input, r.name, options, &r.file);
      } else {
        r.result = ReadResults(input, ResultsReading::kEstimates);
        r.name = UniqueName(input.stem().string(), taken);
        r.file = input.string();
      }
      read.push_back(std::move(r));
    } catch (const std::exception& error) {
      campaign.failures.push_back({input.string(), error.what()});
    }
  }
  if (!read.empty()) campaign.units = read.front().result.units;
  for (const Read& r : read) {
    try {
      campaign.sessions.push_back(TabulateSession(r.result, r.name, r.file, campaign.units));
    } catch (const std::exception& error) {  // e.g. a unit kind with no conversion
      campaign.failures.push_back({r.input, fmt::format("{}: {}", r.file, error.what())});
    }
  }
  std::stable_sort(campaign.sessions.begin(), campaign.sessions.end(), GroupedBefore);
  campaign.fits = FitMaterials(campaign.sessions, options.false_alarm);
  return campaign;
}

}  // namespace impactlab
