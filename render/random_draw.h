// Drawing a photo's look at random (internal to render/): what every style's
// drawing shares, with the rectangles it is framed by (render/rectangles.h).
#pragma once

#include <cmath>
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

// Uniform in log: for scale factors whose small values matter as much as
// their large ones (size, blur, noise, brightness).
inline double LogUniform(std::mt19937_64& random, double lo, double hi) {
  return std::exp(Uniform(random, std::log(lo), std::log(hi)));
}

inline bool Chance(std::mt19937_64& random, double p) { return Uniform(random, 0.0, 1.0) < p; }

}  // namespace impactlab::render
