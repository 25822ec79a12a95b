// TIFF decoding with libtiff directly, read the way OpenCV's decoder read it
// (imgcodecs/grfmt_tiff.cpp), so the pixels are the same: 8-bit output
// through libtiff's RGBA interface (any photometric, compression or
// layout it handles), 16-bit output from the strips or tiles as stored.
#include <algorithm>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <tiffio.h>

#include "imagefile/image_file.h"
#include "imagefile/imagefile_internal.h"

namespace impactlab::imagefile {
namespace {

// The bytes libtiff reads through its client procedures, clamped to the
// buffer as OpenCV's were; and libtiff's first error message.
struct TiffSource {
  std::span<const unsigned char> bytes;
  toff_t position = 0;
  std::string message;
};

tmsize_t TiffReadProc(thandle_t handle, void* out, tmsize_t size) {
  auto* s = static_cast<TiffSource*>(handle);
  const toff_t left = s->bytes.size() - s->position;
  const toff_t n = std::min<toff_t>(static_cast<toff_t>(size), left);
  std::memcpy(out, s->bytes.data() + s->position, n);
  s->position += n;
  return static_cast<tmsize_t>(n);
}

tmsize_t TiffWriteNothing(thandle_t, void*, tmsize_t) { return 0; }

toff_t TiffSeekProc(thandle_t handle, toff_t offset, int whence) {
  auto* s = static_cast<TiffSource*>(handle);
  toff_t position = s->position;
  if (whence == SEEK_SET) position = offset;
  if (whence == SEEK_CUR) position += offset;
  if (whence == SEEK_END) position = s->bytes.size() + offset;
  s->position = std::min<toff_t>(position, s->bytes.size());
  return s->position;
}

int TiffCloseNothing(thandle_t) { return 0; }

toff_t TiffSizeProc(thandle_t handle) { return static_cast<TiffSource*>(handle)->bytes.size(); }

// libtiff's errors are kept (the first one says most); warnings pass, as
// OpenCV let them pass. Returning 1 keeps libtiff's global handlers (stderr)
// out of it.
int TiffOnError(TIFF*, void* user_data, const char* module, const char* format, va_list ap) {
  auto* s = static_cast<TiffSource*>(user_data);
  if (s->message.empty()) {
    char text[512];
    std::vsnprintf(text, sizeof text, format, ap);
    s->message = module != nullptr && *module != '\0' ? fmt::format("{}: {}", module, text) : text;
  }
  return 1;
}

int TiffOnWarning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

struct TiffCloser {
  TIFF* tif = nullptr;
  ~TiffCloser() {
    if (tif != nullptr) TIFFClose(tif);
  }
};

struct TiffOptionsFreer {
  TIFFOpenOptions* options;
  ~TiffOptionsFreer() { TIFFOpenOptionsFree(options); }
};

// What the header says, and the pixel type OpenCV's decoder made of it.
struct TiffLayoutRead {
  std::uint32_t width = 0, height = 0;
  std::uint16_t photometric = 0;
  bool grey = false;          // MinIsWhite or MinIsBlack
  std::uint16_t bits = 8;     // BitsPerSample as stored
  std::uint16_t samples = 1;  // SamplesPerPixel as stored
  int depth = CV_8U;          // of the decoded image
  int channels = 1;           // of the decoded image (IMREAD_ANYCOLOR: 1 or 3)
};

// OpenCV's TiffDecoder::readHeader, for IMREAD_ANYDEPTH | IMREAD_ANYCOLOR.
// Sample kinds OpenCV decoded to types the photo refuses (signed, floating
// point) are refused here, saying what they are.
bool TiffReadLayout(TIFF* tif, TiffLayoutRead* t, std::string* error) {
  if (TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &t->width) == 0 ||
      TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &t->height) == 0 ||
      TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &t->photometric) == 0) {
    *error = "the TIFF has no ImageWidth, ImageLength or PhotometricInterpretation";
    return false;
  }
  t->grey = t->photometric == PHOTOMETRIC_MINISWHITE || t->photometric == PHOTOMETRIC_MINISBLACK;
  t->samples = t->grey ? 1 : 3;
  if (TIFFGetField(tif, TIFFTAG_BITSPERSAMPLE, &t->bits) == 0) t->bits = 1;  // bi-level
  TIFFGetField(tif, TIFFTAG_SAMPLESPERPIXEL, &t->samples);
  if (t->samples == 3 && t->photometric == PHOTOMETRIC_LOGLUV) {
    *error = "its samples are LogLuv floating point, not 8 or 16 bit unsigned integers";
    return false;
  }
  std::uint16_t bits = t->bits;
  if (bits > 8 && (t->photometric > 2 || (t->samples != 1 && t->samples != 3 && t->samples != 4))) {
    bits = 8;  // read through the RGBA interface, as 8 bit
  }
  std::uint16_t format = SAMPLEFORMAT_UINT;
  TIFFGetField(tif, TIFFTAG_SAMPLEFORMAT, &format);
  if (t->samples < 1 || t->samples > 4) {
    *error = fmt::format("it has {} samples per pixel; 1 to 4 are read", t->samples);
    return false;
  }
  const auto refuse = [&](const std::string& kind) {
    *error = fmt::format("its samples are {}, not 8 or 16 bit unsigned integers", kind);
    return false;
  };
  int channels = t->grey ? 1 : t->samples;
  switch (bits) {
    case 1:
    case 8:
    case 10:
    case 12:
    case 14:
    case 16:
      if (format == SAMPLEFORMAT_INT) return refuse(fmt::format("{}-bit signed integers", bits));
      if (format != SAMPLEFORMAT_UINT) {
        *error = fmt::format("its {}-bit samples have SampleFormat {}", bits, format);
        return false;
      }
      t->depth = bits <= 8 ? CV_8U : CV_16U;
      if (bits == 8 && t->photometric == PHOTOMETRIC_PALETTE) channels = 3;
      break;
    case 32:
      if (format == SAMPLEFORMAT_IEEEFP) return refuse("32-bit floating point");
      if (format == SAMPLEFORMAT_INT) return refuse("32-bit signed integers");
      *error = fmt::format("its 32-bit samples have SampleFormat {}", format);
      return false;
    case 64:
      if (format == SAMPLEFORMAT_IEEEFP) return refuse("64-bit floating point");
      *error = fmt::format("its 64-bit samples have SampleFormat {}", format);
      return false;
    default:
      *error = fmt::format("it has {} bits per sample; 1, 8, 10, 12, 14, 16 are read", bits);
      return false;
  }
  t->channels = channels > 1 ? 3 : 1;
  return true;
}

// `count` samples of `bits` bits each, packed most significant bit first
// from `in`, widened to 16 bit (OpenCV's _unpack10To16 and its kin).
void UnpackSamples(const unsigned char* in, int bits, std::size_t count, std::uint16_t* out) {
  std::uint32_t buffer = 0;
  int held = 0;
  for (std::size_t i = 0; i < count; ++i) {
    while (held < bits) {
      buffer = buffer << 8 | *in++;
      held += 8;
    }
    held -= bits;
    out[i] = static_cast<std::uint16_t>((buffer >> held) & ((1u << bits) - 1));
  }
}

// One row of 16-bit samples (`samples` a pixel, RGB(A) or grey) into the
// image's row: BGR or grey, as OpenCV's icvCvt_* functions made it.
void Put16BitRow(const std::uint16_t* in, int samples, int width, int channels,
                 std::uint16_t* out) {
  if (channels == 1 && samples == 1) {
    std::memcpy(out, in, static_cast<std::size_t>(width) * sizeof *out);
    return;
  }
  for (int x = 0; x < width; ++x, in += samples) {
    if (channels == 1) {
      out[x] = static_cast<std::uint16_t>(internal::LumaOf(in[0], in[1], in[2]));
    } else if (samples == 1) {
      out[3 * x] = out[3 * x + 1] = out[3 * x + 2] = in[0];
    } else {
      out[3 * x] = in[2];
      out[3 * x + 1] = in[1];
      out[3 * x + 2] = in[0];
    }
  }
}

// One row of libtiff's RGBA pixels (R, G, B, A bytes) into the image's row.
void PutRgbaRow(const unsigned char* in, int width, int channels, unsigned char* out) {
  for (int x = 0; x < width; ++x, in += 4) {
    if (channels == 1) {
      out[x] = static_cast<unsigned char>(internal::LumaOf(in[0], in[1], in[2]));
    } else {
      out[3 * x] = in[2];
      out[3 * x + 1] = in[1];
      out[3 * x + 2] = in[0];
    }
  }
}

// OpenCV's TiffDecoder::readData into `image` (sized and typed from the
// layout).
bool TiffReadPixels(TIFF* tif, const TiffLayoutRead& t, cv::Mat& image, std::string* error) {
  const bool tiled = TIFFIsTiled(tif) != 0;
  std::uint16_t orientation = ORIENTATION_TOPLEFT;
  TIFFGetField(tif, TIFFTAG_ORIENTATION, &orientation);
  const int out_bits = image.depth() == CV_8U ? 8 : 16;
  // libtiff's RGBA interface turns a bottom-up image the right way up itself.
  const bool flip_rows =
      out_bits == 8 &&
      (orientation == ORIENTATION_BOTRIGHT || orientation == ORIENTATION_RIGHTBOT ||
       orientation == ORIENTATION_BOTLEFT || orientation == ORIENTATION_LEFTBOT);
  if (out_bits == 8) {
    char message[1024];
    if (TIFFRGBAImageOK(tif, message) == 0) {
      *error = message;
      return false;
    }
  }
  std::uint32_t tile_width = t.width, tile_height = 0;
  if (tiled) {
    if (TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tile_width) == 0 ||
        TIFFGetField(tif, TIFFTAG_TILELENGTH, &tile_height) == 0) {
      *error = "the tiled TIFF has no TileWidth or TileLength";
      return false;
    }
  } else {
    TIFFGetField(tif, TIFFTAG_ROWSPERSTRIP, &tile_height);
  }
  if (tile_width == 0) tile_width = t.width;
  if (tile_height == 0 || (!tiled && tile_height == std::numeric_limits<std::uint32_t>::max())) {
    tile_height = t.height;
  }
  constexpr std::uint32_t kMaxTileSide = 1u << 24;
  if (tile_width > kMaxTileSide || tile_height > kMaxTileSide) {
    *error = fmt::format("its {}x{} tiles or strips are too large", tile_width, tile_height);
    return false;
  }
  constexpr std::uint64_t kMaxTileBytes = std::uint64_t{1} << 30;
  if (t.bits > 64 ||
      std::uint64_t{tile_width} * tile_height * t.samples * std::max(1, t.bits / 8) >=
          kMaxTileBytes) {
    *error = "its tiles or strips are 1 GB or more";
    return false;
  }
  // Bytes of one decoded row of a strip or tile: RGBA for the 8-bit path.
  const int bits = out_bits == 8 ? 8 : t.bits;
  const int samples = out_bits == 8 ? 4 : t.samples;
  const std::size_t row_bytes = (std::size_t{tile_width} * samples * bits + 7) / 8;
  std::vector<unsigned char> buffer(tile_height * row_bytes);
  std::vector<std::uint16_t> unpacked(bits < out_bits ? std::size_t{tile_width} * samples : 0);
  const int width = static_cast<int>(t.width), height = static_cast<int>(t.height);
  const int step_y = static_cast<int>(tile_height), step_x = static_cast<int>(tile_width);
  tstrile_t index = 0;
  for (int y = 0; y < height; y += step_y) {
    const int rows = std::min(step_y, height - y);
    const int image_y = flip_rows ? height - y - rows : y;
    for (int x = 0; x < width; x += step_x, ++index) {
      const int columns = std::min(step_x, width - x);
      if (out_bits == 8) {
        // RGBA rasters fill from the bottom up; a tile's from its last row.
        auto* raster = reinterpret_cast<std::uint32_t*>(buffer.data());
        const int read =
            tiled ? TIFFReadRGBATile(tif, x, y, raster) : TIFFReadRGBAStrip(tif, y, raster);
        if (read == 0) {
          *error = "libtiff could not read its RGBA pixels";
          return false;
        }
        const unsigned char* first =
            buffer.data() + (tiled ? std::size_t(step_y - rows) * step_x * 4 : 0);
        for (int i = 0; i < rows; ++i) {
          PutRgbaRow(first + std::size_t(i) * step_x * 4, columns, image.channels(),
                     image.ptr<unsigned char>(image_y + rows - i - 1, x));
        }
        continue;
      }
      const tmsize_t read = tiled ? TIFFReadEncodedTile(tif, index, buffer.data(), buffer.size())
                                  : TIFFReadEncodedStrip(tif, index, buffer.data(), buffer.size());
      if (static_cast<int>(read) < 0) {
        *error = "libtiff could not read its strips or tiles";
        return false;
      }
      for (int i = 0; i < rows; ++i) {
        const unsigned char* row = buffer.data() + i * row_bytes;
        const std::uint16_t* samples16 = reinterpret_cast<const std::uint16_t*>(row);
        if (!unpacked.empty()) {
          UnpackSamples(row, bits, unpacked.size(), unpacked.data());
          samples16 = unpacked.data();
        }
        Put16BitRow(samples16, samples, columns, image.channels(),
                    image.ptr<std::uint16_t>(image_y + i, x));
      }
    }
  }
  if (bits < out_bits) image *= 1 << (out_bits - bits);
  if (out_bits == 16) {
    ApplyExifOrientation(orientation, image);
  } else if (orientation == ORIENTATION_RIGHTTOP || orientation == ORIENTATION_LEFTBOT) {
    cv::flip(image, image, -1);  // the rest was done by libtiff
    cv::transpose(image, image);
  } else if (orientation == ORIENTATION_LEFTTOP || orientation == ORIENTATION_RIGHTBOT) {
    cv::transpose(image, image);
  }
  return true;
}

}  // namespace

bool DecodeTiff(std::span<const unsigned char> bytes, cv::Mat* image, std::string* error) {
  *image = cv::Mat();
  TiffSource source{bytes, 0, {}};
  TiffOptionsFreer options{TIFFOpenOptionsAlloc()};
  TIFFOpenOptionsSetErrorHandlerExtR(options.options, TiffOnError, &source);
  TIFFOpenOptionsSetWarningHandlerExtR(options.options, TiffOnWarning, &source);
  TiffCloser closer;
  closer.tif = TIFFClientOpenExt("", "r", &source, TiffReadProc, TiffWriteNothing, TiffSeekProc,
                                 TiffCloseNothing, TiffSizeProc, nullptr, nullptr, options.options);
  const auto fail = [&](const std::string& what) {
    *error = source.message.empty() ? what : fmt::format("{} ({})", what, source.message);
    *image = cv::Mat();
    return false;
  };
  if (closer.tif == nullptr) return fail("libtiff could not open it");
  TiffLayoutRead layout;
  std::string problem;
  if (!TiffReadLayout(closer.tif, &layout, &problem)) return fail(problem);
  cv::Mat pixels(static_cast<int>(layout.height), static_cast<int>(layout.width),
                 CV_MAKETYPE(layout.depth, layout.channels));
  if (!TiffReadPixels(closer.tif, layout, pixels, &problem)) return fail(problem);
  *image = std::move(pixels);
  return true;
}

}  // namespace impactlab::imagefile
