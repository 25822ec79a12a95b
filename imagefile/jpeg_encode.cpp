// JPEG encoding with libjpeg(-turbo) directly, set up as OpenCV's encoder
// set it up (imgcodecs/grfmt_jpeg.cpp), so the bytes are the same.
#include <algorithm>
#include <csetjmp>
#include <cstdlib>

#include <fmt/format.h>

#include "imagefile/image_file.h"
#include "imagefile/imagefile_internal.h"

namespace impactlab::imagefile {
namespace {

// Destroys the compressor and frees libjpeg's output buffer however
// EncodeJpeg is left.
struct CompressorGuard {
  jpeg_compress_struct* cinfo;
  unsigned char** buffer;
  ~CompressorGuard() {
    jpeg_destroy_compress(cinfo);
    std::free(*buffer);
  }
};

}  // namespace

bool EncodeJpeg(const cv::Mat& image, int quality, Bytes* bytes, std::string* error) {
  const int channels = image.channels();
  if (image.empty() || image.depth() != CV_8U ||
      (channels != 1 && channels != 3 && channels != 4)) {
    *error = fmt::format("JPEG takes 8-bit images of 1, 3 or 4 channels, not depth {} with {}",
                         image.depth(), channels);
    return false;
  }
  // Everything with a destructor is declared before setjmp.
  jpeg_compress_struct cinfo{};
  internal::JpegErrors errors{};
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  Bytes row(static_cast<std::size_t>(image.cols) * 3);
  cinfo.err = internal::UseJpegErrors(errors, /*warnings_fail=*/false);
  CompressorGuard guard{&cinfo, &buffer};
  if (setjmp(errors.jump) != 0) {
    *error = errors.message;
    return false;
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = static_cast<JDIMENSION>(image.cols);
  cinfo.image_height = static_cast<JDIMENSION>(image.rows);
  cinfo.input_components = channels > 1 ? 3 : 1;
  cinfo.in_color_space = channels > 1 ? JCS_RGB : JCS_GRAYSCALE;
  jpeg_set_defaults(&cinfo);
  cinfo.restart_interval = 0;
  jpeg_set_quality(&cinfo, std::clamp(quality, 0, 100), TRUE /* baseline tables */);
  jpeg_start_compress(&cinfo, TRUE);
  for (int y = 0; y < image.rows; ++y) {
    const unsigned char* in = image.ptr<unsigned char>(y);
    JSAMPROW pointer = const_cast<JSAMPROW>(in);  // libjpeg only reads it
    if (channels > 1) {  // BGR(A) to RGB, as OpenCV did before handing it over
      for (int x = 0; x < image.cols; ++x, in += channels) {
        row[3 * x] = in[2];
        row[3 * x + 1] = in[1];
        row[3 * x + 2] = in[0];
      }
      pointer = row.data();
    }
    jpeg_write_scanlines(&cinfo, &pointer, 1);
  }
  jpeg_finish_compress(&cinfo);
  bytes->assign(buffer, buffer + size);
  return true;
}

}  // namespace impactlab::imagefile
