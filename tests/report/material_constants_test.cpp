// The contact-law parameter table shows the material constant a law's k
// holds where the session's specimen makes it identifiable (E* with its
// error, the handbook's beside it), and says why where it does not.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

#include "report/tables.h"

namespace impactlab {
namespace {

const Table& ContactTableNamed(const std::vector<Table>& tables, const std::string& name) {
  const auto it =
      std::find_if(tables.begin(), tables.end(), [&](const Table& t) { return t.name == name; });
  REQUIRE(it != tables.end());
  return *it;
}

TEST_CASE("material constants: the contact laws' table shows E*, the handbook's, or why not") {
  SessionResult r;
  ContactLawFit hc;
  hc.law = "hunt-crossley";
  hc.ok = true;
  hc.maxima = 30;
  hc.parameters = {{"hertz_stiffness", "hertz_stiffness", {6.0e7, 3.0e5}},
                   {"damping_factor", "inverse_speed", {1.5, 0.01}}};
  hc.effective_modulus = Estimate{1.59e7, 8.0e4};
  hc.handbook_effective_modulus = 1.63e7;
  ContactLawFit hertz = hc;
  hertz.law = "hertz";
  hertz.effective_modulus.reset();
  hertz.handbook_effective_modulus.reset();
  hertz.effective_modulus_unidentifiable = "plane ends";
  r.contact_laws = {hc, hertz};

  const std::vector<Table> tables = BuildTables(r);
  const Table& t = ContactTableNamed(tables, "contact_law_parameters");
  const auto row = [&](const std::string& law, const std::string& starts) {
    for (const auto& cells : t.rows) {
      if (cells[0].text == law && cells[1].text.rfind(starts, 0) == 0) return cells;
    }
    FAIL("no row " << law << " " << starts);
    return t.rows.front();
  };
  const auto modulus = row("hunt-crossley", "effective_modulus");
  CHECK(modulus[2].value == 1.59e7);
  CHECK(modulus[2].sigma == 8.0e4);
  CHECK(modulus[6].text == "psi");
  CHECK(row("hunt-crossley", "handbook_effective_modulus")[2].value == 1.63e7);
  CHECK(std::find(t.notes.begin(), t.notes.end(), "hertz: E* not identifiable: plane ends.") !=
        t.notes.end());
}

}  // namespace
}  // namespace impactlab
