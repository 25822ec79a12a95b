#include "model/rebound_history.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace impactlab {

ReboundSequence SimulateRebounds(const Pendulum& pendulum, const ContactLaw& contact,
                                 double release_x, int rebound_count) {
  if (rebound_count < 0) {
    throw std::invalid_argument(fmt::format("rebound count must be >= 0, got {}", rebound_count));
  }
  if (!(release_x > 0.0)) {
    throw std::invalid_argument(fmt::format("release displacement must be > 0, got {}", release_x));
  }
  ReboundSequence seq;
  const double quarter_swing = 0.5 * HalfPeriod(pendulum, release_x);
  seq.xmax.push_back(release_x);
  seq.peak_time.push_back(0.0);
  seq.start_time.push_back(0.0);
  seq.duration.push_back(quarter_swing);

  double t = quarter_swing;
  double speed = SpeedFromAmplitude(pendulum, release_x);
  for (int n = 1; n <= rebound_count; ++n) {
    // Impact n: a linear contact law gives the same tau_c and e at every speed,
    // but asking it each time keeps the loop right for any law.
    const ContactResponse response = contact.Respond(speed);
    if (n == 1) seq.contact = response;
    seq.impact_time.push_back(t);
    seq.impact_speed.push_back(speed);
    t += response.contact_time;
    speed *= response.restitution;  // conservative rebound: leaves at the exit speed
    seq.exit_speed.push_back(speed);

    const double amplitude = AmplitudeFromSpeed(pendulum, speed);
    const double duration = HalfPeriod(pendulum, amplitude);
    seq.xmax.push_back(amplitude);
    seq.start_time.push_back(t);
    seq.duration.push_back(duration);
    seq.peak_time.push_back(t + 0.5 * duration);
    t += duration;
  }
  if (rebound_count == 0) seq.contact = contact.Respond(speed);
  return seq;
}

double HistoryDisplacement(const ReboundSequence& seq, const Pendulum& pendulum,
                           const ContactLaw& contact, double t) {
  if (t < 0.0) return seq.xmax.front();  // held at the magnet before release
  if (t < seq.duration.front()) return ReleaseSwingDisplacement(pendulum, seq.xmax.front(), t);
  // The last impact that began at or before t.
  const auto next = std::upper_bound(seq.impact_time.begin(), seq.impact_time.end(), t);
  if (next == seq.impact_time.begin()) return 0.0;
  const std::size_t n = static_cast<std::size_t>(next - seq.impact_time.begin());  // impact n
  const double since_impact = t - seq.impact_time[n - 1];
  if (t < seq.start_time[n]) {
    return -contact.Compression(seq.impact_speed[n - 1], since_impact);  // eq. 20
  }
  const double since_rebound = t - seq.start_time[n];
  if (since_rebound > seq.duration[n]) return 0.0;  // past the simulated rebounds
  return ReboundDisplacement(pendulum, seq.exit_speed[n - 1], since_rebound);
}

SampledHistory SampleHistory(const ReboundSequence& seq, const Pendulum& pendulum,
                             const ContactLaw& contact, double time_step) {
  const double end = seq.start_time.back() + seq.duration.back();
  if (!(time_step > 0.0) || !(end / time_step < 1e8)) {
    throw std::invalid_argument(fmt::format(
        "time step must be > 0 and give at most 1e8 samples over {} s, got {}", end, time_step));
  }
  const auto count = static_cast<std::size_t>(std::floor(end / time_step)) + 1;
  SampledHistory out;
  out.time.reserve(count);
  out.displacement.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double t = static_cast<double>(i) * time_step;  // no accumulated drift
    out.time.push_back(t);
    out.displacement.push_back(HistoryDisplacement(seq, pendulum, contact, t));
  }
  return out;
}

}  // namespace impactlab
