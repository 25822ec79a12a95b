// Image files decoded and encoded with libjpeg(-turbo), libpng and libtiff
// directly, giving the pixels and the bytes OpenCV's imgcodecs gave (the
// tests compare them with cv::imdecode and cv::imencode), without loading
// OpenCV's codec module: on Debian it links some 140 shared libraries (GDAL,
// GDCM, libheif, Poppler, ...), which cost every command most of its start.
//
// Pixels are cv::Mat as OpenCV has them: 8 or 16 bit, grey, BGR or BGRA. The
// decoders read bytes already in memory and return false with the decoder's
// own message in *error when the bytes cannot be decoded (no C++ exception
// passes through a codec's C frames). They allocate what the header
// declares: a caller bounds that first (imagefile/image_header.h).
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace impactlab::imagefile {

using Bytes = std::vector<unsigned char>;

// ---------------------------------------------------------------------------
// Decoding

// A PNG or a TIFF as cv::imdecode(bytes, IMREAD_ANYDEPTH | IMREAD_ANYCOLOR)
// decoded it: 8 or 16 bit as stored (a TIFF of 10-14 bit scaled to 16),
// grey stays grey (CV_8UC1/CV_16UC1), anything else becomes BGR (alpha
// dropped, a palette expanded), turned as the PNG's eXIf chunk or the TIFF's
// Orientation tag says. A TIFF whose samples are not unsigned integers of 1,
// 8 or 10-16 bit is refused with a message saying what they are.
bool DecodePng(std::span<const unsigned char> bytes, cv::Mat* image, std::string* error);
bool DecodeTiff(std::span<const unsigned char> bytes, cv::Mat* image, std::string* error);

// Progressive JPEGs with more scans than this are refused: a few hundred
// bytes per scan can make the decoder redo the whole image each time (the
// "scan bomb"); real encoders write at most a few dozen.
constexpr int kMaxJpegScans = 1000;

// A JPEG as cv::imdecode(bytes, IMREAD_GRAYSCALE) decoded it, turned as its
// EXIF orientation says: for YCbCr or grey JPEGs the luma plane itself (no
// colour upsampling or conversion is done), for RGB ones libjpeg's BT.601
// luma, for CMYK/YCCK the luma of OpenCV's CMYK-to-BGR conversion. Strict,
// for photos: any warning libjpeg gives about the image data ("Corrupt JPEG
// data: ...", "Premature end of JPEG file"; OpenCV printed these and
// returned the filled-in image) fails the decode with libjpeg's message, as
// do more than kMaxJpegScans scans. An unknown JFIF version (metadata only)
// passes.
bool DecodeJpegGrey(std::span<const unsigned char> bytes, cv::Mat* grey, std::string* error);

// A JPEG as BGR, as cv::imdecode(bytes, IMREAD_COLOR) decoded it, or with
// `scale_denom` 2, 4 or 8 as IMREAD_REDUCED_COLOR_2/4/8 did: libjpeg scales
// while it decodes (each side rounded up), which costs a fraction of a full
// decode. For JPEGs this program wrote (thumbnails, a rendered photo's
// round trip): libjpeg's warnings pass, as they did through OpenCV.
bool DecodeJpegBgr(std::span<const unsigned char> bytes, int scale_denom, cv::Mat* bgr,
                   std::string* error);

// ---------------------------------------------------------------------------
// Encoding: the bytes cv::imencode wrote, byte for byte. Each takes an 8-bit
// image (PNG and TIFF 16-bit too) of 1, 3 (BGR) or 4 (BGRA) channels and
// returns false with the reason otherwise.

// Baseline JPEG at `quality` (0-100; OpenCV's default was 95), 4:2:0; a
// BGRA image loses its alpha, a grey one is stored grey.
bool EncodeJpeg(const cv::Mat& image, int quality, Bytes* bytes, std::string* error);

// PNG at zlib `compression` level 0-9 (libpng's adaptive filters, zlib's
// default strategy), or with compression -1 OpenCV's default, tuned for
// speed: the Sub filter, level 1, run-length strategy.
bool EncodePng(const cv::Mat& image, int compression, Bytes* bytes, std::string* error);

// TIFF as OpenCV wrote it: LZW with the horizontal predictor, strips of
// about 8 kB, RGB or grey (BGR and BGRA images stored as RGB and RGBA).
bool EncodeTiff(const cv::Mat& image, Bytes* bytes, std::string* error);

// What cv::imwrite(path, image, params) wrote, chosen by the file's
// extension (any case): ".png", ".jpg"/".jpeg" at `jpeg_quality`, ".tif"/
// ".tiff". Returns false with the reason for any other extension.
struct EncodeOptions {
  int jpeg_quality = 95;     // JPEG quality, 0-100 (OpenCV's default 95)
  int png_compression = -1;  // zlib level 0-9; -1: OpenCV's default (see EncodePng)
};
bool EncodeForExtension(std::string_view extension, const cv::Mat& image,
                        const EncodeOptions& options, Bytes* bytes, std::string* error);

// ---------------------------------------------------------------------------
// Orientation

// Turns `image` as an EXIF/TIFF orientation (1-8) says, as OpenCV did
// (loadsave.cpp's ExifTransform); other values leave it as it is.
void ApplyExifOrientation(int orientation, cv::Mat& image);

}  // namespace impactlab::imagefile
