#include "pipeline/run_fingerprint.h"

#include <xxhash.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <memory>

#include <fmt/format.h>

#include "io/errors.h"

namespace impactlab {
namespace {

// Streams every value with a separator, so that adjacent fields cannot alias.
class Hasher {
 public:
  Hasher() : state_(XXH3_createState(), XXH3_freeState) { XXH3_128bits_reset(state_.get()); }

  Hasher& Add(const std::string& text) {
    XXH3_128bits_update(state_.get(), text.data(), text.size());
    XXH3_128bits_update(state_.get(), "\x1f", 1);
    return *this;
  }
  Hasher& Add(double value) { return Add(fmt::format("{:a}", value)); }  // exact bits

  Hasher& AddFile(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError({path, "", std::nullopt}, "cannot read the file");
    std::array<char, 1 << 16> buffer{};
    while (in) {
      in.read(buffer.data(), buffer.size());
      XXH3_128bits_update(state_.get(), buffer.data(), static_cast<std::size_t>(in.gcount()));
    }
    return Add(path.filename().string());
  }

  std::string Hex() const {
    const XXH128_hash_t h = XXH3_128bits_digest(state_.get());
    return fmt::format("{:016x}{:016x}", h.high64, h.low64);
  }

 private:
  std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state_;
};

void AddTrace(Hasher& h, const TraceSettings& s) {
  h.Add(s.time_per_div).Add(s.volts_per_div).Add(s.zero_div).Add(s.band_div[0]).Add(s.band_div[1]);
  h.Add(s.t0_div).Add(s.impact ? std::to_string(*s.impact) : "-");
  if (s.csv) h.AddFile(*s.csv);
}

}  // namespace

std::string RunFingerprint(const Run& run, const Session& session, const std::string& producer) {
  Hasher h;
  h.Add(producer).Add(std::string(UnitSystemName(session.units)));
  if (session.apparatus) {
    h.Add(session.apparatus->pendulum_length).Add(session.apparatus->mass);
    h.Add(session.apparatus->gravity);
  }
  h.Add(session.divisions[0]).Add(session.divisions[1]);
  h.Add(run.id).Add(run.initial_displacement).Add(run.first_rebound);
  for (double x : run.rebounds) h.Add(x);
  h.Add(run.contact_time.value_or(-1.0)).Add(run.rebound_uncertainty.value_or(-1.0));
  h.Add(run.contact_time_uncertainty.value_or(-1.0));
  if (run.photo) h.AddFile(*run.photo);
  for (const auto& [name, trace] : run.traces) {
    h.Add(name);
    AddTrace(h, trace);
  }
  for (const auto& [cell, id] : run.calibration) {
    h.Add(cell).Add(id);
    const auto c = std::find_if(session.calibrations.begin(), session.calibrations.end(),
                                [&](const Calibration& k) { return k.id == id; });
    if (c == session.calibrations.end()) continue;
    h.Add(c->cell).Add(c->initial_displacement);
    if (c->photo) h.AddFile(*c->photo);
    AddTrace(h, c->trace);
  }
  return h.Hex();
}

}  // namespace impactlab
