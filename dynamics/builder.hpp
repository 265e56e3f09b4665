// Building a Model from links and joints: the small C++ API for models, and the back end of the
// URDF reader. Fixed joints are merged into their parent body, the floating base becomes one
// multi-coordinate joint on the root link's body (BaseType), bodies are numbered depth first,
// and every link and joint is validated.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "dynamics/model.hpp"

namespace saltus::dynamics {

// A model that cannot be built; the message names the file (when there is one), the element
// and what was expected.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class LinkJointType { Revolute, Continuous, Prismatic, Fixed };

struct LinkSpec {
  std::string name;
  bool has_inertial = false;  // a link without inertial data is massless
  // An inertial of mass 0 and inertia 0 given on purpose (a URDF's massless cross of a two-axis
  // joint): not refused as a non-positive mass, but still needs mass below it (build()).
  bool declared_massless = false;
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();         // in the link frame
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();  // rotational inertia about the com, link axes
  std::vector<Visual> visuals;                           // poses relative to the link frame
};

struct JointSpec {
  std::string name;
  LinkJointType type = LinkJointType::Revolute;
  std::string parent, child;                           // link names
  Eigen::Matrix3d R_PJ = Eigen::Matrix3d::Identity();  // joint (= child link) frame in the parent link frame
  Eigen::Vector3d p_PJ = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();     // in the joint frame; normalised by the builder
  JointLimits limits;
};

class ModelBuilder {
 public:
  explicit ModelBuilder(std::string name = "model") : name_(std::move(name)) {}

  // A massless link (the world, or a frame to attach things to).
  ModelBuilder& addLink(const std::string& name);
  // A link with mass, centre of mass c (link frame) and rotational inertia about c. A point
  // mass (zero rotational inertia) is allowed; otherwise the inertia must be positive definite
  // and satisfy the triangle inequality.
  ModelBuilder& addLink(const std::string& name, double mass, const Eigen::Vector3d& com,
                        const Eigen::Matrix3d& inertia_com);
  ModelBuilder& addLink(LinkSpec link);
  ModelBuilder& addJoint(JointSpec joint);
  ModelBuilder& addVisual(const std::string& link, Visual visual);
  // Prefix of every error message, e.g. the file the model came from.
  ModelBuilder& setSource(std::string source);
  // When set (the URDF reader sets it), every moving link must carry an <inertial> of its own
  // or through a link fixed to it. Otherwise a massless moving link is accepted as long as some
  // body below it has mass (an intermediate link of a multi-axis joint); a massless leaf never is.
  ModelBuilder& requireInertials(bool require);

  // Throws ModelError naming the offending link or joint.
  Model<double> build(BaseType base = BaseType::Fixed,
                      const Eigen::Vector3d& gravity = Eigen::Vector3d(0, 0, -9.81)) const;

  const std::vector<LinkSpec>& links() const { return links_; }
  const std::vector<JointSpec>& joints() const { return joints_; }

 private:
  [[noreturn]] void fail(const std::string& what) const;
  int linkIndex(const std::string& name) const;

  std::string name_;
  std::string source_ = "builder";
  bool require_inertials_ = false;
  std::vector<LinkSpec> links_;
  std::vector<JointSpec> joints_;
};

// Checks a rigid body's inertial data; returns an empty string when valid, else what is wrong.
// allow_point_mass admits a zero rotational inertia.
std::string checkInertia(double mass, const Eigen::Matrix3d& inertia_com, bool allow_point_mass);

// A point mass moving along one prismatic coordinate (axis in world coordinates), e.g. a ball
// dropping vertically: the smallest model of a scene that needs one coordinate.
Model<double> pointMassModel(double mass, const Eigen::Vector3d& axis,
                             const std::string& coordinate = "z",
                             const Eigen::Vector3d& gravity = Eigen::Vector3d(0, 0, -9.81));

}  // namespace saltus::dynamics
