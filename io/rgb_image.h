// An image as HDF5's image convention stores it (io/hdf5_extras.h).
#pragma once

#include <vector>

namespace impactlab {

struct RgbImage {
  int height = 0, width = 0;
  std::vector<unsigned char> pixels;  // height * width * 3, red-green-blue, row-major
};

}  // namespace impactlab
