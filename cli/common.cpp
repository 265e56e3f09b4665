#include "cli/common.hpp"

#include <filesystem>
#include <charconv>
#include <cmath>
#include <sstream>

#include "dynamics/urdf.hpp"
#include "scene/atomic_file.hpp"

namespace saltus::cli {

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

}  // namespace

dynamics::BaseType parseBaseOption(const std::string& option, const std::string& value) {
  try {
    return dynamics::parseBaseType(value);
  } catch (const std::invalid_argument&) {
  }
  throw UsageError(option + ": expected fixed, planar or free, got '" + value + "'");
}

UsageError optionError(const std::exception& e) {
  std::string message = e.what();
  const std::size_t colon = message.find(':');
  for (std::size_t i = 0; i < colon && colon != std::string::npos; ++i)
    if (message[i] == '_') message[i] = '-';
  return UsageError("--" + message);
}

Eigen::VectorXd parseCoordinateVector(const std::string& option, const std::string& text,
                                      const std::vector<std::string>& coordinates) {
  const std::size_t n = coordinates.size();
  const auto expected = [&] {
    std::ostringstream s;
    s << "expected " << n << " comma-separated number" << (n == 1 ? "" : "s") << " (coordinates: "
      << (n ? joined(coordinates) : "none") << ")";
    return s.str();
  };
  std::vector<std::string> tokens;
  if (!trimmed(text).empty()) {
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = text.find(',', start);
      tokens.push_back(trimmed(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  if (tokens.size() != n)
    throw UsageError(option + ": " + expected() + ", got " + std::to_string(tokens.size()));
  Eigen::VectorXd x(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const std::string& t = tokens[i];
    const char* first = t.data() + (t.size() > 1 && t[0] == '+' ? 1 : 0);
    const char* last = t.data() + t.size();
    double value = 0;
    const auto [end, ec] = std::from_chars(first, last, value);
    const std::string where = "value " + std::to_string(i + 1) + " (" + coordinates[i] + ")";
    if (t.empty()) throw UsageError(option + ": " + where + " is empty; " + expected());
    if (ec == std::errc::result_out_of_range)
      throw UsageError(option + ": " + where + " '" + t + "' is out of range for a double");
    if (ec != std::errc() || end != last)
      throw UsageError(option + ": " + where + " '" + t + "' is not a number; " + expected());
    if (!std::isfinite(value)) throw UsageError(option + ": " + where + " '" + t + "' is not a finite number");
    x[static_cast<Eigen::Index>(i)] = value;
  }
  return x;
}

}  // namespace saltus::cli

namespace saltus::cli {

void checkOutputTarget(const std::string& option, const std::string& path, bool folder) {
  namespace fs = std::filesystem;
  std::error_code error;
  const auto status = fs::symlink_status(path, error);
  const auto target = fs::status(path, error);
  const std::string named = option + " " + path + ": ";
  if (folder) {
    if (fs::exists(target) && !fs::is_directory(target)) throw UsageError(named + "exists and is not a folder");
    return;
  }
  if (fs::is_directory(target)) throw UsageError(named + "is a folder; expected a file to write");
  const bool device = scene::writtenInPlace(path);
  if (fs::is_symlink(status) && !device)
    throw UsageError(named + "is a symlink; refusing to replace it (give the file it points to)");
  if (fs::exists(status) && !fs::is_regular_file(status) && !device && !fs::is_symlink(status))
    throw UsageError(named + "exists and is not a regular file; refusing to replace it");
  const fs::path parent = fs::path(path).parent_path();
  if (!device && !parent.empty() && !fs::is_directory(parent, error))
    throw UsageError(named + "the folder " + parent.string() + " does not exist");
}

}  // namespace saltus::cli
