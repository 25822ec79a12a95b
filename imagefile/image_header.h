// What a PNG, JPEG or TIFF file declares about its image, read from the
// header alone, before anything is decoded: a decoder allocates what the
// header declares, so a 3 MB PNG that declares 32000 x 32000 pixels would
// cost 3 GB and most of a minute. LoadPhoto/DecodePhoto (digitize/) refuse
// such a photo from these numbers instead.
//
// Formats: PNG (the IHDR chunk, PNG spec. 11.2.2), JPEG (the first SOFn
// frame header, found by walking the marker segments; ITU T.81 B.2.2),
// TIFF (the first IFD, either byte order, classic and BigTIFF; TIFF 6.0
// section 2). Also the EXIF orientation a JPEG's APP1 segment may carry
// (EXIF 2.3, tag 0x0112) or a PNG's eXIf chunk may carry, since a photo
// decoded by hand must be turned as OpenCV would turn it.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace impactlab::imagefile {

enum class ImageFormat { kPng, kJpeg, kTiff };

const char* ImageFormatName(ImageFormat format);  // "PNG", "JPEG", "TIFF"

struct ImageHeader {
  ImageFormat format = ImageFormat::kPng;
  std::uint64_t width = 0;   // pixels, as declared
  std::uint64_t height = 0;  // pixels, as declared
  int bits_per_sample = 0;   // as declared (PNG 1-16, JPEG 8 or 12, TIFF BitsPerSample)
  int channels = 0;          // samples per pixel as stored (PNG: 1 for a palette)
};

// True when the declared size exceeds `max_pixels` (no overflow for any
// declared sides, BigTIFF's 64-bit ones included).
inline bool ExceedsPixels(const ImageHeader& h, std::uint64_t max_pixels) {
  return h.width > max_pixels || h.height > max_pixels || h.width * h.height > max_pixels;
}

// Reads the header of `bytes`. Returns false, with the reason in *error,
// when the bytes are not a PNG, JPEG or TIFF, or the header is cut short,
// inconsistent or declares a zero size. Reads nothing past the header (for
// a JPEG, the marker segments before the first frame header; for a TIFF,
// the first IFD and the BitsPerSample values it points to) and never
// allocates in proportion to the declared size.
bool ReadImageHeader(std::span<const unsigned char> bytes, ImageHeader* header, std::string* error);

// The EXIF orientation (1-8) of a JPEG's first APP1 "Exif" segment, or 1
// (as stored) when there is none or it cannot be read.
int ReadJpegExifOrientation(std::span<const unsigned char> bytes);

// The orientation (1-8) in the first IFD of an EXIF block (a TIFF header and
// its IFDs, as after a JPEG APP1's "Exif\0\0" or in a PNG's eXIf chunk), or
// 1 when there is none or it cannot be read.
int ReadExifOrientation(std::span<const unsigned char> tiff_block);

}  // namespace impactlab::imagefile
