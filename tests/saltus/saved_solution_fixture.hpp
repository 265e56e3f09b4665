// The fixture of the saved solutions' tests (saved_solutions_test.cpp, legged_solution_test.cpp,
// ollie_solution_test.cpp): a benchmark's saved solution (tests/data/solutions/<name>, each
// folder's README says how it was made), refused when its problem has changed since; and a side
// view of it drawn offscreen; the centre of mass's velocity.
#pragma once

#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "collocation/saved_solution.hpp"
#include "dynamics/energy.hpp"
#include "render/animation.hpp"
#include "render/renderer.hpp"
#include "saltus/build_paths.hpp"
#include "saltus/saltus.hpp"

namespace saltus::saved_solutions {

inline std::string solutionDir(const std::string& name) {
  return (std::filesystem::path(SALTUS_SOURCE_DIR) / "tests/data/solutions" / name).string();
}

class SavedSolutionTest : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    solution_ = std::make_unique<collocation::SavedSolution>(collocation::loadSolution(solutionDir(GetParam())));
    // A solution of another problem proves nothing: refresh the data (its README) when this fails.
    ASSERT_TRUE(solution_->problem_changed.empty()) << solution_->problem_changed;
  }
  const collocation::Problem& problem() const { return *solution_->problem; }
  const collocation::Transcription& transcription() const { return *solution_->transcription; }
  std::unique_ptr<collocation::SavedSolution> solution_;
};

// Tolerances: the solver's constraint violation tolerance (1e-5) and the complementarity
// tolerance's scale; a reaction's cone and a bound are checked relative to their size.
inline constexpr double kTol = 1e-5;

// The centre of mass's velocity: its derivative along q̇ (= v: both bases are joints, planar or
// Euler angles), by central differences.
inline Eigen::Vector3d comVelocity(const dynamics::Model<double>& model, dynamics::Data<double>& data, const Eigen::VectorXd& q,
                                   const Eigen::VectorXd& v) {
  const double eps = 1e-6;
  dynamics::forwardKinematics(model, data, Eigen::VectorXd(q + eps * v));
  const Eigen::Vector3d plus = dynamics::centerOfMass(model, data);
  dynamics::forwardKinematics(model, data, Eigen::VectorXd(q - eps * v));
  return (plus - dynamics::centerOfMass(model, data)) / (2 * eps);
}

// A saved solution drawn from the side, the bodies alone (no surfaces, no shadows).
struct SideView {
  SideView(const std::string& dir, int width, int height, double fps)
      : input(saltus::openSolution(dir)),
        options(optionsOf(width, height, fps)),
        animation(input.scene, *input.trajectory, options, warnings),
        settings(bodiesOnly(animation.settings())),
        renderer(animation.geometry(), settings) {}
  static render::AnimationOptions optionsOf(int width, int height, double fps) {
    render::AnimationOptions o;
    o.width = width;
    o.height = height;
    o.fps = fps;
    o.camera = render::CameraMode::Side;
    return o;
  }
  static render::RenderSettings bodiesOnly(render::RenderSettings s) {
    s.surfaces = false;
    s.shadows = false;
    return s;
  }
  saltus::RenderInput input;
  render::AnimationOptions options;
  std::ostringstream warnings;
  render::Animation animation;
  render::RenderSettings settings;
  render::Renderer renderer;
};

// The image column of a world point (look-at camera, focal length (H/2)/tan(fov/2)).
inline double projectedColumn(const render::Camera& c, const Eigen::Vector3d& p, int width, int height) {
  const Eigen::Vector3d f = (c.target - c.eye).normalized(), r = f.cross(c.up).normalized();
  const Eigen::Vector3d d = p - c.eye;
  return width / 2.0 + (height / 2.0) / std::tan(c.fov_y / 2) * d.dot(r) / d.dot(f);
}

// The image row of a world point (look-at camera, as projectedColumn).
inline double projectedRow(const render::Camera& c, const Eigen::Vector3d& p, int height) {
  const Eigen::Vector3d f = (c.target - c.eye).normalized(), r = f.cross(c.up).normalized(), up = r.cross(f);
  const Eigen::Vector3d d = p - c.eye;
  return height / 2.0 - (height / 2.0) / std::tan(c.fov_y / 2) * d.dot(up) / d.dot(f);
}

}  // namespace saltus::saved_solutions
