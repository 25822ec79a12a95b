// What layout 2 changed in the results file, checked on the files themselves
// (with HDF5 where io/'s Hdf5File has no word for it): correlation matrices,
// dimension scales, overlays as HDF5 images, and nothing written that does not
// apply.
#include <set>
#include <string>
#include <vector>

#include <hdf5.h>
#include <hdf5_hl.h>
#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/hdf5_extras.h"
#include "io/hdf5_file.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "tests/support/sample_data.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

using testing::kSampleData;

SessionResult Reduced(const std::string& sample) {
  return ReduceSession(ReadManifest(kSampleData / sample).session, {});
}

// A dataset's dimensions.
std::vector<hsize_t> Dimensions(const fs::path& file, const std::string& dataset) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  std::vector<hsize_t> dims(
      static_cast<std::size_t>(std::max(0, H5Sget_simple_extent_ndims(space))));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
  return dims;
}

// Whether `scale` is attached to `dataset`'s first dimension.
bool Attached(const fs::path& file, const std::string& dataset, const std::string& scale) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  const hid_t s = H5Dopen2(f, scale.c_str(), H5P_DEFAULT);
  const bool attached = d >= 0 && s >= 0 && H5DSis_attached(d, s, 0) > 0;
  H5Dclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return attached;
}

// The attribute names of `object`.
std::set<std::string> AttributeNames(const fs::path& file, const std::string& object) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  const hid_t o = H5Oopen(f, object.c_str(), H5P_DEFAULT);
  std::set<std::string> names;
  hsize_t index = 0;
  H5Aiterate2(
      o, H5_INDEX_NAME, H5_ITER_INC, &index,
      [](hid_t, const char* name, const H5A_info_t*, void* data) {
        static_cast<std::set<std::string>*>(data)->insert(name);
        return herr_t{0};
      },
      &names);
  H5Oclose(o);
  H5Fclose(f);
  return names;
}

// Every correlation of `fit` at `g`: n x n, its values as the fit's, each row
// named as an estimate of the fit (or, Poynting-Thomson, a run's speed).
template <typename Fit>
void CheckCorrelation(const fs::path& file, const std::string& g, const Fit& fit,
                      const std::vector<std::string>& run_ids) {
  INFO(g);
  const std::size_t n = fit.covariance.names.size();
  REQUIRE(n > 0);
  CHECK(Dimensions(file, g + "/correlation") == std::vector<hsize_t>{n, n});
  const Hdf5File f = Hdf5File::OpenReadOnly(file);
  CHECK(f.ReadVector(g + "/correlation") == fit.covariance.correlation);
  const std::vector<std::string> rows =
      ReadStringsAttribute(file, g + "/correlation", "parameter_names");
  REQUIRE(rows.size() == n);
  std::set<std::string> estimates;
  for (const std::string& p : f.ReadStrings(g + "/parameter_names")) estimates.insert(p);
  for (const std::string& id : run_ids) estimates.insert("rebound0_speed_" + id);
  for (const std::string& row : rows) {
    INFO(row);
    CHECK(estimates.contains(row));
  }
}

TEST_CASE(
    "results_layout2: a correlation is an n x n matrix, its rows named as the fit's estimates") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "thesis.h5";
  const SessionResult r = Reduced("thesis-1969");
  WriteResults(r, path);
  std::vector<std::string> run_ids;
  for (const RunResult& run : r.runs) run_ids.push_back(run.id);
  for (const RunResult& run : r.runs) {
    const std::string g = "/runs/" + run.id + "/fit/";
    REQUIRE(run.fits.kelvin_voigt_least_squares);
    REQUIRE(run.fits.poynting_thomson);
    CheckCorrelation(path, g + "kelvin_voigt_least_squares", *run.fits.kelvin_voigt_least_squares,
                     run_ids);
    CheckCorrelation(path, g + "poynting_thomson", *run.fits.poynting_thomson, run_ids);
  }
  REQUIRE(r.joint_fits.size() == 1);
  CheckCorrelation(path, "/session/joint_fits/poynting_thomson", r.joint_fits[0], run_ids);
  CHECK(ReadStringsAttribute(path, "/runs/0.405/fit/poynting_thomson/correlation",
                             "parameter_names") ==
        std::vector<std::string>{"stiffness_1", "stiffness_2", "damping", "rebound0_speed_0.405"});
  CHECK(ReadStringsAttribute(path, "/runs/0.405/fit/kelvin_voigt_least_squares/correlation",
                             "parameter_names") ==
        std::vector<std::string>{"zeta", "rebound0_speed"});
  // Read back, the rows are named as the fits name them.
  const SessionResult read = ReadResults(path);
  CHECK(read.runs.front().fits.poynting_thomson->covariance.names ==
        r.runs.front().fits.poynting_thomson->covariance.names);
  CHECK(read.runs.front().fits.kelvin_voigt_least_squares->covariance.names ==
        std::vector<std::string>{"zeta", "v0"});
  CHECK(read.joint_fits.front().covariance.names == r.joint_fits.front().covariance.names);
}

TEST_CASE("results_layout2: per-rebound arrays carry the rebounds' numbers as a dimension scale") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "thesis.h5";
  WriteResults(Reduced("thesis-1969"), path);
  const Hdf5File f = Hdf5File::OpenReadOnly(path);
  const std::string run = "/runs/0.405";
  CHECK(f.ReadIntegers(run + "/rebounds/rebound") == std::vector<long long>{0, 1, 2, 3, 4});
  for (const char* array :
       {"rebounds/xmax", "rebounds/xmax_std_error", "rebounds/t_peak",
        "fit/kelvin_voigt/predicted_xmax", "fit/kelvin_voigt/predicted_xmax_std_error",
        "fit/kelvin_voigt/deviation", "fit/kelvin_voigt/deviation_pct_peak",
        "fit/kelvin_voigt/deviation_pct_x0", "fit/kelvin_voigt_least_squares/predicted_xmax"}) {
    INFO(array);
    CHECK(Attached(path, run + "/" + array, run + "/rebounds/rebound"));
  }
  CHECK(Attached(path, run + "/fit/kelvin_voigt/response/displacement",
                 run + "/fit/kelvin_voigt/response/time"));
  // A prediction counts from the target's rebound it starts at.
  const std::string p = "/predictions/0.405_from_0.323";
  CHECK(f.ReadIntegers(p + "/rebound").front() == f.ReadIntegerAttribute(p, "start_rebound"));
  CHECK(Attached(path, p + "/predicted_xmax", p + "/rebound"));
  CHECK(Attached(path, "/session/kelvin_voigt/stiffness", "/session/kelvin_voigt/run_ids"));
}

TEST_CASE("results_layout2: a session of logs only has no pendulum and no runs") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "logs.h5";
  const SessionResult written = Reduced("logs-two-link");
  WriteResults(written, path);
  const Hdf5File f = Hdf5File::OpenReadOnly(path);
  CHECK_FALSE(f.Exists("/apparatus"));
  CHECK_FALSE(f.Exists("/runs"));
  CHECK_FALSE(f.HasAttribute("/", "convention"));
  CHECK_FALSE(f.HasAttribute("/", "separation"));
  const std::string channel = "/logs/case1/experiment/a1";
  CHECK(Attached(path, channel + "/spectrum/psd", channel + "/spectrum/frequency"));
  CHECK(Attached(path, channel + "/series/value", channel + "/series/time"));
  const SessionResult read = ReadResults(path);
  CHECK(read.runs.empty());
  CHECK(read.apparatus.mass == 0.0);
  REQUIRE(read.logs.size() == written.logs.size());
  CHECK(read.logs[0].Status() == written.logs[0].Status());
}

// A string attribute as the HDF5 Image spec has them (fixed length).
std::string ImageAttribute(const fs::path& file, const std::string& dataset, const char* name) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  char text[64] = {};
  const herr_t status = H5LTget_attribute_string(f, dataset.c_str(), name, text);
  H5Fclose(f);
  return status < 0 ? "(none)" : text;
}

// A photo run whose overlay is a JPEG of colour stripes on grey.
SessionResult WithOverlay(const std::vector<unsigned char>& jpeg) {
  SessionResult r;
  r.title = "an overlay";
  r.producer = "impactlab";
  r.created = "2026-01-01T00:00:00Z";
  RunResult run;
  run.id = "photo";
  run.initial_displacement = 0.3;
  run.reason = "not measured";
  PhotoOverlay overlay;
  overlay.photo = "runs/photo.jpg";
  overlay.jpeg = jpeg;
  overlay.trace_names = {"right", "left"};
  overlay.trace_coverage = {0.9, 0.8};
  overlay.trace_spread_px2 = {1.0, 2.0};
  overlay.trace_spread_sigma_px2 = {0.1, 0.2};
  run.measured.overlays = {overlay};
  r.runs = {run};
  return r;
}

TEST_CASE("results_layout2: a digitized photo's overlay is an HDF5 true-colour image") {
  cv::Mat picture(90, 160, CV_8UC3, cv::Scalar(128, 128, 128));
  picture(cv::Rect(10, 0, 20, 90)).setTo(cv::Scalar(255, 0, 0));  // blue, as OpenCV orders
  picture(cv::Rect(50, 0, 20, 90)).setTo(cv::Scalar(0, 0, 255));  // red
  std::vector<unsigned char> jpeg;
  REQUIRE(cv::imencode(".jpg", picture, jpeg));
  testing::TempDir dir;
  const fs::path path = dir.path() / "r.h5";
  WriteResults(WithOverlay(jpeg), path);
  const std::string image = "/runs/photo/digitized/0/overlay";
  CHECK(Dimensions(path, image) ==
        std::vector<hsize_t>{23, 40, 3});  // a quarter of the JPEG's width
  CHECK(ImageAttribute(path, image, "CLASS") == "IMAGE");
  CHECK(ImageAttribute(path, image, "IMAGE_VERSION") == "1.2");
  CHECK(ImageAttribute(path, image, "IMAGE_SUBCLASS") == "IMAGE_TRUECOLOR");
  CHECK(ImageAttribute(path, image, "INTERLACE_MODE") == "INTERLACE_PIXEL");
  CHECK(ImageAttribute(path, image, "DISPLAY_ORIGIN") == "UL");
  // The pixels are the JPEG's at a quarter of its width, red first.
  cv::Mat rgb;
  cv::cvtColor(cv::imdecode(jpeg, cv::IMREAD_REDUCED_COLOR_4), rgb, cv::COLOR_BGR2RGB);
  const Hdf5File f = Hdf5File::OpenReadOnly(path);
  CHECK(f.ReadBytes(image) == std::vector<unsigned char>(rgb.data, rgb.data + rgb.total() * 3));
  CHECK(rgb.at<cv::Vec3b>(11, 15)[0] > 200);  // the red stripe is red
  // The JPEG stays for the report, and reads back as it was.
  CHECK(f.ReadBytes("/runs/photo/digitized/0/overlay_jpeg") == jpeg);
  REQUIRE(ReadResults(path).runs.at(0).measured.overlays.size() == 1);
  CHECK(ReadResults(path).runs[0].measured.overlays[0].jpeg == jpeg);
  CHECK(Attached(path, "/runs/photo/digitized/0/trace_coverage",
                 "/runs/photo/digitized/0/trace_names"));
}

// A run the manifest rejected, and a Poynting-Thomson fit that could not run,
// as reduce leaves them.
SessionResult WithNothingToSay() {
  SessionResult r;
  r.title = "nothing to say";
  r.producer = "impactlab";
  r.created = "2026-01-01T00:00:00Z";
  RunResult rejected;
  rejected.id = "rejected";
  rejected.reason = "session.toml:3: run \"rejected\".initial_displacement: must be positive";
  RunResult run;
  run.id = "run";
  run.initial_displacement = 0.3;
  run.measured.xmax = {0.1};
  run.measured.xmax_sigma = {0.0};
  run.reason = "one maximum";
  PoyntingThomsonLeastSquaresFit fit;  // refused by its inputs: no solver message
  fit.reason = "needs two maxima";
  run.fits.poynting_thomson = fit;
  r.runs = {rejected, run};
  return r;
}

TEST_CASE("results_layout2: what does not apply is not written") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "r.h5";
  WriteResults(WithNothingToSay(), path);
  const Hdf5File f = Hdf5File::OpenReadOnly(path);
  CHECK(AttributeNames(path, "/runs/rejected") == std::set<std::string>{"status"});
  CHECK(f.Children("/runs/rejected").empty());
  CHECK_FALSE(f.Exists("/runs/run/rebounds/t_peak"));
  const std::string fit = "/runs/run/fit/poynting_thomson";
  CHECK(AttributeNames(path, fit) == std::set<std::string>{"method", "status"});
  CHECK(f.Children(fit).empty());

  const SessionResult read = ReadResults(path);
  REQUIRE(read.runs.size() == 2);
  CHECK(read.runs[0].reason == WithNothingToSay().runs[0].reason);
  CHECK(read.runs[0].initial_displacement == 0.0);
  REQUIRE(read.runs[1].fits.poynting_thomson);
  CHECK_FALSE(read.runs[1].fits.kelvin_voigt_least_squares);
  const PoyntingThomsonLeastSquaresFit& pt = *read.runs[1].fits.poynting_thomson;
  CHECK_FALSE(pt.ok);
  CHECK(pt.reason == "needs two maxima");
  CHECK_FALSE(pt.status.Ran());
}

}  // namespace
}  // namespace impactlab
