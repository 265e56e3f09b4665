#include "scene/trajectory_csv.hpp"

#include "scene/scenario.hpp"  // kMaxPosition

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <unordered_map>

namespace saltus::scene {

TrajectoryLayout trajectoryLayout(const Scene& scene) {
  TrajectoryLayout layout;
  layout.coordinates = scene.model.coordinate_name;
  layout.positions = scene.model.position_name;
  for (const Contact& c : scene.contacts) {
    const bool spatial = c.directions > 2;
    const int axes = c.surface >= 0 ? 0 : !c.free_axes.empty() ? static_cast<int>(c.free_axes.size()) : spatial ? 2 : 1;
    layout.contacts.push_back({c.name, spatial, axes});
  }
  for (const LimitStop& l : scene.limits) layout.contacts.push_back({l.name, false});
  return layout;
}

std::vector<std::string> trajectoryHeader(const TrajectoryLayout& layout) {
  std::vector<std::string> names = {"t"};
  for (const std::string& c : layout.positions.empty() ? layout.coordinates : layout.positions) names.push_back("q." + c);
  for (const std::string& c : layout.coordinates) names.push_back("v." + c);
  for (const std::string& c : layout.inputs) names.push_back("u." + c);
  for (const TrajectoryLayout::ContactColumns& c : layout.contacts) {
    const std::string p = "contact." + c.name + ".";
    auto tangential = [&](const std::string& name) {
      if (c.spatial) {
        names.push_back(p + name + "1");
        names.push_back(p + name + "2");
      } else {
        names.push_back(p + name);
      }
    };
    names.push_back(p + "gap");
    names.push_back(p + "vn");
    tangential("vt");
    if (layout.forces) {
      names.push_back(p + "rn");
      tangential("rt");
    }
    names.push_back(p + "pn");
    tangential("pt");
    if (c.plane_axes == 1) names.push_back(p + "s");
    if (c.plane_axes == 2) {
      names.push_back(p + "s1");
      names.push_back(p + "s2");
    }
  }
  return names;
}

TrajectoryCsvWriter::TrajectoryCsvWriter(const std::string& path, TrajectoryLayout layout)
    : file_(path), layout_(std::move(layout)) {
  std::string header;
  for (const std::string& name : trajectoryHeader(layout_)) header += (header.empty() ? "" : ",") + name;
  std::fprintf(file_.stream(), "%s\n", header.c_str());
}

void TrajectoryCsvWriter::beginRow(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                   const Eigen::VectorXd& u) {
  const std::size_t n = layout_.coordinates.size();
  const std::size_t nq = layout_.positions.empty() ? n : layout_.positions.size();
  if (static_cast<std::size_t>(q.size()) != nq || static_cast<std::size_t>(v.size()) != n ||
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
  const TrajectoryLayout::ContactColumns& columns = layout_.contacts[next_contact_++];
  const bool spatial = columns.spatial;
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
  for (int i = 0; i < columns.plane_axes; ++i) std::fprintf(f, ",%.12g", c.s[i]);
}

void TrajectoryCsvWriter::endRow() {
  if (next_contact_ != layout_.contacts.size())
    throw std::invalid_argument(file_.path() + ": fewer contacts in a trajectory row than in its header");
  std::fputc('\n', file_.stream());
}

int TrajectoryTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return static_cast<int>(i);
  return -1;
}

std::vector<double> TrajectoryTable::values(const std::string& name) const {
  const int c = column(name);
  if (c < 0) throw std::out_of_range(path_ + ": no column '" + name + "'");
  std::vector<double> out(rows());
  for (std::size_t r = 0; r < out.size(); ++r) out[r] = at(r, c);
  return out;
}

namespace {

// The fields of a CSV line (no quoting: trajectory names hold no commas), without a trailing \r.
std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (!out.empty() && !out.back().empty() && out.back().back() == '\r') out.back().pop_back();
  return out;
}

}  // namespace

TrajectoryTable readTrajectoryCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read trajectory (" + std::strerror(errno) + ")");
  TrajectoryTable table;
  table.path_ = path;
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty file, expected a CSV header starting with 't'");
  table.names_ = splitFields(line);
  const std::vector<std::string>& header = table.names_;
  if (header[0] != "t")
    throw std::runtime_error(path + ":1: expected the first column to be 't', got '" + header[0] + "'");
  std::unordered_map<std::string, std::size_t> seen;
  for (std::size_t i = 0; i < header.size(); ++i)
    if (!seen.emplace(header[i], i).second)
      throw std::runtime_error(path + ":1: column '" + header[i] + "' appears twice (columns " +
                               std::to_string(seen[header[i]] + 1) + " and " + std::to_string(i + 1) + ")");

  double t_previous = -INFINITY;
  for (int line_no = 2; std::getline(in, line); ++line_no) {
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> fields = splitFields(line);
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    if (line.find('\0') != std::string::npos)
      throw std::runtime_error(where + "column '" + header[std::min(fields.size(), header.size()) - 1] +
                               "' holds a NUL byte (binary content); expected text numbers");
    if (fields.size() != header.size())
      throw std::runtime_error(where + std::to_string(fields.size()) + " fields, the header has " +
                               std::to_string(header.size()));
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const char* s = fields[i].c_str();
      char* end = nullptr;
      const double x = std::strtod(s, &end);
      if (end == s || *end != '\0' || !std::isfinite(x))
        throw std::runtime_error(where + "column '" + header[i] + "': expected a finite number, got '" + fields[i] + "'");
      // Plausible sizes: a time of 1e308 s, or a coordinate of 1e308 m, is finite but draws and
      // frames nothing (the frame count, the camera's distance overflow).
      const bool time = i == 0, coordinate = header[i].rfind("q.", 0) == 0;
      if ((time && std::abs(x) > kMaxTrajectoryTime) || (coordinate && std::abs(x) > kMaxPosition))
        throw std::runtime_error(where + "column '" + header[i] + "': " + fields[i] + " is beyond the bound of " +
                                 (time ? "1e9 s on times" : "1e6 m or rad on coordinates") +
                                 " (scene/trajectory_csv.hpp); expected a trajectory of a robot");
      table.cells_.push_back(x);
    }
    const double t = table.cells_[table.cells_.size() - header.size()];
    if (t < t_previous)
      throw std::runtime_error(where + "t = " + fields[0] + " is before the previous row's; times must not decrease");
    t_previous = t;
  }
  return table;
}

}  // namespace saltus::scene
