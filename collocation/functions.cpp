// The AD of the transcription's local functions (functions.hpp), instantiated here alone, with the
// Jacobian columns the functors form themselves (the jacobianColumns; the equations of motion's
// are in equation_of_motion.cpp). Built with the default inlining limits: collocation/CMakeLists.txt
// says why.
#include "collocation/functions.hpp"

#include <algorithm>

namespace saltus::collocation {

void RestitutionBalance::jacobianColumns(const double* x, double* J) const {
  const int n = models->model<double>().nv();
  const auto& model = models->model<double>();
  auto& data = models->data<double>();
  for (int i = 0; i < inputs(); ++i)
    if (!columnByAd(i)) J[i] = 0.0;  // one output: column i is J[i]
  for (int side = 0; side < sides(); ++side) {
    const double* q = x + 2 * side * n;
    dynamics::forwardKinematics(model, data, ConstMap<double>(q, n));
    // ∂ẏ/∂q̇ = nᵀ J_c (contact::normalVelocity), with −1 after the jump and −e before it.
    const Vec3<double> normal = (side == 0 ? -1.0 : -contact->restitution) * contact::planeNormal(*contact, data);
    contact::forEachJacobianColumn(model, data, *contact,
                                   [&](int k, const Vec3<double>& c) { J[(2 * side + 1) * n + k] += normal.dot(c); });
  }
  J[2 * sides() * n] = 1.0;
  J[2 * sides() * n + 1] = -1.0;
}

void SlipSlack::jacobianColumns(const double* x, double* J) const {
  const int n = models->model<double>().nv(), m = contact->freeAxes(), k = contact->k();
  const auto& model = models->model<double>();
  auto& data = models->data<double>();
  for (int i = 0; i < inputs(); ++i)
    if (!columnByAd(i)) std::fill(J + i * k, J + (i + 1) * k, 0.0);
  dynamics::forwardKinematics(model, data, ConstMap<double>(x, n));
  // ∂ψ_i/∂q̇ = ∓d_iᵀ J_c: the relative Jacobian of the slip (at the plane coordinates s for a free point).
  const double sign = friction == FrictionForm::Activation ? 1.0 : -1.0;
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxCoordinates> d(3, k);
  for (int i = 0; i < k; ++i) d.col(i) = sign * contact::frictionDirection(*contact, data, i);
  auto add = [&](int coordinate, const Vec3<double>& c) {
    double* column = J + (n + coordinate) * k;
    for (int i = 0; i < k; ++i) column[i] += d.col(i).dot(c);
  };
  if (m > 0)
    contact::forEachJacobianColumnAt(model, data, *contact, x + 2 * n, add);
  else
    contact::forEachJacobianColumn(model, data, *contact, add);
  for (int i = 0; i < k; ++i) {
    J[i + (2 * n + m) * k] = -1.0;        // γ
    J[i + (2 * n + m + 1 + i) * k] = 1.0;  // ψ_i
  }
}

template class AdFunction<GapDefinition>;
template class AdFunction<PlaneCoordinate>;
template class AdFunction<FreePointOffset>;
template class AdFunction<RestitutionBalance>;
template class AdFunction<SlipSlack>;
template class AdFunction<Integration>;
template class AdFunction<Effort>;

}  // namespace saltus::collocation
