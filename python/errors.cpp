// C++ exceptions as Python ones, with the same located messages as the command line: bad input
// (a model, scenario, problem or solution file; an option out of range; an array of the wrong
// size) is a ValueError; a time step that fails is saltus.SimulationError (a RuntimeError).
#include <stdexcept>

#include "collocation/input_schedule.hpp"
#include "collocation/saved_solution.hpp"
#include "dynamics/builder.hpp"
#include "python/bindings.hpp"
#include "scene/yaml_reader.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::python {

void bindErrors(py::module_& m) {
  static py::exception<timestepper::SimulationError> simulation_error(m, "SimulationError", PyExc_RuntimeError);
  simulation_error.doc() = "A time step failed (LCP failure, a state that is not finite); the message says when.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const timestepper::SimulationError& e) {
      simulation_error(e.what());
    } catch (const scene::ScenarioError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const dynamics::ModelError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const collocation::SolutionError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const collocation::InputScheduleError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
}

}  // namespace saltus::python
