// The parameter file (docs/two-link.md, "Parameters"): TOML tables [beam1],
// [beam2], [hub1], [body2], [hub3], [tool], [drive_a], [drive_b], [surface],
// [sensors], [sanding], [case1], [case2], [case3], SI units. A key left out
// keeps its nominal value (TwoLinkParameters::Nominal), so a file may list
// only what differs; an unknown table or key is an error (a typo).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "multibody/two_link_parameters.h"

namespace impactlab {

// Throws InputError (io/errors.h) naming `file`, the line and the key for
// TOML that does not parse, an unknown key, a value that is not a number or
// out of its range.
TwoLinkParameters ParseTwoLinkParameters(std::string_view text, const std::filesystem::path& file);

// The same, with the keys the file leaves out taken from `base` instead of
// the nominal set (an experiment's file listing only how it differs from a
// simulation's).
TwoLinkParameters ParseTwoLinkParameters(std::string_view text, const std::filesystem::path& file,
                                         const TwoLinkParameters& base);

// Every key with its description as a comment; reads back to the same values.
std::string TwoLinkParametersText(const TwoLinkParameters& parameters);

}  // namespace impactlab
