// The message of the exception a call throws ("" when it throws none), for tests of argument and
// input checks.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace saltus::testing {

// The message of the exception of type E a call throws ("" when it throws none); `thrown`, when
// given, says whether it threw.
template <class E>
std::string messageOf(const std::function<void()>& f, bool* thrown = nullptr) {
  if (thrown != nullptr) *thrown = true;
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  if (thrown != nullptr) *thrown = false;
  return "";
}

// The same, and a test failure when the call throws nothing (for checks of bad input that must
// be refused).
template <class E>
std::string expectedMessageOf(const std::function<void()>& f) {
  bool thrown = false;
  std::string message = messageOf<E>(f, &thrown);
  if (!thrown) ADD_FAILURE() << "no exception of the expected type thrown";
  return message;
}

inline std::string invalidArgumentOf(const std::function<void()>& f) {
  return messageOf<std::invalid_argument>(f);
}

}  // namespace saltus::testing
