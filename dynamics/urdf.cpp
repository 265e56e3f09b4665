#include "dynamics/urdf.hpp"
#include "dynamics/urdf_text.hpp"

#include <filesystem>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include <console_bridge/console.h>
#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#if defined(__SANITIZE_ADDRESS__)
#define SALTUS_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SALTUS_ASAN 1
#endif
#endif
#ifdef SALTUS_ASAN
#include <sanitizer/lsan_interface.h>
#endif

namespace saltus::dynamics {

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw ModelError(source + ": " + what);
}

// ---- urdfdom's messages -------------------------------------------------------------------------

struct ParserMessage {
  console_bridge::LogLevel level;
  std::string text;
};

// Collects what urdfdom logs through console_bridge while one parse runs. It is never destroyed:
// console_bridge keeps a pointer to it as its "previous" handler after we restore the old one.
class ParserLog final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (sink) sink->push_back({level, text});  // outside a parse: dropped, never printed
  }
  std::vector<ParserMessage>* sink = nullptr;
};

// urdfdom 3.0 leaks the links of a closed kinematic loop when it rejects the file (they own each
// other through shared_ptr): under AddressSanitizer, LeakSanitizer ignores what it allocates.
struct IgnoreUrdfdomLeaks {
#ifdef SALTUS_ASAN
  IgnoreUrdfdomLeaks() { __lsan_disable(); }
  ~IgnoreUrdfdomLeaks() { __lsan_enable(); }
#endif
};

// urdf::parseURDF with console_bridge redirected into `messages` (warnings and errors); the
// previous output handler and log level are restored before returning. Parses are serialised:
// console_bridge's handler is process-wide.
urdf::ModelInterfaceSharedPtr parseWithUrdfdom(const std::string& xml, std::vector<ParserMessage>& messages) {
  static std::mutex parse_mutex;
  static ParserLog* const handler = new ParserLog;
  std::lock_guard<std::mutex> lock(parse_mutex);
  const console_bridge::LogLevel level = console_bridge::getLogLevel();
  handler->sink = &messages;
  console_bridge::useOutputHandler(handler);
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);
  urdf::ModelInterfaceSharedPtr model;
  try {
    [[maybe_unused]] const IgnoreUrdfdomLeaks ignore_leaks;
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    messages.push_back({console_bridge::CONSOLE_BRIDGE_LOG_ERROR, e.what()});
  }
  console_bridge::restorePreviousOutputHandler();
  console_bridge::setLogLevel(level);
  handler->sink = nullptr;
  return model;
}

// The parser's errors (its warnings when it gave no error), joined for a message.
std::string summarise(const std::vector<ParserMessage>& messages) {
  std::string errors, warnings;
  for (const ParserMessage& m : messages) {
    std::string& out = m.level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR ? errors : warnings;
    out += (out.empty() ? "" : "; ") + m.text;
  }
  if (!errors.empty()) return errors;
  return warnings.empty() ? "no message" : warnings;
}

// ---- loops urdfdom rejects before we see the tree -----------------------------------------------

// The value of attribute `name` of the first element `tag` in xml[begin, end), or "".
std::string attributeIn(const std::string& xml, size_t begin, size_t end, const std::string& tag,
                        const std::string& name) {
  const size_t t = xml.find("<" + tag, begin);
  if (t == std::string::npos || t >= end) return "";
  const size_t close = xml.find('>', t);
  size_t a = xml.find(name, t);
  if (a == std::string::npos || a > close) return "";
  a = xml.find_first_of("\"'", a);
  if (a == std::string::npos || a > close) return "";
  const size_t b = xml.find(xml[a], a + 1);
  return b == std::string::npos ? "" : xml.substr(a + 1, b - a - 1);
}

// When urdfdom fails, a plain text scan of the <joint> elements (comments removed) for a chain
// of child -> parent links that closes on itself; "" when there is none. Used only to explain the
// failure: urdfdom reports a closed loop as "no root link".
std::string findLoopByScan(std::string xml) {
  for (size_t c; (c = xml.find("<!--")) != std::string::npos;) {
    const size_t e = xml.find("-->", c);
    xml.erase(c, e == std::string::npos ? std::string::npos : e + 3 - c);
  }
  std::map<std::string, std::string> parent_of;  // child link -> parent link
  for (size_t j = 0; (j = xml.find("<joint", j)) != std::string::npos; ++j) {
    const size_t open_end = xml.find('>', j);
    if (open_end == std::string::npos) break;
    if (!std::isspace(static_cast<unsigned char>(xml[j + 6])) && xml[j + 6] != '>') continue;  // <jointX
    if (xml[open_end - 1] == '/') continue;  // <joint .../> (e.g. inside <transmission>)
    size_t end = xml.find("</joint>", open_end);
    if (end == std::string::npos) end = xml.size();
    const std::string parent = attributeIn(xml, open_end, end, "parent", "link");
    const std::string child = attributeIn(xml, open_end, end, "child", "link");
    if (!parent.empty() && !child.empty()) parent_of.emplace(child, parent);
    j = end;
  }
  for (const auto& [start, unused] : parent_of) {
    std::vector<std::string> chain{start};
    std::set<std::string> seen{start};
    for (auto p = parent_of.find(start); p != parent_of.end(); p = parent_of.find(p->second)) {
      chain.push_back(p->second);
      if (!seen.insert(p->second).second) {  // closed: report from the repeated link on
        std::string loop;
        for (auto l = std::find(chain.begin(), chain.end(), chain.back()); l != chain.end(); ++l)
          loop += (loop.empty() ? "'" : " -> '") + *l + "'";
        return loop;
      }
    }
  }
  return "";
}

// ---- urdfdom -> builder -------------------------------------------------------------------------

Eigen::Vector3d toVector(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }

// Rotation matrix of a urdfdom quaternion (x, y, z, w).
Eigen::Matrix3d toRotation(const urdf::Rotation& r) {
  return Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
}

// A visual with its pose in the link frame (the builder moves it into the body frame).
bool toVisual(const urdf::Visual& in, Visual& out) {
  if (!in.geometry) return false;
  out.R_BG = toRotation(in.origin.rotation);
  out.p_BG = toVector(in.origin.position);
  switch (in.geometry->type) {
    case urdf::Geometry::BOX:
      out.shape = Visual::Shape::Box;
      out.size = toVector(static_cast<const urdf::Box&>(*in.geometry).dim);
      break;
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(*in.geometry);
      out.shape = Visual::Shape::Cylinder;
      out.size = {c.radius, c.length, 0};
      break;
    }
    case urdf::Geometry::SPHERE:
      out.shape = Visual::Shape::Sphere;
      out.size = {static_cast<const urdf::Sphere&>(*in.geometry).radius, 0, 0};
      break;
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(*in.geometry);
      out.shape = Visual::Shape::Mesh;
      out.mesh_file = m.filename;
      out.mesh_scale = toVector(m.scale);
      break;
    }
    default: return false;
  }
  // urdfdom resolves a material named here but defined at robot level into in.material.
  if (in.material) {
    const urdf::Color& c = in.material->color;
    out.rgba = Eigen::Vector4d(c.r, c.g, c.b, c.a);
  }
  return true;
}

constexpr double kMaxVisualSize = 1e6;  // [m]: a robot's part (and a scale factor) is far smaller; a 1e300 one draws nothing

// A shape's sizes are positive and finite (a box's three edges, a cylinder's radius and length, a
// sphere's radius; a mesh's scale finite and non-zero): a negative or NaN size draws nothing.
void checkVisualSize(const Visual& v, const std::string& link, const UrdfText& text) {
  const char* shapes[] = {"box", "cylinder", "sphere", "mesh"};
  const int used = v.shape == Visual::Shape::Box ? 3 : v.shape == Visual::Shape::Cylinder ? 2 : 1;
  const Eigen::Vector3d size = v.shape == Visual::Shape::Mesh ? v.mesh_scale : v.size;
  bool ok = true;
  for (int i = 0; i < (v.shape == Visual::Shape::Mesh ? 3 : used); ++i)
    ok = ok && std::isfinite(size[i]) && std::abs(size[i]) <= kMaxVisualSize &&
         (v.shape == Visual::Shape::Mesh ? size[i] != 0 : size[i] > 0);
  if (ok) return;
  std::ostringstream got;
  for (int i = 0; i < (v.shape == Visual::Shape::Mesh ? 3 : used); ++i) got << (i ? " " : "") << size[i];
  fail(text.where("link", link, "visual"), "link '" + link + "': visual " + shapes[static_cast<int>(v.shape)] +
                   (v.shape == Visual::Shape::Mesh ? " scale: expected non-zero factors of at most 1000 in magnitude"
                                                   : " size: expected positive lengths of at most 1e6 m") +
                   ", got '" + got.str() + "'");
}

LinkSpec toLinkSpec(const urdf::Link& link, const UrdfText& text) {
  LinkSpec spec;
  spec.name = link.name;
  if (link.inertial) {
    const urdf::Inertial& in = *link.inertial;
    // Rotational inertia about the com in the inertial frame I (urdfdom's numbers).
    Eigen::Matrix3d I_I;
    I_I << in.ixx, in.ixy, in.ixz,
           in.ixy, in.iyy, in.iyz,
           in.ixz, in.iyz, in.izz;
    // In a URDF a zero or singular inertia is an error: point masses are for the builder API. The
    // one exception is a link declared massless, mass 0 and inertia 0 (the cross of a two-axis
    // joint), which the builder accepts only where a body below it has mass.
    const bool declared_massless = in.mass == 0 && I_I.isZero(0);
    const std::string why = declared_massless ? "" : checkInertia(in.mass, I_I, /*allow_point_mass=*/false);
    if (!why.empty()) {
      const bool mass = why.rfind("mass", 0) == 0;
      const std::string element = mass ? "inertial/mass" : "inertial/inertia";
      const std::string as_written = text.written("link", link.name, element);
      fail(text.where("link", link.name, element),
           "link '" + link.name + "': " + why + (as_written.empty() ? "" : "; written " + as_written));
    }
    // Link frame L: com at the inertial origin, I_L = R_LI I_I R_LIᵀ.
    const Eigen::Matrix3d R_LI = toRotation(in.origin.rotation);
    spec.has_inertial = true;
    spec.declared_massless = declared_massless;
    spec.mass = in.mass;
    spec.com = toVector(in.origin.position);
    spec.inertia_com = R_LI * I_I * R_LI.transpose();
    spec.inertia_com = 0.5 * (spec.inertia_com + spec.inertia_com.transpose());  // exact symmetry
  }
  for (const urdf::VisualSharedPtr& v : link.visual_array) {
    Visual visual;
    if (v && toVisual(*v, visual)) {
      checkVisualSize(visual, link.name, text);
      visual.link = link.name;
      spec.visuals.push_back(std::move(visual));
    }
  }
  return spec;
}

JointSpec toJointSpec(const urdf::Joint& joint, const UrdfText& text) {
  const std::string source = text.where("joint", joint.name);
  JointSpec spec;
  spec.name = joint.name;
  switch (joint.type) {
    case urdf::Joint::REVOLUTE: spec.type = LinkJointType::Revolute; break;
    case urdf::Joint::CONTINUOUS: spec.type = LinkJointType::Continuous; break;
    case urdf::Joint::PRISMATIC: spec.type = LinkJointType::Prismatic; break;
    case urdf::Joint::FIXED: spec.type = LinkJointType::Fixed; break;
    case urdf::Joint::FLOATING:
    case urdf::Joint::PLANAR: {
      const std::string type = joint.type == urdf::Joint::FLOATING ? "floating" : "planar";
      fail(source, "joint '" + joint.name + "': joint type '" + type +
                       "' is not supported (use revolute, continuous, prismatic or fixed; a free or "
                       "planar root is chosen with the base type when building)");
    }
    default: fail(source, "joint '" + joint.name + "': unknown joint type");
  }
  spec.parent = joint.parent_link_name;
  spec.child = joint.child_link_name;
  // Joint frame J (= child link frame) in the parent link frame P.
  spec.R_PJ = toRotation(joint.parent_to_joint_origin_transform.rotation);
  spec.p_PJ = toVector(joint.parent_to_joint_origin_transform.position);
  spec.axis = toVector(joint.axis);
  // A zero axis, or one whose length underflows (1e-320 0 0), has no direction to normalise.
  if (spec.type != LinkJointType::Fixed && spec.axis.allFinite() && !(spec.axis.norm() > 0))
    fail(text.where("joint", joint.name, "axis"), "joint '" + joint.name +
                                                   "': axis must be a non-zero vector of normal length, got " +
                                                   text.written("joint", joint.name, "axis"));
  if (joint.limits) {
    spec.limits.velocity = joint.limits->velocity;
    spec.limits.effort = joint.limits->effort;
    // Maxima: a negative or non-finite one is a typo, not a limit.
    for (const auto& [name, value] : {std::pair<const char*, double>{"effort", spec.limits.effort},
                                      std::pair<const char*, double>{"velocity", spec.limits.velocity}})
      if (!(value >= 0) || !std::isfinite(value))
        fail(text.where("joint", joint.name, "limit"), "joint '" + joint.name + "': <limit " + name +
                                                            ">: expected a non-negative, finite maximum, got " +
                                                            text.written("joint", joint.name, "limit"));
    if (spec.type == LinkJointType::Revolute || spec.type == LinkJointType::Prismatic) {
      spec.limits.lower = joint.limits->lower;
      spec.limits.upper = joint.limits->upper;
    }
  }
  return spec;
}

}  // namespace


ModelBuilder readUrdfString(const std::string& xml, const std::string& source_name) {
  // Parse with urdfdom; on failure explain a closed loop ourselves, then quote the parser.
  const UrdfText text(xml, source_name);  // text, nesting, XML syntax, number ranges
  std::vector<ParserMessage> messages;
  const urdf::ModelInterfaceSharedPtr urdf_model = parseWithUrdfdom(xml, messages);
  if (!urdf_model) {
    const std::string loop = findLoopByScan(xml);
    if (!loop.empty())
      fail(source_name, "kinematic loop: links " + loop + " (child -> parent) close a circle, so "
                            "there is no root link (urdfdom: " + summarise(messages) + ")");
    std::string quoted;
    const std::string where = text.urdfdomLocation(summarise(messages), &quoted);
    fail(where, "not a valid URDF (urdfdom: " + summarise(messages) + ")" + quoted);
  }
  // urdfdom reports some bad elements (a box size of "1 nan 1") as errors and drops them,
  // returning the rest: what it could not read is refused too.
  for (const ParserMessage& m : messages)
    if (m.level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      std::string quoted;
      const std::string where = text.urdfdomLocation(summarise(messages), &quoted);
      fail(where, "not a valid URDF (urdfdom: " + summarise(messages) + ")" + quoted);
    }

  // urdfdom's links own their child links: a loop it accepts (beside the tree) would leak, so
  // drop that ownership once converted, also when conversion throws.
  struct ReleaseLinks {
    const urdf::ModelInterface& model;
    ~ReleaseLinks() {
      for (const auto& [name, link] : model.links_) link->child_links.clear();
    }
  } release{*urdf_model};

  // Links (with inertials and visuals) and joints, each checked as it is converted.
  ModelBuilder builder(urdf_model->getName());
  builder.setSource(source_name);
  builder.requireInertials(true);  // a moving URDF link without <inertial> is an error
  for (const auto& [name, link] : urdf_model->links_) builder.addLink(toLinkSpec(*link, text));
  for (const auto& [name, joint] : urdf_model->joints_) builder.addJoint(toJointSpec(*joint, text));
  return builder;
}

ModelBuilder readUrdfFile(const std::string& path) {
  // Read the whole file; a missing, unreadable or non-regular file is reported with errno's reason.
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (std::filesystem::is_directory(status)) fail(path, "is a folder; expected a URDF file");
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    fail(path, "is not a regular file (a device, a pipe); expected a URDF file");
  if (std::filesystem::exists(status) && std::filesystem::file_size(path, error) > kMaxUrdfBytes)
    fail(path, std::to_string(std::filesystem::file_size(path, error)) + " bytes; expected a URDF of at most " +
                   std::to_string(kMaxUrdfBytes) + " bytes");
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) fail(path, std::string("cannot open the file: ") + std::strerror(errno));
  std::string xml;
  char buffer[1 << 16];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, file)) > 0) xml.append(buffer, n);
  const bool read_error = std::ferror(file);
  const int read_errno = errno;
  std::fclose(file);
  if (read_error) fail(path, std::string("cannot read the file: ") + std::strerror(read_errno));
  return readUrdfString(xml, path);
}

Model<double> loadUrdfFile(const std::string& path, BaseType base) { return readUrdfFile(path).build(base); }

Model<double> loadUrdfString(const std::string& xml, BaseType base, const std::string& source_name) {
  return readUrdfString(xml, source_name).build(base);
}

BaseType parseBaseType(const std::string& s) {
  if (s == "fixed") return BaseType::Fixed;
  if (s == "planar") return BaseType::Planar;
  if (s == "free") return BaseType::Free;
  if (s == "free_quaternion") return BaseType::FreeQuaternion;
  throw std::invalid_argument("unknown base type '" + s + "' (expected fixed, planar, free or free_quaternion)");
}

}  // namespace saltus::dynamics
