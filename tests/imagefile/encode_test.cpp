// Encoded bytes byte for byte as cv::imencode wrote them, and the extension
// choosing the format as cv::imwrite chose it.
#include <cstdint>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "imagefile/image_file.h"

namespace impactlab {
namespace {

using imagefile::Bytes;

cv::Mat Picture(int width, int height, int type) {
  cv::Mat out(height, width, type);
  cv::RNG rng(3);
  rng.fill(out, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  // Smooth areas too, which compress differently from noise.
  cv::rectangle(out, {width / 4, height / 4}, {width / 2, height / 2}, cv::Scalar::all(200), -1);
  return out;
}

Bytes OpenCvEncoded(const std::string& extension, const cv::Mat& image,
                    const std::vector<int>& params = {}) {
  Bytes bytes;
  REQUIRE(cv::imencode(extension, image, bytes, params));
  return bytes;
}

TEST_CASE("imagefile/PNG bytes are OpenCV's, at its default and at a zlib level") {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    INFO("type " << type);
    const cv::Mat image = Picture(97, 61, type);
    Bytes ours;
    std::string error;
    REQUIRE(imagefile::EncodePng(image, -1, &ours, &error));
    CHECK(ours == OpenCvEncoded(".png", image));
    REQUIRE(imagefile::EncodePng(image, 6, &ours, &error));
    CHECK(ours == OpenCvEncoded(".png", image, {cv::IMWRITE_PNG_COMPRESSION, 6}));
  }
}

TEST_CASE("imagefile/JPEG bytes are OpenCV's at any quality") {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4}) {
    for (const int quality : {10, 82, 95, 100}) {
      INFO("type " << type << " quality " << quality);
      const cv::Mat image = Picture(130, 70, type);
      Bytes ours;
      std::string error;
      REQUIRE(imagefile::EncodeJpeg(image, quality, &ours, &error));
      CHECK(ours == OpenCvEncoded(".jpg", image, {cv::IMWRITE_JPEG_QUALITY, quality}));
    }
  }
  Bytes bytes;
  std::string error;
  CHECK_FALSE(imagefile::EncodeJpeg(Picture(10, 10, CV_16UC1), 90, &bytes, &error));
  CHECK_THAT(error, Catch::Contains("8-bit"));
}

TEST_CASE("imagefile/TIFF bytes are OpenCV's") {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    INFO("type " << type);
    const cv::Mat image = Picture(97, 301, type);
    Bytes ours;
    std::string error;
    REQUIRE(imagefile::EncodeTiff(image, &ours, &error));
    CHECK(ours == OpenCvEncoded(".tiff", image));
  }
}

TEST_CASE("imagefile/the extension chooses the format as cv::imwrite chose it") {
  const cv::Mat image = Picture(64, 48, CV_8UC3);
  Bytes bytes;
  std::string error;
  REQUIRE(imagefile::EncodeForExtension(".PNG", image, {}, &bytes, &error));
  CHECK(bytes == OpenCvEncoded(".png", image));
  REQUIRE(imagefile::EncodeForExtension(".jpeg", image, {.jpeg_quality = 70}, &bytes, &error));
  CHECK(bytes == OpenCvEncoded(".jpg", image, {cv::IMWRITE_JPEG_QUALITY, 70}));
  REQUIRE(imagefile::EncodeForExtension(".jpg", image, {}, &bytes, &error));
  CHECK(bytes == OpenCvEncoded(".jpg", image));  // quality 95, OpenCV's default
  REQUIRE(imagefile::EncodeForExtension(".tif", image, {}, &bytes, &error));
  CHECK(bytes == OpenCvEncoded(".tiff", image));
  CHECK_FALSE(imagefile::EncodeForExtension(".bmp", image, {}, &bytes, &error));
  CHECK_THAT(error, Catch::Contains(".bmp"));
}

}  // namespace
}  // namespace impactlab
