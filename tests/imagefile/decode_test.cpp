// Decoded pixels bit for bit as cv::imdecode gave them: PNG and TIFF as
// IMREAD_ANYDEPTH | IMREAD_ANYCOLOR (the photos), JPEG as IMREAD_COLOR and
// IMREAD_REDUCED_COLOR_2/4/8 (thumbnails).
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <png.h>
#include <tiffio.h>
#include <unistd.h>
#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>

#include "imagefile/image_file.h"

namespace impactlab {
namespace {

using imagefile::Bytes;
constexpr int kPhotoFlags = cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR;

// Gradients, a grid and noise in every channel: rows and columns differ, so
// a wrong orientation, row order or channel order shows.
cv::Mat Scene(int width, int height, int type) {
  cv::Mat out(height, width, type);
  cv::RNG rng(11);
  const int channels = CV_MAT_CN(type);
  const double top = CV_MAT_DEPTH(type) == CV_16U ? 65535.0 : 255.0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        const double grid = (x % 17 == 0 || y % 13 == 0) ? 0.3 : 0.0;
        const double v =
            (0.5 * x / width + 0.3 * y / height + 0.15 * c + grid) / 1.3 + rng.uniform(0.0, 0.05);
        const double value = std::min(top, v * top);
        if (CV_MAT_DEPTH(type) == CV_16U) {
          out.ptr<std::uint16_t>(y)[x * channels + c] = static_cast<std::uint16_t>(value);
        } else {
          out.ptr<std::uint8_t>(y)[x * channels + c] = static_cast<std::uint8_t>(value);
        }
      }
    }
  }
  return out;
}

void RequireIdentical(const cv::Mat& ours, const cv::Mat& reference) {
  REQUIRE_FALSE(reference.empty());
  REQUIRE(ours.type() == reference.type());
  REQUIRE(ours.size() == reference.size());
  CHECK(cv::norm(ours, reference, cv::NORM_INF) == 0.0);
}

// Our decode of `bytes` against OpenCV's, for a photo: the same pixels, or
// both fail (libtiff, read from memory as OpenCV read it, refuses some tiled
// files it reads from disk: the photo was refused before too).
bool CheckPhotoDecode(const Bytes& bytes, bool tiff) {
  cv::Mat ours;
  std::string error;
  const bool ok = tiff ? imagefile::DecodeTiff(bytes, &ours, &error)
                       : imagefile::DecodePng(bytes, &ours, &error);
  const cv::Mat reference = cv::imdecode(bytes, kPhotoFlags);
  INFO(error);
  CHECK(ok == !reference.empty());
  if (ok && !reference.empty()) RequireIdentical(ours, reference);
  return ok;
}

// ---------------------------------------------------------------------------
// PNGs of every colour type, written with libpng.

struct PngKind {
  int colour_type;
  int bit_depth;
  bool interlaced = false;
  bool transparency = false;  // a tRNS chunk
  int orientation = 0;        // an eXIf chunk with this orientation; 0: none
};

void AppendPng(png_structp png, png_bytep data, std::size_t size) {
  auto* out = static_cast<Bytes*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + size);
}

Bytes WritePng(const PngKind& kind, int width, int height) {
  Bytes out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  REQUIRE(setjmp(png_jmpbuf(png)) == 0);
  png_set_write_fn(png, &out, AppendPng, nullptr);
  png_set_IHDR(png, info, width, height, kind.bit_depth, kind.colour_type,
               kind.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_color palette[16];
  png_byte alphas[16];
  for (int i = 0; i < 16; ++i) {
    palette[i] = {static_cast<png_byte>(i * 16), static_cast<png_byte>(255 - i * 9),
                  static_cast<png_byte>(i * i)};
    alphas[i] = static_cast<png_byte>(255 - i * 10);
  }
  if (kind.colour_type == PNG_COLOR_TYPE_PALETTE) png_set_PLTE(png, info, palette, 16);
  png_color_16 grey_key{};
  grey_key.gray = 3;
  grey_key.red = 3;
  if (kind.transparency) {
    png_set_tRNS(png, info, alphas, kind.colour_type == PNG_COLOR_TYPE_PALETTE ? 16 : 0, &grey_key);
  }
  Bytes exif;
  if (kind.orientation > 0) {
    exif = {'I',
            'I',
            42,
            0,
            8,
            0,
            0,
            0,
            1,
            0,
            0x12,
            0x01,
            3,
            0,
            1,
            0,
            0,
            0,
            static_cast<unsigned char>(kind.orientation),
            0,
            0,
            0,
            0,
            0,
            0,
            0};
    png_set_eXIf_1(png, info, static_cast<png_uint_32>(exif.size()), exif.data());
  }
  png_write_info(png, info);
  const int channels = png_get_channels(png, info);
  const int sample_bits = kind.bit_depth;
  const std::size_t row_bytes = (std::size_t(width) * channels * sample_bits + 7) / 8;
  std::vector<png_byte> image(row_bytes * height);
  cv::RNG rng(5);
  for (std::size_t i = 0; i < image.size(); ++i) {
    image[i] = static_cast<png_byte>((i * 7 + i / row_bytes * 3) % 251 ^ rng.uniform(0, 4));
  }
  if (kind.colour_type == PNG_COLOR_TYPE_PALETTE) {
    const int per_byte = 8 / kind.bit_depth;
    for (auto& b : image) {  // indices below 16
      png_byte packed = 0;
      for (int k = 0; k < per_byte; ++k) {
        const int index = (b + k * 5) % std::min(16, 1 << kind.bit_depth);
        packed = static_cast<png_byte>(packed | index << (k * kind.bit_depth));
      }
      b = packed;
    }
  }
  std::vector<png_bytep> rows(height);
  for (int y = 0; y < height; ++y) rows[y] = image.data() + y * row_bytes;
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return out;
}

TEST_CASE("imagefile/PNG from OpenCV's encoder decodes as OpenCV decodes it") {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    INFO("type " << type);
    Bytes png;
    REQUIRE(cv::imencode(".png", Scene(131, 97, type), png));
    CheckPhotoDecode(png, false);
  }
}

TEST_CASE("imagefile/PNG of every colour type, depth and layout decodes as OpenCV decodes it") {
  const std::vector<PngKind> kinds = {
      {PNG_COLOR_TYPE_GRAY, 1},
      {PNG_COLOR_TYPE_GRAY, 2},
      {PNG_COLOR_TYPE_GRAY, 4},
      {PNG_COLOR_TYPE_GRAY, 8, false, true},
      {PNG_COLOR_TYPE_GRAY, 16, true},
      {PNG_COLOR_TYPE_GRAY_ALPHA, 8},
      {PNG_COLOR_TYPE_GRAY_ALPHA, 16},
      {PNG_COLOR_TYPE_PALETTE, 4},
      {PNG_COLOR_TYPE_PALETTE, 8, false, true},
      {PNG_COLOR_TYPE_PALETTE, 8, true},
      {PNG_COLOR_TYPE_RGB, 8, true},
      {PNG_COLOR_TYPE_RGB, 8, false, true},
      {PNG_COLOR_TYPE_RGB, 16},
      {PNG_COLOR_TYPE_RGB_ALPHA, 8},
      {PNG_COLOR_TYPE_RGB_ALPHA, 16, true},
  };
  for (const PngKind& kind : kinds) {
    INFO("colour type " << kind.colour_type << " depth " << kind.bit_depth << " interlaced "
                        << kind.interlaced << " tRNS " << kind.transparency);
    CheckPhotoDecode(WritePng(kind, 123, 45), false);
  }
}

TEST_CASE("imagefile/a PNG's eXIf orientation is applied as OpenCV applies it") {
  for (int orientation = 1; orientation <= 8; ++orientation) {
    INFO("orientation " << orientation);
    for (const int colour_type : {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_RGB}) {
      const Bytes png = WritePng({colour_type, 8, false, false, orientation}, 60, 40);
      CheckPhotoDecode(png, false);
      cv::Mat ours;
      std::string error;
      REQUIRE(imagefile::DecodePng(png, &ours, &error));
      CHECK(ours.cols == (orientation >= 5 ? 40 : 60));
    }
  }
}

TEST_CASE("imagefile/a damaged or cut PNG fails with libpng's message") {
  Bytes png;
  REQUIRE(cv::imencode(".png", Scene(200, 150, CV_8UC3), png));
  cv::Mat image;
  std::string error;
  Bytes cut(png.begin(), png.begin() + static_cast<std::ptrdiff_t>(png.size() / 2));
  CHECK_FALSE(imagefile::DecodePng(cut, &image, &error));
  CHECK(image.empty());
  CHECK_THAT(error, Catch::Contains("incomplete"));
  Bytes damaged = png;
  for (std::size_t i = png.size() / 2; i < png.size() / 2 + 16; ++i) damaged[i] ^= 0x5A;
  error.clear();
  CHECK_FALSE(imagefile::DecodePng(damaged, &image, &error));
  CHECK_FALSE(error.empty());
  CHECK(cv::imdecode(damaged, kPhotoFlags).empty());  // OpenCV failed it too
}

// ---------------------------------------------------------------------------
// TIFFs of the kinds OpenCV reads differently (RGBA interface for 8-bit
// output, strips or tiles as stored for 16-bit), written with libtiff.

struct TiffKind {
  int bits = 8;
  int samples = 1;
  int photometric = PHOTOMETRIC_MINISBLACK;
  int orientation = ORIENTATION_TOPLEFT;
  bool tiled = false;
  int compression = COMPRESSION_NONE;
  int sample_format = SAMPLEFORMAT_UINT;
  int rows_per_strip = 7;
};

Bytes WriteTiff(const TiffKind& kind, int width, int height) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("imagefile_test_" + std::to_string(::getpid()) + ".tif");
  TIFF* tif = TIFFOpen(path.c_str(), "w");
  REQUIRE(tif != nullptr);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, width);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, height);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, kind.bits);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, kind.samples);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, kind.photometric);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_ORIENTATION, kind.orientation);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, kind.compression);
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, kind.sample_format);
  if (kind.samples == 2 || kind.samples == 4) {
    const std::uint16_t extra = EXTRASAMPLE_UNASSALPHA;
    TIFFSetField(tif, TIFFTAG_EXTRASAMPLES, 1, &extra);
  }
  std::vector<std::uint16_t> map(std::size_t{1} << std::min(kind.bits, 16));
  if (kind.photometric == PHOTOMETRIC_PALETTE) {
    for (std::size_t i = 0; i < map.size(); ++i) map[i] = static_cast<std::uint16_t>(i * 4099);
    TIFFSetField(tif, TIFFTAG_COLORMAP, map.data(), map.data(), map.data());
  }
  const std::size_t row_bytes = (std::size_t(width) * kind.samples * kind.bits + 7) / 8;
  const auto value = [](std::size_t i, int y) {
    return static_cast<unsigned char>((i * 13 + y * 7 + (i * y) % 5) % 256);
  };
  if (kind.tiled) {
    constexpr int kTile = 16;
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, kTile);
    TIFFSetField(tif, TIFFTAG_TILELENGTH, kTile);
    std::vector<unsigned char> tile(static_cast<std::size_t>(TIFFTileSize(tif)));
    for (int ty = 0; ty < height; ty += kTile) {
      for (int tx = 0; tx < width; tx += kTile) {
        for (std::size_t i = 0; i < tile.size(); ++i) tile[i] = value(i + tx, ty + int(i / 40));
        REQUIRE(TIFFWriteTile(tif, tile.data(), tx, ty, 0, 0) >= 0);
      }
    }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, kind.rows_per_strip);
    std::vector<unsigned char> row(row_bytes);
    for (int y = 0; y < height; ++y) {
      for (std::size_t i = 0; i < row_bytes; ++i) row[i] = value(i, y);
      REQUIRE(TIFFWriteScanline(tif, row.data(), y, 0) == 1);
    }
  }
  TIFFClose(tif);
  std::ifstream in(path, std::ios::binary);
  Bytes bytes((std::istreambuf_iterator<char>(in)), {});
  std::filesystem::remove(path);
  return bytes;
}

TEST_CASE("imagefile/TIFF from OpenCV's encoder decodes as OpenCV decodes it") {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    INFO("type " << type);
    Bytes tiff;
    REQUIRE(cv::imencode(".tiff", Scene(131, 97, type), tiff));
    CheckPhotoDecode(tiff, true);
  }
}

TEST_CASE("imagefile/TIFF of other layouts, depths and orientations decodes as OpenCV decodes it") {
  std::vector<TiffKind> kinds = {
      {1, 1, PHOTOMETRIC_MINISBLACK},
      {1, 1, PHOTOMETRIC_MINISWHITE},
      {8, 1, PHOTOMETRIC_MINISWHITE},
      {8, 2, PHOTOMETRIC_MINISBLACK},
      {8, 1, PHOTOMETRIC_PALETTE},
      {8, 3, PHOTOMETRIC_RGB, ORIENTATION_TOPLEFT, true},
      {8, 3, PHOTOMETRIC_RGB, ORIENTATION_TOPLEFT, false, COMPRESSION_LZW},
      {8, 3, PHOTOMETRIC_RGB, ORIENTATION_TOPLEFT, false, COMPRESSION_ADOBE_DEFLATE},
      {16, 1, PHOTOMETRIC_MINISBLACK, ORIENTATION_TOPLEFT, true},
      {16, 3, PHOTOMETRIC_RGB, ORIENTATION_TOPLEFT, true},
      {16, 2, PHOTOMETRIC_MINISBLACK},
      {16, 3, PHOTOMETRIC_MINISBLACK},
      {12, 1, PHOTOMETRIC_MINISBLACK},
      {12, 3, PHOTOMETRIC_RGB},
      {10, 1, PHOTOMETRIC_MINISBLACK},
      {14, 4, PHOTOMETRIC_RGB},
  };
  for (int orientation = 1; orientation <= 8; ++orientation) {
    kinds.push_back({8, 1, PHOTOMETRIC_MINISBLACK, orientation});
    kinds.push_back({8, 3, PHOTOMETRIC_RGB, orientation, orientation % 2 == 0});
    kinds.push_back({16, 1, PHOTOMETRIC_MINISBLACK, orientation});
    kinds.push_back({16, 3, PHOTOMETRIC_RGB, orientation, orientation % 2 == 1});
  }
  std::size_t decoded = 0;
  for (const TiffKind& kind : kinds) {
    INFO("bits " << kind.bits << " samples " << kind.samples << " photometric " << kind.photometric
                 << " orientation " << kind.orientation << " tiled " << kind.tiled
                 << " compression " << kind.compression);
    if (CheckPhotoDecode(WriteTiff(kind, 50, 37), true)) ++decoded;
  }
  // Only 8-bit tiled ones fail, in both (libtiff's RGBA tiles from memory).
  CHECK(decoded + 6 >= kinds.size());
}

TEST_CASE("imagefile/TIFF samples that are not unsigned integers are refused by name") {
  for (const auto& [kind, what] :
       {std::pair{TiffKind{32, 1, PHOTOMETRIC_MINISBLACK, 1, false, COMPRESSION_NONE,
                           SAMPLEFORMAT_IEEEFP},
                  "32-bit floating point"},
        std::pair{
            TiffKind{16, 1, PHOTOMETRIC_MINISBLACK, 1, false, COMPRESSION_NONE, SAMPLEFORMAT_INT},
            "16-bit signed integers"},
        std::pair{TiffKind{4, 1, PHOTOMETRIC_MINISBLACK}, "4 bits per sample"}}) {
    INFO(what);
    cv::Mat image;
    std::string error;
    CHECK_FALSE(imagefile::DecodeTiff(WriteTiff(kind, 40, 30), &image, &error));
    CHECK_THAT(error, Catch::Contains(what));
  }
  cv::Mat image;
  std::string error;
  CHECK_FALSE(imagefile::DecodeTiff(Bytes{'I', 'I', 42, 0, 8, 0, 0, 0}, &image, &error));
  CHECK_FALSE(error.empty());
}

// ---------------------------------------------------------------------------
// JPEG in colour, full size and reduced.

Bytes ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

TEST_CASE("imagefile/JPEG in colour, full size and reduced, decodes as OpenCV decodes it") {
  std::vector<std::pair<std::string, Bytes>> jpegs;
  jpegs.emplace_back("sample photo", ReadFile(std::filesystem::path(IMPACTLAB_SOURCE_DIR) /
                                              "sample_data/thesis-photos/runs/0.405.jpg"));
  for (const int type : {CV_8UC1, CV_8UC3}) {
    Bytes jpeg;
    REQUIRE(cv::imencode(".jpg", Scene(333, 221, type), jpeg, {cv::IMWRITE_JPEG_QUALITY, 82}));
    jpegs.emplace_back("type " + std::to_string(type), jpeg);
  }
  for (const auto& [label, jpeg] : jpegs) {
    for (const auto& [denominator, flags] :
         {std::pair{1, int{cv::IMREAD_COLOR}}, std::pair{2, int{cv::IMREAD_REDUCED_COLOR_2}},
          std::pair{4, int{cv::IMREAD_REDUCED_COLOR_4}},
          std::pair{8, int{cv::IMREAD_REDUCED_COLOR_8}}}) {
      INFO(label << ", 1/" << denominator);
      cv::Mat ours;
      std::string error;
      REQUIRE(imagefile::DecodeJpegBgr(jpeg, denominator, &ours, &error));
      RequireIdentical(ours, cv::imdecode(jpeg, flags));
    }
  }
}

}  // namespace
}  // namespace impactlab
