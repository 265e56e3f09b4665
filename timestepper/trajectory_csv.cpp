#include "timestepper/trajectory_csv.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <unistd.h>

namespace saltus::timestepper {

TrajectoryCsvWriter::TrajectoryCsvWriter(const std::string& path, const Scene& scene)
    : path_(path), tmp_path_(path + ".tmp-" + std::to_string(::getpid())) {
  file_ = std::fopen(tmp_path_.c_str(), "w");
  if (!file_) throw std::runtime_error(path + ": cannot write (" + std::strerror(errno) + ")");
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
  std::fprintf(file_, "%s\n", header.c_str());
}

TrajectoryCsvWriter::~TrajectoryCsvWriter() {
  if (file_) std::fclose(file_);
  if (!committed_) std::remove(tmp_path_.c_str());
}

void TrajectoryCsvWriter::writeRow(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                   const std::vector<ContactReport>& contacts) {
  std::fprintf(file_, "%.10g", t);
  for (int i = 0; i < q.size(); ++i) std::fprintf(file_, ",%.12g", q[i]);
  for (int i = 0; i < v.size(); ++i) std::fprintf(file_, ",%.12g", v[i]);
  for (size_t c = 0; c < contacts.size(); ++c) {
    const ContactReport& r = contacts[c];
    if (spatial_[c])
      std::fprintf(file_, ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g", r.gap, r.vn, r.vt1, r.vt2, r.pn, r.pt1, r.pt2);
    else
      std::fprintf(file_, ",%.12g,%.12g,%.12g,%.12g,%.12g", r.gap, r.vn, r.vt1, r.pn, r.pt1);
  }
  std::fputc('\n', file_);
}

void TrajectoryCsvWriter::commit() {
  const bool write_failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (write_failed || close_failed) throw std::runtime_error(path_ + ": writing failed (" + std::strerror(errno) + ")");
  if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0)
    throw std::runtime_error(path_ + ": cannot rename the finished file into place (" + std::strerror(errno) + ")");
  committed_ = true;
}

}  // namespace saltus::timestepper
