// Problem files: a Problem (problem.hpp) written in YAML. A problem file holds the keys of a
// scenario file (the scene: model, surfaces, contacts, joint-limit stops, the initial state and
// the named parameters, read by scene::readScene) plus the mesh, the conditions, the cost and
// the solve options. The format is documented in models/problems/README.md; the built-in
// problems are models/problems/<name>.yaml.
//
// Files number elements from 1 as the paper does (`at: [6, 0]` is element 5, point 0 in
// Problem). Every error is a scene::ScenarioError whose message starts with the file and the
// position of the offending node, then the key path and what was expected, e.g.
//   models/problems/x.yaml:31:12: constraints[0].at: element 21 is outside 1 … 20 (mesh.N)
#pragma once

#include <map>
#include <string>
#include <vector>

#include "collocation/problem.hpp"

namespace saltus::collocation {

// Loads a problem by built-in name (problemsDirectory()/<name>.yaml) or by file path (anything
// containing '/' or ending in .yaml/.yml). `overrides` replace parameter defaults (--set); one
// naming no parameter of the file is an error that lists the file's parameters.
// Problem::source is "builtin:<name>" for a built-in problem, else the path as given; so is
// scene.source, except for a scene of its own file (`scene:`), where it is that scenario file's
// ("builtin:<scene>" or its path) and Problem::scene_file its path.
Problem loadProblem(const std::string& name_or_path, const std::map<std::string, double>& overrides = {});

// Names of the built-in problems, sorted.
std::vector<std::string> builtinProblemNames();

// Where built-in problems are looked up: $SALTUS_PROBLEMS_DIR when set and non-empty, else
// scene::dataDirectory()/models/problems.
std::string problemsDirectory();

}  // namespace saltus::collocation
