// The double-precision instantiations of the dynamics templates, compiled once here; other
// translation units see them as extern templates (dynamics/dynamics.hpp).
#define SALTUS_DYNAMICS_INSTANTIATE
#include "dynamics/dynamics.hpp"
