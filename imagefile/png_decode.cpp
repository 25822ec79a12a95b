// PNG decoding with libpng directly, with the transformations OpenCV's
// decoder asked libpng for (imgcodecs/grfmt_png.cpp), so the pixels are the
// same.
#include <bit>
#include <cstring>
#include <vector>

#include <png.h>

#include "imagefile/image_file.h"
#include "imagefile/image_header.h"

namespace impactlab::imagefile {
namespace {

// The bytes libpng reads, and how far it has read.
struct PngSource {
  std::span<const unsigned char> bytes;
  std::size_t position = 0;
  std::string message;  // libpng's error
};

void PngReadBytes(png_structp png, png_bytep out, std::size_t size) {
  auto* source = static_cast<PngSource*>(png_get_io_ptr(png));
  if (source->bytes.size() - source->position < size) {
    png_error(png, "PNG input buffer is incomplete");
  }
  std::memcpy(out, source->bytes.data() + source->position, size);
  source->position += size;
}

// An error leaves libpng by longjmp to the setjmp of the function that
// called it (PngReadInfo or PngReadImage), which have nothing to destroy.
[[noreturn]] void PngOnError(png_structp png, png_const_charp message) {
  static_cast<PngSource*>(png_get_error_ptr(png))->message = message;
  png_longjmp(png, 1);
}

// Warnings (a bad CRC in an ancillary chunk, say) pass, as they did
// through OpenCV, which printed them.
void PngOnWarning(png_structp, png_const_charp) {}

// libpng's reader and its two info structs, destroyed however the decode
// is left.
struct PngReader {
  png_structp png = nullptr;
  png_infop info = nullptr;
  png_infop end_info = nullptr;
  PngSource source;
  // From the header:
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, colour_type = 0;
  int type = CV_8UC1;  // what OpenCV's decoder declared (before IMREAD_ANYCOLOR)

  ~PngReader() { png_destroy_read_struct(&png, &info, &end_info); }
};

bool PngReadInfo(PngReader& r) {
  if (setjmp(png_jmpbuf(r.png)) != 0) return false;
  png_set_read_fn(r.png, &r.source, PngReadBytes);
  png_read_info(r.png, r.info);
  png_get_IHDR(r.png, r.info, &r.width, &r.height, &r.bit_depth, &r.colour_type, nullptr, nullptr,
               nullptr);
  int channels = 1;
  if (r.colour_type == PNG_COLOR_TYPE_RGB || r.colour_type == PNG_COLOR_TYPE_PALETTE) {
    png_bytep trans = nullptr;
    int num_trans = 0;
    png_color_16p trans_values = nullptr;
    png_get_tRNS(r.png, r.info, &trans, &num_trans, &trans_values);
    channels = num_trans > 0 ? 4 : 3;
  } else if (r.colour_type == PNG_COLOR_TYPE_GRAY_ALPHA ||
             r.colour_type == PNG_COLOR_TYPE_RGB_ALPHA) {
    channels = 4;
  }
  r.type = CV_MAKETYPE(r.bit_depth == 16 ? CV_16U : CV_8U, channels);
  return true;
}

// Decodes into `rows` (image.rows pointers into an image of `channels`
// channels) with the transformations OpenCV asked for.
bool PngReadImage(PngReader& r, png_bytepp rows, int channels) {
  if (setjmp(png_jmpbuf(r.png)) != 0) return false;
  const bool colour = channels > 1;
  if constexpr (std::endian::native == std::endian::little) png_set_swap(r.png);  // 16-bit samples
  if (channels < 4) {
    png_set_strip_alpha(r.png);
  } else {
    png_set_tRNS_to_alpha(r.png);
  }
  if (r.colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(r.png);
  if ((r.colour_type & PNG_COLOR_MASK_COLOR) == 0 && r.bit_depth < 8) {
    png_set_expand_gray_1_2_4_to_8(r.png);
  }
  if ((r.colour_type & PNG_COLOR_MASK_COLOR) != 0 && colour) {
    png_set_bgr(r.png);
  } else if (colour) {
    png_set_gray_to_rgb(r.png);
  } else {
    png_set_rgb_to_gray(r.png, 1, 0.299, 0.587);
  }
  png_set_interlace_handling(r.png);
  png_read_update_info(r.png, r.info);
  png_read_image(r.png, rows);
  png_read_end(r.png, r.end_info);
  return true;
}

// The orientation in the PNG's eXIf chunk (before or after the image data).
int PngExifOrientation(const PngReader& r) {
  png_uint_32 size = 0;
  png_bytep exif = nullptr;
  if (png_get_valid(r.png, r.info, PNG_INFO_eXIf) != 0) {
    png_get_eXIf_1(r.png, r.info, &size, &exif);
  } else if (png_get_valid(r.png, r.end_info, PNG_INFO_eXIf) != 0) {
    png_get_eXIf_1(r.png, r.end_info, &size, &exif);
  }
  if (exif == nullptr || size == 0) return 1;
  return ReadExifOrientation({exif, size});
}

}  // namespace

bool DecodePng(std::span<const unsigned char> bytes, cv::Mat* image, std::string* error) {
  *image = cv::Mat();
  PngReader r;
  r.source.bytes = bytes;
  r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r.source, PngOnError, PngOnWarning);
  if (r.png != nullptr) {
    r.info = png_create_info_struct(r.png);
    r.end_info = png_create_info_struct(r.png);
  }
  if (r.info == nullptr || r.end_info == nullptr) {
    *error = "libpng could not start (out of memory)";
    return false;
  }
  if (!PngReadInfo(r)) {
    *error = r.source.message;
    return false;
  }
  // IMREAD_ANYCOLOR: grey stays grey, anything with colour or alpha is BGR.
  const int channels = CV_MAT_CN(r.type) > 1 ? 3 : 1;
  cv::Mat pixels(static_cast<int>(r.height), static_cast<int>(r.width),
                 CV_MAKETYPE(CV_MAT_DEPTH(r.type), channels));
  std::vector<png_bytep> rows(static_cast<std::size_t>(pixels.rows));
  for (int y = 0; y < pixels.rows; ++y) rows[y] = pixels.ptr<png_byte>(y);
  if (!PngReadImage(r, rows.data(), channels)) {
    *error = r.source.message;
    return false;
  }
  ApplyExifOrientation(PngExifOrientation(r), pixels);
  *image = std::move(pixels);
  return true;
}

}  // namespace impactlab::imagefile
