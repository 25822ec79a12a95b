#include "digitize/jpeg_grey.h"

#include <algorithm>
#include <csetjmp>
#include <cstdio>

#include <jerror.h>
#include <jpeglib.h>

namespace impactlab::digitize {
namespace {

// libjpeg reports through these callbacks. An error (and a warning, which
// here is one) leaves libjpeg by longjmp back to DecodeJpegGrey: a C++
// exception must not unwind through libjpeg's C frames.
struct ErrorManager {
  jpeg_error_mgr pub;  // first, so a j_common_ptr's err points at the whole
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void OnError(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

// msg_level -1 is a warning; 0 and above are trace messages.
void OnMessage(j_common_ptr cinfo, int msg_level) {
  if (msg_level >= 0) return;
  // An unknown JFIF revision says nothing about the pixels.
  if (cinfo->err->msg_code == JWRN_JFIF_MAJOR) return;
  OnError(cinfo);
}

void OnProgress(j_common_ptr cinfo) {
  if (!cinfo->is_decompressor) return;
  const auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
  if (d->input_scan_number > kMaxJpegScans) {
    auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
    std::snprintf(e->message, sizeof e->message, "more than %d scans (a progressive scan bomb?)",
                  kMaxJpegScans);
    std::longjmp(e->jump, 1);
  }
}

// OpenCV's icvCvt_CMYK2Gray_8u_C4C1R (Adobe's inverted CMYK), so a CMYK
// JPEG gives the grey it gave before.
void CmykRowToGrey(const JSAMPLE* cmyk, int width, unsigned char* grey) {
  constexpr int kShift = 14;
  constexpr int kR = 4899, kG = 9617, kB = 1868;  // 0.299, 0.587, 0.114 in Q14
  for (int x = 0; x < width; ++x, cmyk += 4) {
    const int k = cmyk[3];
    const int c = k - ((255 - cmyk[0]) * k >> 8);
    const int m = k - ((255 - cmyk[1]) * k >> 8);
    const int y = k - ((255 - cmyk[2]) * k >> 8);
    grey[x] =
        static_cast<unsigned char>((y * kB + m * kG + c * kR + (1 << (kShift - 1))) >> kShift);
  }
}

// Destroys the decompressor however DecodeJpegGrey is left: by return, by a
// C++ exception (cv::Mat's allocation) or after the longjmp.
struct Destroyer {
  jpeg_decompress_struct* cinfo;
  ~Destroyer() { jpeg_destroy_decompress(cinfo); }
};

}  // namespace

bool DecodeJpegGrey(std::span<const unsigned char> bytes, cv::Mat* grey, std::string* error) {
  // Everything with a destructor is declared before setjmp: the longjmp
  // must not skip one.
  jpeg_decompress_struct cinfo{};
  ErrorManager err{};
  jpeg_progress_mgr progress{};
  cinfo.err = jpeg_std_error(&err.pub);
  err.pub.error_exit = OnError;
  err.pub.emit_message = OnMessage;
  progress.progress_monitor = OnProgress;
  Destroyer destroyer{&cinfo};  // jpeg_destroy_decompress accepts a zeroed struct
  if (setjmp(err.jump) != 0) {
    *error = err.message;
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
  JSAMPARRAY cmyk_row = cmyk ? (*cinfo.mem->alloc_sarray)(reinterpret_cast<j_common_ptr>(&cinfo),
                                                          JPOOL_IMAGE, cinfo.output_width * 4, 1)
                             : nullptr;
  constexpr int kRowsPerRead = 16;
  JSAMPROW rows[kRowsPerRead];
  while (cinfo.output_scanline < cinfo.output_height) {
    const int first = static_cast<int>(cinfo.output_scanline);
    if (cmyk) {
      jpeg_read_scanlines(&cinfo, cmyk_row, 1);
      CmykRowToGrey(cmyk_row[0], grey->cols, grey->ptr<unsigned char>(first));
      continue;
    }
    const int count = std::min<int>(kRowsPerRead, grey->rows - first);
    for (int i = 0; i < count; ++i) rows[i] = grey->ptr<unsigned char>(first + i);
    jpeg_read_scanlines(&cinfo, rows, static_cast<JDIMENSION>(count));
  }
  jpeg_finish_decompress(&cinfo);
  return true;
}

}  // namespace impactlab::digitize
