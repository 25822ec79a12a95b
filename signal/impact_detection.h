// The instant of impact from the accelerometers, cross-checked by the
// encoders' velocity change (docs/logs.md, "Impact detection").
//
// Accelerometer: a rigid stop changes the structure's velocity within the
// contact time, so the acceleration jumps. The first difference d_n = x_n -
// x_(n-1) is white noise (sigma_d = 1.4826 MAD, robust to the ring-down) apart
// from the jump. The strongest |d_n| marks the impact; the onset is the first
// n within `onset_search_s` before it with |d_n| > threshold_sigma * sigma_d.
// The jump happened in (t_(n-1), t_n]: the estimate is the interval's middle,
// with one-sigma dt / sqrt(12) (a uniform distribution over it).
//
// Encoder: straight lines fitted to the angle over `encoder_fit_s` before and
// after the impact (leaving `encoder_gap_s` out on each side) meet at the
// impact; their covariances give its uncertainty. Quantisation and the
// post-impact vibration make it coarser than the accelerometer's, so it is the
// fallback and the cross-check, and it gives the joint velocities before and
// after.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "io/log_reader.h"  // LogChannelKind
#include "model/estimate.h"

namespace impactlab {

struct ImpactDetectionOptions {
  double threshold_sigma = 8.0;  // onset: |first difference| above this many noise sigmas
  double onset_search_s = 0.05;  // the onset lies at most this long before the strongest jump, s
  double encoder_fit_s = 0.05;   // line fits span this long on each side of the impact, s
  double encoder_gap_s = 0.002;  // samples this close to the impact stay out of the fits, s

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("threshold_sigma", self.threshold_sigma, "onset above this many noise sigmas");
    visit("onset_search_s", self.onset_search_s, "onset at most this long before the jump, s");
    visit("encoder_fit_s", self.encoder_fit_s, "encoder line fits' span each side, s");
    visit("encoder_gap_s", self.encoder_gap_s, "samples this close stay out of the fits, s");
  }

  bool Check(std::string* error) const;
};

// One channel, sampled at a common rate from a common start.
struct ChannelSamples {
  std::string name;
  LogChannelKind kind = LogChannelKind::kOther;
  std::span<const double> values;
};

struct ChannelImpact {
  std::string channel;
  bool found = false;
  Estimate time_s;           // log time
  long long sample = -1;     // first sample after the impact (index into the values given)
  double jump_snr = 0.0;     // accelerometers: strongest |d_n| / sigma_d
  Estimate velocity_before;  // encoders: rad/s, just before
  Estimate velocity_after;   // encoders: rad/s, just after
};

struct ImpactEstimate {
  bool found = false;
  std::string reason;                   // why not found
  Estimate time_s;                      // log time of the impact
  long long sample = -1;                // first sample after it (index into the values given)
  std::string method;                   // e.g. "accelerometer a1", "encoder q1"
  std::vector<ChannelImpact> channels;  // every accelerometer and encoder
};

// Channels of other kinds are ignored. Throws std::invalid_argument for bad
// options or rate.
ImpactEstimate DetectImpact(const std::vector<ChannelSamples>& channels, double start_time_s,
                            double sample_rate_hz, const ImpactDetectionOptions& options);

}  // namespace impactlab
