// The model and its workspaces for the three scalar types the local functions are evaluated in
// (double, first-order duals, second-order duals over chunks of 8 and of 4; local_function.hpp), with and without gravity: the
// impulsive equation of motion (6) is RNEA at zero velocity without gravity, M(q) q̈; and the
// workspaces of RNEA's derivatives (dynamics/derivatives.hpp) for the equations of motion's
// Jacobian.
#pragma once

#include <memory>
#include <tuple>

#include "collocation/local_function.hpp"
#include "dynamics/data.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/model.hpp"

namespace saltus::collocation {

class ModelSet {
 public:
  explicit ModelSet(const dynamics::Model<double>& model)
      : models_(model, model.template cast<Dual>(), model.template cast<Dual2>(), model.template cast<Dual2Small>()),
        unforced_(withoutGravity(model), withoutGravity(model).template cast<Dual>(),
                  withoutGravity(model).template cast<Dual2>(), withoutGravity(model).template cast<Dual2Small>()),
        data_(std::get<0>(models_), std::get<1>(models_), std::get<2>(models_), std::get<3>(models_)) {}

  template <class S> const dynamics::Model<S>& model() const { return std::get<dynamics::Model<S>>(models_); }
  template <class S> const dynamics::Model<S>& modelWithoutGravity() const {
    return std::get<dynamics::Model<S>>(unforced_);
  }
  // One workspace per scalar; the local functions run one at a time.
  template <class S> dynamics::Data<S>& data() const { return std::get<dynamics::Data<S>>(data_); }
  // ∂τ/∂q and ∂τ/∂q̇ of RNEA for the model with or without gravity (dynamics::rneaDerivatives),
  // made at the first use.
  dynamics::DerivativeData<kChunk>& rneaDerivatives(bool with_gravity) const {
    auto& d = derivatives_[with_gravity ? 1 : 0];
    if (!d)
      d = std::make_unique<dynamics::DerivativeData<kChunk>>(with_gravity ? model<double>()
                                                                         : modelWithoutGravity<double>());
    return *d;
  }

 private:
  static dynamics::Model<double> withoutGravity(dynamics::Model<double> m) {
    m.gravity.setZero();
    return m;
  }
  using Models =
      std::tuple<dynamics::Model<double>, dynamics::Model<Dual>, dynamics::Model<Dual2>, dynamics::Model<Dual2Small>>;
  Models models_, unforced_;
  mutable std::tuple<dynamics::Data<double>, dynamics::Data<Dual>, dynamics::Data<Dual2>, dynamics::Data<Dual2Small>>
      data_;
  mutable std::unique_ptr<dynamics::DerivativeData<kChunk>> derivatives_[2];
};

}  // namespace saltus::collocation
