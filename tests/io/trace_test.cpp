#include "io/trace.h"

#include <sstream>

#include <catch2/catch.hpp>

#include "io/errors.h"

namespace impactlab {
namespace {

TEST_CASE("trace: a CSV reads to its samples") {
  std::istringstream in("time_s,volts\n0.0,1.5\n0.001,1.25\n");
  const Trace trace = ParseTraceCsv(in, "t.csv");
  CHECK(trace.time_s == std::vector<double>{0.0, 0.001});
  CHECK(trace.volts == std::vector<double>{1.5, 1.25});
}

TEST_CASE("trace: an empty CSV is called empty, a wrong header is quoted") {
  std::istringstream empty("");
  CHECK_THROWS_WITH(ParseTraceCsv(empty, "empty.csv"),
                    Catch::Contains("empty.csv") && Catch::Contains("the file is empty"));
  std::istringstream wrong("t,v\n0,1\n");
  CHECK_THROWS_WITH(ParseTraceCsv(wrong, "wrong.csv"),
                    Catch::Contains("expected the header \"time_s,volts\", found \"t,v\""));
}

}  // namespace
}  // namespace impactlab
