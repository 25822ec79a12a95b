// ReadLogCsv (encoder and accelerometer logs) on arbitrary bytes, with the
// sample session's columns.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <vector>

#include "fuzz/fuzz_file.h"
#include "io/log_reader.h"

namespace {

// sample_data/logs-two-link's channels: an encoder and two accelerometers.
std::vector<impactlab::LogChannel> Channels() {
  impactlab::LogChannel q1{"q1", "enc1", 4096.0, 50.0, std::nullopt};
  impactlab::LogChannel a1{"a1", "acc1", std::nullopt, 1.0, 0.1};
  impactlab::LogChannel a2{"a2", "acc2", std::nullopt, 1.0, 0.005};
  return {q1, a1, a2};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<impactlab::LogChannel> channels = Channels();
  const auto path = impactlab::fuzz::WriteInput(data, size, "log.csv");
  try {
    // Small blocks, so that the fuzzer's short inputs reach the block logic.
    impactlab::LogReadOptions options;
    options.block_rows = 64;
    options.rate_estimate_rows = 16;
    impactlab::ReadLogCsv(path, "t", channels, impactlab::LogSource::kExperiment, options,
                          [](const impactlab::LogBlock&) {});
  } catch (const std::exception&) {
  }
  return 0;
}
