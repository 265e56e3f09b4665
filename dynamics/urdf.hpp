// Reading URDF files (through urdfdom) into a ModelBuilder, and from there into a Model.
//
// What is kept: links with their inertial data (the inertial frame may be rotated), joints of
// type revolute, continuous, prismatic and fixed (fixed joints are merged by the builder, the
// merged link stays a Frame), joint limits (position, velocity, effort; continuous joints have
// no position limits) and visuals (box, cylinder, sphere, mesh with origin, scale and the rgba of
// their material, named materials defined at robot level included). Collision elements, joint
// dynamics, safety controllers and calibration are ignored; a mimic joint is read as an
// independent coordinate. Mesh file names are kept as written (package:// URIs unresolved).
//
// Coordinates are numbered depth first with the children of a link in urdfdom's order (by joint
// name), the order Pinocchio uses for the same file.
//
// Every error is a ModelError whose message starts with the file path (or the source name given
// for a string) and names the element, e.g.
//   models/x.urdf: link 'forearm': inertia is not positive definite (principal moments ...)
// URDF inertias must be positive definite: point masses exist only in the builder API.
// Messages urdfdom prints through console_bridge are captured while it parses (the previous
// output handler is restored afterwards) and quoted in the error; nothing is printed.
#pragma once

#include <string>

#include "dynamics/builder.hpp"

namespace saltus::dynamics {

// Reads a URDF file into a builder whose error messages start with the path. Errors found in the
// file itself (XML, inertias, joint types) are thrown here; the tree's topology, axes, limit order
// and missing inertials are checked by ModelBuilder::build.
ModelBuilder readUrdfFile(const std::string& path);
ModelBuilder readUrdfString(const std::string& xml, const std::string& source_name = "<string>");

// Convenience: read + build.
Model<double> loadUrdfFile(const std::string& path, BaseType base = BaseType::Fixed);
Model<double> loadUrdfString(const std::string& xml, BaseType base = BaseType::Fixed,
                             const std::string& source_name = "<string>");

// "fixed" | "planar" | "free" | "free_quaternion"; anything else throws std::invalid_argument naming the accepted values.
BaseType parseBaseType(const std::string& s);

}  // namespace saltus::dynamics
