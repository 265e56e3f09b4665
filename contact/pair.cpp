#include "contact/pair.hpp"

#include "dynamics/world_translation.hpp"

namespace saltus::contact {
namespace {

// Marks the coordinates of body b's joint and of every joint between it and the world.
void markPath(const dynamics::Model<double>& model, int b, std::vector<bool>& marks) {
  for (; b >= 0; b = model.parent[b])
    for (int k = 0; k < model.num_coordinates[b]; ++k) marks[model.first_coordinate[b] + k] = true;
}

}  // namespace

std::vector<ContactPair> contactPairs(const scene::Scene& scene) {
  std::vector<ContactPair> pairs;
  pairs.reserve(scene.contacts.size() + scene.limits.size());
  for (const scene::Contact& c : scene.contacts) {
    ContactPair p;
    p.name = c.name;
    p.kind = PairKind::PointOnPlane;
    p.body_a = c.body;
    p.point_A = c.p_B;
    if (c.surface >= 0) {
      const scene::Surface& surface = scene.surfaces.at(static_cast<std::size_t>(c.surface));
      p.body_b = -1;
      p.plane_point_B = surface.point;
      p.normal_B = surface.normal;
      p.tangents_B = surface.tangents();
      p.surface = c.surface;
    } else {
      p.body_b = c.plane.body;
      p.plane_point_B = c.plane.point;
      p.normal_B = c.plane.normal;
      p.tangents_B = c.plane.tangents;
      p.extent = c.plane.extent;
      p.free_axes = c.free_axes;
      p.surface = -1;
    }
    p.directions_B = c.friction > 0 ? scene::coneDirections(p.tangents_B, c.directions) : Eigen::Matrix3Xd(3, 0);
    p.restitution = c.restitution;
    p.friction = c.friction;
    std::vector<bool> path_a(scene.model.nv(), false), path_b(scene.model.nv(), false);
    markPath(scene.model, p.body_a, path_a);
    markPath(scene.model, p.body_b, path_b);
    p.moves_with.assign(scene.model.nv(), false);
    p.jacobian_with.assign(scene.model.nv(), false);
    for (int k = 0; k < scene.model.nv(); ++k) {
      p.moves_with[k] = path_a[k] || path_b[k];
      const bool shifts_both = p.body_b < 0 || (path_a[k] && path_b[k]);  // A against a world plane
      p.jacobian_with[k] = p.moves_with[k] && !(dynamics::isWorldTranslation(scene.model, k) && shifts_both);
    }
    p.reaction_jacobian_with = p.jacobian_with;
    if (p.freePoint())
      for (int k = 0; k < scene.model.nv(); ++k)
        p.reaction_jacobian_with[k] = p.moves_with[k] && !dynamics::isWorldTranslation(scene.model, k);
    pairs.push_back(std::move(p));
  }
  for (const scene::LimitStop& l : scene.limits) {
    ContactPair p;
    p.name = l.name;
    p.kind = PairKind::JointStop;
    p.coordinate = l.coordinate;
    p.position = scene.model.positionOf(l.coordinate);
    p.sign = l.upper ? -1.0 : 1.0;
    p.limit = l.limit;
    p.directions_B = Eigen::Matrix3Xd(3, 0);
    p.restitution = l.restitution;
    p.moves_with.assign(scene.model.nv(), false);
    p.moves_with[l.coordinate] = true;
    p.jacobian_with.assign(scene.model.nv(), false);
    p.reaction_jacobian_with = p.jacobian_with;
    pairs.push_back(std::move(p));
  }
  return pairs;
}

}  // namespace saltus::contact
