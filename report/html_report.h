// `impactlab report --format html`: one self-contained page (inline CSS and
// dygraphs, no network) opening with what to check (tables.h CheckList, each
// item linked to its run, log or table), then contents, a summary, the
// tables and the figures
// a person checks a reduction by: per run the measured displacement against
// the fitted response with the residual beneath (thesis Figures 16-18), the
// photocell calibrations (13-14), contact time against initial displacement
// (19), C against sqrt(xi) with its line (20), the logs' histories and
// spectra. Formatting only: everything shown is read from the results.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pipeline/session_result.h"

namespace impactlab {

std::string RenderHtmlReport(const SessionResult& result);

// The page's figures as static SVG, for papers (`report --figures DIR`):
// (file name, SVG text), in the page's order.
std::vector<std::pair<std::string, std::string>> RenderStaticFigures(const SessionResult& result);

}  // namespace impactlab
