// PNG encoding with libpng directly, set up as OpenCV's encoder set it up
// (imgcodecs/grfmt_png.cpp), so the bytes are the same.
#include <algorithm>
#include <bit>
#include <vector>

#include <fmt/format.h>
#include <png.h>
#include <zlib.h>

#include "imagefile/image_file.h"

namespace impactlab::imagefile {
namespace {

struct PngSink {
  Bytes* bytes;
  std::string message;  // libpng's error
};

void PngWriteBytes(png_structp png, png_bytep data, std::size_t size) {
  Bytes* bytes = static_cast<PngSink*>(png_get_io_ptr(png))->bytes;
  bytes->insert(bytes->end(), data, data + size);
}

void PngFlushNothing(png_structp) {}

[[noreturn]] void PngWriteOnError(png_structp png, png_const_charp message) {
  static_cast<PngSink*>(png_get_error_ptr(png))->message = message;
  png_longjmp(png, 1);
}

void PngWriteOnWarning(png_structp, png_const_charp) {}

struct PngWriter {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngWriter() { png_destroy_write_struct(&png, &info); }
};

// The libpng calls, in OpenCV's order; nothing here has a destructor, as
// an error leaves by longjmp.
bool PngWrite(PngWriter& w, PngSink& sink, const cv::Mat& image, int compression, png_bytepp rows) {
  if (setjmp(png_jmpbuf(w.png)) != 0) return false;
  png_set_write_fn(w.png, &sink, PngWriteBytes, PngFlushNothing);
  if (compression >= 0) {
    png_set_compression_level(w.png, std::min(compression, Z_BEST_COMPRESSION));
    png_set_compression_strategy(w.png, Z_DEFAULT_STRATEGY);
  } else {  // OpenCV's default, for speed
    png_set_filter(w.png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_level(w.png, Z_BEST_SPEED);
    png_set_compression_strategy(w.png, Z_RLE);
  }
  const int channels = image.channels();
  png_set_IHDR(w.png, w.info, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows), image.depth() == CV_8U ? 8 : 16,
               channels == 1   ? PNG_COLOR_TYPE_GRAY
               : channels == 3 ? PNG_COLOR_TYPE_RGB
                               : PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(w.png, w.info);
  png_set_bgr(w.png);
  if constexpr (std::endian::native == std::endian::little) png_set_swap(w.png);
  png_write_image(w.png, rows);
  png_write_end(w.png, w.info);
  return true;
}

}  // namespace

bool EncodePng(const cv::Mat& image, int compression, Bytes* bytes, std::string* error) {
  const int channels = image.channels();
  if (image.empty() || (image.depth() != CV_8U && image.depth() != CV_16U) ||
      (channels != 1 && channels != 3 && channels != 4)) {
    *error = fmt::format("PNG takes 8 or 16-bit images of 1, 3 or 4 channels, not depth {} with {}",
                         image.depth(), channels);
    return false;
  }
  bytes->clear();
  PngSink sink{bytes, {}};
  PngWriter w;
  w.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, PngWriteOnError, PngWriteOnWarning);
  if (w.png != nullptr) w.info = png_create_info_struct(w.png);
  if (w.info == nullptr) {
    *error = "libpng could not start (out of memory)";
    return false;
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y) rows[y] = const_cast<png_bytep>(image.ptr<png_byte>(y));
  if (!PngWrite(w, sink, image, compression, rows.data())) {
    *error = sink.message;
    bytes->clear();
    return false;
  }
  return true;
}

}  // namespace impactlab::imagefile
