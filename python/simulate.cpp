// Scenes, the time-stepper one step at a time (so a user closes a control loop in Python), and
// saltus.simulate (the library API's run, its arrays as NumPy arrays, its files as the command's).
#include <map>
#include <memory>
#include <string>

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "python/bindings.hpp"
#include "saltus/saltus.hpp"

namespace saltus::python {

namespace {

using Parameters = std::map<std::string, double>;
using ScenePtr = std::shared_ptr<scene::Scene>;

timestepper::LcpMethod parseSolver(const std::string& solver) {
  if (solver == "lemke") return timestepper::LcpMethod::Lemke;
  if (solver == "pgs") return timestepper::LcpMethod::Pgs;
  throw std::invalid_argument("solver: expected lemke or pgs, got '" + solver + "'");
}

// A scene given by name or path (with overrides), or a Scene object.
ScenePtr sceneOf(const py::object& scene, const Parameters& set) {
  if (py::isinstance<py::str>(scene)) return std::make_shared<scene::Scene>(loadScene(scene.cast<std::string>(), set));
  if (!set.empty()) throw std::invalid_argument("set: give the overrides to load_scene, not with a Scene object");
  return scene.cast<ScenePtr>();
}

// The stepper with the scene it refers to, kept alive as long as the stepper.
struct StepperHandle {
  StepperHandle(ScenePtr s, const timestepper::StepperOptions& options) : scene(std::move(s)), stepper(*scene, options) {}
  ScenePtr scene;
  timestepper::TimeStepper stepper;
};

py::dict contactDict(const timestepper::ContactReport& r) {
  py::dict d;
  d["gap"] = r.gap;
  d["vn"] = r.vn;
  d["vt"] = py::make_tuple(r.vt1, r.vt2);
  d["pn"] = r.pn;
  d["pt"] = py::make_tuple(r.pt1, r.pt2);
  d["s"] = py::make_tuple(r.s1, r.s2);
  d["active"] = r.active;
  return d;
}

py::dict statsDict(const timestepper::StepperStats& s) {
  py::dict d;
  d["steps"] = s.steps;
  d["lcp_solves"] = s.lcp_solves;
  d["lcp_failures"] = s.lcp_failures;
  d["lcp_warm_solves"] = s.lcp_warm_solves;
  d["located_impacts"] = s.located_impacts;
  d["max_lcp_size"] = s.max_lcp_size;
  d["max_penetration"] = s.max_penetration;
  d["max_stop_penetration"] = s.max_stop_penetration;
  return d;
}

}  // namespace

void bindScenes(py::module_& m) {
  py::class_<scene::Scene, ScenePtr>(m, "Scene", "A model with its surfaces, contacts, limit stops, initial state and inputs.")
      .def_readonly("name", &scene::Scene::name)
      .def_readonly("duration", &scene::Scene::duration, "Default simulated time [s].")
      .def_readonly("parameters", &scene::Scene::parameters, "The parameters' values (overrides applied).")
      .def_property_readonly("coordinate_names", [](const scene::Scene& s) { return s.model.coordinate_name; })
      .def_property_readonly("position_names", [](const scene::Scene& s) { return s.model.position_name; })
      .def_property_readonly("contact_names",
                             [](const scene::Scene& s) {
                               std::vector<std::string> names;
                               for (const scene::Contact& c : s.contacts) names.push_back(c.name);
                               return names;
                             })
      .def_property_readonly("surface_names",
                             [](const scene::Scene& s) {
                               std::vector<std::string> names;
                               for (const scene::Surface& c : s.surfaces) names.push_back(c.name);
                               return names;
                             })
      .def_readonly("q0", &scene::Scene::q0, "Initial coordinates.")
      .def_readonly("v0", &scene::Scene::v0, "Initial velocities.")
      .def("__repr__", [](const scene::Scene& s) { return "<saltus.Scene '" + s.name + "'>"; });

  m.def(
      "load_scene",
      [](const std::string& name, const Parameters& set) {
        return std::make_shared<scene::Scene>(loadScene(name, set));
      },
      py::arg("name"), py::arg("set") = Parameters{},
      "A built-in scene (ball_drop, block_slide, ...) or a scenario file, with parameter overrides "
      "(the command line's --set as a dict). Bad files raise ValueError naming file, line and key.");

  py::class_<StepperHandle>(m, "Stepper",
                            "The Moreau–Stewart–Trinkle time-stepper on a scene, one step at a time.")
      .def(py::init([](const py::object& scene, double dt, double theta, const std::string& solver,
                       const Parameters& set) {
             SimulateOptions check;
             check.dt = dt;
             check.theta = theta;
             checkSimulateOptions(check);
             timestepper::StepperOptions o;
             o.dt = dt;
             o.theta = theta;
             o.solver = parseSolver(solver);
             return std::make_unique<StepperHandle>(sceneOf(scene, set), o);
           }),
           py::arg("scene"), py::kw_only(), py::arg("dt") = 1e-3, py::arg("theta") = 1.0, py::arg("solver") = "lemke",
           py::arg("set") = Parameters{},
           "scene: a Scene, or a built-in name or file (with `set` overrides); dt [s]; theta in [0.5, 1].")
      .def(
          "step",
          [](StepperHandle& h, int steps) {
            for (int i = 0; i < steps; ++i) h.stepper.step();
          },
          py::arg("steps") = 1, "Advances by `steps` steps; raises saltus.SimulationError when one fails.")
      .def(
          "set_input", [](StepperHandle& h, const Eigen::VectorXd& tau) { h.stepper.setInput(tau); }, py::arg("tau"),
          "Generalised forces τ (nv values) held over the following steps, in place of the scene's.")
      .def(
          "reset",
          [](StepperHandle& h, const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t) { h.stepper.reset(q, v, t); },
          py::arg("q"), py::arg("v"), py::arg("t") = 0.0, "Sets the state and the time [s].")
      .def_property_readonly("t", [](const StepperHandle& h) { return h.stepper.time(); }, "Time [s].")
      .def_property_readonly("q", [](const StepperHandle& h) { return Eigen::VectorXd(h.stepper.q()); }, "Coordinates.")
      .def_property_readonly("v", [](const StepperHandle& h) { return Eigen::VectorXd(h.stepper.v()); }, "Velocities.")
      .def_property_readonly("scene", [](const StepperHandle& h) { return h.scene; })
      .def("energy", [](StepperHandle& h) { return h.stepper.energy(); }, "Kinetic plus potential energy [J].")
      .def_property_readonly(
          "contacts",
          [](const StepperHandle& h) {
            py::dict out;
            const scene::Scene& s = *h.scene;
            for (std::size_t c = 0; c < s.contacts.size(); ++c) out[py::str(s.contacts[c].name)] = contactDict(h.stepper.contacts()[c]);
            return out;
          },
          "Per scene contact after the last step: gap [m], vn, vt [m/s], pn, pt impulses [N s], active, and s "
          "[m]: on a body's plane the point's plane coordinates (else zero).")
      .def_property_readonly("stats", [](const StepperHandle& h) { return statsDict(h.stepper.stats()); });

  py::class_<Simulation>(m, "Simulation", "A time-stepper run held in memory: one row per sample.")
      .def_property_readonly("t", [](const Simulation& s) { return s.t; }, "Times [s], shape (samples,).")
      .def_property_readonly("q", [](const Simulation& s) { return s.q; }, "Coordinates, shape (samples, nq).")
      .def_property_readonly("v", [](const Simulation& s) { return s.v; }, "Velocities, shape (samples, nv).")
      .def_property_readonly("coordinate_names", [](const Simulation& s) { return s.layout.coordinates; },
                             "Velocity coordinates: the columns of v.")
      .def_property_readonly("position_names", [](const Simulation& s) { return s.layout.positions; },
                             "Position coordinates: the columns of q (a quaternion base has four for its orientation).")
      .def_property_readonly(
          "contacts",
          [](const Simulation& s) {
            py::dict out;
            for (const ContactHistory& h : s.contacts) {
              py::dict d;
              d["gap"] = h.gap;
              d["vn"] = h.vn;
              d["vt1"] = h.vt1;
              d["vt2"] = h.vt2;
              d["pn"] = h.pn;
              d["pt1"] = h.pt1;
              d["pt2"] = h.pt2;
              d["s1"] = h.s1;
              d["s2"] = h.s2;
              out[py::str(h.name)] = d;
            }
            return out;
          },
          "Per contact (scene contacts, then limit stops): arrays gap [m], vn, vt1, vt2 [m/s], pn, pt1, pt2 [N s], "
          "s1, s2 [m] (on a body's plane the point's plane coordinates, else zero).")
      .def_property_readonly("stats", [](const Simulation& s) { return statsDict(s.summary.stats); })
      .def_property_readonly("energy_start", [](const Simulation& s) { return s.summary.energy_start; }, "[J]")
      .def_property_readonly("energy_end", [](const Simulation& s) { return s.summary.energy_end; }, "[J]")
      .def_property_readonly("wall_seconds", [](const Simulation& s) { return s.summary.wall_seconds; },
                             "Wall time of the stepping [s].")
      .def(
          "save", [](const Simulation& s, const std::string& path) { writeTrajectoryCsv(path, s); }, py::arg("path"),
          "Writes the trajectory CSV of `saltus simulate` (whole or not at all).");

  m.def(
      "simulate",
      [](const py::object& scene, double dt, double duration, double theta, const std::string& solver,
         const Parameters& set, long every) {
        const ScenePtr s = sceneOf(scene, set);
        SimulateOptions o;
        o.every = every;
        o.dt = dt;
        o.duration = duration;
        o.theta = theta;
        o.solver = parseSolver(solver);
        py::gil_scoped_release release;
        return saltus::simulate(*s, o);
      },
      py::arg("scene"), py::kw_only(), py::arg("dt") = 1e-3, py::arg("duration") = 0.0, py::arg("theta") = 1.0,
      py::arg("solver") = "lemke", py::arg("set") = Parameters{}, py::arg("every") = 1,
      "Runs the time-stepper on a scene (a Scene, or a built-in name or file with `set` overrides) for "
      "`duration` seconds (0: the scene's) at step dt [s]; returns a Simulation. `every` keeps the samples at "
      "t = 0, after every `every`-th step and after the last (as `saltus simulate --every`).");
}

}  // namespace saltus::python
