// TIFF encoding with libtiff directly, with the tags OpenCV's encoder wrote
// (imgcodecs/grfmt_tiff.cpp), so the bytes are the same.
#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <vector>

#include <fmt/format.h>
#include <tiffio.h>

#include "imagefile/image_file.h"

namespace impactlab::imagefile {
namespace {

// The growing file libtiff writes through its client procedures.
struct TiffSink {
  Bytes* bytes;
  toff_t position = 0;
  std::string message;
};

tmsize_t TiffReadNothing(thandle_t, void*, tmsize_t) { return 0; }

tmsize_t TiffWriteProc(thandle_t handle, void* data, tmsize_t size) {
  auto* s = static_cast<TiffSink*>(handle);
  const std::size_t end = s->position + static_cast<std::size_t>(size);
  if (s->bytes->size() < end) s->bytes->resize(end);
  std::memcpy(s->bytes->data() + s->position, data, static_cast<std::size_t>(size));
  s->position = end;
  return size;
}

toff_t TiffSinkSeek(thandle_t handle, toff_t offset, int whence) {
  auto* s = static_cast<TiffSink*>(handle);
  if (whence == SEEK_SET) s->position = offset;
  if (whence == SEEK_CUR) s->position += offset;
  if (whence == SEEK_END) s->position = s->bytes->size() + offset;
  return s->position;
}

int TiffSinkClose(thandle_t) { return 0; }

toff_t TiffSinkSize(thandle_t handle) { return static_cast<TiffSink*>(handle)->bytes->size(); }

int TiffWriteOnError(TIFF*, void* user_data, const char* module, const char* format, va_list ap) {
  auto* s = static_cast<TiffSink*>(user_data);
  if (s->message.empty()) {
    char text[512];
    std::vsnprintf(text, sizeof text, format, ap);
    s->message = module != nullptr && *module != '\0' ? fmt::format("{}: {}", module, text) : text;
  }
  return 1;
}

int TiffWriteOnWarning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

}  // namespace

bool EncodeTiff(const cv::Mat& image, Bytes* bytes, std::string* error) {
  const int channels = image.channels();
  if (image.empty() || (image.depth() != CV_8U && image.depth() != CV_16U) ||
      (channels != 1 && channels != 3 && channels != 4)) {
    *error = fmt::format(
        "TIFF is written from 8 or 16-bit images of 1, 3 or 4 channels, not depth {} with {}",
        image.depth(), channels);
    return false;
  }
  bytes->clear();
  TiffSink sink{bytes, 0, {}};
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  TIFFOpenOptionsSetErrorHandlerExtR(options, TiffWriteOnError, &sink);
  TIFFOpenOptionsSetWarningHandlerExtR(options, TiffWriteOnWarning, &sink);
  TIFF* tif = TIFFClientOpenExt("", "w", &sink, TiffReadNothing, TiffWriteProc, TiffSinkSeek,
                                TiffSinkClose, TiffSinkSize, nullptr, nullptr, options);
  TIFFOpenOptionsFree(options);
  if (tif == nullptr) {
    *error = "libtiff could not start writing: " + sink.message;
    return false;
  }
  const int bits = image.depth() == CV_8U ? 8 : 16;
  const std::size_t file_step = std::size_t(image.cols) * channels * bits / 8;
  const int rows_per_strip =
      std::max(1, std::min(image.rows, static_cast<int>((1 << 13) / file_step)));
  bool ok = TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, image.cols) != 0 &&
            TIFFSetField(tif, TIFFTAG_IMAGELENGTH, image.rows) != 0 &&
            TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, bits) != 0 &&
            TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_LZW) != 0 &&
            TIFFSetField(tif, TIFFTAG_PHOTOMETRIC,
                         channels > 1 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK) != 0 &&
            TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, channels) != 0 &&
            TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG) != 0 &&
            TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, rows_per_strip) != 0 &&
            TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_UINT) != 0 &&
            TIFFSetField(tif, TIFFTAG_PREDICTOR, PREDICTOR_HORIZONTAL) != 0;
  // libtiff's predictor changes the row it is given: a copy, red first.
  std::vector<unsigned char> row(static_cast<std::size_t>(TIFFScanlineSize(tif)) + 32);
  const std::size_t sample_bytes = bits / 8;
  for (int y = 0; ok && y < image.rows; ++y) {
    const unsigned char* in = image.ptr<unsigned char>(y);
    std::memcpy(row.data(), in, file_step);
    if (channels > 1) {  // BGR(A) to RGB(A)
      for (int x = 0; x < image.cols; ++x) {
        unsigned char* pixel = row.data() + std::size_t(x) * channels * sample_bytes;
        std::swap_ranges(pixel, pixel + sample_bytes, pixel + 2 * sample_bytes);
      }
    }
    ok = TIFFWriteScanline(tif, row.data(), static_cast<std::uint32_t>(y), 0) == 1;
  }
  ok = ok && TIFFWriteDirectory(tif) != 0;
  TIFFClose(tif);
  if (!ok) {
    *error = "libtiff could not write it: " + sink.message;
    bytes->clear();
    return false;
  }
  return true;
}

}  // namespace impactlab::imagefile
