#include "timestepper/trajectory_csv.hpp"

namespace saltus::timestepper {

TrajectoryCsvWriter::TrajectoryCsvWriter(const std::string& path, const Scene& scene)
    : file_(path) {
  std::string header = "t";
  for (const std::string& c : scene.model.coordinate_name) header += ",q." + c;
  for (const std::string& c : scene.model.coordinate_name) header += ",v." + c;
  auto group = [&](const std::string& name, bool spatial) {
    const std::string p = ",contact." + name + ".";
    header += p + "gap" + p + "vn";
    header += spatial ? p + "vt1" + p + "vt2" : p + "vt";
    header += p + "pn";
    header += spatial ? p + "pt1" + p + "pt2" : p + "pt";
    spatial_.push_back(spatial);
  };
  for (const Contact& c : scene.contacts) group(c.name, c.directions > 2);
  for (const LimitStop& l : scene.limits) group(l.name, false);
  std::fprintf(file_.stream(), "%s\n", header.c_str());
}

void TrajectoryCsvWriter::writeRow(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                   const std::vector<ContactReport>& contacts) {
  std::FILE* const file = file_.stream();
  std::fprintf(file, "%.10g", t);
  for (int i = 0; i < q.size(); ++i) std::fprintf(file, ",%.12g", q[i]);
  for (int i = 0; i < v.size(); ++i) std::fprintf(file, ",%.12g", v[i]);
  for (size_t c = 0; c < contacts.size(); ++c) {
    const ContactReport& r = contacts[c];
    if (spatial_[c])
      std::fprintf(file, ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g", r.gap, r.vn, r.vt1, r.vt2, r.pn, r.pt1, r.pt2);
    else
      std::fprintf(file, ",%.12g,%.12g,%.12g,%.12g,%.12g", r.gap, r.vn, r.vt1, r.pn, r.pt1);
  }
  std::fputc('\n', file);
}

}  // namespace saltus::timestepper
