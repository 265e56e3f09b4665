#include "contact/initial_state.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "contact/kinematics.hpp"
#include "contact/pair.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::contact {

std::vector<Penetration> penetrations(const scene::Scene& scene, const Eigen::VectorXd& q, double tolerance) {
  const dynamics::Model<double>& model = scene.model;
  dynamics::Data<double> data(model);
  dynamics::forwardKinematics(model, data, q);
  std::vector<Penetration> found;
  for (const ContactPair& pair : contactPairs(scene)) {
    const double g = gap(pair, data, q.data());
    if (!(g < -tolerance) || !withinExtent(pair, data)) continue;
    Penetration p;
    p.name = pair.name;
    p.depth = -g;
    if (pair.isStop()) {
      p.unit = model.isTranslation(pair.coordinate) ? "m" : "rad";
      std::ostringstream s;
      s << "beyond its " << (pair.sign > 0 ? "lower" : "upper") << " limit " << pair.limit << " " << p.unit
        << " on coordinate '" << model.coordinate_name[static_cast<std::size_t>(pair.coordinate)] << "'";
      p.against = s.str();
    } else {
      p.unit = "m";
      p.against = pair.surface >= 0 ? "inside surface '" + scene.surfaces[static_cast<std::size_t>(pair.surface)].name + "'"
                                    : "inside the plane of body " + std::to_string(pair.body_b);
      for (const scene::Contact& c : scene.contacts)
        if (c.name == pair.name && c.surface < 0) p.against = "inside the plane on link '" + c.plane.link + "'";
    }
    found.push_back(p);
  }
  // deepest first, ties by name (std::sort: no temporary buffer, which the heap-counting tests'
  // operator new does not cover)
  std::sort(found.begin(), found.end(), [](const Penetration& a, const Penetration& b) {
    return a.depth != b.depth ? a.depth > b.depth : a.name < b.name;
  });
  return found;
}

void checkInitialState(const scene::Scene& scene, const std::string& where) {
  const std::vector<Penetration> found = penetrations(scene, scene.q0, kInitialPenetrationTolerance);
  if (found.empty()) return;
  std::ostringstream s;
  s << where << ": ";
  for (std::size_t i = 0; i < found.size(); ++i) {
    const Penetration& p = found[i];
    s << (i == 0 ? "" : "; ") << (p.against.rfind("beyond", 0) == 0 ? "stop '" : "contact '") << p.name << "' starts "
      << p.depth << " " << p.unit << " " << p.against;
  }
  s << " (expected at most " << kInitialPenetrationTolerance << " m or rad; move the initial state out)";
  throw std::invalid_argument(s.str());
}

}  // namespace saltus::contact
