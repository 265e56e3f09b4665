// Sweep records and their statistics (sweep/record.hpp): quartiles as numpy's linear
// interpolation gives them, cells grouped by problem, method and parameters, statistics over the
// successful solves only, and the record's JSON read back as written.
#include "sweep/record.hpp"

#include <cmath>
#include <sstream>

#include <gtest/gtest.h>

namespace saltus::sweep {
namespace {

SweepRecord record(const std::string& method, double restitution, unsigned seed, bool feasible, bool physical,
                   double wall, int iterations) {
  SweepRecord r;
  r.problem = r.problem_name = "drop";
  r.method = method;
  r.set = {{"restitution", restitution}};
  r.seed = seed;
  r.id = "drop__" + method + "__restitution=" + std::to_string(restitution) + "__seed=" + std::to_string(seed);
  r.status = feasible ? "Solve_Succeeded" : "Infeasible_Problem_Detected";
  r.feasible = feasible;
  r.converged = feasible && seed != 4;  // seed 4: a task stage stopped at a feasible point
  if (feasible) r.physical = physical;
  r.wall_seconds = wall;
  r.iterations = iterations;
  r.mean_local_error = 1e-3 * seed;
  r.objective = 2.0 * seed;
  return r;
}

TEST(SweepRecord, QuartilesInterpolateLinearlyBetweenOrderStatistics) {
  // numpy.percentile([4, 1, 3, 2], [0, 25, 50, 75, 100]) = 1, 1.75, 2.5, 3.25, 4
  const Quartiles q = quartiles({4, 1, 3, 2});
  EXPECT_EQ(q.count, 4);
  EXPECT_DOUBLE_EQ(q.min, 1);
  EXPECT_DOUBLE_EQ(q.q1, 1.75);
  EXPECT_DOUBLE_EQ(q.median, 2.5);
  EXPECT_DOUBLE_EQ(q.q3, 3.25);
  EXPECT_DOUBLE_EQ(q.max, 4);
  const Quartiles one = quartiles({7, std::nan("")});  // non-finite values are left out
  EXPECT_EQ(one.count, 1);
  EXPECT_DOUBLE_EQ(one.q1, 7);
  EXPECT_DOUBLE_EQ(one.q3, 7);
  EXPECT_TRUE(std::isnan(quartiles({}).median));
}

TEST(SweepRecord, CellsCountSuccessesAndTakeStatisticsOverThem) {
  const std::vector<SweepRecord> records = {
      record("impulsive", 0, 1, true, true, 1.0, 100),   record("impulsive", 0, 2, true, false, 9.0, 900),
      record("impulsive", 0, 3, false, false, 5.0, 500), record("impulsive", 0, 4, true, true, 3.0, 300),
      record("first-order", 0, 1, true, true, 2.0, 200), record("impulsive", 0.5, 1, true, true, 4.0, 400),
  };
  const std::vector<CellSummary> cells = summarise(records);
  ASSERT_EQ(cells.size(), 3u);
  const CellSummary& c = cells[0];
  EXPECT_EQ(c.method, "impulsive");
  EXPECT_EQ(c.set.at("restitution"), 0);
  EXPECT_EQ(c.solves, 4);
  EXPECT_EQ(c.feasible, 3);
  EXPECT_EQ(c.converged, 2);
  EXPECT_EQ(c.physical, 2);
  EXPECT_EQ(c.successes, 2);
  EXPECT_DOUBLE_EQ(c.success_rate, 0.5);
  // Over the successes (seeds 1 and 4): wall 1 and 3; over every solve: 1, 9, 5, 3.
  EXPECT_DOUBLE_EQ(c.wall_seconds.median, 2.0);
  EXPECT_DOUBLE_EQ(c.wall_seconds.max, 3.0);
  EXPECT_DOUBLE_EQ(c.wall_all.median, 4.0);
  EXPECT_DOUBLE_EQ(c.iterations.median, 200);
  EXPECT_DOUBLE_EQ(c.mean_local_error.median, 2.5e-3);
  EXPECT_DOUBLE_EQ(c.objective.min, 2.0);
  EXPECT_EQ(cells[1].method, "first-order");
  EXPECT_EQ(cells[2].set.at("restitution"), 0.5);

  std::istringstream csv(summaryCsv(cells));
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_EQ(header.substr(0, 107),
            "problem,method,parameters,variant,solves,feasible,converged,physical,successes,success_rate,wall_all_median");
  EXPECT_EQ(first.substr(0, 46), "drop,impulsive,restitution=0,,4,3,2,2,2,0.5,4,");

  const auto j = summaryJson(cells, records);
  EXPECT_EQ(j["cells"].size(), 3u);
  EXPECT_EQ(j["records"].size(), records.size());
  EXPECT_EQ(j["cells"][0]["wall_seconds"]["median"], 2.0);
  EXPECT_TRUE(j["cells"][1]["iterations"]["q1"].is_number());
}

TEST(SweepRecord, UnderTheFeasibleRuleAFeasibleSolveSucceedsWhateverItsReplay) {
  std::vector<SweepRecord> records = {record("impulsive", 0, 1, true, true, 1.0, 100),
                                      record("impulsive", 0, 2, true, false, 9.0, 900),
                                      record("impulsive", 0, 3, false, false, 5.0, 500)};
  for (SweepRecord& r : records) r.physical_required = false;
  EXPECT_TRUE(records[1].success());
  EXPECT_FALSE(records[2].success());
  const CellSummary c = summarise(records).at(0);
  EXPECT_EQ(c.successes, 2);
  EXPECT_EQ(c.physical, 1) << "the replay's verdict is still counted";
  EXPECT_DOUBLE_EQ(c.wall_seconds.max, 9.0);
  const SweepRecord back = recordFromJson(toJson(records[1]));
  EXPECT_FALSE(back.physical_required);
  EXPECT_TRUE(back.success());
  EXPECT_EQ(toJson(records[1])["success"], true);
}

TEST(SweepRecord, CsvQuotesNamesWithCommas) {
  SweepRecord r = record("impulsive", 0, 1, true, true, 1.0, 10);
  r.problem_name = "drop, \"tall\"";
  std::istringstream csv(summaryCsv(summarise({r})));
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_EQ(row.substr(0, 41), "\"drop, \"\"tall\"\"\",impulsive,restitution=0,");
}

// A spec's variants are cells of their own, beside the same problem, method and parameters: the
// variant is in the cell's CSV row and JSON, and in the record's JSON only when there is one.
TEST(SweepRecord, EachVariantIsACellOfItsOwn) {
  std::vector<SweepRecord> records = {record("impulsive", 0, 1, true, true, 1.0, 100),
                                      record("impulsive", 0, 2, true, true, 3.0, 300),
                                      record("impulsive", 0, 1, false, false, 5.0, 500),
                                      record("impulsive", 0, 2, true, true, 7.0, 700)};
  records[0].variant = records[1].variant = "baseline";
  records[2].variant = records[3].variant = "monotone";
  const std::vector<CellSummary> cells = summarise(records);
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells[0].variant, "baseline");
  EXPECT_EQ(cells[0].successes, 2);
  EXPECT_DOUBLE_EQ(cells[0].wall_seconds.median, 2.0);
  EXPECT_EQ(cells[1].variant, "monotone");
  EXPECT_EQ(cells[1].successes, 1);
  EXPECT_DOUBLE_EQ(cells[1].wall_seconds.median, 7.0);
  std::istringstream csv(summaryCsv(cells));
  std::string header, first, second;
  std::getline(csv, header);
  std::getline(csv, first);
  std::getline(csv, second);
  EXPECT_EQ(first.substr(0, 38), "drop,impulsive,restitution=0,baseline,");
  EXPECT_EQ(second.substr(0, 38), "drop,impulsive,restitution=0,monotone,");
  const auto j = summaryJson(cells, records);
  EXPECT_EQ(j["cells"][1]["variant"], "monotone");
  EXPECT_EQ(recordFromJson(toJson(records[2])).variant, "monotone");
  EXPECT_FALSE(toJson(record("impulsive", 0, 1, true, true, 1.0, 100)).contains("variant"));
  EXPECT_EQ(recordFromJson(toJson(record("impulsive", 0, 1, true, true, 1.0, 100))).variant, "");
}

TEST(SweepRecord, JsonReadsBackAsWritten) {
  SweepRecord r = record("impulsive", 0.5, 7, true, false, 1.5, 150);
  r.command = "saltus optimize drop --seed 7";
  r.replay_deviation = 0.02;
  r.replay_message = "";
  const SweepRecord back = recordFromJson(toJson(r));
  EXPECT_EQ(back.id, r.id);
  EXPECT_EQ(back.set, r.set);
  EXPECT_EQ(back.seed, 7u);
  EXPECT_EQ(back.command, r.command);
  ASSERT_TRUE(back.physical.has_value());
  EXPECT_FALSE(*back.physical);
  EXPECT_FALSE(back.success());
  EXPECT_DOUBLE_EQ(back.replay_deviation, 0.02);
  EXPECT_DOUBLE_EQ(back.wall_seconds, 1.5);
  EXPECT_TRUE(back.converged);
  SweepRecord not_converged = r;
  not_converged.converged = false;
  EXPECT_FALSE(recordFromJson(toJson(not_converged)).converged);
  // A record written before the key: feasible meant converged.
  nlohmann::json old = toJson(r);
  old.erase("converged");
  EXPECT_TRUE(recordFromJson(old).converged);
  // Infeasible: no replay, physical absent.
  const SweepRecord infeasible = recordFromJson(toJson(record("impulsive", 0, 1, false, false, 1, 1)));
  EXPECT_FALSE(infeasible.physical.has_value());
  nlohmann::json broken = toJson(r);
  broken.erase("wall_seconds");
  try {
    recordFromJson(broken);
    FAIL() << "a record without wall_seconds was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("wall_seconds"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saltus::sweep
