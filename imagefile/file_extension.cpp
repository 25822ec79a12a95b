// The encoder cv::imwrite chose from a file's extension.
#include <algorithm>
#include <cctype>
#include <string>

#include <fmt/format.h>

#include "imagefile/image_file.h"

namespace impactlab::imagefile {

bool EncodeForExtension(std::string_view extension, const cv::Mat& image,
                        const EncodeOptions& options, Bytes* bytes, std::string* error) {
  std::string lower(extension);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == ".png") return EncodePng(image, options.png_compression, bytes, error);
  if (lower == ".jpg" || lower == ".jpeg") {
    return EncodeJpeg(image, options.jpeg_quality, bytes, error);
  }
  if (lower == ".tif" || lower == ".tiff") return EncodeTiff(image, bytes, error);
  *error = fmt::format("images are written as .png, .jpg (.jpeg) or .tif (.tiff), not as '{}'",
                       extension);
  return false;
}

}  // namespace impactlab::imagefile
