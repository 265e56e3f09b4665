// The `saltus bench` subcommands that other subcommands run (cli/bench.cpp: work-precision and
// stability; cli/bench_summary.cpp: summary, which runs both for every scene), and their options.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace saltus::cli::bench {

struct BenchOptions {
  std::string engine = "saltus";
  std::string bullet_solver = "dantzig";
  std::string scene;
  std::vector<std::string> set;
  std::string solver = "lemke";
  double theta = 1.0;
  bool no_locate_impacts = false;
  std::optional<double> duration;
  std::string out;
};

struct WorkPrecisionOptions : BenchOptions {
  std::string dts = "1e-2,5e-3,2e-3,1e-3,5e-4,2e-4,1e-4";
  double min_time = 0.2;
};

struct StabilityOptions : BenchOptions {
  std::string dts = "1e-3,2e-3,5e-3,1e-2,2e-2,5e-2,1e-1";
  std::optional<std::string> frictions, restitutions, mass_ratios;
};

struct SummaryOptions {
  std::string scenes = "all";
  double target = 1e-3;
  double min_time = 0.05;
  std::string out;
};

// Each writes its CSV and charts into opt.out (made when the results are ready) and returns 0;
// bad options throw UsageError, failures std::runtime_error.
int workPrecision(const WorkPrecisionOptions& opt);
int stability(const StabilityOptions& opt);
int summary(const SummaryOptions& opt);

// The output folder, made when the results are ready to write (checkOutputTarget has checked it
// before the work), so an interrupted or failed run leaves no empty folder.
std::filesystem::path prepareOutputDirectory(const std::string& dir);

}  // namespace saltus::cli::bench
