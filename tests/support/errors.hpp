// The message of the std::invalid_argument a call throws ("" when it throws none), for tests of
// argument checks.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

namespace saltus::testing {

inline std::string invalidArgumentOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace saltus::testing
