// The traces of one photo, digitized for `reduce` (digitize/digitize.h): every
// trace the manifest reads from the photo in one pass (the photo is decoded
// once), the contact pulse measured on the image, and a small overlay for the
// report. OpenCV stays behind this header.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "digitize/digitize.h"
#include "io/session.h"
#include "io/trace.h"
#include "pipeline/session_result.h"
#include "rebounds/rebound_extraction.h"

namespace impactlab {

// A trace the photo's reading could not find, and was read without: where
// (the photo, and the trace's key on it, "traces.contact") and why.
struct LostTrace {
  InputLocation at;
  std::string reason;
};

struct DigitizedPhoto {
  // false: the photo was not read to the end (DigitizeResult): no traces,
  // the overlay shows what was found and why not.
  bool ok = true;
  InputLocation failed_at;
  std::string reason;
  std::map<std::string, Trace> traces;  // by trace name ("right", "left", "contact", ...)
  // Contact (step) traces not found: each fails alone, the photo read again
  // without it, so that the bars' traces are kept. By trace name.
  std::map<std::string, LostTrace> lost;
  std::optional<ContactPulse> pulse;  // the contact trace's edges, measured on the image
  PhotoOverlay overlay;               // what was found, drawn on the photo
  // Per trace, the error in volts its samples share through the photo's
  // mapping: a quarter of the graticule's residual. The residual holds the
  // lines' own measurement scatter, which the mapping's fit averages over
  // hundreds of measurements, and the model's misfit, which neighbouring
  // samples share (a maximum's fit does not average it away); the fit's
  // summary does not tell them apart, and a quarter is the share that makes
  // the maxima's pulls honest on both benchmark sets (docs/digitizing.md).
  std::map<std::string, double> mapping_sigma_volts;
};

// A photo not read to the end (no graticule, a trace missing from its band)
// is a result with !ok naming the photo and what was not found, its overlay
// drawn; a contact trace missing from its band is `lost` instead, when the
// photo reads without it. Throws InputError for a file that cannot be read
// or decoded.
// `options`: the photo's entry's; the manifest's corners hint, when it gives one, is added.
// `thumbnail`: make the overlay's quarter-width pixels too (products.thumbnails).
DigitizedPhoto DigitizeSessionPhoto(const std::filesystem::path& photo, const Session& session,
                                    const std::map<std::string, TraceSettings>& traces,
                                    DigitizeOptions options, bool thumbnail = true);

}  // namespace impactlab
