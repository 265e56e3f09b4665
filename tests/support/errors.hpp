// The message of the exception a call throws ("" when it throws none), for tests of argument and
// input checks.
#pragma once

#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

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

// 1-based number of the first line of `path` containing `text` (the line an error message should
// name), or a test failure and −1.
inline int lineOf(const std::string& path, const std::string& text) {
  std::ifstream in(path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (line.find(text) != std::string::npos) return n;
  ADD_FAILURE() << path << " has no line containing '" << text << "'";
  return -1;
}

// The checks of a fixture broken on purpose, whose offending line carries the comment
// `# <-- error`: loading it (`load`) throws an E whose message starts with "<path>:<that line>:",
// names ": <key_path>: " (unless key_path is empty) and contains every one of `parts`. Returns the
// message.
template <class E>
std::string expectMarkedError(const std::string& path, const std::function<void()>& load,
                              const std::string& key_path, const std::vector<std::string>& parts) {
  const std::string what = expectedMessageOf<E>(load);
  const std::string where = path + ":" + std::to_string(lineOf(path, "# <-- error")) + ":";
  EXPECT_EQ(what.rfind(where, 0), 0u) << "expected to start with " << where << "\n" << what;
  if (!key_path.empty()) {
    EXPECT_NE(what.find(": " + key_path + ": "), std::string::npos) << key_path << "\n" << what;
  }
  for (const std::string& p : parts) EXPECT_NE(what.find(p), std::string::npos) << p << "\n" << what;
  return what;
}

inline std::string invalidArgumentOf(const std::function<void()>& f) {
  return messageOf<std::invalid_argument>(f);
}

}  // namespace saltus::testing
