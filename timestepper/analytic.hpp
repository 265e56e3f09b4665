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

// Housner's rocking block (2b wide, 2h tall, uniform, on a rigid floor with no sliding; G. W.
// Housner, Bull. Seismological Society of America 53(2), 1963): α = atan(b/h), R = √(b² + h²),
// inertia about a corner I_O = (4/3) m R². An inelastic impact on the landing corner, the pivot
// lifting off, keeps the angular momentum about the landing corner: ω⁺ = r ω⁻ with
// r = 1 − (3/2) sin² α (Housner eq. 3).
double rockingImpactRatio(double b, double h);
// |ω| when the block, released from rest at tilt θ0 ∈ (0, α), comes back flat (energy about the
// pivot): √(2 m g R (cos(α − θ0) − cos α) / I_O) = √((3 g / (2 R)) (cos(α − θ0) − cos α)).
double rockingReturnSpeed(double b, double h, double theta0, double g);
// The largest tilt after an impact that leaves |ω| = omega when flat: the energy
// ½ I_O ω² = m g R (cos(α − θ) − cos α) gives θ = α − acos(cos α + (2 R / (3 g)) ω²).
double rockingTilt(double b, double h, double omega, double g);
// The largest |θ| between the first and the second impact of a rocking trajectory, from samples
// of the tilt θ: an impact is where θ changes sign (the block is flat). NaN without two sign
// changes within the samples (the second may be missing: then up to the end).
double rockingFirstTilt(const std::vector<double>& theta);

// Three equal balls in a row, the first at speed v striking the other two at rest and touching,
// restitution e on both contacts, Newton's law on both at once (the impact LCP; newtons_cradle's
// header): v1 = (1 − 2e) v / 3, v2 = v3 = (1 + e) v / 3. (Pairwise impacts, the resting balls
// apart, give (0, 0, v) for e = 1 instead.)
std::vector<double> cradleVelocities(double e, double v);

// A free rigid body with principal moments I1 < I2 < I3 spinning torque-free from body rates
// (0, ω2, ω3), ω3 ≠ 0 small (M² > 2 E I2): ω2 = b sn(τ + K, k), so ω2 first changes sign at
// t = K(k)/λ and then every 2 K(k)/λ, with λ = √((I3 − I2)(M² − 2 E I1) / (I1 I2 I3)) and
// k² = (I2 − I1)(2 E I3 − M²) / ((I3 − I2)(M² − 2 E I1)) (Landau and Lifshitz, Mechanics, §37).
// Returns the flip times up to t_end (fast_spin's answer).
std::vector<double> spinFlipTimes(double I1, double I2, double I3, double w2, double w3, double t_end);

// The first apex of a bouncing trajectory: the largest height between the first and the second
// impact, from samples (height z, normal impulse pn over the step that ended at the sample).
// An impact is a run of consecutive samples with pn > 0; the apex is searched from the first
// impact's first sample up to (not including) the first sample of the next impact, or to the
// end when there is none. NaN when there is no impact at all.
double firstApex(const std::vector<double>& z, const std::vector<double>& pn);

}  // namespace saltus::timestepper::analytic
