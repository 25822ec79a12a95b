// Helpers the codec files share: libjpeg's error manager, OpenCV's luma
// weights, and a Mat's rows for a C decoder to write.
#pragma once

#include <csetjmp>
#include <cstdio>
#include <string>

#include <jerror.h>
#include <jpeglib.h>  // after <cstdio>: it needs FILE

namespace impactlab::imagefile::internal {

// libjpeg reports through these callbacks. An error leaves libjpeg by
// longjmp back to the function that called setjmp(jump): a C++ exception
// must not unwind through libjpeg's C frames. With `warnings_fail`, a
// warning about the data is an error too (the strict photo decode).
struct JpegErrors {
  jpeg_error_mgr pub;  // first, so a j_common_ptr's err points at the whole
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {};
  bool warnings_fail = false;
};

[[noreturn]] inline void JpegOnError(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegErrors*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

// msg_level -1 is a warning; 0 and above are trace messages. Warnings that
// pass are dropped (OpenCV printed the first on stderr).
inline void JpegOnMessage(j_common_ptr cinfo, int msg_level) {
  if (msg_level >= 0) return;
  auto* e = reinterpret_cast<JpegErrors*>(cinfo->err);
  if (!e->warnings_fail) return;
  // An unknown JFIF revision says nothing about the pixels.
  if (cinfo->err->msg_code == JWRN_JFIF_MAJOR) return;
  JpegOnError(cinfo);
}

// Sets up `errors` as cinfo's error manager.
inline jpeg_error_mgr* UseJpegErrors(JpegErrors& errors, bool warnings_fail) {
  jpeg_error_mgr* pub = jpeg_std_error(&errors.pub);
  errors.pub.error_exit = JpegOnError;
  errors.pub.emit_message = JpegOnMessage;
  errors.warnings_fail = warnings_fail;
  return pub;
}

// OpenCV's fixed-point luma (imgcodecs/utils.cpp): BT.601 weights in Q14,
// rounded.
constexpr int kLumaShift = 14;
constexpr int kLumaR = 4899;                                 // 0.299
constexpr int kLumaG = 9617;                                 // 0.587
constexpr int kLumaB = (1 << kLumaShift) - kLumaR - kLumaG;  // 0.114
constexpr int LumaOf(int r, int g, int b) {
  return (r * kLumaR + g * kLumaG + b * kLumaB + (1 << (kLumaShift - 1))) >> kLumaShift;
}

// Adobe's inverted CMYK as OpenCV turned it to R, G, B
// (icvCvt_CMYK2BGR_8u_C4C3R).
struct Rgb8 {
  int r, g, b;
};
constexpr Rgb8 RgbOfCmyk(const unsigned char* cmyk) {
  const int k = cmyk[3];
  return {k - ((255 - cmyk[0]) * k >> 8), k - ((255 - cmyk[1]) * k >> 8),
          k - ((255 - cmyk[2]) * k >> 8)};
}

}  // namespace impactlab::imagefile::internal
