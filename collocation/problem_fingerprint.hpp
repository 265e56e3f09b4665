// A problem's fingerprint, saved with its solutions (saved_solution.hpp) so that replaying or
// drawing a solution of a problem that has since changed is refused (or warned about).
//
// It covers what defines the problem: the problem file's content as yaml-cpp emits it (so not its
// comments or layout) without its solver settings (`ipopt:`, and `solve:` but for the
// complementarity tolerance, which decides feasibility); the model file's bytes when the model
// is a file of its own (a URDF); the parameter values (defaults and --set). A solution stays
// valid when only how it is solved changes.
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

#include "collocation/problem.hpp"

namespace saltus::collocation {

// 16 hexadecimal digits (FNV-1a, 64 bits: a fingerprint, not a defence against a forger) of the
// problem whose file's parsed root node is `root`: that content without its solver settings, the
// bytes of the URDF files its model was read from (Scene::model_files) and the parameters.
std::string problemFingerprint(const YAML::Node& root, const Problem& problem);

}  // namespace saltus::collocation
