// Every table of the bundled sessions compiles with Debian's TeX
// (texlive-latex-recommended, texlive-science: `scripts/setup.sh --tex`) in a
// plain article on A4 with 25 mm margins, with nothing but the packages the
// report names, and fits its page: no error, no overfull box. Without pdflatex the test says so and
// CTest counts it skipped.
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "report/latex_table.h"
#include "report/tables.h"
#include "tests/support/sample_data.h"
#include "tests/support/temp_dir.h"
#include "tests/support/text_file.h"

namespace impactlab {
// A named namespace: the test program is one unity build.
namespace latex_compile_test {

namespace fs = std::filesystem;

using testing::ReadText;

TEST_CASE("latex_compile: every table compiles with pdflatex and fits an A4 article's page") {
  if (std::string(IMPACTLAB_PDFLATEX).empty()) {
    WARN(
        "[skipped] no pdflatex: install texlive-latex-recommended and texlive-science "
        "(scripts/setup.sh --tex) and reconfigure to run this test");
    return;
  }
  for (const char* session : {"thesis-1969", "logs-two-link"}) {
    const SessionResult result =
        ReduceSession(ReadManifest(testing::kSampleData / session).session, {});
    testing::TempDir dir;
    // The report's own document: every table, as `report -f tex` writes it.
    std::ofstream(dir.path() / "tables.tex")
        << RenderTables(result.title, BuildTables(result), ReportFormat::kLatex);
    // A paper's page: A4, 25 mm margins (16 cm of text).
    std::ofstream(dir.path() / "paper.tex") << "\\documentclass[a4paper]{article}\n"
                                            << "\\usepackage[margin=25mm]{geometry}\n"
                                            << kLatexPackages
                                            << "\\begin{document}\n\\input{tables}\n"
                                               "\\end{document}\n";
    const std::string command = fmt::format(
        "cd '{}' && '{}' -interaction=nonstopmode -halt-on-error paper.tex > pdflatex.out 2>&1",
        dir.path().string(), IMPACTLAB_PDFLATEX);
    const int status = std::system(command.c_str());
    const std::string log = ReadText(dir.path() / "paper.log");
    INFO(session << ":\n" << log.substr(log.size() > 6000 ? log.size() - 6000 : 0));
    CHECK(status == 0);
    CHECK(fs::exists(dir.path() / "paper.pdf"));
    // Fits the page: TeX reports every line or row wider than the text.
    CHECK(log.find("Overfull \\hbox") == std::string::npos);
    CHECK(log.find("LaTeX Error") == std::string::npos);
  }
}

}  // namespace latex_compile_test
}  // namespace impactlab
