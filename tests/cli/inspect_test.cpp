// `saltus inspect`, run as a program: the built binary (SALTUS_BINARY) on the bundled double
// pendulum, its JSON checked against the closed-form dynamics of two uniform rods, and its
// errors checked for exit code, message and an empty standard output.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "tests/support/run_saltus.hpp"
#include "saltus/build_paths.hpp"
#include <nlohmann/json.hpp>

namespace {

const std::string kPendulum = SALTUS_SOURCE_DIR "/models/pendulum/double_pendulum.urdf";

using Result = saltus::testing::RunResult;
using saltus::testing::readFile;

using saltus::testing::runSaltus;

std::string csv(const Eigen::Vector2d& x) {
  std::ostringstream s;
  s.precision(17);
  s << x[0] << "," << x[1];
  return s.str();
}

Eigen::Vector2d vec(const nlohmann::json& j) {
  EXPECT_EQ(j.size(), 2u) << j;
  return {j.at(0).get<double>(), j.at(1).get<double>()};
}

Eigen::Matrix2d mat(const nlohmann::json& j) {
  EXPECT_EQ(j.size(), 2u) << j;
  Eigen::Matrix2d M;
  M.row(0) = vec(j.at(0)).transpose();
  M.row(1) = vec(j.at(1)).transpose();
  return M;
}

// Two uniform rods of mass m = 1 kg and length l = 0.5 m hanging along −z at q = 0, hinged
// about y at their upper ends; c = l/2 is the distance of each centre of mass from its joint
// and I = m l²/12 the inertia about it across the rod.
constexpr double m = 1.0, l = 0.5, c = l / 2, I = m * l * l / 12, g = 9.81;

Eigen::Matrix2d closedFormM(const Eigen::Vector2d& q) {
  const double c2 = std::cos(q[1]);
  Eigen::Matrix2d M;
  M(0, 0) = I + m * c * c + I + m * (l * l + c * c + 2 * l * c * c2);
  M(0, 1) = M(1, 0) = I + m * (c * c + l * c * c2);
  M(1, 1) = I + m * c * c;
  return M;
}

// g(q) = ∂V/∂q with V = −m g c cos q1 − m g (l cos q1 + c cos(q1 + q2)).
Eigen::Vector2d closedFormGravity(const Eigen::Vector2d& q) {
  return {g * (m * c * std::sin(q[0]) + m * (l * std::sin(q[0]) + c * std::sin(q[0] + q[1]))),
          g * m * c * std::sin(q[0] + q[1])};
}

// C(q, v) v of the double pendulum.
Eigen::Vector2d closedFormCoriolis(const Eigen::Vector2d& q, const Eigen::Vector2d& v) {
  const double k = m * l * c * std::sin(q[1]);
  return {-k * (2 * v[0] * v[1] + v[1] * v[1]), k * v[0] * v[0]};
}

nlohmann::json inspectJson(const std::vector<std::string>& extra) {
  std::vector<std::string> args{"inspect", kPendulum, "--json"};
  args.insert(args.end(), extra.begin(), extra.end());
  const Result r = runSaltus(args);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  return nlohmann::json::parse(r.out);
}

const std::vector<Eigen::Vector2d> kConfigurations = {{0, 0}, {0, 0.785}, {0.3, -1.2}, {-2.5, 2.9}, {1.0, M_PI}};

TEST(Inspect, CoordinatesAndModelFacts) {
  const nlohmann::json j = inspectJson({});
  EXPECT_EQ(j.at("coordinates"), nlohmann::json({"theta1", "theta2"}));
  EXPECT_EQ(j.at("model"), "double_pendulum");
  EXPECT_EQ(j.at("base"), "fixed");
  EXPECT_DOUBLE_EQ(j.at("total_mass").get<double>(), 2.0);
  EXPECT_FALSE(j.contains("M")) << "no state given, so no dynamics";
}

TEST(Inspect, MassMatrixMatchesClosedForm) {
  for (const Eigen::Vector2d& q : kConfigurations) {
    const nlohmann::json j = inspectJson({"--q=" + csv(q), "--v=0,0"});
    EXPECT_LT((mat(j.at("M")) - closedFormM(q)).cwiseAbs().maxCoeff(), 1e-12) << "q = " << q.transpose();
  }
}

TEST(Inspect, BiasAtRestIsGravityTorque) {
  for (const Eigen::Vector2d& q : kConfigurations) {
    const nlohmann::json j = inspectJson({"--q=" + csv(q), "--v=0,0"});
    EXPECT_LT((vec(j.at("h")) - closedFormGravity(q)).norm(), 1e-10) << "q = " << q.transpose();
  }
}

TEST(Inspect, BiasWithVelocityAddsCoriolis) {
  const Eigen::Vector2d q(0.4, -0.9), v(1.3, -2.1);
  const nlohmann::json j = inspectJson({"--q=" + csv(q), "--v=" + csv(v)});
  EXPECT_LT((vec(j.at("h")) - closedFormGravity(q) - closedFormCoriolis(q, v)).norm(), 1e-10);
}

TEST(Inspect, VelocityDefaultsToZero) {
  const Eigen::Vector2d q(0.7, 0.2);
  const nlohmann::json j = inspectJson({"--q=" + csv(q)});
  EXPECT_EQ(j.at("state").at("v"), nlohmann::json({0.0, 0.0}));
  EXPECT_LT((vec(j.at("h")) - closedFormGravity(q)).norm(), 1e-10);
}

TEST(Inspect, InverseDynamicsIsMaPlusH) {
  const Eigen::Vector2d q(0.3, 0.785), v(-0.5, 1.5), a(2.0, -3.0);
  const nlohmann::json j = inspectJson({"--q=" + csv(q), "--v=" + csv(v), "--a=" + csv(a)});
  const Eigen::Vector2d tau = vec(j.at("tau"));
  EXPECT_LT((tau - (mat(j.at("M")) * a + vec(j.at("h")))).norm(), 1e-10);
  EXPECT_LT((tau - (closedFormM(q) * a + closedFormGravity(q) + closedFormCoriolis(q, v))).norm(), 1e-10);
  EXPECT_FALSE(j.contains("qdd"));
}

TEST(Inspect, ForwardDynamicsSolvesEquationsOfMotion) {
  const Eigen::Vector2d q(-0.6, 1.1), v(0.8, 0.3), tau(1.5, -0.25);
  const nlohmann::json j = inspectJson({"--q=" + csv(q), "--v=" + csv(v), "--tau=" + csv(tau)});
  const Eigen::Vector2d qdd = vec(j.at("qdd"));
  EXPECT_LT((mat(j.at("M")) * qdd + vec(j.at("h")) - tau).norm(), 1e-10);
  const Eigen::Vector2d expected =
      closedFormM(q).ldlt().solve(tau - closedFormGravity(q) - closedFormCoriolis(q, v));
  EXPECT_LT((qdd - expected).norm(), 1e-9);
  EXPECT_FALSE(j.contains("tau"));
}

TEST(Inspect, SpaceSeparatedValuesAndBothDirections) {
  // "--a 0,0" (value as the next argument) works like "--a=0,0"; ID then FD round-trips.
  const nlohmann::json j = inspectJson({"--q", "0.2,0.4", "--v", "0.1,-0.1", "--a", "0.5,0.25"});
  const nlohmann::json k = inspectJson({"--q=0.2,0.4", "--v=0.1,-0.1", "--tau=" + csv(vec(j.at("tau")))});
  EXPECT_LT((vec(k.at("qdd")) - Eigen::Vector2d(0.5, 0.25)).norm(), 1e-10);
}

TEST(Inspect, FreeBaseAddsSixCoordinates) {
  // HyQ on a free base: 6 base coordinates, then its 12 joints; at rest with zero base angles
  // the whole robot rides on base_x, so M(0, 0) is its mass, and gravity loads base_z.
  const std::string hyq = SALTUS_SOURCE_DIR "/models/benchmark/hyq.urdf";
  const Result r = runSaltus({"inspect", hyq, "--json", "--base", "free", "--q=0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const auto& names = j.at("coordinates");
  ASSERT_EQ(names.size(), 18u);
  EXPECT_EQ(nlohmann::json(std::vector<nlohmann::json>(names.begin(), names.begin() + 6)),
            nlohmann::json({"base_x", "base_y", "base_z", "base_yaw", "base_pitch", "base_roll"}));
  EXPECT_EQ(j.at("base"), "free");
  const double mass = j.at("total_mass").get<double>();
  EXPECT_GT(mass, 0);
  EXPECT_NEAR(j.at("M").at(0).at(0).get<double>(), mass, 1e-9);
  EXPECT_NEAR(j.at("h").at(2).get<double>(), mass * g, 1e-9);
}

TEST(Inspect, FloatingBaseNeedsAMassiveRoot) {
  // The pendulum's root link is the massless 'world': it cannot be a floating base.
  const Result r = runSaltus({"inspect", kPendulum, "--base=planar"});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("world"), std::string::npos) << r.err;
}

TEST(Inspect, ReadableSummary) {
  const Result r = runSaltus({"inspect", kPendulum});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const char* text : {"double_pendulum", "double_pendulum.urdf", "fixed", "link1", "link2", "theta1", "theta2",
                           "revolute", "2 kg"})
    EXPECT_NE(r.out.find(text), std::string::npos) << "missing '" << text << "' in\n" << r.out;
}

// An error: exit code, message on stderr, nothing on stdout.
void expectError(const std::vector<std::string>& args, int status, const std::string& message) {
  const Result r = runSaltus(args);
  EXPECT_EQ(r.status, status) << r.err;
  EXPECT_EQ(r.out, "") << "stdout must stay empty on error";
  EXPECT_NE(r.err.find(message), std::string::npos) << "expected '" << message << "' in stderr:\n" << r.err;
  EXPECT_EQ(r.err.rfind("saltus: ", 0), 0u) << r.err;
}

TEST(InspectErrors, WrongNumberOfValues) {
  expectError({"inspect", kPendulum, "--json", "--q=0,0,0"}, 2,
              "--q: expected 2 comma-separated numbers (coordinates: theta1, theta2), got 3");
  expectError({"inspect", kPendulum, "--q=0,0", "--v=1"}, 2, "--v: expected 2 comma-separated numbers");
  expectError({"inspect", kPendulum, "--q= "}, 2, "--q: expected 2 comma-separated numbers (coordinates: theta1, theta2), got 0");
}

TEST(InspectErrors, NotANumberNamesTheToken) {
  expectError({"inspect", kPendulum, "--json", "--q=0,0", "--tau=0.5,abc"}, 2, "--tau: value 2 (theta2) 'abc' is not a number");
  expectError({"inspect", kPendulum, "--q=0,1.5x"}, 2, "'1.5x'");
  expectError({"inspect", kPendulum, "--q=0,inf"}, 2, "'inf' is not a finite number");
  expectError({"inspect", kPendulum, "--q=0,"}, 2, "--q: value 2 (theta2) is empty");
}

// Finite inputs whose results overflow (v² ~ 1e400) are an error, not "null" with exit 0.
TEST(InspectErrors, ResultsThatAreNotFiniteAreErrors) {
  expectError({"inspect", kPendulum, "--json", "--q=0,0", "--v=1e200,1e200"}, 1, "h(q, v) is not finite for the state given");
}

TEST(InspectErrors, StateOptionsNeedQ) {
  expectError({"inspect", kPendulum, "--json", "--a=0,0"}, 2, "--a needs --q");
}

TEST(InspectErrors, BadBase) {
  expectError({"inspect", kPendulum, "--base=floating"}, 2, "--base: expected fixed, planar or free, got 'floating'");
}

TEST(InspectErrors, UsageErrors) {
  expectError({}, 2, "saltus: ");
  expectError({"inspect"}, 2, "MODEL");
  expectError({"inspect", kPendulum, "--bogus"}, 2, "--bogus");
  expectError({"frobnicate"}, 2, "unknown command 'frobnicate'");
}

TEST(InspectErrors, MissingFile) {
  expectError({"inspect", "/nonexistent/robot.urdf", "--json"}, 1, "/nonexistent/robot.urdf");
}

TEST(InspectErrors, InvalidModelNamesFileAndElement) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("saltus_cli_test_" + std::to_string(::getpid()) + ".urdf");
  std::ofstream(path) << R"(<robot name="broken">
  <link name="base"/>
  <link name="arm"><inertial><mass value="-1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>)";
  const Result r = runSaltus({"inspect", path.string(), "--json"});
  std::filesystem::remove(path);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err.rfind("saltus: " + path.string(), 0), 0u) << r.err;
  EXPECT_NE(r.err.find("arm"), std::string::npos) << r.err;
}

TEST(Saltus, HelpAndVersionGoToStdout) {
  const Result help = runSaltus({"inspect", "--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("--tau"), std::string::npos) << help.out;
  const Result version = runSaltus({"--version"});
  EXPECT_EQ(version.status, 0);
  EXPECT_EQ(version.out.rfind("saltus ", 0), 0u) << version.out;
}

}  // namespace
