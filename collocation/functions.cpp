// The AD of the transcription's local functions (functions.hpp), instantiated here alone: this
// file is compiled with raised inlining limits (CMakeLists.txt), without which GCC leaves
// Eigen's AutoDiffScalar expression templates as calls and the nested-dual Hessians run about
// twice as slowly.
#include "collocation/functions.hpp"

namespace saltus::collocation {

template class AdFunction<EquationOfMotion>;
template class AdFunction<GapDefinition>;
template class AdFunction<RestitutionBalance>;
template class AdFunction<SlipSlack>;
template class AdFunction<Integration>;
template class AdFunction<Effort>;

}  // namespace saltus::collocation
