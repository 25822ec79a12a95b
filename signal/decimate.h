// Decimation: the low-pass FIR decimator that keeps long logs in bounded memory,
// and the min/max decimation used for plots (docs/logs.md).
//
// The FIR is a Kaiser-windowed sinc (beta 8, 16 taps per output sample on each
// side), cut off at 0.45 of the output rate: flat to about 0.35 of the output
// rate (-0.0005 dB) and 80 dB down from 0.55. Output k is centred on input k * factor (no
// delay); past either end the edge sample is held. A linear time-invariant
// filter maps a damped sinusoid to one with the same frequency and decay, so
// decimating a ring-down biases neither (apart from the first and last
// 16 output samples, where the edge hold acts).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace impactlab {

// Output samples at each end of a decimated record that the edge hold reaches.
inline constexpr int kDecimationEdgeSamples = 16;

// The FIR taps for `factor` (odd length 32 * factor + 1, unit DC gain).
std::vector<double> DecimationTaps(int factor);

// Feeds samples block by block; outputs appear as soon as the filter has the
// samples it needs. The output count is ceil(n / factor) for n input samples.
class StreamingDecimator {
 public:
  explicit StreamingDecimator(int factor);

  void Push(std::span<const double> samples, std::vector<double>& out);
  void Finish(std::vector<double>& out);  // the outputs that need the held last sample

  int factor() const { return factor_; }

 private:
  void Produce(std::vector<double>& out);

  int factor_;
  int half_;  // taps on each side of the centre
  std::vector<double> taps_;
  std::vector<double> buffer_;  // inputs from buffer_start_ on
  long long buffer_start_ = 0;  // input index of buffer_[0] (negative: held first sample)
  long long received_ = 0;      // inputs pushed so far
  long long next_centre_ = 0;   // input index of the next output's centre
};

// The whole signal at once.
std::vector<double> Decimate(std::span<const double> samples, int factor);

// At most about `points` samples for plotting: each bucket of samples keeps its
// minimum and maximum, in time order, so spikes and envelopes survive.
struct DecimatedSeries {
  std::vector<double> time_s;
  std::vector<double> value;
};
DecimatedSeries MinMaxDecimate(std::span<const double> values, double start_time_s, double interval_s,
                          std::size_t points);

}  // namespace impactlab
