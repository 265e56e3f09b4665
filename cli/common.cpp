#include "cli/common.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

#include "dynamics/urdf.hpp"
#include "scene/atomic_file.hpp"
#include "scene/cleanup.hpp"

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

std::vector<std::string> splitCommaList(const std::string& text) {
  std::vector<std::string> items;
  for (std::size_t start = 0;;) {
    const std::size_t comma = text.find(',', start);
    items.push_back(trimmed(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) return items;
    start = comma + 1;
  }
}

dynamics::BaseType parseBaseOption(const std::string& option, const std::string& value) {
  try {
    return dynamics::parseBaseType(value);
  } catch (const std::invalid_argument&) {
  }
  throw UsageError(option + ": expected fixed, planar or free, got '" + value + "'");
}

namespace {

// The option `name` ("--dt") of `app` or of a subcommand of it that was given.
const CLI::Option* givenOption(const CLI::App& app, const std::string& name) {
  for (const CLI::Option* o : app.get_options())
    if (o->check_name(name) && o->count() > 0) return o;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    if (sub->parsed())
      if (const CLI::Option* o = givenOption(*sub, name)) return o;
  return nullptr;
}

// `text` occurs in `message` as a whole token ("1" is not shown by "10" or "1.5").
bool showsToken(const std::string& message, const std::string& text) {
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.'; };
  for (std::size_t k = message.find(text); k != std::string::npos; k = message.find(text, k + 1)) {
    const bool left = k == 0 || !word(message[k - 1]) || !word(text.front());
    const std::size_t end = k + text.size();
    const bool right = end >= message.size() || !word(message[end]) || !word(text.back());
    if (left && right) return true;
  }
  return false;
}

}  // namespace

std::string withValueAsWritten(const CLI::App& command, const std::string& message) {
  if (message.rfind("--", 0) != 0) return message;
  const std::size_t end = message.find_first_of(": ");
  const std::string name = message.substr(0, end);
  const CLI::Option* option = givenOption(command, name);
  if (!option || option->results().empty()) return message;
  std::string written;
  for (const std::string& r : option->results()) written += (written.empty() ? "" : ",") + r;
  if (written.empty() || showsToken(message, written)) return message;
  for (const std::string& r : option->results())  // a list: the message quotes the item it is about
    for (std::size_t start = 0; start <= r.size();) {
      const std::size_t comma = std::min(r.find(',', start), r.size());
      const std::string item = r.substr(start, comma - start);
      if (!item.empty() && showsToken(message, item)) return message;
      start = comma + 1;
    }
  return message + (message.find(", got ") != std::string::npos ? " (written '" + written + "')"
                                                                   : ", got '" + written + "'");
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
  if (!trimmed(text).empty()) tokens = splitCommaList(text);
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

void checkOutputTarget(const std::string& option, const std::string& path, OutputTarget kind) {
  namespace fs = std::filesystem;
  std::error_code error;
  const auto status = fs::symlink_status(path, error);
  const auto target = fs::status(path, error);
  const std::string named = option + " " + path + ": ";
  fs::path probe_in;  // the folder a probe file is made in
  if (kind == OutputTarget::Folder) {
    if (fs::exists(target) && !fs::is_directory(target)) throw UsageError(named + "exists and is not a folder");
    probe_in = fs::absolute(path, error);  // the nearest folder that exists: missing ones are made
    while (!probe_in.empty() && !fs::is_directory(probe_in, error) && probe_in != probe_in.root_path())
      probe_in = probe_in.parent_path();
    if (fs::exists(probe_in, error) && !fs::is_directory(probe_in, error))
      throw UsageError(named + probe_in.string() + " is not a folder");
  } else {
    if (fs::is_directory(target)) throw UsageError(named + "is a folder; expected a file to write");
    const bool device = scene::writtenInPlace(path);
    if (device && kind == OutputTarget::RegularFile)
      throw UsageError(named + "is a device or a pipe; expected a regular file (it is written to a temporary file "
                               "beside it and renamed)");
    if (device) return;
    if (fs::is_symlink(status))
      throw UsageError(named + "is a symlink; refusing to replace it (give the file it points to)");
    if (fs::exists(status) && !fs::is_regular_file(status))
      throw UsageError(named + "exists and is not a regular file; refusing to replace it");
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty() && !fs::is_directory(parent, error))
      throw UsageError(named + "the folder " + parent.string() + " does not exist");
    probe_in = parent.empty() ? fs::path(".") : parent;
  }
  // A file made and removed where the output goes: only writing tells whether it can be written.
  const std::string probe = scene::temporaryName((probe_in / ".saltus-probe").string());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw UsageError(named + "cannot write in " + probe_in.string() + " (" + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

}  // namespace saltus::cli
