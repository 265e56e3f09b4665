// The transcription's starting points (transcription.hpp): the paper's null seed, its random
// perturbation (§V.C), and the auxiliaries (gaps, free points' offsets, restitution splits, slip
// bounds, penalty variables) made consistent with the positions and velocities.
#include "collocation/transcription.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace saltus::collocation {

void Transcription::makeConsistent(Eigen::VectorXd& x) const {
  auto& data = models_->data<double>();
  for (const auto& L : layout_)
    for (std::size_t p = 0; p < L.points.size(); ++p) {
      dynamics::forwardKinematics(models_->model<double>(), data, x.segment(L.points[p].q, nv_));
      for (std::size_t c = 0; c < contacts_.size(); ++c) {
        const ContactPair& cp = contacts_[c];
        const auto& C = L.contacts[c];
        if (C.y[p] >= 0) x[C.y[p]] = std::max(0.0, contact::gap(cp, data, x.data() + L.points[p].q));
        // A free point at A's projection, clamped to the rectangle; d± the rest (FreePointOffset).
        if (C.s[p] < 0) continue;
        const Eigen::Vector2d s_A = contact::planeCoordinates(cp, data);
        for (int i = 0; i < cp.freeAxes(); ++i) {
          const int axis = cp.free_axes[i];
          const double s = std::clamp(s_A[axis], -cp.extent[axis], cp.extent[axis]);
          x[C.s[p] + i] = s;
          x[C.d_plus[p] + i] = std::max(0.0, s_A[axis] - s);
          x[C.d_minus[p] + i] = std::max(0.0, s - s_A[axis]);
        }
      }
    }
  x = x.cwiseMax(x_lower_hint_).cwiseMin(x_upper_hint_);
  // a⁺ − a⁻ = ẏ[n, 0] + e ẏ[n − 1, P + 1] (9a) with a⁺ a⁻ = 0: the balance is linear in the pair.
  Eigen::VectorXd local;
  double residual[2];
  for (const auto& L : layout_)
    for (const auto& C : L.contacts) {
      if (C.restitution_block < 0) continue;
      const Block& blk = blocks_[C.restitution_block];
      local.resize(blk.vars.size());
      for (std::size_t j = 0; j < blk.vars.size(); ++j) local[j] = x[blk.vars[j]];
      const int ip = static_cast<int>(blk.vars.size()) - 2, im = ip + 1;  // a⁺, a⁻ are its last inputs
      local[ip] = local[im] = 0;
      blk.f->value(local.data(), &residual[0]);
      local[ip] = 1;
      blk.f->value(local.data(), &residual[1]);
      const double difference = -residual[0] / (residual[1] - residual[0]);
      x[C.a_plus] = std::max(0.0, difference);
      x[C.a_minus] = std::max(0.0, -difference);
    }
  // γ at the largest slip projection and ψ_i = γ − d_iᵀ v_t (12): the slip block is
  // ψ_i − γ ± d_iᵀ v_t with γ and ψ its last 1 + k inputs.
  std::vector<double> projection;
  for (const auto& L : layout_)
    for (std::size_t c = 0; c < L.contacts.size(); ++c) {
      const auto& C = L.contacts[c];
      const int k = contacts_[c].k();
      for (std::size_t p = 0; p < C.slip_block.size(); ++p) {
        if (C.slip_block[p] < 0) continue;
        const Block& blk = blocks_[C.slip_block[p]];
        local.resize(blk.vars.size());
        for (std::size_t j = 0; j < blk.vars.size(); ++j) local[j] = x[blk.vars[j]];
        const int first = static_cast<int>(blk.vars.size()) - 1 - k;  // γ
        local.segment(first, 1 + k).setZero();
        projection.resize(k);
        blk.f->value(local.data(), projection.data());
        const double gamma = std::max(0.0, *std::max_element(projection.begin(), projection.end()));
        x[C.gamma[p]] = gamma;
        for (int i = 0; i < k; ++i) x[C.psi[p] + i] = gamma - projection[i];
      }
    }
  setPenaltyToProducts(x);  // eq. 8: A·B ≤ ε holds at the start
}

void Transcription::setPenaltyToProducts(Eigen::VectorXd& x) const {
  Eigen::VectorXd local;
  for (std::size_t i = 0; i < product_blocks_.size(); ++i) {
    const Block& blk = blocks_[product_blocks_[i]];
    local.resize(blk.vars.size());
    for (std::size_t j = 0; j < blk.vars.size(); ++j) local[j] = x[blk.vars[j]];
    x[epsilon_[i]] = std::max(0.0, static_cast<const ComplementarityProduct&>(*blk.f).product(local.data()));
  }
}

Eigen::VectorXd Transcription::nullSeed() const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(variables());
  for (const auto& L : layout_) {
    x[L.h] = 0.5 * (x_lower_[L.h] + x_upper_[L.h]);
  }
  makeConsistent(x);
  return x;
}

Eigen::VectorXd Transcription::perturb(const Eigen::VectorXd& x0, double scale, unsigned seed) const {
  Eigen::VectorXd x = x0;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, scale);
  for (const auto& L : layout_) {
    for (const auto& pt : L.points)
      for (int i = 0; i < nv_; ++i) x[pt.q + i] += U(rng);
    for (const auto& C : L.contacts)
      for (int r : C.rn)
        if (r >= 0) x[r] += U(rng);
  }
  makeConsistent(x);
  return x;
}

void Transcription::tightenMaxVariable(Eigen::VectorXd& x) const {
  if (x_max_ < 0) return;
  const int i = problem_.cost.max_coordinate;
  double largest = -std::numeric_limits<double>::infinity();
  for (const ElementLayout& L : layout_)
    for (const auto& point : L.points) largest = std::max(largest, x[point.q + i]);
  x[x_max_] = largest;
}

}  // namespace saltus::collocation
