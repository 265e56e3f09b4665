#include "sweep/record.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sweep/spec.hpp"

namespace saltus::sweep {

nlohmann::ordered_json toJson(const SweepRecord& r) {
  nlohmann::ordered_json j;
  j["id"] = r.id;
  j["problem"] = r.problem;
  j["problem_name"] = r.problem_name;
  j["method"] = r.method;
  j["set"] = r.set;
  if (!r.variant.empty()) j["variant"] = r.variant;
  j["seed"] = r.seed;
  j["command"] = r.command;
  j["exit_code"] = r.exit_code;
  j["status"] = r.status;
  if (!r.error.empty()) j["error"] = r.error;
  j["feasible"] = r.feasible;
  j["converged"] = r.converged;
  j["physical"] = r.physical ? nlohmann::ordered_json(*r.physical) : nlohmann::ordered_json();
  j["physical_required"] = r.physical_required;
  j["success"] = r.success();
  j["replay_deviation"] = r.replay_deviation;
  if (!r.replay_message.empty()) j["replay_message"] = r.replay_message;
  j["iterations"] = r.iterations;
  j["wall_seconds"] = r.wall_seconds;
  j["evaluation_seconds"] = r.evaluation_seconds;
  j["largest_product"] = r.largest_product;
  j["mean_local_error"] = r.mean_local_error;
  j["objective"] = r.objective;
  j["variables"] = r.variables;
  j["constraints"] = r.constraints;
  j["attempts"] = r.attempts;
  return j;
}

SweepRecord recordFromJson(const nlohmann::json& j) {
  auto get = [&](const char* key) -> const nlohmann::json& {
    if (!j.contains(key)) throw std::runtime_error(std::string("record: missing key '") + key + "'");
    return j.at(key);
  };
  SweepRecord r;
  try {
    r.id = get("id").get<std::string>();
    r.problem = get("problem").get<std::string>();
    r.problem_name = get("problem_name").get<std::string>();
    r.method = get("method").get<std::string>();
    r.set = get("set").get<std::map<std::string, double>>();
    r.variant = j.value("variant", std::string());
    r.seed = get("seed").get<unsigned>();
    r.command = get("command").get<std::string>();
    r.exit_code = get("exit_code").get<int>();
    r.status = get("status").get<std::string>();
    r.error = j.value("error", std::string());
    r.feasible = get("feasible").get<bool>();
    r.converged = j.value("converged", r.feasible);  // records before the key: feasible meant converged
    if (!get("physical").is_null()) r.physical = get("physical").get<bool>();
    r.physical_required = j.value("physical_required", true);
    r.replay_deviation = get("replay_deviation").get<double>();
    r.replay_message = j.value("replay_message", std::string());
    r.iterations = get("iterations").get<int>();
    r.wall_seconds = get("wall_seconds").get<double>();
    r.evaluation_seconds = get("evaluation_seconds").get<double>();
    r.largest_product = get("largest_product").get<double>();
    r.mean_local_error = get("mean_local_error").get<double>();
    r.objective = get("objective").get<double>();
    r.variables = get("variables").get<int>();
    r.constraints = get("constraints").get<int>();
    r.attempts = get("attempts").get<int>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("record: ") + e.what());
  }
  return r;
}

Quartiles quartiles(std::vector<double> values) {
  Quartiles q;
  values.erase(std::remove_if(values.begin(), values.end(), [](double x) { return !std::isfinite(x); }), values.end());
  q.count = static_cast<int>(values.size());
  if (values.empty()) {
    q.min = q.q1 = q.median = q.q3 = q.max = std::nan("");
    return q;
  }
  std::sort(values.begin(), values.end());
  auto at = [&](double fraction) {
    const double pos = fraction * static_cast<double>(values.size() - 1);
    const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  q.min = values.front();
  q.q1 = at(0.25);
  q.median = at(0.5);
  q.q3 = at(0.75);
  q.max = values.back();
  return q;
}

std::vector<CellSummary> summarise(const std::vector<SweepRecord>& records) {
  struct Cell {
    CellSummary summary;
    std::vector<double> wall_all, wall, iterations, error, objective;
  };
  std::vector<Cell> cells;
  auto key = [](const SweepRecord& r) {
    SweepCase c;
    c.problem_name = r.problem_name;
    c.method = r.method;
    c.set = r.set;
    c.variant = r.variant;
    return c.cell();
  };
  std::map<std::string, std::size_t> index;
  for (const SweepRecord& r : records) {
    const auto [it, added] = index.try_emplace(key(r), cells.size());
    if (added) {
      cells.emplace_back();
      cells.back().summary.problem_name = r.problem_name;
      cells.back().summary.method = r.method;
      cells.back().summary.set = r.set;
      cells.back().summary.variant = r.variant;
    }
    Cell& c = cells[it->second];
    ++c.summary.solves;
    c.summary.feasible += r.feasible;
    c.summary.converged += r.converged;
    c.summary.physical += r.physical.value_or(false);
    c.wall_all.push_back(r.wall_seconds);
    if (!r.success()) continue;
    ++c.summary.successes;
    c.wall.push_back(r.wall_seconds);
    c.iterations.push_back(r.iterations);
    c.error.push_back(r.mean_local_error);
    c.objective.push_back(r.objective);
  }
  std::vector<CellSummary> out;
  for (Cell& c : cells) {
    CellSummary s = c.summary;
    s.success_rate = s.solves ? static_cast<double>(s.successes) / s.solves : 0.0;
    s.wall_all = quartiles(c.wall_all);
    s.wall_seconds = quartiles(c.wall);
    s.iterations = quartiles(c.iterations);
    s.mean_local_error = quartiles(c.error);
    s.objective = quartiles(c.objective);
    out.push_back(s);
  }
  return out;
}

namespace {

// A CSV field, quoted when it holds a comma, quote or line break.
std::string field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string number(double x) {
  if (std::isnan(x)) return "";
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

const std::pair<const char*, Quartiles CellSummary::*> kStatistics[] = {
    {"wall_seconds", &CellSummary::wall_seconds},
    {"iterations", &CellSummary::iterations},
    {"mean_local_error", &CellSummary::mean_local_error},
    {"objective", &CellSummary::objective},
};

nlohmann::ordered_json toJson(const Quartiles& q) {
  auto value = [](double x) { return std::isnan(x) ? nlohmann::ordered_json() : nlohmann::ordered_json(x); };
  return {{"count", q.count}, {"min", value(q.min)},       {"q1", value(q.q1)},
          {"median", value(q.median)}, {"q3", value(q.q3)}, {"max", value(q.max)}};
}

}  // namespace

std::string summaryCsv(const std::vector<CellSummary>& cells) {
  std::ostringstream csv;
  csv << "problem,method,parameters,variant,solves,feasible,converged,physical,successes,success_rate,wall_all_median";
  for (const auto& [name, member] : kStatistics)
    for (const char* q : {"min", "q1", "median", "q3", "max"}) csv << "," << name << "_" << q;
  csv << "\n";
  for (const CellSummary& c : cells) {
    std::string parameters;
    for (const auto& [name, value] : c.set) parameters += (parameters.empty() ? "" : " ") + name + "=" + formatValue(value);
    csv << field(c.problem_name) << "," << c.method << "," << field(parameters) << "," << c.variant << "," << c.solves << "," << c.feasible << ","
        << c.converged << "," << c.physical << "," << c.successes << "," << number(c.success_rate) << "," << number(c.wall_all.median);
    for (const auto& [name, member] : kStatistics) {
      const Quartiles& q = c.*member;
      for (double x : {q.min, q.q1, q.median, q.q3, q.max}) csv << "," << number(x);
    }
    csv << "\n";
  }
  return csv.str();
}

nlohmann::ordered_json summaryJson(const std::vector<CellSummary>& cells, const std::vector<SweepRecord>& records) {
  nlohmann::ordered_json j;
  j["cells"] = nlohmann::ordered_json::array();
  for (const CellSummary& c : cells) {
    nlohmann::ordered_json cell;
    cell["problem"] = c.problem_name;
    cell["method"] = c.method;
    cell["set"] = c.set;
    if (!c.variant.empty()) cell["variant"] = c.variant;
    cell["solves"] = c.solves;
    cell["feasible"] = c.feasible;
    cell["converged"] = c.converged;
    cell["physical"] = c.physical;
    cell["successes"] = c.successes;
    cell["success_rate"] = c.success_rate;
    cell["wall_all"] = toJson(c.wall_all);
    for (const auto& [name, member] : kStatistics) cell[name] = toJson(c.*member);
    j["cells"].push_back(cell);
  }
  j["records"] = nlohmann::ordered_json::array();
  for (const SweepRecord& r : records) j["records"].push_back(toJson(r));
  return j;
}

}  // namespace saltus::sweep
