#include "collocation/input_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scene/trajectory_csv.hpp"
#include "scene/yaml_reader.hpp"  // fmt

namespace saltus::collocation {

const Eigen::VectorXd& InputSchedule::at(double t) const {
  const auto it = std::upper_bound(times.begin(), times.end(), t);
  return values[it == times.begin() ? 0 : static_cast<std::size_t>(it - times.begin()) - 1];
}

void Tracking::reference(double t, Eigen::VectorXd& q_out, Eigen::VectorXd& v_out) const {
  const auto it = std::upper_bound(times.begin(), times.end(), t);  // the first sample after t
  if (it == times.begin() || it == times.end()) {
    const std::size_t i = it == times.begin() ? 0 : times.size() - 1;
    q_out = q[i];
    v_out = v[i];
    return;
  }
  const auto i = static_cast<std::size_t>(it - times.begin());  // times[i - 1] <= t < times[i]
  const double w = (t - times[i - 1]) / (times[i] - times[i - 1]);
  q_out = (1 - w) * q[i - 1] + w * q[i];
  v_out = (1 - w) * v[i - 1] + w * v[i];
}

InputSchedule readInputSchedule(const std::string& path, const Problem& p) {
  const int nu = static_cast<int>(p.inputs.size());
  if (nu == 0)
    throw InputScheduleError(path + ": an input schedule drives a problem's inputs, and problem '" + p.name +
                             "' has none");
  scene::TrajectoryTable table;
  try {
    table = scene::readTrajectoryCsv(path);
  } catch (const std::runtime_error& e) {
    throw InputScheduleError(e.what());
  }
  const auto& names = p.scene.model.coordinate_name;
  std::vector<int> column(nu);
  std::string expected;
  for (int i = 0; i < nu; ++i) expected += (i ? ", u." : "u.") + names[p.inputs[i]];
  for (int i = 0; i < nu; ++i) {
    column[i] = table.column("u." + names[p.inputs[i]]);
    if (column[i] < 0)
      throw InputScheduleError(path + ":1: no column 'u." + names[p.inputs[i]] + "'; a schedule for '" + p.name +
                               "' has a column per input: " + expected);
  }
  for (const std::string& name : table.names())
    if (name.rfind("u.", 0) == 0 && std::find(column.begin(), column.end(), table.column(name)) == column.end())
      throw InputScheduleError(path + ":1: column '" + name + "' is not an input of '" + p.name + "'; expected " +
                               expected);
  if (table.rows() < 2)
    throw InputScheduleError(path + ": " + std::to_string(table.rows()) +
                             " rows; a schedule needs at least two (its first at t = 0, its last at the horizon)");
  InputSchedule s;
  s.path = path;
  for (std::size_t r = 0; r < table.rows(); ++r) {
    const double t = table.at(r, 0);
    const std::string row = path + ": row " + std::to_string(r + 1) + " (t = " + scene::fmt(t) + "): ";
    if (r == 0 && t != 0) throw InputScheduleError(row + "the first row must be at t = 0");
    if (r > 0 && !(t > s.times.back()))
      throw InputScheduleError(row + "times must increase strictly (the previous row's is " + scene::fmt(s.times.back()) + ")");
    Eigen::VectorXd u(nu);
    for (int i = 0; i < nu; ++i) {
      u[i] = table.at(r, column[i]);
      // within the bounds (to the last digits a %.12g file keeps)
      const double slack = 1e-10 * std::max({1.0, std::abs(p.input_lower[i]), std::abs(p.input_upper[i])});
      if (u[i] < p.input_lower[i] - slack || u[i] > p.input_upper[i] + slack)
        throw InputScheduleError(row + "column 'u." + names[p.inputs[i]] + "': " + scene::fmt(u[i]) +
                                 " is outside the input's bounds [" + scene::fmt(p.input_lower[i]) + ", " +
                                 scene::fmt(p.input_upper[i]) + "]");
    }
    s.times.push_back(t);
    s.values.push_back(std::move(u));
  }
  return s;
}

}  // namespace saltus::collocation
