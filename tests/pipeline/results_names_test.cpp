// docs/results.md against the files: the sample sessions, reduced (a typed-in
// session with a failing and a level pair added, the photo session with a
// manual hint, its calibrations alone, the logs), hold every name the page
// lists, and the page lists every group, dataset and attribute they hold, with
// ids, indices and the fixed vocabularies (cells, log sources, comparison
// models) as the page's placeholders.
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <hdf5.h>
#include <hdf5_hl.h>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "io/manifest.h"
#include "model/power_law_contact.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "synth/law_session.h"
#include "tests/support/sample_data.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

using testing::kSampleData;

std::string ReadText(const fs::path& path) {
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  return text.str();
}

// The names a results file may use for its ids: the page writes them as
// placeholders.
struct Vocabulary {
  std::set<std::string> run_ids, channels, models, laws;
};

void Add(Vocabulary& v, const SessionResult& r) {
  for (const RunResult& run : r.runs) v.run_ids.insert(run.id);
  for (const LogResult& log : r.logs) {
    for (const LogSourceResult& s : log.sources) {
      for (const ChannelAnalysis& c : s.channels) v.channels.insert(c.name);
    }
  }
  if (r.model_comparison) {
    for (const ComparedRestitutionModel& m : r.model_comparison->restitution_models) {
      v.models.insert(m.Name());
    }
    for (const ComparedContactLaw& m : r.model_comparison->contact_laws) v.laws.insert(m.Name());
  }
}

// `name` with a run id suffix ("log_restitution_0.115", "…_std_error") as
// "log_restitution_<run id>".
std::string GeneraliseRunSuffix(const std::string& name, const Vocabulary& v) {
  for (const std::string& id : v.run_ids) {
    for (const std::string tail : {"", "_std_error"}) {
      const std::string suffix = "_" + id + tail;
      if (name.size() > suffix.size() && name.ends_with(suffix)) {
        return name.substr(0, name.size() - suffix.size()) + "_<run id>" + tail;
      }
    }
  }
  return name;
}

// One path component as the page writes it, given the generalised path of
// its parent.
std::string GeneraliseComponent(const std::string& parent, const std::string& c,
                                const Vocabulary& v) {
  const auto in = [&](std::initializer_list<const char*> words) {
    for (const char* w : words) {
      if (c == w) return true;
    }
    return false;
  };
  if (parent == "/runs") return "<run id>";
  if (parent == "/calibrations") return "<calibration id>";
  if (parent == "/predictions") return "<target>_from_<source>";
  if (parent == "/logs") return "<log id>";
  if (parent == "/logs/<log id>" && in({"experiment", "simulation"})) return "<source>";
  if ((parent == "/logs/<log id>/<source>" || parent == "/logs/<log id>/comparison") &&
      v.channels.contains(c)) {
    return "<channel>";
  }
  if (parent == "/runs/<run id>/digitized") return "<i>";
  if ((parent == "/runs/<run id>/calibration" || parent == "/runs/<run id>/rebounds") &&
      in({"right", "left"})) {
    return "<cell>";
  }
  if (parent == "/session/model_comparison" && v.models.contains(c)) return "<model>";
  if (parent == "/session/model_comparison" && v.laws.contains(c)) return "<law>";
  if (parent == "/session/contact_laws") return "<law>";
  if (parent == "/session/model_comparison/<model>") return GeneraliseRunSuffix(c, v);
  return c;
}

// Groups written alike in several places, which the page describes once.
struct Template {
  std::string name;
  std::vector<std::string> places;
};
const std::vector<Template> kTemplates = {
    {"<calibration>", {"/runs/<run id>/calibration/<cell>", "/calibrations/<calibration id>"}},
    {"<photo>", {"<calibration>/digitized", "/runs/<run id>/digitized/<i>"}},
    {"<least-squares fit>",
     {"/runs/<run id>/fit/kelvin_voigt_least_squares", "/runs/<run id>/fit/poynting_thomson",
      "/session/joint_fits/poynting_thomson"}},
    {"<contact law>", {"/session/contact_laws/<law>", "/session/model_comparison/<law>"}},
};

// A generalised name with what lies inside a template's place written from
// the template ("<calibration>@cell"); the place itself keeps its path.
std::string InTemplates(std::string name) {
  for (bool changed = true; changed;) {
    changed = false;
    for (const Template& t : kTemplates) {
      for (const std::string& place : t.places) {
        if (name.size() > place.size() && name.starts_with(place) &&
            (name[place.size()] == '/' || name[place.size()] == '@')) {
          name = t.name + name.substr(place.size());
          changed = true;
        }
      }
    }
  }
  return name;
}

std::string Generalise(const std::string& path, const Vocabulary& v) {
  std::string out;
  std::size_t start = 1;
  while (start <= path.size() && path != "/") {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string component = GeneraliseComponent(out, path.substr(start, end - start), v);
    out += '/';
    out += component;
    start = end + 1;
  }
  return out.empty() ? "/" : out;
}

// Every name in a results file, generalised, with one place it was seen.
using Names = std::map<std::string, std::string>;

struct Walk {
  const Vocabulary* vocabulary;
  std::string file;
  Names* names;
  std::string object;  // the object whose attributes are listed
  bool is_dataset = false;
};

// H5Aiterate2's callback (C: it returns a status, never throws). The
// attributes every dataset may have, and HDF5's own of a dimension scale, the
// page lists once, for all.
herr_t CollectAttribute(hid_t object, const char* attribute, const H5A_info_t*, void* data) {
  Walk& walk = *static_cast<Walk*>(data);
  const std::string name = attribute;
  const std::string where = fmt::format("{}: {}@{}", walk.file, walk.object, name);
  const bool scale = walk.is_dataset && H5DSis_scale(object) > 0;
  if (walk.is_dataset && (name == "units" || name == "DIMENSION_LIST")) {
    walk.names->emplace("<dataset>@" + name, where);
  } else if (scale && (name == "CLASS" || name == "NAME" || name == "REFERENCE_LIST")) {
    walk.names->emplace("<scale>@" + name, where);
  } else if (walk.object.ends_with("/settings") && name == "stages") {
    walk.names->emplace("<settings>@stages", where);
  } else if (walk.object == "/settings" || walk.object.ends_with("/settings")) {
    // One attribute per stage setting, keyed as docs/settings.md lists them.
    walk.names->emplace("<settings>@<key>", where);
  } else {
    walk.names->emplace(InTemplates(Generalise(walk.object, *walk.vocabulary) + "@" + name), where);
  }
  return 0;
}

// H5Ovisit2's callback: the object's name and its attributes'.
herr_t CollectObject(hid_t file, const char* relative, const H5O_info_t* info, void* data) {
  Walk& walk = *static_cast<Walk*>(data);
  const std::string name = relative;
  walk.object = name == "." ? std::string("/") : std::string("/").append(name);
  walk.is_dataset = info->type == H5O_TYPE_DATASET;
  walk.names->emplace(InTemplates(Generalise(walk.object, *walk.vocabulary)),
                      walk.file + ": " + walk.object);
  const hid_t object = H5Oopen(file, relative, H5P_DEFAULT);
  if (object < 0) return -1;
  hsize_t index = 0;
  const herr_t status =
      H5Aiterate2(object, H5_INDEX_NAME, H5_ITER_INC, &index, CollectAttribute, &walk);
  return H5Oclose(object) < 0 ? -1 : status;
}

void CollectNames(const fs::path& path, const Vocabulary& v, Names& names) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(file >= 0);
  Walk walk{&v, path.filename().string(), &names, "", false};
  CHECK(H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_INC, CollectObject, &walk, H5O_INFO_BASIC) >= 0);
  REQUIRE(H5Fclose(file) >= 0);
}

// The names docs/results.md lists: in each table whose first column is
// "name", the backquoted names of that column, relative to the path in
// backquotes of the heading above (a path from "/", or a template such as
// "<calibration>"); a heading's path is itself listed.
std::set<std::string> DocumentedNames(const std::string& text) {
  static const std::regex kQuoted("`([^`]+)`");
  std::set<std::string> names;
  std::string base;
  bool name_table = false;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.starts_with("#")) {
      base.clear();
      std::smatch m;
      if (std::regex_search(line, m, kQuoted) && (m[1].str()[0] == '/' || m[1].str()[0] == '<')) {
        base = m[1].str();
        if (base.starts_with("/")) names.insert(base);
      }
      continue;
    }
    if (!line.starts_with("|")) {
      name_table = false;
      continue;
    }
    const std::string first = line.substr(1, line.find('|', 1) - 1);
    if (first == " name ") {
      name_table = true;
      continue;
    }
    if (!name_table || base.empty()) continue;
    for (std::sregex_iterator m(first.begin(), first.end(), kQuoted), end; m != end; ++m) {
      const std::string token = (*m)[1];
      if (token.starts_with("@")) {
        names.insert(base + token);
      } else {
        names.insert(base == "/" ? "/" + token : base + "/" + token);
      }
    }
  }
  return names;
}

// A copy of the thesis's typed-in session with three more runs: one whose fit
// pair shows no dissipation (the fit fails), one whose pair is level (the fit
// succeeds with a caveat), and one of two maxima without uncertainties (its
// least-squares Kelvin-Voigt fit is exact, a caveat too).
fs::path TypedInSession(const fs::path& dir) {
  fs::create_directories(dir);
  std::ofstream(dir / "session.toml")
      << ReadText(kSampleData / "thesis-1969" / "session.toml") << R"(
[[run]]
id = "rising"
initial_displacement = 0.3
rebounds = [0.15, 0.18, 0.1]
fit_rebounds = [0, 1]

[[run]]
id = "level"
initial_displacement = 0.3
rebounds = [0.15, 0.15, 0.1]
fit_rebounds = [0, 1]
rebound_uncertainty = 0.0005

[[run]]
id = "pair"
initial_displacement = 0.3
rebounds = [0.15, 0.1]
fit_rebounds = [0, 1]
)";
  return dir;
}

// A session of spherical-ended bars with its every [specimen] key, typed in
// from runs drawn under Hunt-Crossley with contact times (so that the laws
// report E*); with `own_ends`, its last run has ends of its own
// ([run.specimen]), so that E* is said to be unidentifiable.
fs::path SpecimenSession(const fs::path& dir, bool own_ends) {
  fs::create_directories(dir);
  constexpr double kGravity = 385.644;
  const HuntCrossley law{2.23 / kGravity, 6.0e7, 1.5, 1.5};
  LawSessionOptions draw;
  draw.initial_displacements = {0.2, 0.4, 0.6};
  std::string text = fmt::format(
      "format = 1\n[apparatus]\npendulum_length = 22.0\nweight = 2.23\n\n[products]\n"
      "joint_fits = false\nintervals = false\nleave_one_out = false\nmodel_comparison = false\n"
      "[products.contact_laws]\nkelvin_voigt = false\nhertz = false\nhunt_crossley_n = false\n"
      "hertz_damper = false\n\n[specimen]\nmaterial = \"steel\"\nend_shape = \"sphere\"\n"
      "sphere_radius = 2.0\nedge_radius = 0.01\ncontact_stiffness = 6e7\nbar_length = 10.1\n"
      "bar_diameter = 1.0\nmodulus = 29e6\npoisson_ratio = 0.29\n");
  text += LawSessionRunsToml(DrawLawSession({22.0, kGravity}, HuntCrossleyContactLaw(law), draw));
  if (own_ends) {
    text +=
        "[run.specimen]\nmaterial = \"steel\"\nend_shape = \"sphere\"\nsphere_radius = 1.0\n"
        "edge_radius = 0.02\ncontact_stiffness = 4e7\nbar_length = 10.0\nbar_diameter = 0.9\n"
        "modulus = 30e6\npoisson_ratio = 0.3\n";
  }
  std::ofstream(dir / "session.toml") << text;
  return dir;
}

// A copy of the photo session whose first run's left trace has three points
// given by hand (from the truth), so its digitized photo records hints.
fs::path HintedPhotoSession(const fs::path& dir) {
  fs::copy(kSampleData / "thesis-photos", dir, fs::copy_options::recursive);
  const nlohmann::json truth =
      nlohmann::json::parse(ReadText(kSampleData / "thesis-photos.truth.json"));
  std::string points = "points = [";
  for (const auto& trace : truth["runs"][0]["photo"]["traces"]) {
    if (trace["name"] != "left") continue;
    const auto& samples = trace["points_t_x_y_px"];
    for (std::size_t k = 1; k <= 3; ++k) {
      const auto& s = samples[k * samples.size() / 4];
      points += fmt::format("{}[{:.1f}, {:.1f}]", k > 1 ? ", " : "", s[1].get<double>(),
                            s[2].get<double>());
    }
  }
  std::string text = ReadText(dir / "session.toml");
  const std::string table = "\n[run.traces.left]\n";
  const std::size_t at = text.find(table, text.find("[[run]]"));
  REQUIRE(at != std::string::npos);
  text.insert(at + table.size(), points + "]\n");
  std::ofstream(dir / "session.toml") << text;
  return dir;
}

TEST_CASE("results_names: docs/results.md lists every name of the files, and no other") {
  testing::TempDir dir;
  const fs::path photos = HintedPhotoSession(dir.path() / "photos");
  struct Reduction {
    fs::path session;
    Products products;
    bool average_stiffness = false;  // [reduction] average_stiffness
  };
  const fs::path typed_in = TypedInSession(dir.path() / "typed-in");
  const std::vector<Reduction> reductions = {
      {SpecimenSession(dir.path() / "spheres", false), Products::kFit},
      {SpecimenSession(dir.path() / "own-ends", true), Products::kFit},
      {typed_in, Products::kFit},
      {typed_in, Products::kFit, true},
      {photos, Products::kFit},
      {photos, Products::kCalibration},
      {kSampleData / "logs-two-link", Products::kFit},
  };
  Vocabulary vocabulary;
  std::vector<fs::path> files;
  for (const Reduction& r : reductions) {
    ReduceOptions options;
    options.products = r.products;
    options.jobs = 2;
    Session session = ReadManifest(r.session).session;
    session.reduction.average_stiffness = r.average_stiffness;
    SessionResult result = ReduceSession(session, options);
    // No sample session's run trace lies far outside its calibrated volts:
    // one bar is given a stretch left out as misread, so that its names are
    // written (tests/pipeline/trace_session_test.cpp reads one).
    for (RunResult& run : result.runs) {
      if (!run.ok || !run.measured.left || r.products != Products::kFit) continue;
      run.measured.left->left_out_from_s = {1.0};
      run.measured.left->left_out_to_s = {1.1};
      break;
    }
    Add(vocabulary, result);
    files.push_back(dir.path() /
                    fmt::format("{}-{}.h5", files.size(), r.session.filename().string()));
    WriteResults(result, files.back());
  }
  Names in_files;
  for (const fs::path& file : files) CollectNames(file, vocabulary, in_files);

  const std::set<std::string> documented =
      DocumentedNames(ReadText(fs::path(IMPACTLAB_SOURCE_DIR) / "docs" / "results.md"));
  for (const auto& [name, where] : in_files) {
    if (!documented.contains(name)) {
      FAIL_CHECK("docs/results.md does not list " << name << " (" << where << ")");
    }
  }
  for (const std::string& name : documented) {
    if (!in_files.contains(name)) {
      FAIL_CHECK("docs/results.md lists " << name << ", which no file of the sample sessions has");
    }
  }
  CHECK(in_files.size() > 200);
}

}  // namespace
}  // namespace impactlab
