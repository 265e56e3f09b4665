#include "saltus/collocation_source.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace saltus {

CollocationSource::CollocationSource(collocation::SavedSolution solution)
    : solution_(std::move(solution)), trajectory_(solution_.trajectory()) {
  using collocation::Method;
  const collocation::Transcription& t = *solution_.transcription;
  for (const contact::ContactPair& c : t.contacts()) scene_contacts_ += c.isStop() ? 0 : 1;
  // The transcription's contacts are the scene's contact pairs: its contacts in order, then the
  // limit stops (contact::contactPairs), so contact c < scene_contacts_ is scene contact c.
  const std::vector<collocation::Sample> samples = collocation::trajectory(t, solution_.x);
  std::map<std::pair<int, int>, const collocation::Sample*> at;  // (element, point) -> sample
  for (const collocation::Sample& s : samples) at[{s.element, s.point}] = &s;

  auto load = [](const collocation::ContactSample& cs, bool impulse) {
    render::ContactLoad l;
    l.normal = impulse ? cs.pn : cs.rn;
    l.tangent = impulse ? cs.pt : cs.rt;
    return l;
  };
  element_forces_.resize(t.elements());
  for (int n = 0; n < t.elements(); ++n) {
    for (int p : t.layout()[n].collocation) {
      const auto it = at.find({n, p});
      std::vector<render::ContactLoad> loads(scene_contacts_);
      if (it != at.end())
        for (int c = 0; c < scene_contacts_; ++c) loads[c] = load(it->second->contacts[c], false);
      element_forces_[n].push_back(std::move(loads));
    }
  }

  if (t.method() == Method::Impulsive) {
    double largest = 0;
    for (const collocation::Sample& s : samples)
      if (s.point == 0 && s.element > 0)
        for (int c = 0; c < scene_contacts_; ++c) largest = std::max(largest, load(s.contacts[c], true).magnitude());
    const double threshold = std::max(1e-6, 1e-3 * largest);
    for (const collocation::Sample& s : samples) {
      if (s.point != 0 || s.element == 0) continue;
      for (int c = 0; c < scene_contacts_; ++c) {
        const render::ContactLoad p = load(s.contacts[c], true);
        if (p.magnitude() > threshold) impulses_.push_back({trajectory_.meshTimes()[s.element], c, p});
      }
    }
    std::stable_sort(impulses_.begin(), impulses_.end(),
                     [](const render::Impulse& a, const render::Impulse& b) { return a.t < b.t; });
  }
}

CollocationSource CollocationSource::load(const std::string& path) {
  return CollocationSource(collocation::loadSolution(path));
}

Eigen::VectorXd CollocationSource::q(double t) const {
  return trajectory_.at(std::clamp(t, 0.0, trajectory_.endTime())).q;
}

std::vector<render::ContactLoad> CollocationSource::contactForces(double t) const {
  t = std::clamp(t, 0.0, trajectory_.endTime());
  const int n = trajectory_.elementAt(t);
  const std::vector<std::vector<render::ContactLoad>>& points = element_forces_[n];
  std::vector<render::ContactLoad> out(scene_contacts_);
  if (points.empty()) return out;
  if (points.size() == 1) return points[0];  // first order: the step's value, held
  const std::vector<double>& mesh = trajectory_.meshTimes();
  const double h = mesh[n + 1] - mesh[n];
  const double s = h > 0 ? std::clamp((t - mesh[n]) / h, 0.0, 1.0) : 0.0;
  // Lagrange basis through the collocation points (the roots of the Legendre–Gauss rule).
  const Eigen::VectorXd l = solution_.transcription->lg().basis(s);
  for (std::size_t j = 0; j < points.size(); ++j)
    for (int c = 0; c < scene_contacts_; ++c) {
      out[c].normal += l[j] * points[j][c].normal;
      out[c].tangent += l[j] * points[j][c].tangent;
    }
  return out;
}

}  // namespace saltus
