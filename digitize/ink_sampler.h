// Reading the full photo at sub-pixel positions (internal to digitize/).
//
// The photo is never converted as a whole: a 3-megapixel photo in floating
// point is 36 MB, and touching that much fresh memory costs more than all the
// measuring. Instead every measurement reads the few pixels it needs, turning
// them into grey "ink" (bright where the traces and lines are, whatever the
// photo's polarity) on the fly.
#pragma once

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace impactlab::digitize {

class InkSampler {
 public:
  InkSampler(const cv::Mat& image, bool dark_traces)
      : image_(image),
        dark_traces_(dark_traces),
        channels_(image.channels()),
        sixteen_bit_(image.depth() == CV_16U),
        scale_(sixteen_bit_ ? 1.0f / 65535.0f : 1.0f / 255.0f),
        max_x_(image.cols - 1),
        max_y_(image.rows - 1) {
    CV_Assert(image.depth() == CV_8U || image.depth() == CV_16U);
    CV_Assert(channels_ == 1 || channels_ == 3 || channels_ == 4);
  }

  // Bilinear ink at (x, y), photo pixels; positions beyond the photo read its
  // nearest edge.
  float operator()(double x, double y) const {
    x = std::clamp(x, 0.0, static_cast<double>(max_x_));
    y = std::clamp(y, 0.0, static_cast<double>(max_y_));
    const int x0 = std::min(static_cast<int>(x), std::max(0, max_x_ - 1));
    const int y0 = std::min(static_cast<int>(y), std::max(0, max_y_ - 1));
    const int x1 = std::min(x0 + 1, max_x_), y1 = std::min(y0 + 1, max_y_);
    const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
    const float top = Grey(y0, x0) * (1.0f - fx) + Grey(y0, x1) * fx;
    const float bottom = Grey(y1, x0) * (1.0f - fx) + Grey(y1, x1) * fx;
    const float value = (top * (1.0f - fy) + bottom * fy) * scale_;
    return dark_traces_ ? 1.0f - value : value;
  }

  float operator()(cv::Point2d p) const { return (*this)(p.x, p.y); }

  cv::Size size() const { return image_.size(); }

 private:
  // ITU-R BT.601 luma of one pixel, in the file's units.
  float Grey(int row, int col) const {
    if (sixteen_bit_) return Luma(image_.ptr<ushort>(row) + col * channels_);
    return Luma(image_.ptr<uchar>(row) + col * channels_);
  }

  template <typename Sample>
  float Luma(const Sample* p) const {
    if (channels_ == 1) return p[0];
    return 0.114f * p[0] + 0.587f * p[1] + 0.299f * p[2];
  }

  const cv::Mat& image_;
  bool dark_traces_;
  int channels_;
  bool sixteen_bit_;
  float scale_;
  int max_x_, max_y_;
};

}  // namespace impactlab::digitize
