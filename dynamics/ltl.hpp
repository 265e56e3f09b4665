// The factorisation M = Lᵀ L of the joint-space inertia matrix that keeps its branch-induced
// sparsity (RBDA 6.5, Table 6.3 "LTL"): M_ij ≠ 0 only when coordinate j is i or on i's path to the
// root (Model::parent_coordinate), and L, lower triangular, has exactly that pattern, so the
// factorisation and the solves with L and Lᵀ visit only each coordinate's ancestors: O(n d) and
// O(n d²) for a tree of depth d instead of O(n²) and O(n³). A quadruped's legs never meet
// but in the base. The time-stepper's Delassus matrix J M⁻¹ Jᵀ = (L⁻ᵀ Jᵀ)ᵀ (L⁻ᵀ Jᵀ) then costs one
// sparse solve per row, and a row of a contact on one leg stays zero off that leg's path.
#pragma once

#include <cmath>

#include "dynamics/model.hpp"

namespace saltus::dynamics {

// Overwrites the lower triangle of M (both triangles filled, as crba leaves data.M) with L,
// M = Lᵀ L (RBDA Table 6.3); the strict upper triangle is left as it was. Returns false when a
// pivot is not positive (M not positive definite), leaving M partly factored.
inline bool factorLtl(const Model<double>& model, MatX<double>& M) {
  const std::vector<int>& parent = model.parent_coordinate;
  for (int k = model.nv() - 1; k >= 0; --k) {
    if (!(M(k, k) > 0)) return false;
    const double d = std::sqrt(M(k, k));
    M(k, k) = d;
    for (int i = parent[k]; i >= 0; i = parent[i]) M(k, i) /= d;
    for (int i = parent[k]; i >= 0; i = parent[i])
      for (int j = i; j >= 0; j = parent[j]) M(i, j) -= M(k, i) * M(k, j);
  }
  return true;
}

// x ← L⁻ᵀ x (RBDA 6.5: Lᵀ y = x, leaves to root). Entries that are zero stay so and cost nothing:
// for x nonzero only on the path of one body, so is the result.
inline void solveLtlTranspose(const Model<double>& model, const MatX<double>& L, double* x) {
  const std::vector<int>& parent = model.parent_coordinate;
  for (int i = model.nv() - 1; i >= 0; --i) {
    if (x[i] == 0) continue;
    x[i] /= L(i, i);
    for (int j = parent[i]; j >= 0; j = parent[j]) x[j] -= L(i, j) * x[i];
  }
}

// x ← L⁻¹ x (L y = x, root to leaves).
inline void solveLtl(const Model<double>& model, const MatX<double>& L, double* x) {
  const std::vector<int>& parent = model.parent_coordinate;
  for (int i = 0; i < model.nv(); ++i) {
    double s = x[i];
    for (int j = parent[i]; j >= 0; j = parent[j]) s -= L(i, j) * x[j];
    x[i] = s / L(i, i);
  }
}

// x ← M⁻¹ x = L⁻¹ L⁻ᵀ x.
inline void solveMassLtl(const Model<double>& model, const MatX<double>& L, double* x) {
  solveLtlTranspose(model, L, x);
  solveLtl(model, L, x);
}

}  // namespace saltus::dynamics
