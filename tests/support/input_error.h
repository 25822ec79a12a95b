// The message of the InputError a call throws, for tests that check what a
// user is told.
#pragma once

#include <string>

#include "io/errors.h"

namespace impactlab::testing {

// The message of the InputError `f` throws (empty when none is thrown).
template <typename F>
std::string InputErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace impactlab::testing
