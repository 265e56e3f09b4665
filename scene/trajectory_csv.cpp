#include "scene/trajectory_csv.hpp"

#include <stdexcept>

namespace saltus::scene {

TrajectoryLayout trajectoryLayout(const Scene& scene) {
  TrajectoryLayout layout;
  layout.coordinates = scene.model.coordinate_name;
  for (const Contact& c : scene.contacts) layout.contacts.push_back({c.name, c.directions > 2});
  for (const LimitStop& l : scene.limits) layout.contacts.push_back({l.name, false});
  return layout;
}

TrajectoryCsvWriter::TrajectoryCsvWriter(const std::string& path, TrajectoryLayout layout)
    : file_(path), layout_(std::move(layout)) {
  std::string header = "t";
  for (const std::string& c : layout_.coordinates) header += ",q." + c;
  for (const std::string& c : layout_.coordinates) header += ",v." + c;
  for (const std::string& c : layout_.inputs) header += ",u." + c;
  for (const TrajectoryLayout::ContactColumns& c : layout_.contacts) {
    const std::string p = ",contact." + c.name + ".";
    auto tangential = [&](const std::string& name) { return c.spatial ? p + name + "1" + p + name + "2" : p + name; };
    header += p + "gap" + p + "vn" + tangential("vt");
    if (layout_.forces) header += p + "rn" + tangential("rt");
    header += p + "pn" + tangential("pt");
  }
  std::fprintf(file_.stream(), "%s\n", header.c_str());
}

void TrajectoryCsvWriter::beginRow(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                   const Eigen::VectorXd& u) {
  const std::size_t n = layout_.coordinates.size();
  if (static_cast<std::size_t>(q.size()) != n || static_cast<std::size_t>(v.size()) != n ||
      static_cast<std::size_t>(u.size()) != layout_.inputs.size())
    throw std::invalid_argument(file_.path() + ": a trajectory row of the wrong size");
  std::FILE* const f = file_.stream();
  std::fprintf(f, "%.12g", t);
  for (int i = 0; i < q.size(); ++i) std::fprintf(f, ",%.12g", q[i]);
  for (int i = 0; i < v.size(); ++i) std::fprintf(f, ",%.12g", v[i]);
  for (int i = 0; i < u.size(); ++i) std::fprintf(f, ",%.12g", u[i]);
  next_contact_ = 0;
}

void TrajectoryCsvWriter::contact(const ContactRow& c) {
  if (next_contact_ >= layout_.contacts.size())
    throw std::invalid_argument(file_.path() + ": more contacts in a trajectory row than in its header");
  const bool spatial = layout_.contacts[next_contact_++].spatial;
  std::FILE* const f = file_.stream();
  auto tangential = [&](const Eigen::Vector2d& x) {
    std::fprintf(f, ",%.12g", x[0]);
    if (spatial) std::fprintf(f, ",%.12g", x[1]);
  };
  std::fprintf(f, ",%.12g,%.12g", c.gap, c.vn);
  tangential(c.vt);
  if (layout_.forces) {
    std::fprintf(f, ",%.12g", c.rn);
    tangential(c.rt);
  }
  std::fprintf(f, ",%.12g", c.pn);
  tangential(c.pt);
}

void TrajectoryCsvWriter::endRow() {
  if (next_contact_ != layout_.contacts.size())
    throw std::invalid_argument(file_.path() + ": fewer contacts in a trajectory row than in its header");
  std::fputc('\n', file_.stream());
}

}  // namespace saltus::scene
