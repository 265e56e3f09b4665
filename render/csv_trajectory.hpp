// A trajectory CSV as a TrajectorySource. Reads the file with scene::readTrajectoryCsv (finite
// numbers, distinct names, times not decreasing; located errors) and its columns by name against
// the scene:
// t, q.<coordinate> for every model coordinate (required), v.<coordinate>, and per scene contact
// contact.<name>.{rn,rt|rt1,rt2,pn,pt|pt1,pt2} (each optional: a missing one reads as zero).
// Other columns (u.*, gap, vn, vt, limit stops) are ignored.
//
// Two rows with the same t are a velocity jump (`saltus optimize`: before, then after); q(t)
// interpolates linearly between consecutive rows of distinct times.
//
// Forces and impulses depend on what the file holds:
//  - force columns (.rn present, `saltus optimize`): forces are the rn/rt columns, interpolated
//    linearly between the rows that carry a force sample (rows whose force columns are all
//    exactly 0 are points with no force variable, e.g. mesh points); impulses are the rows whose
//    pn/pt are above max(1e-6 N s, 1e-3 × the largest impulse in the file).
//  - no force columns (`saltus simulate`: pn/pt are the impulses over the step that ended at t):
//    a step whose contact changes relative velocity by more than 20 |g| Δt is an impact (no bounded
//    force near that size would do it in one step) and its pn/pt is an impulse at the row's t;
//    otherwise the step's mean force pn/Δt, pt/Δt is the force, held over the step (t − Δt, t].
#pragma once

#include <string>

#include "render/trajectory_source.hpp"
#include "scene/scene.hpp"

namespace saltus::render {

class CsvTrajectory : public TrajectorySource {
 public:
  // Throws std::runtime_error naming the file (and line, column) on a missing file, a missing
  // q column, a malformed number or decreasing times.
  CsvTrajectory(const std::string& path, const scene::Scene& scene);

  double startTime() const override { return t_.front(); }
  double endTime() const override { return t_.back(); }
  Eigen::VectorXd q(double t) const override;
  std::vector<ContactLoad> contactForces(double t) const override;
  const std::vector<Impulse>& impulses() const override { return impulses_; }

  int rows() const { return static_cast<int>(t_.size()); }
  bool hasForceColumns() const { return force_columns_; }

 private:
  std::vector<double> t_;
  std::vector<Eigen::VectorXd> q_;
  bool force_columns_ = false;
  // Per contact: force samples (time, load); with force columns linear interpolation between
  // them, else held over (previous sample time, this time].
  std::vector<std::vector<std::pair<double, ContactLoad>>> forces_;
  std::vector<Impulse> impulses_;
};

}  // namespace saltus::render
