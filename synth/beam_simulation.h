// The flexible arm (synth/beam_model.h) in motion, sampled as its sensors see
// it, and what the experiment's logger makes of that.
//
// Free flight until the tip reaches the wall, s = L (theta - theta_w) + q2 = 0.
// The impact is perfectly plastic and the tip then stays on the wall, the
// paper's non-holonomic constraint: the post-impact velocity is the projection
// p'+ = p'- - M^-1 G^T (G M^-1 G^T)^-1 G p'-, G = (L, 1, 0), and the motion
// continues in (q2, q3) with theta = theta_w - q2 / L. The response is
// integrated by RK4 with 20 steps per sample (relative error ~1e-8), the impact
// instant bracketed and bisected to 1e-13 s.
//
// An accelerometer sample is the mean acceleration over the sample interval
// before it (an integrating anti-alias filter: the change of the sensor's
// velocity over the interval), so the impact's impulse shows as one sample's
// spike of (velocity jump) / dt, as a real accelerometer sees the short
// contact. Sample k is at t = k / rate.
#pragma once

#include <cstdint>
#include <vector>

#include "synth/beam_model.h"

namespace impactlab {

// A clean record of one arm, in SI.
struct BeamRecord {
  std::vector<double> time_s, angle_rad, a1_m_s2, a2_m_s2;
  double impact_time_s = 0.0;
  double impact_speed_m_s = 0.0;     // tip speed into the wall
  double min_contact_force_n = 0.0;  // after the impact; < 0 would mean the tip pulls
  std::vector<BeamPole> free_modes;  // free flight: real poles, then modes by frequency
  std::vector<BeamPole> post_modes;  // tip on the wall, the same
  // Per channel (angle, a1, a2) and post-impact pole: amplitude at the first
  // sample whose interval lies after the impact, SI.
  std::vector<std::vector<double>> post_mode_amplitudes;
};

// Throws std::invalid_argument for an arm that fails its Check() or a tip that
// does not reach the wall within `duration_s`.
BeamRecord SimulateBeam(const BeamArm& arm, const BeamSensors& sensors, double sample_rate_hz,
                        double duration_s);

// What the experiment's logger writes of a record: the encoder's whole counts
// and the accelerometers' volts with Gaussian noise (`noise_factor` times the
// sensors' sigmas), in the ADC's steps.
struct LoggedSamples {
  std::vector<double> time_s;
  std::vector<long long> encoder_counts;
  std::vector<double> a1_v, a2_v;
};

// The noise follows from `seed` alone, on every platform.
LoggedSamples LogExperiment(const BeamRecord& record, const BeamSensors& sensors,
                            double noise_factor, std::uint64_t seed);

}  // namespace impactlab
