#include "collocation/problem_fingerprint.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace saltus::collocation {

namespace {

void fnv1a(std::uint64_t& h, const std::string& bytes) {
  for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ull;
}

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::string problemFingerprint(const YAML::Node& root, const Problem& problem) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  YAML::Node content = YAML::Clone(root);
  content.remove("ipopt");
  content.remove("task_ipopt");
  content.remove("solve");
  YAML::Emitter emitted;
  emitted << content;
  fnv1a(h, emitted.c_str());
  char tolerance[64];
  std::snprintf(tolerance, sizeof tolerance, "complementarity_tolerance=%.17g;", problem.complementarity_tolerance);
  fnv1a(h, tolerance);
  // The scenario file of `scene:` and the URDF files the model was read from (a model written in
  // the problem file is in its text).
  std::error_code error;
  if (!problem.scene_file.empty()) fnv1a(h, fileBytes(problem.scene_file));  // a scene of its own file
  for (const std::string& urdf : problem.scene.model_files)
    if (std::filesystem::is_regular_file(urdf, error)) fnv1a(h, fileBytes(urdf));
  for (const auto& [name, value] : problem.parameters) {
    char text[64];
    std::snprintf(text, sizeof text, "=%.17g;", value);
    fnv1a(h, name + text);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace saltus::collocation
