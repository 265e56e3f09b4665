// Closed-form answers for the validation scenes (elementary mechanics: Newton restitution,
// Coulomb friction) and the trajectory measurement they are compared with. Used by
// `saltus bench work-precision` (cli/bench.cpp) and the physics tests.
#pragma once

#include <vector>

namespace saltus::timestepper::analytic {

// Ball dropped from rest at height h0 onto a plane, restitution e, gravity g.
// Apex after k bounces: h_k = e^(2k) h0.
double ballApex(double h0, double e, int k);
// Speed just before impact k (k = 0: the first impact): v_k = e^k √(2 g h0).
double ballImpactSpeed(double h0, double e, int k, double g);
// Time at which the bounces have died out: √(2 h0/g) (1 + e)/(1 − e); +∞ for e = 1.
double ballRestTime(double h0, double e, double g);

// Particle sliding downhill at v0 > 0 on a plane inclined by α (α = 0: level ground) with
// Coulomb friction μ, gravity g. s is the distance travelled down the slope.
// Once stopped it stays: static friction holds iff tan α ≤ μ.
bool slideSticks(double mu, double alpha);
// Acceleration while sliding downhill: a = g (sin α − μ cos α) (negative: decelerating).
double slideAcceleration(double mu, double alpha, double g);
// Time and distance to the stop, v0/|a| and v0²/(2 g (μ cos α − sin α)); +∞ when a ≥ 0.
double slideStopTime(double v0, double mu, double alpha, double g);
double slideStopDistance(double v0, double mu, double alpha, double g);
// s(t): v0 t + ½ a t² until the stop, then the stopping distance.
double slidePosition(double v0, double mu, double alpha, double g, double t);

// The first apex of a bouncing trajectory: the largest height between the first and the second
// impact, from samples (height z, normal impulse pn over the step that ended at the sample).
// An impact is a run of consecutive samples with pn > 0; the apex is searched from the first
// impact's first sample up to (not including) the first sample of the next impact, or to the
// end when there is none. NaN when there is no impact at all.
double firstApex(const std::vector<double>& z, const std::vector<double>& pn);

}  // namespace saltus::timestepper::analytic
