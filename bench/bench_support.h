// What the benchmarks share: percentiles, pulls' RMS and shares, wall time, and the floor any
// reducer pays, decoding a session's photos.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <vector>

#include <fmt/core.h>
#include <opencv2/imgcodecs.hpp>

namespace impactlab {

// The p-quantile, interpolated between ranks (p = 0.5: the median).
inline double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double rank = p * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(rank);
  const double f = rank - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

inline double Rms(const std::vector<double>& v) {
  if (v.empty()) return NAN;
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return std::sqrt(sum / static_cast<double>(v.size()));
}

// The share of pulls (error / stated sigma) within k: about 68 % within 1
// and 95 % within 2 when the sigmas are honest.
inline double ShareWithin(const std::vector<double>& pulls, double k) {
  if (pulls.empty()) return NAN;
  const auto n =
      std::count_if(pulls.begin(), pulls.end(), [&](double p) { return std::abs(p) <= k; });
  return static_cast<double>(n) / static_cast<double>(pulls.size());
}

inline double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Decoding every photo of the session alone: the floor any reducer pays.
inline double DecodeSeconds(const std::filesystem::path& session) {
  const auto start = std::chrono::steady_clock::now();
  for (const char* sub : {"runs", "calibration"}) {
    if (!std::filesystem::exists(session / sub)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(session / sub)) {
      const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED);
      if (image.empty()) fmt::print(stderr, "cannot decode {}\n", entry.path().string());
    }
  }
  return Seconds(start);
}

}  // namespace impactlab
