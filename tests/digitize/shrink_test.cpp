// The photo shrunk by a whole factor (digitize/grey_ink.h): the pixels of
// OpenCV's area resampling, which the working copy and the overlay were made
// with before, for every channel count, sample type and factor.
#include <random>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/grey_ink.h"

namespace impactlab::digitize {
namespace {

TEST_CASE("a photo shrunk by a whole factor has the pixels of OpenCV's area resampling",
          "[digitize][shrink]") {
  cv::RNG random(1531);
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3}) {
    // Sizes that are not multiples of the factors: the last partial blocks go.
    cv::Mat photo(301, 457, type);
    random.fill(photo, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_8U ? 256 : 65536);
    for (const int f : {1, 2, 3, 4, 5, 7, 16}) {
      CAPTURE(type, f);
      const cv::Mat shrunk = ShrunkByArea(photo, f);
      cv::Mat expected = photo;
      if (f > 1) {
        cv::resize(photo(cv::Rect(0, 0, photo.cols / f * f, photo.rows / f * f)), expected,
                   cv::Size(photo.cols / f, photo.rows / f), 0.0, 0.0, cv::INTER_AREA);
      }
      REQUIRE(shrunk.type() == expected.type());
      REQUIRE(shrunk.size() == expected.size());
      CHECK(cv::norm(shrunk, expected, cv::NORM_INF) == 0.0);
    }
  }
}

}  // namespace
}  // namespace impactlab::digitize
