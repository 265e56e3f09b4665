// The stability maps' classifier on hand-made runs, one per outcome, and the order in which the
// criteria apply.
#include "verify/run_outcome.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace saltus::verify {
namespace {

RunRecord runWithEnergies(const std::vector<double>& energies, double penetration = 0) {
  RunRecord r;
  for (double e : energies)
    if (!r.addEnergy(e)) break;
  r.max_penetration = penetration;
  return r;
}

TEST(RunOutcome, OnePerClass) {
  const RunCriteria contact;  // a scene with contacts: energy may only fall
  RunCriteria conservative;
  conservative.conservative = true;
  RunCriteria bullet;
  bullet.fallbacks_fail = true;

  // A ball settling: energy falls, nothing passed.
  EXPECT_EQ(classifyRun(runWithEnergies({10, 9, 5, 2, 2}), contact).outcome, "ok");
  // A state that blew up: the energy turns infinite, then NaN.
  const RunRecord blown = runWithEnergies({10, 11, INFINITY, NAN});
  EXPECT_FALSE(blown.energy_finite);
  EXPECT_EQ(classifyRun(blown, contact).outcome, "nan");
  // The solver gave up, or something else failed, mid-run.
  RunRecord lcp = runWithEnergies({10, 9});
  lcp.end = RunEnd::LcpFailure;
  lcp.message = "LCP solver (pgs) failed at t = 0.271 s";
  EXPECT_EQ(classifyRun(lcp, contact).outcome, "lcp_failure");
  EXPECT_EQ(classifyRun(lcp, contact).message, lcp.message);
  RunRecord other = runWithEnergies({10, 9});
  other.end = RunEnd::OtherError;
  EXPECT_EQ(classifyRun(other, contact).outcome, "error");
  // A foot 2 mm under the ground.
  const RunOutcome sunk = classifyRun(runWithEnergies({10, 9}, 2e-3), contact);
  EXPECT_EQ(sunk.outcome, "penetration");
  EXPECT_NE(sunk.message.find("0.002"), std::string::npos) << sunk.message;
  // Energy above its start by 1e-6 of it, where nothing adds energy.
  const RunOutcome gained = classifyRun(runWithEnergies({10, 9, 10.00001}), contact);
  EXPECT_EQ(gained.outcome, "energy_gain");
  EXPECT_NE(gained.message.find("1e-06"), std::string::npos) << gained.message;
  // A free spin losing 1 % of its energy, and one wobbling by 1e-5: drift, and ok.
  EXPECT_EQ(classifyRun(runWithEnergies({3.6, 3.59, 3.564}), conservative).outcome, "drift");
  EXPECT_EQ(classifyRun(runWithEnergies({3.6, 3.60004, 3.59996}), conservative).outcome, "ok");
  // Bullet's MLCP fell back to sequential impulse on an otherwise good run.
  RunRecord fallback = runWithEnergies({10, 9});
  fallback.solver_fallbacks = 3;
  EXPECT_EQ(classifyRun(fallback, bullet).outcome, "solver_fallback");
  EXPECT_EQ(classifyRun(fallback, contact).outcome, "ok");
}

// The first criterion that applies wins: a failure over a penetration over an energy gain.
TEST(RunOutcome, CriteriaApplyInOrder) {
  RunRecord r = runWithEnergies({10, 20}, 1.0);
  const RunCriteria c;
  EXPECT_EQ(classifyRun(r, c).outcome, "penetration");
  r.end = RunEnd::LcpFailure;
  EXPECT_EQ(classifyRun(r, c).outcome, "lcp_failure");
  r.end = RunEnd::NotFinite;
  EXPECT_EQ(classifyRun(r, c).outcome, "nan");
  RunRecord driven = runWithEnergies({10, 20});
  RunCriteria unchecked;
  unchecked.energy_checked = false;  // an input or a belt adds energy
  EXPECT_EQ(classifyRun(driven, unchecked).outcome, "ok");
  EXPECT_DOUBLE_EQ(driven.energyGain(), 1.0);
  const RunRecord zero = runWithEnergies({0, 0.5});  // E_0 = 0: relative to 1
  EXPECT_DOUBLE_EQ(zero.energyGain(), 0.5);
}

}  // namespace
}  // namespace saltus::verify
