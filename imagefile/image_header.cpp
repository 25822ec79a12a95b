#include "imagefile/image_header.h"

#include <algorithm>
#include <array>
#include <optional>

#include <fmt/format.h>

namespace impactlab::imagefile {
namespace {

bool StartsWith(std::span<const unsigned char> bytes, std::initializer_list<unsigned char> magic) {
  return bytes.size() >= magic.size() && std::equal(magic.begin(), magic.end(), bytes.begin());
}

bool Fail(std::string* error, std::string text) {
  if (error != nullptr) *error = std::move(text);
  return false;
}

// Fixed-size integers at byte offsets, in either byte order. A read past the
// end returns 0 and sets `bad`, so a parser checks once at the end of a step.
struct Reader {
  std::span<const unsigned char> bytes;
  bool little_endian = false;
  bool bad = false;

  std::uint64_t Read(std::uint64_t offset, int size) {
    if (offset > bytes.size() || bytes.size() - offset < static_cast<std::uint64_t>(size)) {
      bad = true;
      return 0;
    }
    std::uint64_t value = 0;
    for (int i = 0; i < size; ++i) {
      const std::uint64_t byte = bytes[offset + (little_endian ? size - 1 - i : i)];
      value = value << 8 | byte;
    }
    return value;
  }
  std::uint64_t U8(std::uint64_t offset) { return Read(offset, 1); }
  std::uint64_t U16(std::uint64_t offset) { return Read(offset, 2); }
  std::uint64_t U32(std::uint64_t offset) { return Read(offset, 4); }
  std::uint64_t U64(std::uint64_t offset) { return Read(offset, 8); }
};

bool ReadPng(std::span<const unsigned char> bytes, ImageHeader* header, std::string* error) {
  // Signature (8), then the first chunk, which must be IHDR: length 13 (4),
  // type (4), width (4), height (4), bit depth, colour type, compression,
  // filter, interlace (1 each), CRC (4).
  Reader r{bytes};
  const std::uint64_t length = r.U32(8);
  const bool ihdr =
      bytes.size() >= 16 && std::equal(bytes.begin() + 12, bytes.begin() + 16, "IHDR");
  if (r.bad || !ihdr) return Fail(error, "the PNG does not start with its IHDR chunk");
  if (length != 13)
    return Fail(error, fmt::format("the PNG's IHDR chunk is {} bytes long, not 13", length));
  header->width = r.U32(16);
  header->height = r.U32(20);
  header->bits_per_sample = static_cast<int>(r.U8(24));
  const int colour_type = static_cast<int>(r.U8(25));
  if (r.bad) return Fail(error, "the PNG's IHDR chunk is cut short");
  switch (colour_type) {
    case 0:  // grey
    case 3:  // palette
      header->channels = 1;
      break;
    case 2:  // RGB
      header->channels = 3;
      break;
    case 4:  // grey and alpha
      header->channels = 2;
      break;
    case 6:  // RGBA
      header->channels = 4;
      break;
    default:
      return Fail(error,
                  fmt::format("the PNG's colour type {} is not one PNG defines", colour_type));
  }
  return true;
}

// Start-of-frame markers: SOF0-SOF3, SOF5-SOF7, SOF9-SOF11, SOF13-SOF15
// (0xC4 is DHT, 0xC8 reserved, 0xCC DAC).
bool IsStartOfFrame(unsigned marker) {
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
}

// Walks a JPEG's marker segments from SOI and calls visit(marker, payload
// offset, payload length) for each segment with a length, until visit
// returns true (found) or a scan starts. Returns false with *error when the
// stream is not a sequence of well-formed segments up to that point.
template <typename Visit>
bool WalkJpegSegments(std::span<const unsigned char> bytes, std::string* error, Visit visit) {
  if (!StartsWith(bytes, {0xFF, 0xD8})) return Fail(error, "the JPEG does not start with SOI");
  std::size_t pos = 2;
  for (;;) {
    if (pos >= bytes.size() || bytes[pos] != 0xFF) {
      return Fail(error,
                  pos >= bytes.size()
                      ? "the JPEG ends before its frame header"
                      : fmt::format("the JPEG has no marker where one is due (byte {})", pos));
    }
    while (pos < bytes.size() && bytes[pos] == 0xFF) ++pos;  // fill bytes
    if (pos >= bytes.size()) return Fail(error, "the JPEG ends before its frame header");
    const unsigned marker = bytes[pos++];
    if ((marker >= 0xD0 && marker <= 0xD7) || marker == 0x01) continue;  // RSTn, TEM: no length
    if (marker == 0x00 || marker == 0xD8 || marker == 0xD9 || marker == 0xDA) {
      return Fail(error,
                  fmt::format("the JPEG has marker 0x{:02X} before any frame header", marker));
    }
    if (bytes.size() - pos < 2) return Fail(error, "the JPEG ends inside a marker segment");
    const std::size_t length = std::size_t{bytes[pos]} << 8 | bytes[pos + 1];
    if (length < 2 || bytes.size() - pos < length) {
      return Fail(error, fmt::format("the JPEG's marker 0x{:02X} segment is cut short", marker));
    }
    if (visit(marker, pos + 2, length - 2)) return true;
    pos += length;
  }
}

bool ReadJpeg(std::span<const unsigned char> bytes, ImageHeader* header, std::string* error) {
  std::string problem;
  const bool found = WalkJpegSegments(
      bytes, &problem, [&](unsigned marker, std::size_t payload, std::size_t length) {
        if (!IsStartOfFrame(marker)) return false;
        // Frame header: precision (1), lines (2), samples per line (2),
        // components (1), then 3 bytes per component.
        Reader r{bytes.subspan(payload, length)};
        header->bits_per_sample = static_cast<int>(r.U8(0));
        header->height = r.U16(1);
        header->width = r.U16(3);
        header->channels = static_cast<int>(r.U8(5));
        if (r.bad || length < 6 + 3 * static_cast<std::size_t>(header->channels)) {
          problem = "the JPEG's frame header is cut short";
        }
        return true;
      });
  if (!found) return Fail(error, problem);
  if (!problem.empty()) return Fail(error, problem);
  if (header->height == 0) {
    return Fail(error, "the JPEG declares its height later (a DNL marker), which is not supported");
  }
  return true;
}

// A TIFF's byte order and the offset of its first IFD; BigTIFF too.
struct TiffLayout {
  Reader reader;
  bool big = false;
  std::uint64_t first_ifd = 0;
};

std::optional<TiffLayout> ReadTiffLayout(std::span<const unsigned char> bytes) {
  TiffLayout t{Reader{bytes}};
  if (StartsWith(bytes, {'I', 'I'})) {
    t.reader.little_endian = true;
  } else if (!StartsWith(bytes, {'M', 'M'})) {
    return std::nullopt;
  }
  const std::uint64_t magic = t.reader.U16(2);
  if (magic == 42) {
    t.first_ifd = t.reader.U32(4);
  } else if (magic == 43) {  // BigTIFF: offset size 8, a zero, then an 8-byte offset
    t.big = true;
    if (t.reader.U16(4) != 8 || t.reader.U16(6) != 0) return std::nullopt;
    t.first_ifd = t.reader.U64(8);
  } else {
    return std::nullopt;
  }
  if (t.reader.bad) return std::nullopt;
  return t;
}

// The first value of each wanted tag in the IFD at t.first_ifd; tags absent
// keep their defaults.
struct IfdEntry {
  unsigned tag;
  std::optional<std::uint64_t> value;
};

bool ReadIfd(TiffLayout& t, std::span<IfdEntry> wanted, std::string* error) {
  Reader& r = t.reader;
  const std::uint64_t count = t.big ? r.U64(t.first_ifd) : r.U16(t.first_ifd);
  const std::uint64_t entry_size = t.big ? 20 : 12;
  const std::uint64_t first_entry = t.first_ifd + (t.big ? 8 : 2);
  if (r.bad || count == 0 || count > r.bytes.size() / entry_size ||
      first_entry + count * entry_size > r.bytes.size()) {
    return Fail(error, "the TIFF's first IFD is empty or cut short");
  }
  const int inline_size = t.big ? 8 : 4;
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint64_t entry = first_entry + i * entry_size;
    const unsigned tag = static_cast<unsigned>(r.U16(entry));
    auto it =
        std::find_if(wanted.begin(), wanted.end(), [&](const IfdEntry& w) { return w.tag == tag; });
    if (it == wanted.end()) continue;
    const unsigned type = static_cast<unsigned>(r.U16(entry + 2));
    const std::uint64_t values = t.big ? r.U64(entry + 4) : r.U32(entry + 4);
    const std::uint64_t field = entry + (t.big ? 12 : 8);
    int size = 0;
    if (type == 1) size = 1;   // BYTE
    if (type == 3) size = 2;   // SHORT
    if (type == 4) size = 4;   // LONG
    if (type == 16) size = 8;  // LONG8 (BigTIFF)
    if (size == 0 || values == 0) {
      return Fail(error, fmt::format("the TIFF's tag {} has type {} or no value", tag, type));
    }
    const bool inline_value = values <= static_cast<std::uint64_t>(inline_size / size);
    const std::uint64_t at = inline_value ? field : (t.big ? r.U64(field) : r.U32(field));
    it->value = r.Read(at, size);
    if (r.bad) return Fail(error, fmt::format("the TIFF's tag {} points past the file's end", tag));
  }
  return true;
}

bool ReadTiff(std::span<const unsigned char> bytes, ImageHeader* header, std::string* error) {
  std::optional<TiffLayout> t = ReadTiffLayout(bytes);
  if (!t) return Fail(error, "the TIFF's header (byte order, version, first IFD) is unreadable");
  std::array<IfdEntry, 4> wanted = {{{256, {}}, {257, {}}, {258, {}}, {277, {}}}};
  if (!ReadIfd(*t, wanted, error)) return false;
  if (!wanted[0].value || !wanted[1].value) {
    return Fail(error, "the TIFF's first IFD has no ImageWidth or ImageLength");
  }
  header->width = *wanted[0].value;
  header->height = *wanted[1].value;
  header->bits_per_sample =
      static_cast<int>(std::min<std::uint64_t>(wanted[2].value.value_or(1), 1024));
  header->channels = static_cast<int>(std::min<std::uint64_t>(wanted[3].value.value_or(1), 1024));
  return true;
}

}  // namespace

const char* ImageFormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::kPng:
      return "PNG";
    case ImageFormat::kJpeg:
      return "JPEG";
    case ImageFormat::kTiff:
      return "TIFF";
  }
  return "image";
}

bool ReadImageHeader(std::span<const unsigned char> bytes, ImageHeader* header,
                     std::string* error) {
  *header = {};
  bool ok = false;
  if (StartsWith(bytes, {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A})) {
    header->format = ImageFormat::kPng;
    ok = ReadPng(bytes, header, error);
  } else if (StartsWith(bytes, {0xFF, 0xD8, 0xFF})) {
    header->format = ImageFormat::kJpeg;
    ok = ReadJpeg(bytes, header, error);
  } else if (StartsWith(bytes, {'I', 'I', 42, 0}) || StartsWith(bytes, {'M', 'M', 0, 42}) ||
             StartsWith(bytes, {'I', 'I', 43, 0}) || StartsWith(bytes, {'M', 'M', 0, 43})) {
    header->format = ImageFormat::kTiff;
    ok = ReadTiff(bytes, header, error);
  } else {
    return Fail(error, "not a PNG, JPEG or TIFF image (its first bytes are none of theirs)");
  }
  if (!ok) return false;
  if (header->width == 0 || header->height == 0) {
    return Fail(error, fmt::format("the {} declares {}x{} pixels", ImageFormatName(header->format),
                                   header->width, header->height));
  }
  return true;
}

int ReadExifOrientation(std::span<const unsigned char> tiff_block) {
  std::optional<TiffLayout> t = ReadTiffLayout(tiff_block);
  std::array<IfdEntry, 1> wanted = {{{0x0112, {}}}};
  std::string ignored;
  if (t && !t->big && ReadIfd(*t, wanted, &ignored) && wanted[0].value && *wanted[0].value >= 1 &&
      *wanted[0].value <= 8) {
    return static_cast<int>(*wanted[0].value);
  }
  return 1;
}

int ReadJpegExifOrientation(std::span<const unsigned char> bytes) {
  int orientation = 1;
  std::string ignored;
  WalkJpegSegments(bytes, &ignored, [&](unsigned marker, std::size_t payload, std::size_t length) {
    if (marker != 0xE1 || length < 6 ||
        !StartsWith(bytes.subspan(payload), {'E', 'x', 'i', 'f', 0, 0})) {
      return false;
    }
    orientation = ReadExifOrientation(bytes.subspan(payload + 6, length - 6));
    return true;  // only the first EXIF segment counts
  });             // (or up to the first scan, where the walk stops)
  return orientation;
}

}  // namespace impactlab::imagefile
