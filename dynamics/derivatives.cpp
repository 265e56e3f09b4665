// The default chunk (8 directions: one AVX-512 register, two AVX2 registers) compiled once.
#include "dynamics/derivatives.hpp"

namespace saltus::dynamics {
template struct DerivativeData<8>;
template void rneaDerivatives<8>(const Model<double>&, DerivativeData<8>&, const VecRef<double>&,
                                 const VecRef<double>&, const VecRef<double>&);
template void abaDerivatives<8>(const Model<double>&, DerivativeData<8>&, const VecRef<double>&,
                                const VecRef<double>&, const VecRef<double>&);
}  // namespace saltus::dynamics
