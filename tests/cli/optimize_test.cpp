// `saltus optimize`, run as a program: the built-in point-mass drop solved into trajectory.csv
// and summary.json (columns, rows, the summary's figures), and the refusals (a method that
// cannot represent the problem, unknown names, bad options) with exit code and message.
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/run_saltus.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;
using saltus::testing::runSaltus;

fs::path freshDir(const std::string& name) { return saltus::testing::scratchPath("optimize_test", name); }

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string item; std::getline(s, item, ',');) out.push_back(item);
  return out;
}

TEST(Optimize, PointMassDropWritesTrajectoryAndSummary) {
  const fs::path dir = freshDir("drop");
  const auto r = runSaltus({"optimize", "point_mass_drop", "--out", dir.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const nlohmann::json s = nlohmann::json::parse(readFile(dir / "summary.json"));
  EXPECT_EQ(s["method"], "impulsive");
  EXPECT_EQ(s["N"], 20);
  EXPECT_EQ(s["P"], 4);
  EXPECT_TRUE(s["feasible"].get<bool>());
  EXPECT_LE(s["largest_product"].get<double>(), 1e-4);
  EXPECT_GE(s["total_time"].get<double>(), 0.2 - 1e-6);
  ASSERT_EQ(s["stages"].size(), 1u);  // no hints, no task cost: the feasibility stage alone
  EXPECT_EQ(s["stages"][0]["name"], "feasibility");
  EXPECT_EQ(s["stages"][0]["status"], "Solve_Succeeded");
  // The default seed: the time-stepper's motion, its landing on an element boundary.
  EXPECT_EQ(s["seed"], "simulation");
  ASSERT_EQ(s["simulation_seed"]["events"].size(), 1u);
  EXPECT_NEAR(s["simulation_seed"]["events"][0].get<double>(), std::sqrt(2 * 0.1 / 9.81), 1e-3);
  EXPECT_EQ(s["attempts"].size(), 1u);
  EXPECT_GT(s["iterations"].get<int>(), 0);
  EXPECT_GT(s["evaluation_seconds"].get<double>(), 0.0);
  EXPECT_LT(s["evaluation_seconds"].get<double>(), s["wall_seconds"].get<double>());
  EXPECT_GT(s["variables"].get<int>(), s["constraints"].get<int>());
  EXPECT_GT(s["mean_local_error"].get<double>(), 0.0);

  std::stringstream csv(readFile(dir / "trajectory.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line,
            "t,q.z,v.z,contact.ball.gap,contact.ball.vn,contact.ball.vt,contact.ball.rn,contact.ball.rt,"
            "contact.ball.pn,contact.ball.pt");
  int rows = 0, jumps = 0;
  double t_prev = -1, v_prev = 0;
  while (std::getline(csv, line)) {
    const auto f = split(line);
    ASSERT_EQ(f.size(), 10u) << line;
    const double t = std::stod(f[0]), v = std::stod(f[2]);
    EXPECT_GE(t, t_prev);
    if (t == t_prev && std::abs(v - v_prev) > 0.5) ++jumps;  // the impact: before, then after
    EXPECT_NEAR(std::stod(f[4]), v, 1e-12) << "vn of a vertical coordinate is ż";
    t_prev = t;
    v_prev = v;
    ++rows;
  }
  EXPECT_EQ(rows, 20 * 6 - 0);  // 6 points per element (P = 4), every [n, 0] kept (the jumps)
  EXPECT_EQ(jumps, 1);

  // The solution seeds a new solve (unperturbed): it ends feasible again, and says where it started.
  EXPECT_NE(readFile(dir / "variables.csv").find("# source: builtin:point_mass_drop"), std::string::npos);
  const fs::path again = freshDir("drop_again");
  const auto r2 = runSaltus({"optimize", "point_mass_drop", "--seed-from", dir.string(), "--seed-scale", "0",
                             "--restarts", "0", "--out", again.string()});
  ASSERT_EQ(r2.status, 0) << r2.err;
  const nlohmann::json s2 = nlohmann::json::parse(readFile(again / "summary.json"));
  EXPECT_EQ(s2["seed"], "solution");
  EXPECT_EQ(s2["seed_solution"], dir.string());
  EXPECT_TRUE(s2["feasible"].get<bool>());
  EXPECT_EQ(s2["attempts"].size(), 1u);
  fs::remove_all(dir);
  fs::remove_all(again);
}

TEST(Optimize, SeedFromAMissingSolutionIsAnError) {
  const fs::path dir = freshDir("seed_missing");
  const auto r = runSaltus({"optimize", "point_mass_drop", "--seed-from", "/nonexistent/run", "--out", dir.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--seed-from: /nonexistent/run: no such solution"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir)) << "nothing written before the solve";
}

TEST(Optimize, ContinuousAndFirstOrderRefuseRestitution) {
  for (const std::string method : {"continuous", "first-order"}) {
    const fs::path dir = freshDir("refuse");
    const auto r = runSaltus({"optimize", "point_mass_drop", "--method", method, "--set", "restitution=0.5",
                              "--out", dir.string()});
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find(method + " method cannot represent restitution: contact 'ball' has e = 0.5"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir));
  }
}

TEST(Optimize, BadInputNamesWhatWasExpected) {
  const fs::path dir = freshDir("bad");
  auto r = runSaltus({"optimize", "point_mass_dorp", "--out", dir.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("did you mean 'point_mass_drop'"), std::string::npos) << r.err;
  r = runSaltus({"optimize", "point_mass_drop", "--method", "second-order", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--method"), std::string::npos) << r.err;
  // Ipopt's options are checked against Ipopt's own list before the solve: usage errors
  r = runSaltus({"optimize", "point_mass_drop", "--ipopt", "max_itr=3", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--ipopt max_itr=3: unknown Ipopt option 'max_itr'"), std::string::npos) << r.err;
  r = runSaltus({"optimize", "point_mass_drop", "--ipopt", "max_iter=many", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("expected an integer"), std::string::npos) << r.err;
  r = runSaltus({"optimize", "point_mass_drop", "--task-ipopt", "obj_scaling=10", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--task-ipopt obj_scaling=10: unknown Ipopt option 'obj_scaling'"), std::string::npos) << r.err;
  // A two-step solve's first method: a method, another than --method, able to take the problem.
  r = runSaltus({"optimize", "point_mass_drop", "--seed-method", "euler", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--seed-method: "), std::string::npos) << r.err;
  r = runSaltus({"optimize", "point_mass_drop", "--seed-method", "impulsive", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--seed-method: expected another method than the solve's own (impulsive)"), std::string::npos) << r.err;
  r = runSaltus({"optimize", "point_mass_drop", "--set", "restitution=0.5", "--seed-method", "first-order", "--out",
                 dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--seed-method: the first-order method cannot represent restitution"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Optimize, FailedSolveExitsNonZeroWithIpoptStatus) {
  const fs::path dir = freshDir("fail");
  const auto r = runSaltus({"optimize", "point_mass_drop", "--ipopt", "max_iter=2", "--out", dir.string()});
  EXPECT_EQ(r.status, 1);
  const nlohmann::json s = nlohmann::json::parse(readFile(dir / "summary.json"));
  EXPECT_FALSE(s["feasible"].get<bool>());
  EXPECT_EQ(s["stages"][0]["status"], "Maximum_Iterations_Exceeded");
  fs::remove_all(dir);
}

// --resimulations: after each failed attempt, one from the time-stepper's motion under its inputs,
// before the next restart; the summary lists each attempt's restart and re-simulation index.
TEST(Optimize, ResimulationsFollowEachFailedAttempt) {
  const fs::path dir = freshDir("resimulate");
  auto r = runSaltus({"optimize", "ollie_simple", "--restarts", "1", "--resimulations", "1", "--resimulation-tracking", "20",
                      "--ipopt", "max_iter=1", "--tighten-within", "0", "--task-max-iter", "0", "--out", dir.string()});
  EXPECT_EQ(r.status, 1) << r.err;
  const nlohmann::json s = nlohmann::json::parse(readFile(dir / "summary.json"));
  EXPECT_EQ(s["resimulations"], 1);
  EXPECT_EQ(s["resimulation_tracking"], 20.0);
  ASSERT_EQ(s["attempts"].size(), 4u) << s["attempts"].dump();
  const int expected[4][2] = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(s["attempts"][i]["attempt"], expected[i][0]) << i;
    EXPECT_EQ(s["attempts"][i]["resimulation"], expected[i][1]) << i;
    EXPECT_FALSE(s["attempts"][i]["feasible"].get<bool>()) << i;
  }
  fs::remove_all(dir);
  r = runSaltus({"optimize", "ollie_simple", "--resimulations", "-1", "--out", dir.string()});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("resimulations: expected a non-negative integer"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir));
  r = runSaltus({"optimize", "ollie_simple", "--resimulation-tracking", "-5", "--out", dir.string()});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--resimulation-tracking: expected a natural frequency >= 0 rad/s"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
