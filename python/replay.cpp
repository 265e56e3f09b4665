// saltus.replay and saltus.render: a saved solution replayed in the time-stepper and/or Bullet, and
// a trajectory drawn off-screen, writing the same files as `saltus replay` and `saltus render`;
// frames one at a time as NumPy images.
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "python/bindings.hpp"
#include "saltus/saltus.hpp"

namespace saltus::python {

namespace {

render::AnimationOptions animationOptions(double fps, double speed, int width, int height, int antialias,
                                          const std::string& camera) {
  render::AnimationOptions o;
  o.fps = fps;
  o.speed = speed;
  o.width = width;
  o.height = height;
  o.supersample = antialias;
  o.camera = render::parseCameraMode(camera);
  return o;
}

RenderInput renderInput(const std::string& path, const py::object& scene, const std::map<std::string, double>& set,
                        bool allow_changed_problem = false) {
  if (scene.is_none()) return openSolution(path, allow_changed_problem);
  const scene::Scene s =
      py::isinstance<py::str>(scene) ? loadScene(scene.cast<std::string>(), set) : *scene.cast<std::shared_ptr<scene::Scene>>();
  return openTrajectoryCsv(path, s);
}

}  // namespace

void bindReplay(py::module_& m) {
  m.def(
      "replay",
      [](const std::string& solution, const std::string& out, const std::string& engine, double dt, double theta,
         const std::string& feedback, double kp, double kd, const std::string& restart, double tolerance, bool charts,
         bool allow_changed_problem) {
        verify::ReplayOptions o;
        o.engines = verify::parseEngines(engine);
        o.dt = dt;
        o.theta = theta;
        o.feedback = verify::parseFeedback(feedback);
        o.kp = kp;
        o.kd = kd;
        o.restart = verify::parseRestart(restart);
        o.tolerance = tolerance;
        verify::ReplayResult r;
        std::string chart_error;
        {
          py::gil_scoped_release release;
          r = saltus::replay(solution, o, allow_changed_problem);
          if (!out.empty()) chart_error = writeReplay(out, r, solution, charts);
        }
        py::dict d;
        d["within_tolerance"] = r.withinTolerance();
        d["tolerance"] = r.tolerance;
        d["steps"] = r.steps;
        py::dict engines;
        for (const verify::EngineReplay& e : r.engines) {
          py::dict ed;
          ed["completed"] = e.completed;
          ed["message"] = e.message;
          ed["max_position_deviation"] = e.max_position_deviation;
          ed["final_position_deviation"] = e.final_position_deviation;
          ed["max_penetration"] = e.max_penetration;
          ed["within_tolerance"] = e.within_tolerance;
          int matched = 0;
          for (const verify::EventMatch& x : e.matches) matched += x.matched;
          ed["events_matched"] = matched;
          ed["events_optimised"] = static_cast<int>(e.matches.size());
          engines[py::str(verify::engineName(e.engine))] = ed;
        }
        d["engines"] = engines;
        if (!chart_error.empty()) d["chart_error"] = chart_error;
        return d;
      },
      py::arg("solution"), py::kw_only(), py::arg("out") = "", py::arg("engine") = "saltus", py::arg("dt") = 1e-4,
      py::arg("theta") = 0.5, py::arg("feedback") = "none", py::arg("kp") = 100.0, py::arg("kd") = 20.0,
      py::arg("restart") = "none", py::arg("tolerance") = 0.0, py::arg("charts") = true, py::arg("allow_changed_problem") = false,
      "Replays a saved solution (a Solution.save / `saltus optimize` folder) from its initial state in the "
      "time-stepper ('saltus'), Bullet ('bullet') or 'both', driven by its inputs, as `saltus replay`; with `out`, "
      "writes replay.csv, replay.json and the charts there. Returns a dict: within_tolerance, tolerance [m or rad] "
      "(0: 10 m/s × dt), steps, and per engine its deviations, penetration and matched events. A solution whose "
      "problem file changed since the solve raises ValueError unless allow_changed_problem.");

  m.def(
      "render",
      [](const std::string& trajectory, const std::string& video, const std::string& frames, const py::object& scene,
         const std::map<std::string, double>& set, double fps, double speed, int width, int height, int antialias,
         const std::string& camera, bool allow_changed_problem) {
        if (video.empty() && frames.empty()) throw std::invalid_argument("nothing to write: give video and/or frames");
        const RenderInput input = renderInput(trajectory, scene, set, allow_changed_problem);
        if (!input.problem_changed.empty())
          PyErr_WarnEx(PyExc_UserWarning, (input.problem_changed + ": drawn in the problem as it is now").c_str(), 1);
        const render::AnimationOptions o = animationOptions(fps, speed, width, height, antialias, camera);
        std::ostringstream warnings;
        RenderReport r;
        {
          py::gil_scoped_release release;
          r = renderTrajectory(input, o, video, frames, warnings);
        }
        if (!warnings.str().empty()) PyErr_WarnEx(PyExc_UserWarning, warnings.str().c_str(), 1);
        return r.frames;
      },
      py::arg("trajectory"), py::kw_only(), py::arg("video") = "", py::arg("frames") = "", py::arg("scene") = py::none(),
      py::arg("set") = std::map<std::string, double>{}, py::arg("fps") = 60.0, py::arg("speed") = 1.0,
      py::arg("width") = 1280, py::arg("height") = 720, py::arg("antialias") = 1, py::arg("camera") = "auto",
      py::arg("allow_changed_problem") = false,
      "Draws a saved solution folder, or a trajectory CSV in `scene`, off-screen into an H.264 MP4 (`video`) "
      "and/or PNG frames (`frames` folder), as `saltus render`; returns the number of frames.");

  py::class_<FrameRenderer>(m, "FrameRenderer", "Frames of a trajectory drawn one at a time, as NumPy images.")
      .def(py::init([](const std::string& trajectory, const py::object& scene, const std::map<std::string, double>& set,
                       double fps, double speed, int width, int height, int antialias, const std::string& camera) {
             std::ostringstream warnings;
             return std::make_unique<FrameRenderer>(renderInput(trajectory, scene, set),
                                                    animationOptions(fps, speed, width, height, antialias, camera),
                                                    warnings);
           }),
           py::arg("trajectory"), py::kw_only(), py::arg("scene") = py::none(),
           py::arg("set") = std::map<std::string, double>{}, py::arg("fps") = 60.0, py::arg("speed") = 1.0,
           py::arg("width") = 640, py::arg("height") = 360, py::arg("antialias") = 1, py::arg("camera") = "auto")
      .def_property_readonly("frames", &FrameRenderer::frames)
      .def("time", &FrameRenderer::time, py::arg("frame"), "Trajectory time of a frame [s].")
      .def(
          "draw",
          [](FrameRenderer& r, int frame) {
            const std::vector<std::uint8_t>& rgb = r.draw(frame);
            py::array_t<std::uint8_t> image({r.height(), r.width(), 3});
            std::copy(rgb.begin(), rgb.end(), image.mutable_data());
            return image;
          },
          py::arg("frame"), "The frame's pixels, uint8 of shape (height, width, 3), top row first.");
}

}  // namespace saltus::python
