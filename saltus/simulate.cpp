// saltus::simulate (saltus/saltus.hpp): the time-stepper over a duration, its samples streamed in
// batches (the clock runs around the stepping only) or gathered into arrays.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "dynamics/urdf.hpp"
#include "saltus/format.hpp"
#include "saltus/saltus.hpp"

namespace saltus {

namespace {

// A trajectory file's contact values from a stepper's report (its tangential pair along the
// surface's tangents; the writer drops the second for a planar contact, and s off a body's plane).
scene::ContactRow contactRow(const timestepper::ContactReport& r) {
  scene::ContactRow c;
  c.gap = r.gap;
  c.vn = r.vn;
  c.vt = {r.vt1, r.vt2};
  c.pn = r.pn;
  c.pt = {r.pt1, r.pt2};
  c.s = {r.s1, r.s2};
  return c;
}

}  // namespace

dynamics::Model<double> loadModel(const std::string& urdf_path, dynamics::BaseType base) {
  return dynamics::loadUrdfFile(urdf_path, base);
}

long stepCount(double duration, double dt) {
  const double r = duration / dt;
  if (!(r < 9007199254740992.0))  // 2^53; also NaN
    throw std::invalid_argument("dt: " + formatNumber(dt) + " s over " + formatNumber(duration) +
                                " s is too many steps (expected fewer than 2^53)");
  const double nearest = std::round(r);
  const long n = std::abs(r - nearest) <= 1e-9 * std::max(1.0, r) ? static_cast<long>(nearest)
                                                                   : static_cast<long>(std::ceil(r));
  return std::max(1L, n);
}

void checkSimulateOptions(const SimulateOptions& options) {
  if (!(options.dt > 0) || !std::isfinite(options.dt))
    throw std::invalid_argument("dt: expected a positive time step [s], got " + formatNumber(options.dt));
  if (!(options.duration >= 0) || !std::isfinite(options.duration))
    throw std::invalid_argument("duration: expected a positive time [s] (0: the scene's), got " +
                                formatNumber(options.duration));
  if (!(options.theta >= 0.5 && options.theta <= 1))
    throw std::invalid_argument("theta: expected a number in [0.5, 1] (0.5: Moreau midpoint, 1: Stewart-Trinkle), got " +
                                formatNumber(options.theta));
  if (options.every < 1)
    throw std::invalid_argument("every: expected a whole number of steps of 1 or more, got " + std::to_string(options.every));
}

namespace {

// The steps of a run of `scene`, the options checked: a step no longer than the duration (a 10 s
// step on a 3 s scene would simulate to 10 s).
long runSteps(const scene::Scene& scene, const SimulateOptions& options) {
  checkSimulateOptions(options);
  const double duration = options.duration > 0 ? options.duration : scene.duration;
  if (options.dt > duration * (1 + 1e-9))
    throw std::invalid_argument("dt: " + formatNumber(options.dt) + " s is longer than the duration " +
                                formatNumber(duration) + " s (expected at most the duration)");
  return stepCount(duration, options.dt);
}

}  // namespace

long sampleCount(const scene::Scene& scene, const SimulateOptions& options) {
  const long steps = runSteps(scene, options);
  return 1 + (steps + options.every - 1) / options.every;
}

double csvBytesEstimate(const scene::Scene& scene, const SimulateOptions& options) {
  const scene::TrajectoryLayout layout = scene::trajectoryLayout(scene);
  const double columns = static_cast<double>(scene::trajectoryHeader(layout).size());
  return static_cast<double>(sampleCount(scene, options)) * columns * 16.0;
}

bool isDriven(const scene::Scene& scene) {
  for (const scene::Surface& s : scene.surfaces)
    for (const auto& step : s.velocity_schedule)
      if (step.velocity.squaredNorm() > 0) return true;
  return scene.tau.size() > 0 && scene.tau.cwiseAbs().maxCoeff() > 0;
}

SimulationSummary simulate(const scene::Scene& scene, const SimulateOptions& options,
                           const std::function<void(const SimulationSample&)>& sink) {
  const long steps = runSteps(scene, options);
  SimulationSummary summary;
  summary.scene = scene.name;
  summary.options = options;
  summary.options.duration = options.duration > 0 ? options.duration : scene.duration;
  summary.driven = isDriven(scene);

  timestepper::StepperOptions stepper_options;
  stepper_options.dt = options.dt;
  stepper_options.theta = options.theta;
  stepper_options.solver = options.solver;
  timestepper::TimeStepper stepper(scene, stepper_options);
  summary.energy_start = stepper.energy();
  const SimulationSample first{stepper.time(), stepper.q(), stepper.v(), stepper.contacts()};
  sink(first);

  // Steps in batches: the clock runs around the stepping only, the sink sees a batch after it.
  constexpr long kBatch = 1024;
  std::vector<SimulationSample> batch(static_cast<std::size_t>(std::min(kBatch, steps)), first);
  // Kept: every `every`-th step and the last.
  std::chrono::steady_clock::duration wall{};
  for (long done = 0; done < steps;) {
    const long n = std::min(kBatch, steps - done);
    const auto start = std::chrono::steady_clock::now();
    std::size_t kept = 0;
    for (long i = 0; i < n; ++i) {
      stepper.step();
      const long step = done + i + 1;
      if (step % options.every != 0 && step != steps) continue;
      SimulationSample& s = batch[kept++];
      s.t = stepper.time();
      s.q = stepper.q();
      s.v = stepper.v();
      s.contacts = stepper.contacts();
    }
    wall += std::chrono::steady_clock::now() - start;
    for (std::size_t i = 0; i < kept; ++i) sink(batch[i]);
    done += n;
  }
  summary.energy_end = stepper.energy();
  summary.stats = stepper.stats();
  summary.end_time = stepper.time();
  summary.wall_seconds = std::chrono::duration<double>(wall).count();
  return summary;
}

Simulation simulate(const scene::Scene& scene, const SimulateOptions& options) {
  const long samples = sampleCount(scene, options);
  Simulation run;
  run.layout = scene::trajectoryLayout(scene);
  // Refused before allocating: samples × (t, q, v, 7 per contact) doubles.
  const double bytes = static_cast<double>(samples) * 8.0 *
                       static_cast<double>(1 + scene.model.nq() + scene.model.nv() + 7 * run.layout.contacts.size());
  if (bytes > kMaxSimulationBytes)
    throw std::invalid_argument("duration: " + std::to_string(samples) + " samples would take " +
                                formatNumber(bytes / 1e9, 3) + " GB of memory (the limit is " +
                                formatNumber(kMaxSimulationBytes / 1e9, 3) +
                                " GB); keep fewer with every, or stream the run to a file");
  const Eigen::Index nq = scene.model.nq(), nv = scene.model.nv();
  run.t.resize(samples);
  run.q.resize(samples, nq);
  run.v.resize(samples, nv);
  for (const scene::TrajectoryLayout::ContactColumns& c : run.layout.contacts) {
    ContactHistory h;
    h.name = c.name;
    for (Eigen::VectorXd* x : {&h.gap, &h.vn, &h.vt1, &h.vt2, &h.pn, &h.pt1, &h.pt2, &h.s1, &h.s2}) x->setZero(samples);
    run.contacts.push_back(std::move(h));
  }
  Eigen::Index k = 0;
  run.summary = simulate(scene, options, [&](const SimulationSample& s) {
    run.t[k] = s.t;
    run.q.row(k) = s.q.transpose();
    run.v.row(k) = s.v.transpose();
    for (std::size_t c = 0; c < run.contacts.size(); ++c) {
      const timestepper::ContactReport& r = s.contacts[c];
      ContactHistory& h = run.contacts[c];
      h.gap[k] = r.gap;
      h.vn[k] = r.vn;
      h.vt1[k] = r.vt1;
      h.vt2[k] = r.vt2;
      h.pn[k] = r.pn;
      h.pt1[k] = r.pt1;
      h.pt2[k] = r.pt2;
      h.s1[k] = r.s1;
      h.s2[k] = r.s2;
    }
    ++k;
  });
  return run;
}

void writeSample(scene::TrajectoryCsvWriter& writer, const SimulationSample& sample) {
  static const Eigen::VectorXd no_inputs;
  writer.beginRow(sample.t, sample.q, sample.v, no_inputs);
  for (const timestepper::ContactReport& r : sample.contacts) writer.contact(contactRow(r));
  writer.endRow();
}

void writeTrajectoryCsv(const std::string& path, const Simulation& simulation) {
  static const Eigen::VectorXd no_inputs;
  scene::TrajectoryCsvWriter writer(path, simulation.layout);
  Eigen::VectorXd q, v;
  for (Eigen::Index k = 0; k < simulation.t.size(); ++k) {
    q = simulation.q.row(k).transpose();
    v = simulation.v.row(k).transpose();
    writer.beginRow(simulation.t[k], q, v, no_inputs);
    for (const ContactHistory& h : simulation.contacts) {
      timestepper::ContactReport r;
      r.gap = h.gap[k];
      r.vn = h.vn[k];
      r.vt1 = h.vt1[k];
      r.vt2 = h.vt2[k];
      r.pn = h.pn[k];
      r.pt1 = h.pt1[k];
      r.pt2 = h.pt2[k];
      r.s1 = h.s1[k];
      r.s2 = h.s2[k];
      writer.contact(contactRow(r));
    }
    writer.endRow();
  }
  writer.commit();
}

}  // namespace saltus
