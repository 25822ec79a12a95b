// The photo shrunk and turned grey (internal to digitize/): the working copy
// the searches run on (PreparePhoto) and the copy hand marks are looked for
// in (hand_marks.cpp) are made alike.
#pragma once

#include <opencv2/core.hpp>

namespace impactlab::digitize {

// `image` (8 or 16 bit, 1, 3 or 4 channels) shrunk by the whole factor `f`:
// each pixel the mean of an f x f block, the photo's last partial blocks left
// out, the pixels cv::resize's area resampling gives (an 8-bit photo shrunk
// by 3 or more in under half its time). Channels and sample type kept; `f`
// 1 is `image` itself.
cv::Mat ShrunkByArea(const cv::Mat& image, int f);

// The same as BT.601 luma, in the photo's own sample type.
cv::Mat ShrunkLuma(const cv::Mat& image, int f);

// The same in [0, 1].
cv::Mat1f ShrunkGrey(const cv::Mat& image, int f);

// The same as 8-bit ink: bright where traces and lines are, whatever the
// polarity (morphology on bytes is several times faster than on floats).
cv::Mat1b ShrunkInk8(const cv::Mat& image, int f, bool dark_traces);

}  // namespace impactlab::digitize
