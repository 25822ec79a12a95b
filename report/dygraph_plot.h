// Interactive plots for the HTML report, drawn by dygraphs (Debian's
// libjs-dygraphs, inlined into the page so that it opens offline): zoom and
// pan, error bars where a value has a standard error, the legend beside the
// plot rather than over it. The same Plot renders as a static SVG
// (report/svg_plot.h) for papers.
#pragma once

#include <string>

#include "report/svg_plot.h"

namespace impactlab {

// The dygraphs library and its style sheet, as the page inlines them once.
std::string DygraphLibrary();

// `plot` as a <div> and the <script> that draws it there when it comes into
// view (within a screen's height of it); `id` must be unique in the page
// (letters, digits, '-').
std::string RenderDygraph(const Plot& plot, const std::string& id);

}  // namespace impactlab
