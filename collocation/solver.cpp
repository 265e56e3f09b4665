#include "collocation/solver.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>

#include <chrono>
#include <stdexcept>

#include "collocation/nlp.hpp"

namespace saltus::collocation {

std::string ipoptStatusName(int status) {
  switch (status) {
    case Ipopt::Solve_Succeeded: return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level: return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected: return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small: return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates: return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop: return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found: return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded: return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed: return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation: return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded: return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom: return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition: return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option: return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected: return "Invalid_Number_Detected";
    case Ipopt::Unrecoverable_Exception: return "Unrecoverable_Exception";
    case Ipopt::NonIpopt_Exception_Thrown: return "NonIpopt_Exception_Thrown";
    case Ipopt::Insufficient_Memory: return "Insufficient_Memory";
    case Ipopt::Internal_Error: return "Internal_Error";
    default: return "Unknown_Status_" + std::to_string(status);
  }
}

namespace {

void setOption(Ipopt::IpoptApplication& app, const std::string& name, const std::string& value) {
  const auto option = app.RegOptions()->GetOption(name);
  if (!IsValid(option)) throw IpoptOptionError("unknown Ipopt option '" + name + "'");
  bool ok = false;
  try {
    switch (option->Type()) {
      case Ipopt::OT_Number: {
        std::size_t used = 0;
        const double x = std::stod(value, &used);
        if (used != value.size()) throw std::invalid_argument(value);
        ok = app.Options()->SetNumericValue(name, x);
        break;
      }
      case Ipopt::OT_Integer: {
        std::size_t used = 0;
        const int x = std::stoi(value, &used);
        if (used != value.size()) throw std::invalid_argument(value);
        ok = app.Options()->SetIntegerValue(name, x);
        break;
      }
      default: ok = app.Options()->SetStringValue(name, value); break;
    }
  } catch (const std::logic_error&) {
    ok = false;
  }
  if (!ok)
    throw IpoptOptionError("Ipopt option '" + name + "': invalid value '" + value + "' (expected " +
                           (option->Type() == Ipopt::OT_Number    ? "a number"
                            : option->Type() == Ipopt::OT_Integer ? "an integer"
                                                                  : "one of its names") +
                           ")");
}

StageReport runStage(const Transcription& t, Stage stage, const Eigen::VectorXd& x0, const SolveOptions& options,
                     Eigen::VectorXd& x_out, SolveReport& report) {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", options.print_level);
  app->Options()->SetStringValue("sb", "yes");  // no banner
  // Defaults (the problem file and the command line override them): the tolerance of the
  // paper group's code (facts.md §1), and an acceptable level for the complementarity
  // problems, whose multipliers need not converge.
  app->Options()->SetNumericValue("tol", 1e-6);
  app->Options()->SetNumericValue("acceptable_tol", 1e-4);
  app->Options()->SetIntegerValue("acceptable_iter", 10);
  app->Options()->SetIntegerValue("max_iter", 3000);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  app->Options()->SetStringValue("hessian_approximation",
                                 t.problem().exact_hessian ? "exact" : "limited-memory");
  if (stage == Stage::Task) {  // start close to the feasibility stage's point
    app->Options()->SetNumericValue("bound_push", 1e-6);
    app->Options()->SetNumericValue("bound_frac", 1e-6);
    app->Options()->SetNumericValue("mu_init", 1e-4);
  }
  if (t.problem().derivative_check) {
    app->Options()->SetStringValue("derivative_test", "second-order");
    app->Options()->SetNumericValue("derivative_test_perturbation", 1e-7);
  }
  for (const auto& [name, value] : t.problem().ipopt_options) setOption(*app, name, value);
  for (const auto& [name, value] : options.ipopt) setOption(*app, name, value);
  if (app->Initialize() != Ipopt::Solve_Succeeded) throw std::runtime_error("Ipopt failed to initialise");

  Ipopt::SmartPtr<Nlp> nlp = new Nlp(t, stage, x0);
  const auto start = std::chrono::steady_clock::now();
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(nlp)));
  StageReport r;
  r.name = stage == Stage::Feasibility ? "feasibility" : "task";
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.status_code = status;
  r.status = ipoptStatusName(status);
  r.succeeded = status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
  if (IsValid(app->Statistics())) r.iterations = app->Statistics()->IterationCount();
  r.evaluation_seconds = nlp->evaluationSeconds();
  x_out = nlp->solution().size() == t.variables() ? nlp->solution() : x0;
  r.objective = nlp->solution().size() == t.variables() ? nlp->objective() : 0;
  r.largest_product = t.largestProduct(x_out);
  report.jacobian_nonzeros = nlp->jacobianNonzeros();
  report.hessian_nonzeros = nlp->hessianNonzeros();
  return r;
}

}  // namespace

SolveReport solve(const Transcription& t, const Eigen::VectorXd& x0, const SolveOptions& options) {
  SolveReport report;
  report.variables = t.variables();
  report.constraints = t.constraints();
  Eigen::VectorXd x = x0;
  report.stages.push_back(runStage(t, Stage::Feasibility, x0, options, x, report));
  // The task stage runs when there is a task cost, and also when hints shaped the feasibility
  // stage: they are a seeding aid, not part of the problem.
  const bool task = (t.problem().task_stage && t.problem().cost.hasTask()) || !t.problem().hints.empty();
  if (task && report.stages.back().succeeded) {
    const Eigen::VectorXd x1 = x;
    report.stages.push_back(runStage(t, Stage::Task, x1, options, x, report));
  }
  report.x = x;
  report.largest_product = t.largestProduct(x);
  report.objective = report.stages.back().objective;
  bool all = true;
  for (const StageReport& s : report.stages) {
    all = all && s.succeeded;
    report.wall_seconds += s.wall_seconds;
    report.evaluation_seconds += s.evaluation_seconds;
    report.iterations += s.iterations;
  }
  report.feasible = all && (!task || report.stages.size() == 2) &&
                    report.largest_product <= t.problem().complementarity_tolerance;
  return report;
}

}  // namespace saltus::collocation
