// The multi-coordinate base joints (Planar, Free) against the same mechanism built from
// one-coordinate joints through massless links (the builder accepts massless intermediate
// links): every algorithm gives the same results to round-off, coordinate by coordinate.
#include "dynamics/joint.hpp"

#include <gtest/gtest.h>

#include <set>

#include "dynamics/aba.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/jacobian.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "tests/support/random_model.hpp"

namespace saltus::dynamics {
namespace {

void expectNear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tol, const std::string& what) {
  EXPECT_LT((a - b).norm(), tol * (1 + b.norm())) << what;
}

TEST(Joint, BaseJointEqualsChainOfOneCoordinateJoints) {
  for (BaseType base : {BaseType::Planar, BaseType::Free}) {
    for (int k = 0; k < 6; ++k) {
      std::mt19937 rng(900 + k);
      const ModelBuilder tree = testing::randomTreeBuilder(rng, 2 + 2 * k);
      const Model<double> joint = tree.build(base);
      const Model<double> chain = testing::explicitChain(tree, base);
      const int n = joint.nv();
      ASSERT_EQ(chain.nv(), n);
      ASSERT_EQ(joint.coordinate_name, chain.coordinate_name);
      const int nb = joint.nbodies(), offset = chain.nbodies() - nb;  // the chain's massless links
      ASSERT_EQ(offset, joint.n_base - 1);
      EXPECT_EQ(joint.joint_type[0], base == BaseType::Free ? JointType::Free : JointType::Planar);
      EXPECT_EQ(joint.num_coordinates[0], joint.n_base);
      Data<double> dj(joint), dc(chain);
      for (int trial = 0; trial < 3; ++trial) {
        const Eigen::VectorXd q = testing::randomVector(rng, n, 1.2), v = testing::randomVector(rng, n, 2),
                              a = testing::randomVector(rng, n, 2), tau = testing::randomVector(rng, n, 3);
        const std::string what = std::string(toString(base)) + " seed " + std::to_string(900 + k);
        expectNear(rnea(joint, dj, q, v, a), rnea(chain, dc, q, v, a), 1e-12, what + " rnea");
        expectNear(nonLinearEffects(joint, dj, q, v), nonLinearEffects(chain, dc, q, v), 1e-12, what + " h");
        expectNear(crba(joint, dj, q), crba(chain, dc, q), 1e-12, what + " crba");
        expectNear(aba(joint, dj, q, v, tau), aba(chain, dc, q, v, tau), 1e-10, what + " aba");
        forwardKinematics(joint, dj, q, v, a);
        forwardKinematics(chain, dc, q, v, a);
        for (int i = 0; i < nb; ++i) {
          const int ic = i + offset;
          EXPECT_LT((dj.X_world[i].E - dc.X_world[ic].E).norm(), 1e-13) << what;
          EXPECT_LT((dj.X_world[i].r - dc.X_world[ic].r).norm(), 1e-13) << what;
          EXPECT_LT((dj.v[i].vector() - dc.v[ic].vector()).norm(), 1e-12) << what;
          EXPECT_LT((dj.a[i].vector() - dc.a[ic].vector()).norm(), 1e-12) << what;
          EXPECT_LT((dj.a_bias[i].vector() - dc.a_bias[ic].vector()).norm(), 1e-12) << what;
          Mat6X<double> Jj(6, n), Jc(6, n);
          bodyJacobianWorld(joint, dj, i, Jj);
          bodyJacobianWorld(chain, dc, ic, Jc);
          expectNear(Jj, Jc, 1e-13, what + " body Jacobian");
        }
        EXPECT_NEAR(kineticEnergy(joint, dj), kineticEnergy(chain, dc), 1e-12);
        EXPECT_NEAR(potentialEnergy(joint, dj), potentialEnergy(chain, dc), 1e-12);
        EXPECT_LT((centerOfMass(joint, dj) - centerOfMass(chain, dc)).norm(), 1e-13);
        DerivativeData<8> ddj(joint), ddc(chain);
        rneaDerivatives(joint, ddj, q, v, a);
        rneaDerivatives(chain, ddc, q, v, a);
        expectNear(ddj.dtau_dq, ddc.dtau_dq, 1e-11, what + " dtau/dq");
        expectNear(ddj.dtau_dv, ddc.dtau_dv, 1e-11, what + " dtau/dv");
      }
    }
  }
}

TEST(Joint, TranslationCoordinates) {
  std::mt19937 rng(5);
  const ModelBuilder tree = testing::randomTreeBuilder(rng, 4);
  const Model<double> free = tree.build(BaseType::Free), planar = tree.build(BaseType::Planar);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(free.isTranslation(k), k < 3) << k;
  for (int k = 0; k < 3; ++k) EXPECT_EQ(planar.isTranslation(k), k < 2) << k;
  for (int k = 6; k < free.nv(); ++k)
    EXPECT_EQ(free.isTranslation(k), free.joint_type[free.coordinate_body[k]] == JointType::Prismatic);
  // The coordinate tree: base coordinates in a chain, each joint after its parent body's last.
  for (int k = 0; k < free.nv(); ++k) {
    const int b = free.coordinate_body[k], p = free.parent[b];
    const int expected = k > free.first_coordinate[b] ? k - 1 : p < 0 ? -1 : free.first_coordinate[p] + free.num_coordinates[p] - 1;
    EXPECT_EQ(free.parent_coordinate[k], expected);
  }
}

// The model with every one-coordinate joint on the generic path (a general transform from
// jointTransformUp, S_i from the axis) and no turned frames: the reference for the specialised
// joint kernels.
Model<double> withGenericKernels(Model<double> model) {
  for (int i = 0; i < model.nbodies(); ++i)
    if (model.joint_kernel[i] != kMultiJoint) model.joint_kernel[i] = kGenericJoint, model.axis_sign[i] = 1.0;
  prepareTurnedFrames(model);
  for (const TurnedFrame<double>& t : model.turned_frame) EXPECT_TRUE(t.Q.isIdentity(0) && !t.turned);
  return model;
}

TEST(Joint, KernelsFollowAxesAndJointOrigins) {
  ModelBuilder b("kinds");
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  b.addLink("a", 1, Eigen::Vector3d::Zero(), I);
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  struct Case {
    LinkJointType type;
    Eigen::Vector3d axis;
    bool rotated;
    int kernel;
    double sign;
  };
  const std::vector<Case> cases = {
      {LinkJointType::Revolute, Eigen::Vector3d::UnitX(), false, kAxisJoint + 0, 1},
      {LinkJointType::Continuous, -Eigen::Vector3d::UnitY(), false, kAxisJoint + 1, -1},
      {LinkJointType::Revolute, Eigen::Vector3d::UnitZ(), true, kRotatedAxisJoint + 2, 1},
      {LinkJointType::Revolute, -Eigen::Vector3d::UnitX(), true, kRotatedAxisJoint + 0, -1},
      {LinkJointType::Revolute, Eigen::Vector3d(1, 1, 0), false, kGenericJoint, 1},
      {LinkJointType::Prismatic, Eigen::Vector3d::UnitZ(), false, kGenericJoint, 1}};
  std::string parent = "a";
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const std::string child = "l" + std::to_string(k);
    b.addLink(child, 1, Eigen::Vector3d::Zero(), I);
    JointSpec j;
    j.name = "j" + std::to_string(k);
    j.type = cases[k].type;
    j.parent = parent;
    j.child = child;
    j.axis = cases[k].axis;
    j.R_PJ = cases[k].rotated ? turned : Eigen::Matrix3d::Identity();
    j.p_PJ = Eigen::Vector3d(0.1, 0.2, 0.3);
    if (j.type != LinkJointType::Continuous) j.limits = {-1, 1, 10, 10};
    b.addJoint(j);
    parent = child;
  }
  const Model<double> model = b.build(BaseType::Free);
  EXPECT_EQ(model.joint_kernel[0], kMultiJoint);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    EXPECT_EQ(model.joint_kernel[k + 1], cases[k].kernel) << k;
    EXPECT_EQ(model.axis_sign[k + 1], cases[k].sign) << k;
  }
  // A chain: every subtree runs to the end.
  for (int i = 0; i < model.nbodies(); ++i) EXPECT_EQ(model.subtree_end[i], model.nbodies());
  // Turned frames (model.hpp, TurnedFrame): none before the rotated joint 3; the axis joints are
  // axis joints from their parents' frames.
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(model.turned_frame[i].Q.isIdentity(0)) << i;
    EXPECT_EQ(model.turned_frame[i].kernel, i == 0 ? kMultiJoint : kAxisJoint + i - 1) << i;
  }
  EXPECT_EQ(model.turned_frame[3].kernel, kRotatedAxisJoint + 2);
  EXPECT_FALSE(model.turned_frame[3].turned);
}

// Joint origins at multiples of π/2 written to 12 digits, as in the benchmark URDF files, are made
// exact signed permutations, and the axis joints after them become axis joints about the turned
// axis: with Q_i = Q_λ E_Tᵀ, Q_i σ e_K = σ' e_K'.
TEST(Joint, TurnedFramesFollowSignedPermutationOrigins) {
  ModelBuilder b("turned");
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  b.addLink("a", 1, Eigen::Vector3d::Zero(), I);
  const double half_pi = 1.57079632679;  // π/2 − 4.9e-12
  const auto rpy = [](double r, double p, double y) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
                           Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()));
  };
  struct Case {
    Eigen::Matrix3d R_PJ;
    Eigen::Vector3d axis;
    bool snapped;   // R_PJ made exact
    int kernel;     // turned kernel
    double sign;    // σ'
  };
  // Q_i = R_PJ of the joints so far: Rx(π/2), then Rx(π/2) Ry(−π/2), unchanged by the joint with
  // no rotation; the last origin is 1e-8 rad off and keeps its frame (Q = 1).
  const std::vector<Case> cases = {
      {rpy(half_pi, 0, 0), Eigen::Vector3d::UnitZ(), true, kAxisJoint + 1, -1},       // Rx(π/2) e_z = −e_y
      {rpy(0, -half_pi, 0), -Eigen::Vector3d::UnitX(), true, kAxisJoint + 1, 1},      // Rx(π/2) Ry(−π/2) (−e_x) = e_y
      {I, Eigen::Vector3d::UnitY(), true, kAxisJoint + 2, 1},                         // Rx(π/2) Ry(−π/2) e_y = e_z
      {rpy(1e-8, half_pi, 0), Eigen::Vector3d::UnitZ(), false, kRotatedAxisJoint + 2, 1}};
  std::string parent = "a";
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const std::string child = "l" + std::to_string(k);
    b.addLink(child, 1, Eigen::Vector3d::Zero(), I);
    JointSpec j;
    j.name = "j" + std::to_string(k);
    j.type = LinkJointType::Continuous;
    j.parent = parent;
    j.child = child;
    j.axis = cases[k].axis;
    j.R_PJ = cases[k].R_PJ;
    j.p_PJ = Eigen::Vector3d(0.1, 0.2, 0.3);
    b.addJoint(j);
    parent = child;
  }
  const Model<double> model = b.build(BaseType::Fixed);
  Eigen::Matrix3d Q = I;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const Eigen::Matrix3d& E_T = model.X_tree[k].E;
    const TurnedFrame<double>& t = model.turned_frame[k];
    SCOPED_TRACE(k);
    EXPECT_EQ(isSignedPermutationRotation(E_T), cases[k].snapped);
    EXPECT_LT((E_T - cases[k].R_PJ.transpose()).cwiseAbs().maxCoeff(), 1e-11);
    if (!cases[k].snapped) {
      EXPECT_EQ(snapToSignedPermutation(E_T), E_T);
      EXPECT_EQ(t.kernel, cases[k].kernel);
      EXPECT_TRUE(t.Q.isIdentity(0));
      EXPECT_TRUE(t.parent_turned);
      continue;
    }
    Q = Q * E_T.transpose();
    EXPECT_EQ(t.Q, Q);
    EXPECT_EQ(t.kernel, cases[k].kernel);
    EXPECT_EQ(t.sign, cases[k].sign);
    // σ' e_K' = Q_i σ e_K.
    EXPECT_EQ(Eigen::Vector3d(t.sign * Eigen::Vector3d::Unit(t.kernel - kAxisJoint)),
              Eigen::Vector3d(Q * (model.axis_sign[k] * Eigen::Vector3d::Unit(model.joint_kernel[k] % 3))));
  }
  // The CRBA in the turned frames against the generic path.
  const Model<double> generic = withGenericKernels(model);
  Data<double> d(model), dg(generic);
  std::mt19937 rng(4);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = testing::randomVector(rng, model.nv(), 3);
    expectNear(crba(model, d, q), crba(generic, dg, q), 1e-13, "crba");
  }
}

TEST(Joint, SubtreesAreContiguousRanges) {
  std::mt19937 rng(31);
  const Model<double> model = testing::randomTreeBuilder(rng, 25).build(BaseType::Free);
  for (int i = 0; i < model.nbodies(); ++i)
    for (int j = 0; j < model.nbodies(); ++j)
      EXPECT_EQ(model.isAncestor(i, j), j >= i && j < model.subtree_end[i]) << i << " " << j;
}

// Each specialised joint kernel (revolute about ±x, ±y, ±z, with and without a rotation in the
// joint origin) and the CRBA's turned frames against the generic path, on random trees on each
// base. The trees have joint origins at multiples of π/2 for joints about all three axes with both
// signs, turned frames that turn them to all three axes with both signs, and joints with general
// origins below turned frames.
TEST(Joint, AxisKernelsEqualGenericPath) {
  std::set<int> permuted_origin_axes, turned_axes;  // 2 K + (σ > 0)
  int rotated_under_turned = 0;
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int seed = 0; seed < 6; ++seed) {
      std::mt19937 rng(1200 + seed);
      const Model<double> model = testing::randomAxisTreeBuilder(rng, 6 + 4 * seed).build(base);
      const Model<double> generic = withGenericKernels(model);
      int axis_joints = 0, rotated_joints = 0;
      for (int i = 0; i < model.nbodies(); ++i) {
        const int kernel = model.joint_kernel[i];
        axis_joints += kernel >= kAxisJoint && kernel < kAxisJoint + 3;
        rotated_joints += kernel >= kRotatedAxisJoint && kernel < kRotatedAxisJoint + 3;
        const TurnedFrame<double>& t = model.turned_frame[i];
        const int axis = 2 * (kernel % 3) + (model.axis_sign[i] > 0);
        if (kernel >= kRotatedAxisJoint && kernel < kGenericJoint && isSignedPermutationRotation(model.X_tree[i].E))
          permuted_origin_axes.insert(axis);
        if (t.turned && !t.Q.isIdentity(0)) turned_axes.insert(2 * (t.kernel - kAxisJoint) + (t.sign > 0));
        rotated_under_turned += !t.turned && t.parent_turned && kernel != kMultiJoint;
      }
      ASSERT_GT(axis_joints, 0);
      ASSERT_GT(rotated_joints, 0);
      const int n = model.nv();
      Data<double> d(model), dg(generic);
      for (int trial = 0; trial < 3; ++trial) {
        const Eigen::VectorXd q = testing::randomVector(rng, n, 3), v = testing::randomVector(rng, n, 2),
                              a = testing::randomVector(rng, n, 2), tau = testing::randomVector(rng, n, 3);
        const std::string what = std::string(toString(base)) + " seed " + std::to_string(1200 + seed);
        expectNear(rnea(model, d, q, v, a), rnea(generic, dg, q, v, a), 1e-12, what + " rnea");
        for (int i = 0; i < model.nbodies(); ++i) {
          EXPECT_LT((d.X_up[i].matrix() - dg.X_up[i].matrix()).norm(), 1e-12) << what << " X_up " << i;
          EXPECT_LT((d.v[i].vector() - dg.v[i].vector()).norm(), 1e-12) << what << " v " << i;
          EXPECT_LT((d.a_gf[i].vector() - dg.a_gf[i].vector()).norm(), 1e-12) << what << " a " << i;
        }
        expectNear(nonLinearEffects(model, d, q, v), nonLinearEffects(generic, dg, q, v), 1e-12, what + " h");
        expectNear(crba(model, d, q), crba(generic, dg, q), 1e-12, what + " crba");
        for (int i = 0; i < model.nbodies(); ++i)  // in the body frames for the other algorithms
          EXPECT_LT((d.X_up[i].matrix() - dg.X_up[i].matrix()).norm(), 1e-12) << what << " crba X_up " << i;
        expectNear(aba(model, d, q, v, tau), aba(generic, dg, q, v, tau), 1e-12, what + " aba");
        DerivativeData<8> dd(model), ddg(generic);
        rneaDerivatives(model, dd, q, v, a);
        rneaDerivatives(generic, ddg, q, v, a);
        expectNear(dd.dtau_dq, ddg.dtau_dq, 1e-11, what + " dtau/dq");
        abaDerivatives(model, dd, q, v, tau);
        abaDerivatives(generic, ddg, q, v, tau);
        expectNear(dd.dqdd_dq, ddg.dqdd_dq, 1e-10, what + " dqdd/dq");
      }
    }
  }
  EXPECT_EQ(permuted_origin_axes.size(), 6u);
  EXPECT_EQ(turned_axes.size(), 6u);
  EXPECT_GT(rotated_under_turned, 0);
}

}  // namespace
}  // namespace saltus::dynamics
