// One bad [[run]], [[calibration]] or [[log]] entry fails alone: the manifest
// reader keeps every other entry and reports the bad one with the file, the
// key, the line, what was expected and what was found. Only a manifest that
// cannot be used at all stops the session. Also the checks that keep the
// reader inside the session folder and away from special files.
#include <sys/stat.h>

#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/manifest.h"
#include "tests/io/session_folder.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using testing::SessionFolder;
using testing::TempDir;

using testing::kManifestHeader;

std::string TypedRun(const std::string& id, const std::string& extra = "") {
  return fmt::format(
      "\n[[run]]\nid = \"{}\"\ninitial_displacement = 0.405\n"
      "rebounds = [0.293, 0.195, 0.117]\n{}",
      id, extra);
}

const std::string kCalibration = R"toml(
[[calibration]]
id = "R"
cell = "right"
initial_displacement = 0.2
photo = "c.png"
[calibration.trace]
time_per_div = 0.05
volts_per_div = 0.2
)toml";

// A photo run named `id`, with `photo` and the right trace's time_per_div.
std::string PhotoRun(const std::string& id, const std::string& photo,
                     const std::string& time_per_div = "0.5") {
  return fmt::format(
      "\n[[run]]\nid = \"{}\"\ninitial_displacement = 0.234\nphoto = {}\n"
      "[run.traces.right]\ntime_per_div = {}\nvolts_per_div = 0.2\n",
      id, photo, time_per_div);
}

// Reads a manifest of a good run, then `bad`, then another good run, and
// checks that exactly the bad entry (of `table`) is rejected with `key`
// and a reason containing `expected`.
void CheckRejectedAlone(SessionFolder& folder, const std::string& bad, const std::string& table,
                        const std::string& key, const std::string& expected,
                        const std::string& before = "") {
  const std::string text = kManifestHeader + before + TypedRun("good-1") + bad + TypedRun("good-2");
  folder.Write(text);
  const ManifestReadResult read = folder.Read();
  const Session& session = read.session;
  INFO(text);
  REQUIRE(session.rejected.size() == 1);
  const RejectedEntry& entry = session.rejected.front();
  INFO(entry.Reason());
  CHECK(entry.table == table);
  CHECK(entry.where.file == folder.manifest());
  CHECK(entry.where.key == key);
  CHECK(entry.where.line.has_value());
  CHECK_THAT(entry.problem, Contains(expected));
  CHECK_THAT(entry.Reason(), Contains(folder.manifest().string()));
  int good_runs = 0;
  for (const Run& run : session.runs) good_runs += run.id.rfind("good-", 0) == 0 ? 1 : 0;
  CHECK(good_runs == 2);
}

TEST_CASE("manifest entries: each mistake inside one run fails that run alone") {
  SessionFolder folder;
  folder.Touch("runs/ok.jpg");
  SECTION("a missing photo") {
    CheckRejectedAlone(folder, PhotoRun("bad", "\"runs/missing.jpg\""), "run", "run \"bad\".photo",
                       "expected an existing file, found no file at \"runs/missing.jpg\"");
  }
  SECTION("a path through ..") {
    CheckRejectedAlone(folder, PhotoRun("bad", "\"../x.jpg\""), "run", "run \"bad\".photo",
                       "which uses '..'");
  }
  SECTION("an absolute path") {
    CheckRejectedAlone(folder, PhotoRun("bad", "\"/etc/passwd\""), "run", "run \"bad\".photo",
                       "found the absolute path \"/etc/passwd\"");
  }
  SECTION("a symbolic link leading out") {
    TempDir outside;
    std::ofstream(outside.path() / "secret.jpg") << "x";
    fs::create_symlink(outside.path() / "secret.jpg", folder.path() / "runs/link.jpg");
    CheckRejectedAlone(folder, PhotoRun("bad", "\"runs/link.jpg\""), "run", "run \"bad\".photo",
                       "leads outside it through a symbolic link");
  }
  SECTION("a folder given as the photo") {
    fs::create_directories(folder.path() / "runs/folder.jpg");
    CheckRejectedAlone(folder, PhotoRun("bad", "\"runs/folder.jpg\""), "run", "run \"bad\".photo",
                       "expected a file, found a folder");
  }
  SECTION("a named pipe given as the photo") {
    REQUIRE(::mkfifo((folder.path() / "runs/pipe.jpg").c_str(), 0600) == 0);
    CheckRejectedAlone(folder, PhotoRun("bad", "\"runs/pipe.jpg\""), "run", "run \"bad\".photo",
                       "expected a regular file, found a named pipe");
  }
  SECTION("a wrong type") {
    std::string bad = TypedRun("bad");
    bad.replace(bad.find("0.405"), 5, "\"abc\"");
    CheckRejectedAlone(folder, bad, "run", "run \"bad\".initial_displacement",
                       "expected a positive displacement X0 (in), found string \"abc\"");
  }
  SECTION("nan") {
    std::string bad = TypedRun("bad");
    bad.replace(bad.find("0.405"), 5, "nan");
    CheckRejectedAlone(folder, bad, "run", "run \"bad\".initial_displacement",
                       "which is not a finite number");
  }
  SECTION("inf") {
    CheckRejectedAlone(folder, TypedRun("bad", "contact_time = inf\n"), "run",
                       "run \"bad\".contact_time", "which is not a finite number");
  }
  SECTION("time_per_div = 0") {
    CheckRejectedAlone(folder, PhotoRun("bad", "\"runs/ok.jpg\"", "0"), "run",
                       "run \"bad\".traces.right.time_per_div",
                       "expected a positive number of s/div, found 0");
  }
  SECTION("a duplicate id") {
    CheckRejectedAlone(folder, TypedRun("good-1"), "run", "run \"good-1\".id",
                       "expected an id no other run has, found \"good-1\"");
  }
  SECTION("an unknown calibration id") {
    CheckRejectedAlone(folder, TypedRun("bad", "calibration = { right = \"nope\" }\n"), "run",
                       "run \"bad\".calibration.right", "found \"nope\", which no calibration has");
  }
  SECTION("a calibration of the other cell") {
    folder.Touch("c.png");
    CheckRejectedAlone(folder, TypedRun("bad", "calibration = { left = \"R\" }\n"), "run",
                       "run \"bad\".calibration.left", "which calibrates the right cell",
                       kCalibration);
  }
  SECTION("X0 longer than the pendulum") {
    std::string bad = TypedRun("bad");
    bad.replace(bad.find("0.405"), 5, "1e6");
    CheckRejectedAlone(folder, bad, "run", "run \"bad\".initial_displacement",
                       "expected a displacement X0 between 2.2e-05 and 22 in");
  }
  SECTION("X0 vanishingly small") {
    std::string bad = TypedRun("bad");
    bad.replace(bad.find("0.405"), 5, "1e-300");
    CheckRejectedAlone(folder, bad, "run", "run \"bad\".initial_displacement", "found 1e-300");
  }
}

TEST_CASE("manifest entries: unsafe ids are refused and the entry is named by its position") {
  SessionFolder folder;
  for (const std::string id : {"a/b", ".", "..", "x/", "", " spaced", "-opt", "<b>", "a\\\\b"}) {
    INFO("id: " << id);
    folder.Write(kManifestHeader + TypedRun("good-1") + TypedRun(id) + TypedRun("good-2"));
    const Session session = folder.Read().session;
    REQUIRE(session.rejected.size() == 1);
    CHECK(session.rejected[0].id == "#2");
    CHECK(session.rejected[0].position == 1);
    CHECK(session.runs.size() == 2);
  }
  folder.Write(kManifestHeader + TypedRun("R-0.234_a+b"));
  CHECK(folder.Read().session.rejected.empty());
}

TEST_CASE("manifest entries: a bad calibration fails itself and the runs that need it") {
  SessionFolder folder;
  std::string bad = kCalibration;
  bad.replace(bad.find("volts_per_div = 0.2"), 19, "volts_per_div = -1");
  folder.Write(kManifestHeader + bad + TypedRun("needs-it", "calibration = { right = \"R\" }\n") +
               TypedRun("independent"));
  folder.Touch("c.png");
  const Session session = folder.Read().session;
  REQUIRE(session.rejected.size() == 2);
  CHECK(session.rejected[0].table == "calibration");
  CHECK(session.rejected[0].id == "R");
  CHECK(session.rejected[1].table == "run");
  CHECK(session.rejected[1].id == "needs-it");
  CHECK_THAT(session.rejected[1].problem, Contains("found \"R\", which cannot be used"));
  CHECK_THAT(session.rejected[1].problem, Contains("calibration \"R\".trace.volts_per_div"));
  REQUIRE(session.runs.size() == 1);
  CHECK(session.runs[0].id == "independent");
}

TEST_CASE("manifest entries: a bad channel in one of two logs fails that log alone") {
  SessionFolder folder;
  folder.Touch("l.csv");
  folder.Write(
      "format = 1\n[[log]]\nid = \"one\"\nexperiment = \"l.csv\"\n"
      "[log.channels]\nq1 = { column = \"enc1\", counts_per_rev = \"many\" }\n"
      "[[log]]\nid = \"two\"\nexperiment = \"l.csv\"\n"
      "[log.channels]\nq1 = { column = \"enc1\", counts_per_rev = 4096 }\n");
  const Session session = folder.Read().session;
  REQUIRE(session.rejected.size() == 1);
  CHECK(session.rejected[0].table == "log");
  CHECK(session.rejected[0].where.key == "log \"one\".channels.q1.counts_per_rev");
  CHECK(session.rejected[0].where.line == 6);
  REQUIRE(session.logs.size() == 1);
  CHECK(session.logs[0].id == "two");
}

TEST_CASE("manifest entries: a prediction of a rejected run is rejected, saying why") {
  SessionFolder folder;
  folder.Write(kManifestHeader + TypedRun("good-1") + TypedRun("bad", "contact_time = -1\n") +
               "\n[[prediction]]\nsource_run = \"good-1\"\ntarget_run = \"bad\"\n");
  const Session session = folder.Read().session;
  REQUIRE(session.rejected.size() == 2);
  CHECK(session.rejected[1].table == "prediction");
  CHECK_THAT(session.rejected[1].problem, Contains("a run that cannot be reduced"));
}

TEST_CASE("manifest entries: an unusable manifest still stops the session") {
  SessionFolder folder;
  SECTION("not TOML") { folder.Write("format = = 1\n"); }
  SECTION("no format") { folder.Write("title = \"x\"\n"); }
  SECTION("a broken apparatus") { folder.Write("format = 1\n[apparatus]\nweight = 2.23\n"); }
  CHECK_THROWS_AS(folder.Read(), InputError);
}

TEST_CASE("manifest entries: an implausible apparatus is refused with its range") {
  SessionFolder folder;
  const auto refusal = [&](const std::string& apparatus) {
    folder.Write("format = 1\n[apparatus]\n" + apparatus);
    try {
      folder.Read();
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(refusal("pendulum_length = 22\nweight = 2.23\ngravity = 1e-300\n"),
             Contains("apparatus.gravity: expected the acceleration of gravity in in/s^2"));
  CHECK_THAT(refusal("pendulum_length = 22\nweight = 2.23\ngravity = 9.81\n"),
             Contains("within 5 % of the standard 385.644"));
  CHECK_THAT(refusal("pendulum_length = 1e300\nweight = 2.23\n"),
             Contains("apparatus.pendulum_length: expected a pendulum length between"));
  CHECK_THAT(refusal("pendulum_length = 22\nweight = 2.23\narrangement = \"wall\"\n"),
             Contains("not supported yet"));
  CHECK(refusal("pendulum_length = 22\nmass = 0.0058\ngravity = 386.1\n") == "accepted");
}

TEST_CASE("manifest entries: a manifest that is a link out of the folder is not read") {
  SessionFolder folder;
  TempDir outside;
  std::ofstream(outside.path() / "session.toml") << kManifestHeader << TypedRun("outside");
  fs::create_symlink(outside.path() / "session.toml", folder.manifest());
  try {
    folder.Read();
    FAIL("the outside manifest was read");
  } catch (const InputError& error) {
    CHECK_THAT(error.what(), Contains("outside the session folder"));
  }
}

TEST_CASE("manifest entries: a manifest that is a named pipe is refused without waiting") {
  SessionFolder folder;
  REQUIRE(::mkfifo(folder.manifest().c_str(), 0600) == 0);
  try {
    folder.Read();
    FAIL("accepted");
  } catch (const InputError& error) {
    CHECK_THAT(error.what(), Contains("named pipe"));
  }
}

}  // namespace
}  // namespace impactlab
