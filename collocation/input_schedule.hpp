// An open-loop input schedule for the simulation seed (simulation_seed.hpp): the problem's inputs
// as a function of time, held from each row's time to the next (a zero-order hold, as a
// time-stepper applies an input over its step). A scripted motion (a stamp, a jump) or one found
// by a search in the time-stepper then seeds the optimiser with its own contact sequence: the
// seed is the time-stepper's motion under these inputs, physically consistent from the start.
//
// The file is a trajectory CSV (scene/trajectory_csv.hpp): the column t, then u.<coordinate> for
// every input of the problem (its actuated coordinates' names); other q., v. and contact. columns
// are ignored, so an optimised trajectory.csv can serve as well. The first row is at t = 0, times
// increase strictly, and the last row's time is the schedule's horizon: the seed's total time
// (its elements share it equally before they are placed on the simulated events). Every value
// must lie within its input's bounds.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "collocation/problem.hpp"

namespace saltus::collocation {

// A schedule file that cannot be used (bad input: the Python module raises ValueError).
struct InputScheduleError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Feedback on a schedule (a re-simulation's, simulation_seed.hpp): each input also pulls its own
// coordinate towards a reference motion, u_i = ū_i(t) + kp_i (q_ref,i(t) − q_i) + kd_i (v_ref,i(t) − v_i),
// clamped to the input's bounds, where ū is the schedule's value. The reference is linear between
// its samples; two samples at one time are a velocity jump (before, then after).
struct Tracking {
  std::vector<double> times;        // nondecreasing from 0 [s]
  std::vector<Eigen::VectorXd> q, v;  // per sample, the inputs' coordinates' positions and rates
  Eigen::VectorXd kp, kd;           // per input [N/m or N m/rad; N s/m or N m s/rad]

  // The reference at t (after a jump at t; the first sample before 0, the last after the end).
  void reference(double t, Eigen::VectorXd& q_out, Eigen::VectorXd& v_out) const;
};

struct InputSchedule {
  std::string path;
  std::vector<double> times;            // strictly increasing from 0; the last: the horizon [s]
  std::vector<Eigen::VectorXd> values;  // per row, the problem's inputs (Problem::inputs' order)
  std::optional<Tracking> tracking;     // none: open loop

  double horizon() const { return times.back(); }
  // The inputs held at time t: the last row whose time is ≤ t (the first row before 0).
  const Eigen::VectorXd& at(double t) const;
};

// Reads a schedule for problem p. Throws InputScheduleError naming the file, the row or line and
// the column: a missing u.<input> column, a u. column that is not one of the problem's inputs,
// a first time other than 0, times not increasing, a value outside its input's bounds, fewer
// than two rows, a problem without inputs.
InputSchedule readInputSchedule(const std::string& path, const Problem& p);

}  // namespace saltus::collocation
