// JPEG decoding with libjpeg(-turbo) directly: to grey for photos, to BGR
// (optionally scaled) for thumbnails and rendered photos.
#include <algorithm>
#include <csetjmp>
#include <cstdio>

#include "imagefile/image_file.h"
#include "imagefile/image_header.h"
#include "imagefile/imagefile_internal.h"

namespace impactlab::imagefile {
namespace {

using internal::JpegErrors;

void RefuseScanBombs(j_common_ptr cinfo) {
  if (!cinfo->is_decompressor) return;
  const auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
  if (d->input_scan_number > kMaxJpegScans) {
    auto* e = reinterpret_cast<JpegErrors*>(cinfo->err);
    std::snprintf(e->message, sizeof e->message, "more than %d scans (a progressive scan bomb?)",
                  kMaxJpegScans);
    std::longjmp(e->jump, 1);
  }
}

// Destroys the decompressor however a decode is left: by return, by a C++
// exception (cv::Mat's allocation) or after the longjmp.
struct DecompressorGuard {
  jpeg_decompress_struct* cinfo;
  ~DecompressorGuard() { jpeg_destroy_decompress(cinfo); }
};

// Reads every scanline into `image` (already sized) through `convert`,
// which turns one decoded row (libjpeg's `row`) into the image's row y;
// rows libjpeg can write as they are go straight in when `direct`.
template <typename Convert>
void ReadRows(jpeg_decompress_struct& cinfo, cv::Mat& image, bool direct, Convert convert) {
  if (direct) {
    constexpr int kRowsPerRead = 16;
    JSAMPROW rows[kRowsPerRead];
    while (cinfo.output_scanline < cinfo.output_height) {
      const int first = static_cast<int>(cinfo.output_scanline);
      const int count = std::min<int>(kRowsPerRead, image.rows - first);
      for (int i = 0; i < count; ++i) rows[i] = image.ptr<unsigned char>(first + i);
      jpeg_read_scanlines(&cinfo, rows, static_cast<JDIMENSION>(count));
    }
    return;
  }
  JSAMPARRAY row = (*cinfo.mem->alloc_sarray)(reinterpret_cast<j_common_ptr>(&cinfo), JPOOL_IMAGE,
                                              cinfo.output_width * cinfo.output_components, 1);
  while (cinfo.output_scanline < cinfo.output_height) {
    const int y = static_cast<int>(cinfo.output_scanline);
    jpeg_read_scanlines(&cinfo, row, 1);
    convert(row[0], image.ptr<unsigned char>(y));
  }
}

}  // namespace

bool DecodeJpegGrey(std::span<const unsigned char> bytes, cv::Mat* grey, std::string* error) {
  // Everything with a destructor is declared before setjmp: the longjmp
  // must not skip one.
  jpeg_decompress_struct cinfo{};
  JpegErrors errors{};
  jpeg_progress_mgr progress{};
  cinfo.err = internal::UseJpegErrors(errors, /*warnings_fail=*/true);
  progress.progress_monitor = RefuseScanBombs;
  DecompressorGuard guard{&cinfo};  // jpeg_destroy_decompress accepts a zeroed struct
  if (setjmp(errors.jump) != 0) {
    *error = errors.message;
    *grey = cv::Mat();
    return false;
  }
  jpeg_create_decompress(&cinfo);
  cinfo.progress = &progress;
  jpeg_mem_src(&cinfo, bytes.data(), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&cinfo, TRUE);
  // Luma only: libjpeg then skips colour upsampling and conversion. CMYK
  // and YCCK have no grey conversion in libjpeg; they come as CMYK.
  const bool cmyk = cinfo.num_components == 4;
  cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_GRAYSCALE;
  jpeg_start_decompress(&cinfo);
  grey->create(static_cast<int>(cinfo.output_height), static_cast<int>(cinfo.output_width),
               CV_8UC1);
  ReadRows(cinfo, *grey, !cmyk, [width = grey->cols](const JSAMPLE* in, unsigned char* out) {
    for (int x = 0; x < width; ++x, in += 4) {
      const internal::Rgb8 c = internal::RgbOfCmyk(in);
      out[x] = static_cast<unsigned char>(internal::LumaOf(c.r, c.g, c.b));
    }
  });
  jpeg_finish_decompress(&cinfo);
  ApplyExifOrientation(ReadJpegExifOrientation(bytes), *grey);
  return true;
}

bool DecodeJpegBgr(std::span<const unsigned char> bytes, int scale_denom, cv::Mat* bgr,
                   std::string* error) {
  jpeg_decompress_struct cinfo{};
  JpegErrors errors{};
  cinfo.err = internal::UseJpegErrors(errors, /*warnings_fail=*/false);
  DecompressorGuard guard{&cinfo};
  if (setjmp(errors.jump) != 0) {
    *error = errors.message;
    *bgr = cv::Mat();
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, bytes.data(), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&cinfo, TRUE);
  cinfo.scale_num = 1;
  cinfo.scale_denom = static_cast<unsigned>(scale_denom);
  // OpenCV asked libjpeg for RGB and swapped it; libjpeg-turbo writes BGR
  // itself, the same values. CMYK is turned by hand, as OpenCV did.
  const bool cmyk = cinfo.num_components == 4;
  cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_EXT_BGR;
  jpeg_start_decompress(&cinfo);
  bgr->create(static_cast<int>(cinfo.output_height), static_cast<int>(cinfo.output_width), CV_8UC3);
  ReadRows(cinfo, *bgr, !cmyk, [width = bgr->cols](const JSAMPLE* in, unsigned char* out) {
    for (int x = 0; x < width; ++x, in += 4, out += 3) {
      const internal::Rgb8 c = internal::RgbOfCmyk(in);
      out[0] = static_cast<unsigned char>(c.b);
      out[1] = static_cast<unsigned char>(c.g);
      out[2] = static_cast<unsigned char>(c.r);
    }
  });
  jpeg_finish_decompress(&cinfo);
  ApplyExifOrientation(ReadJpegExifOrientation(bytes), *bgr);
  return true;
}

}  // namespace impactlab::imagefile
