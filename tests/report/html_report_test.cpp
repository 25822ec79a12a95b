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

TEST_CASE("html_report: a digitized photo's overlay is embedded, not linked") {
  SessionResult r = Thesis();
  PhotoOverlay o;
  o.photo = "runs/a.jpg";
  o.jpeg = {0xff, 0xd8, 0xff, 0xe0, 'M', 'a', 'n'};
  o.trace_names = {"right"};
  o.trace_coverage = {0.9};
  r.runs[0].measured.overlays.push_back(o);
  const std::string html = RenderHtmlReport(r);
  CHECK_THAT(html, Catch::Contains("data:image/jpeg;base64,/9j/4E1hbg=="));
  CHECK_THAT(html, Catch::Contains("right 90 %"));
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
