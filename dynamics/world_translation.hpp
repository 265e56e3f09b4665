// World translations: the coordinates that translate their joint's whole subtree along an axis
// fixed in the world, a translation whose every ancestor coordinate is one too (a base's x, y, z;
// a prismatic joint hung from the world, as a planar part's x and z). Moving such a coordinate
// moves every body of the subtree by the same vector and turns none, so M(q), C(q, q̇) q̇ and g(q)
// depend neither on it nor on its rate (the velocities are in world axes; in Lagrange's equations
// the terms in its rate are the rate times ∂²c/∂q_i∂q_j − ∂²c/∂q_j∂q_i for the subtree's centre of
// mass c, which is zero). Neither do the points' relative Jacobians, the planes' normals nor any
// relative velocity, and a gap is affine in these coordinates: the collocation's Hessians and
// Jacobians leave them out (contact::ContactPair::jacobian_with, collocation/equation_of_motion.hpp,
// collocation/functions.hpp).
#pragma once

#include "dynamics/model.hpp"

namespace saltus::dynamics {

// Whether velocity coordinate k is a world translation.
template <class S>
bool isWorldTranslation(const Model<S>& model, int k) {
  for (; k >= 0; k = model.parent_coordinate[k])
    if (!model.isTranslation(k)) return false;
  return true;
}

}  // namespace saltus::dynamics
