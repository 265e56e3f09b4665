// The problem-file reader (collocation/problem_file.hpp's loadProblem), shared by the two files
// that implement it: problem_file.cpp (the mesh, inputs, conditions, surface velocities and cost)
// and problem_file_solve.cpp (the `solve`, `ipopt` and `task_ipopt` sections, how the problem is
// solved). A private header: nothing outside those two files includes it.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "collocation/problem.hpp"
#include "scene/yaml_reader.hpp"

namespace saltus::collocation::detail {

using scene::YamlReader;

// Reads the problem keys of a problem file into `p`, whose scene is already read.
class ProblemReader {
 public:
  ProblemReader(YamlReader& reader, Problem& problem) : r_(reader), p_(problem) {}

  void read(const YAML::Node& root);

 private:
  void readMesh(const YAML::Node& node);
  void readInputs(const YAML::Node& node);
  void readInitialFree(const YAML::Node& node);
  std::vector<int> readCoordinateList(const YAML::Node& node, const std::string& path);
  void readConditions(const YAML::Node& map, const std::string& path, int element, int point,
                      std::vector<PointBound>& out);
  void readPointConditions(const YAML::Node& node, const std::string& path, std::vector<PointBound>& out);
  std::pair<int, int> readAt(const YAML::Node& entry, const std::string& path, const std::string& key = "at");
  void readSurfaceVelocity(const YAML::Node& node, const YAML::Node& root);
  void readCost(const YAML::Node& node);
  void readSolve(const YAML::Node& node);
  void readPenaltyKeys(const YAML::Node& node, const std::string& at, Problem::MethodSolve& into);
  void readIpopt(const YAML::Node& node, const std::string& key, std::map<std::string, std::string>& options);

  int coordinate(const YAML::Node& name_node, const std::string& path) const;
  int input(const YAML::Node& name_node, const std::string& path) const;
  int gapIndex(const YAML::Node& name_node, const std::string& path) const;
  // One side of a range: a number, null (unbounded) or ±.inf.
  double bound(const YAML::Node& n, const std::string& path, double unbounded);
  // A number (fixes the value: lower = upper) or [lower, upper].
  void readRange(const YAML::Node& n, const std::string& path, double& lower, double& upper);
  std::string origin(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    return m.is_null() || m.line < 0 ? r_.file() : r_.file() + ":" + std::to_string(m.line + 1);
  }

  YamlReader& r_;
  Problem& p_;
};

}  // namespace saltus::collocation::detail
