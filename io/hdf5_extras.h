// What results layout 2 needs of HDF5 beyond Hdf5File's scalars, vectors and
// strings: 2-D datasets, string-array attributes, dimension scales (HDF5
// Dimension Scales, H5DS) and images (HDF5 Image and Palette Specification
// 1.2), the last two from HDF5's high-level library (hdf5_hl). They write into
// the file an Hdf5File is writing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/hdf5_file.h"
#include "io/rgb_image.h"

namespace impactlab {

class Hdf5Extras {
 public:
  // Writes into `file` (which must outlive this).
  explicit Hdf5Extras(const Hdf5File& file);

  // A rows x cols float64 dataset from row-major `values`, with its `units`.
  void WriteMatrix(const std::string& dataset, std::size_t rows, std::size_t cols,
                   const std::vector<double>& values, std::string_view units) const;
  // A 1-D attribute of UTF-8 strings (variable length, like Hdf5File's strings).
  void SetStringsAttribute(const std::string& object, const std::string& name,
                           const std::vector<std::string>& values) const;
  // Makes the 1-D `scale` a dimension scale, named as its last path component
  // ("rebound", "time"), and attaches it to the first dimension of `dataset`.
  void AttachScale(const std::string& dataset, const std::string& scale) const;
  // A height x width x 3 uint8 dataset with the Image spec's attributes for a
  // true-colour image (CLASS, IMAGE_VERSION, IMAGE_SUBCLASS, INTERLACE_MODE,
  // DISPLAY_ORIGIN), so that HDFView shows it; stored as it is (not deflated).
  void WriteImage(const std::string& dataset, const RgbImage& image) const;

 private:
  void Check(int status, const std::string& object, const char* what) const;

  std::filesystem::path path_;
  std::int64_t file_ = -1;  // hid_t; the Hdf5File's, not closed here
};

// A 1-D string attribute as SetStringsAttribute writes it. Opens `file`
// read-only for the call; throws InputError naming the file and the object.
std::vector<std::string> ReadStringsAttribute(const std::filesystem::path& file,
                                              const std::string& object, const std::string& name);

}  // namespace impactlab
