// Writing trajectories as CSV: a header, then one row per time sample, with columns
//   t, q.<coordinate>…, v.<coordinate>…, then per contact (scene contacts, then limit stops)
//   contact.<name>.gap, .vn, .vt, .pn, .pt        (planar contacts: k ≤ 2)
//   contact.<name>.gap, .vn, .vt1, .vt2, .pn, .pt1, .pt2   (spatial contacts: k ≥ 4)
// (pn, pt: impulses over the step that ended at t). The file is written to a temporary name
// beside the target and renamed on commit(), so an interrupted run leaves nothing half-written.
#pragma once

#include "scene/atomic_file.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::timestepper {

class TrajectoryCsvWriter {
 public:
  // Opens a temporary file beside `path` (scene/atomic_file.hpp) and writes the header; throws
  // std::runtime_error naming the file when it cannot. Destroyed uncommitted, it leaves nothing.
  TrajectoryCsvWriter(const std::string& path, const Scene& scene);

  void writeRow(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                const std::vector<ContactReport>& contacts);
  // Flushes, closes and renames onto the target path.
  void commit() { file_.commit(); }

 private:
  scene::AtomicFile file_;
  std::vector<bool> spatial_;  // per contact column group: vt1/vt2 instead of vt
};

}  // namespace saltus::timestepper
