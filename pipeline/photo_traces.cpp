#include "pipeline/photo_traces.h"

#include <opencv2/imgcodecs.hpp>

#include "digitize/digitize.h"
#include "io/errors.h"
#include "io/session_file.h"

namespace impactlab {
namespace {

// The overlay at a size a report page shows well, as JPEG: a few hundred kB
// per photo instead of megabytes of PNG. Drawn at that size, not shrunk
// afterwards: a full-size overlay cost about as much as the digitizing.
constexpr int kOverlayWidthPx = 1200;

std::vector<unsigned char> EncodeOverlay(const Photo& photo, const DigitizeResult& result) {
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", DrawOverlay(photo, result, {.max_width_px = kOverlayWidthPx}), jpeg,
               {cv::IMWRITE_JPEG_QUALITY, 82});
  return jpeg;
}

// The manifest's corners hint for the photo at `path`: of the run or the
// calibration whose photo it is (the first that gives one, should two
// entries share a photo).
std::optional<GraticuleCorners> CornersHintOf(const std::filesystem::path& path,
                                              const Session& session) {
  for (const Run& run : session.runs) {
    if (run.photo == path && run.graticule_corners_px) return run.graticule_corners_px;
  }
  for (const Calibration& calibration : session.calibrations) {
    if (calibration.photo == path && calibration.graticule_corners_px) {
      return calibration.graticule_corners_px;
    }
  }
  return std::nullopt;
}

}  // namespace

DigitizedPhoto DigitizeSessionPhoto(const std::filesystem::path& path, const Session& session,
                                    const std::map<std::string, TraceSettings>& traces,
                                    DigitizeOptions options) {
  // Read from inside the session folder only, and only a regular file.
  const Photo photo = DecodePhoto(ReadSessionFile(session.folder, path), path);
  std::vector<TraceRequest> requests;
  for (const auto& [name, settings] : traces) requests.push_back({name, settings});
  options.graticule.corners_px = CornersHintOf(path, session);
  const DigitizeResult result = DigitizePhoto(photo, session.divisions, requests, options);

  DigitizedPhoto out;
  out.overlay.photo = std::filesystem::relative(path, session.folder).string();
  out.overlay.jpeg = EncodeOverlay(photo, result);
  out.overlay.graticule_residual_px = result.graticule.residual_px;
  out.overlay.processing_ms = result.ProcessingMs();
  out.overlay.hints = HintsUsed(result);
  for (std::size_t i = 0; i < result.traces.size(); ++i) {
    const DigitizedTrace& t = result.traces[i];
    out.traces[t.name] = t.trace;
    out.overlay.trace_names.push_back(t.name);
    out.overlay.trace_coverage.push_back(t.coverage);
    out.overlay.trace_spread_px2.push_back(t.spread_px2);
    out.overlay.trace_spread_sigma_px2.push_back(t.spread_sigma_px2);
    if (const auto& fit = result.pulses[i]) out.pulse = fit->pulse;
  }
  return out;
}

}  // namespace impactlab
