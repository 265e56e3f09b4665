#include "verify/measured_contact.hpp"

#include <algorithm>

#include "contact/kinematics.hpp"

namespace saltus::verify {

double measureContactKinematics(const scene::Scene& scene, const std::vector<contact::ContactPair>& pairs,
                                const dynamics::Data<double>& data, const double* q, double t,
                                std::vector<MeasuredContact>& reports) {
  double largest = 0;
  for (std::size_t c = 0; c < scene.contacts.size(); ++c) {
    const contact::ContactPair& pair = pairs[c];
    const Eigen::Vector3d surface_velocity =
        pair.body_b < 0 ? scene.surfaces[pair.surface].velocity(t) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d v_frame = contact::frameVelocity(pair, data, surface_velocity);
    MeasuredContact& r = reports[c];
    r.gap = contact::gap(pair, data, q);
    r.vn = v_frame[0];
    r.vt1 = v_frame[1];
    r.vt2 = v_frame[2];
    r.active = false;
    r.pn = r.pt1 = r.pt2 = 0;
    if (contact::withinExtent(pair, data)) largest = std::max(largest, -r.gap);
  }
  return largest;
}

}  // namespace saltus::verify
