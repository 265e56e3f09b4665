// Umbrella header of the dynamics library.
#pragma once

#include "dynamics/aba.hpp"
#include "dynamics/builder.hpp"
#include "dynamics/configuration.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/data.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/jacobian.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/model.hpp"
#include "dynamics/rnea.hpp"

#ifdef SALTUS_DYNAMICS_INSTANTIATE
#define SALTUS_EXTERN
#else
#define SALTUS_EXTERN extern
#endif

namespace saltus::dynamics {
SALTUS_EXTERN template struct Model<double>;
SALTUS_EXTERN template struct Data<double>;
using RefV = const VecRef<double>&;
SALTUS_EXTERN template void forwardKinematics<double>(const Model<double>&, Data<double>&, RefV);
SALTUS_EXTERN template void forwardKinematics<double>(const Model<double>&, Data<double>&, RefV, RefV);
SALTUS_EXTERN template void forwardKinematics<double>(const Model<double>&, Data<double>&, RefV, RefV, RefV);
SALTUS_EXTERN template const VecX<double>& rnea<double>(const Model<double>&, Data<double>&, RefV, RefV, RefV);
SALTUS_EXTERN template const VecX<double>& nonLinearEffects<double>(const Model<double>&, Data<double>&, RefV, RefV);
SALTUS_EXTERN template const MatX<double>& crba<double>(const Model<double>&, Data<double>&, RefV);
SALTUS_EXTERN template const VecX<double>& aba<double>(const Model<double>&, Data<double>&, RefV, RefV, RefV);
}  // namespace saltus::dynamics

#undef SALTUS_EXTERN
