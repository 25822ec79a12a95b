// Photographing the face (internal to render/): one pass over the photo's
// pixels that looks each one up on the screen through the camera, lights it,
// develops it through the style's tone curve, adds grain or sensor noise, the
// print's border and dirt, and writes the file's samples. One pass, because a
// full-size floating-point image per step costs more in memory traffic than
// the arithmetic does.
#pragma once

#include <random>

#include <opencv2/core.hpp>

#include "render/oscillograph.h"
#include "render/screen.h"
#include "render/styles.h"

namespace impactlab::render {

// The photo's samples: CV_8U or CV_16U (8-bit whenever the style ends in a
// JPEG), one channel when look.grey, else BGR.
cv::Mat Photograph(const PhosphorCanvas& phosphor, const ScreenLayout& layout,
                   const StyleLook& look, const CameraMapping& mapping, const Dirt& dirt,
                   std::mt19937_64& random);

}  // namespace impactlab::render
