// World translations (dynamics/world_translation.hpp) on random trees, against what they claim:
// the dynamics and the bodies' rotations do not change when one moves.
#include "dynamics/world_translation.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "tests/support/random_model.hpp"

namespace saltus::dynamics {
namespace {

void expectNear(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double tol, const std::string& what) {
  EXPECT_LT((a - b).norm(), tol * (1 + b.norm())) << what;
}

// World translations (isWorldTranslation): a base's x, y, z, the prismatic joints from
// the world that stand for them (explicitChain), and a prismatic joint of the random tree when
// everything above it translates. Shifting one, or its rate, leaves τ = RNEA(q, q̇, q̈) and every
// body's rotation as they were and moves every body of its subtree by the same vector; shifting
// any other coordinate, or its rate, changes τ (a prismatic joint under a revolute one included).
TEST(WorldTranslation, LeavesTheDynamicsAsItWas) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-1, 1);
  int world = 0, tree_world = 0, other_translations = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const ModelBuilder tree = testing::randomTreeBuilder(rng, 4);
    for (const BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
      for (const bool chain : {false, true}) {
        if (chain && base == BaseType::Fixed) continue;
        const Model<double> model = chain ? testing::explicitChain(tree, base) : tree.build(base);
        const int n = model.nv(), n_base = base == BaseType::Free ? 6 : base == BaseType::Planar ? 3 : 0;
        for (int k = 0; k < n_base; ++k) EXPECT_EQ(isWorldTranslation(model, k), model.isTranslation(k)) << k;
        Data<double> data(model);
        Eigen::VectorXd q(n), v(n), a(n);
        for (int i = 0; i < n; ++i) q[i] = U(rng), v[i] = U(rng), a[i] = U(rng);
        const Eigen::VectorXd tau = rnea(model, data, q, v, a);
        forwardKinematics(model, data, q);
        const std::vector<Transform<double>> X0 = data.X_world;
        for (int k = 0; k < n; ++k) {
          Eigen::VectorXd q1 = q, v1 = v;
          q1[k] += 0.4;
          v1[k] += 0.7;
          const Eigen::VectorXd tau_q = rnea(model, data, q1, v, a), tau_v = rnea(model, data, q, v1, a);
          if (!isWorldTranslation(model, k)) {
            EXPECT_GT((tau_q - tau).norm() + (tau_v - tau).norm(), 1e-9) << k;
            other_translations += model.isTranslation(k);
            continue;
          }
          ++world;
          tree_world += k >= n_base && !chain;
          expectNear(tau_q, tau, 1e-12, "tau after q_" + std::to_string(k));
          expectNear(tau_v, tau, 1e-12, "tau after v_" + std::to_string(k));
          forwardKinematics(model, data, q1);
          const int body = model.coordinate_body[k];
          const Eigen::Vector3d shift = data.X_world[body].r - X0[body].r;
          EXPECT_NEAR(shift.norm(), 0.4, 1e-12) << k;
          for (int b = 0; b < model.nbodies(); ++b) {
            EXPECT_LT((data.X_world[b].E - X0[b].E).norm(), 1e-14) << k << " body " << b;
            const bool moved = b >= body && b < model.subtree_end[body];
            EXPECT_LT((data.X_world[b].r - X0[b].r - (moved ? shift : Eigen::Vector3d::Zero())).norm(), 1e-12)
                << k << " body " << b;
          }
        }
      }
    }
  }
  EXPECT_GT(world, 0);
  EXPECT_GT(tree_world, 0);          // a prismatic joint of the tree hung from the world
  EXPECT_GT(other_translations, 0);  // a prismatic joint under a revolute one
}

}  // namespace
}  // namespace saltus::dynamics
