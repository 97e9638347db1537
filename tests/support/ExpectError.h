#pragma once
// The message of the InputError an action throws, to compare with the one
// line a user sees; the test fails if it throws nothing.
#include <gtest/gtest.h>

#include <string>

#include "tessera/core/Error.h"

namespace tessera::test {

template <class Action>
std::string inputErrorMessage(Action action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

}  // namespace tessera::test
