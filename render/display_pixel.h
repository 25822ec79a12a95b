// One pixel's display values written in an image file's format: shared by
// the photo's and the print's renderers (internal to render/).
#pragma once

#include <opencv2/core.hpp>

namespace impactlab {

// `bgr` in [0, 1]; `grey`: one channel of ITU-R BT.601 luma, as
// cv::cvtColor(COLOR_BGR2GRAY); `full_scale`: 255 or 65535.
template <typename Sample>
void StoreDisplayPixel(const cv::Vec3f& bgr, bool grey, float full_scale, Sample* out) {
  if (grey) {
    out[0] = cv::saturate_cast<Sample>((0.114f * bgr[0] + 0.587f * bgr[1] + 0.299f * bgr[2]) *
                                       full_scale);
    return;
  }
  for (int c = 0; c < 3; ++c) out[c] = cv::saturate_cast<Sample>(bgr[c] * full_scale);
}

}  // namespace impactlab
