// Bad photos and missing traces: each a clear InputError naming the photo and
// what was not found; never a made-up trace.
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "io/errors.h"
#include "render/oscillograph.h"
#include "tests/digitize/photo_scenes.h"
#include "tests/support/input_error.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

void WriteBytes(const std::filesystem::path& path, const std::vector<uchar>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

using testing::InputErrorOf;

std::vector<uchar> Encoded(const cv::Mat& image, const std::string& extension) {
  std::vector<uchar> bytes;
  cv::imencode(extension, image, bytes);
  return bytes;
}

}  // namespace

TEST_CASE("digitize errors: unreadable, truncated or unusable photo files name the file") {
  const testing::TempDir dir;
  const cv::Mat image = RenderOscillograph(testing::StandardRunScene().scene, {}).image;

  const auto missing = dir.path() / "missing.png";
  std::string message = InputErrorOf([&] { LoadPhoto(missing); });
  CHECK(message.find("missing.png") != std::string::npos);
  CHECK(message.find("does not exist") != std::string::npos);

  for (const std::string extension : {".png", ".jpg"}) {
    std::vector<uchar> bytes = Encoded(image, extension);
    bytes.resize(bytes.size() / 2);
    const auto truncated = dir.path() / ("truncated" + extension);
    WriteBytes(truncated, bytes);
    message = InputErrorOf([&] { LoadPhoto(truncated); });
    INFO(message);
    CHECK(message.find(truncated.filename().string()) != std::string::npos);
    CHECK(message.find("truncated") != std::string::npos);
  }

  const auto text = dir.path() / "notes.jpg";
  std::ofstream(text) << "not a photo at all\n";
  message = InputErrorOf([&] { LoadPhoto(text); });
  CHECK(message.find("notes.jpg") != std::string::npos);
  CHECK(message.find("cannot decode") != std::string::npos);

  const auto empty = dir.path() / "empty.png";
  std::ofstream{empty};
  CHECK(InputErrorOf([&] { LoadPhoto(empty); }).find("empty") != std::string::npos);

  const auto tiny = dir.path() / "tiny.png";
  WriteBytes(tiny, Encoded(cv::Mat(40, 60, CV_8UC3, cv::Scalar(0, 0, 0)), ".png"));
  CHECK(InputErrorOf([&] { LoadPhoto(tiny); }).find("too small") != std::string::npos);

  // A good file loads with its depth and channels as they are.
  const auto good = dir.path() / "good.png";
  cv::Mat sixteen;
  image.convertTo(sixteen, CV_16U, 257.0);
  WriteBytes(good, Encoded(sixteen, ".png"));
  const Photo photo = LoadPhoto(good);
  CHECK(photo.image.type() == CV_16UC3);
  CHECK(photo.source == good);
}

TEST_CASE("digitize errors: a photo without the graticule says so") {
  // A blank frame, random noise, and a photo of something else (circles).
  cv::Mat noise(600, 800, CV_8UC1);
  cv::randu(noise, 0, 255);
  cv::Mat circles(600, 800, CV_8UC3, cv::Scalar(40, 40, 40));
  for (int r = 20; r < 300; r += 25)
    cv::circle(circles, {400, 300}, r, cv::Scalar(200, 220, 200), 2);
  const std::vector<std::pair<std::string, cv::Mat>> photos = {
      {"blank.png", cv::Mat(600, 800, CV_8UC3, cv::Scalar(30, 30, 30))},
      {"noise.png", noise},
      {"circles.png", circles},
  };
  for (const auto& [name, image] : photos) {
    const DigitizeResult result =
        DigitizePhoto({image, name}, {10, 8}, testing::StandardRunScene().requests, {});
    const std::string message = result.Failure();
    CHECK_FALSE(result.ok);
    CHECK_FALSE(result.graticule_found);
    CHECK(result.traces.empty());
    INFO(name << ": " << message);
    CHECK(message.find(name) != std::string::npos);
    CHECK(message.find("graticule of 10 x 8 divisions not found") != std::string::npos);
  }
}

TEST_CASE("digitize errors: a graticule of other divisions than the manifest's is not taken") {
  RenderOptions options;
  options.width_px = 1200;
  const PreparedPhoto photo = PreparePhoto(
      {RenderOscillograph(testing::StandardRunScene().scene, options).image, "p.png"}, {});
  for (const std::array<int, 2> divisions :
       {std::array<int, 2>{12, 8}, {8, 8}, {10, 6}, {10, 10}}) {
    const std::string message = InputErrorOf([&] { FindGraticule(photo, divisions, {}); });
    INFO(divisions[0] << " x " << divisions[1] << ": " << message);
    CHECK(message.find("p.png") != std::string::npos);
    CHECK(message.find(fmt::format("graticule of {} x {} divisions not found", divisions[0],
                                   divisions[1])) != std::string::npos);
  }
  CHECK_NOTHROW(FindGraticule(photo, {10, 8}, {}));
}

TEST_CASE("digitize errors: a trace missing from its band is reported, not invented") {
  testing::RunScene run = testing::StandardRunScene();
  const std::vector<TraceRequest> requests = run.requests;
  run.scene.traces.erase(run.scene.traces.begin() + 1);  // no left trace on the photo
  for (const PhotoStyle style : {PhotoStyle::kClean, PhotoStyle::kPolaroid, PhotoStyle::kPhone}) {
    RenderOptions options;
    options.style = style;
    options.width_px = 1000;
    const cv::Mat image = RenderOscillograph(run.scene, options).image;
    const DigitizeResult result = DigitizePhoto({image, "run-7.jpg"}, {10, 8}, requests, {});
    const std::string message = result.Failure();
    CHECK_FALSE(result.ok);
    // What was found before the trace was missed stays: the graticule.
    CHECK(result.graticule_found);
    CHECK(result.graticule.residual_px < 1.0);
    CHECK(result.traces.empty());
    INFO(PhotoStyleName(style) << ": " << message);
    CHECK(message.find("run-7.jpg") != std::string::npos);
    CHECK(message.find("trace 'left' not found in its band [-2.4, 0] div") != std::string::npos);
    // The overlay of a photo not read shows the graticule found and why.
    const cv::Mat overlay = DrawOverlay({image, "run-7.jpg"}, result, {.max_width_px = 500});
    CHECK(!overlay.empty());
  }
}

TEST_CASE("digitize errors: bad trace settings are refused") {
  const testing::RunScene run = testing::StandardRunScene();
  RenderOptions options;
  options.width_px = 800;
  const cv::Mat image = RenderOscillograph(run.scene, options).image;
  std::vector<TraceRequest> requests = run.requests;
  requests[0].settings.volts_per_div = 0.0;
  CHECK_THROWS_AS(DigitizePhoto({image, "p.png"}, {10, 8}, requests, {}), std::invalid_argument);
}

}  // namespace impactlab
