// The Python module `saltus` (pybind11): one binding file per floor of the library, each adding
// its classes and functions to the module. The module wraps the library API (saltus/saltus.hpp)
// and the dynamics kernels; it holds no pipeline of its own.
#pragma once

#include <pybind11/pybind11.h>

namespace saltus::python {

namespace py = pybind11;

void bindErrors(py::module_& m);    // errors.cpp: C++ exceptions as Python ones
void bindDynamics(py::module_& m);  // dynamics.cpp: Model and the kernels
void bindScenes(py::module_& m);    // simulate.cpp: scenes, the stepper, simulate
void bindOptimize(py::module_& m);  // optimize.cpp: problems, optimize, solutions
void bindReplay(py::module_& m);    // replay.cpp: replay, render, frames

}  // namespace saltus::python
