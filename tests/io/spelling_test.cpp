#include "io/spelling.h"

#include <catch2/catch.hpp>

namespace impactlab {
namespace {

TEST_CASE("spelling: the edit distance counts insertions, deletions, substitutions, swaps") {
  CHECK(EditDistance("", "") == 0);
  CHECK(EditDistance("reduce", "reduce") == 0);
  CHECK(EditDistance("reduc", "reduce") == 1);                 // a dropped letter
  CHECK(EditDistance("rebounds_", "rebounds") == 1);           // a stray underscore
  CHECK(EditDistance("volts_per_dvi", "volts_per_div") == 1);  // a swapped pair
  CHECK(EditDistance("kitten", "sitting") == 3);
  CHECK(EditDistance("abc", "") == 3);
}

TEST_CASE("spelling: the nearest known word, when near enough to be a typo") {
  const std::vector<std::string> keys = {"id", "initial_displacement", "rebounds",
                                         "rebound_uncertainty", "contact_time"};
  CHECK(NearestWord("initial_displacment", keys) == "initial_displacement");
  CHECK(NearestWord("Rebounds_", keys) == "rebounds");  // case is ignored
  CHECK(NearestWord("ib", keys) == "id");
  CHECK_FALSE(NearestWord("photo", keys).has_value());     // nothing like it
  CHECK_FALSE(NearestWord("rebounds", keys).has_value());  // not a typo: the word itself
  CHECK(DidYouMean("contact_tme", keys) == " (did you mean \"contact_time\"?)");
  CHECK(DidYouMean("weight", keys).empty());
}

}  // namespace
}  // namespace impactlab
