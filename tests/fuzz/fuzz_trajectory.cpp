// Fuzzes the trajectory CSV reader: scene::readTrajectoryCsv on the input written to
// /tmp/saltus_fuzz_trajectory_<pid>/traj.csv, then every cell of the table read back (rows,
// column lookup by name, at, row). Documented failure for bad input: std::runtime_error naming
// the file and line. Anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "scene/trajectory_csv.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto path = saltus::fuzz::tempDir("trajectory") / "traj.csv";
  saltus::fuzz::writeFile(path, data, size);
  try {
    const saltus::scene::TrajectoryTable table = saltus::scene::readTrajectoryCsv(path.string());
    volatile double sum = 0;
    for (std::size_t r = 0; r < table.rows(); ++r)
      for (const std::string& name : table.names()) sum = sum + table.at(r, table.column(name)) + table.row(r)[0];
    if (table.rows() > 0) (void)table.values("t");
  } catch (const std::runtime_error&) {
  }
  return 0;
}
