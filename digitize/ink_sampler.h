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
    const auto the_point = [&](int) { return cv::Point2d(x, y); };
    float value = 0.0f;
    Read(1, the_point, &value);
    return value;
  }

  float operator()(cv::Point2d p) const { return (*this)(p.x, p.y); }

  // Ink at `count` points, point_of(i) for i = 0 .. count - 1, into out[i].
  // The photo's sample type and channels are settled once for all of them:
  // per pixel, the branches on them cost as much as the interpolation.
  template <typename PointOf>
  void Read(int count, PointOf point_of, float* out) const {
    if (sixteen_bit_) {
      ReadAs<ushort>(count, point_of, out);
    } else {
      ReadAs<uchar>(count, point_of, out);
    }
  }

  cv::Size size() const { return image_.size(); }

 private:
  template <typename Sample, typename PointOf>
  void ReadAs(int count, PointOf point_of, float* out) const {
    switch (channels_) {
      case 1:
        ReadWith<Sample, 1>(count, point_of, out);
        break;
      case 3:
        ReadWith<Sample, 3>(count, point_of, out);
        break;
      default:
        ReadWith<Sample, 4>(count, point_of, out);
        break;
    }
  }

  template <typename Sample, int kChannels, typename PointOf>
  void ReadWith(int count, PointOf point_of, float* out) const {
    const int last_x0 = std::max(0, max_x_ - 1), last_y0 = std::max(0, max_y_ - 1);
    Block<Sample, kChannels> block{*this};
    for (int i = 0; i < count; ++i) {
      const cv::Point2d p = point_of(i);
      const double x = std::clamp(p.x, 0.0, static_cast<double>(max_x_));
      const double y = std::clamp(p.y, 0.0, static_cast<double>(max_y_));
      const int x0 = std::min(static_cast<int>(x), last_x0);
      const int y0 = std::min(static_cast<int>(y), last_y0);
      block.MoveTo(x0, y0);
      const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
      const float top = block.g00 * (1.0f - fx) + block.g01 * fx;
      const float bottom = block.g10 * (1.0f - fx) + block.g11 * fx;
      const float value = (top * (1.0f - fy) + bottom * fy) * scale_;
      out[i] = dark_traces_ ? 1.0f - value : value;
    }
  }

  // The luma of the 2 x 2 pixels a point is interpolated from, (x0, y0) the
  // top left one, kept from point to point: points a fraction of a pixel
  // apart share all four or a side, and luma is most of the work in colour.
  template <typename Sample, int kChannels>
  struct Block {
    const InkSampler& ink;
    int x0 = -1, y0 = -1;
    float g00 = 0.0f, g01 = 0.0f, g10 = 0.0f, g11 = 0.0f;  // g<row><column>

    void MoveTo(int x, int y) {
      if (x == x0 && y == y0) return;
      const bool same_row = y == y0, same_column = x == x0;
      const bool right = same_row && x == x0 + 1, left = same_row && x == x0 - 1;
      const bool down = same_column && y == y0 + 1, up = same_column && y == y0 - 1;
      x0 = x, y0 = y;
      const int x1 = std::min(x + 1, ink.max_x_), y1 = std::min(y + 1, ink.max_y_);
      if (right) {
        g00 = g01, g10 = g11;
        g01 = At(y, x1), g11 = At(y1, x1);
      } else if (left) {
        g01 = g00, g11 = g10;
        g00 = At(y, x), g10 = At(y1, x);
      } else if (down) {
        g00 = g10, g01 = g11;
        g10 = At(y1, x), g11 = At(y1, x1);
      } else if (up) {
        g10 = g00, g11 = g01;
        g00 = At(y, x), g01 = At(y, x1);
      } else {
        g00 = At(y, x), g01 = At(y, x1), g10 = At(y1, x), g11 = At(y1, x1);
      }
    }

    float At(int row, int col) const {
      return Luma<kChannels>(ink.image_.ptr<Sample>(row) + col * kChannels);
    }
  };

  // ITU-R BT.601 luma of one pixel, in the file's units.
  template <int kChannels, typename Sample>
  static float Luma(const Sample* p) {
    if constexpr (kChannels == 1) {
      return p[0];
    } else {
      return 0.114f * p[0] + 0.587f * p[1] + 0.299f * p[2];
    }
  }

  const cv::Mat& image_;
  bool dark_traces_;
  int channels_;
  bool sixteen_bit_;
  float scale_;
  int max_x_, max_y_;
};

}  // namespace impactlab::digitize
