#include "report/html_report.h"

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/svg_plot.h"

namespace impactlab {
namespace {

SessionResult Thesis() {
  const auto folder = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";
  return ReduceSession(ReadManifest(folder).session, {});
}

TEST_CASE("html_report: one self-contained page with every table and a figure per run") {
  const std::string html = RenderHtmlReport(Thesis());
  CHECK_THAT(html, Catch::StartsWith("<!DOCTYPE html>"));
  // Nothing is fetched: the only URL is the SVG namespace.
  std::string without_ns = html;
  for (std::size_t p; (p = without_ns.find("http://www.w3.org/2000/svg")) != std::string::npos;) {
    without_ns.erase(p, 26);
  }
  CHECK(without_ns.find("http") == std::string::npos);
  CHECK(without_ns.find("<script") == std::string::npos);
  for (const char* caption : {"thesis Table 2", "thesis Table 3", "thesis eq. 40", "thesis Table 4",
                              "thesis Figure 20"}) {
    INFO(caption);
    CHECK_THAT(html, Catch::Contains(caption));
  }
  std::size_t figures = 0;
  for (std::size_t p = 0; (p = html.find("<svg", p)) != std::string::npos; ++p) ++figures;
  CHECK(figures == 8 + 1);  // one per run, and C against sqrt(xi)
}

TEST_CASE("svg_plot: text is escaped and the axes cover the data") {
  Plot plot;
  plot.title = "a < b & c";
  plot.series.push_back({"s", {0.0, 1.0, 2.0}, {10.0, 20.0, 15.0}});
  const std::string svg = RenderSvg(plot);
  CHECK_THAT(svg, Catch::Contains("a &lt; b &amp; c"));
  CHECK_THAT(svg, Catch::Contains("<polyline"));
  CHECK_THAT(svg, Catch::EndsWith("</svg>"));
}

}  // namespace
}  // namespace impactlab
