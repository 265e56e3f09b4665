// Problems and saltus.optimize: the library API's solve, the GIL released while Ipopt runs and
// Ctrl-C stopping it cleanly (Ipopt's intermediate callback) as a KeyboardInterrupt; the solution's
// samples as NumPy arrays, its polynomials at any time, its summary and its files.
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "collocation/interpolation.hpp"
#include "python/bindings.hpp"
#include "saltus/saltus.hpp"

namespace saltus::python {

namespace {

using Parameters = std::map<std::string, double>;
using ProblemPtr = std::shared_ptr<collocation::Problem>;

// A solve with its collocation polynomials (which refer to the result's transcription).
struct SolutionHandle {
  explicit SolutionHandle(OptimizeResult r) : result(std::move(r)), trajectory(*result.transcription, result.report.x) {}
  OptimizeResult result;
  collocation::CollocationTrajectory trajectory;
};

ProblemPtr problemOf(const py::object& problem, const Parameters& set) {
  if (py::isinstance<py::str>(problem))
    return std::make_shared<collocation::Problem>(loadProblem(problem.cast<std::string>(), set));
  if (!set.empty()) throw std::invalid_argument("set: give the overrides to load_problem, not with a Problem object");
  return problem.cast<ProblemPtr>();
}

// Samples × columns of one quantity of the samples.
template <class F>
Eigen::MatrixXd sampleMatrix(const std::vector<collocation::Sample>& samples, int columns, F value) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(samples.size()), columns);
  for (std::size_t k = 0; k < samples.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = value(samples[k]).transpose();
  return out;
}

}  // namespace

void bindOptimize(py::module_& m) {
  static py::exception<std::runtime_error> solve_error(m, "SolveError", PyExc_RuntimeError);
  solve_error.doc() = "A solve that ended infeasible when a feasible one was required; args: (message, status).";

  py::class_<collocation::Problem, ProblemPtr>(m, "Problem", "A trajectory optimisation problem: scene, mesh, task.")
      .def_readonly("name", &collocation::Problem::name)
      .def_readonly("description", &collocation::Problem::description)
      .def_readonly("N", &collocation::Problem::N, "Finite elements.")
      .def_readonly("P", &collocation::Problem::P, "Collocation points per element.")
      .def_readonly("h_max", &collocation::Problem::h_max, "Longest element [s].")
      .def_property_readonly("parameters", [](const collocation::Problem& p) { return p.parameters; })
      .def_property_readonly(
          "inputs",
          [](const collocation::Problem& p) {
            std::vector<std::string> names;
            for (int c : p.inputs) names.push_back(p.scene.model.coordinate_name[c]);
            return names;
          },
          "The actuated coordinates, in the order of the inputs (the u.<name> columns of a trajectory).")
      .def_property_readonly("input_lower", [](const collocation::Problem& p) { return p.input_lower; },
                             "Lower bound of each input [N or N m].")
      .def_property_readonly("input_upper", [](const collocation::Problem& p) { return p.input_upper; },
                             "Upper bound of each input [N or N m].")
      .def_property_readonly("scene", [](const collocation::Problem& p) { return std::make_shared<scene::Scene>(p.scene); })
      .def("__repr__", [](const collocation::Problem& p) { return "<saltus.Problem '" + p.name + "'>"; });

  m.def(
      "load_problem",
      [](const std::string& name, const Parameters& set) { return std::make_shared<collocation::Problem>(loadProblem(name, set)); },
      py::arg("name"), py::arg("set") = Parameters{},
      "A built-in problem (point_mass_drop, point_mass_throw, pendulum_conveyor, biped_stop, monopod_turn) or a problem file, with "
      "parameter overrides. Bad files raise ValueError naming file, line and key.");

  py::class_<SolutionHandle, std::shared_ptr<SolutionHandle>>(m, "Solution", "An optimised trajectory.")
      .def_property_readonly("feasible", [](const SolutionHandle& s) { return s.result.feasible(); },
                             "Every complementarity product and every constraint is within its tolerance at the solution.")
      .def_property_readonly("converged", [](const SolutionHandle& s) { return s.result.report.converged; },
                             "Feasible, and Ipopt solved the stage the solution comes from (minimising the task cost, if any).")
      .def_property_readonly("status", [](const SolutionHandle& s) { return s.result.report.keptStage().status; },
                             "Ipopt's status of the stage whose point is the solution.")
      .def_property_readonly(
          "summary",
          [](const SolutionHandle& s) { return py::module_::import("json").attr("loads")(summaryJson(s.result)); },
          "summary.json as a dict: the mesh, seed, Ipopt's status per stage and attempt, timing, products.")
      .def_property_readonly("problem", [](const SolutionHandle& s) { return std::make_shared<collocation::Problem>(s.result.problem()); })
      .def_property_readonly(
          "t",
          [](const SolutionHandle& s) {
            Eigen::VectorXd t(static_cast<Eigen::Index>(s.result.samples.size()));
            for (Eigen::Index k = 0; k < t.size(); ++k) t[k] = s.result.samples[static_cast<std::size_t>(k)].t;
            return t;
          },
          "Sample times [s]: every point of every element (a velocity jump: two samples at one time).")
      .def_property_readonly(
          "q", [](const SolutionHandle& s) { return sampleMatrix(s.result.samples, s.result.problem().scene.model.nq(), [](const auto& x) { return x.q; }); },
          "Coordinates at the samples, shape (samples, nq).")
      .def_property_readonly(
          "v", [](const SolutionHandle& s) { return sampleMatrix(s.result.samples, s.result.problem().scene.model.nv(), [](const auto& x) { return x.v; }); },
          "Velocities at the samples, shape (samples, nv).")
      .def_property_readonly(
          "u",
          [](const SolutionHandle& s) {
            const int nu = static_cast<int>(s.result.problem().inputs.size());
            return sampleMatrix(s.result.samples, nu, [nu](const auto& x) {
              return x.u.size() == nu ? Eigen::VectorXd(x.u) : Eigen::VectorXd(Eigen::VectorXd::Zero(nu));
            });
          },
          "Inputs at the samples (zero where a point has none), shape (samples, inputs).")
      .def_property_readonly(
          "contacts",
          [](const SolutionHandle& s) {
            py::dict out;
            const std::vector<collocation::Sample>& samples = s.result.samples;
            const auto& pairs = s.result.transcription->contacts();
            for (std::size_t c = 0; c < pairs.size(); ++c) {
              Eigen::VectorXd gap(samples.size()), vn(samples.size()), rn(samples.size()), pn(samples.size());
              Eigen::MatrixXd plane(samples.size(), 2);
              for (std::size_t k = 0; k < samples.size(); ++k) {
                const scene::ContactRow& r = samples[k].contacts[c];
                gap[static_cast<Eigen::Index>(k)] = r.gap;
                vn[static_cast<Eigen::Index>(k)] = r.vn;
                rn[static_cast<Eigen::Index>(k)] = r.rn;
                pn[static_cast<Eigen::Index>(k)] = r.pn;
                plane.row(static_cast<Eigen::Index>(k)) = r.s.transpose();
              }
              py::dict d;
              d["gap"] = gap;
              d["vn"] = vn;
              d["rn"] = rn;
              d["pn"] = pn;
              d["s"] = plane;
              out[py::str(pairs[c].name)] = d;
            }
            return out;
          },
          "Per contact (scene contacts, then limit stops) at the samples: gap [m], vn [m/s], the normal force "
          "rn [N] at the collocation points, the normal impulse pn [N s] at a velocity jump, and s [m], shape "
          "(samples, 2): on a body's plane the contact point's plane coordinates (a free point's variables), else zero.")
      .def_property_readonly("mesh_times", [](const SolutionHandle& s) { return s.trajectory.meshTimes(); },
                             "Element boundaries [s].")
      .def(
          "at",
          [](const SolutionHandle& s, double t, const std::string& side) {
            if (side != "before" && side != "after") throw std::invalid_argument("side: expected 'before' or 'after'");
            const collocation::TrajectoryPoint p =
                s.trajectory.at(t, side == "before" ? collocation::Side::Before : collocation::Side::After);
            py::dict d;
            d["q"] = p.q;
            d["v"] = p.v;
            d["a"] = p.a;
            d["u"] = p.u;
            return d;
          },
          py::arg("t"), py::arg("side") = "after",
          "The element polynomials at time t [s] (paper eq. 3): q, v, a, u; at a velocity jump the left "
          "('before') or right ('after') limit.")
      .def(
          "save", [](const SolutionHandle& s, const std::string& dir) { saveSolution(dir, s.result); }, py::arg("dir"),
          "Writes trajectory.csv, variables.csv and summary.json into dir, as `saltus optimize --out dir` does "
          "(what `saltus replay` and `saltus render` read).");

  m.def(
      "optimize",
      [](const py::object& problem, const std::string& method, std::optional<int> N, std::optional<int> P,
         std::optional<unsigned> seed, std::optional<std::string> seed_kind, const std::string& seed_from,
         std::optional<std::string> seed_method, const std::string& seed_inputs, std::optional<double> seed_scale, std::optional<int> restarts, std::optional<int> resimulations, std::optional<double> resimulation_tracking, std::optional<std::string> hessian,
         std::optional<std::string> feasibility_hessian, const std::map<std::string, std::string>& ipopt, int print_level, std::optional<double> tighten_within, std::optional<double> tighten_factor, std::optional<int> feasibility_repeats,
         std::optional<int> task_max_iter, std::optional<int> penalty_iterations, std::optional<bool> task_penalty, const std::map<std::string, std::string>& task_ipopt, bool hints, bool continuation,
         bool require_feasible, const Parameters& set) {
        const ProblemPtr p = problemOf(problem, set);
        OptimizeOptions o;
        o.method = collocation::parseMethod(method);
        o.N = N;
        o.P = P;
        o.random_seed = seed;
        if (seed_kind) o.seed_kind = collocation::parseSeedKind(*seed_kind);
        o.seed_from = seed_from;
        if (seed_method) {
          try {
            o.seed_method = collocation::parseMethod(*seed_method);
          } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(std::string("seed_method: ") + e.what());
          }
        }
        o.seed_inputs = seed_inputs;
        o.seed_scale = seed_scale;
        o.restarts = restarts;
        o.resimulations = resimulations;
        o.resimulation_tracking = resimulation_tracking;
        o.hints = hints;
        o.continuation = continuation;
        const auto exact = [](const char* name, const std::optional<std::string>& kind, std::optional<bool>& out) {
          if (!kind) return;
          if (*kind != "exact" && *kind != "limited-memory")
            throw std::invalid_argument(std::string(name) + ": expected 'exact' or 'limited-memory', got '" + *kind +
                                        "'");
          out = *kind == "exact";
        };
        exact("hessian", hessian, o.exact_hessian);
        exact("feasibility_hessian", feasibility_hessian, o.feasibility_exact_hessian);
        o.solve.ipopt = ipopt;
        o.solve.task_ipopt = task_ipopt;
        o.solve.print_level = print_level;
        if (tighten_within) o.solve.tighten_within = *tighten_within;
        if (tighten_factor) o.solve.tighten_factor = *tighten_factor;
        if (feasibility_repeats) o.solve.feasibility_repeats = *feasibility_repeats;  // ≥ 0: checked by optimize
        o.penalty_iterations = penalty_iterations;
        o.task_penalty = task_penalty;
        if (task_max_iter) {
          if (*task_max_iter < 0) throw std::invalid_argument("task_max_iter: expected a non-negative iteration count");
          o.solve.task_max_iter = *task_max_iter;
        }
        // Ctrl-C: Python's signal handler only flags the signal; Ipopt's callback looks at every
        // iteration (with the GIL) and stops the solve, which then raises KeyboardInterrupt.
        bool stopped = false;
        o.solve.interrupted = [&stopped] {
          py::gil_scoped_acquire gil;
          if (!stopped && PyErr_CheckSignals() != 0) {
            PyErr_Clear();
            stopped = true;
          }
          return stopped;
        };
        std::optional<OptimizeResult> result;
        {
          py::gil_scoped_release release;
          result.emplace(saltus::optimize(*p, o));
        }
        if (stopped) {
          PyErr_SetNone(PyExc_KeyboardInterrupt);
          throw py::error_already_set();
        }
        auto solution = std::make_shared<SolutionHandle>(std::move(*result));
        if (require_feasible && !solution->result.feasible()) {
          const std::string status = solution->result.report.keptStage().status;
          PyErr_SetObject(solve_error.ptr(),
                          py::make_tuple(p->name + ": the solve ended infeasible (" + status + ", largest product " +
                                             std::to_string(solution->result.report.largest_product) + ")",
                                         status)
                              .ptr());
          throw py::error_already_set();
        }
        return solution;
      },
      py::arg("problem"), py::kw_only(), py::arg("method") = "impulsive", py::arg("N") = py::none(),
      py::arg("P") = py::none(), py::arg("seed") = py::none(), py::arg("seed_kind") = py::none(),
      py::arg("seed_from") = "", py::arg("seed_method") = py::none(), py::arg("seed_inputs") = "", py::arg("seed_scale") = py::none(), py::arg("restarts") = py::none(),
      py::arg("resimulations") = py::none(), py::arg("resimulation_tracking") = py::none(), py::arg("hessian") = py::none(), py::arg("feasibility_hessian") = py::none(), py::arg("ipopt") = std::map<std::string, std::string>{},
      py::arg("print_level") = 0, py::arg("tighten_within") = py::none(), py::arg("tighten_factor") = py::none(), py::arg("feasibility_repeats") = py::none(),
      py::arg("task_max_iter") = py::none(), py::arg("penalty_iterations") = py::none(), py::arg("task_penalty") = py::none(), py::arg("task_ipopt") = std::map<std::string, std::string>{},
      py::arg("hints") = true, py::arg("continuation") = true, py::arg("require_feasible") = false,
      py::arg("set") = Parameters{},
      "Contact-implicit trajectory optimisation of a problem (a Problem, or a built-in name or file with `set` "
      "overrides) by a method: 'impulsive' (default), 'continuous' or 'first-order', as `saltus optimize` (seed_method: "
      "a first solve with that method seeds this one, --seed-method). An "
      "infeasible solve is a Solution with feasible False (require_feasible=True raises saltus.SolveError "
      "instead). The GIL is released while Ipopt runs; Ctrl-C stops the solve and raises KeyboardInterrupt.");
}

}  // namespace saltus::python
