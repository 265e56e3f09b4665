// The message of the exception a call throws ("" when it throws none), for tests of argument and
// input checks.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

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

inline std::string invalidArgumentOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace saltus::testing
