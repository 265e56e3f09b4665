// saltus.Model and the dynamics kernels on NumPy arrays: RNEA, CRBA, ABA, the nonlinear effects,
// forward kinematics, point Jacobians, energy and the AD derivatives of RNEA and ABA. Each Model
// carries its own workspace (dynamics::Data), so a call allocates only its result. Arrays are
// float64; a contiguous float64 array is read in place (Eigen::Ref), any other is converted. A
// vector of the wrong length is a ValueError naming the function and the argument.
#include <fstream>
#include <memory>
#include <string>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "dynamics/derivatives.hpp"
#include "dynamics/dynamics.hpp"
#include "dynamics/urdf.hpp"
#include "python/bindings.hpp"
#include "saltus/saltus.hpp"
#include "scene/scenario.hpp"

namespace saltus::python {

namespace {

using VecIn = Eigen::Ref<const Eigen::VectorXd>;

// A model with its workspace; the Data refers to the Model, so neither moves after construction.
struct ModelHandle {
  explicit ModelHandle(dynamics::Model<double> m) : model(std::move(m)), data(model) {}
  ModelHandle(const ModelHandle&) = delete;
  ModelHandle& operator=(const ModelHandle&) = delete;
  dynamics::DerivativeData<8>& derivatives() {
    if (!derivative_data) derivative_data = std::make_unique<dynamics::DerivativeData<8>>(model);
    return *derivative_data;
  }
  dynamics::Model<double> model;
  dynamics::Data<double> data;
  std::unique_ptr<dynamics::DerivativeData<8>> derivative_data;  // made on first use
};
using ModelPtr = std::shared_ptr<ModelHandle>;

dynamics::BaseType parseBase(const std::string& base) {
  if (base == "fixed") return dynamics::BaseType::Fixed;
  if (base == "planar") return dynamics::BaseType::Planar;
  if (base == "free") return dynamics::BaseType::Free;
  if (base == "free_quaternion") return dynamics::BaseType::FreeQuaternion;
  throw std::invalid_argument("base: expected fixed, planar, free or free_quaternion, got '" + base + "'");
}

Eigen::MatrixXd crbaOf(ModelHandle& h, const VecIn& q) { return dynamics::crba(h.model, h.data, q); }

int bodyIndex(const ModelHandle& h, const std::string& body) {
  const int i = h.model.bodyIndex(body);
  if (i < 0) throw std::invalid_argument("body '" + body + "': not a body of model '" + h.model.name + "'");
  return i;
}

}  // namespace

void bindDynamics(py::module_& m) {
  py::class_<ModelHandle, ModelPtr>(m, "Model", "A rigid multibody model (bodies, joints, inertias) with its workspace.")
      .def_static(
          "from_urdf",
          [](const std::string& path, const std::string& base) {
            return std::make_shared<ModelHandle>(saltus::loadModel(path, parseBase(base)));
          },
          py::arg("path"), py::arg("base") = "fixed",
          "Reads a URDF file; base: 'fixed', 'planar' (x, z, pitch) or 'free' (x, y, z and a rotation vector).")
      .def_static(
          "builtin",
          [](const std::string& name, const std::string& base) {
            for (const char* folder : {"benchmark", "pendulum"}) {
              const std::string path = scene::dataDirectory() + "/models/" + folder + "/" + name + ".urdf";
              if (std::ifstream(path)) return std::make_shared<ModelHandle>(saltus::loadModel(path, parseBase(base)));
            }
            throw std::invalid_argument("model '" + name +
                                        "': not a bundled model (iiwa, hyq, atlas in models/benchmark; "
                                        "double_pendulum in models/pendulum)");
          },
          py::arg("name"), py::arg("base") = "fixed",
          "A bundled URDF by name: 'iiwa', 'hyq', 'atlas' (models/benchmark, MIT licence) or 'double_pendulum'.")
      .def_static(
          "from_scene",
          [](const std::string& scene, const std::map<std::string, double>& set) {
            return std::make_shared<ModelHandle>(saltus::loadScene(scene, set).model);
          },
          py::arg("scene"), py::arg("set") = std::map<std::string, double>{},
          "The model of a built-in scene (ball_drop, ...) or scenario file, with parameter overrides.")
      .def_property_readonly("name", [](const ModelHandle& h) { return h.model.name; })
      .def_property_readonly("nq", [](const ModelHandle& h) { return h.model.nq(); },
                             "Number of position coordinates (nv + 1 with a quaternion base).")
      .def_property_readonly("nv", [](const ModelHandle& h) { return h.model.nv(); },
                             "Number of velocity coordinates (= nq but for a quaternion base).")
      .def_property_readonly("coordinate_names", [](const ModelHandle& h) { return h.model.coordinate_name; },
                             "Velocity coordinates (of v, a, tau).")
      .def_property_readonly("position_names", [](const ModelHandle& h) { return h.model.position_name; },
                             "Position coordinates (of q).")
      .def_property_readonly("body_names", [](const ModelHandle& h) { return h.model.body_name; })
      .def_property_readonly("total_mass", [](const ModelHandle& h) { return h.model.totalMass(); }, "[kg]")
      .def_property_readonly("gravity", [](const ModelHandle& h) { return Eigen::Vector3d(h.model.gravity); },
                             "Gravity in world coordinates [m/s²].")
      .def("__repr__", [](const ModelHandle& h) {
        return "<saltus.Model '" + h.model.name + "': " + std::to_string(h.model.nbodies()) + " bodies, nq = " +
               std::to_string(h.model.nq()) + ">";
      });

  m.def(
      "rnea",
      [](ModelHandle& h, const VecIn& q, const VecIn& v, const VecIn& a) -> Eigen::VectorXd {
        return dynamics::rnea(h.model, h.data, q, v, a);
      },
      py::arg("model"), py::arg("q"), py::arg("v"), py::arg("a"),
      "Inverse dynamics (RBDA 5.3): τ = M(q) q̈ + C(q, q̇) q̇ + g(q) [N or N·m], shape (nv,).");
  m.def(
      "crba",
      [](ModelHandle& h, const VecIn& q) -> Eigen::MatrixXd { return dynamics::crba(h.model, h.data, q); },
      py::arg("model"), py::arg("q"), "Joint-space inertia matrix M(q) (RBDA 6.2) [kg or kg·m²], shape (nv, nv).");
  m.def(
      "aba",
      [](ModelHandle& h, const VecIn& q, const VecIn& v, const VecIn& tau) -> Eigen::VectorXd {
        return dynamics::aba(h.model, h.data, q, v, tau);
      },
      py::arg("model"), py::arg("q"), py::arg("v"), py::arg("tau"),
      "Forward dynamics (RBDA 7.3): q̈ = M⁻¹ (τ − C q̇ − g), shape (nv,).");
  m.def(
      "nonlinear_effects",
      [](ModelHandle& h, const VecIn& q, const VecIn& v) -> Eigen::VectorXd {
        return dynamics::nonLinearEffects(h.model, h.data, q, v);
      },
      py::arg("model"), py::arg("q"), py::arg("v"), "Bias forces C(q, q̇) q̇ + g(q), shape (nv,).");
  m.def(
      "forward_kinematics",
      [](ModelHandle& h, const VecIn& q) {
        dynamics::forwardKinematics(h.model, h.data, q);
        std::vector<Eigen::Matrix4d> poses;
        for (int i = 0; i < h.model.nbodies(); ++i) {
          Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
          T.topLeftCorner<3, 3>() = dynamics::bodyRotation(h.data, i);
          T.topRightCorner<3, 1>() = dynamics::bodyPosition(h.data, i);
          poses.push_back(T);
        }
        return poses;
      },
      py::arg("model"), py::arg("q"), "Each body's pose in the world, 4 × 4 homogeneous [m], in body order.");
  m.def(
      "point_jacobian",
      [](ModelHandle& h, const VecIn& q, const std::string& body, const Eigen::Vector3d& point) {
        const int i = bodyIndex(h, body);
        dynamics::forwardKinematics(h.model, h.data, q);
        Eigen::Matrix<double, 3, Eigen::Dynamic> J(3, h.model.nv());
        dynamics::pointJacobian(h.model, h.data, i, point, J);
        return Eigen::MatrixXd(J);
      },
      py::arg("model"), py::arg("q"), py::arg("body"), py::arg("point") = Eigen::Vector3d::Zero(),
      "World-frame Jacobian of a point fixed in a body (given in the body's frame [m]): ṗ = J q̇, shape (3, nv).");
  m.def(
      "kinetic_energy",
      [](ModelHandle& h, const VecIn& q, const VecIn& v) {
        dynamics::forwardKinematics(h.model, h.data, q, v);
        return dynamics::kineticEnergy(h.model, h.data);
      },
      py::arg("model"), py::arg("q"), py::arg("v"), "T = ½ q̇ᵀ M q̇ [J].");
  m.def(
      "potential_energy",
      [](ModelHandle& h, const VecIn& q) {
        dynamics::forwardKinematics(h.model, h.data, q);
        return dynamics::potentialEnergy(h.model, h.data);
      },
      py::arg("model"), py::arg("q"), "Gravitational potential energy, zero at the world origin [J].");
  m.def(
      "rnea_derivatives",
      [](ModelHandle& h, const VecIn& q, const VecIn& v, const VecIn& a) {
        dynamics::DerivativeData<8>& dd = h.derivatives();
        dynamics::rneaDerivatives(h.model, dd, q, v, a);
        return py::make_tuple(Eigen::MatrixXd(dd.dtau_dq), Eigen::MatrixXd(dd.dtau_dv), crbaOf(h, q));
      },
      py::arg("model"), py::arg("q"), py::arg("v"), py::arg("a"),
      "∂τ/∂q, ∂τ/∂q̇ and ∂τ/∂q̈ = M(q) of RNEA, by forward-mode AD; each (nv, nv).");
  m.def(
      "aba_derivatives",
      [](ModelHandle& h, const VecIn& q, const VecIn& v, const VecIn& tau) {
        dynamics::DerivativeData<8>& dd = h.derivatives();
        dynamics::abaDerivatives(h.model, dd, q, v, tau);
        return py::make_tuple(Eigen::MatrixXd(dd.dqdd_dq), Eigen::MatrixXd(dd.dqdd_dv), Eigen::MatrixXd(dd.dqdd_dtau));
      },
      py::arg("model"), py::arg("q"), py::arg("v"), py::arg("tau"),
      "∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹ of ABA, by AD; each (nv, nv).");
}

}  // namespace saltus::python
