// The problem fingerprint (collocation/problem_fingerprint.hpp): unchanged by comments, layout and
// solver settings; changed by anything that defines the problem (a value of the problem file, a
// parameter, the complementarity tolerance, the bytes of a URDF model file).
#include "collocation/problem_fingerprint.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "collocation/problem_file.hpp"
#include "saltus/build_paths.hpp"
#include "tests/support/files.hpp"

namespace saltus::collocation {
namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;

// `text` with its first `from` replaced by `to` (which must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

class Fingerprint : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("saltus_fingerprint_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "problems");
    fs::create_directories(dir_ / "biped");
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The fingerprint of `text` written as a problem file (in problems/, next to biped/).
  std::string of(const std::string& text, const std::map<std::string, double>& overrides = {}) {
    const fs::path path = dir_ / "problems" / "p.yaml";
    std::ofstream(path) << text;
    return loadProblem(path.string(), overrides).fingerprint;
  }
  fs::path dir_;
};

TEST_F(Fingerprint, CommentsLayoutAndSolverSettingsDoNotChangeIt) {
  const std::string drop = readFile(fs::path(SALTUS_SOURCE_DIR) / "models/problems/point_mass_drop.yaml");
  const std::string base = of(drop);
  EXPECT_EQ(base.size(), 16u);
  EXPECT_EQ(of(drop), base);  // deterministic
  EXPECT_EQ(of(drop + "# a comment\n\n"), base);
  EXPECT_EQ(of(replaced(drop, "tol: 1e-8", "tol: 1e-7")), base);
  EXPECT_EQ(of(drop + "solve: {seed: perturbed, seed_scale: 0.2, restarts: 3}\n"), base);
  EXPECT_EQ(of(drop + "task_ipopt: {obj_scaling_factor: 10}\n"), base);
  EXPECT_EQ(of(replaced(drop, "mass: 1.0", "mass:    1.0   # kg")), base);
}

TEST_F(Fingerprint, WhatDefinesTheProblemChangesIt) {
  const std::string drop = readFile(fs::path(SALTUS_SOURCE_DIR) / "models/problems/point_mass_drop.yaml");
  const std::string base = of(drop);
  EXPECT_NE(of(replaced(drop, "mass: 1.0", "mass: 2.0")), base);
  EXPECT_NE(of(replaced(drop, "N: 20", "N: 21")), base);
  EXPECT_NE(of(drop, {{"restitution", 0.5}}), base);
  EXPECT_NE(of(drop + "solve: {complementarity_tolerance: 1e-5}\n"), base);
}

TEST_F(Fingerprint, AUrdfModelFileIsPartOfIt) {
  const std::string biped = readFile(fs::path(SALTUS_SOURCE_DIR) / "models/problems/biped_stop.yaml");
  const std::string urdf = readFile(fs::path(SALTUS_SOURCE_DIR) / "models/biped/biped.urdf");
  std::ofstream(dir_ / "biped" / "biped.urdf") << urdf;
  const std::string base = of(biped);
  std::ofstream(dir_ / "biped" / "biped.urdf") << urdf << "<!-- edited -->\n";
  EXPECT_NE(of(biped), base);
}

// A model of parts hashes every URDF it reads: the drop with a (fixed) biped beside the ball.
TEST_F(Fingerprint, EveryUrdfOfAModelOfPartsIsPartOfIt) {
  const std::string drop = readFile(fs::path(SALTUS_SOURCE_DIR) / "models/problems/point_mass_drop.yaml");
  const std::string parts =
      replaced(replaced(drop, "    visuals:\n      - {shape: sphere, size: 0.01, xyz: [0, 0, 0.01], rgba: [0.8, 0.2, 0.2, 1]}\n", ""),
               "model:\n  point_mass:\n    mass: 1.0\n    link: ball\n    axes: {z: [0, 0, 1]}\n",
               "model:\n  parts:\n    - point_mass: {mass: 1.0, link: ball, axes: {z: [0, 0, 1]}}\n"
               "    - {name: robot, urdf: ../biped/biped.urdf}\n");
  const std::string urdf = readFile(fs::path(SALTUS_SOURCE_DIR) / "models/biped/biped.urdf");
  std::ofstream(dir_ / "biped" / "biped.urdf") << urdf;
  const std::string base = of(parts);
  EXPECT_NE(base, of(drop));
  std::ofstream(dir_ / "biped" / "biped.urdf") << urdf << "<!-- edited -->\n";
  EXPECT_NE(of(parts), base);
}

}  // namespace
}  // namespace saltus::collocation
