// The `model:` section of a scenario or problem file (models/scenes/README.md): a URDF file, one
// rigid body, point masses on their own axes, or parts, several of these each joined to the
// world by a base of its own (a skateboard and its rider, both planar).
//
// Parts make one fixed-base tree: a part's planar base (x, z, θ about y) or Euler base (x, y, z,
// yaw, pitch, roll) becomes a chain of one-coordinate joints from the world through massless
// links, coordinates <part>_x, <part>_z, <part>_theta (planar) or <part>_x ... <part>_roll (free),
// the same coordinates and the same mass matrix as the multi-coordinate base joint of a model of
// one part (dynamics/model.hpp, BaseType); a part's own links and joints keep their names, which
// must differ from every other part's.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dynamics/model.hpp"
#include "scene/yaml_reader.hpp"

namespace saltus::scene {

// A model and the URDF files it was read from (the problem fingerprint hashes their bytes).
struct ModelSection {
  dynamics::Model<double> model;
  std::vector<std::string> urdf_files;
};

// Reads `node` (the value of `model:`); `base` is the file's `base:` (`base_node` its node, maybe
// undefined), which parts do not take: each part has its own. Errors are ScenarioErrors located
// in the file.
ModelSection readModelSection(YamlReader& reader, const YAML::Node& node, dynamics::BaseType base,
                              const Eigen::Vector3d& gravity, const YAML::Node& base_node);

}  // namespace saltus::scene
