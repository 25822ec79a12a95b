#include "signal/decimate.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace impactlab {
namespace {

constexpr int kTapsPerSide = kDecimationEdgeSamples;  // per output sample
constexpr double kCutoffFraction = 0.45;              // of the output rate
constexpr double kKaiserBeta = 8.0;

}  // namespace

std::vector<double> DecimationTaps(int factor) {
  if (factor < 1) throw std::invalid_argument("decimation factor must be at least 1");
  if (factor == 1) return {1.0};
  const int half = kTapsPerSide * factor;
  const double cutoff = kCutoffFraction / factor;  // cycles per input sample
  const double norm = std::cyl_bessel_i(0.0, kKaiserBeta);
  std::vector<double> taps(2 * half + 1);
  double sum = 0.0;
  for (int j = -half; j <= half; ++j) {
    const double x = 2.0 * std::numbers::pi * cutoff * j;
    const double sinc = j == 0 ? 1.0 : std::sin(x) / x;
    const double r = static_cast<double>(j) / half;
    const double kaiser = std::cyl_bessel_i(0.0, kKaiserBeta * std::sqrt(1.0 - r * r)) / norm;
    taps[j + half] = sinc * kaiser;
    sum += taps[j + half];
  }
  for (double& t : taps) t /= sum;
  return taps;
}

StreamingDecimator::StreamingDecimator(int factor)
    : factor_(factor),
      half_(factor == 1 ? 0 : kTapsPerSide * factor),
      taps_(DecimationTaps(factor)) {}

void StreamingDecimator::Push(std::span<const double> samples, std::vector<double>& out) {
  if (samples.empty()) return;
  if (factor_ == 1) {
    out.insert(out.end(), samples.begin(), samples.end());
    received_ += static_cast<long long>(samples.size());
    return;
  }
  if (received_ == 0) {  // hold the first sample before the start
    buffer_.assign(static_cast<std::size_t>(half_), samples.front());
    buffer_start_ = -half_;
  }
  buffer_.insert(buffer_.end(), samples.begin(), samples.end());
  received_ += static_cast<long long>(samples.size());
  Produce(out);
}

void StreamingDecimator::Finish(std::vector<double>& out) {
  if (factor_ == 1 || received_ == 0) return;
  const long long end = received_;
  buffer_.insert(buffer_.end(), static_cast<std::size_t>(half_), buffer_.back());
  received_ += half_;
  Produce(out);  // every centre before `end` now has its window
  received_ = end;
}

void StreamingDecimator::Produce(std::vector<double>& out) {
  const long long window = 2LL * half_ + 1;
  while (next_centre_ + half_ < received_) {
    const double* x = buffer_.data() + (next_centre_ - half_ - buffer_start_);
    double acc = 0.0;
    for (long long j = 0; j < window; ++j) acc += taps_[static_cast<std::size_t>(j)] * x[j];
    out.push_back(acc);
    next_centre_ += factor_;
  }
  // Drop the inputs no later output needs (in bulk, to keep the cost linear).
  const long long unused = next_centre_ - half_ - buffer_start_;
  if (unused > 0 && static_cast<std::size_t>(unused) * 2 >= buffer_.size()) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + unused);
    buffer_start_ += unused;
  }
}

std::vector<double> Decimate(std::span<const double> samples, int factor) {
  StreamingDecimator decimator(factor);
  std::vector<double> out;
  out.reserve(samples.size() / static_cast<std::size_t>(factor) + 1);
  decimator.Push(samples, out);
  decimator.Finish(out);
  return out;
}

DecimatedSeries MinMaxDecimate(std::span<const double> values, double start_time_s, double interval_s,
                          std::size_t points) {
  DecimatedSeries series;
  const std::size_t n = values.size();
  auto add = [&](std::size_t i) {
    series.time_s.push_back(start_time_s + interval_s * static_cast<double>(i));
    series.value.push_back(values[i]);
  };
  if (n <= std::max<std::size_t>(points, 2)) {
    for (std::size_t i = 0; i < n; ++i) add(i);
    return series;
  }
  const std::size_t buckets = std::max<std::size_t>(points / 2, 1);
  const std::size_t size = (n + buckets - 1) / buckets;
  for (std::size_t begin = 0; begin < n; begin += size) {
    const std::size_t end = std::min(n, begin + size);
    const auto [lo, hi] = std::minmax_element(values.begin() + begin, values.begin() + end);
    const auto a = static_cast<std::size_t>(lo - values.begin());
    const auto b = static_cast<std::size_t>(hi - values.begin());
    add(std::min(a, b));
    if (a != b) add(std::max(a, b));
  }
  return series;
}

}  // namespace impactlab
