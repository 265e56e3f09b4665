#include "python/bindings.hpp"

PYBIND11_MODULE(_saltus, m) {
  m.doc() = "Saltus: rigid multibody systems with impacts and friction (C++ core).";
  saltus::python::bindErrors(m);
  saltus::python::bindDynamics(m);
  saltus::python::bindScenes(m);
  saltus::python::bindOptimize(m);
  saltus::python::bindReplay(m);
}
