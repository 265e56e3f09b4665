// A solved transcription as a render::TrajectorySource: the renderer's view of an optimisation
// output directory through the collocation polynomials (collocation/interpolation.hpp) rather
// than straight lines between the CSV rows. It lives in the library API (saltus::openSolution),
// not in render/, because render/ reads trajectories and scene geometry only and does not
// depend on collocation/.
//
//  q(t):   the state polynomial of the element that holds t (paper eq. 3), t clamped to [0, T];
//          positions are continuous at a mesh point, so either side gives the same value.
//  forces: per element, the Lagrange polynomial of degree P − 1 through the finite reactions at
//          its P collocation points (first order: the step's one value, held); limit stops are
//          not scene contacts and are left out.
//  impulses: the impulsive method's reactions at the mesh points [n, 0] (n ≥ 1) whose size is
//          above max(1e-6 N s, 1e-3 × the largest), at their mesh time (the velocity jump's
//          instant); none for the continuous and first-order methods.
#pragma once

#include <string>
#include <vector>

#include "collocation/saved_solution.hpp"
#include "collocation/solution.hpp"
#include "render/trajectory_source.hpp"

namespace saltus {

class CollocationSource : public render::TrajectorySource {
 public:
  explicit CollocationSource(collocation::SavedSolution solution);
  // loadSolution(path) (a `saltus optimize` output directory or a file in it); throws
  // collocation::SolutionError naming the file.
  static CollocationSource load(const std::string& path);

  double startTime() const override { return 0.0; }
  double endTime() const override { return trajectory_.endTime(); }
  Eigen::VectorXd q(double t) const override;
  std::vector<render::ContactLoad> contactForces(double t) const override;
  const std::vector<render::Impulse>& impulses() const override { return impulses_; }

  // The scene the solution was computed in (Problem::scene of the rebuilt problem).
  const scene::Scene& scene() const { return solution_.problem->scene; }
  // Not empty when the problem changed since the solve (collocation::SavedSolution).
  const std::string& problemChanged() const { return solution_.problem_changed; }
  const collocation::SavedSolution& solution() const { return solution_; }
  const collocation::CollocationTrajectory& trajectory() const { return trajectory_; }

 private:
  collocation::SavedSolution solution_;
  collocation::CollocationTrajectory trajectory_;
  int scene_contacts_ = 0;
  // Per element (transcription element), per collocation point, per scene contact: the load.
  std::vector<std::vector<std::vector<render::ContactLoad>>> element_forces_;
  std::vector<render::Impulse> impulses_;
};

}  // namespace saltus
