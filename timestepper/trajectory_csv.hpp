// Writing trajectories as CSV: a header, then one row per time sample, with columns
//   t, q.<coordinate>…, v.<coordinate>…, then per contact (scene contacts, then limit stops)
//   contact.<name>.gap, .vn, .vt, .pn, .pt        (planar contacts: k ≤ 2)
//   contact.<name>.gap, .vn, .vt1, .vt2, .pn, .pt1, .pt2   (spatial contacts: k ≥ 4)
// (pn, pt: impulses over the step that ended at t). The file is written to a temporary name
// beside the target and renamed on commit(), so an interrupted run leaves nothing half-written.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::timestepper {

class TrajectoryCsvWriter {
 public:
  // Opens path + ".tmp-<pid>" for writing and writes the header; throws std::runtime_error
  // naming the file when it cannot.
  TrajectoryCsvWriter(const std::string& path, const Scene& scene);
  ~TrajectoryCsvWriter();  // removes the temporary file unless committed
  TrajectoryCsvWriter(const TrajectoryCsvWriter&) = delete;
  TrajectoryCsvWriter& operator=(const TrajectoryCsvWriter&) = delete;

  void writeRow(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                const std::vector<ContactReport>& contacts);
  // Flushes, closes and renames onto the target path.
  void commit();

 private:
  std::string path_, tmp_path_;
  std::FILE* file_ = nullptr;
  std::vector<bool> spatial_;  // per contact column group: vt1/vt2 instead of vt
  bool committed_ = false;
};

}  // namespace saltus::timestepper
