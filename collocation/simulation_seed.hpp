// A starting point for a transcription from Saltus' own time-stepper (timestepper/stepper.hpp):
// the problem's scene simulated from its initial state with the inputs at zero (or an open-loop
// schedule of them, input_schedule.hpp), the mesh placed
// so that element boundaries fall on the simulated impacts, and the simulation resampled onto
// it. The paper closes on this question ("how these seeds can be obtained for truly unknown
// contact sequences", §VII); a simulation gives a seed that is physically consistent from the
// start: states, velocity jumps Δq̇ at the boundaries, contact forces and impulses, friction
// activations and slip bounds.
//
// The mesh: elements of equal length h0 (the total time T / N when it is fixed, else the middle
// of the length bounds, and at least T / N when T is a lower bound); each event is moved to the
// nearest element boundary (counted from the previous event's when the lengths cannot reach it,
// or the next or the one before: with h0 = h_max an event late for its boundary takes a later
// one, and so every event after it; an event within h0 / 2 after the previous one shares its
// boundary and is left out), and the elements between consecutive events share the time between
// them equally (within the length bounds). The events are the impacts (a step of the simulation
// whose velocity change exceeds 20 g dt while a contact carries an impulse; a run of such steps
// is one impact, when its contact closes) and the changes of a contact's mode that last 5 steps
// (lift-off, a touchdown without impact, sticking, slipping): the transcription allows these at
// element boundaries only (paper eqs. 10 and 13 sum over the element). A surface whose velocity steps on the mesh steps at its mesh point's time, so the mesh
// and the simulation are iterated (at most 4 times) until the steps stay where they were
// simulated.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "collocation/input_schedule.hpp"
#include "collocation/transcription.hpp"

namespace saltus::collocation {

struct SimulationSeedReport {
  double dt = 0;                    // the simulation's step
  std::vector<double> events;       // times of the impacts and contact changes on the mesh's boundaries
  std::vector<double> mesh_times;   // the problem's element boundaries (N + 1 values)
  int iterations = 0;               // mesh–simulation passes
};

// With a schedule (input_schedule.hpp) the inputs are the schedule's instead of zero, in the
// simulation and in the seed's u, and the elements start at the schedule's horizon over N (when
// the total time is free; a total time the problem fixes or bounds below takes precedence).
// Throws std::runtime_error (naming the time-stepper's failure) when the simulation fails.
Eigen::VectorXd seedFromSimulation(const Transcription& t, SimulationSeedReport* report = nullptr,
                                   const InputSchedule* schedule = nullptr);

// The inputs of a point x of t (an optimiser's end point) as an open-loop schedule: each
// collocation point's inputs held from halfway after the previous point (the element's start for
// the first) to halfway to the next, clamped within the inputs' bounds (Ipopt relaxes them by
// 1e-8); the horizon is x's total time. Throws std::invalid_argument for a problem without inputs.
InputSchedule scheduleFromInputs(const Transcription& t, const Eigen::VectorXd& x);

// The motion of x's actuated coordinates (its trajectory's samples) as a reference for its inputs
// to track: each input's gains those of a critically damped oscillator of natural frequency
// omega [rad/s] on its coordinate's inertia at the initial state (the diagonal of M(q0)).
// Throws std::invalid_argument for a problem without inputs or omega ≤ 0.
Tracking trackingFromPoint(const Transcription& t, const Eigen::VectorXd& x, double omega);

// Re-simulation: the simulation seed under x's inputs (scheduleFromInputs). From the end of a
// failed solve, the time-stepper's motion under its inputs is a physically consistent point
// (every product zero, each impact a real one) near what the optimiser was doing; what it
// violates is the task's constraints, which a solve from there can pull in (README, "The Ollie").
// With tracking > 0 the inputs also track x's motion of their coordinates (trackingFromPoint,
// natural frequency tracking [rad/s]): open loop, the motion under the inputs of a point that
// relaxes its contacts drifts from it; the feedback keeps the actuated coordinates on it, and the
// rest follows through real contacts. The seed's inputs are then the ones applied.
// Throws as seedFromSimulation.
Eigen::VectorXd seedFromResimulation(const Transcription& t, const Eigen::VectorXd& x,
                                     SimulationSeedReport* report = nullptr, double tracking = 0);

// Whether a hint that closes a contact (a gap bound ≤ 1e-6 at [n, p]) can be met by the
// problem's own motion: the mesh point can lie anywhere in [earliest, latest] (the element
// lengths within their bounds), and the simulation from the initial state with the inputs at
// zero (as for the seed) has the contact closed at some time in that window. For a problem
// without inputs the simulation is the motion, and a hint it does not reach cannot be met; with
// inputs (`actuated`), it is one the unactuated motion does not reach, which the inputs may
// still bring about. Other hints are not checked.
struct HintReach {
  std::string origin;   // where the hint was given
  std::string contact;
  int element = 0, point = 0;  // 0-based
  double earliest = 0, latest = 0;
  double closes = -1;   // the first time the simulated contact is closed (−1: never)
  bool reachable = false;
  bool actuated = false;  // the problem has inputs: the simulated motion is not the only one
};
std::vector<HintReach> checkHints(const Transcription& t);

}  // namespace saltus::collocation
