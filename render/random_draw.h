// Drawing a photo's look at random (internal to render/): what every style's
// drawing shares, with the rectangles it is framed by (render/rectangles.h).
#pragma once

#include <random>

#include <opencv2/core.hpp>

#include "render/rectangles.h"

namespace impactlab::render {

inline double Uniform(std::mt19937_64& random, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(random);
}

inline int UniformInt(std::mt19937_64& random, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(random);
}

}  // namespace impactlab::render
