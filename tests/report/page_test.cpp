// The HTML page of the bundled photo session as a reader's browser gets it:
// light enough to open at once (under 2 MB with its 24 digitized photos),
// its figures' points with error bars rather than joined by a line and a
// band, kept inside the frame, and text columns read left to right. (That a
// browser draws it, and how fast: browser_test.cpp.)
#include <regex>
#include <string>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/html_report.h"
#include "tests/report/thesis_result.h"
#include "tests/support/sample_data.h"

namespace impactlab {
// A named namespace: the test program is one unity build.
namespace page_test {

// The <script> that draws the figure titled `title`.
std::string FigureScript(const std::string& html, const std::string& title) {
  const std::size_t at = html.find("title:\"" + title + "\"");
  if (at == std::string::npos) return "";
  const std::size_t begin = html.rfind("<script>", at), end = html.find("</script>", at);
  return html.substr(begin, end - begin);
}

TEST_CASE(
    "page: the photo session's page weighs under 2 MB with its photos and draws contact times with "
    "bars") {
  const SessionResult r =
      ReduceSession(ReadManifest(testing::kSampleData / "thesis-photos").session, {});
  std::size_t photos = 0;
  for (const RunResult& run : r.runs) {
    photos += run.measured.overlays.size();
    for (const CellCalibration& c : run.measured.calibrations) photos += c.overlay ? 1 : 0;
  }
  REQUIRE(photos == 24);
  const std::string html = RenderHtmlReport(r);
  CHECK(html.size() < 2'000'000);
  // Each photo at a size a page shows, loaded when scrolled to.
  std::size_t images = 0;
  for (std::size_t p = 0; (p = html.find("<img ", p)) != std::string::npos; ++p) {
    ++images;
    const std::string tag = html.substr(p, html.find('>', p) - p);
    CHECK_THAT(tag, Catch::Contains("loading=\"lazy\""));
  }
  CHECK(images == 24);
  for (const RunResult& run : r.runs) {
    for (const PhotoOverlay& o : run.measured.overlays) CHECK(o.jpeg.size() < 60'000);
  }
  // Its contact times, measured on the photos: points with bars.
  const std::string contact = FigureScript(html, "Contact time against initial displacement");
  REQUIRE(!contact.empty());
  CHECK_THAT(contact, Catch::Contains("plotter:impactlabErrorBars"));
  CHECK_THAT(contact, Catch::Contains("xRangePad:14,yRangePad:14"));
}

TEST_CASE("page: contact time against X0 is points with error bars, inside a padded frame") {
  const std::string html = RenderHtmlReport(testing::Thesis());
  const std::string contact = FigureScript(html, "Contact time against initial displacement");
  // thesis-1969 has no per-run contact times: C against sqrt(xi) has the same kind of points.
  const std::string damping = FigureScript(html, "C against √ξ");
  REQUIRE(!damping.empty());
  for (const std::string& script : {contact, damping}) {
    if (script.empty()) continue;
    INFO(script.substr(0, 300));
    // The runs' points drawn by the bar plotter: no band, no line between them.
    CHECK_THAT(script, Catch::Contains("\"runs ± 1σ\":{strokeWidth:0,drawPoints:true,pointSize:3,"
                                       "plotter:impactlabErrorBars}"));
    // The axes padded, so that the end points and their bars are whole.
    CHECK_THAT(script, Catch::Contains("xRangePad:14,yRangePad:14"));
  }
  CHECK_THAT(html, Catch::Contains("function impactlabErrorBars(e)"));
}

TEST_CASE("page: numbers right-aligned, texts left-aligned in every table") {
  const std::string html = RenderHtmlReport(testing::Thesis());
  CHECK_THAT(html, Catch::Contains("text-align: left") &&
                       Catch::Contains("th.num, td.num { text-align: right; }"));
  // Table 2: the run id and the fit-pair star are text, the maxima numbers.
  const std::regex row(
      R"(<tr><td>0\.115</td><td class="num">0</td><td>\*</td><td class="num">0\.0680</td>)");
  CHECK(std::regex_search(html, row));
  // The check list and the statuses: text.
  CHECK(html.find("<td class=\"num\">ok") == std::string::npos);
}

}  // namespace page_test
}  // namespace impactlab
