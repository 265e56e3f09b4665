#include "scene/yaml_reader.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <fstream>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <set>
#include <sstream>

namespace saltus::scene {

namespace {

std::size_t editDistance(const std::string& a, const std::string& b);
double atan2Fn(double y, double x) { return std::atan2(y, x); }
std::string checkExpressionText(const std::string& s);
void setupParser(mu::Parser& p);
bool plainNumber(const std::string& s, double& x);

}  // namespace

std::string joinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(none)" : s;
}

std::string keyPath(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}
std::string indexPath(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Scalar: return "the scalar '" + n.Scalar() + "'";
    case YAML::NodeType::Sequence: return "a sequence";
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Null: return "an empty value";
    default: return "nothing";
  }
}

std::string location(const std::string& file, const YAML::Mark& m) {
  if (m.is_null() || m.line < 0) return file;
  return file + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(10);
  s << x;
  return s.str();
}
std::string fmt(const Eigen::Vector3d& v) {
  return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]";
}

bool isIdentifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}


// " (did you mean 'x'?)" when one candidate is close to `word`.
std::string suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const std::string& c : candidates) {
    const std::size_t d = editDistance(word, c);
    if (d < best_d) best_d = d, best = c;
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}


namespace {

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> d(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = d[0];
    d[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = d[j];
      d[j] = std::min({d[j] + 1, d[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return d[b.size()];
}

// Rejects muparser's assignment operator (`x = 3` would change a parameter) and its
// comma-separated multiple expressions; returns "" when the text is acceptable.
std::string checkExpressionText(const std::string& s) {
  int depth = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (c == ',' && depth == 0)
      return "a number is one expression, found a ',' outside parentheses (a YAML list needs [ ] "
             "around it)";
    if (c == '=') {
      const char prev = i > 0 ? s[i - 1] : ' ', next = i + 1 < s.size() ? s[i + 1] : ' ';
      if (next != '=' && prev != '=' && prev != '<' && prev != '>' && prev != '!')
        return "assignment ('=') is not allowed in an expression";
    }
  }
  return "";
}

void setupParser(mu::Parser& p) {
  p.DefineConst("pi", std::numbers::pi);
  p.DefineFun("atan2", atan2Fn);
}

// A plain decimal number, without going through muparser.
bool plainNumber(const std::string& s, double& x) {
  if (s.empty()) return false;
  char* end = nullptr;
  x = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(x) &&
         s.find_first_of("xXpP") == std::string::npos;  // no hex floats, no inf/nan words
}

}  // namespace

namespace {

// Where each document starts; nothing else of the events is kept.
struct DocumentMarks : YAML::EventHandler {
  std::vector<YAML::Mark> starts;
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

}  // namespace

YAML::Node loadYamlFile(const std::string& path, const std::string& what) {
  try {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (std::filesystem::is_directory(status))
      throw ScenarioError(path + ": is a folder; expected a " + what + " (YAML)");
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
      throw ScenarioError(path + ": is not a regular file; expected a " + what + " (YAML)");
    if (!std::filesystem::exists(status)) throw ScenarioError(path + ": cannot open the " + what + ": no such file");
    // Size before reading: yaml-cpp holds the whole tree in memory, several times the text.
    if (std::filesystem::file_size(path, error) > kMaxYamlBytes)
      throw ScenarioError(path + ": " + std::to_string(std::filesystem::file_size(path, error)) +
                          " bytes; expected a " + what + " of at most " + std::to_string(kMaxYamlBytes) + " bytes");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ScenarioError(path + ": cannot open the " + what);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    const YAML::Node root = YAML::Load(text);
    // One document: a second one (after '---') would be silently ignored. Counted with a parser
    // that stops at two: yaml-cpp 0.7's LoadAll never ends on some inputs (a line starting with
    // ',', yaml-cpp issue #1040, found by tests/fuzz).
    std::istringstream again(text);
    YAML::Parser parser(again);
    DocumentMarks marks;
    for (int n = 0; n < 2 && parser.HandleNextDocument(marks); ++n) {
    }
    if (marks.starts.size() > 1)
      throw ScenarioError(location(path, marks.starts[1]) + ": a second YAML document; a " + what +
                          " holds one (remove the '---' line before it)");
    return root;
  } catch (const YAML::ParserException& e) {
    throw ScenarioError(location(path, e.mark) + ": YAML syntax error: " + e.msg);
  } catch (const YAML::BadFile&) {
    throw ScenarioError(path + ": cannot open the " + what);
  }
}

std::vector<std::string> yamlFileNames(const std::string& directory) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

YamlSource resolveYamlFile(const std::string& name_or_path, const std::string& directory, const std::string& kind,
                           const std::string& file_kind) {
  auto ends = [&](const std::string& suffix) {
    return name_or_path.size() >= suffix.size() &&
           name_or_path.compare(name_or_path.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (name_or_path.find('/') != std::string::npos || ends(".yaml") || ends(".yml")) return {name_or_path, name_or_path};
  const std::vector<std::string> names = yamlFileNames(directory);
  if (std::find(names.begin(), names.end(), name_or_path) == names.end())
    throw ScenarioError("unknown built-in " + kind + " '" + name_or_path + "'" + suggestion(name_or_path, names) +
                        "; built-in " + kind + "s (" + directory + "): " + joinNames(names) + "; or give the path of a " +
                        file_kind + " (.yaml)");
  return {directory + "/" + name_or_path + ".yaml", "builtin:" + name_or_path};
}

YamlReader::YamlReader(std::string file, std::map<std::string, double> overrides)
    : file_(std::move(file)), overrides_(std::move(overrides)) {
  setupParser(parser_);
}

void YamlReader::fail(const YAML::Mark& m, const std::string& path, const std::string& what) const {
  throw ScenarioError(location(file_, m) + ": " + (path.empty() ? "" : path + ": ") + what);
}

void YamlReader::checkMap(const YAML::Node& n, const std::string& path, const std::vector<std::string>& allowed,
                          bool allow_null) const {
  if (allow_null && n.IsNull()) return;
  if (!n.IsMap()) fail(n, path, "expected a map, got " + describe(n));
  std::set<std::string> seen;
  for (auto it = n.begin(); it != n.end(); ++it) {
    if (!it->first.IsScalar()) fail(it->first, path, "map keys must be plain names, got " + describe(it->first));
    const std::string k = it->first.Scalar();
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), k) == allowed.end())
      fail(it->first, keyPath(path, k),
           "unknown key '" + k + "'" + suggestion(k, allowed) + "; expected one of: " + joinNames(allowed));
    if (!seen.insert(k).second) fail(it->first, keyPath(path, k), "key '" + k + "' is given twice");
  }
}

void YamlReader::checkSequence(const YAML::Node& n, const std::string& path) const {
  if (!n.IsSequence() && !n.IsNull()) fail(n, path, "expected a sequence (a YAML list), got " + describe(n));
}

YAML::Mark YamlReader::keyMark(const YAML::Node& map, const std::string& key) {
  for (auto it = map.begin(); it != map.end(); ++it)
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->first.Mark();
  return map.Mark();
}

YAML::Node YamlReader::required(const YAML::Node& map, const std::string& path, const std::string& key) const {
  const YAML::Node n = map[key];
  if (!n.IsDefined()) fail(map, keyPath(path, key), "missing required key '" + key + "'");
  return n;
}

std::string YamlReader::text(const YAML::Node& n, const std::string& path) const {
  if (!n.IsScalar()) fail(n, path, "expected a name (a scalar), got " + describe(n));
  return n.Scalar();
}

double YamlReader::evaluate(const std::string& expr, const YAML::Node& at, const std::string& path) {
  double x;
  if (plainNumber(expr, x)) {
    // strtod reads 1e-400 as 0 (and 1e400 as inf, which plainNumber refuses): a value the
    // conversion changed is reported as written, not as the 0 a later check would see.
    if (x == 0 && expr.find_first_of("123456789") < expr.find_first_of("eE"))
      fail(at, path, "'" + expr + "' is out of the range of a double (it would be read as 0); expected a number of "
                     "magnitude above 4.9e-324, or 0");
    return x;
  }
  {
    errno = 0;
    char* end = nullptr;
    const double y = std::strtod(expr.c_str(), &end);
    if (end == expr.c_str() + expr.size() && errno == ERANGE && std::isinf(y) &&
        expr.find_first_of("xXpP") == std::string::npos)
      fail(at, path, "'" + expr + "' is out of the range of a double (it would be read as infinite); expected a "
                     "number of magnitude below 1.8e308");
  }
  const std::string bad = checkExpressionText(expr);
  if (!bad.empty()) fail(at, path, "bad expression '" + expr + "': " + bad);
  try {
    parser_.SetExpr(expr);
    x = parser_.Eval();
  } catch (const mu::Parser::exception_type& e) {
    std::vector<std::string> names;
    for (const auto& [name, value] : params_) names.push_back(name);
    fail(at, path, "bad expression '" + expr + "': " + e.GetMsg() +
                       " (known names: parameters " + joinNames(names) + "; constant pi)");
  }
  if (!std::isfinite(x)) {
    // the parameters it uses, with their values and where a value came from (--set)
    std::string used;
    for (const auto& [name, value] : params_) {
      for (std::size_t k = expr.find(name); k != std::string::npos; k = expr.find(name, k + 1)) {
        const auto word = [&](std::size_t i) { return i < expr.size() && (std::isalnum(static_cast<unsigned char>(expr[i])) || expr[i] == '_'); };
        if ((k > 0 && word(k - 1)) || word(k + name.size())) continue;
        used += (used.empty() ? " with " : ", ") + name + " = " + fmt(value) + (overrides_.count(name) ? " (--set)" : "");
        break;
      }
    }
    fail(at, path, "expression '" + expr + "' evaluates to " + fmt(x) + used);
  }
  return x;
}

double YamlReader::number(const YAML::Node& n, const std::string& path) {
  if (!n.IsScalar()) fail(n, path, "expected a number or an expression, got " + describe(n));
  return evaluate(n.Scalar(), n, path);
}

double YamlReader::number(const YAML::Node& map, const std::string& path, const std::string& key, double dflt) {
  const YAML::Node n = map[key];
  return n.IsDefined() ? number(n, keyPath(path, key)) : dflt;
}

int YamlReader::integer(const YAML::Node& n, const std::string& path) {
  const double x = number(n, path);
  if (x != std::round(x) || std::abs(x) > 1e9) fail(n, path, "expected an integer, got " + fmt(x));
  return static_cast<int>(x);
}

Eigen::VectorXd YamlReader::vector(const YAML::Node& n, const std::string& path, int size) {
  if (!n.IsSequence() || static_cast<int>(n.size()) != size)
    fail(n, path, "expected a sequence of " + std::to_string(size) + " numbers, got " +
                      (n.IsSequence() ? "a sequence of " + std::to_string(n.size()) : describe(n)));
  Eigen::VectorXd v(size);
  for (int i = 0; i < size; ++i) v[i] = number(n[i], indexPath(path, i));
  return v;
}

Eigen::Vector3d YamlReader::vec3(const YAML::Node& map, const std::string& path, const std::string& key,
                                 const Eigen::Vector3d& dflt) {
  const YAML::Node n = map[key];
  return n.IsDefined() ? vec3(n, keyPath(path, key)) : dflt;
}

bool YamlReader::boolean(const YAML::Node& n, const std::string& path) const {
  if (n.IsScalar() && (n.Scalar() == "true" || n.Scalar() == "false")) return n.Scalar() == "true";
  fail(n, path, "expected true or false, got " + describe(n));
}

void YamlReader::readParameters(const YAML::Node& root) {
  const YAML::Node node = root["parameters"];
  std::vector<std::string> names;
  if (node.IsDefined()) {
    checkNameMap(node, "parameters");
    if (node.IsMap()) {
      for (auto it = node.begin(); it != node.end(); ++it) {
        const std::string name = it->first.Scalar();
        const std::string path = keyPath("parameters", name);
        if (!isIdentifier(name))
          fail(it->first, path, "a parameter name must be a letter or '_' followed by letters, digits or '_'");
        if (name == "pi") fail(it->first, path, "'pi' is a constant and cannot be a parameter");
        if (const auto d = defined_elsewhere_.find(name); d != defined_elsewhere_.end())
          fail(it->first, path, "'" + name + "' is a parameter of " + d->second +
                                    " already: give this one another name (set that one with --set " + name + "=...)");
        // The default is evaluated even when overridden, so that a broken file shows at once.
        double value = number(it->second, path);
        if (const auto o = overrides_.find(name); o != overrides_.end()) value = o->second;
        double& slot = params_[name];
        slot = value;
        try {
          parser_.DefineVar(name, &slot);
        } catch (const mu::Parser::exception_type& e) {
          fail(it->first, path, "cannot use '" + name + "' as a parameter name: " + e.GetMsg());
        }
        names.push_back(name);
      }
    }
  }
  for (const auto& [name, value] : defined_elsewhere_) names.push_back(name);  // (their overrides are theirs)
  for (const auto& [name, value] : overrides_)
    if (!params_.count(name))
      fail(keyMark(root, "parameters"), "parameters",
           "--set " + name + "=" + fmt(value) + ": the " + (file_kind_problem_ ? "problem" : "scene") +
               " has no parameter '" + name + "'" + suggestion(name, names) + "; its parameters are: " + joinNames(names));
}
void YamlReader::defineParameters(const std::map<std::string, double>& values, const std::string& origin) {
  for (const auto& [name, value] : values) {
    double& slot = params_[name];
    slot = value;
    parser_.DefineVar(name, &slot);
    defined_elsewhere_[name] = origin;
  }
  file_kind_problem_ = true;
}

std::map<std::string, double> parseOverrides(const std::vector<std::string>& assignments) {
  std::map<std::string, double> out;
  mu::Parser parser;
  setupParser(parser);
  auto trim = [](std::string s) {
    const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  };
  for (const std::string& a : assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos)
      throw ScenarioError("--set '" + a + "': expected name=value, e.g. --set height=2");
    const std::string name = trim(a.substr(0, eq)), value = trim(a.substr(eq + 1));
    if (!isIdentifier(name))
      throw ScenarioError("--set '" + a + "': '" + name + "' is not a parameter name (letters, digits, '_')");
    double x;
    if (!plainNumber(value, x)) {
      const std::string bad = checkExpressionText(value);
      if (!bad.empty()) throw ScenarioError("--set '" + a + "': bad value '" + value + "': " + bad);
      try {
        parser.SetExpr(value);
        x = parser.Eval();
      } catch (const mu::Parser::exception_type& e) {
        throw ScenarioError("--set '" + a + "': bad value '" + value + "': " + e.GetMsg() +
                            " (a number or a constant expression such as pi/4)");
      }
      if (!std::isfinite(x)) throw ScenarioError("--set '" + a + "': value evaluates to " + fmt(x));
    }
    out[name] = x;
  }
  return out;
}

}  // namespace saltus::scene
