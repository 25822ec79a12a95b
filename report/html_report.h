// `impactlab report --format html`: one self-contained page (inline CSS and
// SVG, no network) with the session summary, the tables and the figures a
// person checks a reduction by: per run the measured displacement against the
// fitted response (thesis Figures 16-18), the photocell calibrations (13-14),
// contact time against initial displacement (19), C against sqrt(xi) with its
// line (20). Formatting only: everything shown is read from the results.
#pragma once

#include <string>

#include "pipeline/session_result.h"

namespace impactlab {

std::string RenderHtmlReport(const SessionResult& result);

}  // namespace impactlab
