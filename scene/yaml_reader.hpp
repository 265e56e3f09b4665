// Reading YAML input files (scenario files, problem files) with located errors: every value is
// type-checked before use, numbers may be muparser expressions over the file's named
// `parameters` (overridable with `--set name=value`), and every error is a ScenarioError whose
// message starts with file:line:column and the key path, e.g.
//   models/scenes/x.yaml:14:15: contacts[1].surface: unknown surface 'blet'; surfaces: ground, belt
#pragma once

#include <cstdint>
#include <muParser.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace saltus::scene {

class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Message helpers shared by the readers.
std::string joinNames(const std::vector<std::string>& names);  // "a, b, c" or "(none)"
std::string keyPath(const std::string& path, const std::string& key);  // "a.b"
std::string indexPath(const std::string& path, std::size_t i);         // "a[3]"
std::string describe(const YAML::Node& n);                             // "a map", "the scalar 'x'"
std::string location(const std::string& file, const YAML::Mark& m);   // "file:line:column"
std::string fmt(double x);
std::string fmt(const Eigen::Vector3d& v);
bool isIdentifier(const std::string& s);
// " (did you mean 'x'?)" when one candidate is close to `word`, else "".
std::string suggestion(const std::string& word, const std::vector<std::string>& candidates);

// Parses the file; a missing file or a YAML syntax error is a ScenarioError naming the file
// (and the line of the syntax error).
constexpr std::uintmax_t kMaxYamlBytes = 16u << 20;  // 16 MiB: a scenario or problem file is a few KB
YAML::Node loadYamlFile(const std::string& path, const std::string& what = "scenario file");

// Built-in files: a name stands for <directory>/<name>.yaml; anything containing '/' or ending in
// .yaml/.yml is a path. `kind` names them in messages ("scene", "problem"), `file_kind` names a
// file ("scenario file"). An unknown name is a ScenarioError listing the built-ins.
struct YamlSource {
  std::string path;
  std::string source;  // "builtin:<name>", or the path as given
};
std::vector<std::string> yamlFileNames(const std::string& directory);  // stems of the .yaml files, sorted
YamlSource resolveYamlFile(const std::string& name_or_path, const std::string& directory, const std::string& kind,
                           const std::string& file_kind);

// Parses `--set` assignments "name=value"; value is a number or a constant expression (pi/4).
// A later assignment to the same name wins. Throws ScenarioError naming the bad item.
std::map<std::string, double> parseOverrides(const std::vector<std::string>& assignments);

class YamlReader {
 public:
  YamlReader(std::string file, std::map<std::string, double> overrides);
  YamlReader(const YamlReader&) = delete;  // muparser holds pointers into params_
  YamlReader& operator=(const YamlReader&) = delete;

  const std::string& file() const { return file_; }
  // The parameter values in use (defaults replaced by overrides), after readParameters.
  const std::map<std::string, double>& parameters() const { return params_; }

  // Reads root["parameters"] (a map name: default); an override naming no parameter is an error
  // that lists the file's parameters.
  void readParameters(const YAML::Node& root);
  // Before readParameters: parameters read from another file (a problem's scene file), with their
  // values in use, for this file's expressions; `origin` names that file. A parameter of this file
  // with one of their names is an error (it would shadow the other file's).
  void defineParameters(const std::map<std::string, double>& values, const std::string& origin);

  [[noreturn]] void fail(const YAML::Mark& m, const std::string& path, const std::string& what) const;
  [[noreturn]] void fail(const YAML::Node& at, const std::string& path, const std::string& what) const {
    fail(at.Mark(), path, what);
  }

  // A map (an empty value counts as an empty map when `allow_null`) whose keys are all in
  // `allowed` (any keys when empty) and each given once.
  void checkMap(const YAML::Node& n, const std::string& path, const std::vector<std::string>& allowed,
                bool allow_null = false) const;
  void checkNameMap(const YAML::Node& n, const std::string& path) const { checkMap(n, path, {}, true); }
  void checkSequence(const YAML::Node& n, const std::string& path) const;
  // Position of `key` itself in a map (the key, not its value).
  static YAML::Mark keyMark(const YAML::Node& map, const std::string& key);
  YAML::Node required(const YAML::Node& map, const std::string& path, const std::string& key) const;

  std::string text(const YAML::Node& n, const std::string& path) const;
  double evaluate(const std::string& expr, const YAML::Node& at, const std::string& path);
  double number(const YAML::Node& n, const std::string& path);
  double number(const YAML::Node& map, const std::string& path, const std::string& key, double dflt);
  int integer(const YAML::Node& n, const std::string& path);
  Eigen::VectorXd vector(const YAML::Node& n, const std::string& path, int size);
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& path) { return vector(n, path, 3); }
  Eigen::Vector3d vec3(const YAML::Node& map, const std::string& path, const std::string& key,
                       const Eigen::Vector3d& dflt);
  bool boolean(const YAML::Node& n, const std::string& path) const;

 private:
  std::string file_;
  std::map<std::string, double> overrides_;
  std::map<std::string, double> params_;  // node-stable storage: muparser holds pointers into it
  std::map<std::string, std::string> defined_elsewhere_;  // defineParameters: name -> its file
  bool file_kind_problem_ = false;  // a problem file over a scene's (defineParameters called): for messages
  mu::Parser parser_;
};

}  // namespace saltus::scene
