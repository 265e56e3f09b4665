// Cross-check of saltus forward dynamics (ABA) against Bullet's btMultiBody (double precision) on
// random robots read from the same URDF text, plus closed-form checks through Bullet.
//
// Tolerance. Both sides run an O(n) articulated-body recursion in double precision on the same
// data, but in different frames (saltus: joint frames; Bullet: com/principal frames, with an
// eigen-decomposition and a matrix->quaternion conversion in between), so they differ by
// rounding only, amplified by the conditioning of the joint-space inertia matrix M. We compare
//   ‖q̈_saltus − q̈_bullet‖∞ ≤ kRelTol · (‖q̈‖∞ + ‖M⁻¹‖·‖τ_all‖∞)
// where the scale is the size of the accelerations the inputs can produce (τ_all = τ minus the
// bias forces h, M⁻¹ from saltus' CRBA): a backward-stable solve of M q̈ = τ − h errs by about
// ε ‖M⁻¹‖ ‖τ − h‖, so this is the natural yardstick (it is up to ~2e3 × ‖q̈‖∞ on these robots).
// Observed (500 robots × 4 states per base, g++ 12 -O3 -march=native): ‖Δq̈‖∞ / scale ≤ 5.3e-15,
// ‖Δq̈‖∞ / ‖q̈‖∞ ≤ 3.1e-13. kRelTol = 1e-10 leaves more than four orders of magnitude of headroom
// for other compilers and flags, yet a 1e-6 relative change of one body's mass in the Bullet model
// (≈ 5e-9 at that scale) is detected (ModelPerturbationIsDetected).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <Eigen/Cholesky>

#include "dynamics/dynamics.hpp"
#include "dynamics/urdf.hpp"
#include "saltus/build_paths.hpp"
#include "tests/support/free_body.hpp"
#include "tests/support/random_urdf.hpp"
#include "verify/bullet_multibody.hpp"

namespace {

using namespace saltus::dynamics;
using saltus::testing::RandomUrdfRobot;
using saltus::testing::randomUrdfRobot;
using saltus::verify::BulletMultiBody;
using saltus::verify::FreeBase;

constexpr double kRelTol = 1e-10;
// 20 robots per base; SALTUS_BULLET_SEEDS=N runs N (for longer soak runs).
int numSeeds() {
  const char* env = std::getenv("SALTUS_BULLET_SEEDS");
  return env ? std::max(1, std::atoi(env)) : 20;
}

Eigen::VectorXd uniform(std::mt19937& rng, int n, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = u(rng);
  return x;
}

struct State {
  Eigen::VectorXd q, v, tau;
};

// Random state: joint positions in [−π, π] (prismatic in ±1 m), velocities in ±2, torques in ±5;
// free-base pitch kept in ±1.2 rad, away from the Euler singularity.
State randomState(std::mt19937& rng, const Model<double>& model) {
  const int n = model.nv();
  State s{uniform(rng, n, -M_PI, M_PI), uniform(rng, n, -2, 2), uniform(rng, n, -5, 5)};
  for (int i = 0; i < n; ++i)
    if (model.isTranslation(i)) s.q[i] /= M_PI;
  if (model.base == BaseType::Free) s.q[4] = std::uniform_real_distribution<double>(-1.2, 1.2)(rng);
  if (model.base == BaseType::FreeQuaternion) {  // any orientation: a random unit quaternion
    Eigen::VectorXd q(model.nq());
    q << s.q.head<3>(), uniform(rng, 4, -1, 1).normalized(), s.q.tail(n - 6);
    s.q = q;
  }
  return s;
}

// The scale that accelerations are compared at (see the header comment).
double accelerationScale(const Model<double>& model, const State& s, const Eigen::VectorXd& qdd) {
  Data<double> data(model);
  const Eigen::MatrixXd M = crba(model, data, s.q);
  const Eigen::VectorXd h = nonLinearEffects(model, data, s.q, s.v);
  const Eigen::MatrixXd Minv = M.ldlt().solve(Eigen::MatrixXd::Identity(model.nv(), model.nv()));
  const double minv_norm = Minv.cwiseAbs().rowwise().sum().maxCoeff();  // ‖M⁻¹‖∞
  return qdd.cwiseAbs().maxCoeff() + minv_norm * (s.tau - h).cwiseAbs().maxCoeff();
}

struct Comparison {
  double error = 0;  // ‖Δq̈‖∞
  double scale = 0;
  double qdd = 0;    // ‖q̈‖∞ (saltus)
  double relative() const { return error / scale; }
};

Comparison compare(const Model<double>& model, BulletMultiBody& bullet, const State& s) {
  Data<double> data(model);
  const Eigen::VectorXd ours = aba(model, data, s.q, s.v, s.tau);
  const Eigen::VectorXd theirs = bullet.forwardDynamics(s.q, s.v, s.tau);
  EXPECT_TRUE(theirs.allFinite());
  return {(ours - theirs).cwiseAbs().maxCoeff(), accelerationScale(model, s, ours), ours.cwiseAbs().maxCoeff()};
}

struct Worst {
  double relative = 0;       // max ‖Δq̈‖∞ / scale
  double plain = 0;          // max ‖Δq̈‖∞ / ‖q̈‖∞
  double scale_ratio = 0;    // max scale / ‖q̈‖∞
};

// Runs numSeeds() random robots with 2..12 moving joints on the given base; reports the worst errors.
void randomRobots(BaseType base, FreeBase free_base, unsigned seed0, const char* label) {
  Worst worst;
  for (int k = 0, n = numSeeds(); k < n; ++k) {
    std::mt19937 rng(seed0 + k);
    const int moving = 2 + k % 11;
    const RandomUrdfRobot robot = randomUrdfRobot(rng, moving);
    const Model<double> model = loadUrdfString(robot.urdf, base, "random_robot_" + std::to_string(seed0 + k));
    BulletMultiBody bullet(model, free_base);
    bool printed = false;
    for (int trial = 0; trial < 4; ++trial) {
      const State s = randomState(rng, model);
      const Comparison c = compare(model, bullet, s);
      if (!(c.relative() <= kRelTol)) {  // the URDF text once per robot, to reproduce
        ADD_FAILURE() << "seed " << seed0 + k << ", " << moving << " moving joints, base " << toString(base)
                      << ", trial " << trial << ": ‖Δq̈‖∞ = " << c.error << " at scale " << c.scale
                      << " (relative " << c.relative() << " > " << kRelTol << ")\n"
                      << (printed ? std::string() : robot.urdf);
        printed = true;
      }
      worst.relative = std::max(worst.relative, c.relative());
      worst.plain = std::max(worst.plain, c.error / c.qdd);
      worst.scale_ratio = std::max(worst.scale_ratio, c.scale / c.qdd);
    }
  }
  std::printf("[ worst    ] %s: ‖Δq̈‖∞/scale %.2g, ‖Δq̈‖∞/‖q̈‖∞ %.2g (scale/‖q̈‖∞ up to %.2g)\n", label,
              worst.relative, worst.plain, worst.scale_ratio);
}

// ---------------------------------------------------------------------------------------------
// Closed forms through Bullet.

// A compound pendulum on a y hinge whose joint frame is rotated and offset, plus a slider.
TEST(BulletDynamics, PendulumClosedForm) {
  const double m = 1.7, l = 0.6, Iyy = 0.09, g = 9.81;
  // Body frame: com at (l, 0, 0); the hinge (about body y) sits at 0.3 m along world x. The
  // inertia is diagonal about the com, with distinct moments on x and z so a wrong axis shows.
  ModelBuilder b("pendulum");
  b.addLink("world");
  Eigen::Matrix3d Ic = Eigen::Vector3d(0.05, Iyy, 0.11).asDiagonal();
  b.addLink("bob", m, Eigen::Vector3d(l, 0, 0), Ic);
  JointSpec j;
  j.name = "hinge";
  j.type = LinkJointType::Continuous;
  j.parent = "world";
  j.child = "bob";
  j.p_PJ = Eigen::Vector3d(0.3, 0, 0);
  j.axis = Eigen::Vector3d::UnitY();
  b.addJoint(j);
  const Model<double> model = b.build();
  BulletMultiBody bullet(model);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 10; ++trial) {
    const double q = std::uniform_real_distribution<double>(-M_PI, M_PI)(rng);
    const double v = std::uniform_real_distribution<double>(-3, 3)(rng);
    const double tau = std::uniform_real_distribution<double>(-4, 4)(rng);
    // com in world: Ry(q) (l, 0, 0) = (l cos q, 0, −l sin q); moment of m g (−z) about +y is
    // ρ_z F_x − ρ_x F_z = m g l cos q. No velocity term for a fixed axis.
    const double expected = (tau + m * g * l * std::cos(q)) / (Iyy + m * l * l);
    const Eigen::VectorXd qdd = bullet.forwardDynamics(Eigen::VectorXd::Constant(1, q), Eigen::VectorXd::Constant(1, v),
                                                       Eigen::VectorXd::Constant(1, tau));
    EXPECT_NEAR(qdd[0], expected, 1e-12 * (1 + std::abs(expected))) << "q = " << q;
    Data<double> data(model);
    const Eigen::VectorXd ours = aba(model, data, Eigen::VectorXd::Constant(1, q), Eigen::VectorXd::Constant(1, v),
                                     Eigen::VectorXd::Constant(1, tau));
    EXPECT_NEAR(ours[0], expected, 1e-12 * (1 + std::abs(expected)));
  }
}

TEST(BulletDynamics, SliderClosedForm) {
  // A body on a slider whose axis, in a rotated joint frame, points partly downhill:
  // ẍ = (τ + m g·a_world) / m, independent of x and ẋ.
  const double m = 2.3;
  ModelBuilder b("slider");
  b.addLink("world");
  b.addLink("block", m, Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0.02, 0.03, 0.04).asDiagonal());
  JointSpec j;
  j.name = "slide";
  j.type = LinkJointType::Prismatic;
  j.parent = "world";
  j.child = "block";
  j.R_PJ = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  j.p_PJ = Eigen::Vector3d(0.5, 0.1, -0.2);
  j.axis = Eigen::Vector3d(1, 0, -1);
  b.addJoint(j);
  const Model<double> model = b.build();
  const Eigen::Vector3d a_world = j.R_PJ * j.axis.normalized();
  BulletMultiBody bullet(model);
  for (double tau : {-3.0, 0.0, 1.5}) {
    const double expected = (tau + m * model.gravity.dot(a_world)) / m;
    const Eigen::VectorXd qdd = bullet.forwardDynamics(Eigen::VectorXd::Constant(1, 0.7), Eigen::VectorXd::Constant(1, -1.1),
                                                       Eigen::VectorXd::Constant(1, tau));
    EXPECT_NEAR(qdd[0], expected, 1e-12 * (1 + std::abs(expected)));
  }
}

// A single free rigid body: com falls with g, ω̇ = I_w⁻¹ (τ_c − ω × I_w ω) (Euler's equations),
// through Bullet's native floating base and back through the Euler-rate conversion. ω̇ and the
// com acceleration are recovered from q̈ by differentiating the Euler map numerically here,
// independently of the conversion inside BulletMultiBody.
TEST(BulletDynamics, FreeBodyClosedForm) {
  using saltus::testing::eulerAngularVelocity;
  using saltus::testing::eulerRotation;
  const double m = 1.3;
  const Eigen::Vector3d com(0.2, -0.1, 0.15);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -1, 2).normalized()).toRotationMatrix();
  const Eigen::Matrix3d Ic = Q * Eigen::Vector3d(0.05, 0.08, 0.11).asDiagonal() * Q.transpose();
  const Model<double> model = saltus::testing::freeBodyModel(m, com, Ic);
  std::mt19937 rng(11);
  for (FreeBase mode : {FreeBase::Native, FreeBase::VirtualLinks}) {
    BulletMultiBody bullet(model, mode);
    for (int trial = 0; trial < 5; ++trial) {
      State s = randomState(rng, model);
      s.tau.setZero();  // no applied wrench: torque-free rotation, free fall of the com
      const Eigen::VectorXd qdd = bullet.forwardDynamics(s.q, s.v, s.tau);
      const Eigen::Matrix3d R = eulerRotation(s.q);
      const Eigen::Matrix3d Iw = R * Ic * R.transpose();
      const Eigen::Vector3d w = eulerAngularVelocity(s.q, s.v);
      const Eigen::Vector3d wd_expected = Iw.ldlt().solve(-w.cross(Iw * w));
      // Along the trajectory q(t) = q + v t + q̈ t²/2: ω̇ = d/dt ω(q(t), v + q̈ t) at t = 0,
      // and the com acceleration d²/dt² (p + R c); central differences, h = 1e-4.
      const double h = 1e-4;
      auto qt = [&](double t) { return Eigen::VectorXd(s.q + s.v * t + 0.5 * qdd * t * t); };
      auto vt = [&](double t) { return Eigen::VectorXd(s.v + qdd * t); };
      const Eigen::Vector3d wd = (eulerAngularVelocity(qt(h), vt(h)) - eulerAngularVelocity(qt(-h), vt(-h))) / (2 * h);
      auto comAt = [&](double t) {
        const Eigen::VectorXd x = qt(t);
        return Eigen::Vector3d(x.head<3>() + eulerRotation(x) * com);
      };
      const Eigen::Vector3d acom = (comAt(h) - 2 * comAt(0) + comAt(-h)) / (h * h);
      EXPECT_LT((wd - wd_expected).norm(), 1e-5 * (1 + wd_expected.norm())) << "trial " << trial;
      EXPECT_LT((acom - model.gravity).norm(), 1e-4) << "trial " << trial << ": " << acom.transpose();
      Data<double> data(model);
      const Eigen::VectorXd ours = aba(model, data, s.q, s.v, s.tau);
      EXPECT_LT((ours - qdd).cwiseAbs().maxCoeff(), kRelTol * (1 + qdd.cwiseAbs().maxCoeff()));
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The mapping itself: Bullet's com positions equal saltus' at random configurations.

TEST(BulletDynamics, ComPositionsAgree) {
  for (BaseType base : {BaseType::Fixed, BaseType::Free, BaseType::FreeQuaternion}) {
    for (int k = 0; k < 5; ++k) {
      std::mt19937 rng(100 + k);
      const RandomUrdfRobot robot = randomUrdfRobot(rng, 6);
      const Model<double> model = loadUrdfString(robot.urdf, base);
      BulletMultiBody bullet(model);
      const State s = randomState(rng, model);
      bullet.forwardDynamics(s.q, s.v, s.tau);
      Data<double> data(model);
      forwardKinematics(model, data, s.q);
      for (int i = 0; i < model.nbodies(); ++i) {
        const auto& X = data.X_world[i];
        const Eigen::Vector3d c = X.r + X.E.transpose() * (model.inertia[i].h / model.inertia[i].m);
        EXPECT_LT((bullet.comPosition(i) - c).norm(), 1e-12) << "body " << model.body_name[i];
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Random robots from URDF text.

TEST(BulletDynamics, RandomUrdfFixedBase) {
  randomRobots(BaseType::Fixed, FreeBase::Native, 1000, "fixed base");
}

TEST(BulletDynamics, RandomUrdfFreeBaseNative) {
  randomRobots(BaseType::Free, FreeBase::Native, 2000, "free base (Bullet floating base)");
}

TEST(BulletDynamics, RandomUrdfQuaternionBase) {
  randomRobots(BaseType::FreeQuaternion, FreeBase::Native, 2000, "quaternion base (Bullet floating base)");
}

TEST(BulletDynamics, RandomUrdfFreeBaseVirtualLinks) {
  randomRobots(BaseType::Free, FreeBase::VirtualLinks, 2000, "free base (massless Bullet links)");
}

TEST(BulletDynamics, RandomUrdfPlanarBase) {
  randomRobots(BaseType::Planar, FreeBase::Native, 3000, "planar base (massless Bullet links)");
}

// The legged benchmarks' models (models/biped, models/monopod) against Bullet at random states:
// the planar biped on its planar base, the monopod on its free base with its massless Hooke cross.
TEST(BulletDynamics, LeggedBenchmarkModelsAgreeAtRandomStates) {
  const struct {
    const char* file;
    BaseType base;
  } models[] = {{"/models/biped/biped.urdf", BaseType::Planar}, {"/models/monopod/monopod.urdf", BaseType::Free}};
  for (const auto& m : models) {
    const Model<double> model = loadUrdfFile(std::string(SALTUS_SOURCE_DIR) + m.file, m.base);
    BulletMultiBody bullet(model, FreeBase::Native);
    std::mt19937 rng(6000);
    double worst = 0;
    for (int trial = 0; trial < 50; ++trial) {
      const State s = randomState(rng, model);
      const Comparison c = compare(model, bullet, s);
      EXPECT_LE(c.relative(), kRelTol) << m.file << ", trial " << trial;
      worst = std::max(worst, c.relative());
    }
    std::printf("[ worst    ] %s: ‖Δq̈‖∞/scale %.2g\n", m.file, worst);
  }
}

// The URDF reader and the builder given the same robot produce the same model (up to the order
// of coordinates: the reader orders siblings by joint name).
TEST(BulletDynamics, RandomUrdfMatchesBuilder) {
  for (int k = 0; k < 20; ++k) {
    std::mt19937 rng(4000 + k);
    const RandomUrdfRobot robot = randomUrdfRobot(rng, 2 + k % 11);
    const Model<double> a = loadUrdfString(robot.urdf, BaseType::Fixed);
    const Model<double> b = robot.builder.build(BaseType::Fixed);
    ASSERT_EQ(a.nv(), b.nv());
    for (int i = 0; i < a.nv(); ++i) {
      const int jc = b.coordinateIndex(a.coordinate_name[i]);
      ASSERT_GE(jc, 0) << a.coordinate_name[i];
      const int j = b.coordinate_body[jc];  // bodies of the coordinates (a fixed base: the same indices)
      ASSERT_EQ(a.coordinate_body[i], i);
      const int pa = a.parent[i], pb = b.parent[j];
      EXPECT_EQ(pa < 0 ? "" : a.coordinate_name[pa], pb < 0 ? "" : b.coordinate_name[pb]);
      EXPECT_EQ(a.joint_type[i], b.joint_type[j]);
      EXPECT_LT((a.axis[i] - b.axis[j]).norm(), 1e-14) << a.coordinate_name[i];
      EXPECT_LT((a.X_tree[i].E - b.X_tree[j].E).norm(), 1e-14) << a.coordinate_name[i];
      EXPECT_LT((a.X_tree[i].r - b.X_tree[j].r).norm(), 1e-14) << a.coordinate_name[i];
      EXPECT_NEAR(a.inertia[i].m, b.inertia[j].m, 1e-14);
      EXPECT_LT((a.inertia[i].h - b.inertia[j].h).norm(), 1e-13) << a.coordinate_name[i];
      EXPECT_LT((a.inertia[i].I - b.inertia[j].I).norm(), 1e-13) << a.coordinate_name[i];
    }
  }
}

// The comparison can fail: a model that differs by one part in a million in one mass (or by a
// wrong joint sign) is told apart from the original.
TEST(BulletDynamics, ModelPerturbationIsDetected) {
  std::mt19937 rng(5000);
  const RandomUrdfRobot robot = randomUrdfRobot(rng, 6);
  const Model<double> model = loadUrdfString(robot.urdf);
  const State s = randomState(rng, model);
  Model<double> heavier = model;
  const int i = model.nbodies() - 1;
  const double f = 1 + 1e-6;
  heavier.inertia[i] = {model.inertia[i].m * f, model.inertia[i].h * f, model.inertia[i].I * f};
  BulletMultiBody bullet_heavier(heavier);
  const Comparison c = compare(model, bullet_heavier, s);
  EXPECT_GT(c.relative(), 10 * kRelTol) << "a 1e-6 mass change went unnoticed";

  Model<double> flipped = model;
  flipped.axis[0] = -flipped.axis[0];
  BulletMultiBody bullet_flipped(flipped);
  EXPECT_GT(compare(model, bullet_flipped, s).relative(), 1e-3);
}

}  // namespace
