// What a run of an engine came to, for the stability maps (`saltus bench stability`): a record of
// the run (how it ended, the energy it had along the way, the deepest penetration, the solver's
// fallbacks) and the one rule that turns it into an outcome. The criteria are the README's:
//   nan          the state (or the energy) stopped being finite;
//   lcp_failure  the contact solver failed (SimulationError naming the LCP);
//   error        any other SimulationError;
//   penetration  a contact or stop passed by more than penetration_limit (m or rad);
//   energy_gain  the energy rose above E_0 by more than energy_tolerance |E_0| (a scene where
//                nothing adds energy: no input, no moving surface);
//   drift        a conservative scene (no contact, no stop, no input) whose energy left E_0 by
//                more than drift_tolerance |E_0|, either way;
//   solver_fallback  Bullet's MLCP fell back to sequential impulse (ok otherwise);
//   ok           none of these.
// The first that applies, in this order.
#pragma once

#include <limits>
#include <string>

namespace saltus::verify {

enum class RunEnd { Completed, NotFinite, LcpFailure, OtherError };

struct RunRecord {
  RunEnd end = RunEnd::Completed;
  std::string message;  // the error's message, when the run ended on one
  double energy_start = std::numeric_limits<double>::quiet_NaN();
  double energy_max = -std::numeric_limits<double>::infinity();
  double energy_min = std::numeric_limits<double>::infinity();
  bool energy_finite = true;
  double max_penetration = 0;  // [m or rad]
  long solver_fallbacks = 0;

  // The energy after a step (the first call: E_0). Returns false once it is not finite.
  bool addEnergy(double e);
  // (E_max − E_0) / |E_0| (|E_0| = 0: / 1) and the largest |E − E_0| / |E_0|.
  double energyGain() const;
  double energyDrift() const;
};

struct RunCriteria {
  double penetration_limit = 1e-3;   // [m or rad]
  double energy_tolerance = 1e-9;    // relative to |E_0|
  double drift_tolerance = 1e-3;     // relative to |E_0|
  bool energy_checked = true;        // false: an input or a moving surface may add energy
  bool conservative = false;         // no contact, stop or input: energy must stay (drift)
  bool fallbacks_fail = false;       // Bullet: MLCP fallbacks are an outcome of their own
};

struct RunOutcome {
  std::string outcome;  // ok | nan | lcp_failure | error | penetration | energy_gain | drift | solver_fallback
  std::string message;  // why, with the measured figure
};

RunOutcome classifyRun(const RunRecord& run, const RunCriteria& criteria);

}  // namespace saltus::verify
