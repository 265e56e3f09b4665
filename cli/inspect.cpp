// saltus inspect MODEL.urdf: what a model is (bodies, coordinates, limits, mass) and, for a given
// state, its joint-space dynamics: M(q) by CRBA, h(q, v) = C(q, v) v + g(q) by RNEA with zero
// acceleration, τ = ID(q, v, a) by RNEA and q̈ = FD(q, v, τ) by ABA.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/common.hpp"
#include "dynamics/dynamics.hpp"

namespace saltus::cli {

namespace {

using Json = nlohmann::ordered_json;  // keys in the order written

using dynamics::Model;

struct InspectOptions {
  std::string model_path;
  bool json = false;
  std::string base = "fixed";
  std::optional<std::string> q, v, a, tau;
};

// The inputs and results for one state.
struct Evaluation {
  Eigen::VectorXd q, v;
  std::optional<Eigen::VectorXd> a, tau_in;
  Eigen::MatrixXd M;
  Eigen::VectorXd h;
  std::optional<Eigen::VectorXd> tau;  // ID(q, v, a)
  std::optional<Eigen::VectorXd> qdd;  // FD(q, v, τ)
};

Evaluation evaluate(const Model<double>& model, const InspectOptions& opt) {
  const auto& names = model.coordinate_name;
  Evaluation e;
  e.q = parseCoordinateVector("--q", *opt.q, model.position_name);  // a quaternion base: 4 values for its orientation
  if (model.base == dynamics::BaseType::FreeQuaternion) {
    const double norm = e.q.segment<4>(3).norm();
    if (!(std::abs(norm - 1.0) <= 1e-6))
      throw std::invalid_argument("--q: the base quaternion (base_qw, base_qx, base_qy, base_qz) must have unit length, got " +
                                  std::to_string(norm));
  }
  e.v = opt.v ? parseCoordinateVector("--v", *opt.v, names) : Eigen::VectorXd::Zero(model.nv());
  if (opt.a) e.a = parseCoordinateVector("--a", *opt.a, names);
  if (opt.tau) e.tau_in = parseCoordinateVector("--tau", *opt.tau, names);
  dynamics::Data<double> data(model);
  e.M = dynamics::crba(model, data, e.q);
  e.h = dynamics::nonLinearEffects(model, data, e.q, e.v);
  if (e.a) e.tau = dynamics::rnea(model, data, e.q, e.v, *e.a);
  if (e.tau_in) e.qdd = dynamics::aba(model, data, e.q, e.v, *e.tau_in);
  // Finite inputs can overflow (--v=1e200: the velocity product is 1e400): a result that is not
  // finite is an error, not a null in the output.
  auto check = [](const char* what, const Eigen::MatrixXd& x, const char* inputs) {
    if (!x.allFinite())
      throw std::runtime_error(std::string(what) + " is not finite for the state given (" + inputs +
                               " too large for double precision?)");
  };
  check("M(q)", e.M, "--q");
  check("h(q, v)", e.h, "--q, --v");
  if (e.tau) check("tau", *e.tau, "--q, --v, --a");
  if (e.qdd) check("qdd", *e.qdd, "--q, --v, --tau");
  return e;
}

std::string parentName(const Model<double>& model, int i) {
  return model.parent[i] < 0 ? "world" : model.body_name[model.parent[i]];
}

// JSON has no infinity: an absent bound is null.
Json bound(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

Json toJson(const Eigen::VectorXd& x) { return std::vector<double>(x.data(), x.data() + x.size()); }

Json toJson(const Eigen::MatrixXd& M) {
  Json rows = Json::array();
  for (Eigen::Index i = 0; i < M.rows(); ++i) rows.push_back(toJson(Eigen::VectorXd(M.row(i).transpose())));
  return rows;
}

Json describeJson(const Model<double>& model, const std::optional<Evaluation>& e) {
  Json j;
  j["model"] = model.name;
  j["source"] = model.source;
  j["base"] = dynamics::toString(model.base);
  j["nq"] = model.nq();
  j["coordinates"] = model.coordinate_name;
  j["positions"] = model.position_name;
  Json bodies = Json::array(), limits = Json::array();
  for (int i = 0; i < model.nbodies(); ++i) {
    const auto first = model.coordinate_name.begin() + model.first_coordinate[i];
    bodies.push_back({{"name", model.body_name[i]},
                      {"parent", model.parent[i] < 0 ? Json(nullptr) : Json(parentName(model, i))},
                      {"joint", dynamics::toString(model.joint_type[i])},
                      {"coordinates", std::vector<std::string>(first, first + model.num_coordinates[i])},
                      {"mass", model.inertia[i].m}});
  }
  for (int i = 0; i < model.nv(); ++i) {
    const auto& L = model.limits[i];
    limits.push_back({{"lower", bound(L.lower)}, {"upper", bound(L.upper)},
                      {"velocity", bound(L.velocity)}, {"effort", bound(L.effort)}});
  }
  j["bodies"] = bodies;
  j["limits"] = limits;
  j["total_mass"] = model.totalMass();
  j["gravity"] = toJson(Eigen::VectorXd(model.gravity));
  if (e) {
    Json state{{"q", toJson(e->q)}, {"v", toJson(e->v)}};
    if (e->a) state["a"] = toJson(*e->a);
    if (e->tau_in) state["tau"] = toJson(*e->tau_in);
    j["state"] = state;
    j["M"] = toJson(e->M);
    j["h"] = toJson(e->h);
    if (e->tau) j["tau"] = toJson(*e->tau);
    if (e->qdd) j["qdd"] = toJson(*e->qdd);
  }
  return j;
}

std::string num(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return std::string(buf) == "-0" ? "0" : buf;
}

// A plain-text table: columns padded to their widest cell.
std::string table(const std::vector<std::vector<std::string>>& rows, const std::string& indent = "  ") {
  std::vector<std::size_t> width;
  for (const auto& r : rows)
    for (std::size_t c = 0; c < r.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], r[c].size());
    }
  std::ostringstream s;
  for (const auto& r : rows) {
    std::string line = indent;
    for (std::size_t c = 0; c < r.size(); ++c) {
      line += r[c];
      if (c + 1 < r.size()) line += std::string(width[c] - r[c].size() + 2, ' ');
    }
    s << line << "\n";
  }
  return s.str();
}

std::string vectorText(const Eigen::VectorXd& x) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < x.size(); ++i) s += (i ? ", " : "") + num(x[i]);
  return s + "]";
}

std::string describeText(const Model<double>& model, const std::optional<Evaluation>& e) {
  std::ostringstream s;
  s << "model        " << model.name << "\n"
    << "source       " << model.source << "\n"
    << "base         " << dynamics::toString(model.base);
  if (model.n_base) s << " (" << model.n_base << " base coordinates in one joint)";
  s << "\n"
    << "coordinates  " << model.nq() << "\n"
    << "total mass   " << num(model.totalMass()) << " kg\n"
    << "gravity      " << vectorText(model.gravity) << " m/s^2\n";

  s << "\nbodies\n";
  std::vector<std::vector<std::string>> rows{{"#", "body", "parent", "joint", "mass [kg]"}};
  for (int i = 0; i < model.nbodies(); ++i)
    rows.push_back({std::to_string(i), model.body_name[i], parentName(model, i),
                    dynamics::toString(model.joint_type[i]), num(model.inertia[i].m)});
  s << table(rows);

  s << "\ncoordinates (order of q, v, a, tau)\n";
  rows = {{"#", "name", "unit", "lower", "upper", "velocity", "effort"}};
  for (int i = 0; i < model.nv(); ++i) {
    const auto& L = model.limits[i];
    const bool rev = !model.isTranslation(i);
    const auto lim = [](double x) { return std::isfinite(x) ? num(x) : "-"; };
    rows.push_back({std::to_string(i), model.coordinate_name[i], rev ? "rad" : "m", lim(L.lower), lim(L.upper),
                    lim(L.velocity), lim(L.effort)});
  }
  s << table(rows);
  s << "  (- : unlimited; velocity in unit/s, effort in N m for rad, N for m)\n";

  if (e) {
    s << "\nstate\n"
      << "  q    = " << vectorText(e->q) << "\n"
      << "  v    = " << vectorText(e->v) << "\n";
    if (e->a) s << "  a    = " << vectorText(*e->a) << "\n";
    if (e->tau_in) s << "  tau  = " << vectorText(*e->tau_in) << "\n";
    s << "\nmass matrix M(q) (CRBA)\n";
    rows.clear();
    for (Eigen::Index i = 0; i < e->M.rows(); ++i) {
      rows.emplace_back();
      for (Eigen::Index k = 0; k < e->M.cols(); ++k) rows.back().push_back(num(e->M(i, k)));
    }
    s << table(rows);
    s << "\nh(q, v) = C(q, v) v + g(q)      " << vectorText(e->h) << "\n";
    if (e->tau) s << "tau = M a + h (RNEA)            " << vectorText(*e->tau) << "\n";
    if (e->qdd) s << "qdd: M qdd + h = tau (ABA)      " << vectorText(*e->qdd) << "\n";
  }
  return s.str();
}

}  // namespace

Command addInspectCommand(CLI::App& saltus) {
  auto opt = std::make_shared<InspectOptions>();
  CLI::App* app = saltus.add_subcommand(
      "inspect",
      "Describe a model (bodies, coordinates, limits, mass) and, given a state, evaluate M, h, "
      "inverse and forward dynamics.");
  app->add_option("MODEL", opt->model_path, "URDF file")->required();
  app->add_flag("--json", opt->json, "Print one JSON object instead of the readable summary");
  app->add_option("--base", opt->base, "How the root link is attached to the world: fixed, planar or free")
      ->capture_default_str();
  const auto vector_option = [&](const std::string& name, std::optional<std::string>& target, const std::string& what) {
    app->add_option_function<std::string>(name, [&target](const std::string& s) { target = s; }, what);
  };
  vector_option("--q", opt->q, "Position coordinates, comma-separated in the model's order (enables M and h; a quaternion base takes base_qw, base_qx, base_qy, base_qz)");
  vector_option("--v", opt->v, "Velocities (default: zero)");
  vector_option("--a", opt->a, "Accelerations: adds tau = M a + h (inverse dynamics)");
  vector_option("--tau", opt->tau, "Joint forces: adds qdd with M qdd + h = tau (forward dynamics)");

  return {app, [opt] {
            const dynamics::BaseType base = parseBaseOption("--base", opt->base);
            if (!opt->q)
              for (const auto& [name, given] : {std::pair{"--v", bool(opt->v)}, {"--a", bool(opt->a)}, {"--tau", bool(opt->tau)}})
                if (given) throw UsageError(std::string(name) + " needs --q (the state's coordinates)");
            const Model<double> model = loadModel(opt->model_path, base);
            std::optional<Evaluation> e;
            if (opt->q) e = evaluate(model, *opt);
            // Everything is computed before anything is printed: on error, stdout stays empty.
            const std::string out = opt->json ? describeJson(model, e).dump(2) + "\n" : describeText(model, e);
            std::cout << out << std::flush;
            return std::cout ? 0 : 1;
          }};
}

}  // namespace saltus::cli
