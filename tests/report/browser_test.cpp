// The HTML report as a person opens it: in a real browser, headless
// Chromium (Debian's chromium, which scripts/setup.sh installs). The page
// must draw every figure with no console message, fetch nothing from the
// network, and give a failed run its section with the reason.
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/html_report.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The thesis's typed-in session with one more run whose rebounds grow: its
// fit fails, and the page must still show it.
SessionResult ThesisWithFailedRun(const fs::path& dir) {
  fs::create_directories(dir);
  std::ofstream(dir / "session.toml")
      << ReadText(fs::path(IMPACTLAB_SOURCE_DIR) / "sample_data/thesis-1969/session.toml")
      << "\n[[run]]\nid = \"rising\"\ninitial_displacement = 0.3\nrebounds = [0.15, 0.18, 0.1]\n";
  return ReduceSession(ReadManifest(dir).session, {});
}

struct BrowserRun {
  int status = -1;
  std::string dom;  // the page's DOM after its scripts ran
  std::string log;  // the browser's stderr: console messages appear as "CONSOLE"
  nlohmann::json net_log;
};

BrowserRun OpenInChromium(const fs::path& page, const fs::path& dir) {
  const fs::path dom = dir / "dom.html", log = dir / "browser.log", net = dir / "net.json";
  const std::string command = fmt::format(
      "'{}' --headless=new --no-sandbox --disable-gpu --disable-background-networking "
      "--disable-component-update --disable-sync --no-first-run --disable-default-apps "
      "--disable-extensions --user-data-dir='{}' --virtual-time-budget=15000 "
      "--enable-logging=stderr --v=0 --log-net-log='{}' --dump-dom 'file://{}' > '{}' 2> '{}'",
      IMPACTLAB_CHROMIUM, (dir / "profile").string(), net.string(), page.string(), dom.string(),
      log.string());
  BrowserRun run;
  run.status = std::system(command.c_str());
  run.dom = ReadText(dom);
  run.log = ReadText(log);
  std::ifstream net_in(net);
  if (net_in) run.net_log = nlohmann::json::parse(net_in, nullptr, false);
  return run;
}

// The URLs the page itself asked for (Chromium's own update checks carry no
// file:// isolation key): anything but the page, data: and blob: URLs.
std::vector<std::string> PageRequests(const nlohmann::json& net_log) {
  std::vector<std::string> urls;
  if (!net_log.is_object() || !net_log.contains("events")) return urls;
  int start_job = -1;
  for (const auto& [name, id] : net_log["constants"]["logEventTypes"].items()) {
    if (name == "URL_REQUEST_START_JOB") start_job = id.get<int>();
  }
  for (const auto& event : net_log["events"]) {
    if (event.value("type", -2) != start_job || !event.contains("params")) continue;
    const auto& params = event["params"];
    const std::string url = params.value("url", "");
    const std::string key = params.value("network_isolation_key", "");
    if (key.find("file://") == std::string::npos) continue;
    if (url.rfind("file:", 0) == 0 || url.rfind("data:", 0) == 0 || url.rfind("blob:", 0) == 0) {
      continue;
    }
    urls.push_back(url);
  }
  return urls;
}

TEST_CASE("browser: the report draws every figure, fetches nothing, shows the failed run") {
  INFO("chromium: " << IMPACTLAB_CHROMIUM << " (scripts/setup.sh installs it)");
  REQUIRE(std::string(IMPACTLAB_CHROMIUM).size() > 0);
  testing::TempDir dir;
  const SessionResult result = ThesisWithFailedRun(dir.path() / "session");
  const fs::path page = dir.path() / "report.html";
  std::ofstream(page) << RenderHtmlReport(result);

  const BrowserRun run = OpenInChromium(page, dir.path());
  REQUIRE(run.status == 0);
  REQUIRE(run.dom.find("<h1>") != std::string::npos);
  // No console message: no script error, no warning from dygraphs.
  {
    INFO(run.log);
    CHECK(run.log.find("CONSOLE") == std::string::npos);
  }
  // Nothing fetched by the page.
  REQUIRE(run.net_log.is_object());
  CHECK(PageRequests(run.net_log).empty());
  // Every figure drawn: dygraphs puts its canvas into each graph's div and
  // the series names into each legend.
  const std::regex graph(
      R"re(<div id="(figure-\d+)" class="graph"[^>]*>([\s\S]*?)</div><div id="\1-legend" class="legend"[^>]*>([\s\S]*?)</div></div>)re");
  std::size_t figures = 0;
  for (std::sregex_iterator m(run.dom.begin(), run.dom.end(), graph), end; m != end; ++m) {
    INFO((*m)[1]);
    ++figures;
    CHECK((*m)[2].str().find("<canvas") != std::string::npos);
    CHECK((*m)[3].str().size() > 20);
  }
  CHECK(figures == 8 + 1);  // the thesis's runs, and C against sqrt(xi); none for the failed run
  // The failed run: its section, with its reason.
  const std::size_t section = run.dom.find("<h2 id=\"run-rising\">");
  REQUIRE(section != std::string::npos);
  CHECK(run.dom.find("exceeds", section) != std::string::npos);
}

}  // namespace
}  // namespace impactlab
