// The transcription (collocation/transcription.hpp): the reduced forms of its rows against the
// general functors (restitution, joint-stop gaps), the penalty weights of the feasibility stage,
// the first-order mesh, the extent rows of a body's plane, and what it refuses.
#include "collocation/transcription.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "collocation/nlp.hpp"
#include "contact/kinematics.hpp"
#include "scene/scenario.hpp"
#include "tests/support/problems.hpp"
#include "tests/support/transcription_points.hpp"

namespace saltus::collocation {
namespace {

using testing::randomPoint;
using testing::smallLegged;

// The restitution balance (9a) in its reduced forms against the two-sided functor on the full
// state at both sides of the boundary: a stop's is linear in four variables, a contact with e = 0
// drops the state before the jump. The biped has both (feet e = 0, twelve stops), here with a
// restitution of 0.3 given to the stops; the ball on the paddle keeps both sides (e = 0.4).
void checkRestitutionForms(const Problem& p, int expected_stops, int expected_one_sided, int expected_two_sided) {
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd x = randomPoint(t, 17);
  const int n = t.models().model<double>().nv();
  int stops = 0, one_sided = 0, two_sided = 0;
  for (int e = 1; e < t.elements(); ++e) {
    const auto& after = t.layout()[e].points[0];
    const auto& prev = t.layout()[e - 1];
    const auto& before = prev.points[prev.end];
    for (std::size_t c = 0; c < t.contacts().size(); ++c) {
      const int bi = t.layout()[e].contacts[c].restitution_block;
      if (bi < 0) continue;
      const Block& b = t.blocks()[bi];
      Eigen::VectorXd local(b.vars.size());
      for (std::size_t j = 0; j < b.vars.size(); ++j) local[j] = x[b.vars[j]];
      double reduced = 0;
      b.f->value(local.data(), &reduced);
      Eigen::VectorXd full(4 * n + 2);
      full << x.segment(after.q, n), x.segment(after.v, n), x.segment(before.q, n), x.segment(before.v, n),
          x[t.layout()[e].contacts[c].a_plus], x[t.layout()[e].contacts[c].a_minus];
      const AdFunction<RestitutionBalance> two_sided_form(RestitutionBalance{&t.models(), &t.contacts()[c], true});
      double expected = 0;
      two_sided_form.value(full.data(), &expected);
      EXPECT_NEAR(reduced, expected, 1e-12 * (1 + std::abs(expected))) << t.constraintNames()[b.row];
      if (t.contacts()[c].isStop()) {
        ++stops;
        EXPECT_TRUE(b.f->linear());
        EXPECT_EQ(b.f->inputs(), 4);
      } else if (t.contacts()[c].restitution == 0) {
        ++one_sided;
        EXPECT_EQ(b.f->inputs(), 2 * n + 2);
      } else {
        ++two_sided;
        EXPECT_EQ(b.f->inputs(), 4 * n + 2);
      }
    }
  }
  EXPECT_EQ(stops, expected_stops);
  EXPECT_EQ(one_sided, expected_one_sided);
  EXPECT_EQ(two_sided, expected_two_sided);
}

TEST(Transcription, RestitutionFormsAgreeWithTheTwoSidedBalance) {
  Problem biped = smallLegged("biped_stop", 3);
  for (auto& stop : biped.scene.limits) stop.restitution = 0.3;
  checkRestitutionForms(biped, 2 * 12, 2 * 2, 0);
  checkRestitutionForms(testing::ballOnPaddleProblem(0.4, 0.5), 0, 0, testing::ballOnPaddleProblem(0.4, 0.5).N - 1);
}

// The penalty Σ w ε of the feasibility stage: w = kMidAirImpulseWeight for an impulse at an open
// contact (impact_gap) and for a free point's impulse away from its point (on_point at [n, 0]),
// 1 for every other product, the continuous method's on_point at the collocation points included.
TEST(Transcription, PenaltyWeightsMidAirImpulsesAndImpulsesOffTheirPoint) {
  for (Method method : {Method::Impulsive, Method::Continuous}) {
    const Problem p = testing::ballOnPaddleFreePoint(method == Method::Impulsive ? 0.4 : 0.0, 0.5, {0}, 3, 2);
    const Transcription t(p, method);
    Nlp nlp(t, Stage::Feasibility, t.nullSeed());
    const Eigen::VectorXd x = t.nullSeed();
    const double base = nlp.cost(x);
    int heavy = 0, on_point = 0;
    for (std::size_t k = 0; k < t.productBlocks().size(); ++k) {
      const std::string& name = t.constraintNames()[t.blocks()[t.productBlocks()[k]].row];
      Eigen::VectorXd y = x;
      y[t.penaltyVariables()[k]] += 1.0;
      const bool impulse_off_point = name.starts_with("on_point.") && name.ends_with(",0]");
      const bool expected_heavy = name.starts_with("impact_gap.") || impulse_off_point;
      EXPECT_NEAR(nlp.cost(y) - base, expected_heavy ? kMidAirImpulseWeight : 1.0, 1e-12) << toString(method) << " " << name;
      heavy += expected_heavy;
      on_point += name.starts_with("on_point.");
    }
    EXPECT_EQ(heavy > 0, method == Method::Impulsive) << toString(method);
    EXPECT_GT(on_point, 0) << toString(method);
  }
}

// Rows per coordinate are named by the model's coordinate (`int.v[2,1].rknee`, `eom[1,2].base_z`),
// every name once, and each is that coordinate's row: a continuity row `cont.q[n,0].c` is +1 on
// q[n, 0] of c and an integration row `int.v[n,p].c` depends on q̇[n, p] of c (the Jacobian at a
// random point).
TEST(Transcription, RowsPerCoordinateAreNamedByTheirCoordinate) {
  for (Method method : {Method::Impulsive, Method::FirstOrder}) {
    const Problem biped = smallLegged("biped_stop", 2);
    const Transcription t(biped, method);
    const auto& model = biped.scene.model;
    const auto& rows = t.constraintNames();
    const auto& vars = t.variableNames();
    std::map<std::string, int> column;
    for (int i = 0; i < t.variables(); ++i) column[vars[i]] = i;
    EXPECT_EQ(std::set<std::string>(rows.begin(), rows.end()).size(), rows.size()) << toString(method);
    Nlp nlp(t, Stage::Task, t.nullSeed());
    const Eigen::MatrixXd J = nlp.jacobian(testing::randomPoint(t, 3));
    std::map<std::string, int> per_family;
    for (int r = 0; r < t.constraints(); ++r) {
      const std::string& name = rows[r];
      const std::string family = name.substr(0, name.find('['));
      if (family != "int.q" && family != "int.v" && family != "cont.q" && family != "cont.v" && family != "jump.v" &&
          family != "eom" && family != "impulse")
        continue;
      const std::string point = name.substr(family.size(), name.rfind('.') - family.size());  // "[n,p]"
      const std::string coordinate = name.substr(name.rfind('.') + 1);
      const auto it = std::find(model.coordinate_name.begin(), model.coordinate_name.end(), coordinate);
      ASSERT_NE(it, model.coordinate_name.end()) << name;
      const std::string index = std::to_string(it - model.coordinate_name.begin());
      ++per_family[family];
      if (family == "cont.q") { EXPECT_EQ(J(r, column.at("q" + point + "." + index)), 1.0) << name; }
      if (family == "int.v") { EXPECT_NE(J(r, column.at("v" + point + "." + index)), 0.0) << name; }
    }
    for (const char* f : {"int.q", "int.v", "cont.q", "eom"}) EXPECT_GT(per_family[f], 0) << toString(method) << " " << f;
    EXPECT_EQ(per_family["eom"] % model.nv(), 0) << toString(method);
  }
}

TEST(Transcription, ContinuousRefusesRestitution) {
  try {
    const Problem bouncing = testing::pointMassDrop(0.5);
    Transcription t(bouncing, Method::Continuous);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("restitution"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'ball'"), std::string::npos) << e.what();
  }
}

TEST(Transcription, FirstOrderGetsFourStepsPerElement) {
  const Problem p = testing::pointMassDrop(0.0);
  const Transcription first_order(p, Method::FirstOrder), lg(p, Method::Impulsive);
  EXPECT_EQ(first_order.elements(), 4 * lg.elements());
  EXPECT_NEAR(first_order.variableUpper()[first_order.layout()[0].h], p.h_max / 4, 1e-15);
}

// A joint stop's gap sign·(q_i − limit) is linear in its coordinate: no gap variable and no
// defining row, y ≥ 0 is the coordinate's bound at every point, a gap bound of the problem's is a
// bound on the coordinate, and the products see the same gap (against contact::gap at a random
// point). The biped's 12 stops on three elements of four points: 12 × 3 × 4 variables fewer than
// one a stop and point, and as many gap rows.
TEST(Transcription, AJointStopsGapIsItsCoordinate) {
  Problem biped = smallLegged("biped_stop", 3);
  const int stop = [&] {  // an upper stop
    const Transcription probe(biped, Method::Impulsive);
    for (std::size_t c = 0; c < probe.contacts().size(); ++c)
      if (probe.contacts()[c].isStop() && probe.contacts()[c].sign < 0) return static_cast<int>(c);
    return -1;
  }();
  ASSERT_GE(stop, 0);
  biped.bounds.push_back(PointBound{Quantity{Quantity::Kind::Gap, stop}, 1, 2, 0.05, 0.25, "test"});
  for (Method method : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
    const Transcription t(biped, method);
    int stops = 0, gap_variables = 0, gap_rows = 0;
    for (const auto& name : t.variableNames()) gap_variables += name.starts_with("y.");
    for (const auto& name : t.constraintNames()) gap_rows += name.starts_with("gap");
    int points = 0;
    for (const auto& L : t.layout()) points += static_cast<int>(L.points.size());
    for (const ContactPair& cp : t.contacts()) stops += cp.isStop();
    EXPECT_EQ(stops, 12);
    EXPECT_EQ(gap_variables, (static_cast<int>(t.contacts().size()) - stops) * points) << toString(method);
    EXPECT_EQ(gap_rows, (static_cast<int>(t.contacts().size()) - stops) * points) << toString(method);
    const Eigen::VectorXd x = randomPoint(t, 3);
    auto& data = t.models().data<double>();
    for (int n = 0; n < t.elements(); ++n)
      for (std::size_t p = 0; p < t.layout()[n].points.size(); ++p) {
        const auto& pt = t.layout()[n].points[p];
        dynamics::forwardKinematics(t.models().model<double>(), data, x.segment(pt.q, t.models().model<double>().nv()));
        for (std::size_t c = 0; c < t.contacts().size(); ++c) {
          const ContactPair& cp = t.contacts()[c];
          if (!cp.isStop()) continue;
          EXPECT_EQ(t.layout()[n].contacts[c].y[p], -1);
          EXPECT_NEAR(t.gapValue(x, n, static_cast<int>(c), static_cast<int>(p)), contact::gap(cp, data, x.data() + pt.q), 1e-14);
          const int qi = pt.q + cp.position;
          if (n == 0 && p == 0) continue;  // the initial state
          // the problem's element 1, point 2 (first order: its steps' ends, four steps an element)
          const bool bounded = cp.position == t.contacts()[stop].position &&
                               (method == Method::FirstOrder ? n / 4 == 1 && p == 1 : n == 1 && p == 2);
          if (bounded) {  // 0.05 ≤ limit − q ≤ 0.25
            const double limit = t.contacts()[stop].limit;
            EXPECT_DOUBLE_EQ(t.variableUpper()[qi], limit - 0.05);
            EXPECT_DOUBLE_EQ(t.variableLower()[qi], limit - 0.25);
          } else if (cp.sign > 0) {
            EXPECT_DOUBLE_EQ(t.variableLower()[qi], cp.limit) << t.variableNames()[qi];
          } else {
            EXPECT_DOUBLE_EQ(t.variableUpper()[qi], cp.limit) << t.variableNames()[qi];
          }
        }
      }
    // Each stop's contact product at a collocation point: r_n · Σ_i y[n, i] (first order: y[k+1]).
    const Nlp nlp(t, Stage::Feasibility, x);
    int checked = 0;
    for (int b : t.productBlocks()) {
      const Block& blk = t.blocks()[b];
      const std::string& name = t.constraintNames()[blk.row];
      if (!name.starts_with("contact.")) continue;
      const std::string pair = name.substr(8, name.find('[') - 8);
      const auto it = std::find_if(t.contacts().begin(), t.contacts().end(), [&](const ContactPair& cp) { return cp.name == pair; });
      ASSERT_NE(it, t.contacts().end()) << name;
      if (!it->isStop()) continue;
      const int c = static_cast<int>(it - t.contacts().begin());
      const int n = std::stoi(name.substr(name.find('[') + 1)) - 1;
      const int p = std::stoi(name.substr(name.find(',') + 1));
      double sum = 0;
      if (method == Method::FirstOrder) sum = t.gapValue(x, n, c, p);
      else
        for (std::size_t i = 0; i < t.layout()[n].points.size(); ++i) sum += t.gapValue(x, n, c, static_cast<int>(i));
      Eigen::VectorXd local(blk.vars.size());
      for (std::size_t i = 0; i < blk.vars.size(); ++i) local[i] = x[blk.vars[i]];
      const double product = static_cast<const ComplementarityProduct&>(*blk.f).product(local.data());
      EXPECT_NEAR(product, x[t.layout()[n].contacts[c].rn[p]] * sum, 1e-12 * (1 + std::abs(product))) << name;
      ++checked;
    }
    EXPECT_GT(checked, 12) << toString(method);
  }
}

// A plane fixed in a body is a rectangle: its contact point is kept over it at every point of the
// mesh (point 0 of a later element is the previous end), the row is the point's coordinate in
// the plane and its bounds the extent. Block on the cart's top: s_1 = block_x − cart_x, s_2 = 0.
TEST(Transcription, APointIsKeptOverItsBodysPlane) {
  Problem p;
  p.name = "block_on_cart";
  p.scene = scene::loadScene("block_on_cart", {{"deck", 0.5}});
  p.N = 2;
  p.P = 2;
  p.h_max = 0.1;
  for (const Method method : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
    SCOPED_TRACE(toString(method));
    const Transcription t(p, method);
    const int points = method == Method::FirstOrder ? 1 + t.elements() : 1 + p.N * (p.P + 1);
    std::vector<int> rows1, rows2;
    for (int r = 0; r < t.constraints(); ++r) {
      const std::string& name = t.constraintNames()[r];
      if (name.rfind("extent.block_on_deck.1[", 0) == 0) rows1.push_back(r);
      if (name.rfind("extent.block_on_deck.2[", 0) == 0) rows2.push_back(r);
    }
    ASSERT_EQ(static_cast<int>(rows1.size()), points);
    ASSERT_EQ(rows2.size(), rows1.size());
    for (int r : rows1) {
      EXPECT_EQ(t.constraintLower()[r], -0.5);
      EXPECT_EQ(t.constraintUpper()[r], 0.5);
    }
    for (int r : rows2) {
      EXPECT_EQ(t.constraintLower()[r], -0.2);
      EXPECT_EQ(t.constraintUpper()[r], 0.2);
    }

    // At a point with the cart at x = 0.1 and the block at x = 0.7 everywhere: s_1 = 0.6, beyond.
    Eigen::VectorXd x = t.nullSeed();
    for (const ElementLayout& L : t.layout())
      for (const ElementLayout::Point& pt : L.points) {
        x[pt.q + 0] = 0.1;  // cart_x
        x[pt.q + 1] = 0.7;  // block_x
        x[pt.q + 2] = 0.3;  // block_z
      }
    Nlp nlp(t, Stage::Task, t.nullSeed());
    const Eigen::VectorXd g = nlp.constraints(x);
    for (int r : rows1) EXPECT_NEAR(g[r], 0.6, 1e-12) << t.constraintNames()[r];
    for (int r : rows2) EXPECT_NEAR(g[r], 0.0, 1e-12) << t.constraintNames()[r];
  }
  // A world plane has no extent rows.
  const Problem drop_problem = testing::pointMassDrop(0.0);
  const Transcription drop(drop_problem, Method::Impulsive);
  for (const std::string& name : drop.constraintNames()) EXPECT_NE(name.rfind("extent.", 0), 0u) << name;
}

}  // namespace
}  // namespace saltus::collocation
