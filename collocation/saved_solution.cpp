#include "collocation/saved_solution.hpp"

#include <cstdio>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include "collocation/problem_file.hpp"
#include "scene/atomic_file.hpp"

namespace saltus::collocation {

namespace fs = std::filesystem;

namespace {

constexpr const char* kFileName = "variables.csv";
constexpr const char* kBuiltinPrefix = "builtin:";

// The source as written: built-ins by name, files by absolute path (a replay may run elsewhere).
std::string sourceForFile(const std::string& source) {
  if (source.rfind(kBuiltinPrefix, 0) == 0 || source.empty()) return source;
  return fs::absolute(source).lexically_normal().string();
}

double parseNumber(const std::string& text, const std::string& where, const std::string& what) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  while (used < text.size() && std::isspace(static_cast<unsigned char>(text[used]))) ++used;
  if (used == 0 || used != text.size() || !std::isfinite(value))
    throw SolutionError(where + ": " + what + ": expected a finite number, got '" + text + "'");
  return value;
}

int parseInteger(const std::string& text, const std::string& where, const std::string& what) {
  const double v = parseNumber(text, where, what);
  if (v != std::floor(v) || v < 1 || v > 1e6)
    throw SolutionError(where + ": " + what + ": expected a positive integer, got '" + text + "'");
  return static_cast<int>(v);
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// "y.NAME[n,p]" of a joint stop NAME: a gap variable of the solutions saved before a stop's gap
// became its coordinate (Transcription::gap); the coordinate's own variable holds its value.
bool isStopGap(const Transcription& t, const std::string& name) {
  if (name.rfind("y.", 0) != 0) return false;
  const std::string pair = name.substr(2, name.find('[') - 2);
  for (const ContactPair& cp : t.contacts())
    if (cp.isStop() && cp.name == pair) return true;
  return false;
}

}  // namespace

void writeSolution(const std::string& dir, const Transcription& t, const Eigen::VectorXd& x) {
  const Problem& p = t.problem();
  const std::string path = (fs::path(dir) / kFileName).string();
  std::ostringstream out;
  out << std::setprecision(17);  // %.17g: every double reads back exactly
  out << "# saltus solution: decision variables by name\n"
      << "# source: " << sourceForFile(p.source) << "\n"
      << "# method: " << toString(t.method()) << "\n"
      << "# N: " << p.N << "\n# P: " << p.P << "\n";
  if (!p.fingerprint.empty()) out << "# problem_fingerprint: " << p.fingerprint << "\n";
  for (const auto& [name, value] : p.parameters) out << "# parameter." << name << ": " << value << "\n";
  out << "name,value\n";
  for (int i = 0; i < t.variables(); ++i) out << t.variableNames()[i] << "," << x[i] << "\n";
  try {
    scene::writeFileAtomically(path, out.str());
  } catch (const std::runtime_error& e) {
    throw SolutionError(path + ": cannot write the solution (" + e.what() + ")");
  }
}

namespace {
std::string shortNumber(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}
}  // namespace

void checkSameProblem(const SavedSolution& solution, bool allow_changed_problem) {
  if (solution.problem_changed.empty() || allow_changed_problem) return;
  throw SolutionError((solution.file.empty() ? "" : solution.file + ": ") + solution.problem_changed + "; re-solve it, or allow the changed problem explicitly (--allow-changed-problem; in Python "
                      "allow_changed_problem=True)");
}

fs::path solutionFile(const std::string& path) {
  const fs::path given = path;
  std::error_code error;
  const char* expected = "expected the --out folder of saltus optimize, or the variables.csv in it";
  if (fs::is_directory(given, error)) {
    const fs::path file = given / kFileName;
    if (!fs::exists(file, error))
      throw SolutionError(path + ": no " + std::string(kFileName) + " in this folder; " + expected);
    return file;
  }
  // The other files saltus optimize writes beside it name the solution too.
  const fs::path sibling = given.parent_path() / kFileName;
  const bool beside = given.filename() == "trajectory.csv" || given.filename() == "summary.json";
  if (beside && fs::exists(sibling, error)) return sibling;
  if (!fs::exists(given, error)) throw SolutionError(path + ": no such solution; " + expected);
  if (given.filename() == kFileName) return given;
  throw SolutionError(path + ": not a solution; " + expected);
}

SavedSolution loadSolution(const std::string& path) {
  const fs::path file = solutionFile(path);
  std::ifstream in(file);
  if (!in)
    throw SolutionError(file.string() + ": cannot read the solution (saltus optimize writes variables.csv into its --out directory)");

  // Header: '# key: value' lines, then "name,value".
  std::map<std::string, std::string> keys;
  std::map<std::string, double> parameters;
  std::string line;
  int line_no = 0;
  bool header_done = false;
  auto where = [&] { return file.string() + ":" + std::to_string(line_no); };
  while (std::getline(in, line)) {
    ++line_no;
    if (line.rfind("#", 0) == 0) {
      const std::string body = trim(line.substr(1));
      const auto colon = body.find(':');
      if (colon == std::string::npos) continue;  // a comment
      const std::string key = trim(body.substr(0, colon)), value = trim(body.substr(colon + 1));
      if (key.rfind("parameter.", 0) == 0) parameters[key.substr(10)] = parseNumber(value, where(), key);
      else keys[key] = value;
      continue;
    }
    if (trim(line) != "name,value") throw SolutionError(where() + ": expected the column header 'name,value', got '" + line + "'");
    header_done = true;
    break;
  }
  if (!header_done) throw SolutionError(file.string() + ": no 'name,value' header: not a saltus solution");
  for (const char* k : {"source", "method", "N", "P"})
    if (!keys.count(k)) throw SolutionError(file.string() + ": the header lacks '# " + k + ": ...'");

  SavedSolution s;
  s.file = file.string();
  std::string source = keys["source"];
  if (source.rfind(kBuiltinPrefix, 0) == 0) source = source.substr(std::string(kBuiltinPrefix).size());
  try {
    s.problem = std::make_unique<Problem>(loadProblem(source, parameters));
  } catch (const std::exception& e) {
    // the problem file's own message (with its line), under the solution that names it
    std::string given;
    for (const auto& [name, value] : parameters) given += (given.empty() ? "" : ", ") + name + " = " + shortNumber(value);
    throw SolutionError(file.string() + ": source " + keys["source"] + (given.empty() ? "" : " with parameters " + given) +
                        ": cannot rebuild the problem: " + e.what());
  }
  if (keys.count("problem_fingerprint") && keys["problem_fingerprint"] != s.problem->fingerprint)
    s.problem_changed = "the problem " + keys["source"] + " (or its model file) changed since this solution was saved " +
                        "(fingerprint " + keys["problem_fingerprint"] + ", now " + s.problem->fingerprint + ")";
  Method method;
  try {
    method = parseMethod(keys["method"]);
  } catch (const std::invalid_argument& e) {
    throw SolutionError(file.string() + ": method: " + e.what());
  }
  const int N = parseInteger(keys["N"], file.string(), "N"), P = parseInteger(keys["P"], file.string(), "P");
  // the problem file's limits, before anything of that size is allocated
  if (N < 1 || N > kMaxElements)
    throw SolutionError(file.string() + ": N: expected from 1 to " + std::to_string(kMaxElements) + " elements, got " +
                        std::to_string(N));
  if (P < 1 || P > 9) throw SolutionError(file.string() + ": P: expected an order from 1 to 9, got " + std::to_string(P));
  try {
    remesh(*s.problem, N, P);
    s.transcription = std::make_unique<Transcription>(*s.problem, method);
  } catch (const std::invalid_argument& e) {  // a method that cannot represent the problem
    throw SolutionError(file.string() + ": " + e.what());
  }

  std::map<std::string, int> index;
  const auto& names = s.transcription->variableNames();
  for (int i = 0; i < static_cast<int>(names.size()); ++i) index[names[i]] = i;
  s.x = Eigen::VectorXd::Constant(s.transcription->variables(), std::nan(""));
  int count = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    const auto comma = line.rfind(',');
    if (comma == std::string::npos) throw SolutionError(where() + ": expected name,value, got '" + line + "'");
    const std::string name = line.substr(0, comma);
    const auto it = index.find(name);
    if (it == index.end() && isStopGap(*s.transcription, name)) continue;  // saved before stops lost theirs
    if (it == index.end())
      throw SolutionError(where() + ": variable '" + name + "' does not belong to the rebuilt transcription (" +
                          keys["method"] + ", N = " + keys["N"] + ", P = " + keys["P"] + "): the problem changed since?");
    if (!std::isnan(s.x[it->second])) throw SolutionError(where() + ": variable '" + name + "' is given twice");
    s.x[it->second] = parseNumber(line.substr(comma + 1), where(), name);
    ++count;
  }
  if (count != s.transcription->variables()) {
    for (int i = 0; i < s.x.size(); ++i)
      if (std::isnan(s.x[i]))
        throw SolutionError(file.string() + ": variable '" + names[i] + "' is missing (" + std::to_string(count) +
                            " of " + std::to_string(s.x.size()) + " given)");
  }
  // Element lengths are positive (Ipopt keeps them within their bounds): a zero or negative one
  // would give a trajectory running backwards or of no duration.
  for (const ElementLayout& L : s.transcription->layout()) {
    if (s.x[L.h] > s.problem->h_max * (1 + 1e-6))
      throw SolutionError(file.string() + ": variable '" + names[L.h] + "': expected an element length of at most h_max = " +
                          shortNumber(s.problem->h_max) + " s, got " + shortNumber(s.x[L.h]));
    if (!(s.x[L.h] > 0))
      throw SolutionError(file.string() + ": variable '" + names[L.h] + "': expected a positive element length [s], got " +
                          shortNumber(s.x[L.h]));
  }
  return s;
}

Eigen::VectorXd seedFromSolution(const Transcription& target, const Transcription& src, const Eigen::VectorXd& earlier_x,
                                 const std::string& origin) {
  Eigen::VectorXd x = target.nullSeed();
  if (src.method() == target.method() && src.variableNames() == target.variableNames()) {
    x = earlier_x;
    target.makeConsistent(x);
    return x;
  }
  const int nv = target.problem().scene.model.nv();
  const int nu = static_cast<int>(target.problem().inputs.size());
  if (src.problem().scene.model.nv() != nv || static_cast<int>(src.problem().inputs.size()) != nu)
    throw SolutionError(origin + ": the earlier solution has " + std::to_string(src.problem().scene.model.nv()) +
                        " coordinates and " + std::to_string(src.problem().inputs.size()) + " inputs, the problem " +
                        std::to_string(nv) + " and " + std::to_string(nu) + ": it cannot seed this problem");
  const CollocationTrajectory traj(src, earlier_x);
  const double T = traj.endTime();
  double t0 = 0;
  for (int n = 0; n < target.elements(); ++n) {
    const ElementLayout& L = target.layout()[n];
    // The earlier element lengths when the element counts match (its mesh points, and so its
    // velocity jumps, carry over), else equal lengths over its duration.
    const double h_earlier = src.elements() == target.elements() ? earlier_x[src.layout()[n].h] : T / target.elements();
    const double h = std::clamp(h_earlier, target.variableLower()[L.h], target.variableUpper()[L.h]);
    x[L.h] = h;
    for (std::size_t p = 0; p < L.points.size(); ++p) {
      const double t = std::min(t0 + h * L.tau[p], T);
      const bool start = p == 0, end = static_cast<int>(p) == L.end;
      const TrajectoryPoint e = traj.at(t, end ? Side::Before : Side::After);
      const auto& pt = L.points[p];
      x.segment(pt.q, nv) = e.q;
      x.segment(pt.v, nv) = e.v;
      if (pt.accel_or_jump >= 0)
        x.segment(pt.accel_or_jump, nv) = start ? Eigen::VectorXd(e.v - traj.at(t, Side::Before).v) : e.a;  // Δq̇ at [n, 0]
      if (pt.u >= 0 && nu > 0) x.segment(pt.u, nu) = e.u;
    }
    t0 += h;
  }
  target.makeConsistent(x);
  return x;
}

Eigen::VectorXd seedFromSolution(const Transcription& target, const SavedSolution& earlier) {
  return seedFromSolution(target, *earlier.transcription, earlier.x, earlier.file);
}

}  // namespace saltus::collocation
