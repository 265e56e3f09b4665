// The trajectory CSV of Saltus: what `saltus simulate` (the time-stepper) and `saltus optimize`
// (the collocation) write, and what `saltus render` (render/csv_trajectory.hpp) and
// scripts/charts.py read by column name. A header, then one row per time sample:
//   t, q.<coordinate>…, v.<coordinate>…, u.<input coordinate>… (inputs: the optimiser's), then
//   per contact (scene contacts, then limit stops)
//   contact.<name>.gap, .vn, .vt, [.rn, .rt,] .pn, .pt
// A spatial contact (more than two friction directions) has two columns for each tangential
// quantity (.vt1 .vt2, .rt1 .rt2, .pt1 .pt2), along its surface's tangents. rn and rt are finite
// forces [N] (the optimiser's collocation points; zero where a row has none); pn and pt impulses
// [N s] (the time-stepper's over the step that ended at t, the optimiser's at a velocity jump).
// Numbers are written as %.12g. The file is written through scene::AtomicFile: it appears whole
// on commit(), or not at all.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "scene/atomic_file.hpp"
#include "scene/scene.hpp"

namespace saltus::scene {

// The columns of a trajectory file.
struct TrajectoryLayout {
  struct ContactColumns {
    std::string name;
    bool spatial = false;  // vt1/vt2 (rt1/rt2, pt1/pt2) instead of vt (rt, pt)
  };
  std::vector<std::string> coordinates;
  std::vector<std::string> inputs;  // the coordinates the inputs act on
  std::vector<ContactColumns> contacts;
  bool forces = false;  // rn and rt columns
};

// The scene's coordinates and contacts (then its limit stops), no inputs, no force columns.
TrajectoryLayout trajectoryLayout(const Scene& scene);

// One contact's values in a row (the tangential ones along the surface's tangents; the second
// of each pair is written for spatial contacts only, rn and rt only with force columns).
struct ContactRow {
  double gap = 0, vn = 0;
  Eigen::Vector2d vt = Eigen::Vector2d::Zero();
  double rn = 0;
  Eigen::Vector2d rt = Eigen::Vector2d::Zero();
  double pn = 0;
  Eigen::Vector2d pt = Eigen::Vector2d::Zero();
};

class TrajectoryCsvWriter {
 public:
  // Opens the file (scene::AtomicFile) and writes the header; throws std::runtime_error naming
  // the file. Destroyed before commit(), it leaves nothing behind.
  TrajectoryCsvWriter(const std::string& path, TrajectoryLayout layout);

  // A row: t, q, v and u (sizes as the layout's coordinates and inputs; u empty without inputs),
  // then contact() once per contact of the layout, in order, then endRow(). No allocation.
  void beginRow(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u);
  void contact(const ContactRow& c);
  void endRow();

  // Flushes, closes and renames onto the target; throws std::runtime_error naming the file.
  void commit() { file_.commit(); }

 private:
  AtomicFile file_;
  TrajectoryLayout layout_;
  std::size_t next_contact_ = 0;
};

}  // namespace saltus::scene
