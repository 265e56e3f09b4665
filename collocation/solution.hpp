// A solved transcription as a trajectory: rows at every mesh and collocation point in time
// order (at a velocity jump two rows with the same t, before then after), written as CSV with
// the columns of `saltus simulate` plus inputs and reactions; and the paper's mean local error
// (Fig. 7).
#pragma once

#include <string>
#include <vector>

#include "collocation/transcription.hpp"
#include "scene/trajectory_csv.hpp"

namespace saltus::collocation {

// A contact's values at a sample: gap, normal and slip velocity, finite force (collocation
// points) and impulse (impulsive [n, 0]), the tangential ones along the surface's tangents.
using ContactSample = scene::ContactRow;

struct Sample {
  double t = 0;
  int element = 0, point = 0;  // 0-based
  Eigen::VectorXd q, v, u;
  std::vector<ContactSample> contacts;  // scene contacts, then limit stops
};

std::vector<Sample> trajectory(const Transcription& t, const Eigen::VectorXd& x);

// Writes the samples as a trajectory CSV (scene/trajectory_csv.hpp) with the inputs and the force
// columns. Throws std::runtime_error naming the file when it cannot write.
void writeTrajectoryCsv(const std::string& path, const Transcription& t, const std::vector<Sample>& samples);

// The paper's mean local error (§V.D, Fig. 7): on every element, the difference between the
// derivative of each state polynomial and the derivative the equations of motion give for the
// interpolated state, input and reactions, integrated over the element in time (Gauss rule of
// P + 1 points), divided by the largest magnitude of the variable on the element (at least 1 %
// of its largest magnitude over the trajectory, so that a variable resting at zero does not
// divide round-off by zero); the mean over elements and state variables. Dimensionless: the
// state error one element adds, relative to the state's size. The first-order method's steps
// are its elements (linear q and q̇ with the end point's rates).
double meanLocalError(const Transcription& t, const Eigen::VectorXd& x);

}  // namespace saltus::collocation
