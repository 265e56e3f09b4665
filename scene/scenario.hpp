// Scenario files: a Scene (scene.hpp) written in YAML, with named parameters that any number in
// the file may use in an expression (muparser), and overrides from the command line
// (`--set name=value`). The format is documented in models/scenes/README.md; the built-in scenes
// are models/scenes/<name>.yaml.
//
// Every error is a ScenarioError whose message starts with the file and the position of the
// offending node, then the key path and what was expected, e.g.
//   models/scenes/x.yaml:14:15: contacts[1].surface: unknown surface 'blet'; surfaces: ground, belt
// Errors of a URDF model keep the URDF reader's message (which names the URDF file), prefixed by
// the position of the `urdf:` key in the scenario file.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "scene/yaml_reader.hpp"

namespace saltus::scene {

// Plausibility limits of a scenario's numbers, far beyond any robot and short of where products
// of them overflow or swamp the solvers' tolerances: |gravity| [m/s²], each initial coordinate
// [m or rad], each initial velocity [m/s or rad/s] and input [N or N m].
constexpr double kMaxGravity = 1e3;
constexpr double kMaxPosition = 1e6;
constexpr double kMaxRate = 1e5;
constexpr int kMaxDirections = 64;  // friction directions of a contact

// Loads a scenario by built-in name (models/scenes/<name>.yaml in the directory
// scenesDirectory() returns) or by file path (anything containing '/' or ending in .yaml/.yml,
// or an existing file). `overrides` replace parameter defaults; one naming no parameter of the
// scene is an error that lists the scene's parameters.
// Scene::source is "builtin:<name>" for a built-in scene, else the path as given.
Scene loadScene(const std::string& name_or_path, const std::map<std::string, double>& overrides = {});

// Reads the scene keys of `root` with `reader` (whose parameters are already read), for files
// that hold a scene among other keys (problem files): `extra_keys` are the other allowed keys.
Scene readScene(YamlReader& reader, const YAML::Node& root, const std::vector<std::string>& extra_keys = {});

// Names of the built-in scenes, sorted.
std::vector<std::string> builtinSceneNames();

// The folder holding the bundled models/ and scripts/: the source tree Saltus was built from
// while it has them, else the installed copy (<prefix>/share/saltus, `cmake --install`).
std::string dataDirectory();

// Where built-in scenes are looked up: $SALTUS_SCENES_DIR when set and non-empty, else
// dataDirectory()/models/scenes.
std::string scenesDirectory();

}  // namespace saltus::scene
