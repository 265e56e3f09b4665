// The message of the exception a call throws ("" when it throws none), for tests of argument and
// input checks.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace saltus::testing {

// The message of the exception of type E a call throws ("" when it throws none).
template <class E>
std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

// The same, and a test failure when the call throws nothing (for checks of bad input that must
// be refused).
template <class E>
std::string expectedMessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception of the expected type thrown";
  return "";
}

inline std::string invalidArgumentOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace saltus::testing
