// The transcription (transcription.hpp) as an Ipopt TNLP for one stage of the two-stage solve
// (paper §V.C): the feasibility stage minimises the complementarity penalty Σ ε with the hint
// bounds applied; the task stage minimises the task cost plus the weighted penalty with every
// product bounded by the complementarity tolerance; a tightening stage in between minimises Σ ε
// with every ε so bounded; a penalty stage may come first, with the products in its cost (Stage).
// Only the sparsity structure is stored: the Jacobian and the Hessian of the Lagrangian are
// assembled from the blocks' dense local derivatives.
#pragma once

#include <functional>

#include <IpTNLP.hpp>

#include <string>
#include <vector>

#include "collocation/transcription.hpp"

namespace saltus::collocation {

// Feasibility: Σ ε with the hints' bounds. Tighten: Σ ε with every ε bounded (below), from a
// feasibility stage's near miss. Task: the task cost and the weighted penalty, the products
// bounded. In the task stage every ε is fixed at its bound, so that A·B − ε ≤ 0 reads A·B ≤ the
// bound, and the penalty weighs the products themselves, Σ w A·B: at a solution of the ε form
// each ε equals its product, so the problem is the same, with one variable fewer per product
// (Ipopt's default fixed_variable_treatment, make_parameter, takes the fixed ε out). On the
// biped (3,200 products) the capped task stage takes about a tenth less time for the same x_m
// (README).
// Penalty: the feasibility stage's problem in the penalty formulation of Leyffer, López-Calva &
// Nocedal (SIAM J. Optim. 17(1), 2006, DOI 10.1137/040621065): each product row A·B − ε ≤ 0 is
// left out of the NLP Ipopt sees, every ε is fixed at 0, and the cost is Σ w A·B over factors
// that their bounds keep ≥ 0. On the biped Ipopt's inequalities go from 3,550 to 398 and an
// iteration costs about half. With Problem::task_penalty the task stage takes the same form (the
// task cost plus penalty_weight × Σ w A·B). Saved points carry each product in its ε.
enum class Stage { Feasibility, Tighten, Task, Penalty };
const char* toString(Stage s);  // "feasibility", "tighten", "task", "penalty"

// The task stage bounds every ε by this fraction of the complementarity tolerance.
constexpr double kPenaltyBoundFraction = 0.9;

// Ipopt's multipliers at a solution: bound multipliers z_L, z_U and constraint multipliers λ.
struct Multipliers {
  Eigen::VectorXd z_lower, z_upper, lambda;
  bool empty() const { return lambda.size() == 0 && z_lower.size() == 0; }
};

class Nlp : public Ipopt::TNLP {
 public:
  // With `start` (non-empty) the multipliers are handed to Ipopt too, for
  // warm_start_init_point = yes.
  // hinted: a first stage (feasibility, penalty) within the hints' bounds (Transcription::hintedLower).
  Nlp(const Transcription& t, Stage stage, const Eigen::VectorXd& x0, Multipliers start = {}, bool hinted = true);

  // Results of the last solve.
  const Eigen::VectorXd& solution() const { return x_; }
  const Multipliers& multipliers() const { return multipliers_; }
  Ipopt::SolverReturn status() const { return status_; }
  double objective() const { return objective_; }
  double evaluationSeconds() const { return eval_seconds_; }
  int hessianEvaluations() const { return hessian_evaluations_; }  // values, not the structure
  int jacobianNonzeros() const { return static_cast<int>(jac_row_.size()); }
  int hessianNonzeros() const { return static_cast<int>(hess_row_.size()); }

  // Ipopt::TNLP
  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override;
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m,
                       Ipopt::Number* g_l, Ipopt::Number* g_u) override;
  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number* z_L,
                          Ipopt::Number* z_U, Ipopt::Index m, bool init_lambda, Ipopt::Number* lambda) override;
  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number& obj_value) override;
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number* grad_f) override;
  bool eval_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Number* g) override;
  bool eval_jac_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Index nele_jac,
                  Ipopt::Index* iRow, Ipopt::Index* jCol, Ipopt::Number* values) override;
  bool eval_h(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number obj_factor, Ipopt::Index m,
              const Ipopt::Number* lambda, bool new_lambda, Ipopt::Index nele_hess, Ipopt::Index* iRow,
              Ipopt::Index* jCol, Ipopt::Number* values) override;
  void finalize_solution(Ipopt::SolverReturn status, Ipopt::Index n, const Ipopt::Number* x,
                         const Ipopt::Number* z_L, const Ipopt::Number* z_U, Ipopt::Index m,
                         const Ipopt::Number* g, const Ipopt::Number* lambda, Ipopt::Number obj_value,
                         const Ipopt::IpoptData* ip_data, Ipopt::IpoptCalculatedQuantities* ip_cq) override;

  // Asked at every iteration (intermediate_callback); true stops Ipopt (User_Requested_Stop).
  void setInterruption(std::function<bool()> interrupted) { interrupted_ = std::move(interrupted); }
  bool intermediate_callback(Ipopt::AlgorithmMode mode, Ipopt::Index iter, Ipopt::Number obj_value,
                             Ipopt::Number inf_pr, Ipopt::Number inf_du, Ipopt::Number mu, Ipopt::Number d_norm,
                             Ipopt::Number regularization_size, Ipopt::Number alpha_du, Ipopt::Number alpha_pr,
                             Ipopt::Index ls_trials, const Ipopt::IpoptData* ip_data,
                             Ipopt::IpoptCalculatedQuantities* ip_cq) override {
    iteration_ = iter;
    if (stop_when_feasible_ && hasBestFeasible()) {
      stopped_feasible_ = true;
      return false;
    }
    return !(interrupted_ && interrupted_());
  }
  // With keepBestFeasible: stop at the first iteration after a feasible point was evaluated (the
  // tightening stage, whose only aim is such a point). Ipopt then returns User_Requested_Stop,
  // and stoppedAtFeasible() says why.
  void stopWhenFeasible() { stop_when_feasible_ = true; }
  // Tighten: every ε bounded by `bound` instead of the tolerance's fraction (a step of the
  // tightening continuation, solver.cpp).
  void boundProducts(double bound) {
    for (int e : t_.penaltyVariables()) x_upper_[e] = bound;
  }
  bool stoppedAtFeasible() const { return stopped_feasible_; }

  // Keeps, among the points at which Ipopt evaluates the constraints (iterates and line-search
  // trials alike), the one of lowest objective whose products are within `product_tolerance`
  // and whose constraints are within `violation_tolerance` of their bounds: a valid trajectory
  // even when the stage ends away from the feasible set. Ipopt's iterates stay within the
  // variables' bounds (relaxed by bound_relax_factor, 1e-8), so the constraints are what is checked.
  void keepBestFeasible(double product_tolerance, double violation_tolerance) {
    best_product_tolerance_ = product_tolerance;
    best_violation_tolerance_ = violation_tolerance;
  }
  bool hasBestFeasible() const { return best_x_.size() > 0; }
  const Eigen::VectorXd& bestFeasible() const { return best_x_; }
  double bestFeasibleObjective() const { return best_objective_; }
  int bestFeasibleIteration() const { return best_iteration_; }  // the iteration it was a trial of

  // The same evaluations for tests (dense, no Ipopt).
  double cost(const Eigen::VectorXd& x);
  Eigen::VectorXd constraints(const Eigen::VectorXd& x);
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& x);
  Eigen::MatrixXd hessian(const Eigen::VectorXd& x, double obj_factor, const Eigen::VectorXd& lambda);  // full symmetric

 private:
  double weight(std::size_t block) const;  // cost weight of a block in this stage (0: not in the cost)
  bool productInCost(std::size_t block) const { return !product_weight_.empty() && product_weight_[block] != 0; }
  double objectiveAt(const Ipopt::Number* x);
  void considerFeasible(const Ipopt::Number* x, const Ipopt::Number* g);
  const double* gather(const Block& b, const Ipopt::Number* x);

  const Transcription& t_;
  Stage stage_;
  std::function<bool()> interrupted_;
  Eigen::VectorXd x0_, x_lower_, x_upper_;
  std::vector<int> jac_row_, jac_col_, jac_pos_, jac_first_;     // per block: first position in jac_pos_
  std::vector<int> hess_row_, hess_col_, hess_pos_, hess_first_;  // per block: first in hess_pos_ (−1: none)
  std::vector<double> local_x_, local_y_, local_d_, local_l_;
  std::vector<int> row_;  // per transcription row, its row in Ipopt's NLP (−1: left out, the penalty stage's products)
  int rows_ = 0;
  Eigen::VectorXd g_full_;
  bool leftOut(const Block& b) const { return !b.isCost() && row_[b.row] < 0; }
  std::vector<double> product_weight_;  // the task and penalty stages: per block, a product's weight in the cost (0: none)
  Eigen::VectorXd x_;
  Multipliers start_, multipliers_;
  Ipopt::SolverReturn status_ = Ipopt::INTERNAL_ERROR;
  double objective_ = 0;
  double eval_seconds_ = 0;
  int hessian_evaluations_ = 0;
  int iteration_ = -1;  // of the last intermediate callback
  bool stop_when_feasible_ = false, stopped_feasible_ = false;
  double best_product_tolerance_ = -1, best_violation_tolerance_ = -1;  // < 0: not kept
  Eigen::VectorXd best_x_;
  double best_objective_ = 0;
  int best_iteration_ = -1;
};

}  // namespace saltus::collocation
