#include "pipeline/photo_traces.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "imagefile/image_file.h"
#include "io/errors.h"
#include "io/session_file.h"

namespace impactlab {
namespace {

// The overlay as a report page shows it, as JPEG: no wider than the page's
// column, at a quality that keeps a photo's overlay near 40 kB, so that a
// session's page with its 24 photos stays under 2 MB. Drawn at that size (the
// photo shrunk by a whole factor), not shrunk afterwards: a full-size overlay
// cost about as much as the digitizing, and shrinking a drawn one to the
// column by a fraction was a tenth of the sample photo session's CPU.
constexpr int kOverlayPageWidthPx = 800;
constexpr int kOverlayJpegQuality = 50;

// The overlay at a third of its width as RGB pixels, for the results file's
// HDF5 image: a thumbnail HDFView shows (the JPEG has every pixel). A
// whole-factor shrink is OpenCV's fast path.
constexpr int kPreviewShrink = 3;

void DrawOverlays(const Photo& photo, const DigitizeResult& result, bool thumbnail,
                  PhotoOverlay& out) {
  const cv::Mat page = DrawOverlay(photo, result, {.max_width_px = kOverlayPageWidthPx});
  if (std::string problem; !imagefile::EncodeJpeg(page, kOverlayJpegQuality, &out.jpeg, &problem)) {
    throw std::runtime_error("the overlay's JPEG: " +
                             problem);  // an 8-bit BGR image always encodes
  }
  if (!thumbnail) return;
  const int f = kPreviewShrink;
  const cv::Rect whole(0, 0, std::max(f, page.cols / f * f), std::max(f, page.rows / f * f));
  cv::Mat small;
  cv::resize(page(whole & cv::Rect(0, 0, page.cols, page.rows)), small,
             cv::Size(std::max(1, page.cols / f), std::max(1, page.rows / f)), 0.0, 0.0,
             cv::INTER_AREA);
  RgbImage& preview = out.preview;
  preview = {small.rows, small.cols, {}};
  preview.pixels.resize(static_cast<std::size_t>(small.rows) * small.cols * 3);
  cv::Mat rgb(small.rows, small.cols, CV_8UC3, preview.pixels.data());
  cv::cvtColor(small, rgb, cv::COLOR_BGR2RGB);
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

// How long the trace on the photo at `path` runs one way
// (TraceRequest::one_way_until_s): on a calibration's photo (and no run's),
// a free swing's from the release to equilibrium, a quarter of the
// small-angle period (every convention's swing lasts at least that long);
// 0 elsewhere, or where the apparatus is not given.
double OneWayUntil(const std::filesystem::path& path, const Session& session) {
  const auto is_path = [&](const auto& entry) { return entry.photo == path; };
  if (!session.apparatus || !(session.apparatus->pendulum_length > 0.0) ||
      !(session.apparatus->gravity > 0.0) ||
      std::none_of(session.calibrations.begin(), session.calibrations.end(), is_path) ||
      std::any_of(session.runs.begin(), session.runs.end(), is_path)) {
    return 0.0;
  }
  return 0.5 * std::numbers::pi *
         std::sqrt(session.apparatus->pendulum_length / session.apparatus->gravity);
}

// The contact (step) trace a photo's refusal names, when it names one: the
// refusal's key is the trace's ("traces.contact") or one within it (its
// points hint's).
std::optional<std::string> RefusedContactTrace(const InputLocation& failed_at,
                                               const std::vector<TraceRequest>& requests) {
  for (const TraceRequest& request : requests) {
    if (!request.settings.impact) continue;
    const std::string key = "traces." + request.name;
    if (failed_at.key == key || failed_at.key.starts_with(key + ".")) return request.name;
  }
  return std::nullopt;
}

}  // namespace

DigitizedPhoto DigitizeSessionPhoto(const std::filesystem::path& path, const Session& session,
                                    const std::map<std::string, TraceSettings>& traces,
                                    DigitizeOptions options, bool thumbnail) {
  // Read from inside the session folder only, and only a regular file.
  const Photo photo = DecodePhoto(ReadSessionFile(session.folder, path), path);
  std::vector<TraceRequest> requests;
  const double one_way_until_s = OneWayUntil(path, session);
  for (const auto& [name, settings] : traces) requests.push_back({name, settings, one_way_until_s});
  options.graticule.corners_px = CornersHintOf(path, session);
  DigitizeResult result = DigitizePhoto(photo, session.divisions, requests, options);
  // A contact trace not found fails alone: only the contact time needs it,
  // so the photo is read again without it and the bars' traces are kept
  // (reading the contact first, the digitizer stops at it before it reads
  // them). The second reading costs the photo's time again, on such photos
  // alone.
  DigitizedPhoto out;
  while (!result.ok && requests.size() > 1) {
    const std::optional<std::string> contact = RefusedContactTrace(result.failed_at, requests);
    if (!contact) break;
    out.lost[*contact] = {result.failed_at, result.reason};
    std::erase_if(requests, [&](const TraceRequest& r) { return r.name == *contact; });
    result = DigitizePhoto(photo, session.divisions, requests, options);
  }
  out.ok = result.ok;
  out.failed_at = result.failed_at;
  out.reason = result.reason;
  out.overlay.photo = std::filesystem::relative(path, session.folder).string();
  DrawOverlays(photo, result, thumbnail, out.overlay);
  out.overlay.graticule_residual_px = result.graticule.residual_px;
  out.overlay.processing_ms = result.ProcessingMs();
  out.overlay.hints = HintsUsed(result);
  out.overlay.hand_marks = static_cast<int>(result.mark_outlines_px.size());
  for (std::size_t i = 0; i < result.traces.size(); ++i) {
    const DigitizedTrace& t = result.traces[i];
    out.traces[t.name] = t.trace;
    out.mapping_sigma_volts[t.name] = result.graticule.px_per_div > 0.0
                                          ? 0.25 * result.graticule.residual_px /
                                                result.graticule.px_per_div *
                                                std::abs(t.settings.volts_per_div)
                                          : 0.0;
    out.overlay.trace_names.push_back(t.name);
    out.overlay.trace_coverage.push_back(t.coverage);
    out.overlay.trace_spread_px2.push_back(t.spread_px2);
    out.overlay.trace_spread_sigma_px2.push_back(t.spread_sigma_px2);
    for (const auto& [from, to] : t.mark_stretches_div) {
      out.overlay.mark_stretch_trace.push_back(static_cast<double>(i));
      out.overlay.mark_stretch_from_div.push_back(from);
      out.overlay.mark_stretch_to_div.push_back(to);
    }
    if (const auto& fit = result.pulses[i]) out.pulse = fit->pulse;
  }
  return out;
}

}  // namespace impactlab
