#include "render/csv_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>

#include "contact/kinematics.hpp"
#include "dynamics/kinematics.hpp"
#include "scene/trajectory_csv.hpp"

namespace saltus::render {

namespace {

// Column indices of one contact's loads (−1: absent).
struct LoadColumns {
  int n = -1, t1 = -1, t2 = -1;
  bool any() const { return n >= 0 || t1 >= 0 || t2 >= 0; }
  ContactLoad read(std::span<const double> row) const {
    ContactLoad l;
    if (n >= 0) l.normal = row[n];
    if (t1 >= 0) l.tangent[0] = row[t1];
    if (t2 >= 0) l.tangent[1] = row[t2];
    return l;
  }
};

}  // namespace

CsvTrajectory::CsvTrajectory(const std::string& path, const scene::Scene& scene) {
  const scene::TrajectoryTable table = scene::readTrajectoryCsv(path);
  auto find = [&](const std::string& name) { return table.column(name); };
  const dynamics::Model<double>& model = scene.model;
  const int nq = model.nq(), nv = model.nv();
  std::vector<int> q_col(nq), v_col(nv);
  for (int k = 0; k < nq; ++k) {
    q_col[k] = find("q." + model.position_name[k]);
    if (q_col[k] < 0)
      throw std::runtime_error(path + ":1: no column 'q." + model.position_name[k] + "' for coordinate '" +
                               model.position_name[k] + "' of model '" + model.name +
                               "' (is this trajectory from another scene?)");
  }
  bool have_v = true;
  for (int k = 0; k < nv; ++k) {
    v_col[k] = find("v." + model.coordinate_name[k]);
    have_v = have_v && v_col[k] >= 0;
  }
  const int nc = static_cast<int>(scene.contacts.size());
  std::vector<LoadColumns> r_cols(nc), p_cols(nc);
  for (int c = 0; c < nc; ++c) {
    const std::string p = "contact." + scene.contacts[c].name + ".";
    r_cols[c] = {find(p + "rn"), find(p + "rt") >= 0 ? find(p + "rt") : find(p + "rt1"), find(p + "rt2")};
    p_cols[c] = {find(p + "pn"), find(p + "pt") >= 0 ? find(p + "pt") : find(p + "pt1"), find(p + "pt2")};
    force_columns_ = force_columns_ || r_cols[c].any();
  }

  // Rows.
  if (table.rows() == 0) throw std::runtime_error(path + ": no data rows after the header");
  if (table.at(table.rows() - 1, 0) == table.at(0, 0))
    throw std::runtime_error(path + ": every row is at t = " + std::to_string(table.at(0, 0)) +
                             " s; a trajectory to draw spans some time");
  std::vector<std::span<const double>> rows;
  for (std::size_t i = 0; i < table.rows(); ++i) rows.push_back(table.row(i));
  for (const auto& row : rows) {
    t_.push_back(row[0]);
    Eigen::VectorXd q(nq);
    for (int k = 0; k < nq; ++k) q[k] = row[q_col[k]];
    if (model.base == dynamics::BaseType::FreeQuaternion) {
      const double n = q.segment<4>(3).norm();
      if (!(std::abs(n - 1.0) <= 1e-6))
        throw std::runtime_error(path + ": at t = " + std::to_string(row[0]) +
                                 " s the base quaternion (base_qw, base_qx, base_qy, base_qz) has length " +
                                 std::to_string(n) + ", not 1");
      q.segment<4>(3) /= n;
    }
    q_.push_back(q);
  }

  forces_.assign(nc, {});
  if (force_columns_) {
    double largest = 0;
    for (const auto& row : rows)
      for (int c = 0; c < nc; ++c) largest = std::max(largest, p_cols[c].read(row).magnitude());
    const double threshold = std::max(1e-6, 1e-3 * largest);
    for (const auto& row : rows)
      for (int c = 0; c < nc; ++c) {
        const ContactLoad r = r_cols[c].read(row);
        if (r.normal != 0 || r.tangent[0] != 0 || r.tangent[1] != 0) forces_[c].emplace_back(row[0], r);
        const ContactLoad p = p_cols[c].read(row);
        if (p.magnitude() > threshold) impulses_.push_back({row[0], c, p});
      }
  } else {
    // Time-stepper rows: classify each step's impulse as an impact or a mean force (see header).
    dynamics::Data<double> data(model);
    const std::vector<contact::ContactPair> pairs = contact::contactPairs(scene);  // contacts first
    std::vector<std::vector<Eigen::Vector3d>> v_point(rows.size(), std::vector<Eigen::Vector3d>(nc, Eigen::Vector3d::Zero()));
    if (have_v) {
      Eigen::VectorXd v(nv);
      for (std::size_t i = 0; i < rows.size(); ++i) {
        for (int k = 0; k < nv; ++k) v[k] = rows[i][v_col[k]];
        dynamics::forwardKinematics(model, data, q_[i], v);
        for (int c = 0; c < nc; ++c) v_point[i][c] = contact::relativeVelocity(pairs[c], data);
      }
    }
    const double g = model.gravity.norm();
    for (int c = 0; c < nc; ++c) forces_[c].emplace_back(t_.front(), ContactLoad{});
    for (std::size_t i = 1; i < rows.size(); ++i) {
      const double dt = t_[i] - t_[i - 1];
      for (int c = 0; c < nc; ++c) {
        const ContactLoad p = p_cols[c].read(rows[i]);
        ContactLoad f;
        if (p.magnitude() > 0 && dt > 0) {
          const double dv = (v_point[i][c] - v_point[i - 1][c]).norm();
          if (dv > 20 * g * dt) {
            impulses_.push_back({t_[i], c, p});
          } else {
            f.normal = p.normal / dt;
            f.tangent = p.tangent / dt;
          }
        }
        forces_[c].emplace_back(t_[i], f);
      }
    }
  }
  std::stable_sort(impulses_.begin(), impulses_.end(), [](const Impulse& a, const Impulse& b) { return a.t < b.t; });
}

Eigen::VectorXd CsvTrajectory::q(double t) const {
  if (t <= t_.front()) return q_.front();
  if (t >= t_.back()) return q_.back();
  // first row with time > t; the row before it has time ≤ t (at a jump: the "after" row)
  const std::size_t hi = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
  const std::size_t lo = hi - 1;
  const double h = t_[hi] - t_[lo];  // > 0: t_[lo] ≤ t < t_[hi]
  const double s = (t - t_[lo]) / h;
  // A base quaternion interpolated so is normalised by the kinematics (nlerp: between samples a
  // step apart, within rounding of the rotation's slerp for the renderer's purpose).
  return (1 - s) * q_[lo] + s * q_[hi];
}

std::vector<ContactLoad> CsvTrajectory::contactForces(double t) const {
  std::vector<ContactLoad> out(forces_.size());
  for (std::size_t c = 0; c < forces_.size(); ++c) {
    const auto& samples = forces_[c];
    if (samples.empty()) continue;
    // first sample with time ≥ t
    const auto it = std::lower_bound(samples.begin(), samples.end(), t,
                                     [](const auto& s, double x) { return s.first < x; });
    if (!force_columns_) {
      // held over (previous time, this time]
      if (it != samples.end()) out[c] = it->second;
      continue;
    }
    if (it == samples.end()) {
      out[c] = samples.back().second;
    } else if (it == samples.begin() || it->first == t) {
      out[c] = it->second;
    } else {
      const auto& a = *(it - 1);
      const auto& b = *it;
      const double s = b.first > a.first ? (t - a.first) / (b.first - a.first) : 1.0;
      out[c].normal = (1 - s) * a.second.normal + s * b.second.normal;
      out[c].tangent = (1 - s) * a.second.tangent + s * b.second.tangent;
    }
  }
  return out;
}

}  // namespace saltus::render
