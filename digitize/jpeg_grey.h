// A JPEG decoded to 8-bit grey (its luma) with libjpeg(-turbo) directly,
// because through OpenCV a damaged JPEG passes: libjpeg *warns* about
// corrupt entropy-coded data ("Corrupt JPEG data: ...", "Premature end of
// JPEG file"), fills in what it could not read and goes on, and OpenCV's
// decoder prints the warning on stderr and returns the image. Here every
// warning about the image data fails the decode with libjpeg's message.
#pragma once

#include <span>
#include <string>

#include <opencv2/core.hpp>

namespace impactlab::digitize {

// Progressive JPEGs with more scans than this are refused: a few hundred
// bytes per scan can make the decoder redo the whole image each time (the
// "scan bomb"); real encoders write at most a few dozen.
constexpr int kMaxJpegScans = 1000;

// Decodes `bytes` to CV_8UC1 as stored (no EXIF orientation applied): for
// YCbCr or grey JPEGs the luma plane itself, for RGB ones libjpeg's BT.601
// luma, for CMYK/YCCK the luma of OpenCV's CMYK-to-BGR conversion (so pixels
// match cv::imdecode's IMREAD_GRAYSCALE). Returns false, with libjpeg's
// message in *error, on any error or on any warning other than an unknown
// JFIF version (metadata only).
bool DecodeJpegGrey(std::span<const unsigned char> bytes, cv::Mat* grey, std::string* error);

}  // namespace impactlab::digitize
