#include "signal/impact_detection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace impactlab {
namespace {

double Median(std::vector<double> v) {
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

// A clean (simulated) record has no noise to scale by: the onset then needs
// this fraction of the strongest jump.
constexpr double kOnsetFractionOfPeak = 0.1;

ChannelImpact AccelerometerImpact(const ChannelSamples& channel, double start_time_s,
                                  double rate_hz, const ImpactDetectionOptions& options) {
  ChannelImpact impact;
  impact.channel = channel.name;
  const std::span<const double> x = channel.values;
  if (x.size() < 8) return impact;
  std::vector<double> d(x.size() - 1);
  for (std::size_t i = 0; i + 1 < x.size(); ++i) d[i] = x[i + 1] - x[i];
  const double centre = Median(d);
  std::vector<double> deviation(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) deviation[i] = std::abs(d[i] - centre);
  std::size_t peak = 0;
  for (std::size_t i = 1; i < d.size(); ++i) {
    if (deviation[i] > deviation[peak]) peak = i;
  }
  const double sigma_d = std::max(1.4826 * Median(deviation), 1e-300);
  impact.jump_snr = deviation[peak] / sigma_d;
  if (impact.jump_snr < options.threshold_sigma) return impact;

  const double threshold =
      std::max(options.threshold_sigma * sigma_d, kOnsetFractionOfPeak * deviation[peak]);
  const auto search = static_cast<std::size_t>(std::llround(options.onset_search_s * rate_hz));
  std::size_t onset = peak;
  for (std::size_t i = peak > search ? peak - search : 0; i <= peak; ++i) {
    if (deviation[i] > threshold) {
      onset = i;
      break;
    }
  }
  impact.found = true;
  impact.sample = static_cast<long long>(onset) + 1;  // d[i] ends at sample i + 1
  impact.time_s = {start_time_s + (static_cast<double>(impact.sample) - 0.5) / rate_hz,
                   1.0 / (rate_hz * std::sqrt(12.0))};
  return impact;
}

struct Line {
  double slope = 0.0, intercept = 0.0;  // value = intercept + slope * u
  double var_slope = 0.0, var_intercept = 0.0, covariance = 0.0;
};

// Least-squares line through (u_i, x_i), i in [begin, end), u = (i - origin) / rate.
Line FitLine(std::span<const double> x, long long begin, long long end, long long origin,
             double rate_hz) {
  const auto n = static_cast<double>(end - begin);
  double su = 0, sx = 0, suu = 0, sux = 0;
  for (long long i = begin; i < end; ++i) {
    const double u = static_cast<double>(i - origin) / rate_hz;
    su += u;
    sx += x[static_cast<std::size_t>(i)];
    suu += u * u;
    sux += u * x[static_cast<std::size_t>(i)];
  }
  const double det = n * suu - su * su;
  Line line;
  line.slope = (n * sux - su * sx) / det;
  line.intercept = (sx - line.slope * su) / n;
  double rss = 0.0;
  for (long long i = begin; i < end; ++i) {
    const double u = static_cast<double>(i - origin) / rate_hz;
    const double r = x[static_cast<std::size_t>(i)] - line.intercept - line.slope * u;
    rss += r * r;
  }
  const double s2 = rss / std::max(1.0, n - 2.0);
  line.var_slope = s2 * n / det;
  line.var_intercept = s2 * suu / det;
  line.covariance = -s2 * su / det;
  return line;
}

// Where the velocity changes most: the largest |second difference| over h samples.
long long LargestVelocityChange(std::span<const double> x, long long h) {
  long long best = -1;
  double best_change = -1.0;
  for (long long i = h; i + h < static_cast<long long>(x.size()); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double change = std::abs(x[k + static_cast<std::size_t>(h)] - 2.0 * x[k] +
                                   x[k - static_cast<std::size_t>(h)]);
    if (change > best_change) {
      best_change = change;
      best = i;
    }
  }
  return best;
}

ChannelImpact EncoderImpact(const ChannelSamples& channel, long long near_sample,
                            double start_time_s, double rate_hz,
                            const ImpactDetectionOptions& options) {
  ChannelImpact impact;
  impact.channel = channel.name;
  const std::span<const double> x = channel.values;
  const auto size = static_cast<long long>(x.size());
  const long long width = std::max<long long>(3, std::llround(options.encoder_fit_s * rate_hz));
  const long long gap = std::llround(options.encoder_gap_s * rate_hz);
  if (near_sample < 0) near_sample = LargestVelocityChange(x, std::max<long long>(2, width / 2));
  if (near_sample < 0) return impact;
  const long long b0 = near_sample - gap - width, b1 = near_sample - gap;
  const long long a0 = near_sample + gap, a1 = near_sample + gap + width;
  if (b0 < 0 || a1 > size) return impact;
  const Line before = FitLine(x, b0, b1, near_sample, rate_hz);
  const Line after = FitLine(x, a0, a1, near_sample, rate_hz);
  impact.velocity_before = {before.slope, std::sqrt(before.var_slope)};
  impact.velocity_after = {after.slope, std::sqrt(after.var_slope)};
  const double dm = before.slope - after.slope;
  if (!(std::abs(dm) > 3.0 * std::sqrt(before.var_slope + after.var_slope)) || dm == 0.0) {
    return impact;
  }
  // The lines meet at u = (b2 - b1) / (m1 - m2).
  const double u = (after.intercept - before.intercept) / dm;
  if (!(std::abs(u) <= static_cast<double>(gap + width) / rate_hz)) return impact;
  // Gradients: (du/db1, du/dm1) = -(1, u) / dm and (du/db2, du/dm2) = (1, u) / dm.
  const double var =
      (before.var_intercept + 2.0 * u * before.covariance + u * u * before.var_slope +
       after.var_intercept + 2.0 * u * after.covariance + u * u * after.var_slope) /
      (dm * dm);
  impact.found = true;
  const double t = static_cast<double>(near_sample) / rate_hz + u;
  impact.time_s = {start_time_s + t, std::sqrt(std::max(0.0, var))};
  impact.sample = static_cast<long long>(std::ceil(t * rate_hz - 1e-9));
  return impact;
}

}  // namespace

bool ImpactDetectionOptions::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (!(threshold_sigma > 0.0)) return fail("threshold_sigma must be positive");
  if (!(onset_search_s >= 0.0)) return fail("onset_search_s must be >= 0");
  if (!(encoder_fit_s > 0.0)) return fail("encoder_fit_s must be positive");
  if (!(encoder_gap_s >= 0.0)) return fail("encoder_gap_s must be >= 0");
  return true;
}

ImpactEstimate DetectImpact(const std::vector<ChannelSamples>& channels, double start_time_s,
                            double sample_rate_hz, const ImpactDetectionOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("ImpactDetectionOptions: " + error);
  }
  if (!(sample_rate_hz > 0.0)) throw std::invalid_argument("impact detection: rate must be > 0");
  ImpactEstimate estimate;
  const ChannelImpact* best = nullptr;
  for (const ChannelSamples& channel : channels) {
    if (channel.kind != LogChannelKind::kAcceleration) continue;
    estimate.channels.push_back(
        AccelerometerImpact(channel, start_time_s, sample_rate_hz, options));
  }
  for (const ChannelImpact& impact : estimate.channels) {
    if (impact.found && (!best || impact.jump_snr > best->jump_snr)) best = &impact;
  }
  const long long near_sample = best ? best->sample : -1;
  if (best) {
    estimate.found = true;
    estimate.time_s = best->time_s;
    estimate.sample = best->sample;
    estimate.method = "accelerometer " + best->channel;
  }
  const std::size_t accelerometers = estimate.channels.size();
  for (const ChannelSamples& channel : channels) {
    if (channel.kind != LogChannelKind::kAngle) continue;
    estimate.channels.push_back(
        EncoderImpact(channel, near_sample, start_time_s, sample_rate_hz, options));
  }
  if (!estimate.found) {
    const ChannelImpact* encoder = nullptr;
    for (std::size_t i = accelerometers; i < estimate.channels.size(); ++i) {
      const ChannelImpact& impact = estimate.channels[i];
      if (impact.found && (!encoder || impact.time_s.sigma < encoder->time_s.sigma)) {
        encoder = &impact;
      }
    }
    if (encoder) {
      estimate.found = true;
      estimate.time_s = encoder->time_s;
      estimate.sample = encoder->sample;
      estimate.method = "encoder " + encoder->channel;
    }
  }
  if (!estimate.found) {
    estimate.reason =
        accelerometers == 0 && estimate.channels.empty()
            ? "no accelerometer or encoder channel"
            : fmt::format("no jump above {} noise sigmas and no velocity change found",
                          options.threshold_sigma);
  }
  return estimate;
}

}  // namespace impactlab
