// An interrupted saltus command leaves nothing behind, and a refused one creates nothing: SIGINT and SIGTERM during `simulate`,
// `render` (with its ffmpeg child) and `run` (with its child saltus) exit 130 / 143 with the
// folder as it was before and no process left running; after a SIGKILL, the next run in the same
// folder removes the stale temporary.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "saltus/build_paths.hpp"
#include "tests/support/run_saltus.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;
using saltus::testing::runSaltus;

class InterruptTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = saltus::testing::scratchPath("interrupt", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    fs::remove_all(dir_);
    if (!err_.empty()) fs::remove(err_);
  }

  // Starts `saltus ARGS...` in the folder, standard error to a file beside it.
  pid_t start(const std::vector<std::string>& args) {
    std::vector<std::string> all = {SALTUS_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    err_ = dir_.string() + ".stderr";
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addchdir_np(&actions, dir_.c_str());
    pid_t pid = 0;
    EXPECT_EQ(::posix_spawn(&pid, SALTUS_BINARY, &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    return pid;
  }

  // Waits (up to a minute) until `ready()` holds.
  static bool waitFor(const std::function<bool()>& ready) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      if (ready()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  // Entries of the folder (recursively) inside or named as a temporary (".tmp-"); files that
  // vanish while listed (renamed into place) are skipped.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> found;
    std::error_code error;
    for (fs::recursive_directory_iterator it(dir_, error), end; !error && it != end; it.increment(error)) {
      const std::string path = it->path().string().substr(dir_.string().size());
      if (path.find(".tmp-") != std::string::npos) found.push_back(it->path().string());
    }
    return found;
  }
  std::set<std::string> entries() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }
  // Processes other than this one whose command line mentions the folder.
  int processesUsingFolder() const {
    int n = 0;
    for (const auto& e : fs::directory_iterator("/proc")) {
      const std::string name = e.path().filename().string();
      if (name.find_first_not_of("0123456789") != std::string::npos) continue;
      std::string cmdline = readFile(e.path() / "cmdline");
      for (char& c : cmdline) c = c == '\0' ? ' ' : c;
      std::string state = readFile(e.path() / "stat");
      const bool zombie = state.find(") Z ") != std::string::npos;
      n += !zombie && std::stoi(name) != ::getpid() && cmdline.find(dir_.string()) != std::string::npos;
    }
    return n;
  }
  // Sends `signal` and returns the exit code (−signal when killed by it).
  static int stop(pid_t pid, int signal) {
    ::kill(pid, signal);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }

  fs::path dir_;
  std::string err_;
};

TEST_F(InterruptTest, SimulateRemovesItsUnfinishedTrajectory) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const pid_t pid = start({"simulate", "ball_drop", "--duration", "100000", "--out", (dir_ / "traj.csv").string(),
                             "--max-output-mb", "1e9"});
    ASSERT_TRUE(waitFor([&] { return !temporaries().empty() && fs::file_size(temporaries()[0]) > 0; }));
    EXPECT_EQ(stop(pid, signal), 128 + signal);
    EXPECT_TRUE(entries().empty()) << *entries().begin();
    EXPECT_NE(readFile(err_).find(signal == SIGINT ? "interrupted by SIGINT" : "interrupted by SIGTERM"),
              std::string::npos)
        << readFile(err_);
  }
}

// bench summary works in a temporary folder: interrupted between two scenes' maps, it leaves
// neither them nor the folder.
TEST_F(InterruptTest, BenchSummaryLeavesNoPartOfItself) {
  const pid_t pid = start({"bench", "summary", "--scenes", "ball_drop,block_slide", "--min-time", "0", "--out",
                           (dir_ / "summary").string()});
  ASSERT_TRUE(waitFor([&] {
    for (const std::string& t : temporaries())
      if (fs::path(t).filename() == "ball_drop") return true;
    return false;
  }));
  EXPECT_EQ(stop(pid, SIGTERM), 128 + SIGTERM);
  EXPECT_TRUE(entries().empty()) << *entries().begin();
}

TEST_F(InterruptTest, AfterAKillTheNextRunRemovesTheStaleTemporary) {
  const pid_t pid = start({"simulate", "ball_drop", "--duration", "100000", "--out", (dir_ / "traj.csv").string(),
                           "--max-output-mb", "1e9"});
  ASSERT_TRUE(waitFor([&] { return !temporaries().empty(); }));
  EXPECT_EQ(stop(pid, SIGKILL), -SIGKILL);
  ASSERT_EQ(temporaries().size(), 1u);  // nothing can clean up after SIGKILL itself
  const auto r = runSaltus({"simulate", "ball_drop", "--duration", "0.1", "--out", (dir_ / "other.csv").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(entries(), (std::set<std::string>{"other.csv"}));
}

TEST_F(InterruptTest, RenderStopsItsEncoderAndRemovesFramesAndVideo) {
  const std::string csv = (dir_ / "p.csv").string();
  ASSERT_EQ(runSaltus({"simulate", "pendulum_conveyor", "--duration", "30", "--out", csv}).status, 0);
  const pid_t pid = start({"render", csv, "--scene", "pendulum_conveyor", "--out", (dir_ / "v.mp4").string(),
                           "--frames", (dir_ / "frames").string(), "--width", "320", "--height", "180"});
  // interrupted once frames are written and the encoder runs
  ASSERT_TRUE(waitFor([&] {
    for (const std::string& t : temporaries())
      if (t.find("frame_00002.png") != std::string::npos) return true;
    return false;
  }));
  EXPECT_EQ(processesUsingFolder(), 2);  // saltus render and its ffmpeg
  EXPECT_EQ(stop(pid, SIGTERM), 143);
  EXPECT_EQ(entries(), (std::set<std::string>{"p.csv"}));
  EXPECT_TRUE(waitFor([&] { return processesUsingFolder() == 0; }));
}

TEST_F(InterruptTest, RunStopsItsChildStep) {
  const pid_t pid = start({"run", "pendulum_conveyor", "--out", (dir_ / "run").string()});
  // interrupted while a step (a child process) runs
  ASSERT_TRUE(waitFor([&] { return processesUsingFolder() >= 2; }));
  EXPECT_EQ(stop(pid, SIGINT), 130);
  EXPECT_EQ(processesUsingFolder(), 0);
  EXPECT_TRUE(temporaries().empty()) << temporaries()[0];
  EXPECT_NE(readFile(err_).find("stopped 1 child process"), std::string::npos) << readFile(err_);
}

TEST_F(InterruptTest, AKilledRunTakesItsChildWithIt) {
  const pid_t pid = start({"run", "pendulum_conveyor", "--out", (dir_ / "run").string()});
  ASSERT_TRUE(waitFor([&] { return processesUsingFolder() >= 2; }));
  EXPECT_EQ(stop(pid, SIGKILL), -SIGKILL);
  // the child saltus gets SIGTERM as its parent dies (SALTUS_PARENT_PID) and cleans up
  EXPECT_TRUE(waitFor([&] { return processesUsingFolder() == 0; }));
  // What is left is the killed parent's own (the running step's log), which the next saltus
  // writing into that folder removes.
  const std::string parent = ".tmp-" + std::to_string(pid) + "@";
  EXPECT_TRUE(waitFor([&] {
    for (const std::string& t : temporaries())
      if (t.find(parent) == std::string::npos) return false;
    return true;
  })) << temporaries().front();
  for (const std::string& t : temporaries()) {
    const fs::path next = fs::path(t).parent_path() / "next.csv";
    EXPECT_EQ(runSaltus({"simulate", "ball_drop", "--duration", "0.01", "--out", next.string()}).status, 0);
  }
  EXPECT_TRUE(temporaries().empty()) << temporaries().front();
}

}  // namespace

namespace {

// Refused before any work: nothing is created, and the message names the option.
TEST(BeforeAnyWork, OptionsAndOutputFoldersAreCheckedFirst) {
  const fs::path dir = saltus::testing::scratchPath("before", "work");
  fs::create_directories(dir);
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::string run_dir = (dir / "run").string(), out = (dir / "sol").string();
  const std::vector<Case> cases = {
      {{"run", "point_mass_drop", "--N", "0", "--out", run_dir}, "--N: expected from 1 to 10000"},
      {{"run", "point_mass_drop", "--ipopt", "foo=1", "--out", run_dir}, "--ipopt foo=1: unknown Ipopt option 'foo'"},
      {{"run", "point_mass_drop", "--set", "nosuch=1", "--out", run_dir}, "nosuch"},
      {{"optimize", "point_mass_drop", "--ipopt", "max_iter=abc", "--out", out}, "--ipopt max_iter=abc"},
      {{"optimize", "point_mass_drop", "--ipopt", "hessian_approximation=exact", "--out", out}, "--hessian"},
      {{"optimize", "point_mass_drop", "--out", "/proc/saltus-test/x"}, "--out /proc/saltus-test/x: cannot create"},
      {{"optimize", "point_mass_drop", "--N", "", "--out", out}, "--N: expected a value, got an empty string"},
      {{"optimize", "point_mass_drop", "--seed=", "--out", out}, "--seed: expected a value"},
      {{"optimize", "point_mass_drop", "--seed", "-1", "--out", out}, "--seed: expected a whole number of 0 or more, got '-1'"},
      // the value as written, not as converted (1e400 is read as inf)
      {{"simulate", "ball_drop", "--dt", "1e400", "--out", out}, "got inf (written '1e400')"},
      {{"optimize", "point_mass_drop", "--seed-scale", "-1", "--out", out}, "--seed-scale: expected a non-negative number, got '-1'"},
      {{"optimize", "point_mass_drop", "--penalty-iterations", "-1", "--out", out}, "--penalty-iterations: expected a non-negative iteration count (0: no penalty stage)"},
      {{"optimize", "point_mass_drop", "--set", "height=-1", "--out", out}, "evaluates to -nan with height = -1 (--set)"},
      {{"optimize", "point_mass_drop", "--seed-from", (dir / "nowhere").string(), "--out", out}, "--seed-from: " + (dir / "nowhere").string() + ": no such solution"},
      {{"optimize", "point_mass_drop", "--seed-inputs", (dir / "push.csv").string(), "--out", out}, "--seed-inputs: " + (dir / "push.csv").string() + ": an input schedule drives a problem's inputs, and problem 'point_mass_drop' has none"},
      // output places that cannot be written, named by their option before any work
      {{"run", "point_mass_drop", "--out", "/proc/saltus-test"}, "--out /proc/saltus-test: cannot write in /proc"},
      {{"run", "point_mass_drop", "--video-seconds", "1e9", "--out", run_dir}, "--video-seconds: 1e+09 s at 30 fps is 3e+10 frames, more than a million, got '1e9'"},
      {{"render", "nothing.csv", "--scene", "ball_drop", "--frames", "/proc/saltus-test"}, "--frames /proc/saltus-test: cannot write in /proc"},
      {{"render", "nothing.csv", "--scene", "ball_drop", "--out", "/dev/null"}, "--out /dev/null: is a device or a pipe; expected a regular file"},
      {{"bench", "work-precision", "ball_drop", "--dts", "1e-300", "--out", run_dir}, "--dts: dt: 1e-300 s over 3 s is too many steps"},
      {{"bench", "work-precision", "ball_drop", "--out", "/proc/saltus-test"}, "--out /proc/saltus-test: cannot write in /proc"},
      {{"bench", "per-step", "--scenes", "ball_drop,banana"}, "--scenes: 'banana': unknown built-in scene"},
  };
  for (const Case& c : cases) {
    const auto r = runSaltus(c.args);
    EXPECT_NE(r.status, 0) << c.args[0] << " " << c.message;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << "expected '" << c.message << "' in:\n" << r.err;
    EXPECT_TRUE(fs::is_empty(dir)) << "left behind by: " << c.message;
  }
  fs::remove_all(dir);
}

// A solution records its problem's fingerprint; replay and render refuse it when the problem
// changed, unless told to go on (then with a warning). A comment or a solver option (`ipopt:`)
// does not change the problem.
TEST(BeforeAnyWork, ReplaySaysWhenTheProblemChanged) {
  const fs::path dir = saltus::testing::scratchPath("changed", "problem");
  fs::create_directories(dir);
  const fs::path problem = dir / "drop.yaml";
  fs::copy_file(fs::path(SALTUS_SOURCE_DIR) / "models" / "problems" / "point_mass_drop.yaml", problem);
  ASSERT_EQ(runSaltus({"optimize", problem.string(), "--out", (dir / "sol").string()}).status, 0);
  auto r = runSaltus({"replay", (dir / "sol").string(), "--engine", "saltus", "--out", (dir / "rep").string()});
  EXPECT_EQ(r.err.find("changed since this solution was saved"), std::string::npos) << r.err;
  std::ofstream(problem, std::ios::app) << "# edited\n";
  std::string text = readFile(problem);
  ASSERT_NE(text.find("tol: 1e-8"), std::string::npos);
  text.replace(text.find("tol: 1e-8"), 9, "tol: 1e-7");
  std::ofstream(problem) << text;
  fs::remove_all(dir / "rep");
  r = runSaltus({"replay", (dir / "sol").string(), "--engine", "saltus", "--out", (dir / "rep").string()});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("changed since this solution was saved"), std::string::npos) << r.err;
  ASSERT_NE(text.find("mass: 1.0"), std::string::npos);
  text.replace(text.find("mass: 1.0"), 9, "mass: 2.0");
  std::ofstream(problem) << text;
  const std::string changed = "the problem " + problem.string() + " (or its model file) changed since this solution was saved";
  fs::remove_all(dir / "rep");
  r = runSaltus({"replay", (dir / "sol").string(), "--engine", "saltus", "--out", (dir / "rep").string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find((dir / "sol" / "variables.csv").string() + ": " + changed), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--allow-changed-problem"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "rep"));
  r = runSaltus({"render", (dir / "sol").string(), "--frames", (dir / "frames").string(), "--width", "32", "--height", "32"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(changed), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "frames"));
  r = runSaltus({"replay", (dir / "sol").string(), "--engine", "saltus", "--out", (dir / "rep").string(),
                 "--allow-changed-problem"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: " + changed), std::string::npos) << r.err;
  fs::remove_all(dir);
}

}  // namespace
