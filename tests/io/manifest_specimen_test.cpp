// The manifest's [specimen] and a run's own [run.specimen]: what the bars are
// made of and what their ends look like. Read into the session and the run,
// merged key by key for a run; a bad value in [specimen] stops the session
// with the file and key, one in [run.specimen] fails that run alone.
#include <catch2/catch.hpp>

#include <string>

#include "io/manifest.h"
#include "io/session.h"
#include "tests/io/session_folder.h"

namespace impactlab {
namespace {

using Catch::Matchers::Contains;
using testing::kManifestHeader;
using testing::SessionFolder;

const std::string kRun =
    "\n[[run]]\nid = \"r1\"\ninitial_displacement = 0.405\nrebounds = [0.293, 0.195, 0.117]\n";

const std::string kSpecimen = R"toml(
[specimen]
material = "AISI 1020 steel"
end_shape = "sphere"
sphere_radius = 2.0
bar_length = 10.1
bar_diameter = 1.0
modulus = 30e6
poisson_ratio = 0.29
)toml";

std::string Refusal(SessionFolder& folder, const std::string& text) {
  folder.Write(text);
  try {
    folder.Read();
  } catch (const InputError& error) {
    return error.what();
  }
  return "accepted";
}

TEST_CASE("manifest specimen: every key is read into the session") {
  SessionFolder folder;
  folder.Write(kManifestHeader + kSpecimen + kRun);
  const Session session = folder.Read().session;
  const Specimen& s = session.specimen;
  CHECK(s.material == "AISI 1020 steel");
  CHECK(s.end_shape == "sphere");
  CHECK(s.sphere_radius == 2.0);
  CHECK(s.bar_length == 10.1);
  CHECK(s.bar_diameter == 1.0);
  CHECK(s.modulus == 30e6);
  CHECK(s.poisson_ratio == 0.29);
  CHECK_FALSE(s.edge_radius);
  CHECK_FALSE(s.contact_stiffness);
  REQUIRE(session.runs.size() == 1);
  CHECK(session.runs[0].specimen.empty());
  CHECK(SpecimenOf(session.specimen, session.runs[0].specimen).sphere_radius == 2.0);
}

TEST_CASE("manifest specimen: none given leaves it empty") {
  SessionFolder folder;
  folder.Write(kManifestHeader + kRun);
  CHECK(folder.Read().session.specimen.empty());
}

TEST_CASE("manifest specimen: a run's own table overrides the session's key by key") {
  SessionFolder folder;
  folder.Write(kManifestHeader + kSpecimen + kRun +
               "[run.specimen]\nend_shape = \"given_stiffness\"\ncontact_stiffness = 4.5e7\n");
  const Session session = folder.Read().session;
  REQUIRE(session.runs.size() == 1);
  const Specimen& own = session.runs[0].specimen;
  CHECK(own.end_shape == "given_stiffness");
  CHECK(own.contact_stiffness == 4.5e7);
  CHECK(own.material.empty());
  const Specimen merged = SpecimenOf(session.specimen, own);
  CHECK(merged.material == "AISI 1020 steel");   // the session's
  CHECK(merged.end_shape == "given_stiffness");  // the run's
  CHECK(merged.contact_stiffness == 4.5e7);
  CHECK(merged.modulus == 30e6);
}

TEST_CASE("manifest specimen: a bad value stops the session with the file and key") {
  SessionFolder folder;
  const std::string manifest = folder.manifest().string();
  const auto refusal = [&](const std::string& table) {
    return Refusal(folder, kManifestHeader + "\n[specimen]\n" + table + kRun);
  };
  CHECK_THAT(refusal("end_shape = \"cone\"\n"),
             Contains("specimen.end_shape: expected \"plane\", \"sphere\" or \"given_stiffness\", "
                      "found \"cone\""));
  CHECK_THAT(refusal("end_shape = \"cone\"\n"), Contains(manifest));
  CHECK_THAT(refusal("sphere_radius = -2\n"),
             Contains("specimen.sphere_radius: expected a positive length, found -2"));
  CHECK_THAT(refusal("modulus = \"steel\"\n"),
             Contains("specimen.modulus: expected a positive Young's modulus"));
  CHECK_THAT(refusal("poisson_ratio = 0.5\n"),
             Contains("specimen.poisson_ratio: expected a Poisson ratio greater than -1 and less "
                      "than 0.5, found 0.5"));
  CHECK_THAT(refusal("material = 7\n"),
             Contains("specimen.material: expected the material's name"));
  CHECK_THAT(Refusal(folder, "format = 1\nspecimen = 3\n" + kManifestHeader.substr(11) + kRun),
             Contains("specimen: expected a table"));
  CHECK(refusal("poisson_ratio = 0.3\n") == "accepted");
}

TEST_CASE("manifest specimen: an unknown key is said, as in every table") {
  SessionFolder folder;
  folder.Write(kManifestHeader + "\n[specimen]\nsphere_radus = 2.0\n" + kRun);
  const ManifestReadResult read = folder.Read();
  REQUIRE(read.warnings.size() == 1);
  CHECK(read.warnings[0].where.key == "specimen.sphere_radus");
  CHECK_THAT(read.warnings[0].message, Contains("sphere_radius"));
}

TEST_CASE("manifest specimen: a bad [run.specimen] fails that run alone") {
  SessionFolder folder;
  folder.Write(kManifestHeader + kSpecimen + kRun + "[run.specimen]\nsphere_radius = 0\n" +
               "\n[[run]]\nid = \"r2\"\ninitial_displacement = 0.3\nrebounds = [0.2, 0.1]\n");
  const Session session = folder.Read().session;
  REQUIRE(session.runs.size() == 1);
  CHECK(session.runs[0].id == "r2");
  REQUIRE(session.rejected.size() == 1);
  const RejectedEntry& bad = session.rejected[0];
  CHECK(bad.id == "r1");
  CHECK(bad.where.file == folder.manifest());
  CHECK(bad.where.key == "run \"r1\".specimen.sphere_radius");
  CHECK_THAT(bad.problem, Contains("expected a positive length, found 0"));
}

}  // namespace
}  // namespace impactlab
