// Photos that could cost unbounded memory or pass damaged: the header is
// read before decoding and a photo over the size limit refused; a JPEG the
// decoder warns about is refused; an intact JPEG decodes as OpenCV decodes it.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <jpeglib.h>  // after <cstdio>: it needs FILE
#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>

#include "digitize/digitize.h"
#include "imagefile/image_header.h"
#include "io/errors.h"

namespace impactlab {
namespace {

using Bytes = std::vector<unsigned char>;

Bytes ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

std::filesystem::path SamplePhoto(const std::string& name) {
  return std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-photos" / "runs" /
         name;
}

// A photo-like image: a gradient, a grid and noise, so a JPEG of it has
// entropy-coded data worth damaging.
cv::Mat Scene(int width, int height, int type) {
  cv::Mat grey(height, width, CV_8UC1);
  cv::RNG rng(7);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int grid = (x % 40 == 0 || y % 40 == 0) ? 120 : 0;
      grey.at<uchar>(y, x) = cv::saturate_cast<uchar>(x * 100 / width + grid + rng.uniform(0, 30));
    }
  }
  cv::Mat out;
  if (CV_MAT_CN(type) == 3) {
    cv::Mat channels[] = {grey, 255 - grey, grey / 2};
    cv::merge(channels, 3, out);
  } else if (CV_MAT_CN(type) == 4) {
    cv::Mat channels[] = {grey, 255 - grey, grey / 2, cv::Mat(height, width, CV_8UC1, 255)};
    cv::merge(channels, 4, out);
  } else {
    out = grey;
  }
  if (CV_MAT_DEPTH(type) == CV_16U) out.convertTo(out, CV_MAKETYPE(CV_16U, out.channels()), 257);
  return out;
}

Bytes Encode(const std::string& extension, const cv::Mat& image, std::vector<int> params = {}) {
  Bytes bytes;
  REQUIRE(cv::imencode(extension, image, bytes, params));
  return bytes;
}

imagefile::ImageHeader Header(const Bytes& bytes) {
  imagefile::ImageHeader header;
  std::string error;
  INFO(error);
  REQUIRE(imagefile::ReadImageHeader(bytes, &header, &error));
  return header;
}

std::uint32_t Crc32(const unsigned char* data, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void PutBe32(Bytes& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<unsigned char>(v >> shift));
}

void PngChunk(Bytes& out, const char* type, const Bytes& data) {
  PutBe32(out, static_cast<std::uint32_t>(data.size()));
  Bytes typed(type, type + 4);
  typed.insert(typed.end(), data.begin(), data.end());
  out.insert(out.end(), typed.begin(), typed.end());
  PutBe32(out, Crc32(typed.data(), typed.size()));
}

// A valid PNG signature and IHDR declaring width x height 8-bit grey, a tiny
// IDAT (an empty zlib stream) and IEND: a few dozen bytes.
Bytes PngDeclaring(std::uint32_t width, std::uint32_t height) {
  Bytes png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  Bytes ihdr;
  PutBe32(ihdr, width);
  PutBe32(ihdr, height);
  ihdr.insert(ihdr.end(), {8, 0, 0, 0, 0});
  PngChunk(png, "IHDR", ihdr);
  PngChunk(png, "IDAT", {0x78, 0x9C, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01});
  PngChunk(png, "IEND", {});
  return png;
}

// The offset of the first byte of entropy-coded data (after SOS's header).
std::size_t ScanDataStart(const Bytes& jpeg) {
  for (std::size_t i = 2; i + 3 < jpeg.size();) {
    REQUIRE(jpeg[i] == 0xFF);
    const unsigned marker = jpeg[i + 1];
    const std::size_t length = std::size_t{jpeg[i + 2]} << 8 | jpeg[i + 3];
    if (marker == 0xDA) return i + 2 + length;
    i += 2 + length;
  }
  FAIL("no SOS");
  return 0;
}

// Overwrites `count` bytes from `at` with a pattern that holds no 0xFF (so
// no marker is made up): what a bad sector or a flipped block does.
Bytes Damaged(Bytes bytes, std::size_t at, std::size_t count) {
  for (std::size_t i = at; i < at + count && i < bytes.size(); ++i) {
    bytes[i] = static_cast<unsigned char>(i * 37 % 251);
  }
  return bytes;
}

std::string RefusalOf(const Bytes& bytes, const std::filesystem::path& source) {
  try {
    DecodePhoto(bytes, source);
  } catch (const InputError& e) {
    CHECK(e.where().file == source);
    return e.what();
  }
  FAIL("the photo was not refused");
  return "";
}

double MaxDifference(const cv::Mat& a, const cv::Mat& b) {
  REQUIRE(a.size() == b.size());
  REQUIRE(a.type() == b.type());
  double difference = 0.0;
  cv::minMaxLoc(cv::abs(a - b), nullptr, &difference);
  return difference;
}

TEST_CASE("photo_safety: the header reader gives the size, depth and channels of PNG and TIFF") {
  for (const int depth : {CV_8U, CV_16U}) {
    for (const int channels : {1, 3, 4}) {
      const cv::Mat image = Scene(123, 77, CV_MAKETYPE(depth, channels));
      for (const std::string extension : {".png", ".tiff"}) {
        INFO(extension << " depth " << depth << " channels " << channels);
        const imagefile::ImageHeader h = Header(Encode(extension, image));
        CHECK(h.format ==
              (extension == ".png" ? imagefile::ImageFormat::kPng : imagefile::ImageFormat::kTiff));
        CHECK(h.width == 123);
        CHECK(h.height == 77);
        CHECK(h.bits_per_sample == (depth == CV_8U ? 8 : 16));
        CHECK(h.channels == channels);
      }
    }
  }
}

TEST_CASE("photo_safety: the header reader walks a JPEG's segments to its frame header") {
  for (const int channels : {1, 3}) {
    for (const bool progressive : {false, true}) {
      INFO("channels " << channels << " progressive " << progressive);
      const Bytes jpeg = Encode(".jpg", Scene(321, 123, CV_MAKETYPE(CV_8U, channels)),
                                {cv::IMWRITE_JPEG_PROGRESSIVE, progressive ? 1 : 0});
      const imagefile::ImageHeader h = Header(jpeg);
      CHECK(h.format == imagefile::ImageFormat::kJpeg);
      CHECK(h.width == 321);
      CHECK(h.height == 123);
      CHECK(h.bits_per_sample == 8);
      CHECK(h.channels == channels);
    }
  }
  // A sample photo, whose JFIF segment comes before the frame header.
  const imagefile::ImageHeader h = Header(ReadFile(SamplePhoto("0.405.jpg")));
  CHECK(h.width == 2000);
  CHECK(h.height == 1500);
  CHECK(h.channels == 3);
}

TEST_CASE("photo_safety: the header reader reads big-endian TIFF and BigTIFF") {
  // Big-endian classic TIFF: IFD at 8 with ImageWidth (SHORT) 300,
  // ImageLength (LONG) 200, BitsPerSample 3 x 16 (at offset 62),
  // SamplesPerPixel 3.
  Bytes be = {'M', 'M', 0, 42, 0, 0, 0, 8, 0, 4};
  const auto entry = [](Bytes& b, unsigned tag, unsigned type, std::uint32_t count,
                        std::uint32_t value, bool short_value) {
    b.insert(b.end(), {static_cast<unsigned char>(tag >> 8), static_cast<unsigned char>(tag), 0,
                       static_cast<unsigned char>(type)});
    PutBe32(b, count);
    if (short_value) {
      b.insert(b.end(),
               {static_cast<unsigned char>(value >> 8), static_cast<unsigned char>(value), 0, 0});
    } else {
      PutBe32(b, value);
    }
  };
  entry(be, 256, 3, 1, 300, true);
  entry(be, 257, 4, 1, 200, false);
  entry(be, 258, 3, 3, 62, false);
  entry(be, 277, 3, 1, 3, true);
  PutBe32(be, 0);  // no next IFD
  REQUIRE(be.size() == 62);
  be.insert(be.end(), {0, 16, 0, 16, 0, 16});
  imagefile::ImageHeader h = Header(be);
  CHECK(h.format == imagefile::ImageFormat::kTiff);
  CHECK(h.width == 300);
  CHECK(h.height == 200);
  CHECK(h.bits_per_sample == 16);
  CHECK(h.channels == 3);

  // Little-endian BigTIFF: IFD at 16, two LONG8 entries.
  Bytes big = {'I', 'I', 43, 0, 8, 0, 0, 0, 16, 0, 0, 0, 0, 0, 0, 0};
  const auto le = [](Bytes& b, std::uint64_t v, int size) {
    for (int i = 0; i < size; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
  };
  le(big, 2, 8);
  for (const auto& [tag, value] : {std::pair<unsigned, std::uint64_t>{256, 40000},
                                   std::pair<unsigned, std::uint64_t>{257, 30000}}) {
    le(big, tag, 2);
    le(big, 16, 2);  // LONG8
    le(big, 1, 8);
    le(big, value, 8);
  }
  le(big, 0, 8);
  h = Header(big);
  CHECK(h.width == 40000);
  CHECK(h.height == 30000);
  CHECK(h.bits_per_sample == 1);  // TIFF's default
  // 1200 Mpx: refused before decoding.
  CHECK_THAT(RefusalOf(big, "big.tif"), Catch::Contains("40000x30000"));
}

TEST_CASE("photo_safety: unreadable headers are refused, naming the file") {
  const Bytes jpeg = Encode(".jpg", Scene(200, 150, CV_8UC1));
  CHECK_THAT(RefusalOf(Bytes(jpeg.begin(), jpeg.begin() + 40), "cut.jpg"),
             Catch::Contains("cut.jpg") && Catch::Contains("JPEG"));
  CHECK_THAT(RefusalOf({'G', 'I', 'F', '8', '9', 'a', 0, 0}, "a.gif"),
             Catch::Contains("not a PNG, JPEG or TIFF"));
  Bytes png = PngDeclaring(0, 500);
  CHECK_THAT(RefusalOf(png, "zero.png"), Catch::Contains("0x500"));
  png = Encode(".png", Scene(200, 150, CV_8UC1));
  png[11] = 14;  // IHDR's length
  CHECK_THAT(RefusalOf(png, "ihdr.png"), Catch::Contains("IHDR"));
}

TEST_CASE("photo_safety: a PNG declaring 32000 x 32000 pixels is refused fast") {
  const Bytes bomb = PngDeclaring(32000, 32000);
  CHECK(bomb.size() < 100);
  const auto start = std::chrono::steady_clock::now();
  const std::string message = RefusalOf(bomb, "runs/bomb.png");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(seconds < 1.0);
  CHECK_THAT(message, Catch::Contains("runs/bomb.png") && Catch::Contains("32000x32000") &&
                          Catch::Contains("100 megapixels"));
  // Just under the limit on one side and far over in area, too.
  CHECK_THAT(RefusalOf(PngDeclaring(10000, 10001), "b.png"), Catch::Contains("10000x10001"));
}

TEST_CASE("photo_safety: a JPEG whose frame header declares 65000 x 65000 is refused fast") {
  Bytes jpeg = Encode(".jpg", Scene(200, 150, CV_8UC1));
  // Patch the SOF0 frame header's lines and samples per line.
  for (std::size_t i = 2; i + 9 < jpeg.size();) {
    const std::size_t length = std::size_t{jpeg[i + 2]} << 8 | jpeg[i + 3];
    if (jpeg[i + 1] == 0xC0) {
      jpeg[i + 5] = jpeg[i + 7] = 0xFD;
      jpeg[i + 6] = jpeg[i + 8] = 0xE8;
      break;
    }
    i += 2 + length;
  }
  const auto start = std::chrono::steady_clock::now();
  CHECK_THAT(RefusalOf(jpeg, "huge.jpg"), Catch::Contains("65000x65000"));
  CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < 1.0);
}

TEST_CASE("photo_safety: a JPEG with its scan data overwritten is refused, naming the file") {
  const Bytes intact = ReadFile(SamplePhoto("0.405.jpg"));
  const std::size_t scan = ScanDataStart(intact);
  // Damage libjpeg notices (not all does: where the Huffman code
  // resynchronises it decodes on without a warning; docs/digitizing.md).
  const Bytes damaged = Damaged(intact, scan + (intact.size() - scan) / 2, 256);
  // What passed before: OpenCV decodes it (and prints libjpeg's warning).
  CHECK_FALSE(cv::imdecode(damaged, cv::IMREAD_GRAYSCALE).empty());
  const std::string message = RefusalOf(damaged, "runs/0.405.jpg");
  CHECK_THAT(message, Catch::Contains("runs/0.405.jpg") && Catch::Contains("damaged") &&
                          Catch::Contains("Corrupt JPEG data"));

  // A JPEG cut short with its end marker kept (CheckComplete sees an EOI).
  Bytes cut(intact.begin(), intact.begin() + static_cast<std::ptrdiff_t>(intact.size() * 2 / 3));
  cut.insert(cut.end(), {0xFF, 0xD9});
  CHECK_THAT(RefusalOf(cut, "cut.jpg"), Catch::Contains("cut.jpg") && Catch::Contains("JPEG"));

  // A small synthetic one, damaged near the start of its scan.
  const Bytes small = Encode(".jpg", Scene(640, 480, CV_8UC3), {cv::IMWRITE_JPEG_QUALITY, 90});
  CHECK_THAT(RefusalOf(Damaged(small, ScanDataStart(small) + 500, 64), "small.jpg"),
             Catch::Contains("small.jpg"));
}

TEST_CASE("photo_safety: a PNG with damaged image data is refused") {
  const Bytes png = Encode(".png", Scene(400, 300, CV_8UC3));
  CHECK_THAT(RefusalOf(Damaged(png, png.size() / 2, 16), "flip.png"),
             Catch::Contains("flip.png") && Catch::Contains("cannot decode the PNG"));
}

TEST_CASE("photo_safety: intact JPEGs decode as OpenCV decodes them") {
  // The sample session's run photos (baseline 4:2:0 colour).
  for (const char* name : {"0.115.jpg", "0.405.jpg", "1.519.jpg"}) {
    INFO(name);
    const Bytes bytes = ReadFile(SamplePhoto(name));
    const Photo photo = DecodePhoto(bytes, name);
    CHECK(photo.source == name);
    CHECK(MaxDifference(photo.image, cv::imdecode(bytes, cv::IMREAD_GRAYSCALE)) == 0.0);
    CHECK(MaxDifference(LoadPhoto(SamplePhoto(name)).image, photo.image) == 0.0);
  }
  // Grey, colour, progressive, 4:4:4.
  const cv::Mat colour = Scene(333, 222, CV_8UC3);
  for (const auto& [label, bytes] :
       {std::pair{"grey", Encode(".jpg", Scene(333, 222, CV_8UC1))},
        std::pair{"colour", Encode(".jpg", colour)},
        std::pair{"progressive", Encode(".jpg", colour, {cv::IMWRITE_JPEG_PROGRESSIVE, 1})},
        std::pair{"4:4:4", Encode(".jpg", colour,
                                  {cv::IMWRITE_JPEG_LUMA_QUALITY, 90,
                                   cv::IMWRITE_JPEG_CHROMA_QUALITY, 80})}}) {
    INFO(label);
    CHECK(MaxDifference(DecodePhoto(bytes, "x.jpg").image,
                        cv::imdecode(bytes, cv::IMREAD_GRAYSCALE)) == 0.0);
  }
}

// A CMYK JPEG (as some print workflows write them), by libjpeg itself:
// OpenCV writes none.
Bytes EncodeCmykJpeg(int width, int height, J_COLOR_SPACE stored) {
  jpeg_compress_struct cinfo;
  jpeg_error_mgr error;
  cinfo.err = jpeg_std_error(&error);
  jpeg_create_compress(&cinfo);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = static_cast<JDIMENSION>(width);
  cinfo.image_height = static_cast<JDIMENSION>(height);
  cinfo.input_components = 4;
  cinfo.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&cinfo);
  jpeg_set_colorspace(&cinfo, stored);
  jpeg_set_quality(&cinfo, 90, TRUE);
  jpeg_start_compress(&cinfo, TRUE);
  std::vector<unsigned char> row(static_cast<std::size_t>(width) * 4);
  while (cinfo.next_scanline < cinfo.image_height) {
    const int y = static_cast<int>(cinfo.next_scanline);
    for (int x = 0; x < width; ++x) {
      row[4 * x + 0] = static_cast<unsigned char>(x * 2);
      row[4 * x + 1] = static_cast<unsigned char>(y * 3);
      row[4 * x + 2] = static_cast<unsigned char>(x + y);
      row[4 * x + 3] = static_cast<unsigned char>(128 + x % 64);
    }
    JSAMPROW pointer = row.data();
    jpeg_write_scanlines(&cinfo, &pointer, 1);
  }
  jpeg_finish_compress(&cinfo);
  Bytes bytes(buffer, buffer + size);
  std::free(buffer);
  jpeg_destroy_compress(&cinfo);
  return bytes;
}

TEST_CASE("photo_safety: a CMYK or YCCK JPEG decodes to the grey OpenCV gave") {
  for (const J_COLOR_SPACE stored : {JCS_CMYK, JCS_YCCK}) {
    INFO("stored as " << (stored == JCS_CMYK ? "CMYK" : "YCCK"));
    const Bytes jpeg = EncodeCmykJpeg(200, 150, stored);
    const imagefile::ImageHeader h = Header(jpeg);
    CHECK(h.channels == 4);
    const cv::Mat ours = DecodePhoto(jpeg, "cmyk.jpg").image;
    CHECK(ours.type() == CV_8UC1);
    CHECK(MaxDifference(ours, cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE)) == 0.0);
  }
}

TEST_CASE("photo_safety: a JPEG's EXIF orientation is applied as OpenCV applies it") {
  const Bytes plain = Encode(".jpg", Scene(240, 160, CV_8UC1), {cv::IMWRITE_JPEG_QUALITY, 95});
  const std::size_t after_app0 = 4 + (std::size_t{plain[4]} << 8 | plain[5]);
  for (unsigned char orientation = 1; orientation <= 8; ++orientation) {
    INFO("orientation " << int{orientation});
    Bytes app1 = {0xFF, 0xE1, 0, 0, 'E',         'x', 'i', 'f', 0,    0,    'I', 'I',
                  42,   0,    8, 0, 0,           0,   1,   0,   0x12, 0x01, 3,   0,
                  1,    0,    0, 0, orientation, 0,   0,   0,   0,    0,    0,   0};
    app1[3] = static_cast<unsigned char>(app1.size() - 2);
    Bytes jpeg = plain;
    jpeg.insert(jpeg.begin() + static_cast<std::ptrdiff_t>(after_app0), app1.begin(), app1.end());
    CHECK(imagefile::ReadJpegExifOrientation(jpeg) == orientation);
    const cv::Mat ours = DecodePhoto(jpeg, "o.jpg").image;
    CHECK(ours.cols == (orientation >= 5 ? 160 : 240));
    CHECK(MaxDifference(ours, cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE)) == 0.0);
  }
}

TEST_CASE("photo_safety: PNG and TIFF still decode as they are, 8 and 16 bit") {
  for (const int type : {CV_8UC1, CV_8UC3, CV_16UC1, CV_16UC3}) {
    for (const std::string extension : {".png", ".tiff"}) {
      INFO(extension << " type " << type);
      const cv::Mat image = Scene(150, 120, type);
      const Photo photo = DecodePhoto(Encode(extension, image), "p" + extension);
      CHECK(MaxDifference(photo.image, image) == 0.0);
    }
  }
}

}  // namespace
}  // namespace impactlab
