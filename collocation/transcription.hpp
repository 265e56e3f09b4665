// The transcription of a Problem (problem.hpp) to a nonlinear program for one method: the
// variables with their bounds, the constraints as blocks of local functions
// (local_function.hpp, functions.hpp) with their bounds, the cost terms, and the layout that
// tells where each state, input and reaction lives. The NLP (nlp.hpp) evaluates it for Ipopt.
//
// impulsive (paper LG-P I), per element n with points p = 0 … P+1:
//   (3), (4)  integration of q and q̇ (q̈ at the collocation points)
//   (5)       q[n,0] = q[n−1,P+1]; q̇[n,0] = q̇[n−1,P+1] + Δq̇[n]   (Δq̇ is "q̈[n,0]")
//   (6)       M(q[n,0]) Δq̇[n] = Σ J_cᵀ p_c[n,0]                   (n ≥ 1)
//   EOM       M q̈ + h = B u + Σ J_cᵀ f_c at the collocation points
//   (9a–c)    a⁺ − a⁻ = ẏ[n,0] + e ẏ[n−1,P+1];  r_n[n,0] ⊥ y[n,0] + a⁺ + a⁻, written as the two
//             products r_n[n,0] ⊥ y[n,0] (weighted kMidAirImpulseWeight in the penalty) and
//             r_n[n,0] ⊥ a⁺ + a⁻;  and a⁺ ⊥ a⁻
//   (10)      r_n[n,p] ⊥ Σ_{i=0}^{P+1} y[n,i]               (p = 1 … P)
//   (11–13)   r_t = μ r_n Σ d_i α_i;  α_i ⊥ γ − d_iᵀ v_t;  Σ_p γ[n,p] ⊥ 1 − Σ_i α_i[n,p]
//             at the points that carry reactions (the collocation points, and [n,0] for n ≥ 1;
//             the sum in (13) runs over those points)
//   free point  a contact whose point on B's plane is free (ContactPair::free_axes): at the
//             points with reactions, plane coordinates s within the extent, s_A(q) − s = d⁺ − d⁻
//             (FreePointOffset), r_n ⊥ Σ (d⁺ + d⁻) and d⁺ ⊥ d⁻; the reaction acts on B at s.
//             Other contacts on a body's plane keep the point over the rectangle at every point.
// continuous (LG-P C): the same without Δq̇, the impulse and (9); contact through (10) only.
// first-order (Posa, Cantu & Tedrake 2014): K = steps_per_element · N backward-Euler steps,
//   q[k+1] = q[k] + h q̇[k+1], q̇[k+1] = q̇[k] + h q̈[k+1], EOM at k+1 with λ_n, β_i ≥ 0;
//   φ(q[k+1]) ⊥ λ_n;  γ + d_iᵀ v_t ⊥ β_i;  μ λ_n − Σ β_i ⊥ γ.
// Every product A·B ≤ ε with ε ≥ 0 a variable (paper eq. 8), penalised in the cost: Σ w ε with
// w = 1, except kMidAirImpulseWeight for an impulse's gap product and a free point's on-point
// product at an impulse. That is the feasibility and tightening stages' form; the task stage
// fixes each ε at its bound and weighs Σ w A·B instead (Nlp, nlp.hpp).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "collocation/functions.hpp"
#include "collocation/legendre_gauss.hpp"
#include "collocation/problem.hpp"

namespace saltus::collocation {

// A group of constraint rows [row, row + outputs) or a cost term (isCost) given by one local
// function of the variables `vars`.
struct Block {
  std::shared_ptr<const LocalFunction> f;
  std::vector<int> vars;
  int row = -1;         // first constraint row; −1: a cost term
  int cost_group = -1;  // cost terms: CostGroup
  bool isCost() const { return row < 0; }
};

enum CostGroup { kPenaltyCost = 0, kTaskCost = 1 };

// Penalty weight of r_n[n,0] · y[n,0] (an impulse at an open contact). From the paper's
// perturbed seeds (bench/sweeps/perturbed_seeds.yaml: the built-in drop, throw and pendulum, 10
// random seeds each) the solves most often stop at a local minimum with an impulse in mid-air;
// weighted 1, 10 and 100: 18, 26 and 22 successes of 40 (16 with the single product of (9b)), and
// no change on the simulation-seeded grid (contact_discovery.yaml: 187 and 188 of 191).
// A free contact point's r_n[n,0] ⊥ Σ (d⁺ + d⁻) (an impulse where the foot is not) has the same
// weight: on ollie_simple (strategy 3, seeds 1–4, 150 s) the largest products at the end of the
// feasibility stage went from 27, 22, 10, 21 (all at such products) to 9.8, 15, 15, 15 (none).
constexpr double kMidAirImpulseWeight = 10.0;

// Where the variables of one element live (−1: absent).
struct ElementLayout {
  int h = -1;
  std::vector<double> tau;  // point positions in the element, [0, 1]
  struct Point {
    int q = -1, v = -1;  // first of nv
    int accel_or_jump = -1;  // q̈ (collocation points) or Δq̇ (impulsive [n, 0])
    int u = -1;          // first input (collocation points)
  };
  std::vector<Point> points;
  std::vector<int> collocation;  // indices of the collocation points in `points`
  int end = -1;                  // index of the end mesh point
  struct ContactVars {
    std::vector<int> y;      // gap, per point; −1 for a joint stop (Transcription::gap)
    std::vector<int> rn;     // normal reaction (impulse at an impulsive [n, 0]), per point, −1 where none
    std::vector<int> tangential;  // first tangential variable (α or β), per point
    std::vector<int> gamma;  // slip-speed bound γ, per point
    std::vector<int> psi;         // first slip slack ψ (12), per point, −1 where none
    std::vector<int> slip_block;  // the block defining ψ, in blocks(), per point
    // A free contact point (ContactPair::free_axes), per point with a reaction, −1 elsewhere: the
    // first of its plane coordinates s and of the offsets d⁺, d⁻ (FreePointOffset).
    std::vector<int> s, d_plus, d_minus;
    int a_plus = -1, a_minus = -1;  // (9)
    int restitution_block = -1;     // (9a), in blocks()
  };
  std::vector<ContactVars> contacts;
};

// Why `method` cannot represent `problem`, or "" when it can: only the impulsive method has a
// restitution law (9); the continuous one has no velocity jumps and the first-order one (Posa,
// Cantu & Tedrake's backward Euler) stops every impact inelastically, so both refuse a contact
// or joint stop with e > 0 rather than silently solve a different problem.
std::string methodCannotTake(const Problem& problem, Method method);

class Transcription {
 public:
  // Throws std::invalid_argument with methodCannotTake's reason, or for a bad mesh. Refers to
  // `problem`, which must outlive it (a temporary is refused at compile time).
  Transcription(const Problem& problem, Method method);
  Transcription(Problem&&, Method) = delete;

  const Problem& problem() const { return problem_; }
  Method method() const { return method_; }
  // How the tangential variables make the friction force: the first-order method's Direct form
  // (β), the collocation methods' Activation form (α, paper eq. 11).
  FrictionForm frictionForm() const {
    return method_ == Method::FirstOrder ? FrictionForm::Direct : FrictionForm::Activation;
  }
  // The scene's constant generalised force τ_0 (Scene::tau), acting besides the inputs; empty
  // when the scene has none.
  Eigen::VectorXd constantInput() const {
    const Eigen::VectorXd& tau = problem_.scene.tau;
    return tau.size() == nv_ && !tau.isZero(0) ? tau : Eigen::VectorXd();
  }
  const ModelSet& models() const { return *models_; }
  const std::vector<ContactPair>& contacts() const { return contacts_; }
  const LegendreGauss& lg() const { return lg_; }
  int elements() const { return static_cast<int>(layout_.size()); }
  const std::vector<ElementLayout>& layout() const { return layout_; }

  int variables() const { return static_cast<int>(x_lower_.size()); }
  int constraints() const { return static_cast<int>(g_lower_.size()); }
  const std::vector<std::string>& variableNames() const { return x_names_; }
  const Eigen::VectorXd& variableLower() const { return x_lower_; }
  const Eigen::VectorXd& variableUpper() const { return x_upper_; }
  // Bounds with the hints (feasibility stage only) applied.
  const Eigen::VectorXd& hintedLower() const { return x_lower_hint_; }
  const Eigen::VectorXd& hintedUpper() const { return x_upper_hint_; }
  const Eigen::VectorXd& constraintLower() const { return g_lower_; }
  const Eigen::VectorXd& constraintUpper() const { return g_upper_; }
  const std::vector<Block>& blocks() const { return blocks_; }  // constraints, then cost terms
  const std::vector<std::string>& constraintNames() const { return g_names_; }

  // The complementarity products (paper eq. 8): their blocks and penalty variables ε.
  const std::vector<int>& productBlocks() const { return product_blocks_; }
  const std::vector<int>& penaltyVariables() const { return epsilon_; }
  const std::vector<double>& penaltyWeights() const { return penalty_weights_; }  // per ε
  // max_i of A·B at x (the feasibility measure: ≤ complementarity_tolerance); `where` gets the
  // name of that product's constraint (e.g. "impact.ball[10,0]"), untouched when all are ≤ 0.
  double largestProduct(const Eigen::VectorXd& x, std::string* where = nullptr) const;
  // Each penalty variable ε ← max(0, A·B), so eq. 8 holds with equality where A·B ≥ 0 (the
  // end of makeConsistent; the NLP's task stage, whose ε are fixed, saves its points this way).
  void setPenaltyToProducts(Eigen::VectorXd& x) const;

  // The gap y of contact c at point p of element n as an affine form Σ_i c_i x[vars_i] + c0: its
  // gap variable, or for a joint stop its coordinate, sign·(q_i − limit). A stop's gap is linear
  // in one coordinate, so it has no variable of its own and no defining equation: y ≥ 0 is that
  // coordinate's bound at every point (on the biped, 1,800 variables and as many equations fewer
  // out of 13,322 and 6,730).
  struct Affine {
    std::vector<int> vars;
    Eigen::VectorXd c;
    double c0 = 0;
  };
  Affine gap(int n, int c, int p) const;
  double gapValue(const Eigen::VectorXd& x, int n, int c, int p) const;

  // The surface velocity a contact sees at element n (steps on the mesh, problem.hpp).
  Eigen::Vector3d surfaceVelocity(int surface, int element) const;

  // The paper's null seed: every variable zero, then projected into its bounds (so the initial
  // point holds the initial state and every other position is zero), h at the middle of its
  // bounds; the auxiliaries from makeConsistent (gaps computed before the projection).
  Eigen::VectorXd nullSeed() const;
  // Uniform random values in [0, scale] added to positions and normal reactions (paper §V.C),
  // then gaps recomputed; a fixed random seed makes it reproducible.
  Eigen::VectorXd perturb(const Eigen::VectorXd& x, double scale, unsigned seed) const;
  // Gap variables set from the positions (clipped at 0), variables projected into bounds, and
  // each penalty variable ε set to its product A·B (at least 0).
  void makeConsistent(Eigen::VectorXd& x) const;
  // The minimise-max variable x_m set to the largest value of its coordinate over the points: its
  // least value that meets q_i ≤ x_m, which is the task cost of a point whose stage did not
  // minimise it (a feasibility stage's). Nothing without a minimise-max cost.
  void tightenMaxVariable(Eigen::VectorXd& x) const;

 private:
  int addVariables(int count, double lower, double upper, const std::string& name);
  // The name of velocity coordinate i (the model's), in constraint names: "int.v[6,3].board_theta".
  const std::string& coordinate(int i) const;
  int addBlock(std::shared_ptr<const LocalFunction> f, std::vector<int> vars, double lower, double upper,
               const std::string& name);
  void addCost(std::shared_ptr<const LocalFunction> f, std::vector<int> vars, CostGroup group);
  int addProduct(const std::vector<int>& a_vars, const Eigen::VectorXd& a, double a0,
                 const std::vector<int>& b_vars, const Eigen::VectorXd& b, double b0, const std::string& name,
                 double weight = 1.0);
  void addLinearEquality(const std::vector<int>& vars, const Eigen::VectorXd& c, double rhs, const std::string& name);

  void buildContacts();
  void buildVariables();
  void buildElementConstraints(int n);
  void buildContactConstraints(int n);
  void buildProblemConstraints();
  void applyBounds();

  const Problem& problem_;
  Method method_;
  std::unique_ptr<ModelSet> models_;
  std::vector<ContactPair> contacts_;
  LegendreGauss lg_;
  int nv_ = 0, nu_ = 0;
  std::vector<ElementLayout> layout_;
  int x_max_ = -1;  // minimise-max variable
  // Local functions shared by the blocks of every element: the equations of motion (impulsive,
  // with dynamics) and each contact's restitution balance.
  std::shared_ptr<const LocalFunction> eom_with_dynamics_, eom_impulsive_;  // shared by every point
  std::vector<std::shared_ptr<const LocalFunction>> restitution_;

  std::vector<std::string> x_names_, g_names_;
  Eigen::VectorXd x_lower_, x_upper_, x_lower_hint_, x_upper_hint_, g_lower_, g_upper_;
  std::vector<double> xl_, xu_, gl_, gu_;  // while building
  std::vector<Block> blocks_;
  std::vector<int> product_blocks_, epsilon_;
  std::vector<double> penalty_weights_;  // per ε
};

}  // namespace saltus::collocation
