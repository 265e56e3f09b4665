// The trajectory CSV of Saltus: what `saltus simulate` (the time-stepper) and `saltus optimize`
// (the collocation) write, and what `saltus render` (render/csv_trajectory.hpp) and
// scripts/charts.py read by column name. A header, then one row per time sample:
//   t, q.<position coordinate>…, v.<coordinate>…, u.<input coordinate>… (inputs: the optimiser's),
//   then
//   per contact (scene contacts, then limit stops)
//   contact.<name>.gap, .vn, .vt, [.rn, .rt,] .pn, .pt[, .s]
// A spatial contact (more than two friction directions) has two columns for each tangential
// quantity (.vt1 .vt2, .rt1 .rt2, .pt1 .pt2), along its surface's tangents. rn and rt are finite
// forces [N] (the optimiser's collocation points; zero where a row has none); pn and pt impulses
// [N s] (the time-stepper's over the step that ended at t, the optimiser's at a velocity jump).
// A contact on a plane fixed in a body (a foot on a deck) has the contact point's coordinates in
// that plane, s [m] along its tangent t1 (.s), or along t1 and t2 (.s1 .s2) when the optimiser's
// point is free along both or the contact is spatial: the optimiser's variable for a free point
// at a point with a reaction (where the reaction acts), otherwise the point's projection onto the
// plane (what the extent bounds).
// Numbers are written as %.12g. The file is written through scene::AtomicFile: it appears whole
// on commit(), or not at all. readTrajectoryCsv reads any such file back, by column name.
#pragma once

#include <span>
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
    int plane_axes = 0;    // 0: not on a body's plane; 1: the .s column; 2: .s1 and .s2
  };
  std::vector<std::string> coordinates;  // velocity coordinates: the v. columns
  std::vector<std::string> positions;    // the q. columns (model.position_name); empty: as coordinates
  std::vector<std::string> inputs;  // the coordinates the inputs act on
  std::vector<ContactColumns> contacts;
  bool forces = false;  // rn and rt columns
};

// The scene's coordinates and contacts (then its limit stops), no inputs, no force columns. A
// contact on a body's plane has plane_axes: its free axes' count when its point is free, else 2
// when spatial, else 1.
TrajectoryLayout trajectoryLayout(const Scene& scene);

// The header's column names, in order.
std::vector<std::string> trajectoryHeader(const TrajectoryLayout& layout);

// One contact's values in a row (the tangential ones along the surface's tangents; the second
// of each pair is written for spatial contacts only, rn and rt only with force columns, s on a
// body's plane only).
struct ContactRow {
  double gap = 0, vn = 0;
  Eigen::Vector2d vt = Eigen::Vector2d::Zero();
  double rn = 0;
  Eigen::Vector2d rt = Eigen::Vector2d::Zero();
  double pn = 0;
  Eigen::Vector2d pt = Eigen::Vector2d::Zero();
  Eigen::Vector2d s = Eigen::Vector2d::Zero();  // plane coordinates on a body's plane [m]
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

// A trajectory file read back: its columns by name, every cell a finite number.
class TrajectoryTable {
 public:
  const std::string& path() const { return path_; }
  const std::vector<std::string>& names() const { return names_; }
  std::size_t rows() const { return names_.empty() ? 0 : cells_.size() / names_.size(); }
  // The index of a column, −1 when the file has none of that name.
  int column(const std::string& name) const;
  bool has(const std::string& name) const { return column(name) >= 0; }
  // A column's values; throws std::out_of_range naming the file and the column when absent.
  std::vector<double> values(const std::string& name) const;
  double at(std::size_t row, int column) const { return cells_[row * names_.size() + static_cast<std::size_t>(column)]; }
  std::span<const double> row(std::size_t i) const { return {cells_.data() + i * names_.size(), names_.size()}; }

 private:
  friend TrajectoryTable readTrajectoryCsv(const std::string& path);
  std::string path_;
  std::vector<std::string> names_;
  std::vector<double> cells_;  // row-major
};

// The largest time a trajectory file may hold [s] (some 30 years); coordinates are bounded by
// kMaxPosition (scene/scenario.hpp).
constexpr double kMaxTrajectoryTime = 1e9;

// Reads a trajectory file: a header whose first column is t and whose names are distinct, then
// rows of as many finite numbers (times and coordinates within their bounds), times not
// decreasing (two rows with one t are a velocity jump);
// blank lines are skipped. Throws std::runtime_error naming the file, the line and the column:
// "traj.csv:7: column 'q.z': expected a finite number, got 'nan'".
TrajectoryTable readTrajectoryCsv(const std::string& path);

}  // namespace saltus::scene
