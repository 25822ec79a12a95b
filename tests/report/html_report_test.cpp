#include "report/html_report.h"

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/svg_plot.h"
#include "report/tables.h"
#include "tests/report/thesis_result.h"

namespace impactlab {
namespace {

using testing::Thesis;

TEST_CASE("html_report: one self-contained page with every table and a figure per run") {
  const std::string html = RenderHtmlReport(Thesis());
  CHECK_THAT(html, Catch::StartsWith("<!DOCTYPE html>"));
  // Nothing is fetched: no script, style sheet or image comes from elsewhere;
  // dygraphs is inlined, once.
  for (const char* outside : {"<script src", "<link", "src=\"http", "href=\"http", "url(http"}) {
    INFO(outside);
    CHECK(html.find(outside) == std::string::npos);
  }
  CHECK_THAT(html, Catch::Contains("Dygraph"));
  const auto count = [&](const std::string& text) {
    std::size_t n = 0;
    for (std::size_t p = 0; (p = html.find(text, p)) != std::string::npos; ++p) ++n;
    return n;
  };
  CHECK(count("<script>") - count("<script>impactlabPlot(") == 1);
  for (const char* caption : {"thesis Table 2", "thesis Table 3", "thesis eq. 40", "thesis Table 4",
                              "thesis Figure 20"}) {
    INFO(caption);
    CHECK_THAT(html, Catch::Contains(caption));
  }
  // Every figure is drawn from its own data: one per run, and C against sqrt(xi).
  std::size_t figures = 0, empty = 0;
  for (std::size_t p = 0; (p = html.find("new Dygraph(", p)) != std::string::npos; ++p) {
    ++figures;
    empty += html.compare(html.find(',', p) + 1, 3, "[],") == 0 ? 1 : 0;
  }
  CHECK(figures == 8 + 1);
  CHECK(empty == 0);
  // The maxima carry their error bars, at one sigma.
  CHECK_THAT(html, Catch::Contains("errorBars:true,sigma:1"));
}

TEST_CASE("html_report: every figure also exists as a static SVG for papers") {
  const SessionResult r = Thesis();
  const auto figures = RenderStaticFigures(r);
  REQUIRE(figures.size() == 8 + 1);
  for (const auto& [name, svg] : figures) {
    INFO(name);
    CHECK_THAT(name, Catch::EndsWith(".svg"));
    CHECK(name.find('/') == std::string::npos);
    CHECK_THAT(svg, Catch::StartsWith("<svg") && Catch::EndsWith("</svg>"));
  }
  // The maxima's error bars are drawn in the SVG too (a vertical line per maximum).
  CHECK_THAT(figures[0].second, Catch::Contains("<line x1=\""));
}

TEST_CASE("html_report: the page reads top-down: contents, a summary, then the details") {
  SessionResult r = Thesis();
  r.runs[2].ok = false;
  r.runs[2].reason = "session.toml:40: run \"0.323\": the photo is unreadable";
  const std::string html = RenderHtmlReport(r);
  const auto at = [&](const std::string& text) {
    const std::size_t p = html.find(text);
    INFO(text);
    CHECK(p != std::string::npos);
    return p;
  };
  // Contents before the summary, the summary before the tables and the runs.
  CHECK(at("<nav><h2>Contents</h2>") < at("<h2 id=\"summary\">Summary</h2>"));
  CHECK(at("<h2 id=\"summary\">Summary</h2>") < at("<h2 id=\"tables\">Tables</h2>"));
  CHECK(at("<h2 id=\"tables\">Tables</h2>") < at("<h2 id=\"run-0.115\">"));
  // Every table is linked from the contents, by an id it has.
  for (const Table& t : BuildTables(r)) {
    at("href=\"#table-" + t.name + "\"");
    at("<table id=\"table-" + t.name + "\">");
  }
  // The summary counts the failed run and links to its section, which says why.
  at("8 run(s): <span class=\"ok\">7 reduced</span>");
  at("1 failed</span>: <a href=\"#run-0.323\">0.323</a>");
  CHECK(at("<h2 id=\"run-0.323\">") < at("the photo is unreadable</p>"));
  at("K avg = ");
  at("best at predicting an unseen run <b>");
  // Poynting-Thomson: a short sentence per run, the full account folded away.
  at("1 of 3 combinations determined");
  CHECK(at("<details><summary>Details</summary>") > at("<table id=\"table-poynting_thomson\">"));
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
  plot.series.push_back({"s", {0.0, 1.0, 2.0}, {10.0, 20.0, 15.0}, {}});
  const std::string svg = RenderSvg(plot);
  CHECK_THAT(svg, Catch::Contains("a &lt; b &amp; c"));
  CHECK_THAT(svg, Catch::Contains("<polyline"));
  CHECK_THAT(svg, Catch::EndsWith("</svg>"));
}

}  // namespace
}  // namespace impactlab
